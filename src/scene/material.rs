//! Materials and lights: what a surface is made of and what lights it.
//!
//! - [`Material`]: the base (albedo, specular, roughness, optional textures) plus the optional
//!   parts each technique reads: [`Translucency`] (GDC 2011), [`SssProfile`] (screen-space SSS,
//!   a sum of Gaussians) and [`LayeredMedium`] (Li et al.'s multi-layer scattering).
//!   A part that is `None` costs nothing: the frame graph leaves out its passes.
//! - [`Light`]: point, spot or directional, with colour, intensity, range and the talk's
//!   per-light translucency scale.
//!
//! Presets carry their sources: d'Eon's six-Gaussian skin fit (the thesis's Figure 17); the
//! layered media (Jensen et al. 2001's measured materials, which Li et al.'s Table 1 uses, and a
//! two-layer skin) live in [`super::layered`] and are re-exported here.

use glam::Vec3;

use crate::{LucentError, Result};

pub use super::layered::{Layer, LayeredMedium, Thickness};
pub use super::profile::{
    BurleyDistance, Gaussian, SssProfile, TechniqueName, Texturing, MARBLE_GAUSSIANS,
    SKIN_GAUSSIANS,
};
pub use super::texture::{ProceduralTexture, TextureSource};

/// Where the GDC 2011 local thickness comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ThicknessSource {
    /// The same value everywhere (0 = opaque, 1 = thinnest).
    Constant(f32),
    /// A texture (linear data, thin = white), sampled with the mesh's UVs.
    Texture(TextureSource),
    /// The mesh's vertex colours (e.g. written by `lucent bake-thickness --per-vertex`).
    PerVertex,
    /// Baked at load by [`crate::bake`], cached on disk keyed by mesh content.
    Bake,
    /// A distance under the surface in the mesh's own units, as glTF's `KHR_materials_volume`
    /// gives it: `factor` times the texture's green channel (`factor` alone without one),
    /// scaled with the object. Only for a term derived from a medium (`extinction`): its
    /// transmittance through this distance replaces the one through the baked distance.
    Volume {
        /// `thicknessFactor`: mesh units, finite, >= 0.
        factor: f32,
        /// `thicknessTexture` (linear; its green channel scales `factor`).
        texture: Option<TextureSource>,
    },
}

/// How the translucency's view-dependent lobe raises to its power.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PowMode {
    /// `pow(x, n)`, as in the talk.
    Exact,
    /// The seed's simplified spherical-Gaussian form `exp2(n * x - n)`, without the scale and
    /// bias (spherical-gaussian-pow-translucency: artists tune `n` by eye, so it need not
    /// match `pow`'s exponent).
    SphericalGaussian,
    /// The full spherical-Gaussian approximation of `pow(x, n)`: `exp2(n' x - n')` with
    /// `n' = (n + 1) / ln 2`, the scale and bias applied once on the CPU.
    SphericalGaussianScaled,
}

/// Frostbite 2 translucency parameters (GDC 2011), per material.
#[derive(Clone, Debug, PartialEq)]
pub struct Translucency {
    /// Local thickness source.
    pub thickness: ThicknessSource,
    /// Colour of the light that travels through (white = grayscale thickness).
    pub color: Vec3,
    /// `iLTPower`: sharpness of the view-dependent back-lighting lobe.
    pub power: f32,
    /// `fLTDistortion`: how much the surface normal bends the inverted light vector.
    pub distortion: f32,
    /// `fLTAmbient`: translucency visible from every angle.
    pub ambient: f32,
    /// Exact `pow` or the spherical-Gaussian `exp2` form.
    pub pow_mode: PowMode,
    /// The material's medium, when the term's thickness derives from it: the thickness stream
    /// then holds the medium's transmittance through the baked slab-equivalent distance in
    /// millimetres (`thickness` is [`ThicknessSource::Bake`], baked as distances), and
    /// `color` scales it. `None`: the talk's artistic 0-1 thickness.
    pub extinction: Option<Extinction>,
    /// Other objects' shadows fall on the light let through (lucent's extension: a tap of
    /// the light-space maps whose first surface is this material's own counts as lit, any
    /// other occluder darkens the term). `false` is the talk's term, which its local
    /// thickness alone attenuates: it costs no shadow lookup for lights behind the surface and
    /// no ID target in the light-space maps (issue 34: they cost `grid125` +30-45% on the
    /// maps and +45-50% on lighting). Scene files: `shadowed = true` in
    /// `[material.translucency]`.
    pub shadowed: bool,
}

