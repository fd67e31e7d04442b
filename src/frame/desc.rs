//! The frame description: what a frame of a scene shades, derived from the scene's materials.
//!
//! A feature is in the frame exactly when some object's material asks for it (and the
//! [`super::Technique`] override does not leave it out): GB2 and the GDC 2011 term when some material
//! is translucent, one SSS chain per blur the SSS materials use with every profile in the
//! profile table, the LEAN targets when some chain is LCB or LBB, normal and albedo maps when
//! some material has one, light-space maps when some light casts shadows, Li et al.'s
//! scattering passes (and the G-buffer and light-space targets they read) when some material
//! is layered. Everything else
//! costs nothing: [`super::declare_frame`] declares
//! no pass, image or shader permutation for it, and [`crate::gpu_scene`] uploads no stream,
//! texture or table.

use super::FrameSettings;
use crate::features::gbuffer::{GBufferLayout, TranslucencyLayout};
use crate::features::layered::LayeredDesc;
use crate::features::registry::{self, Shades, TechniqueModule};
use crate::features::shadows::ShadowDesc;
use crate::features::sss::SssProfiles;
use crate::features::translucency::{MaterialTable, ThicknessPacking};
use crate::gpu_scene::{SceneUpload, TableRegion};
use crate::scene::material::Texturing;
use crate::scene::Scene;
use crate::Result;

/// The translucency part of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct TranslucencyDesc {
    /// The translucent materials with their IDs.
    pub table: MaterialTable,
    /// How GB2 packs thickness.
    pub packing: ThicknessPacking,
}

/// What a frame of a scene shades beyond plain deferred lighting (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameDesc {
    /// GDC 2011 translucency, when some object is translucent (and the technique keeps it).
    pub translucency: Option<TranslucencyDesc>,
    /// Screen-space SSS: every profile of the SSS materials with its blur, when some object
    /// scatters (and the technique keeps it).
    pub sss: Option<SssProfiles>,
    /// Some object has a normal map.
    pub normal_maps: bool,
    /// Some object has an albedo texture.
    pub albedo_maps: bool,
    /// Light-space maps, when some light casts shadows.
    pub shadows: Option<ShadowDesc>,
    /// Li et al.'s layered media, when some object is layered (and the technique keeps it).
    pub layered: Option<LayeredDesc>,
}

impl FrameDesc {
    /// What `scene` asks for under `settings` (its technique and knobs).
    pub fn new(scene: &Scene, settings: &FrameSettings) -> Result<Self> {
        let technique = settings.technique;
        // Every technique a material names must exist, whichever technique this frame runs.
        registry::check_names(scene)?;
        let sss = if technique.sss() {
            SssProfiles::new(
                scene,
                technique.sss_blur(),
                settings.sss.gaussians,
                settings.sss.texturing,
                &registry::blur_of,
            )?
        } else {
            None
        };
        let translucency = if technique.translucency() {
            // Forced (not `auto`): media without a term of their own derive one.
            let table = MaterialTable::new(scene, technique != crate::frame::Technique::Auto)?;
            let packing = if settings.force_grayscale {
                ThicknessPacking::Grayscale
            } else {
                table.packing()
            };
            (!table.is_empty()).then_some(TranslucencyDesc { table, packing })
        } else {
            None
        };
        let any = |f: &dyn Fn(&crate::scene::Material) -> bool| {
            scene.objects.iter().any(|o| f(&o.material))
        };
        let layered = if technique.layered() {
            LayeredDesc::new(scene)?
        } else {
            None
        };
        // The atlas stores each texel's translucency material only for materials whose
        // transmitted light other objects shadow (the talk's term needs no lookup).
        let shadowed_transmission = translucency
            .as_ref()
            .is_some_and(|t| t.table.any_shadowed());
        let mut shadows = ShadowDesc::new(scene, &settings.shadows, shadowed_transmission);
        if let Some(s) = &mut shadows {
            // Single scattering reads each map texel's entry normal and layered material, and
            // with TexDep media its depth texels.
            s.entry = layered.is_some();
            s.layer_depth_textures = layered.as_ref().map_or(0, LayeredDesc::depth_textures);
        }
        Ok(Self {
            shadows,
            layered,
            translucency,
            sss,
            normal_maps: any(&|m| m.normal_texture.is_some()),
            albedo_maps: any(&|m| m.albedo_texture.is_some()),
        })
    }

    /// `TexDep` depth textures the frame's layered media read per object (0, 1 or 2).
    pub fn layer_depth_textures(&self) -> usize {
        self.layered.as_ref().map_or(0, LayeredDesc::depth_textures)
    }

    /// Whether the frame blurs the LEAN G-buffer (some SSS chain is LCB, LBB or bilateral).
    pub fn lean(&self) -> bool {
        self.sss.as_ref().is_some_and(SssProfiles::lean)
    }

    /// Whether some SSS chain is a two-pass blur (separable or bilateral): the frame needs
    /// the kernel table those passes read their weights from.
    pub fn two_pass(&self) -> bool {
        self.sss.as_ref().is_some_and(|s| s.two_pass())
    }

