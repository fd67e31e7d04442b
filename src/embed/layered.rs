//! [`LayeredEffect`]: Li et al.'s layered media (single scattering along the refracted view
//! ray, light transmitted through the object, and the dipole's multiple scattering) added to a
//! host's lit diffuse, on the host's own G-buffer and drawn from the host's own meshes.
//!
//! The host describes, for each of its materials that is a layered medium, its ID in the
//! host's material ID image and its medium ([`LayeredMaterial`]: lucent's `[material.layers]`,
//! a [`LayeredMedium`]). Each frame it hands over its lights, its environment, its G-buffer
//! (depth, normals, material IDs) and the meshes it drew ([`MeshDraw`]: its own vertex and
//! index buffers, laid out as the description's [`VertexLayout`] says, each with its model
//! matrix and material ID). lucent then records, into the host's command buffer:
//!
//! 1. `light-space maps`: every mesh drawn into each face of the frame's [`ShadowFace`]s, into
//!    lucent's own depth atlas (of the description's size) and its entry target (the first
//!    surface's normal and layered material: where light enters an object). The same shaders
//!    as lucent's own maps; the faces' matrices are the host's (a host that renders shadow
//!    maps already passes the same faces).
//! 2. The passes of lucent's own frame (src/features/layered): the transmitted irradiance,
//!    the dipole's gather over it, its blur, and single scattering, which adds
//!    `λ3 L_t + λ4 L_ss + λ5 L_ms` into the host's lit diffuse. The same shaders, reading the
//!    host's G-buffer as it is encoded: the ID bit field, each ID's material and the normal
//!    encoding are specialization constants (`LayeredDecode`, whose defaults are lucent's own
//!    G-buffer), unsigned IDs and linear depth defines (`LayeredHost`).
//!
//! Eq. 3's `λ1 L_d + λ2 L_s` is the host's own lighting: a host weights its diffuse and
//! specular light of a layered material by the medium's `weights[0]` and `weights[1]`, as
//! lucent's G-buffer does. The medium's lengths are scaled by the G-buffer's
//! [`GBufferDesc::metres_per_unit`], not by its own `units_per_mm`.
//!
//! A host with an albedo image may use it as the layered materials' film
//! ([`LayeredEffectDesc::with_film`]: lucent's `post` texturing of a layered material, the
//! albedo texture multiplying the light leaving the surface). Layers whose thickness is read
//! from depth textures (Li et al.'s `TexDep`) take the texels at each pixel from the host's
//! G-buffer ([`GBufferDesc::with_layer_depths`], written with TERMS'
//! `lucent_pack_layer_texels`) and, at each light's entry point, from each mesh's own
//! textures ([`MeshDraw::with_depth_textures`], read at [`VertexLayout::uv`]) in lucent's
//! light-space maps (`super::depth_textures`: a set per distinct pair, per frame).

use std::sync::{Arc, Mutex};

use ash::vk;
use glam::Mat4;

use super::depth_textures::DepthTextureSets;
use super::image::{distinct_inputs, HostImage, Role};
use super::passes::{
    check_described, check_environment, check_lights, check_material_id, check_views, depth_role,
    id_role, import_host_image, EffectPasses,
};
use super::regions::{box_nearest_depth, box_screen_region, clipped};
use super::shadow_faces::{shadow_table, ShadowFace};
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::backend::format::format_name;
use crate::backend::pipeline::HostVertexInput;
use crate::error::HostError;
use crate::features::capabilities::{require, Effect};
use crate::features::gbuffer_desc::{DepthEncoding, GBufferDesc, HostCamera};
use crate::features::layered::{
    blurs_on_screen, layered_passes, LayeredDecode, LayeredDesc, LayeredHost, LayeredInputs,
    LayeredKnobs, LayeredTableGpu, MAX_LAYERED_MATERIALS, TABLE_REGION,
};
use crate::features::shadows::{
    self, host_shadow_pass, HostDepthTextures, HostShadowDraw, HostShadowFrame, ShadowUniforms,
    MAX_ATLAS_EXTENT,
};
use crate::gpu_scene::{SceneGpu, SceneUpload, TableRegion, TileRect, FRAME};
use crate::graph::{RenderGraph, ResourceId};
use crate::scene::layered::LayeredMedium;
use crate::scene::{Environment, Light};
use crate::Result;

/// One material of the host that is a layered medium: its ID in the host's material ID image
/// and its medium.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct LayeredMaterial {
    /// The host's ID (1 to 255; 0 is taken to mean "not layered").
    pub id: u8,
    /// The medium (its layers, index and eq. 3's weights; its `units_per_mm` is replaced by
    /// the G-buffer's world scale).
    pub medium: LayeredMedium,
}

impl LayeredMaterial {
    /// Material `id` with `medium`.
    pub fn new(id: u8, medium: LayeredMedium) -> Self {
        Self { id, medium }
    }
}

/// One attribute of the host's vertices: the vertex buffer binding it is read from (0 or 1),
/// its format and its byte offset within a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct VertexAttribute {
    /// The binding (0 or 1: [`MeshDraw::vertex_buffers`]).
    pub binding: u32,
    /// Its format: positions `R32G32B32_SFLOAT`, `R32G32B32A32_SFLOAT` or
    /// `R16G16B16A16_SFLOAT`; normals those or `R8G8B8A8_SNORM`, `R16G16B16A16_SNORM`,
    /// `A2B10G10R10_SNORM_PACK32` (each where the device reads it from vertex buffers).
    pub format: vk::Format,
    /// Byte offset within a vertex.
    pub offset: u32,
}

