//! lucent embedded in a host engine (`lucent::embed`): the example engine against `lucent
//! render`, the post-process SSS path against lucent's own SSS frame, the host's allocator
//! and pipeline cache in use, and mistakes a host can make refused as errors, not as
//! validation errors.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::blur;
use crate::common::{submit_back_to_back, TestGpu};
use ash::vk;
use glam::DVec3;
use lucent::backend::{GpuImage, ImageDesc};
use lucent::embed::gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use lucent::embed::{
    EmbedOptions, HostDevice, HostImage, ImageState, Lucent, OptionalFeatures, PostProcessDesc,
    PostProcessFrame, PostProcessInputs, PostProcessSss, PostProcessStates, SceneRenderer,
};
use lucent::features::sss::SssProfiles;
use lucent::frame::{FrameSettings, Renderer, Technique};
use lucent::images::compare::{flip_rgba8, FlipThresholds};
use lucent::images::output::{read_png_rgba8, write_png_rgba8};
use lucent::scene::material::Texturing;
use lucent::LucentError;

/// The example binary `cargo test` built beside this test's (target/<profile>/examples).
fn example_binary() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().and_then(Path::parent).unwrap();
    let name = format!("host_engine{}", std::env::consts::EXE_SUFFIX);
    let path = profile_dir.join("examples").join(name);
    assert!(
        path.is_file(),
        "{} is missing: `cargo test` builds the examples with the tests (with `--test gpu` \
         alone, run `cargo build --example host_engine` first)",
        path.display()
    );
    path
}

/// `lucent` for the host's own device: the test context's handles.
fn wrap(test: &TestGpu, options: EmbedOptions) -> Lucent {
    let gpu = &test.gpu;
    let host = HostDevice {
        entry: gpu.entry.clone(),
        instance: gpu.instance.clone(),
        physical_device: gpu.physical_device,
        device: gpu.device.clone(),
        queue: gpu.queue,
        queue_family: gpu.queue_family,
        enabled: OptionalFeatures {
            host_query_reset: gpu.info.host_query_reset,
            independent_blend: gpu.info.independent_blend,
            storage_image_write_without_format: gpu.info.storage_image_write_without_format,
        },
    };
    // SAFETY: the handles are the test context's, created together with lucent's
    // requirements, and outlive the returned value (dropped before `test.finish()`).
    unsafe { Lucent::new(host, options) }.expect("wrap the test's device")
}

