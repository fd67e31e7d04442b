//! Hardened glTF 2.0 import: `.gltf` (external or data-URI buffers) and `.glb` files become
//! lucent meshes, objects, materials, a camera and lights (docs/gltf.md maps every key).
//!
//! [`load_gltf`] is the only way a glTF asset becomes part of a [`Scene`]. The JSON is
//! parsed by the `gltf` crate's serde types and checked by its validation; everything else
//! is done here, because the crate's importer opens URIs itself (no size bound, no device or
//! FIFO check) and its GLB reader underflows on a header shorter than it says. It never
//! panics (what a dependency might still panic on is caught and becomes an error), and every
//! error names the file and the glTF object at fault:
//!
//! | input | result |
//! |---|---|
//! | not a regular file (device, FIFO, directory), over 2 GiB | error |
//! | truncated `.glb` (header, chunk lengths past the end), first chunk not JSON, GLB version not 2 | error |
//! | JSON that does not parse, or that the `gltf` crate's validation refuses (an index out of range, a missing required key, an unknown enum value) | error naming the JSON path |
//! | `asset.version` not 2.x; an extension in `extensionsRequired` lucent does not implement | error |
//! | a buffer or image URI that is missing, unreadable, not a regular file (device, FIFO), absolute, leading out of the asset's folder (`..`, a link), another scheme than `data:`, or a non-base64 data URI | error naming the buffer or image and the URI |
//! | a buffer shorter than its `byteLength`; a buffer view past its buffer; an accessor past its view | error naming both |
//! | a `byteStride` smaller than the element (overlapping elements), over 252 or unaligned | error |
//! | an accessor count of 0, or over [`MAX_VERTICES`](crate::scene::obj::MAX_VERTICES) vertices or 3 x [`MAX_TRIANGLES`](crate::scene::obj::MAX_TRIANGLES) indices (a count of 2^32) | error, before anything is allocated |
//! | an index not below the vertex count; a non-whole number of triangles; NaN or infinite vertex data | error |
//! | a primitive mode other than TRIANGLES (points, lines, strips, fans) | error naming the mode and the mesh |
//! | sparse accessors | error |
//! | a texture that is not an image (or one larger than the texture limits) | error naming the image |
//! | a node that is its own ancestor or has two parents | error naming the node |
//! | a NaN or infinite node transform (or one that overflows when composed) | error naming the node |
//! | an extension or key lucent does not use (`KHR_materials_clearcoat`, `occlusionTexture`, skins, animations, ...) | **warning** naming it |
//!
//! Memory is bounded by the data: every allocation is sized from bytes that were read (and
//! capped), never from a count the file merely declares.
//!
//! **Units:** a glTF unit is a metre; lucent's media are in mm^-1 with `units_per_mm` scene
//! units per millimetre, so a glTF medium has `units_per_mm = 0.001` ([`GLTF_UNITS_PER_MM`])
//! unless a scene file says otherwise. glTF's `(0, 0)` texture coordinate is the image's top
//! left corner, as lucent's: UVs are taken as stored.

mod accessors;
mod container;
mod geometry;
mod materials;

use std::collections::{BTreeSet, HashMap};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use ::gltf::json;
use ::gltf::json::validation::Checked;
use glam::{Mat4, Quat, Vec3};

pub use container::IMPLEMENTED;
pub use materials::{
    lucent_roughness, lucent_specular, medium as volume_medium, single_scattering_albedo, UvMapping,
};

use super::material::{Light, LightKind};
use super::{Camera, Environment, Mesh, Object, Scene, MAX_LIGHTS};
use crate::{LucentError, Result};

/// Scene units per millimetre of a glTF asset's media: a glTF unit is a metre.
pub const GLTF_UNITS_PER_MM: f32 = 0.001;

/// How an asset is read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfOptions {
    /// Scene units per millimetre of the media the materials describe
    /// ([`GLTF_UNITS_PER_MM`] unless a scene file overrides it).
    pub units_per_mm: f32,
}

impl Default for GltfOptions {
    fn default() -> Self {
        Self {
            units_per_mm: GLTF_UNITS_PER_MM,
        }
    }
}

/// A camera a glTF file gives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GltfCamera {
    /// Its eye and direction (the node's -Z) and perspective; `far` is the file's `zfar`
    /// or, for an infinite one, past the asset's bounds.
    pub camera: Camera,
}

