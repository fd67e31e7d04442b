//! The report suite: `lucent report --out DIR [--quick]` runs everything lucent measures and
//! writes `DIR/report.md` with its tables and PNG plots.
//!
//! In order:
//! 1. **Per technique** (every entry of [`Technique::all`], on the scene made for it, see
//!    [`scene_for`]): the verified benchmark ([`crate::measure::bench`], with `--isolate`) and every
//!    pass beside its speed-of-light copy ([`crate::measure::speed_of_light`]), measured in the same run;
//!    a bar plot of pass against copy; beside the thesis's table where the thesis has one.
//! 2. **The seeds' tables**: GDC 2011's full-screen translucency cost beside ours as a share of
//!    the lighting pass, and Li et al.'s Table 1 beside our frame times (technique `auto`, their
//!    passes included) at its triangle counts and dynamic-texture (light-space map)
//!    resolutions, with their claim as ratios ([`crate::report::seeds`]).
//! 3. **Scaling** ([`crate::measure::scaling`]): frame and per-pass time against triangles, resolution
//!    and light count, with curves and which passes grow with what.
//! 4. **Error against time**: one section per technique with approximation knobs
//!    ([`ERROR_SECTIONS`]; a section is one [`SectionFn`], so a technique plugs its own in),
//!    and the anti-aliasing pass's cost and effect ([`antialias`]).
//!
//! Numbers compared with each other are always measured in one run, alternating or round-robin
//! (the machine is shared and noisy: separate runs differ by up to 15%).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{FrameSettings, Renderer, Technique};
use crate::measure::bench::{BenchOptions, BenchReport};
use crate::measure::scaling::{Config, Measured};
use crate::measure::speed_of_light::FloorFrame;
use crate::report::plot::{write_bars_png, write_curves_png, BarRow, PlotPoint, PlotSeries};
use crate::report::seeds::{LiOurs, TranslucencyCost, LI_TABLE_1};
use crate::{LucentError, Result};

pub mod antialias;
mod font;
pub mod li;
pub mod plot;
pub mod section;
pub mod seeds;
pub mod sss;
pub mod translucency;
pub mod truth;

pub use section::{embed, SectionFn, SectionOutput, SuiteContext, SuiteOptions};

/// The error-against-time sections, one per technique with approximation knobs, in report order.
pub const ERROR_SECTIONS: &[(&str, SectionFn)] = &[
    (
        "translucency",
        crate::report::translucency::translucency_section as SectionFn,
    ),
    ("sss", sss_section as SectionFn),
    (
        "anti-aliasing",
        crate::report::antialias::antialias_section as SectionFn,
    ),
];

/// Writes one error-against-time report into a directory: its Markdown and the files written.
pub type WriteReportFn = fn(
    &crate::backend::GpuContext,
    &crate::backend::shader::ShaderCompiler,
    &crate::backend::shader::PipelineCache,
    &std::path::Path,
    &section::ReportOptions,
) -> Result<(String, Vec<std::path::PathBuf>)>;

/// The sections `lucent report NAME` writes on their own (besides `li`, which has its own
/// options), by name.
pub const STANDALONE_REPORTS: &[(&str, WriteReportFn)] = &[
    (
        "translucency",
        crate::report::translucency::write_translucency_report as WriteReportFn,
    ),
    ("sss", crate::report::sss::write_sss_report as WriteReportFn),
];

/// The SSS error-against-time report ([`crate::report::sss`]) as a section, written beside
/// `report.md`. Full run: the suite's size, 5 rounds after 1 warm-up (as `docs/report/sss.md`
/// was first measured); quick: 128x96, 1 round, no warm-up.
pub fn sss_section(ctx: &SuiteContext<'_>) -> Result<SectionOutput> {
    let opts = if ctx.options.quick {
        crate::report::section::ReportOptions {
            width: 128,
            height: 96,
            rounds: 1,
            warmup: 0,
        }
    } else {
        crate::report::section::ReportOptions {
            width: ctx.options.width,
            height: ctx.options.height,
            rounds: 5,
            warmup: 1,
        }
    };
    let (text, files) = crate::report::sss::write_sss_report(
        ctx.gpu,
        ctx.shaders,
        ctx.pipeline_cache,
        ctx.dir,
        &opts,
    )?;
    let mut markdown = embed(&text);
    // Its plot, linked where the section's own Markdown does not link it.
    for png in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
    {
        let name = file_name(png);
        if !text.contains(&format!("]({name})")) {
            let _ = writeln!(markdown, "\n![SSS error against time]({name})\n");
        }
    }
    Ok(SectionOutput {
        markdown,
        files,
        ..Default::default()
    })
}

