//! Declaring a frame: resources, passes, and what each pass reads and writes.
//!
//! Reading takes `&Handle`, writing takes `&mut Handle` and advances the handle to the next
//! version, so the borrow checker keeps the dataflow honest: whoever holds a handle holds the
//! newest version, and a pass cannot read a version that a later pass is about to overwrite.

use std::marker::PhantomData;

use ash::vk;

use crate::backend::access::{has_stencil, is_depth_format, Access};

use super::PassExec;

/// Index of a resource in its graph.
pub type ResourceId = usize;

/// Marker for image handles.
#[derive(Debug)]
pub enum Image {}
/// Marker for buffer handles.
#[derive(Debug)]
pub enum Buffer {}

/// A versioned handle to a graph resource. Deliberately neither `Clone` nor `Copy`: there is one
/// live handle per resource, and writing through it advances its version.
#[derive(Debug)]
pub struct Handle<T> {
    id: ResourceId,
    version: u32,
    _kind: PhantomData<T>,
}

impl<T> Handle<T> {
    /// The resource this handle names (stable across versions); passes keep it to look up the
    /// physical image at record time.
    pub fn id(&self) -> ResourceId {
        self.id
    }
    /// The version this handle currently names (0 = contents from before the graph).
    pub fn version(&self) -> u32 {
        self.version
    }
}

/// Size and format of a graph image (2D, one mip, one layer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageInfo {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Texel format.
    pub format: vk::Format,
}

impl ImageInfo {
    /// Aspect implied by the format.
    pub fn aspect(&self) -> vk::ImageAspectFlags {
        if has_stencil(self.format) {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        } else if is_depth_format(self.format) {
            vk::ImageAspectFlags::DEPTH
        } else {
            vk::ImageAspectFlags::COLOR
        }
    }
}

/// A host engine's image handed to the graph, and the state it is in when the frame starts.
#[derive(Clone, Copy, Debug)]
pub struct ImportedImage {
    /// The host's image.
    pub image: vk::Image,
    /// A view of the whole image.
    pub view: vk::ImageView,
    /// How the image was last accessed before this frame (layout and stages to wait for).
    pub initial: Access,
}

/// One resource declaration.
#[derive(Clone, Debug)]
pub struct ResourceDecl {
    /// Name used in labels, object names and the plan dump.
    pub name: String,
    /// Size and format.
    pub info: ImageInfo,
    /// Set when a host (or the caller) owns the image.
    pub import: Option<ImportedImage>,
    /// State the resource must be left in at the end of the frame, if it leaves the graph.
    pub export: Option<Access>,
    /// Number of versions written so far (the handle's version).
    pub versions: u32,
}

/// What to do with an attachment's old contents when a raster pass starts writing it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LoadOp {
    /// Clear to this value (colour RGBA, or depth in `[0]`).
    Clear([f32; 4]),
    /// Keep the previous version (the pass reads it: read-modify-write, e.g. additive lights).
    Load,
    /// Every pixel is overwritten; the old contents are not needed.
    DontCare,
}

/// What kind of work a pass records.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassKind {
    /// Draws into attachments inside a render pass; may be merged with neighbours as a subpass.
    Raster,
    /// Dispatches compute work outside render passes.
    Compute,
    /// Copies, blits, clears.
    Transfer,
}

/// What a mesh pass draws, as its speed-of-light floor needs to know it
/// ([`PassBuilder::mesh_draws`]): every object of the scene, once per view, with the pass's
/// culling. The floor (`crate::measure::speed_of_light`) draws the same objects into the
/// same attachments with a trivial shader, so a pass that draws each object twice, or shades
/// each fragment twice as hard, is measured against what its geometry costs by itself.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshDraws {
    /// Where the objects are drawn and with which matrix.
    pub views: MeshViews,
    /// Back faces are culled (the G-buffer) or not (the light-space maps: open meshes cast
    /// from both sides).
    pub cull_back: bool,
}

/// The views a mesh pass draws every object into.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshViews {
    /// Once, with the camera's matrix, over the whole render area.
    Camera,
    /// Once per light-space face: the face's matrix from the shadow table, its viewport the
    /// tile at `(x, y)` with edge `tile` texels (in face order).
    ShadowFaces {
        /// Each face's tile origin in the atlas, in texels.
        origins: Vec<(u32, u32)>,
        /// A tile's edge in texels.
        tile: u32,
    },
}

/// One read or write of one version of one resource.
#[derive(Clone, Debug, PartialEq)]
pub struct Use {
    /// The resource.
    pub resource: ResourceId,
    /// The version read, or for writes the version produced.
    pub version: u32,
    /// How it is touched.
    pub access: Access,
    /// For attachment writes: the load op.
    pub load: Option<LoadOp>,
}

