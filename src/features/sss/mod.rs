//! Screen-space subsurface scattering as separable blurs of the lit diffuse light, each pixel
//! with its own material's diffusion profile.
//!
//! The control technique (Jimenez et al. 2009, as the LEAN-mapping thesis describes it): for
//! each Gaussian of the material's diffusion profile (a sum of Gaussians, narrowest first), a
//! horizontal pass into a temporary target and a vertical pass back, each a 7-tap kernel whose
//! width is the Gaussian projected to the screen at the pixel's depth, with taps across large
//! depth differences lerped back to the centre colour. The blurs are iterative: step `i` blurs
//! the previous result by `sqrt(v_i - v_(i-1))` (variances of convolved Gaussians add), so after
//! step `i` the image is the diffuse light convolved with the Gaussian of variance `v_i`; the
//! vertical pass adds that, times the Gaussian's RGB weight, into the sum. A final pass adds the
//! specular the lighting pass kept apart. Pass names follow the thesis's Table 2
//! (`horizontal blur #1`, `vertical blur #1`, ...).
//!
//! **Profiles per pixel.** Every SSS material of the frame gets a profile ID (1 to
//! [`MAX_SSS_PROFILES`]` - 1`), which the G-buffer pass writes per pixel; a profile table on
//! the GPU ([`ProfileTableGpu`], a region of the per-frame buffer) holds each profile's blur
//! steps. Step `i` of the blur reads the pixel's own profile's sigma and weight, so skin and
//! marble in one frame are each diffused with their own profile in the same passes; a
//! profile with fewer Gaussians than the frame's longest simply adds nothing at the extra
//! steps. With more than one profile in the frame, a tap that lands on another profile's
//! pixel counts as a depth discontinuity (no light bleeds from one profile's object into
//! another's).
//!
//! **Chains.** Materials choose their blur ([`SssBlur`]: a registered technique that implements
//! [`SssBlurTechnique`], see [`super::registry`]). The frame runs one chain of blur passes per
//! blur in use, in registry order, each touching only the pixels of its profiles, and
//! each chain's final pass keeps the previous chain's result elsewhere; a frame with one
//! blur (every frame under a named technique) has exactly the passes the thesis's tables
//! list. With tiles on (the default), each chain draws only over the screen rectangles of its
//! objects, widened by their profiles' reach ([`profile_reach`]).

use std::sync::Arc;

use ash::vk;

use crate::gpu_scene::{SceneGpu, TableRegion, FRAME};
use crate::graph::{Handle, Image, RecordContext, RenderGraph};
use crate::scene::material::{SssProfile, Texturing};
use crate::scene::Scene;
use crate::{LucentError, Result};

/// Implements [`TechniqueModule`](super::technique::TechniqueModule) for a chain technique
/// struct (its `name`, `summary`, `knobs` and `scene` fields; itself as the chain; the
/// `shader_permutations(chain, out)` of the module that invokes it), written once for the
/// iterative and the two-pass chains.
macro_rules! chain_technique_module {
    ($chain:ty) => {
        impl $crate::features::technique::TechniqueModule for $chain {
            fn name(&self) -> &'static str {
                self.name
            }

            fn summary(&self) -> &'static str {
                self.summary
            }

            fn part(&self) -> &'static dyn $crate::features::technique::PartKind {
                &$crate::features::sss::SSS_PART
            }

            fn sss_chain(
                &'static self,
            ) -> Option<&'static dyn $crate::features::sss::SssBlurTechnique> {
                Some(self)
            }

            fn knobs(&self) -> &'static [&'static $crate::features::knob::Knob] {
                self.knobs
            }

            fn scene(&self) -> &'static str {
                self.scene
            }

            fn shader_permutations(&self, out: &mut Vec<$crate::backend::shader::PipelineShaders>) {
                shader_permutations(self, out);
            }

            fn published_timing(&self) -> Option<&'static $crate::features::technique::SeedTable> {
                self.published_timing
            }
        }
    };
}
use chain_technique_module;

pub mod bilateral;
pub mod burley;
pub mod control;
pub mod described;
mod iterative;
pub mod kernel;
pub mod knobs;
pub mod lbb;
pub mod lcb;
mod part;
pub mod separable;
pub mod settings;
pub mod tables;
pub mod transmission;
mod two_pass;

pub use crate::features::gbuffer_desc::IdMap;
use crate::features::gbuffer_desc::IdDesc;
pub use part::{SssPart, SSS_PART};
pub use settings::{SssKnobs, SssPrecision, DEFAULT_SENSITIVITY};

use super::pass::FullscreenPass;

/// Profile IDs are stored in 8 bits and index a uniform table: 0 means "does not scatter", so
/// a frame holds up to `MAX_SSS_PROFILES - 1` distinct profiles (glsl/common/sss.glsl).
pub const MAX_SSS_PROFILES: usize = 32;
/// Most blur steps (Gaussians) of one profile ([`SssProfile::validate`] allows 8).
pub const MAX_SSS_STEPS: usize = 8;

/// A screen-space SSS technique's chain of passes: what its module implements besides
/// [`super::technique::TechniqueModule`] (whose `sss_chain` returns it). The two kinds of chain are built by shared code (`iterative.rs`: one blur pair
/// per Gaussian; `two_pass.rs`: one pair for the whole profile), parametrised by the
/// properties below, never by a technique's name.
pub trait SssBlurTechnique: Sync {
    /// Whether it blurs the LEAN G-buffer (view-plane slopes and moments) with the light.
    fn lean(&self) -> bool;
    /// Whether its taps are point taps weighted by depth (LBB's per-Gaussian depth Gaussian,
    /// the two-pass bilateral's profile at the 3D distance); else bilinear taps lerped back to
    /// the centre across depth edges.
    fn bilateral(&self) -> bool;
    /// Whether it blurs one horizontal + vertical pair per Gaussian of the profile (the
    /// thesis's iterative scheme); else one pair for the whole profile with a kernel table.
    fn iterative(&self) -> bool;
    /// Whether it can blur at half resolution per side (`--sss-half-res`).
    fn half_resolution(&self) -> bool {
        false
    }
    /// Whether its taps read linear depth from the lit diffuse's alpha, which the lighting
    /// pass then writes there (when no LEAN chain keeps its slope x there).
    fn depth_in_alpha(&self) -> bool {
        false
    }
    /// A per-frame table of its own beside the profile table every chain reads (the two-pass
    /// blurs' kernel table): its region and bytes. Chains sharing a region share one table.
    fn table(&self) -> Option<TableRegion> {
        None
    }
    /// The bytes of its table ([`Self::table`]) for `profiles` under `knobs`, written each
    /// frame.
    fn table_bytes(&self, _profiles: &SssProfiles, _knobs: &SssKnobs) -> Vec<u8> {
        Vec::new()
    }
    /// Declares the chain's passes after the lighting pass: its blurs and its final pass,
    /// which keeps `base` (the previous chain's result) on the pixels the chain does not own.
    /// Returns the chain's result (`output` when given).
    #[allow(clippy::too_many_arguments)]
    fn declare_chain(
        &self,
        graph: &mut RenderGraph,
        inputs: &SssInputs<'_>,
        chain: &Chain,
        base: Option<&Handle<Image>>,
        knobs: &SssKnobs,
        scene: Option<&Arc<SceneGpu>>,
        output: Option<Handle<Image>>,
    ) -> Handle<Image>;
}

