//! The interactive demo under Xvfb (a virtual X server) on lavapipe, validation on: a scripted
//! run that resizes the window (also to nothing and back), switches techniques and moves the
//! camera must exit 0, and its last frame must match `lucent render` of the same view.
//!
//! The test starts its own Xvfb on a free display number and stops it at the end. Without an
//! Xvfb binary it fails (tools/setup.sh installs it): a demo nobody ran is not a passing test.

#![cfg(feature = "window")]

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use lucent::images::compare::{flip_rgba8, FlipThresholds};
use lucent::images::output::read_png_rgba8;

/// A running Xvfb, killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Self {
        let binary = ["/usr/bin/Xvfb", "/usr/local/bin/Xvfb"]
            .into_iter()
            .map(PathBuf::from)
            .find(|p| p.is_file())
            .or_else(|| which("Xvfb"))
            .unwrap_or_else(|| {
                panic!("Xvfb not found: the demo test needs it; run tools/setup.sh (apt-get install xvfb)")
            });
        // A display number nobody uses: no lock file and no socket. Tests of this file run in
        // parallel in one process, so a counter keeps them apart, and a number another process
        // took in the meantime (Xvfb exits at once) moves on to the next.
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let base = 100 + std::process::id() % 400;
        for _ in 0..50 {
            let number = base + NEXT.fetch_add(1, Ordering::Relaxed);
            if Path::new(&format!("/tmp/.X{number}-lock")).exists()
                || Path::new(&format!("/tmp/.X11-unix/X{number}")).exists()
            {
                continue;
            }
            let display = format!(":{number}");
            let child = Command::new(&binary)
                .args([&display, "-screen", "0", "1024x768x24", "-nolisten", "tcp"])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("starting Xvfb");
            let mut xvfb = Self { child, display };
            let socket = PathBuf::from(format!("/tmp/.X11-unix/X{number}"));
            let started = Instant::now();
            loop {
                if socket.exists() {
                    return xvfb;
                }
                if let Ok(Some(_)) = xvfb.child.try_wait() {
                    break; // taken by someone else: try the next number
                }
                assert!(
                    started.elapsed() < Duration::from_secs(20),
                    "Xvfb {} did not open its socket within 20 s",
                    xvfb.display
                );
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        panic!("Xvfb did not start on any of 50 display numbers from :{base}");
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn which(name: &str) -> Option<PathBuf> {
    std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join(name))
            .find(|p| p.is_file())
    })
}

fn out_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("demo");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `lucent ARGS` against `display` (X11 only: a Wayland session of the host must not be used).
fn lucent(display: &str) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_lucent"));
    command
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .env("LUCENT_VALIDATION", "1")
        .env("RUST_LOG", "lucent=info");
    command
}

