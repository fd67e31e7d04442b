//! HDR to display: exposure, ACES fit, sRGB encoding into an RGBA8 UNORM target.
//!
//! The tonemap samples its input rather than reading it as an input attachment: it is where the
//! post chain (SSS blurs, which read neighbourhoods) ends, so it is its own physical pass with
//! its own timing row whatever precedes it.

use std::sync::Arc;

use ash::vk;

use crate::error::VkResultExt;
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

use super::util::{Binding, DescriptorSet, GraphicsPipeline, GraphicsPipelineDesc, VertexInput};
use super::SceneGpu;

/// Display target format: sRGB-encoded by the shader, stored as UNORM.
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// Declares the tonemap pass: samples `hdr`, writes a new display image.
pub fn tonemap_pass(
    graph: &mut RenderGraph,
    hdr: &Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let info = graph.resources()[hdr.id()].info;
    let mut ldr = graph.create_image(
        "display",
        ImageInfo {
            format: LDR_FORMAT,
            ..info
        },
    );
    let mut pass = graph.add_pass("tonemap", PassKind::Raster);
    pass.sample(hdr).color(&mut ldr, LoadOp::DontCare);
    match scene {
        Some(scene) => pass.execute(TonemapPass {
            scene: scene.clone(),
            input: hdr.id(),
            sampler: vk::Sampler::null(),
            pipeline: None,
            set: None,
        }),
        None => pass.finish(),
    }
    ldr
}

struct TonemapPass {
    scene: Arc<SceneGpu>,
    input: ResourceId,
    sampler: vk::Sampler,
    pipeline: Option<GraphicsPipeline>,
    set: Option<DescriptorSet>,
}

impl PassExec for TonemapPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        // SAFETY: valid device and create info.
        self.sampler =
            unsafe { ctx.gpu.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
        let set = DescriptorSet::new(
            ctx,
            &[
                Binding::Uniform(self.scene.frame_uniforms),
                Binding::Sampled(ctx.views[self.input], self.sampler),
            ],
            vk::ShaderStageFlags::FRAGMENT,
            "tonemap",
        )?;
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsPipelineDesc {
                vertex: "fullscreen.vert",
                fragment: "post/tonemap.frag",
                defines: &[],
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                set_layouts: &[set.layout],
                push_constant_bytes: 0,
                name: "tonemap",
            },
        );
        self.set = Some(set);
        self.pipeline = Some(pipeline?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        if let (Some(pipeline), Some(set)) = (&self.pipeline, &self.set) {
            draw_fullscreen(ctx, pipeline, set);
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut s) = self.set.take() {
            s.destroy(&gpu.device);
        }
        // SAFETY: created in prepare; the GPU is done (caller's contract).
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}

/// Binds `pipeline` and `set` and draws the fullscreen triangle.
pub(crate) fn draw_fullscreen(
    ctx: &RecordContext<'_>,
    pipeline: &GraphicsPipeline,
    set: &DescriptorSet,
) {
    let device = &ctx.gpu.device;
    // SAFETY: pipeline and set are alive; the executor began this pass's subpass.
    unsafe {
        device.cmd_bind_pipeline(ctx.cmd, vk::PipelineBindPoint::GRAPHICS, pipeline.pipeline);
        device.cmd_bind_descriptor_sets(
            ctx.cmd,
            vk::PipelineBindPoint::GRAPHICS,
            pipeline.layout,
            0,
            &[set.set],
            &[],
        );
        device.cmd_draw(ctx.cmd, 3, 1, 0, 0);
    }
}
