use crate::features::debug_view::DebugView;
use crate::features::deferred::GBufferPrecision;
use crate::features::sss;
use crate::graph::CompileOptions;
use crate::{LucentError, Result};

/// Which technique lights the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// Plain deferred lighting (no translucency, no SSS).
    None,
    /// Deferred lighting plus GDC 2011 thickness-based translucency for translucent materials.
    Translucency,
    /// Screen-space SSS, the thesis's control: Jimenez's separable sum-of-Gaussians blur of the
    /// lit diffuse light for materials with an SSS profile.
    Control,
    /// The thesis's LEAN pipeline with the control's blur: LEAN maps projected to the view
    /// plane, the lit diffuse and the LEAN moments blurred with Jimenez's kernel, LEAN specular
    /// with Fresnel evaluated on the blurred moments.
    Lcb,
    /// The thesis's technique: the LEAN pipeline with a separable bilateral (depth-weighted)
    /// blur of the projected G-buffer in ping-pong targets.
    Lbb,
}

impl Technique {
    /// Every technique with its command-line name.
    pub const ALL: &'static [(&'static str, Technique)] = &[
        ("none", Technique::None),
        ("translucency", Technique::Translucency),
        ("control", Technique::Control),
        ("lcb", Technique::Lcb),
        ("lbb", Technique::Lbb),
    ];

    /// Parses a command-line name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, t)| t)
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "unknown technique '{name}'; available: {}",
                    Self::ALL
                        .iter()
                        .map(|(n, _)| *n)
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, t)| *t == self)
            .map_or("?", |(n, _)| n)
    }

    /// The screen-space SSS blur this technique runs, if any.
    pub fn sss_blur(self) -> Option<sss::SssBlur> {
        match self {
            Technique::None | Technique::Translucency => None,
            Technique::Control => Some(sss::SssBlur::Control),
            Technique::Lcb => Some(sss::SssBlur::LeanControl),
            Technique::Lbb => Some(sss::SssBlur::LeanBilateral),
        }
    }
}

/// How a frame is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Technique.
    pub technique: Technique,
    /// Graph compiler switches.
    pub compile: CompileOptions,
    /// Also export the linear HDR image (for EXR output); otherwise it stays transient.
    pub export_hdr: bool,
    /// Also export the G-buffer (for the CPU reference); otherwise it stays transient.
    pub export_gbuffer: bool,
    /// Precision of the G-buffer's colour targets.
    pub gbuffer: GBufferPrecision,
    /// Write coloured thickness as grayscale (its luminance) even when the scene has colour:
    /// the talk's one-channel G-buffer, for A/B comparisons.
    pub force_grayscale: bool,
    /// Run the SSS blurs only over the screen rectangles of objects with a profile (off: the
    /// whole screen, for A/B comparisons).
    pub sss_tiles: bool,
    /// Robustness tests: the lighting pass writes this value into one pixel, so tests can
    /// prove that later passes keep it from spreading.
    pub fault: Option<Fault>,
    /// Screen-space SSS knobs (Gaussian count, precision, bilateral sensitivity).
    pub sss: sss::SssKnobs,
    /// Show a G-buffer target (or the lit image before SSS) instead of the frame, when the
    /// frame has it (the demo's debug views).
    pub debug_view: Option<DebugView>,
}

/// A value injected into one pixel of the lit image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// NaN (true) or +Inf (false).
    pub nan: bool,
}

impl FrameSettings {
    /// Defaults for a size: technique none, merging and aliasing on, no HDR export.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            technique: Technique::None,
            compile: CompileOptions::default(),
            export_hdr: false,
            export_gbuffer: false,
            gbuffer: GBufferPrecision::Compact,
            force_grayscale: false,
            sss_tiles: true,
            fault: None,
            sss: sss::SssKnobs::default(),
            debug_view: None,
        }
    }
}
