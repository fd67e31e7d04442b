//! What the GPU test files share: a validated device with the shader compiler and a pipeline
//! cache, that fails the test on any validation error when it is finished.

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
        let shaders = ShaderCompiler::new(
            ShaderCompiler::default_glsl_root(),
            Some(ShaderCompiler::default_cache_dir()),
        )
        .unwrap();
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
