//! Run-time GLSL compilation, the SPIR-V disk cache, shader modules and the Vulkan pipeline cache.
//!
//! # When to use what
//!
//! - [`ShaderCompiler`]: turn a GLSL file under the GLSL root (`glsl/` in the repository, or
//!   `LUCENT_GLSL_DIR`) into SPIR-V with [`ShaderCompiler::compile`]. The stage comes from the
//!   extension (`.vert`, `.frag`, `.comp`), the GLSL version from the file's `#version` line.
//!   `#include "x.glsl"` is looked up next to the including file first, then under the GLSL root,
//!   so `#include "common/gbuffer.glsl"` works from any directory. Macro permutations are passed
//!   as `defines`. Keep one compiler for the whole program: creating a shaderc compiler is costly.
//! - The SPIR-V disk cache (the `cache_dir` of [`ShaderCompiler::new`], by default
//!   [`ShaderCompiler::default_cache_dir`]) skips glslang entirely when nothing changed. An entry
//!   is found by a hash of the file's path, stage, defines, source text and the compiler settings,
//!   and is only used when every included file still has the content hash recorded with it, so
//!   editing an include recompiles every shader that uses it. The cache is an optimisation and
//!   never an error source: unreadable or corrupt entries are misses, an unwritable directory
//!   only logs a warning. Pass `None` to always compile (tests that must see the compiler run).
//!   One case is not detected: a new file that would shadow an include previously found
//!   elsewhere (e.g. a new `pass/x.glsl` beside a shader that included the root's `x.glsl`);
//!   delete the cache directory after such a move.
//! - [`CompiledShader::dependencies`] lists the main file and every include (absolute paths), which
//!   is what a hot-reloader watches.
//! - [`create_shader_module`] wraps the SPIR-V in a `VkShaderModule`. The SPIR-V targets
//!   Vulkan 1.3 / SPIR-V 1.6, so the device must enable `maintenance4` (DESIGN.md, "Facts measured").
//! - [`PipelineCache`] is the driver's own pipeline cache (compiled machine code), loaded from and
//!   saved to one file. It is independent of the SPIR-V cache: that one saves glslang time, this one
//!   saves the driver's time in `vkCreate*Pipelines`. A file written by another driver or device is
//!   detected from its header and ignored.
//!
//! Compile errors are [`LucentError::ShaderCompile`] whose message holds shaderc's
//! `file:line: error: ...` lines, with files named relative to the GLSL root (an error inside an
//! include names the include, not the shader that included it).

use std::cell::RefCell;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use ash::vk;
use xxhash_rust::xxh3::{xxh3_64, Xxh3};

use crate::error::{LucentError, Result, VkResultExt};
use crate::files::{read_capped, read_optional};
use crate::images::output::write_file_atomic;

/// The platform's per-user cache directory (see [`ShaderCompiler::default_cache_dir`]).
fn user_cache_dir() -> PathBuf {
    user_cache_dir_from(|name| std::env::var_os(name))
}

/// [`user_cache_dir`] with the environment given as a lookup (for tests). Relative values are
/// ignored, as the XDG base directory specification asks.
fn user_cache_dir_from(env: impl Fn(&str) -> Option<std::ffi::OsString>) -> PathBuf {
    let var = |name: &str| env(name).map(PathBuf::from).filter(|p| p.is_absolute());
    let found = if cfg!(windows) {
        var("LOCALAPPDATA")
    } else if cfg!(target_os = "macos") {
        var("HOME").map(|h| h.join("Library/Caches"))
    } else {
        var("XDG_CACHE_HOME").or_else(|| var("HOME").map(|h| h.join(".cache")))
    };
    found.unwrap_or_else(std::env::temp_dir)
}

/// Everything besides the inputs that changes the SPIR-V; part of every cache key. Change it when a
/// compile option below changes, so old cache entries stop matching. (A newer system shaderc does
/// not invalidate entries: their SPIR-V stays valid, only possibly less optimised.)
const COMPILER_SETTINGS: &str =
    "lucent-spirv-cache-v1;shaderc-rs-0.10;glsl;vulkan1.3;spirv1.6;opt=performance;debug-info=off";

/// First bytes of a SPIR-V cache entry (format version in the last byte).
const CACHE_MAGIC: &[u8; 8] = b"LUCSPV\0\x01";

/// File name extension of SPIR-V cache entries.
const CACHE_EXTENSION: &str = "spvcache";

/// Largest GLSL source or include read.
const MAX_SOURCE_BYTES: u64 = 4 << 20;
/// Largest SPIR-V cache entry read.
const MAX_CACHE_ENTRY_BYTES: u64 = 64 << 20;
/// Largest pipeline cache file read.
const MAX_PIPELINE_CACHE_BYTES: u64 = 1 << 30;

