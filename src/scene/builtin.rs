//! The built-in scenes, by name. Each renders with no file from outside the repository: meshes
//! are generated and textures procedural; thickness asked to be baked is baked by whoever loads
//! the scene ([`crate::bake::scene::prepare_thickness`], cached).

use std::path::Path;

use glam::{Mat4, Vec3};

use super::build::{base_scene, camera, translucent};
use super::generators::{self, Generator};
use super::material::{
    LayeredMedium, Light, LightKind, Material, ProceduralTexture, SssProfile, TextureSource,
    ThicknessSource,
};
use super::{Deformation, Mesh, Scene, Shape};
use crate::{LucentError, Result};

/// Built-in scenes: (name, one-line description).
pub const BUILTIN_SCENES: &[(&str, &str)] = &[
    (
        "smoke",
        "a lit sphere on a ground plane: G-buffer -> deferred lighting -> tonemap",
    ),
    (
        "cubes",
        "the GDC 2011 demo: three lights, cubes with baked grayscale thickness, one red-veined cube with a green light inside",
    ),
    (
        "grid125",
        "5x5x5 translucent cubes (exp2 pow) filling the screen, three point lights (`grid125:P`: P% translucent)",
    ),
    ("teapot", "the Utah teapot in normal-mapped marble (SSS profile)"),
    ("skin", "spheres with d'Eon's six-Gaussian skin profile"),
    (
        "mixed",
        "every technique in one frame: a translucent cube, a skin sphere, a marble sphere, a thin skin disc with both translucency and SSS, a floor",
    ),
    (
        "edges",
        "SSS edge quality: a skin sphere before a bright wall, a thin skin slab before a dark pillar",
    ),
    (
        "layered",
        "Li et al.'s Table 1 materials (Jensen 2001 media) on five spheres",
    ),
    ("dynamic", "a layered torus deforming every frame"),
    (
        "scaling",
        "one teapot at a chosen triangle count: `scaling` (100k) or `scaling:N`",
    ),
    (
        "showcase-translucency",
        "GDC 2011 translucency at its best: an ear, two leaves and a wax panel, thin, baked thickness, lit from behind",
    ),
    (
        "showcase-skin",
        "Lee Perry-Smith's scanned head (CC BY 3.0) as skin1 with its colour and normal maps: the red terminator, the ear glowing against a back light",
    ),
    (
        "showcase-marble",
        "veined marble (procedural albedo and fine normal map) under a grazing light: the waxy look of SSS",
    ),
    (
        "showcase-layered",
        "Li et al.'s layered media as jade and wax: a thin jade leaf, a jade ring, wax candles, lit from behind",
    ),
];

/// Loads a scene by built-in name, from a glTF asset when `name_or_path` ends in `.gltf` or
/// `.glb` ([`crate::scene::gltf::load_gltf_scene`]), or from a `.toml` file when it ends in
/// `.toml` or names an existing file. Only parses and checks: thickness the materials ask to
/// bake or sample is prepared by the caller ([`crate::bake::scene::prepare_thickness`]).
pub fn load_scene(name_or_path: &str) -> Result<Scene> {
    let path = Path::new(name_or_path);
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if matches!(extension.as_deref(), Some("gltf" | "glb")) {
        return super::gltf::load_gltf_scene(path);
    }
    // Anything at that path but a directory is the user's file (a FIFO or device named as a
    // scene gets the loader's "not a regular file" error, not "unknown scene").
    if name_or_path.ends_with(".toml") || (path.exists() && !path.is_dir()) {
        super::file::load_scene_file(path)
    } else {
        builtin(name_or_path)
    }
}

