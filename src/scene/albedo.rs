//! The albedo of a medium: how much of the light falling on a flat, semi-infinite slab of it
//! from every direction (a white sky) comes back out, single and multiple scattering together.
//! It is the one number a Lambertian surface of the medium must have to reflect as much light
//! as the medium does, so it is the albedo `[material.medium]` derives
//! ([`crate::scene::material::Medium`]).
//!
//! Jensen's dipole `R_d` (`crate::reference::dipole`) is not it: it leaves out single scattering and,
//! being a diffusion approximation, underestimates media of moderate albedo. Against Monte
//! Carlo, skin1's `R_d` (0.547, 0.291, 0.161) is 13-34% below its white-sky albedo (0.625,
//! 0.385, 0.241); for a medium of albedo near 1 (marble) they differ by 2-3%.
//!
//! [`white_sky_albedo`] is exact for an index-matched boundary and isotropic scattering:
//! Chandrasekhar's H-function gives the plane albedo `r(mu0) = 1 - H(mu0) sqrt(1 - omega)`
//! (Chandrasekhar 1960, Radiative Transfer, ch. IV), whose cosine-weighted mean is
//! `1 - 2 sqrt(1 - omega) int_0^1 H(mu) mu dmu`. Anisotropic scattering enters through the
//! similarity relation (`omega = sigma_s' / (sigma_s' + sigma_a)`, the dipole's own), a
//! refracting boundary through Fresnel's transmittance in, at the refracted angle, and out,
//! of the intensity a white sky's reflection has (`r(mu)`, by reciprocity), with what the
//! boundary reflects back in returned again and again (an approximation: 4-7% above the
//! random walk at eta 1.3-1.4, where the dipole's `R_d` is 6-29% above it). The independent check,
//! in the tests, is `monte_carlo_white_sky_albedo`: a random walk with the true
//! Henyey-Greenstein phase function and exact Fresnel at the boundary.

/// Largest |g| accepted: HG and Schlick's phase functions peak like 1/(1 - |g|)^2, so |g| = 1
/// is a delta and 0.999 already a 4e6:1 peak (`scene::layered` re-exports it).
pub const MAX_ABS_G: f32 = 0.999;

/// Gauss-Legendre nodes on [0, 1]: enough that the H-function's moments are exact to 1e-9.
const NODES: usize = 32;

/// Gauss-Legendre nodes and weights of `n` points on [0, 1] (Newton's iteration on the
/// Legendre polynomial from Chebyshev's guesses).
fn gauss_legendre_unit(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = Vec::with_capacity(n);
    let mut weights = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            // P_n(x) and P_n'(x) by the three-term recurrence.
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
            }
            derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
            let step = p1 / derivative;
            x -= step;
            if step.abs() < 1e-15 {
                break;
            }
        }
        nodes.push(0.5 * (x + 1.0));
        weights.push(1.0 / ((1.0 - x * x) * derivative * derivative));
    }
    (nodes, weights)
}

/// Chandrasekhar's H-function for isotropic scattering of single-scattering albedo `omega`
/// in [0, 1], at the nodes of `(nodes, weights)`, by the iteration of its second form,
/// `1 / H(mu) = sqrt(1 - omega) + (omega / 2) int_0^1 mu' H(mu') / (mu + mu') dmu'`, which
/// converges for every omega in [0, 1] (the first form slows to a crawl at omega = 1).
fn h_function(omega: f64, nodes: &[f64], weights: &[f64]) -> Vec<f64> {
    let root = (1.0 - omega).max(0.0).sqrt();
    let mut h = vec![1.0; nodes.len()];
    for _ in 0..10_000 {
        let next: Vec<f64> = nodes
            .iter()
            .map(|&mu| {
                let integral: f64 = nodes
                    .iter()
                    .zip(weights)
                    .zip(&h)
                    .map(|((&m, &w), &hm)| w * m * hm / (mu + m))
                    .sum();
                1.0 / (root + 0.5 * omega * integral)
            })
            .collect();
        let change = next
            .iter()
            .zip(&h)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // The geometric mean of successive iterates: at omega = 1 the map sends c H to H / c,
        // so plain iteration would swing between the two for ever; the mean lands on H.
        for (old, new) in h.iter_mut().zip(next) {
            *old = (*old * new).sqrt();
        }
        if change < 1e-13 {
            break;
        }
    }
    h
}

