//! Triangle meshes and the procedural generators.

use glam::Vec3;

/// The analytic shape a generated mesh approximates (object space).
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

/// Interleaved vertex: position and normal (24 bytes; matches glsl/deferred/gbuffer.vert).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
}

/// An indexed triangle mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertices.
    pub vertices: Vec<Vertex>,
    /// Triangle list indices.
    pub indices: Vec<u32>,
    /// The exact shape, for generated meshes.
    pub shape: Option<Shape>,
}

impl Mesh {
    /// Tessellates `shape`: `segments` around and `rings` from pole to pole for a sphere; a plane
    /// is split into `segments` x `segments` quads (`rings` unused).
    pub fn generate(shape: Shape, segments: u32, rings: u32) -> Mesh {
        let segments = segments.max(3);
        let rings = rings.max(2);
        let mut vertices = Vec::new();
        let mut indices = Vec::new();
        match shape {
            Shape::Sphere { radius } => {
                for ring in 0..=rings {
                    let theta = std::f32::consts::PI * ring as f32 / rings as f32;
                    for seg in 0..=segments {
                        let phi = std::f32::consts::TAU * seg as f32 / segments as f32;
                        let n = Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.cos(),
                            theta.sin() * phi.sin(),
                        );
                        vertices.push(Vertex {
                            position: (n * radius).to_array(),
                            normal: n.to_array(),
                        });
                    }
                }
                let stride = segments + 1;
                for ring in 0..rings {
                    for seg in 0..segments {
                        let a = ring * stride + seg;
                        let b = a + stride;
                        // Counter-clockwise seen from outside.
                        if ring != 0 {
                            indices.extend_from_slice(&[a, a + 1, b]);
                        }
                        if ring != rings - 1 {
                            indices.extend_from_slice(&[a + 1, b + 1, b]);
                        }
                    }
                }
            }
            Shape::Plane { half_size } => {
                let n = segments.min(256);
                for z in 0..=n {
                    for x in 0..=n {
                        let u = x as f32 / n as f32 * 2.0 - 1.0;
                        let v = z as f32 / n as f32 * 2.0 - 1.0;
                        vertices.push(Vertex {
                            position: [u * half_size, 0.0, v * half_size],
                            normal: [0.0, 1.0, 0.0],
                        });
                    }
                }
                let stride = n + 1;
                for z in 0..n {
                    for x in 0..n {
                        let a = z * stride + x;
                        let b = a + stride;
                        indices.extend_from_slice(&[a, b, a + 1, a + 1, b, b + 1]);
                    }
                }
            }
        }
        Mesh {
            vertices,
            indices,
            shape: Some(shape),
        }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_vertices_lie_on_the_sphere_with_unit_normals() {
        let m = Mesh::generate(Shape::Sphere { radius: 2.0 }, 16, 8);
        for v in &m.vertices {
            let p = Vec3::from(v.position);
            assert!((p.length() - 2.0).abs() < 1e-5);
            assert!((Vec3::from(v.normal).length() - 1.0).abs() < 1e-5);
        }
        assert!(m.indices.iter().all(|&i| (i as usize) < m.vertices.len()));
        // 16 segments x 8 rings, minus the degenerate pole triangles.
        assert_eq!(m.triangle_count(), 16 * (8 - 1) * 2);
    }

    #[test]
    fn sphere_triangles_face_outwards() {
        let m = Mesh::generate(Shape::Sphere { radius: 1.0 }, 12, 6);
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(m.vertices[t[k] as usize].position));
            let n = (b - a).cross(c - a);
            assert!(n.dot(a + b + c) > 0.0, "triangle {t:?} faces inwards");
        }
    }

    #[test]
    fn plane_faces_up() {
        let m = Mesh::generate(Shape::Plane { half_size: 1.0 }, 2, 2);
        for t in m.indices.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| Vec3::from(m.vertices[t[k] as usize].position));
            assert!((b - a).cross(c - a).y > 0.0);
        }
    }
}
