//! Perceptual image comparison with NVIDIA's FLIP, for golden-image tests and reports.
//!
//! Exact pixel equality is the wrong test for renders: a CPU driver (lavapipe) and a GPU round,
//! rasterise edges and evaluate `exp2`/`pow` slightly differently. FLIP estimates the difference a
//! viewer would notice when flipping between two images (0 = none, 1 = maximal), per pixel.
//!
//! - [`flip_rgba8`]: compare two sRGB RGBA8 images; gives mean and max error, the fraction of
//!   clearly visible pixels, and a magma-coloured error map (black = same, yellow = very different).
//! - [`compare_with_golden`]: what a golden test calls. It never creates a golden: a missing one
//!   is an error that says how to bless it (`tools/bless-goldens.sh`), so a new or changed image
//!   is always looked at by a person before it becomes the reference. On failure it writes
//!   `NAME.actual.png` and `NAME.diff.png` next to each other for inspection.

use std::path::{Path, PathBuf};

use crate::error::{LucentError, Result};
use crate::images::output::{read_png_rgba8, write_png_rgba8};

/// Limits a test image must stay within to count as equal to its reference.
///
/// A comparison passes when `mean FLIP <= mean` and the fraction of pixels with
/// `FLIP > pixel_threshold` is `<= max_fraction_above`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlipThresholds {
    /// Largest accepted mean FLIP error over the image.
    pub mean: f32,
    /// Largest accepted fraction (0..1) of pixels whose FLIP error exceeds `pixel_threshold`.
    pub max_fraction_above: f32,
    /// Per-pixel FLIP error above which a pixel counts as visibly different.
    pub pixel_threshold: f32,
}

impl Default for FlipThresholds {
    /// `mean` 0.02, `pixel_threshold` 0.3, `max_fraction_above` 0.002.
    ///
    /// Why these: the differences a golden must tolerate are driver noise (rounding, edge coverage,
    /// `exp2`/`pow` precision), which is small and spread thin, while the regressions it must catch
    /// (a wrong shading term, a missing light, a shifted blur) are large over a whole region. A
    /// mean of 0.02 is about twice what 1-LSB noise on every seventh channel value of every pixel
    /// gives (mean 0.011, max 0.036 in the unit tests) and a tenth of what one recoloured object
    /// covering a fifth of the image gives (mean 0.21, 24% of pixels above 0.3). A pixel above 0.3 is a clearly visible
    /// difference; allowing 0.2% of them (about 150 pixels at 320x240) accepts a silhouette
    /// rasterised a pixel differently but not a missing or misplaced object. These are starting
    /// values: tighten them once lavapipe-versus-GPU differences of the real scenes are measured.
    fn default() -> Self {
        Self {
            mean: 0.02,
            max_fraction_above: 0.002,
            pixel_threshold: 0.3,
        }
    }
}

/// The outcome of one FLIP comparison.
#[derive(Debug, Clone, PartialEq)]
pub struct FlipResult {
    /// Mean FLIP error over all pixels (0 for identical images).
    pub mean: f32,
    /// Largest per-pixel FLIP error.
    pub max: f32,
    /// Fraction (0..1) of pixels whose error exceeds the `pixel_threshold` it was computed with
    /// (the default threshold for [`flip_rgba8`]).
    pub fraction_above: f32,
    /// The error map through the magma colour map, RGBA8 (alpha 255), same size as the inputs.
    pub error_map_rgba: Vec<u8>,
}

impl FlipResult {
    /// Whether this result is within `thresholds` (see [`FlipThresholds`]).
    pub fn within(&self, thresholds: &FlipThresholds) -> bool {
        self.mean <= thresholds.mean && self.fraction_above <= thresholds.max_fraction_above
    }
}

/// Compares two sRGB-encoded RGBA8 images (alpha ignored) with FLIP at 67 pixels per degree
/// (a 0.7 m viewing distance from a 24" 4K screen, FLIP's default).
///
/// `fraction_above` uses the default [`FlipThresholds::pixel_threshold`]; use
/// [`flip_rgba8_with_threshold`] for another one.
pub fn flip_rgba8(reference: &[u8], test: &[u8], width: u32, height: u32) -> Result<FlipResult> {
    flip_rgba8_with_threshold(
        reference,
        test,
        width,
        height,
        FlipThresholds::default().pixel_threshold,
    )
}

