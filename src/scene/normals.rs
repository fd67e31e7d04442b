//! Vertex normals and tangents generated from geometry, for meshes whose source lacks them.
//!
//! - [`angle_weighted_normals`]: smooth per-vertex normals, each face's normal weighted by the
//!   angle it spans at the vertex (Thürmer and Wüthrich), so a vertex's normal does not depend on
//!   how the faces around it happen to be triangulated.
//! - [`generate_tangents`]: per-vertex tangent frames for normal mapping, from the UV derivatives
//!   of each triangle (Lengyel), orthogonalised against the normal, with the bitangent's
//!   handedness in `w`.
//!
//! Both accumulate in `f64` and never return NaN: a vertex no usable triangle touches gets a
//! documented fallback instead. That matters because these run on user files, where zero-area
//! triangles, collapsed UVs and huge coordinates are common, and one NaN in a vertex buffer
//! poisons every pixel the triangle covers.

use glam::{DVec2, DVec3, Vec2, Vec3, Vec4};

/// The normal given to a vertex that no non-degenerate triangle touches.
pub const FALLBACK_NORMAL: Vec3 = Vec3::Y;

/// Smooth per-vertex unit normals: the sum over the triangles around each vertex of the face
/// normal times the angle the triangle spans at that vertex, normalised.
///
/// Triangles are taken counter-clockwise as front-facing (the normal is `(b - a) x (c - a)`).
/// Zero-area triangles and triangles with an index out of range contribute nothing; a vertex
/// left with no contribution (isolated, or touched only by degenerate triangles) gets
/// [`FALLBACK_NORMAL`] (+Y). A trailing partial triangle in `indices` is ignored.
pub fn angle_weighted_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let Some(corners) = triangle_corners(positions, tri) else {
            continue;
        };
        // f64: the cross product of two f32 edges near f32::MAX overflows in f32 but not here.
        let [a, b, c] = corners.map(|p| p.as_dvec3());
        let face = (b - a).cross(c - a);
        let len = face.length();
        // Zero area (or non-finite input): no direction to contribute.
        if !(len > 0.0 && len.is_finite()) {
            continue;
        }
        let face = face / len;
        for k in 0..3 {
            let p = [a, b, c][k];
            let e1 = [b, c, a][k] - p;
            let e2 = [c, a, b][k] - p;
            sums[tri[k] as usize] += face * corner_angle(e1, e2);
        }
    }
    sums.into_iter()
        .map(|s| unit_or(s, FALLBACK_NORMAL))
        .collect()
}

/// Per-vertex tangents `(x, y, z, w)`: `xyz` is a unit vector perpendicular to the vertex normal
/// pointing toward increasing `u`; `w` is ±1 and the bitangent is `w * cross(normal, xyz)`,
/// pointing toward increasing `v` of the given UVs.
///
/// (The meshes in this crate store image-space UVs, `v` = 0 on the top row of the texture, so
/// the bitangent points *down* the image; a normal map authored with green pointing up the
/// image uses `-bitangent` for its green axis.)
///
/// Each triangle's UV-derivative tangent and bitangent are accumulated, weighted by the angle
/// the triangle spans at the vertex, then Gram-Schmidt orthogonalised against the normal.
/// Triangles whose UV mapping is degenerate (zero UV area) or whose indices are out of range are
/// skipped; a vertex left without a usable tangent gets some unit vector perpendicular to its
/// normal and `w = +1`. `normals` and `uvs` should have one entry per position; a missing normal
/// is taken as [`FALLBACK_NORMAL`] and a missing UV as (0, 0), so mismatched lengths degrade
/// rather than panic.
pub fn generate_tangents(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
) -> Vec<Vec4> {
    let n = positions.len();
    let mut tan = vec![DVec3::ZERO; n];
    let mut bit = vec![DVec3::ZERO; n];
    let uv_of = |i: u32| {
        uvs.get(i as usize)
            .copied()
            .unwrap_or(Vec2::ZERO)
            .as_dvec2()
    };
    for tri in indices.chunks_exact(3) {
        let Some(corners) = triangle_corners(positions, tri) else {
            continue;
        };
        let [a, b, c] = corners.map(|p| p.as_dvec3());
        let [ta, tb, tc] = [uv_of(tri[0]), uv_of(tri[1]), uv_of(tri[2])];
        let (e1, e2) = (b - a, c - a);
        let (d1, d2): (DVec2, DVec2) = (tb - ta, tc - ta);
        let det = d1.x * d2.y - d2.x * d1.y;
        // A UV triangle of (relatively) zero area has no defined u or v direction: skip it rather
        // than divide by ~0. The threshold is relative to the UV edge lengths.
        let scale = d1.length_squared().max(d2.length_squared());
        if !(det.abs() > 1e-12 * scale && det.is_finite()) {
            continue;
        }
        let t = (e1 * d2.y - e2 * d1.y) / det;
        let b_vec = (e2 * d1.x - e1 * d2.x) / det;
        let (Some(t), Some(b_vec)) = (t.try_normalize(), b_vec.try_normalize()) else {
            continue;
        };
        for k in 0..3 {
            let p = [a, b, c][k];
            let w = corner_angle([b, c, a][k] - p, [c, a, b][k] - p);
            tan[tri[k] as usize] += t * w;
            bit[tri[k] as usize] += b_vec * w;
        }
    }
    (0..n)
        .map(|i| {
            let normal = normals
                .get(i)
                .map(|v| v.as_dvec3())
                .and_then(DVec3::try_normalize)
                .unwrap_or(FALLBACK_NORMAL.as_dvec3());
            // Gram-Schmidt: remove the normal component so the frame is orthonormal.
            let t = tan[i] - normal * normal.dot(tan[i]);
            match t.try_normalize() {
                Some(t) => {
                    let w = if normal.cross(t).dot(bit[i]) < 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    t.as_vec3().extend(w)
                }
                None => any_perpendicular(normal).as_vec3().extend(1.0),
            }
        })
        .collect()
}

