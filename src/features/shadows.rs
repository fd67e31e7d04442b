//! Light-space maps: one depth atlas holding a map per face of every light that casts shadows
//! (directional and spot lights one face, point lights six, a cube), drawn in one pass
//! (`light-space maps`) before the G-buffer, and read by every pass that lights a surface
//! directly (deferred lighting, the LEAN specular of LCB/LBB/bilateral frames).
//!
//! Lookup (glsl/common/shadows.glsl): the shaded point is moved along its normal by 1.5 map
//! texels (normal-offset shadows: the offset follows the texel's world size at that distance,
//! so acne is gone at every distance without a depth bias that detaches shadows), projected
//! with its face's matrix and compared with a 4x4-texel tent of the map (four gathers).
//!
//! The GDC 2011 term is light that went *through* the object. As the talk has it, only its
//! local thickness attenuates it: no shadow falls on it, and it costs no lookup. A material
//! may ask for other objects' shadows on it (`shadowed = true`, lucent's extension); then its
//! own front faces must still not shadow it, so in frames with such a material the atlas also
//! stores which translucency material each texel's first surface belongs to
//! (`light-space.ids`), and the transmitted term counts a tap as lit when its occluder is the
//! shaded pixel's own material: only other objects (other materials) shadow transmission.
//! Frames without a shadowed translucent material have no ID target.
//!
//! A frame has the pass and its images exactly when some light casts and the scene has
//! objects (`--no-shadows` or every light's `shadows = false`: no pass, no image, no shader
//! permutation).

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3, Vec4};

use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, MeshDraws, MeshViews, PassExec, PassKind, PrepareContext,
    RecordContext, RenderGraph,
};
use crate::scene::{LightKind, Scene, MAX_LIGHTS};
use crate::Result;

use super::util::PassPipeline;
use crate::backend::descriptor::{Binding, DescriptorSet};
use crate::backend::pipeline::{GraphicsPipelineDesc, VertexInput};
use crate::gpu_scene::{Region, SceneGpu, TableRegion};

/// Depth of the light-space maps.
pub const SHADOW_DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// The translucency material ID of each map texel's first surface (frames with translucency).
pub const SHADOW_ID_FORMAT: vk::Format = vk::Format::R8_UINT;
/// The light-space maps' entry data in frames with layered media (single scattering's light
/// entry points, src/features/layered.rs): the first surface's normal (`n * 0.5 + 0.5`) and
/// its layered material ID / 255.
pub const ENTRY_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Faces the atlas holds at most: six per light (glsl/common/shadows.glsl).
pub const MAX_SHADOW_FACES: usize = 6 * MAX_LIGHTS;
/// Largest atlas edge in texels: when a scene's faces do not fit at the asked size, the tile
/// edge is halved until they do (8192 x 8192 x 4 bytes = 256 MiB at most).
pub const MAX_ATLAS_EXTENT: u32 = 8192;
/// Map sizes the knob takes.
pub const SHADOW_SIZES: std::ops::RangeInclusive<u32> = 16..=4096;

/// The shadow knobs of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowSettings {
    /// Lights cast shadows (each light's own `shadows` switch still applies).
    pub enabled: bool,
    /// Edge of one face's map in texels (Li et al.'s Table 1 uses 512 and 1024).
    pub size: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            size: 1024,
        }
    }
}

/// The light-space maps of a frame: which lights cast, and where their faces lie in the atlas.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShadowDesc {
    /// Per scene light: its faces in the atlas (0: the light casts no shadow, 1, or 6).
    pub light_faces: Vec<u32>,
    /// Edge of one face's map in texels (the asked size, halved until the atlas fits).
    pub tile: u32,
    /// Atlas columns and rows of tiles.
    pub columns: u32,
    /// Atlas rows.
    pub rows: u32,
    /// The atlas stores each texel's translucency material (frames with a translucent
    /// material whose transmitted light other objects shadow: `Translucency::shadowed`).
    pub transmission_ids: bool,
    /// The atlas stores each texel's entry normal and layered material (frames with layered
    /// media: single scattering's light entry points).
    pub entry: bool,
    /// With `entry`: the `TexDep` depth textures the layered media read per object (0: none;
    /// 1 or 2): the atlas stores each texel's depth texels too.
    pub layer_depth_textures: usize,
}

impl ShadowDesc {
    /// The maps `scene`'s lights ask for under `settings`, with the translucency ID target
    /// when `shadowed_transmission`; `None` when no light casts (or nothing could cast: the
    /// scene has no object).
    pub fn new(
        scene: &Scene,
        settings: &ShadowSettings,
        shadowed_transmission: bool,
    ) -> Option<Self> {
        if !settings.enabled || scene.objects.is_empty() {
            return None;
        }
        let light_faces: Vec<u32> = scene
            .lights
            .iter()
            .take(MAX_LIGHTS)
            .map(|l| match (l.shadows, l.kind) {
                (false, _) => 0,
                (true, LightKind::Point { .. }) => 6,
                (true, _) => 1,
            })
            .collect();
        let faces: u32 = light_faces.iter().sum();
        if faces == 0 {
            return None;
        }
        let columns = (faces as f64).sqrt().ceil() as u32;
        let rows = faces.div_ceil(columns);
        let mut tile = settings
            .size
            .clamp(*SHADOW_SIZES.start(), *SHADOW_SIZES.end());
        while tile > *SHADOW_SIZES.start() && columns.max(rows) * tile > MAX_ATLAS_EXTENT {
            tile /= 2;
        }
        Some(Self {
            light_faces,
            tile,
            columns,
            rows,
            transmission_ids: shadowed_transmission,
            entry: false,
            layer_depth_textures: 0,
        })
    }

