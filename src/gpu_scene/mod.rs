//! What a scene becomes on the GPU: meshes with the vertex streams the frame needs, the draws
//! with their per-object constants, the material textures (normal or LEAN maps, albedo maps),
//! and the per-frame parameter buffer ([`per_frame`]). Made once per scene and frame layout
//! ([`SceneGpu::new`]); the passes of [`crate::features`] share it read-only.
//!
//! A stream or texture exists only in frames that read it: thickness streams with
//! translucency, UV + tangent streams and the samplers with normal or albedo maps.
//!
//! - [`per_frame`]: frame uniforms and material/profile tables, one slot per frame in flight.
//! - [`tiles`]: the screen rectangles objects of a kind may cover, for the passes to draw their
//!   expensive variants in.

pub mod per_frame;
pub mod tiles;

use std::sync::Mutex;

use ash::vk;

use crate::backend::{GpuBuffer, GpuContext, GpuImage};
use crate::error::VkResultExt;
use crate::scene::material::TextureSource;
use crate::scene::texture::{decode_texture, procedural_texture, Texture, TextureUsage};
use crate::scene::upload::{self, UploadLayout};
use crate::scene::Scene;
use crate::{LucentError, Result};

pub use per_frame::{
    projection_depth_decode, projection_depth_ends, FrameUniforms, PerFrame, PerFrameBinding,
    Region, SlotTiles, TableRegion, FRAME,
};
pub use tiles::TileRect;

/// One draw: which mesh, with which material textures and per-object constants.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// Index into [`SceneGpu::meshes`].
    pub mesh: usize,
    /// Index into [`MaterialMaps::sets`] (0 in frames without maps).
    pub maps: usize,
    /// Index into [`MaterialMaps::depth_sets`] (0 in frames without `TexDep` media, and for
    /// objects whose medium reads no depth texture): the light-space maps pass binds it.
    pub depth_maps: usize,
    /// Push constants of the G-buffer pass.
    pub constants: ObjectConstants,
}

/// Per-object push constants (glsl/deferred/object.glsl `Object`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ObjectConstants {
    /// Object → world.
    pub model: [[f32; 4]; 4],
    /// Albedo rgb, specular a.
    pub albedo_specular: [f32; 4],
    /// Roughness in x; y: the SSS profile ID (0: the object does not scatter), in frames
    /// with SSS; z: the layered material ID (0: not layered), in frames with layered media.
    pub roughness: [f32; 4],
    /// Translucency: thickness factor rgb (tint x constant thickness), material ID in w
    /// (0: not translucent). Zero when the frame has no translucency.
    pub thickness: [f32; 4],
}

/// A mesh's position + normal stream.
pub enum VertexStream {
    /// Uploaded once, device-local.
    Static(GpuBuffer),
    /// A deforming scene's: one host-visible buffer per frame in flight, rewritten for each
    /// frame in its slot ([`crate::frame::Renderer::update_slot`]) while the GPU may still
    /// read the other slots'.
    PerSlot {
        /// The buffers' handles, for binding while a slot is written.
        handles: Vec<vk::Buffer>,
        /// The buffers, locked only while the CPU writes one.
        buffers: Vec<Mutex<GpuBuffer>>,
    },
}

impl VertexStream {
    /// The buffer frames recorded for `slot` read.
    pub fn buffer(&self, slot: usize) -> vk::Buffer {
        match self {
            VertexStream::Static(b) => b.buffer,
            VertexStream::PerSlot { handles, .. } => handles[slot.min(handles.len() - 1)],
        }
    }

    /// Writes the vertices of `slot` (a deforming scene's; the GPU must not be reading that
    /// slot). `bytes` must be the size the stream was made with.
    pub fn write(&self, slot: usize, bytes: &[u8]) -> Result<()> {
        let VertexStream::PerSlot { buffers, .. } = self else {
            return Err(LucentError::InvalidInput(
                "a static mesh's vertices are uploaded once".into(),
            ));
        };
        let buffer = buffers.get(slot).ok_or_else(|| {
            LucentError::InvalidInput(format!("vertex slot {slot} of {}", buffers.len()))
        })?;
        // A poisoned lock only means a writer panicked mid-copy; the bytes are plain data.
        let mut buffer = buffer.lock().unwrap_or_else(|e| e.into_inner());
        let mapped = buffer.mapped_mut().ok_or_else(|| {
            LucentError::InvalidInput("a deforming mesh's vertices are not host-visible".into())
        })?;
        if mapped.len() != bytes.len() {
            return Err(LucentError::InvalidInput(format!(
                "deformed mesh of {} bytes written into a vertex buffer of {}",
                bytes.len(),
                mapped.len()
            )));
        }
        mapped.copy_from_slice(bytes);
        Ok(())
    }

