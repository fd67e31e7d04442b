//! lucent inside a host Vulkan engine: the host's device, allocator, images and command
//! buffers, with frames in flight.
//!
//! The host owns everything Vulkan: instance, device, queue, swapchain, frame loop, fences and
//! command buffers. lucent borrows the device ([`Lucent::new`]), builds one of two renderers,
//! and records into the host's command buffer when asked:
//!
//! - [`SceneRenderer`] (*whole frame*): a lucent [`Scene`] — the host's meshes (handed over
//!   as [`crate::scene::Mesh`]es for lucent to upload), transforms, lucent materials and
//!   lights — drawn into a host colour image with every feature its materials ask for
//!   (translucency, screen-space SSS, layered media, shadows), tonemapped.
//! - [`PostProcessSss`] (*post-process*): screen-space SSS over the host's own lit diffuse,
//!   depth and per-pixel profile index, written into a host image (how Jimenez's
//!   `SeparableSSS.h` is integrated into an engine).
//!
//! # The contract
//!
//! 1. **Before the device:** [`requirements`] says what lucent needs (Vulkan 1.3 with
//!    `synchronization2` and `maintenance4`, a queue family with graphics, compute and
//!    timestamps; no device extension) and which optional features it uses when the host
//!    enabled them ([`OptionalFeatures`]); [`Requirements::check`] tests a physical device.
//! 2. **Construction** ([`Lucent::new`]) from the host's instance, physical device, device,
//!    queue and family, the number of frames in flight, optionally its pipeline cache and its
//!    `gpu-allocator` ([`EmbedOptions`]). lucent creates its own objects (pipelines, images,
//!    buffers, descriptor pools, one command pool for uploads) and destroys only those; no
//!    handle of the host's is ever destroyed.
//! 3. **Host images** ([`HostImage`]) come with the format, size and usage they were created
//!    with and the state ([`ImageState`]: layout, stage, access) they are in; the host also
//!    says the state each must be left in. Everything lucent can check is checked before the
//!    first command (usage flags, layouts against usage and aspect, accesses against stages and
//!    layout, formats, sizes): a mistake is an error naming the image, not a validation error.
//! 4. **Recording** (`record`) goes into the host's primary command buffer, in the recording
//!    state and outside any render pass the host began. lucent records its barriers from each
//!    image's declared state, its passes, and barriers to the final states the host asked
//!    for, and returns those states. Afterwards the bound pipeline, descriptor sets, viewport
//!    and push constants are undefined: the host binds its own again.
//! 5. **Frames in flight:** every `record` names a frame slot `0..frames_in_flight`; lucent
//!    keeps one set of per-frame parameters per slot and writes slot `k`'s when the frame
//!    for slot `k` is recorded, so the host must have waited for the previous frame recorded
//!    with slot `k` (its fence) first — the wait it does anyway before reusing that frame's
//!    command buffer. Transient images are shared by the slots; the frames' barriers order
//!    them on the queue.
//! 6. **No hidden submissions:** recording never submits. The one time lucent uses the queue
//!    is when a renderer is built: [`SceneRenderer::new`] and [`PostProcessSss::new`] upload
//!    (meshes, textures, tables) with one submission on the host's queue and wait for it.
//!    Call them where nothing else uses the queue (Vulkan requires external synchronization
//!    of queue access).
//! 7. **Teardown:** `destroy` the renderers, then drop the [`Lucent`], once the device is idle
//!    for lucent's work (the host waits on its frames' fences). Resizing is rebuilding.
//!
//! # Example
//!
//! ```no_run
//! use ash::vk;
//! use lucent::embed::{EmbedOptions, HostDevice, HostImage, ImageState, Lucent, SceneRenderer};
//!
//! # fn host_engine(host: HostDevice, cmd: vk::CommandBuffer, image: vk::Image, view: vk::ImageView)
//! #     -> lucent::Result<()> {
//! // (The host created its device after checking lucent::embed::requirements().)
//! // SAFETY: the host's handles are valid, belong together and outlive `lucent`.
//! let lucent = unsafe { Lucent::new(host, EmbedOptions { frames_in_flight: 2, ..Default::default() }) }?;
//! let scene = lucent.load_scene("cubes")?;
//! let mut renderer = SceneRenderer::new(&lucent, &scene, 320, 240, vk::Format::R8G8B8A8_UNORM)?;
//! let output = HostImage {
//!     name: "back buffer".into(),
//!     image,
//!     view,
//!     format: vk::Format::R8G8B8A8_UNORM,
//!     extent: vk::Extent2D { width: 320, height: 240 },
//!     usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
//!     state: ImageState::UNDEFINED,
//! };
//! // Each frame: wait for slot k's fence, begin `cmd`, then
//! let left_in = renderer.record(&lucent, cmd, 0, &scene, &output, ImageState::transfer_src())?;
//! assert_eq!(left_in, ImageState::transfer_src());
//! // ... end `cmd`, submit it with the host's semaphores and fence.
//! # renderer.destroy(&lucent);
//! # Ok(()) }
//! ```
//!
//! `examples/host_engine.rs` is a complete small ash engine doing this with three frames in
//! flight, under the validation layer.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use ash::vk;

