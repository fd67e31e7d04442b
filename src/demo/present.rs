//! Putting frames on a window: surface, swapchain, and the per-frame submit and present.
//!
//! One frame is in flight at a time: the frame's fence is waited for before the next one is
//! recorded, which is what [`Renderer::update`] needs (the uniforms are written between frames)
//! and what makes every rebuild and resize safe (nothing is pending when objects are replaced).
//! Each frame records the renderer's whole frame (and, for a comparison view, the plain-lighting
//! renderer's frame and the comparison pass, [`super::compare`]), blits the result (RGBA8,
//! sRGB-encoded) onto the acquired swapchain image (a UNORM format, so the bytes are shown as
//! they are), draws the panel over it with egui-ash-renderer in a render pass of its own
//! (load, draw, store), and transitions it for presentation. egui's textures (the font atlas)
//! are uploaded before the frame is recorded (egui-ash-renderer submits and waits for its own
//! copies) and freed after the frame is done.
//!
//! Sizes: the swapchain follows the surface's current extent (or the window's size where the
//! surface leaves it to the application). A zero extent (a minimized window) creates no
//! swapchain at all: [`Presenter::is_zero_sized`] tells the caller to render nothing.
//! `OUT_OF_DATE` from acquire or present and `SUBOPTIMAL` ask for a recreate, which the caller
//! does before the next frame.
//!
//! Waits are bounded: acquiring an image gives up after [`ACQUIRE_TIMEOUT_NS`] and a frame after
//! [`FRAME_TIMEOUT_NS`], as errors, so a hung driver or display ends the demo instead of
//! hanging it. Device and surface loss arrive as [`LucentError::DeviceLost`] and
//! [`LucentError::SurfaceLost`].

use ash::vk;
use egui_ash_renderer::allocator::DefaultAllocator;

use crate::backend::timer::{GpuTimer, ScopeTime};
use crate::backend::GpuContext;
use crate::error::VkResultExt;
use crate::frame::Renderer;
use crate::{LucentError, Result};

use super::compare::Comparer;
use super::controls::Comparison;

/// Longest wait for a swapchain image, nanoseconds.
pub const ACQUIRE_TIMEOUT_NS: u64 = 5_000_000_000;
/// Longest wait for one frame to finish on the GPU, nanoseconds (a huge scene on a CPU driver
/// takes seconds; a minute means something is stuck).
pub const FRAME_TIMEOUT_NS: u64 = 60_000_000_000;

/// What a frame did.
///
/// (With isolated timing the caller renders the frame pass by pass before [`Presenter::draw`];
/// `passes` is then empty.)
#[derive(Debug)]
pub enum Drawn {
    /// Presented. `passes`: the GPU times of its passes (in-frame timestamps); `stale`: the
    /// swapchain should be recreated before the next frame (SUBOPTIMAL or OUT_OF_DATE at present).
    Presented {
        /// Per physical pass, milliseconds.
        passes: Vec<ScopeTime>,
        /// Recreate before the next frame.
        stale: bool,
    },
    /// Nothing was drawn: the swapchain is out of date (recreate and try again).
    OutOfDate,
}

/// The panel of one frame: egui's triangles (its texture changes go through
/// [`Presenter::queue_textures`]).
pub struct UiFrame {
    /// What to draw, in points.
    pub primitives: Vec<egui::ClippedPrimitive>,
    /// Pixels per point.
    pub pixels_per_point: f32,
}

/// What one frame puts on the window.
pub struct FrameInput<'a> {
    /// The frame with the current technique.
    pub renderer: &'a Renderer,
    /// Record that frame here (false: the caller rendered it already, pass by pass, for
    /// isolated timing).
    pub render: bool,
    /// A comparison view: the plain-lighting renderer (same view and size), the comparison
    /// pass, and what it shows. Its frame is recorded here, untimed.
    pub compare: Option<(&'a Renderer, &'a mut Comparer, Comparison)>,
    /// The panel, drawn over the frame.
    pub ui: Option<UiFrame>,
}

