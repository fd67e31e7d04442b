//! The SSS part of a frame's per-frame tables, written by the one function both the renderer
//! ([`crate::frame::Renderer`]) and the embedding post-process ([`crate::embed`]) call: the
//! profile table and each chain technique's own table
//! ([`super::SssBlurTechnique::table`]: the two-pass blurs' kernels); and the per-frame regions
//! they live in ([`regions`]).

use super::{SssBlur, SssKnobs, SssProfiles};
use crate::gpu_scene::{PerFrame, Region, TableRegion};
use crate::Result;

/// The SSS profile table ([`super::ProfileTableGpu`]): every frame with SSS.
pub static PROFILES: Region = Region::new("SSS profile table", "SssProfiles");

/// The two-pass blurs' kernel table ([`super::kernel::kernel_table`]): frames with a two-pass
/// chain.
pub static KERNELS: Region = Region::new("SSS kernel table", "SssKernels");

/// The regions `profiles`' frame needs: the profile table and each chain's own table (once
/// per region: chains that share a table share its region).
pub fn regions(profiles: &SssProfiles) -> Vec<TableRegion> {
    let mut regions = vec![TableRegion {
        region: &PROFILES,
        bytes: super::PROFILE_TABLE_BYTES,
    }];
    for (region, _) in chain_tables(profiles) {
        regions.push(region);
    }
    regions
}

/// Each distinct table the frame's chains read besides the profile table, with the chain that
/// writes it.
fn chain_tables(profiles: &SssProfiles) -> Vec<(TableRegion, SssBlur)> {
    let mut tables: Vec<(TableRegion, SssBlur)> = Vec::new();
    for chain in profiles.chains() {
        if let Some(table) = chain.technique().table() {
            if !tables.iter().any(|(t, _)| t.region == table.region) {
                tables.push((table, chain));
            }
        }
    }
    tables
}

/// Writes `profiles`' tables under `knobs` into slot `slot` of `per_frame`.
pub fn write(
    per_frame: &PerFrame,
    slot: usize,
    profiles: &SssProfiles,
    knobs: &SssKnobs,
) -> Result<()> {
    let table = profiles.table(knobs);
    per_frame.write(slot, &PROFILES, bytemuck::bytes_of(&table))?;
    for (table, chain) in chain_tables(profiles) {
        let bytes = chain.technique().table_bytes(profiles, knobs);
        per_frame.write(slot, table.region, &bytes)?;
    }
    Ok(())
}
