//! A compiled frame as plain data: passes in order, physical passes (merged groups) with their
//! render passes, subpasses, dependencies and barriers, resources with lifetimes, usage and
//! memory slots. [`super::compile`] makes it; [`super::execute`] makes it real on a device;
//! [`super::dump`] prints it.

use ash::vk;

use crate::backend::access::Access;

use super::declare::{ImageInfo, MeshDraws, PassKind, ResourceId, Use};

/// A pass that survived culling, in execution order.
#[derive(Clone, Debug)]
pub struct PlannedPass {
    /// Declared name.
    pub name: String,
    /// Raster, compute or transfer.
    pub kind: PassKind,
    /// Index in declaration order (to find its executor).
    pub declared_index: usize,
    /// Reads as declared.
    pub reads: Vec<Use>,
    /// Writes as declared.
    pub writes: Vec<Use>,
    /// Texture taps per pixel, when declared ([`super::declare::PassBuilder::taps`]).
    pub taps: Option<u32>,
    /// What it draws, when it draws the scene's meshes
    /// ([`super::declare::PassBuilder::mesh_draws`]).
    pub mesh: Option<MeshDraws>,
}

/// One synchronisation2 barrier.
#[derive(Clone, Debug, PartialEq)]
pub struct Barrier {
    /// The image.
    pub resource: ResourceId,
    /// Stages that must finish first.
    pub src_stage: vk::PipelineStageFlags2,
    /// Writes that must be made available.
    pub src_access: vk::AccessFlags2,
    /// Stages that wait.
    pub dst_stage: vk::PipelineStageFlags2,
    /// Accesses the writes are made visible to.
    pub dst_access: vk::AccessFlags2,
    /// Layout before (UNDEFINED when the old contents are not needed).
    pub old_layout: vk::ImageLayout,
    /// Layout after.
    pub new_layout: vk::ImageLayout,
    /// The image takes over memory another image used earlier in the frame.
    pub aliasing: bool,
}

/// An attachment of a merged render pass.
#[derive(Clone, Debug, PartialEq)]
pub struct AttachmentPlan {
    /// The image.
    pub resource: ResourceId,
    /// Format.
    pub format: vk::Format,
    /// What happens to old contents at the start of the render pass.
    pub load: vk::AttachmentLoadOp,
    /// Clear value when `load` is CLEAR.
    pub clear: [f32; 4],
    /// Whether the contents are kept after the render pass (someone reads them later).
    pub store: vk::AttachmentStoreOp,
    /// Layout when the render pass begins (established by the barrier before it).
    pub initial_layout: vk::ImageLayout,
    /// Layout when the render pass ends (that of its last use inside).
    pub final_layout: vk::ImageLayout,
}

/// One subpass: attachment indices with the layout each is used in.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SubpassPlan {
    /// Colour attachments, in location order.
    pub colors: Vec<(usize, vk::ImageLayout)>,
    /// Input attachments, in binding order.
    pub inputs: Vec<(usize, vk::ImageLayout)>,
    /// Depth attachment.
    pub depth: Option<(usize, vk::ImageLayout)>,
}

/// A dependency between two subpasses of one render pass.
#[derive(Clone, Debug, PartialEq)]
pub struct SubpassDependencyPlan {
    /// Earlier subpass.
    pub src: u32,
    /// Later subpass.
    pub dst: u32,
    /// Stages of the earlier subpass.
    pub src_stage: vk::PipelineStageFlags2,
    /// Accesses of the earlier subpass to make available.
    pub src_access: vk::AccessFlags2,
    /// Stages of the later subpass that wait.
    pub dst_stage: vk::PipelineStageFlags2,
    /// Accesses of the later subpass.
    pub dst_access: vk::AccessFlags2,
    /// Only the same pixel is read (input attachments): lets tilers stay on chip.
    pub by_region: bool,
}

/// The render pass of a raster physical pass.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderPassPlan {
    /// Attachments (framebuffer order).
    pub attachments: Vec<AttachmentPlan>,
    /// Subpasses, one per merged pass.
    pub subpasses: Vec<SubpassPlan>,
    /// Dependencies between subpasses.
    pub dependencies: Vec<SubpassDependencyPlan>,
}

/// One physical pass: what gets one debug label and one timestamp pair.
#[derive(Clone, Debug)]
pub struct PhysicalPass {
    /// Name: the pass's, or "a + b" for merged passes.
    pub name: String,
    /// Kind of the passes inside.
    pub kind: PassKind,
    /// Indices into [`Plan::passes`], in subpass order.
    pub passes: Vec<usize>,
    /// Render area for raster passes.
    pub extent: (u32, u32),
    /// Barriers recorded before the pass, batched into one call.
    pub barriers: Vec<Barrier>,
    /// For raster passes: the render pass.
    pub render_pass: Option<RenderPassPlan>,
}

