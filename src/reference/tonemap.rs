//! Exposure, ACES fit and sRGB encoding (twin of glsl/common/color.glsl).

use super::DVec3;

/// Narkowicz's ACES fit; negative and NaN inputs map to 0, as in the shader.
pub fn tonemap_aces(x: DVec3) -> DVec3 {
    let x = DVec3::new(sanitize(x.x), sanitize(x.y), sanitize(x.z));
    ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)).clamp(DVec3::ZERO, DVec3::ONE)
}

fn sanitize(v: f64) -> f64 {
    if v.is_nan() {
        0.0
    } else {
        v.clamp(0.0, 65504.0)
    }
}

/// The sRGB transfer function.
pub fn linear_to_srgb(c: f64) -> f64 {
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear HDR radiance to an 8-bit sRGB pixel, as the tonemap pass writes it.
pub fn display_rgba8(hdr: DVec3, exposure: f64) -> [u8; 4] {
    let t = tonemap_aces(hdr * exposure);
    let e = |c: f64| (linear_to_srgb(c) * 255.0).round().clamp(0.0, 255.0) as u8;
    [e(t.x), e(t.y), e(t.z), 255]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn black_white_and_nan() {
        assert_eq!(display_rgba8(DVec3::ZERO, 1.0), [0, 0, 0, 255]);
        assert_eq!(display_rgba8(DVec3::splat(1e9), 1.0), [255, 255, 255, 255]);
        assert_eq!(display_rgba8(DVec3::splat(f64::NAN), 1.0), [0, 0, 0, 255]);
    }

    #[test]
    fn srgb_is_continuous_at_the_knee() {
        let k = 0.0031308;
        assert!((k * 12.92 - (1.055 * f64::powf(k, 1.0 / 2.4) - 0.055)).abs() < 1e-6);
    }
}
