//! The SSS passes on a described G-buffer ([`GBufferDesc`]): the one declaration that both
//! lucent's own frames (`super::part`, their G-buffer described by
//! [`crate::features::gbuffer::GBufferLayout::described`]) and a host's frames
//! (`lucent::embed::SssEffect`, the host's own description) go through. What differs between
//! the two is only what the description says: how the diffuse holds the albedo (an adapter
//! pass puts it right when it differs from what a profile wants before the blur), whether the
//! LEAN targets are given or built from the normals, whether the specular is kept apart,
//! where the depth is read, and how the shadow maps are laid out.

use std::sync::Arc;

use super::{host_albedo_pass, host_lean_pass, sss_passes, HostAlbedo, LeanInputs, SssInputs};
use super::{IdMap, SssBlur, SssKnobs, SssProfiles, MAX_SSS_PROFILES};
use crate::features::capabilities::{require, Effect};
use ash::vk;

use crate::error::HostError;
use crate::features::gbuffer_desc::{
    check_metres_per_unit, DepthEncoding, DiffuseAlbedo, GBufferDesc,
};
use crate::features::lighting::HDR_FORMAT;
use crate::gpu_scene::{Region, SceneGpu};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, PassKind, RenderGraph};
use crate::scene::material::{SssProfile, Texturing};
use crate::Result;

/// The host LEAN pass's constants in the per-frame buffer (glsl/sss/host_lean.frag
/// `HostLean`: the normals' decode, the view-to-world matrix and each profile's surface),
/// written by the effect that builds the LEAN targets from a host's normals.
pub static HOST_LEAN: Region = Region::new("host LEAN decode", "HostLean");

/// The shadow maps the LEAN blurs' relit specular is shadowed by.
#[derive(Clone, Copy)]
pub struct DescribedShadows<'a> {
    /// The map (an atlas, or an array of layers when `array`).
    pub depth: &'a Handle<Image>,
    /// `depth` is an array of layers.
    pub array: bool,
    /// A second map beside an atlas: an array of layers.
    pub second: Option<&'a Handle<Image>>,
    /// Its faces may store reversed Z (a host's: each face says); lucent's own atlas stores
    /// standard Z only, and its passes carry no per-texel flip.
    pub reversible: bool,
}

/// The images of a described G-buffer, as handles of the graph the passes join.
#[derive(Clone, Copy)]
pub struct DescribedImages<'a> {
    /// The depth image.
    pub depth: &'a Handle<Image>,
    /// The lit diffuse light.
    pub diffuse: &'a Handle<Image>,
    /// The material IDs.
    pub material_ids: &'a Handle<Image>,
    /// The specular kept apart (`None`: a cleared image stands in).
    pub specular: Option<&'a Handle<Image>>,
    /// The albedo, when described.
    pub albedo: Option<&'a Handle<Image>>,
    /// The normals, when described.
    pub normals: Option<&'a Handle<Image>>,
    /// The LEAN targets (moments, albedo and specular, normal and roughness), when described.
    pub lean_targets: Option<[&'a Handle<Image>; 3]>,
    /// The shadow maps, when described.
    pub shadows: Option<DescribedShadows<'a>>,
}

/// One scattering material of the host: its ID in the host's material ID image and the
/// profile its pixels are blurred with.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SssMaterial {
    /// The host's ID (1 to 255; 0 is taken to mean "does not scatter" and cannot have one).
    pub id: u8,
    /// Its profile: the Gaussians in millimetres (its `units_per_mm` is set from
    /// [`Self::metres_per_unit`], or the G-buffer's [`GBufferDesc::metres_per_unit`]), the
    /// blur ([`SssProfile::blur`]: the control, separable, Burley, or a LEAN blur: LCB, LBB,
    /// bilateral) and where the albedo goes ([`SssProfile::texturing`]).
    pub profile: SssProfile,
    /// The world scale of this material's objects, metres per world unit, when it is not the
    /// G-buffer's ([`Self::with_metres_per_unit`]; as HDRP's diffusion profiles each have a
    /// world scale): a profile in millimetres spans as many world units on an object
    /// modelled at another scale.
    pub metres_per_unit: Option<f32>,
    /// The specular surface the LEAN blurs relight (required with them, refused with the
    /// others, whose specular is the host's own).
    pub surface: Option<SpecularSurface>,
    /// The profile's own `units_per_mm` is the material's scale (lucent's own materials,
    /// [`Self::at_profile_scale`]), unless `metres_per_unit` says otherwise.
    at_profile_scale: bool,
}

