//! [`SssEffect`]: lucent's screen-space SSS (the control, the separable blur, 2-D Burley,
//! and the LEAN-mapping thesis's LCB, LBB and bilateral blur) inserted into a host's frame, on
//! the host's own G-buffer ([`GBufferDesc`](super::GBufferDesc)).
//!
//! The host renders its G-buffer and lighting as usual, keeping the lit diffuse apart (and,
//! ideally, the specular), and writes a material ID per pixel. lucent blurs the diffuse of
//! every pixel whose ID has a profile, following the depth, adds the specular back and
//! writes the result into a host image; pixels without a profile keep their light. The passes
//! are the ones lucent's own frames run (`features::sss`): the host's encodings reach them as
//! shader permutations and per-frame constants (the ID decode, the depth decode of the host's
//! projection), not as copies into lucent's layout. The one exception: when the host's
//! diffuse holds its albedo differently from how a profile wants it before the blur
//! ([`DiffuseAlbedo`](super::DiffuseAlbedo) against [`Texturing`](super::Texturing)), one fullscreen pass puts it right first
//! (`sss albedo in`).
//!
//! LCB, LBB and the bilateral blur blur LEAN moments with the light and relight the specular
//! from the blurred moments, for the host's lights ([`LeanLighting`]; shadowed by the host's
//! shadow maps when it describes them). A host whose G-buffer pass writes lucent's LEAN
//! targets ([`super::LeanTargetsDesc`], with the functions of [`super::glsl::TERMS`]) hands
//! them over as they are ([`LeanSurface::Targets`]). Otherwise one pass (`sss lean in`) builds
//! them from the host's normals and its materials' roughness ([`SpecularSurface`]), with the
//! albedo adjustment above folded in: a host normal is one direction per pixel, so the LEAN
//! texel is that of a surface without a LEAN map (the spread of a normal map inside one pixel
//! is lost; the spread the blur mixes across pixels is kept). On those materials' pixels the
//! host's specular is replaced by the LEAN specular.
//!
//! Images are bound when a frame records, into that frame's slot and view: any number of
//! different images over time, a view recreated between frames (even with a reused handle
//! value) is simply the next frame's. Several views per frame (split screen, stereo) each
//! have their own slot of parameters and descriptors ([`SssEffectDesc::views_per_frame`]).

use std::sync::Arc;

use ash::vk;

use super::image::{check_image, distinct_inputs, HostImage, Role};
use super::passes::{check_lights, check_views, EffectPasses};
use super::regions::tiles_marked_by;
use super::shadow_faces::{
    check_shadow_format, shadow_table, undescribed_second_map, MapSizes, ShadowFace, ShadowMaps,
};
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::backend::format::{format_info, format_name};
use crate::error::{HostError, ImageFault};
use crate::features::gbuffer_desc::{sampled_float, HostCamera, IdEncoding};
use crate::features::registry;
use crate::features::sss::described::{
    sss_on_gbuffer, CheckedMaterials, DescribedImages, DescribedShadows, SpecularSurface,
    SssEffectDesc, SssMaterial, HOST_LEAN,
};
use crate::features::sss::{self, SssProfiles};
use crate::gpu_scene::{SceneGpu, SceneUpload, TableRegion, TileRect, FRAME};
use crate::graph::{Handle, ImageInfo, ImportedImage, RenderGraph, ResourceId};
use crate::scene::Light;
use crate::Result;

/// Most views one frame may record ([`SssEffectDesc::views_per_frame`]).
pub const MAX_VIEWS_PER_FRAME: usize = 4;

/// The [`SssMaterial`] methods that look a profile's blur up in the technique registry.
impl SssMaterial {
    /// Whether its profile's blur relights the specular (LCB, LBB, the bilateral blur): the
    /// material then needs a [`SpecularSurface`] ([`Self::with_surface`]), and the effect the
    /// normals and the lights ([`SssFrame::lean`]). The blur named by the profile, or the
    /// default blur when it names none; an unknown name is an error that lists the blurs.
    pub fn relights_specular(&self) -> Result<bool> {
        Ok(registry::blur_of(&self.profile)?.lean())
    }

    /// [`Self::with_surface`] when the profile's blur relights the specular
    /// ([`Self::relights_specular`]), the material as it is otherwise: what a host that
    /// knows each material's surface gives whatever blur the profile names.
    pub fn with_surface_if_relit(self, surface: SpecularSurface) -> Result<Self> {
        Ok(if self.relights_specular()? {
            self.with_surface(surface)
        } else {
            self
        })
    }
}

