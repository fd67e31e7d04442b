//! Li et al.'s layered passes (lavapipe, validation on): each term of eq. 3 against its f64
//! reference on a lone sphere (tolerances below, measured numbers in docs/layered.md), the
//! plan of a layered frame, and what a frame without layered materials leaves out.

use glam::Vec3;
use lucent::features::layered::{LayeredKnobs, PhaseForm, LAYERED_PART};
use lucent::frame::{FrameDesc, FrameSettings, Technique};
use lucent::graph::Plan;
use lucent::measure::layered_error::{
    clear_medium, comparison_lights, sphere_scene, term_error, Term,
};
use lucent::scene::builtin;
use lucent::scene::layered::{Layer, LayeredMedium, Thickness};

use crate::common;

use crate::common::TestGpu;

fn settings(w: u32, h: u32) -> FrameSettings {
    let mut s = FrameSettings::new(w, h);
    s.shadows.size = 512;
    s
}

/// Two layers with a forward-scattering top (skin-layered's epidermis over a clearer rest).
fn two_layers() -> LayeredMedium {
    let mut m = LayeredMedium::preset("apple").unwrap();
    m.layers = vec![
        Layer {
            sigma_a: Vec3::new(0.2, 0.4, 0.8),
            sigma_s: Vec3::new(6.0, 7.0, 9.0),
            g: 0.7,
            thickness: Thickness::Mm(0.3),
        },
        Layer {
            sigma_a: Vec3::new(0.01, 0.03, 0.1),
            sigma_s: Vec3::new(1.5, 2.0, 2.5),
            g: 0.0,
            thickness: Thickness::Rest,
        },
    ];
    m
}

/// (medium, term, knobs, largest relative L1 error accepted). The tolerances are about 1.5-2x
/// what was measured (docs/layered.md): the GPU's error comes from the mesh (5,120 triangles)
/// against the sphere, the 512^2 light-space maps, K steps against 256, and for multiple
/// scattering M pixel lights over what the screen sees against the whole surface.
fn cases() -> Vec<(&'static str, LayeredMedium, Term, LayeredKnobs, f64)> {
    let default = LayeredKnobs::default();
    let fine = LayeredKnobs {
        steps: 64,
        pixel_lights: 64,
        ..default
    };
    let preset = |n| LayeredMedium::preset(n).unwrap();
    vec![
        ("apple", preset("apple"), Term::Single, default, 0.07),
        ("apple", preset("apple"), Term::Single, fine, 0.06),
        ("skin1", preset("skin1"), Term::Single, default, 0.07),
        ("two layers", two_layers(), Term::Single, default, 0.08),
        ("two layers", two_layers(), Term::Single, fine, 0.08),
        (
            "two layers schlick",
            two_layers(),
            Term::Single,
            LayeredKnobs {
                phase: PhaseForm::Schlick,
                ..fine
            },
            0.08,
        ),
        ("apple", preset("apple"), Term::Multiple, default, 0.08),
        ("apple", preset("apple"), Term::Multiple, fine, 0.06),
        ("skin1", preset("skin1"), Term::Multiple, default, 0.15),
        (
            "skin1 half irradiance",
            preset("skin1"),
            Term::Multiple,
            LayeredKnobs {
                half_irradiance: true,
                ..default
            },
            0.15,
        ),
        (
            "apple full gather",
            preset("apple"),
            Term::Multiple,
            LayeredKnobs {
                half_gather: false,
                ..default
            },
            0.08,
        ),
        (
            "skin1 full gather",
            preset("skin1"),
            Term::Multiple,
            LayeredKnobs {
                half_gather: false,
                ..default
            },
            0.15,
        ),
        ("clear", clear_medium(), Term::Transmitted, default, 0.12),
    ]
}