/// What a glTF asset's default scene holds, in the asset's own space.
#[derive(Clone, Debug)]
pub struct GltfAsset {
    /// The file's stem.
    pub name: String,
    /// One mesh per mesh primitive used (a primitive drawn by several nodes is one mesh).
    pub meshes: Vec<Mesh>,
    /// Every node's primitives placed: `mesh` indexes [`GltfAsset::meshes`], `transform` is
    /// the node's world matrix, `material` the primitive's material converted.
    pub objects: Vec<Object>,
    /// The first camera of the default scene, when it has a perspective one lucent can use.
    pub camera: Option<GltfCamera>,
    /// `KHR_lights_punctual` lights placed by the default scene's nodes.
    pub lights: Vec<Light>,
    /// `asset.copyright`, as one line.
    pub credits: Vec<String>,
    /// The axis-aligned bounds of every object, world space: (min, max).
    pub bounds: (Vec3, Vec3),
}

/// Loads a glTF asset's default scene (its `scene`, else its first, else every root node).
/// See the module docs for what is checked and what is refused.
pub fn load_gltf(path: &Path, options: &GltfOptions) -> Result<GltfAsset> {
    let fail = |message: String| LucentError::file(path, message);
    // Last resort: the checks cover every failure known, but a panic in a dependency must
    // still end as an error naming the file, never as a crash.
    match catch_unwind(AssertUnwindSafe(|| load(path, options))) {
        Ok(result) => result.map_err(fail),
        Err(panic) => Err(fail(format!(
            "the glTF reader crashed on this file ({}); please report it",
            super::obj::panic_message(&*panic)
        ))),
    }
}

fn load(path: &Path, options: &GltfOptions) -> std::result::Result<GltfAsset, String> {
    let container = container::read(path)?;
    let root = &container.root;
    for (key, present) in [
        ("animations", !root.animations.is_empty()),
        ("skins", !root.skins.is_empty()),
    ] {
        if present {
            log::warn!(
                "{}: {key} ignored: lucent draws the static scene",
                path.display()
            );
        }
    }
    if let Some(ext) = &root.extensions {
        for key in ext.others.keys() {
            log::warn!("{}: extensions.{key} ignored", path.display());
        }
    }
    let parents = check_hierarchy(root)?;
    let roots = scene_roots(root, &parents)?;
    let data = accessors::Accessors {
        root,
        buffers: &container.buffers,
    };
    let mut materials = materials::MaterialContext::new(path, &container, options.units_per_mm);
    let mut converted: HashMap<Option<usize>, materials::Converted> = HashMap::new();
    let mut mesh_of: HashMap<(usize, usize), usize> = HashMap::new();
    let mut ignored = BTreeSet::new();
    let mut asset = GltfAsset {
        name: path
            .file_stem()
            .map_or_else(|| "gltf".into(), |s| s.to_string_lossy().into_owned()),
        meshes: Vec::new(),
        objects: Vec::new(),
        camera: None,
        lights: Vec::new(),
        credits: Vec::new(),
        bounds: (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
    };
    let mut camera_node = None;
    let mut light_nodes = Vec::new();
    // Depth first, with an explicit stack: a deep hierarchy cannot overflow the call stack.
    let mut stack: Vec<(usize, Mat4)> = roots.iter().rev().map(|&n| (n, Mat4::IDENTITY)).collect();
    while let Some((n, parent)) = stack.pop() {
        let node = &root.nodes[n];
        let what = match &node.name {
            Some(name) => format!("nodes[{n}] \"{name}\""),
            None => format!("nodes[{n}]"),
        };
        let world = parent * local_transform(node).map_err(|e| format!("{what}: {e}"))?;
        if !world.is_finite() {
            return Err(format!(
                "{what}: its world transform is not finite (its ancestors' matrices overflow)"
            ));
        }
        if node.skin.is_some() || node.weights.is_some() {
            ignored.insert("skins and morph weights (drawn in their bind pose)".to_string());
        }
        if let Some(ext) = &node.extensions {
            for key in ext.others.keys() {
                log::warn!("{}: {what}.extensions.{key} ignored", path.display());
            }
            if let Some(light) = &ext.khr_lights_punctual {
                light_nodes.push((light.light.value(), world, what.clone()));
            }
        }
        if let (Some(c), None) = (node.camera, &camera_node) {
            camera_node = Some((c.value(), world, what.clone()));
        }
        if let Some(m) = node.mesh {
            let m = m.value();
            let mesh = root
                .meshes
                .get(m)
                .ok_or_else(|| format!("{what}: meshes[{m}] does not exist"))?;
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                let key = primitive.material.map(|i| i.value());
                let material = match converted.entry(key) {
                    std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
                    std::collections::hash_map::Entry::Vacant(e) => {
                        e.insert(materials.convert(key)?)
                    }
                };
                let index = match mesh_of.get(&(m, p)) {
                    Some(&i) => i,
                    None => {
                        let lucent_mesh =
                            geometry::primitive(&data, m, p, material.uv, &mut ignored)?;
                        asset.meshes.push(lucent_mesh);
                        mesh_of.insert((m, p), asset.meshes.len() - 1);
                        asset.meshes.len() - 1
                    }
                };
                if world.determinant().abs() < 1e-30 {
                    log::warn!(
                        "{}: {what}: its transform has no volume (a zero scale); not drawn",
                        path.display()
                    );
                    continue;
                }
                for v in &asset.meshes[index].positions {
                    let w = world.transform_point3(*v);
                    asset.bounds.0 = asset.bounds.0.min(w);
                    asset.bounds.1 = asset.bounds.1.max(w);
                }
                asset.objects.push(Object {
                    mesh: index,
                    transform: world,
                    material: material.material.clone(),
                });
            }
        }
        for child in node.children.iter().flatten().rev() {
            stack.push((child.value(), world));
        }
    }
    for name in &ignored {
        log::warn!("{}: {name} ignored", path.display());
    }
    if asset.objects.is_empty() {
        return Err("its scene draws no mesh: nothing to render".into());
    }
    if let Some((c, world, what)) = camera_node {
        asset.camera = camera(root, c, world, &what, asset.bounds, path)?;
    }
    for (l, world, what) in light_nodes {
        asset
            .lights
            .push(light(root, l, world, &what, asset.bounds)?);
    }
    if asset.lights.len() > MAX_LIGHTS {
        return Err(format!(
            "{} KHR_lights_punctual lights are placed; at most {MAX_LIGHTS} are supported",
            asset.lights.len()
        ));
    }
    if let Some(copyright) = &root.asset.copyright {
        // One printable line, as a scene file's credits are.
        let line: String = copyright
            .chars()
            .map(|c| if c.is_control() { ' ' } else { c })
            .take(1000)
            .collect();
        if !line.trim().is_empty() {
            let file = path
                .file_name()
                .map_or_else(String::new, |f| f.to_string_lossy().into_owned());
            asset.credits.push(format!("{file}: {}", line.trim()));
        }
    }
    Ok(asset)
}

