//! The kernels of the two-pass blurs, pre-integrated on the CPU from each profile.
//!
//! **Separable** (Jimenez et al. 2015, the iryoku reference's `SeparableSSS`): one 1-D kernel of
//! N samples (11, 17 or 25) per profile, applied horizontally then vertically. Samples sit at
//! `range * sign(t) * t^2` for `t` evenly spaced in [-1, 1] (denser near the centre, where a sum
//! of Gaussians is sharpest), `range` three standard deviations of the profile's widest
//! Gaussian; each sample weighs the 1-D kernel function times the length of the interval it
//! stands for (half-way to its neighbours), normalised per channel. The kernel is in
//! millimetres and the GPU table in world units: the shader scales it by the pixel's depth.
//!
//! A sum of Gaussians is not separable: `K(x) K(y)` only approximates `R(sqrt(x^2 + y^2))`. Two
//! 1-D functions are offered and measured ([`KernelShape`], [`separability_error`]): the profile
//! along a line (Jimenez's choice) and the sum of the Gaussians' 1-D marginals.
//!
//! **Bilateral** (the two-pass LEAN blur) weighs each tap by the whole profile at the tap's 3D
//! distance: its entries in the same table are the profile's 1-D form tabulated at
//! `MAX_KERNEL_SAMPLES` distances `reach * u^2` (denser near the centre, where the narrow
//! Gaussians are), which the shader interpolates: six exponentials per tap cost more than every
//! fetch of the pass on a CPU driver (measured: the horizontal pass 112 ms with them, 47 ms
//! with one).

use glam::DVec3;

use super::{SssProfiles, MAX_SSS_PROFILES};
use crate::scene::material::SssProfile;

/// The sample counts the separable kernel is built with (`--sss-samples`).
pub const SAMPLE_COUNTS: [u32; 3] = [11, 17, 25];
/// Most samples of a kernel.
pub const MAX_KERNEL_SAMPLES: usize = 25;
/// Default samples: measured in docs/sss.md ("Two passes").
pub const DEFAULT_SAMPLES: u32 = 17;

/// Which 1-D function of the profile the separable kernel samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelShape {
    /// The 2-D profile along a line through its centre, `R(|x|)`, normalised (Jimenez 2015).
    Line,
    /// The sum of each Gaussian's 1-D marginal, `sum w_i g_i(x)`: exact for one Gaussian, and
    /// it keeps each Gaussian's share of the energy.
    Marginal,
}

/// One sample: offset in millimetres and RGB weight (each channel's weights sum to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KernelTap {
    /// Offset from the centre, mm.
    pub offset_mm: f64,
    /// Weight per channel.
    pub weight: DVec3,
}

/// The profile's reach: three standard deviations of its widest Gaussian, mm.
pub fn range_mm(profile: &SssProfile) -> f64 {
    let widest = profile
        .gaussians
        .iter()
        .fold(0.0f64, |m, g| m.max(f64::from(g.variance)));
    3.0 * widest.max(0.0).sqrt()
}

/// The sample offsets (mm) of an N-sample kernel of `range` mm: `range * sign(t) * t^2`.
pub fn sample_offsets(range: f64, samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|k| {
            let t = if samples > 1 {
                -1.0 + 2.0 * k as f64 / (samples - 1) as f64
            } else {
                0.0
            };
            range * t.signum() * t * t
        })
        .collect()
}

/// The 1-D kernel function of `shape` at `x` mm, per channel, with the profile's weights
/// normalised per channel (a channel whose weights are all 0 is a delta: its light stays).
fn kernel_function(profile: &SssProfile, shape: KernelShape, x: f64) -> DVec3 {
    let total = profile
        .gaussians
        .iter()
        .fold(DVec3::ZERO, |acc, g| acc + g.weight.as_dvec3());
    profile.gaussians.iter().fold(DVec3::ZERO, |acc, g| {
        let v = f64::from(g.variance).max(1e-12);
        let w = g.weight.as_dvec3() / total.max(DVec3::splat(1e-300));
        let g1 = (-x * x / (2.0 * v)).exp() / (2.0 * std::f64::consts::PI * v).sqrt();
        acc + w * match shape {
            // The 2-D Gaussian at (x, 0) is g1(x) / sqrt(2 pi v).
            KernelShape::Line => g1 / (2.0 * std::f64::consts::PI * v).sqrt(),
            KernelShape::Marginal => g1,
        }
    })
}

