//! The frame description: what a frame of a scene shades, derived from the scene's materials.
//!
//! A feature is in the frame exactly when some object's material asks for it (and the
//! [`super::Technique`] override does not leave it out). The techniques' parts are described
//! by their own families ([`crate::features::technique::FramePart`]): GB2 and the GDC 2011 term
//! when some material is translucent, one SSS chain per blur the SSS materials use with every
//! profile in the profile table (and the LEAN targets when some chain is LCB or LBB), Li et
//! al.'s scattering passes (and the G-buffer and light-space targets they read) when some
//! material is layered. The frame's own features are normal and albedo maps when some material
//! has one and light-space maps when some light casts shadows. Everything else costs nothing:
//! [`super::declare_frame`] declares no pass, image or shader permutation for it, and
//! [`crate::gpu_scene`] uploads no stream, texture or table.

use super::FrameSettings;
use crate::features::gbuffer::GBufferLayout;
use crate::features::layered::LayeredDesc;
use crate::features::registry::{self, TechniqueModule};
use crate::features::shadows::ShadowDesc;
use crate::features::sss::SssProfiles;
use crate::features::technique::{downcast, Describe, FramePart};
use crate::gpu_scene::{SceneUpload, TableRegion};
use crate::scene::Scene;
use crate::Result;

pub use crate::features::translucency::TranslucencyDesc;

/// What a frame of a scene shades beyond plain deferred lighting (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct FrameDesc {
    /// The parts the materials ask for (and the technique keeps), in registry order: each
    /// family of techniques describes its own ([`crate::features::technique`]).
    parts: Vec<Box<dyn FramePart>>,
    /// Some object has a normal map.
    pub normal_maps: bool,
    /// Some object has an albedo texture.
    pub albedo_maps: bool,
    /// Light-space maps, when some light casts shadows.
    pub shadows: Option<ShadowDesc>,
}

impl FrameDesc {
    /// What `scene` asks for under `settings` (its technique and knobs): each part kind of
    /// the registry describes its part, when the technique keeps it.
    pub fn new(scene: &Scene, settings: &FrameSettings) -> Result<Self> {
        // Every technique a material names must exist, whichever technique this frame runs.
        registry::check_names(scene)?;
        let context = Describe {
            scene,
            forced: settings.technique.module(),
            knobs: settings.part_knobs(),
            lookup: &registry::Registry,
        };
        let mut parts = Vec::new();
        for kind in registry::part_kinds() {
            if settings.technique.keeps(kind) {
                parts.extend(kind.describe(&context)?);
            }
        }
        let mut shadows = ShadowDesc::new(scene, &settings.shadows, false);
        if let Some(maps) = &mut shadows {
            for part in &parts {
                part.shadows(maps);
            }
        }
        let any = |f: &dyn Fn(&crate::scene::Material) -> bool| {
            scene.objects.iter().any(|o| f(&o.material))
        };
        Ok(Self {
            parts,
            shadows,
            normal_maps: any(&|m| m.normal_texture.is_some()),
            albedo_maps: any(&|m| m.albedo_texture.is_some()),
        })
    }

    /// Holds each part to what the effects accept of a host, on lucent's G-buffer described
    /// as a host describes its own under `settings` (the SSS chains are declared as
    /// `SssEffect` declares a host's): run where a frame is built ([`super::Renderer::new`],
    /// [`super::plan_frame`]), not on every description (`Renderer::update_slot` describes
    /// the scene every frame).
    pub fn check_described(&self, settings: &FrameSettings) -> Result<()> {
        let described = self
            .gbuffer_layout(settings)
            .described(settings.width, settings.height);
        for part in self.parts() {
            part.check_described(&described, &registry::Registry)?;
        }
        Ok(())
    }

    /// The frame's parts, in registry order.
    pub fn parts(&self) -> impl Iterator<Item = &dyn FramePart> {
        self.parts.iter().map(|p| p.as_ref())
    }

    /// The frame's part of type `T`, when it has one.
    pub fn part<T: FramePart>(&self) -> Option<&T> {
        self.parts().find_map(downcast::<T>)
    }

    /// GDC 2011 translucency, when some object is translucent (and the technique keeps it).
    pub fn translucency(&self) -> Option<&TranslucencyDesc> {
        self.part()
    }

    /// Screen-space SSS: every profile of the SSS materials with its blur, when some object
    /// scatters (and the technique keeps it).
    pub fn sss(&self) -> Option<&SssProfiles> {
        self.part()
    }

