//! The showcase scenes: one per technique, each built so the technique is unmistakable in a
//! still (issue 16's look check: each changes at least 5% of its pixels against `--technique
//! none`, without halos; `tests/gpu/showcase.rs` measures both, `lucent gallery` renders them).
//!
//! - `showcase-translucency`: GDC 2011 where it shines: thin objects (an ear, two leaves, a
//!   wax panel) with baked thickness, a warm light behind them, the camera looking into it.
//! - `showcase-skin`: Lee Perry-Smith's scanned head (`assets/showcase-skin.toml`) as Jensen's
//!   skin1 at physical scale, its colour map applied after the scatter, a key light from the
//!   front left (the red terminator), a fill, and a back light the ear glows against (the
//!   medium's transmission through the ear's thickness).
//! - `showcase-marble`: veined marble (a procedural albedo and a fine normal map lined up with
//!   the veins) under a grazing light, the marble profile at 5x: SSS turns the grainy bumps
//!   into the soft, waxy look of stone that light enters.
//! - `showcase-layered`: Li et al.'s media as jade (a thin leaf, a ring) and wax (candles),
//!   lit from behind and the side: thin parts glow with the colour the medium transmits.
//!
//! Every other mesh is made here from the generators by sculpting (a displacement of the
//! vertices, normals and tangents recomputed); the head is a scan in `assets/`, so no scene
//! needs a file from outside the repository.

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};

use super::build::{base_scene, camera, translucent};
use super::environment::Environment;
use super::generators::{self, Generator};
use super::layered::{LayeredMedium, PHYSICAL_WEIGHTS};
use super::material::{
    Light, LightKind, Material, ProceduralTexture, SssProfile, TextureSource, ThicknessSource,
};
use super::{normals, Mesh, Scene};
use crate::{LucentError, Result};

