//! `lucent report truth`: every technique, and each of its knobs, on every path-traced truth
//! scene, as (error against the truth, milliseconds); which technique comes closest to the
//! light transport it imitates under a few cost budgets.
//!
//! For each truth of the truth directory (`tools/truth`, [`crate::measure::truth`]), and for
//! each region a truth names (`truths/NAME.regions.toml`: a head's ear, measured on its own as
//! `NAME-REGION` from the same frames):
//! - **error**: every variant renders the scene once at the truth's size; its linear HDR frame
//!   is measured against the truth over the object's pixels: relative mean absolute error,
//!   energy per channel, and FLIP after the scene's tonemap.
//! - **time**: every variant's frames at the report's size (default: the truth's), taken
//!   round-robin (one frame of each variant per round, after warm-up rounds), so a shared, noisy
//!   machine slows every variant alike; the median frame (submit to fence) and its ratio to
//!   plain lighting's (`none`) in the same run.
//!
//! The variants ([`truth_variants`]) come from the technique registry: `auto`, `none`, every
//! registered technique at its defaults, then (without `--quick`) each knob a technique lists
//! turned to each of its values (both ends of a whole-number range; continuous knobs are left at
//! their defaults and named in the report). A new technique is in this report by registering.
//!
//! Writes `truth.md` and one `truth-NAME.png` plot per scene.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::knob::Given;
use crate::frame::{render_frame, FrameSettings, Technique};
use crate::measure::round_robin::{self, IfUnbuildable};
use crate::measure::stats::Stats;
use crate::measure::truth::{load_truth, measure, truth_names, Truth, TruthError};
use crate::report::plot::{write_scatter_png, PlotPoint, PlotSeries};
use crate::{LucentError, Result};

/// The cost budgets of the summary table, as multiples of plain lighting's frame.
pub const BUDGETS: &[f64] = &[1.25, 1.5, 2.0, 4.0];

/// Errors within this fraction of each other count as equal when the budget table picks the
/// best variant (the cheaper wins): far below any difference a viewer sees.
pub const TIE: f64 = 0.005;

/// "Near the best" in the report's choice of a technique: within this fraction of the least
/// error.
pub const NEAR_BEST: f64 = 0.1;

/// What `lucent report truth` measures.
#[derive(Clone, Debug)]
pub struct TruthOptions {
    /// The truth directory (`scenes/` and `truths/`).
    pub truths: PathBuf,
    /// Only these scenes (by name); `None`: every scene with a truth.
    pub scenes: Option<Vec<String>>,
    /// Techniques at their defaults only (no knob variants).
    pub quick: bool,
    /// The timed frames' size; `None`: each truth's own.
    pub size: Option<(u32, u32)>,
    /// Measured rounds (one frame of each variant per round).
    pub rounds: usize,
    /// Discarded rounds first.
    pub warmup: usize,
}

impl TruthOptions {
    /// The full report: every knob, 9 rounds after 2 warm-up rounds.
    pub fn full(truths: PathBuf) -> Self {
        Self {
            truths,
            scenes: None,
            quick: false,
            size: None,
            rounds: 9,
            warmup: 2,
        }
    }

    /// `--quick`: techniques at their defaults, 2 rounds after 1 warm-up round.
    pub fn quick(truths: PathBuf) -> Self {
        Self {
            quick: true,
            rounds: 2,
            warmup: 1,
            ..Self::full(truths)
        }
    }
}

/// One configuration to measure.
#[derive(Clone, Debug)]
pub struct TruthVariant {
    /// The technique (the plot's series).
    pub technique: Technique,
    /// The knob turned and its value, as on the command line; `None`: the defaults.
    pub knob: Option<String>,
    /// The frame's settings (size set per measurement).
    pub settings: FrameSettings,
}

impl TruthVariant {
    /// The variant as the command line says it: `burley`, `burley --burley-budget 4`.
    pub fn name(&self) -> String {
        match &self.knob {
            Some(knob) => format!("{} {knob}", self.technique.name()),
            None => self.technique.name().to_string(),
        }
    }
}

fn given_text(value: Given) -> String {
    match value {
        Given::Switch => String::new(),
        Given::Whole(n) => format!(" {n}"),
        Given::Number(x) => format!(" {x}"),
        Given::Choice(name) => format!(" {name}"),
    }
}

