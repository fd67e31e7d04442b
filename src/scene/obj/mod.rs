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

use std::borrow::Cow;
use std::cell::RefCell;
use std::fmt::Write as _;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use glam::{DVec3, Vec2, Vec3};

use super::normals::{angle_weighted_normals, generate_tangents};
use crate::scene::Mesh;
use crate::{LucentError, Result};

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
    /// `map_Bump` / `bump`: normal map, resolved like `diffuse_texture`.
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

/// Writes `mesh` as OBJ with one linear colour per vertex: `v x y z r g b` per vertex, then `vn`
/// per normal, `vt` per UV (flipped back to OBJ's `v`-up), and faces `f a/b/c` with 1-based
/// indices. The file is written atomically (a crash never leaves half a file).
///
/// Errors when the mesh fails [`Mesh::validate`], or `colors` does not hold one finite colour
/// per vertex.
pub fn write_obj_with_colors(path: &Path, mesh: &Mesh, colors: &[Vec3]) -> Result<()> {
    let what = path.display().to_string();
    mesh.validate(&what)?;
    if colors.len() != mesh.positions.len() {
        return Err(LucentError::InvalidInput(format!(
            "{what}: {} colours for {} vertices",
            colors.len(),
            mesh.positions.len()
        )));
    }
    if let Some(v) = colors.iter().position(|c| !c.is_finite()) {
        return Err(LucentError::InvalidInput(format!(
            "{what}: vertex {v} has a non-finite colour {}",
            colors[v]
        )));
    }
    let mut s = String::with_capacity(mesh.positions.len() * 80 + mesh.indices.len() * 12);
    // Writing to a String cannot fail; the fmt::Result is ignored.
    let _ = writeln!(
        s,
        "# written by lucent: {} vertices (v x y z r g b, linear colour), {} triangles",
        mesh.positions.len(),
        mesh.triangle_count()
    );
    for (p, c) in mesh.positions.iter().zip(colors) {
        let _ = writeln!(s, "v {} {} {} {} {} {}", p.x, p.y, p.z, c.x, c.y, c.z);
    }
    for n in &mesh.normals {
        let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &mesh.uvs {
        let _ = writeln!(s, "vt {} {}", t.x, 1.0 - t.y);
    }
    let (has_uv, has_n) = (!mesh.uvs.is_empty(), !mesh.normals.is_empty());
    for tri in mesh.indices.chunks_exact(3) {
        s.push('f');
        for &i in tri {
            let i = i as u64 + 1;
            let _ = match (has_uv, has_n) {
                (true, true) => write!(s, " {i}/{i}/{i}"),
                (false, true) => write!(s, " {i}//{i}"),
                (true, false) => write!(s, " {i}/{i}"),
                (false, false) => write!(s, " {i}"),
            };
        }
        s.push('\n');
    }
    crate::files::write_file_atomic(path, s.as_bytes())
}

// ---------------------------------------------------------------------------------------------
// Reading text

/// Reads a whole OBJ/MTL file as UTF-8 text; the error says what is wrong (no path).
fn read_text(path: &Path) -> std::result::Result<String, String> {
    // A regular file (a device would be read forever, a FIFO blocks), read with the cap
    // counted as the bytes arrive.
    let bytes = crate::files::read_capped(path, MAX_FILE_BYTES, "mesh or material file")?;
    decode_text(bytes)
}

/// Checks that `bytes` are UTF-8 text (not empty, not UTF-16, no NUL) and strips a UTF-8 BOM.
fn decode_text(bytes: Vec<u8>) -> std::result::Result<String, String> {
    if bytes.is_empty() {
        return Err("file is empty (0 bytes)".into());
    }
    if bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]) {
        return Err(
            "text is UTF-16 encoded (it starts with a UTF-16 byte-order mark); save it as UTF-8"
                .into(),
        );
    }
    if let Some(offset) = bytes.iter().position(|&b| b == 0) {
        if looks_like_utf16(&bytes) {
            return Err(
                "text looks UTF-16 encoded (every other byte is NUL); save it as UTF-8".into(),
            );
        }
        let like = binary_kind(&bytes).map_or(String::new(), |k| format!(", it starts like {k}"));
        return Err(format!(
            "line {}: binary data (NUL byte at offset {offset}{like}); not a text file",
            line_of(&bytes, offset)
        ));
    }
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let offset = e.utf8_error().valid_up_to();
        let bytes = e.as_bytes();
        format!(
            "line {}: not UTF-8 text (invalid byte 0x{:02X} at offset {offset}); save it as UTF-8",
            line_of(bytes, offset),
            bytes.get(offset).copied().unwrap_or(0)
        )
    })?;
    // A UTF-8 byte-order mark would glue itself to the first keyword ("\u{feff}v"), which tobj
    // would then skip as unknown, silently losing the first vertex.
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// True when the start reads as UTF-16 text without a BOM: in nine pairs of bytes out of ten,
/// one byte (the same one in every pair) is NUL and the other printable ASCII or whitespace.
/// Binary files have NULs too (an executable's header is mostly zeros), but not in that
/// pattern.
fn looks_like_utf16(bytes: &[u8]) -> bool {
    let head = &bytes[..bytes.len().min(512)];
    let pairs = head.len() / 2;
    if pairs < 2 {
        return false;
    }
    let text = |b: u8| matches!(b, b'\t' | b'\n' | b'\r' | 0x20..=0x7e);
    [0, 1].into_iter().any(|nul| {
        let texty = head
            .chunks_exact(2)
            .filter(|pair| pair[nul] == 0 && text(pair[1 - nul]))
            .count();
        texty * 10 >= pairs * 9
    })
}

