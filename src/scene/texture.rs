//! Texture loading: image files to linear-space floating-point texels with a full mip chain.
//!
//! [`load_texture`] reads PNG, JPEG, TGA, OpenEXR and Radiance HDR through the `image` crate
//! and returns a [`Texture`] whose texels are linear `f32` RGBA, whatever the file stored:
//!
//! - [`TextureUsage::Color`] (albedo and other colours): 8- and 16-bit files are sRGB-encoded,
//!   so their RGB is decoded to linear (alpha stays linear). EXR and HDR files are already
//!   linear and are taken as stored.
//! - [`TextureUsage::Data`] (normal maps, thickness, roughness): values are taken as stored,
//!   8/16-bit ones mapped to [0, 1]. Decoding a normal map as sRGB would bend every normal.
//!
//! Float texels that are NaN or infinite are replaced by 0 and counted in a warning. Mip levels
//! go down to 1x1 with a 2x2 box filter; an odd size is filtered by area (a texel of the smaller
//! level covers 2.5 texels of a 5-wide level, with weights 1, 1, 0.5), so every level keeps the
//! image's mean exactly. Errors name the file: "not found", not a regular file (a device or FIFO
//! is never read), "corrupt or unsupported", larger than [`MAX_TEXTURE_SIZE`] per side or than
//! [`MAX_TEXTURE_TEXELS`] in all (refused from the header, before anything is decoded).
//!
//! Memory: a loaded texture costs its linear `f32` texels and mips ([`host_bytes`], about 21
//! bytes per texel); while loading, the decoded file is held beside its `f32` level 0 and
//! nothing else of the image's size. That is for what computes with texels on the CPU (the
//! f64 references, layer depth textures); the renderer uploads texture files without any
//! `f32` copy ([`super::upload`]: the file's own precision, about twice its decoded size plus
//! mips while loading). [`decode_texture`] keeps the image as stored (its decoded size, no
//! `f32` copy) for what samples it on the CPU: thickness maps, `lucent inspect`, the upload.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec3;
use image::{DynamicImage, ImageReader, Limits};
use rayon::prelude::*;

use super::upload::{axis_weights, make_mips, split_level0, UploadLayout};
pub use super::upload::{mip_levels, srgb_to_linear};
use crate::files::Capped;
use crate::{LucentError, Result};

/// Where a texture comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// A file (PNG, JPEG, TGA, EXR, HDR), relative paths resolved against the scene file.
    File(PathBuf),
    /// Made in code, so built-in scenes need no file from outside the repository.
    Procedural(ProceduralTexture),
    /// An encoded image (PNG, JPEG, ...) held in memory: what a glTF asset's images are
    /// (a data URI, a GLB buffer view, or a file its loader read), decoded with the same
    /// checks and limits as a file.
    Encoded(EncodedImage),
}

/// An encoded image held in memory ([`TextureSource::Encoded`]).
#[derive(Clone, Debug, PartialEq)]
pub struct EncodedImage {
    /// The file it came from (a glTF asset): errors name it.
    pub file: PathBuf,
    /// Which image of that file it is (`image 2 "skin"`): errors name it after the file.
    pub name: String,
    /// The encoded bytes, shared by every material that uses the image.
    pub bytes: Arc<[u8]>,
    /// For a tangent-space normal map, the factor its x and y are scaled by once decoded
    /// (glTF's `normalTexture.scale`: `normalize((2 c - 1) * (s, s, 1))`, then stored back as
    /// `n / 2 + 1 / 2`); 1 leaves the texels as stored.
    pub normal_scale: f32,
}

impl EncodedImage {
    /// An error about this image: names the file, then the image.
    pub fn error(&self, message: impl std::fmt::Display) -> LucentError {
        LucentError::file(&self.file, format!("{}: {message}", self.name))
    }

    /// The size the image's header declares, after the checks a file gets (not empty, a known
    /// format) and [`check_texture_size`]'s limits; nothing is decoded.
    pub fn dimensions(&self) -> Result<(u32, u32)> {
        let (width, height) = self
            .reader()?
            .into_dimensions()
            .map_err(|e| self.error(format!("corrupt or unsupported image: {e}")))?;
        match texture_size_problem(width, height) {
            Some(problem) => Err(self.error(problem)),
            None => Ok((width, height)),
        }
    }

    fn reader(&self) -> Result<ImageReader<std::io::Cursor<&[u8]>>> {
        if self.bytes.is_empty() {
            return Err(self.error("image is empty (0 bytes)"));
        }
        let reader = ImageReader::new(std::io::Cursor::new(&self.bytes[..]))
            .with_guessed_format()
            .map_err(|e| self.error(format!("cannot read image: {e}")))?;
        if reader.format().is_none() {
            return Err(self.error(
                "not an image: format not recognised (supported: PNG, JPEG, TGA, EXR, HDR)",
            ));
        }
        Ok(reader)
    }
}

impl TextureSource {
    /// What logs and errors call it: the file's path, the procedural texture, or the encoded
    /// image's file and name.
    pub fn describe(&self) -> String {
        match self {
            TextureSource::File(path) => path.display().to_string(),
            TextureSource::Procedural(p) => format!("{p:?}"),
            TextureSource::Encoded(e) => format!("{}: {}", e.file.display(), e.name),
        }
    }

    /// The image decoded as stored ([`decode_texture`], or [`decode_encoded`]); `None` for a
    /// procedural texture, which is made, not decoded.
    pub fn decode(&self, usage: TextureUsage) -> Result<Option<DecodedImage>> {
        match self {
            TextureSource::File(path) => decode_texture(path, usage).map(Some),
            TextureSource::Encoded(e) => decode_encoded(e, usage).map(Some),
            TextureSource::Procedural(_) => Ok(None),
        }
    }
}

