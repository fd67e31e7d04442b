//! Li et al. 2009: layered media shaded as Li et al.'s eq. 3,
//! `L = λ1 L_d + λ2 L_s + λ3 L_t + λ4 L_ss + λ5 L_ms`, in image space.
//!
//! - `L_d`, `L_s`: the deferred lighting's diffuse and specular. The G-buffer pass writes a
//!   layered object's albedo times `λ1` and its specular intensity times `λ2` (lighting is
//!   linear in both, so this is exactly eq. 3's weighting, at no cost).
//! - `layered irradiance`: the light transmitted into the surface per pixel,
//!   `E = Σ_lights V T(cos, eta) radiance falloff cos` (shadowed) plus the ambient's
//!   `pi L_a c` (`c`: the share of a white sky the boundary lets in), at full or half resolution
//!   (`layered.irradiance`).
//! - `single scattering` (eqs. 4-11): the view ray refracted at the surface and marched `K`
//!   steps up to `D_max / (N . T)`; at each step `M` the light's entry point `P'` comes from
//!   the light-space map (its distance, and the entry normal and layered material stored with
//!   it in `light-space.entry`), attenuated by the planar-layer optical depth with extinction
//!   `sigma_t`, times `sigma_s`, the phase function (true Henyey-Greenstein or Schlick's form)
//!   and the light's radiance at `P'`. A light without a map takes the surface at the pixel as
//!   a plane. One map lookup per light and pixel (at the middle of the march): each step's
//!   entry point is where its ray to the light crosses that entry surface's tangent plane.
//!   The same pass adds `L_t`.
//! - `L_t`, "refraction light" (the paper's text is garbled there): we read it as light that
//!   crossed the object without scattering, from where it entered on the light's side (`P'`,
//!   from the map) to the shaded point on the far side, leaving it diffusely:
//!   `L_t = T(x_o) / pi Σ_lights T(P') E(P') exp(-tau(P' -> x_o))`, for points facing away from
//!   the light (a lit point is its own entry point: its light is `L_d`'s).
//! - `multiple scattering` (eqs. 12-13): Jensen's dipole of the first layer (the corrected
//!   form, `d_r` in the real source's exponential) gathered over `M` pixel lights of the
//!   irradiance image: samples on a disc in the tangent plane (radius from the slowest
//!   channel's `1 / sigma_tr`), importance-sampled in radius, each projected to the screen and
//!   weighted by `Rd(r)` with `r` from the reconstructed world positions and its area; samples
//!   on other materials or off screen are rejected and the weights renormalised (the
//!   weighted mean of the accepted samples' `E` times the dipole's total reflectance, so a
//!   uniformly lit surface gets exactly `E R_d,total`: energy normalised); times
//!   `T(x_o) / pi`.
//! - `multiple scattering blur`: the gathered term's texels of a medium that diffuses far on
//!   screen become the mean of the 3x3 of their material and depth around them, which single
//!   scattering resolves: half the sampling grain left, where the term has no detail at that
//!   scale (glsl/layered/term_blur.frag).
//!
//! Both scattering passes add into the lit image (after the SSS blurs, which layered pixels
//! are not part of) and draw only the screen rectangles layered objects may cover. A frame
//! without layered materials has none of this: no pass, no image, no table, no G-buffer
//! target, no light-space entry target. The f64 twin of every term is
//! [`crate::reference::layered`].

use std::sync::Arc;

use ash::vk;

use super::knob::Knob;
use super::pass::FullscreenPass;
use super::shadows::{self, ShadowMaps};
use super::technique::{PartKind, TechniqueModule};
use crate::gpu_scene::{Region, SceneGpu, TableRegion, TileRect, FRAME};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, RenderGraph};
use crate::scene::layered::{AlbedoSplit, LayeredMedium, Thickness, MAX_LAYERS};
use crate::scene::Scene;
use crate::{LucentError, Result};

pub mod knobs;
mod part;
pub mod settings;

pub use knobs::{
    GATHER_KNOB, HALF_IRRADIANCE_KNOB, PHASE_KNOB, PIXEL_LIGHTS_KNOB, SINGLE_DEPTH_KNOB, STEPS_KNOB,
};
pub use part::{LayeredPart, LAYERED_PART};
pub use settings::{LayeredKnobs, PhaseForm, PIXEL_LIGHT_RANGE, STEP_RANGE};

/// The transmitted irradiance image.
pub const IRRADIANCE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Layered materials a frame holds at most (IDs 1 to 16).
pub const MAX_LAYERED_MATERIALS: usize = 16;

/// The layered part of a frame: its materials (ID = index + 1) and each object's ID.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredDesc {
    /// The distinct layered media, in order of first use.
    pub materials: Vec<LayeredMedium>,
    /// Per scene object: its layered material ID (0: not layered).
    pub object_ids: Vec<u8>,
    /// Some layered object's material has an albedo texture: the G-buffer stores the texel
    /// beside the ID and single scattering multiplies the light leaving the surface by it (a
    /// pigment film, the screen-space blurs' `post` texturing); without one, none of that.
    pub film: bool,
    /// Each material's [`AlbedoSplit`], computed once here (about 0.3 ms each), not in every
    /// frame's table.
    splits: Vec<AlbedoSplit>,
}

impl LayeredDesc {
    /// These media with their object IDs (per scene object, 0: not layered) and film flag.
    pub fn of_media(materials: Vec<LayeredMedium>, object_ids: Vec<u8>, film: bool) -> Self {
        let splits = materials.iter().map(LayeredMedium::albedo_split).collect();
        Self {
            materials,
            object_ids,
            film,
            splits,
        }
    }

