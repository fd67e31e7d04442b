//! The LEAN-mapping thesis's control (C): Jimenez et al.'s separable sum-of-Gaussians blur of
//! the lit diffuse light. One horizontal + vertical pair per Gaussian of the profile, each a
//! 7-tap kernel as wide as the Gaussian projected at the pixel's depth, taps across depth
//! edges lerped back to the centre colour, then `combine` adds the specular back
//! (glsl/sss/blur.frag, glsl/sss/combine.frag).

use super::iterative::IterativeChain;
use super::iterative::THESIS_DEVICE;
use super::knobs;
use crate::features::technique::{seed_row, SeedTable};

/// The control technique (`--technique control`, `blur = "control"`).
pub static CONTROL: IterativeChain = IterativeChain {
    name: "control",
    summary: "the thesis's control: Jimenez's separable sum-of-Gaussians blur of the lit \
              diffuse light, one blur pair per Gaussian",
    lean: false,
    bilateral: false,
    knobs: &[
        &knobs::GAUSSIANS,
        &knobs::PRECISION,
        &knobs::TEXTURING,
        &knobs::NO_TILES,
        &knobs::NO_TRANSMISSION,
    ],
    scene: "skin",
    published_timing: Some(&THESIS_TABLE_2_CONTROL),
};

/// The thesis, section 5.1.2, Table 2: "Performance figures for the control screen space
/// shader" (Jimenez's blur, marble, four blurs; "Vertical Blur #3" is printed without a unit).
pub static THESIS_TABLE_2_CONTROL: SeedTable = SeedTable {
    source: "LEAN-mapping SSS thesis, section 5.1.2, Table 2 (control)",
    device: THESIS_DEVICE,
    rows: &[
        seed_row("Lighting calculations", 0.05174),
        seed_row("Horizontal Blur #1", 0.10),
        seed_row("Vertical Blur #1", 0.16),
        seed_row("Horizontal Blur #2", 0.11),
        seed_row("Vertical Blur #2", 0.16),
        seed_row("Horizontal Blur #3", 0.14),
        seed_row("Vertical Blur #3", 0.15),
        seed_row("Horizontal Blur #4", 0.14),
        seed_row("Vertical Blur #4", 0.21),
    ],
};
