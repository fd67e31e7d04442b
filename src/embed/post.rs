//! [`PostProcessSss`]: lucent's screen-space SSS over a host's own lit image, the way
//! Jimenez's `SeparableSSS.h` is integrated into an engine.
//!
//! The host renders its lighting as usual, keeping the diffuse light apart (and, ideally, the
//! specular too), and writes a per-pixel SSS profile index. lucent blurs the diffuse of every
//! pixel with its profile, following the depth, adds the specular back and writes the result
//! into a host image. The passes are the frame's own SSS passes (`features::sss`); only their
//! inputs come from the host.
//!
//! What the host provides, per frame (formats fixed at construction):
//! - **diffuse**: the lit diffuse light, linear, any sampled float or UNORM colour format
//!   (RGBA16F typical); its alpha is not read.
//! - **specular** (optional): the lit specular, added back unblurred. Without it lucent adds
//!   nothing (a cleared image: pass the specular apart if the host has it, or it would be
//!   blurred with the diffuse light).
//! - **depth**: the depth buffer the host rendered with, sampled (a depth format, a view of
//!   its depth aspect), in lucent's projection convention: right-handed view, Vulkan depth 0
//!   at the near plane and 1 at the far plane of [`Camera`] (`glam`'s `perspective_rh`). The
//!   [`Camera`] passed each frame must be the host's (eye, target, vertical field of view,
//!   near and far); the blur widths are world distances projected with it.
//! - **profile IDs**: `R8_UNORM`, the profile's number `k` (1 to the number of profiles)
//!   written as `k / 255`; 0 where the pixel does not scatter.
//!
//! Each input set's images are bound into descriptors when the renderer is built, so the
//! host lists every set it will use (one, or one per frame in flight for a host that
//! double-buffers its targets); the output may be any image of the declared format each
//! frame.

use std::sync::Arc;

use ash::vk;

use super::image::{check_image, is_depth, record_transition, HostImage, ImageState, Role};
use super::Lucent;
use crate::backend::access::Access;
use crate::backend::format::{format_info, FormatKind};
use crate::features::registry;
use crate::features::sss::{self, SssKnobs, SssProfiles};
use crate::gpu_scene::{FrameUniforms, SceneGpu, SceneUpload, SlotTiles, FRAME};
use crate::graph::{
    Executable, Handle, Image, ImageInfo, ImportedImage, LoadOp, PassKind, RenderGraph, ResourceId,
};
use crate::scene::material::{SssProfile, Texturing};
use crate::scene::{Camera, Scene};
use crate::{LucentError, Result};

/// What a post-process SSS renderer is built for.
#[derive(Clone, Debug)]
pub struct PostProcessDesc {
    /// Width of every image, in pixels.
    pub width: u32,
    /// Height of every image.
    pub height: u32,
    /// The profiles, by ID: pixels with ID `k` are blurred with `profiles[k - 1]` and its
    /// blur ([`SssProfile::blur`]: the control, separable or bilateral; LCB and LBB blur the
    /// G-buffer's LEAN data, which a host's lit image does not carry). 1 to 31 profiles. Their
    /// [`SssProfile::texturing`] must be [`Texturing::Pre`]: the host's diffuse light already
    /// holds its albedo, so the blur diffuses it with the light.
    pub profiles: Vec<SssProfile>,
    /// The blurs' knobs (samples, kernel shape, precision, half resolution...).
    pub knobs: SssKnobs,
    /// The output's format (a colour-attachment float or UNORM format, e.g. RGBA16F).
    pub output_format: vk::Format,
}

/// The host's input images for one frame.
#[derive(Clone, Copy, Debug)]
pub struct PostProcessInputs<'a> {
    /// Lit diffuse light.
    pub diffuse: &'a HostImage,
    /// Lit specular (optional).
    pub specular: Option<&'a HostImage>,
    /// Depth.
    pub depth: &'a HostImage,
    /// Profile IDs (R8_UNORM, ID / 255).
    pub profile_ids: &'a HostImage,
}

/// The state of each image after a frame: what the host asks for (passed to
/// [`PostProcessSss::record`]) and what it gets back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PostProcessStates {
    /// The inputs' state afterwards (all of them: diffuse, specular, depth, profile IDs).
    pub inputs: ImageState,
    /// The output's.
    pub output: ImageState,
}

