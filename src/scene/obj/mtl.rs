//! MTL files: checking their lines before tobj parses them, resolving the textures they name,
//! and loading the libraries an OBJ's `mtllib` lines name.

use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::str::FromStr;

use glam::Vec3;

use super::scan::{data_tokens, finite};
use super::text::read_text;
use super::{panic_message, ObjMaterial};

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
    ("norm", 4),
];

/// MTL keys that name a bump (height) map: lucent renders tangent-space normal maps (`norm`)
/// only, so these are noted as not rendered, never read as normal maps (a height map read as
/// one would tilt every normal).
const BUMP_KEYS: &[&str] = &["map_Bump", "map_bump", "bump"];

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
                    if BUMP_KEYS.contains(&key) {
                        notes.push(format!(
                            "line {ln}: {key} '{name}' is a bump (height) map, which lucent \
                             does not render: ignored (a tangent-space normal map is `norm`, \
                             or the scene's `normal_texture`)"
                        ));
                    } else if resolve_texture(dir, name).is_none() {
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
pub(super) fn load_mtl_file(
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
            // `norm` (tobj keeps it among the keys it does not know).
            normal_texture: m
                .unknown_param
                .get("norm")
                .and_then(|t| resolve_texture(dir, texture_file_name(t))),
        })
        .collect();
    Ok((Ok(parsed), ours, notes))
}

/// Loads the material library an OBJ's `mtllib` names (relative to the OBJ's directory). A name
/// that is not a file but contains spaces is taken as several files (`mtllib a.mtl b.mtl`).
/// Errors (and notes) name the MTL path and the OBJ line that references it.
pub(super) fn load_material_libraries(
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
#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::tests::{temp_dir, QUAD};
    use super::super::{load_mtl, load_obj};

    #[test]
    fn materials_resolve_and_bad_mtl_is_an_error_naming_both_files() {
        let dir = temp_dir("mtl");
        std::fs::write(dir.join("wood.png"), b"not checked here").unwrap();
        std::fs::write(
            dir.join("good.mtl"),
            "newmtl wood\nKd 0.5 0.25 1\nmap_Kd -s 1 1 1 wood.png\nnorm wood.png\n",
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
            "newmtl wood\nmap_Kd .\\wood.png\nnorm maps\\wood.png\n",
        )
        .unwrap();
        let (m, notes) = load_mtl(&dir.join("win.mtl")).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
        assert_eq!(m[0].diffuse_texture, Some(dir.join("wood.png")));
        assert_eq!(m[0].normal_texture, Some(dir.join("maps/wood.png")));
        // A bump (height) map is not a normal map: noted as not rendered, not read as one.
        std::fs::write(dir.join("bump.mtl"), "newmtl wood\nbump wood.png\n").unwrap();
        let (m, notes) = load_mtl(&dir.join("bump.mtl")).unwrap();
        assert_eq!(m[0].normal_texture, None);
        assert!(
            notes
                .iter()
                .any(|n| n.contains("line 2: bump 'wood.png' is a bump (height) map")),
            "{notes:?}"
        );
        std::fs::remove_dir_all(dir).ok();
    }
}
