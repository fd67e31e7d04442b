//! lucent embedded in a host engine (`lucent::embed`): the example host, the SSS effect on
//! host G-buffer layouts against lucent's own SSS frame, several views per frame, the host's
//! allocator and pipeline cache, no submission or wait on the host's device, the leak
//! detector, and mistakes a host can make refused as typed errors, not validation errors.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use crate::common::blur;
use crate::common::{submit_back_to_back, TestGpu};
use ash::vk;
use glam::{DVec3, Mat4};
use lucent::backend::{GpuImage, ImageDesc};
use lucent::embed::gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use lucent::embed::{
    DepthDesc, DiffuseDesc, EmbedOptions, GBufferDesc, HostCamera, HostDevice, HostError,
    HostImage, IdDesc, ImageFault, ImageState, Lucent, NormalDesc, OptionalFeatures, SceneRenderer,
    SssEffect, SssEffectDesc, SssFrame, SssImages, SssMaterial, SssRegion, ThicknessDesc,
    TranslucencyEffect, TranslucencyEffectDesc, TranslucencyFrame, TranslucencyImages,
    TranslucentMaterial, Uploads,
};
use lucent::features::sss::SssProfiles;
use lucent::frame::{FrameSettings, Renderer, Technique};
use lucent::images::compare::{flip_rgba8, FlipThresholds};
use lucent::images::output::{read_png_rgba8, write_png_rgba8};
use lucent::scene::material::{SssProfile, Texturing};
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

/// The host's handles of the test context, with `device` as the device lucent calls through.
pub(crate) fn host_device(test: &TestGpu, device: ash::Device) -> HostDevice {
    let gpu = &test.gpu;
    HostDevice {
        entry: gpu.entry.clone(),
        instance: gpu.instance.clone(),
        physical_device: gpu.physical_device,
        device,
        queue: gpu.queue,
        queue_family: gpu.queue_family,
        enabled: OptionalFeatures {
            host_query_reset: gpu.info.host_query_reset,
            storage_image_write_without_format: gpu.info.storage_image_write_without_format,
        },
    }
}

/// `lucent` for the host's own device: the test context's handles.
pub(crate) fn wrap(test: &TestGpu, options: EmbedOptions) -> Lucent {
    let host = host_device(test, test.gpu.device.clone());
    // SAFETY: the handles are the test context's, created together with lucent's
    // requirements, and outlive the returned value (dropped before `test.finish()`).
    unsafe { Lucent::new(host, options) }.expect("wrap the test's device")
}

pub(crate) fn options(frames_in_flight: usize) -> EmbedOptions {
    EmbedOptions {
        frames_in_flight,
        ..Default::default()
    }
}

/// Builds a renderer with its uploads recorded into a command buffer the test (the host)
/// submits and waits for, then releases the uploads' staging memory.
pub(crate) fn built<T>(
    test: &TestGpu,
    lucent: &Lucent,
    build: impl FnOnce(&mut Uploads) -> lucent::Result<T>,
) -> lucent::Result<T> {
    let mut result = None;
    let mut recorded = None;
    test.gpu
        .submit_and_wait(|cmd| {
            // SAFETY: the test's one-shot command buffer, recording, on lucent's queue family.
            let mut uploads = unsafe { lucent.uploads(cmd) };
            result = Some(build(&mut uploads));
            recorded = Some(uploads);
        })
        .unwrap();
    let mut uploads = recorded.unwrap();
    // SAFETY: submit_and_wait waited for the submission holding the uploads.
    unsafe { uploads.release(lucent) }.unwrap();
    result.unwrap()
}

/// Runs `record` into a command buffer the test submits and waits for.
fn recorded<T>(test: &TestGpu, record: impl FnOnce(vk::CommandBuffer) -> T) -> T {
    let mut out = None;
    test.gpu
        .submit_and_wait(|cmd| out = Some(record(cmd)))
        .unwrap();
    out.unwrap()
}

/// The host's description of one of its images.
pub(crate) fn described(image: &GpuImage, name: &str, usage: vk::ImageUsageFlags) -> HostImage {
    HostImage::new(
        name,
        image.image,
        image.view,
        image.desc.format,
        vk::Extent2D {
            width: image.desc.width,
            height: image.desc.height,
        },
        usage,
    )
    .in_state(ImageState::fragment_sampled())
}

pub(crate) fn f32_bytes(texels: &[[f32; 4]]) -> Vec<u8> {
    bytemuck::cast_slice(texels).to_vec()
}

pub(crate) fn tonemapped(hdr: &[f32], exposure: f64) -> Vec<u8> {
    hdr.chunks_exact(4)
        .flat_map(|t| {
            lucent::reference::tonemap::display_rgba8(
                DVec3::new(t[0] as f64, t[1] as f64, t[2] as f64),
                exposure,
            )
        })
        .collect()
}

/// A host colour image lucent can render into (and the test read back).
fn output_image(
    test: &TestGpu,
    w: u32,
    h: u32,
    format: vk::Format,
    usage: vk::ImageUsageFlags,
) -> GpuImage {
    test.gpu
        .create_image(&ImageDesc::color(w, h, format, usage), "host output")
        .unwrap()
}

/// The error a host gets for `result`, which must be a [`HostError`].
pub(crate) fn host_error<T>(result: lucent::Result<T>) -> HostError {
    match result {
        Err(LucentError::Host(e)) => e,
        Err(other) => panic!("expected a HostError, got {other}"),
        Ok(_) => panic!("expected a HostError, got Ok"),
    }
}

/// `image` changed by `change` (the descriptions cannot be made with struct update syntax
/// outside lucent: they may grow fields).
pub(crate) fn changed<T: Clone>(image: &T, change: impl FnOnce(&mut T)) -> T {
    let mut out = image.clone();
    change(&mut out);
    out
}

