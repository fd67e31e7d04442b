//! [`EnvironmentEffect`]: lucent's SH environment light added to a host's frame, on the host's
//! own G-buffer ([`GBufferDesc`]).
//!
//! lucent lights every surface of its own scenes with an environment ([`Environment`]: a
//! constant, a sky-over-ground hemisphere, the built-in sky or a radiance map) projected on
//! nine spherical-harmonic coefficients (Ramamoorthi and Hanrahan 2001): the diffuse
//! irradiance at a normal is a quadratic polynomial in it, evaluated per pixel. The host
//! renders its G-buffer and its own lights as usual; this effect adds that ambient term,
//! `ambient_radiance(n) * albedo`, to every surface pixel of the host's lit diffuse light (its
//! contents are kept): the same GLSL (`ambient_radiance` in `glsl/common/scene.glsl`) lucent's
//! lighting pass adds. When the host's diffuse light is kept without the albedo
//! ([`super::DiffuseAlbedo::Excluded`]), so is the term, and the albedo image is not read.
//! Recorded before an [`super::SssEffect`] on the same light, the blur diffuses the
//! environment's light too, as lucent's own frames do.
//!
//! The term is unshadowed (lucent's own ambient has no occlusion either): a host with ambient
//! occlusion multiplies it into its own light, not into this one.
//!
//! The host's encodings reach one shader (`glsl/deferred/host_environment.frag`) as a
//! permutation (whether the albedo is read) and per-frame constants (the normal encoding and
//! space, how the background's depth reads): no copy into lucent's layout.

use std::sync::Arc;

use ash::vk;

use super::image::{distinct_inputs, HostImage, Role};
use super::passes::{
    check_described, check_environment, check_views, depth_role, frame_albedo, import_host_image,
    EffectPasses,
};
use super::regions::clipped;
use super::{Lucent, Uploads};
use crate::backend::access::Access;
use crate::backend::shader::PipelineShaders;
use crate::features::capabilities::{require, Effect};
use crate::features::gbuffer_desc::{DepthEncoding, DiffuseAlbedo, GBufferDesc, HostCamera};
use crate::features::pass::FullscreenPass;
use crate::gpu_scene::{projection_depth_ends, Region, SceneGpu, SceneUpload, TableRegion, FRAME};
use crate::graph::{LoadOp, RenderGraph, ResourceId};
use crate::scene::Environment;
use crate::Result;

/// The effect's fragment shader.
const FRAGMENT: &str = "deferred/host_environment.frag";

/// The background's view depth the shader is given for an infinite far plane.
const INFINITE_FAR: f32 = 3.0e38;

/// What an [`EnvironmentEffect`] is built for.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct EnvironmentEffectDesc {
    /// The host's G-buffer: it must describe its normals, and its albedo when its diffuse
    /// light has the albedo multiplied in. The diffuse format is the format of the light the
    /// term is added to.
    pub gbuffer: GBufferDesc,
    /// Views recorded per frame (1 to [`super::MAX_VIEWS_PER_FRAME`]).
    pub views_per_frame: usize,
}

impl EnvironmentEffectDesc {
    /// The effect over `gbuffer`, one view a frame.
    pub fn new(gbuffer: GBufferDesc) -> Self {
        Self {
            gbuffer,
            views_per_frame: 1,
        }
    }

    /// With this many views per frame.
    pub fn with_views_per_frame(mut self, views: usize) -> Self {
        self.views_per_frame = views;
        self
    }
}

/// The host's G-buffer images for one view of one frame, each with its current and final
/// state.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentImages<'a> {
    /// The depth image (a depth format's view of its depth aspect, or linear depth): read
    /// only to tell surfaces from the background the host cleared (the far end of the depth
    /// range, or a linear depth at or past the far plane, 0 or not finite).
    pub depth: &'a HostImage,
    /// The normals.
    pub normals: &'a HostImage,
    /// The albedo: required when the description's diffuse light has the albedo multiplied
    /// in, not read (and refused when given) when it is kept apart.
    pub albedo: Option<&'a HostImage>,
}

