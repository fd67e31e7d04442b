//! Scene files: TOML, read through serde, validated, and turned into a [`Scene`].
//!
//! The format is documented by `docs/scene-format.toml`, a commented example that the tests load.
//! Every error names the file, the line and the key: syntax errors, unknown keys and wrong types
//! come from the TOML parser (which knows the position); missing files and out-of-range values
//! are checked here, and the line is that of the value at fault, from the span the TOML parser
//! kept for it.
//!
//! `schema` is the format as serde reads it, `build` turns its tables into the scene's parts (one
//! function per table) and `materials` its `[[material]]` tables.

mod build;
mod materials;
mod schema;

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::Spanned;

use super::Scene;
use crate::{LucentError, Result};
use schema::SceneToml;

/// Largest file a scene may be (a scene file is a few kilobytes; this refuses binary garbage).
const MAX_SCENE_FILE_BYTES: u64 = 4 * 1024 * 1024;

/// The longest `credits` line a scene may carry (a licence notice with its links fits).
const MAX_CREDIT_BYTES: usize = 1000;

/// The scene file being read: its name and text, for errors, and its directory, which relative
/// paths inside it are resolved against.
struct SceneFile<'a> {
    path: &'a Path,
    source: &'a str,
    base: PathBuf,
}

impl<'a> SceneFile<'a> {
    fn new(path: &'a Path, source: &'a str) -> Self {
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        SceneFile { path, source, base }
    }

    /// `p` as the file names it: relative paths are relative to the file's directory.
    fn resolve(&self, p: &Path) -> PathBuf {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base.join(p)
        }
    }

    /// The table errors name keys of: `section` (`""` for the top level) and, for an array of
    /// tables, the entry's `index`.
    fn table(&self, section: &'a str, index: Option<usize>) -> Table<'_> {
        Table {
            file: self,
            section,
            index,
        }
    }
}

/// The 1-based line of `source` that `span` starts on. A table's span may start at the blank
/// line before it: that is skipped to its text.
fn line_of(source: &str, span: &Range<usize>) -> Option<usize> {
    let text = source.get(span.clone())?;
    let start = span.start + (text.len() - text.trim_start().len());
    Some(source.get(..start)?.matches('\n').count() + 1)
}

/// Where an error is: the span of a value the file gives, or `None` for a key it leaves out.
fn span<T>(value: &Option<Spanned<T>>) -> Option<Range<usize>> {
    value.as_ref().map(Spanned::span)
}

/// A value the file may give, without its span.
fn value<T: Copy>(value: &Option<Spanned<T>>) -> Option<T> {
    value.as_ref().map(|v| *v.get_ref())
}

/// One table of the scene file (the top level, `[camera]`, or `[[material]]` number `index`):
/// what errors about its keys are named after.
#[derive(Clone, Copy)]
struct Table<'a> {
    file: &'a SceneFile<'a>,
    section: &'a str,
    index: Option<usize>,
}

impl Table<'_> {
    /// Where a key is: `line N, key `material[0].roughness`` (the line of `span`, when the
    /// key is in the file; `camera.near`, `exposure` for other tables).
    fn location(&self, key: &str, span: Option<Range<usize>>) -> String {
        let full_key = match (self.section.is_empty(), self.index) {
            (true, _) => key.to_string(),
            (false, Some(i)) => format!("{}[{i}].{key}", self.section),
            (false, None) => format!("{}.{key}", self.section),
        };
        match span.and_then(|span| line_of(self.file.source, &span)) {
            Some(line) => format!("line {line}, key `{full_key}`"),
            None => format!("key `{full_key}`"),
        }
    }

    /// An error naming the file, the line of `span` (when the key is in the file) and the key
    /// (`material[0].roughness`, `camera.near`, `exposure`).
    fn error(
        &self,
        key: &str,
        span: Option<Range<usize>>,
        message: impl std::fmt::Display,
    ) -> LucentError {
        let location = self.location(key, span);
        LucentError::file(self.file.path, format!("{location}: {message}"))
    }

    /// Checks that the three numbers at `key`, if given, are finite and (for a finite `min`)
    /// at least `min`.
    fn check3(&self, key: &str, v: Option<&Spanned<[f32; 3]>>, min: f32) -> Result<()> {
        let Some(v) = v else { return Ok(()) };
        let numbers = *v.get_ref();
        if numbers.iter().all(|c| c.is_finite() && *c >= min) {
            return Ok(());
        }
        let bound = if min.is_finite() {
            format!(" and >= {min}")
        } else {
            String::new()
        };
        Err(self.error(
            key,
            Some(v.span()),
            format!("{numbers:?} must be finite{bound}"),
        ))
    }
}

