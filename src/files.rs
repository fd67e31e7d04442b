//! The files lucent reads and the outputs of one command.
//!
//! Reading: every file lucent parses (scenes, OBJ and MTL files, textures, demo scripts, GLSL
//! sources, caches) goes through [`open_regular`] or [`read_capped`]: the path must be a
//! regular file once symlinks are followed (a character device such as `/dev/zero` would be
//! read forever, a FIFO blocks the open until a writer comes, a directory cannot be parsed), and
//! the bytes are read with a cap, counted as they arrive rather than taken from the size the
//! filesystem reports (which `/proc` files and growing files get wrong). The errors say what the
//! path is instead (`is a FIFO (named pipe), not a regular file`), without the path: callers
//! name the file.
//!
//! Outputs: [`check_outputs`] refuses, before any work, an output that is one of the command's
//! inputs (`bake-thickness in.obj --per-vertex in.obj` would overwrite the mesh) and two
//! outputs that are the same file (`render --out same.png --exr same.png`), whether they are
//! spelled alike or reached through a symlink, `..` or a hard link. Every file lucent writes
//! (images, reports, meshes, caches) is written by [`write_file_atomic`]: never half a file,
//! through symlinks and into devices rather than replacing them.
//!
//! Caches: [`default_cache_dir`] is where the SPIR-V, pipeline and thickness caches live when
//! the caller names no directory (per user, never the source tree).

use std::fs::{File, Metadata};
use std::io::{Read, Seek, SeekFrom, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{format_bytes, LucentError, Result};

/// What a path is, when it is not a regular file: `"a directory"`, `"a FIFO (named pipe)"`.
pub fn kind_of(metadata: &Metadata) -> &'static str {
    let t = metadata.file_type();
    if t.is_dir() {
        return "a directory";
    }
    if t.is_symlink() {
        return "a symbolic link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// Why `path` (symlinks followed) cannot be read as a regular file, if it cannot: not found,
/// unreadable, or what it is instead. The message does not repeat the path.
pub fn regular_file_problem(path: &Path) -> Option<String> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Some("file not found".into()),
        Err(e) => Some(format!("cannot read: {e}")),
        Ok(m) if m.is_file() => None,
        Ok(m) => Some(not_regular(path, &m)),
    }
}

/// "is a character device, not a regular file", naming where a symlink points.
fn not_regular(path: &Path, metadata: &Metadata) -> String {
    let through = match std::fs::symlink_metadata(path) {
        Ok(link) if link.file_type().is_symlink() => match std::fs::canonicalize(path) {
            Ok(target) => format!("is a symlink to {}, which is ", target.display()),
            Err(_) => "is a symlink to ".into(),
        },
        _ => "is ".into(),
    };
    format!(
        "{through}{}, not a regular file (lucent reads only regular files)",
        kind_of(metadata)
    )
}

/// Opens `path` for reading after checking it is a regular file (symlinks followed), so a FIFO
/// never blocks the open and a device is never read. Returns the file and its size, checked
/// again on the opened handle (the path could have been swapped in between). `cap` is the
/// largest size accepted, `what` names the kind of file in the size error ("scene file").
pub fn open_regular(path: &Path, cap: u64, what: &str) -> std::result::Result<(File, u64), String> {
    if let Some(problem) = regular_file_problem(path) {
        return Err(problem);
    }
    let file = File::open(path).map_err(|e| format!("cannot read: {e}"))?;
    let metadata = file.metadata().map_err(|e| format!("cannot read: {e}"))?;
    if !metadata.is_file() {
        return Err(not_regular(path, &metadata));
    }
    if metadata.len() > cap {
        return Err(too_large(metadata.len(), cap, what));
    }
    Ok((file, metadata.len()))
}

fn too_large(bytes: u64, cap: u64, what: &str) -> String {
    format!(
        "{} is too large for a {what} (at most {})",
        format_bytes(bytes),
        format_bytes(cap)
    )
}

/// Reads the whole regular file `path` ([`open_regular`]), at most `cap` bytes: the bytes are
/// counted as they are read, so a file that grows (or whose reported size lies) past `cap` is
/// refused rather than read on.
pub fn read_capped(path: &Path, cap: u64, what: &str) -> std::result::Result<Vec<u8>, String> {
    let (file, len) = open_regular(path, cap, what)?;
    // The reported size only sizes the first allocation (bounded by the cap).
    let mut bytes = Vec::with_capacity(usize::try_from(len.min(cap)).unwrap_or(0));
    file.take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read: {e}"))?;
    if bytes.len() as u64 > cap {
        return Err(format!(
            "grew past {} while being read: too large for a {what}",
            format_bytes(cap)
        ));
    }
    Ok(bytes)
}

