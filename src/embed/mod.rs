//! lucent inside a host Vulkan engine: the host's device, allocator, G-buffer, images and
//! command buffers, with frames in flight.
//!
//! The host owns everything Vulkan: instance, device, queues, swapchain, frame loop, fences and
//! command buffers. lucent borrows the device ([`Lucent::new`]), builds effects and renderers,
//! and records into the host's command buffers when asked:
//!
//! - [`SssEffect`]: screen-space SSS (the control, the separable blur, 2-D
//!   Burley) over the host's **own G-buffer**, described by [`GBufferDesc`]: its depth in any
//!   depth format, standard or reversed Z, finite or infinite far (decoded through the host's
//!   projection matrix, [`HostCamera`]) or as linear view depth; its lit diffuse with or
//!   without the albedo; its specular and albedo when it has them; its material IDs as
//!   `R8_UINT`/`R8_UNORM`, stencil bits or a bit field of a packed target; its world scale.
//!   lucent adapts by shader permutation and per-frame constants, not by copying into its own
//!   layout. Several views per frame (split screen, stereo).
//! - [`TranslucencyEffect`]: GDC 2011 thickness-based translucency added to the host's lit
//!   diffuse, lit by the host's lights ([`Light`]), on the same G-buffer with its normals
//!   ([`NormalDesc`]: world or view space, xyz or octahedral), albedo and local thickness
//!   ([`ThicknessDesc`]; [`bake_thickness`] bakes it per vertex of the host's mesh).
//! - [`EnvironmentEffect`]: lucent's SH environment light ([`Environment`]: constant,
//!   hemisphere, the built-in sky or a radiance map) added to the host's lit diffuse at each
//!   surface pixel's normal, times the albedo when the host's diffuse light has it.
//! - [`TransmissionEffect`]: screen-space SSS's transmission through thin parts of the
//!   materials with a medium ([`TransmissionMaterial`]), measured through the host's own
//!   shadow maps ([`ShadowFace`]).
//! - [`LayeredEffect`]: Li et al.'s layered media (transmitted light, single scattering along
//!   the refracted view ray, the dipole's multiple scattering) added to the host's lit
//!   diffuse; lucent draws its light-space maps from the host's own vertex and index buffers
//!   ([`VertexLayout`], [`MeshDraw`]) with the faces the host gives ([`ShadowFace`]), and
//!   reads layers' thicknesses from each mesh's depth textures where a medium asks.
//! - [`glsl::TERMS`]: the environment's, GDC 2011's and the transmission's terms as GLSL for
//!   the host's own lighting pass, with no pass of their own (docs/embedding.md measures
//!   what each costs there), and the LEAN texel a host's G-buffer pass writes for the LEAN
//!   blurs ([`LeanTargetsDesc`]).
//! - [`SceneRenderer`] (*whole frame*): a lucent [`Scene`] (the host's meshes handed over as
//!   [`crate::scene::Mesh`]es, transforms, lucent materials and lights) drawn into a host
//!   colour image with every feature its materials ask for (translucency, screen-space SSS,
//!   SSS transmission, layered media, shadows, the SH environment), tonemapped.
//!
//! Effects draw over the screen regions a host gives each frame ([`screen_region`] projects an
//! object's box), and time their passes only when recorded with `record_timed` and an
//! [`EffectTimer`].
//!
//! # The contract
//!
//! 1. **Before the device:** [`requirements`] says what lucent needs (Vulkan 1.3 with
//!    `synchronization2` and `maintenance4`, a queue family with graphics and compute; no
//!    device extension, no timestamps) and which optional features it uses when the host
//!    enabled them ([`OptionalFeatures`]); [`Requirements::check`] tests a physical device.
//! 2. **Construction** ([`Lucent::new`]) from the host's instance, physical device, device,
//!    queue and family, the number of frames in flight, optionally its pipeline cache and its
//!    memory: its `gpu-allocator` or its own allocator ([`HostAllocator`]) ([`EmbedOptions`]). lucent creates its own objects (pipelines, images,
//!    buffers, descriptor pools) and destroys only those; no handle of the host's is ever
//!    destroyed. No debug messenger is installed unless [`EmbedOptions::debug_messenger`]
//!    asks for one.
//! 3. **No waits, no submissions.** Building an effect or renderer records its uploads into a
//!    command buffer of the host's ([`Lucent::uploads`], [`Uploads`]); the host submits it
//!    with its own work and frees the staging memory once that submission completed
//!    ([`Uploads::release`]). Recording a frame submits nothing. No embed path waits on the
//!    host's device, queues or fences.
//! 4. **Host images** ([`HostImage`]) come with the format, size and usage they were created
//!    with, the state ([`ImageState`]: layout, stage, access) they are in, and each its own
//!    final state ([`HostImage::then`]; by default the state it came in). Everything lucent
//!    can check is checked before the first command (usage flags, layouts against usage and
//!    aspect, accesses against stages and layout, formats, sizes): a mistake is a typed
//!    [`HostError`] naming the input, not a validation error. Images are bound when a frame
//!    records: any number of different images over time, and a view recreated between frames
//!    (even one whose handle value is reused) is simply the next frame's.
//! 5. **Recording** (`record`) goes into the host's primary command buffer, in the recording
//!    state and outside any render pass the host began. lucent records its barriers from each
//!    image's declared state, its passes, and barriers to the final states. Afterwards the
//!    bound pipeline, descriptor sets, viewport and push constants are undefined: the host
//!    binds its own again.
//! 6. **Frames in flight:** every `record` names a frame slot `0..frames_in_flight` (and, for
//!    an effect with several views, a view); lucent keeps one set of per-frame parameters and
//!    descriptors per slot and view and writes them when that frame records, so the host must
//!    have waited for the previous frame recorded with that slot (its fence) first — the wait
//!    it does anyway before reusing that frame's command buffer.
//! 7. **Threads:** effects and renderers are `Send` (build them on a loader thread, record on
//!    the render thread); a `&Lucent` is shared by reference. Vulkan's own rules hold: a
//!    command buffer is recorded by one thread at a time.
//! 8. **Teardown:** `destroy` the effects and renderers, then drop the [`Lucent`], once the
//!    GPU is done with lucent's work (the host waits on its frames' fences). One dropped
//!    without `destroy` is logged as an error and counted ([`leaked`]): never silent.
//!    Resizing is rebuilding.
//!
//! # Example
//!
//! ```no_run
//! use lucent::embed::ash::vk;
//! use lucent::embed::glam::Mat4;
//! use lucent::embed::{
//!     DepthDesc, DiffuseDesc, EmbedOptions, GBufferDesc, HostCamera, HostDevice, HostImage,
//!     IdDesc, ImageState, Lucent, SssEffect, SssEffectDesc, SssFrame, SssImages, SssMaterial,
//!     SssProfile,
//! };
//!
//! # fn host_engine(host: HostDevice, setup: vk::CommandBuffer, cmd: vk::CommandBuffer,
//! #     depth: HostImage, lighting: HostImage, ids: HostImage, output: HostImage,
//! #     view: Mat4, projection: Mat4) -> lucent::Result<()> {
//! // (The host created its device after checking lucent::embed::requirements().)
//! // SAFETY: the host's handles are valid, belong together and outlive `lucent`.
//! let options = EmbedOptions { frames_in_flight: 2, ..Default::default() };
//! let lucent = unsafe { Lucent::new(host, options) }?;
//! // The host's G-buffer: reversed-Z D32 depth, lit diffuse with albedo, R8_UINT IDs, metres.
//! let gbuffer = GBufferDesc::new(
//!     1280,
//!     720,
//!     DepthDesc::device(vk::Format::D32_SFLOAT),
//!     DiffuseDesc::with_albedo(vk::Format::B10G11R11_UFLOAT_PACK32),
//! )
//! .with_material_ids(IdDesc::value(vk::Format::R8_UINT));
//! // The host's material 3 is skin.
//! let skin = SssMaterial::new(3, SssProfile::preset("skin")?);
//! let desc = SssEffectDesc::new(gbuffer, vec![skin], vk::Format::B10G11R11_UFLOAT_PACK32);
//! // Uploads go into the host's `setup` command buffer (recording); the host submits it.
//! let mut uploads = unsafe { lucent.uploads(setup) };
//! let mut sss = SssEffect::new(&lucent, &mut uploads, desc)?;
//! // ... end `setup`, submit it; once its fence has signalled:
//! unsafe { uploads.release(&lucent) }?;
//!
//! // Each frame: wait for slot k's fence, begin `cmd`, render the G-buffer and lighting, then
//! // say what state each image is in (and, for the output, the state to leave it in).
//! let depth = depth.in_state(ImageState::depth_attachment());
//! let lighting = lighting.in_state(ImageState::color_attachment());
//! let ids = ids.in_state(ImageState::color_attachment());
//! let output = output.then(ImageState::fragment_sampled());
//! let frame = SssFrame {
//!     slot: 0,
//!     view: 0,
//!     camera: HostCamera::new(view, projection),
//!     images: SssImages {
//!         depth: &depth,
//!         diffuse: &lighting,
//!         specular: None,
//!         albedo: None,
//!         material_ids: &ids,
//!     },
//!     regions: &[], // the whole screen (or the skin's projected bounds)
//!     output: &output,
//!     lean: None, // normals and lights, for LCB, LBB and the bilateral blur
//! };
//! sss.record(&lucent, cmd, &frame)?;
//! // ... the host's tonemap reads `output`; end `cmd`, submit it with its fence.
//! # sss.destroy(&lucent);
//! # Ok(()) }
//! ```
//!
//! `examples/host_engine.rs` is a complete small ash engine doing this: its own G-buffer pass
//! in formats lucent does not use itself, its own lighting and tonemap, and the effect between
//! them, with three frames in flight, under the validation layer.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use ash::vk;