    /// Faces in the atlas.
    pub fn faces(&self) -> u32 {
        self.light_faces.iter().sum()
    }

    /// Atlas size in texels.
    pub fn extent(&self) -> (u32, u32) {
        (self.columns * self.tile, self.rows * self.tile)
    }

    /// Top-left texel of face `face`'s tile.
    pub fn tile_origin(&self, face: u32) -> (u32, u32) {
        (
            (face % self.columns) * self.tile,
            (face / self.columns) * self.tile,
        )
    }

    /// For messages and the plan header.
    pub fn name(&self) -> String {
        let lights = self.light_faces.iter().filter(|&&f| f > 0).count();
        format!(
            "shadows ({lights} light{}, {} face{} of {}x{})",
            if lights == 1 { "" } else { "s" },
            self.faces(),
            if self.faces() == 1 { "" } else { "s" },
            self.tile,
            self.tile
        )
    }

    /// The per-frame shadow table of `scene` (whose objects' object-space boxes are
    /// `mesh_bounds`): each casting light's faces with their matrices.
    pub fn uniforms(&self, scene: &Scene, mesh_bounds: &[(Vec3, Vec3)]) -> ShadowUniforms {
        let mut u = ShadowUniforms::zeroed();
        let (w, h) = self.extent();
        u.atlas = [w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32];
        let (center, radius) = world_sphere(scene, mesh_bounds);
        let mut face = 0u32;
        for (i, (light, &count)) in scene.lights.iter().zip(&self.light_faces).enumerate() {
            if count == 0 {
                u.lights[i] = [-1, 0, 0, 0];
                continue;
            }
            u.lights[i] = [face as i32, count as i32, 0, 0];
            for (view, proj, texel) in light_faces(light.kind, center, radius, self.tile) {
                let (x, y) = self.tile_origin(face);
                u.faces[face as usize] = ShadowFaceGpu {
                    view_proj: (proj * view).to_cols_array_2d(),
                    rect: [x as f32, y as f32, self.tile as f32, 0.0],
                    params: texel.to_array(),
                };
                face += 1;
            }
        }
        u
    }
}

/// One face of the atlas as a host describes its own shadow maps
/// ([`crate::embed::ShadowFace`]): what tests hand an embedded effect to compare it with
/// lucent's own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceMatrices {
    /// The light's index in the scene.
    pub light: usize,
    /// World to the face's view space.
    pub view: Mat4,
    /// The face's projection (standard Z).
    pub projection: Mat4,
    /// Its tile's top-left texel and edge in the atlas.
    pub tile: (u32, u32, u32),
}

impl ShadowDesc {
    /// Each casting light's faces in atlas order, with their matrices and tiles (what
    /// [`Self::uniforms`] writes, before the matrices are multiplied).
    pub fn face_matrices(&self, scene: &Scene, mesh_bounds: &[(Vec3, Vec3)]) -> Vec<FaceMatrices> {
        let (center, radius) = world_sphere(scene, mesh_bounds);
        let mut out = Vec::new();
        for (i, (light, &count)) in scene.lights.iter().zip(&self.light_faces).enumerate() {
            if count == 0 {
                continue;
            }
            for (view, projection, _) in light_faces(light.kind, center, radius, self.tile) {
                let (x, y) = self.tile_origin(out.len() as u32);
                out.push(FaceMatrices {
                    light: i,
                    view,
                    projection,
                    tile: (x, y, self.tile),
                });
            }
        }
        out
    }
}

/// One face of the atlas, std140 (glsl/common/shadows.glsl `ShadowFace`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowFaceGpu {
    /// World to the face's clip space.
    pub view_proj: [[f32; 4]; 4],
    /// xy: the tile's top-left texel in the atlas; z: its edge in texels.
    pub rect: [f32; 4],
    /// A map texel's world size at a point: x * clip.w + y (perspective faces: x =
    /// 2 tan(fov / 2) / tile, y = 0; orthographic: x = 0, y = 2 radius / tile); z, w: near
    /// and far distance (near negated for orthographic faces), to compare distances in world
    /// units.
    pub params: [f32; 4],
}

/// The per-frame shadow table, std140 (glsl/common/shadows.glsl `Shadows`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowUniforms {
    /// xy: atlas size in texels; zw: its inverse.
    pub atlas: [f32; 4],
    /// Per light: x its first face (-1: no map), y its face count.
    pub lights: [[i32; 4]; MAX_LIGHTS],
    /// The faces.
    pub faces: [ShadowFaceGpu; MAX_SHADOW_FACES],
}

