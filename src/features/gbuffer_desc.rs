//! A G-buffer as lucent's effects read it (a host's, or lucent's own: [`super::gbuffer::GBufferLayout::described`]): each image's format and encoding, the
//! camera as the host's own matrices, and the world's scale. A description holds no handles;
//! the images themselves come with each frame ([`crate::embed::HostImage`]).
//!
//! lucent adapts to the host's layout rather than asking for its own: depth in any depth
//! format with any perspective (standard or reversed Z, finite or infinite far: the depth is
//! decoded through the host's projection matrix) or as linear view depth; material IDs as an
//! `R8_UINT` or `R8_UNORM` image, stencil bits, or a bit field of one channel of a packed
//! target; the diffuse light with or without the albedo multiplied in. Everything is checked
//! when an effect is built ([`GBufferDesc::check`]): an unsupported combination is a
//! [`HostError`] naming the input and what lucent would accept, before anything is recorded.

use ash::vk;
use glam::Mat4;

use crate::backend::format::{format_info, format_name, FormatKind};
use crate::error::HostError;
use crate::Result;

/// How the depth image's values encode depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum DepthEncoding {
    /// The device depth the host's projection wrote (a depth format): decoded through the
    /// projection matrix each frame, so near and far, standard or reversed Z and a finite or
    /// infinite far plane all follow from the matrix.
    Device,
    /// View-space depth in world units along the view axis, positive in front of the camera
    /// (an `R32_SFLOAT` or `R16_SFLOAT` colour image), as some engines keep for their own
    /// post-processing.
    LinearView,
}

/// The host's depth image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct DepthDesc {
    /// Its format: `D32_SFLOAT`, `D32_SFLOAT_S8_UINT`, `D24_UNORM_S8_UINT`,
    /// `X8_D24_UNORM_PACK32` or `D16_UNORM` for [`DepthEncoding::Device`] (the view the host
    /// passes is of the depth aspect), `R32_SFLOAT` or `R16_SFLOAT` for
    /// [`DepthEncoding::LinearView`].
    pub format: vk::Format,
    /// How its values encode depth.
    pub encoding: DepthEncoding,
}

impl DepthDesc {
    /// A depth buffer written through the host's projection.
    pub fn device(format: vk::Format) -> Self {
        Self {
            format,
            encoding: DepthEncoding::Device,
        }
    }

    /// A colour image holding linear view depth.
    pub fn linear(format: vk::Format) -> Self {
        Self {
            format,
            encoding: DepthEncoding::LinearView,
        }
    }
}

/// Whether the host's lit diffuse light has the surface albedo multiplied in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum DiffuseAlbedo {
    /// `light * albedo` (most engines' lit diffuse).
    Included,
    /// The light alone (irradiance / pi), the albedo kept apart in the albedo image (as
    /// engines that apply the albedo after their SSS do).
    Excluded,
    /// Each screen-space SSS material's pixels hold the part of the albedo its profile's
    /// texturing puts before the blur ([`crate::scene::material::Texturing`]: all of it for
    /// `pre`, none for `post`, its square root for `pre-post`); every other pixel all of it.
    /// HDRP's lighting pass writes its diffuse so, and lucent's own does: [`crate::embed::SssEffect`]
    /// then needs no pass to put the albedo right (the albedo image only for the profiles
    /// that apply it after the blur). The effects that add light of their own to the diffuse
    /// (the environment, SSS transmission) refuse it: they do not know which pixels scatter.
    AsTexturing,
}

/// The host's lit diffuse light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct DiffuseDesc {
    /// A sampled float, UNORM or SRGB colour format (linear values; alpha not read), e.g.
    /// `R16G16B16A16_SFLOAT` or `B10G11R11_UFLOAT_PACK32`.
    pub format: vk::Format,
    /// Whether the albedo is in it.
    pub albedo: DiffuseAlbedo,
    /// Whether its alpha holds the pixel's linear view depth (world units along the view
    /// axis, positive in front of the camera), as lucent's own lighting pass writes it and
    /// Jimenez et al.'s separable SSS reads it: the separable and Burley blurs then read each
    /// tap's depth with its light, one fetch instead of two. Needs a float format with alpha.
    pub depth_in_alpha: bool,
}

impl DiffuseDesc {
    /// Diffuse light with the albedo multiplied in.
    pub fn with_albedo(format: vk::Format) -> Self {
        Self {
            format,
            albedo: DiffuseAlbedo::Included,
            depth_in_alpha: false,
        }
    }

    /// Diffuse light without the albedo.
    pub fn without_albedo(format: vk::Format) -> Self {
        Self {
            format,
            albedo: DiffuseAlbedo::Excluded,
            depth_in_alpha: false,
        }
    }

    /// Diffuse light with the albedo as each SSS material's texturing asks
    /// ([`DiffuseAlbedo::AsTexturing`]).
    pub fn with_albedo_as_texturing(format: vk::Format) -> Self {
        Self {
            format,
            albedo: DiffuseAlbedo::AsTexturing,
            depth_in_alpha: false,
        }
    }