/// A built-in scene by name (`scaling:N` picks the triangle count of `scaling`).
pub fn builtin(name: &str) -> Result<Scene> {
    let (base, parameter) = match name.split_once(':') {
        Some((b, p)) => (b, Some(p)),
        None => (name, None),
    };
    if parameter.is_some() && base != "scaling" && base != "grid125" {
        return Err(LucentError::InvalidInput(format!(
            "scene '{base}' takes no parameter (only scaling:N and grid125:PERCENT do)"
        )));
    }
    match base {
        "smoke" => Ok(smoke()),
        "cubes" => cubes(),
        "grid125" => {
            let percent = match parameter {
                None => 100,
                Some(p) => p.parse::<u32>().ok().filter(|&p| p <= 100).ok_or_else(|| {
                    LucentError::InvalidInput(format!(
                        "grid125:{p}: the translucent share must be a whole percentage 0 to 100"
                    ))
                })?,
            };
            grid125(percent)
        }
        "teapot" => teapot(),
        "skin" => skin(),
        "mixed" => mixed(),
        "edges" => edges(),
        "layered" => layered(),
        "dynamic" => dynamic(),
        "showcase-translucency" => super::showcase::translucency(),
        "showcase-skin" => super::showcase::skin(),
        "showcase-marble" => super::showcase::marble(),
        "showcase-layered" => super::showcase::layered(),
        "scaling" => {
            let triangles = match parameter {
                None => 100_000,
                Some(p) => p.parse::<u64>().map_err(|_| {
                    LucentError::InvalidInput(format!(
                        "scaling:{p}: the triangle count must be a whole number"
                    ))
                })?,
            };
            scaling(triangles)
        }
        _ => Err(LucentError::InvalidInput(format!(
            "unknown scene '{name}'; built-in scenes: {}",
            BUILTIN_SCENES
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// The vertical slice: a sphere on a plane, a warm key light and a cool directional fill.
fn smoke() -> Scene {
    let mut s = base_scene(
        "smoke",
        camera(Vec3::new(0.0, 2.2, 5.0), Vec3::new(0.0, 0.8, 0.0)),
    );
    let sphere = s.add_mesh(Mesh::generate(Shape::Sphere { radius: 1.0 }, 96, 48));
    s.add(
        sphere,
        Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
        Material::opaque("clay", Vec3::new(0.8, 0.3, 0.2), 0.5, 0.35),
    );
    // Its own, smaller and lighter floor than the other scenes': the golden and the ray-traced
    // reference test were made with this one.
    let plane = s.add_mesh(Mesh::generate(Shape::Plane { half_size: 6.0 }, 1, 1));
    s.add(
        plane,
        Mat4::IDENTITY,
        Material::opaque("floor", Vec3::new(0.6, 0.6, 0.55), 0.1, 0.8),
    );
    s.lights = vec![
        Light::point(
            Vec3::new(2.5, 3.5, 2.0),
            Vec3::new(1.0, 26.0 / 30.0, 20.0 / 30.0),
            30.0,
            20.0,
        ),
        Light::directional(Vec3::new(0.3, -1.0, -0.6), Vec3::new(0.35, 0.45, 0.6), 1.0),
    ];
    s
}

/// The talk's demo scene (GDC 2011, slide "3 lights, Frostbite 2 deferred"): a row of cubes with
/// grayscale baked thickness and one whose thickness is red, lit by a green light inside it.
fn cubes() -> Result<Scene> {
    let mut s = base_scene(
        "cubes",
        camera(Vec3::new(0.0, 2.5, 7.5), Vec3::new(0.0, 0.9, 0.0)),
    );
    s.add_floor();
    let cube = s.add_mesh(generators::generate(Generator::Cube, 6)?);
    let gray = translucent(
        "translucent-gray",
        Vec3::new(0.85, 0.85, 0.8),
        ThicknessSource::Bake,
        Vec3::ONE,
    );
    for (i, x) in [-3.0f32, -1.0, 1.0].into_iter().enumerate() {
        let size = 0.6 + 0.15 * i as f32;
        s.add(
            cube,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(size),
                glam::Quat::from_rotation_y(0.3 * i as f32),
                Vec3::new(x, size, -0.5 * i as f32),
            ),
            gray.clone(),
        );
    }
    let red = translucent(
        "red-veined",
        Vec3::new(0.9, 0.85, 0.8),
        ThicknessSource::Bake,
        Vec3::new(1.0, 0.1, 0.05),
    );
    s.add(
        cube,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.8),
            glam::Quat::from_rotation_y(-0.4),
            Vec3::new(3.0, 0.8, 0.0),
        ),
        red,
    );
    s.lights = vec![
        Light::point(
            Vec3::new(-2.0, 3.0, -2.5),
            Vec3::new(1.0, 0.9, 0.7),
            25.0,
            15.0,
        ),
        Light::point(
            Vec3::new(0.0, 1.0, -2.0),
            Vec3::new(0.6, 0.7, 1.0),
            10.0,
            8.0,
        ),
        // The green light inside the red-veined cube's convex hull.
        Light::point(Vec3::new(3.0, 0.8, 0.0), Vec3::new(0.1, 1.0, 0.2), 6.0, 4.0),
    ];
    Ok(s)
}

/// 5 x 5 x 5 cubes filling the screen, three point lights; `percent` of the cubes of every layer
/// are translucent (spread evenly, so about that share of the screen is), the rest opaque with
/// the same base material. With 0% one translucent cube sits behind the camera: the frame keeps
/// its translucency G-buffer target and material-ID test while no pixel is translucent, which is
/// what the "0% of the screen" measurement needs.
fn grid125(percent: u32) -> Result<Scene> {
    let mut s = base_scene("grid125", camera(Vec3::new(0.0, 0.0, 9.0), Vec3::ZERO));
    s.sky = Vec3::new(0.02, 0.02, 0.03);
    let cube = s.add_mesh(generators::generate(Generator::Cube, 1)?);
    let mut material = translucent(
        "grid-translucent",
        Vec3::new(0.8, 0.75, 0.7),
        ThicknessSource::Constant(0.7),
        Vec3::ONE,
    );
    // The grid is the spherical-Gaussian seed's own test scene (5x5x5 cubes): it uses the
    // seed's exp2 form, the one meant for covering the screen; `lucent report translucency`
    // measures exact pow beside it.
    if let Some(t) = &mut material.translucency {
        t.pow_mode = crate::scene::material::PowMode::SphericalGaussian;
    }
    let mut opaque = material.clone();
    opaque.name = "grid-opaque".into();
    opaque.translucency = None;
    let cube_at =
        |p: Vec3| Mat4::from_scale_rotation_translation(Vec3::splat(0.45), glam::Quat::IDENTITY, p);
    for x in 0..5 {
        for y in 0..5 {
            // Cube k of a layer is translucent when the running share crosses a whole cube.
            let k = x * 5 + y;
            let translucent = (k + 1) * percent / 100 > k * percent / 100;
            for z in 0..5 {
                let p = Vec3::new(x as f32 - 2.0, y as f32 - 2.0, z as f32 - 2.0) * 1.25;
                let m = if translucent { &material } else { &opaque };
                s.add(cube, cube_at(p), m.clone());
            }
        }
    }
    if percent == 0 {
        s.add(cube, cube_at(Vec3::new(0.0, 0.0, 20.0)), material);
    }
    s.lights = vec![
        Light::point(
            Vec3::new(-1.9, 1.2, 0.6),
            Vec3::new(1.0, 0.6, 0.3),
            8.0,
            6.0,
        ),
        Light::point(
            Vec3::new(1.3, -0.6, -1.2),
            Vec3::new(0.3, 0.7, 1.0),
            8.0,
            6.0,
        ),
        Light::point(Vec3::new(0.6, 1.9, 2.4), Vec3::new(0.9, 0.9, 0.9), 8.0, 6.0),
    ];
    Ok(s)
}

fn marble_normal() -> TextureSource {
    TextureSource::Procedural(ProceduralTexture::MarbleNormal {
        frequency: 18.0,
        strength: 0.35,
    })
}

/// The thesis's subject: a normal-mapped marble teapot.
fn teapot() -> Result<Scene> {
    let mut s = base_scene(
        "teapot",
        camera(Vec3::new(0.0, 1.6, 3.6), Vec3::new(0.0, 0.6, 0.0)),
    );
    s.add_floor();
    let teapot = s.add_mesh(generators::generate(Generator::Teapot, 4)?);
    let mut marble = Material::opaque("marble", Vec3::new(0.83, 0.79, 0.75), 0.6, 0.25);
    marble.normal_texture = Some(marble_normal());
    marble.sss = Some(SssProfile::preset("marble")?);
    s.add(teapot, Mat4::IDENTITY, marble);
    s.lights = vec![
        Light::point(Vec3::new(2.0, 3.0, 2.0), Vec3::ONE, 25.0, 15.0),
        Light::directional(Vec3::new(-0.5, -1.0, -0.3), Vec3::new(0.3, 0.35, 0.45), 1.0),
    ];
    Ok(s)
}

/// Three spheres with d'Eon's skin profile.
/// Where screen-space SSS goes wrong (thesis section 3.1): a skin sphere in front of a bright
/// wall (halo and background bleeding at its silhouette) and a thin slab of skin in front of a
/// dark pillar (the pillar seen around and through thin parts). The profile is four times as
/// wide as the preset so the blur spans pixels at test sizes.
fn edges() -> Result<Scene> {
    let mut s = base_scene(
        "edges",
        camera(Vec3::new(0.0, 1.0, 5.0), Vec3::new(0.0, 0.9, 0.0)),
    );
    s.sky = Vec3::new(0.05, 0.05, 0.06);
    let wall = s.add_mesh(Mesh::generate(Shape::Plane { half_size: 3.0 }, 1, 1));
    s.add(
        wall,
        Mat4::from_rotation_translation(
            glam::Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
            Vec3::new(0.0, 1.0, -2.0),
        ),
        Material::opaque("bright wall", Vec3::new(0.95, 0.95, 0.9), 0.0, 1.0),
    );
    let mut skin = Material::opaque("skin", Vec3::new(0.85, 0.62, 0.52), 0.35, 0.45);
    let mut profile = SssProfile::preset("skin")?;
    profile.units_per_mm *= 4.0;
    skin.sss = Some(profile);
    let sphere = s.add_mesh(generators::generate(Generator::Icosphere, 4)?);
    s.add(
        sphere,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.6),
            glam::Quat::IDENTITY,
            Vec3::new(-0.9, 1.0, 0.0),
        ),
        skin.clone(),
    );
    let cube = s.add_mesh(generators::generate(Generator::Cube, 2)?);
    s.add(
        cube,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.35, 1.6, 0.35),
            glam::Quat::IDENTITY,
            Vec3::new(1.0, 0.8, -1.0),
        ),
        Material::opaque("dark pillar", Vec3::new(0.05, 0.05, 0.06), 0.1, 0.6),
    );
    s.add(
        cube,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.9, 1.1, 0.04),
            glam::Quat::from_rotation_y(0.3),
            Vec3::new(0.9, 1.0, 0.3),
        ),
        skin,
    );
    s.lights = vec![
        Light::point(Vec3::new(0.5, 2.5, 3.0), Vec3::ONE, 25.0, 15.0),
        Light::point(
            Vec3::new(0.0, 2.0, -1.2),
            Vec3::new(1.0, 0.95, 0.9),
            12.0,
            6.0,
        ),
    ];
    Ok(s)
}