/// The example host runs headless under validation, with every effect it inserts, and its
/// frame shows them: it differs from the same host frame without lucent where the skin is
/// (the scatter), where the leaf is (the light let through) and where the layered ball is
/// (Li et al.'s terms), and nowhere it has no material of lucent's.
#[test]
fn host_engine_example_runs_under_validation_and_its_frame_scatters_and_lets_light_through() {
    let dir = common::temp_dir("embed-example");
    let run = |png: &Path, extra: &[&str]| {
        let out = Command::new(example_binary())
            .args(["--size", "256x192", "--frames", "5", "--out"])
            .arg(png)
            .args(extra)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "host_engine failed:\n{stderr}");
        assert!(
            stderr.contains("validation on (synchronization validation included)")
                && stderr.contains("(0 validation errors)"),
            "the example must run under validation with no errors:\n{stderr}"
        );
        stderr.to_string()
    };
    let with = dir.join("with.png");
    let without = dir.join("without.png");
    let whole = dir.join("whole-screen.png");
    // Timed (record_timed, the engine's own EffectTimers): the same frame, and each pass's
    // time printed.
    let log = run(&with, &["--timing"]);
    assert!(
        log.contains("lucent's passes (GPU timestamps")
            && log.contains("engine: lighting")
            && log.contains("environment: host environment")
            && log.contains("translucency: host translucency")
            && log.contains("layered: light-space maps")
            && log.contains("layered: single scattering")
            && log.contains("transmission: host transmission")
            && log.contains("sss: separable horizontal blur")
            && log.contains("sss: sss lean in")
            && log.contains("sss: lbb final lighting"),
        "{log}"
    );
    // The effects drawn only over the objects' screen regions (the default: tiles left out,
    // the blurs' pass-through there) change nothing against the whole screen.
    run(&whole, &["--whole-screen"]);
    assert_eq!(
        read_png_rgba8(&with).unwrap(),
        read_png_rgba8(&whole).unwrap(),
        "the effects over their regions differ from the whole screen ({} and {})",
        with.display(),
        whole.display()
    );
    assert!(
        log.contains("lucent effects: environment")
            && log.contains("translucency (leaf")
            && log.contains("layered media (apple flesh")
            && log.contains("transmission (skin and marble")
            && log.contains("with the separable blur, marble ID 42 with the lbb blur"),
        "{log}"
    );
    // lucent's EnvironmentEffect adds the engine's own sky-over-ground ambient (the engine's
    // lighting leaves it out): the frame equals the one with the engine's own term within
    // the rounding of its B10G11R11 light (one sum rounded twice: 2/255 at most, measured).
    let engine_ambient = dir.join("engine-ambient.png");
    let ambient_log = run(&engine_ambient, &["--engine-ambient"]);
    assert!(
        !ambient_log.contains("environment ("),
        "{log}\n{ambient_log}"
    );
    let (_, _, x) = read_png_rgba8(&with).unwrap();
    let (_, _, y) = read_png_rgba8(&engine_ambient).unwrap();
    let diffs: Vec<u8> = x.iter().zip(&y).map(|(p, q)| p.abs_diff(*q)).collect();
    let worst = diffs.iter().copied().max().unwrap();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    println!("host_engine: lucent's environment against the engine's ambient: worst {worst}/255, mean {mean:.3}");
    assert!(
        worst <= 2 && mean < 0.5,
        "lucent's environment differs from the engine's own ambient: worst {worst}/255, mean \
         {mean} ({} and {})",
        with.display(),
        engine_ambient.display()
    );
    // The engine's lighting pass adds lucent's environment, translucency and transmission
    // terms itself (lucent::embed::glsl::TERMS; the transmission's thickness from the
    // engine's own shadow atlas and cube array, read with lucent's lookup): the same frame within its B10G11R11 light's
    // rounding, with no pass of lucent's but the layered media and the SSS. (The transmission
    // alone changes more than 1,000 pixels by up to 154/255: a fused frame without it, or
    // with its thickness measured wrong, fails this.)
    let fused = dir.join("fused.png");
    let fused_log = run(&fused, &["--fused", "--timing"]);
    assert!(
        fused_log.contains("lucent::embed::glsl::TERMS")
            && fused_log.contains("engine: lighting")
            && fused_log.contains(
                "transmission (skin and marble, lucent's lookup of the engine's shadow atlas and \
                 cube array)"
            )
            && !fused_log.contains("host translucency")
            && !fused_log.contains("host environment")
            && !fused_log.contains("host transmission"),
        "{fused_log}"
    );
    let (_, _, z) = read_png_rgba8(&fused).unwrap();
    let diffs: Vec<u8> = x.iter().zip(&z).map(|(p, q)| p.abs_diff(*q)).collect();
    let worst = diffs.iter().copied().max().unwrap();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    println!("host_engine: lucent's terms in the engine's lighting against lucent's effects: worst {worst}/255, mean {mean:.3}");
    assert!(
        worst <= 2 && mean < 0.5,
        "lucent's fused terms differ from its effects: worst {worst}/255, mean {mean} ({} and \
         {})",
        with.display(),
        fused.display()
    );
    run(&without, &["--without-lucent"]);
    let (w, h, a) = read_png_rgba8(&with).unwrap();
    let (_, _, b) = read_png_rgba8(&without).unwrap();
    let differs = |x: &[u8], y: &[u8]| (0..3).any(|c| x[c].abs_diff(y[c]) > 2);
    let changed = a
        .chunks_exact(4)
        .zip(b.chunks_exact(4))
        .filter(|(x, y)| differs(x, y))
        .count();
    let share = changed as f64 / f64::from(w * h);
    println!(
        "host_engine: lucent's effects change {:.2}% of the pixels",
        share * 100.0
    );
    // The engine's spheres are 6 cm across and its profiles physical (skin, marble): the
    // scatter softens their shadow terminators, 0.49% of the pixels by more than 2/255 at
    // this size (0.51% at 512x384); a blur that did nothing changes none.
    assert!(
        share > 0.002 && share < 0.6,
        "the host frame with lucent's SSS changed {:.2}% of its pixels ({} and {})",
        share * 100.0,
        with.display(),
        without.display()
    );
    // The jade leaf above the spheres (top third, the middle of the frame) is lit through by
    // the light behind it: GDC 2011 translucency brightens it.
    let row = 4 * w as usize;
    let lit_through = (0..h as usize / 3)
        .flat_map(|y| (w as usize / 3..2 * w as usize / 3).map(move |x| y * row + 4 * x))
        .filter(|&i| a[i + 1] > b[i + 1].saturating_add(8))
        .count();
    println!("host_engine: lucent's translucency brightens {lit_through} pixels of the leaf");
    assert!(
        lit_through > 150,
        "translucency brightened only {lit_through} pixels of the leaf ({} and {})",
        with.display(),
        without.display()
    );
    // The apple-flesh ball in front (lower left of the middle) has no Lambert term of the
    // engine's (eq. 3's physical weights): without lucent it is black but for its highlight;
    // Li et al.'s terms light it.
    let ball = (h as usize / 2..3 * h as usize / 4)
        .flat_map(|y| (w as usize / 16..w as usize / 4).map(move |x| y * row + 4 * x))
        .filter(|&i| a[i + 1] > b[i + 1].saturating_add(40))
        .count();
    println!("host_engine: lucent's layered media light {ball} pixels of the ball");
    assert!(
        ball > 600,
        "the layered media lit only {ball} pixels of the ball ({} and {})",
        with.display(),
        without.display()
    );
    // SSS transmission through the engine's own shadow maps: the thin skin ear beside the leaf
    // glows through its thickness, lit from behind (measured: 1,002 pixels by more than 2/255
    // at this size; the 12 cm spheres let next to nothing through).
    let no_transmission = dir.join("no-transmission.png");
    let log_without = run(&no_transmission, &["--no-transmission"]);
    assert!(!log_without.contains("transmission (skin"), "{log_without}");
    let (_, _, c) = read_png_rgba8(&no_transmission).unwrap();
    let through = a
        .chunks_exact(4)
        .zip(c.chunks_exact(4))
        .filter(|(x, y)| differs(x, y))
        .count();
    println!("host_engine: lucent's transmission changes {through} pixels");
    assert!(
        through > 500,
        "transmission changed only {through} pixels ({} and {})",
        with.display(),
        no_transmission.display()
    );
    // The marble's LBB (the LEAN-mapping thesis's technique, the example's default) relights
    // its specular from the blurred LEAN moments of the engine's normals: against the
    // separable blur, which keeps the engine's specular, the marble's highlight changes.
    let separable = dir.join("marble-separable.png");
    run(&separable, &["--marble-blur", "separable"]);
    let (_, _, d) = read_png_rgba8(&separable).unwrap();
    let relit = a
        .chunks_exact(4)
        .zip(d.chunks_exact(4))
        .filter(|(x, y)| differs(x, y))
        .count();
    println!("host_engine: the marble's LBB against the separable blur changes {relit} pixels");
    assert!(
        relit > 50,
        "the marble's LEAN blur changed only {relit} pixels ({} and {})",
        with.display(),
        separable.display()
    );
    // The right of the frame is the blue plastic sphere (the engine's material 5, no profile)
    // and the floor (0): lucent leaves their light as the engine lit it.
    let right = (7 * w / 10) as usize;
    for (y, (ra, rb)) in a.chunks_exact(row).zip(b.chunks_exact(row)).enumerate() {
        for x in right..w as usize {
            let (pa, pb) = (&ra[4 * x..4 * x + 4], &rb[4 * x..4 * x + 4]);
            assert!(
                !differs(pa, pb),
                "pixel ({x}, {y}) without a profile changed: {pa:?} against {pb:?} ({} and {})",
                with.display(),
                without.display()
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Runs the example's `--scene` mode (lucent's whole frame through `SceneRenderer`, in the
/// engine's sRGB target) and `lucent render` on the same scene and size, both under validation
/// (the example's own messenger fails it on any error): within 1/255 per channel (the sRGB
/// target's encode against the PNG's) and FLIP's thresholds.
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
    let worst = engine
        .iter()
        .zip(&render)
        .map(|(a, b)| a.abs_diff(*b))
        .max()
        .unwrap();
    let flip = flip_rgba8(&render, &engine, w, h).unwrap();
    assert!(
        worst <= 1 && flip.within(&FlipThresholds::default()),
        "{scene}: the host engine's frame differs from lucent render: worst {worst}/255, mean \
         FLIP {:.4}, {:.3}% above threshold ({} and {})",
        flip.mean,
        flip.fraction_above * 100.0,
        engine_png.display(),
        render_png.display()
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn host_engine_scene_mode_matches_lucent_render_under_validation() {
    // cubes, 320x240, 6 frames (three frames in flight, each slot used twice).
    example_matches_render("cubes", "320x240", "6");
    // Every screen-space feature at once (translucency, two SSS profiles, shadows) at another
    // size, frames not a multiple of the slots; and Li et al.'s layered media.
    example_matches_render("mixed", "200x150", "4");
    example_matches_render("showcase-layered", "200x150", "4");
}

/// How a test host stores its depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum HostDepth {
    /// D32, standard Z (lucent's own).
    Standard,
    /// D32, reversed Z with an infinite far plane.
    ReversedInfinite,
    /// D24S8, standard Z (its stencil holds the IDs).
    D24Stencil,
    /// R32F linear view depth.
    Linear,
}

/// How a test host stores its material IDs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum HostIds {
    /// R8_UNORM, the profile number / 255 (lucent's own).
    Unorm,
    /// R8_UINT, the host's own numbers (10 + 3k; 200 where nothing scatters).
    Uint,
    /// Bits 4..8 of the depth image's stencil (the low bits hold other data).
    Stencil,
    /// Bits 4..8 of the alpha of an RGBA8 target whose other bits and channels hold other
    /// data.
    AlphaBits,
}

/// The host's ID of profile `k` (0: none).
pub(crate) fn host_id(ids: HostIds, k: u8) -> u8 {
    match (ids, k) {
        (HostIds::Uint, 0) => 200,
        (HostIds::Uint, k) => 10 + 3 * k,
        (_, k) => k,
    }
}

/// A depth-stencil image of `format` (D24_UNORM_S8_UINT or D32_SFLOAT_S8_UINT) holding
/// `depth` and `stencil`, with a view of each aspect, in SHADER_READ_ONLY_OPTIMAL.
struct DepthStencil {
    image: GpuImage,
    depth_view: vk::ImageView,
    stencil_view: vk::ImageView,
}

fn depth_stencil_image(
    test: &TestGpu,
    w: u32,
    h: u32,
    format: vk::Format,
    depth: &[f32],
    stencil: &[u8],
) -> DepthStencil {
    let gpu = &test.gpu;
    let usage = vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST;
    let both = vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL;
    let desc = ImageDesc {
        aspect: both,
        ..ImageDesc::depth(w, h, format, usage)
    };
    let image = gpu.create_image(&desc, "host depth-stencil").unwrap();
    let view = |aspect| {
        gpu.create_view(
            image.image,
            &ImageDesc { aspect, ..desc },
            "host aspect view",
        )
        .unwrap()
    };
    let (depth_view, stencil_view) = (
        view(vk::ImageAspectFlags::DEPTH),
        view(vk::ImageAspectFlags::STENCIL),
    );
    let depth_bytes: Vec<u8> = match format {
        // The 24 low bits of each word (buffer copies of D24's depth aspect are 32-bit).
        vk::Format::D24_UNORM_S8_UINT => depth
            .iter()
            .flat_map(|&d| {
                ((f64::from(d.clamp(0.0, 1.0)) * 16777215.0).round() as u32).to_le_bytes()
            })
            .collect(),
        _ => bytemuck::cast_slice(depth).to_vec(),
    };
    let bytes = [depth_bytes.as_slice(), stencil].concat();
    let region = |aspect, offset| vk::BufferImageCopy {
        buffer_offset: offset,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: aspect,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D {
            width: w,
            height: h,
            depth: 1,
        },
    };
    upload_regions(
        test,
        &image,
        &bytes,
        &[
            region(vk::ImageAspectFlags::DEPTH, 0),
            region(vk::ImageAspectFlags::STENCIL, depth_bytes.len() as u64),
        ],
    );
    DepthStencil {
        image,
        depth_view,
        stencil_view,
    }
}

/// A host layout: its description, its images and its camera, made from lucent's own frame's
/// depth (standard Z, `depth`) and profile numbers (`ids`).
pub(crate) struct HostLayout {
    pub(crate) desc: GBufferDesc,
    pub(crate) camera: HostCamera,
    /// The depth image.
    pub(crate) depth: GpuImage,
    /// The ID image, unless the IDs are in the depth image's stencil.
    pub(crate) ids: Option<GpuImage>,
    /// The depth image's stencil view, when the IDs are there.
    pub(crate) stencil_ids: Option<vk::ImageView>,
    /// Views the test made (destroyed with the layout).
    pub(crate) views: Vec<vk::ImageView>,
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn host_layout(
    test: &TestGpu,
    depth_kind: HostDepth,
    ids_kind: HostIds,
    w: u32,
    h: u32,
    scene: &lucent::scene::Scene,
    depth: &[f32],
    ids: &[u8],
    metres_per_unit: f32,
) -> HostLayout {
    let gpu = &test.gpu;
    let usage = vk::ImageUsageFlags::SAMPLED;
    let camera = &scene.camera;
    let (n, f) = (f64::from(camera.near), f64::from(camera.far));
    let aspect = w as f32 / h as f32;
    let linear: Vec<f64> = depth
        .iter()
        .map(|&d| n * f / (f - f64::from(d) * (f - n)))
        .collect();
    let mut projection = camera.projection(aspect);
    let host_ids: Vec<u8> = ids.iter().map(|&k| host_id(ids_kind, k)).collect();
    let mut extra_views = Vec::new();
    let (depth_image, depth_desc, stencil) = match depth_kind {
        HostDepth::Standard => {
            let image = gpu
                .upload_image(
                    &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
                    &[bytemuck::cast_slice(depth).to_vec()],
                    "host depth",
                )
                .unwrap();
            (image, DepthDesc::device(vk::Format::D32_SFLOAT), None)
        }
        HostDepth::ReversedInfinite => {
            // Reversed Z, no far plane, the y axis the other way round from lucent's.
            projection = Mat4::perspective_infinite_reverse_rh(
                camera.fov_y_degrees.to_radians(),
                aspect,
                camera.near,
            );
            let reversed: Vec<f32> = linear.iter().map(|&z| (n / z) as f32).collect();
            let image = gpu
                .upload_image(
                    &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
                    &[bytemuck::cast_slice(&reversed).to_vec()],
                    "host reversed depth",
                )
                .unwrap();
            (image, DepthDesc::device(vk::Format::D32_SFLOAT), None)
        }
        HostDepth::D24Stencil => {
            // Other bits of the stencil hold the host's own data.
            let stencil: Vec<u8> = host_ids.iter().map(|&id| (id << 4) | 0b0101).collect();
            let ds =
                depth_stencil_image(test, w, h, vk::Format::D24_UNORM_S8_UINT, depth, &stencil);
            extra_views.push(ds.depth_view);
            extra_views.push(ds.stencil_view);
            (
                ds.image,
                DepthDesc::device(vk::Format::D24_UNORM_S8_UINT),
                Some(ds.stencil_view),
            )
        }
        HostDepth::Linear => {
            let z: Vec<f32> = linear.iter().map(|&z| z as f32).collect();
            let image = gpu
                .upload_image(
                    &ImageDesc::color(w, h, vk::Format::R32_SFLOAT, usage),
                    &[bytemuck::cast_slice(&z).to_vec()],
                    "host linear depth",
                )
                .unwrap();
            (image, DepthDesc::linear(vk::Format::R32_SFLOAT), None)
        }
    };
    let (id_desc, id_image) = match ids_kind {
        HostIds::Unorm => (
            IdDesc::value(vk::Format::R8_UNORM),
            Some(
                gpu.upload_image(
                    &ImageDesc::color(w, h, vk::Format::R8_UNORM, usage),
                    std::slice::from_ref(&host_ids),
                    "host IDs",
                )
                .unwrap(),
            ),
        ),
        HostIds::Uint => (
            IdDesc::value(vk::Format::R8_UINT),
            Some(
                gpu.upload_image(
                    &ImageDesc::color(w, h, vk::Format::R8_UINT, usage),
                    std::slice::from_ref(&host_ids),
                    "host IDs",
                )
                .unwrap(),
            ),
        ),
        HostIds::Stencil => {
            assert!(stencil.is_some(), "stencil IDs need the D24S8 depth");
            (IdDesc::stencil(vk::Format::D24_UNORM_S8_UINT, 4, 4), None)
        }
        HostIds::AlphaBits => {
            let packed: Vec<u8> = host_ids
                .iter()
                .flat_map(|&id| [17, 200, 3, (id << 4) | 0b0011])
                .collect();
            (
                IdDesc::bits(vk::Format::R8G8B8A8_UNORM, 3, 4, 4),
                Some(
                    gpu.upload_image(
                        &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
                        &[packed],
                        "host packed target",
                    )
                    .unwrap(),
                ),
            )
        }
    };
    let desc = GBufferDesc::new(
        w,
        h,
        depth_desc,
        DiffuseDesc::with_albedo(vk::Format::R32G32B32A32_SFLOAT),
    )
    .with_specular(vk::Format::R32G32B32A32_SFLOAT)
    .with_material_ids(id_desc)
    .with_metres_per_unit(metres_per_unit);
    HostLayout {
        desc,
        camera: HostCamera::new(camera.view(), projection),
        depth: depth_image,
        ids: id_image,
        stencil_ids: stencil.filter(|_| ids_kind == HostIds::Stencil),
        views: extra_views,
    }
}

/// One host frame's images of a [`HostLayout`]: its depth (through a view made for the frame),
/// its material IDs (none when the layout keeps them in a target of the test's own) and the
/// frame's lighting image, which the effect adds to.
pub(crate) struct FrameImages<'a> {
    pub(crate) depth: &'a HostImage,
    pub(crate) ids: Option<&'a HostImage>,
    pub(crate) lighting: &'a HostImage,
}

/// Records three frames of a host's effect on `layout` (described by `desc`) back to back,
/// three frames in flight, as a host would: each frame's depth view made anew (a recreated
/// view can reuse a handle value), and its own lighting image (RGBA32F holding `start`, a
/// colour attachment left for the transfer); `record(k, cmd, images)` records frame `k`.
/// Returns each frame's lighting, read back.
pub(crate) fn host_frames(
    test: &TestGpu,
    layout: &HostLayout,
    desc: &GBufferDesc,
    start: &[u8],
    mut record: impl FnMut(usize, vk::CommandBuffer, FrameImages<'_>),
) -> Vec<Vec<f32>> {
    let gpu = &test.gpu;
    let (w, h) = (desc.width, desc.height);
    let usage = vk::ImageUsageFlags::SAMPLED;
    let lighting_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
        | vk::ImageUsageFlags::SAMPLED
        | vk::ImageUsageFlags::TRANSFER_SRC;
    let lightings: Vec<GpuImage> = (0..3)
        .map(|_| {
            gpu.upload_image(
                &ImageDesc::color(w, h, vk::Format::R32G32B32A32_SFLOAT, lighting_usage),
                &[start.to_vec()],
                "host lighting",
            )
            .unwrap()
        })
        .collect();
    let depth_aspect = match desc.depth.encoding {
        lucent::embed::DepthEncoding::LinearView => vk::ImageAspectFlags::COLOR,
        _ => vk::ImageAspectFlags::DEPTH,
    };
    let mut views = Vec::new();
    submit_back_to_back(gpu, 3, |k, cmd| {
        let depth_view = fresh_view(test, layout.depth.image, desc.depth.format, depth_aspect);
        views.push(depth_view);
        let depth = HostImage::new(
            "host depth",
            layout.depth.image,
            depth_view,
            desc.depth.format,
            desc.extent(),
            usage,
        )
        .in_state(ImageState::fragment_sampled());
        let ids = match (&layout.ids, layout.stencil_ids) {
            (Some(image), _) => Some(described(image, "host IDs", usage)),
            (None, Some(view)) => Some(
                HostImage::new(
                    "host stencil IDs",
                    layout.depth.image,
                    view,
                    vk::Format::D24_UNORM_S8_UINT,
                    desc.extent(),
                    usage,
                )
                .in_state(ImageState::fragment_sampled()),
            ),
            (None, None) => None,
        };
        let lighting = described(&lightings[k], "host lighting", lighting_usage)
            .then(ImageState::transfer_src());
        record(
            k,
            cmd,
            FrameImages {
                depth: &depth,
                ids: ids.as_ref(),
                lighting: &lighting,
            },
        );
    });
    for view in views {
        // SAFETY: the frames that used it completed (submit_back_to_back waited).
        unsafe { gpu.device.destroy_image_view(view, None) };
    }
    lightings
        .into_iter()
        .map(|lighting| {
            let bytes = gpu
                .read_image(&lighting, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .unwrap();
            gpu.destroy_image(lighting);
            bytemuck::cast_slice(&bytes).to_vec()
        })
        .collect()
}

impl HostLayout {
    pub(crate) fn destroy(self, test: &TestGpu) {
        for view in self.views {
            // SAFETY: made for this test; the GPU is done with it.
            unsafe { test.gpu.device.destroy_image_view(view, None) };
        }
        test.gpu.destroy_image(self.depth);
        if let Some(image) = self.ids {
            test.gpu.destroy_image(image);
        }
    }
}

/// The screen regions of `scene`'s scattering objects (their boxes' corners in the world)
/// seen by `camera`, each widened by its material's reach and given for its material (its
/// host ID, `id_of` the object): what a host passes as `SssFrame::regions`. None (the whole
/// screen) when one crosses the eye's plane.
fn sss_regions(
    scene: &lucent::scene::Scene,
    camera: &HostCamera,
    extent: vk::Extent2D,
    effect: &SssEffect,
    id_of: impl Fn(usize) -> u8,
) -> Vec<SssRegion> {
    let bounds = lucent::gpu_scene::tiles::mesh_bounds(scene);
    let regions: Option<Vec<SssRegion>> = scene
        .objects
        .iter()
        .enumerate()
        .filter(|(_, o)| o.material.sss.is_some())
        .map(|(i, o)| {
            let id = id_of(i);
            let reach = effect
                .reach_of(id)
                .expect("every scattering object's ID has a material");
            let rect = lucent::embed::box_screen_region(
                bounds[o.mesh],
                o.transform,
                camera,
                extent,
                reach,
            );
            rect.map(|rect| SssRegion::of(id, rect))
        })
        .collect();
    regions.unwrap_or_default()
}

/// How many channel values of a frame may differ by more than 1/255: 0.1% (Burley's random
/// taps round differently now and then).
fn over_allowed(frame: &[u8]) -> usize {
    frame.len() / 1000
}

/// Compares a host frame (`have`, RGBA8 after tonemapping) with lucent's own (`want`): at most
/// `over` channel values more than 1/255 apart and within FLIP's thresholds, or it writes both
/// PNGs under `dir` (a temporary directory's name) and fails naming `what`. Returns the report
/// line.
pub(crate) fn compare_host_frame(
    want: &[u8],
    have: &[u8],
    (w, h): (u32, u32),
    over: usize,
    what: &str,
    dir: &str,
) -> String {
    let diffs: Vec<u8> = want.iter().zip(have).map(|(a, b)| a.abs_diff(*b)).collect();
    let worst = *diffs.iter().max().unwrap();
    let count = diffs.iter().filter(|&&d| d > 1).count();
    let flip = flip_rgba8(want, have, w, h).unwrap();
    if count > over || !flip.within(&FlipThresholds::default()) {
        let dir = common::temp_dir(dir);
        write_png_rgba8(&dir.join("frame.png"), w, h, want).unwrap();
        write_png_rgba8(&dir.join("host.png"), w, h, have).unwrap();
        panic!(
            "{what}: the host frame differs from lucent's: worst {worst}/255, {count} values \
             over 1/255 ({})",
            dir.display()
        );
    }
    format!(
        "{what}: worst {worst}/255, {count} channel values over 1/255 ({:.3}%), mean FLIP {:.5}",
        100.0 * count as f64 / diffs.len() as f64,
        flip.mean
    )
}

/// A new view of `image` (a host recreating its views between frames).
pub(crate) fn fresh_view(
    test: &TestGpu,
    image: vk::Image,
    format: vk::Format,
    aspect: vk::ImageAspectFlags,
) -> vk::ImageView {
    let desc = ImageDesc {
        aspect,
        ..ImageDesc::color(1, 1, format, vk::ImageUsageFlags::SAMPLED)
    };
    test.gpu
        .create_view(image, &desc, "recreated view")
        .unwrap()
}

#[test]
fn the_sss_effect_on_host_layouts_equals_lucents_own_sss_frame() {
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
    let mut worst_report = Vec::new();
    for technique in [
        &lucent::features::sss::separable::SEPARABLE
            as &'static dyn lucent::features::registry::TechniqueModule,
        &lucent::features::sss::control::CONTROL,
        &lucent::features::sss::burley::BURLEY,
    ] {
        // (the LEAN blurs, LCB, LBB and bilateral: tests/gpu/embed_lean.rs)
        let sss_blur = blur(technique);
        // lucent's own frame, keeping what a host's lighting would have made.
        let mut settings = FrameSettings {
            technique: Technique::Only(technique),
            export_hdr: true,
            export_gbuffer: true,
            export_lit: true,
            ..FrameSettings::new(w, h)
        };
        // A host's lit diffuse carries its albedo: blurred with the light.
        settings.sss.texturing = Some(Texturing::Pre);
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        let (diffuse, specular) = (lit.diffuse, lit.specular);
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        let expected = images.hdr.unwrap();
        let gb = images.gbuffer.unwrap();
        let ids: Vec<u8> = gb.sss.unwrap().iter().map(|&v| v as u8).collect();
        assert!(ids.iter().any(|&v| v > 0), "the skin scene scatters");

        // The scene's profiles in the frame's ID order, their scale the host's world scale.
        let frame_profiles = SssProfiles::new(
            &scene,
            Some(sss_blur),
            None,
            Some(Texturing::Pre),
            &lucent::features::registry::blur_of,
        )
        .unwrap()
        .unwrap();
        // Each object's profile number (0: none), which the host IDs below follow.
        let object_ids = frame_profiles.object_ids.clone();
        let profiles: Vec<SssProfile> = frame_profiles
            .profiles
            .into_iter()
            .map(|(mut p, b)| {
                p.blur = Some(b.name().into());
                p
            })
            .collect();
        let units_per_mm = profiles[0].units_per_mm;
        assert!(profiles.iter().all(|p| p.units_per_mm == units_per_mm));
        let metres_per_unit = 1.0 / (1000.0 * units_per_mm);

        let usage = vk::ImageUsageFlags::SAMPLED;
        let rgba32 = |t: &[[f32; 4]], name| {
            gpu.upload_image(
                &ImageDesc::color(w, h, vk::Format::R32G32B32A32_SFLOAT, usage),
                &[f32_bytes(t)],
                name,
            )
            .unwrap()
        };
        let diffuse_image = rgba32(&diffuse, "host diffuse");
        // The same light with linear view depth in its alpha, as lucent's own lighting pass
        // writes it for the separable blur (DiffuseDesc::with_depth_in_alpha).
        let (near, far) = (f64::from(scene.camera.near), f64::from(scene.camera.far));
        let with_depth: Vec<[f32; 4]> = diffuse
            .iter()
            .zip(&gb.depth)
            .map(|(t, &d)| {
                let z = near * far / (far - f64::from(d) * (far - near));
                [t[0], t[1], t[2], z as f32]
            })
            .collect();
        let diffuse_depth_image = rgba32(&with_depth, "host diffuse with depth");
        let specular_image = rgba32(&specular, "host specular");
        let exposure = f64::from(scene.exposure);
        let want = tonemapped(&expected, exposure);
        for (name, depth_kind, ids_kind, depth_in_alpha) in [
            (
                "D32, R8_UNORM IDs, linear depth in the diffuse's alpha (lucent's own)",
                HostDepth::Standard,
                HostIds::Unorm,
                true,
            ),
            (
                "reversed-Z infinite D32, R8_UINT IDs",
                HostDepth::ReversedInfinite,
                HostIds::Uint,
                false,
            ),
            (
                "D24S8, IDs in stencil bits 4-7",
                HostDepth::D24Stencil,
                HostIds::Stencil,
                false,
            ),
            (
                "linear R32F depth, IDs in RGBA8 alpha bits 4-7",
                HostDepth::Linear,
                HostIds::AlphaBits,
                false,
            ),
        ] {
            let diffuse_image = if depth_in_alpha {
                &diffuse_depth_image
            } else {
                &diffuse_image
            };
            let mut layout = host_layout(
                &test,
                depth_kind,
                ids_kind,
                w,
                h,
                &scene,
                &gb.depth,
                &ids,
                metres_per_unit,
            );
            if depth_in_alpha {
                layout.desc.diffuse = layout.desc.diffuse.with_depth_in_alpha();
            }
            let mut materials: Vec<SssMaterial> = profiles
                .iter()
                .enumerate()
                .map(|(i, p)| SssMaterial::new(host_id(ids_kind, i as u8 + 1), p.clone()))
                .collect();
            // Each way a host ID finds its profile (IdMap::specialization): the R8_UINT host
            // has eight SSS materials more, which no pixel shows, past the eight its passes
            // tell apart by constants, so they look their profiles up in the table; the
            // stencil host has one more, ID 9, which no pixel shows either: its IDs are then
            // not the profile numbers, so its passes compare them with constants; the
            // others' IDs are 1 to n in order, the profile numbers themselves.
            if ids_kind == HostIds::Uint {
                materials.extend((0..8).map(|k| SssMaterial::new(100 + k, profiles[0].clone())));
            }
            if ids_kind == HostIds::Stencil {
                assert!(materials.iter().all(|m| m.id < 9));
                materials.push(SssMaterial::new(9, profiles[0].clone()));
            }
            let lucent = wrap(&test, options(3));
            let desc = SssEffectDesc::new(
                layout.desc.clone(),
                materials,
                vk::Format::R16G16B16A16_SFLOAT,
            )
            .with_knobs(settings.sss);
            let mut effect = built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc)).unwrap();
            let output_usage =
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
            let outputs: Vec<GpuImage> = (0..3)
                .map(|_| output_image(&test, w, h, vk::Format::R16G16B16A16_SFLOAT, output_usage))
                .collect();
            // One layout blurs only on the tiles its scattering objects' screen bounds
            // (widened by the blurs' reach) touch, as a host computes them; the others on the
            // whole screen. (At this size and the widened profiles' reach the regions touch
            // every tile: the example's test covers regions that leave tiles out.)
            let regions: Vec<SssRegion> = if depth_kind == HostDepth::D24Stencil {
                sss_regions(&scene, &layout.camera, layout.desc.extent(), &effect, |i| {
                    host_id(ids_kind, object_ids[i])
                })
            } else {
                Vec::new()
            };
            // Three frames in flight, submitted back to back; every frame the host makes its
            // views anew (a recreated view can reuse a handle value).
            let mut views = Vec::new();
            submit_back_to_back(gpu, 3, |k, cmd| {
                let depth_format = layout.desc.depth.format;
                let depth_aspect = if depth_kind == HostDepth::Linear {
                    vk::ImageAspectFlags::COLOR
                } else {
                    vk::ImageAspectFlags::DEPTH
                };
                let depth_view = fresh_view(&test, layout.depth.image, depth_format, depth_aspect);
                let diffuse_view = fresh_view(
                    &test,
                    diffuse_image.image,
                    vk::Format::R32G32B32A32_SFLOAT,
                    vk::ImageAspectFlags::COLOR,
                );
                views.extend([depth_view, diffuse_view]);
                let depth_host = HostImage::new(
                    "host depth",
                    layout.depth.image,
                    depth_view,
                    depth_format,
                    layout.desc.extent(),
                    usage,
                )
                .in_state(ImageState::fragment_sampled());
                let diffuse_host = changed(&described(diffuse_image, "host diffuse", usage), |i| {
                    i.view = diffuse_view
                });
                let specular_host = described(&specular_image, "host specular", usage);
                let ids_host = match (&layout.ids, layout.stencil_ids) {
                    (Some(image), _) => HostImage::new(
                        "host IDs",
                        image.image,
                        image.view,
                        image.desc.format,
                        layout.desc.extent(),
                        usage,
                    ),
                    (None, Some(view)) => HostImage::new(
                        "host stencil IDs",
                        layout.depth.image,
                        view,
                        vk::Format::D24_UNORM_S8_UINT,
                        layout.desc.extent(),
                        usage,
                    ),
                    (None, None) => unreachable!(),
                }
                .in_state(ImageState::fragment_sampled());
                let output = described(&outputs[k], "host output", output_usage)
                    .in_state(ImageState::UNDEFINED)
                    .then(ImageState::transfer_src());
                effect
                    .record(
                        &lucent,
                        cmd,
                        &SssFrame {
                            slot: k,
                            view: 0,
                            camera: layout.camera,
                            images: SssImages {
                                depth: &depth_host,
                                diffuse: &diffuse_host,
                                specular: Some(&specular_host),
                                albedo: None,
                                material_ids: &ids_host,
                            },
                            regions: &regions,
                            output: &output,
                            lean: None,
                        },
                    )
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            });
            for view in views {
                // SAFETY: the frames that used it completed (submit_back_to_back waited).
                unsafe { gpu.device.destroy_image_view(view, None) };
            }
            for (k, output) in outputs.iter().enumerate() {
                let got = lucent::images::output::f16_bytes_to_f32(
                    &gpu.read_image(output, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                        .unwrap(),
                );
                let have = tonemapped(&got, exposure);
                let line = compare_host_frame(
                    &want,
                    &have,
                    (w, h),
                    over_allowed(&want),
                    &format!("{} on {name}, frame {k}", technique.name()),
                    &format!("embed-layout-{}-{k}", technique.name()),
                );
                worst_report.push(line);
            }
            effect.destroy(&lucent);
            drop(lucent);
            for output in outputs {
                gpu.destroy_image(output);
            }
            layout.destroy(&test);
        }
        gpu.destroy_image(diffuse_image);
        gpu.destroy_image(diffuse_depth_image);
        gpu.destroy_image(specular_image);
    }
    for line in &worst_report {
        println!("{line}");
    }
    test.finish();
}

/// A host whose lighting pass writes each SSS material's light with the albedo as its
/// profile's texturing asks (`DiffuseAlbedo::AsTexturing`, as HDRP's and lucent's own do),
/// its materials each at their own world scale (`SssMaterial::with_metres_per_unit`), equals
/// lucent's own frame of veined marble with the albedo applied after the scatter, before and
/// after it, and before it alone: the albedo image multiplies in after the blur what the
/// light left out, with no pass to put the light right first.
#[test]
fn a_host_light_with_the_albedo_as_each_texturing_asks_equals_lucents_post_and_pre_post_frames() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (240, 180);
    let mut scene = lucent::bake::scene::load_scene_baked("showcase-marble").unwrap();
    let mut scattering = 0;
    for object in &mut scene.objects {
        if let Some(p) = &mut object.material.sss {
            // Each material its own texturing and its own scale (wide enough to see here).
            let k = scattering % 3;
            p.texturing = [Texturing::Post, Texturing::PrePost, Texturing::Pre][k];
            p.units_per_mm *= [2.0, 4.0, 3.0][k];
            scattering += 1;
        }
    }
    assert!(
        scattering >= 2,
        "showcase-marble has several veined materials"
    );
    let mut report = Vec::new();
    for technique in [
        &lucent::features::sss::separable::SEPARABLE
            as &'static dyn lucent::features::registry::TechniqueModule,
        &lucent::features::sss::control::CONTROL,
        &lucent::features::sss::burley::BURLEY,
    ] {
        let settings = FrameSettings {
            technique: Technique::Only(technique),
            export_hdr: true,
            export_gbuffer: true,
            export_lit: true,
            ..FrameSettings::new(w, h)
        };
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        let gb = images.gbuffer.unwrap();
        let ids: Vec<u8> = gb.sss.unwrap().iter().map(|&v| v as u8).collect();
        let frame_profiles = SssProfiles::new(
            &scene,
            Some(blur(technique)),
            None,
            None,
            &lucent::features::registry::blur_of,
        )
        .unwrap()
        .unwrap();
        let texturings: Vec<Texturing> = frame_profiles
            .profiles
            .iter()
            .map(|(p, _)| p.texturing)
            .collect();
        assert!(
            texturings.contains(&Texturing::Post) && texturings.contains(&Texturing::PrePost),
            "{texturings:?}"
        );
        let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
        let usage = vk::ImageUsageFlags::SAMPLED;
        let upload = |texels: &[[f32; 4]], name| {
            gpu.upload_image(
                &ImageDesc::color(w, h, rgba32, usage),
                &[f32_bytes(texels)],
                name,
            )
            .unwrap()
        };
        // The diffuse as lucent's lighting pass wrote it: for the separable and Burley blurs,
        // linear depth in the alpha, which the taps read there (lucent's own frame reads it
        // at RGBA16F's precision, so does the host: a depth image's differs at depth edges).
        let diffuse = upload(&lit.diffuse, "host diffuse");
        let specular = upload(&lit.specular, "host specular");
        let albedo = upload(&gb.gb0, "host albedo");
        let exposure = f64::from(scene.exposure);
        let want = tonemapped(&images.hdr.unwrap(), exposure);
        for (name, depth_kind, ids_kind) in [
            ("D32, R8_UNORM IDs", HostDepth::Standard, HostIds::Unorm),
            (
                "reversed-Z infinite D32, R8_UINT IDs",
                HostDepth::ReversedInfinite,
                HostIds::Uint,
            ),
        ] {
            let mut layout = host_layout(
                &test, depth_kind, ids_kind, w, h, &scene, &gb.depth, &ids,
                // Every material has its own scale: the G-buffer's is none of theirs.
                1.0,
            );
            layout.desc.diffuse = DiffuseDesc::with_albedo_as_texturing(rgba32);
            if frame_profiles.depth_in_alpha() {
                layout.desc.diffuse = layout.desc.diffuse.with_depth_in_alpha();
            }
            layout.desc = layout.desc.clone().with_albedo(rgba32);
            let materials: Vec<SssMaterial> = frame_profiles
                .profiles
                .iter()
                .enumerate()
                .map(|(i, (p, b))| {
                    let mut profile = p.clone();
                    profile.blur = Some(b.name().into());
                    SssMaterial::new(host_id(ids_kind, i as u8 + 1), profile)
                        .with_metres_per_unit(1.0 / (1000.0 * p.units_per_mm))
                })
                .collect();
            let lucent = wrap(&test, options(3));
            let desc =
                SssEffectDesc::new(layout.desc.clone(), materials, rgba32).with_knobs(settings.sss);
            let mut effect = built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc)).unwrap();
            let start = vec![0u8; (w * h * 16) as usize];
            let frames = host_frames(&test, &layout, &layout.desc, &start, |k, cmd, images| {
                effect
                    .record(
                        &lucent,
                        cmd,
                        &SssFrame {
                            slot: k,
                            view: 0,
                            camera: layout.camera,
                            images: SssImages {
                                depth: images.depth,
                                diffuse: &described(&diffuse, "host diffuse", usage),
                                specular: Some(&described(&specular, "host specular", usage)),
                                albedo: Some(&described(&albedo, "host albedo", usage)),
                                material_ids: images.ids.expect("the IDs are an image"),
                            },
                            regions: &[],
                            output: images.lighting,
                            lean: None,
                        },
                    )
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            });
            for (k, frame) in frames.iter().enumerate() {
                report.push(compare_host_frame(
                    &want,
                    &tonemapped(frame, exposure),
                    (w, h),
                    over_allowed(&want),
                    &format!("{} on {name}, frame {k}", technique.name()),
                    &format!("embed-as-texturing-{}-{k}", technique.name()),
                ));
            }
            effect.destroy(&lucent);
            drop(lucent);
            layout.destroy(&test);
        }
        for image in [diffuse, specular, albedo] {
            gpu.destroy_image(image);
        }
    }
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

/// The SSS passes of a plan between the lighting pass and the tonemap, in execution order:
/// each pass's name, taps, and how many images it reads and writes.
fn sss_passes_of(
    plan: &lucent::graph::Plan,
    from_lighting: bool,
) -> Vec<(String, Option<u32>, usize, usize)> {
    let ordered = plan
        .physical
        .iter()
        .flat_map(|p| p.passes.iter().map(|&i| &plan.passes[i]));
    let mut after_lighting = !from_lighting;
    let mut out = Vec::new();
    for pass in ordered {
        if pass.name == "tonemap" {
            break;
        }
        if after_lighting {
            out.push((
                pass.name.clone(),
                pass.taps,
                pass.reads.len(),
                pass.writes.len(),
            ));
        }
        after_lighting |= pass.name == "lighting";
    }
    out
}

/// lucent's own frames declare their SSS passes through the declaration an `SssEffect`
/// makes, over lucent's G-buffer described as a host describes its own
/// (`GBufferLayout::described`): an effect built on that description, with lucent's profiles
/// as its materials, plans the frame's SSS passes one for one (names, taps, reads and writes),
/// for every blur and for scenes with several profiles and chains.
#[test]
fn an_sss_effect_on_lucents_described_gbuffer_plans_lucents_own_sss_passes() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(1));
    let (w, h) = (320, 240);
    let blurs: Vec<Option<&'static dyn lucent::features::registry::TechniqueModule>> = vec![
        None,
        Some(&lucent::features::sss::control::CONTROL),
        Some(&lucent::features::sss::separable::SEPARABLE),
        Some(&lucent::features::sss::burley::BURLEY),
        Some(&lucent::features::sss::lcb::LCB),
        Some(&lucent::features::sss::lbb::LBB),
        Some(&lucent::features::sss::bilateral::BILATERAL),
    ];
    let mut cases = Vec::new();
    for blur in blurs {
        cases.push(("skin", blur));
    }
    cases.push(("showcase-marble", None));
    cases.push(("mixed", None));
    let mut compared = Vec::new();
    for (name, technique) in cases {
        let scene = lucent::bake::scene::load_scene_baked(name).unwrap();
        let settings = FrameSettings {
            technique: technique.map_or(Technique::Auto, Technique::Only),
            ..FrameSettings::new(w, h)
        };
        let frame = lucent::frame::FrameDesc::new(&scene, &settings).unwrap();
        let profiles = frame.sss().expect("an SSS frame").clone();
        let layout = frame.gbuffer_layout(&settings);
        let frame_plan = lucent::frame::plan_frame(&settings, &frame).unwrap();
        let shadows = frame_plan
            .passes
            .iter()
            .any(|p| p.name == "light-space maps");
        // lucent's profiles as the host's materials: IDs 1 to n (the profile numbers lucent's
        // G-buffer writes), each with its blur and its own scale.
        let materials = profiles
            .profiles
            .iter()
            .enumerate()
            .map(|(i, (p, b))| {
                let mut p = p.clone();
                p.blur = Some(b.name().into());
                let metres = 1.0 / (1000.0 * p.units_per_mm);
                SssMaterial::new(i as u8 + 1, p).with_metres_per_unit(metres)
            })
            .collect();
        let mut desc = SssEffectDesc::new(
            layout.described(w, h),
            materials,
            vk::Format::R16G16B16A16_SFLOAT,
        )
        .with_knobs(settings.sss);
        if shadows && layout.lean {
            desc = desc.with_shadow_maps(vk::Format::D32_SFLOAT);
        }
        let effect = built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc)).unwrap();
        let want = sss_passes_of(&frame_plan, true);
        let got = sss_passes_of(effect.plan(), false);
        effect.destroy(&lucent);
        assert!(!want.is_empty(), "{name}: the frame has SSS passes");
        assert_eq!(
            got,
            want,
            "{name} ({}): the effect on lucent's described G-buffer plans other passes than \
             lucent's frame",
            technique.map_or("auto", |t| t.name())
        );
        compared.push(format!(
            "{name}/{}: {} passes",
            technique.map_or("auto", |t| t.name()),
            want.len()
        ));
    }
    eprintln!("{}", compared.join("; "));
    drop(lucent);
    test.finish();
}

