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

use crate::common;
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

/// `lucent ARGS` against `display` (X11 only: a Wayland session of the host must not be used).
fn lucent(display: &str) -> Command {
    let mut command = common::lucent_command();
    command
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .env("LUCENT_VALIDATION", "1")
        .env("RUST_LOG", "lucent=info");
    command
}

/// Runs a scripted demo to the end: it must exit 0 without a validation error; returns its
/// stdout and stderr.
fn run_demo(command: &mut Command) -> (String, String) {
    let out = command.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "demo failed ({}):\n{stdout}\n{stderr}",
        out.status
    );
    assert!(!stderr.contains("Validation Error"), "{stderr}");
    (stdout, stderr)
}

#[test]
fn scripted_demo_exits_cleanly_and_its_last_frame_matches_render() {
    let xvfb = Xvfb::start();
    let dir = common::temp_dir("demo-cubes");
    let shot = dir.join("demo-cubes.png");
    let script = common::data("demo.script");
    let (stdout, stderr) = run_demo(
        lucent(&xvfb.display)
            .args([
                "demo", "--scene", "cubes", "--size", "320x240", "--frames", "90",
            ])
            .arg("--script")
            .arg(&script)
            .arg("--screenshot")
            .arg(&shot),
    );
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
    common::succeeded(
        lucent(&xvfb.display)
            .args(["render", "--scene", "cubes", "--technique", "translucency"])
            .args(["--size", &format!("{w}x{h}")])
            .arg("--out")
            .arg(&reference),
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
    let glsl = common::temp_dir("demo-glsl");
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

/// A small scene of the test's own: a translucent block lit from behind by one point light
/// (casting shadows) over a floor, so that the technique (translucency) differs from plain
/// lighting and a moved light moves both the lit areas and the shadow.
fn light_scene(light: [f32; 3], intensity: f32) -> String {
    std::fs::read_to_string(common::data("demo-lights.toml"))
        .unwrap()
        .replace(
            "POSITION",
            &format!("[{}, {}, {}]", light[0], light[1], light[2]),
        )
        .replace("INTENSITY", &intensity.to_string())
}

/// Columns `from..to` of a `w`-wide RGBA8 image.
fn columns(pixels: &[u8], w: u32, h: u32, from: u32, to: u32) -> Vec<u8> {
    let mut out = Vec::with_capacity(((to - from) * h * 4) as usize);
    for y in 0..h {
        let row = (y * w) as usize * 4;
        out.extend_from_slice(&pixels[row + from as usize * 4..row + to as usize * 4]);
    }
    out
}

/// |a - b| x 4 per channel (alpha opaque): the difference view, computed on the CPU.
fn amplified_difference(a: &[u8], b: &[u8]) -> Vec<u8> {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .flat_map(|(p, q)| {
            let d = |i: usize| ((i32::from(p[i]) - i32::from(q[i])).abs() * 4).min(255) as u8;
            [d(0), d(1), d(2), 255]
        })
        .collect()
}

fn assert_flip(what: &str, expected: &[u8], got: &[u8], w: u32, h: u32) {
    let flip = flip_rgba8(expected, got, w, h).unwrap();
    assert!(
        flip.within(&FlipThresholds::default()),
        "{what}: mean FLIP {:.4}, {:.3}% above threshold",
        flip.mean,
        flip.fraction_above * 100.0
    );
}

#[test]
fn scripted_light_move_split_and_difference_views_match_render() {
    let xvfb = Xvfb::start();
    let dir = common::temp_dir("demo-lights");
    let start = [1.0, 2.2, -2.0];
    let scene = dir.join("lights.toml");
    std::fs::write(&scene, light_scene(start, 20.0)).unwrap();
    let shot = |name: &str| dir.join(format!("{name}.png"));
    // Keys move the light (camera-relative: right, right, right, up) and brighten it twice;
    // then the split view, split + difference, and the difference alone, a screenshot of each.
    let script = dir.join("lights.script");
    std::fs::write(
        &script,
        format!(
            "2 key Right\n3 key Right\n4 key Right\n5 key Up\n6 key ]\n7 key ]\n\
             9 screenshot {}\n10 key C\n12 screenshot {}\n13 key X\n15 screenshot {}\n\
             16 key C\n18 screenshot {}\n",
            shot("moved").display(),
            shot("split").display(),
            shot("split-difference").display(),
            shot("difference").display()
        ),
    )
    .unwrap();
    let (stdout, _) = run_demo(
        lucent(&xvfb.display)
            .args(["demo", "--technique", "translucency", "--size", "240x180"])
            .arg("--scene")
            .arg(&scene)
            .args(["--frames", "20"])
            .arg("--script")
            .arg(&script),
    );
    // Where the keys put the light: the demo prints every light at exit.
    let line = stdout
        .lines()
        .find(|l| l.starts_with("demo light 1: point position"))
        .unwrap_or_else(|| panic!("no light line:\n{stdout}"));
    let words: Vec<&str> = line.split_whitespace().collect();
    let number = |i: usize| -> f32 { words[i].parse().unwrap_or_else(|_| panic!("{line}")) };
    let moved = [number(5), number(6), number(7)];
    let intensity = number(9);
    assert!((intensity - 20.0 * 1.25 * 1.25).abs() < 1e-3, "{line}");
    // Three steps right and one up: the camera looks down -Z (right is +X), so x grew and z
    // did not change (the up vector tilts towards the camera).
    assert!(moved[0] > start[0] + 0.5 && moved[1] > start[1], "{line}");
    let moved_scene = dir.join("moved.toml");
    std::fs::write(&moved_scene, light_scene(moved, intensity)).unwrap();

    let (w, h, demo_moved) = read_png_rgba8(&shot("moved")).unwrap();
    let render = |scene: &Path, technique: &str| -> Vec<u8> {
        let file = dir.join(format!(
            "render-{}-{technique}.png",
            scene.file_stem().unwrap().to_string_lossy()
        ));
        common::succeeded(
            lucent(&xvfb.display)
                .args(["render", "--technique", technique])
                .args(["--size", &format!("{w}x{h}")])
                .arg("--scene")
                .arg(scene)
                .arg("--out")
                .arg(&file),
        );
        let (rw, rh, pixels) = read_png_rgba8(&file).unwrap();
        assert_eq!((rw, rh), (w, h));
        pixels
    };
    let technique = render(&moved_scene, "translucency");
    let plain = render(&moved_scene, "none");
    let before = render(&scene, "translucency");

    // The moved light is where `render` puts a light at that position (shadow included), and
    // the picture did change with the move.
    assert_flip("moved light", &technique, &demo_moved, w, h);
    let unmoved = flip_rgba8(&before, &demo_moved, w, h).unwrap();
    assert!(
        !unmoved.within(&FlipThresholds::default()),
        "moving the light changed nothing: mean FLIP {:.4} against the start",
        unmoved.mean
    );

    // Split: left half plain lighting, right half the technique.
    let half = w / 2;
    let (_, _, split) = read_png_rgba8(&shot("split")).unwrap();
    assert_flip(
        "split, left half vs render --technique none",
        &columns(&plain, w, h, 0, half),
        &columns(&split, w, h, 0, half),
        half,
        h,
    );
    assert_flip(
        "split, right half vs render --technique translucency",
        &columns(&technique, w, h, half, w),
        &columns(&split, w, h, half, w),
        w - half,
        h,
    );
    // The technique differs from plain lighting in this scene, so the two halves are not the
    // same frame.
    let same = flip_rgba8(&plain, &technique, w, h).unwrap();
    assert!(!same.within(&FlipThresholds::default()), "{}", same.mean);

    // Difference: |technique - plain| x 4 over the whole window; with the split, on the right.
    let expected = amplified_difference(&technique, &plain);
    let (_, _, difference) = read_png_rgba8(&shot("difference")).unwrap();
    assert_flip("difference view", &expected, &difference, w, h);
    let (_, _, split_difference) = read_png_rgba8(&shot("split-difference")).unwrap();
    assert_flip(
        "split + difference, right half",
        &columns(&expected, w, h, half, w),
        &columns(&split_difference, w, h, half, w),
        w - half,
        h,
    );
    assert_flip(
        "split + difference, left half",
        &columns(&plain, w, h, 0, half),
        &columns(&split_difference, w, h, 0, half),
        half,
        h,
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
