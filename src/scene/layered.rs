//! Li et al.'s (2009) layered translucent media: what a layered material is made of, in
//! physical units, and the constants the GPU passes derive from it.
//!
//! A [`LayeredMedium`] is 1 to [`MAX_LAYERS`] planar layers, outermost first. Each [`Layer`]
//! has RGB absorption `sigma_a` and scattering `sigma_s` in mm^-1, a Henyey-Greenstein
//! anisotropy `g` and a [`Thickness`]: a constant in mm, read per texel from a float texture
//! (the paper's `TexDep`: four layers per RGBA texture, layer `i` reads channel `i % 4` of
//! texture `i / 4`), or the semi-infinite rest of the object (last layer only). The medium adds
//! the relative index of refraction `eta`, the five weights of the paper's eq. 3
//! (`lambda_1..lambda_5`: diffuse, specular, transmitted, single and multiple scattering) and
//! `units_per_mm`, which turns the physical coefficients into the scene's units.
//!
//! Multiple scattering (eqs. 12-13) uses only the first layer, as the paper does:
//! [`LayeredMedium::dipole_constants`] gives Jensen's dipole constants per channel ([`Dipole`]
//! in f64, whose profile `Rd(r)` the reference evaluates: `crate::reference::dipole`). Single
//! scattering (eqs. 4-11) attenuates through every layer: [`LayeredMedium::sigma_t_per_unit`].
//!
//! # Presets
//!
//! [`JENSEN_2001`] is Jensen et al.'s 2001 table of measured media (the same numbers as pbrt-v3's
//! `src/core/medium.cpp`): reduced scattering `sigma_s'` and absorption `sigma_a` in mm^-1, so
//! each preset is one semi-infinite layer with `g = 0` (`sigma_s = sigma_s'`) and `eta = 1.3`.
//! Li et al.'s Table 1 lists three "layers" per object; they are Jensen's R, G, B columns of one
//! homogeneous material:
//!
//! | Table 1 object | preset | note |
//! |---|---|---|
//! | deformed frog, goddess, monster | `apple` | exact |
//! | teapot | `skin1` | Li's blue `sigma_a` is 0.18, Jensen's 0.48: `li-teapot` keeps Li's |
//! | bunny | `chicken1` | exact |
//! | Maitreya, Happy Buddha | `skin2` | exact |
//! | dragon | `skimmilk` | exact |
//!
//! `skin-layered` is a real two-layer stack: Donner & Jensen's (2005) layered skin structure,
//! epidermis over dermis, with the parameters of the public `patwonder/pbrt-v2-skin` renderer
//! (`scenes/skin.pbrt`: epidermis 0.25 mm, index 1.4, melanin fraction 0.008 of which 0.6
//! eumelanin, blood fraction 0.009 at 0.8 oxygenation; `src/materials/skincoeffs.h`: Jacques'
//! skin-optics formulas, g = 0.9 epidermis and 0.8 dermis), evaluated at 650, 550 and 450 nm for
//! R, G and B and converted from cm^-1 to mm^-1. The source's dermis is 20 mm thick; here it is
//! the semi-infinite rest.

use glam::Vec3;

use super::texture::{Texture, TextureSource, TextureUsage};
use crate::{LucentError, Result};

/// Most layers a medium may have (two RGBA depth textures).
pub const MAX_LAYERS: usize = 8;

/// Largest |g| accepted: HG and Schlick's phase functions peak like 1/(1 - |g|)^2, so |g| = 1
/// is a delta and 0.999 already a 4e6:1 peak (defined beside the phase function,
/// [`crate::scene::albedo::henyey_greenstein`]).
pub use crate::scene::albedo::MAX_ABS_G;

/// Li et al.'s eq. 3 weights of their Fig. 4 (diffuse, specular, transmitted, single, multiple).
pub const DEFAULT_WEIGHTS: [f32; 5] = [0.3, 0.3, 0.05, 0.05, 0.03];

/// Eq. 3's weights read physically: `λ1 = 0` because the dipole's multiple scattering *is* a
/// translucent medium's diffuse reflection (Lambert on top would count it twice), and every
/// other term at its own radiance. The paper's [`DEFAULT_WEIGHTS`] darken an object to 30% of
/// its Lambert diffuse plus 3-5% of the scattering terms; the built-in layered scenes use
/// these instead.
pub const PHYSICAL_WEIGHTS: [f32; 5] = [0.0, 1.0, 1.0, 1.0, 1.0];

/// Scene units per millimetre when a scene names none: 0.04, so a built-in object about one unit
/// across is 25 mm, a few centimetres (a fruit or a figurine).
pub const DEFAULT_UNITS_PER_MM: f32 = 0.04;

