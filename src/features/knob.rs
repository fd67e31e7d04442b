//! Technique knobs: a command-line flag that turns one approximation of a technique, declared
//! once, in the module of the technique (or technique family) it acts on, as a [`Knob`]: its
//! flag, help text, what values it takes (the range check with the message users see), its
//! default, and how a given value sets the frame's knobs ([`KnobTargets`]).
//!
//! A technique lists the knobs that act on it ([`super::technique::TechniqueModule::knobs`]).
//! The command line builds its flags from the registry's knobs
//! ([`super::registry::knobs`]); a knob given where no technique of the frame lists it draws a
//! warning naming the techniques that do. Nothing outside the technique modules lists knobs.

use super::layered::settings::LayeredKnobs;
use super::sss::settings::SssKnobs;

/// One knob: a flag that acts on one or more techniques.
pub struct Knob {
    /// The flag, `--name`.
    pub flag: &'static str,
    /// Its help text (`lucent render --help`): what it does, its values and its default.
    pub help: &'static str,
    /// What values it takes; parsing checks them.
    pub takes: Takes,
    /// The value it has when not given (`None`: off for a switch, or the scene's own value, as
    /// `--sss-gaussians` keeps each material's profile). A test checks that it is what
    /// [`KnobTargets`]' defaults hold, so the help cannot drift from the code.
    pub default: Option<Given>,
    /// Sets the value given in the frame's knobs. The value was checked by [`Takes::parse`].
    pub apply: fn(&mut KnobTargets<'_>, Given),
}

/// What values a knob takes.
#[derive(Clone, Copy, Debug)]
pub enum Takes {
    /// None: given means on.
    Switch,
    /// A whole number from `min` to `max`.
    Whole {
        /// The smallest value.
        min: u32,
        /// The largest value.
        max: u32,
    },
    /// A whole number among these.
    WholeOf(&'static [u32]),
    /// A finite number that `accept` takes; `noun` says which (`'X' is not NOUN`).
    Number {
        /// Whether a finite number is in range.
        accept: fn(f32) -> bool,
        /// The range in words, for the error.
        noun: &'static str,
    },
    /// One of these names.
    Choice(&'static [&'static str]),
}

/// A knob's value, as given (or its default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Given {
    /// A switch given.
    Switch,
    /// A whole number.
    Whole(u32),
    /// A finite number.
    Number(f32),
    /// A choice's name.
    Choice(&'static str),
}

impl Given {
    /// The whole number (0 for any other kind; [`Takes::parse`] only hands a knob its kind).
    pub fn whole(self) -> u32 {
        match self {
            Given::Whole(n) => n,
            _ => 0,
        }
    }

    /// The finite number (0 for any other kind).
    pub fn number(self) -> f32 {
        match self {
            Given::Number(x) => x,
            _ => 0.0,
        }
    }

    /// The choice's name (empty for any other kind).
    pub fn choice(self) -> &'static str {
        match self {
            Given::Choice(name) => name,
            _ => "",
        }
    }
}

impl Takes {
    /// Parses `text`, or the message for a value out of range (`'TEXT' is not ...`, which the
    /// tests and docs quote).
    pub fn parse(&self, text: &str) -> Result<Given, String> {
        let trimmed = text.trim();
        match *self {
            Takes::Switch => Ok(Given::Switch),
            Takes::Whole { min, max } => trimmed
                .parse::<u32>()
                .ok()
                .filter(|n| (min..=max).contains(n))
                .map(Given::Whole)
                .ok_or_else(|| format!("'{text}' is not a whole number from {min} to {max}")),
            Takes::WholeOf(values) => trimmed
                .parse::<u32>()
                .ok()
                .filter(|n| values.contains(n))
                .map(Given::Whole)
                .ok_or_else(|| {
                    let names: Vec<String> = values.iter().map(u32::to_string).collect();
                    format!("'{text}' is not one of {}", names.join(", "))
                }),
            Takes::Number { accept, noun } => trimmed
                .parse::<f32>()
                .ok()
                // Finite first: NaN and Inf never reach a GPU table through a knob.
                .filter(|x| x.is_finite() && accept(*x))
                .map(Given::Number)
                .ok_or_else(|| format!("'{text}' is not {noun}")),
            Takes::Choice(names) => names
                .iter()
                .find(|name| **name == trimmed)
                .map(|name| Given::Choice(name))
                .ok_or_else(|| format!("'{text}' is not one of {}", names.join(", "))),
        }
    }