impl SssMaterial {
    /// Material `id` scattering with `profile`.
    pub fn new(id: u8, profile: SssProfile) -> Self {
        Self {
            id,
            profile,
            surface: None,
            metres_per_unit: None,
            at_profile_scale: false,
        }
    }

    /// Material `id` scattering with `profile` at the profile's own scale (its
    /// `units_per_mm`, as lucent's scenes give it), whatever the G-buffer's: how lucent's own
    /// frames describe their materials (the scale is not turned into metres and back).
    pub(crate) fn at_profile_scale(id: u8, profile: SssProfile) -> Self {
        Self {
            at_profile_scale: true,
            ..Self::new(id, profile)
        }
    }

    /// With its own world scale ([`Self::metres_per_unit`]: positive, finite, at most
    /// [`crate::features::gbuffer_desc::MAX_METRES_PER_UNIT`]).
    pub fn with_metres_per_unit(mut self, metres: f32) -> Self {
        self.metres_per_unit = Some(metres);
        self
    }

    /// With the specular surface a LEAN blur (LCB, LBB, bilateral) relights.
    pub fn with_surface(mut self, surface: SpecularSurface) -> Self {
        self.surface = Some(surface);
        self
    }
}

/// A material's specular as lucent's own materials describe it (`roughness`, `specular` of a
/// scene's `[material]`): what LCB, LBB and the bilateral blur evaluate their LEAN specular
/// with, in place of the host's specular, on the material's pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SpecularSurface {
    /// Roughness, 0 to 1 (lucent's Blinn-Phong exponent `2 / r^4 - 2` and the LEAN lobe's base
    /// variance come from it).
    pub roughness: f32,
    /// Specular intensity: reflectance at normal incidence, 0 to 1.
    pub specular: f32,
}

impl SpecularSurface {
    /// A surface of `roughness` reflecting `specular` at normal incidence.
    pub fn new(roughness: f32, specular: f32) -> Self {
        Self {
            roughness,
            specular,
        }
    }

    /// Both finite and in 0..=1.
    pub(crate) fn check(&self, field: &str) -> Result<()> {
        for (name, value) in [("roughness", self.roughness), ("specular", self.specular)] {
            if !(0.0..=1.0).contains(&value) {
                return Err(HostError::Description {
                    field: format!("{field}.surface.{name}"),
                    problem: format!("{value} is not in 0 to 1"),
                }
                .into());
            }
        }
        Ok(())
    }
}

/// What an [`crate::embed::SssEffect`] is built for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct SssEffectDesc {
    /// The host's G-buffer (it must describe its material IDs).
    pub gbuffer: GBufferDesc,
    /// The scattering materials (1 to 31 of them).
    pub materials: Vec<SssMaterial>,
    /// The blurs' knobs (samples, kernel shape, precision, half resolution...).
    pub knobs: SssKnobs,
    /// The output's format (an RGB(A) float, UNORM or SRGB colour format).
    pub output_format: vk::Format,
    /// Views recorded per frame (1 to [`crate::embed::MAX_VIEWS_PER_FRAME`]): each view of a frame has its
    /// own camera and images.
    pub views_per_frame: usize,
    /// The format of the host's shadow map that shadows the LEAN blurs' specular (a depth
    /// format), when it has one ([`crate::embed::LeanLighting::shadow_map`]). Only with a LEAN blur.
    pub shadow_format: Option<vk::Format>,
    /// That shadow map is an array of layers (its view a 2-D array view), each face in its
    /// [`crate::embed::ShadowFace::layer`] ([`Self::with_shadow_array`]); else one 2-D image (an atlas).
    pub shadow_array: bool,
    /// The format of a second shadow map beside the first (an atlas): an array of layers of
    /// its own size, each of its faces [`crate::embed::ShadowFace::in_second_map`]
    /// ([`Self::with_second_shadow_map`], [`crate::embed::LeanLighting::second_shadow_map`]).
    pub second_shadow_format: Option<vk::Format>,
}

impl SssEffectDesc {
    /// The effect over `gbuffer` for `materials`, writing `output_format`, one view a frame,
    /// the default knobs.
    pub fn new(
        gbuffer: GBufferDesc,
        materials: Vec<SssMaterial>,
        output_format: vk::Format,
    ) -> Self {
        Self {
            gbuffer,
            materials,
            knobs: SssKnobs::default(),
            output_format,
            views_per_frame: 1,
            shadow_format: None,
            shadow_array: false,
            second_shadow_format: None,
        }
    }

    /// With a second shadow map of `format` beside the first, an atlas
    /// ([`Self::second_shadow_format`]).
    pub fn with_second_shadow_map(mut self, format: vk::Format) -> Self {
        self.second_shadow_format = Some(format);
        self
    }