impl VertexAttribute {
    /// An attribute of `format` at `offset` in binding `binding`.
    pub fn new(binding: u32, format: vk::Format, offset: u32) -> Self {
        Self {
            binding,
            format,
            offset,
        }
    }
}

/// How the host's vertex buffers hold the positions and normals lucent draws its light-space
/// maps with (and, for depth textures, the texture coordinate): up to two bindings (a stride
/// each; 0: unused) and where each attribute is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct VertexLayout {
    /// Bytes between consecutive vertices of bindings 0 and 1 (0: the binding is unused).
    pub strides: [u32; 2],
    /// The object-space position.
    pub position: VertexAttribute,
    /// The object-space normal (outward; it need not be unit length).
    pub normal: VertexAttribute,
    /// The texture coordinate where the mesh's depth textures are read, for layered
    /// materials whose layers read their thickness from them (Li et al.'s `TexDep`;
    /// [`MeshDraw::with_depth_textures`]): `R32G32_SFLOAT`, `R16G16_SFLOAT` or
    /// `R16G16_UNORM`. `None`: no mesh has depth textures.
    pub uv: Option<VertexAttribute>,
}

impl VertexLayout {
    /// One interleaved stream of `stride` bytes: an `f32` position at `position_offset` and an
    /// `f32` normal at `normal_offset`.
    pub fn interleaved(stride: u32, position_offset: u32, normal_offset: u32) -> Self {
        let vec3 = vk::Format::R32G32B32_SFLOAT;
        Self {
            strides: [stride, 0],
            position: VertexAttribute::new(0, vec3, position_offset),
            normal: VertexAttribute::new(0, vec3, normal_offset),
            uv: None,
        }
    }

    /// Any layout: the bindings' strides and the two attributes.
    pub fn new(strides: [u32; 2], position: VertexAttribute, normal: VertexAttribute) -> Self {
        Self {
            strides,
            position,
            normal,
            uv: None,
        }
    }

    /// With the texture coordinate the meshes' depth textures are read at.
    pub fn with_uv(mut self, uv: VertexAttribute) -> Self {
        self.uv = Some(uv);
        self
    }

    /// The layout as the pipeline takes it, each attribute checked: in a used binding, within
    /// its stride, in a format the device reads from vertex buffers.
    fn check(&self, gpu: &crate::backend::GpuContext) -> Result<HostVertexInput> {
        // Vulkan's guaranteed minimums of maxVertexInputBindingStride and
        // maxVertexInputAttributeOffset.
        const MAX_STRIDE: u32 = 2048;
        const MAX_OFFSET: u32 = 2047;
        if self.strides.iter().any(|&s| s > MAX_STRIDE) || self.strides[0] == 0 {
            return Err(HostError::Description {
                field: "vertices.strides".into(),
                problem: format!(
                    "{:?}: binding 0 is used (stride > 0), and strides are at most {MAX_STRIDE}",
                    self.strides
                ),
            }
            .into());
        }
        let vec3 = vk::Format::R32G32B32_SFLOAT;
        let vec4 = vk::Format::R32G32B32A32_SFLOAT;
        let half4 = vk::Format::R16G16B16A16_SFLOAT;
        // Each accepted format with its bytes.
        let positions = [(vec3, 12), (vec4, 16), (half4, 8)];
        let normals = [
            (vec3, 12),
            (vec4, 16),
            (half4, 8),
            (vk::Format::R8G8B8A8_SNORM, 4),
            (vk::Format::R16G16B16A16_SNORM, 8),
            (vk::Format::A2B10G10R10_SNORM_PACK32, 4),
        ];
        let uvs = [
            (vk::Format::R32G32_SFLOAT, 8),
            (vk::Format::R16G16_SFLOAT, 4),
            (vk::Format::R16G16_UNORM, 4),
        ];
        let mut attributes = [(0, vec3, 0); 3];
        for (k, (name, attribute, accepted)) in [
            ("vertices.position", self.position, &positions[..]),
            ("vertices.normal", self.normal, &normals[..]),
        ]
        .into_iter()
        .chain(self.uv.map(|uv| ("vertices.uv", uv, &uvs[..])))
        .enumerate()
        {
            let names: Vec<String> = accepted.iter().map(|&(f, _)| format_name(f)).collect();
            let bytes = accepted
                .iter()
                .find(|(f, _)| *f == attribute.format)
                .map(|&(_, bytes)| bytes);
            let readable = bytes.is_some() && {
                // SAFETY: a query of the host's physical device.
                let properties = unsafe {
                    gpu.instance.get_physical_device_format_properties(
                        gpu.physical_device,
                        attribute.format,
                    )
                };
                properties
                    .buffer_features
                    .contains(vk::FormatFeatureFlags::VERTEX_BUFFER)
            };
            if !readable {
                return Err(HostError::Unsupported {
                    input: name.into(),
                    found: format!("format {}", format_name(attribute.format)),
                    accepted: format!("{} (read from vertex buffers)", names.join(", ")),
                }
                .into());
            }
            let bytes = bytes.unwrap_or(0);
            let stride = self
                .strides
                .get(attribute.binding as usize)
                .copied()
                .unwrap_or(0);
            if stride == 0 || attribute.offset > MAX_OFFSET || attribute.offset + bytes > stride {
                return Err(HostError::Description {
                    field: name.into(),
                    problem: format!(
                        "{attribute:?}: its binding must be 0 or 1 with a stride, and its {bytes} \
                         bytes at its offset (at most {MAX_OFFSET}) within that stride \
                         ({stride})"
                    ),
                }
                .into());
            }
            attributes[k] = (attribute.binding, attribute.format, attribute.offset);
        }
        Ok(HostVertexInput {
            strides: self.strides,
            position: attributes[0],
            normal: attributes[1],
            uv: self.uv.map(|_| attributes[2]),
        })
    }
}