    fn destroy(self, gpu: &GpuContext) {
        match self {
            VertexStream::Static(b) => gpu.destroy_buffer(b),
            VertexStream::PerSlot { buffers, .. } => {
                for b in buffers {
                    gpu.destroy_buffer(b.into_inner().unwrap_or_else(|e| e.into_inner()));
                }
            }
        }
    }
}

/// A mesh on the GPU.
pub struct GpuMesh {
    /// Position + normal stream.
    pub vertices: VertexStream,
    /// Index buffer (u32).
    pub indices: GpuBuffer,
    /// Number of indices.
    pub index_count: u32,
    /// Per-vertex RGB thickness (vertex colours, or white), only in frames with translucency.
    pub thickness: Option<GpuBuffer>,
    /// Per-vertex UV + tangent (`[u, v, tx, ty, tz, tw]`), only in frames with normal or
    /// albedo maps.
    pub surface: Option<GpuBuffer>,
}

impl GpuMesh {
    /// Records the mesh's indexed draw into `cmd` (recording inside a subpass whose bound
    /// pipeline reads the position + normal stream at binding 0): binds the vertex buffer,
    /// the thickness stream at binding 1 with `thickness`, the UV + tangent stream at binding
    /// 2 with `surface` (each when the mesh has it), and the index buffer; `slot` is the
    /// recorded frame's (a deforming mesh's vertices are per slot).
    pub fn draw(
        &self,
        device: &ash::Device,
        cmd: vk::CommandBuffer,
        slot: usize,
        thickness: bool,
        surface: bool,
    ) {
        // SAFETY: the caller records inside a subpass with a compatible pipeline bound; the
        // buffers live as long as the scene, which outlives its frames.
        unsafe {
            device.cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.buffer(slot)], &[0]);
            if let (Some(stream), true) = (&self.thickness, thickness) {
                device.cmd_bind_vertex_buffers(cmd, 1, &[stream.buffer], &[0]);
            }
            if let (Some(stream), true) = (&self.surface, surface) {
                device.cmd_bind_vertex_buffers(cmd, 2, &[stream.buffer], &[0]);
            }
            device.cmd_bind_index_buffer(cmd, self.indices.buffer, 0, vk::IndexType::UINT32);
            device.cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
        }
    }
}

/// The material textures a draw binds: indices into [`MaterialMaps`]' lists.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapSet {
    /// Into [`MaterialMaps::normal`] (and `lean2`).
    pub normal: usize,
    /// Into [`MaterialMaps::albedo`].
    pub albedo: usize,
    /// Into [`MaterialMaps::depth`]: the medium's first and second `TexDep` textures.
    pub depth: [usize; 2],
}

/// The material textures of a frame with normal or albedo maps or layered media whose
/// thickness comes from a texture (`TexDep`). Entry 0 of each list is the neutral texture
/// objects without a map of that kind read (a flat normal, white albedo, zero depth).
/// In LEAN frames each normal map is uploaded as its two LEAN maps instead
/// ([`crate::scene::lean`]): `normal` holds LEAN map 1, `lean2` LEAN map 2.
pub struct MaterialMaps {
    /// Normal (or LEAN 1) maps, RGBA16F mipmapped; empty without normal maps.
    pub normal: Vec<GpuImage>,
    /// LEAN frames: the second LEAN map of each entry of `normal` (empty otherwise).
    pub lean2: Vec<GpuImage>,
    /// Albedo maps (decoded from sRGB to linear), RGBA16F mipmapped; empty without albedo
    /// maps.
    pub albedo: Vec<GpuImage>,
    /// `TexDep` depth textures (linear data), RGBA16F mipmapped; empty in frames without
    /// them.
    pub depth: Vec<GpuImage>,
    /// Trilinear, repeating sampler.
    pub sampler: vk::Sampler,
    /// The distinct texture sets the G-buffer draws use: one descriptor set each.
    pub sets: Vec<MapSet>,
    /// The distinct depth-texture pairs the draws use (the light-space maps pass binds only
    /// these): one descriptor set each. Entry 0 is the zero pair.
    pub depth_sets: Vec<[usize; 2]>,
}

