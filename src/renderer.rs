//! Turning a scene and a technique into a compiled frame, and running frames.
//!
//! [`declare_frame`] is the one place that decides which passes a frame has; `lucent plan` calls
//! it without a GPU, [`Renderer`] with one. [`FrameRunner`] submits frames either as one command
//! buffer (in-frame timestamps) or one submission per physical pass (isolated timing).

use std::sync::Arc;
use std::time::Instant;

use ash::vk;

use crate::backend::access::Access;
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::timer::{GpuTimer, ScopeTime};
use crate::backend::{GpuBuffer, GpuContext};
use crate::error::VkResultExt;
use crate::graph::{CompileOptions, Executable, Plan, RenderGraph, ResourceId};
use crate::passes::debug_view::{self, DebugView};
use crate::passes::deferred::{GBufferLayout, GBufferPrecision, TranslucencyLayout};
use crate::passes::translucency::{
    mesh_bounds, object_tiles, tile_rects, translucent_tiles, MaterialTable, ThicknessPacking,
};
use crate::passes::{deferred, sss, tonemap, SceneGpu};
use crate::scene::material::SssProfile;
use crate::scene::{LightKind, Scene, MAX_LIGHTS};
use crate::{LucentError, Result};
use glam::Vec3;

/// Which technique lights the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    /// Plain deferred lighting (no translucency, no SSS).
    None,
    /// Deferred lighting plus GDC 2011 thickness-based translucency for translucent materials.
    Translucency,
    /// Screen-space SSS, the thesis's control: Jimenez's separable sum-of-Gaussians blur of the
    /// lit diffuse light for materials with an SSS profile.
    Control,
    /// The thesis's LEAN pipeline with the control's blur: LEAN maps projected to the view
    /// plane, the lit diffuse and the LEAN moments blurred with Jimenez's kernel, LEAN specular
    /// with Fresnel evaluated on the blurred moments.
    Lcb,
    /// The thesis's technique: the LEAN pipeline with a separable bilateral (depth-weighted)
    /// blur of the projected G-buffer in ping-pong targets.
    Lbb,
}

impl Technique {
    /// Every technique with its command-line name.
    pub const ALL: &'static [(&'static str, Technique)] = &[
        ("none", Technique::None),
        ("translucency", Technique::Translucency),
        ("control", Technique::Control),
        ("lcb", Technique::Lcb),
        ("lbb", Technique::Lbb),
    ];

    /// Parses a command-line name.
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .iter()
            .find(|(n, _)| *n == name)
            .map(|&(_, t)| t)
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "unknown technique '{name}'; available: {}",
                    Self::ALL
                        .iter()
                        .map(|(n, _)| *n)
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, t)| *t == self)
            .map_or("?", |(n, _)| n)
    }

    /// The screen-space SSS blur this technique runs, if any.
    pub fn sss_blur(self) -> Option<sss::SssBlur> {
        match self {
            Technique::None | Technique::Translucency => None,
            Technique::Control => Some(sss::SssBlur::Control),
            Technique::Lcb => Some(sss::SssBlur::LeanControl),
            Technique::Lbb => Some(sss::SssBlur::LeanBilateral),
        }
    }
}

/// How a frame is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameSettings {
    /// Output width.
    pub width: u32,
    /// Output height.
    pub height: u32,
    /// Technique.
    pub technique: Technique,
    /// Graph compiler switches.
    pub compile: CompileOptions,
    /// Also export the linear HDR image (for EXR output); otherwise it stays transient.
    pub export_hdr: bool,
    /// Also export the G-buffer (for the CPU reference); otherwise it stays transient.
    pub export_gbuffer: bool,
    /// Precision of the G-buffer's colour targets.
    pub gbuffer: GBufferPrecision,
    /// Write coloured thickness as grayscale (its luminance) even when the scene has colour:
    /// the talk's one-channel G-buffer, for A/B comparisons.
    pub force_grayscale: bool,
    /// Run the SSS blurs only over the screen rectangles of objects with a profile (off: the
    /// whole screen, for A/B comparisons).
    pub sss_tiles: bool,
    /// Robustness tests: the lighting pass writes this value into one pixel, so tests can
    /// prove that later passes keep it from spreading.
    pub fault: Option<Fault>,
    /// Screen-space SSS knobs (Gaussian count, precision, bilateral sensitivity).
    pub sss: sss::SssKnobs,
    /// Show a G-buffer target (or the lit image before SSS) instead of the frame, when the
    /// frame has it (the demo's debug views).
    pub debug_view: Option<DebugView>,
}

/// A value injected into one pixel of the lit image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Fault {
    /// Column.
    pub x: u32,
    /// Row.
    pub y: u32,
    /// NaN (true) or +Inf (false).
    pub nan: bool,
}

