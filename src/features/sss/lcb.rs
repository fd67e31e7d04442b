//! LCB: the LEAN-mapping thesis's LEAN pipeline with the control's blur. LEAN maps projected
//! to the view plane in the G-buffer; the lit diffuse and the LEAN slopes and moments blurred
//! together with Jimenez's kernel, one pair per Gaussian; then `final lighting` evaluates LEAN
//! specular with Fresnel on the blurred moments (glsl/sss/lean_brdf.frag).

use super::iterative::IterativeChain;
use super::knobs;

/// LCB (`--technique lcb`, `blur = "lcb"`).
pub static LCB: IterativeChain = IterativeChain {
    name: "lcb",
    summary: "the thesis's LEAN pipeline with the control's blur: lit diffuse and LEAN \
              moments blurred together, LEAN specular on the blurred moments",
    lean: true,
    bilateral: false,
    knobs: &[
        &knobs::GAUSSIANS,
        &knobs::PRECISION,
        &knobs::TEXTURING,
        &knobs::NO_TILES,
        &knobs::NO_TRANSMISSION,
    ],
    scene: "teapot",
    published_timing: Some(&super::lbb::THESIS_TABLE_1_LBB),
};
