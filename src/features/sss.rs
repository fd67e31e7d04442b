//! Screen-space subsurface scattering as separable blurs of the lit diffuse light.
//!
//! The control technique (Jimenez et al. 2009, as the LEAN-mapping thesis describes it): for
//! each Gaussian of the material's diffusion profile (a sum of Gaussians, narrowest first), a
//! horizontal pass into a temporary target and a vertical pass back, each a 7-tap kernel whose
//! width is the Gaussian projected to the screen at the pixel's depth, with taps across large
//! depth differences lerped back to the centre colour. The blurs are iterative: step `i` blurs
//! the previous result by `sqrt(v_i - v_(i-1))` (variances of convolved Gaussians add), so after
//! step `i` the image is the diffuse light convolved with the Gaussian of variance `v_i`; the
//! vertical pass adds that, times the Gaussian's RGB weight, into the sum. A final pass adds the
//! specular the lighting pass kept apart. Pass names follow the thesis's Table 2
//! (`horizontal blur #1`, `vertical blur #1`, ...).
//!
//! A frame blurs with one profile: the first SSS material's (the scenes use one profile each);
//! the per-pixel strength (0 = not SSS, from the G-buffer) scales the kernel width. With tiles
//! on (the default), the blurs draw only over the screen rectangles of objects with a profile,
//! widened by the profile's reach ([`profile_reach`]).

use std::sync::Arc;

use ash::vk;

use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::scene::material::SssProfile;
use crate::Result;

use super::deferred::HDR_FORMAT;
use super::util::{clamp_sampler, Binding, GraphicsPipelineDesc, PassPipeline, VertexInput};
use crate::gpu_scene::SceneGpu;

/// Depth correction of the control blur: a tap whose linear depth differs from the centre's by
/// `1 / DEPTH_CORRECTION` world units or more is fully replaced by the centre colour.
pub const DEPTH_CORRECTION: f32 = 20.0;

/// One blur step of a profile: the incremental sigma (world units) and the weight of the
/// Gaussian it completes (normalised per channel so the weights sum to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlurStep {
    /// Standard deviation added by this step, world units.
    pub sigma: f32,
    /// The completed Gaussian's RGB weight in the sum.
    pub weight: [f32; 3],
}

/// The blur steps of `profile`: `sigma_i = sqrt(v_i - v_(i-1))` mm in world units, weights
/// normalised per channel (a channel whose weights are all 0 keeps its light unblurred by
/// taking the narrowest Gaussian whole). Variances are sorted; equal ones merge.
pub fn blur_steps(profile: &SssProfile) -> Vec<BlurStep> {
    let mut gaussians = profile.gaussians.clone();
    gaussians.sort_by(|a, b| a.variance.total_cmp(&b.variance));
    let total = gaussians
        .iter()
        .fold(glam::Vec3::ZERO, |acc, g| acc + g.weight);
    let mut steps: Vec<BlurStep> = Vec::new();
    let mut previous = 0.0f32;
    for (i, g) in gaussians.iter().enumerate() {
        let weight: [f32; 3] = std::array::from_fn(|c| {
            if total[c] > 0.0 {
                g.weight[c] / total[c]
            } else if i == 0 {
                1.0
            } else {
                0.0
            }
        });
        // Guarded: equal variances add no blur (sqrt of a tiny negative is NaN).
        let sigma_mm = (g.variance - previous).max(0.0).sqrt();
        previous = previous.max(g.variance);
        steps.push(BlurStep {
            sigma: sigma_mm * profile.units_per_mm,
            weight,
        });
    }
    steps
}

/// How far (world units) the blurs of `profile` spread light: the kernel spans 3 sigma of the
/// widest Gaussian (the iterative steps' variances add up to it).
pub fn profile_reach(profile: &SssProfile) -> f32 {
    let widest = profile
        .gaussians
        .iter()
        .fold(0.0f32, |m, g| m.max(g.variance));
    3.0 * widest.max(0.0).sqrt() * profile.units_per_mm
}

/// LBB's packed ping-pong texel: eight fp16 halves (glsl/sss/blur.frag `pack_texels`).
pub const PACKED_FORMAT: vk::Format = vk::Format::R32G32B32A32_UINT;

/// LCB's and LBB's final lighting pass.
const LEAN_FINAL_SHADER: &str = "sss/lean_brdf.frag";