#[test]
fn scripted_demo_exits_cleanly_and_its_last_frame_matches_render() {
    let xvfb = Xvfb::start();
    let dir = out_dir();
    let shot = dir.join("demo-cubes.png");
    let _ = std::fs::remove_file(&shot);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/demo.script");
    let out = lucent(&xvfb.display)
        .args([
            "demo", "--scene", "cubes", "--size", "320x240", "--frames", "90",
        ])
        .arg("--script")
        .arg(&script)
        .arg("--screenshot")
        .arg(&shot)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "demo failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    assert!(!stderr.contains("Validation Error"), "{stderr}");
    // The summary line: all frames presented, time spent minimized, the swapchain recreated
    // for every resize that changed its size (at least: to 0x0, and back).
    let summary = stdout
        .lines()
        .find(|l| l.starts_with("demo: "))
        .unwrap_or_else(|| panic!("no summary line:\n{stdout}"));
    let number_before = |word: &str| -> u64 {
        let words: Vec<&str> = summary.split_whitespace().collect();
        let at = words
            .iter()
            .position(|w| w.starts_with(word))
            .unwrap_or_else(|| panic!("'{word}' in {summary}"));
        words[at - 1].trim_matches(',').parse().unwrap()
    };
    assert_eq!(number_before("frames"), 90, "{summary}");
    assert!(
        number_before("ticks") >= 19,
        "minimized for 20 ticks: {summary}"
    );
    assert!(number_before("swapchain") >= 2, "{summary}");
    assert!(summary.contains("technique translucency"), "{summary}");
    assert!(
        stderr.contains("swapchain recreated") && stderr.contains("-> 0x0"),
        "{stderr}"
    );

    // Whatever size the X server gave the window, `render` renders the same view at that size.
    let (w, h, demo) = read_png_rgba8(&shot).unwrap();
    if (w, h) != (320, 240) {
        eprintln!("note: the X server kept the window at {w}x{h} instead of 320x240");
    }
    let reference = dir.join("render-cubes.png");
    let rendered = lucent(&xvfb.display)
        .args(["render", "--scene", "cubes", "--technique", "translucency"])
        .args(["--size", &format!("{w}x{h}")])
        .arg("--out")
        .arg(&reference)
        .output()
        .unwrap();
    assert!(
        rendered.status.success(),
        "{}",
        String::from_utf8_lossy(&rendered.stderr)
    );
    let (_, _, expected) = read_png_rgba8(&reference).unwrap();
    let flip = flip_rgba8(&expected, &demo, w, h).unwrap();
    assert!(
        flip.within(&FlipThresholds::default()),
        "demo's last frame differs from render: mean FLIP {:.4}, {:.3}% above threshold",
        flip.mean,
        flip.fraction_above * 100.0
    );
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// Waits for a stderr line containing `wanted`; returns every line read so far.
fn wait_for(
    lines: &std::sync::mpsc::Receiver<String>,
    seen: &mut Vec<String>,
    wanted: &str,
    what: &str,
) {
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match lines.recv_timeout(left) {
            Ok(line) => {
                let found = line.contains(wanted);
                seen.push(line);
                if found {
                    return;
                }
            }
            Err(_) => panic!(
                "{what}: no '{wanted}' within 120 s; log:\n{}",
                seen.join("\n")
            ),
        }
    }
}

#[test]
fn shader_edits_rebuild_the_frame_and_a_broken_shader_keeps_the_old_one() {
    let xvfb = Xvfb::start();
    // A private copy of the shaders, so the edits below touch nothing another test compiles.
    let glsl = out_dir().join(format!("glsl-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&glsl);
    copy_tree(&Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"), &glsl);
    let tonemap = glsl.join("post/tonemap.frag");
    let original = std::fs::read_to_string(&tonemap).unwrap();

    let mut child = lucent(&xvfb.display)
        .env("LUCENT_GLSL_DIR", &glsl)
        .args(["demo", "--scene", "smoke", "--size", "160x120"])
        .args(["--frames", "100000000"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (send, lines) = std::sync::mpsc::channel();
    let reader = std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            if send.send(line).is_err() {
                break;
            }
        }
    });
    let mut seen = Vec::new();
    wait_for(&lines, &mut seen, "renderer 160x120", "first build");

    // A typo: the rebuild fails, the error names the file, the old renderer keeps running.
    std::fs::write(&tonemap, format!("{original}\nthis is not glsl;\n")).unwrap();
    wait_for(&lines, &mut seen, "rebuild failed", "broken shader");
    wait_for(
        &lines,
        &mut seen,
        "post/tonemap.frag",
        "the error names the file",
    );
    let built_before = seen
        .iter()
        .filter(|l| l.contains("renderer 160x120"))
        .count();

    // Fixed: the next poll rebuilds.
    std::fs::write(&tonemap, &original).unwrap();
    wait_for(
        &lines,
        &mut seen,
        "renderer 160x120",
        "rebuild after the fix",
    );
    assert_eq!(
        seen.iter()
            .filter(|l| l.contains("renderer 160x120"))
            .count(),
        built_before + 1
    );
    // Still alive (it kept rendering through the error); this test ends it.
    assert!(child.try_wait().unwrap().is_none(), "{}", seen.join("\n"));
    let _ = child.kill();
    let _ = child.wait();
    drop(lines);
    let _ = reader.join();
    let log = seen.join("\n");
    assert!(!log.contains("Validation Error"), "{log}");
    std::fs::remove_dir_all(&glsl).unwrap();
}
