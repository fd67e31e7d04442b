//! The harness the three test binaries share (each includes this file as `mod common`): a
//! validated device and the one way to render a frame on it, the golden comparison, the one way
//! to run the `lucent` binary, scratch and output folders, and the technique list every test
//! that loops over techniques iterates.
//!
//! The tests of one binary run in one process, two at a time: nothing here changes the
//! process's environment or directory, and every folder is named by its caller so that no two
//! tests share one.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use ash::vk;
use lucent::backend::shader::{PipelineCache, ShaderCompiler};
use lucent::backend::{ContextDesc, GpuContext};
use lucent::frame::{
    plan_frame, render_frame, FrameDesc, FrameImages, FrameRunner, FrameSettings, GBufferReadback,
    Renderer, Technique,
};
use lucent::graph::Plan;
use lucent::images::compare::{compare_with_golden, FlipThresholds};
use lucent::scene::Scene;

/// A device with the Khronos validation layer (synchronization validation included) on.
pub struct TestGpu {
    /// The context.
    pub gpu: GpuContext,
    /// Shader compiler with the on-disk SPIR-V cache.
    pub shaders: ShaderCompiler,
    /// An in-memory pipeline cache.
    pub cache: PipelineCache,
}

impl TestGpu {
    /// Creates the device; panics with the setup hint when there is none.
    pub fn new() -> Self {
        let gpu = GpuContext::new(&ContextDesc {
            validation: true,
            ..ContextDesc::default()
        })
        .expect("a Vulkan device (run tools/setup.sh for lavapipe)");
        // The shipped SPIR-V, as the `lucent` command and a host use it: a permutation missing
        // from glsl/permutations.txt fails the test that renders it.
        let shaders = ShaderCompiler::shipped().unwrap();
        let cache = PipelineCache::load(&gpu.device, None).unwrap();
        Self {
            gpu,
            shaders,
            cache,
        }
    }

    /// One frame of `scene` (`Renderer::render_once`), read back as `settings` exports it.
    pub fn render(&self, scene: &Scene, settings: FrameSettings) -> FrameImages {
        render_frame(&self.gpu, &self.shaders, &self.cache, scene, settings).unwrap()
    }

    /// Two frames of `scene` in one runner (the second must find every resource as the first
    /// left it), then every pass once more on its own (`run_isolated`, as `bench --isolate`
    /// times them); returns the display and, where `settings` exports them, the HDR image, the
    /// tonemapped image FXAA reads and the G-buffer.
    pub fn render_repeated(&self, scene: &Scene, settings: FrameSettings) -> Repeated {
        let gpu = &self.gpu;
        let renderer = Renderer::new(gpu, &self.shaders, &self.cache, scene, settings).unwrap();
        let mut runner = FrameRunner::new(gpu, renderer.executable.plan.physical.len()).unwrap();
        runner.run_frame(gpu, &renderer.executable).unwrap();
        runner.run_frame(gpu, &renderer.executable).unwrap();
        runner.run_isolated(gpu, &renderer.executable).unwrap();
        let frame = Repeated {
            display: renderer.read_display(gpu).unwrap(),
            hdr: settings.export_hdr.then(|| renderer.read_hdr(gpu).unwrap()),
            ldr: settings.export_ldr.then(|| renderer.read_ldr(gpu).unwrap()),
            gbuffer: settings
                .export_gbuffer
                .then(|| renderer.read_gbuffer(gpu).unwrap()),
        };
        gpu.wait_idle().unwrap();
        runner.destroy(gpu);
        renderer.destroy(gpu);
        frame
    }

    /// Fails if validation reported any error (the cache and device go when `self` drops).
    pub fn finish(self) {
        let errors = self.gpu.validation_error_count();
        assert_eq!(
            errors,
            0,
            "validation errors:\n{}",
            self.gpu.take_validation_messages().join("\n")
        );
    }
}

impl Drop for TestGpu {
    /// Destroys the pipeline cache before the device goes, also when a test panics (a device
    /// destroyed with its cache alive is a validation error of its own, which would bury the
    /// test's message).
    fn drop(&mut self) {
        // SAFETY: the tests create pipelines on this cache only on this thread, and none is
        // being created while the harness drops; a null handle is ignored.
        unsafe {
            self.gpu
                .device
                .destroy_pipeline_cache(self.cache.handle, None)
        };
    }
}