/// Textures lucent can make itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ProceduralTexture {
    /// A tangent-space normal map of marble-like veins: the height field
    /// `sin(frequency * (x + turbulence(x, y)))`, differentiated.
    MarbleNormal {
        /// Vein frequency across the texture.
        frequency: f32,
        /// Bump strength (slope scale).
        strength: f32,
    },
    /// A veined marble albedo (linear RGB, multiplied with the material's albedo): white
    /// crossed by thin `vein_color` veins along the zero crossings of the same height field as
    /// `MarbleNormal` at the same `frequency`, so veins and bumps line up, and a fainter,
    /// finer second net.
    MarbleAlbedo {
        /// Vein frequency across the texture (as `MarbleNormal`'s).
        frequency: f32,
        /// Colour at the centre of a vein (linear, each channel in [0, 1]).
        vein_color: Vec3,
    },
}

/// Largest width or height accepted (the minimum `maxImageDimension2D` Vulkan devices commonly
/// offer, and already 4 GiB of `f32` RGBA texels).
pub const MAX_TEXTURE_SIZE: u32 = 16384;

/// How a texture's values are interpreted, which decides whether sRGB is decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureUsage {
    /// A colour (albedo, tint): 8/16-bit files are sRGB-encoded and decoded to linear.
    Color,
    /// Linear data (normal maps, thickness, roughness): values are used as stored.
    Data,
}

/// A decoded texture: linear RGBA `f32` texels and its mip chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width of level 0 in texels.
    pub width: u32,
    /// Height of level 0 in texels.
    pub height: u32,
    /// How the values were interpreted when decoding.
    pub usage: TextureUsage,
    /// Mip levels, row-major, top row first: level 0 is full resolution, each next level is
    /// `max(1, size / 2)` per side, the last is 1x1. All values are finite and linear.
    pub mips: Vec<Vec<[f32; 4]>>,
}

impl Texture {
    /// Builds a texture from level-0 linear texels (row-major, top row first): replaces
    /// non-finite values by 0 and generates the mip chain. `what` names the source in errors
    /// and warnings.
    pub fn from_texels(
        what: &str,
        width: u32,
        height: u32,
        usage: TextureUsage,
        mut texels: Vec<[f32; 4]>,
    ) -> Result<Texture> {
        if width == 0 || height == 0 {
            return Err(LucentError::InvalidInput(format!(
                "{what}: image has no texels ({width}x{height})"
            )));
        }
        if width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
            return Err(LucentError::InvalidInput(format!(
                "{what}: image is {width}x{height}, larger than {MAX_TEXTURE_SIZE} per side"
            )));
        }
        if texels.len() != width as usize * height as usize {
            return Err(LucentError::InvalidInput(format!(
                "{what}: {} texels for a {width}x{height} image",
                texels.len()
            )));
        }
        let replaced = sanitize(&mut texels);
        if replaced > 0 {
            log::warn!("{what}: replaced {replaced} NaN or infinite texel values with 0");
        }
        let mut mips = vec![texels];
        let (mut w, mut h) = (width as usize, height as usize);
        while w > 1 || h > 1 {
            let (next, nw, nh) = downsample(mips.last().map_or(&[][..], |v| v), w, h);
            mips.push(next);
            (w, h) = (nw, nh);
        }
        Ok(Texture {
            width,
            height,
            usage,
            mips,
        })
    }

    /// Number of mip levels (`floor(log2(max(width, height))) + 1`).
    pub fn level_count(&self) -> usize {
        self.mips.len()
    }

    /// Width and height of mip `level`.
    pub fn level_size(&self, level: usize) -> (u32, u32) {
        let shift = level.min(31) as u32;
        ((self.width >> shift).max(1), (self.height >> shift).max(1))
    }

    /// Bilinear sample of level 0 at `uv` (0..1, v = 0 the top row), wrapping like a `REPEAT`
    /// sampler. A non-finite `uv` samples texel (0, 0) rather than propagating NaN.
    pub fn sample_bilinear(&self, uv: glam::Vec2) -> [f32; 4] {
        let width = self.width as usize;
        bilinear(self.width, self.height, uv, |x, y| {
            self.mips[0][y * width + x]
        })
    }
}

/// Bilinear sample at `uv` (0..1, v = 0 the top row) of a `width x height` image whose texels
/// `texel(x, y)` gives, wrapping like a `REPEAT` sampler. A non-finite `uv` samples texel
/// (0, 0) rather than propagating NaN.
fn bilinear(
    width: u32,
    height: u32,
    uv: glam::Vec2,
    texel: impl Fn(usize, usize) -> [f32; 4],
) -> [f32; 4] {
    let uv = if uv.is_finite() { uv } else { glam::Vec2::ZERO };
    let x = uv.x * width as f32 - 0.5;
    let y = uv.y * height as f32 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let at = |tx: f32, ty: f32| {
        let tx = (tx as i64).rem_euclid(i64::from(width)) as usize;
        let ty = (ty as i64).rem_euclid(i64::from(height)) as usize;
        texel(tx, ty)
    };
    let (a, b) = (at(x0, y0), at(x0 + 1.0, y0));
    let (c, d) = (at(x0, y0 + 1.0), at(x0 + 1.0, y0 + 1.0));
    std::array::from_fn(|i| {
        let top = a[i] + (b[i] - a[i]) * fx;
        let bottom = c[i] + (d[i] - c[i]) * fx;
        top + (bottom - top) * fy
    })
}

/// Side of the procedural textures lucent makes, in texels (the GPU upload and the f64
/// references make the same texture).
pub const PROCEDURAL_TEXTURE_SIZE: u32 = 512;

/// The tileable marble height field at texel (`x`, `y`) of an `n` x `n` map:
/// `h = sin(2 pi (f u + t(u, v)))` with a periodic turbulence `t` (whole frequencies, so the map
/// tiles).
fn marble_height(frequency: f32, n: usize, x: usize, y: usize) -> f32 {
    let tau = std::f32::consts::TAU;
    let (u, v) = (x as f32 / n as f32, y as f32 / n as f32);
    let turbulence = 0.35 * (tau * (2.0 * v + 0.6 * (tau * u).sin())).sin()
        + 0.15 * (tau * (5.0 * (u + v))).sin()
        + 0.08 * (tau * (11.0 * u - 7.0 * v)).sin();
    (tau * (frequency * u + turbulence)).sin()
}

