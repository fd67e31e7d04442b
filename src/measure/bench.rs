//! The benchmark: per-pass GPU times that are proven to add up, and a statement of how they were
//! taken.
//!
//! Two timing modes exist (DESIGN.md, "Facts measured": lavapipe's in-frame timestamps can lie):
//! - **in-frame**: one command buffer per frame, a timestamp pair around each physical pass.
//!   Cheap and realistic, but on lavapipe passes chained in one command buffer can report a
//!   fraction of their cost.
//! - **isolated**: each physical pass in its own submission with the device idle before it,
//!   still timed with timestamps. True per-pass cost; it loses overlap between passes.
//!
//! The benchmark measures in-frame first and checks that the pass medians add up to the frame's
//! wall time (submit to fence) within 10%, and with `--isolate` that each pass of 0.5 ms or
//! more is within 20% of its isolated time. If a check fails it reports the isolated times
//! instead and says so. If even those do not add up, the report is marked untrusted and the
//! command exits non-zero.
//!
//! With a [`FloorFrame`] the same run also times every pass's
//! speed-of-light floor, alternating with the frames, and the report gains the pass / floor
//! table.
//! Output: [`BenchReport::markdown`], [`BenchReport::csv`], [`BenchReport::json`]. Runs longer
//! than [`PROGRESS_AFTER_S`] show a progress bar on stderr when it is a terminal (without the
//! `report` feature, log lines instead: [`crate::progress`]).

use std::io::IsTerminal as _;

use serde::Serialize;

use crate::backend::GpuContext;
use crate::frame::{FrameRunner, FrameTiming, Renderer};
use crate::measure::speed_of_light::{FloorFrame, FloorRow};
use crate::measure::stats::Stats;
use crate::progress::Progress;
use crate::scene::Scene;
use crate::{LucentError, Result};

/// Estimated run time (from the warm-up) above which a progress bar is drawn.
pub const PROGRESS_AFTER_S: f64 = 3.0;

/// Tolerance of the sum check: pass medians vs frame median.
pub const SUM_TOLERANCE: f64 = 0.10;
/// Tolerance of the isolation check, for passes of at least [`ISOLATION_MIN_MS`].
pub const ISOLATION_TOLERANCE: f64 = 0.20;
/// Passes shorter than this are too close to timer noise to compare with their isolated time.
pub const ISOLATION_MIN_MS: f64 = 0.5;

/// Most frames (or rounds) one measurement takes: the bound `--frames` and `--rounds` are
/// checked against at parse time, and every per-frame buffer is sized within it.
pub const MAX_FRAMES: usize = 100_000;
/// Most warm-up frames (or rounds).
pub const MAX_WARMUP: usize = 10_000;
/// Runs shorter than this many measured frames fail the timing checks by chance on a shared
/// machine; the error says so.
pub const SHORT_RUN_FRAMES: usize = 10;

/// Refuses frame and warm-up counts outside `1..=MAX_FRAMES` and `0..=MAX_WARMUP`.
fn check_counts(frames: usize, warmup: usize) -> Result<()> {
    if !(1..=MAX_FRAMES).contains(&frames) {
        return Err(LucentError::InvalidInput(format!(
            "--frames {frames}: must be 1 to {MAX_FRAMES}"
        )));
    }
    if warmup > MAX_WARMUP {
        return Err(LucentError::InvalidInput(format!(
            "--warmup {warmup}: must be 0 to {MAX_WARMUP}"
        )));
    }
    Ok(())
}

/// What to measure.
#[derive(Clone, Copy, Debug)]
pub struct BenchOptions {
    /// Frames measured.
    pub frames: usize,
    /// Frames run first and discarded (lazy shader compilation, caches).
    pub warmup: usize,
    /// Also time every pass alone and compare.
    pub isolate: bool,
}

/// One row of the table.
#[derive(Clone, Debug, Serialize)]
pub struct PassRow {
    /// Physical pass name ("a + b" for merged passes).
    pub name: String,
    /// Median milliseconds in the reported timing mode.
    pub median_ms: f64,
    /// Minimum.
    pub min_ms: f64,
    /// Maximum.
    pub max_ms: f64,
    /// Median when submitted alone (with `--isolate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub isolated_ms: Option<f64>,
    /// Median in-frame (timestamps inside one command buffer).
    pub in_frame_ms: f64,
    /// Share of the frame's median wall time.
    pub share: f64,
}

