//! lucent: real-time translucency and subsurface scattering on Vulkan, measured honestly.
//!
//! Layers (dependencies point one way, down this list):
//! - [`frame`]: the frame a scene's materials ask for ([`frame::FrameDesc`]), declared as one
//!   render graph, the [`frame::Renderer`] that records it (frames in flight, into its own
//!   image or one the caller gives), read-back and the frame runner.
//! - [`features`]: one module per technique or feature (G-buffer and lighting, GDC 2011
//!   translucency, screen-space SSS, tonemap, debug views), each adding its passes to a graph:
//!   handles in, handles out.
//! - [`gpu_scene`]: what a scene becomes on the GPU (meshes, textures, draws) and the
//!   per-frame parameter buffer the passes read (camera, lights, material and profile tables).
//! - [`graph`]: the render graph: declare passes and resources, compile to a plan, execute
//!   into any command buffer. Knows nothing about techniques.
//! - [`backend`]: a thin layer over `ash`: context (own or wrapped), memory, images, the one
//!   access table, the one format table, debug labels, GPU timer, shader compilation.
//!
//! Above the frame, for a host engine: [`embed`] (lucent on the host's device, allocator,
//! images and command buffers: a whole frame into a host image, or SSS as a post-process).
//!
//! Beside them: [`scene`] (the CPU model of what is drawn; no GPU), [`bake`] (the thickness
//! baker, called explicitly by whoever loads a scene), [`reference`](mod@reference) (CPU f64
//! versions of every shading equation, used by tests and reports, never by features),
//! [`images`] (PNG/EXR files; FLIP comparison with `measure`). At the bottom, used by every
//! layer: [`error`] (the one error type), [`files`] (every file read is a regular file read
//! with a cap, every file written is written atomically, a command's outputs are checked
//! against its inputs, the default cache directory) and [`progress`] (the bake's and the
//! benchmark's progress). Above the frame, with their features: `measure` (benchmark, speed
//! of light, scaling, sweeps), `report` (`lucent report`: the suite, its sections, the seeds'
//! tables, plots) and `demo` (the interactive window).
//!
//! Cargo features, all on by default: `runtime-shaders` (shaderc: GLSL compiled at run time,
//! `backend::shader::ShaderCompiler::new`; without it pipelines use only the SPIR-V shipped
//! with the crate, [`backend::shader::ShaderCompiler::shipped`]), `window` (winit, ash-window,
//! egui, egui-winit, egui-ash-renderer: the `demo` module and `lucent demo`, which needs
//! `runtime-shaders` for hot reload), `measure` (nv-flip: the `measure` module and
//! `images::compare`), `cli` (clap, env_logger: the `lucent` binary's command line; needs
//! `measure`) and `report` (plotters, indicatif: the `report` module and progress bars on
//! stderr; needs `measure`). The `lucent` binary needs `cli` and `report`. With
//! `--no-default-features` the library keeps everything a host renders with (context, graph,
//! scene, bake, renderer, embed, reference, images, shipped shaders) and depends on none of
//! those crates, nor on shaderc at run time; the bake and the benchmark then report progress
//! through `log` (info level, every tenth) instead of a bar.

pub mod backend;
pub mod bake;
#[cfg(feature = "window")]
pub mod demo;
pub mod embed;
pub mod error;
pub mod features;
pub mod files;
pub mod frame;
pub mod gpu_scene;
pub mod graph;
pub mod images;
#[cfg(feature = "measure")]
pub mod measure;
pub mod progress;
pub mod reference;
#[cfg(feature = "report")]
pub mod report;
pub mod scene;
pub mod shipped;

pub use error::{HostError, ImageFault, LucentError, Result};
