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

use super::{chain_tiles, sss_pass, BlurConstants, Chain, SssBlurTechnique, SssInputs, SssKnobs};
use crate::backend::shader::PipelineShaders;
use crate::features::pass::FullscreenPass;
use crate::features::util::Defines;
use crate::features::util::HDR_FORMAT;
use crate::gpu_scene::{SceneGpu, TableRegion, TileRect};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, RenderGraph};

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
    let half_res = knobs.half_res && blur.half_resolution();
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
    let albedo_after = inputs.albedo.is_some();
    // Fetches per pixel of a blur pass, for the benchmark's cost per tap: the centre texels,
    // depth and profile ID, then each sample's texels (and its depth where it does not travel
    // in alpha, and its profile ID with several profiles).
    let fetches = |texels: u32, depth_fetch: bool| {
        let per_sample = texels + u32::from(depth_fetch) + u32::from(chain.edges);
        texels + 2 + samples * per_sample
    };
    let mut temp = graph.create_image(&chain.image_name("temp"), blur_info);
    let mut temp_lean = lean.map(|_| graph.create_image(&chain.image_name("temp.lean"), blur_info));
    let shape = |vertical: bool, compose: bool| PassShape {
        bilateral: blur.bilateral(),
        vertical,
        compose,
        half_res,
        base: compose && base.is_some(),
        edges: chain.edges,
        depth_in_alpha: depth_in_alpha || vertical,
        point_taps: knobs.point_taps,
        albedo: compose && albedo_after,
        samples,
    };

    // Horizontal: the lit diffuse (and the LEAN target) into the temporaries.
    let mut reads: Vec<(&'static str, &Handle<Image>)> = vec![
        ("color_tex", inputs.diffuse),
        ("depth_tex", inputs.depth),
        ("profile_tex", inputs.profile_ids),
    ];
    reads.extend(lean.map(|l| ("lean_tex", l.view_plane)));
    let mut pass = blur_pass(
        graph,
        inputs,
        &format!("{}horizontal blur", chain.prefix),
        scene,
        chain,
        shape(false, false),
        [1.0, 0.0],
        &reads,
    );
    let texels = 1 + u32::from(lean.is_some());
    pass.taps(fetches(texels, !depth_in_alpha || blur.bilateral()));
    pass.color(&mut temp, LoadOp::DontCare);
    if let Some(t) = &mut temp_lean {
        pass.color(t, LoadOp::DontCare);
    }
    pass.finish();

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
    let mut reads: Vec<(&'static str, &Handle<Image>)> = vec![
        ("color_tex", &temp),
        ("depth_tex", inputs.depth),
        ("profile_tex", inputs.profile_ids),
    ];
    reads.extend(temp_lean.as_ref().map(|t| ("lean_tex", t)));
    if !half_res {
        reads.extend([
            ("diffuse_tex", inputs.diffuse),
            ("specular_tex", inputs.specular),
        ]);
        if let Some(l) = lean {
            reads.extend([("albedo_tex", l.gb0), ("normal_tex", l.gb1)]);
        }
        reads.extend(base.map(|b| ("base_tex", b)));
        // The albedo left out of the light (the LEAN pass reads GB0 already).
        if lean.is_none() {
            reads.extend(inputs.albedo.map(|a| ("albedo_tex", a)));
        }
    }
    let mut pass = blur_pass(
        graph,
        inputs,
        &format!("{}vertical blur", chain.prefix),
        scene,
        chain,
        shape(true, !half_res),
        [0.0, 1.0],
        &reads,
    );
    // The bilateral chain's LEAN specular is direct light: the light-space maps shadow it.
    if let Some(depth) = inputs.shadow_depth.filter(|_| lean.is_some() && !half_res) {
        super::bind_shadow_maps(&mut pass, inputs, depth);
    }
    pass.taps(fetches(texels, blur.bilateral()));
    pass.color(&mut vertical_out, LoadOp::DontCare);
    pass.finish();
    if !half_res {
        return vertical_out;
    }

    // Upsample: the half-resolution blur composed at full resolution.
    let mut hdr = result(graph);
    let mut reads: Vec<(&'static str, &Handle<Image>)> = vec![
        ("blurred_tex", &vertical_out),
        ("depth_tex", inputs.depth),
        ("profile_tex", inputs.profile_ids),
        ("diffuse_tex", inputs.diffuse),
        ("specular_tex", inputs.specular),
    ];
    reads.extend(base.map(|b| ("base_tex", b)));
    reads.extend(inputs.albedo.map(|a| ("albedo_tex", a)));
    let mut pass = blur_pass(
        graph,
        inputs,
        &format!("{}upsample", chain.prefix),
        scene,
        chain,
        shape(true, true),
        [0.0, 0.0],
        &reads,
    );
    pass.color(&mut hdr, LoadOp::DontCare);
    pass.finish();
    hdr
}

