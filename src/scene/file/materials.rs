//! The scene file's `[[material]]` tables turned into [`Material`]s: the opaque surface and its
//! textures, `[material.translucency]`, `[material.sss]` and `[material.layered]` with its
//! `[[material.layered.layer]]` tables. Every bad value is an error naming its key and line.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;
use toml::Spanned;

use super::schema::{
    LayerToml, LayeredToml, MaterialToml, MediumToml, SssToml, ThicknessToml, TranslucencyToml,
};
use super::{span, value, SceneFile, Table};
use crate::scene::layered::{
    self, sigma_s_from_reduced, MAX_ABS_G, MAX_COEFFICIENT, MAX_LAYERS, PHYSICAL_WEIGHTS,
};
use crate::scene::material::{
    BurleyDistance, Gaussian, Layer, LayeredMedium, Material, Medium, PowMode, SssProfile,
    TechniqueName, TextureSource, Texturing, Thickness, ThicknessSource, Translucency,
};
use crate::scene::obj::ObjMaterial;
use crate::Result;

/// The `[[material]]` tables by name.
pub(super) fn materials<'a>(
    file: &SceneFile<'_>,
    tables: &'a [MaterialToml],
) -> Result<HashMap<&'a str, Material>> {
    let mut materials = HashMap::new();
    for (i, m) in tables.iter().enumerate() {
        let at = file.table("material", Some(i));
        let material = material(file, at, m)?;
        if materials
            .insert(m.name.get_ref().as_str(), material)
            .is_some()
        {
            return Err(at.error(
                "name",
                Some(m.name.span()),
                format!("material '{}' is defined twice", m.name.get_ref()),
            ));
        }
    }
    Ok(materials)
}

/// One `[[material]]` table.
fn material(file: &SceneFile<'_>, at: Table<'_>, m: &MaterialToml) -> Result<Material> {
    let texture = |p: &Option<Spanned<PathBuf>>, key: &str| -> Result<Option<TextureSource>> {
        let Some(p) = p else { return Ok(None) };
        let full = file.resolve(p.get_ref());
        if !full.exists() {
            return Err(at.error(
                key,
                Some(p.span()),
                format!("texture {} not found", full.display()),
            ));
        }
        Ok(Some(TextureSource::File(full)))
    };
    let medium = m.medium.as_ref().map(|t| medium(at, t)).transpose()?;
    // What the techniques derive from the medium, made once (the profile fit takes a few ms).
    let derived = medium.clone().map(Medium::new);
    // The albedo a technique shades with: as written, else the medium's white-sky albedo
    // (what a Lambertian surface of it reflects), else a light grey.
    let albedo = match (value(&m.albedo), &derived) {
        (Some(written), _) => Vec3::from(written),
        (None, Some(derived)) => derived.albedo,
        (None, None) => Vec3::splat(0.8),
    };
    let mut material = Material::opaque(
        m.name.get_ref(),
        albedo,
        value(&m.specular).unwrap_or(0.5),
        value(&m.roughness).unwrap_or(0.5),
    );
    material.albedo_texture = texture(&m.albedo_texture, "albedo_texture")?;
    material.normal_texture = texture(&m.normal_texture, "normal_texture")?;
    if let Some(t) = &m.translucency {
        material.translucency = Some(translucency(file, at, t, medium.as_ref())?);
    }
    if let Some(s) = &m.sss {
        material.sss = Some(sss(at, s, material.albedo, derived.as_ref())?);
    }
    if m.layers.is_some() {
        return Err(at.error(
            "layers",
            None,
            "`layers` is now `[material.layered]` with a `preset` (Jensen 2001 media: apple, \
             skin1, ...) or `[[material.layered.layer]]` tables (see docs/scene-format.toml)",
        ));
    }
    // Li et al.'s layers: the material's own table, else the medium as one semi-infinite layer
    // when the material names no other technique: a medium with a [material.sss] or
    // [material.translucency] is rendered by that technique under `auto` (one technique per
    // material; a forced SSS technique fits a profile to the medium, `SssProfiles::new`).
    let other_technique = m.sss.is_some() || m.translucency.is_some();
    material.layers = match (&m.layered, &medium) {
        (Some(l), _) => Some(layered_medium(file, at, l)?),
        (None, Some(medium)) if !other_technique => Some(medium.clone()),
        (None, _) => None,
    };
    material.medium = derived;
    // Map a range failure to the key it names.
    material.validate().map_err(|e| {
        let message = e.to_string();
        let t = m.translucency.as_ref();
        let keys = [
            ("albedo", span(&m.albedo)),
            ("specular", span(&m.specular)),
            ("roughness", span(&m.roughness)),
            ("power", t.and_then(|t| span(&t.power))),
            ("distortion", t.and_then(|t| span(&t.distortion))),
            ("ambient", t.and_then(|t| span(&t.ambient))),
            ("thickness", t.and_then(|t| span(&t.thickness))),
            ("color", t.and_then(|t| span(&t.color))),
        ];
        let (key, key_span) = keys
            .into_iter()
            .find(|(k, _)| message.contains(k))
            .unwrap_or(("name", Some(m.name.span())));
        at.error(key, key_span, message)
    })?;
    Ok(material)
}

