//! Scene files: TOML, read through serde, validated, and turned into a [`Scene`].
//!
//! The format is documented by `docs/scene-format.toml`, a commented example that the tests load.
//! Every error names the file, the line and the key: syntax errors, unknown keys and wrong types
//! come from the TOML parser (which knows the position); missing files and out-of-range values
//! are checked here, and the line is found from the section and key.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::Deserialize;

use super::generators::{self, Generator};
use super::material::{
    Gaussian, Layer, LayeredMedium, Light, LightKind, Material, PowMode, SssProfile, TextureSource,
    Thickness, ThicknessSource, Translucency,
};
use super::{Camera, Deformation, Object, Scene, MAX_LIGHTS};
use crate::{LucentError, Result};

/// Largest file a scene may be (a scene file is a few kilobytes; this refuses binary garbage).
const MAX_SCENE_FILE_BYTES: u64 = 4 * 1024 * 1024;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneToml {
    name: Option<String>,
    /// Gone: the materials decide the frame. Kept only to explain that.
    technique: Option<toml::Value>,
    ambient: Option<[f32; 3]>,
    environment: Option<EnvironmentToml>,
    sky: Option<[f32; 3]>,
    exposure: Option<f32>,
    camera: CameraToml,
    #[serde(default)]
    mesh: Vec<MeshToml>,
    #[serde(default)]
    material: Vec<MaterialToml>,
    #[serde(default)]
    object: Vec<ObjectToml>,
    #[serde(default)]
    light: Vec<LightToml>,
    deformation: Option<DeformationToml>,
}

