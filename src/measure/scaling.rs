//! Scaling: frame and per-pass time against triangle count, resolution and light count.
//!
//! Every point of one axis is a frame of its own (its scene and settings built once), and the
//! points are measured round-robin ([`round_robin`]): one frame of each per round, after warm-up
//! rounds, so a noisy, shared machine slows every point alike and the curve's shape holds.
//! Frames are compiled without subpass merging, so the G-buffer and the lighting pass have their
//! own timestamp pairs (the geometry cost and the per-pixel lighting cost are what the axes
//! separate).
//!
//! [`growth`] fits each pass's time as `a * x^s` over the axis (least squares in log-log) and
//! says what the exponent means: about 1 grows in proportion, about 0 does not grow.

use std::fmt::Write as _;

use serde::Serialize;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{FrameSettings, Technique};
use crate::graph::CompileOptions;
use crate::measure::round_robin::{self, IfUnbuildable};
use crate::measure::stats::Stats;
use crate::scene::Scene;
use crate::Result;

/// One point of a curve: a scene under settings, at an axis value.
#[derive(Clone)]
pub struct Config {
    /// Label (e.g. "100k triangles").
    pub label: String,
    /// The axis value (triangles, pixels per side, lights).
    pub x: f64,
    /// What is drawn.
    pub scene: Scene,
    /// How.
    pub settings: FrameSettings,
}

/// What one point measured.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    /// Its label.
    pub label: String,
    /// The axis value.
    pub x: f64,
    /// Per physical pass: name and in-frame timestamp statistics.
    pub passes: Vec<(String, Stats)>,
    /// Frame wall time, submit to fence.
    pub frame: Stats,
    /// Triangles drawn per frame.
    pub triangles: u64,
}

impl Measured {
    /// Median of the pass named `name`, if the frame has it.
    pub fn pass_ms(&self, name: &str) -> Option<f64> {
        self.passes
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, s)| s.median)
    }

    /// Sum of the pass medians over the frame's median (the benchmark's sum check).
    pub fn sum_share(&self) -> f64 {
        let sum: f64 = self.passes.iter().map(|(_, s)| s.median).sum();
        // Guarded: a frame measured at 0 ms (never on a real device) gives 0, not NaN.
        if self.frame.median > 0.0 {
            sum / self.frame.median
        } else {
            0.0
        }
    }
}

/// Frame settings for scaling points: technique at a size, unmerged (see the module docs).
pub fn settings(technique: Technique, width: u32, height: u32) -> FrameSettings {
    FrameSettings {
        technique,
        compile: CompileOptions {
            merge: false,
            alias: true,
            ..CompileOptions::default()
        },
        ..FrameSettings::new(width, height)
    }
}

/// Measures `configs` round-robin: `warmup` discarded rounds, then `rounds` measured ones.
/// `progress` is called after each round with (done, total).
pub fn measure(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    configs: &[Config],
    rounds: usize,
    warmup: usize,
    progress: impl FnMut(usize, usize),
) -> Result<Vec<Measured>> {
    let frames = round_robin::time_frames(
        gpu,
        shaders,
        pipeline_cache,
        configs.iter().map(|c| (&c.scene, c.settings)),
        IfUnbuildable::Fail,
        // At least one measured round: every point needs a median.
        rounds.max(1),
        warmup,
        progress,
    )?;
    Ok(configs
        .iter()
        .zip(&frames)
        .map(|(c, frames)| Measured {
            label: c.label.clone(),
            x: c.x,
            passes: frames.pass_stats(),
            frame: frames.wall(),
            triangles: triangles(&c.scene),
        })
        .collect())
}

/// Triangles a frame of `scene` draws (each object draws its whole mesh).
pub fn triangles(scene: &Scene) -> u64 {
    scene
        .objects
        .iter()
        .filter_map(|o| scene.meshes.get(o.mesh))
        .map(|m| m.triangle_count() as u64)
        .sum()
}

/// How one pass (or the frame) grows along an axis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Growth {
    /// Pass name, or "frame".
    pub pass: String,
    /// Fitted exponent `s` of `ms = a * x^s`.
    pub exponent: f64,
    /// Time at the last point over time at the first.
    pub last_over_first: f64,
    /// Least-squares line `base + per_unit * x`: the time at x = 0, ms.
    pub base: f64,
    /// The line's slope: ms per unit of x.
    pub per_unit: f64,
}

impl Growth {
    /// The exponent in words.
    pub fn verdict(&self) -> &'static str {
        match self.exponent {
            s if s >= 1.3 => "grows faster than in proportion",
            s if s >= 0.75 => "grows in proportion",
            s if s >= 0.35 => "grows, less than in proportion",
            s if s >= 0.1 => "grows weakly",
            s if s > -0.1 => "flat",
            _ => "shrinks",
        }
    }
}

/// Least-squares slope of `ln y` against `ln x` over the points with both positive (`None`
/// with fewer than two such points or no spread in x).
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    // Guarded: all points at one x have no slope.
    (sxx > 1e-12).then(|| sxy / sxx)
}

/// Least-squares line `(intercept, slope)` through the finite points (`None` with fewer than two
/// or no spread in x).
pub fn linear_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    // Guarded: all points at one x have no slope.
    (sxx > 1e-12).then(|| {
        let slope = sxy / sxx;
        (my - slope * mx, slope)
    })
}

