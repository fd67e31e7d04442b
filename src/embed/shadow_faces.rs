//! [`ShadowFace`]: one face of a light's depth map as a host describes it (its light, its view
//! and projection matrices, its square rectangle in one depth atlas), and the shadow table
//! lucent's shaders read (glsl/common/shadows.glsl `Shadows`) made from a frame's faces, each
//! checked. [`super::TransmissionEffect`] reads the host's own maps through it;
//! [`super::LayeredEffect`] draws lucent's light-space maps of the host's meshes with the
//! faces' matrices into its own atlas.

use ash::vk;
use glam::{Mat4, Vec3};

use super::image::{check_image, HostImage, Role};
use crate::error::HostError;
use crate::features::shadows::{ShadowFaceGpu, ShadowUniforms, MAX_SHADOW_FACES};
use crate::gpu_scene::projection_depth_ends;
use crate::scene::{Light, LightKind};
use crate::Result;

/// One face of a host's shadow map: the light it belongs to, the matrices the host rendered
/// it with and where it lies in the shadow map image.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct ShadowFace {
    /// Index of its light in the frame's lights.
    pub light: usize,
    /// World to the face's view space (looking down -z).
    pub view: Mat4,
    /// The face's view to clip space: standard Z (0 near, 1 far) or reversed Z (1 near, 0
    /// far), a finite or infinite far plane, perspective
    /// (a spot light's cone, a point light's 90-degree faces) or orthographic (a directional
    /// light), either y convention.
    pub projection: Mat4,
    /// Its square rectangle in the shadow map image, in texels, which the host's viewport
    /// covered when it rendered the face.
    pub rect: vk::Rect2D,
    /// The array layer it lies in, for a shadow map that is an array of layers (cascades, a
    /// cube's faces: [`super::HostImage::with_layers`]); 0 in an atlas.
    pub layer: u32,
    /// The shadow map it lies in: 0 the frame's shadow map, 1 the second one (an array of
    /// layers beside a first map that is an atlas: a cube array's faces beside a spot and
    /// sun atlas; `with_second_shadow_map` of the effect's description).
    pub map: u32,
}

impl ShadowFace {
    /// Face `rect` of light `light`, rendered with `view` and `projection`, in layer 0.
    pub fn new(light: usize, view: Mat4, projection: Mat4, rect: vk::Rect2D) -> Self {
        Self {
            light,
            view,
            projection,
            rect,
            layer: 0,
            map: 0,
        }
    }

    /// The face in array layer `layer` of the shadow map.
    pub fn in_layer(mut self, layer: u32) -> Self {
        self.layer = layer;
        self
    }

    /// The face in layer `layer` of the second shadow map (an array beside an atlas:
    /// [`Self::map`] 1).
    pub fn in_second_map(mut self, layer: u32) -> Self {
        self.map = 1;
        self.layer = layer;
        self
    }

    /// The face as a host's own lighting pass reads it with [`super::glsl::TERMS`]'
    /// `lucent_shadow_texels(map, view_proj, rect, params, ...)` (the rows lucent's own
    /// shadow table holds): rows 0-3 the columns of `view_proj` (world to the face's clip
    /// space, standard Z even for a reversed-Z face), row 4 `rect` (its corner and edge in
    /// the map of `map_extent`; w: 1 for reversed Z, plus 2 x its layer), row 5 `params` (a
    /// map texel's world size, near and far). A face outside the map or not square, or whose
    /// projection is not one lucent reads, is refused ([`HostError::Description`], field
    /// `shadow face`).
    pub fn terms_rows(&self, map_extent: vk::Extent2D) -> Result<[[f32; 4]; 6]> {
        let row = face_row(self, map_extent).map_err(|problem| HostError::Description {
            field: "shadow face".into(),
            problem,
        })?;
        let [c0, c1, c2, c3] = row.view_proj;
        Ok([c0, c1, c2, c3, row.rect, row.params])
    }
}

