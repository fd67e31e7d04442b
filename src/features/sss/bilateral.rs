//! The thesis's bilateral LEAN blur in two passes: the lit diffuse and the LEAN G-buffer
//! blurred by a kernel whose tap weights are the whole profile at each tap's 3D distance (a
//! tabulated falloff in the kernel table), then LEAN specular in the vertical pass.

use super::knobs;
use super::two_pass::TwoPassChain;

/// The two-pass bilateral blur (`--technique bilateral`, `blur = "bilateral"`).
pub static BILATERAL: TwoPassChain = TwoPassChain {
    name: "bilateral",
    summary: "the thesis's bilateral LEAN blur in two passes, tap weights from the whole \
              profile at each tap's 3D distance",
    lean: true,
    bilateral: true,
    half_resolution: false,
    depth_in_alpha: false,
    knobs: &[
        &knobs::GAUSSIANS,
        &knobs::SAMPLES,
        &knobs::KERNEL,
        &knobs::TEXTURING,
        &knobs::NO_TILES,
        &knobs::NO_TRANSMISSION,
    ],
    scene: "teapot",
    published_timing: None,
};
