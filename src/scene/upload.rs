//! Texture files written straight into an upload buffer in the layout the GPU samples, their
//! mip chain made in place: how the renderer loads a texture file (`gpu_scene`), at about
//! twice its decoded size plus mips in host memory while loading.
//!
//! [`load_texture`](super::texture::load_texture) makes linear `f32` texels with mips (about
//! 21 bytes a texel) for what computes with a texture on the CPU. A texture bound for the GPU
//! needs none of that: [`write_texture_chain`](super::texture::write_texture_chain) takes the file decoded as it is stored
//! ([`DecodedImage`](super::texture::DecodedImage)), writes level 0 into the caller's buffer (the staging buffer of the
//! upload) in the smallest [`UploadLayout`] that keeps what the file holds, drops the decoded
//! file, and makes every next mip level from the one before it inside that buffer:
//!
//! | file stores | usage | layout | bytes a texel |
//! |---|---|---|---|
//! | 8-bit grey, grey + alpha, RGB, RGBA | data (normal maps, masks) | [`UploadLayout::Unorm8`], values as stored | 4 |
//! | 8-bit, as above | colour | [`UploadLayout::Srgb8`], still sRGB-encoded: the sampler decodes, exactly as the loader would | 4 |
//! | 16-bit integers, 32-bit floats (EXR, HDR) | any | [`UploadLayout::Half`], linear binary16 (what these were uploaded as before) | 8 |
//!
//! Host memory while loading: the decoded file and the staging buffer, then (the file dropped)
//! the staging buffer and the GPU image, which on a CPU driver is host memory too. For an
//! 8-bit RGBA file that is twice its decoded size plus mips; an RGB or grey one costs less
//! while decoding. Derived maps (the LEAN maps of a normal map) are written the same way by
//! [`write_chain`] from a function of the level-0 texel, so neither they nor the normal map
//! exist as `f32` images.
//!
//! Mips: the area-weighted box filter of [`Texture`](super::texture::Texture)'s chain (a
//! texel of an odd-sized level's next level covers 2.5 texels, weights 1, 1, 0.5: every level
//! keeps the mean), each level accumulated in `f32` from the stored level before it: data as
//! stored, colour in linear light (sRGB decoded, averaged, re-encoded), alpha linear. The
//! 8-bit layouts round each level to 8 bits, as a GPU's own mip generation would.

use rayon::prelude::*;

use crate::{LucentError, Result};

/// The texel layout a texture is uploaded in (see the module docs for which file gets which).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UploadLayout {
    /// RGBA, 8 bits a channel, values as stored (`R8G8B8A8_UNORM`).
    Unorm8,
    /// RGBA, 8 bits a channel, sRGB-encoded RGB and linear alpha (`R8G8B8A8_SRGB`).
    Srgb8,
    /// RGBA binary16, linear (`R16G16B16A16_SFLOAT`).
    Half,
    /// One binary16 channel, linear (`R16_SFLOAT`): sampled as `(r, 0, 0, 1)`.
    HalfRed,
}

impl UploadLayout {
    /// Bytes of one texel.
    pub fn texel_bytes(self) -> usize {
        match self {
            UploadLayout::Unorm8 | UploadLayout::Srgb8 => 4,
            UploadLayout::Half => 8,
            UploadLayout::HalfRed => 2,
        }
    }

    /// The texel `bytes` hold, as linear RGBA.
    fn decode(self, bytes: &[u8], srgb: &[f32; 256]) -> [f32; 4] {
        let unorm = |v: u8| f32::from(v) / 255.0;
        let half = |i: usize| half::f16::from_le_bytes([bytes[i], bytes[i + 1]]).to_f32();
        match self {
            UploadLayout::Unorm8 => std::array::from_fn(|c| unorm(bytes[c])),
            UploadLayout::Srgb8 => [
                srgb[usize::from(bytes[0])],
                srgb[usize::from(bytes[1])],
                srgb[usize::from(bytes[2])],
                unorm(bytes[3]),
            ],
            UploadLayout::Half => std::array::from_fn(|c| half(c * 2)),
            UploadLayout::HalfRed => [half(0), 0.0, 0.0, 1.0],
        }
    }

    /// Writes linear RGBA `t` into `out` (one texel). Values are clamped to what the layout
    /// holds (`[0, 1]` for 8 bits, fp16's finite range), so nothing overflows to infinity.
    pub(super) fn encode(self, t: [f32; 4], out: &mut [u8]) {
        let unorm = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
        let half = |v: f32| half::f16::from_f32(v.clamp(-65504.0, 65504.0)).to_le_bytes();
        match self {
            UploadLayout::Unorm8 => {
                for c in 0..4 {
                    out[c] = unorm(t[c]);
                }
            }
            UploadLayout::Srgb8 => {
                for c in 0..3 {
                    out[c] = unorm(linear_to_srgb(t[c].clamp(0.0, 1.0)));
                }
                out[3] = unorm(t[3]);
            }
            UploadLayout::Half => {
                for c in 0..4 {
                    out[c * 2..c * 2 + 2].copy_from_slice(&half(t[c]));
                }
            }
            UploadLayout::HalfRed => out[..2].copy_from_slice(&half(t[0])),
        }
    }
}