/// What a [`LayeredEffect`] is built for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct LayeredEffectDesc {
    /// The host's G-buffer: it must describe its normals and material IDs.
    pub gbuffer: GBufferDesc,
    /// The layered materials (1 to 16 of them).
    pub materials: Vec<LayeredMaterial>,
    /// How the host's vertex buffers hold positions and normals.
    pub vertices: VertexLayout,
    /// The size of lucent's light-space atlas (each side 16 to 8192 texels), which every
    /// frame's [`LayeredFrame::light_faces`] lie in.
    pub light_space: vk::Extent2D,
    /// Li et al.'s knobs (march steps, pixel lights, phase function, resolutions).
    pub knobs: LayeredKnobs,
    /// Views recorded per frame (1 to [`super::MAX_VIEWS_PER_FRAME`]).
    pub views_per_frame: usize,
    /// The host's albedo image multiplies the light leaving the layered surfaces (a pigment
    /// film: lucent's `post` texturing of a layered material); needs the G-buffer's albedo.
    pub film: bool,
}

impl LayeredEffectDesc {
    /// The effect over `gbuffer` for `materials`, drawing meshes laid out as `vertices` into a
    /// light-space atlas of `light_space`, with the default knobs, one view a frame.
    pub fn new(
        gbuffer: GBufferDesc,
        materials: Vec<LayeredMaterial>,
        vertices: VertexLayout,
        light_space: vk::Extent2D,
    ) -> Self {
        Self {
            gbuffer,
            materials,
            vertices,
            light_space,
            knobs: LayeredKnobs::default(),
            views_per_frame: 1,
            film: false,
        }
    }

    /// With the host's albedo image as the layered materials' film (the frame's
    /// [`LayeredImages::albedo`]).
    pub fn with_film(mut self) -> Self {
        self.film = true;
        self
    }

    /// With these knobs.
    pub fn with_knobs(mut self, knobs: LayeredKnobs) -> Self {
        self.knobs = knobs;
        self
    }

    /// With this many views per frame.
    pub fn with_views_per_frame(mut self, views: usize) -> Self {
        self.views_per_frame = views;
        self
    }
}

/// A host's index buffer: the buffer, the byte offset of index 0 and the index type
/// (`UINT16` or `UINT32`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IndexBuffer {
    /// The buffer (with `INDEX_BUFFER` usage).
    pub buffer: vk::Buffer,
    /// Byte offset of index 0.
    pub offset: vk::DeviceSize,
    /// `UINT16` or `UINT32`.
    pub index_type: vk::IndexType,
}

/// One mesh the host drew this frame, as lucent draws it into its light-space maps: the
/// host's buffers (valid until the frame completes), the range drawn, its model matrix and
/// its material ID (the host's; an ID without a [`LayeredMaterial`] casts shadows only).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct MeshDraw {
    /// The vertex buffers of bindings 0 and 1 (with `VERTEX_BUFFER` usage), each with the
    /// byte offset of vertex 0; binding 1's is ignored when the layout does not use it.
    pub vertex_buffers: [(vk::Buffer, vk::DeviceSize); 2],
    /// The index buffer; `None`: the vertices are drawn in order.
    pub indices: Option<IndexBuffer>,
    /// Indices (or, without an index buffer, vertices) drawn: a multiple of 3 (triangles).
    pub count: u32,
    /// The first index (or vertex).
    pub first: u32,
    /// Added to each index before the vertex is fetched.
    pub vertex_offset: i32,
    /// Object to world.
    pub transform: Mat4,
    /// The host's material ID of the mesh.
    pub material_id: u8,
    /// The mesh's bounding box in its own space (`None`: not given). When every layered mesh
    /// of a frame has one, the term's blur draws only over the meshes whose medium it acts on
    /// at their distance, as in lucent's own frames, instead of over every layered region.
    pub bounds: Option<(glam::Vec3, glam::Vec3)>,
    /// The mesh's depth textures, for a material whose layers read their thickness from
    /// them (Li et al.'s `TexDep`: layer `i` reads channel `i % 4` of texture `i / 4`, at
    /// the layout's [`VertexLayout::uv`]): views of sampled images in
    /// `SHADER_READ_ONLY_OPTIMAL`, written before the frame's submission and valid until it
    /// completes; the second null when the medium reads one. Required for such a material,
    /// refused for any other.
    pub depth_textures: Option<[vk::ImageView; 2]>,
}

