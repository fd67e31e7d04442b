//! Screen-space SSS in f64: the diffusion profile applied as a brute-force convolution over
//! the visible surface, from a read-back G-buffer. It is the reference every screen-space
//! blur (the control, LCB, LBB) is measured against.
//!
//! For each scattering pixel `p` (SSS profile ID > 0), the outgoing diffuse light is
//! `sum_q R(|x_p - x_q|) A_q E_q / sum_q R(|x_p - x_q|) A_q` over the scattering pixels `q`,
//! where `x` is the world position rebuilt from depth, `A_q` the world area the pixel covers,
//! `E_q` its lit diffuse (ambient + Lambert, as the lighting pass computes it) and
//! `R(r) = sum_i w_i G(v_i, r)` the profile with `r` in millimetres. The normalisation keeps
//! energy, as the blurs' normalised weights do; specular is added unblurred. Non-scattering
//! pixels keep their lighting. The albedo `a` enters as the profile's texturing says
//! ([`Texturing`]): `E_q` carries `before(a_q)` and the result is multiplied by `after(a_p)`.
//! Cost is quadratic in scattering pixels: use small frames.

use glam::{DMat3, DVec2};

use super::lighting::{light_incidence, radiance, shade_direct_split, shininess};
use super::{gbuffer_pixels, DVec3};
use crate::frame::GBufferReadback;
use crate::scene::lean::covariance_of;
use crate::scene::material::{SssProfile, Texturing};
use crate::scene::profile::{burley_cdf, burley_profile, normalized_weights};
use crate::scene::Scene;

/// One pixel of the read-back frame, in world space.
struct SurfacePixel {
    index: usize,
    position: DVec3,
    area: f64,
    /// Lit diffuse with the part of the albedo applied before the blur.
    diffuse: DVec3,
    /// The part applied after it.
    albedo_after: DVec3,
}

/// Smallest view-space n.z (relative to |n|) a slope is taken from (glsl/common/lean.glsl).
pub const LEAN_MIN_NZ: f64 = 0.05;

/// Slope of a view-space direction (glsl `view_slope`).
pub fn view_slope(n_view: DVec3) -> DVec2 {
    let z = n_view.z.max(LEAN_MIN_NZ * n_view.length());
    DVec2::new(n_view.x, n_view.y) / z
}

/// The LEAN lobe (glsl/common/lean.glsl `lean_lobe`): the view-plane covariance carried back
/// to the mean normal's frame through the inverse slope Jacobian, held to at least the base
/// roughness variance `base` (`lean_bounded_covariance`), the microfacet density p / (n.h)^4,
/// Schlick's Fresnel, Cook-Torrance's G, over 4 max(n.v, 0.1).
#[allow(clippy::too_many_arguments)]
pub fn lean_lobe(
    b: DVec2,
    c: DVec3,
    base: f64,
    h: DVec3,
    v_dot_h: f64,
    n_dot_v: f64,
    n_dot_l: f64,
    f0: f64,
) -> f64 {
    let n = DVec3::new(b.x, b.y, 1.0).normalize();
    let n_dot_h = n.dot(h);
    if n_dot_h.is_nan() || n_dot_h <= 0.0 {
        return 0.0;
    }
    let helper = if n.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
    let t = helper.cross(n).normalize();
    let bt = n.cross(t);
    let z = n.z.max(LEAN_MIN_NZ);
    let column = |v: DVec3| (DVec2::new(v.x, v.y) * z - DVec2::new(n.x, n.y) * v.z) / (z * z);
    let j = glam::DMat2::from_cols(column(t), column(bt));
    let j_det = j.determinant();
    let j_inv = glam::DMat2::from_cols(
        DVec2::new(j.y_axis.y, -j.x_axis.y),
        DVec2::new(-j.y_axis.x, j.x_axis.x),
    ) / if j_det.abs() > 1e-12 { j_det } else { 1e-12 };
    let c_n = j_inv
        * glam::DMat2::from_cols(DVec2::new(c.x, c.z), DVec2::new(c.z, c.y))
        * j_inv.transpose();
    let cn = bounded_covariance(
        DVec3::new(c_n.x_axis.x, c_n.y_axis.y, c_n.x_axis.y),
        DVec3::new(base, base, 0.0),
    );
    let det = (cn.x * cn.y - cn.z * cn.z).max(0.75 * base * base);
    let x = DVec2::new(h.dot(t), h.dot(bt)) / n_dot_h;
    let e = (x.x * x.x * cn.y + x.y * x.y * cn.x - 2.0 * x.x * x.y * cn.z) / det;
    let density = (-0.5 * e).exp() / (2.0 * std::f64::consts::PI * det.sqrt() * n_dot_h.powi(4));
    let f = 1.0 - v_dot_h.clamp(0.0, 1.0);
    let fresnel = if f0 > 0.0 {
        f0 + (1.0 - f0) * f.powi(5)
    } else {
        0.0
    };
    let g = (2.0 * n_dot_h * n_dot_v.max(0.0).min(n_dot_l.max(0.0)) / v_dot_h.max(1e-4)).min(1.0);
    fresnel * g * density / (4.0 * n_dot_v.max(0.1))
}