/// Growth of every pass present at every point, and of the frame.
pub fn growth(points: &[Measured]) -> Vec<Growth> {
    let Some(first) = points.first() else {
        return Vec::new();
    };
    let mut names: Vec<String> = first
        .passes
        .iter()
        .map(|(n, _)| n.clone())
        .filter(|n| points.iter().all(|p| p.pass_ms(n).is_some()))
        .collect();
    names.push("frame".into());
    names
        .into_iter()
        .filter_map(|name| {
            let ms = |p: &Measured| {
                if name == "frame" {
                    p.frame.median
                } else {
                    p.pass_ms(&name).unwrap_or(0.0)
                }
            };
            let xy: Vec<(f64, f64)> = points.iter().map(|p| (p.x, ms(p))).collect();
            let exponent = log_log_slope(&xy)?;
            let (base, per_unit) = linear_fit(&xy)?;
            let last = points.last().map(ms).unwrap_or(0.0);
            let first_ms = ms(first);
            Some(Growth {
                pass: name,
                exponent,
                last_over_first: if first_ms > 0.0 { last / first_ms } else { 0.0 },
                base,
                per_unit,
            })
        })
        .collect()
}

/// One axis as Markdown: a table of per-pass medians per point and the growth verdicts.
pub fn markdown(axis: &str, unit: &str, points: &[Measured]) -> String {
    let mut out = String::new();
    let names: Vec<String> = points
        .first()
        .map(|p| p.passes.iter().map(|(n, _)| n.clone()).collect())
        .unwrap_or_default();
    let _ = write!(out, "| {unit} | triangles drawn |");
    for n in &names {
        let _ = write!(out, " {n} ms |");
    }
    out.push_str(" frame ms | passes / frame |\n|---:|---:|");
    for _ in &names {
        out.push_str("---:|");
    }
    out.push_str("---:|---:|\n");
    for p in points {
        let _ = write!(out, "| {} | {} |", p.label, p.triangles);
        for n in &names {
            let _ = write!(
                out,
                " {} |",
                p.pass_ms(n).map_or("-".into(), |m| format!("{m:.3}"))
            );
        }
        let _ = writeln!(
            out,
            " {:.3} | {:.0}% |",
            p.frame.median,
            p.sum_share() * 100.0
        );
    }
    let _ = writeln!(
        out,
        "\nGrowth along {axis} (x: {unit}; exponent s of a fit ms = a * x^s; 1: in proportion, 0: flat):\n"
    );
    // The line's slope in a unit that reads well on this axis.
    let (scale, per) = match unit {
        "triangles" => (1e5, "per 100k triangles"),
        "pixels" => (1e6, "per megapixel"),
        "lights" => (1.0, "per light"),
        _ => (1.0, "per unit"),
    };
    for g in growth(points) {
        let _ = writeln!(
            out,
            "- `{}`: s = {:.2}, {} (last / first {:.2}x); line: {:.3} ms {:+.3} ms {per}",
            g.pass,
            g.exponent,
            g.verdict(),
            g.last_over_first,
            g.base,
            g.per_unit * scale,
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_a_power_law_is_its_exponent() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&x| (x, 3.0 * x)).collect();
        assert!((log_log_slope(&pts).unwrap() - 1.0).abs() < 1e-9);
        let flat: Vec<(f64, f64)> = [1.0, 10.0, 100.0].iter().map(|&x| (x, 2.0)).collect();
        assert!(log_log_slope(&flat).unwrap().abs() < 1e-9);
        assert_eq!(log_log_slope(&[(1.0, 1.0)]), None);
        assert_eq!(log_log_slope(&[(2.0, 1.0), (2.0, 5.0)]), None);
        assert_eq!(log_log_slope(&[(0.0, 1.0), (-1.0, 5.0)]), None);
    }

    #[test]
    fn growth_names_what_grows() {
        let stat = |m| Stats {
            median: m,
            min: m,
            max: m,
        };
        let points: Vec<Measured> = [1.0f64, 4.0, 16.0]
            .iter()
            .map(|&x| Measured {
                label: format!("{x}"),
                x,
                passes: vec![("gbuffer".into(), stat(x)), ("tonemap".into(), stat(1.0))],
                frame: stat(x + 1.0),
                triangles: 0,
            })
            .collect();
        let g = growth(&points);
        assert_eq!(g[0].verdict(), "grows in proportion");
        assert_eq!(g[1].verdict(), "flat");
        assert_eq!(g[2].pass, "frame");
        let text = markdown("lights", "lights", &points);
        assert!(
            text.contains(
                "`gbuffer`: s = 1.00, grows in proportion (last / first 16.00x); \
                 line: 0.000 ms +1.000 ms per light"
            ),
            "{text}"
        );
        let (a, b) = linear_fit(&[(1.0, 3.0), (2.0, 5.0), (4.0, 9.0)]).unwrap();
        assert!((a - 1.0).abs() < 1e-9 && (b - 2.0).abs() < 1e-9);
        assert_eq!(linear_fit(&[(1.0, 1.0), (1.0, 2.0)]), None);
    }
}