/// `[material.translucency]`. With a `[material.medium]` (`medium`), what the table does not
/// write derives from it ([`Translucency::from_medium`]): without `thickness`, the medium's
/// transmittance through the baked distance (its colour), and the fitted power and
/// distortion; a written key overrides (a written `thickness` is the talk's artistic 0-1 map,
/// whose colour is `color`, white by default, as without a medium).
fn translucency(
    file: &SceneFile<'_>,
    at: Table<'_>,
    t: &TranslucencyToml,
    medium: Option<&LayeredMedium>,
) -> Result<Translucency> {
    let Some(written) = &t.thickness else {
        let Some(medium) = medium else {
            return Err(at.error(
                "translucency.thickness",
                None,
                "missing `thickness`: a number in [0, 1], \"bake\", \"vertex\" or a texture \
                 (only a material with a [material.medium] may leave it out: its thickness is \
                 then the baked distance through the medium)",
            ));
        };
        let mut translucency = Translucency::from_medium(medium);
        overrides(at, t, &mut translucency)?;
        return Ok(translucency);
    };
    let thickness = match written.get_ref() {
        ThicknessToml::Value(v) => ThicknessSource::Constant(*v),
        ThicknessToml::Named(s) if s == "bake" => ThicknessSource::Bake,
        ThicknessToml::Named(s) if s == "vertex" => ThicknessSource::PerVertex,
        ThicknessToml::Named(s) => {
            let full = file.resolve(Path::new(s));
            if !full.exists() {
                return Err(at.error(
                    "thickness",
                    Some(written.span()),
                    format!(
                        "thickness texture {} not found (or use a number, \"bake\" or \"vertex\")",
                        full.display()
                    ),
                ));
            }
            ThicknessSource::Texture(TextureSource::File(full))
        }
    };
    let mut translucency = Translucency::new(thickness);
    if let Some(medium) = medium {
        // The lobe's fit holds whatever the thickness: the medium's power and distortion.
        let derived = Translucency::from_medium(medium);
        translucency.power = derived.power;
        translucency.distortion = derived.distortion;
    }
    overrides(at, t, &mut translucency)?;
    Ok(translucency)
}

/// The keys of `[material.translucency]` besides `thickness`, over what `translucency` holds.
fn overrides(at: Table<'_>, t: &TranslucencyToml, translucency: &mut Translucency) -> Result<()> {
    if let Some(c) = value(&t.color) {
        translucency.color = Vec3::from(c);
    }
    translucency.power = value(&t.power).unwrap_or(translucency.power);
    translucency.distortion = value(&t.distortion).unwrap_or(translucency.distortion);
    translucency.ambient = value(&t.ambient).unwrap_or(translucency.ambient);
    translucency.shadowed = value(&t.shadowed).unwrap_or(translucency.shadowed);
    translucency.pow_mode = match t.pow.as_ref().map(|p| p.get_ref().as_str()) {
        None | Some("exact") => PowMode::Exact,
        Some("exp2") => PowMode::SphericalGaussian,
        Some("exp2-scaled") => PowMode::SphericalGaussianScaled,
        Some(other) => {
            return Err(at.error(
                "pow",
                span(&t.pow),
                format!("unknown pow mode '{other}'; use exact, exp2 or exp2-scaled"),
            ))
        }
    };
    Ok(())
}