/// Makes a procedural texture at `size` x `size` (linear, with mips).
///
/// `MarbleNormal`: the height field of `marble_height`, differentiated by central differences
/// (wrapping) into a tangent-space normal `normalize(-s dh/dx, -s dh/dy, 1)`, stored as a
/// normal map file would store it (`n * 0.5 + 0.5`).
///
/// `MarbleAlbedo`: white mixed toward the vein colour by `(1 - |h|)^10` (thin veins where the
/// field crosses zero) and by a third of that of a field at 2.7 times the frequency (rounded)
/// turned
/// across it (the finer net); linear RGB.
pub fn procedural_texture(texture: &ProceduralTexture, size: u32) -> Result<Texture> {
    let n = size.max(1) as usize;
    let (frequency, strength) = match *texture {
        ProceduralTexture::MarbleNormal {
            frequency,
            strength,
        } => (frequency, strength),
        ProceduralTexture::MarbleAlbedo {
            frequency,
            vein_color,
        } => {
            // Guarded where it is born: a colour outside [0, 1] is no reflectance.
            let vein = vein_color.clamp(glam::Vec3::ZERO, glam::Vec3::ONE);
            let vein = if vein.is_finite() {
                vein
            } else {
                glam::Vec3::ZERO
            };
            // A whole frequency, so the finer net tiles too.
            let fine_frequency = (frequency * 2.7).round().max(1.0);
            let mut texels = Vec::with_capacity(n * n);
            for y in 0..n {
                for x in 0..n {
                    let main = (1.0 - marble_height(frequency, n, x, y).abs()).powi(10);
                    let fine = (1.0 - marble_height(fine_frequency, n, y, x).abs()).powi(10);
                    let w = (main + fine / 3.0).min(1.0);
                    let c = glam::Vec3::ONE.lerp(vein, w);
                    texels.push([c.x, c.y, c.z, 1.0]);
                }
            }
            return Texture::from_texels(
                "procedural marble albedo",
                size.max(1),
                size.max(1),
                TextureUsage::Color,
                texels,
            );
        }
    };
    let height = |x: usize, y: usize| marble_height(frequency, n, x, y);
    let mut texels = Vec::with_capacity(n * n);
    for y in 0..n {
        for x in 0..n {
            // Central differences per texel, wrapped: the map tiles.
            let dx = (height((x + 1) % n, y) - height((x + n - 1) % n, y)) * 0.5;
            let dy = (height(x, (y + 1) % n) - height(x, (y + n - 1) % n)) * 0.5;
            let normal = glam::Vec3::new(-strength * dx, -strength * dy, 1.0).normalize();
            let e = normal * 0.5 + glam::Vec3::splat(0.5);
            texels.push([e.x, e.y, e.z, 1.0]);
        }
    }
    Texture::from_texels(
        "procedural marble normal map",
        size.max(1),
        size.max(1),
        TextureUsage::Data,
        texels,
    )
}

/// Largest texture file read (2 GiB): an uncompressed 8192x8192 RGBA f32 EXR is 1 GiB.
pub const MAX_TEXTURE_FILE_BYTES: u64 = 2 << 30;

/// Most texels one texture may have: 8192 x 8192 (or, say, 16384 x 4096). A loaded texture
/// is linear RGBA `f32` with its mip chain, about 21.3 bytes per texel on the host (1.3 GiB at
/// this limit, 5.3 GiB for a 16384x16384 image), and a normal map drawn with LEAN mapping
/// makes two more of the same size; so the limit is on the texel count, checked from the
/// file's header before anything is decoded.
pub const MAX_TEXTURE_TEXELS: u64 = 8192 * 8192;

/// Host bytes of a loaded `width x height` texture: linear RGBA `f32` texels of every mip
/// level. Checked arithmetic: `None` only beyond `u64`, which no accepted size reaches.
pub fn host_bytes(width: u32, height: u32) -> Option<u64> {
    (0..mip_levels(width, height)).try_fold(0u64, |sum, level| {
        let (w, h) = ((width >> level).max(1), (height >> level).max(1));
        u64::from(w)
            .checked_mul(u64::from(h))?
            .checked_mul(16)?
            .checked_add(sum)
    })
}

/// Opens an image file after checking it is a regular file (symlinks followed), reads at most
/// [`MAX_TEXTURE_FILE_BYTES`] of it, and guesses its format from its first bytes.
fn open_image(path: &Path) -> Result<ImageReader<std::io::BufReader<Capped<std::fs::File>>>> {
    let err = |message: String| LucentError::file(path, message);
    let (file, len) =
        crate::files::open_regular(path, MAX_TEXTURE_FILE_BYTES, "texture").map_err(|e| {
            if e == "file not found" {
                err("texture not found".into())
            } else {
                err(e)
            }
        })?;
    if len == 0 {
        return Err(err("image file is empty (0 bytes)".into()));
    }
    let mut reader = ImageReader::new(std::io::BufReader::new(Capped::new(
        file,
        MAX_TEXTURE_FILE_BYTES,
    )));
    // The extension first (TGA has no signature), the content where it is recognised.
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let reader = reader
        .with_guessed_format()
        .map_err(|e| err(format!("cannot read texture: {e}")))?;
    if reader.format().is_none() {
        return Err(err(
            "corrupt or unsupported image: format not recognised (supported: PNG, JPEG, TGA, \
             EXR, HDR)"
                .into(),
        ));
    }
    Ok(reader)
}

fn corrupt(path: &Path, e: image::ImageError) -> LucentError {
    LucentError::file(path, format!("corrupt or unsupported image: {e}"))
}

/// The size an image file declares in its header, read without decoding anything, after the
/// checks [`load_texture`] makes first (a regular file, not empty, a known format).
pub fn texture_dimensions(path: &Path) -> Result<(u32, u32)> {
    open_image(path)?
        .into_dimensions()
        .map_err(|e| corrupt(path, e))
}

