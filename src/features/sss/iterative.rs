//! The thesis's iterative chains (control, LCB, LBB): one horizontal + vertical blur pair per
//! Gaussian of the longest profile in the chain, each step blurring the previous result by the
//! variance the next Gaussian adds, accumulated into the sum of Gaussians, then the chain's
//! final pass (`combine` or LEAN `final lighting`).

use std::sync::Arc;

use ash::vk;

use super::{
    chain_tiles, sss_pass, BlurConstants, Chain, SssBlurTechnique, SssInputs, SssKnobs,
    LEAN_FINAL_SHADER, PACKED_FORMAT,
};
use crate::backend::shader::PipelineShaders;
use crate::features::pass::FullscreenPass;
use crate::features::util::Defines;
use crate::features::util::HDR_FORMAT;
use crate::gpu_scene::SceneGpu;
use crate::graph::{Handle, Image, ImageInfo, LoadOp, RenderGraph};

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
    // The sums of Gaussians so far ping-pong between two sets of targets: each vertical pass
    // reads the previous steps' sum and writes its own step added (no blending, see
    // glsl/sss/blur.frag). A one-step chain needs one set.
    let sets = if chain.steps > 1 { 2 } else { 1 };
    let mut sums: Vec<Vec<Handle<Image>>> = ["", ".b"][..sets]
        .iter()
        .map(|set| {
            (0..targets)
                .map(|t| {
                    let name = chain.image_name(&format!("sum{set}{}", names[t]));
                    graph.create_image(&name, sum_info)
                })
                .collect()
        })
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
        // The light and the LEAN texel come packed in one image (packed ping-pong targets).
        let packed_in = packed && source_handles.len() == 1;
        let constants = |direction: [f32; 2]| BlurConstants {
            step: [direction[0], direction[1], step as f32, chain.index as f32],
        };
        let mut pass = blur_pass(
            graph,
            &format!("{}horizontal blur #{n}", chain.prefix),
            scene,
            chain,
            constants([1.0, 0.0]),
            &source_handles,
            packed_in,
            inputs,
        );
        pass.taps(fetches(source_handles.len() as u32))
            .defines(&blur_defines(
                blur.technique(),
                knobs.taps,
                chain.edges,
                packed_in,
                packed,
                false,
            ));
        for t in &mut temp {
            pass.color(t, LoadOp::DontCare);
        }
        pass.finish();
        // Vertical: back into the current result, and its weighted share into the sum.
        let temps: Vec<&Handle<Image>> = temp.iter().collect();
        let packed_in = packed && temps.len() == 1;
        let mut pass = blur_pass(
            graph,
            &format!("{}vertical blur #{n}", chain.prefix),
            scene,
            chain,
            constants([0.0, 1.0]),
            &temps,
            packed_in,
            inputs,
        );
        let (written, read) = (step % sets, (step + 1) % sets);
        let sum_in = step > 0;
        let mut defines = blur_defines(
            blur.technique(),
            knobs.taps,
            chain.edges,
            packed_in,
            packed,
            true,
        );
        if sum_in {
            defines.push(SUM_IN);
            for (name, s) in ["sum_in_tex", "lean_sum_in_tex"].into_iter().zip(&sums[read]) {
                pass.sample(name, s);
            }
        }
        // The previous sum is one more fetch per target.
        let sum_fetches = if sum_in { targets as u32 } else { 0 };
        pass.taps(fetches(temps.len() as u32) + sum_fetches)
            .defines(&defines);
        for c in &mut current {
            pass.color(c, LoadOp::DontCare);
        }
        // Every pixel of the chain's tiles is written (zero where nothing scatters); the
        // final pass reads only its profiles' pixels, all inside the tiles.
        for s in &mut sums[written] {
            pass.color(s, LoadOp::DontCare);
        }
        pass.finish();
    }
    let sum = &sums[(chain.steps + sets - 1) % sets];
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
    // The chain's last pass samples every input at its own pixel: on the pixels of its chain's
    // profiles it writes the blurred light; elsewhere the previous chain's result (`base`), or
    // the lighting pass's diffuse + specular. Each input with the shaders' name for it.
    let mut reads: Vec<(&'static str, &Handle<Image>)> =
        ["sum_tex", "lean_sum_tex"].into_iter().zip(sum).collect();
    reads.extend([
        ("diffuse_tex", inputs.diffuse),
        ("specular_tex", inputs.specular),
        ("profile_tex", inputs.profile_ids),
    ]);
    if let Some(l) = lean {
        reads.extend([
            ("depth_tex", inputs.depth),
            ("albedo_tex", l.gb0),
            ("normal_tex", l.gb1),
        ]);
    }
    reads.extend(base.map(|b| ("base_tex", b)));
    // The albedo left out of the light: LCB's and LBB's pass reads GB0 already; the control's
    // combine reads it too.
    if let (Some(albedo), None) = (inputs.albedo, lean) {
        reads.push(("albedo_tex", albedo));
    }
    let constants = BlurConstants {
        step: [0.0, 0.0, 0.0, chain.index as f32],
    };
    let mut pass = sss_pass(
        graph,
        inputs,
        &format!("{}{name}", chain.prefix),
        fragment,
        scene,
        constants,
    );
    let (defines, passthrough) = final_defines(
        lean.is_some(),
        base.is_some(),
        inputs.albedo.is_some(),
        false,
    );
    pass.defines(&defines);
    for (name, h) in reads {
        pass.sample(name, h);
    }
    // LEAN specular is direct light: the light-space maps shadow it.
    if let Some(depth) = inputs.shadow_depth.filter(|_| lean.is_some()) {
        super::bind_shadow_maps(&mut pass, inputs, depth);
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    // With SSS tiles, `final lighting` evaluates LEAN only on the rectangles its chain may
    // cover and draws the pass-through variant on the others: lavapipe shades both sides of
    // the shader's per-pixel branch, rasterisation it does skip.
    if let Some(extra) = passthrough {
        let index = chain.index;
        pass.variant(extra)
            .tiles(move |scene, ctx| chain_tiles(scene, ctx, index));
    }
    pass.finish();
    hdr
}

/// Starts a blur pass of an iterative chain reading `colors` (the light, packed with the LEAN
/// texel when `packed_in`, or with LCB and LBB the LEAN texel beside it). The control's taps
/// fall between texels (linear); depth, profile IDs and the bilateral blur's whole-texel taps
/// are read nearest (texelFetch; depth formats need not support linear filtering). It draws only where objects of its chain (and their blur's
/// reach) can be: every pixel a tap of a scattering pixel reads is written; the rest is never
/// read.
#[allow(clippy::too_many_arguments)]
fn blur_pass<'g>(
    graph: &'g mut RenderGraph,
    name: &str,
    scene: Option<&Arc<SceneGpu>>,
    chain: &Chain,
    constants: BlurConstants,
    colors: &[&Handle<Image>],
    packed_in: bool,
    inputs: &SssInputs<'_>,
) -> FullscreenPass<'g> {
    let filter = if chain.blur.bilateral() {
        vk::Filter::NEAREST
    } else {
        vk::Filter::LINEAR
    };
    let mut pass = sss_pass(graph, inputs, name, BLUR_FRAGMENT, scene, constants);
    let first = if packed_in { "packed_tex" } else { "color_tex" };
    pass.sample_with(first, colors[0], filter);
    for lean in &colors[1..] {
        pass.sample_with("lean_tex", lean, filter);
    }
    pass.sample("depth_tex", inputs.depth)
        .sample("profile_tex", inputs.profile_ids);
    let index = chain.index;
    pass.tiles(move |scene, ctx| chain_tiles(scene, ctx, index));
    pass
}

