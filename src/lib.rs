//! lucent: real-time translucency and subsurface scattering on Vulkan, measured honestly.
//!
//! Layers (dependencies point one way, down this list):
//! - [`passes`]: the techniques, each a struct that adds its passes to a graph.
//! - [`graph`]: the render graph: declare passes and resources, compile to a plan, execute
//!   into any command buffer. Knows nothing about techniques.
//! - [`backend`]: a thin layer over `ash`: context (own or wrapped), memory, images, the one
//!   access table, debug labels, GPU timer, shader compilation.
//!
//! Beside them: [`scene`] (what is drawn), [`reference`](mod@reference) (CPU f64 versions of every shading
//! equation, for tests and reports), [`output`] (PNG/EXR), [`compare`] (perceptual image
//! comparison), [`bench`](mod@bench) (the benchmark and its honest timing modes), [`speed_of_light`] (each pass's
//! copy floor), [`scaling`] (time against triangles, resolution, lights), [`suite`] (`lucent
//! report`: everything above written as one report with plots), and, with the `window`
//! feature, `demo` (the interactive window; it sits above the renderer and passes).

pub mod backend;
pub mod bake;
pub mod bench;
pub mod compare;
#[cfg(feature = "window")]
pub mod demo;
pub mod error;
pub mod graph;
pub mod output;
pub mod passes;
pub mod plot;
pub mod reference;
pub mod renderer;
pub mod report;
pub mod scaling;
pub mod scene;
pub mod seeds;
pub mod speed_of_light;
pub mod sss_report;
pub mod suite;
pub mod sweep;

pub use error::{LucentError, Result};