/// What the frame needs of the scene on the GPU (the frame description decides it).
#[derive(Clone, Debug)]
pub struct SceneUpload<'a> {
    /// Frames with translucency: each object's translucency material ID (0: opaque); the
    /// meshes get their thickness streams.
    pub translucency_ids: Option<&'a [u8]>,
    /// Frames with SSS: each object's SSS profile ID (0: does not scatter).
    pub profile_ids: Option<&'a [u8]>,
    /// Some object has a normal map.
    pub normal_maps: bool,
    /// Normal maps are uploaded as LEAN maps (LCB and LBB blurs).
    pub lean: bool,
    /// Some object has an albedo texture.
    pub albedo_maps: bool,
    /// Frames in flight (slots of the per-frame buffer).
    pub frames_in_flight: usize,
    /// The per-frame tables the frame's features write (besides the frame uniforms), in the
    /// order the per-frame buffer lays them out.
    pub tables: Vec<TableRegion>,
    /// Frames with layered materials: each object's layered material ID (0: not layered);
    /// a layered object's albedo is weighted by its eq. 3 `λ1` and its specular by `λ2`.
    pub layered_ids: Option<&'a [u8]>,
    /// `TexDep` depth textures the frame's layered media read per object (0: none; 1 or 2:
    /// [`crate::features::layered::LayeredDesc::depth_textures`]).
    pub layer_depth_textures: usize,
}

impl SceneUpload<'_> {
    /// A per-frame buffer of `tables` and nothing of a scene's (no objects, maps or IDs): what
    /// an effect on a host's G-buffer uploads (`lucent::embed`; its frames in flight are set
    /// when the effect is built).
    pub fn tables_only(tables: Vec<TableRegion>) -> Self {
        Self {
            translucency_ids: None,
            profile_ids: None,
            normal_maps: false,
            lean: false,
            albedo_maps: false,
            frames_in_flight: 1,
            tables,
            layered_ids: None,
            layer_depth_textures: 0,
        }
    }
}

pub use crate::scene::texture::PROCEDURAL_TEXTURE_SIZE;

/// The scene's GPU data the passes share (see the module docs).
pub struct SceneGpu {
    /// Meshes.
    pub meshes: Vec<GpuMesh>,
    /// Draws in submission order.
    pub draws: Vec<Draw>,
    /// Material textures, when some object has a normal or albedo map.
    pub maps: Option<MaterialMaps>,
    /// The per-frame parameters (uniforms, tables, tiles), one slot per frame in flight.
    pub per_frame: PerFrame,
}

/// Uploads a texture with its whole mip chain as RGBA16F, converting each level straight into
/// the staging buffer (values clamped to fp16's range): the upload costs the staging copy, no
/// second copy of the texels.
pub fn upload_texture(gpu: &GpuContext, texture: &Texture, name: &str) -> Result<GpuImage> {
    let desc = crate::backend::ImageDesc {
        mip_levels: texture.level_count() as u32,
        ..crate::backend::ImageDesc::color(
            texture.width,
            texture.height,
            vk::Format::R16G16B16A16_SFLOAT,
            vk::ImageUsageFlags::SAMPLED,
        )
    };
    let sizes: Vec<u64> = texture.mips.iter().map(|m| m.len() as u64 * 8).collect();
    gpu.upload_image_with(&desc, &sizes, name, |level, out| {
        for (texel, bytes) in texture.mips[level].iter().zip(out.chunks_exact_mut(8)) {
            for (c, &v) in texel.iter().enumerate() {
                let h = half::f16::from_f32(v.clamp(-65504.0, 65504.0));
                bytes[c * 2..c * 2 + 2].copy_from_slice(&h.to_le_bytes());
            }
        }
        Ok(())
    })
}

