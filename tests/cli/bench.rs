//! `lucent bench` output formats and the speed-of-light table, through the command line (with
//! the validation layer on: any validation error fails the command and so the test).

use crate::common;

use crate::common::{run_bench, TestGpu};
use lucent::frame::{FrameSettings, Renderer, Technique};
use lucent::measure::speed_of_light::{floors, FloorFrame};

/// A validated bench of `cubes` under translucency, with `extra` arguments.
fn bench_args(extra: &str) -> String {
    format!(
        "bench --validation --scene cubes --technique translucency --size 128x96 --frames 3 \
         --warmup 1 {extra}"
    )
}

#[test]
fn csv_has_a_row_per_pass_with_its_speed_of_light_ratio() {
    let csv = run_bench(&bench_args("--speed-of-light --format csv"));
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header line").split(',').collect();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("no column {name} in {header:?}"))
    };
    let (pass, ratio, taps, median) = (
        column("pass"),
        column("pass_per_floor"),
        column("taps"),
        column("median_ms"),
    );
    // The device name holds a comma and is quoted: split on commas outside quotes.
    let split = |line: &str| -> Vec<String> {
        let (mut fields, mut field, mut quoted) = (Vec::new(), String::new(), false);
        for c in line.chars() {
            match c {
                '"' => quoted = !quoted,
                ',' if !quoted => fields.push(std::mem::take(&mut field)),
                _ => field.push(c),
            }
        }
        fields.push(field);
        fields
    };
    let rows: Vec<Vec<String>> = lines.map(split).collect();
    let names: Vec<&str> = rows.iter().map(|r| r[pass].as_str()).collect();
    assert_eq!(
        names,
        ["light-space maps", "gbuffer + lighting", "tonemap", "frame"],
        "{csv}"
    );
    for r in &rows {
        assert_eq!(r.len(), header.len(), "{r:?}");
        assert!(r[median].parse::<f64>().is_ok_and(|v| v > 0.0), "{r:?}");
        if r[pass] != "frame" {
            let x: f64 = r[ratio].parse().unwrap_or_else(|_| panic!("ratio: {r:?}"));
            assert!(x.is_finite() && x > 0.0, "{r:?}");
            // The light-space maps read no image: no taps.
            let min_taps = u32::from(r[pass] != "light-space maps");
            assert!(r[taps].parse::<u32>().is_ok_and(|t| t >= min_taps), "{r:?}");
        }
    }
}

#[test]
fn json_on_stdout_carries_the_speed_of_light_rows() {
    let json = run_bench(&bench_args("--speed-of-light --format json"));
    let v: serde_json::Value =
        serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}: {json}"));
    let passes = v["passes"].as_array().unwrap();
    let floors = v["speed_of_light"].as_array().unwrap();
    assert_eq!(passes.len(), floors.len(), "{v}");
    for (p, f) in passes.iter().zip(floors) {
        assert_eq!(p["name"], f["pass"]);
        assert!(f["floor_ms"].as_f64().is_some_and(|c| c > 0.0), "{f}");
        let ratio = f["ratio"].as_f64().unwrap();
        assert!(
            (ratio - p["median_ms"].as_f64().unwrap() / f["floor_ms"].as_f64().unwrap()).abs()
                < 1e-9,
            "{f}"
        );
        assert!(f["io"].as_str().unwrap().contains("->"), "{f}");
    }
    // The deferred group writes the G-buffer with GB2 (translucency) and depth.
    assert!(
        floors[0]["io"].as_str().unwrap().contains("D32"),
        "{}",
        floors[0]
    );
}

#[test]
fn markdown_names_the_passes_far_above_their_floor_and_the_seeds_alias_works() {
    let text = run_bench(
        "bench --validation --scene skin --technique control --size 96x64 --frames 2 --warmup 1 \
         --speed-of-light --compare-seeds",
    );
    assert!(text.contains("### Speed of light"), "{text}");
    assert!(
        text.contains("Far above their floor") || text.contains("No pass is more than"),
        "{text}"
    );
    assert!(text.contains("Table 2 (control)"), "{text}");
}

