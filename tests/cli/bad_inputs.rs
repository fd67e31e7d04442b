//! The malformed-input corpus: every file in `tests/data/bad/` must fail cleanly.
//!
//! The expectations live in `tests/data/bad/README.md` (one table row per file: the file, its
//! problem, and the substrings its error must contain), so the corpus documents itself and a
//! new file only needs a new row. Two checks run over the same table:
//!
//! - the real one: `lucent inspect FILE` exits non-zero with exactly one `lucent: error:` line
//!   on stderr that names the file and contains the substrings, and nothing panicked;
//! - in-process: `lucent::frame::inspect::inspect_file` returns the same error (and does not
//!   panic), so a failure points at the loader rather than the command line.
//!
//! The README's second table lists files that load with a repair or a warning: `inspect` must
//! succeed and print the note. Cases that cannot be committed as files are made at run time:
//! FIFOs, devices and directories where files are expected (each must fail at once, never
//! block or read forever), a 16384x16384 normal map (refused from its header in under a
//! second), command lines with absurd counts or misplaced knobs (one `lucent: error:` line, or a
//! warning naming the technique they need), a bake whose UVs cover no texel, a demo script with
//! a bad key.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use crate::common;

/// One row of the README's tables.
struct Case {
    file: String,
    expected: Vec<String>,
}

fn corpus_dir() -> PathBuf {
    common::data("bad")
}

/// The texts between pairs of backticks.
fn backticked(cell: &str) -> Vec<String> {
    cell.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

/// The README's rows: files that must fail, files that must load with a note, helpers.
struct Readme {
    failing: Vec<Case>,
    loaded: Vec<Case>,
    helpers: Vec<String>,
}

/// The table rows and the helper files listed in the README (the failing table's rows for the
/// first two tests; see [`read_corpus`] for all of them).
fn read_readme() -> (Vec<Case>, Vec<String>) {
    let r = read_corpus();
    let mut helpers = r.helpers;
    helpers.extend(r.loaded.into_iter().map(|c| c.file));
    (r.failing, helpers)
}

fn read_corpus() -> Readme {
    let readme = std::fs::read_to_string(corpus_dir().join("README.md"))
        .expect("tests/data/bad/README.md is readable");
    let (mut cases, mut loaded, mut helpers) = (Vec::new(), Vec::new(), Vec::new());
    let (mut in_helpers, mut in_loaded) = (false, false);
    for line in readme.lines() {
        let line = line.trim();
        if line.starts_with("## ") {
            in_helpers = line.eq_ignore_ascii_case("## helpers");
            in_loaded = line.starts_with("## Loaded");
        } else if line.starts_with("| `") {
            let cells: Vec<&str> = line.trim_matches('|').split('|').collect();
            let file = backticked(cells[0]);
            let expected = backticked(cells[cells.len() - 1]);
            assert_eq!(file.len(), 1, "README row without one file name: {line}");
            assert!(
                !expected.is_empty(),
                "README row without a substring: {line}"
            );
            let case = Case {
                file: file[0].clone(),
                expected,
            };
            if in_loaded {
                loaded.push(case);
            } else {
                cases.push(case);
            }
        } else if in_helpers && line.starts_with("- `") {
            helpers.push(backticked(line)[0].clone());
        }
    }
    Readme {
        failing: cases,
        loaded,
        helpers,
    }
}

#[test]
fn readme_lists_every_corpus_file() {
    let (cases, helpers) = read_readme();
    assert!(cases.len() >= 33, "only {} cases", cases.len());
    assert!(read_corpus().loaded.len() >= 5);
    let listed: Vec<&str> = cases
        .iter()
        .map(|c| c.file.as_str())
        .chain(helpers.iter().map(String::as_str))
        .collect();
    for name in &listed {
        assert!(
            corpus_dir().join(name).is_file(),
            "README lists {name}, which is not in tests/data/bad/"
        );
        assert_eq!(
            listed.iter().filter(|n| *n == name).count(),
            1,
            "{name} is listed twice"
        );
    }
    for entry in std::fs::read_dir(corpus_dir()).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name == "README.md" || listed.contains(&name.as_str()),
            "tests/data/bad/{name} is not described in tests/data/bad/README.md"
        );
    }
}

/// What is wrong with `message` as the error for `case`, if anything.
fn check_message(case: &Case, message: &str) -> Option<String> {
    let missing: Vec<&String> = std::iter::once(&case.file)
        .chain(&case.expected)
        .filter(|s| !message.contains(s.as_str()))
        .collect();
    if message.contains("panicked") || message.contains("crashed") {
        return Some(format!("{}: a panic was reported: {message}", case.file));
    }
    (!missing.is_empty()).then(|| format!("{}: {missing:?} not in: {message}", case.file))
}