/// The window's surface, its swapchain, and what a frame needs to reach it.
pub struct Presenter {
    surface_fn: ash::khr::surface::Instance,
    swapchain_fn: ash::khr::swapchain::Device,
    surface: vk::SurfaceKHR,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    format: vk::SurfaceFormatKHR,
    /// The swapchain's size (0 x 0 while there is none).
    pub extent: vk::Extent2D,
    /// The present mode in use.
    pub present_mode: vk::PresentModeKHR,
    vsync: bool,
    acquired: vk::Semaphore,
    /// One per swapchain image: presentation waits on it, and a semaphore may only be signalled
    /// again once the presentation that waited on it is known to be done (it is, once the same
    /// image was acquired again).
    rendered: Vec<vk::Semaphore>,
    /// One view and framebuffer per swapchain image, for the panel's render pass.
    views: Vec<vk::ImageView>,
    framebuffers: Vec<vk::Framebuffer>,
    /// The panel's render pass (one colour attachment in the swapchain's format: load, store)
    /// and the format it was made for.
    render_pass: vk::RenderPass,
    render_pass_format: vk::Format,
    /// Draws the panel; created with the first render pass.
    egui: Option<egui_ash_renderer::Renderer<DefaultAllocator>>,
    /// egui-ash-renderer's texture uploads allocate their command buffers here.
    upload_pool: vk::CommandPool,
    /// egui's texture changes not applied yet: new textures go in before the next frame that
    /// is drawn, freed ones after it.
    textures: egui::TexturesDelta,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timer: Option<(GpuTimer, u32)>,
}

