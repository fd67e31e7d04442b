//! GPU timestamps: one begin/end pair per named scope (one per physical pass).
//!
//! Results are read with `vkGetQueryPoolResults` *without* the WAIT flag, only once the caller
//! knows the frame finished (its fence signalled): reading never stalls the frame loop, and on
//! lavapipe, where the call drains the device, it drains nothing. Keep one timer per frame in
//! flight.
//!
//! Each timestamp is written at `ALL_COMMANDS`: the begin waits for everything recorded before
//! it, the end for everything in the scope, so a scope measures its own work. Timestamps are
//! written outside render passes only (inside one, lavapipe's values are wrong: DESIGN.md).

use ash::vk;

use crate::error::VkResultExt;
use crate::{LucentError, Result};

use super::GpuContext;

/// A pool of timestamp pairs with names.
pub struct GpuTimer {
    pool: vk::QueryPool,
    capacity: u32,
    scopes: Vec<String>,
    period_ns: f64,
    valid_mask: u64,
}

/// One measured scope.
#[derive(Clone, Debug, PartialEq)]
pub struct ScopeTime {
    /// The scope's name (the physical pass's).
    pub name: String,
    /// Milliseconds between its begin and end timestamps.
    pub ms: f64,
}

impl GpuTimer {
    /// A timer with room for `max_scopes` scopes per frame.
    pub fn new(gpu: &GpuContext, max_scopes: u32) -> Result<Self> {
        let capacity = max_scopes.max(1) * 2;
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(capacity);
        // SAFETY: valid device and create info.
        let pool = unsafe { gpu.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        gpu.set_name(pool, "lucent timestamps");
        let bits = gpu.info.timestamp_valid_bits;
        if bits == 0 {
            return Err(LucentError::MissingFeature {
                device: gpu.info.name.clone(),
                feature: "timestamps on the graphics queue".into(),
            });
        }
        Ok(Self {
            pool,
            capacity,
            scopes: Vec::new(),
            period_ns: f64::from(gpu.info.timestamp_period_ns),
            valid_mask: if bits >= 64 {
                u64::MAX
            } else {
                (1u64 << bits) - 1
            },
        })
    }

    /// Resets the pool for a new frame; record before any scope, outside render passes.
    pub fn reset(&mut self, gpu: &GpuContext, cmd: vk::CommandBuffer) {
        self.scopes.clear();
        // SAFETY: the pool is valid and no query of it is active.
        unsafe {
            gpu.device
                .cmd_reset_query_pool(cmd, self.pool, 0, self.capacity)
        };
    }

    /// Opens a scope. Returns its index for [`GpuTimer::end`]; scopes past capacity are not timed
    /// (index `usize::MAX`) and are reported missing.
    pub fn begin(&mut self, gpu: &GpuContext, cmd: vk::CommandBuffer, name: &str) -> usize {
        let index = self.scopes.len();
        if (index as u32) * 2 + 1 >= self.capacity {
            log::warn!("GPU timer full: scope '{name}' not timed");
            return usize::MAX;
        }
        self.scopes.push(name.to_string());
        // SAFETY: query index < capacity, reset this frame.
        unsafe {
            gpu.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                index as u32 * 2,
            )
        };
        index
    }

    /// Closes a scope opened by [`GpuTimer::begin`].
    pub fn end(&mut self, gpu: &GpuContext, cmd: vk::CommandBuffer, scope: usize) {
        if scope == usize::MAX {
            return;
        }
        // SAFETY: as in `begin`.
        unsafe {
            gpu.device.cmd_write_timestamp2(
                cmd,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                scope as u32 * 2 + 1,
            )
        };
    }

    /// The scopes' times, or `None` if the GPU has not finished writing them. Never waits.
    pub fn results(&self, gpu: &GpuContext) -> Result<Option<Vec<ScopeTime>>> {
        if self.scopes.is_empty() {
            return Ok(Some(Vec::new()));
        }
        let mut data = vec![0u64; self.scopes.len() * 2];
        // SAFETY: the range was reset and written this frame; no WAIT flag, so NOT_READY is
        // reported rather than waited for.
        let result = unsafe {
            gpu.device.get_query_pool_results(
                self.pool,
                0,
                &mut data,
                vk::QueryResultFlags::TYPE_64,
            )
        };
        match result {
            Ok(()) => {}
            Err(vk::Result::NOT_READY) => return Ok(None),
            Err(e) => {
                return Err(LucentError::Vulkan {
                    call: "vkGetQueryPoolResults",
                    result: e,
                })
            }
        }
        Ok(Some(
            self.scopes
                .iter()
                .enumerate()
                .map(|(i, name)| {
                    let begin = data[i * 2] & self.valid_mask;
                    let end = data[i * 2 + 1] & self.valid_mask;
                    // Wrap-around of a narrower counter: the difference modulo its width.
                    let ticks = end.wrapping_sub(begin) & self.valid_mask;
                    ScopeTime {
                        name: name.clone(),
                        ms: ticks as f64 * self.period_ns * 1e-6,
                    }
                })
                .collect(),
        ))
    }

    /// Destroys the pool; the GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        // SAFETY: created on this device; caller guarantees no pending use.
        unsafe { gpu.device.destroy_query_pool(self.pool, None) };
    }
}
