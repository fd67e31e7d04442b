//! Texture-space baking: rasterise the mesh's UV charts, bake every covered texel, dilate.
//!
//! # Texel convention
//!
//! Texel `(x, y)` (column `x`, row `y`, rows stored top row first) is the point of the surface
//! whose UV is its centre `((x + 0.5) / size, (y + 0.5) / size)`: **v = 0 is the top row**, which
//! is how Vulkan samples an image uploaded first row first, so the map lines up with the mesh's
//! UVs used as they are. (OBJ files put v = 0 at the bottom; a loader that flips v for the GPU
//! gets a matching map from the flipped mesh.) UVs outside `[0, 1]` are clipped, not wrapped.
//!
//! A texel is *covered* when its centre lies inside a triangle's UV footprint; where charts
//! overlap (mirrored UVs) the first triangle in index order wins. Covered texels get a baked
//! value; then [`DILATION_RINGS`] rings of uncovered texels around the charts get the mean of
//! their already-filled 8-neighbours, so bilinear filtering and mipmaps at chart borders blend
//! with thickness rather than black. Texels farther from every chart stay 0.

use std::path::Path;
use std::time::Instant;

use glam::{Vec2, Vec3};
use image::{ExtendedColorType, ImageEncoder};

use super::{area_weighted_normals, usable, BakeOptions, BakeStats, Baker, SamplePoint};
use crate::scene::Mesh;
use crate::{LucentError, Result};

/// Rings of texels filled around each chart after baking.
pub const DILATION_RINGS: u32 = 4;

/// Largest texture side a bake accepts (memory: about 5 bytes per texel plus samples).
pub const MAX_TEXTURE_SIZE: u32 = 8192;

/// A baked thickness texture: linear values in `[0, 1]`, thin = 1.
#[derive(Clone, Debug, PartialEq)]
pub struct ThicknessMap {
    /// Width and height in texels.
    pub size: u32,
    /// `size * size` values, row-major, top row (v = 0) first; dilated texels included.
    pub values: Vec<f32>,
    /// Whether each texel's centre lies on the mesh (baked), as opposed to dilated or empty.
    pub coverage: Vec<bool>,
}

impl ThicknessMap {
    /// The value at column `x`, row `y` (0 outside the map).
    pub fn get(&self, x: u32, y: u32) -> f32 {
        if x >= self.size || y >= self.size {
            return 0.0;
        }
        self.values[(y * self.size + x) as usize]
    }

    /// The values as 8-bit grey levels, linear (no sRGB curve): `round(255 * value)`.
    pub fn to_luma8(&self) -> Vec<u8> {
        self.values
            .iter()
            .map(|&v| {
                let v = if v.is_finite() {
                    v.clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (v * 255.0).round() as u8
            })
            .collect()
    }

    /// Writes an 8-bit greyscale PNG of the linear values (thin = white). The values are not
    /// sRGB-encoded: sample the file as a linear (UNORM) texture. Creates missing directories.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        if self.size == 0 || self.values.len() != (self.size as usize).pow(2) {
            return Err(LucentError::file(
                path,
                format!(
                    "thickness map of size {} holds {} values",
                    self.size,
                    self.values.len()
                ),
            ));
        }
        let mut encoded = Vec::new();
        image::codecs::png::PngEncoder::new(&mut encoded)
            .write_image(
                &self.to_luma8(),
                self.size,
                self.size,
                ExtendedColorType::L8,
            )
            .map_err(|e| LucentError::file(path, format!("PNG encoding failed: {e}")))?;
        crate::files::write_file_atomic(path, &encoded)
    }
}

/// Bakes a [`ThicknessMap`] of `options.texture_size` texels square over `mesh`'s UV charts.
///
/// The mesh needs texture coordinates (an error otherwise). Each covered texel is baked from its
/// point on the triangle (barycentric position), along the interpolated vertex normal, or the
/// triangle's own normal where the interpolated one vanishes; its rays ignore that triangle.
/// [`BakeStats::samples`] counts covered texels.
pub fn bake_texture(mesh: &Mesh, options: &BakeOptions) -> Result<(ThicknessMap, BakeStats)> {
    let start = Instant::now();
    let size = options.texture_size;
    if size == 0 || size > MAX_TEXTURE_SIZE {
        return Err(LucentError::InvalidInput(format!(
            "thickness texture bake: texture size {size} (must be 1 to {MAX_TEXTURE_SIZE})"
        )));
    }
    let baker = Baker::new(mesh, options)?;
    if mesh.uvs.is_empty() {
        return Err(LucentError::InvalidInput(
            "thickness texture bake: the mesh has no texture coordinates (bake per vertex \
             instead, or give it UVs)"
                .into(),
        ));
    }
    let (texels, points) = rasterize(mesh, size);
    if texels.is_empty() {
        // Baking nothing would write an all-black map: "thick everywhere", silently.
        return Err(LucentError::InvalidInput(no_coverage_message(mesh, size)));
    }
    let (baked, stats) = baker.run(&points, start);
    let n = (size as usize).pow(2);
    let mut values = vec![0.0f32; n];
    let mut coverage = vec![false; n];
    for (&texel, value) in texels.iter().zip(baked) {
        values[texel] = value;
        coverage[texel] = true;
    }
    let mut filled = coverage.clone();
    dilate(&mut values, &mut filled, size as usize, DILATION_RINGS);
    Ok((
        ThicknessMap {
            size,
            values,
            coverage,
        },
        stats,
    ))
}

