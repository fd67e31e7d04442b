//! What is drawn: meshes, materials, lights, camera, and the built-in scenes by name.
//!
//! Every mesh keeps the analytic shape it was generated from (when it has one), so the CPU
//! reference in [`crate::reference`] can ray-trace the exact surface the GPU rasterises an
//! approximation of.

pub mod mesh;

use glam::{Mat4, Vec3};

pub use mesh::{Mesh, Shape};

use crate::{LucentError, Result};

/// Surface parameters of the base (opaque) material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Linear albedo, each channel in [0, 1].
    pub albedo: Vec3,
    /// Specular intensity in [0, 1].
    pub specular: f32,
    /// Roughness in [0, 1] (Blinn-Phong exponent 2^(11 - 10 r)).
    pub roughness: f32,
}

/// A light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Parallel light travelling along `direction`.
    Directional {
        /// Direction the light travels (need not be normalised).
        direction: Vec3,
        /// Linear colour times intensity.
        radiance: Vec3,
    },
    /// Inverse-square light that fades smoothly to zero at `range`.
    Point {
        /// World position.
        position: Vec3,
        /// Linear colour times intensity.
        radiance: Vec3,
        /// Distance at which its contribution reaches zero.
        range: f32,
    },
}

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
    /// Ambient radiance (linear RGB), multiplied by albedo.
    pub ambient: Vec3,
    /// Radiance of pixels no geometry covers.
    pub sky: Vec3,
    /// Exposure multiplier before tonemapping.
    pub exposure: f32,
}

/// Lights the shaders loop over at most (glsl/common/scene.glsl).
pub const MAX_LIGHTS: usize = 16;

/// Built-in scenes: (name, one-line description).
pub const BUILTIN_SCENES: &[(&str, &str)] = &[(
    "smoke",
    "a lit sphere on a ground plane: G-buffer -> deferred lighting -> tonemap",
)];

/// A built-in scene by name.
pub fn builtin(name: &str) -> Result<Scene> {
    match name {
        "smoke" => Ok(smoke()),
        _ => Err(LucentError::InvalidInput(format!(
            "unknown scene '{name}'; built-in scenes: {}",
            BUILTIN_SCENES
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        ))),
    }
}

/// The vertical slice: a sphere on a plane, a warm key light and a cool directional fill.
fn smoke() -> Scene {
    Scene {
        name: "smoke".into(),
        meshes: vec![
            Mesh::generate(Shape::Sphere { radius: 1.0 }, 96, 48),
            Mesh::generate(Shape::Plane { half_size: 6.0 }, 1, 1),
        ],
        objects: vec![
            Object {
                mesh: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
                material: Material {
                    albedo: Vec3::new(0.8, 0.3, 0.2),
                    specular: 0.5,
                    roughness: 0.35,
                },
            },
            Object {
                mesh: 1,
                transform: Mat4::IDENTITY,
                material: Material {
                    albedo: Vec3::new(0.6, 0.6, 0.55),
                    specular: 0.1,
                    roughness: 0.8,
                },
            },
        ],
        lights: vec![
            Light::Point {
                position: Vec3::new(2.5, 3.5, 2.0),
                radiance: Vec3::new(30.0, 26.0, 20.0),
                range: 20.0,
            },
            Light::Directional {
                direction: Vec3::new(0.3, -1.0, -0.6),
                radiance: Vec3::new(0.35, 0.45, 0.6),
            },
        ],
        camera: Camera {
            eye: Vec3::new(0.0, 2.2, 5.0),
            target: Vec3::new(0.0, 0.8, 0.0),
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 100.0,
        },
        ambient: Vec3::new(0.03, 0.035, 0.04),
        sky: Vec3::new(0.15, 0.2, 0.3),
        exposure: 1.0,
    }
}
