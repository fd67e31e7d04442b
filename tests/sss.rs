//! Screen-space SSS, the control technique (Jimenez's separable sum-of-Gaussians blur), on
//! lavapipe with validation and synchronization validation on: the passes it declares (and
//! leaves out), non-scattering pixels untouched, scattering pixels blurred with their energy
//! kept, and every output finite.

mod common;

use common::TestGpu;
use lucent::reference::sss::ReferenceSpecular;
use lucent::renderer::{plan_frame, FrameFeatures, FrameSettings, Renderer, Technique};
use lucent::scene::{self, Scene};

fn settings(technique: Technique) -> FrameSettings {
    FrameSettings {
        technique,
        export_hdr: true,
        export_gbuffer: true,
        ..FrameSettings::new(160, 120)
    }
}

fn render(test: &TestGpu, scene: &Scene, settings: FrameSettings) -> lucent::renderer::FrameImages {
    let gpu = &test.gpu;
    let renderer = Renderer::new(gpu, &test.shaders, &test.cache, scene, settings).unwrap();
    let images = renderer.render_once(gpu).unwrap();
    gpu.wait_idle().unwrap();
    renderer.destroy(gpu);
    images
}

#[test]
fn control_declares_one_blur_pair_per_gaussian_and_nothing_without_sss() {
    let skin = scene::load_scene("skin").unwrap();
    let s = settings(Technique::Control);
    let plan = plan_frame(&s, &FrameFeatures::new(&skin, &s).unwrap()).unwrap();
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    let mut expected = vec!["gbuffer + lighting".to_string()];
    for i in 1..=6 {
        expected.push(format!("horizontal blur #{i}"));
        expected.push(format!("vertical blur #{i}"));
    }
    expected.extend(["combine".to_string(), "tonemap".to_string()]);
    assert_eq!(names, expected);
    // No SSS material: no blur passes, no SSS targets.
    let smoke = scene::load_scene("smoke").unwrap();
    let plan = plan_frame(&s, &FrameFeatures::new(&smoke, &s).unwrap()).unwrap();
    let names: Vec<&str> = plan.physical.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["gbuffer + lighting", "tonemap"]);
    assert!(plan.resources.iter().all(|r| !r.name.starts_with("sss.")));
}

#[test]
fn control_blurs_only_scattering_pixels_keeps_their_energy_and_stays_finite() {
    let test = TestGpu::new();
    for name in ["skin", "teapot"] {
        let scene = scene::load_scene(name).unwrap();
        let plain = render(&test, &scene, settings(Technique::None));
        let blurred = render(&test, &scene, settings(Technique::Control));
        let (a, b) = (plain.hdr.unwrap(), blurred.hdr.unwrap());
        assert!(b.iter().all(|v| v.is_finite()), "{name}: non-finite output");
        // Which pixels scatter: the G-buffer's SSS strength says.
        let gb = blurred.gbuffer.unwrap();
        let strength = gb.sss.as_ref().expect("SSS frames store the strength");
        let (mut changed_far, mut sum_a, mut sum_b, mut scattering) = (0usize, 0.0, 0.0, 0usize);
        for (i, s) in strength.iter().enumerate() {
            let pa = &a[i * 4..i * 4 + 3];
            let pb = &b[i * 4..i * 4 + 3];
            let diff: f32 = pa.iter().zip(pb).map(|(x, y)| (x - y).abs()).sum();
            let peak = pa.iter().fold(1e-3f32, |m, v| m.max(v.abs()));
            // Sky and the floor (no profile) must come out as without SSS, up to fp16
            // rounding of diffuse and specular stored apart.
            if *s == 0.0 {
                if diff > 4e-3 * peak.max(1.0) {
                    changed_far += 1;
                }
            } else {
                scattering += 1;
                sum_a += pa.iter().sum::<f32>() as f64;
                sum_b += pb.iter().sum::<f32>() as f64;
            }
        }
        assert!(scattering > 500, "{name}: {scattering} scattering pixels");
        assert!(
            changed_far * 100 < gb.depth.len(),
            "{name}: {changed_far} non-scattering pixels changed"
        );
        let ratio = sum_b / sum_a;
        assert!(
            (0.9..1.1).contains(&ratio),
            "{name}: scattering pixels' energy ratio {ratio:.3}"
        );
        assert_ne!(
            plain.display, blurred.display,
            "{name}: the blur changed nothing"
        );
    }
    test.finish();
}

