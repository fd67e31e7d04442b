use super::{FrameSettings, Technique};
use crate::features::deferred::{GBufferLayout, TranslucencyLayout};
use crate::features::sss;
use crate::features::translucency::{MaterialTable, ThicknessPacking};
use crate::scene::material::SssProfile;
use crate::scene::Scene;
use crate::Result;

/// What a frame of a scene needs beyond the plain deferred path: derived once from the scene
/// and the settings, so the graph declares only what the scene uses.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameFeatures {
    /// The translucent materials and GB2's packing, when the technique is `translucency` and
    /// some object is translucent.
    pub translucency: Option<(MaterialTable, ThicknessPacking)>,
    /// The diffusion profile the SSS blurs use, when the technique is an SSS one and some
    /// object has a profile (the first such object's; refitted to `SssKnobs::gaussians` when
    /// that is set), and the blur.
    pub sss: Option<(SssProfile, sss::SssBlur)>,
    /// Some object has a normal map.
    pub normal_maps: bool,
}

impl FrameFeatures {
    /// The features `scene` needs under `settings`.
    pub fn new(scene: &Scene, settings: &FrameSettings) -> Result<Self> {
        let sss = match settings.technique.sss_blur() {
            Some(blur) => scene
                .objects
                .iter()
                .find_map(|o| o.material.sss.clone())
                .map(|p| -> Result<_> {
                    let profile = match settings.sss.gaussians {
                        Some(n) => crate::scene::profile::fit_profile(&p, n)?.0,
                        None => p,
                    };
                    Ok((profile, blur))
                })
                .transpose()?,
            None => None,
        };
        let translucency = match settings.technique {
            Technique::None | Technique::Control | Technique::Lcb | Technique::Lbb => None,
            Technique::Translucency => {
                let table = MaterialTable::new(scene)?;
                let packing = if settings.force_grayscale {
                    ThicknessPacking::Grayscale
                } else {
                    table.packing()
                };
                (!table.is_empty()).then_some((table, packing))
            }
        };
        let normal_maps = scene
            .objects
            .iter()
            .any(|o| o.material.normal_texture.is_some());
        Ok(Self {
            translucency,
            sss,
            normal_maps,
        })
    }

    /// The SSS blur the frame runs, if any.
    pub fn sss_blur(&self) -> Option<sss::SssBlur> {
        self.sss.as_ref().map(|(_, blur)| *blur)
    }

    /// The G-buffer layout these features and `settings` call for.
    pub fn gbuffer_layout(&self, settings: &FrameSettings) -> GBufferLayout {
        GBufferLayout {
            precision: settings.gbuffer,
            translucency: self
                .translucency
                .as_ref()
                .map(|(table, packing)| TranslucencyLayout {
                    packing: *packing,
                    pow_modes: table.pow_modes(),
                    single_material: table.rows.len() == 1,
                }),
            sss: self.sss.is_some(),
            lean: self.sss_blur().is_some_and(sss::SssBlur::lean),
            lean_clear: self
                .sss_blur()
                .is_some_and(|blur| blur.lean() && !blur.bilateral()),
            normal_maps: self.normal_maps,
            fault_injection: settings.fault.is_some(),
        }
    }
}