/// What a binary file looks like from its first bytes, for the error message.
fn binary_kind(bytes: &[u8]) -> Option<&'static str> {
    const MAGIC: &[(&[u8], &str)] = &[
        (b"\x7fELF", "an ELF executable or library"),
        (b"MZ", "a Windows executable"),
        (b"\x89PNG", "a PNG image"),
        (b"\xff\xd8\xff", "a JPEG image"),
        (b"PK\x03\x04", "a ZIP archive"),
        (b"\x1f\x8b", "a gzip archive"),
        (b"glTF", "a binary glTF file"),
    ];
    MAGIC
        .iter()
        .find(|(magic, _)| bytes.starts_with(magic))
        .map(|&(_, kind)| kind)
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

/// 1-based line number of byte `offset`.
fn line_of(bytes: &[u8], offset: usize) -> usize {
    bytes[..offset.min(bytes.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// A token shortened for an error message.
fn quote(token: &str) -> String {
    const MAX: usize = 40;
    match token.char_indices().nth(MAX) {
        Some((cut, _)) => format!("'{}...'", &token[..cut]),
        None => format!("'{token}'"),
    }
}

// ---------------------------------------------------------------------------------------------
// Checking the OBJ text before tobj sees it

/// What [`scan_obj`] learnt about a file that passed it.
#[derive(Debug, Default)]
struct ObjScan {
    vertices: usize,
    faces: usize,
    polylines: usize,
    /// `mtllib` lines: (line number, file name as tobj extracts it).
    mtllibs: Vec<(usize, String)>,
    /// Comments after data, polylines or concave polygons: the text tobj gets must be
    /// rewritten.
    needs_rewrite: bool,
    /// Every vertex position so far (after dividing by `w`), for triangulating polygons.
    positions: Vec<DVec3>,
    /// Concave polygons, ear-clipped: (line number, triangles as corner numbers of the face).
    /// tobj would fan them; the rewrite writes these triangles instead.
    clipped: Vec<(usize, Vec<[usize; 3]>)>,
    /// Lines of polygons that cross themselves (or are too large to ear-clip): partly fanned.
    unclean: Vec<usize>,
}

/// The tokens of a data line after its keyword, up to a `#` comment.
fn data_tokens<'a>(words: impl Iterator<Item = &'a str>) -> (Vec<&'a str>, bool) {
    let mut out = Vec::new();
    for w in words {
        if w.starts_with('#') {
            return (out, true);
        }
        out.push(w);
    }
    (out, false)
}

/// Parses a finite `f32`; `what` names the quantity in the error.
fn finite(token: &str, line: usize, what: &str) -> std::result::Result<f32, String> {
    let v = f32::from_str(token)
        .map_err(|_| format!("line {line}: {} is not a number ({what})", quote(token)))?;
    // NaN and infinity parse ("nan", "inf", or a value beyond f32 like 1e39) but would reach
    // the GPU; tobj passes them through silently.
    if !v.is_finite() {
        return Err(format!(
            "line {line}: {what} is not finite ({}); NaN and infinity are not allowed",
            quote(token)
        ));
    }
    Ok(v)
}

/// Which face-corner attribute an index refers to.
#[derive(Clone, Copy)]
enum Attr {
    Position,
    Texcoord,
    Normal,
}

impl Attr {
    fn plural(self) -> &'static str {
        match self {
            Attr::Position => "vertices",
            Attr::Texcoord => "texture coordinates",
            Attr::Normal => "normals",
        }
    }
}

/// Checks an OBJ face index against the `count` elements defined so far; tobj resolves the
/// same way (positive: 1-based; negative: relative to the count so far) but does not check:
/// 0 and out-of-range negatives wrap to huge `usize`s that overflow (a panic in debug builds).
fn check_index(
    part: &str,
    count: usize,
    attr: Attr,
    line: usize,
) -> std::result::Result<(), String> {
    let index = isize::from_str(part).map_err(|_| {
        format!(
            "line {line}: face index {} is not an integer in range",
            quote(part)
        )
    })?;
    let kind = attr.plural();
    if index == 0 {
        return Err(format!(
            "line {line}: face index 0 is invalid (OBJ indices start at 1)"
        ));
    }
    if index < 0 && index.unsigned_abs() > count {
        return Err(format!(
            "line {line}: relative face index {index} points before the first of the {count} \
             {kind} defined so far"
        ));
    }
    if index > 0 && index.unsigned_abs() > count {
        return Err(format!(
            "line {line}: face index {index} is out of range: only {count} {kind} are defined \
             before this line"
        ));
    }
    Ok(())
}

/// Checks every line of an OBJ file for what tobj would panic on or pass silently.
fn scan_obj(text: &str) -> std::result::Result<ObjScan, String> {
    let mut scan = ObjScan::default();
    let (mut texcoords, mut normals, mut triangles) = (0usize, 0usize, 0usize);
    let mut colored: Option<usize> = None; // first line of a vertex with a colour
    let mut plain: Option<usize> = None; // first line of a vertex without one
    let mut with_uv: Option<usize> = None; // first line of a face corner with a texcoord
    let mut without_uv: Option<usize> = None;
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = raw.split_whitespace();
        let Some(key) = words.next() else {
            continue;
        };
        match key {
            "v" => {
                let (nums, comment) = data_tokens(words);
                scan.needs_rewrite |= comment;
                let n = nums.len();
                if n < 3 {
                    return Err(format!(
                        "line {ln}: vertex position needs 3 numbers (x y z), found {n}"
                    ));
                }
                if n != 3 && n != 4 && n != 6 {
                    return Err(format!(
                        "line {ln}: vertex has {n} numbers; expected 3 (x y z), 4 (x y z w) or \
                         6 (x y z r g b)"
                    ));
                }
                let mut p = [0.0f32; 3];
                for (k, t) in nums[..3].iter().enumerate() {
                    p[k] = finite(t, ln, "vertex position")?;
                }
                let mut w = 1.0;
                if n == 4 {
                    w = finite(nums[3], ln, "vertex weight w")?;
                    if w == 0.0 {
                        return Err(format!("line {ln}: vertex weight w is 0"));
                    }
                    // tobj divides x, y, z by w: a tiny w can overflow to infinity.
                    if p.iter().any(|c| !(c / w).is_finite()) {
                        return Err(format!(
                            "line {ln}: vertex position divided by w = {w} is not finite"
                        ));
                    }
                }
                scan.positions
                    .push(DVec3::new(p[0].into(), p[1].into(), p[2].into()) / f64::from(w));
                if n == 6 {
                    for t in &nums[3..] {
                        finite(t, ln, "vertex colour")?;
                    }
                    colored.get_or_insert(ln);
                } else {
                    plain.get_or_insert(ln);
                }
                // tobj keeps one colour array for all vertices: if only some have colours, the
                // colours land on the wrong vertices.
                if let (Some(c), Some(p)) = (colored, plain) {
                    let (has, lacks) = if ln == c { (c, p) } else { (c, ln) };
                    return Err(format!(
                        "line {ln}: vertex colours must be on every vertex or none (line {has} \
                         has one, line {lacks} has none)"
                    ));
                }
                scan.vertices += 1;
                if scan.vertices > MAX_VERTICES {
                    return Err(format!(
                        "line {ln}: more than {MAX_VERTICES} vertices; refusing an absurd count"
                    ));
                }
            }
            "vt" => {
                let (nums, comment) = data_tokens(words);
                scan.needs_rewrite |= comment;
                let n = nums.len();
                if n < 2 {
                    return Err(format!(
                        "line {ln}: texture coordinate needs 2 numbers (u v), found {n}"
                    ));
                }
                if n > 3 {
                    return Err(format!(
                        "line {ln}: texture coordinate has {n} numbers; expected 2 (u v) or 3 \
                         (u v w)"
                    ));
                }
                for t in &nums {
                    finite(t, ln, "texture coordinate")?;
                }
                texcoords += 1;
                if texcoords > MAX_VERTICES {
                    return Err(format!(
                        "line {ln}: more than {MAX_VERTICES} texture coordinates; refusing an \
                         absurd count"
                    ));
                }
            }
            "vn" => {
                let (nums, comment) = data_tokens(words);
                scan.needs_rewrite |= comment;
                let n = nums.len();
                if n != 3 {
                    return Err(format!(
                        "line {ln}: normal needs 3 numbers (x y z), found {n}"
                    ));
                }
                for t in &nums {
                    finite(t, ln, "normal")?;
                }
                normals += 1;
                if normals > MAX_VERTICES {
                    return Err(format!(
                        "line {ln}: more than {MAX_VERTICES} normals; refusing an absurd count"
                    ));
                }
            }
            "f" => {
                let (corners, comment) = data_tokens(words);
                scan.needs_rewrite |= comment;
                let n = corners.len();
                if n < 3 {
                    return Err(format!(
                        "line {ln}: face has {n} vertices; a face needs at least 3"
                    ));
                }
                for corner in &corners {
                    let parts: Vec<&str> = corner.split('/').collect();
                    if parts.len() > 3 {
                        return Err(format!(
                            "line {ln}: face corner {} has more than 3 parts (v/vt/vn)",
                            quote(corner)
                        ));
                    }
                    if parts[0].is_empty() {
                        return Err(format!(
                            "line {ln}: face corner {} has no vertex index",
                            quote(corner)
                        ));
                    }
                    check_index(parts[0], scan.vertices, Attr::Position, ln)?;
                    let uv = parts.get(1).filter(|p| !p.is_empty());
                    if let Some(p) = uv {
                        check_index(p, texcoords, Attr::Texcoord, ln)?;
                        with_uv.get_or_insert(ln);
                    } else {
                        without_uv.get_or_insert(ln);
                    }
                    if let Some(p) = parts.get(2).filter(|p| !p.is_empty()) {
                        check_index(p, normals, Attr::Normal, ln)?;
                    }
                    // Corners without texcoords leave tobj's texcoord array shorter than the
                    // positions (a "short texcoord array"): UVs would land on the wrong vertices.
                    if let (Some(has), Some(lacks)) = (with_uv, without_uv) {
                        return Err(format!(
                            "line {ln}: texture coordinates must be on every face corner or none \
                             (line {has} has one, line {lacks} has a corner without)"
                        ));
                    }
                }
                if n > 3 {
                    // Checked above: every index is a valid integer in range.
                    let corners: Vec<DVec3> = corners
                        .iter()
                        .map(|c| {
                            let i = c.split('/').next().and_then(|t| isize::from_str(t).ok());
                            let i = i.unwrap_or(1);
                            let at = if i > 0 {
                                i.unsigned_abs() - 1
                            } else {
                                scan.positions.len() - i.unsigned_abs()
                            };
                            scan.positions[at]
                        })
                        .collect();
                    let t = super::polygon::triangulate(&corners);
                    if !t.clean {
                        scan.unclean.push(ln);
                    }
                    if !t.convex {
                        scan.clipped.push((ln, t.triangles));
                        scan.needs_rewrite = true;
                    }
                }
                scan.faces += 1;
                triangles = triangles.saturating_add(n - 2);
                if triangles > MAX_TRIANGLES {
                    return Err(format!(
                        "line {ln}: more than {MAX_TRIANGLES} triangles; refusing an absurd count"
                    ));
                }
            }
            "l" => {
                scan.polylines += 1;
                scan.needs_rewrite = true;
            }
            "mtllib" | "usemtl" => {
                // Extracted exactly as tobj does (the rest after the first space, trimmed).
                let name = raw.split_once(' ').map_or("", |(_, rest)| rest.trim());
                if name.is_empty() {
                    let what = if key == "mtllib" {
                        "file (separate it with a space)"
                    } else {
                        "material"
                    };
                    return Err(format!("line {ln}: {key} names no {what}"));
                }
                if key == "mtllib" {
                    scan.mtllibs.push((ln, name.to_string()));
                }
            }
            _ => {}
        }
    }
    Ok(scan)
}