/// One frame of post-process SSS: what [`PostProcessSss::record`] reads, writes and leaves.
#[derive(Clone, Copy, Debug)]
pub struct PostProcessFrame<'a> {
    /// The host's camera this frame (the one its depth buffer was rendered with).
    pub camera: &'a Camera,
    /// The host's inputs.
    pub inputs: PostProcessInputs<'a>,
    /// The image the result is written into.
    pub output: &'a HostImage,
    /// The states the images are left in.
    pub finals: PostProcessStates,
}

/// One executable frame per input set (descriptors hold the inputs' views).
struct InputSet {
    views: [vk::ImageView; 4],
    executable: Executable,
    output: ResourceId,
}

/// Screen-space SSS over a host's images (see the module docs).
pub struct PostProcessSss {
    sets: Vec<InputSet>,
    scene_gpu: Option<Arc<SceneGpu>>,
    profiles: SssProfiles,
    desc: PostProcessDesc,
    /// The formats of the inputs, from the first set (every set must match).
    formats: [Option<vk::Format>; 4],
}

/// Inputs in a fixed order: diffuse, specular, depth, profile IDs.
fn input_images<'a>(inputs: &PostProcessInputs<'a>) -> [Option<&'a HostImage>; 4] {
    [
        Some(inputs.diffuse),
        inputs.specular,
        Some(inputs.depth),
        Some(inputs.profile_ids),
    ]
}

fn views(inputs: &PostProcessInputs<'_>) -> [vk::ImageView; 4] {
    input_images(inputs).map(|i| i.map_or(vk::ImageView::null(), |i| i.view))
}

/// Colour formats lucent samples as floats (UNORM, SRGB, float), 1 to 4 channels.
fn sampled_float(format: vk::Format) -> bool {
    format_info(format).is_some_and(|f| {
        matches!(
            f.kind,
            FormatKind::Unorm | FormatKind::Srgb | FormatKind::Float
        )
    })
}

