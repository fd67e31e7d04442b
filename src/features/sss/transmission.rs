//! Diffuse transmission through thickness for screen-space SSS materials with a medium
//! (issue 26): HDRP's "thick" transmission, from the material's `[material.medium]`.
//!
//! The blurs spread light a few millimetres across the visible surface; light that entered on
//! an object's far side and diffused through it (a back-lit ear, the wrap of a side-lit skin
//! sphere past its terminator) never reaches them. So the lighting pass adds, per light, for
//! the pixels of a profile whose material has a medium: the light's radiance at the entry
//! point the light-space map gives (the first surface on the segment towards the light) x the
//! medium's diffuse transmittance through that thickness x the back-facing cosine, times the
//! albedo as the diffuse light carries it (its texturing mode) over pi; the blur then spreads
//! it with the rest (glsl/common/sss_transmission.glsl).
//!
//! **The transmittance is the medium's diffusion through a slab of that thickness**: Donner and
//! Jensen's (2005) multipole (the medium's dipole mirrored about both faces, every image),
//! integrated over the far face and summed in closed form, never less than the semi-infinite dipole's
//! light beyond the thickness, `Tb(a) = 2 pi ∫_a^∞ Rd(r) r dr`
//! ([`crate::scene::layered::Dipole::transmitted_beyond`], what Li et al.'s layered pass adds
//! today: `dipole_beyond`), which takes over for slabs thinner than about a mean free path,
//! where the multipole's real source lies outside the slab and its sum goes negative. Over the
//! medium's albedo `A` (its white-sky albedo, what the material takes when it writes none):
//! `T(a) = (alpha' / 2) max(multipole(a), Tb(a)) / A`. Multiplied by the material's albedo,
//! `A` when the material writes none, it is the model's light through the slab; a written
//! albedo or texture scales it as it scales the diffuse light.
//!
//! Why not `Tb(a)` alone, as the layered pass: measured against the path-traced truth of a
//! 4 mm skin1 slab lit from behind (docs/sss.md, "Transmission through thickness"), `Tb`
//! lets through 49% / 13% / 2% of the truth's red / green / blue (error 0.60): light that
//! leaves a semi-infinite medium far from where it entered is not light that crosses a slab,
//! whose far face catches what would have diffused deeper. The multipole lets through 119% /
//! 64% / 21% (error 0.26). Not the fitted Gaussians' closed form (`sum w_i e^(-a^2 / 2 v_i)`)
//! either: the fit covers the profile out to a few mean free paths, and a Gaussian's tail falls
//! as `e^(-a^2)` where diffusion falls as `e^(-sigma_tr a)`, so thick parts would lose their
//! light.
//!
//! Lights without a light-space map transmit nothing (nothing measures the thickness), as in
//! the layered pass. `--no-sss-transmission` leaves the term out (A/B).

use crate::scene::layered::{dipole_constants, Dipole};
use crate::scene::material::Medium;

/// Rows per profile of the table's `medium` array: four of transmission, two of reflectance.
pub const MEDIUM_ROWS: usize = 6;

/// What a screen-space SSS material's lighting reads of its medium: its transmission through
/// thickness and (two rows more) its reflectance (Chandrasekhar's, relative to Lambert's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SssTransmission {
    /// The medium's dipole per channel (R, G, B), lengths in mm.
    pub dipoles: [Dipole; 3],
    /// Millimetres per scene unit (`1 / units_per_mm`).
    pub mm_per_unit: f64,
    /// The medium's white-sky albedo per channel, which the transmittance is relative to
    /// (the albedo a material with a medium takes when it writes none).
    pub medium_albedo: [f64; 3],
    /// Its reduced single-scattering albedo `sigma_s' / (sigma_s' + sigma_a)` per channel
    /// and its white-sky albedo behind an index-matched boundary: what its reflectance
    /// relative to Lambert's takes ([`crate::scene::albedo::medium_reflectance`]).
    pub reflectance: [(f64, f64); 3],
}