/// The N-sample separable kernel of `profile` (see the module docs), centre sample included.
pub fn separable_kernel(
    profile: &SssProfile,
    samples: usize,
    shape: KernelShape,
) -> Vec<KernelTap> {
    let samples = samples.clamp(1, MAX_KERNEL_SAMPLES);
    let offsets = sample_offsets(range_mm(profile), samples);
    let n = offsets.len();
    let mut taps: Vec<KernelTap> = (0..n)
        .map(|k| {
            // The interval the sample stands for: half-way to each neighbour.
            let lo = if k == 0 {
                offsets[0]
            } else {
                0.5 * (offsets[k - 1] + offsets[k])
            };
            let hi = if k + 1 == n {
                offsets[n - 1]
            } else {
                0.5 * (offsets[k] + offsets[k + 1])
            };
            let width = (hi - lo).max(0.0);
            KernelTap {
                offset_mm: offsets[k],
                weight: kernel_function(profile, shape, offsets[k]) * width,
            }
        })
        .collect();
    let total = taps.iter().fold(DVec3::ZERO, |acc, t| acc + t.weight);
    let centre = n / 2;
    for c in 0..3 {
        if total[c] > 0.0 {
            for t in &mut taps {
                t.weight[c] /= total[c];
            }
        } else {
            // A degenerate profile (zero range): all weight on the centre sample.
            for (k, t) in taps.iter_mut().enumerate() {
                t.weight[c] = if k == centre { 1.0 } else { 0.0 };
            }
        }
    }
    taps
}

/// How far the separable filter `K(x) K(y)` of a kernel shape is from the 2-D profile, per
/// channel: the L1 distance `integral |K(x) K(y) - R(x, y)| dx dy` of the two normalised
/// densities (0: identical, 2: disjoint), on a grid as dense near the centre as the samples
/// are (where a sum of Gaussians is sharpest). It measures the shape's separability; what the
/// N samples cost on top is measured in the image (`lucent report sss`).
pub fn separability_error(profile: &SssProfile, shape: KernelShape) -> [f64; 3] {
    let range = range_mm(profile).max(1e-9);
    let cells = 400usize;
    // x = range * t |t|: dx = 2 range |t| dt.
    let grid: Vec<(f64, f64)> = (0..cells)
        .map(|i| {
            let t = -1.0 + (i as f64 + 0.5) * 2.0 / cells as f64;
            (
                range * t * t.abs(),
                2.0 * range * t.abs() * 2.0 / cells as f64,
            )
        })
        .collect();
    // K normalised over the grid per channel.
    let k: Vec<DVec3> = grid
        .iter()
        .map(|&(x, _)| kernel_function(profile, shape, x))
        .collect();
    let k_total = k
        .iter()
        .zip(&grid)
        .fold(DVec3::ZERO, |acc, (v, &(_, dx))| acc + *v * dx);
    let k: Vec<DVec3> = k
        .iter()
        .map(|v| *v / k_total.max(DVec3::splat(1e-300)))
        .collect();
    let mut exact_total = DVec3::ZERO;
    let mut exact = Vec::with_capacity(cells * cells);
    for &(x, dx) in &grid {
        for &(y, dy) in &grid {
            let r = crate::scene::profile::profile_value(profile, (x * x + y * y).sqrt());
            exact_total += r * dx * dy;
            exact.push(r);
        }
    }
    let mut diff = DVec3::ZERO;
    for (i, &(_, dx)) in grid.iter().enumerate() {
        for (j, &(_, dy)) in grid.iter().enumerate() {
            let r = exact[i * cells + j] / exact_total.max(DVec3::splat(1e-300));
            diff += (k[i] * k[j] - r).abs() * dx * dy;
        }
    }
    std::array::from_fn(|c| diff[c])
}

