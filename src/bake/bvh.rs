//! A bounding volume hierarchy over a triangle mesh, for the thickness baker's ray queries.
//!
//! Built once per bake with a binned surface-area heuristic (SAH) over triangle centroids, stored
//! as a flat array of 32-byte nodes (a node's two children sit next to each other), and traversed
//! iteratively with a fixed-size stack. Triangles are intersected two-sided with Möller–Trumbore:
//! a ray from inside a closed mesh meets the far surface from its back, and that must count.
//!
//! - [`Bvh::any_hit`]: is there any triangle within `t_max`? (what ambient occlusion needs; stops
//!   at the first hit found, in no particular order).
//! - [`Bvh::closest_hit`]: the nearest hit, with its triangle and barycentrics (tests, probes).
//!
//! Degenerate (zero-area) triangles are kept in the index space but can never be hit. Rays
//! (nearly) parallel to a triangle's plane miss it: a cosine tolerance of [`PARALLEL_COS`] guards
//! the division in Möller–Trumbore, so no query produces NaN or infinity.

use glam::Vec3;

use crate::{LucentError, Result};

/// Bins per axis for the SAH split search.
const BINS: usize = 16;
/// Leaves hold at most this many triangles unless the triangles cannot be separated.
const MAX_LEAF: usize = 4;
/// Below this depth the builder follows the SAH; deeper it splits at the object median, so the
/// tree depth stays below `SAH_DEPTH + 32` and the traversal stack below can never overflow.
const SAH_DEPTH: usize = 48;
/// Traversal stack size: at least the deepest possible tree plus one.
const STACK: usize = SAH_DEPTH + 40;
/// A ray whose direction makes `|cos| <= PARALLEL_COS` with a triangle's plane normal is
/// treated as parallel to it and misses (Möller–Trumbore divides by that cosine).
pub const PARALLEL_COS: f32 = 1e-7;

/// A ray-triangle intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the ray, in units of the direction's length.
    pub t: f32,
    /// Index of the triangle in the mesh's index list (`indices[3 * triangle..]`).
    pub triangle: u32,
    /// Barycentric weight of the triangle's second corner.
    pub u: f32,
    /// Barycentric weight of the triangle's third corner.
    pub v: f32,
}

/// Axis-aligned box.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    min: Vec3,
    max: Vec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    fn merge(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    /// Half the surface area (enough for SAH ratios); 0 for an empty box.
    fn half_area(&self) -> f32 {
        let e = self.max - self.min;
        if e.x < 0.0 || e.y < 0.0 || e.z < 0.0 {
            return 0.0;
        }
        e.x * e.y + e.y * e.z + e.z * e.x
    }
}

/// Flat node: interior when `count == 0` (children at `first` and `first + 1`), leaf otherwise
/// (triangles `first..first + count` of the reordered triangle arrays).
#[derive(Clone, Copy, Debug)]
struct Node {
    min: Vec3,
    first: u32,
    max: Vec3,
    count: u32,
}

/// Precomputed triangle for Möller–Trumbore.
#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
    /// |e1 × e2| (twice the area): scales the parallel-ray tolerance; 0 for degenerate triangles.
    normal_len: f32,
}