/// One pass as declared.
pub struct PassDecl {
    /// Name used for the debug label, timer scope, and plan dump.
    pub name: String,
    /// Raster, compute or transfer.
    pub kind: PassKind,
    /// Reads, in declaration order.
    pub reads: Vec<Use>,
    /// Writes, in declaration order (colour attachments in attachment-location order).
    pub writes: Vec<Use>,
    /// Never culled (it has effects the graph cannot see, e.g. writes a host buffer).
    pub side_effects: bool,
    /// Texture taps per shaded pixel, when the pass declares them ([`PassBuilder::taps`]);
    /// the benchmark's speed-of-light table counts one per image read otherwise.
    pub taps: Option<u32>,
    /// What the pass draws, when it draws the scene's meshes ([`PassBuilder::mesh_draws`]).
    pub mesh: Option<MeshDraws>,
    /// The code that records the pass; `None` in graph-only tests.
    pub exec: Option<Box<dyn PassExec>>,
}

impl std::fmt::Debug for PassDecl {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PassDecl")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .field("reads", &self.reads)
            .field("writes", &self.writes)
            .finish()
    }
}

/// A frame being declared. Build it, then [`RenderGraph::compile`](crate::graph::RenderGraph::compile) it.
#[derive(Debug, Default)]
pub struct RenderGraph {
    pub(crate) resources: Vec<ResourceDecl>,
    pub(crate) passes: Vec<PassDecl>,
}

impl RenderGraph {
    /// An empty graph.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares an image that lives only inside the frame (its memory may be aliased).
    pub fn create_image(&mut self, name: &str, info: ImageInfo) -> Handle<Image> {
        self.push_resource(name, info, None)
    }

    /// Hands a host's image to the graph. It enters the frame in `import.initial`'s state.
    pub fn import_image(
        &mut self,
        name: &str,
        info: ImageInfo,
        import: ImportedImage,
    ) -> Handle<Image> {
        self.push_resource(name, info, Some(import))
    }

    /// Marks the handle's version as an output of the frame, left in `final_access`'s state.
    /// Passes whose results reach no export are culled.
    pub fn export_image(&mut self, handle: &Handle<Image>, final_access: Access) {
        self.resources[handle.id].export = Some(final_access);
    }

    /// Starts declaring a pass; finish it with [`PassBuilder::execute`] or [`PassBuilder::finish`].
    pub fn add_pass(&mut self, name: &str, kind: PassKind) -> PassBuilder<'_> {
        PassBuilder {
            graph: self,
            decl: PassDecl {
                name: name.to_string(),
                kind,
                reads: Vec::new(),
                writes: Vec::new(),
                side_effects: false,
                taps: None,
                mesh: None,
                exec: None,
            },
        }
    }

    /// The declared resources.
    pub fn resources(&self) -> &[ResourceDecl] {
        &self.resources
    }

    fn push_resource(
        &mut self,
        name: &str,
        info: ImageInfo,
        import: Option<ImportedImage>,
    ) -> Handle<Image> {
        self.resources.push(ResourceDecl {
            name: name.to_string(),
            info,
            import,
            export: None,
            versions: 0,
        });
        Handle {
            id: self.resources.len() - 1,
            version: 0,
            _kind: PhantomData,
        }
    }
}

/// Declares one pass's reads and writes.
pub struct PassBuilder<'g> {
    graph: &'g mut RenderGraph,
    decl: PassDecl,
}