pub use gpu_allocator;
use gpu_allocator::vulkan::Allocator;

use crate::backend::memory::MemorySource;
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::scene::Scene;
use crate::{LucentError, Result};

mod depth_textures;
mod environment;
pub mod glsl;
pub(crate) mod image;
mod layered;
pub(crate) mod passes;
pub(crate) mod regions;
mod scene;
mod shadow_faces;
mod sss;
mod timing;
mod translucency;
mod transmission;
mod uploads;

pub use crate::features::capabilities::{capabilities, Effect, Support};
pub use crate::features::gbuffer_desc::{
    DepthDesc, DepthEncoding, DiffuseAlbedo, DiffuseDesc, GBufferDesc, HostCamera, IdDesc,
    IdEncoding, LeanTargetsDesc, NormalDesc, NormalEncoding, NormalSpace, ThicknessChannels,
    ThicknessDesc, MAX_METRES_PER_UNIT,
};
pub use crate::features::sss::described::{SpecularSurface, SssEffectDesc, SssMaterial};
pub(crate) use environment::shader_permutations as environment_permutations;
pub use environment::{
    EnvironmentEffect, EnvironmentEffectDesc, EnvironmentFrame, EnvironmentImages,
};
pub use image::{HostImage, ImageState};
pub use layered::{
    IndexBuffer, LayeredEffect, LayeredEffectDesc, LayeredFrame, LayeredImages, LayeredMaterial,
    MeshDraw, VertexAttribute, VertexLayout,
};
pub use passes::EffectMemory;
pub use regions::{box_screen_region, screen_region};
pub use scene::SceneRenderer;
pub use shadow_faces::ShadowFace;
pub use sss::{
    LeanLighting, LeanSurface, LeanTargetImages, SssEffect, SssFrame, SssImages, SssRegion,
    MAX_VIEWS_PER_FRAME,
};
pub use timing::{EffectTimer, PassTime};
pub(crate) use translucency::shader_permutations as translucency_permutations;
pub use translucency::{
    bake_thickness, TranslucencyEffect, TranslucencyEffectDesc, TranslucencyFrame,
    TranslucencyImages, TranslucentMaterial,
};
pub(crate) use transmission::shader_permutations as transmission_permutations;
pub use transmission::{
    TransmissionEffect, TransmissionEffectDesc, TransmissionFrame, TransmissionImages,
    TransmissionMaterial,
};
pub use uploads::{leaked, Uploads};
// The types a host names in its descriptions, and the versions of the crates it must build its
// handles with.
pub use crate::backend::memory::{HostAllocation, HostAllocator, MemoryRequest, MemoryUse};
pub use crate::error::{HostError, ImageFault};
pub use crate::features::layered::{LayeredKnobs, PhaseForm, PIXEL_LIGHT_RANGE, STEP_RANGE};
pub use crate::features::sss::kernel::{KernelShape, SAMPLE_COUNTS};
pub use crate::features::sss::{SssKnobs, SssPrecision, DEFAULT_SENSITIVITY};
pub use crate::scene::layered::{Layer, LayeredMedium, Thickness};
pub use crate::scene::material::{Medium, PowMode, SssProfile, Texturing, Translucency};
pub use crate::scene::profile::BurleyFit;
pub use crate::scene::{Environment, Light, LightKind};
pub use ash;
pub use glam;

