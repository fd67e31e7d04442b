//! `lucent render`: one frame rendered headless, written as PNG (and optionally EXR).

use std::path::PathBuf;

use lucent::frame::FrameRunner;
use lucent::images::output;
use lucent::Result;

use crate::cli::RenderArgs;
use crate::session::{check_scene_outputs, with_renderer};

/// Renders `--scene` once and writes `--out` (default `<scene>.png`) and `--exr`.
pub fn run(args: RenderArgs) -> Result<()> {
    let RenderArgs {
        frame,
        gpu,
        out,
        exr,
    } = args;
    let out = out.unwrap_or_else(|| PathBuf::from(format!("{}.png", frame.scene)));
    let mut outputs = vec![("--out", out.as_path())];
    outputs.extend(exr.as_deref().map(|e| ("--exr", e)));
    check_scene_outputs(&frame.scene, &outputs)?;
    with_renderer(&frame, &gpu, exr.is_some(), |session, renderer, scene| {
        let gpu = &session.gpu;
        let (width, height) = (renderer.settings.width, renderer.settings.height);
        let mut runner = FrameRunner::new(gpu, renderer.executable.plan.physical.len())?;
        let timing = runner.run_frame(gpu, &renderer.executable);
        runner.destroy(gpu);
        let timing = timing?;
        output::write_png_rgba8(&out, width, height, &renderer.read_display(gpu)?)?;
        println!(
            "wrote {} ({width}x{height}, frame {:.2} ms on {})",
            out.display(),
            timing.wall_ms,
            gpu.info.describe()
        );
        // The assets' licences (CC BY) ask for credit wherever they are shown.
        for credit in &scene.credits {
            println!("credit: {credit}");
        }
        if let Some(exr) = &exr {
            output::write_exr_rgba32f(exr, width, height, &renderer.read_hdr(gpu)?)?;
            println!("wrote {}", exr.display());
        }
        Ok(())
    })
}
