//! What a scene becomes on the GPU: meshes with their vertex streams, the draws, normal and
//! albedo maps, and the translucency material table. Made once per scene and frame layout
//! ([`SceneGpu::new`]); the passes of [`crate::features`] share it read-only.

use std::sync::Arc;

use ash::vk;

use crate::backend::{GpuBuffer, GpuContext, GpuImage};
use crate::error::VkResultExt;
use crate::scene::material::TextureSource;
use crate::scene::texture::{load_texture, procedural_texture, Texture, TextureUsage};
use crate::scene::Scene;
use crate::Result;

use crate::features::translucency::{thickness_factor, MaterialTable, ThicknessPacking};

/// One draw: which mesh, with which per-object constants.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// Index into [`SceneGpu::meshes`].
    pub mesh: usize,
    /// Index into [`NormalMaps::images`] (0: the flat map).
    pub normal_map: usize,
    /// Push constants of the G-buffer pass.
    pub constants: ObjectConstants,
}

/// Per-object push constants (glsl/deferred/gbuffer.vert `Object`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ObjectConstants {
    /// Object → world.
    pub model: [[f32; 4]; 4],
    /// Albedo rgb, specular a.
    pub albedo_specular: [f32; 4],
    /// Roughness in x.
    pub roughness: [f32; 4],
    /// Translucency: thickness factor rgb (tint x constant thickness), material ID in w
    /// (0: not translucent). Zero when the frame has no translucency.
    pub thickness: [f32; 4],
}

/// A mesh on the GPU.
pub struct GpuMesh {
    /// Vertex buffer.
    pub vertices: GpuBuffer,
    /// Index buffer (u32).
    pub indices: GpuBuffer,
    /// Number of indices.
    pub index_count: u32,
    /// Per-vertex RGB thickness (vertex colours, or white), only in frames with translucency.
    pub thickness: Option<GpuBuffer>,
    /// Per-vertex UV + tangent (`[u, v, tx, ty, tz, tw]`), only in normal-mapped frames.
    pub surface: Option<GpuBuffer>,
}

/// What the translucency technique keeps on the GPU (absent from frames without it).
pub struct TranslucencyGpu {
    /// The material table uniform buffer ([`crate::features::translucency::MaterialTableGpu`]).
    pub materials: GpuBuffer,
    /// How GB2 packs thickness.
    pub packing: ThicknessPacking,
    /// The lighting pass's rectangles for this frame ([`translucency::tile_rects`]), written
    /// by the renderer before each frame is recorded.
    pub tiles: std::sync::Mutex<Vec<crate::features::translucency::TileRect>>,
}

/// Normal maps of a normal-mapped frame: image 0 is a flat 1x1 map for objects without one.
/// In LEAN frames (LCB, LBB) each normal map is uploaded as its two LEAN maps instead
/// ([`crate::scene::lean`]): `images` holds LEAN map 1, `lean2` LEAN map 2.
pub struct NormalMaps {
    /// Sampled images (RGBA16F, mipmapped), in `SHADER_READ_ONLY_OPTIMAL`.
    pub images: Vec<GpuImage>,
    /// LEAN frames: the second LEAN map of each entry of `images` (empty otherwise).
    pub lean2: Vec<GpuImage>,
    /// Trilinear, repeating sampler.
    pub sampler: vk::Sampler,
}

/// Side of the procedural textures lucent makes, in texels.
pub const PROCEDURAL_TEXTURE_SIZE: u32 = 512;

/// The scene's GPU data the passes share: meshes, draws, and the frame uniform buffer.
pub struct SceneGpu {
    /// Meshes.
    pub meshes: Vec<GpuMesh>,
    /// Draws in submission order.
    pub draws: Vec<Draw>,
    /// Frame uniform buffer (camera, lights), owned and written by the renderer.
    pub frame_uniforms: vk::Buffer,
    /// Translucency data, when the frame shades translucency.
    pub translucency: Option<TranslucencyGpu>,
    /// Normal maps, when some object has one.
    pub normal_maps: Option<NormalMaps>,
    /// The screen's rectangles for the SSS passes this frame, marked (`translucent`) where
    /// objects with a profile (widened by the profile's reach) may be: the blurs run only in
    /// those. Written by the renderer before each frame; `None`: everything is blurred.
    pub sss_tiles: std::sync::Mutex<Option<Vec<crate::features::translucency::TileRect>>>,
}

