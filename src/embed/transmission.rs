//! [`TransmissionEffect`]: screen-space SSS's transmission through thin parts (HDRP's "thick"
//! mode, from a material's medium) added to a host's lit diffuse, measured through the host's
//! own shadow maps.
//!
//! For each pixel whose material has a medium ([`TransmissionMaterial`]: lucent's
//! `[material.medium]`), and each of the host's lights with a shadow map, the light that
//! entered on the far side of the object diffuses through the thickness the map measures and
//! leaves here: the same GLSL (`sss_transmitted` in `glsl/common/sss_transmission.glsl`) that
//! lucent's own lighting pass adds, with its f64 twin in `src/reference/transmission.rs`. The
//! thickness is the light's path through the object: from this pixel (moved one map texel
//! inside) towards the light, to the first surface the map holds, bilinearly over the map's
//! four texels around it. Recorded before an [`super::SssEffect`] on the same light, the blur
//! spreads the transmitted light, as lucent's own frames do.
//!
//! The host describes the maps it already renders for its shadows ([`ShadowFace`]): one depth
//! image (an atlas: each face a square rectangle of it), and per face its light, its view and
//! projection matrices (perspective or orthographic; standard Z, depth 0 at the near plane
//! and 1 at the far, or reversed Z; a finite or infinite far plane) and its rectangle, with
//! which it rendered the map. A point light has six faces, +X, -X, +Y, -Y, +Z, -Z in that order (checked from their view matrices); a spot or
//! directional light one. Lights without faces transmit nothing (nothing measures the
//! thickness), as in lucent's own frames.
//!
//! The host's encodings reach one shader (`glsl/deferred/host_transmission.frag`) as
//! permutations (unsigned or UNORM IDs; whether the albedo is read) and per-frame constants
//! (the ID bit field and the ID-to-medium table, the normal encoding, the depth decode, the
//! shadow table lucent's own light-space maps fill): no copy into lucent's layout.

use std::sync::Arc;

use ash::vk;

use super::image::{distinct_inputs, HostImage, Role};
use super::passes::{
    check_described, check_lights, check_material_id, check_views, depth_role, frame_albedo,
    id_role, import_host_image, EffectPasses,
};
use super::regions::clipped;
use super::shadow_faces::{check_shadow_format, shadow_table, MapSizes, ShadowFace, ShadowMaps};
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::backend::shader::PipelineShaders;
use crate::error::HostError;
use crate::features::capabilities::{require, Effect};
use crate::features::gbuffer_desc::{
    check_metres_per_unit, DepthEncoding, DiffuseAlbedo, GBufferDesc, HostCamera,
};
use crate::features::pass::FullscreenPass;
use crate::features::shadows::ShadowUniforms;
use crate::features::sss::transmission::{SssTransmission, MEDIUM_ROWS};
use crate::features::sss::{ProfileTableGpu, MAX_SSS_PROFILES};
use crate::gpu_scene::{Region, SceneGpu, SceneUpload, TableRegion, FRAME};
use crate::graph::{LoadOp, RenderGraph, ResourceId};
use crate::scene::material::Medium;
use crate::scene::Light;
use crate::Result;

/// The effect's fragment shader.
const FRAGMENT: &str = "deferred/host_transmission.frag";

/// One material of the host whose light diffuses through its thickness: its ID in the host's
/// material ID image and its medium (lucent's `[material.medium]`,
/// [`crate::scene::material::Medium::new`]). Its lengths are scaled by the G-buffer's
/// [`GBufferDesc::metres_per_unit`], not by the medium's own `units_per_mm`.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TransmissionMaterial {
    /// The host's ID (1 to 255; 0 is taken to mean "no medium").
    pub id: u8,
    /// The medium.
    pub medium: Medium,
}

impl TransmissionMaterial {
    /// Material `id` with `medium`.
    pub fn new(id: u8, medium: Medium) -> Self {
        Self { id, medium }
    }

