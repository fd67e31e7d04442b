//! What the GPU test files share: a validated device with the shader compiler and a pipeline
//! cache, that fails the test on any validation error when it is finished.

use ash::vk;
use lucent::backend::shader::{PipelineCache, ShaderCompiler};
use lucent::backend::{ContextDesc, GpuContext};

/// A device with the Khronos validation layer (synchronization validation included) on.
pub struct TestGpu {
    /// The context.
    pub gpu: GpuContext,
    /// Shader compiler with the on-disk SPIR-V cache.
    pub shaders: ShaderCompiler,
    /// An in-memory pipeline cache.
    pub cache: PipelineCache,
}

impl TestGpu {
    /// Creates the device; panics with the setup hint when there is none.
    pub fn new() -> Self {
        let gpu = GpuContext::new(&ContextDesc {
            validation: true,
            ..ContextDesc::default()
        })
        .expect("a Vulkan device (run tools/setup.sh for lavapipe)");
        // The shipped SPIR-V, as the `lucent` command and a host use it: a permutation missing
        // from glsl/permutations.txt fails the test that renders it.
        let shaders = ShaderCompiler::shipped().unwrap();
        let cache = PipelineCache::load(&gpu.device, None).unwrap();
        Self {
            gpu,
            shaders,
            cache,
        }
    }

    /// Tears down and fails if validation reported any error.
    pub fn finish(self) {
        self.cache.destroy(&self.gpu.device);
        let errors = self.gpu.validation_error_count();
        assert_eq!(
            errors,
            0,
            "validation errors:\n{}",
            self.gpu.take_validation_messages().join("\n")
        );
    }
}

/// Runs `lucent ARGS` (a benchmark) and returns its stdout. Tiny frames on a shared machine
/// may fail the timing checks: that one clean, explained failure is allowed, nothing else.
#[allow(dead_code)] // not every test file benches
pub fn run_bench(args: &[&str]) -> String {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        assert!(stderr.contains("lucent: error: timing:"), "{stderr}");
    }
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Records `count` primary command buffers, `record(k, cmd)` into the k-th (begun and ended
/// here), submits them back to back on the queue and waits once, after the last: frames in
/// flight as a host submits them.
#[allow(dead_code)] // not every test file records frames itself
pub fn submit_back_to_back(
    gpu: &GpuContext,
    count: usize,
    mut record: impl FnMut(usize, vk::CommandBuffer),
) {
    let device = &gpu.device;
    // SAFETY: valid device; the pool, buffers and fence are used only here and freed after
    // the wait.
    unsafe {
        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(gpu.queue_family),
                None,
            )
            .unwrap();
        let cmds = device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(count as u32),
            )
            .unwrap();
        for (k, &cmd) in cmds.iter().enumerate() {
            device
                .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            record(k, cmd);
            device.end_command_buffer(cmd).unwrap();
        }
        let fence = device
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .unwrap();
        for (k, &cmd) in cmds.iter().enumerate() {
            let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
            let signal = if k + 1 == count {
                fence
            } else {
                vk::Fence::null()
            };
            device.queue_submit2(gpu.queue, &[submit], signal).unwrap();
        }
        device.wait_for_fences(&[fence], true, u64::MAX).unwrap();
        device.destroy_fence(fence, None);
        device.destroy_command_pool(pool, None);
    }
}

/// Whether pixel (`x`, `y`) of a ray-traced reference `w` pixels wide is interior: the same
/// surface (hit distances within 5%), or the sky, covers it and its 8 neighbours. At
/// silhouettes the tessellated mesh and the exact shape cover different pixels, so GPU-against-
/// reference comparisons skip them. `x` and `y` must be at least 1 pixel from the border.
#[allow(dead_code)] // not every test file compares with the ray tracer
pub fn interior(
    reference: &lucent::reference::raytrace::ReferenceImage,
    w: u32,
    x: u32,
    y: u32,
) -> bool {
    let i = (y * w + x) as usize;
    (-1i32..=1).all(|dy| {
        (-1i32..=1).all(|dx| {
            let j = ((y as i32 + dy) as u32 * w + (x as i32 + dx) as u32) as usize;
            match (reference.hit[i], reference.hit[j]) {
                (Some(a), Some(b)) => (a - b).abs() < 0.05 * a,
                (None, None) => true,
                _ => false,
            }
        })
    })
}