    /// The layered materials of `scene`'s objects; `None` when no object is layered. Errors
    /// name the material: more than [`MAX_LAYERED_MATERIALS`] distinct media, a medium that
    /// fails validation, or one that reads layer thickness from a texture (`TexDep`) on a mesh
    /// without texture coordinates.
    pub fn new(scene: &Scene) -> Result<Option<Self>> {
        let mut materials: Vec<LayeredMedium> = Vec::new();
        let mut object_ids = Vec::with_capacity(scene.objects.len());
        let mut film = false;
        for o in &scene.objects {
            let Some(medium) = &o.material.layers else {
                object_ids.push(0);
                continue;
            };
            film |= o.material.albedo_texture.is_some();
            medium.validate().map_err(|e| {
                LucentError::InvalidInput(format!("material '{}': {e}", o.material.name))
            })?;
            let mesh = scene.meshes.get(o.mesh);
            if medium.depth_textures_needed() > 0
                && mesh.is_some_and(|m| m.uvs.len() != m.positions.len())
            {
                return Err(LucentError::InvalidInput(format!(
                    "material '{}' reads layer thickness from a depth texture (TexDep) but mesh \
                     {} has no texture coordinates",
                    o.material.name, o.mesh
                )));
            }
            let id = match materials.iter().position(|m| m == medium) {
                Some(i) => i,
                None => {
                    if materials.len() == MAX_LAYERED_MATERIALS {
                        return Err(LucentError::InvalidInput(format!(
                            "scene '{}' has more than {MAX_LAYERED_MATERIALS} distinct layered \
                             media (at material '{}')",
                            scene.name, o.material.name
                        )));
                    }
                    materials.push(medium.clone());
                    materials.len() - 1
                }
            };
            object_ids.push(id as u8 + 1);
        }
        Ok((!materials.is_empty()).then_some(Self::of_media(materials, object_ids, film)))
    }

    /// `TexDep` depth textures one object reads at most (0, 1 or 2): the G-buffer and the
    /// light-space maps store that many textures' texels per pixel.
    pub fn depth_textures(&self) -> usize {
        self.materials
            .iter()
            .map(LayeredMedium::depth_textures_needed)
            .max()
            .unwrap_or(0)
    }

    /// The per-frame table of these materials under `knobs`.
    pub fn table(&self, knobs: &LayeredKnobs) -> LayeredTableGpu {
        let mut t: LayeredTableGpu = bytemuck::Zeroable::zeroed();
        t.knobs = [
            knobs.steps.clamp(*STEP_RANGE.start(), *STEP_RANGE.end()) as i32,
            knobs
                .pixel_lights
                .clamp(*PIXEL_LIGHT_RANGE.start(), *PIXEL_LIGHT_RANGE.end()) as i32,
            i32::from(knobs.phase == PhaseForm::Schlick),
            if knobs.half_irradiance { 2 } else { 1 },
        ];
        for (i, (row, m)) in t.materials.iter_mut().zip(&self.materials).enumerate() {
            // A material pushed after construction has no split yet: computed here then.
            let split = self.splits.get(i).copied().unwrap_or_else(|| m.albedo_split());
            *row = material_row(m, &split, knobs);
        }
        t.view_to_world = glam::Mat4::IDENTITY.to_cols_array_2d();
        // lucent's own IDs are the material numbers.
        for id in 0..=MAX_LAYERED_MATERIALS {
            t.id_materials[id / 4][id % 4] = id as u32;
        }
        t
    }
}

/// Gather radius in units of the slowest channel's diffusion length `1 / sigma_tr`: beyond
/// 3 lengths the dipole's tail holds a few percent of its energy.
pub const GATHER_LENGTHS: f64 = 3.0;
/// Largest gather radius in multiples of the largest `z_r` (a channel without absorption has
/// `sigma_tr = 0` and an unbounded `1/r^3` tail: the radius is bounded explicitly).
pub const MAX_GATHER_Z_R: f64 = 200.0;

/// The gather radius of `medium` (scene units): [`GATHER_LENGTHS`] over the smallest nonzero
/// `sigma_tr`, at most [`MAX_GATHER_Z_R`] times the largest `z_r`.
pub fn gather_radius(medium: &LayeredMedium) -> f64 {
    let d = medium.dipole_constants();
    let z_r = f64::from(d.z_r.max_element());
    let sigma_tr = d
        .sigma_tr
        .to_array()
        .into_iter()
        .map(f64::from)
        .filter(|s| *s > 0.0)
        .fold(f64::INFINITY, f64::min);
    let bound = MAX_GATHER_Z_R * z_r;
    let radius = if sigma_tr.is_finite() {
        (GATHER_LENGTHS / sigma_tr).min(bound)
    } else {
        bound
    };
    // A vacuum-like medium (sigma_t' -> 0) has z_r -> 1e12: keep the radius a length f32
    // and the screen projection handle.
    radius.clamp(1e-6, 1e4)
}

/// Single scattering's depth `D_max` of `medium` in scene units: `mfp` mean free paths of the
/// first layer's clearest channel (its smallest `sigma_t`), at least a millionth of a unit.
pub fn single_depth(medium: &LayeredMedium, mfp: f32) -> f64 {
    let sigma_t = medium.sigma_t_per_unit(0);
    let clearest = f64::from(sigma_t.min_element()).max(1e-6);
    (f64::from(mfp.max(1e-3)) / clearest).clamp(1e-6, 1e6)
}

