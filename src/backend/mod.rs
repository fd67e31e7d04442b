//! The thin layer over `ash`: one abstraction level, no more.
//!
//! - [`context`]: the Vulkan context, created by lucent or wrapping a host engine's device.
//! - [`resources`]: images and buffers with named allocations, readback (a buffer itself,
//!   [`GpuBuffer`], is its own small module, which the context's staging uses too).
//! - [`memory`]: where their memory comes from: `gpu-allocator` or a host's own allocator.
//! - [`access`]: the one access table every barrier is derived from.
//! - [`pipeline`]: graphics pipelines, made for the render pass and subpass a caller names.
//! - [`descriptor`]: descriptor sets (one per pass, with its own pool) and samplers.
//! - [`bindings`]: a pass's binding numbers written into its shaders by name, and checked.
//! - [`format`](mod@format): the one format table (sizes, channels, encodings, names).
//! - [`shader`]: SPIR-V shipped with the crate or compiled at run time (feature
//!   `runtime-shaders`), shader modules, pipeline cache.
//! - [`spirv`]: what a shader compiles to: its stage and SPIR-V words.
//! - [`timer`]: GPU timestamp scopes, read without stalling.

pub mod access;
pub mod bindings;
mod buffer;
pub mod context;
mod desc;
pub mod descriptor;
pub(crate) mod device;
pub mod format;
pub mod memory;
#[cfg(feature = "runtime-shaders")]
mod glsl_compile;
mod instance;
pub mod pipeline;
pub mod resources;
pub mod shader;
mod shader_files;
#[cfg(feature = "runtime-shaders")]
mod shader_runtime;
pub mod spirv;
pub mod timer;

pub use context::*;
pub use resources::*;
