//! Pass-level helpers: a pass's pipeline with its descriptor set ([`PassPipeline`]) and its
//! fullscreen draws over tile rectangles, and the render graph's contexts as the backend's
//! pipeline targets. The ash-level pipeline and descriptor code is [`crate::backend::pipeline`]
//! and [`crate::backend::descriptor`]; passes that draw meshes use it from there. Also
//! [`numbered_from_one`], which the SSS and layered passes' ID maps share.

use ash::vk;

use crate::backend::bindings::SetBinding;
use crate::backend::descriptor::{Binding, DescriptorSet};
use crate::backend::pipeline::{GraphicsPipeline, GraphicsPipelineDesc};
use crate::backend::pipeline::{PipelineTarget, Recording};
use crate::backend::shader::ShaderCompiler;
use crate::backend::GpuContext;
use crate::graph::{PrepareContext, RecordContext};
use crate::Result;

// The mesh stream's stride the backend builds vertex input with is the scene's vertex.
const _: () = assert!(
    std::mem::size_of::<crate::scene::mesh::Vertex>()
        == crate::backend::pipeline::MESH_VERTEX_BYTES as usize
);

impl PipelineTarget for PrepareContext<'_> {
    fn gpu(&self) -> &GpuContext {
        self.gpu
    }
    fn shaders(&self) -> &ShaderCompiler {
        self.shaders
    }
    fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache
    }
    fn render_pass(&self) -> vk::RenderPass {
        self.render_pass
    }
    fn subpass(&self) -> u32 {
        self.subpass
    }
    fn color_attachment_count(&self) -> u32 {
        self.color_attachment_count
    }
}

impl Recording for RecordContext<'_> {
    fn gpu(&self) -> &GpuContext {
        self.gpu
    }
    fn cmd(&self) -> vk::CommandBuffer {
        self.cmd
    }
    fn frame(&self) -> usize {
        self.frame
    }
}

/// A pass's shader defines, `("NAME", "VALUE")` (see [`crate::shipped`]).
pub type Defines = Vec<(&'static str, &'static str)>;

/// Lit HDR colour: the lighting pass's output and what the SSS blurs and Li et al.'s terms
/// write (here, below both, so that the blurs need not import the lighting).
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// LCB and LBB: view-plane LEAN slope y and moments (blurred, so at least fp16): the G-buffer
/// pass writes it, or for a host the SSS chains' own pass (here, below both, so that the
/// blurs need not import the G-buffer).
pub const LEAN_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// A pass's pipeline together with its descriptor set: what most passes hold after `prepare`.
pub struct PassPipeline {
    /// The pipeline.
    pub pipeline: GraphicsPipeline,
    /// Its one descriptor set (set 0).
    pub set: DescriptorSet,
    /// The set's bindings as declared (names, kinds), which a variant's shaders bind by too.
    declared: Vec<SetBinding<'static>>,
}