/// Deepest `#include` nesting accepted; deeper is taken to be an include cycle.
const MAX_INCLUDE_DEPTH: usize = 32;

/// The SPIR-V magic number, first word of every module.
const SPIRV_MAGIC: u32 = 0x0723_0203;

/// A programmable pipeline stage, decided by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ShaderStage {
    /// `.vert`
    Vertex,
    /// `.frag`
    Fragment,
    /// `.comp`
    Compute,
}

impl ShaderStage {
    /// The stage for a file name ending in `.vert`, `.frag` or `.comp`; `None` for anything else.
    pub fn from_path(path: impl AsRef<Path>) -> Option<Self> {
        match path.as_ref().extension()?.to_str()? {
            "vert" => Some(Self::Vertex),
            "frag" => Some(Self::Fragment),
            "comp" => Some(Self::Compute),
            _ => None,
        }
    }

    /// The Vulkan stage flag, for pipeline stage create infos and descriptor set layouts.
    pub fn vk_stage(self) -> vk::ShaderStageFlags {
        match self {
            Self::Vertex => vk::ShaderStageFlags::VERTEX,
            Self::Fragment => vk::ShaderStageFlags::FRAGMENT,
            Self::Compute => vk::ShaderStageFlags::COMPUTE,
        }
    }

    /// The file extension (without dot), also used as the stage's name in cache keys.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Vertex => "vert",
            Self::Fragment => "frag",
            Self::Compute => "comp",
        }
    }

    fn shaderc_kind(self) -> shaderc::ShaderKind {
        match self {
            Self::Vertex => shaderc::ShaderKind::Vertex,
            Self::Fragment => shaderc::ShaderKind::Fragment,
            Self::Compute => shaderc::ShaderKind::Compute,
        }
    }
}

/// The result of [`ShaderCompiler::compile`].
#[derive(Debug, Clone)]
pub struct CompiledShader {
    /// SPIR-V words, ready for [`create_shader_module`].
    pub spirv: Vec<u32>,
    /// The stage, from the file extension.
    pub stage: ShaderStage,
    /// Absolute paths of the main file (first) and every file it included, each once.
    pub dependencies: Vec<PathBuf>,
    /// True when the SPIR-V came from the disk cache and glslang did not run.
    pub from_cache: bool,
}

/// Compiles GLSL files under one root directory to SPIR-V, with an optional disk cache.
///
/// `ShaderCompiler` is `Send + Sync`; one instance can serve several threads.
#[derive(Debug)]
pub struct ShaderCompiler {
    compiler: shaderc::Compiler,
    glsl_root: PathBuf,
    cache_dir: Option<PathBuf>,
    /// Set once the "cache directory not writable" warning has been logged, to log it only once.
    cache_write_warned: AtomicBool,
}

/// One file the compile read: its name (relative to the GLSL root, or absolute outside it) and
/// the xxh3 of its content.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Dependency {
    name: String,
    hash: u64,
}

impl ShaderCompiler {
    /// A compiler for the GLSL files under `glsl_root`, caching SPIR-V in `cache_dir` if given.
    ///
    /// Fails when `glsl_root` is not a directory or shaderc cannot be initialised. The cache
    /// directory is created on first use; if it cannot be, compiles still work (with a warning).
    pub fn new(glsl_root: impl Into<PathBuf>, cache_dir: Option<PathBuf>) -> Result<Self> {
        let glsl_root = glsl_root.into();
        if !glsl_root.is_dir() {
            return Err(LucentError::file(
                &glsl_root,
                "GLSL root is not a directory; lucent looks in $LUCENT_GLSL_DIR, then beside \
                 the executable (glsl/, ../share/lucent/glsl, glsl/ in a directory above it), \
                 then in the source tree it was built from: set LUCENT_GLSL_DIR to lucent's \
                 glsl/ folder",
            ));
        }
        // Absolute, so dependencies and cache-hit checks do not depend on the working directory.
        let glsl_root = glsl_root
            .canonicalize()
            .map_err(|e| LucentError::file(&glsl_root, e))?;
        let compiler = shaderc::Compiler::new().map_err(|e| {
            LucentError::InvalidInput(format!("the shaderc compiler could not be created: {e}"))
        })?;
        Ok(Self {
            compiler,
            glsl_root,
            cache_dir,
            cache_write_warned: AtomicBool::new(false),
        })
    }