/// Every variant: `auto`, `none` and each registered technique at its defaults, then (unless
/// `quick`) each knob of each technique at each of its values other than its default. Returns
/// the variants and the continuous knobs left at their defaults (`--flag`).
pub fn truth_variants(quick: bool) -> (Vec<TruthVariant>, Vec<&'static str>) {
    let base = |technique| FrameSettings {
        technique,
        export_hdr: true,
        ..FrameSettings::new(1, 1)
    };
    let mut variants: Vec<TruthVariant> = Technique::all()
        .into_iter()
        .map(|(_, technique)| TruthVariant {
            technique,
            knob: None,
            settings: base(technique),
        })
        .collect();
    let mut continuous = Vec::new();
    if quick {
        return (variants, continuous);
    }
    for &module in crate::features::registry::TECHNIQUES {
        let technique = Technique::Only(module);
        for &knob in module.knobs() {
            let Some(values) = knob.takes.values() else {
                if !continuous.contains(&knob.flag) {
                    continuous.push(knob.flag);
                }
                continue;
            };
            for value in values.into_iter().filter(|&v| Some(v) != knob.default) {
                let mut settings = base(technique);
                settings.set_knob(knob, value);
                variants.push(TruthVariant {
                    technique,
                    knob: Some(format!("{}{}", knob.flag, given_text(value))),
                    settings,
                });
            }
        }
    }
    (variants, continuous)
}

/// What one variant measured on one truth.
#[derive(Clone, Debug)]
pub struct TruthResult {
    /// The variant.
    pub variant: TruthVariant,
    /// Its frame against the truth, or why it could not render the scene.
    pub error: std::result::Result<TruthError, String>,
    /// Whole frame (submit to fence), ms, at the timed size.
    pub frame: Stats,
    /// It rendered exactly plain lighting's picture (nothing in the scene for it to act on):
    /// never picked as the best choice.
    pub renders_as_none: bool,
}

/// One truth scene's results.
pub struct SceneResults {
    /// The truth (scene, size, samples, noise).
    pub truth: Truth,
    /// What the scene file's leading comment says it is.
    pub description: String,
    /// The timed frames' size.
    pub timed_size: (u32, u32),
    /// Every variant, in [`truth_variants`] order.
    pub results: Vec<TruthResult>,
}

impl SceneResults {
    /// Plain lighting's result.
    pub fn none_result(&self) -> Option<&TruthResult> {
        self.results
            .iter()
            .find(|r| r.variant.technique == Technique::None && r.variant.knob.is_none())
    }

    /// Plain lighting's median frame in this run.
    pub fn none_ms(&self) -> f64 {
        self.none_result().map_or(f64::NAN, |r| r.frame.median)
    }

    /// The variant with the least error whose frame is at most `budget` times plain
    /// lighting's (`None`: no limit); of variants within [`TIE`] of that error, the cheapest
    /// (`auto` and `none` on a plain sphere differ in rounding, not in what they show).
    pub fn best_within(&self, budget: Option<f64>) -> Option<&TruthResult> {
        let limit = budget.map_or(f64::INFINITY, |b| b * self.none_ms());
        let within: Vec<(&TruthResult, f64)> = self
            .results
            .iter()
            .filter(|r| r.frame.median <= limit && !r.renders_as_none)
            .filter_map(|r| r.error.as_ref().ok().map(|e| (r, e.error)))
            .collect();
        let least = within.iter().map(|&(_, e)| e).fold(f64::INFINITY, f64::min);
        within
            .into_iter()
            .filter(|&(_, e)| e <= least * (1.0 + TIE))
            .min_by(|a, b| a.0.frame.median.total_cmp(&b.0.frame.median))
            .map(|(r, _)| r)
    }
}

/// The leading `#` comment of a scene file, as one paragraph.
fn scene_description(path: &Path) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim())
        .collect::<Vec<_>>()
        .join(" ")
}

