//! lucent against the path-traced truth: loading the truths `tools/truth` renders (Mitsuba 3
//! `volpath`, `tools/truth/README.md`) and measuring a lucent frame against one, exactly as
//! `tools/truth/compare.py` does, so neither the tests nor `lucent report truth` need Mitsuba.
//!
//! A truth directory holds `scenes/NAME.toml` (a lucent scene file) and, for each scene that has
//! been rendered, `truths/NAME.exr` (linear RGB radiance), `truths/NAME.coverage.exr` (the
//! fraction of each pixel's camera rays that hit an object) and `truths/NAME.json` (sample
//! count, seconds, noise).
//!
//! What is measured, over the object's pixels ([`object_mask`]: wholly covered, eroded by one
//! pixel, since a tessellated mesh and an analytic sphere differ by a fraction of a pixel at the
//! silhouette):
//! - **error**: the relative mean absolute error `sum |L - T| / sum T` over the three channels;
//! - **energy**: `sum L / sum T` per channel (1 = as much light as the truth);
//! - **FLIP**: the mean perceptual difference (NVIDIA's FLIP) of the two images after the one
//!   tonemap lucent shows them with (the scene's exposure, ACES, sRGB), over the same pixels.

use std::path::{Path, PathBuf};

use crate::reference::tonemap::display_rgba8;
use crate::reference::DVec3;
use crate::scene::Scene;
use crate::{LucentError, Result};

/// How many pixels the object mask is eroded by (see the module docs).
pub const ERODE_PIXELS: usize = 1;

/// One truth: the scene, its path-traced radiance and which pixels are the object's.
#[derive(Clone)]
pub struct Truth {
    /// The scene's name (its file stem).
    pub name: String,
    /// The scene file.
    pub scene_path: PathBuf,
    /// The scene, loaded.
    pub scene: Scene,
    /// The truth's size.
    pub width: u32,
    /// The truth's size.
    pub height: u32,
    /// Linear RGBA f32 radiance, rows top first.
    pub radiance: Vec<f32>,
    /// The object's pixels ([`object_mask`]).
    pub mask: Vec<bool>,
    /// Samples per pixel over all seeds, from the JSON (when it says).
    pub spp: Option<u64>,
    /// The truth's noise (half the relative difference of two seeds' 4x4-pixel block means),
    /// from the JSON (when it says).
    pub noise: Option<f64>,
    /// Parts of the frame measured apart as well (`truths/NAME.regions.toml`).
    pub regions: Vec<TruthRegion>,
}

/// A part of a truth's frame measured on its own as well as with the rest (a head's ear: the
/// thin part where screen-space diffusion and the truth differ most), from
/// `truths/NAME.regions.toml`:
///
/// ```toml
/// [[region]]
/// name = "ear"             # letters, digits, '-' and '_'
/// rect = [154, 80, 184, 130] # x0, y0, x1, y1 in the truth's pixels (x1, y1 excluded)
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TruthRegion {
    /// Its name (the report's `NAME-REGION`).
    pub name: String,
    /// `[x0, y0, x1, y1]`, pixels of the truth's size, the ends excluded.
    pub rect: [u32; 4],
}

impl Truth {
    /// How many pixels are the object's.
    pub fn object_pixels(&self) -> usize {
        self.mask.iter().filter(|&&m| m).count()
    }

    /// This truth measured over `region` only (its object pixels inside the rectangle), named
    /// `NAME-REGION`, without regions of its own.
    pub fn region(&self, region: &TruthRegion) -> Truth {
        let [x0, y0, x1, y1] = region.rect.map(|v| v as usize);
        let width = self.width as usize;
        let mask = self
            .mask
            .iter()
            .enumerate()
            .map(|(i, &m)| {
                let (x, y) = (i % width, i / width);
                m && (x0..x1).contains(&x) && (y0..y1).contains(&y)
            })
            .collect();
        Truth {
            name: format!("{}-{}", self.name, region.name),
            mask,
            regions: Vec::new(),
            ..self.clone()
        }
    }
}

