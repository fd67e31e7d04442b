//! 2-D Burley SSS (Christensen and Burley 2015, as HDRP, Unreal and EEVEE ship it): a
//! fullscreen gather pass that importance-samples the normalized diffusion profile
//! `R(r) = (e^(-r/d) + e^(-r/3d)) / (8 pi d r)` around each pixel (glsl/sss/burley.frag), and a
//! resolve pass (glsl/sss/burley_resolve.frag).
//!
//! Per pixel of a Burley profile: radii from the exact inverse of the widest channel's radial
//! CDF at stratified `xi_i = (i + 1/2) / n`, angles on a golden-angle spiral rotated by one of
//! nine angles per 3x3 block (`--burley-rotation off`: not rotated), `n` from the kernel's
//! area on screen (`pi R^2 / 4` pixels for a reach `R` of 16.56 `d`, HDRP's cut) under a budget
//! (`--burley-budget`), pixels whose reach is under one pixel left as they are. Each sample
//! weighs `R_c(r_3d) / pdf(r)` per channel with the depth difference inside the distance; taps
//! on pixels of another profile or that do not scatter are rejected (no halo: those pixels keep
//! their light); the sum is divided by the weights' sum. `d` per channel comes from the
//! material ([`crate::scene::material::BurleyDistance`]; a mean free path through
//! `--burley-fit`) or from its Gaussians' second moment.
//!
//! Its table (`burley` per frame: [`BurleyTableGpu`]) holds each profile's `d` in world units
//! and the budget. Two passes: `burley` gathers (the per-frame pair, that table, the lit
//! diffuse with linear depth in alpha, depth, profile IDs), `burley resolve` averages each
//! scattering pixel with its 3x3 neighbours of the same profile and depth (the nine spiral
//! rotations of a 3x3 block together: every radius at nine evenly spaced angles, so a still
//! shows neither grain nor the unrotated spiral's striations) and composes the chain's result
//! (plus specular; the previous chain's result or the lit light elsewhere).

use std::sync::Arc;

use super::settings::BURLEY_BUDGET_RANGE;
use super::{chain_tiles, sss_pass, BlurConstants, Chain, SssBlurTechnique, SssInputs, SssKnobs};
use super::{SssProfiles, MAX_SSS_PROFILES};
use crate::backend::shader::PipelineShaders;
use crate::features::knob::{Given, Knob, Takes};
use crate::features::util::Defines;
use crate::features::util::HDR_FORMAT;
use crate::gpu_scene::{Region, SceneGpu, TableRegion};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, RenderGraph};
use crate::scene::profile::{burley_cdf, burley_radius, BurleyFit, BURLEY_REACH};

/// The Burley blur (`--technique burley`, `blur = "burley"`).
pub static BURLEY: BurleyChain = BurleyChain {
    name: "burley",
    summary: "2-D Burley SSS (HDRP, Unreal, EEVEE): the normalized diffusion profile \
              importance-sampled around each pixel in one pass",
    knobs: &[
        &BUDGET,
        &ROTATION,
        &FIT,
        &HALF_RES,
        &super::knobs::TEXTURING,
        &super::knobs::NO_TILES,
        &super::knobs::NO_TRANSMISSION,
    ],
    scene: "skin",
    published_timing: None,
};

/// The Burley chain's module data (one instance, [`BURLEY`]).
pub struct BurleyChain {
    /// Its name.
    pub name: &'static str,
    /// One line for help texts.
    pub summary: &'static str,
    /// The knobs that act on it.
    pub knobs: &'static [&'static Knob],
    /// The built-in scene it is measured on.
    pub scene: &'static str,
    /// No published per-pass table.
    pub published_timing: Option<&'static crate::features::technique::SeedTable>,
}

super::chain_technique_module!(BurleyChain);

/// `--burley-budget N`: the most samples per pixel.
pub static BUDGET: Knob = Knob {
    flag: "--burley-budget",
    help: "Burley SSS: the most samples per pixel (4 to 256; default 8; fewer where the \
           kernel covers fewer pixels, pi R^2 / 4; HDRP's budgets are 20, 40 and 80).",
    takes: Takes::Whole {
        min: BURLEY_BUDGET_RANGE.0,
        max: BURLEY_BUDGET_RANGE.1,
    },
    default: Some(Given::Whole(super::settings::DEFAULT_BURLEY_BUDGET)),
    apply: |k, v| k.sss.burley_budget = v.whole(),
};

