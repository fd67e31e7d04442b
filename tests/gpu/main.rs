//! The tests that render in-process on a Vulkan device (lavapipe on CI) with the validation
//! layer and synchronization validation on: the context, shaders, the graph executor, every
//! technique against its goldens and f64 references, embedding. One binary, each former test
//! file a module; `cargo test --test gpu sss::` runs one of them.

#[path = "../common/mod.rs"]
#[allow(dead_code)] // the harness serves three binaries; this one does not use all of it
mod common;
#[path = "../common/gltf.rs"]
#[allow(dead_code)] // shared with the CLI tests
mod gltf_file;

mod antialias;
mod burley;
mod context;
mod debug_view;
mod deformation;
mod embed;
mod embed_environment;
mod embed_layered;
mod embed_lean;
mod embed_memory;
mod embed_translucency;
mod embed_transmission;
mod environment;
mod gltf;
mod graph_gpu;
mod layered;
mod materials;
mod render;
mod shaders;
mod shadows;
mod showcase;
mod sss;
mod sss_artifacts;
mod sweep_layered;
mod translucency;
mod transmission;
mod truth;
