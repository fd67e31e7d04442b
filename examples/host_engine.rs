//! A small ash "engine" that embeds lucent, the way a host engine would.
//!
//! The engine owns everything Vulkan: its instance (with the Khronos validation layer and
//! synchronization validation when the layer is installed), its device (created with what
//! `lucent::embed::requirements()` asks for), its `gpu-allocator` (shared with lucent), its
//! pipeline cache, and a frame loop with three frames in flight, each with its own command
//! buffer, fence and output image. lucent records the scene into the engine's command buffer
//! each frame and leaves the image in the state the engine asks for; the engine submits,
//! and at the end copies the last frame's image to a buffer and writes it as PNG.
//!
//! ```sh
//! cargo run --release --example host_engine -- --scene cubes --size 320x240 --frames 6 --out f.png
//! ```
//!
//! Exits non-zero when anything fails, including any validation error (counted by the
//! engine's own debug messenger).

use std::ffi::{c_void, CStr};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use lucent::embed::gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use lucent::embed::gpu_allocator::MemoryLocation;
use lucent::embed::{
    requirements, EmbedOptions, HostDevice, HostImage, ImageState, Lucent, OptionalFeatures,
    SceneRenderer,
};

/// Frames the engine keeps in flight.
const FRAMES_IN_FLIGHT: usize = 3;
/// The format of the engine's output images.
const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

static VALIDATION_ERRORS: AtomicU32 = AtomicU32::new(0);

struct Args {
    scene: String,
    width: u32,
    height: u32,
    frames: usize,
    out: PathBuf,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        scene: "cubes".into(),
        width: 320,
        height: 240,
        frames: 6,
        out: PathBuf::from("host_engine.png"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--scene" => args.scene = value()?,
            "--size" => {
                let v = value()?;
                let (w, h) = v
                    .split_once('x')
                    .ok_or(format!("--size {v}: expected WIDTHxHEIGHT"))?;
                args.width = w.parse().map_err(|_| format!("--size {v}: bad width"))?;
                args.height = h.parse().map_err(|_| format!("--size {v}: bad height"))?;
            }
            "--frames" => {
                let v = value()?;
                args.frames = v
                    .parse()
                    .map_err(|_| format!("--frames {v}: not a count"))?;
                if args.frames == 0 {
                    return Err("--frames must be at least 1".into());
                }
            }
            "--out" => args.out = PathBuf::from(value()?),
            "--help" | "-h" => return Err(
                "usage: host_engine [--scene NAME|FILE] [--size WxH] [--frames N] [--out F.png]"
                    .into(),
            ),
            other => return Err(format!("unknown argument {other}")),
        }
    }
    Ok(args)
}

unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        VALIDATION_ERRORS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the loader passes valid callback data whose message is a C string.
        let message = unsafe { (*data).message_as_c_str() }
            .map(|m| m.to_string_lossy().into_owned())
            .unwrap_or_default();
        eprintln!("host_engine: validation error: {message}");
    }
    vk::FALSE
}

/// The engine's Vulkan objects.
struct Engine {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    physical_device: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    enabled: OptionalFeatures,
    validation: bool,
}

