//! Image files: what a render writes and what tests read back.
//!
//! - [`write_png_rgba8`]: display-ready (sRGB-encoded) 8-bit images, e.g. the final frame, goldens.
//! - [`write_exr_rgba32f`]: linear floating-point images, e.g. HDR lighting buffers or thickness
//!   maps, where 8 bits would clip or band. Written with the `image` crate's OpenEXR encoder.
//! - [`read_png_rgba8`]: load a PNG (golden images) as tightly packed RGBA8.
//! - [`f16_bytes_to_f32`]: turn an `R16G16B16A16_SFLOAT` readback into `f32`s for EXR or checks.
//! - [`write_file_atomic`]: the write-to-temporary-then-rename used by every writer here (and by
//!   the shader caches), so a crash or a concurrent reader never sees half a file; it writes
//!   through symlinks and into devices and FIFOs rather than replacing them.
//!
//! All writers create missing parent directories; every error names the file.

use std::io::{Cursor, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use image::{ExtendedColorType, ImageEncoder, ImageFormat, ImageReader};

use crate::error::{LucentError, Result};

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

/// Reads a PNG file as `(width, height, rgba8)`, converting grey, RGB or 16-bit PNGs to RGBA8.
pub fn read_png_rgba8(path: &Path) -> Result<(u32, u32, Vec<u8>)> {
    let (file, _) =
        crate::files::open_regular(path, crate::scene::texture::MAX_TEXTURE_FILE_BYTES, "PNG")
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

/// Writes `bytes` to `path`, never replacing what `path` is:
///
/// - a regular file, or nothing yet: atomically, into a temporary file in the same directory,
///   then renamed over `path` (a crash or a concurrent reader never sees half a file);
/// - a symlink: written through it, atomically at its target (the link stays a link, and a
///   dangling link creates its target);
/// - a character device, FIFO or socket (`/dev/null`, a pipe to another program): opened and
///   written into, as a shell redirection would; renaming over it would replace the device with
///   a file (as root, `/dev/full` became a regular file);
/// - a directory: an error.
///
/// Creates missing parent directories. The error names `path`.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = resolve_symlinks(path)?;
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => Err(LucentError::file(
            path,
            "is a directory; give a file name to write",
        )),
        Ok(m) if !m.is_file() => {
            // A device or FIFO: written into, never replaced.
            let mut file = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(|e| LucentError::file(path, format!("cannot open for writing: {e}")))?;
            file.write_all(bytes)
                .and_then(|()| file.flush())
                .map_err(|e| {
                    LucentError::file(
                        path,
                        format!("writing into {} failed: {e}", crate::files::kind_of(&m)),
                    )
                })
        }
        _ => write_regular_atomic(path, &target, bytes),
    }
}

/// `path` with every symlink of its last component followed (relative links resolved against
/// their directory); the path itself when it is no symlink. Refuses symlink loops.
fn resolve_symlinks(path: &Path) -> Result<PathBuf> {
    let mut target = path.to_path_buf();
    // The limit Linux puts on symlinks followed in one lookup.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let next = std::fs::read_link(&target)
                    .map_err(|e| LucentError::file(path, format!("cannot read symlink: {e}")))?;
                target = match target.parent() {
                    Some(parent) if next.is_relative() => parent.join(next),
                    _ => next,
                };
            }
            _ => return Ok(target),
        }
    }
    Err(LucentError::file(
        path,
        "too many levels of symbolic links (a symlink loop?)",
    ))
}

/// The temporary-then-rename write of a regular file at `target` (`path` names it in errors).
fn write_regular_atomic(path: &Path, target: &Path, bytes: &[u8]) -> Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let file_name = target
        .file_name()
        .ok_or_else(|| LucentError::file(path, "not a file path"))?;
    let parent = target.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(parent) = parent {
        std::fs::create_dir_all(parent)
            .map_err(|e| LucentError::file(path, format!("cannot create directory: {e}")))?;
    }
    // Unique per process and call, so concurrent writers of the same file never share a temporary.
    let tmp_name = format!(
        "{}.{}-{}.tmp",
        file_name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let tmp: PathBuf = match parent {
        Some(parent) => parent.join(tmp_name),
        None => PathBuf::from(tmp_name),
    };
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, target));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        LucentError::file(path, e)
    })
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

    #[cfg(unix)]
    #[test]
    fn symlinks_are_written_through_and_devices_into() {
        let dir = temp_dir("through");
        std::fs::create_dir_all(&dir).unwrap();
        let real = dir.join("real.json");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_file_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        // A dangling link creates its target.
        let dangling = dir.join("dangling.json");
        std::os::unix::fs::symlink("made.json", &dangling).unwrap();
        write_file_atomic(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.join("made.json")).unwrap(), b"made");
        // A device is written into, not replaced.
        write_file_atomic(Path::new("/dev/null"), b"gone").unwrap();
        let null = std::fs::metadata("/dev/null").unwrap();
        assert!(!null.is_file(), "/dev/null was replaced by a file");
        let e = write_file_atomic(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let looped = dir.join("loop");
        std::os::unix::fs::symlink("loop", &looped).unwrap();
        let e = write_file_atomic(&looped, b"x").unwrap_err().to_string();
        assert!(e.contains("symlink loop"), "{e}");
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