    /// With linear view depth in the alpha channel ([`Self::depth_in_alpha`]).
    pub fn with_depth_in_alpha(mut self) -> Self {
        self.depth_in_alpha = true;
        self
    }
}

/// Where in the material ID image the IDs are.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum IdEncoding {
    /// The first channel's value is the ID: `R8_UINT` (the integer) or `R8_UNORM` (the ID
    /// `k` stored as `k / 255`), or any one-channel UINT / UNORM format of up to 8 bits.
    Value,
    /// Bits `shift .. shift + count` of the stencil aspect of a depth-stencil image (the view
    /// the host passes is of the stencil aspect).
    Stencil {
        /// The lowest bit.
        shift: u8,
        /// How many bits (1 to 8).
        count: u8,
    },
    /// Bits `shift .. shift + count` of one channel of a packed target (UINT, or UNORM read
    /// back as its integer: the alpha of an `RGBA8` or `RGB10A2` target, say).
    Bits {
        /// The channel: 0 = R, 1 = G, 2 = B, 3 = A.
        channel: u8,
        /// The lowest bit.
        shift: u8,
        /// How many bits (1 to 8).
        count: u8,
    },
}

/// How the passes find a pixel's material in an ID image (`IdDesc::decode`): a bit field of
/// one channel of the image, and the profile number of each ID. lucent's own G-buffer
/// (`IdMap::lucent`, its description's decode) and a host's are read by the same passes with
/// their specialization constants (`IdMap::specialization`); those methods, which only the SSS passes use, are in
/// `crate::features::sss`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct IdMap {
    /// The image is read as unsigned integers (a UINT format or a stencil aspect; define
    /// `LUCENT_SSS_IDS_UINT`), else as UNORM floats turned back into their integers.
    pub uint: bool,
    /// The channel holding the IDs (0 = R).
    pub channel: u32,
    /// The ID's bit field: `(value >> shift) & mask`.
    pub shift: u32,
    /// Its mask (at most 8 bits: IDs 0 to 255).
    pub mask: u32,
    /// For UNORM channels, the largest integer (`2^bits - 1`).
    pub unorm_max: u32,
    /// The profile number (1 to the number of profiles; 0: none) of each ID 0 to 255.
    pub profile_of: Vec<u8>,
}

/// The host's per-pixel material ID image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct IdDesc {
    /// The image's format.
    pub format: vk::Format,
    /// Where the ID is in it.
    pub encoding: IdEncoding,
}

impl IdDesc {
    /// A one-channel ID image (`R8_UINT`, `R8_UNORM`).
    pub fn value(format: vk::Format) -> Self {
        Self {
            format,
            encoding: IdEncoding::Value,
        }
    }

    /// IDs in stencil bits of a depth-stencil image.
    pub fn stencil(format: vk::Format, shift: u8, count: u8) -> Self {
        Self {
            format,
            encoding: IdEncoding::Stencil { shift, count },
        }
    }

    /// IDs in a bit field of one channel of a packed target.
    pub fn bits(format: vk::Format, channel: u8, shift: u8, count: u8) -> Self {
        Self {
            format,
            encoding: IdEncoding::Bits {
                channel,
                shift,
                count,
            },
        }
    }