/// Measures every variant on every truth of `opts.truths`.
pub fn run(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    opts: &TruthOptions,
) -> Result<Vec<SceneResults>> {
    if opts.rounds == 0 {
        return Err(LucentError::InvalidInput(
            "report truth: --rounds must be at least 1".into(),
        ));
    }
    let available = truth_names(&opts.truths)?;
    let names = match &opts.scenes {
        None => available.clone(),
        Some(wanted) => {
            if let Some(unknown) = wanted.iter().find(|w| !available.contains(w)) {
                return Err(LucentError::InvalidInput(format!(
                    "report truth: no truth '{unknown}' in {}; available: {}",
                    opts.truths.display(),
                    available.join(", ")
                )));
            }
            wanted.clone()
        }
    };
    if names.is_empty() {
        return Err(LucentError::InvalidInput(format!(
            "report truth: {} holds no scene with a truth (tools/truth/README.md says how to \
             render one)",
            opts.truths.display()
        )));
    }
    let (variants, _) = truth_variants(opts.quick);
    let mut out = Vec::with_capacity(names.len());
    for name in &names {
        let truth = load_truth(&opts.truths, name)?;
        let description = scene_description(&truth.scene_path);
        let frames: Vec<std::result::Result<Vec<f32>, String>> = variants
            .iter()
            .map(|v| {
                let settings = FrameSettings {
                    width: truth.width,
                    height: truth.height,
                    ..v.settings
                };
                render_frame(gpu, shaders, cache, &truth.scene, settings)
                    .map_err(|e| e.to_string())?
                    .hdr
                    .ok_or_else(|| "no HDR frame exported".to_string())
            })
            .collect();
        // Plain lighting's picture: a variant that renders exactly it has nothing to act on in
        // this scene (an SSS blur on a scene without SSS materials).
        let plain = variants
            .iter()
            .position(|v| v.technique == Technique::None && v.knob.is_none())
            .and_then(|i| frames[i].as_ref().ok());
        let timed_size = opts.size.unwrap_or((truth.width, truth.height));
        let (width, height) = timed_size;
        // A variant that cannot build its frame sits the timing out with NaN times; its error
        // says why.
        let timed = round_robin::time_frames(
            gpu,
            shaders,
            cache,
            variants.iter().map(|v| {
                let settings = FrameSettings {
                    width,
                    height,
                    export_hdr: false,
                    ..v.settings
                };
                (&truth.scene, settings)
            }),
            IfUnbuildable::SitOut,
            opts.rounds,
            opts.warmup,
            |_, _| {},
        )?;
        let results = |truth: &Truth| -> Vec<TruthResult> {
            variants
                .iter()
                .zip(&frames)
                .zip(&timed)
                .map(|((variant, hdr), timed)| TruthResult {
                    variant: variant.clone(),
                    error: hdr
                        .as_ref()
                        .map_err(Clone::clone)
                        .and_then(|hdr| measure(truth, hdr).map_err(|e| e.to_string())),
                    renders_as_none: variant.technique != Technique::None
                        && hdr.as_ref().ok().zip(plain).is_some_and(|(a, b)| a == b),
                    frame: timed.wall(),
                })
                .collect()
        };
        // Each region of the frame (a head's ear) is a row of its own: the same frames and
        // times, measured over its pixels only.
        let parts: Vec<SceneResults> = truth
            .regions
            .iter()
            .map(|region| {
                let part = truth.region(region);
                let [x0, y0, x1, y1] = region.rect;
                SceneResults {
                    results: results(&part),
                    truth: part,
                    description: format!(
                        "`{}` measured over its {} only (pixels x {x0}..{x1}, y {y0}..{y1} of \
                         the truth's frame): {description}",
                        truth.name, region.name
                    ),
                    timed_size,
                }
            })
            .collect();
        out.push(SceneResults {
            results: results(&truth),
            truth,
            description,
            timed_size,
        });
        out.extend(parts);
    }
    Ok(out)
}

