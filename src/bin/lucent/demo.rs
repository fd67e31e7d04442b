//! `lucent demo`: the interactive window (the library's `demo` module) started from the
//! command line.

use lucent::frame::{FrameSettings, Technique};
use lucent::Result;

use crate::cli::DemoArgs;

/// Opens the demo with the command line's scene, technique, size and script.
pub fn run(args: DemoArgs) -> Result<()> {
    let DemoArgs {
        scene,
        technique,
        size,
        vsync,
        frames,
        script,
        screenshot,
        gpu,
    } = args;
    lucent::demo::run(lucent::demo::DemoOptions {
        scene,
        technique: technique.as_deref().map(Technique::parse).transpose()?,
        size,
        vsync,
        frames,
        script,
        screenshot,
        validation: gpu.validation,
        device: gpu.device,
        glsl_root: gpu.shaders,
        base: FrameSettings::new(size.0, size.1),
    })
}