impl PassPipeline {
    /// Creates the descriptor set from `bindings` (visible to vertex and fragment stages), each
    /// with the name the shaders give it, which numbers it there
    /// ([`crate::backend::bindings`]), and the pipeline described by `desc` with that set as
    /// set 0.
    pub fn new(
        ctx: &PrepareContext<'_>,
        bindings: &[(&'static str, Binding)],
        desc: &GraphicsPipelineDesc<'_>,
    ) -> Result<Self> {
        let declared: Vec<SetBinding<'static>> = bindings
            .iter()
            .map(|(name, b)| SetBinding {
                name: Some(name),
                kind: b.kind(),
            })
            .collect();
        let resources: Vec<Binding> = bindings.iter().map(|(_, b)| *b).collect();
        let mut set = DescriptorSet::new(
            ctx,
            &resources,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            desc.name,
            ctx.slots,
        )?;
        let layouts = [set.layout];
        let desc = GraphicsPipelineDesc {
            set_layouts: &layouts,
            bindings: &declared,
            ..*desc
        };
        match GraphicsPipeline::new(ctx, &desc) {
            Ok(pipeline) => Ok(Self {
                pipeline,
                set,
                declared,
            }),
            Err(e) => {
                set.destroy(&ctx.gpu.device);
                Err(e)
            }
        }
    }

    /// A second pipeline of `desc` with `extra` defines added, bound with this pipeline's set
    /// (a shader variant the pass draws in some rectangles). On failure this pipeline is
    /// destroyed too, so the caller's `?` leaves nothing behind.
    pub fn with_variant(
        self,
        ctx: &PrepareContext<'_>,
        desc: &GraphicsPipelineDesc<'_>,
        extra: &[(&str, &str)],
        name: &str,
    ) -> Result<(Self, GraphicsPipeline)> {
        let mut defines = desc.defines.to_vec();
        defines.extend_from_slice(extra);
        let layouts = [self.set.layout];
        let variant = GraphicsPipeline::new(
            ctx,
            &GraphicsPipelineDesc {
                defines: &defines,
                set_layouts: &layouts,
                bindings: &self.declared,
                name,
                ..*desc
            },
        );
        match variant {
            Ok(variant) => Ok((self, variant)),
            Err(e) => {
                let mut this = self;
                this.destroy(&ctx.gpu.device);
                Err(e)
            }
        }
    }

    /// Binds the pipeline and its set (per-frame bindings at the recorded frame's slot).
    pub fn bind(&self, ctx: &crate::graph::RecordContext<'_>) {
        // SAFETY: the pipeline is alive; the executor began this pass's subpass.
        unsafe {
            ctx.gpu.device.cmd_bind_pipeline(
                ctx.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.pipeline.pipeline,
            );
        }
        self.set.bind(ctx, self.pipeline.layout, 0);
    }

    /// Binds and draws the fullscreen triangle (glsl/fullscreen.vert).
    pub fn draw_fullscreen(&self, ctx: &crate::graph::RecordContext<'_>) {
        self.bind(ctx);
        // SAFETY: bound above, inside the pass's subpass.
        unsafe { ctx.gpu.device.cmd_draw(ctx.cmd, 3, 1, 0, 0) };
    }

    /// Draws the fullscreen triangle once per rectangle, each under its own scissor (the
    /// pipeline must be bound), then restores the scissor to the render area.
    pub fn draw_fullscreen_in<'r>(
        ctx: &crate::graph::RecordContext<'_>,
        rects: impl IntoIterator<Item = &'r crate::gpu_scene::TileRect>,
    ) {
        let device = &ctx.gpu.device;
        // SAFETY: scissor is dynamic state of every lucent pipeline; called inside a subpass
        // with a pipeline bound.
        unsafe {
            for r in rects {
                let scissor = vk::Rect2D {
                    offset: vk::Offset2D {
                        x: r.x as i32,
                        y: r.y as i32,
                    },
                    extent: vk::Extent2D {
                        width: r.width,
                        height: r.height,
                    },
                };
                device.cmd_set_scissor(ctx.cmd, 0, &[scissor]);
                device.cmd_draw(ctx.cmd, 3, 1, 0, 0);
            }
            device.cmd_set_scissor(
                ctx.cmd,
                0,
                &[vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent: ctx.extent,
                }],
            );
        }
    }

    /// Destroys pipeline and set.
    pub fn destroy(&mut self, device: &ash::Device) {
        self.pipeline.destroy(device);
        self.set.destroy(device);
    }
}

/// Sets the viewport and scissor to the square tile of edge `edge` texels at `origin` (a
/// light-space face's tile of the atlas): where the light-space maps pass, and its floor in the
/// benchmark, draw one face. A pipeline must be bound (viewport and scissor are dynamic state
/// of every lucent pipeline); nothing restores the executor's full-area viewport afterwards,
/// so a pass that draws into tiles sets each tile it draws.
pub fn set_tile_viewport(ctx: &RecordContext<'_>, origin: (u32, u32), edge: u32) {
    let (x, y) = origin;
    let viewport = vk::Viewport {
        x: x as f32,
        y: y as f32,
        width: edge as f32,
        height: edge as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    let scissor = vk::Rect2D {
        offset: vk::Offset2D {
            x: x as i32,
            y: y as i32,
        },
        extent: vk::Extent2D {
            width: edge,
            height: edge,
        },
    };
    // SAFETY: called while recording inside a render pass with a lucent pipeline bound.
    unsafe {
        ctx.gpu.device.cmd_set_viewport(ctx.cmd, 0, &[viewport]);
        ctx.gpu.device.cmd_set_scissor(ctx.cmd, 0, &[scissor]);
    }
}

/// `n` when IDs 1 to `n` (of 0 to 255) are numbers 1 to `n` of `number_of` and every other ID is
/// 0, `n` at least 1: a G-buffer whose material IDs are the SSS profile or layered material
/// numbers themselves, which the passes then read with no lookup.
pub fn numbered_from_one(number_of: impl Fn(usize) -> usize) -> Option<usize> {
    let n = (0..256).filter(|&id| number_of(id) != 0).count();
    let numbered = (0..256).all(|id| number_of(id) == if (1..=n).contains(&id) { id } else { 0 });
    (n > 0 && numbered).then_some(n)
}