impl SssTransmission {
    /// The transmission of `medium` (its one semi-infinite layer at its eta).
    pub fn of(medium: &Medium) -> Self {
        let m = &medium.layered;
        let layer = &m.layers[0];
        let (sp, sa) = (layer.sigma_s_prime(), layer.sigma_a);
        Self {
            dipoles: [0, 1, 2]
                .map(|c| dipole_constants(f64::from(sp[c]), f64::from(sa[c]), f64::from(m.eta))),
            // units_per_mm is validated finite and > 0.
            mm_per_unit: 1.0 / f64::from(m.units_per_mm),
            medium_albedo: medium.albedo.as_dvec3().to_array(),
            reflectance: std::array::from_fn(|c| {
                let (sp, sa) = (f64::from(sp[c]).max(0.0), f64::from(sa[c]).max(0.0));
                // A medium that neither scatters nor absorbs (validated away) scatters nothing.
                let omega = if sp + sa > 0.0 { sp / (sp + sa) } else { 0.0 };
                (omega, f64::from(medium.matched_albedo[c]))
            }),
        }
    }

    /// The transmittance per channel through `a` scene units, relative to the medium's albedo
    /// ([`crate::scene::transmittance::transmittance_over_albedo`]).
    pub fn transmittance(&self, a: f64) -> [f64; 3] {
        std::array::from_fn(|c| {
            crate::scene::transmittance::transmittance_over_albedo(
                &self.dipoles[c],
                a * self.mm_per_unit,
                self.medium_albedo[c],
            )
        })
    }

    /// The profile table's four rows (glsl/common/sss.glsl `transmission`): sigma_tr (a: mm
    /// per unit, > 0: the profile transmits), z_r, z_v (mm), and `(alpha' / 2) / A` (the
    /// sums' factor to the light, over the medium's albedo `A`, at least 1e-3); the alphas of
    /// the last three the largest transmittance per channel, `1 / A` (at most 1000).
    /// Each value is finite: `z_r = 1 / sigma_t'` with `sigma_t'` at least 1e-12 / mm, `z_v`
    /// at most 2700 `z_r`, `alpha' <= 1` and `A >= 1e-3`.
    pub fn rows(&self) -> [[f32; 4]; 4] {
        let v = |f: &dyn Fn(&Dipole) -> f64| self.dipoles.map(|d| f(&d) as f32);
        let [sr, sg, sb] = v(&|d| d.sigma_tr);
        let [rr, rg, rb] = v(&|d| d.z_r);
        let [vr, vg, vb] = v(&|d| d.z_v);
        let albedo = self.medium_albedo.map(|a| a.max(1e-3));
        let [nr, ng, nb] =
            std::array::from_fn(|c| (0.5 * self.dipoles[c].alpha_prime / albedo[c]) as f32);
        let [mr, mg, mb] = albedo.map(|a| (1.0 / a) as f32);
        [
            [sr, sg, sb, self.mm_per_unit as f32],
            [rr, rg, rb, mr],
            [vr, vg, vb, mg],
            [nr, ng, nb, mb],
        ]
    }

    /// The reflectance's two rows (glsl/common/sss_medium.glsl): `gamma = sqrt(1 - omega)`
    /// (a: 1, the profile has a medium) and `omega / (4 A_1)`, `A_1` at least 1e-3 (finite).
    pub fn reflectance_rows(&self) -> [[f32; 4]; 2] {
        let [r, g, b] = self
            .reflectance
            .map(|(omega, _)| (1.0 - omega).max(0.0).sqrt() as f32);
        let [sr, sg, sb] = self
            .reflectance
            .map(|(omega, matched)| (omega / (4.0 * matched.max(1e-3))) as f32);
        [[r, g, b, 1.0], [sr, sg, sb, 0.0]]
    }
}
