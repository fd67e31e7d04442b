//! `lucent plan`: the compiled render graph of a frame (passes, merged groups, barriers,
//! lifetimes, memory), without a GPU.

use lucent::bake::scene as bake;
use lucent::frame::{plan_frame, FrameDesc};
use lucent::Result;

use crate::cli::PlanArgs;

/// Prints the plan of `--scene` under the frame flags, after the inapplicable-knob warnings.
pub fn run(args: PlanArgs) -> Result<()> {
    let frame = args.frame;
    let settings = frame.settings(false)?;
    let scene = bake::load_scene_baked(&frame.scene)?;
    let desc = FrameDesc::new(&scene, &settings)?;
    frame.warn_inapplicable(&scene, &settings, &desc);
    let plan = plan_frame(&settings, &desc)?;
    print!("{}", plan.dump());
    Ok(())
}
