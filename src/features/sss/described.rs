//! The SSS passes on a described G-buffer ([`GBufferDesc`]): the one declaration that both
//! lucent's own frames ([`super::part`], their G-buffer described by
//! [`crate::features::gbuffer::GBufferLayout::described`]) and a host's frames
//! (`lucent::embed::SssEffect`, the host's own description) go through. What differs between
//! the two is only what the description says: how the diffuse holds the albedo (an adapter
//! pass puts it right when it differs from what a profile wants before the blur), whether the
//! LEAN targets are given or built from the normals, whether the specular is kept apart,
//! where the depth is read, and how the shadow maps are laid out.

use std::sync::Arc;

use super::{host_albedo_pass, host_lean_pass, sss_passes, HostAlbedo, LeanInputs, SssInputs};
use super::{SssKnobs, SssProfiles};
use crate::features::gbuffer_desc::{DepthEncoding, DiffuseAlbedo, GBufferDesc};
use crate::features::lighting::HDR_FORMAT;
use crate::gpu_scene::{Region, SceneGpu};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, PassKind, RenderGraph};
use crate::scene::material::{SssProfile, Texturing};

/// The host LEAN pass's constants in the per-frame buffer (glsl/sss/host_lean.frag
/// `HostLean`: the normals' decode, the view-to-world matrix and each profile's surface),
/// written by the effect that builds the LEAN targets from a host's normals.
pub static HOST_LEAN: Region = Region::new("host LEAN decode", "HostLean");

/// The shadow maps the LEAN blurs' relit specular is shadowed by.
#[derive(Clone, Copy)]
pub struct DescribedShadows<'a> {
    /// The map (an atlas, or an array of layers when `array`).
    pub depth: &'a Handle<Image>,
    /// `depth` is an array of layers.
    pub array: bool,
    /// A second map beside an atlas: an array of layers.
    pub second: Option<&'a Handle<Image>>,
    /// Its faces may store reversed Z (a host's: each face says); lucent's own atlas stores
    /// standard Z only, and its passes carry no per-texel flip.
    pub reversible: bool,
}

/// The images of a described G-buffer, as handles of the graph the passes join.
#[derive(Clone, Copy)]
pub struct DescribedImages<'a> {
    /// The depth image.
    pub depth: &'a Handle<Image>,
    /// The lit diffuse light.
    pub diffuse: &'a Handle<Image>,
    /// The material IDs.
    pub material_ids: &'a Handle<Image>,
    /// The specular kept apart (`None`: a cleared image stands in).
    pub specular: Option<&'a Handle<Image>>,
    /// The albedo, when described.
    pub albedo: Option<&'a Handle<Image>>,
    /// The normals, when described.
    pub normals: Option<&'a Handle<Image>>,
    /// The LEAN targets (moments, albedo and specular, normal and roughness), when described.
    pub lean_targets: Option<[&'a Handle<Image>; 3]>,
    /// The shadow maps, when described.
    pub shadows: Option<DescribedShadows<'a>>,
}

/// Whether a diffuse that holds the albedo as `albedo` says must pass through `sss albedo in`
/// for these profiles: when some pixel's light must hold a different part of the albedo than
/// the described light does.
pub fn needs_albedo_pass<'p>(
    albedo: DiffuseAlbedo,
    mut profiles: impl Iterator<Item = &'p SssProfile>,
) -> bool {
    match albedo {
        // Pixels that do not scatter need the albedo in their light too.
        DiffuseAlbedo::Excluded => true,
        DiffuseAlbedo::Included => profiles.any(|p| p.texturing != Texturing::Pre),
        // The light holds what each profile wants before the blur already.
        DiffuseAlbedo::AsTexturing => false,
    }
}

/// Whether some profile applies its albedo after the blur (the passes then read the albedo).
pub fn applies_albedo_after<'p>(mut profiles: impl Iterator<Item = &'p SssProfile>) -> bool {
    profiles.any(|p| p.texturing != Texturing::Pre)
}