/// The report as Markdown.
pub fn markdown(scenes: &[SceneResults], opts: &TruthOptions, device: &str) -> String {
    let mut out = String::new();
    let (_, continuous) = truth_variants(opts.quick);
    let size = opts
        .size
        .map_or("each truth's size".to_string(), |(w, h)| format!("{w}x{h}"));
    let _ = writeln!(
        out,
        "# lucent against the path-traced truth\n\n\
         - device: {device}\n\
         - truths: `{}` (Mitsuba 3 `volpath`, tools/truth/README.md); each scene's samples and \
         noise below\n\
         - error: relative mean absolute error `sum |L - T| / sum T` over the object's pixels \
         (wholly covered, eroded one pixel), at the truth's size; energy: `sum L / sum T` per \
         channel; FLIP: mean over the same pixels after the scene's tonemap (exposure, ACES, \
         sRGB)\n\
         - time: frames at {size}, {} rounds round-robin after {} warm-up rounds, submit to \
         fence; `/ none` is the ratio to plain lighting's frame in the same run\n\
         - variants: `auto`, `none`, every registered technique at its defaults{}\n\
         - generated by `lucent report truth --out DIR{}{}`\n",
        opts.truths.display(),
        opts.rounds,
        opts.warmup,
        if opts.quick {
            " (`--quick`: no knob variants)".to_string()
        } else if continuous.is_empty() {
            ", then each knob of each technique at each of its values".to_string()
        } else {
            format!(
                ", then each knob of each technique at each of its values (both ends of a \
                 whole-number range); continuous knobs stay at their defaults: {}",
                continuous
                    .iter()
                    .map(|k| format!("`{k}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        },
        if opts.quick { " --quick" } else { "" },
        opts.size
            .map_or(String::new(), |(w, h)| format!(" --size {w}x{h}")),
    );
    let _ = writeln!(out, "## The best technique under a cost budget\n");
    let _ = writeln!(
        out,
        "The variant with the least error whose frame costs at most the budget times plain \
         lighting's (same run), per scene: its error, and its cost as a multiple of plain \
         lighting's. Errors within {:.1}% of each other count as equal; the cheaper wins. A \
         variant that renders exactly plain lighting's picture (marked `(= none)` in the \
         scene's table: nothing in the scene for it to act on) is never picked.\n",
        TIE * 100.0
    );
    let mut header = "| scene | none |".to_string();
    let mut rule = "|---|---|".to_string();
    for b in BUDGETS {
        let _ = write!(header, " <= {b}x none |");
        rule.push_str("---|");
    }
    header.push_str(" any cost |");
    rule.push_str("---|");
    let _ = writeln!(out, "{header}\n{rule}");
    for s in scenes {
        let none = s.none_result();
        let cell = |r: Option<&TruthResult>| match r {
            Some(r) => match &r.error {
                Ok(e) => format!(
                    "`{}` {:.3} ({:.2}x)",
                    r.variant.name(),
                    e.error,
                    r.frame.median / s.none_ms()
                ),
                Err(_) => "-".into(),
            },
            None => "-".into(),
        };
        let mut row = format!(
            "| {} | {} |",
            s.truth.name,
            none.and_then(|r| r.error.as_ref().ok())
                .map_or("-".into(), |e| format!("{:.3}", e.error))
        );
        for &b in BUDGETS {
            let _ = write!(row, " {} |", cell(s.best_within(Some(b))));
        }
        let _ = write!(row, " {} |", cell(s.best_within(None)));
        let _ = writeln!(out, "{row}");
    }
    let _ = writeln!(
        out,
        "\n## Choosing a technique\n\n\
         Per scene: the variant closest to the truth at any cost, the cheapest variant within \
         {:.0}% of that error (what to pick when the frame budget matters), and plain \
         lighting's error (what the techniques buy). A technique's error here is against the \
         light transport it imitates, so a variant that is cheaper and as close is the better \
         choice for that material, whatever its own equations' accuracy.\n",
        NEAR_BEST * 100.0
    );
    for s in scenes {
        let (Some(best), Some(none)) = (s.best_within(None), s.none_result()) else {
            continue;
        };
        let (Ok(best_error), Ok(none_error)) = (&best.error, &none.error) else {
            continue;
        };
        let near = s
            .results
            .iter()
            .filter(|r| r.frame.median.is_finite() && !r.renders_as_none)
            .filter(|r| {
                r.error
                    .as_ref()
                    .is_ok_and(|e| e.error <= best_error.error * (1.0 + NEAR_BEST))
            })
            .min_by(|a, b| a.frame.median.total_cmp(&b.frame.median))
            .unwrap_or(best);
        let near_error = near.error.as_ref().map_or(f64::NAN, |e| e.error);
        let _ = writeln!(
            out,
            "- **{}**: closest `{}` (error {:.3}, {:.2}x plain lighting's frame, energy {:.2} / \
             {:.2} / {:.2}); cheapest within {:.0}%: `{}` ({:.3}, {:.2}x); plain lighting {:.3}.",
            s.truth.name,
            best.variant.name(),
            best_error.error,
            best.frame.median / s.none_ms(),
            best_error.energy[0],
            best_error.energy[1],
            best_error.energy[2],
            NEAR_BEST * 100.0,
            near.variant.name(),
            near_error,
            near.frame.median / s.none_ms(),
            none_error.error,
        );
    }
    for s in scenes {
        let _ = writeln!(
            out,
            "\n## {}\n\n{}\n\n- truth: {}x{}, {} samples per pixel, noise {} (half the \
             relative difference of two seeds' 4x4-pixel block means); {} object pixels\n\
             - timed at {}x{}; plain lighting {:.2} ms\n\n\
             ![error against time](truth-{}.png)\n",
            s.truth.name,
            s.description,
            s.truth.width,
            s.truth.height,
            s.truth.spp.map_or("?".into(), |n| n.to_string()),
            s.truth.noise.map_or("?".into(), |n| format!("{n:.4}")),
            s.truth.object_pixels(),
            s.timed_size.0,
            s.timed_size.1,
            s.none_ms(),
            s.truth.name,
        );
        let _ = writeln!(
            out,
            "| variant | frame ms | / none | error | FLIP | energy R | energy G | energy B |\n\
             |---|---:|---:|---:|---:|---:|---:|---:|"
        );
        for r in &s.results {
            let (ms, ratio) = (r.frame.median, r.frame.median / s.none_ms());
            match &r.error {
                Ok(e) => {
                    let _ = writeln!(
                        out,
                        "| `{}`{} | {ms:.2} | {ratio:.2}x | {:.4} | {:.4} | {:.3} | {:.3} | {:.3} |",
                        r.variant.name(),
                        if r.renders_as_none { " (= `none`)" } else { "" },
                        e.error,
                        e.flip,
                        e.energy[0],
                        e.energy[1],
                        e.energy[2]
                    );
                }
                Err(why) => {
                    let _ = writeln!(
                        out,
                        "| `{}` | {ms:.2} | {ratio:.2}x | not rendered: {} | | | | |",
                        r.variant.name(),
                        why.replace('|', "/").replace('\n', " ")
                    );
                }
            }
        }
    }
    out
}

/// Runs the truth report and writes `truth.md` and a `truth-NAME.png` plot per scene into
/// `out`. Returns the Markdown and the files written.
pub fn write_truth_report(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    out: &Path,
    opts: &TruthOptions,
) -> Result<(String, Vec<PathBuf>)> {
    let scenes = run(gpu, shaders, cache, opts)?;
    let text = markdown(&scenes, opts, &gpu.info.describe());
    std::fs::create_dir_all(out)
        .map_err(|e| LucentError::InvalidInput(format!("{}: {e}", out.display())))?;
    let md = out.join("truth.md");
    crate::files::write_file_atomic(&md, text.as_bytes())?;
    let mut files = vec![md];
    for s in &scenes {
        let mut series: Vec<PlotSeries> = Vec::new();
        for r in &s.results {
            let Ok(e) = &r.error else { continue };
            if !r.frame.median.is_finite() {
                continue;
            }
            let point = PlotPoint {
                label: r.variant.knob.clone().unwrap_or_default(),
                x: r.frame.median,
                y: e.error,
            };
            let name = r.variant.technique.name();
            match series.iter_mut().find(|p| p.name == name) {
                Some(p) => p.points.push(point),
                None => series.push(PlotSeries {
                    name: name.into(),
                    points: vec![point],
                }),
            }
        }
        let png = out.join(format!("truth-{}.png", s.truth.name));
        write_scatter_png(
            &png,
            &format!("{}: error against the path-traced truth", s.truth.name),
            &format!("frame ms ({}x{})", s.timed_size.0, s.timed_size.1),
            "sum |lucent - truth| / sum truth (object pixels)",
            &series,
            false,
        )?;
        files.push(png);
    }
    Ok((text, files))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variants_cover_every_technique_and_turn_each_knob() {
        let (quick, _) = truth_variants(true);
        assert_eq!(quick.len(), Technique::all().len());
        let (full, continuous) = truth_variants(false);
        for &module in crate::features::registry::TECHNIQUES {
            for knob in module.knobs() {
                let turned = full.iter().any(|v| {
                    v.technique == Technique::Only(module)
                        && v.knob.as_deref().is_some_and(|k| k.starts_with(knob.flag))
                });
                assert!(
                    turned || continuous.contains(&knob.flag),
                    "{} {}: neither measured nor named as continuous",
                    module.name(),
                    knob.flag
                );
            }
        }
        // Every knob variant differs from its technique's defaults.
        for v in full.iter().filter(|v| v.knob.is_some()) {
            let defaults = full
                .iter()
                .find(|d| d.technique == v.technique && d.knob.is_none())
                .unwrap();
            assert!(
                v.settings != defaults.settings,
                "{} changes nothing",
                v.name()
            );
        }
    }
}