/// The distinct sources of one kind of map, in order of first use.
fn distinct_sources<'s>(
    scene: &'s Scene,
    pick: impl Fn(&'s crate::scene::Object) -> Option<&'s TextureSource>,
) -> Vec<&'s TextureSource> {
    let mut sources: Vec<&TextureSource> = Vec::new();
    for o in &scene.objects {
        if let Some(t) = pick(o) {
            if !sources.contains(&t) {
                sources.push(t);
            }
        }
    }
    sources
}

/// The distinct `TexDep` textures of the layered objects `upload` draws as layered, in order
/// of first use (none when the frame reads no depth texture).
fn distinct_depth_sources<'s>(
    scene: &'s Scene,
    upload: &SceneUpload<'_>,
) -> Vec<&'s TextureSource> {
    let mut sources: Vec<&TextureSource> = Vec::new();
    let Some(ids) = upload.layered_ids else {
        return sources;
    };
    if upload.layer_depth_textures == 0 {
        return sources;
    }
    for (o, id) in scene.objects.iter().zip(ids) {
        let Some(medium) = o.material.layers.as_ref().filter(|_| *id > 0) else {
            continue;
        };
        for t in &medium.depth_textures {
            if !sources.contains(&t) {
                sources.push(t);
            }
        }
    }
    sources
}

/// The index of `value` in `list`, pushed first if it is not there.
fn index_of_or_push<T: PartialEq + Copy>(list: &mut Vec<T>, value: T) -> usize {
    match list.iter().position(|v| *v == value) {
        Some(i) => i,
        None => {
            list.push(value);
            list.len() - 1
        }
    }
}

/// The Vulkan format of an upload layout.
fn upload_format(layout: UploadLayout) -> vk::Format {
    match layout {
        UploadLayout::Unorm8 => vk::Format::R8G8B8A8_UNORM,
        UploadLayout::Srgb8 => vk::Format::R8G8B8A8_SRGB,
        UploadLayout::Half => vk::Format::R16G16B16A16_SFLOAT,
        UploadLayout::HalfRed => vk::Format::R16_SFLOAT,
    }
}

/// Creates a sampled `width x height` image in `layout` with its whole mip chain, which
/// `fill` writes into the staging buffer ([`upload::write_chain`] or
/// [`crate::scene::texture::write_texture_chain`]).
fn upload_chain(
    gpu: &GpuContext,
    width: u32,
    height: u32,
    layout: UploadLayout,
    name: &str,
    fill: impl FnOnce(&mut [u8]) -> Result<()>,
) -> Result<GpuImage> {
    let desc = crate::backend::ImageDesc {
        mip_levels: crate::scene::texture::mip_levels(width, height),
        ..crate::backend::ImageDesc::color(
            width,
            height,
            upload_format(layout),
            vk::ImageUsageFlags::SAMPLED,
        )
    };
    let sizes = upload::level_bytes(width, height, layout);
    gpu.upload_image_chain(&desc, &sizes, name, fill)
}

/// Loads a texture file onto the GPU in the layout [`crate::scene::upload`] picks for it: the
/// file is decoded as stored, written into the staging buffer and dropped, and the mips are
/// made there, so loading costs about twice the texture's decoded size plus mips in host
/// memory. Errors name the file.
pub fn upload_texture_file(
    gpu: &GpuContext,
    path: &std::path::Path,
    usage: TextureUsage,
    name: &str,
) -> Result<GpuImage> {
    let decoded = decode_texture(path, usage)?;
    upload_decoded(gpu, decoded, &path.display().to_string(), name)
}

/// Uploads an image decoded as stored ([`upload_texture_file`]'s way); `what` names its
/// source in the warning about non-finite texels.
fn upload_decoded(
    gpu: &GpuContext,
    decoded: crate::scene::texture::DecodedImage,
    what: &str,
    name: &str,
) -> Result<GpuImage> {
    warn_non_finite(what, &decoded);
    let (width, height, layout) = (decoded.width, decoded.height, decoded.upload_layout());
    upload_chain(gpu, width, height, layout, name, move |out| {
        crate::scene::texture::write_texture_chain(decoded, out)
    })
}