    /// The GLSL root used when none is given: `$LUCENT_GLSL_DIR`; else the first shader tree
    /// found from the running executable: `glsl/` beside it, `../share/lucent/glsl` (an
    /// installed layout), or `glsl/` in a directory above it (the repository a `target/`
    /// build runs from: `cargo run`, the tests); else the source tree the library was
    /// compiled from, when it still exists (a host embedding the library). A tree is
    /// recognised by its `fullscreen.vert`.
    pub fn default_glsl_root() -> PathBuf {
        if let Some(dir) = std::env::var_os("LUCENT_GLSL_DIR").filter(|d| !d.is_empty()) {
            return PathBuf::from(dir);
        }
        let is_root = |dir: &Path| dir.join("fullscreen.vert").is_file();
        let compiled_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
        let exe_dir = std::env::current_exe()
            .ok()
            .and_then(|exe| exe.canonicalize().ok())
            .and_then(|exe| exe.parent().map(Path::to_path_buf));
        if let Some(dir) = exe_dir {
            let beside = [dir.join("glsl"), dir.join("../share/lucent/glsl")];
            let above = dir.ancestors().skip(1).map(|a| a.join("glsl"));
            if let Some(found) = beside.into_iter().chain(above).find(|d| is_root(d)) {
                return found;
            }
        }
        compiled_from
    }

    /// The SPIR-V cache directory used when none is given (the thickness bake cache and the
    /// pipeline cache live in it too): `$LUCENT_CACHE_DIR`, else `lucent` in the user's cache
    /// directory: `$XDG_CACHE_HOME` or `~/.cache` on Linux and other Unixes,
    /// `~/Library/Caches` on macOS, `%LOCALAPPDATA%` on Windows; the system's temporary
    /// directory when none of those is known. Per user, so another user's run neither warns
    /// nor writes into someone else's tree.
    pub fn default_cache_dir() -> PathBuf {
        if let Some(dir) = std::env::var_os("LUCENT_CACHE_DIR").filter(|d| !d.is_empty()) {
            return PathBuf::from(dir);
        }
        user_cache_dir().join("lucent")
    }

    /// The (absolute) GLSL root directory.
    pub fn glsl_root(&self) -> &Path {
        &self.glsl_root
    }

    /// The SPIR-V cache directory, if caching is on.
    pub fn cache_dir(&self) -> Option<&Path> {
        self.cache_dir.as_deref()
    }