/// A registered SSS blur, as materials and frames hold it: its technique's name, its place in
/// the registry (chains run in that order) and its chain. Made by
/// [`super::registry`] (`sss_blurs`, `sss_blur`, `blur_of`); two blurs are equal when they are
/// the same technique.
#[derive(Clone, Copy)]
pub struct SssBlur {
    name: &'static str,
    rank: usize,
    technique: &'static dyn SssBlurTechnique,
}

impl SssBlur {
    /// The blur of the technique `name`, `rank`-th in the registry (the registry makes these).
    pub(crate) fn new(
        name: &'static str,
        rank: usize,
        technique: &'static dyn SssBlurTechnique,
    ) -> Self {
        Self {
            name,
            rank,
            technique,
        }
    }

    /// Its chain's properties and declaration.
    pub fn technique(self) -> &'static dyn SssBlurTechnique {
        self.technique
    }

    /// Its technique's name.
    pub fn name(self) -> &'static str {
        self.name
    }

    /// See [`SssBlurTechnique::lean`].
    pub fn lean(self) -> bool {
        self.technique.lean()
    }

    /// See [`SssBlurTechnique::bilateral`].
    pub fn bilateral(self) -> bool {
        self.technique.bilateral()
    }

    /// See [`SssBlurTechnique::iterative`].
    pub fn iterative(self) -> bool {
        self.technique.iterative()
    }

    /// See [`SssBlurTechnique::half_resolution`].
    pub fn half_resolution(self) -> bool {
        self.technique.half_resolution()
    }
}

impl PartialEq for SssBlur {
    fn eq(&self, other: &Self) -> bool {
        self.rank == other.rank
    }
}

impl Eq for SssBlur {}

impl PartialOrd for SssBlur {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for SssBlur {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.rank.cmp(&other.rank)
    }
}

impl std::hash::Hash for SssBlur {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.rank.hash(state);
    }
}

impl std::fmt::Debug for SssBlur {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// The SSS profiles of a frame: every distinct (profile, blur) of the scene's SSS materials,
/// each with its ID, and each object's ID.
#[derive(Clone, Debug, PartialEq)]
pub struct SssProfiles {
    /// The profiles in ID order (ID = index + 1), refitted when `--sss-gaussians` asks, with
    /// the blur each is diffused with.
    pub profiles: Vec<(SssProfile, SssBlur)>,
    /// Per profile (as `profiles`): the diffuse transmission through thickness of its
    /// material's medium ([`transmission`]), `None` for a material without one.
    pub transmission: Vec<Option<transmission::SssTransmission>>,
    /// Per scene object: its profile ID (0: the object does not scatter).
    pub object_ids: Vec<u8>,
    /// How the passes read a pixel's profile from the ID image ([`IdMap`]: lucent's own
    /// `R8_UNORM` profile numbers, or a host's encoding and ID-to-profile map).
    pub id_map: IdMap,
}

/// How many SSS materials with IDs other than their profile numbers the passes tell apart by
/// comparisons with constants ([`IdMap::specialization`]); more are looked up in the profile
/// table.
pub const LISTED_HOST_IDS: usize = 8;

/// The define of passes reading an ID image of unsigned integers ([`IdMap::uint`]).
const HOST_IDS_UINT: &[(&str, &str)] = &[("LUCENT_SSS_IDS_UINT", "1")];

impl IdMap {
    /// lucent's own G-buffer's IDs, decoded as its description says
    /// ([`crate::features::gbuffer::GBufferLayout::described`]: `R8_UNORM`, each pixel's
    /// profile number `k` stored as `k / 255`) for `profiles` profiles numbered 1 to
    /// `profiles`: the decode a host whose SSS materials have IDs 1 to n gets.
    pub fn lucent(profiles: usize) -> Result<Self> {
        let mut profile_of = vec![0u8; 256];
        for (id, p) in profile_of.iter_mut().enumerate().take(profiles + 1).skip(1) {
            *p = id as u8;
        }
        IdDesc::value(crate::features::gbuffer::SSS_PROFILE_FORMAT).decode(profile_of)
    }

    /// The decode as the shaders take it (glsl/common/host_ids.glsl `decode`): channel,
    /// shift, mask, UNORM maximum.
    fn decode(&self) -> [u32; 4] {
        [self.channel, self.shift, self.mask, self.unorm_max]
    }

    /// The defines the passes reading the ID image are built with (the image's sampler type).
    pub fn defines(&self) -> &'static [(&'static str, &'static str)] {
        if self.uint {
            HOST_IDS_UINT
        } else {
            &[]
        }
    }

    /// The value of the passes' `SSS_IDS_PROFILES_UP_TO` (glsl/common/sss.glsl): `n` when
    /// the IDs are the profile numbers, IDs 1 to `n` having profiles 1 to `n` and every other
    /// ID none (lucent's own G-buffer, and a host whose SSS materials have IDs 1 to `n` in
    /// order), else `None`. The passes then take a pixel's profile from its ID with no
    /// lookup.
    fn profiles_up_to(&self) -> Option<u32> {
        crate::features::util::numbered_from_one(|id| {
            usize::from(self.profile_of.get(id).copied().unwrap_or(0))
        })
        .filter(|&n| n < MAX_SSS_PROFILES)
        .map(|n| n as u32)
    }

    /// The ID constants of the SSS passes (glsl/common/sss.glsl, `constant_id` 0-20; the
    /// passes add 21 and 22, [`SssInputs::specialization`]), fixed when the passes are made:
    /// the decode (channel, shift, mask, UNORM maximum), then how many SSS materials are
    /// listed, their IDs and their profile numbers. Up to [`LISTED_HOST_IDS`] materials are
    /// listed unless the IDs are the profile numbers (`profiles_up_to`): the passes
    /// compare a pixel's ID with each instead of loading its profile from the table (the
    /// table's load made the control's combine 1.10-1.16x lucent's own pass).
    pub fn specialization(&self) -> Vec<u32> {
        let scattering: Vec<(u32, u32)> = self
            .profile_of
            .iter()
            .enumerate()
            .take(256)
            .filter(|&(_, &p)| p != 0)
            .map(|(id, &p)| (id as u32, u32::from(p)))
            .collect();
        let listed = if self.profiles_up_to().is_none() && scattering.len() <= LISTED_HOST_IDS {
            scattering.as_slice()
        } else {
            &[]
        };
        // An unlisted slot holds ID 256, which no decoded ID (at most 255) equals.
        let ids = (0..LISTED_HOST_IDS).map(|k| listed.get(k).map_or(256, |&(id, _)| id));
        let profiles = (0..LISTED_HOST_IDS).map(|k| listed.get(k).map_or(0, |&(_, p)| p));
        self.decode()
            .into_iter()
            .chain([listed.len() as u32])
            .chain(ids)
            .chain(profiles)
            .collect()
    }