/// The host's images for one view of one frame, each with its current and final state.
#[derive(Clone, Copy, Debug)]
pub struct SssImages<'a> {
    /// The depth image (a depth format's view of its depth aspect, or linear depth).
    pub depth: &'a HostImage,
    /// The lit diffuse light.
    pub diffuse: &'a HostImage,
    /// The lit specular, when the description has it.
    pub specular: Option<&'a HostImage>,
    /// The albedo, when the description has it.
    pub albedo: Option<&'a HostImage>,
    /// The material IDs (for stencil bits: a view of the depth-stencil image's stencil
    /// aspect; it may be the depth image's image).
    pub material_ids: &'a HostImage,
}

/// What the LEAN blurs (LCB, LBB, bilateral) read besides the G-buffer's images: the surface
/// their LEAN moments come from, and the lights (and shadow maps) they relight the specular
/// with.
#[derive(Clone, Copy, Debug)]
pub struct LeanLighting<'a> {
    /// The normals the LEAN moments are made from, or the LEAN targets the host wrote (as the
    /// G-buffer description has them).
    pub surface: LeanSurface<'a>,
    /// The host's lights this frame, in its world (at most [`crate::scene::MAX_LIGHTS`]).
    pub lights: &'a [Light],
    /// The shadow map holding every face of `shadow_faces`, when the description has a
    /// shadow format ([`SssEffectDesc::with_shadow_maps`]): every face, or those not in the
    /// second map.
    pub shadow_map: Option<&'a HostImage>,
    /// The second shadow map, an array of layers holding the faces
    /// [`ShadowFace::in_second_map`], exactly when the description has one
    /// ([`SssEffectDesc::with_second_shadow_map`]).
    pub second_shadow_map: Option<&'a HostImage>,
    /// The faces of the lights' shadow maps (as [`super::TransmissionFrame::shadow_faces`]):
    /// a light without one is unshadowed.
    pub shadow_faces: &'a [ShadowFace],
}

/// Where the LEAN blurs' moments, albedo and normals come from in a frame.
#[derive(Clone, Copy, Debug)]
pub enum LeanSurface<'a> {
    /// The host's normals ([`GBufferDesc::normals`](super::GBufferDesc::normals)): lucent builds the LEAN targets from them
    /// and each material's [`SpecularSurface`] in one pass (`sss lean in`).
    Normals(&'a HostImage),
    /// The LEAN targets the host's G-buffer pass wrote ([`GBufferDesc::with_lean_targets`](super::GBufferDesc::with_lean_targets)).
    Targets(LeanTargetImages<'a>),
}

/// The LEAN targets of one frame, as [`super::LeanTargetsDesc`] describes them.
#[derive(Clone, Copy, Debug)]
pub struct LeanTargetImages<'a> {
    /// The view-plane slope y and second moments.
    pub moments: &'a HostImage,
    /// The albedo and specular intensity.
    pub albedo_specular: &'a HostImage,
    /// The world normal and roughness.
    pub normal_roughness: &'a HostImage,
}

/// A screen rectangle where scattered light may reach this frame ([`SssFrame::regions`]): for
/// one material's blur chain, or for every chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct SssRegion {
    /// The rectangle, in pixels (it may reach past the screen: it is clipped).
    pub rect: vk::Rect2D,
    /// The host material ID whose blur chain runs here (`None`: every chain).
    pub material: Option<u8>,
}

impl SssRegion {
    /// Where material `id`'s light may reach: its objects' bounds widened by
    /// [`SssEffect::reach_of`] `id`. Only its own blur chain runs here.
    pub fn of(id: u8, rect: vk::Rect2D) -> Self {
        Self {
            rect,
            material: Some(id),
        }
    }

    /// Where any material's light may reach: every blur chain runs here.
    pub fn any(rect: vk::Rect2D) -> Self {
        Self {
            rect,
            material: None,
        }
    }
}