/// One verification of the timing.
#[derive(Clone, Debug, Serialize)]
pub struct Check {
    /// What was checked.
    pub name: String,
    /// Whether it held.
    pub passed: bool,
    /// Numbers behind it.
    pub detail: String,
}

/// Everything `lucent bench` prints.
#[derive(Clone, Debug, Serialize)]
pub struct BenchReport {
    /// Device name and type.
    pub device: String,
    /// Driver name and version.
    pub driver: String,
    /// Scene name.
    pub scene: String,
    /// Technique name.
    pub technique: String,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Frames measured.
    pub frames: usize,
    /// Warm-up frames discarded.
    pub warmup: usize,
    /// Which mode produced the pass numbers, and why.
    pub timing_mode: String,
    /// Per-pass rows.
    pub passes: Vec<PassRow>,
    /// Wall time of whole frames (submit to fence), in-frame mode.
    pub frame_ms: Stats,
    /// Sum of the reported pass medians.
    pub pass_sum_ms: f64,
    /// The checks made.
    pub checks: Vec<Check>,
    /// Whether the reported numbers passed their checks.
    pub trusted: bool,
    /// Each pass against its speed-of-light floor, when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_of_light: Option<Vec<FloorRow>>,
    /// A deforming scene: the CPU time per frame to deform its meshes and write them into
    /// the frame's vertex buffers, before the frame is submitted (not in `frame_ms`). Null
    /// for static scenes.
    pub deformation_ms: Option<Stats>,
    /// With `--against`: the same scene under another technique, alternating frames with
    /// this one, each pass's ratio ([`Comparison::against`]); in the JSON only when measured.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub against: Option<Against>,
}

/// A [`Comparison`] as the report's JSON carries it: each pass (and the frame) under both
/// techniques, and the ratio of the benchmarked technique to the other.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Against {
    /// The technique measured against (`--against`).
    pub baseline: String,
    /// The benchmarked technique.
    pub technique: String,
    /// Frames measured per side, alternating.
    pub frames: usize,
    /// Per physical pass, then `frame` (submit to fence).
    pub passes: Vec<AgainstRow>,
}

/// One pass of an [`Against`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct AgainstRow {
    /// Physical pass name, or `frame`.
    pub pass: String,
    /// Median ms under the baseline technique (`None`: it has no such pass).
    pub baseline_ms: Option<f64>,
    /// Median ms under the benchmarked technique (`None`: it has no such pass).
    pub technique_ms: Option<f64>,
    /// `technique_ms / baseline_ms` when both exist.
    pub ratio: Option<f64>,
}

/// The report formats `lucent bench --format` offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Header, table and checks.
    Markdown,
    /// One row per pass plus the frame, with a header line.
    Csv,
    /// The documented JSON object.
    Json,
}

impl Format {
    /// Every format with its command-line name.
    pub const ALL: &'static [(&'static str, Format)] = &[
        ("markdown", Format::Markdown),
        ("csv", Format::Csv),
        ("json", Format::Json),
    ];

    /// Parses a command-line name.
    pub fn parse(name: &str) -> Result<Self> {
        crate::error::parse_named(Self::ALL, name, "format")
    }
}

/// Seconds a benchmarked frame of a deforming scene advances its time (a 60 Hz animation).
pub const ANIMATION_STEP_S: f32 = 1.0 / 60.0;

/// Runs the benchmark on a built renderer. `scene` is the scene it was built for: a deforming
/// scene is animated, every frame deformed at its own time ([`ANIMATION_STEP_S`] apart) and
/// uploaded before it is submitted, and that CPU work is timed and reported with the frame.
pub fn run(
    gpu: &GpuContext,
    renderer: &Renderer,
    scene: &Scene,
    scene_name: &str,
    options: &BenchOptions,
) -> Result<BenchReport> {
    run_with_floor(gpu, renderer, None, scene, scene_name, options)
}

/// [`run`], and with `copies` (built from the renderer's plan) each pass's speed-of-light floor
/// timed in the same run, one floor frame after each measured frame.
pub fn run_with_floor(
    gpu: &GpuContext,
    renderer: &Renderer,
    copies: Option<&mut FloorFrame>,
    scene: &Scene,
    scene_name: &str,
    options: &BenchOptions,
) -> Result<BenchReport> {
    check_counts(options.frames, options.warmup)?;
    let exe = &renderer.executable;
    let names: Vec<String> = exe.plan.physical.iter().map(|p| p.name.clone()).collect();
    let mut runner = FrameRunner::new(gpu, names.len())?;
    let mut animation = Animation::of(scene);
    let result = measure(
        gpu,
        renderer,
        &mut runner,
        copies,
        animation.as_mut(),
        &names,
        scene_name,
        options,
    );
    runner.destroy(gpu);
    result
}