impl FrameSettings {
    /// Defaults for a size: technique none, merging and aliasing on, no HDR export.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            technique: Technique::None,
            compile: CompileOptions::default(),
            export_hdr: false,
            export_gbuffer: false,
            gbuffer: GBufferPrecision::Compact,
            force_grayscale: false,
            sss_tiles: true,
            fault: None,
            sss: sss::SssKnobs::default(),
            debug_view: None,
        }
    }
}

/// What a frame of a scene needs beyond the plain deferred path: derived once from the scene
/// and the settings, so the graph declares only what the scene uses.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameFeatures {
    /// The translucent materials and GB2's packing, when the technique is `translucency` and
    /// some object is translucent.
    pub translucency: Option<(MaterialTable, ThicknessPacking)>,
    /// The diffusion profile the SSS blurs use, when the technique is an SSS one and some
    /// object has a profile (the first such object's; refitted to `SssKnobs::gaussians` when
    /// that is set), and the blur.
    pub sss: Option<(SssProfile, sss::SssBlur)>,
    /// Some object has a normal map.
    pub normal_maps: bool,
}

impl FrameFeatures {
    /// The features `scene` needs under `settings`.
    pub fn new(scene: &Scene, settings: &FrameSettings) -> Result<Self> {
        let sss = match settings.technique.sss_blur() {
            Some(blur) => scene
                .objects
                .iter()
                .find_map(|o| o.material.sss.clone())
                .map(|p| -> Result<_> {
                    let profile = match settings.sss.gaussians {
                        Some(n) => sss::fit_profile(&p, n)?.0,
                        None => p,
                    };
                    Ok((profile, blur))
                })
                .transpose()?,
            None => None,
        };
        let translucency = match settings.technique {
            Technique::None | Technique::Control | Technique::Lcb | Technique::Lbb => None,
            Technique::Translucency => {
                let table = MaterialTable::new(scene)?;
                let packing = if settings.force_grayscale {
                    ThicknessPacking::Grayscale
                } else {
                    table.packing()
                };
                (!table.is_empty()).then_some((table, packing))
            }
        };
        let normal_maps = scene
            .objects
            .iter()
            .any(|o| o.material.normal_texture.is_some());
        Ok(Self {
            translucency,
            sss,
            normal_maps,
        })
    }

    /// The SSS blur the frame runs, if any.
    pub fn sss_blur(&self) -> Option<sss::SssBlur> {
        self.sss.as_ref().map(|(_, blur)| *blur)
    }

    /// The G-buffer layout these features and `settings` call for.
    pub fn gbuffer_layout(&self, settings: &FrameSettings) -> GBufferLayout {
        GBufferLayout {
            precision: settings.gbuffer,
            translucency: self
                .translucency
                .as_ref()
                .map(|(table, packing)| TranslucencyLayout {
                    packing: *packing,
                    pow_modes: table.pow_modes(),
                    single_material: table.rows.len() == 1,
                }),
            sss: self.sss.is_some(),
            lean: self.sss_blur().is_some_and(sss::SssBlur::lean),
            lean_clear: self
                .sss_blur()
                .is_some_and(|blur| blur.lean() && !blur.bilateral()),
            normal_maps: self.normal_maps,
            fault_injection: settings.fault.is_some(),
        }
    }
}

/// The G-buffer images a frame hands out when asked to (`export_gbuffer`).
#[derive(Clone, Copy, Debug)]
pub struct GBufferOutputs {
    /// Albedo + specular.
    pub gb0: ResourceId,
    /// Normal + roughness.
    pub gb1: ResourceId,
    /// Thickness + material ID (frames with translucency).
    pub gb2: Option<ResourceId>,
    /// Screen-space SSS strength (frames with SSS).
    pub sss: Option<ResourceId>,
    /// View-plane LEAN slope y and second moments (LCB and LBB frames).
    pub lean: Option<ResourceId>,
    /// Depth.
    pub depth: ResourceId,
    /// Its layout.
    pub layout: GBufferLayout,
}

/// The images a frame hands out.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    /// Display image (RGBA8, sRGB-encoded), left in TRANSFER_SRC layout.
    pub display: ResourceId,
    /// Linear HDR image (RGBA16F), when exported.
    pub hdr: Option<ResourceId>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferOutputs>,
}