/// The text tobj parses: polylines blanked (tobj would read `l 1 2 3` as a triangle),
/// trailing `#` comments cut from data lines (tobj rejects them), and each concave polygon of
/// `clipped` (line number, triangles as corner numbers) written as its triangles, one `f` line
/// each with the face's own corner tokens (no `v` line moves, so relative indices still hold).
/// tobj reports no line numbers; ours come from the original text.
fn rewrite_for_tobj(text: &str, clipped: &[(usize, Vec<[usize; 3]>)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut clipped = clipped.iter().peekable();
    for (i, line) in text.lines().enumerate() {
        let key = line.split_whitespace().next().unwrap_or("");
        match key {
            "l" => {}
            "v" | "vt" | "vn" | "f" => {
                let cut = line
                    .match_indices('#')
                    .map(|(i, _)| i)
                    .find(|&i| line[..i].ends_with(char::is_whitespace))
                    .unwrap_or(line.len());
                let data = &line[..cut];
                match clipped.peek() {
                    Some((ln, triangles)) if *ln == i + 1 => {
                        let corners: Vec<&str> = data.split_whitespace().skip(1).collect();
                        for t in triangles {
                            let _ = writeln!(
                                out,
                                "f {} {} {}",
                                corners[t[0]], corners[t[1]], corners[t[2]]
                            );
                        }
                        clipped.next();
                        continue;
                    }
                    _ => out.push_str(data),
                }
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}

// ---------------------------------------------------------------------------------------------
// MTL files

/// The file an MTL texture statement names: its value, or the last word when it starts with
/// options (`map_Kd -s 2 2 1 bricks.png`). Names with spaces are kept when there are no options.
fn texture_file_name(value: &str) -> &str {
    if value.starts_with('-') {
        value.split_whitespace().last().unwrap_or(value)
    } else {
        value
    }
}

/// MTL texture statements tobj reads, with the byte length tobj skips to find the file name.
const TEXTURE_KEYS: &[(&str, usize)] = &[
    ("map_Ka", 6),
    ("map_Kd", 6),
    ("map_Ks", 6),
    ("map_Ns", 6),
    ("map_ns", 6),
    ("map_NS", 6),
    ("map_Bump", 8),
    ("map_bump", 8),
    ("bump", 4),
    ("map_d", 5),
];

/// Where the texture an MTL file names is (relative to the MTL's directory `dir`), if it is
/// there: as written, or with Windows separators (`.\tex.jpg`, `maps\wood.png`, which a
/// Unix path takes as one odd file name) turned into `/`.
fn resolve_texture(dir: &Path, name: &str) -> Option<PathBuf> {
    let as_written = dir.join(name);
    if as_written.is_file() {
        return Some(as_written);
    }
    // `.` components dropped, so `.\tex.jpg` is shown as `dir/tex.jpg`.
    let slashed: PathBuf = Path::new(&name.replace('\\', "/"))
        .components()
        .filter(|c| *c != std::path::Component::CurDir)
        .collect();
    let slashed = dir.join(slashed);
    slashed.is_file().then_some(slashed)
}

/// Checks every line of an MTL file for what tobj would panic on or pass silently. Textures it
/// names that are not there are notes, not errors (a missing texture must not fail the mesh's
/// load; its material is drawn without it): one per missing texture, naming its line.
fn scan_mtl(text: &str, dir: &Path) -> std::result::Result<Vec<String>, String> {
    let mut notes = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let line = raw.trim();
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else {
            continue;
        };
        match key {
            "newmtl" => {
                if line["newmtl".len()..].trim().is_empty() {
                    return Err(format!("line {ln}: newmtl has no material name"));
                }
            }
            "Ka" | "Kd" | "Ks" | "Ke" => {
                // tobj 4.0.5 unwraps a 3-element conversion here: fewer numbers panic.
                let (nums, _) = data_tokens(words);
                if nums.len() < 3 {
                    return Err(format!(
                        "line {ln}: {key} needs 3 numbers (r g b), found {}",
                        nums.len()
                    ));
                }
                for t in &nums[..3] {
                    finite(t, ln, key)?;
                }
            }
            "Ns" | "Ni" | "d" => match words.next() {
                Some(t) => {
                    finite(t, ln, key)?;
                }
                None => return Err(format!("line {ln}: {key} needs a number")),
            },
            "illum" => {
                if words.next().and_then(|t| u8::from_str(t).ok()).is_none() {
                    return Err(format!(
                        "line {ln}: illum needs an illumination model number (0-10)"
                    ));
                }
            }
            _ => {
                if let Some(&(_, skip)) = TEXTURE_KEYS.iter().find(|(k, _)| *k == key) {
                    let value = line.get(skip..).map_or("", str::trim);
                    if value.is_empty() {
                        return Err(format!("line {ln}: {key} names no texture file"));
                    }
                    let name = texture_file_name(value);
                    if resolve_texture(dir, name).is_none() {
                        notes.push(format!(
                            "line {ln}: texture '{name}' ({key}) not found (looked for {}): \
                             ignored, the material is drawn without it",
                            dir.join(name).display()
                        ));
                    }
                }
            }
        }
    }
    Ok(notes)
}

/// Reads, checks and parses one MTL file: tobj's result (always `Ok`, for `usemtl` lookups),
/// ours, and the notes of [`scan_mtl`].
fn load_mtl_file(
    path: &Path,
) -> std::result::Result<(tobj::MTLLoadResult, Vec<ObjMaterial>, Vec<String>), String> {
    let text = read_text(path)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let notes = scan_mtl(&text, dir)?;
    let parsed = catch_unwind(AssertUnwindSafe(|| {
        tobj::load_mtl_buf(&mut Cursor::new(text.as_bytes()))
    }));
    let parsed = match parsed {
        Err(panic) => {
            return Err(format!(
                "the MTL parser crashed on this file ({}); please report it",
                panic_message(&*panic)
            ))
        }
        Ok(Err(e)) => return Err(format!("cannot parse MTL: {e}")),
        Ok(Ok(parsed)) => parsed,
    };
    let ours = parsed
        .0
        .iter()
        .map(|m| ObjMaterial {
            name: m.name.clone(),
            diffuse: m.diffuse.map(Vec3::from),
            diffuse_texture: m
                .diffuse_texture
                .as_deref()
                .and_then(|t| resolve_texture(dir, texture_file_name(t))),
            normal_texture: m
                .normal_texture
                .as_deref()
                .and_then(|t| resolve_texture(dir, texture_file_name(t))),
        })
        .collect();
    Ok((Ok(parsed), ours, notes))
}

/// Loads the material library an OBJ's `mtllib` names (relative to the OBJ's directory). A name
/// that is not a file but contains spaces is taken as several files (`mtllib a.mtl b.mtl`).
/// Errors (and notes) name the MTL path and the OBJ line that references it.
fn load_material_libraries(
    obj_dir: &Path,
    requested: &Path,
    mtllibs: &[(usize, String)],
) -> std::result::Result<(tobj::MTLLoadResult, Vec<ObjMaterial>, Vec<String>), String> {
    let name = requested.to_string_lossy();
    let line = mtllibs
        .iter()
        .find(|(_, n)| *n == name)
        .map_or(String::new(), |(l, _)| format!(" (mtllib on line {l})"));
    let whole = obj_dir.join(requested);
    let files: Vec<PathBuf> = if !whole.is_file() && name.split_whitespace().nth(1).is_some() {
        name.split_whitespace().map(|n| obj_dir.join(n)).collect()
    } else {
        vec![whole]
    };
    let mut merged: tobj::MTLLoadResult = Ok(Default::default());
    let mut ours = Vec::new();
    let mut notes = Vec::new();
    for file in files {
        let (parsed, mut converted, file_notes) = load_mtl_file(&file)
            .map_err(|m| format!("material library {}{line}: {m}", file.display()))?;
        notes.extend(
            file_notes
                .into_iter()
                .map(|n| format!("material library {}{line}: {n}", file.display())),
        );
        if let (Ok((all, all_map)), Ok((mut materials, map))) = (&mut merged, parsed) {
            let offset = all.len();
            all.append(&mut materials);
            all_map.extend(map.into_iter().map(|(k, v)| (k, v + offset)));
        }
        ours.append(&mut converted);
    }
    Ok((merged, ours, notes))
}

/// The message of a caught panic.
fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = panic.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = panic.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

// ---------------------------------------------------------------------------------------------
// From tobj's models to one mesh

/// Concatenates tobj's models into one mesh (UVs flipped to image space), checking that every
/// attribute array has the length tobj promises. The flag is true when the file has normals on
/// some face corners but not all (the mesh's normals are then incomplete).
/// Merges the parser's models into one mesh; returns it with each triangle's material index and
/// whether normals were only on some face corners.
#[allow(clippy::type_complexity)]
fn merge_models(
    models: &[tobj::Model],
) -> std::result::Result<(Mesh, Vec<Option<usize>>, bool), String> {
    let mut mesh = Mesh::default();
    let mut triangle_materials = Vec::new();
    let (mut uv_models, mut plain_models) = (0, 0);
    let (mut any_normals, mut normals_complete) = (false, true);
    for model in models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let n = m.positions.len() / 3;
        if m.positions.len() % 3 != 0 {
            return Err(format!(
                "object '{}': parser returned {} position values (not a multiple of 3)",
                model.name,
                m.positions.len()
            ));
        }
        let base = mesh.positions.len();
        if base + n > u32::MAX as usize {
            return Err("more vertices than 32-bit indices can address".into());
        }
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        any_normals |= !m.normals.is_empty();
        if m.normals.len() == n * 3 {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|p| Vec3::new(p[0], p[1], p[2])),
            );
        } else {
            normals_complete = false;
        }
        match m.texcoords.len() {
            0 => plain_models += 1,
            len if len == n * 2 => {
                uv_models += 1;
                // OBJ's v points up the image; image-space v (Vulkan's) points down.
                mesh.uvs.extend(
                    m.texcoords
                        .chunks_exact(2)
                        .map(|t| Vec2::new(t[0], 1.0 - t[1])),
                );
            }
            len => {
                return Err(format!(
                    "object '{}': {} texture coordinates for {n} vertices: some face corners \
                     lack texture coordinates",
                    model.name,
                    len / 2
                ))
            }
        }
        match m.vertex_color.len() {
            0 => {}
            len if len == n * 3 => mesh.colors.extend(
                m.vertex_color
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            ),
            len => {
                return Err(format!(
                    "object '{}': {} vertex colours for {n} vertices",
                    model.name,
                    len / 3
                ))
            }
        }
        for &i in &m.indices {
            if i as usize >= n {
                return Err(format!(
                    "object '{}': parser returned index {i} for {n} vertices",
                    model.name
                ));
            }
            mesh.indices.push((base + i as usize) as u32);
        }
        triangle_materials.extend(std::iter::repeat_n(m.material_id, m.indices.len() / 3));
    }
    if uv_models > 0 && plain_models > 0 {
        return Err(
            "texture coordinates must be on every face or none: some objects have them and \
             others do not"
                .into(),
        );
    }
    if !mesh.colors.is_empty() && mesh.colors.len() != mesh.positions.len() {
        return Err("vertex colours must be on every vertex or none".into());
    }
    if !normals_complete {
        mesh.normals.clear();
    }
    Ok((mesh, triangle_materials, any_normals && !normals_complete))
}