    /// The values a knob is tried at (tests, `lucent report truth`): a switch given, both ends
    /// of a whole range, every listed whole number or choice; `None` for a continuous number
    /// (no finite set of values to try).
    pub fn values(&self) -> Option<Vec<Given>> {
        Some(match *self {
            Takes::Switch => vec![Given::Switch],
            Takes::Whole { min, max } => vec![Given::Whole(min), Given::Whole(max)],
            Takes::WholeOf(values) => values.iter().map(|&n| Given::Whole(n)).collect(),
            Takes::Choice(names) => names.iter().map(|&n| Given::Choice(n)).collect(),
            Takes::Number { .. } => return None,
        })
    }

    /// The value's placeholder in `--help` (`N`, `X`, `NAME`; the help text says which);
    /// `None` for a switch.
    pub fn placeholder(&self) -> Option<&'static str> {
        match self {
            Takes::Switch => None,
            Takes::Whole { .. } | Takes::WholeOf(_) => Some("N"),
            Takes::Number { .. } => Some("X"),
            Takes::Choice(_) => Some("NAME"),
        }
    }
}

impl Knob {
    /// The flag without its dashes (clap's argument id and long name).
    pub fn long(&self) -> &'static str {
        self.flag.trim_start_matches('-')
    }
}

impl std::fmt::Debug for Knob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.flag)
    }
}

/// The frame settings technique knobs set: the frame's settings lend them
/// (`crate::frame::FrameSettings::knob_targets`), so a knob's `apply` can sit in its technique's
/// module without that module knowing the frame.
pub struct KnobTargets<'a> {
    /// The screen-space SSS chains' knobs.
    pub sss: &'a mut SssKnobs,
    /// The layered passes' knobs.
    pub layered: &'a mut LayeredKnobs,
    /// The translucency term's thickness stored as grayscale.
    pub force_grayscale: &'a mut bool,
    /// The SSS blurs limited to the rectangles of objects with a profile.
    pub sss_tiles: &'a mut bool,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::registry;

    /// Every knob's declared default is what the settings hold when it is not given: applying
    /// it to default settings changes nothing.
    #[test]
    fn declared_defaults_are_the_settings_defaults() {
        for knob in registry::knobs() {
            let (mut sss, mut layered) = (SssKnobs::default(), LayeredKnobs::default());
            let (mut grayscale, mut tiles) = (false, true);
            let mut targets = KnobTargets {
                sss: &mut sss,
                layered: &mut layered,
                force_grayscale: &mut grayscale,
                sss_tiles: &mut tiles,
            };
            // `None`: off for a switch, or what the scene's materials say (`--sss-gaussians`).
            if let Some(default) = knob.default {
                (knob.apply)(&mut targets, default);
            }
            assert_eq!(sss, SssKnobs::default(), "{knob:?}");
            assert_eq!(layered, LayeredKnobs::default(), "{knob:?}");
            assert_eq!((grayscale, tiles), (false, true), "{knob:?}");
        }
    }

    /// Every value a knob accepts changes the settings it names, or is its default: no knob is
    /// parsed and ignored.
    #[test]
    fn every_knob_acts() {
        for knob in registry::knobs() {
            let values: Vec<Given> = knob
                .takes
                .values()
                .unwrap_or_else(|| vec![knob.takes.parse("0.5").unwrap()]);
            for value in values {
                if Some(value) == knob.default {
                    continue;
                }
                let (mut sss, mut layered) = (SssKnobs::default(), LayeredKnobs::default());
                let (mut grayscale, mut tiles) = (false, true);
                (knob.apply)(
                    &mut KnobTargets {
                        sss: &mut sss,
                        layered: &mut layered,
                        force_grayscale: &mut grayscale,
                        sss_tiles: &mut tiles,
                    },
                    value,
                );
                assert!(
                    sss != SssKnobs::default()
                        || layered != LayeredKnobs::default()
                        || (grayscale, tiles) != (false, true),
                    "{knob:?} {value:?} changed nothing"
                );
            }
        }
    }

    #[test]
    fn parse_says_what_is_wrong() {
        let whole = Takes::Whole { min: 1, max: 8 };
        assert_eq!(whole.parse("8"), Ok(Given::Whole(8)));
        assert_eq!(
            whole.parse("9"),
            Err("'9' is not a whole number from 1 to 8".into())
        );
        assert_eq!(
            Takes::WholeOf(&[3, 5, 7]).parse("4"),
            Err("'4' is not one of 3, 5, 7".into())
        );
        let number = Takes::Number {
            accept: |x| x >= 0.0,
            noun: "a finite number >= 0",
        };
        assert!(number.parse("nan").is_err());
        assert!(number.parse("inf").is_err());
        assert_eq!(
            number.parse("-1"),
            Err("'-1' is not a finite number >= 0".into())
        );
        assert_eq!(
            Takes::Choice(&["a", "b"]).parse(" b"),
            Ok(Given::Choice("b"))
        );
    }
}
