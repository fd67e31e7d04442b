//! GDC 2011 thickness-based translucency in f64 (twin of glsl/common/translucency.glsl), and the
//! whole deferred lighting pass evaluated from a read-back G-buffer (twin of
//! glsl/deferred/lighting.frag), so a test can prove every lit pixel right.

use super::lighting::{light_incidence, radiance, shade_direct};
use super::{gbuffer_pixels, DVec3};
use crate::features::translucency::{MaterialRow, ThicknessPacking};
use crate::frame::GBufferReadback;
use crate::scene::{Light, Scene};

/// `x^n` for `x` in [0, 1]: exact `pow` (mode 0) or the spherical-Gaussian `exp2(n x - n)`
/// (mode 1). The base is clamped as in the shader so `n = 0` gives 1, never NaN.
pub fn translucency_lobe(x: f64, n: f64, mode: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if mode == 1.0 {
        (n * (x - 1.0)).exp2()
    } else {
        x.max(1e-30).powf(n)
    }
}

/// The talk's per-light term: `albedo * lightColour * attenuation * (pow(saturate(dot(V,
/// -(L + N d))), p) * scale + ambient) * thickness`.
#[allow(clippy::too_many_arguments)]
pub fn translucency_term(
    albedo: DVec3,
    normal: DVec3,
    to_eye: DVec3,
    to_light: DVec3,
    attenuation: f64,
    light_radiance: DVec3,
    scale: f64,
    material: MaterialRow,
    thickness: DVec3,
) -> DVec3 {
    let [power, distortion, ambient, mode] = material.map(f64::from);
    let lt_light = to_light + normal * distortion;
    let lobe = translucency_lobe(to_eye.dot(-lt_light), power, mode) * scale;
    albedo * light_radiance * (attenuation * (lobe + ambient)) * thickness
}

/// The transmittance GDC 2011's term takes from a medium (twin of
/// [`crate::scene::material::Extinction::transmittance`], in f64 from the medium's
/// coefficients): `exp(-sigma_tr t)` per channel through `mm` millimetres, `sigma_tr =
/// sqrt(3 sigma_a sigma_t')` with `sigma_t' = sigma_s (1 - g) + sigma_a`.
pub fn medium_transmittance(sigma_a: [f64; 3], sigma_s: [f64; 3], g: f64, mm: f64) -> [f64; 3] {
    std::array::from_fn(|c| {
        let sigma_t_prime = sigma_s[c] * (1.0 - g) + sigma_a[c];
        (-(3.0 * sigma_a[c] * sigma_t_prime).sqrt() * mm).exp()
    })
}

/// What the lighting pass needs besides the G-buffer.
pub struct LightingInputs<'a> {
    /// The scene (camera, lights, ambient, sky).
    pub scene: &'a Scene,
    /// Translucency material rows by material ID - 1, and the packing of GB2.
    pub translucency: Option<(&'a [MaterialRow], ThicknessPacking)>,
}

/// Evaluates the deferred lighting pass in f64 for every pixel of `gbuffer`: linear HDR RGB per
/// pixel, rows top first, clamped to the fp16 maximum as the shader does.
pub fn shade_gbuffer(gbuffer: &GBufferReadback, inputs: &LightingInputs<'_>) -> Vec<DVec3> {
    let scene = inputs.scene;
    let eye = scene.camera.eye.as_dvec3();
    gbuffer_pixels(gbuffer, &scene.camera)
        .into_iter()
        .map(|pixel| {
            let Some(p) = pixel else {
                return scene.sky.as_dvec3();
            };
            let albedo = p.material.albedo.as_dvec3();
            let to_eye = (eye - p.position).normalize();
            let mut color = scene.environment.ambient_radiance(p.normal) * albedo;
            let translucent = inputs.translucency.and_then(|(rows, packing)| {
                let t = gbuffer.gb2.as_ref()?[p.index];
                let (thickness, id) = match packing {
                    ThicknessPacking::Colored => {
                        (DVec3::new(t[0].into(), t[1].into(), t[2].into()), t[3])
                    }
                    ThicknessPacking::Grayscale => (DVec3::splat(t[0].into()), t[1]),
                };
                let id = (f64::from(id) * 255.0 + 0.5) as usize;
                (id > 0).then(|| (rows.get(id - 1).copied().unwrap_or([0.0; 4]), thickness))
            });
            for light in &scene.lights {
                color += shade_direct(&p.material, p.normal, p.position, to_eye, light);
                if let Some((row, thickness)) = translucent {
                    color += light_translucency(
                        albedo, p.normal, p.position, to_eye, light, row, thickness,
                    );
                }
            }
            color.min(DVec3::splat(65504.0))
        })
        .collect()
}