#[test]
fn wrong_layouts_missing_usage_and_bad_slots_are_typed_errors_not_validation_errors() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (64, 48);
    let lucent = wrap(&test, options(2));
    let scene = lucent.load_scene("smoke").unwrap();
    let mut renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, w, h, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
    let full = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let image = output_image(&test, w, h, vk::Format::R8G8B8A8_UNORM, full);
    let good = described(&image, "back buffer", full)
        .in_state(ImageState::UNDEFINED)
        .then(ImageState::transfer_src());
    let record = |renderer: &mut SceneRenderer, output: &HostImage, slot| {
        recorded(&test, |cmd| {
            renderer.record(&lucent, cmd, slot, &scene, output)
        })
    };
    let with = |change: &dyn Fn(&mut HostImage)| {
        let mut image = good.clone();
        change(&mut image);
        image
    };
    // (what is wrong, the image as declared, slot, the kind of error, what it must say)
    let image_fault =
        |kind| move |e: &HostError| matches!(e, HostError::Image { kind: k, .. } if *k == kind);
    type Case<'a> = (
        &'a str,
        HostImage,
        usize,
        Box<dyn Fn(&HostError) -> bool>,
        Vec<&'a str>,
    );
    let cases: Vec<Case> = vec![
        (
            "no COLOR_ATTACHMENT usage",
            with(&|i| i.usage = vk::ImageUsageFlags::TRANSFER_SRC),
            0,
            Box::new(image_fault(ImageFault::Usage)),
            vec!["'back buffer'", "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT"],
        ),
        (
            "a final layout its usage does not allow (SHADER_READ_ONLY without SAMPLED)",
            with(&|i| i.final_state = Some(ImageState::fragment_sampled())),
            0,
            Box::new(image_fault(ImageFault::Layout)),
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
            Box::new(image_fault(ImageFault::Access)),
            vec!["'back buffer'", "TRANSFER_SRC_OPTIMAL", "cannot hold"],
        ),
        (
            "a depth layout on a colour image",
            with(&|i| i.state = ImageState::depth_attachment()),
            0,
            Box::new(image_fault(ImageFault::Layout)),
            vec!["'back buffer'", "DEPTH_STENCIL_ATTACHMENT_OPTIMAL"],
        ),
        (
            "an UNDEFINED final layout",
            with(&|i| i.final_state = Some(ImageState::UNDEFINED)),
            0,
            Box::new(image_fault(ImageFault::Layout)),
            vec!["'back buffer'", "final"],
        ),
        (
            "no final state for an image that comes in UNDEFINED",
            with(&|i| i.final_state = None),
            0,
            Box::new(image_fault(ImageFault::Layout)),
            vec!["'back buffer'", "HostImage::then"],
        ),
        (
            "half the frame's width",
            with(&|i| i.extent.width = w / 2),
            0,
            Box::new(image_fault(ImageFault::Size)),
            vec!["'back buffer'", "32x48"],
        ),
        (
            "a mip level no image of the device has",
            with(&|i| i.mip = 40),
            0,
            Box::new(image_fault(ImageFault::Size)),
            vec!["'back buffer'", "mip 40"],
        ),
        (
            "layers past the end of u32",
            with(&|i| i.base_layer = u32::MAX),
            0,
            Box::new(image_fault(ImageFault::Size)),
            vec!["'back buffer'", "layers 4294967295"],
        ),
        (
            "another format than the renderer's",
            with(&|i| i.format = vk::Format::R16G16B16A16_SFLOAT),
            0,
            Box::new(|e: &HostError| matches!(e, HostError::Unsupported { .. })),
            vec!["'back buffer'", "RGBA16F", "RGBA8"],
        ),
        (
            "a slot beyond the frames in flight",
            good.clone(),
            2,
            Box::new(|e: &HostError| {
                matches!(
                    e,
                    HostError::OutOfRange {
                        what: "frame slot",
                        index: 2,
                        count: 2
                    }
                )
            }),
            vec!["frame slot 2"],
        ),
    ];
    for (what, image, slot, kind, wanted) in cases {
        println!("refused: {what}");
        let e = host_error(record(&mut renderer, &image, slot));
        assert!(kind(&e), "{what}: the wrong kind of error: {e:?}");
        let message = e.to_string();
        for w in wanted {
            assert!(
                message.contains(w),
                "{what}: '{message}' does not say '{w}'"
            );
        }
    }
    // After all of that, a correct frame still renders (nothing half-recorded).
    let state = record(&mut renderer, &good, 1).unwrap();
    assert_eq!(state, ImageState::transfer_src());
    let pixels = gpu
        .read_image(&image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .unwrap();
    assert!(pixels.chunks_exact(4).any(|p| p[0] != pixels[0]));
    renderer.destroy(&lucent);

    // The SSS effect checks its description when it is built and its images each frame.
    let usage = vk::ImageUsageFlags::SAMPLED;
    // Filled, so that each is in SHADER_READ_ONLY_OPTIMAL as described below.
    let texels = (w * h) as usize;
    let colour = gpu
        .upload_image(
            &ImageDesc::color(w, h, vk::Format::R16G16B16A16_SFLOAT, usage),
            &[vec![0; texels * 8]],
            "c",
        )
        .unwrap();
    let depth = gpu
        .upload_image(
            &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
            &[bytemuck::cast_slice(&vec![0.5f32; texels]).to_vec()],
            "d",
        )
        .unwrap();
    let ids = gpu
        .upload_image(
            &ImageDesc::color(w, h, vk::Format::R8_UINT, usage),
            &[vec![7; texels]],
            "i",
        )
        .unwrap();
    let skin = SssProfile {
        texturing: Texturing::Pre,
        ..SssProfile::preset("skin").unwrap()
    };
    let gbuffer = GBufferDesc::new(
        w,
        h,
        DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT));
    let desc = |gbuffer: GBufferDesc, materials: Vec<SssMaterial>| {
        SssEffectDesc::new(gbuffer, materials, vk::Format::R8G8B8A8_UNORM)
    };
    let refused = |desc: SssEffectDesc| {
        host_error(built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc)))
    };
    let material = |id| SssMaterial::new(id, skin.clone());
    // No material IDs described.
    let e = refused(desc(
        GBufferDesc::new(
            w,
            h,
            DepthDesc::device(vk::Format::D32_SFLOAT),
            DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
        ),
        vec![material(1)],
    ));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "material IDs"),
        "{e}"
    );
    // A depth encoding its format cannot have.
    let e = refused(desc(
        changed(&gbuffer, |g| {
            g.depth = DepthDesc::linear(vk::Format::D32_SFLOAT)
        }),
        vec![material(1)],
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "depth"),
        "{e}"
    );
    // An ID bit field wider than 8 bits, an ID 0, the same ID twice, an ID its field cannot hold.
    let e = refused(desc(
        gbuffer
            .clone()
            .with_material_ids(IdDesc::bits(vk::Format::R8G8B8A8_UINT, 3, 0, 9)),
        vec![material(1)],
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "material IDs"),
        "{e}"
    );
    for (materials, says) in [
        (vec![material(0)], "ID 0"),
        (vec![material(3), material(3)], "each once"),
    ] {
        let e = refused(desc(gbuffer.clone(), materials));
        assert!(
            matches!(&e, HostError::Description { .. }) && e.to_string().contains(says),
            "{e}"
        );
    }
    let e = refused(desc(
        gbuffer
            .clone()
            .with_material_ids(IdDesc::bits(vk::Format::R8G8B8A8_UINT, 3, 6, 2)),
        vec![material(5)],
    ));
    assert!(e.to_string().contains("does not fit"), "{e}");
    // The LEAN blurs (LBB, bilateral) make their LEAN moments from normals, which this
    // description lacks (tests/gpu/embed_lean.rs has their other errors).
    for lean_blur in [
        &lucent::features::sss::lbb::LBB
            as &'static dyn lucent::features::registry::TechniqueModule,
        &lucent::features::sss::bilateral::BILATERAL,
    ] {
        let lean = SssProfile {
            blur: Some(blur(lean_blur).name().into()),
            ..skin.clone()
        };
        let e = refused(desc(gbuffer.clone(), vec![SssMaterial::new(1, lean)]));
        assert!(
            matches!(&e, HostError::Missing { input, .. } if input == "normals"),
            "{e}"
        );
    }
    // Texturing after the scatter without an albedo image.
    let post = SssProfile {
        texturing: Texturing::Post,
        ..skin.clone()
    };
    let e = refused(desc(
        gbuffer.clone(),
        vec![SssMaterial::new(1, post.clone())],
    ));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "albedo"),
        "{e}"
    );
    // Diffuse light without albedo and no albedo image.
    let e = refused(desc(
        changed(&gbuffer, |g| {
            g.diffuse = DiffuseDesc::without_albedo(vk::Format::R16G16B16A16_SFLOAT)
        }),
        vec![material(1)],
    ));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "albedo"),
        "{e}"
    );
    // The albedo as each texturing asks, a profile applying it after the scatter and no
    // albedo image.
    let e = refused(desc(
        changed(&gbuffer, |g| {
            g.diffuse = DiffuseDesc::with_albedo_as_texturing(vk::Format::R16G16B16A16_SFLOAT)
        }),
        vec![SssMaterial::new(1, post.clone())],
    ));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "albedo"),
        "{e}"
    );
    // A material's own world scale that is no size.
    for metres in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let e = refused(desc(
            gbuffer.clone(),
            vec![material(1), material(2).with_metres_per_unit(metres)],
        ));
        assert!(
            matches!(&e, HostError::Description { field, .. }
                if field == "materials[1] (ID 2).metres_per_unit"),
            "{metres}: {e}"
        );
    }

    // Built correctly, then given wrong images.
    let mut effect = built(&test, &lucent, |u| {
        SssEffect::new(&lucent, u, desc(gbuffer.clone(), vec![material(7)]))
    })
    .unwrap();
    let diffuse_host = described(&colour, "lit diffuse", usage);
    let depth_host = described(&depth, "scene depth", usage);
    let ids_host = described(&ids, "material IDs", usage);
    let out = output_image(&test, w, h, vk::Format::R8G8B8A8_UNORM, full);
    let out_host = described(&out, "sss output", full)
        .in_state(ImageState::UNDEFINED)
        .then(ImageState::transfer_src());
    let camera = HostCamera::new(
        scene.camera.view(),
        scene.camera.projection(w as f32 / h as f32),
    );
    let mut frame = |images: SssImages<'_>, slot, view| {
        let frame = SssFrame {
            slot,
            view,
            camera,
            images,
            regions: &[],
            output: &out_host,
            lean: None,
        };
        recorded(&test, |cmd| effect.record(&lucent, cmd, &frame))
    };
    let good_images = SssImages {
        depth: &depth_host,
        diffuse: &diffuse_host,
        specular: None,
        albedo: None,
        material_ids: &ids_host,
    };
    let unsampled_depth = changed(&depth_host, |i| {
        i.usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT;
        i.state = ImageState::depth_attachment();
    });
    let e = host_error(frame(
        SssImages {
            depth: &unsampled_depth,
            ..good_images
        },
        0,
        0,
    ));
    assert!(
        matches!(
            e,
            HostError::Image {
                kind: ImageFault::Usage,
                ..
            }
        ),
        "{e}"
    );
    assert!(
        e.to_string().contains("'scene depth'") && e.to_string().contains("SAMPLED"),
        "{e}"
    );
    let colour_as_ids = changed(&diffuse_host, |i| i.name = "material IDs".into());
    let e = host_error(frame(
        SssImages {
            material_ids: &colour_as_ids,
            ..good_images
        },
        0,
        0,
    ));
    assert!(
        matches!(e, HostError::Unsupported { .. }) && e.to_string().contains("R8UI"),
        "{e}"
    );
    let e = host_error(frame(
        SssImages {
            specular: Some(&diffuse_host),
            ..good_images
        },
        0,
        0,
    ));
    assert!(
        matches!(
            e,
            HostError::Image {
                kind: ImageFault::Aliased,
                ..
            }
        ),
        "{e}"
    );
    let e = host_error(frame(good_images, 0, 1));
    assert!(
        matches!(
            e,
            HostError::OutOfRange {
                what: "view",
                index: 1,
                count: 1
            }
        ),
        "{e}"
    );
    let e = host_error(frame(good_images, 5, 0));
    assert!(
        matches!(
            e,
            HostError::OutOfRange {
                what: "frame slot",
                ..
            }
        ),
        "{e}"
    );
    // And a correct frame after all of them.
    frame(good_images, 1, 0).unwrap();
    // Normals and lights for a LEAN blur, given to an effect without one: refused, as a LEAN
    // effect without them is (tests/gpu/embed_lean.rs builds those).
    let with_lean = SssFrame {
        slot: 0,
        view: 0,
        camera,
        images: good_images,
        regions: &[],
        output: &out_host,
        lean: Some(lucent::embed::LeanLighting {
            surface: lucent::embed::LeanSurface::Normals(&diffuse_host),
            lights: &scene.lights,
            shadow_map: None,
            second_shadow_map: None,
            shadow_faces: &[],
        }),
    };
    let e = host_error(recorded(&test, |cmd| {
        effect.record(&lucent, cmd, &with_lean)
    }));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "lean"),
        "{e}"
    );
    // A region for a material the effect does not have (its one material is 7).
    let rect = vk::Rect2D {
        offset: vk::Offset2D { x: 8, y: 8 },
        extent: vk::Extent2D {
            width: 16,
            height: 16,
        },
    };
    let stray = [SssRegion::of(7, rect), SssRegion::of(8, rect)];
    let e = host_error(recorded(&test, |cmd| {
        effect.record(
            &lucent,
            cmd,
            &SssFrame {
                regions: &stray,
                lean: None,
                ..with_lean
            },
        )
    }));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field == "regions[1].material"),
        "{e}"
    );
    effect.destroy(&lucent);
    drop(lucent);
    for image in [image, colour, depth, ids, out] {
        gpu.destroy_image(image);
    }
    // No validation error anywhere above.
    test.finish();
}