    /// The medium's four rows as a host's own lighting pass reads them
    /// ([`super::glsl::TERMS`]' `lucent_sss_transmittance(vec4 medium[4], thickness)` and
    /// `lucent_sss_transmitted`), its lengths in the host's world at `metres_per_unit`
    /// ([`GBufferDesc::metres_per_unit`]): the same rows [`TransmissionEffect`] and lucent's
    /// own frames read from the SSS profile table. Every value is finite; a unit that is not
    /// finite, above 0 and at most [`crate::features::gbuffer_desc::MAX_METRES_PER_UNIT`] is
    /// refused ([`HostError::Description`], field `metres_per_unit`).
    pub fn rows(&self, metres_per_unit: f32) -> Result<[[f32; 4]; 4]> {
        Ok(self.transmission(metres_per_unit)?.rows())
    }

    /// The medium's transmission with its lengths in the host's world at `metres_per_unit`
    /// (checked as [`Self::rows`] says).
    fn transmission(&self, metres_per_unit: f32) -> Result<SssTransmission> {
        check_metres_per_unit(metres_per_unit, "metres_per_unit")?;
        Ok(SssTransmission {
            mm_per_unit: 1000.0 * f64::from(metres_per_unit),
            ..SssTransmission::of(&self.medium)
        })
    }
}

/// What a [`TransmissionEffect`] is built for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct TransmissionEffectDesc {
    /// The host's G-buffer: it must describe its normals and material IDs, and its albedo
    /// when its diffuse light has the albedo multiplied in.
    pub gbuffer: GBufferDesc,
    /// The materials with a medium (1 to 31 of them).
    pub materials: Vec<TransmissionMaterial>,
    /// The format of the host's shadow map (a depth format: `D32_SFLOAT`, `D16_UNORM`,
    /// `D24_UNORM_S8_UINT`, `D32_SFLOAT_S8_UINT`, `X8_D24_UNORM_PACK32`).
    pub shadow_format: vk::Format,
    /// The shadow map is an array of layers (cascades, a cube's faces), its view a 2-D array
    /// view, each face in its [`ShadowFace::layer`] ([`Self::with_shadow_array`]); else one
    /// 2-D image (an atlas).
    pub shadow_array: bool,
    /// The format of a second shadow map beside the first (an atlas): an array of layers of
    /// its own size, its view a 2-D array view (a point light's cube faces beside the spot
    /// and sun faces of an atlas), each of its faces [`ShadowFace::in_second_map`]
    /// ([`Self::with_second_shadow_map`]).
    pub second_shadow_format: Option<vk::Format>,
    /// Views recorded per frame (1 to [`super::MAX_VIEWS_PER_FRAME`]).
    pub views_per_frame: usize,
}

impl TransmissionEffectDesc {
    /// The effect over `gbuffer` for `materials`, reading shadow maps of `shadow_format`, one
    /// view a frame.
    pub fn new(
        gbuffer: GBufferDesc,
        materials: Vec<TransmissionMaterial>,
        shadow_format: vk::Format,
    ) -> Self {
        Self {
            gbuffer,
            materials,
            shadow_format,
            shadow_array: false,
            second_shadow_format: None,
            views_per_frame: 1,
        }
    }

    /// With a second shadow map of `format` beside the first, an atlas
    /// ([`Self::second_shadow_format`]; [`TransmissionImages::second_shadow_map`]).
    pub fn with_second_shadow_map(mut self, format: vk::Format) -> Self {
        self.second_shadow_format = Some(format);
        self
    }

    /// The shadow map is an array of layers (its view a 2-D array view,
    /// [`HostImage::with_layers`]), each face in its own ([`ShadowFace::in_layer`]).
    pub fn with_shadow_array(mut self) -> Self {
        self.shadow_array = true;
        self
    }

    /// With this many views per frame.
    pub fn with_views_per_frame(mut self, views: usize) -> Self {
        self.views_per_frame = views;
        self
    }
}