/// Drops triangles with a repeated vertex or zero area; errors when none is left.
fn drop_degenerate_triangles(
    mesh: &mut Mesh,
    triangle_materials: &mut Vec<Option<usize>>,
    repairs: &mut Vec<String>,
) -> std::result::Result<(), String> {
    let total = mesh.triangle_count();
    let positions = &mesh.positions;
    let mut kept = Vec::with_capacity(mesh.indices.len());
    let mut kept_materials = Vec::with_capacity(triangle_materials.len());
    for (i, t) in mesh.indices.chunks_exact(3).enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        // f64: exact zero test without f32 overflow for huge coordinates.
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3());
        if (b - a).cross(c - a) == DVec3::ZERO {
            continue;
        }
        kept.extend_from_slice(t);
        kept_materials.push(triangle_materials.get(i).copied().flatten());
    }
    *triangle_materials = kept_materials;
    let dropped = total - kept.len() / 3;
    if kept.is_empty() {
        return Err(format!(
            "all {total} triangles are degenerate (zero area or a repeated vertex)"
        ));
    }
    if dropped > 0 {
        repairs.push(format!(
            "dropped {dropped} of {total} degenerate triangles (zero area or a repeated vertex)"
        ));
    }
    mesh.indices = kept;
    Ok(())
}