/// Declares every pass of a frame. `scene_gpu` is `None` for plan-only graphs.
pub fn declare_frame(
    graph: &mut RenderGraph,
    settings: &FrameSettings,
    features: &FrameFeatures,
    scene_gpu: Option<&Arc<SceneGpu>>,
) -> FrameOutputs {
    let layout = features.gbuffer_layout(settings);
    let gb = deferred::gbuffer_pass(graph, settings.width, settings.height, layout, scene_gpu);
    let lit = deferred::lighting_pass(graph, &gb, scene_gpu);
    let debug_display = settings
        .debug_view
        .and_then(|view| debug_view::debug_view_pass(graph, view, &gb, &lit, scene_gpu));
    let hdr = match (&features.sss, &lit.specular, &gb.sss) {
        (Some((profile, blur)), Some(specular), Some(strength)) => sss::sss_passes(
            graph,
            &sss::SssInputs {
                diffuse: &lit.color,
                specular,
                depth: &gb.depth,
                strength,
                lean: gb.lean.as_ref(),
                gb0: &gb.gb0,
            },
            profile,
            *blur,
            &settings.sss,
            scene_gpu,
        ),
        _ => lit.color,
    };
    let display = debug_display.unwrap_or_else(|| tonemap::tonemap_pass(graph, &hdr, scene_gpu));
    graph.export_image(&display, Access::TransferRead);
    let hdr_id = settings.export_hdr.then(|| {
        graph.export_image(&hdr, Access::TransferRead);
        hdr.id()
    });
    let gbuffer = settings.export_gbuffer.then(|| {
        for image in [&gb.gb0, &gb.gb1, &gb.depth]
            .into_iter()
            .chain(gb.gb2.as_ref())
            .chain(gb.sss.as_ref())
            .chain(gb.lean.as_ref())
        {
            graph.export_image(image, Access::TransferRead);
        }
        GBufferOutputs {
            gb0: gb.gb0.id(),
            gb1: gb.gb1.id(),
            gb2: gb.gb2.as_ref().map(|h| h.id()),
            sss: gb.sss.as_ref().map(|h| h.id()),
            lean: gb.lean.as_ref().map(|h| h.id()),
            depth: gb.depth.id(),
            layout,
        }
    });
    FrameOutputs {
        display: display.id(),
        hdr: hdr_id,
        gbuffer,
    }
}

/// Compiles the plan of a frame without a GPU (for `lucent plan` and tests).
pub fn plan_frame(settings: &FrameSettings, features: &FrameFeatures) -> Result<Plan> {
    let mut graph = RenderGraph::new();
    declare_frame(&mut graph, settings, features, None);
    graph.plan(settings.compile)
}

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
        Ok(crate::output::f16_bytes_to_f32(&self.read_export(gpu, id)?))
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

/// One frame's read-back images.
#[derive(Clone, Debug)]
pub struct FrameImages {
    /// Display image, RGBA8 sRGB.
    pub display: Vec<u8>,
    /// Linear HDR RGBA f32, when exported.
    pub hdr: Option<Vec<f32>>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferReadback>,
    /// The frame's times.
    pub timing: FrameTiming,
}

/// A G-buffer read back and decoded: one `[f32; 4]` per pixel and target (missing channels
/// are 0), rows top first.
#[derive(Clone, Debug)]
pub struct GBufferReadback {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Albedo rgb + specular.
    pub gb0: Vec<[f32; 4]>,
    /// Normal xyz + roughness.
    pub gb1: Vec<[f32; 4]>,
    /// Thickness + material ID as stored (see glsl/common/gbuffer.glsl).
    pub gb2: Option<Vec<[f32; 4]>>,
    /// Screen-space SSS strength per pixel (frames with SSS).
    pub sss: Option<Vec<f32>>,
    /// View-plane LEAN slope y and second moments xx, yy, xy (LCB and LBB frames).
    pub lean: Option<Vec<[f32; 4]>>,
    /// Device depth.
    pub depth: Vec<f32>,
    /// The layout the frame used.
    pub layout: GBufferLayout,
}

/// Decodes tightly packed texels of the formats lucent's G-buffer uses to f32.
pub fn decode_texels(bytes: &[u8], format: vk::Format) -> Result<Vec<[f32; 4]>> {
    let (channels, kind) = match format {
        vk::Format::R8_UNORM => (1, 0),
        vk::Format::R8G8_UNORM => (2, 0),
        vk::Format::R8G8B8A8_UNORM => (4, 0),
        vk::Format::R16G16_SFLOAT => (2, 1),
        vk::Format::R16G16B16A16_SFLOAT => (4, 1),
        vk::Format::R32G32_SFLOAT => (2, 2),
        vk::Format::R32G32B32A32_SFLOAT => (4, 2),
        // Depth-stencil images read back their depth aspect, 32-bit float.
        vk::Format::D32_SFLOAT | vk::Format::D32_SFLOAT_S8_UINT => (1, 2),
        other => {
            return Err(LucentError::InvalidInput(format!(
                "cannot decode texels of format {other:?}"
            )))
        }
    };
    let values: Vec<f32> = match kind {
        0 => bytes.iter().map(|&b| f32::from(b) / 255.0).collect(),
        1 => crate::output::f16_bytes_to_f32(bytes),
        _ => bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
    };
    Ok(values
        .chunks_exact(channels)
        .map(|c| {
            let mut t = [0.0; 4];
            t[..channels].copy_from_slice(c);
            t
        })
        .collect())
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

/// Waits for the device, then destroys `renderers` and `runners` (the round-robin measurements'
/// teardown): everything is destroyed even when the wait fails, whose error is returned.
pub fn destroy_after_idle(
    gpu: &GpuContext,
    renderers: Vec<Renderer>,
    runners: Vec<FrameRunner>,
) -> Result<()> {
    let idle = gpu.wait_idle();
    for runner in runners {
        runner.destroy(gpu);
    }
    for renderer in renderers {
        renderer.destroy(gpu);
    }
    idle
}

/// Times of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameTiming {
    /// Wall time from submit to fence signalled, milliseconds.
    pub wall_ms: f64,
    /// GPU timestamps per physical pass.
    pub passes: Vec<ScopeTime>,
}

