//! The screen-space SSS chains' settings ([`SssKnobs`]): what a frame's blurs are built with.
//! The command-line knobs that set them are [`super::knobs`].

use ash::vk;

use super::kernel;

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

    pub(super) fn format(self) -> vk::Format {
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

/// The Burley blur's default sample budget (measured in docs/sss.md, "Burley").
pub const DEFAULT_BURLEY_BUDGET: u32 = 8;

/// The Burley blur's budgets `--burley-budget` takes.
pub const BURLEY_BUDGET_RANGE: (u32, u32) = (4, 256);

/// The screen-space SSS knobs a frame is built with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssKnobs {
    /// Refit the profile with this many Gaussians (fewer blur pairs; [`crate::scene::profile::fit_profile`] reports
    /// the error it costs). `None`: the material's own profile.
    pub gaussians: Option<usize>,
    /// Precision of the sum targets.
    pub precision: SssPrecision,
    /// Bilateral blur: sensitivity to depth differences, relative to each Gaussian's own
    /// width (`DEFAULT_SENSITIVITY`).
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
    /// The two-pass blurs (separable, bilateral): samples per direction, 11, 17 or 25
    /// (`kernel::SAMPLE_COUNTS`).
    pub samples: u32,
    /// The separable blur's 1-D kernel function (`kernel::KernelShape`).
    pub shape: kernel::KernelShape,
    /// The separable blur at half resolution per side (a quarter of the pixels), upsampled
    /// depth-aware in a combine pass.
    pub half_res: bool,
    /// The separable blur's taps: the nearest texel (the default: one fetch instead of four on
    /// a CPU driver, measured as close to the brute-force reference as bilinear taps,
    /// docs/sss.md), or bilinear between texels (Jimenez's).
    pub point_taps: bool,
    /// The Burley blur's most samples per pixel (HDRP's budget; fewer where the kernel covers
    /// fewer pixels: `pi R^2 / 4`).
    pub burley_budget: u32,
    /// The Burley blur's golden-angle spiral rotated by one of nine angles per 3x3 block (the
    /// resolve averages the nine); off: every pixel samples the same directions.
    pub burley_rotation: bool,
    /// The fit of Burley's `s` from the albedo, for materials that give a mean free path.
    pub burley_fit: crate::scene::profile::BurleyFit,
    /// The Burley gather at half resolution per side (a quarter of the gathers), resolved at
    /// full resolution over the 3x3 half-resolution texels around each pixel.
    pub burley_half_res: bool,
    /// Every SSS material's texturing mode instead of its own (`--sss-texturing`).
    pub texturing: Option<crate::scene::material::Texturing>,
    /// SSS materials with a medium add the light diffused through their thickness
    /// (`super::transmission`; on by default, `--no-sss-transmission` for A/B).
    pub transmission: bool,
}

impl Default for SssKnobs {
    fn default() -> Self {
        Self {
            gaussians: None,
            precision: SssPrecision::Full,
            sensitivity: DEFAULT_SENSITIVITY,
            packed: false,
            taps: 5,
            samples: kernel::DEFAULT_SAMPLES,
            shape: kernel::KernelShape::Marginal,
            half_res: false,
            point_taps: true,
            burley_budget: DEFAULT_BURLEY_BUDGET,
            burley_rotation: true,
            burley_fit: crate::scene::profile::BurleyFit::Searchlight,
            burley_half_res: false,
            texturing: None,
            transmission: true,
        }
    }
}