pub use gpu_allocator;
use gpu_allocator::vulkan::Allocator;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::scene::Scene;
use crate::{LucentError, Result};

mod image;
mod post;
mod scene;

pub use image::{HostImage, ImageState};
pub use post::{
    PostProcessDesc, PostProcessFrame, PostProcessInputs, PostProcessSss, PostProcessStates,
};
pub use scene::SceneRenderer;

/// Most frames in flight a renderer keeps per-frame parameters for.
pub const MAX_FRAMES_IN_FLIGHT: usize = 8;

/// What lucent needs of a device, for a host to ask for before it creates its own.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Requirements {
    /// The Vulkan version the device (and instance) must support and be created with.
    pub api_version: u32,
    /// Device extensions lucent needs (none: a host that presents enables
    /// `VK_KHR_swapchain` for itself).
    pub device_extensions: Vec<&'static std::ffi::CStr>,
    /// Vulkan 1.3 features to enable: `synchronization2` (every barrier lucent records) and
    /// `maintenance4` (SPIR-V for Vulkan 1.3 needs it).
    pub vulkan13_features: Vec<&'static str>,
    /// What the queue lucent records for must support: graphics and compute, and
    /// timestamps (`timestampValidBits > 0`, lucent's per-pass timer).
    pub queue_flags: vk::QueueFlags,
    /// Features lucent uses when the host enabled them (and says so in [`OptionalFeatures`]).
    pub optional: Vec<&'static str>,
}

/// lucent's device requirements.
pub fn requirements() -> Requirements {
    Requirements {
        api_version: vk::API_VERSION_1_3,
        device_extensions: Vec::new(),
        vulkan13_features: vec!["synchronization2", "maintenance4"],
        queue_flags: vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE,
        optional: vec![
            "hostQueryReset (Vulkan 1.2): timer queries reset from the CPU",
            "independentBlend: per-target blend states",
            "shaderStorageImageWriteWithoutFormat: storage writes without a declared format",
        ],
    }
}

impl Requirements {
    /// The Vulkan 1.3 feature struct with what lucent needs set, to chain into the host's
    /// `VkDeviceCreateInfo` (merged with the host's own 1.3 features).
    pub fn vulkan13(&self) -> vk::PhysicalDeviceVulkan13Features<'static> {
        vk::PhysicalDeviceVulkan13Features::default()
            .synchronization2(true)
            .maintenance4(true)
    }

    /// Checks a physical device against the requirements; returns the first queue family
    /// that qualifies. Errors name the device and what it lacks.
    ///
    /// # Safety
    ///
    /// `physical_device` must be a valid handle enumerated from `instance`.
    pub unsafe fn check(
        &self,
        instance: &ash::Instance,
        physical_device: vk::PhysicalDevice,
    ) -> Result<u32> {
        crate::backend::device::probe_device(instance, physical_device, false)
            .map(|probe| probe.queue_family)
    }
}

/// Optional features the host enabled on its device (Vulkan cannot be asked which were
/// enabled); lucent uses each only when it is set here.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OptionalFeatures {
    /// `hostQueryReset` (Vulkan 1.2 features).
    pub host_query_reset: bool,
    /// `independentBlend` (core features).
    pub independent_blend: bool,
    /// `shaderStorageImageWriteWithoutFormat` (core features).
    pub storage_image_write_without_format: bool,
}

/// The host's Vulkan objects lucent borrows.
#[derive(Clone)]
pub struct HostDevice {
    /// The loader entry the host uses.
    pub entry: ash::Entry,
    /// The host's instance.
    pub instance: ash::Instance,
    /// The physical device the device was created from.
    pub physical_device: vk::PhysicalDevice,
    /// The host's device, created with [`requirements`] enabled.
    pub device: ash::Device,
    /// The queue lucent's frames are submitted to (by the host) and its uploads use.
    pub queue: vk::Queue,
    /// The queue's family (its pools and resources are created for it).
    pub queue_family: u32,
    /// What else the host enabled.
    pub enabled: OptionalFeatures,
}

/// How lucent runs inside the host.
#[derive(Clone, Default)]
pub struct EmbedOptions {
    /// Frames the host keeps in flight (1 to [`MAX_FRAMES_IN_FLIGHT`]; 0 means 2).
    pub frames_in_flight: usize,
    /// The host's pipeline cache, used for every pipeline lucent creates (never saved or
    /// destroyed by lucent). `None`: an in-memory cache of lucent's own.
    pub pipeline_cache: Option<vk::PipelineCache>,
    /// The host's `gpu-allocator` (the same version: [`gpu_allocator`] is re-exported),
    /// shared for every buffer and image lucent creates. `None`: lucent's own allocator.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    /// Where lucent keeps what it caches between runs (the thickness bake; shaders come
    /// compiled with the crate):
    /// a directory the host chooses. `None`: the platform's per-user cache
    /// ([`crate::files::default_cache_dir`]: `$LUCENT_CACHE_DIR`, else e.g.
    /// `~/.cache/lucent`), never the source tree.
    pub cache_dir: Option<PathBuf>,
}

