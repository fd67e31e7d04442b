//! The technique registry: every technique lucent can put in a frame, each declared by its own
//! module and listed once, in [`TECHNIQUES`].
//!
//! A technique module (for example [`super::sss::separable`]) is a unit struct with a static
//! instance that implements [`TechniqueModule`]: its name (what `--technique NAME` and a
//! scene's `blur = "NAME"` say), a one-line summary, the part of a frame it belongs to
//! ([`super::technique::PartKind`]: which materials it shades), the command-line knobs that act on it, the built-in scene it is measured on,
//! and the shader permutations its passes compile. Everything that lists techniques iterates
//! [`TECHNIQUES`]: the `--technique` names and their help ([`crate::frame::Technique`]), the
//! warnings for knobs that do nothing in a frame, the demo's picker, bench and report, the
//! gallery, the shipped SPIR-V manifest ([`crate::shipped`]) and the tests. No enum or
//! hand-written list elsewhere names a technique.
//!
//! Screen-space SSS techniques are blur chains: their module also implements
//! [`super::sss::SssBlurTechnique`] (how its chain of passes is declared), which its
//! `sss_chain` hands out: the registry makes it the [`super::sss::SssBlur`] handle a
//! material's profile is diffused with. Chains run in registry order, so the order of [`TECHNIQUES`] is also the
//! order of a frame's SSS chains (and of its passes in `lucent plan`).
//!
//! Adding a technique is its module, its shader, one line here and its goldens:
//! `docs/architecture.md` walks through it.

use super::knob::Knob;
use super::sss::SssBlur;
pub use super::technique::TechniqueModule;
use super::technique::{same_kind, Lookup, PartKind};
use crate::scene::material::SssProfile;
use crate::{LucentError, Result};

/// Every technique, in chain order. **The one list**: a new technique is one line here.
pub static TECHNIQUES: &[&dyn TechniqueModule] = &[
    &super::translucency::TRANSLUCENCY,
    &super::sss::control::CONTROL,
    &super::sss::lcb::LCB,
    &super::sss::lbb::LBB,
    &super::sss::separable::SEPARABLE,
    &super::sss::bilateral::BILATERAL,
    &super::sss::burley::BURLEY,
    &super::layered::LAYERED,
];

/// The position of the technique called `name` in [`TECHNIQUES`] (chain order), or `None`.
pub fn position(name: &str) -> Option<usize> {
    TECHNIQUES.iter().position(|t| t.name() == name)
}

/// The screen-space SSS blurs, in chain order.
pub fn sss_blurs() -> impl Iterator<Item = SssBlur> {
    TECHNIQUES
        .iter()
        .enumerate()
        .filter_map(|(rank, t)| blur_at(rank, *t))
}

/// The screen-space SSS techniques, in chain order.
pub fn sss_techniques() -> impl Iterator<Item = &'static dyn TechniqueModule> {
    TECHNIQUES
        .iter()
        .copied()
        .filter(|t| t.sss_chain().is_some())
}

/// The parts of a frame the techniques belong to, each once, in registry order (the order a
/// frame describes them in and runs their passes in).
pub fn part_kinds() -> Vec<&'static dyn PartKind> {
    let mut kinds: Vec<&'static dyn PartKind> = Vec::new();
    for technique in TECHNIQUES {
        let kind = technique.part();
        if !kinds.iter().any(|k| same_kind(*k, kind)) {
            kinds.push(kind);
        }
    }
    kinds
}

/// The registry's lookups, as a frame's parts receive them ([`Lookup`]).
pub struct Registry;

impl Lookup for Registry {
    fn blur_of(&self, profile: &SssProfile) -> Result<SssBlur> {
        blur_of(profile)
    }

    fn blur_of_technique(&self, technique: &'static dyn TechniqueModule) -> Option<SssBlur> {
        blur_of_technique(technique)
    }
}

