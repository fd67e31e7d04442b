//! Speed of light: the floor each pass of a frame is measured against.
//!
//! For every physical pass of a compiled [`Plan`], [`floors`] derives what the pass touches in
//! memory: the images it reads from outside itself (a merged group's internal reads stay in
//! tile memory on a tiler and are not counted) and every image it writes, with their formats,
//! at the pass's resolution. [`CopyFrame`] builds a small graph from those: per pass, one
//! fullscreen fragment pass (`glsl/bench/copy.frag`) that fetches one texel from an image of
//! each read format and writes every written format, nothing else. That is the cheapest pass
//! that moves the same bytes, so `pass / copy` says how much of a pass is its own work (ALU,
//! extra taps, geometry) rather than bandwidth. Because it is derived from the plan, it covers
//! any pass a technique adds. Integer formats (LBB's packed RGBA32UI ping-pong target) are read
//! with integer samplers and written as integer vectors, as the format table
//! ([`crate::backend::format`]) says: reading them as floats would be undefined behaviour and
//! the copy's time meaningless.
//!
//! The copies are timed submitted one by one with the device idle (the isolated mode of
//! [`crate::measure::bench`]), alternating with the frames of the same run, so machine noise hits both.
//!
//! Taps: a pass that declares its texture taps per pixel ([`crate::graph::declare::PassBuilder::taps`])
//! is divided by that; otherwise each image a pass reads (an input attachment, a sampled image,
//! a depth test, a loaded attachment) counts as one tap, which is exact for same-pixel passes and
//! an undercount for blurs; the table says which count it used.
//!
//! A pass above [`FAR_ABOVE_FLOOR`] times its copy is named in the output: lucent's same-pixel
//! passes measure within about 1-3x their copy on lavapipe (DESIGN.md: a 1024x768 RGBA16F copy
//! is about 2 ms, each extra tap about 1.1 ms), so 4x means the pass does several copies' worth
//! of work of its own.

use std::collections::HashSet;

use ash::vk;
use serde::Serialize;

use crate::backend::format::{format_info, format_name};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::copy_pass::{copy_defines, COPY_FRAGMENT, MAX_COPY_IMAGES, MAX_COPY_INPUTS};
use crate::features::pass::FullscreenPass;
use crate::frame::FrameRunner;
use crate::graph::{
    CompileOptions, Executable, ImageInfo, LoadOp, PassKind, Plan, RenderGraph, ResourceId,
};
use crate::{LucentError, Result};

/// Passes at more than this many times their copy's time are named as far above their floor.
pub const FAR_ABOVE_FLOOR: f64 = 4.0;

/// What one physical pass moves, and how many taps it makes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassFloor {
    /// The physical pass's name.
    pub pass: String,
    /// Its render area.
    pub extent: (u32, u32),
    /// Formats of the images it reads from outside itself (one per image).
    #[serde(skip)]
    pub reads: Vec<ImageInfo>,
    /// Formats of its colour (or storage) writes.
    #[serde(skip)]
    pub colour_writes: Vec<vk::Format>,
    /// Format of its depth write, if it writes depth.
    #[serde(skip)]
    pub depth_write: Option<vk::Format>,
    /// Texture taps per pixel.
    pub taps: u32,
    /// Whether `taps` was declared by the passes (else one per image read).
    pub taps_declared: bool,
}

impl PassFloor {
    /// Why no copy can stand in for this pass, if none can.
    pub fn unsupported(&self) -> Option<String> {
        if self.reads.len() > MAX_COPY_INPUTS || self.colour_writes.len() > MAX_COPY_IMAGES {
            return Some(format!(
                "'{}' reads {} and writes {} images; the copy reads at most {MAX_COPY_INPUTS} \
                 and writes at most {MAX_COPY_IMAGES}",
                self.pass,
                self.reads.len(),
                self.colour_writes.len()
            ));
        }
        if self.colour_writes.is_empty() && self.depth_write.is_none() {
            return Some(format!("'{}' writes no image", self.pass));
        }
        None
    }
}