/// A resource as planned.
#[derive(Clone, Debug)]
pub struct PlannedResource {
    /// Declared name.
    pub name: String,
    /// Size and format.
    pub info: ImageInfo,
    /// Owned by a host.
    pub imported: bool,
    /// The host's image, when imported.
    pub import: Option<super::declare::ImportedImage>,
    /// State it must be left in.
    pub export: Option<Access>,
    /// Usage flags derived from every access.
    pub usage: vk::ImageUsageFlags,
    /// First and last physical pass that touches it; `None` if no surviving pass does
    /// (then it gets no memory at all).
    pub lifetime: Option<(usize, usize)>,
    /// Memory slot shared with other transient images (when aliasing is on).
    pub slot: Option<usize>,
}

impl PlannedResource {
    /// Bytes the image needs, estimated from size and format (the device may pad).
    pub fn estimated_bytes(&self) -> u64 {
        u64::from(self.info.width)
            * u64::from(self.info.height)
            * u64::from(crate::backend::format::texel_bytes(self.info.format).unwrap_or(0))
    }
}

/// A block of memory shared by transient images with disjoint lifetimes.
#[derive(Clone, Debug)]
pub struct MemorySlot {
    /// Images placed in it, in lifetime order.
    pub resources: Vec<ResourceId>,
    /// Estimated size: the largest of its images.
    pub estimated_bytes: u64,
}

/// The compiled frame: plain data, printable, executable by [`super::Executable`].
#[derive(Clone, Debug)]
pub struct Plan {
    /// Options it was compiled with.
    pub options: CompileOptions,
    /// Every declared resource (unused ones have no lifetime and no memory).
    pub resources: Vec<PlannedResource>,
    /// Surviving passes, in execution order.
    pub passes: Vec<PlannedPass>,
    /// Physical passes, in execution order.
    pub physical: Vec<PhysicalPass>,
    /// Transitions to export states at the end of the frame.
    pub export_barriers: Vec<Barrier>,
    /// Memory slots of aliased transient images.
    pub slots: Vec<MemorySlot>,
    /// Names of culled passes.
    pub culled: Vec<String>,
}

impl Plan {
    /// Estimated bytes of transient memory (images that neither enter nor leave the frame) with
    /// the plan's aliasing, and without any aliasing.
    pub fn transient_memory(&self) -> (u64, u64) {
        let transient = self
            .resources
            .iter()
            .filter(|r| r.lifetime.is_some() && !r.imported && r.export.is_none());
        let unaliased: u64 = transient.clone().map(|r| r.estimated_bytes()).sum();
        let slotted: u64 = self.slots.iter().map(|s| s.estimated_bytes).sum();
        let unslotted: u64 = transient
            .filter(|r| r.slot.is_none())
            .map(|r| r.estimated_bytes())
            .sum();
        (slotted + unslotted, unaliased)
    }

    /// Estimated bytes of device memory the executable allocates for the frame's images: every
    /// memory slot, and every image it owns outside a slot (exported ones included; a host's
    /// imported images are not counted). With the largest of those images.
    pub fn frame_memory(&self) -> (u64, Option<&PlannedResource>) {
        let owned = self
            .resources
            .iter()
            .filter(|r| r.lifetime.is_some() && !r.imported && r.slot.is_none());
        let slotted: u64 = self.slots.iter().map(|s| s.estimated_bytes).sum();
        let total = slotted + owned.map(PlannedResource::estimated_bytes).sum::<u64>();
        let largest = self
            .resources
            .iter()
            .filter(|r| r.lifetime.is_some() && !r.imported)
            .max_by_key(|r| r.estimated_bytes());
        (total, largest)
    }

    /// The physical pass index of a resource's export barrier etc.: finds a resource by name.
    pub fn resource_by_name(&self, name: &str) -> Option<ResourceId> {
        self.resources.iter().position(|r| r.name == name)
    }
}

/// Switches for A/B comparisons of the compiler's optimisations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CompileOptions {
    /// Merge same-pixel raster chains into subpasses of one render pass.
    pub merge: bool,
    /// Let transient images with disjoint lifetimes share memory.
    pub alias: bool,
    /// Frames are submitted back to back without the host waiting for each (frames in
    /// flight): each frame's first access to a transient image also waits for the previous
    /// frame's last access to it (and to its memory slot). Off, the caller waits for a frame
    /// before submitting the next, and frames start from nothing.
    pub chained_frames: bool,
}

impl Default for CompileOptions {
    fn default() -> Self {
        Self {
            merge: true,
            alias: true,
            chained_frames: false,
        }
    }
}
