//! Li et al.'s part of a frame ([`crate::features::technique`]): the layered media of the scene's
//! materials ([`LayeredDesc`]), and what they ask of the G-buffer, the light-space maps, the
//! per-frame buffer, the scene's GPU data and the passes after lighting.

use std::sync::Arc;

use super::TABLE_REGION;
use super::{blurs_on_screen, layered_passes, table_region, LayeredDesc, LayeredInputs};
use crate::features::gbuffer::GBufferLayout;
use crate::features::shadows::ShadowDesc;
use crate::features::technique::{
    downcast, part_value_methods, Describe, FrameImages, FramePart, PartKind, PartKnobs,
    SlotWrite,
};
use crate::gpu_scene::tiles::{object_tiles, object_tiles_at_depth, tile_rects};
use crate::gpu_scene::{SceneGpu, SceneUpload, TableRegion};
use crate::graph::{Handle, Image, RenderGraph};
use crate::Result;

/// Li et al.'s layered media's part of a frame.
pub static LAYERED_PART: LayeredPart = LayeredPart;

/// The kind of [`LAYERED_PART`].
pub struct LayeredPart;

impl PartKind for LayeredPart {
    fn name(&self) -> &'static str {
        "layered media"
    }

    fn describe(&'static self, context: &Describe<'_>) -> Result<Option<Box<dyn FramePart>>> {
        Ok(LayeredDesc::new(context.scene)?.map(|l| Box::new(l) as Box<dyn FramePart>))
    }
}

impl FramePart for LayeredDesc {
    part_value_methods!();

    fn kind(&self) -> &'static dyn PartKind {
        &LAYERED_PART
    }

    fn same_shape(&self, other: &dyn FramePart) -> bool {
        downcast::<Self>(other).is_some_and(|o| {
            o.object_ids == self.object_ids && o.materials.len() == self.materials.len()
        })
    }

    fn names(&self, out: &mut Vec<String>) {
        let media: Vec<&str> = self.materials.iter().map(|m| m.name.as_str()).collect();
        out.push(format!("layered ({})", media.join(", ")));
        if self.depth_textures() > 0 {
            out.push(format!(
                "layer depth textures ({} per object)",
                self.depth_textures()
            ));
        }
    }

    fn gbuffer(&self, layout: &mut GBufferLayout) {
        layout.layered = true;
        layout.layered_film = self.film;
        layout.layer_depth_textures = self.depth_textures();
    }

    fn shadows(&self, maps: &mut ShadowDesc) {
        // Single scattering reads each map texel's entry normal and layered material, and
        // with TexDep media its depth texels.
        maps.entry = true;
        maps.layer_depth_textures = self.depth_textures();
    }

    fn tables(&self, out: &mut Vec<TableRegion>) {
        out.push(table_region());
    }

    fn upload<'a>(&'a self, upload: &mut SceneUpload<'a>) {
        upload.layered_ids = Some(&self.object_ids);
        upload.layer_depth_textures = self.depth_textures();
    }

    fn declare(
        &self,
        graph: &mut RenderGraph,
        images: &FrameImages<'_>,
        hdr: Handle<Image>,
        knobs: &PartKnobs<'_>,
        scene_gpu: Option<&Arc<SceneGpu>>,
    ) -> Handle<Image> {
        let gb = images.gbuffer;
        let Some(ids) = &gb.layered else {
            // The G-buffer of a frame with this part always has the ID target.
            return hdr;
        };
        // Li et al.'s terms add into the lit image after the SSS blurs (layered pixels have
        // no SSS profile, so the blurs left them as lit).
        layered_passes(
            graph,
            hdr,
            &LayeredInputs {
                depth: &gb.depth,
                gb1: &gb.gb1,
                ids,
                layer_depths: gb.layer_depths.as_ref(),
                layer_depth_textures: gb.layout.layer_depth_textures,
                shadows: images.shadow_maps,
                film: gb.layout.layered_film,
                host: None,
                decode: None,
                host_film: None,
            },
            knobs.layered,
            scene_gpu,
        )
    }

    fn write_slot(&self, slot: &mut SlotWrite<'_>) -> Result<()> {
        let table = self.table(slot.knobs.layered);
        slot.per_frame
            .write(slot.slot, &TABLE_REGION, bytemuck::bytes_of(&table))?;
        let (scene, bounds, width, height) =
            (slot.scene, slot.mesh_bounds, slot.width, slot.height);
        // The scattering passes stay on the object (the gather rejects other materials).
        let (columns, _, marked) = object_tiles(scene, bounds, width, height, |i, _| {
            (self.object_ids.get(i).copied().unwrap_or(0) > 0).then_some(0.0)
        });
        slot.tiles.layered = tile_rects(columns, &marked, width, height);
        // The term's blur only over objects whose medium it acts on at their distance.
        let focal_px = scene.camera.focal_px(height);
        let texel_px = if slot.knobs.layered.half_gather {
            2.0
        } else {
            1.0
        };
        let (columns, _, marked) =
            object_tiles_at_depth(scene, bounds, width, height, |i, _, nearest| {
                let id = usize::from(self.object_ids.get(i).copied().unwrap_or(0));
                let medium = self.materials.get(id.checked_sub(1)?)?;
                blurs_on_screen(medium, nearest, focal_px, texel_px).then_some(0.0)
            });
        slot.tiles.layered_blur = tile_rects(columns, &marked, width, height);
        Ok(())
    }
}
