//! A host engine's own deferred lighting pass, for `lucent bench --embed` to time what one of
//! lucent's lighting terms costs a host that adds it in its own lighting through
//! `lucent::embed::glsl::TERMS` (the way docs/embedding.md recommends for the translucency,
//! environment and transmission terms), beside what the term costs inside lucent's own
//! lighting pass.
//!
//! The pass (`glsl/bench/host_lighting.frag`) reads a host G-buffer (device depth, world
//! normals, albedo), loops over the lights (Lambert) and, in its term's variant, calls the
//! term's `TERMS` functions with the data the Rust API hands a host
//! ([`crate::embed::TranslucentMaterial::row`], [`crate::scene::Environment::coefficients`],
//! [`crate::embed::TransmissionMaterial::rows`], [`crate::embed::ShadowFace::terms_rows`]).
//! It is recorded twice a frame, as two passes of one graph:
//! - `host lighting`: the plain variant over the whole screen;
//! - `host lighting with the term`: the term's variant in the screen tiles the host's regions
//!   touch (for the environment, which every surface has, the whole screen) and the plain
//!   variant in the others, as lucent's own lighting pass draws its translucent variant.
//!
//! Their difference is what the term costs the host, measured as lucent's own is (its lighting
//! pass with the term minus without). The passes run on lucent's effect machinery
//! (`EffectPasses`: the host's images bound when recorded, a per-frame
//! buffer), which is the benchmark's host's plumbing, not part of what is compared.

use std::sync::Arc;

use ash::vk;

use crate::backend::access::Access;
use crate::embed::image::{HostImage, Role};
use crate::embed::passes::{import_host_image, EffectPasses};
use crate::embed::{EffectTimer, GBufferDesc, HostCamera, Lucent, Uploads};
use crate::features::copy_pass::{HostTerm, HOST_LIGHTING_FRAGMENT};
use crate::features::pass::FullscreenPass;
use crate::features::shadows::MAX_SHADOW_FACES;
use crate::gpu_scene::{Region, SceneGpu, SceneUpload, TableRegion};
use crate::graph::{LoadOp, RenderGraph, ResourceId};
use crate::scene::{Light, MAX_LIGHTS};
use crate::{LucentError, Result};

/// Material IDs whose medium the transmission variant holds (the shader's
/// `BENCH_MAX_MEDIA`).
pub const MAX_MEDIA: usize = 32;

/// The pass of the plain lighting over the whole screen (its name in the timings).
pub const PLAIN_PASS: &str = "host lighting";
/// The pass with the term's variant where the term's objects are.
pub const TERM_PASS: &str = "host lighting with the term";

/// The shader's constants (`BenchHostLighting`, std140).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct HostLightingGpu {
    clip_to_world: [[f32; 4]; 4],
    eye: [f32; 4],
    ambient: [f32; 4],
    counts: [i32; 4],
    lights: [[[f32; 4]; 4]; MAX_LIGHTS],
    light_faces: [[i32; 4]; MAX_LIGHTS],
    sh: [[f32; 4]; 9],
    rows: [[f32; 4]; 256],
    media: [[[f32; 4]; 4]; MAX_MEDIA],
    faces: [[[f32; 4]; 6]; MAX_SHADOW_FACES],
}

/// The constants in the per-frame buffer.
static HOST_LIGHTING: Region = Region::new("bench host lighting", "BenchHostLighting");

/// The term's data, as a host holds it.
pub enum TermData<'a> {
    /// GDC 2011 translucency: each material's row at its ID, and where the thickness target
    /// keeps the ID (its channel) and whether its thickness is rgb.
    Translucency {
        /// (ID, row) per material.
        rows: &'a [(u8, [f32; 4])],
        /// The ID's channel of the thickness target.
        id_channel: u32,
        /// The thickness is rgb (else the target's first channel).
        coloured: bool,
    },
    /// The SH environment's coefficients.
    Environment([[f32; 4]; 9]),
    /// SSS transmission: each medium's rows at its ID, and the shadow faces (each with its
    /// light's index) as the host's atlas holds them.
    Transmission {
        /// (ID, rows) per medium.
        media: &'a [(u8, [[f32; 4]; 4])],
        /// (light index, `ShadowFace::terms_rows`) per face, a light's faces together (a point
        /// light's six in lucent's order: +X, -X, +Y, -Y, +Z, -Z).
        faces: &'a [(usize, [[f32; 4]; 6])],
        /// The atlas's depth format.
        shadow_format: vk::Format,
    },
}

impl TermData<'_> {
    fn term(&self) -> HostTerm {
        match self {
            // The lobe's forms the materials use (a row's w: 0 exact, 1 exp2), as lucent's own
            // lighting compiles only those.
            TermData::Translucency { rows, .. } => {
                let exact = rows.iter().any(|(_, row)| row[3] < 0.5);
                let exp2 = rows.iter().any(|(_, row)| row[3] >= 0.5);
                HostTerm::Translucency {
                    pow_modes: u8::from(exact) + 2 * u8::from(exp2 || !exact),
                }
            }
            TermData::Environment(_) => HostTerm::Environment,
            TermData::Transmission { .. } => HostTerm::Transmission,
        }
    }
}