    /// How the passes decode it, with each host ID's profile number from `profile_of`.
    pub(crate) fn decode(&self, profile_of: Vec<u8>) -> Result<IdMap> {
        let refuse = |found: String, accepted: &str| -> crate::LucentError {
            HostError::Unsupported {
                input: "material IDs".into(),
                found,
                accepted: accepted.into(),
            }
            .into()
        };
        let info = format_info(self.format).ok_or_else(|| {
            refuse(
                format!("format {:?}", self.format),
                "a UINT or UNORM colour format, or a depth-stencil format's stencil",
            )
        })?;
        let name = format_name(self.format);
        let (uint, channel, shift, count, channel_bits) = match self.encoding {
            IdEncoding::Value => {
                let bits = channel_bits(self.format, 0);
                if info.channels != 1 || !matches!(info.kind, FormatKind::Uint | FormatKind::Unorm)
                {
                    return Err(refuse(
                        format!("format {name} with IdEncoding::Value"),
                        "a one-channel UINT or UNORM format (R8_UINT, R8_UNORM); for a channel \
                         of a packed target, IdEncoding::Bits",
                    ));
                }
                // The whole channel is the ID; IDs past 255 have no profile (the shader's
                // sss_host_profile), so a 16-bit ID image works for the IDs it can map.
                return Ok(IdMap {
                    uint: info.kind == FormatKind::Uint,
                    channel: 0,
                    shift: 0,
                    mask: if bits >= 32 {
                        u32::MAX
                    } else {
                        (1u32 << bits) - 1
                    },
                    unorm_max: if info.kind == FormatKind::Uint {
                        0
                    } else {
                        ((1u64 << bits) - 1) as u32
                    },
                    profile_of,
                });
            }
            IdEncoding::Stencil { shift, count } => {
                if !crate::backend::access::has_stencil(self.format) {
                    return Err(refuse(
                        format!("format {name} with IdEncoding::Stencil"),
                        "a format with a stencil aspect (D24_UNORM_S8_UINT, D32_SFLOAT_S8_UINT, \
                         S8_UINT)",
                    ));
                }
                (true, 0, shift, count, 8)
            }
            IdEncoding::Bits {
                channel,
                shift,
                count,
            } => {
                if !matches!(info.kind, FormatKind::Uint | FormatKind::Unorm)
                    || u32::from(channel) >= info.channels
                {
                    return Err(refuse(
                        format!("channel {channel} of format {name}"),
                        "a channel the format has, of a UINT or UNORM format",
                    ));
                }
                (
                    info.kind == FormatKind::Uint,
                    channel,
                    shift,
                    count,
                    channel_bits(self.format, u32::from(channel)),
                )
            }
        };
        if count == 0 || count > 8 || u32::from(shift) + u32::from(count) > channel_bits {
            return Err(refuse(
                format!(
                    "bits {shift}..{} of a {channel_bits}-bit channel",
                    shift as u32 + count as u32
                ),
                "1 to 8 bits (IDs 0 to 255) inside the channel",
            ));
        }
        Ok(IdMap {
            uint,
            channel: u32::from(channel),
            shift: u32::from(shift),
            mask: (1u32 << count) - 1,
            unorm_max: if uint { 0 } else { (1u32 << channel_bits) - 1 },
            profile_of,
        })
    }
}

/// Bits of channel `channel` of `format` (packed 10:10:10:2 formats by channel, every other
/// format its bytes shared evenly).
fn channel_bits(format: vk::Format, channel: u32) -> u32 {
    match format {
        vk::Format::A2B10G10R10_UNORM_PACK32
        | vk::Format::A2B10G10R10_UINT_PACK32
        | vk::Format::A2R10G10B10_UNORM_PACK32
        | vk::Format::A2R10G10B10_UINT_PACK32 => {
            if channel == 3 {
                2
            } else {
                10
            }
        }
        _ => format_info(format).map_or(8, |f| 8 * f.bytes / f.channels.max(1)),
    }
}

/// How the normal image's values encode a unit normal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum NormalEncoding {
    /// x, y, z in the first three channels: as stored for float and SNORM formats, `2v - 1`
    /// for UNORM ones (`RGBA16F`, `RGB10A2`, `RGBA8`).
    Xyz,
    /// Octahedral (Cigolle et al. 2014) in the first two channels, in [-1, 1] (float and
    /// SNORM formats) or mapped to [0, 1] (UNORM: `RG16_UNORM`, `RG8_UNORM`).
    Octahedral,
}

/// The space the host's normals are in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum NormalSpace {
    /// World space.
    World,
    /// View space of the frame's [`HostCamera::view`] (turned to world space with its
    /// inverse).
    View,
}

/// The host's per-pixel shading normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct NormalDesc {
    /// Its format: a float, SNORM or UNORM colour format with the channels the encoding
    /// reads (3 for [`NormalEncoding::Xyz`], 2 for [`NormalEncoding::Octahedral`]).
    pub format: vk::Format,
    /// How the channels hold the normal.
    pub encoding: NormalEncoding,
    /// The space.
    pub space: NormalSpace,
}

impl NormalDesc {
    /// World-space normals as x, y, z.
    pub fn world(format: vk::Format) -> Self {
        Self {
            format,
            encoding: NormalEncoding::Xyz,
            space: NormalSpace::World,
        }
    }

    /// Octahedral normals in `space`.
    pub fn octahedral(format: vk::Format, space: NormalSpace) -> Self {
        Self {
            format,
            encoding: NormalEncoding::Octahedral,
            space,
        }
    }

    /// With the normals in `space`.
    pub fn in_space(mut self, space: NormalSpace) -> Self {
        self.space = space;
        self
    }

    /// Checks the format against the encoding; returns the shader's decode (x: octahedral,
    /// y: view space, z: UNORM channels mapped from [0, 1]).
    pub(crate) fn decode(&self) -> Result<[u32; 4]> {
        let needed = match self.encoding {
            NormalEncoding::Xyz => 3,
            NormalEncoding::Octahedral => 2,
        };
        let info = format_info(self.format);
        let kind_ok = info.is_some_and(|f| {
            matches!(
                f.kind,
                FormatKind::Unorm | FormatKind::Snorm | FormatKind::Float
            )
        });
        let channels = info.map_or(0, |f| f.channels);
        if !kind_ok || channels < needed {
            return Err(HostError::Unsupported {
                input: "normals".into(),
                found: format!(
                    "format {} with {:?}",
                    format_name(self.format),
                    self.encoding
                ),
                accepted: format!(
                    "a float, SNORM or UNORM colour format with at least {needed} channels \
                     (Xyz: RGBA16F, RGB10A2, RGBA8; Octahedral: RG16_UNORM, RG16F, RG8_SNORM)"
                ),
            }
            .into());
        }
        let unorm = info.is_some_and(|f| f.kind == FormatKind::Unorm);
        Ok([
            u32::from(self.encoding == NormalEncoding::Octahedral),
            u32::from(self.space == NormalSpace::View),
            u32::from(unorm),
            0,
        ])
    }
}

