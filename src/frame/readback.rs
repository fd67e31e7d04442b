//! Frames read back: [`FrameImages`] (display, HDR, G-buffer, times) and the G-buffer decoded
//! to f32 ([`GBufferReadback`], the f64 reference's input).

use ash::vk;

use super::FrameTiming;
use crate::features::gbuffer::GBufferLayout;
use crate::{LucentError, Result};

/// One frame's read-back images.
#[derive(Clone, Debug)]
pub struct FrameImages {
    /// Display image, RGBA8 sRGB.
    pub display: Vec<u8>,
    /// Linear HDR RGBA f32, when exported.
    pub hdr: Option<Vec<f32>>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferReadback>,
    /// The frame's times.
    pub timing: FrameTiming,
}

/// The lighting pass's diffuse and specular before the SSS blurs, read back and decoded
/// (frames with SSS and `export_lit`), rows top first.
#[derive(Clone, Debug)]
pub struct LitReadback {
    /// Lit diffuse light; its alpha is the frame's own (linear depth, or a LEAN slope).
    pub diffuse: Vec<[f32; 4]>,
    /// Lit specular.
    pub specular: Vec<[f32; 4]>,
}

/// A G-buffer read back and decoded: one `[f32; 4]` per pixel and target (missing channels
/// are 0), rows top first.
#[derive(Clone, Debug)]
pub struct GBufferReadback {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Albedo rgb + specular.
    pub gb0: Vec<[f32; 4]>,
    /// Normal xyz + roughness.
    pub gb1: Vec<[f32; 4]>,
    /// Thickness + material ID as stored (see glsl/common/gbuffer.glsl).
    pub gb2: Option<Vec<[f32; 4]>>,
    /// Screen-space SSS profile ID per pixel (frames with SSS; 0: the pixel does not
    /// scatter).
    pub sss: Option<Vec<f32>>,
    /// View-plane LEAN slope y and second moments xx, yy, xy (LCB and LBB frames).
    pub lean: Option<Vec<[f32; 4]>>,
    /// Li et al.'s layered target (frames with layered media): the material ID / 255 in red
    /// (0: the pixel is not layered) and, in frames with the film, the film texel in green,
    /// blue and alpha.
    pub layered: Option<Vec<[f32; 4]>>,
    /// The `TexDep` texels as stored (frames whose layered media read depth textures): the
    /// bytes of the `R32G32_UINT` or `R32G32B32A32_UINT` target, two fp16 texels per 32-bit
    /// component (glsl/common/layer_depths.glsl).
    pub layer_depths: Option<Vec<u8>>,
    /// Device depth.
    pub depth: Vec<f32>,
    /// The layout the frame used.
    pub layout: GBufferLayout,
}

/// Decodes tightly packed texels to f32, for the formats of the format table whose channels
/// are whole bytes: 8-bit (UNORM and sRGB as stored, `/ 255`), fp16, fp32 and 32-bit integers
/// (as their values). Depth formats decode their depth aspect, which reads back as 32-bit
/// float for D32 and D32S8.
pub fn decode_texels(bytes: &[u8], format: vk::Format) -> Result<Vec<[f32; 4]>> {
    use crate::backend::format::{format_info, FormatKind};
    let unsupported =
        || LucentError::InvalidInput(format!("cannot decode texels of format {format:?}"));
    let info = format_info(format).ok_or_else(unsupported)?;
    let channels = info.channels as usize;
    let component = match info.kind {
        FormatKind::Depth => match format {
            vk::Format::D32_SFLOAT | vk::Format::D32_SFLOAT_S8_UINT => 4,
            _ => return Err(unsupported()),
        },
        _ if info.bytes % info.channels == 0 => (info.bytes / info.channels) as usize,
        _ => return Err(unsupported()),
    };
    let values: Vec<f32> = match (info.kind, component) {
        (FormatKind::Unorm | FormatKind::Srgb, 1) => {
            bytes.iter().map(|&b| f32::from(b) / 255.0).collect()
        }
        (FormatKind::Float, 2) => crate::images::output::f16_bytes_to_f32(bytes),
        (FormatKind::Float | FormatKind::Depth, 4) => bytes
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        (FormatKind::Uint, 4) => bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]) as f32)
            .collect(),
        _ => return Err(unsupported()),
    };
    let mut texels: Vec<[f32; 4]> = values
        .chunks_exact(channels)
        .map(|c| {
            let mut t = [0.0; 4];
            t[..channels].copy_from_slice(c);
            t
        })
        .collect();
    if info.bgra {
        for t in &mut texels {
            t.swap(0, 2);
        }
    }
    Ok(texels)
}
