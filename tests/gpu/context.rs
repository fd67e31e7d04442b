//! GpuContext and resource tests. They run on any Vulkan 1.3 device (lavapipe on CI) with the
//! validation layer and synchronization validation on, and fail on any validation error.

use ash::vk;
use lucent::backend::format::texel_bytes;
use lucent::backend::memory::MemoryUse;
use lucent::backend::{ContextDesc, GpuContext, GpuImage, ImageDesc};
use lucent::LucentError;

/// Environment variable that makes `environment_child` run, naming what its environment lacks.
const CHILD_MODE: &str = "LUCENT_TEST_CHILD_MODE";

fn desc(filter: Option<&str>) -> ContextDesc {
    ContextDesc {
        validation: true,
        device_filter: filter.map(str::to_string),
        app_name: "lucent tests".to_string(),
        ..ContextDesc::default()
    }
}

fn context() -> GpuContext {
    let _ = env_logger::builder().is_test(true).try_init();
    GpuContext::new(&desc(None)).unwrap_or_else(|e| panic!("creating the GPU context failed: {e}"))
}

/// Fails the test if the validation layer reported any error.
fn assert_clean(ctx: &GpuContext) {
    let count = ctx.validation_error_count();
    if count != 0 {
        let messages = ctx.take_validation_messages().join("\n\n");
        panic!("{count} validation error(s):\n{messages}");
    }
}

/// Records a full-image layout transition from `old` to `TRANSFER_DST_OPTIMAL` for a clear.
fn to_transfer_dst(ctx: &GpuContext, cmd: vk::CommandBuffer, image: &GpuImage) {
    let barrier = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::NONE)
        .src_access_mask(vk::AccessFlags2::NONE)
        .dst_stage_mask(vk::PipelineStageFlags2::CLEAR)
        .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .old_layout(vk::ImageLayout::UNDEFINED)
        .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.image)
        .subresource_range(image.desc.subresource_range())];
    // SAFETY: `cmd` is recording and the image is live.
    unsafe {
        ctx.device.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().image_memory_barriers(&barrier),
        )
    };
}

/// Clears a colour image to `color`, leaving it in TRANSFER_DST_OPTIMAL.
fn clear_color(ctx: &GpuContext, image: &GpuImage, color: vk::ClearColorValue) {
    ctx.submit_and_wait(|cmd| {
        ctx.begin_label(cmd, &format!("clear {}", image.name));
        to_transfer_dst(ctx, cmd, image);
        // SAFETY: the image is in TRANSFER_DST_OPTIMAL with TRANSFER_DST usage.
        unsafe {
            ctx.device.cmd_clear_color_image(
                cmd,
                image.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &color,
                &[image.desc.subresource_range()],
            )
        };
        ctx.end_label(cmd);
    })
    .expect("clear submit");
}