/// Mip levels of a `width x height` texture down to 1x1 (`floor(log2(max side)) + 1`).
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1), encoded [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// For each texel of a `m`-texel axis downsampled from `n` texels: the source texels it covers
/// and their weights (overlap / footprint), summing to 1.
pub(super) fn axis_weights(n: usize, m: usize) -> Vec<Vec<(usize, f32)>> {
    (0..m)
        .map(|i| {
            let start = i as f64 * n as f64 / m as f64;
            let end = (i + 1) as f64 * n as f64 / m as f64;
            let width = end - start; // >= 1 because m <= n
            (start.floor() as usize..(end.ceil() as usize).min(n))
                .filter_map(|j| {
                    let overlap = end.min(j as f64 + 1.0) - start.max(j as f64);
                    (overlap > 0.0).then(|| (j, (overlap / width) as f32))
                })
                .collect()
        })
        .collect()
}

/// Bytes of each mip level of a `width x height` texture in `layout`, level 0 first, down to
/// 1x1 (`max(1, size >> level)` per side).
pub fn level_bytes(width: u32, height: u32, layout: UploadLayout) -> Vec<u64> {
    (0..mip_levels(width, height))
        .map(|level| {
            let (w, h) = ((width >> level).max(1), (height >> level).max(1));
            u64::from(w) * u64::from(h) * layout.texel_bytes() as u64
        })
        .collect()
}

/// Writes a whole mip chain of a `width x height` texture into `out` (its [`level_bytes`] for
/// `layout`, packed, level 0 first): level 0 texel (`x`, `y`) is `texel(x, y)` (linear RGBA,
/// encoded as `layout` stores it), the rest is made from it in place.
pub fn write_chain(
    width: u32,
    height: u32,
    layout: UploadLayout,
    out: &mut [u8],
    texel: impl Fn(usize, usize) -> [f32; 4] + Sync,
) -> Result<()> {
    let (level0, rest) = split_level0(width, height, layout, out)?;
    let row_bytes = width as usize * layout.texel_bytes();
    level0
        .par_chunks_mut(row_bytes)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.chunks_exact_mut(layout.texel_bytes()).enumerate() {
                layout.encode(texel(x, y), out);
            }
        });
    make_mips(width, height, layout, level0, rest);
    Ok(())
}

/// `out` split into level 0 and the levels after it, checked against [`level_bytes`].
pub(super) fn split_level0(
    width: u32,
    height: u32,
    layout: UploadLayout,
    out: &mut [u8],
) -> Result<(&mut [u8], &mut [u8])> {
    let expected: u64 = level_bytes(width, height, layout).iter().sum();
    if width == 0 || height == 0 || out.len() as u64 != expected {
        return Err(LucentError::InvalidInput(format!(
            "a {width}x{height} {layout:?} mip chain is {expected} bytes, not {}",
            out.len()
        )));
    }
    Ok(out.split_at_mut(width as usize * height as usize * layout.texel_bytes()))
}

/// Makes every level after `level0` (a `width x height` image in `layout`) into `rest`, each
/// from the level before it.
pub(super) fn make_mips(
    width: u32,
    height: u32,
    layout: UploadLayout,
    level0: &[u8],
    rest: &mut [u8],
) {
    let srgb: [f32; 256] = std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0));
    let tb = layout.texel_bytes();
    let (mut w, mut h) = (width as usize, height as usize);
    // The level being read: level 0 first, then the last level written into `rest`.
    let mut src_start: Option<usize> = None;
    let mut dst_start = 0usize;
    while w > 1 || h > 1 {
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let (done, todo) = rest.split_at_mut(dst_start);
        let src = match src_start {
            None => level0,
            Some(start) => &done[start..],
        };
        let dst = &mut todo[..nw * nh * tb];
        downsample(layout, &srgb, src, w, h, dst, nw, nh);
        src_start = Some(dst_start);
        dst_start += nw * nh * tb;
        (w, h) = (nw, nh);
    }
}

/// One mip step in `layout`: `src` (`w x h`) into `dst` (`nw x nh`), area-weighted.
#[allow(clippy::too_many_arguments)]
fn downsample(
    layout: UploadLayout,
    srgb: &[f32; 256],
    src: &[u8],
    w: usize,
    h: usize,
    dst: &mut [u8],
    nw: usize,
    nh: usize,
) {
    let tb = layout.texel_bytes();
    let wx = axis_weights(w, nw);
    let wy = axis_weights(h, nh);
    dst.par_chunks_mut(nw * tb)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, out) in row.chunks_exact_mut(tb).enumerate() {
                let mut sum = [0.0f32; 4];
                for &(sy, weight_y) in &wy[y] {
                    for &(sx, weight_x) in &wx[x] {
                        let at = (sy * w + sx) * tb;
                        let t = layout.decode(&src[at..at + tb], srgb);
                        for c in 0..4 {
                            sum[c] += t[c] * (weight_x * weight_y);
                        }
                    }
                }
                layout.encode(sum, out);
            }
        });
    debug_assert_eq!(dst.len(), nw * nh * tb);
}