/// Each node's parent, after checking the nodes form trees: no node is its own ancestor,
/// none has two parents.
fn check_hierarchy(root: &json::Root) -> std::result::Result<Vec<Option<usize>>, String> {
    let n = root.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (p, node) in root.nodes.iter().enumerate() {
        for child in node.children.iter().flatten() {
            let c = child.value();
            if c >= n {
                return Err(format!(
                    "nodes[{p}].children names nodes[{c}], which does not exist"
                ));
            }
            if c == p {
                return Err(format!(
                    "nodes[{p}] is its own child: the node hierarchy has a cycle"
                ));
            }
            if let Some(other) = parent[c] {
                return Err(format!(
                    "nodes[{c}] is a child of both nodes[{other}] and nodes[{p}]: glTF nodes form \
                     trees"
                ));
            }
            parent[c] = Some(p);
        }
    }
    // With one parent each, a cycle is a walk up that comes back: mark each walk's nodes, and
    // a walk that meets its own mark is a cycle (linear time).
    let mut state = vec![0u8; n]; // 0 unseen, 1 on this walk, 2 done
    for start in 0..n {
        let mut walk = Vec::new();
        let mut at = Some(start);
        while let Some(i) = at {
            match state[i] {
                2 => break,
                1 => {
                    return Err(format!(
                        "nodes[{i}] is its own ancestor: the node hierarchy has a cycle"
                    ))
                }
                _ => {
                    state[i] = 1;
                    walk.push(i);
                    at = parent[i];
                }
            }
        }
        for i in walk {
            state[i] = 2;
        }
    }
    Ok(parent)
}