/// Every call lucent makes through the host's device, counted where a host would see it.
static SUBMITS: AtomicUsize = AtomicUsize::new(0);
static WAITS: AtomicUsize = AtomicUsize::new(0);
static REAL: OnceLock<(ash::DeviceFnV1_0, ash::DeviceFnV1_3)> = OnceLock::new();

unsafe extern "system" fn counted_queue_submit(
    queue: vk::Queue,
    count: u32,
    submits: *const vk::SubmitInfo<'_>,
    fence: vk::Fence,
) -> vk::Result {
    SUBMITS.fetch_add(1, Ordering::SeqCst);
    (REAL.get().unwrap().0.queue_submit)(queue, count, submits, fence)
}

unsafe extern "system" fn counted_queue_submit2(
    queue: vk::Queue,
    count: u32,
    submits: *const vk::SubmitInfo2<'_>,
    fence: vk::Fence,
) -> vk::Result {
    SUBMITS.fetch_add(1, Ordering::SeqCst);
    (REAL.get().unwrap().1.queue_submit2)(queue, count, submits, fence)
}

unsafe extern "system" fn counted_queue_wait_idle(queue: vk::Queue) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    (REAL.get().unwrap().0.queue_wait_idle)(queue)
}

unsafe extern "system" fn counted_device_wait_idle(device: vk::Device) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    (REAL.get().unwrap().0.device_wait_idle)(device)
}

