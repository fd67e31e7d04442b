//! LBB: the LEAN-mapping thesis's technique. The LEAN pipeline of [`super::lcb`] with a
//! separable *bilateral* blur in ping-pong targets: point taps weighted by a depth Gaussian as
//! wide as the Gaussian each step completes (`--sensitivity`), 3, 5 or 7 taps per direction
//! (`--sss-taps`), optionally both blurred texels packed into one RGBA32UI (`--sss-packed`).

use super::iterative::IterativeChain;

/// LBB (`--technique lbb`, `blur = "lbb"`).
pub static LBB: IterativeChain = IterativeChain {
    name: "lbb",
    summary: "the thesis's technique: the LEAN pipeline with a separable bilateral \
              (depth-weighted) blur per Gaussian in ping-pong targets",
    lean: true,
    bilateral: true,
    knobs: &[
        "--sss-taps",
        "--sss-packed",
        "--sensitivity",
        "--sss-gaussians",
        "--sss-precision",
        "--no-sss-tiles",
    ],
    scene: "teapot",
};
