//! Fullscreen passes that state each input once.
//!
//! A [`FullscreenPass`] is declared with one call chain: each [`sample`](FullscreenPass::sample),
//! [`input`](FullscreenPass::input) or [`color`](FullscreenPass::color) declares the graph access
//! and appends a descriptor binding under the name the shader gives the resource, and
//! [`per_frame`](FullscreenPass::per_frame) a region of the per-frame buffer under its uniform
//! block's name: the shader declares its resources without numbers, and the declaration's
//! order numbers them ([`crate::backend::bindings`]). The pass owns its pipeline (and the variant some passes draw
//! outside their tiles), its descriptor set and its samplers, and records the fullscreen
//! triangle over the whole screen or over tile rectangles. Declared without a scene on the GPU
//! (`lucent plan`), it declares the graph accesses only.
//!
//! Passes that draw meshes (the G-buffer, the light-space maps) keep their own
//! [`PassExec`].
//!
//! ```text
//! let mut pass = FullscreenPass::new(graph, "tonemap", "post/tonemap.frag", scene);
//! pass.per_frame(&FRAME)
//!     .sample(hdr)
//!     .color(&mut display, LoadOp::DontCare)
//!     .defines(defines);
//! pass.finish();
//! ```

use std::sync::Arc;

use ash::vk;

use super::util::{Defines, PassPipeline};
use crate::backend::descriptor::{clamp_sampler, Binding};
use crate::backend::pipeline::{GraphicsPipeline, GraphicsPipelineDesc};
use crate::gpu_scene::{Region, SceneGpu, TileRect};
use crate::graph::declare::PassBuilder;
use crate::graph::{
    Handle, Image, LoadOp, PassExec, PassKind, PrepareContext, RecordContext, RenderGraph,
    ResourceId,
};
use crate::Result;

