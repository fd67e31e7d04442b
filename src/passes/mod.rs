//! The techniques, each a struct that adds its passes to a [`RenderGraph`](crate::graph::RenderGraph):
//! handles in, handles out.
//!
//! - [`deferred`]: the MRT G-buffer and per-light deferred lighting (merged as subpasses).
//! - [`translucency`]: GDC 2011 thickness-based translucency: its material table and thickness
//!   packing (its shading runs inside the deferred lighting pass).
//! - [`sss`]: screen-space subsurface scattering, separable blurs of the lit diffuse light.
//! - [`tonemap`]: HDR to display (exposure, ACES fit, sRGB).
//! - [`util`]: pipeline and descriptor helpers the passes share.

pub mod deferred;
pub mod sss;
pub mod tonemap;
pub mod translucency;
pub mod util;

use std::sync::Arc;

use ash::vk;

use crate::backend::{GpuBuffer, GpuContext};
use crate::scene::Scene;
use crate::Result;

use translucency::{thickness_factor, MaterialTable, ThicknessPacking};

/// One draw: which mesh, with which per-object constants.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    /// Index into [`SceneGpu::meshes`].
    pub mesh: usize,
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
}

/// What the translucency technique keeps on the GPU (absent from frames without it).
pub struct TranslucencyGpu {
    /// The material table uniform buffer ([`translucency::MaterialTableGpu`]).
    pub materials: GpuBuffer,
    /// How GB2 packs thickness.
    pub packing: ThicknessPacking,
    /// The lighting pass's rectangles for this frame ([`translucency::tile_rects`]), written
    /// by the renderer before each frame is recorded.
    pub tiles: std::sync::Mutex<Vec<translucency::TileRect>>,
}

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
    /// The screen rectangles the SSS blurs run in this frame (objects with a profile, widened
    /// by the profile's reach), written by the renderer before each frame; `None`: the blurs
    /// cover the whole screen.
    pub sss_tiles: std::sync::Mutex<Option<Vec<translucency::TileRect>>>,
}

impl SceneGpu {
    /// Uploads `scene`'s meshes; `frame_uniforms` is the renderer's uniform buffer. With
    /// `translucency` (the frame's material table and packing), also each mesh's thickness
    /// stream and the material table.
    pub fn new(
        gpu: &GpuContext,
        scene: &Scene,
        frame_uniforms: vk::Buffer,
        translucency: Option<(&MaterialTable, ThicknessPacking)>,
    ) -> Result<Arc<Self>> {
        let mut meshes: Vec<GpuMesh> = Vec::with_capacity(scene.meshes.len());
        let mut materials: Option<GpuBuffer> = None;
        let upload = |gpu: &GpuContext,
                      meshes: &mut Vec<GpuMesh>,
                      materials: &mut Option<GpuBuffer>|
         -> Result<()> {
            if let Some((table, _)) = translucency {
                *materials = Some(gpu.upload_buffer(
                    std::slice::from_ref(&table.gpu()),
                    vk::BufferUsageFlags::UNIFORM_BUFFER,
                    &format!("{} translucency materials", scene.name),
                )?);
            }
            for (i, mesh) in scene.meshes.iter().enumerate() {
                // A deforming scene is drawn as it stands at t = 0 (per-frame updates come with
                // the layered-scattering technique that needs them).
                let deformed = scene.deformation.map(|d| d.apply(mesh, 0.0));
                let mesh = deformed.as_ref().unwrap_or(mesh);
                mesh.validate(&format!("scene '{}' mesh {i}", scene.name))?;
                let vertices = gpu.upload_buffer(
                    &mesh.gpu_vertices(),
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    &format!("{} mesh {i} vertices", scene.name),
                )?;
                let indices = match gpu.upload_buffer(
                    &mesh.indices,
                    vk::BufferUsageFlags::INDEX_BUFFER,
                    &format!("{} mesh {i} indices", scene.name),
                ) {
                    Ok(b) => b,
                    Err(e) => {
                        gpu.destroy_buffer(vertices);
                        return Err(e);
                    }
                };
                let mut gpu_mesh = GpuMesh {
                    vertices,
                    indices,
                    index_count: mesh.indices.len() as u32,
                    thickness: None,
                };
                if translucency.is_some() {
                    // Meshes without vertex colours are uniformly "thin": the material's
                    // constant thickness then carries the value.
                    let colors: Vec<[f32; 3]> = if mesh.colors.is_empty() {
                        vec![[1.0; 3]; mesh.positions.len()]
                    } else {
                        mesh.colors.iter().map(|c| c.to_array()).collect()
                    };
                    match gpu.upload_buffer(
                        &colors,
                        vk::BufferUsageFlags::VERTEX_BUFFER,
                        &format!("{} mesh {i} thickness", scene.name),
                    ) {
                        Ok(b) => gpu_mesh.thickness = Some(b),
                        Err(e) => {
                            meshes.push(gpu_mesh);
                            return Err(e);
                        }
                    }
                }
                meshes.push(gpu_mesh);
            }
            Ok(())
        };
        if let Err(e) = upload(gpu, &mut meshes, &mut materials) {
            Self::free(gpu, meshes, materials);
            return Err(e);
        }
        let draws = scene
            .objects
            .iter()
            .enumerate()
            .map(|(index, o)| {
                let thickness = match (translucency, &o.material.translucency) {
                    (Some((table, _)), Some(t)) => thickness_factor(t)
                        .extend(f32::from(table.object_ids[index]))
                        .to_array(),
                    _ => [0.0; 4],
                };
                Draw {
                    mesh: o.mesh,
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
                }
            })
            .collect();
        Ok(Arc::new(Self {
            meshes,
            draws,
            frame_uniforms,
            sss_tiles: std::sync::Mutex::new(None),
            translucency: materials
                .zip(translucency)
                .map(|(materials, (_, packing))| TranslucencyGpu {
                    materials,
                    packing,
                    tiles: std::sync::Mutex::new(Vec::new()),
                }),
        }))
    }

    /// Sets the lighting pass's rectangles for the next frames (frames with translucency).
    pub fn set_tiles(&self, rects: Vec<translucency::TileRect>) {
        if let Some(t) = &self.translucency {
            // A poisoned lock only means a recording thread panicked; the data is plain.
            *t.tiles.lock().unwrap_or_else(|e| e.into_inner()) = rects;
        }
    }

    /// Sets the SSS blurs' rectangles for the next frames (`None`: whole screen).
    pub fn set_sss_tiles(&self, rects: Option<Vec<translucency::TileRect>>) {
        // A poisoned lock only means a recording thread panicked; the data is plain.
        *self.sss_tiles.lock().unwrap_or_else(|e| e.into_inner()) = rects;
    }

    fn free(gpu: &GpuContext, meshes: Vec<GpuMesh>, materials: Option<GpuBuffer>) {
        for m in meshes {
            gpu.destroy_buffer(m.vertices);
            gpu.destroy_buffer(m.indices);
            if let Some(t) = m.thickness {
                gpu.destroy_buffer(t);
            }
        }
        if let Some(b) = materials {
            gpu.destroy_buffer(b);
        }
    }

    /// Frees the GPU memory. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        Self::free(gpu, self.meshes, self.translucency.map(|t| t.materials));
    }
}
