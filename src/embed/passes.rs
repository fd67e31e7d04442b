//! What every effect on a host's G-buffer is made of ([`EffectPasses`]): its compiled passes
//! with the host's images imported, its per-frame buffer with one slot per frame in flight and
//! view, and the leak guard; building it, checking a frame's slot and view, and recording a
//! frame (the host's images bound, moved into the states the passes use and back, timestamps
//! when asked). The effects ([`super::SssEffect`], [`super::TranslucencyEffect`]) add what
//! their technique needs: their description, tables and per-frame constants.

use std::sync::Arc;

use ash::vk;

use super::image::{record_transition, HostImage, Role};
use super::uploads::LeakGuard;
use super::{EffectTimer, Lucent, Uploads};
use crate::error::HostError;
use crate::gpu_scene::{PerFrame, SceneGpu, SceneUpload};
use crate::graph::{CompileOptions, Executable, RenderGraph, ResourceId};
use crate::scene::{Camera, Scene};
use crate::Result;

/// The public methods every effect has alike, over its `passes` ([`EffectPasses`]) and its
/// own `record_with(lucent, cmd, frame, timer)`: `plan`, `record` (documented with `$does`,
/// what one frame's recording does), `record_timed`, `memory` and (unless `own_destroy`)
/// `destroy`.
macro_rules! effect_methods {
    ($frame:ident, $does:literal) => {
        $crate::embed::passes::effect_methods!($frame, $does, own_destroy);

        /// Destroys the passes and their buffers. The GPU must be done with every frame that
        /// recorded them (the host's fences).
        pub fn destroy(self, lucent: &Lucent) {
            self.passes.destroy(lucent);
        }

        /// The effect holds no image besides its passes'.
        fn own_image_bytes(&self) -> u64 {
            0
        }
    };
    // An effect with more to destroy than its passes writes its own `destroy`, and says what
    // device memory those resources hold (`own_image_bytes`, counted in `memory`).
    ($frame:ident, $does:literal, own_destroy) => {
        /// The passes the effect records (their plan, for lucent's tables and tests): an
        /// internal type, only with the `internals` feature ([`Self::record_timed`] names
        /// each pass with its time).
        #[cfg(feature = "internals")]
        pub fn plan(&self) -> &crate::graph::Plan {
            self.passes.plan()
        }

        #[doc = concat!(
            "Records one view of one frame into `cmd` (recording, outside any render pass): ",
            $does,
            "; every image then left in its final state ([`HostImage::left_in`]). The frame \
             last recorded with the same slot and view must have completed (its fence); each \
             (slot, view) is recorded once per frame. Everything is checked before anything \
             is recorded."
        )]
        pub fn record(
            &mut self,
            lucent: &Lucent,
            cmd: vk::CommandBuffer,
            frame: &$frame<'_>,
        ) -> Result<()> {
            self.record_with(lucent, cmd, frame, None)
        }

        /// [`Self::record`] with a timestamp pair around each pass, written into `timer`
        /// (reset in `cmd` first): read the times with [`super::EffectTimer::results`] once
        /// the frame's fence has signalled.
        pub fn record_timed(
            &mut self,
            lucent: &Lucent,
            cmd: vk::CommandBuffer,
            frame: &$frame<'_>,
            timer: &mut super::EffectTimer,
        ) -> Result<()> {
            self.record_with(lucent, cmd, frame, Some(timer))
        }

        /// The GPU memory the effect holds while it exists (its intermediate images and its
        /// per-frame parameters), for a host's memory budget. Allocated when the effect is
        /// built, freed by [`Self::destroy`]; recording allocates nothing.
        pub fn memory(&self) -> super::EffectMemory {
            let mut memory = self.passes.memory();
            memory.images += self.own_image_bytes();
            memory
        }
    };
}
pub(crate) use effect_methods;

/// The GPU memory an effect holds while it exists ([`super::SssEffect::memory`] and the
/// other effects' `memory`): what a host counts against its budget. Both parts are allocated
/// when the effect is built (in the host's allocator) and freed when it is destroyed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct EffectMemory {
    /// Its images, bytes of device memory: the intermediate targets its passes write and read
    /// between them (at the G-buffer's size; images whose lifetimes do not overlap share
    /// memory) and any texture of its own (`LayeredEffect`'s blank depth texture for draws
    /// without one). The host's own images count nothing.
    pub images: u64,
    /// Its per-frame parameters (tables, camera, lights: one slot per frame in flight and
    /// view), bytes of host-visible memory.
    pub parameters: u64,
}

