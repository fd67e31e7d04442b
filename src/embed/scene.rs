//! [`SceneRenderer`]: a lucent scene drawn into a host's colour image, recorded into the host's
//! command buffer with frames in flight.

use ash::vk;

use super::image::{check_image, record_transition, HostImage, ImageState, Role};
use super::uploads::LeakGuard;
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::frame::{FrameSettings, Renderer, TargetDesc};
use crate::scene::Scene;
use crate::Result;

/// A scene's whole frame (G-buffer, lighting and every feature its materials ask for,
/// tonemapped) rendered into a host image.
///
/// Built once per scene shape and output size and format; between frames the host may change
/// whatever `Renderer::can_update` allows (camera, lights, material values, the time of a
/// deforming scene) by passing the changed scene to [`SceneRenderer::record`]. A scene with
/// other objects, features or profiles needs a new renderer.
pub struct SceneRenderer {
    renderer: Renderer,
    extent: vk::Extent2D,
    format: vk::Format,
    guard: LeakGuard,
}

impl SceneRenderer {
    /// Builds the frame of `scene` at `width` x `height` for output images of `format`
    /// (8-bit UNORM or SRGB RGBA/BGRA — the tonemapped display values, sRGB-encoded — or
    /// RGBA16F/RGBA32F, the same values linear), with lucent's default settings.
    ///
    /// The scene's uploads are recorded into `uploads`' command buffer, which the host submits
    /// before the first frame that records this renderer; nothing is submitted or waited for.
    /// On an error that command buffer may hold copies into freed resources: reset it rather
    /// than submit it.
    pub fn new(
        lucent: &Lucent,
        uploads: &mut Uploads,
        scene: &Scene,
        width: u32,
        height: u32,
        format: vk::Format,
    ) -> Result<Self> {
        Self::with_settings(
            lucent,
            uploads,
            scene,
            FrameSettings::new(width, height),
            format,
        )
    }

    /// [`SceneRenderer::new`] with the caller's frame settings (technique, SSS and layered
    /// knobs, shadows...). Their size is the output's; their frames in flight and target are
    /// lucent's to set (the embedding's frames in flight, the host image).
    pub fn with_settings(
        lucent: &Lucent,
        uploads: &mut Uploads,
        scene: &Scene,
        settings: FrameSettings,
        format: vk::Format,
    ) -> Result<Self> {
        let settings = FrameSettings {
            frames_in_flight: lucent.frames_in_flight(),
            // lucent's barriers move the image between the host's declared states and the
            // colour-attachment state the frame's passes use, before and after the frame.
            target: Some(TargetDesc {
                format,
                initial: Access::ColorAttachmentWrite,
                final_access: Access::ColorAttachmentWrite,
            }),
            ..settings
        };
        let extent = vk::Extent2D {
            width: settings.width,
            height: settings.height,
        };
        let renderer = uploads.record(lucent, "SceneRenderer::new", || {
            Renderer::new(
                lucent.gpu(),
                lucent.shaders(),
                lucent.pipeline_cache(),
                scene,
                settings,
            )
        })?;
        Ok(Self {
            renderer,
            extent,
            format,
            guard: LeakGuard::new(format!(
                "SceneRenderer ({} objects, {}x{})",
                scene.objects.len(),
                extent.width,
                extent.height
            )),
        })
    }

    /// The renderer underneath (its plan, passes and settings): lucent's internals, for its
    /// own tests (only with the `internals` feature).
    #[cfg(feature = "internals")]
    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    /// Records the frame of `scene` for frame slot `slot` into `cmd` (recording, outside any
    /// render pass), drawing into `output` and leaving it in its final state
    /// ([`HostImage::left_in`]), which it returns.
    ///
    /// Writes slot `slot`'s per-frame parameters from `scene` first (camera, lights, material
    /// values, a deforming scene's vertices at `scene.time`): the frame last recorded with
    /// this slot must have completed. Everything is checked before anything is recorded; on an
    /// error `cmd` holds nothing of this call.
    pub fn record(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        slot: usize,
        scene: &Scene,
        output: &HostImage,
    ) -> Result<ImageState> {
        lucent.check_slot(slot)?;
        let format = self.format;
        check_image(
            lucent.gpu(),
            output,
            "output",
            Role::Output,
            self.extent,
            |f| f == format,
            &format!(
                "{} (the renderer's)",
                crate::backend::format::format_name(format)
            ),
        )?;
        self.renderer.update_slot(scene, slot)?;
        self.renderer.bind_target_at(
            lucent.gpu(),
            slot,
            output.image,
            output.view,
            output.subresources(),
        )?;
        let final_state = output.left_in();
        let gpu = lucent.gpu();
        let working = Role::Output.working_state();
        record_transition(gpu, cmd, output, &output.state, &working);
        self.renderer.record(gpu, cmd, slot, None)?;
        record_transition(gpu, cmd, output, &working, &final_state);
        Ok(final_state)
    }

    /// Destroys the frame and the scene's GPU data. lucent's work must be complete (the host
    /// waited for every frame it recorded).
    pub fn destroy(self, lucent: &Lucent) {
        let Self {
            renderer, guard, ..
        } = self;
        renderer.destroy(lucent.gpu());
        guard.disarm();
    }
}
