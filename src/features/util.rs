//! Small helpers every pass uses to build its pipeline and descriptor set: one level over ash.

use ash::vk;

use crate::backend::shader::create_shader_module;
use crate::error::VkResultExt;
use crate::graph::PrepareContext;
use crate::Result;

/// A sampler that clamps to the edge with `filter` for magnification and minification (what the
/// fullscreen passes sample their inputs with).
pub fn clamp_sampler(ctx: &PrepareContext<'_>, filter: vk::Filter) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(filter)
        .min_filter(filter)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
    // SAFETY: valid device and create info.
    unsafe { ctx.gpu.device.create_sampler(&info, None) }.vk("vkCreateSampler")
}

/// A pass's shader defines, `("NAME", "VALUE")` (see [`crate::features::shipped`]).
pub type Defines = Vec<(&'static str, &'static str)>;

/// Checks that a pass built the descriptor bindings its shader permutation numbers from:
/// binding numbers in defines come from the pass's shape ([`crate::features::shipped`] lists
/// every permutation), so `built` (the bindings made) must be `expected` (what the defines say).
pub fn check_bindings(pass: &str, built: usize, expected: usize) -> Result<()> {
    if built == expected {
        return Ok(());
    }
    Err(crate::LucentError::Graph(format!(
        "pass '{pass}': {built} descriptor bindings before the next group, but its shader \
         permutation numbers them from {expected} (the pass's bindings and its defines disagree)"
    )))
}

/// What one descriptor binding points at.
pub enum Binding {
    /// A uniform buffer (whole range).
    Uniform(vk::Buffer),
    /// A region of the per-frame buffer: a dynamic uniform buffer bound at the recorded
    /// frame's slot ([`crate::gpu_scene::PerFrame`]).
    PerFrame(crate::gpu_scene::PerFrameBinding),
    /// An input attachment (same-pixel read) in the given layout.
    InputAttachment(vk::ImageView, vk::ImageLayout),
    /// A combined image sampler in SHADER_READ_ONLY_OPTIMAL.
    Sampled(vk::ImageView, vk::Sampler),
}

/// A descriptor set with its own pool and layout (passes have one set each).
pub struct DescriptorSet {
    /// Layout, for the pipeline layout.
    pub layout: vk::DescriptorSetLayout,
    /// The set, to bind.
    pub set: vk::DescriptorSet,
    pool: vk::DescriptorPool,
    /// Per-frame bindings (dynamic uniform buffers) and their slot stride: each is bound at
    /// `slot * stride`.
    dynamic: u32,
    stride: u64,
}