    /// The profile table's `id_decode` and `id_profiles` rows.
    pub(crate) fn rows(&self) -> ([u32; 4], [[u32; 4]; 16]) {
        let mut profiles = [[0u32; 4]; 16];
        for (id, &p) in self.profile_of.iter().enumerate().take(256) {
            profiles[id / 16][(id / 4) % 4] |= u32::from(p) << (8 * (id % 4));
        }
        (self.decode(), profiles)
    }
}

impl SssProfiles {
    /// The profiles `scene`'s SSS materials ask for: each with its own blur (`blur_of` resolves
    /// a profile's, [`super::registry::blur_of`]), or `forced` on all (a named technique);
    /// refitted to `gaussians` Gaussians when set, and with `texturing` instead of each
    /// material's own when set (`--sss-texturing`). `None` when no object scatters. Under a
    /// `forced` blur, a material without a profile of its own but with a medium
    /// (`[material.medium]`) scatters with the profile fitted to its medium when it was made
    /// ([`crate::scene::material::Medium::profile`]). A material with a medium transmits light
    /// diffused through its thickness ([`transmission`]): materials that share a profile but
    /// not a medium get one ID each.
    pub fn new(
        scene: &Scene,
        forced: Option<SssBlur>,
        gaussians: Option<usize>,
        texturing: Option<Texturing>,
        blur_of: &dyn Fn(&SssProfile) -> Result<SssBlur>,
    ) -> Result<Option<Self>> {
        let mut profiles: Vec<(SssProfile, SssBlur)> = Vec::new();
        let mut transmissions: Vec<Option<transmission::SssTransmission>> = Vec::new();
        let mut object_ids = Vec::with_capacity(scene.objects.len());
        for object in &scene.objects {
            let material = &object.material;
            let derived = match (forced, &material.medium) {
                (Some(_), Some(medium)) => Some(&medium.profile),
                _ => None,
            };
            let Some(p) = material.sss.as_ref().or(derived) else {
                object_ids.push(0);
                continue;
            };
            let blur = match forced {
                Some(blur) => blur,
                None => blur_of(p)?,
            };
            let mut profile = match gaussians {
                Some(n) => crate::scene::profile::fit_profile(p, n)?.0,
                None => p.clone(),
            };
            if let Some(texturing) = texturing {
                profile.texturing = texturing;
            }
            let entry = (profile, blur);
            let through = material
                .medium
                .as_ref()
                .map(transmission::SssTransmission::of);
            let index = match profiles
                .iter()
                .zip(&transmissions)
                .position(|(e, t)| *e == entry && *t == through)
            {
                Some(i) => i,
                None => {
                    if profiles.len() + 1 == MAX_SSS_PROFILES {
                        return Err(LucentError::InvalidInput(format!(
                            "scene '{}' has more than {} distinct SSS profiles (profile IDs \
                             index a table of {MAX_SSS_PROFILES})",
                            scene.name,
                            MAX_SSS_PROFILES - 1
                        )));
                    }
                    profiles.push(entry);
                    transmissions.push(through);
                    profiles.len() - 1
                }
            };
            object_ids.push(index as u8 + 1);
        }
        if profiles.is_empty() {
            return Ok(None);
        }
        Ok(Some(Self {
            id_map: IdMap::lucent(profiles.len())?,
            profiles,
            transmission: transmissions,
            object_ids,
        }))
    }

    /// Whether some profile's material has a medium, whose light diffuses through its
    /// thickness ([`transmission`]).
    pub fn transmits(&self) -> bool {
        self.transmission.iter().any(Option::is_some)
    }

    /// The blurs in use, one chain each, in registry order.
    pub fn chains(&self) -> Vec<SssBlur> {
        let mut chains: Vec<SssBlur> = self.profiles.iter().map(|(_, b)| *b).collect();
        chains.sort();
        chains.dedup();
        chains
    }

    /// Blur steps of `chain`: its longest profile's Gaussian count (the iterative chains'
    /// blur pairs; a two-pass chain has one pair whatever it is).
    pub fn steps(&self, chain: SssBlur) -> usize {
        self.profiles
            .iter()
            .filter(|(_, b)| *b == chain)
            .map(|(p, _)| p.gaussians.len())
            .max()
            .unwrap_or(0)
    }

    /// Whether some chain is a two-pass blur (separable or bilateral), whose passes read the
    /// kernel table.
    pub fn two_pass(&self) -> bool {
        self.chains().iter().any(|b| !b.iterative())
    }

    /// Whether some chain blurs the LEAN G-buffer.
    pub fn lean(&self) -> bool {
        self.profiles.iter().any(|(_, b)| b.lean())
    }

    /// Whether the lighting pass writes linear depth into the lit diffuse's alpha for the
    /// separable blur's taps (a separable chain, and no LEAN chain whose slope x lives there).
    pub fn depth_in_alpha(&self) -> bool {
        !self.lean() && self.chains().iter().any(|b| b.technique().depth_in_alpha())
    }

    /// The profile of `object`, if it scatters.
    pub fn of_object(&self, object: usize) -> Option<&(SssProfile, SssBlur)> {
        let id = *self.object_ids.get(object)?;
        (id > 0).then(|| &self.profiles[usize::from(id) - 1])
    }

