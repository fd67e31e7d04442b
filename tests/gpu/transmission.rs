//! Diffuse transmission through thickness for screen-space SSS materials with a medium
//! (lucent::features::sss::transmission): a back-lit slab against the f64 twin
//! (lucent::reference::transmission), and extreme media without NaN or Inf.

use std::path::Path;

use glam::DVec3;
use lucent::features::sss::transmission::SssTransmission;
use lucent::frame::{FrameSettings, Technique};
use lucent::scene::file::parse_scene;

use crate::common::TestGpu;

/// A 40 x 40 x 4 mm slab (1 unit = 20 mm) of `medium` (a `[material.medium]` body), a point
/// light 1 unit behind it, the camera in front, no ambient light.
fn slab(medium: &str, albedo: &str) -> lucent::scene::Scene {
    let source = format!(
        r#"name = "transmission-slab"
ambient = [0.0, 0.0, 0.0]
sky = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 36.0
[[mesh]]
name = "slab"
generator = "cube"
level = 3
[[material]]
name = "m"
specular = 0.0
{albedo}
[material.medium]
{medium}
units_per_mm = 0.05
[[object]]
mesh = "slab"
material = "m"
scale = [1.0, 1.0, 0.1]
[[light]]
type = "point"
position = [0.0, 0.0, -1.0]
intensity = 10.0
range = 1000.0
"#
    );
    parse_scene(Path::new("transmission-slab.toml"), &source).unwrap_or_else(|e| panic!("{e}"))
}

fn technique(name: &str) -> Technique {
    Technique::parse(name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn a_back_lit_slab_lets_through_what_the_f64_twin_says() {
    let test = TestGpu::new();
    let scene = slab("preset = \"skin1\"\neta = 1.0", "");
    let material = &scene.objects[0].material;
    let medium = material.medium.as_ref().unwrap();
    let t = SssTransmission::of(medium);
    let albedo = material.albedo.as_dvec3();
    // The centre pixel sees the front face's centre; the light enters straight behind it.
    let x_o = DVec3::new(0.0, 0.0, 0.1);
    let p_in = DVec3::new(0.0, 0.0, -0.1);
    let expected = lucent::reference::transmission::sss_transmitted(
        &scene.lights[0],
        x_o,
        DVec3::Z,
        p_in,
        albedo,
        &t.dipoles,
        t.mm_per_unit,
        DVec3::from_array(t.medium_albedo),
    );
    let (w, h) = (64usize, 48usize);
    for name in ["separable", "burley"] {
        for (on, settings) in [true, false].map(|on| {
            let mut s = FrameSettings {
                technique: technique(name),
                export_hdr: true,
                ..FrameSettings::new(w as u32, h as u32)
            };
            s.sss.transmission = on;
            (on, s)
        }) {
            let hdr = test.render(&scene, settings).hdr.unwrap();
            assert!(hdr.iter().all(|v| v.is_finite()), "{name}: NaN or Inf");
            // The four pixels around the image's centre.
            let mut got = DVec3::ZERO;
            for (x, y) in [(31, 23), (32, 23), (31, 24), (32, 24)] {
                let i = (y * w + x) * 4;
                got += DVec3::new(hdr[i].into(), hdr[i + 1].into(), hdr[i + 2].into()) / 4.0;
            }
            println!("{name} transmission {on}: {got:.5} (f64 twin {expected:.5})");
            if on {
                // The blur averages a few millimetres of a slowly varying field, the map's
                // depths are 32-bit: within 4% per channel.
                for c in 0..3 {
                    let relative = (got[c] - expected[c]).abs() / expected[c];
                    assert!(relative < 0.04, "{name} channel {c}: {got} vs {expected}");
                }
            } else {
                assert!(
                    got.max_element() < 1e-6,
                    "{name}: back-lit without transmission"
                );
            }
        }
    }
    test.finish();
}

#[test]
fn extreme_media_transmit_no_nan_or_inf() {
    let test = TestGpu::new();
    // sigma -> 0 and 1e6 / mm, albedo -> 1, g -> +-0.999, eta 1 and 2.5 (issue 26).
    let media = [
        "sigma_a = [0.0, 0.0, 0.0]\nsigma_s = [0.0, 0.0, 0.0]",
        "sigma_a = [1e-9, 0.0, 1e-9]\nsigma_s = [1e-9, 1e-9, 0.0]",
        "sigma_a = [1e6, 0.0, 1e6]\nsigma_s = [1e6, 1e6, 0.0]",
        "sigma_a = [0.0, 0.0, 0.0]\nsigma_s = [1.0, 10.0, 1e6]",
        "sigma_a = [0.01, 0.01, 0.01]\nsigma_s = [1.0, 1.0, 1.0]\ng = 0.999",
        "sigma_a = [0.01, 0.01, 0.01]\nsigma_s = [1.0, 1.0, 1.0]\ng = -0.999",
    ];
    let mut failures = Vec::new();
    for medium in media {
        for eta in ["1.0", "2.5"] {
            let scene = slab(&format!("{medium}\neta = {eta}"), "");
            for name in ["separable", "burley", "control"] {
                let settings = FrameSettings {
                    technique: technique(name),
                    export_hdr: true,
                    ..FrameSettings::new(32, 24)
                };
                let hdr = test.render(&scene, settings).hdr.unwrap();
                let bad = hdr.iter().filter(|v| !v.is_finite()).count();
                if bad > 0 {
                    failures.push(format!("{medium:?} eta {eta} {name}: {bad} NaN/Inf"));
                }
            }
        }
    }
    test.finish();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