/// The white-sky albedo of a semi-infinite medium of reduced scattering `sigma_s_prime` and
/// absorption `sigma_a` (any one unit) behind a smooth boundary of relative index `eta`, the
/// light reflected specularly off the boundary left out (lucent's specular lobe is that).
/// In [0, 1] for every input; 0 for a medium that neither scatters nor absorbs.
pub fn white_sky_albedo(sigma_s_prime: f64, sigma_a: f64, eta: f64) -> f64 {
    let (sp, sa) = (sigma_s_prime.max(0.0), sigma_a.max(0.0));
    // NaN coefficients (never from a validated medium) and an empty medium reflect nothing.
    if sp + sa <= 0.0 || (sp + sa).is_nan() {
        return 0.0;
    }
    let omega = (sp / (sp + sa)).clamp(0.0, 1.0);
    // Nothing scatters: nothing comes back (exactly, not quadrature's 1e-16).
    if omega == 0.0 {
        return 0.0;
    }
    let (nodes, weights) = gauss_legendre_unit(NODES);
    let h = h_function(omega, &nodes, &weights);
    let first_moment: f64 = nodes
        .iter()
        .zip(&weights)
        .zip(&h)
        .map(|((&m, &w), &hm)| w * m * hm)
        .sum();
    let root = (1.0 - omega).sqrt();
    let matched = (1.0 - 2.0 * root * first_moment).clamp(0.0, 1.0);
    if eta == 1.0 || !eta.is_finite() || eta <= 0.0 {
        return matched;
    }
    // Behind a refracting boundary. Light from every direction enters with Fresnel's
    // transmittance at the refracted cosine mu_t, where the medium's plane albedo r(mu_t) sends
    // it back up. What comes up has the intensity of a white sky's reflection, r(mu) (by
    // reciprocity); the boundary lets out (1 - F(mu)) of it and reflects the rest back in,
    // where the medium returns it with r averaged over that reflected light, again and again.
    let plane_albedo = |mu: f64| {
        // 1 / H(mu) from the converged nodes (the H-function's second form, at any mu).
        let integral: f64 = nodes
            .iter()
            .zip(&weights)
            .zip(&h)
            .map(|((&m, &w), &hm)| w * m * hm / (mu + m))
            .sum();
        (1.0 - root / (root + 0.5 * omega * integral)).clamp(0.0, 1.0)
    };
    let (mut entered, mut up, mut escaped) = (0.0, 0.0, 0.0);
    let (mut back, mut back_returned) = (0.0, 0.0);
    for ((&mu, &w), &hm) in nodes.iter().zip(&weights).zip(&h) {
        let refracted = (1.0 - (1.0 - mu * mu) / (eta * eta)).max(0.0).sqrt();
        entered += w * 2.0 * mu * (1.0 - fresnel(mu, 1.0, eta)) * plane_albedo(refracted);
        let r = (1.0 - root * hm).clamp(0.0, 1.0);
        let inside = fresnel(mu, eta, 1.0);
        up += w * r * mu;
        escaped += w * r * mu * (1.0 - inside);
        back += w * r * mu * inside;
        back_returned += w * r * mu * inside * r;
    }
    // A medium that sends nothing up reflects nothing (and the ratios below are 0 / 0).
    if up <= 0.0 || entered <= 0.0 {
        return 0.0;
    }
    let out_fraction = escaped / up;
    let returned = if back > 0.0 {
        back_returned / back
    } else {
        0.0
    };
    (entered * out_fraction / (1.0 - (1.0 - out_fraction) * returned).max(1e-12)).clamp(0.0, 1.0)
}

/// Midpoints of [0, 1] for the boundary's integral below: Fresnel's
/// kink at the critical angle (a boundary of `eta` < 1 seen from outside) defeats Gauss's
/// nodes, midpoints converge on it as 1/n^2.
const MIDPOINTS: usize = 256;

