//! The thesis's iterative chains (control, LCB, LBB): one horizontal + vertical blur pair per
//! Gaussian of the longest profile in the chain, each step blurring the previous result by the
//! variance the next Gaussian adds, accumulated into the sum of Gaussians, then the chain's
//! final pass (`combine` or LEAN `final lighting`).

use std::sync::Arc;

use ash::vk;

use super::{
    chain_tiles, per_frame_bindings, push_constants, BlurConstants, Chain, SssBlur,
    SssBlurTechnique, SssInputs, SssKnobs, LEAN_FINAL_SHADER, PACKED_FORMAT,
};
use crate::backend::shader::PipelineShaders;
use crate::features::lighting::HDR_FORMAT;
use crate::features::technique::{Shades, TechniqueModule};
use crate::features::util::{
    check_bindings, clamp_sampler, Binding, Defines, GraphicsPipelineDesc, PassPipeline,
};
use crate::gpu_scene::SceneGpu;
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

/// Declares an iterative chain (see the module docs). Returns the chain's result (`output`
/// when given).
pub(super) fn chain_passes(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    chain: &Chain,
    base: Option<&Handle<Image>>,
    knobs: &SssKnobs,
    scene: Option<&Arc<SceneGpu>>,
    output: Option<Handle<Image>>,
) -> Handle<Image> {
    let blur = chain.blur;
    let info = ImageInfo {
        format: HDR_FORMAT,
        ..graph.resources()[inputs.diffuse.id()].info
    };
    let sum_info = ImageInfo {
        format: knobs.precision.format(),
        ..info
    };
    // LCB and LBB blur two texels per pixel (light + slope x, slope y + moments), the control one.
    let lean = match (blur.lean(), inputs.lean) {
        (true, Some(l)) => Some(l),
        _ => None,
    };
    let targets = if lean.is_some() { 2 } else { 1 };
    let packed = packed_pingpong(blur.technique(), lean.is_some(), knobs.packed);
    let names = ["", ".lean"];
    // The ping-pong targets: one packed RGBA32UI texel, or one RGBA16F per blurred texel.
    let (pingpong, pingpong_info) = if packed {
        let packed_info = ImageInfo {
            format: PACKED_FORMAT,
            ..info
        };
        (1, packed_info)
    } else {
        (targets, info)
    };
    let mut temp: Vec<Handle<Image>> = (0..pingpong)
        .map(|t| {
            graph.create_image(
                &chain.image_name(&format!("temp{}", names[t])),
                pingpong_info,
            )
        })
        .collect();
    let mut current: Vec<Handle<Image>> = (0..pingpong)
        .map(|t| {
            graph.create_image(
                &chain.image_name(&format!("current{}", names[t])),
                pingpong_info,
            )
        })
        .collect();
    let mut sum: Vec<Handle<Image>> = (0..targets)
        .map(|t| graph.create_image(&chain.image_name(&format!("sum{}", names[t])), sum_info))
        .collect();
    // Texture fetches per pixel of a pass reading `texels` colour images, for the benchmark's
    // cost per tap: the centre texels, depth and profile ID, then each kernel tap's texels and
    // depth (the control: Jimenez's six bilinear taps around its centre; the bilateral blur:
    // its point taps, centre included), and with several profiles each tap's profile ID.
    let fetches = |texels: u32| {
        let kernel = if blur.bilateral() { knobs.taps } else { 6 };
        let per_tap = texels + 1 + u32::from(chain.edges);
        texels + 2 + kernel * per_tap
    };
    for step in 0..chain.steps {
        let n = step + 1;
        // Horizontal: the previous result (the lit diffuse the first time) into the temporary.
        let source_handles: Vec<&Handle<Image>> = if step == 0 {
            std::iter::once(inputs.diffuse)
                .chain(lean.map(|l| l.view_plane))
                .collect()
        } else {
            current.iter().collect()
        };
        let mut pass = graph.add_pass(
            &format!("{}horizontal blur #{n}", chain.prefix),
            PassKind::Raster,
        );
        for h in &source_handles {
            pass.sample(h);
        }
        pass.sample(inputs.depth)
            .sample(inputs.profile_ids)
            .taps(fetches(source_handles.len() as u32));
        let sources: Vec<ResourceId> = source_handles.iter().map(|h| h.id()).collect();
        for t in &mut temp {
            pass.color(t, LoadOp::DontCare);
        }
        let exec = |direction: [f32; 2],
                    accumulate: bool,
                    colors: Vec<ResourceId>,
                    scene: &Arc<SceneGpu>| BlurPass {
            scene: scene.clone(),
            packed_in: packed && colors.len() == 1,
            packed_out: packed,
            sums: if accumulate { targets } else { 0 },
            taps: knobs.taps,
            colors,
            depth: inputs.depth.id(),
            profile_ids: inputs.profile_ids.id(),
            constants: BlurConstants {
                step: [direction[0], direction[1], step as f32, chain.index as f32],
            },
            blur,
            edges: chain.edges,
            chain: chain.index,
            sampler: vk::Sampler::null(),
            nearest: vk::Sampler::null(),
            pipeline: None,
        };
        match scene {
            Some(scene) => pass.execute(exec([1.0, 0.0], false, sources, scene)),
            None => pass.finish(),
        }
        // Vertical: back into the current result, and its weighted share into the sum.
        let mut pass = graph.add_pass(
            &format!("{}vertical blur #{n}", chain.prefix),
            PassKind::Raster,
        );
        for t in &temp {
            pass.sample(t);
        }
        pass.sample(inputs.depth)
            .sample(inputs.profile_ids)
            .taps(fetches(temp.len() as u32));
        for c in &mut current {
            pass.color(c, LoadOp::DontCare);
        }
        for s in &mut sum {
            pass.color(
                s,
                if step == 0 {
                    LoadOp::Clear([0.0; 4])
                } else {
                    LoadOp::Load
                },
            );
        }
        let temps = temp.iter().map(|h| h.id()).collect();
        match scene {
            Some(scene) => pass.execute(exec([0.0, 1.0], true, temps, scene)),
            None => pass.finish(),
        }
    }
    let mut hdr = output.unwrap_or_else(|| {
        graph.create_image(
            &if chain.last {
                "hdr".to_string()
            } else {
                chain.image_name("result")
            },
            info,
        )
    });
    let (name, fragment) = match lean {
        None => ("combine", COMBINE_FRAGMENT),
        Some(_) => ("final lighting", LEAN_FINAL_SHADER),
    };
    let mut pass = graph.add_pass(&format!("{}{name}", chain.prefix), PassKind::Raster);
    // Inputs in the shader's binding order (after the frame uniforms and the profile table).
    let mut reads: Vec<&Handle<Image>> = sum.iter().collect();
    reads.extend([inputs.diffuse, inputs.specular, inputs.profile_ids]);
    if let Some(l) = lean {
        reads.extend([inputs.depth, l.gb0, l.gb1]);
    }
    reads.extend(base);
    for h in &reads {
        pass.sample(h);
    }
    // LEAN specular is direct light: the light-space maps shadow it.
    let shadow_depth = inputs.shadow_depth.filter(|_| lean.is_some());
    if let Some(depth) = shadow_depth {
        pass.sample(depth);
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    let ids = reads.iter().map(|h| h.id()).collect();
    match scene {
        Some(scene) => pass.execute(FinalPass {
            shadow_depth: shadow_depth.map(|h| h.id()),
            scene: scene.clone(),
            inputs: ids,
            fragment,
            chain: chain.index,
            base: base.is_some(),
            sampler: vk::Sampler::null(),
            pipeline: None,
            passthrough: None,
        }),
        None => pass.finish(),
    }
    hdr
}

/// The iterative blur's fragment shader.
const BLUR_FRAGMENT: &str = "sss/blur.frag";
/// The control chain's final pass.
const COMBINE_FRAGMENT: &str = "sss/combine.frag";

/// Whether a chain's ping-pong targets are one packed RGBA32UI texel: LBB with the LEAN
/// target, when the `packed` knob asks.
fn packed_pingpong(blur: &dyn SssBlurTechnique, lean: bool, packed: bool) -> bool {
    lean && blur.bilateral() && packed
}

/// The iterative blur pass's defines: the chain's blur, bilateral `taps` per direction,
/// profile edges, LBB's packed input and output, and whether it accumulates into the sums.
fn blur_defines(
    blur: &dyn SssBlurTechnique,
    taps: u32,
    edges: bool,
    packed_in: bool,
    packed_out: bool,
    accumulate: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut defines: Vec<(&str, &str)> = Vec::new();
    if blur.bilateral() {
        defines.push((
            "LUCENT_SSS_HALF_TAPS",
            match taps {
                3 => "1",
                5 => "2",
                _ => "3",
            },
        ));
    }
    if blur.lean() {
        defines.push(("LUCENT_SSS_LEAN", "1"));
    }
    if blur.bilateral() {
        defines.push(("LUCENT_SSS_BILATERAL", "1"));
    }
    if edges {
        defines.push(("LUCENT_SSS_PROFILE_EDGES", "1"));
    }
    if packed_in {
        defines.push(("LUCENT_SSS_PACKED_IN", "1"));
    }
    if packed_out {
        defines.push(("LUCENT_SSS_PACKED_OUT", "1"));
    }
    if accumulate {
        defines.push(("LUCENT_SSS_ACCUMULATE", "1"));
    }
    defines
}

/// The final pass's bindings before the shadow bindings: the per-frame pair, the sums (two
/// with LEAN), diffuse, specular, profile IDs, with LEAN depth, GB0 and GB1, and the previous
/// chain's result (`base`).
fn final_bindings(lean: bool, base: bool) -> usize {
    let sums = if lean { 2 } else { 1 };
    2 + sums + 3 + 3 * usize::from(lean) + usize::from(base)
}

/// The final pass's defines (`lean`: LEAN `final lighting`, else `combine`), and with LEAN the
/// pass-through variant's extra define. `shadows`: LEAN specular reads the light-space maps.
fn final_defines(lean: bool, base: bool, shadows: bool) -> (Defines, Option<Defines>) {
    let mut defines: Vec<(&str, &str)> = Vec::new();
    if base {
        defines.push(("LUCENT_SSS_BASE", "1"));
    }
    if shadows {
        defines.extend(crate::features::shadows::lighting_defines(final_bindings(
            lean, base,
        )));
    }
    (defines, lean.then(|| vec![("LUCENT_SSS_PASSTHROUGH", "1")]))
}

/// The pipelines an iterative chain of `blur` builds in any frame.
pub(super) fn shader_permutations(blur: &dyn SssBlurTechnique, out: &mut Vec<PipelineShaders>) {
    for taps in [3, 5, 7] {
        for flags in 0u32..1 << 5 {
            let bit = |i: u32| flags & (1 << i) != 0;
            let (edges, accumulate) = (bit(0), bit(1));
            // The LEAN target is there (blur.lean()) or not; the packed knob.
            let packed = packed_pingpong(blur, blur.lean() && bit(2), bit(3));
            // A packed chain's first horizontal pass reads the unpacked light.
            let packed_in = packed && bit(4);
            out.push(PipelineShaders::fullscreen(
                BLUR_FRAGMENT,
                &blur_defines(blur, taps, edges, packed_in, packed, accumulate),
            ));
        }
    }
    for lean in [false, true] {
        let fragment = if lean {
            LEAN_FINAL_SHADER
        } else {
            COMBINE_FRAGMENT
        };
        for base in [false, true] {
            for shadows in [false, true] {
                let (defines, passthrough) = final_defines(lean, base, shadows);
                out.push(PipelineShaders::fullscreen(fragment, &defines));
                if let Some(extra) = passthrough {
                    let mut all = defines.clone();
                    all.extend(extra);
                    out.push(PipelineShaders::fullscreen(fragment, &all));
                }
            }
        }
    }
}

struct BlurPass {
    scene: Arc<SceneGpu>,
    /// The texels to blur: the light (LCB, LBB: and the LEAN target).
    colors: Vec<ResourceId>,
    depth: ResourceId,
    profile_ids: ResourceId,
    constants: BlurConstants,
    blur: SssBlur,
    /// Reject taps on other profiles' pixels.
    edges: bool,
    chain: usize,
    /// LBB packed: the input is one RGBA32UI texel (after the first pass).
    packed_in: bool,
    /// LBB packed: the result is written as one RGBA32UI texel.
    packed_out: bool,
    /// Sum-of-Gaussians targets accumulated after the result (vertical passes), else 0.
    sums: usize,
    /// Bilateral taps per direction.
    taps: u32,
    /// Linear filtering for the control's taps between texels (its offsets are fractional).
    sampler: vk::Sampler,
    /// Nearest, for depth and profile IDs and the bilateral blur's whole-texel taps (read with
    /// texelFetch; depth formats need not support linear filtering).
    nearest: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl PassExec for BlurPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, vk::Filter::LINEAR)?;
        self.nearest = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let color_sampler = if self.blur.bilateral() {
            self.nearest
        } else {
            self.sampler
        };
        // Bindings as glsl/sss/blur.frag declares them: 5 is the LEAN texel.
        let mut bindings = per_frame_bindings(&self.scene);
        bindings.extend([
            Binding::Sampled(views[self.colors[0]], color_sampler),
            Binding::Sampled(views[self.depth], self.nearest),
            Binding::Sampled(views[self.profile_ids], self.nearest),
        ]);
        if let Some(&lean) = self.colors.get(1) {
            bindings.push(Binding::Sampled(views[lean], color_sampler));
        }
        let defines = blur_defines(
            self.blur.technique(),
            self.taps,
            self.edges,
            self.packed_in,
            self.packed_out,
            self.sums > 0,
        );
        // The sums follow the results (one packed attachment, or one per blurred texel).
        let results = match (self.packed_out, self.blur.lean()) {
            (true, _) | (false, false) => 1,
            (false, true) => 2,
        };
        let additive = ((1u32 << self.sums) - 1) << results;
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &bindings,
            &GraphicsPipelineDesc {
                additive_attachments: additive,
                push_constant_bytes: std::mem::size_of::<BlurConstants>() as u32,
                ..GraphicsPipelineDesc::fullscreen(BLUR_FRAGMENT, &defines, "sss blur")
            },
        )?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        push_constants(ctx, pipeline, &self.constants);
        match chain_tiles(&self.scene, ctx, self.chain) {
            // Only where objects of this chain (and their blur's reach) can be: every pixel a
            // tap of a scattering pixel reads is written; the rest is never read.
            Some(rects) => {
                PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent))
            }
            None => {
                // SAFETY: bound above, inside the pass's subpass.
                unsafe { ctx.gpu.device.cmd_draw(ctx.cmd, 3, 1, 0, 0) };
            }
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created by `prepare` (or null); the GPU is done with them.
        unsafe {
            gpu.device.destroy_sampler(self.sampler, None);
            gpu.device.destroy_sampler(self.nearest, None);
        }
    }
}

