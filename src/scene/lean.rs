//! LEAN maps (Olano and Baker 2010, "LEAN Mapping") from a tangent-space normal map, for the
//! LEAN-mapping SSS thesis's pipeline (LCB and LBB).
//!
//! Each texel's normal `n` becomes its slope ("bump centre") `B = (n.x / n.z, n.y / n.z)` and
//! second moments `M = (B.x^2, B.y^2, B.x B.y)`. Both are linear in what they describe, so the
//! mip chain is the plain average of level 0 (the texture's own downsampling): a coarse texel's
//! moments are the moments of the slopes it covers, and `Sigma = M - B B^T` is their covariance,
//! the highlight's spread that filtering would otherwise lose. Layout (both linear RGBA):
//!
//! | map | r | g | b | a |
//! |---|---|---|---|---|
//! | LEAN 1 | B.x | B.y | M.xx | M.yy |
//! | LEAN 2 | M.xy | 0 | 0 | 1 |
//!
//! Numerics, guarded where they are born: a normal at or below the tangent plane (n.z <= 0.05)
//! is clamped to n.z = 0.05 before dividing, so slopes stay within +-20 and moments within 400;
//! users of `Sigma` clamp its diagonal at 0 and its determinant at >= 0 (DESIGN.md).

use glam::{DVec2, DVec3, Vec3};

use super::texture::{Texture, TextureUsage};
use crate::Result;

/// Smallest tangent-space n.z a slope is taken from.
pub const MIN_NZ: f32 = 0.05;

/// The two LEAN maps of a normal map stored as `n * 0.5 + 0.5`.
pub fn lean_maps(normal_map: &Texture) -> Result<(Texture, Texture)> {
    Ok((lean_map(normal_map, 1)?, lean_map(normal_map, 2)?))
}

/// One of the two LEAN maps of [`lean_maps`] (`which` 1 or 2), so a large normal map's two
/// maps need not be in memory at once.
pub fn lean_map(normal_map: &Texture, which: u8) -> Result<Texture> {
    let texels: Vec<[f32; 4]> = normal_map.mips[0]
        .iter()
        .map(|&t| lean_texel(t, which))
        .collect();
    let name = if which == 1 {
        "LEAN map 1"
    } else {
        "LEAN map 2"
    };
    let (w, h) = (normal_map.width, normal_map.height);
    Texture::from_texels(name, w, h, TextureUsage::Data, texels)
}

/// Texel of LEAN map `which` (1 or 2) for a normal-map texel stored as `n * 0.5 + 0.5`
/// (the layout in the module docs).
pub fn lean_texel(normal_map_texel: [f32; 4], which: u8) -> [f32; 4] {
    let t = normal_map_texel;
    let (b, m) = slope_and_moments(Vec3::new(t[0], t[1], t[2]) * 2.0 - Vec3::ONE);
    if which == 1 {
        [b[0], b[1], m[0], m[1]]
    } else {
        [m[2], 0.0, 0.0, 1.0]
    }
}

/// Slope `B` and second moments `(B.x^2, B.y^2, B.x B.y)` of a tangent-space normal.
pub fn slope_and_moments(n: Vec3) -> ([f32; 2], [f32; 3]) {
    let n = if n.is_finite() && n.length_squared() > 1e-12 {
        n.normalize()
    } else {
        Vec3::Z
    };
    let z = n.z.max(MIN_NZ);
    let (bx, by) = (n.x / z, n.y / z);
    ([bx, by], [bx * bx, by * by, bx * by])
}

/// The covariance `Sigma = M - B B^T` of a (filtered) LEAN texel, as the shader will compute it
/// (diagonal clamped at 0, off-diagonal shrunk so the determinant stays >= 0), in f64.
pub fn covariance(lean1: [f32; 4], lean2: [f32; 4]) -> (DVec2, f64) {
    let b = DVec2::new(lean1[0].into(), lean1[1].into());
    let m = DVec3::new(lean1[2].into(), lean1[3].into(), lean2[0].into());
    let c = covariance_of(b, m);
    (DVec2::new(c.x, c.y), c.z)
}

/// The covariance (xx, yy, xy) of slope moments `m` about their mean `b`, clamped as the
/// shaders clamp it (glsl/common/lean.glsl `lean_covariance`): diagonal at 0, off-diagonal
/// shrunk so the determinant stays >= 0.
pub fn covariance_of(b: DVec2, m: DVec3) -> DVec3 {
    let xx = (m.x - b.x * b.x).max(0.0);
    let yy = (m.y - b.y * b.y).max(0.0);
    let limit = (xx * yy).sqrt();
    DVec3::new(xx, yy, (m.z - b.x * b.y).clamp(-limit, limit))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn encode(n: Vec3) -> [f32; 4] {
        let e = n.normalize() * 0.5 + Vec3::splat(0.5);
        [e.x, e.y, e.z, 1.0]
    }

    #[test]
    fn a_flat_map_has_no_slope_and_no_spread() {
        let flat =
            Texture::from_texels("flat", 4, 4, TextureUsage::Data, vec![encode(Vec3::Z); 16])
                .unwrap();
        let (l1, l2) = lean_maps(&flat).unwrap();
        for level in 0..l1.level_count() {
            for (a, b) in l1.mips[level].iter().zip(&l2.mips[level]) {
                assert!(a.iter().all(|v| v.abs() < 1e-6), "{a:?}");
                let (diag, xy) = covariance(*a, *b);
                assert!(diag.max_element() < 1e-9 && xy.abs() < 1e-9);
            }
        }
    }

    #[test]
    fn filtering_two_slopes_keeps_their_spread_as_covariance() {
        // Half the texels tilt +x, half -x: the mean slope is 0 but the 1x1 mip remembers the
        // spread, which plain normal filtering would average away.
        let tilt = 0.3f32;
        let texels: Vec<[f32; 4]> = (0..16)
            .map(|i| encode(Vec3::new(if i % 2 == 0 { tilt } else { -tilt }, 0.0, 1.0)))
            .collect();
        let map = Texture::from_texels("ridges", 4, 4, TextureUsage::Data, texels).unwrap();
        let (l1, l2) = lean_maps(&map).unwrap();
        let top = l1.level_count() - 1;
        let (diag, xy) = covariance(l1.mips[top][0], l2.mips[top][0]);
        assert!(
            l1.mips[top][0][0].abs() < 1e-3,
            "mean slope {}",
            l1.mips[top][0][0]
        );
        assert!(
            (diag.x - f64::from(tilt * tilt)).abs() < 1e-3,
            "variance {}",
            diag.x
        );
        assert!(diag.y.abs() < 1e-6 && xy.abs() < 1e-6);
    }

    #[test]
    fn grazing_and_broken_normals_stay_bounded() {
        for n in [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, -1.0, -1.0),
            Vec3::ZERO,
            Vec3::splat(f32::NAN),
        ] {
            let (b, m) = slope_and_moments(n);
            assert!(
                b.iter()
                    .chain(&m)
                    .all(|v| v.is_finite() && v.abs() <= 400.0),
                "{n}: {b:?} {m:?}"
            );
        }
    }
}
