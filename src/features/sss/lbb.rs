//! LBB: the LEAN-mapping thesis's technique. The LEAN pipeline of [`super::lcb`] with a
//! separable *bilateral* blur in ping-pong targets: point taps weighted by a depth Gaussian as
//! wide as the Gaussian each step completes (`--sensitivity`), 3, 5 or 7 taps per direction
//! (`--sss-taps`), optionally both blurred texels packed into one RGBA32UI (`--sss-packed`).

use super::iterative::IterativeChain;
use super::iterative::THESIS_DEVICE;
use super::knobs;
use crate::features::technique::{seed_row, SeedTable};

/// LBB (`--technique lbb`, `blur = "lbb"`).
pub static LBB: IterativeChain = IterativeChain {
    name: "lbb",
    summary: "the thesis's technique: the LEAN pipeline with a separable bilateral \
              (depth-weighted) blur per Gaussian in ping-pong targets",
    lean: true,
    bilateral: true,
    knobs: &[
        &knobs::TAPS,
        &knobs::PACKED,
        &knobs::SENSITIVITY,
        &knobs::GAUSSIANS,
        &knobs::PRECISION,
        &knobs::TEXTURING,
        &knobs::NO_TILES,
        &knobs::NO_TRANSMISSION,
    ],
    scene: "teapot",
    published_timing: Some(&THESIS_TABLE_1_LBB),
};

/// The LEAN-mapping SSS thesis, section 5.1.2, Table 1: "Performance figures for bilateral
/// blur" (LBB, marble, four blurs).
pub static THESIS_TABLE_1_LBB: SeedTable = SeedTable {
    source: "LEAN-mapping SSS thesis, section 5.1.2, Table 1 (LBB)",
    device: THESIS_DEVICE,
    rows: &[
        seed_row("Projection", 0.20),
        seed_row("Horizontal Blur #1", 0.24),
        seed_row("Vertical Blur #1", 0.63),
        seed_row("Horizontal Blur #2", 0.36),
        seed_row("Vertical Blur #2", 0.63),
        seed_row("Horizontal Blur #3", 0.36),
        seed_row("Vertical Blur #3", 0.63),
        seed_row("Horizontal Blur #4", 0.35),
        seed_row("Vertical Blur #4", 0.63),
        seed_row("Final Lighting Pass", 0.09862),
    ],
};
