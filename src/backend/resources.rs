//! GPU images and buffers, their memory, and copies to and from the host.
//!
//! Every resource carries a name; the same name goes to the memory allocator (leak reports) and
//! to the Vulkan object (validation messages, RenderDoc).
//!
//! Which API to use:
//! - [`GpuContext::create_image`] / [`GpuContext::create_buffer`] allocate a resource with its own
//!   memory; free it with [`GpuContext::destroy_image`] / [`GpuContext::destroy_buffer`]
//!   (resources are not freed on drop: a forgotten one shows up in the allocator's leak report).
//! - [`GpuContext::upload_buffer`] puts host data into a device-local buffer (vertices, indices,
//!   constants) through a staging copy.
//! - [`GpuContext::read_image`] and [`GpuContext::read_buffer`] copy GPU results back to the host
//!   (tests, screenshots, reports).
//! - For memory aliasing (the render graph places images whose lifetimes do not overlap in one
//!   block): [`GpuContext::create_image_unbound`] gives an image and its memory requirements,
//!   [`GpuContext::allocate_memory_block`] allocates a block, [`GpuContext::bind_image`] places
//!   an image at an offset in it and [`GpuContext::create_view`] makes its view. Wrap the result
//!   in [`GpuImage::from_parts`] to use the other functions on it.
//!
//! Setup copies go through [`GpuContext::submit_and_wait`] (or, inside
//! [`GpuContext::record_setup_into`], into the caller's command buffer) and end with a full
//! barrier, so later GPU work sees their results without further synchronization.

use ash::vk;
use super::memory::{Allocation, MemoryUse};

pub use super::buffer::GpuBuffer;
use super::context::GpuContext;
use crate::error::{LucentError, Result, VkResultExt};

/// Usages that access an image through a view (VUID-VkImageViewCreateInfo-image-04441).
const VIEW_USAGES: vk::ImageUsageFlags = vk::ImageUsageFlags::from_raw(
    vk::ImageUsageFlags::SAMPLED.as_raw()
        | vk::ImageUsageFlags::STORAGE.as_raw()
        | vk::ImageUsageFlags::COLOR_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::TRANSIENT_ATTACHMENT.as_raw()
        | vk::ImageUsageFlags::INPUT_ATTACHMENT.as_raw(),
);

/// A 2D image with one layer (and `mip_levels` levels), in optimal tiling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageDesc {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texel format.
    pub format: vk::Format,
    /// Every way the image will be used.
    pub usage: vk::ImageUsageFlags,
    /// `COLOR` or `DEPTH` (the aspect of the view and of copies).
    pub aspect: vk::ImageAspectFlags,
    /// Mip levels (1 for render targets).
    pub mip_levels: u32,
    /// Array layers (1: a 2-D image; more: a 2-D array, its view a 2-D array view).
    pub layers: u32,
}

impl ImageDesc {
    /// A colour image description.
    pub fn color(width: u32, height: u32, format: vk::Format, usage: vk::ImageUsageFlags) -> Self {
        Self {
            width,
            height,
            format,
            usage,
            aspect: vk::ImageAspectFlags::COLOR,
            mip_levels: 1,
            layers: 1,
        }
    }

    /// A depth image description.
    pub fn depth(width: u32, height: u32, format: vk::Format, usage: vk::ImageUsageFlags) -> Self {
        Self {
            width,
            height,
            format,
            usage,
            aspect: vk::ImageAspectFlags::DEPTH,
            mip_levels: 1,
            layers: 1,
        }
    }

    /// The same image as an array of `layers` layers (a shadow map's cascades or cube faces);
    /// uploads then hold the layers one after the other.
    pub fn with_layers(self, layers: u32) -> Self {
        Self { layers, ..self }
    }

    /// The image's extent as a 3D extent with depth 1.
    pub fn extent(&self) -> vk::Extent3D {
        vk::Extent3D {
            width: self.width,
            height: self.height,
            depth: 1,
        }
    }

    /// The subresource range covering the whole image (every mip, every layer).
    pub fn subresource_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: self.aspect,
            base_mip_level: 0,
            level_count: self.mip_levels.max(1),
            base_array_layer: 0,
            layer_count: self.layers.max(1),
        }
    }
}

