//! The render graph: declare → compile → execute. It knows nothing about techniques.
//!
//! - [`declare`]: a frame's resources and passes, with versioned handles (`&Handle` reads,
//!   `&mut Handle` writes).
//! - [`compile`]: turns the declaration into a [`Plan`], plain data: culling, ordering, merging
//!   into subpasses, aliasing, barriers. No GPU needed, so it is unit-tested on the CPU.
//! - [`dump`]: the plan as text (`lucent plan`).
//! - [`execute`]: creates the physical images, render passes and framebuffers of a plan, and
//!   records it into any command buffer the caller gives, with one debug label and one timestamp
//!   pair per physical pass under the same name.
//!
//! A technique implements [`PassExec`] for each of its passes: `prepare` creates pipelines once
//! the render pass and subpass are known, `record` draws.
//!
//! Declaring and compiling needs no GPU:
//!
//! ```
//! use ash::vk;
//! use lucent::backend::access::Access;
//! use lucent::graph::{CompileOptions, ImageInfo, LoadOp, PassKind, RenderGraph};
//!
//! let size = |format| ImageInfo { width: 64, height: 64, format };
//! let mut graph = RenderGraph::new();
//! let mut albedo = graph.create_image("albedo", size(vk::Format::R8G8B8A8_UNORM));
//! let mut lit = graph.create_image("lit", size(vk::Format::R16G16B16A16_SFLOAT));
//! let mut pass = graph.add_pass("gbuffer", PassKind::Raster);
//! pass.color(&mut albedo, LoadOp::Clear([0.0; 4]));
//! pass.finish(); // a real pass calls `execute(its PassExec)` instead
//! let mut pass = graph.add_pass("lighting", PassKind::Raster);
//! pass.input(&albedo).color(&mut lit, LoadOp::DontCare);
//! pass.finish();
//! graph.export_image(&lit, Access::TransferRead);
//!
//! let plan = graph.plan(CompileOptions::default()).unwrap();
//! // Same-pixel read: merged into one render pass with two subpasses.
//! assert_eq!(plan.physical.len(), 1);
//! assert_eq!(plan.physical[0].name, "gbuffer + lighting");
//! println!("{}", plan.dump());
//! ```

pub mod compile;
pub mod declare;
pub mod dump;
pub mod execute;
pub mod plan;

pub use compile::{CompileOptions, Plan};
pub use declare::{
    Handle, Image, ImageInfo, ImportedImage, LoadOp, MeshDraws, MeshViews, PassKind, PingPong,
    RenderGraph, ResourceId,
};
pub use execute::{Executable, PrepareContext, RecordContext, Subresources};

use crate::backend::GpuContext;
use crate::Result;

/// The code behind one pass.
pub trait PassExec: Send {
    /// Creates pipelines and descriptor sets, once the plan placed the pass (render pass and
    /// subpass for raster passes) and the physical images exist.
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()>;
    /// Records the pass. The executor has already begun the render pass / subpass and set the
    /// viewport and scissor to the full extent (pipelines use dynamic viewport and scissor).
    fn record(&self, ctx: &RecordContext<'_>);
    /// Writes `view` as imported image `id` into the descriptors the pass reads it through for
    /// frame slot `slot` (an import bound at record time, [`Executable::bind_imports`]). Only
    /// passes that read imports through descriptors are asked; the default refuses.
    fn bind_view(
        &mut self,
        _gpu: &GpuContext,
        _slot: usize,
        id: ResourceId,
        _view: ash::vk::ImageView,
    ) -> Result<()> {
        Err(crate::LucentError::Graph(format!(
            "this pass cannot read imported image {id} bound per frame through its descriptors"
        )))
    }
    /// Destroys what `prepare` created.
    fn destroy(&mut self, gpu: &GpuContext);
}