/// A progress bar on stderr for `total` steps, drawn only when stderr is a terminal and the run
/// is expected to take longer than [`PROGRESS_AFTER_S`] (without the `report` feature, under
/// the same conditions, coarse log lines: [`Progress`]).
pub fn progress_bar(total: u64, expected_s: f64, what: &str) -> Progress {
    if !std::io::stderr().is_terminal() || expected_s < PROGRESS_AFTER_S {
        return Progress::hidden();
    }
    Progress::stderr(
        total,
        what,
        "{msg} [{bar:40}] {pos}/{len} ({eta} left)",
        Some("=> "),
    )
}

fn collect(samples: &mut [Vec<f64>], timing: &FrameTiming, names: &[String]) -> Result<()> {
    if timing.passes.len() != names.len() {
        return Err(LucentError::Timing(format!(
            "expected {} timestamp scopes, got {}",
            names.len(),
            timing.passes.len()
        )));
    }
    for (sample, pass) in samples.iter_mut().zip(&timing.passes) {
        sample.push(pass.ms);
    }
    Ok(())
}

/// A deforming scene advanced frame by frame.
struct Animation {
    scene: Scene,
    start: f32,
    frame: u32,
}

impl Animation {
    /// `scene` animated from its own time, when it deforms.
    fn of(scene: &Scene) -> Option<Self> {
        scene.deformation.map(|_| Animation {
            scene: scene.clone(),
            start: scene.time,
            frame: 0,
        })
    }

    /// Moves to the next frame's time.
    fn step(&mut self) {
        self.scene.time = self.start + self.frame as f32 * ANIMATION_STEP_S;
        self.frame += 1;
    }