/// Which screen-space blur a frame runs (the technique decides: control, LCB, LBB).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SssBlur {
    /// Jimenez's blur of the lit diffuse light (the thesis's control, C).
    Control,
    /// The LEAN pipeline with Jimenez's blur (LCB).
    LeanControl,
    /// The LEAN pipeline with the bilateral blur (LBB).
    LeanBilateral,
}

impl SssBlur {
    /// Whether it blurs the LEAN G-buffer (view-plane slopes and moments) with the light.
    pub fn lean(self) -> bool {
        self != SssBlur::Control
    }

    /// Whether taps are weighted by a depth-difference Gaussian (else lerped back by depth).
    pub fn bilateral(self) -> bool {
        self == SssBlur::LeanBilateral
    }
}

/// Precision of the sum-of-Gaussians targets.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SssPrecision {
    /// RGBA16F sums (half the bandwidth of the accumulating writes).
    Half,
    /// RGBA32F sums: one rounded addition per Gaussian in fp16 costs about 4e-4 of the
    /// diffuse light against the f64 reference (measured, six Gaussians); f32 keeps the sum
    /// exact to the blur's own error.
    #[default]
    Full,
}

impl SssPrecision {
    /// Every precision with its command-line name.
    pub const ALL: &'static [(&'static str, SssPrecision)] =
        &[("half", SssPrecision::Half), ("full", SssPrecision::Full)];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("?", |(n, _)| n)
    }

    fn format(self) -> vk::Format {
        match self {
            SssPrecision::Half => vk::Format::R16G16B16A16_SFLOAT,
            SssPrecision::Full => vk::Format::R32G32B32A32_SFLOAT,
        }
    }
}

/// Default bilateral sensitivity: the depth-difference Gaussian of each blur step has the
/// standard deviation of the profile Gaussian the step completes, divided by the sensitivity.
/// At 1 the bilateral weight is the profile Gaussian of the tap's 3D distance (screen offset and
/// depth difference alike), which is what the brute-force reference convolves with: a surface
/// curving away is blurred by its true distance, a background a few sigma behind gets nothing.
pub const DEFAULT_SENSITIVITY: f32 = 1.0;

/// The screen-space SSS knobs a frame is built with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssKnobs {
    /// Refit the profile with this many Gaussians (fewer blur pairs; [`fit_profile`] reports
    /// the error it costs). `None`: the material's own profile.
    pub gaussians: Option<usize>,
    /// Precision of the sum targets.
    pub precision: SssPrecision,
    /// Bilateral blur: sensitivity to depth differences, relative to each Gaussian's own
    /// width ([`DEFAULT_SENSITIVITY`]).
    pub sensitivity: f32,
    /// LBB: carry the two blurred texels (light + slope x, slope y + moments) between passes
    /// as one RGBA32UI texel of eight fp16 halves, so each tap is one fetch and each pass one
    /// write. Needs point taps: LCB's bilinear taps keep two RGBA16F targets. Off by default:
    /// measured on lavapipe, unpacking costs more than the fetch it saves (docs/sss.md).
    pub packed: bool,
    /// LBB: taps per direction, 3, 5 or 7 (the thesis's 7): spaced 3 sigma / ((taps - 1) / 2)
    /// apart, weighted where they land. Default 5: measured (docs/report/sss.md) both cheaper
    /// and closer to the brute-force reference than 7 on the edges scene. The control's kernel
    /// is Jimenez's 7 taps.
    pub taps: u32,
}

impl Default for SssKnobs {
    fn default() -> Self {
        Self {
            gaussians: None,
            precision: SssPrecision::Full,
            sensitivity: DEFAULT_SENSITIVITY,
            packed: false,
            taps: 5,
        }
    }
}

/// The images the SSS passes read.
pub struct SssInputs<'a> {
    /// Lit diffuse (LCB, LBB: alpha holds the view-plane slope x).
    pub diffuse: &'a Handle<Image>,
    /// Lit specular, added back where the pixel does not scatter (everywhere for the control).
    pub specular: &'a Handle<Image>,
    /// Depth.
    pub depth: &'a Handle<Image>,
    /// SSS strength per pixel.
    pub strength: &'a Handle<Image>,
    /// LCB, LBB: the G-buffer's view-plane LEAN target (slope y, moments).
    pub lean: Option<&'a Handle<Image>>,
    /// G-buffer albedo + specular intensity (LEAN specular).
    pub gb0: &'a Handle<Image>,
}