impl ShadowUniforms {
    fn zeroed() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

/// Bytes of the per-frame shadow region.
pub const SHADOW_TABLE_BYTES: u64 = std::mem::size_of::<ShadowUniforms>() as u64;

/// The light-space maps' table in the per-frame buffer.
pub static TABLE_REGION: Region = Region::new("light-space maps' table", "Shadows");

/// The per-frame region a frame with shadows writes its table into.
pub fn table_region() -> TableRegion {
    TableRegion {
        region: &TABLE_REGION,
        bytes: SHADOW_TABLE_BYTES,
    }
}

/// A sphere around every object in world space (the directional lights' maps cover it).
fn world_sphere(scene: &Scene, mesh_bounds: &[(Vec3, Vec3)]) -> (Vec3, f32) {
    let mut lo = Vec3::splat(f32::MAX);
    let mut hi = Vec3::splat(f32::MIN);
    for object in &scene.objects {
        let Some(&(a, b)) = mesh_bounds.get(object.mesh) else {
            continue;
        };
        if !(a.is_finite() && b.is_finite()) || a.cmpgt(b).any() {
            continue; // an empty mesh
        }
        for corner in 0..8 {
            let p = Vec3::new(
                if corner & 1 == 0 { a.x } else { b.x },
                if corner & 2 == 0 { a.y } else { b.y },
                if corner & 4 == 0 { a.z } else { b.z },
            );
            let w = object.transform.transform_point3(p);
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    if lo.cmpgt(hi).any() || !(lo.is_finite() && hi.is_finite()) {
        return (Vec3::ZERO, 1.0);
    }
    let center = (lo + hi) * 0.5;
    // At least a millimetre-scale radius: a degenerate (flat) scene still gets a valid map.
    (center, ((hi - lo).length() * 0.5).max(1e-3))
}

/// The view and projection matrices and texel-size parameters of each face of a light.
fn light_faces(kind: LightKind, center: Vec3, radius: f32, tile: u32) -> Vec<(Mat4, Mat4, Vec4)> {
    let tile = tile as f32;
    // Perspective faces: far at the light's range or the scene's farthest point from the
    // light, whichever is nearer, and near at 1/200 of that, which keeps fp32 depth resolution
    // at the far end of a 20-unit span near 1e-4 units (the normal offset covers that). Far
    // must not be the range alone: a light with a range of 1000 units put its near plane 5
    // units out, and a slab 0.9 units from it was missing from its map (no shadow, and a
    // layered medium that took its entry points from the map rendered black).
    let perspective = |position: Vec3, forward: Vec3, up: Vec3, fov: f32, range: f32| {
        // (A tenth more: deforming meshes move a little beyond their rest bounds.)
        let reach = ((position - center).length() + radius) * 1.1;
        let far = range.min(reach).max(1e-3);
        let near = far / 200.0;
        let view = Mat4::look_to_rh(position, forward, up);
        let proj = Mat4::perspective_rh(fov, 1.0, near, far);
        (
            view,
            proj,
            Vec4::new(2.0 * (fov * 0.5).tan() / tile, 0.0, near, far),
        )
    };
    let up_for = |forward: Vec3| {
        if forward.y.abs() > 0.99 {
            Vec3::Z
        } else {
            Vec3::Y
        }
    };
    match kind {
        LightKind::Directional { direction } => {
            let d = direction.normalize_or(Vec3::NEG_Y);
            let eye = center - d * (2.0 * radius);
            let view = Mat4::look_to_rh(eye, d, up_for(d));
            let proj =
                Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, 3.0 * radius);
            // Negative near marks the orthographic face (depth is linear in distance).
            vec![(
                view,
                proj,
                Vec4::new(0.0, 2.0 * radius / tile, -radius, 3.0 * radius),
            )]
        }
        LightKind::Spot {
            position,
            direction,
            range,
            outer_degrees,
            ..
        } => {
            let d = direction.normalize_or(Vec3::NEG_Y);
            // The cone's full angle, with a texel of margin; at most 170 degrees (a wider
            // cone's map would spend its texels at the rim).
            let fov = (2.0 * outer_degrees).clamp(1.0, 170.0).to_radians() * (1.0 + 2.0 / tile);
            vec![perspective(position, d, up_for(d), fov, range)]
        }
        LightKind::Point { position, range } => {
            // Faces +X, -X, +Y, -Y, +Z, -Z: glsl/common/shadows.glsl picks the face by the
            // major axis of (point - light) in this order. A texel of margin on each side
            // keeps the tent filter inside the face at its edges.
            let fov = std::f32::consts::FRAC_PI_2 * (1.0 + 4.0 / tile);
            [
                Vec3::X,
                Vec3::NEG_X,
                Vec3::Y,
                Vec3::NEG_Y,
                Vec3::Z,
                Vec3::NEG_Z,
            ]
            .into_iter()
            .map(|f| perspective(position, f, up_for(f), fov, range))
            .collect()
        }
    }
}

/// The light-space maps' handles.
pub struct ShadowMaps {
    /// Depth atlas.
    pub depth: Handle<Image>,
    /// Translucency material of each texel's first surface (frames with translucency).
    pub ids: Option<Handle<Image>>,
    /// Each texel's first surface's normal and layered material (frames with layered media).
    pub entry: Option<Handle<Image>>,
    /// Each texel's first surface's `TexDep` texels (frames whose layered media read depth
    /// textures; glsl/common/layer_depths.glsl).
    pub layer_depths: Option<Handle<Image>>,
}

/// Declares the `light-space maps` pass. `scene` is `None` for plan-only graphs.
pub fn shadow_pass(
    graph: &mut RenderGraph,
    desc: &ShadowDesc,
    scene: Option<&Arc<SceneGpu>>,
) -> ShadowMaps {
    let (width, height) = desc.extent();
    let info = |format| ImageInfo {
        width,
        height,
        format,
    };
    let mut maps = ShadowMaps {
        depth: graph.create_image("light-space.depth", info(SHADOW_DEPTH_FORMAT)),
        ids: desc
            .transmission_ids
            .then(|| graph.create_image("light-space.ids", info(SHADOW_ID_FORMAT))),
        entry: desc
            .entry
            .then(|| graph.create_image("light-space.entry", info(ENTRY_FORMAT))),
        layer_depths: desc
            .entry
            .then(|| super::layer_depth::layer_depth_format(desc.layer_depth_textures))
            .flatten()
            .map(|f| graph.create_image("light-space.layer-depth", info(f))),
    };
    let mut pass = graph.add_pass("light-space maps", PassKind::Raster);
    if let Some(ids) = &mut maps.ids {
        // Not cleared (a clear of the whole atlas cost as much as drawing it on lavapipe): a
        // texel no object covers keeps depth 1, never nearer than a point, so every lookup
        // counts it lit whatever its ID says.
        pass.color(ids, LoadOp::DontCare);
    }
    if let Some(entry) = &mut maps.entry {
        // Not cleared (a clear of the whole atlas cost as much as drawing it on lavapipe):
        // readers trust a texel's entry only where its depth says a surface was drawn.
        pass.color(entry, LoadOp::DontCare);
    }
    if let Some(depths) = &mut maps.layer_depths {
        // Not cleared, as the entry target (read only where the depth says a surface is).
        pass.color(depths, LoadOp::DontCare);
    }
    pass.depth(&mut maps.depth, LoadOp::Clear([1.0; 4]));
    // Every object into every face's tile, both sides (the benchmark's floor draws the same).
    pass.mesh_draws(MeshDraws {
        views: MeshViews::ShadowFaces {
            origins: (0..desc.faces()).map(|f| desc.tile_origin(f)).collect(),
            tile: desc.tile,
        },
        cull_back: false,
    });
    match scene {
        Some(scene) => pass.execute(ShadowPass {
            scene: scene.clone(),
            desc: desc.clone(),
            pipeline: None,
            depth_sets: Vec::new(),
        }),
        None => pass.finish(),
    }
    maps
}

/// Push constants of the shadow pass (glsl/shadow/depth.vert).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadowConstants {
    model: [[f32; 4]; 4],
    /// x: face index; y: the object's translucency material ID (0: none); z: its layered
    /// material ID (0: none).
    face_id: [i32; 4],
}

struct ShadowPass {
    scene: Arc<SceneGpu>,
    desc: ShadowDesc,
    pipeline: Option<PassPipeline>,
    /// Frames with `TexDep` media: one set per depth-texture pair after the first (the
    /// pipeline's own), each `maps table + the pair`, bound per draw.
    depth_sets: Vec<DescriptorSet>,
}

impl ShadowPass {
    /// The atlas stores `TexDep` texels.
    fn layer_depths(&self) -> bool {
        self.desc.entry && self.desc.layer_depth_textures > 0
    }

