//! The host meshes' own depth textures in lucent's light-space maps (Li et al.'s `TexDep`,
//! [`super::LayeredEffect`]): the maps pass reads each draw's textures at the light's entry
//! point, so every draw binds a set holding the maps' table and its textures. A frame writes
//! one set per distinct pair of textures among its draws, when it records, from a pool of its
//! own frame slot and view (reset first: the frame last recorded with that slot has
//! completed, the host's contract). A pool grows to the most pairs a frame of its slot has
//! had, so its size is bounded by the host's draws, and nothing outlives the effect.

use std::collections::HashMap;

use ash::vk;

use crate::backend::resources::{GpuImage, ImageDesc};
use crate::backend::GpuContext;
use crate::error::VkResultExt;
use crate::features::shadows::HostDepthTextures;
use crate::gpu_scene::PerFrameBinding;
use crate::Result;

/// The sets' layout, sampler, blank texture and per-slot pools (see the module docs).
pub(crate) struct DepthTextureSets {
    layout: vk::DescriptorSetLayout,
    textures: usize,
    sampler: vk::Sampler,
    /// What a draw without depth textures (a mesh that only casts, a medium without texture
    /// layers) binds: one zero texel. Its texels are never read: the single scattering pass
    /// reads an entry's texels only where the entry is a medium with texture layers.
    blank: GpuImage,
    /// Per frame slot and view: its pool and how many sets it holds.
    pools: Vec<(vk::DescriptorPool, u32)>,
}

impl DepthTextureSets {
    /// The layout for `textures` depth textures per draw (1 or 2), its sampler, the blank
    /// texture (an upload: call it inside the effect's upload recording) and `rings` empty
    /// pools.
    pub(crate) fn new(gpu: &GpuContext, textures: usize, rings: usize) -> Result<Self> {
        let kinds = crate::features::shadows::HostDepthTextures::bindings(textures);
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let bindings: Vec<vk::DescriptorSetLayoutBinding> = kinds
            .iter()
            .enumerate()
            .map(|(i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(b.kind)
                    .descriptor_count(1)
                    .stage_flags(stages)
            })
            .collect();
        // SAFETY: a valid create info on the host's device; destroyed in `destroy` (or below
        // on failure).
        let layout = unsafe {
            gpu.device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
        }
        .vk("vkCreateDescriptorSetLayout")?;
        let sampler = match crate::gpu_scene::create_repeat_sampler(gpu) {
            Ok(sampler) => sampler,
            Err(e) => {
                // SAFETY: created above, unused.
                unsafe { gpu.device.destroy_descriptor_set_layout(layout, None) };
                return Err(e);
            }
        };
        let blank = gpu.upload_image(
            &ImageDesc::color(
                1,
                1,
                vk::Format::R8G8B8A8_UNORM,
                vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
            ),
            &[vec![0; 4]],
            "layered maps: no depth texture",
        );
        let blank = match blank {
            Ok(blank) => blank,
            Err(e) => {
                // SAFETY: created above, unused.
                unsafe {
                    gpu.device.destroy_sampler(sampler, None);
                    gpu.device.destroy_descriptor_set_layout(layout, None);
                }
                return Err(e);
            }
        };
        Ok(Self {
            layout,
            textures: textures.clamp(1, 2),
            sampler,
            blank,
            pools: vec![(vk::DescriptorPool::null(), 0); rings],
        })
    }

    /// What the maps pass's pipeline is made with.
    pub(crate) fn host_depth_textures(&self) -> HostDepthTextures {
        HostDepthTextures {
            layout: self.layout,
            textures: self.textures,
        }
    }