/// The root nodes of the default scene.
fn scene_roots(
    root: &json::Root,
    parents: &[Option<usize>],
) -> std::result::Result<Vec<usize>, String> {
    let scene = root
        .scene
        .map(|s| s.value())
        .or((!root.scenes.is_empty()).then_some(0));
    match scene {
        Some(s) => {
            let scene = root
                .scenes
                .get(s)
                .ok_or_else(|| format!("scene {s} does not exist"))?;
            let nodes: Vec<usize> = scene.nodes.iter().map(|n| n.value()).collect();
            if let Some(&bad) = nodes.iter().find(|&&n| n >= parents.len()) {
                return Err(format!(
                    "scenes[{s}] names nodes[{bad}], which does not exist"
                ));
            }
            if let Some(&child) = nodes.iter().find(|&&n| parents[n].is_some()) {
                return Err(format!(
                    "scenes[{s}] names nodes[{child}] as a root, but it is a child of another node"
                ));
            }
            Ok(nodes)
        }
        None => Ok((0..parents.len())
            .filter(|&n| parents[n].is_none())
            .collect()),
    }
}

/// A node's local transform: its `matrix`, or its translation, rotation and scale; every
/// number finite.
fn local_transform(node: &json::scene::Node) -> std::result::Result<Mat4, String> {
    if let Some(m) = node.matrix {
        if m.iter().any(|x| !x.is_finite()) {
            return Err(format!("matrix {m:?} is not finite"));
        }
        return Ok(Mat4::from_cols_array(&m));
    }
    let t = node.translation.unwrap_or([0.0; 3]);
    let s = node.scale.unwrap_or([1.0; 3]);
    let r = node.rotation.map_or([0.0, 0.0, 0.0, 1.0], |q| q.0);
    for (key, values) in [
        ("translation", &t[..]),
        ("scale", &s[..]),
        ("rotation", &r[..]),
    ] {
        if values.iter().any(|x| !x.is_finite()) {
            return Err(format!("{key} {values:?} is not finite"));
        }
    }
    let q = Quat::from_array(r);
    // A rotation must be a unit quaternion (the crate checks it too): one within rounding
    // of unit length is taken as written, a longer or shorter one normalised, a zero one
    // has no direction.
    let length2 = q.length_squared();
    if length2 < 1e-12 {
        return Err(format!("rotation {r:?} is not a unit quaternion"));
    }
    let q = if (length2 - 1.0).abs() > 1e-5 {
        q.normalize()
    } else {
        q
    };
    Ok(Mat4::from_scale_rotation_translation(
        Vec3::from(s),
        q,
        Vec3::from(t),
    ))
}

/// The centre and radius of `bounds`.
fn sphere(bounds: (Vec3, Vec3)) -> (Vec3, f32) {
    let centre = (bounds.0 + bounds.1) * 0.5;
    (centre, ((bounds.1 - bounds.0).length() * 0.5).max(1e-3))
}

/// Camera `c` placed by a node with world matrix `world`: eye at the node's origin, looking
/// down its -Z. `None` (with a warning) for an orthographic camera or one looking straight
/// up or down (lucent's cameras keep +Y up).
fn camera(
    root: &json::Root,
    c: usize,
    world: Mat4,
    what: &str,
    bounds: (Vec3, Vec3),
    path: &Path,
) -> std::result::Result<Option<GltfCamera>, String> {
    let cam = root
        .cameras
        .get(c)
        .ok_or_else(|| format!("{what}: cameras[{c}] does not exist"))?;
    let Some(p) = &cam.perspective else {
        log::warn!(
            "{}: cameras[{c}] is orthographic, which lucent does not render; framing the scene \
             with a perspective camera instead",
            path.display()
        );
        return Ok(None);
    };
    let fov = p.yfov.to_degrees();
    if !(fov > 1.0 && fov < 179.0) {
        return Err(format!(
            "cameras[{c}].perspective.yfov: {} radians must be between 1 and 179 degrees",
            p.yfov
        ));
    }
    if !(p.znear.is_finite() && p.znear > 0.0) {
        return Err(format!(
            "cameras[{c}].perspective.znear: {} must be > 0",
            p.znear
        ));
    }
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    if forward == Vec3::ZERO || forward.y.abs() > 0.9999 {
        log::warn!(
            "{}: {what}: its camera looks straight up or down, which lucent's +Y-up cameras \
             cannot; framing the scene instead",
            path.display()
        );
        return Ok(None);
    }
    if p.aspect_ratio.is_some() {
        log::warn!(
            "{}: cameras[{c}].perspective.aspectRatio ignored: the image's size decides",
            path.display()
        );
    }
    let (centre, radius) = sphere(bounds);
    let far = match p.zfar {
        Some(f) if f.is_finite() && f > p.znear => f,
        Some(f) => {
            return Err(format!(
                "cameras[{c}].perspective.zfar: {f} must be finite and > znear ({})",
                p.znear
            ))
        }
        // An infinite far plane: past everything the scene holds.
        None => (eye.distance(centre) + radius) * 2.0,
    };
    let far = far.max(p.znear * 2.0);
    let distance = (centre - eye).dot(forward).max(p.znear * 2.0);
    if let Some(w) = super::camera_range::depth_range_warning(p.znear, far, distance) {
        log::warn!("{}: cameras[{c}]: {w}", path.display());
    }
    Ok(Some(GltfCamera {
        camera: Camera {
            eye,
            target: eye + forward * distance,
            fov_y_degrees: fov,
            near: p.znear,
            far,
        },
    }))
}