    /// Deforms the scene at its current time into the renderer's slot (the previous frame
    /// has completed: `run_frame` waits for it); returns the CPU milliseconds it took.
    fn upload(&self, renderer: &Renderer) -> Result<f64> {
        let t = std::time::Instant::now();
        renderer.update_slot(&self.scene, 0)?;
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    /// [`Self::step`], then [`Self::upload`].
    fn advance(&mut self, renderer: &Renderer) -> Result<f64> {
        self.step();
        self.upload(renderer)
    }
}

#[allow(clippy::too_many_arguments)]
fn measure(
    gpu: &GpuContext,
    renderer: &Renderer,
    runner: &mut FrameRunner,
    mut copies: Option<&mut FloorFrame>,
    mut animation: Option<&mut Animation>,
    names: &[String],
    scene_name: &str,
    options: &BenchOptions,
) -> Result<BenchReport> {
    let exe = &renderer.executable;
    let warm_start = std::time::Instant::now();
    for _ in 0..options.warmup {
        if let Some(a) = animation.as_deref_mut() {
            a.advance(renderer)?;
        }
        runner.run_frame(gpu, exe)?;
        if options.isolate {
            runner.run_isolated(gpu, exe)?;
        }
        if let Some(c) = copies.as_deref_mut() {
            c.measure(gpu, false)?;
        }
    }
    // Warm-up frames are the slow ones (lazy compilation): an overestimate, which only shows
    // the bar a little early.
    let per_frame_s = warm_start.elapsed().as_secs_f64() / options.warmup.max(1) as f64;
    let bar = progress_bar(
        options.frames as u64,
        per_frame_s * options.frames as f64,
        "bench",
    );
    let mut deformation_ms = Vec::new();
    let mut samples = Samples {
        frame_walls: Vec::with_capacity(options.frames),
        in_frame: vec![Vec::new(); names.len()],
        isolated: vec![Vec::new(); names.len()],
    };
    // Interleaved, so both modes see the same machine load.
    for _ in 0..options.frames {
        if let Some(a) = animation.as_deref_mut() {
            deformation_ms.push(a.advance(renderer)?);
        }
        let t = runner.run_frame(gpu, exe)?;
        samples.frame_walls.push(t.wall_ms);
        collect(&mut samples.in_frame, &t, names)?;
        if options.isolate {
            collect(
                &mut samples.isolated,
                &runner.run_isolated(gpu, exe)?,
                names,
            )?;
        }
        if let Some(c) = copies.as_deref_mut() {
            c.measure(gpu, true)?;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut verdict = judge(names, &samples, options.isolate);
    if verdict.needs_isolated {
        // The in-frame numbers did not add up: measure the isolated ones to report instead.
        for _ in 0..options.frames {
            collect(
                &mut samples.isolated,
                &runner.run_isolated(gpu, exe)?,
                names,
            )?;
        }
        verdict = judge(names, &samples, options.isolate);
    }
    let speed_of_light = copies.map(|c| {
        crate::measure::speed_of_light::rows(&c.floors, &c.medians(), |name| {
            verdict
                .passes
                .iter()
                .find(|p| p.name == name)
                .map(|p| p.median_ms)
        })
    });
    Ok(BenchReport {
        device: gpu.info.describe(),
        driver: gpu.info.driver(),
        scene: scene_name.to_string(),
        technique: renderer.settings.technique.name().to_string(),
        width: renderer.settings.width,
        height: renderer.settings.height,
        frames: options.frames,
        warmup: options.warmup,
        timing_mode: verdict.timing_mode,
        pass_sum_ms: verdict.passes.iter().map(|p| p.median_ms).sum(),
        passes: verdict.passes,
        frame_ms: verdict.frame,
        checks: verdict.checks,
        trusted: verdict.trusted,
        speed_of_light,
        deformation_ms: (!deformation_ms.is_empty()).then(|| Stats::of(&deformation_ms)),
        against: None,
    })
}

/// Raw timings: per frame, and per pass per frame in each mode (milliseconds).
struct Samples {
    frame_walls: Vec<f64>,
    in_frame: Vec<Vec<f64>>,
    isolated: Vec<Vec<f64>>,
}

/// Which numbers to report, and why.
struct Verdict {
    timing_mode: String,
    passes: Vec<PassRow>,
    frame: Stats,
    checks: Vec<Check>,
    trusted: bool,
    /// The in-frame numbers failed and no isolated ones were measured yet.
    needs_isolated: bool,
}

/// Decides the timing mode from the samples: in-frame numbers when they add up to the frame
/// (and, when `isolate_checked`, match the isolated ones), isolated numbers otherwise.
fn judge(names: &[String], samples: &Samples, isolate_checked: bool) -> Verdict {
    let frame = Stats::of(&samples.frame_walls);
    let in_frame: Vec<Stats> = samples.in_frame.iter().map(|s| Stats::of(s)).collect();
    let have_isolated = samples.isolated.iter().all(|s| !s.is_empty()) && !names.is_empty();
    let isolated: Option<Vec<Stats>> =
        have_isolated.then(|| samples.isolated.iter().map(|s| Stats::of(s)).collect());
    let in_frame_sum: f64 = in_frame.iter().map(|s| s.median).sum();
    let mut checks = vec![sum_check(
        "in-frame passes sum to frame",
        in_frame_sum,
        frame.median,
    )];
    if isolate_checked && have_isolated {
        checks.push(isolation_check(names, &in_frame, &samples.isolated));
    }
    let in_frame_ok = checks.iter().all(|c| c.passed);
    let (timing_mode, reported, trusted) = if in_frame_ok {
        let mode = format!(
            "in-frame timestamps (verified: passes sum to {:.1}% of frame wall time{})",
            100.0 * in_frame_sum / frame.median,
            if isolate_checked {
                format!(
                    "; every pass of {ISOLATION_MIN_MS} ms or more within {:.0}% of its isolated time",
                    ISOLATION_TOLERANCE * 100.0
                )
            } else {
                String::new()
            }
        );
        (mode, in_frame.clone(), true)
    } else if let Some(iso) = &isolated {
        let iso_sum: f64 = iso.iter().map(|s| s.median).sum();
        let check = sum_check("isolated passes sum to frame", iso_sum, frame.median);
        let trusted = check.passed;
        let failed: Vec<String> = checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.detail.clone())
            .collect();
        checks.push(check);
        let mode = format!(
            "isolated per-pass submissions, timestamps (in-frame timestamps rejected: {}){}",
            failed.join("; "),
            if trusted {
                ""
            } else {
                " — UNTRUSTED: isolated passes do not add up to the frame either"
            }
        );
        (mode, iso.clone(), trusted)
    } else {
        return Verdict {
            timing_mode: String::new(),
            passes: Vec::new(),
            frame,
            checks,
            trusted: false,
            needs_isolated: true,
        };
    };
    let passes = names
        .iter()
        .enumerate()
        .map(|(i, name)| PassRow {
            name: name.clone(),
            median_ms: reported[i].median,
            min_ms: reported[i].min,
            max_ms: reported[i].max,
            isolated_ms: isolated.as_ref().map(|s| s[i].median),
            in_frame_ms: in_frame[i].median,
            share: if frame.median > 0.0 {
                reported[i].median / frame.median
            } else {
                0.0
            },
        })
        .collect();
    Verdict {
        timing_mode,
        passes,
        frame,
        checks,
        trusted,
        needs_isolated: false,
    }
}

fn sum_check(name: &str, sum: f64, frame: f64) -> Check {
    let ratio = if frame > 0.0 { sum / frame } else { 0.0 };
    Check {
        name: name.into(),
        passed: (ratio - 1.0).abs() <= SUM_TOLERANCE,
        detail: format!(
            "sum of pass medians {sum:.3} ms is {:.1}% of frame median {frame:.3} ms (allowed {:.0}-{:.0}%)",
            ratio * 100.0,
            (1.0 - SUM_TOLERANCE) * 100.0,
            (1.0 + SUM_TOLERANCE) * 100.0
        ),
    }
}

fn isolation_check(names: &[String], in_frame: &[Stats], isolated: &[Vec<f64>]) -> Check {
    let mut worst = String::new();
    let mut passed = true;
    let mut worst_error = 0.0f64;
    for (i, name) in names.iter().enumerate() {
        let alone = Stats::of(&isolated[i]).median;
        if alone < ISOLATION_MIN_MS {
            continue;
        }
        let error = (in_frame[i].median - alone).abs() / alone;
        if error > worst_error {
            worst_error = error;
            worst = format!(
                "'{name}' {:.3} ms in-frame vs {alone:.3} ms alone ({:.0}% off)",
                in_frame[i].median,
                error * 100.0
            );
        }
        if error > ISOLATION_TOLERANCE {
            passed = false;
        }
    }
    Check {
        name: "in-frame passes match isolated".into(),
        passed,
        detail: if worst.is_empty() {
            format!("no pass of {ISOLATION_MIN_MS} ms or more")
        } else {
            format!("largest difference: {worst}")
        },
    }
}

impl BenchReport {
    /// The report as Markdown: a header with device and mode, the table, and the checks.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "## lucent bench: scene `{}`, technique `{}`, {}x{}\n\n\
             - device: {}\n- driver: {}\n- frames: {} measured after {} warm-up\n\
             - timing mode: {}\n\n",
            self.scene,
            self.technique,
            self.width,
            self.height,
            self.device,
            self.driver,
            self.frames,
            self.warmup,
            self.timing_mode
        );
        let isolated = self.passes.iter().any(|p| p.isolated_ms.is_some());
        out.push_str("| pass | median ms | min ms | max ms | share of frame |");
        out.push_str(if isolated { " isolated ms |\n" } else { "\n" });
        out.push_str("|---|---:|---:|---:|---:|");
        out.push_str(if isolated { "---:|\n" } else { "\n" });
        for p in &self.passes {
            out.push_str(&format!(
                "| {} | {:.3} | {:.3} | {:.3} | {:.1}% |",
                p.name,
                p.median_ms,
                p.min_ms,
                p.max_ms,
                p.share * 100.0
            ));
            if let Some(iso) = p.isolated_ms {
                out.push_str(&format!(" {iso:.3} |"));
            } else if isolated {
                out.push_str(" |");
            }
            out.push('\n');
        }
        let sum_share = if self.frame_ms.median > 0.0 {
            self.pass_sum_ms / self.frame_ms.median * 100.0
        } else {
            0.0
        };
        out.push_str(&format!(
            "| **sum of passes** | {:.3} | | | {sum_share:.1}% |{}\n",
            self.pass_sum_ms,
            if isolated { " |" } else { "" }
        ));
        out.push_str(&format!(
            "| **frame (submit to fence)** | {:.3} | {:.3} | {:.3} | 100.0% |{}\n\n",
            self.frame_ms.median,
            self.frame_ms.min,
            self.frame_ms.max,
            if isolated { " |" } else { "" }
        ));
        if let Some(d) = &self.deformation_ms {
            // The deformation runs on the CPU before each frame is submitted: the frame's cost
            // to an animation is both.
            out.push_str(&format!(
                "- deformation (CPU, before submit): median {:.3} ms (min {:.3}, max {:.3}); \
                 frame + deformation {:.3} ms\n",
                d.median,
                d.min,
                d.max,
                self.frame_ms.median + d.median
            ));
        }
        for c in &self.checks {
            out.push_str(&format!(
                "- check {}: {} ({})\n",
                c.name,
                if c.passed { "ok" } else { "FAILED" },
                c.detail
            ));
        }
        if let Some(rows) = &self.speed_of_light {
            out.push_str("\n### Speed of light: each pass against its floor (its draws, or a copy of its formats)\n\n");
            out.push_str(&crate::measure::speed_of_light::markdown(rows));
        }
        out
    }

