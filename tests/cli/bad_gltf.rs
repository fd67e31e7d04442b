//! Hostile glTF assets: each fails with an error naming the file and the problem, never a
//! panic, never an unbounded read or allocation. The files are written here, tiny, by
//! `tests/common/gltf.rs`; each case says the text its error must contain. The library's
//! error is checked for every case, and `lucent render --scene` for a few (one
//! `lucent: error:` line, before any device is opened).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use serde_json::json;

use crate::common;
use crate::gltf_file::{base64, triangle, GltfBuilder};

/// Writes `name` with `bytes` in `dir`; returns its path.
fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Loads `path` as a scene and returns its error, checking it names the file and contains
/// every one of `expected`, in under a few seconds (nothing reads forever).
fn fails_with(path: &Path, expected: &[&str]) -> String {
    let started = Instant::now();
    let result = std::panic::catch_unwind(|| lucent::scene::load_scene(&path.to_string_lossy()));
    let error = match result {
        Err(_) => panic!("{}: the loader panicked", path.display()),
        Ok(Ok(_)) => panic!(
            "{}: loaded, expected an error with {expected:?}",
            path.display()
        ),
        Ok(Err(e)) => e.to_string(),
    };
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "{}: took {:?}",
        path.display(),
        started.elapsed()
    );
    let file = path.file_name().unwrap().to_string_lossy();
    assert!(error.contains(&*file), "{error}\n(does not name {file})");
    for e in expected {
        assert!(error.contains(e), "{error}\n(does not contain {e:?})");
    }
    println!("{error}");
    error
}

/// The triangle asset with `edit` applied to its JSON, written as `name` (a `.glb`).
fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut GltfBuilder)) -> PathBuf {
    let mut b = triangle();
    edit(&mut b);
    write(dir, name, &b.glb())
}