#[test]
fn each_term_agrees_with_its_reference() {
    let test = TestGpu::new();
    for (name, medium, term, knobs, tolerance) in cases() {
        let scene = sphere_scene(medium, comparison_lights()).unwrap();
        let mut s = settings(96, 96);
        s.layered = knobs;
        let e = term_error(&test.gpu, &test.shaders, &test.cache, &scene, &s, term, 3).unwrap();
        println!(
            "{name} {} (K {}, M {}, {}{}): {} px, relative L1 {:.4} (accepted {tolerance}), \
             GPU mean {:.5}, reference mean {:.5}",
            term.name(),
            knobs.steps,
            knobs.pixel_lights,
            knobs.phase.name(),
            match (knobs.half_irradiance, knobs.half_gather) {
                (true, true) => ", half irradiance, half gather",
                (true, false) => ", half irradiance, full gather",
                (false, true) => ", half gather",
                (false, false) => ", full gather",
            },
            e.pixels,
            e.relative_l1,
            e.gpu_mean,
            e.reference_mean
        );
        assert!(e.pixels > 300, "{name}: {} pixels compared", e.pixels);
        assert!(
            e.reference_mean > 1e-4,
            "{name}: the reference is ~0: nothing tested"
        );
        assert!(
            e.relative_l1 <= tolerance || std::env::var("LUCENT_MEASURE").is_ok(),
            "{name} {}: relative L1 {:.4} > {tolerance}",
            term.name(),
            e.relative_l1
        );
    }
    test.finish();
}

fn passes(plan: &Plan) -> Vec<String> {
    plan.passes.iter().map(|p| p.name.clone()).collect()
}

fn images(plan: &Plan) -> Vec<String> {
    plan.resources
        .iter()
        .filter(|r| r.lifetime.is_some())
        .map(|r| r.name.clone())
        .collect()
}

const LAYERED_PASSES: [&str; 4] = [
    "layered irradiance",
    "single scattering",
    "multiple scattering",
    "multiple scattering blur",
];
const LAYERED_IMAGES: [&str; 3] = ["gbuffer.layered", "layered.irradiance", "light-space.entry"];