impl MeshDraw {
    /// `count` vertices of `vertex_buffer` (binding 0, offset 0) in order, three per
    /// triangle, placed by `transform`, of material `material_id`.
    pub fn new(vertex_buffer: vk::Buffer, count: u32, transform: Mat4, material_id: u8) -> Self {
        Self {
            vertex_buffers: [(vertex_buffer, 0), (vk::Buffer::null(), 0)],
            indices: None,
            count,
            first: 0,
            vertex_offset: 0,
            transform,
            material_id,
            bounds: None,
            depth_textures: None,
        }
    }

    /// This draw with its depth textures (`second`: for a medium with more than four layers).
    pub fn with_depth_textures(
        mut self,
        first: vk::ImageView,
        second: Option<vk::ImageView>,
    ) -> Self {
        self.depth_textures = Some([first, second.unwrap_or_default()]);
        self
    }

    /// This draw with its object-space bounding box.
    pub fn with_bounds(mut self, low: glam::Vec3, high: glam::Vec3) -> Self {
        self.bounds = Some((low, high));
        self
    }

    /// This draw through `indices` (`count` then counts indices).
    pub fn with_indices(mut self, indices: IndexBuffer) -> Self {
        self.indices = Some(indices);
        self
    }

    /// This draw with binding 1's vertex buffer (for layouts with two bindings).
    pub fn with_second_binding(mut self, buffer: vk::Buffer, offset: vk::DeviceSize) -> Self {
        self.vertex_buffers[1] = (buffer, offset);
        self
    }
}

/// The host's images for one view of one frame, each with its current and final state.
#[derive(Clone, Copy, Debug)]
pub struct LayeredImages<'a> {
    /// The depth image (a depth format's view of its depth aspect, or linear depth).
    pub depth: &'a HostImage,
    /// The normals.
    pub normals: &'a HostImage,
    /// The material IDs (for stencil bits: a view of the depth-stencil image's stencil
    /// aspect).
    pub material_ids: &'a HostImage,
    /// The albedo, the layered materials' film: required with
    /// [`LayeredEffectDesc::with_film`], refused without.
    pub albedo: Option<&'a HostImage>,
    /// The `TexDep` texels ([`GBufferDesc::with_layer_depths`]): required when a material's
    /// layers read their thickness from depth textures, refused otherwise.
    pub layer_depths: Option<&'a HostImage>,
}

/// One view of one frame: what [`LayeredEffect::record`] reads and adds to.
#[derive(Clone, Copy, Debug)]
pub struct LayeredFrame<'a> {
    /// The frame-in-flight slot (0 to the frames in flight of the [`Lucent`]).
    pub slot: usize,
    /// The view within the frame.
    pub view: usize,
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The host's lights this frame, in its world (at most [`crate::scene::MAX_LIGHTS`]).
    pub lights: &'a [Light],
    /// The environment whose light enters the media (Li et al.'s ambient term; `None`: none).
    pub environment: Option<&'a Environment>,
    /// The faces lucent draws its light-space maps with (at most
    /// `crate::features::shadows::MAX_SHADOW_FACES`), each light's together and in order,
    /// their rectangles inside [`LayeredEffectDesc::light_space`]. A light without faces
    /// lights the media unshadowed, and its entry points are the shaded surface's plane.
    pub light_faces: &'a [ShadowFace],
    /// The meshes drawn into the maps: every object that casts, layered or not.
    pub meshes: &'a [MeshDraw],
    /// The images.
    pub images: LayeredImages<'a>,
    /// Screen rectangles the layered materials may cover this frame; empty: the whole
    /// screen. Clipped to the G-buffer.
    pub regions: &'a [vk::Rect2D],
    /// The host's lit diffuse light, which the terms are added to (a colour attachment of the
    /// description's diffuse format that can be blended; its contents are kept, so it cannot
    /// come in UNDEFINED).
    pub lighting: &'a HostImage,
}

/// The graph's imports, by input.
#[derive(Clone, Copy, Debug)]
struct Imports {
    depth: ResourceId,
    normals: ResourceId,
    material_ids: ResourceId,
    albedo: Option<ResourceId>,
    layer_depths: Option<ResourceId>,
    lighting: ResourceId,
}

/// Li et al.'s layered media on a host's G-buffer (see the module docs).
pub struct LayeredEffect {
    passes: EffectPasses,
    imports: Imports,
    desc: LayeredEffectDesc,
    /// The table every frame shares; each frame adds its view.
    table: LayeredTableGpu,
    /// The media, layered material `k` at `k - 1` (lengths in the G-buffer's units).
    media: Vec<LayeredMedium>,
    /// What the light-space maps pass draws: filled just before each frame records.
    shadow_frame: Arc<Mutex<HostShadowFrame>>,
    /// With media whose layers read depth textures: the draws' sets of them.
    depth_sets: Option<DepthTextureSets>,
}

