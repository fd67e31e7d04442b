//! The contract every technique module implements ([`TechniqueModule`]; the list of them is
//! [`super::registry`]), and the parts of a frame the techniques belong to.
//!
//! ## A frame's parts
//!
//! What each family of techniques adds to a frame is declared by the family itself, so that
//! the frame ([`crate::frame`]) knows none of them by kind.
//!
//! Every technique says which part of a frame it belongs to ([`TechniqueModule::part`]): GDC
//! 2011's term ([`super::translucency`]), the screen-space SSS chains ([`super::sss`]) or Li et
//! al.'s layered media ([`super::layered`]). A [`PartKind`] reads a scene's materials and
//! describes what a frame of it needs ([`PartKind::describe`]), or nothing when no material
//! asks for it. That description is a [`FramePart`], which answers for the whole frame:
//!
//! | method | what the frame asks it |
//! |---|---|
//! | [`FramePart::gbuffer`] | the G-buffer targets and lighting variants it needs |
//! | [`FramePart::shadows`] | what the light-space maps must store for it |
//! | [`FramePart::tables`] | its per-frame tables |
//! | [`FramePart::upload`] | what the scene's GPU data must hold for it |
//! | [`FramePart::declare`] | its passes after the lighting pass |
//! | [`FramePart::write_slot`] | its per-frame tables and screen tiles, every frame |
//! | [`FramePart::runs`], [`FramePart::names`] | which techniques it runs, and its lines for messages |
//! | [`FramePart::same_shape`] | whether a new description of it fits the frame already built |
//!
//! A frame holds its parts in registry order (the order of [`super::registry::TECHNIQUES`]),
//! which is also the order their passes run in after the lighting pass. A new family of
//! techniques is a new [`PartKind`] and [`FramePart`], returned by its techniques' `part`: no
//! enum, field or `match` elsewhere names it.

use std::any::Any;
use std::fmt::Debug;
use std::sync::Arc;

use glam::Vec3;

use super::gbuffer::{GBuffer, GBufferLayout};
use super::gbuffer_desc::GBufferDesc;
use super::knob::Knob;
use super::layered::settings::LayeredKnobs;
use super::shadows::{ShadowDesc, ShadowMaps};
use super::sss::settings::SssKnobs;
use super::sss::{SssBlur, SssBlurTechnique};
use crate::backend::shader::PipelineShaders;
use crate::gpu_scene::per_frame::PerFrame;
use crate::gpu_scene::{SceneGpu, SceneUpload, SlotTiles, TableRegion};
use crate::graph::{Handle, Image, RenderGraph};
use crate::scene::material::SssProfile;
use crate::scene::Scene;
use crate::Result;

/// One technique: its module implements this once (see the module docs).
pub trait TechniqueModule: Sync {
    /// Its name on the command line and in scene files (`--technique NAME`, `blur = "NAME"`).
    fn name(&self) -> &'static str;
    /// One line for help texts and the demo's panel.
    fn summary(&self) -> &'static str;
    /// The part of a frame it belongs to (see the module docs): the family that describes, from
    /// the materials, what a frame with it needs (GDC 2011's translucent materials, the SSS
    /// materials' blur chains, the layered media).
    fn part(&self) -> &'static dyn PartKind;
    /// A screen-space SSS technique's chain of passes (`'static`: it hands out itself);
    /// `None` for every other technique.
    fn sss_chain(&'static self) -> Option<&'static dyn SssBlurTechnique> {
        None
    }
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

/// A family of techniques that adds one part to a frame (see the module docs): a `static`
/// its techniques return from [`TechniqueModule::part`], known by its name.
pub trait PartKind: Sync {
    /// Its name in messages ("translucency", "screen-space SSS", "layered media"), unique
    /// among the registry's part kinds ([`same_kind`] compares it).
    fn name(&self) -> &'static str;

    /// What `context.scene`'s materials ask of this part; `None` when none does (the frame
    /// then has no pass, image, table or shader permutation of it). Errors name the material
    /// or scene key that is wrong.
    fn describe(&'static self, context: &Describe<'_>) -> Result<Option<Box<dyn FramePart>>>;
}

/// Whether two part kinds are the same: kinds are known by name (unique in the registry;
/// their statics are zero-sized, so their addresses need not differ).
pub fn same_kind(a: &dyn PartKind, b: &dyn PartKind) -> bool {
    a.name() == b.name()
}

/// The knobs a part reads: the features' view of the frame's settings.
#[derive(Clone, Copy, Debug)]
pub struct PartKnobs<'a> {
    /// The screen-space SSS chains' knobs.
    pub sss: &'a SssKnobs,
    /// The layered passes' knobs.
    pub layered: &'a LayeredKnobs,
    /// GDC 2011: thickness stored as grayscale even where the scene has colour.
    pub force_grayscale: bool,
    /// The SSS blurs limited to the rectangles of objects with a profile.
    pub sss_tiles: bool,
}

/// The registry's answers a part needs while it describes a frame, handed down so that a
/// part never imports the registry above it.
pub trait Lookup {
    /// The SSS blur `profile` is diffused with (its material's `blur`, or the default); an
    /// unknown name is an error naming the scene file, line and key.
    fn blur_of(&self, profile: &SssProfile) -> Result<SssBlur>;
    /// The SSS blur of `technique` (`None` when it is not a screen-space blur).
    fn blur_of_technique(&self, technique: &'static dyn TechniqueModule) -> Option<SssBlur>;
}

/// What [`PartKind::describe`] reads.
pub struct Describe<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The technique the frame runs alone (a forced `--technique`), whose part this is;
    /// `None`: every part the materials ask for, each material with its own technique.
    pub forced: Option<&'static dyn TechniqueModule>,
    /// The frame's knobs.
    pub knobs: PartKnobs<'a>,
    /// The registry's lookups.
    pub lookup: &'a dyn Lookup,
}

/// The images a part's passes read, as the frame declared them before the parts' passes.
pub struct FrameImages<'a> {
    /// The G-buffer.
    pub gbuffer: &'a GBuffer,
    /// The lighting pass's specular, apart from the diffuse (frames with screen-space SSS:
    /// [`super::lighting::Lit::specular`]).
    pub specular: Option<&'a Handle<Image>>,
    /// The light-space maps, when some light casts shadows.
    pub shadow_maps: Option<&'a ShadowMaps>,
}

