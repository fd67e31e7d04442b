//! The debug views (`FrameSettings::debug_view`, the demo's V key) against the G-buffer read
//! back from the same frame, validation on.

use crate::common::TestGpu;
use lucent::features::debug_view::DebugView;
use lucent::features::translucency::ThicknessPacking;
use lucent::frame::{FrameSettings, GBufferReadback, Technique};
use lucent::scene;

/// The display image of one frame, and its G-buffer.
fn frame(
    test: &TestGpu,
    scene: &scene::Scene,
    settings: FrameSettings,
) -> (Vec<u8>, GBufferReadback) {
    let frame = test.render_repeated(
        scene,
        FrameSettings {
            export_gbuffer: true,
            ..settings
        },
    );
    (frame.display, frame.gbuffer.unwrap())
}

fn srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Largest per-channel difference (RGB) between the display and `expected` (0..1 values).
fn worst(display: &[u8], expected: impl Iterator<Item = [f32; 3]>) -> u8 {
    display
        .chunks_exact(4)
        .zip(expected)
        .flat_map(|(px, e)| (0..3).map(move |c| px[c].abs_diff((e[c] * 255.0).round() as u8)))
        .max()
        .unwrap()
}

#[test]
fn gbuffer_views_show_what_the_gbuffer_holds() {
    let test = TestGpu::new();
    let cubes = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    let base = FrameSettings {
        technique: Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
        ..FrameSettings::new(160, 120)
    };
    let view = |v| FrameSettings {
        debug_view: Some(v),
        ..base
    };
    let (final_frame, _) = frame(&test, &cubes, base);

    let (albedo, gb) = frame(&test, &cubes, view(DebugView::Albedo));
    let w = worst(
        &albedo,
        gb.gb0.iter().map(|t| [srgb(t[0]), srgb(t[1]), srgb(t[2])]),
    );
    assert!(w <= 1, "albedo view off by {w}/255");

    let (normal, gb) = frame(&test, &cubes, view(DebugView::Normal));
    let expected = gb.gb1.iter().map(|t| {
        let n = glam::Vec3::new(t[0], t[1], t[2]);
        if n.length_squared() < 1e-6 {
            [0.0; 3]
        } else {
            (n.normalize() * 0.5 + 0.5).to_array()
        }
    });
    let w = worst(&normal, expected);
    assert!(w <= 1, "normal view off by {w}/255");

    let (depth, gb) = frame(&test, &cubes, view(DebugView::Depth));
    let (n, f) = (cubes.camera.near, cubes.camera.far);
    let expected = gb.depth.iter().map(|&d| {
        if d >= 1.0 {
            return [0.0; 3];
        }
        let linear = n * f / (f - d * (f - n)).max(1e-6);
        [(1.0 - (linear.max(n) / n).ln() / (f / n).ln()).clamp(0.0, 1.0); 3]
    });
    let w = worst(&depth, expected);
    assert!(w <= 2, "depth view off by {w}/255");

    let (thickness, gb) = frame(&test, &cubes, view(DebugView::Thickness));
    let gb2 = gb.gb2.expect("translucency frames have GB2");
    // GB2: (thickness rgb, material ID / 255) coloured, (thickness, material ID / 255) gray.
    let packing = gb.layout.translucency.unwrap().packing;
    let colored = packing == ThicknessPacking::Colored;
    assert!(
        colored,
        "cubes has a coloured thickness (its red-veined cube)"
    );
    let w = worst(
        &thickness,
        gb2.iter().map(|t| [srgb(t[0]), srgb(t[1]), srgb(t[2])]),
    );
    assert!(w <= 1, "thickness view off by {w}/255");

    let (material, gb) = frame(&test, &cubes, view(DebugView::MaterialId));
    let gb2 = gb.gb2.unwrap();
    for (px, t) in material.chunks_exact(4).zip(&gb2) {
        let id = (t[3] * 255.0).round() as u32;
        let black = px[..3] == [0, 0, 0];
        assert_eq!(black, id == 0, "material {id} shown as {px:?}");
    }
    assert!(material.chunks_exact(4).any(|p| p[..3] != [0, 0, 0]));

    // A view the frame cannot show (no SSS here) is the ordinary frame, exactly.
    let (fallback, _) = frame(&test, &cubes, view(DebugView::LitBeforeSss));
    assert_eq!(fallback, final_frame);
    test.finish();
}

