//! The tests that run the `lucent` binary (`CARGO_BIN_EXE_lucent`, validation on): bad inputs,
//! the benchmark, the interactive demo under Xvfb, host memory while loading a texture, outputs,
//! the reports. One binary, each former
//! test file a module; `cargo test --test cli bench::` runs one of them.

#[path = "../common/mod.rs"]
#[allow(dead_code)] // the harness serves three binaries; this one does not use all of it
mod common;
#[path = "../common/gltf.rs"]
#[allow(dead_code)] // shared with the GPU tests
mod gltf_file;

mod bad_gltf;
mod bad_inputs;
mod bench;
mod demo;
mod memory;
mod outputs;
mod report;
mod report_li;
mod report_truth;
