//! The glTF file itself: the `.glb` container split by hand (header, JSON chunk, BIN chunk,
//! every length checked against what is there), the JSON read by the `gltf` crate's serde
//! types and checked by its validation, and every URI the asset names resolved here, never
//! by the crate: data URIs decoded, files read only inside the asset's folder, as regular
//! files, with a cap ([`crate::files::read_capped`]).

use std::path::{Component, Path, PathBuf};
use std::sync::Arc;

use ::gltf::json;
use ::gltf::json::validation::{Checked, Error as ValidationError, Validate};

/// Largest `.gltf`/`.glb` file, and largest buffer or image file it names (2 GiB, the OBJ
/// loader's cap).
pub const MAX_FILE_BYTES: u64 = 2 << 30;

/// Extensions lucent implements (see docs/gltf.md): a file may require these.
pub const IMPLEMENTED: [&str; 6] = [
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_volume",
    "KHR_materials_volume_scatter",
    "KHR_materials_ior",
    "KHR_materials_diffuse_transmission",
];

/// The asset's JSON, and its buffers read (index = buffer index).
pub struct Container {
    /// The document, validated by the `gltf` crate.
    pub root: json::Root,
    /// Every buffer's bytes, at least its declared `byteLength` long.
    pub buffers: Vec<Arc<[u8]>>,
    /// The asset's folder: URIs resolve inside it.
    pub dir: PathBuf,
}

/// Reads `path` (`.gltf` JSON or `.glb`), validates it and reads every buffer it names.
/// Errors are messages (the caller names the file).
pub fn read(path: &Path) -> Result<Container, String> {
    let bytes = crate::files::read_capped(path, MAX_FILE_BYTES, "glTF file")?;
    let (json_bytes, blob) = if bytes.starts_with(b"glTF") {
        let (json, blob) = split_glb(&bytes)?;
        (json.to_vec(), blob.map(<[u8]>::to_vec))
    } else {
        (bytes, None)
    };
    if json_bytes.iter().all(u8::is_ascii_whitespace) {
        return Err("empty file: no glTF JSON".into());
    }
    // serde_json refuses nesting deeper than 128 levels, so hostile nesting cannot overflow
    // the stack.
    let root: json::Root =
        serde_json::from_slice(&json_bytes).map_err(|e| format!("not valid glTF JSON: {e}"))?;
    drop(json_bytes);
    check_version(&root)?;
    check_required_extensions(&root)?;
    validate(&root)?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let buffers = read_buffers(&root, &dir, blob)?;
    Ok(Container { root, buffers, dir })
}

