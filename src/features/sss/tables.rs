//! The SSS part of a frame's per-frame tables, written by the one function both the renderer
//! ([`crate::frame::Renderer`]) and the embedding post-process ([`crate::embed`]) call: the
//! profile table and, when some chain is two passes, the kernel table.

use super::{kernel, SssKnobs, SssProfiles};
use crate::gpu_scene::{PerFrame, Region};
use crate::Result;

/// Writes `profiles`' tables under `knobs` into slot `slot` of `per_frame`.
pub fn write(
    per_frame: &PerFrame,
    slot: usize,
    profiles: &SssProfiles,
    knobs: &SssKnobs,
) -> Result<()> {
    let table = profiles.table(knobs);
    per_frame.write(slot, Region::Profiles, bytemuck::bytes_of(&table))?;
    if profiles.two_pass() {
        let kernels = kernel::kernel_table(profiles, knobs.samples, knobs.shape);
        per_frame.write(slot, Region::Kernels, bytemuck::bytes_of(&kernels))?;
    }
    Ok(())
}
