//! The local-thickness baker: the per-vertex or per-texel "thin = white" map that the GDC 2011
//! translucency technique (Barré-Brisebois and Bouchard, *Approximating Translucency for a Fast,
//! Cheap and Convincing Subsurface Scattering Look*) reads at run time.
//!
//! # Method
//!
//! The talk computes local thickness as ambient occlusion with the normals inverted, then inverts
//! the colours. Here, from every surface sample (a vertex, or a texel's point on its triangle):
//!
//! 1. the origin is moved inside by `ε = 1e-5 ×` the mesh's bounding-box diagonal along the
//!    inward normal `-N` (so the ray does not hit the surface it starts on; a texel's own
//!    triangle is also ignored);
//! 2. `N` rays (`BakeOptions::rays`) are cast into the interior, cosine-weighted about `-N`,
//!    against a [`Bvh`] of the mesh (every triangle, two-sided);
//! 3. a ray is *occluded* when it hits any triangle at a distance below the maximum distance `D`
//!    (`BakeOptions::max_distance`; by default the bounding-box diagonal);
//! 4. the value is the cosine-weighted fraction of occluded rays; with cosine-weighted sampling
//!    that is simply `hits / N`.
//!
//! So 1 means the opposite surface is close in every direction (thin, most translucent) and 0
//! means it is farther than `D` everywhere (thick). `D` is the knob: it is the thickness that
//! reads as fully opaque. Normals must point outward (the mesh convention).
//!
//! # Closed forms (what the tests check against)
//!
//! With cosine-weighted directions the angle `θ` from `-N` has `P(cos θ <= c) = c²`.
//!
//! - **Slab** of thickness `d` between two large parallel planes: the ray at `θ` meets the other
//!   plane at `d / cos θ`, occluded iff `cos θ > d / D`, so the value is `1 - (d/D)²` for `d < D`
//!   and 0 otherwise.
//! - **Sphere** of radius `R`: from any surface point the chord at `θ` from the inward normal is
//!   `2R cos θ`, occluded iff `cos θ < D / 2R`, so the value is `(D / 2R)²` for `D < 2R` and 1
//!   otherwise (the same everywhere on the sphere).
//!
//! # Error
//!
//! Each sample is a binomial estimate of its true value `p` with standard error
//! `sqrt(p(1-p)/N)`, at most `0.5/sqrt(N)`. [`BakeStats`] reports both (the mean of the former
//! over all samples, and the latter), and [`bake_report`] prints them: at 256 rays the worst case
//! is ±0.031, at 1024 rays ±0.016.
//!
//! # Which function
//!
//! - [`bake_per_vertex`]: one value per vertex, from the vertex along its normal (vertex colours,
//!   `lucent bake-thickness --per-vertex`).
//! - [`bake_texture`]: a [`ThicknessMap`] over the mesh's UV charts, dilated so bilinear
//!   filtering at chart borders does not pull in black; [`ThicknessMap::write_png`] saves it.
//! - [`cached_per_vertex`]: [`bake_per_vertex`] behind an on-disk cache keyed by mesh content
//!   and options (scenes with `thickness = "bake"`).
//! - [`bake_points`]: arbitrary sample points (probes, tests).
//!
//! Bakes are multi-threaded (rayon) and deterministic for a seed whatever the thread count: each
//! sample draws from its own random stream seeded from `(seed, sample index)`. (The streams come
//! from `rand`'s `SmallRng`, so results are reproducible for one build of lucent, not promised
//! across `rand` versions or between 32- and 64-bit targets.)

pub mod bvh;
mod cache;
pub mod scene;
mod texture;

use std::time::Instant;

use glam::Vec3;
use rand::{rngs::SmallRng, Rng, SeedableRng};
use rayon::prelude::*;

pub use bvh::{Bvh, Hit};
pub use cache::{
    cache_file, cached_per_vertex, cached_per_vertex_with_status, CACHE_FORMAT_VERSION,
};
pub use texture::{bake_texture, ThicknessMap, DILATION_RINGS, MAX_TEXTURE_SIZE};

use crate::scene::Mesh;
use crate::{LucentError, Result};