impl PassBuilder<'_> {
    fn read(&mut self, handle: &Handle<Image>, access: Access) {
        self.decl.reads.push(Use {
            resource: handle.id,
            version: handle.version,
            access,
            load: None,
        });
    }

    fn write(&mut self, handle: &mut Handle<Image>, access: Access, load: Option<LoadOp>) {
        // A load of the old contents is a read of the previous version.
        if load == Some(LoadOp::Load) {
            self.read(handle, access);
        }
        let resource = &mut self.graph.resources[handle.id];
        resource.versions += 1;
        handle.version = resource.versions;
        self.decl.writes.push(Use {
            resource: handle.id,
            version: handle.version,
            access,
            load,
        });
    }

    /// Writes a colour attachment; location = order of `color` calls.
    pub fn color(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.write(handle, Access::ColorAttachmentWrite, Some(load));
        self
    }

    /// Writes (and tests against) the depth attachment.
    pub fn depth(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.write(handle, Access::DepthAttachmentWrite, Some(load));
        self
    }

    /// Tests against a read-only depth attachment.
    pub fn depth_read(&mut self, handle: &Handle<Image>) -> &mut Self {
        self.read(handle, Access::DepthAttachmentRead);
        self
    }

    /// Reads the image only at the pixel being shaded (`subpassLoad`); lets the graph merge this
    /// pass with the one that wrote the image. Binding = order of `input` calls.
    pub fn input(&mut self, handle: &Handle<Image>) -> &mut Self {
        let access = self.input_access(handle);
        self.read(handle, access);
        self
    }

    /// How [`Self::input`] reads the image: as a depth or a colour input attachment.
    pub fn input_access(&self, handle: &Handle<Image>) -> Access {
        if self
            .info(handle)
            .aspect()
            .contains(vk::ImageAspectFlags::DEPTH)
        {
            Access::DepthInputAttachmentRead
        } else {
            Access::InputAttachmentRead
        }
    }

    /// Size and format of the image.
    pub fn info(&self, handle: &Handle<Image>) -> ImageInfo {
        self.graph.resources[handle.id].info
    }

    /// Whether the pass declared a read of the image's current version so far.
    pub fn reads(&self, handle: &Handle<Image>) -> bool {
        self.decl
            .reads
            .iter()
            .any(|u| u.resource == handle.id && u.version == handle.version)
    }

    /// Samples the image anywhere (neighbourhood reads, e.g. a blur): never merged with its writer.
    pub fn sample(&mut self, handle: &Handle<Image>) -> &mut Self {
        let access = if self.decl.kind == PassKind::Compute {
            Access::ComputeSampledRead
        } else {
            Access::FragmentSampledRead
        };
        self.read(handle, access);
        self
    }

    /// Reads a storage image in a compute pass.
    pub fn storage_read(&mut self, handle: &Handle<Image>) -> &mut Self {
        self.read(handle, Access::ComputeStorageRead);
        self
    }

    /// Writes a storage image in a compute pass (`Load` keeps the old contents).
    pub fn storage_write(&mut self, handle: &mut Handle<Image>, load: LoadOp) -> &mut Self {
        self.write(handle, Access::ComputeStorageWrite, Some(load));
        self
    }

    /// Reads the image as a copy source.
    pub fn transfer_src(&mut self, handle: &Handle<Image>) -> &mut Self {
        self.read(handle, Access::TransferRead);
        self
    }

    /// Writes the image as a copy destination.
    pub fn transfer_dst(&mut self, handle: &mut Handle<Image>) -> &mut Self {
        self.write(handle, Access::TransferWrite, Some(LoadOp::DontCare));
        self
    }

    /// The pass has effects the graph cannot see; never cull it.
    pub fn side_effects(&mut self) -> &mut Self {
        self.decl.side_effects = true;
        self
    }

    /// Declares how many texture taps the pass's shader makes per pixel (a blur: its kernel's
    /// taps, times the images it reads at each). The benchmark divides the pass's time by it;
    /// without it, each image the pass reads counts as one tap.
    pub fn taps(&mut self, per_pixel: u32) -> &mut Self {
        self.decl.taps = Some(per_pixel);
        self
    }

    /// Declares that the pass draws the scene's meshes, and how ([`MeshDraws`]): the
    /// benchmark then holds it against the same draws with a trivial shader, instead of a
    /// fullscreen copy of its bytes.
    pub fn mesh_draws(&mut self, draws: MeshDraws) -> &mut Self {
        self.decl.mesh = Some(draws);
        self
    }

    /// Finishes the pass with the code that records it.
    pub fn execute(self, exec: impl PassExec + 'static) {
        let mut decl = self.decl;
        decl.exec = Some(Box::new(exec));
        self.graph.passes.push(decl);
    }

    /// Finishes the pass without recording code (graph-only tests and plan dumps).
    pub fn finish(self) {
        self.graph.passes.push(self.decl);
    }

    /// Finishes a raster pass whose work is its attachments' load ops (a clear): it records no
    /// draw, but runs on a GPU.
    pub fn clears_only(self) {
        self.execute(ClearsOnly);
    }
}

/// The code behind [`PassBuilder::clears_only`]: nothing beyond the render pass's clears.
struct ClearsOnly;

impl PassExec for ClearsOnly {
    fn prepare(&mut self, _: &super::PrepareContext<'_>) -> crate::Result<()> {
        Ok(())
    }
    fn record(&self, _: &super::RecordContext<'_>) {}
    fn destroy(&mut self, _: &crate::backend::GpuContext) {}
}

/// Two images a multi-pass blur alternates between: each step reads one and writes the other.
#[derive(Debug)]
pub struct PingPong {
    /// The image holding the newest result.
    pub current: Handle<Image>,
    /// The image the next step writes.
    pub spare: Handle<Image>,
}

impl PingPong {
    /// A pair: `current` holds the input, `spare` is scratch of the same size.
    pub fn new(current: Handle<Image>, spare: Handle<Image>) -> Self {
        Self { current, spare }
    }

    /// One step: returns (source to read, destination to write), then swaps, so after the pass
    /// `current` names the freshly written image.
    pub fn step(&mut self) -> (&Handle<Image>, &mut Handle<Image>) {
        std::mem::swap(&mut self.current, &mut self.spare);
        (&self.spare, &mut self.current)
    }
}
