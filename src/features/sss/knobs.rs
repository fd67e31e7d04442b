//! The screen-space SSS chains' command-line knobs, declared once here and listed by each
//! chain's module (`control`, `lcb`, `lbb`, `separable`, `bilateral`) among its knobs.

use super::kernel;
use super::settings::{SssPrecision, DEFAULT_SENSITIVITY};
use crate::features::knob::{Given, Knob, Takes};
use crate::scene::material::Texturing;

/// `--sss-gaussians N`: refit the profile with fewer Gaussians.
pub static GAUSSIANS: Knob = Knob {
    flag: "--sss-gaussians",
    help: "SSS (control, lcb, lbb, and the two-pass blurs' kernels): refit the profile with \
           this many Gaussians (1-8): fewer blur pairs, at the fit error `lucent plan` and the \
           report print. Default: the material's own profile.",
    takes: Takes::Whole { min: 1, max: 8 },
    default: None,
    apply: |k, v| k.sss.gaussians = Some(v.whole() as usize),
};

/// `--sss-precision half|full`: the sum targets' format.
pub static PRECISION: Knob = Knob {
    flag: "--sss-precision",
    help: "SSS (control, lcb, lbb): precision of the sum-of-Gaussians targets: half (RGBA16F) \
           or full (RGBA32F, the default).",
    takes: Takes::Choice(&["half", "full"]),
    default: Some(Given::Choice("full")),
    apply: |k, v| {
        if let Some((_, precision)) = SssPrecision::ALL.iter().find(|(n, _)| *n == v.choice()) {
            k.sss.precision = *precision;
        }
    },
};

/// `--sensitivity X`: the bilateral blur's depth sensitivity.
pub static SENSITIVITY: Knob = Knob {
    flag: "--sensitivity",
    help: "LBB: the bilateral blur's sensitivity to depth differences, relative to each \
           profile Gaussian's width (a finite number >= 0; 1: weights follow the taps' 3D \
           distance; default 1).",
    takes: Takes::Number {
        accept: |x| x >= 0.0,
        noun: "a finite number >= 0",
    },
    default: Some(Given::Number(DEFAULT_SENSITIVITY)),
    apply: |k, v| k.sss.sensitivity = v.number(),
};

/// `--sss-packed`: LBB's ping-pong as one packed target.
pub static PACKED: Knob = Knob {
    flag: "--sss-packed",
    help: "LBB: blur the light and the LEAN moments as one packed RGBA32UI target (eight fp16 \
           halves) instead of two RGBA16F targets (A/B comparison; slower on lavapipe).",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| k.sss.packed = true,
};

/// `--sss-taps N`: LBB's bilateral taps per direction.
pub static TAPS: Knob = Knob {
    flag: "--sss-taps",
    help: "LBB: bilateral taps per direction (3, 5 or 7; default 5; the thesis's shader has 7).",
    takes: Takes::WholeOf(&[3, 5, 7]),
    default: Some(Given::Whole(5)),
    apply: |k, v| k.sss.taps = v.whole(),
};

/// `--sss-samples N`: the two-pass blurs' kernel samples.
pub static SAMPLES: Knob = Knob {
    flag: "--sss-samples",
    help: "The two-pass blurs (separable, bilateral): samples per direction (11, 17 or 25; \
           default 17).",
    takes: Takes::WholeOf(&kernel::SAMPLE_COUNTS),
    default: Some(Given::Whole(kernel::DEFAULT_SAMPLES)),
    apply: |k, v| k.sss.samples = v.whole(),
};

/// `--sss-kernel marginal|line`: the two-pass blurs' 1-D kernel.
pub static KERNEL: Knob = Knob {
    flag: "--sss-kernel",
    help: "The two-pass blurs' 1-D kernel: marginal (each Gaussian's 1-D marginal, the \
           default) or line (the profile along a line, Jimenez 2015).",
    takes: Takes::Choice(&["marginal", "line"]),
    default: Some(Given::Choice("marginal")),
    apply: |k, v| {
        k.sss.shape = if v.choice() == "line" {
            kernel::KernelShape::Line
        } else {
            kernel::KernelShape::Marginal
        }
    },
};

/// `--sss-half-res`: the separable blur at half resolution.
pub static HALF_RES: Knob = Knob {
    flag: "--sss-half-res",
    help: "The separable blur at half resolution per side, upsampled depth-aware.",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| k.sss.half_res = true,
};

/// `--sss-filter point|bilinear`: the separable blur's taps.
pub static FILTER: Knob = Knob {
    flag: "--sss-filter",
    help: "The separable blur's taps: bilinear (between texels, Jimenez's) or point (the \
           nearest texel, the default: one fetch instead of four on a CPU driver).",
    takes: Takes::Choice(&["point", "bilinear"]),
    default: Some(Given::Choice("point")),
    apply: |k, v| k.sss.point_taps = v.choice() == "point",
};

/// `--sss-texturing pre|post|pre-post`: where every SSS material's albedo meets the blur.
pub static TEXTURING: Knob = Knob {
    flag: "--sss-texturing",
    help: "Every screen-space SSS material: where its albedo (texture included) is applied: \
           post (after the blur), pre-post (its square root before and after) or pre (blurred \
           with the light: textures smear). Default: each material's `texturing` (post \
           unless it says otherwise).",
    takes: Takes::Choice(&["pre", "post", "pre-post"]),
    default: None,
    apply: |k, v| k.sss.texturing = Texturing::named(v.choice()),
};

/// `--no-sss-tiles`: every SSS chain over the whole screen.
pub static NO_TILES: Knob = Knob {
    flag: "--no-sss-tiles",
    help: "Run the SSS blurs over the whole screen instead of only the rectangles of objects \
           with a profile (A/B comparison).",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| *k.sss_tiles = false,
};

/// `--no-sss-transmission`: leave out the light diffused through SSS materials' thickness.
pub static NO_TRANSMISSION: Knob = Knob {
    flag: "--no-sss-transmission",
    help: "SSS materials with a [material.medium]: leave out the light their medium diffuses \
           through the object's thickness from its far side (measured in the light-space maps; \
           on by default; A/B comparison).",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| k.sss.transmission = false,
};
