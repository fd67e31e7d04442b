//! Executing a plan: physical images (with aliased memory), render passes and framebuffers, and
//! recording into any command buffer the caller gives.
//!
//! Use [`Executable::record_frame`] for a whole frame in one command buffer, or
//! [`Executable::record_physical`] once per physical pass when each pass must be submitted on
//! its own (the benchmark's isolated timing mode), followed by [`Executable::record_exports`].

use ash::vk;

use crate::backend::access::{has_stencil, Access};
use crate::backend::shader::ShaderCompiler;
use crate::backend::timer::GpuTimer;
use crate::backend::{GpuContext, GpuImage, ImageDesc, MemoryBlock};
use crate::error::VkResultExt;
use crate::{LucentError, Result};

use super::compile::{Barrier, Plan, RenderPassPlan};
use super::declare::ResourceId;
use super::PassExec;

/// What a pass needs to create its pipelines.
pub struct PrepareContext<'a> {
    /// The context.
    pub gpu: &'a GpuContext,
    /// Shader compiler (with its SPIR-V cache).
    pub shaders: &'a ShaderCompiler,
    /// Pipeline cache to create pipelines with.
    pub pipeline_cache: vk::PipelineCache,
    /// The render pass of the pass's physical group (null for compute and transfer passes).
    pub render_pass: vk::RenderPass,
    /// The pass's subpass index in `render_pass`.
    pub subpass: u32,
    /// Number of colour attachments the subpass writes (for blend state counts).
    pub color_attachment_count: u32,
    /// Render area.
    pub extent: vk::Extent2D,
    /// Views of every graph image, by [`ResourceId`] (null for images without memory).
    pub views: &'a [vk::ImageView],
    /// Views for descriptors (input attachments, sampling), by [`ResourceId`]: the same as
    /// `views` except for depth-stencil images, whose descriptor view must name one aspect
    /// (depth) while the framebuffer's names both. Null for an imported image bound at record
    /// time ([`Executable::bind_imports`]): a pass that samples one keeps a descriptor set per
    /// frame slot and writes the view into the slot's set when it is bound
    /// ([`PassExec::bind_view`]).
    pub descriptor_views: &'a [vk::ImageView],
    /// Frame-in-flight slots the executable records (per-slot descriptor sets have this many).
    pub slots: usize,
}

/// What a pass needs to record itself.
pub struct RecordContext<'a> {
    /// The context.
    pub gpu: &'a GpuContext,
    /// The command buffer being recorded.
    pub cmd: vk::CommandBuffer,
    /// Render area.
    pub extent: vk::Extent2D,
    /// Images by [`ResourceId`].
    pub images: &'a [vk::Image],
    /// Views by [`ResourceId`].
    pub views: &'a [vk::ImageView],
    /// The frame-in-flight slot being recorded: passes read their per-frame data (uniforms,
    /// tiles) from this slot, so frames of other slots may still be running on the GPU.
    pub frame: usize,
}

/// How a physical image came to be.
enum Physical {
    /// No surviving pass uses it: nothing was created.
    None,
    /// Its own allocation.
    Owned(GpuImage),
    /// Bound into a shared memory slot.
    Aliased {
        image: vk::Image,
        view: vk::ImageView,
    },
    /// The host's.
    Imported,
}

/// The subresources of an image the graph's barriers cover: one mip level and a run of array
/// layers (an imported image's view shows exactly these).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Subresources {
    /// The mip level.
    pub mip: u32,
    /// The first array layer.
    pub base_layer: u32,
    /// How many layers (1: a 2-D view; more: a 2-D array view).
    pub layers: u32,
}

impl Subresources {
    /// Mip 0, layer 0: every image the graph owns, and most imports.
    pub const FIRST: Subresources = Subresources {
        mip: 0,
        base_layer: 0,
        layers: 1,
    };

    /// The Vulkan range of these subresources in `aspect`.
    pub fn vk(self, aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: self.mip,
            level_count: 1,
            base_array_layer: self.base_layer,
            layer_count: self.layers.max(1),
        }
    }
}