/// A chain's pass after its blurs: `combine` (control) or `final lighting` (LCB, LBB, with
/// LEAN specular): every input sampled at its own pixel, in the shader's binding order. On
/// the pixels of its chain's profiles it writes the blurred light; elsewhere the previous
/// chain's result (`base`), or the lighting pass's diffuse + specular. With SSS tiles,
/// `final lighting` evaluates LEAN only on the rectangles its chain may cover and draws the
/// pass-through variant on the others: lavapipe shades both sides of the shader's per-pixel
/// branch, rasterisation it does skip.
struct FinalPass {
    scene: Arc<SceneGpu>,
    inputs: Vec<ResourceId>,
    fragment: &'static str,
    chain: usize,
    /// The last input is the previous chain's result.
    base: bool,
    sampler: vk::Sampler,
    pipeline: Option<PassPipeline>,
    /// LCB, LBB: the pass-through variant for rectangles nothing of the chain scatters in.
    passthrough: Option<crate::features::util::GraphicsPipeline>,
    /// The light-space maps' depth (LEAN frames where some light casts shadows).
    shadow_depth: Option<ResourceId>,
}

impl PassExec for FinalPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let mut bindings = per_frame_bindings(&self.scene);
        bindings.extend(
            self.inputs
                .iter()
                .map(|&id| Binding::Sampled(views[id], self.sampler)),
        );
        let lean = self.fragment == LEAN_FINAL_SHADER;
        let (defines, passthrough) = final_defines(lean, self.base, self.shadow_depth.is_some());
        if let Some(depth) = self.shadow_depth {
            check_bindings(
                self.fragment,
                bindings.len(),
                final_bindings(lean, self.base),
            )?;
            bindings.extend(crate::features::shadows::lighting_bindings(
                &self.scene,
                depth,
                None,
                views,
                self.sampler,
            ));
        }
        let desc = GraphicsPipelineDesc {
            push_constant_bytes: std::mem::size_of::<BlurConstants>() as u32,
            ..GraphicsPipelineDesc::fullscreen(self.fragment, &defines, self.fragment)
        };
        let mut pipeline = PassPipeline::new(ctx, &bindings, &desc)?;
        if let Some(extra) = passthrough {
            let (lean, passthrough) =
                pipeline.with_variant(ctx, &desc, &extra, "final lighting (pass-through)")?;
            pipeline = lean;
            self.passthrough = Some(passthrough);
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        let constants = BlurConstants {
            step: [0.0, 0.0, 0.0, self.chain as f32],
        };
        pipeline.bind(ctx);
        push_constants(ctx, pipeline, &constants);
        let tiles = chain_tiles(&self.scene, ctx, self.chain);
        let (Some(passthrough), Some(rects)) = (&self.passthrough, tiles) else {
            // SAFETY: bound above, inside the pass's subpass.
            unsafe { ctx.gpu.device.cmd_draw(ctx.cmd, 3, 1, 0, 0) };
            return;
        };
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent));
        // SAFETY: made for this subpass with the bound set's layout (same push constants).
        unsafe {
            ctx.gpu.device.cmd_bind_pipeline(
                ctx.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                passthrough.pipeline,
            );
        }
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| !r.translucent));
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.passthrough.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created by `prepare`; the GPU is done with it.
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
    }
}