/// The rectangles a pass draws in the recorded frame (`None`: the whole screen).
type Tiles = Box<dyn Fn(&SceneGpu, &RecordContext<'_>) -> Option<Vec<TileRect>> + Send>;

/// One descriptor binding, as declared.
#[derive(Clone, Copy, Debug)]
enum Slot {
    /// A region of the per-frame buffer (the shaders' name for it is its block's).
    PerFrame(&'static Region),
    /// An image the shaders name so, sampled through a clamp sampler with this filter.
    Sampled(&'static str, ResourceId, vk::Filter),
    /// An image the shaders name so, an input attachment in this layout.
    Input(&'static str, ResourceId, vk::ImageLayout),
}

impl Slot {
    /// The name the shaders give the binding, which numbers it there.
    fn name(&self) -> &'static str {
        match *self {
            Slot::PerFrame(region) => region.block,
            Slot::Sampled(name, ..) | Slot::Input(name, ..) => name,
        }
    }
}

/// A fullscreen raster pass being declared (see the module docs). Finish it with
/// [`FullscreenPass::finish`].
pub struct FullscreenPass<'g> {
    pass: PassBuilder<'g>,
    /// The scene on the GPU, which per-frame bindings and tiles read.
    scene: Option<Arc<SceneGpu>>,
    /// Whether the pass runs on a GPU (false: only planning, the graph accesses alone).
    runs: bool,
    /// The pass writes depth and its pipeline tests it ([`Self::depth`]).
    depth_test: bool,
    /// The pass's name (also its pipeline's).
    name: String,
    fragment: &'static str,
    slots: Vec<Slot>,
    defines: Defines,
    /// The fragment shader's specialization constants ([`Self::specialize`]).
    specialization: Vec<u32>,
    /// Colour attachments (bit i = location i) that add the shader's output.
    additive: u32,
    /// Colour attachments declared so far.
    colors: u32,
    push_constants: Vec<u8>,
    tiles: Option<Tiles>,
    variant: Option<Variant>,
}

/// A second pipeline of a tiled pass: the pass's defines plus `extra`, drawn in the tiles the
/// pass's own pipeline does not draw.
struct Variant {
    extra: Defines,
    /// Drawn in the marked (`translucent`) tiles, the pass's own pipeline in the others;
    /// otherwise the reverse.
    in_marked: bool,
    /// Its pipeline's name after the pass's (`pass-through`, `translucent`).
    label: &'static str,
}

impl<'g> FullscreenPass<'g> {
    /// Starts declaring the raster pass `name` drawing `fragment` (a shader under `glsl/`) over
    /// the fullscreen triangle. `scene` is `None` when only planning.
    pub fn new(
        graph: &'g mut RenderGraph,
        name: &str,
        fragment: &'static str,
        scene: Option<&Arc<SceneGpu>>,
    ) -> Self {
        Self {
            pass: graph.add_pass(name, PassKind::Raster),
            scene: scene.cloned(),
            runs: scene.is_some(),
            depth_test: false,
            name: name.to_string(),
            fragment,
            slots: Vec::new(),
            defines: Vec::new(),
            specialization: Vec::new(),
            additive: 0,
            colors: 0,
            push_constants: Vec::new(),
            tiles: None,
            variant: None,
        }
    }

    /// A pass that runs without a scene on the GPU (the benchmark's speed-of-light copies): it
    /// may sample images, but binds no per-frame region and draws no tiles.
    pub fn standalone(graph: &'g mut RenderGraph, name: &str, fragment: &'static str) -> Self {
        Self {
            runs: true,
            ..Self::new(graph, name, fragment, None)
        }
    }

    /// Writes the depth attachment, the pipeline testing (and writing) depth.
    pub fn depth(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.pass.depth(handle, load);
        self.depth_test = true;
        self
    }

    /// The graph pass being declared, for accesses that bind nothing (an image only declared
    /// as read, the taps per pixel).
    pub fn graph(&mut self) -> &mut PassBuilder<'g> {
        &mut self.pass
    }

    /// Binds a region of the per-frame buffer (a dynamic uniform buffer at the recorded
    /// frame's slot).
    pub fn per_frame(&mut self, region: &'static Region) -> &mut Self {
        self.slots.push(Slot::PerFrame(region));
        self
    }

    /// Samples the image (nearest texels) and binds it as the shaders' `name`.
    pub fn sample(&mut self, name: &'static str, handle: &Handle<Image>) -> &mut Self {
        self.sample_with(name, handle, vk::Filter::NEAREST)
    }

    /// Samples the image (`LINEAR`: taps between texels) and binds it as the shaders' `name`.
    pub fn sample_with(
        &mut self,
        name: &'static str,
        handle: &Handle<Image>,
        filter: vk::Filter,
    ) -> &mut Self {
        self.pass.sample(handle);
        self.slots.push(Slot::Sampled(name, handle.id(), filter));
        self
    }

    /// Binds an image the pass already declared a read of as the shaders' `name`, sampled
    /// with `filter` (an image the graph reads before the pass binds it).
    ///
    /// # Panics
    /// If the pass does not read the image's current version (a declaration bug).
    pub fn bind_sampled(
        &mut self,
        name: &'static str,
        handle: &Handle<Image>,
        filter: vk::Filter,
    ) -> &mut Self {
        assert!(
            self.pass.reads(handle),
            "pass '{}' binds an image it does not read",
            self.name
        );
        self.slots.push(Slot::Sampled(name, handle.id(), filter));
        self
    }

    /// Reads the image at the pixel being shaded (`subpassLoad`) and binds it as an input
    /// attachment, the shaders' `name`.
    pub fn input(&mut self, name: &'static str, handle: &Handle<Image>) -> &mut Self {
        let layout = self.pass.input_access(handle).info().layout;
        self.pass.input(handle);
        self.slots.push(Slot::Input(name, handle.id(), layout));
        self
    }

    /// Writes the next colour attachment (location = order of `color` calls).
    pub fn color(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.pass.color(handle, load);
        self.colors += 1;
        self
    }

    /// Writes the next colour attachment by adding the shader's output to it (`Load` keeps
    /// what is there; a first accumulation clears).
    pub fn color_add(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.additive |= 1 << self.colors;
        self.color(handle, load)
    }

    /// Adds a shader define.
    pub fn define(&mut self, name: &'static str, value: &'static str) -> &mut Self {
        self.defines.push((name, value));
        self
    }

    /// Adds shader defines.
    pub fn defines(&mut self, defines: &[(&'static str, &'static str)]) -> &mut Self {
        self.defines.extend_from_slice(defines);
        self
    }

    /// Sets the fragment shader's specialization constants (value `i` for `constant_id = i`),
    /// for what is fixed when the pass's pipeline is made: the driver folds them into the
    /// code, as it does defines, without a shader permutation per value.
    pub fn specialize(&mut self, constants: &[u32]) -> &mut Self {
        self.specialization = constants.to_vec();
        self
    }

    /// Samples the light-space maps' depth atlas: their defines (glsl/common/shadows.glsl),
    /// the shadow table and the atlas.
    pub fn shadows(&mut self, depth: &Handle<Image>) -> &mut Self {
        self.pass.sample(depth);
        self.bind_shadows(depth)
    }

    /// [`Self::shadows`] for a depth atlas the pass already declared a read of.
    pub fn bind_shadows(&mut self, depth: &Handle<Image>) -> &mut Self {
        self.defines(&super::shadows::LIGHTING_DEFINES);
        self.per_frame(&super::shadows::TABLE_REGION).bind_sampled(
            "shadow_depth",
            depth,
            vk::Filter::NEAREST,
        )
    }

    /// Push constants the pass pushes before drawing (visible to both stages).
    pub fn push_constants(&mut self, constants: &impl bytemuck::Pod) -> &mut Self {
        self.push_constants = bytemuck::bytes_of(constants).to_vec();
        self
    }

    /// Declares how many texture taps the shader makes per pixel ([`PassBuilder::taps`]).
    pub fn taps(&mut self, per_pixel: u32) -> &mut Self {
        self.pass.taps(per_pixel);
        self
    }

    /// Draws only in the rectangles `tiles` gives for the recorded frame (`None`: the whole
    /// screen): the pass's pipeline in the translucent ones, its [`variant`](Self::variant),
    /// if any, in the others.
    pub fn tiles(
        &mut self,
        tiles: impl Fn(&SceneGpu, &RecordContext<'_>) -> Option<Vec<TileRect>> + Send + 'static,
    ) -> &mut Self {
        self.tiles = Some(Box::new(tiles));
        self
    }

    /// A second pipeline with `extra` defines added, drawn in the tiles that are not
    /// translucent (the pass-through variant of a composing pass).
    pub fn variant(&mut self, extra: Defines) -> &mut Self {
        self.variant = Some(Variant {
            extra,
            in_marked: false,
            label: "pass-through",
        });
        self
    }

    /// A second pipeline with `extra` defines added, drawn in the marked (`translucent`)
    /// tiles, the pass's own pipeline in the others (the lighting pass's translucent shader).
    pub fn marked_variant(&mut self, extra: Defines) -> &mut Self {
        self.variant = Some(Variant {
            extra,
            in_marked: true,
            label: "translucent",
        });
        self
    }

    /// The shader defines declared so far: what the pipeline is built with once the pass is
    /// finished.
    pub fn shader_defines(&self) -> &[(&'static str, &'static str)] {
        &self.defines
    }

    /// Finishes the declaration: with a scene on the GPU, the pass with the code that
    /// records it; when only planning, the graph accesses alone.
    pub fn finish(self) {
        if !self.runs {
            self.pass.finish();
            return;
        }
        self.pass.execute(FullscreenExec {
            scene: self.scene,
            depth_test: self.depth_test,
            name: self.name,
            fragment: self.fragment,
            slots: self.slots,
            defines: self.defines,
            specialization: self.specialization,
            additive: self.additive,
            push_constants: self.push_constants,
            tiles: self.tiles,
            variant: self.variant,
            samplers: Vec::new(),
            pipeline: None,
            bare: None,
            variant_pipeline: None,
        });
    }
}

/// The code behind a [`FullscreenPass`].
struct FullscreenExec {
    scene: Option<Arc<SceneGpu>>,
    depth_test: bool,
    name: String,
    fragment: &'static str,
    slots: Vec<Slot>,
    defines: Defines,
    specialization: Vec<u32>,
    additive: u32,
    push_constants: Vec<u8>,
    tiles: Option<Tiles>,
    variant: Option<Variant>,
    /// One clamp sampler per filter the bindings use.
    samplers: Vec<(vk::Filter, vk::Sampler)>,
    pipeline: Option<PassPipeline>,
    /// A pass without bindings: its pipeline, without a descriptor set.
    bare: Option<GraphicsPipeline>,
    variant_pipeline: Option<GraphicsPipeline>,
}

/// The clamp sampler with `filter` among `samplers`, made on first use.
fn sampler(
    samplers: &mut Vec<(vk::Filter, vk::Sampler)>,
    ctx: &PrepareContext<'_>,
    filter: vk::Filter,
) -> Result<vk::Sampler> {
    if let Some(&(_, sampler)) = samplers.iter().find(|(f, _)| *f == filter) {
        return Ok(sampler);
    }
    let sampler = clamp_sampler(ctx, filter)?;
    samplers.push((filter, sampler));
    Ok(sampler)
}

impl PassExec for FullscreenExec {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let views = ctx.descriptor_views;
        let mut bindings = Vec::with_capacity(self.slots.len());
        for slot in &self.slots {
            let binding = match *slot {
                Slot::PerFrame(region) => {
                    let scene = self.scene.as_ref().ok_or_else(|| {
                        crate::LucentError::Graph(format!(
                            "pass '{}' binds the per-frame region '{}' without a scene",
                            self.name, region.name
                        ))
                    })?;
                    Binding::PerFrame(scene.per_frame.binding(region))
                }
                Slot::Sampled(_, id, filter) => {
                    let sampler = sampler(&mut self.samplers, ctx, filter)?;
                    if views[id] == vk::ImageView::null() {
                        // A host's image bound when its frame is recorded (bind_view).
                        Binding::SampledPerSlot(sampler)
                    } else {
                        Binding::Sampled(views[id], sampler)
                    }
                }
                Slot::Input(_, id, layout) => Binding::InputAttachment(views[id], layout),
            };
            bindings.push((slot.name(), binding));
        }
        let desc = GraphicsPipelineDesc {
            additive_attachments: self.additive,
            push_constant_bytes: self.push_constants.len() as u32,
            depth_test: self.depth_test,
            specialization: &self.specialization,
            ..GraphicsPipelineDesc::fullscreen(self.fragment, &self.defines, &self.name)
        };
        // Nothing to bind, push or tile: a pipeline without a descriptor set.
        let bare = bindings.is_empty() && self.push_constants.is_empty();
        if bare && self.variant.is_none() && self.tiles.is_none() {
            self.bare = Some(GraphicsPipeline::new(ctx, &desc)?);
            return Ok(());
        }
        let mut pipeline = PassPipeline::new(ctx, &bindings, &desc)?;
        if let Some(variant) = &self.variant {
            let name = format!("{} ({})", self.name, variant.label);
            let (main, variant) = pipeline.with_variant(ctx, &desc, &variant.extra, &name)?;
            pipeline = main;
            self.variant_pipeline = Some(variant);
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let device = &ctx.gpu.device;
        if let Some(bare) = &self.bare {
            // SAFETY: the pipeline is alive; the executor began this pass's subpass.
            unsafe {
                device.cmd_bind_pipeline(ctx.cmd, vk::PipelineBindPoint::GRAPHICS, bare.pipeline);
                device.cmd_draw(ctx.cmd, 3, 1, 0, 0);
            }
            return;
        }
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        if !self.push_constants.is_empty() {
            // SAFETY: the pipeline's layout has this push-constant range; it is bound.
            unsafe {
                device.cmd_push_constants(
                    ctx.cmd,
                    pipeline.pipeline.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    &self.push_constants,
                );
            }
        }
        let tiles = self.tiles.as_ref().zip(self.scene.as_ref());
        let Some(rects) = tiles.and_then(|(tiles, scene)| tiles(scene, ctx)) else {
            // SAFETY: bound above, inside the pass's subpass.
            unsafe { device.cmd_draw(ctx.cmd, 3, 1, 0, 0) };
            return;
        };
        // The pass's own pipeline draws the marked tiles, or with a marked variant the others.
        let own_in_marked = !self.variant.as_ref().is_some_and(|v| v.in_marked);
        PassPipeline::draw_fullscreen_in(
            ctx,
            rects.iter().filter(|r| r.translucent == own_in_marked),
        );
        if let Some(variant) = &self.variant_pipeline {
            // SAFETY: made for this subpass with the bound set's layout (same push constants).
            unsafe {
                device.cmd_bind_pipeline(
                    ctx.cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    variant.pipeline,
                );
            }
            PassPipeline::draw_fullscreen_in(
                ctx,
                rects.iter().filter(|r| r.translucent != own_in_marked),
            );
        }
    }

    fn bind_view(
        &mut self,
        gpu: &crate::backend::GpuContext,
        slot: usize,
        id: crate::graph::ResourceId,
        view: vk::ImageView,
    ) -> Result<()> {
        let pipeline = self.pipeline.as_ref().ok_or_else(|| {
            crate::LucentError::Graph(format!("pass '{}' has no descriptor set", self.name))
        })?;
        for (binding, s) in self.slots.iter().enumerate() {
            if matches!(*s, Slot::Sampled(_, sampled, _) if sampled == id) {
                pipeline
                    .set
                    .write_view(&gpu.device, slot, binding as u32, view)?;
            }
        }
        Ok(())
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.variant_pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.bare.take() {
            p.destroy(&gpu.device);
        }
        for (_, sampler) in self.samplers.drain(..) {
            // SAFETY: created in prepare; the GPU is done (caller's contract).
            unsafe { gpu.device.destroy_sampler(sampler, None) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::access::Access;
    use crate::gpu_scene::FRAME;
    use crate::graph::ImageInfo;

    fn image(graph: &mut RenderGraph, name: &str) -> Handle<Image> {
        let info = ImageInfo {
            width: 8,
            height: 8,
            format: vk::Format::R16G16B16A16_SFLOAT,
        };
        graph.create_image(name, info)
    }

    #[test]
    fn bindings_follow_the_declaration_order_under_the_shaders_names() {
        let mut graph = RenderGraph::new();
        let (a, b, depth) = (
            image(&mut graph, "a"),
            image(&mut graph, "b"),
            image(&mut graph, "depth"),
        );
        let mut out = image(&mut graph, "out");
        let mut pass = FullscreenPass::new(&mut graph, "pass", "post/tonemap.frag", None);
        pass.per_frame(&FRAME)
            .sample("a", &a)
            .graph()
            .sample(&depth);
        pass.sample_with("b", &b, vk::Filter::LINEAR)
            .bind_shadows(&depth)
            .color(&mut out, LoadOp::DontCare);
        let names: Vec<&str> = pass.slots.iter().map(Slot::name).collect();
        assert_eq!(names, ["Frame", "a", "b", "Shadows", "shadow_depth"]);
        assert_eq!(pass.shader_defines(), &[("LUCENT_SHADOWS", "1")]);
        pass.finish();
        // Planning only: the graph accesses, in declaration order, and no code.
        let decl = &graph.passes[0];
        assert!(decl.exec.is_none());
        let reads: Vec<_> = decl.reads.iter().map(|u| u.resource).collect();
        assert_eq!(reads, [a.id(), depth.id(), b.id()]);
        assert_eq!(decl.reads[0].access, Access::FragmentSampledRead);
        assert_eq!(decl.writes[0].resource, out.id());
    }

    #[test]
    #[should_panic(expected = "binds an image it does not read")]
    fn binding_an_image_the_pass_does_not_read_is_refused() {
        let mut graph = RenderGraph::new();
        let a = image(&mut graph, "a");
        let mut pass = FullscreenPass::new(&mut graph, "pass", "post/tonemap.frag", None);
        pass.bind_sampled("a", &a, vk::Filter::NEAREST);
    }
}