/// A plan made real on a device, ready to record every frame.
pub struct Executable {
    /// The plan being executed.
    pub plan: Plan,
    execs: Vec<Box<dyn PassExec>>,
    physical: Vec<Physical>,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    /// The subresources per image its barriers cover (mip 0, layer 0 but for an imported
    /// image's: a host's image may be one mip or layer of a larger one, or an array of
    /// layers, a shadow map's cascades, [`Self::bind_imports`]).
    ranges: Vec<Subresources>,
    /// Depth-only views of depth-stencil images (null for every other image).
    depth_views: Vec<vk::ImageView>,
    /// `views` with `depth_views` where those exist: what descriptors point at.
    descriptor_views: Vec<vk::ImageView>,
    blocks: Vec<MemoryBlock>,
    render_passes: Vec<vk::RenderPass>,
    /// Per physical pass, its framebuffer per frame slot: one shared by every slot for a pass
    /// whose attachments are all the executable's own (made at `new`); for a pass with an
    /// imported attachment, slot `k`'s, made by [`Executable::bind_imports`] for slot `k`
    /// (null until then) and destroyed when slot `k` is bound again. Bounded: at most one per
    /// pass and slot, and never matched by handle, so a host view recreated with a reused
    /// handle value gets a framebuffer of its own.
    framebuffers: Vec<Vec<vk::Framebuffer>>,
    /// Per physical pass, the framebuffer made at `new` over views known then (null when an
    /// attachment had none yet): every slot's until a bind replaces that slot's.
    shared_framebuffers: Vec<vk::Framebuffer>,
    /// Frame slots recorded (`record_frame`'s `frame` is below it).
    slots: usize,
}

