//! The scene file's tables turned into the scene's parts, one function per table (`[camera]`,
//! `[[mesh]]`, `[[object]]`, `[[light]]`, `[deformation]`, `[environment]`): each checks its
//! values and names the key and line of the first bad one. Materials are [`super::materials`].

use std::collections::HashMap;

use glam::{EulerRot, Mat4, Quat, Vec3};
use toml::Spanned;

use super::schema::{
    CameraToml, DeformationToml, EnvironmentToml, LightToml, MaterialToml, MeshToml, ObjectToml,
    ScaleToml,
};
use super::{span, value, SceneFile};
use crate::scene::camera_range::depth_range_warning;
use crate::scene::generators::{self, Generator};
use crate::scene::material::{Light, LightKind, Material};
use crate::scene::obj::{self, ObjMaterial};
use crate::scene::{environment, Camera, Deformation, Environment, Mesh, Object, MAX_LIGHTS};
use crate::{LucentError, Result};

/// `[camera]`, checked; a depth range the depth buffer cannot resolve is a warning.
pub(super) fn camera(file: &SceneFile<'_>, cam: &CameraToml) -> Result<Camera> {
    let at = file.table("camera", None);
    at.check3("eye", Some(&cam.eye), f32::NEG_INFINITY)?;
    at.check3("target", Some(&cam.target), f32::NEG_INFINITY)?;
    let fov = value(&cam.fov_y_degrees).unwrap_or(45.0);
    if !(fov > 1.0 && fov < 179.0) {
        return Err(at.error(
            "fov_y_degrees",
            span(&cam.fov_y_degrees),
            format!("{fov} must be between 1 and 179"),
        ));
    }
    let near = value(&cam.near).unwrap_or(0.1);
    let far = value(&cam.far).unwrap_or(100.0);
    if !(near > 0.0 && near.is_finite()) {
        return Err(at.error("near", span(&cam.near), format!("{near} must be > 0")));
    }
    if !(far > near && far.is_finite()) {
        return Err(at.error(
            "far",
            span(&cam.far),
            format!("{far} must be finite and > near ({near})"),
        ));
    }
    let eye = Vec3::from(*cam.eye.get_ref());
    let target = Vec3::from(*cam.target.get_ref());
    if eye.distance(target) < 1e-6 {
        return Err(at.error("target", Some(cam.target.span()), "must differ from eye"));
    }
    if let Some(warning) = depth_range_warning(near, far, eye.distance(target)) {
        log::warn!("{}", at.error("near", span(&cam.near), warning));
    }
    Ok(Camera {
        eye,
        target,
        fov_y_degrees: fov,
        near,
        far,
    })
}

/// The `[[mesh]]` tables: every mesh drawn, and each table's parts of it.
pub(super) struct Meshes<'a> {
    pub(super) meshes: Vec<Mesh>,
    /// Per table: the parts. An OBJ whose faces use MTL materials with a colour or texture is
    /// one part per material (each drawn with its `Kd` and `map_Kd`); a glTF asset one part
    /// per primitive a node draws; every other mesh is one part.
    parts: Vec<Vec<Part>>,
    /// The table of each mesh name.
    index: HashMap<&'a str, usize>,
}

/// One part of a `[[mesh]]`: an index into [`Meshes::meshes`] and where its material and
/// placement come from.
struct Part {
    mesh: usize,
    source: PartSource,
}

enum PartSource {
    /// A generated mesh or an OBJ part without an MTL material.
    Plain,
    /// An OBJ part whose faces use this MTL material.
    Mtl(ObjMaterial),
    /// A glTF primitive: its node's transform (asset space) and its material.
    Gltf(Mat4, Box<Material>),
}