impl EffectMemory {
    /// Both parts, bytes.
    pub fn total(&self) -> u64 {
        self.images + self.parameters
    }
}

/// A host image of `gbuffer`'s size imported into `graph` as `name` (bound to the host's
/// image when each frame records), first used as `initial`.
pub(crate) fn import_host_image(
    graph: &mut RenderGraph,
    gbuffer: &super::GBufferDesc,
    name: &str,
    format: vk::Format,
    initial: crate::backend::access::Access,
) -> crate::graph::Handle<crate::graph::Image> {
    graph.import_image(
        name,
        crate::graph::ImageInfo {
            width: gbuffer.width,
            height: gbuffer.height,
            format,
        },
        crate::graph::ImportedImage {
            image: vk::Image::null(),
            view: vk::ImageView::null(),
            initial,
        },
    )
}

/// The albedo image a frame gives, against whether the effect reads it (`reads`: the host's
/// diffuse light has the albedo multiplied in): required then, refused otherwise; `term`
/// names the light the effect adds, for the errors.
pub(crate) fn frame_albedo<'a>(
    reads: bool,
    given: Option<&'a HostImage>,
    term: &str,
) -> Result<Option<&'a HostImage>> {
    match (reads, given) {
        (true, Some(albedo)) => Ok(Some(albedo)),
        (false, None) => Ok(None),
        (true, None) => Err(HostError::Missing {
            input: "albedo".into(),
            needed_by: format!(
                "{term} is multiplied by the albedo, as the host's diffuse light has it (the \
                 frame's albedo image)"
            ),
        }
        .into()),
        (false, Some(_)) => Err(HostError::Description {
            field: "albedo".into(),
            problem: format!(
                "given, but the description's diffuse light is kept without the albedo, so \
                 {term} is too: pass None"
            ),
        }
        .into()),
    }
}

/// How an effect samples the host's depth image: as depth (a depth format's depth aspect) or
/// as a colour image (linear view depth).
pub(crate) fn depth_role(gbuffer: &super::GBufferDesc) -> Role {
    match gbuffer.depth.encoding {
        super::DepthEncoding::Device => Role::SampledDepth,
        super::DepthEncoding::LinearView => Role::SampledColor,
    }
}

/// How an effect samples the host's material IDs: a stencil aspect as a depth-stencil
/// image's, any other as a colour image.
pub(crate) fn id_role(ids: &super::IdDesc) -> Role {
    if matches!(ids.encoding, super::IdEncoding::Stencil { .. }) {
        Role::SampledDepth
    } else {
        Role::SampledColor
    }
}

/// Checks each of a frame's images (image, input name, role, the format its description
/// names) at the G-buffer's size: the first mistake as its typed error.
pub(crate) fn check_described(
    lucent: &Lucent,
    extent: vk::Extent2D,
    checks: &[(&HostImage, &str, Role, vk::Format)],
) -> Result<()> {
    for &(image, input, role, format) in checks {
        super::image::check_image(
            lucent.gpu(),
            image,
            input,
            role,
            extent,
            |f| f == format,
            &format!(
                "{} (the description's)",
                crate::backend::format::format_name(format)
            ),
        )?;
    }
    Ok(())
}

/// The host's lights: at most [`crate::scene::MAX_LIGHTS`], each finite, with a finite translucency scale
/// and, for point and spot lights, a positive range (the shader divides by it).
pub(crate) fn check_lights(lights: &[crate::scene::Light]) -> Result<()> {
    if lights.len() > crate::scene::MAX_LIGHTS {
        return Err(HostError::Description {
            field: "lights".into(),
            problem: format!(
                "{} lights; at most {}",
                lights.len(),
                crate::scene::MAX_LIGHTS
            ),
        }
        .into());
    }
    for (index, light) in lights.iter().enumerate() {
        let radiance = light.radiance();
        let geometry_ok = match light.kind {
            crate::scene::LightKind::Directional { direction } => {
                direction.is_finite() && direction.length_squared() > 0.0
            }
            crate::scene::LightKind::Point { position, range } => {
                position.is_finite() && range.is_finite() && range > 0.0
            }
            crate::scene::LightKind::Spot {
                position,
                direction,
                range,
                inner_degrees,
                outer_degrees,
            } => {
                position.is_finite()
                    && direction.is_finite()
                    && direction.length_squared() > 0.0
                    && range.is_finite()
                    && range > 0.0
                    && inner_degrees.is_finite()
                    && outer_degrees.is_finite()
            }
        };
        if !(geometry_ok
            && radiance.is_finite()
            && radiance.min_element() >= 0.0
            && light.translucency_scale.is_finite()
            && light.translucency_scale >= 0.0)
        {
            return Err(HostError::Description {
                field: format!("lights[{index}]"),
                problem: format!(
                    "{light:?}: positions, directions (non-zero), ranges (> 0), colours and \
                     intensities (>= 0) and the translucency scale (>= 0) must be finite"
                ),
            }
            .into());
        }
    }
    Ok(())
}

