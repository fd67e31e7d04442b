//! Build script: the shipped SPIR-V bundle, and shaderc's link on Debian.
//!
//! 1. Compiles every permutation of `glsl/permutations.txt` (one `path NAME=VALUE ...` line
//!    each, generated from `lucent::shipped::permutations`; see that module) with
//!    shaderc, in parallel, into `$OUT_DIR/shaders.bundle`, which the library embeds
//!    (`include_bytes!`) and `ShaderCompiler::shipped` serves. The options and the `#include`
//!    lookup are the run-time compiler's own (`src/backend/glsl_compile.rs`, included below).
//!    A compile error stops the build with shaderc's `file:line: error:` messages. Only distinct
//!    compiles run: a define that no file of the shader's include tree mentions cannot change
//!    its SPIR-V, so it is left out of the compile's key (the fullscreen vertex shader, compiled
//!    with every fullscreen pass's defines, compiles once), and identical SPIR-V is stored once.
//! 2. With the `runtime-shaders` feature the library links shaderc too. Debian's
//!    `libshaderc.so` leaves glslang symbols unresolved and rust-lld refuses it (DESIGN.md,
//!    "Facts measured"). With shaderc's `prefer-static-linking` feature the crate links
//!    `libshaderc_combined.a` when it finds it; the glslang / SPIRV-Tools static libraries it
//!    needs are linked here explicitly, in dependency order, from the system library directory.
//!    (This script's own link gets them from the `lucent-shaderc-link` build-dependency.)

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

// Links the glslang / SPIRV-Tools archives into this script (the crate has no code).
use lucent_shaderc_link as _;

#[allow(dead_code)]
#[path = "src/backend/shader_files.rs"]
mod shader_files;

#[allow(dead_code)]
#[path = "src/backend/glsl_compile.rs"]
mod glsl_compile;

/// The manifest, relative to the package root.
const MANIFEST: &str = "glsl/permutations.txt";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=glsl");
    println!("cargo:rerun-if-changed=src/backend/shader_files.rs");
    println!("cargo:rerun-if-changed=src/backend/glsl_compile.rs");
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    if std::env::var_os("CARGO_FEATURE_RUNTIME_SHADERS").is_some() {
        link_shaderc();
    }
    // Regenerating the manifest (tests/cpu/shipped_shaders.rs) must work while the committed one is
    // stale, even when some of its lines no longer compile: that run ships nothing.
    println!("cargo:rerun-if-env-changed=LUCENT_WRITE_MANIFEST");
    let result = if std::env::var_os("LUCENT_WRITE_MANIFEST").is_some() {
        write_empty_bundle()
    } else {
        write_bundle()
    };
    if let Err(message) = result {
        eprintln!("{message}");
        std::process::exit(1);
    }
}

/// The library's link line for shaderc (feature `runtime-shaders`).
fn link_shaderc() {
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
        let path = Path::new(&lib_dir).join(format!("lib{lib}.a"));
        if path.exists() {
            println!("cargo:rustc-link-arg={}", path.display());
        }
    }
    println!("cargo:rustc-link-arg=-lstdc++");
}

/// One manifest line to compile.
struct Job {
    line: String,
    name: String,
    kind: shaderc::ShaderKind,
    defines: BTreeMap<String, String>,
}

/// A job's SPIR-V, or shaderc's messages.
type JobResult = Result<Vec<u32>, String>;

