//! Triangulating OBJ polygons: ear clipping, so concave faces keep their shape.
//!
//! A fan from the first corner (what tobj does) is right only for convex polygons: a U shape
//! or a ring (a polygon whose outline runs round a hole and back along a bridge edge) fanned
//! covers area outside the polygon, and a ring renders as a filled disc. [`triangulate`]
//! projects the polygon onto the plane of its Newell normal and clips ears: a corner whose
//! triangle with its two neighbours turns the polygon's way and contains no other corner is
//! cut off, until three corners are left. Corners that repeat a position (the two ends of a
//! ring's bridge) are not counted as inside an ear they coincide with a corner of, which is
//! what makes such "weakly simple" polygons work. Corners on a straight line between their
//! neighbours are dropped without a triangle (it would have no area).
//!
//! Numerics: positions are f64; "turns the polygon's way" and "inside" use a tolerance of
//! `1e-12` times the squared size of the polygon's bounding box, so rounding on nearly
//! collinear corners neither makes slivers nor hides ears. A polygon with no ear (one that
//! crosses itself) is finished as a fan of what is left, and [`Triangulation::clean`] says so.

use glam::{DVec2, DVec3};

/// Polygons with more corners than this are fanned as before (ear clipping is quadratic or
/// worse in the corner count) and reported.
pub const MAX_EAR_CLIP_CORNERS: usize = 4096;

/// How a polygon was split.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Triangulation {
    /// Triangles as corner numbers of the polygon (0-based), wound like the polygon.
    pub triangles: Vec<[usize; 3]>,
    /// Whether the polygon was convex (a fan would have been the same surface).
    pub convex: bool,
    /// Whether every triangle was a true ear (false: the polygon crosses itself, or is too
    /// large to ear-clip, and part of it was fanned).
    pub clean: bool,
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The fan from corner 0 (what a convex polygon gets).
fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n.saturating_sub(1)).map(|i| [0, i, i + 1]).collect()
}