/// Normalises the file's normals, generating angle-weighted ones where the file has none (or
/// only some) and in place of zero-length ones.
fn finish_normals(mesh: &mut Mesh, repairs: &mut Vec<String>) {
    if mesh.normals.len() != mesh.positions.len() {
        mesh.normals = angle_weighted_normals(&mesh.positions, &mesh.indices);
        return;
    }
    let generated = angle_weighted_normals(&mesh.positions, &mesh.indices);
    let mut replaced = 0;
    for (n, g) in mesh.normals.iter_mut().zip(generated) {
        // f64: squaring components near f32::MAX overflows f32 to infinity.
        match n.as_dvec3().try_normalize() {
            Some(u) => *n = u.as_vec3(),
            None => {
                *n = g;
                replaced += 1;
            }
        }
    }
    if replaced > 0 {
        repairs.push(format!(
            "replaced {replaced} zero-length normals with generated ones"
        ));
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
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lucent-obj-test-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn load_str(name: &str, text: &str) -> Result<LoadedObj> {
        let dir = temp_dir(name);
        let path = dir.join(format!("{name}.obj"));
        std::fs::write(&path, text).unwrap();
        let r = load_obj(&path);
        std::fs::remove_dir_all(dir).ok();
        r
    }

    fn err(name: &str, text: &str) -> String {
        let e = load_str(name, text).unwrap_err().to_string();
        assert!(e.contains(&format!("{name}.obj")), "{e}");
        e
    }

    const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

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

    /// Total area of a loaded mesh's triangles.
    fn mesh_area(mesh: &Mesh) -> f64 {
        mesh.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn concave_polygons_are_ear_clipped_to_their_true_area_and_reported() {
        // A U (area 7 of its 3x3 box) as one face.
        let u = "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 2 3 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\n\
                 f 1 2 3 4 5 6 7 8 # the U\n";
        let o = load_str("u", u).unwrap();
        assert_eq!(o.mesh.triangle_count(), 6);
        assert!(
            (mesh_area(&o.mesh) - 7.0).abs() < 1e-5,
            "{}",
            mesh_area(&o.mesh)
        );
        assert!(
            o.repairs.iter().any(|r| r.contains(
                "triangulated 1 concave polygon(s) by ear \
                 clipping (line 9)"
            )),
            "{:?}",
            o.repairs
        );
        // A ring (radii 2 and 1, 16 segments) as one face bridged from the outside in, with
        // relative indices, UVs and normals: it keeps its hole.
        let n = 16;
        let mut text = String::new();
        for r in [2.0f64, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let _ = writeln!(text, "v {} {} 0", r * a.cos(), r * a.sin());
                let _ = writeln!(text, "vt {} {}", a.cos() * 0.5 + 0.5, a.sin() * 0.5 + 0.5);
            }
        }
        text.push_str("vn 0 0 1\nf");
        let corner = |v: usize| format!(" {}/{}/1", v as isize - 2 * n as isize, v + 1);
        let mut face: Vec<usize> = (0..n).collect();
        face.push(0);
        face.push(n);
        face.extend((n + 1..2 * n).rev());
        face.push(n);
        for v in face {
            text.push_str(&corner(v));
        }
        text.push('\n');
        let o = load_str("ring", &text).unwrap();
        let want = 3.0 * 8.0 * (std::f64::consts::TAU / 16.0).sin();
        assert!(
            (mesh_area(&o.mesh) - want).abs() < 1e-4,
            "{} vs {want}",
            mesh_area(&o.mesh)
        );
        // Every triangle faces +z like the face (winding kept), none covers the centre.
        for t in o.mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| o.mesh.positions[t[k] as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
            let centroid = (a + b + c) / 3.0;
            assert!(
                centroid.length() > 0.9,
                "a triangle inside the hole: {centroid}"
            );
        }
        assert!(
            o.repairs.iter().any(|r| r.contains("ear clipping")),
            "{:?}",
            o.repairs
        );
        // A convex quad is not a repair.
        assert!(load_str("quad2", &format!("{QUAD}f 1 2 3 4\n"))
            .unwrap()
            .repairs
            .is_empty());
    }

    #[test]
    fn degenerate_triangles_are_dropped_and_counted() {
        let text = format!("{QUAD}v 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 5\n");
        let o = load_str("degen", &text).unwrap();
        assert_eq!(o.mesh.triangle_count(), 1);
        assert!(o.repairs[0].contains("dropped 2 of 3"), "{:?}", o.repairs);
        let e = err("alldegen", &format!("{QUAD}f 1 1 2\nf 1 2 1\n"));
        assert!(e.contains("all 2 triangles are degenerate"), "{e}");
    }

    #[test]
    fn errors_name_line_and_problem() {
        let cases = [
            ("zero", format!("{QUAD}f 0 1 2\n"), "line 5: face index 0"),
            ("big", format!("{QUAD}f 1 2 1000000000000\n"), "line 5"),
            (
                "neg",
                format!("{QUAD}f -5 1 2\n"),
                "points before the first",
            ),
            (
                "nan",
                "v 0 0 0\nv nan 0 0\n".into(),
                "line 2: vertex position is not finite",
            ),
            ("inf", "v 0 0 1e39\n".into(), "not finite"),
            (
                "vt",
                format!("{QUAD}vt 0.5\n"),
                "line 5: texture coordinate needs 2",
            ),
            ("vtnan", format!("{QUAD}vt 0.5 NaN\n"), "not finite"),
            (
                "two",
                format!("{QUAD}f 1 2\n"),
                "line 5: face has 2 vertices",
            ),
            (
                "trunc",
                "v 1 2 3\nv 1.0 2".into(),
                "line 2: vertex position needs 3",
            ),
            ("empty", "\n  \n# nothing\n".into(), "empty"),
            ("nofaces", QUAD.into(), "no faces"),
            (
                "mixuv",
                format!("{QUAD}vt 0 0\nf 1/1 2/1 3/1\nf 1 3 4\n"),
                "line 7",
            ),
            ("five", "v 1 2 3 4 5\n".into(), "expected 3"),
            ("w0", "v 1 2 3 0\n".into(), "w is 0"),
            ("tab", "mtllib\tx.mtl\n".into(), "mtllib names no file"),
            (
                "color",
                "v 0 0 0 1 1 1\nv 1 0 0\n".into(),
                "line 2: vertex colours",
            ),
            (
                "parts",
                format!("{QUAD}f 1/1/1/1 2 3\n"),
                "more than 3 parts",
            ),
            (
                "huge",
                format!("{QUAD}f 1 2 99999999999999999999999\n"),
                "not an integer",
            ),
        ];
        for (name, text, want) in cases {
            let e = err(name, &text);
            assert!(e.contains(want), "{name}: {e}");
        }
    }

    #[test]
    fn rejects_encodings_and_binary() {
        assert!(decode_text(vec![]).unwrap_err().contains("empty"));
        let utf16: Vec<u8> = "v 1 2 3\n"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        assert!(decode_text(utf16.clone()).unwrap_err().contains("UTF-16"));
        let mut bom = vec![0xFF, 0xFE];
        bom.extend(utf16);
        assert!(decode_text(bom).unwrap_err().contains("UTF-16"));
        assert!(decode_text(b"v 1\n\x00\x01\x02".to_vec())
            .unwrap_err()
            .contains("line 2: binary"));
        assert!(decode_text(b"v 1 2 3\nv \xe9 1 2\n".to_vec())
            .unwrap_err()
            .contains("line 2: not UTF-8"));
        assert_eq!(decode_text(b"\xEF\xBB\xBFv".to_vec()).unwrap(), "v");
    }

    #[test]
    fn materials_resolve_and_bad_mtl_is_an_error_naming_both_files() {
        let dir = temp_dir("mtl");
        std::fs::write(dir.join("wood.png"), b"not checked here").unwrap();
        std::fs::write(
            dir.join("good.mtl"),
            "newmtl wood\nKd 0.5 0.25 1\nmap_Kd -s 1 1 1 wood.png\nbump wood.png\n",
        )
        .unwrap();
        std::fs::write(dir.join("bad.mtl"), "newmtl x\nKd 0.5 0.5\n").unwrap();
        std::fs::write(dir.join("tex.mtl"), "newmtl x\nmap_Kd gone.png\n").unwrap();
        let obj = |mtl: &str| {
            let p = dir.join(format!("uses-{mtl}.obj"));
            std::fs::write(&p, format!("mtllib {mtl}\nusemtl wood\n{QUAD}f 1 2 3\n")).unwrap();
            load_obj(&p)
        };
        let o = obj("good.mtl").unwrap();
        assert_eq!(o.materials.len(), 1);
        assert_eq!(o.materials[0].diffuse, Some(Vec3::new(0.5, 0.25, 1.0)));
        assert_eq!(o.materials[0].diffuse_texture, Some(dir.join("wood.png")));
        assert_eq!(o.materials[0].normal_texture, Some(dir.join("wood.png")));

        let e = obj("bad.mtl").unwrap_err().to_string();
        assert!(e.contains("uses-bad.mtl.obj") && e.contains("bad.mtl (mtllib on line 1)"));
        assert!(
            e.contains("line 2: Kd needs 3 numbers (r g b), found 2"),
            "{e}"
        );
        let e = obj("missing.mtl").unwrap_err().to_string();
        assert!(e.contains("missing.mtl") && e.contains("not found"), "{e}");
        // A texture that is not there is a note, not an error: drawn without it.
        let o = obj("tex.mtl").unwrap();
        assert_eq!(o.materials[0].diffuse_texture, None);
        assert!(
            o.repairs.iter().any(|r| r.contains("tex.mtl")
                && r.contains("line 2: texture 'gone.png' (map_Kd) not found")
                && r.contains("ignored")),
            "{:?}",
            o.repairs
        );
        let e = load_mtl(&dir.join("bad.mtl")).unwrap_err().to_string();
        assert!(e.contains("bad.mtl: line 2: Kd needs 3"), "{e}");
        assert_eq!(load_mtl(&dir.join("good.mtl")).unwrap().0.len(), 1);
        // Windows separators: `.\wood.png` and `maps\wood.png` are found.
        std::fs::create_dir_all(dir.join("maps")).unwrap();
        std::fs::write(dir.join("maps/wood.png"), b"not checked here").unwrap();
        std::fs::write(
            dir.join("win.mtl"),
            "newmtl wood\nmap_Kd .\\wood.png\nbump maps\\wood.png\n",
        )
        .unwrap();
        let (m, notes) = load_mtl(&dir.join("win.mtl")).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
        assert_eq!(m[0].diffuse_texture, Some(dir.join("wood.png")));
        assert_eq!(m[0].normal_texture, Some(dir.join("maps/wood.png")));
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn written_obj_reads_back_with_colours() {
        let dir = temp_dir("write");
        let mut mesh = Mesh::generate(crate::scene::Shape::Sphere { radius: 1.0 }, 8, 4);
        mesh.uvs.clear();
        let colors: Vec<Vec3> = mesh.positions.iter().map(|p| p.abs()).collect();
        let path = dir.join("sub/thick.obj");
        write_obj_with_colors(&path, &mesh, &colors).unwrap();
        let back = load_obj(&path).unwrap();
        // tobj renumbers vertices in order of first use: compare corner by corner.
        assert_eq!(back.mesh.triangle_count(), mesh.triangle_count());
        for (a, b) in back.mesh.indices.iter().zip(&mesh.indices) {
            assert_eq!(
                back.mesh.positions[*a as usize],
                mesh.positions[*b as usize]
            );
            assert_eq!(back.mesh.colors[*a as usize], colors[*b as usize]);
        }
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text
            .lines()
            .any(|l| l.starts_with("f ") && l.contains("//")));
        assert!(write_obj_with_colors(&path, &mesh, &colors[1..]).is_err());
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn written_uvs_round_trip() {
        let dir = temp_dir("write-uv");
        let mesh = Mesh::generate(crate::scene::Shape::Plane { half_size: 1.0 }, 2, 2);
        let path = dir.join("plane.obj");
        write_obj_with_colors(&path, &mesh, &vec![Vec3::ONE; mesh.positions.len()]).unwrap();
        let back = load_obj(&path).unwrap();
        for (a, b) in back.mesh.indices.iter().zip(&mesh.indices) {
            let (a, b) = (back.mesh.uvs[*a as usize], mesh.uvs[*b as usize]);
            assert!((a - b).length() < 1e-6, "{a} vs {b}");
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
