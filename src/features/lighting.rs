//! Deferred lighting: the pass that reads the G-buffer ([`super::gbuffer`]) at the same pixel
//! (input attachments, so the graph merges it with the G-buffer pass as a subpass) and the
//! light-space maps, when some light casts shadows, and writes lit HDR colour (with SSS,
//! diffuse and specular apart).
//!
//! With translucency (GDC 2011) the G-buffer has GB2 (thickness + material ID), and the
//! lighting pass is drawn as scissored rectangles of screen tiles: tiles that translucent objects
//! may cover (their projected bounding boxes, on the CPU each frame) get the shader with the
//! talk's per-light term, the others the plain shader. Only rasterisation reliably skips work on every
//! driver: lavapipe shades both sides of a per-pixel branch, and it runs input-attachment
//! shaders with late depth/stencil tests, so neither a material-ID branch nor a stencil mask
//! saves anything there (measured in docs/translucency.md).

use std::sync::Arc;

use ash::vk;

use crate::backend::access::Access;
use crate::backend::shader::PipelineShaders;
use crate::gpu_scene::{Region, SceneGpu};
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

use super::gbuffer::{all_layouts, GBuffer, GBufferLayout};
use super::shadows::{self, ShadowMaps};
use super::util::{
    check_bindings, clamp_sampler, Binding, Defines, GraphicsPipeline, GraphicsPipelineDesc,
    PassPipeline,
};

/// Lit HDR colour.
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// What the lighting pass writes.
pub struct Lit {
    /// Lit HDR colour; with SSS, the diffuse part only.
    pub color: Handle<Image>,
    /// With SSS: the specular part, added back after the blurs.
    pub specular: Option<Handle<Image>>,
}

/// Declares the lighting pass: reads the G-buffer at the same pixel (and the light-space maps,
/// when some light casts shadows), writes lit HDR colour (with SSS: diffuse and specular
/// apart).
pub fn lighting_pass(
    graph: &mut RenderGraph,
    gb: &GBuffer,
    shadows: Option<&ShadowMaps>,
    scene: Option<&Arc<SceneGpu>>,
) -> Lit {
    let info = graph.resources()[gb.gb0.id()].info;
    let hdr_info = ImageInfo {
        format: HDR_FORMAT,
        ..info
    };
    let mut hdr = graph.create_image(
        if gb.layout.sss {
            "lighting.diffuse"
        } else {
            "hdr"
        },
        hdr_info,
    );
    let mut specular = gb
        .layout
        .sss
        .then(|| graph.create_image("lighting.specular", hdr_info));
    let mut pass = graph.add_pass("lighting", PassKind::Raster);
    pass.input(&gb.gb0).input(&gb.gb1).input(&gb.depth);
    if let Some(gb2) = &gb.gb2 {
        pass.input(gb2);
    }
    if let Some(maps) = shadows {
        pass.sample(&maps.depth);
        if let Some(ids) = &maps.ids {
            pass.sample(ids);
        }
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    if let Some(specular) = &mut specular {
        pass.color(specular, LoadOp::DontCare);
    }
    let inputs = LightingInputs {
        gb0: gb.gb0.id(),
        gb1: gb.gb1.id(),
        depth: gb.depth.id(),
        gb2: gb.gb2.as_ref().map(|h| h.id()),
        shadow_depth: shadows.map(|m| m.depth.id()),
        shadow_ids: shadows.and_then(|m| m.ids.as_ref().map(|h| h.id())),
    };
    match scene {
        Some(scene) => pass.execute(LightingPass {
            scene: scene.clone(),
            inputs,
            layout: gb.layout,
            pipeline: None,
            translucent: None,
            sampler: vk::Sampler::null(),
        }),
        None => pass.finish(),
    }
    Lit {
        color: hdr,
        specular,
    }
}

/// The lighting pass's fragment shader.
const LIGHTING_FRAGMENT: &str = "deferred/lighting.frag";

/// The lighting pass's descriptor bindings before the shadow bindings
/// (glsl/deferred/lighting.frag): 0-3 always, 4 (GB2) and 5 (material table) with translucency.
fn lighting_bindings_before_shadows(layout: &GBufferLayout) -> usize {
    4 + 2 * usize::from(layout.translucency.is_some())
}

/// The lighting pass's defines: the plain shader's, and with translucency the extra ones of the
/// translucent variant (drawn on the tiles translucent objects may cover). `shadows`: some
/// light casts shadows, `Some(true)` when the atlas stores translucency IDs.
fn lighting_defines(layout: &GBufferLayout, shadows: Option<bool>) -> (Defines, Option<Defines>) {
    let mut plain: Vec<(&'static str, &'static str)> = Vec::new();
    if shadows.is_some() {
        plain.extend(shadows::lighting_defines(lighting_bindings_before_shadows(
            layout,
        )));
    }
    if layout.sss {
        plain.push(("LUCENT_SPLIT_SPECULAR", "1"));
    }
    if layout.lean {
        plain.push(("LUCENT_LEAN", "1"));
    }
    if layout.depth_in_alpha {
        plain.push(("LUCENT_DEPTH_IN_ALPHA", "1"));
    }
    if layout.fault_injection {
        plain.push(("LUCENT_FAULT_INJECTION", "1"));
    }
    let translucent = layout.translucency.map(|_| {
        // The plain variant's defines (split specular, LEAN slope) plus the translucency's.
        let mut extra = layout.defines();
        if shadows == Some(true) {
            // Only the translucent variant shades transmission: only it reads the IDs.
            extra.push(("LUCENT_SHADOW_IDS", "1"));
        }
        extra
    });
    (plain, translucent)
}

/// The pipelines the lighting pass of any frame builds: every G-buffer layout, without
/// shadows and with them (with and without translucency IDs).
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for layout in all_layouts() {
        for shadows in [None, Some(false), Some(true)] {
            let (plain, translucent) = lighting_defines(&layout, shadows);
            let fullscreen =
                |defines: &[(&str, &str)]| PipelineShaders::fullscreen(LIGHTING_FRAGMENT, defines);
            out.push(fullscreen(&plain));
            if let Some(extra) = translucent {
                let mut all = plain.clone();
                all.extend(extra);
                out.push(fullscreen(&all));
            }
        }
    }
}

