//! GDC 2011 translucency on lavapipe (validation and synchronization validation on): the lit
//! image against the f64 reference evaluated from the read-back G-buffer, translucency lighting
//! only translucent pixels, leaving it out of scenes that do not use it, the stability sweep,
//! and the error-against-time report.

use lucent::features::gbuffer::GBufferPrecision;
use lucent::frame::{FrameDesc, FrameImages, FrameSettings, Technique};
use lucent::reference::translucency::{shade_gbuffer, LightingInputs};
use lucent::scene::Scene;

use crate::common;

use crate::common::TestGpu;

/// How many passes the plan of `scene` under `settings` keeps.
fn passes(scene: &Scene, settings: &FrameSettings) -> usize {
    common::plan(scene, settings).passes.len()
}

fn translucency_settings(w: u32, h: u32) -> FrameSettings {
    FrameSettings {
        technique: Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
        export_hdr: true,
        export_gbuffer: true,
        // The f64 reference shades without shadows (tests/gpu/shadows.rs checks those).
        shadows: lucent::features::shadows::ShadowSettings {
            enabled: false,
            ..Default::default()
        },
        ..FrameSettings::new(w, h)
    }
}

/// max |GPU - reference| over all pixels and channels, and the reference's peak.
fn compare_with_reference(
    scene: &Scene,
    settings: &FrameSettings,
    images: &FrameImages,
) -> (f64, f64) {
    let features = FrameDesc::new(scene, settings).unwrap();
    let t = features.translucency().expect("translucent scene");
    let gbuffer = images.gbuffer.as_ref().unwrap();
    let reference = shade_gbuffer(
        gbuffer,
        &LightingInputs {
            scene,
            translucency: Some((&t.table.rows, t.packing)),
        },
    );
    let hdr = images.hdr.as_ref().unwrap();
    let peak = reference
        .iter()
        .map(|c| c.max_element())
        .fold(0.0, f64::max);
    let mut max = 0.0f64;
    for (i, r) in reference.iter().enumerate() {
        for c in 0..3 {
            let gpu = f64::from(hdr[i * 4 + c]);
            assert!(gpu.is_finite(), "pixel {i} channel {c} is {gpu}");
            max = max.max((gpu - r[c]).abs());
        }
    }
    (max, peak)
}

#[test]
fn cubes_match_the_f64_reference_evaluated_from_the_gbuffer() {
    let gpu = TestGpu::new();
    let scene = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    for precision in [GBufferPrecision::Compact, GBufferPrecision::Full] {
        let settings = FrameSettings {
            gbuffer: precision,
            ..translucency_settings(320, 240)
        };
        let images = gpu.render(&scene, settings);
        let (max, peak) = compare_with_reference(&scene, &settings, &images);
        eprintln!(
            "cubes ({}): max |GPU - f64 reference| = {max:.3e} = {:.3e} of peak {peak:.3}",
            precision.name(),
            max / peak
        );
        assert!(peak > 0.1, "the image is lit");
        assert!(
            max <= 2e-3 * peak,
            "{}: max error {max:.3e} exceeds 2e-3 of peak {peak:.3}",
            precision.name()
        );
    }
    gpu.finish();
}