/// The translucency of one light at `pos` (direction and attenuation as for diffuse).
pub fn light_translucency(
    albedo: DVec3,
    normal: DVec3,
    pos: DVec3,
    to_eye: DVec3,
    light: &Light,
    material: MaterialRow,
    thickness: DVec3,
) -> DVec3 {
    let (to_light, attenuation) = light_incidence(light, pos);
    translucency_term(
        albedo,
        normal,
        to_eye,
        to_light,
        attenuation,
        radiance(light),
        f64::from(light.translucency_scale),
        material,
        thickness,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lobe_is_finite_and_bounded_at_the_extremes() {
        for n in [0.0, 1e-3, 1.0, 12.0, 1e4] {
            for x in [-5.0, 0.0, 1e-9, 0.5, 1.0, 11.0] {
                for mode in [0.0, 1.0] {
                    let v = translucency_lobe(x, n, mode);
                    assert!(
                        v.is_finite() && (0.0..=1.0).contains(&v),
                        "{x} {n} {mode}: {v}"
                    );
                }
            }
        }
        assert_eq!(translucency_lobe(0.0, 0.0, 0.0), 1.0, "x^0 = 1, even at 0");
        assert_eq!(translucency_lobe(1.0, 1e4, 1.0), 1.0);
    }

    #[test]
    fn spherical_gaussian_approaches_pow_for_large_powers_near_one() {
        // exp2(n(x-1)) vs x^n = exp2(n log2 x): log2 x ~ (x-1)/ln 2 near 1, so they differ by
        // the factor 1/ln 2 in the exponent; both peak at 1 with value 1 and vanish away.
        let (n, x): (f64, f64) = (12.0, 0.99);
        let exact = translucency_lobe(x, n, 0.0);
        let sg = translucency_lobe(x, n, 1.0);
        assert!((exact - x.powf(n)).abs() < 1e-15);
        assert!((sg - (n * (x - 1.0)).exp2()).abs() < 1e-15);
        assert!((exact - sg).abs() < 0.05, "{exact} vs {sg}");
    }

    #[test]
    fn back_light_through_a_thin_surface_matches_the_formula() {
        // View straight at the surface, light straight behind it: V . -L = 1, full lobe.
        let row = [12.0, 0.0, 0.25, 0.0]; // exact in f32
        let c = translucency_term(
            DVec3::ONE,
            DVec3::Z,
            DVec3::Z,
            -DVec3::Z,
            0.5,
            DVec3::splat(2.0),
            3.0,
            row,
            DVec3::new(1.0, 0.5, 0.0),
        );
        let expected = 2.0 * 0.5 * (1.0 * 3.0 + 0.25);
        assert!((c - DVec3::new(expected, expected * 0.5, 0.0)).length() < 1e-12);
    }

    use crate::scene::layered::LayeredMedium;
    use crate::scene::material::{Extinction, Translucency};
    use glam::Vec3;

    fn medium(sigma_a: Vec3, sigma_s: Vec3, g: f32, eta: f32) -> LayeredMedium {
        let mut m = LayeredMedium::homogeneous("test", Vec3::ZERO, sigma_a, g, eta);
        m.layers[0].sigma_s = sigma_s;
        m.units_per_mm = 0.05;
        m
    }

    #[test]
    fn medium_transmittance_matches_its_f64_twin() {
        for preset in ["skin1", "marble", "wholemilk", "ketchup"] {
            let m = LayeredMedium::preset(preset).unwrap();
            let l = &m.layers[0];
            let e = Extinction::of(&m);
            for mm in [0.0f32, 0.1, 1.0, 4.0, 20.0] {
                let got = e.transmittance(mm);
                let want = medium_transmittance(
                    l.sigma_a.as_dvec3().to_array(),
                    l.sigma_s.as_dvec3().to_array(),
                    f64::from(l.g),
                    f64::from(mm),
                );
                for c in 0..3 {
                    assert!(
                        (f64::from(got[c]) - want[c]).abs() < 1e-5 * want[c].max(1e-3),
                        "{preset} {mm} mm channel {c}: {} vs {}",
                        got[c],
                        want[c]
                    );
                }
            }
            // 1 / units_per_mm millimetres per unit.
            assert!((e.mm_per_unit * m.units_per_mm - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn the_derived_term_is_finite_at_extreme_media() {
        let mut cases = 0;
        for sigma in [0.0f32, 1e-9, 1.0, 1e6] {
            for albedo in [0.0f32, 0.5, 0.999_999, 1.0] {
                for g in [-0.999f32, 0.0, 0.999] {
                    for eta in [1.0f32, 1.3, 2.5] {
                        let m = medium(
                            Vec3::splat(sigma * (1.0 - albedo)),
                            Vec3::splat(sigma * albedo),
                            g,
                            eta,
                        );
                        let t = Translucency::from_medium(&m);
                        let e = t.extinction.unwrap();
                        assert!(e.sigma_tr.is_finite() && e.sigma_tr.min_element() >= 0.0);
                        for mm in [0.0f32, 1e-6, 1.0, 1e6, f32::MAX, f32::NAN] {
                            let x = e.transmittance(mm);
                            assert!(
                                x.is_finite() && x.min_element() >= 0.0 && x.max_element() <= 1.0,
                                "sigma {sigma} albedo {albedo} g {g} eta {eta} {mm} mm: {x}"
                            );
                            cases += 1;
                        }
                        // A clear medium lets everything through; a dense one nothing at 1 mm.
                        if sigma == 0.0 || albedo == 1.0 {
                            assert_eq!(e.transmittance(1.0), Vec3::ONE);
                        }
                        if sigma == 1e6 && albedo < 1.0 {
                            assert!(e.transmittance(1.0).max_element() < 1e-20);
                        }
                    }
                }
            }
        }
        assert_eq!(cases, 4 * 4 * 3 * 3 * 6);
    }
}