    /// The GPU profile table with `knobs` (the bilateral sensitivity).
    pub fn table(&self, knobs: &SssKnobs) -> ProfileTableGpu {
        let chains = self.chains();
        let mut table = ProfileTableGpu {
            info: [[0.0; 4]; MAX_SSS_PROFILES],
            steps: [[[0.0; 4]; 2]; MAX_SSS_PROFILES * MAX_SSS_STEPS],
            gaussians: [[0.0; 4]; MAX_SSS_PROFILES * MAX_SSS_STEPS],
            medium: [[0.0; 4]; MAX_SSS_PROFILES * transmission::MEDIUM_ROWS],
            id_decode: [0; 4],
            id_profiles: [[0; 4]; 16],
        };
        (table.id_decode, table.id_profiles) = self.id_map.rows();
        for (i, (profile, blur)) in self.profiles.iter().enumerate() {
            let id = i + 1;
            // Rows of zeros: no medium; the transmission's (mm per unit 0) also with
            // `--no-sss-transmission`.
            if let Some(t) = self.transmission[i] {
                let rows = &mut table.medium[id * transmission::MEDIUM_ROWS..];
                if knobs.transmission {
                    rows[..4].copy_from_slice(&t.rows());
                }
                rows[4..transmission::MEDIUM_ROWS].copy_from_slice(&t.reflectance_rows());
            }
            let chain = chains.iter().position(|c| c == blur).unwrap_or(0);
            let steps = blur_steps(profile);
            table.info[id] = [
                chain as f32,
                steps.len() as f32,
                profile.gaussians.len().min(MAX_SSS_STEPS) as f32,
                profile.texturing.code(),
            ];
            // The whole profile in world units, for the two-pass bilateral blur's weights: its
            // 1-D form at the tap's distance d, sum_i w_i exp(-d^2 / 2 v_i) / sqrt(2 pi v_i)
            // (each pass blurs along one axis; the Gaussians' marginals are what a separable
            // pair of passes composes back into the 2-D profile best, kernel.rs measures it),
            // weights normalised per channel.
            let units = profile.units_per_mm;
            let total = profile
                .gaussians
                .iter()
                .fold(glam::Vec3::ZERO, |acc, g| acc + g.weight);
            for (k, g) in profile.gaussians.iter().take(MAX_SSS_STEPS).enumerate() {
                // Guarded: a variance under 1e-12 world units^2 is a delta at any scale.
                let v = (g.variance * units * units).max(1e-12);
                let w = g.weight / total.max(glam::Vec3::splat(1e-30));
                let norm = w / (2.0 * std::f32::consts::PI * v).sqrt();
                table.gaussians[id * MAX_SSS_STEPS + k] = [norm.x, norm.y, norm.z, 0.5 / v];
            }
            let mut completed_variance = 0.0f32;
            for (s, step) in steps.iter().take(MAX_SSS_STEPS).enumerate() {
                completed_variance += step.sigma * step.sigma;
                // Bilateral: per world unit of depth difference, the sensitivity over the width
                // of the Gaussian this step completes (guarded: a zero-width profile rejects
                // every neighbour, which leaves the pixel as it is).
                let depth_term = if blur.bilateral() {
                    knobs.sensitivity.max(0.0) / completed_variance.sqrt().max(1e-9)
                } else {
                    DEPTH_CORRECTION
                };
                let mean_weight = step.weight.iter().sum::<f32>() / 3.0;
                table.steps[id * MAX_SSS_STEPS + s] = [
                    [step.sigma, depth_term, 0.0, 0.0],
                    [step.weight[0], step.weight[1], step.weight[2], mean_weight],
                ];
            }
        }
        table
    }
}

/// The profile table uniform block (std140, glsl/common/sss.glsl `SssProfiles`), indexed by
/// profile ID; ID 0 is unused ("does not scatter").
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ProfileTableGpu {
    /// Per ID: x the chain (index into [`SssProfiles::chains`]), y its step count, z its
    /// Gaussian count, w its texturing ([`Texturing::code`]).
    pub info: [[f32; 4]; MAX_SSS_PROFILES],
    /// Per ID and step (`id * MAX_SSS_STEPS + step`): `[sigma in world units, depth term, 0,
    /// 0]` and `[weight r, g, b, their mean]`.
    pub steps: [[[f32; 4]; 2]; MAX_SSS_PROFILES * MAX_SSS_STEPS],
    /// Per ID and Gaussian (`id * MAX_SSS_STEPS + i`, `info[id].z` of them): RGB weight
    /// normalised per channel over sqrt(2 pi v), and 1 / 2v, with v in world units squared
    /// (the two-pass bilateral blur evaluates the whole profile's 1-D form at each tap's 3D
    /// distance).
    pub gaussians: [[f32; 4]; MAX_SSS_PROFILES * MAX_SSS_STEPS],
    /// Per ID, [`transmission::MEDIUM_ROWS`] rows (`id * MEDIUM_ROWS + row`): the medium's
    /// diffuse transmission ([`transmission::SssTransmission::rows`]) and reflectance
    /// ([`transmission::SssTransmission::reflectance_rows`]); zero where the profile has none.
    pub medium: [[f32; 4]; MAX_SSS_PROFILES * transmission::MEDIUM_ROWS],
    /// The ID decode ([`IdMap`]): channel, shift, mask, UNORM maximum.
    pub id_decode: [u32; 4],
    /// The ID-to-profile map, a byte per ID 0 to 255.
    pub id_profiles: [[u32; 4]; 16],
}

/// Bytes of [`ProfileTableGpu`] (the per-frame buffer's profile region).
pub const PROFILE_TABLE_BYTES: u64 = std::mem::size_of::<ProfileTableGpu>() as u64;

/// Depth correction of the control blur: a tap whose linear depth differs from the centre's by
/// `1 / DEPTH_CORRECTION` world units or more is fully replaced by the centre colour.
pub const DEPTH_CORRECTION: f32 = 20.0;

/// One blur step of a profile: the incremental sigma (world units) and the weight of the
/// Gaussian it completes (normalised per channel so the weights sum to 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlurStep {
    /// Standard deviation added by this step, world units.
    pub sigma: f32,
    /// The completed Gaussian's RGB weight in the sum.
    pub weight: [f32; 3],
}

/// The blur steps of `profile`: `sigma_i = sqrt(v_i - v_(i-1))` mm in world units, weights
/// normalised per channel (a channel whose weights are all 0 keeps its light unblurred by
/// taking the narrowest Gaussian whole). Variances are sorted; equal ones merge.
pub fn blur_steps(profile: &SssProfile) -> Vec<BlurStep> {
    let mut gaussians = profile.gaussians.clone();
    gaussians.sort_by(|a, b| a.variance.total_cmp(&b.variance));
    let total = gaussians
        .iter()
        .fold(glam::Vec3::ZERO, |acc, g| acc + g.weight);
    let mut steps: Vec<BlurStep> = Vec::new();
    let mut previous = 0.0f32;
    for (i, g) in gaussians.iter().enumerate() {
        let weight: [f32; 3] = std::array::from_fn(|c| {
            if total[c] > 0.0 {
                g.weight[c] / total[c]
            } else if i == 0 {
                1.0
            } else {
                0.0
            }
        });
        // Guarded: equal variances add no blur (sqrt of a tiny negative is NaN).
        let sigma_mm = (g.variance - previous).max(0.0).sqrt();
        previous = previous.max(g.variance);
        steps.push(BlurStep {
            sigma: sigma_mm * profile.units_per_mm,
            weight,
        });
    }
    steps
}

