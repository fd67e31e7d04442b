//! glTF materials as lucent [`Material`]s (docs/gltf.md has the table): metallic-roughness
//! mapped to lucent's albedo, specular and roughness; the base colour and normal textures
//! (with `normalTexture.scale` and `KHR_texture_transform`); `KHR_materials_volume` +
//! `KHR_materials_volume_scatter` + `KHR_materials_ior` as a `[material.medium]`;
//! `KHR_materials_diffuse_transmission` as GDC 2011's light through thin parts. Every key
//! lucent does not use is a warning naming it.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use ::gltf::json;
use ::gltf::json::validation::Checked;
use glam::{Vec2, Vec3};
use serde_json::{Map, Value};

use super::container::{read_uri, Container, MAX_FILE_BYTES};
use crate::scene::layered::{LayeredMedium, MAX_ABS_G, MAX_COEFFICIENT, PHYSICAL_WEIGHTS};
use crate::scene::material::{Material, Medium, TextureSource, ThicknessSource, Translucency};
use crate::scene::texture::EncodedImage;

/// How a material's textures are sampled: lucent has one UV set per mesh, so the set and the
/// `KHR_texture_transform` of the material's textures are applied to the mesh's UVs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvMapping {
    /// `TEXCOORD_n`.
    pub set: u32,
    /// The affine transform `uv' = m * (u, v, 1)` as two rows, or `None`.
    pub transform: Option<[[f32; 3]; 2]>,
}

impl UvMapping {
    /// `uv` transformed.
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        match self.transform {
            None => uv,
            Some([a, b]) => Vec2::new(
                a[0] * uv.x + a[1] * uv.y + a[2],
                b[0] * uv.x + b[1] * uv.y + b[2],
            ),
        }
    }
}

/// A glTF material converted: what lucent draws with, and the UVs its textures want.
#[derive(Clone, Debug)]
pub struct Converted {
    pub material: Material,
    /// `None` when the material has no texture.
    pub uv: Option<UvMapping>,
}

/// What the conversion needs of the asset; images are read once each.
pub struct MaterialContext<'a> {
    pub path: &'a Path,
    pub container: &'a Container,
    /// Scene units per millimetre of the media (a glTF unit is a metre: 0.001).
    pub units_per_mm: f32,
    images: HashMap<usize, Arc<[u8]>>,
}

impl<'a> MaterialContext<'a> {
    pub fn new(path: &'a Path, container: &'a Container, units_per_mm: f32) -> Self {
        Self {
            path,
            container,
            units_per_mm,
            images: HashMap::new(),
        }
    }

    /// Material `index` (`None`: glTF's default material) converted.
    pub fn convert(&mut self, index: Option<usize>) -> Result<Converted, String> {
        let default;
        let (what, m) = match index {
            Some(i) => (
                format!("materials[{i}]"),
                self.container
                    .root
                    .materials
                    .get(i)
                    .ok_or_else(|| format!("materials[{i}] does not exist"))?,
            ),
            None => {
                default = default_material();
                ("the default material".to_string(), &default)
            }
        };
        let name = match (&m.name, index) {
            (Some(n), _) => n.clone(),
            (None, Some(i)) => format!("material {i}"),
            (None, None) => "default".into(),
        };
        convert(self, &what, &name, m)
    }

    /// The encoded bytes of image `index` (a URI inside the asset's folder, a data URI or a
    /// buffer view), read once.
    fn image_bytes(&mut self, index: usize) -> Result<Arc<[u8]>, String> {
        if let Some(bytes) = self.images.get(&index) {
            return Ok(bytes.clone());
        }
        let what = format!("images[{index}]");
        let image = self
            .container
            .root
            .images
            .get(index)
            .ok_or_else(|| format!("{what} does not exist"))?;
        let bytes: Arc<[u8]> = match (&image.uri, image.buffer_view) {
            (Some(uri), None) => read_uri(&self.container.dir, uri, &what, "glTF image")?.into(),
            (None, Some(view)) => {
                let v = view.value();
                let view = self
                    .container
                    .root
                    .buffer_views
                    .get(v)
                    .ok_or_else(|| format!("{what}: bufferViews[{v}] does not exist"))?;
                let b = view.buffer.value();
                let buffer = self
                    .container
                    .buffers
                    .get(b)
                    .ok_or_else(|| format!("bufferViews[{v}]: buffers[{b}] does not exist"))?;
                let start = view.byte_offset.map_or(0, |o| o.0);
                let end = start
                    .checked_add(view.byte_length.0)
                    .filter(|&e| e <= buffer.len() as u64 && e - start <= MAX_FILE_BYTES)
                    .ok_or_else(|| {
                        format!(
                            "bufferViews[{v}] (offset {start}, length {}) runs past the end of \
                             buffers[{b}] ({} bytes)",
                            view.byte_length.0,
                            buffer.len()
                        )
                    })?;
                buffer[start as usize..end as usize].into()
            }
            _ => return Err(format!("{what} needs exactly one of uri and bufferView")),
        };
        self.images.insert(index, bytes.clone());
        Ok(bytes)
    }