/// Declares the SSS passes after the lighting pass: one horizontal + vertical blur pair per
/// Gaussian of `profile`, then the final pass (`combine` for the control, `final lighting`
/// with LEAN specular for LCB and LBB). Returns the final HDR image.
pub fn sss_passes(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    profile: &SssProfile,
    blur: SssBlur,
    knobs: &SssKnobs,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
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
    let packed = lean.is_some() && blur.bilateral() && knobs.packed;
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
        .map(|t| graph.create_image(&format!("sss.temp{}", names[t]), pingpong_info))
        .collect();
    let mut current: Vec<Handle<Image>> = (0..pingpong)
        .map(|t| graph.create_image(&format!("sss.current{}", names[t]), pingpong_info))
        .collect();
    let mut sum: Vec<Handle<Image>> = (0..targets)
        .map(|t| graph.create_image(&format!("sss.sum{}", names[t]), sum_info))
        .collect();
    // Texture fetches per pixel of a pass reading `texels` colour images, for the benchmark's
    // cost per tap: the centre texels, depth and strength, then each kernel tap's texels and
    // depth (the control: Jimenez's six bilinear taps around its centre; the bilateral blur:
    // its point taps, centre included).
    let fetches = |texels: u32| {
        let kernel = if blur.bilateral() { knobs.taps } else { 6 };
        texels + 2 + kernel * (texels + 1)
    };
    let steps = blur_steps(profile);
    let mut completed_variance = 0.0f32;
    for (i, step) in steps.iter().enumerate() {
        let n = i + 1;
        completed_variance += step.sigma * step.sigma;
        // Bilateral: per world unit of depth difference, the sensitivity over the width of the
        // Gaussian this step completes (guarded: a zero-width profile rejects every neighbour,
        // which leaves the pixel as it is).
        let depth_term = if blur.bilateral() {
            knobs.sensitivity.max(0.0) / completed_variance.sqrt().max(1e-9)
        } else {
            DEPTH_CORRECTION
        };
        let mean_weight = step.weight.iter().sum::<f32>() / 3.0;
        let constants = |direction: [f32; 2]| BlurConstants {
            step: [direction[0], direction[1], step.sigma, depth_term],
            weight: [step.weight[0], step.weight[1], step.weight[2], mean_weight],
        };
        // Horizontal: the previous result (the lit diffuse the first time) into the temporary.
        let source_handles: Vec<&Handle<Image>> = if i == 0 {
            std::iter::once(inputs.diffuse).chain(lean).collect()
        } else {
            current.iter().collect()
        };
        let mut pass = graph.add_pass(&format!("horizontal blur #{n}"), PassKind::Raster);
        for h in &source_handles {
            pass.sample(h);
        }
        pass.sample(inputs.depth)
            .sample(inputs.strength)
            .taps(fetches(source_handles.len() as u32));
        let sources: Vec<ResourceId> = source_handles.iter().map(|h| h.id()).collect();
        for t in &mut temp {
            pass.color(t, LoadOp::DontCare);
        }
        let exec =
            |constants, accumulate, colors: Vec<ResourceId>, scene: &Arc<SceneGpu>| BlurPass {
                scene: scene.clone(),
                // The first pass reads the lighting pass's and the G-buffer's own targets.
                packed_in: packed && colors.len() == 1,
                packed_out: packed,
                sums: if accumulate { targets } else { 0 },
                taps: knobs.taps,
                colors,
                depth: inputs.depth.id(),
                strength: inputs.strength.id(),
                constants,
                blur,
                sampler: vk::Sampler::null(),
                nearest: vk::Sampler::null(),
                pipeline: None,
            };
        match scene {
            Some(scene) => pass.execute(exec(constants([1.0, 0.0]), false, sources, scene)),
            None => pass.finish(),
        }
        // Vertical: back into the current result, and its weighted share into the sum.
        let mut pass = graph.add_pass(&format!("vertical blur #{n}"), PassKind::Raster);
        for t in &temp {
            pass.sample(t);
        }
        pass.sample(inputs.depth)
            .sample(inputs.strength)
            .taps(fetches(temp.len() as u32));
        for c in &mut current {
            pass.color(c, LoadOp::DontCare);
        }
        for s in &mut sum {
            pass.color(
                s,
                if i == 0 {
                    LoadOp::Clear([0.0; 4])
                } else {
                    LoadOp::Load
                },
            );
        }
        let temps = temp.iter().map(|h| h.id()).collect();
        match scene {
            Some(scene) => pass.execute(exec(constants([0.0, 1.0]), true, temps, scene)),
            None => pass.finish(),
        }
    }
    let mut hdr = graph.create_image("hdr", info);
    match lean {
        None => {
            let mut pass = graph.add_pass("combine", PassKind::Raster);
            pass.sample(&sum[0])
                .sample(inputs.diffuse)
                .sample(inputs.specular)
                .sample(inputs.strength)
                .color(&mut hdr, LoadOp::DontCare);
            let ids = vec![
                sum[0].id(),
                inputs.diffuse.id(),
                inputs.specular.id(),
                inputs.strength.id(),
            ];
            match scene {
                Some(scene) => pass.execute(FinalPass::new(scene, ids, "sss/combine.frag")),
                None => pass.finish(),
            }
        }
        Some(_) => {
            let mut pass = graph.add_pass("final lighting", PassKind::Raster);
            pass.sample(&sum[0])
                .sample(&sum[1])
                .sample(inputs.diffuse)
                .sample(inputs.specular)
                .sample(inputs.strength)
                .sample(inputs.depth)
                .sample(inputs.gb0)
                .color(&mut hdr, LoadOp::DontCare);
            let ids = vec![
                sum[0].id(),
                sum[1].id(),
                inputs.diffuse.id(),
                inputs.specular.id(),
                inputs.strength.id(),
                inputs.depth.id(),
                inputs.gb0.id(),
            ];
            match scene {
                Some(scene) => pass.execute(FinalPass::new(scene, ids, LEAN_FINAL_SHADER)),
                None => pass.finish(),
            }
        }
    }
    hdr
}