fn material_row(m: &LayeredMedium, split: &AlbedoSplit, knobs: &LayeredKnobs) -> LayeredMaterialGpu {
    let mut row: LayeredMaterialGpu = bytemuck::Zeroable::zeroed();
    let d = m.dipole_constants();
    row.info = [
        m.layers.len().min(MAX_LAYERS) as f32,
        m.eta,
        single_depth(m, knobs.max_depth_mfp) as f32,
        gather_radius(m) as f32,
    ];
    // The share of a white sky the boundary lets in, c: the ambient's, and how light leaving
    // diffusely is spread (not Jensen's 1 - F_dr, the share of light inside that gets out,
    // c / eta^2). Held off 0 (AlbedoSplit's own bound), as the shaders divide by it.
    let c = split.diffuse_transmittance;
    row.weights = [m.weights[2], m.weights[3], m.weights[4], c];
    for (i, l) in m.layers.iter().take(MAX_LAYERS).enumerate() {
        let sigma_t = m.sigma_t_per_unit(i);
        let sigma_s = m.sigma_s_per_unit(i);
        let thickness = match l.thickness {
            // -1: no bottom (the shader's "rest").
            Thickness::Rest => -1.0,
            // TexDep: the texel times this scale (units per texel unit); no constant part.
            Thickness::Texture { scale } => {
                row.thickness_scale[i / 4][i % 4] = scale * m.units_per_mm;
                0.0
            }
            Thickness::Mm(_) => m.thickness_mm(i, &[]) * m.units_per_mm,
        };
        row.sigma_t_g[i] = [sigma_t.x, sigma_t.y, sigma_t.z, l.g];
        row.sigma_s_thickness[i] = [sigma_s.x, sigma_s.y, sigma_s.z, thickness];
    }
    row.sigma_tr = d.sigma_tr.extend(0.0).to_array();
    row.z_r = d.z_r.extend(0.0).to_array();
    row.z_v = d.z_v.extend(0.0).to_array();
    row.alpha_prime = d.alpha_prime.extend(0.0).to_array();
    row.total = split.multiple_scale.extend(0.0).to_array();
    // The ambient's single scattering leaves as F_t(mu_o) ambient(n) S / c: S / c of a white
    // sky's radiance (an irradiance pi L, of which S leaves, spread as F_t / (pi c)).
    row.ambient_single = (split.single / c).extend(0.0).to_array();
    row
}

/// One layered material, std140 (glsl/common/layered.glsl `LayeredMaterial`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LayeredMaterialGpu {
    /// x: layer count; y: eta; z: `D_max` (units); w: gather radius (units).
    pub info: [f32; 4],
    /// x: λ3 (transmitted); y: λ4 (single); z: λ5 (multiple); w: the share of the ambient
    /// the boundary lets in (`scene::albedo::diffuse_transmittance`), which is also how light
    /// leaving diffusely is spread (`F_t(mu_o) / (pi c)`).
    pub weights: [f32; 4],
    /// Per layer: extinction rgb (1/unit), g.
    pub sigma_t_g: [[f32; 4]; MAX_LAYERS],
    /// Per layer: scattering rgb (1/unit), thickness (units; -1: the rest of the object; 0
    /// for a `TexDep` layer).
    pub sigma_s_thickness: [[f32; 4]; MAX_LAYERS],
    /// Layer `j`'s `TexDep` scale at `[j / 4][j % 4]`: units per texel unit (0: the layer's
    /// thickness is the constant above).
    pub thickness_scale: [[f32; 4]; 2],
    /// The first layer's dipole: `sigma_tr` rgb (1/unit).
    pub sigma_tr: [f32; 4],
    /// `z_r` rgb (units).
    pub z_r: [f32; 4],
    /// `z_v` rgb (units).
    pub z_v: [f32; 4],
    /// `alpha'` rgb.
    pub alpha_prime: [f32; 4],
    /// What multiple scattering scales the dipole's profile to, rgb
    /// ([`AlbedoSplit::multiple_scale`]).
    pub total: [f32; 4],
    /// The ambient's single scattering: `S / c` rgb
    /// ([`AlbedoSplit::single`] over the diffuse transmittance).
    pub ambient_single: [f32; 4],
}

/// The per-frame layered table, std140 (glsl/common/layered.glsl `Layered`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LayeredTableGpu {
    /// x: march steps; y: pixel lights; z: phase (0 HG, 1 Schlick); w: irradiance
    /// downscale (1 or 2).
    pub knobs: [i32; 4],
    /// The materials (ID - 1).
    pub materials: [LayeredMaterialGpu; MAX_LAYERED_MATERIALS],
    /// The inverse of the frame's view matrix (a host's view-space normals and linear depth).
    pub view_to_world: [[f32; 4]; 4],
    /// ID k's layered material at `[k / 4][k % 4]` (0: none), read by passes whose IDs are
    /// not the material numbers ([`LayeredDecode::ids_up_to`] 0).
    pub id_materials: [[u32; 4]; 64],
}

/// Bytes of the per-frame layered region.
pub const LAYERED_TABLE_BYTES: u64 = std::mem::size_of::<LayeredTableGpu>() as u64;

/// The layered media's table in the per-frame buffer.
pub static TABLE_REGION: Region = Region::new("layered media table", "Layered");

/// The per-frame region a frame with layered materials writes its table into.
pub fn table_region() -> TableRegion {
    TableRegion {
        region: &TABLE_REGION,
        bytes: LAYERED_TABLE_BYTES,
    }
}

/// The G-buffer images the layered passes read.
pub struct LayeredInputs<'a> {
    /// Depth.
    pub depth: &'a Handle<Image>,
    /// GB1: normal + roughness.
    pub gb1: &'a Handle<Image>,
    /// The layered material IDs.
    pub ids: &'a Handle<Image>,
    /// The `TexDep` texels per pixel (frames whose media read depth textures).
    pub layer_depths: Option<&'a Handle<Image>>,
    /// Depth textures per object those texels come from (1 or 2; 0 without them).
    pub layer_depth_textures: usize,
    /// The light-space maps (with their entry target), when some light casts.
    pub shadows: Option<&'a ShadowMaps>,
    /// The ID target holds each pixel's albedo texel too ([`LayeredDesc::film`]).
    pub film: bool,
    /// `None`: lucent's own G-buffer. `Some`: a host's (`lucent::embed::LayeredEffect`): the
    /// shaders' permutation for its IDs' sampler and its depth.
    pub host: Option<LayeredHost>,
    /// How the passes read the G-buffer's IDs and normals (`None`: lucent's own, the
    /// constants' defaults).
    pub decode: Option<LayeredDecode>,
    /// A host's film (its albedo image), which single scattering multiplies the light leaving
    /// the surface by when `film` is set on a host's G-buffer.
    pub host_film: Option<&'a Handle<Image>>,
}