/// [`read_capped`] for an optional file (a cache entry): `Ok(None)` when nothing is there.
pub fn read_optional(
    path: &Path,
    cap: u64,
    what: &str,
) -> std::result::Result<Option<Vec<u8>>, String> {
    match std::fs::symlink_metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        _ => read_capped(path, cap, what).map(Some),
    }
}

/// [`read_capped`] as a lucent error naming the file.
pub fn read_file(path: &Path, cap: u64, what: &str) -> Result<Vec<u8>> {
    read_capped(path, cap, what).map_err(|m| LucentError::file(path, m))
}

/// A reader that refuses to read past `cap` bytes from the start of the file, for decoders
/// that need `Seek` (image decoders): a file that grows while it is decoded stops at the cap.
pub struct Capped<R> {
    inner: R,
    position: u64,
    cap: u64,
}

impl<R: Read + Seek> Capped<R> {
    /// Wraps `inner`, positioned at its start.
    pub fn new(inner: R, cap: u64) -> Self {
        Self {
            inner,
            position: 0,
            cap,
        }
    }
}

impl<R: Read> Read for Capped<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let left = self.cap.saturating_sub(self.position);
        if left == 0 && !buf.is_empty() {
            return Err(std::io::Error::other(format!(
                "file grew past its {} limit while being read",
                format_bytes(self.cap)
            )));
        }
        let n = buf.len().min(usize::try_from(left).unwrap_or(usize::MAX));
        let read = self.inner.read(&mut buf[..n])?;
        self.position += read as u64;
        Ok(read)
    }
}

impl<R: Seek> Seek for Capped<R> {
    fn seek(&mut self, pos: SeekFrom) -> std::io::Result<u64> {
        self.position = self.inner.seek(pos)?;
        Ok(self.position)
    }
}

/// An existing file's identity: device and inode on Unix (so hard links and symlinks compare
/// equal), its canonical path elsewhere.
#[cfg(unix)]
type FileKey = (u64, u64);
#[cfg(not(unix))]
type FileKey = PathBuf;

/// Who a path is, to compare an output with the inputs and the other outputs.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Identity {
    /// An existing file.
    Existing(FileKey),
    /// A file that does not exist yet: its canonical directory and name.
    New(PathBuf),
}

/// The identity of `path` and whether it is (or will be) a regular file.
fn identity(path: &Path) -> Option<(Identity, bool)> {
    if let Ok(metadata) = std::fs::metadata(path) {
        #[cfg(unix)]
        let key = {
            use std::os::unix::fs::MetadataExt as _;
            (metadata.dev(), metadata.ino())
        };
        #[cfg(not(unix))]
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        return Some((Identity::Existing(key), metadata.is_file()));
    }
    // Not there yet: where it would be created (a dangling symlink is followed by the writer,
    // so it is compared by its target).
    let mut target = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::read_link(&target) {
            Ok(next) => {
                target = match target.parent() {
                    Some(parent) if next.is_relative() => parent.join(next),
                    _ => next,
                }
            }
            Err(_) => break,
        }
    }
    let name = target.file_name()?.to_owned();
    let parent = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    // A directory that does not exist yet (the writer creates it) cannot be canonicalised:
    // compared without its `.` components then.
    let parent = std::fs::canonicalize(parent).unwrap_or_else(|_| {
        parent
            .components()
            .filter(|c| *c != std::path::Component::CurDir)
            .collect()
    });
    Some((Identity::New(parent.join(name)), true))
}

