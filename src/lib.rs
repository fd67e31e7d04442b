//! lucent: real-time translucency and subsurface scattering on Vulkan, measured honestly.
//!
//! Layers (dependencies point one way, down this list):
//! - `frame`: the frame a scene's materials ask for (`frame::FrameDesc`), declared as one
//!   render graph, the `frame::Renderer` that records it (frames in flight, into its own
//!   image or one the caller gives), read-back and the frame runner.
//! - `features`: one module per technique or feature (G-buffer and lighting, GDC 2011
//!   translucency, screen-space SSS, tonemap, debug views), each adding its passes to a graph:
//!   handles in, handles out.
//! - `gpu_scene`: what a scene becomes on the GPU (meshes, textures, draws) and the
//!   per-frame parameter buffer the passes read (camera, lights, material and profile tables).
//! - `graph`: the render graph: declare passes and resources, compile to a plan, execute
//!   into any command buffer. Knows nothing about techniques.
//! - `backend`: a thin layer over `ash`: context (own or wrapped), memory, images, the one
//!   access table, the one format table, debug labels, GPU timer, shader compilation.
//!
//! Above the frame, for a host engine: [`embed`] (lucent on the host's device, allocator,
//! images and command buffers: a whole frame into a host image, or SSS as a post-process).
//!
//! Beside them: [`scene`] (the CPU model of what is drawn; no GPU), [`bake`] (the thickness
//! baker, called explicitly by whoever loads a scene), `reference` (CPU f64
//! versions of every shading equation, used by tests and reports, never by features),
//! [`images`] (PNG/EXR files; FLIP comparison with `measure`). At the bottom, used by every
//! layer: [`error`] (the one error type), `files` (every file read is a regular file read
//! with a cap, every file written is written atomically, a command's outputs are checked
//! against its inputs, the default cache directory) and `progress` (the bake's and the
//! benchmark's progress). Above the frame, with their features: `measure` (benchmark, speed
//! of light, scaling, sweeps), `report` (`lucent report`: the suite, its sections, the seeds'
//! tables, plots) and `demo` (the interactive window).
//!
//! **The surface a host relies on** is [`embed`], [`scene`], [`bake`], [`images`] and
//! [`error`]: what docs/embedding.md states as the contract, kept meaningful across versions
//! (`embed::API_VERSION`). The layers above (`frame`, `features`, `gpu_scene`, `graph`,
//! `backend`) and `reference`, `files`, `progress` and `shipped` are lucent's internals: public
//! only with the `internals` feature, which lucent's own command, demo, benchmark, report and
//! tests build with, and crate-private in a host's build, so that no internal change breaks a
//! host.
//!
//! Cargo features, all on by default: `runtime-shaders` (shaderc: GLSL compiled at run time;
//! without it pipelines use only the SPIR-V shipped with the crate), `window` (winit,
//! ash-window, egui, egui-winit, egui-ash-renderer: the `demo` module and `lucent demo`, which
//! needs `runtime-shaders` for hot reload), `internals` (the internal modules made public),
//! `measure` (nv-flip: the `measure` module and `images::compare`; needs `internals`), `cli`
//! (clap, env_logger: the `lucent` binary's command line; needs `measure`) and `report`
//! (plotters, indicatif: the `report` module and progress bars on stderr; needs `measure`).
//! The `lucent` binary needs `cli` and `report`. With `--no-default-features` (an embedding
//! host's build) the library keeps everything a host renders with (the embed API and the
//! scene, bake and image modules, over the internal context, graph, renderer and shipped
//! shaders) and depends on none of those crates, nor on shaderc at run time; the bake then
//! reports progress through `log` (info level, every tenth) instead of a bar;
//! `examples/host_engine.rs` builds that way.

/// Declares lucent's internal modules: `pub` with the `internals` feature (lucent's own
/// command, demo, benchmark, report and tests, which build on them), `pub(crate)` without it,
/// so that a host's build (`--no-default-features`) sees only the surface it can rely on
/// ([`embed`], [`scene`], [`bake`], [`images`], [`error`]) and no internal change breaks it.
macro_rules! internal_modules {
    ($($(#[$attr:meta])* $name:ident;)*) => {
        $(
            $(#[$attr])*
            #[cfg(feature = "internals")]
            pub mod $name;
            $(#[$attr])*
            #[cfg(not(feature = "internals"))]
            #[allow(dead_code, unused_imports)]
            pub(crate) mod $name;
        )*
    };
}

internal_modules! {
    backend;
    features;
    files;
    frame;
    gpu_scene;
    graph;
    progress;
    reference;
    shipped;
}

pub mod bake;
#[cfg(feature = "window")]
pub mod demo;
pub mod embed;
pub mod error;
pub mod images;
#[cfg(feature = "measure")]
pub mod measure;
#[cfg(feature = "report")]
pub mod report;
pub mod scene;

pub use error::{HostError, ImageFault, LucentError, Result};