/// `[material.sss]`: a preset or Gaussians, their scale, Burley's distances, and the blur that
/// renders them. `albedo` is the material's, which a `mean_free_path` is scaled by.
fn sss(at: Table<'_>, s: &SssToml, albedo: Vec3, medium: Option<&Medium>) -> Result<SssProfile> {
    let burley = burley_distance(at, s, albedo)?;
    let mut profile =
        match (&s.preset, &s.gaussians, medium) {
            // Beside a [material.medium], a table that gives no profile takes the medium's
            // (the Gaussians and Burley's distance fitted to its dipole): the table then says
            // how to blur it (`blur`, `texturing`), and that the material is screen-space SSS.
            (None, None, Some(medium)) if burley.is_none() => medium.profile.clone(),
            (Some(p), None, _) => SssProfile::preset(p.get_ref())
                .map_err(|e| at.error("preset", Some(p.span()), e))?,
            (None, Some(rows), _) => SssProfile {
                name: "custom".into(),
                gaussians: rows
                    .get_ref()
                    .iter()
                    .map(|r| Gaussian {
                        variance: r[0],
                        weight: Vec3::new(r[1], r[2], r[3]),
                    })
                    .collect(),
                units_per_mm: 0.01,
                blur: None,
                burley: None,
                texturing: Texturing::default(),
            },
            // Burley's distances alone: the Gaussian blurs get six Gaussians fitted to the profile
            // (a mean free path through the default fit).
            (None, None, _) if burley.is_some() => SssProfile {
                name: "burley".into(),
                gaussians: Vec::new(),
                units_per_mm: 0.01,
                blur: None,
                burley,
                texturing: Texturing::default(),
            },
            _ => return Err(at.error(
                "sss",
                None,
                "give exactly one of `preset` or `gaussians` (or only `scattering_distance` or \
                 `mean_free_path`, or neither beside a [material.medium]: its fitted profile)",
            )),
        };
    if burley.is_some() || medium.is_none() || s.preset.is_some() || s.gaussians.is_some() {
        profile.burley = burley;
    }
    if profile.gaussians.is_empty() {
        profile.gaussians =
            crate::scene::profile::burley_gaussians(profile.burley_d(Default::default()));
    }
    if let Some(u) = &s.units_per_mm {
        let u_value = *u.get_ref();
        if !(u_value.is_finite() && u_value > 0.0) {
            return Err(at.error(
                "sss.units_per_mm",
                Some(u.span()),
                format!(
                    "{u_value} must be finite and > 0 (scene units per millimetre of the \
                     profile: 1 when a scene unit is a millimetre, 0.001 when it is a metre)"
                ),
            ));
        }
        profile.units_per_mm = u_value;
    }
    if let Some(b) = &s.blur {
        profile.blur = Some(sss_blur(at, b));
    }
    if let Some(t) = &s.texturing {
        profile.texturing = Texturing::named(t.get_ref()).ok_or_else(|| {
            at.error(
                "sss.texturing",
                Some(t.span()),
                format!(
                    "unknown texturing '{}'; use post (albedo after the blur), pre-post (its \
                     square root before and after) or pre (albedo blurred with the light)",
                    t.get_ref()
                ),
            )
        })?;
    }
    profile.validate().map_err(|e| match &s.gaussians {
        Some(g) => at.error("gaussians", Some(g.span()), e),
        None => at.error("units_per_mm", span(&s.units_per_mm), e),
    })?;
    Ok(profile)
}

