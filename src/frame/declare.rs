//! [`declare_frame`]: the one place that decides which passes a frame has, from its
//! [`FrameDesc`]; `lucent plan` calls it without a GPU ([`plan_frame`]), the
//! [`super::Renderer`] with one.

use std::sync::Arc;

use ash::vk;

use super::{FrameDesc, FrameSettings};
use crate::backend::access::Access;
use crate::features::antialias::{self, Antialias};
use crate::features::debug_view;
use crate::features::gbuffer::{self, GBufferLayout};
use crate::features::technique::FrameImages;
use crate::features::{lighting, shadows, sss, tonemap};
use crate::gpu_scene::SceneGpu;
use crate::graph::{CompileOptions, ImageInfo, ImportedImage, Plan, RenderGraph, ResourceId};
use crate::Result;

/// The G-buffer images a frame hands out when asked to (`export_gbuffer`).
#[derive(Clone, Copy, Debug)]
pub struct GBufferOutputs {
    /// Albedo + specular.
    pub gb0: ResourceId,
    /// Normal + roughness.
    pub gb1: ResourceId,
    /// Thickness + material ID (frames with translucency).
    pub gb2: Option<ResourceId>,
    /// Screen-space SSS profile ID (frames with SSS).
    pub sss: Option<ResourceId>,
    /// View-plane LEAN slope y and second moments (LCB and LBB frames).
    pub lean: Option<ResourceId>,
    /// Li et al.'s layered material IDs (frames with layered media).
    pub layered: Option<ResourceId>,
    /// The `TexDep` texels (frames whose layered media read depth textures).
    pub layer_depths: Option<ResourceId>,
    /// Depth.
    pub depth: ResourceId,
    /// Its layout.
    pub layout: GBufferLayout,
}

/// The images a frame hands out.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    /// Display image: lucent's own (RGBA8, sRGB-encoded, left in TRANSFER_SRC layout), or the
    /// caller's target (imported, left in its `final_access` state).
    pub display: ResourceId,
    /// Whether `display` is the caller's target.
    pub target: bool,
    /// Linear HDR image (RGBA16F), when exported.
    pub hdr: Option<ResourceId>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferOutputs>,
    /// The lit diffuse and specular before the SSS blurs, when exported (frames with SSS).
    pub lit: Option<(ResourceId, ResourceId)>,
    /// The tonemapped image the anti-aliasing reads (sRGB RGBA8, luma in alpha), when
    /// exported (`export_ldr` in a frame with anti-aliasing).
    pub ldr: Option<ResourceId>,
    /// The light-space maps' depth atlas, when exported (`export_shadows` in a frame with
    /// them).
    pub shadows: Option<ResourceId>,
}