/// The embedding API's version: raised whenever a change to `lucent::embed` can break a host
/// that built against the previous one (the crate's own version says which release). 3: the
/// host's G-buffer described ([`GBufferDesc`]) and bound per frame ([`SssEffect`], replacing
/// `PostProcessSss`), uploads recorded into the host's command buffer ([`Uploads`]), typed
/// errors ([`HostError`]). 4: [`SssFrame::regions`] (the blurs' screen regions),
/// [`TranslucencyEffect`], [`capabilities`], [`EffectTimer`] and `record_timed`. 5:
/// [`EnvironmentEffect`], [`TransmissionEffect`] (with [`ShadowFace`]), [`glsl::TERMS`];
/// [`capabilities`] reports SSS transmission and the environment as effects that run. 6:
/// [`LayeredEffect`] (with [`VertexLayout`] and [`MeshDraw`]); `Support::NotEmbedded` is gone
/// (every effect of [`Effect::ALL`] has a path on a host's G-buffer). 7: the LEAN blurs (LCB,
/// LBB, bilateral) in [`SssEffect`] ([`SssFrame::lean`], [`SssMaterial::surface`],
/// [`SssEffectDesc::shadow_format`]), [`Effect::LeanSss`]; host shadow maps in reversed Z and
/// as arrays ([`ShadowFace::layer`], [`HostImage::layers`], `with_shadow_array`). 8:
/// [`SssFrame::regions`] per material ([`SssRegion`]): each blur chain runs on its own
/// materials' regions; [`SssMaterial::relights_specular`]. 9: SSS transmission in
/// [`glsl::TERMS`] (`lucent_sss_transmittance`, `lucent_sss_transmitted`) with
/// [`TransmissionMaterial::rows`] and the shadow-map lookup (`lucent_shadow_texels`,
/// [`ShadowFace::terms_rows`]); [`GBufferDesc::metres_per_unit`] at most
/// [`MAX_METRES_PER_UNIT`]; host images that are one mip level or layer of a larger image
/// ([`HostImage::at`]). 10: lucent's internal modules are crate-private in a build without
/// the `internals` feature (a host's `default-features = false`): a host names only
/// `lucent::embed` and what it re-exports (now also the knobs' value types: [`SssPrecision`],
/// [`KernelShape`], [`BurleyFit`] and their ranges), `scene`, `bake`, `images` and `error`;
/// each effect says what it holds in memory (`memory`, [`EffectMemory`]). 11: a host's G-buffer
/// pass may write the LEAN blurs' targets itself ([`GBufferDesc::with_lean_targets`],
/// [`LeanTargetsDesc`], the LEAN texel's functions in [`glsl::TERMS`]); [`LeanLighting`]'s
/// `normals` became `surface` ([`LeanSurface`]: the normals or the [`LeanTargetImages`]). 12:
/// [`crate::LucentError`] is `#[non_exhaustive]` (a host matches it with a wildcard arm), and
/// a build that ships no SPIR-V says so (`LucentError::ShadersNotBuilt`); the TERMS function
/// `lucent_any_tangent_frame`. 13: a diffuse light with the albedo as each SSS material's
/// texturing asks ([`DiffuseAlbedo::AsTexturing`], [`DiffuseDesc::with_albedo_as_texturing`]),
/// a world scale per SSS material ([`SssMaterial::with_metres_per_unit`]);
/// [`Support::Lacks`] may hold [`HostError::Unsupported`]; a second shadow map, an array
/// beside an atlas (`with_second_shadow_map` of [`TransmissionEffectDesc`] and
/// [`SssEffectDesc`], [`TransmissionImages::second_shadow_map`],
/// [`LeanLighting::second_shadow_map`], [`ShadowFace::map`]); TERMS'
/// `lucent_shadow_texels` on a `sampler2DArray` too. 14: `OptionalFeatures::independent_blend`
/// is gone (no effect blends one target and overwrites another any more: the SSS chains add
/// their sum of Gaussians in the shader), and `requirements().optional` no longer lists it.
/// 15: a host's own allocator ([`EmbedOptions::memory`], [`HostAllocator`]), errors
/// `LucentError::HostAllocation` and [`HostError::Memory`]; a failed build leaves its
/// [`Uploads`]' command buffer valid to submit; [`LayeredEffect`] takes media whose layers
/// read depth textures ([`LayeredImages::layer_depths`], a new field of a frame struct;
/// [`GBufferDesc::with_layer_depths`], [`VertexLayout::with_uv`],
/// [`MeshDraw::with_depth_textures`], TERMS' `lucent_pack_layer_texels`).
pub const API_VERSION: u32 = 15;

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
    /// What the queue lucent records for must support: graphics and compute. (Timestamps are
    /// not needed: the effects time nothing unless a host asks lucent's timer to.)
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
            "hostQueryReset (Vulkan 1.2): timer queries reset from the CPU (lucent's timer only)",
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
    /// shared for every buffer and image lucent creates. `None` (and no [`Self::memory`]):
    /// lucent's own allocator.
    pub allocator: Option<Arc<Mutex<Allocator>>>,
    /// The host's own allocator (VMA behind it, or the engine's own): every buffer's and
    /// image's memory comes from it and goes back to it ([`HostAllocator`]). Not together
    /// with [`Self::allocator`]. `None`: the shared `gpu-allocator` or lucent's own.
    pub memory: Option<Arc<dyn HostAllocator>>,
    /// Where lucent keeps what it caches between runs (the thickness bake; shaders come
    /// compiled with the crate):
    /// a directory the host chooses. `None`: the platform's per-user cache
    /// (`crate::files::default_cache_dir`: `$LUCENT_CACHE_DIR`, else e.g.
    /// `~/.cache/lucent`), never the source tree.
    pub cache_dir: Option<PathBuf>,
    /// Install lucent's own debug messenger on the host's instance (when it has
    /// `VK_EXT_debug_utils`), so `crate::backend::GpuContext::validation_error_count` counts
    /// the messages the layers send while lucent is alive. Off by default: a host with its own
    /// messenger would see every message twice, and lucent's count would include the host's.
    pub debug_messenger: bool,
}