/// Ray origins move inside by this fraction of the mesh's bounding-box diagonal.
pub const OFFSET_EPSILON: f32 = 1e-5;

/// The most rays per sample a bake accepts.
pub const MAX_RAYS: u32 = 1 << 20;

/// What to bake and how.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeOptions {
    /// Rays per sample (default 256; 1 ..= [`MAX_RAYS`]).
    pub rays: u32,
    /// Distance at which the opposite surface stops counting (thickness that reads as opaque);
    /// `None` = the mesh's bounding-box diagonal.
    pub max_distance: Option<f32>,
    /// Seed of the random directions (default 0).
    pub seed: u64,
    /// Width and height of a baked texture in texels (default 512; 1 ..= [`MAX_TEXTURE_SIZE`]).
    pub texture_size: u32,
    /// Draw a progress bar on stderr (hidden when stderr is not a terminal); without the
    /// `report` feature, log the count at info level instead (`crate::progress`).
    pub progress: bool,
    /// What a sample's value measures: the talk's occlusion (default) or a distance.
    pub measure: BakeMeasure,
}

/// What a baked value measures. Both are in [0, 1], so textures, vertex colours and the cache
/// hold either.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BakeMeasure {
    /// The talk's artistic map: the cosine-weighted fraction of inward rays that meet the
    /// mesh within the maximum distance `D` (1 = thin, 0 = thick).
    #[default]
    Occlusion,
    /// A distance for materials with a medium (`[material.medium]`): the **slab-equivalent
    /// thickness** over `D`, `t / D` with `t = E[min(chord, D)] / 2`, half the cosine-weighted
    /// mean chord along the inward rays (rays that meet nothing within `D` count `D`). For a
    /// slab of thickness `d` the mean chord is `2d - d^2 / D` (so `t` is `d` when `d << D`);
    /// for a sphere of radius `R` (and `D >= 2R`) it is `4R / 3` (`t = 2R / 3`). Multiply by
    /// `D` ([`BakeStats::max_distance`]) for scene units.
    Distance,
}

impl Default for BakeOptions {
    fn default() -> Self {
        BakeOptions {
            rays: 256,
            max_distance: None,
            seed: 0,
            texture_size: 512,
            progress: false,
            measure: BakeMeasure::Occlusion,
        }
    }
}

/// What a bake did, and how precise it is.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeStats {
    /// Samples baked (vertices, covered texels or points).
    pub samples: usize,
    /// Rays cast in all.
    pub rays: u64,
    /// Wall-clock time of the bake (BVH build included).
    pub seconds: f64,
    /// The maximum distance used (resolved from the default when it was `None`).
    pub max_distance: f32,
    /// Worst-case standard error of one sample, `0.5 / sqrt(rays)` (a binomial at p = 0.5).
    pub std_error: f64,
    /// Mean over samples of the estimated standard error `sqrt(p(1-p) / rays)`.
    pub mean_std_error: f64,
}

/// One point to bake: a position on the surface and its outward normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SamplePoint {
    /// Position on the surface.
    pub position: Vec3,
    /// Outward normal (need not be unit length). A zero normal bakes to 0.
    pub normal: Vec3,
    /// Triangle the point lies on, ignored by its rays (`None` for vertices, which lie on
    /// several triangles and rely on the origin offset alone).
    pub triangle: Option<u32>,
}

/// Bakes one thickness value per vertex of `mesh`, from the vertex position along its normal.
///
/// A vertex whose normal has zero length falls back to its area-weighted face normal; one with
/// neither (an unused vertex, or one only on degenerate triangles) bakes to 0.
pub fn bake_per_vertex(mesh: &Mesh, options: &BakeOptions) -> Result<(Vec<f32>, BakeStats)> {
    let start = Instant::now();
    let baker = Baker::new(mesh, options)?;
    let mut face_normals: Option<Vec<Vec3>> = None;
    let points: Vec<SamplePoint> = (0..mesh.vertex_count())
        .map(|v| {
            let mut normal = mesh.normals[v];
            if !usable(normal) {
                // A broken normal says nothing about which side is inside; the faces around the
                // vertex still do (counter-clockwise = outward, the mesh convention).
                normal = face_normals.get_or_insert_with(|| area_weighted_normals(mesh))[v];
            }
            SamplePoint {
                position: mesh.positions[v],
                normal,
                triangle: None,
            }
        })
        .collect();
    Ok(baker.run(&points, start))
}