/// Largest coefficient accepted (mm^-1): Spectralon's 20 mm^-1 is the densest measured medium of
/// the table; 1e6 keeps every product with a thickness or a distance far from overflow in f32.
pub const MAX_COEFFICIENT: f32 = 1e6;

/// Scene units per millimetre accepted: a micrometre to a kilometre per unit. Beyond, a
/// coefficient of [`MAX_COEFFICIENT`] mm^-1 divided by `units_per_mm` overflows f32 (the
/// layered sweep found NaN in the dipole at 1e-33).
pub const UNITS_PER_MM_RANGE: std::ops::RangeInclusive<f32> = 1e-6..=1e6;

/// Smallest `1 - g` used when converting `sigma_s'` to `sigma_s` (the guard of
/// [`sigma_s_from_reduced`]): `g` is clamped to [`MAX_ABS_G`] first, so this is `1 - 0.999`.
const MIN_ONE_MINUS_G: f32 = 1.0 - MAX_ABS_G;

/// How thick a layer is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Thickness {
    /// The same thickness everywhere, in mm (>= 0; 0 is a layer that is not there).
    Mm(f32),
    /// Per texel: layer `i` reads channel `i % 4` of depth texture `i / 4`, times `scale` mm per
    /// texel unit (a float texture storing mm has `scale` 1).
    Texture {
        /// mm per texel unit (> 0).
        scale: f32,
    },
    /// The rest of the object: a semi-infinite layer (last layer only). Written `"rest"` in scene
    /// files.
    Rest,
}

/// One layer of a layered medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    /// Absorption coefficient per channel, mm^-1.
    pub sigma_a: Vec3,
    /// Scattering coefficient per channel, mm^-1 (not reduced).
    pub sigma_s: Vec3,
    /// Henyey-Greenstein anisotropy, |g| <= [`MAX_ABS_G`].
    pub g: f32,
    /// How thick it is.
    pub thickness: Thickness,
}

impl Layer {
    /// Reduced scattering `sigma_s' = sigma_s (1 - g)`, mm^-1.
    pub fn sigma_s_prime(&self) -> Vec3 {
        self.sigma_s * (1.0 - self.g.clamp(-MAX_ABS_G, MAX_ABS_G))
    }

    /// Extinction `sigma_t = sigma_a + sigma_s`, mm^-1.
    pub fn sigma_t(&self) -> Vec3 {
        self.sigma_a + self.sigma_s
    }
}

/// `sigma_s = sigma_s' / (1 - g)`, with `g` clamped to |g| <= [`MAX_ABS_G`] so the division
/// is by at least 0.001 (g -> 1 would divide by zero).
pub fn sigma_s_from_reduced(sigma_s_prime: Vec3, g: f32) -> Vec3 {
    let one_minus_g = (1.0 - g.clamp(-MAX_ABS_G, MAX_ABS_G)).max(MIN_ONE_MINUS_G);
    sigma_s_prime / one_minus_g
}

/// Diffuse Fresnel reflectance of a boundary with relative index `eta` (Jensen's fit). The fit
/// gives 0.0014 at `eta` = 1, where there is no boundary: `eta` = 1 returns 0 exactly (as
/// Mitsuba forces it), so the dipole's `A` is exactly 1.
///
/// Jensen's polynomial is a fit for `eta > 1` (it goes negative below 0.9993: -3.6 at 0.5);
/// below 1 the fit for a medium less dense than its surroundings is used instead (Egan and
/// Hilgeman 1979, as in Jensen's dipole literature): `-0.4399 + 0.7099/eta - 0.3319/eta^2 +
/// 0.0636/eta^3`. Both are clamped to [0, 0.999] (a reflectance; A stays finite).
pub fn fresnel_diffuse_reflectance(eta: f64) -> f64 {
    if eta == 1.0 {
        return 0.0;
    }
    let f = if eta > 1.0 {
        -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
    } else {
        -0.4399 + 0.7099 / eta - 0.3319 / (eta * eta) + 0.0636 / (eta * eta * eta)
    };
    if f.is_nan() {
        return 0.0;
    }
    f.clamp(0.0, 0.999)
}

/// Smallest `sigma_t'` used (1/length): `sigma_s' = sigma_a = 0` is a vacuum, where `z_r =
/// 1/sigma_t'` would be infinite; 1e-12 keeps every constant finite and Rd ~ 0.
const MIN_SIGMA_T_PRIME: f64 = 1e-12;