    /// Li et al.'s layered media, when some object is layered (and the technique keeps it).
    pub fn layered(&self) -> Option<&LayeredDesc> {
        self.part()
    }

    /// The G-buffer layout this description and `settings` call for: plain deferred
    /// lighting's, with what each part needs.
    pub fn gbuffer_layout(&self, settings: &FrameSettings) -> GBufferLayout {
        let mut layout = GBufferLayout {
            precision: settings.gbuffer,
            translucency: None,
            sss: false,
            sss_texturing: false,
            sss_medium: false,
            lean: false,
            lean_clear: false,
            normal_maps: self.normal_maps,
            albedo_maps: self.albedo_maps,
            depth_in_alpha: false,
            layered: false,
            layered_film: false,
            layer_depth_textures: 0,
            fault_injection: settings.fault.is_some(),
        };
        for part in self.parts() {
            part.gbuffer(&mut layout);
        }
        layout
    }

    /// The per-frame tables of this frame's parts and features, each registered by its owner.
    pub fn tables(&self) -> Vec<TableRegion> {
        let mut tables = Vec::new();
        for part in self.parts() {
            part.tables(&mut tables);
        }
        if self.shadows.is_some() {
            tables.push(crate::features::shadows::table_region());
        }
        tables
    }

    /// What the scene's GPU data must hold for this frame.
    pub fn upload(&self, frames_in_flight: usize) -> SceneUpload<'_> {
        let mut upload = SceneUpload {
            translucency_ids: None,
            profile_ids: None,
            normal_maps: self.normal_maps,
            lean: false,
            albedo_maps: self.albedo_maps,
            frames_in_flight,
            tables: self.tables(),
            layered_ids: None,
            layer_depth_textures: 0,
        };
        for part in self.parts() {
            part.upload(&mut upload);
        }
        upload
    }

    /// Whether a frame built for `self` can show `other` by rewriting only its per-frame
    /// tables: the same passes, images, permutations and per-object IDs (a knob changed a
    /// value, not which features or profiles exist).
    pub fn same_shape(&self, other: &FrameDesc, settings: &FrameSettings) -> bool {
        self.gbuffer_layout(settings) == other.gbuffer_layout(settings)
            && self.shadows == other.shadows
            && self.parts.len() == other.parts.len()
            && self
                .parts()
                .zip(other.parts())
                .all(|(a, b)| a.same_shape(b))
    }

    /// The registered techniques this frame runs, in registry order: GDC 2011 translucency,
    /// each SSS chain's blur, Li et al.'s layered media, as far as the frame has them.
    pub fn techniques(&self) -> Vec<&'static dyn TechniqueModule> {
        registry::TECHNIQUES
            .iter()
            .copied()
            .filter(|t| self.parts().any(|p| p.runs(*t)))
            .collect()
    }

    /// The features in the frame, for messages and the plan dump's header.
    pub fn names(&self) -> Vec<String> {
        let mut names = Vec::new();
        for part in self.parts() {
            part.names(&mut names);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::registry::{part_kinds, TECHNIQUES};
    use crate::features::technique::same_kind;
    use crate::frame::Technique;
    use crate::scene::builtin::{builtin, BUILTIN_SCENES};

    fn kinds(desc: &FrameDesc) -> Vec<&'static str> {
        desc.parts().map(|p| p.kind().name()).collect()
    }

    /// lucent's SSS part is held to the checks a host's SssEffect makes on its description:
    /// every built-in frame passes them (`FrameDesc::check_described`, above), and a G-buffer
    /// that lacked what the chains read would be refused as a host's is.
    #[test]
    fn the_sss_part_is_checked_as_a_hosts_effect_is() {
        let scene = builtin("skin").unwrap();
        let mut settings = FrameSettings::new(64, 48);
        settings.technique = Technique::parse("lbb").unwrap();
        let desc = FrameDesc::new(&scene, &settings).unwrap();
        let part = desc.sss().expect("skin scatters");
        let layout = desc.gbuffer_layout(&settings);
        part.check_described(&layout.described(64, 48), &registry::Registry)
            .unwrap();
        let refused = |layout: GBufferLayout| {
            let e = part
                .check_described(&layout.described(64, 48), &registry::Registry)
                .unwrap_err();
            match e {
                crate::LucentError::Host(e) => e.to_string(),
                e => panic!("not a host error: {e}"),
            }
        };
        // Without the LEAN targets, LBB's material must bring its specular surface.
        let no_lean = refused(GBufferLayout {
            lean: false,
            ..layout
        });
        assert!(no_lean.contains("surface"), "{no_lean}");
        // Without the profile IDs, SSS cannot run at all.
        let no_ids = refused(GBufferLayout {
            sss: false,
            lean: false,
            ..layout
        });
        assert!(no_ids.contains("material IDs"), "{no_ids}");
    }

    /// Every built-in scene under every technique: the frame holds the parts its technique
    /// keeps, each once, in registry order; a part runs exactly the techniques of its kind
    /// that the frame lists.
    #[test]
    fn parts_follow_the_registry_and_the_technique() {
        let order: Vec<&str> = part_kinds().iter().map(|k| k.name()).collect();
        let mut seen = std::collections::BTreeSet::new();
        for (name, _) in BUILTIN_SCENES {
            let scene = builtin(name).unwrap();
            for (_, technique) in Technique::all() {
                let mut settings = FrameSettings::new(64, 48);
                settings.technique = technique;
                let desc = FrameDesc::new(&scene, &settings).unwrap();
                desc.check_described(&settings).unwrap();
                let names = kinds(&desc);
                let positions: Vec<usize> = names
                    .iter()
                    .map(|n| order.iter().position(|o| o == n).unwrap())
                    .collect();
                assert!(
                    positions.windows(2).all(|w| w[0] < w[1]),
                    "{name}: {names:?}"
                );
                for part in desc.parts() {
                    assert!(
                        technique.keeps(part.kind()),
                        "{name} {technique:?}: {names:?}"
                    );
                    seen.insert(part.kind().name());
                }
                if technique == Technique::None {
                    assert!(names.is_empty(), "{name}: {names:?}");
                }
                for t in desc.techniques() {
                    let part = desc.parts().find(|p| same_kind(p.kind(), t.part()));
                    assert!(part.is_some_and(|p| p.runs(t)), "{name}: {}", t.name());
                }
            }
        }
        // The built-in scenes between them have every part.
        assert_eq!(seen.len(), order.len(), "{seen:?}");
    }

    /// Part kinds are told apart by name (their statics are zero-sized): each is unique, and
    /// a technique keeps only its own.
    #[test]
    fn part_kinds_are_distinct() {
        let kinds = part_kinds();
        for (i, k) in kinds.iter().enumerate() {
            assert!(
                kinds[..i].iter().all(|o| !same_kind(*o, *k)),
                "{}",
                k.name()
            );
        }
        for t in TECHNIQUES {
            let keeps: Vec<&str> = kinds
                .iter()
                .filter(|k| Technique::Only(*t).keeps(**k))
                .map(|k| k.name())
                .collect();
            assert_eq!(keeps, [t.part().name()], "{}", t.name());
            assert!(kinds.iter().all(|k| Technique::Auto.keeps(*k)));
            assert!(kinds.iter().all(|k| !Technique::None.keeps(*k)));
        }
    }

    /// A frame without parts is plain deferred lighting: no G-buffer target, table or upload
    /// of any technique.
    #[test]
    fn a_frame_without_parts_asks_for_nothing_of_them() {
        let scene = builtin("mixed").unwrap();
        let mut settings = FrameSettings::new(64, 48);
        settings.technique = Technique::None;
        settings.shadows.enabled = false;
        let desc = FrameDesc::new(&scene, &settings).unwrap();
        assert!(desc.tables().is_empty());
        let layout = desc.gbuffer_layout(&settings);
        assert!(layout.translucency.is_none() && !layout.sss && !layout.lean && !layout.layered);
        let upload = desc.upload(1);
        assert!(upload.translucency_ids.is_none() && upload.profile_ids.is_none());
        assert!(upload.layered_ids.is_none() && !upload.lean);
        // With every part the materials ask for, each sets its own.
        settings.technique = Technique::Auto;
        let desc = FrameDesc::new(&scene, &settings).unwrap();
        assert!(desc.translucency().is_some() && desc.sss().is_some());
        let layout = desc.gbuffer_layout(&settings);
        assert!(layout.translucency.is_some() && layout.sss);
        assert_eq!(desc.tables().len(), desc.upload(1).tables.len());
        assert!(desc.same_shape(&desc.clone(), &settings));
    }
}