unsafe extern "system" fn counted_wait_for_fences(
    device: vk::Device,
    count: u32,
    fences: *const vk::Fence,
    wait_all: vk::Bool32,
    timeout: u64,
) -> vk::Result {
    WAITS.fetch_add(1, Ordering::SeqCst);
    (REAL.get().unwrap().0.wait_for_fences)(device, count, fences, wait_all, timeout)
}

/// The test's device with its submits and waits counted.
fn counting_device(device: &ash::Device) -> ash::Device {
    let real = REAL.get_or_init(|| (device.fp_v1_0().clone(), device.fp_v1_3().clone()));
    let mut v1_0 = real.0.clone();
    v1_0.queue_submit = counted_queue_submit;
    v1_0.queue_wait_idle = counted_queue_wait_idle;
    v1_0.device_wait_idle = counted_device_wait_idle;
    v1_0.wait_for_fences = counted_wait_for_fences;
    let mut v1_3 = real.1.clone();
    v1_3.queue_submit2 = counted_queue_submit2;
    ash::Device::from_parts_1_3(
        device.handle(),
        v1_0,
        device.fp_v1_1().clone(),
        device.fp_v1_2().clone(),
        v1_3,
    )
}

#[test]
fn no_embed_path_submits_or_waits_on_the_hosts_device() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (96, 72);
    let host = host_device(&test, counting_device(&gpu.device));
    // SAFETY: the test context's handles (the device's functions counted, then forwarded).
    let lucent = unsafe { Lucent::new(host, options(2)) }.unwrap();
    let mut scene = lucent.load_scene("mixed").unwrap();
    scene.name = "counted".into();
    let before = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
    // A whole frame (translucency, SSS, shadows: every upload a scene has), and the SSS
    // effect, each built and recorded twice into the test's own command buffers.
    let mut renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, w, h, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let image = output_image(&test, w, h, vk::Format::R8G8B8A8_UNORM, usage);
    for slot in 0..2 {
        let output = described(&image, "frame", usage)
            .in_state(ImageState::UNDEFINED)
            .then(ImageState::transfer_src());
        recorded(&test, |cmd| {
            renderer.record(&lucent, cmd, slot, &scene, &output)
        })
        .unwrap();
    }
    renderer.destroy(&lucent);
    let sampled = vk::ImageUsageFlags::SAMPLED;
    let colour = gpu
        .create_image(
            &ImageDesc::color(w, h, vk::Format::R16G16B16A16_SFLOAT, sampled),
            "c",
        )
        .unwrap();
    let depth = gpu
        .create_image(
            &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, sampled),
            "d",
        )
        .unwrap();
    let ids = gpu
        .create_image(&ImageDesc::color(w, h, vk::Format::R8_UINT, sampled), "i")
        .unwrap();
    let out = output_image(&test, w, h, vk::Format::R16G16B16A16_SFLOAT, usage);
    // Contents undefined is fine here: this test counts calls, not pixels. Each image is
    // moved into the sampled state once, by the test, so the states declared below are true.
    recorded(&test, |cmd| {
        for image in [&colour, &depth, &ids] {
            let range = image.desc.subresource_range();
            let barrier = [vk::ImageMemoryBarrier2::default()
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
                .dst_stage_mask(vk::PipelineStageFlags2::FRAGMENT_SHADER)
                .dst_access_mask(vk::AccessFlags2::SHADER_SAMPLED_READ)
                .image(image.image)
                .subresource_range(range)];
            // SAFETY: the test's recording command buffer and its own images.
            unsafe {
                gpu.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&barrier),
                )
            };
        }
    });
    let gbuffer = GBufferDesc::new(
        w,
        h,
        DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
    .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT))
    .with_albedo(vk::Format::R16G16B16A16_SFLOAT)
    .with_thickness(ThicknessDesc::channel(vk::Format::R16G16B16A16_SFLOAT, 0));
    let skin = SssProfile {
        texturing: Texturing::Pre,
        ..SssProfile::preset("skin").unwrap()
    };
    let mut translucency = built(&test, &lucent, |u| {
        TranslucencyEffect::new(
            &lucent,
            u,
            TranslucencyEffectDesc::new(
                gbuffer.clone(),
                vec![TranslucentMaterial::new(2, 12.0, 0.2, 0.0)],
            ),
        )
    })
    .unwrap();
    let mut effect = built(&test, &lucent, |u| {
        SssEffect::new(
            &lucent,
            u,
            SssEffectDesc::new(
                // (The albedo is the translucency's: the SSS is given none.)
                changed(&gbuffer, |g| g.albedo = None),
                vec![SssMaterial::new(1, skin)],
                vk::Format::R16G16B16A16_SFLOAT,
            ),
        )
    })
    .unwrap();
    let mut environment = built(&test, &lucent, |u| {
        lucent::embed::EnvironmentEffect::new(
            &lucent,
            u,
            lucent::embed::EnvironmentEffectDesc::new(gbuffer.clone()),
        )
    })
    .unwrap();
    let skin1 = lucent::scene::material::Medium::new(
        lucent::scene::layered::LayeredMedium::preset("skin1").unwrap(),
    );
    let mut transmission = built(&test, &lucent, |u| {
        lucent::embed::TransmissionEffect::new(
            &lucent,
            u,
            lucent::embed::TransmissionEffectDesc::new(
                gbuffer.clone(),
                vec![lucent::embed::TransmissionMaterial::new(1, skin1)],
                vk::Format::D32_SFLOAT,
            ),
        )
    })
    .unwrap();
    // Li et al.'s layered media, drawing one triangle of a host vertex buffer into its maps.
    let mut layered = built(&test, &lucent, |u| {
        lucent::embed::LayeredEffect::new(
            &lucent,
            u,
            lucent::embed::LayeredEffectDesc::new(
                gbuffer.clone(),
                vec![lucent::embed::LayeredMaterial::new(
                    1,
                    lucent::embed::LayeredMedium::preset("apple").unwrap(),
                )],
                lucent::embed::VertexLayout::interleaved(24, 0, 12),
                vk::Extent2D {
                    width: 64,
                    height: 64,
                },
            ),
        )
    })
    .unwrap();
    let triangle = gpu
        .upload_buffer(
            &[
                0.0f32, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0,
                1.0, 0.0,
            ],
            vk::BufferUsageFlags::VERTEX_BUFFER,
            "triangle",
        )
        .unwrap();
    let meshes = [lucent::embed::MeshDraw::new(
        triangle.buffer,
        3,
        glam::Mat4::IDENTITY,
        1,
    )];
    // A sun whose shadow map is the depth image's top-left square (its contents do not
    // matter: this test counts calls).
    let sun = [lucent::embed::Light::directional(
        glam::Vec3::new(0.2, -1.0, 0.3),
        glam::Vec3::ONE,
        3.0,
    )];
    let sun_face = [lucent::embed::ShadowFace::new(
        0,
        glam::Mat4::look_to_rh(
            glam::Vec3::new(0.0, 5.0, 0.0),
            glam::Vec3::new(0.2, -1.0, 0.3),
            glam::Vec3::Z,
        ),
        glam::Mat4::orthographic_rh(-2.0, 2.0, -2.0, 2.0, 0.5, 10.0),
        vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: h,
                height: h,
            },
        },
    )];
    let camera = HostCamera::new(
        scene.camera.view(),
        scene.camera.projection(w as f32 / h as f32),
    );
    for slot in 0..2 {
        let images = SssImages {
            depth: &described(&depth, "depth", sampled),
            diffuse: &described(&colour, "diffuse", sampled),
            specular: None,
            albedo: None,
            material_ids: &described(&ids, "ids", sampled),
        };
        let output = described(&out, "out", usage)
            .in_state(ImageState::UNDEFINED)
            .then(ImageState::transfer_src());
        recorded(&test, |cmd| {
            effect.record(
                &lucent,
                cmd,
                &SssFrame {
                    slot,
                    view: 0,
                    camera,
                    images,
                    regions: &[],
                    output: &output,
                    lean: None,
                },
            )
        })
        .unwrap();
        // The translucency adds to what the SSS wrote (left in TRANSFER_SRC_OPTIMAL).
        let colour_in = described(&colour, "colour", sampled);
        let lighting = described(&out, "out", usage).in_state(ImageState::transfer_src());
        recorded(&test, |cmd| {
            translucency.record(
                &lucent,
                cmd,
                &TranslucencyFrame {
                    slot,
                    view: 0,
                    camera,
                    lights: &scene.lights,
                    images: TranslucencyImages {
                        depth: images.depth,
                        normals: &colour_in,
                        albedo: &colour_in,
                        thickness: &colour_in,
                        material_ids: images.material_ids,
                    },
                    regions: &[],
                    lighting: &lighting,
                },
            )
        })
        .unwrap();
        // The environment and the transmission add to it too.
        recorded(&test, |cmd| {
            environment.record(
                &lucent,
                cmd,
                &lucent::embed::EnvironmentFrame {
                    slot,
                    view: 0,
                    camera,
                    environment: &scene.environment,
                    images: lucent::embed::EnvironmentImages {
                        depth: images.depth,
                        normals: &colour_in,
                        albedo: Some(&colour_in),
                    },
                    regions: &[],
                    lighting: &lighting,
                },
            )
        })
        .unwrap();
        let shadow_map = described(&depth, "shadow map", sampled);
        recorded(&test, |cmd| {
            transmission.record(
                &lucent,
                cmd,
                &lucent::embed::TransmissionFrame {
                    slot,
                    view: 0,
                    camera,
                    lights: &sun,
                    shadow_faces: &sun_face,
                    images: lucent::embed::TransmissionImages {
                        depth: images.depth,
                        normals: &colour_in,
                        material_ids: images.material_ids,
                        albedo: Some(&colour_in),
                        shadow_map: &shadow_map,
                        second_shadow_map: None,
                    },
                    regions: &[],
                    lighting: &lighting,
                },
            )
        })
        .unwrap();
        let mut light_face = sun_face;
        light_face[0].rect.extent = vk::Extent2D {
            width: 64,
            height: 64,
        };
        recorded(&test, |cmd| {
            layered.record(
                &lucent,
                cmd,
                &lucent::embed::LayeredFrame {
                    slot,
                    view: 0,
                    camera,
                    lights: &sun,
                    environment: Some(&scene.environment),
                    light_faces: &light_face,
                    meshes: &meshes,
                    images: lucent::embed::LayeredImages {
                        depth: images.depth,
                        normals: &colour_in,
                        material_ids: images.material_ids,
                        albedo: None,
                        layer_depths: None,
                    },
                    regions: &[],
                    lighting: &lighting,
                },
            )
        })
        .unwrap();
    }
    effect.destroy(&lucent);
    translucency.destroy(&lucent);
    environment.destroy(&lucent);
    transmission.destroy(&lucent);
    layered.destroy(&lucent);
    gpu.destroy_buffer(triangle);
    drop(lucent);
    let after = (SUBMITS.load(Ordering::SeqCst), WAITS.load(Ordering::SeqCst));
    assert_eq!(
        after, before,
        "lucent submitted or waited on the host's device: (submits, waits) went from {before:?} \
         to {after:?}"
    );
    for image in [image, colour, depth, ids, out] {
        gpu.destroy_image(image);
    }
    test.finish();
}