/// Every technique in one frame, each object asking for its own: a translucent cube (GDC
/// 2011, baked thickness), a skin sphere (d'Eon's profile), a marble sphere (the marble
/// profile; both with the default blur, each pixel with its own profile), a thin disc of skin
/// that is both translucent and scattering (the light behind it shines through, and the
/// diffusion blurs it), and a floor that is neither. The profiles are at 5x physical scale
/// (0.05 units per mm on spheres 0.5 units across), so each blur spans many pixels and the
/// two profiles' colours are told apart; a key light from the side, a warm back light.
fn mixed() -> Result<Scene> {
    let mut s = base_scene(
        "mixed",
        camera(Vec3::new(0.0, 1.3, 5.0), Vec3::new(0.0, 0.55, 0.0)),
    );
    s.add_floor();
    let cube = s.add_mesh(generators::generate(Generator::Cube, 6)?);
    let sphere = s.add_mesh(generators::generate(Generator::Icosphere, 4)?);
    // A disc: the unit sphere flattened to a fifth along z in its own mesh, so the baked
    // thickness sees the thin shape.
    let mut disc = generators::generate(Generator::Icosphere, 4)?;
    for p in &mut disc.positions {
        p.z *= 0.2;
    }
    disc.normals = super::normals::angle_weighted_normals(&disc.positions, &disc.indices);
    disc.shape = None;
    let disc = s.add_mesh(disc);
    let mut cube_material = translucent(
        "translucent-jade",
        Vec3::new(0.55, 0.8, 0.6),
        ThicknessSource::Bake,
        Vec3::new(0.6, 1.0, 0.7),
    );
    // lucent's extension beside the talk's term: the skin sphere's shadow falls on the light
    // through the cube and the disc (`shadowed`; so does the head's on showcase-skin's far ear;
    // the other built-in scenes keep the talk's unshadowed term, which no object of theirs
    // would shadow anyway).
    set_shadowed(&mut cube_material);
    s.add(
        cube,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.45),
            glam::Quat::from_rotation_y(0.5),
            Vec3::new(-1.85, 0.45, -0.2),
        ),
        cube_material,
    );
    let mut skin = Material::opaque("skin", Vec3::new(0.85, 0.62, 0.52), 0.3, 0.5);
    let mut skin_profile = SssProfile::preset("skin")?;
    skin_profile.units_per_mm = 0.05;
    skin.sss = Some(skin_profile.clone());
    s.add(
        sphere,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.55),
            glam::Quat::IDENTITY,
            Vec3::new(-0.62, 0.55, 0.0),
        ),
        skin,
    );
    let mut marble = Material::opaque("marble", Vec3::new(0.86, 0.83, 0.78), 0.4, 0.3);
    let mut marble_profile = SssProfile::preset("marble")?;
    marble_profile.units_per_mm = 0.05;
    marble.sss = Some(marble_profile);
    s.add(
        sphere,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.55),
            glam::Quat::IDENTITY,
            Vec3::new(0.62, 0.55, 0.0),
        ),
        marble,
    );
    let mut ear = translucent(
        "ear",
        Vec3::new(0.85, 0.6, 0.5),
        ThicknessSource::Bake,
        Vec3::new(1.0, 0.35, 0.25),
    );
    ear.sss = Some(skin_profile);
    set_shadowed(&mut ear);
    s.add(
        disc,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.5, 0.65, 0.5),
            glam::Quat::from_rotation_y(-0.35),
            Vec3::new(1.82, 0.7, -0.1),
        ),
        ear,
    );
    s.lights = vec![
        // Key light from the side: the terminators where the profiles show their colour.
        Light::point(
            Vec3::new(-3.5, 2.2, 1.8),
            Vec3::new(1.0, 0.96, 0.9),
            30.0,
            15.0,
        ),
        // Warm back light behind the cube and the disc: light through the thin parts.
        Light::point(
            Vec3::new(1.2, 1.4, -2.6),
            Vec3::new(1.0, 0.75, 0.5),
            16.0,
            10.0,
        ),
        // A cool fill from the front.
        Light::directional(Vec3::new(0.2, -0.5, -1.0), Vec3::new(0.55, 0.65, 0.8), 0.35),
    ];
    Ok(s)
}