    /// The shadow map of [`Self::with_shadow_maps`] is an array of layers
    /// ([`crate::embed::HostImage::with_layers`]), each face in its own ([`crate::embed::ShadowFace::in_layer`]).
    pub fn with_shadow_array(mut self) -> Self {
        self.shadow_array = true;
        self
    }

    /// With a shadow map of `format` shadowing the LEAN blurs' specular.
    pub fn with_shadow_maps(mut self, format: vk::Format) -> Self {
        self.shadow_format = Some(format);
        self
    }

    /// With these knobs.
    pub fn with_knobs(mut self, knobs: SssKnobs) -> Self {
        self.knobs = knobs;
        self
    }

    /// With this many views per frame.
    pub fn with_views_per_frame(mut self, views: usize) -> Self {
        self.views_per_frame = views;
        self
    }
}

/// What [`SssEffectDesc::check_materials`] decides: each material's profile at its world
/// scale with the blur it names, in the description's order (profile number = index + 1),
/// and how the passes read the material ID image.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedMaterials {
    /// The profiles with their blurs.
    pub profiles: Vec<(SssProfile, SssBlur)>,
    /// The ID decode, each material's ID mapped to its profile number.
    pub id_map: IdMap,
}

impl SssEffectDesc {
    /// The checks of the G-buffer and the materials that every path of the SSS passes makes,
    /// a host's `SssEffect` and lucent's own frames on their described G-buffer alike
    /// (`FramePart::check_described`): the G-buffer on its own, the inputs SSS needs, 1 to
    /// 31 materials with distinct IDs that fit the ID image, each profile valid at its scale
    /// with a blur that exists (`blur_of`: the technique registry's), a specular surface
    /// exactly where a LEAN blur must relight one, and the albedo where the light or a
    /// profile needs it. Errors are [`HostError`]s naming the field.
    pub fn check_materials(
        &self,
        blur_of: &dyn Fn(&SssProfile) -> Result<SssBlur>,
    ) -> Result<CheckedMaterials> {
        let gbuffer = &self.gbuffer;
        gbuffer.check()?;
        require(Effect::Sss, gbuffer)?;
        let ids = gbuffer
            .material_ids
            .expect("missing() lists the material IDs");
        if self.materials.is_empty() || self.materials.len() >= MAX_SSS_PROFILES {
            return Err(HostError::Description {
                field: "materials".into(),
                problem: format!(
                    "{} scattering materials; 1 to {} are supported",
                    self.materials.len(),
                    MAX_SSS_PROFILES - 1
                ),
            }
            .into());
        }
        let units_per_mm = 1.0 / (1000.0 * gbuffer.metres_per_unit);
        let mut id_map = ids.decode(Vec::new())?;
        let mut profile_of = vec![0u8; 256];
        let mut profiles = Vec::with_capacity(self.materials.len());
        for (index, material) in self.materials.iter().enumerate() {
            let field = format!("materials[{index}] (ID {})", material.id);
            if material.id == 0 || profile_of[usize::from(material.id)] != 0 {
                return Err(HostError::Description {
                    field,
                    problem: "IDs are 1 to 255 (0: does not scatter), each once".into(),
                }
                .into());
            }
            if u32::from(material.id) > id_map.mask {
                return Err(HostError::Description {
                    field,
                    problem: "the ID does not fit the material ID image's bit field".into(),
                }
                .into());
            }
            let mut profile = material.profile.clone();
            profile.units_per_mm = match material.metres_per_unit {
                // lucent's own materials carry their scale in their profiles.
                None if material.at_profile_scale => profile.units_per_mm,
                None => units_per_mm,
                Some(metres) => {
                    check_metres_per_unit(metres, &format!("{field}.metres_per_unit"))?;
                    1.0 / (1000.0 * metres)
                }
            };
            profile.validate()?;
            let blur = blur_of(&profile)?;
            if blur.lean() {
                // The normals first: what capabilities says the LEAN blurs lack.
                require(Effect::LeanSss, gbuffer)?;
            }
            match (blur.lean(), &material.surface) {
                (true, Some(_)) if gbuffer.lean_targets.is_some() => {
                    return Err(HostError::Unsupported {
                        input: format!("{field}.surface"),
                        found: "a specular surface with the host's LEAN targets".into(),
                        accepted: "no surface: the roughness and specular intensity are the \
                                   LEAN targets' (GBufferDesc::with_lean_targets)"
                            .into(),
                    }
                    .into())
                }
                (true, Some(surface)) => surface.check(&format!("materials[{index}]"))?,
                (true, None) if gbuffer.lean_targets.is_some() => {}
                (true, None) => {
                    return Err(HostError::Missing {
                        input: format!("{field}.surface"),
                        needed_by: format!(
                            "the {} blur relights the specular from the blurred LEAN moments \
                             with the material's roughness and specular intensity \
                             (SssMaterial::with_surface)",
                            blur.name()
                        ),
                    }
                    .into())
                }
                (false, Some(_)) => {
                    return Err(HostError::Unsupported {
                        input: format!("{field}.surface"),
                        found: format!("a specular surface with the {} blur", blur.name()),
                        accepted: "a surface only with LCB, LBB or the bilateral blur, which \
                                   relight the specular; the other blurs keep the host's"
                            .into(),
                    }
                    .into())
                }
                (false, None) => {}
            }
            profile_of[usize::from(material.id)] = index as u8 + 1;
            profiles.push((profile, blur));
        }
        let albedo_pass =
            needs_albedo_pass(gbuffer.diffuse.albedo, profiles.iter().map(|(p, _)| p));
        let post_albedo = applies_albedo_after(profiles.iter().map(|(p, _)| p));
        if (albedo_pass || post_albedo) && gbuffer.albedo.is_none() {
            return Err(HostError::Missing {
                input: "albedo".into(),
                needed_by: match gbuffer.diffuse.albedo {
                    DiffuseAlbedo::Excluded => {
                        "the diffuse light is described without its albedo, so lucent applies it \
                         (GBufferDesc::with_albedo)"
                            .into()
                    }
                    DiffuseAlbedo::Included | DiffuseAlbedo::AsTexturing => format!(
                        "a profile applies its albedo after the scatter (texturing '{}'): \
                         describe the albedo image, or use texturing 'pre'",
                        profiles
                            .iter()
                            .find(|(p, _)| p.texturing != Texturing::Pre)
                            .map_or("post", |(p, _)| p.texturing.name())
                    ),
                },
            }
            .into());
        }
        id_map.profile_of = profile_of;
        Ok(CheckedMaterials { profiles, id_map })
    }
}

