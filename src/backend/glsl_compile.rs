//! GLSL to SPIR-V with shaderc, as both the run-time compiler ([`super::shader::ShaderCompiler`]
//! with the `runtime-shaders` feature) and `build.rs` (the shipped bundle) run it: the same
//! options and the same `#include` lookup, so the shipped SPIR-V is what a run-time compile of
//! the same sources gives.
//!
//! `build.rs` includes this file (`#[path]`) next to [`super::shader_files`]; it depends on
//! `std`, shaderc and that module only.

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

use super::shader_files::{
    normalize_relative, path_to_name, spirv_instructions, DECORATION_DESCRIPTOR_SET, OP_DECORATE,
    OP_NAME, OP_TYPE_POINTER, OP_VARIABLE, SPIRV_HEADER_WORDS,
};

/// Everything besides the inputs that changes the SPIR-V; part of every run-time cache key.
/// Change it when an option of [`compile_glsl`] changes, so old cache entries stop matching. (A
/// newer system shaderc does not invalidate entries: their SPIR-V stays valid, only possibly
/// less optimised.)
pub const COMPILER_SETTINGS: &str =
    "lucent-spirv-cache-v2;shaderc-rs-0.10;glsl;vulkan1.3;spirv1.6;opt=performance;auto-bind;resource-names";

/// Largest GLSL source or include read.
pub const MAX_SOURCE_BYTES: u64 = 4 << 20;

/// Deepest `#include` nesting accepted; deeper is taken to be an include cycle.
const MAX_INCLUDE_DEPTH: usize = 32;

/// What one compile produced.
pub struct GlslOutput {
    /// SPIR-V words.
    pub spirv: Vec<u32>,
    /// Every file read, main file first, each once: its name (relative to the root, or
    /// absolute outside it) and its content.
    pub files: Vec<(String, String)>,
    /// shaderc's warnings (empty when none).
    pub warnings: String,
}

/// Reads a GLSL file: UTF-8, at most [`MAX_SOURCE_BYTES`], without NUL bytes.
pub fn read_source(file: &Path) -> Result<String, String> {
    let size = std::fs::metadata(file).map_err(|e| e.to_string())?.len();
    if size > MAX_SOURCE_BYTES {
        return Err(format!(
            "GLSL source of {size} bytes, more than the {MAX_SOURCE_BYTES} accepted"
        ));
    }
    let bytes = std::fs::read(file).map_err(|e| e.to_string())?;
    let text = String::from_utf8(bytes).map_err(|_| "not UTF-8 text".to_string())?;
    if text.contains('\0') {
        return Err("GLSL source contains a NUL byte".to_string());
    }
    Ok(text)
}

/// Compiles `source` (the file `name` under `root`) for `kind` with `defines` through glslang
/// and spirv-opt. The error is shaderc's `file:line: error: ...` text, with the defines after
/// it when there are any.
pub fn compile_glsl(
    compiler: &shaderc::Compiler,
    root: &Path,
    name: &str,
    kind: shaderc::ShaderKind,
    defines: &BTreeMap<&str, &str>,
    source: &str,
) -> Result<GlslOutput, String> {
    let files = RefCell::new(vec![(name.to_string(), source.to_string())]);
    let mut options = shaderc::CompileOptions::new()
        .map_err(|e| format!("shaderc compile options could not be created: {e}"))?;
    options.set_source_language(shaderc::SourceLanguage::GLSL);
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_3 as u32,
    );
    options.set_target_spirv(shaderc::SpirvVersion::V1_6);
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    // Resources without a `binding` qualifier get glslang's numbers, which lucent overwrites
    // with the pass's declared order by the resource's name (backend/bindings.rs). Without
    // debug info the optimiser strips every name, so it is generated and then stripped here
    // down to the resources' names ([`keep_resource_names`]).
    options.set_auto_bind_uniforms(true);
    options.set_generate_debug_info();
    for (define, value) in defines {
        options.add_macro_definition(define, Some(value));
    }
    options.set_include_callback(|requested, include_type, requester, depth| {
        if depth > MAX_INCLUDE_DEPTH {
            return Err(format!(
                "#include nesting deeper than {MAX_INCLUDE_DEPTH} (an include cycle without a guard?)"
            ));
        }
        let (resolved_name, content) = resolve_include(root, requested, include_type, requester)?;
        let mut files = files.borrow_mut();
        if !files.iter().any(|(n, _)| *n == resolved_name) {
            files.push((resolved_name.clone(), content.clone()));
        }
        Ok(shaderc::ResolvedInclude {
            resolved_name,
            content,
        })
    });
    let artifact = compiler
        .compile_into_spirv(source, kind, name, "main", Some(&options))
        .map_err(|e| {
            let mut message = match e {
                shaderc::Error::CompilationError(_, text) => text.trim_end().to_string(),
                other => other.to_string(),
            };
            if !defines.is_empty() {
                message.push_str(&format!("\n(defines: {})", format_defines(defines)));
            }
            message
        })?;
    let warnings = if artifact.get_num_warnings() > 0 {
        artifact.get_warning_messages().trim_end().to_string()
    } else {
        String::new()
    };
    let spirv = keep_resource_names(artifact.as_binary());
    drop(options);
    Ok(GlslOutput {
        spirv,
        files: files.into_inner(),
        warnings,
    })
}