#[test]
fn a_layered_frame_has_the_scattering_passes_and_others_leave_them_out() {
    let layered = builtin::builtin("layered").unwrap();
    let s = settings(320, 240);
    let p = common::plan(&layered, &s);
    for name in LAYERED_PASSES {
        assert!(
            passes(&p).iter().any(|n| n == name),
            "{name}: {:?}",
            passes(&p)
        );
    }
    for name in LAYERED_IMAGES {
        assert!(
            images(&p).iter().any(|n| n == name),
            "{name}: {:?}",
            images(&p)
        );
    }
    // Half-resolution irradiance.
    let mut half = s;
    half.layered.half_irradiance = true;
    let p = common::plan(&layered, &half);
    assert_eq!(common::image_size(&p, "layered.irradiance"), (160, 120));
    // The term multiple scattering writes for single scattering to resolve: half size by
    // default (the half gather; single scattering resolves it over 4x4 texels), full size with
    // the full gather (single scattering averages it over 3x3 pixels); drawn before single
    // scattering either way.
    assert_eq!(common::image_size(&p, "layered.multiple"), (160, 120));
    // Blurred at the gather's resolution between the two.
    assert_eq!(
        common::image_size(&p, "layered.multiple-blurred"),
        (160, 120)
    );
    let order = passes(&p);
    let at = |name: &str| order.iter().position(|n| n == name).unwrap();
    assert!(
        at("multiple scattering") < at("multiple scattering blur")
            && at("multiple scattering blur") < at("single scattering"),
        "{order:?}"
    );
    let mut full_gather = s;
    full_gather.layered.half_gather = false;
    let p = common::plan(&layered, &full_gather);
    assert_eq!(common::image_size(&p, "layered.multiple"), (320, 240));
    assert_eq!(
        common::image_size(&p, "layered.multiple-blurred"),
        (320, 240)
    );
    let order = passes(&p);
    let at = |name: &str| order.iter().position(|n| n == name).unwrap();
    assert!(
        at("multiple scattering") < at("multiple scattering blur")
            && at("multiple scattering blur") < at("single scattering"),
        "{order:?}"
    );
    // Without shadows the passes stay (lights without a map take the surface as a plane)
    // but there is no light-space map, so no entry target.
    let mut no_shadows = s;
    no_shadows.shadows.enabled = false;
    let p = common::plan(&layered, &no_shadows);
    assert!(passes(&p).iter().any(|n| n == "single scattering"));
    assert!(!images(&p).iter().any(|n| n.starts_with("light-space")));
    // --technique none (and every other technique but auto and layered) leave layered media out.
    for technique in common::techniques()
        .into_iter()
        .filter(|t| !t.keeps(&LAYERED_PART))
    {
        let mut t = s;
        t.technique = technique;
        let p = common::plan(&layered, &t);
        for name in LAYERED_PASSES {
            assert!(
                !passes(&p).contains(&name.to_string()),
                "{technique:?}: {name}"
            );
        }
        for name in LAYERED_IMAGES {
            assert!(
                !images(&p).contains(&name.to_string()),
                "{technique:?}: {name}"
            );
        }
    }
    // Scenes without layered materials: no pass, no image, and the maps have no entry target.
    for scene in ["smoke", "cubes", "skin", "teapot", "mixed"] {
        let scene = lucent::scene::load_scene(scene).unwrap();
        let p = common::plan(&scene, &s);
        for name in LAYERED_PASSES {
            assert!(
                !passes(&p).contains(&name.to_string()),
                "{}: {name}",
                scene.name
            );
        }
        for name in LAYERED_IMAGES {
            assert!(
                !images(&p).contains(&name.to_string()),
                "{}: {name}",
                scene.name
            );
        }
        let desc = FrameDesc::new(&scene, &s).unwrap();
        assert!(desc.layered().is_none());
        assert!(!desc
            .tables()
            .iter()
            .any(|t| t.region == &lucent::features::layered::TABLE_REGION));
    }
}

#[test]
fn the_layered_scene_differs_from_plain_lighting() {
    let test = TestGpu::new();
    let scene = builtin::builtin("layered").unwrap();
    let render = |technique| {
        let mut s = settings(160, 120);
        s.technique = technique;
        test.render(&scene, s).display
    };
    let (plain, layered) = (render(Technique::None), render(Technique::Auto));
    let changed = plain
        .chunks_exact(4)
        .zip(layered.chunks_exact(4))
        .filter(|(a, b)| {
            a.iter()
                .zip(b.iter())
                .take(3)
                .any(|(x, y)| x.abs_diff(*y) > 8)
        })
        .count();
    let share = changed as f64 / (160.0 * 120.0);
    println!(
        "layered vs none: {changed} pixels ({:.1}%) differ by more than 8/255",
        100.0 * share
    );
    assert!(share > 0.05, "{share}");
    test.finish();
}

/// A three-layer stack whose first two thicknesses come from a depth texture (`TexDep`:
/// layers 0 and 1 read channels r and g, times 1 mm per texel unit) over a clearer rest;
/// `constant` gives the same stack with the thicknesses `top` and `middle` as constants.
fn texdep_medium(path: Option<&std::path::Path>, top: f32, middle: f32) -> LayeredMedium {
    let mut m = two_layers();
    let rest = m.layers.pop().unwrap();
    let middle_layer = Layer {
        sigma_a: Vec3::new(0.05, 0.5, 1.0),
        sigma_s: Vec3::new(20.0, 15.0, 10.0),
        g: 0.3,
        thickness: Thickness::Mm(middle),
    };
    m.layers[0].thickness = Thickness::Mm(top);
    m.layers.push(middle_layer);
    m.layers.push(rest);
    if let Some(path) = path {
        m.name = "texdep".into();
        m.layers[0].thickness = Thickness::Texture { scale: 1.0 };
        m.layers[1].thickness = Thickness::Texture { scale: 1.0 };
        m.depth_textures = vec![lucent::scene::material::TextureSource::File(
            path.to_path_buf(),
        )];
    }
    m.validate().unwrap();
    m
}