/// How the layered passes read a G-buffer's material IDs and normals: their specialization
/// constants (glsl/common/layered.glsl, `constant_id` 0-7), whose defaults are lucent's own
/// G-buffer (R8_UNORM material numbers, world-space float normals).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayeredDecode {
    /// The ID decode (glsl/common/host_ids.glsl): channel, shift, mask, UNORM maximum.
    pub ids: [u32; 4],
    /// `n` (1 to [`MAX_LAYERED_MATERIALS`]) when IDs 1 to `n` are materials 1 to `n` and every
    /// other ID none; 0: each ID's material is read from the table's `id_materials`.
    pub ids_up_to: u32,
    /// The normal encoding (glsl/common/host_normals.glsl): octahedral, view space, UNORM.
    pub normals: [u32; 3],
}

impl LayeredDecode {
    /// The decode of IDs `ids` (channel, shift, mask, UNORM maximum) mapped to materials by
    /// `id_materials` (as the table holds it), and normals encoded as `normals`.
    pub fn new(ids: [u32; 4], id_materials: &[[u32; 4]; 64], normals: [u32; 3]) -> Self {
        let material = |id: usize| id_materials[id / 4][id % 4] as usize;
        Self {
            ids,
            ids_up_to: crate::features::util::numbered_from_one(material).unwrap_or(0) as u32,
            normals,
        }
    }

    /// The constants, value `i` for `constant_id = i`.
    fn specialization(&self) -> Vec<u32> {
        let mut constants = self.ids.to_vec();
        constants.push(self.ids_up_to);
        constants.extend(self.normals);
        constants
    }
}

/// What a host's G-buffer changes in the layered passes' shaders (their permutation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayeredHost {
    /// The material IDs are an unsigned-integer image (`LUCENT_HOST_IDS_UINT`).
    pub uint_ids: bool,
    /// The depth is linear view depth (`LUCENT_HOST_LINEAR_DEPTH`), else a device depth.
    pub linear_depth: bool,
}

impl LayeredHost {
    /// Every host permutation.
    const ALL: [LayeredHost; 4] = [
        LayeredHost {
            uint_ids: false,
            linear_depth: false,
        },
        LayeredHost {
            uint_ids: true,
            linear_depth: false,
        },
        LayeredHost {
            uint_ids: false,
            linear_depth: true,
        },
        LayeredHost {
            uint_ids: true,
            linear_depth: true,
        },
    ];

    /// Its defines.
    fn defines(self) -> Vec<(&'static str, &'static str)> {
        let mut defines = Vec::new();
        if self.uint_ids {
            defines.push(("LUCENT_HOST_IDS_UINT", "1"));
        }
        if self.linear_depth {
            defines.push(("LUCENT_HOST_LINEAR_DEPTH", "1"));
        }
        defines
    }
}

/// Declares `layered irradiance`, `single scattering` and `multiple scattering`; both
/// scattering passes add into `hdr`, which is returned.
pub fn layered_passes(
    graph: &mut RenderGraph,
    mut hdr: Handle<Image>,
    inputs: &LayeredInputs<'_>,
    knobs: &LayeredKnobs,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let info = graph.resources()[inputs.depth.id()].info;
    let scale = if knobs.half_irradiance { 2 } else { 1 };
    let mut irradiance = graph.create_image(
        "layered.irradiance",
        ImageInfo {
            width: info.width.div_ceil(scale),
            height: info.height.div_ceil(scale),
            format: IRRADIANCE_FORMAT,
        },
    );
    // Cleared: pixels outside the rectangles read 0 (the gather rejects them by ID anyway).
    let mut pass = layered_pass(graph, Kind::Irradiance, inputs, scale, None, None, scene);
    pass.color(&mut irradiance, LoadOp::Clear([0.0; 4]));
    pass.finish();

    if !knobs.half_gather {
        // Full-resolution gather: the term per pixel (alpha: its material), rotated by one of
        // nine angles per 3x3 block; single scattering then adds its own terms and the term
        // averaged over 3x3 pixels (glsl/common/layered_upsample.glsl): no grain in a still.
        let term_info = ImageInfo {
            format: IRRADIANCE_FORMAT,
            ..info
        };
        let mut term = graph.create_image("layered.multiple", term_info);
        let mut blurred = graph.create_image("layered.multiple-blurred", term_info);
        let mut pass = layered_pass(
            graph,
            Kind::Multiple,
            inputs,
            1,
            Some(&irradiance),
            None,
            scene,
        );
        // Cleared: pixels outside the rectangles read material 0, which the resolve skips.
        pass.color(&mut term, LoadOp::Clear([0.0; 4]))
            .color(&mut blurred, LoadOp::Clear([0.0; 4]));
        pass.finish();
        let term = term_blur(graph, inputs, 1, &term, blurred, scene);
        let mut pass = layered_pass(graph, Kind::Single, inputs, 1, None, Some(&term), scene);
        pass.color_add(&mut hdr, LoadOp::Load);
        pass.finish();
        return hdr;
    }
    // Half-resolution gather: the term per 2x2 block (alpha: its material) first, then single
    // scattering adds its own terms and the upsampled one (glsl/common/layered_upsample.glsl).
    let half_info = ImageInfo {
        width: info.width.div_ceil(2),
        height: info.height.div_ceil(2),
        format: IRRADIANCE_FORMAT,
    };
    let mut half_term = graph.create_image("layered.multiple", half_info);
    let mut blurred = graph.create_image("layered.multiple-blurred", half_info);
    let mut pass = layered_pass(
        graph,
        Kind::HalfGather,
        inputs,
        2,
        Some(&irradiance),
        None,
        scene,
    );
    // Cleared: texels outside the rectangles read material 0, which the upsample skips.
    pass.color(&mut half_term, LoadOp::Clear([0.0; 4]))
        .color(&mut blurred, LoadOp::Clear([0.0; 4]));
    pass.finish();
    let half_term = term_blur(graph, inputs, 2, &half_term, blurred, scene);
    let mut pass = layered_pass(
        graph,
        Kind::Single,
        inputs,
        1,
        None,
        Some(&half_term),
        scene,
    );
    pass.color_add(&mut hdr, LoadOp::Load);
    pass.finish();
    hdr
}