    /// Writes, into ring entry `ring`'s pool, one set per distinct pair of depth-texture
    /// views among `draws` (each a draw's views; `None`: the blank texture), binding `table`
    /// first; returns each draw's set.
    ///
    /// The frame last recorded with `ring` has completed (the host waited for its fence), so
    /// its sets are free to reset.
    pub(crate) fn write(
        &mut self,
        gpu: &GpuContext,
        ring: usize,
        table: PerFrameBinding,
        draws: &[Option<[vk::ImageView; 2]>],
    ) -> Result<Vec<vk::DescriptorSet>> {
        let blank = [self.blank.view; 2];
        // Each draw's pair's index among the distinct pairs, in order of first use (a map: a
        // host may draw thousands of meshes a frame).
        let mut index_of: HashMap<[vk::ImageView; 2], usize> = HashMap::new();
        let mut distinct: Vec<[vk::ImageView; 2]> = Vec::new();
        let draw_pairs: Vec<usize> = draws
            .iter()
            .map(|d| {
                let pair = d.unwrap_or(blank);
                *index_of.entry(pair).or_insert_with(|| {
                    distinct.push(pair);
                    distinct.len() - 1
                })
            })
            .collect();
        let needed = distinct.len().max(1) as u32;
        let pool = self.pool_for(gpu, ring, needed)?;
        let layouts = vec![self.layout; distinct.len()];
        let sets = if distinct.is_empty() {
            Vec::new()
        } else {
            // SAFETY: the pool was reset (or made) for this frame with room for `needed` sets
            // of this layout.
            unsafe {
                gpu.device.allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(pool)
                        .set_layouts(&layouts),
                )
            }
            .vk("vkAllocateDescriptorSets")?
        };
        let table_info = [vk::DescriptorBufferInfo {
            buffer: table.buffer,
            offset: table.offset,
            range: table.range,
        }];
        let image_infos: Vec<[vk::DescriptorImageInfo; 2]> = distinct
            .iter()
            .map(|pair| {
                pair.map(|view| vk::DescriptorImageInfo {
                    sampler: self.sampler,
                    image_view: if view == vk::ImageView::null() {
                        self.blank.view
                    } else {
                        view
                    },
                    image_layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                })
            })
            .collect();
        let mut writes = Vec::new();
        for (set, infos) in sets.iter().zip(&image_infos) {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(*set)
                    .dst_binding(0)
                    .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC)
                    .buffer_info(&table_info),
            );
            for (k, info) in infos.iter().take(self.textures).enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(*set)
                        .dst_binding(1 + k as u32)
                        .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                        .image_info(std::slice::from_ref(info)),
                );
            }
        }
        // SAFETY: every set was allocated above and is in no pending command buffer; the
        // views are the host's (valid for the frame, its contract) or the blank texture's.
        unsafe { gpu.device.update_descriptor_sets(&writes, &[]) };
        Ok(draw_pairs.iter().map(|&at| sets[at]).collect())
    }

    /// Ring entry `ring`'s pool, reset, with room for `needed` sets: the old one reset, or
    /// replaced by one twice as large when it is too small.
    fn pool_for(
        &mut self,
        gpu: &GpuContext,
        ring: usize,
        needed: u32,
    ) -> Result<vk::DescriptorPool> {
        let (pool, capacity) = self.pools[ring];
        if pool != vk::DescriptorPool::null() && capacity >= needed {
            // SAFETY: the pool's sets are in no pending command buffer (the slot's previous
            // frame completed).
            unsafe {
                gpu.device
                    .reset_descriptor_pool(pool, vk::DescriptorPoolResetFlags::empty())
            }
            .vk("vkResetDescriptorPool")?;
            return Ok(pool);
        }
        let capacity = needed.max(capacity.saturating_mul(2)).max(4);
        let textures = self.textures as u32;
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC,
                descriptor_count: capacity,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                descriptor_count: capacity * textures,
            },
        ];
        // SAFETY: a valid create info on the host's device.
        let grown = unsafe {
            gpu.device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(capacity)
                    .pool_sizes(&sizes),
                None,
            )
        }
        .vk("vkCreateDescriptorPool")?;
        if pool != vk::DescriptorPool::null() {
            // SAFETY: as for the reset: none of its sets is in a pending command buffer.
            unsafe { gpu.device.destroy_descriptor_pool(pool, None) };
        }
        gpu.set_name(grown, "layered maps: depth textures");
        self.pools[ring] = (grown, capacity);
        Ok(grown)
    }

    /// The device memory of the blank texture (the sets themselves are pool memory the
    /// driver keeps, not an allocation of lucent's).
    pub(crate) fn image_bytes(&self) -> u64 {
        self.blank.memory_bytes()
    }

    /// Destroys the pools, the layout, the sampler and the blank texture. The GPU is done
    /// with the effect.
    pub(crate) fn destroy(self, gpu: &GpuContext) {
        // SAFETY: the effect is being destroyed once the host's frames completed; each object
        // is destroyed once.
        unsafe {
            for (pool, _) in &self.pools {
                if *pool != vk::DescriptorPool::null() {
                    gpu.device.destroy_descriptor_pool(*pool, None);
                }
            }
            gpu.device.destroy_sampler(self.sampler, None);
            gpu.device.destroy_descriptor_set_layout(self.layout, None);
        }
        gpu.destroy_image(self.blank);
    }
}
