//! The diffuse transmittance of a medium through a slab, relative to its reflectance: Jensen's
//! dipole beyond a distance and Donner and Jensen's multipole through a slab, in f64 (the CPU
//! math behind the tables of screen-space SSS transmission, `features::sss::transmission`,
//! and the twin of glsl/common/sss_transmission.glsl; `crate::reference::transmission` adds
//! the per-light term and tests them).

use super::layered::Dipole;

/// `sum_{z = z_r, z_v} z e^(-sigma_tr d) / d`, `d = sqrt(a^2 + z^2)` (glsl/embed/lucent_terms.glsl
/// `lucent_dipole_beyond_sum`): the dipole's light diffusing out farther than `a` from its entry is
/// `alpha' / 2` times it ([`Dipole::transmitted_beyond`]). Lengths in the dipole's unit.
pub fn beyond_sum(dipole: &Dipole, a: f64) -> f64 {
    let term = |z: f64| {
        let d = (a * a + z * z).sqrt();
        // z / d <= 1 and e^-x of a large x is 0; an infinite a transmits nothing.
        if d.is_finite() {
            z / d * (-dipole.sigma_tr * d).exp()
        } else {
            0.0
        }
    };
    term(dipole.z_r) + term(dipole.z_v)
}

/// One row of the multipole's sources summed over every image (glsl `multipole_row`): `sum_i
/// sign(x - i P) e^(-sigma |x - i P|)` for `|x| < P`, `sign(x) e^(-sigma |x|) (1 - e^(-sigma (P -
/// 2|x|))) / (1 - e^(-sigma P))`, its limit `(P - 2|x|) / P` where `sigma P < 1e-6`.
fn multipole_row(sigma: f64, x: f64, period: f64) -> f64 {
    let ax = x.abs().min(period);
    let ratio = if sigma * period < 1e-6 {
        (period - 2.0 * ax) / period
    } else {
        (-sigma * (period - 2.0 * ax)).exp_m1() / (-sigma * period).exp_m1().min(-1e-300)
    };
    // GLSL's sign(0) is 0.
    let sign = if x == 0.0 { 0.0 } else { x.signum() };
    sign * (-sigma * ax).exp() * ratio
}

/// Donner and Jensen's (2005) multipole through a slab of thickness `a` (glsl
/// `lucent_multipole_slab_sum`), every image summed in closed form: with `z_b = (z_v - z_r) / 2` and
/// `P = 2 (a + 2 z_b)`, real sources at `i P + z_r`, virtual ones at `i P - z_r - 2 z_b`:
/// `sum_i sign(a - z_ri) e^(-sigma_tr |a - z_ri|) - sign(a - z_vi) e^(-sigma_tr |a - z_vi|)`;
/// the slab's total diffuse transmittance is `alpha' / 2` times it. Negative for slabs that
/// do not hold the real source (`a < z_r`).
pub fn multipole_sum(dipole: &Dipole, a: f64) -> f64 {
    let boundaries = dipole.z_v - dipole.z_r;
    let period = 2.0 * (a + boundaries);
    multipole_row(dipole.sigma_tr, a - dipole.z_r, period)
        - multipole_row(dipole.sigma_tr, a + dipole.z_r + boundaries, period)
}

/// The largest transmittance [`transmittance`] returns for `dipole`: `1 / R_d` (the slab lets
/// through at most all the light; `R_d = Tb(0)`), at most 1000 (a medium that scatters
/// nothing has `R_d = 0`; its albedo then zeroes the light).
pub fn most(dipole: &Dipole) -> f64 {
    let rd = dipole.transmitted_beyond(0.0);
    if rd > 1e-3 {
        1.0 / rd
    } else {
        1e3
    }
}

/// The medium's diffuse transmittance through `a` (its unit), relative to its total diffuse
/// reflectance (glsl `sss_transmittance`, `crate::features::sss::transmission` says why):
/// `max(multipole, dipole beyond a) / (dipole beyond 0)`, in `[0, most]`; 1 at `a = 0` for a
/// medium that scatters (the multipole is negative there), not for a pure absorber, whose
/// albedo (`R_d = 0`) zeroes the light anyway. Written
/// as the ratio of sums, so a medium that scatters nothing (`alpha' = 0`) still has a finite
/// shape: its albedo, `R_d = 0`, is what zeroes its light. The sum at 0 is at least
/// `e^-sqrt(3)` (`crate::features::sss::transmission::SssTransmission::rows`).
pub fn transmittance(dipole: &Dipole, a: f64) -> f64 {
    let a = a.max(0.0);
    let through = beyond_sum(dipole, a).max(multipole_sum(dipole, a));
    // An infinite a: the multipole's period is infinite too (NaN terms); nothing crosses it.
    if !through.is_finite() {
        return 0.0;
    }
    (through / beyond_sum(dipole, 0.0)).clamp(0.0, most(dipole))
}

/// The medium's transmitted light through `a` relative to its albedo (the white-sky albedo a
/// material with a medium takes, [`crate::scene::layered::LayeredMedium::white_sky_albedo`]),
/// not to its `R_d`: `T(a) R_d / A`, in `[0, 1 / A]` (at most 1000, for a medium that reflects
/// nothing), so that the albedo the diffuse light carries, `A`, gives back the model's light.
/// What the GPU table holds (glsl `sss_transmittance`).
pub fn transmittance_over_albedo(dipole: &Dipole, a: f64, medium_albedo: f64) -> f64 {
    let albedo = medium_albedo.max(1e-3);
    (transmittance(dipole, a) * dipole.transmitted_beyond(0.0) / albedo).clamp(0.0, 1.0 / albedo)
}