/// Whether a diffuse that holds the albedo as `albedo` says must pass through `sss albedo in`
/// for these profiles: when some pixel's light must hold a different part of the albedo than
/// the described light does.
pub fn needs_albedo_pass<'p>(
    albedo: DiffuseAlbedo,
    mut profiles: impl Iterator<Item = &'p SssProfile>,
) -> bool {
    match albedo {
        // Pixels that do not scatter need the albedo in their light too.
        DiffuseAlbedo::Excluded => true,
        DiffuseAlbedo::Included => profiles.any(|p| p.texturing != Texturing::Pre),
        // The light holds what each profile wants before the blur already.
        DiffuseAlbedo::AsTexturing => false,
    }
}

/// Whether some profile applies its albedo after the blur (the passes then read the albedo).
pub fn applies_albedo_after<'p>(mut profiles: impl Iterator<Item = &'p SssProfile>) -> bool {
    profiles.any(|p| p.texturing != Texturing::Pre)
}

/// Declares the SSS passes of `profiles` over the G-buffer `gbuffer` describes, whose images
/// are `images`; returns the image the final pass wrote (`output`, or a new one). The
/// description has been checked by whoever built it (`GBufferDesc::check` and the effect's
/// own checks: the images each path needs are there).
pub fn sss_on_gbuffer(
    graph: &mut RenderGraph,
    gbuffer: &GBufferDesc,
    images: &DescribedImages<'_>,
    profiles: &SssProfiles,
    knobs: &SssKnobs,
    scene_gpu: Option<&Arc<SceneGpu>>,
    output: Option<Handle<Image>>,
) -> Handle<Image> {
    let (width, height) = (gbuffer.width, gbuffer.height);
    let each_profile = || profiles.profiles.iter().map(|(p, _)| p);
    let lean = profiles.lean();
    let albedo_pass = needs_albedo_pass(gbuffer.diffuse.albedo, each_profile());
    let cleared;
    let specular = match images.specular {
        Some(s) => s,
        None => {
            cleared = cleared_image(graph, width, height);
            &cleared
        }
    };
    let mut inputs = SssInputs {
        diffuse: images.diffuse,
        specular,
        depth: images.depth,
        profile_ids: images.material_ids,
        lean: None,
        shadow_depth: None,
        shadow_array: false,
        second_shadow_depth: None,
        shadow_reversible: false,
        albedo: None,
        // The diffuse's alpha is read only when it holds linear depth: then the taps read it
        // there; otherwise they read the depth image.
        depth_in_alpha: gbuffer.diffuse.depth_in_alpha,
        ids: &profiles.id_map,
        linear_depth: gbuffer.depth.encoding == DepthEncoding::LinearView,
    };
    let targets = images.lean_targets.filter(|_| lean);
    let normals = images.normals.filter(|_| lean && targets.is_none());
    let adjusted;
    let built_targets;
    // The diffuse put right where a profile wants its albedo otherwise (`sss albedo in`, which
    // keeps the alpha: the LEAN slope x of given LEAN targets), unless the LEAN pass that
    // builds the targets from the normals does it.
    if albedo_pass && normals.is_none() {
        let albedo = images.albedo.expect("the effect checks the albedo is described");
        let included = gbuffer.diffuse.albedo == DiffuseAlbedo::Included;
        adjusted = host_albedo_pass(graph, &inputs, albedo, included, width, height, scene_gpu);
        inputs.diffuse = &adjusted;
    }
    if let Some([moments, albedo_specular, normal_roughness]) = targets {
        // The LEAN targets as the G-buffer pass wrote them (lucent's own, or a host's).
        inputs.lean = Some(LeanInputs {
            view_plane: moments,
            gb0: albedo_specular,
            gb1: normal_roughness,
        });
    } else if let Some(normals) = normals {
        // The LEAN chains' G-buffer targets built from the normals, the albedo put right in
        // the same pass.
        let mode = match (albedo_pass, gbuffer.diffuse.albedo) {
            (false, _) => None,
            (true, DiffuseAlbedo::Included) => Some(HostAlbedo::Included),
            (true, DiffuseAlbedo::Excluded) => Some(HostAlbedo::Excluded),
            (true, DiffuseAlbedo::AsTexturing) => {
                unreachable!("needs_albedo_pass: the light is as the profiles want it")
            }
        };
        let host_albedo = mode.map(|mode| {
            let albedo = images.albedo.expect("the effect checks the albedo is described");
            (albedo, mode)
        });
        built_targets = host_lean_pass(
            graph,
            &inputs,
            normals,
            host_albedo,
            &HOST_LEAN,
            width,
            height,
            scene_gpu,
        );
        inputs.diffuse = &built_targets.diffuse;
        inputs.lean = Some(LeanInputs {
            view_plane: &built_targets.view_plane,
            gb0: &built_targets.gb0,
            gb1: &built_targets.gb1,
        });
    }
    if inputs.lean.is_some() {
        // The LEAN chains' diffuse carries the slope in its alpha, not depth; their specular
        // is shadowed by the described maps.
        inputs.depth_in_alpha = false;
        if let Some(shadows) = images.shadows {
            inputs.shadow_depth = Some(shadows.depth);
            inputs.shadow_array = shadows.array;
            inputs.second_shadow_depth = shadows.second;
            inputs.shadow_reversible = shadows.reversible;
        }
    }
    if applies_albedo_after(each_profile()) {
        inputs.albedo = images.albedo;
    }
    sss_passes(graph, &inputs, profiles, knobs, scene_gpu, output)
}

