//! [`TranslucencyEffect`]: GDC 2011 thickness-based translucency (Frostbite 2, Barré-Brisebois
//! and Bouchard) inserted into a host's frame, on the host's own G-buffer ([`GBufferDesc`]),
//! lit by the host's lights.
//!
//! The host renders its G-buffer and lighting as usual and keeps, per pixel, a material ID and
//! a local thickness (GDC 2011's "inverted ambient occlusion", baked per vertex by
//! [`bake_thickness`] and carried through the host's vertex buffers, or from a thickness
//! texture). lucent adds the talk's per-light term for every pixel whose ID is one of the
//! effect's [`TranslucentMaterial`]s, blended additively into the host's lit diffuse light
//! (its contents are kept): the same term, from the same GLSL (`translucency_transmitted` in
//! `glsl/common/translucency.glsl`), that lucent's own lighting pass adds. Recorded before an
//! [`super::SssEffect`] on the same light, the blur also diffuses the light let through thin
//! parts, as lucent's own frames do.
//!
//! The talk's term is unshadowed (the local thickness is its only attenuation); lucent's
//! `shadowed` extension needs lucent's light-space maps and is refused here.
//!
//! The host's encodings reach one shader (`glsl/deferred/host_translucency.frag`) as a
//! permutation (unsigned or UNORM IDs) and per-frame constants (the ID bit field, the normal
//! encoding and space, the thickness channels, the depth decode): no copy into lucent's layout.

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::image::{distinct_inputs, HostImage, Role};
use super::passes::{
    check_described, check_lights, check_views, depth_role, id_role, import_host_image,
    EffectPasses,
};
use super::regions::clipped;
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::backend::shader::PipelineShaders;
use crate::error::HostError;
use crate::features::capabilities::{require, Effect};
use crate::features::gbuffer_desc::{DepthEncoding, GBufferDesc, HostCamera};
use crate::features::pass::FullscreenPass;
use crate::features::translucency::{material_row, MaterialTableGpu, TABLE_REGION};
use crate::gpu_scene::{Region, SceneGpu, SceneUpload, TableRegion, FRAME};
use crate::graph::{LoadOp, RenderGraph, ResourceId};
use crate::scene::material::{PowMode, Translucency};
use crate::scene::{Light, Mesh};
use crate::Result;

/// The effect's fragment shader.
const FRAGMENT: &str = "deferred/host_translucency.frag";

/// One translucent material of the host: its ID in the host's material ID image and the
/// talk's per-material parameters. The per-pixel part of the term (the local thickness, tinted
/// by the material's colour where it has one) is the host's thickness image; the per-light
/// scale (`fLTScale`) is [`Light::translucency_scale`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct TranslucentMaterial {
    /// The host's ID (1 to 255; 0 is taken to mean "not translucent").
    pub id: u8,
    /// `iLTPower`: the sharpness of the view-dependent back-lighting lobe (>= 0).
    pub power: f32,
    /// `fLTDistortion`: how much the normal bends the inverted light vector.
    pub distortion: f32,
    /// `fLTAmbient`: translucency visible from every angle (>= 0).
    pub ambient: f32,
    /// The exact `pow` or the spherical-Gaussian `exp2` form of the lobe.
    pub pow_mode: PowMode,
}

impl TranslucentMaterial {
    /// Material `id` with the talk's power, distortion and ambient, the exact `pow`.
    pub fn new(id: u8, power: f32, distortion: f32, ambient: f32) -> Self {
        Self {
            id,
            power,
            distortion,
            ambient,
            pow_mode: PowMode::Exact,
        }
    }

    /// With the lobe's pow form.
    pub fn with_pow_mode(mut self, pow_mode: PowMode) -> Self {
        self.pow_mode = pow_mode;
        self
    }