    /// The G-buffer layout this description and `settings` call for.
    pub fn gbuffer_layout(&self, settings: &FrameSettings) -> GBufferLayout {
        let chains = self
            .sss
            .as_ref()
            .map(SssProfiles::chains)
            .unwrap_or_default();
        GBufferLayout {
            precision: settings.gbuffer,
            translucency: self.translucency.as_ref().map(|t| TranslucencyLayout {
                packing: t.packing,
                pow_modes: t.table.pow_modes(),
                single_material: t.table.rows.len() == 1,
            }),
            sss: self.sss.is_some(),
            sss_texturing: self.sss.as_ref().is_some_and(|p| {
                p.profiles
                    .iter()
                    .any(|(profile, _)| profile.texturing != Texturing::Pre)
            }),
            // Some profile's material has a medium: the lighting pass shades it as its medium
            // reflects, and (with light-space maps and unless the knob is off) transmits.
            sss_medium: self.sss.as_ref().is_some_and(SssProfiles::transmits),
            lean: self.lean(),
            // LCB's control-style taps straddle silhouettes: its LEAN target must be cleared.
            lean_clear: chains.iter().any(|b| b.lean() && !b.bilateral()),
            normal_maps: self.normal_maps,
            albedo_maps: self.albedo_maps,
            depth_in_alpha: self.sss.as_ref().is_some_and(SssProfiles::depth_in_alpha),
            layered: self.layered.is_some(),
            layered_film: self.layered.as_ref().is_some_and(|l| l.film),
            layer_depth_textures: self.layer_depth_textures(),
            fault_injection: settings.fault.is_some(),
        }
    }

    /// The per-frame tables of this frame's features, each registered by its feature.
    pub fn tables(&self) -> Vec<TableRegion> {
        let mut tables = Vec::new();
        if self.translucency.is_some() {
            tables.push(crate::features::translucency::table_region());
        }
        if let Some(profiles) = &self.sss {
            tables.extend(crate::features::sss::tables::regions(profiles));
        }
        if self.shadows.is_some() {
            tables.push(crate::features::shadows::table_region());
        }
        if self.layered.is_some() {
            tables.push(crate::features::layered::table_region());
        }
        tables
    }

    /// What the scene's GPU data must hold for this frame.
    pub fn upload(&self, frames_in_flight: usize) -> SceneUpload<'_> {
        SceneUpload {
            translucency_ids: self.translucency.as_ref().map(|t| &t.table.object_ids[..]),
            profile_ids: self.sss.as_ref().map(|s| &s.object_ids[..]),
            normal_maps: self.normal_maps,
            lean: self.lean(),
            albedo_maps: self.albedo_maps,
            frames_in_flight,
            tables: self.tables(),
            layered_ids: self.layered.as_ref().map(|l| &l.object_ids[..]),
            layer_depth_textures: self.layer_depth_textures(),
        }
    }

    /// Whether a frame built for `self` can show `other` by rewriting only its per-frame
    /// tables: the same passes, images, permutations and per-object IDs (a knob changed a
    /// value, not which features or profiles exist).
    pub fn same_shape(&self, other: &FrameDesc, settings: &FrameSettings) -> bool {
        let ids = |d: &FrameDesc| {
            (
                d.translucency.as_ref().map(|t| t.table.object_ids.clone()),
                d.sss.as_ref().map(|s| s.object_ids.clone()),
                d.layered.as_ref().map(|l| l.object_ids.clone()),
            )
        };
        let steps = |d: &FrameDesc| {
            d.sss.as_ref().map(|s| {
                s.chains()
                    .into_iter()
                    .map(|c| (c, s.steps(c)))
                    .collect::<Vec<_>>()
            })
        };
        self.gbuffer_layout(settings) == other.gbuffer_layout(settings)
            && self.shadows == other.shadows
            && ids(self) == ids(other)
            && steps(self) == steps(other)
            && self.sss.as_ref().map(|s| s.profiles.len())
                == other.sss.as_ref().map(|s| s.profiles.len())
            && self.layered.as_ref().map(|l| l.materials.len())
                == other.layered.as_ref().map(|l| l.materials.len())
    }

    /// The registered techniques this frame runs, in registry order: GDC 2011 translucency,
    /// each SSS chain's blur, Li et al.'s layered media, as far as the frame has them.
    pub fn techniques(&self) -> Vec<&'static dyn TechniqueModule> {
        let chains = self
            .sss
            .as_ref()
            .map(SssProfiles::chains)
            .unwrap_or_default();
        registry::TECHNIQUES
            .iter()
            .copied()
            .filter(|t| match t.shades() {
                Shades::Translucent => self.translucency.is_some(),
                Shades::Scattering(_) => chains.iter().any(|c| c.name() == t.name()),
                Shades::Layered => self.layered.is_some(),
            })
            .collect()
    }

    /// The features in the frame, for messages and the plan dump's header.
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::new();
        if let Some(t) = &self.translucency {
            names.push(format!(
                "translucency ({} material{}, {})",
                t.table.rows.len(),
                if t.table.rows.len() == 1 { "" } else { "s" },
                t.packing.name()
            ));
        }
        if let Some(s) = &self.sss {
            for chain in s.chains() {
                let profiles: Vec<&str> = s
                    .profiles
                    .iter()
                    .filter(|(_, b)| *b == chain)
                    .map(|(p, _)| p.name.as_str())
                    .collect();
                names.push(format!("sss {} ({})", chain.name(), profiles.join(", ")));
            }
            if s.transmits() {
                names.push("sss transmission through thickness (media)".into());
            }
        }
        if let Some(l) = &self.layered {
            let media: Vec<&str> = l.materials.iter().map(|m| m.name.as_str()).collect();
            names.push(format!("layered ({})", media.join(", ")));
            if l.depth_textures() > 0 {
                names.push(format!(
                    "layer depth textures ({} per object)",
                    l.depth_textures()
                ));
            }
        }
        if let Some(s) = &self.shadows {
            names.push(s.name());
        }
        if self.normal_maps {
            names.push("normal maps".into());
        }
        if self.albedo_maps {
            names.push("albedo maps".into());
        }
        names
    }
}