    /// Set 0 with depth-texture pair `index` (glsl/shadow/depth.frag): the maps' table, then
    /// in frames with `TexDep` media the pair's textures.
    fn bindings(&self, index: usize) -> Vec<(&'static str, Binding)> {
        let table = Binding::PerFrame(self.scene.per_frame.binding(&TABLE_REGION));
        let mut bindings = vec![(TABLE_REGION.block, table)];
        if let (true, Some(maps)) = (self.layer_depths(), &self.scene.maps) {
            let pair = maps.depth_sets.get(index).copied().unwrap_or([0, 0]);
            bindings.extend(super::layer_depth::depth_map_bindings(
                maps,
                pair,
                self.desc.layer_depth_textures,
            ));
        }
        bindings
    }
}

impl PassExec for ShadowPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let defines = shadow_map_defines(
            self.desc.transmission_ids,
            self.desc.entry,
            self.desc.layer_depth_textures,
        );
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &self.bindings(0),
            &maps_pipeline(
                &defines,
                // The entry target needs the normals.
                if self.desc.entry {
                    VertexInput::Mesh {
                        thickness: false,
                        // TexDep: the UVs where the depth textures are read.
                        surface: self.layer_depths(),
                    }
                } else {
                    VertexInput::Positions
                },
            ),
        )?);
        let pairs = if self.layer_depths() {
            self.scene.maps.as_ref().map_or(0, |m| m.depth_sets.len())
        } else {
            0
        };
        for index in 1..pairs {
            // Identically defined layouts are compatible: these sets bind to the pipeline's.
            let bindings: Vec<Binding> = self.bindings(index).into_iter().map(|b| b.1).collect();
            let set = DescriptorSet::new(
                ctx,
                &bindings,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                "light-space depth maps",
                ctx.slots,
            )?;
            self.depth_sets.push(set);
        }
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        let device = &ctx.gpu.device;
        // The depth-texture set bound (pair 0 is the pipeline's own); bindings outlast the
        // viewport changes between faces.
        let mut bound_pair = 0usize;
        for face in 0..self.desc.faces() {
            super::util::set_tile_viewport(ctx, self.desc.tile_origin(face), self.desc.tile);
            for draw in &self.scene.draws {
                if self.layer_depths() && draw.depth_maps != bound_pair {
                    let set = match draw.depth_maps {
                        0 => &pipeline.set,
                        i => &self.depth_sets[i - 1],
                    };
                    set.bind(ctx, pipeline.pipeline.layout, 0);
                    bound_pair = draw.depth_maps;
                }
                let constants = ShadowConstants {
                    model: draw.constants.model,
                    face_id: [
                        face as i32,
                        draw.constants.thickness[3] as i32,
                        draw.constants.roughness[2] as i32,
                        0,
                    ],
                };
                // SAFETY: the bound pipeline's layout has this push-constant range.
                unsafe {
                    device.cmd_push_constants(
                        ctx.cmd,
                        pipeline.pipeline.layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&constants),
                    );
                }
                self.scene.meshes[draw.mesh].draw(
                    device,
                    ctx.cmd,
                    ctx.frame,
                    false,
                    self.layer_depths(),
                );
            }
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        for mut set in self.depth_sets.drain(..) {
            set.destroy(&gpu.device);
        }
    }
}