/// How far (world units) the blurs of `profile` spread light: the kernel spans 3 sigma of the
/// widest Gaussian (the iterative steps' variances add up to it).
pub fn profile_reach(profile: &SssProfile) -> f32 {
    let widest = profile
        .gaussians
        .iter()
        .fold(0.0f32, |m, g| m.max(g.variance));
    3.0 * widest.max(0.0).sqrt() * profile.units_per_mm
}

/// LBB's packed ping-pong texel: eight fp16 halves (glsl/sss/blur.frag `pack_texels`).
pub const PACKED_FORMAT: vk::Format = vk::Format::R32G32B32A32_UINT;

/// LCB's and LBB's final lighting pass.
const LEAN_FINAL_SHADER: &str = "sss/lean_brdf.frag";

/// The images the SSS passes read.
pub struct SssInputs<'a> {
    /// Lit diffuse (LEAN frames: alpha holds the view-plane slope x).
    pub diffuse: &'a Handle<Image>,
    /// Lit specular, added back where the pixel does not scatter (everywhere for the control).
    pub specular: &'a Handle<Image>,
    /// Depth.
    pub depth: &'a Handle<Image>,
    /// SSS profile ID per pixel (R8: ID / 255).
    pub profile_ids: &'a Handle<Image>,
    /// LEAN frames: what LCB's and LBB's chains read of the G-buffer (`None`: no LEAN chain
    /// can run; their blurs fall back to their non-LEAN passes).
    pub lean: Option<LeanInputs<'a>>,
    /// The light-space maps' depth, when some light casts shadows (LEAN specular is shadowed).
    pub shadow_depth: Option<&'a Handle<Image>>,
    /// `shadow_depth` is an array of layers (a host's cascades or cube faces, each face in its
    /// layer: define `LUCENT_SHADOW_ARRAY`); lucent's own maps are one atlas.
    pub shadow_array: bool,
    /// A host's second shadow map beside `shadow_depth` (an atlas): an array of layers,
    /// sampled as `shadow_layers` (define `LUCENT_SHADOW_SECOND_MAP`; its faces are marked
    /// in the shadow table). lucent's own maps are one atlas.
    pub second_shadow_depth: Option<&'a Handle<Image>>,
    /// `shadow_depth` is a host's map, whose faces may store reversed Z (define
    /// `LUCENT_SHADOW_REVERSIBLE`: the shadow table says per face); lucent's own maps store
    /// standard Z.
    pub shadow_reversible: bool,
    /// G-buffer albedo (GB0), when some profile applies its albedo after the blur
    /// ([`Texturing`]): the lighting pass left it out of `diffuse`, and each chain's last pass
    /// multiplies it back in (define `LUCENT_SSS_ALBEDO`). `None`: the light carries its
    /// albedo (every profile `Texturing::Pre`, or a host's lit image).
    pub albedo: Option<&'a Handle<Image>>,
    /// The lit diffuse's alpha holds linear depth for the separable chain's taps (the lighting
    /// pass wrote it: [`SssProfiles::depth_in_alpha`]); otherwise the taps read `depth`.
    pub depth_in_alpha: bool,
    /// How the passes read `profile_ids` (its [`IdMap::defines`] and
    /// [`IdMap::specialization`]).
    pub ids: &'a IdMap,
    /// `depth` holds linear view depth (a host's `DepthEncoding::LinearView`), which the LEAN
    /// specular's position cannot be unprojected from: a host's passes take it as a
    /// specialization constant ([`SssInputs::specialization`]). Always false in lucent's own
    /// frames.
    pub linear_depth: bool,
}

impl SssInputs<'_> {
    /// The SSS passes' specialization constants (`glsl/common/sss.glsl`): the ID map's
    /// ([`IdMap::specialization`], `constant_id` 0-20), whether the depth is a host's linear
    /// view depth (21, `glsl/common/host_depth.glsl`) and how many IDs are the profile numbers
    /// (22; 0: none, the IDs are listed or looked up).
    pub fn specialization(&self) -> Vec<u32> {
        pass_specialization(self.ids, self.linear_depth)
    }
}

/// [`SssInputs::specialization`] of `ids`, with a host's linear depth or not.
fn pass_specialization(ids: &IdMap, linear_depth: bool) -> Vec<u32> {
    let mut constants = ids.specialization();
    constants.push(u32::from(linear_depth));
    constants.push(ids.profiles_up_to().unwrap_or(0));
    constants
}

/// The G-buffer images LCB's and LBB's chains read besides the lit light.
#[derive(Clone, Copy)]
pub struct LeanInputs<'a> {
    /// The G-buffer's view-plane LEAN target (slope y, moments).
    pub view_plane: &'a Handle<Image>,
    /// G-buffer albedo + specular intensity (LEAN specular).
    pub gb0: &'a Handle<Image>,
    /// G-buffer normal + roughness (LEAN specular's roughness bound).
    pub gb1: &'a Handle<Image>,
}

/// Declares every chain's passes after the lighting pass (see the module docs): per chain, one
/// horizontal + vertical blur pair per step, then its final pass (`combine` for the control,
/// `final lighting` with LEAN specular for LCB and LBB), which keeps the previous chain's
/// result on the pixels the chain does not own. Returns the final HDR image: `output` when
/// given (an image the last chain's final pass writes as a colour attachment, e.g. a host's),
/// else a new one.
pub fn sss_passes(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    profiles: &SssProfiles,
    knobs: &SssKnobs,
    scene: Option<&Arc<SceneGpu>>,
    mut output: Option<Handle<Image>>,
) -> Handle<Image> {
    let chains = profiles.chains();
    let edges = profiles.profiles.len() > 1;
    let mut base: Option<Handle<Image>> = None;
    for (index, &blur) in chains.iter().enumerate() {
        // One chain keeps the thesis's names; several are told apart by their blur.
        let prefix = if chains.len() == 1 {
            String::new()
        } else {
            format!("{} ", blur.name())
        };
        let chain = Chain {
            index,
            blur,
            steps: profiles.steps(blur),
            edges,
            prefix,
            last: index + 1 == chains.len(),
        };
        let result = if chain.last { output.take() } else { None };
        base = Some(blur.technique.declare_chain(
            graph,
            inputs,
            &chain,
            base.as_ref(),
            knobs,
            scene,
            result,
        ));
    }
    base.expect("SssProfiles is never empty")
}

/// One chain of a frame, as its technique's [`SssBlurTechnique::declare_chain`] declares it.
pub struct Chain {
    /// Its index in the frame's chains (the profile table's chain number).
    index: usize,
    blur: SssBlur,
    steps: usize,
    /// The frame has more than one profile: taps on another profile's pixels are rejected.
    edges: bool,
    /// Pass name prefix (empty in one-chain frames).
    prefix: String,
    /// The frame's last chain writes `hdr`.
    last: bool,
}