/// Loads a scene file. Relative paths inside it (OBJ files, textures) are resolved against the
/// file's directory.
pub fn load_scene_file(path: &Path) -> Result<Scene> {
    // A regular file, read with the cap counted as it is read (not the size the filesystem
    // reports): a device or FIFO named as a scene is an error, never an endless read.
    let bytes = crate::files::read_capped(path, MAX_SCENE_FILE_BYTES, "scene file")
        .map_err(|e| LucentError::file(path, e))?;
    let source = String::from_utf8(bytes).map_err(|e| {
        LucentError::file(
            path,
            format!(
                "not UTF-8 text (byte {}): scene files are UTF-8 TOML",
                e.utf8_error().valid_up_to()
            ),
        )
    })?;
    parse_scene(path, &source)
}

/// A TOML parse or type error as one line: `FILE: line L, column C: MESSAGE`. toml's own
/// `Display` spreads over several lines (a source excerpt with a caret), which would break the
/// one-line `lucent: error:` contract; its message already names the key or value at fault.
fn toml_error(path: &Path, source: &str, error: &toml::de::Error) -> LucentError {
    let message = error
        .message()
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    // A missing key is reported at the table it is missing from: the text of that table's
    // first line is not the key at fault. A missing [camera] is at the top of the file.
    if let Some(field) = message
        .strip_prefix("missing field `")
        .and_then(|m| m.strip_suffix('`'))
    {
        if field == "camera" {
            return LucentError::file(
                path,
                "invalid scene: no [camera] table; every scene needs one, with `eye` and \
                 `target` (see docs/scene-format.toml)",
            );
        }
        let table = error
            .span()
            .and_then(|span| line_of(source, &span))
            .map(|line| format!("line {line}: "));
        return LucentError::file(
            path,
            format!(
                "invalid scene: {}missing key `{field}` in this table",
                table.unwrap_or_default()
            ),
        );
    }
    let location = error.span().and_then(|span| {
        let before = source.get(..span.start)?;
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        // A type error's message names the expected type but not the key: take the key from
        // the text before `=` on the offending line.
        let text = source.lines().nth(line - 1).unwrap_or_default();
        let key = text
            .split_once('=')
            .map(|(k, _)| format!(", key `{}`", k.trim()))
            .unwrap_or_default();
        Some(format!("line {line}, column {column}{key}: "))
    });
    LucentError::file(
        path,
        format!("invalid scene: {}{message}", location.unwrap_or_default()),
    )
}