/// An environment's nine SH coefficients, refused unless finite (a NaN or Inf coefficient
/// would light every pixel with it: refused where it enters).
pub(crate) fn check_environment(environment: &crate::scene::Environment) -> Result<[[f32; 4]; 9]> {
    let coefficients = environment.coefficients();
    if coefficients.iter().flatten().any(|c| !c.is_finite()) {
        return Err(HostError::Description {
            field: "environment".into(),
            problem: format!(
                "{}: its SH coefficients must be finite",
                environment.describe()
            ),
        }
        .into());
    }
    Ok(coefficients)
}

/// Checks material `index`'s host ID: 1 to 255, not `taken` by an earlier material, within
/// the ID image's bit field (`mask`).
pub(crate) fn check_material_id(index: usize, id: u8, taken: bool, mask: u32) -> Result<()> {
    if id == 0 || taken || u32::from(id) > mask {
        return Err(HostError::Description {
            field: format!("materials[{index}] (ID {id})"),
            problem: "IDs are 1 to 255, each once, within the material ID image's bit field".into(),
        }
        .into());
    }
    Ok(())
}

/// Checks an effect's views per frame: 1 to [`super::MAX_VIEWS_PER_FRAME`].
pub(crate) fn check_views(views: usize) -> Result<()> {
    if (1..=super::MAX_VIEWS_PER_FRAME).contains(&views) {
        return Ok(());
    }
    Err(HostError::Description {
        field: "views_per_frame".into(),
        problem: format!(
            "{views} views; 1 to {} are supported",
            super::MAX_VIEWS_PER_FRAME
        ),
    }
    .into())
}

/// An effect's passes and per-frame data (see the module docs).
pub(crate) struct EffectPasses {
    executable: Option<Executable>,
    scene_gpu: Option<Arc<SceneGpu>>,
    frames_in_flight: usize,
    views: usize,
    guard: Option<LeakGuard>,
}

impl EffectPasses {
    /// Builds the passes `declare` declares over a per-frame buffer of `upload`'s tables,
    /// one slot per frame in flight and view (`upload.frames_in_flight` is set here). The
    /// buffer's creation is recorded into `uploads` under `what` (the effect's name).
    pub(crate) fn new<I>(
        lucent: &Lucent,
        uploads: &mut Uploads,
        what: &'static str,
        mut upload: SceneUpload<'_>,
        views: usize,
        declare: impl FnOnce(&Arc<SceneGpu>) -> (RenderGraph, I),
    ) -> Result<(Self, I)> {
        let ring = lucent.frames_in_flight() * views;
        upload.frames_in_flight = ring;
        let no_objects = frame_scene();
        let scene_gpu = uploads.record(lucent, what, || {
            SceneGpu::new(lucent.gpu(), &no_objects, &upload).map(Arc::new)
        })?;
        let (graph, imports) = declare(&scene_gpu);
        let options = CompileOptions {
            chained_frames: ring > 1,
            ..Default::default()
        };
        let compiled = graph.compile(options).and_then(|(plan, execs)| {
            Executable::new(
                lucent.gpu(),
                plan,
                execs,
                lucent.shaders(),
                lucent.pipeline_cache().handle,
                ring,
            )
        });
        match compiled {
            Ok(executable) => Ok((
                Self {
                    executable: Some(executable),
                    scene_gpu: Some(scene_gpu),
                    frames_in_flight: lucent.frames_in_flight(),
                    views,
                    guard: Some(LeakGuard::new(what)),
                },
                imports,
            )),
            Err(e) => {
                if let Ok(s) = Arc::try_unwrap(scene_gpu) {
                    s.destroy(lucent.gpu());
                }
                Err(e)
            }
        }
    }

    /// The memory the passes hold ([`super::EffectMemory`]).
    pub(crate) fn memory(&self) -> super::EffectMemory {
        super::EffectMemory {
            images: self
                .executable
                .as_ref()
                .expect("alive until destroy")
                .memory_bytes(),
            parameters: self.per_frame().bytes(),
        }
    }