    /// Material `id` with a lucent material's translucency parameters (a scene file's
    /// `[material.translucency]`, or [`crate::scene::material::Medium::translucency`]). Its
    /// colour, thickness source and medium extinction are per-pixel data the host writes into
    /// its thickness image (thickness times colour; for a medium, its transmittance through
    /// the baked distance), as lucent's own G-buffer does. Refused when `shadowed`: that needs
    /// lucent's light-space maps.
    pub fn from_translucency(id: u8, translucency: &Translucency) -> Result<Self> {
        if translucency.shadowed {
            return Err(HostError::Unsupported {
                input: format!("translucent material {id}"),
                found: "shadowed = true".into(),
                accepted: "the talk's unshadowed term (shadowed = false): shadows on the light \
                           let through need lucent's own light-space maps"
                    .into(),
            }
            .into());
        }
        Ok(Self {
            id,
            power: translucency.power,
            distortion: translucency.distortion,
            ambient: translucency.ambient,
            pow_mode: translucency.pow_mode,
        })
    }

    /// The material's row as the shaders read it (x power, y distortion, z ambient, w the pow
    /// form: 0 exact, 1 exp2): what a host passes to `lucent_translucency` in its own
    /// lighting pass ([`super::glsl::TERMS`]), lucent's `features::translucency::material_row`.
    pub fn row(&self) -> [f32; 4] {
        material_row(&Translucency {
            power: self.power,
            distortion: self.distortion,
            ambient: self.ambient,
            pow_mode: self.pow_mode,
            shadowed: false,
            ..Translucency::new(crate::scene::material::ThicknessSource::Bake)
        })
    }

    fn check(&self, index: usize) -> Result<()> {
        let field = format!("materials[{index}] (ID {})", self.id);
        let bad = |problem: String| -> crate::LucentError {
            HostError::Description {
                field: field.clone(),
                problem,
            }
            .into()
        };
        if self.id == 0 {
            return Err(bad("IDs are 1 to 255 (0: not translucent)".into()));
        }
        // A NaN or negative power would make the lobe NaN or unbounded (pow(x, -n) at x -> 0).
        if !(self.power.is_finite() && self.power >= 0.0 && self.power <= 1e4) {
            return Err(bad(format!("power {} must be in [0, 10000]", self.power)));
        }
        if !(self.distortion.is_finite() && self.distortion.abs() <= 1e4) {
            return Err(bad(format!(
                "distortion {} must be finite (|d| <= 10000)",
                self.distortion
            )));
        }
        if !(self.ambient.is_finite() && self.ambient >= 0.0 && self.ambient <= 1e4) {
            return Err(bad(format!(
                "ambient {} must be in [0, 10000]",
                self.ambient
            )));
        }
        Ok(())
    }
}

/// What a [`TranslucencyEffect`] is built for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct TranslucencyEffectDesc {
    /// The host's G-buffer: it must describe its normals, albedo, thickness and material IDs.
    /// The diffuse format is the format of the light the term is added to.
    pub gbuffer: GBufferDesc,
    /// The translucent materials (1 to 255 of them).
    pub materials: Vec<TranslucentMaterial>,
    /// Views recorded per frame (1 to [`super::MAX_VIEWS_PER_FRAME`]).
    pub views_per_frame: usize,
}

impl TranslucencyEffectDesc {
    /// The effect over `gbuffer` for `materials`, one view a frame.
    pub fn new(gbuffer: GBufferDesc, materials: Vec<TranslucentMaterial>) -> Self {
        Self {
            gbuffer,
            materials,
            views_per_frame: 1,
        }
    }

    /// With this many views per frame.
    pub fn with_views_per_frame(mut self, views: usize) -> Self {
        self.views_per_frame = views;
        self
    }
}

/// The host's G-buffer images for one view of one frame, each with its current and final
/// state.
#[derive(Clone, Copy, Debug)]
pub struct TranslucencyImages<'a> {
    /// The depth image (a depth format's view of its depth aspect, or linear depth).
    pub depth: &'a HostImage,
    /// The normals.
    pub normals: &'a HostImage,
    /// The albedo.
    pub albedo: &'a HostImage,
    /// The local thickness (it may be the same image as the material IDs, a packed target).
    pub thickness: &'a HostImage,
    /// The material IDs (for stencil bits: a view of the depth-stencil image's stencil
    /// aspect).
    pub material_ids: &'a HostImage,
}