#[test]
fn renderers_move_between_threads_and_destroyed_ones_are_not_counted_as_leaks() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(1));
    let scene = lucent.load_scene("smoke").unwrap();
    let before = lucent::embed::leaked();
    // Renderers can move to another thread (a host's loader thread builds them).
    fn send<T: Send>(_: &T) {}
    let renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, 32, 24, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
    send(&renderer);
    let renderer = std::thread::spawn(move || renderer).join().unwrap();
    renderer.destroy(&lucent);
    // (A renderer dropped without `destroy` raises `leaked()` and logs an error naming it:
    // the unit test in src/embed/uploads.rs; here its allocations would fail the context's
    // own leak report.)
    assert_eq!(
        lucent::embed::leaked(),
        before,
        "a destroyed renderer is not a leak"
    );
    drop(lucent);
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
            ..Default::default()
        },
    );
    let scene = lucent.load_scene("cubes").unwrap();
    let renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, 96, 64, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
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

/// Where [`two_views_per_frame_each_equal_their_view_alone`] writes each view.
#[derive(Clone, Copy, Debug, PartialEq)]
enum ViewOutputs {
    /// An image of its own each.
    Separate,
    /// View k into layer k of one two-layer image (stereo), through a 2-D view of the layer,
    /// reading its inputs from layer k of two-layer images too.
    Layers,
    /// Mip 1 of an image twice the size, with two levels (mip 0 never touched).
    SecondMip,
}

