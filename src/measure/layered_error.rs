//! How far Li et al.'s layered passes are from their f64 references: one term of eq. 3 at a
//! time (its weight 1, every other weight 0, no ambient, so the frame's HDR *is* that term),
//! rendered on the GPU and compared per pixel with [`crate::reference::layered`] evaluated on
//! the exact sphere the mesh approximates.
//!
//! The error is relative L1 over the sphere's interior pixels, `Σ|gpu - ref| / Σ ref` over
//! every channel, on a grid of pixels (`stride`); pixels next to the silhouette (where the mesh
//! and the sphere disagree about coverage) are left out. The references: single scattering
//! with 256 steps per channel and the GPU's `D_max`, multiple scattering integrated over the
//! whole surface ([`SurfaceSamples`]), the transmitted term ray-traced. Used by the tests and by
//! `lucent report li`.

use glam::{DMat4, DVec3, Mat4, Vec3};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::layered::{single_depth, PhaseForm};
use crate::frame::{FrameSettings, Renderer};
use crate::reference::layered::{
    multiple_scattering, single_scattering, transmitted, Phase, SingleScatteringOptions,
    SurfaceSamples,
};
use crate::reference::raytrace::intersect;
use crate::scene::generators::{generate, Generator};
use crate::scene::layered::LayeredMedium;
use crate::scene::{Camera, Light, Material, Object, Scene};
use crate::{LucentError, Result};

/// One term of eq. 3 that has a reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Term {
    /// `L_t`, light through the object unscattered.
    Transmitted,
    /// `L_ss`, single scattering.
    Single,
    /// `L_ms`, dipole multiple scattering.
    Multiple,
}

impl Term {
    /// Every term.
    pub const ALL: [Term; 3] = [Term::Transmitted, Term::Single, Term::Multiple];

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Term::Transmitted => "transmitted",
            Term::Single => "single scattering",
            Term::Multiple => "multiple scattering",
        }
    }

    /// Eq. 3's weights that leave only this term.
    pub fn weights(self) -> [f32; 5] {
        match self {
            Term::Transmitted => [0.0, 0.0, 1.0, 0.0, 0.0],
            Term::Single => [0.0, 0.0, 0.0, 1.0, 0.0],
            Term::Multiple => [0.0, 0.0, 0.0, 0.0, 1.0],
        }
    }
}

/// Radius of the comparison sphere (scene units; 12.5 mm at the presets' 0.04 units per mm).
pub const SPHERE_RADIUS: f32 = 0.5;

/// A lone layered sphere of `medium` at the origin (an icosphere of 5,120 triangles, whose
/// exact shape the references ray-trace) under `lights`, seen from +z, no ambient, black sky.
pub fn sphere_scene(medium: LayeredMedium, lights: Vec<Light>) -> Result<Scene> {
    let mut material = Material::opaque("layered", Vec3::splat(0.8), 0.0, 0.5);
    material.layers = Some(medium);
    Ok(Scene {
        name: "layered-reference".into(),
        meshes: vec![generate(Generator::Icosphere, 4)?],
        objects: vec![Object {
            mesh: 0,
            transform: Mat4::from_scale(Vec3::splat(SPHERE_RADIUS)),
            material,
        }],
        lights,
        camera: Camera {
            eye: Vec3::new(0.0, 0.0, 1.9),
            target: Vec3::ZERO,
            fov_y_degrees: 40.0,
            near: 0.1,
            far: 20.0,
        },
        environment: crate::scene::Environment::constant(Vec3::ZERO),
        sky: Vec3::ZERO,
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    })
}

/// A clear medium (a 12.5 mm sphere lets e^-1.5 of the light through): the transmitted term
/// is large (the layered tests' and `report li`'s).
pub fn clear_medium() -> LayeredMedium {
    LayeredMedium::homogeneous(
        "clear",
        Vec3::new(0.04, 0.05, 0.06),
        Vec3::new(0.01, 0.02, 0.04),
        0.0,
        1.3,
    )
}

