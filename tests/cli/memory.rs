//! Host memory a texture costs while loading, measured on the `lucent` process itself: its
//! peak resident set (its own `VmHWM`, so tests running beside it do not count), rendering a
//! scene with a large normal map against the same scene without it.
//!
//! The loader's promise (src/scene/upload.rs): about twice the texture's decoded size plus
//! mips. On lavapipe the GPU image is host memory too, so the difference is the whole cost: the
//! staging buffer and the image (each the decoded RGBA8 size plus mips), with the decoded file
//! gone before the image exists. The earlier loader, with `f32` texels and mips, took 10x.

use std::path::Path;
use std::process::{Command, Stdio};

use lucent::scene::upload::{level_bytes, UploadLayout};

use crate::common;

/// Runs `command` to the end and returns its peak resident set in bytes; fails the test,
/// showing its stderr, unless it succeeded.
///
/// The peak is the child's own `VmHWM` (`/proc/PID/status`), read every millisecond while it
/// runs: a high-water mark, so any read after the peak sees it. Not `ru_maxrss` from `wait4`:
/// Linux carries the forking process's high-water mark across `exec` into it, and this test
/// binary, with the other CLI tests running in it, can be larger than the child.
fn peak_resident_bytes(command: &mut Command, stderr_file: &Path) -> u64 {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(stderr_file).unwrap())
        .spawn()
        .expect("lucent runs");
    let status_file = format!("/proc/{}/status", child.id());
    let mut peak_kib = 0u64;
    let status = loop {
        // A zombie's status has no VmHWM line: nothing read then, the peak was read before.
        if let Ok(text) = std::fs::read_to_string(&status_file) {
            let hwm = text
                .lines()
                .find_map(|line| line.strip_prefix("VmHWM:"))
                .and_then(|rest| {
                    rest.trim()
                        .trim_end_matches("kB")
                        .trim()
                        .parse::<u64>()
                        .ok()
                });
            peak_kib = peak_kib.max(hwm.unwrap_or(0));
        }
        if let Some(status) = child.try_wait().expect("waitable") {
            break status;
        }
        std::thread::sleep(std::time::Duration::from_millis(1));
    };
    assert!(
        status.success(),
        "{command:?} failed ({status}): {}",
        std::fs::read_to_string(stderr_file).unwrap_or_default()
    );
    assert!(peak_kib > 0, "no VmHWM read from {status_file}");
    peak_kib * 1024
}

/// A `size x size` RGB8 PNG normal map with some relief (so nothing about it is special),
/// written row by row.
fn write_normal_map(path: &Path, size: u32) {
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
    for y in 0..size {
        let row: Vec<u8> = (0..size)
            .flat_map(|x| {
                [
                    128 + ((x / 7 + y / 5) % 40) as u8,
                    128 + ((y / 3) % 50) as u8,
                    230,
                ]
            })
            .collect();
        std::io::Write::write_all(&mut writer, &row).unwrap();
    }
    writer.finish().unwrap();
}

#[test]
fn a_texture_costs_about_twice_its_decoded_size_while_loading() {
    let dir = common::temp_dir("memory-texture");
    let size = 4096;
    write_normal_map(&dir.join("normal.png"), size);
    let scene = |material: &str| {
        format!(
            "[camera]\neye = [0.0, 3.0, 2.0]\ntarget = [0.0, 0.0, 0.0]\n\
             [[mesh]]\nname = \"quad\"\ngenerator = \"plane\"\n\
             [[material]]\nname = \"m\"\n{material}\n\
             [[object]]\nmesh = \"quad\"\nmaterial = \"m\"\n\
             [[light]]\ntype = \"directional\"\ndirection = [0.0, -1.0, 0.0]\nintensity = 1.0\n"
        )
    };
    std::fs::write(
        dir.join("textured.toml"),
        scene("normal_texture = \"normal.png\""),
    )
    .unwrap();
    std::fs::write(dir.join("plain.toml"), scene("")).unwrap();
    let peak = |name: &str| {
        peak_resident_bytes(
            common::lucent_command().current_dir(&dir).args([
                "render",
                "--scene",
                &format!("{name}.toml"),
                "--size",
                "64x48",
                "--out",
                &format!("{name}.png"),
            ]),
            &dir.join(format!("{name}.stderr")),
        )
    };
    let plain = peak("plain");
    let textured = peak("textured");
    let cost = textured.saturating_sub(plain) as f64;
    // The decoded size plus mips: RGBA8 (what an RGB file becomes on the GPU), 85.3 MiB.
    let decoded: u64 = level_bytes(size, size, UploadLayout::Unorm8).iter().sum();
    let ratio = cost / decoded as f64;
    eprintln!(
        "peak resident: {:.1} MiB without the map, {:.1} MiB with it: {ratio:.2}x its decoded \
         RGBA8 size with mips ({:.1} MiB)",
        plain as f64 / 1048576.0,
        textured as f64 / 1048576.0,
        decoded as f64 / 1048576.0
    );
    // At least the GPU image itself: the measurement sees the texture (a bound that a
    // texture never loaded would pass is no bound).
    assert!(
        ratio >= 0.75,
        "the texture cost only {ratio:.2}x its size: not loaded?"
    );
    // Twice, with room for the allocator's and the driver's slack (the earlier loader: 10x).
    assert!(
        ratio <= 2.5,
        "loading a {size}x{size} normal map cost {ratio:.2}x its decoded size with mips \
         (at most 2.5x)"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
