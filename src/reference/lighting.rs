//! Lambert + normalised Blinn-Phong, point and directional lights (twin of
//! glsl/common/lighting.glsl).

use super::DVec3;
use crate::scene::{Light, Material};

/// Blinn-Phong exponent from roughness: 2^(11 - 10 r), in [2, 2048].
pub fn shininess(roughness: f64) -> f64 {
    (11.0 - 10.0 * roughness.clamp(0.0, 1.0)).exp2()
}

/// Direction towards the light (unit) and the attenuation at `pos`.
pub fn light_incidence(light: &Light, pos: DVec3) -> (DVec3, f64) {
    match *light {
        Light::Directional { direction, .. } => (-direction.as_dvec3().normalize(), 1.0),
        Light::Point {
            position, range, ..
        } => {
            let d = position.as_dvec3() - pos;
            // Same clamp as the shader: a light on the surface must not divide by zero.
            let dist2 = d.length_squared().max(1e-4);
            let ratio = dist2.sqrt() / f64::from(range).max(1e-4);
            let window = (1.0 - ratio.powi(4)).clamp(0.0, 1.0);
            (d / dist2.sqrt(), window * window / dist2)
        }
    }
}

/// Radiance of a light.
pub fn radiance(light: &Light) -> DVec3 {
    match *light {
        Light::Directional { radiance, .. } | Light::Point { radiance, .. } => radiance.as_dvec3(),
    }
}

/// Outgoing radiance towards `to_eye` from one light.
pub fn shade_direct(
    material: &Material,
    normal: DVec3,
    pos: DVec3,
    to_eye: DVec3,
    light: &Light,
) -> DVec3 {
    let (to_light, attenuation) = light_incidence(light, pos);
    let n_dot_l = normal.dot(to_light).max(0.0);
    let h = to_light + to_eye;
    let h = if h.length_squared() > 1e-12 {
        h.normalize()
    } else {
        normal
    };
    let n = shininess(f64::from(material.roughness));
    let spec = (n + 8.0) / (8.0 * std::f64::consts::PI) * normal.dot(h).max(0.0).powf(n);
    let albedo = material.albedo.as_dvec3();
    let brdf = albedo / std::f64::consts::PI + DVec3::splat(f64::from(material.specular) * spec);
    brdf * radiance(light) * (n_dot_l * attenuation)
}

/// Ambient plus every light, as the deferred lighting pass computes it.
pub fn shade(
    material: &Material,
    normal: DVec3,
    pos: DVec3,
    eye: DVec3,
    ambient: DVec3,
    lights: &[Light],
) -> DVec3 {
    let to_eye = (eye - pos).normalize();
    let mut color = ambient * material.albedo.as_dvec3();
    for light in lights {
        color += shade_direct(material, normal, pos, to_eye, light);
    }
    color.min(DVec3::splat(65504.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn energy_of_a_white_lambert_surface_under_a_unit_directional_light() {
        let m = Material {
            albedo: Vec3::ONE,
            specular: 0.0,
            roughness: 1.0,
        };
        let light = Light::Directional {
            direction: Vec3::new(0.0, -1.0, 0.0),
            radiance: Vec3::ONE,
        };
        let c = shade_direct(&m, DVec3::Y, DVec3::ZERO, DVec3::Y, &light);
        assert!((c.x - 1.0 / std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn light_on_the_surface_and_opposite_view_stay_finite() {
        let m = Material {
            albedo: Vec3::ONE,
            specular: 1.0,
            roughness: 0.0,
        };
        let light = Light::Point {
            position: Vec3::ZERO,
            radiance: Vec3::splat(1e5),
            range: 10.0,
        };
        let c = shade(
            &m,
            DVec3::Y,
            DVec3::ZERO,
            DVec3::new(0.0, -1.0, 0.0),
            DVec3::ZERO,
            &[light],
        );
        assert!(c.is_finite());
    }
}