/// One draw of a host's mesh into the light-space maps ([`host_shadow_pass`]): its vertex
/// buffers (bindings 0 and 1 of the host's layout, each with its byte offset), its index
/// buffer (with offset and type; `None`: a non-indexed draw), how many indices (or vertices)
/// from which first one, the model matrix, its layered material ID (0: it only casts) and,
/// when the maps store `TexDep` texels, the set of [`HostDepthTextures::layout`] binding the
/// maps' table and its depth textures (null otherwise).
#[derive(Clone, Copy, Debug)]
pub(crate) struct HostShadowDraw {
    pub vertex_buffers: [(vk::Buffer, vk::DeviceSize); 2],
    pub indices: Option<(vk::Buffer, vk::DeviceSize, vk::IndexType)>,
    pub count: u32,
    pub first: u32,
    pub vertex_offset: i32,
    pub model: Mat4,
    pub layered_id: u8,
    pub depth_set: vk::DescriptorSet,
}

/// The light-space maps of a host's meshes store Li et al.'s `TexDep` texels at each entry
/// point, read from each draw's own depth textures: the pass's set 0 is laid out as
/// [`HostDepthTextures::bindings`] says (the maps' table, then `textures` sampled textures),
/// and every draw binds its own set of that layout ([`HostShadowDraw::depth_set`], written by
/// the effect before the frame records).
#[derive(Clone, Copy, Debug)]
pub(crate) struct HostDepthTextures {
    /// The layout of every draw's set.
    pub layout: vk::DescriptorSetLayout,
    /// Depth textures per draw (1 or 2).
    pub textures: usize,
}

impl HostDepthTextures {
    /// Set 0's bindings in order (glsl/shadow/depth.frag names them): the maps' table (a
    /// per-frame uniform), then `depth_map0` and, with two textures, `depth_map1`.
    pub fn bindings(textures: usize) -> Vec<crate::backend::bindings::SetBinding<'static>> {
        use crate::backend::bindings::SetBinding;
        let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        let mut bindings = vec![SetBinding {
            name: Some(TABLE_REGION.block),
            kind: vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC,
        }];
        for name in super::layer_depth::DEPTH_MAP_NAMES
            .into_iter()
            .take(textures.clamp(1, 2))
        {
            bindings.push(SetBinding {
                name: Some(name),
                kind: sampled,
            });
        }
        bindings
    }
}

/// What [`host_shadow_pass`] draws in the frame being recorded: each face's square tile
/// (origin and edge, in face order) and the draws, every draw into every face. The effect
/// fills it just before it records the frame.
#[derive(Clone, Debug, Default)]
pub(crate) struct HostShadowFrame {
    pub tiles: Vec<((u32, u32), u32)>,
    pub draws: Vec<HostShadowDraw>,
}