/// One view of one frame: what [`EnvironmentEffect::record`] reads and adds to.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentFrame<'a> {
    /// The frame-in-flight slot (0 to the frames in flight of the [`Lucent`]).
    pub slot: usize,
    /// The view within the frame.
    pub view: usize,
    /// The camera the G-buffer was rendered with.
    pub camera: HostCamera,
    /// The environment this frame (its nine coefficients are written per frame, so a host may
    /// change it every frame: a time of day, a fade between two).
    pub environment: &'a Environment,
    /// The G-buffer's images.
    pub images: EnvironmentImages<'a>,
    /// Screen rectangles to light this frame; empty: the whole screen. Clipped to the
    /// G-buffer.
    pub regions: &'a [vk::Rect2D],
    /// The host's lit diffuse light, which the term is added to (a colour attachment of the
    /// description's diffuse format that can be blended; its contents are kept, so it cannot
    /// come in UNDEFINED).
    pub lighting: &'a HostImage,
}

/// The effect's per-frame constants (glsl/deferred/host_environment.frag `HostEnvironment`,
/// std140).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct HostEnvironmentGpu {
    normals: [u32; 4],
    depth: [u32; 4],
    far: [f32; 4],
    view_to_world: [[f32; 4]; 4],
}

/// The effect's constants in the per-frame buffer.
static HOST_ENVIRONMENT: Region = Region::new("host environment decode", "HostEnvironment");

/// The graph's imports, by input.
#[derive(Clone, Copy, Debug)]
struct Imports {
    depth: ResourceId,
    normals: ResourceId,
    albedo: Option<ResourceId>,
    lighting: ResourceId,
}

/// The SH environment's diffuse light on a host's G-buffer (see the module docs).
pub struct EnvironmentEffect {
    passes: EffectPasses,
    imports: Imports,
    desc: EnvironmentEffectDesc,
    /// The normal decode every frame shares; each frame adds its view and depth range.
    normals: [u32; 4],
}

/// The shader defines: whether the albedo is read.
fn defines(albedo: bool) -> &'static [(&'static str, &'static str)] {
    if albedo {
        &[("LUCENT_HOST_ALBEDO", "1")]
    } else {
        &[]
    }
}

/// Every pipeline the effect may build, for the shipped SPIR-V.
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for albedo in [false, true] {
        out.push(PipelineShaders::fullscreen(FRAGMENT, defines(albedo)));
    }
}

/// For a depth image seen through `projection`: whether the background (the far end of the
/// device depth range) is at device depth 1 (standard Z) rather than 0 (reversed Z), and the
/// view depth from which a depth reads as the background: the far plane's, less its f32
/// rounding ([`INFINITE_FAR`] for an infinite far plane). A projection with no depth range
/// (refused for device depth by [`GBufferDesc::view_uniforms`]) gives standard Z with an
/// infinite far plane, which leaves the background to the depth image's own values.
fn far_end(projection: &glam::Mat4) -> (bool, f32) {
    let Some((at_zero, at_one)) = projection_depth_ends(projection) else {
        return (true, INFINITE_FAR);
    };
    let (near, far) = (at_zero.min(at_one), at_zero.max(at_one));
    if !far.is_finite() || far >= f64::from(INFINITE_FAR) {
        return (at_one >= at_zero, INFINITE_FAR);
    }
    // The matrix's f32 entries put the far plane's distance f32 epsilon times far / near off
    // (the decode's cancellation there), and a host's linear depth image holds the far plane
    // rounded to f32: within a few of those of the far plane is the background.
    let tolerance = (8.0 * f64::from(f32::EPSILON) * far / near.max(1e-30)).clamp(1e-6, 1e-2);
    (at_one >= at_zero, (far * (1.0 - tolerance)) as f32)
}