fn warn_non_finite(what: &str, decoded: &crate::scene::texture::DecodedImage) {
    let replaced = decoded.non_finite();
    if replaced > 0 {
        log::warn!("{what}: replaced {replaced} NaN or infinite texel values with 0");
    }
}

/// Uploads a map of `usage` from `source`: a file or an encoded image decoded as stored, a
/// procedural texture through [`upload_texture`].
pub(crate) fn upload_source(
    gpu: &GpuContext,
    source: &TextureSource,
    usage: TextureUsage,
    name: &str,
) -> Result<GpuImage> {
    match source {
        TextureSource::File(path) => upload_texture_file(gpu, path, usage, name),
        TextureSource::Encoded(e) => upload_decoded(
            gpu,
            crate::scene::texture::decode_encoded(e, usage)?,
            &source.describe(),
            name,
        ),
        TextureSource::Procedural(p) => {
            upload_texture(gpu, &procedural_texture(p, PROCEDURAL_TEXTURE_SIZE)?, name)
        }
    }
}

impl SceneGpu {
    /// Uploads what `upload` asks for of `scene` and creates the per-frame buffer.
    pub fn new(gpu: &GpuContext, scene: &Scene, upload: &SceneUpload<'_>) -> Result<Self> {
        let per_frame = PerFrame::new(gpu, upload.frames_in_flight, &upload.tables, &scene.name)?;
        let mut out = Self {
            meshes: Vec::with_capacity(scene.meshes.len()),
            draws: Vec::with_capacity(scene.objects.len()),
            maps: None,
            per_frame,
        };
        // Everything created so far is freed by `destroy` if a later step fails.
        match out.upload(gpu, scene, upload) {
            Ok(()) => Ok(out),
            Err(e) => {
                out.destroy(gpu);
                Err(e)
            }
        }
    }