impl LayeredEffect {
    /// Builds the effect for `desc`, checking all of it first. Its tables are written into
    /// lucent's own host-visible per-frame buffer: nothing is recorded into `uploads`,
    /// submitted or waited for (`uploads` is taken so that every effect is built alike).
    pub fn new(lucent: &Lucent, uploads: &mut Uploads, desc: LayeredEffectDesc) -> Result<Self> {
        let gbuffer = &desc.gbuffer;
        gbuffer.check()?;
        require(Effect::LayeredMedia, gbuffer)?;
        let (Some(ids), Some(normals)) = (gbuffer.material_ids, gbuffer.normals) else {
            unreachable!("missing() lists each input the effect reads");
        };
        check_views(desc.views_per_frame)?;
        if desc.film && gbuffer.albedo.is_none() {
            return Err(HostError::Missing {
                input: "albedo".into(),
                needed_by: "the layered media's film multiplies the light leaving them by the \
                            albedo (GBufferDesc::with_albedo, or no film)"
                    .into(),
            }
            .into());
        }
        let input = desc.vertices.check(lucent.gpu())?;
        let extent = desc.light_space;
        let sides = 16..=MAX_ATLAS_EXTENT;
        if !(sides.contains(&extent.width) && sides.contains(&extent.height)) {
            return Err(HostError::Description {
                field: "light_space".into(),
                problem: format!(
                    "{}x{}: each side 16 to {MAX_ATLAS_EXTENT} texels",
                    extent.width, extent.height
                ),
            }
            .into());
        }
        if desc.materials.is_empty() || desc.materials.len() > MAX_LAYERED_MATERIALS {
            return Err(HostError::Description {
                field: "materials".into(),
                problem: format!(
                    "{} layered materials; 1 to {MAX_LAYERED_MATERIALS} are supported",
                    desc.materials.len()
                ),
            }
            .into());
        }
        let id_map = ids.decode(Vec::new())?;
        let units_per_mm = 1.0 / (1000.0 * gbuffer.metres_per_unit);
        let mut id_materials = [[0u32; 4]; 64];
        let mut media = Vec::with_capacity(desc.materials.len());
        for (index, material) in desc.materials.iter().enumerate() {
            let id = usize::from(material.id);
            check_material_id(
                index,
                material.id,
                id_materials[id / 4][id % 4] != 0,
                id_map.mask,
            )?;
            let field = format!("materials[{index}] (ID {id})");
            let medium = LayeredMedium {
                units_per_mm,
                ..material.medium.clone()
            };
            if !medium.depth_textures.is_empty() {
                return Err(HostError::Description {
                    field: format!("{field}.medium.depth_textures"),
                    problem: "a host gives each mesh's own depth textures \
                              (MeshDraw::with_depth_textures): leave the medium's list empty"
                        .into(),
                }
                .into());
            }
            medium
                .validate_values()
                .map_err(|e| HostError::Description {
                    field: field.clone(),
                    problem: e.to_string(),
                })?;
            id_materials[id / 4][id % 4] = index as u32 + 1;
            media.push(medium);
        }
        let depth_textures = media
            .iter()
            .map(LayeredMedium::depth_textures_needed)
            .max()
            .unwrap_or(0);
        if depth_textures > 0 {
            check_texture_layers(gbuffer, &desc.vertices, depth_textures)?;
        }
        let mut input = input;
        if depth_textures == 0 {
            // Nothing reads the texture coordinate: the pipeline does not fetch it.
            input.uv = None;
        }
        let uint_ids = id_map.uint;
        let (host_ids, _) = id_map.rows();
        let layered = LayeredDesc::of_media(media, Vec::new(), false);
        let table = LayeredTableGpu {
            id_materials,
            ..layered.table(&desc.knobs)
        };
        let [octahedral, view_space, unorm, _] = normals.decode()?;
        let decode = LayeredDecode::new(host_ids, &id_materials, [octahedral, view_space, unorm]);
        let upload = SceneUpload::tables_only(vec![
            TableRegion {
                region: &TABLE_REGION,
                bytes: std::mem::size_of::<LayeredTableGpu>() as u64,
            },
            shadows::table_region(),
        ]);
        let shadow_frame = Arc::new(Mutex::new(HostShadowFrame::default()));
        let rings = lucent.frames_in_flight() * desc.views_per_frame;
        let depth_sets = (depth_textures > 0)
            .then(|| {
                uploads.record(lucent, "LayeredEffect", || {
                    DepthTextureSets::new(lucent.gpu(), depth_textures, rings)
                })
            })
            .transpose()?;
        let host_depth = depth_sets.as_ref().map(|s| s.host_depth_textures());
        let built = EffectPasses::new(
            lucent,
            uploads,
            "LayeredEffect",
            upload,
            desc.views_per_frame,
            |scene_gpu| {
                declare(
                    &desc,
                    uint_ids,
                    decode,
                    input,
                    (shadow_frame.clone(), host_depth),
                    scene_gpu,
                )
            },
        );
        let (passes, imports) = match built {
            Ok(built) => built,
            Err(e) => {
                if let Some(sets) = depth_sets {
                    sets.destroy(lucent.gpu());
                }
                return Err(e);
            }
        };
        Ok(Self {
            passes,
            imports,
            desc,
            table,
            media: layered.materials,
            shadow_frame,
            depth_sets,
        })
    }

    /// Destroys the passes, their buffers and the draws' depth-texture sets. The GPU must be
    /// done with every frame that recorded the effect.
    pub fn destroy(self, lucent: &Lucent) {
        if let Some(sets) = self.depth_sets {
            sets.destroy(lucent.gpu());
        }
        self.passes.destroy(lucent);
    }

