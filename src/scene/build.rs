//! Helpers the built-in and showcase scenes are assembled with: a scene with lucent's defaults,
//! a camera, the floor, a translucent material in the talk's style, and adding meshes and
//! objects to a scene.

use glam::{Mat4, Vec3};

use super::material::{Material, ThicknessSource, Translucency};
use super::{Camera, Environment, Mesh, Object, Scene, Shape};

pub(super) fn floor() -> (Mesh, Material) {
    (
        Mesh::generate(Shape::Plane { half_size: 12.0 }, 1, 1),
        Material::opaque("floor", Vec3::new(0.55, 0.55, 0.5), 0.1, 0.8),
    )
}

pub(super) fn base_scene(name: &str, camera: Camera) -> Scene {
    Scene {
        name: name.to_string(),
        meshes: Vec::new(),
        objects: Vec::new(),
        lights: Vec::new(),
        camera,
        environment: Environment::constant(Vec3::new(0.03, 0.035, 0.04)),
        sky: Vec3::new(0.15, 0.2, 0.3),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    }
}

pub(super) fn camera(eye: Vec3, target: Vec3) -> Camera {
    Camera {
        eye,
        target,
        fov_y_degrees: 45.0,
        near: 0.1,
        far: 100.0,
    }
}

impl Scene {
    /// Adds a mesh, returning its index.
    pub(super) fn add_mesh(&mut self, mesh: Mesh) -> usize {
        self.meshes.push(mesh);
        self.meshes.len() - 1
    }

    /// Adds an object.
    pub(super) fn add(&mut self, mesh: usize, transform: Mat4, material: Material) {
        self.objects.push(Object {
            mesh,
            transform,
            material,
        });
    }

    /// Adds the floor plane at y = 0.
    pub(super) fn add_floor(&mut self) {
        let (mesh, material) = floor();
        let m = self.add_mesh(mesh);
        self.add(m, Mat4::IDENTITY, material);
    }
}

/// A translucent material in the talk's style.
pub(super) fn translucent(
    name: &str,
    albedo: Vec3,
    thickness: ThicknessSource,
    color: Vec3,
) -> Material {
    let mut m = Material::opaque(name, albedo, 0.3, 0.4);
    let mut t = Translucency::new(thickness);
    t.color = color;
    t.ambient = 0.1;
    m.translucency = Some(t);
    m
}