/// The floor of every physical pass of `plan`, in execution order.
pub fn floors(plan: &Plan) -> Vec<PassFloor> {
    plan.physical
        .iter()
        .map(|phys| {
            let group: Vec<&crate::graph::compile::PlannedPass> =
                phys.passes.iter().map(|&i| &plan.passes[i]).collect();
            let produced: HashSet<(ResourceId, u32)> = group
                .iter()
                .flat_map(|p| p.writes.iter().map(|w| (w.resource, w.version)))
                .collect();
            let mut read_ids: Vec<ResourceId> = Vec::new();
            for u in group.iter().flat_map(|p| p.reads.iter()) {
                if !produced.contains(&(u.resource, u.version)) && !read_ids.contains(&u.resource) {
                    read_ids.push(u.resource);
                }
            }
            let mut write_ids: Vec<ResourceId> = Vec::new();
            for u in group.iter().flat_map(|p| p.writes.iter()) {
                if !write_ids.contains(&u.resource) {
                    write_ids.push(u.resource);
                }
            }
            let info = |id: ResourceId| plan.resources[id].info;
            let is_depth = |id: ResourceId| info(id).aspect().contains(vk::ImageAspectFlags::DEPTH);
            let depth_write = write_ids
                .iter()
                .find(|&&id| is_depth(id))
                .map(|&id| info(id).format);
            let colour_writes = write_ids
                .iter()
                .filter(|&&id| !is_depth(id))
                .map(|&id| info(id).format)
                .collect();
            // Taps: declared by the pass, else one per image it reads (distinct images; a
            // merged group's internal reads are taps too, they are made per pixel).
            let taps_declared = group.iter().all(|p| p.taps.is_some());
            let taps = group
                .iter()
                .map(|p| {
                    p.taps.unwrap_or_else(|| {
                        let distinct: HashSet<ResourceId> =
                            p.reads.iter().map(|u| u.resource).collect();
                        distinct.len() as u32
                    })
                })
                .sum();
            let extent = if phys.kind == PassKind::Raster {
                phys.extent
            } else {
                write_ids
                    .first()
                    .map_or((1, 1), |&id| (info(id).width, info(id).height))
            };
            PassFloor {
                pass: phys.name.clone(),
                extent,
                reads: read_ids.iter().map(|&id| info(id)).collect(),
                colour_writes,
                depth_write,
                taps,
                taps_declared,
            }
        })
        .collect()
}

/// Name of the copy pass standing in for `pass`.
pub fn copy_name(pass: &str) -> String {
    format!("copy of {pass}")
}

/// The copy passes of a frame's floors, compiled and ready to time.
pub struct CopyFrame {
    executable: Executable,
    runner: FrameRunner,
    /// Per floor (in [`floors`] order): the physical pass index of its copy, `None` when no copy
    /// can stand in for it (see [`PassFloor::unsupported`]).
    copy_index: Vec<Option<usize>>,
    /// The floors it was built from.
    pub floors: Vec<PassFloor>,
    samples: Vec<Vec<f64>>,
}