    /// The texture `info` names as an encoded image lucent decodes, its header checked now
    /// (an image that is not one, or too large, is an error here), and the UVs it wants.
    fn texture(
        &mut self,
        key: &str,
        index: usize,
        tex_coord: u32,
        transform: Option<&json::extensions::texture::TextureTransform>,
        normal_scale: f32,
    ) -> Result<(TextureSource, UvMapping), String> {
        let texture = self
            .container
            .root
            .textures
            .get(index)
            .ok_or_else(|| format!("{key}: textures[{index}] does not exist"))?;
        if let Some(ext) = &texture.extensions {
            for name in ext.others.keys() {
                log::warn!(
                    "{}: textures[{index}]: extension {name} ignored",
                    self.path.display()
                );
            }
        }
        if let Some(s) = texture.sampler {
            if let Some(sampler) = self.container.root.samplers.get(s.value()) {
                let repeat = Checked::Valid(json::texture::WrappingMode::Repeat);
                if sampler.wrap_s != repeat || sampler.wrap_t != repeat {
                    log::warn!(
                        "{}: samplers[{}]: wrapS/wrapT ignored: lucent repeats every texture",
                        self.path.display(),
                        s.value()
                    );
                }
            }
        }
        let image = texture.source.value();
        let bytes = self.image_bytes(image)?;
        let name = match self
            .container
            .root
            .images
            .get(image)
            .and_then(|i| i.name.as_ref())
        {
            Some(n) => format!("images[{image}] \"{n}\""),
            None => format!("images[{image}]"),
        };
        let encoded = EncodedImage {
            file: self.path.to_path_buf(),
            name: format!("{key}: {name}"),
            bytes,
            normal_scale,
        };
        // Not an image, or too large: refused now, naming the file and the image.
        encoded.dimensions().map_err(|e| {
            let text = e.to_string();
            let prefix = format!("{}: ", self.path.display());
            text.strip_prefix(&prefix).unwrap_or(&text).to_string()
        })?;
        let uv = UvMapping {
            set: transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord),
            transform: transform.map(texture_transform),
        };
        Ok((TextureSource::Encoded(encoded), uv))
    }
}

/// glTF's default material (every property at its default).
fn default_material() -> json::Material {
    // The empty object is a valid material: every field has a default.
    serde_json::from_str("{}").unwrap_or_default()
}

/// `KHR_texture_transform` as the rows of `T * R * S` (the ratified extension's GLSL:
/// `uv' = offset + R(rotation) (scale * uv)`, R the counter-clockwise rotation).
fn texture_transform(t: &json::extensions::texture::TextureTransform) -> [[f32; 3]; 2] {
    let (o, r, s) = (t.offset.0, t.rotation.0, t.scale.0);
    let (sin, cos) = r.sin_cos();
    [
        [cos * s[0], -sin * s[1], o[0]],
        [sin * s[0], cos * s[1], o[1]],
    ]
}