#[test]
fn two_views_per_frame_each_equal_their_view_alone() {
    // Split screen or stereo: two cameras recorded into one frame's command buffer, for the
    // same slot, each with its own images, each as it would be alone; the same into the two
    // layers of one array image (a stereo renderer's eyes), reading each eye's G-buffer and
    // light from the layers of array images, and into the second mip level of larger images:
    // lucent's barriers then cover the view's layer or level only (a barrier on layer 0 or mip
    // 0 instead leaves the written subresource in the wrong layout, which the validation layer
    // reports).
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (160, 120);
    let mut scene = lucent::bake::scene::load_scene_baked("skin").unwrap();
    for object in &mut scene.objects {
        if let Some(p) = &mut object.material.sss {
            p.units_per_mm *= 8.0;
        }
    }
    let views: Vec<lucent::scene::Scene> = (0..2)
        .map(|k| {
            let mut s = scene.clone();
            s.camera.eye.x += 0.6 * (k as f32 * 2.0 - 1.0);
            s
        })
        .collect();
    // Each view's G-buffer and lit light from lucent's own frame.
    let mut inputs = Vec::new();
    for view in &views {
        let mut settings = FrameSettings {
            technique: Technique::Only(&lucent::features::sss::separable::SEPARABLE),
            export_gbuffer: true,
            export_lit: true,
            ..FrameSettings::new(w, h)
        };
        settings.sss.texturing = Some(Texturing::Pre);
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, view, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        inputs.push((images.gbuffer.unwrap(), lit));
    }
    let sampled = vk::ImageUsageFlags::SAMPLED;
    let upload = |format, bytes: Vec<u8>, depth: bool| {
        let desc = if depth {
            ImageDesc::depth(w, h, format, sampled)
        } else {
            ImageDesc::color(w, h, format, sampled)
        };
        gpu.upload_image(&desc, &[bytes], "view input").unwrap()
    };
    // Per view: depth, diffuse, specular and IDs, their formats and texels.
    let formats = [
        vk::Format::D32_SFLOAT,
        vk::Format::R32G32B32A32_SFLOAT,
        vk::Format::R32G32B32A32_SFLOAT,
        vk::Format::R8_UINT,
    ];
    let texels: Vec<[Vec<u8>; 4]> = inputs
        .iter()
        .map(|(gb, lit)| {
            [
                bytemuck::cast_slice(&gb.depth).to_vec(),
                f32_bytes(&lit.diffuse),
                f32_bytes(&lit.specular),
                gb.sss.as_ref().unwrap().iter().map(|&v| v as u8).collect(),
            ]
        })
        .collect();
    let images: Vec<[GpuImage; 4]> = texels
        .iter()
        .map(|view| [0, 1, 2, 3].map(|i| upload(formats[i], view[i].clone(), i == 0)))
        .collect();
    // The same inputs as two-layer images, view k's in layer k (a stereo G-buffer).
    let layered: [GpuImage; 4] = [0, 1, 2, 3].map(|i| {
        let layers = [texels[0][i].clone(), texels[1][i].clone()];
        upload_layers(&test, &images[0][i].desc, &layers)
    });
    let profile = SssProfiles::new(
        &scene,
        Some(blur(&lucent::features::sss::separable::SEPARABLE)),
        None,
        Some(Texturing::Pre),
        &lucent::features::registry::blur_of,
    )
    .unwrap()
    .unwrap()
    .profiles;
    let materials: Vec<SssMaterial> = profile
        .iter()
        .enumerate()
        .map(|(i, (p, b))| {
            let mut p = p.clone();
            p.blur = Some(b.name().into());
            SssMaterial::new(i as u8 + 1, p)
        })
        .collect();
    let gbuffer = GBufferDesc::new(
        w,
        h,
        DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R32G32B32A32_SFLOAT),
    )
    .with_specular(vk::Format::R32G32B32A32_SFLOAT)
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
    .with_metres_per_unit(1.0 / (1000.0 * profile[0].0.units_per_mm));
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let format = vk::Format::R16G16B16A16_SFLOAT;
    // A 2-D view of mip `mip`, layer `layer` of `image`.
    let view_of = |image: &GpuImage, mip: u32, layer: u32| {
        let info = vk::ImageViewCreateInfo::default()
            .image(image.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(vk::ImageSubresourceRange {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                base_mip_level: mip,
                level_count: 1,
                base_array_layer: layer,
                layer_count: 1,
            });
        // SAFETY: the image is live, made with this format and these levels and layers.
        unsafe { gpu.device.create_image_view(&info, None) }.unwrap()
    };
    // What each effect holds in memory, by views per frame.
    let memory = std::cell::RefCell::new(Vec::new());
    let render = |views_per_frame: usize, which: &[usize], into: ViewOutputs| -> Vec<Vec<u8>> {
        let lucent = wrap(&test, options(1));
        let desc = SssEffectDesc::new(gbuffer.clone(), materials.clone(), format)
            .with_views_per_frame(views_per_frame);
        let mut effect = built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc)).unwrap();
        memory.borrow_mut().push((views_per_frame, effect.memory()));
        // Per view: the image, the view of what it writes, its mip and layer.
        let targets: Vec<GpuImage> = match into {
            ViewOutputs::Separate => which
                .iter()
                .map(|_| output_image(&test, w, h, format, usage))
                .collect(),
            ViewOutputs::Layers => vec![gpu
                .create_image(
                    &ImageDesc::color(w, h, format, usage).with_layers(2),
                    "stereo output",
                )
                .unwrap()],
            ViewOutputs::SecondMip => which
                .iter()
                .map(|_| {
                    let mut desc = ImageDesc::color(2 * w, 2 * h, format, usage);
                    desc.mip_levels = 2;
                    gpu.create_image(&desc, "two-level output").unwrap()
                })
                .collect(),
        };
        let outputs: Vec<(&GpuImage, vk::ImageView, u32, u32)> = which
            .iter()
            .enumerate()
            .map(|(index, _)| match into {
                ViewOutputs::Separate => (&targets[index], targets[index].view, 0, 0),
                ViewOutputs::Layers => {
                    let layer = index as u32;
                    (&targets[0], view_of(&targets[0], 0, layer), 0, layer)
                }
                ViewOutputs::SecondMip => (&targets[index], view_of(&targets[index], 1, 0), 1, 0),
            })
            .collect();
        // The 2-D views of input layers the frame reads, destroyed after it.
        let mut input_views = Vec::new();
        recorded(&test, |cmd| {
            for (index, (&k, &(output, view, mip, layer))) in which.iter().zip(&outputs).enumerate()
            {
                let mut host_output = described(output, "view output", usage);
                host_output.view = view;
                host_output.extent = vk::Extent2D {
                    width: w,
                    height: h,
                };
                let aspect = w as f32 / h as f32;
                // Layers: view `index` reads layer `index` of the layered inputs.
                let input = |i: usize, name: &str| match into {
                    ViewOutputs::Layers => {
                        let image = &layered[i];
                        let mut host = described(image, name, sampled);
                        host.view = layer_view(&test, image, index as u32);
                        host.at(0, index as u32)
                    }
                    _ => described(&images[k][i], name, sampled),
                };
                let inputs = [
                    input(0, "depth"),
                    input(1, "diffuse"),
                    input(2, "specular"),
                    input(3, "ids"),
                ];
                input_views.extend(
                    inputs
                        .iter()
                        .filter(|_| matches!(into, ViewOutputs::Layers))
                        .map(|i| i.view),
                );
                let frame_images = SssImages {
                    depth: &inputs[0],
                    diffuse: &inputs[1],
                    specular: Some(&inputs[2]),
                    albedo: None,
                    material_ids: &inputs[3],
                };
                effect
                    .record(
                        &lucent,
                        cmd,
                        &SssFrame {
                            slot: 0,
                            view: index,
                            camera: HostCamera::new(
                                views[k].camera.view(),
                                views[k].camera.projection(aspect),
                            ),
                            images: frame_images,
                            regions: &[],
                            output: &host_output
                                .at(mip, layer)
                                .in_state(ImageState::UNDEFINED)
                                .then(ImageState::transfer_src()),
                            lean: None,
                        },
                    )
                    .unwrap();
            }
        });
        let out: Vec<Vec<u8>> = outputs
            .iter()
            .map(|&(image, _, mip, layer)| {
                gpu.read_image_at(image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, mip, layer)
                    .unwrap()
            })
            .collect();
        effect.destroy(&lucent);
        drop(lucent);
        for &(image, view, _, _) in &outputs {
            if view != image.view {
                // SAFETY: the frame completed (`recorded` waits); the view is the test's.
                unsafe { gpu.device.destroy_image_view(view, None) };
            }
        }
        for view in input_views {
            // SAFETY: as above.
            unsafe { gpu.device.destroy_image_view(view, None) };
        }
        for image in targets {
            gpu.destroy_image(image);
        }
        out
    };
    let alone = [
        render(1, &[0], ViewOutputs::Separate).remove(0),
        render(1, &[1], ViewOutputs::Separate).remove(0),
    ];
    assert_ne!(alone[0], alone[1], "the two views differ");
    for into in [
        ViewOutputs::Separate,
        ViewOutputs::Layers,
        ViewOutputs::SecondMip,
    ] {
        let both = render(2, &[0, 1], into);
        for k in 0..2 {
            assert_eq!(
                both[k], alone[k],
                "view {k} recorded beside the other ({into:?}) differs from alone"
            );
        }
    }
    // The views share the intermediate images (a frame's views record one after the other)
    // and each has its own parameter slot: memory says so. The separable blur's intermediate
    // is the horizontal pass's RGBA16F target at the G-buffer's size; the host's images count
    // nothing.
    let memory = memory.into_inner();
    let one = memory.iter().find(|(v, _)| *v == 1).unwrap().1;
    let target = u64::from(w * h) * 8;
    assert!(one.images >= target && one.images < 2 * target, "{one:?}");
    assert!(one.parameters > 0 && one.total() == one.images + one.parameters);
    for (views, m) in &memory {
        assert_eq!(m.images, one.images, "{views} views: {m:?} against {one:?}");
        assert_eq!(
            m.parameters,
            *views as u64 * one.parameters,
            "{views} views: {m:?}"
        );
    }
    for image in images.into_iter().flatten().chain(layered) {
        gpu.destroy_image(image);
    }
    test.finish();
}