    /// The per-frame buffer and tiles.
    pub(crate) fn per_frame(&self) -> &PerFrame {
        &self
            .scene_gpu
            .as_ref()
            .expect("alive until destroy")
            .per_frame
    }

    /// Every slot of the per-frame buffer (frames in flight times views).
    pub(crate) fn slots(&self) -> usize {
        self.frames_in_flight * self.views
    }

    /// The passes (their plan; the effects hand it out with `internals`).
    #[cfg(feature = "internals")]
    pub(crate) fn plan(&self) -> &crate::graph::Plan {
        &self.executable.as_ref().expect("alive until destroy").plan
    }

    /// The per-frame slot of frame slot `slot`, view `view`, or the error naming which is out
    /// of range.
    pub(crate) fn slot(&self, slot: usize, view: usize) -> Result<usize> {
        if slot >= self.frames_in_flight {
            return Err(HostError::OutOfRange {
                what: "frame slot",
                index: slot,
                count: self.frames_in_flight,
            }
            .into());
        }
        if view >= self.views {
            return Err(HostError::OutOfRange {
                what: "view",
                index: view,
                count: self.views,
            }
            .into());
        }
        Ok(slot * self.views + view)
    }

    /// Records per-frame slot `ring`'s passes into `cmd`: `binds` (each import's host image)
    /// bound, the `inputs` (distinct images, checked) moved to the sampled state and `output`
    /// to `output_role`'s, the passes (timed into `timer` when given), then each image to its
    /// final state.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn record(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        ring: usize,
        binds: &[(ResourceId, &HostImage)],
        inputs: &[&HostImage],
        (output, output_role): (&HostImage, Role),
        timer: Option<&mut EffectTimer>,
    ) -> Result<()> {
        let gpu = lucent.gpu();
        let binds: Vec<(
            ResourceId,
            vk::Image,
            vk::ImageView,
            crate::graph::Subresources,
        )> = binds
            .iter()
            .map(|(id, i)| (*id, i.image, i.view, i.subresources()))
            .collect();
        let executable = self.executable.as_mut().expect("alive until destroy");
        executable.bind_imports(gpu, ring, &binds)?;
        let sampled = Role::SampledColor.working_state();
        let attachment = output_role.working_state();
        for image in inputs {
            record_transition(gpu, cmd, image, &image.state, &sampled);
        }
        record_transition(gpu, cmd, output, &output.state, &attachment);
        let timer = timer.map(|t| {
            let timer = t.timer_mut();
            timer.reset(gpu, cmd);
            timer
        });
        executable.record_frame(gpu, cmd, ring, timer);
        for image in inputs {
            record_transition(gpu, cmd, image, &sampled, &image.left_in());
        }
        record_transition(gpu, cmd, output, &attachment, &output.left_in());
        Ok(())
    }

    /// Destroys the passes and their buffers; the GPU must be done with them.
    pub(crate) fn destroy(mut self, lucent: &Lucent) {
        if let Some(executable) = self.executable.take() {
            executable.destroy(lucent.gpu());
        }
        if let Some(s) = self.scene_gpu.take().and_then(|s| Arc::try_unwrap(s).ok()) {
            s.destroy(lucent.gpu());
        }
        if let Some(guard) = self.guard.take() {
            guard.disarm();
        }
    }
}

/// The scene the effect's GPU data is created with: no objects, lights or environment (the
/// passes read the camera, the viewport and the tables only).
fn frame_scene() -> Scene {
    Scene {
        name: "host effect".into(),
        meshes: Vec::new(),
        objects: Vec::new(),
        lights: Vec::new(),
        camera: Camera {
            eye: glam::Vec3::new(0.0, 0.0, 1.0),
            target: glam::Vec3::ZERO,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 100.0,
        },
        environment: crate::scene::Environment::constant(glam::Vec3::ZERO),
        sky: glam::Vec3::ZERO,
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Light;
    use glam::Vec3;

    #[test]
    fn lights_that_are_not_finite_or_too_many_are_refused() {
        let good = Light::point(Vec3::ONE, Vec3::ONE, 2.0, 5.0);
        check_lights(&[good]).unwrap();
        let mut bad = good;
        bad.intensity = f32::NAN;
        assert!(check_lights(&[bad]).is_err());
        let zero_range = Light::point(Vec3::ONE, Vec3::ONE, 2.0, 0.0);
        assert!(check_lights(&[zero_range]).is_err());
        assert!(check_lights(&vec![good; crate::scene::MAX_LIGHTS + 1]).is_err());
    }
}