    /// Compiles `path` (relative to the GLSL root, `/`-separated, e.g. `"smoke/gbuffer.frag"`) with
    /// the given macro definitions (`("NAME", "VALUE")`; an empty value defines the name as empty;
    /// when a name repeats, the last value wins).
    ///
    /// Errors: an unknown extension or a bad define is [`LucentError::InvalidInput`], an unreadable
    /// main file is [`LucentError::File`], and a GLSL error (including a missing include) is
    /// [`LucentError::ShaderCompile`] with shaderc's `file:line: error:` lines.
    pub fn compile(&self, path: &str, defines: &[(&str, &str)]) -> Result<CompiledShader> {
        let stage = ShaderStage::from_path(path).ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "shader {path}: unknown stage; the file name must end in .vert, .frag or .comp"
            ))
        })?;
        let name = normalize_relative(Path::new(path))
            .filter(|p| !p.as_os_str().is_empty())
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "shader {path}: the path must be relative to the GLSL root and stay inside it"
                ))
            })?;
        let name = path_to_name(&name);
        let defines = sorted_defines(path, defines)?;
        let file = self.glsl_root.join(&name);
        let source = read_capped(&file, MAX_SOURCE_BYTES, "GLSL source")
            .and_then(|b| String::from_utf8(b).map_err(|_| "not UTF-8 text".to_string()))
            .map_err(|e| LucentError::file(&file, e))?;
        if source.contains('\0') {
            return Err(LucentError::file(&file, "GLSL source contains a NUL byte"));
        }

        let key = cache_key(&name, stage, &defines, &source);
        if let Some((spirv, deps)) = self.cache_lookup(key) {
            log::debug!("shader {name}: SPIR-V from cache");
            return Ok(CompiledShader {
                spirv,
                stage,
                dependencies: self.dependency_paths(&deps),
                from_cache: true,
            });
        }

        let (spirv, deps) = self.compile_uncached(&name, stage, &defines, &source)?;
        self.cache_store(key, &spirv, &deps);
        Ok(CompiledShader {
            spirv,
            stage,
            dependencies: self.dependency_paths(&deps),
            from_cache: false,
        })
    }

    /// Runs glslang + spirv-opt through shaderc; returns the SPIR-V and every file read.
    fn compile_uncached(
        &self,
        name: &str,
        stage: ShaderStage,
        defines: &BTreeMap<&str, &str>,
        source: &str,
    ) -> Result<(Vec<u32>, Vec<Dependency>)> {
        let deps = RefCell::new(vec![Dependency {
            name: name.to_string(),
            hash: xxh3_64(source.as_bytes()),
        }]);
        let root = self.glsl_root.as_path();
        let mut options = shaderc::CompileOptions::new().map_err(|e| {
            LucentError::InvalidInput(format!("shaderc compile options could not be created: {e}"))
        })?;
        options.set_source_language(shaderc::SourceLanguage::GLSL);
        options.set_target_env(
            shaderc::TargetEnv::Vulkan,
            shaderc::EnvVersion::Vulkan1_3 as u32,
        );
        options.set_target_spirv(shaderc::SpirvVersion::V1_6);
        options.set_optimization_level(shaderc::OptimizationLevel::Performance);
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
            let mut deps = deps.borrow_mut();
            if !deps.iter().any(|d| d.name == resolved_name) {
                deps.push(Dependency {
                    name: resolved_name.clone(),
                    hash: xxh3_64(content.as_bytes()),
                });
            }
            Ok(shaderc::ResolvedInclude {
                resolved_name,
                content,
            })
        });

        let artifact = self
            .compiler
            .compile_into_spirv(source, stage.shaderc_kind(), name, "main", Some(&options))
            .map_err(|e| {
                let mut message = match e {
                    shaderc::Error::CompilationError(_, text) => text.trim_end().to_string(),
                    other => other.to_string(),
                };
                if !defines.is_empty() {
                    let _ = write!(message, "\n(defines: {})", format_defines(defines));
                }
                LucentError::ShaderCompile {
                    path: name.to_string(),
                    message,
                }
            })?;
        if artifact.get_num_warnings() > 0 {
            log::warn!(
                "shader {name}: {}",
                artifact.get_warning_messages().trim_end()
            );
        }
        let spirv = artifact.as_binary().to_vec();
        drop(options);
        Ok((spirv, deps.into_inner()))
    }

    fn dependency_paths(&self, deps: &[Dependency]) -> Vec<PathBuf> {
        deps.iter().map(|d| self.glsl_root.join(&d.name)).collect()
    }

    fn cache_entry_path(&self, key: u128) -> Option<PathBuf> {
        self.cache_dir
            .as_ref()
            .map(|dir| dir.join(format!("{key:032x}.{CACHE_EXTENSION}")))
    }

    /// A cache hit: an entry for `key` exists, parses, and every dependency still has its hash.
    fn cache_lookup(&self, key: u128) -> Option<(Vec<u32>, Vec<Dependency>)> {
        let path = self.cache_entry_path(key)?;
        let bytes = match read_optional(&path, MAX_CACHE_ENTRY_BYTES, "SPIR-V cache entry") {
            Ok(Some(bytes)) => bytes,
            Ok(None) => return None,
            Err(e) => {
                log::warn!(
                    "SPIR-V cache entry {} unreadable ({e}); recompiling",
                    path.display()
                );
                return None;
            }
        };
        let Some((spirv, deps)) = decode_cache_entry(&bytes, key) else {
            log::warn!(
                "SPIR-V cache entry {} is corrupt; recompiling",
                path.display()
            );
            return None;
        };
        for dep in &deps {
            let file = self.glsl_root.join(&dep.name);
            match read_capped(&file, MAX_SOURCE_BYTES, "GLSL source") {
                Ok(content) if xxh3_64(&content) == dep.hash => {}
                _ => {
                    log::debug!(
                        "SPIR-V cache entry {} is stale: {} changed",
                        path.display(),
                        dep.name
                    );
                    return None;
                }
            }
        }
        Some((spirv, deps))
    }

    /// Writes a cache entry; failures only warn (once per compiler) because the cache is optional.
    fn cache_store(&self, key: u128, spirv: &[u32], deps: &[Dependency]) {
        let Some(path) = self.cache_entry_path(key) else {
            return;
        };
        if let Err(e) = write_file_atomic(&path, &encode_cache_entry(key, spirv, deps)) {
            if !self.cache_write_warned.swap(true, Ordering::Relaxed) {
                log::warn!("SPIR-V cache not written, shaders will be recompiled next run: {e}");
            }
        }
    }
}

/// Lexically normalises a relative path (`a/./b/../c` -> `a/c`); `None` if it is absolute or
/// climbs above its start.
fn normalize_relative(path: &Path) -> Option<PathBuf> {
    let mut out = PathBuf::new();
    for component in path.components() {
        match component {
            Component::Normal(part) => out.push(part),
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    return None;
                }
            }
            Component::RootDir | Component::Prefix(_) => return None,
        }
    }
    Some(out)
}

