//! Diffusion profiles as sums of Gaussians (d'Eon and Luebke): evaluating one at a radius,
//! normalising its weights, and fitting a sum of Gaussians to any radial profile (how the
//! `marble` preset was made from Jensen's dipole, and how `--sss-gaussians N` refits a profile
//! with fewer blur steps); and Christensen and Burley's normalized diffusion (the 2-D Burley
//! blur's profile, its exact radial CDF inverse, the albedo fits and a sum of Gaussians fitted
//! to it). CPU math of the materials; the f64 reference and the frame both use it.

use std::f64::consts::PI;
use std::path::PathBuf;

use glam::{DVec3, Vec3};

use super::layered::{dipole_constants, LayeredMedium};
use crate::{LucentError, Result};

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

/// Each Gaussian's weight, normalised per channel so the weights sum to 1 (as the blurs
/// normalise them); a channel whose weights are all 0 keeps its light where it is, which the
/// first Gaussian then takes whole.
pub fn normalized_weights(profile: &SssProfile) -> Vec<DVec3> {
    let total = profile
        .gaussians
        .iter()
        .fold(DVec3::ZERO, |acc, g| acc + g.weight.as_dvec3());
    profile
        .gaussians
        .iter()
        .enumerate()
        .map(|(i, g)| {
            DVec3::select(
                total.cmpgt(DVec3::ZERO),
                g.weight.as_dvec3() / total.max(DVec3::splat(1e-300)),
                DVec3::splat(if i == 0 { 1.0 } else { 0.0 }),
            )
        })
        .collect()
}

/// `R(r)` of a profile at `r_mm` millimetres, per channel, with [`normalized_weights`].
pub fn profile_value(profile: &SssProfile, r_mm: f64) -> DVec3 {
    profile
        .gaussians
        .iter()
        .zip(normalized_weights(profile))
        .fold(DVec3::ZERO, |sum, (g, w)| {
            let v = f64::from(g.variance).max(1e-12);
            sum + w * ((-r_mm * r_mm / (2.0 * v)).exp() / (2.0 * std::f64::consts::PI * v))
        })
}

/// The normalised 2D Gaussian of variance `v` at radius `r`: exp(-r²/2v) / (2πv).
pub fn gaussian(v: f64, r: f64) -> f64 {
    (-r * r / (2.0 * v)).exp() / (2.0 * PI * v)
}

/// Non-negative weights w minimising ∫ (profile(r) - Σ w_i G(v_i, r))² 2πr dr over [0, r_max]
/// (area-weighted, as the profile is applied over the plane). Returns the weights and the
/// relative L2 error of the fit.
pub fn fit_sum_of_gaussians(
    variances: &[f64],
    profile: impl Fn(f64) -> f64,
    r_max: f64,
) -> (Vec<f64>, f64) {
    let n = variances.len();
    let samples = 4000;
    let dr = r_max / samples as f64;
    // Normal equations H w = b by midpoint quadrature.
    let mut h = vec![vec![0.0; n]; n];
    let mut b = vec![0.0; n];
    let mut norm = 0.0;
    for s in 0..samples {
        let r = (s as f64 + 0.5) * dr;
        let area = 2.0 * PI * r * dr;
        let p = profile(r);
        let g: Vec<f64> = variances.iter().map(|&v| gaussian(v, r)).collect();
        for i in 0..n {
            b[i] += g[i] * p * area;
            for j in 0..n {
                h[i][j] += g[i] * g[j] * area;
            }
        }
        norm += p * p * area;
    }
    // Projected coordinate descent: the problem is a convex quadratic with w >= 0.
    let mut w = vec![0.0; n];
    for _ in 0..20_000 {
        for i in 0..n {
            let grad: f64 = (0..n).map(|j| h[i][j] * w[j]).sum::<f64>() - b[i];
            if h[i][i] > 0.0 {
                w[i] = (w[i] - grad / h[i][i]).max(0.0);
            }
        }
    }
    let residual: f64 = {
        let mut e = norm;
        for i in 0..n {
            e -= 2.0 * w[i] * b[i];
            for j in 0..n {
                e += w[i] * w[j] * h[i][j];
            }
        }
        e.max(0.0)
    };
    (w, (residual / norm.max(1e-300)).sqrt())
}