/// `[environment]`: the light from everywhere (see [`super::environment`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EnvironmentToml {
    /// `constant`, `hemisphere` or `map`.
    kind: String,
    /// `constant`: the radiance.
    radiance: Option<[f32; 3]>,
    /// `hemisphere`: radiance above the horizon.
    sky: Option<[f32; 3]>,
    /// `hemisphere`: radiance below the horizon.
    ground: Option<[f32; 3]>,
    /// `map`: an equirectangular file (HDR, EXR, PNG, ...).
    file: Option<PathBuf>,
    /// `map`: a built-in map instead of a file (`sky`).
    builtin: Option<String>,
    /// `map`: radiance multiplier (default 1).
    intensity: Option<f32>,
    /// `map`: turn about +y, degrees (default 0).
    rotation_degrees: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraToml {
    eye: [f32; 3],
    target: [f32; 3],
    fov_y_degrees: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshToml {
    name: String,
    obj: Option<PathBuf>,
    generator: Option<String>,
    level: Option<u32>,
    triangles: Option<u64>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum ThicknessToml {
    Value(f32),
    Named(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TranslucencyToml {
    thickness: ThicknessToml,
    color: Option<[f32; 3]>,
    power: Option<f32>,
    distortion: Option<f32>,
    ambient: Option<f32>,
    pow: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SssToml {
    preset: Option<String>,
    /// Rows of `[variance_mm2, r, g, b]`.
    gaussians: Option<Vec<[f32; 4]>>,
    units_per_mm: Option<f32>,
    blur: Option<String>,
}

/// One `[[material.layered.layer]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerToml {
    sigma_a: Option<[f32; 3]>,
    sigma_s: Option<[f32; 3]>,
    sigma_s_prime: Option<[f32; 3]>,
    g: Option<f32>,
    /// A number (mm), `"texture"` or `"rest"`: read by hand for a message naming all three.
    thickness: Option<toml::Value>,
    thickness_scale: Option<f32>,
}

/// `[material.layered]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LayeredToml {
    preset: Option<String>,
    layer: Option<Vec<LayerToml>>,
    eta: Option<f32>,
    weights: Option<[f32; 5]>,
    units_per_mm: Option<f32>,
    /// A path or an array of paths.
    depth_texture: Option<toml::Value>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialToml {
    name: String,
    albedo: Option<[f32; 3]>,
    specular: Option<f32>,
    roughness: Option<f32>,
    albedo_texture: Option<PathBuf>,
    normal_texture: Option<PathBuf>,
    translucency: Option<TranslucencyToml>,
    sss: Option<SssToml>,
    layered: Option<LayeredToml>,
    /// Gone: `[material.layered]` replaced it. Kept only to say so.
    layers: Option<toml::Value>,
}

/// `scale = 2` or `scale = [x, y, z]`. Deserialized by hand: serde's untagged enum would
/// report anything else as "data did not match any variant of untagged enum ScaleToml".
enum ScaleToml {
    Uniform(f32),
    PerAxis([f32; 3]),
}

impl<'de> Deserialize<'de> for ScaleToml {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        const EXPECTED: &str = "one number (uniform) or [x, y, z] (three numbers)";
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ScaleToml;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(EXPECTED)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<ScaleToml, A::Error> {
                let mut values = Vec::new();
                while let Some(v) = seq.next_element::<f32>()? {
                    values.push(v);
                    if values.len() > 3 {
                        break;
                    }
                }
                match <[f32; 3]>::try_from(values.as_slice()) {
                    Ok(v) => Ok(ScaleToml::PerAxis(v)),
                    Err(_) => Err(serde::de::Error::custom(format!(
                        "`scale` must be {EXPECTED}, not an array of {}{} numbers",
                        if values.len() > 3 { "more than " } else { "" },
                        values.len().min(3)
                    ))),
                }
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectToml {
    mesh: String,
    material: String,
    translate: Option<[f32; 3]>,
    rotate_degrees: Option<[f32; 3]>,
    scale: Option<ScaleToml>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightToml {
    #[serde(rename = "type")]
    kind: String,
    color: Option<[f32; 3]>,
    intensity: f32,
    position: Option<[f32; 3]>,
    direction: Option<[f32; 3]>,
    range: Option<f32>,
    inner_degrees: Option<f32>,
    outer_degrees: Option<f32>,
    translucency_scale: Option<f32>,
    shadows: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DeformationToml {
    #[serde(rename = "type")]
    kind: String,
    amplitude: f32,
    frequency: f32,
    speed: f32,
}

/// Where in the file a value sits: `[[section]]` number `index` (or a plain `[section]` /
/// top level when `index` is `None`), key `key`. Used to put line numbers on semantic errors.
struct Locator<'a> {
    path: &'a Path,
    source: &'a str,
}

impl Locator<'_> {
    /// The 1-based line of `key` inside the `index`-th `[[section]]` (or `[section]`, or the
    /// top level for an empty section name), if it can be found. `key` may be dotted
    /// (`sss.units_per_mm`): it is then found in a `[section.sss]` sub-table, as a dotted key,
    /// or inside an inline table `sss = { ... }`. A key not found at its full path is looked
    /// for by its last part anywhere in the section (sub-tables and inline tables included).
    fn line(&self, section: &str, index: Option<usize>, key: &str) -> Option<usize> {
        let (parent, leaf) = match key.rsplit_once('.') {
            Some((parent, leaf)) => (Some(parent), leaf),
            None => (None, key),
        };
        let mut current = (String::new(), 0usize);
        let mut counts: HashMap<String, usize> = HashMap::new();
        // Entries of nested arrays (`[[material.layered.layer]]`) per (array, owner entry).
        let mut nested: HashMap<(String, usize), usize> = HashMap::new();
        let mut fallback = None;
        for (number, raw) in self.source.lines().enumerate() {
            let line = raw.trim();
            if let Some(header) = line.strip_prefix("[[").and_then(|l| l.split("]]").next()) {
                let name = header.trim().to_string();
                // `[[material.layered.layer]]` belongs to the latest `[[material]]` and is
                // numbered within it: its keys sit at `layered.layer[k].key` of that entry.
                let owner = counts
                    .iter()
                    .find(|(array, _)| {
                        name.strip_prefix(array.as_str())
                            .is_some_and(|rest| rest.starts_with('.'))
                    })
                    .map(|(_, n)| n.saturating_sub(1));
                if let Some(owner) = owner {
                    let k = nested.entry((name.clone(), owner)).or_insert(0);
                    current = (format!("{name}[{k}]"), owner);
                    *k += 1;
                    continue;
                }
                let n = counts.entry(name.clone()).or_insert(0);
                current = (name, *n);
                *n += 1;
                continue;
            }
            if let Some(header) = line.strip_prefix('[').and_then(|l| l.split(']').next()) {
                let name = header.trim().to_string();
                // `[material.sss]` belongs to the latest `[[material]]`.
                let owner = counts
                    .iter()
                    .filter(|(array, _)| {
                        name.strip_prefix(array.as_str())
                            .is_some_and(|rest| rest.starts_with('.'))
                    })
                    .map(|(_, n)| n.saturating_sub(1))
                    .next()
                    .unwrap_or(0);
                current = (name, owner);
                continue;
            }
            let (name, i) = &current;
            // Where this table sits inside the section: "" for the section itself.
            let within = if name == section {
                Some("")
            } else if section.is_empty() {
                None
            } else {
                name.strip_prefix(section).and_then(|r| r.strip_prefix('.'))
            };
            let Some(within) = within else { continue };
            if index.is_some_and(|want| *i != want) {
                continue;
            }
            let Some((k, value)) = line.split_once('=') else {
                continue;
            };
            let k = k.trim();
            let full = if within.is_empty() {
                k.to_string()
            } else {
                format!("{within}.{k}")
            };
            if full == key || (parent.is_some_and(|p| p == full) && inline_has(value, leaf)) {
                return Some(number + 1);
            }
            if fallback.is_none() && (k == leaf || inline_has(value, leaf)) {
                fallback = Some(number + 1);
            }
        }
        fallback
    }

    /// An error naming the file, the line (when found) and the key.
    fn error(
        &self,
        section: &str,
        index: Option<usize>,
        key: &str,
        message: impl std::fmt::Display,
    ) -> LucentError {
        let full_key = match (section.is_empty(), index) {
            (true, _) => key.to_string(),
            (false, Some(i)) => format!("{section}[{i}].{key}"),
            (false, None) => format!("{section}.{key}"),
        };
        let location = match self.line(section, index, key) {
            Some(line) => format!("line {line}, key `{full_key}`"),
            None => format!("key `{full_key}`"),
        };
        LucentError::file(self.path, format!("{location}: {message}"))
    }
}

/// Largest `far / near` a scene may have without a warning: the 32-bit float depth buffer
/// (standard, not reversed, depth) then resolves 0.6% of the distance at the far plane.
pub const MAX_DEPTH_RATIO: f32 = 1e5;

/// The warning for a depth range the depth buffer cannot resolve, with the numbers, or `None`.
///
/// With depth `d = f/(f-n) (1 - n/z)` stored as f32 (spacing `2^-24` just below 1), two
/// surfaces at distance `z` are told apart when they are `z^2 2^-24 / n` apart, and a surface
/// beyond `n 2^25` gets the depth the buffer is cleared to (1) and fails the depth test: it
/// vanishes. `distance` is the camera's distance to its target, where the step is reported.
pub fn depth_range_warning(near: f32, far: f32, distance: f32) -> Option<String> {
    let ratio = far / near;
    if ratio <= MAX_DEPTH_RATIO {
        return None;
    }
    // f64: near 1e-7 squared and divided must not round to 0 or overflow.
    let (n, f, d) = (
        f64::from(near),
        f64::from(far),
        f64::from(distance).min(f64::from(far)),
    );
    let step = d * d * 2f64.powi(-24) / n;
    let lost = n * 2f64.powi(25);
    let vanish = if lost < f {
        format!(
            "; surfaces farther than {lost:.3} from the camera get the far plane's depth and \
             vanish"
        )
    } else {
        String::new()
    };
    // Tiny and huge numbers in exponent form (`1e-7`, not `0.0000001`).
    let num = |x: f64| {
        if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
            format!("{x:.3e}")
        } else {
            format!("{x:.3}")
        }
    };
    Some(format!(
        "near = {near:e} and far = {far} (far/near = {ratio:.1e}) is more than the 32-bit depth \
         buffer resolves: at the target's distance ({}) its step is {}, so surfaces closer \
         together than that are not told apart{vanish}; raise `near` or lower `far` to keep \
         far/near under {MAX_DEPTH_RATIO:.0e}",
        num(d),
        num(step)
    ))
}

/// Whether the value text of a line is an inline table with `key = ...` in it.
fn inline_has(value: &str, key: &str) -> bool {
    value.trim_start().starts_with('{')
        && value.match_indices(key).any(|(at, _)| {
            let before = value[..at].trim_end().chars().last();
            let after = value[at + key.len()..].trim_start();
            matches!(before, Some('{' | ',')) && after.starts_with('=')
        })
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
        let table = error.span().and_then(|span| {
            // The span may start at the blank line before the table: skip to its text.
            let text = source.get(span.clone())?;
            let start = span.start + (text.len() - text.trim_start().len());
            let before = source.get(..start)?;
            Some(format!("line {}: ", before.matches('\n').count() + 1))
        });
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
    let at = Locator { path, source };
    if raw.technique.is_some() {
        return Err(at.error(
            "",
            None,
            "technique",
            "the scene-level `technique` key is gone: each material's parts decide what the \
             frame shades (translucency, [material.sss] with its `blur`); remove the key, and \
             use `--technique` on the command line for A/B comparisons",
        ));
    }
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let resolve = |p: &Path| {
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            base.join(p)
        }
    };

    let finite3 = |v: [f32; 3]| v.iter().all(|c| c.is_finite());
    let check3 = |section: &str,
                  index: Option<usize>,
                  key: &str,
                  v: Option<[f32; 3]>,
                  min: f32|
     -> Result<()> {
        if let Some(v) = v {
            if !finite3(v) || v.iter().any(|&c| c < min) {
                return Err(at.error(
                    section,
                    index,
                    key,
                    format!(
                        "{v:?} must be finite{}",
                        if min.is_finite() {
                            format!(" and >= {min}")
                        } else {
                            String::new()
                        }
                    ),
                ));
            }
        }
        Ok(())
    };

    // Camera.
    let cam = &raw.camera;
    check3("camera", None, "eye", Some(cam.eye), f32::NEG_INFINITY)?;
    check3(
        "camera",
        None,
        "target",
        Some(cam.target),
        f32::NEG_INFINITY,
    )?;
    let fov = cam.fov_y_degrees.unwrap_or(45.0);
    if !(fov > 1.0 && fov < 179.0) {
        return Err(at.error(
            "camera",
            None,
            "fov_y_degrees",
            format!("{fov} must be between 1 and 179"),
        ));
    }
    let near = cam.near.unwrap_or(0.1);
    let far = cam.far.unwrap_or(100.0);
    if !(near > 0.0 && near.is_finite()) {
        return Err(at.error("camera", None, "near", format!("{near} must be > 0")));
    }
    if !(far > near && far.is_finite()) {
        return Err(at.error(
            "camera",
            None,
            "far",
            format!("{far} must be finite and > near ({near})"),
        ));
    }
    if Vec3::from(cam.eye).distance(Vec3::from(cam.target)) < 1e-6 {
        return Err(at.error("camera", None, "target", "must differ from eye"));
    }
    if let Some(warning) = depth_range_warning(
        near,
        far,
        Vec3::from(cam.eye).distance(Vec3::from(cam.target)),
    ) {
        log::warn!("{}", at.error("camera", None, "near", warning));
    }

    // Meshes. An OBJ whose faces use MTL materials with a colour or texture becomes one part
    // per material (each drawn with its `Kd` and `map_Kd`); every other mesh is one part.
    let mut meshes = Vec::new();
    let mut mesh_parts: Vec<Vec<(usize, Option<super::obj::ObjMaterial>)>> = Vec::new();
    let mut mesh_index: HashMap<&str, usize> = HashMap::new();
    for (i, m) in raw.mesh.iter().enumerate() {
        if mesh_index.insert(m.name.as_str(), i).is_some() {
            return Err(at.error(
                "mesh",
                Some(i),
                "name",
                format!("mesh '{}' is defined twice", m.name),
            ));
        }
        let mesh = match (&m.obj, &m.generator) {
            (Some(obj), None) => {
                let obj_path = resolve(obj);
                if !obj_path.exists() {
                    return Err(at.error(
                        "mesh",
                        Some(i),
                        "obj",
                        format!("mesh file {} not found", obj_path.display()),
                    ));
                }
                let loaded = super::obj::load_obj(&obj_path)?;
                let mut parts = Vec::new();
                for (part, material) in loaded.parts() {
                    meshes.push(part);
                    parts.push((meshes.len() - 1, material.cloned()));
                }
                mesh_parts.push(parts);
                continue;
            }
            (None, Some(name)) => {
                let generator = Generator::parse(name)
                    .map_err(|e| at.error("mesh", Some(i), "generator", e))?;
                match (m.level, m.triangles) {
                    (Some(_), Some(_)) => {
                        return Err(at.error(
                            "mesh",
                            Some(i),
                            "triangles",
                            "give `level` or `triangles`, not both",
                        ))
                    }
                    (_, Some(t)) => {
                        generators::generate_with_triangles(generator, t)
                            .map_err(|e| at.error("mesh", Some(i), "triangles", e))?
                            .0
                    }
                    (level, None) => generators::generate(generator, level.unwrap_or(2))
                        .map_err(|e| at.error("mesh", Some(i), "level", e))?,
                }
            }
            _ => {
                return Err(at.error(
                    "mesh",
                    Some(i),
                    "name",
                    format!(
                        "mesh '{}' needs exactly one of `obj` or `generator`",
                        m.name
                    ),
                ))
            }
        };
        meshes.push(mesh);
        mesh_parts.push(vec![(meshes.len() - 1, None)]);
    }

    // Materials.
    let mut materials: HashMap<&str, Material> = HashMap::new();
    for (i, m) in raw.material.iter().enumerate() {
        let material = build_material(m, i, &at, &resolve)?;
        if materials.insert(m.name.as_str(), material).is_some() {
            return Err(at.error(
                "material",
                Some(i),
                "name",
                format!("material '{}' is defined twice", m.name),
            ));
        }
    }

    // Objects.
    let mut objects = Vec::new();
    for (i, o) in raw.object.iter().enumerate() {
        let mesh_entry = *mesh_index.get(o.mesh.as_str()).ok_or_else(|| {
            at.error(
                "object",
                Some(i),
                "mesh",
                format!("no mesh named '{}'", o.mesh),
            )
        })?;
        let material = materials
            .get(o.material.as_str())
            .ok_or_else(|| {
                at.error(
                    "object",
                    Some(i),
                    "material",
                    format!("no material named '{}'", o.material),
                )
            })?
            .clone();
        check3(
            "object",
            Some(i),
            "translate",
            o.translate,
            f32::NEG_INFINITY,
        )?;
        check3(
            "object",
            Some(i),
            "rotate_degrees",
            o.rotate_degrees,
            f32::NEG_INFINITY,
        )?;
        let scale = match o.scale {
            None => Vec3::ONE,
            Some(ScaleToml::Uniform(s)) => Vec3::splat(s),
            Some(ScaleToml::PerAxis(s)) => Vec3::from(s),
        };
        if !(scale.is_finite() && scale.min_element() > 0.0) {
            return Err(at.error(
                "object",
                Some(i),
                "scale",
                format!("{scale} must be finite and > 0"),
            ));
        }
        let r = Vec3::from(o.rotate_degrees.unwrap_or_default());
        let rotation = Quat::from_euler(
            EulerRot::XYZ,
            r.x.to_radians(),
            r.y.to_radians(),
            r.z.to_radians(),
        );
        let transform = Mat4::from_scale_rotation_translation(
            scale,
            rotation,
            Vec3::from(o.translate.unwrap_or_default()),
        );
        let explicit_albedo = raw
            .material
            .iter()
            .find(|m| m.name == o.material)
            .is_some_and(|m| m.albedo.is_some());
        for (mesh, obj_material) in &mesh_parts[mesh_entry] {
            let material = match obj_material {
                Some(m) => with_mtl(&material, m, explicit_albedo),
                None => material.clone(),
            };
            objects.push(Object {
                mesh: *mesh,
                transform,
                material,
            });
        }
    }
    if objects.is_empty() {
        return Err(LucentError::file(
            path,
            "the scene has no [[object]]: nothing to draw",
        ));
    }

    // Lights.
    if raw.light.len() > MAX_LIGHTS {
        return Err(at.error(
            "light",
            Some(MAX_LIGHTS),
            "type",
            format!(
                "{} lights; at most {MAX_LIGHTS} are supported",
                raw.light.len()
            ),
        ));
    }
    let mut lights = Vec::new();
    for (i, l) in raw.light.iter().enumerate() {
        let need = |v: Option<[f32; 3]>, key: &str| -> Result<Vec3> {
            let v = v.ok_or_else(|| {
                at.error(
                    "light",
                    Some(i),
                    key,
                    format!("a {} light needs `{key}`", l.kind),
                )
            })?;
            check3("light", Some(i), key, Some(v), f32::NEG_INFINITY)?;
            Ok(Vec3::from(v))
        };
        let range = l.range.unwrap_or(20.0);
        // Checked here so the message names `range` itself (the light's own check names the
        // position and range together).
        if !(range.is_finite() && range > 0.0) {
            return Err(at.error(
                "light",
                Some(i),
                "range",
                format!(
                    "{range} must be finite and > 0 (the distance at which the light's \
                     contribution falls to zero)"
                ),
            ));
        }
        let kind = match l.kind.as_str() {
            "directional" => LightKind::Directional {
                direction: need(l.direction, "direction")?,
            },
            "point" => LightKind::Point {
                position: need(l.position, "position")?,
                range,
            },
            "spot" => LightKind::Spot {
                position: need(l.position, "position")?,
                direction: need(l.direction, "direction")?,
                range,
                inner_degrees: l.inner_degrees.unwrap_or(20.0),
                outer_degrees: l.outer_degrees.unwrap_or(30.0),
            },
            other => {
                return Err(at.error(
                    "light",
                    Some(i),
                    "type",
                    format!("unknown light type '{other}'; use point, spot or directional"),
                ))
            }
        };
        check3("light", Some(i), "color", l.color, 0.0)?;
        let light = Light {
            kind,
            color: Vec3::from(l.color.unwrap_or([1.0; 3])),
            intensity: l.intensity,
            translucency_scale: l.translucency_scale.unwrap_or(1.0),
            shadows: l.shadows.unwrap_or(true),
        };
        // Map the validation failure back to the key it is about.
        light.validate("light").map_err(|e| {
            let message = e.to_string();
            let key = [
                "intensity",
                "translucency_scale",
                "range",
                "direction",
                "position",
                "color",
            ]
            .into_iter()
            .find(|k| message.contains(k))
            .unwrap_or(if message.contains("angles") {
                "outer_degrees"
            } else {
                "type"
            });
            at.error("light", Some(i), key, message.trim_start_matches("light: "))
        })?;
        lights.push(light);
    }

    let deformation = match &raw.deformation {
        None => None,
        Some(d) if d.kind == "wave" => {
            for (key, v) in [
                ("amplitude", d.amplitude),
                ("frequency", d.frequency),
                ("speed", d.speed),
            ] {
                if !v.is_finite() {
                    return Err(at.error("deformation", None, key, format!("{v} must be finite")));
                }
            }
            Some(Deformation::Wave {
                amplitude: d.amplitude,
                frequency: d.frequency,
                speed: d.speed,
            })
        }
        Some(d) => {
            return Err(at.error(
                "deformation",
                None,
                "type",
                format!("unknown deformation '{}'; use wave", d.kind),
            ))
        }
    };

    check3("", None, "ambient", raw.ambient, 0.0)?;
    check3("", None, "sky", raw.sky, 0.0)?;
    let environment = match (&raw.environment, raw.ambient) {
        (Some(_), Some(_)) => {
            return Err(at.error(
                "",
                None,
                "ambient",
                "give either `ambient` (a constant radiance) or an `[environment]` table, not both",
            ))
        }
        (None, ambient) => super::Environment::constant(Vec3::from(ambient.unwrap_or([0.03; 3]))),
        (Some(e), None) => {
            let section = "environment";
            check3(section, None, "radiance", e.radiance, 0.0)?;
            check3(section, None, "sky", e.sky, 0.0)?;
            check3(section, None, "ground", e.ground, 0.0)?;
            // Keys that belong to another kind are refused, not ignored: a parsed key does
            // what it says or is an error.
            let refuse = |keys: &[(&str, bool)]| -> Result<()> {
                match keys.iter().find(|(_, given)| *given) {
                    Some((key, _)) => Err(at.error(
                        section,
                        None,
                        key,
                        format!("`{key}` does not apply to kind = \"{}\"", e.kind),
                    )),
                    None => Ok(()),
                }
            };
            let map_keys = [
                ("file", e.file.is_some()),
                ("builtin", e.builtin.is_some()),
                ("intensity", e.intensity.is_some()),
                ("rotation_degrees", e.rotation_degrees.is_some()),
            ];
            match e.kind.as_str() {
                "constant" => {
                    refuse(&[("sky", e.sky.is_some()), ("ground", e.ground.is_some())])?;
                    refuse(&map_keys)?;
                    let radiance = e.radiance.ok_or_else(|| {
                        at.error(
                            section,
                            None,
                            "radiance",
                            "kind = \"constant\" needs `radiance`",
                        )
                    })?;
                    super::Environment::constant(Vec3::from(radiance))
                }
                "hemisphere" => {
                    refuse(&[("radiance", e.radiance.is_some())])?;
                    refuse(&map_keys)?;
                    let (Some(sky), Some(ground)) = (e.sky, e.ground) else {
                        return Err(at.error(
                            section,
                            None,
                            if e.sky.is_none() { "sky" } else { "ground" },
                            "kind = \"hemisphere\" needs `sky` and `ground`",
                        ));
                    };
                    super::Environment::hemisphere(Vec3::from(sky), Vec3::from(ground))
                }
                "map" => {
                    refuse(&[
                        ("radiance", e.radiance.is_some()),
                        ("sky", e.sky.is_some()),
                        ("ground", e.ground.is_some()),
                    ])?;
                    let intensity = e.intensity.unwrap_or(1.0);
                    if !(intensity.is_finite() && intensity >= 0.0) {
                        return Err(at.error(
                            section,
                            None,
                            "intensity",
                            format!("{intensity} must be finite and >= 0"),
                        ));
                    }
                    let rotation = e.rotation_degrees.unwrap_or(0.0);
                    if !rotation.is_finite() {
                        return Err(at.error(
                            section,
                            None,
                            "rotation_degrees",
                            format!("{rotation} must be finite"),
                        ));
                    }
                    match (&e.file, &e.builtin) {
                        (Some(file), None) => {
                            super::Environment::from_file(&resolve(file), intensity, rotation)?
                        }
                        (None, Some(name)) if name == super::environment::BUILTIN_SKY => {
                            super::Environment::builtin_sky(intensity, rotation)?
                        }
                        (None, Some(name)) => {
                            return Err(at.error(
                                section,
                                None,
                                "builtin",
                                format!(
                                    "unknown built-in map '{name}'; available: {}",
                                    super::environment::BUILTIN_SKY
                                ),
                            ))
                        }
                        _ => {
                            return Err(at.error(
                                section,
                                None,
                                "file",
                                "kind = \"map\" needs exactly one of `file` and `builtin`",
                            ))
                        }
                    }
                }
                other => {
                    return Err(at.error(
                        section,
                        None,
                        "kind",
                        format!(
                            "unknown environment kind '{other}'; use constant, hemisphere or map"
                        ),
                    ))
                }
            }
        }
    };
    let exposure = raw.exposure.unwrap_or(1.0);
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(at.error(
            "",
            None,
            "exposure",
            format!("{exposure} must be finite and > 0"),
        ));
    }
    let name = raw.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into())
    });
    Ok(Scene {
        name,
        meshes,
        objects,
        lights,
        camera: Camera {
            eye: Vec3::from(cam.eye),
            target: Vec3::from(cam.target),
            fov_y_degrees: fov,
            near,
            far,
        },
        environment,
        sky: Vec3::from(raw.sky.unwrap_or([0.15, 0.2, 0.3])),
        exposure,
        deformation,
        time: 0.0,
    })
}