fn create_engine() -> Result<Engine, String> {
    // SAFETY: loading the system's Vulkan loader.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader: {e}"))?;
    let layer = c"VK_LAYER_KHRONOS_validation";
    // SAFETY: plain queries of the loader.
    let validation = unsafe { entry.enumerate_instance_layer_properties() }
        .map_err(|e| format!("vkEnumerateInstanceLayerProperties: {e}"))?
        .iter()
        .any(|l| l.layer_name_as_c_str() == Ok(layer));
    let app = vk::ApplicationInfo::default()
        .application_name(c"host_engine")
        .api_version(requirements().api_version);
    let layers = if validation {
        vec![layer.as_ptr()]
    } else {
        vec![]
    };
    let extensions = if validation {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if validation {
        info = info.push_next(&mut features);
    }
    // SAFETY: every pointer in `info` refers to locals that outlive the call.
    let instance = unsafe { entry.create_instance(&info, None) }
        .map_err(|e| format!("vkCreateInstance: {e}"))?;
    let debug = if validation {
        let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE
                    | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
            )
            .pfn_user_callback(Some(on_message));
        // SAFETY: the instance enabled VK_EXT_debug_utils.
        let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
            .map_err(|e| format!("vkCreateDebugUtilsMessengerEXT: {e}"))?;
        Some((loader, messenger))
    } else {
        None
    };

    // The first device lucent's requirements accept.
    let needs = requirements();
    // SAFETY: plain query of the instance.
    let devices = unsafe { instance.enumerate_physical_devices() }
        .map_err(|e| format!("vkEnumeratePhysicalDevices: {e}"))?;
    let mut refusals = Vec::new();
    let mut picked = None;
    for pd in devices {
        // SAFETY: `pd` was enumerated from `instance`.
        match unsafe { needs.check(&instance, pd) } {
            Ok(family) => {
                picked = Some((pd, family));
                break;
            }
            Err(e) => refusals.push(e.to_string()),
        }
    }
    let (physical_device, queue_family) = picked.ok_or(format!(
        "no device meets lucent's requirements: {refusals:?}"
    ))?;

    // lucent's required features, plus the optional ones it uses when the device has them.
    // SAFETY: plain queries of a device of this instance.
    let (supported, supported12) = unsafe {
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut v12);
        instance.get_physical_device_features2(physical_device, &mut features2);
        (features2.features, v12.host_query_reset)
    };
    let enabled = OptionalFeatures {
        host_query_reset: supported12 == vk::TRUE,
        independent_blend: supported.independent_blend == vk::TRUE,
        storage_image_write_without_format: supported.shader_storage_image_write_without_format
            == vk::TRUE,
    };
    let core = vk::PhysicalDeviceFeatures::default()
        .independent_blend(enabled.independent_blend)
        .shader_storage_image_write_without_format(enabled.storage_image_write_without_format);
    let mut v12 =
        vk::PhysicalDeviceVulkan12Features::default().host_query_reset(enabled.host_query_reset);
    let mut v13 = needs.vulkan13();
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut v12)
        .push_next(&mut v13);
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let extensions: Vec<*const std::ffi::c_char> =
        needs.device_extensions.iter().map(|e| e.as_ptr()).collect();
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&extensions)
        .push_next(&mut features2);
    // SAFETY: the features were reported as supported; pointers refer to live locals.
    let device = unsafe { instance.create_device(physical_device, &info, None) }
        .map_err(|e| format!("vkCreateDevice: {e}"))?;
    // SAFETY: one queue of this family was requested.
    let queue = unsafe { device.get_device_queue(queue_family, 0) };
    Ok(Engine {
        entry,
        instance,
        debug,
        physical_device,
        device,
        queue,
        queue_family,
        enabled,
        validation,
    })
}

/// One frame in flight: its command pool and buffer, its fence, and the image it renders
/// into (the engine's stand-in for a swapchain image) with the state the engine tracks.
struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    image: vk::Image,
    view: vk::ImageView,
    memory: Option<Allocation>,
    state: ImageState,
}

fn check(what: &str, r: Result<(), vk::Result>) -> Result<(), String> {
    r.map_err(|e| format!("{what}: {e}"))
}

fn create_slot(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    width: u32,
    height: u32,
    index: usize,
) -> Result<FrameSlot, String> {
    let device = &engine.device;
    // SAFETY: plain object creation on the engine's device; every handle is destroyed in
    // `destroy_slot`.
    unsafe {
        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER)
                    .queue_family_index(engine.queue_family),
                None,
            )
            .map_err(|e| format!("vkCreateCommandPool: {e}"))?;
        let cmd = device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
            .map_err(|e| format!("vkAllocateCommandBuffers: {e}"))?[0];
        let fence = device
            .create_fence(
                &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                None,
            )
            .map_err(|e| format!("vkCreateFence: {e}"))?;
        let image = device
            .create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(FORMAT)
                    .extent(vk::Extent3D {
                        width,
                        height,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::OPTIMAL)
                    .usage(
                        vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
                    ),
                None,
            )
            .map_err(|e| format!("vkCreateImage: {e}"))?;
        let requirements = device.get_image_memory_requirements(image);
        let memory = allocator
            .lock()
            .map_err(|_| "allocator lock poisoned".to_string())?
            .allocate(&AllocationCreateDesc {
                name: &format!("host output {index}"),
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| format!("allocate output image: {e}"))?;
        check(
            "vkBindImageMemory",
            device.bind_image_memory(image, memory.memory(), memory.offset()),
        )?;
        let view = device
            .create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(FORMAT)
                    .subresource_range(vk::ImageSubresourceRange {
                        aspect_mask: vk::ImageAspectFlags::COLOR,
                        base_mip_level: 0,
                        level_count: 1,
                        base_array_layer: 0,
                        layer_count: 1,
                    }),
                None,
            )
            .map_err(|e| format!("vkCreateImageView: {e}"))?;
        Ok(FrameSlot {
            pool,
            cmd,
            fence,
            image,
            view,
            memory: Some(memory),
            state: ImageState::UNDEFINED,
        })
    }
}

