//! What the GPU commands share: a [`Session`] (device, shaders, pipeline cache) opened and
//! closed in order, a renderer built for the command line's frame, the device-fit check, and
//! the refusal of outputs that would overwrite a scene's inputs.

use std::path::Path;

use lucent::backend::shader::{PipelineCache, ShaderCompiler};
use lucent::backend::{ContextDesc, GpuContext};
use lucent::frame::{plan_frame, FrameDesc, FrameSettings, Renderer};
use lucent::{scene, LucentError, Result};

use crate::cli::{FrameArgs, GpuArgs};

/// The GPU objects every GPU command needs, torn down in order.
pub struct Session {
    pub gpu: GpuContext,
    pub shaders: ShaderCompiler,
    pub pipeline_cache: PipelineCache,
}

/// A run-time compiler for the GLSL tree `dir` (`--shaders`), refused with the reason when
/// `dir` is no shader tree or this build has no compiler.
fn runtime_shaders(dir: &Path) -> Result<ShaderCompiler> {
    if !ShaderCompiler::is_glsl_root(dir) {
        return Err(LucentError::InvalidInput(format!(
            "--shaders {}: not a shader tree (a copy of the repository's glsl/, with {})",
            dir.display(),
            lucent::backend::shader::FULLSCREEN_VERTEX
        )));
    }
    #[cfg(feature = "runtime-shaders")]
    {
        ShaderCompiler::new(dir, None)
    }
    #[cfg(not(feature = "runtime-shaders"))]
    {
        Err(LucentError::InvalidInput(format!(
            "--shaders {}: this build has no run-time shader compiler (feature runtime-shaders)",
            dir.display()
        )))
    }
}

impl Session {
    fn new(args: &GpuArgs) -> Result<Self> {
        let gpu = GpuContext::new(&ContextDesc::from_env(args.validation, args.device.clone()))?;
        log::info!("device: {} ({})", gpu.info.describe(), gpu.info.driver());
        // The SPIR-V compiled with the crate (the demo compiles at run time, for hot reload),
        // or the GLSL of `--shaders DIR` compiled as the passes ask for it.
        let shaders = match &args.shaders {
            None => ShaderCompiler::shipped()?,
            Some(dir) => runtime_shaders(dir)?,
        };
        let pipeline_cache = PipelineCache::load_default(&gpu)?;
        Ok(Self {
            gpu,
            shaders,
            pipeline_cache,
        })
    }

    /// Saves the pipeline cache and fails if validation reported errors.
    fn finish(self) -> Result<()> {
        if let Err(e) = self.pipeline_cache.save(&self.gpu.device) {
            log::warn!("pipeline cache not saved: {e}");
        }
        let errors = self.gpu.validation_error_count();
        self.pipeline_cache.destroy(&self.gpu.device);
        if errors > 0 {
            // The messages themselves went to the log as they arrived.
            return Err(LucentError::InvalidInput(format!(
                "the validation layer reported {errors} error(s)"
            )));
        }
        Ok(())
    }
}

/// Opens a session, runs `work` with it, and closes it whatever `work` returned; `work`'s error
/// comes first, then validation errors fail the command.
pub fn with_session<T>(gpu_args: &GpuArgs, work: impl FnOnce(&Session) -> Result<T>) -> Result<T> {
    let session = Session::new(gpu_args)?;
    let result = work(&session);
    let finished = session.finish();
    let value = result?;
    finished?;
    Ok(value)
}

/// Builds the frame of `frame`'s scene, runs `work` with it, and tears everything down in order
/// whatever `work` returned; validation errors fail the command.
pub fn with_renderer(
    frame: &FrameArgs,
    gpu_args: &GpuArgs,
    export_hdr: bool,
    work: impl FnOnce(&Session, &Renderer, &scene::Scene) -> Result<()>,
) -> Result<()> {
    let settings = frame.settings(export_hdr)?;
    let scene = frame.load_scene()?;
    frame.warn_inapplicable(&scene, &settings, &FrameDesc::new(&scene, &settings)?);
    // Texture headers first: one too large is refused before the device is even opened.
    scene::texture::scene_texture_sizes(&scene, None)?;
    with_session(gpu_args, |session| {
        check_device_fits(&session.gpu, &scene, &settings)?;
        let renderer = Renderer::new(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            &scene,
            settings,
        )?;
        let worked = work(session, &renderer, &scene);
        let idle = session.gpu.wait_idle();
        renderer.destroy(&session.gpu);
        worked.and(idle)
    })
}

/// Refuses textures larger than the device's `maxImageDimension2D`, and warns when the
/// frame's images and the textures will not fit the device's largest memory heap (naming the
/// largest image and what to try): an out-of-memory error later would be less clear. Only a
/// warning, because some drivers (lavapipe: 2 GiB reported) allocate beyond the heap they
/// report.
fn check_device_fits(
    gpu: &GpuContext,
    scene: &scene::Scene,
    settings: &FrameSettings,
) -> Result<()> {
    let info = &gpu.info;
    let textures = scene::texture::scene_texture_sizes(scene, Some(info.max_image_dimension_2d))?;
    let desc = FrameDesc::new(scene, settings)?;
    let plan = plan_frame(settings, &desc)?;
    let (frame_bytes, largest) = plan.frame_memory();
    // Maps go up as RGBA16F with mips (4/3); in LEAN frames a normal map as two such maps.
    let lean = desc.upload(1).lean;
    let texture_bytes: u64 = textures
        .iter()
        .map(|(_, w, h, normal)| {
            let copies = if *normal && lean { 2 } else { 1 };
            u64::from(*w) * u64::from(*h) * 8 * 4 / 3 * copies
        })
        .sum();
    let heap = info.device_local_bytes;
    if heap > 0 && frame_bytes.saturating_add(texture_bytes) > heap {
        let size = lucent::error::format_bytes;
        let largest = largest.map_or(String::new(), |r| {
            format!(
                "; largest image '{}' {}x{} {}, {}",
                r.name,
                r.info.width,
                r.info.height,
                lucent::backend::format::format_name(r.info.format),
                size(r.estimated_bytes())
            )
        });
        eprintln!(
            "lucent: warning: the frame at {}x{} needs about {} of GPU memory for its images{largest}{}, \
             more than the device's largest memory heap ({}): it may fail with out of memory; \
             try a smaller --size",
            settings.width,
            settings.height,
            size(frame_bytes),
            if texture_bytes > 0 {
                format!(", and {} for textures", size(texture_bytes))
            } else {
                String::new()
            },
            size(heap)
        );
    }
    Ok(())
}

/// Refuses, before any work, outputs that are the scene file or a file it names, or that are
/// the same file twice.
pub fn check_scene_outputs(scene: &str, outputs: &[(&str, &Path)]) -> Result<()> {
    let inputs = scene::inputs::scene_inputs(scene);
    let inputs: Vec<(&str, &Path)> = inputs
        .iter()
        .map(|(what, path)| (what.as_str(), path.as_path()))
        .collect();
    lucent::files::check_outputs(&inputs, outputs)
}