/// Declares `multiple scattering blur`: the term gathered at `1 / scale` of the screen per
/// side, each texel of a medium that diffuses far on screen replaced by the mean of the 3x3
/// texels of its material and depth around it (glsl/layered/term_blur.frag), written over
/// `blurred`, the gather's second copy of the term, which single scattering then resolves. It
/// draws only the rectangles of objects whose medium can be blurred this frame
/// ([`blurs_on_screen`]); elsewhere `blurred` keeps the gather's copy, and a frame with no such
/// object draws nothing. Returns `blurred`.
fn term_blur(
    graph: &mut RenderGraph,
    inputs: &LayeredInputs<'_>,
    scale: u32,
    term: &Handle<Image>,
    mut blurred: Handle<Image>,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let mut pass = layered_pass(graph, Kind::Blur, inputs, scale, Some(term), None, scene);
    pass.color(&mut blurred, LoadOp::Load);
    pass.finish();
    blurred
}

/// The narrowest channel's diffusion length `1 / sigma_tr` on screen, in the gather's texels,
/// from which the term's blur starts to act (glsl/layered/term_blur.frag `BLUR_NO_KERNEL_PX`
/// is this times the texel's pixels: keep the two equal); it acts fully from twice this.
pub const BLUR_MIN_KERNEL_TEXELS: f32 = 6.0;

/// Whether the term's blur acts anywhere on an object of `medium` whose nearest point is
/// `nearest_depth` (view depth, scene units; 0 or less: it reaches the eye) from the eye, with
/// `focal_px` the focal length in pixels and `texel_px` the gather's texel size in pixels (1
/// or 2): its narrowest channel's diffusion length, at that depth, spans at least
/// [`BLUR_MIN_KERNEL_TEXELS`] texels.
pub fn blurs_on_screen(
    medium: &LayeredMedium,
    nearest_depth: f32,
    focal_px: f32,
    texel_px: f32,
) -> bool {
    // At or behind the eye's plane (or not a number): the object may come arbitrarily close.
    if nearest_depth.is_nan() || nearest_depth <= 0.0 {
        return true;
    }
    let sigma_max = medium.dipole_constants().sigma_tr.max_element().max(1e-12);
    focal_px / (nearest_depth * sigma_max) >= BLUR_MIN_KERNEL_TEXELS * texel_px
}