impl CopyFrame {
    /// Builds the copy graph of `floors`: per supported floor, clears of its input images (not
    /// timed) and one copy pass.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        floors: Vec<PassFloor>,
    ) -> Result<Self> {
        let mut graph = RenderGraph::new();
        let mut names = Vec::new();
        for (f, floor) in floors.iter().enumerate() {
            if floor.unsupported().is_some() {
                names.push(None);
                continue;
            }
            let (width, height) = floor.extent;
            let mut inputs = Vec::new();
            for (k, read) in floor.reads.iter().enumerate() {
                let info = ImageInfo {
                    width: read.width,
                    height: read.height,
                    format: copy_format(read.format),
                };
                let mut image = graph.create_image(&format!("floor {f} in {k}"), info);
                let mut fill = graph.add_pass(&format!("fill floor {f} in {k}"), PassKind::Raster);
                if info.aspect().contains(vk::ImageAspectFlags::DEPTH) {
                    fill.depth(&mut image, LoadOp::Clear([1.0, 0.0, 0.0, 0.0]));
                } else {
                    fill.color(&mut image, LoadOp::Clear([0.25, 0.5, 0.75, 1.0]));
                }
                fill.clears_only();
                inputs.push(image);
            }
            let name = copy_name(&floor.pass);
            let mut outputs: Vec<_> = floor
                .colour_writes
                .iter()
                .enumerate()
                .map(|(k, &format)| {
                    graph.create_image(
                        &format!("floor {f} out {k}"),
                        ImageInfo {
                            width,
                            height,
                            format: copy_format(format),
                        },
                    )
                })
                .collect();
            let mut depth = floor.depth_write.map(|format| {
                graph.create_image(
                    &format!("floor {f} depth"),
                    ImageInfo {
                        width,
                        height,
                        format,
                    },
                )
            });
            let defines = copy_defines(inputs.len(), floor.colour_writes.len(), depth.is_some());
            let mut pass = FullscreenPass::standalone(&mut graph, &name, COPY_FRAGMENT);
            pass.defines(&defines);
            for input in &inputs {
                pass.sample(input);
            }
            for output in &mut outputs {
                pass.color(output, LoadOp::DontCare);
            }
            if let Some(depth) = &mut depth {
                pass.depth(depth, LoadOp::Clear([1.0, 0.0, 0.0, 0.0]));
            }
            pass.taps(inputs.len() as u32).graph().side_effects();
            pass.finish();
            names.push(Some(name));
        }
        // Unmerged: each copy is its own render pass with its own timestamp pair.
        let (plan, execs) = graph.compile(CompileOptions {
            merge: false,
            alias: true,
            ..CompileOptions::default()
        })?;
        let copy_index = names
            .iter()
            .map(|n| {
                n.as_ref()
                    .and_then(|n| plan.physical.iter().position(|p| &p.name == n))
            })
            .collect();
        let executable = Executable::new(gpu, plan, execs, shaders, pipeline_cache.handle)?;
        let runner = match FrameRunner::new(gpu, executable.plan.physical.len()) {
            Ok(r) => r,
            Err(e) => {
                executable.destroy(gpu);
                return Err(e);
            }
        };
        let samples = vec![Vec::new(); floors.len()];
        Ok(Self {
            executable,
            runner,
            copy_index,
            floors,
            samples,
        })
    }

    /// The copies of `plan`'s passes.
    pub fn for_plan(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        plan: &Plan,
    ) -> Result<Self> {
        Self::new(gpu, shaders, pipeline_cache, floors(plan))
    }

    /// Runs every copy once, each alone with the device idle, and records their times; with
    /// `keep == false` (warm-up) the times are dropped.
    pub fn measure(&mut self, gpu: &GpuContext, keep: bool) -> Result<()> {
        let timing = self.runner.run_isolated(gpu, &self.executable)?;
        if !keep {
            return Ok(());
        }
        for (f, index) in self.copy_index.iter().enumerate() {
            if let Some(i) = *index {
                let ms = timing.passes.get(i).map(|p| p.ms).ok_or_else(|| {
                    LucentError::Timing(format!(
                        "copy timing: expected {} scopes, got {}",
                        self.executable.plan.physical.len(),
                        timing.passes.len()
                    ))
                })?;
                self.samples[f].push(ms);
            }
        }
        Ok(())
    }

    /// Median copy time of each floor (`None`: no copy for it, or not measured yet).
    pub fn medians(&self) -> Vec<Option<crate::measure::stats::Stats>> {
        self.samples
            .iter()
            .map(|s| (!s.is_empty()).then(|| crate::measure::stats::Stats::of(s)))
            .collect()
    }

    /// Destroys the copy graph. The GPU must be idle.
    pub fn destroy(self, gpu: &GpuContext) {
        self.runner.destroy(gpu);
        self.executable.destroy(gpu);
    }
}