impl PostProcessSss {
    /// Builds the passes for `desc` and each of `input_sets` (the images the host will pass,
    /// one set or one per frame in flight). Checks every image as [`Self::record`] would.
    /// Uploads the profile tables' buffer: **one submission on the host's queue, waited for**.
    pub fn new(
        lucent: &Lucent,
        desc: PostProcessDesc,
        input_sets: &[PostProcessInputs<'_>],
    ) -> Result<Self> {
        if desc.width == 0 || desc.height == 0 || desc.width > 16384 || desc.height > 16384 {
            return Err(LucentError::InvalidInput(format!(
                "post-process SSS: size {}x{} is out of range (1..=16384 per side)",
                desc.width, desc.height
            )));
        }
        if desc.profiles.is_empty() || desc.profiles.len() >= sss::MAX_SSS_PROFILES {
            return Err(LucentError::InvalidInput(format!(
                "post-process SSS: {} profiles; 1 to {} are supported (IDs are 8-bit, 0 means \
                 none)",
                desc.profiles.len(),
                sss::MAX_SSS_PROFILES - 1
            )));
        }
        let mut profiles = Vec::with_capacity(desc.profiles.len());
        for p in &desc.profiles {
            p.validate()?;
            let blur = registry::blur_of(p)?;
            if blur.lean() {
                let usable: Vec<&str> = registry::sss_blurs()
                    .filter(|b| !b.lean())
                    .map(|b| b.name())
                    .collect();
                return Err(LucentError::InvalidInput(format!(
                    "post-process SSS: profile '{}' asks for the {} blur, which blurs the \
                     G-buffer's LEAN data a host's lit image does not carry; use one of: {}",
                    p.name,
                    blur.name(),
                    usable.join(", ")
                )));
            }
            if p.texturing != Texturing::Pre {
                return Err(LucentError::InvalidInput(format!(
                    "post-process SSS: profile '{}' asks for texturing '{}', but a host's lit \
                     diffuse already carries its albedo, so only 'pre' (the albedo blurred with \
                     the light) can be honoured here; set `texturing: Texturing::Pre`",
                    p.name,
                    p.texturing.name()
                )));
            }
            profiles.push((p.clone(), blur));
        }
        if input_sets.is_empty() || input_sets.len() > lucent.frames_in_flight() {
            return Err(LucentError::InvalidInput(format!(
                "post-process SSS: {} input sets; give 1 to {} (one per frame in flight at most)",
                input_sets.len(),
                lucent.frames_in_flight()
            )));
        }
        check_output_format(desc.output_format)?;
        // Each pixel's ID picks its profile; there are no objects (`object_ids` is empty).
        // A host's lit light has no lighting pass here to add transmission in: no media.
        let profiles = SssProfiles {
            transmission: vec![None; profiles.len()],
            profiles,
            object_ids: Vec::new(),
        };
        let no_objects = frame_scene(PLACEHOLDER_CAMERA);
        let upload = SceneUpload {
            translucency_ids: None,
            profile_ids: Some(&[]),
            normal_maps: false,
            lean: false,
            albedo_maps: false,
            frames_in_flight: lucent.frames_in_flight(),
            tables: sss::tables::regions(&profiles),
            layered_ids: None,
            layer_depth_textures: 0,
        };
        let scene_gpu = Arc::new(SceneGpu::new(lucent.gpu(), &no_objects, &upload)?);
        let mut out = Self {
            sets: Vec::new(),
            scene_gpu: Some(scene_gpu),
            profiles,
            desc,
            formats: [None; 4],
        };
        for set in input_sets {
            if let Err(e) = out.add_set(lucent, set) {
                out.destroy(lucent);
                return Err(e);
            }
        }
        // The tables do not change between frames: written once into every slot.
        for slot in 0..lucent.frames_in_flight() {
            if let Err(e) = out.write_tables(slot) {
                out.destroy(lucent);
                return Err(e);
            }
        }
        Ok(out)
    }

    fn scene_gpu(&self) -> &Arc<SceneGpu> {
        self.scene_gpu.as_ref().expect("alive until destroy")
    }

    fn extent(&self) -> vk::Extent2D {
        vk::Extent2D {
            width: self.desc.width,
            height: self.desc.height,
        }
    }

    /// Checks one input image (its state as declared for this frame, `final_state` the
    /// state asked for afterwards) and that its format is the one the passes were built for.
    fn check_input(
        &self,
        lucent: &Lucent,
        index: usize,
        image: &HostImage,
        final_state: &ImageState,
    ) -> Result<()> {
        let (role, ok, formats): (Role, fn(vk::Format) -> bool, &str) = match index {
            2 => (Role::SampledDepth, is_depth, "a depth format"),
            3 => (
                Role::SampledColor,
                |f| f == vk::Format::R8_UNORM,
                "R8_UNORM (profile ID / 255)",
            ),
            _ => (
                Role::SampledColor,
                sampled_float,
                "a float, UNORM or SRGB colour format",
            ),
        };
        check_image(
            lucent.gpu(),
            image,
            role,
            self.extent(),
            final_state,
            ok,
            formats,
        )?;
        if let Some(format) = self.formats[index] {
            if format != image.format {
                return Err(LucentError::InvalidInput(format!(
                    "host image '{}': format {:?}, but the passes were built for {:?}",
                    image.name, image.format, format
                )));
            }
        }
        Ok(())
    }

    fn add_set(&mut self, lucent: &Lucent, set: &PostProcessInputs<'_>) -> Result<()> {
        let images = input_images(set);
        if let Some(first) = self.sets.first() {
            if (first.views[1] == vk::ImageView::null()) != set.specular.is_none() {
                return Err(LucentError::InvalidInput(
                    "post-process SSS: every input set has a specular image, or none has".into(),
                ));
            }
        }
        for (i, image) in images.iter().enumerate() {
            if let Some(image) = image {
                self.check_input(lucent, i, image, &Role::SampledColor.working_state())?;
                self.formats[i] = Some(image.format);
            }
        }
        let mut graph = RenderGraph::new();
        let import = |graph: &mut RenderGraph, image: &HostImage| {
            graph.import_image(
                &image.name,
                ImageInfo {
                    width: self.desc.width,
                    height: self.desc.height,
                    format: image.format,
                },
                ImportedImage {
                    image: image.image,
                    view: image.view,
                    initial: Access::FragmentSampledRead,
                },
            )
        };
        let diffuse = import(&mut graph, set.diffuse);
        let depth = import(&mut graph, set.depth);
        let profile_ids = import(&mut graph, set.profile_ids);
        let specular = match set.specular {
            Some(s) => import(&mut graph, s),
            None => cleared_image(&mut graph, self.desc.width, self.desc.height),
        };
        let output = graph.import_image(
            "output",
            ImageInfo {
                width: self.desc.width,
                height: self.desc.height,
                format: self.desc.output_format,
            },
            ImportedImage {
                image: vk::Image::null(),
                view: vk::ImageView::null(),
                initial: Access::ColorAttachmentWrite,
            },
        );
        let inputs = sss::SssInputs {
            diffuse: &diffuse,
            specular: &specular,
            depth: &depth,
            profile_ids: &profile_ids,
            lean: None,
            shadow_depth: None,
            // The host's diffuse light carries its albedo (every profile is `Texturing::Pre`).
            albedo: None,
            // The host's alpha is its own: the taps read the depth buffer.
            depth_in_alpha: false,
        };
        let result = sss::sss_passes(
            &mut graph,
            &inputs,
            &self.profiles,
            &self.desc.knobs,
            Some(self.scene_gpu()),
            Some(output),
        );
        let output_id = result.id();
        graph.export_image(&result, Access::ColorAttachmentWrite);
        let options = crate::graph::CompileOptions {
            chained_frames: lucent.frames_in_flight() > 1,
            ..Default::default()
        };
        let (plan, execs) = graph.compile(options)?;
        let executable = Executable::new(
            lucent.gpu(),
            plan,
            execs,
            lucent.shaders(),
            lucent.pipeline_cache().handle,
        )?;
        self.sets.push(InputSet {
            views: views(set),
            executable,
            output: output_id,
        });
        Ok(())
    }

    fn write_tables(&self, slot: usize) -> Result<()> {
        let per_frame = &self.scene_gpu().per_frame;
        sss::tables::write(per_frame, slot, &self.profiles, &self.desc.knobs)?;
        // No tiles: every chain covers the whole screen (the host's mask decides per pixel).
        *per_frame.tiles(slot) = SlotTiles::default();
        Ok(())
    }

    /// Records the SSS of one frame for slot `slot` into `cmd` (recording, outside any render
    /// pass): `frame`'s inputs (one of the sets given at construction) seen by its camera,
    /// written into its output, every image then left in the states `frame.finals` asks
    /// for, which are returned. The frame last recorded with this slot must have completed.
    /// Everything is checked before anything is recorded.
    pub fn record(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        slot: usize,
        frame: &PostProcessFrame<'_>,
    ) -> Result<PostProcessStates> {
        let PostProcessFrame {
            camera,
            inputs,
            output,
            finals,
        } = *frame;
        let inputs = &inputs;
        lucent.check_slot(slot)?;
        check_camera(camera)?;
        let wanted = views(inputs);
        let index = self
            .sets
            .iter()
            .position(|s| s.views == wanted)
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "post-process SSS: the input images ('{}', ...) are not one of the {} set(s) \
                     the renderer was built with (their views are bound into descriptors)",
                    inputs.diffuse.name,
                    self.sets.len()
                ))
            })?;
        let images = input_images(inputs);
        for (i, image) in images.iter().enumerate() {
            if let Some(image) = image {
                self.check_input(lucent, i, image, &finals.inputs)?;
            }
        }
        if output.format != self.desc.output_format {
            return Err(LucentError::InvalidInput(format!(
                "host image '{}': format {:?}, but the passes were built for {:?}",
                output.name, output.format, self.desc.output_format
            )));
        }
        check_image(
            lucent.gpu(),
            output,
            Role::Output,
            self.extent(),
            &finals.output,
            |_| true,
            "the output format",
        )?;
        if images.iter().flatten().any(|i| i.image == output.image) {
            return Err(LucentError::InvalidInput(format!(
                "host image '{}' is both an input and the output",
                output.name
            )));
        }

        let scene = frame_scene(*camera);
        let uniforms = FrameUniforms::new(&scene, self.desc.width, self.desc.height);
        self.scene_gpu()
            .per_frame
            .write(slot, &FRAME, bytemuck::bytes_of(&uniforms))?;
        let set = &mut self.sets[index];
        let gpu = lucent.gpu();
        set.executable
            .bind_import(gpu, set.output, output.image, output.view)?;
        let sampled = Role::SampledColor.working_state();
        let attachment = Role::Output.working_state();
        for image in images.iter().flatten() {
            record_transition(gpu, cmd, image, &image.state, &sampled);
        }
        record_transition(gpu, cmd, output, &output.state, &attachment);
        set.executable.record_frame(gpu, cmd, slot, None);
        for image in images.iter().flatten() {
            record_transition(gpu, cmd, image, &sampled, &finals.inputs);
        }
        record_transition(gpu, cmd, output, &attachment, &finals.output);
        Ok(finals)
    }

    /// The passes of input set `index` (their plan, for tables and tests).
    pub fn executable(&self, index: usize) -> Option<&Executable> {
        self.sets.get(index).map(|s| &s.executable)
    }

    /// Destroys the passes and their buffers. lucent's work must be complete.
    pub fn destroy(mut self, lucent: &Lucent) {
        for set in self.sets.drain(..) {
            set.executable.destroy(lucent.gpu());
        }
        if let Some(s) = self.scene_gpu.take().and_then(|s| Arc::try_unwrap(s).ok()) {
            s.destroy(lucent.gpu());
        }
    }
}