/// An image, its view and (unless its memory is owned elsewhere) its memory.
#[derive(Debug)]
pub struct GpuImage {
    /// The image.
    pub image: vk::Image,
    /// A 2D view of the whole image with [`ImageDesc::aspect`]; null when the usage allows no
    /// view (e.g. a transfer-only image).
    pub view: vk::ImageView,
    /// What the image was created with.
    pub desc: ImageDesc,
    /// Debug name of the image, its view and its memory.
    pub name: String,
    allocation: Option<Allocation>,
}

impl GpuImage {
    /// Bytes of its own memory (0 when its memory is owned elsewhere).
    pub fn memory_bytes(&self) -> u64 {
        self.allocation.as_ref().map_or(0, Allocation::size)
    }

    /// Wraps an image whose memory is owned elsewhere (e.g. bound into a [`MemoryBlock`] with
    /// [`GpuContext::bind_image`]). [`GpuContext::destroy_image`] then destroys the view and the
    /// image but leaves the memory alone.
    pub fn from_parts(image: vk::Image, view: vk::ImageView, desc: ImageDesc, name: &str) -> Self {
        Self {
            image,
            view,
            desc,
            name: name.to_string(),
            allocation: None,
        }
    }
}

/// A block of device-local memory that several resources can be bound into (memory aliasing).
/// Free it with [`GpuContext::free_memory_block`] after every resource in it is destroyed.
#[derive(Debug)]
pub struct MemoryBlock {
    allocation: Allocation,
    name: String,
    memory_type_bits: u32,
}

impl MemoryBlock {
    /// The `VkDeviceMemory` the block lives in (shared with other blocks; never free it directly).
    pub fn memory(&self) -> vk::DeviceMemory {
        self.allocation.memory()
    }

    /// Offset of the block inside [`MemoryBlock::memory`]; resource offsets passed to
    /// [`GpuContext::bind_image`] are relative to it.
    pub fn offset(&self) -> u64 {
        self.allocation.offset()
    }

    /// Size of the block in bytes.
    pub fn size(&self) -> u64 {
        self.allocation.size()
    }

    /// The block's debug name.
    pub fn name(&self) -> &str {
        &self.name
    }
}

impl GpuContext {
    /// Creates an image with its own device-local memory and a view of it (no view when the
    /// usage is transfer-only).
    pub fn create_image(&self, desc: &ImageDesc, name: &str) -> Result<GpuImage> {
        let (image, requirements) = self.create_image_unbound(desc, name)?;
        let allocation = match self.memory().allocate(
            name,
            requirements,
            MemoryUse::DeviceLocal,
            false,
        ) {
            Ok(allocation) => allocation,
            Err(e) => {
                // SAFETY: the image was created above, is unbound and unused.
                unsafe { self.device.destroy_image(image, None) };
                return Err(e);
            }
        };
        // SAFETY: the allocation satisfies `requirements` of this image (gpu-allocator honours
        // size, alignment and memory type bits; a host allocator's size and alignment were
        // checked, its memory type is its contract) and the image is not yet bound.
        let bound = unsafe {
            self.device
                .bind_image_memory(image, allocation.memory(), allocation.offset())
        }
        .vk("vkBindImageMemory");
        let view = bound.and_then(|()| {
            if desc.usage.intersects(VIEW_USAGES) {
                self.create_view(image, desc, name)
            } else {
                // Vulkan allows views only of images with a usage that reads or writes through
                // one; a transfer-only image has none.
                Ok(vk::ImageView::null())
            }
        });
        match view {
            Ok(view) => Ok(GpuImage {
                image,
                view,
                desc: *desc,
                name: name.to_string(),
                allocation: Some(allocation),
            }),
            Err(e) => {
                // SAFETY: the image was created above and is unused; it is destroyed before its
                // memory is freed.
                unsafe { self.device.destroy_image(image, None) };
                self.memory().free(allocation, name);
                Err(e)
            }
        }
    }

    /// Destroys an image, its view and (if it owns it) its memory. The GPU must be done with it.
    /// On a thread recording setup work into a caller's command buffer, the destruction waits
    /// for that submission ([`GpuContext::record_setup_into`]).
    pub fn destroy_image(&self, image: GpuImage) {
        self.destroy_after_setup(move |gpu| gpu.destroy_image_now(image));
    }

    fn destroy_image_now(&self, image: GpuImage) {
        // SAFETY: the caller hands over ownership and guarantees the GPU no longer uses the
        // image; the view is destroyed before the image, the image before its memory.
        unsafe {
            self.device.destroy_image_view(image.view, None);
            self.device.destroy_image(image.image, None);
        }
        if let Some(allocation) = image.allocation {
            self.memory().free(allocation, &image.name);
        }
    }