/// A face of lucent's own light-space atlas as a host describes it
/// ([`crate::features::shadows::ShadowDesc::face_matrices`]): what tests and `lucent bench
/// --embed` hand the effect to compare it with lucent's own frame.
impl From<crate::features::shadows::FaceMatrices> for ShadowFace {
    fn from(face: crate::features::shadows::FaceMatrices) -> Self {
        let (x, y, edge) = face.tile;
        Self::new(
            face.light,
            face.view,
            face.projection,
            vk::Rect2D {
                offset: vk::Offset2D {
                    x: x as i32,
                    y: y as i32,
                },
                extent: vk::Extent2D {
                    width: edge,
                    height: edge,
                },
            },
        )
    }
}

/// The unit axes a point light's six faces look along, in order.
const CUBE_AXES: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

/// Each of a frame's host shadow maps' size and layers, as [`shadow_table`] takes them.
pub(crate) type MapSizes = Vec<(vk::Extent2D, u32)>;

/// How an effect's host shadow maps are laid out, from its description: one 2-D atlas, one
/// array of layers, or an atlas with an array beside it (the second map, each of its faces
/// [`ShadowFace::in_second_map`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShadowMaps {
    /// One 2-D image.
    Atlas,
    /// One array of layers (its view a 2-D array view).
    Array,
    /// An atlas and, beside it, an array of layers of its own size.
    AtlasAndArray,
}

impl ShadowMaps {
    /// The layout a description asks for (`array`: its first map is an array; `second`: the
    /// format of a second map, checked), or why it cannot be read.
    pub(crate) fn described(array: bool, second: Option<vk::Format>) -> Result<Self> {
        match (array, second) {
            (false, None) => Ok(Self::Atlas),
            (true, None) => Ok(Self::Array),
            (false, Some(format)) => {
                check_shadow_format(format, "second shadow map")?;
                Ok(Self::AtlasAndArray)
            }
            (true, Some(_)) => Err(HostError::Unsupported {
                input: "second shadow map".into(),
                found: "a second shadow map beside a first that is an array".into(),
                accepted: "a second map (an array of layers) beside a first that is an atlas \
                           (one 2-D image); or one array holding every face"
                    .into(),
            }
            .into()),
        }
    }

    /// The defines of the passes reading them (glsl/common/shadows.glsl).
    pub(crate) fn defines(self) -> &'static [(&'static str, &'static str)] {
        match self {
            Self::Atlas => &[],
            Self::Array => &[("LUCENT_SHADOW_ARRAY", "1")],
            Self::AtlasAndArray => &[("LUCENT_SHADOW_SECOND_MAP", "1")],
        }
    }

    /// Every layout, for the shipped SPIR-V.
    pub(crate) const ALL: [Self; 3] = [Self::Atlas, Self::Array, Self::AtlasAndArray];

    /// Checks a frame's shadow maps against the layout and their formats (`formats`: the
    /// first map's, the second's when described); returns each map's size and layers, as
    /// [`shadow_table`] takes them.
    pub(crate) fn check_frame(
        self,
        gpu: &crate::backend::GpuContext,
        first: &HostImage,
        second: Option<&HostImage>,
        formats: (vk::Format, Option<vk::Format>),
    ) -> Result<MapSizes> {
        check_shadow_map(gpu, first, "shadow map", formats.0, self == Self::Array)?;
        let mut maps = vec![(first.extent, first.layers)];
        match (formats.1, second) {
            (Some(format), Some(map)) => {
                check_shadow_map(gpu, map, "second shadow map", format, true)?;
                maps.push((map.extent, map.layers));
            }
            (None, None) => {}
            (Some(_), None) => {
                return Err(HostError::Missing {
                    input: "second shadow map".into(),
                    needed_by: "the description has a second shadow map (with_second_shadow_map)"
                        .into(),
                }
                .into())
            }
            (None, Some(map)) => return Err(undescribed_second_map(map)),
        }
        Ok(maps)
    }
}

/// The error for a second shadow map a frame gives although the effect's description has
/// none.
pub(crate) fn undescribed_second_map(map: &HostImage) -> crate::LucentError {
    HostError::Image {
        image: map.name.clone(),
        kind: crate::error::ImageFault::Aliased,
        problem: "given as the second shadow map, which the description has none of \
                  (with_second_shadow_map)"
            .into(),
    }
    .into()
}

