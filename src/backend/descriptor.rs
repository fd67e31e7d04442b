//! Descriptor sets: what a pass's shader reads ([`Binding`]), one set with its own pool and
//! layout per pass ([`DescriptorSet`]), and the samplers the bindings sample through.

use ash::vk;

use super::pipeline::{PipelineTarget, Recording};
use crate::error::VkResultExt;
use crate::Result;

/// A sampler that clamps to the edge with `filter` for magnification and minification (what the
/// fullscreen passes sample their inputs with).
pub fn clamp_sampler(ctx: &impl PipelineTarget, filter: vk::Filter) -> Result<vk::Sampler> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(filter)
        .min_filter(filter)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
    // SAFETY: valid device and create info.
    unsafe { ctx.gpu().device.create_sampler(&info, None) }.vk("vkCreateSampler")
}

/// One region of a buffer that holds a copy per frame-in-flight slot, bound as a dynamic
/// uniform buffer whose offset is added at bind time (`slot * stride`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DynamicUniform {
    /// The buffer.
    pub buffer: vk::Buffer,
    /// The region's offset in slot 0.
    pub offset: u64,
    /// The region's size.
    pub range: u64,
    /// Bytes from one slot to the next.
    pub stride: u64,
}

/// What one descriptor binding points at.
#[derive(Clone, Copy, Debug)]
pub enum Binding {
    /// A uniform buffer (whole range).
    Uniform(vk::Buffer),
    /// A region of a buffer with one copy per frame-in-flight slot: a dynamic uniform buffer
    /// bound at the recorded frame's slot (lucent's per-frame buffer).
    PerFrame(DynamicUniform),
    /// An input attachment (same-pixel read) in the given layout.
    InputAttachment(vk::ImageView, vk::ImageLayout),
    /// A combined image sampler in SHADER_READ_ONLY_OPTIMAL.
    Sampled(vk::ImageView, vk::Sampler),
    /// A combined image sampler whose view is given per frame slot
    /// ([`DescriptorSet::write_view`]): a host's image bound when its frame is recorded. The
    /// set then has one copy per slot.
    SampledPerSlot(vk::Sampler),
}

impl Binding {
    /// The descriptor type it is bound as.
    pub fn kind(&self) -> vk::DescriptorType {
        match self {
            Binding::Uniform(_) => vk::DescriptorType::UNIFORM_BUFFER,
            Binding::PerFrame(_) => vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC,
            Binding::InputAttachment(..) => vk::DescriptorType::INPUT_ATTACHMENT,
            Binding::Sampled(..) | Binding::SampledPerSlot(_) => {
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER
            }
        }
    }
}

/// A descriptor set with its own pool and layout (passes have one set each), or one copy of it
/// per frame slot when a binding's view is given per slot.
pub struct DescriptorSet {
    /// Layout, for the pipeline layout.
    pub layout: vk::DescriptorSetLayout,
    /// The set, to bind (slot 0's copy when there are several).
    pub set: vk::DescriptorSet,
    /// One copy per frame slot when some binding is [`Binding::SampledPerSlot`] (empty
    /// otherwise): slot `k` binds `per_slot[k]`.
    per_slot: Vec<vk::DescriptorSet>,
    /// The samplers of the per-slot bindings, by binding index.
    per_slot_samplers: Vec<(u32, vk::Sampler)>,
    pool: vk::DescriptorPool,
    /// Per-frame bindings (dynamic uniform buffers) and their slot stride: each is bound at
    /// `slot * stride`.
    dynamic: u32,
    stride: u64,
}