/// A transient image cleared to black by a pass that draws nothing (the specular a host did
/// not keep apart).
fn cleared_image(graph: &mut RenderGraph, width: u32, height: u32) -> Handle<Image> {
    let mut image = graph.create_image(
        "specular (none)",
        ImageInfo {
            width,
            height,
            format: HDR_FORMAT,
        },
    );
    let mut pass = graph.add_pass("clear specular", PassKind::Raster);
    pass.color(&mut image, LoadOp::Clear([0.0; 4]));
    pass.clears_only();
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_albedo_pass_runs_only_when_the_light_and_the_profiles_differ() {
        let profile = |texturing| SssProfile {
            texturing,
            ..SssProfile::preset("skin").expect("a preset")
        };
        let pre = [profile(Texturing::Pre)];
        let post = [profile(Texturing::Post), profile(Texturing::Pre)];
        assert!(!needs_albedo_pass(DiffuseAlbedo::Included, pre.iter()));
        assert!(needs_albedo_pass(DiffuseAlbedo::Included, post.iter()));
        assert!(needs_albedo_pass(DiffuseAlbedo::Excluded, pre.iter()));
        // lucent's own lighting pass writes the light as each texturing asks.
        assert!(!needs_albedo_pass(DiffuseAlbedo::AsTexturing, post.iter()));
        assert!(!applies_albedo_after(pre.iter()));
        assert!(applies_albedo_after(post.iter()));
    }
}