/// Declares the `light-space maps` pass of a host's meshes (`lucent::embed::LayeredEffect`):
/// a depth atlas of `extent` and its entry target (each texel's first surface's normal and
/// layered material), drawn with the same shaders as lucent's own maps from the host's vertex
/// and index buffers laid out as `input` says, the draws and faces `frame` holds when the
/// pass records. Its table is the shadow table region, as lucent's own.
///
/// With `depth_textures`, the maps also store each entry point's `TexDep` texels from the
/// draws' own depth textures, read at the layout's texture coordinate.
pub(crate) fn host_shadow_pass(
    graph: &mut RenderGraph,
    (width, height): (u32, u32),
    input: crate::backend::pipeline::HostVertexInput,
    frame: Arc<std::sync::Mutex<HostShadowFrame>>,
    scene: &Arc<SceneGpu>,
    depth_textures: Option<HostDepthTextures>,
) -> ShadowMaps {
    let info = |format| ImageInfo {
        width,
        height,
        format,
    };
    let mut maps = ShadowMaps {
        depth: graph.create_image("light-space.depth", info(SHADOW_DEPTH_FORMAT)),
        ids: None,
        entry: Some(graph.create_image("light-space.entry", info(ENTRY_FORMAT))),
        layer_depths: depth_textures
            .and_then(|d| super::layer_depth::layer_depth_format(d.textures))
            .map(|format| graph.create_image("light-space.layer-depth", info(format))),
    };
    let mut pass = graph.add_pass("light-space maps", PassKind::Raster);
    if let Some(entry) = &mut maps.entry {
        // Not cleared, as lucent's own: readers trust an entry only where the depth says a
        // surface was drawn.
        pass.color(entry, LoadOp::DontCare);
    }
    if let Some(depths) = &mut maps.layer_depths {
        // The same: read only where the entry is a surface's.
        pass.color(depths, LoadOp::DontCare);
    }
    pass.depth(&mut maps.depth, LoadOp::Clear([1.0; 4]));
    pass.execute(HostShadowPass {
        scene: scene.clone(),
        input,
        frame,
        depth_textures,
        pipeline: None,
    });
    maps
}

struct HostShadowPass {
    scene: Arc<SceneGpu>,
    input: crate::backend::pipeline::HostVertexInput,
    frame: Arc<std::sync::Mutex<HostShadowFrame>>,
    depth_textures: Option<HostDepthTextures>,
    pipeline: Option<HostShadowPipeline>,
}

/// The host maps pass's pipeline: with its own set (the maps' table), or laid out for the
/// draws' sets of depth textures.
enum HostShadowPipeline {
    Plain(PassPipeline),
    DepthTextures(crate::backend::pipeline::GraphicsPipeline),
}

impl HostShadowPipeline {
    fn layout(&self) -> vk::PipelineLayout {
        match self {
            HostShadowPipeline::Plain(p) => p.pipeline.layout,
            HostShadowPipeline::DepthTextures(p) => p.layout,
        }
    }
}