/// Refuses a `width x height` image lucent would not load: more than [`MAX_TEXTURE_SIZE`] per
/// side or more than [`MAX_TEXTURE_TEXELS`] texels. The message names the size, the limit and
/// what the image would cost.
pub fn check_texture_size(path: &Path, width: u32, height: u32) -> Result<()> {
    match texture_size_problem(width, height) {
        Some(problem) => Err(LucentError::file(path, problem)),
        None => Ok(()),
    }
}

/// What [`check_texture_size`] says about a `width x height` image, or `None` when it fits.
fn texture_size_problem(width: u32, height: u32) -> Option<String> {
    if width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Some(format!(
            "image is {width}x{height}, larger than {MAX_TEXTURE_SIZE} per side"
        ));
    }
    let texels = u64::from(width) * u64::from(height);
    if texels > MAX_TEXTURE_TEXELS {
        let cost = host_bytes(width, height).unwrap_or(u64::MAX);
        let gpu: u64 =
            super::upload::level_bytes(width, height, super::upload::UploadLayout::Unorm8)
                .iter()
                .sum();
        return Some(format!(
            "image is {width}x{height} ({texels} texels), more than the {MAX_TEXTURE_TEXELS} \
             texels (8192x8192) a texture may have: it would take {} on the GPU as 8-bit \
             RGBA with mips (twice that while loading; a 16-bit or float file twice that \
             again) and {} of host memory as linear RGBA f32 where the CPU computes with \
             it; scale it down to at most 8192x8192",
            crate::error::format_bytes(gpu),
            crate::error::format_bytes(cost)
        ));
    }
    None
}

/// The image files `scene` uploads as textures (its materials' normal and albedo maps), each
/// once, with the size its header declares and whether it is a normal map, checked before
/// anything is decoded: [`check_texture_size`], and with `max_dimension` (the device's
/// `maxImageDimension2D`) that neither side is larger. Reads only the headers, so a scene with
/// a texture too large is refused in milliseconds.
pub fn scene_texture_sizes(
    scene: &super::Scene,
    max_dimension: Option<u32>,
) -> Result<Vec<(std::path::PathBuf, u32, u32, bool)>> {
    let mut sizes: Vec<(std::path::PathBuf, u32, u32, bool)> = Vec::new();
    for object in &scene.objects {
        let m = &object.material;
        let maps = [(&m.normal_texture, true), (&m.albedo_texture, false)];
        for (source, normal) in maps {
            let (path, (width, height)) = match source {
                Some(TextureSource::File(path)) => {
                    if sizes.iter().any(|(p, _, _, n)| p == path && *n == normal) {
                        continue;
                    }
                    let size = texture_dimensions(path)?;
                    check_texture_size(path, size.0, size.1)?;
                    (path.clone(), size)
                }
                Some(TextureSource::Encoded(e)) => {
                    let name =
                        PathBuf::from(source.as_ref().map_or(String::new(), |s| s.describe()));
                    if sizes.iter().any(|(p, _, _, n)| *p == name && *n == normal) {
                        continue;
                    }
                    (name, e.dimensions()?)
                }
                _ => continue,
            };
            let path = &path;
            if let Some(limit) = max_dimension.filter(|&l| width > l || height > l) {
                return Err(LucentError::file(
                    path,
                    format!(
                        "{} of material '{}' is {width}x{height}, larger than this device \
                         supports ({limit} per side, maxImageDimension2D); scale it down",
                        if normal {
                            "normal map"
                        } else {
                            "albedo texture"
                        },
                        m.name
                    ),
                ));
            }
            sizes.push((path.clone(), width, height, normal));
        }
    }
    Ok(sizes)
}

/// Loads an image file as a linear-float texture with mips; see the module docs for how
/// `usage` decides sRGB decoding.
///
/// Errors name the file and say whether it was not found, is not a regular file, is empty, is
/// corrupt or unsupported, or is too large ([`check_texture_size`], decided from the header
/// before anything is decoded). Memory: the decoded file and the `f32` texels at once, then the
/// texture ([`host_bytes`]); nothing else of the image's size.
pub fn load_texture(path: &Path, usage: TextureUsage) -> Result<Texture> {
    let (width, height, texels) = decode(path, usage)?;
    Texture::from_texels(&path.display().to_string(), width, height, usage, texels)
}

/// Loads any texture source as [`load_texture`] loads a file: a file, an encoded image (the
/// same checks and limits) or a procedural texture made at [`PROCEDURAL_TEXTURE_SIZE`].
pub fn load_source(source: &TextureSource, usage: TextureUsage) -> Result<Texture> {
    match source {
        TextureSource::File(path) => load_texture(path, usage),
        TextureSource::Procedural(p) => procedural_texture(p, PROCEDURAL_TEXTURE_SIZE),
        TextureSource::Encoded(e) => {
            let decoded = decode_encoded(e, usage)?;
            let (texels, replaced) = decoded.texels();
            let what = source.describe();
            if replaced > 0 {
                log::warn!("{what}: replaced {replaced} NaN or infinite texel values with 0");
            }
            Texture::from_texels(&what, decoded.width, decoded.height, usage, texels)
        }
    }
}

/// An image file decoded but kept in the layout it was stored in (8- or 16-bit integers, or
/// floats): about the image's decoded size in memory, a quarter of [`load_texture`]'s level 0
/// for an 8-bit RGBA file. Texels become linear RGBA `f32` as they are read
/// ([`DecodedImage::texel`]), with the same rules as [`load_texture`] (sRGB decoded for colour
/// usage of 8/16-bit files, grey replicated, missing alpha 1, non-finite values 0). What samples a
/// texture on the CPU uses this (thickness maps at vertices, `lucent inspect`).
pub struct DecodedImage {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    image: DynamicImage,
    /// sRGB-decoded 8-bit values (or the plain `v / 255` for linear data).
    lut: [f32; 256],
    srgb: bool,
}