    /// The report as CSV: a header line, one line per pass and one for the frame. Every line
    /// repeats the run's scene, technique, size, device and timing mode, so files from several
    /// runs concatenate into one table.
    pub fn csv(&self) -> String {
        let mode = if self.timing_mode.starts_with("in-frame") {
            "in-frame"
        } else {
            "isolated"
        };
        let mut out = String::from(
            "scene,technique,width,height,device,timing_mode,trusted,pass,median_ms,min_ms,max_ms,\
             isolated_ms,share,floor,floor_ms,pass_per_floor,taps,ms_per_tap\n",
        );
        let prefix = format!(
            "{},{},{},{},{},{mode},{}",
            csv_field(&self.scene),
            csv_field(&self.technique),
            self.width,
            self.height,
            csv_field(&self.device),
            self.trusted
        );
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.6}"));
        for p in &self.passes {
            let floor = self
                .speed_of_light
                .as_ref()
                .and_then(|rows| rows.iter().find(|r| r.pass == p.name));
            out.push_str(&format!(
                "{prefix},{},{:.6},{:.6},{:.6},{},{:.6},{},{},{},{},{}\n",
                csv_field(&p.name),
                p.median_ms,
                p.min_ms,
                p.max_ms,
                opt(p.isolated_ms),
                p.share,
                floor.map_or(String::new(), |f| csv_field(&f.floor)),
                opt(floor.and_then(|f| f.floor_ms)),
                opt(floor.and_then(|f| f.ratio)),
                floor.map_or(String::new(), |f| f.taps.to_string()),
                opt(floor.and_then(|f| f.ms_per_tap)),
            ));
        }
        out.push_str(&format!(
            "{prefix},frame,{:.6},{:.6},{:.6},,1.000000,,,,,\n",
            self.frame_ms.median, self.frame_ms.min, self.frame_ms.max
        ));
        out
    }

    /// The report in `format`.
    pub fn format(&self, format: Format) -> String {
        match format {
            Format::Markdown => self.markdown(),
            Format::Csv => self.csv(),
            Format::Json => self.json(),
        }
    }

    /// The report as JSON (the shape documented in the README; later fields only extend it).
    pub fn json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }
}

