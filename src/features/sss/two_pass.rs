//! The two-pass chains (separable, bilateral): one horizontal and one vertical pass blur every
//! profile of the chain with a kernel made from the whole profile (glsl/sss/separable.frag and
//! glsl/sss/bilateral.frag over glsl/sss/two_pass_kernel.glsl), the vertical pass writing the
//! chain's result itself. The separable blur can run at half resolution per side, then a
//! full-resolution `upsample` pass composes it depth-aware (glsl/sss/upsample.frag).
//!
//! Pass names: `horizontal blur`, `vertical blur` (and `upsample`), prefixed by the blur in
//! frames with several chains.

use std::sync::Arc;

use ash::vk;

use super::{
    chain_tiles, per_frame_bindings, push_constants, BlurConstants, Chain, SssBlur, SssInputs,
    SssKnobs,
};
use crate::features::deferred::HDR_FORMAT;
use crate::features::shipped::PipelineShaders;
use crate::features::util::{
    check_bindings, clamp_sampler, Binding, Defines, GraphicsPipeline, GraphicsPipelineDesc,
    PassPipeline,
};
use crate::gpu_scene::{Region, SceneGpu, TileRect};
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

/// Declares a two-pass chain (see the module docs). Returns the chain's result (`output`
/// when given).
pub(super) fn chain_passes(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    chain: &Chain,
    base: Option<&Handle<Image>>,
    knobs: &SssKnobs,
    scene: Option<&Arc<SceneGpu>>,
    mut output: Option<Handle<Image>>,
) -> Handle<Image> {
    let blur = chain.blur;
    let depth_in_alpha = inputs.depth_in_alpha;
    let full = ImageInfo {
        format: HDR_FORMAT,
        ..graph.resources()[inputs.diffuse.id()].info
    };
    let half_res = knobs.half_res && blur == SssBlur::Separable;
    let blur_info = if half_res {
        ImageInfo {
            width: full.width.div_ceil(2),
            height: full.height.div_ceil(2),
            ..full
        }
    } else {
        full
    };
    let lean = match (blur.lean(), inputs.lean) {
        (true, Some(l)) => Some(l),
        _ => None,
    };
    let samples = knobs.samples;
    // Fetches per pixel of a blur pass, for the benchmark's cost per tap: the centre texels,
    // depth and profile ID, then each sample's texels (and its depth where it does not travel
    // in alpha, and its profile ID with several profiles).
    let fetches = |texels: u32, depth_fetch: bool| {
        let per_sample = texels + u32::from(depth_fetch) + u32::from(chain.edges);
        texels + 2 + samples * per_sample
    };
    let mut temp = graph.create_image(&chain.image_name("temp"), blur_info);
    let mut temp_lean = lean.map(|_| graph.create_image(&chain.image_name("temp.lean"), blur_info));
    let constants = |direction: [f32; 2]| BlurConstants {
        step: [direction[0], direction[1], 0.0, chain.index as f32],
    };
    let spec = |vertical: bool, compose: bool, inputs: Vec<ResourceId>| PassSpec {
        blur,
        vertical,
        compose,
        half_res,
        base: compose && base.is_some(),
        edges: chain.edges,
        depth_in_alpha: depth_in_alpha || vertical,
        point_taps: knobs.point_taps,
        samples,
        chain: chain.index,
        constants: constants(if vertical { [0.0, 1.0] } else { [1.0, 0.0] }),
        inputs,
        shadow_depth: None,
    };

    // Horizontal: the lit diffuse (and the LEAN target) into the temporaries.
    let mut pass = graph.add_pass(
        &format!("{}horizontal blur", chain.prefix),
        PassKind::Raster,
    );
    let mut reads: Vec<&Handle<Image>> = vec![inputs.diffuse, inputs.depth, inputs.profile_ids];
    reads.extend(lean.map(|l| l.view_plane));
    for h in &reads {
        pass.sample(h);
    }
    let texels = 1 + u32::from(lean.is_some());
    pass.taps(fetches(
        texels,
        !depth_in_alpha || blur == SssBlur::Bilateral,
    ));
    pass.color(&mut temp, LoadOp::DontCare);
    if let Some(t) = &mut temp_lean {
        pass.color(t, LoadOp::DontCare);
    }
    let ids = reads.iter().map(|h| h.id()).collect();
    match scene {
        Some(scene) => pass.execute(TwoPassBlur::new(scene, spec(false, false, ids))),
        None => pass.finish(),
    }

    // Vertical: at full resolution it writes the chain's result; at half resolution a
    // half-resolution blurred image the upsample composes.
    let result_name = |chain: &Chain| {
        if chain.last {
            "hdr".to_string()
        } else {
            chain.image_name("result")
        }
    };
    let mut result = |graph: &mut RenderGraph| {
        output
            .take()
            .unwrap_or_else(|| graph.create_image(&result_name(chain), full))
    };
    let mut vertical_out = if half_res {
        graph.create_image(&chain.image_name("blurred"), blur_info)
    } else {
        result(graph)
    };
    let mut pass = graph.add_pass(&format!("{}vertical blur", chain.prefix), PassKind::Raster);
    let mut reads: Vec<&Handle<Image>> = vec![&temp, inputs.depth, inputs.profile_ids];
    reads.extend(temp_lean.as_ref());
    if !half_res {
        reads.extend([inputs.diffuse, inputs.specular]);
        if let Some(l) = lean {
            reads.extend([l.gb0, l.gb1]);
        }
        reads.extend(base);
    }
    for h in &reads {
        pass.sample(h);
    }
    // The bilateral chain's LEAN specular is direct light: the light-space maps shadow it.
    let shadow_depth = inputs.shadow_depth.filter(|_| lean.is_some() && !half_res);
    if let Some(depth) = shadow_depth {
        pass.sample(depth);
    }
    pass.taps(fetches(texels, blur == SssBlur::Bilateral));
    pass.color(&mut vertical_out, LoadOp::DontCare);
    let ids = reads.iter().map(|h| h.id()).collect();
    match scene {
        Some(scene) => pass.execute(TwoPassBlur::new(
            scene,
            PassSpec {
                shadow_depth: shadow_depth.map(|h| h.id()),
                ..spec(true, !half_res, ids)
            },
        )),
        None => pass.finish(),
    }
    if !half_res {
        return vertical_out;
    }

    // Upsample: the half-resolution blur composed at full resolution.
    let mut hdr = result(graph);
    let mut pass = graph.add_pass(&format!("{}upsample", chain.prefix), PassKind::Raster);
    let mut reads: Vec<&Handle<Image>> = vec![
        &vertical_out,
        inputs.depth,
        inputs.profile_ids,
        inputs.diffuse,
        inputs.specular,
    ];
    reads.extend(base);
    for h in &reads {
        pass.sample(h);
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    let ids = reads.iter().map(|h| h.id()).collect();
    match scene {
        Some(scene) => pass.execute(TwoPassBlur::new(
            scene,
            PassSpec {
                constants: constants([0.0, 0.0]),
                ..spec(true, true, ids)
            },
        )),
        None => pass.finish(),
    }
    hdr
}

/// What one pass of a two-pass chain is.
#[derive(Clone, Debug)]
struct PassSpec {
    blur: SssBlur,
    /// The vertical pass (its taps read the temporaries).
    vertical: bool,
    /// It writes the chain's result (full-resolution vertical pass, or the upsample).
    compose: bool,
    half_res: bool,
    /// The last input is the previous chain's result.
    base: bool,
    edges: bool,
    /// The taps' depth travels in the light's alpha.
    depth_in_alpha: bool,
    /// Separable: nearest-texel taps.
    point_taps: bool,
    samples: u32,
    chain: usize,
    constants: BlurConstants,
    /// The images it samples, in the shader's binding order (after the per-frame bindings).
    inputs: Vec<ResourceId>,
    /// The light-space maps' depth (the bilateral vertical pass's LEAN specular, when some
    /// light casts shadows).
    shadow_depth: Option<ResourceId>,
}

impl PassSpec {
    /// What its shader permutation depends on.
    fn shape(&self) -> PassShape {
        PassShape {
            bilateral: self.blur == SssBlur::Bilateral,
            vertical: self.vertical,
            compose: self.compose,
            half_res: self.half_res,
            base: self.base,
            edges: self.edges,
            depth_in_alpha: self.depth_in_alpha,
            point_taps: self.point_taps,
            samples: self.samples,
            inputs: self.inputs.len(),
        }
    }

    /// Whether the pass reads the kernel table (binding 2): all of them.
    fn kernels(&self) -> bool {
        true
    }
}

/// The fields of a [`PassSpec`] its shader permutation depends on.
#[derive(Clone, Copy, Debug)]
struct PassShape {
    /// The bilateral blur (else separable).
    bilateral: bool,
    vertical: bool,
    compose: bool,
    half_res: bool,
    base: bool,
    edges: bool,
    depth_in_alpha: bool,
    point_taps: bool,
    samples: u32,
    /// Images sampled (after the per-frame bindings and the kernel table).
    inputs: usize,
}

impl PassShape {
    /// The upsample pass of a half-resolution chain.
    fn upsample(&self) -> bool {
        self.half_res && self.compose
    }

    fn fragment(&self) -> &'static str {
        if self.upsample() {
            "sss/upsample.frag"
        } else if self.bilateral {
            "sss/bilateral.frag"
        } else {
            "sss/separable.frag"
        }
    }

    /// Bindings before the shadow bindings: the per-frame pair, the kernel table, the inputs.
    fn bindings(&self) -> usize {
        3 + self.inputs
    }

    /// The defines (`shadows`: the bilateral vertical pass's LEAN specular reads the
    /// light-space maps), and for composing passes the pass-through variant's extra define.
    fn defines(&self, shadows: bool) -> (Defines, Option<Defines>) {
        let mut defines: Vec<(&str, &str)> = Vec::new();
        if self.upsample() {
            if self.base {
                defines.push(("LUCENT_SSS_BASE", "1"));
            }
        } else {
            if self.bilateral {
                defines.push((
                    "LUCENT_SSS_SAMPLES",
                    match self.samples {
                        11 => "11",
                        25 => "25",
                        _ => "17",
                    },
                ));
            } else {
                // Only the separable blur runs at half resolution, passes depth on in alpha
                // and takes point taps.
                if self.point_taps {
                    defines.push(("LUCENT_SSS_POINT_TAPS", "1"));
                }
                if self.half_res {
                    defines.push(("LUCENT_SSS_HALF_RES", "1"));
                }
                if self.depth_in_alpha && !self.vertical {
                    defines.push(("LUCENT_SSS_DEPTH_IN_ALPHA", "1"));
                }
            }
            if self.vertical {
                defines.push(("LUCENT_SSS_VERTICAL", "1"));
            }
            if self.edges {
                defines.push(("LUCENT_SSS_PROFILE_EDGES", "1"));
            }
            if self.base {
                defines.push(("LUCENT_SSS_BASE", "1"));
            }
        }
        if shadows {
            defines.extend(crate::features::shadows::lighting_defines(self.bindings()));
        }
        (
            defines,
            self.compose.then(|| vec![("LUCENT_SSS_PASSTHROUGH", "1")]),
        )
    }
}

