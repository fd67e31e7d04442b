//! What the report's sections share: the suite's options, the context a section runs in, what
//! it returns, the options of an error-against-time section, and the scene variants sections
//! measure (so the suite and its sections import this module, never each other).

use std::path::{Path, PathBuf};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use glam::Vec3;

use crate::scene::{Light, Scene};
use crate::Result;

/// How much the suite measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SuiteOptions {
    /// The small preset (`--quick`: under 2 minutes on lavapipe).
    pub quick: bool,
    /// Benchmark size of the per-technique tables.
    pub width: u32,
    /// Benchmark size of the per-technique tables.
    pub height: u32,
    /// Measured frames (rounds, for round-robin sections).
    pub frames: usize,
    /// Discarded frames first.
    pub warmup: usize,
}

impl SuiteOptions {
    /// The default run: 1024x768 tables, the full axes (under 15 minutes on lavapipe).
    pub fn full() -> Self {
        Self {
            quick: false,
            width: 1024,
            height: 768,
            frames: 25,
            warmup: 3,
        }
    }

    /// `--quick`: small frames, few rounds, short axes.
    pub fn quick() -> Self {
        Self {
            quick: true,
            width: 256,
            height: 192,
            frames: 3,
            warmup: 1,
        }
    }
}

/// What a section needs.
pub struct SuiteContext<'a> {
    /// The device.
    pub gpu: &'a GpuContext,
    /// Shader compiler.
    pub shaders: &'a ShaderCompiler,
    /// Pipeline cache.
    pub pipeline_cache: &'a PipelineCache,
    /// Output directory (exists).
    pub dir: &'a Path,
    /// The run's options.
    pub options: SuiteOptions,
}

/// What a section produced.
#[derive(Clone, Debug, Default)]
pub struct SectionOutput {
    /// Markdown for `report.md` (headings at level 2 and below).
    pub markdown: String,
    /// Files it wrote (plots, its own Markdown).
    pub files: Vec<PathBuf>,
    /// Problems to list in the summary (e.g. untrusted timing).
    pub warnings: Vec<String>,
    /// Findings to list in the summary at the top.
    pub summary: Vec<String>,
}

/// One section of the suite.
pub type SectionFn = fn(&SuiteContext<'_>) -> Result<SectionOutput>;

/// A section's own Markdown file embedded in `report.md`: every heading one level down.
pub fn embed(text: &str) -> String {
    let mut out: String = text
        .lines()
        .map(|l| {
            if l.starts_with('#') {
                format!("#{l}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    out.push('\n');
    out
}

/// Options of a report run.
#[derive(Clone, Copy, Debug)]
pub struct ReportOptions {
    /// Frame size of every variant.
    pub width: u32,
    /// Frame size of every variant.
    pub height: u32,
    /// Measured rounds (one frame of each variant per round).
    pub rounds: usize,
    /// Discarded rounds first.
    pub warmup: usize,
}

/// `scene` with `n` point lights on a ring around its centre (deterministic colours).
pub fn with_lights(scene: &Scene, n: usize) -> Scene {
    let mut s = scene.clone();
    s.lights = (0..n)
        .map(|i| {
            let a = i as f32 / n as f32 * std::f32::consts::TAU;
            let color = Vec3::new(
                0.6 + 0.4 * (a).cos().abs(),
                0.6 + 0.4 * (a * 1.7).sin().abs(),
                0.6 + 0.4 * (a * 2.3).cos().abs(),
            );
            // Total intensity held constant so images stay comparable across counts.
            Light::point(
                Vec3::new(
                    3.5 * a.cos(),
                    1.0 + 0.8 * (a * 3.0).sin(),
                    3.5 * a.sin() - 0.5,
                ),
                color,
                30.0 / n as f32,
                12.0,
            )
        })
        .collect();
    s
}
