//! What the commands' outputs do to what is already at their paths (issue 12): a symlink is
//! written through (the link stays, its target gets the file), a device or FIFO is written
//! into (never replaced by a file), a directory is an error; an output that is one of the
//! command's inputs, or two outputs that are the same file, are refused before any work and
//! leave every file as it was. Renders run tiny, with the validation layer on.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common;

fn lucent(dir: &Path, args: &[&str]) -> Output {
    common::lucent_command()
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the lucent binary runs")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A tiny validated render writing `extra` outputs.
fn render(dir: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["render", "--validation", "--size", "32x24"];
    args.extend_from_slice(extra);
    lucent(dir, &args)
}

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

#[cfg(unix)]
#[test]
fn symlinked_outputs_are_written_through_and_stay_links() {
    let dir = common::temp_dir("outputs-symlink");
    std::fs::create_dir_all(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/frame.png"), b"old").unwrap();
    std::os::unix::fs::symlink("real/frame.png", dir.join("frame.png")).unwrap();
    // A dangling link: its target is created.
    std::os::unix::fs::symlink("real/made.exr", dir.join("made.exr")).unwrap();
    let out = render(&dir, &["--out", "frame.png", "--exr", "made.exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    for link in ["frame.png", "made.exr"] {
        let m = std::fs::symlink_metadata(dir.join(link)).unwrap();
        assert!(m.file_type().is_symlink(), "{link} was replaced by a file");
    }
    let png = std::fs::read(dir.join("real/frame.png")).unwrap();
    assert!(
        png.starts_with(PNG_SIGNATURE),
        "the link's target was not written"
    );
    let exr = std::fs::read(dir.join("real/made.exr")).unwrap();
    assert!(
        exr.starts_with(&[0x76, 0x2f, 0x31, 0x01]),
        "no EXR at the target"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(unix)]
#[test]
fn devices_and_fifos_are_written_into_never_replaced() {
    let dir = common::temp_dir("outputs-devices");
    // /dev/null through a symlink and directly, twice in one command (writing into a device
    // twice overwrites nothing).
    std::os::unix::fs::symlink("/dev/null", dir.join("null.png")).unwrap();
    let out = render(&dir, &["--out", "null.png", "--exr", "/dev/null"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
    assert!(std::fs::symlink_metadata(dir.join("null.png"))
        .unwrap()
        .file_type()
        .is_symlink());
    // A FIFO: a reader on the other end gets the PNG, the FIFO stays a FIFO.
    let fifo = dir.join("frame.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let out = render(&dir, &["--out", "frame.fifo"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let bytes = reader.join().unwrap();
    assert!(bytes.starts_with(PNG_SIGNATURE), "{} bytes", bytes.len());
    use std::os::unix::fs::FileTypeExt as _;
    assert!(std::fs::symlink_metadata(&fifo)
        .unwrap()
        .file_type()
        .is_fifo());
    // A device that refuses the bytes is an error naming it, not a replaced device.
    if Path::new("/dev/full").exists() {
        let out = render(&dir, &["--out", "/dev/full"]);
        assert!(!out.status.success());
        let e = stderr(&out);
        assert!(
            e.contains("/dev/full") && e.contains("writing into a character device failed"),
            "{e}"
        );
        assert!(!std::fs::metadata("/dev/full").unwrap().is_file());
    }
    // A directory is an error.
    std::fs::create_dir_all(dir.join("folder.png")).unwrap();
    let out = render(&dir, &["--out", "folder.png"]);
    assert!(
        stderr(&out).contains("folder.png: is a directory"),
        "{}",
        stderr(&out)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Runs a command that must be refused before any work: one error line with `wanted`, fast,
/// and every file in `dir` exactly as before.
fn refused(dir: &Path, args: &[&str], wanted: &[&str]) {
    let before: Vec<(PathBuf, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let bytes = std::fs::read(&p).unwrap();
            (p, bytes)
        })
        .collect();
    let start = Instant::now();
    let out = lucent(dir, args);
    let took = start.elapsed();
    let e = stderr(&out);
    assert!(!out.status.success(), "{args:?} succeeded");
    let lines = common::error_lines(&out);
    assert_eq!(lines.len(), 1, "{args:?}: {e}");
    for w in wanted {
        assert!(lines[0].contains(w), "{args:?}: '{w}' not in {}", lines[0]);
    }
    assert!(!e.contains("wrote"), "{args:?} wrote something: {e}");
    // Before any work: no device opened, nothing baked (a render alone takes longer).
    assert!(took < Duration::from_secs(5), "{args:?} took {took:?}");
    for (path, bytes) in before {
        assert_eq!(
            std::fs::read(&path).unwrap(),
            bytes,
            "{args:?} changed {}",
            path.display()
        );
    }
    let after = std::fs::read_dir(dir).unwrap().count();
    assert!(after > 0);
}

#[test]
fn outputs_that_are_inputs_or_each_other_are_refused_before_any_work() {
    let dir = common::temp_dir("outputs-same-file");
    let cube = "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\n\
                v -1 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    std::fs::write(dir.join("in.obj"), cube).unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n[[mesh]]\nname = \"m\"\n\
         obj = \"in.obj\"\n[[material]]\nname = \"a\"\n[[object]]\nmesh = \"m\"\n\
         material = \"a\"\n",
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    refused(
        &dir,
        &["bake-thickness", "in.obj", "--per-vertex", "in.obj"],
        &["in.obj", "--per-vertex would overwrite the input mesh"],
    );
    refused(
        &dir,
        &["bake-thickness", "in.obj", "--out", "sub/../in.obj"],
        &["--out would overwrite the input mesh"],
    );
    refused(
        &dir,
        &[
            "bake-thickness",
            "in.obj",
            "--out",
            "t.png",
            "--per-vertex",
            "./t.png",
        ],
        &["--out and --per-vertex name the same file"],
    );
    refused(
        &dir,
        &["render", "--out", "same.png", "--exr", "same.png"],
        &["same.png", "--out and --exr name the same file"],
    );
    refused(
        &dir,
        &["render", "--scene", "scene.toml", "--out", "scene.toml"],
        &["--out would overwrite the scene file"],
    );
    refused(
        &dir,
        &["render", "--scene", "scene.toml", "--out", "in.obj"],
        &["--out would overwrite the mesh of [[mesh]] 'm'"],
    );
    refused(
        &dir,
        &["bench", "--json", "b.json", "--out", "sub/../b.json"],
        &["--json and --out name the same file"],
    );
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("in.obj", dir.join("alias.obj")).unwrap();
        refused(
            &dir,
            &["bake-thickness", "in.obj", "--per-vertex", "alias.obj"],
            &["alias.obj", "would overwrite the input mesh"],
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