/// A bundle without permutations (while the manifest is regenerated).
fn write_empty_bundle() -> Result<(), String> {
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").map_err(|e| e.to_string())?);
    let path = out_dir.join("shaders.bundle");
    std::fs::write(&path, shader_files::encode_bundle(&[], &[]))
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// Compiles the manifest into `$OUT_DIR/shaders.bundle`.
fn write_bundle() -> Result<(), String> {
    let package = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").map_err(|e| e.to_string())?);
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").map_err(|e| e.to_string())?);
    let root = package
        .join("glsl")
        .canonicalize()
        .map_err(|e| format!("{}: {e}", package.join("glsl").display()))?;
    let manifest_path = package.join(MANIFEST);
    let manifest = std::fs::read_to_string(&manifest_path)
        .map_err(|e| format!("{}: {e}", manifest_path.display()))?;
    let mut jobs = Vec::new();
    for (number, line) in manifest.lines().enumerate() {
        let line = line.trim_end();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = || format!("{MANIFEST}:{}", number + 1);
        let (name, defines) =
            shader_files::parse_permutation_line(line).map_err(|e| format!("{}: {e}", at()))?;
        let kind = match Path::new(&name).extension().and_then(|e| e.to_str()) {
            Some("vert") => shaderc::ShaderKind::Vertex,
            Some("frag") => shaderc::ShaderKind::Fragment,
            Some("comp") => shaderc::ShaderKind::Compute,
            _ => {
                return Err(format!(
                    "{}: {name}: unknown stage; the file name must end in .vert, .frag or .comp",
                    at()
                ))
            }
        };
        jobs.push(Job {
            line: line.to_string(),
            name,
            kind,
            defines,
        });
    }

    // Compile each distinct (shader, defines it can see) once: a define whose name appears
    // nowhere in the shader's sources cannot change its SPIR-V (fullscreen.vert reads none of
    // the fragment shaders' defines it is compiled with).
    let mut visible: HashMap<String, Option<HashSet<String>>> = HashMap::new();
    let mut compile_of: HashMap<(String, BTreeMap<String, String>), usize> = HashMap::new();
    let mut compiles: Vec<usize> = Vec::new();
    let mut job_compile = Vec::with_capacity(jobs.len());
    for (index, job) in jobs.iter().enumerate() {
        let names = visible
            .entry(job.name.clone())
            .or_insert_with(|| identifiers(&root, &job.name));
        let seen: BTreeMap<String, String> = job
            .defines
            .iter()
            .filter(|(define, _)| names.as_ref().is_none_or(|n| n.contains(*define)))
            .map(|(d, v)| (d.clone(), v.clone()))
            .collect();
        let compile = *compile_of
            .entry((job.name.clone(), seen))
            .or_insert_with(|| {
                compiles.push(index);
                compiles.len() - 1
            });
        job_compile.push(compile);
    }

    let compiler = shaderc::Compiler::new()
        .map_err(|e| format!("the shaderc compiler could not be created: {e}"))?;
    // Cargo's -j (NUM_JOBS); one thread per job slot.
    let threads = std::env::var("NUM_JOBS")
        .ok()
        .and_then(|n| n.parse::<usize>().ok())
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get()))
        .clamp(1, 64);
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<JobResult>>> =
        Mutex::new((0..compiles.len()).map(|_| None).collect());
    let sources: Mutex<HashMap<String, Result<String, String>>> = Mutex::new(HashMap::new());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| loop {
                let index = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = compiles.get(index).map(|&j| &jobs[j]) else {
                    break;
                };
                let source = {
                    let mut sources = sources.lock().unwrap_or_else(|e| e.into_inner());
                    sources
                        .entry(job.name.clone())
                        .or_insert_with(|| glsl_compile::read_source(&root.join(&job.name)))
                        .clone()
                };
                let defines: BTreeMap<&str, &str> = job
                    .defines
                    .iter()
                    .map(|(n, v)| (n.as_str(), v.as_str()))
                    .collect();
                let result = source
                    .map_err(|e| format!("glsl/{}: {e}", job.name))
                    .and_then(|source| {
                        glsl_compile::compile_glsl(
                            &compiler, &root, &job.name, job.kind, &defines, &source,
                        )
                    })
                    .map(|output| {
                        for warning in output.warnings.lines() {
                            println!("cargo:warning={}: {warning}", job.line);
                        }
                        output.spirv
                    });
                results.lock().unwrap_or_else(|e| e.into_inner())[index] = Some(result);
            });
        }
    });

    let mut failures = Vec::new();
    let mut entries = Vec::with_capacity(jobs.len());
    let mut modules: Vec<Vec<u32>> = Vec::new();
    let mut module_of: HashMap<Vec<u32>, u32> = HashMap::new();
    let results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    let mut module_of_compile = Vec::with_capacity(compiles.len());
    for (&job, result) in compiles.iter().zip(results) {
        match result {
            Some(Ok(spirv)) => {
                let index = *module_of.entry(spirv.clone()).or_insert_with(|| {
                    modules.push(spirv);
                    (modules.len() - 1) as u32
                });
                module_of_compile.push(Some(index));
            }
            Some(Err(message)) => {
                failures.push(format!("{}:\n{message}", jobs[job].line));
                module_of_compile.push(None);
            }
            None => {
                failures.push(format!("{}: not compiled", jobs[job].line));
                module_of_compile.push(None);
            }
        }
    }
    for (job, &compile) in jobs.iter().zip(&job_compile) {
        if let Some(module) = module_of_compile[compile] {
            entries.push((job.line.clone(), module));
        }
    }
    if !failures.is_empty() {
        return Err(format!(
            "{} of {} distinct compiles of the shipped shader permutations ({MANIFEST}) failed \
             (GLSL files are named relative to glsl/):\n\n{}",
            failures.len(),
            compiles.len(),
            failures.join("\n\n")
        ));
    }
    entries.sort();
    let bundle = shader_files::encode_bundle(&entries, &modules);
    let path = out_dir.join("shaders.bundle");
    std::fs::write(&path, bundle).map_err(|e| format!("{}: {e}", path.display()))
}

/// Every identifier in shader `name` and the files it includes (all of them, whatever `#if`
/// guards them); `None` when an include cannot be followed, and then every define counts.
fn identifiers(root: &Path, name: &str) -> Option<HashSet<String>> {
    let mut names = HashSet::new();
    let mut pending = vec![name.to_string()];
    let mut read = HashSet::new();
    while let Some(file) = pending.pop() {
        if !read.insert(file.clone()) {
            continue;
        }
        let text = glsl_compile::read_source(&root.join(&file)).ok()?;
        // Token pasting could build a name from pieces: count every define then.
        if text.contains("##") {
            return None;
        }
        for line in text.lines() {
            if let Some(rest) = line.trim_start().strip_prefix('#') {
                if let Some(target) = rest.trim_start().strip_prefix("include") {
                    let target = target.trim();
                    let requested = target.get(1..target.len().checked_sub(1)?)?;
                    // Where the include callback looks (beside the including file, then the
                    // root): both, when both exist.
                    let dir = Path::new(&file).parent().unwrap_or(Path::new(""));
                    let found: Vec<String> = [
                        glsl_compile::candidate_name(root, dir, requested),
                        glsl_compile::candidate_name(root, Path::new(""), requested),
                    ]
                    .into_iter()
                    .filter(|candidate| root.join(candidate).is_file())
                    .collect();
                    if found.is_empty() {
                        return None;
                    }
                    pending.extend(found);
                }
            }
        }
        let mut word = String::new();
        for c in text.chars().chain(std::iter::once(' ')) {
            if c.is_ascii_alphanumeric() || c == '_' {
                word.push(c);
            } else if !word.is_empty() {
                names.insert(std::mem::take(&mut word));
            }
        }
    }
    Some(names)
}