/// GDC 2011's power, distortion and gain for a material with a medium, fitted once against the
/// path-traced truth of the back-lit 4 mm skin1 slab (`tools/truth/truths/skin1-slab-backlit`,
/// the 160x120 truth committed with issue 26; docs/translucency.md, "From the medium", has the
/// grid; `cargo test --test gpu translucency_fit -- --ignored --nocapture` redoes it): the
/// slab alone prefers power 0 (error 0.321), a view-independent term that wraps light onto
/// lit faces (the side-lit marble sphere: 0.093 -> 0.73), so the power is the smallest that
/// keeps the side-lit spheres within 0.011 of plain shading: 2 (slab 0.433 at gain 0.53).
pub const MEDIUM_POWER: f32 = 2.0;
/// See [`MEDIUM_POWER`].
pub const MEDIUM_DISTORTION: f32 = 0.0;
/// See [`MEDIUM_POWER`]: the fitted gain on the transmittance, the derived `color` (grey).
pub const MEDIUM_GAIN: f32 = 0.53;

/// A medium's extinction as GDC 2011's term reads it: the per-channel transmittance
/// `exp(-sigma_tr t)` through a thickness `t` in millimetres, `sigma_tr = sqrt(3 sigma_a
/// sigma_t')` the diffusion's effective extinction (the far-field decay of the medium's
/// dipole, Jensen et al. 2001), so the colour of the light let through is the medium's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extinction {
    /// `sigma_tr` per channel, mm^-1 (finite, >= 0).
    pub sigma_tr: Vec3,
    /// Millimetres per scene unit (`1 / units_per_mm`, finite, > 0).
    pub mm_per_unit: f32,
}

impl Extinction {
    /// The extinction of `medium` (one semi-infinite layer at its eta).
    pub fn of(medium: &LayeredMedium) -> Self {
        let layer = &medium.layers[0];
        let (sp, sa) = (layer.sigma_s_prime(), layer.sigma_a);
        let sigma_tr = [0, 1, 2].map(|c| {
            super::layered::dipole_constants(
                f64::from(sp[c]),
                f64::from(sa[c]),
                f64::from(medium.eta),
            )
            .sigma_tr as f32
        });
        Self {
            // Validated coefficients are at most 1e6 / mm, so sigma_tr <= sqrt(3) 1e6 * ~1.4:
            // finite; the max drops a NaN a future model might give to 0 (clear).
            sigma_tr: Vec3::from(sigma_tr).max(Vec3::ZERO),
            // units_per_mm is validated finite and in [1e-6, 1e6].
            mm_per_unit: 1.0 / medium.units_per_mm,
        }
    }

    /// The transmittance per channel through `mm` millimetres, in [0, 1]:
    /// `exp(-sigma_tr mm)`. The exponent is held in [0, 1e4] (a NaN thickness reads as
    /// opaque), so it never overflows and `0 * inf` never happens.
    pub fn transmittance(&self, mm: f32) -> Vec3 {
        let tau = |s: f32| {
            let x = s * mm;
            if x.is_nan() {
                1e4
            } else {
                x.clamp(0.0, 1e4)
            }
        };
        Vec3::new(
            (-tau(self.sigma_tr.x)).exp(),
            (-tau(self.sigma_tr.y)).exp(),
            (-tau(self.sigma_tr.z)).exp(),
        )
    }
}

impl Translucency {
    /// The talk's defaults: power 12 (Fig. 16), distortion 0.2 (Fig. 17), no ambient.
    pub fn new(thickness: ThicknessSource) -> Self {
        Self {
            thickness,
            color: Vec3::ONE,
            power: 12.0,
            distortion: 0.2,
            ambient: 0.0,
            pow_mode: PowMode::Exact,
            extinction: None,
            shadowed: false,
        }
    }