/// Runs the example and `lucent render` on the same scene and size; both under validation
/// (the example's own messenger fails it on any error).
fn example_matches_render(scene: &str, size: &str, frames: &str) {
    let dir = common::temp_dir(&format!("embed-example-{scene}"));
    let engine_png = dir.join("engine.png");
    let out = Command::new(example_binary())
        .args([
            "--scene", scene, "--size", size, "--frames", frames, "--out",
        ])
        .arg(&engine_png)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "host_engine failed:\n{stderr}");
    assert!(
        stderr.contains("validation on (synchronization validation included)")
            && stderr.contains("(0 validation errors)"),
        "the example must run under validation with no errors:\n{stderr}"
    );
    let render_png = dir.join("render.png");
    common::succeeded(
        common::lucent_command()
            .args(["render", "--scene", scene, "--size", size, "--out"])
            .arg(&render_png),
    );
    let (w, h, engine) = read_png_rgba8(&engine_png).unwrap();
    let (rw, rh, render) = read_png_rgba8(&render_png).unwrap();
    assert_eq!((w, h), (rw, rh));
    let flip = flip_rgba8(&render, &engine, w, h).unwrap();
    assert!(
        flip.within(&FlipThresholds::default()),
        "{scene}: the host engine's frame differs from lucent render: mean FLIP {:.4}, {:.3}% \
         above threshold ({} and {})",
        flip.mean,
        flip.fraction_above * 100.0,
        engine_png.display(),
        render_png.display()
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn host_engine_example_matches_lucent_render_under_validation() {
    // The check: cubes, 320x240, 6 frames (three frames in flight, each slot used
    // twice).
    example_matches_render("cubes", "320x240", "6");
    // A frame with every screen-space feature at once (translucency, two SSS profiles,
    // shadows) at another size, frames not a multiple of the slots.
    example_matches_render("mixed", "200x150", "4");
}

/// Uploads `texels` (tightly packed) as a sampled host image in SHADER_READ_ONLY_OPTIMAL.
fn host_input(test: &TestGpu, desc: &ImageDesc, bytes: Vec<u8>, name: &str) -> GpuImage {
    test.gpu.upload_image(desc, &[bytes], name).unwrap()
}

fn described(image: &GpuImage, name: &str, usage: vk::ImageUsageFlags) -> HostImage {
    HostImage {
        name: name.into(),
        image: image.image,
        view: image.view,
        format: image.desc.format,
        extent: vk::Extent2D {
            width: image.desc.width,
            height: image.desc.height,
        },
        usage,
        state: ImageState::fragment_sampled(),
    }
}

fn f32_bytes(texels: &[[f32; 4]]) -> Vec<u8> {
    bytemuck::cast_slice(texels).to_vec()
}

fn tonemapped(hdr: &[f32], exposure: f64) -> Vec<u8> {
    hdr.chunks_exact(4)
        .flat_map(|t| {
            lucent::reference::tonemap::display_rgba8(
                DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64),
                exposure,
            )
        })
        .collect()
}