/// `mesh` with every vertex moved by `displace` (object space in, object space out), normals
/// recomputed angle-weighted and tangents from the UVs; the exact shape is dropped.
fn sculpt(mut mesh: Mesh, displace: impl Fn(Vec3) -> Vec3) -> Mesh {
    for p in &mut mesh.positions {
        *p = displace(*p);
    }
    mesh.normals = normals::angle_weighted_normals(&mesh.positions, &mesh.indices);
    if !mesh.uvs.is_empty() {
        mesh.tangents =
            normals::generate_tangents(&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
    }
    mesh.shape = None;
    mesh
}

/// A thin, cupped ear-like shell: the unit icosphere flattened to `thickness` along z, an
/// egg-shaped outline (wider at the top), cupped forward, its rim rolled.
fn ear_mesh(thickness: f32) -> Result<Mesh> {
    Ok(sculpt(
        generators::generate(Generator::Icosphere, 4)?,
        |p| {
            let y = p.y;
            // Wider at the top than at the lobe.
            let width = 0.55 + 0.2 * y;
            let mut q = Vec3::new(p.x * width, y, p.z * thickness);
            // Cupped: the middle sits back, the rim comes forward.
            q.z += 0.18 * (q.x / 0.55).powi(2) + 0.08 * (y * 0.9).powi(2);
            // The rolled rim (the helix): the outer edge thickens a little and curls forward.
            let rim = ((p.x * p.x + p.y * p.y).sqrt() - 0.75).max(0.0) / 0.25;
            q.z += 0.06 * rim;
            q
        },
    ))
}

/// A leaf: a thin, pointed blade, bent back along its length and a little across.
fn leaf_mesh() -> Result<Mesh> {
    Ok(sculpt(
        generators::generate(Generator::Icosphere, 4)?,
        |p| {
            let y = p.y;
            // Pointed at both ends: the width falls to 0 at y = +-1.
            let width = 0.42 * (1.0 - y * y).max(0.0).sqrt() * (1.0 - 0.25 * y);
            let x = p.x * width;
            let z = p.z * 0.025 - 0.22 * y * y - 0.5 * x * x;
            Vec3::new(x, y, z)
        },
    ))
}

/// GDC 2011 translucency: thin objects with baked thickness, lit from behind.
pub fn translucency() -> Result<Scene> {
    let mut s = base_scene(
        "showcase-translucency",
        camera(Vec3::new(0.0, 1.25, 4.2), Vec3::new(0.0, 1.05, 0.0)),
    );
    s.sky = Vec3::new(0.015, 0.018, 0.03);
    s.environment =
        Environment::hemisphere(Vec3::new(0.05, 0.06, 0.09), Vec3::new(0.02, 0.018, 0.015));
    s.add_floor();
    let ear = s.add_mesh(ear_mesh(0.09)?);
    let leaf = s.add_mesh(leaf_mesh()?);
    let panel = s.add_mesh(generators::generate(Generator::Cube, 8)?);

    let mut ear_material = translucent(
        "ear",
        Vec3::new(0.86, 0.62, 0.52),
        ThicknessSource::Bake,
        Vec3::new(1.0, 0.32, 0.18),
    );
    if let Some(t) = &mut ear_material.translucency {
        t.power = 6.0;
        t.distortion = 0.25;
        t.ambient = 0.15;
    }
    s.add(
        ear,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.55),
            Quat::from_rotation_y(0.35),
            Vec3::new(-1.35, 1.15, 0.0),
        ),
        ear_material,
    );
    let mut leaf_material = translucent(
        "leaf",
        Vec3::new(0.22, 0.42, 0.1),
        ThicknessSource::Bake,
        Vec3::new(0.55, 1.0, 0.22),
    );
    if let Some(t) = &mut leaf_material.translucency {
        t.power = 4.0;
        t.distortion = 0.3;
        t.ambient = 0.2;
    }
    for (x, tilt, scale) in [(-0.1f32, 0.25f32, 0.8f32), (0.55, -0.3, 0.65)] {
        s.add(
            leaf,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(scale),
                Quat::from_rotation_z(tilt) * Quat::from_rotation_y(0.2),
                Vec3::new(x, 0.95 + 0.2 * scale, 0.15),
            ),
            leaf_material.clone(),
        );
    }
    let mut wax = translucent(
        "wax panel",
        Vec3::new(0.92, 0.86, 0.72),
        ThicknessSource::Bake,
        Vec3::new(1.0, 0.62, 0.28),
    );
    if let Some(t) = &mut wax.translucency {
        t.power = 3.0;
        t.distortion = 0.15;
        t.ambient = 0.25;
    }
    s.add(
        panel,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.45, 0.7, 0.035),
            Quat::from_rotation_y(-0.45),
            Vec3::new(1.45, 0.75, -0.1),
        ),
        wax,
    );
    s.lights = vec![
        // The light behind everything, a little above the objects: the talk's back light.
        {
            let mut l = Light::point(
                Vec3::new(0.0, 1.35, -1.4),
                Vec3::new(1.0, 0.86, 0.66),
                14.0,
                9.0,
            );
            l.translucency_scale = 2.5;
            l
        },
        // A dim cool fill from the front so the lit sides read too.
        Light::directional(Vec3::new(0.3, -0.4, -1.0), Vec3::new(0.5, 0.6, 0.8), 0.35),
    ];
    Ok(s)
}

/// The folder of the assets built-in scenes load (`assets/` in the repository): the build's
/// own copy, so `lucent` finds it from any working directory.
pub fn assets_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// The scene file a built-in scene is made from, for those written as one (`showcase-skin`).
pub fn builtin_scene_file(name: &str) -> Option<PathBuf> {
    (name == "showcase-skin").then(|| assets_dir().join("showcase-skin.toml"))
}

/// Screen-space SSS on skin: Lee Perry-Smith's scanned head as skin1, key, fill and a back
/// light through the ear (`assets/showcase-skin.toml` says what each part is for).
pub fn skin() -> Result<Scene> {
    let path = builtin_scene_file("showcase-skin").expect("showcase-skin is a scene file");
    if !path.is_file() {
        return Err(LucentError::file(
            &path,
            "the head scan showcase-skin loads is not there: lucent's built-in scenes read \
             the repository's assets/ folder (this binary was built from a checkout that has \
             moved or lost it)",
        ));
    }
    super::file::load_scene_file(&path)
}