    fn upload(&mut self, gpu: &GpuContext, scene: &Scene, upload: &SceneUpload<'_>) -> Result<()> {
        let normal_sources = distinct_sources(scene, |o| o.material.normal_texture.as_ref());
        let albedo_sources = distinct_sources(scene, |o| o.material.albedo_texture.as_ref());
        let depth_sources = distinct_depth_sources(scene, upload);
        let normal_maps = upload.normal_maps && !normal_sources.is_empty();
        let albedo_maps = upload.albedo_maps && !albedo_sources.is_empty();
        let depth_maps = !depth_sources.is_empty();
        if normal_maps || albedo_maps || depth_maps {
            self.upload_maps(
                gpu,
                scene,
                upload.lean,
                normal_maps,
                albedo_maps,
                &depth_sources,
            )?;
        }
        for (i, mesh) in scene.meshes.iter().enumerate() {
            // A deforming scene starts as it stands at its time; each frame rewrites its slot.
            let deformed = scene.deformation.map(|d| d.apply(mesh, scene.time));
            let mesh = deformed.as_ref().unwrap_or(mesh);
            mesh.validate(&format!("scene '{}' mesh {i}", scene.name))?;
            let name = format!("{} mesh {i}", scene.name);
            let vertices = if deformed.is_some() {
                per_slot_vertices(gpu, mesh, upload.frames_in_flight, &name)?
            } else {
                VertexStream::Static(gpu.upload_buffer(
                    &mesh.gpu_vertices(),
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    &format!("{name} vertices"),
                )?)
            };
            let indices = gpu.upload_buffer(
                &mesh.indices,
                vk::BufferUsageFlags::INDEX_BUFFER,
                &format!("{name} indices"),
            );
            let indices = match indices {
                Ok(b) => b,
                Err(e) => {
                    vertices.destroy(gpu);
                    return Err(e);
                }
            };
            self.meshes.push(GpuMesh {
                vertices,
                indices,
                index_count: mesh.indices.len() as u32,
                thickness: None,
                surface: None,
            });
            let gpu_mesh = self.meshes.last_mut().expect("just pushed");
            if upload.translucency_ids.is_some() {
                // Meshes without vertex colours are uniformly "thin": the material's
                // constant thickness then carries the value.
                let colors: Vec<[f32; 3]> = if mesh.colors.is_empty() {
                    vec![[1.0; 3]; mesh.positions.len()]
                } else {
                    mesh.colors.iter().map(|c| c.to_array()).collect()
                };
                gpu_mesh.thickness = Some(gpu.upload_buffer(
                    &colors,
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    &format!("{name} thickness"),
                )?);
            }
            if self.maps.is_some() {
                gpu_mesh.surface = Some(gpu.upload_buffer(
                    &surface_stream(mesh),
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    &format!("{name} UVs and tangents"),
                )?);
            }
        }
        for (index, o) in scene.objects.iter().enumerate() {
            let m = &scene.meshes[o.mesh];
            if o.material.normal_texture.is_some()
                && normal_maps
                && (m.uvs.len() != m.positions.len() || m.tangents.len() != m.positions.len())
            {
                return Err(LucentError::InvalidInput(format!(
                    "material '{}' has a normal map but mesh {} has no UVs and tangents",
                    o.material.name, o.mesh
                )));
            }
            if o.material.albedo_texture.is_some()
                && albedo_maps
                && m.uvs.len() != m.positions.len()
            {
                return Err(LucentError::InvalidInput(format!(
                    "material '{}' has an albedo texture but mesh {} has no texture coordinates",
                    o.material.name, o.mesh
                )));
            }
            let translucency_id = upload
                .translucency_ids
                .and_then(|ids| ids.get(index).copied())
                .unwrap_or(0);
            // A material in the table shades with its own term or, forced, its medium's.
            let thickness = match (o.material.translucency_in_table(), translucency_id) {
                (Some(t), id) if id > 0 => t.thickness_factor().extend(f32::from(id)).to_array(),
                _ => [0.0; 4],
            };
            let profile_id = upload
                .profile_ids
                .and_then(|ids| ids.get(index).copied())
                .unwrap_or(0);
            let position_in = |sources: &[&TextureSource], t: Option<&TextureSource>| {
                t.and_then(|t| sources.iter().position(|s| *s == t))
                    .map_or(0, |i| i + 1)
            };
            let layered_id = upload
                .layered_ids
                .and_then(|ids| ids.get(index).copied())
                .unwrap_or(0);
            // A layered object's depth textures (TexDep), each after the zero texture.
            let mut depth = [0usize; 2];
            if let (Some(medium), true) = (&o.material.layers, layered_id > 0 && depth_maps) {
                for (slot, t) in depth.iter_mut().zip(&medium.depth_textures) {
                    *slot = position_in(&depth_sources, Some(t));
                }
            }
            let set = MapSet {
                normal: if normal_maps {
                    position_in(&normal_sources, o.material.normal_texture.as_ref())
                } else {
                    0
                },
                albedo: if albedo_maps {
                    position_in(&albedo_sources, o.material.albedo_texture.as_ref())
                } else {
                    0
                },
                depth,
            };
            let (maps, depth_maps_index) = match &mut self.maps {
                Some(maps) => (
                    index_of_or_push(&mut maps.sets, set),
                    index_of_or_push(&mut maps.depth_sets, depth),
                ),
                None => (0, 0),
            };
            // Li et al.'s eq. 3 weights the lit diffuse by λ1 and the specular by λ2: lighting
            // is linear in albedo and specular intensity, so weighting them here is exact.
            let (diffuse_weight, specular_weight) = match (&o.material.layers, layered_id) {
                (Some(m), id) if id > 0 => (m.weights[0], m.weights[1]),
                _ => (1.0, 1.0),
            };
            self.draws.push(Draw {
                mesh: o.mesh,
                maps,
                depth_maps: depth_maps_index,
                constants: ObjectConstants {
                    model: o.transform.to_cols_array_2d(),
                    albedo_specular: (o.material.albedo * diffuse_weight)
                        .extend(o.material.specular * specular_weight)
                        .to_array(),
                    roughness: [
                        o.material.roughness,
                        f32::from(profile_id),
                        f32::from(layered_id),
                        0.0,
                    ],
                    thickness,
                },
            });
        }
        Ok(())
    }

