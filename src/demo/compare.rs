//! The comparison views: plain lighting (a second renderer with technique `none`) against the
//! technique, side by side (split) or as an amplified difference.
//!
//! Both renderers render the same view at the same size into their display images (RGBA8,
//! sRGB-encoded). [`Comparer::record`] copies the two into images of its own that a compute
//! shader may read (the renderers' display images are transfer sources and colour attachments
//! only), and runs `glsl/demo/compare.comp` (compiled at run time like every demo shader, so it
//! reloads when edited) into an output image that the presenter blits onto the swapchain and
//! that screenshots read back: a screenshot is what the window shows, without the panel.
//!
//! Synchronisation: every frame is waited for before the next is recorded, but the barriers
//! still name the previous frame's accesses (the compute reads and writes, the blit and
//! read-back of the output), so the synchronization validation layer sees every hazard
//! covered.

use ash::vk;

use crate::backend::bindings::{bind_by_name, SetBinding};
use crate::backend::resources::{GpuImage, ImageDesc};
use crate::backend::shader::{create_shader_module, PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::error::VkResultExt;
use crate::frame::Renderer;
use crate::{LucentError, Result};

use super::controls::{Comparison, DIFFERENCE_GAIN};

/// The shader, relative to the GLSL root.
pub const SHADER: &str = "demo/compare.comp";

/// The shader's storage images in binding order: the plain frame, the technique's, the output
/// (the shader takes their numbers from here by name, `backend::bindings`).
const IMAGES: [SetBinding<'static>; 3] = [
    storage_image("plain_image"),
    storage_image("technique_image"),
    storage_image("out_image"),
];

/// A storage image binding the shader calls `name`.
const fn storage_image(name: &'static str) -> SetBinding<'static> {
    SetBinding {
        name: Some(name),
        kind: vk::DescriptorType::STORAGE_IMAGE,
    }
}
/// The shader's work group edge (`local_size_x`, `local_size_y`).
const GROUP: u32 = 8;
/// The format of the display images and of the comparison's own images.
const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// The shader's push constants (`Compare` in the shader).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Push {
    split_x: i32,
    difference: i32,
    gain: f32,
}

/// The push constants for `comparison` at `width` columns.
fn push_for(comparison: Comparison, width: u32) -> Push {
    Push {
        split_x: if comparison.split {
            (width / 2) as i32
        } else {
            0
        },
        difference: i32::from(comparison.difference),
        gain: DIFFERENCE_GAIN,
    }
}

/// The comparison pass: its pipeline, and its images at one size.
pub struct Comparer {
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    /// Copies of the plain and the technique's display images, and the output.
    images: Option<[GpuImage; 3]>,
    /// Whether `record` ran since the images were (re)created: the output has contents.
    written: bool,
}

impl Comparer {
    /// Compiles the shader and creates the pipeline. Errors: a shader that does not compile
    /// (with shaderc's message), Vulkan failures.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
    ) -> Result<Self> {
        let mut compiled = shaders.compile(SHADER, &[])?;
        bind_by_name(&mut compiled.spirv, &IMAGES).map_err(|message| {
            LucentError::ShaderBindings {
                pipeline: "demo compare".into(),
                shader: SHADER.into(),
                message,
            }
        })?;
        let device = &gpu.device;
        let mut comparer = Self {
            set_layout: vk::DescriptorSetLayout::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            images: None,
            written: false,
        };
        let bindings: Vec<_> = (0..IMAGES.len() as u32)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(IMAGES[b as usize].kind)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let created = (|| -> Result<()> {
            // SAFETY: valid create infos; every object is destroyed in `destroy` (null
            // handles of a failed creation are ignored there).
            unsafe {
                comparer.set_layout = device
                    .create_descriptor_set_layout(
                        &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                        None,
                    )
                    .vk("vkCreateDescriptorSetLayout")?;
                let ranges = [vk::PushConstantRange::default()
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
                    .size(std::mem::size_of::<Push>() as u32)];
                let set_layouts = [comparer.set_layout];
                comparer.layout = device
                    .create_pipeline_layout(
                        &vk::PipelineLayoutCreateInfo::default()
                            .set_layouts(&set_layouts)
                            .push_constant_ranges(&ranges),
                        None,
                    )
                    .vk("vkCreatePipelineLayout")?;
                let module = create_shader_module(device, &compiled.spirv)?;
                let stage = vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::COMPUTE)
                    .module(module)
                    .name(c"main");
                let info = vk::ComputePipelineCreateInfo::default()
                    .stage(stage)
                    .layout(comparer.layout);
                let pipelines =
                    device.create_compute_pipelines(pipeline_cache.handle, &[info], None);
                device.destroy_shader_module(module, None);
                comparer.pipeline = pipelines
                    .map_err(|(_, e)| e)
                    .vk("vkCreateComputePipelines")?[0];
                let sizes = [vk::DescriptorPoolSize::default()
                    .ty(vk::DescriptorType::STORAGE_IMAGE)
                    .descriptor_count(3)];
                comparer.pool = device
                    .create_descriptor_pool(
                        &vk::DescriptorPoolCreateInfo::default()
                            .max_sets(1)
                            .pool_sizes(&sizes),
                        None,
                    )
                    .vk("vkCreateDescriptorPool")?;
                comparer.set = device
                    .allocate_descriptor_sets(
                        &vk::DescriptorSetAllocateInfo::default()
                            .descriptor_pool(comparer.pool)
                            .set_layouts(&set_layouts),
                    )
                    .vk("vkAllocateDescriptorSets")?[0];
            }
            gpu.set_name(comparer.pipeline, "demo compare");
            Ok(())
        })();
        match created {
            Ok(()) => Ok(comparer),
            Err(e) => {
                comparer.destroy(gpu);
                Err(e)
            }
        }
    }

    /// Makes the images `width` x `height` (recreated only when the size changes). The GPU
    /// must not be using them (every demo frame is waited for).
    fn ensure_images(&mut self, gpu: &GpuContext, width: u32, height: u32) -> Result<()> {
        if self
            .images
            .as_ref()
            .is_some_and(|i| (i[2].desc.width, i[2].desc.height) == (width, height))
        {
            return Ok(());
        }
        if let Some(old) = self.images.take() {
            for image in old {
                gpu.destroy_image(image);
            }
        }
        self.written = false;
        let input = ImageDesc::color(
            width,
            height,
            FORMAT,
            vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::STORAGE,
        );
        let output = ImageDesc::color(
            width,
            height,
            FORMAT,
            vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC,
        );
        let plain = gpu.create_image(&input, "demo compare plain")?;
        let technique = match gpu.create_image(&input, "demo compare technique") {
            Ok(i) => i,
            Err(e) => {
                gpu.destroy_image(plain);
                return Err(e);
            }
        };
        let out = match gpu.create_image(&output, "demo compare output") {
            Ok(i) => i,
            Err(e) => {
                gpu.destroy_image(plain);
                gpu.destroy_image(technique);
                return Err(e);
            }
        };
        let infos: Vec<[vk::DescriptorImageInfo; 1]> = [&plain, &technique, &out]
            .iter()
            .map(|i| {
                [vk::DescriptorImageInfo::default()
                    .image_view(i.view)
                    .image_layout(vk::ImageLayout::GENERAL)]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .enumerate()
            .map(|(b, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(b as u32)
                    .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                    .image_info(info)
            })
            .collect();
        // SAFETY: the set is not in use by the GPU (see above); the views are alive.
        unsafe { gpu.device.update_descriptor_sets(&writes, &[]) };
        self.images = Some([plain, technique, out]);
        Ok(())
    }

    /// Records the comparison of `plain`'s and `technique`'s last frames (recorded earlier in
    /// `cmd`, their display images in their export layouts) into the output image, and leaves
    /// it in `TRANSFER_SRC_OPTIMAL`, visible to transfer reads. Returns the output image.
    pub fn record(
        &mut self,
        gpu: &GpuContext,
        cmd: vk::CommandBuffer,
        plain: &Renderer,
        technique: &Renderer,
        comparison: Comparison,
    ) -> Result<vk::Image> {
        let display = |r: &Renderer| -> Result<(vk::Image, vk::ImageLayout, u32, u32)> {
            let image = r
                .executable
                .owned_image(r.outputs.display)
                .ok_or_else(|| LucentError::Graph("the display image is not readable".into()))?;
            let layout = r
                .executable
                .export_layout(r.outputs.display)
                .unwrap_or(vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
            Ok((image.image, layout, image.desc.width, image.desc.height))
        };
        let (plain_image, plain_layout, w, h) = display(plain)?;
        let (tech_image, tech_layout, tw, th) = display(technique)?;
        if (w, h) != (tw, th) {
            return Err(LucentError::InvalidInput(format!(
                "comparison of frames of different sizes ({w}x{h} and {tw}x{th})"
            )));
        }
        self.ensure_images(gpu, w, h)?;
        let Some([copy_plain, copy_tech, out]) = self.images.as_ref() else {
            return Err(LucentError::InvalidInput(
                "comparison images missing".into(),
            ));
        };
        let device = &gpu.device;
        let color = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(1);
        let layers = vk::ImageSubresourceLayers::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .layer_count(1);
        let barrier = |image: vk::Image| {
            vk::ImageMemoryBarrier2::default()
                .image(image)
                .subresource_range(color)
        };
        // The copies overwrite what the previous frame's shader read: an execution dependency
        // on those reads (write-after-read) and a layout change that discards the contents.
        let to_copy = [copy_plain, copy_tech].map(|i| {
            barrier(i.image)
                .src_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
                .src_access_mask(vk::AccessFlags2::NONE)
                .dst_stage_mask(vk::PipelineStageFlags2::COPY)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
        });
        let region = vk::ImageCopy::default()
            .src_subresource(layers)
            .dst_subresource(layers)
            .extent(vk::Extent3D {
                width: w,
                height: h,
                depth: 1,
            });
        // Each copy, written by the transfer above, is read by the compute shader.
        let copied_to_shader = |image| {
            barrier(image)
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
                .dst_access_mask(vk::AccessFlags2::SHADER_STORAGE_READ)
                .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .new_layout(vk::ImageLayout::GENERAL)
        };
        let to_shader = [
            copied_to_shader(copy_plain.image),
            copied_to_shader(copy_tech.image),
            // The output was last read by a blit or a read-back copy (transfer).
            barrier(out.image)
                .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
                .src_access_mask(vk::AccessFlags2::NONE)
                .dst_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
                .dst_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::GENERAL),
        ];
        let to_transfer = [barrier(out.image)
            .src_stage_mask(vk::PipelineStageFlags2::COMPUTE_SHADER)
            .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .dst_access_mask(vk::AccessFlags2::TRANSFER_READ)
            .old_layout(vk::ImageLayout::GENERAL)
            .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)];
        let push = push_for(comparison, w);
        gpu.begin_label(cmd, "compare");
        // SAFETY: recording; the display images are in their export layouts and readable by
        // transfer (the frames' export barriers), the comparison's images were transitioned
        // above, the set points at them.
        unsafe {
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_copy),
            );
            device.cmd_copy_image(
                cmd,
                plain_image,
                plain_layout,
                copy_plain.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            device.cmd_copy_image(
                cmd,
                tech_image,
                tech_layout,
                copy_tech.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_shader),
            );
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            device.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::COMPUTE,
                self.layout,
                0,
                &[self.set],
                &[],
            );
            device.cmd_push_constants(
                cmd,
                self.layout,
                vk::ShaderStageFlags::COMPUTE,
                0,
                bytemuck::bytes_of(&push),
            );
            device.cmd_dispatch(cmd, w.div_ceil(GROUP), h.div_ceil(GROUP), 1);
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&to_transfer),
            );
        }
        gpu.end_label(cmd);
        self.written = true;
        Ok(out.image)
    }

    /// Reads the last comparison back: RGBA8, sRGB-encoded, tightly packed, with its size.
    /// `None` before the first [`Self::record`] at the current size.
    pub fn read(&self, gpu: &GpuContext) -> Result<Option<(u32, u32, Vec<u8>)>> {
        match (&self.images, self.written) {
            (Some([_, _, out]), true) => Ok(Some((
                out.desc.width,
                out.desc.height,
                gpu.read_image(out, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)?,
            ))),
            _ => Ok(None),
        }
    }

    /// Destroys the pipeline and the images. The GPU must be done with them.
    pub fn destroy(mut self, gpu: &GpuContext) {
        if let Some(images) = self.images.take() {
            for image in images {
                gpu.destroy_image(image);
            }
        }
        let device = &gpu.device;
        // SAFETY: the caller guarantees the GPU is done; null handles are ignored.
        unsafe {
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_descriptor_pool(self.pool, None);
            device.destroy_pipeline_layout(self.layout, None);
            device.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_constants_follow_the_comparison() {
        let split = push_for(
            Comparison {
                split: true,
                difference: false,
            },
            321,
        );
        assert_eq!((split.split_x, split.difference), (160, 0));
        let diff = push_for(
            Comparison {
                split: false,
                difference: true,
            },
            320,
        );
        assert_eq!((diff.split_x, diff.difference), (0, 1));
        assert_eq!(diff.gain, DIFFERENCE_GAIN);
    }
}