/// The regions of truth `name` in `truths` (none without a regions file); each must have a
/// name of letters, digits, `-` and `_`, and a non-empty rectangle inside `width` x `height`.
/// Errors name the file.
pub fn load_regions(
    truths: &Path,
    name: &str,
    width: u32,
    height: u32,
) -> Result<Vec<TruthRegion>> {
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Regions {
        region: Vec<RegionToml>,
    }
    #[derive(serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    struct RegionToml {
        name: String,
        rect: [u32; 4],
    }
    let path = truths.join(format!("{name}.regions.toml"));
    if !path.exists() {
        return Ok(Vec::new());
    }
    let bytes = crate::files::read_capped(&path, 1 << 20, "regions file")
        .map_err(|e| LucentError::file(&path, e))?;
    let text = String::from_utf8(bytes).map_err(|_| LucentError::file(&path, "not UTF-8"))?;
    let parsed: Regions =
        toml::from_str(&text).map_err(|e| LucentError::file(&path, e.message().to_string()))?;
    parsed
        .region
        .into_iter()
        .map(|r| {
            let [x0, y0, x1, y1] = r.rect;
            let named = !r.name.is_empty()
                && r.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
            if !named {
                return Err(LucentError::file(
                    &path,
                    format!("region name '{}': use letters, digits, '-' and '_'", r.name),
                ));
            }
            if !(x0 < x1 && y0 < y1 && x1 <= width && y1 <= height) {
                return Err(LucentError::file(
                    &path,
                    format!(
                        "region '{}': rect {:?} is not a non-empty rectangle inside the \
                         truth's {width}x{height} pixels",
                        r.name, r.rect
                    ),
                ));
            }
            Ok(TruthRegion {
                name: r.name,
                rect: r.rect,
            })
        })
        .collect()
}

/// A lucent frame measured against a truth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TruthError {
    /// `sum |L - T| / sum T` over the object's pixels and the three channels.
    pub error: f64,
    /// `sum L / sum T` per channel.
    pub energy: [f64; 3],
    /// The mean FLIP over the object's pixels, after the scene's tonemap.
    pub flip: f64,
}

/// A linear EXR as RGBA f32 rows and its size; errors name the file.
pub fn read_exr(path: &Path) -> Result<(u32, u32, Vec<f32>)> {
    let image = image::open(path)
        .map_err(|e| LucentError::InvalidInput(format!("{}: {e}", path.display())))?;
    Ok((image.width(), image.height(), image.to_rgba32f().into_raw()))
}

/// The pixels whose coverage (first channel) is whole (every camera ray hit an object), less
/// `erode` pixels at the edge of that region.
pub fn object_mask(coverage: &[f32], width: usize, height: usize, erode: usize) -> Vec<bool> {
    let mut mask: Vec<bool> = (0..width * height)
        .map(|i| coverage.get(i * 4).is_some_and(|&c| c >= 0.999))
        .collect();
    for _ in 0..erode {
        let inside = |x: i64, y: i64, m: &[bool]| {
            x >= 0
                && y >= 0
                && (x as usize) < width
                && (y as usize) < height
                && m[y as usize * width + x as usize]
        };
        mask = (0..width * height)
            .map(|i| {
                let (x, y) = ((i % width) as i64, (i / width) as i64);
                (-1..=1).all(|dy| (-1..=1).all(|dx| inside(x + dx, y + dy, &mask)))
            })
            .collect();
    }
    mask
}

/// The scenes of `dir/scenes` that have a truth in `dir/truths`, by name, sorted.
pub fn truth_names(dir: &Path) -> Result<Vec<String>> {
    let scenes = dir.join("scenes");
    let entries = std::fs::read_dir(&scenes).map_err(|e| {
        LucentError::InvalidInput(format!(
            "{}: {e} (a truth directory holds scenes/ and truths/: tools/truth/README.md)",
            scenes.display()
        ))
    })?;
    let mut names = Vec::new();
    for entry in entries.flatten() {
        let path = entry.path();
        if path.extension().is_some_and(|e| e == "toml") {
            if let Some(stem) = path.file_stem().and_then(|s| s.to_str()) {
                if dir.join("truths").join(format!("{stem}.exr")).is_file() {
                    names.push(stem.to_string());
                }
            }
        }
    }
    names.sort();
    Ok(names)
}