/// The built-in scene a technique is measured on: the scene its module names (`auto`:
/// `mixed`, where every technique meets in one frame; `none`: `smoke`).
pub fn scene_for(technique: Technique) -> Result<String> {
    Ok(match technique {
        Technique::Auto => "mixed",
        Technique::None => "smoke",
        Technique::Only(t) => t.scene(),
    }
    .to_string())
}

/// Runs the suite and writes `report.md` (and the plots) under `dir`. Prints one progress line
/// per step to stderr. Returns the report's text and the files written.
pub fn run(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    dir: &Path,
    options: SuiteOptions,
) -> Result<(String, Vec<PathBuf>)> {
    if options.frames == 0 {
        return Err(LucentError::InvalidInput(
            "report: at least one frame must be measured".into(),
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| LucentError::file(dir, e))?;
    let started = Instant::now();
    let ctx = SuiteContext {
        gpu,
        shaders,
        pipeline_cache,
        dir,
        options,
    };
    let mut steps: Vec<(String, SectionFn)> = Vec::new();
    steps.push(("per-technique benchmarks".into(), techniques_section));
    steps.push(("the seeds' tables".into(), seeds_section));
    steps.push(("scaling".into(), scaling_section));
    for (name, f) in ERROR_SECTIONS {
        steps.push((format!("error against time: {name}"), *f));
    }
    let mut body = String::new();
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    let mut summary = Vec::new();
    for (i, (name, f)) in steps.iter().enumerate() {
        eprintln!(
            "report: [{}/{}] {name} ({:.0} s so far)",
            i + 1,
            steps.len(),
            started.elapsed().as_secs_f64()
        );
        let out = f(&ctx)?;
        body.push_str(&out.markdown);
        body.push('\n');
        files.extend(out.files);
        warnings.extend(out.warnings);
        summary.extend(out.summary);
    }
    let mut text = String::new();
    let _ = writeln!(
        text,
        "# lucent report{}\n\n\
         - device: {} (driver {})\n\
         - command: `lucent report{} --out {}`; ran in {:.0} s\n\
         - per-technique tables at {}x{}, {} frames after {} warm-up; every comparison in this \
         report is measured in one run (alternating or round-robin), because separate runs on a \
         shared machine differ by up to 15%\n",
        if options.quick { " (quick)" } else { "" },
        gpu.info.describe(),
        gpu.info.driver(),
        if options.quick { " --quick" } else { "" },
        dir.display(),
        started.elapsed().as_secs_f64(),
        options.width,
        options.height,
        options.frames,
        options.warmup,
    );
    if warnings.is_empty() {
        text.push_str("- every timing check passed\n\n");
    } else {
        for w in &warnings {
            let _ = writeln!(text, "- **warning**: {w}");
        }
        text.push('\n');
    }
    if !summary.is_empty() {
        text.push_str("Findings:\n\n");
        for line in &summary {
            let _ = writeln!(text, "- {line}");
        }
        text.push('\n');
    }
    text.push_str(&body);
    let md = dir.join("report.md");
    crate::files::write_file_atomic(&md, text.as_bytes())?;
    files.insert(0, md);
    Ok((text, files))
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned())
}

/// One technique's verified benchmark with its speed-of-light copies.
pub fn bench_technique(
    ctx: &SuiteContext<'_>,
    technique: Technique,
    scene_name: &str,
) -> Result<BenchReport> {
    let scene = crate::bake::scene::load_scene_baked(scene_name)?;
    let settings = FrameSettings {
        technique,
        ..FrameSettings::new(ctx.options.width, ctx.options.height)
    };
    let renderer = Renderer::new(ctx.gpu, ctx.shaders, ctx.pipeline_cache, &scene, settings)?;
    let copies = FloorFrame::for_renderer(ctx.gpu, ctx.shaders, ctx.pipeline_cache, &renderer);
    let result = copies.and_then(|mut copies| {
        let report = crate::measure::bench::run_with_floor(
            ctx.gpu,
            &renderer,
            Some(&mut copies),
            &scene,
            scene_name,
            &BenchOptions {
                frames: ctx.options.frames,
                warmup: ctx.options.warmup,
                isolate: true,
            },
        );
        let idle = ctx.gpu.wait_idle();
        copies.destroy(ctx.gpu);
        idle.and(report)
    });
    let idle = ctx.gpu.wait_idle();
    renderer.destroy(ctx.gpu);
    idle.and(result)
}

fn techniques_section(ctx: &SuiteContext<'_>) -> Result<SectionOutput> {
    let mut out = SectionOutput::default();
    let _ = writeln!(
        out.markdown,
        "## Per technique: passes, speed of light\n\n\
         Each technique on the scene made for it, subpasses merged as in production. Every \
         pass's copy reads and writes the pass's own formats at its resolution and is timed in \
         the same run (see `src/speed_of_light.rs`).\n"
    );
    for (name, technique) in Technique::all() {
        let scene = scene_for(technique)?;
        eprintln!("report:   bench `{name}` on `{scene}`");
        let report = bench_technique(ctx, technique, &scene)?;
        if !report.trusted {
            out.warnings.push(format!(
                "`{name}` on `{scene}`: the per-pass times could not be verified ({})",
                report.timing_mode
            ));
        }
        if let Some(rows) = &report.speed_of_light {
            let far: Vec<String> = rows
                .iter()
                .filter(|r| r.far_above)
                .map(|r| format!("`{}` {:.1}x", r.pass, r.ratio.unwrap_or(0.0)))
                .collect();
            let closest = rows
                .iter()
                .filter_map(|r| r.ratio.map(|x| (x, &r.pass)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            out.summary.push(format!(
                "`{name}` on `{scene}`: frame {:.2} ms; {}{}",
                report.frame_ms.median,
                if far.is_empty() {
                    format!(
                        "no pass above {}x its copy",
                        crate::measure::speed_of_light::FAR_ABOVE_FLOOR
                    )
                } else {
                    format!("far above their copy: {}", far.join(", "))
                },
                closest.map_or(String::new(), |(x, p)| format!(
                    "; closest to its floor: `{p}` {x:.2}x"
                ))
            ));
        }
        let md = report.markdown().replacen("## ", "### ", 1);
        out.markdown
            .push_str(&md.replace("\n### Speed of light", "\n#### Speed of light"));
        let png = ctx.dir.join(format!("passes-{name}.png"));
        let rows: Vec<BarRow> = report
            .passes
            .iter()
            .map(|p| BarRow {
                label: p.name.clone(),
                value: p.median_ms,
                floor: report
                    .speed_of_light
                    .as_ref()
                    .and_then(|rows| rows.iter().find(|r| r.pass == p.name))
                    .and_then(|r| r.floor_ms),
            })
            .collect();
        write_bars_png(
            &png,
            &format!(
                "`{name}` on {scene}, {}x{}: pass against its copy (median ms)",
                report.width, report.height
            ),
            "ms (median)",
            "pass",
            "copy (speed of light)",
            &rows,
        )?;
        let _ = writeln!(out.markdown, "\n![passes of {name}]({})\n", file_name(&png));
        out.files.push(png);
        if let Some(table) = technique.module().and_then(|m| m.published_timing()) {
            out.markdown.push_str(
                &crate::report::seeds::beside(&report, table).replacen("## ", "#### ", 1),
            );
            out.markdown.push('\n');
        }
    }
    Ok(out)
}

/// Li et al.'s triangle counts (all eight rows; quick: the first three).
fn li_counts(quick: bool) -> Vec<u64> {
    let n = if quick { 3 } else { LI_TABLE_1.len() };
    LI_TABLE_1.iter().take(n).map(|r| r.triangles).collect()
}

fn measure_with_progress(
    ctx: &SuiteContext<'_>,
    what: &str,
    configs: &[Config],
) -> Result<Vec<Measured>> {
    let rounds = ctx.options.frames;
    let warmup = ctx.options.warmup;
    let bar = crate::measure::bench::progress_bar(
        (rounds + warmup) as u64,
        // Unknown until measured: a run of many configurations is assumed long.
        configs.len() as f64,
        what,
    );
    let result = crate::measure::scaling::measure(
        ctx.gpu,
        ctx.shaders,
        ctx.pipeline_cache,
        configs,
        rounds,
        warmup,
        |done, _| bar.set_position(done as u64),
    );
    bar.finish_and_clear();
    result
}

fn seeds_section(ctx: &SuiteContext<'_>) -> Result<SectionOutput> {
    let mut out = SectionOutput::default();
    let device = ctx.gpu.info.describe();
    let _ = writeln!(
        out.markdown,
        "## The seeds' tables beside ours\n\n\
         The thesis's Tables 1 and 2 are beside the per-technique tables above (`control`: \
         Table 2; `lbb`: Table 1).\n"
    );
    // GDC 2011: grid125 all translucent, none against translucency, lighting separate.
    let (w, h) = (ctx.options.width, ctx.options.height);
    let cost = gdc_cost(
        ctx.gpu,
        ctx.shaders,
        ctx.pipeline_cache,
        &crate::bake::scene::load_scene_baked("grid125")?,
        "`grid125` (all 125 cubes translucent, 3 point lights)",
        (w, h),
        (ctx.options.frames, ctx.options.warmup),
    )?;
    out.markdown
        .push_str(&crate::report::seeds::gdc_beside(&cost).replacen("## ", "### ", 1));
    out.markdown.push('\n');
    // Li et al.: scaling:N at their counts, technique auto (their passes included), 512^2 and
    // 1024^2 light-space maps, one output size, all in one round-robin run.
    let (li, side) = li_points(ctx)?;
    let ours: Vec<LiOurs> = li[0]
        .iter()
        .zip(&li[1])
        .map(|(a, b)| LiOurs {
            triangles: a.triangles,
            frame_ms: [a.frame.median, b.frame.median],
            maps_ms: [a.pass_ms("light-space maps"), b.pass_ms("light-space maps")],
            layered_ms: [
                crate::report::li::layered_sum(a),
                crate::report::li::layered_sum(b),
            ],
        })
        .collect();
    let ratios = crate::report::seeds::li_ratios(&ours);
    let shown = |x: Option<f64>| x.map_or("-".to_string(), |x| format!("{x:.2}x"));
    out.summary.push(format!(
        "Li et al.'s Table 1 (`scaling:N`, technique `auto`, {side}x{side}): frame time 1024 / \
         512 light-space maps {} at {} triangles (theirs {:.2}x), triangles {} / {} {} at 512 \
         maps (theirs {:.2}x)",
        shown(ratios.ours_resolution[0]),
        li_counts(ctx.options.quick)[0],
        ratios.theirs_resolution[0],
        LI_TABLE_1[ratios.rows - 1].triangles,
        LI_TABLE_1[0].triangles,
        shown(ratios.ours_triangles[0]),
        ratios.theirs_triangles[0],
    ));
    out.markdown.push_str(
        &crate::report::seeds::li_beside(
            &device,
            &format!(
                "`scaling:N` (a procedural teapot of N triangles, Jensen's skin1 as a layered \
                 medium, one point light) under technique `{}` at {side}x{side} output, \
                 subpasses unmerged, medians of {} round-robin frames after {} warm-up (every \
                 row and both texture sizes in one run)",
                Technique::Auto.name(),
                ctx.options.frames,
                ctx.options.warmup
            ),
            &ours,
        )
        .replacen("## ", "### ", 1)
        .replace("\n### Cost follows", "\n#### Cost follows"),
    );
    let png = ctx.dir.join("li-table-1.png");
    let mut series = Vec::new();
    for (label, fps) in [("Li et al. 512", 0usize), ("Li et al. 1024", 1)] {
        series.push(PlotSeries {
            name: format!("{label} (theirs, 8800 GTS)"),
            points: LI_TABLE_1
                .iter()
                .map(|r| PlotPoint {
                    label: String::new(),
                    x: r.triangles as f64,
                    y: 1000.0 / if fps == 0 { r.fps_512 } else { r.fps_1024 },
                })
                .collect(),
        });
    }
    for (i, size) in LI_MAP_SIZES.iter().enumerate() {
        series.push(PlotSeries {
            name: format!("lucent, {size}^2 maps (ours, {device})"),
            points: li[i]
                .iter()
                .map(|m| PlotPoint {
                    label: String::new(),
                    x: m.triangles as f64,
                    y: m.frame.median,
                })
                .collect(),
        });
    }
    write_curves_png(
        &png,
        "Frame time against triangles: Li et al.'s Table 1 and lucent",
        "triangles",
        "frame ms (median; theirs 1000 / FPS)",
        &series,
    )?;
    let _ = writeln!(
        out.markdown,
        "\n![Li et al. beside lucent]({})\n",
        file_name(&png)
    );
    out.files.push(png);
    Ok(out)
}

/// The cost of GDC 2011 translucency on `scene`: techniques `none` and `translucency`
/// round-robin at `size`, subpasses unmerged so the lighting pass has its own time, medians of
/// `frames` after `warmup` (both counts in `rounds`).
pub fn gdc_cost(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scene: &crate::scene::Scene,
    scene_label: &str,
    (width, height): (u32, u32),
    (frames, warmup): (usize, usize),
) -> Result<TranslucencyCost> {
    let configs: Vec<Config> = [
        Technique::None,
        Technique::Only(&crate::features::translucency::TRANSLUCENCY),
    ]
    .iter()
    .map(|&t| Config {
        label: t.name().into(),
        x: 1.0,
        scene: scene.clone(),
        settings: crate::measure::scaling::settings(t, width, height),
    })
    .collect();
    let m = crate::measure::scaling::measure(
        gpu,
        shaders,
        pipeline_cache,
        &configs,
        frames,
        warmup,
        |_, _| {},
    )?;
    let lighting = |p: &Measured| p.pass_ms("lighting").unwrap_or(0.0);
    Ok(TranslucencyCost {
        device: gpu.info.describe(),
        setup: format!(
            "{scene_label}, {width}x{height}, lighting pass unmerged, medians of {frames} \
             round-robin frames"
        ),
        lighting_none_ms: lighting(&m[0]),
        lighting_translucency_ms: lighting(&m[1]),
        frame_ms: [m[0].frame.median, m[1].frame.median],
    })
}

/// Li et al.'s dynamic-texture resolutions: lucent's light-space map texels per face.
pub const LI_MAP_SIZES: [u32; 2] = [512, 1024];

/// The output size (square) Li et al.'s Table 1 is measured at: 1024x1024, `--quick` 256x256.
pub fn li_output_side(quick: bool) -> u32 {
    if quick {
        256
    } else {
        1024
    }
}

/// `scaling:N` at Li et al.'s counts under technique `auto` (Li et al.'s passes on the
/// layered teapot) with 512^2 and 1024^2 light-space maps at [`li_output_side`], every point
/// in one round-robin run; per map size the points in count order, and the output side.
fn li_points(ctx: &SuiteContext<'_>) -> Result<([Vec<Measured>; 2], u32)> {
    let counts = li_counts(ctx.options.quick);
    let side = li_output_side(ctx.options.quick);
    let mut scenes = Vec::new();
    for &n in &counts {
        scenes.push(crate::bake::scene::load_scene_baked(&format!(
            "scaling:{n}"
        ))?);
    }
    let mut configs = Vec::new();
    for &size in &LI_MAP_SIZES {
        for (&n, scene) in counts.iter().zip(&scenes) {
            let scene = scene.clone();
            let mut settings = crate::measure::scaling::settings(Technique::Auto, side, side);
            settings.shadows.enabled = true;
            settings.shadows.size = size;
            configs.push(Config {
                label: format!("{n}, {size}^2 maps"),
                x: crate::measure::scaling::triangles(&scene) as f64,
                scene,
                settings,
            });
        }
    }
    let mut measured = measure_with_progress(
        ctx,
        &format!("Li et al.'s Table 1, {side}x{side}"),
        &configs,
    )?;
    let at_1024 = measured.split_off(counts.len());
    Ok(([measured, at_1024], side))
}

fn curves(points: &[Measured]) -> Vec<PlotSeries> {
    let mut names: Vec<String> = points
        .first()
        .map(|p| p.passes.iter().map(|(n, _)| n.clone()).collect())
        .unwrap_or_default();
    names.push("frame".into());
    names
        .into_iter()
        .map(|name| PlotSeries {
            points: points
                .iter()
                .filter_map(|p| {
                    let y = if name == "frame" {
                        Some(p.frame.median)
                    } else {
                        p.pass_ms(&name)
                    }?;
                    Some(PlotPoint {
                        label: String::new(),
                        x: p.x,
                        y,
                    })
                })
                .collect(),
            name,
        })
        .collect()
}

fn scaling_section(ctx: &SuiteContext<'_>) -> Result<SectionOutput> {
    let mut out = SectionOutput::default();
    let quick = ctx.options.quick;
    let (w, h) = (ctx.options.width, ctx.options.height);
    let _ = writeln!(
        out.markdown,
        "## Scaling\n\n\
         Per-pass medians (in-frame timestamps, subpasses unmerged so geometry and lighting \
         have their own rows) of round-robin frames, {} rounds after {} warm-up.\n",
        ctx.options.frames, ctx.options.warmup
    );
    let mut axes: Vec<(&str, &str, String, Vec<Config>)> = Vec::new();
    // Triangles: the procedural teapot, technique none.
    let counts: Vec<u64> = if quick {
        vec![3_000, 30_000]
    } else {
        vec![3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000]
    };
    let mut tri = Vec::new();
    for n in counts {
        let scene = crate::bake::scene::load_scene_baked(&format!("scaling:{n}"))?;
        tri.push(Config {
            label: format!("{n}"),
            x: crate::measure::scaling::triangles(&scene) as f64,
            scene,
            settings: crate::measure::scaling::settings(Technique::None, w, h),
        });
    }
    axes.push((
        "triangles",
        "triangles",
        format!("`scaling:N`, technique `none`, {w}x{h}"),
        tri,
    ));
    // Resolution: the SSS control on `skin` (its blurs are per pixel).
    let sides: &[u32] = if quick {
        &[128, 256]
    } else {
        &[256, 512, 1024, 2048]
    };
    let skin = crate::bake::scene::load_scene_baked("skin")?;
    axes.push((
        "resolution",
        "pixels",
        "`skin`, technique `control`, square frames".into(),
        sides
            .iter()
            .map(|&s| Config {
                label: format!("{s}x{s}"),
                x: f64::from(s) * f64::from(s),
                scene: skin.clone(),
                settings: crate::measure::scaling::settings(
                    Technique::Only(&crate::features::sss::control::CONTROL),
                    s,
                    s,
                ),
            })
            .collect(),
    ));
    // Lights: `grid125` under translucency, n point lights on a ring.
    let lights: &[usize] = if quick {
        &[1, 8]
    } else {
        &[1, 2, 4, 8, 16, 32, 64]
    };
    let grid = crate::bake::scene::load_scene_baked("grid125")?;
    axes.push((
        "lights",
        "lights",
        format!("`grid125` with n point lights on a ring, technique `translucency`, {w}x{h}"),
        lights
            .iter()
            .map(|&n| Config {
                label: format!("{n}"),
                x: n as f64,
                scene: crate::report::section::with_lights(&grid, n),
                settings: crate::measure::scaling::settings(
                    Technique::Only(&crate::features::translucency::TRANSLUCENCY),
                    w,
                    h,
                ),
            })
            .collect(),
    ));
    for (axis, unit, setup, configs) in axes {
        eprintln!("report:   scaling with {axis}");
        let points = measure_with_progress(ctx, &format!("scaling: {axis}"), &configs)?;
        let grows: Vec<String> = crate::measure::scaling::growth(&points)
            .iter()
            .filter(|g| g.pass != "frame" && g.exponent >= 0.35)
            .map(|g| format!("`{}` (s = {:.2})", g.pass, g.exponent))
            .collect();
        out.summary.push(format!(
            "with {axis} ({}): {}",
            setup.replace('`', ""),
            if grows.is_empty() {
                "no pass grows".to_string()
            } else {
                let verb = if grows.len() == 1 { "grows" } else { "grow" };
                format!("{} {verb}", grows.join(", "))
            }
        ));
        let _ = writeln!(out.markdown, "### Against {axis}: {setup}\n");
        out.markdown
            .push_str(&crate::measure::scaling::markdown(axis, unit, &points));
        let png = ctx.dir.join(format!("scaling-{axis}.png"));
        write_curves_png(
            &png,
            &format!("Time against {axis}: {}", setup.replace('`', "")),
            unit,
            "ms (median)",
            &curves(&points),
        )?;
        let _ = writeln!(
            out.markdown,
            "\n![time against {axis}]({})\n",
            file_name(&png)
        );
        out.files.push(png);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_gets_a_scene_it_does_something_in() {
        assert_eq!(scene_for(Technique::None).unwrap(), "smoke");
        assert_eq!(
            scene_for(Technique::Only(
                &crate::features::translucency::TRANSLUCENCY
            ))
            .unwrap(),
            "cubes"
        );
        assert_eq!(
            scene_for(Technique::Only(&crate::features::sss::control::CONTROL)).unwrap(),
            "skin"
        );
    }

    #[test]
    fn quick_preset_is_smaller_than_the_full_one() {
        let (q, f) = (SuiteOptions::quick(), SuiteOptions::full());
        assert!(q.quick && !f.quick);
        assert!(q.width * q.height < f.width * f.height && q.frames < f.frames);
        assert_eq!(li_counts(false).len(), 8);
        assert_eq!(li_counts(true), [2_900, 6_400, 63_932]);
    }
}