impl DecodedImage {
    /// Texel (`x`, `y`) (`y = 0` the top row) as linear RGBA, every value finite.
    pub fn texel(&self, x: usize, y: usize) -> [f32; 4] {
        let i = y * self.width as usize + x;
        let lut = &self.lut;
        let wide = |v: u16| {
            let v = f32::from(v) / 65535.0;
            if self.srgb {
                srgb_to_linear(v)
            } else {
                v
            }
        };
        let a8 = |v: u8| f32::from(v) / 255.0;
        let a16 = |v: u16| f32::from(v) / 65535.0;
        let t = match &self.image {
            DynamicImage::ImageLuma8(im) => {
                let c = lut[usize::from(im.as_raw()[i])];
                [c, c, c, 1.0]
            }
            DynamicImage::ImageLumaA8(im) => {
                let p = &im.as_raw()[i * 2..i * 2 + 2];
                let c = lut[usize::from(p[0])];
                [c, c, c, a8(p[1])]
            }
            DynamicImage::ImageRgb8(im) => {
                let p = &im.as_raw()[i * 3..i * 3 + 3];
                [
                    lut[p[0] as usize],
                    lut[p[1] as usize],
                    lut[p[2] as usize],
                    1.0,
                ]
            }
            DynamicImage::ImageRgba8(im) => {
                let p = &im.as_raw()[i * 4..i * 4 + 4];
                [
                    lut[p[0] as usize],
                    lut[p[1] as usize],
                    lut[p[2] as usize],
                    a8(p[3]),
                ]
            }
            DynamicImage::ImageLuma16(im) => {
                let c = wide(im.as_raw()[i]);
                [c, c, c, 1.0]
            }
            DynamicImage::ImageLumaA16(im) => {
                let p = &im.as_raw()[i * 2..i * 2 + 2];
                let c = wide(p[0]);
                [c, c, c, a16(p[1])]
            }
            DynamicImage::ImageRgb16(im) => {
                let p = &im.as_raw()[i * 3..i * 3 + 3];
                [wide(p[0]), wide(p[1]), wide(p[2]), 1.0]
            }
            DynamicImage::ImageRgba16(im) => {
                let p = &im.as_raw()[i * 4..i * 4 + 4];
                [wide(p[0]), wide(p[1]), wide(p[2]), a16(p[3])]
            }
            DynamicImage::ImageRgb32F(im) => {
                let p = &im.as_raw()[i * 3..i * 3 + 3];
                [p[0], p[1], p[2], 1.0]
            }
            DynamicImage::ImageRgba32F(im) => {
                let p = &im.as_raw()[i * 4..i * 4 + 4];
                [p[0], p[1], p[2], p[3]]
            }
            // A layout added to `image` later: converted one texel at a time.
            other => {
                let p = image::GenericImageView::get_pixel(other, x as u32, y as u32).0;
                [
                    lut[p[0] as usize],
                    lut[p[1] as usize],
                    lut[p[2] as usize],
                    a8(p[3]),
                ]
            }
        };
        // Guarded where it is born: one NaN poisons every filter tap that touches it.
        t.map(|v| if v.is_finite() { v } else { 0.0 })
    }

    /// Bilinear sample at `uv`, as [`Texture::sample_bilinear`] samples level 0.
    pub fn sample_bilinear(&self, uv: glam::Vec2) -> [f32; 4] {
        bilinear(self.width, self.height, uv, |x, y| self.texel(x, y))
    }

    /// The layout the GPU stores this image in ([`super::upload`]): 8-bit files stay 8-bit
    /// (sRGB-encoded for colour usage, the sampler decodes), everything else is linear binary16.
    pub fn upload_layout(&self) -> super::upload::UploadLayout {
        use super::upload::UploadLayout;
        match self.image {
            DynamicImage::ImageLuma8(_)
            | DynamicImage::ImageLumaA8(_)
            | DynamicImage::ImageRgb8(_)
            | DynamicImage::ImageRgba8(_) => {
                if self.srgb {
                    UploadLayout::Srgb8
                } else {
                    UploadLayout::Unorm8
                }
            }
            _ => UploadLayout::Half,
        }
    }

    /// Writes row `y` of an 8-bit image into `out` as RGBA8, values as stored (grey
    /// replicated, missing alpha 255), and returns true; returns false, writing nothing, for
    /// any other layout.
    pub(super) fn write_rgba8_row(&self, y: usize, out: &mut [u8]) -> bool {
        let w = self.width as usize;
        match &self.image {
            DynamicImage::ImageLuma8(im) => {
                for (o, &v) in out
                    .chunks_exact_mut(4)
                    .zip(&im.as_raw()[y * w..(y + 1) * w])
                {
                    o.copy_from_slice(&[v, v, v, 255]);
                }
            }
            DynamicImage::ImageLumaA8(im) => {
                let row = &im.as_raw()[y * w * 2..(y + 1) * w * 2];
                for (o, p) in out.chunks_exact_mut(4).zip(row.chunks_exact(2)) {
                    o.copy_from_slice(&[p[0], p[0], p[0], p[1]]);
                }
            }
            DynamicImage::ImageRgb8(im) => {
                let row = &im.as_raw()[y * w * 3..(y + 1) * w * 3];
                for (o, p) in out.chunks_exact_mut(4).zip(row.chunks_exact(3)) {
                    o.copy_from_slice(&[p[0], p[1], p[2], 255]);
                }
            }
            DynamicImage::ImageRgba8(im) => {
                out.copy_from_slice(&im.as_raw()[y * w * 4..(y + 1) * w * 4]);
            }
            _ => return false,
        }
        true
    }

    /// Every texel in row order as linear RGBA `f32` (level 0 of a [`Texture`]), converted in
    /// parallel; non-finite values counted.
    fn texels(&self) -> (Vec<[f32; 4]>, usize) {
        let w = self.width as usize;
        let texels: Vec<[f32; 4]> = (0..w * self.height as usize)
            .into_par_iter()
            .map(|i| self.texel(i % w, i / w))
            .collect();
        (texels, self.non_finite())
    }

    /// How many stored float values are NaN or infinite (read back as 0).
    pub fn non_finite(&self) -> usize {
        let bad = |v: &[f32]| v.par_iter().filter(|x| !x.is_finite()).count();
        match &self.image {
            DynamicImage::ImageRgb32F(im) => bad(im.as_raw()),
            DynamicImage::ImageRgba32F(im) => bad(im.as_raw()),
            _ => 0,
        }
    }
}