/// Starts a layered pass of `kind` at `1 / scale` of the screen per side, reading the gather's
/// `irradiance` or, in single scattering, the multiple scattering term (`half_term`: half
/// resolution under the default `--gather half`) it resolves and adds. The graph reads the G-buffer first;
/// irradiance the depth atlas (shadows), single scattering the depth and entry atlases (entry
/// points). The shader numbers its bindings as glsl/common/layered.glsl does: 0 frame, 1
/// layered table, 2 depth, 3 GB1, 4 IDs, then the pass's own (the irradiance image; or the
/// half-resolution term, the `TexDep` texels, the entry atlas and the shadow bindings), so the
/// pass's own are bound after all its reads are declared. It draws only the screen rectangles
/// layered objects may cover.
fn layered_pass<'g>(
    graph: &'g mut RenderGraph,
    kind: Kind,
    inputs: &LayeredInputs<'_>,
    scale: u32,
    irradiance: Option<&Handle<Image>>,
    half_term: Option<&Handle<Image>>,
    scene: Option<&Arc<SceneGpu>>,
) -> FullscreenPass<'g> {
    let single = kind == Kind::Single;
    // The multiple-scattering term single scattering reads is at full resolution unless it
    // was gathered at half (its image is then half the depth's width).
    let half_gather = half_term.is_some_and(|h| {
        graph.resources()[h.id()].info.width != graph.resources()[inputs.depth.id()].info.width
    });
    let mut pass = FullscreenPass::new(graph, kind.name(), kind.fragment(), scene);
    if let Some(host) = inputs.host {
        pass.defines(&host.defines());
    }
    if let Some(decode) = &inputs.decode {
        pass.specialize(&decode.specialization());
    }
    pass.per_frame(&FRAME)
        .per_frame(&TABLE_REGION)
        .sample("gbuffer_depth", inputs.depth)
        .sample("gbuffer_normal", inputs.gb1)
        .sample("gbuffer_layered", inputs.ids);
    // Only single scattering reads layer thicknesses (multiple scattering's dipole is the
    // first layer's, semi-infinite, as in the paper).
    let layer_depths = inputs.layer_depths.filter(|_| single);
    let shadows = inputs
        .shadows
        .filter(|_| matches!(kind, Kind::Irradiance | Kind::Single));
    let entry = shadows
        .and_then(|maps| maps.entry.as_ref())
        .filter(|_| single);
    let entry_depths = entry.and(shadows.and_then(|maps| maps.layer_depths.as_ref()));
    // A host's film, read by single scattering (its binding comes last).
    let host_film = inputs
        .host_film
        .filter(|_| single && inputs.film && inputs.host.is_some());
    for h in [layer_depths]
        .into_iter()
        .chain([shadows.map(|maps| &maps.depth), entry, entry_depths])
        .chain([irradiance, half_term, host_film])
        .flatten()
    {
        pass.graph().sample(h);
    }
    // The image the pass reads at binding 5: the irradiance (the gather) or the term (its
    // blur).
    if let Some(irradiance) = irradiance {
        // The term's blur reads the term; multiple scattering the gathered irradiance.
        let name = if kind == Kind::Blur {
            "term_tex"
        } else {
            "irradiance_tex"
        };
        pass.bind_sampled(name, irradiance, vk::Filter::NEAREST);
    }
    if let (true, Some(half_term)) = (single, half_term) {
        pass.define("LUCENT_HALF_TERM", "1").bind_sampled(
            "half_term",
            half_term,
            vk::Filter::NEAREST,
        );
        if scale == 1 && !half_gather {
            pass.define("LUCENT_FULL_RES_TERM", "1");
        }
    }
    if single && inputs.film {
        pass.define("LUCENT_LAYERED_FILM", "1");
        if host_film.is_some() {
            pass.define("LUCENT_HOST_FILM", "1");
        }
    }
    if let Some(depths) = layer_depths {
        pass.define(
            "LUCENT_LAYER_DEPTHS",
            super::layer_depth::layer_depths_define(inputs.layer_depth_textures),
        )
        .bind_sampled("gbuffer_layer_depths", depths, vk::Filter::NEAREST);
    }
    if let Some(maps) = shadows {
        if let Some(entry) = entry {
            pass.define("LUCENT_ENTRY", "1").bind_sampled(
                "shadow_entry",
                entry,
                vk::Filter::NEAREST,
            );
            if let (Some(_), Some(depths)) = (layer_depths, entry_depths) {
                pass.define("LUCENT_ENTRY_DEPTHS", "1").bind_sampled(
                    "shadow_layer_depths",
                    depths,
                    vk::Filter::NEAREST,
                );
            }
        }
        pass.bind_shadows(&maps.depth);
    }
    if let Some(film) = host_film {
        pass.bind_sampled("host_film", film, vk::Filter::NEAREST);
    }
    match (kind, scale) {
        (Kind::Irradiance, 2) => {
            pass.define("LUCENT_HALF_RES", "1");
        }
        (Kind::HalfGather, _) | (Kind::Blur, 2) => {
            pass.define("LUCENT_HALF_GATHER", "1");
        }
        _ => {}
    }
    pass.tiles(move |scene, ctx| {
        let tiles = scene.per_frame.tiles(ctx.frame);
        let rects = if kind == Kind::Blur {
            tiles.layered_blur.clone()
        } else {
            tiles.layered.clone()
        };
        Some(
            rects
                .iter()
                .filter(|r| r.translucent)
                .map(|r| TileRect {
                    x: r.x / scale,
                    y: r.y / scale,
                    width: r
                        .width
                        .div_ceil(scale)
                        .min(ctx.extent.width.saturating_sub(r.x / scale)),
                    height: r
                        .height
                        .div_ceil(scale)
                        .min(ctx.extent.height.saturating_sub(r.y / scale)),
                    translucent: true,
                })
                .collect(),
        )
    });
    pass
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Irradiance,
    Single,
    Multiple,
    /// Multiple scattering into the half-resolution target.
    HalfGather,
    /// The multiple-scattering term's blur (at the gather's resolution).
    Blur,
}

impl Kind {
    const ALL: [Kind; 5] = [
        Kind::Irradiance,
        Kind::Single,
        Kind::Multiple,
        Kind::HalfGather,
        Kind::Blur,
    ];

    /// The pass's name.
    fn name(self) -> &'static str {
        match self {
            Kind::Irradiance => "layered irradiance",
            Kind::Single => "single scattering",
            Kind::Multiple | Kind::HalfGather => "multiple scattering",
            Kind::Blur => "multiple scattering blur",
        }
    }

    fn fragment(self) -> &'static str {
        match self {
            Kind::Irradiance => "layered/irradiance.frag",
            Kind::Single => "layered/single.frag",
            Kind::Multiple | Kind::HalfGather => "layered/multiple.frag",
            Kind::Blur => "layered/term_blur.frag",
        }
    }
}

/// What a layered pass's shader permutation depends on: its kind and which inputs it reads
/// (for the shipped enumeration; a pass itself takes its defines from [`layered_pass`]).
#[derive(Clone, Copy, Debug)]
struct LayeredShape {
    kind: Kind,
    /// The pass runs at half resolution (scale 2).
    half_res: bool,
    half_term: bool,
    /// The term single scattering reads is at full resolution (resolved over 3x3 pixels).
    full_res_term: bool,
    /// The G-buffer's `TexDep` texels, of this many depth textures.
    layer_depths: Option<usize>,
    shadows: bool,
    entry: bool,
    entry_depths: bool,
    /// The ID target carries the albedo film (single scattering applies it).
    film: bool,
    /// A host's G-buffer.
    host: Option<LayeredHost>,
}