/// One row of the speed-of-light table.
#[derive(Clone, Debug, Serialize)]
pub struct FloorRow {
    /// Physical pass.
    pub pass: String,
    /// The pass's reported median, ms.
    pub pass_ms: f64,
    /// Its copy's median (isolated), ms; `None` when no copy can stand in for it.
    pub copy_ms: Option<f64>,
    /// `pass_ms / copy_ms`.
    pub ratio: Option<f64>,
    /// Texture taps per pixel.
    pub taps: u32,
    /// Whether the pass declared its taps (else one per image read).
    pub taps_declared: bool,
    /// `pass_ms / taps` (`None` for a pass without taps).
    pub ms_per_tap: Option<f64>,
    /// Images the copy reads and writes, as text (`2 in (RGBA16F, D32) -> 1 out (RGBA8)`).
    pub io: String,
    /// Above [`FAR_ABOVE_FLOOR`] times its copy.
    pub far_above: bool,
    /// Why there is no copy, when there is none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// The copy's inputs and outputs as text.
pub fn describe_io(floor: &PassFloor) -> String {
    let reads: Vec<String> = floor.reads.iter().map(|i| format_name(i.format)).collect();
    let writes: Vec<String> = floor
        .colour_writes
        .iter()
        .chain(floor.depth_write.as_ref())
        .map(|&f| format_name(f))
        .collect();
    format!(
        "{} in ({}) -> {} out ({})",
        reads.len(),
        reads.join(", "),
        writes.len(),
        writes.join(", ")
    )
}

/// The table's rows: each floor beside the measured pass of the same name (`pass_ms` looks a
/// pass's reported median up by name).
pub fn rows(
    floors: &[PassFloor],
    copies: &[Option<crate::measure::stats::Stats>],
    pass_ms: impl Fn(&str) -> Option<f64>,
) -> Vec<FloorRow> {
    floors
        .iter()
        .zip(copies)
        .filter_map(|(floor, copy)| {
            let ms = pass_ms(&floor.pass)?;
            // Guarded: a copy measured as 0 ms (timer granularity) gives no ratio, not Inf.
            let copy_ms = copy.map(|c| c.median).filter(|&c| c > 0.0);
            let ratio = copy_ms.map(|c| ms / c);
            Some(FloorRow {
                pass: floor.pass.clone(),
                pass_ms: ms,
                copy_ms,
                ratio,
                taps: floor.taps,
                taps_declared: floor.taps_declared,
                ms_per_tap: (floor.taps > 0).then(|| ms / f64::from(floor.taps)),
                io: describe_io(floor),
                far_above: ratio.is_some_and(|r| r > FAR_ABOVE_FLOOR),
                note: floor.unsupported(),
            })
        })
        .collect()
}

/// The speed-of-light table as Markdown, with the passes far above their floor named.
pub fn markdown(rows: &[FloorRow]) -> String {
    let mut out = String::from(
        "| pass | pass ms | copy ms | pass / copy | taps / px | ms per tap | copy reads -> writes |\n\
         |---|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {:.3} | {} | {} | {}{} | {} | {} |\n",
            r.pass,
            r.pass_ms,
            r.copy_ms.map_or("-".into(), |c| format!("{c:.3}")),
            r.ratio.map_or("-".into(), |x| format!(
                "{x:.2}x{}",
                if r.far_above { " **far above**" } else { "" }
            )),
            r.taps,
            if r.taps_declared { "" } else { " (reads)" },
            r.ms_per_tap.map_or("-".into(), |m| format!("{m:.3}")),
            r.io,
        ));
    }
    let far: Vec<String> = rows
        .iter()
        .filter(|r| r.far_above)
        .map(|r| format!("`{}` ({:.1}x)", r.pass, r.ratio.unwrap_or(0.0)))
        .collect();
    out.push_str(
        "\nCopy: a fullscreen pass fetching one texel of each image the pass reads and writing \
         every format it writes, same resolution, timed alone (device idle), alternating with \
         the frames. Taps: declared by the pass, or \"(reads)\": one per image read. ",
    );
    if far.is_empty() {
        out.push_str(&format!(
            "No pass is more than {FAR_ABOVE_FLOOR}x its copy.\n"
        ));
    } else {
        out.push_str(&format!(
            "Far above their floor (more than {FAR_ABOVE_FLOOR}x their copy): {}.\n",
            far.join(", ")
        ));
    }
    for r in rows.iter().filter(|r| r.note.is_some()) {
        out.push_str(&format!("- no copy: {}\n", r.note.as_deref().unwrap_or("")));
    }
    out
}