/// Writes `image`'s whole mip chain into `out` (its [`level_bytes`](super::upload::level_bytes) for
/// [`DecodedImage::upload_layout`], packed, level 0 first). Level 0 is the file's texels in
/// that layout; `image` is dropped before the mips are made, so the decoded file and the mips
/// never share memory.
pub fn write_texture_chain(image: DecodedImage, out: &mut [u8]) -> Result<()> {
    let (width, height) = (image.width, image.height);
    let layout = image.upload_layout();
    let (level0, rest) = split_level0(width, height, layout, out)?;
    let w = width as usize;
    let row_bytes = w * layout.texel_bytes();
    let eight_bit = matches!(layout, UploadLayout::Unorm8 | UploadLayout::Srgb8);
    level0
        .par_chunks_mut(row_bytes)
        .enumerate()
        .for_each(|(y, row)| {
            // 8-bit files are copied as stored (exact); anything else is converted.
            if !(eight_bit && image.write_rgba8_row(y, row)) {
                for (x, texel) in row.chunks_exact_mut(layout.texel_bytes()).enumerate() {
                    layout.encode(image.texel(x, y), texel);
                }
            }
        });
    drop(image);
    make_mips(width, height, layout, level0, rest);
    Ok(())
}

/// Decodes an image file ([`load_texture`]'s checks and limits) into a [`DecodedImage`].
pub fn decode_texture(path: &Path, usage: TextureUsage) -> Result<DecodedImage> {
    // Read the header alone first, so an absurd size is refused before anything is allocated.
    let (width, height) = texture_dimensions(path)?;
    check_texture_size(path, width, height)?;
    let reader = open_image(path)?;
    let image = decode_limited(reader).map_err(|e| corrupt(path, e))?;
    Ok(DecodedImage::new(image, usage))
}

/// Decodes an encoded image held in memory with the checks and limits of [`decode_texture`]
/// (its header's size first), then scales a normal map's x and y by its `normal_scale`.
pub fn decode_encoded(encoded: &EncodedImage, usage: TextureUsage) -> Result<DecodedImage> {
    encoded.dimensions()?;
    let image = decode_limited(encoded.reader()?)
        .map_err(|e| encoded.error(format!("corrupt or unsupported image: {e}")))?;
    let image = if encoded.normal_scale == 1.0 {
        image
    } else {
        scale_normals(image, encoded.normal_scale)
    };
    Ok(DecodedImage::new(image, usage))
}

/// Decodes what `reader` reads, allocating no more than the largest accepted image needs.
fn decode_limited<R: std::io::BufRead + std::io::Seek>(
    mut reader: ImageReader<R>,
) -> std::result::Result<DynamicImage, image::ImageError> {
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIZE);
    limits.max_image_height = Some(MAX_TEXTURE_SIZE);
    // The decoded image of the largest accepted size in the widest format (RGBA f32): the
    // decoder may not allocate more, whatever the header said.
    limits.max_alloc = Some(MAX_TEXTURE_TEXELS * 16);
    reader.limits(limits);
    reader.decode()
}

/// A tangent-space normal map with x and y scaled by `scale` (glTF's `normalTexture.scale`):
/// each texel `c` becomes `normalize((2 c - 1) * (scale, scale, 1)) / 2 + 1 / 2`. 8-bit maps
/// stay 8-bit (rounded), anything else becomes RGBA `f32`. A texel whose scaled normal has no
/// length (a zero texel at scale 0) becomes the flat normal.
pub fn scale_normals(image: DynamicImage, scale: f32) -> DynamicImage {
    let scaled = |c: [f32; 3]| -> [f32; 3] {
        let n = Vec3::new(
            (c[0] * 2.0 - 1.0) * scale,
            (c[1] * 2.0 - 1.0) * scale,
            c[2] * 2.0 - 1.0,
        );
        // Guarded where it is born: a zero or non-finite vector has no direction.
        let n = n.try_normalize().unwrap_or(Vec3::Z);
        (n * 0.5 + Vec3::splat(0.5)).to_array()
    };
    let eight_bit = matches!(
        image,
        DynamicImage::ImageLuma8(_)
            | DynamicImage::ImageLumaA8(_)
            | DynamicImage::ImageRgb8(_)
            | DynamicImage::ImageRgba8(_)
    );
    if eight_bit {
        let mut rgba = image.into_rgba8();
        for p in rgba.pixels_mut() {
            let c = scaled([0, 1, 2].map(|i| f32::from(p.0[i]) / 255.0));
            for (stored, value) in p.0.iter_mut().zip(c) {
                *stored = (value * 255.0).round().clamp(0.0, 255.0) as u8;
            }
        }
        DynamicImage::ImageRgba8(rgba)
    } else {
        let mut rgba = image.into_rgba32f();
        for p in rgba.pixels_mut() {
            let c = scaled([p.0[0], p.0[1], p.0[2]]);
            p.0[..3].copy_from_slice(&c);
        }
        DynamicImage::ImageRgba32F(rgba)
    }
}

impl DecodedImage {
    /// `image` as [`decode_texture`] keeps it, its texels read as `usage` says.
    fn new(image: DynamicImage, usage: TextureUsage) -> Self {
        // Float formats (EXR, HDR) store linear values; 8/16-bit ones store sRGB for colours.
        let stored_linear = matches!(
            image,
            DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
        );
        let srgb = usage == TextureUsage::Color && !stored_linear;
        let lut = std::array::from_fn(|i| {
            let v = i as f32 / 255.0;
            if srgb {
                srgb_to_linear(v)
            } else {
                v
            }
        });
        DecodedImage {
            width: image.width(),
            height: image.height(),
            image,
            lut,
            srgb,
        }
    }
}

