//! FXAA (`--aa fxaa`, issue 16) on lavapipe with validation on: the GPU pass against its f64
//! twin on the very image it read, flat regions untouched, silhouettes smoothed, and frames
//! without it unchanged.

use crate::common;

use crate::common::TestGpu;
use lucent::features::antialias::Antialias;
use lucent::frame::{FrameSettings, Renderer};
use lucent::reference::fxaa::{fxaa_rgba8, LdrImage};

/// Renders `scene_name` at `w x h` with `antialias`; returns (display, the tonemapped image
/// FXAA read, when it ran).
fn render(scene_name: &str, w: u32, h: u32, antialias: Antialias) -> (Vec<u8>, Option<Vec<u8>>) {
    let scene = lucent::bake::scene::load_scene_baked(scene_name).unwrap();
    let settings = FrameSettings {
        antialias,
        export_ldr: antialias == Antialias::Fxaa,
        ..FrameSettings::new(w, h)
    };
    let test = TestGpu::new();
    let frame = test.render_repeated(&scene, settings);
    test.finish();
    (frame.display, frame.ldr)
}

#[test]
fn fxaa_matches_its_f64_twin_on_the_image_it_read() {
    let (w, h) = (240, 180);
    for scene in ["cubes", "showcase-skin"] {
        let (display, ldr) = render(scene, w, h, Antialias::Fxaa);
        let ldr = ldr.unwrap();
        let (expected, edges) = fxaa_rgba8(&LdrImage {
            width: w,
            height: h,
            rgba8: &ldr,
        });
        assert!(edges > 200, "{scene}: only {edges} edge pixels");
        // The GPU filters in fixed point (8-bit lerp weights on lavapipe), the twin in f64: a
        // step of 1-2 in a channel, and rarely a probe that lands the other side of a threshold.
        let mut off_by_more = 0usize;
        let mut worst = 0u8;
        for (a, b) in display.chunks_exact(4).zip(expected.chunks_exact(4)) {
            let d = a[..3]
                .iter()
                .zip(&b[..3])
                .map(|(x, y)| x.abs_diff(*y))
                .max()
                .unwrap();
            worst = worst.max(d);
            if d > 3 {
                off_by_more += 1;
            }
        }
        eprintln!(
            "{scene}: {edges} edge pixels, {off_by_more} off by more than 3/255 (worst {worst})"
        );
        // Measured: cubes 33 of 3,360 edge pixels (1%); a wrong search, direction or blend
        // would put most edge pixels off.
        assert!(
            off_by_more * 40 < edges,
            "{scene}: {off_by_more} pixels differ from the f64 twin by more than 3/255"
        );
    }
}

#[test]
fn fxaa_leaves_flat_regions_alone_and_softens_silhouettes() {
    let (w, h) = (240, 180);
    let (plain, _) = render("cubes", w, h, Antialias::Off);
    let (smoothed, ldr) = render("cubes", w, h, Antialias::Fxaa);
    let ldr = ldr.unwrap();
    // The image FXAA read is the frame without it (sRGB RGBA8 from the same tonemap).
    for (a, b) in plain.chunks_exact(4).zip(ldr.chunks_exact(4)) {
        assert_eq!(&a[..3], &b[..3]);
    }
    let (_, edges) = fxaa_rgba8(&LdrImage {
        width: w,
        height: h,
        rgba8: &ldr,
    });
    let changed = plain
        .chunks_exact(4)
        .zip(smoothed.chunks_exact(4))
        .filter(|(a, b)| a[..3] != b[..3])
        .count();
    eprintln!("cubes: {changed} pixels changed by FXAA, {edges} edge pixels");
    // Only edges change (a flat pixel is copied), and most edges do.
    assert!(changed <= edges, "{changed} changed, {edges} edges");
    assert!(changed * 2 >= edges, "{changed} changed, {edges} edges");
    // And only a few percent of the frame: FXAA is not a blur.
    assert!(changed * 10 < (w * h) as usize, "{changed}");
}

#[test]
fn fxaa_into_a_hosts_srgb_and_float_targets_matches_lucents_own_display() {
    use ash::vk;
    use lucent::backend::access::Access;
    use lucent::backend::resources::ImageDesc;
    use lucent::frame::TargetDesc;
    let (w, h) = (160, 120);
    let (expected, _) = render("cubes", w, h, Antialias::Fxaa);
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let scene = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    for format in [vk::Format::R8G8B8A8_SRGB, vk::Format::R16G16B16A16_SFLOAT] {
        let settings = FrameSettings {
            antialias: Antialias::Fxaa,
            target: Some(TargetDesc {
                format,
                initial: Access::Undefined,
                final_access: Access::TransferRead,
            }),
            ..FrameSettings::new(w, h)
        };
        let mut renderer =
            Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let target = gpu
            .create_image(
                &ImageDesc::color(
                    w,
                    h,
                    format,
                    vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                ),
                "host target",
            )
            .unwrap();
        common::submit_back_to_back(gpu, 1, |slot, cmd| {
            renderer.update_slot(&scene, slot).unwrap();
            renderer
                .bind_target(gpu, slot, target.image, target.view)
                .unwrap();
            renderer.record(gpu, cmd, slot, None).unwrap();
        });
        let bytes = gpu
            .read_image(&target, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .unwrap();
        // The float target holds linear values (FXAA decodes what it blended): encode them as
        // lucent's own display is encoded.
        let got: Vec<u8> = if format == vk::Format::R16G16B16A16_SFLOAT {
            lucent::images::output::f16_bytes_to_f32(&bytes)
                .iter()
                .map(|&v| {
                    let v = f64::from(v).clamp(0.0, 1.0);
                    (lucent::reference::tonemap::linear_to_srgb(v) * 255.0).round() as u8
                })
                .collect()
        } else {
            bytes
        };
        let worst = got
            .chunks_exact(4)
            .zip(expected.chunks_exact(4))
            .map(|(a, b)| {
                a[..3]
                    .iter()
                    .zip(&b[..3])
                    .map(|(x, y)| x.abs_diff(*y))
                    .max()
                    .unwrap()
            })
            .max()
            .unwrap();
        eprintln!("{format:?}: largest difference {worst}/255");
        assert!(worst <= 1, "{format:?}: {worst}/255 off");
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        gpu.destroy_image(target);
    }
    test.finish();
}
