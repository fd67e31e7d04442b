//! How a frame is built: [`FrameSettings`], and the [`Technique`] override for A/B runs.

use crate::backend::access::Access;
use crate::features::antialias::Antialias;
use crate::features::debug_view::DebugView;
use crate::features::gbuffer::GBufferPrecision;
use crate::features::knob::{Given, Knob, KnobTargets};
use crate::features::layered::LayeredKnobs;
use crate::features::registry::{self, TechniqueModule};
use crate::features::shadows::ShadowSettings;
use crate::features::sss;
use crate::features::sss::SssBlur;
use crate::features::technique::{same_kind, PartKind, PartKnobs};
use crate::graph::CompileOptions;
use crate::Result;

/// What the frame shades. `Auto` (the default) is what the scene's materials ask for: every
/// feature some material has, composed in one frame. `None` is plain deferred lighting. A
/// registered technique ([`registry::TECHNIQUES`]) restricts the frame to that technique for
/// A/B runs and the seeds' tables: the materials' parts of other techniques are left out, and
/// an SSS technique blurs every SSS material with its blur.
#[derive(Clone, Copy)]
pub enum Technique {
    /// Whatever the materials ask for: GDC 2011 translucency on translucent materials, each
    /// SSS material's profile with its own blur, layered media, normal and albedo maps.
    Auto,
    /// Plain deferred lighting (no translucency, no SSS, no layered media).
    None,
    /// One registered technique alone.
    Only(&'static dyn TechniqueModule),
}

impl PartialEq for Technique {
    fn eq(&self, other: &Self) -> bool {
        self.name() == other.name()
    }
}

impl Eq for Technique {}

impl std::fmt::Debug for Technique {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl Technique {
    /// Every choice with its command-line name: `auto`, `none`, then the registry's techniques
    /// in registry order.
    pub fn all() -> Vec<(&'static str, Technique)> {
        [("auto", Technique::Auto), ("none", Technique::None)]
            .into_iter()
            .chain(
                registry::TECHNIQUES
                    .iter()
                    .map(|&t| (t.name(), Technique::Only(t))),
            )
            .collect()
    }

    /// Parses a command-line name.
    pub fn parse(name: &str) -> Result<Self> {
        crate::error::parse_named(&Self::all(), name, "technique")
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Technique::Auto => "auto",
            Technique::None => "none",
            Technique::Only(t) => t.name(),
        }
    }

    /// One line saying what it shades (help texts, the demo's panel).
    pub fn summary(self) -> &'static str {
        match self {
            Technique::Auto => "what the materials ask for, every technique composed in one frame",
            Technique::None => "plain deferred lighting",
            Technique::Only(t) => t.summary(),
        }
    }