/// Which channels of the thickness image hold the local thickness.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ThicknessChannels {
    /// One channel (0 = R .. 3 = A): grayscale thickness, the talk's one G-buffer channel.
    One(u8),
    /// R, G and B: coloured thickness (light of each colour let through apart).
    Rgb,
}

/// The host's local thickness per pixel, GDC 2011's "inverted ambient occlusion": 0 opaque,
/// 1 lets all the light through. [`crate::embed::bake_thickness`] bakes it per vertex from
/// a mesh, for the host to carry through its vertex buffers into this image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ThicknessDesc {
    /// A float or UNORM colour format (values clamped to [0, 1]).
    pub format: vk::Format,
    /// The channels.
    pub channels: ThicknessChannels,
}

impl ThicknessDesc {
    /// Grayscale thickness in channel `channel` of `format`.
    pub fn channel(format: vk::Format, channel: u8) -> Self {
        Self {
            format,
            channels: ThicknessChannels::One(channel),
        }
    }

    /// Coloured thickness in the R, G, B channels of `format`.
    pub fn rgb(format: vk::Format) -> Self {
        Self {
            format,
            channels: ThicknessChannels::Rgb,
        }
    }

    /// Checks the format against the channels; returns the shader's decode (x: the channel,
    /// 4 for rgb).
    pub(crate) fn decode(&self) -> Result<[u32; 4]> {
        let info = format_info(self.format);
        let channels = info.map_or(0, |f| f.channels);
        let kind_ok = info.is_some_and(|f| matches!(f.kind, FormatKind::Unorm | FormatKind::Float));
        let (channel, needed) = match self.channels {
            ThicknessChannels::One(c) => (u32::from(c), u32::from(c) + 1),
            ThicknessChannels::Rgb => (4, 3),
        };
        if !kind_ok || channels < needed {
            return Err(HostError::Unsupported {
                input: "thickness".into(),
                found: format!("{:?} of format {}", self.channels, format_name(self.format)),
                accepted: "a float or UNORM colour format that has the channels named".into(),
            }
            .into());
        }
        Ok([channel, 0, 0, 0])
    }
}

/// The LEAN targets a host's G-buffer pass writes for LCB, LBB and the bilateral blur, as
/// lucent's own G-buffer pass writes them ([`GBufferDesc::with_lean_targets`]). With them the
/// [`crate::embed::SssEffect`] reads the host's LEAN moments, albedo and normals as they are, instead of
/// building them from the normals in a pass of its own (`sss lean in`): the same work as
/// lucent's own frame, and the LEAN maps' spread inside a pixel is kept. The values are those
/// of [`crate::embed::glsl::TERMS`]' `lucent_view_plane_lean` (which lucent's own passes call):
///
/// | image | rgba |
/// |---|---|
/// | `moments` | view-plane slope mean y, second moments xx, yy, xy (`vec4(b_v.y, m_v)`) |
/// | `albedo_specular` | albedo, specular intensity |
/// | `normal_roughness` | mean world normal (`n_world`, unit), roughness |
/// | the lit diffuse's alpha | view-plane slope mean x (`lucent_view_slope(view * n_world).x`) |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct LeanTargetsDesc {
    /// The slope y and moments: a float format with four channels (`R16G16B16A16_SFLOAT`,
    /// `R32G32B32A32_SFLOAT`; moments reach 60000).
    pub moments: vk::Format,
    /// The albedo and specular intensity: a float, UNORM or SRGB format with four channels.
    pub albedo_specular: vk::Format,
    /// The world normal and roughness: a float or SNORM format with four channels (the
    /// normal is signed).
    pub normal_roughness: vk::Format,
}

impl LeanTargetsDesc {
    /// The three targets' formats.
    pub fn new(
        moments: vk::Format,
        albedo_specular: vk::Format,
        normal_roughness: vk::Format,
    ) -> Self {
        Self {
            moments,
            albedo_specular,
            normal_roughness,
        }
    }