/// An image like `desc` with one layer per entry of `layers` (texels tightly packed, the
/// depth aspect of a depth format), left in the sampled state.
fn upload_layers(test: &TestGpu, desc: &ImageDesc, layers: &[Vec<u8>]) -> GpuImage {
    let gpu = &test.gpu;
    let usage = desc.usage | vk::ImageUsageFlags::TRANSFER_DST;
    let layered = ImageDesc { usage, ..*desc }.with_layers(layers.len() as u32);
    let image = gpu.create_image(&layered, "layered input").unwrap();
    let bytes: Vec<u8> = layers.concat();
    let regions: Vec<vk::BufferImageCopy> = (0..layers.len())
        .map(|k| vk::BufferImageCopy {
            buffer_offset: (k * layers[0].len()) as u64,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: desc.aspect,
                mip_level: 0,
                base_array_layer: k as u32,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D {
                width: desc.width,
                height: desc.height,
                depth: 1,
            },
        })
        .collect();
    upload_regions(test, &image, &bytes, &regions);
    image
}

/// Copies `bytes` into `image` (every subresource from UNDEFINED) through a staging buffer,
/// `regions` saying where each part goes, and leaves it in SHADER_READ_ONLY_OPTIMAL.
fn upload_regions(test: &TestGpu, image: &GpuImage, bytes: &[u8], regions: &[vk::BufferImageCopy]) {
    let gpu = &test.gpu;
    let mut staging = gpu
        .create_buffer(
            bytes.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            lucent::backend::memory::MemoryUse::Upload,
            "test upload staging",
        )
        .unwrap();
    staging.mapped_mut().unwrap()[..bytes.len()].copy_from_slice(bytes);
    let range = image.desc.subresource_range();
    gpu.submit_and_wait(|cmd| {
        let to_dst = [vk::ImageMemoryBarrier2::default()
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .dst_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .image(image.image)
            .subresource_range(range)];
        let to_read = [vk::ImageMemoryBarrier2::default()
            .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .new_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::FRAGMENT_SHADER)
            .dst_access_mask(vk::AccessFlags2::SHADER_SAMPLED_READ)
            .image(image.image)
            .subresource_range(range)];
        // SAFETY: the test's command buffer; the image and buffer are alive.
        unsafe {
            gpu.device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_dst),
            );
            gpu.device.cmd_copy_buffer_to_image(
                cmd,
                staging.buffer,
                image.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                regions,
            );
            gpu.device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_read),
            );
        }
    })
    .unwrap();
    gpu.destroy_buffer(staging);
}

/// A 2-D view of layer `layer` of `image` (its format and aspect).
fn layer_view(test: &TestGpu, image: &GpuImage, layer: u32) -> vk::ImageView {
    let info = vk::ImageViewCreateInfo::default()
        .image(image.image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(image.desc.format)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: image.desc.aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: layer,
            layer_count: 1,
        });
    // SAFETY: the image is live, made with this format and at least `layer + 1` layers.
    unsafe { test.gpu.device.create_image_view(&info, None) }.unwrap()
}

/// A scene a host builds itself: its own meshes (handed over for lucent to upload), transforms,
/// lucent materials and lights.
pub(crate) fn host_built_scene() -> lucent::scene::Scene {
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
        credits: Vec::new(),
    }
}

#[test]
fn a_host_built_scene_renders_with_three_frames_in_flight_like_frames_one_at_a_time() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (120, 90);
    let lucent = wrap(&test, options(3));
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

    let mut renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, w, h, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
    let desc = &renderer.renderer().desc;
    assert!(desc.sss().is_some() && desc.translucency().is_some() && desc.shadows.is_some());
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let images: Vec<GpuImage> = (0..3)
        .map(|_| output_image(&test, w, h, vk::Format::R8G8B8A8_UNORM, usage))
        .collect();
    // Recorded into three command buffers, submitted back to back, waited for once.
    submit_back_to_back(gpu, 3, |k, cmd| {
        let output = described(&images[k], &format!("frame {k}"), usage)
            .in_state(ImageState::UNDEFINED)
            .then(ImageState::transfer_src());
        renderer
            .record(&lucent, cmd, k, &scenes[k], &output)
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

#[test]
fn effects_build_while_another_host_thread_submits_to_the_queue() {
    // lavapipe has one queue, so the host's other thread submits to the queue lucent was given:
    // the host's own business, legal only because lucent never touches a queue. Were any
    // embed path to submit or wait on it, the validation layer's thread-safety checks (on in
    // every test) would report two threads using the queue at once.
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let lucent = wrap(&test, options(2));
    let scene = lucent.load_scene("mixed").unwrap();
    let (w, h) = (64, 48);
    let gbuffer = GBufferDesc::new(
        w,
        h,
        DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT));
    let skin = SssProfile {
        texturing: Texturing::Pre,
        ..SssProfile::preset("skin").unwrap()
    };
    let desc = SssEffectDesc::new(
        gbuffer,
        vec![SssMaterial::new(3, skin)],
        vk::Format::R16G16B16A16_SFLOAT,
    );
    let stop = std::sync::atomic::AtomicBool::new(false);
    let mut built = None;
    std::thread::scope(|s| {
        let other = s.spawn(|| {
            // The host's streaming thread: empty submissions, each waited for, until told to
            // stop (and at least one).
            let mut count = 0usize;
            while count == 0 || !stop.load(Ordering::SeqCst) {
                submit_back_to_back(gpu, 1, |_, _| {});
                count += 1;
            }
            count
        });
        // The host's setup command buffer, recorded on this thread and submitted once the
        // other thread has stopped using the queue (submit_back_to_back submits after this).
        let (mut other, mut desc) = (Some(other), Some(desc));
        submit_back_to_back(gpu, 1, |_, setup| {
            let (other, desc) = (other.take().unwrap(), desc.take().unwrap());
            // SAFETY: `setup` is recording, on lucent's queue family, submitted and waited
            // for by submit_back_to_back before the uploads are released below.
            let mut uploads = unsafe { lucent.uploads(setup) };
            let renderer = SceneRenderer::new(
                &lucent,
                &mut uploads,
                &scene,
                w,
                h,
                vk::Format::R8G8B8A8_UNORM,
            )
            .unwrap();
            let effect = SssEffect::new(&lucent, &mut uploads, desc).unwrap();
            stop.store(true, Ordering::SeqCst);
            built = Some((other.join().unwrap(), uploads, renderer, effect));
        });
    });
    let (submissions, mut uploads, renderer, effect) = built.unwrap();
    assert!(submissions > 0);
    assert!(
        !uploads.is_empty(),
        "the scene's uploads were recorded into the host's buffer"
    );
    // SAFETY: the submission holding the uploads completed.
    unsafe { uploads.release(&lucent) }.unwrap();
    println!(
        "built a SceneRenderer and an SssEffect while another thread made {submissions} \
         submissions on the queue"
    );
    effect.destroy(&lucent);
    renderer.destroy(&lucent);
    drop(lucent);
    test.finish();
}
