//! Graphics pipelines: everything that differs between lucent's pipelines
//! ([`GraphicsPipelineDesc`]), made for one render pass and subpass ([`GraphicsPipeline`]).
//!
//! The caller says where a pipeline goes and which command buffer it records into through
//! [`PipelineTarget`] and [`Recording`], so this layer knows nothing of the render graph that
//! places passes (the graph's prepare and record contexts implement both).

use ash::vk;

use super::bindings::{bind_by_name, SetBinding};
use super::shader::{create_shader_module, ShaderCompiler};
use super::GpuContext;
use crate::error::VkResultExt;
use crate::Result;

/// Bytes of one mesh vertex in the position + normal stream (two `f32` triples, lucent's
/// `scene::mesh::Vertex`).
pub const MESH_VERTEX_BYTES: u32 = 24;

/// Where a pipeline is created: the device, the shader compiler, and the render pass and
/// subpass it draws in.
pub trait PipelineTarget {
    /// The context.
    fn gpu(&self) -> &GpuContext;
    /// Shader compiler (with its SPIR-V cache).
    fn shaders(&self) -> &ShaderCompiler;
    /// Pipeline cache to create pipelines with.
    fn pipeline_cache(&self) -> vk::PipelineCache;
    /// The render pass the pipeline draws in.
    fn render_pass(&self) -> vk::RenderPass;
    /// Its subpass index in that render pass.
    fn subpass(&self) -> u32;
    /// Number of colour attachments the subpass writes (for blend state counts).
    fn color_attachment_count(&self) -> u32;
}

/// A command buffer being recorded inside a render pass, for one frame-in-flight slot.
pub trait Recording {
    /// The context.
    fn gpu(&self) -> &GpuContext;
    /// The command buffer.
    fn cmd(&self) -> vk::CommandBuffer;
    /// The frame-in-flight slot: per-frame bindings are bound at its copy.
    fn frame(&self) -> usize;
}

/// Vertex input of a graphics pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexInput {
    /// No vertex buffer (fullscreen triangle from `gl_VertexIndex`).
    None,
    /// A mesh: interleaved position + normal ([`MESH_VERTEX_BYTES`] per vertex, binding 0),
    /// optionally the RGB thickness stream (binding 1, location 2) of G-buffers that carry
    /// translucency, and the UV + tangent stream (binding 2, locations 3 and 4) of
    /// normal-mapped frames.
    Mesh {
        /// Thickness stream.
        thickness: bool,
        /// UV + tangent stream.
        surface: bool,
    },
    /// A mesh's positions only (binding 0, location 0: depth-only passes).
    Positions,
    /// A host's mesh streams as the host lays them out (`lucent::embed::VertexLayout`):
    /// position at location 0 and normal at location 1, each from one of two vertex
    /// buffer bindings with the host's strides, offsets and formats.
    Host(HostVertexInput),
}

/// A host's vertex layout as pipelines take it: two bindings (their strides; 0: the binding is
/// unused) and the position and normal attributes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HostVertexInput {
    /// Bytes between consecutive vertices of bindings 0 and 1.
    pub strides: [u32; 2],
    /// The position: its binding, format and byte offset in a vertex.
    pub position: (u32, vk::Format, u32),
    /// The normal: its binding, format and byte offset in a vertex.
    pub normal: (u32, vk::Format, u32),
    /// The texture coordinate, when the pass reads one (location 3, as lucent's own surface
    /// stream has it): its binding, format and byte offset in a vertex.
    pub uv: Option<(u32, vk::Format, u32)>,
}

/// Everything that differs between lucent's graphics pipelines.
#[derive(Clone, Copy)]
pub struct GraphicsPipelineDesc<'a> {
    /// Vertex shader path under glsl/.
    pub vertex: &'a str,
    /// Fragment shader path under glsl/.
    pub fragment: &'a str,
    /// Macro definitions for both stages.
    pub defines: &'a [(&'a str, &'a str)],
    /// Vertex buffer layout.
    pub vertex_input: VertexInput,
    /// Depth test and write (less).
    pub depth_test: bool,
    /// Cull back faces (closed meshes).
    pub cull_back: bool,
    /// Colour attachments (bit i = attachment i) that add the shader's output to their
    /// contents instead of replacing them.
    pub additive_attachments: u32,
    /// Descriptor set layouts (set 0, 1, ...).
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    /// Set 0's bindings in order, as its layout was made: the shaders' resources take their
    /// numbers from it by name and are checked against it ([`super::bindings`]).
    pub bindings: &'a [SetBinding<'a>],
    /// Push constant bytes visible to vertex and fragment stages.
    pub push_constant_bytes: u32,
    /// The fragment shader's specialization constants: value `i` for `constant_id = i`
    /// (empty: the shader's defaults). For what is fixed when a pipeline is made but varies
    /// too much to be a define (a host's ID decode): the driver folds them into the code.
    pub specialization: &'a [u32],
    /// Name for debug tools.
    pub name: &'a str,
}