/// One view of one frame: what [`TranslucencyEffect::record`] reads and adds to.
#[derive(Clone, Copy, Debug)]
pub struct TranslucencyFrame<'a> {
    /// The frame-in-flight slot (0 to the frames in flight of the [`Lucent`]).
    pub slot: usize,
    /// The view within the frame.
    pub view: usize,
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The host's lights this frame, in its world (at most [`crate::scene::MAX_LIGHTS`]). Their
    /// `shadows` flag does not apply: the talk's term is unshadowed.
    pub lights: &'a [Light],
    /// The G-buffer's images.
    pub images: TranslucencyImages<'a>,
    /// Screen rectangles the translucent materials may cover this frame (say, their
    /// objects' projected bounds): the pass draws only inside them, as lucent's own lighting
    /// pass runs the term only on the tiles translucent objects cover. Empty: the whole
    /// screen. Clipped to the G-buffer.
    pub regions: &'a [vk::Rect2D],
    /// The host's lit diffuse light, which the term is added to (a colour attachment of the
    /// description's diffuse format that can be blended; its contents are kept, so it cannot
    /// come in UNDEFINED).
    pub lighting: &'a HostImage,
}

/// The effect's per-frame constants (glsl/deferred/host_translucency.frag `HostTranslucency`,
/// std140).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HostTranslucencyGpu {
    ids: [u32; 4],
    normals: [u32; 4],
    thickness: [u32; 4],
    depth: [u32; 4],
    translucent: [[u32; 4]; 2],
    view_to_world: [[f32; 4]; 4],
}

/// The effect's constants in the per-frame buffer.
static HOST_TRANSLUCENCY: Region = Region::new("host translucency decode", "HostTranslucency");

/// The graph's imports, by input.
#[derive(Clone, Copy, Debug)]
struct Imports {
    depth: ResourceId,
    normals: ResourceId,
    albedo: ResourceId,
    thickness: ResourceId,
    material_ids: ResourceId,
    lighting: ResourceId,
}

/// GDC 2011 translucency on a host's G-buffer (see the module docs).
pub struct TranslucencyEffect {
    passes: EffectPasses,
    imports: Imports,
    desc: TranslucencyEffectDesc,
    /// The constants every frame shares; each frame adds its view.
    constants: HostTranslucencyGpu,
}

/// The shader defines of a host's ID image (unsigned or UNORM).
fn defines(uint_ids: bool) -> &'static [(&'static str, &'static str)] {
    if uint_ids {
        &[("LUCENT_HOST_IDS_UINT", "1")]
    } else {
        &[]
    }
}

/// Every pipeline the effect may build, for the shipped SPIR-V.
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for uint in [false, true] {
        out.push(PipelineShaders::fullscreen(FRAGMENT, defines(uint)));
    }
}