impl PassExec for HostShadowPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let textures = self.depth_textures.map_or(0, |d| d.textures);
        let defines = shadow_map_defines(false, true, textures);
        let input = VertexInput::Host(self.input);
        let desc = maps_pipeline(&defines, input);
        self.pipeline = Some(match self.depth_textures {
            None => HostShadowPipeline::Plain(PassPipeline::new(
                ctx,
                &[(
                    TABLE_REGION.block,
                    Binding::PerFrame(self.scene.per_frame.binding(&TABLE_REGION)),
                )],
                &desc,
            )?),
            Some(depth) => {
                let layouts = [depth.layout];
                let bindings = HostDepthTextures::bindings(depth.textures);
                HostShadowPipeline::DepthTextures(crate::backend::pipeline::GraphicsPipeline::new(
                    ctx,
                    &GraphicsPipelineDesc {
                        set_layouts: &layouts,
                        bindings: &bindings,
                        ..desc
                    },
                )?)
            }
        });
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        // A poisoned lock means a panic elsewhere while filling it: draw nothing rather than
        // half a frame.
        let Ok(frame) = self.frame.lock() else {
            return;
        };
        let device = &ctx.gpu.device;
        match pipeline {
            HostShadowPipeline::Plain(p) => p.bind(ctx),
            // SAFETY: the pipeline is alive; the executor began this pass's subpass.
            HostShadowPipeline::DepthTextures(p) => unsafe {
                device.cmd_bind_pipeline(ctx.cmd, vk::PipelineBindPoint::GRAPHICS, p.pipeline);
            },
        }
        let layout = pipeline.layout();
        // The draws' sets bind the table at the recorded slot, as a pass's own set does.
        let table_offset = [(self.scene.per_frame.binding(&TABLE_REGION).stride
            * ctx.frame as u64) as u32];
        let streams = 1 + usize::from(self.input.strides[1] > 0);
        // Bindings outlast the viewport changes between faces.
        let mut bound = vk::DescriptorSet::null();
        for (face, &(origin, edge)) in frame.tiles.iter().enumerate() {
            super::util::set_tile_viewport(ctx, origin, edge);
            for draw in &frame.draws {
                if matches!(pipeline, HostShadowPipeline::DepthTextures(_))
                    && draw.depth_set != bound
                {
                    // SAFETY: the draw's set was written for this frame's slot with this
                    // pipeline's set layout (LayeredEffect) and lives until the slot records
                    // again.
                    unsafe {
                        device.cmd_bind_descriptor_sets(
                            ctx.cmd,
                            vk::PipelineBindPoint::GRAPHICS,
                            layout,
                            0,
                            &[draw.depth_set],
                            &table_offset,
                        );
                    }
                    bound = draw.depth_set;
                }
                let constants = ShadowConstants {
                    model: draw.model.to_cols_array_2d(),
                    face_id: [face as i32, 0, i32::from(draw.layered_id), 0],
                };
                let buffers = draw.vertex_buffers.map(|(buffer, _)| buffer);
                let offsets = draw.vertex_buffers.map(|(_, offset)| offset);
                // SAFETY: recording inside the pass's render pass with its pipeline bound; the
                // host's buffers are valid for the frame (its contract, checked non-null).
                unsafe {
                    device.cmd_push_constants(
                        ctx.cmd,
                        layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&constants),
                    );
                    device.cmd_bind_vertex_buffers(
                        ctx.cmd,
                        0,
                        &buffers[..streams],
                        &offsets[..streams],
                    );
                    match draw.indices {
                        Some((buffer, offset, index_type)) => {
                            device.cmd_bind_index_buffer(ctx.cmd, buffer, offset, index_type);
                            device.cmd_draw_indexed(
                                ctx.cmd,
                                draw.count,
                                1,
                                draw.first,
                                draw.vertex_offset,
                                0,
                            );
                        }
                        None => device.cmd_draw(ctx.cmd, draw.count, 1, draw.first, 0),
                    }
                }
            }
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        match self.pipeline.take() {
            Some(HostShadowPipeline::Plain(mut p)) => p.destroy(&gpu.device),
            Some(HostShadowPipeline::DepthTextures(mut p)) => p.destroy(&gpu.device),
            None => {}
        }
    }
}

/// The light-space maps pipeline of lucent's meshes or a host's (`vertex_input`): depth
/// tested, both faces drawn (open meshes, the floor or a leaf, cast from both sides), each
/// draw's face and model pushed.
fn maps_pipeline<'a>(
    defines: &'a [(&'a str, &'a str)],
    vertex_input: VertexInput,
) -> GraphicsPipelineDesc<'a> {
    GraphicsPipelineDesc {
        vertex: SHADOW_VERTEX,
        fragment: SHADOW_FRAGMENT,
        defines,
        vertex_input,
        depth_test: true,
        cull_back: false,
        additive_attachments: 0,
        set_layouts: &[],
        bindings: &[],
        push_constant_bytes: std::mem::size_of::<ShadowConstants>() as u32,
        specialization: &[],
        name: "light-space maps",
    }
}

/// The light-space maps pass's shaders.
const SHADOW_VERTEX: &str = "shadow/depth.vert";
const SHADOW_FRAGMENT: &str = "shadow/depth.frag";

/// The light-space maps pass's defines: the translucency ID target (`ids`), the entry target
/// (`entry`: frames with layered media) and, with `entry`, the `TexDep` texels of
/// `layer_depth_textures` depth textures (0: none).
pub(crate) fn shadow_map_defines(
    ids: bool,
    entry: bool,
    layer_depth_textures: usize,
) -> Vec<(&'static str, &'static str)> {
    let mut defines: Vec<(&str, &str)> = Vec::new();
    if ids {
        defines.push(("LUCENT_SHADOW_IDS", "1"));
    }
    if entry {
        defines.push(("LUCENT_SHADOW_ENTRY", "1"));
        defines.push(("LUCENT_ENTRY_LOCATION", if ids { "1" } else { "0" }));
    }
    if entry && layer_depth_textures > 0 {
        defines.push((
            "LUCENT_LAYER_DEPTHS",
            super::layer_depth::layer_depths_define(layer_depth_textures),
        ));
        defines.push(("LUCENT_LAYER_DEPTH_LOCATION", if ids { "2" } else { "1" }));
    }
    defines
}

/// The pipelines the light-space maps pass of any frame builds.
pub(crate) fn shader_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    for ids in [false, true] {
        for entry in [false, true] {
            for textures in 0..=2 {
                out.push(crate::backend::shader::PipelineShaders::new(
                    SHADOW_VERTEX,
                    SHADOW_FRAGMENT,
                    &shadow_map_defines(ids, entry, textures),
                ));
            }
        }
    }
}

