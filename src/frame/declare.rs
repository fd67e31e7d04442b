use std::sync::Arc;

use super::{FrameFeatures, FrameSettings};
use crate::backend::access::Access;
use crate::features::debug_view::{self};
use crate::features::deferred::GBufferLayout;
use crate::features::{deferred, sss, tonemap};
use crate::gpu_scene::SceneGpu;
use crate::graph::{Plan, RenderGraph, ResourceId};
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
    /// Screen-space SSS strength (frames with SSS).
    pub sss: Option<ResourceId>,
    /// View-plane LEAN slope y and second moments (LCB and LBB frames).
    pub lean: Option<ResourceId>,
    /// Depth.
    pub depth: ResourceId,
    /// Its layout.
    pub layout: GBufferLayout,
}

/// The images a frame hands out.
#[derive(Clone, Copy, Debug)]
pub struct FrameOutputs {
    /// Display image (RGBA8, sRGB-encoded), left in TRANSFER_SRC layout.
    pub display: ResourceId,
    /// Linear HDR image (RGBA16F), when exported.
    pub hdr: Option<ResourceId>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferOutputs>,
}

/// Declares every pass of a frame. `scene_gpu` is `None` for plan-only graphs.
pub fn declare_frame(
    graph: &mut RenderGraph,
    settings: &FrameSettings,
    features: &FrameFeatures,
    scene_gpu: Option<&Arc<SceneGpu>>,
) -> FrameOutputs {
    let layout = features.gbuffer_layout(settings);
    let gb = deferred::gbuffer_pass(graph, settings.width, settings.height, layout, scene_gpu);
    let lit = deferred::lighting_pass(graph, &gb, scene_gpu);
    let debug_display = settings
        .debug_view
        .and_then(|view| debug_view::debug_view_pass(graph, view, &gb, &lit, scene_gpu));
    let hdr = match (&features.sss, &lit.specular, &gb.sss) {
        (Some((profile, blur)), Some(specular), Some(strength)) => sss::sss_passes(
            graph,
            &sss::SssInputs {
                diffuse: &lit.color,
                specular,
                depth: &gb.depth,
                strength,
                lean: gb.lean.as_ref(),
                gb0: &gb.gb0,
            },
            profile,
            *blur,
            &settings.sss,
            scene_gpu,
        ),
        _ => lit.color,
    };
    let display = debug_display.unwrap_or_else(|| tonemap::tonemap_pass(graph, &hdr, scene_gpu));
    graph.export_image(&display, Access::TransferRead);
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
        {
            graph.export_image(image, Access::TransferRead);
        }
        GBufferOutputs {
            gb0: gb.gb0.id(),
            gb1: gb.gb1.id(),
            gb2: gb.gb2.as_ref().map(|h| h.id()),
            sss: gb.sss.as_ref().map(|h| h.id()),
            lean: gb.lean.as_ref().map(|h| h.id()),
            depth: gb.depth.id(),
            layout,
        }
    });
    FrameOutputs {
        display: display.id(),
        hdr: hdr_id,
        gbuffer,
    }
}

/// Compiles the plan of a frame without a GPU (for `lucent plan` and tests).
pub fn plan_frame(settings: &FrameSettings, features: &FrameFeatures) -> Result<Plan> {
    let mut graph = RenderGraph::new();
    declare_frame(&mut graph, settings, features, None);
    graph.plan(settings.compile)
}