impl LayeredShape {
    /// The defines [`layered_pass`] gives a pass of this shape.
    fn defines(&self) -> Vec<(&'static str, &'static str)> {
        let mut defines: Vec<(&str, &str)> = Vec::new();
        if let Some(host) = self.host {
            defines.extend(host.defines());
        }
        let single = self.kind == Kind::Single;
        if single && self.half_term {
            defines.push(("LUCENT_HALF_TERM", "1"));
            if self.full_res_term && !self.half_res {
                defines.push(("LUCENT_FULL_RES_TERM", "1"));
            }
        }
        if single && self.film {
            defines.push(("LUCENT_LAYERED_FILM", "1"));
            if self.host.is_some() {
                defines.push(("LUCENT_HOST_FILM", "1"));
            }
        }
        let texdep = single && self.layer_depths.is_some();
        if let (true, Some(textures)) = (texdep, self.layer_depths) {
            defines.push((
                "LUCENT_LAYER_DEPTHS",
                super::layer_depth::layer_depths_define(textures),
            ));
        }
        if self.shadows && matches!(self.kind, Kind::Irradiance | Kind::Single) {
            if single && self.entry {
                defines.push(("LUCENT_ENTRY", "1"));
                if texdep && self.entry_depths {
                    defines.push(("LUCENT_ENTRY_DEPTHS", "1"));
                }
            }
            defines.extend(shadows::LIGHTING_DEFINES);
        }
        match (self.kind, self.half_res) {
            (Kind::Irradiance, true) => defines.push(("LUCENT_HALF_RES", "1")),
            (Kind::HalfGather, _) | (Kind::Blur, true) => defines.push(("LUCENT_HALF_GATHER", "1")),
            _ => {}
        }
        defines
    }
}

/// The pipelines the layered passes of any frame build: every kind with every set of inputs.
fn shader_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    for kind in Kind::ALL {
        for flags in 0u32..1 << 7 {
            let bit = |i: u32| flags & (1 << i) != 0;
            // The full-resolution term only tells a single scattering pass that reads one apart.
            if bit(5) && !(kind == Kind::Single && bit(1) && !bit(0)) {
                continue;
            }
            // Only single scattering applies the film.
            if bit(6) && kind != Kind::Single {
                continue;
            }
            for layer_depths in [None, Some(1), Some(2)] {
                for host in std::iter::once(None).chain(LayeredHost::ALL.map(Some)) {
                    // A host's G-buffer: lucent draws the maps with their entry target, and
                    // with depth textures their texels too (the film is the host's albedo
                    // image).
                    let embedded = bit(2) && bit(3) && bit(4) == layer_depths.is_some();
                    if host.is_some() && !embedded {
                        continue;
                    }
                    let shape = LayeredShape {
                        kind,
                        half_res: bit(0),
                        half_term: bit(1),
                        full_res_term: bit(5),
                        layer_depths,
                        shadows: bit(2),
                        entry: bit(3),
                        entry_depths: bit(4),
                        film: bit(6),
                        host,
                    };
                    out.push(crate::backend::shader::PipelineShaders::fullscreen(
                        kind.fragment(),
                        &shape.defines(),
                    ));
                }
            }
        }
    }
}

/// Li et al.'s layered media as a registered technique (`--technique layered`).
pub struct LiLayeredMedia;

/// The technique's instance, listed in [`super::registry`].
pub static LAYERED: LiLayeredMedia = LiLayeredMedia;

