//! GDC 2011 thickness-based translucency (Frostbite 2, Barré-Brisebois and Bouchard): what the
//! G-buffer and the deferred lighting pass need beyond plain shading.
//!
//! The technique adds no pass of its own. It adds one G-buffer target (`GB2`: local thickness
//! and material ID, layout in `glsl/common/gbuffer.glsl`), a thickness stream per mesh, and a
//! material table the lighting pass indexes by material ID; the per-light scale travels with the
//! light. A frame whose scene has no translucent object (or whose technique leaves
//! translucency out) declares none of it: no target, no vertex stream, no table, no shader code.
//!
//! This module is the CPU side: which materials get which ID ([`MaterialTable`]), the table's
//! GPU layout ([`MaterialTableGpu`], a region of the per-frame buffer, so a changed power or
//! distortion needs no new frame) and how thickness is packed ([`ThicknessPacking`]). Which
//! screen tiles the lighting pass shades with the translucency variant is
//! [`crate::gpu_scene::tiles`]: the projected bounds of translucent objects, recomputed every
//! frame, so pixels no translucent object can cover never run its code.

use std::sync::Arc;

use glam::Vec3;

use super::gbuffer::{GBufferLayout, TranslucencyLayout};
use super::knob::{Knob, Takes};
use super::shadows::ShadowDesc;
use super::technique::TechniqueModule;
use super::technique::{
    downcast, part_value_methods, Describe, FrameImages, FramePart, PartKind, PartKnobs,
    SlotWrite,
};
use crate::backend::shader::PipelineShaders;
use crate::gpu_scene::tiles::{tile_rects, translucent_tiles};
use crate::gpu_scene::{Region, SceneGpu, SceneUpload, TableRegion};
use crate::graph::{Handle, Image, RenderGraph};
use crate::scene::material::{PowMode, Translucency};
use crate::scene::Scene;
use crate::{LucentError, Result};

/// Material IDs are stored in 8 bits; 0 means "not translucent", so 255 translucent materials
/// fit in one frame.
pub const MAX_TRANSLUCENT_MATERIALS: usize = 255;

pub use super::gbuffer::ThicknessPacking;

/// Rec. 709 luminance: how a coloured thickness becomes grayscale.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// One material table row as the lighting pass reads it (`glsl/common/translucency.glsl`):
/// x power, y distortion, z ambient, w pow mode (0 exact, 1 spherical Gaussian) plus
/// [`SHADOWED`] when other objects' shadows fall on its transmitted light.
pub type MaterialRow = [f32; 4];

/// The translucent materials of a scene, each with its ID (row `id - 1`).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialTable {
    /// Distinct translucency parameter sets, in order of first use.
    pub rows: Vec<MaterialRow>,
    /// Per scene object: its material ID (0 = not translucent).
    pub object_ids: Vec<u8>,
    /// Whether any translucent object's thickness is coloured (tint or vertex colours).
    pub any_colored: bool,
}

impl MaterialTable {
    /// Assigns IDs to the distinct translucency parameters of `scene`'s objects. Under a
    /// `forced` `--technique translucency`, a material with a medium and no
    /// `[material.translucency]` of its own gets the term derived from its medium
    /// ([`crate::scene::material::Medium::translucency`]); under `auto` such a material is
    /// another technique's (Li et al.'s layered passes).
    pub fn new(scene: &Scene, forced: bool) -> Result<Self> {
        let mut rows: Vec<MaterialRow> = Vec::new();
        let mut object_ids = Vec::with_capacity(scene.objects.len());
        let mut any_colored = false;
        for object in &scene.objects {
            let Some(t) = object.material.translucency_under(forced) else {
                object_ids.push(0);
                continue;
            };
            let row = material_row(t);
            let index = match rows.iter().position(|r| *r == row) {
                Some(i) => i,
                None => {
                    if rows.len() == MAX_TRANSLUCENT_MATERIALS {
                        return Err(LucentError::InvalidInput(format!(
                            "scene '{}' has more than {MAX_TRANSLUCENT_MATERIALS} distinct \
                             translucent materials (material IDs are 8 bits)",
                            scene.name
                        )));
                    }
                    rows.push(row);
                    rows.len() - 1
                }
            };
            object_ids.push(index as u8 + 1);
            let mesh_colored = scene.meshes[object.mesh]
                .colors
                .iter()
                .any(|c| c.x != c.y || c.y != c.z);
            any_colored |= t.is_colored() || mesh_colored;
        }
        Ok(Self {
            rows,
            object_ids,
            any_colored,
        })
    }