/// The `[[mesh]]` tables: OBJ files loaded, generators run.
pub(super) fn meshes<'a>(file: &SceneFile<'_>, tables: &'a [MeshToml]) -> Result<Meshes<'a>> {
    let mut out = Meshes {
        meshes: Vec::new(),
        parts: Vec::new(),
        index: HashMap::new(),
    };
    for (i, m) in tables.iter().enumerate() {
        let at = file.table("mesh", Some(i));
        let name = m.name.get_ref();
        if out.index.insert(name.as_str(), i).is_some() {
            return Err(at.error(
                "name",
                Some(m.name.span()),
                format!("mesh '{name}' is defined twice"),
            ));
        }
        let mesh = match (&m.obj, &m.generator) {
            (Some(obj), None) => {
                let obj_path = file.resolve(obj.get_ref());
                if !obj_path.exists() {
                    return Err(at.error(
                        "obj",
                        Some(obj.span()),
                        format!("mesh file {} not found", obj_path.display()),
                    ));
                }
                if let Some(u) = &m.units_per_mm {
                    return Err(at.error(
                        "units_per_mm",
                        Some(u.span()),
                        "only a `gltf` mesh reads `units_per_mm` (its media's units)",
                    ));
                }
                if m.gltf.is_some() {
                    return Err(at.error(
                        "gltf",
                        span(&m.gltf),
                        format!("mesh '{name}' needs exactly one of `obj`, `gltf` or `generator`"),
                    ));
                }
                let loaded = obj::load_obj(&obj_path)?;
                let mut parts = Vec::new();
                if value(&m.mtl).unwrap_or(true) {
                    for (part, material) in loaded.parts() {
                        out.meshes.push(part);
                        parts.push(Part {
                            mesh: out.meshes.len() - 1,
                            source: material
                                .map_or(PartSource::Plain, |m| PartSource::Mtl(m.clone())),
                        });
                    }
                } else {
                    // `mtl = false`: one mesh, drawn with the objects' materials alone.
                    out.meshes.push(loaded.mesh);
                    parts.push(Part {
                        mesh: out.meshes.len() - 1,
                        source: PartSource::Plain,
                    });
                }
                out.parts.push(parts);
                continue;
            }
            (None, None) if m.gltf.is_some() => {
                if let Some(mtl) = &m.mtl {
                    return Err(at.error(
                        "mtl",
                        Some(mtl.span()),
                        "`mtl` chooses whether an OBJ's MTL materials are used: a `gltf` \
                         mesh's materials are its own (an [[object]]'s `material` replaces them)",
                    ));
                }
                out.parts.push(gltf_parts(file, i, m, &mut out.meshes)?);
                continue;
            }
            (None, Some(generator)) if m.gltf.is_none() && m.units_per_mm.is_none() => {
                if let Some(mtl) = &m.mtl {
                    return Err(at.error(
                        "mtl",
                        Some(mtl.span()),
                        "`mtl` chooses whether an OBJ's MTL materials are used: a `generator` \
                         mesh has none",
                    ));
                }
                let generator = Generator::parse(generator.get_ref())
                    .map_err(|e| at.error("generator", Some(generator.span()), e))?;
                match (&m.level, &m.triangles) {
                    (Some(_), Some(triangles)) => {
                        return Err(at.error(
                            "triangles",
                            Some(triangles.span()),
                            "give `level` or `triangles`, not both",
                        ))
                    }
                    (_, Some(t)) => {
                        generators::generate_with_triangles(generator, *t.get_ref())
                            .map_err(|e| at.error("triangles", Some(t.span()), e))?
                            .0
                    }
                    (level, None) => generators::generate(generator, value(level).unwrap_or(2))
                        .map_err(|e| at.error("level", span(level), e))?,
                }
            }
            _ => {
                return Err(at.error(
                    "name",
                    Some(m.name.span()),
                    format!(
                        "mesh '{name}' needs exactly one of `obj`, `gltf` or `generator` (and \
                         `units_per_mm` only with `gltf`)"
                    ),
                ))
            }
        };
        out.meshes.push(mesh);
        out.parts.push(vec![Part {
            mesh: out.meshes.len() - 1,
            source: PartSource::Plain,
        }]);
    }
    Ok(out)
}

/// `[[mesh]]` number `i` with a `gltf` asset: its default scene's primitives, each a part
/// placed by its node, with its material; the asset's cameras and lights are the scene
/// file's business (warned about when the asset has them).
fn gltf_parts(
    file: &SceneFile<'_>,
    i: usize,
    m: &MeshToml,
    meshes: &mut Vec<Mesh>,
) -> Result<Vec<Part>> {
    let at = file.table("mesh", Some(i));
    let Some(given) = &m.gltf else {
        return Ok(Vec::new());
    };
    let path = file.resolve(given.get_ref());
    if !path.exists() {
        return Err(at.error(
            "gltf",
            Some(given.span()),
            format!("glTF file {} not found", path.display()),
        ));
    }
    let mut options = crate::scene::gltf::GltfOptions::default();
    if let Some(u) = &m.units_per_mm {
        let v = *u.get_ref();
        let range = crate::scene::layered::UNITS_PER_MM_RANGE;
        if !(v.is_finite() && range.contains(&v)) {
            return Err(at.error(
                "units_per_mm",
                Some(u.span()),
                format!(
                    "{v} must be in [{:e}, {:e}] (scene units per millimetre of the asset's \
                     media: 0.001 when a unit is a metre, glTF's unit)",
                    range.start(),
                    range.end()
                ),
            ));
        }
        options.units_per_mm = v;
    }
    let asset = crate::scene::gltf::load_gltf(&path, &options)?;
    if asset.camera.is_some() || !asset.lights.is_empty() {
        log::warn!(
            "{}: its camera and KHR_lights_punctual lights ignored: the scene file {} places \
             the asset and lights it",
            path.display(),
            file.path.display()
        );
    }
    let first = meshes.len();
    meshes.extend(asset.meshes);
    Ok(asset
        .objects
        .into_iter()
        .map(|o| Part {
            mesh: first + o.mesh,
            source: PartSource::Gltf(o.transform, Box::new(o.material)),
        })
        .collect())
}