/// Runs `check` on every file of the README's first table (with its path); fails listing
/// every problem it reported.
fn each_corpus_file(check: impl Fn(&Case, &Path) -> Vec<String>) {
    let (cases, _) = read_readme();
    let failures: Vec<String> = cases
        .iter()
        .flat_map(|case| check(case, &corpus_dir().join(&case.file)))
        .collect();
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

#[test]
fn library_reports_each_problem() {
    each_corpus_file(|case, path| {
        let result = std::panic::catch_unwind(|| lucent::frame::inspect::inspect_file(path));
        match result {
            Err(_) => vec![format!("{}: inspect_file panicked", case.file)],
            Ok(Ok(summary)) => vec![format!("{}: accepted:\n{summary}", case.file)],
            Ok(Err(e)) => {
                // The message's first line is what `lucent: error:` prints on its line.
                let message = e.to_string();
                let first = message.lines().next().unwrap_or("");
                check_message(case, first).into_iter().collect()
            }
        }
    });
}

#[test]
fn cli_reports_each_problem() {
    each_corpus_file(|case, path| {
        let out = lucent_in(None, &["inspect", &path.to_string_lossy()]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        let errors = common::error_lines(&out);
        if out.status.success() {
            vec![format!("{}: exit status 0", case.file)]
        } else if stderr.contains("panicked") {
            vec![format!("{}: panicked:\n{stderr}", case.file)]
        } else if errors.len() != 1 {
            vec![format!(
                "{}: {} 'lucent: error:' lines in stderr:\n{stderr}",
                case.file,
                errors.len()
            )]
        } else {
            check_message(case, &errors[0]).into_iter().collect()
        }
    });
}

#[test]
fn repaired_files_load_and_say_what_was_repaired() {
    let mut failures = Vec::new();
    for case in &read_corpus().loaded {
        let path = corpus_dir().join(&case.file);
        if let Err(e) = lucent::frame::inspect::inspect_file(&path) {
            failures.push(format!("{}: inspect_file failed: {e}", case.file));
        }
        let out = lucent(&["inspect", &path.to_string_lossy()]);
        let text = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        if !out.status.success() {
            failures.push(format!(
                "{}: exit status {}:\n{text}",
                case.file, out.status
            ));
            continue;
        }
        let missing: Vec<&String> = case
            .expected
            .iter()
            .filter(|s| !text.contains(s.as_str()))
            .collect();
        if !missing.is_empty() {
            failures.push(format!("{}: {missing:?} not in:\n{text}", case.file));
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}

/// `lucent ARGS` in `dir` (or here), failing after a minute (a hang is a failure).
fn lucent_in(dir: Option<&Path>, args: &[&str]) -> Output {
    let mut command = common::lucent_command();
    command.args(args);
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    common::output_within(&mut command, Duration::from_secs(60))
}

fn lucent(args: &[&str]) -> Output {
    lucent_in(None, args)
}

/// The single `lucent: error:` line of a failed run (panics if there is not exactly one, the
/// run succeeded or anything panicked).
fn one_error_line(args: &[&str], out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded:\n{stderr}");
    assert!(!stderr.contains("panicked"), "{args:?} panicked:\n{stderr}");
    let errors = common::error_lines(out);
    assert_eq!(errors.len(), 1, "{args:?}: not one error line:\n{stderr}");
    let lines = stderr.lines().filter(|l| !l.trim().is_empty()).count();
    assert_eq!(
        lines, 1,
        "{args:?}: a command-line error is one line, not:\n{stderr}"
    );
    errors[0].clone()
}

const SCENE: &str = "[camera]\neye = [0, 1, 5]\ntarget = [0, 0, 0]\n\n[[mesh]]\nname = \"m\"\n\
                     MESH\n\n[[material]]\nname = \"a\"\nMATERIAL\n\n[[object]]\nmesh = \"m\"\n\
                     material = \"a\"\n";

fn scene_with(mesh: &str, material: &str) -> String {
    SCENE.replace("MESH", mesh).replace("MATERIAL", material)
}

#[cfg(unix)]
#[test]
fn devices_fifos_and_directories_are_refused_at_once() {
    let dir = common::temp_dir("bad-inputs-special");
    let fifo = |name: &str| {
        let path = dir.join(name);
        let made = Command::new("mkfifo")
            .arg(&path)
            .status()
            .expect("mkfifo runs");
        assert!(made.success(), "mkfifo {name}");
        path
    };
    fifo("fifo.obj");
    fifo("fifo.toml");
    fifo("fifo.png");
    fifo("fifo.mtl");
    for (name, target) in [("zero.obj", "/dev/zero"), ("zero.png", "/dev/zero")] {
        std::os::unix::fs::symlink(target, dir.join(name)).unwrap();
    }
    std::os::unix::fs::symlink(dir.join("fifo.toml"), dir.join("link.toml")).unwrap();
    std::fs::create_dir_all(dir.join("folder.obj")).unwrap();
    std::fs::write(
        dir.join("fifo_mesh.toml"),
        scene_with("obj = \"fifo.obj\"", "albedo = [1, 1, 1]"),
    )
    .unwrap();
    std::fs::write(
        dir.join("fifo_normal_map.toml"),
        scene_with("generator = \"sphere\"", "normal_texture = \"zero.png\""),
    )
    .unwrap();
    std::fs::write(
        dir.join("uses_fifo.obj"),
        "mtllib fifo.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let d = |name: &str| dir.join(name).to_string_lossy().into_owned();
    let fifo_says = "is a FIFO (named pipe), not a regular file";
    let zero_says = "is a symlink to /dev/zero, which is a character device, not a regular file";
    let inspect = |file: &str| vec!["inspect".to_string(), d(file)];
    let mut cases: Vec<(Vec<String>, Vec<&str>)> = Vec::new();
    for file in ["fifo.obj", "fifo.toml", "fifo.png", "fifo.mtl"] {
        cases.push((inspect(file), vec![file, fifo_says]));
    }
    for file in ["zero.obj", "zero.png"] {
        cases.push((inspect(file), vec![file, zero_says]));
    }
    cases.extend([
        (
            inspect("link.toml"),
            vec!["link.toml", "is a symlink to", "a FIFO (named pipe)"],
        ),
        (
            inspect("folder.obj"),
            vec!["folder.obj", "is a directory, not a regular file"],
        ),
        (
            inspect("uses_fifo.obj"),
            vec!["fifo.mtl", "mtllib on line 1", fifo_says],
        ),
        (inspect("fifo_mesh.toml"), vec!["fifo.obj", fifo_says]),
        (
            vec!["render".into(), "--scene".into(), d("fifo.toml")],
            vec!["fifo.toml", fifo_says],
        ),
        (
            vec!["render".into(), "--scene".into(), d("fifo_normal_map.toml")],
            vec!["zero.png", zero_says],
        ),
        (
            vec![
                "bake-thickness".into(),
                d("zero.obj"),
                "--per-vertex".into(),
                d("o.obj"),
            ],
            vec!["zero.obj", zero_says],
        ),
    ]);
    for (args, wanted) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let start = Instant::now();
        let line = one_error_line(&args, &lucent(&args));
        for w in wanted {
            assert!(line.contains(w), "{args:?}: '{w}' not in: {line}");
        }
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{args:?} took {:?}",
            start.elapsed()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Command lines with absurd counts, values out of range, misplaced arguments: each is one
/// `lucent: error:` line (exit code 2 for what the parser refuses) with the substrings, before
/// any GPU work.
#[test]
fn command_line_errors_are_one_line_with_the_fix() {
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["bench", "--frames", "18446744073709551615"],
            &["--frames", "from 1 to 100000", "lucent bench --help"],
        ),
        (&["bench", "--frames", "4294967295"], &["from 1 to 100000"]),
        (&["bench", "--frames", "0"], &["from 1 to 100000"]),
        (
            &["bench", "--warmup", "99999999"],
            &["--warmup", "from 0 to 10000"],
        ),
        (
            &["report", "--rounds", "4294967296"],
            &["--rounds", "from 1 to 100000"],
        ),
        (
            &["bench", "--sensitivity", "-1"],
            &["--sensitivity", "'-1' is not a finite number >= 0"],
        ),
        (&["render", "--sensitivity", "nan"], &["finite number"]),
        (
            &[
                "bake-thickness",
                "x.obj",
                "--size",
                "16384",
                "--out",
                "t.png",
            ],
            &["--size", "from 1 to 8192"],
        ),
        (
            &["bake-thickness", "x.obj", "--rays", "0"],
            &["--rays", "from 1 to 1048576"],
        ),
        (
            &["bake-thickness", "x.obj", "--max-distance", "-2"],
            &["--max-distance", "finite number > 0"],
        ),
        (
            &["render", "--sss-gaussians", "9"],
            &["--sss-gaussians", "from 1 to 8"],
        ),
        (&["render", "--size", "0x10"], &["between 1 and 16384"]),
        (&["render", "--sss-taps", "4"], &["not one of 3, 5, 7"]),
        (
            &["render", "--bogus"],
            &["unexpected argument '--bogus'", "lucent render --help"],
        ),
        (&["paint"], &["unrecognized subcommand 'paint'"]),
        (&[], &["no command given", "render", "bench"]),
        (&["bench", "--format", "xml"], &["xml"]),
    ];
    for &(args, wanted) in cases {
        let line = one_error_line(args, &lucent(args));
        for w in wanted {
            assert!(line.contains(w), "{args:?}: '{w}' not in: {line}");
        }
    }
    // Parser errors exit with 2, as clap's convention has it.
    assert_eq!(lucent(&["bench", "--frames", "0"]).status.code(), Some(2));
    // Help and version are not errors.
    let help = lucent(&["report", "--help"]);
    assert!(help.status.success());
    let help = String::from_utf8_lossy(&help.stdout).into_owned();
    assert!(help.contains("--quick"), "{help}");
}

#[test]
fn knobs_that_do_not_apply_warn_naming_the_technique_they_need() {
    // `lucent LINE` succeeds with one warning per entry of `wanted`, the k-th containing every
    // substring of `wanted[k]`.
    let warns = |line: &str, wanted: &[&[&str]]| {
        let args = common::words(line);
        let out = lucent(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{args:?}: {stderr}");
        let w: Vec<&str> = stderr
            .lines()
            .filter(|l| l.starts_with("lucent: warning:"))
            .collect();
        assert_eq!(w.len(), wanted.len(), "{line}: {w:?}");
        for (warning, parts) in w.iter().zip(wanted) {
            for part in *parts {
                assert!(warning.contains(part), "{line}: '{part}' not in {warning}");
            }
        }
    };
    warns(
        "plan --technique none --sss-taps 3 --sss-packed",
        &[
            &[
                "--sss-taps has no effect with --technique none",
                "--technique lbb",
            ],
            &["--sss-packed", "--technique lbb"],
        ],
    );
    warns(
        "plan --scene skin --technique control --sss-packed",
        &[&["--technique control", "lbb"]],
    );
    warns(
        "plan --technique translucency --sss-gaussians 2",
        &[&["control, lcb, lbb, separable or bilateral"]],
    );
    // The two-pass knobs name the blurs they apply to.
    warns(
        "plan --scene skin --technique lbb --sss-samples 25 --sss-half-res",
        &[
            &["--sss-samples", "--technique separable or bilateral"],
            &["--sss-half-res", "--technique separable"],
        ],
    );
    warns(
        "plan --scene skin --technique separable --sss-samples 25 --sss-half-res \
         --sss-filter bilinear --sss-kernel line",
        &[],
    );
    warns(
        "plan --technique none --grayscale",
        &[&["--technique translucency"]],
    );
    // Under auto the frame decides: skin's profile is blurred with the control, so the
    // bilateral knobs still do nothing.
    warns(
        "plan --scene skin --sss-packed",
        &[&["--technique auto on scene 'skin'", "lbb"]],
    );
    // Where they apply, no warning.
    warns(
        "plan --scene skin --technique lbb --sss-taps 3 --sss-packed --sensitivity 2",
        &[],
    );
}

/// Writes a `size` x `size` RGB8 PNG of the flat normal (128, 128, 255) row by row, so the test
/// never holds the image in memory.
fn write_flat_normal_map(path: &Path, size: u32) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut encoder = png::Encoder::new(file, size, size);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Fastest);
    let mut writer = encoder
        .write_header()
        .unwrap()
        .into_stream_writer()
        .unwrap();
    let row: Vec<u8> = (0..size).flat_map(|_| [128u8, 128, 255]).collect();
    for _ in 0..size {
        std::io::Write::write_all(&mut writer, &row).unwrap();
    }
    writer.finish().unwrap();
}

#[test]
fn a_16384_squared_normal_map_is_refused_from_its_header_in_under_a_second() {
    let dir = common::temp_dir("bad-inputs-huge-normal-map");
    let map = dir.join("normal16k.png");
    write_flat_normal_map(&map, 16384);
    // A real, decodable PNG of that size (not only a header).
    let (w, h) = image::ImageReader::open(&map)
        .unwrap()
        .into_dimensions()
        .unwrap();
    assert_eq!((w, h), (16384, 16384));
    std::fs::write(
        dir.join("scene.toml"),
        scene_with(
            "generator = \"sphere\"",
            "normal_texture = \"normal16k.png\"\ntranslucency = { thickness = 0.5 }",
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("thickness.toml"),
        scene_with(
            "generator = \"sphere\"",
            "translucency = { thickness = \"normal16k.png\" }",
        ),
    )
    .unwrap();
    let scene = dir.join("scene.toml").to_string_lossy().into_owned();
    let thickness = dir.join("thickness.toml").to_string_lossy().into_owned();
    let map_arg = map.to_string_lossy().into_owned();
    let runs: [&[&str]; 4] = [
        &["inspect", &map_arg],
        &[
            "render",
            "--scene",
            &scene,
            "--technique",
            "lbb",
            "--size",
            "64x48",
            "--out",
            "x.png",
        ],
        &[
            "render", "--scene", &scene, "--size", "64x48", "--out", "x.png",
        ],
        &[
            "render",
            "--scene",
            &thickness,
            "--technique",
            "translucency",
            "--size",
            "64x48",
        ],
    ];
    for args in runs {
        let start = Instant::now();
        let out = lucent_in(Some(&dir), args);
        let took = start.elapsed();
        let line = one_error_line(args, &out);
        assert!(
            line.contains("normal16k.png")
                && line.contains("16384x16384")
                && line.contains("8192x8192")
                && line.contains("of host memory"),
            "{args:?}: {line}"
        );
        assert!(took < Duration::from_secs(1), "{args:?} took {took:?}");
        eprintln!("{args:?}: refused in {took:?}: {line}");
    }
    assert!(!dir.join("x.png").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bake_whose_uvs_cover_no_texel_is_an_error_not_a_black_map() {
    let dir = common::temp_dir("bad-inputs-bake-no-texel");
    // A tetrahedron whose UVs all sit in a speck smaller than a texel.
    let obj = dir.join("speck.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0.3 0.3\nvt 0.30001 0.3\nvt 0.3 0.30001\n\
         f 1/1 3/3 2/2\nf 1/1 2/2 4/3\nf 1/1 4/3 3/2\nf 2/2 3/3 4/1\n",
    )
    .unwrap();
    let out_png = dir.join("t.png");
    let (obj, out_png_arg) = (obj.to_string_lossy(), out_png.to_string_lossy());
    let args = ["bake-thickness", &obj, "--out", &out_png_arg, "--rays", "8"];
    let line = one_error_line(&args, &lucent(&args));
    assert!(
        line.contains("cover no texel of the 512x512 map") && line.contains("--per-vertex"),
        "{line}"
    );
    assert!(!out_png.exists(), "a map was written");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[cfg(feature = "window")]
#[test]
fn a_bad_demo_script_fails_before_any_window_with_its_line() {
    let dir = common::temp_dir("bad-inputs-demo-script");
    let script = dir.join("bad.script");
    std::fs::write(&script, "# keys\n1 key F1\n2 key Hyperspace\n3 quit\n").unwrap();
    let args = ["demo", "--script", &script.to_string_lossy()];
    // No display: the script is read first, so its error comes before "cannot open a window".
    let line = one_error_line(&args, &lucent(&args));
    assert!(
        line.contains("bad.script") && line.contains("line 3: unknown key 'Hyperspace'"),
        "{line}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn docs_and_help_agree_with_the_binary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let format = std::fs::read_to_string(root.join("docs/scene-format.toml")).unwrap();
    let limit = format!("Lights (at most {})", lucent::scene::MAX_LIGHTS);
    assert!(
        format.contains(&limit),
        "docs/scene-format.toml does not say '{limit}'"
    );
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let help = String::from_utf8_lossy(&lucent(&["report", "--help"]).stdout).into_owned();
    let quick = "about 15 s";
    assert!(help.contains(quick), "report --help: {help}");
    let row = readme
        .lines()
        .find(|l| l.starts_with("| `lucent report [--out DIR] [--quick]`"))
        .unwrap();
    assert!(row.contains(&format!("`--quick` {quick}")), "{row}");
    // The light limit is the one the loader applies.
    let light = "[[light]]\ntype = \"point\"\nposition = [0, 2, 0]\nintensity = 1\n";
    let scene = |n: usize| {
        format!(
            "{}{}",
            scene_with("generator = \"sphere\"", ""),
            light.repeat(n)
        )
    };
    let path = Path::new("lights.toml");
    assert!(lucent::scene::file::parse_scene(path, &scene(lucent::scene::MAX_LIGHTS)).is_ok());
    let e = lucent::scene::file::parse_scene(path, &scene(lucent::scene::MAX_LIGHTS + 1))
        .unwrap_err()
        .to_string();
    assert!(e.contains("at most 64"), "{e}");
}