    /// Whether some material's transmitted light is shadowed by other objects
    /// ([`Translucency::shadowed`]): only then do the light-space maps store each texel's
    /// material, and the lighting pass look up lights behind a surface.
    pub fn any_shadowed(&self) -> bool {
        self.rows.iter().any(|r| r[3] >= SHADOWED)
    }

    /// Whether the frame needs translucency at all.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The packing a frame uses: coloured only when some thickness is coloured.
    pub fn packing(&self) -> ThicknessPacking {
        if self.any_colored {
            ThicknessPacking::Colored
        } else {
            ThicknessPacking::Grayscale
        }
    }

    /// Which pow forms the materials use: bit 0 exact, bit 1 spherical Gaussian (the lighting
    /// shader compiles only the forms a frame needs).
    pub fn pow_modes(&self) -> u8 {
        self.rows
            .iter()
            .map(|r| if row_pow_mode(r) == 1.0 { 2 } else { 1 })
            .fold(0, |a, b| a | b)
    }

    /// The uniform buffer contents.
    pub fn gpu(&self) -> MaterialTableGpu {
        let mut gpu = MaterialTableGpu {
            rows: [[0.0; 4]; MAX_TRANSLUCENT_MATERIALS + 1],
        };
        for (i, row) in self.rows.iter().enumerate() {
            gpu.rows[i + 1] = *row;
        }
        gpu
    }
}

/// The table row of one material's parameters.
pub fn material_row(t: &Translucency) -> MaterialRow {
    let shadowed = if t.shadowed { SHADOWED } else { 0.0 };
    match t.pow_mode {
        PowMode::Exact => [t.power, t.distortion, t.ambient, shadowed],
        PowMode::SphericalGaussian => [t.power, t.distortion, t.ambient, 1.0 + shadowed],
        // The seed's scale and bias, "handled offline": the shader runs the plain exp2 form.
        PowMode::SphericalGaussianScaled => [
            (t.power + 1.0) * std::f32::consts::LOG2_E,
            t.distortion,
            t.ambient,
            1.0 + shadowed,
        ],
    }
}

/// Added to a row's pow mode (`w`) when other objects' shadows fall on the material's
/// transmitted light ([`Translucency::shadowed`]; `TRANSLUCENCY_SHADOWED` in
/// `glsl/common/translucency.glsl`).
pub const SHADOWED: f32 = 2.0;

/// A row's pow mode without the [`SHADOWED`] flag: 0 exact, 1 spherical Gaussian.
pub fn row_pow_mode(row: &MaterialRow) -> f32 {
    if row[3] >= SHADOWED {
        row[3] - SHADOWED
    } else {
        row[3]
    }
}

/// The material table uniform block (std140: an array of vec4), indexed by material ID; row 0
/// is unused (ID 0 is "not translucent").
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialTableGpu {
    /// Rows by material ID.
    pub rows: [MaterialRow; MAX_TRANSLUCENT_MATERIALS + 1],
}

/// The GDC 2011 material table in the per-frame buffer.
pub static TABLE_REGION: Region = Region::new("GDC 2011 material table", "TranslucencyMaterials");

/// The per-frame region a frame with translucency writes its material table into.
pub fn table_region() -> TableRegion {
    TableRegion {
        region: &TABLE_REGION,
        bytes: std::mem::size_of::<MaterialTableGpu>() as u64,
    }
}

/// GDC 2011 translucency as a registered technique (`--technique translucency`).
pub struct Gdc2011Translucency;

/// The technique's instance, listed in [`super::registry`].
pub static TRANSLUCENCY: Gdc2011Translucency = Gdc2011Translucency;

/// `--grayscale`: thickness stored as its luminance, the talk's one-channel G-buffer.
pub static GRAYSCALE_KNOB: Knob = Knob {
    flag: "--grayscale",
    help: "Store coloured thickness as grayscale (its luminance), the talk's one-channel \
           G-buffer.",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| *k.force_grayscale = true,
};

impl TechniqueModule for Gdc2011Translucency {
    fn name(&self) -> &'static str {
        "translucency"
    }

    fn summary(&self) -> &'static str {
        "GDC 2011 thickness-based translucency (Frostbite 2) on translucent materials, in the \
         deferred lighting pass"
    }

    fn part(&self) -> &'static dyn PartKind {
        &TRANSLUCENCY_PART
    }

    fn knobs(&self) -> &'static [&'static Knob] {
        static KNOBS: &[&Knob] = &[&GRAYSCALE_KNOB];
        KNOBS
    }

    fn scene(&self) -> &'static str {
        "cubes"
    }

    /// None of its own: its term is compiled into the lighting pass, whose permutations
    /// ([`super::lighting`]) walk every translucency layout.
    fn shader_permutations(&self, _out: &mut Vec<PipelineShaders>) {}
}