/// `profile` refitted with `n` Gaussians (1 to 8): variances spaced geometrically between the
/// profile's narrowest and widest, weights per channel by non-negative least squares against
/// the profile's radial shape (area-weighted, out to 4 sigma of the widest), normalised per
/// channel. Returns it with the fit's relative L2 error per channel. `n` at or above the
/// profile's own count returns the profile unchanged (error 0).
pub fn fit_profile(profile: &SssProfile, n: usize) -> Result<(SssProfile, [f64; 3])> {
    if !(1..=8).contains(&n) {
        return Err(crate::LucentError::InvalidInput(format!(
            "--sss-gaussians {n}: 1 to 8 Gaussians are supported"
        )));
    }
    if n >= profile.gaussians.len() {
        return Ok((profile.clone(), [0.0; 3]));
    }
    let variances: Vec<f64> = profile
        .gaussians
        .iter()
        .map(|g| f64::from(g.variance).max(1e-9))
        .collect();
    let (lo, hi) = variances
        .iter()
        .fold((f64::MAX, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let fitted: Vec<f64> = (0..n)
        .map(|k| {
            if n == 1 {
                (lo * hi).sqrt()
            } else {
                (lo.ln() + (hi.ln() - lo.ln()) * k as f64 / (n - 1) as f64).exp()
            }
        })
        .collect();
    let r_max = 4.0 * hi.sqrt();
    let mut weights = vec![glam::Vec3::ZERO; n];
    let mut errors = [0.0; 3];
    for c in 0..3 {
        let target = |r: f64| profile_value(profile, r)[c];
        let (w, err) = fit_sum_of_gaussians(&fitted, target, r_max);
        let total: f64 = w.iter().sum();
        for (i, wi) in w.iter().enumerate() {
            weights[i][c] = if total > 0.0 {
                (wi / total) as f32
            } else {
                0.0
            };
        }
        errors[c] = err;
    }
    let refit = SssProfile {
        name: format!("{} ({n} Gaussians)", profile.name),
        gaussians: fitted
            .iter()
            .zip(weights)
            .map(|(&v, weight)| Gaussian {
                variance: v as f32,
                weight,
            })
            .collect(),
        units_per_mm: profile.units_per_mm,
        blur: profile.blur.clone(),
        burley: profile.burley,
        texturing: profile.texturing,
    };
    Ok((refit, errors))
}

/// Gaussians a medium's profile is fitted with (the skin and marble presets' count).
pub const MEDIUM_GAUSSIANS: usize = 6;

/// The screen-space SSS profile of a medium (`[material.medium]`, its first layer taken as
/// semi-infinite), for a material the frame's SSS technique renders without a
/// `[material.sss]` of its own: [`MEDIUM_GAUSSIANS`] Gaussians fitted per channel to Jensen's
/// dipole `Rd(r)` (the model `[material.medium]`'s albedo integrates: the weights are
/// normalised per channel, the albedo carries `R_d`), by area-weighted non-negative least
/// squares, variances spaced geometrically from half the shallowest real source's depth
/// `z_r = 1 / sigma_t'` to three diffusion lengths `1 / sigma_tr` of the widest channel (at
/// most 300 transport mean free paths: a medium that absorbs nothing diffuses without end);
/// and Burley's normalized diffusion from the medium's diffuse mean free path `1 / sigma_t'`
/// with `albedo`, its white-sky albedo ([`LayeredMedium::white_sky_albedo`]; Christensen and
/// Burley's surface albedo is a Monte Carlo total reflectance too). Returns the profile and the
/// fit's relative L2 error per channel (`inspect` prints it).
pub fn medium_profile(medium: &LayeredMedium, albedo: glam::Vec3) -> (SssProfile, [f64; 3]) {
    let layer = &medium.layers[0];
    let (sp, sa) = (layer.sigma_s_prime(), layer.sigma_a);
    let dipoles: Vec<_> = (0..3)
        .map(|c| dipole_constants(f64::from(sp[c]), f64::from(sa[c]), f64::from(medium.eta)))
        .collect();
    // Lengths in mm. z_r is finite (sigma_t' is held above a floor); sigma_tr may be 0.
    let narrow = dipoles.iter().map(|d| d.z_r).fold(f64::MAX, f64::min);
    let widest_z_r = dipoles.iter().map(|d| d.z_r).fold(0.0, f64::max);
    let reach = dipoles
        .iter()
        .map(|d| (3.0 / d.sigma_tr.max(1e-300)).min(300.0 * widest_z_r))
        .fold(0.0, f64::max)
        .max(narrow);
    let (lo, hi) = ((0.5 * narrow).powi(2), reach.powi(2));
    let n = MEDIUM_GAUSSIANS;
    let variances: Vec<f64> = (0..n)
        .map(|k| (lo.ln() + (hi.ln() - lo.ln()) * k as f64 / (n - 1) as f64).exp())
        .collect();
    let mut weights = vec![glam::Vec3::ZERO; n];
    let mut errors = [0.0; 3];
    for (c, dipole) in dipoles.iter().enumerate() {
        let (w, err) = fit_sum_of_gaussians(&variances, |r| dipole.rd(r), 4.0 * hi.sqrt());
        let total: f64 = w.iter().sum();
        for (i, wi) in w.iter().enumerate() {
            // A channel that scatters nothing (all weights 0) keeps the pixel's own light.
            weights[i][c] = if total > 0.0 {
                (wi / total) as f32
            } else if i == 0 {
                1.0
            } else {
                0.0
            };
        }
        errors[c] = err;
    }
    let mfp = glam::Vec3::new(
        dipoles[0].z_r as f32,
        dipoles[1].z_r as f32,
        dipoles[2].z_r as f32,
    );
    let profile = SssProfile {
        name: format!("{} (fitted to its dipole)", medium.name),
        gaussians: variances
            .iter()
            .zip(weights)
            .map(|(&v, weight)| Gaussian {
                variance: v as f32,
                weight,
            })
            .collect(),
        units_per_mm: medium.units_per_mm,
        blur: None,
        burley: Some(BurleyDistance::MeanFreePath { mfp, albedo }),
        texturing: Texturing::default(),
    };
    (profile, errors)
}

/// Christensen and Burley's (2015) fits of the scaling `s` of the normalized diffusion profile
/// from the surface albedo `A`, for a shape given as a mean free path `l` (`d = l / s`). Their
/// relative errors against Monte Carlo are a few percent; which one is right for a material
/// is what the path-traced truth decides, so all three stay one knob away (`--burley-fit`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BurleyFit {
    /// Searchlight configuration (their eq. 6, with the diffuse mean free path): `s = 3.5 +
    /// 100 (A - 0.33)^4`, Unreal's choice.
    #[default]
    Searchlight,
    /// Diffuse surface transmission (eq. 5): `s = 1.9 - A + 3.5 (A - 0.8)^2`, EEVEE's.
    Diffuse,
    /// Perpendicular incidence (eq. 3): `s = 1.85 - A + 7 |A - 0.8|^3`.
    Perpendicular,
}

impl BurleyFit {
    /// Every fit with its command-line name.
    pub const ALL: &'static [(&'static str, BurleyFit)] = &[
        ("searchlight", BurleyFit::Searchlight),
        ("diffuse", BurleyFit::Diffuse),
        ("perpendicular", BurleyFit::Perpendicular),
    ];

    /// `s` for albedo `a` (clamped to [0, 1]: every fit is positive there).
    pub fn scale(self, a: f64) -> f64 {
        let a = a.clamp(0.0, 1.0);
        match self {
            BurleyFit::Searchlight => 3.5 + 100.0 * (a - 0.33).powi(4),
            BurleyFit::Diffuse => 1.9 - a + 3.5 * (a - 0.8).powi(2),
            BurleyFit::Perpendicular => 1.85 - a + 7.0 * (a - 0.8).abs().powi(3),
        }
    }
}