/// The pipelines the two-pass chains of any frame build. Only the shadowed pass (the
/// bilateral chain's full-resolution vertical pass with LEAN) numbers bindings after its
/// inputs: temp, depth, profile IDs, the LEAN temp, diffuse, specular, GB0, GB1 and the
/// previous chain's result (`base`), as `chain_passes` reads them.
pub(super) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for flags in 0u32..1 << 8 {
        let bit = |i: u32| flags & (1 << i) != 0;
        for samples in [11, 17, 25] {
            let shape = PassShape {
                bilateral: bit(0),
                vertical: bit(1),
                compose: bit(2),
                half_res: bit(3),
                base: bit(4),
                edges: bit(5),
                depth_in_alpha: bit(6),
                point_taps: bit(7),
                samples,
                inputs: 8 + usize::from(bit(4)),
            };
            for shadows in [false, true] {
                let (defines, passthrough) = shape.defines(shadows);
                out.push(PipelineShaders::fullscreen(shape.fragment(), &defines));
                if let Some(extra) = passthrough {
                    let mut all = defines.clone();
                    all.extend(extra);
                    out.push(PipelineShaders::fullscreen(shape.fragment(), &all));
                }
            }
        }
    }
}

struct TwoPassBlur {
    scene: Arc<SceneGpu>,
    spec: PassSpec,
    /// Linear filtering for the separable blur's taps between texels.
    linear: vk::Sampler,
    /// Nearest, for depth and profile IDs and point taps.
    nearest: vk::Sampler,
    pipeline: Option<PassPipeline>,
    /// Composing passes: the variant for rectangles no object of the chain covers.
    passthrough: Option<GraphicsPipeline>,
}

