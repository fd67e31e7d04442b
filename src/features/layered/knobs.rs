//! The layered passes' command-line knobs, declared once here and listed by the layered
//! technique ([`super::LAYERED`]).

use super::settings::{PhaseForm, PIXEL_LIGHT_RANGE, STEP_RANGE};
use crate::features::knob::{Given, Knob, Takes};

/// `--layered-steps N`: single scattering's march steps.
pub static STEPS_KNOB: Knob = Knob {
    flag: "--layered-steps",
    help: "Layered media (Li et al.): single scattering's march steps along the refracted view \
           ray (1 to 64; default 4).",
    takes: Takes::Whole {
        min: *STEP_RANGE.start(),
        max: *STEP_RANGE.end(),
    },
    default: Some(Given::Whole(4)),
    apply: |k, v| k.layered.steps = v.whole(),
};

/// `--pixel-lights N`: multiple scattering's pixel lights.
pub static PIXEL_LIGHTS_KNOB: Knob = Knob {
    flag: "--pixel-lights",
    help: "Layered media: multiple scattering's pixel lights per pixel (4 to 64; default 12, \
           Li et al.'s).",
    takes: Takes::Whole {
        min: *PIXEL_LIGHT_RANGE.start(),
        max: *PIXEL_LIGHT_RANGE.end(),
    },
    default: Some(Given::Whole(12)),
    apply: |k, v| k.layered.pixel_lights = v.whole(),
};

/// `--phase hg|schlick`: single scattering's phase function.
pub static PHASE_KNOB: Knob = Knob {
    flag: "--phase",
    help: "Layered media: single scattering's phase function: hg (true Henyey-Greenstein, the \
           default) or schlick (Li et al.'s eq. 9 form with Schlick's k).",
    takes: Takes::Choice(&["hg", "schlick"]),
    default: Some(Given::Choice("hg")),
    apply: |k, v| {
        if let Some((_, phase)) = PhaseForm::ALL.iter().find(|(n, _)| *n == v.choice()) {
            k.layered.phase = *phase;
        }
    },
};

/// `--half-irradiance`: the irradiance image at half resolution.
pub static HALF_IRRADIANCE_KNOB: Knob = Knob {
    flag: "--half-irradiance",
    help: "Layered media: the irradiance image multiple scattering gathers from at half \
           resolution per side.",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| k.layered.half_irradiance = true,
};

/// `--gather half|full`: multiple scattering gathered per 2x2 block (the default) or per pixel.
pub static GATHER_KNOB: Knob = Knob {
    flag: "--gather",
    help: "Layered media: multiple scattering's pixel-light gather, half (the default: once per \
           2x2 block, resolved at full resolution over the 4x4 half-resolution texels around \
           each pixel, by material and depth) or full (once per pixel, resolved over 3x3 \
           pixels; the same error and grain for about 3x the gather's time).",
    takes: Takes::Choice(&["half", "full"]),
    default: Some(Given::Choice("half")),
    apply: |k, v| k.layered.half_gather = v.choice() == "half",
};

/// `--single-depth X`: single scattering's depth in mean free paths.
pub static SINGLE_DEPTH_KNOB: Knob = Knob {
    flag: "--single-depth",
    help: "Layered media: single scattering's depth D_max in mean free paths of the first \
           layer (a finite number > 0; default 4).",
    takes: Takes::Number {
        accept: |x| x > 0.0 && x <= 1e3,
        noun: "a number of mean free paths in (0, 1000]",
    },
    default: Some(Given::Number(4.0)),
    apply: |k, v| k.layered.max_depth_mfp = v.number(),
};