    /// GDC 2011's term derived from `medium`: the transmittance through the baked distance
    /// (a distance bake, in mm through the medium's `units_per_mm`), with the power,
    /// distortion and gain fitted against the path-traced truth ([`MEDIUM_POWER`]).
    pub fn from_medium(medium: &LayeredMedium) -> Self {
        Self {
            thickness: ThicknessSource::Bake,
            color: Vec3::splat(MEDIUM_GAIN),
            power: MEDIUM_POWER,
            distortion: MEDIUM_DISTORTION,
            ambient: 0.0,
            pow_mode: PowMode::Exact,
            extinction: Some(Extinction::of(medium)),
            shadowed: false,
        }
    }

    /// The constant part of the thickness, multiplied in the G-buffer pass with the mesh's
    /// thickness stream (its vertex colours, or white): the tint times the constant thickness
    /// (1 for per-vertex, baked or texture thickness, which live in the stream).
    pub fn thickness_factor(&self) -> Vec3 {
        let constant = match self.thickness {
            ThicknessSource::Constant(c) => c,
            _ => 1.0,
        };
        self.color * constant
    }

    /// Whether the thickness is coloured (not the same in every channel).
    pub fn is_colored(&self) -> bool {
        self.color.x != self.color.y || self.color.y != self.color.z
    }
}

/// What a surface is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name (for scene files and errors).
    pub name: String,
    /// Linear albedo, each channel in [0, 1].
    pub albedo: Vec3,
    /// Specular intensity in [0, 1].
    pub specular: f32,
    /// Roughness in [0, 1] (Blinn-Phong exponent 2^(11 - 10 r)).
    pub roughness: f32,
    /// Albedo texture (sRGB), multiplied with `albedo`.
    pub albedo_texture: Option<TextureSource>,
    /// Tangent-space normal map (linear).
    pub normal_texture: Option<TextureSource>,
    /// GDC 2011 translucency, if the material lets light through thin parts.
    pub translucency: Option<Translucency>,
    /// Screen-space SSS diffusion profile, if the material scatters below the surface.
    pub sss: Option<SssProfile>,
    /// Li et al.'s layered medium, if the material is layered.
    pub layers: Option<LayeredMedium>,
    /// The one homogeneous medium the material is made of (`[material.medium]`), if it gives
    /// one: its albedo (when not written) is the medium's white-sky albedo and its
    /// `layers` (when not written) the medium itself.
    pub medium: Option<Medium>,
}

/// The one homogeneous medium a material is made of (`[material.medium]`) with what a
/// technique derives from it that takes work to derive, done once when the material is made
/// (a frame reads it every frame).
#[derive(Clone, Debug, PartialEq)]
pub struct Medium {
    /// The medium as one semi-infinite layer with physical weights: Li et al.'s layers.
    pub layered: LayeredMedium,
    /// The screen-space profile fitted to its dipole
    /// ([`crate::scene::profile::medium_profile`]): what a forced SSS technique blurs a
    /// material without a `[material.sss]` of its own with.
    pub profile: SssProfile,
    /// That fit's relative L2 error per channel.
    pub fit_error: [f64; 3],
    /// GDC 2011's term from the medium ([`Translucency::from_medium`]): what a forced
    /// `--technique translucency` renders a material without a `[material.translucency]` of
    /// its own with.
    pub translucency: Translucency,
    /// Its white-sky albedo at its eta ([`LayeredMedium::white_sky_albedo`]): the albedo a
    /// material takes from it, Burley's surface albedo, what its screen-space transmission is
    /// relative to.
    pub albedo: Vec3,
    /// Its white-sky albedo behind an index-matched boundary: what its screen-space
    /// reflectance's shape is normalised to (`crate::features::sss::transmission`).
    pub matched_albedo: Vec3,
}

impl Medium {
    /// `layered` (one semi-infinite layer) with what the techniques derive from it: its
    /// albedos (an H-function iteration each), its SSS profile fitted, GDC 2011's term. Made
    /// once with the material; frames read it.
    pub fn new(layered: LayeredMedium) -> Self {
        let albedo = layered.white_sky_albedo();
        let matched_albedo = layered.white_sky_albedo_at(1.0);
        let (profile, fit_error) = crate::scene::profile::medium_profile(&layered, albedo);
        let translucency = Translucency::from_medium(&layered);
        Self {
            layered,
            profile,
            fit_error,
            translucency,
            albedo,
            matched_albedo,
        }
    }
}