/// The camera the scene data is created with (its per-frame uniforms are written from the
/// host's camera at every frame).
const PLACEHOLDER_CAMERA: Camera = Camera {
    eye: glam::Vec3::new(0.0, 0.0, 1.0),
    target: glam::Vec3::ZERO,
    fov_y_degrees: 45.0,
    near: 0.1,
    far: 100.0,
};

/// The scene the SSS passes' uniforms are filled from: the host's camera, nothing else (no
/// objects, lights or ambient: the passes read the camera and the viewport only).
fn frame_scene(camera: Camera) -> Scene {
    Scene {
        name: "post-process SSS".into(),
        meshes: Vec::new(),
        objects: Vec::new(),
        lights: Vec::new(),
        camera,
        environment: crate::scene::Environment::constant(glam::Vec3::ZERO),
        sky: glam::Vec3::ZERO,
        exposure: 1.0,
        deformation: None,
        time: 0.0,
    }
}

/// The output must be a colour-attachment format the final pass writes floats into.
fn check_output_format(format: vk::Format) -> Result<()> {
    if sampled_float(format) && format_info(format).is_some_and(|f| f.channels >= 3) {
        Ok(())
    } else {
        Err(LucentError::InvalidInput(format!(
            "post-process SSS: output format {format:?}: lucent writes RGB(A) float, UNORM or \
             SRGB colour"
        )))
    }
}