impl<'a> GraphicsPipelineDesc<'a> {
    /// A fullscreen pass's pipeline: the fullscreen triangle (`fullscreen.vert`, no vertex
    /// buffer), no depth test, no culling, no blending, no push constants; change the rest
    /// with struct update syntax.
    pub fn fullscreen(fragment: &'a str, defines: &'a [(&'a str, &'a str)], name: &'a str) -> Self {
        Self {
            vertex: "fullscreen.vert",
            fragment,
            defines,
            vertex_input: VertexInput::None,
            depth_test: false,
            cull_back: false,
            additive_attachments: 0,
            set_layouts: &[],
            bindings: &[],
            push_constant_bytes: 0,
            specialization: &[],
            name,
        }
    }
}

/// A graphics pipeline and its layout.
pub struct GraphicsPipeline {
    /// The pipeline.
    pub pipeline: vk::Pipeline,
    /// Its layout.
    pub layout: vk::PipelineLayout,
}

impl GraphicsPipeline {
    /// Compiles the shaders and creates the pipeline for the pass's render pass and subpass.
    /// Viewport and scissor are dynamic (the executor sets them).
    pub fn new(ctx: &impl PipelineTarget, desc: &GraphicsPipelineDesc<'_>) -> Result<Self> {
        let device = &ctx.gpu().device;
        let mut vert = ctx.shaders().compile(desc.vertex, desc.defines)?;
        let mut frag = ctx.shaders().compile(desc.fragment, desc.defines)?;
        for (shader, path) in [(&mut vert, desc.vertex), (&mut frag, desc.fragment)] {
            bind_by_name(&mut shader.spirv, desc.bindings).map_err(|message| {
                crate::LucentError::ShaderBindings {
                    pipeline: desc.name.to_string(),
                    shader: path.to_string(),
                    message,
                }
            })?;
        }
        let vert_module = create_shader_module(device, &vert.spirv)?;
        let frag_module = match create_shader_module(device, &frag.spirv) {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: created above, unused.
                unsafe { device.destroy_shader_module(vert_module, None) };
                return Err(e);
            }
        };
        let result = Self::create(ctx, desc, vert_module, frag_module);
        // SAFETY: modules are only needed during pipeline creation.
        unsafe {
            device.destroy_shader_module(vert_module, None);
            device.destroy_shader_module(frag_module, None);
        }
        result
    }

    fn create(
        ctx: &impl PipelineTarget,
        desc: &GraphicsPipelineDesc<'_>,
        vert: vk::ShaderModule,
        frag: vk::ShaderModule,
    ) -> Result<Self> {
        let device = &ctx.gpu().device;
        let push_ranges = [vk::PushConstantRange {
            stage_flags: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            offset: 0,
            size: desc.push_constant_bytes,
        }];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(desc.set_layouts);
        if desc.push_constant_bytes > 0 {
            layout_info = layout_info.push_constant_ranges(&push_ranges);
        }
        // SAFETY: valid device and set layouts.
        let layout = unsafe { device.create_pipeline_layout(&layout_info, None) }
            .vk("vkCreatePipelineLayout")?;
        let entry = c"main";
        let entries: Vec<vk::SpecializationMapEntry> = (0..desc.specialization.len() as u32)
            .map(|id| vk::SpecializationMapEntry {
                constant_id: id,
                offset: id * 4,
                size: 4,
            })
            .collect();
        let constant_bytes: Vec<u8> = desc
            .specialization
            .iter()
            .flat_map(|v| v.to_ne_bytes())
            .collect();
        let specialization = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(&constant_bytes);
        let mut fragment_stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(frag)
            .name(entry);
        if !desc.specialization.is_empty() {
            fragment_stage = fragment_stage.specialization_info(&specialization);
        }
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vert)
                .name(entry),
            fragment_stage,
        ];
        // Mesh streams: binding 0 position + normal (locations 0, 1); binding 1 the thickness
        // colour (location 2), a buffer of its own so frames without translucency neither
        // store nor fetch it; binding 2 UV + tangent (locations 3, 4) for normal mapping.
        let mut vertex_bindings = Vec::new();
        let mut vertex_attributes = Vec::new();
        let attribute = |location, binding, format, offset| vk::VertexInputAttributeDescription {
            location,
            binding,
            format,
            offset,
        };
        let binding = |binding, stride| vk::VertexInputBindingDescription {
            binding,
            stride,
            input_rate: vk::VertexInputRate::VERTEX,
        };
        if let VertexInput::Mesh { thickness, surface } = desc.vertex_input {
            let vec2 = vk::Format::R32G32_SFLOAT;
            let vec3 = vk::Format::R32G32B32_SFLOAT;
            let vec4 = vk::Format::R32G32B32A32_SFLOAT;
            vertex_bindings.push(binding(0, MESH_VERTEX_BYTES));
            vertex_attributes.push(attribute(0, 0, vec3, 0));
            vertex_attributes.push(attribute(1, 0, vec3, 12));
            if thickness {
                vertex_bindings.push(binding(1, 12));
                vertex_attributes.push(attribute(2, 1, vec3, 0));
            }
            if surface {
                vertex_bindings.push(binding(2, 24));
                vertex_attributes.push(attribute(3, 2, vec2, 0));
                vertex_attributes.push(attribute(4, 2, vec4, 8));
            }
        }
        if let VertexInput::Host(host) = desc.vertex_input {
            for (index, stride) in host.strides.into_iter().enumerate() {
                if stride > 0 {
                    vertex_bindings.push(binding(index as u32, stride));
                }
            }
            for (location, (stream, format, offset)) in
                [host.position, host.normal].into_iter().enumerate()
            {
                vertex_attributes.push(attribute(location as u32, stream, format, offset));
            }
            if let Some((stream, format, offset)) = host.uv {
                vertex_attributes.push(attribute(3, stream, format, offset));
            }
        }
        if let VertexInput::Positions = desc.vertex_input {
            vertex_bindings.push(binding(0, MESH_VERTEX_BYTES));
            vertex_attributes.push(attribute(0, 0, vk::Format::R32G32B32_SFLOAT, 0));
        }
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&vertex_bindings)
            .vertex_attribute_descriptions(&vertex_attributes);
        let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(if desc.cull_back {
                vk::CullModeFlags::BACK
            } else {
                vk::CullModeFlags::NONE
            })
            // Meshes are counter-clockwise seen from outside. The projection flips y
            // (scene::Camera::projection) and Vulkan's framebuffer y points down: the two flips
            // cancel, so front faces stay counter-clockwise.
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(desc.depth_test)
            .depth_write_enable(desc.depth_test)
            .depth_compare_op(vk::CompareOp::LESS);
        let blend_attachments: Vec<vk::PipelineColorBlendAttachmentState> = (0..ctx
            .color_attachment_count())
            .map(|i| {
                let state = vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA);
                if desc.additive_attachments & (1 << i) == 0 {
                    return state;
                }
                // dst += src: accumulation into a target loaded with its previous contents.
                state
                    .blend_enable(true)
                    .src_color_blend_factor(vk::BlendFactor::ONE)
                    .dst_color_blend_factor(vk::BlendFactor::ONE)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ONE)
                    .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                    .alpha_blend_op(vk::BlendOp::ADD)
            })
            .collect();
        let blend =
            vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&input_assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .render_pass(ctx.render_pass())
            .subpass(ctx.subpass());
        // SAFETY: every referenced struct lives until the call returns.
        let pipelines =
            unsafe { device.create_graphics_pipelines(ctx.pipeline_cache(), &[info], None) };
        match pipelines {
            Ok(p) => {
                ctx.gpu().set_name(p[0], desc.name);
                Ok(Self {
                    pipeline: p[0],
                    layout,
                })
            }
            Err((_, e)) => {
                // SAFETY: created above, unused.
                unsafe { device.destroy_pipeline_layout(layout, None) };
                Err(crate::LucentError::Vulkan {
                    call: "vkCreateGraphicsPipelines",
                    result: e,
                })
            }
        }
    }

    /// Destroys the pipeline and its layout.
    pub fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: created by `new`; the caller guarantees the GPU is done.
        unsafe {
            device.destroy_pipeline(self.pipeline, None);
            device.destroy_pipeline_layout(self.layout, None);
        }
        self.pipeline = vk::Pipeline::null();
        self.layout = vk::PipelineLayout::null();
    }
}