/// One view of one frame: what [`SssEffect::record`] reads and writes.
#[derive(Clone, Copy, Debug)]
pub struct SssFrame<'a> {
    /// The frame-in-flight slot (0 to the frames in flight of the [`Lucent`]).
    pub slot: usize,
    /// The view within the frame (0 to [`SssEffectDesc::views_per_frame`]).
    pub view: usize,
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The G-buffer's images.
    pub images: SssImages<'a>,
    /// Screen rectangles the scattering materials' light may reach this frame: their
    /// objects' projected bounds widened by the blurs' reach ([`SssEffect::reach_of`] each
    /// object's material's, or [`SssEffect::reach`] the widest; [`super::screen_region`]
    /// computes both), each for one material ([`SssRegion::of`]) or for all
    /// ([`SssRegion::any`]). Each blur chain runs on the 64-pixel tiles its own materials'
    /// regions (and the regions for all) touch and a pass-through elsewhere, as lucent's own
    /// frames give each chain its own objects' tiles: a region that leaves out the reach
    /// changes the result near its edge, and a material without a region is not blurred
    /// (when other regions are given). Empty: the whole screen for every chain.
    pub regions: &'a [SssRegion],
    /// The image the result is written into (a colour attachment of the output format).
    pub output: &'a HostImage,
    /// With a LEAN blur's material: the normals and lights it relights the specular with
    /// (`None` without one).
    pub lean: Option<LeanLighting<'a>>,
}

/// The graph's imports, by input.
#[derive(Clone, Copy, Debug)]
struct Imports {
    depth: ResourceId,
    diffuse: ResourceId,
    specular: Option<ResourceId>,
    albedo: Option<ResourceId>,
    material_ids: ResourceId,
    output: ResourceId,
    /// With LEAN blurs built from the normals: the normals.
    normals: Option<ResourceId>,
    /// With the host's LEAN targets: the moments, the albedo and specular, the normal and
    /// roughness.
    lean_targets: Option<[ResourceId; 3]>,
    /// With LEAN blurs and a shadow format: the shadow map.
    shadow_map: Option<ResourceId>,
    /// And the second shadow map, when described.
    second_shadow_map: Option<ResourceId>,
}

/// The host LEAN pass's per-frame constants (glsl/sss/host_lean.frag `HostLean`, std140).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HostLeanGpu {
    normals: [u32; 4],
    view_to_world: [[f32; 4]; 4],
    /// Per profile number: x roughness, y specular intensity.
    surface: [[f32; 4]; sss::MAX_SSS_PROFILES],
}

/// Screen-space SSS over a host's G-buffer (see the module docs).
pub struct SssEffect {
    passes: EffectPasses,
    imports: Imports,
    desc: SssEffectDesc,
    /// The blur chains the profiles use (each draws in its own materials' tiles).
    chains: usize,
    /// Each material's host ID, reach and chain, in the description's order.
    materials: Vec<MaterialChain>,
    /// Whether a material has a LEAN blur (the frame then gives [`SssFrame::lean`]).
    lean_blur: bool,
    /// With LEAN blurs built from the normals: the host LEAN pass's constants but for the view
    /// (written per frame).
    lean: Option<HostLeanGpu>,
    /// How the host's shadow maps are laid out, when it describes them.
    shadow_maps: Option<ShadowMaps>,
}

/// One of an [`SssEffect`]'s materials: its host ID, its reach ([`SssEffect::reach_of`]) and
/// the blur chain its pixels are diffused by (an index into the profiles' chains).
#[derive(Clone, Copy, Debug)]
struct MaterialChain {
    id: u8,
    reach: f32,
    chain: usize,
}

