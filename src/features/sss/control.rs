//! The LEAN-mapping thesis's control (C): Jimenez et al.'s separable sum-of-Gaussians blur of
//! the lit diffuse light. One horizontal + vertical pair per Gaussian of the profile, each a
//! 7-tap kernel as wide as the Gaussian projected at the pixel's depth, taps across depth
//! edges lerped back to the centre colour, then `combine` adds the specular back
//! (glsl/sss/blur.frag, glsl/sss/combine.frag).

use super::iterative::IterativeChain;

/// The control technique (`--technique control`, `blur = "control"`).
pub static CONTROL: IterativeChain = IterativeChain {
    name: "control",
    summary: "the thesis's control: Jimenez's separable sum-of-Gaussians blur of the lit \
              diffuse light, one blur pair per Gaussian",
    lean: false,
    bilateral: false,
    knobs: &["--sss-gaussians", "--sss-precision", "--no-sss-tiles"],
    scene: "skin",
};
