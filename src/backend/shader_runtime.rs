//! Run-time GLSL compilation with shaderc and its SPIR-V disk cache (feature `runtime-shaders`):
//! the [`super::shader::ShaderCompiler`] of [`super::shader::ShaderCompiler::new`].
//!
//! An entry of the disk cache is found by a hash of the file's path, stage, defines, source text
//! and the compiler settings, and is only used when every included file still has the content
//! hash recorded with it, so editing an include recompiles every shader that uses it. The cache
//! is an optimisation and never an error source: unreadable or corrupt entries are misses, an
//! unwritable directory only logs a warning.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use xxhash_rust::xxh3::{xxh3_64, Xxh3};

use super::glsl_compile::{compile_glsl, read_source, COMPILER_SETTINGS, MAX_SOURCE_BYTES};
use super::spirv::{CompiledShader, ShaderStage, SPIRV_MAGIC};
use crate::error::{LucentError, Result};
use crate::files::write_file_atomic;
use crate::files::{read_capped, read_optional};

/// First bytes of a SPIR-V cache entry (format version in the last byte).
const CACHE_MAGIC: &[u8; 8] = b"LUCSPV\0\x01";

/// File name extension of SPIR-V cache entries.
const CACHE_EXTENSION: &str = "spvcache";

/// Largest SPIR-V cache entry read.
const MAX_CACHE_ENTRY_BYTES: u64 = 64 << 20;

fn shaderc_kind(stage: ShaderStage) -> shaderc::ShaderKind {
    match stage {
        ShaderStage::Vertex => shaderc::ShaderKind::Vertex,
        ShaderStage::Fragment => shaderc::ShaderKind::Fragment,
        ShaderStage::Compute => shaderc::ShaderKind::Compute,
    }
}

/// shaderc, the GLSL root and the optional disk cache.
#[derive(Debug)]
pub(super) struct RuntimeCompiler {
    compiler: shaderc::Compiler,
    pub(super) glsl_root: PathBuf,
    pub(super) cache_dir: Option<PathBuf>,
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

impl RuntimeCompiler {
    /// See [`super::shader::ShaderCompiler::new`].
    pub(super) fn new(glsl_root: PathBuf, cache_dir: Option<PathBuf>) -> Result<Self> {
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

    /// Compiles shader `name` (normalised) with validated, sorted `defines`.
    pub(super) fn compile(
        &self,
        name: &str,
        stage: ShaderStage,
        defines: &BTreeMap<&str, &str>,
    ) -> Result<CompiledShader> {
        let file = self.glsl_root.join(name);
        let source = read_source(&file).map_err(|e| LucentError::file(&file, e))?;
        let key = cache_key(name, stage, defines, &source);
        if let Some((spirv, deps)) = self.cache_lookup(key) {
            log::debug!("shader {name}: SPIR-V from cache");
            return Ok(CompiledShader {
                spirv,
                stage,
                dependencies: self.dependency_paths(&deps),
                from_cache: true,
            });
        }
        let (spirv, deps) = self.compile_uncached(name, stage, defines, &source)?;
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
        let output = compile_glsl(
            &self.compiler,
            &self.glsl_root,
            name,
            shaderc_kind(stage),
            defines,
            source,
        )
        .map_err(|message| LucentError::ShaderCompile {
            path: name.to_string(),
            message,
        })?;
        if !output.warnings.is_empty() {
            log::warn!("shader {name}: {}", output.warnings);
        }
        let deps = output
            .files
            .iter()
            .map(|(name, content)| Dependency {
                name: name.clone(),
                hash: xxh3_64(content.as_bytes()),
            })
            .collect();
        Ok((output.spirv, deps))
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::shader::ShaderCompiler;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lucent-shader-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
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
}