/// `c` held to at least `c_base` (glsl `lean_bounded_covariance`).
pub fn bounded_covariance(c: DVec3, c_base: DVec3) -> DVec3 {
    let det = (c.x * c.y - c.z * c.z).max(0.0);
    let det_base = (c_base.x * c_base.y - c_base.z * c_base.z).max(1e-20);
    let k = (1.0 - det / det_base).clamp(0.0, 1.0);
    c + k * c_base
}

/// LEAN specular at a surface point from every light (glsl/sss/lean_brdf.frag): view-plane
/// slope mean `b` and moments `m`, specular intensity `ks`, the material's `roughness`, `view`
/// the world-to-view rotation.
pub fn lean_specular(
    scene: &Scene,
    view: DMat3,
    position: DVec3,
    b: DVec2,
    m: DVec3,
    ks: f64,
    roughness: f64,
) -> DVec3 {
    let base = roughness_variance(roughness);
    // Bounded by the unblurred Blinn-Phong's peak (glsl/sss/lean_brdf.frag).
    let peak = ks * (shininess(roughness) + 8.0) / (8.0 * std::f64::consts::PI);
    let c = covariance_of(b, m);
    let to_eye = view * (scene.camera.eye.as_dvec3() - position).normalize();
    let n = DVec3::new(b.x, b.y, 1.0).normalize();
    let n_dot_v = n.dot(to_eye);
    let mut out = DVec3::ZERO;
    for light in &scene.lights {
        let (to_light, attenuation) = light_incidence(light, position);
        let l = view * to_light;
        let h = l + to_eye;
        let n_dot_l = n.dot(l);
        if h.length_squared() <= 1e-12 || n_dot_l <= 0.0 {
            continue;
        }
        let h = h.normalize();
        let lobe = lean_lobe(b, c, base, h, to_eye.dot(h), n_dot_v, n_dot_l, ks).min(peak);
        out += lobe * radiance(light) * attenuation;
    }
    out
}

/// A pixel's LEAN data projected to the view plane (glsl `view_plane_lean`): `n` the unit
/// world geometric normal, `t`, `bt` a world tangent frame around it, `b_t`, `m_t` tangent-space
/// slope mean and moments, `base` the roughness variance, `view` the world-to-view rotation.
/// Returns the mean world normal, the view-plane slope mean and moments.
pub fn view_plane_lean(
    view: DMat3,
    frame: [DVec3; 3],
    b_t: DVec2,
    m_t: DVec3,
    base: f64,
) -> (DVec3, DVec2, DVec3) {
    let [t, bt, n] = frame;
    let c_t = covariance_of(b_t, m_t) + DVec3::new(base, base, 0.0);
    let (t_v, bt_v, n_v) = (view * t, view * bt, view * n);
    let u = t_v * b_t.x + bt_v * b_t.y + n_v;
    let n_world = (t * b_t.x + bt * b_t.y + n).normalize();
    let z = u.z.max(LEAN_MIN_NZ * u.length());
    let b_v = DVec2::new(u.x, u.y) / z;
    let column = |c: DVec3| (DVec2::new(c.x, c.y) * z - DVec2::new(u.x, u.y) * c.z) / (z * z);
    let j = glam::DMat2::from_cols(column(t_v), column(bt_v));
    let c = j
        * glam::DMat2::from_cols(DVec2::new(c_t.x, c_t.z), DVec2::new(c_t.z, c_t.y))
        * j.transpose();
    let m_v = DVec3::new(
        c.x_axis.x + b_v.x * b_v.x,
        c.y_axis.y + b_v.y * b_v.y,
        c.x_axis.y + b_v.x * b_v.y,
    );
    (n_world, b_v, m_v)
}