/// `material` on the faces of an OBJ part whose MTL material is `mtl`: the MTL's `map_Kd`
/// becomes the albedo texture unless the scene's material has one, and its `Kd` the albedo
/// unless the scene's material sets `albedo` (clamped to [0, 1], which is all a reflectance
/// can be).
fn with_mtl(material: &Material, mtl: &super::obj::ObjMaterial, explicit_albedo: bool) -> Material {
    let mut m = material.clone();
    m.name = format!("{} ({})", material.name, mtl.name);
    if m.albedo_texture.is_none() {
        if let Some(t) = &mtl.diffuse_texture {
            m.albedo_texture = Some(TextureSource::File(t.clone()));
        }
    }
    if let (false, Some(kd)) = (explicit_albedo, mtl.diffuse) {
        let clamped = kd.clamp(Vec3::ZERO, Vec3::ONE);
        if clamped != kd {
            log::warn!(
                "MTL material '{}': Kd {kd} clamped to {clamped} (a reflectance is in [0, 1])",
                mtl.name
            );
        }
        m.albedo = clamped;
    }
    m
}

/// `[material.layered]` of material `i` as a checked [`LayeredMedium`]: every bad value is an
/// error naming its key (`material[1].layered.layer[0].g`), every key does something or is
/// refused.
fn build_layered(
    l: &LayeredToml,
    i: usize,
    at: &Locator<'_>,
    resolve: &dyn Fn(&Path) -> PathBuf,
) -> Result<LayeredMedium> {
    use super::layered::{sigma_s_from_reduced, MAX_ABS_G, MAX_COEFFICIENT, MAX_LAYERS};
    let err = |key: &str, message: String| at.error("material", Some(i), key, message);
    let mut medium = match (&l.preset, &l.layer) {
        (Some(p), None) => {
            LayeredMedium::preset(p).map_err(|e| err("layered.preset", e.to_string()))?
        }
        (None, Some(layers)) => {
            if !(1..=MAX_LAYERS).contains(&layers.len()) {
                return Err(err(
                    "layered.layer",
                    format!(
                        "{} layers; 1 to {MAX_LAYERS} [[material.layered.layer]] tables are \
                         supported",
                        layers.len()
                    ),
                ));
            }
            let mut out = Vec::new();
            for (k, t) in layers.iter().enumerate() {
                let key = |leaf: &str| format!("layered.layer[{k}].{leaf}");
                let coefficient = |leaf: &str, v: [f32; 3]| -> Result<Vec3> {
                    if v.iter()
                        .all(|c| c.is_finite() && (0.0..=MAX_COEFFICIENT).contains(c))
                    {
                        Ok(Vec3::from(v))
                    } else {
                        Err(err(
                            &key(leaf),
                            format!("{v:?} must be finite and in [0, {MAX_COEFFICIENT:e}] (mm^-1)"),
                        ))
                    }
                };
                let sigma_a = match t.sigma_a {
                    Some(v) => coefficient("sigma_a", v)?,
                    None => {
                        return Err(err(
                            &format!("layered.layer[{k}]"),
                            "missing `sigma_a` (absorption, RGB, mm^-1)".into(),
                        ))
                    }
                };
                let g = t.g.unwrap_or(0.0);
                if !(g.is_finite() && g.abs() <= MAX_ABS_G) {
                    return Err(err(
                        &key("g"),
                        format!(
                            "{g} must be in [-{MAX_ABS_G}, {MAX_ABS_G}] (Henyey-Greenstein \
                             anisotropy; |g| = 1 is a delta)"
                        ),
                    ));
                }
                let sigma_s = match (t.sigma_s, t.sigma_s_prime) {
                    (Some(v), None) => coefficient("sigma_s", v)?,
                    (None, Some(v)) => {
                        let s = sigma_s_from_reduced(coefficient("sigma_s_prime", v)?, g);
                        if s.max_element() > MAX_COEFFICIENT {
                            return Err(err(
                                &key("sigma_s_prime"),
                                format!("{v:?} / (1 - g) = {s} exceeds {MAX_COEFFICIENT:e} mm^-1"),
                            ));
                        }
                        s
                    }
                    (Some(_), Some(_)) => {
                        return Err(err(
                            &key("sigma_s_prime"),
                            "give `sigma_s` or the reduced `sigma_s_prime`, not both".into(),
                        ))
                    }
                    (None, None) => {
                        return Err(err(
                            &format!("layered.layer[{k}]"),
                            "missing `sigma_s` (or the reduced `sigma_s_prime`), RGB, mm^-1".into(),
                        ))
                    }
                };
                const THICKNESS: &str =
                    "a number of mm (>= 0), \"texture\" (per texel from depth_texture) or \
                     \"rest\" (semi-infinite, last layer only)";
                let thickness = match &t.thickness {
                    None => {
                        return Err(err(
                            &format!("layered.layer[{k}]"),
                            format!("missing `thickness`: {THICKNESS}"),
                        ))
                    }
                    Some(toml::Value::Float(v)) => Thickness::Mm(*v as f32),
                    Some(toml::Value::Integer(v)) => Thickness::Mm(*v as f32),
                    Some(toml::Value::String(s)) if s == "rest" => Thickness::Rest,
                    Some(toml::Value::String(s)) if s == "texture" => Thickness::Texture {
                        scale: t.thickness_scale.unwrap_or(1.0),
                    },
                    Some(other) => {
                        return Err(err(
                            &key("thickness"),
                            format!("{other} must be {THICKNESS}"),
                        ))
                    }
                };
                match thickness {
                    Thickness::Mm(v) if !(v.is_finite() && v >= 0.0) => {
                        return Err(err(&key("thickness"), format!("{v} must be {THICKNESS}")))
                    }
                    Thickness::Rest if k + 1 != layers.len() => {
                        return Err(err(
                            &key("thickness"),
                            format!(
                                "\"rest\" (semi-infinite) is allowed only on the last layer \
                                 (layer[{}])",
                                layers.len() - 1
                            ),
                        ))
                    }
                    Thickness::Texture { scale } if !(scale.is_finite() && scale > 0.0) => {
                        return Err(err(
                            &key("thickness_scale"),
                            format!("{scale} must be finite and > 0 (mm per texel unit)"),
                        ))
                    }
                    Thickness::Mm(_) | Thickness::Rest if t.thickness_scale.is_some() => {
                        return Err(err(
                            &key("thickness_scale"),
                            "only a layer with thickness = \"texture\" reads a scale".into(),
                        ))
                    }
                    _ => {}
                }
                out.push(Layer {
                    sigma_a,
                    sigma_s,
                    g,
                    thickness,
                });
            }
            let mut medium = LayeredMedium::homogeneous("custom", Vec3::ZERO, Vec3::ZERO, 0.0, 1.3);
            medium.layers = out;
            medium
        }
        (Some(_), Some(_)) => {
            return Err(err(
                "layered.preset",
                "give a `preset` or [[material.layered.layer]] tables, not both".into(),
            ))
        }
        (None, None) => {
            return Err(err(
                "layered",
                "give a `preset` or [[material.layered.layer]] tables".into(),
            ))
        }
    };
    if let Some(eta) = l.eta {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(err(
                "layered.eta",
                format!("{eta} must be finite and > 0 (relative index; 1 = no boundary)"),
            ));
        }
        medium.eta = eta;
    }
    if let Some(w) = l.weights {
        if let Some(bad) = w.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(err(
                "layered.weights",
                format!(
                    "{w:?}: {bad} must be finite and >= 0 (lambda_1..lambda_5 of Li et al.'s \
                     eq. 3: diffuse, specular, transmitted, single, multiple)"
                ),
            ));
        }
        medium.weights = w;
    }
    if let Some(u) = l.units_per_mm {
        let range = super::layered::UNITS_PER_MM_RANGE;
        if !(u.is_finite() && range.contains(&u)) {
            return Err(err(
                "layered.units_per_mm",
                format!(
                    "{u} must be in [{:e}, {:e}] (scene units per millimetre: 1 when a unit is \
                     a millimetre, 0.001 when it is a metre)",
                    range.start(),
                    range.end()
                ),
            ));
        }
        medium.units_per_mm = u;
    }
    let needed = medium.depth_textures_needed();
    if let Some(v) = &l.depth_texture {
        let paths: Vec<&str> = match v {
            toml::Value::String(s) => vec![s.as_str()],
            toml::Value::Array(a) if a.iter().all(|x| x.is_str()) => {
                a.iter().filter_map(|x| x.as_str()).collect()
            }
            other => {
                return Err(err(
                    "layered.depth_texture",
                    format!("{other} must be a path or an array of paths"),
                ))
            }
        };
        if needed == 0 {
            return Err(err(
                "layered.depth_texture",
                "no layer reads it: give a layer thickness = \"texture\" or remove the key".into(),
            ));
        }
        if paths.len() != needed {
            return Err(err(
                "layered.depth_texture",
                format!(
                    "{} textures given, the layers read {needed} (layer i with thickness = \
                     \"texture\" reads channel i % 4 of texture i / 4)",
                    paths.len()
                ),
            ));
        }
        for p in paths {
            let full = resolve(Path::new(p));
            if !full.exists() {
                return Err(err(
                    "layered.depth_texture",
                    format!("depth texture {} not found", full.display()),
                ));
            }
            medium.depth_textures.push(TextureSource::File(full));
        }
    } else if needed > 0 {
        return Err(err(
            "layered.depth_texture",
            format!(
                "missing: {needed} depth texture(s) for the layers with thickness = \"texture\""
            ),
        ));
    }
    // Everything was checked above; this names what a future field would miss.
    medium
        .validate()
        .map_err(|e| err("layered", e.to_string()))?;
    Ok(medium)
}