/// The two-pass blurs' kernel table uniform block (std140, glsl/common/sss.glsl
/// `SssKernels`), indexed by profile ID like [`super::ProfileTableGpu`]: a separable profile's
/// kernel, or a bilateral profile's tabulated weights.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct KernelTableGpu {
    /// Per ID: x the sample count, y one over the kernel's reach in world units (separable:
    /// the follow-surface depth term, a depth step as deep as the kernel is wide is a full
    /// edge), z the kernel's reach in world units, w (bilateral) one over the falloff table's
    /// reach in world units.
    pub info: [[f32; 4]; MAX_SSS_PROFILES],
    /// Per ID and sample (`id * MAX_KERNEL_SAMPLES + k`): RGB weight and offset in world units.
    pub taps: [[f32; 4]; MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES],
    /// Per bilateral ID and entry (`id * FALLOFF_ENTRIES + k`): the profile's 1-D form per
    /// channel (per world unit) at distance `reach * (k / (FALLOFF_ENTRIES - 1))^2`, and that
    /// distance.
    pub falloff: [[f32; 4]; MAX_SSS_PROFILES * FALLOFF_ENTRIES],
    /// Per bilateral ID and sample: one over the falloff table's value at the sample's offset
    /// (RGB; 0 where the table holds 0), so a tap needs one table lookup, at its 3D distance.
    pub inverse_falloff: [[f32; 4]; MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES],
}

/// Entries of a bilateral profile's falloff table (glsl/common/sss.glsl `FALLOFF_ENTRIES`).
pub const FALLOFF_ENTRIES: usize = 25;

/// Bytes of [`KernelTableGpu`] (the per-frame buffer's kernel region).
pub const KERNEL_TABLE_BYTES: u64 = std::mem::size_of::<KernelTableGpu>() as u64;

/// How far a bilateral profile's table reaches, mm: the kernel's reach (three standard
/// deviations of its widest Gaussian) times 1.5, since a tap's 3D distance adds the depth
/// difference to its offset.
pub fn bilateral_reach_mm(profile: &SssProfile) -> f64 {
    1.5 * range_mm(profile)
}

/// The kernel table of `profiles`: for two-pass profiles their `samples`-sample kernels of
/// `shape`, and for bilateral profiles also their tabulated falloff (the weight a tap gets at
/// its 3D distance, relative to the weight at its screen offset).
pub fn kernel_table(profiles: &SssProfiles, samples: u32, shape: KernelShape) -> KernelTableGpu {
    let mut table = KernelTableGpu {
        info: [[0.0; 4]; MAX_SSS_PROFILES],
        taps: [[0.0; 4]; MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES],
        falloff: [[0.0; 4]; MAX_SSS_PROFILES * FALLOFF_ENTRIES],
        inverse_falloff: [[0.0; 4]; MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES],
    };
    for (i, (profile, blur)) in profiles.profiles.iter().enumerate() {
        // Iterative chains blur per Gaussian and read no kernel.
        if blur.iterative() {
            continue;
        }
        let id = i + 1;
        let units = f64::from(profile.units_per_mm);
        let kernel = separable_kernel(profile, samples as usize, shape);
        let reach = (range_mm(profile) * units) as f32;
        let falloff_reach_mm = bilateral_reach_mm(profile);
        let falloff_reach = (falloff_reach_mm * units) as f32;
        table.info[id] = [
            kernel.len() as f32,
            // Guarded: a zero-width profile never blurs, any depth step is an edge.
            1.0 / reach.max(1e-9),
            reach,
            1.0 / falloff_reach.max(1e-9),
        ];
        for (k, tap) in kernel.iter().enumerate() {
            table.taps[id * MAX_KERNEL_SAMPLES + k] = [
                tap.weight.x as f32,
                tap.weight.y as f32,
                tap.weight.z as f32,
                (tap.offset_mm * units) as f32,
            ];
        }
        if blur.bilateral() {
            let last = (FALLOFF_ENTRIES - 1) as f64;
            for k in 0..FALLOFF_ENTRIES {
                let u = k as f64 / last;
                let d_mm = falloff_reach_mm * u * u;
                // Per world unit of distance: the mm density over units per mm.
                let w = kernel_function(profile, KernelShape::Marginal, d_mm) / units;
                table.falloff[id * FALLOFF_ENTRIES + k] =
                    [w.x as f32, w.y as f32, w.z as f32, (d_mm * units) as f32];
            }
            for (k, tap) in kernel.iter().enumerate() {
                let at_offset = falloff_at(
                    &table.falloff[id * FALLOFF_ENTRIES..][..FALLOFF_ENTRIES],
                    (tap.offset_mm * units).abs() as f32 * table.info[id][3],
                );
                // Guarded: where the table holds (next to) nothing the tap gets no weight
                // rather than an Inf.
                let inverse = at_offset.map(|v| if v > 1e-30 { 1.0 / v } else { 0.0 });
                table.inverse_falloff[id * MAX_KERNEL_SAMPLES + k] =
                    [inverse[0], inverse[1], inverse[2], 0.0];
            }
        }
    }
    table
}