/// One frame of the host's lighting: its camera, lights, G-buffer and regions.
pub struct HostLightingFrame<'a> {
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The host's lights.
    pub lights: &'a [Light],
    /// The term's objects' screen bounds (empty: the whole screen).
    pub regions: &'a [vk::Rect2D],
    /// Device depth (standard Z).
    pub depth: &'a HostImage,
    /// World normals in xyz.
    pub normals: &'a HostImage,
    /// Albedo in rgb.
    pub albedo: &'a HostImage,
    /// Translucency: the thickness and ID target; transmission: the ID image (`k / 255`).
    pub ids: Option<&'a HostImage>,
    /// Transmission: the shadow atlas.
    pub shadow_map: Option<&'a HostImage>,
    /// What the lighting writes.
    pub lit: &'a HostImage,
}

/// The graph's imports.
struct Imports {
    depth: ResourceId,
    normals: ResourceId,
    albedo: ResourceId,
    ids: Option<ResourceId>,
    shadow_map: Option<ResourceId>,
    lit: ResourceId,
}

/// The host's lighting pass, plain and with one term (see the module docs).
pub struct HostLighting {
    passes: EffectPasses,
    imports: Imports,
    constants: Box<HostLightingGpu>,
}

impl HostLighting {
    /// The host's lighting on `gbuffer` (its diffuse format is the lit target's; it must
    /// describe its normals and albedo, and what the term reads) with `term`.
    pub fn new(
        lucent: &Lucent,
        uploads: &mut Uploads,
        gbuffer: &GBufferDesc,
        term: &TermData<'_>,
    ) -> Result<Self> {
        let mut constants: Box<HostLightingGpu> = bytemuck::zeroed_box();
        // A dim constant ambient: the host's own, which the environment variant replaces.
        constants.ambient = [0.03, 0.03, 0.03, 0.0];
        match term {
            TermData::Translucency {
                rows,
                id_channel,
                coloured,
            } => {
                for &(id, row) in rows.iter() {
                    constants.rows[usize::from(id)] = row;
                }
                constants.counts[1] = (*id_channel).min(3) as i32;
                constants.counts[2] = i32::from(*coloured);
            }
            TermData::Environment(sh) => constants.sh = *sh,
            TermData::Transmission { media, faces, .. } => {
                for &(id, rows) in media.iter() {
                    let slot = constants.media.get_mut(usize::from(id)).ok_or_else(|| {
                        LucentError::InvalidInput(format!(
                            "the benchmark's host lighting holds media of IDs below \
                             {MAX_MEDIA} (not {id})"
                        ))
                    })?;
                    *slot = rows;
                }
                if faces.len() > MAX_SHADOW_FACES {
                    return Err(LucentError::InvalidInput(format!(
                        "{} shadow faces; the benchmark's host lighting holds {MAX_SHADOW_FACES}",
                        faces.len()
                    )));
                }
                constants.light_faces = [[-1, 0, 0, 0]; MAX_LIGHTS];
                for (f, &(light, rows)) in faces.iter().enumerate() {
                    constants.faces[f] = rows;
                    if let Some(entry) = constants.light_faces.get_mut(light) {
                        if entry[1] == 0 {
                            entry[0] = f as i32;
                        }
                        entry[1] += 1;
                    }
                }
            }
        }
        let kind = term.term();
        let read = |what: &str, format: Option<vk::Format>| {
            format.ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "the benchmark's host lighting reads the G-buffer's {what}, which it does \
                     not describe"
                ))
            })
        };
        let formats = Formats {
            normals: read("normals", gbuffer.normals.map(|n| n.format))?,
            albedo: read("albedo", gbuffer.albedo)?,
            ids: match term {
                TermData::Translucency { .. } => {
                    Some(read("thickness", gbuffer.thickness.map(|t| t.format))?)
                }
                TermData::Transmission { .. } => Some(read(
                    "material IDs",
                    gbuffer.material_ids.map(|i| i.format),
                )?),
                TermData::Environment(_) => None,
            },
            shadow_map: match term {
                TermData::Transmission { shadow_format, .. } => Some(*shadow_format),
                _ => None,
            },
        };
        let upload = SceneUpload::tables_only(vec![TableRegion {
            region: &HOST_LIGHTING,
            bytes: std::mem::size_of::<HostLightingGpu>() as u64,
        }]);
        let (passes, imports) = EffectPasses::new(
            lucent,
            uploads,
            "the benchmark's host lighting",
            upload,
            1,
            |scene_gpu| declare(gbuffer, kind, &formats, scene_gpu),
        )?;
        Ok(Self {
            passes,
            imports,
            constants,
        })
    }

    /// Records one frame (slot 0): both passes, timed into `timer`.
    pub fn record_timed(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &HostLightingFrame<'_>,
        timer: &mut EffectTimer,
    ) -> Result<()> {
        let (camera, lights) = (&frame.camera, frame.lights);
        let ring = self.passes.slot(0, 0)?;
        let mut constants = self.constants.clone();
        constants.clip_to_world = (camera.projection * camera.view)
            .inverse()
            .to_cols_array_2d();
        constants.eye = camera.view.inverse().w_axis.to_array();
        for (slot, light) in constants.lights.iter_mut().zip(lights) {
            *slot = crate::gpu_scene::per_frame::light_rows(light);
        }
        constants.counts[0] = lights.len().min(MAX_LIGHTS) as i32;
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &HOST_LIGHTING, bytemuck::bytes_of(&*constants))?;
        per_frame.tiles(ring).lighting =
            crate::embed::regions::tiles_marked_by(frame.regions, frame.lit.extent);
        let mut binds = vec![
            (self.imports.depth, frame.depth),
            (self.imports.normals, frame.normals),
            (self.imports.albedo, frame.albedo),
            (self.imports.lit, frame.lit),
        ];
        let mut inputs = vec![frame.depth, frame.normals, frame.albedo];
        for (import, image, what) in [
            (self.imports.ids, frame.ids, "ID"),
            (self.imports.shadow_map, frame.shadow_map, "shadow map"),
        ] {
            if let Some(import) = import {
                let image = image.ok_or_else(|| {
                    LucentError::InvalidInput(format!("the host lighting's term reads its {what}"))
                })?;
                binds.push((import, image));
                inputs.push(image);
            }
        }
        self.passes.record(
            lucent,
            cmd,
            ring,
            &binds,
            &inputs,
            (frame.lit, Role::Output),
            Some(timer),
        )
    }

    /// Destroys the passes. The GPU must be done with them.
    pub fn destroy(self, lucent: &Lucent) {
        self.passes.destroy(lucent);
    }
}