#[test]
fn post_process_sss_over_a_hosts_lit_images_matches_lucents_own_sss_frame() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (240, 180);
    let mut scene = lucent::bake::scene::load_scene_baked("skin").unwrap();
    // At the scene's physical scale the blur spans ~3 pixels here; 8x makes it one a
    // comparison can miss nothing of (the red terminator spans many pixels).
    for object in &mut scene.objects {
        if let Some(p) = &mut object.material.sss {
            p.units_per_mm *= 8.0;
        }
    }
    for (technique, blur) in [
        (
            Technique::Only(&lucent::features::sss::separable::SEPARABLE),
            blur(&lucent::features::sss::separable::SEPARABLE),
        ),
        (
            Technique::Only(&lucent::features::sss::control::CONTROL),
            blur(&lucent::features::sss::control::CONTROL),
        ),
        (
            Technique::Only(&lucent::features::sss::burley::BURLEY),
            blur(&lucent::features::sss::burley::BURLEY),
        ),
    ] {
        // lucent's own frame, keeping what a host's lighting would have made.
        let settings = FrameSettings {
            technique,
            export_hdr: true,
            export_gbuffer: true,
            export_lit: true,
            ..FrameSettings::new(w, h)
        };
        // A host's lit diffuse carries its albedo: the post-process blurs it with the light.
        let mut settings = settings;
        settings.sss.texturing = Some(Texturing::Pre);
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        let (diffuse, specular) = (lit.diffuse, lit.specular);
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        let expected = images.hdr.unwrap();
        let gb = images.gbuffer.unwrap();

        // The host's images: its lit diffuse and specular, depth buffer and profile IDs.
        let usage = vk::ImageUsageFlags::SAMPLED;
        let rgba32 = |t: &[[f32; 4]], name| {
            host_input(
                &test,
                &ImageDesc::color(w, h, vk::Format::R32G32B32A32_SFLOAT, usage),
                f32_bytes(t),
                name,
            )
        };
        let diffuse_image = rgba32(&diffuse, "host diffuse");
        let specular_image = rgba32(&specular, "host specular");
        let depth_image = host_input(
            &test,
            &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
            bytemuck::cast_slice(&gb.depth).to_vec(),
            "host depth",
        );
        let ids: Vec<u8> = gb.sss.unwrap().iter().map(|&v| v as u8).collect();
        assert!(ids.iter().any(|&v| v > 0), "the skin scene scatters");
        let ids_image = host_input(
            &test,
            &ImageDesc::color(w, h, vk::Format::R8_UNORM, usage),
            ids,
            "host profile ids",
        );
        let output_usage =
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let output_image = gpu
            .create_image(
                &ImageDesc::color(w, h, vk::Format::R16G16B16A16_SFLOAT, output_usage),
                "host output",
            )
            .unwrap();

        let lucent = wrap(
            &test,
            EmbedOptions {
                frames_in_flight: 1,
                ..Default::default()
            },
        );
        let diffuse_host = described(&diffuse_image, "host diffuse", usage);
        let specular_host = described(&specular_image, "host specular", usage);
        let depth_host = described(&depth_image, "host depth", usage);
        let ids_host = described(&ids_image, "host profile ids", usage);
        let inputs = PostProcessInputs {
            diffuse: &diffuse_host,
            specular: Some(&specular_host),
            depth: &depth_host,
            profile_ids: &ids_host,
        };
        // The scene's profiles in the frame's ID order.
        let profiles = SssProfiles::new(
            &scene,
            Some(blur),
            None,
            Some(Texturing::Pre),
            &lucent::features::registry::blur_of,
        )
        .unwrap()
        .unwrap()
        .profiles
        .into_iter()
        .map(|(mut p, b)| {
            p.blur = Some(b.name().into());
            p
        })
        .collect();
        let desc = PostProcessDesc {
            width: w,
            height: h,
            profiles,
            knobs: settings.sss,
            output_format: vk::Format::R16G16B16A16_SFLOAT,
        };
        let desc_again = desc.clone();
        let mut post = PostProcessSss::new(&lucent, desc, &[inputs]).unwrap();
        let output = HostImage {
            state: ImageState::UNDEFINED,
            ..described(&output_image, "host output", output_usage)
        };
        let finals = PostProcessStates {
            inputs: ImageState::fragment_sampled(),
            output: ImageState::transfer_src(),
        };
        let mut returned = None;
        gpu.submit_and_wait(|cmd| {
            returned = Some(post.record(
                &lucent,
                cmd,
                0,
                &PostProcessFrame {
                    camera: &scene.camera,
                    inputs,
                    output: &output,
                    finals,
                },
            ));
        })
        .unwrap();
        assert_eq!(returned.unwrap().unwrap(), finals);
        let got = lucent::images::output::f16_bytes_to_f32(
            &gpu.read_image(&output_image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .unwrap(),
        );
        post.destroy(&lucent);

        // Without the host's specular lucent adds none: the result is the blurred diffuse
        // alone (and the frame's minus its specular).
        let without = PostProcessInputs {
            specular: None,
            ..inputs
        };
        let mut post = PostProcessSss::new(&lucent, desc_again, &[without]).unwrap();
        let mut returned = None;
        gpu.submit_and_wait(|cmd| {
            let output = HostImage {
                state: ImageState::transfer_src(),
                ..output.clone()
            };
            returned = Some(post.record(
                &lucent,
                cmd,
                0,
                &PostProcessFrame {
                    camera: &scene.camera,
                    inputs: without,
                    output: &output,
                    finals,
                },
            ));
        })
        .unwrap();
        returned.unwrap().unwrap();
        let diffuse_only = lucent::images::output::f16_bytes_to_f32(
            &gpu.read_image(&output_image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .unwrap(),
        );
        post.destroy(&lucent);
        drop(lucent);
        let worst = diffuse_only
            .chunks_exact(4)
            .zip(specular.iter())
            .zip(got.chunks_exact(4))
            .map(|((d, s), g)| {
                (0..3)
                    .map(|c| ((d[c] + s[c]) - g[c]).abs() / g[c].abs().max(0.05))
                    .fold(0.0f32, f32::max)
            })
            .fold(0.0f32, f32::max);
        assert!(
            worst < 0.01,
            "{}: blurred diffuse + specular is not the frame with specular (worst {worst})",
            technique.name()
        );

        // The same passes over the same light: equal up to how the taps get their depth
        // (lucent's separable frame carries linear depth in the diffuse's alpha; the host's
        // is linearised from its depth buffer).
        let mean = expected.iter().map(|v| v.abs() as f64).sum::<f64>() / expected.len() as f64;
        let l1 = expected
            .iter()
            .zip(&got)
            .map(|(a, b)| (a - b).abs() as f64)
            .sum::<f64>()
            / expected.len() as f64;
        let exposure = scene.exposure as f64;
        let (want, have) = (tonemapped(&expected, exposure), tonemapped(&got, exposure));
        let flip = flip_rgba8(&want, &have, w, h).unwrap();
        println!(
            "{}: post-process vs frame: relative L1 {:.5}, mean FLIP {:.5}",
            technique.name(),
            l1 / mean,
            flip.mean
        );
        if !flip.within(&FlipThresholds::default()) || l1 / mean > 0.01 {
            let dir = common::temp_dir(&format!("embed-post-{}", technique.name()));
            write_png_rgba8(&dir.join("frame.png"), w, h, &want).unwrap();
            write_png_rgba8(&dir.join("post.png"), w, h, &have).unwrap();
            panic!(
                "{}: post-process SSS differs from the frame's: relative L1 {:.4}, mean FLIP \
                 {:.4} ({})",
                technique.name(),
                l1 / mean,
                flip.mean,
                dir.display()
            );
        }
        // And it scattered: the blurred frame differs from the lit light it started from.
        let lit: Vec<f32> = diffuse
            .iter()
            .zip(&specular)
            .flat_map(|(d, s)| [d[0] + s[0], d[1] + s[1], d[2] + s[2], 1.0])
            .collect();
        let changed = lit
            .chunks_exact(4)
            .zip(got.chunks_exact(4))
            .filter(|(a, b)| (0..3).any(|c| (a[c] - b[c]).abs() > 0.01 * a[c].abs().max(0.01)))
            .count();
        println!(
            "{}: {:.1}% of pixels changed by more than 1% by the blur",
            technique.name(),
            100.0 * changed as f64 / (w * h) as f64
        );
        assert!(
            changed > (w * h / 100) as usize,
            "only {changed} pixels blurred"
        );
        for image in [
            diffuse_image,
            specular_image,
            depth_image,
            ids_image,
            output_image,
        ] {
            gpu.destroy_image(image);
        }
    }
    test.finish();
}

/// A host colour image lucent can render into (and the test read back).
fn output_image(test: &TestGpu, w: u32, h: u32, usage: vk::ImageUsageFlags) -> GpuImage {
    test.gpu
        .create_image(
            &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
            "host output",
        )
        .unwrap()
}

fn expect_refused(result: lucent::Result<ImageState>, wanted: &[&str]) {
    match result {
        Err(LucentError::InvalidInput(message)) => {
            for w in wanted {
                assert!(message.contains(w), "'{message}' does not say '{w}'");
            }
        }
        other => panic!("expected a refusal naming {wanted:?}, got {other:?}"),
    }
}

#[test]
fn wrong_layouts_missing_usage_and_bad_slots_are_errors_not_validation_errors() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (64, 48);
    let lucent = wrap(
        &test,
        EmbedOptions {
            frames_in_flight: 2,
            ..Default::default()
        },
    );
    let scene = lucent.load_scene("smoke").unwrap();
    let mut renderer =
        SceneRenderer::new(&lucent, &scene, w, h, vk::Format::R8G8B8A8_UNORM).unwrap();
    let full = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let image = output_image(&test, w, h, full);
    let good = HostImage {
        name: "back buffer".into(),
        image: image.image,
        view: image.view,
        format: vk::Format::R8G8B8A8_UNORM,
        extent: vk::Extent2D {
            width: w,
            height: h,
        },
        usage: full,
        state: ImageState::UNDEFINED,
    };
    let cmd_result = |renderer: &mut SceneRenderer, output: &HostImage, slot, finals| {
        let mut result = None;
        gpu.submit_and_wait(|cmd| {
            result = Some(renderer.record(&lucent, cmd, slot, &scene, output, finals));
        })
        .unwrap();
        result.unwrap()
    };
    let with = |change: &dyn Fn(&mut HostImage)| {
        let mut image = good.clone();
        change(&mut image);
        image
    };
    let transfer = ImageState::transfer_src();
    // (what is wrong, the image as declared, slot, final state, what the error must say)
    let cases: Vec<(&str, HostImage, usize, ImageState, Vec<&str>)> = vec![
        (
            "no COLOR_ATTACHMENT usage",
            with(&|i| i.usage = vk::ImageUsageFlags::TRANSFER_SRC),
            0,
            transfer,
            vec!["'back buffer'", "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT"],
        ),
        (
            "a final layout its usage does not allow (SHADER_READ_ONLY without SAMPLED)",
            good.clone(),
            0,
            ImageState::fragment_sampled(),
            vec!["'back buffer'", "SHADER_READ_ONLY_OPTIMAL", "SAMPLED"],
        ),
        (
            "written as a colour attachment, declared in TRANSFER_SRC_OPTIMAL",
            with(&|i| {
                i.state = ImageState {
                    layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    ..ImageState::color_attachment()
                }
            }),
            0,
            transfer,
            vec!["'back buffer'", "TRANSFER_SRC_OPTIMAL", "cannot hold"],
        ),
        (
            "a depth layout on a colour image",
            with(&|i| i.state = ImageState::depth_attachment()),
            0,
            transfer,
            vec!["'back buffer'", "DEPTH_STENCIL_ATTACHMENT_OPTIMAL"],
        ),
        (
            "an UNDEFINED final layout",
            good.clone(),
            0,
            ImageState::UNDEFINED,
            vec!["'back buffer'", "final"],
        ),
        (
            "half the frame's width",
            with(&|i| i.extent.width = w / 2),
            0,
            transfer,
            vec!["'back buffer'", "32x48"],
        ),
        (
            "another format than the renderer's",
            with(&|i| i.format = vk::Format::R16G16B16A16_SFLOAT),
            0,
            transfer,
            vec!["'back buffer'", "format"],
        ),
        (
            "a slot beyond the frames in flight",
            good.clone(),
            2,
            transfer,
            vec!["slot 2", "2 frame(s) in flight"],
        ),
    ];
    for (what, image, slot, finals, wanted) in cases {
        println!("refused: {what}");
        expect_refused(cmd_result(&mut renderer, &image, slot, finals), &wanted);
    }
    // After all of that, a correct frame still renders (nothing half-recorded).
    let state = cmd_result(&mut renderer, &good, 1, ImageState::transfer_src()).unwrap();
    assert_eq!(state, ImageState::transfer_src());
    let pixels = gpu
        .read_image(&image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .unwrap();
    assert!(pixels.chunks_exact(4).any(|p| p[0] != pixels[0]));
    renderer.destroy(&lucent);

    // The post-process path checks its inputs the same way: a depth input without SAMPLED
    // usage, a profile-ID image of the wrong format, an input set it was not built with.
    let usage = vk::ImageUsageFlags::SAMPLED;
    let colour = gpu
        .create_image(
            &ImageDesc::color(w, h, vk::Format::R16G16B16A16_SFLOAT, usage),
            "c",
        )
        .unwrap();
    let depth = gpu
        .create_image(&ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage), "d")
        .unwrap();
    let ids = gpu
        .create_image(&ImageDesc::color(w, h, vk::Format::R8_UNORM, usage), "i")
        .unwrap();
    let diffuse_host = described(&colour, "lit diffuse", usage);
    let depth_host = described(&depth, "scene depth", usage);
    let ids_host = described(&ids, "sss mask", usage);
    let skin = lucent::scene::material::SssProfile {
        texturing: Texturing::Pre,
        ..lucent::scene::material::SssProfile::preset("skin").unwrap()
    };
    let desc = PostProcessDesc {
        width: w,
        height: h,
        profiles: vec![skin],
        knobs: Default::default(),
        output_format: vk::Format::R16G16B16A16_SFLOAT,
    };
    let refused = |inputs: PostProcessInputs<'_>, wanted: &[&str]| match PostProcessSss::new(
        &lucent,
        desc.clone(),
        &[inputs],
    ) {
        Err(LucentError::InvalidInput(m)) => {
            for w in wanted {
                assert!(m.contains(w), "'{m}' does not say '{w}'");
            }
        }
        Err(other) => panic!("expected InvalidInput, got {other}"),
        Ok(post) => {
            post.destroy(&lucent);
            panic!("expected a refusal naming {wanted:?}");
        }
    };
    let unsampled_depth = HostImage {
        usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        state: ImageState::depth_attachment(),
        ..depth_host.clone()
    };
    refused(
        PostProcessInputs {
            diffuse: &diffuse_host,
            specular: None,
            depth: &unsampled_depth,
            profile_ids: &ids_host,
        },
        &["'scene depth'", "VK_IMAGE_USAGE_SAMPLED_BIT"],
    );
    let colour_as_ids = HostImage {
        name: "sss mask".into(),
        ..diffuse_host.clone()
    };
    refused(
        PostProcessInputs {
            diffuse: &diffuse_host,
            specular: None,
            depth: &depth_host,
            profile_ids: &colour_as_ids,
        },
        &["'sss mask'", "R8_UNORM"],
    );
    let lean = lucent::scene::material::SssProfile {
        blur: Some(blur(&lucent::features::sss::lbb::LBB).name().into()),
        ..lucent::scene::material::SssProfile::preset("skin").unwrap()
    };
    let good_inputs = PostProcessInputs {
        diffuse: &diffuse_host,
        specular: None,
        depth: &depth_host,
        profile_ids: &ids_host,
    };
    match PostProcessSss::new(
        &lucent,
        PostProcessDesc {
            profiles: vec![lean],
            ..desc.clone()
        },
        &[good_inputs],
    ) {
        Err(LucentError::InvalidInput(m)) => assert!(m.contains("LEAN"), "{m}"),
        Err(other) => panic!("expected InvalidInput, got {other}"),
        Ok(_) => panic!("a LEAN blur has no post-process path"),
    }
    // Built for one set, recorded with another: refused before recording.
    let mut post = PostProcessSss::new(&lucent, desc.clone(), &[good_inputs]).unwrap();
    let other_depth = gpu
        .create_image(&ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage), "d2")
        .unwrap();
    let other_depth_host = described(&other_depth, "other depth", usage);
    let out = output_image(&test, w, h, full);
    let out_host = HostImage {
        format: vk::Format::R8G8B8A8_UNORM,
        ..described(&out, "post output", full)
    };
    let mut result = None;
    gpu.submit_and_wait(|cmd| {
        result = Some(post.record(
            &lucent,
            cmd,
            0,
            &PostProcessFrame {
                camera: &scene.camera,
                inputs: PostProcessInputs {
                    depth: &other_depth_host,
                    ..good_inputs
                },
                output: &out_host,
                finals: PostProcessStates {
                    inputs: ImageState::fragment_sampled(),
                    output: ImageState::transfer_src(),
                },
            },
        ));
    })
    .unwrap();
    match result.unwrap() {
        Err(LucentError::InvalidInput(m)) => assert!(m.contains("not one of the 1 set"), "{m}"),
        other => panic!("expected a refusal, got {other:?}"),
    }
    post.destroy(&lucent);
    drop(lucent);
    for image in [image, colour, depth, ids, other_depth, out] {
        gpu.destroy_image(image);
    }
    // No validation error anywhere above.
    test.finish();
}