/// Starts one pass of a two-pass chain: the kernel table bound after the per-frame pair, then
/// `reads`, each with the shaders' name for it (the light, first, the separable blur taps
/// between texels linear, the rest nearest), pushing the blur `direction`. It draws only where objects of its
/// chain (and their blur's reach) can be, at half resolution in halved rectangles; a composing
/// pass draws its pass-through variant on the other rectangles.
#[allow(clippy::too_many_arguments)]
fn blur_pass<'g>(
    graph: &'g mut RenderGraph,
    inputs: &SssInputs<'_>,
    name: &str,
    scene: Option<&Arc<SceneGpu>>,
    chain: &Chain,
    shape: PassShape,
    direction: [f32; 2],
    reads: &[(&'static str, &Handle<Image>)],
) -> FullscreenPass<'g> {
    let constants = BlurConstants {
        step: [direction[0], direction[1], 0.0, chain.index as f32],
    };
    let mut pass = sss_pass(graph, inputs, name, shape.fragment(), scene, constants);
    pass.per_frame(&super::tables::KERNELS);
    for (i, &(name, h)) in reads.iter().enumerate() {
        let filter = if i == 0 && !chain.blur.bilateral() {
            vk::Filter::LINEAR
        } else {
            vk::Filter::NEAREST
        };
        pass.sample_with(name, h, filter);
    }
    let (defines, passthrough) = shape.defines(false);
    pass.defines(&defines);
    if let Some(extra) = passthrough {
        pass.variant(extra);
    }
    let index = chain.index;
    // Half-resolution passes (all but the upsample) draw halved rectangles.
    let halve = shape.half_res && !shape.upsample();
    pass.tiles(move |scene, ctx| {
        let rects = chain_tiles(scene, ctx, index)?;
        Some(if halve {
            rects.iter().map(halved).collect()
        } else {
            rects
        })
    });
    pass
}

/// What the shader permutation of one pass of a two-pass chain depends on.
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
    /// A composing pass multiplies the albedo the lighting pass left out back in
    /// (`SssInputs::albedo`).
    albedo: bool,
    samples: u32,
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

    /// The defines (`shadows`: the bilateral vertical pass's LEAN specular reads the
    /// light-space maps), and for composing passes the pass-through variant's extra define.
    fn defines(&self, shadows: bool) -> (Defines, Option<Defines>) {
        let mut defines: Vec<(&str, &str)> = Vec::new();
        if self.albedo {
            defines.push(("LUCENT_SSS_ALBEDO", "1"));
        }
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
            defines.extend(crate::features::shadows::LIGHTING_DEFINES);
        }
        (
            defines,
            self.compose.then(|| vec![("LUCENT_SSS_PASSTHROUGH", "1")]),
        )
    }
}

/// The pipelines a two-pass chain of `blur` builds in any frame.
pub(super) fn shader_permutations(blur: &dyn SssBlurTechnique, out: &mut Vec<PipelineShaders>) {
    for flags in 0u32..1 << 8 {
        let bit = |i: u32| flags & (1 << i) != 0;
        // Only a composing pass multiplies the albedo in.
        if bit(7) && !bit(1) {
            continue;
        }
        for samples in [11, 17, 25] {
            let shape = PassShape {
                bilateral: blur.bilateral(),
                vertical: bit(0),
                compose: bit(1),
                half_res: bit(2),
                base: bit(3),
                edges: bit(4),
                depth_in_alpha: bit(5),
                point_taps: bit(6),
                albedo: bit(7),
                samples,
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

/// A tile rectangle at half resolution (every half-resolution pixel the full-resolution one
/// touches).
pub(super) fn halved(r: &TileRect) -> TileRect {
    TileRect {
        x: r.x / 2,
        y: r.y / 2,
        width: (r.x + r.width).div_ceil(2) - r.x / 2,
        height: (r.y + r.height).div_ceil(2) - r.y / 2,
        translucent: r.translucent,
    }
}

/// A technique whose chain is two passes (separable, bilateral): what tells them apart. Each
/// one's module holds its instance; [`crate::features::registry`] lists it.
pub struct TwoPassChain {
    /// Its name (`--technique`, `blur = "..."`).
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// It blurs the LEAN G-buffer too and adds LEAN specular in its vertical pass.
    pub lean: bool,
    /// Tap weights from the whole profile at each tap's 3D distance (else the kernel's
    /// weights at the screen offset, following the surface's depth).
    pub bilateral: bool,
    /// It can blur at half resolution per side (`--sss-half-res`).
    pub half_resolution: bool,
    /// Its taps read linear depth from the lit diffuse's alpha.
    pub depth_in_alpha: bool,
    /// The knobs that act on it.
    pub knobs: &'static [&'static crate::features::knob::Knob],
    /// The per-pass timings its seed published for it.
    pub published_timing: Option<&'static crate::features::technique::SeedTable>,
    /// The built-in scene it is measured on.
    pub scene: &'static str,
}

super::chain_technique_module!(TwoPassChain);

impl SssBlurTechnique for TwoPassChain {
    fn lean(&self) -> bool {
        self.lean
    }

    fn bilateral(&self) -> bool {
        self.bilateral
    }

    fn iterative(&self) -> bool {
        false
    }

    fn half_resolution(&self) -> bool {
        self.half_resolution
    }

    fn depth_in_alpha(&self) -> bool {
        self.depth_in_alpha
    }

    fn table(&self) -> Option<TableRegion> {
        Some(TableRegion {
            region: &super::tables::KERNELS,
            bytes: super::kernel::KERNEL_TABLE_BYTES,
        })
    }

    fn table_bytes(&self, profiles: &super::SssProfiles, knobs: &SssKnobs) -> Vec<u8> {
        let kernels = super::kernel::kernel_table(profiles, knobs.samples, knobs.shape);
        bytemuck::bytes_of(&kernels).to_vec()
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