/// GDC 2011's part of a frame ([`super::technique`]): the translucent materials' table and how
/// GB2 packs thickness. Its shading runs inside the lighting pass, so it declares no pass.
pub static TRANSLUCENCY_PART: TranslucencyPart = TranslucencyPart;

/// The kind of [`TRANSLUCENCY_PART`].
pub struct TranslucencyPart;

impl PartKind for TranslucencyPart {
    fn name(&self) -> &'static str {
        "translucency"
    }

    fn describe(&'static self, context: &Describe<'_>) -> Result<Option<Box<dyn FramePart>>> {
        // Forced (not `auto`): media without a term of their own derive one.
        let table = MaterialTable::new(context.scene, context.forced.is_some())?;
        let packing = if context.knobs.force_grayscale {
            ThicknessPacking::Grayscale
        } else {
            table.packing()
        };
        Ok((!table.is_empty())
            .then(|| Box::new(TranslucencyDesc { table, packing }) as Box<dyn FramePart>))
    }
}

/// The translucency part of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TranslucencyDesc {
    /// The translucent materials with their IDs.
    pub table: MaterialTable,
    /// How GB2 packs thickness.
    pub packing: ThicknessPacking,
}

impl FramePart for TranslucencyDesc {
    part_value_methods!();

    fn kind(&self) -> &'static dyn PartKind {
        &TRANSLUCENCY_PART
    }

    fn same_shape(&self, other: &dyn FramePart) -> bool {
        downcast::<Self>(other).is_some_and(|o| o.table.object_ids == self.table.object_ids)
    }

    fn names(&self, out: &mut Vec<String>) {
        let n = self.table.rows.len();
        out.push(format!(
            "translucency ({n} material{}, {})",
            if n == 1 { "" } else { "s" },
            self.packing.name()
        ));
    }

    fn gbuffer(&self, layout: &mut GBufferLayout) {
        layout.translucency = Some(TranslucencyLayout {
            packing: self.packing,
            pow_modes: self.table.pow_modes(),
            single_material: self.table.rows.len() == 1,
        });
    }

    fn shadows(&self, maps: &mut ShadowDesc) {
        // The atlas stores each texel's translucency material only for materials whose
        // transmitted light other objects shadow (the talk's term needs no lookup).
        maps.transmission_ids = self.table.any_shadowed();
    }

    fn tables(&self, out: &mut Vec<TableRegion>) {
        out.push(table_region());
    }

    fn upload<'a>(&'a self, upload: &mut SceneUpload<'a>) {
        upload.translucency_ids = Some(&self.table.object_ids);
    }

    fn declare(
        &self,
        _graph: &mut RenderGraph,
        _images: &FrameImages<'_>,
        hdr: Handle<Image>,
        _knobs: &PartKnobs<'_>,
        _scene_gpu: Option<&Arc<SceneGpu>>,
    ) -> Handle<Image> {
        hdr
    }

    fn write_slot(&self, slot: &mut SlotWrite<'_>) -> Result<()> {
        slot.per_frame.write(
            slot.slot,
            &TABLE_REGION,
            bytemuck::bytes_of(&self.table.gpu()),
        )?;
        // The lighting pass runs the translucency variant only where translucent objects
        // may be.
        let (columns, _, marked) = translucent_tiles(
            slot.scene,
            &self.table.object_ids,
            slot.mesh_bounds,
            slot.width,
            slot.height,
        );
        slot.tiles.lighting = tile_rects(columns, &marked, slot.width, slot.height);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn ids_are_shared_by_equal_parameters_and_zero_for_opaque() {
        let scene = builtin("grid125:50").unwrap();
        let table = MaterialTable::new(&scene, false).unwrap();
        assert_eq!(table.rows.len(), 1);
        assert!(table.object_ids.contains(&0) && table.object_ids.contains(&1));
        assert_eq!(table.packing(), ThicknessPacking::Grayscale);
        assert_eq!(table.gpu().rows[1], table.rows[0]);
        assert_eq!(table.gpu().rows[0], [0.0; 4]);
    }

    #[test]
    fn a_coloured_tint_selects_the_coloured_packing() {
        let scene = builtin("cubes").unwrap();
        let table = MaterialTable::new(&scene, false).unwrap();
        assert_eq!(table.packing(), ThicknessPacking::Colored);
        assert_eq!(
            table.rows.len(),
            1,
            "gray and red share power/distortion/ambient"
        );
    }

    #[test]
    fn scenes_without_translucency_need_no_table() {
        let scene = builtin("smoke").unwrap();
        assert!(MaterialTable::new(&scene, false).unwrap().is_empty());
    }
}