/// Loads truth `name` of `dir`: its scene, radiance, coverage (both must have one size) and
/// JSON.
pub fn load_truth(dir: &Path, name: &str) -> Result<Truth> {
    let scene_path = dir.join("scenes").join(format!("{name}.toml"));
    let scene_text = scene_path.to_str().ok_or_else(|| {
        LucentError::InvalidInput(format!("{}: not a UTF-8 path", scene_path.display()))
    })?;
    // Baked as a frame of it is (GDC 2011's thickness; a medium's distances), through the
    // default cache.
    let scene = crate::bake::scene::load_scene_baked(scene_text)?;
    let truths = dir.join("truths");
    let (width, height, radiance) = read_exr(&truths.join(format!("{name}.exr")))?;
    let coverage_path = truths.join(format!("{name}.coverage.exr"));
    let (cw, ch, coverage) = read_exr(&coverage_path)?;
    if (cw, ch) != (width, height) {
        return Err(LucentError::InvalidInput(format!(
            "{}: {cw}x{ch}, but the truth is {width}x{height}",
            coverage_path.display()
        )));
    }
    let mask = object_mask(&coverage, width as usize, height as usize, ERODE_PIXELS);
    let json_path = truths.join(format!("{name}.json"));
    let json: Option<serde_json::Value> = std::fs::read_to_string(&json_path)
        .ok()
        .map(|text| {
            serde_json::from_str(&text)
                .map_err(|e| LucentError::InvalidInput(format!("{}: {e}", json_path.display())))
        })
        .transpose()?;
    let field = |key: &str| json.as_ref().and_then(|j| j.get(key).cloned());
    let regions = load_regions(&truths, name, width, height)?;
    Ok(Truth {
        name: name.to_string(),
        scene_path,
        scene,
        width,
        height,
        radiance,
        mask,
        spp: field("spp_total").and_then(|v| v.as_u64()),
        noise: field("noise_4x4").and_then(|v| v.as_f64()),
        regions,
    })
}

/// Measures lucent's linear HDR frame (RGBA f32, the truth's size) against `truth`. A
/// non-finite lucent pixel on the object is an error, not a number.
pub fn measure(truth: &Truth, lucent: &[f32]) -> Result<TruthError> {
    let pixels = (truth.width * truth.height) as usize;
    if lucent.len() != pixels * 4 {
        return Err(LucentError::InvalidInput(format!(
            "truth {}: lucent's frame has {} floats, the truth's {}x{} RGBA needs {}",
            truth.name,
            lucent.len(),
            truth.width,
            truth.height,
            pixels * 4
        )));
    }
    let (mut diff, mut total) = (0.0f64, 0.0f64);
    let (mut lucent_sum, mut truth_sum) = ([0.0f64; 3], [0.0f64; 3]);
    for i in (0..pixels).filter(|&i| truth.mask[i]) {
        for c in 0..3 {
            let (l, t) = (
                f64::from(lucent[i * 4 + c]),
                f64::from(truth.radiance[i * 4 + c]),
            );
            if !l.is_finite() {
                return Err(LucentError::InvalidInput(format!(
                    "truth {}: lucent's pixel {i} channel {c} is {l}",
                    truth.name
                )));
            }
            diff += (l - t).abs();
            total += t;
            lucent_sum[c] += l;
            truth_sum[c] += t;
        }
    }
    // A truth with no light on its object has no relative error: say so rather than divide by 0.
    if total <= 0.0 {
        return Err(LucentError::InvalidInput(format!(
            "truth {}: no light on the object's {} pixels",
            truth.name,
            truth.object_pixels()
        )));
    }
    let energy = std::array::from_fn(|c| lucent_sum[c] / truth_sum[c].max(f64::MIN_POSITIVE));
    Ok(TruthError {
        error: diff / total,
        energy,
        flip: object_flip(truth, lucent)?,
    })
}