    /// The draws' depth-texture sets' blank texture (none without `TexDep` media).
    fn own_image_bytes(&self) -> u64 {
        self.depth_sets
            .as_ref()
            .map_or(0, DepthTextureSets::image_bytes)
    }

    super::passes::effect_methods!(
        LayeredFrame,
        "`frame.meshes` drawn into lucent's light-space maps with `frame.light_faces`, then Li et al.'s transmitted, single and multiple scattering terms of the layered materials added to `frame.lighting`",
        own_destroy
    );

    fn record_with(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &LayeredFrame<'_>,
        timer: Option<&mut super::EffectTimer>,
    ) -> Result<()> {
        let ring = self.passes.slot(frame.slot, frame.view)?;
        check_lights(frame.lights)?;
        let coefficients = frame
            .environment
            .map(check_environment)
            .transpose()?
            .unwrap_or([[0.0; 4]; 9]);
        let inputs = self.check_images(lucent, frame)?;
        let light_table = shadow_table(
            frame.lights,
            frame.light_faces,
            &[(self.desc.light_space, 1)],
        )?;
        let mut draws = self.draws(frame.meshes)?;
        if let Some(sets) = &mut self.depth_sets {
            let textures: Vec<Option<[vk::ImageView; 2]>> =
                frame.meshes.iter().map(|m| m.depth_textures).collect();
            let table = self.passes.per_frame().binding(&shadows::TABLE_REGION);
            let written = sets.write(lucent.gpu(), ring, table, &textures)?;
            for (draw, set) in draws.iter_mut().zip(written) {
                draw.depth_set = set;
            }
        }
        let gbuffer = &self.desc.gbuffer;
        let uniforms = gbuffer
            .view_uniforms(&frame.camera)?
            .with_lights(frame.lights)
            .with_environment(coefficients);
        let table = LayeredTableGpu {
            view_to_world: frame.camera.view.inverse().to_cols_array_2d(),
            ..self.table
        };
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &FRAME, bytemuck::bytes_of(&uniforms))?;
        per_frame.write(ring, &TABLE_REGION, bytemuck::bytes_of(&table))?;
        per_frame.write(
            ring,
            &shadows::TABLE_REGION,
            bytemuck::bytes_of(&light_table),
        )?;
        // The layered passes draw in the slot's `layered` tiles, the term's blur in its
        // `layered_blur` ones.
        let (layered_rects, blur_rects) = self.rects(frame, &draws);
        {
            let mut tiles = per_frame.tiles(ring);
            tiles.layered = layered_rects;
            tiles.layered_blur = blur_rects;
        }
        *self.shadow_frame.lock().unwrap_or_else(|e| e.into_inner()) = HostShadowFrame {
            tiles: face_tiles(&light_table, frame.light_faces.len()),
            draws,
        };
        let images = &frame.images;
        let mut binds = vec![
            (self.imports.depth, images.depth),
            (self.imports.normals, images.normals),
            (self.imports.material_ids, images.material_ids),
            (self.imports.lighting, frame.lighting),
        ];
        if let (Some(id), Some(albedo)) = (self.imports.albedo, images.albedo) {
            binds.push((id, albedo));
        }
        if let (Some(id), Some(depths)) = (self.imports.layer_depths, images.layer_depths) {
            binds.push((id, depths));
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

    /// The layered passes' rectangles (the frame's regions; none: the whole screen) and the
    /// term blur's: where every layered mesh has its bounds, those of the meshes whose medium
    /// the blur acts on at their nearest point ([`crate::features::layered::blurs_on_screen`],
    /// lucent's own rule), else the layered passes' own (the blur's shader then narrows it
    /// per texel).
    fn rects(
        &self,
        frame: &LayeredFrame<'_>,
        draws: &[HostShadowDraw],
    ) -> (Vec<TileRect>, Vec<TileRect>) {
        let gbuffer = &self.desc.gbuffer;
        let extent = gbuffer.extent();
        let layered = if frame.regions.is_empty() {
            vec![TileRect {
                x: 0,
                y: 0,
                width: extent.width,
                height: extent.height,
                translucent: true,
            }]
        } else {
            clipped(frame.regions, extent)
        };
        let camera = &frame.camera;
        let focal_px = camera.projection.y_axis.y.abs() * extent.height as f32 * 0.5;
        let texel_px = if self.desc.knobs.half_gather {
            2.0
        } else {
            1.0
        };
        let mut blurred = Vec::new();
        for (mesh, draw) in frame.meshes.iter().zip(draws) {
            let Some(medium) = usize::from(draw.layered_id)
                .checked_sub(1)
                .and_then(|k| self.media.get(k))
            else {
                continue;
            };
            let Some(bounds) = mesh.bounds else {
                return (layered.clone(), layered);
            };
            let nearest = box_nearest_depth(bounds, mesh.transform, camera);
            if !blurs_on_screen(medium, nearest, focal_px, texel_px) {
                continue;
            }
            match box_screen_region(bounds, mesh.transform, camera, extent, 0.0) {
                Some(region) => blurred.push(region),
                // The box reaches the eye's plane: it may cover the whole screen.
                None => return (layered.clone(), layered),
            }
        }
        // One union of the meshes' regions: overlapping boxes are blurred once.
        (layered, clipped(&blurred, extent))
    }

    /// The frame's meshes as the light-space pass draws them, each checked: its buffers given,
    /// whole triangles, a finite model matrix, a 16- or 32-bit index type.
    fn draws(&self, meshes: &[MeshDraw]) -> Result<Vec<HostShadowDraw>> {
        let two_bindings = self.desc.vertices.strides[1] > 0;
        meshes
            .iter()
            .enumerate()
            .map(|(index, mesh)| {
                let bad = |problem: &str| -> crate::LucentError {
                    HostError::Description {
                        field: format!("meshes[{index}]"),
                        problem: problem.into(),
                    }
                    .into()
                };
                if mesh.vertex_buffers[0].0 == vk::Buffer::null()
                    || (two_bindings && mesh.vertex_buffers[1].0 == vk::Buffer::null())
                {
                    return Err(bad("a vertex buffer of a binding the layout uses is null"));
                }
                if mesh.count % 3 != 0 {
                    return Err(bad("its count is not whole triangles (a multiple of 3)"));
                }
                if !mesh.transform.is_finite() {
                    return Err(bad("its transform is not finite"));
                }
                let indices = match mesh.indices {
                    None => None,
                    Some(i) if i.buffer == vk::Buffer::null() => {
                        return Err(bad("its index buffer is null"))
                    }
                    Some(i)
                        if i.index_type != vk::IndexType::UINT16
                            && i.index_type != vk::IndexType::UINT32 =>
                    {
                        return Err(bad("its index type is neither UINT16 nor UINT32"))
                    }
                    Some(i) => Some((i.buffer, i.offset, i.index_type)),
                };
                let id = usize::from(mesh.material_id);
                let layered_id = self.table.id_materials[id / 4][id % 4] as u8;
                let reads = usize::from(layered_id)
                    .checked_sub(1)
                    .and_then(|k| self.media.get(k))
                    .map_or(0, LayeredMedium::depth_textures_needed);
                match (reads, mesh.depth_textures) {
                    (0, None) => {}
                    (0, Some(_)) => {
                        return Err(bad(&format!(
                            "depth textures given, but material ID {} has no layer that reads \
                             its thickness from one: pass none",
                            mesh.material_id
                        )))
                    }
                    (_, None) => {
                        return Err(HostError::Missing {
                            input: format!("meshes[{index}].depth_textures"),
                            needed_by: format!(
                                "material ID {}'s layers read their thickness from {reads} depth \
                                 texture(s) (MeshDraw::with_depth_textures)",
                                mesh.material_id
                            ),
                        }
                        .into())
                    }
                    (_, Some(views)) => {
                        if views[..reads].contains(&vk::ImageView::null()) {
                            return Err(bad(&format!(
                                "material ID {} reads {reads} depth texture(s); a view given \
                                 is null",
                                mesh.material_id
                            )));
                        }
                    }
                }
                Ok(HostShadowDraw {
                    vertex_buffers: mesh.vertex_buffers,
                    indices,
                    count: mesh.count,
                    first: mesh.first,
                    vertex_offset: mesh.vertex_offset,
                    model: mesh.transform,
                    layered_id,
                    depth_set: vk::DescriptorSet::null(),
                })
            })
            .collect()
    }

    /// Checks every image of `frame` against the description; returns the inputs, one per
    /// distinct Vulkan image.
    fn check_images<'a>(
        &self,
        lucent: &Lucent,
        frame: &LayeredFrame<'a>,
    ) -> Result<Vec<&'a HostImage>> {
        let gbuffer = &self.desc.gbuffer;
        let images = &frame.images;
        let ids = gbuffer.material_ids.expect("checked at new");
        let normal_format = gbuffer.normals.expect("checked at new").format;
        let albedo = match (self.desc.film, images.albedo) {
            (true, Some(albedo)) => Some(albedo),
            (false, None) => None,
            (true, None) => {
                return Err(HostError::Missing {
                    input: "albedo".into(),
                    needed_by: "the layered media's film (LayeredEffectDesc::with_film)".into(),
                }
                .into())
            }
            (false, Some(_)) => {
                return Err(HostError::Description {
                    field: "albedo".into(),
                    problem: "given, but the effect was built without a film: pass None".into(),
                }
                .into())
            }
        };
        let mut checks = vec![
            (
                images.depth,
                "depth",
                depth_role(gbuffer),
                gbuffer.depth.format,
            ),
            (images.normals, "normals", Role::SampledColor, normal_format),
            (
                images.material_ids,
                "material IDs",
                id_role(&ids),
                ids.format,
            ),
            (
                frame.lighting,
                "lighting",
                Role::Accumulate,
                gbuffer.diffuse.format,
            ),
        ];
        if let (Some(albedo), Some(format)) = (albedo, gbuffer.albedo) {
            checks.push((albedo, "albedo", Role::SampledColor, format));
        }
        let layer_depths = match (self.depth_sets.is_some(), images.layer_depths) {
            (true, Some(depths)) => Some(depths),
            (false, None) => None,
            (true, None) => {
                return Err(HostError::Missing {
                    input: "layer depths".into(),
                    needed_by: "a layered material's layers read their thickness from depth \
                                textures (the G-buffer's TexDep texels)"
                        .into(),
                }
                .into())
            }
            (false, Some(_)) => {
                return Err(HostError::Description {
                    field: "layer_depths".into(),
                    problem: "given, but no layered material reads depth textures: pass None"
                        .into(),
                }
                .into())
            }
        };
        if let (Some(depths), Some(format)) = (layer_depths, gbuffer.layer_depths) {
            checks.push((depths, "layer depths", Role::SampledColor, format));
        }
        check_described(lucent, gbuffer.extent(), &checks)?;
        distinct_inputs(
            [images.depth, images.normals, images.material_ids]
                .into_iter()
                .chain(albedo)
                .chain(layer_depths),
            frame.lighting,
        )
    }
}

