//! The scene file's TOML format as serde reads it: one struct per table, unknown keys refused.
//! Every value an error may name is a [`Spanned`], so the error gives its line (see
//! `docs/scene-format.toml` for what each key means). Tables are not: toml cannot span a table
//! that is only implied (`[material.layered]` by a `[[material.layered.layer]]`), so an error
//! about a whole table names its key without a line.

use std::path::PathBuf;

use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneToml {
    pub(super) name: Option<String>,
    /// Attributions of the assets the scene shows (name, source, licence).
    #[serde(default)]
    pub(super) credits: Vec<Spanned<String>>,
    /// Gone: the materials decide the frame. Kept only to explain that.
    pub(super) technique: Option<Spanned<toml::Value>>,
    pub(super) ambient: Option<Spanned<[f32; 3]>>,
    pub(super) environment: Option<EnvironmentToml>,
    pub(super) sky: Option<Spanned<[f32; 3]>>,
    pub(super) exposure: Option<Spanned<f32>>,
    pub(super) camera: CameraToml,
    #[serde(default)]
    pub(super) mesh: Vec<MeshToml>,
    #[serde(default)]
    pub(super) material: Vec<MaterialToml>,
    #[serde(default)]
    pub(super) object: Vec<ObjectToml>,
    #[serde(default)]
    pub(super) light: Vec<LightToml>,
    pub(super) deformation: Option<DeformationToml>,
}