    /// Checks each format against what its target holds.
    fn check(&self) -> Result<()> {
        let four = |format: vk::Format, kinds: &[FormatKind]| {
            format_info(format).is_some_and(|f| f.channels == 4 && kinds.contains(&f.kind))
        };
        for (input, format, kinds, accepted) in [
            (
                "lean targets: moments",
                self.moments,
                &[FormatKind::Float][..],
                "a float format with four channels (R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT)",
            ),
            (
                "lean targets: albedo and specular",
                self.albedo_specular,
                &[FormatKind::Unorm, FormatKind::Srgb, FormatKind::Float][..],
                "a float, UNORM or SRGB format with four channels",
            ),
            (
                "lean targets: normal and roughness",
                self.normal_roughness,
                &[FormatKind::Float, FormatKind::Snorm][..],
                "a float or SNORM format with four channels (the normal is signed)",
            ),
        ] {
            if !four(format, kinds) {
                return Err(HostError::Unsupported {
                    input: input.into(),
                    found: format!("format {}", format_name(format)),
                    accepted: accepted.into(),
                }
                .into());
            }
        }
        Ok(())
    }
}

/// The host's G-buffer: what each of its images holds and how, its size and its world's scale.
///
/// ```
/// # use ash::vk;
/// use lucent::embed::{DepthDesc, DiffuseDesc, GBufferDesc, IdDesc};
/// let gbuffer = GBufferDesc::new(
///     1280,
///     720,
///     DepthDesc::device(vk::Format::D32_SFLOAT),
///     DiffuseDesc::with_albedo(vk::Format::B10G11R11_UFLOAT_PACK32),
/// )
/// .with_specular(vk::Format::B10G11R11_UFLOAT_PACK32)
/// .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
/// .with_metres_per_unit(0.01);
/// gbuffer.check().unwrap();
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct GBufferDesc {
    /// Width of every image, in pixels.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// The depth image.
    pub depth: DepthDesc,
    /// The lit diffuse light.
    pub diffuse: DiffuseDesc,
    /// The lit specular light kept apart, when the host has it (added back unblurred;
    /// without it the diffuse image's light is all blurred).
    pub specular: Option<vk::Format>,
    /// The surface albedo (rgb; a float, UNORM or SRGB colour format), when the host has it:
    /// needed for albedo applied after the scatter, and for diffuse light without albedo.
    pub albedo: Option<vk::Format>,
    /// The per-pixel material ID image.
    pub material_ids: Option<IdDesc>,
    /// The shading normals, when the host has them (GDC 2011 translucency reads them).
    pub normals: Option<NormalDesc>,
    /// The local thickness, when the host has it (GDC 2011 translucency reads it).
    pub thickness: Option<ThicknessDesc>,
    /// The LEAN targets its G-buffer pass writes, when it writes them (LCB, LBB and the
    /// bilateral blur read them instead of building them from the normals); the lit
    /// diffuse's alpha then holds the LEAN slope x ([`LeanTargetsDesc`]).
    pub lean_targets: Option<LeanTargetsDesc>,
    /// Li et al.'s `TexDep` texels at each pixel, when the host's layered materials read
    /// layer thicknesses from depth textures: its G-buffer pass samples each mesh's depth
    /// textures (one per four layers) and writes them packed as [`crate::embed::glsl::TERMS`]'
    /// `lucent_pack_layer_texels` does, `R32G32_UINT` for one texture (four layers) or
    /// `R32G32B32A32_UINT` for two (eight).
    pub layer_depths: Option<vk::Format>,
    /// The size of the host's world unit in metres (1: metres, 0.01: centimetres): the SSS
    /// profiles' millimetres are converted with it. Finite, above 0 and at most
    /// [`MAX_METRES_PER_UNIT`].
    pub metres_per_unit: f32,
}

/// The largest world unit a host may describe, in metres: a million kilometres. Larger, a
/// medium's millimetres per unit would pass f32's range where the shaders multiply a
/// thickness by it.
pub const MAX_METRES_PER_UNIT: f32 = 1e9;

/// Checks a world unit's size in metres: finite, above 0, at most [`MAX_METRES_PER_UNIT`]
/// (`field`: where the description gives it, for the error).
pub(crate) fn check_metres_per_unit(metres: f32, field: &str) -> crate::Result<()> {
    if metres.is_finite() && metres > 0.0 && metres <= MAX_METRES_PER_UNIT {
        return Ok(());
    }
    Err(HostError::Description {
        field: field.into(),
        problem: format!(
            "{metres} must be a finite number above 0 and at most {MAX_METRES_PER_UNIT}"
        ),
    }
    .into())
}

impl GBufferDesc {
    /// A G-buffer of `width` x `height` with its depth and lit diffuse, in metres.
    pub fn new(width: u32, height: u32, depth: DepthDesc, diffuse: DiffuseDesc) -> Self {
        Self {
            width,
            height,
            depth,
            diffuse,
            specular: None,
            albedo: None,
            material_ids: None,
            normals: None,
            thickness: None,
            lean_targets: None,
            layer_depths: None,
            metres_per_unit: 1.0,
        }
    }

