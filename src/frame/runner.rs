//! [`FrameRunner`]: submits frames and measures them, either as one command buffer (in-frame
//! timestamps) or one submission per physical pass (isolated timing); and the teardown the
//! round-robin measurements share.

use std::time::Instant;

use ash::vk;

use super::Renderer;
use crate::backend::timer::{GpuTimer, ScopeTime};
use crate::backend::GpuContext;
use crate::error::VkResultExt;
use crate::graph::Executable;
use crate::{LucentError, Result};

/// Waits for the device, then destroys `renderers` and `runners` (the round-robin measurements'
/// teardown): everything is destroyed even when the wait fails, whose error is returned.
pub fn destroy_after_idle(
    gpu: &GpuContext,
    renderers: Vec<Renderer>,
    runners: Vec<FrameRunner>,
) -> Result<()> {
    let idle = gpu.wait_idle();
    for runner in runners {
        runner.destroy(gpu);
    }
    for renderer in renderers {
        renderer.destroy(gpu);
    }
    idle
}

/// Times of one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameTiming {
    /// Wall time from submit to fence signalled, milliseconds.
    pub wall_ms: f64,
    /// GPU timestamps per physical pass.
    pub passes: Vec<ScopeTime>,
}

/// Submits frames and measures them: owns a command pool, command buffer, fence and timer.
pub struct FrameRunner {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timer: GpuTimer,
}

impl FrameRunner {
    /// A runner for frames of up to `max_passes` physical passes.
    pub fn new(gpu: &GpuContext, max_passes: usize) -> Result<Self> {
        let device = &gpu.device;
        // SAFETY: valid device and create infos.
        let pool = unsafe {
            device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(gpu.queue_family)
                    .flags(vk::CommandPoolCreateFlags::TRANSIENT),
                None,
            )
        }
        .vk("vkCreateCommandPool")?;
        // SAFETY: the pool was just created.
        let cmd = unsafe {
            device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
        }
        .vk("vkAllocateCommandBuffers")?[0];
        // SAFETY: valid device.
        let fence = unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) }
            .vk("vkCreateFence")?;
        let timer = GpuTimer::new(gpu, max_passes as u32 + 1)?;
        gpu.set_name(cmd, "lucent frame");
        Ok(Self {
            pool,
            cmd,
            fence,
            timer,
        })
    }

    /// Records with `record`, submits, waits, and reads the timer. Never overlaps frames, so
    /// the timer's results are always ready (no stall, no drain).
    fn submit(
        &mut self,
        gpu: &GpuContext,
        record: impl FnOnce(&GpuContext, vk::CommandBuffer, &mut GpuTimer),
    ) -> Result<FrameTiming> {
        let device = &gpu.device;
        // SAFETY: the previous submission of `cmd` finished (we waited on the fence).
        unsafe {
            device
                .reset_command_pool(self.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            device
                .begin_command_buffer(
                    self.cmd,
                    &vk::CommandBufferBeginInfo::default()
                        .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
                )
                .vk("vkBeginCommandBuffer")?;
        }
        self.timer.reset(gpu, self.cmd);
        record(gpu, self.cmd, &mut self.timer);
        let cmd_infos = [vk::CommandBufferSubmitInfo::default().command_buffer(self.cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmd_infos);
        // SAFETY: recording is complete; the fence is unsignalled.
        let start = unsafe {
            device
                .end_command_buffer(self.cmd)
                .vk("vkEndCommandBuffer")?;
            let start = Instant::now();
            device
                .queue_submit2(gpu.queue, &[submit], self.fence)
                .vk("vkQueueSubmit2")?;
            device
                .wait_for_fences(&[self.fence], true, u64::MAX)
                .vk("vkWaitForFences")?;
            start
        };
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        // SAFETY: the fence is signalled and not in use.
        unsafe { device.reset_fences(&[self.fence]) }.vk("vkResetFences")?;
        let passes = self.timer.results(gpu)?.ok_or_else(|| {
            LucentError::Timing("timestamps not available after the frame's fence signalled".into())
        })?;
        Ok(FrameTiming { wall_ms, passes })
    }

    /// One whole frame in one command buffer, timestamps around each physical pass.
    pub fn run_frame(&mut self, gpu: &GpuContext, executable: &Executable) -> Result<FrameTiming> {
        self.submit(gpu, |gpu, cmd, timer| {
            executable.record_frame(gpu, cmd, 0, Some(timer))
        })
    }

    /// One frame submitted pass by pass: each physical pass alone in its own submission, the
    /// device idle before it. Returns each pass's timestamp time (and the sum of walls).
    pub fn run_isolated(
        &mut self,
        gpu: &GpuContext,
        executable: &Executable,
    ) -> Result<FrameTiming> {
        let count = executable.plan.physical.len();
        let mut passes = Vec::with_capacity(count);
        let mut wall_ms = 0.0;
        for index in 0..count {
            let timing = self.submit(gpu, |gpu, cmd, timer| {
                executable.record_physical(gpu, cmd, index, 0, Some(timer));
                if index + 1 == count {
                    executable.record_exports(gpu, cmd);
                }
            })?;
            wall_ms += timing.wall_ms;
            passes.extend(timing.passes);
        }
        Ok(FrameTiming { wall_ms, passes })
    }

    /// Destroys the runner. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        self.timer.destroy(gpu);
        // SAFETY: created by `new`; nothing pending (every submit waited).
        unsafe {
            gpu.device.destroy_fence(self.fence, None);
            gpu.device.destroy_command_pool(self.pool, None);
        }
    }
}
