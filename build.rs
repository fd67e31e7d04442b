//! Build script: make shaderc link on Debian.
//!
//! Debian's `libshaderc.so` leaves glslang symbols unresolved and rust-lld refuses it (DESIGN.md,
//! "Facts measured"). With shaderc's `prefer-static-linking` feature the crate links
//! `libshaderc_combined.a` when it finds it; the glslang / SPIRV-Tools static libraries it needs
//! are linked here explicitly, in dependency order, from the system library directory.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    let lib_dir = std::env::var("SHADERC_LIB_DIR")
        .unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".to_string());
    for lib in [
        "glslang",
        "MachineIndependent",
        "GenericCodeGen",
        "OSDependent",
        "OGLCompiler",
        "SPIRV",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
        "glslang-default-resource-limits",
    ] {
        // Passed as plain linker arguments so they land after shaderc-sys's archive on the link
        // line: static archives only resolve symbols of objects that come before them.
        let path = std::path::Path::new(&lib_dir).join(format!("lib{lib}.a"));
        if path.exists() {
            println!("cargo:rustc-link-arg={}", path.display());
        }
    }
    println!("cargo:rustc-link-arg=-lstdc++");
}
