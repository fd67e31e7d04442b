//! Jensen et al.'s dipole diffusion profile (2001) in f64, and fitting a sum of Gaussians to a
//! radial profile. Used to derive and check the `marble` SSS preset; the multiple-scattering
//! technique (Li et al.) evaluates the same dipole.

use std::f64::consts::PI;

use crate::scene::profile::fit_sum_of_gaussians;

/// Diffuse Fresnel reflectance of a boundary with relative index `eta` (Jensen's fit).
pub fn fresnel_diffuse_reflectance(eta: f64) -> f64 {
    -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
}

/// Diffuse reflectance R_d(r) of the dipole at distance `r` (mm) for reduced scattering
/// `sigma_s_prime` and absorption `sigma_a` (1/mm) and relative index `eta`.
pub fn dipole_rd(r: f64, sigma_s_prime: f64, sigma_a: f64, eta: f64) -> f64 {
    let sigma_t_prime = (sigma_a + sigma_s_prime).max(1e-12);
    let albedo = sigma_s_prime / sigma_t_prime;
    let sigma_tr = (3.0 * sigma_a * sigma_t_prime).sqrt();
    let fdr = fresnel_diffuse_reflectance(eta);
    let a = (1.0 + fdr) / (1.0 - fdr);
    let zr = 1.0 / sigma_t_prime;
    let zv = zr * (1.0 + 4.0 * a / 3.0);
    let dr = (r * r + zr * zr).sqrt();
    let dv = (r * r + zv * zv).sqrt();
    let term = |z: f64, d: f64| z * (sigma_tr * d + 1.0) * (-sigma_tr * d).exp() / (d * d * d);
    albedo / (4.0 * PI) * (term(zr, dr) + term(zv, dv))
}

/// Jensen et al.'s measured marble: reduced scattering and absorption per channel (1/mm), η.
pub const MARBLE_SIGMA_S_PRIME: [f64; 3] = [2.19, 2.62, 3.00];
/// Marble absorption (1/mm).
pub const MARBLE_SIGMA_A: [f64; 3] = [0.0021, 0.0041, 0.0071];
/// Marble relative index of refraction.
pub const MARBLE_ETA: f64 = 1.5;

/// Fits the skin variances to the marble dipole per channel, each channel's weights normalised
/// to sum to 1. Returns (weights per Gaussian as RGB, relative fit error per channel).
pub fn fit_marble(variances: &[f64]) -> (Vec<[f64; 3]>, [f64; 3]) {
    let mut weights = vec![[0.0; 3]; variances.len()];
    let mut errors = [0.0; 3];
    for c in 0..3 {
        let (w, err) = fit_sum_of_gaussians(
            variances,
            |r| dipole_rd(r, MARBLE_SIGMA_S_PRIME[c], MARBLE_SIGMA_A[c], MARBLE_ETA),
            10.0,
        );
        let sum: f64 = w.iter().sum();
        for (i, wi) in w.iter().enumerate() {
            weights[i][c] = if sum > 0.0 { wi / sum } else { 0.0 };
        }
        errors[c] = err;
    }
    (weights, errors)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::profile::gaussian;

    #[test]
    fn dipole_is_positive_decreasing_and_finite() {
        let mut prev = f64::INFINITY;
        for i in 0..100 {
            let r = i as f64 * 0.1;
            let v = dipole_rd(r, 2.19, 0.0021, 1.5);
            assert!(v.is_finite() && v > 0.0 && v <= prev, "r={r} v={v}");
            prev = v;
        }
    }

    #[test]
    fn marble_preset_matches_its_fit() {
        let table = crate::scene::material::MARBLE_GAUSSIANS;
        let variances: Vec<f64> = table.iter().map(|g| f64::from(g.0)).collect();
        let (weights, errors) = fit_marble(&variances);
        for (row, fitted) in table.iter().zip(&weights) {
            for c in 0..3 {
                assert!(
                    (f64::from(row.1[c]) - fitted[c]).abs() < 1e-3,
                    "preset {:?} vs fit {fitted:?}",
                    row.1
                );
            }
        }
        for e in errors {
            assert!(e < 0.025, "fit error {e}");
        }
    }

    #[test]
    fn fitting_a_gaussian_recovers_it() {
        let variances = [0.1, 1.0, 4.0];
        let (w, err) = fit_sum_of_gaussians(&variances, |r| 0.7 * gaussian(1.0, r), 10.0);
        assert!(
            (w[1] - 0.7).abs() < 1e-3 && w[0] < 1e-3 && w[2] < 1e-3,
            "{w:?}"
        );
        assert!(err < 1e-3);
    }
}