    /// With the lit specular kept apart.
    pub fn with_specular(mut self, format: vk::Format) -> Self {
        self.specular = Some(format);
        self
    }

    /// With the albedo image.
    pub fn with_albedo(mut self, format: vk::Format) -> Self {
        self.albedo = Some(format);
        self
    }

    /// With the material ID image.
    pub fn with_material_ids(mut self, ids: IdDesc) -> Self {
        self.material_ids = Some(ids);
        self
    }

    /// With the normal image.
    pub fn with_normals(mut self, normals: NormalDesc) -> Self {
        self.normals = Some(normals);
        self
    }

    /// With the thickness image.
    pub fn with_thickness(mut self, thickness: ThicknessDesc) -> Self {
        self.thickness = Some(thickness);
        self
    }

    /// With the LEAN targets of [`LeanTargetsDesc`] (the lit diffuse's alpha holding the LEAN
    /// slope x).
    pub fn with_lean_targets(mut self, targets: LeanTargetsDesc) -> Self {
        self.lean_targets = Some(targets);
        self
    }

    /// With the `TexDep` texels image (`R32G32_UINT`: one depth texture's four layers;
    /// `R32G32B32A32_UINT`: two textures', eight layers).
    pub fn with_layer_depths(mut self, format: vk::Format) -> Self {
        self.layer_depths = Some(format);
        self
    }

    /// How many depth textures' texels [`Self::layer_depths`] holds (0 without it).
    pub fn layer_depth_textures(&self) -> usize {
        match self.layer_depths {
            Some(vk::Format::R32G32B32A32_UINT) => 2,
            Some(_) => 1,
            None => 0,
        }
    }

    /// With the world unit's size in metres.
    pub fn with_metres_per_unit(mut self, metres: f32) -> Self {
        self.metres_per_unit = metres;
        self
    }

    /// The frame's extent.
    pub fn extent(&self) -> vk::Extent2D {
        vk::Extent2D {
            width: self.width,
            height: self.height,
        }
    }

    /// Checks the description on its own (sizes, formats against their encodings, the ID bit
    /// field, the scale); what each effect needs of it is checked when the effect is built.
    pub fn check(&self) -> Result<()> {
        let description = |field: &str, problem: String| -> crate::LucentError {
            HostError::Description {
                field: field.into(),
                problem,
            }
            .into()
        };
        if self.width == 0 || self.height == 0 || self.width > 16384 || self.height > 16384 {
            return Err(description(
                "G-buffer size",
                format!(
                    "{}x{} is out of range (1..=16384 per side)",
                    self.width, self.height
                ),
            ));
        }
        check_metres_per_unit(self.metres_per_unit, "metres_per_unit")?;
        let depth_ok = match self.depth.encoding {
            DepthEncoding::Device => matches!(
                self.depth.format,
                vk::Format::D32_SFLOAT
                    | vk::Format::D32_SFLOAT_S8_UINT
                    | vk::Format::D24_UNORM_S8_UINT
                    | vk::Format::X8_D24_UNORM_PACK32
                    | vk::Format::D16_UNORM
            ),
            DepthEncoding::LinearView => matches!(
                self.depth.format,
                vk::Format::R32_SFLOAT | vk::Format::R16_SFLOAT
            ),
        };
        if !depth_ok {
            return Err(HostError::Unsupported {
                input: "depth".into(),
                found: format!(
                    "format {} with {:?}",
                    format_name(self.depth.format),
                    self.depth.encoding
                ),
                accepted: "D32_SFLOAT, D32_SFLOAT_S8_UINT, D24_UNORM_S8_UINT, \
                           X8_D24_UNORM_PACK32 or D16_UNORM device depth; R32_SFLOAT or \
                           R16_SFLOAT linear view depth"
                    .into(),
            }
            .into());
        }
        for (input, format) in [
            ("diffuse", Some(self.diffuse.format)),
            ("specular", self.specular),
            ("albedo", self.albedo),
        ] {
            if let Some(format) = format {
                if !sampled_float(format) {
                    return Err(HostError::Unsupported {
                        input: input.into(),
                        found: format!("format {}", format_name(format)),
                        accepted: "a float, UNORM or SRGB colour format".into(),
                    }
                    .into());
                }
            }
        }
        if let Some(ids) = &self.material_ids {
            ids.decode(Vec::new())?;
        }
        let float_alpha = format_info(self.diffuse.format)
            .is_some_and(|f| f.kind == FormatKind::Float && f.channels == 4);
        if self.diffuse.depth_in_alpha && !float_alpha {
            return Err(HostError::Unsupported {
                input: "diffuse".into(),
                found: format!(
                    "format {} with depth in alpha",
                    format_name(self.diffuse.format)
                ),
                accepted: "a float format with alpha (R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT) \
                           for linear depth in the alpha"
                    .into(),
            }
            .into());
        }
        if let Some(normals) = &self.normals {
            normals.decode()?;
        }
        if let Some(thickness) = &self.thickness {
            thickness.decode()?;
        }
        if let Some(format) = self.layer_depths {
            if !matches!(
                format,
                vk::Format::R32G32_UINT | vk::Format::R32G32B32A32_UINT
            ) {
                return Err(HostError::Unsupported {
                    input: "layer depths".into(),
                    found: format!("format {}", format_name(format)),
                    accepted: "R32G32_UINT (one depth texture's four layers) or \
                               R32G32B32A32_UINT (two textures', eight layers), packed as \
                               lucent_pack_layer_texels writes them"
                        .into(),
                }
                .into());
            }
        }
        if let Some(targets) = &self.lean_targets {
            targets.check()?;
            // The LEAN slope x travels in the diffuse's alpha, signed: lucent's own layout.
            if !float_alpha || self.diffuse.depth_in_alpha {
                return Err(HostError::Unsupported {
                    input: "diffuse".into(),
                    found: format!(
                        "format {}{} with LEAN targets",
                        format_name(self.diffuse.format),
                        if self.diffuse.depth_in_alpha {
                            " and depth in alpha"
                        } else {
                            ""
                        }
                    ),
                    accepted: "a float format with alpha (R16G16B16A16_SFLOAT, \
                               R32G32B32A32_SFLOAT) whose alpha holds the LEAN slope x, not \
                               depth"
                        .into(),
                }
                .into());
            }
        }
        Ok(())
    }

