//! Which of lucent's effects a host's G-buffer can run, and what each lacks
//! ([`capabilities`]): asked before building anything, answered from the description alone.
//! The effects' own constructors refuse with the same errors.

use crate::error::HostError;
use crate::features::gbuffer_desc::{DiffuseAlbedo, GBufferDesc};
use crate::Result;

/// One of the techniques lucent can add to a host's frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Effect {
    /// Screen-space SSS on the host's lit diffuse ([`crate::embed::SssEffect`]: the control, the
    /// separable blur, 2-D Burley).
    Sss,
    /// GDC 2011 thickness-based translucency added to the host's light
    /// ([`crate::embed::TranslucencyEffect`]).
    Translucency,
    /// Screen-space SSS's transmission through thin parts: a medium's diffusion through the
    /// thickness the host's shadow maps measure ([`crate::embed::TransmissionEffect`]).
    SssTransmission,
    /// Li et al.'s multi-layer single + dipole multiple scattering, drawn from the host's
    /// meshes ([`crate::embed::LayeredEffect`]).
    LayeredMedia,
    /// The SH environment's diffuse light added to the host's light
    /// ([`crate::embed::EnvironmentEffect`]).
    Environment,
    /// Screen-space SSS with the LEAN-mapping thesis's blurs (LCB, LBB, the bilateral blur:
    /// [`crate::embed::SssEffect`] with materials of those blurs), which blur LEAN moments made from
    /// the host's normals (or its own LEAN targets) with the light and relight the specular
    /// from them.
    LeanSss,
}

impl Effect {
    /// Every effect, in the order [`capabilities`] reports them.
    pub const ALL: [Effect; 6] = [
        Effect::Sss,
        Effect::Translucency,
        Effect::SssTransmission,
        Effect::LayeredMedia,
        Effect::Environment,
        Effect::LeanSss,
    ];

    /// A short name (`sss`, `translucency`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Effect::Sss => "sss",
            Effect::Translucency => "translucency",
            Effect::SssTransmission => "sss-transmission",
            Effect::LayeredMedia => "layered-media",
            Effect::Environment => "environment",
            Effect::LeanSss => "lean-sss",
        }
    }
}

/// Whether a host's G-buffer can run an effect.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Support {
    /// The description has every input the effect reads.
    Runs,
    /// Inputs the description lacks, each a [`HostError::Missing`] naming the input and why
    /// the effect needs it, or a [`HostError::Unsupported`] for an input it describes in a
    /// form the effect cannot read (what the effect's constructor would refuse with).
    Lacks(Vec<HostError>),
}

impl Support {
    /// Whether the effect can be built on the description.
    pub fn runs(&self) -> bool {
        matches!(self, Support::Runs)
    }
}

/// For a host's G-buffer `gbuffer`, every effect ([`Effect::ALL`]) and whether it can run on
/// it. An invalid description (a format that cannot hold its input, a size out of range) is
/// the error [`GBufferDesc::check`] gives.
///
/// ```
/// # use ash::vk;
/// use lucent::embed::{capabilities, DepthDesc, DiffuseDesc, Effect, GBufferDesc, IdDesc};
/// let gbuffer = GBufferDesc::new(
///     1280,
///     720,
///     DepthDesc::device(vk::Format::D32_SFLOAT),
///     DiffuseDesc::with_albedo(vk::Format::B10G11R11_UFLOAT_PACK32),
/// )
/// .with_material_ids(IdDesc::value(vk::Format::R8_UINT));
/// let support = capabilities(&gbuffer).unwrap();
/// assert!(support[0].1.runs()); // screen-space SSS: depth, diffuse and IDs are enough
/// assert_eq!(support[1].0, Effect::Translucency); // ...which lacks normals, albedo, thickness
/// assert!(!support[1].1.runs());
/// ```
pub fn capabilities(gbuffer: &GBufferDesc) -> Result<Vec<(Effect, Support)>> {
    gbuffer.check()?;
    Ok(Effect::ALL
        .iter()
        .map(|&effect| (effect, support(effect, gbuffer)))
        .collect())
}

/// Whether `effect` can run on `gbuffer` (already checked).
pub(crate) fn support(effect: Effect, gbuffer: &GBufferDesc) -> Support {
    let lacks = missing(effect, gbuffer);
    if lacks.is_empty() {
        Support::Runs
    } else {
        Support::Lacks(lacks)
    }
}