/// Linear RGBA f32 texels as tightly packed RGBA16F bytes (values clamped to fp16's range).
fn rgba16f_bytes(texels: &[[f32; 4]]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.map(|v| half::f16::from_f32(v.clamp(-65504.0, 65504.0))))
        .flat_map(|h| h.to_le_bytes())
        .collect()
}

/// Uploads a texture with its whole mip chain as RGBA16F.
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
    let levels: Vec<Vec<u8>> = texture.mips.iter().map(|m| rgba16f_bytes(m)).collect();
    gpu.upload_image(&desc, &levels, name)
}

impl SceneGpu {
    /// Uploads `scene`'s meshes; `frame_uniforms` is the renderer's uniform buffer. With
    /// `translucency` (the frame's material table and packing), also each mesh's thickness
    /// stream and the material table; when some object has a normal map, each mesh's UV +
    /// tangent stream and the normal maps (with `lean`, their LEAN maps).
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        frame_uniforms: vk::Buffer,
        translucency: Option<(&MaterialTable, ThicknessPacking)>,
        lean: bool,
    ) -> Result<Arc<Self>> {
        let mut out = Self {
            meshes: Vec::with_capacity(scene.meshes.len()),
            draws: Vec::with_capacity(scene.objects.len()),
            frame_uniforms,
            translucency: None,
            normal_maps: None,
            sss_tiles: std::sync::Mutex::new(None),
        };
        // Everything created so far is freed by `destroy` if a later step fails.
        match out.upload(gpu, scene, translucency, lean) {
            Ok(()) => Ok(Arc::new(out)),
            Err(e) => {
                out.destroy(gpu);
                Err(e)
            }
        }
    }

    fn upload(
        &mut self,
        gpu: &GpuContext,
        scene: &Scene,
        translucency: Option<(&MaterialTable, ThicknessPacking)>,
        lean: bool,
    ) -> Result<()> {
        if let Some((table, packing)) = translucency {
            let materials = gpu.upload_buffer(
                std::slice::from_ref(&table.gpu()),
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                &format!("{} translucency materials", scene.name),
            )?;
            self.translucency = Some(TranslucencyGpu {
                materials,
                packing,
                tiles: std::sync::Mutex::new(Vec::new()),
            });
        }
        // Normal maps: one per distinct source, after the flat default.
        let mut sources: Vec<&TextureSource> = Vec::new();
        for o in &scene.objects {
            if let Some(t) = &o.material.normal_texture {
                if !sources.contains(&t) {
                    sources.push(t);
                }
            }
        }
        let normal_mapped = !sources.is_empty();
        if normal_mapped {
            self.normal_maps = Some(NormalMaps {
                images: Vec::with_capacity(sources.len() + 1),
                lean2: Vec::new(),
                sampler: create_repeat_sampler(gpu)?,
            });
            let flat = Texture::from_texels(
                "flat normal map",
                1,
                1,
                TextureUsage::Data,
                vec![[0.5, 0.5, 1.0, 1.0]],
            )?;
            let maps = self.normal_maps.as_mut().expect("just set");
            let push = |maps: &mut NormalMaps, texture: &Texture, name: &str| -> Result<()> {
                if lean {
                    let (lean1, lean2) = crate::scene::lean::lean_maps(texture)?;
                    maps.images
                        .push(upload_texture(gpu, &lean1, &format!("{name} LEAN 1"))?);
                    maps.lean2
                        .push(upload_texture(gpu, &lean2, &format!("{name} LEAN 2"))?);
                } else {
                    maps.images.push(upload_texture(gpu, texture, name)?);
                }
                Ok(())
            };
            push(maps, &flat, "flat normal map")?;
            for (i, source) in sources.iter().enumerate() {
                let texture = match source {
                    TextureSource::File(path) => load_texture(path, TextureUsage::Data)?,
                    TextureSource::Procedural(p) => procedural_texture(p, PROCEDURAL_TEXTURE_SIZE)?,
                };
                push(maps, &texture, &format!("{} normal map {i}", scene.name))?;
            }
        }
        for (i, mesh) in scene.meshes.iter().enumerate() {
            // A deforming scene is drawn as it stands at t = 0 (per-frame updates come with
            // the layered-scattering technique that needs them).
            let deformed = scene.deformation.map(|d| d.apply(mesh, 0.0));
            let mesh = deformed.as_ref().unwrap_or(mesh);
            mesh.validate(&format!("scene '{}' mesh {i}", scene.name))?;
            let name = format!("{} mesh {i}", scene.name);
            let vertices = gpu.upload_buffer(
                &mesh.gpu_vertices(),
                vk::BufferUsageFlags::VERTEX_BUFFER,
                &format!("{name} vertices"),
            )?;
            let indices = gpu.upload_buffer(
                &mesh.indices,
                vk::BufferUsageFlags::INDEX_BUFFER,
                &format!("{name} indices"),
            );
            let indices = match indices {
                Ok(b) => b,
                Err(e) => {
                    gpu.destroy_buffer(vertices);
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
            if translucency.is_some() {
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
            if normal_mapped {
                gpu_mesh.surface = Some(gpu.upload_buffer(
                    &surface_stream(mesh),
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    &format!("{name} UVs and tangents"),
                )?);
            }
        }
        for (index, o) in scene.objects.iter().enumerate() {
            if o.material.normal_texture.is_some() {
                let m = &scene.meshes[o.mesh];
                if m.uvs.len() != m.positions.len() || m.tangents.len() != m.positions.len() {
                    return Err(crate::LucentError::InvalidInput(format!(
                        "material '{}' has a normal map but mesh {} has no UVs and tangents",
                        o.material.name, o.mesh
                    )));
                }
            }
            let thickness = match (translucency, &o.material.translucency) {
                (Some((table, _)), Some(t)) => thickness_factor(t)
                    .extend(f32::from(table.object_ids[index]))
                    .to_array(),
                _ => [0.0; 4],
            };
            let normal_map = o
                .material
                .normal_texture
                .as_ref()
                .and_then(|t| sources.iter().position(|s| *s == t))
                .map_or(0, |i| i + 1);
            self.draws.push(Draw {
                mesh: o.mesh,
                normal_map,
                constants: ObjectConstants {
                    model: o.transform.to_cols_array_2d(),
                    albedo_specular: o.material.albedo.extend(o.material.specular).to_array(),
                    // y: screen-space SSS strength (read only by SSS frames).
                    roughness: [
                        o.material.roughness,
                        if o.material.sss.is_some() { 1.0 } else { 0.0 },
                        0.0,
                        0.0,
                    ],
                    thickness,
                },
            });
        }
        Ok(())
    }

    /// Sets the lighting pass's rectangles for the next frames (frames with translucency).
    pub fn set_tiles(&self, rects: Vec<crate::features::translucency::TileRect>) {
        if let Some(t) = &self.translucency {
            // A poisoned lock only means a recording thread panicked; the data is plain.
            *t.tiles.lock().unwrap_or_else(|e| e.into_inner()) = rects;
        }
    }

    /// Sets the SSS blurs' rectangles for the next frames (`None`: whole screen).
    pub fn set_sss_tiles(&self, rects: Option<Vec<crate::features::translucency::TileRect>>) {
        // A poisoned lock only means a recording thread panicked; the data is plain.
        *self.sss_tiles.lock().unwrap_or_else(|e| e.into_inner()) = rects;
    }

    /// Frees the GPU memory. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        for m in self.meshes {
            gpu.destroy_buffer(m.vertices);
            gpu.destroy_buffer(m.indices);
            for b in [m.thickness, m.surface].into_iter().flatten() {
                gpu.destroy_buffer(b);
            }
        }
        if let Some(t) = self.translucency {
            gpu.destroy_buffer(t.materials);
        }
        if let Some(maps) = self.normal_maps {
            for image in maps.images.into_iter().chain(maps.lean2) {
                gpu.destroy_image(image);
            }
            // SAFETY: created by `create_repeat_sampler`; the GPU is done with it.
            unsafe { gpu.device.destroy_sampler(maps.sampler, None) };
        }
    }
}

/// UV + tangent per vertex; meshes without them (drawn without a normal map in a normal-mapped
/// frame) get zeros and a +X tangent, which the flat map ignores.
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

fn create_repeat_sampler(gpu: &GpuContext) -> Result<vk::Sampler> {
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
