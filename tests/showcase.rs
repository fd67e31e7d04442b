//! The showcase scenes and the gallery (issue 16), on lavapipe with validation on: each
//! showcase scene changes at least 5% of its pixels against plain lighting, without halos,
//! matches its golden, and `lucent gallery` writes its pictures and page.

use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

use common::TestGpu;
use lucent::frame::FrameSettings;
use lucent::images::compare::{compare_with_golden, FlipThresholds};
use lucent::measure::look;

const SHOWCASES: [&str; 4] = [
    "showcase-translucency",
    "showcase-skin",
    "showcase-marble",
    "showcase-layered",
];

fn output_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("test-output");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn each_showcase_scene_changes_five_percent_of_its_pixels_without_halos() {
    let test = TestGpu::new();
    // Two sizes: the share of pixels a technique changes must not hang on one resolution.
    for (w, h) in [(320, 240), (200, 150)] {
        for name in SHOWCASES.into_iter().chain(["mixed"]) {
            let scene = lucent::bake::scene::load_scene_baked(name).unwrap();
            let images = look::look(
                &test.gpu,
                &test.shaders,
                &test.cache,
                &scene,
                FrameSettings::new(w, h),
            )
            .unwrap();
            let l = images.look;
            eprintln!(
                "{name} {w}x{h}: {:.1}% changed, {} technique pixels, {} halo (max {})",
                100.0 * l.changed,
                l.technique_pixels,
                l.halo_pixels,
                l.halo_max
            );
            assert!(
                l.changed >= 0.05,
                "{name} at {w}x{h}: only {:.1}% of pixels changed against --technique none",
                100.0 * l.changed
            );
            // The technique objects cover a real part of the frame (the mask found them).
            assert!(l.technique_pixels * 10 > (w * h) as usize, "{name}: {l:?}");
            assert_eq!(l.halo_pixels, 0, "{name} at {w}x{h}: {l:?}");
        }
    }
    test.finish();
}

#[test]
fn showcase_scenes_match_their_goldens() {
    // Same settings as tests/golden/LIST's `showcase-*` lines.
    let test = TestGpu::new();
    for name in SHOWCASES {
        let scene = lucent::bake::scene::load_scene_baked(name).unwrap();
        let frame = lucent::frame::render_frame(
            &test.gpu,
            &test.shaders,
            &test.cache,
            &scene,
            FrameSettings::new(320, 240),
        )
        .unwrap();
        let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/{name}.png"));
        let outcome = compare_with_golden(
            name,
            &golden,
            &frame.display,
            320,
            240,
            &FlipThresholds::default(),
            &output_dir(),
        )
        .unwrap();
        assert!(
            outcome.passed,
            "{name} differs from its golden: mean FLIP {:.4}; see {:?} and {:?}",
            outcome.result.mean, outcome.actual_path, outcome.diff_path
        );
    }
    test.finish();
}

#[test]
fn gallery_writes_every_scene_and_its_page() {
    let out = output_dir().join("gallery");
    let _ = std::fs::remove_dir_all(&out);
    let run = Command::new(env!("CARGO_BIN_EXE_lucent"))
        .args(["gallery", "--size", "96x72", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let page = std::fs::read_to_string(out.join("index.md")).unwrap();
    for (name, _) in lucent::measure::gallery::GALLERY_SCENES {
        for suffix in ["", "-none", "-difference"] {
            let png = out.join(format!("{name}{suffix}.png"));
            let (w, h, _) = lucent::images::output::read_png_rgba8(&png).unwrap();
            assert_eq!((w, h), (96, 72), "{png:?}");
            assert!(page.contains(&format!("({name}{suffix}.png)")), "{page}");
        }
        assert!(page.contains(&format!("| `{name}` |")), "{page}");
        assert!(stdout.contains(&format!("{name}: ")), "{stdout}");
    }
}

#[test]
fn gallery_refuses_an_unknown_scene_and_a_bad_size() {
    let out = output_dir().join("gallery-bad");
    for args in [
        vec!["--scene", "no-such-scene", "--size", "32x24"],
        vec!["--size", "0x24"],
        vec!["--aa", "msaa", "--size", "32x24"],
    ] {
        let run = Command::new(env!("CARGO_BIN_EXE_lucent"))
            .arg("gallery")
            .args(&args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{args:?}");
        assert!(stderr.contains("lucent: error:"), "{args:?}: {stderr}");
    }
}