/// What [`FramePart::write_slot`] writes into, for one frame slot.
pub struct SlotWrite<'a> {
    /// The scene at this frame.
    pub scene: &'a Scene,
    /// Object-space bounds per mesh (deformed at this frame in a deforming scene).
    pub mesh_bounds: &'a [(Vec3, Vec3)],
    /// Frame size in pixels.
    pub width: u32,
    /// Frame height in pixels.
    pub height: u32,
    /// The frame's knobs.
    pub knobs: PartKnobs<'a>,
    /// The per-frame buffer.
    pub per_frame: &'a PerFrame,
    /// The slot.
    pub slot: usize,
    /// The slot's screen tiles, which each part fills for its passes.
    pub tiles: &'a mut SlotTiles,
}

/// One part of a frame, as its [`PartKind`] described it (see the module docs).
pub trait FramePart: Any + Debug + Send + Sync {
    /// The kind that described it.
    fn kind(&self) -> &'static dyn PartKind;

    /// A copy (frames keep their description; the demo compares a new one with it).
    fn clone_part(&self) -> Box<dyn FramePart>;

    /// Whether `other` describes the same part with the same values.
    fn equals(&self, other: &dyn FramePart) -> bool;

    /// Whether a frame built for `self` can show `other` by rewriting only its per-frame
    /// tables: the same per-object IDs, passes and table sizes (a knob changed a value, not
    /// which materials or profiles exist).
    fn same_shape(&self, other: &dyn FramePart) -> bool;

    /// Whether the frame runs `technique` for this part: by default every technique of its
    /// kind (a part whose techniques are its materials' choice, the SSS chains, says which).
    fn runs(&self, technique: &dyn TechniqueModule) -> bool {
        same_kind(technique.part(), self.kind())
    }

    /// Its lines in the list of a frame's features (messages, `lucent plan`'s header).
    fn names(&self, out: &mut Vec<String>);

    /// Sets the G-buffer targets and lighting variants it needs in `layout` (which starts as
    /// plain deferred lighting's).
    fn gbuffer(&self, layout: &mut GBufferLayout);

    /// Sets what the light-space maps must store for it.
    fn shadows(&self, _maps: &mut ShadowDesc) {}

    /// Checks it against the frame's G-buffer described as a host describes its own
    /// ([`GBufferLayout::described`]) with the checks a host's effect makes on its
    /// description: a part whose passes are declared as an effect declares a host's (the SSS
    /// chains) is held to what the effect accepts. Nothing for the others.
    fn check_described(&self, _gbuffer: &GBufferDesc, _lookup: &dyn Lookup) -> Result<()> {
        Ok(())
    }

    /// Adds its per-frame tables, in the order the per-frame buffer lays them out.
    fn tables(&self, out: &mut Vec<TableRegion>);

    /// Sets what the scene's GPU data must hold for it.
    fn upload<'a>(&'a self, upload: &mut SceneUpload<'a>);

    /// Declares its passes after the lighting pass: `hdr` is the lit image as the parts
    /// before it left it; returns it as this part leaves it (unchanged for a part whose
    /// shading runs inside the lighting pass).
    fn declare(
        &self,
        graph: &mut RenderGraph,
        images: &FrameImages<'_>,
        hdr: Handle<Image>,
        knobs: &PartKnobs<'_>,
        scene_gpu: Option<&Arc<SceneGpu>>,
    ) -> Handle<Image>;

    /// Writes its per-frame tables and screen tiles for one frame.
    fn write_slot(&self, slot: &mut SlotWrite<'_>) -> Result<()>;
}

impl Clone for Box<dyn FramePart> {
    fn clone(&self) -> Self {
        self.clone_part()
    }
}

impl PartialEq for Box<dyn FramePart> {
    fn eq(&self, other: &Self) -> bool {
        self.equals(other.as_ref())
    }
}

/// `part` as a `T`, when it is one.
pub fn downcast<T: FramePart>(part: &dyn FramePart) -> Option<&T> {
    (part as &dyn Any).downcast_ref::<T>()
}

/// Implements [`FramePart::clone_part`] and [`FramePart::equals`] for a part that is `Clone`
/// and `PartialEq` (every part today).
macro_rules! part_value_methods {
    () => {
        fn clone_part(&self) -> Box<dyn $crate::features::technique::FramePart> {
            Box::new(self.clone())
        }

        fn equals(&self, other: &dyn $crate::features::technique::FramePart) -> bool {
            $crate::features::technique::downcast::<Self>(other) == Some(self)
        }
    };
}
pub(crate) use part_value_methods;