/// Smallest and largest Burley `d` (mm) lucent accepts: below, the profile is far narrower
/// than any pixel; above, wider than any scene (the blur clamps its reach on screen anyway).
pub const BURLEY_D_RANGE: (f32, f32) = (1e-4, 1e3);

/// Burley's 2-D profile with shape `d` (mm) at radius `r` (mm), normalised to integrate to 1
/// over the plane: `(e^(-r/d) + e^(-r/3d)) / (8 pi d r)`. Infinite at `r = 0` (integrable).
pub fn burley_profile(d: f64, r: f64) -> f64 {
    let d = d.max(1e-12);
    ((-r / d).exp() + (-r / (3.0 * d)).exp()) / (8.0 * PI * d * r)
}

/// The fraction of Burley's profile within radius `r` (mm) of its centre:
/// `1 - e^(-r/d) / 4 - 3 e^(-r/3d) / 4`.
pub fn burley_cdf(d: f64, r: f64) -> f64 {
    let d = d.max(1e-12);
    1.0 - 0.25 * (-r / d).exp() - 0.75 * (-r / (3.0 * d)).exp()
}

/// The radius (in units of `d`) within which a fraction `xi` in [0, 1) of Burley's profile
/// lies: the exact inverse of [`burley_cdf`] (Golubev): with `u = 1 - xi` and
/// `G = 1 + 4 u (2 u + sqrt(1 + 4 u^2))`, `r / d = 3 ln((1 + G^(-1/3) + G^(1/3)) / (4 u))`.
pub fn burley_radius(xi: f64) -> f64 {
    // Guarded: u -> 0 sends the radius to infinity; 1e-7 is past any reach the blur uses.
    let u = (1.0 - xi).clamp(1e-7, 1.0);
    let g = 1.0 + 4.0 * u * (2.0 * u + (1.0 + 4.0 * u * u).sqrt());
    let third = g.cbrt();
    3.0 * ((1.0 + 1.0 / third + third) / (4.0 * u)).ln()
}

