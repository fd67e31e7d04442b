//! Diffusion profiles as sums of Gaussians (d'Eon and Luebke): evaluating one at a radius,
//! normalising its weights, and fitting a sum of Gaussians to any radial profile (how the
//! `marble` preset was made from Jensen's dipole, and how `--sss-gaussians N` refits a profile
//! with fewer blur steps). CPU math of the materials; the f64 reference and the frame both use
//! it.

use std::f64::consts::PI;

use glam::DVec3;

use super::material::{Gaussian, SssProfile};
use crate::Result;

/// Each Gaussian's weight, normalised per channel so the weights sum to 1 (as the blurs
/// normalise them); a channel whose weights are all 0 keeps its light where it is, which the
/// first Gaussian then takes whole.
pub fn normalized_weights(profile: &SssProfile) -> Vec<DVec3> {
    let total = profile
        .gaussians
        .iter()
        .fold(DVec3::ZERO, |acc, g| acc + g.weight.as_dvec3());
    profile
        .gaussians
        .iter()
        .enumerate()
        .map(|(i, g)| {
            DVec3::select(
                total.cmpgt(DVec3::ZERO),
                g.weight.as_dvec3() / total.max(DVec3::splat(1e-300)),
                DVec3::splat(if i == 0 { 1.0 } else { 0.0 }),
            )
        })
        .collect()
}

/// `R(r)` of a profile at `r_mm` millimetres, per channel, with [`normalized_weights`].
pub fn profile_value(profile: &SssProfile, r_mm: f64) -> DVec3 {
    profile
        .gaussians
        .iter()
        .zip(normalized_weights(profile))
        .fold(DVec3::ZERO, |sum, (g, w)| {
            let v = f64::from(g.variance).max(1e-12);
            sum + w * ((-r_mm * r_mm / (2.0 * v)).exp() / (2.0 * std::f64::consts::PI * v))
        })
}

/// The normalised 2D Gaussian of variance `v` at radius `r`: exp(-r²/2v) / (2πv).
pub fn gaussian(v: f64, r: f64) -> f64 {
    (-r * r / (2.0 * v)).exp() / (2.0 * PI * v)
}

/// Non-negative weights w minimising ∫ (profile(r) - Σ w_i G(v_i, r))² 2πr dr over [0, r_max]
/// (area-weighted, as the profile is applied over the plane). Returns the weights and the
/// relative L2 error of the fit.
pub fn fit_sum_of_gaussians(
    variances: &[f64],
    profile: impl Fn(f64) -> f64,
    r_max: f64,
) -> (Vec<f64>, f64) {
    let n = variances.len();
    let samples = 4000;
    let dr = r_max / samples as f64;
    // Normal equations H w = b by midpoint quadrature.
    let mut h = vec![vec![0.0; n]; n];
    let mut b = vec![0.0; n];
    let mut norm = 0.0;
    for s in 0..samples {
        let r = (s as f64 + 0.5) * dr;
        let area = 2.0 * PI * r * dr;
        let p = profile(r);
        let g: Vec<f64> = variances.iter().map(|&v| gaussian(v, r)).collect();
        for i in 0..n {
            b[i] += g[i] * p * area;
            for j in 0..n {
                h[i][j] += g[i] * g[j] * area;
            }
        }
        norm += p * p * area;
    }
    // Projected coordinate descent: the problem is a convex quadratic with w >= 0.
    let mut w = vec![0.0; n];
    for _ in 0..20_000 {
        for i in 0..n {
            let grad: f64 = (0..n).map(|j| h[i][j] * w[j]).sum::<f64>() - b[i];
            if h[i][i] > 0.0 {
                w[i] = (w[i] - grad / h[i][i]).max(0.0);
            }
        }
    }
    let residual: f64 = {
        let mut e = norm;
        for i in 0..n {
            e -= 2.0 * w[i] * b[i];
            for j in 0..n {
                e += w[i] * w[j] * h[i][j];
            }
        }
        e.max(0.0)
    };
    (w, (residual / norm.max(1e-300)).sqrt())
}

/// `profile` refitted with `n` Gaussians (1 to 8): variances spaced geometrically between the
/// profile's narrowest and widest, weights per channel by non-negative least squares against
/// the profile's radial shape (area-weighted, out to 4 sigma of the widest), normalised per
/// channel. Returns it with the fit's relative L2 error per channel. `n` at or above the
/// profile's own count returns the profile unchanged (error 0).
pub fn fit_profile(profile: &SssProfile, n: usize) -> Result<(SssProfile, [f64; 3])> {
    if !(1..=8).contains(&n) {
        return Err(crate::LucentError::InvalidInput(format!(
            "--sss-gaussians {n}: 1 to 8 Gaussians are supported"
        )));
    }
    if n >= profile.gaussians.len() {
        return Ok((profile.clone(), [0.0; 3]));
    }
    let variances: Vec<f64> = profile
        .gaussians
        .iter()
        .map(|g| f64::from(g.variance).max(1e-9))
        .collect();
    let (lo, hi) = variances
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let fitted: Vec<f64> = (0..n)
        .map(|k| {
            if n == 1 {
                (lo * hi).sqrt()
            } else {
                (lo.ln() + (hi.ln() - lo.ln()) * k as f64 / (n - 1) as f64).exp()
            }
        })
        .collect();
    let r_max = 4.0 * hi.sqrt();
    let mut weights = vec![glam::Vec3::ZERO; n];
    let mut errors = [0.0; 3];
    for c in 0..3 {
        let target = |r: f64| profile_value(profile, r)[c];
        let (w, err) = fit_sum_of_gaussians(&fitted, target, r_max);
        let total: f64 = w.iter().sum();
        for (i, wi) in w.iter().enumerate() {
            weights[i][c] = if total > 0.0 {
                (wi / total) as f32
            } else {
                0.0
            };
        }
        errors[c] = err;
    }
    let refit = SssProfile {
        name: format!("{} ({n} Gaussians)", profile.name),
        gaussians: fitted
            .iter()
            .zip(weights)
            .map(|(&v, weight)| Gaussian {
                variance: v as f32,
                weight,
            })
            .collect(),
        units_per_mm: profile.units_per_mm,
        blur: profile.blur.clone(),
    };
    Ok((refit, errors))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitting_fewer_gaussians_reports_a_growing_error() {
        let skin = SssProfile::preset("skin").unwrap();
        let (same, e) = fit_profile(&skin, 6).unwrap();
        assert_eq!(same, skin);
        assert_eq!(e, [0.0; 3]);
        let mut previous = 0.0;
        for n in [4, 3, 2, 1] {
            let (fit, e) = fit_profile(&skin, n).unwrap();
            assert_eq!(fit.gaussians.len(), n);
            fit.validate().unwrap();
            let worst = e.iter().fold(0.0f64, |a, &b| a.max(b));
            assert!(worst.is_finite() && worst >= previous - 1e-9, "{n}: {e:?}");
            previous = worst;
            for c in 0..3 {
                let total: f32 = fit.gaussians.iter().map(|g| g.weight[c]).sum();
                assert!((total - 1.0).abs() < 1e-4, "{n} channel {c}: {total}");
            }
        }
        // Four Gaussians (the thesis's count) fit d'Eon's six within a few percent.
        let (_, e4) = fit_profile(&skin, 4).unwrap();
        assert!(e4.iter().all(|&e| e < 0.05), "{e4:?}");
        assert!(fit_profile(&skin, 0).is_err() && fit_profile(&skin, 9).is_err());
    }
}