/// `[material.sss] scattering_distance` or `mean_free_path`: Burley's shape per channel, mm,
/// each component finite and within [`crate::scene::profile::BURLEY_D_RANGE`].
fn burley_distance(at: Table<'_>, s: &SssToml, albedo: Vec3) -> Result<Option<BurleyDistance>> {
    let (lo, hi) = crate::scene::profile::BURLEY_D_RANGE;
    let checked = |key: &str, v: &Spanned<[f32; 3]>| -> Result<Vec3> {
        let d = Vec3::from(*v.get_ref());
        if d.is_finite() && d.min_element() >= lo && d.max_element() <= hi {
            return Ok(d);
        }
        Err(at.error(
            key,
            Some(v.span()),
            format!("{d} must be three finite millimetres from {lo} to {hi}"),
        ))
    };
    match (&s.scattering_distance, &s.mean_free_path) {
        (Some(_), Some(m)) => Err(at.error(
            "sss.mean_free_path",
            Some(m.span()),
            "give at most one of `scattering_distance` (Burley's d) and `mean_free_path`",
        )),
        (Some(d), None) => Ok(Some(BurleyDistance::Scattering(checked(
            "sss.scattering_distance",
            d,
        )?))),
        (None, Some(m)) => Ok(Some(BurleyDistance::MeanFreePath {
            mfp: checked("sss.mean_free_path", m)?,
            albedo: albedo.clamp(Vec3::ZERO, Vec3::ONE),
        })),
        (None, None) => Ok(None),
    }
}

/// `[material.sss] blur`: the blur that renders the profile, by name.
fn sss_blur(at: Table<'_>, name: &Spanned<String>) -> TechniqueName {
    // The name stays a name: the technique registry, above the scene, resolves it, and its
    // error names this file, line and key.
    TechniqueName::written_at(
        name.get_ref().as_str(),
        at.file.path,
        at.location("blur", Some(name.span())),
    )
}

/// `[material.layered]` as a checked [`LayeredMedium`]: every bad value is an error naming its
/// key (`material[1].layered.layer[0].g`), every key does something or is refused.
fn layered_medium(file: &SceneFile<'_>, at: Table<'_>, l: &LayeredToml) -> Result<LayeredMedium> {
    let mut medium = match (&l.preset, &l.layer) {
        (Some(p), None) => LayeredMedium::preset(p.get_ref())
            .map_err(|e| at.error("layered.preset", Some(p.span()), e))?,
        (None, Some(layers)) => {
            let count = layers.len();
            if !(1..=MAX_LAYERS).contains(&count) {
                return Err(at.error(
                    "layered.layer",
                    None,
                    format!(
                        "{count} layers; 1 to {MAX_LAYERS} [[material.layered.layer]] tables are \
                         supported"
                    ),
                ));
            }
            let mut medium = LayeredMedium::homogeneous("custom", Vec3::ZERO, Vec3::ZERO, 0.0, 1.3);
            medium.layers = layers
                .iter()
                .enumerate()
                .map(|(k, t)| layer(at, k, count, t))
                .collect::<Result<_>>()?;
            medium
        }
        (Some(p), Some(_)) => {
            return Err(at.error(
                "layered.preset",
                Some(p.span()),
                "give a `preset` or [[material.layered.layer]] tables, not both",
            ))
        }
        (None, None) => {
            return Err(at.error(
                "layered",
                None,
                "give a `preset` or [[material.layered.layer]] tables",
            ))
        }
    };
    if let Some(eta) = &l.eta {
        medium.eta = checked_eta(at, "layered.eta", eta)?;
    }
    if let Some(weights) = &l.weights {
        let w = *weights.get_ref();
        if let Some(bad) = w.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
            return Err(at.error(
                "layered.weights",
                Some(weights.span()),
                format!(
                    "{w:?}: {bad} must be finite and >= 0 (lambda_1..lambda_5 of Li et al.'s \
                     eq. 3: diffuse, specular, transmitted, single, multiple)"
                ),
            ));
        }
        medium.weights = w;
    }
    if let Some(units) = &l.units_per_mm {
        medium.units_per_mm = checked_units_per_mm(at, "layered.units_per_mm", units)?;
    }
    medium.depth_textures = depth_textures(file, at, l, medium.depth_textures_needed())?;
    // Everything was checked above; this names what a future field would miss.
    medium
        .validate()
        .map_err(|e| at.error("layered", None, e))?;
    Ok(medium)
}