/// `--burley-rotation on|off`: the per-pixel rotation of the sample spiral.
pub static ROTATION: Knob = Knob {
    flag: "--burley-rotation",
    help: "Burley SSS: rotate the golden-angle sample spiral by one of nine angles per 3x3 \
           block, which the resolve averages (on, the default), or not (off: every pixel \
           samples the same directions, striations along them).",
    takes: Takes::Choice(&["on", "off"]),
    default: Some(Given::Choice("on")),
    apply: |k, v| k.sss.burley_rotation = v.choice() == "on",
};

/// `--burley-half-res`: the gather at half resolution per side.
pub static HALF_RES: Knob = Knob {
    flag: "--burley-half-res",
    help: "Burley SSS: gather at half resolution per side (a quarter of the gathers) and \
           resolve at full resolution over the 3x3 half-resolution texels around each pixel, \
           by depth and profile; pixels whose profile reaches under two pixels keep their own \
           light.",
    takes: Takes::Switch,
    default: None,
    apply: |k, _| k.sss.burley_half_res = true,
};

/// `--burley-fit`: the albedo fit of materials that give a mean free path.
pub static FIT: Knob = Knob {
    flag: "--burley-fit",
    help: "Burley SSS: Christensen and Burley's fit of s from the albedo for materials that \
           give a mean_free_path: searchlight (the default, Unreal's), diffuse (EEVEE's) or \
           perpendicular.",
    takes: Takes::Choice(&["searchlight", "diffuse", "perpendicular"]),
    default: Some(Given::Choice("searchlight")),
    apply: |k, v| {
        if let Some((_, fit)) = BurleyFit::ALL.iter().find(|(n, _)| *n == v.choice()) {
            k.sss.burley_fit = *fit;
        }
    },
};

/// The Burley table in the per-frame buffer.
pub static TABLE_REGION: Region = Region::new("SSS Burley table", "SssBurley");

/// The Burley table, std140 (glsl/sss/burley.frag `SssBurley`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BurleyTableGpu {
    /// Per profile ID: rgb `d` per channel in world units, a the widest `d`.
    pub distance: [[f32; 4]; MAX_SSS_PROFILES],
    /// x: the sample budget; y: 1 to rotate the spiral per pixel; z: the reach in units of `d`.
    pub knobs: [f32; 4],
    /// The inverse CDF `r / d` at [`BURLEY_RADII`]` + 1` evenly spaced fractions of the profile
    /// within the reach, four a row: the shader interpolates it.
    pub radii: [[f32; 4]; BURLEY_RADII / 4 + 1],
    /// At the same fractions, `t / (e^(-t) + e^(-t/3))` for the radius `t` in units of `d`:
    /// the sample's `1 / pdf` up to constants.
    pub inverse_pdf: [[f32; 4]; BURLEY_RADII / 4 + 1],
}

/// Entries of the tabulated inverse CDF (glsl/sss/burley.frag `BURLEY_RADII`).
pub const BURLEY_RADII: usize = 128;

/// The inverse CDF of Burley's profile at `BURLEY_RADII + 1` fractions of the energy within
/// [`BURLEY_REACH`] `d`, in units of `d`, and each radius's `1 / pdf` up to constants.
type RadiusTable = [[f32; 4]; BURLEY_RADII / 4 + 1];

fn radii_tables() -> (RadiusTable, RadiusTable) {
    let within = burley_cdf(1.0, BURLEY_REACH);
    let (mut radii, mut inverse_pdf) = (
        [[0.0; 4]; BURLEY_RADII / 4 + 1],
        [[0.0; 4]; BURLEY_RADII / 4 + 1],
    );
    for k in 0..=BURLEY_RADII {
        let t = burley_radius(within * k as f64 / BURLEY_RADII as f64).min(BURLEY_REACH);
        radii[k / 4][k % 4] = t as f32;
        // (e^(-t) + e^(-t/3)) >= 2 e^(-t/3) > 0 within the reach: no division by zero.
        inverse_pdf[k / 4][k % 4] = (t / ((-t).exp() + (-t / 3.0).exp())) as f32;
    }
    (radii, inverse_pdf)
}