    /// The frame uniforms of a view of this G-buffer seen by `camera` (checked): its
    /// matrices, size and depth decode; no lights.
    pub(crate) fn view_uniforms(
        &self,
        camera: &HostCamera,
    ) -> Result<crate::gpu_scene::FrameUniforms> {
        camera.check()?;
        let decode = self.depth_decode(&camera.projection)?;
        Ok(crate::gpu_scene::FrameUniforms::for_view(
            camera.view,
            camera.projection,
            self.width,
            self.height,
            decode,
        ))
    }

    /// The depth decode coefficients for a frame seen through `projection`
    /// ([`crate::gpu_scene::projection_depth_decode`]; the identity for linear depth).
    pub(crate) fn depth_decode(&self, projection: &Mat4) -> Result<[f32; 4]> {
        match self.depth.encoding {
            DepthEncoding::LinearView => Ok([0.0, 1.0, 1.0, 0.0]),
            DepthEncoding::Device => crate::gpu_scene::projection_depth_decode(projection)
                .ok_or_else(|| {
                    HostError::Description {
                        field: "camera projection".into(),
                        problem: format!(
                            "{projection:?} maps no depth range (a perspective or orthographic \
                             projection to Vulkan's depth 0..1 is needed)"
                        ),
                    }
                    .into()
                }),
        }
    }
}

/// The host's camera for one view: its matrices, any handedness and up axis. The view matrix
/// maps world to view space (the camera looking down -z, as `look_at_rh` makes), the
/// projection view to Vulkan clip space (depth 0..1; either y convention).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct HostCamera {
    /// World to view space.
    pub view: Mat4,
    /// View to clip space.
    pub projection: Mat4,
}

impl HostCamera {
    /// A camera from its two matrices.
    pub fn new(view: Mat4, projection: Mat4) -> Self {
        Self { view, projection }
    }

    /// Checks the matrices: finite, the view invertible, the projection with a non-zero
    /// vertical scale (blur widths are projected with it).
    pub(crate) fn check(&self) -> Result<()> {
        let finite = self.view.is_finite() && self.projection.is_finite();
        let determinant = self.view.determinant();
        if !finite || determinant.abs() < 1e-12 || !determinant.is_finite() {
            return Err(HostError::Description {
                field: "camera view".into(),
                problem: format!("{:?} must be finite and invertible", self.view),
            }
            .into());
        }
        if self.projection.y_axis.y == 0.0 || (self.projection * self.view).determinant() == 0.0 {
            return Err(HostError::Description {
                field: "camera projection".into(),
                problem: format!(
                    "{:?} must be finite with a non-zero vertical scale",
                    self.projection
                ),
            }
            .into());
        }
        Ok(())
    }
}

