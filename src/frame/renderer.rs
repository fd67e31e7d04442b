use std::sync::Arc;

use ash::vk;

use super::{
    declare_frame, decode_texels, FrameFeatures, FrameImages, FrameOutputs, FrameRunner,
    FrameSettings, GBufferReadback,
};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::{GpuBuffer, GpuContext};
use crate::features::sss;
use crate::features::translucency::{mesh_bounds, object_tiles, tile_rects, translucent_tiles};
use crate::gpu_scene::SceneGpu;
use crate::graph::{Executable, RenderGraph, ResourceId};
use crate::scene::{LightKind, Scene, MAX_LIGHTS};
use crate::{LucentError, Result};
use glam::Vec3;

/// Frame uniforms, std140 (glsl/common/scene.glsl `Frame`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    view_proj: [[f32; 4]; 4],
    inv_view_proj: [[f32; 4]; 4],
    view: [[f32; 4]; 4],
    camera_pos: [f32; 4],
    ambient: [f32; 4],
    sky: [f32; 4],
    viewport: [f32; 4],
    exposure: [f32; 4],
    light_count: [i32; 4],
    camera: [f32; 4],
    fault: [i32; 4],
    lights: [[[f32; 4]; 4]; MAX_LIGHTS],
}

impl FrameUniforms {
    /// Fills the uniforms from a scene at a size.
    pub fn new(scene: &Scene, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let view_proj = scene.camera.projection(aspect) * scene.camera.view();
        let mut lights = [[[0.0; 4]; 4]; MAX_LIGHTS];
        for (slot, light) in lights.iter_mut().zip(&scene.lights) {
            let radiance = light.radiance();
            let scale = light.translucency_scale;
            *slot = match light.kind {
                LightKind::Directional { direction } => [
                    direction.extend(0.0).to_array(),
                    radiance.extend(0.0).to_array(),
                    [0.0; 4],
                    [1.0, scale, 0.0, 0.0],
                ],
                LightKind::Point { position, range } => [
                    position.extend(1.0).to_array(),
                    radiance.extend(range).to_array(),
                    [0.0; 4],
                    [1.0, scale, 0.0, 0.0],
                ],
                LightKind::Spot {
                    position,
                    direction,
                    range,
                    inner_degrees,
                    outer_degrees,
                } => [
                    position.extend(2.0).to_array(),
                    radiance.extend(range).to_array(),
                    direction
                        .normalize_or(Vec3::NEG_Y)
                        .extend(outer_degrees.to_radians().cos())
                        .to_array(),
                    [inner_degrees.to_radians().cos(), scale, 0.0, 0.0],
                ],
            };
        }
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            view: scene.camera.view().to_cols_array_2d(),
            camera_pos: scene.camera.eye.extend(1.0).to_array(),
            ambient: scene.ambient.extend(0.0).to_array(),
            sky: scene.sky.extend(0.0).to_array(),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            exposure: [scene.exposure, 0.0, 0.0, 0.0],
            light_count: [scene.lights.len().min(MAX_LIGHTS) as i32, 0, 0, 0],
            camera: [
                scene.camera.near,
                scene.camera.far,
                scene.camera.focal_px(height),
                0.0,
            ],
            fault: [0; 4],
            lights,
        }
    }
}

/// A scene compiled into an executable frame on a device.
pub struct Renderer {
    /// The executable frame.
    pub executable: Executable,
    /// Where the outputs are.
    pub outputs: FrameOutputs,
    /// The settings it was built with.
    pub settings: FrameSettings,
    scene_gpu: Option<Arc<SceneGpu>>,
    uniforms: Option<GpuBuffer>,
    /// Object-space bounds per mesh, for the screen tiles (frames with translucency or SSS).
    mesh_bounds: Vec<(Vec3, Vec3)>,
    /// Whether the frame blurs SSS.
    sss: bool,
}

