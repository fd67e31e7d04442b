//! Putting frames on a window: surface, swapchain, and the per-frame submit and present.
//!
//! One frame is in flight at a time: the frame's fence is waited for before the next one is
//! recorded, which is what [`Renderer::update`] needs (the uniforms are written between frames)
//! and what makes every rebuild and resize safe (nothing is pending when objects are replaced).
//! Each frame records the renderer's whole frame, blits its display image (RGBA8, sRGB-encoded)
//! onto the acquired swapchain image (a UNORM format, so the bytes are shown as they are),
//! copies the overlay panel over its top-left corner, and transitions it for presentation.
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
use gpu_allocator::MemoryLocation;

use crate::backend::timer::{GpuTimer, ScopeTime};
use crate::backend::{GpuBuffer, GpuContext};
use crate::error::VkResultExt;
use crate::frame::Renderer;
use crate::{LucentError, Result};

use super::overlay::Panel;

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
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timer: Option<(GpuTimer, u32)>,
    overlay: Option<GpuBuffer>,
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
            pool: vk::CommandPool::null(),
            cmd: vk::CommandBuffer::null(),
            fence: vk::Fence::null(),
            timer: None,
            overlay: None,
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
            self.pool = device
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default()
                        .queue_family_index(gpu.queue_family)
                        .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                    None,
                )
                .vk("vkCreateCommandPool")?;
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
        if !caps
            .supported_usage_flags
            .contains(vk::ImageUsageFlags::TRANSFER_DST)
        {
            return Err(LucentError::MissingFeature {
                device: gpu.info.name.clone(),
                feature: "swapchain images that can be a transfer destination".into(),
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
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST)
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

    /// Renders `renderer`'s frame onto the next swapchain image with `overlay` on top, and
    /// presents it. With `render` false the frame was already rendered (isolated timing: pass
    /// by pass, by the caller) and only its display image is put on screen. The GPU is idle
    /// when it returns.
    pub fn draw(
        &mut self,
        gpu: &GpuContext,
        renderer: &Renderer,
        overlay: Option<&Panel>,
        render: bool,
    ) -> Result<Drawn> {
        if self.is_zero_sized() {
            return Ok(Drawn::OutOfDate);
        }
        let passes = renderer.executable.plan.physical.len() as u32 + 1;
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
        let image = self.images[index as usize];
        let panel = match overlay {
            Some(p) => self.upload_overlay(gpu, p)?,
            None => None,
        };
        self.record(gpu, renderer, image, panel, render)?;
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
        let passes = match (&self.timer, render) {
            (Some((timer, _)), true) => timer.results(gpu)?.unwrap_or_default(),
            _ => Vec::new(),
        };
        Ok(Drawn::Presented { passes, stale })
    }

    /// Copies the panel into the host-visible overlay buffer; returns its size, clipped to the
    /// swapchain, or `None` when it does not fit at all.
    fn upload_overlay(&mut self, gpu: &GpuContext, panel: &Panel) -> Result<Option<(u32, u32)>> {
        let width = panel.width.min(self.extent.width);
        let height = panel.height.min(self.extent.height);
        if width == 0
            || height == 0
            || panel.pixels.len() as u64 != u64::from(panel.width) * u64::from(panel.height) * 4
        {
            return Ok(None);
        }
        let bytes = u64::from(width) * u64::from(height) * 4;
        if self.overlay.as_ref().is_none_or(|b| b.size < bytes) {
            if let Some(old) = self.overlay.take() {
                // The GPU is idle between frames.
                gpu.destroy_buffer(old);
            }
            self.overlay = Some(gpu.create_buffer(
                bytes.max(256 * 1024),
                vk::BufferUsageFlags::TRANSFER_SRC,
                MemoryLocation::CpuToGpu,
                "demo overlay",
            )?);
        }
        let mapped = self
            .overlay
            .as_mut()
            .and_then(GpuBuffer::mapped_mut)
            .ok_or_else(|| {
                LucentError::InvalidInput("overlay buffer is not host-visible".into())
            })?;
        let row = width as usize * 4;
        for y in 0..height as usize {
            let src = y * panel.width as usize * 4;
            mapped[y * row..(y + 1) * row].copy_from_slice(&panel.pixels[src..src + row]);
        }
        Ok(Some((width, height)))
    }

    fn record(
        &mut self,
        gpu: &GpuContext,
        renderer: &Renderer,
        target: vk::Image,
        panel: Option<(u32, u32)>,
        render: bool,
    ) -> Result<()> {
        let device = &gpu.device;
        let cmd = self.cmd;
        let display = renderer
            .executable
            .owned_image(renderer.outputs.display)
            .ok_or_else(|| LucentError::Graph("the display image is not readable".into()))?;
        let display_layout = renderer
            .executable
            .export_layout(renderer.outputs.display)
            .unwrap_or(vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
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
        if render {
            let timer = self.timer.as_mut().map(|(t, _)| t);
            if let Some(t) = timer {
                t.reset(gpu, cmd);
                renderer.executable.record_frame(gpu, cmd, 0, Some(t));
            } else {
                renderer.executable.record_frame(gpu, cmd, 0, None);
            }
        }
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
        let (w, h) = (display.desc.width as i32, display.desc.height as i32);
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let blit = vk::ImageBlit::default()
            .src_subresource(layers)
            .src_offsets([vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }])
            .dst_subresource(layers)
            .dst_offsets([
                vk::Offset3D::default(),
                vk::Offset3D {
                    x: self.extent.width as i32,
                    y: self.extent.height as i32,
                    z: 1,
                },
            ]);
        // SAFETY: recording; the display image is in its export layout (readable by transfer,
        // made visible by the frame's export barrier), the target was just transitioned.
        unsafe {
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[to_transfer]),
            );
            device.cmd_blit_image(
                cmd,
                display.image,
                display_layout,
                target,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[blit],
                vk::Filter::NEAREST,
            );
        }
        if let (Some((pw, ph)), Some(buffer)) = (panel, &self.overlay) {
            let after_blit = vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .image(target)
                .subresource_range(color);
            let region = vk::BufferImageCopy::default()
                .image_subresource(layers)
                .image_extent(vk::Extent3D {
                    width: pw,
                    height: ph,
                    depth: 1,
                });
            // SAFETY: recording; the buffer holds pw*ph tightly packed texels written by the
            // host before the submit (host writes before a submit are visible to it).
            unsafe {
                device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&[after_blit]),
                );
                device.cmd_copy_buffer_to_image(
                    cmd,
                    buffer.buffer,
                    target,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[region],
                );
            }
        }
        let to_present = vk::ImageMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            // Presentation waits on the frame's semaphore, signalled after ALL_COMMANDS.
            .dst_stage_mask(vk::PipelineStageFlags2::NONE)
            .dst_access_mask(vk::AccessFlags2::NONE)
            .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .new_layout(vk::ImageLayout::PRESENT_SRC_KHR)
            .image(target)
            .subresource_range(color);
        // SAFETY: recording.
        unsafe {
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[to_present]),
            );
        }
        gpu.end_label(cmd);
        // SAFETY: recording is complete.
        unsafe { device.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")
    }

    /// Destroys everything (the surface too). Waits for the device first.
    pub fn destroy(mut self, gpu: &GpuContext) {
        if let Err(e) = gpu.wait_idle() {
            log::error!("waiting for the GPU before destroying the swapchain failed: {e}");
        }
        if let Some((timer, _)) = self.timer.take() {
            timer.destroy(gpu);
        }
        if let Some(buffer) = self.overlay.take() {
            gpu.destroy_buffer(buffer);
        }
        let device = &gpu.device;
        // SAFETY: the device is idle; every handle was created by this presenter (null ones
        // are ignored by Vulkan); the swapchain goes before its surface.
        unsafe {
            device.destroy_fence(self.fence, None);
            device.destroy_command_pool(self.pool, None);
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

/// Whether the overlay panel must be written as B, G, R, A for `format`.
pub fn is_bgra(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::B8G8R8A8_UNORM | vk::Format::B8G8R8A8_SRGB
    )
}
