//! [`Renderer`]: a scene compiled into an executable frame on a device, recorded into any
//! command buffer, with frames in flight and into the caller's target image.

use std::sync::Arc;

use ash::vk;

use super::declare::compile_options;
use super::{
    declare_frame, decode_texels, FrameDesc, FrameImages, FrameOutputs, FrameRunner, FrameSettings,
    GBufferReadback, LitReadback,
};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::technique::SlotWrite;
use crate::gpu_scene::tiles::{bounds_of, mesh_bounds};
use crate::gpu_scene::{FrameUniforms, SceneGpu, SlotTiles, FRAME};
use crate::graph::{Executable, RenderGraph, ResourceId, Subresources};
use crate::scene::{Scene, MAX_LIGHTS};
use crate::{LucentError, Result};
use glam::Vec3;

/// A scene compiled into an executable frame on a device.
///
/// One frame at a time: [`Renderer::update`] then record ([`FrameRunner`] does both halves of
/// a frame and waits). Frames in flight ([`FrameSettings::frames_in_flight`] N): per frame,
/// [`Renderer::update_slot`] for slot `k` (whose previous frame has completed),
/// [`Renderer::bind_target`] when rendering into the caller's images, then
/// [`Renderer::record`] into the caller's command buffer with slot `k`; the N slots' frames
/// may run on the GPU together.
pub struct Renderer {
    /// The executable frame.
    pub executable: Executable,
    /// Where the outputs are.
    pub outputs: FrameOutputs,
    /// The settings it was built with.
    pub settings: FrameSettings,
    /// What the frame shades (derived from the scene's materials).
    pub desc: FrameDesc,
    scene_gpu: Option<Arc<SceneGpu>>,
    /// Object-space bounds per mesh, for the screen tiles (frames with translucency or SSS).
    mesh_bounds: Vec<(Vec3, Vec3)>,
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
        if let Some(target) = settings.target {
            check_target_format(target.format)?;
        }
        let desc = FrameDesc::new(scene, &settings)?;
        desc.check_described(&settings)?;
        let scene_gpu = Arc::new(SceneGpu::new(
            gpu,
            scene,
            &desc.upload(settings.frames_in_flight),
        )?);
        let mut graph = RenderGraph::new();
        let outputs = declare_frame(&mut graph, &settings, &desc, Some(&scene_gpu));
        let compiled = graph
            .compile(compile_options(&settings))
            .and_then(|(plan, execs)| {
                Executable::new(
                    gpu,
                    plan,
                    execs,
                    shaders,
                    pipeline_cache.handle,
                    settings.frames_in_flight,
                )
            });
        let executable = match compiled {
            Ok(e) => e,
            Err(e) => {
                if let Ok(s) = Arc::try_unwrap(scene_gpu) {
                    s.destroy(gpu);
                }
                return Err(e);
            }
        };
        // Every object's box, for the tiles of translucency, SSS and layered media and the
        // directional lights' maps. Computed whatever the frame has (one pass over the
        // vertices): a list of the features that need it missed one twice (a plain scene's
        // maps, a layered scene without shadows).
        let mesh_bounds = mesh_bounds(scene);
        let mut renderer = Self {
            executable,
            outputs,
            settings,
            desc,
            scene_gpu: Some(scene_gpu),
            mesh_bounds,
        };
        if let Err(e) = renderer.update(scene) {
            renderer.destroy(gpu);
            return Err(e);
        }
        Ok(renderer)
    }

    /// Writes the scene's camera, lights and material values into every slot of the
    /// per-frame parameters. Call between frames: the GPU must not be reading any slot (with
    /// frames in flight use [`Self::update_slot`]). Fails when the scene no longer has the
    /// shape the frame was built for (see [`Self::can_update`]).
    pub fn update(&mut self, scene: &Scene) -> Result<()> {
        for slot in 0..self.settings.frames_in_flight {
            self.update_slot(scene, slot)?;
        }
        Ok(())
    }

    /// Whether [`Self::update`] can show `scene` without rebuilding: the same features,
    /// profiles, permutations and per-object IDs; only values changed (camera, lights, a
    /// material's translucency power or an SSS width). Changing a knob that only changes
    /// values must not re-upload the scene.
    pub fn can_update(&self, scene: &Scene) -> Result<bool> {
        let desc = FrameDesc::new(scene, &self.settings)?;
        Ok(scene.objects.len() == self.scene_gpu().draws.len()
            && desc.same_shape(&self.desc, &self.settings))
    }

    /// Takes `settings` if they differ from the frame's only in values the per-frame tables
    /// carry (the bilateral sensitivity); returns whether it did (otherwise the frame must be
    /// rebuilt for them).
    pub fn retune(&mut self, settings: &FrameSettings) -> bool {
        let values_only = FrameSettings {
            sss: crate::features::sss::SssKnobs {
                sensitivity: self.settings.sss.sensitivity,
                ..settings.sss
            },
            width: self.settings.width,
            height: self.settings.height,
            technique: self.settings.technique,
            debug_view: self.settings.debug_view,
            ..*settings
        } == self.settings;
        if values_only {
            self.settings.sss.sensitivity = settings.sss.sensitivity;
        }
        values_only
    }

    /// Writes `scene`'s per-frame values into slot `slot` (whose previous frame has
    /// completed): frame uniforms, the translucency material table, the SSS profile table,
    /// the light-space maps' table, the screen tiles and, in a deforming scene, every mesh
    /// deformed at `scene.time` (normals recomputed) into the slot's vertex buffers.
    pub fn update_slot(&self, scene: &Scene, slot: usize) -> Result<()> {
        if slot >= self.settings.frames_in_flight {
            return Err(LucentError::InvalidInput(format!(
                "frame slot {slot}: the renderer has {} frame(s) in flight",
                self.settings.frames_in_flight
            )));
        }
        let desc = FrameDesc::new(scene, &self.settings)?;
        if scene.objects.len() != self.scene_gpu().draws.len()
            || !desc.same_shape(&self.desc, &self.settings)
        {
            return Err(LucentError::InvalidInput(format!(
                "scene '{}' no longer has the shape its frame was built for (features, \
                 profiles or objects changed): build a new renderer",
                scene.name
            )));
        }
        let deformed_bounds;
        let mesh_bounds = match scene.deformation {
            Some(deformation) => {
                deformed_bounds = self.deform(scene, deformation, slot)?;
                &deformed_bounds
            }
            None => &self.mesh_bounds,
        };
        let per_frame = &self.scene_gpu().per_frame;
        let (width, height) = (self.settings.width, self.settings.height);
        let mut uniforms = FrameUniforms::new(scene, width, height);
        if let Some(f) = self.settings.fault {
            uniforms.fault = [f.x as i32, f.y as i32, if f.nan { 1 } else { 2 }, 0];
        }
        per_frame.write(slot, &FRAME, bytemuck::bytes_of(&uniforms))?;
        if let Some(shadows) = &desc.shadows {
            let table = shadows.uniforms(scene, mesh_bounds);
            per_frame.write(
                slot,
                &crate::features::shadows::TABLE_REGION,
                bytemuck::bytes_of(&table),
            )?;
        }
        let mut tiles = SlotTiles::default();
        let mut write = SlotWrite {
            scene,
            mesh_bounds,
            width,
            height,
            knobs: self.settings.part_knobs(),
            per_frame,
            slot,
            tiles: &mut tiles,
        };
        for part in desc.parts() {
            part.write_slot(&mut write)?;
        }
        *per_frame.tiles(slot) = tiles;
        Ok(())
    }

    /// Deforms every mesh of `scene` at `scene.time` into slot `slot`'s vertex buffers;
    /// returns the deformed meshes' boxes (for this frame's tiles and maps). Only the scene's
    /// own meshes are deformed: the frame was built for them.
    fn deform(
        &self,
        scene: &Scene,
        deformation: crate::scene::Deformation,
        slot: usize,
    ) -> Result<Vec<(Vec3, Vec3)>> {
        let gpu_meshes = &self.scene_gpu().meshes;
        if gpu_meshes.len() != scene.meshes.len() {
            return Err(LucentError::InvalidInput(format!(
                "scene '{}' has {} meshes; its frame was built for {}",
                scene.name,
                scene.meshes.len(),
                gpu_meshes.len()
            )));
        }
        let mut deformed = Vec::with_capacity(scene.meshes.len());
        for (i, (mesh, gpu_mesh)) in scene.meshes.iter().zip(gpu_meshes).enumerate() {
            let mesh = deformation.apply(mesh, scene.time);
            // Guarded here: a deformation of a finite mesh at a finite time is finite, but a
            // NaN time or parameter must not reach a vertex buffer.
            mesh.validate(&format!(
                "scene '{}' mesh {i} at t = {}",
                scene.name, scene.time
            ))?;
            gpu_mesh
                .vertices
                .write(slot, bytemuck::cast_slice(&mesh.gpu_vertices()))?;
            deformed.push(mesh);
        }
        Ok(bounds_of(&deformed))
    }

    /// Gives the caller's target its image for the frame recorded next with slot `slot`
    /// (frames built with [`FrameSettings::target`]): an image of the target's format and the
    /// frame's size, usable as a colour attachment, and a view of it. The frame last recorded
    /// with `slot` must have completed: its framebuffer is replaced.
    pub fn bind_target(
        &mut self,
        gpu: &GpuContext,
        slot: usize,
        image: vk::Image,
        view: vk::ImageView,
    ) -> Result<()> {
        self.bind_target_at(gpu, slot, image, view, Subresources::FIRST)
    }

    /// [`Self::bind_target`] for a view of one mip level and layer of a larger image
    /// (`range`): the frame's barriers on the target cover those subresources only.
    pub fn bind_target_at(
        &mut self,
        gpu: &GpuContext,
        slot: usize,
        image: vk::Image,
        view: vk::ImageView,
        range: Subresources,
    ) -> Result<()> {
        if !self.outputs.target {
            return Err(LucentError::InvalidInput(
                "bind_target: the frame was built without a target (FrameSettings::target)".into(),
            ));
        }
        self.executable
            .bind_imports(gpu, slot, &[(self.outputs.display, image, view, range)])
    }

    /// Records one frame for slot `slot` into `cmd` (in the recording state), with a
    /// timestamp pair per physical pass when `timer` is given. Fails when the frame renders
    /// into the caller's target and none is bound.
    pub fn record(
        &self,
        gpu: &GpuContext,
        cmd: vk::CommandBuffer,
        slot: usize,
        timer: Option<&mut crate::backend::timer::GpuTimer>,
    ) -> Result<()> {
        if slot >= self.settings.frames_in_flight {
            return Err(LucentError::InvalidInput(format!(
                "frame slot {slot}: the renderer has {} frame(s) in flight",
                self.settings.frames_in_flight
            )));
        }
        if !self.executable.ready(slot) {
            return Err(LucentError::InvalidInput(
                "the frame renders into the caller's target and none is bound (bind_target)".into(),
            ));
        }
        self.executable.record_frame(gpu, cmd, slot, timer);
        Ok(())
    }

    fn scene_gpu(&self) -> &SceneGpu {
        self.scene_gpu.as_ref().expect("alive until destroy")
    }

    /// The scene's GPU meshes and per-frame buffer, shared (the benchmark's mesh floors draw
    /// the same objects); `None` once destroyed.
    #[cfg(feature = "measure")]
    pub(crate) fn scene_gpu_shared(&self) -> Option<&Arc<SceneGpu>> {
        self.scene_gpu.as_ref()
    }

    /// Reads lucent's own display image of the last frame: RGBA8, sRGB-encoded, tightly
    /// packed (a frame with a caller's target has none: the caller reads its image).
    pub fn read_display(&self, gpu: &GpuContext) -> Result<Vec<u8>> {
        self.read_export(gpu, self.outputs.display)
    }

    /// Reads the tonemapped image the anti-aliasing read in the last frame: RGBA8, sRGB-encoded
    /// colour, luma in alpha (needs `export_ldr` in a frame with anti-aliasing).
    pub fn read_ldr(&self, gpu: &GpuContext) -> Result<Vec<u8>> {
        let id = self.outputs.ldr.ok_or_else(|| {
            LucentError::InvalidInput(
                "the tonemapped image is not exported in this frame (export_ldr, frames with \
                 anti-aliasing)"
                    .into(),
            )
        })?;
        self.read_export(gpu, id)
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

    /// Reads the lighting pass's diffuse and specular of the last frame (before the SSS
    /// blurs), decoded to f32 RGBA (needs `export_lit` in a frame with SSS).
    pub fn read_lit(&self, gpu: &GpuContext) -> Result<LitReadback> {
        let (diffuse, specular) = self.outputs.lit.ok_or_else(|| {
            LucentError::InvalidInput(
                "the lit diffuse and specular are not exported in this frame (export_lit, \
                 frames with SSS)"
                    .into(),
            )
        })?;
        let read = |id: ResourceId| -> Result<Vec<[f32; 4]>> {
            let format = self.executable.plan.resources[id].info.format;
            decode_texels(&self.read_export(gpu, id)?, format)
        };
        Ok(LitReadback {
            diffuse: read(diffuse)?,
            specular: read(specular)?,
        })
    }

    /// Reads the light-space maps' depth atlas of the last frame: its width, height and
    /// depths (needs `export_shadows` and a frame with light-space maps).
    pub fn read_shadow_map(&self, gpu: &GpuContext) -> Result<(u32, u32, Vec<f32>)> {
        let id = self.outputs.shadows.ok_or_else(|| {
            LucentError::InvalidInput(
                "the light-space maps are not exported in this frame (export_shadows, frames \
                 with shadows)"
                    .into(),
            )
        })?;
        let info = self.executable.plan.resources[id].info;
        let texels = decode_texels(&self.read_export(gpu, id)?, info.format)?;
        Ok((
            info.width,
            info.height,
            texels.into_iter().map(|t| t[0]).collect(),
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
            // Stored as ID / 255 (UNORM8): rounding recovers the integer.
            sss: outputs
                .sss
                .map(|id| read(id).map(|t| t.into_iter().map(|v| (v[0] * 255.0).round()).collect()))
                .transpose()?,
            lean: outputs.lean.map(read).transpose()?,
            layered: outputs.layered.map(read).transpose()?,
            // Packed fp16 pairs: raw bytes (as f32 the integers would lose bits).
            layer_depths: outputs
                .layer_depths
                .map(|id| self.read_export(gpu, id))
                .transpose()?,
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
        // The passes hold the scene's data: they go first, so the data is ours alone.
        self.executable.destroy(gpu);
        if let Some(s) = self.scene_gpu.take().and_then(|s| Arc::try_unwrap(s).ok()) {
            s.destroy(gpu);
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

/// Refuses target formats the tonemap cannot write: colour formats of the format table with
/// four 8-bit UNORM or SRGB channels, or RGBA fp16 or fp32.
fn check_target_format(format: vk::Format) -> Result<()> {
    use crate::backend::format::{format_info, FormatKind};
    let ok = format_info(format).is_some_and(|f| {
        f.channels >= 3
            && match f.kind {
                FormatKind::Unorm | FormatKind::Srgb => f.bytes == 4,
                FormatKind::Float => f.bytes == 8 || f.bytes == 16,
                _ => false,
            }
    });
    if ok {
        Ok(())
    } else {
        Err(LucentError::InvalidInput(format!(
            "target format {format:?}: lucent writes RGBA8/BGRA8 UNORM or SRGB, RGBA16F or \
             RGBA32F targets"
        )))
    }
}