/// The host's images for one view of one frame, each with its current and final state.
#[derive(Clone, Copy, Debug)]
pub struct TransmissionImages<'a> {
    /// The depth image (a depth format's view of its depth aspect, or linear depth).
    pub depth: &'a HostImage,
    /// The normals.
    pub normals: &'a HostImage,
    /// The material IDs (for stencil bits: a view of the depth-stencil image's stencil
    /// aspect).
    pub material_ids: &'a HostImage,
    /// The albedo: required when the description's diffuse light has the albedo multiplied
    /// in, refused when it is kept apart.
    pub albedo: Option<&'a HostImage>,
    /// The shadow map holding the [`TransmissionFrame::shadow_faces`] faces (a view of its
    /// depth aspect, sampled): every face, or those not in the second map.
    pub shadow_map: &'a HostImage,
    /// The second shadow map, an array of layers (a 2-D array view of its depth aspect),
    /// holding the faces [`ShadowFace::in_second_map`]: given exactly when the description
    /// has one ([`TransmissionEffectDesc::with_second_shadow_map`]).
    pub second_shadow_map: Option<&'a HostImage>,
}

/// One view of one frame: what [`TransmissionEffect::record`] reads and adds to.
#[derive(Clone, Copy, Debug)]
pub struct TransmissionFrame<'a> {
    /// The frame-in-flight slot (0 to the frames in flight of the [`Lucent`]).
    pub slot: usize,
    /// The view within the frame.
    pub view: usize,
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The host's lights this frame, in its world (at most [`crate::scene::MAX_LIGHTS`]).
    pub lights: &'a [Light],
    /// The faces of the lights' shadow maps this frame (at most
    /// `crate::features::shadows::MAX_SHADOW_FACES`), each light's together and in order.
    pub shadow_faces: &'a [ShadowFace],
    /// The images.
    pub images: TransmissionImages<'a>,
    /// Screen rectangles the materials with a medium may cover this frame; empty: the whole
    /// screen. Clipped to the G-buffer.
    pub regions: &'a [vk::Rect2D],
    /// The host's lit diffuse light, which the transmitted light is added to (a colour
    /// attachment of the description's diffuse format that can be blended; its contents are
    /// kept, so it cannot come in UNDEFINED).
    pub lighting: &'a HostImage,
}

/// The effect's per-frame constants (glsl/deferred/host_transmission.frag
/// `HostTransmission`, std140).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HostTransmissionGpu {
    normals: [u32; 4],
    depth: [u32; 4],
    view_to_world: [[f32; 4]; 4],
}

/// The effect's constants, its profile table (the media) and its shadow table in the
/// per-frame buffer.
static HOST_TRANSMISSION: Region = Region::new("host transmission decode", "HostTransmission");
static MEDIA: Region = Region::new("host transmission media", "SssProfiles");
static SHADOWS: Region = Region::new("host shadow maps' table", "Shadows");

/// The graph's imports, by input.
#[derive(Clone, Copy, Debug)]
struct Imports {
    depth: ResourceId,
    normals: ResourceId,
    material_ids: ResourceId,
    albedo: Option<ResourceId>,
    shadow_map: ResourceId,
    second_shadow_map: Option<ResourceId>,
    lighting: ResourceId,
}

/// Screen-space SSS's transmission on a host's G-buffer (see the module docs).
pub struct TransmissionEffect {
    passes: EffectPasses,
    imports: Imports,
    desc: TransmissionEffectDesc,
    /// The normal decode every frame shares; each frame adds its view.
    normals: [u32; 4],
    /// How the host's shadow maps are laid out.
    shadow_maps: ShadowMaps,
}

/// The shader defines of a host's ID image (unsigned or UNORM), whether the albedo is read and
/// how the shadow maps are laid out.
fn defines(
    uint_ids: bool,
    albedo: bool,
    shadow_maps: ShadowMaps,
) -> Vec<(&'static str, &'static str)> {
    let mut defines = Vec::new();
    if albedo {
        defines.push(("LUCENT_HOST_ALBEDO", "1"));
    }
    if uint_ids {
        defines.push(("LUCENT_HOST_IDS_UINT", "1"));
    }
    defines.extend_from_slice(shadow_maps.defines());
    defines
}

/// Every pipeline the effect may build, for the shipped SPIR-V.
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for uint in [false, true] {
        for albedo in [false, true] {
            for maps in ShadowMaps::ALL {
                out.push(PipelineShaders::fullscreen(
                    FRAGMENT,
                    &defines(uint, albedo, maps),
                ));
            }
        }
    }
}

