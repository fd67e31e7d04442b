//! Image files: what a render writes and what tests read back.
//!
//! - [`write_png_rgba8`]: display-ready (sRGB-encoded) 8-bit images, e.g. the final frame, goldens.
//! - [`write_exr_rgba32f`]: linear floating-point images, e.g. HDR lighting buffers or thickness
//!   maps, where 8 bits would clip or band. Written with the `image` crate's OpenEXR encoder.
//! - [`read_png_rgba8`]: load a PNG (golden images) as tightly packed RGBA8.
//! - [`f16_bytes_to_f32`]: turn an `R16G16B16A16_SFLOAT` readback into `f32`s for EXR or checks.
//!
//! Every writer writes through `crate::files::write_file_atomic` (never half a file, missing
//! parent directories created); every error names the file.

use std::io::Cursor;
use std::path::Path;

use image::{ExtendedColorType, ImageEncoder, ImageFormat, ImageReader};

use crate::error::{LucentError, Result};
use crate::files::write_file_atomic;

/// Writes a PNG from tightly packed, row-major (top row first) RGBA8 pixels.
///
/// `rgba` must hold exactly `width * height * 4` bytes.
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    check_len(path, width, height, 4, rgba.len())?;
    let mut encoded = Vec::new();
    image::codecs::png::PngEncoder::new(&mut encoded)
        .write_image(rgba, width, height, ExtendedColorType::Rgba8)
        .map_err(|e| LucentError::file(path, format!("PNG encoding failed: {e}")))?;
    write_file_atomic(path, &encoded)
}

/// Writes an OpenEXR file from tightly packed, row-major RGBA `f32` pixels in linear colour.
///
/// `rgba` must hold exactly `width * height * 4` floats. Values are stored as they are (no
/// clamping, no transfer function), NaN and infinities included.
pub fn write_exr_rgba32f(path: &Path, width: u32, height: u32, rgba: &[f32]) -> Result<()> {
    check_len(path, width, height, 4, rgba.len())?;
    let mut encoded = Cursor::new(Vec::new());
    image::codecs::openexr::OpenExrEncoder::new(&mut encoded)
        .write_image(
            bytemuck::cast_slice(rgba),
            width,
            height,
            ExtendedColorType::Rgba32F,
        )
        .map_err(|e| LucentError::file(path, format!("OpenEXR encoding failed: {e}")))?;
    write_file_atomic(path, encoded.get_ref())
}

/// Largest PNG file read (2 GiB, as for a texture): goldens and screenshots are far smaller.
const MAX_PNG_FILE_BYTES: u64 = 2 << 30;

/// Reads a PNG file as `(width, height, rgba8)`, converting grey, RGB or 16-bit PNGs to RGBA8.
pub fn read_png_rgba8(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    let (file, _) = crate::files::open_regular(path, MAX_PNG_FILE_BYTES, "PNG")
        .map_err(|e| LucentError::file(path, e))?;
    let image = ImageReader::with_format(std::io::BufReader::new(file), ImageFormat::Png)
        .decode()
        .map_err(|e| LucentError::file(path, format!("not a readable PNG: {e}")))?
        .into_rgba8();
    Ok((image.width(), image.height(), image.into_raw()))
}

/// Converts little-endian IEEE half floats (e.g. an `R16G16B16A16_SFLOAT` image read back from the
/// GPU) to `f32`. A trailing odd byte is ignored.
pub fn f16_bytes_to_f32(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|b| half::f16::from_le_bytes([b[0], b[1]]).to_f32())
        .collect()
}

fn check_len(path: &Path, width: u32, height: u32, channels: u64, len: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(LucentError::file(
            path,
            format!("cannot write an empty {width}x{height} image"),
        ));
    }
    let expected = u64::from(width) * u64::from(height) * channels;
    if expected != len as u64 {
        return Err(LucentError::file(
            path,
            format!("{width}x{height} image needs {expected} values, got {len}"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lucent-output-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn png_round_trip_creates_directories() {
        let dir = temp_dir("png");
        let path = dir.join("a/b/img.png");
        let rgba: Vec<u8> = (0..3 * 2 * 4).map(|i| (i * 10) as u8).collect();
        write_png_rgba8(&path, 3, 2, &rgba).unwrap();
        assert_eq!(read_png_rgba8(&path).unwrap(), (3, 2, rgba));
        let leftovers: Vec<_> = std::fs::read_dir(path.parent().unwrap()).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "temporary file left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn exr_is_written_and_decodes_to_the_same_floats() {
        let dir = temp_dir("exr");
        let path = dir.join("img.exr");
        let rgba = [0.0, 0.5, 1.0, 1.0, 2.5, 1000.0, 0.001, 0.25];
        write_exr_rgba32f(&path, 2, 1, &rgba).unwrap();
        let decoded = image::open(&path).unwrap().into_rgba32f();
        assert_eq!(decoded.into_raw(), rgba.to_vec());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn errors_name_the_file() {
        let dir = temp_dir("errors");
        let path = dir.join("short.png");
        let message = write_png_rgba8(&path, 2, 2, &[0; 3])
            .unwrap_err()
            .to_string();
        assert!(message.contains("short.png"), "{message}");
        let message = read_png_rgba8(&dir.join("missing.png"))
            .unwrap_err()
            .to_string();
        assert!(message.contains("missing.png"), "{message}");
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("bad.png"), b"not a png").unwrap();
        let message = read_png_rgba8(&dir.join("bad.png"))
            .unwrap_err()
            .to_string();
        assert!(message.contains("bad.png"), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn half_floats_convert() {
        let values = [0.0f32, 1.0, -2.5, 65504.0];
        let bytes: Vec<u8> = values
            .iter()
            .flat_map(|v| half::f16::from_f32(*v).to_le_bytes())
            .collect();
        assert_eq!(f16_bytes_to_f32(&bytes), values.to_vec());
        let inf = f16_bytes_to_f32(&half::f16::INFINITY.to_le_bytes());
        assert!(inf[0].is_infinite());
    }
}