/// `[environment]`: the light from everywhere (see [`crate::scene::environment`]).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct EnvironmentToml {
    /// `constant`, `hemisphere` or `map`.
    pub(super) kind: Spanned<String>,
    /// `constant`: the radiance.
    pub(super) radiance: Option<Spanned<[f32; 3]>>,
    /// `hemisphere`: radiance above the horizon.
    pub(super) sky: Option<Spanned<[f32; 3]>>,
    /// `hemisphere`: radiance below the horizon.
    pub(super) ground: Option<Spanned<[f32; 3]>>,
    /// `map`: an equirectangular file (HDR, EXR, PNG, ...).
    pub(super) file: Option<Spanned<PathBuf>>,
    /// `map`: a built-in map instead of a file (`sky`).
    pub(super) builtin: Option<Spanned<String>>,
    /// `map`: radiance multiplier (default 1).
    pub(super) intensity: Option<Spanned<f32>>,
    /// `map`: turn about +y, degrees (default 0).
    pub(super) rotation_degrees: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraToml {
    pub(super) eye: Spanned<[f32; 3]>,
    pub(super) target: Spanned<[f32; 3]>,
    pub(super) fov_y_degrees: Option<Spanned<f32>>,
    pub(super) near: Option<Spanned<f32>>,
    pub(super) far: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MeshToml {
    pub(super) name: Spanned<String>,
    pub(super) obj: Option<Spanned<PathBuf>>,
    /// With `obj`: whether the OBJ's MTL materials are used (default true); `false` draws its
    /// faces with the objects' materials alone.
    pub(super) mtl: Option<Spanned<bool>>,
    /// A glTF 2.0 asset (`.gltf` or `.glb`): every mesh of its default scene, placed by its
    /// nodes, with its materials unless the `[[object]]` names one.
    pub(super) gltf: Option<Spanned<PathBuf>>,
    /// With `gltf`: scene units per millimetre of its media (default 0.001, a glTF metre).
    pub(super) units_per_mm: Option<Spanned<f32>>,
    pub(super) generator: Option<Spanned<String>>,
    pub(super) level: Option<Spanned<u32>>,
    pub(super) triangles: Option<Spanned<u64>>,
}

#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum ThicknessToml {
    Value(f32),
    Named(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TranslucencyToml {
    /// Required without a `[material.medium]`; with one, omitted = the medium's distances.
    pub(super) thickness: Option<Spanned<ThicknessToml>>,
    pub(super) color: Option<Spanned<[f32; 3]>>,
    pub(super) power: Option<Spanned<f32>>,
    pub(super) distortion: Option<Spanned<f32>>,
    pub(super) ambient: Option<Spanned<f32>>,
    pub(super) pow: Option<Spanned<String>>,
    /// Other objects' shadows fall on the transmitted light (default false: the talk's term).
    pub(super) shadowed: Option<Spanned<bool>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SssToml {
    pub(super) preset: Option<Spanned<String>>,
    /// Rows of `[variance_mm2, r, g, b]`.
    pub(super) gaussians: Option<Spanned<Vec<[f32; 4]>>>,
    pub(super) units_per_mm: Option<Spanned<f32>>,
    pub(super) blur: Option<Spanned<String>>,
    /// Burley's `d` per channel, mm.
    pub(super) scattering_distance: Option<Spanned<[f32; 3]>>,
    /// Burley's diffuse mean free path per channel, mm.
    pub(super) mean_free_path: Option<Spanned<[f32; 3]>>,
    /// `post`, `pre-post` or `pre` (`Texturing`).
    pub(super) texturing: Option<Spanned<String>>,
}

/// One `[[material.layered.layer]]` table.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LayerToml {
    pub(super) sigma_a: Option<Spanned<[f32; 3]>>,
    pub(super) sigma_s: Option<Spanned<[f32; 3]>>,
    pub(super) sigma_s_prime: Option<Spanned<[f32; 3]>>,
    pub(super) g: Option<Spanned<f32>>,
    /// A number (mm), `"texture"` or `"rest"`: read by hand for a message naming all three.
    pub(super) thickness: Option<Spanned<toml::Value>>,
    pub(super) thickness_scale: Option<Spanned<f32>>,
}

/// `[material.layered]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LayeredToml {
    pub(super) preset: Option<Spanned<String>>,
    pub(super) layer: Option<Vec<LayerToml>>,
    pub(super) eta: Option<Spanned<f32>>,
    pub(super) weights: Option<Spanned<[f32; 5]>>,
    pub(super) units_per_mm: Option<Spanned<f32>>,
    /// A path or an array of paths.
    pub(super) depth_texture: Option<Spanned<toml::Value>>,
}

/// `[material.medium]`: one homogeneous medium the material is made of.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MediumToml {
    pub(super) preset: Option<Spanned<String>>,
    pub(super) sigma_a: Option<Spanned<[f32; 3]>>,
    pub(super) sigma_s: Option<Spanned<[f32; 3]>>,
    pub(super) sigma_s_prime: Option<Spanned<[f32; 3]>>,
    pub(super) g: Option<Spanned<f32>>,
    pub(super) eta: Option<Spanned<f32>>,
    pub(super) units_per_mm: Option<Spanned<f32>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MaterialToml {
    pub(super) name: Spanned<String>,
    pub(super) albedo: Option<Spanned<[f32; 3]>>,
    pub(super) specular: Option<Spanned<f32>>,
    pub(super) roughness: Option<Spanned<f32>>,
    pub(super) albedo_texture: Option<Spanned<PathBuf>>,
    pub(super) normal_texture: Option<Spanned<PathBuf>>,
    pub(super) translucency: Option<TranslucencyToml>,
    pub(super) sss: Option<SssToml>,
    pub(super) layered: Option<LayeredToml>,
    pub(super) medium: Option<MediumToml>,
    /// Gone: `[material.layered]` replaced it. Kept only to say so.
    pub(super) layers: Option<toml::Value>,
}

/// `scale = 2` or `scale = [x, y, z]`. Deserialized by hand: serde's untagged enum would
/// report anything else as "data did not match any variant of untagged enum ScaleToml".
pub(super) enum ScaleToml {
    Uniform(f32),
    PerAxis([f32; 3]),
}

impl<'de> Deserialize<'de> for ScaleToml {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Visitor;
        const EXPECTED: &str = "one number (uniform) or [x, y, z] (three numbers)";
        impl<'de> serde::de::Visitor<'de> for Visitor {
            type Value = ScaleToml;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(EXPECTED)
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<ScaleToml, E> {
                Ok(ScaleToml::Uniform(v as f32))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<ScaleToml, A::Error> {
                let mut values = Vec::new();
                while let Some(v) = seq.next_element::<f32>()? {
                    values.push(v);
                    if values.len() > 3 {
                        break;
                    }
                }
                match <[f32; 3]>::try_from(values.as_slice()) {
                    Ok(v) => Ok(ScaleToml::PerAxis(v)),
                    Err(_) => Err(serde::de::Error::custom(format!(
                        "`scale` must be {EXPECTED}, not an array of {}{} numbers",
                        if values.len() > 3 { "more than " } else { "" },
                        values.len().min(3)
                    ))),
                }
            }
        }
        deserializer.deserialize_any(Visitor)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObjectToml {
    pub(super) mesh: Spanned<String>,
    /// Required, except for a glTF mesh, whose own materials it then keeps.
    pub(super) material: Option<Spanned<String>>,
    pub(super) translate: Option<Spanned<[f32; 3]>>,
    pub(super) rotate_degrees: Option<Spanned<[f32; 3]>>,
    pub(super) scale: Option<Spanned<ScaleToml>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightToml {
    #[serde(rename = "type")]
    pub(super) kind: Spanned<String>,
    pub(super) color: Option<Spanned<[f32; 3]>>,
    pub(super) intensity: Spanned<f32>,
    pub(super) position: Option<Spanned<[f32; 3]>>,
    pub(super) direction: Option<Spanned<[f32; 3]>>,
    pub(super) range: Option<Spanned<f32>>,
    pub(super) inner_degrees: Option<Spanned<f32>>,
    pub(super) outer_degrees: Option<Spanned<f32>>,
    pub(super) translucency_scale: Option<Spanned<f32>>,
    pub(super) shadows: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DeformationToml {
    #[serde(rename = "type")]
    pub(super) kind: Spanned<String>,
    pub(super) amplitude: Spanned<f32>,
    pub(super) frequency: Spanned<f32>,
    pub(super) speed: Spanned<f32>,
}
