//! Deferred shading: the MRT G-buffer pass and the lighting pass that reads it at the same pixel
//! (input attachments), so the graph merges the two into subpasses of one render pass.
//! G-buffer layout and bit budget: glsl/common/gbuffer.glsl.

use std::sync::Arc;

use ash::vk;

use crate::backend::access::Access;
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph,
};
use crate::Result;

use super::util::{Binding, GraphicsPipelineDesc, PassPipeline, VertexInput};
use super::SceneGpu;

/// G-buffer target formats (see glsl/common/gbuffer.glsl).
pub const GB0_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Normal + roughness.
pub const GB1_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Depth.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Lit HDR colour.
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The G-buffer's handles.
pub struct GBuffer {
    /// Albedo + specular.
    pub gb0: Handle<Image>,
    /// Normal + roughness.
    pub gb1: Handle<Image>,
    /// Depth.
    pub depth: Handle<Image>,
}

/// Declares the G-buffer pass. `scene` is `None` for plan-only graphs (`lucent plan`).
pub fn gbuffer_pass(
    graph: &mut RenderGraph,
    width: u32,
    height: u32,
    scene: Option<&Arc<SceneGpu>>,
) -> GBuffer {
    let image = |format| ImageInfo {
        width,
        height,
        format,
    };
    let mut gb = GBuffer {
        gb0: graph.create_image("gbuffer.albedo", image(GB0_FORMAT)),
        gb1: graph.create_image("gbuffer.normal", image(GB1_FORMAT)),
        depth: graph.create_image("gbuffer.depth", image(DEPTH_FORMAT)),
    };
    let mut pass = graph.add_pass("gbuffer", PassKind::Raster);
    pass.color(&mut gb.gb0, LoadOp::Clear([0.0; 4]))
        .color(&mut gb.gb1, LoadOp::Clear([0.0, 1.0, 0.0, 1.0]))
        .depth(&mut gb.depth, LoadOp::Clear([1.0; 4]));
    match scene {
        Some(scene) => pass.execute(GBufferPass {
            scene: scene.clone(),
            pipeline: None,
        }),
        None => pass.finish(),
    }
    gb
}

/// Declares the lighting pass: reads the G-buffer at the same pixel, writes lit HDR colour.
pub fn lighting_pass(
    graph: &mut RenderGraph,
    gb: &GBuffer,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let info = graph.resources()[gb.gb0.id()].info;
    let mut hdr = graph.create_image(
        "hdr",
        ImageInfo {
            format: HDR_FORMAT,
            ..info
        },
    );
    let mut pass = graph.add_pass("lighting", PassKind::Raster);
    pass.input(&gb.gb0)
        .input(&gb.gb1)
        .input(&gb.depth)
        .color(&mut hdr, LoadOp::DontCare);
    let inputs = [gb.gb0.id(), gb.gb1.id(), gb.depth.id()];
    match scene {
        Some(scene) => pass.execute(LightingPass {
            scene: scene.clone(),
            inputs,
            pipeline: None,
        }),
        None => pass.finish(),
    }
    hdr
}

struct GBufferPass {
    scene: Arc<SceneGpu>,
    pipeline: Option<PassPipeline>,
}

impl PassExec for GBufferPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[Binding::Uniform(self.scene.frame_uniforms)],
            &GraphicsPipelineDesc {
                vertex: "deferred/gbuffer.vert",
                fragment: "deferred/gbuffer.frag",
                defines: &[],
                vertex_input: VertexInput::PositionNormal,
                depth_test: true,
                cull_back: true,
                set_layouts: &[],
                push_constant_bytes: std::mem::size_of::<super::ObjectConstants>() as u32,
                name: "gbuffer",
            },
        )?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        let device = &ctx.gpu.device;
        // SAFETY: the pipeline is bound inside this pass's subpass; buffers are alive.
        unsafe {
            for draw in &self.scene.draws {
                let mesh = &self.scene.meshes[draw.mesh];
                device.cmd_push_constants(
                    ctx.cmd,
                    pipeline.pipeline.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&draw.constants),
                );
                device.cmd_bind_vertex_buffers(ctx.cmd, 0, &[mesh.vertices.buffer], &[0]);
                device.cmd_bind_index_buffer(
                    ctx.cmd,
                    mesh.indices.buffer,
                    0,
                    vk::IndexType::UINT32,
                );
                device.cmd_draw_indexed(ctx.cmd, mesh.index_count, 1, 0, 0, 0);
            }
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
    }
}

struct LightingPass {
    scene: Arc<SceneGpu>,
    inputs: [crate::graph::ResourceId; 3],
    pipeline: Option<PassPipeline>,
}

impl PassExec for LightingPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let [gb0, gb1, depth] = self.inputs;
        let color_layout = Access::InputAttachmentRead.info().layout;
        let depth_layout = Access::DepthInputAttachmentRead.info().layout;
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[
                Binding::Uniform(self.scene.frame_uniforms),
                Binding::InputAttachment(ctx.views[gb0], color_layout),
                Binding::InputAttachment(ctx.views[gb1], color_layout),
                Binding::InputAttachment(ctx.views[depth], depth_layout),
            ],
            &GraphicsPipelineDesc {
                vertex: "fullscreen.vert",
                fragment: "deferred/lighting.frag",
                defines: &[],
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                set_layouts: &[],
                push_constant_bytes: 0,
                name: "lighting",
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
    }
}