/// The base slope variance of a roughness (glsl `roughness_variance`): 1 / (s + 2) for the
/// lighting pass's Blinn-Phong exponent s.
pub fn roughness_variance(roughness: f64) -> f64 {
    1.0 / (shininess(roughness) + 2.0)
}

/// The specular the reference adds to scattering pixels (each technique's own model).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReferenceSpecular {
    /// The lighting pass's Blinn-Phong (the control).
    BlinnPhong,
    /// LEAN specular of the unblurred view-plane LEAN data (LCB, LBB): needs the G-buffer's
    /// LEAN target; slope x comes from the stored normal, as the lighting pass computes it.
    Lean,
}

/// The reference HDR image (RGB per pixel, rows top first) of the SSS frame whose G-buffer is
/// `gbuffer` (it must carry the SSS profile IDs), blurring with `profile`; scattering pixels get
/// `specular`'s model, unblurred (specular reflection happens at the surface).
/// Every pixel's shading as the lighting pass computes it: the non-scattering pixels' whole
/// light and the scattering pixels' specular in the image, their diffuse apart (in world
/// space) for a profile to convolve.
/// The scattering pixels' albedo enters as `texturing` says.
fn shaded(
    scene: &Scene,
    gbuffer: &GBufferReadback,
    specular: ReferenceSpecular,
    texturing: Texturing,
) -> (Vec<DVec3>, Vec<SurfacePixel>) {
    let view = DMat3::from_mat4(scene.camera.view().as_dmat4());
    let eye = scene.camera.eye.as_dvec3();
    let focal = f64::from(scene.camera.focal_px(gbuffer.height));
    let strength = gbuffer.sss.as_deref().unwrap_or(&[]);
    let pixels = gbuffer_pixels(gbuffer, &scene.camera);
    let mut out = vec![DVec3::ZERO; pixels.len()];
    let mut scattering: Vec<SurfacePixel> = Vec::new();
    for (i, pixel) in pixels.iter().enumerate() {
        let Some(p) = pixel else {
            out[i] = scene.sky.as_dvec3();
            continue;
        };
        let to_eye = (eye - p.position).normalize();
        let scatters = strength.get(i).is_some_and(|&s| s > 0.0);
        // A scattering pixel's light carries only the albedo's part before the blur.
        let albedo = p.material.albedo.as_dvec3();
        let mut material = p.material.clone();
        let apply = |f: fn(Texturing, f64) -> f64| albedo.to_array().map(|a| f(texturing, a));
        let albedo_after = if scatters {
            material.albedo = DVec3::from(apply(Texturing::before)).as_vec3();
            DVec3::from(apply(Texturing::after))
        } else {
            DVec3::ONE
        };
        let mut diffuse = scene.environment.ambient_radiance(p.normal) * material.albedo.as_dvec3();
        let mut blinn_phong = DVec3::ZERO;
        for light in &scene.lights {
            let (d, s) = shade_direct_split(&material, p.normal, p.position, to_eye, light);
            diffuse += d;
            blinn_phong += s;
        }
        out[i] += match (specular, gbuffer.lean.as_ref()) {
            (ReferenceSpecular::Lean, Some(lean)) if scatters => {
                let [by, mxx, myy, mxy] = lean[i].map(f64::from);
                let b = DVec2::new(view_slope(view * p.normal).x, by);
                let ks = f64::from(p.material.specular);
                let roughness = f64::from(p.material.roughness);
                lean_specular(
                    scene,
                    view,
                    p.position,
                    b,
                    DVec3::new(mxx, myy, mxy),
                    ks,
                    roughness,
                )
            }
            _ => blinn_phong,
        };
        if scatters {
            let distance = (p.position - eye).length();
            let cos = p.normal.dot(to_eye).abs().max(0.1);
            scattering.push(SurfacePixel {
                index: i,
                position: p.position,
                area: (distance / focal).powi(2) / cos,
                diffuse,
                albedo_after,
            });
        } else {
            out[i] += diffuse;
        }
    }
    (out, scattering)
}