fn build_material(
    m: &MaterialToml,
    i: usize,
    at: &Locator<'_>,
    resolve: &dyn Fn(&Path) -> PathBuf,
) -> Result<Material> {
    let texture = |p: &Option<PathBuf>, key: &str| -> Result<Option<TextureSource>> {
        match p {
            None => Ok(None),
            Some(p) => {
                let full = resolve(p);
                if !full.exists() {
                    return Err(at.error(
                        "material",
                        Some(i),
                        key,
                        format!("texture {} not found", full.display()),
                    ));
                }
                Ok(Some(TextureSource::File(full)))
            }
        }
    };
    let mut material = Material::opaque(
        &m.name,
        Vec3::from(m.albedo.unwrap_or([0.8; 3])),
        m.specular.unwrap_or(0.5),
        m.roughness.unwrap_or(0.5),
    );
    material.albedo_texture = texture(&m.albedo_texture, "albedo_texture")?;
    material.normal_texture = texture(&m.normal_texture, "normal_texture")?;
    if let Some(t) = &m.translucency {
        let thickness = match &t.thickness {
            ThicknessToml::Value(v) => ThicknessSource::Constant(*v),
            ThicknessToml::Named(s) if s == "bake" => ThicknessSource::Bake,
            ThicknessToml::Named(s) if s == "vertex" => ThicknessSource::PerVertex,
            ThicknessToml::Named(s) => {
                let full = resolve(Path::new(s));
                if !full.exists() {
                    return Err(at.error("material", Some(i), "thickness", format!("thickness texture {} not found (or use a number, \"bake\" or \"vertex\")", full.display())));
                }
                ThicknessSource::Texture(TextureSource::File(full))
            }
        };
        let mut translucency = Translucency::new(thickness);
        if let Some(c) = t.color {
            translucency.color = Vec3::from(c);
        }
        translucency.power = t.power.unwrap_or(translucency.power);
        translucency.distortion = t.distortion.unwrap_or(translucency.distortion);
        translucency.ambient = t.ambient.unwrap_or(translucency.ambient);
        translucency.pow_mode = match t.pow.as_deref() {
            None | Some("exact") => PowMode::Exact,
            Some("exp2") => PowMode::SphericalGaussian,
            Some("exp2-scaled") => PowMode::SphericalGaussianScaled,
            Some(other) => {
                return Err(at.error(
                    "material",
                    Some(i),
                    "pow",
                    format!("unknown pow mode '{other}'; use exact, exp2 or exp2-scaled"),
                ))
            }
        };
        material.translucency = Some(translucency);
    }
    if let Some(s) = &m.sss {
        let mut profile = match (&s.preset, &s.gaussians) {
            (Some(p), None) => {
                SssProfile::preset(p).map_err(|e| at.error("material", Some(i), "preset", e))?
            }
            (None, Some(rows)) => SssProfile {
                name: "custom".into(),
                gaussians: rows
                    .iter()
                    .map(|r| Gaussian {
                        variance: r[0],
                        weight: Vec3::new(r[1], r[2], r[3]),
                    })
                    .collect(),
                units_per_mm: 0.01,
                blur: None,
            },
            _ => {
                return Err(at.error(
                    "material",
                    Some(i),
                    "sss",
                    "give exactly one of `preset` or `gaussians`",
                ))
            }
        };
        if let Some(u) = s.units_per_mm {
            if !(u.is_finite() && u > 0.0) {
                return Err(at.error(
                    "material",
                    Some(i),
                    "sss.units_per_mm",
                    format!(
                        "{u} must be finite and > 0 (scene units per millimetre of the \
                         profile: 1 when a scene unit is a millimetre, 0.001 when it is a \
                         metre)"
                    ),
                ));
            }
            profile.units_per_mm = u;
        }
        if let Some(b) = &s.blur {
            profile.blur = Some(
                crate::scene::material::SssBlur::parse(b)
                    .map_err(|e| at.error("material", Some(i), "blur", e))?,
            );
        }
        profile.validate().map_err(|e| {
            at.error(
                "material",
                Some(i),
                if s.gaussians.is_some() {
                    "gaussians"
                } else {
                    "units_per_mm"
                },
                e,
            )
        })?;
        material.sss = Some(profile);
    }
    if m.layers.is_some() {
        return Err(at.error(
            "material",
            Some(i),
            "layers",
            "`layers` is now `[material.layered]` with a `preset` (Jensen 2001 media: apple, \
             skin1, ...) or `[[material.layered.layer]]` tables (see docs/scene-format.toml)",
        ));
    }
    if let Some(l) = &m.layered {
        material.layers = Some(build_layered(l, i, at, resolve)?);
    }
    // Map a range failure to the key it names.
    material.validate().map_err(|e| {
        let message = e.to_string();
        let key = [
            "albedo",
            "specular",
            "roughness",
            "power",
            "distortion",
            "ambient",
            "thickness",
            "color",
        ]
        .into_iter()
        .find(|k| message.contains(k))
        .unwrap_or("name");
        at.error("material", Some(i), key, message)
    })?;
    Ok(material)
}

