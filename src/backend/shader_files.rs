//! What the library and `build.rs` must agree on about shader files: shader names, permutation
//! lines, the shipped SPIR-V bundle's byte layout and a SPIR-V module's instruction stream
//! ([`spirv_instructions`], which both read the resources' names through).
//!
//! `build.rs` cannot call the library, so it includes this file (`#[path]`): one copy of the
//! code, compiled twice. It depends on `std` only.
//!
//! - A *name* is a shader's path relative to the GLSL root, `/`-separated and normalised
//!   (`deferred/../sss/blur.frag` is `sss/blur.frag`).
//! - A *permutation line* is a name followed by its defines, sorted by name, each `NAME=VALUE`
//!   (an empty value is `NAME=`), separated by single spaces: `sss/blur.frag LUCENT_SSS_LEAN=1`.
//!   It is the key of the bundle and one line of `glsl/permutations.txt`.
//! - The bundle (little-endian): [`BUNDLE_MAGIC`], entry count, SPIR-V module count (u32 each);
//!   per entry its permutation line (u32 length + UTF-8) and the index of its module (u32); per
//!   module its word count (u32) and words. Permutations that compile to the same words share
//!   one module.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

/// First bytes of a shipped SPIR-V bundle (format version in the last byte).
pub const BUNDLE_MAGIC: &[u8; 8] = b"LUCBNDL\x01";

/// Lexically normalises a relative path (`a/./b/../c` -> `a/c`); `None` if it is absolute or
/// climbs above its start.
pub fn normalize_relative(path: &Path) -> Option<PathBuf> {
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

/// A path as a `/`-separated name for messages, cache entries and permutation lines.
pub fn path_to_name(path: &Path) -> String {
    path.components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
        .replace("//", "/")
}

/// The shader name of `path` (relative to the GLSL root); `None` when it is empty, absolute or
/// leaves the root.
pub fn shader_name(path: &str) -> Option<String> {
    normalize_relative(Path::new(path))
        .filter(|p| !p.as_os_str().is_empty())
        .map(|p| path_to_name(&p))
}

/// Why `name` is not a define name (a GLSL identifier), or why `value` cannot be a define's
/// value; `None` when both are fine. `line_safe` also refuses whitespace in the value, which a
/// permutation line could not hold.
pub fn define_problem(name: &str, value: &str, line_safe: bool) -> Option<String> {
    let valid_name = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !valid_name {
        return Some(format!("define name '{name}' is not a GLSL identifier"));
    }
    if value.contains(['\0', '\n', '\r']) {
        return Some(format!(
            "the value of define {name} contains a NUL or line break"
        ));
    }
    if line_safe && value.contains(char::is_whitespace) {
        return Some(format!(
            "the value of define {name} ('{value}') contains whitespace, which a permutation \
             line cannot hold"
        ));
    }
    None
}

/// The permutation line of shader `name` with `defines` (already sorted and deduplicated).
pub fn permutation_line<'a>(
    name: &str,
    defines: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> String {
    let mut line = name.to_string();
    for (define, value) in defines {
        line.push(' ');
        line.push_str(define);
        line.push('=');
        line.push_str(value);
    }
    line
}

// The library only reads bundles; build.rs parses the manifest.
#[allow(dead_code)]
/// Splits a permutation line into its name and defines; `Err` says what is wrong (a define
/// without `=`, defines out of order or repeated, a bad name or value).
pub fn parse_permutation_line(line: &str) -> Result<(String, BTreeMap<String, String>), String> {
    let mut parts = line.split(' ');
    let name = parts.next().unwrap_or_default();
    if shader_name(name).as_deref() != Some(name) {
        return Err(format!("'{name}' is not a normalised shader path"));
    }
    let mut defines = BTreeMap::new();
    let mut previous: Option<&str> = None;
    for part in parts {
        let (define, value) = part
            .split_once('=')
            .ok_or_else(|| format!("'{part}' is not NAME=VALUE"))?;
        if let Some(problem) = define_problem(define, value, true) {
            return Err(problem);
        }
        if previous.is_some_and(|p| p >= define) {
            return Err(format!(
                "define {define} is out of order or repeated (names are sorted, each once)"
            ));
        }
        previous = Some(define);
        defines.insert(define.to_string(), value.to_string());
    }
    Ok((name.to_string(), defines))
}

// The library only reads bundles; build.rs writes them.
#[allow(dead_code)]
/// Encodes a bundle: `entries` are (permutation line, module index) pairs.
pub fn encode_bundle(entries: &[(String, u32)], modules: &[Vec<u32>]) -> Vec<u8> {
    let words: usize = modules.iter().map(Vec::len).sum();
    let mut out = Vec::with_capacity(16 + entries.len() * 64 + words * 4);
    out.extend_from_slice(BUNDLE_MAGIC);
    out.extend_from_slice(&(entries.len() as u32).to_le_bytes());
    out.extend_from_slice(&(modules.len() as u32).to_le_bytes());
    for (line, module) in entries {
        out.extend_from_slice(&(line.len() as u32).to_le_bytes());
        out.extend_from_slice(line.as_bytes());
        out.extend_from_slice(&module.to_le_bytes());
    }
    for module in modules {
        out.extend_from_slice(&(module.len() as u32).to_le_bytes());
        for word in module {
            out.extend_from_slice(&word.to_le_bytes());
        }
    }
    out
}

/// A decoded bundle: each permutation line with its module index, and the modules.
pub struct DecodedBundle {
    /// (permutation line, index into `modules`).
    pub entries: Vec<(String, u32)>,
    /// SPIR-V words of each module.
    pub modules: Vec<Vec<u32>>,
}

/// Decodes [`encode_bundle`]'s bytes; `Err` names what is malformed.
pub fn decode_bundle(bytes: &[u8]) -> Result<DecodedBundle, String> {
    let mut reader = Reader(bytes);
    if reader.take(BUNDLE_MAGIC.len())? != BUNDLE_MAGIC {
        return Err("not a lucent SPIR-V bundle (bad magic)".to_string());
    }
    let entry_count = reader.u32()? as usize;
    let module_count = reader.u32()? as usize;
    let mut entries = Vec::with_capacity(entry_count.min(1 << 16));
    for _ in 0..entry_count {
        let len = reader.u32()? as usize;
        let line = std::str::from_utf8(reader.take(len)?)
            .map_err(|_| "a permutation line is not UTF-8".to_string())?
            .to_string();
        let module = reader.u32()?;
        if module as usize >= module_count {
            return Err(format!("{line}: module {module} out of range"));
        }
        entries.push((line, module));
    }
    let mut modules = Vec::with_capacity(module_count.min(1 << 16));
    for _ in 0..module_count {
        let words = reader.u32()? as usize;
        let bytes = reader.take(words.checked_mul(4).ok_or("module too large")?)?;
        modules.push(
            bytes
                .chunks_exact(4)
                .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
                .collect(),
        );
    }
    if !reader.0.is_empty() {
        return Err(format!("{} bytes after the last module", reader.0.len()));
    }
    Ok(DecodedBundle { entries, modules })
}

/// Cursor over the bundle's bytes.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let (head, tail) = self
            .0
            .split_at_checked(n)
            .ok_or_else(|| "truncated".to_string())?;
        self.0 = tail;
        Ok(head)
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
}