/// Writes a 64 x 64 RGBA32F EXR whose texel at row `y` is `texel(y / 63)`.
fn depth_exr(name: &str, texel: impl Fn(f32) -> [f32; 4]) -> std::path::PathBuf {
    // One folder per file: the tests run in parallel and each removes its own.
    let dir = common::temp_dir(&format!("layered-texdep-{name}"));
    let path = dir.join(name);
    let image = image::Rgba32FImage::from_fn(64, 64, |_, y| image::Rgba(texel(y as f32 / 63.0)));
    image.save(&path).unwrap();
    path
}

#[test]
fn thickness_from_depth_textures_is_read_per_pixel_on_the_gpu() {
    let test = TestGpu::new();
    let error = |medium: LayeredMedium| {
        let scene = sphere_scene(medium, comparison_lights()).unwrap();
        let mut s = settings(96, 96);
        // A thin top over a denser layer needs more than the default 4 steps: 21% error at
        // K = 4, 5% at 16 (docs/layered.md); the plumbing is what this test is about.
        s.layered.steps = 16;
        term_error(
            &test.gpu,
            &test.shaders,
            &test.cache,
            &scene,
            &s,
            Term::Single,
            3,
        )
        .unwrap()
    };
    // The same stack from a constant texture and from constants: the GPU frames agree (fp16
    // texels: 3 digits) and both agree with the reference. The layers' thicknesses matter
    // and differ: a channel mix-up (layer 1 reading r, or the two swapped) moves the mean by
    // more than 10%, as does reading 0.
    let constant = error(texdep_medium(None, 0.1, 0.3));
    let swapped = error(texdep_medium(None, 0.3, 0.1));
    let zero = error(texdep_medium(None, 0.0, 0.0));
    let flat = depth_exr("flat.exr", |_| [0.1, 0.3, 0.9, 0.7]);
    let textured = error(texdep_medium(Some(&flat), 0.0, 0.0));
    println!(
        "TexDep constant texture: relative L1 {:.4} (constants {:.4}), GPU mean {:.5} against \
         {:.5} (swapped thicknesses {:.5}, zero {:.5})",
        textured.relative_l1,
        constant.relative_l1,
        textured.gpu_mean,
        constant.gpu_mean,
        swapped.gpu_mean,
        zero.gpu_mean
    );
    for other in [&swapped, &zero] {
        assert!(
            (other.gpu_mean - constant.gpu_mean).abs() > 0.1 * constant.gpu_mean,
            "the thicknesses must matter for this test to test anything"
        );
    }
    assert!(
        (textured.gpu_mean - constant.gpu_mean).abs() <= 0.005 * constant.gpu_mean,
        "{} vs {}",
        textured.gpu_mean,
        constant.gpu_mean
    );
    assert!(textured.relative_l1 <= 0.08, "{}", textured.relative_l1);

    // A texture that changes over the object: the top half (v < 0.5, +y) has the layers, the
    // bottom half none. The reference reads the texel at each shaded point; the GPU reads it
    // there (G-buffer) and where the light enters (light-space map).
    let halves = depth_exr("halves.exr", |v| {
        if v < 0.5 {
            [0.1, 0.3, 0.0, 0.0]
        } else {
            [0.0, 0.0, 0.0, 0.0]
        }
    });
    let varying = error(texdep_medium(Some(&halves), 0.0, 0.0));
    println!(
        "TexDep two halves: relative L1 {:.4}, GPU mean {:.5}, reference mean {:.5}",
        varying.relative_l1, varying.gpu_mean, varying.reference_mean
    );
    assert!(varying.relative_l1 <= 0.10, "{}", varying.relative_l1);
    for file in [&flat, &halves] {
        let _ = std::fs::remove_dir_all(file.parent().unwrap());
    }
    test.finish();
}

