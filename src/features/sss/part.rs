//! Screen-space SSS's part of a frame ([`crate::features::technique`]): every profile of the SSS
//! materials with the blur chain it is diffused with ([`SssProfiles`]), and what that asks of
//! the G-buffer, the per-frame buffer, the scene's GPU data and the passes after lighting.

use std::sync::Arc;

use super::described::{
    sss_on_gbuffer, DescribedImages, DescribedShadows, SssEffectDesc, SssMaterial,
};
use super::{profile_reach, tables, SssBlur, SssProfiles};
use crate::features::gbuffer::GBufferLayout;
use crate::features::gbuffer_desc::GBufferDesc;
use crate::features::lighting::HDR_FORMAT;
use crate::features::technique::TechniqueModule;
use crate::features::technique::{
    downcast, part_value_methods, Describe, FrameImages, FramePart, Lookup, PartKind, PartKnobs,
    SlotWrite,
};
use crate::gpu_scene::tiles::{object_tiles, tile_rects};
use crate::gpu_scene::{SceneGpu, SceneUpload, TableRegion};
use crate::graph::{Handle, Image, RenderGraph};
use crate::scene::material::{SssProfile, Texturing};
use crate::{LucentError, Result};

/// The screen-space SSS chains' part of a frame, which every blur technique belongs to.
pub static SSS_PART: SssPart = SssPart;

/// The kind of [`SSS_PART`].
pub struct SssPart;

impl PartKind for SssPart {
    fn name(&self) -> &'static str {
        "screen-space SSS"
    }

    fn describe(&'static self, context: &Describe<'_>) -> Result<Option<Box<dyn FramePart>>> {
        // A forced blur diffuses every SSS material (and every medium) with its chain.
        let forced = context
            .forced
            .and_then(|t| context.lookup.blur_of_technique(t));
        let profiles = SssProfiles::new(
            context.scene,
            forced,
            context.knobs.sss.gaussians,
            context.knobs.sss.texturing,
            &|profile| context.lookup.blur_of(profile),
        )?;
        Ok(profiles.map(|p| Box::new(p) as Box<dyn FramePart>))
    }
}

impl FramePart for SssProfiles {
    part_value_methods!();