/// Roughness as lucent's Blinn-Phong roughness: glTF's perceptual roughness `r` is GGX
/// `alpha = r^2`, whose Blinn-Phong exponent is `2 / alpha^2 - 2` (Walter et al. 2007,
/// "Microfacet Models for Refraction through Rough Surfaces", §5.2), and lucent's exponent is
/// `2^(11 - 10 r')` (material.rs): `r' = (11 - log2(max(2 / r^4 - 2, 2))) / 10`, in [0, 1].
pub fn lucent_roughness(r: f32) -> f32 {
    let alpha = f64::from(r.clamp(0.0, 1.0)).powi(2);
    // alpha = 0 gives an infinite exponent: r' = 0, the sharpest lucent has.
    let exponent = (2.0 / (alpha * alpha) - 2.0).max(2.0);
    ((11.0 - exponent.log2()) / 10.0).clamp(0.0, 1.0) as f32
}

/// lucent's (white) specular intensity: a dielectric's normal-incidence Fresnel reflectance
/// `((ior - 1) / (ior + 1))^2` (0.04 at glTF's default ior 1.5), blended towards a metal's,
/// the luminance of its base colour, by `metallic`.
pub fn lucent_specular(base: Vec3, metallic: f32, ior: f32) -> f32 {
    let f0 = ((ior - 1.0) / (ior + 1.0)).powi(2);
    let metal = base.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    (f0 * (1.0 - metallic) + metal * metallic).clamp(0.0, 1.0)
}

/// The single-scattering albedo whose multiple-scattering albedo is `rho_ms`, for
/// Henyey-Greenstein anisotropy `g`: the inversion `KHR_materials_volume_scatter` (the
/// draft, KhronosGroup/glTF PR 2453, as the glTF Sample Viewer and Babylon.js read it)
/// takes from Kulla and Conty 2017 ("Revisiting Physically Based Shading at Imageworks",
/// SIGGRAPH course: `s = 4.09712 + 4.20863 rho - sqrt(9.59217 + 41.6808 rho + 17.7126
/// rho^2)`, the inverse of `rho = (1 - s)(1 - 0.139 s) / (1 + 1.17 s)`), with the anisotropic
/// similarity `s^2 = (1 - a) / (1 - g a)`: `a = (1 - s^2) / (1 - g s^2)`.
pub fn single_scattering_albedo(rho_ms: f32, g: f32) -> f32 {
    let rho = f64::from(rho_ms.clamp(0.0, 1.0));
    let g = f64::from(g.clamp(-MAX_ABS_G, MAX_ABS_G));
    let s = (4.09712 + 4.20863 * rho - (9.59217 + 41.6808 * rho + 17.7126 * rho * rho).sqrt())
        .clamp(0.0, 1.0);
    let s2 = s * s;
    // 1 - g s^2 >= 1 - 0.999 > 0: no division by zero.
    ((1.0 - s2) / (1.0 - g * s2)).clamp(0.0, 1.0) as f32
}

/// The extension objects of one material, read key by key: what is left at the end is
/// warned about, by name.
struct Fields<'a> {
    what: String,
    map: Map<String, Value>,
    path: &'a Path,
}

impl<'a> Fields<'a> {
    fn new(path: &'a Path, what: String, value: &Value) -> Result<Self, String> {
        match value {
            Value::Object(map) => Ok(Self {
                what,
                map: map.clone(),
                path,
            }),
            other => Err(format!("{what} must be an object, not {other}")),
        }
    }

    fn number(&mut self, key: &str) -> Result<Option<f32>, String> {
        match self.map.remove(key) {
            None => Ok(None),
            Some(Value::Number(n)) => {
                let v = n.as_f64().unwrap_or(f64::NAN) as f32;
                if v.is_finite() {
                    Ok(Some(v))
                } else {
                    Err(format!("{}.{key}: {n} is not a finite number", self.what))
                }
            }
            Some(other) => Err(format!("{}.{key}: {other} is not a number", self.what)),
        }
    }

    fn vec3(&mut self, key: &str) -> Result<Option<Vec3>, String> {
        match self.map.remove(key) {
            None => Ok(None),
            Some(Value::Array(a)) if a.len() == 3 => {
                let v: Vec<f32> = a
                    .iter()
                    .map(|x| x.as_f64().map_or(f32::NAN, |x| x as f32))
                    .collect();
                if v.iter().all(|x| x.is_finite()) {
                    Ok(Some(Vec3::from_slice(&v)))
                } else {
                    Err(format!(
                        "{}.{key}: {a:?} must be three finite numbers",
                        self.what
                    ))
                }
            }
            Some(other) => Err(format!(
                "{}.{key}: {other} must be three numbers",
                self.what
            )),
        }
    }