/// lucent on a host's device: the wrapped context, the shaders and the pipeline cache every
/// renderer built from it shares.
pub struct Lucent {
    gpu: GpuContext,
    shaders: ShaderCompiler,
    pipeline_cache: PipelineCache,
    owns_pipeline_cache: bool,
    frames_in_flight: usize,
    cache_dir: PathBuf,
}

impl Lucent {
    /// Wraps the host's device (see the module docs for the contract). Checks the device
    /// against [`requirements`] and the queue family against its needs.
    ///
    /// # Safety
    ///
    /// - Every handle in `host` is valid, they belong together (the device was created from
    ///   the physical device of the instance, the queue from the family of the device) and
    ///   they outlive the returned value.
    /// - The device was created with [`requirements`]'s version and features enabled, and the
    ///   features in `host.enabled` really enabled.
    /// - A shared allocator (`options.allocator`) was created for this device; a pipeline
    ///   cache for this device.
    /// - The host synchronizes its use of the queue with lucent's uploads (see
    ///   [`SceneRenderer::new`]).
    pub unsafe fn new(host: HostDevice, options: EmbedOptions) -> Result<Self> {
        let frames_in_flight = match options.frames_in_flight {
            0 => 2,
            n @ 1..=MAX_FRAMES_IN_FLIGHT => n,
            n => {
                return Err(LucentError::InvalidInput(format!(
                    "{n} frames in flight: lucent keeps 1 to {MAX_FRAMES_IN_FLIGHT}"
                )))
            }
        };
        let enabled = host.enabled;
        // SAFETY: the caller's contract covers wrap's.
        let mut gpu = unsafe {
            GpuContext::wrap_with_allocator(
                host.entry,
                host.instance,
                host.physical_device,
                host.device,
                host.queue,
                host.queue_family,
                options.allocator,
            )
        }?;
        gpu.info.host_query_reset = enabled.host_query_reset;
        gpu.info.independent_blend = enabled.independent_blend;
        gpu.info.storage_image_write_without_format = enabled.storage_image_write_without_format;
        let cache_dir = options
            .cache_dir
            .unwrap_or_else(crate::files::default_cache_dir);
        // The SPIR-V built with the crate: no `glsl/`, no shaderc at run time.
        let shaders = ShaderCompiler::shipped()?;
        let (pipeline_cache, owns_pipeline_cache) = match options.pipeline_cache {
            Some(handle) if handle != vk::PipelineCache::null() => {
                (PipelineCache::borrowed(handle), false)
            }
            _ => (PipelineCache::load(&gpu.device, None)?, true),
        };
        Ok(Self {
            gpu,
            shaders,
            pipeline_cache,
            owns_pipeline_cache,
            frames_in_flight,
            cache_dir,
        })
    }

    /// The wrapped context (for lucent's lower layers, debug names, validation counts).
    pub fn gpu(&self) -> &GpuContext {
        &self.gpu
    }

    /// Frames in flight every renderer built from this keeps.
    pub fn frames_in_flight(&self) -> usize {
        self.frames_in_flight
    }

    /// The directory lucent caches in.
    pub fn cache_dir(&self) -> &Path {
        &self.cache_dir
    }

    /// Loads a scene by built-in name or `.toml` path and prepares its thickness (the bake
    /// cached under [`Self::cache_dir`]). CPU work only.
    pub fn load_scene(&self, name_or_path: &str) -> Result<Scene> {
        let mut scene = crate::scene::load_scene(name_or_path)?;
        self.prepare_scene(&mut scene)?;
        Ok(scene)
    }

    /// Prepares a scene the host built (its own meshes and materials) for rendering: the
    /// GDC 2011 thickness of its translucent meshes, baked once and cached under
    /// [`Self::cache_dir`]. CPU work only.
    pub fn prepare_scene(&self, scene: &mut Scene) -> Result<()> {
        crate::bake::scene::prepare_thickness(scene, &self.cache_dir.join("thickness"))
    }

    pub(crate) fn shaders(&self) -> &ShaderCompiler {
        &self.shaders
    }

    pub(crate) fn pipeline_cache(&self) -> &PipelineCache {
        &self.pipeline_cache
    }

    /// Checks a frame slot against the frames in flight.
    pub(crate) fn check_slot(&self, slot: usize) -> Result<()> {
        if slot < self.frames_in_flight {
            Ok(())
        } else {
            Err(LucentError::InvalidInput(format!(
                "frame slot {slot}: lucent was built for {} frame(s) in flight (slots 0..{})",
                self.frames_in_flight, self.frames_in_flight
            )))
        }
    }
}

impl Drop for Lucent {
    fn drop(&mut self) {
        if self.owns_pipeline_cache {
            // SAFETY: every renderer built from this was destroyed first (their `destroy`
            // takes `&Lucent`), so no pipeline creation uses the cache.
            unsafe {
                self.gpu
                    .device
                    .destroy_pipeline_cache(self.pipeline_cache.handle, None)
            };
        }
    }
}