#[test]
fn a_hosts_allocator_and_pipeline_cache_are_used_and_left_alive() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let allocator = std::sync::Arc::new(std::sync::Mutex::new(
        Allocator::new(&AllocatorCreateDesc {
            instance: gpu.instance.clone(),
            device: gpu.device.clone(),
            physical_device: gpu.physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .unwrap(),
    ));
    // SAFETY: plain object creation on the test's device; destroyed below.
    let cache = unsafe {
        gpu.device
            .create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None)
    }
    .unwrap();
    let lucent = wrap(
        &test,
        EmbedOptions {
            frames_in_flight: 2,
            pipeline_cache: Some(cache),
            allocator: Some(allocator.clone()),
            cache_dir: Some(common::temp_dir("embed-cache")),
        },
    );
    let scene = lucent.load_scene("cubes").unwrap();
    let renderer = SceneRenderer::new(&lucent, &scene, 96, 64, vk::Format::R8G8B8A8_UNORM).unwrap();
    let while_alive = allocator.lock().unwrap().generate_report();
    assert!(
        while_alive.allocations.len() > 5,
        "lucent's buffers and images live in the host's allocator ({} allocations)",
        while_alive.allocations.len()
    );
    // The thickness bake went to the host's directory.
    assert!(
        std::fs::read_dir(lucent.cache_dir().join("thickness"))
            .unwrap()
            .next()
            .is_some(),
        "the bake cache is under the host's cache directory"
    );
    renderer.destroy(&lucent);
    drop(lucent);
    // Everything lucent allocated went back; the allocator and the cache are the host's.
    let after = allocator.lock().unwrap().generate_report();
    assert_eq!(after.allocations.len(), 0, "{:?}", after.allocations);
    // SAFETY: lucent is gone; the host's cache is still valid (validation would report a
    // destroyed handle here) and is destroyed once, here.
    unsafe {
        assert!(!gpu
            .device
            .get_pipeline_cache_data(cache)
            .unwrap()
            .is_empty());
        gpu.device.destroy_pipeline_cache(cache, None);
    }
    drop(allocator);
    test.finish();
}