impl SssEffect {
    /// Builds the effect for `desc`. The profile tables' upload is recorded into `uploads`
    /// (the host submits it before the first frame); nothing is submitted or waited for.
    /// Everything about the description is checked here.
    pub fn new(lucent: &Lucent, uploads: &mut Uploads, desc: SssEffectDesc) -> Result<Self> {
        check_views(desc.views_per_frame)?;
        check_output_format(desc.output_format)?;
        // The checks every path of the SSS passes makes (lucent's own frames too).
        let CheckedMaterials { profiles, id_map } = desc.check_materials(&registry::blur_of)?;
        let gbuffer = &desc.gbuffer;
        let lean = profiles.iter().any(|(_, b)| b.lean());
        if desc.shadow_array && desc.shadow_format.is_none() {
            return Err(HostError::Description {
                field: "shadow_array".into(),
                problem:
                    "a shadow map array without a shadow map (SssEffectDesc::with_shadow_maps)"
                        .into(),
            }
            .into());
        }
        if let Some(format) = desc.shadow_format {
            if !lean {
                return Err(HostError::Unsupported {
                    input: "shadow map".into(),
                    found: "a shadow format without a LEAN blur's material".into(),
                    accepted: "shadow maps only with LCB, LBB or the bilateral blur, whose \
                               relit specular they shadow"
                        .into(),
                }
                .into());
            }
            check_shadow_format(format, "shadow map")?;
        } else if desc.second_shadow_format.is_some() {
            return Err(HostError::Description {
                field: "second_shadow_format".into(),
                problem: "a second shadow map without a first (SssEffectDesc::with_shadow_maps)"
                    .into(),
            }
            .into());
        }
        let shadow_maps = desc
            .shadow_format
            .map(|_| ShadowMaps::described(desc.shadow_array, desc.second_shadow_format))
            .transpose()?;
        // Without the host's LEAN targets, the LEAN pass builds them from the normals.
        let lean_constants = if lean && gbuffer.lean_targets.is_none() {
            let normals = gbuffer.normals.expect("require(LeanSss) checked them");
            let mut constants: HostLeanGpu = bytemuck::Zeroable::zeroed();
            constants.normals = normals.decode()?;
            // Material i has profile i + 1 (as check_materials numbers them).
            for (index, material) in desc.materials.iter().enumerate() {
                if let Some(surface) = material.surface {
                    constants.surface[index + 1] = [surface.roughness, surface.specular, 0.0, 0.0];
                }
            }
            Some(constants)
        } else {
            None
        };
        let profiles = SssProfiles {
            transmission: vec![None; profiles.len()],
            profiles,
            object_ids: Vec::new(),
            id_map,
        };
        let upload = SceneUpload {
            profile_ids: Some(&[]),
            ..SceneUpload::tables_only({
                let mut tables = sss::tables::regions(&profiles);
                if lean_constants.is_some() {
                    tables.push(TableRegion {
                        region: &HOST_LEAN,
                        bytes: std::mem::size_of::<HostLeanGpu>() as u64,
                    });
                }
                if desc.shadow_format.is_some() {
                    tables.push(crate::features::shadows::table_region());
                }
                tables
            })
        };
        let (passes, imports) = EffectPasses::new(
            lucent,
            uploads,
            "SssEffect",
            upload,
            desc.views_per_frame,
            |scene_gpu| declare(&desc, &profiles, scene_gpu, lean),
        )?;
        let chains = profiles.chains();
        // Material i has profile i + 1 (as check_materials numbers them).
        let materials = desc
            .materials
            .iter()
            .zip(&profiles.profiles)
            .map(|(m, (profile, blur))| MaterialChain {
                id: m.id,
                reach: sss::profile_reach(profile),
                chain: chains
                    .iter()
                    .position(|c| c == blur)
                    .expect("chains() lists every profile's blur"),
            })
            .collect();
        let out = Self {
            passes,
            imports,
            shadow_maps,
            chains: chains.len(),
            materials,
            desc,
            lean_blur: lean,
            lean: lean_constants,
        };
        // The tables do not change between frames: written once into every slot.
        for slot in 0..out.passes.slots() {
            let per_frame = out.passes.per_frame();
            let written = sss::tables::write(per_frame, slot, &profiles, &out.desc.knobs);
            if let Err(e) = written {
                out.destroy(lucent);
                return Err(e);
            }
        }
        Ok(out)
    }

    /// How far, in the host's world units, the blurs spread light beyond an object (3 sigma
    /// of the widest profile's widest Gaussian): widen each object's screen bounds by it
    /// projected at the object's depth for [`SssFrame::regions`] ([`super::screen_region`]
    /// does).
    pub fn reach(&self) -> f32 {
        self.materials.iter().map(|m| m.reach).fold(0.0, f32::max)
    }

    /// The reach of the material with host ID `id` alone (`None`: no material has it): widen
    /// each object's bounds by its own material's reach and the regions cover no more than
    /// the blurs need, as lucent's own frames widen each object's tiles by its own profile's.
    pub fn reach_of(&self, id: u8) -> Option<f32> {
        self.materials.iter().find(|m| m.id == id).map(|m| m.reach)
    }

    super::passes::effect_methods!(
        SssFrame,
        "the frame's images, seen by its camera, blurred into its output"
    );