/// Colour formats lucent samples as floats (UNORM, SRGB, float), 1 to 4 channels.
pub(crate) fn sampled_float(format: vk::Format) -> bool {
    format_info(format).is_some_and(|f| {
        matches!(
            f.kind,
            FormatKind::Unorm | FormatKind::Srgb | FormatKind::Float
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gbuffer() -> GBufferDesc {
        GBufferDesc::new(
            64,
            32,
            DepthDesc::device(vk::Format::D32_SFLOAT),
            DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
        )
    }

    #[test]
    fn every_depth_format_a_host_uses_is_accepted_and_others_are_named() {
        for format in [
            vk::Format::D32_SFLOAT,
            vk::Format::D32_SFLOAT_S8_UINT,
            vk::Format::D24_UNORM_S8_UINT,
            vk::Format::D16_UNORM,
        ] {
            GBufferDesc {
                depth: DepthDesc::device(format),
                ..gbuffer()
            }
            .check()
            .unwrap();
        }
        GBufferDesc {
            depth: DepthDesc::linear(vk::Format::R32_SFLOAT),
            ..gbuffer()
        }
        .check()
        .unwrap();
        let e = GBufferDesc {
            depth: DepthDesc::device(vk::Format::R32_SFLOAT),
            ..gbuffer()
        }
        .check()
        .unwrap_err();
        assert!(
            matches!(&e, crate::LucentError::Host(HostError::Unsupported { input, .. }) if input == "depth"),
            "{e}"
        );
        assert!(e.to_string().contains("D24_UNORM_S8_UINT"), "{e}");
    }

    #[test]
    fn id_encodings_decode_to_their_bit_fields() {
        let map = IdDesc::value(vk::Format::R8_UINT)
            .decode(vec![0, 1])
            .unwrap();
        assert!(map.uint && map.mask == 0xff && map.shift == 0);
        let map = IdDesc::value(vk::Format::R8_UNORM)
            .decode(Vec::new())
            .unwrap();
        assert!(!map.uint && map.unorm_max == 255);
        let map = IdDesc::stencil(vk::Format::D24_UNORM_S8_UINT, 4, 4)
            .decode(Vec::new())
            .unwrap();
        assert!(map.uint && map.shift == 4 && map.mask == 0xf);
        // The 2-bit alpha of RGB10A2, and the top 4 bits of an RGBA8 target's alpha.
        let map = IdDesc::bits(vk::Format::A2B10G10R10_UNORM_PACK32, 3, 0, 2)
            .decode(Vec::new())
            .unwrap();
        assert!(!map.uint && map.unorm_max == 3 && map.channel == 3);
        let map = IdDesc::bits(vk::Format::R8G8B8A8_UNORM, 3, 4, 4)
            .decode(Vec::new())
            .unwrap();
        assert!(map.unorm_max == 255 && map.shift == 4 && map.mask == 0xf);
        for bad in [
            IdDesc::value(vk::Format::R8G8B8A8_UNORM),
            IdDesc::value(vk::Format::R16G16B16A16_SFLOAT),
            IdDesc::stencil(vk::Format::D32_SFLOAT, 0, 8),
            IdDesc::bits(vk::Format::R8G8_UINT, 2, 0, 8),
            IdDesc::bits(vk::Format::R8G8B8A8_UINT, 3, 6, 4),
            IdDesc::bits(vk::Format::R8G8B8A8_UINT, 3, 0, 0),
        ] {
            let e = bad.decode(Vec::new()).unwrap_err();
            assert!(
                matches!(&e, crate::LucentError::Host(HostError::Unsupported { input, .. }) if input == "material IDs"),
                "{bad:?}: {e}"
            );
        }
    }

    #[test]
    fn depth_in_the_diffuses_alpha_needs_a_float_format_with_alpha() {
        let with_depth = |format| GBufferDesc {
            diffuse: DiffuseDesc::with_albedo(format).with_depth_in_alpha(),
            ..gbuffer()
        };
        with_depth(vk::Format::R16G16B16A16_SFLOAT).check().unwrap();
        with_depth(vk::Format::R32G32B32A32_SFLOAT).check().unwrap();
        for format in [
            vk::Format::R8G8B8A8_UNORM,
            vk::Format::B10G11R11_UFLOAT_PACK32,
        ] {
            let e = with_depth(format).check().unwrap_err();
            assert!(e.to_string().contains("depth in alpha"), "{e}");
        }
    }

    #[test]
    fn sizes_scales_and_cameras_out_of_range_are_refused() {
        assert!(GBufferDesc {
            width: 0,
            ..gbuffer()
        }
        .check()
        .is_err());
        assert!(gbuffer().with_metres_per_unit(0.0).check().is_err());
        assert!(gbuffer().with_metres_per_unit(f32::NAN).check().is_err());
        assert!(gbuffer().with_metres_per_unit(2e9).check().is_err());
        assert!(gbuffer().with_metres_per_unit(1e9).check().is_ok());
        let good = HostCamera::new(
            Mat4::look_at_rh(glam::Vec3::Z, glam::Vec3::ZERO, glam::Vec3::Y),
            Mat4::perspective_infinite_reverse_rh(1.0, 2.0, 0.1),
        );
        good.check().unwrap();
        assert!(HostCamera::new(Mat4::ZERO, good.projection)
            .check()
            .is_err());
        assert!(HostCamera::new(good.view, Mat4::ZERO).check().is_err());
        assert!(
            HostCamera::new(good.view, Mat4::from_cols_array(&[f32::NAN; 16]))
                .check()
                .is_err()
        );
        assert!(gbuffer().depth_decode(&Mat4::ZERO).is_err());
    }
}