/// A falloff table's value at `x` (distance over the table's reach), as the shader
/// interpolates it (glsl/common/sss.glsl `sss_falloff`): entries at `x = u^2`, 0 past the end.
fn falloff_at(entries: &[[f32; 4]], x: f32) -> [f32; 3] {
    if !(0.0..1.0).contains(&x) {
        return [0.0; 3];
    }
    let last = entries.len() - 1;
    let u = x.sqrt() * last as f32;
    let i = (u as usize).min(last - 1);
    let t = u - i as f32;
    let (a, b) = (entries[i], entries[i + 1]);
    [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_sum_to_one_are_symmetric_and_exact_for_one_gaussian() {
        let skin = SssProfile::preset("skin").unwrap();
        for samples in SAMPLE_COUNTS {
            for shape in [KernelShape::Line, KernelShape::Marginal] {
                let k = separable_kernel(&skin, samples as usize, shape);
                assert_eq!(k.len(), samples as usize);
                let total = k.iter().fold(DVec3::ZERO, |a, t| a + t.weight);
                assert!((total - DVec3::ONE).abs().max_element() < 1e-12, "{total}");
                for (a, b) in k.iter().zip(k.iter().rev()) {
                    assert!((a.offset_mm + b.offset_mm).abs() < 1e-12);
                    assert!((a.weight - b.weight).abs().max_element() < 1e-12);
                }
                assert!(k
                    .iter()
                    .all(|t| t.weight.is_finite() && t.weight.min_element() >= 0.0));
            }
        }
        // One Gaussian is separable: only the sampling is left.
        let mut one = skin.clone();
        one.gaussians.truncate(1);
        one.gaussians[0].variance = 1.0;
        let e = separability_error(&one, KernelShape::Marginal);
        assert!(e.iter().all(|&e| e < 1e-3), "{e:?}");
        let e = separability_error(&one, KernelShape::Line);
        assert!(e.iter().all(|&e| e < 1e-3), "{e:?}");
    }

    #[test]
    #[ignore]
    fn print_separability() {
        for name in ["skin", "marble"] {
            let p = SssProfile::preset(name).unwrap();
            for shape in [KernelShape::Line, KernelShape::Marginal] {
                eprintln!("{name} {shape:?}: {:?}", separability_error(&p, shape));
            }
        }
    }

    #[test]
    fn degenerate_profiles_stay_finite() {
        let skin = SssProfile::preset("skin").unwrap();
        let mut flat = skin.clone();
        for g in &mut flat.gaussians {
            g.weight = glam::Vec3::ZERO;
        }
        let k = separable_kernel(&flat, 17, KernelShape::Line);
        assert!(k.iter().all(|t| t.weight.is_finite()));
        assert_eq!(
            k[8].weight,
            DVec3::ONE,
            "a channel without weights keeps its light"
        );
    }
}