impl Material {
    /// A plain opaque material.
    pub fn opaque(name: &str, albedo: Vec3, specular: f32, roughness: f32) -> Self {
        Self {
            name: name.to_string(),
            albedo,
            specular,
            roughness,
            albedo_texture: None,
            normal_texture: None,
            translucency: None,
            sss: None,
            layers: None,
            medium: None,
        }
    }

    /// GDC 2011's term under `--technique translucency` (`forced`) or `auto`: the material's
    /// own `[material.translucency]`, else, forced, the one derived from its medium.
    pub fn translucency_under(&self, forced: bool) -> Option<&Translucency> {
        match (&self.translucency, &self.medium) {
            (Some(t), _) => Some(t),
            (None, Some(m)) if forced => Some(&m.translucency),
            _ => None,
        }
    }

    /// The term a frame with this material in its translucency table shades it with
    /// ([`Material::translucency_under`] with the force on: a table lists a material without
    /// its own term only when forced).
    pub fn translucency_in_table(&self) -> Option<&Translucency> {
        self.translucency_under(true)
    }

    /// Checks ranges: albedo, specular and roughness in [0, 1], finite; the optional parts valid.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| {
            Err(LucentError::InvalidInput(format!(
                "material '{}': {m}",
                self.name
            )))
        };
        if !(self.albedo.is_finite()
            && self.albedo.min_element() >= 0.0
            && self.albedo.max_element() <= 1.0)
        {
            return bad(format!("albedo {} must be in [0, 1]", self.albedo));
        }
        for (what, v) in [("specular", self.specular), ("roughness", self.roughness)] {
            if !(0.0..=1.0).contains(&v) {
                return bad(format!("{what} {v} must be in [0, 1]"));
            }
        }
        if let Some(t) = &self.translucency {
            for (what, v, max) in [
                ("translucency power", t.power, 1e4),
                ("translucency distortion", t.distortion, 10.0),
                ("translucency ambient", t.ambient, 1.0),
            ] {
                if !(v.is_finite() && (0.0..=max).contains(&v)) {
                    return bad(format!("{what} {v} must be in [0, {max}]"));
                }
            }
            if !(t.color.is_finite() && t.color.min_element() >= 0.0) {
                return bad("translucency color must be finite and >= 0".into());
            }
            match &t.thickness {
                ThicknessSource::Constant(c) if !(0.0..=1.0).contains(c) => {
                    return bad(format!("thickness {c} must be in [0, 1]"));
                }
                ThicknessSource::Volume { factor, .. } => {
                    if !(factor.is_finite() && *factor >= 0.0) {
                        return bad(format!("volume thickness {factor} must be finite and >= 0"));
                    }
                    // A distance means something only to a term derived from a medium.
                    if t.extinction.is_none() {
                        return bad(
                            "a volume thickness (a distance) needs the medium's extinction: \
                             GDC 2011's own term reads a 0-1 thickness"
                                .into(),
                        );
                    }
                }
                _ => {}
            }
        }
        if let Some(p) = &self.sss {
            p.validate()?;
        }
        if let Some(l) = &self.layers {
            l.validate()?;
        }
        if let Some(Medium { layered: m, .. }) = &self.medium {
            m.validate()?;
            if m.layers.len() != 1 || m.layers[0].thickness != Thickness::Rest {
                return bad("a medium is one semi-infinite layer".into());
            }
        }
        Ok(())
    }
}

/// The geometry of a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Parallel light travelling along `direction`.
    Directional {
        /// Direction the light travels (need not be normalised).
        direction: Vec3,
    },
    /// Inverse-square light that fades smoothly to zero at `range`.
    Point {
        /// World position.
        position: Vec3,
        /// Distance at which its contribution reaches zero.
        range: f32,
    },
    /// A point light restricted to a cone, with a smooth edge between the two angles.
    Spot {
        /// World position.
        position: Vec3,
        /// Direction the cone points (need not be normalised).
        direction: Vec3,
        /// Distance at which its contribution reaches zero.
        range: f32,
        /// Half-angle of full intensity, degrees.
        inner_degrees: f32,
        /// Half-angle where intensity reaches zero, degrees.
        outer_degrees: f32,
    },
}