impl DescriptorSet {
    /// Creates and writes a set; binding `i` of the set is `bindings[i]`, visible to `stages`.
    pub fn new(
        ctx: &PrepareContext<'_>,
        bindings: &[Binding],
        stages: vk::ShaderStageFlags,
        name: &str,
    ) -> Result<Self> {
        let device = &ctx.gpu.device;
        let kind = |b: &Binding| match b {
            Binding::Uniform(_) => vk::DescriptorType::UNIFORM_BUFFER,
            Binding::PerFrame(_) => vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC,
            Binding::InputAttachment(..) => vk::DescriptorType::INPUT_ATTACHMENT,
            Binding::Sampled(..) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        };
        let layout_bindings: Vec<vk::DescriptorSetLayoutBinding> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let stage = if matches!(b, Binding::InputAttachment(..)) {
                    vk::ShaderStageFlags::FRAGMENT
                } else {
                    stages
                };
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(kind(b))
                    .descriptor_count(1)
                    .stage_flags(stage)
            })
            .collect();
        // SAFETY: valid device; arrays outlive each call.
        let layout = unsafe {
            device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                None,
            )
        }
        .vk("vkCreateDescriptorSetLayout")?;
        let sizes: Vec<vk::DescriptorPoolSize> = bindings
            .iter()
            .map(|b| vk::DescriptorPoolSize {
                ty: kind(b),
                descriptor_count: 1,
            })
            .collect();
        // SAFETY: as above.
        let pool = unsafe {
            device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(1)
                    .pool_sizes(&sizes),
                None,
            )
        }
        .vk("vkCreateDescriptorPool");
        let pool = match pool {
            Ok(p) => p,
            Err(e) => {
                // SAFETY: created above, unused.
                unsafe { device.destroy_descriptor_set_layout(layout, None) };
                return Err(e);
            }
        };
        let layouts = [layout];
        // SAFETY: the pool has room for exactly this set.
        let set = unsafe {
            device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
        }
        .vk("vkAllocateDescriptorSets")?[0];
        ctx.gpu.set_name(set, name);
        let buffer_infos: Vec<[vk::DescriptorBufferInfo; 1]> = bindings
            .iter()
            .map(|b| match b {
                Binding::Uniform(buffer) => [vk::DescriptorBufferInfo {
                    buffer: *buffer,
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }],
                Binding::PerFrame(p) => [vk::DescriptorBufferInfo {
                    buffer: p.buffer,
                    offset: p.offset,
                    range: p.range,
                }],
                _ => [vk::DescriptorBufferInfo::default()],
            })
            .collect();
        let image_infos: Vec<[vk::DescriptorImageInfo; 1]> = bindings
            .iter()
            .map(|b| match b {
                Binding::InputAttachment(view, layout) => [vk::DescriptorImageInfo {
                    sampler: vk::Sampler::null(),
                    image_view: *view,
                    image_layout: *layout,
                }],
                Binding::Sampled(view, sampler) => [vk::DescriptorImageInfo {
                    sampler: *sampler,
                    image_view: *view,
                    image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                }],
                Binding::Uniform(_) | Binding::PerFrame(_) => [vk::DescriptorImageInfo::default()],
            })
            .collect();
        let writes: Vec<vk::WriteDescriptorSet> = bindings
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let w = vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(kind(b));
                match b {
                    Binding::Uniform(_) | Binding::PerFrame(_) => w.buffer_info(&buffer_infos[i]),
                    _ => w.image_info(&image_infos[i]),
                }
            })
            .collect();
        // SAFETY: every write names a live set, buffer, view and sampler.
        unsafe { device.update_descriptor_sets(&writes, &[]) };
        let per_frame: Vec<u64> = bindings
            .iter()
            .filter_map(|b| match b {
                Binding::PerFrame(p) => Some(p.stride),
                _ => None,
            })
            .collect();
        Ok(Self {
            layout,
            set,
            pool,
            dynamic: per_frame.len() as u32,
            // Every per-frame region lives in the same buffer: one stride.
            stride: per_frame.first().copied().unwrap_or(0),
        })
    }

    /// Binds the set as set `index` of `layout`, its per-frame bindings at the recorded
    /// frame's slot.
    pub fn bind(
        &self,
        ctx: &crate::graph::RecordContext<'_>,
        layout: vk::PipelineLayout,
        index: u32,
    ) {
        // At most MAX_FRAMES_IN_FLIGHT slots of a few tens of kilobytes: fits u32.
        let offset = (self.stride * ctx.frame as u64) as u32;
        let offsets = vec![offset; self.dynamic as usize];
        // SAFETY: the set and layout are alive; the executor began this pass's subpass.
        unsafe {
            ctx.gpu.device.cmd_bind_descriptor_sets(
                ctx.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                layout,
                index,
                &[self.set],
                &offsets,
            );
        }
    }

    /// Destroys the pool (and with it the set) and the layout.
    pub fn destroy(&mut self, device: &ash::Device) {
        // SAFETY: created by `new` on this device; the caller guarantees the GPU is done.
        unsafe {
            device.destroy_descriptor_pool(self.pool, None);
            device.destroy_descriptor_set_layout(self.layout, None);
        }
        self.pool = vk::DescriptorPool::null();
        self.layout = vk::DescriptorSetLayout::null();
        self.dynamic = 0;
    }
}

/// Vertex input of a graphics pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexInput {
    /// No vertex buffer (fullscreen triangle from `gl_VertexIndex`).
    None,
    /// A mesh: interleaved position + normal ([`crate::scene::mesh::Vertex`], binding 0),
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
    /// Descriptor set layouts (set 0, 1, ...); [`PassPipeline::new`] fills in its own.
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    /// Push constant bytes visible to vertex and fragment stages.
    pub push_constant_bytes: u32,
    /// Name for debug tools.
    pub name: &'a str,
}