#[test]
fn hostile_gltf_files_fail_with_errors_naming_the_file_and_the_problem() {
    let dir = common::temp_dir("bad-gltf");
    // (file, the edit, what the error must say)
    type Edit = Box<dyn FnOnce(&mut GltfBuilder)>;
    let cases: Vec<(&str, Edit, &[&str])> = vec![
        (
            "index_out_of_range.glb",
            Box::new(|b| {
                let i = b.indices(&[0, 1, 99]);
                b.json["meshes"][0]["primitives"][0]["indices"] = json!(i);
            }),
            &["index 99", "out of range for 3 vertices"],
        ),
        (
            "accessor_index_out_of_range.glb",
            Box::new(|b| {
                b.json["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = json!(42)
            }),
            &["invalid glTF", "meshes[0].primitives[0].attributes"],
        ),
        (
            "accessor_past_its_view.glb",
            Box::new(|b| b.json["accessors"][0]["count"] = json!(300)),
            &["accessors[0]", "runs past the end of bufferViews[0]"],
        ),
        (
            "view_past_its_buffer.glb",
            Box::new(|b| b.json["bufferViews"][1]["byteLength"] = json!(4000)),
            &["bufferViews[1]", "runs past the end of buffers[0]"],
        ),
        (
            "overlapping_stride.glb",
            Box::new(|b| b.json["bufferViews"][0]["byteStride"] = json!(4)),
            &["byteStride 4", "overlap"],
        ),
        (
            "count_2_to_the_32.glb",
            Box::new(|b| b.json["accessors"][0]["count"] = json!(4294967296u64)),
            &["accessors[0]", "count 4294967296"],
        ),
        (
            "lines.glb",
            Box::new(|b| b.json["meshes"][0]["primitives"][0]["mode"] = json!(1)),
            &["meshes[0].primitives[0]", "mode LINES"],
        ),
        (
            "triangle_strip.glb",
            Box::new(|b| b.json["meshes"][0]["primitives"][0]["mode"] = json!(5)),
            &["mode TRIANGLE_STRIP"],
        ),
        (
            "cyclic_nodes.glb",
            Box::new(|b| {
                let child = b.push("nodes", json!({"children": [0]}));
                b.json["nodes"][0]["children"] = json!([child]);
            }),
            &["cycle"],
        ),
        (
            "two_parents.glb",
            Box::new(|b| {
                let a = b.push("nodes", json!({"children": [0]}));
                let c = b.push("nodes", json!({"children": [0]}));
                b.json["scenes"][0]["nodes"] = json!([a, c]);
            }),
            &["nodes[0]", "child of both"],
        ),
        (
            "infinite_translation.glb",
            Box::new(|b| b.json["nodes"][0]["translation"] = json!([1e39, 0, 0])),
            &["nodes[0]", "translation", "not finite"],
        ),
        (
            "infinite_matrix.glb",
            Box::new(|b| {
                let mut m = vec![json!(0.0); 16];
                m[0] = json!(1e39);
                b.json["nodes"][0]["matrix"] = json!(m);
            }),
            &["nodes[0]", "matrix", "not finite"],
        ),
        (
            "overflowing_hierarchy.glb",
            Box::new(|b| {
                // Each scale is finite; their product is not (NaN or infinity downstream).
                let parent = b.push(
                    "nodes",
                    json!({"scale": [1e30, 1e30, 1e30], "children": [0]}),
                );
                b.json["nodes"][0]["scale"] = json!([1e30, 1e30, 1e30]);
                b.json["scenes"][0]["nodes"] = json!([parent]);
            }),
            &["nodes[0]", "not finite"],
        ),
        (
            "required_extension.glb",
            Box::new(|b| {
                b.json["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
                b.json["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
            }),
            &["KHR_draco_mesh_compression", "does not implement"],
        ),
        (
            "texture_not_an_image.glb",
            Box::new(|b| {
                let uri = format!("data:image/png;base64,{}", base64(b"this is not a PNG"));
                b.push("images", json!({"uri": uri}));
                b.push("textures", json!({"source": 0}));
                b.push(
                    "materials",
                    json!({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}),
                );
                b.json["meshes"][0]["primitives"][0]["material"] = json!(0);
                let t = b.floats(&[0.0; 6], "VEC2", 2);
                b.json["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = json!(t);
            }),
            &["images[0]", "not an image"],
        ),
        (
            "version_1.glb",
            Box::new(|b| b.json["asset"]["version"] = json!("1.0")),
            &["asset.version", "2.x"],
        ),
    ];
    for (name, edit, expected) in cases {
        let path = edited(&dir, name, edit);
        fails_with(&path, expected);
    }

    // A truncated .glb, cut anywhere: never a panic, always "truncated" or a JSON error.
    let glb = triangle().glb();
    for cut in [0, 3, 11, 12, 19, 20, 40, glb.len() - 1] {
        let path = write(&dir, &format!("truncated_{cut}.glb"), &glb[..cut]);
        let e = std::panic::catch_unwind(|| lucent::scene::load_scene(&path.to_string_lossy()))
            .unwrap_or_else(|_| panic!("truncated at {cut}: panicked"))
            .err()
            .unwrap_or_else(|| panic!("truncated at {cut}: loaded"))
            .to_string();
        assert!(
            e.contains("truncated") || e.contains("empty") || e.contains("JSON"),
            "cut at {cut}: {e}"
        );
    }
    let mut short = glb.clone();
    short[8..12].copy_from_slice(&4u32.to_le_bytes()); // a header shorter than itself
    fails_with(
        &write(&dir, "header_length_4.glb", &short),
        &["truncated GLB", "12-byte header"],
    );
    let mut long = glb;
    long[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    fails_with(
        &write(&dir, "header_length_huge.glb", &long),
        &["truncated GLB", "4294967295"],
    );
    fails_with(
        &write(&dir, "not_json.gltf", b"{\"asset\": "),
        &["not valid glTF JSON"],
    );
}

#[test]
fn hostile_gltf_uris_are_refused() {
    let dir = common::temp_dir("bad-gltf-uris");
    let b = triangle();
    let with_uri = |name: &str, uri: &str| write(&dir, name, b.gltf_external(uri).as_bytes());
    fails_with(
        &with_uri("missing.gltf", "missing.bin"),
        &["buffers[0]", "missing.bin", "not found"],
    );
    std::fs::create_dir_all(dir.join("folder.bin")).unwrap();
    fails_with(
        &with_uri("folder.gltf", "folder.bin"),
        &["buffers[0]", "folder.bin", "directory"],
    );
    fails_with(
        &with_uri("escape.gltf", "../escape.bin"),
        &["outside the asset's folder"],
    );
    fails_with(
        &with_uri("absolute.gltf", "/etc/hostname"),
        &["absolute path"],
    );
    fails_with(
        &with_uri("scheme.gltf", "https://example.com/a.bin"),
        &["https: scheme"],
    );
    fails_with(
        &with_uri("not_base64.gltf", "data:application/octet-stream,abc"),
        &["not base64"],
    );
    fails_with(
        &with_uri(
            "bad_base64.gltf",
            "data:application/octet-stream;base64,@@@@",
        ),
        &["is not base64"],
    );
    // A FIFO beside the asset: refused at once, never read (it would block).
    let made = Command::new("mkfifo")
        .arg(dir.join("fifo.bin"))
        .status()
        .unwrap();
    assert!(made.success());
    fails_with(&with_uri("fifo.gltf", "fifo.bin"), &["fifo.bin", "FIFO"]);
    // A link beside the asset to a device: it leads out of the folder, to the device.
    std::os::unix::fs::symlink("/dev/zero", dir.join("zero.bin")).unwrap();
    fails_with(
        &with_uri("device.gltf", "zero.bin"),
        &["zero.bin", "/dev/zero"],
    );
    // A buffer shorter than it says.
    write(&dir, "short.bin", &b.bin[..8]);
    fails_with(
        &with_uri("short.gltf", "short.bin"),
        &["buffers[0]", "byteLength"],
    );
    // And the real one loads.
    write(&dir, "ok.bin", &b.bin);
    lucent::scene::load_scene(&with_uri("ok.gltf", "ok.bin").to_string_lossy()).unwrap();
}

#[test]
fn lucent_render_refuses_a_hostile_glb_in_one_line() {
    let dir = common::temp_dir("bad-gltf-cli");
    let path = edited(&dir, "cyclic.glb", |b| {
        let child = b.push("nodes", json!({"children": [0]}));
        b.json["nodes"][0]["children"] = json!([child]);
    });
    let out = common::output_within(
        common::lucent_command()
            .arg("render")
            .arg("--scene")
            .arg(&path)
            .arg("--out")
            .arg(dir.join("out.png")),
        Duration::from_secs(60),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let errors = common::error_lines(&out);
    assert_eq!(errors.len(), 1, "{stderr}");
    assert!(
        errors[0].contains("cyclic.glb") && errors[0].contains("cycle"),
        "{stderr}"
    );
}
