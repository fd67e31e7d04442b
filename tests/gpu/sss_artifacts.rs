//! Artefacts of the screen-space SSS techniques in still images (lavapipe, validation on): LEAN
//! specular fireflies at silhouettes (the HDR maximum under SSS against the frame without it)
//! and column streaks inside the thin slab of `edges` (the largest jump between the mean
//! brightness of adjacent columns, in display levels, against the frame without SSS).

use lucent::bake::scene::load_scene_baked;
use lucent::frame::{FrameImages, FrameSettings, Technique};

use crate::common;

use crate::common::TestGpu;

const SIZE: (u32, u32) = (320, 240);

fn settings(technique: Technique) -> FrameSettings {
    FrameSettings {
        technique,
        export_hdr: true,
        export_gbuffer: true,
        ..FrameSettings::new(SIZE.0, SIZE.1)
    }
}

fn hdr_max(images: &FrameImages) -> f32 {
    images
        .hdr
        .as_ref()
        .unwrap()
        .chunks_exact(4)
        .map(|t| t[0].max(t[1]).max(t[2]))
        .fold(0.0, f32::max)
}

/// The largest jump between adjacent columns inside the slab of `edges` (pixels of a profile in
/// the right half, four columns and two rows away from anything else: the slab's side, seen
/// edge-on, is a column of its own), in display luminance levels: per pair of adjacent columns
/// the mean over the rows where both are inside of the signed difference, so a streak (a
/// column brighter than its neighbour all the way down) counts in full and the shading's smooth
/// gradient barely.
fn column_jump(frame: &FrameImages, ids: &[f32]) -> f32 {
    let (w, h) = (SIZE.0 as usize, SIZE.1 as usize);
    let inside = |x: usize, y: usize| {
        x >= w / 2
            && (x.saturating_sub(4)..=(x + 4).min(w - 1)).all(|xx| {
                (y.saturating_sub(2)..=(y + 2).min(h - 1)).all(|yy| ids[yy * w + xx] > 0.0)
            })
    };
    let luminance = |x: usize, y: usize| {
        let p = &frame.display[(y * w + x) * 4..(y * w + x) * 4 + 3];
        0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
    };
    (0..w - 1)
        .filter_map(|x| {
            let diffs: Vec<f32> = (0..h)
                .filter(|&y| inside(x, y) && inside(x + 1, y))
                .map(|y| luminance(x + 1, y) - luminance(x, y))
                .collect();
            (diffs.len() >= 8).then(|| (diffs.iter().sum::<f32>() / diffs.len() as f32).abs())
        })
        .fold(0.0, f32::max)
}

#[test]
fn lean_specular_stays_bounded_and_draws_no_streaks() {
    let test = TestGpu::new();
    for name in ["edges", "skin"] {
        let scene = load_scene_baked(name).unwrap();
        let plain = test.render(&scene, settings(Technique::None));
        let plain_max = hdr_max(&plain);
        // The profile IDs of an SSS frame mark the scattering pixels.
        let reference = test.render(
            &scene,
            settings(Technique::Only(&lucent::features::sss::control::CONTROL)),
        );
        let ids = reference.gbuffer.as_ref().unwrap().sss.clone().unwrap();
        let plain_jump = column_jump(&plain, &ids);
        for technique in common::sss_techniques() {
            let frame = test.render(&scene, settings(technique));
            let max = hdr_max(&frame);
            let jump = column_jump(&frame, &ids);
            eprintln!(
                "{name} {}: HDR max {max:.2} (without SSS {plain_max:.2}), column jump {jump:.2} \
                 levels (without SSS {plain_jump:.2})",
                technique.name()
            );
            assert!(
                max <= 1.5 * plain_max,
                "{name} {}: HDR max {max} against {plain_max} without SSS (fireflies)",
                technique.name()
            );
            if name == "edges" {
                assert!(
                    jump <= 2.0 * plain_jump.max(0.5),
                    "{name} {}: column jump {jump} levels against {plain_jump} (streaks)",
                    technique.name()
                );
            }
        }
    }
    test.finish();
}
