//! Anti-aliasing: FXAA as a post pass after the tonemap (`--aa fxaa`, off by default).
//!
//! A frame with anti-aliasing tonemaps into an intermediate RGBA8 image (sRGB-encoded colour,
//! the luma of each pixel in alpha: [`super::tonemap::tonemap_with_luma_pass`]) and the `fxaa`
//! pass reads it, texel by texel, into the display image, encoded for the display's format
//! (`glsl/post/fxaa.frag`; its f64 twin is [`crate::reference::fxaa`]). Pixels below the
//! contrast thresholds are copied unchanged, so flat regions keep their exact values and the
//! goldens of frames without anti-aliasing stay what they were: a frame without it has neither
//! the pass nor the intermediate image.
//!
//! Cost: 1.4-1.5x the tonemap pass on lavapipe at 1024x768 (it was 4-5x with bilinear taps;
//! docs/antialias.md has the table and where the time went). Why still off by default: it is
//! 4-8% of the frame there, and lucent's frames are measurements (ratios to the plain frame,
//! goldens, f64 references of the display) that a default post pass would shift; a host
//! brings its own anti-aliasing, and on a GPU may well turn this on.

use std::sync::Arc;

use crate::graph::{Handle, Image, LoadOp, RenderGraph};
use crate::Result;

use super::pass::FullscreenPass;
use crate::gpu_scene::{SceneGpu, FRAME};

/// The anti-aliasing a frame applies after the tonemap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Antialias {
    /// None: the tonemap writes the display image directly.
    #[default]
    Off,
    /// FXAA (Lottes' 3.11 "quality" form) on the tonemapped image.
    Fxaa,
}

impl Antialias {
    /// Every mode with its command-line name.
    pub const ALL: &'static [(&'static str, Antialias)] =
        &[("off", Antialias::Off), ("fxaa", Antialias::Fxaa)];

    /// Parses a command-line name.
    pub fn parse(name: &str) -> Result<Self> {
        crate::error::parse_named(Self::ALL, name, "anti-aliasing")
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        crate::error::name_of(Self::ALL, &self)
    }
}

/// The FXAA pass's fragment shader.
const FXAA_FRAGMENT: &str = "post/fxaa.frag";

/// Its defines: `linear` for sRGB and float display images (decoded back to linear).
fn fxaa_defines(linear: bool) -> &'static [(&'static str, &'static str)] {
    if linear {
        &[("LUCENT_OUTPUT_LINEAR", "1")]
    } else {
        &[]
    }
}

/// The pipelines the anti-aliasing of any frame builds.
pub(crate) fn shader_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    for linear in [false, true] {
        out.push(crate::backend::shader::PipelineShaders::fullscreen(
            FXAA_FRAGMENT,
            fxaa_defines(linear),
        ));
    }
}

/// Declares the `fxaa` pass: samples `ldr` (the tonemap's sRGB + luma image), writes
/// `display` encoded for its format.
pub fn fxaa_pass(
    graph: &mut RenderGraph,
    ldr: &Handle<Image>,
    mut display: Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let linear = super::tonemap::writes_linear(graph.resources()[display.id()].info.format);
    let mut pass = FullscreenPass::new(graph, "fxaa", FXAA_FRAGMENT, scene);
    // Read with texel fetches only (the shader averages the texels it needs between).
    pass.per_frame(&FRAME)
        .sample("ldr", ldr)
        .color(&mut display, LoadOp::DontCare)
        .defines(fxaa_defines(linear));
    pass.finish();
    display
}