/// Parses scene TOML `source`; `path` names it in errors and anchors relative paths.
pub fn parse_scene(path: &Path, source: &str) -> Result<Scene> {
    let raw: SceneToml = toml::from_str(source).map_err(|e| toml_error(path, source, &e))?;
    let file = SceneFile::new(path, source);
    let top = file.table("", None);
    if let Some(technique) = &raw.technique {
        return Err(top.error(
            "technique",
            Some(technique.span()),
            "the scene-level `technique` key is gone: each material's parts decide what the \
             frame shades (translucency, [material.sss] with its `blur`); remove the key, and \
             use `--technique` on the command line for A/B comparisons",
        ));
    }
    let camera = build::camera(&file, &raw.camera)?;
    let meshes = build::meshes(&file, &raw.mesh)?;
    let materials = materials::materials(&file, &raw.material)?;
    let objects = build::objects(&file, &raw.object, &meshes, &materials, &raw.material)?;
    let lights = build::lights(&file, &raw.light)?;
    let deformation = build::deformation(&file, raw.deformation.as_ref())?;
    top.check3("ambient", raw.ambient.as_ref(), 0.0)?;
    top.check3("sky", raw.sky.as_ref(), 0.0)?;
    let environment = build::environment(&file, raw.environment.as_ref(), &raw.ambient)?;
    let exposure = value(&raw.exposure).unwrap_or(1.0);
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(top.error(
            "exposure",
            span(&raw.exposure),
            format!("{exposure} must be finite and > 0"),
        ));
    }
    let credits = raw
        .credits
        .iter()
        .map(|credit| {
            let text = credit.get_ref().trim();
            // One printable line each: the demo's panel and `lucent render` print them as is.
            if text.is_empty()
                || text.len() > MAX_CREDIT_BYTES
                || text.chars().any(char::is_control)
            {
                return Err(top.error(
                    "credits",
                    Some(credit.span()),
                    format!(
                        "each credit must be one line of 1 to {MAX_CREDIT_BYTES} bytes without \
                         control characters"
                    ),
                ));
            }
            Ok(text.to_string())
        })
        .collect::<Result<Vec<_>>>()?;
    let name = raw.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into())
    });
    Ok(Scene {
        name,
        meshes: meshes.meshes,
        objects,
        lights,
        camera,
        environment,
        sky: glam::Vec3::from(value(&raw.sky).unwrap_or([0.15, 0.2, 0.3])),
        exposure,
        deformation,
        time: 0.0,
        credits,
    })
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::scene::material::{LightKind, Thickness, ThicknessSource};

    fn parse(source: &str) -> Result<Scene> {
        parse_scene(Path::new("test.toml"), source)
    }

    const MINIMAL: &str = r#"
[camera]
eye = [0, 1, 5]
target = [0, 0, 0]

[[mesh]]
name = "ball"
generator = "icosphere"
level = 1

[[material]]
name = "red"
albedo = [0.8, 0.1, 0.1]