/// Jensen's dipole constants for one channel (lengths and coefficients in the caller's unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dipole {
    /// `sigma_t' = sigma_s' + sigma_a` (clamped to at least 1e-12).
    pub sigma_t_prime: f64,
    /// Effective transport coefficient `sqrt(3 sigma_a sigma_t')`.
    pub sigma_tr: f64,
    /// Reduced albedo `sigma_s' / sigma_t'`, in [0, 1].
    pub alpha_prime: f64,
    /// Depth of the real source, `1 / sigma_t'`.
    pub z_r: f64,
    /// Height of the virtual source, `z_r (1 + 4A/3)`.
    pub z_v: f64,
    /// Diffuse Fresnel reflectance (0 at `eta` = 1).
    pub f_dr: f64,
    /// `A = (1 + F_dr) / (1 - F_dr)`.
    pub a: f64,
}

/// The dipole constants for reduced scattering `sigma_s_prime` and absorption `sigma_a` (same
/// unit, clamped to >= 0) and relative index `eta` (> 0).
pub fn dipole_constants(sigma_s_prime: f64, sigma_a: f64, eta: f64) -> Dipole {
    let (sp, sa) = (sigma_s_prime.max(0.0), sigma_a.max(0.0));
    let sigma_t_prime = (sp + sa).max(MIN_SIGMA_T_PRIME);
    let f_dr = fresnel_diffuse_reflectance(eta);
    // F_dr < 1 for every eta > 0.03 or so; clamp so A stays finite for absurd indices.
    let f_dr_safe = f_dr.min(0.999);
    let a = (1.0 + f_dr_safe) / (1.0 - f_dr_safe);
    let z_r = 1.0 / sigma_t_prime;
    Dipole {
        sigma_t_prime,
        sigma_tr: (3.0 * sa * sigma_t_prime).sqrt(),
        alpha_prime: sp / sigma_t_prime,
        z_r,
        z_v: z_r * (1.0 + 4.0 * a / 3.0),
        f_dr,
        a,
    }
}

/// How Li et al.'s terms share a medium's albedo under a white sky
/// ([`LayeredMedium::albedo_split`]; issue 37). Jensen's dipole counts every order of
/// scattering, the first too, so beside single scattering its `R_d` reflects more light than
/// the medium does (skin1: 0.743 / 0.462 / 0.300 of a white sky against 0.625 / 0.385 /
/// 0.241); the gather scales the dipole's profile to what single scattering leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlbedoSplit {
    /// `c`: the share of a white sky's light the boundary lets in
    /// ([`crate::scene::albedo::diffuse_transmittance`]), which is also how light leaving
    /// diffusely is spread, `F_t(mu_o) / (pi c)`. At least 1e-3.
    pub diffuse_transmittance: f32,
    /// `S` per channel: the first layer's single scattering under a white sky
    /// ([`crate::scene::albedo::single_scattering_white_sky_albedo`] with its `sigma_s /
    /// sigma_t`, `g` and the medium's `eta`). Li et al.'s march takes the lights; the
    /// ambient's share is this.
    pub single: Vec3,
    /// `k = (A - S) / c^2` per channel, what multiple scattering scales the dipole's profile
    /// to: the radiance it sends out is `F_t(mu_o) / pi` times `k` times the Rd-weighted
    /// mean of the irradiance that entered. `A` is the white-sky albedo
    /// ([`LayeredMedium::white_sky_albedo`]); `c^2` because the entering irradiance has
    /// already passed the boundary once and the light leaving is spread as `F_t / (pi c)`.
    pub multiple_scale: Vec3,
}

/// Jensen's dipole constants for one medium, per channel, in scene units (lengths in units,
/// coefficients in 1/unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DipoleConstants {
    /// Effective transport coefficient `sqrt(3 sigma_a sigma_t')`, 1/unit.
    pub sigma_tr: Vec3,
    /// Depth of the real source `1 / sigma_t'`, units.
    pub z_r: Vec3,
    /// Height of the virtual source `z_r (1 + 4A/3)`, units.
    pub z_v: Vec3,
    /// Reduced albedo `sigma_s' / sigma_t'`.
    pub alpha_prime: Vec3,
    /// Diffuse Fresnel reflectance (0 exactly when `eta` = 1).
    pub f_dr: f32,
    /// `A = (1 + F_dr) / (1 - F_dr)` (1 exactly when `eta` = 1).
    pub a: f32,
}

/// Reduced coefficients of a layer in 1/scene-unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedCoefficients {
    /// `sigma_s'`, 1/unit.
    pub sigma_s_prime: Vec3,
    /// `sigma_a`, 1/unit.
    pub sigma_a: Vec3,
    /// `sigma_t' = sigma_s' + sigma_a`, 1/unit.
    pub sigma_t_prime: Vec3,
}