/// The G-buffer images the lighting pass reads.
struct LightingInputs {
    gb0: ResourceId,
    gb1: ResourceId,
    depth: ResourceId,
    gb2: Option<ResourceId>,
    /// The light-space maps' depth and ID atlases, when some light casts shadows.
    shadow_depth: Option<ResourceId>,
    shadow_ids: Option<ResourceId>,
}

struct LightingPass {
    scene: Arc<SceneGpu>,
    inputs: LightingInputs,
    layout: GBufferLayout,
    /// The plain shader: every pixel, or with translucency the tiles no translucent object
    /// touches.
    pipeline: Option<PassPipeline>,
    /// With translucency: the translucency shader for the other tiles (same set).
    translucent: Option<GraphicsPipeline>,
    /// Nearest clamp sampler for the light-space maps (null without shadows).
    sampler: vk::Sampler,
}

impl PassExec for LightingPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let inputs = &self.inputs;
        let color_layout = Access::InputAttachmentRead.info().layout;
        let depth_layout = Access::DepthInputAttachmentRead.info().layout;
        let views = ctx.descriptor_views;
        // Bindings 0-3 always; 4 (GB2) and 5 (material table) only with translucency
        // (glsl/deferred/lighting.frag).
        let mut bindings = vec![
            Binding::PerFrame(self.scene.per_frame.binding(Region::Frame)),
            Binding::InputAttachment(views[inputs.gb0], color_layout),
            Binding::InputAttachment(views[inputs.gb1], color_layout),
            Binding::InputAttachment(views[inputs.depth], depth_layout),
        ];
        if let Some(gb2) = inputs.gb2 {
            bindings.push(Binding::InputAttachment(views[gb2], color_layout));
            bindings.push(Binding::PerFrame(
                self.scene.per_frame.binding(Region::Translucency),
            ));
        }
        let shadow_ids = inputs.shadow_depth.map(|_| inputs.shadow_ids.is_some());
        let (plain_defines, translucent_defines) = lighting_defines(&self.layout, shadow_ids);
        if let Some(depth) = inputs.shadow_depth {
            self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
            // The shadow table, then the atlases (glsl/common/shadows.glsl).
            check_bindings(
                "lighting",
                bindings.len(),
                lighting_bindings_before_shadows(&self.layout),
            )?;
            bindings.extend(shadows::lighting_bindings(
                &self.scene,
                depth,
                inputs.shadow_ids,
                views,
                self.sampler,
            ));
        }
        let plain = GraphicsPipelineDesc::fullscreen(LIGHTING_FRAGMENT, &plain_defines, "lighting");
        let mut pipeline = PassPipeline::new(ctx, &bindings, &plain)?;
        if let Some(extra) = translucent_defines {
            let (plain_pipeline, translucent) =
                pipeline.with_variant(ctx, &plain, &extra, "lighting (translucent)")?;
            pipeline = plain_pipeline;
            self.translucent = Some(translucent);
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        let Some(translucent) = &self.translucent else {
            pipeline.draw_fullscreen(ctx);
            return;
        };
        let rects = self.scene.per_frame.tiles(ctx.frame).lighting.clone();
        pipeline.bind(ctx);
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| !r.translucent));
        // SAFETY: made for this subpass with the bound set's layout.
        unsafe {
            ctx.gpu.device.cmd_bind_pipeline(
                ctx.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                translucent.pipeline,
            );
        }
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent));
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.translucent.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created in prepare (or null); the GPU is done (caller's contract).
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}
