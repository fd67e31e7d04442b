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

use std::path::PathBuf;

use glam::Vec3;

use crate::{LucentError, Result};

pub use super::layered::{Layer, LayeredMedium, Thickness};

/// Where a texture comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureSource {
    /// A file (PNG, JPEG, TGA, EXR, HDR), relative paths resolved against the scene file.
    File(PathBuf),
    /// Made in code, so built-in scenes need no file from outside the repository.
    Procedural(ProceduralTexture),
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

/// One Gaussian of a diffusion profile: variance in mm² and its RGB weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    /// Variance v (the Gaussian is exp(-r²/2v) / 2πv), mm².
    pub variance: f32,
    /// Weight per colour channel.
    pub weight: Vec3,
}

/// A diffusion profile as a sum of Gaussians (d'Eon and Luebke), used by screen-space SSS.
#[derive(Clone, Debug, PartialEq)]
pub struct SssProfile {
    /// Preset name or "custom".
    pub name: String,
    /// The Gaussians, narrowest first.
    pub gaussians: Vec<Gaussian>,
    /// World units per millimetre of the profile (scene scale).
    pub units_per_mm: f32,
    /// The screen-space blur the material asks for (`[material.sss] blur`, a registered SSS
    /// technique's name); `None`: the registry's default blur.
    pub blur: Option<TechniqueName>,
    /// Christensen and Burley's normalized diffusion, for the 2-D Burley blur
    /// (`[material.sss] scattering_distance` or `mean_free_path`); `None`: the Burley blur
    /// matches the Gaussians' second moment (the other blurs always read the Gaussians).
    pub burley: Option<BurleyDistance>,
    /// Where the surface albedo meets the scattered light (`[material.sss] texturing`).
    pub texturing: Texturing,
}

/// Where a screen-space SSS material's albedo (its texture included) is applied relative to
/// the blur. Light that scatters under a surface crosses it on the way in and on the way out,
/// so a texture's detail belongs outside the blur, not smeared by it (HDRP's "post-scatter"
/// and "pre- and post-scatter" texturing modes; UE and EEVEE multiply after).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Texturing {
    /// The albedo is in the light the blur diffuses (lucent's behaviour before this mode
    /// existed; kept to measure what the other two change): textures are blurred away.
    Pre,
    /// The blur diffuses light without albedo; the pixel's own albedo multiplies the result:
    /// textures stay as sharp as under plain lighting. The default: the only mode that keeps
    /// `showcase-marble`'s veins at the contrast plain lighting gives them (docs/sss.md,
    /// "Albedo after the scatter", has the measurements).
    #[default]
    Post,
    /// The square root of the albedo before the blur and after it (HDRP's default): some of
    /// the neighbours' colour bleeds in (light entered through them), half the pixel's own
    /// detail stays.
    PrePost,
}

impl Texturing {
    /// Every mode with its scene-file and command-line name.
    pub const ALL: [(&'static str, Texturing); 3] = [
        ("pre", Texturing::Pre),
        ("post", Texturing::Post),
        ("pre-post", Texturing::PrePost),
    ];

    /// The mode named `name` (scene files, `--sss-texturing`).
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, t)| *t == self)
            .map_or("post", |(n, _)| n)
    }

    /// The shaders' code for it (glsl/common/sss.glsl `sss_albedo_*`): 0 pre, 1 post,
    /// 2 pre-post.
    pub fn code(self) -> f32 {
        match self {
            Texturing::Pre => 0.0,
            Texturing::Post => 1.0,
            Texturing::PrePost => 2.0,
        }
    }

    /// The factor of the albedo `a` in the light the blur diffuses.
    pub fn before(self, a: f64) -> f64 {
        match self {
            Texturing::Pre => a,
            Texturing::Post => 1.0,
            Texturing::PrePost => a.max(0.0).sqrt(),
        }
    }

    /// The factor of the albedo `a` that multiplies the blurred light.
    pub fn after(self, a: f64) -> f64 {
        match self {
            Texturing::Pre => 1.0,
            Texturing::Post => a,
            Texturing::PrePost => a.max(0.0).sqrt(),
        }
    }
}

/// How a material gives Burley's per-channel shape parameter `d` (mm): directly, as HDRP's
/// "scattering distance", or as a diffuse mean free path `l` with the surface albedo `A`,
/// `d = l / s(A)` by one of Christensen and Burley's fits (chosen per frame: `--burley-fit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BurleyDistance {
    /// `d` per channel, mm.
    Scattering(Vec3),
    /// The diffuse mean free path per channel (mm) and the albedo the fit reads.
    MeanFreePath {
        /// `l` per channel, mm.
        mfp: Vec3,
        /// Surface albedo `A` per channel, in [0, 1].
        albedo: Vec3,
    },
}