/// What media whose layers read depth textures need of the host: the G-buffer's `TexDep`
/// texels for `textures` depth textures, and the texture coordinate in its vertices.
fn check_texture_layers(
    gbuffer: &GBufferDesc,
    vertices: &VertexLayout,
    textures: usize,
) -> Result<()> {
    let reason = format!(
        "a layered material's layers read their thickness from {textures} depth texture(s) \
         (Li et al.'s TexDep)"
    );
    if gbuffer.layer_depths.is_none() {
        return Err(HostError::Missing {
            input: "layer depths".into(),
            needed_by: format!("{reason}: GBufferDesc::with_layer_depths"),
        }
        .into());
    }
    if gbuffer.layer_depth_textures() < textures {
        return Err(HostError::Unsupported {
            input: "layer depths".into(),
            found: "R32G32_UINT (one texture's four layers)".into(),
            accepted: format!("R32G32B32A32_UINT (two textures' eight layers): {reason}"),
        }
        .into());
    }
    if vertices.uv.is_none() {
        return Err(HostError::Missing {
            input: "vertices.uv".into(),
            needed_by: format!(
                "{reason}: lucent reads them in its light-space maps at the meshes' texture \
                 coordinate (VertexLayout::with_uv)"
            ),
        }
        .into());
    }
    Ok(())
}