#[test]
fn extreme_profiles_stay_finite_and_bounded() {
    let test = TestGpu::new();
    let base = scene::load_scene("skin").unwrap();
    let plain = render(&test, &base, settings(Technique::None)).hdr.unwrap();
    let peak = plain.iter().fold(0.0f32, |m, v| m.max(*v));
    for (what, units_per_mm, variance) in [
        ("huge strength (1e6 units per mm)", 1e6f32, None),
        ("zero-width kernel (variances 1e-30)", 0.01, Some(1e-30f32)),
        ("one huge Gaussian", 0.01, Some(1e6)),
    ] {
        let mut scene = base.clone();
        for o in &mut scene.objects {
            if let Some(p) = &mut o.material.sss {
                p.units_per_mm = units_per_mm;
                if let Some(v) = variance {
                    p.gaussians.iter_mut().for_each(|g| g.variance = v);
                }
            }
        }
        let hdr = render(&test, &scene, settings(Technique::Control))
            .hdr
            .unwrap();
        let bad = hdr.iter().filter(|v| !v.is_finite()).count();
        assert_eq!(bad, 0, "{what}: {bad} non-finite values");
        // A blur only averages: nothing brighter than the brightest unblurred pixel.
        let max = hdr.iter().fold(0.0f32, |m, v| m.max(*v));
        assert!(
            max <= peak * 1.01 + 1e-3,
            "{what}: max {max} above the unblurred peak {peak}"
        );
    }
    test.finish();
}

#[test]
fn bench_prints_the_control_beside_the_thesis_table_2() {
    let stdout = common::run_bench(&[
        "bench",
        "--scene",
        "teapot",
        "--technique",
        "control",
        "--size",
        "96x72",
        "--frames",
        "2",
        "--warmup",
        "1",
        "--compare-thesis",
    ]);
    assert!(
        stdout.contains("Beside LEAN-mapping SSS thesis"),
        "{stdout}"
    );
    for row in [
        "| Lighting calculations | 0.052 |",
        "| Vertical Blur #4 | 0.210 |",
    ] {
        assert!(stdout.contains(row), "missing {row}:\n{stdout}");
    }
    assert!(stdout.contains("| horizontal blur #1 |"));
    assert!(stdout.contains("Thesis LBB / control: 3.38x"));
}

#[test]
fn blurring_only_the_profiles_rectangles_gives_the_whole_screen_result() {
    let test = TestGpu::new();
    for name in ["skin", "teapot"] {
        let scene = scene::load_scene(name).unwrap();
        let tiled = render(&test, &scene, settings(Technique::Control));
        let whole = render(
            &test,
            &scene,
            FrameSettings {
                sss_tiles: false,
                ..settings(Technique::Control)
            },
        );
        assert_eq!(
            tiled.hdr, whole.hdr,
            "{name}: tiled blurs differ from whole-screen ones"
        );
    }
    test.finish();
}

#[test]
fn control_is_closer_to_the_brute_force_reference_than_no_blur() {
    let test = TestGpu::new();
    for name in ["skin", "teapot"] {
        let mut scene = scene::load_scene(name).unwrap();
        // At 128x96 the presets' scattering is under a pixel wide, and a blur that narrow only
        // adds its bilinear taps' filtering (measured: at 1x and 5x the control is further
        // from the reference than no blur at all). Widened twentyfold it spans many pixels,
        // where the blur must win.
        for o in &mut scene.objects {
            if let Some(p) = &mut o.material.sss {
                p.units_per_mm *= 20.0;
            }
        }
        let s = FrameSettings {
            technique: Technique::Control,
            export_hdr: true,
            export_gbuffer: true,
            ..FrameSettings::new(128, 96)
        };
        let control = render(&test, &scene, s);
        let plain = render(
            &test,
            &scene,
            FrameSettings {
                technique: Technique::None,
                ..s
            },
        );
        let gbuffer = control.gbuffer.as_ref().unwrap();
        let (profile, _) = FrameFeatures::new(&scene, &s).unwrap().sss.unwrap();
        let reference = lucent::reference::sss::reference_image(
            &scene,
            gbuffer,
            &profile,
            ReferenceSpecular::BlinnPhong,
        );
        let strength = gbuffer.sss.as_ref().unwrap();
        let (w, h) = (128i64, 96i64);
        // Interior: the pixel and every pixel within 4 of it scatter (away from silhouettes,
        // where screen-space blurs bleed; those are measured by the edge metrics).
        let interior = |i: usize| {
            let (x, y) = (i as i64 % w, i as i64 / w);
            (-4..=4).all(|dy| {
                (-4..=4).all(|dx| {
                    let (nx, ny) = (x + dx, y + dy);
                    (0..w).contains(&nx)
                        && (0..h).contains(&ny)
                        && strength[(ny * w + nx) as usize] > 0.0
                })
            })
        };
        let error = |hdr: &[f32]| {
            let (mut sum, mut n) = (0.0f64, 0usize);
            for (i, r) in reference.iter().enumerate() {
                if interior(i) {
                    for c in 0..3 {
                        sum += (f64::from(hdr[i * 4 + c]) - r[c]).abs();
                    }
                    n += 3;
                }
            }
            sum / n.max(1) as f64
        };
        let (e_control, e_plain) = (
            error(control.hdr.as_ref().unwrap()),
            error(plain.hdr.as_ref().unwrap()),
        );
        eprintln!("{name}: mean |GPU - brute-force reference| on scattering pixels: control {e_control:.4e}, no blur {e_plain:.4e}");
        assert!(
            e_control < e_plain,
            "{name}: the control ({e_control:.4e}) is not closer to the reference than no blur ({e_plain:.4e})"
        );
    }
    test.finish();
}