/// A technique a scene names (`[material.sss] blur`), kept as written. The scene knows no
/// techniques: the technique registry (`lucent::features::registry`), a layer above, resolves
/// the name, and [`TechniqueName::error`] words its complaint with the file, line and key the
/// name came from. Two names are equal when they are spelled the same.
#[derive(Clone, Debug)]
pub struct TechniqueName {
    /// The name as written.
    pub name: String,
    /// Where it was written: the scene file and ``line N, key `...` ``.
    origin: Option<(PathBuf, String)>,
}

impl TechniqueName {
    /// A name given in code (no file to point at).
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            origin: None,
        }
    }

    /// A name read from `path` at `location` (``line N, key `material[i].blur` ``).
    pub fn written_at(name: impl Into<String>, path: &std::path::Path, location: String) -> Self {
        Self {
            name: name.into(),
            origin: Some((path.to_path_buf(), location)),
        }
    }

    /// `message` about this name, naming where it was written when it came from a file.
    pub fn error(&self, message: impl std::fmt::Display) -> LucentError {
        match &self.origin {
            Some((path, location)) => LucentError::file(path, format!("{location}: {message}")),
            None => LucentError::InvalidInput(message.to_string()),
        }
    }
}

impl PartialEq for TechniqueName {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl From<&str> for TechniqueName {
    fn from(name: &str) -> Self {
        Self::new(name)
    }
}

/// d'Eon's six-Gaussian fit of human skin (the thesis, Figure 17): (variance mm², R, G, B).
pub const SKIN_GAUSSIANS: [(f32, [f32; 3]); 6] = [
    (0.0064, [0.233, 0.455, 0.649]),
    (0.0484, [0.100, 0.336, 0.344]),
    (0.187, [0.118, 0.198, 0.0]),
    (0.567, [0.113, 0.007, 0.007]),
    (1.99, [0.358, 0.004, 0.0]),
    (7.41, [0.078, 0.0, 0.0]),
];

/// Marble: the variances of the skin fit with weights fitted (non-negative least squares, in
/// `lucent::reference::dipole`) to Jensen et al.'s dipole profile of marble
/// (σs' = 2.19, 2.62, 3.00 /mm; σa = 0.0021, 0.0041, 0.0071 /mm; η = 1.5), each channel
/// normalised to sum to 1, fitted over 0 to 10 mm. The fit's relative L2 error is 1.8%, 1.2%
/// and 2.0% (R, G, B). Checked by the test `marble_preset_matches_its_fit`.
pub const MARBLE_GAUSSIANS: [(f32, [f32; 3]); 6] = [
    (0.0064, [0.0001, 0.0027, 0.0074]),
    (0.0484, [0.0857, 0.1409, 0.1943]),
    (0.187, [0.2174, 0.2054, 0.1755]),
    (0.567, [0.1421, 0.1372, 0.1612]),
    (1.99, [0.1675, 0.2001, 0.2098]),
    (7.41, [0.3873, 0.3138, 0.2519]),
];

impl SssProfile {
    /// A preset by name: `skin` (d'Eon, thesis Figure 17) or `marble`.
    pub fn preset(name: &str) -> Result<Self> {
        let table = match name {
            "skin" => &SKIN_GAUSSIANS,
            "marble" => &MARBLE_GAUSSIANS,
            _ => {
                return Err(LucentError::InvalidInput(format!(
                    "unknown SSS profile '{name}'; presets: skin, marble"
                )))
            }
        };
        Ok(Self {
            name: name.to_string(),
            gaussians: table
                .iter()
                .map(|&(variance, w)| Gaussian {
                    variance,
                    weight: Vec3::from(w),
                })
                .collect(),
            units_per_mm: 0.01,
            blur: None,
            burley: None,
            texturing: Texturing::default(),
        })
    }

    /// Checks the profile can be blurred safely: 1 to 8 Gaussians, finite positive variances,
    /// finite non-negative weights.
    pub fn validate(&self) -> Result<()> {
        let n = self.gaussians.len();
        if !(1..=8).contains(&n) {
            return Err(LucentError::InvalidInput(format!(
                "SSS profile '{}' has {n} Gaussians; 1 to 8 are supported",
                self.name
            )));
        }
        for (i, g) in self.gaussians.iter().enumerate() {
            if !(g.variance.is_finite() && g.variance > 0.0) {
                return Err(LucentError::InvalidInput(format!(
                    "SSS profile '{}' Gaussian {i}: variance {} must be finite and > 0",
                    self.name, g.variance
                )));
            }
            if !(g.weight.is_finite() && g.weight.min_element() >= 0.0) {
                return Err(LucentError::InvalidInput(format!(
                    "SSS profile '{}' Gaussian {i}: weights must be finite and >= 0",
                    self.name
                )));
            }
        }
        if !(self.units_per_mm.is_finite() && self.units_per_mm > 0.0) {
            return Err(LucentError::InvalidInput(format!(
                "SSS profile '{}': units_per_mm must be finite and > 0",
                self.name
            )));
        }
        Ok(())
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
            if let ThicknessSource::Constant(c) = t.thickness {
                if !(0.0..=1.0).contains(&c) {
                    return bad(format!("thickness {c} must be in [0, 1]"));
                }
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