impl Executable {
    /// Creates everything the plan needs and lets every pass prepare its pipelines.
    /// Every surviving pass must have an executor.
    /// `slots`: the frame-in-flight slots frames are recorded for (1 or more).
    pub fn new(
        gpu: &GpuContext,
        plan: Plan,
        execs: super::compile::PassExecs,
        shaders: &ShaderCompiler,
        pipeline_cache: vk::PipelineCache,
        slots: usize,
    ) -> Result<Self> {
        let slots = slots.max(1);
        let execs = execs
            .into_iter()
            .zip(&plan.passes)
            .map(|(e, p)| {
                e.ok_or_else(|| {
                    LucentError::Graph(format!("pass '{}' has no code to execute", p.name))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut exe = Executable {
            physical: Vec::new(),
            images: vec![vk::Image::null(); plan.resources.len()],
            ranges: vec![Subresources::FIRST; plan.resources.len()],
            views: vec![vk::ImageView::null(); plan.resources.len()],
            depth_views: vec![vk::ImageView::null(); plan.resources.len()],
            descriptor_views: Vec::new(),
            blocks: Vec::new(),
            render_passes: Vec::new(),
            framebuffers: Vec::new(),
            shared_framebuffers: Vec::new(),
            slots,
            execs: Vec::new(),
            plan,
        };
        // On error, whatever was created so far is destroyed by `destroy` below.
        match exe.create_resources(gpu) {
            Ok(()) => {}
            Err(e) => {
                exe.destroy(gpu);
                return Err(e);
            }
        }
        exe.execs = execs;
        if let Err(e) = exe.prepare_passes(gpu, shaders, pipeline_cache) {
            exe.destroy(gpu);
            return Err(e);
        }
        Ok(exe)
    }

    fn desc(&self, id: ResourceId) -> ImageDesc {
        let r = &self.plan.resources[id];
        ImageDesc {
            width: r.info.width,
            height: r.info.height,
            format: r.info.format,
            usage: r.usage,
            aspect: r.info.aspect(),
            mip_levels: 1,
            layers: 1,
        }
    }

    fn create_resources(&mut self, gpu: &GpuContext) -> Result<()> {
        let count = self.plan.resources.len();
        for id in 0..count {
            let r = &self.plan.resources[id];
            let physical = if r.lifetime.is_none() {
                Physical::None
            } else if let Some(import) = r.import {
                self.images[id] = import.image;
                self.views[id] = import.view;
                Physical::Imported
            } else if r.slot.is_some() {
                // Created now, bound below once each slot's block is allocated.
                let (image, _) = gpu.create_image_unbound(&self.desc(id), &r.name)?;
                self.images[id] = image;
                Physical::Aliased {
                    image,
                    view: vk::ImageView::null(),
                }
            } else {
                let image = gpu.create_image(&self.desc(id), &r.name)?;
                self.images[id] = image.image;
                self.views[id] = image.view;
                Physical::Owned(image)
            };
            self.physical.push(physical);
        }
        for (s, slot) in self.plan.slots.clone().iter().enumerate() {
            // One block serves every image of the slot: large enough for the largest, aligned
            // for the strictest, of a memory type they all accept.
            let mut requirements = vk::MemoryRequirements {
                size: 0,
                alignment: 1,
                memory_type_bits: u32::MAX,
            };
            for &id in &slot.resources {
                // SAFETY: the image was created above on this device and is not yet bound.
                let req = unsafe { gpu.device.get_image_memory_requirements(self.images[id]) };
                requirements.size = requirements.size.max(req.size);
                requirements.alignment = requirements.alignment.max(req.alignment);
                requirements.memory_type_bits &= req.memory_type_bits;
            }
            if requirements.memory_type_bits == 0 {
                return Err(LucentError::Graph(format!(
                    "memory slot {s}: its images share no memory type; compile with aliasing off"
                )));
            }
            // Named by what it holds, so an out-of-memory error says which images.
            let names: Vec<&str> = slot
                .resources
                .iter()
                .map(|&id| self.plan.resources[id].name.as_str())
                .collect();
            let shown = names.iter().take(3).copied().collect::<Vec<_>>().join(", ");
            let more = names.len().saturating_sub(3);
            let label = if more > 0 {
                format!("graph slot {s}: {shown} and {more} more")
            } else {
                format!("graph slot {s}: {shown}")
            };
            let block = gpu.allocate_memory_block(requirements, &label)?;
            for &id in &slot.resources {
                gpu.bind_image(self.images[id], &block, 0)?;
                let view = gpu.create_view(
                    self.images[id],
                    &self.desc(id),
                    &self.plan.resources[id].name,
                )?;
                self.views[id] = view;
                if let Physical::Aliased { view: v, .. } = &mut self.physical[id] {
                    *v = view;
                }
            }
            self.blocks.push(block);
        }
        // Depth-stencil images that descriptors read get a depth-only view as well.
        for id in 0..count {
            let desc = self.desc(id);
            let owned = matches!(
                self.physical[id],
                Physical::Owned(_) | Physical::Aliased { .. }
            );
            if owned && has_stencil(desc.format) {
                let depth_only = ImageDesc {
                    aspect: vk::ImageAspectFlags::DEPTH,
                    ..desc
                };
                let name = format!("{} (depth)", self.plan.resources[id].name);
                self.depth_views[id] = gpu.create_view(self.images[id], &depth_only, &name)?;
            }
        }
        self.descriptor_views = self
            .views
            .iter()
            .zip(&self.depth_views)
            .map(|(&v, &d)| if d == vk::ImageView::null() { v } else { d })
            .collect();
        for g in 0..self.plan.physical.len() {
            let phys = &self.plan.physical[g];
            match &phys.render_pass {
                Some(plan) => {
                    let rp = create_render_pass(gpu, plan, &phys.name)?;
                    self.render_passes.push(rp);
                }
                None => self.render_passes.push(vk::RenderPass::null()),
            }
            let shared = if self.attachments_have_views(g) {
                self.create_group_framebuffer(gpu, g)?
            } else {
                // An import without a view yet: made per slot when it is bound.
                vk::Framebuffer::null()
            };
            self.shared_framebuffers.push(shared);
            self.framebuffers.push(vec![shared; self.slots]);
        }
        Ok(())
    }

    /// Whether every attachment of physical pass `g` has a view now.
    fn attachments_have_views(&self, g: usize) -> bool {
        self.plan.physical[g]
            .render_pass
            .as_ref()
            .is_some_and(|rp| {
                rp.attachments
                    .iter()
                    .all(|a| self.views[a.resource] != vk::ImageView::null())
            })
    }

    /// A framebuffer of physical pass `g`'s render pass over the current attachment views
    /// (null when the pass has no render pass).
    fn create_group_framebuffer(&self, gpu: &GpuContext, g: usize) -> Result<vk::Framebuffer> {
        let phys = &self.plan.physical[g];
        let Some(plan) = &phys.render_pass else {
            return Ok(vk::Framebuffer::null());
        };
        create_framebuffer(
            gpu,
            plan,
            self.render_passes[g],
            &self.views,
            phys.extent,
            &phys.name,
        )
    }

    /// Binds imported images for the frame recorded next with slot `slot`: each `(id, image,
    /// view)` gives import `id` its image and view. Attachments get slot `slot`'s framebuffer
    /// made anew (its previous one destroyed); images sampled through descriptors are written
    /// into slot `slot`'s descriptor sets. The frame last recorded with slot `slot` must have
    /// completed (its framebuffer and sets are replaced), and every import the frame reads or
    /// writes must be bound before it is recorded ([`Executable::ready`]).
    pub fn bind_imports(
        &mut self,
        gpu: &GpuContext,
        slot: usize,
        binds: &[(ResourceId, vk::Image, vk::ImageView, Subresources)],
    ) -> Result<()> {
        if slot >= self.slots {
            return Err(LucentError::Graph(format!(
                "bind_imports: slot {slot}, but the executable records {} slot(s)",
                self.slots
            )));
        }
        for &(id, image, view, range) in binds {
            let resource = self.plan.resources.get(id).ok_or_else(|| {
                LucentError::Graph(format!("bind_imports: no resource {id} in this plan"))
            })?;
            if !resource.imported {
                return Err(LucentError::Graph(format!(
                    "bind_imports: '{}' is not an imported image",
                    resource.name
                )));
            }
            if image == vk::Image::null() || view == vk::ImageView::null() {
                return Err(LucentError::Graph(format!(
                    "bind_imports: '{}' needs an image and a view",
                    resource.name
                )));
            }
            self.images[id] = image;
            self.views[id] = view;
            self.ranges[id] = Subresources {
                layers: range.layers.max(1),
                ..range
            };
        }
        for &(id, _, view, _) in binds {
            for p in 0..self.plan.passes.len() {
                let reads_through_descriptors = self.plan.passes[p]
                    .reads
                    .iter()
                    .any(|u| u.resource == id && u.access.through_descriptors());
                if reads_through_descriptors {
                    self.execs[p].bind_view(gpu, slot, id, view)?;
                }
            }
        }
        for g in 0..self.plan.physical.len() {
            let rebinds = self.plan.physical[g]
                .render_pass
                .as_ref()
                .is_some_and(|rp| {
                    rp.attachments
                        .iter()
                        .any(|a| binds.iter().any(|&(id, ..)| id == a.resource))
                });
            if !rebinds {
                continue;
            }
            let old = std::mem::replace(&mut self.framebuffers[g][slot], vk::Framebuffer::null());
            if old != vk::Framebuffer::null() && old != self.shared_framebuffers[g] {
                // SAFETY: made for this slot by an earlier bind; the frame that used it has
                // completed (the caller's contract).
                unsafe { gpu.device.destroy_framebuffer(old, None) };
            }
            if self.attachments_have_views(g) {
                self.framebuffers[g][slot] = self.create_group_framebuffer(gpu, g)?;
            }
        }
        Ok(())
    }

    /// Whether a frame can be recorded for slot `slot` (every imported attachment bound for it,
    /// every import with an image).
    pub fn ready(&self, slot: usize) -> bool {
        slot < self.slots
            && self
                .plan
                .physical
                .iter()
                .zip(&self.framebuffers)
                .all(|(p, fb)| p.render_pass.is_none() || fb[slot] != vk::Framebuffer::null())
            && self
                .plan
                .resources
                .iter()
                .zip(&self.images)
                .all(|(r, i)| r.lifetime.is_none() || *i != vk::Image::null())
    }

    fn prepare_passes(
        &mut self,
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: vk::PipelineCache,
    ) -> Result<()> {
        for (g, phys) in self.plan.physical.iter().enumerate() {
            for (s, &p) in phys.passes.iter().enumerate() {
                let color_attachment_count = phys
                    .render_pass
                    .as_ref()
                    .map_or(0, |rp| rp.subpasses[s].colors.len() as u32);
                let ctx = PrepareContext {
                    gpu,
                    shaders,
                    pipeline_cache,
                    render_pass: self.render_passes[g],
                    subpass: s as u32,
                    color_attachment_count,
                    extent: extent(phys.extent),
                    views: &self.views,
                    descriptor_views: &self.descriptor_views,
                    slots: self.slots,
                };
                self.execs[p].prepare(&ctx).map_err(|e| match e {
                    LucentError::Graph(m) => {
                        LucentError::Graph(format!("pass '{}': {m}", self.plan.passes[p].name))
                    }
                    other => other,
                })?;
            }
        }
        Ok(())
    }

    /// Records the whole frame: every physical pass (each under its debug label and, with a
    /// timer, its timestamp pair) and the final transitions to export states.
    /// `frame` is the frame-in-flight slot whose per-frame data the passes read.
    pub fn record_frame(
        &self,
        gpu: &GpuContext,
        cmd: vk::CommandBuffer,
        frame: usize,
        mut timer: Option<&mut GpuTimer>,
    ) {
        for index in 0..self.plan.physical.len() {
            self.record_physical(gpu, cmd, index, frame, timer.as_deref_mut());
        }
        self.record_exports(gpu, cmd);
    }

    /// Records one physical pass with the barriers before it. The timestamp pair encloses the
    /// barriers too, so the per-pass times add up to the frame.
    pub fn record_physical(
        &self,
        gpu: &GpuContext,
        cmd: vk::CommandBuffer,
        index: usize,
        frame: usize,
        timer: Option<&mut GpuTimer>,
    ) {
        let phys = &self.plan.physical[index];
        gpu.begin_label(cmd, &phys.name);
        let scope = timer.map(|t| {
            let s = t.begin(gpu, cmd, &phys.name);
            (t, s)
        });
        self.record_barriers(gpu, cmd, &phys.barriers);
        let area = extent(phys.extent);
        let record_ctx = RecordContext {
            gpu,
            cmd,
            extent: area,
            images: &self.images,
            views: &self.views,
            frame,
        };
        match &phys.render_pass {
            Some(rp) => {
                let clears: Vec<vk::ClearValue> = rp
                    .attachments
                    .iter()
                    .map(|a| {
                        if crate::backend::access::is_depth_format(a.format) {
                            vk::ClearValue {
                                depth_stencil: vk::ClearDepthStencilValue {
                                    depth: a.clear[0],
                                    stencil: 0,
                                },
                            }
                        } else {
                            vk::ClearValue {
                                color: vk::ClearColorValue { float32: a.clear },
                            }
                        }
                    })
                    .collect();
                let begin = vk::RenderPassBeginInfo::default()
                    .render_pass(self.render_passes[index])
                    .framebuffer(self.framebuffers[index][frame])
                    .render_area(vk::Rect2D {
                        offset: vk::Offset2D::default(),
                        extent: area,
                    })
                    .clear_values(&clears);
                let subpass_begin =
                    vk::SubpassBeginInfo::default().contents(vk::SubpassContents::INLINE);
                let subpass_end = vk::SubpassEndInfo::default();
                // SAFETY: the render pass, framebuffer and command buffer are valid; the command
                // buffer is in the recording state (caller's contract).
                unsafe {
                    gpu.device
                        .cmd_begin_render_pass2(cmd, &begin, &subpass_begin)
                };
                for (s, &p) in phys.passes.iter().enumerate() {
                    if s > 0 {
                        // SAFETY: as above; the render pass has this many subpasses.
                        unsafe {
                            gpu.device
                                .cmd_next_subpass2(cmd, &subpass_begin, &subpass_end)
                        };
                    }
                    set_full_viewport(gpu, cmd, area);
                    gpu.begin_label(cmd, &self.plan.passes[p].name);
                    self.execs[p].record(&record_ctx);
                    gpu.end_label(cmd);
                }
                // SAFETY: matches the begin above.
                unsafe { gpu.device.cmd_end_render_pass2(cmd, &subpass_end) };
            }
            None => {
                for &p in &phys.passes {
                    self.execs[p].record(&record_ctx);
                }
            }
        }
        if let Some((t, s)) = scope {
            t.end(gpu, cmd, s);
        }
        gpu.end_label(cmd);
    }

    /// Records the transitions that leave exported images in their promised states.
    pub fn record_exports(&self, gpu: &GpuContext, cmd: vk::CommandBuffer) {
        self.record_barriers(gpu, cmd, &self.plan.export_barriers);
    }

    fn record_barriers(&self, gpu: &GpuContext, cmd: vk::CommandBuffer, barriers: &[Barrier]) {
        if barriers.is_empty() {
            return;
        }
        let image_barriers: Vec<vk::ImageMemoryBarrier2> = barriers
            .iter()
            .map(|b| {
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(b.src_stage)
                    .src_access_mask(b.src_access)
                    .dst_stage_mask(b.dst_stage)
                    .dst_access_mask(b.dst_access)
                    .old_layout(b.old_layout)
                    .new_layout(b.new_layout)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(self.images[b.resource])
                    .subresource_range(
                        self.ranges[b.resource].vk(self.plan.resources[b.resource].info.aspect()),
                    )
            })
            .collect();
        let dependency = vk::DependencyInfo::default().image_memory_barriers(&image_barriers);
        // SAFETY: every image exists (barriers only name images with a lifetime).
        unsafe { gpu.device.cmd_pipeline_barrier2(cmd, &dependency) };
    }

    /// Bytes of device memory its images hold: each shared memory slot's block once (the
    /// images aliased into it share it) and each image with memory of its own. Imported
    /// images are the host's and count nothing.
    pub fn memory_bytes(&self) -> u64 {
        let blocks: u64 = self.blocks.iter().map(MemoryBlock::size).sum();
        let owned: u64 = self
            .physical
            .iter()
            .map(|p| match p {
                Physical::Owned(image) => image.memory_bytes(),
                _ => 0,
            })
            .sum();
        blocks + owned
    }

    /// The physical image of a resource (null if it has no memory).
    pub fn image(&self, id: ResourceId) -> vk::Image {
        self.images[id]
    }

    /// The owned image of an exported resource (for readback).
    pub fn owned_image(&self, id: ResourceId) -> Option<&GpuImage> {
        match self.physical.get(id) {
            Some(Physical::Owned(image)) => Some(image),
            _ => None,
        }
    }

    /// The layout an exported resource is left in at the end of the frame.
    pub fn export_layout(&self, id: ResourceId) -> Option<vk::ImageLayout> {
        self.plan.resources[id]
            .export
            .map(|a: Access| a.info().layout)
    }

    /// Destroys everything this executable created (the host's imported images are untouched).
    /// The caller makes sure the GPU no longer uses them.
    pub fn destroy(mut self, gpu: &GpuContext) {
        self.destroy_in_place(gpu);
    }

    fn destroy_in_place(&mut self, gpu: &GpuContext) {
        for exec in &mut self.execs {
            exec.destroy(gpu);
        }
        self.execs.clear();
        // SAFETY: created by this executable on this device; the caller guarantees idle.
        unsafe {
            let shared = std::mem::take(&mut self.shared_framebuffers);
            for fb in self.framebuffers.drain(..).flatten() {
                // A shared framebuffer is listed once per slot: destroyed once, below.
                if fb != vk::Framebuffer::null() && !shared.contains(&fb) {
                    gpu.device.destroy_framebuffer(fb, None);
                }
            }
            for fb in shared {
                if fb != vk::Framebuffer::null() {
                    gpu.device.destroy_framebuffer(fb, None);
                }
            }
            for rp in self.render_passes.drain(..) {
                if rp != vk::RenderPass::null() {
                    gpu.device.destroy_render_pass(rp, None);
                }
            }
        }
        for view in self.depth_views.drain(..) {
            if view != vk::ImageView::null() {
                // SAFETY: created by `create_resources`; the GPU is done with it.
                unsafe { gpu.device.destroy_image_view(view, None) };
            }
        }
        for physical in self.physical.drain(..) {
            match physical {
                Physical::Owned(image) => gpu.destroy_image(image),
                Physical::Aliased { image, view } => {
                    // SAFETY: as above.
                    unsafe {
                        if view != vk::ImageView::null() {
                            gpu.device.destroy_image_view(view, None);
                        }
                        gpu.device.destroy_image(image, None);
                    }
                }
                Physical::None | Physical::Imported => {}
            }
        }
        for block in self.blocks.drain(..) {
            gpu.free_memory_block(block);
        }
    }
}

fn extent((width, height): (u32, u32)) -> vk::Extent2D {
    vk::Extent2D { width, height }
}

fn set_full_viewport(gpu: &GpuContext, cmd: vk::CommandBuffer, area: vk::Extent2D) {
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: area.width as f32,
        height: area.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: area,
    };
    // SAFETY: every lucent pipeline declares viewport and scissor as dynamic state.
    unsafe {
        gpu.device.cmd_set_viewport(cmd, 0, &[viewport]);
        gpu.device.cmd_set_scissor(cmd, 0, &[scissor]);
    }
}

fn create_render_pass(
    gpu: &GpuContext,
    plan: &RenderPassPlan,
    name: &str,
) -> Result<vk::RenderPass> {
    let attachments: Vec<vk::AttachmentDescription2> = plan
        .attachments
        .iter()
        .map(|a| {
            vk::AttachmentDescription2::default()
                .format(a.format)
                .samples(vk::SampleCountFlags::TYPE_1)
                .load_op(a.load)
                .store_op(a.store)
                // A stencil aspect is loaded and stored like its depth.
                .stencil_load_op(if has_stencil(a.format) {
                    a.load
                } else {
                    vk::AttachmentLoadOp::DONT_CARE
                })
                .stencil_store_op(if has_stencil(a.format) {
                    a.store
                } else {
                    vk::AttachmentStoreOp::DONT_CARE
                })
                .initial_layout(a.initial_layout)
                .final_layout(a.final_layout)
        })
        .collect();
    let aspect_of = |a: usize| {
        if crate::backend::access::is_depth_format(plan.attachments[a].format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        }
    };
    let reference = |&(a, layout): &(usize, vk::ImageLayout)| {
        vk::AttachmentReference2::default()
            .attachment(a as u32)
            .layout(layout)
            .aspect_mask(aspect_of(a))
    };
    let colors: Vec<Vec<vk::AttachmentReference2>> = plan
        .subpasses
        .iter()
        .map(|s| s.colors.iter().map(reference).collect())
        .collect();
    let inputs: Vec<Vec<vk::AttachmentReference2>> = plan
        .subpasses
        .iter()
        .map(|s| s.inputs.iter().map(reference).collect())
        .collect();
    let depths: Vec<Option<vk::AttachmentReference2>> = plan
        .subpasses
        .iter()
        .map(|s| s.depth.as_ref().map(reference))
        .collect();
    let subpasses: Vec<vk::SubpassDescription2> = (0..plan.subpasses.len())
        .map(|i| {
            let mut d = vk::SubpassDescription2::default()
                .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
                .color_attachments(&colors[i])
                .input_attachments(&inputs[i]);
            if let Some(depth) = &depths[i] {
                d = d.depth_stencil_attachment(depth);
            }
            d
        })
        .collect();
    // Synchronization2 lets each dependency carry 64-bit masks in a chained VkMemoryBarrier2.
    let mut barriers: Vec<vk::MemoryBarrier2> = plan
        .dependencies
        .iter()
        .map(|d| {
            vk::MemoryBarrier2::default()
                .src_stage_mask(d.src_stage)
                .src_access_mask(d.src_access)
                .dst_stage_mask(d.dst_stage)
                .dst_access_mask(d.dst_access)
        })
        .collect();
    let dependencies: Vec<vk::SubpassDependency2> = plan
        .dependencies
        .iter()
        .zip(barriers.iter_mut())
        .map(|(d, barrier)| {
            vk::SubpassDependency2::default()
                .src_subpass(d.src)
                .dst_subpass(d.dst)
                .dependency_flags(if d.by_region {
                    vk::DependencyFlags::BY_REGION
                } else {
                    vk::DependencyFlags::empty()
                })
                .push_next(barrier)
        })
        .collect();
    let info = vk::RenderPassCreateInfo2::default()
        .attachments(&attachments)
        .subpasses(&subpasses)
        .dependencies(&dependencies);
    // SAFETY: all arrays referenced by `info` live until the call returns.
    let rp = unsafe { gpu.device.create_render_pass2(&info, None) }.vk("vkCreateRenderPass2")?;
    gpu.set_name(rp, name);
    Ok(rp)
}

fn create_framebuffer(
    gpu: &GpuContext,
    plan: &RenderPassPlan,
    render_pass: vk::RenderPass,
    views: &[vk::ImageView],
    (width, height): (u32, u32),
    name: &str,
) -> Result<vk::Framebuffer> {
    let attachments: Vec<vk::ImageView> =
        plan.attachments.iter().map(|a| views[a.resource]).collect();
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(&attachments)
        .width(width)
        .height(height)
        .layers(1);
    // SAFETY: the views exist and match the render pass's attachments.
    let fb = unsafe { gpu.device.create_framebuffer(&info, None) }.vk("vkCreateFramebuffer")?;
    gpu.set_name(fb, name);
    Ok(fb)
}
