//! Deforming objects (lavapipe, validation on): `dynamic` deforms between two instants, a
//! renderer updated to a new time draws what a renderer built at that time draws (each frame
//! uploads its own vertices, nothing is precomputed), the shadows follow, every slot of frames
//! in flight holds its own instant, and the benchmark times the deformation.

use lucent::bake::scene::load_scene_baked;
use lucent::frame::{FrameSettings, Renderer};
use lucent::scene::Scene;

use crate::common::{run_bench, submit_back_to_back, TestGpu};

const W: u32 = 160;
const H: u32 = 120;

fn dynamic_at(time: f32) -> Scene {
    let mut scene = load_scene_baked("dynamic").unwrap();
    scene.time = time;
    scene
}

fn changed_pixels(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
        .count()
}

#[test]
fn dynamic_deforms_and_an_updated_renderer_draws_the_new_instant() {
    let test = TestGpu::new();
    let settings = FrameSettings::new(W, H);
    let (t0, t1) = (dynamic_at(0.0), dynamic_at(0.5));
    let at_0 = test.render(&t0, settings).display;
    let at_half = test.render(&t1, settings).display;
    let changed = changed_pixels(&at_0, &at_half);
    println!(
        "dynamic: {changed} of {} pixels change from t = 0 to t = 0.5",
        W * H
    );
    assert!(changed > (W * H / 50) as usize, "{changed} pixels changed");

    // Built at t = 0, updated to t = 0.5: the same image as built at t = 0.5 (the frame
    // deforms and uploads on update; no precomputation depends on the first instant).
    let renderer = Renderer::new(&test.gpu, &test.shaders, &test.cache, &t0, settings).unwrap();
    let mut renderer = renderer;
    renderer.update(&t1).unwrap();
    let updated = renderer.render_once(&test.gpu).unwrap().display;
    test.gpu.wait_idle().unwrap();
    renderer.destroy(&test.gpu);
    assert_eq!(changed_pixels(&updated, &at_half), 0);

    // A static scene's time changes nothing.
    let mut smoke = load_scene_baked("smoke").unwrap();
    let a = test.render(&smoke, settings).display;
    smoke.time = 3.0;
    assert_eq!(test.render(&smoke, settings).display, a);
    test.finish();
}

/// Records and submits one frame of `slot` and waits for it.
fn run_slot(test: &TestGpu, renderer: &Renderer, slot: usize) {
    submit_back_to_back(&test.gpu, 1, |_, cmd| {
        renderer.record(&test.gpu, cmd, slot, None).unwrap()
    });
}

#[test]
fn each_frame_in_flight_draws_its_own_instant() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let settings = FrameSettings {
        frames_in_flight: 2,
        ..FrameSettings::new(W, H)
    };
    let reference = |t: f32| {
        test.render(&dynamic_at(t), FrameSettings::new(W, H))
            .display
    };
    let (want_0, want_half) = (reference(0.0), reference(0.5));
    let renderer =
        Renderer::new(gpu, &test.shaders, &test.cache, &dynamic_at(0.0), settings).unwrap();
    // Both slots written before either frame runs: slot 1 holds t = 0.5 while slot 0 keeps
    // t = 0, so each slot's frame must read its own vertices.
    renderer.update_slot(&dynamic_at(0.5), 1).unwrap();
    for (slot, want) in [(0usize, &want_0), (1, &want_half)] {
        run_slot(&test, &renderer, slot);
        let got = renderer.read_display(gpu).unwrap();
        assert_eq!(changed_pixels(&got, want), 0, "slot {slot}");
    }
    gpu.wait_idle().unwrap();
    renderer.destroy(gpu);
    test.finish();
}

#[test]
fn the_benchmark_times_the_deformation_of_deforming_scenes_only() {
    let json = |scene: &str| {
        let out = run_bench(&format!(
            "bench --scene {scene} --size 96x64 --frames 3 --warmup 1 --format json"
        ));
        serde_json::from_str::<serde_json::Value>(&out).unwrap()
    };
    let dynamic = json("dynamic");
    let d = &dynamic["deformation_ms"];
    assert!(d["median"].as_f64().is_some_and(|m| m > 0.0), "{dynamic}");
    let smoke = json("smoke");
    assert!(smoke["deformation_ms"].is_null(), "{smoke}");
}