impl EnvironmentEffect {
    /// Builds the effect for `desc`, checking all of it first. Nothing is recorded into
    /// `uploads`, submitted or waited for (`uploads` is taken so that every effect is built
    /// alike).
    pub fn new(
        lucent: &Lucent,
        uploads: &mut Uploads,
        desc: EnvironmentEffectDesc,
    ) -> Result<Self> {
        let gbuffer = &desc.gbuffer;
        gbuffer.check()?;
        require(Effect::Environment, gbuffer)?;
        let Some(normals) = gbuffer.normals else {
            unreachable!("missing() lists each input the effect reads");
        };
        check_views(desc.views_per_frame)?;
        let normals = normals.decode()?;
        let upload = SceneUpload::tables_only(vec![TableRegion {
            region: &HOST_ENVIRONMENT,
            bytes: std::mem::size_of::<HostEnvironmentGpu>() as u64,
        }]);
        let (passes, imports) = EffectPasses::new(
            lucent,
            uploads,
            "EnvironmentEffect",
            upload,
            desc.views_per_frame,
            |scene_gpu| declare(&desc, scene_gpu),
        )?;
        Ok(Self {
            passes,
            imports,
            desc,
            normals,
        })
    }

    super::passes::effect_methods!(
        EnvironmentFrame,
        "`frame.environment`'s diffuse light added to `frame.lighting`"
    );

    fn record_with(
        &mut self,
        lucent: &Lucent,
        cmd: vk::CommandBuffer,
        frame: &EnvironmentFrame<'_>,
        timer: Option<&mut super::EffectTimer>,
    ) -> Result<()> {
        let ring = self.passes.slot(frame.slot, frame.view)?;
        let coefficients = check_environment(frame.environment)?;
        let gbuffer = &self.desc.gbuffer;
        let uniforms = gbuffer
            .view_uniforms(&frame.camera)?
            .with_environment(coefficients);
        let inputs = self.check_images(lucent, frame)?;
        let (far_is_one, far) = far_end(&frame.camera.projection);
        let constants = HostEnvironmentGpu {
            normals: self.normals,
            depth: [
                u32::from(gbuffer.depth.encoding == DepthEncoding::LinearView),
                u32::from(far_is_one),
                0,
                0,
            ],
            far: [far, 0.0, 0.0, 0.0],
            view_to_world: frame.camera.view.inverse().to_cols_array_2d(),
        };
        let per_frame = self.passes.per_frame();
        per_frame.write(ring, &FRAME, bytemuck::bytes_of(&uniforms))?;
        per_frame.write(ring, &HOST_ENVIRONMENT, bytemuck::bytes_of(&constants))?;
        // The pass draws in the `lighting` tiles of the slot (none: the whole screen).
        per_frame.tiles(ring).lighting = clipped(frame.regions, gbuffer.extent());
        let images = &frame.images;
        let mut binds = vec![
            (self.imports.depth, images.depth),
            (self.imports.normals, images.normals),
            (self.imports.lighting, frame.lighting),
        ];
        if let (Some(id), Some(albedo)) = (self.imports.albedo, images.albedo) {
            binds.push((id, albedo));
        }
        self.passes.record(
            lucent,
            cmd,
            ring,
            &binds,
            &inputs,
            (frame.lighting, Role::Accumulate),
            timer,
        )
    }

    /// Checks every image of `frame` against the description; returns the inputs, one per
    /// distinct Vulkan image.
    fn check_images<'a>(
        &self,
        lucent: &Lucent,
        frame: &EnvironmentFrame<'a>,
    ) -> Result<Vec<&'a HostImage>> {
        let gbuffer = &self.desc.gbuffer;
        let images = &frame.images;
        let depth_role = depth_role(gbuffer);
        let albedo = frame_albedo(
            self.imports.albedo.is_some(),
            images.albedo,
            "the environment's light",
        )?;
        let normal_format = gbuffer.normals.expect("checked at new").format;
        let mut checks = vec![
            (images.depth, "depth", depth_role, gbuffer.depth.format),
            (images.normals, "normals", Role::SampledColor, normal_format),
            (
                frame.lighting,
                "lighting",
                Role::Accumulate,
                gbuffer.diffuse.format,
            ),
        ];
        if let Some(albedo) = albedo {
            let format = gbuffer.albedo.expect("checked at new");
            checks.push((albedo, "albedo", Role::SampledColor, format));
        }
        check_described(lucent, gbuffer.extent(), &checks)?;
        distinct_inputs(
            [images.depth, images.normals].into_iter().chain(albedo),
            frame.lighting,
        )
    }
}