/// Push constants of glsl/sss/blur.frag.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurConstants {
    step: [f32; 4],
    weight: [f32; 4],
}

struct BlurPass {
    scene: Arc<SceneGpu>,
    /// The texels to blur: the light (LCB, LBB: and the LEAN target).
    colors: Vec<ResourceId>,
    depth: ResourceId,
    strength: ResourceId,
    constants: BlurConstants,
    blur: SssBlur,
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
    /// Nearest, for depth and strength and the bilateral blur's whole-texel taps (read with
    /// texelFetch; depth formats need not support linear filtering).
    nearest: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl PassExec for BlurPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let scene = &self.scene;
        self.sampler = clamp_sampler(ctx, vk::Filter::LINEAR)?;
        self.nearest = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let color_sampler = if self.blur.bilateral() {
            self.nearest
        } else {
            self.sampler
        };
        // Bindings as glsl/sss/blur.frag declares them: 4 is the LEAN texel.
        let mut bindings = vec![
            Binding::Uniform(scene.frame_uniforms),
            Binding::Sampled(views[self.colors[0]], color_sampler),
            Binding::Sampled(views[self.depth], self.nearest),
            Binding::Sampled(views[self.strength], self.nearest),
        ];
        if let Some(&lean) = self.colors.get(1) {
            bindings.push(Binding::Sampled(views[lean], color_sampler));
        }
        let mut defines: Vec<(&str, &str)> = Vec::new();
        if self.blur.bilateral() {
            defines.push((
                "LUCENT_SSS_HALF_TAPS",
                match self.taps {
                    3 => "1",
                    5 => "2",
                    _ => "3",
                },
            ));
        }
        if self.blur.lean() {
            defines.push(("LUCENT_SSS_LEAN", "1"));
        }
        if self.blur.bilateral() {
            defines.push(("LUCENT_SSS_BILATERAL", "1"));
        }
        if self.packed_in {
            defines.push(("LUCENT_SSS_PACKED_IN", "1"));
        }
        if self.packed_out {
            defines.push(("LUCENT_SSS_PACKED_OUT", "1"));
        }
        if self.sums > 0 {
            defines.push(("LUCENT_SSS_ACCUMULATE", "1"));
        }
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
                vertex: "fullscreen.vert",
                fragment: "sss/blur.frag",
                defines: &defines,
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                additive_attachments: additive,
                set_layouts: &[],
                push_constant_bytes: std::mem::size_of::<BlurConstants>() as u32,
                name: "sss blur",
            },
        )?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        // SAFETY: the pipeline's layout has this push-constant range; bound above.
        unsafe {
            ctx.gpu.device.cmd_push_constants(
                ctx.cmd,
                pipeline.pipeline.layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(&self.constants),
            );
        }
        let tiles = self
            .scene
            .sss_tiles
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        match tiles {
            // Only where objects with a profile (and their blur's reach) can be: every pixel a
            // tap of a scattering pixel reads is written; the rest is never read.
            Some(rects) => {
                PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent))
            }
            None => pipeline.draw_fullscreen(ctx),
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

