//! What is drawn: meshes, materials, lights, camera, and the built-in scenes by name.
//!
//! Every mesh keeps the analytic shape it was generated from (when it has one), so the CPU
//! reference in [`crate::reference`] can ray-trace the exact surface the GPU rasterises an
//! approximation of.

pub mod builtin;
pub mod file;
pub mod generators;
pub mod inspect;
pub mod lean;
pub mod material;
pub mod mesh;
pub mod normals;
pub mod obj;
pub mod texture;

use glam::{Mat4, Vec3};

pub use builtin::{builtin, BUILTIN_SCENES};
pub use file::load_scene;
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
    /// The technique the scene is made to show (`None`: plain deferred lighting).
    pub technique: Option<String>,
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
    /// A deformation applied to every object's mesh over time (the `dynamic` scene).
    pub deformation: Option<Deformation>,
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

/// Puts every mesh's local thickness (GDC 2011) into its vertex colours, where the G-buffer
/// pass reads it: meshes drawn with `thickness = "bake"` are baked through the on-disk cache
/// keyed by mesh content (only the first load pays), meshes drawn with a thickness texture
/// sample it at their vertices' UVs (the talk's vertex-colour path: per-vertex, so detail
/// finer than the tessellation is lost; the texture is read as linear data).
pub fn prepare_thickness(scene: &mut Scene, cache_dir: &std::path::Path) -> crate::Result<()> {
    sample_thickness_textures(scene)?;
    let mut wanted: Vec<usize> = scene
        .objects
        .iter()
        .filter(|o| {
            o.material
                .translucency
                .as_ref()
                .is_some_and(|t| t.thickness == material::ThicknessSource::Bake)
        })
        .map(|o| o.mesh)
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let options = crate::bake::BakeOptions {
        rays: 256,
        max_distance: None,
        seed: 1,
        texture_size: 512,
        progress: false,
    };
    for m in wanted {
        if !scene.meshes[m].colors.is_empty() {
            continue; // the mesh brought its own (e.g. an OBJ written by bake-thickness)
        }
        let values = crate::bake::cached_per_vertex(&scene.meshes[m], &options, cache_dir)?;
        scene.meshes[m].colors = values.into_iter().map(Vec3::splat).collect();
    }
    Ok(())
}

/// Samples each thickness texture into the vertex colours of the meshes drawn with it.
fn sample_thickness_textures(scene: &mut Scene) -> crate::Result<()> {
    let mut done: Vec<(usize, std::path::PathBuf)> = Vec::new();
    for object in &scene.objects {
        let Some(material::ThicknessSource::Texture(source)) =
            object.material.translucency.as_ref().map(|t| &t.thickness)
        else {
            continue;
        };
        let material::TextureSource::File(path) = source else {
            return Err(crate::LucentError::InvalidInput(format!(
                "material '{}': a procedural texture cannot be a thickness map",
                object.material.name
            )));
        };
        if done.iter().any(|(m, p)| *m == object.mesh && p == path) {
            continue;
        }
        let mesh = &scene.meshes[object.mesh];
        if let Some((m, other)) = done.iter().find(|(m, _)| *m == object.mesh) {
            return Err(crate::LucentError::InvalidInput(format!(
                "mesh {m} is drawn with two thickness textures ({} and {}); give each its own mesh",
                other.display(),
                path.display()
            )));
        }
        if mesh.uvs.len() != mesh.positions.len() {
            return Err(crate::LucentError::file(
                path,
                format!(
                    "thickness texture of material '{}': its mesh has no texture coordinates",
                    object.material.name
                ),
            ));
        }
        let texture = texture::load_texture(path, texture::TextureUsage::Data)?;
        let colors = mesh
            .uvs
            .iter()
            .map(|&uv| {
                let [r, g, b, _] = texture.sample_bilinear(uv);
                // Thickness is a fraction of light let through: [0, 1], whatever the file held.
                Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE)
            })
            .collect();
        scene.meshes[object.mesh].colors = colors;
        done.push((object.mesh, path.clone()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::material::{ThicknessSource, Translucency};

    fn plane_scene(thickness: ThicknessSource) -> Scene {
        let mut scene = builtin("smoke").unwrap();
        scene.meshes = vec![Mesh::generate(Shape::Plane { half_size: 1.0 }, 4, 1)];
        let mut material = Material::opaque("t", Vec3::splat(0.8), 0.1, 0.5);
        material.translucency = Some(Translucency::new(thickness));
        scene.objects = vec![Object {
            mesh: 0,
            transform: Mat4::IDENTITY,
            material,
        }];
        scene
    }

    #[test]
    fn thickness_textures_are_sampled_into_vertex_colours() {
        let dir = std::env::temp_dir().join(format!("lucent-thickness-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ramp.png");
        // A horizontal ramp: red rises with u, green is constant, blue falls.
        let image = image::RgbImage::from_fn(64, 8, |x, _| {
            let t = (x as f32 + 0.5) / 64.0;
            image::Rgb([(t * 255.0) as u8, 128, ((1.0 - t) * 255.0) as u8])
        });
        image.save(&path).unwrap();
        let mut scene = plane_scene(ThicknessSource::Texture(material::TextureSource::File(
            path.clone(),
        )));
        prepare_thickness(&mut scene, &dir).unwrap();
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.colors.len(), mesh.positions.len());
        for (uv, c) in mesh.uvs.iter().zip(&mesh.colors) {
            // Inside the texture (away from the wrapped edge), bilinear follows the ramp.
            if (0.05..0.95).contains(&uv.x) {
                assert!((c.x - uv.x).abs() < 0.03, "uv {uv} -> {c}");
                assert!((c.z - (1.0 - uv.x)).abs() < 0.03, "uv {uv} -> {c}");
            }
            assert!((c.y - 128.0 / 255.0).abs() < 1e-3);
        }
        // A mesh without UVs cannot take a texture: an error naming the file.
        let mut no_uvs = scene.clone();
        no_uvs.meshes[0].uvs.clear();
        no_uvs.meshes[0].colors.clear();
        let err = prepare_thickness(&mut no_uvs, &dir)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("ramp.png") && err.contains("texture coordinates"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