#[test]
fn a_scene_file_with_depth_textures_renders_and_others_have_no_depth_targets() {
    let exr = depth_exr("file.exr", |v| [0.2 + 0.3 * v, 0.1, 0.0, 0.0]);
    let dir = exr.parent().unwrap().to_path_buf();
    let scene_path = dir.join("texdep.toml");
    // The scene names its depth texture relative to itself: beside the EXR.
    std::fs::copy(common::data("texdep.toml"), &scene_path).unwrap();
    let scene =
        lucent::scene::load_scene(scene_path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let s = settings(64, 64);
    let p = common::plan(&scene, &s);
    for name in ["gbuffer.layer-depth", "light-space.layer-depth"] {
        assert!(
            images(&p).iter().any(|n| n == name),
            "{name}: {:?}",
            images(&p)
        );
    }
    let test = TestGpu::new();
    let frame = test.render(&scene, s);
    let lit = frame
        .display
        .chunks_exact(4)
        .filter(|p| p[..3].iter().any(|&c| c > 8))
        .count();
    assert!(lit > 200, "{lit} lit pixels");
    test.finish();
    // Layered media with constant thicknesses (the built-in scene) store no depth texels.
    let p = common::plan(&builtin::builtin("layered").unwrap(), &s);
    assert!(!images(&p).iter().any(|n| n.contains("layer-depth")));
    let _ = std::fs::remove_dir_all(dir);
}

/// Mean |L - median of its 5x5 neighbourhood| of the luminance of `hdr` over `mask`: the grain
/// a still shows.
fn grain(hdr: &[f32], mask: &[bool], w: usize) -> f64 {
    let lum = |i: usize| {
        0.2126 * f64::from(hdr[i * 4])
            + 0.7152 * f64::from(hdr[i * 4 + 1])
            + 0.0722 * f64::from(hdr[i * 4 + 2])
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for (i, _) in mask.iter().enumerate().filter(|(_, &m)| m) {
        let (x, y) = (i % w, i / w);
        let mut around: Vec<f64> = (0..25)
            .map(|k| lum((y + k / 5 - 2) * w + x + k % 5 - 2))
            .collect();
        around.sort_by(f64::total_cmp);
        sum += (lum(i) - around[12]).abs();
        n += 1;
    }
    assert!(n > 1000, "{n} pixels");
    sum / n as f64
}

/// Issue 25: Li et al.'s pixel-light gather leaves no grain a still can see. On
/// `showcase-layered` at 640x480, over the pixels the technique changes (4 px in from any
/// other), each gather with 12 pixel lights has at most 1.2x the grain of plain lighting on the
/// same pixels (the line): the default half gather (one gather per 2x2 block, nine
/// rotations per 3x3 block of texels, blurred over 3x3 texels where the medium diffuses far,
/// resolved over 4x4 texels; measured 1.08x) and the full gather (the same per pixel, resolved
/// over 3x3 pixels; 1.11x). And at most 1.2x the grain of the same frame with 64 pixel lights
/// gathered per pixel (1.00x and 1.03x), so what is left is not the 12 lights' sampling.
/// (Before the transmitted light's entry normals were filtered per texel, a diamond moire
/// across the back-lit candles' shadow band made even the 64-light frame 1.16x plain and the
/// default 1.18x; the term's blur took the default from 1.11x to 1.08x here and from 1.24x to
/// 1.17x at 1024x768; docs/layered.md, "Grain".)
#[test]
fn the_pixel_light_gather_leaves_no_grain_in_a_still() {
    let test = TestGpu::new();
    let scene = lucent::bake::scene::load_scene_baked("showcase-layered").unwrap();
    let (w, h) = (640usize, 480usize);
    let frame = |technique, pixel_lights: u32, half_gather: bool| {
        let mut s = FrameSettings {
            technique,
            export_hdr: true,
            ..FrameSettings::new(w as u32, h as u32)
        };
        s.layered.pixel_lights = pixel_lights;
        s.layered.half_gather = half_gather;
        test.render(&scene, s).hdr.unwrap()
    };
    let plain = frame(Technique::None, 12, true);
    let half = frame(Technique::Auto, 12, true);
    let full = frame(Technique::Auto, 12, false);
    let converged = frame(Technique::Auto, 64, false);
    // The technique's pixels: changed by more than 2% of the plain frame's luminance, with
    // every pixel 4 px around changed too (silhouettes are not grain).
    let changed: Vec<bool> = (0..w * h)
        .map(|i| {
            (0..3).any(|c| {
                let (a, b) = (plain[i * 4 + c], full[i * 4 + c]);
                (a - b).abs() > 0.02 * a.abs().max(0.05)
            })
        })
        .collect();
    let mask: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            (4..w - 4).contains(&x)
                && (4..h - 4).contains(&y)
                && (0..81).all(|k| changed[(y + k / 9 - 4) * w + x + k % 9 - 4])
        })
        .collect();
    let (g_plain, g_half, g_full, g_converged) = (
        grain(&plain, &mask, w),
        grain(&half, &mask, w),
        grain(&full, &mask, w),
        grain(&converged, &mask, w),
    );
    eprintln!(
        "showcase-layered grain over {} px: half gather {g_half:.4e} ({:.2}x plain, {:.2}x \
         64 lights), full gather {g_full:.4e} ({:.2}x, {:.2}x), 64 pixel lights per pixel \
         {g_converged:.4e} ({:.2}x plain), plain lighting {g_plain:.4e}",
        mask.iter().filter(|&&m| m).count(),
        g_half / g_plain,
        g_half / g_converged,
        g_full / g_plain,
        g_full / g_converged,
        g_converged / g_plain,
    );
    for (name, g) in [("half", g_half), ("full", g_full)] {
        assert!(
            g <= 1.2 * g_plain,
            "the {name} gather with 12 pixel lights {g:.4e} against plain lighting's \
             {g_plain:.4e}: visible grain"
        );
        assert!(
            g <= 1.2 * g_converged,
            "the {name} gather with 12 pixel lights {g:.4e} against 64 per pixel \
             {g_converged:.4e}: visible grain"
        );
    }
    test.finish();
}