/// What [`TestGpu::render_repeated`] read back.
pub struct Repeated {
    /// Display image, RGBA8 sRGB.
    pub display: Vec<u8>,
    /// Linear HDR RGBA f32, when exported.
    pub hdr: Option<Vec<f32>>,
    /// The tonemapped image before FXAA, when exported.
    pub ldr: Option<Vec<u8>>,
    /// The G-buffer, when exported.
    pub gbuffer: Option<GBufferReadback>,
}

/// Compares `display` (`w` x `h` RGBA8) with `tests/golden/NAME.png` under the default FLIP
/// thresholds; on failure `NAME.actual.png` and `NAME.diff.png` are left in [`output_dir`].
pub fn check_golden(name: &str, display: &[u8], w: u32, h: u32) {
    let golden = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/{name}.png"));
    let outcome = compare_with_golden(
        name,
        &golden,
        display,
        w,
        h,
        &FlipThresholds::default(),
        &output_dir(),
    )
    .unwrap();
    assert!(
        outcome.passed,
        "{name} differs from its golden: mean FLIP {:.4}, {:.3}% of pixels above threshold; see {:?} and {:?}",
        outcome.result.mean,
        outcome.result.fraction_above * 100.0,
        outcome.actual_path,
        outcome.diff_path
    );
}

/// The largest difference between two byte images, over every byte.
pub fn max_difference(a: &[u8], b: &[u8]) -> u8 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}

/// The plan of a frame of `scene` under `settings`, compiled without a device.
pub fn plan(scene: &Scene, settings: &FrameSettings) -> Plan {
    plan_frame(settings, &FrameDesc::new(scene, settings).unwrap()).unwrap()
}

/// The size of the image `name` in `plan`.
pub fn image_size(plan: &Plan, name: &str) -> (u32, u32) {
    let id = plan
        .resource_by_name(name)
        .unwrap_or_else(|| panic!("no image '{name}' in the plan"));
    let info = &plan.resources[id].info;
    (info.width, info.height)
}

/// Every technique the command line names (`auto`, `none` and the registry's), in its order:
/// the one list the tests iterate.
pub fn techniques() -> Vec<Technique> {
    Technique::all().into_iter().map(|(_, t)| t).collect()
}

/// The SSS blur of a registered screen-space technique (its module's static).
pub fn blur(
    technique: &'static dyn lucent::features::registry::TechniqueModule,
) -> lucent::features::sss::SssBlur {
    lucent::features::registry::blur_of_technique(technique).expect("an SSS technique")
}

/// The screen-space SSS techniques among [`techniques`]: those that force a blur.
pub fn sss_techniques() -> Vec<Technique> {
    techniques()
        .into_iter()
        .filter(|t| t.sss_blur().is_some())
        .collect()
}

/// `tests/data/NAME`: the files the tests read (scenes, scripts, the bad-input corpus).
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// `CARGO_TARGET_TMPDIR/test-output`, created: where failing tests leave images to look at.
pub fn output_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("test-output");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// An empty folder `CARGO_TARGET_TMPDIR/NAME` (whatever an earlier run left there removed).
/// Tests run in parallel: each names its own.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `lucent` binary cargo built for these tests, as a command to add arguments,
/// environment or a directory to.
pub fn lucent_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_lucent"))
}

/// Runs `lucent ARGS` to the end and returns its output.
pub fn lucent(args: &[&str]) -> Output {
    lucent_command().args(args).output().unwrap()
}

/// Runs `command` with stdin closed and its output captured, killing it and failing the test
/// when it runs longer than `limit` (a command that hangs is a failure, not a stuck CI job).
pub fn output_within(command: &mut Command, limit: Duration) -> Output {
    let mut child = command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the command runs");
    let start = Instant::now();
    while child.try_wait().expect("waitable").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{command:?} still running after {limit:?} (hung)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("output")
}

