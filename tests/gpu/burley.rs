//! 2-D Burley SSS against its f64 brute-force reference (Burley's profile convolved over the
//! read-back G-buffer's visible surface, `lucent::reference::sss::burley_reference_image`), and
//! the separable blur against its own, on the same scenes: Burley must be as close to its
//! reference as the separable blur is to its own, its error must fall as the sample budget
//! grows, and it must stay finite at extreme distances.

use crate::common;
use crate::common::TestGpu;
use glam::DVec3;
use lucent::features::sss::burley::BURLEY;
use lucent::features::sss::separable::SEPARABLE;
use lucent::features::technique::TechniqueModule;
use lucent::frame::{FrameDesc, FrameSettings, Technique};
use lucent::reference::sss::ReferenceSpecular;
use lucent::scene::material::BurleyDistance;
use lucent::scene::Scene;

const SIZE: (u32, u32) = (128, 96);

fn settings(technique: Technique) -> FrameSettings {
    common::sss_frame(technique, SIZE.0, SIZE.1)
}

/// `name` with its profiles widened `factor` times (so the blurs span many pixels at this
/// size) and no specular on scattering materials (the test judges the diffusion).
fn scene(name: &str, factor: f32) -> Scene {
    let mut scene = lucent::bake::scene::load_scene_baked(name).unwrap();
    for o in &mut scene.objects {
        if let Some(p) = &mut o.material.sss {
            p.units_per_mm *= factor;
            o.material.specular = 0.0;
        }
    }
    scene
}

/// Mean |GPU - reference| per channel over scattering pixels whose 9x9 neighbourhood all
/// scatters (the edges are the edge test's), relative to the reference's mean there.
fn interior_error(hdr: &[f32], reference: &[DVec3], strength: &[f32]) -> f64 {
    let (mut error, mut level, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, r) in reference.iter().enumerate() {
        if common::interior_scattering(strength, SIZE.0 as usize, i) {
            for c in 0..3 {
                error += (f64::from(hdr[i * 4 + c]) - r[c]).abs();
                level += r[c].abs();
            }
            n += 3;
        }
    }
    assert!(n > 300, "{n} interior channels");
    error / level.max(1e-12)
}

/// Burley's (at `budget`, at half resolution when `half_res`) and the separable blur's
/// relative errors against their own references on `name`.
fn errors(test: &TestGpu, name: &str, budget: Option<u32>, half_res: bool) -> (f64, f64) {
    let scene = scene(name, 20.0);
    let mut burley = settings(Technique::Only(&BURLEY));
    if let Some(b) = budget {
        burley.sss.burley_budget = b;
    }
    burley.sss.burley_half_res = half_res;
    let frame = test.render(&scene, burley);
    let gbuffer = frame.gbuffer.as_ref().unwrap();
    let (profile, _) = FrameDesc::new(&scene, &burley)
        .unwrap()
        .sss()
        .unwrap()
        .profiles[0]
        .clone();
    let d = profile.burley_d(burley.sss.burley_fit);
    let reference = lucent::reference::sss::burley_reference_image(
        &scene,
        gbuffer,
        d,
        f64::from(profile.units_per_mm),
        ReferenceSpecular::BlinnPhong,
        profile.texturing,
    );
    let strength = gbuffer.sss.as_ref().unwrap();
    let e_burley = interior_error(frame.hdr.as_ref().unwrap(), &reference, strength);

    let separable = settings(Technique::Only(&SEPARABLE));
    let frame = test.render(&scene, separable);
    let gbuffer = frame.gbuffer.as_ref().unwrap();
    let reference = lucent::reference::sss::reference_image(
        &scene,
        gbuffer,
        &profile,
        ReferenceSpecular::BlinnPhong,
    );
    let e_separable = interior_error(
        frame.hdr.as_ref().unwrap(),
        &reference,
        gbuffer.sss.as_ref().unwrap(),
    );
    (e_burley, e_separable)
}

