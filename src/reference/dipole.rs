//! Jensen et al.'s dipole diffusion profile (2001) in f64, and fitting a sum of Gaussians to a
//! radial profile. Used to derive and check the `marble` SSS preset; the multiple-scattering
//! technique (Li et al.) evaluates the same dipole.
//!
//! The dipole's constants are the medium's, derived where the scene derives the GPU's
//! ([`crate::scene::layered::dipole_constants`]); this module evaluates the profile `Rd(r)`
//! and its integrals from them.

use std::f64::consts::PI;

use crate::scene::layered::{dipole_constants, Dipole};
use crate::scene::profile::fit_sum_of_gaussians;

impl Dipole {
    /// Jensen's diffuse reflectance Rd(r) at distance `r` from the point of incidence:
    /// `alpha'/(4 pi) [z_r (sigma_tr d_r + 1) e^(-sigma_tr d_r)/d_r^3 + z_v (sigma_tr d_v + 1)
    /// e^(-sigma_tr d_v)/d_v^3]`, each exponential with its own distance (Li et al.'s eq. 12
    /// writes `d_v` in both). `d_r >= z_r > 0`, so r = 0 is finite.
    pub fn rd(&self, r: f64) -> f64 {
        let r2 = r * r;
        let dr = (r2 + self.z_r * self.z_r).sqrt();
        let dv = (r2 + self.z_v * self.z_v).sqrt();
        let term = |z: f64, d: f64| {
            let e = self.sigma_tr * d;
            // e^-e underflows to 0 for e > 745 and (e + 1) e^-e is then 0, not NaN.
            z * (e + 1.0) * (-e).exp() / (d * d * d)
        };
        self.alpha_prime / (4.0 * PI) * (term(self.z_r, dr) + term(self.z_v, dv))
    }

    /// `2 pi ∫_0^a Rd(r) r dr` in closed form (the reflectance within a disc of radius `a`):
    /// `(alpha'/2) sum_{z = z_r, z_v} [e^(-sigma_tr z) - z e^(-sigma_tr d(a)) / d(a)]`, `d(a) =
    /// sqrt(a^2 + z^2)`, since `(sigma_tr d + 1) e^(-sigma_tr d) / d^2` is the derivative of
    /// `-e^(-sigma_tr d) / d`. Used for the peak of Rd that a surface sample cannot resolve.
    pub fn reflectance_within(&self, a: f64) -> f64 {
        // Both exponentials only shrink: never NaN for finite inputs.
        let part = |z: f64| ((-self.sigma_tr * z).exp() - self.beyond(z, a)).max(0.0);
        0.5 * self.alpha_prime * (part(self.z_r) + part(self.z_v))
    }

    /// One source's share (depth `z`) of the light that leaves farther than `a` from its
    /// entry, before the `alpha'/2`: `z e^(-sigma_tr d) / d` with `d = sqrt(a^2 + z^2)`.
    fn beyond(&self, z: f64, a: f64) -> f64 {
        let d = (a * a + z * z).sqrt();
        // z / d <= 1 and e^-x of a large x is 0: finite for every finite a.
        if d.is_finite() {
            z / d * (-self.sigma_tr * d).exp()
        } else {
            0.0
        }
    }

    /// The part of the light that entered which diffuses out farther than `a` from where it
    /// entered, `2 pi ∫_a^∞ Rd(r) r dr = (alpha'/2) Σ_{z = z_r, z_v} z e^(-sigma_tr d(a)) /
    /// d(a)` (`R_d` less [`Dipole::reflectance_within`] `a`): lucent's diffuse transmission
    /// through a thickness `a` (the light that entered on an object's far side and crossed it
    /// by diffusion; HDRP reads its profile at the thickness the same way). `R_d` at `a = 0`.
    pub fn transmitted_beyond(&self, a: f64) -> f64 {
        0.5 * self.alpha_prime * (self.beyond(self.z_r, a) + self.beyond(self.z_v, a))
    }