/// lucent on a host's device: the wrapped context, the shaders and the pipeline cache every
/// renderer built from it shares.
pub struct Lucent {
    id: u64,
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
        let memory = match (options.allocator, options.memory) {
            (Some(_), Some(_)) => {
                return Err(crate::HostError::Description {
                    field: "EmbedOptions::memory".into(),
                    problem: "given together with EmbedOptions::allocator: lucent takes its \
                              memory from one allocator, the host's gpu-allocator or its own"
                        .into(),
                }
                .into())
            }
            (Some(shared), None) => Some(MemorySource::gpu_allocator(shared)),
            (None, Some(own)) => Some(MemorySource::host(own)),
            (None, None) => None,
        };
        let enabled = host.enabled;
        // SAFETY: the caller's contract covers wrap's.
        let mut gpu = unsafe {
            GpuContext::wrap_with_memory(
                host.entry,
                host.instance,
                host.physical_device,
                host.device,
                host.queue,
                host.queue_family,
                memory,
                options.debug_messenger,
            )
        }?;
        gpu.info.host_query_reset = enabled.host_query_reset;
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
            id: uploads::next_lucent_id(),
            gpu,
            shaders,
            pipeline_cache,
            owns_pipeline_cache,
            frames_in_flight,
            cache_dir,
        })
    }

    /// The wrapped context (for lucent's lower layers, debug names, validation counts).
    pub(crate) fn gpu(&self) -> &GpuContext {
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

    /// Begins recording renderers' uploads into the host's command buffer `cmd` (see
    /// [`Uploads`]): lucent never submits on the host's queue itself.
    ///
    /// # Safety
    ///
    /// `cmd` is a primary command buffer of the host's device, in the recording state,
    /// outside any render pass, for a queue of the family lucent was given; nothing else
    /// records into it while a renderer is built with the returned uploads; the host submits it
    /// before the first frame that records those renderers (or records them after it, in the
    /// same command buffer).
    pub unsafe fn uploads(&self, cmd: vk::CommandBuffer) -> Uploads {
        // SAFETY: the caller's contract is Uploads::new's.
        unsafe { Uploads::new(self, cmd) }
    }

    pub(crate) fn id(&self) -> u64 {
        self.id
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
            Err(crate::HostError::OutOfRange {
                what: "frame slot",
                index: slot,
                count: self.frames_in_flight,
            }
            .into())
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