/// The fraction of the profile the blur gathers: out to [`BURLEY_REACH`] `d` (HDRP's cut,
/// 99.7% of the energy).
pub const BURLEY_REACH: f64 = 16.56;

impl SssProfile {
    /// Burley's `d` per channel (mm) for this profile: as its material gives it
    /// ([`BurleyDistance`], a mean free path through `fit`), or matched to its Gaussians'
    /// second moment (`E[r^2] = 14 d^2` for Burley's profile, `2 v` for a 2-D Gaussian), so a
    /// preset renders with Burley at the width the other blurs give it.
    pub fn burley_d(&self, fit: BurleyFit) -> DVec3 {
        let (lo, hi) = (f64::from(BURLEY_D_RANGE.0), f64::from(BURLEY_D_RANGE.1));
        let d = match self.burley {
            Some(BurleyDistance::Scattering(d)) => d.as_dvec3(),
            Some(BurleyDistance::MeanFreePath { mfp, albedo }) => {
                let a = albedo.as_dvec3();
                mfp.as_dvec3() / DVec3::new(fit.scale(a.x), fit.scale(a.y), fit.scale(a.z))
            }
            None => {
                let weights = normalized_weights(self);
                let moment = self
                    .gaussians
                    .iter()
                    .zip(&weights)
                    .fold(DVec3::ZERO, |m, (g, w)| {
                        m + *w * 2.0 * f64::from(g.variance)
                    });
                (moment / 14.0).max(DVec3::ZERO).map(f64::sqrt)
            }
        };
        // Guarded: a NaN or out-of-range d (only reachable from code, the scene file checks
        // its keys) is held to the range the blur's table is built for.
        DVec3::new(d.x, d.y, d.z).map(|v| if v.is_finite() { v.clamp(lo, hi) } else { lo })
    }
}