/// Loads a scene by built-in name, or from a `.toml` file when `name_or_path` ends in `.toml`
/// or names an existing file. Only parses and checks: thickness the materials ask to bake or
/// sample is prepared by the caller ([`crate::bake::scene::prepare_thickness`]).
pub fn load_scene(name_or_path: &str) -> Result<Scene> {
    let path = Path::new(name_or_path);
    // Anything at that path but a directory is the user's file (a FIFO or device named as a
    // scene gets the loader's "not a regular file" error, not "unknown scene").
    if name_or_path.ends_with(".toml") || (path.exists() && !path.is_dir()) {
        load_scene_file(path)
    } else {
        super::builtin(name_or_path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn depth_ranges_beyond_the_depth_buffer_warn_with_the_numbers() {
        assert_eq!(depth_range_warning(0.1, 100.0, 5.0), None);
        let w = depth_range_warning(1e-7, 100.0, 5.0).unwrap();
        assert!(
            w.contains("near = 1e-7")
                && w.contains("far/near = 1.0e9")
                && w.contains("vanish")
                && w.contains("3.355")
                && w.contains("step is 14.901"),
            "{w}"
        );
        // Beyond the limit but nothing vanishes: the step is reported, not a vanishing distance.
        let w = depth_range_warning(1e-3, 200.0, 10.0).unwrap();
        assert!(w.contains("2.0e5") && !w.contains("vanish"), "{w}");
        // The scene still loads.
        let s = MINIMAL.replace("target = [0, 0, 0]", "target = [0, 0, 0]\nnear = 1e-7");
        assert_eq!(parse(&s).unwrap().camera.near, 1e-7);
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
}