/// The mean FLIP over the object's pixels between the truth and lucent's frame, both through
/// the scene's tonemap.
fn object_flip(truth: &Truth, lucent: &[f32]) -> Result<f64> {
    let exposure = f64::from(truth.scene.exposure);
    let display = |rgba: &[f32]| -> Vec<u8> {
        rgba.chunks_exact(4)
            .flat_map(|p| {
                let c = DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2]));
                display_rgba8(c, exposure)
            })
            .collect()
    };
    let errors = crate::images::compare::flip_errors_rgba8(
        &display(&truth.radiance),
        &display(lucent),
        truth.width,
        truth.height,
    )?;
    let (sum, n) = errors
        .iter()
        .zip(&truth.mask)
        .filter(|(_, &m)| m)
        .fold((0.0f64, 0usize), |(s, n), (&e, _)| {
            (s + f64::from(e), n + 1)
        });
    Ok(sum / n.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mask_is_whole_coverage_eroded() {
        // A 5x5 image whose middle 3x3 is wholly covered: one pixel left after erosion.
        let coverage: Vec<f32> = (0..25)
            .flat_map(|i| {
                let (x, y) = (i % 5, i / 5);
                let c = if (1..4).contains(&x) && (1..4).contains(&y) {
                    1.0
                } else {
                    0.5
                };
                [c, c, c, 1.0]
            })
            .collect();
        assert_eq!(
            object_mask(&coverage, 5, 5, 0)
                .iter()
                .filter(|&&m| m)
                .count(),
            9
        );
        let eroded = object_mask(&coverage, 5, 5, 1);
        assert_eq!(eroded.iter().filter(|&&m| m).count(), 1);
        assert!(eroded[12]);
    }

    #[test]
    fn regions_are_read_checked_and_cut_the_mask() {
        let dir = std::env::temp_dir().join(format!("lucent-regions-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |text: &str| std::fs::write(dir.join("t.regions.toml"), text).unwrap();
        assert_eq!(load_regions(&dir, "t", 8, 6).unwrap(), Vec::new());
        write("[[region]]\nname = \"ear\"\nrect = [2, 1, 5, 4]\n");
        let regions = load_regions(&dir, "t", 8, 6).unwrap();
        assert_eq!(
            regions,
            [TruthRegion {
                name: "ear".into(),
                rect: [2, 1, 5, 4]
            }]
        );
        for (bad, says) in [
            (
                "[[region]]\nname = \"ear\"\nrect = [2, 1, 9, 4]\n",
                "inside the truth's 8x6",
            ),
            (
                "[[region]]\nname = \"ear\"\nrect = [5, 1, 5, 4]\n",
                "non-empty",
            ),
            (
                "[[region]]\nname = \"the ear\"\nrect = [2, 1, 5, 4]\n",
                "letters, digits",
            ),
            ("[[region]]\nname = \"ear\"\n", "rect"),
        ] {
            write(bad);
            let e = load_regions(&dir, "t", 8, 6).unwrap_err().to_string();
            assert!(
                e.contains("t.regions.toml") && e.contains(says),
                "{bad}: {e}"
            );
        }
        // The region's mask is the object's mask inside the rectangle.
        let truth = Truth {
            name: "t".into(),
            scene_path: dir.join("t.toml"),
            scene: crate::scene::builtin("smoke").unwrap(),
            width: 8,
            height: 6,
            radiance: vec![1.0; 8 * 6 * 4],
            mask: (0..48).map(|i| i % 8 != 3).collect(),
            spp: None,
            noise: None,
            regions,
        };
        let ear = truth.region(&truth.regions[0]);
        assert_eq!(ear.name, "t-ear");
        assert!(ear.regions.is_empty());
        // Rows 1-3, columns 2 and 4 (column 3 is not the object's).
        assert_eq!(ear.object_pixels(), 6);
        assert!(ear.mask[8 + 2] && !ear.mask[8 + 3] && ear.mask[3 * 8 + 4] && !ear.mask[4 * 8 + 2]);
        std::fs::remove_dir_all(dir).ok();
    }
}