#[test]
fn burley_matches_its_f64_reference_as_closely_as_the_separable_blur_matches_its_own() {
    let test = TestGpu::new();
    for name in ["skin", "teapot"] {
        let (burley, separable) = errors(&test, name, None, false);
        eprintln!(
            "{name}: mean relative |GPU - own f64 reference| on interior scattering pixels: \
             burley {burley:.4e}, separable {separable:.4e}"
        );
        assert!(
            burley < 0.06,
            "{name}: burley {burley:.4e} from its reference"
        );
        assert!(
            burley <= separable,
            "{name}: burley {burley:.4e} against the separable's {separable:.4e}"
        );
    }
    // More samples, less error: the budget is the knob that trades one for the other.
    let curve: Vec<(u32, f64)> = [4, 8, 12, 20, 32, 64]
        .into_iter()
        .map(|b| (b, errors(&test, "teapot", Some(b), false).0))
        .collect();
    eprintln!("teapot: burley's error by budget {curve:?}");
    let (low, high) = (curve[0].1, curve[curve.len() - 1].1);
    assert!(
        high < low,
        "budget 64 ({high:.4e}) not closer than 4 ({low:.4e})"
    );
    test.finish();
}

#[test]
fn half_resolution_burley_stays_near_its_reference() {
    // `--burley-half-res`: a quarter of the gathers, resolved at full resolution; its error
    // against the full-resolution reference stays within 1.5x the full-resolution gather's.
    let test = TestGpu::new();
    for name in ["skin", "teapot"] {
        let full = errors(&test, name, None, false).0;
        let half = errors(&test, name, None, true).0;
        eprintln!("{name}: burley {full:.4e} at full resolution, {half:.4e} at half");
        assert!(
            half <= 1.5 * full,
            "{name}: half resolution {half:.4e} against full {full:.4e}"
        );
    }
    test.finish();
}

#[test]
fn extreme_burley_distances_stay_finite() {
    let test = TestGpu::new();
    for d in [1e-4f32, 1e-2, 1.0, 1e2, 1e3] {
        let mut scene = scene("skin", 1.0);
        for o in &mut scene.objects {
            if let Some(p) = &mut o.material.sss {
                p.burley = Some(BurleyDistance::Scattering(glam::Vec3::new(
                    d,
                    d * 0.5,
                    d * 0.25,
                )));
            }
        }
        let frame = test.render(&scene, settings(Technique::Only(&BURLEY)));
        let hdr = frame.hdr.unwrap();
        assert!(
            hdr.iter().all(|v| v.is_finite()),
            "d {d}: non-finite output"
        );
        assert!(hdr.iter().all(|v| *v <= 65504.0), "d {d}: beyond fp16");
    }
    // A mean free path at albedo 0 and 1, under every fit.
    for albedo in [0.0f32, 1.0] {
        for (fit_name, fit) in lucent::scene::profile::BurleyFit::ALL {
            let mut scene = scene("skin", 1.0);
            for o in &mut scene.objects {
                if let Some(p) = &mut o.material.sss {
                    p.burley = Some(BurleyDistance::MeanFreePath {
                        mfp: glam::Vec3::splat(2.0),
                        albedo: glam::Vec3::splat(albedo),
                    });
                }
            }
            let mut s = settings(Technique::Only(&BURLEY));
            s.sss.burley_fit = *fit;
            let hdr = test.render(&scene, s).hdr.unwrap();
            assert!(
                hdr.iter().all(|v| v.is_finite()),
                "A {albedo} {fit_name}: non-finite"
            );
        }
    }
    test.finish();
}

#[test]
fn burley_is_a_gather_and_a_resolve_with_its_table_only_when_used() {
    let skin = lucent::bake::scene::load_scene_baked("skin").unwrap();
    let plan = common::plan(&skin, &settings(Technique::Only(&BURLEY)));
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(
        names,
        ["gbuffer + lighting", "burley", "burley resolve", "tonemap"]
    );
    let desc = |t| FrameDesc::new(&skin, &settings(t)).unwrap();
    let has_table = |d: &FrameDesc| {
        d.tables()
            .iter()
            .any(|t| t.region == &lucent::features::sss::burley::TABLE_REGION)
    };
    assert!(has_table(&desc(Technique::Only(&BURLEY))));
    assert!(!has_table(&desc(Technique::Only(&SEPARABLE))));
    // `--burley-half-res`: the same passes, the gathered image a quarter the size.
    let full = settings(Technique::Only(&BURLEY));
    let mut half = full;
    half.sss.burley_half_res = true;
    let (w, h) = common::image_size(&common::plan(&skin, &full), "sss.gathered");
    assert_eq!((w, h), (SIZE.0, SIZE.1));
    let (w, h) = common::image_size(&common::plan(&skin, &half), "sss.gathered");
    assert_eq!((w, h), (SIZE.0.div_ceil(2), SIZE.1.div_ceil(2)));
}

