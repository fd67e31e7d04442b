//! Jimenez's separable SSS (2012/2015): one horizontal and one vertical pass with a kernel
//! pre-integrated from the whole profile ([`super::kernel`], `--sss-samples`, `--sss-kernel`),
//! taps following the surface's depth (read from the lit diffuse's alpha), nearest-texel or
//! bilinear (`--sss-filter`), optionally at half resolution with a depth-aware upsample
//! (`--sss-half-res`). The default blur of SSS materials ([`crate::features::registry`]).

use super::knobs;
use super::two_pass::TwoPassChain;

/// The separable blur (`--technique separable`, `blur = "separable"`).
pub static SEPARABLE: TwoPassChain = TwoPassChain {
    name: "separable",
    summary: "Jimenez's separable SSS: two passes with a kernel pre-integrated from the \
              whole profile",
    lean: false,
    bilateral: false,
    half_resolution: true,
    depth_in_alpha: true,
    knobs: &[
        &knobs::GAUSSIANS,
        &knobs::SAMPLES,
        &knobs::KERNEL,
        &knobs::HALF_RES,
        &knobs::FILTER,
        &knobs::TEXTURING,
        &knobs::NO_TILES,
        &knobs::NO_TRANSMISSION,
    ],
    scene: "teapot",
    published_timing: None,
};