/// Splits the polygon with corners `points` (in face order) into triangles; see the module
/// docs. A polygon with no area (all corners on a line) gets the fan: its triangles have no
/// area either, and the loader drops degenerate triangles.
pub fn triangulate(points: &[DVec3]) -> Triangulation {
    let n = points.len();
    if n <= 3 {
        return Triangulation {
            triangles: fan(n),
            convex: true,
            clean: true,
        };
    }
    // Newell's normal: robust for concave and slightly non-planar polygons.
    let mut normal = DVec3::ZERO;
    for i in 0..n {
        let (a, b) = (points[i], points[(i + 1) % n]);
        normal += DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    if !normal.is_finite() || normal.length_squared() == 0.0 {
        return Triangulation {
            triangles: fan(n),
            convex: true,
            clean: true,
        };
    }
    // Drop the normal's largest axis; flip so the polygon runs counter-clockwise in 2D.
    let a = normal.abs();
    let (u, v) = if a.z >= a.x && a.z >= a.y {
        (0, 1)
    } else if a.x >= a.y {
        (1, 2)
    } else {
        (2, 0)
    };
    let mut flat: Vec<DVec2> = points.iter().map(|p| DVec2::new(p[u], p[v])).collect();
    let area2: f64 = (0..n).map(|i| cross(flat[i], flat[(i + 1) % n])).sum();
    if area2 < 0.0 {
        for p in &mut flat {
            p.y = -p.y;
        }
    }
    let (lo, hi) = flat
        .iter()
        .fold((flat[0], flat[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let eps = 1e-12 * (hi - lo).length_squared();

    let turn = |a: usize, b: usize, c: usize| cross(flat[b] - flat[a], flat[c] - flat[b]);
    let convex = (0..n).all(|i| turn((i + n - 1) % n, i, (i + 1) % n) >= -eps);
    if convex {
        return Triangulation {
            triangles: fan(n),
            convex: true,
            clean: true,
        };
    }
    if n > MAX_EAR_CLIP_CORNERS {
        return Triangulation {
            triangles: fan(n),
            convex: false,
            clean: false,
        };
    }

    let inside = |p: DVec2, a: DVec2, b: DVec2, c: DVec2| {
        cross(b - a, p - a) >= -eps && cross(c - b, p - b) >= -eps && cross(a - c, p - c) >= -eps
    };
    let mut left: Vec<usize> = (0..n).collect();
    let mut triangles = Vec::with_capacity(n - 2);
    let mut clean = true;
    while left.len() > 3 {
        let m = left.len();
        let mut clipped = false;
        for k in 0..m {
            let (ia, ib, ic) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            let t = turn(ia, ib, ic);
            if t.abs() <= eps {
                // On the line between its neighbours (or a zero-width spike): no area to keep.
                left.remove(k);
                clipped = true;
                break;
            }
            if t < 0.0 {
                continue; // reflex: not an ear
            }
            let (pa, pb, pc) = (flat[ia], flat[ib], flat[ic]);
            let blocked = left.iter().any(|&j| {
                let p = flat[j];
                j != ia
                    && j != ib
                    && j != ic
                    && p != pa
                    && p != pb
                    && p != pc
                    && inside(p, pa, pb, pc)
            });
            if !blocked {
                triangles.push([ia, ib, ic]);
                left.remove(k);
                clipped = true;
                break;
            }
        }
        if !clipped {
            // No ear: the polygon crosses itself. Fan what is left rather than lose it.
            clean = false;
            for i in 1..left.len() - 1 {
                triangles.push([left[0], left[i], left[i + 1]]);
            }
            left.clear();
        }
    }
    if left.len() == 3 {
        triangles.push([left[0], left[1], left[2]]);
    }
    Triangulation {
        triangles,
        convex: false,
        clean,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sum of the triangles' signed areas (in the polygon's plane z = 0) and of their absolute
    /// areas: equal when no triangle is flipped, and equal to the polygon's area when they
    /// cover exactly it.
    fn areas(points: &[DVec3], t: &Triangulation) -> (f64, f64) {
        let mut signed = 0.0;
        let mut unsigned = 0.0;
        for &[a, b, c] in &t.triangles {
            let s = 0.5 * (points[b] - points[a]).cross(points[c] - points[a]).z;
            signed += s;
            unsigned += s.abs();
        }
        (signed, unsigned)
    }

    fn shoelace(points: &[DVec3]) -> f64 {
        let n = points.len();
        0.5 * (0..n)
            .map(|i| points[i].x * points[(i + 1) % n].y - points[(i + 1) % n].x * points[i].y)
            .sum::<f64>()
    }

    #[test]
    fn a_u_shape_covers_its_true_area() {
        // A U, 3 wide and 3 tall with a 1x2 notch: area 9 - 2 = 7. The fan from corner 0
        // covers 9 - (part of the notch), not 7.
        let u: Vec<DVec3> = [
            (0.0, 0.0),
            (3.0, 0.0),
            (3.0, 3.0),
            (2.0, 3.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 3.0),
            (0.0, 3.0),
        ]
        .iter()
        .map(|&(x, y)| DVec3::new(x, y, 0.0))
        .collect();
        let t = triangulate(&u);
        assert!(!t.convex && t.clean, "{t:?}");
        assert_eq!(t.triangles.len(), 6);
        let (signed, unsigned) = areas(&u, &t);
        assert!((signed - 7.0).abs() < 1e-12 && (unsigned - 7.0).abs() < 1e-12);
        // The fan is wrong on this shape: that is what this module is for.
        let fanned = Triangulation {
            triangles: fan(u.len()),
            convex: true,
            clean: true,
        };
        assert!((areas(&u, &fanned).1 - 7.0).abs() > 0.5);
    }

    fn ring(segments: usize, outer: f64, inner: f64, reversed: bool) -> Vec<DVec3> {
        let at = |r: f64, i: usize| {
            let a = std::f64::consts::TAU * i as f64 / segments as f64;
            DVec3::new(r * a.cos(), r * a.sin(), 0.0)
        };
        // Outer ring counter-clockwise, the bridge in, the inner ring clockwise, back out.
        let mut p: Vec<DVec3> = (0..segments).map(|i| at(outer, i)).collect();
        p.push(at(outer, 0));
        p.push(at(inner, 0));
        p.extend((1..segments).rev().map(|i| at(inner, i)));
        p.push(at(inner, 0));
        if reversed {
            p.reverse();
        }
        p
    }

    #[test]
    fn a_ring_keeps_its_hole() {
        for reversed in [false, true] {
            let r = ring(16, 2.0, 1.0, reversed);
            let t = triangulate(&r);
            assert!(!t.convex && t.clean, "{t:?}");
            let want = shoelace(&r);
            let (signed, unsigned) = areas(&r, &t);
            assert!((signed - want).abs() < 1e-9, "{signed} vs {want}");
            assert!((unsigned - want.abs()).abs() < 1e-9, "{unsigned} vs {want}");
            // 16-gon areas: outer - inner = (4 - 1) * 16/2 * sin(tau/16).
            let true_area = 3.0 * 8.0 * (std::f64::consts::TAU / 16.0).sin();
            assert!((want.abs() - true_area).abs() < 1e-9);
            // No triangle covers the hole's centre.
            for &[a, b, c] in &t.triangles {
                let (a, b, c) = (r[a].truncate(), r[b].truncate(), r[c].truncate());
                let s = |p: DVec2, q: DVec2| cross(q - p, -p);
                let centre_inside = [s(a, b), s(b, c), s(c, a)].iter().all(|&v| v > 0.0)
                    || [s(a, b), s(b, c), s(c, a)].iter().all(|&v| v < 0.0);
                assert!(!centre_inside, "a triangle covers the hole");
            }
        }
    }

    #[test]
    fn convex_tilted_and_degenerate_polygons_are_fanned() {
        let quad = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 1.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let t = triangulate(&quad);
        assert!(t.convex && t.triangles == fan(4));
        let line = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0];
        assert_eq!(triangulate(&line).triangles.len(), 2);
        // A concave polygon in the xz plane, seen from below (its normal is -y).
        let l: Vec<DVec3> = [
            (0.0, 0.0),
            (0.0, 2.0),
            (1.0, 2.0),
            (1.0, 1.0),
            (2.0, 1.0),
            (2.0, 0.0),
        ]
        .iter()
        .map(|&(x, z)| DVec3::new(x, 0.0, z))
        .collect();
        let t = triangulate(&l);
        assert!(!t.convex && t.clean);
        let area: f64 = t
            .triangles
            .iter()
            .map(|&[a, b, c]| 0.5 * (l[b] - l[a]).cross(l[c] - l[a]).length())
            .sum();
        assert!((area - 3.0).abs() < 1e-12, "{area}");
    }

    #[test]
    fn a_bow_tie_is_finished_and_reported() {
        let bow: Vec<DVec3> = [(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        let t = triangulate(&bow);
        assert!(!t.convex);
        assert!(!t.triangles.is_empty());
        for tri in &t.triangles {
            assert!(tri.iter().all(|&i| i < bow.len()));
        }
    }
}