/// A BVH over the triangles of one mesh.
#[derive(Clone, Debug)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    /// Original triangle index of each entry of `tris`.
    ids: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy over the triangle list `indices` into `positions`.
    ///
    /// Errors when `indices` is not a whole number of triangles, an index is out of range, or a
    /// position is not finite.
    pub fn new(positions: &[Vec3], indices: &[u32]) -> Result<Bvh> {
        let bad = |m: String| Err(LucentError::InvalidInput(format!("BVH: {m}")));
        if !indices.len().is_multiple_of(3) {
            return bad(format!("{} indices is not whole triangles", indices.len()));
        }
        if indices.len() / 3 > u32::MAX as usize {
            return bad("too many triangles for 32-bit triangle ids".into());
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= positions.len()) {
            return bad(format!(
                "index {i} out of range for {} vertices",
                positions.len()
            ));
        }
        if positions.iter().any(|p| !p.is_finite()) {
            return bad("non-finite vertex position".into());
        }
        let n = indices.len() / 3;
        let mut tris = Vec::with_capacity(n);
        let mut bounds = Vec::with_capacity(n);
        let mut centroids = Vec::with_capacity(n);
        for t in indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            let (e1, e2) = (b - a, c - a);
            let normal_len = e1.cross(e2).length();
            tris.push(Tri {
                v0: a,
                e1,
                e2,
                normal_len: if normal_len.is_finite() {
                    normal_len
                } else {
                    0.0
                },
            });
            let mut bb = Aabb::EMPTY;
            bb.grow(a);
            bb.grow(b);
            bb.grow(c);
            bounds.push(bb);
            centroids.push((a + b + c) / 3.0);
        }
        let mut ids: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n.max(1));
        nodes.push(Node {
            min: Vec3::ZERO,
            first: 0,
            max: Vec3::ZERO,
            count: 0,
        });
        // Explicit work list (node index, first, count, depth) instead of recursion: a skewed
        // mesh cannot overflow the thread's stack.
        let mut work = vec![(0usize, 0usize, n, 0usize)];
        while let Some((node, first, count, depth)) = work.pop() {
            let slice = &mut ids[first..first + count];
            let mut bb = Aabb::EMPTY;
            let mut cb = Aabb::EMPTY;
            for &i in slice.iter() {
                bb.merge(&bounds[i as usize]);
                cb.grow(centroids[i as usize]);
            }
            if count == 0 {
                bb = Aabb {
                    min: Vec3::ZERO,
                    max: Vec3::ZERO,
                };
            }
            nodes[node].min = bb.min;
            nodes[node].max = bb.max;
            let split = if count <= MAX_LEAF {
                None
            } else if depth < SAH_DEPTH {
                sah_split(slice, &bounds, &centroids, &cb, bb.half_area())
                    .or_else(|| median_split(slice, &centroids, &cb))
            } else {
                median_split(slice, &centroids, &cb)
            };
            match split {
                Some(mid) if mid > 0 && mid < count => {
                    let left = nodes.len();
                    for _ in 0..2 {
                        nodes.push(Node {
                            min: Vec3::ZERO,
                            first: 0,
                            max: Vec3::ZERO,
                            count: 0,
                        });
                    }
                    nodes[node].first = left as u32;
                    nodes[node].count = 0;
                    work.push((left, first, mid, depth + 1));
                    work.push((left + 1, first + mid, count - mid, depth + 1));
                }
                _ => {
                    nodes[node].first = first as u32;
                    // A leaf with no triangles (empty mesh) still must not read as interior.
                    nodes[node].count = count as u32;
                }
            }
        }
        let tris = ids.iter().map(|&i| tris[i as usize]).collect();
        Ok(Bvh { nodes, tris, ids })
    }

    /// Number of triangles indexed.
    pub fn triangle_count(&self) -> usize {
        self.ids.len()
    }

    /// Whether a triangle other than `ignore_triangle` is hit at a distance `0 < t < t_max`
    /// (in units of `dir`'s length). `dir` need not be unit length but must be finite and
    /// non-zero; a zero or non-finite direction hits nothing.
    pub fn any_hit(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        ignore_triangle: Option<u32>,
    ) -> bool {
        let mut found = false;
        let dir_len = dir.length();
        self.traverse(origin, dir, t_max, |bvh, i, limit| {
            if Some(bvh.ids[i]) == ignore_triangle {
                return None;
            }
            let hit = intersect(&bvh.tris[i], origin, dir, dir_len, limit);
            if hit.is_some() {
                found = true;
            }
            hit.map(|_| 0.0)
        });
        found
    }

    /// The nearest triangle other than `ignore_triangle` hit at `0 < t < t_max`, if any.
    pub fn closest_hit(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        ignore_triangle: Option<u32>,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let dir_len = dir.length();
        self.traverse(origin, dir, t_max, |bvh, i, limit| {
            if Some(bvh.ids[i]) == ignore_triangle {
                return None;
            }
            let (t, u, v) = intersect(&bvh.tris[i], origin, dir, dir_len, limit)?;
            best = Some(Hit {
                t,
                triangle: bvh.ids[i],
                u,
                v,
            });
            Some(t)
        });
        best
    }

    /// Walks the nodes the ray can reach within the current limit, nearest child first. `leaf`
    /// tests one triangle against the current limit and returns the new limit on a hit; a limit
    /// of 0 ends the walk (any-hit).
    fn traverse(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut leaf: impl FnMut(&Bvh, usize, f32) -> Option<f32>,
    ) {
        let dir_len = dir.length();
        if !dir_len.is_finite()
            || !origin.is_finite()
            || dir_len <= 0.0
            || t_max.is_nan()
            || t_max <= 0.0
        {
            return;
        }
        // 1/0 = inf is fine in the slab test below; a NaN from 0 * inf is ignored by min/max,
        // which only makes that axis non-limiting (a conservative visit, never a miss).
        let inv = dir.recip();
        let mut limit = t_max;
        let mut stack = [0u32; STACK];
        let mut top = 0usize;
        let mut node = 0usize;
        if self.box_entry(node, origin, inv, limit).is_none() {
            return;
        }
        loop {
            let n = &self.nodes[node];
            if n.count > 0 {
                let first = n.first as usize;
                for i in first..first + n.count as usize {
                    if let Some(t) = leaf(self, i, limit) {
                        if t <= 0.0 {
                            return;
                        }
                        limit = t;
                    }
                }
            } else {
                let (a, b) = (n.first as usize, n.first as usize + 1);
                let ta = self.box_entry(a, origin, inv, limit);
                let tb = self.box_entry(b, origin, inv, limit);
                match (ta, tb) {
                    (Some(ta), Some(tb)) => {
                        let (near, far) = if ta <= tb { (a, b) } else { (b, a) };
                        stack[top] = far as u32;
                        top += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = a;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = b;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if top == 0 {
                return;
            }
            top -= 1;
            node = stack[top] as usize;
        }
    }

    /// Entry distance of the ray into node `i`'s box, if it enters before `limit`.
    fn box_entry(&self, i: usize, origin: Vec3, inv: Vec3, limit: f32) -> Option<f32> {
        let n = &self.nodes[i];
        let t1 = (n.min - origin) * inv;
        let t2 = (n.max - origin) * inv;
        let lo = t1.min(t2);
        let hi = t1.max(t2);
        let enter = lo.x.max(lo.y).max(lo.z).max(0.0);
        let exit = hi.x.min(hi.y).min(hi.z).min(limit);
        (enter <= exit).then_some(enter)
    }
}

/// Barycentric slack at triangle edges: rounding can put a ray through a shared edge just
/// outside both triangles, and a closed mesh would leak; enlarging every triangle by this
/// fraction of its size closes such cracks.
pub const EDGE_TOLERANCE: f32 = 1e-5;

/// Two-sided Möller–Trumbore: `(t, u, v)` for a hit at `0 < t < limit`.
#[inline]
fn intersect(
    tri: &Tri,
    origin: Vec3,
    dir: Vec3,
    dir_len: f32,
    limit: f32,
) -> Option<(f32, f32, f32)> {
    let p = dir.cross(tri.e2);
    let det = tri.e1.dot(p);
    // det = -dir·(e1×e2): compare |cos| with the tolerance without a square root per test.
    // Degenerate triangles (normal_len 0) are never hit.
    if tri.normal_len <= 0.0 || det.is_nan() || det.abs() <= PARALLEL_COS * tri.normal_len * dir_len
    {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - tri.v0;
    let u = s.dot(p) * inv_det;
    if !(-EDGE_TOLERANCE..=1.0 + EDGE_TOLERANCE).contains(&u) {
        return None;
    }
    let q = s.cross(tri.e1);
    let v = dir.dot(q) * inv_det;
    if v < -EDGE_TOLERANCE || u + v > 1.0 + EDGE_TOLERANCE {
        return None;
    }
    let t = tri.e2.dot(q) * inv_det;
    (t > 0.0 && t < limit).then_some((t, u, v))
}

/// Binned SAH split of `ids` (reordered in place); returns the count on the left (0 when a leaf
/// is cheaper than any split), or `None` when the centroids cannot be binned (all coincide).
fn sah_split(
    ids: &mut [u32],
    bounds: &[Aabb],
    centroids: &[Vec3],
    cb: &Aabb,
    parent_half_area: f32,
) -> Option<usize> {
    let extent = cb.max - cb.min;
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bin boundary)
    for axis in 0..3 {
        if extent[axis] <= 0.0 || !extent[axis].is_finite() {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of = |c: Vec3| (((c[axis] - cb.min[axis]) * scale) as usize).min(BINS - 1);
        let mut bin_box = [Aabb::EMPTY; BINS];
        let mut bin_count = [0usize; BINS];
        for &i in ids.iter() {
            let b = bin_of(centroids[i as usize]);
            bin_box[b].merge(&bounds[i as usize]);
            bin_count[b] += 1;
        }
        // Sweep from the right to get the right side's area and count at every boundary.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [0usize; BINS];
        let mut acc = Aabb::EMPTY;
        let mut cnt = 0;
        for b in (1..BINS).rev() {
            acc.merge(&bin_box[b]);
            cnt += bin_count[b];
            right_area[b] = acc.half_area();
            right_count[b] = cnt;
        }
        let mut acc = Aabb::EMPTY;
        let mut cnt = 0;
        for b in 1..BINS {
            acc.merge(&bin_box[b - 1]);
            cnt += bin_count[b - 1];
            if cnt == 0 || right_count[b] == 0 {
                continue;
            }
            let cost = acc.half_area() * cnt as f32 + right_area[b] * right_count[b] as f32;
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, boundary) = best?;
    // Leaf cost = intersecting every triangle; traversal cost ~ one triangle test.
    let leaf_cost = parent_half_area * ids.len() as f32;
    if ids.len() <= 2 * MAX_LEAF && cost + parent_half_area >= leaf_cost {
        return Some(0);
    }
    let scale = BINS as f32 / extent[axis];
    let mut mid = 0;
    for k in 0..ids.len() {
        let c = centroids[ids[k] as usize];
        if ((((c[axis] - cb.min[axis]) * scale) as usize).min(BINS - 1)) < boundary {
            ids.swap(k, mid);
            mid += 1;
        }
    }
    Some(mid)
}

/// Object-median split along the widest centroid axis (always splits when `ids.len() >= 2`).
fn median_split(ids: &mut [u32], centroids: &[Vec3], cb: &Aabb) -> Option<usize> {
    if ids.len() < 2 {
        return None;
    }
    let extent = cb.max - cb.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = ids.len() / 2;
    ids.select_nth_unstable_by(mid, |&a, &b| {
        centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis])
    });
    Some(mid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{rngs::SmallRng, Rng, SeedableRng};

    fn brute_closest(
        positions: &[Vec3],
        indices: &[u32],
        o: Vec3,
        d: Vec3,
        t_max: f32,
        ignore: Option<u32>,
    ) -> Option<(f32, u32)> {
        let mut best: Option<(f32, u32)> = None;
        for (t, tri) in indices.chunks_exact(3).enumerate() {
            if Some(t as u32) == ignore {
                continue;
            }
            let [a, b, c] = [0, 1, 2].map(|k| positions[tri[k] as usize]);
            let pre = Tri {
                v0: a,
                e1: b - a,
                e2: c - a,
                normal_len: (b - a).cross(c - a).length(),
            };
            let limit = best.map_or(t_max, |b| b.0);
            if let Some((h, _, _)) = intersect(&pre, o, d, d.length(), limit) {
                best = Some((h, t as u32));
            }
        }
        best
    }

    fn random_soup(rng: &mut SmallRng, n: usize) -> (Vec<Vec3>, Vec<u32>) {
        let mut positions = Vec::new();
        let v3 = |rng: &mut SmallRng, s: f32| {
            Vec3::new(
                rng.gen_range(-s..s),
                rng.gen_range(-s..s),
                rng.gen_range(-s..s),
            )
        };
        for _ in 0..n {
            let c = v3(rng, 10.0);
            for _ in 0..3 {
                positions.push(c + v3(rng, 1.0));
            }
        }
        let indices = (0..positions.len() as u32).collect();
        (positions, indices)
    }

    #[test]
    fn bvh_agrees_with_brute_force_on_random_rays() {
        let mut rng = SmallRng::seed_from_u64(7);
        let (positions, indices) = random_soup(&mut rng, 600);
        let bvh = Bvh::new(&positions, &indices).unwrap();
        assert_eq!(bvh.triangle_count(), 600);
        let mut hits = 0;
        for k in 0..1000 {
            let o = Vec3::new(
                rng.gen_range(-12.0..12.0),
                rng.gen_range(-12.0..12.0),
                rng.gen_range(-12.0..12.0),
            );
            let d = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            let t_max = if k % 2 == 0 { f32::INFINITY } else { 8.0 };
            let ignore = (k % 3 == 0).then(|| rng.gen_range(0..600));
            let brute = brute_closest(&positions, &indices, o, d, t_max, ignore);
            let fast = bvh.closest_hit(o, d, t_max, ignore);
            match (brute, fast) {
                (None, None) => {}
                (Some((t, _)), Some(h)) => {
                    // Ties at shared distances may pick either triangle; the distance must agree.
                    assert!(
                        (t - h.t).abs() <= 1e-5 * t.max(1.0),
                        "ray {k}: {t} vs {}",
                        h.t
                    );
                    hits += 1;
                }
                other => panic!("ray {k}: brute force and BVH disagree: {other:?}"),
            }
            assert_eq!(
                brute.is_some(),
                bvh.any_hit(o, d, t_max, ignore),
                "ray {k}: any_hit disagrees"
            );
        }
        assert!(hits > 100, "too few hits ({hits}) to test anything");
    }

    #[test]
    fn ignores_the_named_triangle_and_respects_t_max() {
        let positions = [
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(1.0, -1.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(-1.0, -1.0, 3.0),
            Vec3::new(1.0, -1.0, 3.0),
            Vec3::new(0.0, 1.0, 3.0),
        ];
        let bvh = Bvh::new(&positions, &[0, 1, 2, 3, 4, 5]).unwrap();
        let hit = bvh.closest_hit(Vec3::ZERO, Vec3::Z, 10.0, None).unwrap();
        assert_eq!((hit.triangle, hit.t), (0, 1.0));
        let hit = bvh.closest_hit(Vec3::ZERO, Vec3::Z, 10.0, Some(0)).unwrap();
        assert_eq!((hit.triangle, hit.t), (1, 3.0));
        assert!(!bvh.any_hit(Vec3::ZERO, Vec3::Z, 0.5, None));
        assert!(bvh.any_hit(Vec3::ZERO, Vec3::Z, 1.5, None));
        // Back faces count: from behind, the same triangles are hit.
        assert!(bvh.any_hit(Vec3::new(0.0, 0.0, 4.0), -Vec3::Z, 10.0, None));
    }

    #[test]
    fn degenerate_inputs_never_hit_or_panic() {
        // A ray in the plane of a triangle, a zero-area triangle, zero and NaN directions.
        let positions = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 2.0, 2.0),
        ];
        let bvh = Bvh::new(&positions, &[0, 1, 2, 3, 3, 3]).unwrap();
        let o = Vec3::new(-1.0, 0.25, 0.0);
        assert!(!bvh.any_hit(o, Vec3::X, 10.0, None));
        assert!(bvh
            .closest_hit(Vec3::new(2.0, 2.0, 0.0), Vec3::Z, 10.0, None)
            .is_none());
        assert!(!bvh.any_hit(o, Vec3::ZERO, 10.0, None));
        assert!(!bvh.any_hit(o, Vec3::NAN, 10.0, None));
        assert!(!bvh.any_hit(Vec3::NAN, Vec3::Z, 10.0, None));
        assert!(Bvh::new(&positions, &[0, 1]).is_err());
        assert!(Bvh::new(&positions, &[0, 1, 9]).is_err());
        let empty = Bvh::new(&positions, &[]).unwrap();
        assert!(!empty.any_hit(o, Vec3::Z, 10.0, None));
    }

    #[test]
    fn a_closed_mesh_does_not_leak() {
        // Rays from just inside a closed sphere, many of them grazing past the vertex fans
        // they start at: every one must meet the surface (rounding at shared edges once let
        // about 1 in 10^6 slip through).
        let mesh =
            crate::scene::Mesh::generate(crate::scene::Shape::Sphere { radius: 1.0 }, 64, 32);
        let bvh = Bvh::new(&mesh.positions, &mesh.indices).unwrap();
        let mut rng = SmallRng::seed_from_u64(3);
        let mut cast = 0;
        while cast < 100_000 {
            let v = rng.gen_range(0..mesh.positions.len());
            let n = mesh.normals[v];
            let d = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
            .normalize_or_zero();
            // Mostly grazing directions: within ~6 degrees of the tangent plane.
            let d = (d - n * d.dot(n) - n * rng.gen_range(0.0..0.1)).normalize_or_zero();
            if d.dot(-n) <= 0.0 {
                continue;
            }
            cast += 1;
            let o = mesh.positions[v] - n * 3.5e-5;
            assert!(
                bvh.any_hit(o, d, f32::INFINITY, None),
                "ray {d} from vertex {v} escaped"
            );
        }
    }

    #[test]
    fn identical_triangles_build_a_bounded_tree() {
        // Centroids that cannot be separated must not recurse forever or overflow the stack.
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let indices: Vec<u32> = (0..3000).flat_map(|_| [0, 1, 2]).collect();
        let bvh = Bvh::new(&positions, &indices).unwrap();
        let hit = bvh
            .closest_hit(Vec3::new(0.2, 0.2, -1.0), Vec3::Z, 5.0, None)
            .unwrap();
        assert_eq!(hit.t, 1.0);
    }
}