/// The sRGB encoding (IEC 61966-2-1) of linear `c` in [0, 1]: the inverse of
/// [`srgb_to_linear`].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::texture::{Texture, TextureUsage};

    /// A deterministic pseudo-random 8-bit RGBA image.
    fn noise(w: usize, h: usize, seed: u32) -> Vec<u8> {
        let mut state = seed;
        (0..w * h * 4)
            .map(|_| {
                state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (state >> 24) as u8
            })
            .collect()
    }

    /// The largest difference, per level, between the chain `write_chain` makes in `layout`
    /// and `Texture`'s `f32` chain of the same level 0 (both as linear values).
    fn worst_per_level(w: u32, h: u32, layout: UploadLayout, bytes: &[u8]) -> Vec<f32> {
        let srgb: [f32; 256] = std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0));
        let tb = layout.texel_bytes();
        let level0: Vec<[f32; 4]> = bytes
            .chunks_exact(4)
            .map(|p| {
                let t = UploadLayout::Unorm8.decode(p, &srgb);
                if layout == UploadLayout::Srgb8 {
                    UploadLayout::Srgb8.decode(p, &srgb)
                } else {
                    t
                }
            })
            .collect();
        let reference =
            Texture::from_texels("noise", w, h, TextureUsage::Data, level0.clone()).unwrap();
        let mut out = vec![0u8; level_bytes(w, h, layout).iter().sum::<u64>() as usize];
        write_chain(w, h, layout, &mut out, |x, y| level0[y * w as usize + x]).unwrap();
        let mut worst = Vec::new();
        let mut start = 0;
        for (level, mip) in reference.mips.iter().enumerate() {
            let ours = &out[start..start + mip.len() * tb];
            start += mip.len() * tb;
            let mut level_worst = 0.0f32;
            for (t, o) in mip.iter().zip(ours.chunks_exact(tb)) {
                let o = layout.decode(o, &srgb);
                for c in 0..4 {
                    level_worst = level_worst.max((t[c] - o[c]).abs());
                }
            }
            assert!(level < 32);
            worst.push(level_worst);
        }
        assert_eq!(
            start,
            out.len(),
            "every byte of the chain belongs to a level"
        );
        worst
    }

    #[test]
    fn eight_bit_chains_stay_within_rounding_of_the_f32_chain() {
        // Odd sizes too: the area weights of a 5-wide level.
        for (w, h) in [(64, 64), (37, 20), (1, 9)] {
            let bytes = noise(w as usize, h as usize, w * 31 + h);
            // Level 0 is exact; each later level rounds once to 8 bits, from a level that was
            // rounded itself: the error grows by at most half a step per level.
            let worst = worst_per_level(w, h, UploadLayout::Unorm8, &bytes);
            assert_eq!(worst[0], 0.0);
            for (level, &e) in worst.iter().enumerate() {
                assert!(
                    e <= (0.5 * level as f32 + 1e-3) / 255.0,
                    "{w}x{h} level {level}: {e}"
                );
            }
            let worst = worst_per_level(w, h, UploadLayout::Half, &bytes);
            for (level, &e) in worst.iter().enumerate() {
                assert!(e <= 1e-3, "{w}x{h} half level {level}: {e}");
            }
        }
    }

    #[test]
    fn srgb_chains_average_in_linear_light() {
        // Black and white columns: the 1x1 level is mid grey in linear light (0.5), which
        // sRGB encodes as 188, not the 128 an average of the encoded bytes would give.
        let (w, h) = (8u32, 8u32);
        let bytes: Vec<u8> = (0..w * h)
            .flat_map(|i| {
                if i % 2 == 0 {
                    [0, 0, 0, 255]
                } else {
                    [255, 255, 255, 255]
                }
            })
            .collect();
        let srgb: [f32; 256] = std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0));
        let mut out =
            vec![0u8; level_bytes(w, h, UploadLayout::Srgb8).iter().sum::<u64>() as usize];
        write_chain(w, h, UploadLayout::Srgb8, &mut out, |x, y| {
            let i = (y * w as usize + x) * 4;
            UploadLayout::Srgb8.decode(&bytes[i..i + 4], &srgb)
        })
        .unwrap();
        // Level 0 round-trips exactly through the decode and encode.
        assert_eq!(&out[..bytes.len()], &bytes[..]);
        let top = &out[out.len() - 4..];
        assert_eq!(top, &[188, 188, 188, 255]);
        let worst = worst_per_level(w, h, UploadLayout::Srgb8, &bytes);
        assert!(worst.iter().all(|&e| e <= 2.0 / 255.0), "{worst:?}");
    }

    #[test]
    fn a_buffer_of_the_wrong_size_is_refused() {
        let mut out = vec![0u8; 10];
        let err = write_chain(4, 4, UploadLayout::Unorm8, &mut out, |_, _| [0.0; 4]).unwrap_err();
        assert!(err.to_string().contains("not 10"), "{err}");
    }
}
