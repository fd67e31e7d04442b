//! Hardened Wavefront OBJ (+ MTL) loading, and writing a mesh back as OBJ with vertex colours.
//!
//! [`load_obj`] is the only way a user's OBJ file becomes a [`Mesh`]. It never panics, and every
//! error names the file, the line (when there is one) and the problem. The parsing itself is
//! `tobj`'s (triangulated, single index; concave polygons are ear-clipped before it sees
//! them), but tobj 4.0.5 panics on some malformed files and passes others through silently
//! (see DESIGN.md, "Facts measured"), so the text is checked line by line *before* tobj sees
//! it, and tobj's output is checked again after:
//!
//! | input | result |
//! |---|---|
//! | not a regular file (device, FIFO, directory), empty, UTF-16, binary (NUL bytes), not UTF-8, over 2 GiB | error |
//! | `v`/`vt`/`vn` with too few numbers, a non-number, NaN or infinity | error naming the line |
//! | face with fewer than 3 corners; index 0; index beyond what is defined so far (positive or negative) | error naming the line |
//! | more than [`MAX_VERTICES`] vertices or [`MAX_TRIANGLES`] triangles | error naming the line |
//! | texture coordinates on some face corners but not others | error naming the line |
//! | `Ka`/`Kd`/`Ks`/`Ke` with fewer than 3 numbers (tobj panics), other bad MTL values | error naming the MTL and its line |
//! | missing MTL file | error naming both files |
//! | texture named by an MTL that is not there | **note** in [`LoadedObj::repairs`]: the material is drawn without it, the mesh still loads; `\` separators are tried as `/` first |
//! | degenerate triangles (zero area or a repeated vertex) | **repair**: dropped, counted in [`LoadedObj::repairs`]; error if all are |
//! | normals on some corners but not others, zero-length normals | **repair**: generated instead, recorded |
//! | polylines (`l`) | **repair**: ignored (they are not surfaces), recorded |
//! | concave polygons (a U, a ring bridged round its hole) | **repair**: ear-clipped ([`super::polygon`]), not fanned (a fan covers area outside them); recorded with their lines |
//! | `#` comments after the data on a line | accepted (stripped before tobj, which rejects them) |
//!
//! Whatever tobj might still panic on is caught with `catch_unwind` and becomes an error.
//!
//! After loading, missing normals are generated (angle-weighted), tangents are generated when
//! the file has texture coordinates, and the mesh passes [`Mesh::validate`].
//!
//! **UV convention:** OBJ's `v` axis points up the image; [`Mesh::uvs`] are image-space (`v` = 0
//! on the top row, as Vulkan samples), so `v` is flipped on load and flipped back on write.
//!
//! This module holds the loading API and its steps in order; the steps live in `text` (reading
//! and decoding the file), `scan` (the OBJ line checks and the text tobj gets), `mtl` (MTL
//! files and their textures), `merge` (tobj's models to one repaired mesh) and `write`
//! ([`write_obj_with_colors`]).

mod merge;
mod mtl;
mod scan;
mod text;
mod write;

use std::borrow::Cow;
use std::cell::RefCell;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::normals::generate_tangents;
use crate::scene::Mesh;
use crate::{LucentError, Result};
use merge::{drop_degenerate_triangles, finish_normals, merge_models};
use mtl::{load_material_libraries, load_mtl_file};
use scan::{rewrite_for_tobj, scan_obj};
use text::read_text;
pub use write::write_obj_with_colors;

/// Largest OBJ or MTL file read (2 GiB).
pub const MAX_FILE_BYTES: u64 = 2 << 30;
/// Most `v` lines accepted in one OBJ file.
pub const MAX_VERTICES: usize = 50_000_000;
/// Most triangles (after triangulating polygons) accepted in one OBJ file.
pub const MAX_TRIANGLES: usize = 100_000_000;

/// A material from an MTL file, with what lucent uses of it.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjMaterial {
    /// Name given by `newmtl`.
    pub name: String,
    /// `Kd`: diffuse colour (finite; as written, usually in [0, 1]).
    pub diffuse: Option<Vec3>,
    /// `map_Kd`: diffuse texture, resolved relative to the MTL file's directory (Windows `\`
    /// separators accepted); `None` also when the file named is not there (a repair note).
    pub diffuse_texture: Option<PathBuf>,
    /// `norm`: tangent-space normal map, resolved like `diffuse_texture` (`map_Bump` / `bump`
    /// name height maps, which lucent does not render: a note says so).
    pub normal_texture: Option<PathBuf>,
}

/// The result of [`load_obj`]: every object of the file merged into one mesh.
#[derive(Clone, Debug)]
pub struct LoadedObj {
    /// All objects and groups of the file in one validated mesh: normals always, UVs (image-space)
    /// and tangents when the file has texture coordinates, colours when its vertices have them.
    pub mesh: Mesh,
    /// Materials of every MTL file the OBJ names, in file order.
    pub materials: Vec<ObjMaterial>,
    /// Per triangle of `mesh`: the index into `materials` of the material its face was given
    /// with `usemtl`, or `None`.
    pub triangle_materials: Vec<Option<usize>>,
    /// One human-readable line per repair applied (e.g. "dropped 3 degenerate triangles ...").
    pub repairs: Vec<String>,
}

