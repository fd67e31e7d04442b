//! Deferred lighting: the pass that reads the G-buffer ([`super::gbuffer`]) at the same pixel
//! (input attachments, so the graph merges it with the G-buffer pass as a subpass) and the
//! light-space maps, when some light casts shadows, and writes lit HDR colour (with SSS,
//! diffuse and specular apart).
//!
//! With translucency (GDC 2011) the G-buffer has GB2 (thickness + material ID), and the
//! lighting pass is drawn as scissored rectangles of screen tiles: tiles that translucent objects
//! may cover (their projected bounding boxes, on the CPU each frame) get the shader with the
//! talk's per-light term, the others the plain shader. Only rasterisation reliably skips work on every
//! driver: lavapipe shades both sides of a per-pixel branch, and it runs input-attachment
//! shaders with late depth/stencil tests, so neither a material-ID branch nor a stencil mask
//! saves anything there (measured in docs/translucency.md).

use std::sync::Arc;

use crate::backend::shader::PipelineShaders;
use crate::gpu_scene::{Region, SceneGpu, FRAME};
use crate::graph::{Handle, Image, ImageInfo, LoadOp, RenderGraph};

use super::gbuffer::{all_layouts, GBuffer, GBufferLayout};
use super::pass::FullscreenPass;
use super::shadows::{self, ShadowMaps};
use super::util::Defines;

pub use super::util::HDR_FORMAT;

/// What the lighting pass writes.
pub struct Lit {
    /// Lit HDR colour; with SSS, the diffuse part only.
    pub color: Handle<Image>,
    /// With SSS: the specular part, added back after the blurs.
    pub specular: Option<Handle<Image>>,
}

/// Declares the lighting pass: reads the G-buffer at the same pixel (and the light-space maps,
/// when some light casts shadows), writes lit HDR colour (with SSS: diffuse and specular
/// apart). When some SSS profile applies its albedo after the blur
/// (`GBufferLayout::sss_texturing`) or transmits light through its medium
/// (`GBufferLayout::sss_medium`), it also reads the profile IDs and `sss_profiles`, the
/// SSS profile table's region (the SSS feature owns it), to leave that albedo out of the
/// diffuse light.
pub fn lighting_pass(
    graph: &mut RenderGraph,
    gb: &GBuffer,
    shadows: Option<&ShadowMaps>,
    sss_profiles: Option<&'static Region>,
    scene: Option<&Arc<SceneGpu>>,
) -> Lit {
    let info = graph.resources()[gb.gb0.id()].info;
    let hdr_info = ImageInfo {
        format: HDR_FORMAT,
        ..info
    };
    let mut hdr = graph.create_image(
        if gb.layout.sss {
            "lighting.diffuse"
        } else {
            "hdr"
        },
        hdr_info,
    );
    let mut specular = gb
        .layout
        .sss
        .then(|| graph.create_image("lighting.specular", hdr_info));
    let shadow_ids = shadows.map(|maps| maps.ids.is_some());
    let (plain, translucent) = lighting_defines(&gb.layout, shadow_ids);
    let mut pass = FullscreenPass::new(graph, "lighting", LIGHTING_FRAGMENT, scene);
    // The G-buffer always; GB2 and the material table with translucency; the profile IDs and
    // table with SSS texturing or media; the shadow table and atlases with shadows
    // (glsl/deferred/lighting.frag, glsl/common/shadows.glsl), each under the shader's name.
    pass.defines(&plain)
        .per_frame(&FRAME)
        .input("gb0", &gb.gb0)
        .input("gb1", &gb.gb1)
        .input("depth", &gb.depth);
    if let Some(gb2) = &gb.gb2 {
        pass.input("gb2", gb2)
            .per_frame(&super::translucency::TABLE_REGION);
    }
    if reads_profiles(&gb.layout) {
        let (Some(ids), Some(table)) = (&gb.sss, sss_profiles) else {
            panic!("a frame with SSS texturing or transmission has profile IDs and a table");
        };
        pass.input("profile_ids", ids).per_frame(table);
    }
    if let Some(maps) = shadows {
        pass.per_frame(&shadows::TABLE_REGION)
            .sample("shadow_depth", &maps.depth);
        if let Some(ids) = &maps.ids {
            pass.sample("shadow_ids", ids);
        }
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    if let Some(specular) = &mut specular {
        pass.color(specular, LoadOp::DontCare);
    }
    if let Some(extra) = translucent {
        // The translucent shader on the tiles translucent objects may cover, the plain one on
        // the others.
        pass.marked_variant(extra)
            .tiles(|scene, ctx| Some(scene.per_frame.tiles(ctx.frame).lighting.clone()));
    }
    pass.finish();
    Lit {
        color: hdr,
        specular,
    }
}

/// The lighting pass's fragment shader.
const LIGHTING_FRAGMENT: &str = "deferred/lighting.frag";

/// Whether the lighting pass reads the SSS profile IDs and table: some profile applies its
/// albedo after the blur, or transmits light through its medium.
fn reads_profiles(layout: &GBufferLayout) -> bool {
    layout.sss_texturing || layout.sss_medium
}

/// The lighting pass's defines: the plain shader's, and with translucency the extra ones of the
/// translucent variant (drawn on the tiles translucent objects may cover). `shadows`: some
/// light casts shadows, `Some(true)` when the atlas stores translucency IDs.
fn lighting_defines(layout: &GBufferLayout, shadows: Option<bool>) -> (Defines, Option<Defines>) {
    let mut plain: Vec<(&'static str, &'static str)> = Vec::new();
    if shadows.is_some() {
        plain.extend(shadows::LIGHTING_DEFINES);
    }
    if layout.sss {
        plain.push(("LUCENT_SPLIT_SPECULAR", "1"));
    }
    if reads_profiles(layout) {
        // The profile IDs and table (named for their first use: profiles in `pre` mode keep
        // their albedo in the light, sss_albedo_before).
        plain.push(("LUCENT_SSS_TEXTURING", "1"));
    }
    if layout.sss_medium {
        // Media's reflectance, and their transmission where light-space maps measure the
        // thickness (glsl/common/sss_medium.glsl).
        plain.push(("LUCENT_SSS_MEDIUM", "1"));
    }
    if layout.lean {
        plain.push(("LUCENT_LEAN", "1"));
    }
    if layout.depth_in_alpha {
        plain.push(("LUCENT_DEPTH_IN_ALPHA", "1"));
    }
    if layout.fault_injection {
        plain.push(("LUCENT_FAULT_INJECTION", "1"));
    }
    let translucent = layout.translucency.map(|_| {
        // The plain variant's defines (split specular, LEAN slope) plus the translucency's.
        let mut extra = layout.defines();
        if shadows == Some(true) {
            // Only the translucent variant shades transmission: only it reads the IDs.
            extra.push(("LUCENT_SHADOW_IDS", "1"));
        }
        extra
    });
    (plain, translucent)
}

/// The pipelines the lighting pass of any frame builds: every G-buffer layout, without
/// shadows and with them (with and without translucency IDs).
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for layout in all_layouts() {
        for shadows in [None, Some(false), Some(true)] {
            let (plain, translucent) = lighting_defines(&layout, shadows);
            let fullscreen =
                |defines: &[(&str, &str)]| PipelineShaders::fullscreen(LIGHTING_FRAGMENT, defines);
            out.push(fullscreen(&plain));
            if let Some(extra) = translucent {
                let mut all = plain.clone();
                all.extend(extra);
                out.push(fullscreen(&all));
            }
        }
    }
}