    fn record_with(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &SssFrame<'_>,
        timer: Option<&mut super::EffectTimer>,
    ) -> Result<()> {
        let ring = self.passes.slot(frame.slot, frame.view)?;
        let gbuffer = &self.desc.gbuffer;
        let mut uniforms = gbuffer.view_uniforms(&frame.camera)?;
        let (inputs, maps) = self.check_images(lucent, frame)?;
        let mut shadows = None;
        if let Some(lean) = &frame.lean {
            check_lights(lean.lights)?;
            uniforms = uniforms.with_lights(lean.lights);
            if !maps.is_empty() {
                shadows = Some(shadow_table(lean.lights, lean.shadow_faces, &maps)?);
            }
        }
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &FRAME, bytemuck::bytes_of(&uniforms))?;
        if let Some(constants) = &self.lean {
            let constants = HostLeanGpu {
                view_to_world: frame.camera.view.inverse().to_cols_array_2d(),
                ..*constants
            };
            per_frame.write(ring, &HOST_LEAN, bytemuck::bytes_of(&constants))?;
        }
        if let Some(table) = &shadows {
            per_frame.write(
                ring,
                &crate::features::shadows::TABLE_REGION,
                bytemuck::bytes_of(table),
            )?;
        }
        // Each chain's tiles (none: the whole screen).
        per_frame.tiles(ring).sss = self.chain_tiles(frame.regions)?;
        let mut binds = vec![
            (self.imports.depth, frame.images.depth),
            (self.imports.diffuse, frame.images.diffuse),
            (self.imports.material_ids, frame.images.material_ids),
            (self.imports.output, frame.output),
        ];
        if let (Some(id), Some(image)) = (self.imports.specular, frame.images.specular) {
            binds.push((id, image));
        }
        if let (Some(id), Some(image)) = (self.imports.albedo, frame.images.albedo) {
            binds.push((id, image));
        }
        if let Some(lean) = &frame.lean {
            match (
                lean.surface,
                self.imports.normals,
                self.imports.lean_targets,
            ) {
                (LeanSurface::Normals(normals), Some(id), _) => binds.push((id, normals)),
                (LeanSurface::Targets(targets), _, Some([moments, albedo, normal])) => {
                    binds.push((moments, targets.moments));
                    binds.push((albedo, targets.albedo_specular));
                    binds.push((normal, targets.normal_roughness));
                }
                _ => unreachable!("check_images matched the surface with the description"),
            }
            if let (Some(id), Some(map)) = (self.imports.shadow_map, lean.shadow_map) {
                binds.push((id, map));
            }
            if let (Some(id), Some(map)) = (self.imports.second_shadow_map, lean.second_shadow_map)
            {
                binds.push((id, map));
            }
        }
        self.passes.record(
            lucent,
            cmd,
            ring,
            &binds,
            &inputs,
            (frame.output, Role::Output),
            timer,
        )
    }

    /// Each blur chain's tiles for `regions` (empty: every chain on the whole screen): the
    /// tiles touched by the regions of the chain's own materials and by those for all.
    fn chain_tiles(&self, regions: &[SssRegion]) -> Result<Vec<Option<Vec<TileRect>>>> {
        let extent = self.desc.gbuffer.extent();
        if regions.is_empty() {
            return Ok(Vec::new());
        }
        let mut rects = vec![Vec::new(); self.chains];
        for (index, region) in regions.iter().enumerate() {
            match region.material {
                None => rects.iter_mut().for_each(|r| r.push(region.rect)),
                Some(id) => {
                    let Some(material) = self.materials.iter().find(|m| m.id == id) else {
                        return Err(HostError::Description {
                            field: format!("regions[{index}].material"),
                            problem: format!(
                                "ID {id} is none of the effect's materials (SssEffectDesc::materials: {})",
                                self.materials
                                    .iter()
                                    .map(|m| m.id.to_string())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        }
                        .into());
                    };
                    rects[material.chain].push(region.rect);
                }
            }
        }
        Ok(rects
            .iter()
            .map(|r| Some(tiles_marked_by(r, extent)))
            .collect())
    }

    /// Checks every image of `frame` against the description; returns the inputs, one per
    /// distinct Vulkan image (the depth and the stencil IDs may share one: it is transitioned
    /// once, and both must declare the same states), and the shadow maps' sizes and layers
    /// (none without shadow maps).
    fn check_images<'a>(
        &self,
        lucent: &Lucent,
        frame: &SssFrame<'a>,
    ) -> Result<(Vec<&'a HostImage>, MapSizes)> {
        let gbuffer = &self.desc.gbuffer;
        let extent = gbuffer.extent();
        let gpu = lucent.gpu();
        let images = &frame.images;
        let same = |format: vk::Format| move |f: vk::Format| f == format;
        let named = |format: vk::Format| format!("{} (the description's)", format_name(format));
        let depth_role = match gbuffer.depth.encoding {
            crate::features::gbuffer_desc::DepthEncoding::Device => Role::SampledDepth,
            crate::features::gbuffer_desc::DepthEncoding::LinearView => Role::SampledColor,
        };
        let ids = gbuffer.material_ids.expect("checked at new");
        let id_role = if matches!(ids.encoding, IdEncoding::Stencil { .. }) {
            Role::SampledDepth
        } else {
            Role::SampledColor
        };
        // The inputs every frame has, and the output; the optional ones below.
        for (image, input, role, format) in [
            (images.depth, "depth", depth_role, gbuffer.depth.format),
            (
                images.diffuse,
                "diffuse",
                Role::SampledColor,
                gbuffer.diffuse.format,
            ),
            (images.material_ids, "material IDs", id_role, ids.format),
            (
                frame.output,
                "output",
                Role::Output,
                self.desc.output_format,
            ),
        ] {
            check_image(
                gpu,
                image,
                input,
                role,
                extent,
                same(format),
                &named(format),
            )?;
        }
        for (input, described, given) in [
            ("specular", gbuffer.specular, images.specular),
            ("albedo", gbuffer.albedo, images.albedo),
        ] {
            match (described, given) {
                (Some(format), Some(image)) => check_image(
                    gpu,
                    image,
                    input,
                    Role::SampledColor,
                    extent,
                    same(format),
                    &named(format),
                )?,
                (None, None) => {}
                (Some(_), None) => {
                    return Err(HostError::Missing {
                        input: input.into(),
                        needed_by: "the G-buffer description has it".into(),
                    }
                    .into())
                }
                (None, Some(image)) => {
                    return Err(HostError::Image {
                        image: image.name.clone(),
                        kind: ImageFault::Aliased,
                        problem: format!(
                            "given as the {input}, which the G-buffer description has none of"
                        ),
                    }
                    .into())
                }
            }
        }
        let (lean, maps) = self.check_lean(lucent, frame)?;
        let all = [
            Some(images.depth),
            Some(images.diffuse),
            Some(images.material_ids),
            images.specular,
            images.albedo,
        ];
        let inputs = distinct_inputs(all.into_iter().flatten().chain(lean), frame.output)?;
        Ok((inputs, maps))
    }

    /// Checks `frame.lean` against the effect: there exactly when a LEAN blur is, its
    /// normals or LEAN targets as described, its shadow map there exactly when the
    /// description has a shadow format. Returns those images, and the shadow maps' sizes and
    /// layers.
    fn check_lean<'a>(
        &self,
        lucent: &Lucent,
        frame: &SssFrame<'a>,
    ) -> Result<(Vec<&'a HostImage>, MapSizes)> {
        let lean = match (self.lean_blur, &frame.lean) {
            (false, None) => return Ok((Vec::new(), Vec::new())),
            (true, Some(lean)) => lean,
            (true, None) => {
                return Err(HostError::Missing {
                    input: "lean".into(),
                    needed_by: "a material of LCB, LBB or the bilateral blur: their LEAN \
                                moments are made from the normals and their specular relit \
                                with the lights (SssFrame::lean)"
                        .into(),
                }
                .into())
            }
            (false, Some(_)) => {
                return Err(HostError::Unsupported {
                    input: "lean".into(),
                    found: "normals and lights for an effect without a LEAN blur".into(),
                    accepted: "SssFrame::lean only with a material of LCB, LBB or the \
                               bilateral blur (the other blurs keep the host's specular)"
                        .into(),
                }
                .into())
            }
        };
        let gbuffer = &self.desc.gbuffer;
        let check = |image: &HostImage, input: &str, format: vk::Format| {
            check_image(
                lucent.gpu(),
                image,
                input,
                Role::SampledColor,
                gbuffer.extent(),
                |f| f == format,
                &format!("{} (the description's)", format_name(format)),
            )
        };
        let mut images = match (lean.surface, &gbuffer.lean_targets) {
            (LeanSurface::Targets(targets), Some(desc)) => {
                check(targets.moments, "lean targets: moments", desc.moments)?;
                check(
                    targets.albedo_specular,
                    "lean targets: albedo and specular",
                    desc.albedo_specular,
                )?;
                check(
                    targets.normal_roughness,
                    "lean targets: normal and roughness",
                    desc.normal_roughness,
                )?;
                vec![
                    targets.moments,
                    targets.albedo_specular,
                    targets.normal_roughness,
                ]
            }
            (LeanSurface::Normals(normals), None) => {
                let format = gbuffer.normals.expect("checked at new").format;
                check(normals, "normals", format)?;
                vec![normals]
            }
            (LeanSurface::Normals(normals), Some(_)) => {
                return Err(HostError::Image {
                    image: normals.name.clone(),
                    kind: ImageFault::Aliased,
                    problem: "given as the LEAN blurs' normals, but the description has LEAN \
                              targets (LeanSurface::Targets)"
                        .into(),
                }
                .into())
            }
            (LeanSurface::Targets(_), None) => {
                return Err(HostError::Unsupported {
                    input: "lean.surface".into(),
                    found: "LEAN targets, which the description has none of".into(),
                    accepted: "the normals (LeanSurface::Normals), or LEAN targets described \
                               by GBufferDesc::with_lean_targets"
                        .into(),
                }
                .into())
            }
        };
        let mut maps = Vec::new();
        let shadow_map = match (self.desc.shadow_format, lean.shadow_map) {
            (Some(format), Some(map)) => {
                maps = self
                    .shadow_maps
                    .expect("described with the shadow format")
                    .check_frame(
                        lucent.gpu(),
                        map,
                        lean.second_shadow_map,
                        (format, self.desc.second_shadow_format),
                    )?;
                images.extend(lean.second_shadow_map);
                Some(map)
            }
            (None, None) => {
                if let Some(map) = lean.second_shadow_map {
                    return Err(undescribed_second_map(map));
                }
                if !lean.shadow_faces.is_empty() {
                    return Err(HostError::Description {
                        field: "lean.shadow_faces".into(),
                        problem: "faces without a shadow map (the description has no shadow \
                                  format: SssEffectDesc::with_shadow_maps)"
                            .into(),
                    }
                    .into());
                }
                None
            }
            (Some(_), None) => {
                return Err(HostError::Missing {
                    input: "shadow map".into(),
                    needed_by: "the description has a shadow format (LeanLighting::shadow_map)"
                        .into(),
                }
                .into())
            }
            (None, Some(map)) => {
                return Err(HostError::Image {
                    image: map.name.clone(),
                    kind: ImageFault::Aliased,
                    problem: "given as the shadow map, which the description has no format \
                              for (SssEffectDesc::with_shadow_maps)"
                        .into(),
                }
                .into())
            }
        };
        images.extend(shadow_map);
        Ok((images, maps))
    }
}

