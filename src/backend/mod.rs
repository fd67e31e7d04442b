//! The thin layer over `ash`: one abstraction level, no more.
//!
//! - [`context`]: the Vulkan context, created by lucent or wrapping a host engine's device.
//! - [`resources`]: images and buffers with named allocations, readback.
//! - [`access`]: the one access table every barrier is derived from.
//! - [`format`](mod@format): the one format table (sizes, channels, encodings, names).
//! - [`shader`]: GLSL compiled at run time with shaderc, SPIR-V cache, pipeline cache.
//! - [`timer`]: GPU timestamp scopes, read without stalling.

pub mod access;
pub mod context;
mod desc;
pub(crate) mod device;
pub mod format;
mod instance;
pub mod resources;
pub mod shader;
pub mod timer;

pub use context::*;
pub use resources::*;