impl Chain {
    fn image_name(&self, what: &str) -> String {
        if self.prefix.is_empty() {
            format!("sss.{what}")
        } else {
            format!("sss.{}.{what}", self.blur.name())
        }
    }
}

/// Push constants of glsl/sss/blur.frag and the final passes.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurConstants {
    /// xy: direction; z: step index; w: chain index.
    step: [f32; 4],
}

/// Starts an SSS pass: the frame uniforms and the profile table bound first (0: frame, 1:
/// profiles), `constants` pushed before it draws, and the defines that say how its profile
/// IDs are read ([`IdMap::defines`], from `inputs`).
fn sss_pass<'g>(
    graph: &'g mut RenderGraph,
    inputs: &SssInputs<'_>,
    name: &str,
    fragment: &'static str,
    scene: Option<&Arc<SceneGpu>>,
    constants: BlurConstants,
) -> FullscreenPass<'g> {
    let mut pass = FullscreenPass::new(graph, name, fragment, scene);
    pass.per_frame(&FRAME)
        .per_frame(&tables::PROFILES)
        .push_constants(&constants)
        .defines(inputs.ids.defines())
        .specialize(&inputs.specialization());
    pass
}

/// The host albedo pass's shader (lucent::embed).
const HOST_ALBEDO_FRAGMENT: &str = "sss/host_albedo.frag";

/// The host albedo pass's defines: the ID decode and whether the host's light holds the albedo.
fn host_albedo_defines(
    id_defines: &'static [(&'static str, &'static str)],
    included: bool,
) -> Vec<(&'static str, &'static str)> {
    let mut defines = id_defines.to_vec();
    if included {
        defines.push(("LUCENT_SSS_HOST_ALBEDO_INCLUDED", "1"));
    }
    defines
}

/// A host's lit diffuse made into the light the chains expect (lucent::embed): the albedo in it
/// as each pixel's profile asks before the blur (`glsl/sss/host_albedo.frag`), from a host's
/// light that holds all of the albedo (`included`) or none. One fullscreen pass, declared only
/// when the host's light and the profiles' texturing differ; returns its RGBA16F result.
pub fn host_albedo_pass(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    albedo: &Handle<Image>,
    included: bool,
    width: u32,
    height: u32,
    scene: Option<&Arc<SceneGpu>>,
) -> Handle<Image> {
    let mut out = graph.create_image(
        "sss.host diffuse",
        crate::graph::ImageInfo {
            width,
            height,
            format: crate::features::util::HDR_FORMAT,
        },
    );
    let mut pass = FullscreenPass::new(graph, "sss albedo in", HOST_ALBEDO_FRAGMENT, scene);
    pass.per_frame(&FRAME)
        .per_frame(&tables::PROFILES)
        .sample("diffuse_tex", inputs.diffuse)
        .sample("albedo_tex", albedo)
        .sample("profile_tex", inputs.profile_ids)
        .defines(&host_albedo_defines(inputs.ids.defines(), included))
        .specialize(&inputs.specialization())
        .color(&mut out, crate::graph::LoadOp::DontCare);
    pass.finish();
    out
}

/// The define of a pass reading a host's shadow map that is an array of layers.
const SHADOW_ARRAY: &[(&str, &str)] = &[("LUCENT_SHADOW_ARRAY", "1")];

/// The define of passes reading a host's shadow map ([`SssInputs::shadow_reversible`]).
const SHADOW_REVERSIBLE: &[(&str, &str)] = &[("LUCENT_SHADOW_REVERSIBLE", "1")];

/// The define of a pass reading a host's second shadow map, an array beside an atlas
/// ([`SssInputs::second_shadow_depth`]).
const SHADOW_SECOND_MAP: &[(&str, &str)] = &[("LUCENT_SHADOW_SECOND_MAP", "1")];

/// Binds the shadow maps of `inputs` to a pass reading them (the first map's depth `depth`):
/// the light-space atlas, a host's second map beside it, and their defines.
fn bind_shadow_maps(pass: &mut FullscreenPass<'_>, inputs: &SssInputs<'_>, depth: &Handle<Image>) {
    pass.shadows(depth);
    if let Some(second) = inputs.second_shadow_depth {
        pass.sample("shadow_layers", second);
    }
    pass.defines(&shadow_defines(inputs));
}

/// The defines of an SSS pass that reads the shadow map of `inputs`.
fn shadow_defines(inputs: &SssInputs<'_>) -> Vec<(&'static str, &'static str)> {
    let mut defines = Vec::new();
    if inputs.shadow_array {
        defines.extend_from_slice(SHADOW_ARRAY);
    }
    if inputs.shadow_reversible {
        defines.extend_from_slice(SHADOW_REVERSIBLE);
    }
    if inputs.second_shadow_depth.is_some() {
        defines.extend_from_slice(SHADOW_SECOND_MAP);
    }
    defines
}

/// The host LEAN pass's shader (lucent::embed).
const HOST_LEAN_FRAGMENT: &str = "sss/host_lean.frag";

/// How the host LEAN pass treats a host's albedo: none read (the light is blurred as it is),
/// or read and put into the light as each profile wants it from a light that holds none of it
/// or all of it (as [`host_albedo_pass`] does).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostAlbedo {
    /// No albedo image: the light as it is, GB0's albedo white.
    None,
    /// The host's light holds none of the albedo.
    Excluded,
    /// The host's light holds all of it.
    Included,
}

impl HostAlbedo {
    const ALL: [HostAlbedo; 3] = [HostAlbedo::None, HostAlbedo::Excluded, HostAlbedo::Included];
}

/// The host LEAN pass's defines: the ID decode and the albedo's treatment.
fn host_lean_defines(
    id_defines: &'static [(&'static str, &'static str)],
    albedo: HostAlbedo,
) -> Vec<(&'static str, &'static str)> {
    let mut defines = id_defines.to_vec();
    match albedo {
        HostAlbedo::None => {}
        HostAlbedo::Excluded => defines.push(("LUCENT_SSS_HOST_ALBEDO", "1")),
        HostAlbedo::Included => defines.push(("LUCENT_SSS_HOST_ALBEDO", "2")),
    }
    defines
}

/// What the host LEAN pass writes: the G-buffer targets LCB's, LBB's and the bilateral blur's
/// chains read, in lucent's layout.
pub struct HostLeanTargets {
    /// The lit diffuse, the view-plane LEAN slope x in alpha (the chains' `diffuse`).
    pub diffuse: Handle<Image>,
    /// The LEAN slope y and moments ([`LeanInputs::view_plane`]).
    pub view_plane: Handle<Image>,
    /// Albedo + specular intensity ([`LeanInputs::gb0`]).
    pub gb0: Handle<Image>,
    /// Normal + roughness ([`LeanInputs::gb1`]).
    pub gb1: Handle<Image>,
}