/// A scene a host builds itself: its own meshes (handed over for lucent to upload), transforms,
/// lucent materials and lights.
fn host_built_scene() -> lucent::scene::Scene {
    use glam::{Mat4, Vec3};
    use lucent::scene::material::{
        Light, LightKind, Material, SssProfile, ThicknessSource, Translucency,
    };
    use lucent::scene::mesh::{Mesh, Shape};
    use lucent::scene::{Camera, Object, Scene};
    let sphere = Mesh::generate(Shape::Sphere { radius: 0.5 }, 48, 24);
    let floor = Mesh::generate(Shape::Plane { half_size: 3.0 }, 4, 0);
    let mut skin = Material::opaque("host skin", Vec3::new(0.8, 0.55, 0.45), 0.3, 0.5);
    skin.sss = Some(SssProfile {
        // Widened so the blur spans many pixels at this size.
        units_per_mm: 0.05,
        ..SssProfile::preset("skin").unwrap()
    });
    let mut jade = Material::opaque("host jade", Vec3::new(0.3, 0.6, 0.4), 0.4, 0.3);
    jade.translucency = Some(Translucency {
        color: Vec3::new(0.4, 1.0, 0.6),
        ..Translucency::new(ThicknessSource::Bake)
    });
    let object = |mesh, x: f32, material| Object {
        mesh,
        transform: Mat4::from_translation(Vec3::new(x, 0.5, 0.0)),
        material,
    };
    Scene {
        name: "host-built".into(),
        meshes: vec![sphere, floor],
        objects: vec![
            object(0, -0.6, skin),
            object(0, 0.6, jade),
            Object {
                mesh: 1,
                transform: Mat4::IDENTITY,
                material: Material::opaque("floor", Vec3::splat(0.5), 0.1, 0.8),
            },
        ],
        lights: vec![
            Light {
                kind: LightKind::Directional {
                    direction: Vec3::new(-0.4, -1.0, -0.3),
                },
                color: Vec3::ONE,
                intensity: 2.0,
                translucency_scale: 1.0,
                shadows: true,
            },
            Light {
                kind: LightKind::Point {
                    position: Vec3::new(0.6, 0.6, -1.2),
                    range: 5.0,
                },
                color: Vec3::new(1.0, 0.8, 0.6),
                intensity: 3.0,
                translucency_scale: 1.0,
                shadows: true,
            },
        ],
        camera: Camera {
            eye: Vec3::new(0.0, 1.2, 3.0),
            target: Vec3::new(0.0, 0.4, 0.0),
            fov_y_degrees: 40.0,
            near: 0.05,
            far: 50.0,
        },
        environment: lucent::scene::Environment::constant(Vec3::splat(0.03)),
        sky: Vec3::new(0.4, 0.5, 0.7),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
    }
}