/// The Burley table of `profiles` under `knobs`: every profile's `d` (a profile another chain
/// blurs gets one too; the pass only reads its own chain's).
pub fn burley_table(profiles: &SssProfiles, knobs: &SssKnobs) -> BurleyTableGpu {
    let mut table = BurleyTableGpu {
        distance: [[0.0; 4]; MAX_SSS_PROFILES],
        knobs: [
            knobs
                .burley_budget
                .clamp(BURLEY_BUDGET_RANGE.0, BURLEY_BUDGET_RANGE.1) as f32,
            if knobs.burley_rotation { 1.0 } else { 0.0 },
            BURLEY_REACH as f32,
            0.0,
        ],
        radii: [[0.0; 4]; BURLEY_RADII / 4 + 1],
        inverse_pdf: [[0.0; 4]; BURLEY_RADII / 4 + 1],
    };
    (table.radii, table.inverse_pdf) = radii_tables();
    for (i, (profile, _)) in profiles
        .profiles
        .iter()
        .enumerate()
        .take(MAX_SSS_PROFILES - 1)
    {
        let units = f64::from(profile.units_per_mm);
        // `burley_d` holds d within the accepted range, so the world-unit d is finite.
        let d = profile.burley_d(knobs.burley_fit) * units;
        table.distance[i + 1] = [d.x as f32, d.y as f32, d.z as f32, d.max_element() as f32];
    }
    table
}

const GATHER_FRAGMENT: &str = "sss/burley.frag";
const RESOLVE_FRAGMENT: &str = "sss/burley_resolve.frag";

/// The gather pass's defines (`half_res`: one gather per 2x2 block).
fn gather_defines(depth_in_alpha: bool, half_res: bool) -> Defines {
    let mut defines = Vec::new();
    if depth_in_alpha {
        defines.push(("LUCENT_SSS_DEPTH_IN_ALPHA", "1"));
    }
    if half_res {
        defines.push(("LUCENT_SSS_HALF_RES", "1"));
    }
    defines
}

/// The resolve pass's defines (`base`: it keeps the previous chain's result; `edges`: the
/// frame has several profiles), and its pass-through variant's extra one.
fn resolve_defines(base: bool, edges: bool, albedo: bool, half_res: bool) -> (Defines, Defines) {
    let mut defines = Vec::new();
    if half_res {
        defines.push(("LUCENT_SSS_HALF_RES", "1"));
    }
    if base {
        defines.push(("LUCENT_SSS_BASE", "1"));
    }
    if albedo {
        defines.push(("LUCENT_SSS_ALBEDO", "1"));
    }
    if edges {
        defines.push(("LUCENT_SSS_PROFILE_EDGES", "1"));
    }
    (defines, vec![("LUCENT_SSS_PASSTHROUGH", "1")])
}

/// Every pipeline the passes may build.
fn shader_permutations(_: &BurleyChain, out: &mut Vec<PipelineShaders>) {
    for flags in 0u32..1 << 2 {
        let bit = |i: u32| flags & (1 << i) != 0;
        out.push(PipelineShaders::fullscreen(
            GATHER_FRAGMENT,
            &gather_defines(bit(0), bit(1)),
        ));
    }
    for flags in 0u32..1 << 4 {
        let bit = |i: u32| flags & (1 << i) != 0;
        let (defines, passthrough) = resolve_defines(bit(0), bit(1), bit(2), bit(3));
        out.push(PipelineShaders::fullscreen(RESOLVE_FRAGMENT, &defines));
        let mut all = defines.clone();
        all.extend(passthrough);
        out.push(PipelineShaders::fullscreen(RESOLVE_FRAGMENT, &all));
    }
}

impl SssBlurTechnique for BurleyChain {
    fn lean(&self) -> bool {
        false
    }

    fn bilateral(&self) -> bool {
        false
    }

    fn iterative(&self) -> bool {
        false
    }

    fn depth_in_alpha(&self) -> bool {
        true
    }

    fn table(&self) -> Option<TableRegion> {
        Some(TableRegion {
            region: &TABLE_REGION,
            bytes: std::mem::size_of::<BurleyTableGpu>() as u64,
        })
    }

    fn table_bytes(&self, profiles: &SssProfiles, knobs: &SssKnobs) -> Vec<u8> {
        bytemuck::bytes_of(&burley_table(profiles, knobs)).to_vec()
    }