/// Runs `command` to the end and fails the test, showing its stderr, unless it succeeded.
pub fn succeeded(command: &mut Command) -> Output {
    let out = command.output().unwrap();
    assert!(
        out.status.success(),
        "{command:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The `lucent: error:` lines of a run's stderr.
pub fn error_lines(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("lucent: error:"))
        .map(str::to_string)
        .collect()
}

/// Runs `lucent report ARGS --out DIR` with the validation layer on (`LUCENT_VALIDATION=1`),
/// DIR being `CARGO_TARGET_TMPDIR/NAME` with whatever an earlier run left there removed; fails
/// the test on an error or a panic, prints how long it took, and returns DIR.
pub fn report(args: &[&str], name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    let started = Instant::now();
    let out = lucent_command()
        .env("LUCENT_VALIDATION", "1")
        .arg("report")
        .args(args)
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    println!(
        "report {} took {:.1} s",
        args.join(" "),
        started.elapsed().as_secs_f64()
    );
    dir
}

/// The words of a command line written as one string (its arguments hold no spaces).
pub fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// Runs `lucent LINE` (a benchmark, its arguments as one string) and returns its stdout. Tiny
/// frames on a shared machine may fail the timing checks: that one clean, explained failure is
/// allowed, nothing else.
pub fn run_bench(line: &str) -> String {
    let out = lucent(&words(line));
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        assert!(stderr.contains("lucent: error: timing:"), "{stderr}");
    }
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Records `count` primary command buffers, `record(k, cmd)` into the k-th (begun and ended
/// here), submits them back to back on the queue and waits once, after the last: frames in
/// flight as a host submits them.
pub fn submit_back_to_back(
    gpu: &GpuContext,
    count: usize,
    mut record: impl FnMut(usize, vk::CommandBuffer),
) {
    let device = &gpu.device;
    // SAFETY: valid device; the pool, buffers and fence are used only here and freed after
    // the wait.
    unsafe {
        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(gpu.queue_family),
                None,
            )
            .unwrap();
        let cmds = device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(count as u32),
            )
            .unwrap();
        for (k, &cmd) in cmds.iter().enumerate() {
            device
                .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            record(k, cmd);
            device.end_command_buffer(cmd).unwrap();
        }
        let fence = device
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .unwrap();
        for (k, &cmd) in cmds.iter().enumerate() {
            let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
            let signal = if k + 1 == count {
                fence
            } else {
                vk::Fence::null()
            };
            device.queue_submit2(gpu.queue, &[submit], signal).unwrap();
        }
        device.wait_for_fences(&[fence], true, u64::MAX).unwrap();
        device.destroy_fence(fence, None);
        device.destroy_command_pool(pool, None);
    }
}

/// Whether pixel (`x`, `y`) of a ray-traced reference `w` pixels wide is interior: the same
/// surface (hit distances within 5%), or the sky, covers it and its 8 neighbours. At
/// silhouettes the tessellated mesh and the exact shape cover different pixels, so GPU-against-
/// reference comparisons skip them. `x` and `y` must be at least 1 pixel from the border.
pub fn interior(
    reference: &lucent::reference::raytrace::ReferenceImage,
    w: u32,
    x: u32,
    y: u32,
) -> bool {
    let i = (y * w + x) as usize;
    (-1i32..=1).all(|dy| {
        (-1i32..=1).all(|dx| {
            let j = ((y as i32 + dy) as u32 * w + (x as i32 + dx) as u32) as usize;
            match (reference.hit[i], reference.hit[j]) {
                (Some(a), Some(b)) => (a - b).abs() < 0.05 * a,
                (None, None) => true,
                _ => false,
            }
        })
    })
}

/// An SSS test frame of `technique` at `width` x `height`: the HDR image and the G-buffer read
/// back, no shadows (the f64 references shade without; tests/gpu/shadows.rs checks those).
pub fn sss_frame(technique: Technique, width: u32, height: u32) -> FrameSettings {
    FrameSettings {
        technique,
        export_hdr: true,
        export_gbuffer: true,
        shadows: lucent::features::shadows::ShadowSettings {
            enabled: false,
            ..Default::default()
        },
        ..FrameSettings::new(width, height)
    }
}

/// Whether pixel `i` of a frame `w` pixels wide scatters with its whole 9x9 neighbourhood
/// (`strength`: the G-buffer's SSS profile per pixel): away from the silhouettes, which the
/// edge tests judge.
pub fn interior_scattering(strength: &[f32], w: usize, i: usize) -> bool {
    let h = strength.len() / w.max(1);
    let (x, y) = ((i % w) as i64, (i / w) as i64);
    (-4..=4).all(|dy| {
        (-4..=4).all(|dx| {
            let (nx, ny) = (x + dx, y + dy);
            (0..w as i64).contains(&nx)
                && (0..h as i64).contains(&ny)
                && strength[ny as usize * w + nx as usize] > 0.0
        })
    })
}