/// Declares every pass of a frame. `scene_gpu` is `None` for plan-only graphs.
pub fn declare_frame(
    graph: &mut RenderGraph,
    settings: &FrameSettings,
    desc: &FrameDesc,
    scene_gpu: Option<&Arc<SceneGpu>>,
) -> FrameOutputs {
    let layout = desc.gbuffer_layout(settings);
    // The light-space maps come first: the G-buffer pass and lighting share one render pass.
    let shadow_maps = desc
        .shadows
        .as_ref()
        .map(|s| shadows::shadow_pass(graph, s, scene_gpu));
    let gb = gbuffer::gbuffer_pass(graph, settings.width, settings.height, layout, scene_gpu);
    let lit = lighting::lighting_pass(
        graph,
        &gb,
        shadow_maps.as_ref(),
        (layout.sss_texturing || layout.sss_medium).then_some(&sss::tables::PROFILES),
        scene_gpu,
    );
    let display_info = ImageInfo {
        width: settings.width,
        height: settings.height,
        format: settings
            .target
            .map_or(tonemap::LDR_FORMAT, |target| target.format),
    };
    // The image the frame ends in, declared by the pass that writes it (so resources keep the
    // order they had before targets existed). The caller's target enters with the state the
    // caller promises; its image is bound per frame (`Renderer::bind_target`).
    let new_display = |graph: &mut RenderGraph| match settings.target {
        Some(target) => graph.import_image(
            "target",
            display_info,
            ImportedImage {
                image: vk::Image::null(),
                view: vk::ImageView::null(),
                initial: target.initial,
            },
        ),
        None => graph.create_image("display", display_info),
    };
    let debug_display = settings.debug_view.and_then(|view| {
        debug_view::debug_view_pass(graph, view, &gb, &lit, new_display, scene_gpu)
    });
    // Exported before the parts' passes are declared; they only read the two images, so
    // the exported contents are the lighting pass's (the specular is apart only in frames
    // with SSS).
    let lit_ids = match (&lit.specular, settings.export_lit) {
        (Some(specular), true) => {
            graph.export_image(&lit.color, Access::TransferRead);
            graph.export_image(specular, Access::TransferRead);
            Some((lit.color.id(), specular.id()))
        }
        _ => None,
    };
    // Each part's passes after the lighting pass, in registry order (GDC 2011's term runs
    // inside the lighting pass; the SSS chains blur the lit diffuse light; Li et al.'s terms
    // add into the result).
    let lighting::Lit {
        color: mut hdr,
        specular,
    } = lit;
    let images = FrameImages {
        gbuffer: &gb,
        specular: specular.as_ref(),
        shadow_maps: shadow_maps.as_ref(),
    };
    let knobs = settings.part_knobs();
    for part in desc.parts() {
        hdr = part.declare(graph, &images, hdr, &knobs, scene_gpu);
    }
    let mut ldr_id = None;
    let display = match (debug_display, settings.antialias) {
        (Some(display), _) => display,
        (None, Antialias::Off) => {
            let display = new_display(graph);
            tonemap::tonemap_pass(graph, &hdr, display, scene_gpu)
        }
        (None, Antialias::Fxaa) => {
            // The tonemap writes an intermediate image (colour + luma) the FXAA pass samples
            // around each pixel: a neighbourhood read, so the two stay separate passes.
            let ldr = graph.create_image(
                "ldr",
                ImageInfo {
                    width: settings.width,
                    height: settings.height,
                    format: tonemap::LDR_FORMAT,
                },
            );
            let ldr = tonemap::tonemap_with_luma_pass(graph, &hdr, ldr, scene_gpu);
            if settings.export_ldr {
                graph.export_image(&ldr, Access::TransferRead);
                ldr_id = Some(ldr.id());
            }
            let display = new_display(graph);
            antialias::fxaa_pass(graph, &ldr, display, scene_gpu)
        }
    };
    graph.export_image(
        &display,
        settings
            .target
            .map_or(Access::TransferRead, |target| target.final_access),
    );
    let hdr_id = settings.export_hdr.then(|| {
        graph.export_image(&hdr, Access::TransferRead);
        hdr.id()
    });
    let gbuffer = settings.export_gbuffer.then(|| {
        for image in [&gb.gb0, &gb.gb1, &gb.depth]
            .into_iter()
            .chain(gb.gb2.as_ref())
            .chain(gb.sss.as_ref())
            .chain(gb.lean.as_ref())
            .chain(gb.layered.as_ref())
            .chain(gb.layer_depths.as_ref())
        {
            graph.export_image(image, Access::TransferRead);
        }
        GBufferOutputs {
            gb0: gb.gb0.id(),
            gb1: gb.gb1.id(),
            gb2: gb.gb2.as_ref().map(|h| h.id()),
            sss: gb.sss.as_ref().map(|h| h.id()),
            lean: gb.lean.as_ref().map(|h| h.id()),
            layered: gb.layered.as_ref().map(|h| h.id()),
            layer_depths: gb.layer_depths.as_ref().map(|h| h.id()),
            depth: gb.depth.id(),
            layout,
        }
    });
    let shadows = shadow_maps
        .as_ref()
        .filter(|_| settings.export_shadows)
        .map(|maps| {
            graph.export_image(&maps.depth, Access::TransferRead);
            maps.depth.id()
        });
    FrameOutputs {
        display: display.id(),
        target: settings.target.is_some(),
        hdr: hdr_id,
        lit: lit_ids,
        ldr: ldr_id,
        gbuffer,
        shadows,
    }
}

/// The compiler options of a frame: `settings.compile`, with frames chained when several are
/// in flight.
pub fn compile_options(settings: &FrameSettings) -> CompileOptions {
    CompileOptions {
        chained_frames: settings.compile.chained_frames || settings.frames_in_flight > 1,
        ..settings.compile
    }
}

/// Compiles the plan of a frame without a GPU (for `lucent plan` and tests).
pub fn plan_frame(settings: &FrameSettings, desc: &FrameDesc) -> Result<Plan> {
    desc.check_described(settings)?;
    let mut graph = RenderGraph::new();
    declare_frame(&mut graph, settings, desc, None);
    graph.plan(compile_options(settings))
}