/// A light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Geometry.
    pub kind: LightKind,
    /// Linear colour.
    pub color: Vec3,
    /// Intensity multiplier (radiance = colour x intensity).
    pub intensity: f32,
    /// The talk's per-light translucency scale (`fLTScale`): how strongly this light shines
    /// through translucent materials.
    pub translucency_scale: f32,
    /// Whether the light casts shadows (a light-space map; on by default). A light that does
    /// not has no map and lights every surface it faces.
    pub shadows: bool,
}

impl Light {
    /// A point light of white-balanced colour.
    pub fn point(position: Vec3, color: Vec3, intensity: f32, range: f32) -> Self {
        Self {
            kind: LightKind::Point { position, range },
            color,
            intensity,
            translucency_scale: 1.0,
            shadows: true,
        }
    }

    /// A directional light.
    pub fn directional(direction: Vec3, color: Vec3, intensity: f32) -> Self {
        Self {
            kind: LightKind::Directional { direction },
            color,
            intensity,
            translucency_scale: 1.0,
            shadows: true,
        }
    }

    /// Colour times intensity.
    pub fn radiance(&self) -> Vec3 {
        self.color * self.intensity
    }

    /// Checks the light is finite and in range.
    pub fn validate(&self, what: &str) -> Result<()> {
        let bad = |m: String| Err(LucentError::InvalidInput(format!("{what}: {m}")));
        if !(self.color.is_finite() && self.color.min_element() >= 0.0) {
            return bad("color must be finite and >= 0".into());
        }
        if !(self.intensity.is_finite() && self.intensity >= 0.0) {
            return bad(format!(
                "intensity {} must be finite and >= 0",
                self.intensity
            ));
        }
        if !(self.translucency_scale.is_finite() && self.translucency_scale >= 0.0) {
            return bad(format!(
                "translucency_scale {} must be finite and >= 0",
                self.translucency_scale
            ));
        }
        match self.kind {
            LightKind::Directional { direction } => {
                if !(direction.is_finite() && direction.length_squared() > 1e-12) {
                    return bad("direction must be a finite non-zero vector".into());
                }
            }
            LightKind::Point { position, range } => {
                if !(position.is_finite() && range.is_finite() && range > 0.0) {
                    return bad("position must be finite and range > 0".into());
                }
            }
            LightKind::Spot {
                position,
                direction,
                range,
                inner_degrees,
                outer_degrees,
            } => {
                if !(position.is_finite() && range.is_finite() && range > 0.0) {
                    return bad("position must be finite and range > 0".into());
                }
                if !(direction.is_finite() && direction.length_squared() > 1e-12) {
                    return bad("direction must be a finite non-zero vector".into());
                }
                if !(0.0 <= inner_degrees && inner_degrees < outer_degrees && outer_degrees <= 90.0)
                {
                    return bad(format!(
                        "spot angles must satisfy 0 <= inner ({inner_degrees}) < outer ({outer_degrees}) <= 90"
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skin_preset_is_the_thesis_table() {
        let p = SssProfile::preset("skin").unwrap();
        p.validate().unwrap();
        assert_eq!(p.gaussians.len(), 6);
        assert_eq!(p.gaussians[0].variance, 0.0064);
        assert_eq!(p.gaussians[5].weight, Vec3::new(0.078, 0.0, 0.0));
        // d'Eon's red weights sum to 1.0 (the table is normalised per channel).
        let red: f32 = p.gaussians.iter().map(|g| g.weight.x).sum();
        assert!((red - 1.0).abs() < 1e-3, "{red}");
    }

    #[test]
    fn out_of_range_values_are_rejected() {
        let mut m = Material::opaque("m", Vec3::splat(0.5), 0.5, 0.5);
        m.validate().unwrap();
        m.roughness = 3.0;
        assert!(m
            .validate()
            .unwrap_err()
            .to_string()
            .contains("roughness 3"));
        let mut l = Light::point(Vec3::ZERO, Vec3::ONE, -1.0, 5.0);
        assert!(l.validate("light").is_err());
        l.intensity = 1.0;
        l.validate("light").unwrap();
        l.kind = LightKind::Spot {
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            range: 5.0,
            inner_degrees: 40.0,
            outer_degrees: 30.0,
        };
        assert!(l.validate("light").is_err());
    }
}