    /// Loads and uploads the normal (or LEAN), albedo and depth maps, each list after its
    /// neutral texture.
    fn upload_maps(
        &mut self,
        gpu: &GpuContext,
        scene: &Scene,
        lean: bool,
        normal_maps: bool,
        albedo_maps: bool,
        depth_sources: &[&TextureSource],
    ) -> Result<()> {
        self.maps = Some(MaterialMaps {
            normal: Vec::new(),
            lean2: Vec::new(),
            albedo: Vec::new(),
            depth: Vec::new(),
            sampler: create_repeat_sampler(gpu)?,
            sets: Vec::new(),
            // The zero pair first: objects without TexDep layers bind it.
            depth_sets: vec![[0, 0]],
        });
        let maps = self.maps.as_mut().expect("just set");
        if normal_maps {
            let flat = Texture::from_texels(
                "flat normal map",
                1,
                1,
                TextureUsage::Data,
                vec![[0.5, 0.5, 1.0, 1.0]],
            )?;
            let push = |maps: &mut MaterialMaps, texture: &Texture, name: &str| -> Result<()> {
                if lean {
                    // One LEAN map at a time: each is made, uploaded and dropped before the
                    // next, so a large map's two LEAN maps are never in memory together.
                    let lean1 = crate::scene::lean::lean_map(texture, 1)?;
                    maps.normal
                        .push(upload_texture(gpu, &lean1, &format!("{name} LEAN 1"))?);
                    drop(lean1);
                    let lean2 = crate::scene::lean::lean_map(texture, 2)?;
                    maps.lean2
                        .push(upload_texture(gpu, &lean2, &format!("{name} LEAN 2"))?);
                } else {
                    maps.normal.push(upload_texture(gpu, texture, name)?);
                }
                Ok(())
            };
            push(maps, &flat, "flat normal map")?;
            let sources = distinct_sources(scene, |o| o.material.normal_texture.as_ref());
            for (i, source) in sources.iter().enumerate() {
                let name = format!("{} normal map {i}", scene.name);
                // A file or an encoded image in a LEAN frame: decoded as stored (procedural
                // maps are made, not decoded).
                let decoded = match source {
                    TextureSource::Procedural(_) => None,
                    _ if lean => source.decode(TextureUsage::Data)?,
                    _ => None,
                };
                match (decoded, source) {
                    (Some(normals), _) => {
                        // The LEAN maps straight from the decoded file into their staging
                        // buffers: no f32 copy of the normal map or of either LEAN map. Map 2
                        // holds one value (M.xy), so it is one fp16 channel (sampled as
                        // (r, 0, 0, 1), what the four-channel map stored).
                        warn_non_finite(&source.describe(), &normals);
                        let (w, h) = (normals.width, normals.height);
                        for (which, layout) in [(1, UploadLayout::Half), (2, UploadLayout::HalfRed)]
                        {
                            let label = format!("{name} LEAN {which}");
                            let image = upload_chain(gpu, w, h, layout, &label, |out| {
                                upload::write_chain(w, h, layout, out, |x, y| {
                                    crate::scene::lean::lean_texel(normals.texel(x, y), which)
                                })
                            })?;
                            if which == 1 {
                                maps.normal.push(image);
                            } else {
                                maps.lean2.push(image);
                            }
                        }
                    }
                    (None, TextureSource::Procedural(p)) => {
                        push(
                            maps,
                            &procedural_texture(p, PROCEDURAL_TEXTURE_SIZE)?,
                            &name,
                        )?;
                    }
                    (None, _) => {
                        maps.normal
                            .push(upload_source(gpu, source, TextureUsage::Data, &name)?);
                    }
                }
            }
        }
        if albedo_maps {
            let white = Texture::from_texels("white", 1, 1, TextureUsage::Color, vec![[1.0; 4]])?;
            maps.albedo
                .push(upload_texture(gpu, &white, "white albedo map")?);
            let sources = distinct_sources(scene, |o| o.material.albedo_texture.as_ref());
            for (i, source) in sources.iter().enumerate() {
                let name = format!("{} albedo map {i}", scene.name);
                maps.albedo
                    .push(upload_source(gpu, source, TextureUsage::Color, &name)?);
            }
        }
        if !depth_sources.is_empty() {
            // Layers of a medium with one depth texture read 0 from the second: never read,
            // since only texture layers read texels.
            let zero =
                Texture::from_texels("zero depth", 1, 1, TextureUsage::Data, vec![[0.0; 4]])?;
            maps.depth
                .push(upload_texture(gpu, &zero, "zero depth map")?);
            for (i, source) in depth_sources.iter().enumerate() {
                // Linear data: 8-bit files stay 8-bit, float and 16-bit ones become fp16 on
                // the GPU (3 significant digits), NaN and infinite texels 0.
                let name = format!("{} layer depth map {i}", scene.name);
                maps.depth
                    .push(upload_source(gpu, source, TextureUsage::Data, &name)?);
            }
        }
        Ok(())
    }