/// `spirv` without its debug instructions (source text, line numbers, processing notes, names
/// and member names) but the names of the variables in descriptor sets and of the blocks they
/// point at: what binding by name needs, a few words per resource. The code is untouched.
pub fn keep_resource_names(spirv: &[u32]) -> Vec<u32> {
    const OP_SOURCE_CONTINUED: u32 = 2;
    const OP_SOURCE: u32 = 3;
    const OP_SOURCE_EXTENSION: u32 = 4;
    const OP_MEMBER_NAME: u32 = 6;
    const OP_STRING: u32 = 7;
    const OP_LINE: u32 = 8;
    const OP_NO_LINE: u32 = 317;
    const OP_MODULE_PROCESSED: u32 = 330;
    // shaderc's own output: well formed.
    let instructions = || spirv_instructions(spirv).map_while(|i| i.ok().map(|(_, words)| words));
    let opcode = |i: &[u32]| i[0] & 0xffff;
    // Variables in a descriptor set, and what their pointer types point at.
    let in_sets: Vec<u32> = instructions()
        .filter(|i| opcode(i) == OP_DECORATE && i.get(2) == Some(&DECORATION_DESCRIPTOR_SET))
        .filter_map(|i| i.get(1).copied())
        .collect();
    let pointees: BTreeMap<u32, u32> = instructions()
        .filter(|i| opcode(i) == OP_TYPE_POINTER && i.len() > 3)
        .map(|i| (i[1], i[3]))
        .collect();
    let mut named: Vec<u32> = in_sets.clone();
    for i in instructions().filter(|i| opcode(i) == OP_VARIABLE && i.len() > 2) {
        if in_sets.contains(&i[2]) {
            named.extend(pointees.get(&i[1]));
        }
    }
    let mut out = spirv[..SPIRV_HEADER_WORDS.min(spirv.len())].to_vec();
    for instruction in instructions() {
        let keep = match opcode(instruction) {
            OP_SOURCE_CONTINUED | OP_SOURCE | OP_SOURCE_EXTENSION | OP_STRING | OP_LINE
            | OP_NO_LINE | OP_MODULE_PROCESSED | OP_MEMBER_NAME => false,
            OP_NAME => instruction.get(1).is_some_and(|id| named.contains(id)),
            _ => true,
        };
        if keep {
            out.extend_from_slice(instruction);
        }
    }
    out
}

/// `NAME=VALUE` pairs separated by spaces, for messages.
pub fn format_defines(defines: &BTreeMap<&str, &str>) -> String {
    defines
        .iter()
        .map(|(name, value)| format!("{name}={value}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Lexically normalises an absolute path.
pub fn normalize_absolute(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other.as_os_str()),
        }
    }
    out
}

/// Candidate name for `requested` seen from `base_dir` (a name relative to the root, or absolute):
/// relative to the root when it stays inside it, else absolute.
pub fn candidate_name(root: &Path, base_dir: &Path, requested: &str) -> String {
    let joined = base_dir.join(requested);
    if joined.is_absolute() {
        let absolute = normalize_absolute(&joined);
        return match absolute.strip_prefix(root) {
            Ok(inside) => path_to_name(inside),
            Err(_) => absolute.to_string_lossy().into_owned(),
        };
    }
    match normalize_relative(&joined) {
        Some(inside) => path_to_name(&inside),
        None => path_to_name(&normalize_absolute(&root.join(joined))),
    }
}

/// The include callback's lookup: `#include "x"` next to the including file first, then (and for
/// `#include <x>` only) under the GLSL root. Returns the file's name and content.
fn resolve_include(
    root: &Path,
    requested: &str,
    include_type: shaderc::IncludeType,
    requester: &str,
) -> Result<(String, String), String> {
    let mut candidates = Vec::with_capacity(2);
    if include_type == shaderc::IncludeType::Relative {
        let requester_dir = Path::new(requester).parent().unwrap_or(Path::new(""));
        candidates.push(candidate_name(root, requester_dir, requested));
    }
    let from_root = candidate_name(root, Path::new(""), requested);
    if !candidates.contains(&from_root) {
        candidates.push(from_root);
    }
    for name in &candidates {
        let file = root.join(name);
        if file.exists() {
            let content = read_source(&file)
                .map_err(|e| format!("cannot read include {}: {e}", file.display()))?;
            return Ok((name.clone(), content));
        }
    }
    // shaderc retries a failed `#include "x"` as `#include <x>`, so this message (root only) is
    // the one users see for both forms; it names both places.
    let next_to = Path::new(requester)
        .parent()
        .map(path_to_name)
        .filter(|dir| !dir.is_empty())
        .unwrap_or_else(|| ".".to_string());
    Err(format!(
        "include \"{requested}\" not found: #include \"...\" looks next to the including file \
         (in {next_to}/), then under the GLSL root {} (as {})",
        root.display(),
        candidate_name(root, Path::new(""), requested)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn include_names_are_normalised() {
        let root = Path::new("/r");
        assert_eq!(
            candidate_name(root, Path::new("smoke"), "../common/x.glsl"),
            "common/x.glsl"
        );
        assert_eq!(
            candidate_name(root, Path::new("smoke"), "./x.glsl"),
            "smoke/x.glsl"
        );
        assert_eq!(candidate_name(root, Path::new(""), "x.glsl"), "x.glsl");
        assert_eq!(candidate_name(root, Path::new(""), "../x.glsl"), "/x.glsl");
        assert_eq!(
            candidate_name(root, Path::new("/r/a"), "b.glsl"),
            "a/b.glsl"
        );
    }
}
