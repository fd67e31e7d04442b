//! The graph executor on a real device (lavapipe, validation and synchronization validation on):
//! a chain long enough that transient images really share memory, executed twice per frame
//! source, with the result read back.

use ash::vk;
use lucent::backend::access::Access;
use lucent::backend::shader::{PipelineCache, ShaderCompiler};
use lucent::backend::{ContextDesc, GpuContext};
use lucent::frame::FrameRunner;
use lucent::graph::{
    CompileOptions, Executable, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext,
    RecordContext, RenderGraph,
};

/// Fills its colour attachment with one value (`vkCmdClearAttachments`: no pipeline needed).
struct Fill([f32; 4]);

impl PassExec for Fill {
    fn prepare(&mut self, _ctx: &PrepareContext<'_>) -> lucent::Result<()> {
        Ok(())
    }
    fn record(&self, ctx: &RecordContext<'_>) {
        let clear = vk::ClearAttachment {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            color_attachment: 0,
            clear_value: vk::ClearValue {
                color: vk::ClearColorValue { float32: self.0 },
            },
        };
        let rect = vk::ClearRect {
            rect: vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: ctx.extent,
            },
            base_array_layer: 0,
            layer_count: 1,
        };
        // SAFETY: inside the pass's subpass, attachment 0 is a colour attachment.
        unsafe {
            ctx.gpu
                .device
                .cmd_clear_attachments(ctx.cmd, &[clear], &[rect])
        };
    }
    fn destroy(&mut self, _gpu: &GpuContext) {}
}

fn run_chain(options: CompileOptions) -> (Vec<u8>, usize) {
    let gpu = GpuContext::new(&ContextDesc {
        validation: true,
        ..ContextDesc::default()
    })
    .unwrap();
    let info = ImageInfo {
        width: 32,
        height: 16,
        format: vk::Format::R8G8B8A8_UNORM,
    };
    let mut graph = RenderGraph::new();
    let mut prev = graph.create_image("a0", info);
    let mut pass = graph.add_pass("p0", PassKind::Raster);
    pass.color(&mut prev, LoadOp::Clear([0.0; 4]));
    pass.execute(Fill([0.1, 0.0, 0.0, 1.0]));
    for i in 1..8 {
        let mut next = graph.create_image(&format!("a{i}"), info);
        let mut pass = graph.add_pass(&format!("p{i}"), PassKind::Raster);
        pass.sample(&prev).color(&mut next, LoadOp::DontCare);
        pass.execute(Fill([i as f32 / 8.0, 0.5, 1.0, 1.0]));
        prev = next;
    }
    graph.export_image(&prev, Access::TransferRead);
    let last = prev.id();
    let (plan, execs) = graph.compile(options).unwrap();
    let shared_slots = plan.slots.iter().filter(|s| s.resources.len() > 1).count();
    let shaders = ShaderCompiler::shipped().unwrap();
    let cache = PipelineCache::load(&gpu.device, None).unwrap();
    let exe = Executable::new(&gpu, plan, execs, &shaders, cache.handle, 1).unwrap();
    let mut runner = FrameRunner::new(&gpu, exe.plan.physical.len()).unwrap();
    for _ in 0..2 {
        let timing = runner.run_frame(&gpu, &exe).unwrap();
        assert_eq!(timing.passes.len(), 8);
        assert!(timing
            .passes
            .iter()
            .all(|p| p.ms.is_finite() && p.ms >= 0.0));
    }
    runner.run_isolated(&gpu, &exe).unwrap();
    let pixels = gpu
        .read_image(
            exe.owned_image(last).unwrap(),
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
        )
        .unwrap();
    gpu.wait_idle().unwrap();
    runner.destroy(&gpu);
    exe.destroy(&gpu);
    cache.destroy(&gpu.device);
    assert_eq!(
        gpu.validation_error_count(),
        0,
        "{}",
        gpu.take_validation_messages().join("\n")
    );
    (pixels, shared_slots)
}

#[test]
fn aliased_chain_executes_validation_clean_and_ends_in_the_last_value() {
    let (pixels, shared) = run_chain(CompileOptions::default());
    assert!(shared > 0, "the chain must really share memory");
    // The last pass filled (7/8, 0.5, 1, 1).
    assert_eq!(&pixels[..4], &[223, 128, 255, 255]);
    assert!(pixels.chunks(4).all(|p| p == &pixels[..4]));
    let (unaliased, shared) = run_chain(CompileOptions {
        merge: true,
        alias: false,
        ..CompileOptions::default()
    });
    assert_eq!(shared, 0);
    assert_eq!(unaliased, pixels);
}