/// The `[[object]]` tables: each mesh part placed, with its material (`materials` by name;
/// `material_tables` says which set `albedo`, which an OBJ's MTL colour then does not replace).
pub(super) fn objects(
    file: &SceneFile<'_>,
    tables: &[ObjectToml],
    meshes: &Meshes<'_>,
    materials: &HashMap<&str, Material>,
    material_tables: &[MaterialToml],
) -> Result<Vec<Object>> {
    let mut objects = Vec::new();
    for (i, o) in tables.iter().enumerate() {
        let at = file.table("object", Some(i));
        let mesh_name = o.mesh.get_ref();
        let mesh_entry = *meshes.index.get(mesh_name.as_str()).ok_or_else(|| {
            at.error(
                "mesh",
                Some(o.mesh.span()),
                format!("no mesh named '{mesh_name}'"),
            )
        })?;
        let parts = &meshes.parts[mesh_entry];
        let gltf_mesh = parts
            .iter()
            .any(|p| matches!(p.source, PartSource::Gltf(..)));
        let material = match &o.material {
            Some(name) => Some(
                materials
                    .get(name.get_ref().as_str())
                    .ok_or_else(|| {
                        at.error(
                            "material",
                            Some(name.span()),
                            format!("no material named '{}'", name.get_ref()),
                        )
                    })?
                    .clone(),
            ),
            None if gltf_mesh => None,
            None => {
                return Err(at.error(
                    "material",
                    None,
                    format!(
                        "missing `material`: only an object of a `gltf` mesh may leave it out \
                         (to keep the asset's materials); mesh '{mesh_name}' is not one"
                    ),
                ))
            }
        };
        at.check3("translate", o.translate.as_ref(), f32::NEG_INFINITY)?;
        at.check3(
            "rotate_degrees",
            o.rotate_degrees.as_ref(),
            f32::NEG_INFINITY,
        )?;
        let scale = match o.scale.as_ref().map(Spanned::get_ref) {
            None => Vec3::ONE,
            Some(ScaleToml::Uniform(s)) => Vec3::splat(*s),
            Some(ScaleToml::PerAxis(s)) => Vec3::from(*s),
        };
        if !(scale.is_finite() && scale.min_element() > 0.0) {
            return Err(at.error(
                "scale",
                span(&o.scale),
                format!("{scale} must be finite and > 0"),
            ));
        }
        let r = Vec3::from(value(&o.rotate_degrees).unwrap_or_default());
        let rotation = Quat::from_euler(
            EulerRot::XYZ,
            r.x.to_radians(),
            r.y.to_radians(),
            r.z.to_radians(),
        );
        let transform = Mat4::from_scale_rotation_translation(
            scale,
            rotation,
            Vec3::from(value(&o.translate).unwrap_or_default()),
        );
        let explicit_albedo = o.material.as_ref().is_some_and(|name| {
            material_tables
                .iter()
                .find(|m| m.name.get_ref() == name.get_ref())
                .is_some_and(|m| m.albedo.is_some())
        });
        for part in parts {
            let (material, placed) = match (&part.source, &material) {
                (PartSource::Plain, Some(m)) => (m.clone(), transform),
                (PartSource::Mtl(mtl), Some(m)) => (
                    super::materials::with_mtl(m, mtl, explicit_albedo),
                    transform,
                ),
                // A named material overrides the asset's; the node still places the part.
                (PartSource::Gltf(node, _), Some(m)) => (m.clone(), transform * *node),
                (PartSource::Gltf(node, own), None) => ((**own).clone(), transform * *node),
                // `material` is required for every other mesh (checked above).
                (_, None) => continue,
            };
            if !placed.is_finite() {
                return Err(at.error(
                    "scale",
                    span(&o.scale),
                    "the object's transform times the asset's node transform is not finite",
                ));
            }
            objects.push(Object {
                mesh: part.mesh,
                transform: placed,
                material,
            });
        }
    }
    if objects.is_empty() {
        return Err(LucentError::file(
            file.path,
            "the scene has no [[object]]: nothing to draw",
        ));
    }
    Ok(objects)
}