/// `[[material.layered.layer]]` number `k` of `count`.
fn layer(at: Table<'_>, k: usize, count: usize, t: &LayerToml) -> Result<Layer> {
    let prefix = format!("layered.layer[{k}]");
    let missing = |what: &str| at.error(&prefix, None, what);
    let (sigma_a, sigma_s, g) = coefficients(
        at,
        &prefix,
        [&t.sigma_a, &t.sigma_s, &t.sigma_s_prime],
        &t.g,
    )?;
    let thickness = layer_thickness(at, k, count, t, &missing)?;
    Ok(Layer {
        sigma_a,
        sigma_s,
        g,
        thickness,
    })
}

/// A medium's absorption, scattering (`sigma_s`, or the reduced `sigma_s_prime` stored as
/// `sigma_s' / (1 - g)`) and Henyey-Greenstein `g`, written as `[sigma_a, sigma_s,
/// sigma_s_prime]` in the table `prefix` (a layer's or `[material.medium]`): each error names
/// its key. Returns (sigma_a, sigma_s, g), mm^-1.
fn coefficients(
    at: Table<'_>,
    prefix: &str,
    [sigma_a, sigma_s, sigma_s_prime]: [&Option<Spanned<[f32; 3]>>; 3],
    g: &Option<Spanned<f32>>,
) -> Result<(Vec3, Vec3, f32)> {
    let key = |leaf: &str| format!("{prefix}.{leaf}");
    let missing = |what: &str| at.error(prefix, None, what);
    let coefficient = |leaf: &str, v: &Spanned<[f32; 3]>| -> Result<Vec3> {
        let numbers = *v.get_ref();
        if numbers
            .iter()
            .all(|c| c.is_finite() && (0.0..=MAX_COEFFICIENT).contains(c))
        {
            Ok(Vec3::from(numbers))
        } else {
            Err(at.error(
                &key(leaf),
                Some(v.span()),
                format!("{numbers:?} must be finite and in [0, {MAX_COEFFICIENT:e}] (mm^-1)"),
            ))
        }
    };
    let sigma_a = match sigma_a {
        Some(v) => coefficient("sigma_a", v)?,
        None => return Err(missing("missing `sigma_a` (absorption, RGB, mm^-1)")),
    };
    let g_value = value(g).unwrap_or(0.0);
    if !(g_value.is_finite() && g_value.abs() <= MAX_ABS_G) {
        return Err(at.error(
            &key("g"),
            span(g),
            format!(
                "{g_value} must be in [-{MAX_ABS_G}, {MAX_ABS_G}] (Henyey-Greenstein anisotropy; \
                 |g| = 1 is a delta)"
            ),
        ));
    }
    let sigma_s = match (sigma_s, sigma_s_prime) {
        (Some(v), None) => coefficient("sigma_s", v)?,
        (None, Some(v)) => {
            let s = sigma_s_from_reduced(coefficient("sigma_s_prime", v)?, g_value);
            if s.max_element() > MAX_COEFFICIENT {
                return Err(at.error(
                    &key("sigma_s_prime"),
                    Some(v.span()),
                    format!(
                        "{:?} / (1 - g) = {s} exceeds {MAX_COEFFICIENT:e} mm^-1",
                        v.get_ref()
                    ),
                ));
            }
            s
        }
        (Some(_), Some(v)) => {
            return Err(at.error(
                &key("sigma_s_prime"),
                Some(v.span()),
                "give `sigma_s` or the reduced `sigma_s_prime`, not both",
            ))
        }
        (None, None) => {
            return Err(missing(
                "missing `sigma_s` (or the reduced `sigma_s_prime`), RGB, mm^-1",
            ))
        }
    };
    Ok((sigma_a, sigma_s, g_value))
}

/// A relative index of refraction (`key`): finite and > 0.
fn checked_eta(at: Table<'_>, key: &str, eta: &Spanned<f32>) -> Result<f32> {
    let eta_value = *eta.get_ref();
    if eta_value.is_finite() && eta_value > 0.0 {
        Ok(eta_value)
    } else {
        Err(at.error(
            key,
            Some(eta.span()),
            format!("{eta_value} must be finite and > 0 (relative index; 1 = no boundary)"),
        ))
    }
}