/// A technique whose chain is iterative (the control, LCB, LBB): what tells them apart. Each
/// one's module holds its instance; [`crate::features::registry`] lists it.
pub struct IterativeChain {
    /// Its name (`--technique`, `blur = "..."`).
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// It blurs the LEAN G-buffer too and ends in LEAN `final lighting` (else `combine`).
    pub lean: bool,
    /// Point taps weighted by a depth Gaussian (else bilinear taps lerped across edges).
    pub bilateral: bool,
    /// The knobs that act on it.
    pub knobs: &'static [&'static str],
    /// The built-in scene it is measured on.
    pub scene: &'static str,
}

impl TechniqueModule for IterativeChain {
    fn name(&self) -> &'static str {
        self.name
    }

    fn summary(&self) -> &'static str {
        self.summary
    }

    fn shades(&'static self) -> Shades {
        Shades::Scattering(self)
    }

    fn knobs(&self) -> &'static [&'static str] {
        self.knobs
    }

    fn scene(&self) -> &'static str {
        self.scene
    }

    fn shader_permutations(&self, out: &mut Vec<PipelineShaders>) {
        shader_permutations(self, out);
    }
}

impl SssBlurTechnique for IterativeChain {
    fn lean(&self) -> bool {
        self.lean
    }

    fn bilateral(&self) -> bool {
        self.bilateral
    }

    fn iterative(&self) -> bool {
        true
    }

    fn declare_chain(
        &self,
        graph: &mut RenderGraph,
        inputs: &SssInputs<'_>,
        chain: &Chain,
        base: Option<&Handle<Image>>,
        knobs: &SssKnobs,
        scene: Option<&Arc<SceneGpu>>,
        output: Option<Handle<Image>>,
    ) -> Handle<Image> {
        chain_passes(graph, inputs, chain, base, knobs, scene, output)
    }
}