/// Other objects' shadows fall on `material`'s transmitted light (`Translucency::shadowed`).
fn set_shadowed(material: &mut Material) {
    if let Some(t) = &mut material.translucency {
        t.shadowed = true;
    }
}

fn skin() -> Result<Scene> {
    let mut s = base_scene(
        "skin",
        camera(Vec3::new(0.0, 1.2, 5.0), Vec3::new(0.0, 0.8, 0.0)),
    );
    s.add_floor();
    let sphere = s.add_mesh(generators::generate(Generator::Icosphere, 4)?);
    for (i, albedo) in [
        Vec3::new(0.85, 0.62, 0.52),
        Vec3::new(0.65, 0.43, 0.33),
        Vec3::new(0.36, 0.22, 0.16),
    ]
    .into_iter()
    .enumerate()
    {
        let mut m = Material::opaque(&format!("skin-{i}"), albedo, 0.35, 0.45);
        m.sss = Some(SssProfile::preset("skin")?);
        s.add(
            sphere,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(0.7),
                glam::Quat::IDENTITY,
                Vec3::new(-1.6 + 1.6 * i as f32, 0.7, 0.0),
            ),
            m,
        );
    }
    s.lights = vec![
        Light::point(
            Vec3::new(1.5, 2.5, 2.5),
            Vec3::new(1.0, 0.95, 0.9),
            20.0,
            15.0,
        ),
        Light::point(
            Vec3::new(-2.0, 1.5, -2.0),
            Vec3::new(0.5, 0.6, 1.0),
            10.0,
            10.0,
        ),
    ];
    Ok(s)
}