[[object]]
mesh = "ball"
material = "red"
"#;

    #[test]
    fn minimal_scene_loads() {
        let s = parse(MINIMAL).unwrap();
        assert_eq!(s.objects.len(), 1);
        assert_eq!(s.name, "test");
    }

    /// The 1-based line of the first line of `source` starting with `prefix`.
    fn line_of(source: &str, prefix: &str) -> usize {
        source.lines().position(|l| l.starts_with(prefix)).unwrap() + 1
    }

    #[test]
    fn errors_name_file_line_and_key() {
        let bad = MINIMAL.replace(
            "albedo = [0.8, 0.1, 0.1]",
            "albedo = [0.8, 0.1, 0.1]\nroughness = 3.0",
        );
        let e = parse(&bad).unwrap_err().to_string();
        let line = format!("line {}", line_of(&bad, "roughness"));
        assert!(
            e.contains("test.toml") && e.contains(&line) && e.contains("material[0].roughness"),
            "{e}"
        );

        let unknown = MINIMAL.replace("level = 1", "level = 1\ncolour = 3");
        let e = parse(&unknown).unwrap_err().to_string();
        let line = format!("line {}", line_of(&unknown, "colour"));
        assert!(
            e.contains("test.toml") && e.contains(&line) && e.contains("colour"),
            "{e}"
        );

        let wrong_type = MINIMAL.replace("level = 1", "level = \"high\"");
        let e = parse(&wrong_type).unwrap_err().to_string();
        let line = format!("line {}", line_of(&wrong_type, "level"));
        assert!(e.contains(&line) && e.contains("level"), "{e}");

        let missing = MINIMAL.replace(
            "generator = \"icosphere\"\nlevel = 1",
            "obj = \"nowhere.obj\"",
        );
        let e = parse(&missing).unwrap_err().to_string();
        assert!(
            e.contains("mesh[0].obj") && e.contains("nowhere.obj") && e.contains("not found"),
            "{e}"
        );
    }

    #[test]
    fn lights_are_checked() {
        let with_light = format!(
            "{MINIMAL}\n[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = -5\n"
        );
        let e = parse(&with_light).unwrap_err().to_string();
        let line = format!("line {}", line_of(&with_light, "intensity"));
        assert!(e.contains("light[0].intensity") && e.contains(&line), "{e}");
        let spot = format!("{MINIMAL}\n[[light]]\ntype = \"spot\"\nposition = [0, 2, 0]\ndirection = [0, -1, 0]\nintensity = 5\n");
        assert!(matches!(
            parse(&spot).unwrap().lights[0].kind,
            LightKind::Spot { .. }
        ));
    }

    #[test]
    fn scene_messages_name_the_key_and_line() {
        let scale = MINIMAL.replace("material = \"red\"", "material = \"red\"\nscale = [8, 1]");
        let e = parse(&scale).unwrap_err().to_string();
        let line = format!("line {}", line_of(&scale, "scale"));
        assert!(
            e.contains(&line) && e.contains("[x, y, z]") && e.contains("array of 2"),
            "{e}"
        );
        assert!(!e.contains("untagged"), "{e}");
        let range = format!(
            "{MINIMAL}\n[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 5\nrange = -1\n"
        );
        let e = parse(&range).unwrap_err().to_string();
        let line = format!("line {}", line_of(&range, "range"));
        assert!(e.contains("light[0].range") && e.contains(&line), "{e}");
        assert!(!e.contains("position"), "{e}");
        let upm = MINIMAL.replace(
            "albedo = [0.8, 0.1, 0.1]",
            "albedo = [0.8, 0.1, 0.1]\nsss = { preset = \"skin\", units_per_mm = 0 }",
        );
        let e = parse(&upm).unwrap_err().to_string();
        let line = format!("line {}", line_of(&upm, "sss"));
        assert!(
            e.contains("material[0].sss.units_per_mm") && e.contains(&line),
            "{e}"
        );
        let no_camera = format!(
            "name = \"x\"\n{}",
            MINIMAL.replace("[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n", "")
        );
        let e = parse(&no_camera).unwrap_err().to_string();
        assert!(
            e.contains("no [camera] table") && !e.contains("`name`"),
            "{e}"
        );
    }

    /// A one-triangle glTF asset (`tri.gltf` + `tri.bin`) in a fresh folder, its node
    /// translated by (1, 0, 0), its material red; returns the folder.
    fn gltf_triangle(name: &str) -> std::path::PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lucent-gltf-scene-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let positions: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
        let bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(dir.join("tri.bin"), &bin).unwrap();
        let json = r#"{"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"mesh": 0, "translation": [1, 0, 0]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
            "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1],
                "metallicFactor": 0}}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "buffers": [{"uri": "tri.bin", "byteLength": 36}]}"#;
        std::fs::write(dir.join("tri.gltf"), json).unwrap();
        dir
    }

    #[test]
    fn a_scene_file_places_gltf_assets_with_their_materials_or_its_own() {
        let dir = gltf_triangle("place");
        let scene = MINIMAL
            .replace(
                "[[mesh]]\nname = \"ball\"",
                "[[mesh]]\nname = \"tri\"\ngltf = \"tri.gltf\"\n\n[[mesh]]\nname = \"ball\"",
            )
            .replace(
                "[[object]]\nmesh = \"ball\"",
                "[[object]]\nmesh = \"tri\"\ntranslate = [0, 2, 0]\n\n[[object]]\nmesh = \"tri\"\n\
                 material = \"red\"\n\n[[object]]\nmesh = \"ball\"",
            );
        let path = dir.join("scene.toml");
        let s = parse_scene(&path, &scene).unwrap();
        assert_eq!(s.objects.len(), 3);
        // The asset's own material (base colour red, dielectric), placed by the object and
        // then the node.
        let own = &s.objects[0];
        assert_eq!(own.material.albedo, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(
            own.transform.transform_point3(Vec3::ZERO),
            Vec3::new(1.0, 2.0, 0.0)
        );
        // A named material overrides it; the node still places the part.
        assert_eq!(s.objects[1].material.name, "red");
        assert_eq!(s.objects[1].transform.transform_point3(Vec3::ZERO), Vec3::X);

        // Errors name the file, the line and the key.
        let missing = scene.replace("gltf = \"tri.gltf\"", "gltf = \"nope.glb\"");
        let e = parse_scene(&path, &missing).unwrap_err().to_string();
        assert!(e.contains("mesh[0].gltf") && e.contains("not found"), "{e}");
        let both = scene.replace(
            "gltf = \"tri.gltf\"",
            "gltf = \"tri.gltf\"\ngenerator = \"cube\"",
        );
        let e = parse_scene(&path, &both).unwrap_err().to_string();
        assert!(
            e.contains("exactly one of `obj`, `gltf` or `generator`"),
            "{e}"
        );
        let units = MINIMAL.replace("level = 1", "level = 1\nunits_per_mm = 0.01");
        let e = parse(&units).unwrap_err().to_string();
        assert!(e.contains("units_per_mm") && e.contains("gltf"), "{e}");
        let bad_units = scene.replace(
            "gltf = \"tri.gltf\"",
            "gltf = \"tri.gltf\"\nunits_per_mm = -1",
        );
        let e = parse_scene(&path, &bad_units).unwrap_err().to_string();
        assert!(e.contains("mesh[0].units_per_mm"), "{e}");
        let no_material = MINIMAL.replace("material = \"red\"\n", "");
        let e = parse(&no_material).unwrap_err().to_string();
        assert!(
            e.contains("object[0].material") && e.contains("gltf"),
            "{e}"
        );
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn the_documented_example_loads() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scene-format.toml");
        let scene = load_scene_file(&path).unwrap();
        assert_eq!(scene.objects.len(), 3);
        assert_eq!(scene.lights.len(), 3);
        let jade = &scene.objects[0].material;
        assert_eq!(
            jade.translucency.as_ref().unwrap().thickness,
            ThicknessSource::Bake
        );
        assert!(jade.translucency.as_ref().unwrap().shadowed);
        assert!(scene.objects[1].material.sss.is_some());
    }

    /// MINIMAL with a second material `skin` (the object's) whose body is `layered`.
    fn with_layered(layered: &str) -> String {
        MINIMAL.replace(
            "[[object]]\nmesh = \"ball\"\nmaterial = \"red\"",
            &format!(
                "[[material]]\nname = \"skin\"\n\n{layered}\n[[object]]\nmesh = \"ball\"\n\
                 material = \"skin\""
            ),
        )
    }

    const TWO_LAYERS: &str = r#"[material.layered]
eta = 1.4
weights = [0.2, 0.3, 0.1, 0.1, 0.3]
units_per_mm = 0.1

[[material.layered.layer]]
sigma_a = [0.2, 0.37, 0.82]
sigma_s_prime = [4.7, 5.9, 8.7]
g = 0.9
thickness = 0.25

[[material.layered.layer]]
sigma_a = [0.03, 0.26, 0.46]
sigma_s = [2.3, 2.9, 4.4]
g = -0.5
thickness = "rest"
"#;

    #[test]
    fn layered_media_load_from_presets_and_layer_tables() {
        let s = parse(&with_layered("[material.layered]\npreset = \"skimmilk\"\n")).unwrap();
        let m = s.objects[0].material.layers.as_ref().unwrap();
        assert_eq!(m.name, "skimmilk");
        assert_eq!(m.weights, crate::scene::layered::DEFAULT_WEIGHTS);

        let s = parse(&with_layered(TWO_LAYERS)).unwrap();
        let m = s.objects[0].material.layers.as_ref().unwrap();
        assert_eq!(m.layers.len(), 2);
        assert_eq!((m.eta, m.units_per_mm), (1.4, 0.1));
        assert_eq!(m.weights, [0.2, 0.3, 0.1, 0.1, 0.3]);
        // sigma_s' / (1 - g) is stored; sigma_s as given.
        assert!(
            (m.layers[0].sigma_s.x - 47.0).abs() < 1e-3,
            "{}",
            m.layers[0].sigma_s
        );
        assert_eq!(m.layers[1].sigma_s, Vec3::new(2.3, 2.9, 4.4));
        assert_eq!(m.layers[0].thickness, Thickness::Mm(0.25));
        assert_eq!(m.layers[1].thickness, Thickness::Rest);
    }

    const MEDIUM: &str = r#"[material.medium]
sigma_a = [0.032, 0.17, 0.48]
sigma_s = [0.74, 0.88, 1.01]
eta = 1.0
units_per_mm = 0.05
"#;

    #[test]
    fn a_medium_gives_the_albedo_and_the_layers_unless_they_are_written() {
        // Skin1 (Jensen 2001) at eta 1: its white-sky albedo, which a Monte Carlo random walk
        // gives as (0.626, 0.385, 0.242) (src/reference/albedo.rs; the dipole's R_d is
        // (0.5473, 0.2912, 0.161)).
        let s = parse(&with_layered(MEDIUM)).unwrap();
        let m = &s.objects[0].material;
        let expected = Vec3::new(0.6253, 0.3849, 0.2413);
        assert!(
            (m.albedo - expected).abs().max_element() < 5e-4,
            "{}",
            m.albedo
        );
        // The f64 twin, channel by channel.
        for c in 0..3 {
            let a = crate::scene::albedo::white_sky_albedo(
                [0.74, 0.88, 1.01][c],
                [0.032, 0.17, 0.48][c],
                1.0,
            );
            assert!((f64::from(m.albedo[c]) - a).abs() < 1e-6);
        }
        let layers = m.layers.as_ref().unwrap();
        assert_eq!(layers, &m.medium.as_ref().unwrap().layered);
        assert_eq!(layers.layers.len(), 1);
        assert_eq!(layers.layers[0].thickness, Thickness::Rest);
        assert_eq!(layers.layers[0].sigma_s, Vec3::new(0.74, 0.88, 1.01));
        assert_eq!((layers.eta, layers.units_per_mm), (1.0, 0.05));
        assert_eq!(layers.weights, crate::scene::layered::PHYSICAL_WEIGHTS);
        // A preset, its eta (1.3) kept: marble's albedo is higher than skin1's in every channel.
        let s = parse(&with_layered("[material.medium]\npreset = \"marble\"\n")).unwrap();
        let marble = &s.objects[0].material;
        assert!(marble.albedo.cmpgt(expected).all(), "{}", marble.albedo);
        assert_eq!(marble.layers.as_ref().unwrap().eta, 1.3);
        // Written keys override what the medium derives.
        let s = parse(&with_layered(&format!(
            "albedo = [0.1, 0.2, 0.3]\n{MEDIUM}"
        )))
        .unwrap();
        assert_eq!(s.objects[0].material.albedo, Vec3::new(0.1, 0.2, 0.3));
        let s = parse(&with_layered(&format!(
            "{MEDIUM}\n[material.layered]\npreset = \"apple\"\n"
        )))
        .unwrap();
        let m = &s.objects[0].material;
        assert_eq!(m.layers.as_ref().unwrap().name, "apple");
        assert!((m.albedo - expected).abs().max_element() < 5e-4);
    }

    #[test]
    fn an_sss_table_without_a_profile_takes_the_medium_s_and_says_how_to_blur_it() {
        let s = parse(&with_layered(&format!(
            "{MEDIUM}\n[material.sss]\ntexturing = \"pre-post\"\nblur = \"burley\"\n"
        )))
        .unwrap();
        let m = &s.objects[0].material;
        let medium = m.medium.as_ref().unwrap();
        let sss = m.sss.as_ref().unwrap();
        assert_eq!(sss.gaussians, medium.profile.gaussians);
        assert_eq!(sss.burley, medium.profile.burley);
        assert_eq!(sss.units_per_mm, medium.profile.units_per_mm);
        assert_eq!(sss.texturing, crate::scene::material::Texturing::PrePost);
        assert!(sss.blur.is_some());
        // Written, the table makes the material screen-space SSS: no layered passes under auto.
        assert!(m.layers.is_none());
        // Without a medium there is still no profile to take.
        let e = parse(&with_layered("[material.sss]\ntexturing = \"pre-post\"\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("beside a [material.medium]"), "{e}");
    }

    #[test]
    fn a_medium_is_layered_under_auto_and_fitted_under_a_forced_sss_technique() {
        use crate::frame::{FrameDesc, FrameSettings, Technique};
        let scene = parse(&with_layered(MEDIUM)).unwrap();
        let settings = |t: &str| FrameSettings {
            technique: Technique::parse(t).unwrap(),
            ..FrameSettings::new(64, 64)
        };
        let auto = FrameDesc::new(&scene, &settings("auto")).unwrap();
        assert!(auto.layered().is_some() && auto.sss().is_none());
        for blur in ["separable", "bilateral", "burley", "control"] {
            let d = FrameDesc::new(&scene, &settings(blur)).unwrap();
            let sss = d.sss().unwrap_or_else(|| panic!("{blur}: no SSS"));
            assert!(d.layered().is_none(), "{blur}");
            let (profile, _) = sss.of_object(0).unwrap();
            assert!(
                profile.name.contains("fitted to its dipole"),
                "{}",
                profile.name
            );
        }
        // A medium beside a technique's own table: that technique renders it under `auto`, and
        // no layered medium is derived as well.
        let with_sss = parse(&with_layered(&format!(
            "{MEDIUM}\n[material.sss]\npreset = \"skin\"\n"
        )))
        .unwrap();
        let m = &with_sss.objects[0].material;
        assert!(m.layers.is_none() && m.sss.is_some() && m.medium.is_some());
        let auto = FrameDesc::new(&with_sss, &settings("auto")).unwrap();
        assert!(auto.layered().is_none());
        assert_eq!(auto.sss().unwrap().of_object(0).unwrap().0.name, "skin");
    }

    #[test]
    fn medium_errors_name_file_line_and_key() {
        let base = with_layered(MEDIUM);
        let cases = [
            ("eta = 1.0", "eta = -1", "material[1].medium.eta", "> 0"),
            (
                "units_per_mm = 0.05",
                "units_per_mm = 1e9",
                "material[1].medium.units_per_mm",
                "must be in",
            ),
            (
                "sigma_a = [0.032, 0.17, 0.48]",
                "sigma_a = [0.032, nan, 0.48]",
                "material[1].medium.sigma_a",
                "finite",
            ),
            (
                "sigma_s = [0.74, 0.88, 1.01]",
                "sigma_s = [0.74, 0.88, 1.01]\ng = 1.5",
                "material[1].medium.g",
                "[-0.999, 0.999]",
            ),
            (
                "sigma_s = [0.74, 0.88, 1.01]",
                "sigma_s = [0.74, 0.88, 1.01]\nsigma_s_prime = [1, 1, 1]",
                "material[1].medium.sigma_s_prime",
                "not both",
            ),
            (
                "eta = 1.0",
                "eta = 1.0\npreset = \"marble\"",
                "material[1].medium.preset",
                "not both",
            ),
            (
                "eta = 1.0",
                "eta = 1.0\nthickness = 2.0",
                "key `thickness`",
                "unknown field `thickness`",
            ),
        ];
        for (from, to, key, part) in cases {
            let src = base.replacen(from, to, 1);
            assert_ne!(src, base, "{from}");
            let e = parse(&src).unwrap_err().to_string();
            assert!(
                e.contains("test.toml") && e.contains(key) && e.contains(part),
                "{to}: {e}"
            );
        }
        // A stack is not one medium; an unknown preset names the ones there are.
        let stack = with_layered("[material.medium]\npreset = \"skin-layered\"\n");
        let e = parse(&stack).unwrap_err().to_string();
        assert!(
            e.contains("medium.preset") && e.contains("[material.layered]"),
            "{e}"
        );
        let e = parse(&with_layered("[material.medium]\npreset = \"jade\"\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("medium.preset") && e.contains("skin1"), "{e}");
        let e = parse(&with_layered("[material.medium]\neta = 1.2\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("medium") && e.contains("sigma_a"), "{e}");
    }

    #[test]
    fn layered_errors_name_file_line_and_key() {
        let base = with_layered(TWO_LAYERS);
        // (replace, with, key, message part); the line is that of the replacement.
        let cases = [
            (
                "g = -0.5",
                "g = -1",
                "material[1].layered.layer[1].g",
                "[-0.999, 0.999]",
            ),
            (
                "g = 0.9",
                "g = nan",
                "material[1].layered.layer[0].g",
                "NaN",
            ),
            (
                "sigma_s = [2.3, 2.9, 4.4]",
                "sigma_s = [2.3, inf, 4.4]",
                "material[1].layered.layer[1].sigma_s",
                "finite",
            ),
            (
                "sigma_a = [0.03, 0.26, 0.46]",
                "sigma_a = [0.03, -0.26, 0.46]",
                "material[1].layered.layer[1].sigma_a",
                "[0, 1e6]",
            ),
            (
                "sigma_s_prime = [4.7, 5.9, 8.7]",
                "sigma_s_prime = [4.7, 5.9, 8.7]\nsigma_s = [1, 1, 1]",
                "material[1].layered.layer[0].sigma_s_prime",
                "not both",
            ),
            (
                "thickness = 0.25",
                "thickness = -0.25",
                "material[1].layered.layer[0].thickness",
                "rest",
            ),
            (
                "thickness = 0.25",
                "thickness = \"thick\"",
                "material[1].layered.layer[0].thickness",
                "texture",
            ),
            (
                "thickness = 0.25",
                "thickness = 0.25\nthickness_scale = 2",
                "material[1].layered.layer[0].thickness_scale",
                "only a layer",
            ),
            (
                "thickness = 0.25",
                "thickness = \"texture\"",
                "material[1].layered.depth_texture",
                "missing",
            ),
            ("eta = 1.4", "eta = 0", "material[1].layered.eta", "> 0"),
            (
                "weights = [0.2, 0.3, 0.1, 0.1, 0.3]",
                "weights = [0.2, 0.3, -0.1, 0.1, 0.3]",
                "material[1].layered.weights",
                "-0.1",
            ),
            (
                "units_per_mm = 0.1",
                "units_per_mm = inf",
                "material[1].layered.units_per_mm",
                "must be in",
            ),
            (
                "units_per_mm = 0.1",
                "units_per_mm = 1e-33",
                "material[1].layered.units_per_mm",
                "must be in [1e-6",
            ),
            (
                "eta = 1.4",
                "eta = 1.4\npreset = \"apple\"",
                "material[1].layered.preset",
                "not both",
            ),
            (
                "eta = 1.4",
                "eta = 1.4\ndepth_texture = [\"a.exr\", 3]",
                "material[1].layered.depth_texture",
                "array of paths",
            ),
        ];
        for (from, to, key, part) in cases {
            let src = base.replacen(from, to, 1);
            assert_ne!(src, base, "{from}");
            let e = parse(&src).unwrap_err().to_string();
            let leaf = key.rsplit('.').next().unwrap();
            let first = to.lines().find(|l| l.starts_with(leaf)).unwrap_or(to);
            let line = format!("line {}", src.lines().position(|l| l == first).unwrap() + 1);
            let line_ok = key.ends_with("depth_texture") && part == "missing" || e.contains(&line);
            assert!(
                e.contains("test.toml") && line_ok && e.contains(key) && e.contains(part),
                "{to}: {e}"
            );
        }
        // No body, an unknown preset, an unknown key, too many layers.
        let e = parse(&with_layered("[material.layered]\neta = 1.3\n"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("material[1].layered") && e.contains("preset"),
            "{e}"
        );
        let e = parse(&with_layered("[material.layered]\npreset = \"frog\"\n"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("material[1].layered.preset") && e.contains("apple"),
            "{e}"
        );
        let e = parse(&with_layered(
            "[material.layered]\npreset = \"apple\"\ncolour = 1\n",
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("colour"), "{e}");
        let layer =
            "[[material.layered.layer]]\nsigma_a = [0, 0, 0]\nsigma_s = [1, 1, 1]\nthickness = 1\n";
        let e = parse(&with_layered(&format!(
            "[material.layered]\n{}",
            layer.repeat(9)
        )))
        .unwrap_err()
        .to_string();
        assert!(e.contains("9 layers"), "{e}");
    }

    #[test]
    fn a_depth_range_beyond_the_depth_buffer_warns_but_the_scene_loads() {
        let s = MINIMAL.replace("target = [0, 0, 0]", "target = [0, 0, 0]\nnear = 1e-7");
        assert_eq!(parse(&s).unwrap().camera.near, 1e-7);
    }
}