#[test]
fn pre_blur_view_is_the_unblurred_lighting_and_the_blur_changes_it() {
    let test = TestGpu::new();
    // `edges`: a skin profile four times as wide, so the blur reaches over several pixels.
    let edges = lucent::bake::scene::load_scene_baked("edges").unwrap();
    let mut base = FrameSettings {
        technique: Technique::Only(&lucent::features::sss::control::CONTROL),
        ..FrameSettings::new(320, 240)
    };
    // The view shows the light the blur reads: with the albedo in it, that is the plain frame.
    base.sss.texturing = Some(lucent::scene::material::Texturing::Pre);
    let (after, gb) = frame(&test, &edges, base);
    let (before, _) = frame(
        &test,
        &edges,
        FrameSettings {
            debug_view: Some(DebugView::LitBeforeSss),
            ..base
        },
    );
    // Diffuse + specular lit apart and summed is the plain deferred frame (technique none).
    let (plain, _) = frame(
        &test,
        &edges,
        FrameSettings {
            technique: Technique::None,
            ..base
        },
    );
    let to_unit = |p: &[u8]| [p[0], p[1], p[2]].map(|v| f32::from(v) / 255.0);
    let w = worst(&before, plain.chunks_exact(4).map(to_unit));
    assert!(
        w <= 2,
        "pre-blur view differs from the unblurred frame by {w}/255"
    );
    // The blur moves light only at scattering pixels.
    let strength = gb.sss.expect("SSS frames export the SSS strength");
    let (mut changed, mut changed_elsewhere) = (0, 0);
    for ((a, b), s) in after
        .chunks_exact(4)
        .zip(before.chunks_exact(4))
        .zip(&strength)
    {
        let d = (0..3).map(|c| a[c].abs_diff(b[c])).max().unwrap();
        if d > 2 {
            if *s > 0.0 {
                changed += 1;
            } else {
                changed_elsewhere += 1;
            }
        }
    }
    eprintln!("blur changed {changed} scattering pixels by > 2/255, {changed_elsewhere} others");
    assert!(changed > 50, "the blur changed only {changed} pixels");
    assert_eq!(changed_elsewhere, 0);
    test.finish();
}

#[test]
fn translucency_term_view_is_the_difference_translucency_makes() {
    // The lighting pass adds the talk's term to diffuse + specular: the term view must be the
    // translucency frame's HDR minus the plain frame's, tonemapped alike.
    let test = TestGpu::new();
    let cubes = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    let hdr = |technique| {
        let settings = FrameSettings {
            technique,
            export_hdr: true,
            ..FrameSettings::new(160, 120)
        };
        test.render(&cubes, settings).hdr.unwrap()
    };
    let (with, without) = (
        hdr(Technique::Only(
            &lucent::features::translucency::TRANSLUCENCY,
        )),
        hdr(Technique::None),
    );
    let (term, gb) = frame(
        &test,
        &cubes,
        FrameSettings {
            technique: Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
            debug_view: Some(DebugView::TranslucencyTerm),
            ..FrameSettings::new(160, 120)
        },
    );
    let exposure = f64::from(cubes.exposure);
    let mut worst_diff = 0u8;
    for (i, px) in term.chunks_exact(4).enumerate() {
        let d = glam::DVec3::from_array(std::array::from_fn(|c| {
            f64::from(with[i * 4 + c] - without[i * 4 + c]).max(0.0)
        }));
        let expected = lucent::reference::tonemap::display_rgba8(d, exposure);
        for c in 0..3 {
            worst_diff = worst_diff.max(px[c].abs_diff(expected[c]));
        }
    }
    // fp16 rounding of the two lit frames (the difference of two rounded values).
    assert!(worst_diff <= 3, "term view off by {worst_diff}/255");
    let gb2 = gb.gb2.unwrap();
    let lit = term
        .chunks_exact(4)
        .zip(&gb2)
        .filter(|(px, t)| px[..3] != [0, 0, 0] && (t[3] * 255.0).round() as u32 != 0)
        .count();
    assert!(lit > 500, "only {lit} pixels show a translucency term");
    test.finish();
}

/// The demo's comparison shader (a compute pipeline, made outside the render graph, compiled
/// at run time as the demo compiles its shaders) binds its three storage images by the names
/// the shader gives them, and makes its pipeline without a validation error. The scripted demo
/// turns the comparison views on too, but the demo shows a failed comparison in its panel
/// instead of failing, so this is where a wrong name fails.
#[cfg(all(feature = "window", feature = "runtime-shaders"))]
#[test]
fn the_demos_comparison_pipeline_binds_its_images_by_name() {
    let test = TestGpu::new();
    let root = lucent::backend::shader::ShaderCompiler::default_glsl_root();
    let shaders = lucent::backend::shader::ShaderCompiler::new(root, None).unwrap();
    let comparer = lucent::demo::compare::Comparer::new(&test.gpu, &shaders, &test.cache)
        .expect("the comparison pipeline");
    comparer.destroy(&test.gpu);
    test.finish();
}