/// The lights of the comparison: a point light above and to the side (it lights about half of
/// what the camera sees, the rest is lit through the object) and a dimmer one behind.
pub fn comparison_lights() -> Vec<Light> {
    vec![
        Light::point(Vec3::new(1.2, 0.9, 0.6), Vec3::ONE, 4.0, 10.0),
        Light::point(
            Vec3::new(-0.3, 0.2, -1.5),
            Vec3::new(1.0, 0.8, 0.6),
            3.0,
            10.0,
        ),
    ]
}

/// The texture coordinates of a point of the unit sphere as [`Generator::Icosphere`] lays
/// them out: u the longitude `atan2(z, x) / 2π` in [0, 1), v the colatitude `acos(y) / π`
/// (0 at +y, the top row). (The generator rescales u by at most a seam triangle's width;
/// textures that vary only in v read exactly the same texels.)
pub fn sphere_uv(p: DVec3) -> glam::Vec2 {
    let n = p.normalize_or_zero();
    let u = n.z.atan2(n.x).rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU;
    let v = n.y.clamp(-1.0, 1.0).acos() / std::f64::consts::PI;
    glam::Vec2::new(u as f32, v as f32)
}

/// The result of one comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermError {
    /// The term.
    pub term: Term,
    /// Pixels compared.
    pub pixels: usize,
    /// `Σ|gpu - ref| / Σ ref` over the pixels' channels.
    pub relative_l1: f64,
    /// Mean GPU value (all channels).
    pub gpu_mean: f64,
    /// Mean reference value.
    pub reference_mean: f64,
    /// The GPU frame's time (ms, the frame's own readback).
    pub frame_ms: f64,
}