pub fn reference_image(
    scene: &Scene,
    gbuffer: &GBufferReadback,
    profile: &SssProfile,
    specular: ReferenceSpecular,
) -> Vec<DVec3> {
    let (mut out, scattering) = shaded(scene, gbuffer, specular, profile.texturing);
    let mm_per_unit = 1.0 / f64::from(profile.units_per_mm).max(1e-12);
    // Each Gaussian is convolved and normalised on its own, then weighted: a Gaussian narrower
    // than a pixel then keeps its light in the pixel (point-sampling it at its peak and
    // normalising the whole profile at once would let it swamp the wide ones).
    let weights = normalized_weights(profile);
    let variances: Vec<f64> = profile
        .gaussians
        .iter()
        .map(|g| f64::from(g.variance).max(1e-12))
        .collect();
    let mut sums = vec![(DVec3::ZERO, 0.0f64); variances.len()];
    for p in &scattering {
        sums.iter_mut().for_each(|s| *s = (DVec3::ZERO, 0.0));
        for q in &scattering {
            let r2 = (p.position - q.position).length_squared() * mm_per_unit * mm_per_unit;
            for (sum, v) in sums.iter_mut().zip(&variances) {
                let k = (-r2 / (2.0 * v)).exp() * q.area;
                sum.0 += k * q.diffuse;
                sum.1 += k;
            }
        }
        // The pixel itself always contributes (k = area > 0), so no sum is 0.
        let blurred = sums
            .iter()
            .zip(&weights)
            .fold(DVec3::ZERO, |acc, ((sum, k), w)| {
                acc + *w * (*sum / k.max(1e-300))
            });
        out[p.index] += p.albedo_after * blurred;
    }
    out
}

/// The reference HDR image of the SSS frame whose G-buffer is `gbuffer` under Christensen and
/// Burley's normalized diffusion with shape `d_mm` per channel (mm; `units_per_mm` scene units
/// per mm): per scattering pixel `p` and channel, `sum_q K(p, q) E_q / sum_q K(p, q)` over the
/// scattering pixels, with `K = R(|x_p - x_q|) A_q` for `q != p` and, for the pixel itself
/// (where `R` is infinite but integrable), the profile's energy within a disc of the pixel's
/// area, `P(sqrt(A_p / pi))`. Specular is added unblurred; other pixels keep their lighting.
/// The albedo enters as `texturing` says.
pub fn burley_reference_image(
    scene: &Scene,
    gbuffer: &GBufferReadback,
    d_mm: DVec3,
    units_per_mm: f64,
    specular: ReferenceSpecular,
    texturing: Texturing,
) -> Vec<DVec3> {
    let (mut out, scattering) = shaded(scene, gbuffer, specular, texturing);
    let mm_per_unit = 1.0 / units_per_mm.max(1e-12);
    let area_mm2 = mm_per_unit * mm_per_unit;
    for p in &scattering {
        let (mut sum, mut weights) = (DVec3::ZERO, DVec3::ZERO);
        for q in &scattering {
            let k = if q.index == p.index {
                let rho = (q.area * area_mm2 / std::f64::consts::PI).sqrt();
                DVec3::new(
                    burley_cdf(d_mm.x, rho),
                    burley_cdf(d_mm.y, rho),
                    burley_cdf(d_mm.z, rho),
                )
            } else {
                let r = (p.position - q.position).length() * mm_per_unit;
                DVec3::new(
                    burley_profile(d_mm.x, r),
                    burley_profile(d_mm.y, r),
                    burley_profile(d_mm.z, r),
                ) * (q.area * area_mm2)
            };
            sum += k * q.diffuse;
            weights += k;
        }
        // The pixel's own term is > 0 (its area is), so no weight sum is 0.
        out[p.index] += p.albedo_after * (sum / weights.max(DVec3::splat(1e-300)));
    }
    out
}

