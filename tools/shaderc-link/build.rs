//! Makes shaderc link into lucent's build script on Debian.
//!
//! Debian's `libshaderc_combined.a` is not combined: it leaves the glslang and SPIRV-Tools
//! symbols undefined (DESIGN.md, "Facts measured"). lucent's own `build.rs` appends those
//! archives to the link line of lucent's targets with `cargo:rustc-link-arg`, but nothing a
//! build script prints reaches the link of the build script itself. A dependency's
//! `rustc-link-lib` does reach every binary that depends on it, build scripts included, so this
//! crate (a build-dependency of lucent) names the archives. They are linked whole
//! (`+whole-archive`): rustc puts a dependency's native libraries wherever the crate graph puts
//! the crate, possibly before `shaderc_combined`, and a plain static archive only resolves
//! symbols of objects that come before it.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    let lib_dir = std::env::var("SHADERC_LIB_DIR")
        .unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".to_string());
    let dir = std::path::Path::new(&lib_dir);
    // Only archives that exist: elsewhere (a real libshaderc_combined.a, a shaderc built from
    // source by shaderc-sys) nothing is missing.
    let libs: Vec<&str> = [
        "glslang",
        "MachineIndependent",
        "GenericCodeGen",
        "OSDependent",
        "OGLCompiler",
        "SPIRV",
        "SPIRV-Tools-opt",
        "SPIRV-Tools",
        "glslang-default-resource-limits",
    ]
    .into_iter()
    .filter(|lib| dir.join(format!("lib{lib}.a")).exists())
    .collect();
    if libs.is_empty() {
        return;
    }
    println!("cargo:rustc-link-search=native={lib_dir}");
    for lib in libs {
        println!("cargo:rustc-link-lib=static:+whole-archive,-bundle={lib}");
    }
    println!("cargo:rustc-link-lib=dylib=stdc++");
}