/// The `[[light]]` tables (at most [`MAX_LIGHTS`]).
pub(super) fn lights(file: &SceneFile<'_>, tables: &[LightToml]) -> Result<Vec<Light>> {
    if let Some(extra) = tables.get(MAX_LIGHTS) {
        return Err(file.table("light", Some(MAX_LIGHTS)).error(
            "type",
            Some(extra.kind.span()),
            format!(
                "{} lights; at most {MAX_LIGHTS} are supported",
                tables.len()
            ),
        ));
    }
    tables
        .iter()
        .enumerate()
        .map(|(i, l)| light(file, i, l))
        .collect()
}

/// `[[light]]` number `i`.
fn light(file: &SceneFile<'_>, i: usize, l: &LightToml) -> Result<Light> {
    let at = file.table("light", Some(i));
    let kind_name = l.kind.get_ref();
    let need = |v: &Option<Spanned<[f32; 3]>>, key: &str| -> Result<Vec3> {
        let given = v
            .as_ref()
            .ok_or_else(|| at.error(key, None, format!("a {kind_name} light needs `{key}`")))?;
        at.check3(key, Some(given), f32::NEG_INFINITY)?;
        Ok(Vec3::from(*given.get_ref()))
    };
    let range = value(&l.range).unwrap_or(20.0);
    // Checked here so the message names `range` itself (the light's own check names the
    // position and range together).
    if !(range.is_finite() && range > 0.0) {
        return Err(at.error(
            "range",
            span(&l.range),
            format!(
                "{range} must be finite and > 0 (the distance at which the light's \
                 contribution falls to zero)"
            ),
        ));
    }
    let kind = match kind_name.as_str() {
        "directional" => LightKind::Directional {
            direction: need(&l.direction, "direction")?,
        },
        "point" => LightKind::Point {
            position: need(&l.position, "position")?,
            range,
        },
        "spot" => LightKind::Spot {
            position: need(&l.position, "position")?,
            direction: need(&l.direction, "direction")?,
            range,
            inner_degrees: value(&l.inner_degrees).unwrap_or(20.0),
            outer_degrees: value(&l.outer_degrees).unwrap_or(30.0),
        },
        other => {
            return Err(at.error(
                "type",
                Some(l.kind.span()),
                format!("unknown light type '{other}'; use point, spot or directional"),
            ))
        }
    };
    at.check3("color", l.color.as_ref(), 0.0)?;
    let light = Light {
        kind,
        color: Vec3::from(value(&l.color).unwrap_or([1.0; 3])),
        intensity: *l.intensity.get_ref(),
        translucency_scale: value(&l.translucency_scale).unwrap_or(1.0),
        shadows: l.shadows.unwrap_or(true),
    };
    // Map the validation failure back to the key it is about.
    light.validate("light").map_err(|e| {
        let message = e.to_string();
        let keys = [
            ("intensity", Some(l.intensity.span())),
            ("translucency_scale", span(&l.translucency_scale)),
            ("range", span(&l.range)),
            ("direction", span(&l.direction)),
            ("position", span(&l.position)),
            ("color", span(&l.color)),
        ];
        let (key, key_span) = keys
            .into_iter()
            .find(|(k, _)| message.contains(k))
            .unwrap_or(if message.contains("angles") {
                ("outer_degrees", span(&l.outer_degrees))
            } else {
                ("type", Some(l.kind.span()))
            });
        at.error(key, key_span, message.trim_start_matches("light: "))
    })?;
    Ok(light)
}

/// `[deformation]`.
pub(super) fn deformation(
    file: &SceneFile<'_>,
    table: Option<&DeformationToml>,
) -> Result<Option<Deformation>> {
    let at = file.table("deformation", None);
    let Some(d) = table else { return Ok(None) };
    if d.kind.get_ref() != "wave" {
        return Err(at.error(
            "type",
            Some(d.kind.span()),
            format!("unknown deformation '{}'; use wave", d.kind.get_ref()),
        ));
    }
    for (key, v) in [
        ("amplitude", &d.amplitude),
        ("frequency", &d.frequency),
        ("speed", &d.speed),
    ] {
        if !v.get_ref().is_finite() {
            return Err(at.error(
                key,
                Some(v.span()),
                format!("{} must be finite", v.get_ref()),
            ));
        }
    }
    Ok(Some(Deformation::Wave {
        amplitude: *d.amplitude.get_ref(),
        frequency: *d.frequency.get_ref(),
        speed: *d.speed.get_ref(),
    }))
}

