//! The one format table: every texel format lucent creates, reads back, imports or names, with
//! its size, channel count, how its values are encoded and its short name.
//!
//! Everything that needs to know about a format asks [`format_info`]: the plan's memory
//! estimates, readback and decoding, the benchmark's speed-of-light copies (which give
//! integer images the float format of the same size), the tonemap's output encoding for a caller's target image and
//! the names in tables. A format that is not here is refused where it enters (the graph
//! compiler names it), never guessed.

use ash::vk;

/// How a format stores its values, which decides how shaders read and write it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatKind {
    /// Unsigned normalised integers, read as floats in [0, 1].
    Unorm,
    /// Signed normalised integers, read as floats in [-1, 1].
    Snorm,
    /// 8-bit sRGB-encoded colour: the hardware decodes on read and encodes on write.
    Srgb,
    /// Floating point (fp16 or fp32, or packed unsigned floats).
    Float,
    /// Unsigned integers, read with `usampler*` and written as `uvec4`.
    Uint,
    /// Signed integers, read with `isampler*` and written as `ivec4`.
    Sint,
    /// A depth (and possibly stencil) format.
    Depth,
}

impl FormatKind {
    /// Whether shaders read and write it as integers (not floats).
    pub fn is_integer(self) -> bool {
        matches!(self, FormatKind::Uint | FormatKind::Sint)
    }
}

/// One row of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FormatInfo {
    /// The format.
    pub format: vk::Format,
    /// Short name for tables and plans (`RGBA16F`).
    pub name: &'static str,
    /// Bytes per texel.
    pub bytes: u32,
    /// Channels stored (depth-stencil: the depth aspect's 1).
    pub channels: u32,
    /// Encoding.
    pub kind: FormatKind,
    /// Whether the channel order is BGRA (swapchain formats).
    pub bgra: bool,
}

const fn row(
    format: vk::Format,
    name: &'static str,
    bytes: u32,
    channels: u32,
    kind: FormatKind,
) -> FormatInfo {
    FormatInfo {
        format,
        name,
        bytes,
        channels,
        kind,
        bgra: false,
    }
}

const fn bgra(format: vk::Format, name: &'static str, kind: FormatKind) -> FormatInfo {
    FormatInfo {
        format,
        name,
        bytes: 4,
        channels: 4,
        kind,
        bgra: true,
    }
}

