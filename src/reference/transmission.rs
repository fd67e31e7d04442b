//! Diffuse transmission through thickness for screen-space SSS materials with a medium, in f64:
//! the twin of glsl/common/sss_transmission.glsl ([`crate::features::sss::transmission`] says
//! what it models and why).

use crate::reference::lighting::{light_incidence, radiance};
use crate::reference::DVec3;
use crate::scene::layered::Dipole;
use crate::scene::material::Light;
// The transmittance itself is CPU math of the materials (the frame's tables use it).
pub use crate::scene::transmittance::{
    beyond_sum, most, multipole_sum, transmittance, transmittance_over_albedo,
};

/// The same sum image by image, `-pairs..=pairs` (the test's check of the closed form).
#[cfg(test)]
fn multipole_sum_by_images(dipole: &Dipole, a: f64, pairs: i32) -> f64 {
    let boundaries = dipole.z_v - dipole.z_r;
    let period = 2.0 * (a + boundaries);
    let term = |h: f64| h.signum() * (-dipole.sigma_tr * h.abs()).exp();
    (-pairs..=pairs)
        .map(|i| {
            let shift = f64::from(i) * period;
            term(a - (shift + dipole.z_r)) - term(a - (shift - dipole.z_r - boundaries))
        })
        .sum()
}