/// The effect's graph: the host's images imported (bound when each frame records), the
/// albedo pass where the host's light needs it, the SSS chains into the output.
fn declare(
    desc: &SssEffectDesc,
    profiles: &SssProfiles,
    scene_gpu: &Arc<SceneGpu>,
    lean: bool,
) -> (RenderGraph, Imports) {
    let gbuffer = &desc.gbuffer;
    let (width, height) = (gbuffer.width, gbuffer.height);
    let mut graph = RenderGraph::new();
    let import = |graph: &mut RenderGraph, name: &str, format: vk::Format, initial: Access| {
        graph.import_image(
            name,
            ImageInfo {
                width,
                height,
                format,
            },
            ImportedImage {
                image: vk::Image::null(),
                view: vk::ImageView::null(),
                initial,
            },
        )
    };
    let sampled = Access::FragmentSampledRead;
    let depth = import(&mut graph, "host depth", gbuffer.depth.format, sampled);
    let diffuse = import(&mut graph, "host diffuse", gbuffer.diffuse.format, sampled);
    let ids_format = gbuffer.material_ids.expect("checked at new").format;
    let material_ids = import(&mut graph, "host material IDs", ids_format, sampled);
    let specular = gbuffer
        .specular
        .map(|f| import(&mut graph, "host specular", f, sampled));
    let albedo = gbuffer
        .albedo
        .map(|f| import(&mut graph, "host albedo", f, sampled));
    let output = import(
        &mut graph,
        "host output",
        desc.output_format,
        Access::ColorAttachmentWrite,
    );
    let targets = gbuffer.lean_targets.filter(|_| lean);
    let normals = (lean && targets.is_none()).then(|| {
        let format = gbuffer.normals.expect("checked at new").format;
        import(&mut graph, "host normals", format, sampled)
    });
    let lean_targets = targets.map(|t| {
        [
            import(&mut graph, "host LEAN moments", t.moments, sampled),
            import(
                &mut graph,
                "host albedo and specular",
                t.albedo_specular,
                sampled,
            ),
            import(
                &mut graph,
                "host normal and roughness",
                t.normal_roughness,
                sampled,
            ),
        ]
    });
    let shadow_map = desc
        .shadow_format
        .map(|format| import(&mut graph, "host shadow map", format, sampled));
    let second_shadow_map = desc
        .second_shadow_format
        .map(|format| import(&mut graph, "host second shadow map", format, sampled));
    let imports = Imports {
        depth: depth.id(),
        diffuse: diffuse.id(),
        specular: specular.as_ref().map(Handle::id),
        albedo: albedo.as_ref().map(Handle::id),
        material_ids: material_ids.id(),
        output: output.id(),
        normals: normals.as_ref().map(Handle::id),
        lean_targets: lean_targets.as_ref().map(|t| t.each_ref().map(Handle::id)),
        shadow_map: shadow_map.as_ref().map(Handle::id),
        second_shadow_map: second_shadow_map.as_ref().map(Handle::id),
    };
    let images = DescribedImages {
        depth: &depth,
        diffuse: &diffuse,
        material_ids: &material_ids,
        specular: specular.as_ref(),
        albedo: albedo.as_ref(),
        normals: normals.as_ref(),
        lean_targets: lean_targets.as_ref().map(|t| t.each_ref()),
        shadows: shadow_map.as_ref().map(|depth| DescribedShadows {
            depth,
            array: desc.shadow_array,
            second: second_shadow_map.as_ref(),
            // A host's map may store reversed Z (its faces say: ShadowFace).
            reversible: true,
        }),
    };
    let result = sss_on_gbuffer(
        &mut graph,
        gbuffer,
        &images,
        profiles,
        &desc.knobs,
        Some(scene_gpu),
        Some(output),
    );
    graph.export_image(&result, Access::ColorAttachmentWrite);
    (graph, imports)
}