/// Why a mesh's UVs cover no texel centre of a `size` map, with the numbers.
fn no_coverage_message(mesh: &Mesh, size: u32) -> String {
    let (lo, hi) = mesh.uvs.iter().filter(|uv| uv.is_finite()).fold(
        (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
        |(lo, hi), uv| (lo.min(*uv), hi.max(*uv)),
    );
    let texel = 1.0 / size as f32;
    let mut with_area = 0usize;
    let mut largest = 0.0f32;
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| mesh.uvs[tri[k] as usize]);
        let area = 0.5 * cross2(b - a, c - a).abs();
        if area.is_finite() && area > 0.0 {
            with_area += 1;
            largest = largest.max(area);
        }
    }
    let why = if !(lo.x < 1.0 && lo.y < 1.0 && hi.x > 0.0 && hi.y > 0.0) {
        "they lie outside [0, 1] (the baker clips, it does not wrap)".to_string()
    } else if with_area == 0 {
        "every triangle has zero UV area".to_string()
    } else {
        format!(
            "no triangle's UVs contain a texel centre (the largest covers {:.2} texels)",
            largest / (texel * texel)
        )
    };
    format!(
        "thickness texture bake: the mesh's UVs cover no texel of the {size}x{size} map, so \
         the map would be empty (black: thick everywhere): its {} triangles' UVs span u {:.5} \
         to {:.5}, v {:.5} to {:.5}, and {why}; bake per vertex (--per-vertex) or give the \
         mesh a UV layout in [0, 1]",
        mesh.triangle_count(),
        lo.x,
        hi.x,
        lo.y,
        hi.y
    )
}

/// 2D cross product (twice the signed area of the triangle `o, o + a, o + b`).
fn cross2(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

/// Covered texel indices and their sample points, in triangle order.
fn rasterize(mesh: &Mesh, size: u32) -> (Vec<usize>, Vec<SamplePoint>) {
    let s = size as usize;
    let scale = size as f32;
    let mut taken = vec![false; s * s];
    let mut texels = Vec::new();
    let mut points = Vec::new();
    let mut face_normals: Option<Vec<Vec3>> = None;
    for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
        let idx = [0, 1, 2].map(|k| tri[k] as usize);
        let uv = idx.map(|i| mesh.uvs[i] * scale);
        let area = cross2(uv[1] - uv[0], uv[2] - uv[0]);
        // A triangle with no UV area covers no texel (and would divide by zero below).
        if area.abs() <= 1e-12 || !area.is_finite() {
            continue;
        }
        let lo = uv[0].min(uv[1]).min(uv[2]);
        let hi = uv[0].max(uv[1]).max(uv[2]);
        // Texel centres x + 0.5 within [lo, hi], clipped to the image.
        let range = |lo: f32, hi: f32| {
            let first = (lo - 0.5).ceil().clamp(0.0, scale);
            let last = (hi - 0.5).floor().clamp(-1.0, scale - 1.0);
            (first as i64, last as i64)
        };
        let (x0, x1) = range(lo.x, hi.x);
        let (y0, y1) = range(lo.y, hi.y);
        if x0 > x1 || y0 > y1 {
            continue;
        }
        let pos = idx.map(|i| mesh.positions[i]);
        let nrm = idx.map(|i| mesh.normals[i]);
        let geometric = (pos[1] - pos[0]).cross(pos[2] - pos[0]);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let texel = y as usize * s + x as usize;
                if taken[texel] {
                    continue;
                }
                let c = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w0 = cross2(uv[2] - uv[1], c - uv[1]) / area;
                let w1 = cross2(uv[0] - uv[2], c - uv[2]) / area;
                let w2 = 1.0 - w0 - w1;
                // A small tolerance so texel centres on shared edges are not lost to rounding.
                const TOL: f32 = -1e-5;
                if w0 < TOL || w1 < TOL || w2 < TOL {
                    continue;
                }
                let w = Vec3::new(w0, w1, w2).max(Vec3::ZERO);
                let w = w / (w.x + w.y + w.z);
                taken[texel] = true;
                let mut normal = nrm[0] * w.x + nrm[1] * w.y + nrm[2] * w.z;
                if !usable(normal) {
                    // Opposite vertex normals (or zero ones) cancel: the triangle's own facing is
                    // the best guess of where the inside is, then its corners' face normals.
                    normal = if usable(geometric) {
                        geometric
                    } else {
                        let f = face_normals.get_or_insert_with(|| area_weighted_normals(mesh));
                        f[idx[0]] * w.x + f[idx[1]] * w.y + f[idx[2]] * w.z
                    };
                }
                texels.push(texel);
                points.push(SamplePoint {
                    position: pos[0] * w.x + pos[1] * w.y + pos[2] * w.z,
                    normal,
                    triangle: Some(t as u32),
                });
            }
        }
    }
    (texels, points)
}