/// `[environment]`, or the top-level `ambient` (a constant radiance; not both).
pub(super) fn environment(
    file: &SceneFile<'_>,
    table: Option<&EnvironmentToml>,
    ambient: &Option<Spanned<[f32; 3]>>,
) -> Result<Environment> {
    let e =
        match (table, ambient) {
            (Some(_), Some(ambient)) => return Err(file.table("", None).error(
                "ambient",
                Some(ambient.span()),
                "give either `ambient` (a constant radiance) or an `[environment]` table, not both",
            )),
            (None, ambient) => {
                return Ok(Environment::constant(Vec3::from(
                    value(ambient).unwrap_or([0.03; 3]),
                )))
            }
            (Some(e), None) => e,
        };
    let at = file.table("environment", None);
    at.check3("radiance", e.radiance.as_ref(), 0.0)?;
    at.check3("sky", e.sky.as_ref(), 0.0)?;
    at.check3("ground", e.ground.as_ref(), 0.0)?;
    let kind = e.kind.get_ref();
    // Keys that belong to another kind are refused, not ignored: a parsed key does what it
    // says or is an error.
    let refuse = |keys: &[(&str, Option<std::ops::Range<usize>>)]| -> Result<()> {
        match keys.iter().find(|(_, given)| given.is_some()) {
            Some((key, given)) => Err(at.error(
                key,
                given.clone(),
                format!("`{key}` does not apply to kind = \"{kind}\""),
            )),
            None => Ok(()),
        }
    };
    let map_keys = [
        ("file", span(&e.file)),
        ("builtin", span(&e.builtin)),
        ("intensity", span(&e.intensity)),
        ("rotation_degrees", span(&e.rotation_degrees)),
    ];
    match kind.as_str() {
        "constant" => {
            refuse(&[("sky", span(&e.sky)), ("ground", span(&e.ground))])?;
            refuse(&map_keys)?;
            let radiance = value(&e.radiance).ok_or_else(|| {
                at.error("radiance", None, "kind = \"constant\" needs `radiance`")
            })?;
            Ok(Environment::constant(Vec3::from(radiance)))
        }
        "hemisphere" => {
            refuse(&[("radiance", span(&e.radiance))])?;
            refuse(&map_keys)?;
            let (Some(sky), Some(ground)) = (value(&e.sky), value(&e.ground)) else {
                let key = if e.sky.is_none() { "sky" } else { "ground" };
                return Err(at.error(key, None, "kind = \"hemisphere\" needs `sky` and `ground`"));
            };
            Ok(Environment::hemisphere(Vec3::from(sky), Vec3::from(ground)))
        }
        "map" => {
            refuse(&[
                ("radiance", span(&e.radiance)),
                ("sky", span(&e.sky)),
                ("ground", span(&e.ground)),
            ])?;
            environment_map(file, e)
        }
        other => Err(at.error(
            "kind",
            Some(e.kind.span()),
            format!("unknown environment kind '{other}'; use constant, hemisphere or map"),
        )),
    }
}

/// `[environment]` with `kind = "map"`: a file or the built-in sky.
fn environment_map(file: &SceneFile<'_>, e: &EnvironmentToml) -> Result<Environment> {
    let at = file.table("environment", None);
    let intensity = value(&e.intensity).unwrap_or(1.0);
    if !(intensity.is_finite() && intensity >= 0.0) {
        return Err(at.error(
            "intensity",
            span(&e.intensity),
            format!("{intensity} must be finite and >= 0"),
        ));
    }
    let rotation = value(&e.rotation_degrees).unwrap_or(0.0);
    if !rotation.is_finite() {
        return Err(at.error(
            "rotation_degrees",
            span(&e.rotation_degrees),
            format!("{rotation} must be finite"),
        ));
    }
    match (&e.file, &e.builtin) {
        (Some(path), None) => {
            Environment::from_file(&file.resolve(path.get_ref()), intensity, rotation)
        }
        (None, Some(name)) if name.get_ref() == environment::BUILTIN_SKY => {
            Environment::builtin_sky(intensity, rotation)
        }
        (None, Some(name)) => Err(at.error(
            "builtin",
            Some(name.span()),
            format!(
                "unknown built-in map '{}'; available: {}",
                name.get_ref(),
                environment::BUILTIN_SKY
            ),
        )),
        _ => Err(at.error(
            "file",
            span(&e.file),
            "kind = \"map\" needs exactly one of `file` and `builtin`",
        )),
    }
}
