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
use super::SceneGpu;

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

/// Declares the control technique's passes after the lighting pass: blurs of `diffuse`
/// (reading `depth` and the SSS `strength`), then the composite with `specular`. Returns the
/// final HDR image.
pub fn control_passes(
    graph: &mut RenderGraph,
    diffuse: &Handle<Image>,
    specular: &Handle<Image>,
    depth: &Handle<Image>,
    strength: &Handle<Image>,
    profile: &SssProfile,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let info = ImageInfo {
        format: HDR_FORMAT,
        ..graph.resources()[diffuse.id()].info
    };
    let mut temp = graph.create_image("sss.temp", info);
    let mut current = graph.create_image("sss.current", info);
    // The sum takes one rounded addition per Gaussian: in fp16 that alone costs about 4e-4 of
    // the diffuse light against the f64 reference (measured, six Gaussians); f32 keeps it exact
    // to the blur's own error.
    let mut sum = graph.create_image(
        "sss.sum",
        ImageInfo {
            format: vk::Format::R32G32B32A32_SFLOAT,
            ..info
        },
    );
    let steps = blur_steps(profile);
    for (i, step) in steps.iter().enumerate() {
        let n = i + 1;
        // Horizontal: the previous result (the lit diffuse the first time) into the temporary.
        let source = if i == 0 { diffuse.id() } else { current.id() };
        let mut pass = graph.add_pass(&format!("horizontal blur #{n}"), PassKind::Raster);
        if i == 0 {
            pass.sample(diffuse);
        } else {
            pass.sample(&current);
        }
        pass.sample(depth)
            .sample(strength)
            .color(&mut temp, LoadOp::DontCare);
        let blur =
            |scene: &Arc<SceneGpu>, direction: [f32; 2], accumulate: bool, source| BlurPass {
                scene: scene.clone(),
                inputs: [source, depth.id(), strength.id()],
                constants: BlurConstants {
                    step: [direction[0], direction[1], step.sigma, DEPTH_CORRECTION],
                    weight: [step.weight[0], step.weight[1], step.weight[2], 0.0],
                },
                accumulate,
                sampler: vk::Sampler::null(),
                nearest: vk::Sampler::null(),
                pipeline: None,
            };
        match scene {
            Some(scene) => pass.execute(blur(scene, [1.0, 0.0], false, source)),
            None => pass.finish(),
        }
        // Vertical: back into the current result, and its weighted share into the sum.
        let mut pass = graph.add_pass(&format!("vertical blur #{n}"), PassKind::Raster);
        pass.sample(&temp)
            .sample(depth)
            .sample(strength)
            .color(&mut current, LoadOp::DontCare)
            .color(
                &mut sum,
                if i == 0 {
                    LoadOp::Clear([0.0; 4])
                } else {
                    LoadOp::Load
                },
            );
        match scene {
            Some(scene) => pass.execute(blur(scene, [0.0, 1.0], true, temp.id())),
            None => pass.finish(),
        }
    }
    let mut hdr = graph.create_image("hdr", info);
    let mut pass = graph.add_pass("combine", PassKind::Raster);
    pass.sample(&sum)
        .sample(diffuse)
        .sample(specular)
        .sample(strength)
        .color(&mut hdr, LoadOp::DontCare);
    match scene {
        Some(scene) => pass.execute(CombinePass {
            scene: scene.clone(),
            inputs: [sum.id(), diffuse.id(), specular.id(), strength.id()],
            sampler: vk::Sampler::null(),
            pipeline: None,
        }),
        None => pass.finish(),
    }
    hdr
}

/// Push constants of glsl/sss/control_blur.frag.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurConstants {
    step: [f32; 4],
    weight: [f32; 4],
}

struct BlurPass {
    scene: Arc<SceneGpu>,
    /// Colour to blur, depth, SSS strength.
    inputs: [ResourceId; 3],
    constants: BlurConstants,
    accumulate: bool,
    /// Linear filtering for the colour taps between texels (the kernel's offsets are
    /// fractional).
    sampler: vk::Sampler,
    /// Nearest, for depth and strength (read with texelFetch; depth formats need not support
    /// linear filtering).
    nearest: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl PassExec for BlurPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let scene = &self.scene;
        self.sampler = clamp_sampler(ctx, vk::Filter::LINEAR)?;
        self.nearest = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let [color, depth, strength] = self.inputs;
        let accumulate: &[(&str, &str)] = &[("LUCENT_SSS_ACCUMULATE", "1")];
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[
                Binding::Uniform(scene.frame_uniforms),
                Binding::Sampled(views[color], self.sampler),
                Binding::Sampled(views[depth], self.nearest),
                Binding::Sampled(views[strength], self.nearest),
            ],
            &GraphicsPipelineDesc {
                vertex: "fullscreen.vert",
                fragment: "sss/control_blur.frag",
                defines: if self.accumulate { accumulate } else { &[] },
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                // The sum (attachment 1 of the vertical pass) accumulates.
                additive_attachments: if self.accumulate { 0b10 } else { 0 },
                set_layouts: &[],
                push_constant_bytes: std::mem::size_of::<BlurConstants>() as u32,
                name: "control blur",
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
            Some(rects) => PassPipeline::draw_fullscreen_in(ctx, &rects),
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

struct CombinePass {
    scene: Arc<SceneGpu>,
    /// Sum of Gaussians, lit diffuse, specular, SSS strength.
    inputs: [ResourceId; 4],
    sampler: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl PassExec for CombinePass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let mut bindings = vec![Binding::Uniform(self.scene.frame_uniforms)];
        bindings.extend(
            self.inputs
                .iter()
                .map(|&id| Binding::Sampled(views[id], self.sampler)),
        );
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &bindings,
            &GraphicsPipelineDesc {
                vertex: "fullscreen.vert",
                fragment: "sss/combine.frag",
                defines: &[],
                vertex_input: VertexInput::None,
                depth_test: false,
                cull_back: false,
                additive_attachments: 0,
                set_layouts: &[],
                push_constant_bytes: 0,
                name: "sss combine",
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