/// Declares the SSS passes of `profiles` over the G-buffer `gbuffer` describes, whose images
/// are `images`; returns the image the final pass wrote (`output`, or a new one). The
/// description has been checked by whoever built it (`GBufferDesc::check` and the effect's
/// own checks: the images each path needs are there).
pub fn sss_on_gbuffer(
    graph: &mut RenderGraph,
    gbuffer: &GBufferDesc,
    images: &DescribedImages<'_>,
    profiles: &SssProfiles,
    knobs: &SssKnobs,
    scene_gpu: Option<&Arc<SceneGpu>>,
    output: Option<Handle<Image>>,
) -> Handle<Image> {
    let (width, height) = (gbuffer.width, gbuffer.height);
    let each_profile = || profiles.profiles.iter().map(|(p, _)| p);
    let lean = profiles.lean();
    let albedo_pass = needs_albedo_pass(gbuffer.diffuse.albedo, each_profile());
    let cleared;
    let specular = match images.specular {
        Some(s) => s,
        None => {
            cleared = cleared_image(graph, width, height);
            &cleared
        }
    };
    let mut inputs = SssInputs {
        diffuse: images.diffuse,
        specular,
        depth: images.depth,
        profile_ids: images.material_ids,
        lean: None,
        shadow_depth: None,
        shadow_array: false,
        second_shadow_depth: None,
        shadow_reversible: false,
        albedo: None,
        // The diffuse's alpha is read only when it holds linear depth: then the taps read it
        // there; otherwise they read the depth image.
        depth_in_alpha: gbuffer.diffuse.depth_in_alpha,
        ids: &profiles.id_map,
        linear_depth: gbuffer.depth.encoding == DepthEncoding::LinearView,
    };
    let targets = images.lean_targets.filter(|_| lean);
    let normals = images.normals.filter(|_| lean && targets.is_none());
    let adjusted;
    let built_targets;
    // The diffuse put right where a profile wants its albedo otherwise (`sss albedo in`, which
    // keeps the alpha: the LEAN slope x of given LEAN targets), unless the LEAN pass that
    // builds the targets from the normals does it.
    if albedo_pass && normals.is_none() {
        let albedo = images.albedo.expect("the effect checks the albedo is described");
        let included = gbuffer.diffuse.albedo == DiffuseAlbedo::Included;
        adjusted = host_albedo_pass(graph, &inputs, albedo, included, width, height, scene_gpu);
        inputs.diffuse = &adjusted;
    }
    if let Some([moments, albedo_specular, normal_roughness]) = targets {
        // The LEAN targets as the G-buffer pass wrote them (lucent's own, or a host's).
        inputs.lean = Some(LeanInputs {
            view_plane: moments,
            gb0: albedo_specular,
            gb1: normal_roughness,
        });
    } else if let Some(normals) = normals {
        // The LEAN chains' G-buffer targets built from the normals, the albedo put right in
        // the same pass.
        let mode = match (albedo_pass, gbuffer.diffuse.albedo) {
            (false, _) => None,
            (true, DiffuseAlbedo::Included) => Some(HostAlbedo::Included),
            (true, DiffuseAlbedo::Excluded) => Some(HostAlbedo::Excluded),
            (true, DiffuseAlbedo::AsTexturing) => {
                unreachable!("needs_albedo_pass: the light is as the profiles want it")
            }
        };
        let host_albedo = mode.map(|mode| {
            let albedo = images.albedo.expect("the effect checks the albedo is described");
            (albedo, mode)
        });
        built_targets = host_lean_pass(
            graph,
            &inputs,
            normals,
            host_albedo,
            &HOST_LEAN,
            width,
            height,
            scene_gpu,
        );
        inputs.diffuse = &built_targets.diffuse;
        inputs.lean = Some(LeanInputs {
            view_plane: &built_targets.view_plane,
            gb0: &built_targets.gb0,
            gb1: &built_targets.gb1,
        });
    }
    if inputs.lean.is_some() {
        // The LEAN chains' diffuse carries the slope in its alpha, not depth; their specular
        // is shadowed by the described maps.
        inputs.depth_in_alpha = false;
        if let Some(shadows) = images.shadows {
            inputs.shadow_depth = Some(shadows.depth);
            inputs.shadow_array = shadows.array;
            inputs.second_shadow_depth = shadows.second;
            inputs.shadow_reversible = shadows.reversible;
        }
    }
    if applies_albedo_after(each_profile()) {
        inputs.albedo = images.albedo;
    }
    sss_passes(graph, &inputs, profiles, knobs, scene_gpu, output)
}

/// A transient image cleared to black by a pass that draws nothing (the specular a host did
/// not keep apart).
fn cleared_image(graph: &mut RenderGraph, width: u32, height: u32) -> Handle<Image> {
    let mut image = graph.create_image(
        "specular (none)",
        ImageInfo {
            width,
            height,
            format: HDR_FORMAT,
        },
    );
    let mut pass = graph.add_pass("clear specular", PassKind::Raster);
    pass.color(&mut image, LoadOp::Clear([0.0; 4]));
    pass.clears_only();
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_albedo_pass_runs_only_when_the_light_and_the_profiles_differ() {
        let profile = |texturing| SssProfile {
            texturing,
            ..SssProfile::preset("skin").expect("a preset")
        };
        let pre = [profile(Texturing::Pre)];
        let post = [profile(Texturing::Post), profile(Texturing::Pre)];
        assert!(!needs_albedo_pass(DiffuseAlbedo::Included, pre.iter()));
        assert!(needs_albedo_pass(DiffuseAlbedo::Included, post.iter()));
        assert!(needs_albedo_pass(DiffuseAlbedo::Excluded, pre.iter()));
        // lucent's own lighting pass writes the light as each texturing asks.
        assert!(!needs_albedo_pass(DiffuseAlbedo::AsTexturing, post.iter()));
        assert!(!applies_albedo_after(pre.iter()));
        assert!(applies_albedo_after(post.iter()));
    }
}
