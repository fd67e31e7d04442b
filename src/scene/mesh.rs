//! Triangle meshes: the data model every loader and generator produces, its validation, and the
//! GPU vertex it is packed into.
//!
//! A [`Mesh`] is structure-of-arrays: positions, normals and indices always; UVs, tangents and
//! vertex colours when the source has them (empty vectors otherwise). [`Mesh::validate`] is the
//! one gate every mesh passes before it reaches a GPU buffer: finite values, indices in range,
//! attribute arrays of matching length.

use glam::{Vec2, Vec3, Vec4};

use crate::{LucentError, Result};

/// The analytic shape a generated mesh approximates (object space), for exact references.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// Sphere centred at the origin.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// Square in the XZ plane centred at the origin, normal +Y.
    Plane {
        /// Half the side length.
        half_size: f32,
    },
}

/// Interleaved GPU vertex: position and normal (24 bytes; matches glsl/deferred/gbuffer.vert).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Object-space positions.
    pub positions: Vec<Vec3>,
    /// Unit normals, one per position.
    pub normals: Vec<Vec3>,
    /// Texture coordinates, one per position, or empty.
    pub uvs: Vec<Vec2>,
    /// Tangents (xyz unit, w = ±1 handedness of the bitangent), one per position, or empty.
    pub tangents: Vec<Vec4>,
    /// Linear vertex colours (e.g. baked thickness), one per position, or empty.
    pub colors: Vec<Vec3>,
    /// Triangle list indices.
    pub indices: Vec<u32>,
    /// The exact shape, for generated meshes.
    pub shape: Option<Shape>,
}

impl Mesh {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The three corner positions of triangle `t`.
    pub fn triangle(&self, t: usize) -> [Vec3; 3] {
        let i = &self.indices[t * 3..t * 3 + 3];
        [0, 1, 2].map(|k| self.positions[i[k] as usize])
    }