/// The world ray through the centre of pixel (x, y) of a `width` x `height` frame (the GPU's
/// `world_position` convention: NDC from the pixel centre, top row at -1).
pub fn pixel_ray(camera: &Camera, width: u32, height: u32, x: u32, y: u32) -> (DVec3, DVec3) {
    let inv: DMat4 = (camera.projection(width as f32 / height as f32) * camera.view())
        .as_dmat4()
        .inverse();
    let ndc_x = (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0;
    let ndc_y = (f64::from(y) + 0.5) / f64::from(height) * 2.0 - 1.0;
    let near = inv.project_point3(DVec3::new(ndc_x, ndc_y, 0.0));
    let far = inv.project_point3(DVec3::new(ndc_x, ndc_y, 1.0));
    (near, (far - near).normalize())
}

/// Renders `term` of `scene`'s object 0 (a layered sphere) under `settings` and compares
/// every `stride`-th pixel with the reference (evaluated with the phase function the GPU
/// frame uses).
pub fn term_error(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    scene: &Scene,
    settings: &FrameSettings,
    term: Term,
    stride: u32,
) -> Result<TermError> {
    term_error_against(
        gpu,
        shaders,
        cache,
        scene,
        settings,
        term,
        stride,
        settings.layered.phase,
    )
}

/// [`term_error`] with the reference's phase function chosen apart from the GPU frame's:
/// Schlick's form on the GPU against the true Henyey-Greenstein reference is what the
/// approximation costs (`lucent report li`), against a Schlick reference only the
/// implementation's error.
#[allow(clippy::too_many_arguments)]
pub fn term_error_against(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    scene: &Scene,
    settings: &FrameSettings,
    term: Term,
    stride: u32,
    reference_phase: PhaseForm,
) -> Result<TermError> {
    let mut scene = scene.clone();
    scene.environment = crate::scene::Environment::constant(Vec3::ZERO);
    let medium = {
        let m = scene
            .objects
            .first_mut()
            .and_then(|o| o.material.layers.as_mut())
            .ok_or_else(|| {
                LucentError::InvalidInput("the comparison needs a layered object 0".into())
            })?;
        m.weights = term.weights();
        m.clone()
    };
    let mut settings = *settings;
    settings.export_hdr = true;
    let renderer = Renderer::new(gpu, shaders, cache, &scene, settings)?;
    let images = renderer.render_once(gpu);
    gpu.wait_idle()?;
    renderer.destroy(gpu);
    let images = images?;
    let hdr = images
        .hdr
        .ok_or_else(|| LucentError::InvalidInput("no HDR image came back".into()))?;
    let (w, h) = (settings.width, settings.height);
    let object = &scene.objects[0];
    let shape = scene.meshes[object.mesh]
        .shape
        .ok_or_else(|| LucentError::InvalidInput("object 0 has no analytic shape".into()))?;
    let transform = object.transform.as_dmat4();
    let hits = |x: i64, y: i64| {
        if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
            return None;
        }
        let (o, d) = pixel_ray(&scene.camera, w, h, x as u32, y as u32);
        intersect(shape, &transform, o, d).map(|(t, _)| (o + d * t, d))
    };
    let samples = match term {
        Term::Multiple => Some(SurfaceSamples::new(
            &scene,
            0,
            SurfaceSamples::default_spacing(&medium).max(0.01),
        )?),
        _ => None,
    };
    // TexDep media: the reference reads the texel at each shaded point (the sphere's UV,
    // sphere_uv), the GPU the one its G-buffer sampled there and the entry point's own.
    let depth_textures = medium.load_depth_textures()?;
    let inverse = transform.inverse();
    let texels_at = |p: DVec3| -> Vec<[f32; 4]> {
        let uv = sphere_uv(inverse.transform_point3(p));
        depth_textures
            .iter()
            .map(|t| t.sample_bilinear(uv))
            .collect()
    };
    let mut options = SingleScatteringOptions {
        phase: match reference_phase {
            PhaseForm::HenyeyGreenstein => Phase::HenyeyGreenstein,
            PhaseForm::Schlick => Phase::Schlick,
        },
        steps: 256,
        depth_texels: Vec::new(),
        max_depth: Some(single_depth(&medium, settings.layered.max_depth_mfp)),
    };
    let (mut diff, mut total, mut gpu_sum, mut pixels) = (0.0, 0.0, 0.0, 0usize);
    let stride = stride.max(1) as i64;
    for y in (0..i64::from(h)).step_by(stride as usize) {
        for x in (0..i64::from(w)).step_by(stride as usize) {
            let Some((p, d)) = hits(x, y) else {
                continue;
            };
            // Interior only: all 8 neighbours two pixels away hit the sphere too.
            let interior = [
                (-2, -2),
                (0, -2),
                (2, -2),
                (-2, 0),
                (2, 0),
                (-2, 2),
                (0, 2),
                (2, 2),
            ]
            .iter()
            .all(|(dx, dy)| hits(x + dx, y + dy).is_some());
            if !interior {
                continue;
            }
            let texels = texels_at(p);
            let reference = match term {
                Term::Transmitted => transmitted(&scene, 0, p, d, &texels)?,
                Term::Single => {
                    options.depth_texels = texels;
                    single_scattering(&scene, 0, p, d, &options)?
                }
                Term::Multiple => {
                    multiple_scattering(&scene, samples.as_ref().expect("built above"), p, d)?
                }
            };
            let i = ((y as u32 * w + x as u32) * 4) as usize;
            for c in 0..3 {
                let g = f64::from(hdr[i + c]);
                diff += (g - reference[c]).abs();
                total += reference[c];
                gpu_sum += g;
            }
            pixels += 1;
        }
    }
    let n = (3 * pixels).max(1) as f64;
    Ok(TermError {
        term,
        pixels,
        relative_l1: if total > 0.0 { diff / total } else { diff },
        gpu_mean: gpu_sum / n,
        reference_mean: total / n,
        frame_ms: images.timing.wall_ms,
    })
}