    /// A `textureInfo` object (`index`, `texCoord`, `extensions`).
    fn texture_info(&mut self, key: &str) -> Result<Option<json::texture::Info>, String> {
        match self.map.remove(key) {
            None => Ok(None),
            Some(value) => serde_json::from_value(value)
                .map(Some)
                .map_err(|e| format!("{}.{key}: not a textureInfo ({e})", self.what)),
        }
    }

    /// A key lucent reads but does not use: removed with a warning naming it.
    fn ignore(&mut self, key: &str, why: &str) {
        if self.map.remove(key).is_some() {
            log::warn!(
                "{}: {}.{key} ignored: {why}",
                self.path.display(),
                self.what
            );
        }
    }

    /// Warns about every key left.
    fn finish(self) {
        for key in self.map.keys() {
            if key != "extras" {
                log::warn!("{}: {}.{key} ignored", self.path.display(), self.what);
            }
        }
    }
}

fn unit(what: &str, key: &str, v: f32) -> Result<f32, String> {
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{what}.{key}: {v} must be in [0, 1]"))
    }
}

/// One material.
fn convert(
    cx: &mut MaterialContext<'_>,
    what: &str,
    name: &str,
    m: &json::Material,
) -> Result<Converted, String> {
    let path = cx.path;
    let warn = |key: &str, why: &str| log::warn!("{}: {what}.{key} ignored: {why}", path.display());
    let pbr = &m.pbr_metallic_roughness;
    let [r, g, b, alpha] = pbr.base_color_factor.0;
    let base = Vec3::new(r, g, b);
    if !(base.is_finite() && base.min_element() >= 0.0 && base.max_element() <= 1.0) {
        return Err(format!(
            "{what}.pbrMetallicRoughness.baseColorFactor: {:?} must be in [0, 1]",
            pbr.base_color_factor.0
        ));
    }
    let metallic = unit(
        what,
        "pbrMetallicRoughness.metallicFactor",
        pbr.metallic_factor.0,
    )?;
    let roughness = unit(
        what,
        "pbrMetallicRoughness.roughnessFactor",
        pbr.roughness_factor.0,
    )?;
    if alpha != 1.0 || m.alpha_mode != Checked::Valid(json::material::AlphaMode::Opaque) {
        warn(
            "alphaMode",
            "lucent draws every surface opaque (base colour alpha unused)",
        );
    }
    if m.double_sided {
        warn(
            "doubleSided",
            "lucent draws front faces as it draws every mesh",
        );
    }
    if pbr.metallic_roughness_texture.is_some() {
        warn(
            "pbrMetallicRoughness.metallicRoughnessTexture",
            "lucent has no roughness or metalness map; the factors are used",
        );
    }
    if m.occlusion_texture.is_some() {
        warn("occlusionTexture", "lucent has no occlusion map");
    }
    if m.emissive_texture.is_some() || m.emissive_factor.0 != [0.0; 3] {
        warn(
            "emissiveFactor/emissiveTexture",
            "lucent's materials do not emit",
        );
    }

    // The extensions lucent reads; every other one is named in a warning.
    let mut ior = 1.5f32;
    let mut volume = None;
    let mut scatter = None;
    let mut transmission = None;
    if let Some(ext) = &m.extensions {
        for (key, value) in &ext.others {
            let fields = Fields::new(path, format!("{what}.extensions.{key}"), value)?;
            match key.as_str() {
                "KHR_materials_ior" => {
                    let mut f = fields;
                    if let Some(v) = f.number("ior")? {
                        if !(1.0..=10.0).contains(&v) {
                            return Err(format!(
                                "{}.ior: {v} must be in [1, 10] (lucent does not read ior 0, \
                                 the extension's fully reflective special case)",
                                f.what
                            ));
                        }
                        ior = v;
                    }
                    f.finish();
                }
                "KHR_materials_volume" => volume = Some(fields),
                "KHR_materials_volume_scatter" => scatter = Some(fields),
                "KHR_materials_diffuse_transmission" => transmission = Some(fields),
                other => log::warn!(
                    "{}: {what}.extensions.{other} ignored: lucent does not implement it",
                    path.display()
                ),
            }
        }
    }

    let mut uv: Option<UvMapping> = None;
    let use_uv = |key: &str, mapping: UvMapping, uv: &mut Option<UvMapping>| match uv {
        None => *uv = Some(mapping),
        Some(first) if *first == mapping => {}
        Some(first) => log::warn!(
            "{}: {what}.{key}: its texture coordinates (TEXCOORD_{}, transform {:?}) differ from \
             the base colour's (TEXCOORD_{}, {:?}); lucent has one UV set per mesh and samples \
             it with the base colour's",
            path.display(),
            mapping.set,
            mapping.transform,
            first.set,
            first.transform
        ),
    };
    let albedo_texture = match &pbr.base_color_texture {
        Some(info) => {
            let key = format!("{what}.pbrMetallicRoughness.baseColorTexture");
            let transform = info
                .extensions
                .as_ref()
                .and_then(|e| e.texture_transform.as_ref());
            let (source, mapping) =
                cx.texture(&key, info.index.value(), info.tex_coord, transform, 1.0)?;
            use_uv("pbrMetallicRoughness.baseColorTexture", mapping, &mut uv);
            Some(source)
        }
        None => None,
    };
    let normal_texture = match &m.normal_texture {
        Some(info) => {
            let key = format!("{what}.normalTexture");
            if !info.scale.is_finite() {
                return Err(format!("{key}.scale: {} is not finite", info.scale));
            }
            let (source, mapping) =
                cx.texture(&key, info.index.value(), info.tex_coord, None, info.scale)?;
            if info.extensions.is_some() {
                warn(
                    "normalTexture.extensions",
                    "lucent reads KHR_texture_transform on the base colour texture and applies it \
                     to every map",
                );
            }
            use_uv("normalTexture", mapping, &mut uv);
            Some(source)
        }
        None => None,
    };

    let albedo = base * (1.0 - metallic);
    let mut material = Material::opaque(
        name,
        albedo,
        lucent_specular(base, metallic, ior),
        lucent_roughness(roughness),
    );
    material.albedo_texture = albedo_texture;
    material.normal_texture = normal_texture;

    if let Some(mut t) = transmission {
        let factor = t.number("diffuseTransmissionFactor")?.unwrap_or(0.0);
        let factor = unit(&t.what, "diffuseTransmissionFactor", factor)?;
        let color = t
            .vec3("diffuseTransmissionColorFactor")?
            .unwrap_or(Vec3::ONE);
        if !(color.min_element() >= 0.0 && color.max_element() <= 1.0) {
            return Err(format!(
                "{}.diffuseTransmissionColorFactor: {color} must be in [0, 1]",
                t.what
            ));
        }
        t.ignore(
            "diffuseTransmissionTexture",
            "lucent's thickness map is read from RGB; the factor is used",
        );
        t.ignore(
            "diffuseTransmissionColorTexture",
            "lucent has no transmission colour map; the factor is used",
        );
        t.finish();
        if factor > 0.0 {
            // GDC 2011's term: the factor is the fraction let through (its thickness, 1 the
            // thinnest), the colour the light's tint through it.
            let mut translucency = Translucency::new(ThicknessSource::Constant(factor));
            translucency.color = color;
            material.translucency = Some(translucency);
        }
    }

    if let Some(mut v) = volume {
        let distance = v.number("attenuationDistance")?;
        let color = v.vec3("attenuationColor")?.unwrap_or(Vec3::ONE);
        // The thickness (mesh units): what GDC 2011's term derived from the medium reads
        // instead of the distance lucent would bake. 0, the default, is a thin wall.
        let thickness_factor = v.number("thicknessFactor")?.unwrap_or(0.0);
        if thickness_factor < 0.0 {
            return Err(format!(
                "{}.thicknessFactor: {thickness_factor} must be >= 0",
                v.what
            ));
        }
        let thickness_texture = match v.texture_info("thicknessTexture")? {
            Some(info) if thickness_factor > 0.0 => {
                let key = format!("{}.thicknessTexture", v.what);
                let transform = info
                    .extensions
                    .as_ref()
                    .and_then(|e| e.texture_transform.as_ref());
                let (source, mapping) =
                    cx.texture(&key, info.index.value(), info.tex_coord, transform, 1.0)?;
                use_uv("KHR_materials_volume.thicknessTexture", mapping, &mut uv);
                Some(source)
            }
            Some(_) => {
                log::warn!(
                    "{}: {}.thicknessTexture ignored: thicknessFactor is 0 (a thin wall), \
                     which the texture multiplies",
                    path.display(),
                    v.what
                );
                None
            }
            None => None,
        };
        let volume_what = v.what.clone();
        v.finish();
        if let Some(d) = distance {
            if d <= 0.0 {
                return Err(format!(
                    "{volume_what}.attenuationDistance: {d} must be > 0"
                ));
            }
        }
        if !(color.min_element() >= 0.0 && color.max_element() <= 1.0) {
            return Err(format!(
                "{volume_what}.attenuationColor: {color} must be in [0, 1]"
            ));
        }
        match scatter.take() {
            None => log::warn!(
                "{}: {volume_what} without KHR_materials_volume_scatter is a clear absorber \
                 meant for refraction, which lucent does not render: drawn as an opaque surface",
                path.display()
            ),
            Some(mut s) => {
                let rho = s.vec3("multiscatterColor")?.unwrap_or(Vec3::ZERO);
                if !(rho.min_element() >= 0.0 && rho.max_element() <= 1.0) {
                    return Err(format!(
                        "{}.multiscatterColor: {rho} must be in [0, 1]",
                        s.what
                    ));
                }
                let g = s.number("scatterAnisotropy")?.unwrap_or(0.0);
                if g.abs() >= 1.0 {
                    return Err(format!(
                        "{}.scatterAnisotropy: {g} must be in (-1, 1)",
                        s.what
                    ));
                }
                s.ignore(
                    "multiscatterColorTexture",
                    "lucent's media are homogeneous; the colour factor is used",
                );
                let scatter_what = s.what.clone();
                s.finish();
                let d = distance.unwrap_or(f32::INFINITY);
                match medium(name, d, color, rho, g, ior, cx.units_per_mm) {
                    None => log::warn!(
                        "{}: {scatter_what} ignored: the volume has no extinction \
                         (attenuationDistance infinite or attenuationColor white in every \
                         channel), so nothing scatters",
                        path.display()
                    ),
                    Some(layered) => {
                        layered
                            .validate()
                            .map_err(|e| format!("{scatter_what}: {e}"))?;
                        let mut derived = Medium::new(layered.clone());
                        if thickness_factor > 0.0 {
                            // The term derived from the medium (a forced `--technique
                            // translucency`) reads the asset's thickness, not a bake.
                            derived.translucency.thickness = ThicknessSource::Volume {
                                factor: thickness_factor,
                                texture: thickness_texture.clone(),
                            };
                        }
                        // The base colour tints what the medium gives (white by default).
                        material.albedo = derived.albedo * base * (1.0 - metallic);
                        if material.translucency.is_none() {
                            material.layers = Some(layered);
                        }
                        material.medium = Some(derived);
                    }
                }
            }
        }
    }
    if let Some(s) = scatter {
        let scatter_what = s.what.clone();
        s.finish();
        log::warn!(
            "{}: {scatter_what} ignored: it extends KHR_materials_volume, which the material \
             does not have",
            path.display()
        );
    }
    material.validate().map_err(|e| format!("{what}: {e}"))?;
    Ok(Converted { material, uv })
}