    /// Creates a buffer of `size` bytes for `memory_use` (`DeviceLocal`, `Upload` or `Readback`; the
    /// last two are mapped, see [`GpuBuffer::mapped_slice`]).
    pub fn create_buffer(
        &self,
        size: u64,
        usage: vk::BufferUsageFlags,
        memory_use: MemoryUse,
        name: &str,
    ) -> Result<GpuBuffer> {
        if size == 0 {
            return Err(LucentError::InvalidInput(format!(
                "buffer '{name}' has size 0 (Vulkan buffers must not be empty)"
            )));
        }
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid create info with non-zero size; the buffer is destroyed on every error
        // path below or by destroy_buffer.
        let buffer = unsafe { self.device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        self.set_name(buffer, name);
        // SAFETY: `buffer` was just created from this device.
        let requirements = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let allocation = match self.memory().allocate(name, requirements, memory_use, true) {
            Ok(allocation) => allocation,
            Err(e) => {
                // SAFETY: the buffer was created above, is unbound and unused.
                unsafe { self.device.destroy_buffer(buffer, None) };
                return Err(e);
            }
        };
        // SAFETY: the allocation satisfies the buffer's requirements and the buffer is unbound.
        let bound = unsafe {
            self.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }
        .vk("vkBindBufferMemory");
        if let Err(e) = bound {
            // SAFETY: the buffer is unused; destroyed before its memory is freed.
            unsafe { self.device.destroy_buffer(buffer, None) };
            self.memory().free(allocation, name);
            return Err(e);
        }
        Ok(GpuBuffer {
            buffer,
            size,
            name: name.to_string(),
            allocation: Some(allocation),
        })
    }

    /// Destroys a buffer and frees its memory. The GPU must be done with it. On a thread
    /// recording setup work into a caller's command buffer, the destruction waits for that
    /// submission ([`GpuContext::record_setup_into`]).
    pub fn destroy_buffer(&self, buffer: GpuBuffer) {
        self.destroy_after_setup(move |gpu| gpu.destroy_buffer_now(buffer));
    }

    fn destroy_buffer_now(&self, buffer: GpuBuffer) {
        // SAFETY: the caller hands over ownership and guarantees the GPU no longer uses the
        // buffer; it is destroyed before its memory is freed.
        unsafe { self.device.destroy_buffer(buffer.buffer, None) };
        if let Some(allocation) = buffer.allocation {
            self.memory().free(allocation, &buffer.name);
        }
    }

    /// Creates a device-local buffer holding `data`, copied through a staging buffer.
    /// `TRANSFER_DST` is added to `usage`. The copy is complete and visible to all later GPU work
    /// when this returns.
    pub fn upload_buffer<T: bytemuck::Pod>(
        &self,
        data: &[T],
        usage: vk::BufferUsageFlags,
        name: &str,
    ) -> Result<GpuBuffer> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let size = bytes.len() as u64;
        if size == 0 {
            return Err(LucentError::InvalidInput(format!(
                "upload '{name}' has no data (Vulkan buffers must not be empty)"
            )));
        }
        let mut staging = self.create_buffer(
            size,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryUse::Upload,
            &format!("{name} (staging)"),
        )?;
        match staging.mapped_mut() {
            Some(mapped) => mapped.copy_from_slice(bytes),
            None => {
                self.destroy_buffer(staging);
                return Err(LucentError::InvalidInput(format!(
                    "staging memory for '{name}' is not host-visible"
                )));
            }
        }
        let buffer = match self.create_buffer(
            size,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryUse::DeviceLocal,
            name,
        ) {
            Ok(buffer) => buffer,
            Err(e) => {
                self.destroy_buffer(staging);
                return Err(e);
            }
        };
        let staging_buffer = staging.buffer;
        let copied = self.setup_copy(staging, |cmd| {
            self.begin_label(cmd, &format!("upload {name}"));
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size,
            };
            // The copy's write must be visible to whatever reads the buffer later, in any stage
            // of any later submission: a full barrier after it.
            let barrier = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)];
            // SAFETY: `cmd` is recording; both buffers are live, large enough for the region and
            // were created with TRANSFER_SRC / TRANSFER_DST usage.
            unsafe {
                self.device
                    .cmd_copy_buffer(cmd, staging_buffer, buffer.buffer, &[region]);
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().memory_barriers(&barrier),
                );
            }
            self.end_label(cmd);
        });
        match copied {
            Ok(()) => Ok(buffer),
            Err(e) => {
                self.destroy_buffer(buffer);
                Err(e)
            }
        }
    }

    /// Creates a sampled image and fills every mip level from `levels` (tightly packed texels
    /// of `desc.format`, level 0 first, each level half the size of the previous, at least 1),
    /// through a staging buffer. The image is left in `SHADER_READ_ONLY_OPTIMAL`, its contents
    /// visible to every later GPU read.
    pub fn upload_image(
        &self,
        desc: &ImageDesc,
        levels: &[Vec<u8>],
        name: &str,
    ) -> Result<GpuImage> {
        let sizes: Vec<u64> = levels.iter().map(|l| l.len() as u64).collect();
        self.upload_image_with(desc, &sizes, name, |level, out| {
            out.copy_from_slice(&levels[level]);
            Ok(())
        })
    }

    /// [`Self::upload_image`] without the levels in memory first: `fill(level, bytes)` writes
    /// level `level` (of `level_bytes[level]` bytes) straight into the staging buffer, so a
    /// large texture costs its staging copy and nothing more.
    pub fn upload_image_with(
        &self,
        desc: &ImageDesc,
        level_bytes: &[u64],
        name: &str,
        mut fill: impl FnMut(usize, &mut [u8]) -> Result<()>,
    ) -> Result<GpuImage> {
        self.upload_image_chain(desc, level_bytes, name, |mapped| {
            let mut start = 0usize;
            for (level, &bytes) in level_bytes.iter().enumerate() {
                let end = start + bytes as usize;
                fill(level, &mut mapped[start..end])?;
                start = end;
            }
            Ok(())
        })
    }

    /// [`Self::upload_image_with`] with the whole staging buffer at once: `fill(bytes)` gets
    /// every level, level 0 first, tightly packed (`level_bytes` each), so it can make each
    /// level from the one before it in place. `fill` runs, and whatever it owns is dropped,
    /// before the image is created: a loader that moves its decoded file into `fill` never
    /// holds the file, the staging buffer and the image at once.
    pub fn upload_image_chain(
        &self,
        desc: &ImageDesc,
        level_bytes: &[u64],
        name: &str,
        fill: impl FnOnce(&mut [u8]) -> Result<()>,
    ) -> Result<GpuImage> {
        if level_bytes.len() != desc.mip_levels.max(1) as usize {
            return Err(LucentError::InvalidInput(format!(
                "upload '{name}': {} levels of data for {} mip levels",
                level_bytes.len(),
                desc.mip_levels
            )));
        }
        let total = level_bytes
            .iter()
            .try_fold(0u64, |sum, &b| sum.checked_add(b))
            .ok_or_else(|| {
                LucentError::InvalidInput(format!("upload '{name}': size overflows 64 bits"))
            })?;
        if total == 0 {
            return Err(LucentError::InvalidInput(format!(
                "upload '{name}' has no data"
            )));
        }
        let mut staging = self.create_buffer(
            total,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryUse::Upload,
            &format!("{name} (staging)"),
        )?;
        let filled = match staging.mapped_mut() {
            Some(mapped) => fill(&mut mapped[..total as usize]),
            None => Err(LucentError::InvalidInput(format!(
                "staging memory for '{name}' is not host-visible"
            ))),
        };
        if let Err(e) = filled {
            self.destroy_buffer(staging);
            return Err(e);
        }
        let desc = ImageDesc {
            usage: desc.usage | vk::ImageUsageFlags::TRANSFER_DST,
            ..*desc
        };
        let image = match self.create_image(&desc, name) {
            Ok(image) => image,
            Err(e) => {
                self.destroy_buffer(staging);
                return Err(e);
            }
        };
        let mut regions = Vec::with_capacity(level_bytes.len());
        let mut offset = 0u64;
        for (level, &bytes) in level_bytes.iter().enumerate() {
            let shift = level as u32;
            regions.push(vk::BufferImageCopy {
                buffer_offset: offset,
                buffer_row_length: 0,
                buffer_image_height: 0,
                image_subresource: vk::ImageSubresourceLayers {
                    aspect_mask: desc.aspect,
                    mip_level: shift,
                    base_array_layer: 0,
                    layer_count: desc.layers.max(1),
                },
                image_offset: vk::Offset3D::default(),
                image_extent: vk::Extent3D {
                    width: (desc.width >> shift).max(1),
                    height: (desc.height >> shift).max(1),
                    depth: 1,
                },
            });
            offset += bytes;
        }
        let range = desc.subresource_range();
        let staging_buffer = staging.buffer;
        let copied = self.setup_copy(staging, |cmd| {
            self.begin_label(cmd, &format!("upload {name}"));
            let to_dst = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::NONE)
                .dst_stage_mask(vk::PipelineStageFlags2::COPY)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.image)
                .subresource_range(range)];
            // The copy's writes must be visible to any later read, in any stage of any later
            // submission.
            let to_read = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_access_mask(vk::AccessFlags2::MEMORY_READ)
                .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .new_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.image)
                .subresource_range(range)];
            // SAFETY: `cmd` is recording; the image and staging buffer are live, the regions lie
            // inside both, and the image has TRANSFER_DST usage.
            unsafe {
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&to_dst),
                );
                self.device.cmd_copy_buffer_to_image(
                    cmd,
                    staging_buffer,
                    image.image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &regions,
                );
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&to_read),
                );
            }
            self.end_label(cmd);
        });
        match copied {
            Ok(()) => Ok(image),
            Err(e) => {
                self.destroy_image(image);
                Err(e)
            }
        }
    }

    /// Copies a whole buffer to host memory. The buffer needs `TRANSFER_SRC` usage; all earlier
    /// GPU writes to it are waited for.
    pub fn read_buffer(&self, buffer: &GpuBuffer) -> Result<Vec<u8>> {
        let readback = self.create_buffer(
            buffer.size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryUse::Readback,
            &format!("{} (readback)", buffer.name),
        )?;
        let copied = self.submit_and_wait(|cmd| {
            self.begin_label(cmd, &format!("read back {}", buffer.name));
            // Earlier writes to the buffer (any stage, any earlier submission) before the copy.
            let before = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::COPY)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_READ)];
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size: buffer.size,
            };
            let after = [host_read_barrier(readback.buffer)];
            // SAFETY: `cmd` is recording; both buffers are live and `buffer.size` bytes long.
            unsafe {
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().memory_barriers(&before),
                );
                self.device
                    .cmd_copy_buffer(cmd, buffer.buffer, readback.buffer, &[region]);
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().buffer_memory_barriers(&after),
                );
            }
            self.end_label(cmd);
        });
        let bytes = copied.and_then(|()| {
            readback.mapped_slice().map(<[u8]>::to_vec).ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "readback memory for '{}' is not host-visible",
                    buffer.name
                ))
            })
        });
        self.destroy_buffer(readback);
        bytes
    }

    /// Copies a colour (or single-aspect depth) image to host memory: rows tightly packed, raw
    /// texel bytes in the image's format.
    ///
    /// `layout` is the image's current layout; the image is returned to it. All earlier GPU
    /// writes to the image are waited for. The image needs `TRANSFER_SRC` usage and a format
    /// known to the format table ([`crate::backend::format`]).
    pub fn read_image(&self, image: &GpuImage, layout: vk::ImageLayout) -> Result<Vec<u8>> {
        self.read_image_at(image, layout, 0, 0)
    }

    /// [`Self::read_image`] of mip level `mip` and array layer `layer` (that subresource in
    /// `layout`; the others are not touched): the level's size, tightly packed.
    pub fn read_image_at(
        &self,
        image: &GpuImage,
        layout: vk::ImageLayout,
        mip: u32,
        layer: u32,
    ) -> Result<Vec<u8>> {
        let desc = &image.desc;
        if mip >= desc.mip_levels.max(1) || layer >= desc.layers.max(1) {
            return Err(LucentError::InvalidInput(format!(
                "image '{}' has {} mip levels and {} layers: no mip {mip}, layer {layer}",
                image.name, desc.mip_levels, desc.layers
            )));
        }
        let (width, height) = ((desc.width >> mip).max(1), (desc.height >> mip).max(1));
        if matches!(
            layout,
            vk::ImageLayout::UNDEFINED | vk::ImageLayout::PREINITIALIZED
        ) {
            return Err(LucentError::InvalidInput(format!(
                "image '{}' is in layout {layout:?}: its contents are undefined",
                image.name
            )));
        }
        if !desc.usage.contains(vk::ImageUsageFlags::TRANSFER_SRC) {
            return Err(LucentError::InvalidInput(format!(
                "image '{}' cannot be read back: it lacks TRANSFER_SRC usage",
                image.name
            )));
        }
        // Depth-stencil images read back their depth aspect (copied as 32 bits per texel for
        // the combined formats).
        let copy_aspect = if desc.aspect.contains(vk::ImageAspectFlags::DEPTH) {
            vk::ImageAspectFlags::DEPTH
        } else {
            desc.aspect
        };
        if copy_aspect != vk::ImageAspectFlags::COLOR && copy_aspect != vk::ImageAspectFlags::DEPTH
        {
            return Err(LucentError::InvalidInput(format!(
                "image '{}' cannot be read back: aspect {:?} has neither COLOR nor DEPTH",
                image.name, desc.aspect
            )));
        }
        let texel = if crate::backend::access::has_stencil(desc.format) {
            Some(4)
        } else {
            crate::backend::format::texel_bytes(desc.format)
        };
        let texel = texel.ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "image '{}' cannot be read back: format {:?} has no known texel size",
                image.name, desc.format
            ))
        })?;
        let size = u64::from(width) * u64::from(height) * u64::from(texel);
        let readback = self.create_buffer(
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryUse::Readback,
            &format!("{} (readback)", image.name),
        )?;
        let range = vk::ImageSubresourceRange {
            aspect_mask: desc.aspect,
            base_mip_level: mip,
            level_count: 1,
            base_array_layer: layer,
            layer_count: 1,
        };
        let copied = self.submit_and_wait(|cmd| {
            self.begin_label(cmd, &format!("read back {}", image.name));
            // Wait for every earlier write to the image, whatever wrote it, then move it to
            // TRANSFER_SRC_OPTIMAL (no transition if it is already there).
            let to_src = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .src_access_mask(vk::AccessFlags2::MEMORY_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::COPY)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_READ)
                .old_layout(layout)
                .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.image)
                .subresource_range(range)];
            let region = vk::BufferImageCopy {
                buffer_offset: 0,
                buffer_row_length: 0,
                buffer_image_height: 0,
                image_subresource: vk::ImageSubresourceLayers {
                    aspect_mask: copy_aspect,
                    mip_level: mip,
                    base_array_layer: layer,
                    layer_count: 1,
                },
                image_offset: vk::Offset3D::default(),
                image_extent: vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                },
            };
            // Back to the caller's layout. The copy only read the image, so an execution
            // dependency suffices on the source side; the transition's writes must be visible to
            // whatever comes next.
            let back = [vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::NONE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
                .old_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .new_layout(layout)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image.image)
                .subresource_range(range)];
            let to_host = [host_read_barrier(readback.buffer)];
            // SAFETY: `cmd` is recording; the image is live, in `layout` (caller's contract) and
            // has TRANSFER_SRC usage; the buffer holds exactly width * height texels.
            unsafe {
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&to_src),
                );
                self.device.cmd_copy_image_to_buffer(
                    cmd,
                    image.image,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    readback.buffer,
                    &[region],
                );
                self.device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default()
                        .image_memory_barriers(&back)
                        .buffer_memory_barriers(&to_host),
                );
            }
            self.end_label(cmd);
        });
        let bytes = copied.and_then(|()| {
            readback.mapped_slice().map(<[u8]>::to_vec).ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "readback memory for '{}' is not host-visible",
                    image.name
                ))
            })
        });
        self.destroy_buffer(readback);
        bytes
    }

    /// Creates an image without memory and returns it with its memory requirements, for binding
    /// into a [`MemoryBlock`] with [`GpuContext::bind_image`]. Destroy it with
    /// `device.destroy_image` (or through [`GpuImage::from_parts`] and
    /// [`GpuContext::destroy_image`]).
    pub fn create_image_unbound(
        &self,
        desc: &ImageDesc,
        name: &str,
    ) -> Result<(vk::Image, vk::MemoryRequirements)> {
        if desc.width == 0 || desc.height == 0 {
            return Err(LucentError::InvalidInput(format!(
                "image '{name}' has zero size {}x{}",
                desc.width, desc.height
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(desc.extent())
            .mip_levels(desc.mip_levels.max(1))
            .array_layers(desc.layers.max(1))
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info (non-zero extent, one mip and layer); the caller owns the
        // returned image.
        let image = unsafe { self.device.create_image(&info, None) }.vk("vkCreateImage")?;
        self.set_name(image, name);
        // SAFETY: `image` was just created from this device.
        let requirements = unsafe { self.device.get_image_memory_requirements(image) };
        Ok((image, requirements))
    }

    /// Allocates a device-local block satisfying `requirements`, for several resources to share.
    ///
    /// For aliasing, pass the largest size (plus offsets), the largest alignment and the
    /// intersection of the `memory_type_bits` of every resource that will live in the block.
    /// Free it with [`GpuContext::free_memory_block`].
    pub fn allocate_memory_block(
        &self,
        requirements: vk::MemoryRequirements,
        name: &str,
    ) -> Result<MemoryBlock> {
        let allocation = self
            .memory()
            .allocate(name, requirements, MemoryUse::DeviceLocal, false)?;
        Ok(MemoryBlock {
            allocation,
            name: name.to_string(),
            memory_type_bits: requirements.memory_type_bits,
        })
    }

    /// Frees a block from [`GpuContext::allocate_memory_block`]. Every resource bound into it must
    /// be destroyed first (or at least no longer used by the GPU).
    ///
    /// On a thread recording setup work into a caller's command buffer, freeing waits for that
    /// submission ([`GpuContext::record_setup_into`]), as destroying the resources in it does.
    pub fn free_memory_block(&self, block: MemoryBlock) {
        self.destroy_after_setup(move |gpu| gpu.memory().free(block.allocation, &block.name));
    }

    /// Binds `image` at byte `offset` inside `block`. The offset must respect the image's
    /// alignment, the image must fit in the block and accept one of the block's memory types;
    /// all three are checked (the last only against the block's requested type bits).
    pub fn bind_image(&self, image: vk::Image, block: &MemoryBlock, offset: u64) -> Result<()> {
        // SAFETY: `image` is an image of this device (caller's contract).
        let requirements = unsafe { self.device.get_image_memory_requirements(image) };
        let alignment = requirements.alignment.max(1);
        if !offset.is_multiple_of(alignment) {
            return Err(LucentError::InvalidInput(format!(
                "offset {offset} in memory block '{}' is not a multiple of the image's alignment {alignment}",
                block.name
            )));
        }
        if offset
            .checked_add(requirements.size)
            .is_none_or(|end| end > block.size())
        {
            return Err(LucentError::InvalidInput(format!(
                "image of {} bytes at offset {offset} does not fit memory block '{}' of {} bytes",
                requirements.size,
                block.name,
                block.size()
            )));
        }
        if requirements.memory_type_bits & block.memory_type_bits == 0 {
            return Err(LucentError::InvalidInput(format!(
                "memory block '{}' (memory types {:#x}) cannot hold the image (memory types {:#x})",
                block.name, block.memory_type_bits, requirements.memory_type_bits
            )));
        }
        // SAFETY: offset and size were checked against the block and the image's alignment; the
        // block's memory stays allocated while the image uses it (caller's contract).
        unsafe {
            self.device
                .bind_image_memory(image, block.memory(), block.offset() + offset)
        }
        .vk("vkBindImageMemory")
    }

    /// Creates a 2D view (a 2-D array view for an array) of the whole of `image` with
    /// `desc`'s format and aspect.
    pub fn create_view(
        &self,
        image: vk::Image,
        desc: &ImageDesc,
        name: &str,
    ) -> Result<vk::ImageView> {
        let info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(if desc.layers > 1 {
                vk::ImageViewType::TYPE_2D_ARRAY
            } else {
                vk::ImageViewType::TYPE_2D
            })
            .format(desc.format)
            .subresource_range(desc.subresource_range());
        // SAFETY: `image` is a live 2D image of this device created with `desc` and bound to
        // memory (caller's contract).
        let view = unsafe { self.device.create_image_view(&info, None) }.vk("vkCreateImageView")?;
        self.set_name(view, name);
        Ok(view)
    }
}

/// Makes a transfer write to `buffer` available to host reads after the fence wait.
fn host_read_barrier(buffer: vk::Buffer) -> vk::BufferMemoryBarrier2<'static> {
    vk::BufferMemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::COPY)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .buffer(buffer)
        .offset(0)
        .size(vk::WHOLE_SIZE)
}