    /// The registered technique this restricts the frame to, if any.
    pub fn module(self) -> Option<&'static dyn TechniqueModule> {
        match self {
            Technique::Only(t) => Some(t),
            Technique::Auto | Technique::None => None,
        }
    }

    /// The screen-space SSS blur this technique forces on every SSS material, if any.
    pub fn sss_blur(self) -> Option<SssBlur> {
        self.module().and_then(registry::blur_of_technique)
    }

    /// Whether the frame keeps the part `kind` of its materials: `auto` keeps every part, a
    /// registered technique only its own, `none` none.
    pub fn keeps(self, kind: &dyn PartKind) -> bool {
        match self {
            Technique::Auto => true,
            Technique::None => false,
            Technique::Only(t) => same_kind(t.part(), kind),
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
    /// Frames with SSS: also export the lighting pass's diffuse and specular, apart, before
    /// the blurs (what a host hands [`crate::embed::SssEffect`]; tests compare the two
    /// paths); otherwise they stay transient.
    pub export_lit: bool,
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
    /// Frames recorded and submitted before the first completes (1 to
    /// [`crate::gpu_scene::per_frame::MAX_FRAMES_IN_FLIGHT`]): the per-frame parameters get
    /// one slot each, and each frame's first use of a transient image waits for the previous
    /// frame's last. With 1 the caller waits for each frame before submitting the next.
    pub frames_in_flight: usize,
    /// Write the frame into an image the caller gives (a host's swapchain or render target)
    /// instead of lucent's own `display` image; each frame binds its image
    /// ([`super::Renderer::bind_target`]).
    pub target: Option<TargetDesc>,
    /// Light-space maps: whether lights cast shadows (each light's own switch still applies)
    /// and the map size.
    pub shadows: ShadowSettings,
    /// Li et al.'s layered passes' knobs (march steps, pixel lights, phase function,
    /// irradiance resolution, single-scattering depth).
    pub layered: LayeredKnobs,
    /// Anti-aliasing after the tonemap (off by default: see [`Antialias`]).
    pub antialias: Antialias,
    /// Frames with anti-aliasing: also export the tonemapped image before it (sRGB-encoded,
    /// luma in alpha) for the CPU reference of the pass ([`crate::reference::fxaa`]).
    pub export_ldr: bool,
    /// Frames with light-space maps: also export the depth atlas (what a host hands
    /// [`crate::embed::TransmissionEffect`] as its shadow map; tests compare the two).
    pub export_shadows: bool,
}

/// An image the caller renders into: its format, the state it is in when the frame starts
/// and the state the frame must leave it in. The size is the frame's.
///
/// The encoding follows the format: UNORM targets get the sRGB transfer function applied by
/// the shader (as lucent's own display image), `_SRGB` targets are written linear and the
/// hardware encodes, float targets are written linear (the tonemapped, display-referred
/// values, for a host that composites in linear light).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TargetDesc {
    /// Its format: any colour-renderable 8-bit UNORM or SRGB, fp16 or fp32 RGBA format.
    pub format: ash::vk::Format,
    /// How the host last used it (`Access::Undefined` when its contents do not matter).
    pub initial: Access,
    /// How the host uses it next (`Access::Present` for a swapchain image, `TransferRead`
    /// to read it back, `FragmentSampledRead` to sample it).
    pub final_access: Access,
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
    /// Defaults for a size: technique `auto` (what the materials ask for), merging and
    /// aliasing on, no HDR export, one frame in flight, lucent's own display image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            technique: Technique::Auto,
            compile: CompileOptions::default(),
            export_hdr: false,
            export_gbuffer: false,
            export_lit: false,
            gbuffer: GBufferPrecision::Compact,
            force_grayscale: false,
            sss_tiles: true,
            fault: None,
            sss: sss::SssKnobs::default(),
            debug_view: None,
            frames_in_flight: 1,
            target: None,
            shadows: ShadowSettings::default(),
            layered: LayeredKnobs::default(),
            antialias: Antialias::Off,
            export_ldr: false,
            export_shadows: false,
        }
    }

    /// The settings technique knobs set, for a knob's `apply`
    /// ([`crate::features::knob::Knob`]).
    pub fn knob_targets(&mut self) -> KnobTargets<'_> {
        KnobTargets {
            sss: &mut self.sss,
            layered: &mut self.layered,
            force_grayscale: &mut self.force_grayscale,
            sss_tiles: &mut self.sss_tiles,
        }
    }

    /// The knobs a frame's parts read ([`crate::features::technique`]).
    pub fn part_knobs(&self) -> PartKnobs<'_> {
        PartKnobs {
            sss: &self.sss,
            layered: &self.layered,
            force_grayscale: self.force_grayscale,
            sss_tiles: self.sss_tiles,
        }
    }

    /// Sets technique knob `knob` to `value` (a value [`crate::features::knob::Takes::parse`]
    /// accepted).
    pub fn set_knob(&mut self, knob: &Knob, value: Given) {
        (knob.apply)(&mut self.knob_targets(), value);
    }
}