/// A camera the blur widths can be projected with: finite, near > 0, far > near, a field of
/// view in (0, 180) degrees (anything else puts Inf or NaN into the uniforms).
fn check_camera(camera: &Camera) -> Result<()> {
    let finite = camera.eye.is_finite()
        && camera.target.is_finite()
        && camera.fov_y_degrees.is_finite()
        && camera.near.is_finite()
        && camera.far.is_finite();
    if !finite
        || camera.near <= 0.0
        || camera.far <= camera.near
        || !(camera.fov_y_degrees > 0.0 && camera.fov_y_degrees < 180.0)
        || (camera.eye - camera.target).length_squared() == 0.0
    {
        return Err(LucentError::InvalidInput(format!(
            "post-process SSS: camera {camera:?} must be finite with near > 0, far > near, a \
             field of view in (0, 180) degrees and eye != target"
        )));
    }
    Ok(())
}

/// A transient image cleared to black by a pass that draws nothing (the specular a host did
/// not keep apart).
fn cleared_image(graph: &mut RenderGraph, width: u32, height: u32) -> Handle<Image> {
    let mut image = graph.create_image(
        "specular (none)",
        ImageInfo {
            width,
            height,
            format: crate::features::lighting::HDR_FORMAT,
        },
    );
    let mut pass = graph.add_pass("clear specular", PassKind::Raster);
    pass.color(&mut image, LoadOp::Clear([0.0; 4]));
    pass.clears_only();
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cameras_that_would_put_inf_or_nan_in_the_uniforms_are_refused() {
        let good = PLACEHOLDER_CAMERA;
        check_camera(&good).unwrap();
        for bad in [
            Camera { near: 0.0, ..good },
            Camera {
                far: good.near,
                ..good
            },
            Camera {
                fov_y_degrees: 180.0,
                ..good
            },
            Camera {
                eye: glam::Vec3::NAN,
                ..good
            },
            Camera {
                target: good.eye,
                ..good
            },
        ] {
            assert!(check_camera(&bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn output_formats_are_colour_the_final_pass_can_write() {
        check_output_format(vk::Format::R16G16B16A16_SFLOAT).unwrap();
        check_output_format(vk::Format::B8G8R8A8_UNORM).unwrap();
        assert!(check_output_format(vk::Format::R32G32B32A32_UINT).is_err());
        assert!(check_output_format(vk::Format::D32_SFLOAT).is_err());
        assert!(check_output_format(vk::Format::R8_UNORM).is_err());
    }
}