/// Light `light`'s contribution to the diffuse light (before the blur) at `x_o` (outward unit
/// normal `n_o`) of a material whose albedo, as the diffuse light carries it, is `albedo`, when
/// the light enters the object at `p_in` (the first surface on the segment from `x_o` towards
/// the light): `albedo / pi x radiance x falloff(p_in) x max(-n_o . l, 0) x T(|p_in - x_o|)`
/// per channel, `T` = [`transmittance_over_albedo`] of `dipoles` (mm) with `mm_per_unit` and
/// the medium's albedo `medium_albedo` (glsl `sss_transmitted`, which finds `p_in` in the
/// light-space map).
#[allow(clippy::too_many_arguments)]
pub fn sss_transmitted(
    light: &Light,
    x_o: DVec3,
    n_o: DVec3,
    p_in: DVec3,
    albedo: DVec3,
    dipoles: &[Dipole; 3],
    mm_per_unit: f64,
    medium_albedo: DVec3,
) -> DVec3 {
    let (to_light, _) = light_incidence(light, x_o);
    let back = -n_o.dot(to_light);
    if back <= 0.0 {
        return DVec3::ZERO;
    }
    let (_, falloff) = light_incidence(light, p_in);
    let a = (p_in - x_o).length() * mm_per_unit;
    let medium_albedo = medium_albedo.to_array();
    let t = DVec3::from_array(std::array::from_fn(|c| {
        transmittance_over_albedo(&dipoles[c], a, medium_albedo[c])
    }));
    albedo / std::f64::consts::PI * radiance(light) * (falloff * back) * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::layered::{dipole_constants, LayeredMedium, MAX_COEFFICIENT};

    #[test]
    fn transmittance_is_the_slab_s_or_the_dipole_s_over_the_total() {
        for &(sp, sa, eta) in &[(0.74, 0.032, 1.0), (2.19, 0.0021, 1.5), (1.0, 1.0, 1.3)] {
            let d = dipole_constants(sp, sa, eta);
            assert_eq!(transmittance(&d, 0.0), 1.0);
            for a in [0.0, 0.1, 1.0, 4.0, 40.0, 1e6] {
                let t = transmittance(&d, a);
                let beyond = d.transmitted_beyond(a) / d.total_reflectance();
                let slab = 0.5 * d.alpha_prime * multipole_sum(&d, a) / d.total_reflectance();
                assert!(
                    (t - beyond.max(slab)).abs() < 1e-9,
                    "{sp} {sa} {eta} {a}: {t} {beyond} {slab}"
                );
            }
            // Thicker slabs let less through.
            let mut previous = f64::INFINITY;
            for a in [4.0 * d.z_r, 8.0 * d.z_r, 16.0 * d.z_r, 64.0 * d.z_r] {
                let t = transmittance(&d, a);
                assert!(t < previous, "{sp} {sa} {eta} {a}: {t} >= {previous}");
                previous = t;
            }
        }
    }

    #[test]
    fn the_closed_form_multipole_is_the_sum_of_its_images() {
        for &(sp, sa) in &[(0.74, 0.032), (2.19, 0.0021), (1.0, 1.0), (0.88, 0.17)] {
            let d = dipole_constants(sp, sa, 1.0);
            // (Not a thickness equal to z_r: sign(0) is 0 in the closed form and 1 in `signum`.)
            for a in [0.1, 0.3, 1.0, 4.0, 40.0] {
                let closed = multipole_sum(&d, a);
                let images = multipole_sum_by_images(&d, a, 4000);
                assert!(
                    (closed - images).abs() < 1e-6,
                    "{sp} {sa} {a}: {closed} {images}"
                );
            }
        }
        // A clear slab: diffusion's (z_r + z_b) / (a + 2 z_b), which a finite set of images
        // misses entirely (every pair cancels at sigma_tr = 0).
        let d = dipole_constants(2.19, 0.0, 1.0);
        let z_b = 0.5 * (d.z_v - d.z_r);
        for a in [1.0, 4.0, 8.0] {
            let t = 0.5 * d.alpha_prime * multipole_sum(&d, a);
            let want = (d.z_r + z_b) / (a + 2.0 * z_b);
            assert!((t - want).abs() < 1e-9, "{a}: {t} {want}");
        }
    }

    #[test]
    fn skin1_through_4_mm_is_what_docs_say() {
        // The numbers docs/sss.md quotes (Jensen 2001 skin1, eta 1, 4 mm).
        let m = LayeredMedium::preset("skin1").unwrap();
        let layer = &m.layers[0];
        let (sp, sa) = (layer.sigma_s_prime(), layer.sigma_a);
        let t: Vec<f64> = (0..3)
            .map(|c| {
                let d = dipole_constants(f64::from(sp[c]), f64::from(sa[c]), 1.0);
                transmittance(&d, 4.0) * d.total_reflectance()
            })
            .collect();
        for (got, want) in t.iter().zip([0.2698, 0.0567, 0.0032]) {
            assert!((got - want).abs() < 5e-4, "{t:?}");
        }
    }

    #[test]
    fn extreme_media_stay_finite() {
        // sigma -> 0 and 1e6 / mm, albedo -> 1, g -> +-0.999, eta 1 and 2.5 (issue 26).
        let max = f64::from(MAX_COEFFICIENT);
        let media = [
            (0.0, 0.0),
            (1e-9, 0.0),
            (0.0, 1e-9),
            (max, 0.0),
            (0.0, max),
            (max, max),
            (1.0, 0.0),
            // sigma_s = 1 at g = 0.999 and -0.999: sigma_s' = sigma_s (1 - g).
            (1.0 - 0.999, 1e-3),
            (1.0 + 0.999, 1e-3),
        ];
        for &(sp, sa) in &media {
            for eta in [1.0, 1.3, 2.5] {
                let d = dipole_constants(sp, sa, eta);
                for a in [0.0, 1e-9, 1e-3, 1.0, 1e3, 1e9, f64::INFINITY] {
                    let t = transmittance(&d, a);
                    assert!(
                        t.is_finite() && (0.0..=most(&d)).contains(&t) && most(&d) <= 1e3,
                        "{sp} {sa} {eta} {a}: {t}"
                    );
                }
                for albedo in [0.0, 1e-9, 0.5, 1.0] {
                    let t = transmittance_over_albedo(&d, 1.0, albedo);
                    assert!(t.is_finite() && (0.0..=1e3).contains(&t), "{albedo}: {t}");
                }
                let rows = crate::features::sss::transmission::SssTransmission {
                    dipoles: [d; 3],
                    mm_per_unit: 20.0,
                    medium_albedo: [0.0, 0.5, 1.0],
                    reflectance: [(0.0, 0.0), (0.5, 0.2), (1.0, 1.0)],
                }
                .rows();
                assert!(
                    rows.iter().flatten().all(|v| v.is_finite()),
                    "{sp} {sa} {eta}"
                );
                let s = beyond_sum(&d, 0.0);
                assert!(
                    s.is_finite() && s >= (-(3.0f64).sqrt()).exp() - 1e-12,
                    "{s}"
                );
            }
        }
        // The presets as well, with their rows finite in f32.
        for name in crate::scene::layered::preset_names() {
            let m = LayeredMedium::preset(name).unwrap();
            if m.layers.len() != 1 {
                continue;
            }
            let t = crate::features::sss::transmission::SssTransmission::of(
                &crate::scene::material::Medium::new(m),
            );
            assert!(t.rows().iter().flatten().all(|v| v.is_finite()), "{name}");
        }
    }
}