/// The JSON chunk and the BIN chunk (if any) of a `.glb` file (glTF 2.0 §4.4).
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let u32_at = |at: usize| -> Option<u32> {
        let b = bytes.get(at..at.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (u32_at(4), u32_at(8)) else {
        return Err(format!(
            "truncated GLB: {} bytes, less than its 12-byte header",
            bytes.len()
        ));
    };
    if version != 2 {
        return Err(format!("GLB version {version}; lucent reads version 2"));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(format!(
            "truncated GLB: its header says {length} bytes, the file has {}",
            bytes.len()
        ));
    }
    if length < 12 {
        return Err(format!(
            "truncated GLB: its header says {length} bytes, less than the 12-byte header itself"
        ));
    }
    if length < bytes.len() {
        log::warn!(
            "GLB header says {length} bytes; the {} bytes after them are ignored",
            bytes.len() - length
        );
    }
    let mut at = 12usize;
    let mut json = None;
    let mut bin = None;
    let mut index = 0;
    while at < length {
        let (Some(chunk_length), Some(kind)) = (u32_at(at), u32_at(at + 4)) else {
            return Err(format!(
                "truncated GLB: chunk {index} header at byte {at} is cut off"
            ));
        };
        let start = at + 8;
        let end = start
            .checked_add(chunk_length as usize)
            .filter(|&end| end <= length)
            .ok_or_else(|| {
                format!(
                    "truncated GLB: chunk {index} says {chunk_length} bytes, only {} are left",
                    length.saturating_sub(start)
                )
            })?;
        let data = &bytes[start..end];
        match (&kind.to_le_bytes(), index) {
            (b"JSON", 0) => json = Some(data),
            (b"JSON", _) => return Err(format!("GLB chunk {index} is a second JSON chunk")),
            (_, 0) => return Err("GLB's first chunk is not its JSON chunk".into()),
            (b"BIN\0", 1) => bin = Some(data),
            (b"BIN\0", _) => return Err(format!("GLB chunk {index} is a second BIN chunk")),
            // glTF 2.0 §4.4.3.1: chunks of unknown types are ignored.
            (other, _) => log::warn!(
                "GLB chunk {index} of unknown type {:?} ignored",
                String::from_utf8_lossy(other)
            ),
        }
        // Chunks are 4-byte aligned (padding included in their length); an unaligned end
        // is read as it is.
        at = end;
        index += 1;
    }
    let json = json.ok_or("GLB has no JSON chunk")?;
    Ok((json, bin))
}

/// glTF 2.x only.
fn check_version(root: &json::Root) -> Result<(), String> {
    let major = |v: &str| v.split('.').next().map(str::to_string);
    if major(&root.asset.version).as_deref() != Some("2") {
        return Err(format!(
            "asset.version is \"{}\"; lucent reads glTF 2.x",
            root.asset.version
        ));
    }
    if let Some(min) = &root.asset.min_version {
        if min != "2.0" {
            return Err(format!(
                "asset.minVersion is \"{min}\"; lucent reads glTF 2.0"
            ));
        }
    }
    Ok(())
}

/// An extension the file requires that lucent does not implement is an error; one it only
/// uses is a warning naming it.
fn check_required_extensions(root: &json::Root) -> Result<(), String> {
    if let Some(missing) = root
        .extensions_required
        .iter()
        .find(|e| !IMPLEMENTED.contains(&e.as_str()))
    {
        return Err(format!(
            "extensionsRequired names {missing}, which lucent does not implement (it implements \
             {})",
            IMPLEMENTED.join(", ")
        ));
    }
    for used in &root.extensions_used {
        if !IMPLEMENTED.contains(&used.as_str()) {
            log::warn!("extension {used} ignored: lucent does not implement it");
        }
    }
    Ok(())
}

/// The `gltf` crate's validation (indices in range, required keys, enum values), its first
/// error as a message naming the JSON path. The crate refuses required extensions it was
/// not built to parse; [`check_required_extensions`] decided those already.
fn validate(root: &json::Root) -> Result<(), String> {
    // The crate's check that POSITION has `min` and `max` indexes the accessors without a
    // bound check (gltf-json 1.4.1 mesh.rs): the index is checked here first.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => format!("{s:?}"),
                        Checked::Invalid => "?".into(),
                    };
                    return Err(format!(
                        "invalid glTF: meshes[{m}].primitives[{p}].attributes ({name}): \
                         accessors[{}] does not exist ({} accessors)",
                        accessor.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    let mut errors = Vec::new();
    root.validate(root, json::Path::new, &mut |path, error| {
        errors.push((path(), error));
    });
    let first = errors.into_iter().find(|(path, error)| {
        !(matches!(error, ValidationError::Unsupported)
            && path.as_str().starts_with("extensionsRequired"))
    });
    match first {
        None => Ok(()),
        Some((path, error)) => Err(format!("invalid glTF: {}: {error}", path.as_str())),
    }
}

/// Every buffer's bytes: the GLB's BIN chunk, a data URI or a file beside the asset; each
/// at least as long as its `byteLength` says.
fn read_buffers(
    root: &json::Root,
    dir: &Path,
    blob: Option<Vec<u8>>,
) -> Result<Vec<Arc<[u8]>>, String> {
    let mut blob = blob.map(Arc::<[u8]>::from);
    let mut out = Vec::with_capacity(root.buffers.len());
    for (i, buffer) in root.buffers.iter().enumerate() {
        let what = format!("buffers[{i}]");
        let bytes: Arc<[u8]> = match &buffer.uri {
            None if i == 0 => blob.take().ok_or_else(|| {
                format!("{what} has no uri and the file has no GLB BIN chunk to be it")
            })?,
            None => {
                return Err(format!(
                    "{what} has no uri: only buffers[0] may be a GLB's BIN chunk"
                ))
            }
            Some(uri) => read_uri(dir, uri, &what, "glTF buffer")?.into(),
        };
        let declared = buffer.byte_length.0;
        if (bytes.len() as u64) < declared {
            return Err(format!(
                "{what}: byteLength is {declared}, but its data has {} bytes",
                bytes.len()
            ));
        }
        out.push(bytes);
    }
    Ok(out)
}

/// The bytes a URI names: a base64 `data:` URI, or a relative path inside `dir` (percent
/// escapes decoded), read as a regular file of at most [`MAX_FILE_BYTES`]. Absolute paths,
/// `..` escapes, links that lead out of `dir` and other schemes are refused.
pub fn read_uri(dir: &Path, uri: &str, what: &str, kind: &str) -> Result<Vec<u8>, String> {
    if let Some(data) = uri.strip_prefix("data:") {
        let (header, payload) = data
            .split_once(',')
            .ok_or_else(|| format!("{what}: data URI without a ','"))?;
        if !header.ends_with(";base64") {
            return Err(format!(
                "{what}: data URI is not base64 (\"data:{header},...\"); lucent reads base64 \
                 data URIs"
            ));
        }
        return decode_base64(payload).map_err(|e| format!("{what}: data URI: {e}"));
    }
    let path = resolve_uri(dir, uri).map_err(|e| format!("{what}: uri \"{uri}\": {e}"))?;
    crate::files::read_capped(&path, MAX_FILE_BYTES, kind)
        .map_err(|e| format!("{what}: uri \"{uri}\" ({}): {e}", path.display()))
}

/// A relative URI as a path inside `dir`.
fn resolve_uri(dir: &Path, uri: &str) -> Result<PathBuf, String> {
    // A scheme is letters, digits, + - . before the first ':' (RFC 3986 §3.1).
    if let Some((scheme, _)) = uri.split_once(':') {
        if !scheme.is_empty()
            && scheme
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
        {
            return Err(format!(
                "the {scheme}: scheme is not read; lucent reads relative paths and data URIs"
            ));
        }
    }
    let decoded = percent_decode(uri)?;
    if decoded.contains('\0') {
        return Err("contains a NUL byte".into());
    }
    let relative = Path::new(&decoded);
    for component in relative.components() {
        match component {
            Component::Normal(_) | Component::CurDir => {}
            Component::ParentDir => {
                return Err("leads outside the asset's folder ('..')".into());
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err("is an absolute path; a glTF asset names files relative to it".into());
            }
        }
    }
    let path = dir.join(relative);
    // A link inside the folder may still lead out of it: compare where both really are.
    if let (Ok(real_dir), Ok(real)) = (
        dir.canonicalize()
            .or_else(|_| Path::new(".").canonicalize()),
        path.canonicalize(),
    ) {
        if !real.starts_with(&real_dir) {
            return Err(format!(
                "leads outside the asset's folder (to {})",
                real.display()
            ));
        }
    }
    Ok(path)
}

/// `%XX` escapes decoded (RFC 3986); the result must be UTF-8.
fn percent_decode(uri: &str) -> Result<String, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad percent escape at byte {i}"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).map_err(|_| "percent escapes decode to bytes that are not UTF-8".into())
}

/// Standard base64 (RFC 4648 §4), padding optional, no whitespace.
pub fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    fn value(c: u8) -> Option<u32> {
        match c {
            b'A'..=b'Z' => Some(u32::from(c - b'A')),
            b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
            b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
            b'+' => Some(62),
            b'/' => Some(63),
            _ => None,
        }
    }
    let text = text.trim_end_matches('=');
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for (i, c) in text.bytes().enumerate() {
        let v = value(c).ok_or_else(|| format!("byte {i} ({:?}) is not base64", c as char))?;
        acc = (acc << 6) | v;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    if bits >= 6 {
        return Err("base64 ends one character short".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_rfc_4648_vectors() {
        for (plain, encoded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(decode_base64(encoded).unwrap(), plain.as_bytes());
        }
        assert!(decode_base64("Zm9v!").is_err());
        assert!(decode_base64("Z").is_err());
    }

    #[test]
    fn uris_stay_inside_the_folder() {
        let dir = std::env::temp_dir();
        for bad in [
            "../x.bin",
            "a/../../x.bin",
            "/etc/passwd",
            "file:///etc/passwd",
            "http://example.com/x.bin",
            "%2e%2e/x.bin",
        ] {
            assert!(resolve_uri(&dir, bad).is_err(), "{bad}");
        }
        assert_eq!(resolve_uri(&dir, "a%20b.bin").unwrap(), dir.join("a b.bin"));
    }

    #[test]
    fn glb_lengths_are_checked() {
        assert!(split_glb(b"glTF").unwrap_err().contains("truncated"));
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(1000u32.to_le_bytes());
        assert!(split_glb(&glb).unwrap_err().contains("header says 1000"));
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(24u32.to_le_bytes());
        glb.extend(u32::MAX.to_le_bytes());
        glb.extend(b"JSON");
        glb.extend(b"{}  ");
        assert!(split_glb(&glb).unwrap_err().contains("chunk 0 says"));
    }
}