/// [`flip_rgba8`] with `fraction_above` counted against `pixel_threshold`.
pub fn flip_rgba8_with_threshold(
    reference: &[u8],
    test: &[u8],
    width: u32,
    height: u32,
    pixel_threshold: f32,
) -> Result<FlipResult> {
    check_rgba8_pair(reference, test, width, height)?;
    let error_map = flip_map(reference, test, width, height);
    let pool = nv_flip::FlipPool::from_image(&error_map);
    let errors = error_map.to_vec();
    let above = errors.iter().filter(|&&e| e > pixel_threshold).count();
    let error_map_rgba = error_map
        .apply_color_lut(&nv_flip::magma_lut())
        .to_vec()
        .chunks_exact(3)
        .flat_map(|rgb| [rgb[0], rgb[1], rgb[2], 255])
        .collect();
    Ok(FlipResult {
        mean: pool.mean(),
        max: errors.iter().copied().fold(0.0, f32::max),
        fraction_above: above as f32 / errors.len() as f32,
        error_map_rgba,
    })
}

/// The per-pixel FLIP errors of two sRGB RGBA8 images (alpha ignored), rows top first, as
/// [`flip_rgba8`] computes them: for a mean over some of the pixels (an object's, say).
pub fn flip_errors_rgba8(
    reference: &[u8],
    test: &[u8],
    width: u32,
    height: u32,
) -> Result<Vec<f32>> {
    check_rgba8_pair(reference, test, width, height)?;
    Ok(flip_map(reference, test, width, height).to_vec())
}

/// Both images are `width x height` RGBA8, and not empty.
fn check_rgba8_pair(reference: &[u8], test: &[u8], width: u32, height: u32) -> Result<()> {
    let expected = u64::from(width) * u64::from(height) * 4;
    if width == 0 || height == 0 {
        return Err(LucentError::InvalidInput(format!(
            "FLIP comparison of an empty {width}x{height} image"
        )));
    }
    for (what, image) in [("reference", reference), ("test", test)] {
        if image.len() as u64 != expected {
            return Err(LucentError::InvalidInput(format!(
                "FLIP comparison: {what} image has {} bytes, {width}x{height} RGBA8 needs {expected}",
                image.len()
            )));
        }
    }
    Ok(())
}

fn flip_map(reference: &[u8], test: &[u8], width: u32, height: u32) -> nv_flip::FlipImageFloat {
    let reference = nv_flip::FlipImageRgb8::with_data(width, height, &rgba_to_rgb(reference));
    let test = nv_flip::FlipImageRgb8::with_data(width, height, &rgba_to_rgb(test));
    nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE)
}

fn rgba_to_rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// What [`compare_with_golden`] found.
#[derive(Debug, Clone)]
pub struct GoldenOutcome {
    /// The FLIP statistics and error map.
    pub result: FlipResult,
    /// Whether the image is within the thresholds.
    pub passed: bool,
    /// `<out_dir>/<name>.actual.png`, written only on failure.
    pub actual_path: Option<PathBuf>,
    /// `<out_dir>/<name>.diff.png` (the FLIP error map), written only on failure.
    pub diff_path: Option<PathBuf>,
}