/// Submits frames and measures them: owns a command pool, command buffer, fence and timer.
pub struct FrameRunner {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timer: GpuTimer,
}

impl FrameRunner {
    /// A runner for frames of up to `max_passes` physical passes.
    pub fn new(gpu: &GpuContext, max_passes: usize) -> Result<Self> {
        let device = &gpu.device;
        // SAFETY: valid device and create infos.
        let pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(gpu.queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                None,
            )
        }
        .vk("vkCreateCommandPool")?;
        // SAFETY: the pool was just created.
        let cmd = unsafe {
            device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
        }
        .vk("vkAllocateCommandBuffers")?[0];
        // SAFETY: valid device.
        let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }
            .vk("vkCreateFence")?;
        let timer = GpuTimer::new(gpu, max_passes as u32 + 1)?;
        gpu.set_name(cmd, "lucent frame");
        Ok(Self {
            pool,
            cmd,
            fence,
            timer,
        })
    }

    /// Records with `record`, submits, waits, and reads the timer. Never overlaps frames, so
    /// the timer's results are always ready (no stall, no drain).
    fn submit(
        &mut self,
        gpu: &GpuContext,
        record: impl FnOnce(&GpuContext, vk::CommandBuffer, &mut GpuTimer),
    ) -> Result<FrameTiming> {
        let device = &gpu.device;
        // SAFETY: the previous submission of `cmd` finished (we waited on the fence).
        unsafe {
            device
                .reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            device
                .begin_command_buffer(
                    self.cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .vk("vkBeginCommandBuffer")?;
        }
        self.timer.reset(gpu, self.cmd);
        record(gpu, self.cmd, &mut self.timer);
        let cmd_infos = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmd_infos);
        // SAFETY: recording is complete; the fence is unsignalled.
        let start = unsafe {
            device
                .end_command_buffer(self.cmd)
                .vk("vkEndCommandBuffer")?;
            let start = Instant::now();
            device
                .queue_submit2(gpu.queue, &[submit], self.fence)
                .vk("vkQueueSubmit2")?;
            device
                .wait_for_fences(&[self.fence], true, u64::MAX)
                .vk("vkWaitForFences")?;
            start
        };
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        // SAFETY: the fence is signalled and not in use.
        unsafe { device.reset_fences(&[self.fence]) }.vk("vkResetFences")?;
        let passes = self.timer.results(gpu)?.ok_or_else(|| {
            LucentError::Timing("timestamps not available after the frame's fence signalled".into())
        })?;
        Ok(FrameTiming { wall_ms, passes })
    }

    /// One whole frame in one command buffer, timestamps around each physical pass.
    pub fn run_frame(&mut self, gpu: &GpuContext, executable: &Executable) -> Result<FrameTiming> {
        self.submit(gpu, |gpu, cmd, timer| {
            executable.record_frame(gpu, cmd, Some(timer))
        })
    }

    /// One frame submitted pass by pass: each physical pass alone in its own submission, the
    /// device idle before it. Returns each pass's timestamp time (and the sum of walls).
    pub fn run_isolated(
        &mut self,
        gpu: &GpuContext,
        executable: &Executable,
    ) -> Result<FrameTiming> {
        let count = executable.plan.physical.len();
        let mut passes = Vec::with_capacity(count);
        let mut wall_ms = 0.0;
        for index in 0..count {
            let timing = self.submit(gpu, |gpu, cmd, timer| {
                executable.record_physical(gpu, cmd, index, Some(timer));
                if index + 1 == count {
                    executable.record_exports(gpu, cmd);
                }
            })?;
            wall_ms += timing.wall_ms;
            passes.extend(timing.passes);
        }
        Ok(FrameTiming { wall_ms, passes })
    }

    /// Destroys the runner. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        self.timer.destroy(gpu);
        // SAFETY: created by `new`; nothing pending (every submit waited).
        unsafe {
            gpu.device.destroy_fence(self.fence, None);
            gpu.device.destroy_command_pool(self.pool, None);
        }
    }
}