/// Lexically normalises an absolute path.
fn normalize_absolute(path: &Path) -> PathBuf {
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

/// A path as a `/`-separated name for messages and cache entries.
fn path_to_name(path: &Path) -> String {
    path.components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
        .replace("//", "/")
}

/// Candidate name for `requested` seen from `base_dir` (a name relative to the root, or absolute):
/// relative to the root when it stays inside it, else absolute.
fn candidate_name(root: &Path, base_dir: &Path, requested: &str) -> String {
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
) -> std::result::Result<(String, String), String> {
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
            let content = read_capped(&file, MAX_SOURCE_BYTES, "GLSL source")
                .and_then(|b| String::from_utf8(b).map_err(|_| "not UTF-8 text".to_string()))
                .map_err(|e| format!("cannot read include {}: {e}", file.display()))?;
            if content.contains('\0') {
                return Err(format!("include {} contains a NUL byte", file.display()));
            }
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

/// Validates defines and orders them by name (last value of a repeated name wins, as in shaderc).
fn sorted_defines<'a>(
    path: &str,
    defines: &[(&'a str, &'a str)],
) -> Result<BTreeMap<&'a str, &'a str>> {
    let mut sorted = BTreeMap::new();
    for &(name, value) in defines {
        let valid_name = name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !valid_name {
            return Err(LucentError::InvalidInput(format!(
                "shader {path}: define name '{name}' is not a GLSL identifier"
            )));
        }
        if value.contains(['\0', '\n', '\r']) {
            return Err(LucentError::InvalidInput(format!(
                "shader {path}: the value of define {name} contains a NUL or line break"
            )));
        }
        sorted.insert(name, value);
    }
    Ok(sorted)
}

fn format_defines(defines: &BTreeMap<&str, &str>) -> String {
    defines
        .iter()
        .map(|(name, value)| format!("{name}={value}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// xxh3-128 of everything that selects one SPIR-V output apart from the included files (which are
/// checked by content hash on every hit).
fn cache_key(name: &str, stage: ShaderStage, defines: &BTreeMap<&str, &str>, source: &str) -> u128 {
    let mut hasher = Xxh3::new();
    // Every field is length-prefixed so that no two different inputs hash the same byte stream.
    let mut field = |bytes: &[u8]| {
        hasher.update(&(bytes.len() as u64).to_le_bytes());
        hasher.update(bytes);
    };
    field(COMPILER_SETTINGS.as_bytes());
    field(name.as_bytes());
    field(stage.extension().as_bytes());
    field(&(defines.len() as u64).to_le_bytes());
    for (define, value) in defines {
        field(define.as_bytes());
        field(value.as_bytes());
    }
    field(source.as_bytes());
    hasher.digest128()
}

/// Cache entry layout (little-endian): magic, key (u128), dependency count (u32), per dependency
/// name length (u32) + UTF-8 name + content hash (u64), SPIR-V word count (u32) + words, and an
/// xxh3-64 of everything before it, so a truncated or damaged file is detected.
fn encode_cache_entry(key: u128, spirv: &[u32], deps: &[Dependency]) -> Vec<u8> {
    let mut out = Vec::with_capacity(64 + spirv.len() * 4);
    out.extend_from_slice(CACHE_MAGIC);
    out.extend_from_slice(&key.to_le_bytes());
    out.extend_from_slice(&(deps.len() as u32).to_le_bytes());
    for dep in deps {
        out.extend_from_slice(&(dep.name.len() as u32).to_le_bytes());
        out.extend_from_slice(dep.name.as_bytes());
        out.extend_from_slice(&dep.hash.to_le_bytes());
    }
    out.extend_from_slice(&(spirv.len() as u32).to_le_bytes());
    for word in spirv {
        out.extend_from_slice(&word.to_le_bytes());
    }
    let checksum = xxh3_64(&out);
    out.extend_from_slice(&checksum.to_le_bytes());
    out
}

/// Parses a cache entry; `None` for anything malformed or written for another key.
fn decode_cache_entry(bytes: &[u8], key: u128) -> Option<(Vec<u32>, Vec<Dependency>)> {
    let (body, checksum) = bytes.split_at_checked(bytes.len().checked_sub(8)?)?;
    if xxh3_64(body) != u64::from_le_bytes(checksum.try_into().ok()?) {
        return None;
    }
    let mut reader = ByteReader(body);
    if reader.take(CACHE_MAGIC.len())? != CACHE_MAGIC {
        return None;
    }
    if u128::from_le_bytes(reader.take(16)?.try_into().ok()?) != key {
        return None;
    }
    let dep_count = reader.u32()? as usize;
    let mut deps = Vec::with_capacity(dep_count.min(1024));
    for _ in 0..dep_count {
        let len = reader.u32()? as usize;
        let name = std::str::from_utf8(reader.take(len)?).ok()?.to_string();
        let hash = u64::from_le_bytes(reader.take(8)?.try_into().ok()?);
        deps.push(Dependency { name, hash });
    }
    let word_count = reader.u32()? as usize;
    let words = reader.take(word_count.checked_mul(4)?)?;
    if !reader.0.is_empty() || deps.is_empty() {
        return None;
    }
    let spirv: Vec<u32> = words
        .chunks_exact(4)
        .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
        .collect();
    (spirv.first() == Some(&SPIRV_MAGIC)).then_some((spirv, deps))
}

/// Minimal cursor over a byte slice for [`decode_cache_entry`].
struct ByteReader<'a>(&'a [u8]);

impl<'a> ByteReader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, tail) = self.0.split_at_checked(n)?;
        self.0 = tail;
        Some(head)
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }
}

/// Creates a `VkShaderModule` from SPIR-V words (e.g. [`CompiledShader::spirv`]).
///
/// The caller destroys it (`vkDestroyShaderModule`), usually right after creating the pipelines.
pub fn create_shader_module(device: &ash::Device, spirv: &[u32]) -> Result<vk::ShaderModule> {
    if spirv.first() != Some(&SPIRV_MAGIC) {
        return Err(LucentError::InvalidInput(
            "create_shader_module: the words are not SPIR-V (bad magic number)".to_string(),
        ));
    }
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    // SAFETY: `info` points at valid SPIR-V words that outlive the call.
    unsafe { device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")
}

/// Size of `VkPipelineCacheHeaderVersionOne`: header length, header version, vendor id, device id
/// (4 bytes each) and the 16-byte pipeline cache UUID.
const PIPELINE_CACHE_HEADER_SIZE: usize = 32;

/// The driver's pipeline cache, persisted to one file between runs.
///
/// Create it with [`PipelineCache::load`] (or [`PipelineCache::load_for_device`], which also
/// checks that the file was written for this exact device), pass [`PipelineCache::handle`] to
/// every `vkCreate*Pipelines`, [`PipelineCache::save`] before shutdown and then
/// [`PipelineCache::destroy`].
#[derive(Debug)]
pub struct PipelineCache {
    /// The Vulkan pipeline cache object.
    pub handle: vk::PipelineCache,
    path: Option<PathBuf>,
}

impl PipelineCache {
    /// Creates a pipeline cache seeded from `path` when that file exists and looks valid.
    ///
    /// A missing file starts an empty cache; a file with a malformed header, or one the driver
    /// rejects, logs a warning and starts an empty cache. `None` gives a cache that is never saved.
    /// Vulkan itself ignores data whose vendor, device or UUID differ from the device's; use
    /// [`PipelineCache::load_for_device`] to check that here too and get a warning when it happens.
    pub fn load(device: &ash::Device, path: Option<PathBuf>) -> Result<Self> {
        Self::load_checked(device, path, None)
    }

    /// The device's cache in the default cache directory
    /// ([`ShaderCompiler::default_cache_dir`]`/pipelines.bin`), checked against the device as
    /// [`PipelineCache::load_for_device`] does: what every command and the demo use.
    pub fn load_default(gpu: &crate::backend::GpuContext) -> Result<Self> {
        // SAFETY: the physical device handle belongs to this instance.
        let properties = unsafe {
            gpu.instance
                .get_physical_device_properties(gpu.physical_device)
        };
        Self::load_for_device(
            &gpu.device,
            Some(ShaderCompiler::default_cache_dir().join("pipelines.bin")),
            &properties,
        )
    }

    /// Like [`PipelineCache::load`], and also ignores (with a warning) a file whose header names
    /// another vendor, device or pipeline cache UUID than `properties`.
    pub fn load_for_device(
        device: &ash::Device,
        path: Option<PathBuf>,
        properties: &vk::PhysicalDeviceProperties,
    ) -> Result<Self> {
        Self::load_checked(device, path, Some(properties))
    }

    fn load_checked(
        device: &ash::Device,
        path: Option<PathBuf>,
        properties: Option<&vk::PhysicalDeviceProperties>,
    ) -> Result<Self> {
        let data = match &path {
            None => Vec::new(),
            Some(path) => match read_optional(path, MAX_PIPELINE_CACHE_BYTES, "pipeline cache") {
                Ok(None) => Vec::new(),
                Ok(Some(data)) => match check_pipeline_cache_header(&data, properties) {
                    Ok(()) => data,
                    Err(why) => {
                        log::warn!(
                            "pipeline cache {} ignored ({why}); starting empty",
                            path.display()
                        );
                        Vec::new()
                    }
                },
                Err(e) => {
                    log::warn!(
                        "pipeline cache {} unreadable ({e}); starting empty",
                        path.display()
                    );
                    Vec::new()
                }
            },
        };
        let create = |initial: &[u8]| {
            let info = vk::PipelineCacheCreateInfo::default().initial_data(initial);
            // SAFETY: `info` and `initial` outlive the call.
            unsafe { device.create_pipeline_cache(&info, None) }.vk("vkCreatePipelineCache")
        };
        let handle = match create(&data) {
            Ok(handle) => handle,
            Err(e) if !data.is_empty() => {
                log::warn!("pipeline cache data rejected by the driver ({e}); starting empty");
                create(&[])?
            }
            Err(e) => return Err(e),
        };
        Ok(Self { handle, path })
    }

    /// A host's pipeline cache, used as it is: never loaded, saved or (the host owns it)
    /// destroyed by lucent; do not call [`PipelineCache::destroy`] on the result.
    pub fn borrowed(handle: vk::PipelineCache) -> Self {
        Self { handle, path: None }
    }

    /// The file this cache is loaded from and saved to, if any.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Writes the cache's current data to its file (atomically: temporary file, then rename),
    /// creating parent directories. Does nothing for a cache without a path.
    pub fn save(&self, device: &ash::Device) -> Result<()> {
        let Some(path) = &self.path else {
            return Ok(());
        };
        // SAFETY: `handle` is a live pipeline cache created on `device`.
        let data =
            unsafe { device.get_pipeline_cache_data(self.handle) }.vk("vkGetPipelineCacheData")?;
        write_file_atomic(path, &data)
    }

    /// Destroys the Vulkan object. Call [`PipelineCache::save`] first to keep its contents.
    pub fn destroy(self, device: &ash::Device) {
        // SAFETY: the caller guarantees no pipeline creation using this cache is in flight.
        unsafe { device.destroy_pipeline_cache(self.handle, None) };
    }
}

/// Checks a pipeline cache file's header (`VkPipelineCacheHeaderVersionOne`), and when
/// `properties` is given that it was written for this vendor, device and cache UUID.
fn check_pipeline_cache_header(
    data: &[u8],
    properties: Option<&vk::PhysicalDeviceProperties>,
) -> std::result::Result<(), String> {
    if data.len() < PIPELINE_CACHE_HEADER_SIZE {
        return Err(format!("{} bytes, shorter than the header", data.len()));
    }
    let word = |i: usize| u32::from_ne_bytes(data[i * 4..i * 4 + 4].try_into().unwrap_or([0; 4]));
    let (header_len, version, vendor_id, device_id) = (word(0), word(1), word(2), word(3));
    if (header_len as usize) < PIPELINE_CACHE_HEADER_SIZE || header_len as usize > data.len() {
        return Err(format!("bad header length {header_len}"));
    }
    if version != vk::PipelineCacheHeaderVersion::ONE.as_raw() as u32 {
        return Err(format!("unknown header version {version}"));
    }
    if let Some(props) = properties {
        let uuid = &data[16..32];
        if vendor_id != props.vendor_id
            || device_id != props.device_id
            || uuid != props.pipeline_cache_uuid
        {
            return Err(format!(
                "written for vendor {vendor_id:#x} device {device_id:#x}, this is vendor {:#x} device {:#x} (or the driver changed)",
                props.vendor_id, props.device_id
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lucent-shader-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn stage_from_extension() {
        assert_eq!(
            ShaderStage::from_path("a/b.vert"),
            Some(ShaderStage::Vertex)
        );
        assert_eq!(
            ShaderStage::from_path("b.frag"),
            Some(ShaderStage::Fragment)
        );
        assert_eq!(ShaderStage::from_path("b.comp"), Some(ShaderStage::Compute));
        assert_eq!(ShaderStage::from_path("common/b.glsl"), None);
        assert_eq!(
            ShaderStage::Compute.vk_stage(),
            vk::ShaderStageFlags::COMPUTE
        );
    }

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

    #[test]
    fn cache_entry_round_trip_and_corruption() {
        let deps = vec![
            Dependency {
                name: "a.frag".into(),
                hash: 1,
            },
            Dependency {
                name: "common/b.glsl".into(),
                hash: 2,
            },
        ];
        let spirv = vec![SPIRV_MAGIC, 0x0001_0600, 7, 8];
        let bytes = encode_cache_entry(42, &spirv, &deps);
        assert_eq!(decode_cache_entry(&bytes, 42), Some((spirv, deps)));
        assert_eq!(decode_cache_entry(&bytes, 43), None);
        for cut in [0, 1, 8, bytes.len() / 2, bytes.len() - 1] {
            assert_eq!(
                decode_cache_entry(&bytes[..cut], 42),
                None,
                "truncated at {cut}"
            );
        }
        let mut flipped = bytes.clone();
        flipped[30] ^= 0x10;
        assert_eq!(decode_cache_entry(&flipped, 42), None);
    }

    #[test]
    fn defines_are_validated_and_sorted() {
        let sorted = sorted_defines("x", &[("B", "1"), ("A", "2"), ("B", "3")]).unwrap();
        assert_eq!(format_defines(&sorted), "A=2 B=3");
        assert!(sorted_defines("x", &[("1A", "1")]).is_err());
        assert!(sorted_defines("x", &[("A B", "1")]).is_err());
        assert!(sorted_defines("x", &[("A", "1\n#define X")]).is_err());
    }

    #[test]
    fn corrupt_cache_entry_is_a_miss_and_unwritable_cache_is_not_an_error() {
        let root = temp_dir("corrupt");
        std::fs::write(
            root.join("a.comp"),
            "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
        )
        .unwrap();
        let cache = root.join("cache");
        let compiler = ShaderCompiler::new(&root, Some(cache.clone())).unwrap();
        assert!(!compiler.compile("a.comp", &[]).unwrap().from_cache);
        assert!(compiler.compile("a.comp", &[]).unwrap().from_cache);
        for entry in std::fs::read_dir(&cache).unwrap() {
            std::fs::write(entry.unwrap().path(), b"garbage").unwrap();
        }
        let again = compiler.compile("a.comp", &[]).unwrap();
        assert!(!again.from_cache);
        assert_eq!(again.spirv[0], SPIRV_MAGIC);

        // A cache "directory" that is a file: compiles still succeed, never from the cache.
        let blocked = root.join("blocked");
        std::fs::write(&blocked, b"not a directory").unwrap();
        let compiler = ShaderCompiler::new(&root, Some(blocked.join("cache"))).unwrap();
        assert!(!compiler.compile("a.comp", &[]).unwrap().from_cache);
        assert!(!compiler.compile("a.comp", &[]).unwrap().from_cache);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn default_paths_are_per_user_and_found_from_the_executable() {
        let env = |pairs: &'static [(&'static str, &'static str)]| {
            move |name: &str| {
                pairs
                    .iter()
                    .find(|(n, _)| *n == name)
                    .map(|(_, v)| std::ffi::OsString::from(v))
            }
        };
        if cfg!(all(unix, not(target_os = "macos"))) {
            assert_eq!(
                user_cache_dir_from(env(&[("XDG_CACHE_HOME", "/c"), ("HOME", "/h")])),
                Path::new("/c")
            );
            assert_eq!(
                user_cache_dir_from(env(&[("XDG_CACHE_HOME", "rel"), ("HOME", "/h")])),
                Path::new("/h/.cache")
            );
        }
        assert_eq!(user_cache_dir_from(env(&[])), std::env::temp_dir());
        // Not under the source tree, unless the user's cache is there.
        if std::env::var_os("LUCENT_CACHE_DIR").is_none() {
            assert!(ShaderCompiler::default_cache_dir().ends_with("lucent"));
        }
        // This test runs from target/<profile>/deps: the repository's tree is found above it.
        if std::env::var_os("LUCENT_GLSL_DIR").is_none() {
            let found = ShaderCompiler::default_glsl_root().canonicalize().unwrap();
            let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("glsl")
                .canonicalize()
                .unwrap();
            assert_eq!(found, repo);
        }
    }

    #[test]
    fn bad_paths_are_input_errors() {
        let root = temp_dir("badpath");
        let compiler = ShaderCompiler::new(&root, None).unwrap();
        assert!(matches!(
            compiler.compile("x.glsl", &[]),
            Err(LucentError::InvalidInput(_))
        ));
        assert!(matches!(
            compiler.compile("../x.frag", &[]),
            Err(LucentError::InvalidInput(_))
        ));
        assert!(matches!(
            compiler.compile("missing.frag", &[]),
            Err(LucentError::File { .. })
        ));
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn pipeline_cache_header_checks() {
        let mut props = vk::PhysicalDeviceProperties {
            vendor_id: 0x10005,
            device_id: 7,
            ..Default::default()
        };
        props.pipeline_cache_uuid = [3; 16];
        let mut data = Vec::new();
        for word in [32u32, 1, 0x10005, 7] {
            data.extend_from_slice(&word.to_ne_bytes());
        }
        data.extend_from_slice(&[3; 16]);
        data.extend_from_slice(b"driver data");
        assert!(check_pipeline_cache_header(&data, Some(&props)).is_ok());
        assert!(check_pipeline_cache_header(&data[..20], None).is_err());
        let mut other_device = data.clone();
        other_device[12] = 8;
        assert!(check_pipeline_cache_header(&other_device, None).is_ok());
        assert!(check_pipeline_cache_header(&other_device, Some(&props)).is_err());
        let mut bad_version = data.clone();
        bad_version[4] = 9;
        assert!(check_pipeline_cache_header(&bad_version, None).is_err());
    }
}