/// Bakes the thickness at arbitrary points of `mesh`'s surface.
pub fn bake_points(
    mesh: &Mesh,
    points: &[SamplePoint],
    options: &BakeOptions,
) -> Result<(Vec<f32>, BakeStats)> {
    let start = Instant::now();
    let baker = Baker::new(mesh, options)?;
    if let Some(i) = points
        .iter()
        .position(|p| !p.position.is_finite() || !p.normal.is_finite())
    {
        return Err(LucentError::InvalidInput(format!(
            "thickness bake: sample point {i} is not finite"
        )));
    }
    if let Some(i) = points.iter().position(|p| {
        p.triangle
            .is_some_and(|t| t as usize >= mesh.triangle_count())
    }) {
        return Err(LucentError::InvalidInput(format!(
            "thickness bake: sample point {i} names a triangle the mesh does not have"
        )));
    }
    Ok(baker.run(points, start))
}

/// One line for the user: sample count, rays, time, maximum distance and Monte Carlo error.
pub fn bake_report(stats: &BakeStats) -> String {
    format!(
        "baked {} samples x {} rays in {:.2} s (max distance {}); Monte Carlo error: mean ±{:.4}, worst case ±{:.4}",
        stats.samples,
        stats.rays.checked_div(stats.samples as u64).unwrap_or(0),
        stats.seconds,
        stats.max_distance,
        stats.mean_std_error,
        stats.std_error,
    )
}

/// A warning when the baked `values` are all the same (within one 8-bit grey level): a
/// constant thickness map says nothing, and is usually a sign of a mesh or distance problem,
/// named here with the likely cause. `None` when the values vary.
pub fn constant_warning(values: &[f32], stats: &BakeStats) -> Option<String> {
    let (lo, hi) = values
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    if values.is_empty() || hi - lo > 1.0 / 255.0 {
        return None;
    }
    let why = if hi <= 0.5 / 255.0 {
        format!(
            "no ray met the mesh within the maximum distance {} (an open mesh, normals \
             pointing inward, or --max-distance too small)",
            stats.max_distance
        )
    } else if lo >= 1.0 - 0.5 / 255.0 {
        format!(
            "every ray met the mesh within the maximum distance {} (try a larger \
             --max-distance)",
            stats.max_distance
        )
    } else {
        "the mesh is equally thick everywhere (a sphere is)".to_string()
    };
    Some(format!(
        "every one of the {} baked samples is {lo:.3}: the thickness map is constant; {why}",
        values.len()
    ))
}

/// The mesh's bounding-box diagonal (the default maximum distance).
pub fn bounding_box_diagonal(mesh: &Mesh) -> f32 {
    let (lo, hi) = mesh.positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    if mesh.positions.is_empty() {
        0.0
    } else {
        (hi - lo).length()
    }
}

/// A normal we can normalise without producing NaN or infinity.
fn usable(n: Vec3) -> bool {
    let len2 = n.length_squared();
    len2.is_finite() && len2 > 1e-24
}

/// Per-vertex sums of the (area-weighted) geometric normals of the triangles around it.
pub(crate) fn area_weighted_normals(mesh: &Mesh) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; mesh.vertex_count()];
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[tri[k] as usize]);
        let n = (b - a).cross(c - a);
        if n.is_finite() {
            for &i in tri {
                normals[i as usize] += n;
            }
        }
    }
    normals
}

/// splitmix64's finaliser: a cheap bijective 64-bit mix.
fn mix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The random stream of sample `index`: depends on the seed and the index only, never on which
/// thread bakes it or in what order.
fn sample_rng(seed: u64, index: usize) -> SmallRng {
    SmallRng::seed_from_u64(mix64(seed ^ mix64(index as u64)))
}

/// A validated mesh's BVH with the resolved bake parameters.
pub(crate) struct Baker {
    bvh: Bvh,
    max_distance: f32,
    epsilon: f32,
    rays: u32,
    seed: u64,
    progress: bool,
    measure: BakeMeasure,
}

