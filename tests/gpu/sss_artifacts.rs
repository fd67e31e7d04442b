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

/// Display luminance (0-1) per pixel of `frame`.
fn display_luminance(frame: &FrameImages) -> Vec<f32> {
    frame
        .display
        .chunks_exact(4)
        .map(|p| {
            (0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])) / 255.0
        })
        .collect()
}

/// The median of `values` over the 9x9 window around `(x, y)` (clipped at the borders).
fn median9(values: &[f32], w: usize, h: usize, x: usize, y: usize) -> f32 {
    let mut window: Vec<f32> = Vec::with_capacity(81);
    for yy in y.saturating_sub(4)..=(y + 4).min(h - 1) {
        for xx in x.saturating_sub(4)..=(x + 4).min(w - 1) {
            window.push(values[yy * w + xx]);
        }
    }
    window.sort_by(f32::total_cmp);
    window[window.len() / 2]
}

/// The vein pixels of a textured SSS frame: scattering pixels whose albedo luminance (GB0) lies
/// more than 0.1 below its 9x9 median (the marble texture's veins are darker than the stone).
fn vein_pixels(frame: &FrameImages, w: usize, h: usize) -> Vec<usize> {
    let gb = frame.gbuffer.as_ref().unwrap();
    let ids = gb.sss.as_ref().unwrap();
    let albedo: Vec<f32> = gb
        .gb0
        .iter()
        .map(|a| 0.2126 * a[0] + 0.7152 * a[1] + 0.0722 * a[2])
        .collect();
    (0..w * h)
        .filter(|&i| ids[i] > 0.0 && albedo[i] < median9(&albedo, w, h, i % w, i / w) - 0.1)
        .collect()
}

/// Mean |L - median9(L)| of display luminance over `pixels`: how much the veins stand out.
fn vein_contrast(frame: &FrameImages, pixels: &[usize], w: usize, h: usize) -> f64 {
    let l = display_luminance(frame);
    let sum: f64 = pixels
        .iter()
        .map(|&i| f64::from((l[i] - median9(&l, w, h, i % w, i / w)).abs()))
        .sum();
    sum / pixels.len().max(1) as f64
}

/// Issue 25: the screen-space blurs diffuse light, not the albedo texture. On `showcase-marble`
/// (veined marble) at 640x480, the veins' contrast against their neighbourhood under each SSS
/// technique with the albedo applied after the blur (`post`, the default) is at least 60% of
/// plain lighting's; blurring the albedo with the light (`pre`, what lucent did before) loses
/// most of it, and `pre-post` (its square root before and after) lies between the two.
#[test]
fn sss_keeps_the_albedo_texture_sharp() {
    use lucent::scene::material::Texturing;
    let (w, h) = (640usize, 480usize);
    let test = TestGpu::new();
    let scene = load_scene_baked("showcase-marble").unwrap();
    let frame = |technique, texturing: Option<Texturing>| {
        let mut settings = FrameSettings {
            technique,
            export_gbuffer: true,
            ..FrameSettings::new(w as u32, h as u32)
        };
        settings.sss.texturing = texturing;
        test.render(&scene, settings)
    };
    let auto = frame(Technique::Auto, None);
    let veins = vein_pixels(&auto, w, h);
    assert!(veins.len() > 500, "{} vein pixels", veins.len());
    let plain = vein_contrast(&frame(Technique::None, None), &veins, w, h);
    let blurred = vein_contrast(&frame(Technique::Auto, Some(Texturing::Pre)), &veins, w, h);
    eprintln!(
        "{} vein pixels; contrast plain {plain:.4}, SSS with the albedo blurred (pre) {blurred:.4} \
         ({:.0}%)",
        veins.len(),
        100.0 * blurred / plain
    );
    assert!(
        blurred < 0.5 * plain,
        "pre {blurred} against plain {plain}: the test sees no blur"
    );
    for technique in common::sss_techniques() {
        // The default texturing (the material does not say).
        let post = vein_contrast(&frame(technique, None), &veins, w, h);
        let pre_post = vein_contrast(&frame(technique, Some(Texturing::PrePost)), &veins, w, h);
        eprintln!(
            "{}: vein contrast post {post:.4} ({:.0}% of plain), pre-post {pre_post:.4} ({:.0}%)",
            technique.name(),
            100.0 * post / plain,
            100.0 * pre_post / plain
        );
        assert!(
            post >= 0.6 * plain,
            "{} post: vein contrast {post} is under 60% of plain lighting's {plain}",
            technique.name()
        );
        assert!(
            pre_post > blurred && pre_post < post,
            "{} pre-post: vein contrast {pre_post} is not between pre's {blurred} and post's \
             {post}",
            technique.name()
        );
    }
    test.finish();
}