    /// Frees the GPU memory. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        for m in self.meshes {
            m.vertices.destroy(gpu);
            gpu.destroy_buffer(m.indices);
            for b in [m.thickness, m.surface].into_iter().flatten() {
                gpu.destroy_buffer(b);
            }
        }
        if let Some(maps) = self.maps {
            for image in maps
                .normal
                .into_iter()
                .chain(maps.lean2)
                .chain(maps.albedo)
                .chain(maps.depth)
            {
                gpu.destroy_image(image);
            }
            // SAFETY: created by `create_repeat_sampler`; the GPU is done with it.
            unsafe { gpu.device.destroy_sampler(maps.sampler, None) };
        }
        self.per_frame.destroy(gpu);
    }
}

/// A deforming mesh's vertices: one host-visible buffer per frame in flight, each holding
/// `mesh` until its slot's first frame rewrites it.
fn per_slot_vertices(
    gpu: &GpuContext,
    mesh: &crate::scene::Mesh,
    slots: usize,
    name: &str,
) -> Result<VertexStream> {
    let data = mesh.gpu_vertices();
    let bytes: &[u8] = bytemuck::cast_slice(&data);
    let mut buffers: Vec<GpuBuffer> = Vec::with_capacity(slots);
    for slot in 0..slots.max(1) {
        let made = gpu.create_buffer(
            bytes.len() as u64,
            vk::BufferUsageFlags::VERTEX_BUFFER,
            crate::backend::memory::MemoryUse::Upload,
            &format!("{name} vertices (slot {slot})"),
        );
        match made {
            Ok(mut b) => {
                if let Some(mapped) = b.mapped_mut() {
                    mapped.copy_from_slice(bytes);
                }
                buffers.push(b);
            }
            Err(e) => {
                for b in buffers {
                    gpu.destroy_buffer(b);
                }
                return Err(e);
            }
        }
    }
    Ok(VertexStream::PerSlot {
        handles: buffers.iter().map(|b| b.buffer).collect(),
        buffers: buffers.into_iter().map(Mutex::new).collect(),
    })
}

/// UV + tangent per vertex; meshes without them (drawn without a map in a frame with maps)
/// get zeros and a +X tangent, which the neutral maps ignore.
fn surface_stream(mesh: &crate::scene::Mesh) -> Vec<[f32; 6]> {
    (0..mesh.positions.len())
        .map(|i| {
            let uv = mesh.uvs.get(i).copied().unwrap_or_default();
            let t = mesh
                .tangents
                .get(i)
                .copied()
                .unwrap_or(glam::Vec4::new(1.0, 0.0, 0.0, 1.0));
            [uv.x, uv.y, t.x, t.y, t.z, t.w]
        })
        .collect()
}

/// The trilinear, repeating sampler of material maps (also the host meshes' depth textures in
/// `lucent::embed::LayeredEffect`'s light-space maps, read as lucent reads its own).
pub(crate) fn create_repeat_sampler(gpu: &GpuContext) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::LINEAR)
        .min_filter(vk::Filter::LINEAR)
        .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
        .address_mode_u(vk::SamplerAddressMode::REPEAT)
        .address_mode_v(vk::SamplerAddressMode::REPEAT)
        .address_mode_w(vk::SamplerAddressMode::REPEAT)
        .max_lod(vk::LOD_CLAMP_NONE);
    // SAFETY: valid device and create info.
    unsafe { gpu.device.create_sampler(&info, None) }.vk("vkCreateSampler")
}