impl Baker {
    /// Validates `mesh` and `options` and builds the BVH.
    pub(crate) fn new(mesh: &Mesh, options: &BakeOptions) -> Result<Baker> {
        mesh.validate("mesh to bake")?;
        validate_options(options)?;
        let diagonal = bounding_box_diagonal(mesh);
        if !(diagonal.is_finite() && diagonal > 0.0) {
            return Err(LucentError::InvalidInput(format!(
                "mesh to bake: bounding-box diagonal {diagonal} (the mesh must have a finite, \
                 non-zero extent)"
            )));
        }
        let max_distance = options.max_distance.unwrap_or(diagonal);
        Ok(Baker {
            bvh: Bvh::new(&mesh.positions, &mesh.indices)?,
            max_distance,
            epsilon: OFFSET_EPSILON * diagonal,
            rays: options.rays,
            seed: options.seed,
            progress: options.progress,
            measure: options.measure,
        })
    }

    /// Bakes every point in parallel; `start` is when the bake began (for the stats).
    pub(crate) fn run(&self, points: &[SamplePoint], start: Instant) -> (Vec<f32>, BakeStats) {
        let bar = self.progress.then(|| {
            crate::progress::Progress::stderr(
                points.len() as u64,
                "baking thickness",
                "{msg} [{bar:40}] {pos}/{len} samples ({eta} left)",
                None,
            )
        });
        let values: Vec<f32> = points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let value = self.sample(p, &mut sample_rng(self.seed, i));
                if let Some(bar) = &bar {
                    bar.inc(1);
                }
                value
            })
            .collect();
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        let n = f64::from(self.rays);
        let mean_std_error = if values.is_empty() {
            0.0
        } else {
            values
                .iter()
                .map(|&p| (f64::from(p) * (1.0 - f64::from(p)) / n).max(0.0).sqrt())
                .sum::<f64>()
                / values.len() as f64
        };
        let stats = BakeStats {
            samples: values.len(),
            rays: values.len() as u64 * u64::from(self.rays),
            seconds: start.elapsed().as_secs_f64(),
            max_distance: self.max_distance,
            std_error: 0.5 / n.sqrt(),
            mean_std_error,
        };
        (values, stats)
    }

    /// The fraction of cosine-weighted inward rays from `p` that hit within the maximum distance.
    fn sample(&self, p: &SamplePoint, rng: &mut SmallRng) -> f32 {
        if !usable(p.normal) {
            return 0.0;
        }
        let inward = -p.normal.normalize();
        let (tangent, bitangent) = inward.any_orthonormal_pair();
        let origin = p.position + inward * self.epsilon;
        let mut hits = 0u32;
        // Distance mode: the sum of min(chord, D) / D over the rays, each term in [0, 1].
        let mut chords = 0.0f64;
        for _ in 0..self.rays {
            // Malley's method: uniform on the unit disc, lifted to the hemisphere. u1 < 1, so
            // the lift is > 0 and no ray runs parallel to the surface.
            let u1: f32 = rng.gen();
            let u2: f32 = rng.gen();
            let r = u1.sqrt();
            let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
            let lift = (1.0 - u1).max(0.0).sqrt();
            let dir = tangent * (r * c) + bitangent * (r * s) + inward * lift;
            match self.measure {
                BakeMeasure::Occlusion => {
                    if self.bvh.any_hit(origin, dir, self.max_distance, p.triangle) {
                        hits += 1;
                    }
                }
                BakeMeasure::Distance => {
                    // `dir` is unit length (r^2 + lift^2 = 1), so `t` is a distance; the
                    // miss counts D, and max_distance > 0 was checked.
                    let t = self
                        .bvh
                        .closest_hit(origin, dir, self.max_distance, p.triangle)
                        .map_or(self.max_distance, |h| h.t.min(self.max_distance));
                    chords += f64::from(t / self.max_distance).clamp(0.0, 1.0);
                }
            }
        }
        match self.measure {
            BakeMeasure::Occlusion => (hits as f32 / self.rays as f32).clamp(0.0, 1.0),
            // Half the mean chord (the slab-equivalent thickness), over D: in [0, 0.5].
            BakeMeasure::Distance => (0.5 * chords / f64::from(self.rays)).clamp(0.0, 1.0) as f32,
        }
    }
}