/// The format the copy frame gives an image that the pass reads or writes as `format`: the
/// format itself, or for an integer format the float format of the same texel size. A texel
/// fetch moves the same bytes, and `glsl/bench/copy.frag` then reads and writes floats only, so
/// its permutations are the image counts alone (reading an integer image through a float
/// sampler would be undefined: VUID-vkCmdDraw-format-07753). The one format table decides.
fn copy_format(format: vk::Format) -> vk::Format {
    match format_info(format) {
        Some(info) if info.kind.is_integer() => match info.bytes {
            1 => vk::Format::R8_UNORM,
            2 => vk::Format::R16_SFLOAT,
            4 => vk::Format::R32_SFLOAT,
            8 => vk::Format::R32G32_SFLOAT,
            _ => vk::Format::R32G32B32A32_SFLOAT,
        },
        _ => format,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{plan_frame, FrameDesc, FrameSettings, Technique};

    fn plan(scene: &str, technique: Technique) -> Plan {
        let scene = crate::bake::scene::load_scene_baked(scene).unwrap();
        let settings = FrameSettings {
            technique,
            ..FrameSettings::new(64, 48)
        };
        plan_frame(&settings, &FrameDesc::new(&scene, &settings).unwrap()).unwrap()
    }

    #[test]
    fn merged_deferred_floor_writes_the_gbuffer_and_reads_nothing_outside() {
        let plan = plan("smoke", Technique::None);
        let floors = floors(&plan);
        assert_eq!(floors.len(), plan.physical.len());
        // The light-space maps come first: a depth-only pass reading nothing.
        let maps = &floors[0];
        assert_eq!(maps.pass, "light-space maps");
        assert!(
            maps.reads.is_empty() && maps.colour_writes.is_empty(),
            "{maps:?}"
        );
        assert_eq!(maps.depth_write, Some(vk::Format::D32_SFLOAT));
        let deferred = &floors[1];
        assert_eq!(deferred.pass, "gbuffer + lighting");
        // From outside its group it reads only the light-space atlas.
        assert_eq!(deferred.reads.len(), 1, "{deferred:?}");
        assert_eq!(deferred.reads[0].format, vk::Format::D32_SFLOAT);
        assert_eq!(deferred.depth_write, Some(vk::Format::D32_SFLOAT));
        // Albedo, normal and the lit image at least.
        assert!(deferred.colour_writes.len() >= 3, "{deferred:?}");
        // The lighting subpass reads depth, GB0 and GB1 as input attachments: three taps.
        assert!(
            deferred.taps >= 3 && !deferred.taps_declared,
            "{deferred:?}"
        );
        let tonemap = &floors[2];
        assert_eq!(tonemap.pass, "tonemap");
        assert_eq!(tonemap.reads.len(), 1);
        assert_eq!(tonemap.reads[0].format, vk::Format::R16G16B16A16_SFLOAT);
        assert_eq!(tonemap.colour_writes, [vk::Format::R8G8B8A8_UNORM]);
        assert_eq!(tonemap.taps, 1);
        assert_eq!(tonemap.extent, (64, 48));
    }

    #[test]
    fn every_pass_of_every_technique_gets_a_floor_a_copy_can_stand_in_for() {
        for (name, technique) in Technique::all() {
            for scene in ["smoke", "cubes", "skin", "teapot"] {
                let plan = plan(scene, technique);
                let floors = floors(&plan);
                assert_eq!(floors.len(), plan.physical.len(), "{name} on {scene}");
                for f in &floors {
                    assert_eq!(f.unsupported(), None, "{name} on {scene}: {f:?}");
                }
            }
        }
    }

    #[test]
    fn packed_lbb_floors_read_and_write_their_rgba32ui_target_as_integers() {
        let scene = crate::bake::scene::load_scene_baked("skin").unwrap();
        let mut settings = FrameSettings {
            technique: Technique::Only(&crate::features::sss::lbb::LBB),
            ..FrameSettings::new(64, 48)
        };
        settings.sss.packed = true;
        let plan = plan_frame(&settings, &FrameDesc::new(&scene, &settings).unwrap()).unwrap();
        let floors = floors(&plan);
        let packed = vk::Format::R32G32B32A32_UINT;
        let reads_packed = floors
            .iter()
            .filter(|f| f.reads.iter().any(|r| r.format == packed))
            .count();
        let writes_packed = floors
            .iter()
            .filter(|f| f.colour_writes.contains(&packed))
            .count();
        assert!(reads_packed > 0 && writes_packed > 0, "{floors:?}");
        // The copy moves the same bytes through a float format.
        assert_eq!(copy_format(packed), vk::Format::R32G32B32A32_SFLOAT);
        assert_eq!(copy_format(vk::Format::R8_UINT), vk::Format::R8_UNORM);
        assert_eq!(
            copy_format(vk::Format::R32G32_SINT),
            vk::Format::R32G32_SFLOAT
        );
        assert_eq!(
            copy_format(vk::Format::R16G16B16A16_SFLOAT),
            vk::Format::R16G16B16A16_SFLOAT
        );
        assert_eq!(copy_format(vk::Format::D32_SFLOAT), vk::Format::D32_SFLOAT);
    }

    #[test]
    fn rows_guard_zero_copies_and_name_far_passes() {
        let floor = PassFloor {
            pass: "blur".into(),
            extent: (8, 8),
            reads: vec![ImageInfo {
                width: 8,
                height: 8,
                format: vk::Format::R16G16B16A16_SFLOAT,
            }],
            colour_writes: vec![vk::Format::R16G16B16A16_SFLOAT],
            depth_write: None,
            taps: 7,
            taps_declared: true,
        };
        let stat = |m| crate::measure::stats::Stats {
            median: m,
            min: m,
            max: m,
        };
        let floors = [
            floor.clone(),
            PassFloor {
                pass: "tonemap".into(),
                ..floor
            },
        ];
        let rows = rows(&floors, &[Some(stat(2.0)), Some(stat(0.0))], |name| {
            Some(if name == "blur" { 9.6 } else { 1.0 })
        });
        assert!(rows[0].far_above && (rows[0].ratio.unwrap() - 4.8).abs() < 1e-9);
        assert!((rows[0].ms_per_tap.unwrap() - 9.6 / 7.0).abs() < 1e-9);
        assert_eq!(rows[1].ratio, None, "a 0 ms copy gives no ratio");
        let text = markdown(&rows);
        assert!(
            text.contains("Far above their floor") && text.contains("`blur` (4.8x)"),
            "{text}"
        );
    }
}