/// The SSS blur of `technique` (`None` when it is not a screen-space blur).
pub fn blur_of_technique(technique: &'static dyn TechniqueModule) -> Option<SssBlur> {
    let rank = position(technique.name())?;
    blur_at(rank, technique)
}

fn blur_at(rank: usize, technique: &'static dyn TechniqueModule) -> Option<SssBlur> {
    let chain = technique.sss_chain()?;
    Some(SssBlur::new(technique.name(), rank, chain))
}

/// The blur of materials whose profile names none: the one measured best for its error at
/// its cost, artefacts included (docs/sss.md, "Two passes"): the separable blur, with a lower
/// mean error against the brute-force reference than the 12-pass control on `skin` and
/// `teapot`, at about 2x the plain frame where the control costs 9x.
pub fn default_sss_blur() -> SssBlur {
    blur_of_technique(&super::sss::separable::SEPARABLE).expect("the separable blur is registered")
}

/// The blur `profile` is diffused with: the one its material names (`[material.sss] blur`),
/// resolved here with the scene file's file, line and key in the error, or the default.
pub fn blur_of(profile: &SssProfile) -> Result<SssBlur> {
    match &profile.blur {
        None => Ok(default_sss_blur()),
        Some(name) => sss_blur(&name.name).map_err(|e| name.error(e)),
    }
}

/// The SSS blur called `name` (a scene's `blur = "NAME"`), or the error naming every blur.
pub fn sss_blur(name: &str) -> Result<SssBlur> {
    sss_blurs().find(|b| b.name() == name).ok_or_else(|| {
        LucentError::InvalidInput(format!(
            "unknown SSS blur '{name}'; use {}",
            sss_blurs()
                .map(SssBlur::name)
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })
}

/// Checks that every technique `scene`'s materials name is registered (an unknown name is an
/// error naming the scene file, line and key it was written at).
pub fn check_names(scene: &crate::scene::Scene) -> Result<()> {
    for object in &scene.objects {
        if let Some(profile) = &object.material.sss {
            blur_of(profile)?;
        }
    }
    Ok(())
}

/// The techniques that list `knob` among their knobs.
pub fn with_knob(knob: &Knob) -> impl Iterator<Item = &'static dyn TechniqueModule> + '_ {
    TECHNIQUES
        .iter()
        .copied()
        .filter(move |t| t.knobs().iter().any(|k| std::ptr::eq(*k, knob)))
}

/// Every technique knob once, in registry order (the order of the command line's flags).
pub fn knobs() -> Vec<&'static Knob> {
    let mut all: Vec<&'static Knob> = Vec::new();
    for knob in TECHNIQUES.iter().flat_map(|t| t.knobs().iter().copied()) {
        if !all.iter().any(|k| std::ptr::eq(*k, knob)) {
            all.push(knob);
        }
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_not_the_frame_selectors() {
        for (i, t) in TECHNIQUES.iter().enumerate() {
            assert_eq!(position(t.name()), Some(i), "{} registered twice", t.name());
            // `auto` and `none` are what `--technique` says besides the registered names.
            assert!(!["auto", "none"].contains(&t.name()));
            assert!(!t.summary().is_empty());
            assert!(t.knobs().iter().all(|k| k.flag.starts_with("--")));
        }
    }

    /// Two knobs never share a flag (the command line would refuse to build).
    #[test]
    fn knob_flags_are_unique() {
        let knobs = knobs();
        for (i, k) in knobs.iter().enumerate() {
            assert!(knobs[..i].iter().all(|o| o.flag != k.flag), "{k:?} twice");
        }
    }

    #[test]
    fn every_blur_resolves_to_itself() {
        for blur in sss_blurs() {
            assert_eq!(sss_blur(blur.name()).unwrap(), blur);
        }
        let e = sss_blur("gaussian").unwrap_err().to_string();
        assert!(e.contains("unknown SSS blur 'gaussian'; use "), "{e}");
    }
}
