//! The tests that need neither a device nor the `lucent` binary: the render graph, the mesh
//! generators, the OBJ fuzzer, the thickness baker and the shipped SPIR-V bundle. One binary,
//! each former test file a module; `cargo test --test cpu graph::` runs one of them.

#[path = "../common/mod.rs"]
#[allow(dead_code)] // the harness serves three binaries; this one uses little of it
mod common;

mod bake;
mod fuzz_mesh;
mod generators;
mod graph;
mod shipped_shaders;