impl TranslucencyEffect {
    /// Builds the effect for `desc`, checking all of it first. Its tables are written into
    /// lucent's own host-visible per-frame buffer: nothing is recorded into `uploads`,
    /// submitted or waited for (`uploads` is taken so that every effect is built alike).
    pub fn new(
        lucent: &Lucent,
        uploads: &mut Uploads,
        desc: TranslucencyEffectDesc,
    ) -> Result<Self> {
        let gbuffer = &desc.gbuffer;
        gbuffer.check()?;
        require(Effect::Translucency, gbuffer)?;
        let (Some(ids), Some(normals), Some(thickness)) =
            (gbuffer.material_ids, gbuffer.normals, gbuffer.thickness)
        else {
            unreachable!("missing() lists each input the effect reads");
        };
        check_views(desc.views_per_frame)?;
        if desc.materials.is_empty() {
            return Err(HostError::Description {
                field: "materials".into(),
                problem: "no translucent material: 1 to 255 are supported".into(),
            }
            .into());
        }
        let id_map = ids.decode(Vec::new())?;
        let mut table = MaterialTableGpu {
            rows: [[0.0; 4]; 256],
        };
        let mut translucent = [[0u32; 4]; 2];
        for (index, material) in desc.materials.iter().enumerate() {
            material.check(index)?;
            let id = usize::from(material.id);
            let word = &mut translucent[id / 128][(id / 32) % 4];
            if *word & (1 << (id % 32)) != 0 || u32::from(material.id) > id_map.mask {
                return Err(HostError::Description {
                    field: format!("materials[{index}] (ID {})", material.id),
                    problem: "each ID once, and within the material ID image's bit field".into(),
                }
                .into());
            }
            *word |= 1 << (id % 32);
            table.rows[id] = material.row();
        }
        let constants = HostTranslucencyGpu {
            ids: [id_map.channel, id_map.shift, id_map.mask, id_map.unorm_max],
            normals: normals.decode()?,
            thickness: thickness.decode()?,
            depth: [
                u32::from(gbuffer.depth.encoding == DepthEncoding::LinearView),
                0,
                0,
                0,
            ],
            translucent,
            view_to_world: glam::Mat4::IDENTITY.to_cols_array_2d(),
        };
        let upload = SceneUpload::tables_only(vec![
            crate::features::translucency::table_region(),
            TableRegion {
                region: &HOST_TRANSLUCENCY,
                bytes: std::mem::size_of::<HostTranslucencyGpu>() as u64,
            },
        ]);
        let (passes, imports) = EffectPasses::new(
            lucent,
            uploads,
            "TranslucencyEffect",
            upload,
            desc.views_per_frame,
            |scene_gpu| declare(&desc, id_map.uint, scene_gpu),
        )?;
        let out = Self {
            passes,
            imports,
            desc,
            constants,
        };
        // The material table does not change between frames: written once into every slot.
        for slot in 0..out.passes.slots() {
            let per_frame = out.passes.per_frame();
            let written = per_frame.write(slot, &TABLE_REGION, bytemuck::bytes_of(&table));
            if let Err(e) = written {
                out.destroy(lucent);
                return Err(e);
            }
        }
        Ok(out)
    }

    super::passes::effect_methods!(
        TranslucencyFrame,
        "the talk's term from `frame.lights` added to `frame.lighting`"
    );

    fn record_with(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &TranslucencyFrame<'_>,
        timer: Option<&mut super::EffectTimer>,
    ) -> Result<()> {
        let ring = self.passes.slot(frame.slot, frame.view)?;
        check_lights(frame.lights)?;
        let gbuffer = &self.desc.gbuffer;
        let uniforms = gbuffer
            .view_uniforms(&frame.camera)?
            .with_lights(frame.lights);
        let inputs = self.check_images(lucent, frame)?;
        let constants = HostTranslucencyGpu {
            view_to_world: frame.camera.view.inverse().to_cols_array_2d(),
            ..self.constants
        };
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &FRAME, bytemuck::bytes_of(&uniforms))?;
        per_frame.write(ring, &HOST_TRANSLUCENCY, bytemuck::bytes_of(&constants))?;
        // The pass draws in the `lighting` tiles of the slot (none: the whole screen).
        per_frame.tiles(ring).lighting = clipped(frame.regions, gbuffer.extent());
        let images = &frame.images;
        let binds = [
            (self.imports.depth, images.depth),
            (self.imports.normals, images.normals),
            (self.imports.albedo, images.albedo),
            (self.imports.thickness, images.thickness),
            (self.imports.material_ids, images.material_ids),
            (self.imports.lighting, frame.lighting),
        ];
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
    /// distinct Vulkan image.
    fn check_images<'a>(
        &self,
        lucent: &Lucent,
        frame: &TranslucencyFrame<'a>,
    ) -> Result<Vec<&'a HostImage>> {
        let gbuffer = &self.desc.gbuffer;
        let images = &frame.images;
        let ids = gbuffer.material_ids.expect("checked at new");
        let depth_role = depth_role(gbuffer);
        let id_role = id_role(&ids);
        let described = |f: Option<vk::Format>| f.expect("checked at new");
        check_described(
            lucent,
            gbuffer.extent(),
            &[
                (images.depth, "depth", depth_role, gbuffer.depth.format),
                (
                    images.normals,
                    "normals",
                    Role::SampledColor,
                    described(gbuffer.normals.map(|n| n.format)),
                ),
                (
                    images.albedo,
                    "albedo",
                    Role::SampledColor,
                    described(gbuffer.albedo),
                ),
                (
                    images.thickness,
                    "thickness",
                    Role::SampledColor,
                    described(gbuffer.thickness.map(|t| t.format)),
                ),
                (images.material_ids, "material IDs", id_role, ids.format),
                (
                    frame.lighting,
                    "lighting",
                    Role::Accumulate,
                    gbuffer.diffuse.format,
                ),
            ],
        )?;
        distinct_inputs(
            [
                images.depth,
                images.normals,
                images.albedo,
                images.thickness,
                images.material_ids,
            ],
            frame.lighting,
        )
    }
}

