//! An on-disk cache of per-vertex bakes, keyed by mesh content and bake options.
//!
//! The key is a 128-bit xxh3 of [`CACHE_FORMAT_VERSION`], the mesh's positions, normals and
//! indices, and the options that change the result (rays, maximum distance, seed). One file per
//! key, `thickness-<key>.bin` in the cache directory, little-endian:
//!
//! ```text
//! magic "LUCTHICK" | version u32 | reserved u32 | key u128 | count u64 | count x f32 | xxh3-64 of all before
//! ```
//!
//! A missing file is a quiet miss. A file that cannot be read, or fails any check (magic,
//! version, key, vertex count, length, checksum, values finite in `[0, 1]`), is a miss with a
//! `log::warn!`, and is overwritten by the fresh bake. A cache that cannot be written is a
//! warning too: the bake is still returned. Bump [`CACHE_FORMAT_VERSION`] whenever the baker's
//! output for the same inputs changes.

use std::path::{Path, PathBuf};

use xxhash_rust::xxh3::{xxh3_64, Xxh3};

use super::{bake_per_vertex, bake_report, BakeOptions};
use crate::scene::Mesh;
use crate::Result;

/// Version of the cache file layout and of the baker's output; part of every key.
pub const CACHE_FORMAT_VERSION: u32 = 1;

const MAGIC: &[u8; 8] = b"LUCTHICK";

/// Largest cache entry read: the header and 4 bytes for each vertex 32-bit indices can address.
const MAX_CACHE_FILE_BYTES: u64 = HEADER as u64 + 4 * u32::MAX as u64;
/// Magic, version, reserved, key, count.
const HEADER: usize = 8 + 4 + 4 + 16 + 8;

/// The cache key of a per-vertex bake of `mesh` with `options`.
fn cache_key(mesh: &Mesh, options: &BakeOptions) -> u128 {
    let mut h = Xxh3::new();
    h.update(b"lucent thickness per vertex");
    h.update(&CACHE_FORMAT_VERSION.to_le_bytes());
    // Lengths first, so no two different meshes concatenate to the same byte stream.
    for len in [mesh.positions.len(), mesh.normals.len(), mesh.indices.len()] {
        h.update(&(len as u64).to_le_bytes());
    }
    for p in mesh.positions.iter().chain(&mesh.normals) {
        for c in p.to_array() {
            h.update(&c.to_le_bytes());
        }
    }
    for i in &mesh.indices {
        h.update(&i.to_le_bytes());
    }
    h.update(&options.rays.to_le_bytes());
    match options.max_distance {
        None => h.update(&[0]),
        Some(d) => {
            h.update(&[1]);
            h.update(&d.to_le_bytes());
        }
    }
    h.update(&options.seed.to_le_bytes());
    // The talk's occlusion keeps the key it always had; a distance bake gets its own.
    if options.measure == super::BakeMeasure::Distance {
        h.update(b"distance");
    }
    h.digest128()
}

/// The file a per-vertex bake of `mesh` with `options` is cached in under `cache_dir`.
pub fn cache_file(mesh: &Mesh, options: &BakeOptions, cache_dir: &Path) -> PathBuf {
    cache_dir.join(format!("thickness-{:032x}.bin", cache_key(mesh, options)))
}

/// [`bake_per_vertex`] behind the on-disk cache in `cache_dir` (created when missing).
///
/// Errors only for what the bake itself rejects (an invalid mesh or options); cache trouble is
/// logged and costs a re-bake.
pub fn cached_per_vertex(mesh: &Mesh, options: &BakeOptions, cache_dir: &Path) -> Result<Vec<f32>> {
    cached_per_vertex_with_status(mesh, options, cache_dir).map(|(values, _)| values)
}