impl TransmissionEffect {
    /// Builds the effect for `desc`, checking all of it first. Its media table is written
    /// into lucent's own host-visible per-frame buffer: nothing is recorded into `uploads`,
    /// submitted or waited for (`uploads` is taken so that every effect is built alike).
    pub fn new(
        lucent: &Lucent,
        uploads: &mut Uploads,
        desc: TransmissionEffectDesc,
    ) -> Result<Self> {
        let gbuffer = &desc.gbuffer;
        gbuffer.check()?;
        require(Effect::SssTransmission, gbuffer)?;
        let (Some(ids), Some(normals)) = (gbuffer.material_ids, gbuffer.normals) else {
            unreachable!("missing() lists each input the effect reads");
        };
        check_views(desc.views_per_frame)?;
        check_shadow_format(desc.shadow_format, "shadow map")?;
        let shadow_maps = ShadowMaps::described(desc.shadow_array, desc.second_shadow_format)?;
        if desc.materials.is_empty() || desc.materials.len() >= MAX_SSS_PROFILES {
            return Err(HostError::Description {
                field: "materials".into(),
                problem: format!(
                    "{} materials with a medium; 1 to {} are supported",
                    desc.materials.len(),
                    MAX_SSS_PROFILES - 1
                ),
            }
            .into());
        }
        let mut id_map = ids.decode(Vec::new())?;
        let mut profile_of = vec![0u8; 256];
        let mut table: ProfileTableGpu = bytemuck::Zeroable::zeroed();
        for (index, material) in desc.materials.iter().enumerate() {
            let id = usize::from(material.id);
            check_material_id(index, material.id, profile_of[id] != 0, id_map.mask)?;
            let profile = index + 1;
            profile_of[id] = profile as u8;
            let transmission = material.transmission(gbuffer.metres_per_unit)?;
            let rows = &mut table.medium[profile * MEDIUM_ROWS..];
            rows[..4].copy_from_slice(&transmission.rows());
            rows[4..MEDIUM_ROWS].copy_from_slice(&transmission.reflectance_rows());
        }
        id_map.profile_of = profile_of;
        let uint_ids = id_map.uint;
        (table.id_decode, table.id_profiles) = id_map.rows();
        let normals = normals.decode()?;
        let region = |region: &'static Region, bytes: usize| TableRegion {
            region,
            bytes: bytes as u64,
        };
        let upload = SceneUpload::tables_only(vec![
            region(&MEDIA, std::mem::size_of::<ProfileTableGpu>()),
            region(
                &HOST_TRANSMISSION,
                std::mem::size_of::<HostTransmissionGpu>(),
            ),
            region(&SHADOWS, std::mem::size_of::<ShadowUniforms>()),
        ]);
        let (passes, imports) = EffectPasses::new(
            lucent,
            uploads,
            "TransmissionEffect",
            upload,
            desc.views_per_frame,
            |scene_gpu| declare(&desc, uint_ids, shadow_maps, scene_gpu),
        )?;
        let out = Self {
            passes,
            imports,
            desc,
            normals,
            shadow_maps,
        };
        // The media do not change between frames: written once into every slot.
        for slot in 0..out.passes.slots() {
            let per_frame = out.passes.per_frame();
            if let Err(e) = per_frame.write(slot, &MEDIA, bytemuck::bytes_of(&table)) {
                out.destroy(lucent);
                return Err(e);
            }
        }
        Ok(out)
    }

    super::passes::effect_methods!(
        TransmissionFrame,
        "the light of `frame.lights` diffused through the thickness their shadow maps measure, added to `frame.lighting`"
    );

    fn record_with(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &TransmissionFrame<'_>,
        timer: Option<&mut super::EffectTimer>,
    ) -> Result<()> {
        let ring = self.passes.slot(frame.slot, frame.view)?;
        check_lights(frame.lights)?;
        let (inputs, maps) = self.check_images(lucent, frame)?;
        let shadows = shadow_table(frame.lights, frame.shadow_faces, &maps)?;
        let gbuffer = &self.desc.gbuffer;
        let uniforms = gbuffer
            .view_uniforms(&frame.camera)?
            .with_lights(frame.lights);
        let constants = HostTransmissionGpu {
            normals: self.normals,
            depth: [
                u32::from(gbuffer.depth.encoding == DepthEncoding::LinearView),
                0,
                0,
                0,
            ],
            view_to_world: frame.camera.view.inverse().to_cols_array_2d(),
        };
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &FRAME, bytemuck::bytes_of(&uniforms))?;
        per_frame.write(ring, &HOST_TRANSMISSION, bytemuck::bytes_of(&constants))?;
        per_frame.write(ring, &SHADOWS, bytemuck::bytes_of(&shadows))?;
        // The pass draws in the `lighting` tiles of the slot (none: the whole screen).
        per_frame.tiles(ring).lighting = clipped(frame.regions, gbuffer.extent());
        let images = &frame.images;
        let mut binds = vec![
            (self.imports.depth, images.depth),
            (self.imports.normals, images.normals),
            (self.imports.material_ids, images.material_ids),
            (self.imports.shadow_map, images.shadow_map),
            (self.imports.lighting, frame.lighting),
        ];
        if let (Some(id), Some(albedo)) = (self.imports.albedo, images.albedo) {
            binds.push((id, albedo));
        }
        if let (Some(id), Some(map)) = (self.imports.second_shadow_map, images.second_shadow_map) {
            binds.push((id, map));
        }
        self.passes.record(
            lucent,
            cmd,
            ring,
            &binds,
            &inputs,
            (frame.lighting, Role::Accumulate),
            timer,
        )
    }

    /// Checks every image of `frame` against the description; returns the inputs, one per
    /// distinct Vulkan image, and the shadow maps' sizes and layers.
    fn check_images<'a>(
        &self,
        lucent: &Lucent,
        frame: &TransmissionFrame<'a>,
    ) -> Result<(Vec<&'a HostImage>, MapSizes)> {
        let gbuffer = &self.desc.gbuffer;
        let images = &frame.images;
        let ids = gbuffer.material_ids.expect("checked at new");
        let depth_role = depth_role(gbuffer);
        let id_role = id_role(&ids);
        let albedo = frame_albedo(
            self.imports.albedo.is_some(),
            images.albedo,
            "the transmitted light",
        )?;
        let normal_format = gbuffer.normals.expect("checked at new").format;
        let mut checks = vec![
            (images.depth, "depth", depth_role, gbuffer.depth.format),
            (images.normals, "normals", Role::SampledColor, normal_format),
            (images.material_ids, "material IDs", id_role, ids.format),
            (
                frame.lighting,
                "lighting",
                Role::Accumulate,
                gbuffer.diffuse.format,
            ),
        ];
        if let Some(albedo) = albedo {
            let format = gbuffer.albedo.expect("checked at new");
            checks.push((albedo, "albedo", Role::SampledColor, format));
        }
        check_described(lucent, gbuffer.extent(), &checks)?;
        // The shadow maps have a size (and maybe layers) of their own.
        let maps = self.shadow_maps.check_frame(
            lucent.gpu(),
            images.shadow_map,
            images.second_shadow_map,
            (self.desc.shadow_format, self.desc.second_shadow_format),
        )?;
        let inputs = distinct_inputs(
            [
                images.depth,
                images.normals,
                images.material_ids,
                images.shadow_map,
            ]
            .into_iter()
            .chain(images.second_shadow_map)
            .chain(albedo),
            frame.lighting,
        )?;
        Ok((inputs, maps))
    }
}