/// The first input `effect` reads that `gbuffer` lacks, as the error its constructor gives.
pub(crate) fn require(effect: Effect, gbuffer: &GBufferDesc) -> Result<()> {
    match missing(effect, gbuffer).into_iter().next() {
        Some(first) => Err(first.into()),
        None => Ok(()),
    }
}

/// The inputs `effect` reads that `gbuffer` lacks, as the errors its constructor gives.
pub(crate) fn missing(effect: Effect, gbuffer: &GBufferDesc) -> Vec<HostError> {
    let lack = |input: &str, needed_by: &str| HostError::Missing {
        input: input.into(),
        needed_by: needed_by.into(),
    };
    // An effect that adds light to the host's diffuse gives it the albedo the diffuse has:
    // with the albedo as each SSS material's texturing asks, that depends on which pixels
    // scatter with which profile, which only the SSS effect knows.
    let as_texturing = |term: &str| HostError::Unsupported {
        input: "diffuse".into(),
        found: "the albedo as each SSS material's texturing asks (DiffuseAlbedo::AsTexturing)"
            .into(),
        accepted: format!(
            "a diffuse light with the albedo or without it (DiffuseAlbedo::Included, \
             Excluded), which {term} is added to as it is"
        ),
    };
    let mut out = Vec::new();
    match effect {
        Effect::Sss => {
            if gbuffer.material_ids.is_none() {
                out.push(lack(
                    "material IDs",
                    "screen-space SSS picks each pixel's profile by its material ID \
                     (GBufferDesc::with_material_ids)",
                ));
            }
        }
        Effect::LeanSss => {
            if gbuffer.material_ids.is_none() {
                out.push(lack(
                    "material IDs",
                    "screen-space SSS picks each pixel's profile by its material ID \
                     (GBufferDesc::with_material_ids)",
                ));
            }
            if gbuffer.normals.is_none() && gbuffer.lean_targets.is_none() {
                out.push(lack(
                    "normals",
                    "LCB, LBB and the bilateral blur blur LEAN moments made from each pixel's \
                     normal (GBufferDesc::with_normals), or the LEAN targets the host writes \
                     (GBufferDesc::with_lean_targets), and relight the specular from them",
                ));
            }
        }
        Effect::Translucency => {
            if gbuffer.material_ids.is_none() {
                out.push(lack(
                    "material IDs",
                    "GDC 2011 translucency picks each pixel's material by its ID \
                     (GBufferDesc::with_material_ids)",
                ));
            }
            if gbuffer.normals.is_none() {
                out.push(lack(
                    "normals",
                    "GDC 2011 translucency bends the light through the surface by its normal \
                     (GBufferDesc::with_normals)",
                ));
            }
            if gbuffer.albedo.is_none() {
                out.push(lack(
                    "albedo",
                    "GDC 2011 translucency tints the light let through by the surface albedo \
                     (GBufferDesc::with_albedo)",
                ));
            }
            if gbuffer.thickness.is_none() {
                out.push(lack(
                    "thickness",
                    "GDC 2011 translucency lets light through in proportion to the local \
                     thickness (GBufferDesc::with_thickness; lucent::embed::bake_thickness \
                     bakes it per vertex)",
                ));
            }
        }
        Effect::Environment => {
            if gbuffer.normals.is_none() {
                out.push(lack(
                    "normals",
                    "the SH environment's irradiance is evaluated at each pixel's normal \
                     (GBufferDesc::with_normals)",
                ));
            }
            if gbuffer.diffuse.albedo == DiffuseAlbedo::Included && gbuffer.albedo.is_none() {
                out.push(lack(
                    "albedo",
                    "the host's diffuse light has the albedo multiplied in, so the \
                     environment's light needs it too (GBufferDesc::with_albedo, or a diffuse \
                     light without the albedo: DiffuseDesc::without_albedo)",
                ));
            }
            if gbuffer.diffuse.albedo == DiffuseAlbedo::AsTexturing {
                out.push(as_texturing("the environment's light"));
            }
        }
        Effect::SssTransmission => {
            if gbuffer.material_ids.is_none() {
                out.push(lack(
                    "material IDs",
                    "SSS transmission picks each pixel's medium by its material ID \
                     (GBufferDesc::with_material_ids)",
                ));
            }
            if gbuffer.normals.is_none() {
                out.push(lack(
                    "normals",
                    "SSS transmission moves each point inside along its normal and lets light \
                     through the back-facing cosine (GBufferDesc::with_normals)",
                ));
            }
            if gbuffer.diffuse.albedo == DiffuseAlbedo::Included && gbuffer.albedo.is_none() {
                out.push(lack(
                    "albedo",
                    "the host's diffuse light has the albedo multiplied in, so the \
                     transmitted light needs it too (GBufferDesc::with_albedo, or \
                     DiffuseDesc::without_albedo)",
                ));
            }
            if gbuffer.diffuse.albedo == DiffuseAlbedo::AsTexturing {
                out.push(as_texturing("the transmitted light"));
            }
        }
        Effect::LayeredMedia => {
            if gbuffer.material_ids.is_none() {
                out.push(lack(
                    "material IDs",
                    "Li et al.'s layered media picks each pixel's medium by its material ID \
                     (GBufferDesc::with_material_ids)",
                ));
            }
            if gbuffer.normals.is_none() {
                out.push(lack(
                    "normals",
                    "Li et al.'s layered media refracts the view ray and lets light in through \
                     each pixel's normal (GBufferDesc::with_normals)",
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::gbuffer_desc::{DepthDesc, DiffuseDesc, IdDesc, NormalDesc, ThicknessDesc};
    use ash::vk;

    #[test]
    fn each_effect_says_what_the_description_lacks() {
        let bare = GBufferDesc::new(
            64,
            64,
            DepthDesc::device(vk::Format::D24_UNORM_S8_UINT),
            DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
        );
        let support = capabilities(&bare).unwrap();
        assert_eq!(support.len(), Effect::ALL.len());
        let Support::Lacks(sss) = &support[0].1 else {
            panic!("{:?}", support[0])
        };
        assert_eq!(sss.len(), 1);
        let Support::Lacks(translucency) = &support[1].1 else {
            panic!("{:?}", support[1])
        };
        let inputs: Vec<String> = translucency
            .iter()
            .map(|e| match e {
                HostError::Missing { input, .. } => input.clone(),
                other => panic!("{other}"),
            })
            .collect();
        assert_eq!(inputs, ["material IDs", "normals", "albedo", "thickness"]);
        // Layered media: IDs and normals.
        let Support::Lacks(layered) = &support[3].1 else {
            panic!("{:?}", support[3])
        };
        assert_eq!(layered.len(), 2);
        // SSS transmission: IDs, normals and (the albedo in the light) the albedo.
        let Support::Lacks(transmission) = &support[2].1 else {
            panic!("{:?}", support[2])
        };
        assert_eq!(transmission.len(), 3);
        // The environment: normals and, with the albedo in the diffuse light, the albedo.
        let Support::Lacks(environment) = &support[4].1 else {
            panic!("{:?}", support[4])
        };
        assert_eq!(environment.len(), 2);
        // The LEAN blurs: IDs and normals.
        let Support::Lacks(lean) = &support[5].1 else {
            panic!("{:?}", support[5])
        };
        assert_eq!(lean.len(), 2);
        let without_albedo = GBufferDesc {
            diffuse: DiffuseDesc::without_albedo(vk::Format::R16G16B16A16_SFLOAT),
            ..bare.clone()
        }
        .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT));
        assert!(capabilities(&without_albedo).unwrap()[4].1.runs());

        let full = bare
            .with_material_ids(IdDesc::stencil(vk::Format::D24_UNORM_S8_UINT, 0, 8))
            .with_normals(NormalDesc::world(vk::Format::A2B10G10R10_UNORM_PACK32))
            .with_albedo(vk::Format::R8G8B8A8_SRGB)
            .with_thickness(ThicknessDesc::channel(vk::Format::R8_UNORM, 0));
        let support = capabilities(&full).unwrap();
        assert!(support.iter().all(|(_, s)| s.runs()));
        // The albedo as each SSS material's texturing asks: the SSS blurs run; the effects
        // adding light to the diffuse cannot tell which pixels hold it and say so.
        let as_texturing = GBufferDesc {
            diffuse: DiffuseDesc::with_albedo_as_texturing(vk::Format::R16G16B16A16_SFLOAT),
            ..full.clone()
        };
        let support = capabilities(&as_texturing).unwrap();
        for (effect, support) in &support {
            let refused = matches!(effect, Effect::Environment | Effect::SssTransmission);
            match support {
                Support::Runs => assert!(!refused, "{effect:?}"),
                Support::Lacks(lacks) => {
                    assert!(refused, "{effect:?}: {lacks:?}");
                    assert!(
                        matches!(&lacks[..], [HostError::Unsupported { input, .. }] if input == "diffuse"),
                        "{effect:?}: {lacks:?}"
                    );
                }
            }
        }
        // An invalid description is its own error, not a list.
        assert!(capabilities(&full.with_metres_per_unit(-1.0)).is_err());
    }
}
