//! The techniques, each a struct that adds its passes to a [`RenderGraph`](crate::graph::RenderGraph):
//! handles in, handles out.
//!
//! - [`deferred`]: the MRT G-buffer and per-light deferred lighting (merged as subpasses).
//! - [`tonemap`]: HDR to display (exposure, ACES fit, sRGB).
//! - [`util`]: pipeline and descriptor helpers the passes share.

pub mod deferred;
pub mod tonemap;
pub mod util;

use std::sync::Arc;

use ash::vk;

use crate::backend::{GpuBuffer, GpuContext};
use crate::scene::Scene;
use crate::Result;

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
}

/// A mesh on the GPU.
pub struct GpuMesh {
    /// Vertex buffer.
    pub vertices: GpuBuffer,
    /// Index buffer (u32).
    pub indices: GpuBuffer,
    /// Number of indices.
    pub index_count: u32,
}

/// The scene's GPU data the passes share: meshes, draws, and the frame uniform buffer.
pub struct SceneGpu {
    /// Meshes.
    pub meshes: Vec<GpuMesh>,
    /// Draws in submission order.
    pub draws: Vec<Draw>,
    /// Frame uniform buffer (camera, lights), owned and written by the renderer.
    pub frame_uniforms: vk::Buffer,
}

impl SceneGpu {
    /// Uploads `scene`'s meshes; `frame_uniforms` is the renderer's uniform buffer.
    pub fn new(gpu: &GpuContext, scene: &Scene, frame_uniforms: vk::Buffer) -> Result<Arc<Self>> {
        let mut meshes: Vec<GpuMesh> = Vec::with_capacity(scene.meshes.len());
        let upload = |gpu: &GpuContext, meshes: &mut Vec<GpuMesh>| -> Result<()> {
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
                meshes.push(GpuMesh {
                    vertices,
                    indices,
                    index_count: mesh.indices.len() as u32,
                });
            }
            Ok(())
        };
        if let Err(e) = upload(gpu, &mut meshes) {
            for m in meshes {
                gpu.destroy_buffer(m.vertices);
                gpu.destroy_buffer(m.indices);
            }
            return Err(e);
        }
        let draws = scene
            .objects
            .iter()
            .map(|o| Draw {
                mesh: o.mesh,
                constants: ObjectConstants {
                    model: o.transform.to_cols_array_2d(),
                    albedo_specular: o.material.albedo.extend(o.material.specular).to_array(),
                    roughness: [o.material.roughness, 0.0, 0.0, 0.0],
                },
            })
            .collect();
        Ok(Arc::new(Self {
            meshes,
            draws,
            frame_uniforms,
        }))
    }

    /// Frees the GPU memory. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        for m in self.meshes {
            gpu.destroy_buffer(m.vertices);
            gpu.destroy_buffer(m.indices);
        }
    }
}