/// The effect's graph: the host's images imported (bound when each frame records) and one
/// fullscreen pass adding the term to the host's light.
fn declare(
    desc: &TranslucencyEffectDesc,
    uint_ids: bool,
    scene_gpu: &Arc<SceneGpu>,
) -> (RenderGraph, Imports) {
    let gbuffer = &desc.gbuffer;
    let mut graph = RenderGraph::new();
    let mut import = |name: &str, format: vk::Format, initial: Access| {
        import_host_image(&mut graph, gbuffer, name, format, initial)
    };
    let sampled = Access::FragmentSampledRead;
    let described = |f: Option<vk::Format>| f.expect("checked at new");
    let depth = import("host depth", gbuffer.depth.format, sampled);
    let normals = import(
        "host normals",
        described(gbuffer.normals.map(|n| n.format)),
        sampled,
    );
    let albedo = import("host albedo", described(gbuffer.albedo), sampled);
    let thickness = import(
        "host thickness",
        described(gbuffer.thickness.map(|t| t.format)),
        sampled,
    );
    let ids_format = gbuffer.material_ids.expect("checked at new").format;
    let material_ids = import("host material IDs", ids_format, sampled);
    let mut lighting = import(
        "host lighting",
        gbuffer.diffuse.format,
        Access::ColorAttachmentWrite,
    );
    let imports = Imports {
        depth: depth.id(),
        normals: normals.id(),
        albedo: albedo.id(),
        thickness: thickness.id(),
        material_ids: material_ids.id(),
        lighting: lighting.id(),
    };
    let mut pass = FullscreenPass::new(&mut graph, "host translucency", FRAGMENT, Some(scene_gpu));
    pass.per_frame(&FRAME)
        .per_frame(&TABLE_REGION)
        .per_frame(&HOST_TRANSLUCENCY)
        .sample("depth_image", &depth)
        .sample("normal_image", &normals)
        .sample("albedo_image", &albedo)
        .sample("thickness_image", &thickness)
        .sample("id_image", &material_ids)
        .defines(defines(uint_ids))
        .tiles(|scene, ctx| {
            let regions = &scene.per_frame.tiles(ctx.frame).lighting;
            (!regions.is_empty()).then(|| regions.clone())
        })
        .color_add(&mut lighting, LoadOp::Load);
    pass.finish();
    graph.export_image(&lighting, Access::ColorAttachmentWrite);
    (graph, imports)
}