/// Checks a frame's host shadow map (`input`: which, for the errors) against the effect's
/// description: its layers (an array, `array`, may have any number; an atlas is one 2-D
/// image), then as an image of the description's `format` ([`check_image`], its own size).
fn check_shadow_map(
    gpu: &crate::backend::GpuContext,
    map: &HostImage,
    input: &str,
    format: vk::Format,
    array: bool,
) -> Result<()> {
    check_shadow_layers(map, array)?;
    check_image(
        gpu,
        map,
        input,
        Role::ShadowMap,
        map.extent,
        |f| f == format,
        &format!(
            "{} (the description's)",
            crate::backend::format::format_name(format)
        ),
    )
}

/// A host's shadow map's layers against the effect's description: an array (`array`, its
/// view a 2-D array view) may have any number; an atlas is one 2-D image.
fn check_shadow_layers(map: &HostImage, array: bool) -> Result<()> {
    if array || map.layers <= 1 {
        return Ok(());
    }
    Err(HostError::Image {
        image: map.name.clone(),
        kind: crate::error::ImageFault::Size,
        problem: format!(
            "has {} layers, but the effect was described with one 2-D shadow map (an atlas); \
             describe an array with with_shadow_array",
            map.layers
        ),
    }
    .into())
}

/// A host's shadow map (`input`: which, for the error) must be a depth format (the shadow
/// lookups compare its depth).
pub(crate) fn check_shadow_format(format: vk::Format, input: &str) -> Result<()> {
    use crate::backend::format::{format_info, format_name, FormatKind};
    if format_info(format).is_some_and(|f| f.kind == FormatKind::Depth) {
        return Ok(());
    }
    Err(HostError::Unsupported {
        input: input.into(),
        found: format!("format {}", format_name(format)),
        accepted: "a depth format (D32_SFLOAT, D16_UNORM, D24_UNORM_S8_UINT, \
                   D32_SFLOAT_S8_UINT, X8_D24_UNORM_PACK32)"
            .into(),
    }
    .into())
}

/// The shadow table (glsl/common/shadows.glsl `Shadows`, what lucent's own light-space maps
/// fill) of the host's faces in its shadow maps (`maps`: each one's size and layers, the
/// second an array beside an atlas), each checked: its light exists and has one face (six
/// for a point light, in [`CUBE_AXES`] order, together), its map is one of the frame's and
/// its layer one of the map's, its matrices are finite with a standard- or reversed-Z
/// projection, its rectangle square and inside the map. A face of the second map is written
/// with `-1 -` its flags (glsl `shadow_in_second_map`).
pub(crate) fn shadow_table(
    lights: &[Light],
    faces: &[ShadowFace],
    maps: &[(vk::Extent2D, u32)],
) -> Result<ShadowUniforms> {
    let bad = |index: usize, problem: String| -> crate::LucentError {
        HostError::Description {
            field: format!("shadow_faces[{index}]"),
            problem,
        }
        .into()
    };
    if faces.len() > MAX_SHADOW_FACES {
        return Err(HostError::Description {
            field: "shadow_faces".into(),
            problem: format!("{} faces; at most {MAX_SHADOW_FACES}", faces.len()),
        }
        .into());
    }
    let mut table: ShadowUniforms = bytemuck::Zeroable::zeroed();
    let (extent, _) = maps.first().copied().unwrap_or_default();
    let (w, h) = (extent.width.max(1) as f32, extent.height.max(1) as f32);
    table.atlas = [w, h, 1.0 / w, 1.0 / h];
    for light in table.lights.iter_mut() {
        *light = [-1, 0, 0, 0];
    }
    let mut index = 0;
    while index < faces.len() {
        let light = faces[index].light;
        let Some(kind) = lights.get(light).map(|l| l.kind) else {
            return Err(bad(
                index,
                format!("light {light}: the frame has {} lights", lights.len()),
            ));
        };
        if table.lights[light][0] >= 0 {
            return Err(bad(
                index,
                format!("light {light}'s faces must come together, once"),
            ));
        }
        let count = match kind {
            LightKind::Point { .. } => 6,
            _ => 1,
        };
        if index + count > faces.len()
            || faces[index..index + count].iter().any(|f| f.light != light)
        {
            return Err(bad(
                index,
                format!(
                    "light {light} needs {count} face{} in a row ({})",
                    if count == 1 { "" } else { "s" },
                    if count == 6 {
                        "a point light: +X, -X, +Y, -Y, +Z, -Z"
                    } else {
                        "a spot or directional light"
                    }
                ),
            ));
        }
        table.lights[light] = [index as i32, count as i32, 0, 0];
        for k in 0..count {
            let face = &faces[index + k];
            let Some(&(extent, layers)) = maps.get(face.map as usize) else {
                return Err(bad(
                    index + k,
                    format!(
                        "map {}: the frame has {} shadow map{} (a second one is described \
                         with with_second_shadow_map)",
                        face.map,
                        maps.len(),
                        if maps.len() == 1 { "" } else { "s" }
                    ),
                ));
            };
            if face.layer >= layers.max(1) {
                return Err(bad(
                    index + k,
                    format!(
                        "layer {}: shadow map {} has {} layer{}",
                        face.layer,
                        face.map,
                        layers.max(1),
                        if layers > 1 { "s" } else { "" }
                    ),
                ));
            }
            let mut row = face_row(face, extent).map_err(|problem| bad(index + k, problem))?;
            if face.map == 1 {
                // The second map: its flags negated (glsl shadow_in_second_map).
                row.rect[3] = -1.0 - row.rect[3];
            }
            table.faces[index + k] = row;
            if count == 6 {
                // The face's view axis in the world: -z of its view space.
                let forward = face
                    .view
                    .inverse()
                    .transform_vector3(Vec3::NEG_Z)
                    .normalize();
                if forward.dot(CUBE_AXES[k]) < 0.999 {
                    return Err(bad(
                        index + k,
                        format!(
                            "face {k} of point light {light} looks along {forward}; the six \
                             faces look along +X, -X, +Y, -Y, +Z, -Z in that order"
                        ),
                    ));
                }
            }
        }
        index += count;
    }
    Ok(table)
}

