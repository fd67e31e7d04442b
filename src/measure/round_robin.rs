//! Round-robin frame timing: how the truth and SSS reports and [`crate::measure::scaling`] time
//! the variants they compare.
//!
//! Each variant (a scene under frame settings) gets its renderer and frame runner built once;
//! then every round takes one frame of each variant in turn, and the rounds after the warm-up
//! ones are kept. Taking the variants in turn, rather than one variant's frames in a block, means
//! a shared, noisy machine (a clock that ramps, a neighbour's load) slows every variant alike, so
//! their ratios hold even when the absolute times drift.
//!
//! [`time_frames`] returns every kept frame's times; [`VariantFrames`] turns them into the
//! [`Stats`] a report tabulates (the frame's wall time, each pass's, or any per-frame sum).

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{FrameRunner, FrameSettings, FrameTiming, Renderer};
use crate::measure::stats::Stats;
use crate::scene::Scene;
use crate::Result;

/// What a variant whose renderer cannot be built does to the run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IfUnbuildable {
    /// The run stops with the renderer's error, before any frame is timed.
    Fail,
    /// The variant sits the rounds out: it has no frames and NaN statistics, and the others are
    /// timed as usual (its own report says why it failed).
    SitOut,
}

/// One variant's kept frames.
#[derive(Clone, Debug, Default)]
pub struct VariantFrames {
    /// Its frame's physical passes by name, in recording order (empty when it sat out).
    pub pass_names: Vec<String>,
    /// The times of its frames after warm-up, one per measured round (empty when it sat out).
    pub frames: Vec<FrameTiming>,
}

impl VariantFrames {
    /// Statistics of one number per frame; NaN when the variant sat out, so a table shows it
    /// as unmeasured rather than as free.
    pub fn stats_of(&self, per_frame: impl Fn(&FrameTiming) -> f64) -> Stats {
        if self.frames.is_empty() {
            return Stats {
                median: f64::NAN,
                min: f64::NAN,
                max: f64::NAN,
            };
        }
        let samples: Vec<f64> = self.frames.iter().map(per_frame).collect();
        Stats::of(&samples)
    }

    /// Statistics of the frame's wall time, submit to fence.
    pub fn wall(&self) -> Stats {
        self.stats_of(|frame| frame.wall_ms)
    }

    /// Per physical pass: its name and the statistics of its in-frame timestamp time.
    pub fn pass_stats(&self) -> Vec<(String, Stats)> {
        self.pass_names
            .iter()
            .enumerate()
            .map(|(index, name)| {
                // Only frames whose timer recorded this pass count toward its samples.
                let samples: Vec<f64> = self
                    .frames
                    .iter()
                    .filter_map(|frame| frame.passes.get(index))
                    .map(|pass| pass.ms)
                    .collect();
                (name.clone(), Stats::of(&samples))
            })
            .collect()
    }
}

/// Times `variants` round-robin: `warmup` discarded rounds, then `rounds` kept ones, one frame
/// of each variant per round. `after_round` is called after each round with (rounds done, all
/// rounds). Returns each variant's kept frames, in the order given; every renderer and runner is
/// destroyed before it returns, on error too.
#[allow(clippy::too_many_arguments)]
pub fn time_frames<'a>(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    variants: impl IntoIterator<Item = (&'a Scene, FrameSettings)>,
    if_unbuildable: IfUnbuildable,
    rounds: usize,
    warmup: usize,
    mut after_round: impl FnMut(usize, usize),
) -> Result<Vec<VariantFrames>> {
    // One slot per variant; `None` for one that sits out.
    let mut renderers: Vec<Option<Renderer>> = Vec::new();
    let mut runners: Vec<Option<FrameRunner>> = Vec::new();
    let timed = (|| -> Result<Vec<VariantFrames>> {
        for (scene, settings) in variants {
            let renderer = match Renderer::new(gpu, shaders, pipeline_cache, scene, settings) {
                Ok(renderer) => Some(renderer),
                Err(_) if if_unbuildable == IfUnbuildable::SitOut => None,
                Err(e) => return Err(e),
            };
            // The renderer is kept before its runner is made, so a runner that fails still
            // leaves its renderer to be destroyed below.
            renderers.push(renderer);
            let renderer = renderers.last().and_then(Option::as_ref);
            let runner = renderer
                .map(|r| FrameRunner::new(gpu, r.executable.plan.physical.len()))
                .transpose()?;
            runners.push(runner);
        }
        let mut kept: Vec<VariantFrames> = renderers
            .iter()
            .map(|renderer| VariantFrames {
                pass_names: renderer.as_ref().map_or_else(Vec::new, |r| {
                    r.executable
                        .plan
                        .physical
                        .iter()
                        .map(|pass| pass.name.clone())
                        .collect()
                }),
                frames: Vec::with_capacity(rounds),
            })
            .collect();
        let total = warmup + rounds;
        for round in 0..total {
            for ((renderer, runner), kept) in renderers.iter().zip(&mut runners).zip(&mut kept) {
                if let (Some(renderer), Some(runner)) = (renderer, runner) {
                    let timing = runner.run_frame(gpu, &renderer.executable)?;
                    if round >= warmup {
                        kept.frames.push(timing);
                    }
                }
            }
            after_round(round + 1, total);
        }
        Ok(kept)
    })();
    crate::frame::destroy_after_idle(
        gpu,
        renderers.into_iter().flatten().collect(),
        runners.into_iter().flatten().collect(),
    )?;
    timed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::timer::ScopeTime;

    fn frame(wall_ms: f64, passes: &[f64]) -> FrameTiming {
        FrameTiming {
            wall_ms,
            passes: passes
                .iter()
                .enumerate()
                .map(|(i, &ms)| ScopeTime {
                    name: format!("pass {i}"),
                    ms,
                })
                .collect(),
        }
    }

    #[test]
    fn a_variant_that_sat_out_is_nan_and_the_others_are_medians() {
        let sat_out = VariantFrames::default();
        assert!(sat_out.wall().median.is_nan());
        assert!(sat_out.wall().min.is_nan() && sat_out.wall().max.is_nan());
        assert!(sat_out.pass_stats().is_empty());

        let timed = VariantFrames {
            pass_names: vec!["gbuffer".into(), "lighting".into()],
            frames: vec![
                frame(3.0, &[1.0, 2.0]),
                frame(5.0, &[2.0, 3.0]),
                frame(4.0, &[3.0]),
            ],
        };
        assert_eq!(timed.wall().median, 4.0);
        assert_eq!(timed.stats_of(|f| f.wall_ms * 2.0).max, 10.0);
        let passes = timed.pass_stats();
        assert_eq!(passes[0].0, "gbuffer");
        assert_eq!(passes[0].1.median, 2.0);
        // The frame whose timer missed the lighting pass adds no sample to it.
        assert_eq!(passes[1].0, "lighting");
        assert_eq!(passes[1].1.median, 2.5);
    }
}