/// The effect's graph: the host's images imported (bound when each frame records) and one
/// fullscreen pass adding the environment's light to the host's.
fn declare(desc: &EnvironmentEffectDesc, scene_gpu: &Arc<SceneGpu>) -> (RenderGraph, Imports) {
    let gbuffer = &desc.gbuffer;
    let reads_albedo = gbuffer.diffuse.albedo == DiffuseAlbedo::Included;
    let mut graph = RenderGraph::new();
    let mut import = |name: &str, format: vk::Format, initial: Access| {
        import_host_image(&mut graph, gbuffer, name, format, initial)
    };
    let sampled = Access::FragmentSampledRead;
    let depth = import("host depth", gbuffer.depth.format, sampled);
    let normal_format = gbuffer.normals.expect("checked at new").format;
    let normals = import("host normals", normal_format, sampled);
    let albedo = reads_albedo.then(|| {
        import(
            "host albedo",
            gbuffer.albedo.expect("checked at new"),
            sampled,
        )
    });
    let mut lighting = import(
        "host lighting",
        gbuffer.diffuse.format,
        Access::ColorAttachmentWrite,
    );
    let imports = Imports {
        depth: depth.id(),
        normals: normals.id(),
        albedo: albedo.as_ref().map(|a| a.id()),
        lighting: lighting.id(),
    };
    let mut pass = FullscreenPass::new(&mut graph, "host environment", FRAGMENT, Some(scene_gpu));
    pass.per_frame(&FRAME)
        .per_frame(&HOST_ENVIRONMENT)
        .sample("depth_image", &depth)
        .sample("normal_image", &normals);
    if let Some(albedo) = &albedo {
        pass.sample("albedo_image", albedo);
    }
    pass.defines(defines(reads_albedo))
        .tiles(|scene, ctx| {
            let regions = &scene.per_frame.tiles(ctx.frame).lighting;
            (!regions.is_empty()).then(|| regions.clone())
        })
        .color_add(&mut lighting, LoadOp::Load);
    pass.finish();
    graph.export_image(&lighting, Access::ColorAttachmentWrite);
    (graph, imports)
}

// Effects move to a loader thread and back.
const _: () = {
    const fn send<T: Send>() {}
    send::<EnvironmentEffect>();
};

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat4;

    #[test]
    fn the_background_depth_follows_the_projection() {
        // Standard Z, finite far: the background is at 1, the far plane at 50.
        let (one, far) = far_end(&Mat4::perspective_rh(1.0, 1.5, 0.1, 50.0));
        assert!(one && far < 50.0 && far > 49.9, "{one} {far}");
        // Reversed Z, infinite far: the background is at 0, the far plane at infinity.
        let (one, far) = far_end(&Mat4::perspective_infinite_reverse_rh(1.0, 1.5, 0.1));
        assert!(!one && far == INFINITE_FAR, "{one} {far}");
        // Standard Z, infinite far.
        let (one, far) = far_end(&Mat4::perspective_infinite_rh(1.0, 1.5, 0.1));
        assert!(one && far == INFINITE_FAR, "{one} {far}");
        // Reversed Z, finite far.
        let (one, far) = far_end(&Mat4::perspective_rh(1.0, 1.5, 50.0, 0.1));
        assert!(!one && far < 50.0 && far > 49.9, "{one} {far}");
        // Orthographic, standard Z.
        let (one, far) = far_end(&Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, 0.5, 20.0));
        assert!(one && far < 20.0 && far > 19.99, "{one} {far}");
    }
}