/// Compare `actual` with the golden PNG at `golden_path`. A missing golden is an ERROR (never
/// created implicitly) whose message says how to bless: `tools/bless-goldens.sh`. Size mismatch is
/// an error. On failure, writes `<out_dir>/<name>.actual.png` and `<name>.diff.png` (the FLIP map)
/// and returns passed=false with their paths.
///
/// `actual` is sRGB-encoded RGBA8, `width * height * 4` bytes. On success, stale `.actual.png` /
/// `.diff.png` files from an earlier failure are removed so they cannot be mistaken for news.
pub fn compare_with_golden(
    name: &str,
    golden_path: &Path,
    actual: &[u8],
    width: u32,
    height: u32,
    thresholds: &FlipThresholds,
    out_dir: &Path,
) -> Result<GoldenOutcome> {
    if !golden_path.exists() {
        return Err(LucentError::file(
            golden_path,
            format!(
                "golden image '{name}' does not exist; goldens are never created implicitly. \
                 Render it, look at it, then bless it with `tools/bless-goldens.sh {name}`"
            ),
        ));
    }
    let (golden_width, golden_height, golden) = read_png_rgba8(golden_path)?;
    if (golden_width, golden_height) != (width, height) {
        return Err(LucentError::file(
            golden_path,
            format!(
                "golden '{name}' is {golden_width}x{golden_height} but the image is {width}x{height}; \
                 re-bless with `tools/bless-goldens.sh {name}` if the size change is intended"
            ),
        ));
    }
    let result =
        flip_rgba8_with_threshold(&golden, actual, width, height, thresholds.pixel_threshold)?;
    let passed = result.within(thresholds);
    let actual_path = out_dir.join(format!("{name}.actual.png"));
    let diff_path = out_dir.join(format!("{name}.diff.png"));
    if passed {
        let _ = std::fs::remove_file(&actual_path);
        let _ = std::fs::remove_file(&diff_path);
        return Ok(GoldenOutcome {
            result,
            passed,
            actual_path: None,
            diff_path: None,
        });
    }
    write_png_rgba8(&actual_path, width, height, actual)?;
    write_png_rgba8(&diff_path, width, height, &result.error_map_rgba)?;
    Ok(GoldenOutcome {
        result,
        passed,
        actual_path: Some(actual_path),
        diff_path: Some(diff_path),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: u32 = 64;
    const H: u32 = 48;

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lucent-compare-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    /// A smooth gradient with a grey square in the middle.
    fn picture() -> Vec<u8> {
        let mut rgba = Vec::with_capacity((W * H * 4) as usize);
        for y in 0..H {
            for x in 0..W {
                let square = (20..44).contains(&x) && (12..36).contains(&y);
                let (r, g, b) = if square {
                    (128, 128, 128)
                } else {
                    ((x * 4) as u8, (y * 5) as u8, 60)
                };
                rgba.extend_from_slice(&[r, g, b, 255]);
            }
        }
        rgba
    }

    #[test]
    fn identical_images_pass_with_zero_error() {
        let dir = temp_dir("identical");
        let golden = dir.join("golden.png");
        write_png_rgba8(&golden, W, H, &picture()).unwrap();
        let outcome = compare_with_golden(
            "same",
            &golden,
            &picture(),
            W,
            H,
            &FlipThresholds::default(),
            &dir,
        )
        .unwrap();
        assert!(outcome.passed);
        assert_eq!(outcome.result.mean, 0.0);
        assert_eq!(outcome.result.max, 0.0);
        assert_eq!(outcome.result.fraction_above, 0.0);
        assert_eq!(outcome.result.error_map_rgba.len(), (W * H * 4) as usize);
        assert!(outcome.actual_path.is_none() && outcome.diff_path.is_none());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn visibly_different_image_fails_and_writes_actual_and_diff() {
        let dir = temp_dir("different");
        let golden = dir.join("golden.png");
        write_png_rgba8(&golden, W, H, &picture()).unwrap();
        // The square turned red: what a broken shading term looks like.
        let mut actual = picture();
        for pixel in actual.chunks_exact_mut(4) {
            if pixel[..3] == [128, 128, 128] {
                pixel[..3].copy_from_slice(&[230, 20, 20]);
            }
        }
        let out = dir.join("out");
        let outcome = compare_with_golden(
            "red",
            &golden,
            &actual,
            W,
            H,
            &FlipThresholds::default(),
            &out,
        )
        .unwrap();
        assert!(!outcome.passed, "{:?}", outcome.result.mean);
        assert!(outcome.result.mean > 0.02 && outcome.result.max > 0.3);
        let actual_path = outcome.actual_path.unwrap();
        let diff_path = outcome.diff_path.unwrap();
        assert_eq!(actual_path, out.join("red.actual.png"));
        assert_eq!(diff_path, out.join("red.diff.png"));
        assert_eq!(read_png_rgba8(&actual_path).unwrap(), (W, H, actual));
        let (w, h, diff) = read_png_rgba8(&diff_path).unwrap();
        assert_eq!((w, h), (W, H));
        // Unchanged corner vs. centre of the changed square.
        assert_ne!(diff[..4], diff[((20 * W + 30) * 4) as usize..][..4]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn tiny_noise_passes() {
        let mut noisy = picture();
        for (i, v) in noisy.iter_mut().enumerate() {
            if i % 4 != 3 && i % 7 == 0 {
                *v = v.saturating_add(1);
            }
        }
        let result = flip_rgba8(&picture(), &noisy, W, H).unwrap();
        // Measured: mean 0.011, max 0.036 (quoted in the `FlipThresholds::default` docs).
        assert!(
            result.mean < 0.015 && result.max < 0.05,
            "{} {}",
            result.mean,
            result.max
        );
        assert!(
            result.within(&FlipThresholds::default()),
            "mean {} fraction above {}",
            result.mean,
            result.fraction_above
        );
    }

    #[test]
    fn missing_golden_says_how_to_bless_and_size_mismatch_is_an_error() {
        let dir = temp_dir("missing");
        let golden = dir.join("nothing.png");
        let thresholds = FlipThresholds::default();
        let message = compare_with_golden("nothing", &golden, &picture(), W, H, &thresholds, &dir)
            .unwrap_err()
            .to_string();
        assert!(message.contains("tools/bless-goldens.sh"), "{message}");
        assert!(!golden.exists(), "a missing golden must never be created");

        write_png_rgba8(&golden, W, H, &picture()).unwrap();
        let message = compare_with_golden("nothing", &golden, &[0; 16], 2, 2, &thresholds, &dir)
            .unwrap_err()
            .to_string();
        assert!(message.contains("64x48"), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn wrong_buffer_sizes_are_errors() {
        assert!(flip_rgba8(&[0; 12], &[0; 16], 2, 2).is_err());
        assert!(flip_rgba8(&[], &[], 0, 0).is_err());
    }
}