/// One CSV field: quoted (with quotes doubled) when it holds a comma, quote or line break.
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_are_quoted_only_when_needed() {
        assert_eq!(csv_field("gbuffer + lighting"), "gbuffer + lighting");
        assert_eq!(
            csv_field("llvmpipe (LLVM 15, 256 bits)"),
            "\"llvmpipe (LLVM 15, 256 bits)\""
        );
        assert_eq!(csv_field("a\"b"), "\"a\"\"b\"");
    }

    #[test]
    fn formats_parse_and_refuse_unknown_names() {
        assert_eq!(Format::parse("csv").unwrap(), Format::Csv);
        let e = Format::parse("xml").unwrap_err().to_string();
        assert!(e.contains("markdown, csv, json"), "{e}");
    }

    #[test]
    fn stats_of_odd_and_even_samples() {
        assert_eq!(Stats::of(&[3.0, 1.0, 2.0]).median, 2.0);
        assert_eq!(Stats::of(&[4.0, 1.0, 2.0, 3.0]).median, 2.5);
        let s = Stats::of(&[5.0, 1.0]);
        assert_eq!((s.min, s.max), (1.0, 5.0));
    }

    #[test]
    fn sum_check_bounds() {
        assert!(sum_check("s", 9.5, 10.0).passed);
        assert!(!sum_check("s", 8.0, 10.0).passed);
        assert!(!sum_check("s", 11.5, 10.0).passed);
    }

    /// Samples of two passes over `n` frames with constant values.
    fn samples(frame: f64, in_frame: [f64; 2], isolated: Option<[f64; 2]>) -> Samples {
        let n = 5;
        Samples {
            frame_walls: vec![frame; n],
            in_frame: in_frame.iter().map(|&v| vec![v; n]).collect(),
            isolated: match isolated {
                Some(iso) => iso.iter().map(|&v| vec![v; n]).collect(),
                None => vec![Vec::new(); 2],
            },
        }
    }

    fn names() -> Vec<String> {
        vec!["blur".to_string(), "tonemap".to_string()]
    }

    #[test]
    fn honest_in_frame_timestamps_are_reported() {
        let v = judge(&names(), &samples(12.0, [9.6, 2.0], Some([9.5, 2.1])), true);
        assert!(v.trusted && !v.needs_isolated);
        assert!(
            v.timing_mode.starts_with("in-frame timestamps (verified"),
            "{}",
            v.timing_mode
        );
        assert_eq!(v.passes[0].median_ms, 9.6);
        assert_eq!(v.passes[0].isolated_ms, Some(9.5));
    }

    #[test]
    fn lying_in_frame_timestamps_fall_back_to_isolated_times() {
        // The measured lavapipe lie: a 9.6 ms blur reported as 0.19 ms inside the frame.
        let lie = samples(11.8, [0.19, 2.0], None);
        let first = judge(&names(), &lie, false);
        assert!(
            first.needs_isolated,
            "a failed sum check asks for isolated times"
        );
        let v = judge(
            &names(),
            &samples(11.8, [0.19, 2.0], Some([9.6, 2.0])),
            false,
        );
        assert!(v.trusted);
        assert!(
            v.timing_mode.starts_with("isolated per-pass submissions"),
            "{}",
            v.timing_mode
        );
        assert!(
            v.timing_mode.contains("in-frame timestamps rejected"),
            "{}",
            v.timing_mode
        );
        assert_eq!(v.passes[0].median_ms, 9.6);
        assert_eq!(v.passes[0].in_frame_ms, 0.19);
    }

    #[test]
    fn sums_that_add_up_but_disagree_with_isolation_are_rejected() {
        // In-frame shares shifted between passes: the sum holds, the per-pass check does not.
        let v = judge(&names(), &samples(11.6, [2.0, 9.6], Some([9.6, 2.0])), true);
        assert!(v.timing_mode.starts_with("isolated"), "{}", v.timing_mode);
        assert_eq!(v.passes[1].median_ms, 2.0);
    }

    #[test]
    fn numbers_that_never_add_up_are_untrusted() {
        let v = judge(
            &names(),
            &samples(50.0, [0.19, 2.0], Some([9.6, 2.0])),
            true,
        );
        assert!(!v.trusted);
        assert!(v.timing_mode.contains("UNTRUSTED"), "{}", v.timing_mode);
    }

    #[test]
    fn isolation_check_ignores_short_passes_and_catches_lies() {
        let names = vec!["blur".to_string(), "tiny".to_string()];
        let stat = |m| Stats {
            median: m,
            min: m,
            max: m,
        };
        // The lavapipe lie: 0.19 ms in-frame for a 9.6 ms blur.
        let lying = isolation_check(&names, &[stat(0.19), stat(0.1)], &[vec![9.6], vec![0.3]]);
        assert!(!lying.passed, "{}", lying.detail);
        let honest = isolation_check(&names, &[stat(9.0), stat(0.01)], &[vec![9.6], vec![0.3]]);
        assert!(honest.passed, "{}", honest.detail);
    }
}