/// The medium `KHR_materials_volume` + `_volume_scatter` + `_ior` describe, as one
/// semi-infinite layer with physical weights (what `[material.medium]` makes): extinction
/// `sigma_t = -ln(attenuationColor) / attenuationDistance` per scene unit (the volume
/// extension's Beer-Lambert law), split by the single-scattering albedo
/// ([`single_scattering_albedo`]) into `sigma_s = a sigma_t` and `sigma_a = sigma_t -
/// sigma_s`, in mm^-1 through `units_per_mm`. `None` when nothing attenuates.
pub fn medium(
    name: &str,
    distance: f32,
    color: Vec3,
    multiscatter: Vec3,
    g: f32,
    ior: f32,
    units_per_mm: f32,
) -> Option<LayeredMedium> {
    let sigma_t = |c: f32| {
        // ln(0) is -inf: an attenuation colour of 0 is as opaque as lucent's media go.
        let per_unit = -f64::from(c.max(1e-30)).ln() / f64::from(distance);
        let per_mm = per_unit * f64::from(units_per_mm);
        (per_mm.clamp(0.0, f64::from(MAX_COEFFICIENT))) as f32
    };
    let t = Vec3::new(sigma_t(color.x), sigma_t(color.y), sigma_t(color.z));
    if t.max_element() <= 0.0 {
        return None;
    }
    let g = g.clamp(-MAX_ABS_G, MAX_ABS_G);
    let a = Vec3::new(
        single_scattering_albedo(multiscatter.x, g),
        single_scattering_albedo(multiscatter.y, g),
        single_scattering_albedo(multiscatter.z, g),
    );
    let sigma_s = a * t;
    let sigma_a = (t - sigma_s).max(Vec3::ZERO);
    let mut medium = LayeredMedium::homogeneous(name, Vec3::ZERO, sigma_a, g, ior);
    medium.layers[0].sigma_s = sigma_s;
    medium.weights = PHYSICAL_WEIGHTS;
    medium.units_per_mm = units_per_mm;
    Some(medium)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roughness_and_specular_map_the_ends() {
        assert_eq!(lucent_roughness(0.0), 0.0);
        assert_eq!(lucent_roughness(1.0), 1.0);
        // alpha 0.25: exponent 30, r' = (11 - log2 30) / 10.
        let r = lucent_roughness(0.5);
        assert!((r - (11.0 - 30f32.log2()) / 10.0).abs() < 1e-6, "{r}");
        assert!((lucent_specular(Vec3::ONE, 0.0, 1.5) - 0.04).abs() < 1e-7);
        assert!((lucent_specular(Vec3::ONE, 1.0, 1.5) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_albedo_inversion_matches_its_forward_form() {
        for g in [0.0f32, 0.5, -0.3] {
            for rho in [0.0f32, 0.1, 0.5, 0.8, 0.99, 1.0] {
                let a = f64::from(single_scattering_albedo(rho, g));
                let s = ((1.0 - a) / (1.0 - f64::from(g) * a)).sqrt();
                let forward = (1.0 - s) * (1.0 - 0.139 * s) / (1.0 + 1.17 * s);
                assert!(
                    (forward - f64::from(rho)).abs() < 2e-3,
                    "{rho} {g}: {forward}"
                );
            }
        }
    }

    #[test]
    fn a_volume_becomes_a_medium_in_mm() {
        // 1 - e^-1 of the light lost over 0.5 m, per channel: sigma_t = 2 / m = 0.002 / mm.
        let c = (-1.0f32).exp();
        let m = medium("m", 0.5, Vec3::splat(c), Vec3::splat(0.5), 0.0, 1.4, 0.001).unwrap();
        let l = &m.layers[0];
        assert!(((l.sigma_a + l.sigma_s).x - 0.002).abs() < 1e-7);
        assert!(l.sigma_s.x > l.sigma_a.x);
        assert_eq!((m.eta, m.units_per_mm), (1.4, 0.001));
        assert!(medium(
            "m",
            f32::INFINITY,
            Vec3::splat(c),
            Vec3::ONE,
            0.0,
            1.5,
            0.001
        )
        .is_none());
        assert!(medium("m", 1.0, Vec3::ONE, Vec3::ONE, 0.0, 1.5, 0.001).is_none());
    }

    #[test]
    fn texture_transform_follows_the_ratified_glsl() {
        let t: json::extensions::texture::TextureTransform = serde_json::from_str(
            r#"{"offset": [0, 1], "rotation": 1.5707963, "scale": [0.5, 0.5]}"#,
        )
        .unwrap();
        let m = UvMapping {
            set: 0,
            transform: Some(texture_transform(&t)),
        };
        // (1, 0): scaled to (0.5, 0), rotated a quarter turn to (0, 0.5), offset to (0, 1.5).
        let uv = m.apply(Vec2::new(1.0, 0.0));
        assert!((uv - Vec2::new(0.0, 1.5)).length() < 1e-6, "{uv}");
    }
}