/// [`cached_per_vertex`], also saying whether the values came from the cache (`true`) or from a
/// fresh bake (`false`).
pub fn cached_per_vertex_with_status(
    mesh: &Mesh,
    options: &BakeOptions,
    cache_dir: &Path,
) -> Result<(Vec<f32>, bool)> {
    // Bad input is an error whether or not some file happens to sit under its key.
    mesh.validate("mesh to bake")?;
    let key = cache_key(mesh, options);
    let path = cache_dir.join(format!("thickness-{key:032x}.bin"));
    // A regular file read with a cap: a cache entry replaced by a FIFO or device is a miss
    // with a warning, never a hang.
    match crate::files::read_optional(&path, MAX_CACHE_FILE_BYTES, "thickness cache entry") {
        Ok(Some(bytes)) => match decode(&bytes, key, mesh.vertex_count()) {
            Ok(values) => {
                log::debug!("thickness cache hit: {}", path.display());
                return Ok((values, true));
            }
            Err(why) => log::warn!("thickness cache {}: {why}; baking again", path.display()),
        },
        Ok(None) => {
            log::debug!("thickness cache miss: {}", path.display());
        }
        Err(e) => log::warn!(
            "thickness cache {} unreadable ({e}); baking again",
            path.display()
        ),
    }
    let (values, stats) = bake_per_vertex(mesh, options)?;
    log::info!("{}", bake_report(&stats));
    if let Err(e) = crate::files::write_file_atomic(&path, &encode(key, &values)) {
        log::warn!("thickness cache not written ({e}); the bake is used uncached");
    }
    Ok((values, false))
}

fn encode(key: u128, values: &[f32]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER + 4 * values.len() + 8);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&CACHE_FORMAT_VERSION.to_le_bytes());
    bytes.extend_from_slice(&0u32.to_le_bytes());
    bytes.extend_from_slice(&key.to_le_bytes());
    bytes.extend_from_slice(&(values.len() as u64).to_le_bytes());
    for v in values {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    let checksum = xxh3_64(&bytes);
    bytes.extend_from_slice(&checksum.to_le_bytes());
    bytes
}

/// The values of a cache file, or why it cannot be used.
fn decode(bytes: &[u8], key: u128, vertices: usize) -> std::result::Result<Vec<f32>, String> {
    if bytes.len() < HEADER + 8 || &bytes[..8] != MAGIC {
        return Err("not a thickness cache file".into());
    }
    let (body, tail) = bytes.split_at(bytes.len() - 8);
    let stored = u64::from_le_bytes(tail.try_into().map_err(|_| "truncated")?);
    if xxh3_64(body) != stored {
        return Err("checksum mismatch (corrupt file)".into());
    }
    let u32_at = |o: usize| u32::from_le_bytes([body[o], body[o + 1], body[o + 2], body[o + 3]]);
    let version = u32_at(8);
    if version != CACHE_FORMAT_VERSION {
        return Err(format!(
            "format version {version}, expected {CACHE_FORMAT_VERSION}"
        ));
    }
    let mut k = [0u8; 16];
    k.copy_from_slice(&body[16..32]);
    if u128::from_le_bytes(k) != key {
        return Err("key mismatch".into());
    }
    let mut c = [0u8; 8];
    c.copy_from_slice(&body[32..40]);
    let count = u64::from_le_bytes(c);
    if count != vertices as u64 {
        return Err(format!("{count} values for {vertices} vertices"));
    }
    if (body.len() - HEADER) as u64 != 4 * count {
        return Err("length does not match the value count".into());
    }
    let values: Vec<f32> = body[HEADER..]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    if values
        .iter()
        .any(|v| !(v.is_finite() && (0.0..=1.0).contains(v)))
    {
        return Err("a value outside [0, 1]".into());
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_decode_round_trip_and_every_check() {
        let values = vec![0.0, 0.5, 1.0];
        let bytes = encode(42, &values);
        assert_eq!(decode(&bytes, 42, 3).unwrap(), values);
        assert!(decode(&bytes, 43, 3).unwrap_err().contains("key"));
        assert!(decode(&bytes, 42, 4).unwrap_err().contains("vertices"));
        assert!(decode(&bytes[..bytes.len() - 1], 42, 3).is_err());
        assert!(decode(&[], 42, 3).is_err());
        let mut flipped = bytes.clone();
        flipped[HEADER + 2] ^= 1;
        assert!(decode(&flipped, 42, 3).unwrap_err().contains("checksum"));
        let bad = encode(42, &[f32::NAN, 0.0, 2.0]);
        assert!(decode(&bad, 42, 3).unwrap_err().contains("[0, 1]"));
    }
}