/// The fraction of a white sky's light, cosine-distributed and arriving from outside, that a
/// smooth boundary of relative index `eta` lets into the medium: `2 int_0^1 (1 - F(mu)) mu dmu`
/// (1 at eta 1; 0.923 at 1.4, 0.908 at 1.5). By reciprocity it is also how far below a
/// Lambertian emitter's the light leaving a medium through the boundary lies
/// (`int (1 - F(mu_o)) mu_o dω = pi c`), so a diffuse exitance `M` leaves as the radiance
/// `(1 - F(mu_o)) M / (pi c)`. Not Jensen's `1 - F_dr`, which is the share of light *inside*
/// that gets out (0.47 at 1.4: `c / eta^2`).
pub fn diffuse_transmittance(eta: f64) -> f64 {
    if eta == 1.0 || !eta.is_finite() || eta <= 0.0 {
        return 1.0;
    }
    let step = 1.0 / MIDPOINTS as f64;
    (0..MIDPOINTS)
        .map(|i| {
            let mu = (i as f64 + 0.5) * step;
            2.0 * mu * (1.0 - fresnel(mu, 1.0, eta)) * step
        })
        .sum::<f64>()
        .clamp(0.0, 1.0)
}

/// The share of the white-sky albedo that single scattering carries: light that scatters
/// once in a flat, semi-infinite medium of single-scattering albedo `omega` (`sigma_s /
/// sigma_t`, not reduced) and Henyey-Greenstein `g`, behind a smooth boundary of relative
/// index `eta`, and leaves. Both paths inside are refracted; the radiance inside is `eta^2`
/// the radiance outside (the light's solid angle narrows as it enters and widens as it
/// leaves), so the radiance a collimated beam of irradiance `E` at cosine `mu_i` sends out at
/// `mu_o` is `F_t(mu_i) F_t(mu_o) / eta^2 omega p(cos θ) E / (mu_t + mu_v)`, `mu_t` and `mu_v`
/// the refracted cosines (glsl/layered/single.frag marches the same). At eta 1 and g 0 it is
/// `(omega / 2) int_0^1 2 mu (1 - mu ln(1 + 1 / mu)) dmu` = 0.2046 omega.
///
/// What Li et al.'s multiple scattering must leave to single scattering: Jensen's dipole
/// counts every order of scattering, the first one too, so the two terms summed reflect more
/// light than the medium does (skin1's white-sky albedo 0.625 / 0.385 / 0.241, dipole plus
/// single scattering 0.743 / 0.462 / 0.300).
pub fn single_scattering_white_sky_albedo(omega: f64, g: f64, eta: f64) -> f64 {
    let omega = if omega.is_nan() {
        0.0
    } else {
        omega.clamp(0.0, 1.0)
    };
    (omega * single_scattering_per_albedo(g, eta)).clamp(0.0, 1.0)
}

/// [`single_scattering_white_sky_albedo`] at omega 1: the single-scattering albedo is linear in
/// omega, so a medium's three channels, which share `g` and `eta`, need this integral once.
/// About 0.3 ms (32^3 phase evaluations).
pub fn single_scattering_per_albedo(g: f64, eta: f64) -> f64 {
    let eta = if eta.is_finite() && eta > 0.0 {
        eta
    } else {
        1.0
    };
    // Midpoints in both cosines and the azimuth: the integrand is smooth in each away from
    // |g| -> 1 (32 and 128 nodes agree within 0.3% at g 0.9, 0.02% at g 0).
    const N: usize = 32;
    let step = 1.0 / N as f64;
    let inside = |mu: f64| {
        let t = (1.0 - (1.0 - mu * mu) / (eta * eta)).max(0.0).sqrt();
        (
            t,
            (1.0 - t * t).max(0.0).sqrt(),
            1.0 - fresnel(mu, 1.0, eta),
        )
    };
    let cosines: Vec<(f64, f64, f64, f64)> = (0..N)
        .map(|i| {
            let mu = (i as f64 + 0.5) * step;
            let (m, sin, t) = inside(mu);
            (mu, m, sin, t)
        })
        .collect();
    let azimuths: Vec<f64> = (0..N)
        .map(|k| (std::f64::consts::PI * (k as f64 + 0.5) * step).cos())
        .collect();
    let mut albedo = 0.0;
    for &(mu_i, mu_t, sin_t, t_i) in &cosines {
        let mut exitance = 0.0;
        for &(mu_o, mu_v, sin_v, t_o) in &cosines {
            // The light travels down at mu_t, the scattered light up at mu_v: cos θ between
            // them is sin_t sin_v cos φ - mu_t mu_v, the phase averaged over φ.
            let phase: f64 = azimuths
                .iter()
                .map(|cos_phi| henyey_greenstein(g, sin_t * sin_v * cos_phi - mu_t * mu_v))
                .sum::<f64>()
                * step;
            // Radiance over E, times mu_o dmu_o dφ over the whole circle (2 pi).
            exitance += t_i * t_o / (eta * eta) * phase / (mu_t + mu_v).max(1e-9)
                * mu_o
                * step
                * std::f64::consts::TAU;
        }
        albedo += 2.0 * mu_i * exitance * step;
    }
    albedo.clamp(0.0, 1.0)
}