fn destroy_slot(engine: &Engine, allocator: &Mutex<Allocator>, mut slot: FrameSlot) {
    // SAFETY: the device is idle (the caller waited) and the handles are the slot's own.
    unsafe {
        engine.device.destroy_image_view(slot.view, None);
        engine.device.destroy_image(slot.image, None);
        engine.device.destroy_fence(slot.fence, None);
        engine.device.destroy_command_pool(slot.pool, None);
    }
    if let (Some(memory), Ok(mut allocator)) = (slot.memory.take(), allocator.lock()) {
        if let Err(e) = allocator.free(memory) {
            eprintln!("host_engine: freeing an output image: {e}");
        }
    }
}

/// Copies `slot`'s image (in TRANSFER_SRC_OPTIMAL, as lucent left it) to host memory.
fn read_back(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    slot: &FrameSlot,
    width: u32,
    height: u32,
) -> Result<Vec<u8>, String> {
    let device = &engine.device;
    let bytes = u64::from(width) * u64::from(height) * 4;
    // SAFETY: objects of the engine's device; the copy is waited for before the buffer is
    // read and everything is destroyed after.
    unsafe {
        let buffer = device
            .create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(bytes)
                    .usage(vk::BufferUsageFlags::TRANSFER_DST),
                None,
            )
            .map_err(|e| format!("vkCreateBuffer: {e}"))?;
        let memory = allocator
            .lock()
            .map_err(|_| "allocator lock poisoned".to_string())?
            .allocate(&AllocationCreateDesc {
                name: "host read-back",
                requirements: device.get_buffer_memory_requirements(buffer),
                location: MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| format!("allocate read-back buffer: {e}"))?;
        check(
            "vkBindBufferMemory",
            device.bind_buffer_memory(buffer, memory.memory(), memory.offset()),
        )?;
        let cmd = slot.cmd;
        check(
            "vkResetCommandBuffer",
            device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()),
        )?;
        check(
            "vkBeginCommandBuffer",
            device.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default()),
        )?;
        device.cmd_copy_image_to_buffer(
            cmd,
            slot.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                })],
        );
        let to_host = [vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)];
        device.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().memory_barriers(&to_host),
        );
        check("vkEndCommandBuffer", device.end_command_buffer(cmd))?;
        check("vkResetFences", device.reset_fences(&[slot.fence]))?;
        let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
        check(
            "vkQueueSubmit2",
            device.queue_submit2(engine.queue, &[submit], slot.fence),
        )?;
        check(
            "vkWaitForFences",
            device.wait_for_fences(&[slot.fence], true, u64::MAX),
        )?;
        let pixels = memory
            .mapped_slice()
            .ok_or("the read-back buffer is not mapped")?[..bytes as usize]
            .to_vec();
        device.destroy_buffer(buffer, None);
        if let Ok(mut allocator) = allocator.lock() {
            allocator.free(memory).map_err(|e| e.to_string())?;
        }
        Ok(pixels)
    }
}