/// The formats of the images the host lighting imports besides depth and the lit target.
struct Formats {
    normals: vk::Format,
    albedo: vk::Format,
    /// The translucency's thickness and ID target, or the transmission's ID image.
    ids: Option<vk::Format>,
    /// The transmission's shadow atlas.
    shadow_map: Option<vk::Format>,
}

/// The two passes over the host's imported images (see the module docs).
fn declare(
    gbuffer: &GBufferDesc,
    term: HostTerm,
    formats: &Formats,
    scene_gpu: &Arc<SceneGpu>,
) -> (RenderGraph, Imports) {
    let mut graph = RenderGraph::new();
    let sampled = Access::FragmentSampledRead;
    let mut import = |name: &str, format: vk::Format, initial: Access| {
        import_host_image(&mut graph, gbuffer, name, format, initial)
    };
    let depth = import("host depth", gbuffer.depth.format, sampled);
    let normals = import("host normals", formats.normals, sampled);
    let albedo = import("host albedo", formats.albedo, sampled);
    let ids = formats
        .ids
        .map(|format| import("host thickness or IDs", format, sampled));
    let shadow_map = formats
        .shadow_map
        .map(|format| import("host shadow map", format, sampled));
    let mut lit = import(
        "host lit",
        gbuffer.diffuse.format,
        Access::ColorAttachmentWrite,
    );
    let imports = Imports {
        depth: depth.id(),
        normals: normals.id(),
        albedo: albedo.id(),
        ids: ids.as_ref().map(|i| i.id()),
        shadow_map: shadow_map.as_ref().map(|m| m.id()),
        lit: lit.id(),
    };
    for with_term in [false, true] {
        let name = if with_term { TERM_PASS } else { PLAIN_PASS };
        let mut pass =
            FullscreenPass::new(&mut graph, name, HOST_LIGHTING_FRAGMENT, Some(scene_gpu));
        pass.per_frame(&HOST_LIGHTING)
            .sample("depth_image", &depth)
            .sample("normal_image", &normals)
            .sample("albedo_image", &albedo);
        match (with_term, term) {
            (false, _) => {
                pass.defines(HostTerm::None.defines());
            }
            // Every surface has the environment's light: the whole screen.
            (true, HostTerm::Environment) => {
                pass.defines(term.defines());
            }
            (true, _) => {
                if let Some(ids) = &ids {
                    let name = if matches!(term, HostTerm::Translucency { .. }) {
                        "thickness_image"
                    } else {
                        "id_image"
                    };
                    pass.sample(name, ids);
                }
                if let Some(map) = &shadow_map {
                    pass.sample("shadow_map", map);
                }
                pass.defines(HostTerm::None.defines())
                    .marked_variant(term.defines().to_vec())
                    .tiles(|scene, ctx| {
                        let tiles = &scene.per_frame.tiles(ctx.frame).lighting;
                        (!tiles.is_empty()).then(|| tiles.clone())
                    });
            }
        }
        // Each pass writes every pixel; the first's result is not read, and is kept.
        pass.color(&mut lit, LoadOp::DontCare)
            .graph()
            .side_effects();
        pass.finish();
    }
    graph.export_image(&lit, Access::ColorAttachmentWrite);
    (graph, imports)
}