/// The pass after the blurs: `combine` (control) or `final lighting` (LCB, LBB, with LEAN
/// specular): every input sampled at its own pixel, in the shader's binding order. With SSS
/// tiles, `final lighting` evaluates LEAN only on the rectangles that may scatter and draws the
/// pass-through variant (diffuse + specular) on the others: lavapipe shades both sides of the
/// shader's per-pixel branch, rasterisation it does skip.
struct FinalPass {
    scene: Arc<SceneGpu>,
    inputs: Vec<ResourceId>,
    fragment: &'static str,
    sampler: vk::Sampler,
    pipeline: Option<PassPipeline>,
    /// LCB, LBB: the pass-through variant for rectangles nothing scatters in.
    passthrough: Option<crate::features::util::GraphicsPipeline>,
}

impl FinalPass {
    fn new(scene: &Arc<SceneGpu>, inputs: Vec<ResourceId>, fragment: &'static str) -> Self {
        Self {
            scene: scene.clone(),
            inputs,
            fragment,
            sampler: vk::Sampler::null(),
            pipeline: None,
            passthrough: None,
        }
    }
}

impl PassExec for FinalPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let mut bindings = vec![Binding::Uniform(self.scene.frame_uniforms)];
        bindings.extend(
            self.inputs
                .iter()
                .map(|&id| Binding::Sampled(views[id], self.sampler)),
        );
        let desc = GraphicsPipelineDesc {
            vertex: "fullscreen.vert",
            fragment: self.fragment,
            defines: &[],
            vertex_input: VertexInput::None,
            depth_test: false,
            cull_back: false,
            additive_attachments: 0,
            set_layouts: &[],
            push_constant_bytes: 0,
            name: self.fragment,
        };
        let pipeline = PassPipeline::new(ctx, &bindings, &desc)?;
        if self.fragment == LEAN_FINAL_SHADER {
            let layouts = [pipeline.set.layout];
            let passthrough = crate::features::util::GraphicsPipeline::new(
                ctx,
                &GraphicsPipelineDesc {
                    defines: &[("LUCENT_SSS_PASSTHROUGH", "1")],
                    set_layouts: &layouts,
                    name: "final lighting (pass-through)",
                    ..desc
                },
            );
            match passthrough {
                Ok(p) => self.passthrough = Some(p),
                Err(e) => {
                    let mut pipeline = pipeline;
                    pipeline.destroy(&ctx.gpu.device);
                    return Err(e);
                }
            }
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        let tiles = self
            .scene
            .sss_tiles
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .clone();
        let (Some(passthrough), Some(rects)) = (&self.passthrough, tiles) else {
            pipeline.draw_fullscreen(ctx);
            return;
        };
        pipeline.bind(ctx);
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent));
        // SAFETY: made for this subpass with the bound set's layout.
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_add_up_to_each_gaussian_and_weights_to_one() {
        let skin = SssProfile::preset("skin").unwrap();
        let steps = blur_steps(&skin);
        assert_eq!(steps.len(), 6);
        let mut variance = 0.0f32;
        for (step, g) in steps.iter().zip(&skin.gaussians) {
            variance += (step.sigma / skin.units_per_mm).powi(2);
            assert!((variance - g.variance).abs() < 1e-4 * g.variance.max(1.0));
        }
        for c in 0..3 {
            let total: f32 = steps.iter().map(|s| s.weight[c]).sum();
            assert!((total - 1.0).abs() < 1e-5, "channel {c}: {total}");
        }
    }

    #[test]
    fn equal_variances_and_empty_channels_stay_finite() {
        let mut p = SssProfile::preset("skin").unwrap();
        p.gaussians[1].variance = p.gaussians[0].variance;
        for g in &mut p.gaussians {
            g.weight.z = 0.0;
        }
        let steps = blur_steps(&p);
        assert!(steps
            .iter()
            .all(|s| s.sigma.is_finite() && s.weight.iter().all(|w| w.is_finite())));
        assert_eq!(steps[1].sigma, 0.0);
        assert_eq!(steps[0].weight[2], 1.0, "blue keeps its light unblurred");
    }
}