/// The G-buffer targets the LEAN chains read, made from a host's lit diffuse, normals and
/// material IDs (lucent::embed; `glsl/sss/host_lean.frag`): one fullscreen pass with four
/// colour outputs, where lucent's own frames write them in the G-buffer pass. `decode` is the
/// per-frame region of the host's normal encoding and its materials' surfaces (binding 2);
/// `albedo` the host's albedo image when [`HostAlbedo`] reads one.
#[allow(clippy::too_many_arguments)]
pub fn host_lean_pass(
    graph: &mut RenderGraph,
    inputs: &SssInputs<'_>,
    normals: &Handle<Image>,
    albedo: Option<(&Handle<Image>, HostAlbedo)>,
    decode: &'static crate::gpu_scene::Region,
    width: u32,
    height: u32,
    scene: Option<&Arc<SceneGpu>>,
) -> HostLeanTargets {
    let info = |format| crate::graph::ImageInfo {
        width,
        height,
        format,
    };
    let mut targets = HostLeanTargets {
        diffuse: graph.create_image("sss.host diffuse", info(crate::features::util::HDR_FORMAT)),
        view_plane: graph.create_image("sss.host lean", info(crate::features::util::LEAN_FORMAT)),
        gb0: graph.create_image("sss.host albedo", info(HOST_GB0_FORMAT)),
        gb1: graph.create_image("sss.host normal", info(HOST_GB1_FORMAT)),
    };
    let mode = albedo.map_or(HostAlbedo::None, |(_, mode)| mode);
    let mut pass = FullscreenPass::new(graph, "sss lean in", HOST_LEAN_FRAGMENT, scene);
    pass.per_frame(&FRAME)
        .per_frame(&tables::PROFILES)
        .per_frame(decode)
        .sample("diffuse_tex", inputs.diffuse)
        .sample("normal_tex", normals)
        .sample("profile_tex", inputs.profile_ids);
    if let Some((albedo, _)) = albedo {
        pass.sample("albedo_tex", albedo);
    }
    pass.defines(&host_lean_defines(inputs.ids.defines(), mode))
        .specialize(&inputs.specialization())
        // The LEAN texels only where a chain blurs (its tiles: the host's regions); elsewhere
        // the light alone, which the chains' final passes pass through.
        .variant(HOST_LEAN_PASSTHROUGH.to_vec())
        .tiles(|scene, ctx| {
            // Each chain's tiles cover the screen, marked on its own materials' regions: the
            // union marks every tile some chain blurs (a chain on the whole screen: all).
            let chains = &scene.per_frame.tiles(ctx.frame).sss;
            let partitions: Option<Vec<&[crate::gpu_scene::TileRect]>> =
                chains.iter().map(|c| c.as_deref()).collect();
            Some(crate::gpu_scene::tiles::union_of_marked(partitions?))
                .filter(|_| !chains.is_empty())
        });
    for target in [
        &mut targets.diffuse,
        &mut targets.view_plane,
        &mut targets.gb0,
        &mut targets.gb1,
    ] {
        pass.color(target, crate::graph::LoadOp::DontCare);
    }
    pass.finish();
    targets
}

/// The host LEAN pass's variant drawn outside the chains' tiles: the light alone.
const HOST_LEAN_PASSTHROUGH: &[(&str, &str)] = &[("LUCENT_SSS_PASSTHROUGH", "1")];

/// The host LEAN pass's GB0 and GB1 counterparts, as lucent's production (`compact`) G-buffer
/// keeps them: albedo and specular intensity in 8 bits, normal and roughness in fp16.
const HOST_GB0_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
const HOST_GB1_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// Adds the SSS pass permutations a host's frame has beyond lucent's own, for the shipped
/// SPIR-V: its shadow map read with reversed Z and as an array, its unsigned IDs
/// ([`IdMap::defines`]), and the host albedo and LEAN passes.
pub fn host_id_permutations(out: &mut Vec<crate::backend::shader::PipelineShaders>) {
    type Shaders = crate::backend::shader::PipelineShaders;
    let with = |p: &Shaders, defines: &[(&str, &str)]| {
        let mut p = p.clone();
        p.defines.extend(
            defines
                .iter()
                .map(|(name, value)| (name.to_string(), value.to_string())),
        );
        p
    };
    let own: Vec<Shaders> = out
        .iter()
        .filter(|p| p.fragment.starts_with("sss/"))
        .cloned()
        .collect();
    // A host's shadow map may store reversed Z, and may be an array (its cascades, a cube's
    // faces), or an atlas with an array beside it; its passes without shadows are lucent's
    // own.
    let mut host: Vec<Shaders> = Vec::new();
    for p in &own {
        if p.defines.iter().any(|(name, _)| name == "LUCENT_SHADOWS") {
            let reversible = with(p, SHADOW_REVERSIBLE);
            host.push(with(&reversible, SHADOW_ARRAY));
            host.push(with(&reversible, SHADOW_SECOND_MAP));
            host.push(reversible);
        }
    }
    out.extend(host.iter().cloned());
    for uint in [false, true] {
        let ids = if uint { HOST_IDS_UINT } else { &[] };
        for included in [false, true] {
            out.push(Shaders::new(
                "fullscreen.vert",
                HOST_ALBEDO_FRAGMENT,
                &host_albedo_defines(ids, included),
            ));
        }
        for albedo in HostAlbedo::ALL {
            let defines = host_lean_defines(ids, albedo);
            out.push(Shaders::new("fullscreen.vert", HOST_LEAN_FRAGMENT, &defines));
            let with_passthrough: Vec<_> = defines
                .iter()
                .chain(HOST_LEAN_PASSTHROUGH)
                .copied()
                .collect();
            out.push(Shaders::new(
                "fullscreen.vert",
                HOST_LEAN_FRAGMENT,
                &with_passthrough,
            ));
        }
        if uint {
            for p in own.iter().chain(&host) {
                out.push(with(p, ids));
            }
        }
    }
}