/// The defines of a pass that looks up the light-space maps (glsl/common/shadows.glsl; its
/// bindings go by their names).
pub const LIGHTING_DEFINES: [(&str, &str); 1] = [("LUCENT_SHADOWS", "1")];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{builtin, Light};

    #[test]
    fn faces_follow_the_lights_that_cast() {
        let mut scene = builtin::builtin("layered").unwrap();
        let settings = ShadowSettings::default();
        let desc = ShadowDesc::new(&scene, &settings, false).unwrap();
        // A point light (six faces) and a spot light (one).
        assert_eq!(desc.light_faces, vec![6, 1]);
        assert_eq!((desc.columns, desc.rows), (3, 3));
        assert_eq!(desc.extent(), (3072, 3072));
        scene.lights[0].shadows = false;
        assert_eq!(
            ShadowDesc::new(&scene, &settings, false).unwrap().faces(),
            1
        );
        scene.lights[1].shadows = false;
        assert!(ShadowDesc::new(&scene, &settings, false).is_none());
        let off = ShadowSettings {
            enabled: false,
            ..settings
        };
        assert!(ShadowDesc::new(&builtin::builtin("layered").unwrap(), &off, false).is_none());
    }

    #[test]
    fn many_faces_shrink_the_tile_to_fit_the_atlas() {
        let mut scene = builtin::builtin("layered").unwrap();
        scene.lights = (0..MAX_LIGHTS)
            .map(|i| Light::point(Vec3::new(i as f32, 3.0, 0.0), Vec3::ONE, 1.0, 10.0))
            .collect();
        let desc = ShadowDesc::new(&scene, &ShadowSettings::default(), false).unwrap();
        assert_eq!(desc.faces() as usize, MAX_SHADOW_FACES);
        let (w, h) = desc.extent();
        assert!(w <= MAX_ATLAS_EXTENT && h <= MAX_ATLAS_EXTENT, "{w}x{h}");
        assert_eq!(desc.tile, 256);
    }

    #[test]
    fn every_face_sees_the_points_it_is_picked_for() {
        // The shader picks a point light's face by the major axis of (point - light): that
        // face's frustum must contain the point, its depth in [0, 1].
        let light = LightKind::Point {
            position: Vec3::new(0.5, 2.0, -1.0),
            range: 10.0,
        };
        let faces = light_faces(light, Vec3::ZERO, 5.0, 512);
        let mut seed = 1u32;
        let mut rand = || {
            seed = seed.wrapping_mul(1664525).wrapping_add(1013904223);
            (seed >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        for _ in 0..2000 {
            let d = Vec3::new(rand(), rand(), rand()) * 4.0;
            if d.length() < 0.2 {
                continue;
            }
            let a = d.abs();
            let axis = if a.x >= a.y && a.x >= a.z {
                0
            } else if a.y >= a.z {
                1
            } else {
                2
            };
            let face = axis * 2 + usize::from(d[axis] < 0.0);
            let clip =
                (faces[face].1 * faces[face].0) * (Vec3::new(0.5, 2.0, -1.0) + d).extend(1.0);
            let ndc = clip.truncate() / clip.w;
            assert!(clip.w > 0.0, "{d}");
            assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{d}: {ndc}");
            assert!((0.0..=1.0).contains(&ndc.z), "{d}: {ndc}");
        }
    }

    #[test]
    fn a_long_range_light_keeps_the_geometry_near_it_in_its_map() {
        // Issue 26's back-lit slab: 2 x 2 x 0.2 units at the origin, a point light 1 unit
        // behind it with a range of 1000. The slab's back face (0.9 units from the light)
        // must lie between the -Z face's planes, as must the far corners of the slab.
        let position = Vec3::new(0.0, 0.0, -1.0);
        let (center, radius) = (Vec3::ZERO, Vec3::new(1.0, 1.0, 0.1).length());
        for range in [10.0, 1000.0, 1e7] {
            let faces = light_faces(LightKind::Point { position, range }, center, radius, 512);
            let plus_z = faces[4].1 * faces[4].0; // +Z: from the light towards the slab
            for p in [Vec3::new(0.0, 0.0, -0.1), Vec3::new(0.0, 0.0, 0.1)] {
                let clip = plus_z * p.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!(
                    clip.w > 0.0 && (0.0..=1.0).contains(&ndc.z),
                    "range {range}: {p}: {ndc}"
                );
            }
            // Far follows the scene, not the range: depth precision is spent on what is there.
            assert!(
                faces[4].2.w <= 1.1 * (1.0 + radius) + 1e-4,
                "range {range}: {}",
                faces[4].2
            );
        }
    }

    #[test]
    fn a_directional_map_covers_the_whole_scene() {
        let scene = builtin::builtin("cubes").unwrap();
        let bounds = crate::gpu_scene::tiles::mesh_bounds(&scene);
        let (center, radius) = world_sphere(&scene, &bounds);
        let faces = light_faces(
            LightKind::Directional {
                direction: Vec3::new(0.3, -1.0, -0.2),
            },
            center,
            radius,
            1024,
        );
        for object in &scene.objects {
            let (a, b) = bounds[object.mesh];
            for p in [a, b] {
                let w = object.transform.transform_point3(p);
                let clip = (faces[0].1 * faces[0].0) * w.extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!(ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0, "{ndc}");
                assert!((0.0..=1.0).contains(&ndc.z), "{ndc}");
            }
        }
    }
}