/// A camera that frames `bounds`: 45 degrees, from the front, a little above.
pub fn framing_camera(bounds: (Vec3, Vec3)) -> Camera {
    let (centre, radius) = sphere(bounds);
    let fov = 45.0f32;
    let distance = radius / (fov.to_radians() * 0.5).sin() * 1.1;
    let eye = centre + Vec3::new(0.0, 0.35, 1.0).normalize() * distance;
    Camera {
        eye,
        target: centre,
        fov_y_degrees: fov,
        near: (distance - radius).max(distance * 0.01) * 0.5,
        far: (distance + radius) * 2.0,
    }
}

/// `KHR_lights_punctual` light `l` placed by a node with world matrix `world` (the light at
/// its origin, shining down its -Z). An infinite range becomes one past the scene's bounds.
fn light(
    root: &json::Root,
    l: usize,
    world: Mat4,
    what: &str,
    bounds: (Vec3, Vec3),
) -> std::result::Result<Light, String> {
    use json::extensions::scene::khr_lights_punctual::Type;
    let lights = root
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map_or(&[][..], |k| &k.lights[..]);
    let key = format!("extensions.KHR_lights_punctual.lights[{l}]");
    let def = lights
        .get(l)
        .ok_or_else(|| format!("{what}: {key} does not exist"))?;
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z);
    let range = match def.range {
        Some(r) if r.is_finite() && r > 0.0 => r,
        Some(r) => return Err(format!("{key}.range: {r} must be finite and > 0")),
        None => {
            let (centre, radius) = sphere(bounds);
            (position.distance(centre) + radius) * 2.0
        }
    };
    let kind = match def.type_ {
        Checked::Valid(Type::Directional) => LightKind::Directional { direction },
        Checked::Valid(Type::Point) => LightKind::Point { position, range },
        Checked::Valid(Type::Spot) => {
            let (inner, outer) = def
                .spot
                .as_ref()
                .map_or((0.0, std::f32::consts::FRAC_PI_4), |s| {
                    (s.inner_cone_angle, s.outer_cone_angle)
                });
            LightKind::Spot {
                position,
                direction,
                range,
                inner_degrees: inner.to_degrees(),
                outer_degrees: outer.to_degrees(),
            }
        }
        Checked::Invalid => return Err(format!("{key}.type is invalid")),
    };
    let light = Light {
        kind,
        color: Vec3::from(def.color),
        intensity: def.intensity,
        translucency_scale: 1.0,
        shadows: true,
    };
    light.validate(&key).map_err(|e| {
        format!(
            "{what}: {}",
            e.to_string().trim_start_matches("invalid input: ")
        )
    })?;
    Ok(light)
}

/// The key light a glTF scene without lights gets (with a warning): white, from above, in
/// front and to the left.
pub fn default_light() -> Light {
    Light::directional(Vec3::new(-0.5, -1.0, -0.6), Vec3::ONE, 3.0)
}

/// A glTF file as a whole scene (`lucent render --scene model.glb`): its default scene's
/// objects, its first camera (else one framing its bounds), its `KHR_lights_punctual`
/// lights (else [`default_light`], with a warning), lucent's default environment.
pub fn load_gltf_scene(path: &Path) -> Result<Scene> {
    let asset = load_gltf(path, &GltfOptions::default())?;
    let camera = match asset.camera {
        Some(c) => c.camera,
        None => framing_camera(asset.bounds),
    };
    let lights = if asset.lights.is_empty() {
        log::warn!(
            "{}: no KHR_lights_punctual lights; lit by a default key light",
            path.display()
        );
        vec![default_light()]
    } else {
        asset.lights
    };
    Ok(Scene {
        name: asset.name,
        meshes: asset.meshes,
        objects: asset.objects,
        lights,
        camera,
        environment: Environment::constant(Vec3::splat(0.03)),
        sky: Vec3::new(0.15, 0.2, 0.3),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: asset.credits,
    })
}