/// Checks a command's outputs before it does any work: no output is one of `inputs` (each
/// `(what, path)`, e.g. `("the input mesh", in.obj)`), and no two outputs (each `(flag, path)`,
/// e.g. `("--out", a.png)`) are the same file. Existing devices and FIFOs are exempt from the
/// second rule: writing into `/dev/null` twice overwrites nothing.
pub fn check_outputs(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<()> {
    let inputs: Vec<(&str, &Path, Identity)> = inputs
        .iter()
        .filter_map(|&(what, path)| identity(path).map(|(id, _)| (what, path, id)))
        .collect();
    let mut seen: Vec<(&str, Identity, bool)> = Vec::new();
    for &(flag, path) in outputs {
        let Some((id, regular)) = identity(path) else {
            continue;
        };
        if let Some((what, input, _)) = inputs.iter().find(|(_, _, i)| *i == id) {
            return Err(LucentError::file(
                path,
                format!(
                    "{flag} would overwrite {what} {} of this command; write the output to \
                     another file",
                    input.display()
                ),
            ));
        }
        if let Some((other, _, _)) = seen.iter().find(|(_, o, r)| *r && regular && *o == id) {
            return Err(LucentError::file(
                path,
                format!("{other} and {flag} name the same file; give each output its own file"),
            ));
        }
        seen.push((flag, id, regular));
    }
    Ok(())
}

/// Writes `bytes` to `path`, never replacing what `path` is:
///
/// - a regular file, or nothing yet: atomically, into a temporary file in the same directory,
///   then renamed over `path` (a crash or a concurrent reader never sees half a file);
/// - a symlink: written through it, atomically at its target (the link stays a link, and a
///   dangling link creates its target);
/// - a character device, FIFO or socket (`/dev/null`, a pipe to another program): opened and
///   written into, as a shell redirection would; renaming over it would replace the device with
///   a file (as root, `/dev/full` became a regular file);
/// - a directory: an error.
///
/// Creates missing parent directories. The error names `path`.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let target = resolve_symlinks(path)?;
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => Err(LucentError::file(
            path,
            "is a directory; give a file name to write",
        )),
        Ok(m) if !m.is_file() => {
            // A device or FIFO: written into, never replaced.
            let mut file = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(|e| LucentError::file(path, format!("cannot open for writing: {e}")))?;
            file.write_all(bytes)
                .and_then(|()| file.flush())
                .map_err(|e| {
                    LucentError::file(path, format!("writing into {} failed: {e}", kind_of(&m)))
                })
        }
        _ => write_regular_atomic(path, &target, bytes),
    }
}

/// `path` with every symlink of its last component followed (relative links resolved against
/// their directory); the path itself when it is no symlink. Refuses symlink loops.
fn resolve_symlinks(path: &Path) -> Result<PathBuf> {
    let mut target = path.to_path_buf();
    // The limit Linux puts on symlinks followed in one lookup.
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let next = std::fs::read_link(&target)
                    .map_err(|e| LucentError::file(path, format!("cannot read symlink: {e}")))?;
                target = match target.parent() {
                    Some(parent) if next.is_relative() => parent.join(next),
                    _ => next,
                };
            }
            _ => return Ok(target),
        }
    }
    Err(LucentError::file(
        path,
        "too many levels of symbolic links (a symlink loop?)",
    ))
}

/// The temporary-then-rename write of a regular file at `target` (`path` names it in errors).
fn write_regular_atomic(path: &Path, target: &Path, bytes: &[u8]) -> Result<()> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let file_name = target
        .file_name()
        .ok_or_else(|| LucentError::file(path, "not a file path"))?;
    let parent = target.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(parent) = parent {
        std::fs::create_dir_all(parent)
            .map_err(|e| LucentError::file(path, format!("cannot create directory: {e}")))?;
    }
    // Unique per process and call, so concurrent writers of the same file never share a temporary.
    let tmp_name = format!(
        "{}.{}-{}.tmp",
        file_name.to_string_lossy(),
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let tmp: PathBuf = match parent {
        Some(parent) => parent.join(tmp_name),
        None => PathBuf::from(tmp_name),
    };
    let result = std::fs::write(&tmp, bytes).and_then(|()| std::fs::rename(&tmp, target));
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        LucentError::file(path, e)
    })
}

/// The cache directory used when the caller names none (the run-time SPIR-V cache, the
/// thickness bake cache and the pipeline cache live in it): `$LUCENT_CACHE_DIR`, else
/// `lucent` in the user's cache directory: `$XDG_CACHE_HOME` or `~/.cache` on Linux and
/// other Unixes, `~/Library/Caches` on macOS, `%LOCALAPPDATA%` on Windows; the system's
/// temporary directory when none of those is known. Per user, so another user's run neither
/// warns nor writes into someone else's tree, and never the source tree. A host passes its
/// own directory instead (`ShaderCompiler::new`,
/// [`PipelineCache::load_for_device`](crate::backend::shader::PipelineCache::load_for_device),
/// [`crate::bake::scene::load_scene_baked_in`]).
pub fn default_cache_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("LUCENT_CACHE_DIR").filter(|d| !d.is_empty()) {
        return PathBuf::from(dir);
    }
    user_cache_dir().join("lucent")
}