/// The three corner positions of a triangle, or `None` when an index is out of range.
fn triangle_corners(positions: &[Vec3], tri: &[u32]) -> Option<[Vec3; 3]> {
    Some([
        *positions.get(tri[0] as usize)?,
        *positions.get(tri[1] as usize)?,
        *positions.get(tri[2] as usize)?,
    ])
}

/// The angle between two edges leaving a corner, in radians; 0 when either edge has zero length.
fn corner_angle(e1: DVec3, e2: DVec3) -> f64 {
    // atan2(|e1 x e2|, e1 . e2) stays accurate near 0 and pi, where acos of a normalised dot
    // product loses precision, and needs no normalisation (so no division by a zero length).
    let angle = e1.cross(e2).length().atan2(e1.dot(e2));
    if angle.is_finite() {
        angle
    } else {
        0.0
    }
}

/// `v` normalised, or `fallback` when `v` has no usable length.
fn unit_or(v: DVec3, fallback: Vec3) -> Vec3 {
    v.try_normalize().map_or(fallback, |u| u.as_vec3())
}

/// Some unit vector perpendicular to the unit vector `n`.
fn any_perpendicular(n: DVec3) -> DVec3 {
    // Cross with the axis least aligned with n, so the result is never near zero.
    let a = n.abs();
    let axis = if a.x <= a.y && a.x <= a.z {
        DVec3::X
    } else if a.y <= a.z {
        DVec3::Y
    } else {
        DVec3::Z
    };
    n.cross(axis).try_normalize().unwrap_or(DVec3::X)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (Vec<Vec3>, Vec<u32>) {
        // 8 shared corners, 12 outward-facing (counter-clockwise) triangles.
        let p: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 != 0 { 1.0 } else { -1.0 },
                    if i & 2 != 0 { 1.0 } else { -1.0 },
                    if i & 4 != 0 { 1.0 } else { -1.0 },
                )
            })
            .collect();
        let quads = [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ];
        let mut idx = Vec::new();
        for q in quads {
            idx.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
        }
        (p, idx)
    }

    #[test]
    fn cube_corner_normals_point_along_the_diagonal() {
        let (p, idx) = cube();
        // Every triangle faces outwards.
        for t in idx.chunks(3) {
            let [a, b, c] = [0, 1, 2].map(|k| p[t[k] as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0);
        }
        let n = angle_weighted_normals(&p, &idx);
        for (pos, n) in p.iter().zip(&n) {
            // Angle weighting makes the result independent of the diagonal each face was split
            // along: every corner sees 90 degrees of each of its three faces.
            let expected = pos.normalize();
            assert!((*n - expected).length() < 1e-5, "{n} vs {expected}");
        }
    }

    #[test]
    fn flat_quad_normals_are_the_face_normal() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 0.0),
        ];
        let n = angle_weighted_normals(&p, &[0, 1, 2, 0, 2, 3]);
        for n in n {
            assert!((n - Vec3::Y).length() < 1e-6);
        }
    }

    #[test]
    fn degenerate_and_isolated_vertices_get_plus_y_never_nan() {
        let p = vec![
            Vec3::ZERO,
            Vec3::ZERO,
            Vec3::ZERO,
            Vec3::new(5.0, 5.0, 5.0), // isolated
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(2.0, 2.0, 2.0), // collinear with 0 and 4
            Vec3::new(f32::MAX, 0.0, 0.0),
            Vec3::new(0.0, f32::MAX, 0.0),
        ];
        // Zero-area, collinear, out-of-range, and a huge (f32-overflowing) triangle.
        let idx = [0, 1, 2, 0, 4, 5, 0, 1, 99, 0, 6, 7, 1];
        let n = angle_weighted_normals(&p, &idx);
        assert_eq!(n.len(), p.len());
        assert!(n.iter().all(|v| v.is_finite()));
        for i in [1, 2, 3, 4, 5] {
            assert_eq!(n[i], Vec3::Y, "vertex {i}");
        }
        // The huge triangle still has a well-defined normal, +Z.
        assert!((n[6] - Vec3::Z).length() < 1e-6);
        let t = generate_tangents(&p, &n, &[Vec2::ZERO; 8], &idx);
        assert!(t.iter().all(|v| v.is_finite()));
        assert!(angle_weighted_normals(&[], &[0, 1, 2]).is_empty());
    }

    /// A unit quad in the XZ plane facing +Y with u along +X and v along -Z.
    fn plane() -> (Vec<Vec3>, Vec<Vec3>, Vec<Vec2>, Vec<u32>) {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
        ];
        let uv = vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        (p, vec![Vec3::Y; 4], uv, vec![0, 1, 2, 0, 2, 3])
    }

    #[test]
    fn plane_tangents_are_plus_x_right_handed() {
        let (p, n, uv, idx) = plane();
        assert!(angle_weighted_normals(&p, &idx)
            .iter()
            .all(|v| (*v - Vec3::Y).length() < 1e-6));
        for t in generate_tangents(&p, &n, &uv, &idx) {
            assert!((t.truncate() - Vec3::X).length() < 1e-6, "{t}");
            assert_eq!(t.w, 1.0);
        }
    }

    #[test]
    fn mirrored_uvs_give_negative_handedness() {
        let (p, n, mut uv, idx) = plane();
        for t in &mut uv {
            t.x = 1.0 - t.x; // mirror u
        }
        for t in generate_tangents(&p, &n, &uv, &idx[..3]).iter().take(3) {
            assert!((t.truncate() + Vec3::X).length() < 1e-6, "{t}");
            assert_eq!(t.w, -1.0);
        }
    }

    #[test]
    fn tangents_are_orthogonal_to_a_tilted_normal() {
        let (p, _, uv, idx) = plane();
        let tilted = Vec3::new(0.3, 1.0, 0.2).normalize();
        for t in generate_tangents(&p, &[tilted; 4], &uv, &idx) {
            assert!(t.truncate().dot(tilted).abs() < 1e-6);
            assert!((t.truncate().length() - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn degenerate_uvs_fall_back_to_a_perpendicular_vector() {
        let (p, _, _, idx) = plane();
        for normal in [
            Vec3::Y,
            Vec3::X,
            Vec3::Z,
            Vec3::new(1.0, -2.0, 3.0).normalize(),
        ] {
            let t = generate_tangents(&p, &[normal; 4], &[Vec2::splat(0.5); 4], &idx);
            for t in t {
                assert!(t.is_finite());
                assert!(t.truncate().dot(normal).abs() < 1e-6);
                assert!((t.truncate().length() - 1.0).abs() < 1e-6);
                assert_eq!(t.w, 1.0);
            }
        }
        // Mismatched attribute lengths and NaN UVs degrade, never panic or produce NaN.
        let t = generate_tangents(&p, &[], &[Vec2::NAN], &idx);
        assert_eq!(t.len(), 4);
        assert!(t.iter().all(|v| v.is_finite()));
    }
}