    /// Total diffuse reflectance `R_d = 2 pi ∫ Rd(r) r dr` in closed form:
    /// `(alpha'/2) (1 + e^(-4/3 A sqrt(3(1 - alpha')))) e^(-sqrt(3(1 - alpha')))`.
    pub fn total_reflectance(&self) -> f64 {
        let s = (3.0 * (1.0 - self.alpha_prime).max(0.0)).sqrt();
        0.5 * self.alpha_prime * (1.0 + (-4.0 / 3.0 * self.a * s).exp()) * (-s).exp()
    }
}

/// Diffuse reflectance R_d(r) of the dipole at distance `r` (mm) for reduced scattering
/// `sigma_s_prime` and absorption `sigma_a` (1/mm) and relative index `eta`.
pub fn dipole_rd(r: f64, sigma_s_prime: f64, sigma_a: f64, eta: f64) -> f64 {
    dipole_constants(sigma_s_prime, sigma_a, eta).rd(r)
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
    fn what_diffuses_beyond_a_is_the_total_less_what_stays_within_a() {
        for &(sp, sa, eta) in &[(2.19, 0.0021, 1.5), (0.74, 0.032, 1.0), (1.0, 1.0, 1.3)] {
            let d = dipole_constants(sp, sa, eta);
            assert!((d.transmitted_beyond(0.0) - d.total_reflectance()).abs() < 1e-12);
            let mut previous = f64::INFINITY;
            for a in [0.0, 0.01, 0.1, 1.0, 4.0, 40.0, 1e6] {
                let beyond = d.transmitted_beyond(a);
                let sum = beyond + d.reflectance_within(a);
                assert!(
                    (sum - d.total_reflectance()).abs() < 1e-9,
                    "{sp} {sa} {eta} {a}"
                );
                assert!(beyond.is_finite() && beyond >= 0.0 && beyond <= previous);
                previous = beyond;
            }
        }
    }

    #[test]
    fn rd_integrates_to_the_total_diffuse_reflectance() {
        // 2 pi ∫ Rd(r) r dr by Simpson's rule on r = z_r sinh(u) (dense near 0, reaching
        // thousands of mean free paths), against the closed form.
        for &(sp, sa, eta) in &[
            (2.19, 0.0021, 1.5),
            (0.74, 0.48, 1.3),
            (1.0, 1.0, 1.0),
            (7.38, 0.0163, 1.3),
        ] {
            let d = dipole_constants(sp, sa, eta);
            let n = 20000;
            let u_max = (1e5_f64).asinh();
            let h = u_max / n as f64;
            let f = |u: f64| {
                let r = d.z_r * u.sinh();
                d.rd(r) * r * d.z_r * u.cosh()
            };
            let mut sum = f(0.0) + f(u_max);
            for i in 1..n {
                sum += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
            }
            let integral = 2.0 * PI * sum * h / 3.0;
            let closed = d.total_reflectance();
            assert!((d.reflectance_within(f64::INFINITY) - closed).abs() < 1e-12 * closed.max(1.0));
            assert!(d.reflectance_within(0.0).abs() < 1e-15);
            assert!(
                (integral - closed).abs() < 2e-4 * closed.max(1e-3),
                "sp {sp} sa {sa} eta {eta}: {integral} vs {closed}"
            );
        }
    }

    #[test]
    fn rd_is_finite_at_the_extremes() {
        for sp in [0.0, 1e-9, 1.0, 1e6] {
            for sa in [0.0, 1e-9, 1.0, 1e6] {
                for eta in [1.0, 1.3, 0.5] {
                    let d = dipole_constants(sp, sa, eta);
                    for r in [0.0, 1e-9, 1.0, 1e6] {
                        let v = d.rd(r);
                        assert!(v.is_finite() && v >= 0.0, "{sp} {sa} {eta} {r}: {v}");
                    }
                    assert!(d.total_reflectance().is_finite());
                }
            }
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