/// Two frames of the same scene measured against each other in one run: `a` and `b` alternate
/// frame by frame (after `warmup` frames each), so a noisy, shared machine slows both alike and
/// the ratio between them holds where separate runs would not (on the project's 2-core machine,
/// separate `bench` runs of one configuration differ by up to 15%).
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Names of the two sides (their techniques).
    pub names: [String; 2],
    /// Per physical pass name: the median of each side (`None` where a side lacks the pass).
    pub passes: Vec<(String, [Option<Stats>; 2])>,
    /// Frame wall time of each side.
    pub frame: [Stats; 2],
    /// Frames measured per side.
    pub frames: usize,
}

/// Measures `a` against `b`, alternating frames, both built for `scene` (a deforming scene
/// is animated: both sides draw the same instant each frame).
pub fn compare(
    gpu: &GpuContext,
    sides: [(&str, &Renderer); 2],
    scene: &Scene,
    frames: usize,
    warmup: usize,
) -> Result<Comparison> {
    check_counts(frames, warmup)?;
    let names: [Vec<String>; 2] = sides.map(|(_, r)| {
        r.executable
            .plan
            .physical
            .iter()
            .map(|p| p.name.clone())
            .collect()
    });
    let mut runners = Vec::new();
    let result = (|| -> Result<Comparison> {
        for side_names in &names {
            runners.push(FrameRunner::new(gpu, side_names.len())?);
        }
        let mut in_frame: [Vec<Vec<f64>>; 2] = [
            vec![Vec::new(); names[0].len()],
            vec![Vec::new(); names[1].len()],
        ];
        let mut walls: [Vec<f64>; 2] = [Vec::new(), Vec::new()];
        let mut animation = Animation::of(scene);
        for frame in 0..warmup + frames {
            if let Some(a) = animation.as_mut() {
                a.step();
            }
            for side in 0..2 {
                if let Some(a) = &animation {
                    a.upload(sides[side].1)?;
                }
                let t = runners[side].run_frame(gpu, &sides[side].1.executable)?;
                if frame >= warmup {
                    collect(&mut in_frame[side], &t, &names[side])?;
                    walls[side].push(t.wall_ms);
                }
            }
        }
        let mut passes: Vec<(String, [Option<Stats>; 2])> = Vec::new();
        for side in 0..2 {
            for (name, samples) in names[side].iter().zip(&in_frame[side]) {
                let stats = Stats::of(samples);
                match passes.iter_mut().find(|(n, _)| n == name) {
                    Some((_, s)) => s[side] = Some(stats),
                    None => {
                        let mut s = [None, None];
                        s[side] = Some(stats);
                        passes.push((name.clone(), s));
                    }
                }
            }
        }
        Ok(Comparison {
            names: sides.map(|(n, _)| n.to_string()),
            passes,
            frame: [Stats::of(&walls[0]), Stats::of(&walls[1])],
            frames,
        })
    })();
    for runner in runners {
        runner.destroy(gpu);
    }
    result
}