/// Henyey-Greenstein: `(1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2))`, per steradian. The base is
/// written `(1 - g)^2 + 2 g (1 - cos)`: both terms are exact near `cos = 1`, where
/// `1 + g^2 - 2g cos` cancels catastrophically for |g| -> 1. |g| is clamped to
/// [`MAX_ABS_G`] (|g| -> 1 makes it a spike; the shaders hold it there too), a NaN `g` reads 0.
pub fn henyey_greenstein(g: f64, cos_theta: f64) -> f64 {
    let m = f64::from(MAX_ABS_G);
    let g = if g.is_nan() { 0.0 } else { g.clamp(-m, m) };
    let c = cos_theta.clamp(-1.0, 1.0);
    // base >= (1 - |g|)^2 > 0 for |g| <= 0.999 (the clamp keeps it off 0).
    let base = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c);
    (1.0 - g * g) / (4.0 * std::f64::consts::PI * base * base.sqrt())
}

/// Chandrasekhar's H-function for isotropic scattering of albedo `omega` at `mu` in [0, 1],
/// exactly (the converged iteration on the quadrature nodes, then its second form at `mu`).
pub fn h_exact(omega: f64, mu: f64) -> f64 {
    let omega = omega.clamp(0.0, 1.0);
    let (nodes, weights) = gauss_legendre_unit(NODES);
    let h = h_function(omega, &nodes, &weights);
    let integral: f64 = nodes
        .iter()
        .zip(&weights)
        .zip(&h)
        .map(|((&m, &w), &hm)| w * m * hm / (mu + m))
        .sum();
    1.0 / ((1.0 - omega).sqrt() + 0.5 * omega * integral)
}

/// Hapke's (2002, eq. 13) closed form of the H-function, within 1% of it for every omega and
/// mu: `1 / (1 - omega mu (r0 + (1 - 2 r0 mu) / 2 ln((1 + mu) / mu)))`, `r0 = (1 - gamma) /
/// (1 + gamma)`, `gamma = sqrt(1 - omega)`. What the lighting pass evaluates
/// (glsl/common/sss_medium.glsl `sss_medium_h`). `mu` is held at 1e-4 or more (ln(1 / 0)); the
/// bracket stays above 0.3 for every omega <= 1 and mu in [0, 1].
pub fn hapke_h(omega: f64, mu: f64) -> f64 {
    let omega = omega.clamp(0.0, 1.0);
    let gamma = (1.0 - omega).sqrt();
    let r0 = (1.0 - gamma) / (1.0 + gamma);
    let mu = mu.clamp(1e-4, 1.0);
    1.0 / (1.0 - omega * mu * (r0 + 0.5 * (1.0 - 2.0 * r0 * mu) * ((1.0 + mu) / mu).ln()))
}

/// How much a semi-infinite medium of (reduced) albedo `omega` reflects from light arriving at
/// cosine `mu0` towards cosine `mu`, relative to a Lambertian surface of its albedo:
/// Chandrasekhar's reflection of an isotropically scattering half-space, `f = (omega / 4 pi)
/// H(mu0) H(mu) / (mu0 + mu)`, over `A / pi` with `A = matched_albedo` (its white-sky albedo
/// behind an index-matched boundary, what `f` integrates to under a white sky). Exact, with
/// [`h_exact`], at eta 1; the lighting pass (glsl `sss_medium_reflectance`, with [`hapke_h`])
/// multiplies the Lambertian diffuse light of an SSS material with a medium by it, so the
/// surface reflects as its medium does: more at grazing light and view, less head-on (skin1
/// side-lit against the path-traced truth: Lambert's error 0.26, this 0.20).
pub fn medium_reflectance(omega: f64, matched_albedo: f64, mu0: f64, mu: f64) -> f64 {
    let h = |x: f64| hapke_h(omega, x);
    // The sum of cosines is held off 0 (grazing light and view at once): the H-functions are
    // bounded, so the factor is at most omega H^2 / (4 A 1e-4).
    omega.clamp(0.0, 1.0) * h(mu0) * h(mu) / (4.0 * matched_albedo.max(1e-3) * (mu0 + mu).max(1e-4))
}