/// Decodes an image file to linear RGBA `f32` texels (level 0). The decoded image is dropped
/// as soon as its texels are made.
fn decode(path: &Path, usage: TextureUsage) -> Result<(u32, u32, Vec<[f32; 4]>)> {
    let decoded = decode_texture(path, usage)?;
    let (texels, replaced) = decoded.texels();
    if replaced > 0 {
        log::warn!(
            "{}: replaced {replaced} NaN or infinite texel values with 0",
            path.display()
        );
    }
    Ok((decoded.width, decoded.height, texels))
}

/// Replaces every NaN or infinite component by 0; returns how many were replaced.
///
/// This happens at load, before filtering, because one NaN poisons every filter tap that touches
/// it: each mip level down would spread it to more texels, and on the GPU bilinear filtering and
/// blurs spread it across the screen. Infinity does the same (inf - inf, inf * 0).
fn sanitize(texels: &mut [[f32; 4]]) -> usize {
    let mut replaced = 0;
    for c in texels.iter_mut().flatten() {
        if !c.is_finite() {
            *c = 0.0;
            replaced += 1;
        }
    }
    replaced
}

/// One mip step: `w x h` to `max(1, w/2) x max(1, h/2)` with an area-weighted box filter.
fn downsample(src: &[[f32; 4]], w: usize, h: usize) -> (Vec<[f32; 4]>, usize, usize) {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let wx = axis_weights(w, nw);
    let wy = axis_weights(h, nh);
    let mut rows = vec![[0.0f32; 4]; nw * h];
    rows.par_chunks_mut(nw).enumerate().for_each(|(y, row)| {
        let src_row = &src[y * w..(y + 1) * w];
        for (out, taps) in row.iter_mut().zip(&wx) {
            for &(j, weight) in taps {
                for c in 0..4 {
                    out[c] += src_row[j][c] * weight;
                }
            }
        }
    });
    let mut dst = vec![[0.0f32; 4]; nw * nh];
    dst.par_chunks_mut(nw).enumerate().for_each(|(y, row)| {
        for &(j, weight) in &wy[y] {
            let src_row = &rows[j * nw..(j + 1) * nw];
            for (out, s) in row.iter_mut().zip(src_row) {
                for c in 0..4 {
                    out[c] += s[c] * weight;
                }
            }
        }
    });
    (dst, nw, nh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{ImageFormat, Rgb32FImage, RgbImage, Rgba32FImage};
    use std::path::PathBuf;

    #[test]
    fn procedural_marble_normals_are_unit_tangent_space_and_tile() {
        let p = ProceduralTexture::MarbleNormal {
            frequency: 18.0,
            strength: 0.35,
        };
        let t = procedural_texture(&p, 64).unwrap();
        assert_eq!((t.width, t.height), (64, 64));
        assert_eq!(t.level_count(), 7);
        let mut tilted = 0;
        for texel in &t.mips[0] {
            let n = glam::Vec3::new(texel[0], texel[1], texel[2]) * 2.0 - glam::Vec3::ONE;
            assert!((n.length() - 1.0).abs() < 1e-4, "{n}");
            assert!(n.z > 0.0, "points out of the surface: {n}");
            tilted += usize::from(n.z < 0.999);
        }
        assert!(
            tilted > 64 * 64 / 2,
            "a normal map that bends almost nothing"
        );
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("lucent-texture-test-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn solid_rgb8(w: u32, h: u32, rgb: [u8; 3]) -> DynamicImage {
        DynamicImage::ImageRgb8(RgbImage::from_pixel(w, h, image::Rgb(rgb)))
    }

    fn mean(level: &[[f32; 4]]) -> [f64; 4] {
        let mut m = [0.0f64; 4];
        for t in level {
            for c in 0..4 {
                m[c] += t[c] as f64 / level.len() as f64;
            }
        }
        m
    }

    #[test]
    fn png_color_is_srgb_decoded_and_data_is_not() {
        let dir = temp_dir("png");
        let path = dir.join("grey.png");
        solid_rgb8(4, 2, [128, 128, 128]).save(&path).unwrap();
        let color = load_texture(&path, TextureUsage::Color).unwrap();
        let data = load_texture(&path, TextureUsage::Data).unwrap();
        assert_eq!((color.width, color.height), (4, 2));
        // sRGB 128/255 is 0.2159 linear.
        assert!((color.mips[0][0][0] - 0.2159).abs() < 1e-3);
        assert!((data.mips[0][0][0] - 128.0 / 255.0).abs() < 1e-6);
        assert_eq!(color.mips[0][0][3], 1.0);
        assert_eq!(color.level_count(), 3); // 4x2, 2x1, 1x1
        assert_eq!(color.level_size(1), (2, 1));
        assert_eq!(color.level_size(2), (1, 1));
        assert_eq!(color.mips[2].len(), 1);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn jpeg_and_tga_load() {
        let dir = temp_dir("jpg-tga");
        let jpg = dir.join("red.jpg");
        let tga = dir.join("blue.tga");
        solid_rgb8(16, 8, [255, 0, 0]).save(&jpg).unwrap();
        solid_rgb8(3, 5, [0, 0, 255]).save(&tga).unwrap();
        let t = load_texture(&jpg, TextureUsage::Data).unwrap();
        assert_eq!((t.width, t.height, t.level_count()), (16, 8, 5));
        // JPEG is lossy: allow a little chroma error.
        assert!(t.mips[0][0][0] > 0.9 && t.mips[0][0][1] < 0.1);
        let t = load_texture(&tga, TextureUsage::Color).unwrap();
        assert_eq!((t.width, t.height, t.level_count()), (3, 5, 3));
        assert_eq!(t.mips[0][7], [0.0, 0.0, 1.0, 1.0]);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn exr_keeps_linear_values_and_sanitizes_nan_and_inf() {
        let dir = temp_dir("exr");
        let path = dir.join("nan.exr");
        let mut img = Rgba32FImage::from_pixel(2, 2, image::Rgba([2.5, 0.25, 0.5, 1.0]));
        img.put_pixel(1, 0, image::Rgba([f32::NAN, f32::INFINITY, 1.0, 1.0]));
        DynamicImage::ImageRgba32F(img)
            .save_with_format(&path, ImageFormat::OpenExr)
            .unwrap();
        // Colour usage does not sRGB-decode float formats.
        let t = load_texture(&path, TextureUsage::Color).unwrap();
        assert_eq!(t.mips[0][0], [2.5, 0.25, 0.5, 1.0]);
        assert_eq!(t.mips[0][1], [0.0, 0.0, 1.0, 1.0]);
        assert!(t.mips.iter().flatten().flatten().all(|v| v.is_finite()));
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn hdr_loads_linear_floats() {
        let dir = temp_dir("hdr");
        let path = dir.join("sky.hdr");
        let img = Rgb32FImage::from_pixel(3, 3, image::Rgb([4.0, 1.0, 0.5]));
        DynamicImage::ImageRgb32F(img)
            .save_with_format(&path, ImageFormat::Hdr)
            .unwrap();
        let t = load_texture(&path, TextureUsage::Color).unwrap();
        assert_eq!((t.width, t.height, t.level_count()), (3, 3, 2));
        // RGBE keeps about 8 bits of mantissa.
        let p = t.mips[0][4];
        assert!((p[0] - 4.0).abs() < 0.05 && (p[1] - 1.0).abs() < 0.02);
        assert_eq!(p[3], 1.0);
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn odd_sizes_keep_the_mean_down_to_one_texel() {
        let (w, h) = (5u32, 3u32);
        let texels: Vec<[f32; 4]> = (0..w * h)
            .map(|i| [i as f32, (i * i) as f32, 1.0, (i % 2) as f32])
            .collect();
        let want = mean(&texels);
        let t = Texture::from_texels("test", w, h, TextureUsage::Data, texels).unwrap();
        assert_eq!(t.level_count(), 3); // 5x3, 2x1, 1x1
        for (level, texels) in t.mips.iter().enumerate() {
            let (lw, lh) = t.level_size(level);
            assert_eq!(texels.len(), (lw * lh) as usize);
            let got = mean(texels);
            for c in 0..4 {
                assert!((got[c] - want[c]).abs() < 1e-4, "level {level}: {got:?}");
            }
        }
        // An even level is an exact 2x2 average.
        let t = Texture::from_texels(
            "even",
            2,
            2,
            TextureUsage::Data,
            vec![[0.0; 4], [1.0; 4], [2.0; 4], [5.0; 4]],
        )
        .unwrap();
        assert_eq!(t.mips[1], vec![[2.0; 4]]);
    }

    #[test]
    fn decoded_images_read_like_the_textures_they_would_load() {
        let dir = temp_dir("decoded");
        let rgba = dir.join("rgba.png");
        let img = image::RgbaImage::from_fn(5, 3, |x, y| {
            image::Rgba([(x * 50) as u8, (y * 80) as u8, 200, (x * 40 + 10) as u8])
        });
        img.save(&rgba).unwrap();
        let grey16 = dir.join("grey16.png");
        image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_fn(4, 4, |x, y| {
            image::Luma([(x * 9000 + y * 1000) as u16])
        })
        .save(&grey16)
        .unwrap();
        let exr = dir.join("nan.exr");
        let mut f = Rgba32FImage::from_pixel(2, 2, image::Rgba([2.5, 0.25, 0.5, 1.0]));
        f.put_pixel(1, 1, image::Rgba([f32::NAN, 1.0, f32::INFINITY, 1.0]));
        DynamicImage::ImageRgba32F(f)
            .save_with_format(&exr, ImageFormat::OpenExr)
            .unwrap();
        for path in [&rgba, &grey16, &exr] {
            for usage in [TextureUsage::Color, TextureUsage::Data] {
                let t = load_texture(path, usage).unwrap();
                let d = decode_texture(path, usage).unwrap();
                assert_eq!((d.width, d.height), (t.width, t.height));
                for y in 0..t.height as usize {
                    for x in 0..t.width as usize {
                        assert_eq!(d.texel(x, y), t.mips[0][y * t.width as usize + x]);
                    }
                }
                let uv = glam::Vec2::new(0.37, 0.61);
                assert_eq!(d.sample_bilinear(uv), t.sample_bilinear(uv));
            }
        }
        assert_eq!(
            decode_texture(&exr, TextureUsage::Data)
                .unwrap()
                .non_finite(),
            2
        );
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn sanitize_counts_and_replaces() {
        let mut t = vec![[f32::NAN, 1.0, f32::NEG_INFINITY, 0.5], [0.0; 4]];
        assert_eq!(sanitize(&mut t), 2);
        assert_eq!(t[0], [0.0, 1.0, 0.0, 0.5]);
    }

    #[test]
    fn errors_name_the_file_and_the_problem() {
        let dir = temp_dir("errors");
        let missing = dir.join("missing.png");
        let e = load_texture(&missing, TextureUsage::Color)
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.png") && e.contains("not found"), "{e}");

        let corrupt = dir.join("corrupt.png");
        std::fs::write(&corrupt, b"\x89PNG\r\n\x1a\nthis is not a png").unwrap();
        let e = load_texture(&corrupt, TextureUsage::Color)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("corrupt.png") && e.contains("corrupt or unsupported"),
            "{e}"
        );

        let empty = dir.join("empty.png");
        std::fs::write(&empty, b"").unwrap();
        let e = load_texture(&empty, TextureUsage::Data)
            .unwrap_err()
            .to_string();
        assert!(e.contains("empty.png") && e.contains("empty"), "{e}");

        let wide = dir.join("wide.png");
        solid_rgb8(MAX_TEXTURE_SIZE + 1, 1, [1, 2, 3])
            .save(&wide)
            .unwrap();
        let e = load_texture(&wide, TextureUsage::Data)
            .unwrap_err()
            .to_string();
        assert!(e.contains("wide.png") && e.contains("16385x1"), "{e}");

        let text = dir.join("notes.txt");
        std::fs::write(&text, b"hello").unwrap();
        let e = load_texture(&text, TextureUsage::Data)
            .unwrap_err()
            .to_string();
        assert!(e.contains("corrupt or unsupported"), "{e}");
        std::fs::remove_dir_all(dir).ok();
    }
}