/// The tile rectangles of `chain` in the recorded frame (`None`: the whole screen).
fn chain_tiles(
    scene: &SceneGpu,
    ctx: &RecordContext<'_>,
    chain: usize,
) -> Option<Vec<crate::gpu_scene::TileRect>> {
    scene
        .per_frame
        .tiles(ctx.frame)
        .sss
        .get(chain)
        .cloned()
        .flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// glsl/common/sss.glsl `sss_host_profile`, step for step, on the table's rows.
    fn host_profile(rows: &[[u32; 4]; 16], host_id: u32) -> usize {
        let id = host_id.min(255) as usize;
        let word = rows[id / 16][(id / 4) % 4];
        let profile = ((word >> (8 * (id % 4))) & 255) as usize % MAX_SSS_PROFILES;
        if host_id > 255 {
            0
        } else {
            profile
        }
    }

    /// Each host ID's profile number when material `i` of `materials` (its host ID) has
    /// profile i + 1, as `lucent::embed` numbers them.
    fn profile_of(materials: &[u8]) -> Vec<u8> {
        let mut profile_of = vec![0u8; 256];
        for (index, &id) in materials.iter().enumerate() {
            profile_of[usize::from(id)] = index as u8 + 1;
        }
        profile_of
    }

    #[test]
    fn host_ids_map_to_their_profiles_and_every_other_id_to_none() {
        for materials in [vec![17u8], vec![17, 42, 5, 255, 1], (1..32).rev().collect()] {
            let profile_of = profile_of(&materials);
            let map = IdMap {
                uint: true,
                channel: 0,
                shift: 0,
                mask: 0xff,
                unorm_max: 0,
                profile_of: profile_of.clone(),
            };
            let (_, rows) = map.rows();
            for id in 0..256u32 {
                assert_eq!(
                    host_profile(&rows, id),
                    usize::from(profile_of[id as usize]),
                    "ID {id} of {materials:?}"
                );
            }
            // A 16-bit ID image's IDs past 255 have no profile.
            assert_eq!(host_profile(&rows, 256 + 17), 0);
            assert_eq!(host_profile(&rows, 4096), 0);
        }
    }

    /// glsl/common/sss.glsl `sss_host_profile` with the specialization constants
    /// ([`SssInputs::specialization`]), step for step: IDs that are the profile numbers, the
    /// listed IDs compared in order, or the table when none are listed.
    fn specialized_profile(constants: &[u32], rows: &[[u32; 4]; 16], host_id: u32) -> usize {
        let up_to = constants[22];
        if up_to > 0 {
            let up_to = up_to.min(MAX_SSS_PROFILES as u32 - 1);
            return if host_id <= up_to { host_id as usize } else { 0 };
        }
        let listed = constants[4];
        if listed == 0 {
            return host_profile(rows, host_id);
        }
        let mut p = 0;
        for k in 0..LISTED_HOST_IDS {
            if host_id == constants[5 + k] {
                p = constants[5 + LISTED_HOST_IDS + k] as usize;
            }
        }
        p
    }

    /// The constants of [`SssInputs::specialization`] for `map`.
    fn constants_of(map: &IdMap) -> Vec<u32> {
        pass_specialization(map, false)
    }

    #[test]
    fn ids_that_are_the_profile_numbers_need_no_lookup() {
        // lucent's own G-buffer: its profile numbers 1 to n, as its description decodes them.
        for n in [1usize, 3, 31] {
            let own = IdMap::lucent(n).unwrap();
            assert_eq!(constants_of(&own)[..4], [0, 0, 0xff, 255], "R8_UNORM");
            assert_eq!(constants_of(&own)[22], n as u32);
            assert_eq!(constants_of(&own)[4], 0, "nothing listed");
        }
        // Hosts with more materials than are listed, numbered 1 to n in order.
        for n in [1u8, 12, 31] {
            let mut map = IdMap::lucent(1).unwrap();
            map.uint = true;
            map.profile_of = profile_of(&(1..=n).collect::<Vec<u8>>());
            let constants = constants_of(&map);
            assert_eq!(constants[22], u32::from(n));
            assert_eq!(constants[4], 0, "nothing listed");
            let (_, rows) = map.rows();
            for id in 0..=300u32 {
                let want = map.profile_of.get(id as usize).map_or(0, |&p| usize::from(p));
                assert_eq!(specialized_profile(&constants, &rows, id), want, "ID {id}");
                assert_eq!(host_profile(&rows, id), want, "the table's ID {id}");
            }
        }
        // One ID out of order: the IDs are listed instead.
        let mut map = IdMap::lucent(3).unwrap();
        map.profile_of = profile_of(&[1, 3, 2]);
        assert_eq!(constants_of(&map)[22], 0);
        assert_eq!(constants_of(&map)[4], 3);
    }

    #[test]
    fn listed_host_ids_find_the_profiles_the_table_holds() {
        let eight: Vec<u8> = vec![200, 3, 1, 77, 255, 0x40, 9, 128];
        let nine: Vec<u8> = vec![1, 2, 3, 4, 5, 6, 7, 8, 10];
        for (materials, listed) in [(vec![17u8], 1), (vec![17, 42, 5], 3), (eight, 8), (nine, 0)] {
            let profile_of = profile_of(&materials);
            let map = IdMap {
                uint: false,
                channel: 3,
                shift: 4,
                mask: 0xf,
                unorm_max: 255,
                profile_of: profile_of.clone(),
            };
            let constants = constants_of(&map);
            assert_eq!(constants.len(), 23);
            assert_eq!(constants[..5], [3, 4, 0xf, 255, listed]);
            assert_eq!(constants[22], 0, "{materials:?}: not the profile numbers");
            let (_, rows) = map.rows();
            for id in 0..=256u32 {
                let want = profile_of.get(id as usize).map_or(0, |&p| usize::from(p));
                assert_eq!(specialized_profile(&constants, &rows, id), want, "ID {id}");
            }
        }
    }

    #[test]
    fn steps_add_up_to_each_gaussian_and_weights_to_one() {
        let skin = SssProfile::preset("skin").unwrap();
        let steps = blur_steps(&skin);
        assert_eq!(steps.len(), 6);
        let mut variance = 0.0f32;
        for (step, g) in steps.iter().zip(&skin.gaussians) {
            variance += (step.sigma / skin.units_per_mm).powi(2);
            assert!((variance - g.variance).abs() < 1e-4 * g.variance.max(1.0));
        }
        for c in 0..3 {
            let total: f32 = steps.iter().map(|s| s.weight[c]).sum();
            assert!((total - 1.0).abs() < 1e-5, "channel {c}: {total}");
        }
    }

    #[test]
    fn equal_variances_and_empty_channels_stay_finite() {
        let mut p = SssProfile::preset("skin").unwrap();
        p.gaussians[1].variance = p.gaussians[0].variance;
        for g in &mut p.gaussians {
            g.weight.z = 0.0;
        }
        let steps = blur_steps(&p);
        assert!(steps
            .iter()
            .all(|s| s.sigma.is_finite() && s.weight.iter().all(|w| w.is_finite())));
        assert_eq!(steps[1].sigma, 0.0);
        assert_eq!(steps[0].weight[2], 1.0, "blue keeps its light unblurred");
    }
}