/// Li et al.'s Table 1 materials, one sphere each, named as the table names them: its
/// coefficients are Jensen et al. 2001's media (see [`super::layered`]): frog = apple,
/// teapot = skin1, bunny = chicken1, buddha = skin2, dragon = skimmilk; eq. 3 weighted
/// physically ([`super::layered::PHYSICAL_WEIGHTS`]).
fn layered() -> Result<Scene> {
    let mut s = base_scene(
        "layered",
        camera(Vec3::new(0.0, 1.5, 6.5), Vec3::new(0.0, 0.6, 0.0)),
    );
    s.add_floor();
    let sphere = s.add_mesh(generators::generate(Generator::Icosphere, 4)?);
    for (i, (name, preset)) in [
        ("frog", "apple"),
        ("teapot", "skin1"),
        ("bunny", "chicken1"),
        ("buddha", "skin2"),
        ("dragon", "skimmilk"),
    ]
    .iter()
    .enumerate()
    {
        let mut m = Material::opaque(name, Vec3::new(0.8, 0.7, 0.6), 0.3, 0.4);
        let mut medium = LayeredMedium::preset(preset)?;
        medium.weights = super::layered::PHYSICAL_WEIGHTS;
        m.layers = Some(medium);
        s.add(
            sphere,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(0.5),
                glam::Quat::IDENTITY,
                Vec3::new(-2.4 + 1.2 * i as f32, 0.5, 0.0),
            ),
            m,
        );
    }
    s.lights = vec![
        Light::point(Vec3::new(0.0, 3.0, 3.0), Vec3::ONE, 25.0, 15.0),
        Light {
            kind: LightKind::Spot {
                position: Vec3::new(0.0, 3.0, -3.0),
                direction: Vec3::new(0.0, -0.6, 1.0),
                range: 12.0,
                inner_degrees: 25.0,
                outer_degrees: 40.0,
            },
            color: Vec3::new(1.0, 0.8, 0.6),
            intensity: 30.0,
            translucency_scale: 1.0,
            shadows: true,
        },
    ];
    Ok(s)
}