/// Loads an OBJ file (and the MTL files it names) into one merged, validated mesh.
///
/// See the module docs for what is checked, what is repaired and what is an error.
pub fn load_obj(path: &Path) -> Result<LoadedObj> {
    let fail = |message: String| LucentError::file(path, message);
    let text = read_text(path).map_err(fail)?;
    let scan = scan_obj(&text).map_err(fail)?;
    if scan.faces == 0 {
        return Err(fail(if scan.vertices == 0 {
            "contains no vertices or faces (empty OBJ)".into()
        } else {
            format!("has {} vertices but no faces (empty mesh)", scan.vertices)
        }));
    }
    let mut repairs = Vec::new();
    if scan.polylines > 0 {
        repairs.push(format!(
            "ignored {} polyline element(s) ('l' lines): lines are not surfaces",
            scan.polylines
        ));
    }
    if !scan.clipped.is_empty() {
        repairs.push(format!(
            "triangulated {} concave polygon(s) by ear clipping ({}): a fan from the first \
             corner would cover area outside them",
            scan.clipped.len(),
            lines_list(scan.clipped.iter().map(|(ln, _)| *ln))
        ));
    }
    if !scan.unclean.is_empty() {
        repairs.push(format!(
            "{} polygon(s) cross themselves or have more than {} corners ({}): fanned where no \
             ear was left; check them",
            scan.unclean.len(),
            super::polygon::MAX_EAR_CLIP_CORNERS,
            lines_list(scan.unclean.iter().copied())
        ));
    }
    let buffer = if scan.needs_rewrite {
        Cow::Owned(rewrite_for_tobj(&text, &scan.clipped))
    } else {
        Cow::Borrowed(text.as_str())
    };

    let obj_dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let mtl_error: RefCell<Option<String>> = RefCell::new(None);
    let materials: RefCell<Vec<ObjMaterial>> = RefCell::new(Vec::new());
    let mtl_notes: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let material_loader = |requested: &Path| -> tobj::MTLLoadResult {
        if mtl_error.borrow().is_some() {
            return Err(tobj::LoadError::GenericFailure);
        }
        match load_material_libraries(&obj_dir, requested, &scan.mtllibs) {
            Ok((tobj_result, mut ours, mut notes)) => {
                materials.borrow_mut().append(&mut ours);
                mtl_notes.borrow_mut().append(&mut notes);
                tobj_result
            }
            Err(message) => {
                *mtl_error.borrow_mut() = Some(message);
                Err(tobj::LoadError::GenericFailure)
            }
        }
    };
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // Last resort: the line checks above cover every panic known in tobj 4.0.5, but a panic in a
    // dependency must still end as an error naming the file, never as a crash.
    let loaded = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_obj_buf(
            &mut Cursor::new(buffer.as_bytes()),
            &options,
            material_loader,
        )
    }));
    if let Some(message) = mtl_error.into_inner() {
        return Err(fail(message));
    }
    let models = match loaded {
        Err(panic) => {
            return Err(fail(format!(
                "the OBJ parser crashed on this file ({}); please report it",
                panic_message(&*panic)
            )))
        }
        Ok(Err(e)) => return Err(fail(format!("cannot parse OBJ: {e}"))),
        Ok(Ok((models, _))) => models,
    };

    repairs.append(&mut mtl_notes.into_inner());
    let (mut mesh, mut triangle_materials, partial_normals) =
        merge_models(&models).map_err(fail)?;
    if partial_normals {
        repairs.push(
            "normals were on some face corners but not others: ignored them and generated all"
                .into(),
        );
        mesh.normals.clear();
    }
    drop_degenerate_triangles(&mut mesh, &mut triangle_materials, &mut repairs).map_err(fail)?;
    finish_normals(&mut mesh, &mut repairs);
    if !mesh.uvs.is_empty() {
        mesh.tangents = generate_tangents(&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
    }
    mesh.validate(&path.display().to_string())?;
    for r in &repairs {
        log::warn!("{}: {r}", path.display());
    }
    let materials = materials.into_inner();
    // A material index past the libraries read names nothing (tobj keeps usemtl names it
    // could not resolve as no material).
    for m in &mut triangle_materials {
        *m = m.filter(|&i| i < materials.len());
    }
    Ok(LoadedObj {
        mesh,
        materials,
        triangle_materials,
        repairs,
    })
}

/// Loads one MTL file on its own, with the same checks [`load_obj`] applies to the MTL files an
/// OBJ names (numbers, finiteness): its materials and one note per texture it names that is
/// not there (not an error: the material is drawn without it).
pub fn load_mtl(path: &Path) -> Result<(Vec<ObjMaterial>, Vec<String>)> {
    load_mtl_file(path)
        .map(|(_, materials, notes)| (materials, notes))
        .map_err(|message| LucentError::file(path, message))
}