impl<'a> GraphicsPipelineDesc<'a> {
    /// A fullscreen pass's pipeline: the fullscreen triangle (`fullscreen.vert`, no vertex
    /// buffer), no depth test, no culling, no blending, no push constants; change the rest
    /// with struct update syntax.
    pub fn fullscreen(fragment: &'a str, defines: &'a [(&'a str, &'a str)], name: &'a str) -> Self {
        Self {
            vertex: crate::backend::shader::FULLSCREEN_VERTEX,
            fragment,
            defines,
            vertex_input: VertexInput::None,
            depth_test: false,
            cull_back: false,
            additive_attachments: 0,
            set_layouts: &[],
            push_constant_bytes: 0,
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
    pub fn new(ctx: &PrepareContext<'_>, desc: &GraphicsPipelineDesc<'_>) -> Result<Self> {
        let device = &ctx.gpu.device;
        let vert = ctx.shaders.compile(desc.vertex, desc.defines)?;
        let frag = ctx.shaders.compile(desc.fragment, desc.defines)?;
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
        ctx: &PrepareContext<'_>,
        desc: &GraphicsPipelineDesc<'_>,
        vert: vk::ShaderModule,
        frag: vk::ShaderModule,
    ) -> Result<Self> {
        let device = &ctx.gpu.device;
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
        let stages = [
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vert)
                .name(entry),
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::FRAGMENT)
                .module(frag)
                .name(entry),
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
            vertex_bindings.push(binding(
                0,
                std::mem::size_of::<crate::scene::mesh::Vertex>() as u32,
            ));
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
        if let VertexInput::Positions = desc.vertex_input {
            vertex_bindings.push(binding(
                0,
                std::mem::size_of::<crate::scene::mesh::Vertex>() as u32,
            ));
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
            .color_attachment_count)
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
            .render_pass(ctx.render_pass)
            .subpass(ctx.subpass);
        // SAFETY: every referenced struct lives until the call returns.
        let pipelines =
            unsafe { device.create_graphics_pipelines(ctx.pipeline_cache, &[info], None) };
        match pipelines {
            Ok(p) => {
                ctx.gpu.set_name(p[0], desc.name);
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

/// A pass's pipeline together with its descriptor set: what most passes hold after `prepare`.
pub struct PassPipeline {
    /// The pipeline.
    pub pipeline: GraphicsPipeline,
    /// Its one descriptor set (set 0).
    pub set: DescriptorSet,
}

impl PassPipeline {
    /// Creates the descriptor set from `bindings` (visible to vertex and fragment stages) and
    /// the pipeline described by `desc` with that set as set 0.
    pub fn new(
        ctx: &PrepareContext<'_>,
        bindings: &[Binding],
        desc: &GraphicsPipelineDesc<'_>,
    ) -> Result<Self> {
        let mut set = DescriptorSet::new(
            ctx,
            bindings,
            vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            desc.name,
        )?;
        let layouts = [set.layout];
        let desc = GraphicsPipelineDesc {
            set_layouts: &layouts,
            ..*desc
        };
        match GraphicsPipeline::new(ctx, &desc) {
            Ok(pipeline) => Ok(Self { pipeline, set }),
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

/// A full-screen pass that reads one image through a sampler: the frame uniforms at binding 0,
/// the image at binding 1, one fragment shader with fixed defines (the tonemap, FXAA). The
/// pass that declares it owns nothing else.
pub(crate) struct SampleOnePass {
    /// The scene on the GPU (the per-frame uniforms).
    scene: std::sync::Arc<crate::gpu_scene::SceneGpu>,
    /// The image sampled.
    input: crate::graph::ResourceId,
    /// Nearest (one texel per pixel) or linear (taps between texels).
    filter: vk::Filter,
    /// Fragment shader under `glsl/`.
    fragment: &'static str,
    /// Its defines.
    defines: &'static [(&'static str, &'static str)],
    /// The pipeline's debug name.
    name: &'static str,
    sampler: vk::Sampler,
    pipeline: Option<PassPipeline>,
}

impl SampleOnePass {
    /// The pass, its sampler and pipeline made in `prepare`.
    pub fn new(
        scene: std::sync::Arc<crate::gpu_scene::SceneGpu>,
        input: crate::graph::ResourceId,
        filter: vk::Filter,
        fragment: &'static str,
        defines: &'static [(&'static str, &'static str)],
        name: &'static str,
    ) -> Self {
        Self {
            scene,
            input,
            filter,
            fragment,
            defines,
            name,
            sampler: vk::Sampler::null(),
            pipeline: None,
        }
    }
}

impl crate::graph::PassExec for SampleOnePass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.sampler = clamp_sampler(ctx, self.filter)?;
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[
                Binding::PerFrame(
                    self.scene
                        .per_frame
                        .binding(crate::gpu_scene::Region::Frame),
                ),
                Binding::Sampled(ctx.views[self.input], self.sampler),
            ],
            &GraphicsPipelineDesc::fullscreen(self.fragment, self.defines, self.name),
        )?);
        Ok(())
    }

    fn record(&self, ctx: &crate::graph::RecordContext<'_>) {
        if let Some(pipeline) = &self.pipeline {
            pipeline.draw_fullscreen(ctx);
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created in prepare (or null); the GPU is done (caller's contract).
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}