/// Scene units per millimetre (`key`), in [`layered::UNITS_PER_MM_RANGE`].
fn checked_units_per_mm(at: Table<'_>, key: &str, units: &Spanned<f32>) -> Result<f32> {
    let u = *units.get_ref();
    let range = layered::UNITS_PER_MM_RANGE;
    if u.is_finite() && range.contains(&u) {
        Ok(u)
    } else {
        Err(at.error(
            key,
            Some(units.span()),
            format!(
                "{u} must be in [{:e}, {:e}] (scene units per millimetre: 1 when a unit is a \
                 millimetre, 0.001 when it is a metre)",
                range.start(),
                range.end()
            ),
        ))
    }
}

/// `[material.medium]`: the one homogeneous medium the material is made of, a Jensen 2001
/// `preset` or its coefficients (mm^-1), its `eta` and `units_per_mm`, as one semi-infinite
/// layer weighted physically (eq. 3's lambdas (0, 1, 1, 1, 1): the medium's light, nothing
/// added). The material's albedo and Li et al.'s layers derive from it where the material
/// does not write its own (`material`).
fn medium(at: Table<'_>, t: &MediumToml) -> Result<LayeredMedium> {
    let written = [&t.sigma_a, &t.sigma_s, &t.sigma_s_prime];
    let coefficients_written = written.iter().any(|c| c.is_some()) || t.g.is_some();
    let mut medium =
        match &t.preset {
            Some(p) if coefficients_written => return Err(at.error(
                "medium.preset",
                Some(p.span()),
                "give a `preset` or the coefficients (`sigma_a`, `sigma_s` or `sigma_s_prime`, \
                 `g`), not both",
            )),
            Some(p) => {
                let preset = LayeredMedium::preset(p.get_ref())
                    .map_err(|e| at.error("medium.preset", Some(p.span()), e))?;
                if preset.layers.len() != 1 {
                    return Err(at.error(
                        "medium.preset",
                        Some(p.span()),
                        format!(
                            "`{}` is a stack of {} layers, not one medium: give it as \
                         `[material.layered] preset = \"{}\"`",
                            p.get_ref(),
                            preset.layers.len(),
                            p.get_ref()
                        ),
                    ));
                }
                preset
            }
            None => {
                let (sigma_a, sigma_s, g) = coefficients(at, "medium", written, &t.g)?;
                let mut medium = LayeredMedium::homogeneous("custom", Vec3::ZERO, sigma_a, g, 1.3);
                medium.layers[0].sigma_s = sigma_s;
                medium
            }
        };
    medium.weights = PHYSICAL_WEIGHTS;
    if let Some(eta) = &t.eta {
        medium.eta = checked_eta(at, "medium.eta", eta)?;
    }
    if let Some(units) = &t.units_per_mm {
        medium.units_per_mm = checked_units_per_mm(at, "medium.units_per_mm", units)?;
    }
    medium.validate().map_err(|e| at.error("medium", None, e))?;
    Ok(medium)
}

/// What a layer's `thickness` may be.
const THICKNESS: &str = "a number of mm (>= 0), \"texture\" (per texel from depth_texture) or \
                         \"rest\" (semi-infinite, last layer only)";

/// The `thickness` (and `thickness_scale`) of layer `k` of `count`; `missing` makes the error
/// for a layer without one.
fn layer_thickness(
    at: Table<'_>,
    k: usize,
    count: usize,
    t: &LayerToml,
    missing: &dyn Fn(&str) -> crate::LucentError,
) -> Result<Thickness> {
    let key = |leaf: &str| format!("layered.layer[{k}].{leaf}");
    let Some(given) = &t.thickness else {
        return Err(missing(&format!("missing `thickness`: {THICKNESS}")));
    };
    let thickness_span = Some(given.span());
    let thickness = match given.get_ref() {
        toml::Value::Float(v) => Thickness::Mm(*v as f32),
        toml::Value::Integer(v) => Thickness::Mm(*v as f32),
        toml::Value::String(s) if s == "rest" => Thickness::Rest,
        toml::Value::String(s) if s == "texture" => Thickness::Texture {
            scale: value(&t.thickness_scale).unwrap_or(1.0),
        },
        other => {
            return Err(at.error(
                &key("thickness"),
                thickness_span,
                format!("{other} must be {THICKNESS}"),
            ))
        }
    };
    match thickness {
        Thickness::Mm(v) if !(v.is_finite() && v >= 0.0) => Err(at.error(
            &key("thickness"),
            thickness_span,
            format!("{v} must be {THICKNESS}"),
        )),
        Thickness::Rest if k + 1 != count => Err(at.error(
            &key("thickness"),
            thickness_span,
            format!(
                "\"rest\" (semi-infinite) is allowed only on the last layer (layer[{}])",
                count - 1
            ),
        )),
        Thickness::Texture { scale } if !(scale.is_finite() && scale > 0.0) => Err(at.error(
            &key("thickness_scale"),
            span(&t.thickness_scale),
            format!("{scale} must be finite and > 0 (mm per texel unit)"),
        )),
        Thickness::Mm(_) | Thickness::Rest if t.thickness_scale.is_some() => Err(at.error(
            &key("thickness_scale"),
            span(&t.thickness_scale),
            "only a layer with thickness = \"texture\" reads a scale",
        )),
        _ => Ok(thickness),
    }
}

