//! The files a scene reads, named before it is loaded: what a command's outputs are checked
//! against (`crate::files::check_outputs`), so `render --scene s.toml --out s.toml` or an
//! output onto the scene's normal map is refused before any work.
//!
//! This reads only the keys that name files (`[[mesh]] obj` and `gltf`, `[[material]] albedo_texture`,
//! `normal_texture`, `translucency.thickness` when it is a path, `[environment] file`; see
//! `docs/scene-format.toml`), resolved against the scene file's directory as the loader
//! resolves them. A file that does not parse names only itself: the loader reports the error.

use std::path::{Path, PathBuf};

/// The scene file itself and every file it names, each with what it is (`"the scene file"`,
/// `"the mesh of [[mesh]] 'ball'"`); empty for a built-in scene. Reads at most the scene file
/// (with the loader's checks: a regular file, capped). A built-in scene made from a scene
/// file in `assets/` (`showcase-skin`) lists that file's inputs.
pub fn scene_inputs(name_or_path: &str) -> Vec<(String, PathBuf)> {
    if let Some(file) = super::showcase::builtin_scene_file(name_or_path) {
        return scene_inputs(&file.to_string_lossy());
    }
    let path = Path::new(name_or_path);
    if !(name_or_path.ends_with(".toml") || (path.exists() && !path.is_dir())) {
        return Vec::new();
    }
    let mut inputs = vec![("the scene file".to_string(), path.to_path_buf())];
    let Ok(bytes) = crate::files::read_capped(path, 4 << 20, "scene file") else {
        return inputs;
    };
    let Some(table) = std::str::from_utf8(&bytes)
        .ok()
        .and_then(|text| text.parse::<toml::Table>().ok())
    else {
        return inputs;
    };
    let base = path.parent().unwrap_or(Path::new(""));
    let resolve = |p: &str| {
        let p = Path::new(p);
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            base.join(p)
        }
    };
    let entries = |key: &str| {
        table
            .get(key)
            .and_then(toml::Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    let name_of = |entry: &toml::Value| {
        entry
            .get("name")
            .and_then(toml::Value::as_str)
            .unwrap_or("?")
            .to_string()
    };
    for mesh in entries("mesh") {
        for key in ["obj", "gltf"] {
            if let Some(file) = mesh.get(key).and_then(toml::Value::as_str) {
                inputs.push((
                    format!("the mesh of [[mesh]] '{}'", name_of(&mesh)),
                    resolve(file),
                ));
            }
        }
    }
    if let Some(file) = table
        .get("environment")
        .and_then(|e| e.get("file"))
        .and_then(toml::Value::as_str)
    {
        inputs.push(("the environment map".to_string(), resolve(file)));
    }
    for material in entries("material") {
        let name = name_of(&material);
        for key in ["albedo_texture", "normal_texture"] {
            if let Some(file) = material.get(key).and_then(toml::Value::as_str) {
                inputs.push((format!("the {key} of material '{name}'"), resolve(file)));
            }
        }
        let thickness = material
            .get("translucency")
            .and_then(|t| t.get("thickness"))
            .and_then(toml::Value::as_str);
        if let Some(file) = thickness.filter(|t| !matches!(*t, "bake" | "vertex")) {
            inputs.push((
                format!("the thickness texture of material '{name}'"),
                resolve(file),
            ));
        }
    }
    inputs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_scene_and_the_files_it_references() {
        let dir = std::env::temp_dir().join(format!("lucent-inputs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("s.toml");
        std::fs::write(
            &scene,
            "[camera]\neye = [0, 0, 5]\ntarget = [0, 0, 0]\n[environment]\nkind = \"map\"\n\
             file = \"env.hdr\"\n[[mesh]]\nname = \"m\"\nobj = \"m.obj\"\n[[material]]\nname = \"a\"\nnormal_texture = \"n.png\"\n\
             translucency = { thickness = \"t.png\" }\n[[material]]\nname = \"b\"\n\
             translucency = { thickness = \"bake\" }\n",
        )
        .unwrap();
        let inputs = scene_inputs(&scene.to_string_lossy());
        let files: Vec<PathBuf> = inputs.iter().map(|(_, p)| p.clone()).collect();
        assert_eq!(
            files,
            [
                scene.clone(),
                dir.join("m.obj"),
                dir.join("env.hdr"),
                dir.join("n.png"),
                dir.join("t.png")
            ]
        );
        assert!(inputs[1].0.contains("[[mesh]] 'm'"), "{inputs:?}");
        assert!(scene_inputs("smoke").is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