#[test]
fn a_nan_or_inf_in_one_lit_pixel_does_not_spread() {
    use lucent::renderer::Fault;
    let test = TestGpu::new();
    let scene = scene::load_scene("skin").unwrap();
    let clean = render(&test, &scene, settings(Technique::Control));
    let clean_hdr = clean.hdr.unwrap();
    let strength = clean.gbuffer.unwrap().sss.unwrap();
    // A scattering pixel in the middle of a sphere, so the blur's taps all around read it.
    let (w, h) = (160usize, 120usize);
    let target = (0..w * h)
        .filter(|&i| strength[i] > 0.0)
        .min_by_key(|&i| {
            let (x, y) = ((i % w) as i64, (i / w) as i64);
            (x - w as i64 / 2).pow(2) + (y - 60).pow(2)
        })
        .unwrap();
    for nan in [true, false] {
        let fault = Fault {
            x: (target % w) as u32,
            y: (target / w) as u32,
            nan,
        };
        let s = FrameSettings {
            fault: Some(fault),
            ..settings(Technique::Control)
        };
        let hdr = render(&test, &scene, s).hdr.unwrap();
        let bad = hdr.iter().filter(|v| !v.is_finite()).count();
        assert_eq!(bad, 0, "{fault:?}: {bad} non-finite values in the output");
        // Only the blur's reach around the pixel may differ from the clean frame.
        let far_changed = (0..w * h)
            .filter(|&i| {
                let (dx, dy) = (
                    (i % w) as i64 - (target % w) as i64,
                    (i / w) as i64 - (target / w) as i64,
                );
                dx.abs() > 8 || dy.abs() > 8
            })
            .filter(|&i| (0..3).any(|c| hdr[i * 4 + c] != clean_hdr[i * 4 + c]))
            .count();
        assert_eq!(
            far_changed, 0,
            "{fault:?}: pixels beyond the blur's reach changed"
        );
        // And the fault did land: the poisoned pixel itself differs from the clean frame.
        assert!(
            (0..3).any(|c| hdr[target * 4 + c] != clean_hdr[target * 4 + c]),
            "{fault:?}: the injected pixel is unchanged"
        );
    }
    test.finish();
}

#[test]
fn edge_quality_of_the_control_is_measured_on_the_edges_scene() {
    let test = TestGpu::new();
    let scene = scene::load_scene("edges").unwrap();
    let s = FrameSettings {
        technique: Technique::Control,
        export_hdr: true,
        export_gbuffer: true,
        ..FrameSettings::new(128, 96)
    };
    let control = render(&test, &scene, s);
    let plain = render(
        &test,
        &scene,
        FrameSettings {
            technique: Technique::None,
            ..s
        },
    );
    let gbuffer = control.gbuffer.as_ref().unwrap();
    let (profile, _) = FrameFeatures::new(&scene, &s).unwrap().sss.unwrap();
    let reference = lucent::reference::sss::reference_image(
        &scene,
        gbuffer,
        &profile,
        ReferenceSpecular::BlinnPhong,
    );
    let strength = gbuffer.sss.as_ref().unwrap();
    let m = lucent::reference::sss::edge_metrics(
        128,
        strength,
        plain.hdr.as_ref().unwrap(),
        control.hdr.as_ref().unwrap(),
        &reference,
        2,
    );
    eprintln!("edges, control: {m:?}");
    assert!(m.edge_pixels > 100 && m.interior_pixels > 100, "{m:?}");
    // The control writes the blur only where the pixel scatters: no halo by construction.
    assert_eq!(m.halo_pixels, 0, "{m:?}");
    assert!(m.edge_error.is_finite() && m.interior_error.is_finite());
    // Bleeding: the silhouette band is further from the reference than the interior.
    assert!(m.edge_error > m.interior_error, "{m:?}");
    test.finish();
}
