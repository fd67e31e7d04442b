//! The layered passes' settings ([`LayeredKnobs`]): what a frame's single and multiple
//! scattering are built with. The command-line knobs that set them are [`super::knobs`].

/// March steps the knob takes (Li et al. do not say; the default 4 is within 4% of the
/// 256-step reference on the test spheres, docs/layered.md).
pub const STEP_RANGE: std::ops::RangeInclusive<u32> = 1..=64;
/// Pixel lights the knob takes (Li et al. use 12).
pub const PIXEL_LIGHT_RANGE: std::ops::RangeInclusive<u32> = 4..=64;

/// Which phase function single scattering evaluates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PhaseForm {
    /// True Henyey-Greenstein.
    #[default]
    HenyeyGreenstein,
    /// Schlick's approximation (`k = 1.55 g - 0.55 g^3`; Li et al.'s eq. 9).
    Schlick,
}

impl PhaseForm {
    /// Every form with its command-line name.
    pub const ALL: &'static [(&'static str, PhaseForm)] = &[
        ("hg", PhaseForm::HenyeyGreenstein),
        ("schlick", PhaseForm::Schlick),
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("?", |(n, _)| n)
    }
}

/// The layered passes' knobs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayeredKnobs {
    /// Single scattering's march steps `K` (`STEP_RANGE`).
    pub steps: u32,
    /// Multiple scattering's pixel lights `M` (`PIXEL_LIGHT_RANGE`).
    pub pixel_lights: u32,
    /// The phase function.
    pub phase: PhaseForm,
    /// The irradiance image at half resolution per side.
    pub half_irradiance: bool,
    /// Multiple scattering gathered at half resolution per side (one gather per 2x2 block,
    /// the default), resolved at full resolution in the single scattering pass over the 4x4
    /// texels around each pixel; or per pixel (`false`), resolved over 3x3 pixels. Both
    /// rotate the gather's spiral by one of nine angles per 3x3 block of the gather's own
    /// texels and give every rotation an equal share in the resolve: the same error against
    /// the reference and the same grain, for a quarter of the gathers (docs/layered.md).
    pub half_gather: bool,
    /// Single scattering's depth `D_max` in mean free paths of the first layer's clearest
    /// channel (> 0; default 4: beyond, `e^-4` of the light is left to multiple scattering).
    pub max_depth_mfp: f32,
}

impl Default for LayeredKnobs {
    fn default() -> Self {
        Self {
            steps: 4,
            pixel_lights: 12,
            phase: PhaseForm::HenyeyGreenstein,
            half_irradiance: false,
            half_gather: true,
            max_depth_mfp: 4.0,
        }
    }
}