#[test]
fn a_layered_bench_prints_li_et_al_s_nearest_row_and_other_scenes_refuse() {
    let bench = |scene: &str, technique: &str, maps: &str| {
        run_bench(&format!(
            "bench --validation --scene {scene} --technique {technique} --size 96x64 \
             --shadow-size {maps} --frames 2 --warmup 1 --compare-seeds"
        ))
    };
    for (technique, maps) in [("auto", "512"), ("layered", "1024")] {
        let text = bench("scaling:2900", technique, maps);
        assert!(
            text.contains("Beside Li et al.'s Table 1 (the row nearest"),
            "{text}"
        );
        assert!(
            text.contains("row `deformed frog`, 2900 triangles"),
            "{text}"
        );
        assert!(
            text.contains("| theirs | 2900 | 512 | 231 | 4.33 |"),
            "{text}"
        );
        assert!(
            text.contains("| theirs | 2900 | 1024 | 71 | 14.08 |"),
            "{text}"
        );
        let ours = text
            .lines()
            .find(|l| l.starts_with("| ours | "))
            .unwrap_or_else(|| panic!("{text}"));
        let cells: Vec<&str> = ours.trim_matches('|').split('|').map(str::trim).collect();
        assert_eq!(cells[2], maps, "{ours}");
        for c in [3, 4, 5] {
            let v: f64 = cells[c].parse().unwrap_or_else(|_| panic!("{ours}"));
            assert!(v.is_finite() && v > 0.0, "{ours}");
        }
        assert!(text.contains("`single scattering"), "{text}");
    }
    // auto on a scene without layered materials: one clear error line.
    let out = common::lucent(&common::words(
        "bench --scene smoke --size 64x48 --frames 1 --compare-seeds",
    ));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(stderr.contains("has no layered material"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn packed_lbb_bench_with_its_copies_is_validation_clean() {
    // The issue-12 case: the packed RGBA32UI target's copy read it as float (88 errors).
    let text = run_bench(
        "bench --validation --scene skin --technique lbb --sss-packed --speed-of-light \
         --size 64x48 --frames 2 --warmup 1",
    );
    assert!(
        text.is_empty() || text.contains("RGBA32UI"),
        "the packed target is not in the table:\n{text}"
    );
}

#[test]
fn bad_formats_and_format_conflicts_are_one_line_errors() {
    for args in [
        vec!["bench", "--format", "xml"],
        vec![
            "bench",
            "--format",
            "csv",
            "--technique",
            "control",
            "--compare-thesis",
        ],
    ] {
        let out = common::lucent(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}");
        let lines = common::error_lines(&out);
        assert_eq!(lines.len(), 1, "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
}

#[test]
fn every_technique_s_copies_run_clean_under_validation_and_time_every_pass() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    // Every technique, and LBB once more with its packed RGBA32UI ping-pong target (whose copy
    // must read and write integers: a float read of it is a validation error).
    let cases = common::techniques()
        .into_iter()
        .map(|technique| (technique.name(), technique, false))
        .chain([(
            "lbb --sss-packed",
            Technique::Only(&lucent::features::sss::lbb::LBB),
            true,
        )]);
    for (name, technique, packed) in cases {
        let scene_name = lucent::report::scene_for(technique).unwrap();
        let scene = lucent::bake::scene::load_scene_baked(&scene_name).unwrap();
        let mut settings = FrameSettings {
            technique,
            ..FrameSettings::new(96, 64)
        };
        settings.sss.packed = packed;
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let plan = &renderer.executable.plan;
        assert_eq!(floors(plan).len(), plan.physical.len());
        let mut copies =
            FloorFrame::for_renderer(gpu, &test.shaders, &test.cache, &renderer).unwrap();
        copies.measure(gpu, false).unwrap();
        copies.measure(gpu, true).unwrap();
        let medians = copies.medians();
        gpu.wait_idle().unwrap();
        copies.destroy(gpu);
        renderer.destroy(gpu);
        assert_eq!(
            medians.len(),
            common::plan(&scene, &settings).physical.len(),
            "{name}"
        );
        for (i, m) in medians.iter().enumerate() {
            let m = m.unwrap_or_else(|| panic!("{name} on {scene_name}: floor {i} has no copy"));
            assert!(m.median > 0.0, "{name}: floor {i} took {m:?}");
        }
    }
    test.finish();
}

/// Copies the repository's `glsl/` into `to`, file by file.
fn copy_tree(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_tree(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

#[test]
fn shaders_dir_compiles_an_edited_tree_at_run_time_and_a_bad_one_is_refused() {
    use lucent::images::output::read_png_rgba8;
    let dir = common::temp_dir("shaders-flag");
    let tree = dir.join("glsl");
    copy_tree(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"),
        &tree,
    );
    // The edit: the tonemap reads no light, so every pixel of the picture is black.
    let tonemap = tree.join("post/tonemap.frag");
    let source = std::fs::read_to_string(&tonemap).unwrap();
    let light = "vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * frame.exposure.x;";
    assert!(
        source.contains(light),
        "the tonemap's first line changed: update this test"
    );
    std::fs::write(&tonemap, source.replace(light, "vec3 c = vec3(0.0);")).unwrap();
    let brightest = |png: &std::path::Path| {
        let (_, _, rgba) = read_png_rgba8(png).unwrap();
        rgba.chunks(4)
            .map(|p| p[0].max(p[1]).max(p[2]))
            .max()
            .unwrap()
    };
    let render = |png: &std::path::Path, extra: &[&str]| {
        let mut args = vec![
            "render",
            "--validation",
            "--scene",
            "smoke",
            "--size",
            "64x48",
        ];
        args.extend_from_slice(&["--out", png.to_str().unwrap()]);
        args.extend_from_slice(extra);
        let out = common::lucent(&args);
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    };
    let shipped = dir.join("shipped.png");
    render(&shipped, &[]);
    assert!(brightest(&shipped) > 64, "the shipped frame is lit");
    let edited = dir.join("edited.png");
    render(&edited, &["--shaders", tree.to_str().unwrap()]);
    assert_eq!(brightest(&edited), 0, "the edited tonemap's frame is black");

    let out = common::lucent(&[
        "render",
        "--scene",
        "smoke",
        "--shaders",
        dir.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("not a shader tree"),
        "{stderr}"
    );
}

#[test]
fn the_gate_refuses_the_flags_it_sets_itself_naming_them() {
    // --gate sets every benchmark's flags: a frame flag given with it is refused by name,
    // before any GPU work (exit 2, clap's convention), not silently ignored.
    let out = common::lucent(&["bench", "--gate", "--scene", "skin", "--frames", "5"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("--gate") && stderr.contains("--scene") && stderr.contains("--frames"),
        "{stderr}"
    );
    // --gate-baseline measures the gate's tables: it needs --gate, and the message says so.
    let out = common::lucent(&["bench", "--gate-baseline", "3"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("not provided: --gate"), "{stderr}");
    // Out of range.
    let out = common::lucent(&["bench", "--gate", "--gate-baseline", "1"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn embed_times_each_kind_of_effect_under_validation() {
    // The SH environment (--technique none), GDC 2011 translucency, an SSS blur, SSS
    // transmission and Li et al.'s layered media, each as a host's effect against lucent's own
    // frame: a table with both columns filled; the lighting terms also in a host's own
    // lighting pass.
    for (scene, technique, effect, row) in [
        ("cubes", "none", "EnvironmentEffect", "| the term |"),
        (
            "cubes",
            "translucency",
            "TranslucencyEffect",
            "| the term |",
        ),
        ("skin", "separable", "SssEffect", "| horizontal blur |"),
        // A LEAN blur: the LEAN targets made from the host's normals, then lucent's passes.
        ("skin", "lbb", "SssEffect", "| final lighting |"),
        // A medium back-lit by a shadowed light: its transmission is timed too.
        (
            "tools/truth/scenes/skin1-slab-backlit.toml",
            "separable",
            "SssEffect",
            "| transmission: the term |",
        ),
        // Its light-space maps drawn from host vertex buffers, then the four layered passes.
        (
            "layered",
            "layered",
            "LayeredEffect",
            "| single scattering |",
        ),
    ] {
        let text = run_bench(&format!(
            "bench --validation --scene {scene} --technique {technique} --size 96x64 \
             --frames 2 --warmup 1 --embed"
        ));
        assert!(
            text.contains("The effect in a host's frame against lucent's own")
                && text.contains(effect),
            "{technique}: {text}"
        );
        // And what the effect holds in memory.
        assert!(
            text.contains(&format!("{effect} holds ")) && text.contains("KiB of per-frame"),
            "{technique}: {text}"
        );
        let line = text
            .lines()
            .find(|l| l.starts_with(row))
            .unwrap_or_else(|| panic!("{technique}: no row {row}: {text}"));
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        assert!(
            cells[2].parse::<f64>().is_ok() && cells[3].parse::<f64>().is_ok_and(|v| v > 0.0),
            "{technique}: {line}"
        );
        // A lighting term is also timed inside a host's own lighting pass through TERMS: the
        // host's lighting with and without it, both run, and the term they differ by beside
        // lucent's (a difference of two medians: it may come out negative on a tiny frame).
        if row.ends_with("the term |") {
            let prefix = row.trim_end_matches("the term |");
            for (name, positive) in [
                ("host's lighting (TERMS), without the term", true),
                ("host's lighting (TERMS), with the term", true),
                ("the term in the host's lighting (TERMS)", false),
            ] {
                let line = text
                    .lines()
                    .find(|l| l.starts_with(&format!("{prefix}{name} |")))
                    .unwrap_or_else(|| panic!("{technique}: no row {name}: {text}"));
                let host: f64 = line
                    .split('|')
                    .map(str::trim)
                    .nth(3)
                    .unwrap()
                    .parse()
                    .unwrap();
                assert!(
                    host.is_finite() && (!positive || host > 0.0),
                    "{technique}: {line}"
                );
            }
        }
    }
    // A technique no host can insert is refused, naming those that can.
    let out = common::lucent(&common::words(
        "bench --scene skin --technique auto --size 96x64 --frames 2 --embed",
    ));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("layered or none (the SH environment)"),
        "{stderr}"
    );
}