impl TwoPassBlur {
    fn new(scene: &Arc<SceneGpu>, spec: PassSpec) -> Self {
        Self {
            scene: scene.clone(),
            spec,
            linear: vk::Sampler::null(),
            nearest: vk::Sampler::null(),
            pipeline: None,
            passthrough: None,
        }
    }
}

/// A tile rectangle at half resolution (every half-resolution pixel the full-resolution one
/// touches).
fn halved(r: &TileRect) -> TileRect {
    TileRect {
        x: r.x / 2,
        y: r.y / 2,
        width: (r.x + r.width).div_ceil(2) - r.x / 2,
        height: (r.y + r.height).div_ceil(2) - r.y / 2,
        translucent: r.translucent,
    }
}

impl PassExec for TwoPassBlur {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.linear = clamp_sampler(ctx, vk::Filter::LINEAR)?;
        self.nearest = clamp_sampler(ctx, vk::Filter::NEAREST)?;
        let views = ctx.descriptor_views;
        let mut bindings = per_frame_bindings(&self.scene);
        if self.spec.kernels() {
            bindings.push(Binding::PerFrame(
                self.scene.per_frame.binding(Region::Kernels),
            ));
        }
        for (i, &id) in self.spec.inputs.iter().enumerate() {
            // The light the separable blur taps between texels: linear; the rest nearest.
            let sampler = if i == 0 && self.spec.blur == SssBlur::Separable {
                self.linear
            } else {
                self.nearest
            };
            bindings.push(Binding::Sampled(views[id], sampler));
        }
        let (defines, passthrough) = self.spec.shape().defines(self.spec.shadow_depth.is_some());
        if let Some(depth) = self.spec.shadow_depth {
            check_bindings(
                "sss two-pass blur",
                bindings.len(),
                self.spec.shape().bindings(),
            )?;
            bindings.extend(crate::features::shadows::lighting_bindings(
                &self.scene,
                depth,
                None,
                views,
                self.nearest,
            ));
        }
        let desc = GraphicsPipelineDesc {
            push_constant_bytes: std::mem::size_of::<BlurConstants>() as u32,
            ..GraphicsPipelineDesc::fullscreen(
                self.spec.shape().fragment(),
                &defines,
                "sss two-pass blur",
            )
        };
        let mut pipeline = PassPipeline::new(ctx, &bindings, &desc)?;
        if let Some(extra) = passthrough {
            let (blur, passthrough) =
                pipeline.with_variant(ctx, &desc, &extra, "sss two-pass blur (pass-through)")?;
            pipeline = blur;
            self.passthrough = Some(passthrough);
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        push_constants(ctx, pipeline, &self.spec.constants);
        let tiles = chain_tiles(&self.scene, ctx, self.spec.chain);
        // Half-resolution passes (all but the upsample) draw halved rectangles.
        let scaled = |rects: Vec<TileRect>| {
            if self.spec.half_res && !self.spec.shape().upsample() {
                rects.iter().map(halved).collect()
            } else {
                rects
            }
        };
        let draw_all = || {
            // SAFETY: bound above, inside the pass's subpass.
            unsafe { ctx.gpu.device.cmd_draw(ctx.cmd, 3, 1, 0, 0) };
        };
        match (tiles, &self.passthrough) {
            (None, _) => draw_all(),
            // Blurring only: where objects of this chain (and their blur's reach) can be.
            (Some(rects), None) => {
                let rects = scaled(rects);
                PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent))
            }
            // Composing: the blur where the chain's objects may be, pass-through elsewhere.
            (Some(rects), Some(passthrough)) => {
                let rects = scaled(rects);
                PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent));
                // SAFETY: made for this subpass with the bound set's layout (same push
                // constants).
                unsafe {
                    ctx.gpu.device.cmd_bind_pipeline(
                        ctx.cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        passthrough.pipeline,
                    );
                }
                PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| !r.translucent));
            }
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.passthrough.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created by `prepare` (or null); the GPU is done with them.
        unsafe {
            gpu.device.destroy_sampler(self.linear, None);
            gpu.device.destroy_sampler(self.nearest, None);
        }
    }
}
