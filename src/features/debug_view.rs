//! Debug views: a G-buffer target or the lit image before screen-space SSS, written into the
//! display image in place of the tonemapped frame (`FrameSettings::debug_view`).
//!
//! The pass samples its source like the tonemap does, so it is one physical pass of its own;
//! the passes whose results it does not show are culled by the graph (a depth view runs only
//! the G-buffer pass and itself).

use std::sync::Arc;

use crate::graph::{Handle, Image, LoadOp, RenderGraph};

use super::gbuffer::GBuffer;
use super::lighting::Lit;
use super::pass::FullscreenPass;
use super::translucency::ThicknessPacking;
use crate::gpu_scene::{SceneGpu, FRAME};

/// What a debug view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    /// Albedo (GB0 rgb), sRGB-encoded.
    Albedo,
    /// World normal (GB1 xyz) mapped to [0, 1].
    Normal,
    /// Depth: log of the view distance between the near and far planes (near white).
    Depth,
    /// Local thickness (GB2), frames with translucency only.
    Thickness,
    /// Material ID (GB2) as a colour, frames with translucency only.
    MaterialId,
    /// The lit frame before the SSS blurs (diffuse + specular, tonemapped), frames with SSS
    /// only; the ordinary frame is the one after. It shows what the blurs read: a profile that
    /// applies its albedo after the blur (`Texturing::Post`, the default) shows its light
    /// without that albedo.
    LitBeforeSss,
    /// The GDC 2011 translucency term alone (every light, tonemapped), frames with
    /// translucency only.
    TranslucencyTerm,
}

impl DebugView {
    /// Every view with its name, in the order the demo cycles through them.
    pub const ALL: &'static [(&'static str, DebugView)] = &[
        ("albedo", DebugView::Albedo),
        ("normal", DebugView::Normal),
        ("depth", DebugView::Depth),
        ("thickness", DebugView::Thickness),
        ("material ID", DebugView::MaterialId),
        ("translucency term", DebugView::TranslucencyTerm),
        ("SSS before blur", DebugView::LitBeforeSss),
    ];

    /// Display name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("?", |(n, _)| n)
    }

    fn define(self) -> &'static str {
        match self {
            DebugView::Albedo => "LUCENT_VIEW_ALBEDO",
            DebugView::Normal => "LUCENT_VIEW_NORMAL",
            DebugView::Depth => "LUCENT_VIEW_DEPTH",
            DebugView::Thickness => "LUCENT_VIEW_THICKNESS",
            DebugView::MaterialId => "LUCENT_VIEW_MATERIAL",
            DebugView::LitBeforeSss => "LUCENT_VIEW_LIT",
            DebugView::TranslucencyTerm => "LUCENT_VIEW_TERM",
        }
    }
}

/// Declares the debug view pass and returns its display image, or `None` when the frame does
/// not have what the view shows (thickness and material ID without GB2, the pre-blur image
/// without SSS); the caller then uses the ordinary tonemapped frame.
pub fn debug_view_pass(
    graph: &mut RenderGraph,
    view: DebugView,
    gb: &GBuffer,
    lit: &Lit,
    display: impl FnOnce(&mut RenderGraph) -> Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Option<Handle<Image>> {
    let (source, second) = match view {
        DebugView::Albedo => (&gb.gb0, None),
        DebugView::Normal => (&gb.gb1, None),
        DebugView::Depth => (&gb.depth, None),
        DebugView::Thickness | DebugView::MaterialId => (gb.gb2.as_ref()?, None),
        DebugView::LitBeforeSss => {
            gb.sss.as_ref()?;
            (&lit.color, lit.specular.as_ref())
        }
        DebugView::TranslucencyTerm => {
            gb.gb2.as_ref()?;
            (&gb.gb0, Some(&gb.gb1))
        }
    };
    // The term also reads GB2 and depth (and the material table).
    let term_inputs = match (view, &gb.gb2) {
        (DebugView::TranslucencyTerm, Some(gb2)) => Some((gb2, &gb.depth)),
        _ => None,
    };
    let mut ldr = display(graph);
    let linear = super::tonemap::writes_linear(graph.resources()[ldr.id()].info.format);
    let colored = gb
        .layout
        .translucency
        .is_some_and(|t| t.packing == ThicknessPacking::Colored);
    // The term binds its inputs and the material table when the frame has the table; without
    // it the view shows the second image alone (its other reads still declared).
    let has_table = scene.is_some_and(|s| s.per_frame.has(&super::translucency::TABLE_REGION));
    let inputs = match (second, term_inputs) {
        (Some(_), Some(_)) if has_table => ViewInputs::Term,
        (Some(_), _) => ViewInputs::Second,
        _ => ViewInputs::One,
    };
    let mut pass = FullscreenPass::new(graph, "debug view", VIEW_FRAGMENT, scene);
    pass.per_frame(&FRAME).sample("source", source);
    if let Some(s) = second {
        // The term's view reads GB1 there (glsl/debug/view.frag).
        let name = if inputs == ViewInputs::Term {
            "gb1_tex"
        } else {
            "second"
        };
        pass.sample(name, s);
    }
    if let Some((gb2, depth)) = term_inputs {
        if inputs == ViewInputs::Term {
            pass.sample("gb2_tex", gb2)
                .sample("depth_tex", depth)
                .per_frame(&super::translucency::TABLE_REGION);
        } else {
            pass.graph().sample(gb2).sample(depth);
        }
    }
    pass.color(&mut ldr, LoadOp::DontCare)
        .defines(&view_defines(view, inputs, colored, linear));
    pass.finish();
    Some(ldr)
}

/// The debug view's fragment shader.
const VIEW_FRAGMENT: &str = "debug/view.frag";

/// What the debug view samples besides its source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ViewInputs {
    /// The source alone.
    One,
    /// A second image (the pre-blur specular).
    Second,
    /// The translucency term's GB1, GB2, depth and material table.
    Term,
}

/// The debug view's defines: the view, what it samples, GB2's packing and the output encoding.
fn view_defines(
    view: DebugView,
    inputs: ViewInputs,
    colored: bool,
    linear: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut defines = vec![(view.define(), "1")];
    match inputs {
        ViewInputs::Term => defines.push(("LUCENT_POW_MODES", "3")),
        ViewInputs::Second => defines.push(("LUCENT_VIEW_SECOND", "1")),
        ViewInputs::One => {}
    }
    if colored {
        defines.push(("LUCENT_COLORED_THICKNESS", "1"));
    }
    if linear {
        defines.push(("LUCENT_OUTPUT_LINEAR", "1"));
    }
    defines
}

/// The pipelines the debug view of any frame builds.
pub(crate) fn shader_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    for &(_, view) in DebugView::ALL {
        for inputs in [ViewInputs::One, ViewInputs::Second, ViewInputs::Term] {
            for colored in [false, true] {
                for linear in [false, true] {
                    out.push(crate::backend::shader::PipelineShaders::fullscreen(
                        VIEW_FRAGMENT,
                        &view_defines(view, inputs, colored, linear),
                    ));
                }
            }
        }
    }
}