/// Fresnel reflectance of unpolarised light arriving at cosine `cos_i` on the side of index
/// `n_i`, going to `n_t` (1 under total internal reflection).
fn fresnel(cos_i: f64, n_i: f64, n_t: f64) -> f64 {
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// A Henyey-Greenstein scattering of a direction whose depth cosine is `uz`: the new depth
/// cosine (the deflection sampled exactly, the azimuth uniformly).
#[cfg(test)]
fn scattered_depth_cosine(uz: f64, g: f64, rng: &mut rand::rngs::SmallRng) -> f64 {
    use rand::Rng;
    let cos = if g.abs() < 1e-6 {
        2.0 * rng.gen::<f64>() - 1.0
    } else {
        let t = (1.0 - g * g) / (1.0 - g + 2.0 * g * rng.gen::<f64>());
        ((1.0 + g * g - t * t) / (2.0 * g)).clamp(-1.0, 1.0)
    };
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * rng.gen::<f64>();
    let sin_z = (1.0 - uz * uz).max(0.0).sqrt();
    (uz * cos + sin_z * sin * phi.cos()).clamp(-1.0, 1.0)
}

/// The same albedo by Monte Carlo: `photons` random walks (seeded, so reproducible) into a
/// semi-infinite medium of `sigma_s` (not reduced), `sigma_a`, Henyey-Greenstein `g`, behind a
/// smooth boundary of index `eta` with exact Fresnel reflection both ways. Light arrives
/// cosine-distributed; what the boundary reflects at once is left out, as above.
#[cfg(test)]
pub fn monte_carlo_white_sky_albedo(
    sigma_s: f64,
    sigma_a: f64,
    g: f64,
    eta: f64,
    photons: usize,
    seed: u64,
) -> f64 {
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
    let sigma_t = sigma_s + sigma_a;
    let albedo = sigma_s / sigma_t;
    let mut out = 0.0;
    for _ in 0..photons {
        let mu_out: f64 = rng.gen::<f64>().sqrt();
        if rng.gen::<f64>() < fresnel(mu_out, 1.0, eta) {
            continue;
        }
        // Direction cosine along +depth after refraction.
        let mut uz = (1.0 - (1.0 - mu_out * mu_out) / (eta * eta))
            .max(0.0)
            .sqrt();
        let (mut z, mut weight) = (0.0f64, 1.0f64);
        loop {
            z += -(1.0 - rng.gen::<f64>()).ln() / sigma_t * uz;
            if z < 0.0 {
                // At the boundary from inside: reflected back (mirror the path) or out.
                if rng.gen::<f64>() < fresnel(-uz, eta, 1.0) {
                    z = -z;
                    uz = -uz;
                    continue;
                }
                out += weight;
                break;
            }
            weight *= albedo;
            if weight < 1e-3 {
                // Russian roulette, unbiased: survive 1 in 10 with ten times the weight.
                if rng.gen::<f64>() < 0.9 {
                    break;
                }
                weight *= 10.0;
            }
            uz = scattered_depth_cosine(uz, g, &mut rng);
        }
    }
    out / photons as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_h_function_has_its_known_zeroth_moment() {
        // int_0^1 H(mu) dmu = (2 / omega) (1 - sqrt(1 - omega)) for isotropic scattering.
        let (nodes, weights) = gauss_legendre_unit(NODES);
        for omega in [0.1, 0.5, 0.9, 0.99, 0.9999, 1.0] {
            let h = h_function(omega, &nodes, &weights);
            let moment: f64 = weights.iter().zip(&h).map(|(w, h)| w * h).sum();
            let exact = 2.0 / omega * (1.0 - (1.0f64 - omega).sqrt());
            assert!(
                (moment - exact).abs() < 1e-4,
                "{omega}: {moment} vs {exact}"
            );
        }
    }

    #[test]
    fn the_closed_form_is_the_random_walk() {
        // (sigma_s, sigma_a, g, eta): skin1's three channels, marble's red, ketchup-like, a
        // forward-scattering medium (similarity), and refracting boundaries.
        let media = [
            (0.74, 0.032, 0.0, 1.0),
            (0.88, 0.17, 0.0, 1.0),
            (1.01, 0.48, 0.0, 1.0),
            (2.19, 0.0021, 0.0, 1.0),
            (0.5, 0.5, 0.0, 1.0),
            (4.0, 0.1, 0.8, 1.0),
            (0.88, 0.17, 0.0, 1.4),
            (1.5, 0.05, 0.0, 1.3),
        ];
        for (i, &(ss, sa, g, eta)) in media.iter().enumerate() {
            let exact = white_sky_albedo(ss * (1.0 - g), sa, eta);
            let walk = monte_carlo_white_sky_albedo(ss, sa, g, eta, 40_000, i as u64 + 1);
            println!("sigma_s {ss} sigma_a {sa} g {g} eta {eta}: {exact:.4} walk {walk:.4}");
            // 40k photons: the walk's own standard error is under 0.0025.
            let tolerance = if eta == 1.0 && g == 0.0 { 0.01 } else { 0.03 };
            assert!(
                (exact - walk).abs() < tolerance,
                "sigma_s {ss} sigma_a {sa} g {g} eta {eta}: closed form {exact:.4}, walk {walk:.4}"
            );
        }
    }

    #[test]
    fn the_boundary_lets_in_a_white_sky_s_known_share() {
        // Glass's hemispherical reflectance of diffuse light is 0.092 at n 1.5; Jensen's
        // internal F_dr is the share of light inside the boundary sends back: 1 - F_dr = c / eta^2
        // (its fit within 2%).
        assert_eq!(diffuse_transmittance(1.0), 1.0);
        assert!((diffuse_transmittance(1.5) - 0.908).abs() < 1e-3);
        for eta in [1.2, 1.33, 1.4, 1.5, 2.0] {
            let inside = 1.0 - crate::scene::layered::fresnel_diffuse_reflectance(eta);
            let c = diffuse_transmittance(eta);
            assert!(
                (c / (eta * eta) / inside - 1.0).abs() < 0.02,
                "{eta}: {c} {inside}"
            );
        }
        // Denser outside (eta < 1): past the critical angle nothing enters, still in [0, 1].
        let c = diffuse_transmittance(0.7);
        assert!(c > 0.0 && c < 0.7, "{c}");
        for eta in [f64::NAN, 0.0, -1.0, f64::INFINITY] {
            assert_eq!(diffuse_transmittance(eta), 1.0);
        }
    }

    /// Single scattering's white-sky albedo by Monte Carlo: cosine-distributed light enters
    /// through exact Fresnel, travels an exponential distance, scatters once (HG `g`, weight
    /// omega) and counts when it reaches the boundary unscattered and gets through it.
    fn monte_carlo_single_scattering(omega: f64, g: f64, eta: f64, photons: usize) -> f64 {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::SmallRng::seed_from_u64(7);
        let mut out = 0.0;
        for _ in 0..photons {
            let mu_out: f64 = rng.gen::<f64>().sqrt();
            if rng.gen::<f64>() < fresnel(mu_out, 1.0, eta) {
                continue;
            }
            // Depth cosine after refraction; sigma_t = 1.
            let uz = (1.0 - (1.0 - mu_out * mu_out) / (eta * eta))
                .max(0.0)
                .sqrt();
            let z = -(1.0 - rng.gen::<f64>()).ln() * uz;
            let up = -scattered_depth_cosine(uz, g, &mut rng);
            if up <= 0.0 {
                continue;
            }
            let escape = (-z / up).exp() * (1.0 - fresnel(up, eta, 1.0));
            out += omega * escape;
        }
        out / photons as f64
    }

    #[test]
    fn single_scattering_s_albedo_is_the_closed_form_and_the_random_walk() {
        // Index-matched and isotropic: 0.204569 omega (the closed form's integral).
        for omega in [0.0, 0.3, 0.9, 1.0] {
            let s = single_scattering_white_sky_albedo(omega, 0.0, 1.0);
            assert!((s - 0.204569 * omega).abs() < 1e-4, "{omega}: {s}");
        }
        // Behind boundaries and with anisotropy, against the walk (its standard error at
        // 400k photons is about 0.001).
        for (omega, g, eta) in [
            (0.68, 0.0, 1.5),
            (0.96, 0.0, 1.4),
            (0.9, 0.8, 1.0),
            (0.9, -0.5, 1.3),
            (0.99, 0.9, 1.4),
        ] {
            let s = single_scattering_white_sky_albedo(omega, g, eta);
            let walk = monte_carlo_single_scattering(omega, g, eta, 400_000);
            assert!(
                (s - walk).abs() < 0.004 + 0.02 * walk,
                "omega {omega} g {g} eta {eta}: {s:.4} walk {walk:.4}"
            );
        }
        // Extreme and bad input stays an albedo.
        for (omega, g, eta) in [
            (f64::NAN, 0.0, 1.0),
            (2.0, 1.0, 1.0),
            (1.0, -1.0, 10.0),
            (1.0, 0.999, 0.5),
            (0.5, f64::NAN, f64::NAN),
        ] {
            let s = single_scattering_white_sky_albedo(omega, g, eta);
            assert!(
                s.is_finite() && (0.0..=1.0).contains(&s),
                "{omega} {g} {eta}: {s}"
            );
        }
    }

    #[test]
    fn hapke_s_h_is_within_a_percent_of_chandrasekhar_s() {
        for omega in [0.0, 0.3, 0.7, 0.9, 0.96, 0.99, 0.999, 1.0] {
            for mu in [0.0, 0.01, 0.1, 0.3, 0.5, 0.8, 1.0] {
                let (exact, hapke) = (h_exact(omega, mu), hapke_h(omega, mu));
                assert!(
                    (hapke / exact - 1.0).abs() < 0.01,
                    "omega {omega} mu {mu}: Hapke {hapke} exact {exact}"
                );
            }
        }
    }

    #[test]
    fn the_medium_s_reflectance_integrates_to_its_albedo_under_a_white_sky() {
        // Over the hemisphere of light and view, cosine-weighted, the factor times A / pi
        // reflects A: the factor's mean is 1 (to the Hapke form's percent).
        let (nodes, weights) = gauss_legendre_unit(NODES);
        for omega in [0.5, 0.9, 0.96, 0.999] {
            let a = white_sky_albedo(omega, 1.0 - omega, 1.0);
            let mut mean = 0.0;
            for (&mu0, &w0) in nodes.iter().zip(&weights) {
                for (&mu, &w) in nodes.iter().zip(&weights) {
                    // 2 mu0 dmu0 (the white sky's cosine-weighted arrival), 2 mu dmu (out).
                    mean += 4.0 * w0 * w * mu0 * mu * medium_reflectance(omega, a, mu0, mu);
                }
            }
            assert!((mean - 1.0).abs() < 0.02, "omega {omega}: {mean}");
        }
        for (mu0, mu) in [(0.0, 0.0), (1e-9, 0.0), (1.0, 1.0)] {
            let f = medium_reflectance(1.0, 1.0, mu0, mu);
            assert!(f.is_finite() && f >= 0.0, "{mu0} {mu}: {f}");
        }
        assert_eq!(medium_reflectance(0.0, 0.0, 0.5, 0.5), 0.0);
    }

    #[test]
    fn extremes_stay_an_albedo() {
        for sp in [0.0, 1e-9, 1e-3, 1.0, 1e6] {
            for sa in [0.0, 1e-9, 1.0, 1e6] {
                for eta in [0.5, 1.0, 1.3, 2.5] {
                    let a = white_sky_albedo(sp, sa, eta);
                    assert!((0.0..=1.0).contains(&a), "{sp} {sa} {eta}: {a}");
                }
            }
        }
        assert!((white_sky_albedo(1.0, 0.0, 1.0) - 1.0).abs() < 1e-12);
        assert_eq!(white_sky_albedo(0.0, 1.0, 1.0), 0.0);
        assert_eq!(white_sky_albedo(f64::NAN, 1.0, 1.0), 0.0);
    }
}