/// The table.
pub const FORMATS: &[FormatInfo] = {
    use vk::Format as F;
    use FormatKind as K;
    &[
        row(F::R8_UNORM, "R8", 1, 1, K::Unorm),
        row(F::R8_SNORM, "R8_SNORM", 1, 1, K::Snorm),
        row(F::R8_UINT, "R8UI", 1, 1, K::Uint),
        row(F::R8_SINT, "R8I", 1, 1, K::Sint),
        row(F::R8_SRGB, "R8_SRGB", 1, 1, K::Srgb),
        row(F::R8G8_UNORM, "RG8", 2, 2, K::Unorm),
        row(F::R8G8_SNORM, "RG8_SNORM", 2, 2, K::Snorm),
        row(F::R8G8_UINT, "RG8UI", 2, 2, K::Uint),
        row(F::R8G8_SINT, "RG8I", 2, 2, K::Sint),
        row(F::R16_UNORM, "R16", 2, 1, K::Unorm),
        row(F::R16_SNORM, "R16_SNORM", 2, 1, K::Snorm),
        row(F::R16_UINT, "R16UI", 2, 1, K::Uint),
        row(F::R16_SINT, "R16I", 2, 1, K::Sint),
        row(F::R16_SFLOAT, "R16F", 2, 1, K::Float),
        row(F::R8G8B8A8_UNORM, "RGBA8", 4, 4, K::Unorm),
        row(F::R8G8B8A8_SNORM, "RGBA8_SNORM", 4, 4, K::Snorm),
        row(F::R8G8B8A8_UINT, "RGBA8UI", 4, 4, K::Uint),
        row(F::R8G8B8A8_SINT, "RGBA8I", 4, 4, K::Sint),
        row(F::R8G8B8A8_SRGB, "RGBA8_SRGB", 4, 4, K::Srgb),
        bgra(F::B8G8R8A8_UNORM, "BGRA8", K::Unorm),
        bgra(F::B8G8R8A8_SRGB, "BGRA8_SRGB", K::Srgb),
        row(F::A8B8G8R8_UNORM_PACK32, "ABGR8", 4, 4, K::Unorm),
        row(F::A8B8G8R8_SRGB_PACK32, "ABGR8_SRGB", 4, 4, K::Srgb),
        row(F::A2B10G10R10_UNORM_PACK32, "A2B10G10R10", 4, 4, K::Unorm),
        row(F::A2R10G10B10_UNORM_PACK32, "A2R10G10B10", 4, 4, K::Unorm),
        row(F::B10G11R11_UFLOAT_PACK32, "B10G11R11F", 4, 3, K::Float),
        row(F::E5B9G9R9_UFLOAT_PACK32, "E5B9G9R9F", 4, 3, K::Float),
        row(F::R16G16_UNORM, "RG16", 4, 2, K::Unorm),
        row(F::R16G16_SNORM, "RG16_SNORM", 4, 2, K::Snorm),
        row(F::R16G16_UINT, "RG16UI", 4, 2, K::Uint),
        row(F::R16G16_SINT, "RG16I", 4, 2, K::Sint),
        row(F::R16G16_SFLOAT, "RG16F", 4, 2, K::Float),
        row(F::R32_UINT, "R32UI", 4, 1, K::Uint),
        row(F::R32_SINT, "R32I", 4, 1, K::Sint),
        row(F::R32_SFLOAT, "R32F", 4, 1, K::Float),
        row(F::R16G16B16A16_UNORM, "RGBA16", 8, 4, K::Unorm),
        row(F::R16G16B16A16_SNORM, "RGBA16_SNORM", 8, 4, K::Snorm),
        row(F::R16G16B16A16_UINT, "RGBA16UI", 8, 4, K::Uint),
        row(F::R16G16B16A16_SINT, "RGBA16I", 8, 4, K::Sint),
        row(F::R16G16B16A16_SFLOAT, "RGBA16F", 8, 4, K::Float),
        row(F::R32G32_UINT, "RG32UI", 8, 2, K::Uint),
        row(F::R32G32_SINT, "RG32I", 8, 2, K::Sint),
        row(F::R32G32_SFLOAT, "RG32F", 8, 2, K::Float),
        row(F::R32G32B32_SFLOAT, "RGB32F", 12, 3, K::Float),
        row(F::R32G32B32A32_UINT, "RGBA32UI", 16, 4, K::Uint),
        row(F::R32G32B32A32_SINT, "RGBA32I", 16, 4, K::Sint),
        row(F::R32G32B32A32_SFLOAT, "RGBA32F", 16, 4, K::Float),
        row(F::S8_UINT, "S8", 1, 1, K::Uint),
        row(F::D16_UNORM, "D16", 2, 1, K::Depth),
        row(F::X8_D24_UNORM_PACK32, "X8D24", 4, 1, K::Depth),
        row(F::D32_SFLOAT, "D32", 4, 1, K::Depth),
        row(F::D24_UNORM_S8_UINT, "D24S8", 4, 1, K::Depth),
        row(F::D32_SFLOAT_S8_UINT, "D32S8", 8, 1, K::Depth),
    ]
};

/// The table's row for `format`, or `None` for a format lucent does not know.
pub fn format_info(format: vk::Format) -> Option<&'static FormatInfo> {
    FORMATS.iter().find(|f| f.format == format)
}

/// Bytes per texel, or `None` for a format lucent does not know.
pub fn texel_bytes(format: vk::Format) -> Option<u32> {
    format_info(format).map(|f| f.bytes)
}

/// The short name of a format (`RGBA16F`), or its Vulkan name when it is not in the table.
pub fn format_name(format: vk::Format) -> String {
    format_info(format).map_or_else(|| format!("{format:?}"), |f| f.name.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_appears_once_with_a_plausible_size() {
        for (i, f) in FORMATS.iter().enumerate() {
            assert!(
                FORMATS[..i].iter().all(|g| g.format != f.format),
                "{:?} twice",
                f.format
            );
            assert!(f.bytes >= 1 && f.bytes <= 16 && f.channels >= 1 && f.channels <= 4);
        }
        assert_eq!(texel_bytes(vk::Format::R32G32B32A32_UINT), Some(16));
        assert!(format_info(vk::Format::R32G32B32A32_UINT)
            .unwrap()
            .kind
            .is_integer());
        assert_eq!(format_name(vk::Format::R16G16B16A16_SFLOAT), "RGBA16F");
    }
}