impl Renderer {
    /// Uploads the scene and compiles its frame.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        scene: &Scene,
        settings: FrameSettings,
    ) -> Result<Self> {
        if settings.width == 0
            || settings.height == 0
            || settings.width > 16384
            || settings.height > 16384
        {
            return Err(LucentError::InvalidInput(format!(
                "size {}x{} is out of range (1..=16384 per side)",
                settings.width, settings.height
            )));
        }
        if scene.lights.len() > MAX_LIGHTS {
            return Err(LucentError::InvalidInput(format!(
                "scene '{}' has {} lights; at most {MAX_LIGHTS} are supported",
                scene.name,
                scene.lights.len()
            )));
        }
        let features = FrameFeatures::new(scene, &settings)?;
        let uniforms = gpu.create_buffer(
            std::mem::size_of::<FrameUniforms>() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            gpu_allocator::MemoryLocation::CpuToGpu,
            "frame uniforms",
        )?;
        let translucency = features.translucency.as_ref().map(|(t, p)| (t, *p));
        let scene_gpu = match SceneGpu::new(
            gpu,
            scene,
            uniforms.buffer,
            translucency,
            features.sss_blur().is_some_and(sss::SssBlur::lean),
        ) {
            Ok(s) => s,
            Err(e) => {
                gpu.destroy_buffer(uniforms);
                return Err(e);
            }
        };
        let mut graph = RenderGraph::new();
        let outputs = declare_frame(&mut graph, &settings, &features, Some(&scene_gpu));
        let compiled = graph.compile(settings.compile).and_then(|(plan, execs)| {
            Executable::new(gpu, plan, execs, shaders, pipeline_cache.handle)
        });
        let executable = match compiled {
            Ok(e) => e,
            Err(e) => {
                if let Ok(s) = Arc::try_unwrap(scene_gpu) {
                    s.destroy(gpu);
                }
                gpu.destroy_buffer(uniforms);
                return Err(e);
            }
        };
        let mesh_bounds = if features.translucency.is_some() || features.sss.is_some() {
            mesh_bounds(scene)
        } else {
            Vec::new()
        };
        let mut renderer = Self {
            executable,
            outputs,
            settings,
            scene_gpu: Some(scene_gpu),
            uniforms: Some(uniforms),
            mesh_bounds,
            sss: features.sss.is_some(),
        };
        renderer.update(scene)?;
        Ok(renderer)
    }

    /// Writes the scene's camera and lights into the frame uniforms. Call between frames: the
    /// GPU must not be reading them (every frame is waited for before the next update).
    pub fn update(&mut self, scene: &Scene) -> Result<()> {
        let mut uniforms = FrameUniforms::new(scene, self.settings.width, self.settings.height);
        if let Some(f) = self.settings.fault {
            uniforms.fault = [f.x as i32, f.y as i32, if f.nan { 1 } else { 2 }, 0];
        }
        let mapped = self
            .uniforms
            .as_mut()
            .and_then(|b| b.mapped_mut())
            .ok_or_else(|| {
                LucentError::InvalidInput("frame uniform buffer is not host-visible".into())
            })?;
        let bytes = bytemuck::bytes_of(&uniforms);
        mapped[..bytes.len()].copy_from_slice(bytes);
        if let Some(scene_gpu) = self.scene_gpu.as_ref().filter(|s| s.translucency.is_some()) {
            let (width, height) = (self.settings.width, self.settings.height);
            let (columns, _, marked) = translucent_tiles(scene, &self.mesh_bounds, width, height);
            scene_gpu.set_tiles(tile_rects(columns, &marked, width, height));
        }
        if let Some(scene_gpu) = &self.scene_gpu {
            let (width, height) = (self.settings.width, self.settings.height);
            let tiles = (self.sss && self.settings.sss_tiles).then(|| {
                let (columns, _, marked) =
                    object_tiles(scene, &self.mesh_bounds, width, height, |o| {
                        o.material.sss.as_ref().map(sss::profile_reach)
                    });
                // All rectangles: the blurs draw the marked ones, LCB's and LBB's final pass
                // its LEAN variant there and the pass-through variant elsewhere.
                tile_rects(columns, &marked, width, height)
            });
            scene_gpu.set_sss_tiles(tiles);
        }
        Ok(())
    }

    /// Reads the display image of the last frame: RGBA8, sRGB-encoded, tightly packed.
    pub fn read_display(&self, gpu: &GpuContext) -> Result<Vec<u8>> {
        self.read_export(gpu, self.outputs.display)
    }

    /// Reads the linear HDR image of the last frame as f32 RGBA (needs `export_hdr`).
    pub fn read_hdr(&self, gpu: &GpuContext) -> Result<Vec<f32>> {
        let id = self.outputs.hdr.ok_or_else(|| {
            LucentError::InvalidInput("the HDR image is not exported in this frame".into())
        })?;
        Ok(crate::images::output::f16_bytes_to_f32(
            &self.read_export(gpu, id)?,
        ))
    }

    /// Runs one frame in one command buffer and reads back everything it exports.
    pub fn render_once(&self, gpu: &GpuContext) -> Result<FrameImages> {
        let mut runner = FrameRunner::new(gpu, self.executable.plan.physical.len())?;
        let timing = runner.run_frame(gpu, &self.executable);
        runner.destroy(gpu);
        let timing = timing?;
        Ok(FrameImages {
            display: self.read_display(gpu)?,
            hdr: self.outputs.hdr.map(|_| self.read_hdr(gpu)).transpose()?,
            gbuffer: self
                .outputs
                .gbuffer
                .map(|_| self.read_gbuffer(gpu))
                .transpose()?,
            timing,
        })
    }

    /// Reads the G-buffer of the last frame, decoded to f32 (needs `export_gbuffer`).
    pub fn read_gbuffer(&self, gpu: &GpuContext) -> Result<GBufferReadback> {
        let outputs = self.outputs.gbuffer.ok_or_else(|| {
            LucentError::InvalidInput("the G-buffer is not exported in this frame".into())
        })?;
        let read = |id: ResourceId| -> Result<Vec<[f32; 4]>> {
            let format = self.executable.plan.resources[id].info.format;
            decode_texels(&self.read_export(gpu, id)?, format)
        };
        Ok(GBufferReadback {
            width: self.settings.width,
            height: self.settings.height,
            gb0: read(outputs.gb0)?,
            gb1: read(outputs.gb1)?,
            gb2: outputs.gb2.map(read).transpose()?,
            sss: outputs
                .sss
                .map(|id| read(id).map(|t| t.into_iter().map(|v| v[0]).collect()))
                .transpose()?,
            lean: outputs.lean.map(read).transpose()?,
            depth: read(outputs.depth)?.into_iter().map(|t| t[0]).collect(),
            layout: outputs.layout,
        })
    }

    fn read_export(&self, gpu: &GpuContext, id: ResourceId) -> Result<Vec<u8>> {
        let image = self.executable.owned_image(id).ok_or_else(|| {
            LucentError::Graph(format!(
                "'{}' has no readable image",
                self.executable.plan.resources[id].name
            ))
        })?;
        let layout = self
            .executable
            .export_layout(id)
            .unwrap_or(vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        gpu.read_image(image, layout)
    }

    /// Destroys the frame and the scene's GPU data. The GPU must be idle.
    pub fn destroy(mut self, gpu: &GpuContext) {
        self.executable.destroy(gpu);
        if let Some(s) = self.scene_gpu.take().and_then(|s| Arc::try_unwrap(s).ok()) {
            s.destroy(gpu);
        }
        if let Some(u) = self.uniforms.take() {
            gpu.destroy_buffer(u);
        }
    }
}

/// Builds the frame of `scene`, renders it once, reads back what it exports and tears it down
/// (whatever the frame returned).
pub fn render_frame(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scene: &Scene,
    settings: FrameSettings,
) -> Result<FrameImages> {
    let renderer = Renderer::new(gpu, shaders, pipeline_cache, scene, settings)?;
    let images = renderer.render_once(gpu);
    let idle = gpu.wait_idle();
    renderer.destroy(gpu);
    idle?;
    images
}