#[test]
fn translucency_lights_only_translucent_pixels_and_costs_nothing_where_unused() {
    let gpu = TestGpu::new();
    let size = (160, 120);
    // Half the grid translucent: translucent pixels brighten, opaque ones are untouched.
    let half = lucent::bake::scene::load_scene_baked("grid125:50").unwrap();
    let plain = FrameSettings {
        technique: Technique::None,
        ..translucency_settings(size.0, size.1)
    };
    let off = gpu.render(&half, plain);
    let on = gpu.render(&half, translucency_settings(size.0, size.1));
    let gb2 = on.gbuffer.as_ref().unwrap().gb2.as_ref().unwrap();
    let (hdr_off, hdr_on) = (off.hdr.unwrap(), on.hdr.unwrap());
    let (mut translucent, mut changed_opaque, mut brighter) = (0, 0, 0);
    for (i, t) in gb2.iter().enumerate() {
        let id = (t[1] * 255.0).round() as u32;
        let delta: f32 = (0..3).map(|c| hdr_on[i * 4 + c] - hdr_off[i * 4 + c]).sum();
        if id == 0 {
            // Opaque pixels on translucent tiles are shaded by the translucency variant, whose
            // sums are ordered differently: allow fp16 rounding (2^-11 relative), no more.
            let value: f32 = (0..3).map(|c| hdr_off[i * 4 + c].abs()).sum();
            changed_opaque += usize::from(delta.abs() > 2e-3 * value + 1e-6);
        } else {
            translucent += 1;
            brighter += usize::from(delta > 0.0);
        }
    }
    let share = translucent as f64 / gb2.len() as f64;
    assert!((0.25..0.75).contains(&share), "translucent share {share}");
    assert_eq!(changed_opaque, 0, "opaque pixels changed");
    assert!(
        brighter * 2 > translucent,
        "{brighter} of {translucent} brightened"
    );

    // A scene with nothing translucent gets no GB2 and the same frame as technique `none`.
    let smoke = lucent::bake::scene::load_scene_baked("smoke").unwrap();
    let settings = translucency_settings(size.0, size.1);
    assert!(FrameDesc::new(&smoke, &settings)
        .unwrap()
        .translucency()
        .is_none());
    let plain = FrameSettings {
        technique: Technique::None,
        ..settings
    };
    let with = gpu.render(&smoke, settings);
    let without = gpu.render(&smoke, plain);
    assert!(with.gbuffer.unwrap().gb2.is_none());
    assert_eq!(passes(&smoke, &settings), passes(&smoke, &plain));
    assert_eq!(with.display, without.display);
    gpu.finish();
}

#[test]
fn stability_sweep_has_no_nan_or_inf_in_any_case() {
    use lucent::measure::sweep::{run_translucency, translucency_cases};
    let test = TestGpu::new();
    let cases = translucency_cases();
    let rows = run_translucency(&test.gpu, &test.shaders, &test.cache, 32, 24, &cases).unwrap();
    assert_eq!(rows.len(), cases.len());
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| r.nan + r.inf > 0)
        .map(|r| format!("{:?}: {} NaN, {} Inf", r.case, r.nan, r.inf))
        .collect();
    assert!(bad.is_empty(), "unstable cases:\n{}", bad.join("\n"));
    // The cases light something: a sweep of black frames would prove nothing.
    assert!(rows.iter().any(|r| r.max > 1.0));
    // The extreme corner saturates fp16 somewhere, and the clamp holds it finite there.
    assert!(rows.iter().any(|r| r.fp16_overflow > 0));
    test.finish();
}

#[test]
fn report_measures_every_knob_and_writes_table_and_plot() {
    let gpu = TestGpu::new();
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-translucency");
    let _ = std::fs::remove_dir_all(&dir);
    let options = lucent::report::section::ReportOptions {
        width: 96,
        height: 72,
        rounds: 2,
        warmup: 1,
    };
    let (text, files) = lucent::report::translucency::write_translucency_report(
        &gpu.gpu,
        &gpu.shaders,
        &gpu.cache,
        &dir,
        &options,
    )
    .unwrap();
    for knob in [
        "exact pow",
        "exp2 (spherical Gaussian)",
        "grayscale",
        "RGBA16F",
        "32 lights",
    ] {
        assert!(text.contains(knob), "report lacks '{knob}':\n{text}");
    }
    assert!(text.contains("100% translucent"));
    for f in &files {
        assert!(
            std::fs::metadata(f).unwrap().len() > 0,
            "{} is empty",
            f.display()
        );
    }
    // The exact variant is the reference's own configuration at 8 bits: its error is the
    // G-buffer's quantisation, far below the exp2 approximation's.
    let row = |name: &str| {
        text.lines()
            .find(|l| l.contains(&format!("| {name} |")))
            .unwrap_or_else(|| panic!("no row {name}"))
            .split('|')
            .map(str::trim)
            .collect::<Vec<_>>()
    };
    let max_abs = |name: &str| row(name)[7].parse::<f64>().unwrap();
    assert!(max_abs("exact pow") < max_abs("exp2 (spherical Gaussian)"));
    assert!(max_abs("RGBA16F") <= max_abs("RGBA8"));
    gpu.finish();
}