/// "line 4" / "lines 4, 9, 12 and 3 more", for repair notes.
fn lines_list(lines: impl Iterator<Item = usize>) -> String {
    let lines: Vec<usize> = lines.collect();
    let shown: Vec<String> = lines.iter().take(5).map(usize::to_string).collect();
    let more = lines.len().saturating_sub(shown.len());
    format!(
        "line{} {}{}",
        if lines.len() == 1 { "" } else { "s" },
        shown.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    )
}

/// The message of a caught panic.
pub(super) fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = panic.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = panic.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

impl LoadedObj {
    /// The mesh split by the materials its faces use, for rendering each with its MTL
    /// material's colour and texture: one part per distinct material among the faces that name
    /// one with a `Kd` or `map_Kd`, each a compact mesh of its triangles, plus one part (with
    /// no material) for the rest. A file whose faces name no such material is one part.
    pub fn parts(&self) -> Vec<(Mesh, Option<&ObjMaterial>)> {
        let shading = |m: &Option<usize>| {
            m.and_then(|i| self.materials.get(i))
                .filter(|m| m.diffuse.is_some() || m.diffuse_texture.is_some())
        };
        let mut keys: Vec<Option<usize>> = Vec::new();
        for m in &self.triangle_materials {
            let key = shading(m).and(*m);
            if !keys.contains(&key) {
                keys.push(key);
            }
        }
        if keys.len() <= 1 && keys.first().is_none_or(|k| k.is_none()) {
            return vec![(self.mesh.clone(), None)];
        }
        keys.iter()
            .map(|&key| {
                let triangles: Vec<usize> = (0..self.mesh.triangle_count())
                    .filter(|&t| {
                        shading(self.triangle_materials.get(t).unwrap_or(&None))
                            .and(self.triangle_materials[t])
                            == key
                    })
                    .collect();
                (
                    sub_mesh(&self.mesh, &triangles),
                    key.and_then(|i| self.materials.get(i)),
                )
            })
            .collect()
    }
}

/// The triangles `triangles` of `mesh` as a mesh of their own (vertices renumbered, every
/// per-vertex stream kept).
fn sub_mesh(mesh: &Mesh, triangles: &[usize]) -> Mesh {
    let mut remap = vec![u32::MAX; mesh.positions.len()];
    let mut out = Mesh::default();
    fn copy<T: Copy>(src: &[T], dst: &mut Vec<T>, v: usize) {
        if let Some(x) = src.get(v) {
            dst.push(*x);
        }
    }
    for &t in triangles {
        for k in 0..3 {
            let v = mesh.indices[t * 3 + k] as usize;
            if remap[v] == u32::MAX {
                remap[v] = out.positions.len() as u32;
                out.positions.push(mesh.positions[v]);
                copy(&mesh.normals, &mut out.normals, v);
                copy(&mesh.uvs, &mut out.uvs, v);
                copy(&mesh.tangents, &mut out.tangents, v);
                copy(&mesh.colors, &mut out.colors, v);
            }
            out.indices.push(remap[v]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;

    pub(super) fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lucent-obj-test-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    pub(super) fn load_str(name: &str, text: &str) -> Result<LoadedObj> {
        let dir = temp_dir(name);
        let path = dir.join(format!("{name}.obj"));
        std::fs::write(&path, text).unwrap();
        let r = load_obj(&path);
        std::fs::remove_dir_all(dir).ok();
        r
    }

    pub(super) fn err(name: &str, text: &str) -> String {
        let e = load_str(name, text).unwrap_err().to_string();
        assert!(e.contains(&format!("{name}.obj")), "{e}");
        e
    }

    pub(super) const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    #[test]
    fn loads_a_quad_with_generated_normals() {
        let o = load_str("quad", &format!("{QUAD}f 1 2 3 4\n")).unwrap();
        assert_eq!(o.mesh.triangle_count(), 2);
        assert!(o
            .mesh
            .normals
            .iter()
            .all(|n| (*n - Vec3::Z).length() < 1e-6));
        assert!(o.mesh.uvs.is_empty() && o.mesh.tangents.is_empty());
        assert!(o.repairs.is_empty());
    }

    #[test]
    fn uvs_are_flipped_and_tangents_generated() {
        let text = format!(
            "{QUAD}vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 2\nf 1/1/1 2/2/1 3/3/1 4/4/1 # quad\n"
        );
        let o = load_str("uv", &text).unwrap();
        assert_eq!(o.mesh.uvs[0], Vec2::new(0.0, 1.0));
        assert_eq!(o.mesh.normals[0], Vec3::Z); // normalised
        assert_eq!(o.mesh.tangents.len(), o.mesh.positions.len());
        assert!((o.mesh.tangents[0].truncate() - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn negative_indices_and_multiple_objects_merge() {
        let text = format!("o a\n{QUAD}f -4 -3 -2\ng b\nv 5 5 5\nf 1 3 -1\nl 1 2 3\n");
        let o = load_str("multi", &text).unwrap();
        assert_eq!(o.mesh.triangle_count(), 2);
        assert_eq!(o.repairs.len(), 1, "{:?}", o.repairs);
        assert!(o.repairs[0].contains("polyline"));
    }
}