impl Comparison {
    /// The comparison as the report's JSON carries it: side `b` (the benchmarked technique)
    /// against side `a`, per pass and for the frame.
    pub fn against(&self) -> Against {
        let ratio = |a: Option<f64>, b: Option<f64>| match (a, b) {
            // Guarded: a 0 ms pass (timer granularity) gives no ratio, not Inf.
            (Some(a), Some(b)) if a > 0.0 => Some(b / a),
            _ => None,
        };
        let row = |pass: &str, a: Option<f64>, b: Option<f64>| AgainstRow {
            pass: pass.to_string(),
            baseline_ms: a,
            technique_ms: b,
            ratio: ratio(a, b),
        };
        let mut passes: Vec<AgainstRow> = self
            .passes
            .iter()
            .map(|(name, [a, b])| row(name, a.map(|s| s.median), b.map(|s| s.median)))
            .collect();
        passes.push(row(
            "frame",
            Some(self.frame[0].median),
            Some(self.frame[1].median),
        ));
        Against {
            baseline: self.names[0].clone(),
            technique: self.names[1].clone(),
            frames: self.frames,
            passes,
        }
    }

    /// The comparison as a Markdown table: each pass's medians and the ratio b / a.
    pub fn markdown(&self, device: &str) -> String {
        let [a, b] = &self.names;
        let mut out = format!(
            "## lucent bench: `{b}` against `{a}`, alternating frames\n\n- device: {device}\n\
             - frames: {} per side, alternating; in-frame timestamps\n\n\
             | pass | `{a}` median ms | `{b}` median ms | `{b}` / `{a}` |\n|---|---:|---:|---:|\n",
            self.frames
        );
        let ratio = |x: f64, y: f64| format!("{:+.1}%", (y / x.max(1e-9) - 1.0) * 100.0);
        for (name, [sa, sb]) in &self.passes {
            let cell =
                |s: &Option<Stats>| s.map_or("-".to_string(), |s| format!("{:.3}", s.median));
            let r = match (sa, sb) {
                (Some(x), Some(y)) => ratio(x.median, y.median),
                _ => "-".into(),
            };
            out.push_str(&format!("| {name} | {} | {} | {r} |\n", cell(sa), cell(sb)));
        }
        out.push_str(&format!(
            "| **frame (submit to fence)** | {:.3} | {:.3} | {} |\n",
            self.frame[0].median,
            self.frame[1].median,
            ratio(self.frame[0].median, self.frame[1].median)
        ));
        out
    }
}