/// An albedo texture on a layered material is a pigment film on the light leaving the surface
/// (`post`, as the screen-space blurs apply it): every layered term is multiplied by the
/// texel, which the G-buffer stores beside the material ID. It was parsed and never applied
/// (the textured truth came out 17-34% too bright under `auto`). On the truth set's
/// validation scene, skin1's sphere with a uniform grey texture (sRGB 137: A = 0.2502; the
/// compact G-buffer stores it in 8 bits, 64 / 255 = 0.2510), every pixel of the textured frame
/// is A times the untextured one's: with physical weights and no specular the frame is the
/// layered terms alone. The ID target is RGBA only in frames whose layered materials have a
/// texture; the untextured frame keeps its R8 target.
#[test]
fn an_albedo_texture_on_a_layered_material_filters_the_light_leaving_it() {
    let test = TestGpu::new();
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/truth/scenes");
    let load = |name: &str| {
        let path = scenes.join(name);
        lucent::scene::load_scene(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"))
    };
    let textured = load("validation/textured-grey.toml");
    let plain = load("skin1-medium-sidelit.toml");
    let (w, h) = (160usize, 120usize);
    let s = FrameSettings {
        export_hdr: true,
        ..settings(w as u32, h as u32)
    };
    let format = |scene: &lucent::scene::Scene| {
        let p = common::plan(scene, &s);
        let id = p.resource_by_name("gbuffer.layered").unwrap();
        p.resources[id].info.format
    };
    assert_eq!(format(&plain), ash::vk::Format::R8_UNORM);
    assert_eq!(format(&textured), ash::vk::Format::R8G8B8A8_UNORM);
    let t = test.render(&textured, s).hdr.unwrap();
    let u = test.render(&plain, s).hdr.unwrap();
    let mut sphere = 0;
    for i in 0..w * h {
        let lit = (0..3).all(|c| u[i * 4 + c] > 1e-4);
        // The background is the sky's constant colour in both.
        if !lit || (0..3).all(|c| t[i * 4 + c] == u[i * 4 + c]) {
            continue;
        }
        sphere += 1;
        for c in 0..3 {
            let ratio = f64::from(t[i * 4 + c]) / f64::from(u[i * 4 + c]);
            assert!(
                (ratio - 64.0 / 255.0).abs() < 0.003,
                "pixel {i} channel {c}: textured / untextured {ratio:.5}, not the film's 0.2510"
            );
        }
    }
    assert!(sphere > 2000, "{sphere} sphere pixels");
    test.finish();
}

/// Issue 26: a thin layered slab lit only from behind glows through. It rendered black: the
/// light's range (1000 units) put its shadow map's near plane 5 units out, past the slab, so
/// the map held no entry points for it (src/features/shadows.rs now ends a face's depth range
/// at the scene). `tests/data/backlit-slab.toml`: 40 x 40 x 4 mm of skin1 at eta 1, a point
/// light 20 mm behind it. Plain lighting leaves the front face black (no light reaches it); the layered
/// frame must show light through it, finite, reddest where skin1 absorbs least. The bar is a
/// floor, not the truth: the path-traced truth of the same slab (tools/truth, its light 2.5x
/// brighter) has a red radiance of 0.23 E / pi at the centre; the layered frame gives 0.19 E /
/// pi with the dipole's diffusion through the thickness (0.06 with unscattered light alone, 0
/// before the shadow map's depth range was fixed). At least 10% says "lit through" with a
/// margin; how close it comes to the truth is `tests/gpu/truth.rs`'s business.
#[test]
fn a_thin_slab_lit_from_behind_glows_through() {
    let test = TestGpu::new();
    let path = common::data("backlit-slab.toml");
    let scene = lucent::scene::load_scene(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{e}"));
    let (w, h) = (160usize, 120usize);
    let frame = |technique| {
        let s = FrameSettings {
            technique,
            export_hdr: true,
            ..settings(w as u32, h as u32)
        };
        test.render(&scene, s).hdr.unwrap()
    };
    // Mean RGB over the 20x20 pixels at the centre of the view (the slab covers about 80%).
    let centre = |hdr: &[f32]| {
        let mut sum = [0.0f64; 3];
        for y in h / 2 - 10..h / 2 + 10 {
            for x in w / 2 - 10..w / 2 + 10 {
                for c in 0..3 {
                    let v = hdr[(y * w + x) * 4 + c];
                    assert!(v.is_finite(), "pixel ({x}, {y}) channel {c}: {v}");
                    sum[c] += f64::from(v) / 400.0;
                }
            }
        }
        sum
    };
    let plain = centre(&frame(Technique::None));
    let layered = centre(&frame(Technique::Auto));
    test.finish();
    // The light's irradiance on the slab's back face, at its centre: 4 / 0.95^2 (intensity 4,
    // the face 0.95 units from the light; the range window is 1 there).
    let e = 4.0 / (0.95f64 * 0.95);
    println!(
        "back-lit slab: plain {plain:.4?}, layered {layered:.4?}, E / pi = {:.4}",
        e / std::f64::consts::PI
    );
    assert!(
        plain.iter().all(|&c| c < 1e-4),
        "plain lighting lit the front face: {plain:?}"
    );
    assert!(
        layered[0] >= 0.1 * e / std::f64::consts::PI,
        "the layered slab lets through {layered:?}: too little (at least 10% of E / pi in red)"
    );
    assert!(
        layered[0] > layered[1] && layered[1] > layered[2],
        "skin1 absorbs blue most and red least: {layered:?}"
    );
}