/// GDC 2011's local thickness baked per vertex of a host's mesh (its positions, unit normals
/// and triangle-list indices, counter-clockwise seen from outside), for the host to carry
/// through its vertex buffers into its thickness image, as lucent bakes its own meshes but
/// with 1024 rays per vertex (lucent's own default is 256; a host bakes once, and a short
/// `max_distance` shows the noise of fewer): the cosine-weighted fraction of the rays into the mesh that meet its
/// other side within `max_distance` (1 thin, 0 thick). `max_distance` is in the mesh's units:
/// the thickness past which a part reads as opaque (`None`: the mesh's bounding-box diagonal,
/// which makes every part of a closed mesh thinner than its size read as thin). A malformed
/// mesh (indices out of range, non-finite positions, mismatched counts) or a distance that is
/// not finite and positive is an error naming the problem.
pub fn bake_thickness(
    positions: &[Vec3],
    normals: &[Vec3],
    indices: &[u32],
    max_distance: Option<f32>,
) -> Result<Vec<f32>> {
    if let Some(d) = max_distance {
        if !(d.is_finite() && d > 0.0) {
            return Err(HostError::Description {
                field: "max_distance".into(),
                problem: format!("{d} must be a finite distance > 0"),
            }
            .into());
        }
    }
    let mesh = Mesh {
        positions: positions.to_vec(),
        normals: normals.to_vec(),
        uvs: Vec::new(),
        tangents: Vec::new(),
        colors: Vec::new(),
        indices: indices.to_vec(),
        shape: None,
    };
    mesh.validate("the host's mesh")?;
    let options = crate::bake::BakeOptions {
        max_distance,
        rays: 1024,
        ..Default::default()
    };
    let (values, _) = crate::bake::bake_per_vertex(&mesh, &options)?;
    Ok(values)
}

// Effects move to a loader thread and back.
const _: () = {
    const fn send<T: Send>() {}
    send::<TranslucencyEffect>();
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn materials_out_of_range_are_refused_and_shadowed_ones_named() {
        TranslucentMaterial::new(3, 12.0, 0.2, 0.0)
            .check(0)
            .unwrap();
        for bad in [
            TranslucentMaterial::new(0, 12.0, 0.2, 0.0),
            TranslucentMaterial::new(1, f32::NAN, 0.2, 0.0),
            TranslucentMaterial::new(1, -1.0, 0.2, 0.0),
            TranslucentMaterial::new(1, 12.0, f32::INFINITY, 0.0),
            TranslucentMaterial::new(1, 12.0, 0.2, -0.5),
        ] {
            assert!(bad.check(2).is_err(), "{bad:?}");
        }
        let shadowed = Translucency {
            shadowed: true,
            ..Translucency::new(crate::scene::material::ThicknessSource::Bake)
        };
        let e = TranslucentMaterial::from_translucency(4, &shadowed).unwrap_err();
        assert!(e.to_string().contains("shadowed"), "{e}");
    }

    #[test]
    fn a_materials_row_is_lucents_own() {
        let t = Translucency {
            power: 7.0,
            distortion: 0.3,
            ambient: 0.1,
            pow_mode: PowMode::SphericalGaussianScaled,
            ..Translucency::new(crate::scene::material::ThicknessSource::Bake)
        };
        let m = TranslucentMaterial::from_translucency(9, &t).unwrap();
        assert_eq!(m.row(), material_row(&t));
    }

    #[test]
    fn a_host_mesh_bakes_and_a_broken_one_is_an_error() {
        let mesh = Mesh::generate(crate::scene::Shape::Sphere { radius: 1.0 }, 8, 6);
        let values = bake_thickness(&mesh.positions, &mesh.normals, &mesh.indices, None).unwrap();
        assert_eq!(values.len(), mesh.positions.len());
        assert!(values.iter().all(|v| (0.0..=1.0).contains(v)));
        // A unit sphere's chords are up to 2 long: within 0.5, most inward rays find no other
        // side (thick), within the diagonal every one does (thin).
        let short =
            bake_thickness(&mesh.positions, &mesh.normals, &mesh.indices, Some(0.5)).unwrap();
        let mean = |v: &[f32]| v.iter().sum::<f32>() / v.len() as f32;
        assert!(
            mean(&short) < 0.5 && mean(&values) > 0.9,
            "{} {}",
            mean(&short),
            mean(&values)
        );
        let mut indices = mesh.indices.clone();
        indices[0] = 1_000_000;
        assert!(bake_thickness(&mesh.positions, &mesh.normals, &indices, None).is_err());
        assert!(bake_thickness(
            &mesh.positions,
            &mesh.normals,
            &mesh.indices,
            Some(f32::NAN)
        )
        .is_err());
    }
}