impl Presenter {
    /// Takes ownership of `surface` (created on `gpu`'s instance) and creates a swapchain of
    /// `wanted` size (used where the surface lets the application choose).
    pub fn new(
        gpu: &GpuContext,
        surface: vk::SurfaceKHR,
        wanted: (u32, u32),
        vsync: bool,
    ) -> Result<Self> {
        let surface_fn = ash::khr::surface::Instance::new(&gpu.entry, &gpu.instance);
        // SAFETY: the surface belongs to this instance; the family index is the context's.
        let supported = unsafe {
            surface_fn.get_physical_device_surface_support(
                gpu.physical_device,
                gpu.queue_family,
                surface,
            )
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR");
        match supported {
            Ok(true) => {}
            Ok(false) | Err(_) => {
                // SAFETY: the surface is ours now and unused.
                unsafe { surface_fn.destroy_surface(surface, None) };
                return Err(supported
                    .err()
                    .unwrap_or_else(|| LucentError::MissingFeature {
                        device: gpu.info.name.clone(),
                        feature: "presenting to this window from its graphics queue family".into(),
                    }));
            }
        }
        let swapchain_fn = ash::khr::swapchain::Device::new(&gpu.instance, &gpu.device);
        let mut presenter = Self {
            surface_fn,
            swapchain_fn,
            surface,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            extent: vk::Extent2D::default(),
            present_mode: vk::PresentModeKHR::FIFO,
            vsync,
            acquired: vk::Semaphore::null(),
            rendered: Vec::new(),
            views: Vec::new(),
            framebuffers: Vec::new(),
            render_pass: vk::RenderPass::null(),
            render_pass_format: vk::Format::UNDEFINED,
            egui: None,
            upload_pool: vk::CommandPool::null(),
            textures: egui::TexturesDelta::default(),
            pool: vk::CommandPool::null(),
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
            timer: None,
        };
        // From here on `destroy` cleans up whatever exists.
        match presenter
            .create_sync(gpu)
            .and_then(|()| presenter.recreate(gpu, wanted))
        {
            Ok(()) => Ok(presenter),
            Err(e) => {
                presenter.destroy(gpu);
                Err(e)
            }
        }
    }

    fn create_sync(&mut self, gpu: &GpuContext) -> Result<()> {
        let device = &gpu.device;
        // SAFETY: valid device and create infos; each object is destroyed in `destroy`.
        unsafe {
            self.acquired = device
                .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
                .vk("vkCreateSemaphore")?;
            let transient_pool = || {
                device
                    .create_command_pool(
                        &vk::CommandPoolCreateInfo::default()
                            .queue_family_index(gpu.queue_family)
                            .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                        None,
                    )
                    .vk("vkCreateCommandPool")
            };
            self.pool = transient_pool()?;
            self.upload_pool = transient_pool()?;
            self.cmd = device
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(self.pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(1),
                )
                .vk("vkAllocateCommandBuffers")?[0];
            self.fence = device
                .create_fence(&vk::FenceCreateInfo::default(), None)
                .vk("vkCreateFence")?;
        }
        gpu.set_name(self.acquired, "demo image acquired");
        gpu.set_name(self.cmd, "demo frame");
        Ok(())
    }

    /// Whether the surface has no area (minimized): there is no swapchain, draw nothing.
    pub fn is_zero_sized(&self) -> bool {
        self.swapchain == vk::SwapchainKHR::null()
    }

    /// The swapchain's format.
    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    /// (Re)creates the swapchain for the surface's current size (`wanted` where the surface
    /// lets the application choose). A zero size leaves no swapchain. The GPU is idle after it.
    pub fn recreate(&mut self, gpu: &GpuContext, wanted: (u32, u32)) -> Result<()> {
        gpu.wait_idle()?;
        let pd = gpu.physical_device;
        // SAFETY: plain queries of a surface of this instance.
        let (caps, formats, modes) = unsafe {
            (
                self.surface_fn
                    .get_physical_device_surface_capabilities(pd, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?,
                self.surface_fn
                    .get_physical_device_surface_formats(pd, self.surface)
                    .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?,
                self.surface_fn
                    .get_physical_device_surface_present_modes(pd, self.surface)
                    .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?,
            )
        };
        let extent = if caps.current_extent.width == u32::MAX {
            // The surface takes the swapchain's size: the window's.
            vk::Extent2D {
                width: wanted
                    .0
                    .clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: wanted
                    .1
                    .clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        } else {
            caps.current_extent
        };
        let extent = if wanted.0 == 0 || wanted.1 == 0 {
            vk::Extent2D::default()
        } else {
            extent
        };
        self.destroy_framebuffers(gpu);
        let old = std::mem::replace(&mut self.swapchain, vk::SwapchainKHR::null());
        self.images.clear();
        self.extent = vk::Extent2D::default();
        if extent.width == 0 || extent.height == 0 {
            // Minimized: a swapchain cannot have a zero size; frames are skipped until it grows.
            if old != vk::SwapchainKHR::null() {
                // SAFETY: the device is idle, so no image of `old` is in use.
                unsafe { self.swapchain_fn.destroy_swapchain(old, None) };
            }
            return Ok(());
        }
        let usage = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(LucentError::MissingFeature {
                device: gpu.info.name.clone(),
                feature: "swapchain images that can be a transfer destination and a colour \
                          attachment"
                    .into(),
            });
        }
        self.format = pick_format(&formats).ok_or_else(|| LucentError::MissingFeature {
            device: gpu.info.name.clone(),
            feature: "any surface format".into(),
        })?;
        self.present_mode = pick_present_mode(&modes, self.vsync);
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let alpha = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|a| caps.supported_composite_alpha.contains(*a))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(count)
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(alpha)
            .present_mode(self.present_mode)
            .clipped(true)
            .old_swapchain(old);
        // SAFETY: the create info refers to this surface and locals; `old` (retired by this
        // call) is destroyed right after, with the device idle.
        let created = unsafe { self.swapchain_fn.create_swapchain(&info, None) };
        if old != vk::SwapchainKHR::null() {
            // SAFETY: as above.
            unsafe { self.swapchain_fn.destroy_swapchain(old, None) };
        }
        self.swapchain = created.vk("vkCreateSwapchainKHR")?;
        // SAFETY: the swapchain was just created.
        self.images = unsafe { self.swapchain_fn.get_swapchain_images(self.swapchain) }
            .vk("vkGetSwapchainImagesKHR")?;
        self.extent = extent;
        self.create_framebuffers(gpu)?;
        while self.rendered.len() < self.images.len() {
            // SAFETY: valid device; destroyed in `destroy`.
            let semaphore = unsafe {
                gpu.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .vk("vkCreateSemaphore")?;
            gpu.set_name(semaphore, &format!("demo rendered {}", self.rendered.len()));
            self.rendered.push(semaphore);
        }
        log::info!(
            "swapchain {}x{} {:?} {:?}, {} images",
            extent.width,
            extent.height,
            self.format.format,
            self.present_mode,
            self.images.len()
        );
        Ok(())
    }

    /// The panel's render pass for the swapchain's format (made again when the format
    /// changes), egui's renderer for it, and one view and framebuffer per swapchain image.
    fn create_framebuffers(&mut self, gpu: &GpuContext) -> Result<()> {
        let device = &gpu.device;
        if self.render_pass_format != self.format.format {
            let attachments = [vk::AttachmentDescription::default()
                .format(self.format.format)
                .samples(vk::SampleCountFlags::TYPE_1)
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::STORE)
                .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
                .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
                // The frame is blitted there first; `record` moves the image into and out of
                // this layout with barriers of its own.
                .initial_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .final_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
            let color = [vk::AttachmentReference::default()
                .attachment(0)
                .layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
            let subpasses = [vk::SubpassDescription::default()
                .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
                .color_attachments(&color)];
            // SAFETY: valid create info; the old render pass is unused (the GPU is idle in
            // `recreate`) and destroyed after egui's pipeline moved to the new one.
            let render_pass = unsafe {
                device.create_render_pass(
                    &vk::RenderPassCreateInfo::default()
                        .attachments(&attachments)
                        .subpasses(&subpasses),
                    None,
                )
            }
            .vk("vkCreateRenderPass")?;
            let old = std::mem::replace(&mut self.render_pass, render_pass);
            self.render_pass_format = self.format.format;
            let mode = egui_ash_renderer::RenderMode::RenderPass(render_pass);
            let egui = match self.egui.as_mut() {
                Some(egui) => egui.set_render_mode(mode).map(|()| None),
                None => egui_ash_renderer::Renderer::with_default_allocator(
                    &gpu.instance,
                    gpu.physical_device,
                    gpu.device.clone(),
                    mode,
                    egui_ash_renderer::Options {
                        in_flight_frames: 1,
                        // A UNORM swapchain holding sRGB-encoded bytes: egui's shader encodes.
                        srgb_framebuffer: false,
                        ..Default::default()
                    },
                )
                .map(Some),
            }
            .map_err(|e| LucentError::InvalidInput(format!("egui renderer: {e}")))?;
            if let Some(egui) = egui {
                self.egui = Some(egui);
            }
            if old != vk::RenderPass::null() {
                // SAFETY: see above.
                unsafe { device.destroy_render_pass(old, None) };
            }
        }
        for &image in &self.images {
            let info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(self.format.format)
                .subresource_range(
                    vk::ImageSubresourceRange::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .level_count(1)
                        .layer_count(1),
                );
            // SAFETY: the image is this swapchain's; the view is destroyed before it.
            let view = unsafe { device.create_image_view(&info, None) }.vk("vkCreateImageView")?;
            self.views.push(view);
            let attachments = [view];
            let info = vk::FramebufferCreateInfo::default()
                .render_pass(self.render_pass)
                .attachments(&attachments)
                .width(self.extent.width)
                .height(self.extent.height)
                .layers(1);
            // SAFETY: the view and render pass are alive; destroyed in `destroy_framebuffers`.
            let framebuffer =
                unsafe { device.create_framebuffer(&info, None) }.vk("vkCreateFramebuffer")?;
            self.framebuffers.push(framebuffer);
        }
        Ok(())
    }

    /// Destroys the views and framebuffers of the swapchain's images (the GPU is idle).
    fn destroy_framebuffers(&mut self, gpu: &GpuContext) {
        // SAFETY: the GPU is idle (callers wait first); every handle is ours.
        unsafe {
            for f in self.framebuffers.drain(..) {
                gpu.device.destroy_framebuffer(f, None);
            }
            for v in self.views.drain(..) {
                gpu.device.destroy_image_view(v, None);
            }
        }
    }

    /// Takes egui's texture changes of a frame (applied around the next frame drawn).
    pub fn queue_textures(&mut self, delta: egui::TexturesDelta) {
        self.textures.append(delta);
    }

    /// Renders `frame` onto the next swapchain image with the panel on top, and presents it.
    /// The GPU is idle when it returns.
    pub fn draw(&mut self, gpu: &GpuContext, mut frame: FrameInput<'_>) -> Result<Drawn> {
        if self.is_zero_sized() {
            return Ok(Drawn::OutOfDate);
        }
        let passes = frame.renderer.executable.plan.physical.len() as u32 + 1;
        if self
            .timer
            .as_ref()
            .is_none_or(|(_, capacity)| *capacity < passes)
        {
            if let Some((old, _)) = self.timer.take() {
                // The GPU is idle between frames (every frame is waited for).
                old.destroy(gpu);
            }
            self.timer = Some((GpuTimer::new(gpu, passes)?, passes));
        }
        // egui's new textures first: egui-ash-renderer records, submits and waits for the
        // copies itself (nothing of ours is pending: the previous frame was waited for).
        if let Some(egui) = self.egui.as_mut() {
            for (id, deltas) in std::mem::take(&mut self.textures.set) {
                for delta in deltas {
                    egui.set_texture(gpu.queue, self.upload_pool, id, &delta)
                        .map_err(|e| LucentError::InvalidInput(format!("egui texture: {e}")))?;
                }
            }
        }
        // SAFETY: the swapchain and semaphore are valid; the semaphore is unsignalled (its last
        // signal was waited on by the previous frame's submission, which has completed).
        let acquired = unsafe {
            self.swapchain_fn.acquire_next_image(
                self.swapchain,
                ACQUIRE_TIMEOUT_NS,
                self.acquired,
                vk::Fence::null(),
            )
        };
        let (index, suboptimal) = match acquired {
            Ok(v) => v,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(Drawn::OutOfDate),
            Err(vk::Result::TIMEOUT) | Err(vk::Result::NOT_READY) => {
                return Err(LucentError::InvalidInput(format!(
                    "no swapchain image became available within {} s (display not answering)",
                    ACQUIRE_TIMEOUT_NS / 1_000_000_000
                )))
            }
            Err(e) => return Err(LucentError::vulkan("vkAcquireNextImageKHR", e)),
        };
        self.record(gpu, &mut frame, index as usize)?;
        let device = &gpu.device;
        let waits = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.acquired)
            .stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)];
        let signals = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.rendered[index as usize])
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let submit = vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&cmds)
            .signal_semaphore_infos(&signals);
        // SAFETY: the command buffer is recorded, the fence unsignalled, the semaphores valid.
        unsafe {
            device
                .queue_submit2(gpu.queue, &[submit], self.fence)
                .vk("vkQueueSubmit2")?;
        }
        // SAFETY: as above.
        match unsafe { device.wait_for_fences(&[self.fence], true, FRAME_TIMEOUT_NS) } {
            Ok(()) => {}
            Err(vk::Result::TIMEOUT) => {
                return Err(LucentError::InvalidInput(format!(
                    "a frame did not finish on the GPU within {} s; giving up (hung driver?)",
                    FRAME_TIMEOUT_NS / 1_000_000_000
                )))
            }
            Err(e) => return Err(LucentError::vulkan("vkWaitForFences", e)),
        }
        // SAFETY: the fence is signalled and no longer used by a pending submission.
        unsafe { device.reset_fences(&[self.fence]) }.vk("vkResetFences")?;
        // The frame is done with the textures egui let go of.
        if let Some(egui) = self.egui.as_mut() {
            for id in std::mem::take(&mut self.textures.free) {
                egui.free_texture(id)
                    .map_err(|e| LucentError::InvalidInput(format!("egui texture: {e}")))?;
            }
        }
        let wait = [self.rendered[index as usize]];
        let swapchains = [self.swapchain];
        let indices = [index];
        let present = vk::PresentInfoKHR::default()
            .wait_semaphores(&wait)
            .swapchains(&swapchains)
            .image_indices(&indices);
        // SAFETY: the image was acquired and is in PRESENT_SRC layout once the wait is done.
        let presented = unsafe { self.swapchain_fn.queue_present(gpu.queue, &present) };
        let stale = match presented {
            Ok(present_suboptimal) => suboptimal || present_suboptimal,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => true,
            Err(e) => return Err(LucentError::vulkan("vkQueuePresentKHR", e)),
        };
        let passes = match (&self.timer, frame.render) {
            (Some((timer, _)), true) => timer.results(gpu)?.unwrap_or_default(),
            _ => Vec::new(),
        };
        Ok(Drawn::Presented { passes, stale })
    }

    fn record(&mut self, gpu: &GpuContext, frame: &mut FrameInput<'_>, index: usize) -> Result<()> {
        let device = &gpu.device;
        let cmd = self.cmd;
        let target = self.images[index];
        let renderer = frame.renderer;
        // SAFETY: the previous frame finished (its fence was waited for), so the pool's command
        // buffer is not pending.
        unsafe {
            device
                .reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            device
                .begin_command_buffer(
                    cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .vk("vkBeginCommandBuffer")?;
        }
        if frame.render {
            let timer = self.timer.as_mut().map(|(t, _)| t);
            if let Some(t) = timer {
                t.reset(gpu, cmd);
                renderer.executable.record_frame(gpu, cmd, 0, Some(t));
            } else {
                renderer.executable.record_frame(gpu, cmd, 0, None);
            }
        }
        // What goes on screen: the frame's display image in its export layout, or the
        // comparison's output.
        let (source, source_layout, (w, h)) = match frame.compare.as_mut() {
            Some((plain, comparer, comparison)) => {
                gpu.begin_label(cmd, "plain lighting");
                plain.executable.record_frame(gpu, cmd, 0, None);
                gpu.end_label(cmd);
                let image = comparer.record(gpu, cmd, plain, renderer, *comparison)?;
                (
                    image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    (renderer.settings.width, renderer.settings.height),
                )
            }
            None => {
                let display = renderer
                    .executable
                    .owned_image(renderer.outputs.display)
                    .ok_or_else(|| {
                        LucentError::Graph("the display image is not readable".into())
                    })?;
                let layout = renderer
                    .executable
                    .export_layout(renderer.outputs.display)
                    .unwrap_or(vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
                (
                    display.image,
                    layout,
                    (display.desc.width, display.desc.height),
                )
            }
        };
        gpu.begin_label(cmd, "present");
        let color = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(1);
        let to_transfer = vk::ImageMemoryBarrier2::default()
            // Chained to the acquire semaphore's wait (ALL_TRANSFER).
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::NONE)
            .dst_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .old_layout(vk::ImageLayout::UNDEFINED)
            .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .image(target)
            .subresource_range(color);
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let blit = vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([
                vk::Offset3D::default(),
                vk::Offset3D {
                    x: w as i32,
                    y: h as i32,
                    z: 1,
                },
            ])
            .dst_subresource(layers)
            .dst_offsets([
                vk::Offset3D::default(),
                vk::Offset3D {
                    x: self.extent.width as i32,
                    y: self.extent.height as i32,
                    z: 1,
                },
            ]);
        // The panel's render pass loads what the blit wrote.
        let to_attachment = vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)
            .dst_access_mask(
                vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
            )
            .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .image(target)
            .subresource_range(color);
        // SAFETY: recording; the source is in `source_layout` and readable by transfer (the
        // frame's export barrier, or the comparison's last barrier), the target was just
        // transitioned.
        unsafe {
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[to_transfer]),
            );
            device.cmd_blit_image(
                cmd,
                source,
                source_layout,
                target,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[blit],
                vk::Filter::NEAREST,
            );
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[to_attachment]),
            );
            device.cmd_begin_render_pass(
                cmd,
                &vk::RenderPassBeginInfo::default()
                    .render_pass(self.render_pass)
                    .framebuffer(self.framebuffers[index])
                    .render_area(vk::Rect2D {
                        offset: vk::Offset2D::default(),
                        extent: self.extent,
                    }),
                vk::SubpassContents::INLINE,
            );
        }
        let drawn = match (frame.ui.as_ref(), self.egui.as_mut()) {
            (Some(ui), Some(egui)) => egui
                .cmd_draw(cmd, self.extent, ui.pixels_per_point, &ui.primitives)
                .map_err(|e| LucentError::InvalidInput(format!("egui draw: {e}"))),
            _ => Ok(()),
        };
        let to_present = vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)
            .src_access_mask(vk::AccessFlags2::COLOR_ATTACHMENT_WRITE)
            // Presentation waits on the frame's semaphore, signalled after ALL_COMMANDS.
            .dst_stage_mask(vk::PipelineStageFlags2::NONE)
            .dst_access_mask(vk::AccessFlags2::NONE)
            .old_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .new_layout(vk::ImageLayout::PRESENT_SRC_KHR)
            .image(target)
            .subresource_range(color);
        // SAFETY: recording, inside the render pass begun above.
        unsafe {
            device.cmd_end_render_pass(cmd);
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[to_present]),
            );
        }
        gpu.end_label(cmd);
        // SAFETY: recording is complete.
        let ended = unsafe { device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer");
        drawn.and(ended)
    }

    /// Destroys everything (the surface too). Waits for the device first.
    pub fn destroy(mut self, gpu: &GpuContext) {
        if let Err(e) = gpu.wait_idle() {
            log::error!("waiting for the GPU before destroying the swapchain failed: {e}");
        }
        if let Some((timer, _)) = self.timer.take() {
            timer.destroy(gpu);
        }
        // egui's pipeline, buffers and textures go before the render pass they were made for.
        self.egui = None;
        self.textures.clear();
        self.destroy_framebuffers(gpu);
        let device = &gpu.device;
        // SAFETY: the device is idle; every handle was created by this presenter (null ones
        // are ignored by Vulkan); the swapchain goes before its surface.
        unsafe {
            device.destroy_fence(self.fence, None);
            device.destroy_command_pool(self.pool, None);
            device.destroy_command_pool(self.upload_pool, None);
            device.destroy_render_pass(self.render_pass, None);
            device.destroy_semaphore(self.acquired, None);
            for s in self.rendered.drain(..) {
                device.destroy_semaphore(s, None);
            }
            if self.swapchain != vk::SwapchainKHR::null() {
                self.swapchain_fn.destroy_swapchain(self.swapchain, None);
            }
            self.surface_fn.destroy_surface(self.surface, None);
        }
    }
}

/// A UNORM 8-bit format (the display image is already sRGB-encoded: an `_SRGB` swapchain would
/// encode it twice), BGRA or RGBA; otherwise the first format offered (with a warning).
fn pick_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    let wanted = [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM];
    wanted
        .iter()
        .find_map(|w| formats.iter().find(|f| f.format == *w).copied())
        .or_else(|| {
            let first = formats.first().copied();
            if let Some(f) = first {
                log::warn!(
                    "no 8-bit UNORM surface format; using {:?}: colours may be encoded twice",
                    f.format
                );
            }
            first
        })
}

/// FIFO with vsync (always available); without: MAILBOX, else IMMEDIATE, else FIFO.
fn pick_present_mode(modes: &[vk::PresentModeKHR], vsync: bool) -> vk::PresentModeKHR {
    if vsync {
        return vk::PresentModeKHR::FIFO;
    }
    [vk::PresentModeKHR::MAILBOX, vk::PresentModeKHR::IMMEDIATE]
        .into_iter()
        .find(|m| modes.contains(m))
        .unwrap_or_else(|| {
            log::info!("no tearing present mode; falling back to FIFO (vsync)");
            vk::PresentModeKHR::FIFO
        })
}