#[test]
fn burley_composes_with_the_other_techniques_in_mixed() {
    // `mixed` with its first SSS material blurred by Burley, the rest as the scene says: every
    // chain of the frame runs, Burley's among them, under validation.
    let mut scene = lucent::bake::scene::load_scene_baked("mixed").unwrap();
    let object = scene
        .objects
        .iter_mut()
        .find(|o| o.material.sss.is_some())
        .expect("mixed has an SSS material");
    if let Some(profile) = &mut object.material.sss {
        profile.blur = Some(BURLEY.name().into());
    }
    let s = settings(Technique::Auto);
    let plan = common::plan(&scene, &s);
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert!(names.iter().any(|n| n.contains("burley")), "{names:?}");
    assert!(names.len() > 4, "{names:?}");
    let test = TestGpu::new();
    let hdr = test.render(&scene, s).hdr.unwrap();
    assert!(hdr.iter().all(|v| v.is_finite()));
    test.finish();
}

/// Mean |L - median of its 5x5 neighbourhood| of the luminance of `hdr` over the pixels whose
/// 9x9 neighbourhood all scatters (`strength`): the grain a still shows.
fn grain(hdr: &[f32], strength: &[f32], w: usize, h: usize) -> f64 {
    let lum = |i: usize| {
        0.2126 * f64::from(hdr[i * 4])
            + 0.7152 * f64::from(hdr[i * 4 + 1])
            + 0.0722 * f64::from(hdr[i * 4 + 2])
    };
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 4..h - 4 {
        for x in 4..w - 4 {
            if !common::interior_scattering(strength, w, y * w + x) {
                continue;
            }
            let mut around: Vec<f64> = (0..25)
                .map(|k| lum((y + k / 5 - 2) * w + x + k % 5 - 2))
                .collect();
            around.sort_by(f64::total_cmp);
            sum += (lum(y * w + x) - around[12]).abs();
            n += 1;
        }
    }
    assert!(n > 1000, "{n} interior pixels");
    sum / n as f64
}

#[test]
fn burley_leaves_no_grain_in_a_still() {
    // showcase-skin at 640x480, the measurement: Burley's grain at most 1.2x plain
    // lighting's on the same pixels (a per-pixel random rotation measured 4.7x).
    let test = TestGpu::new();
    let scene = lucent::bake::scene::load_scene_baked("showcase-skin").unwrap();
    let (w, h) = (640usize, 480usize);
    let s = |technique| FrameSettings {
        technique,
        export_hdr: true,
        export_gbuffer: true,
        ..FrameSettings::new(w as u32, h as u32)
    };
    let burley = test.render(&scene, s(Technique::Only(&BURLEY)));
    let strength = burley.gbuffer.as_ref().unwrap().sss.clone().unwrap();
    let plain = test.render(&scene, s(Technique::None));
    let g_burley = grain(burley.hdr.as_ref().unwrap(), &strength, w, h);
    let g_plain = grain(plain.hdr.as_ref().unwrap(), &strength, w, h);
    eprintln!(
        "showcase-skin grain: burley {g_burley:.4e}, plain {g_plain:.4e} ({:.2}x)",
        g_burley / g_plain
    );
    assert!(
        g_burley <= 1.2 * g_plain,
        "burley {g_burley:.4e}, plain {g_plain:.4e}"
    );
    test.finish();
}

#[test]
fn sweep_burley_finds_no_nan_or_inf() {
    // Every distance from 1e-4 to 1e3 mm, albedo 0 to 1 under each fit, front, grazing and
    // close views (src/measure/sweep_burley.rs), under validation.
    let out = common::succeeded(common::lucent_command().args(["sweep", "burley", "--validation"]));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("0 NaN/Inf values: stable"), "{text}");
    assert!(text.contains("| grazing | d = 1e3 mm |"), "{text}");
}