/// The effect's graph: the host's images imported (bound when each frame records) and one
/// fullscreen pass adding the transmitted light to the host's.
fn declare(
    desc: &TransmissionEffectDesc,
    uint_ids: bool,
    shadow_maps: ShadowMaps,
    scene_gpu: &Arc<SceneGpu>,
) -> (RenderGraph, Imports) {
    let gbuffer = &desc.gbuffer;
    let reads_albedo = gbuffer.diffuse.albedo == DiffuseAlbedo::Included;
    let mut graph = RenderGraph::new();
    let mut import = |name: &str, format: vk::Format, initial: Access| {
        import_host_image(&mut graph, gbuffer, name, format, initial)
    };
    let sampled = Access::FragmentSampledRead;
    let shadow_map = import("host shadow map", desc.shadow_format, sampled);
    let second_shadow_map = desc
        .second_shadow_format
        .map(|format| import("host second shadow map", format, sampled));
    let depth = import("host depth", gbuffer.depth.format, sampled);
    let normal_format = gbuffer.normals.expect("checked at new").format;
    let normals = import("host normals", normal_format, sampled);
    let ids_format = gbuffer.material_ids.expect("checked at new").format;
    let material_ids = import("host material IDs", ids_format, sampled);
    let albedo = reads_albedo.then(|| {
        import(
            "host albedo",
            gbuffer.albedo.expect("checked at new"),
            sampled,
        )
    });
    let mut lighting = import(
        "host lighting",
        gbuffer.diffuse.format,
        Access::ColorAttachmentWrite,
    );
    let imports = Imports {
        depth: depth.id(),
        normals: normals.id(),
        material_ids: material_ids.id(),
        albedo: albedo.as_ref().map(|a| a.id()),
        shadow_map: shadow_map.id(),
        second_shadow_map: second_shadow_map.as_ref().map(|m| m.id()),
        lighting: lighting.id(),
    };
    let mut pass = FullscreenPass::new(&mut graph, "host transmission", FRAGMENT, Some(scene_gpu));
    pass.per_frame(&FRAME)
        .per_frame(&MEDIA)
        .per_frame(&HOST_TRANSMISSION)
        .per_frame(&SHADOWS)
        .sample("shadow_depth", &shadow_map)
        .sample("depth_image", &depth)
        .sample("normal_image", &normals)
        .sample("id_image", &material_ids);
    if let Some(albedo) = &albedo {
        pass.sample("albedo_image", albedo);
    }
    if let Some(map) = &second_shadow_map {
        pass.sample("shadow_layers", map);
    }
    pass.defines(&defines(uint_ids, reads_albedo, shadow_maps))
        .tiles(|scene, ctx| {
            let regions = &scene.per_frame.tiles(ctx.frame).lighting;
            (!regions.is_empty()).then(|| regions.clone())
        })
        .color_add(&mut lighting, LoadOp::Load);
    pass.finish();
    graph.export_image(&lighting, Access::ColorAttachmentWrite);
    (graph, imports)
}