/// The platform's per-user cache directory (see [`default_cache_dir`]).
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

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("lucent-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn regular_files_read_and_everything_else_is_named() {
        let dir = temp_dir("regular");
        let file = dir.join("a.txt");
        std::fs::write(&file, b"hello").unwrap();
        assert_eq!(read_capped(&file, 5, "test file").unwrap(), b"hello");
        let e = read_capped(&file, 4, "test file").unwrap_err();
        assert!(
            e.contains("5 bytes is too large for a test file (at most 4 bytes)"),
            "{e}"
        );
        let e = read_capped(&dir, 100, "test file").unwrap_err();
        assert!(e.contains("is a directory, not a regular file"), "{e}");
        assert!(read_capped(&dir.join("none"), 1, "x")
            .unwrap_err()
            .contains("not found"));
        #[cfg(unix)]
        {
            let link = dir.join("zero.obj");
            std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
            let e = read_capped(&link, 100, "test file").unwrap_err();
            assert!(
                e.contains("symlink to /dev/zero") && e.contains("a character device"),
                "{e}"
            );
            let e = read_capped(Path::new("/dev/null"), 100, "x").unwrap_err();
            assert!(e.contains("is a character device"), "{e}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn capped_reader_stops_at_the_cap_and_seeks() {
        let data: Vec<u8> = (0..100).collect();
        let mut r = Capped::new(std::io::Cursor::new(data), 10);
        let mut buf = Vec::new();
        assert!(r.read_to_end(&mut buf).is_err());
        assert_eq!(buf.len(), 10);
        r.seek(SeekFrom::Start(4)).unwrap();
        let mut six = [0u8; 6];
        r.read_exact(&mut six).unwrap();
        assert_eq!(six, [4, 5, 6, 7, 8, 9]);
    }

    #[test]
    fn outputs_may_not_be_inputs_or_each_other() {
        let dir = temp_dir("outputs");
        let input = dir.join("in.obj");
        std::fs::write(&input, b"v 0 0 0").unwrap();
        let e = check_outputs(&[("the input mesh", &input)], &[("--per-vertex", &input)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--per-vertex would overwrite the input mesh"),
            "{e}"
        );
        // The same file reached another way: through `..` and through a symlink.
        let sub = dir.join("sub");
        std::fs::create_dir_all(&sub).unwrap();
        let around = sub.join("../in.obj");
        assert!(check_outputs(&[("the input mesh", &input)], &[("--out", &around)]).is_err());
        #[cfg(unix)]
        {
            let link = dir.join("link.obj");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            assert!(check_outputs(&[("the input mesh", &input)], &[("--out", &link)]).is_err());
        }
        // Two new outputs spelled differently.
        let a = dir.join("same.png");
        let b = sub.join("../same.png");
        let e = check_outputs(&[], &[("--out", &a), ("--exr", &b)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--out and --exr name the same file"), "{e}");
        check_outputs(
            &[("the input mesh", &input)],
            &[("--out", &a), ("--exr", &dir.join("b"))],
        )
        .unwrap();
        // In a directory that does not exist yet.
        let (x, y) = (dir.join("new/x.png"), dir.join("new/./x.png"));
        assert!(check_outputs(&[], &[("--out", &x), ("--exr", &y)]).is_err());
        #[cfg(unix)]
        check_outputs(
            &[],
            &[
                ("--out", Path::new("/dev/null")),
                ("--json", Path::new("/dev/null")),
            ],
        )
        .unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn symlinks_are_written_through_and_devices_into() {
        let dir = temp_dir("through");
        let real = dir.join("real.json");
        std::fs::write(&real, b"old").unwrap();
        let link = dir.join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_file_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        // A dangling link creates its target.
        let dangling = dir.join("dangling.json");
        std::os::unix::fs::symlink("made.json", &dangling).unwrap();
        write_file_atomic(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.join("made.json")).unwrap(), b"made");
        // A device is written into, not replaced.
        write_file_atomic(Path::new("/dev/null"), b"gone").unwrap();
        let null = std::fs::metadata("/dev/null").unwrap();
        assert!(!null.is_file(), "/dev/null was replaced by a file");
        let e = write_file_atomic(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
        let looped = dir.join("loop");
        std::os::unix::fs::symlink("loop", &looped).unwrap();
        let e = write_file_atomic(&looped, b"x").unwrap_err().to_string();
        assert!(e.contains("symlink loop"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_default_cache_is_per_user() {
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
            assert!(default_cache_dir().ends_with("lucent"));
        }
    }
}