/// Native-endian `f32`s from raw texel bytes.
/// Creates an image, clears it to `color` and reads it back from `TRANSFER_DST_OPTIMAL`.
fn cleared(ctx: &GpuContext, desc: &ImageDesc, name: &str, color: [f32; 4]) -> (GpuImage, Vec<u8>) {
    let image = ctx.create_image(desc, name).expect("create image");
    clear_color(ctx, &image, vk::ClearColorValue { float32: color });
    let bytes = ctx
        .read_image(&image, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .expect("read the image back");
    (image, bytes)
}

fn to_f32(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_ne_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

#[test]
fn create_context_and_print_info() {
    let ctx = context();
    let info = &ctx.info;
    println!("device: {}", info.describe());
    println!("driver: {}", info.driver());
    println!(
        "Vulkan {}, timestamps {} bits at {} ns/tick, hostQueryReset {}",
        info.api_version_string(),
        info.timestamp_valid_bits,
        info.timestamp_period_ns,
        info.host_query_reset
    );
    assert!(ctx.validation_enabled());
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<GpuContext>();
    assert!(!info.name.is_empty());
    assert!(info.api_version >= vk::API_VERSION_1_3);
    assert!(info.timestamp_valid_bits > 0);
    assert!(info.timestamp_period_ns > 0.0);
    assert!(info.describe().starts_with(&info.name));
    ctx.wait_idle().expect("wait idle");
    assert_clean(&ctx);
}

#[test]
fn device_filter_matches_or_names_the_devices() {
    let _ = env_logger::builder().is_test(true).try_init();
    let first = context();
    // Any substring of the default device's name selects it, case-insensitively.
    let wanted: String = first.info.name.chars().take(4).collect();
    let ctx = GpuContext::new(&desc(Some(&wanted.to_uppercase()))).expect("filter by name");
    assert_eq!(ctx.info.name, first.info.name);
    if first.info.name.contains("llvmpipe") {
        let lavapipe = GpuContext::new(&desc(Some("llvmpipe"))).expect("filter 'llvmpipe'");
        assert!(lavapipe.info.name.contains("llvmpipe"));
        assert_eq!(lavapipe.info.driver_name, "llvmpipe");
        assert_clean(&lavapipe);
    }
    match GpuContext::new(&desc(Some("no-such-gpu"))) {
        Err(LucentError::NoMatchingDevice { wanted, available }) => {
            assert_eq!(wanted, "no-such-gpu");
            assert!(available.contains(&first.info.name), "{available}");
            let message = LucentError::NoMatchingDevice { wanted, available }.to_string();
            println!("{message}");
        }
        other => panic!("expected NoMatchingDevice, got {other:?}"),
    }
    assert_clean(&ctx);
    assert_clean(&first);
}

#[test]
fn create_and_destroy_image_and_buffer() {
    let ctx = context();
    let desc = ImageDesc::color(
        128,
        64,
        vk::Format::R16G16B16A16_SFLOAT,
        vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
    );
    let image = ctx
        .create_image(&desc, "test colour")
        .expect("create image");
    assert_eq!(image.name, "test colour");
    assert_ne!(image.view, vk::ImageView::null());
    let depth = ctx
        .create_image(
            &ImageDesc::depth(
                128,
                64,
                vk::Format::D32_SFLOAT,
                vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            ),
            "test depth",
        )
        .expect("create depth image");
    let mut buffer = ctx
        .create_buffer(
            1000,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryUse::Upload,
            "test uniforms",
        )
        .expect("create buffer");
    let mapped = buffer.mapped_mut().expect("CpuToGpu is mapped");
    assert_eq!(mapped.len(), 1000);
    mapped.fill(7);
    assert!(buffer
        .mapped_slice()
        .expect("mapped")
        .iter()
        .all(|&b| b == 7));
    let device_local = ctx
        .create_buffer(
            256,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryUse::DeviceLocal,
            "test storage",
        )
        .expect("create device-local buffer");

    assert!(matches!(
        ctx.create_buffer(
            0,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryUse::Upload,
            "empty"
        ),
        Err(LucentError::InvalidInput(_))
    ));

    ctx.destroy_image(image);
    ctx.destroy_image(depth);
    ctx.destroy_buffer(buffer);
    ctx.destroy_buffer(device_local);
    assert_eq!(texel_bytes(vk::Format::R8G8B8A8_UNORM), Some(4));
    assert_eq!(texel_bytes(vk::Format::R16G16B16A16_SFLOAT), Some(8));
    assert_eq!(texel_bytes(vk::Format::R32G32B32A32_SFLOAT), Some(16));
    assert_eq!(texel_bytes(vk::Format::BC1_RGB_UNORM_BLOCK), None);
    assert_clean(&ctx);
}

#[test]
fn upload_then_read_back_buffer() {
    let ctx = context();
    let data: Vec<u32> = (0..4099u32)
        .map(|i| i.wrapping_mul(2_654_435_761))
        .collect();
    let buffer = ctx
        .upload_buffer(
            &data,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            "test upload",
        )
        .expect("upload");
    assert_eq!(buffer.size, (data.len() * 4) as u64);
    let bytes = ctx.read_buffer(&buffer).expect("read back");
    assert!(matches!(
        ctx.upload_buffer::<u32>(&[], vk::BufferUsageFlags::STORAGE_BUFFER, "empty"),
        Err(LucentError::InvalidInput(_))
    ));
    let read: &[u32] = bytemuck::cast_slice(&bytes);
    assert_eq!(read, &data[..]);
    ctx.destroy_buffer(buffer);
    assert_clean(&ctx);
}

#[test]
fn clear_image_and_read_it_back() {
    let ctx = context();
    // Transfer-only images get no view; SAMPLED gets one.
    let usage = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC;
    let sampled = usage | vk::ImageUsageFlags::SAMPLED;

    // RGBA8, non-square so a row-pitch mistake shows.
    let rgba_desc = ImageDesc::color(37, 19, vk::Format::R8G8B8A8_UNORM, sampled);
    let (rgba, bytes) = cleared(&ctx, &rgba_desc, "test rgba8", [1.0, 0.2, 0.0, 1.0]);
    assert_ne!(rgba.view, vk::ImageView::null());
    assert_eq!(bytes.len(), 37 * 19 * 4);
    for (i, px) in bytes.chunks_exact(4).enumerate() {
        let expected = [255u8, 51, 0, 255];
        let close = px.iter().zip(expected).all(|(&a, b)| a.abs_diff(b) <= 1);
        assert!(close, "pixel {i} is {px:?}, expected {expected:?}");
    }
    // The image was returned to TRANSFER_DST_OPTIMAL: reading it again from there is valid.
    let again = ctx
        .read_image(&rgba, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .expect("read rgba8 again");
    assert_eq!(again, bytes);

    // A float format: exact values.
    let float_desc = ImageDesc::color(8, 4, vk::Format::R32_SFLOAT, usage);
    let (float, floats) = cleared(&ctx, &float_desc, "test r32f", [0.25, 0.0, 0.0, 0.0]);
    assert_eq!(float.view, vk::ImageView::null());
    let floats: Vec<f32> = to_f32(&floats);
    assert_eq!(floats, vec![0.25f32; 32]);

    // Depth: cleared with vkCmdClearDepthStencilImage, read through the DEPTH aspect.
    let depth = ctx
        .create_image(
            &ImageDesc::depth(16, 8, vk::Format::D32_SFLOAT, usage),
            "test depth",
        )
        .expect("create depth");
    ctx.submit_and_wait(|cmd| {
        to_transfer_dst(&ctx, cmd, &depth);
        // SAFETY: the image is in TRANSFER_DST_OPTIMAL with TRANSFER_DST usage.
        unsafe {
            ctx.device.cmd_clear_depth_stencil_image(
                cmd,
                depth.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &vk::ClearDepthStencilValue {
                    depth: 0.75,
                    stencil: 0,
                },
                &[depth.desc.subresource_range()],
            )
        };
    })
    .expect("clear depth");
    let depths = ctx
        .read_image(&depth, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .expect("read depth");
    let depths: Vec<f32> = to_f32(&depths);
    assert_eq!(depths, vec![0.75f32; 16 * 8]);

    // Misuse is an error, not UB.
    assert!(matches!(
        ctx.read_image(&rgba, vk::ImageLayout::UNDEFINED),
        Err(LucentError::InvalidInput(_))
    ));

    ctx.destroy_image(rgba);
    ctx.destroy_image(float);
    ctx.destroy_image(depth);
    assert_clean(&ctx);
}

#[test]
fn aliased_images_share_a_memory_block() {
    let ctx = context();
    let desc = ImageDesc::color(
        32,
        32,
        vk::Format::R8G8B8A8_UNORM,
        vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::SAMPLED,
    );
    let (a, req_a) = ctx.create_image_unbound(&desc, "alias a").expect("image a");
    let (b, req_b) = ctx.create_image_unbound(&desc, "alias b").expect("image b");
    let alignment = req_a.alignment.max(req_b.alignment);
    let second = req_a.size.div_ceil(alignment) * alignment;
    let block = ctx
        .allocate_memory_block(
            vk::MemoryRequirements {
                size: second + req_b.size,
                alignment,
                memory_type_bits: req_a.memory_type_bits & req_b.memory_type_bits,
            },
            "alias block",
        )
        .expect("block");
    assert!(block.size() >= second + req_b.size);

    // Out of range and misaligned offsets are refused.
    assert!(matches!(
        ctx.bind_image(a, &block, block.size()),
        Err(LucentError::InvalidInput(_))
    ));
    if alignment > 1 {
        assert!(matches!(
            ctx.bind_image(a, &block, 1),
            Err(LucentError::InvalidInput(_))
        ));
    }
    ctx.bind_image(a, &block, 0).expect("bind a");
    ctx.bind_image(b, &block, second).expect("bind b");
    let view_a = ctx.create_view(a, &desc, "alias a").expect("view a");
    let view_b = ctx.create_view(b, &desc, "alias b").expect("view b");
    let a = GpuImage::from_parts(a, view_a, desc, "alias a");
    let b = GpuImage::from_parts(b, view_b, desc, "alias b");

    clear_color(&ctx, &a, vk::ClearColorValue { uint32: [0; 4] });
    clear_color(
        &ctx,
        &b,
        vk::ClearColorValue {
            float32: [0.0, 0.0, 1.0, 1.0],
        },
    );
    let pixels_a = ctx
        .read_image(&a, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .expect("read a");
    let pixels_b = ctx
        .read_image(&b, vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        .expect("read b");
    assert!(pixels_a.iter().all(|&v| v == 0));
    assert!(pixels_b.chunks_exact(4).all(|px| px == [0, 0, 255, 255]));

    ctx.destroy_image(a);
    ctx.destroy_image(b);
    ctx.free_memory_block(block);
    assert_clean(&ctx);
}

#[test]
fn wrapped_context_leaves_host_handles_alive() {
    let host = context();
    {
        // SAFETY: the handles come from `host`, which outlives the wrapper and was created with
        // everything lucent needs; nothing else uses the queue meanwhile.
        let wrapped = unsafe {
            GpuContext::wrap(
                host.entry.clone(),
                host.instance.clone(),
                host.physical_device,
                host.device.clone(),
                host.queue,
                host.queue_family,
            )
        }
        .expect("wrap");
        assert!(!wrapped.validation_enabled());
        assert_eq!(wrapped.info.name, host.info.name);
        let data = [1.0f32, 2.0, 3.0, 4.0];
        let buffer = wrapped
            .upload_buffer(
                &data,
                vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
                "wrapped upload",
            )
            .expect("upload through the wrapper");
        let bytes = wrapped
            .read_buffer(&buffer)
            .expect("read through the wrapper");
        assert_eq!(bytemuck::cast_slice::<u8, f32>(&bytes), &data);
        wrapped.destroy_buffer(buffer);
        assert_clean(&wrapped);
    }
    // The host's device, queue and instance still work after the wrapper is gone.
    let buffer = host
        .upload_buffer(
            &[5u32; 16],
            vk::BufferUsageFlags::TRANSFER_SRC,
            "after wrap",
        )
        .expect("host still works");
    assert_eq!(
        bytemuck::cast_slice::<u8, u32>(&host.read_buffer(&buffer).expect("read")),
        &[5u32; 16]
    );
    host.destroy_buffer(buffer);
    assert_clean(&host);
}

/// Runs only inside a child process spawned by [`run_child`], whose environment hides every
/// Vulkan driver (`no-driver`) or the validation layer (`no-layer`).
#[test]
#[ignore = "spawned by no_driver_is_an_error and missing_validation_layer_is_an_error"]
fn environment_child() {
    let Ok(mode) = std::env::var(CHILD_MODE) else {
        return;
    };
    let outcome = |validation: bool| {
        let desc = ContextDesc {
            validation,
            ..desc(None)
        };
        GpuContext::new(&desc)
    };
    match mode.as_str() {
        "no-driver" => {
            for validation in [true, false] {
                match outcome(validation) {
                    Err(LucentError::NoVulkanDriver(detail)) => {
                        println!("validation {validation}: NoVulkanDriver{detail}")
                    }
                    other => panic!(
                        "expected NoVulkanDriver with validation {validation}, got {other:?}"
                    ),
                }
            }
        }
        "no-layer" => {
            match outcome(true) {
                Err(e @ LucentError::NoValidationLayer) => println!("NoValidationLayer: {e}"),
                other => panic!("expected NoValidationLayer, got {other:?}"),
            }
            // Without validation the layer is not needed.
            let ctx = outcome(false).expect("context without validation");
            assert!(!ctx.validation_enabled());
        }
        other => panic!("unknown child mode {other}"),
    }
    println!("CHILD_OK");
}

/// Runs [`environment_child`] in a child process with `mode` and extra environment `env`;
/// returns its stdout after checking it succeeded.
fn run_child(mode: &str, env: &[(&str, &str)]) -> String {
    let exe = std::env::current_exe().expect("test binary path");
    let mut command = std::process::Command::new(exe);
    command
        .args([
            "context::environment_child",
            "--exact",
            "--ignored",
            "--nocapture",
        ])
        .env(CHILD_MODE, mode)
        .envs(env.iter().copied());
    let output = command.output().expect("spawn the test binary");
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && stdout.contains("CHILD_OK"),
        "child '{mode}' failed ({}):\nstdout:\n{stdout}\nstderr:\n{stderr}",
        output.status
    );
    stdout
}

#[test]
fn no_driver_is_an_error() {
    let stdout = run_child(
        "no-driver",
        &[
            ("VK_ICD_FILENAMES", "/nonexistent.json"),
            ("VK_DRIVER_FILES", "/nonexistent.json"),
            ("VK_ADD_DRIVER_FILES", ""),
        ],
    );
    assert!(stdout.contains("NoVulkanDriver"), "{stdout}");
}

#[test]
fn missing_validation_layer_is_an_error() {
    let stdout = run_child(
        "no-layer",
        &[("VK_LAYER_PATH", "/nonexistent"), ("VK_ADD_LAYER_PATH", "")],
    );
    assert!(stdout.contains("NoValidationLayer"), "{stdout}");
}

/// The harness itself: a missing barrier between two clears of one image must be reported by
/// synchronization validation, or every "clean" result above would prove nothing.
#[test]
fn validation_catches_sync_hazards() {
    let ctx = context();
    let image = ctx
        .create_image(
            &ImageDesc::color(
                8,
                8,
                vk::Format::R8G8B8A8_UNORM,
                vk::ImageUsageFlags::TRANSFER_DST,
            ),
            "hazard target",
        )
        .expect("create image");
    ctx.submit_and_wait(|cmd| {
        to_transfer_dst(&ctx, cmd, &image);
        let color = vk::ClearColorValue { uint32: [0; 4] };
        let range = [image.desc.subresource_range()];
        // SAFETY: valid commands on a live image in TRANSFER_DST_OPTIMAL; the missing barrier
        // between them is a write-after-write hazard on purpose (harmless to the driver).
        unsafe {
            for _ in 0..2 {
                ctx.device.cmd_clear_color_image(
                    cmd,
                    image.image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &color,
                    &range,
                );
            }
        }
    })
    .expect("submit");
    ctx.destroy_image(image);
    assert!(
        ctx.validation_error_count() >= 1,
        "the hazard was not reported"
    );
    let messages = ctx.take_validation_messages();
    assert!(
        messages
            .iter()
            .any(|m| m.contains("SYNC-HAZARD-WRITE-AFTER-WRITE")),
        "{messages:#?}"
    );
}