/// Edge quality of a screen-space SSS image (the thesis, section 3.1: halos and background
/// bleeding), against the same frame without SSS and against [`reference_image`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeMetrics {
    /// Non-scattering pixels the SSS passes changed (by more than fp16 rounding).
    pub halo_pixels: usize,
    /// Largest change of a non-scattering pixel (linear HDR, any channel).
    pub halo_max: f64,
    /// Scattering pixels within the band of a non-scattering one (the silhouette, where
    /// background light bleeds in).
    pub edge_pixels: usize,
    /// Mean |SSS - reference| over the edge band (per channel).
    pub edge_error: f64,
    /// Scattering pixels farther in.
    pub interior_pixels: usize,
    /// Mean |SSS - reference| over the interior.
    pub interior_error: f64,
}

/// Measures halo and bleed: `strength` is the frame's SSS profile ID per pixel, `plain` and `sss`
/// its HDR (RGBA) without and with SSS, `reference` the f64 reference; the edge band is `band`
/// pixels wide.
pub fn edge_metrics(
    width: usize,
    strength: &[f32],
    plain: &[f32],
    sss: &[f32],
    reference: &[DVec3],
    band: i64,
) -> EdgeMetrics {
    let height = strength.len() / width.max(1);
    let scatters = |x: i64, y: i64| {
        (0..width as i64).contains(&x)
            && (0..height as i64).contains(&y)
            && strength[y as usize * width + x as usize] > 0.0
    };
    let mut m = EdgeMetrics {
        halo_pixels: 0,
        halo_max: 0.0,
        edge_pixels: 0,
        edge_error: 0.0,
        interior_pixels: 0,
        interior_error: 0.0,
    };
    for i in 0..strength.len() {
        let (x, y) = ((i % width) as i64, (i / width) as i64);
        let rgb = |img: &[f32]| {
            DVec3::new(
                img[i * 4].into(),
                img[i * 4 + 1].into(),
                img[i * 4 + 2].into(),
            )
        };
        if strength[i] <= 0.0 {
            let (a, b) = (rgb(plain), rgb(sss));
            let change = (a - b).abs().max_element();
            // fp16 rounding of diffuse and specular stored apart is not a halo.
            if change > 2e-3 * a.abs().max_element().max(1.0) {
                m.halo_pixels += 1;
            }
            m.halo_max = m.halo_max.max(change);
            continue;
        }
        let error = (rgb(sss) - reference[i]).abs().element_sum() / 3.0;
        let near_edge = (-band..=band).any(|dy| (-band..=band).any(|dx| !scatters(x + dx, y + dy)));
        if near_edge {
            m.edge_pixels += 1;
            m.edge_error += error;
        } else {
            m.interior_pixels += 1;
            m.interior_error += error;
        }
    }
    m.edge_error /= m.edge_pixels.max(1) as f64;
    m.interior_error /= m.interior_pixels.max(1) as f64;
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::profile::profile_value;

    #[test]
    fn profile_integrates_to_one_per_channel() {
        // The 2D integral of each normalised Gaussian is 1, so R integrates to 1.
        let skin = SssProfile::preset("skin").unwrap();
        let (mut total, dr) = (DVec3::ZERO, 0.001);
        let mut r = dr / 2.0;
        while r < 40.0 {
            total += profile_value(&skin, r) * (2.0 * std::f64::consts::PI * r * dr);
            r += dr;
        }
        assert!((total - DVec3::ONE).abs().max_element() < 1e-3, "{total}");
    }
}
