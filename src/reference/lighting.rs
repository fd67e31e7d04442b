//! Lambert + normalised Blinn-Phong, point and directional lights (twin of
//! glsl/common/lighting.glsl).

use super::DVec3;
use crate::scene::{Light, LightKind, Material};

/// Blinn-Phong exponent from roughness: 2^(11 - 10 r), in [2, 2048].
pub fn shininess(roughness: f64) -> f64 {
    (11.0 - 10.0 * roughness.clamp(0.0, 1.0)).exp2()
}

/// Direction towards the light (unit) and the attenuation at `pos`.
pub fn light_incidence(light: &Light, pos: DVec3) -> (DVec3, f64) {
    let point = |position: glam::Vec3, range: f32| {
        let d = position.as_dvec3() - pos;
        // Same clamp as the shader: a light on the surface must not divide by zero.
        let dist2 = d.length_squared().max(1e-4);
        let ratio = dist2.sqrt() / f64::from(range).max(1e-4);
        let window = (1.0 - ratio.powi(4)).clamp(0.0, 1.0);
        (d / dist2.sqrt(), window * window / dist2)
    };
    match light.kind {
        LightKind::Directional { direction } => (-direction.as_dvec3().normalize(), 1.0),
        LightKind::Point { position, range } => point(position, range),
        LightKind::Spot {
            position,
            direction,
            range,
            inner_degrees,
            outer_degrees,
        } => {
            let (to_light, attenuation) = point(position, range);
            let cos_outer = f64::from(outer_degrees).to_radians().cos();
            let cos_inner = f64::from(inner_degrees).to_radians().cos();
            let cos_angle = (-to_light).dot(direction.as_dvec3().normalize());
            let t = ((cos_angle - cos_outer) / (cos_inner - cos_outer).max(1e-4)).clamp(0.0, 1.0);
            (to_light, attenuation * t * t)
        }
    }
}

/// Radiance of a light.
pub fn radiance(light: &Light) -> DVec3 {
    light.radiance().as_dvec3()
}

/// Outgoing radiance towards `to_eye` from one light.
pub fn shade_direct(
    material: &Material,
    normal: DVec3,
    pos: DVec3,
    to_eye: DVec3,
    light: &Light,
) -> DVec3 {
    let (diffuse, specular) = shade_direct_split(material, normal, pos, to_eye, light);
    diffuse + specular
}

/// [`shade_direct`]'s diffuse and specular parts apart (the SSS frames' lighting pass writes
/// them to separate targets; only diffuse is blurred).
pub fn shade_direct_split(
    material: &Material,
    normal: DVec3,
    pos: DVec3,
    to_eye: DVec3,
    light: &Light,
) -> (DVec3, DVec3) {
    let (to_light, attenuation) = light_incidence(light, pos);
    let incident = radiance(light) * (normal.dot(to_light).max(0.0) * attenuation);
    let h = to_light + to_eye;
    let h = if h.length_squared() > 1e-12 {
        h.normalize()
    } else {
        normal
    };
    let n = shininess(f64::from(material.roughness));
    let spec = (n + 8.0) / (8.0 * std::f64::consts::PI) * normal.dot(h).max(0.0).powf(n);
    let diffuse = material.albedo.as_dvec3() / std::f64::consts::PI * incident;
    (diffuse, f64::from(material.specular) * spec * incident)
}

/// Ambient plus every light, as the deferred lighting pass computes it; `ambient` is the
/// environment's `E(n) / π` at this normal ([`crate::scene::Environment::ambient_radiance`]).
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
        let m = Material::opaque("white", Vec3::ONE, 0.0, 1.0);
        let light = Light::directional(Vec3::new(0.0, -1.0, 0.0), Vec3::ONE, 1.0);
        let c = shade_direct(&m, DVec3::Y, DVec3::ZERO, DVec3::Y, &light);
        assert!((c.x - 1.0 / std::f64::consts::PI).abs() < 1e-12);
    }

    #[test]
    fn light_on_the_surface_and_opposite_view_stay_finite() {
        let m = Material::opaque("mirror-ish", Vec3::ONE, 1.0, 0.0);
        let light = Light::point(Vec3::ZERO, Vec3::ONE, 1e5, 10.0);
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

#[cfg(test)]
mod spot_tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn spot_cone_is_full_inside_zero_outside_and_smooth_between() {
        let spot = |inner: f32, outer: f32| Light {
            kind: LightKind::Spot {
                position: Vec3::new(0.0, 1.0, 0.0),
                direction: Vec3::NEG_Y,
                range: 100.0,
                inner_degrees: inner,
                outer_degrees: outer,
            },
            color: Vec3::ONE,
            intensity: 1.0,
            translucency_scale: 1.0,
            shadows: true,
        };
        let l = spot(20.0, 40.0);
        let at = |x: f64| light_incidence(&l, DVec3::new(x, 0.0, 0.0)).1;
        let point_falloff = |x: f64| {
            light_incidence(
                &Light::point(Vec3::new(0.0, 1.0, 0.0), Vec3::ONE, 1.0, 100.0),
                DVec3::new(x, 0.0, 0.0),
            )
            .1
        };
        assert!(
            (at(0.0) - point_falloff(0.0)).abs() < 1e-12,
            "full inside the inner cone"
        );
        assert_eq!(at(2.0), 0.0, "63 degrees: outside");
        let mid = at(0.5); // 26.6 degrees: between
        assert!(mid > 0.0 && mid < point_falloff(0.5));
        // inner == outer must not divide by zero.
        assert!(
            light_incidence(&spot(30.0, 30.0), DVec3::new(0.3, 0.0, 0.0))
                .1
                .is_finite()
        );
    }
}