/// Grows the filled region by up to `rings` texels: each round, every unfilled texel with a
/// filled 8-neighbour takes their mean.
fn dilate(values: &mut [f32], filled: &mut [bool], size: usize, rings: u32) {
    for _ in 0..rings {
        let mut updates = Vec::new();
        for y in 0..size {
            for x in 0..size {
                if filled[y * size + x] {
                    continue;
                }
                let (mut sum, mut count) = (0.0f32, 0u32);
                for ny in y.saturating_sub(1)..=(y + 1).min(size - 1) {
                    for nx in x.saturating_sub(1)..=(x + 1).min(size - 1) {
                        if filled[ny * size + nx] {
                            sum += values[ny * size + nx];
                            count += 1;
                        }
                    }
                }
                if count > 0 {
                    updates.push((y * size + x, sum / count as f32));
                }
            }
        }
        if updates.is_empty() {
            return;
        }
        for (i, v) in updates {
            values[i] = v;
            filled[i] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dilation_grows_one_ring_per_round() {
        let size = 9;
        let mut values = vec![0.0; size * size];
        let mut filled = vec![false; size * size];
        values[4 * size + 4] = 0.5;
        filled[4 * size + 4] = true;
        dilate(&mut values, &mut filled, size, 2);
        for y in 0..size {
            for x in 0..size {
                let ring = (x as i32 - 4).abs().max((y as i32 - 4).abs());
                let i = y * size + x;
                assert_eq!(filled[i], ring <= 2, "({x},{y})");
                assert_eq!(values[i], if ring <= 2 { 0.5 } else { 0.0 });
            }
        }
    }

    #[test]
    fn uvs_that_cover_no_texel_are_refused_with_the_numbers() {
        let mut mesh = Mesh::generate(crate::scene::Shape::Sphere { radius: 1.0 }, 8, 4);
        // Every UV squeezed into a speck smaller than a texel.
        for uv in &mut mesh.uvs {
            *uv = Vec2::splat(0.3) + *uv * 1e-4;
        }
        let options = BakeOptions {
            rays: 4,
            texture_size: 64,
            ..BakeOptions::default()
        };
        let e = bake_texture(&mesh, &options).unwrap_err().to_string();
        assert!(
            e.contains("cover no texel of the 64x64 map") && e.contains("u 0.30000 to 0.30010"),
            "{e}"
        );
        assert!(e.contains("--per-vertex"), "{e}");
        for uv in &mut mesh.uvs {
            *uv += Vec2::splat(5.0);
        }
        let e = bake_texture(&mesh, &options).unwrap_err().to_string();
        assert!(e.contains("outside [0, 1]"), "{e}");
    }

    #[test]
    fn rasterizer_covers_each_texel_centre_once() {
        // Two triangles making the unit UV square: every texel exactly once.
        let mesh = Mesh::generate(crate::scene::Shape::Plane { half_size: 1.0 }, 1, 1);
        let (texels, points) = rasterize(&mesh, 16);
        assert_eq!(texels.len(), 256);
        let mut seen = texels.clone();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), 256);
        // Texel (x, y) maps to uv ((x+.5)/16, (y+.5)/16) and the plane maps uv to xz.
        for (&t, p) in texels.iter().zip(&points) {
            let (x, y) = ((t % 16) as f32, (t / 16) as f32);
            let want = Vec3::new((x + 0.5) / 8.0 - 1.0, 0.0, (y + 0.5) / 8.0 - 1.0);
            assert!((p.position - want).length() < 1e-5, "{t}: {}", p.position);
        }
    }
}
