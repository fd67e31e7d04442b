//! What is drawn: meshes, materials, lights, camera, and the built-in scenes by name.
//!
//! Every mesh keeps the analytic shape it was generated from (when it has one), so the CPU
//! reference in `crate::reference` can ray-trace the exact surface the GPU rasterises an
//! approximation of.

pub mod albedo;
mod build;
pub mod builtin;
pub mod camera_range;
pub mod environment;
pub mod file;
pub mod generators;
pub mod gltf;
pub mod inputs;
pub mod layered;
pub mod lean;
pub mod material;
pub mod mesh;
pub mod normals;
pub mod obj;
pub mod polygon;
pub mod profile;
pub mod showcase;
pub mod texture;
pub mod transmittance;
pub mod upload;

use glam::{Mat4, Vec3};

pub use builtin::load_scene;
pub use builtin::{builtin, BUILTIN_SCENES};
pub use environment::Environment;
pub use material::{Light, LightKind, Material};
pub use mesh::{Mesh, Shape};

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_degrees: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
}

impl Camera {
    /// World → view.
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.eye, self.target, Vec3::Y)
    }

    /// Focal length in pixels of an image `height` pixels tall: how many pixels one world unit
    /// spans at one unit of view depth.
    pub fn focal_px(&self, height: u32) -> f32 {
        height as f32 / (2.0 * (self.fov_y_degrees.to_radians() * 0.5).tan())
    }

    /// View → Vulkan clip space (depth 0..1, y down in NDC flipped so +y is up on screen).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let mut p =
            Mat4::perspective_rh(self.fov_y_degrees.to_radians(), aspect, self.near, self.far);
        // Vulkan's clip space has y pointing down; flip so the image is upright.
        p.y_axis.y = -p.y_axis.y;
        p
    }
}

/// One instance of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Index into [`Scene::meshes`].
    pub mesh: usize,
    /// Object → world.
    pub transform: Mat4,
    /// Its material.
    pub material: Material,
}

/// Everything a frame draws.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Name (built-in scene name or file stem).
    pub name: String,
    /// Meshes, shared by objects.
    pub meshes: Vec<Mesh>,
    /// Instances.
    pub objects: Vec<Object>,
    /// Lights (at most [`MAX_LIGHTS`]).
    pub lights: Vec<Light>,
    /// Camera.
    pub camera: Camera,
    /// Light from the environment (constant, hemisphere or radiance map): the ambient every
    /// technique's diffuse receives, as nine SH irradiance coefficients ([`environment`]).
    pub environment: Environment,
    /// Radiance of pixels no geometry covers.
    pub sky: Vec3,
    /// Exposure multiplier before tonemapping.
    pub exposure: f32,
    /// A deformation applied to every object's mesh over time (the `dynamic` scene).
    pub deformation: Option<Deformation>,
    /// The instant shown, in seconds: the deformation is evaluated at it (`render --time`;
    /// the benchmark and the demo advance it every frame). 0 for a scene just loaded.
    pub time: f32,
    /// Attributions of the assets the scene shows (a scan's name, source and licence), one
    /// line each: `lucent render` prints them and the demo's panel shows them, as a licence
    /// such as CC BY asks wherever the asset is shown.
    pub credits: Vec<String>,
}

/// A mesh deformation over time, evaluated on the CPU per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Deformation {
    /// Radial wave: each vertex moves along its normal by
    /// `amplitude * sin(frequency * y + speed * t)`; normals are recomputed.
    Wave {
        /// Displacement amplitude (object units).
        amplitude: f32,
        /// Spatial frequency along y (radians per unit).
        frequency: f32,
        /// Temporal speed (radians per second).
        speed: f32,
    },
}

impl Deformation {
    /// The mesh deformed at time `t` seconds (normals recomputed angle-weighted).
    pub fn apply(&self, mesh: &Mesh, t: f32) -> Mesh {
        let mut out = mesh.clone();
        match *self {
            Deformation::Wave {
                amplitude,
                frequency,
                speed,
            } => {
                for (p, n) in out.positions.iter_mut().zip(&mesh.normals) {
                    *p += *n * (amplitude * (frequency * p.y + speed * t).sin());
                }
            }
        }
        out.normals = normals::angle_weighted_normals(&out.positions, &out.indices);
        out.shape = None;
        out
    }
}

/// Lights the shaders loop over at most (glsl/common/scene.glsl).
pub const MAX_LIGHTS: usize = 64;