/// A layered torus whose surface ripples every frame (the "dynamic objects" of Li et al.).
fn dynamic() -> Result<Scene> {
    let mut s = base_scene(
        "dynamic",
        camera(Vec3::new(0.0, 2.0, 4.5), Vec3::new(0.0, 0.8, 0.0)),
    );
    s.add_floor();
    let torus = s.add_mesh(generators::generate(Generator::Torus, 4)?);
    let mut m = Material::opaque("jelly", Vec3::new(0.7, 0.8, 0.5), 0.4, 0.3);
    // Li et al.'s bunny row: Jensen's chicken1.
    let mut medium = LayeredMedium::preset("chicken1")?;
    medium.weights = super::layered::PHYSICAL_WEIGHTS;
    m.layers = Some(medium);
    s.add(
        torus,
        Mat4::from_scale_rotation_translation(
            Vec3::ONE,
            glam::Quat::from_rotation_x(0.9),
            Vec3::new(0.0, 1.0, 0.0),
        ),
        m,
    );
    s.deformation = Some(Deformation::Wave {
        amplitude: 0.06,
        frequency: 9.0,
        speed: 3.0,
    });
    s.lights = vec![
        Light::point(Vec3::new(1.5, 3.0, 2.0), Vec3::ONE, 20.0, 15.0),
        Light::point(
            Vec3::new(-1.5, 1.0, -1.5),
            Vec3::new(0.4, 0.6, 1.0),
            8.0,
            8.0,
        ),
    ];
    Ok(s)
}

/// One teapot at `triangles` triangles (Li et al.'s table spans 2,900 to 1,084,450).
fn scaling(triangles: u64) -> Result<Scene> {
    let mut s = base_scene(
        "scaling",
        camera(Vec3::new(0.0, 1.6, 3.6), Vec3::new(0.0, 0.6, 0.0)),
    );
    let (mesh, _) = generators::generate_with_triangles(Generator::Teapot, triangles)?;
    let teapot = s.add_mesh(mesh);
    let mut m = Material::opaque("scaling", Vec3::new(0.8, 0.75, 0.7), 0.4, 0.35);
    // Li et al.'s teapot row: Jensen's skin1.
    m.layers = Some(LayeredMedium::preset("skin1")?);
    s.add(teapot, Mat4::IDENTITY, m);
    s.lights = vec![Light::point(
        Vec3::new(2.0, 3.0, 2.0),
        Vec3::ONE,
        25.0,
        15.0,
    )];
    Ok(s)
}
