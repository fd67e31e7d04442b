//! The showcase scenes: one per technique, each built so the technique is unmistakable in a
//! still (issue 16's look check: each changes at least 5% of its pixels against `--technique
//! none`, without halos; `tests/gpu/showcase.rs` measures both, `lucent gallery` renders them).
//!
//! - `showcase-translucency`: GDC 2011 where it shines: thin objects (an ear, two leaves, a
//!   wax panel) with baked thickness, a warm light behind them, the camera looking into it.
//! - `showcase-skin`: a sculpted head with ears, d'Eon's skin profile at 10x physical scale so
//!   the red Gaussians span tens of pixels, a key light from the side (the red terminator) and
//!   a back light through the ears (translucency and SSS on one material).
//! - `showcase-marble`: veined marble (a procedural albedo and a fine normal map lined up with
//!   the veins) under a grazing light, the marble profile at 5x: SSS turns the grainy bumps
//!   into the soft, waxy look of stone that light enters.
//! - `showcase-layered`: Li et al.'s media as jade (a thin leaf, a ring) and wax (candles),
//!   lit from behind and the side: thin parts glow with the colour the medium transmits.
//!
//! Every mesh is made here from the generators by sculpting (a displacement of the vertices,
//! normals and tangents recomputed), so the scenes need no file from outside the repository.

use glam::{Mat4, Quat, Vec3};

use super::build::{base_scene, camera, translucent};
use super::environment::Environment;
use super::generators::{self, Generator};
use super::layered::{LayeredMedium, PHYSICAL_WEIGHTS};
use super::material::{
    Light, LightKind, Material, ProceduralTexture, SssProfile, TextureSource, ThicknessSource,
};
use super::{normals, Mesh, Scene};
use crate::Result;

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

/// A Gaussian bump of height 1 at `centre` with radii `radius` (per axis).
fn bump(p: Vec3, centre: Vec3, radius: Vec3) -> f32 {
    let d = (p - centre) / radius;
    (-d.length_squared()).exp()
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

/// A head with a nose, brow, eye sockets and cheeks sculpted from an icosphere (1.9 units tall).
fn head_mesh() -> Result<Mesh> {
    Ok(sculpt(
        generators::generate(Generator::Icosphere, 5)?,
        |p| {
            // The skull: taller than wide, deeper at the back, the jaw narrower.
            let jaw = 1.0 - 0.22 * (-p.y).max(0.0);
            let mut q = Vec3::new(p.x * 0.72 * jaw, p.y * 0.95, p.z * 0.82);
            let front = p.z.max(0.0);
            let n = p.normalize_or_zero();
            let mut out = 0.0;
            // Nose (ridge and tip), brow, cheeks, chin; eye sockets and the mouth's groove in.
            out += 0.2 * bump(p, Vec3::new(0.0, -0.12, 1.0), Vec3::new(0.12, 0.26, 0.3)) * front;
            out += 0.1 * bump(p, Vec3::new(0.0, -0.3, 1.0), Vec3::new(0.17, 0.1, 0.3)) * front;
            out += 0.07 * bump(p, Vec3::new(0.0, 0.24, 0.97), Vec3::new(0.5, 0.09, 0.3)) * front;
            out += 0.06 * bump(p, Vec3::new(0.4, -0.18, 0.85), Vec3::new(0.2, 0.2, 0.3)) * front;
            out += 0.06 * bump(p, Vec3::new(-0.4, -0.18, 0.85), Vec3::new(0.2, 0.2, 0.3)) * front;
            out += 0.07 * bump(p, Vec3::new(0.0, -0.78, 0.62), Vec3::new(0.2, 0.12, 0.3)) * front;
            out -= 0.045 * bump(p, Vec3::new(0.3, 0.1, 0.95), Vec3::new(0.17, 0.11, 0.3)) * front;
            out -= 0.045 * bump(p, Vec3::new(-0.3, 0.1, 0.95), Vec3::new(0.17, 0.11, 0.3)) * front;
            out -= 0.03 * bump(p, Vec3::new(0.0, -0.52, 0.9), Vec3::new(0.22, 0.03, 0.3)) * front;
            q += n * out;
            q
        },
    ))
}

/// Screen-space SSS on skin: the red terminator and glowing ears.
pub fn skin() -> Result<Scene> {
    let mut s = base_scene(
        "showcase-skin",
        camera(Vec3::new(0.9, 1.3, 2.55), Vec3::new(0.05, 1.05, 0.0)),
    );
    s.sky = Vec3::new(0.02, 0.022, 0.03);
    s.environment =
        Environment::hemisphere(Vec3::new(0.045, 0.05, 0.065), Vec3::new(0.02, 0.016, 0.014));
    let head = s.add_mesh(head_mesh()?);
    let ear = s.add_mesh(ear_mesh(0.16)?);
    // The head is about 1.9 units for a real 230 mm: 0.008 units per mm; the profile at 10x
    // so its widest (red) Gaussians span tens of pixels at gallery sizes.
    let mut profile = SssProfile::preset("skin")?;
    profile.units_per_mm = 0.08;
    let mut skin = Material::opaque("skin", Vec3::new(0.85, 0.6, 0.5), 0.3, 0.45);
    skin.sss = Some(profile.clone());
    // Turned a little toward the camera.
    let turn = Quat::from_rotation_y(0.3);
    s.add(
        head,
        Mat4::from_rotation_translation(turn, Vec3::new(0.0, 1.1, 0.0)),
        skin.clone(),
    );
    // Ears: skin that also lets the back light through (translucency and SSS on one material).
    let mut ear_material = translucent(
        "ear skin",
        Vec3::new(0.85, 0.6, 0.5),
        ThicknessSource::Bake,
        Vec3::new(1.0, 0.3, 0.18),
    );
    ear_material.sss = Some(profile);
    if let Some(t) = &mut ear_material.translucency {
        t.power = 5.0;
        t.distortion = 0.3;
        t.ambient = 0.1;
        // The head stands between the back light and the far ear: its shadow falls on the
        // light through that ear (lucent's extension; the talk's term would light it anyway).
        t.shadowed = true;
    }
    for side in [-1.0f32, 1.0] {
        s.add(
            ear,
            Mat4::from_scale_rotation_translation(
                Vec3::new(0.22, 0.32, 0.3),
                turn * Quat::from_rotation_y(side * 1.15),
                Vec3::new(0.0, 1.1, 0.0) + turn * Vec3::new(side * 0.8, -0.02, -0.08),
            ),
            ear_material.clone(),
        );
    }
    s.lights = vec![
        // The key light from the camera's right, level with the face: half the face in light,
        // the terminator down its middle.
        Light::point(
            Vec3::new(3.2, 1.6, 0.4),
            Vec3::new(1.0, 0.95, 0.88),
            26.0,
            12.0,
        ),
        // A warm back light behind the near ear: it glows, and the head's rim with it.
        {
            let mut l = Light::point(
                Vec3::new(1.5, 1.4, -1.6),
                Vec3::new(1.0, 0.8, 0.6),
                10.0,
                8.0,
            );
            l.translucency_scale = 2.0;
            l
        },
    ];
    Ok(s)
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
            ("head", head_mesh().unwrap()),
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
}
