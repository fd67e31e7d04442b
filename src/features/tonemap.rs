//! HDR to display: exposure, ACES fit, and the encoding the display image's format needs:
//! the sRGB transfer function into UNORM targets (lucent's own RGBA8 display, a host's UNORM
//! swapchain), linear values into `_SRGB` targets (the hardware encodes) and float targets.
//!
//! The tonemap samples its input rather than reading it as an input attachment: it is where the
//! post chain (SSS blurs, which read neighbourhoods) ends, so it is its own physical pass with
//! its own timing row whatever precedes it.

use std::sync::Arc;

use ash::vk;

use crate::graph::{Handle, Image, LoadOp, RenderGraph};

use super::pass::FullscreenPass;
use crate::gpu_scene::{SceneGpu, FRAME};

/// Display target format: sRGB-encoded by the shader, stored as UNORM.
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// Whether a display image of `format` is written linear (the hardware or the host encodes)
/// rather than sRGB-encoded by the shader.
pub fn writes_linear(format: vk::Format) -> bool {
    crate::backend::format::format_info(format).is_some_and(|f| {
        matches!(
            f.kind,
            crate::backend::format::FormatKind::Srgb | crate::backend::format::FormatKind::Float
        )
    })
}

/// What the tonemap writes into its image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    /// sRGB-encoded colour (lucent's own display, a host's UNORM target).
    Srgb,
    /// Linear colour (sRGB and float targets: the hardware or nobody encodes).
    Linear,
    /// sRGB-encoded colour with its luma in alpha: the anti-aliasing pass's input.
    SrgbLumaInAlpha,
}

/// Declares the tonemap pass: samples `hdr`, writes `display` (encoded for its format).
pub fn tonemap_pass(
    graph: &mut RenderGraph,
    hdr: &Handle<Image>,
    display: Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let encoding = if writes_linear(graph.resources()[display.id()].info.format) {
        Encoding::Linear
    } else {
        Encoding::Srgb
    };
    declare(graph, hdr, display, encoding, scene)
}

/// Declares the tonemap of a frame with anti-aliasing: samples `hdr`, writes `ldr` (an
/// [`LDR_FORMAT`] image) sRGB-encoded with the luma of each pixel in alpha, what
/// [`super::antialias`] reads.
pub fn tonemap_with_luma_pass(
    graph: &mut RenderGraph,
    hdr: &Handle<Image>,
    ldr: Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    declare(graph, hdr, ldr, Encoding::SrgbLumaInAlpha, scene)
}

fn declare(
    graph: &mut RenderGraph,
    hdr: &Handle<Image>,
    mut output: Handle<Image>,
    encoding: Encoding,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let mut pass = FullscreenPass::new(graph, "tonemap", TONEMAP_FRAGMENT, scene);
    pass.per_frame(&FRAME)
        .sample("hdr", hdr)
        .color(&mut output, LoadOp::DontCare)
        .defines(tonemap_defines(encoding));
    pass.finish();
    output
}

/// The tonemap's fragment shader.
const TONEMAP_FRAGMENT: &str = "post/tonemap.frag";

/// The tonemap's defines for an encoding.
fn tonemap_defines(encoding: Encoding) -> &'static [(&'static str, &'static str)] {
    match encoding {
        Encoding::Srgb => &[],
        Encoding::Linear => &[("LUCENT_OUTPUT_LINEAR", "1")],
        Encoding::SrgbLumaInAlpha => &[("LUCENT_LUMA_IN_ALPHA", "1")],
    }
}

/// The pipelines the tonemap of any frame builds.
pub(crate) fn shader_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    for encoding in [Encoding::Srgb, Encoding::Linear, Encoding::SrgbLumaInAlpha] {
        out.push(crate::backend::shader::PipelineShaders::fullscreen(
            TONEMAP_FRAGMENT,
            tonemap_defines(encoding),
        ));
    }
}