fn run(args: &Args, engine: &Engine) -> Result<(), String> {
    let device = &engine.device;
    // The engine's allocator, shared with lucent.
    let allocator = Arc::new(Mutex::new(
        Allocator::new(&AllocatorCreateDesc {
            instance: engine.instance.clone(),
            device: device.clone(),
            physical_device: engine.physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| format!("gpu-allocator: {e}"))?,
    ));
    // SAFETY: plain object creation.
    let pipeline_cache =
        unsafe { device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }
            .map_err(|e| format!("vkCreatePipelineCache: {e}"))?;
    let host = HostDevice {
        entry: engine.entry.clone(),
        instance: engine.instance.clone(),
        physical_device: engine.physical_device,
        device: device.clone(),
        queue: engine.queue,
        queue_family: engine.queue_family,
        enabled: engine.enabled,
    };
    let options = EmbedOptions {
        frames_in_flight: FRAMES_IN_FLIGHT,
        pipeline_cache: Some(pipeline_cache),
        allocator: Some(allocator.clone()),
        cache_dir: None,
    };
    // SAFETY: the handles are the engine's, created together above, and outlive `lucent`
    // (dropped at the end of this function, before the engine is destroyed); nothing else
    // uses the queue while lucent uploads.
    let lucent = unsafe { Lucent::new(host, options) }.map_err(|e| e.to_string())?;
    let scene = lucent.load_scene(&args.scene).map_err(|e| e.to_string())?;
    let mut renderer = SceneRenderer::new(&lucent, &scene, args.width, args.height, FORMAT)
        .map_err(|e| e.to_string())?;
    let mut slots = Vec::with_capacity(FRAMES_IN_FLIGHT);
    for k in 0..FRAMES_IN_FLIGHT {
        slots.push(create_slot(engine, &allocator, args.width, args.height, k)?);
    }
    let extent = vk::Extent2D {
        width: args.width,
        height: args.height,
    };
    let mut result = Ok(());
    for frame in 0..args.frames {
        let k = frame % FRAMES_IN_FLIGHT;
        let slot = &mut slots[k];
        // SAFETY: the slot's own objects; the fence wait makes its command buffer and lucent's
        // slot-k parameters free to reuse.
        let recorded = unsafe {
            check(
                "vkWaitForFences",
                device.wait_for_fences(&[slot.fence], true, u64::MAX),
            )
            .and_then(|()| check("vkResetFences", device.reset_fences(&[slot.fence])))
            .and_then(|()| {
                check(
                    "vkResetCommandBuffer",
                    device.reset_command_buffer(slot.cmd, vk::CommandBufferResetFlags::empty()),
                )
            })
            .and_then(|()| {
                check(
                    "vkBeginCommandBuffer",
                    device.begin_command_buffer(
                        slot.cmd,
                        &vk::CommandBufferBeginInfo::default()
                            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                    ),
                )
            })
            .and_then(|()| {
                let output = HostImage {
                    name: format!("host output {k}"),
                    image: slot.image,
                    view: slot.view,
                    format: FORMAT,
                    extent,
                    usage: vk::ImageUsageFlags::COLOR_ATTACHMENT
                        | vk::ImageUsageFlags::TRANSFER_SRC,
                    state: slot.state,
                };
                renderer
                    .record(
                        &lucent,
                        slot.cmd,
                        k,
                        &scene,
                        &output,
                        ImageState::transfer_src(),
                    )
                    .map(|state| slot.state = state)
                    .map_err(|e| e.to_string())
            })
            .and_then(|()| check("vkEndCommandBuffer", device.end_command_buffer(slot.cmd)))
            .and_then(|()| {
                let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
                check(
                    "vkQueueSubmit2",
                    device.queue_submit2(engine.queue, &[submit], slot.fence),
                )
            })
        };
        if let Err(e) = recorded {
            result = Err(format!("frame {frame}: {e}"));
            break;
        }
    }
    // SAFETY: waits for every frame the engine submitted.
    let idle = unsafe { device.device_wait_idle() };
    if result.is_ok() {
        result = check("vkDeviceWaitIdle", idle).and_then(|()| {
            let last = &slots[(args.frames - 1) % FRAMES_IN_FLIGHT];
            let pixels = read_back(engine, &allocator, last, args.width, args.height)?;
            lucent::images::output::write_png_rgba8(&args.out, args.width, args.height, &pixels)
                .map_err(|e| e.to_string())
        });
    }
    renderer.destroy(&lucent);
    let lucent_errors = lucent.gpu().validation_error_count();
    drop(lucent);
    for slot in slots {
        destroy_slot(engine, &allocator, slot);
    }
    // SAFETY: lucent is gone and the device idle: nothing uses the cache.
    unsafe { device.destroy_pipeline_cache(pipeline_cache, None) };
    drop(allocator);
    if lucent_errors > 0 {
        result = result.and(Err(format!(
            "lucent's messenger counted {lucent_errors} validation error(s)"
        )));
    }
    result
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("host_engine: {e}");
            std::process::exit(2);
        }
    };
    let engine = match create_engine() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("host_engine: {e}");
            std::process::exit(1);
        }
    };
    // SAFETY: plain query of the physical device.
    let name = unsafe {
        engine
            .instance
            .get_physical_device_properties(engine.physical_device)
    }
    .device_name_as_c_str()
    .map(CStr::to_string_lossy)
    .map(|n| n.into_owned())
    .unwrap_or_default();
    eprintln!(
        "host_engine: {} on {name}, {}x{}, {} frames, {FRAMES_IN_FLIGHT} in flight, validation {}",
        args.scene,
        args.width,
        args.height,
        args.frames,
        if engine.validation {
            "on (synchronization validation included)"
        } else {
            "off (VK_LAYER_KHRONOS_validation is not installed)"
        }
    );
    let outcome = run(&args, &engine);
    // SAFETY: everything created from the device is gone (run destroyed it); the device is
    // idle.
    unsafe {
        let _ = engine.device.device_wait_idle();
        engine.device.destroy_device(None);
        if let Some((loader, messenger)) = &engine.debug {
            loader.destroy_debug_utils_messenger(*messenger, None);
        }
        engine.instance.destroy_instance(None);
    }
    let errors = VALIDATION_ERRORS.load(Ordering::Relaxed);
    match outcome {
        Ok(()) if errors == 0 => {
            eprintln!(
                "host_engine: wrote {} (0 validation errors)",
                args.out.display()
            );
        }
        Ok(()) => {
            eprintln!("host_engine: {errors} validation error(s)");
            std::process::exit(1);
        }
        Err(e) => {
            eprintln!("host_engine: {e} ({errors} validation error(s))");
            std::process::exit(1);
        }
    }
}