    /// Checks the invariants every consumer relies on; `what` names the mesh in errors.
    pub fn validate(&self, what: &str) -> Result<()> {
        let bad = |message: String| Err(LucentError::InvalidInput(format!("{what}: {message}")));
        let n = self.positions.len();
        if n == 0 || self.indices.is_empty() {
            return bad("mesh has no triangles".into());
        }
        if !self.indices.len().is_multiple_of(3) {
            return bad(format!(
                "{} indices is not a whole number of triangles",
                self.indices.len()
            ));
        }
        if n > u32::MAX as usize {
            return bad(format!("{n} vertices exceed 32-bit indices"));
        }
        for (name, len) in [
            ("normals", self.normals.len()),
            ("uvs", self.uvs.len()),
            ("tangents", self.tangents.len()),
            ("colors", self.colors.len()),
        ] {
            // Optional attributes are empty or complete; normals are required.
            if len != n && (len != 0 || name == "normals") {
                return bad(format!("{len} {name} for {n} vertices"));
            }
        }
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return bad(format!(
                "vertex {v} has a non-finite position {}",
                self.positions[v]
            ));
        }
        if let Some(v) = self.normals.iter().position(|p| !p.is_finite()) {
            return bad(format!("vertex {v} has a non-finite normal"));
        }
        if let Some(v) = self.uvs.iter().position(|p| !p.is_finite()) {
            return bad(format!("vertex {v} has a non-finite texture coordinate"));
        }
        if let Some(v) = self.tangents.iter().position(|p| !p.is_finite()) {
            return bad(format!("vertex {v} has a non-finite tangent"));
        }
        if let Some(v) = self.colors.iter().position(|p| !p.is_finite()) {
            return bad(format!("vertex {v} has a non-finite colour"));
        }
        if let Some(i) = self.indices.iter().position(|&i| i as usize >= n) {
            return bad(format!(
                "index {} (triangle {}) is out of range for {n} vertices",
                self.indices[i],
                i / 3
            ));
        }
        Ok(())
    }

    /// The interleaved vertices the G-buffer pass draws.
    pub fn gpu_vertices(&self) -> Vec<Vertex> {
        self.positions
            .iter()
            .zip(&self.normals)
            .map(|(p, n)| Vertex {
                position: p.to_array(),
                normal: n.to_array(),
            })
            .collect()
    }

    /// Tessellates `shape`: `segments` around and `rings` from pole to pole for a sphere; a plane
    /// is split into `segments` x `segments` quads (`rings` unused).
    pub fn generate(shape: Shape, segments: u32, rings: u32) -> Mesh {
        let mut mesh = Mesh {
            shape: Some(shape),
            ..Mesh::default()
        };
        match shape {
            Shape::Sphere { radius } => {
                // Fewer than 3 segments or 2 rings encloses no volume.
                let segments = segments.max(3);
                let rings = rings.max(2);
                for ring in 0..=rings {
                    let theta = std::f32::consts::PI * ring as f32 / rings as f32;
                    for seg in 0..=segments {
                        let phi = std::f32::consts::TAU * seg as f32 / segments as f32;
                        let n = Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            theta.sin() * phi.sin(),
                        );
                        mesh.positions.push(n * radius);
                        mesh.normals.push(n);
                        mesh.uvs.push(Vec2::new(
                            seg as f32 / segments as f32,
                            ring as f32 / rings as f32,
                        ));
                    }
                }
                let stride = segments + 1;
                for ring in 0..rings {
                    for seg in 0..segments {
                        let a = ring * stride + seg;
                        let b = a + stride;
                        // Counter-clockwise seen from outside; pole rings have one triangle.
                        if ring != 0 {
                            mesh.indices.extend_from_slice(&[a, a + 1, b]);
                        }
                        if ring != rings - 1 {
                            mesh.indices.extend_from_slice(&[a + 1, b + 1, b]);
                        }
                    }
                }
            }
            Shape::Plane { half_size } => {
                let n = segments.clamp(1, 4096);
                for z in 0..=n {
                    for x in 0..=n {
                        let u = x as f32 / n as f32;
                        let v = z as f32 / n as f32;
                        mesh.positions.push(Vec3::new(
                            (u * 2.0 - 1.0) * half_size,
                            0.0,
                            (v * 2.0 - 1.0) * half_size,
                        ));
                        mesh.normals.push(Vec3::Y);
                        mesh.uvs.push(Vec2::new(u, v));
                    }
                }
                let stride = n + 1;
                for z in 0..n {
                    for x in 0..n {
                        let a = z * stride + x;
                        let b = a + stride;
                        mesh.indices
                            .extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
                    }
                }
            }
        }
        mesh
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_vertices_lie_on_the_sphere_with_unit_normals() {
        let m = Mesh::generate(Shape::Sphere { radius: 2.0 }, 16, 8);
        m.validate("sphere").unwrap();
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((p.length() - 2.0).abs() < 1e-5);
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
        // 16 segments x 8 rings, minus the degenerate pole triangles.
        assert_eq!(m.triangle_count(), 16 * (8 - 1) * 2);
    }

    #[test]
    fn sphere_triangles_face_outwards() {
        let m = Mesh::generate(Shape::Sphere { radius: 1.0 }, 12, 6);
        for t in 0..m.triangle_count() {
            let [a, b, c] = m.triangle(t);
            assert!(
                (b - a).cross(c - a).dot(a + b + c) > 0.0,
                "triangle {t} faces inwards"
            );
        }
    }

    #[test]
    fn plane_faces_up() {
        let m = Mesh::generate(Shape::Plane { half_size: 1.0 }, 2, 2);
        m.validate("plane").unwrap();
        for t in 0..m.triangle_count() {
            let [a, b, c] = m.triangle(t);
            assert!((b - a).cross(c - a).y > 0.0);
        }
    }

    #[test]
    fn validation_catches_every_broken_invariant() {
        let good = Mesh::generate(Shape::Plane { half_size: 1.0 }, 1, 1);
        good.validate("ok").unwrap();
        let mut m = good.clone();
        m.positions[0].x = f32::NAN;
        assert!(m
            .validate("m")
            .unwrap_err()
            .to_string()
            .contains("non-finite position"));
        let mut m = good.clone();
        m.indices[4] = 99;
        assert!(m
            .validate("m")
            .unwrap_err()
            .to_string()
            .contains("out of range"));
        let mut m = good.clone();
        m.indices.pop();
        assert!(m.validate("m").is_err());
        let mut m = good.clone();
        m.uvs.pop();
        assert!(m.validate("m").unwrap_err().to_string().contains("uvs"));
        let mut m = good.clone();
        m.normals.clear();
        assert!(m.validate("m").is_err());
        assert!(Mesh::default().validate("empty").is_err());
    }
}