    fn kind(&self) -> &'static dyn PartKind {
        &SSS_PART
    }

    fn same_shape(&self, other: &dyn FramePart) -> bool {
        let Some(other) = downcast::<Self>(other) else {
            return false;
        };
        let steps = |p: &SssProfiles| {
            p.chains()
                .into_iter()
                .map(|c| (c, p.steps(c)))
                .collect::<Vec<_>>()
        };
        self.object_ids == other.object_ids
            && steps(self) == steps(other)
            && self.profiles.len() == other.profiles.len()
    }

    fn runs(&self, technique: &dyn TechniqueModule) -> bool {
        self.chains().iter().any(|c| c.name() == technique.name())
    }

    fn names(&self, out: &mut Vec<String>) {
        for chain in self.chains() {
            let profiles: Vec<&str> = self
                .profiles
                .iter()
                .filter(|(_, b)| *b == chain)
                .map(|(p, _)| p.name.as_str())
                .collect();
            out.push(format!("sss {} ({})", chain.name(), profiles.join(", ")));
        }
        if self.transmits() {
            out.push("sss transmission through thickness (media)".into());
        }
    }

    fn gbuffer(&self, layout: &mut GBufferLayout) {
        layout.sss = true;
        layout.sss_texturing = self
            .profiles
            .iter()
            .any(|(profile, _)| profile.texturing != Texturing::Pre);
        // Some profile's material has a medium: the lighting pass shades it as its medium
        // reflects, and (with light-space maps and unless the knob is off) transmits.
        layout.sss_medium = self.transmits();
        layout.lean = self.lean();
        // LCB's control-style taps straddle silhouettes: its LEAN target must be cleared.
        layout.lean_clear = self.chains().iter().any(|b| b.lean() && !b.bilateral());
        layout.depth_in_alpha = self.depth_in_alpha();
    }

    fn check_described(&self, gbuffer: &GBufferDesc, lookup: &dyn Lookup) -> Result<()> {
        // The profiles as a host's materials: IDs 1 to n (the profile numbers lucent's
        // G-buffer writes), each naming its blur, at its own scale.
        let named = |(profile, blur): &(SssProfile, SssBlur)| {
            let mut profile = profile.clone();
            profile.blur = Some(blur.name().into());
            (profile, *blur)
        };
        let want: Vec<(SssProfile, SssBlur)> = self.profiles.iter().map(named).collect();
        let materials = want
            .iter()
            .enumerate()
            .map(|(i, (profile, _))| SssMaterial::at_profile_scale(i as u8 + 1, profile.clone()))
            .collect();
        let desc = SssEffectDesc::new(gbuffer.clone(), materials, HDR_FORMAT);
        let checked = desc.check_materials(&|p| lookup.blur_of(p))?;
        // A check, not a conversion: every profile and blur comes back as it went in, and the
        // passes read lucent's ID image with the decode the description gives a host.
        if checked.profiles != want || checked.id_map != self.id_map {
            return Err(LucentError::InvalidInput(format!(
                "the SSS profiles of this frame and their host description differ: {:?} \
                 ({:?}) against {:?} ({:?})",
                self.profiles, self.id_map, checked.profiles, checked.id_map
            )));
        }
        Ok(())
    }

    fn tables(&self, out: &mut Vec<TableRegion>) {
        out.extend(tables::regions(self));
    }

    fn upload<'a>(&'a self, upload: &mut SceneUpload<'a>) {
        upload.profile_ids = Some(&self.object_ids);
        // Normal maps become LEAN maps for LCB's and LBB's chains.
        upload.lean = self.lean();
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
        let (Some(specular), Some(profile_ids)) = (images.specular, &gb.sss) else {
            // The G-buffer and lighting pass of a frame with this part always have both.
            return hdr;
        };
        // lucent's G-buffer described as a host describes its own, through the declaration
        // a host's SssEffect makes.
        let info = graph.resources()[hdr.id()].info;
        let described = gb.layout.described(info.width, info.height);
        let images = DescribedImages {
            depth: &gb.depth,
            diffuse: &hdr,
            material_ids: profile_ids,
            specular: Some(specular),
            albedo: Some(&gb.gb0),
            normals: Some(&gb.gb1),
            lean_targets: gb.lean.as_ref().map(|moments| [moments, &gb.gb0, &gb.gb1]),
            shadows: images.shadow_maps.map(|maps| DescribedShadows {
                depth: &maps.depth,
                // lucent's own light-space maps are one atlas of standard Z.
                array: false,
                second: None,
                reversible: false,
            }),
        };
        sss_on_gbuffer(
            graph,
            &described,
            &images,
            self,
            knobs.sss,
            scene_gpu,
            None,
        )
    }

    fn write_slot(&self, slot: &mut SlotWrite<'_>) -> Result<()> {
        tables::write(slot.per_frame, slot.slot, self, slot.knobs.sss)?;
        for chain in self.chains() {
            let rects = slot.knobs.sss_tiles.then(|| {
                let (columns, _, marked) = object_tiles(
                    slot.scene,
                    slot.mesh_bounds,
                    slot.width,
                    slot.height,
                    |i, _| {
                        // The frame's profile: the material's own, refitted, or the one
                        // fitted to its medium.
                        let (profile, blur) = self.of_object(i)?;
                        (*blur == chain).then(|| profile_reach(profile))
                    },
                );
                // All rectangles: the blurs draw the marked ones, LCB's and LBB's final pass
                // its LEAN variant there and the pass-through variant elsewhere.
                tile_rects(columns, &marked, slot.width, slot.height)
            });
            slot.tiles.sss.push(rects);
        }
        Ok(())
    }
}