/// The iterative blur's fragment shader.
const BLUR_FRAGMENT: &str = "sss/blur.frag";
/// The vertical blur's define for every step after the first: it reads the previous sum.
const SUM_IN: (&str, &str) = ("LUCENT_SSS_SUM_IN", "1");
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

/// The final pass's defines (`lean`: LEAN `final lighting`, else `combine`), and with LEAN the
/// pass-through variant's extra define. `shadows`: LEAN specular reads the light-space maps.
fn final_defines(
    lean: bool,
    base: bool,
    albedo: bool,
    shadows: bool,
) -> (Defines, Option<Defines>) {
    let mut defines: Vec<(&str, &str)> = Vec::new();
    if base {
        defines.push(("LUCENT_SSS_BASE", "1"));
    }
    if albedo {
        defines.push(("LUCENT_SSS_ALBEDO", "1"));
    }
    if shadows {
        defines.extend(crate::features::shadows::LIGHTING_DEFINES);
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
            let defines = blur_defines(blur, taps, edges, packed_in, packed, accumulate);
            // Vertical passes after the first read the previous sum.
            if accumulate {
                let mut sum_in = defines.clone();
                sum_in.push(SUM_IN);
                out.push(PipelineShaders::fullscreen(BLUR_FRAGMENT, &sum_in));
            }
            out.push(PipelineShaders::fullscreen(BLUR_FRAGMENT, &defines));
        }
    }
    for lean in [false, true] {
        let fragment = if lean {
            LEAN_FINAL_SHADER
        } else {
            COMBINE_FRAGMENT
        };
        for (base, albedo) in [(false, false), (false, true), (true, false), (true, true)] {
            for shadows in [false, true] {
                let (defines, passthrough) = final_defines(lean, base, albedo, shadows);
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
    pub knobs: &'static [&'static crate::features::knob::Knob],
    /// The per-pass timings the thesis published for it (Tables 1 and 2).
    pub published_timing: Option<&'static crate::features::technique::SeedTable>,
    /// The built-in scene it is measured on.
    pub scene: &'static str,
}

super::chain_technique_module!(IterativeChain);

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

/// The machine the thesis's tables were measured on.
pub(super) const THESIS_DEVICE: &str =
    "NVIDIA GTX 770, 1024x768 (Visual Studio Graphics Debugger, average of ten runs)";