/// A face's row of the shadow table: its view-projection, rectangle and the parameters
/// glsl/common/shadows.glsl reads (a map texel's world size at a point, near and far: see
/// [`ShadowFaceGpu::params`]), or what is wrong with it.
fn face_row(face: &ShadowFace, extent: vk::Extent2D) -> std::result::Result<ShadowFaceGpu, String> {
    let (view, projection) = (face.view, face.projection);
    if !(view.is_finite() && projection.is_finite()) || view.determinant().abs() < 1e-12 {
        return Err("its view and projection must be finite, the view invertible".into());
    }
    let r = face.rect;
    let inside = r.offset.x >= 0
        && r.offset.y >= 0
        && r.extent.width > 0
        && u64::from(r.offset.x as u32) + u64::from(r.extent.width) <= u64::from(extent.width)
        && u64::from(r.offset.y as u32) + u64::from(r.extent.height) <= u64::from(extent.height);
    if !inside || r.extent.width != r.extent.height {
        return Err(format!(
            "its rectangle {r:?} must be square and inside the {}x{} shadow map",
            extent.width, extent.height
        ));
    }
    let edge = r.extent.width as f32;
    let accepted = || {
        "a perspective or orthographic projection mapping a near plane in front of the eye to \
         depth 0 and a farther (or infinite) plane to 1 (standard Z), or the other way round \
         (reversed Z)"
            .to_string()
    };
    let (at_0, at_1) = projection_depth_ends(&projection).ok_or_else(accepted)?;
    // Reversed Z stores 1 at the near plane: 1 - d is the standard depth of the same planes
    // (exactly, for every perspective or orthographic mapping with those planes, an infinite
    // far plane included), so the face is read through the projection with z flipped and its
    // texels flipped in the shader (glsl/common/shadows.glsl shadow_gather_flagged).
    let reversed = at_0 > at_1;
    let (near, far) = if reversed { (at_1, at_0) } else { (at_0, at_1) };
    if !(near > 0.0 && far > near && near.is_finite()) {
        return Err(accepted());
    }
    // An infinite far plane: a far one the f32 decode cannot tell from it (near * far / (far
    // - d (far - near)) is near / (1 - d) to f32's precision), finite in the table.
    let (near, far) = (near as f32, far.min(1e30) as f32);
    let scale = projection.y_axis.y.abs();
    if scale.is_nan() || scale <= 0.0 {
        return Err(accepted());
    }
    let orthographic = projection.w_axis.w != 0.0;
    // A map texel's world size at a point: x * clip.w + y (glsl map_texel_size).
    let texel = 2.0 / (scale * edge);
    let params = if orthographic {
        [0.0, texel, -near, far]
    } else {
        [texel, 0.0, near, far]
    };
    // z' = w - z: depth 1 - d.
    let flip = Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    );
    let projection = if reversed {
        flip * projection
    } else {
        projection
    };
    Ok(ShadowFaceGpu {
        view_proj: (projection * view).to_cols_array_2d(),
        // w: reversed Z in its lowest bit, the array layer above (glsl/common/shadows.glsl
        // shadow_gather_flagged, shadow_gather_depth).
        rect: [
            r.offset.x as f32,
            r.offset.y as f32,
            edge,
            (2 * face.layer + u32::from(reversed)) as f32,
        ],
        params,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x: i32, y: i32, edge: u32) -> vk::Rect2D {
        vk::Rect2D {
            offset: vk::Offset2D { x, y },
            extent: vk::Extent2D {
                width: edge,
                height: edge,
            },
        }
    }

    #[test]
    fn an_array_map_needs_an_array_description() {
        let map = |layers| {
            HostImage::new(
                "cascades",
                vk::Image::null(),
                vk::ImageView::null(),
                vk::Format::D32_SFLOAT,
                vk::Extent2D {
                    width: 8,
                    height: 8,
                },
                vk::ImageUsageFlags::SAMPLED,
            )
            .with_layers(layers)
        };
        check_shadow_layers(&map(1), false).unwrap();
        check_shadow_layers(&map(4), true).unwrap();
        let e = check_shadow_layers(&map(4), false).unwrap_err().to_string();
        assert!(
            e.contains("'cascades'") && e.contains("with_shadow_array"),
            "{e}"
        );
    }

    #[test]
    fn a_spot_face_becomes_lucents_row_and_bad_faces_are_named() {
        let extent = vk::Extent2D {
            width: 512,
            height: 256,
        };
        let view = Mat4::look_at_rh(Vec3::new(0.0, 2.0, 0.0), Vec3::ZERO, Vec3::Z);
        let projection = Mat4::perspective_rh(1.0, 1.0, 0.1, 20.0);
        let spot = Light {
            kind: LightKind::Spot {
                position: Vec3::new(0.0, 2.0, 0.0),
                direction: Vec3::NEG_Y,
                range: 10.0,
                inner_degrees: 20.0,
                outer_degrees: 30.0,
            },
            ..Light::point(Vec3::ZERO, Vec3::ONE, 1.0, 1.0)
        };
        let face = ShadowFace::new(0, view, projection, rect(256, 0, 256));
        let table = shadow_table(&[spot], &[face], &[(extent, 1)]).unwrap();
        assert_eq!(table.lights[0], [0, 1, 0, 0]);
        assert_eq!(table.lights[1][0], -1);
        let row = table.faces[0];
        assert_eq!(row.rect, [256.0, 0.0, 256.0, 0.0]);
        // A host's lighting pass reads the same row (embed::glsl::TERMS).
        let [c0, c1, c2, c3, rect_row, params] = face.terms_rows(extent).unwrap();
        assert_eq!([c0, c1, c2, c3], row.view_proj);
        assert_eq!((rect_row, params), (row.rect, row.params));
        let outside = ShadowFace::new(0, view, projection, rect(300, 0, 256));
        let message = outside.terms_rows(extent).unwrap_err().to_string();
        assert!(
            message.contains("shadow face") && message.contains("512x256"),
            "{message}"
        );
        assert!((row.params[2] - 0.1).abs() < 1e-4 && (row.params[3] - 20.0).abs() < 0.05);
        // x = 2 tan(fov / 2) / edge.
        assert!(
            (row.params[0] - 2.0 * 0.5f32.tan() / 256.0).abs() < 1e-6,
            "{row:?}"
        );
        for bad in [
            ShadowFace::new(1, view, projection, rect(0, 0, 256)), // no such light
            ShadowFace::new(0, view, projection, rect(300, 0, 256)), // outside the map
            ShadowFace::new(0, view, projection, rect(-1, 0, 64)),
            // Its near plane behind the eye.
            ShadowFace::new(
                0,
                view,
                Mat4::perspective_rh(1.0, 1.0, -0.1, 20.0),
                rect(0, 0, 64),
            ),
            ShadowFace::new(0, Mat4::ZERO, projection, rect(0, 0, 64)),
        ] {
            assert!(
                shadow_table(&[spot], &[bad], &[(extent, 1)]).is_err(),
                "{bad:?}"
            );
        }
        // Reversed Z (near and far swapped): the same row read through z flipped, flagged;
        // and with an infinite far plane, a far one f32 cannot tell from it.
        let reversed = ShadowFace::new(
            0,
            view,
            Mat4::perspective_rh(1.0, 1.0, 20.0, 0.1),
            rect(256, 0, 256),
        );
        let flipped = shadow_table(&[spot], &[reversed], &[(extent, 1)])
            .unwrap()
            .faces[0];
        assert_eq!(flipped.rect, [256.0, 0.0, 256.0, 1.0]);
        for (a, b) in flipped.params.iter().zip(&row.params) {
            assert!(
                (a - b).abs() <= 1e-5 * b.abs(),
                "{flipped:?} against {row:?}"
            );
        }
        for (a, b) in flipped
            .view_proj
            .iter()
            .flatten()
            .zip(row.view_proj.iter().flatten())
        {
            assert!((a - b).abs() < 1e-5, "{flipped:?} against {row:?}");
        }
        let infinite = ShadowFace::new(
            0,
            view,
            Mat4::perspective_infinite_reverse_rh(1.0, 1.0, 0.1),
            rect(0, 0, 64),
        );
        // In layer 2 of a three-layer array: the layer above the reversed bit; no layer 3.
        let layered = shadow_table(&[spot], &[infinite.in_layer(2)], &[(extent, 3)]).unwrap();
        assert_eq!(layered.faces[0].rect[3], 5.0);
        assert!(shadow_table(&[spot], &[infinite.in_layer(3)], &[(extent, 3)]).is_err());
        // In layer 2 of a second map (an array beside the atlas, its own size): the flags
        // negated; refused where the frame has no second map, or past its layers or size.
        let edge_64 = vk::Extent2D {
            width: 64,
            height: 64,
        };
        let second = shadow_table(
            &[spot],
            &[infinite.in_second_map(2)],
            &[(extent, 1), (edge_64, 3)],
        )
        .unwrap();
        assert_eq!(second.faces[0].rect[3], -6.0);
        assert_eq!(second.atlas[0], extent.width as f32, "the first map's size");
        assert!(shadow_table(&[spot], &[infinite.in_second_map(0)], &[(extent, 1)]).is_err());
        assert!(shadow_table(
            &[spot],
            &[infinite.in_second_map(3)],
            &[(extent, 1), (edge_64, 3)]
        )
        .is_err());
        let beyond = ShadowFace {
            rect: rect(32, 0, 64),
            ..infinite.in_second_map(0)
        };
        assert!(shadow_table(&[spot], &[beyond], &[(extent, 1), (edge_64, 3)]).is_err());
        let far = shadow_table(&[spot], &[infinite], &[(extent, 1)])
            .unwrap()
            .faces[0];
        assert_eq!(far.rect[3], 1.0);
        assert!(
            (far.params[2] - 0.1).abs() < 1e-6 && far.params[3] >= 1e29,
            "{far:?}"
        );
        // A point light needs its six faces, in order.
        let point = Light::point(Vec3::ZERO, Vec3::ONE, 1.0, 5.0);
        let cube: Vec<ShadowFace> = CUBE_AXES
            .iter()
            .enumerate()
            .map(|(k, &axis)| {
                let up = if axis.y.abs() > 0.5 { Vec3::Z } else { Vec3::Y };
                let view = Mat4::look_at_rh(Vec3::ZERO, axis, up);
                let projection = Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, 0.05, 5.0);
                ShadowFace::new(0, view, projection, rect(64 * k as i32, 0, 64))
            })
            .collect();
        let table = shadow_table(&[point], &cube, &[(extent, 1)]).unwrap();
        assert_eq!(table.lights[0], [0, 6, 0, 0]);
        let mut swapped = cube.clone();
        swapped.swap(0, 1);
        assert!(shadow_table(&[point], &swapped, &[(extent, 1)]).is_err());
        assert!(shadow_table(&[point], &cube[..3], &[(extent, 1)]).is_err());
    }
}