#[test]
fn a_host_built_scene_renders_with_three_frames_in_flight_like_frames_one_at_a_time() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (120, 90);
    let lucent = wrap(
        &test,
        EmbedOptions {
            frames_in_flight: 3,
            ..Default::default()
        },
    );
    let mut scene = host_built_scene();
    lucent.prepare_scene(&mut scene).unwrap();
    assert!(
        !scene.meshes[0].colors.is_empty(),
        "prepare_scene baked the translucent sphere's thickness"
    );
    // Three cameras, so a frame reading another slot's parameters would show.
    let scenes: Vec<_> = (0..3)
        .map(|k| {
            let mut s = scene.clone();
            s.camera.eye.x += 0.8 * (k as f32 - 1.0);
            s
        })
        .collect();
    let expected: Vec<Vec<u8>> = scenes
        .iter()
        .map(|s| {
            lucent::frame::render_frame(
                gpu,
                &test.shaders,
                &test.cache,
                s,
                FrameSettings::new(w, h),
            )
            .unwrap()
            .display
        })
        .collect();
    assert_ne!(expected[0], expected[2], "the cameras differ");

    let mut renderer =
        SceneRenderer::new(&lucent, &scene, w, h, vk::Format::R8G8B8A8_UNORM).unwrap();
    let desc = &renderer.renderer().desc;
    assert!(desc.sss.is_some() && desc.translucency.is_some() && desc.shadows.is_some());
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let images: Vec<GpuImage> = (0..3).map(|_| output_image(&test, w, h, usage)).collect();
    // Recorded into three command buffers, submitted back to back, waited for once.
    submit_back_to_back(gpu, 3, |k, cmd| {
        let output = HostImage {
            name: format!("frame {k}"),
            image: images[k].image,
            view: images[k].view,
            format: vk::Format::R8G8B8A8_UNORM,
            extent: vk::Extent2D {
                width: w,
                height: h,
            },
            usage,
            state: ImageState::UNDEFINED,
        };
        renderer
            .record(
                &lucent,
                cmd,
                k,
                &scenes[k],
                &output,
                ImageState::transfer_src(),
            )
            .unwrap();
    });
    for (k, image) in images.iter().enumerate() {
        let got = gpu
            .read_image(image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .unwrap();
        let worst = common::max_difference(&got, &expected[k]);
        assert!(
            worst <= 1,
            "frame {k} differs from its frame alone by {worst}/255"
        );
    }
    renderer.destroy(&lucent);
    drop(lucent);
    for image in images {
        gpu.destroy_image(image);
    }
    test.finish();
}