    fn declare_chain(
        &self,
        graph: &mut RenderGraph,
        inputs: &SssInputs<'_>,
        chain: &Chain,
        base: Option<&Handle<Image>>,
        knobs: &SssKnobs,
        scene: Option<&Arc<SceneGpu>>,
        output: Option<Handle<Image>>,
    ) -> Handle<Image> {
        let full = ImageInfo {
            format: HDR_FORMAT,
            ..graph.resources()[inputs.diffuse.id()].info
        };
        let mut result = output.unwrap_or_else(|| {
            let name = if chain.last {
                "hdr".to_string()
            } else {
                chain.image_name("result")
            };
            graph.create_image(&name, full)
        });
        let constants = BlurConstants {
            step: [0.0, 0.0, 0.0, chain.index as f32],
        };
        let index = chain.index;

        // Gather: the profile importance-sampled around each of the chain's pixels (with
        // `--burley-half-res`, around the top-left pixel of each 2x2 block).
        let half_res = knobs.burley_half_res;
        let gathered_info = if half_res {
            ImageInfo {
                width: full.width.div_ceil(2),
                height: full.height.div_ceil(2),
                ..full
            }
        } else {
            full
        };
        let mut gathered = graph.create_image(&chain.image_name("gathered"), gathered_info);
        let name = format!("{}burley", chain.prefix);
        let mut pass = sss_pass(graph, inputs, &name, GATHER_FRAGMENT, scene, constants);
        pass.per_frame(&TABLE_REGION);
        pass.sample("diffuse_tex", inputs.diffuse)
            .sample("depth_tex", inputs.depth)
            .sample("profile_tex", inputs.profile_ids);
        // Per pixel: the centre's light and profile, then per sample its light and profile ID
        // (depth travels in the light's alpha), up to the budget.
        pass.taps(2 + 2 * knobs.burley_budget);
        pass.defines(&gather_defines(inputs.depth_in_alpha, half_res));
        pass.tiles(move |scene, ctx| {
            let rects = chain_tiles(scene, ctx, index)?;
            Some(if half_res {
                rects.iter().map(super::two_pass::halved).collect()
            } else {
                rects
            })
        });
        pass.color(&mut gathered, LoadOp::DontCare);
        pass.finish();

        // Resolve: the 3x3 average of the nine spiral rotations, composed.
        let name = format!("{}burley resolve", chain.prefix);
        let mut pass = sss_pass(graph, inputs, &name, RESOLVE_FRAGMENT, scene, constants);
        pass.per_frame(&TABLE_REGION);
        pass.sample("gathered_tex", &gathered)
            .sample("profile_tex", inputs.profile_ids)
            .sample("diffuse_tex", inputs.diffuse)
            .sample("specular_tex", inputs.specular);
        if let Some(base) = base {
            pass.sample("base_tex", base);
        }
        // The albedo the lighting pass left out of the light; at half resolution the depth
        // (each pixel's own, against the gathered texels').
        if let Some(albedo) = inputs.albedo {
            pass.sample("albedo_tex", albedo);
        }
        if half_res {
            pass.sample("depth_tex", inputs.depth);
        }
        // The centre's profile, then nine gathered texels (and their profile IDs with several
        // profiles), the lit diffuse and specular.
        pass.taps(
            1 + 9 * (1 + u32::from(chain.edges))
                + 2
                + u32::from(inputs.albedo.is_some())
                + u32::from(half_res),
        );
        let (defines, passthrough) = resolve_defines(
            base.is_some(),
            chain.edges,
            inputs.albedo.is_some(),
            half_res,
        );
        pass.defines(&defines).variant(passthrough);
        pass.tiles(move |scene, ctx| chain_tiles(scene, ctx, index));
        pass.color(&mut result, LoadOp::DontCare);
        pass.finish();
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::registry;

    #[test]
    fn table_holds_each_profile_d_in_world_units() {
        let scene = crate::scene::builtin::builtin("skin").unwrap();
        let blur = registry::blur_of_technique(&BURLEY).unwrap();
        let profiles = SssProfiles::new(&scene, Some(blur), None, None, &registry::blur_of)
            .unwrap()
            .unwrap();
        let knobs = SssKnobs::default();
        let table = burley_table(&profiles, &knobs);
        let (profile, _) = &profiles.profiles[0];
        let d = profile.burley_d(knobs.burley_fit) * f64::from(profile.units_per_mm);
        let row = table.distance[1];
        assert!((f64::from(row[0]) - d.x).abs() < 1e-6 * d.x.max(1.0));
        assert_eq!(row[3], row[0].max(row[1]).max(row[2]));
        assert_eq!(table.distance[0], [0.0; 4]);
        assert_eq!(table.knobs[0], knobs.burley_budget as f32);
    }
}