/// Each face's tile (origin, edge) in face order, from the checked shadow table.
fn face_tiles(table: &ShadowUniforms, faces: usize) -> Vec<((u32, u32), u32)> {
    table.faces[..faces]
        .iter()
        .map(|f| ((f.rect[0] as u32, f.rect[1] as u32), f.rect[2] as u32))
        .collect()
}

/// The effect's graph: the host's images imported (bound when each frame records), lucent's
/// light-space maps of the host's meshes, and the layered passes adding into the host's light.
fn declare(
    desc: &LayeredEffectDesc,
    uint_ids: bool,
    decode: LayeredDecode,
    input: HostVertexInput,
    (shadow_frame, depth_textures): (Arc<Mutex<HostShadowFrame>>, Option<HostDepthTextures>),
    scene_gpu: &Arc<SceneGpu>,
) -> (RenderGraph, Imports) {
    let gbuffer = &desc.gbuffer;
    let mut graph = RenderGraph::new();
    let mut import = |name: &str, format: vk::Format, initial: Access| {
        import_host_image(&mut graph, gbuffer, name, format, initial)
    };
    let sampled = Access::FragmentSampledRead;
    let depth = import("host depth", gbuffer.depth.format, sampled);
    let normal_format = gbuffer.normals.expect("checked at new").format;
    let normals = import("host normals", normal_format, sampled);
    let ids_format = gbuffer.material_ids.expect("checked at new").format;
    let material_ids = import("host material IDs", ids_format, sampled);
    let albedo = desc.film.then(|| {
        import(
            "host albedo",
            gbuffer.albedo.expect("checked at new"),
            sampled,
        )
    });
    let layer_depths = depth_textures.map(|_| {
        import(
            "host layer depths",
            gbuffer.layer_depths.expect("checked at new"),
            sampled,
        )
    });
    let lighting = import(
        "host lighting",
        gbuffer.diffuse.format,
        Access::ColorAttachmentWrite,
    );
    let imports = Imports {
        depth: depth.id(),
        normals: normals.id(),
        material_ids: material_ids.id(),
        albedo: albedo.as_ref().map(|a| a.id()),
        layer_depths: layer_depths.as_ref().map(|a| a.id()),
        lighting: lighting.id(),
    };
    let extent = (desc.light_space.width, desc.light_space.height);
    let maps = host_shadow_pass(
        &mut graph,
        extent,
        input,
        shadow_frame,
        scene_gpu,
        depth_textures,
    );
    let inputs = LayeredInputs {
        depth: &depth,
        gb1: &normals,
        ids: &material_ids,
        layer_depths: layer_depths.as_ref(),
        layer_depth_textures: depth_textures.map_or(0, |d| d.textures),
        shadows: Some(&maps),
        film: desc.film,
        host: Some(LayeredHost {
            uint_ids,
            linear_depth: gbuffer.depth.encoding == DepthEncoding::LinearView,
        }),
        decode: Some(decode),
        host_film: albedo.as_ref(),
    };
    let lighting = layered_passes(&mut graph, lighting, &inputs, &desc.knobs, Some(scene_gpu));
    graph.export_image(&lighting, Access::ColorAttachmentWrite);
    (graph, imports)
}

// Effects move to a loader thread and back.
const _: () = {
    const fn send<T: Send>() {}
    send::<LayeredEffect>();
};
