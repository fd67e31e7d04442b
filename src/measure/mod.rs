//! Measurement: everything that times frames or checks their numbers, above the frame layer.
//!
//! - [`stats`]: medians, minima and maxima of samples, the one summary every table uses.
//! - [`round_robin`]: variants' frames timed in turn, one of each per round, so a noisy machine
//!   slows them alike (the truth and SSS reports, and [`scaling`]).
//! - [`bench`](mod@bench): the benchmark (`lucent bench`): per-pass GPU times proven to add up, and its
//!   timing modes, formats and alternating comparisons.
//! - [`speed_of_light`]: each pass's floor: the same draws with a trivial shader (a mesh pass),
//!   or a copy reading and writing the same formats (a fullscreen pass).
//! - [`gate`]: the speed-of-light gate (`lucent bench --gate`): each pass against its floor and
//!   a technique against `none`, held under limits.
//! - [`scaling`]: frame and pass time against triangles, resolution and light count.
//! - [`look`]: how much a technique changes a frame against plain lighting, and its halos.
//! - [`gallery`](mod@gallery): `lucent gallery`, the showcase scenes as PNGs and a Markdown page.
//! - [`layered_error`]: Li et al.'s layered terms against their f64 references.
//! - [`sweep`]: stability sweeps at extreme parameters (NaN, Inf, overflow counts).
//! - [`sweep_layered`]: the layered media's sweep, the GPU frames and the f64 references.
//! - [`sweep_burley`]: 2-D Burley SSS at extreme distances, albedos and views.
//! - [`truth`]: a frame against the path-traced truth (error, energy per channel, FLIP).

pub mod bench;
pub mod embed_cost;
pub mod gallery;
pub mod gate;
pub mod host_lighting;
pub mod layered_error;
pub mod look;
pub mod round_robin;
pub mod scaling;
pub mod speed_of_light;
pub mod stats;
pub mod sweep;
pub mod sweep_burley;
pub mod sweep_layered;
pub mod truth;