/// Veined marble under a grazing light.
pub fn marble() -> Result<Scene> {
    let mut s = base_scene(
        "showcase-marble",
        camera(Vec3::new(0.4, 1.45, 3.1), Vec3::new(0.1, 0.75, 0.0)),
    );
    s.sky = Vec3::new(0.03, 0.03, 0.04);
    s.environment =
        Environment::hemisphere(Vec3::new(0.05, 0.055, 0.07), Vec3::new(0.025, 0.022, 0.02));
    s.add_floor();
    let teapot = s.add_mesh(generators::generate(Generator::Teapot, 5)?);
    let ring = s.add_mesh(generators::generate(Generator::Torus, 5)?);
    let plinth = s.add_mesh(generators::generate(Generator::Cube, 6)?);
    let veined = |name: &str, albedo: Vec3, vein: Vec3, frequency: f32| -> Result<Material> {
        let mut m = Material::opaque(name, albedo, 0.45, 0.22);
        m.albedo_texture = Some(TextureSource::Procedural(ProceduralTexture::MarbleAlbedo {
            frequency,
            vein_color: vein,
        }));
        m.normal_texture = Some(TextureSource::Procedural(ProceduralTexture::MarbleNormal {
            frequency,
            strength: 0.7,
        }));
        let mut profile = SssProfile::preset("marble")?;
        // The teapot is 1.5 units for a real 150 mm: 0.01 units per mm; at 3.5x the light
        // enters a few pixels deep at gallery sizes and the veins (which the blur of the lit
        // diffuse softens with the rest) still read.
        profile.units_per_mm = 0.035;
        m.sss = Some(profile);
        Ok(m)
    };
    s.add(
        teapot,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.8),
            Quat::from_rotation_y(-0.5),
            Vec3::new(-0.35, 0.5, 0.0),
        ),
        veined(
            "white marble",
            Vec3::new(0.93, 0.91, 0.87),
            Vec3::new(0.32, 0.3, 0.34),
            12.0,
        )?,
    );
    s.add(
        ring,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.36),
            Quat::from_rotation_x(0.25),
            Vec3::new(1.05, 0.13, 0.45),
        ),
        veined(
            "red-veined marble",
            Vec3::new(0.93, 0.88, 0.84),
            Vec3::new(0.6, 0.14, 0.1),
            9.0,
        )?,
    );
    s.add(
        plinth,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.9, 0.25, 0.6),
            Quat::from_rotation_y(-0.5),
            Vec3::new(-0.35, 0.25, 0.0),
        ),
        veined(
            "grey marble",
            Vec3::new(0.7, 0.7, 0.72),
            Vec3::new(0.2, 0.2, 0.22),
            7.0,
        )?,
    );
    s.lights = vec![
        // The grazing light: low, from the side, raking across the bumps.
        Light::point(
            Vec3::new(-3.2, 0.9, 0.9),
            Vec3::new(1.0, 0.93, 0.82),
            30.0,
            14.0,
        ),
        // A soft cool fill from above the camera.
        Light::directional(Vec3::new(-0.2, -1.0, -0.6), Vec3::new(0.6, 0.68, 0.8), 0.4),
    ];
    Ok(s)
}

/// A homogeneous medium (Li et al.'s one-layer case) from reduced scattering and absorption
/// (mm^-1), weighted physically (eq. 3 without the albedo term).
fn medium(
    name: &str,
    sigma_s_prime: [f32; 3],
    sigma_a: [f32; 3],
    units_per_mm: f32,
) -> LayeredMedium {
    let mut m = LayeredMedium::homogeneous(
        name,
        Vec3::from(sigma_s_prime),
        Vec3::from(sigma_a),
        0.0,
        1.3,
    );
    m.weights = PHYSICAL_WEIGHTS;
    m.units_per_mm = units_per_mm;
    m
}