// Effects move to a loader thread and back.
const _: () = {
    const fn send<T: Send>() {}
    send::<TransmissionEffect>();
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::layered::LayeredMedium;

    fn skin() -> TransmissionMaterial {
        TransmissionMaterial::new(3, Medium::new(LayeredMedium::preset("skin1").unwrap()))
    }

    /// A host's lighting pass reads the rows lucent's own frames read, in the host's unit:
    /// millimetres per unit from `metres_per_unit`, the rest of the medium unchanged.
    #[test]
    fn the_rows_a_host_reads_are_lucents_in_the_hosts_unit() {
        let material = skin();
        let metres = material.rows(1.0).unwrap();
        let centimetres = material.rows(0.01).unwrap();
        let lucent = SssTransmission {
            mm_per_unit: 1000.0,
            ..SssTransmission::of(&material.medium)
        }
        .rows();
        assert_eq!(metres, lucent);
        assert_eq!(metres[0][3], 1000.0);
        assert!((centimetres[0][3] - 10.0).abs() < 1e-5);
        assert_eq!(metres[1..], centimetres[1..]);
        assert!(metres.iter().flatten().all(|v| v.is_finite()));
    }

    /// A unit no f32 shader can multiply a thickness by is refused, naming the field.
    #[test]
    fn rows_refuse_a_unit_that_is_not_a_length() {
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, 2e9] {
            let message = skin().rows(bad).unwrap_err().to_string();
            assert!(message.contains("metres_per_unit"), "{bad}: {message}");
        }
        assert!(skin()
            .rows(1e9)
            .unwrap()
            .iter()
            .flatten()
            .all(|v| v.is_finite()));
    }
}