/// Words before a SPIR-V module's first instruction (magic, version, generator, bound, schema).
pub const SPIRV_HEADER_WORDS: usize = 5;
/// `OpName`.
pub const OP_NAME: u32 = 5;
/// `OpTypePointer`.
pub const OP_TYPE_POINTER: u32 = 32;
/// `OpVariable`.
pub const OP_VARIABLE: u32 = 59;
/// `OpDecorate`.
pub const OP_DECORATE: u32 = 71;
/// The `DescriptorSet` decoration.
pub const DECORATION_DESCRIPTOR_SET: u32 = 34;

/// The instructions of SPIR-V module `spirv` in order, each as the index of its first word and
/// its words (the first holds the word count in its high half, the opcode in its low half). An
/// instruction of length 0 or one that
/// runs past the module's end is an `Err` naming its word, and ends the stream.
pub fn spirv_instructions(spirv: &[u32]) -> impl Iterator<Item = Result<(usize, &[u32]), String>> {
    let mut at = SPIRV_HEADER_WORDS.min(spirv.len());
    let mut failed = false;
    std::iter::from_fn(move || {
        if failed || at >= spirv.len() {
            return None;
        }
        let count = (spirv[at] >> 16) as usize;
        match spirv.get(at..at + count).filter(|_| count > 0) {
            Some(instruction) => {
                let first = at;
                at += count;
                Some(Ok((first, instruction)))
            }
            None => {
                failed = true;
                Some(Err(format!(
                    "instruction at word {at} runs past the module's end"
                )))
            }
        }
    })
}