/// Six Gaussians fitted to Burley's profile of `d` per channel (mm), weights per channel by
/// non-negative least squares (area-weighted, out to [`BURLEY_REACH`] `d`), normalised: what
/// the Gaussian blurs render a material that gives only Burley's distances with.
pub fn burley_gaussians(d: DVec3) -> Vec<Gaussian> {
    let (lo, hi) = (d.min_element().max(1e-6), d.max_element().max(1e-6));
    // From a fifth of the narrowest d to eight times the widest, geometrically: the
    // e^(-r/3d) tail carries most of the second moment, and narrower Gaussians drop it.
    let (v_lo, v_hi) = ((0.2 * lo).powi(2), (8.0 * hi).powi(2));
    let n = 6;
    let variances: Vec<f64> = (0..n)
        .map(|k| (v_lo.ln() + (v_hi.ln() - v_lo.ln()) * k as f64 / (n - 1) as f64).exp())
        .collect();
    let mut weights = vec![glam::Vec3::ZERO; n];
    for c in 0..3 {
        let dc = d[c].max(1e-6);
        let (w, _) = fit_sum_of_gaussians(
            &variances,
            |r| burley_profile(dc, r.max(1e-9)),
            BURLEY_REACH * dc,
        );
        let total: f64 = w.iter().sum();
        for (i, wi) in w.iter().enumerate() {
            weights[i][c] = if total > 0.0 {
                (wi / total) as f32
            } else {
                1.0 / n as f32
            };
        }
    }
    variances
        .iter()
        .zip(weights)
        .map(|(&v, weight)| Gaussian {
            variance: v as f32,
            weight,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_medium_s_profile_stays_valid_at_extreme_media() {
        // The stability sweep's extremes: coefficients 0 to 1e6 mm^-1, albedo -> 1 (no
        // absorption), g +-0.999, eta 1 and 2.5: a profile that validates (finite, positive
        // variances, weights summing to 1) and a finite fit error, never NaN.
        for sp in [0.0f32, 1e-6, 1.0, 1e6] {
            for sa in [0.0f32, 1e-6, 1.0, 1e6] {
                for g in [-0.999f32, 0.0, 0.999] {
                    for eta in [1.0f32, 2.5] {
                        let medium = LayeredMedium::homogeneous(
                            "x",
                            glam::Vec3::splat(sp),
                            glam::Vec3::splat(sa),
                            g,
                            eta,
                        );
                        let (profile, errors) = medium_profile(&medium, medium.white_sky_albedo());
                        let case = format!("sigma_s' {sp}, sigma_a {sa}, g {g}, eta {eta}");
                        profile.validate().unwrap_or_else(|e| panic!("{case}: {e}"));
                        assert!(errors.iter().all(|e| e.is_finite()), "{case}: {errors:?}");
                        let sum = profile
                            .gaussians
                            .iter()
                            .fold(glam::Vec3::ZERO, |s, g| s + g.weight);
                        assert!(
                            (sum - glam::Vec3::ONE).abs().max_element() < 1e-4,
                            "{case}: {sum}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_medium_s_profile_is_its_dipole_in_six_gaussians() {
        // Every single-layer preset at eta 1 and 1.3: a valid profile, weights summing to 1 per
        // channel, the fit within 20% (relative L2, area-weighted) of the dipole it stands for
        // (measured: 0.6-6% for skin, marble, apple, milk, potato, ketchup, chicken; 7-13% for
        // cream; 11-16% for spectralon, which absorbs almost nothing: its dipole spans more than
        // six Gaussians spaced over 300 mean free paths cover).
        for name in crate::scene::layered::preset_names() {
            let Ok(mut medium) = LayeredMedium::preset(name) else {
                continue;
            };
            if medium.layers.len() != 1 {
                continue;
            }
            for eta in [1.0, 1.3] {
                medium.eta = eta;
                let (profile, errors) = medium_profile(&medium, medium.white_sky_albedo());
                profile.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
                let sum = profile
                    .gaussians
                    .iter()
                    .fold(glam::Vec3::ZERO, |s, g| s + g.weight);
                assert!(
                    (sum - glam::Vec3::ONE).abs().max_element() < 1e-4,
                    "{name}: {sum}"
                );
                println!("{name} eta {eta}: fit error {errors:.3?}");
                assert!(
                    errors.iter().all(|&e| e < 0.2),
                    "{name} eta {eta}: {errors:?}"
                );
                let Some(BurleyDistance::MeanFreePath { mfp, albedo }) = profile.burley else {
                    panic!("{name}: no Burley distance");
                };
                assert_eq!(albedo, medium.white_sky_albedo());
                let expected = 1.0 / (medium.layers[0].sigma_s_prime() + medium.layers[0].sigma_a);
                assert!((mfp - expected).abs().max_element() < 1e-4 * expected.max_element());
            }
        }
    }

    #[test]
    fn fitting_fewer_gaussians_reports_a_growing_error() {
        let skin = SssProfile::preset("skin").unwrap();
        let (same, e) = fit_profile(&skin, 6).unwrap();
        assert_eq!(same, skin);
        assert_eq!(e, [0.0; 3]);
        let mut previous = 0.0;
        for n in [4, 3, 2, 1] {
            let (fit, e) = fit_profile(&skin, n).unwrap();
            assert_eq!(fit.gaussians.len(), n);
            fit.validate().unwrap();
            let worst = e.iter().fold(0.0f64, |a, &b| a.max(b));
            assert!(worst.is_finite() && worst >= previous - 1e-9, "{n}: {e:?}");
            previous = worst;
            for c in 0..3 {
                let total: f32 = fit.gaussians.iter().map(|g| g.weight[c]).sum();
                assert!((total - 1.0).abs() < 1e-4, "{n} channel {c}: {total}");
            }
        }
        // Four Gaussians (the thesis's count) fit d'Eon's six within a few percent.
        let (_, e4) = fit_profile(&skin, 4).unwrap();
        assert!(e4.iter().all(|&e| e < 0.05), "{e4:?}");
        assert!(fit_profile(&skin, 0).is_err() && fit_profile(&skin, 9).is_err());
    }

    #[test]
    fn burley_cdf_inverse_is_exact_and_the_profile_integrates_to_one() {
        for xi in [0.0, 0.1, 0.5, 0.9, 0.99, 0.997] {
            let r = burley_radius(xi);
            assert!((burley_cdf(1.0, r) - xi).abs() < 1e-9, "{xi}: {r}");
        }
        // HDRP's cut: 16.56 d holds 99.7% of the profile.
        assert!((burley_cdf(1.0, BURLEY_REACH) - 0.997).abs() < 1e-3);
        // Midpoint quadrature of 2 pi r R(r) against the closed-form CDF.
        let (d, r_max, steps) = (0.7, 5.0, 200_000);
        let dr = r_max / steps as f64;
        let total: f64 = (0..steps)
            .map(|k| {
                let r = (k as f64 + 0.5) * dr;
                2.0 * PI * r * burley_profile(d, r) * dr
            })
            .sum();
        assert!((total - burley_cdf(d, r_max)).abs() < 1e-6, "{total}");
        // Extreme xi stays finite.
        assert!(burley_radius(1.0).is_finite() && burley_radius(-1.0).is_finite());
    }

    #[test]
    fn burley_d_matches_the_gaussians_second_moment_and_the_fits() {
        // One Gaussian of variance v: E[r^2] = 2 v = 14 d^2.
        let one = SssProfile {
            gaussians: vec![Gaussian {
                variance: 7.0,
                weight: glam::Vec3::ONE,
            }],
            ..SssProfile::preset("skin").unwrap()
        };
        let d = one.burley_d(BurleyFit::Searchlight);
        assert!((d - DVec3::ONE).abs().max_element() < 1e-6, "{d}");
        // Skin: red scatters farthest.
        let skin = SssProfile::preset("skin")
            .unwrap()
            .burley_d(BurleyFit::Searchlight);
        assert!(skin.x > skin.y && skin.y > skin.z, "{skin}");
        let mfp = SssProfile {
            burley: Some(BurleyDistance::MeanFreePath {
                mfp: glam::Vec3::splat(2.0),
                albedo: glam::Vec3::new(0.0, 0.5, 1.0),
            }),
            ..one.clone()
        };
        for (_, fit) in BurleyFit::ALL {
            let d = mfp.burley_d(*fit);
            assert!(d.is_finite() && d.min_element() > 0.0, "{fit:?}: {d}");
        }
        // Searchlight at A = 0.33: s = 3.5.
        assert!((BurleyFit::Searchlight.scale(0.33) - 3.5).abs() < 1e-12);
        // The fitted Gaussians carry the profile's width.
        let gaussians = burley_gaussians(DVec3::new(1.0, 0.5, 0.25));
        let fitted = SssProfile {
            gaussians,
            burley: None,
            ..one
        };
        fitted.validate().unwrap();
        let back = fitted.burley_d(BurleyFit::Searchlight);
        assert!(
            (back.x - 1.0).abs() < 0.25 && back.z < back.y && back.y < back.x,
            "{back}"
        );
    }
}