impl DescriptorSet {
    /// Creates and writes a set; binding `i` of the set is `bindings[i]`, visible to `stages`.
    /// With a [`Binding::SampledPerSlot`] among them, `slots` copies, each written with the
    /// other bindings; the per-slot views are written by [`Self::write_view`].
    pub fn new(
        ctx: &impl PipelineTarget,
        bindings: &[Binding],
        stages: vk::ShaderStageFlags,
        name: &str,
        slots: usize,
    ) -> Result<Self> {
        let copies = if bindings
            .iter()
            .any(|b| matches!(b, Binding::SampledPerSlot(_)))
        {
            slots.max(1)
        } else {
            1
        };
        let device = &ctx.gpu().device;
        let kind = Binding::kind;
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
                descriptor_count: copies as u32,
            })
            .collect();
        // SAFETY: as above.
        let pool = unsafe {
            device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(copies as u32)
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
        let layouts = vec![layout; copies];
        // SAFETY: the pool has room for exactly these sets.
        let allocated = unsafe {
            device.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pool)
                    .set_layouts(&layouts),
            )
        }
        .vk("vkAllocateDescriptorSets");
        let sets = match allocated {
            Ok(sets) => sets,
            Err(e) => {
                // SAFETY: created above, unused.
                unsafe {
                    device.destroy_descriptor_pool(pool, None);
                    device.destroy_descriptor_set_layout(layout, None);
                }
                return Err(e);
            }
        };
        for (k, &set) in sets.iter().enumerate() {
            if copies == 1 {
                ctx.gpu().set_name(set, name);
            } else {
                ctx.gpu().set_name(set, &format!("{name} (slot {k})"));
            }
        }
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
                Binding::Uniform(_) | Binding::PerFrame(_) | Binding::SampledPerSlot(_) => {
                    [vk::DescriptorImageInfo::default()]
                }
            })
            .collect();
        // Every binding but the per-slot views, into every copy.
        let writes: Vec<vk::WriteDescriptorSet> = sets
            .iter()
            .flat_map(|&set| {
                bindings
                    .iter()
                    .enumerate()
                    .filter(|(_, b)| !matches!(b, Binding::SampledPerSlot(_)))
                    .map(move |(i, b)| (set, i, b))
            })
            .map(|(set, i, b)| {
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
        let per_slot_samplers = bindings
            .iter()
            .enumerate()
            .filter_map(|(i, b)| match b {
                Binding::SampledPerSlot(sampler) => Some((i as u32, *sampler)),
                _ => None,
            })
            .collect();
        Ok(Self {
            layout,
            set: sets[0],
            per_slot: if copies > 1 { sets } else { Vec::new() },
            per_slot_samplers,
            pool,
            dynamic: per_frame.len() as u32,
            // Every per-frame region lives in the same buffer: one stride.
            stride: per_frame.first().copied().unwrap_or(0),
        })
    }

    /// Writes `view` into the per-slot binding `binding` of slot `slot`'s copy. That copy must
    /// not be in use by a command buffer still pending (the frame last recorded with the slot
    /// has completed).
    pub fn write_view(
        &self,
        device: &ash::Device,
        slot: usize,
        binding: u32,
        view: vk::ImageView,
    ) -> Result<()> {
        let sampler = self
            .per_slot_samplers
            .iter()
            .find(|(b, _)| *b == binding)
            .map(|&(_, s)| s);
        let set = match sampler {
            // One copy (every slot shares it) when only one slot is recorded.
            Some(_) if self.per_slot.is_empty() => Some(self.set),
            Some(_) => self.per_slot.get(slot).copied(),
            None => None,
        };
        let (Some(sampler), Some(set)) = (sampler, set) else {
            return Err(crate::LucentError::Graph(format!(
                "descriptor binding {binding} of slot {slot} is not written per slot"
            )));
        };
        let info = [vk::DescriptorImageInfo {
            sampler,
            image_view: view,
            image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        }];
        let write = vk::WriteDescriptorSet::default()
            .dst_set(set)
            .dst_binding(binding)
            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .image_info(&info);
        // SAFETY: the set, view and sampler are alive; the caller's contract keeps the set
        // out of pending command buffers.
        unsafe { device.update_descriptor_sets(&[write], &[]) };
        Ok(())
    }

    /// Binds the set as set `index` of `layout` (the recorded frame's copy when there is one
    /// per slot), its per-frame bindings at the recorded frame's slot.
    pub fn bind(&self, ctx: &impl Recording, layout: vk::PipelineLayout, index: u32) {
        let set = self.per_slot.get(ctx.frame()).copied().unwrap_or(self.set);
        // At most MAX_FRAMES_IN_FLIGHT slots of a few tens of kilobytes: fits u32.
        let offset = (self.stride * ctx.frame() as u64) as u32;
        let offsets = vec![offset; self.dynamic as usize];
        // SAFETY: the set and layout are alive; the caller is recording inside a render pass.
        unsafe {
            ctx.gpu().device.cmd_bind_descriptor_sets(
                ctx.cmd(),
                vk::PipelineBindPoint::GRAPHICS,
                layout,
                index,
                &[set],
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