/// A stack of layers, outermost first, with the surface's index and Li et al.'s weights.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredMedium {
    /// Preset name or "custom".
    pub name: String,
    /// Layers, outermost first (1 to [`MAX_LAYERS`]).
    pub layers: Vec<Layer>,
    /// Relative index of refraction at the surface (inside over outside, > 0; 1 = no boundary).
    pub eta: f32,
    /// Eq. 3's `lambda_1..lambda_5`: diffuse, specular, transmitted, single, multiple.
    pub weights: [f32; 5],
    /// Scene units per millimetre (> 0).
    pub units_per_mm: f32,
    /// `TexDep` textures: layer `i` with [`Thickness::Texture`] reads channel `i % 4` of
    /// texture `i / 4` (linear data).
    pub depth_textures: Vec<TextureSource>,
}

/// Jensen et al. 2001's measured media: (name, sigma_s' RGB, sigma_a RGB), mm^-1.
pub const JENSEN_2001: [(&str, [f32; 3], [f32; 3]); 12] = [
    ("apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    ("chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    ("cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("spectralon", [11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    ("wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
];

/// Li et al.'s teapot row: Jensen's skin1 with Li's blue absorption 0.18 (Jensen's is 0.48).
pub const LI_TEAPOT: ([f32; 3], [f32; 3]) = ([0.74, 0.88, 1.01], [0.032, 0.17, 0.18]);

/// `skin-layered` (see the module docs): (thickness mm, sigma_s' RGB, sigma_a RGB, g) per layer,
/// epidermis then dermis. Computed from the source's formulas at 650/550/450 nm.
pub const SKIN_LAYERED: [(Thickness, [f32; 3], [f32; 3], f32); 2] = [
    (
        Thickness::Mm(0.25),
        [4.6657, 5.8637, 8.7214],
        [0.2054, 0.3722, 0.8156],
        0.9,
    ),
    (
        Thickness::Rest,
        [2.3329, 2.9318, 4.3607],
        [0.0339, 0.2629, 0.4627],
        0.8,
    ),
];

/// Index of refraction of `skin-layered` (the source's 1.4).
pub const SKIN_LAYERED_ETA: f32 = 1.4;

/// Every preset name.
pub fn preset_names() -> Vec<&'static str> {
    JENSEN_2001
        .iter()
        .map(|p| p.0)
        .chain(["li-teapot", "skin-layered"])
        .collect()
}

impl LayeredMedium {
    /// One semi-infinite layer from reduced coefficients (mm^-1) with the defaults.
    pub fn homogeneous(name: &str, sigma_s_prime: Vec3, sigma_a: Vec3, g: f32, eta: f32) -> Self {
        Self {
            name: name.to_string(),
            layers: vec![Layer {
                sigma_a,
                sigma_s: sigma_s_from_reduced(sigma_s_prime, g),
                g,
                thickness: Thickness::Rest,
            }],
            eta,
            weights: DEFAULT_WEIGHTS,
            units_per_mm: DEFAULT_UNITS_PER_MM,
            depth_textures: Vec::new(),
        }
    }

    /// Jensen et al.'s total diffuse reflectance `R_d` of the first layer, taken as
    /// semi-infinite, at the medium's `eta`, per channel: the fraction of the light falling on a
    /// flat surface of it that leaves again, everywhere, diffusely (the dipole integrated over
    /// the plane, `crate::reference::dipole`): multiple scattering alone, in the diffusion
    /// approximation. What the layered passes' dipole integrates to; a Lambertian surface of
    /// the medium takes [`LayeredMedium::white_sky_albedo`] instead.
    pub fn total_diffuse_reflectance(&self) -> Vec3 {
        // In [0, 1] for every medium validate() accepts; clamped so an albedo stays one.
        Vec3::from(
            self.first_layer_dipoles()
                .map(|dipole| dipole.total_reflectance().clamp(0.0, 1.0) as f32),
        )
    }

    /// The white-sky albedo of the first layer, taken as semi-infinite, at the medium's `eta`,
    /// per channel: the fraction of the light falling on a flat surface of it from every
    /// direction that leaves again, single and multiple scattering together
    /// ([`crate::scene::albedo`]; exact for isotropic scattering behind an index-matched
    /// boundary). The albedo a Lambertian surface of this medium has: what `[material.medium]`
    /// gives a material that writes none. Above [`LayeredMedium::total_diffuse_reflectance`]
    /// (the dipole's, which misses single scattering and underestimates diffusion at moderate
    /// albedo): skin1 (0.625, 0.385, 0.241) against R_d (0.547, 0.291, 0.161).
    pub fn white_sky_albedo(&self) -> Vec3 {
        self.white_sky_albedo_at(self.eta)
    }

    /// [`LayeredMedium::white_sky_albedo`] behind a boundary of relative index `eta` instead
    /// of the medium's own (1: index-matched, what its reflectance's shape is normalised to).
    pub fn white_sky_albedo_at(&self, eta: f32) -> Vec3 {
        let r = self.first_layer_reduced();
        Vec3::from_array(std::array::from_fn(|c| {
            crate::scene::albedo::white_sky_albedo(
                f64::from(r.sigma_s_prime[c]),
                f64::from(r.sigma_a[c]),
                f64::from(eta),
            ) as f32
        }))
    }

    /// How Li et al.'s terms share this medium's albedo ([`AlbedoSplit`]). About 0.3 ms
    /// (the white-sky albedo's H-functions and single scattering's integral): computed once
    /// per material, not per frame or pixel.
    pub fn albedo_split(&self) -> AlbedoSplit {
        let eta = f64::from(self.eta);
        let c = crate::scene::albedo::diffuse_transmittance(eta);
        let (sigma_s, sigma_t) = (self.sigma_s_per_unit(0), self.sigma_t_per_unit(0));
        let g = f64::from(self.layers.first().map_or(0.0, |l| l.g));
        let per_albedo = crate::scene::albedo::single_scattering_per_albedo(g, eta);
        let single = Vec3::from_array(std::array::from_fn(|k| {
            // sigma_t 0 (a vacuum) scatters nothing: omega 0; so does a NaN ratio, which no
            // validated medium has.
            let ratio = f64::from(sigma_s[k] / sigma_t[k]);
            let omega = if sigma_t[k] > 0.0 && !ratio.is_nan() {
                ratio.clamp(0.0, 1.0)
            } else {
                0.0
            };
            (omega * per_albedo) as f32
        }));
        // c >= 0.75 or so for every eta a medium may have (c -> 0 only as eta -> inf).
        let c = c.max(1e-3);
        AlbedoSplit {
            diffuse_transmittance: c as f32,
            single,
            multiple_scale: (self.white_sky_albedo() - single).max(Vec3::ZERO) / (c * c) as f32,
        }
    }

    /// A preset by name (see the module docs): the Jensen 2001 media, `li-teapot` and
    /// `skin-layered`.
    pub fn preset(name: &str) -> Result<Self> {
        if let Some((_, sp, sa)) = JENSEN_2001.iter().find(|p| p.0 == name) {
            return Ok(Self::homogeneous(
                name,
                Vec3::from(*sp),
                Vec3::from(*sa),
                0.0,
                1.3,
            ));
        }
        match name {
            "li-teapot" => Ok(Self::homogeneous(
                name,
                Vec3::from(LI_TEAPOT.0),
                Vec3::from(LI_TEAPOT.1),
                0.0,
                1.3,
            )),
            "skin-layered" => Ok(Self {
                name: name.to_string(),
                layers: SKIN_LAYERED
                    .iter()
                    .map(|&(thickness, sp, sa, g)| Layer {
                        sigma_a: Vec3::from(sa),
                        sigma_s: sigma_s_from_reduced(Vec3::from(sp), g),
                        g,
                        thickness,
                    })
                    .collect(),
                eta: SKIN_LAYERED_ETA,
                weights: DEFAULT_WEIGHTS,
                units_per_mm: DEFAULT_UNITS_PER_MM,
                depth_textures: Vec::new(),
            }),
            _ => Err(LucentError::InvalidInput(format!(
                "unknown layered preset '{name}'; presets: {}",
                preset_names().join(", ")
            ))),
        }
    }

    /// Extinction `sigma_a + sigma_s` of layer `i` in 1/scene-unit.
    pub fn sigma_t_per_unit(&self, i: usize) -> Vec3 {
        self.layers[i].sigma_t() / self.units_per_mm
    }

    /// Scattering `sigma_s` of layer `i` in 1/scene-unit.
    pub fn sigma_s_per_unit(&self, i: usize) -> Vec3 {
        self.layers[i].sigma_s / self.units_per_mm
    }

    /// The first layer's reduced coefficients in 1/scene-unit (multiple scattering uses only
    /// the first layer, as Li et al. do).
    pub fn first_layer_reduced(&self) -> ReducedCoefficients {
        let l = &self.layers[0];
        let sigma_s_prime = l.sigma_s_prime() / self.units_per_mm;
        let sigma_a = l.sigma_a / self.units_per_mm;
        ReducedCoefficients {
            sigma_s_prime,
            sigma_a,
            sigma_t_prime: sigma_s_prime + sigma_a,
        }
    }

    /// The first layer's dipole per channel (R, G, B), in f64 and scene units: what
    /// [`LayeredMedium::dipole_constants`] rounds for the GPU, and what the references evaluate.
    pub fn first_layer_dipoles(&self) -> [Dipole; 3] {
        let r = self.first_layer_reduced();
        [0, 1, 2].map(|c| {
            dipole_constants(
                f64::from(r.sigma_s_prime[c]),
                f64::from(r.sigma_a[c]),
                f64::from(self.eta),
            )
        })
    }

    /// Jensen's dipole constants of the first layer per channel, in scene units (computed in
    /// f64 by [`dipole_constants`], which the reference's dipole profile evaluates too).
    pub fn dipole_constants(&self) -> DipoleConstants {
        let [x, y, z] = self.first_layer_dipoles();
        let v = |f: fn(&Dipole) -> f64| Vec3::new(f(&x) as f32, f(&y) as f32, f(&z) as f32);
        DipoleConstants {
            sigma_tr: v(|d| d.sigma_tr),
            z_r: v(|d| d.z_r),
            z_v: v(|d| d.z_v),
            alpha_prime: v(|d| d.alpha_prime),
            f_dr: x.f_dr as f32,
            a: x.a as f32,
        }
    }

    /// Thickness of layer `i` in mm; `texels` are the depth textures' texels at the point
    /// (texture `j` at `texels[j]`), needed only by [`Thickness::Texture`] layers (a missing
    /// texel reads 0). [`Thickness::Rest`] is infinite. Negative or non-finite texels read 0.
    pub fn thickness_mm(&self, i: usize, texels: &[[f32; 4]]) -> f32 {
        match self.layers[i].thickness {
            Thickness::Mm(t) => t,
            Thickness::Rest => f32::INFINITY,
            Thickness::Texture { scale } => {
                let v = texels.get(i / 4).map_or(0.0, |t| t[i % 4]);
                // A texel is data from a file: never let NaN or a negative depth through.
                if v.is_finite() {
                    v.max(0.0) * scale
                } else {
                    0.0
                }
            }
        }
    }

    /// Depth textures the layers need: one per four layers up to the last texture layer.
    pub fn depth_textures_needed(&self) -> usize {
        self.layers
            .iter()
            .enumerate()
            .filter(|(_, l)| matches!(l.thickness, Thickness::Texture { .. }))
            .map(|(i, _)| i / 4 + 1)
            .max()
            .unwrap_or(0)
    }

    /// Loads the `TexDep` textures as linear data (the project's texture loader: float and
    /// 16-bit files keep their precision).
    pub fn load_depth_textures(&self) -> Result<Vec<Texture>> {
        self.depth_textures
            .iter()
            .map(|t| super::texture::load_source(t, TextureUsage::Data))
            .collect()
    }

    /// Checks every value is finite and in range: 1 to [`MAX_LAYERS`] layers; `sigma_a`,
    /// `sigma_s` in [0, [`MAX_COEFFICIENT`]]; |g| <= [`MAX_ABS_G`]; constant thickness finite
    /// and >= 0, texture scale finite and > 0, `rest` only on the last layer; as many depth
    /// textures as the layers read; `eta` finite and > 0; weights finite and >= 0;
    /// `units_per_mm` finite and > 0. Errors name the layer and the key (`layer[0].g`).
    pub fn validate(&self) -> Result<()> {
        self.validate_values()?;
        let needed = self.depth_textures_needed();
        if self.depth_textures.len() != needed {
            return Err(LucentError::InvalidInput(format!(
                "layered '{}': depth_texture: {} given, the layers read {needed} (layer i with \
                 thickness \"texture\" reads channel i % 4 of texture i / 4)",
                self.name,
                self.depth_textures.len()
            )));
        }
        Ok(())
    }

    /// [`Self::validate`] but for the depth textures' count: for a medium whose textures come
    /// from elsewhere (a host engine's per mesh, `lucent::embed::MeshDraw`).
    pub fn validate_values(&self) -> Result<()> {
        let bad = |m: String| {
            Err(LucentError::InvalidInput(format!(
                "layered '{}': {m}",
                self.name
            )))
        };
        let n = self.layers.len();
        if !(1..=MAX_LAYERS).contains(&n) {
            return bad(format!("{n} layers; 1 to {MAX_LAYERS} are supported"));
        }
        for (i, l) in self.layers.iter().enumerate() {
            for (what, v) in [("sigma_a", l.sigma_a), ("sigma_s", l.sigma_s)] {
                if !(v.is_finite() && v.min_element() >= 0.0 && v.max_element() <= MAX_COEFFICIENT)
                {
                    return bad(format!(
                        "layer[{i}].{what} {v} must be finite and in [0, {MAX_COEFFICIENT:e}] (mm^-1)"
                    ));
                }
            }
            if !(l.g.is_finite() && l.g.abs() <= MAX_ABS_G) {
                return bad(format!("layer[{i}].g {} must be in [-0.999, 0.999]", l.g));
            }
            match l.thickness {
                Thickness::Mm(t) if !(t.is_finite() && t >= 0.0) => {
                    return bad(format!(
                        "layer[{i}].thickness {t} must be finite and >= 0 (mm), \"texture\" or \
                         \"rest\""
                    ))
                }
                Thickness::Texture { scale } if !(scale.is_finite() && scale > 0.0) => {
                    return bad(format!(
                        "layer[{i}].thickness_scale {scale} must be finite and > 0 (mm per texel \
                         unit)"
                    ))
                }
                Thickness::Rest if i + 1 != n => {
                    return bad(format!(
                        "layer[{i}].thickness \"rest\" (semi-infinite) is allowed only on the \
                         last layer ({} of {n})",
                        n - 1
                    ))
                }
                _ => {}
            }
        }
        if !(self.eta.is_finite() && self.eta > 0.0) {
            return bad(format!("eta {} must be finite and > 0", self.eta));
        }
        if !self.weights.iter().all(|w| w.is_finite() && *w >= 0.0) {
            return bad(format!(
                "weights {:?} must each be finite and >= 0",
                self.weights
            ));
        }
        if !(self.units_per_mm.is_finite() && UNITS_PER_MM_RANGE.contains(&self.units_per_mm)) {
            return bad(format!(
                "units_per_mm {} must be in [{:e}, {:e}]",
                self.units_per_mm,
                UNITS_PER_MM_RANGE.start(),
                UNITS_PER_MM_RANGE.end()
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn total_diffuse_reflectance_stays_an_albedo_at_extreme_media() {
        // A medium's R_d becomes a material's albedo: finite and in [0, 1] for every medium
        // validate() accepts (coefficients 0 to 1e6 mm^-1, g to +-0.999, eta 1 to 2.5 and
        // beyond), 0 without scattering and near 1 without absorption.
        for sp in [0.0, 1e-6, 1.0, 1e6] {
            for sa in [0.0, 1e-6, 1.0, 1e6] {
                for g in [-0.999, 0.0, 0.999] {
                    for eta in [0.5, 1.0, 1.3, 2.5, 10.0] {
                        let m = LayeredMedium::homogeneous(
                            "x",
                            Vec3::splat(sp),
                            Vec3::splat(sa),
                            g,
                            eta,
                        );
                        let rd = m.total_diffuse_reflectance();
                        assert!(
                            rd.is_finite() && rd.min_element() >= 0.0 && rd.max_element() <= 1.0,
                            "sigma_s' {sp}, sigma_a {sa}, g {g}, eta {eta}: {rd}"
                        );
                        if sp == 0.0 {
                            assert_eq!(rd, Vec3::ZERO);
                        }
                        if sa == 0.0 && sp > 0.0 && eta == 1.0 {
                            assert!(rd.min_element() > 0.99, "{sp} {g}: {rd}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn eta_one_has_no_boundary() {
        assert_eq!(fresnel_diffuse_reflectance(1.0), 0.0);
        // Both fits stay reflectances, and meet near eta = 1.
        for eta in [1e-3, 0.1, 0.5, 0.9, 0.999, 1.001, 1.3, 2.0, 5.0, 1e3] {
            let f = fresnel_diffuse_reflectance(eta);
            assert!((0.0..=0.999).contains(&f), "{eta}: {f}");
        }
        assert!(
            (fresnel_diffuse_reflectance(0.9999) - fresnel_diffuse_reflectance(1.0001)).abs()
                < 0.01
        );
        let d = dipole_constants(1.0, 0.1, 1.0);
        assert_eq!(d.a, 1.0);
        assert_eq!(d.z_v, d.z_r * (1.0 + 4.0 / 3.0));
    }

    #[test]
    fn every_jensen_preset_is_one_semi_infinite_layer_of_the_table() {
        for (name, sp, sa) in JENSEN_2001 {
            let m = LayeredMedium::preset(name).unwrap();
            m.validate().unwrap();
            assert_eq!(m.layers.len(), 1);
            assert_eq!(m.layers[0].g, 0.0);
            assert_eq!(m.layers[0].sigma_s, Vec3::from(sp));
            assert_eq!(m.layers[0].sigma_a, Vec3::from(sa));
            assert_eq!(m.layers[0].thickness, Thickness::Rest);
            assert_eq!(m.eta, 1.3);
        }
        let skin1 = LayeredMedium::preset("skin1").unwrap();
        assert_eq!(skin1.layers[0].sigma_a.z, 0.48);
        let li = LayeredMedium::preset("li-teapot").unwrap();
        assert_eq!(li.layers[0].sigma_a.z, 0.18);
        assert!(LayeredMedium::preset("frog").is_err());
    }

    #[test]
    fn skin_layered_is_epidermis_over_dermis() {
        let m = LayeredMedium::preset("skin-layered").unwrap();
        m.validate().unwrap();
        assert_eq!(m.layers.len(), 2);
        assert_eq!(m.layers[0].thickness, Thickness::Mm(0.25));
        assert_eq!(m.layers[1].thickness, Thickness::Rest);
        // sigma_s = sigma_s' / (1 - g) round trips.
        let back = m.layers[0].sigma_s_prime();
        assert!((back.x - 4.6657).abs() < 1e-4, "{back}");
        assert_eq!(m.eta, 1.4);
    }

    #[test]
    fn units_and_dipole_constants() {
        let mut m = LayeredMedium::preset("marble").unwrap();
        m.units_per_mm = 0.5;
        // 1/mm to 1/unit: two mm per unit doubles the coefficient.
        let st = m.sigma_t_per_unit(0);
        assert!((st.x - (2.19 + 0.0021) / 0.5).abs() < 1e-5);
        let d = m.dipole_constants();
        let r = m.first_layer_reduced();
        assert!((d.z_r.x - 1.0 / r.sigma_t_prime.x).abs() < 1e-6);
        assert!(d.z_v.x > d.z_r.x && d.f_dr > 0.0 && d.a > 1.0);
        m.eta = 1.0;
        let d = m.dipole_constants();
        assert_eq!(d.f_dr, 0.0);
        assert_eq!(d.a, 1.0);
    }

    #[test]
    fn texture_thickness_reads_channel_i_mod_4_of_texture_i_div_4() {
        let layer = Layer {
            sigma_a: Vec3::ONE,
            sigma_s: Vec3::ONE,
            g: 0.0,
            thickness: Thickness::Texture { scale: 2.0 },
        };
        let mut m = LayeredMedium::preset("apple").unwrap();
        m.layers = vec![layer; 6];
        m.depth_textures = vec![TextureSource::File("a".into()); 2];
        m.validate().unwrap();
        let texels = [[0.1, 0.2, 0.3, 0.4], [0.5, f32::NAN, 0.7, 0.8]];
        assert_eq!(m.thickness_mm(2, &texels), 0.6);
        assert_eq!(m.thickness_mm(4, &texels), 1.0);
        assert_eq!(m.thickness_mm(5, &texels), 0.0);
        m.depth_textures.pop();
        assert!(m
            .validate()
            .unwrap_err()
            .to_string()
            .contains("depth_texture"));
    }

    #[test]
    fn out_of_range_values_are_rejected() {
        let ok = LayeredMedium::preset("skin-layered").unwrap();
        let check = |f: &dyn Fn(&mut LayeredMedium), what: &str| {
            let mut m = ok.clone();
            f(&mut m);
            let e = m.validate().unwrap_err().to_string();
            assert!(e.contains(what), "{what}: {e}");
        };
        check(&|m| m.layers[0].g = 1.0, "layer[0].g");
        check(&|m| m.layers[1].sigma_a.y = f32::NAN, "layer[1].sigma_a");
        check(&|m| m.layers[0].sigma_s.x = -1.0, "layer[0].sigma_s");
        check(
            &|m| m.layers[0].thickness = Thickness::Rest,
            "only on the last",
        );
        check(
            &|m| m.layers[0].thickness = Thickness::Mm(-1.0),
            "thickness",
        );
        check(&|m| m.eta = 0.0, "eta");
        check(&|m| m.weights[2] = f32::INFINITY, "weights");
        check(&|m| m.units_per_mm = 0.0, "units_per_mm");
        check(&|m| m.layers.clear(), "0 layers");
        check(&|m| m.layers = vec![m.layers[1]; 9], "9 layers");
    }

    #[test]
    fn reduced_to_full_scattering_is_guarded() {
        let s = sigma_s_from_reduced(Vec3::ONE, 1.0);
        assert!(s.is_finite() && (s.x - 1000.0).abs() < 0.1, "{s}");
        assert_eq!(sigma_s_from_reduced(Vec3::ONE, 0.0), Vec3::ONE);
    }
}
