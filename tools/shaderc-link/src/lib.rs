//! No code: this crate exists for its build script, which adds the system's glslang and
//! SPIRV-Tools static libraries to the link of every binary depending on it (lucent's build
//! script, which compiles the shipped SPIR-V with shaderc). See `build.rs`.