/// Rejects options no bake can honour.
fn validate_options(options: &BakeOptions) -> Result<()> {
    let bad = |m: String| Err(LucentError::InvalidInput(format!("thickness bake: {m}")));
    if options.rays == 0 || options.rays > MAX_RAYS {
        return bad(format!(
            "{} rays per sample (must be 1 to {MAX_RAYS})",
            options.rays
        ));
    }
    if let Some(d) = options.max_distance {
        if !(d.is_finite() && d > 0.0) {
            return bad(format!(
                "maximum distance {d} (must be finite and positive)"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Shape;

    #[test]
    fn bad_options_and_meshes_are_errors() {
        let sphere = Mesh::generate(Shape::Sphere { radius: 1.0 }, 8, 4);
        for options in [
            BakeOptions {
                rays: 0,
                ..Default::default()
            },
            BakeOptions {
                max_distance: Some(f32::NAN),
                ..Default::default()
            },
            BakeOptions {
                max_distance: Some(-1.0),
                ..Default::default()
            },
        ] {
            assert!(bake_per_vertex(&sphere, &options).is_err(), "{options:?}");
        }
        for texture_size in [0, MAX_TEXTURE_SIZE + 1] {
            let options = BakeOptions {
                texture_size,
                ..Default::default()
            };
            assert!(bake_texture(&sphere, &options).is_err(), "{options:?}");
        }
        let mut flat = sphere.clone();
        flat.positions.iter_mut().for_each(|p| *p = Vec3::ONE);
        assert!(bake_per_vertex(&flat, &BakeOptions::default()).is_err());
        assert!(bake_per_vertex(&Mesh::default(), &BakeOptions::default()).is_err());
        let point = SamplePoint {
            position: Vec3::X,
            normal: Vec3::X,
            triangle: Some(100_000),
        };
        assert!(bake_points(&sphere, &[point], &BakeOptions::default()).is_err());
    }

    #[test]
    fn zero_normals_fall_back_to_face_normals() {
        let mut sphere = Mesh::generate(Shape::Sphere { radius: 1.0 }, 16, 8);
        let options = BakeOptions {
            rays: 64,
            max_distance: Some(1.0),
            ..Default::default()
        };
        let (reference, _) = bake_per_vertex(&sphere, &options).unwrap();
        sphere.normals[40] = Vec3::ZERO;
        let (values, _) = bake_per_vertex(&sphere, &options).unwrap();
        assert!(values
            .iter()
            .all(|v| v.is_finite() && (0.0..=1.0).contains(v)));
        // Same random stream, nearly the same normal: close to the reference, not 0.
        assert!((values[40] - reference[40]).abs() < 0.2, "{values:?}");
    }

    #[test]
    fn report_is_one_line_with_the_numbers() {
        let stats = BakeStats {
            samples: 10,
            rays: 2560,
            seconds: 1.5,
            max_distance: 2.0,
            std_error: 0.03,
            mean_std_error: 0.02,
        };
        assert_eq!(
            bake_report(&stats),
            "baked 10 samples x 256 rays in 1.50 s (max distance 2); Monte Carlo error: mean \
             ±0.0200, worst case ±0.0300"
        );
    }

    #[test]
    fn constant_maps_are_named_with_their_likely_cause() {
        let stats = BakeStats {
            samples: 3,
            rays: 768,
            seconds: 0.1,
            max_distance: 2.0,
            std_error: 0.03,
            mean_std_error: 0.02,
        };
        let w = constant_warning(&[0.0; 3], &stats).unwrap();
        assert!(
            w.contains("0.000") && w.contains("no ray met the mesh"),
            "{w}"
        );
        let w = constant_warning(&[1.0; 3], &stats).unwrap();
        assert!(w.contains("larger"), "{w}");
        assert!(constant_warning(&[0.2, 0.5, 0.9], &stats).is_none());
        assert!(constant_warning(&[], &stats).is_none());
    }
}
