//! The contract every technique module implements ([`TechniqueModule`]); the list of them is
//! [`super::registry`].

use super::knob::Knob;
use super::sss::SssBlurTechnique;
use crate::backend::shader::PipelineShaders;

/// What a technique shades: the materials it applies to.
#[derive(Clone, Copy)]
pub enum Shades {
    /// Materials with a `[material.translucency]` table (GDC 2011's term in the lighting pass).
    Translucent,
    /// Materials with an SSS profile, diffused by this blur chain.
    Scattering(&'static dyn SssBlurTechnique),
    /// Materials with layered media (Li et al.'s scattering passes).
    Layered,
}

/// One technique: its module implements this once (see the module docs).
pub trait TechniqueModule: Sync {
    /// Its name on the command line and in scene files (`--technique NAME`, `blur = "NAME"`).
    fn name(&self) -> &'static str;
    /// One line for help texts and the demo's panel.
    fn summary(&self) -> &'static str;
    /// The materials it shades (`'static`: an SSS technique hands out itself as the chain).
    fn shades(&'static self) -> Shades;
    /// The command-line knobs that act on it ([`Knob`]: flag, range, default, help): a knob
    /// given for a frame where no technique of the frame lists it draws a warning that names
    /// the techniques that do.
    fn knobs(&self) -> &'static [&'static Knob];
    /// The built-in scene made to show it, which bench and report measure it on.
    fn scene(&self) -> &'static str;
    /// Every pipeline its passes may build, for the shipped SPIR-V ([`crate::shipped`]).
    /// Techniques whose shading is compiled into another feature's pass (GDC 2011's term in
    /// the lighting pass) add nothing here.
    fn shader_permutations(&self, out: &mut Vec<PipelineShaders>);
    /// The per-pass timings its seed published for it, which bench (`--compare-seeds`) and
    /// the report print beside ours; `None` when the seed published none.
    fn published_timing(&self) -> Option<&'static SeedTable> {
        None
    }
}

/// One row of a seed's published per-pass timing table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedRow {
    /// The row's name as printed.
    pub name: &'static str,
    /// Milliseconds.
    pub ms: f64,
}

/// A seed's published per-pass timing table, as printed (`report::seeds` sets ours beside it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedTable {
    /// Where it comes from.
    pub source: &'static str,
    /// The machine it was measured on.
    pub device: &'static str,
    /// Its rows in order.
    pub rows: &'static [SeedRow],
}

impl SeedTable {
    /// Sum of the rows, ms.
    pub fn total(&self) -> f64 {
        self.rows.iter().map(|r| r.ms).sum()
    }
}

/// A [`SeedRow`], for writing tables as data.
pub const fn seed_row(name: &'static str, ms: f64) -> SeedRow {
    SeedRow { name, ms }
}