/// The output must be a colour-attachment format the final pass writes floats into.
fn check_output_format(format: vk::Format) -> Result<()> {
    if sampled_float(format) && format_info(format).is_some_and(|f| f.channels >= 3) {
        Ok(())
    } else {
        Err(HostError::Unsupported {
            input: "output".into(),
            found: format!("format {}", format_name(format)),
            accepted: "an RGB(A) float, UNORM or SRGB colour format".into(),
        }
        .into())
    }
}

// Renderers move to a loader thread and back.
const _: () = {
    const fn send<T: Send>() {}
    send::<SssEffect>();
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::material::SssProfile;

    #[test]
    fn output_formats_are_colour_the_final_pass_can_write() {
        check_output_format(vk::Format::R16G16B16A16_SFLOAT).unwrap();
        check_output_format(vk::Format::B8G8R8A8_UNORM).unwrap();
        check_output_format(vk::Format::B10G11R11_UFLOAT_PACK32).unwrap();
        assert!(check_output_format(vk::Format::R32G32B32A32_UINT).is_err());
        assert!(check_output_format(vk::Format::D32_SFLOAT).is_err());
        assert!(check_output_format(vk::Format::R8_UNORM).is_err());
    }

    #[test]
    fn a_material_says_whether_its_blur_relights_the_specular() {
        let material = |blur: Option<&str>| {
            let mut profile = SssProfile::preset("skin").expect("a preset");
            profile.blur = blur.map(Into::into);
            SssMaterial::new(3, profile)
        };
        for (blur, relit) in [
            (Some("lcb"), true),
            (Some("lbb"), true),
            (Some("bilateral"), true),
            (Some("separable"), false),
            (Some("control"), false),
            (Some("burley"), false),
            // No blur named: the default blur (separable).
            (None, false),
        ] {
            let m = material(blur);
            assert_eq!(m.relights_specular().unwrap(), relit, "{blur:?}");
            let surface = SpecularSurface::new(0.4, 0.3);
            let given = m.with_surface_if_relit(surface).unwrap().surface;
            assert_eq!(given, relit.then_some(surface), "{blur:?}");
        }
        let e = material(Some("gaussian-ish"))
            .relights_specular()
            .unwrap_err();
        assert!(e.to_string().contains("separable"), "{e}");
    }
}
