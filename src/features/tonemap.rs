//! HDR to display: exposure, ACES fit, sRGB encoding into an RGBA8 UNORM target.
//!
//! The tonemap samples its input rather than reading it as an input attachment: it is where the
//! post chain (SSS blurs, which read neighbourhoods) ends, so it is its own physical pass with
//! its own timing row whatever precedes it.

use std::sync::Arc;

use ash::vk;

use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

use super::util::{clamp_sampler, Binding, GraphicsPipelineDesc, PassPipeline, VertexInput};
use crate::gpu_scene::SceneGpu;

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
        }),
        None => pass.finish(),
    }
    ldr
}

struct TonemapPass {
    scene: Arc<SceneGpu>,
    input: ResourceId,
    sampler: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl PassExec for TonemapPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[
                Binding::Uniform(self.scene.frame_uniforms),
                Binding::Sampled(ctx.views[self.input], self.sampler),
            ],
            &GraphicsPipelineDesc {
                vertex: "fullscreen.vert",
                fragment: "post/tonemap.frag",
                defines: &[],
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                additive_attachments: 0,
                set_layouts: &[],
                push_constant_bytes: 0,
                name: "tonemap",
            },
        )?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        if let Some(pipeline) = &self.pipeline {
            pipeline.draw_fullscreen(ctx);
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created in prepare (or null); the GPU is done (caller's contract).
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}