/// Li et al.'s layered media as jade and wax, lit from behind and the side.
pub fn layered() -> Result<Scene> {
    let mut s = base_scene(
        "showcase-layered",
        camera(Vec3::new(0.0, 1.35, 3.6), Vec3::new(0.0, 0.6, 0.0)),
    );
    s.sky = Vec3::new(0.02, 0.022, 0.03);
    s.environment =
        Environment::hemisphere(Vec3::new(0.04, 0.045, 0.06), Vec3::new(0.02, 0.018, 0.015));
    s.add_floor();
    // Jade: scatters little, absorbs red and blue, so what comes through is green. Wax:
    // scatters a lot and absorbs a little blue: a warm, milky glow.
    let jade = medium("jade", [0.8, 0.9, 0.8], [1.4, 0.05, 0.9], 0.05);
    // Wax: scatters a little less than milk, absorbs a little blue; light travels a few
    // tenths of the candles' radius inside (mean free path about 1 mm = 0.1 units).
    let wax = medium("wax", [0.9, 1.0, 1.15], [0.002, 0.01, 0.05], 0.1);
    let with_medium = |name: &str, albedo: Vec3, medium: &LayeredMedium| {
        let mut m = Material::opaque(name, albedo, 0.5, 0.2);
        m.layers = Some(medium.clone());
        m
    };
    let leaf = s.add_mesh(leaf_mesh()?);
    let ring = s.add_mesh(generators::generate(Generator::Torus, 5)?);
    let candle = s.add_mesh(generators::generate(Generator::Icosphere, 4)?);
    s.add(
        leaf,
        Mat4::from_scale_rotation_translation(
            Vec3::new(0.75, 0.62, 0.75),
            Quat::from_rotation_z(-1.15) * Quat::from_rotation_x(-0.3),
            Vec3::new(-0.95, 0.5, 0.2),
        ),
        with_medium("jade leaf", Vec3::new(0.35, 0.7, 0.45), &jade),
    );
    s.add(
        ring,
        Mat4::from_scale_rotation_translation(
            Vec3::splat(0.42),
            Quat::from_rotation_x(1.2),
            Vec3::new(0.15, 0.5, -0.2),
        ),
        with_medium("jade ring", Vec3::new(0.35, 0.7, 0.45), &jade),
    );
    for (x, r, z) in [(1.05f32, 0.3f32, 0.1f32), (1.6, 0.2, -0.35)] {
        s.add(
            candle,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(r),
                Quat::IDENTITY,
                Vec3::new(x, r, z),
            ),
            with_medium("wax candle", Vec3::new(0.9, 0.82, 0.65), &wax),
        );
    }
    s.lights = vec![
        // Behind the objects: the thin leaf, the ring's rim and the candles glow.
        Light {
            kind: LightKind::Spot {
                position: Vec3::new(0.2, 1.6, -2.4),
                direction: Vec3::new(0.0, -0.45, 1.0),
                range: 10.0,
                inner_degrees: 30.0,
                outer_degrees: 50.0,
            },
            color: Vec3::new(1.0, 0.9, 0.75),
            intensity: 26.0,
            translucency_scale: 1.0,
            shadows: true,
        },
        // A key from the front left.
        Light::point(
            Vec3::new(-2.5, 2.2, 2.2),
            Vec3::new(0.9, 0.93, 1.0),
            14.0,
            12.0,
        ),
    ];
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn showcase_meshes_are_valid() {
        for (name, mesh) in [
            ("ear", ear_mesh(0.09).unwrap()),
            ("leaf", leaf_mesh().unwrap()),
        ] {
            mesh.validate(name).unwrap();
            assert!(mesh.normals.iter().all(|n| n.is_finite()));
            assert_eq!(mesh.tangents.len(), mesh.positions.len());
        }
    }

    #[test]
    fn showcase_scenes_load_and_validate() {
        for s in [translucency(), skin(), marble(), layered()] {
            let s = s.unwrap();
            for o in &s.objects {
                o.material.validate().unwrap();
            }
            assert!(!s.lights.is_empty());
        }
    }

    #[test]
    fn showcase_skin_is_the_scan_with_both_maps_and_its_credit() {
        let s = skin().unwrap();
        assert_eq!(s.name, "showcase-skin");
        assert_eq!(s.objects.len(), 1);
        let skin = &s.objects[0].material;
        let file = |t: &Option<TextureSource>| match t {
            Some(TextureSource::File(p)) => p.file_name().unwrap().to_string_lossy().into_owned(),
            other => panic!("{other:?}"),
        };
        assert_eq!(file(&skin.albedo_texture), "Map-COL.jpg");
        assert_eq!(
            file(&skin.normal_texture),
            "Infinite-Level_02_Tangent_SmoothUV.jpg"
        );
        assert!(skin.medium.is_some() && skin.sss.is_some());
        assert!(s.meshes[0].positions.len() >= 8838);
        assert!(s.credits.iter().any(|c| c.contains("Lee Perry-Smith")));
        // Its inputs are the scene file's, so no output may overwrite the scan.
        let inputs = crate::scene::inputs::scene_inputs("showcase-skin");
        assert!(
            inputs
                .iter()
                .any(|(_, p)| p.ends_with("lee-perry-smith.obj")),
            "{inputs:?}"
        );
    }
}