impl TechniqueModule for LiLayeredMedia {
    fn name(&self) -> &'static str {
        "layered"
    }

    fn summary(&self) -> &'static str {
        "Li et al.'s layered media: image-space single and dipole multiple scattering on \
         layered materials"
    }

    fn part(&self) -> &'static dyn PartKind {
        &LAYERED_PART
    }

    fn knobs(&self) -> &'static [&'static Knob] {
        static KNOBS: &[&Knob] = &[
            &STEPS_KNOB,
            &PIXEL_LIGHTS_KNOB,
            &PHASE_KNOB,
            &HALF_IRRADIANCE_KNOB,
            &GATHER_KNOB,
            &SINGLE_DEPTH_KNOB,
        ];
        KNOBS
    }

    fn scene(&self) -> &'static str {
        "layered"
    }

    fn shader_permutations(&self, out: &mut Vec<crate::backend::shader::PipelineShaders>) {
        shader_permutations(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn ids_numbered_from_one_in_order_are_read_as_the_material_numbers() {
        let table = |ids: &[(usize, u32)]| {
            let mut t = [[0u32; 4]; 64];
            for &(id, material) in ids {
                t[id / 4][id % 4] = material;
            }
            t
        };
        let decode = [0, 4, 0xf, 255];
        let numbered = LayeredDecode::new(decode, &table(&[(1, 1), (2, 2), (3, 3)]), [1, 1, 1]);
        assert_eq!(numbered.ids_up_to, 3);
        assert_eq!(numbered.specialization(), [0, 4, 0xf, 255, 3, 1, 1, 1]);
        // Out of order, a gap, or an ID past 255's table: each ID looked up.
        for ids in [
            vec![(1, 2), (2, 1)],
            vec![(1, 1), (3, 2)],
            vec![(13, 1), (16, 2), (19, 3)],
        ] {
            assert_eq!(LayeredDecode::new(decode, &table(&ids), [0; 3]).ids_up_to, 0, "{ids:?}");
        }
        // lucent's own table maps every material number to itself, ID 0 to none.
        let own = LayeredDesc::of_media(Vec::new(), Vec::new(), false).table(&LayeredKnobs::default());
        for id in 0..=MAX_LAYERED_MATERIALS {
            assert_eq!(own.id_materials[id / 4][id % 4] as usize, id);
        }
        assert_eq!(own.view_to_world, glam::Mat4::IDENTITY.to_cols_array_2d());
    }

    #[test]
    fn the_layered_scene_gets_one_row_per_medium() {
        let scene = builtin::builtin("layered").unwrap();
        let desc = LayeredDesc::new(&scene).unwrap().unwrap();
        assert_eq!(desc.materials.len(), 5);
        // The floor is not layered.
        assert_eq!(desc.object_ids.iter().filter(|&&i| i == 0).count(), 1);
        let table = desc.table(&LayeredKnobs::default());
        let apple = &table.materials[0];
        assert_eq!(apple.info[0], 1.0);
        assert!(apple.info[2] > 0.0 && apple.info[3] > apple.info[2]);
        assert!(apple.total.iter().take(3).all(|t| *t > 0.0 && *t < 1.0));
        assert!(LayeredDesc::new(&builtin::builtin("smoke").unwrap())
            .unwrap()
            .is_none());
    }

    #[test]
    fn passes_declare_the_defines_the_shipped_enumeration_lists() {
        let info = ImageInfo {
            width: 8,
            height: 8,
            format: IRRADIANCE_FORMAT,
        };
        for kind in Kind::ALL {
            for flags in 0u32..1 << 8 {
                let bit = |i: u32| flags & (1 << i) != 0;
                for (textures, host) in (0..=2)
                    .map(|t| (t, None))
                    .chain(LayeredHost::ALL.map(|h| (0, Some(h))))
                {
                    let mut graph = RenderGraph::new();
                    let mut image = |name: &str| graph.create_image(name, info);
                    let (depth, gb1, ids) = (image("depth"), image("gb1"), image("ids"));
                    let film = image("film");
                    let layer_depths = (textures > 0).then(|| image("layer depths"));
                    let maps = bit(3).then(|| ShadowMaps {
                        depth: image("atlas"),
                        ids: None,
                        entry: bit(4).then(|| image("entry")),
                        layer_depths: bit(5).then(|| image("entry depths")),
                    });
                    let irradiance = bit(1).then(|| image("irradiance"));
                    // Bit 6: the term at full resolution (else half the depth's width).
                    let term_info = ImageInfo {
                        width: if bit(6) { 8 } else { 4 },
                        ..info
                    };
                    let half_term = bit(2).then(|| graph.create_image("term", term_info));
                    let inputs = LayeredInputs {
                        depth: &depth,
                        gb1: &gb1,
                        ids: &ids,
                        layer_depths: layer_depths.as_ref(),
                        layer_depth_textures: textures,
                        shadows: maps.as_ref(),
                        film: bit(7),
                        host,
                        decode: None,
                        host_film: host.map(|_| &film),
                    };
                    let scale = if bit(0) { 2 } else { 1 };
                    let pass = layered_pass(
                        &mut graph,
                        kind,
                        &inputs,
                        scale,
                        irradiance.as_ref(),
                        half_term.as_ref(),
                        None,
                    );
                    let shape = LayeredShape {
                        kind,
                        half_res: bit(0),
                        half_term: bit(2),
                        full_res_term: bit(6),
                        layer_depths: (textures > 0).then_some(textures),
                        shadows: bit(3),
                        entry: bit(4),
                        entry_depths: bit(5),
                        film: bit(7),
                        host,
                    };
                    assert_eq!(pass.shader_defines(), shape.defines(), "{shape:?}");
                }
            }
        }
    }

    #[test]
    fn the_terms_blur_acts_where_the_narrowest_channel_spans_six_texels() {
        // skin1 at 0.04 units/mm: its largest sigma_tr (blue) makes 1 / sigma_tr about 0.7 mm,
        // 0.027 units: at 3 units from a 1000-pixel focal length, 4.5 half-resolution texels.
        let skin1 = LayeredMedium::preset("skin1").unwrap();
        assert!(!blurs_on_screen(&skin1, 3.0, 1000.0, 2.0));
        // The same medium right at the eye, or a box crossing the eye's plane, is blurred.
        assert!(blurs_on_screen(&skin1, 0.0, 1000.0, 2.0));
        assert!(blurs_on_screen(&skin1, -1.0, 1000.0, 2.0));
        // The threshold: exactly six texels of diffusion length.
        let sigma_max = skin1.dipole_constants().sigma_tr.max_element();
        let depth = 1000.0 / (sigma_max * BLUR_MIN_KERNEL_TEXELS * 2.0);
        assert!(blurs_on_screen(&skin1, depth * 0.99, 1000.0, 2.0));
        assert!(!blurs_on_screen(&skin1, depth * 1.01, 1000.0, 2.0));
        // Full-resolution texels are half as wide: the same depth is blurred.
        assert!(blurs_on_screen(&skin1, depth * 1.01, 1000.0, 1.0));
        // A medium that absorbs nothing (sigma_tr 0) is blurred at any distance, finitely.
        let mut clear = skin1.clone();
        for layer in &mut clear.layers {
            layer.sigma_a = glam::Vec3::ZERO;
        }
        assert!(blurs_on_screen(&clear, 1e6, 1000.0, 2.0));
    }

    #[test]
    fn extreme_media_give_finite_rows() {
        use crate::scene::layered::Layer;
        use glam::Vec3;
        for (sa, ss, g, eta) in [
            (0.0, 1e-6, 0.0, 1.0),
            (0.0, 0.0, 0.999, 1.0),
            (1e6, 1e6, -0.999, 1.5),
            (0.0, 1e6, 0.999, 3.0),
        ] {
            let mut m = LayeredMedium::preset("apple").unwrap();
            m.eta = eta;
            m.layers = vec![Layer {
                sigma_a: Vec3::splat(sa),
                sigma_s: Vec3::splat(ss),
                g,
                thickness: Thickness::Rest,
            }];
            let row = material_row(&m, &m.albedo_split(), &LayeredKnobs::default());
            let all = bytemuck::bytes_of(&row);
            let floats: &[f32] = bytemuck::cast_slice(all);
            assert!(
                floats.iter().all(|v| v.is_finite()),
                "{sa} {ss} {g}: {row:?}"
            );
        }
    }
}