/// `[material.layered] depth_texture`: exactly the `needed` textures the layers with
/// thickness = "texture" read, each found.
fn depth_textures(
    file: &SceneFile<'_>,
    at: Table<'_>,
    l: &LayeredToml,
    needed: usize,
) -> Result<Vec<TextureSource>> {
    const KEY: &str = "layered.depth_texture";
    let Some(given) = &l.depth_texture else {
        if needed > 0 {
            return Err(at.error(
                KEY,
                None,
                format!(
                    "missing: {needed} depth texture(s) for the layers with thickness = \
                     \"texture\""
                ),
            ));
        }
        return Ok(Vec::new());
    };
    let given_span = Some(given.span());
    let paths: Vec<&str> = match given.get_ref() {
        toml::Value::String(s) => vec![s.as_str()],
        toml::Value::Array(a) if a.iter().all(|x| x.is_str()) => {
            a.iter().filter_map(|x| x.as_str()).collect()
        }
        other => {
            return Err(at.error(
                KEY,
                given_span,
                format!("{other} must be a path or an array of paths"),
            ))
        }
    };
    if needed == 0 {
        return Err(at.error(
            KEY,
            given_span,
            "no layer reads it: give a layer thickness = \"texture\" or remove the key",
        ));
    }
    if paths.len() != needed {
        return Err(at.error(
            KEY,
            given_span,
            format!(
                "{} textures given, the layers read {needed} (layer i with thickness = \
                 \"texture\" reads channel i % 4 of texture i / 4)",
                paths.len()
            ),
        ));
    }
    paths
        .into_iter()
        .map(|p| {
            let full = file.resolve(Path::new(p));
            if full.exists() {
                Ok(TextureSource::File(full))
            } else {
                Err(at.error(
                    KEY,
                    given_span.clone(),
                    format!("depth texture {} not found", full.display()),
                ))
            }
        })
        .collect()
}

/// `material` on the faces of an OBJ part whose MTL material is `mtl`: the MTL's `map_Kd`
/// becomes the albedo texture unless the scene's material has one, its `norm` the normal map
/// unless the scene's material has one, and its `Kd` the albedo unless the scene's material
/// sets `albedo` (clamped to [0, 1], which is all a reflectance can be).
pub(super) fn with_mtl(material: &Material, mtl: &ObjMaterial, explicit_albedo: bool) -> Material {
    let mut m = material.clone();
    m.name = format!("{} ({})", material.name, mtl.name);
    if m.albedo_texture.is_none() {
        if let Some(t) = &mtl.diffuse_texture {
            m.albedo_texture = Some(TextureSource::File(t.clone()));
        }
    }
    if m.normal_texture.is_none() {
        if let Some(t) = &mtl.normal_texture {
            m.normal_texture = Some(TextureSource::File(t.clone()));
        }
    }
    if let (false, Some(kd)) = (explicit_albedo, mtl.diffuse) {
        let clamped = kd.clamp(Vec3::ZERO, Vec3::ONE);
        if clamped != kd {
            log::warn!(
                "MTL material '{}': Kd {kd} clamped to {clamped} (a reflectance is in [0, 1])",
                mtl.name
            );
        }
        m.albedo = clamped;
    }
    m
}
