//! Speed of light: the floor each pass of a frame is measured against.
//!
//! Every physical pass of a compiled [`Plan`] gets a floor of its own kind ([`floors`]):
//! - **a fullscreen pass** (a blur, the tonemap, lighting) against its **copy**: one
//!   fullscreen fragment pass (`glsl/bench/copy.frag`) that fetches one texel from an image of
//!   each format the pass reads from outside its group (a merged group's internal reads stay
//!   in tile memory on a tiler and are not counted) and writes every format it writes, at the
//!   pass's resolution, nothing else. That is the cheapest pass that moves the same bytes, so
//!   `pass / copy` says how much of a pass is its own work (ALU, extra taps) rather than
//!   bandwidth.
//! - **a mesh pass** (the light-space maps, the G-buffer: a pass that declares
//!   [`crate::graph::MeshDraws`]) against **the same draws with a trivial shader**
//!   (`glsl/bench/floor.vert`, `floor.frag`): every object of the scene once per view of the
//!   pass (the camera, or each light-space face's tile), the pass's culling and depth test,
//!   the position stream only, one matrix product per vertex and a constant written to each
//!   of the pass's targets. A mesh pass's time is vertex work, binning and rasterisation,
//!   which a fullscreen copy does not have: held to a copy, its ratio follows the CPU's
//!   vertex-to-fill balance under lavapipe (1.5-2x apart between two machines of the same
//!   kind, issue 34), held to its own draws it follows only what its shaders add.
//! - **a merged group** of both (`gbuffer + lighting`) against the sum: its mesh passes'
//!   floors plus one copy of its fullscreen passes (their reads from outside the group, their
//!   writes).
//!
//! [`FloorFrame`] builds the floors as a small graph of their own, one physical pass per
//! part, and times them submitted one by one with the device idle (the isolated mode of
//! [`crate::measure::bench`]), alternating with the frames of the same run, so machine noise
//! hits both. Because the floors are derived from the plan (and the scene the renderer drew),
//! they cover any pass a technique adds. Integer formats (LBB's packed RGBA32UI ping-pong
//! target, the light-space maps' ID target) are read and written as the float format of the
//! same texel size, as the format table ([`crate::backend::format`]) says: reading them as
//! floats would be undefined behaviour and the floor's time meaningless.
//!
//! Taps: a pass that declares its texture taps per pixel ([`crate::graph::declare::PassBuilder::taps`])
//! is divided by that; otherwise each image a pass reads (an input attachment, a sampled image,
//! a depth test, a loaded attachment) counts as one tap, which is exact for same-pixel passes and
//! an undercount for blurs; the table says which count it used.
//!
//! A pass above [`FAR_ABOVE_FLOOR`] times its floor is named in the output: lucent's same-pixel
//! passes measure within about 1-3x their copy on lavapipe (DESIGN.md: a 1024x768 RGBA16F copy
//! is about 2 ms, each extra tap about 1.1 ms), so 4x means the pass does several copies' worth
//! of work of its own.

use std::collections::HashSet;
use std::sync::Arc;

use ash::vk;
use serde::Serialize;

use crate::backend::descriptor::Binding;
use crate::backend::format::{format_info, format_name};
use crate::backend::pipeline::{GraphicsPipelineDesc, VertexInput};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::copy_pass::{
    copy_defines, floor_defines, COPY_FRAGMENT, COPY_INPUT_NAMES, FLOOR_FRAGMENT, FLOOR_VERTEX,
    MAX_COPY_IMAGES, MAX_COPY_INPUTS,
};
use crate::features::pass::FullscreenPass;
use crate::features::util::PassPipeline;
use crate::frame::{FrameRunner, Renderer};
use crate::gpu_scene::SceneGpu;
use crate::graph::{
    CompileOptions, Executable, ImageInfo, LoadOp, MeshDraws, MeshViews, PassExec, PassKind, Plan,
    PrepareContext, RecordContext, RenderGraph, ResourceId,
};
use crate::{LucentError, Result};

/// Passes at more than this many times their floor's time are named as far above it.
pub const FAR_ABOVE_FLOOR: f64 = 4.0;

/// The floor of one mesh pass: the objects it draws, with its views, into its targets.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MeshFloor {
    /// The mesh pass's name (a pass of the physical pass).
    pub pass: String,
    /// Its render area.
    pub extent: (u32, u32),
    /// What it draws.
    #[serde(skip)]
    pub draws: MeshDraws,
    /// Formats of its colour writes.
    #[serde(skip)]
    pub colour_writes: Vec<vk::Format>,
    /// Format of its depth target (every mesh pass tests depth).
    #[serde(skip)]
    pub depth: vk::Format,
}

/// What one physical pass moves and draws, and how many taps it makes: its floor is the sum
/// of its mesh passes' floors ([`Self::meshes`]) and, when it has fullscreen passes, one copy
/// of those ([`Self::copies`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PassFloor {
    /// The physical pass's name.
    pub pass: String,
    /// Its render area.
    pub extent: (u32, u32),
    /// The floors of its mesh passes (none for a fullscreen pass).
    pub meshes: Vec<MeshFloor>,
    /// Whether a copy stands for (some of) it: it has passes that draw no mesh.
    pub copies: bool,
    /// Formats of the images its fullscreen passes read from outside the group (one per image).
    #[serde(skip)]
    pub reads: Vec<ImageInfo>,
    /// Formats of its fullscreen passes' colour (or storage) writes.
    #[serde(skip)]
    pub colour_writes: Vec<vk::Format>,
    /// Format of its fullscreen passes' depth write, if they write depth.
    #[serde(skip)]
    pub depth_write: Option<vk::Format>,
    /// Texture taps per pixel.
    pub taps: u32,
    /// Whether `taps` was declared by the passes (else one per image read).
    pub taps_declared: bool,
}

impl PassFloor {
    /// Why no floor can stand in for this pass, if none can.
    pub fn unsupported(&self) -> Option<String> {
        if let Some(mesh) = self
            .meshes
            .iter()
            .find(|m| m.colour_writes.len() > MAX_COPY_IMAGES)
        {
            return Some(format!(
                "'{}' draws into {} colour targets; the mesh floor writes at most {MAX_COPY_IMAGES}",
                mesh.pass,
                mesh.colour_writes.len()
            ));
        }
        if !self.copies {
            return None;
        }
        if self.reads.len() > MAX_COPY_INPUTS || self.colour_writes.len() > MAX_COPY_IMAGES {
            return Some(format!(
                "'{}' reads {} and writes {} images; the copy reads at most {MAX_COPY_INPUTS} \
                 and writes at most {MAX_COPY_IMAGES}",
                self.pass,
                self.reads.len(),
                self.colour_writes.len()
            ));
        }
        if self.meshes.is_empty() && self.colour_writes.is_empty() && self.depth_write.is_none() {
            return Some(format!("'{}' writes no image", self.pass));
        }
        None
    }

    /// The kind of floor, as the table names it: `copy`, `draws`, or `draws + copy`.
    pub fn kind(&self) -> &'static str {
        match (self.meshes.is_empty(), self.copies) {
            (true, _) => "copy",
            (false, false) => "draws",
            (false, true) => "draws + copy",
        }
    }
}

/// The floor of every physical pass of `plan`, in execution order.
pub fn floors(plan: &Plan) -> Vec<PassFloor> {
    plan.physical
        .iter()
        .map(|phys| {
            let group: Vec<&crate::graph::compile::PlannedPass> =
                phys.passes.iter().map(|&i| &plan.passes[i]).collect();
            let info = |id: ResourceId| plan.resources[id].info;
            let is_depth = |id: ResourceId| info(id).aspect().contains(vk::ImageAspectFlags::DEPTH);
            let produced: HashSet<(ResourceId, u32)> = group
                .iter()
                .flat_map(|p| p.writes.iter().map(|w| (w.resource, w.version)))
                .collect();
            // The images a set of passes writes, each once, in order.
            let writes_of = |passes: &[&&crate::graph::compile::PlannedPass]| {
                let mut ids: Vec<ResourceId> = Vec::new();
                for u in passes.iter().flat_map(|p| p.writes.iter()) {
                    if !ids.contains(&u.resource) {
                        ids.push(u.resource);
                    }
                }
                ids
            };
            let mesh_passes: Vec<&&crate::graph::compile::PlannedPass> =
                group.iter().filter(|p| p.mesh.is_some()).collect();
            let other_passes: Vec<&&crate::graph::compile::PlannedPass> =
                group.iter().filter(|p| p.mesh.is_none()).collect();
            let meshes = mesh_passes
                .iter()
                .filter_map(|p| {
                    let writes = writes_of(&[*p]);
                    Some(MeshFloor {
                        pass: p.name.clone(),
                        extent: phys.extent,
                        draws: p.mesh.clone()?,
                        colour_writes: writes
                            .iter()
                            .filter(|&&id| !is_depth(id))
                            .map(|&id| info(id).format)
                            .collect(),
                        depth: writes
                            .iter()
                            .find(|&&id| is_depth(id))
                            .map_or(crate::features::gbuffer::DEPTH_FORMAT, |&id| {
                                info(id).format
                            }),
                    })
                })
                .collect();
            let mut read_ids: Vec<ResourceId> = Vec::new();
            for u in other_passes.iter().flat_map(|p| p.reads.iter()) {
                if !produced.contains(&(u.resource, u.version)) && !read_ids.contains(&u.resource) {
                    read_ids.push(u.resource);
                }
            }
            let write_ids = writes_of(&other_passes);
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
                meshes,
                copies: !other_passes.is_empty(),
                reads: read_ids.iter().map(|&id| info(id)).collect(),
                colour_writes,
                depth_write,
                taps,
                taps_declared,
            }
        })
        .collect()
}

/// Name of the copy pass standing in for `pass`'s fullscreen passes.
pub fn copy_name(pass: &str) -> String {
    format!("copy of {pass}")
}

/// Name of the floor pass standing in for mesh pass `pass`.
pub fn draws_name(pass: &str) -> String {
    format!("draws of {pass}")
}

/// The floors of a frame's passes, compiled and ready to time.
pub struct FloorFrame {
    executable: Executable,
    runner: FrameRunner,
    /// Per floor (in [`floors`] order): the physical pass indices of its parts (mesh floors
    /// and copy) in the floor frame; empty when no floor can stand in for it (see
    /// [`PassFloor::unsupported`]).
    part_indices: Vec<Vec<usize>>,
    /// The floors it was built from.
    pub floors: Vec<PassFloor>,
    samples: Vec<Vec<f64>>,
}

impl FloorFrame {
    /// Builds the floor graph of `floors`: per supported floor, a mesh floor pass per mesh
    /// pass (drawing `scene`'s objects; needed when some floor has mesh passes), and for its
    /// fullscreen passes clears of their input images (not timed) and one copy pass.
    pub fn new(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        floors: Vec<PassFloor>,
        scene: Option<&Arc<SceneGpu>>,
    ) -> Result<Self> {
        let mut graph = RenderGraph::new();
        let mut names: Vec<Vec<String>> = Vec::new();
        for (f, floor) in floors.iter().enumerate() {
            if floor.unsupported().is_some() {
                names.push(Vec::new());
                continue;
            }
            let mut parts = Vec::new();
            for (m, mesh) in floor.meshes.iter().enumerate() {
                let scene = scene.ok_or_else(|| {
                    LucentError::InvalidInput(format!(
                        "the floor of '{}' draws the scene's meshes, and no scene was given",
                        mesh.pass
                    ))
                })?;
                let name = draws_name(&mesh.pass);
                declare_mesh_floor(
                    &mut graph,
                    &format!("floor {f} mesh {m}"),
                    &name,
                    mesh,
                    scene,
                );
                parts.push(name);
            }
            if floor.copies {
                let name = copy_name(&floor.pass);
                declare_copy(&mut graph, f, &name, floor);
                parts.push(name);
            }
            names.push(parts);
        }
        // Unmerged: each part is its own render pass with its own timestamp pair.
        let (plan, execs) = graph.compile(CompileOptions {
            merge: false,
            alias: true,
            ..CompileOptions::default()
        })?;
        let part_indices = names
            .iter()
            .map(|parts| {
                parts
                    .iter()
                    .filter_map(|n| plan.physical.iter().position(|p| &p.name == n))
                    .collect()
            })
            .collect();
        // One slot: the floors are recorded one at a time, each waited for.
        let executable = Executable::new(gpu, plan, execs, shaders, pipeline_cache.handle, 1)?;
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
            part_indices,
            floors,
            samples,
        })
    }

    /// The floors of `renderer`'s passes, the mesh floors drawing its scene.
    pub fn for_renderer(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        renderer: &Renderer,
    ) -> Result<Self> {
        Self::new(
            gpu,
            shaders,
            pipeline_cache,
            floors(&renderer.executable.plan),
            renderer.scene_gpu_shared(),
        )
    }

    /// Runs every floor part once, each alone with the device idle, and records each floor's
    /// time (the sum of its parts); with `keep == false` (warm-up) the times are dropped.
    pub fn measure(&mut self, gpu: &GpuContext, keep: bool) -> Result<()> {
        let timing = self.runner.run_isolated(gpu, &self.executable)?;
        if !keep {
            return Ok(());
        }
        for (f, parts) in self.part_indices.iter().enumerate() {
            if parts.is_empty() {
                continue;
            }
            let mut ms = 0.0;
            for &i in parts {
                ms += timing.passes.get(i).map(|p| p.ms).ok_or_else(|| {
                    LucentError::Timing(format!(
                        "floor timing: expected {} scopes, got {}",
                        self.executable.plan.physical.len(),
                        timing.passes.len()
                    ))
                })?;
            }
            self.samples[f].push(ms);
        }
        Ok(())
    }

    /// Median floor time of each pass (`None`: no floor for it, or not measured yet).
    pub fn medians(&self) -> Vec<Option<crate::measure::stats::Stats>> {
        self.samples
            .iter()
            .map(|s| (!s.is_empty()).then(|| crate::measure::stats::Stats::of(s)))
            .collect()
    }

    /// Destroys the floor graph. The GPU must be idle.
    pub fn destroy(self, gpu: &GpuContext) {
        self.runner.destroy(gpu);
        self.executable.destroy(gpu);
    }
}

/// Declares the copy of `floor`'s fullscreen passes (the `f`-th floor) as pass `name`: clears
/// of images of its input formats (not timed: separate passes), then one fullscreen pass that
/// fetches a texel of each and writes each of its output formats.
fn declare_copy(graph: &mut RenderGraph, f: usize, name: &str, floor: &PassFloor) {
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
    let mut pass = FullscreenPass::standalone(graph, name, COPY_FRAGMENT);
    pass.defines(&defines);
    for (input, name) in inputs.iter().zip(COPY_INPUT_NAMES) {
        pass.sample(name, input);
    }
    for output in &mut outputs {
        pass.color(output, LoadOp::DontCare);
    }
    if let Some(depth) = &mut depth {
        pass.depth(depth, LoadOp::Clear([1.0, 0.0, 0.0, 0.0]));
    }
    pass.taps(inputs.len() as u32).graph().side_effects();
    pass.finish();
}

/// Declares `mesh`'s floor as pass `name` (its images named after `prefix`): targets of its
/// formats (integer ones as floats of the same size) and depth, cleared as the pass clears
/// them, and `scene`'s objects drawn into them with the pass's views.
fn declare_mesh_floor(
    graph: &mut RenderGraph,
    prefix: &str,
    name: &str,
    mesh: &MeshFloor,
    scene: &Arc<SceneGpu>,
) {
    let (width, height) = mesh.extent;
    let image = |format| ImageInfo {
        width,
        height,
        format,
    };
    let mut outputs: Vec<_> = mesh
        .colour_writes
        .iter()
        .enumerate()
        .map(|(k, &format)| {
            graph.create_image(&format!("{prefix} out {k}"), image(copy_format(format)))
        })
        .collect();
    let mut depth = graph.create_image(&format!("{prefix} depth"), image(mesh.depth));
    let mut pass = graph.add_pass(name, PassKind::Raster);
    for output in &mut outputs {
        pass.color(output, LoadOp::Clear([0.0; 4]));
    }
    pass.depth(&mut depth, LoadOp::Clear([1.0; 4]));
    pass.side_effects();
    pass.execute(MeshFloorPass {
        scene: scene.clone(),
        draws: mesh.draws.clone(),
        outputs: mesh.colour_writes.len(),
        pipeline: None,
    });
}

/// Push constants of the mesh floor (glsl/bench/floor.vert).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct FloorConstants {
    model: [[f32; 4]; 4],
    /// x: the light-space face.
    face: [i32; 4],
}

/// A mesh pass's floor: the scene's objects with the pass's views and culling, the trivial
/// shaders of `glsl/bench/floor.*`.
struct MeshFloorPass {
    scene: Arc<SceneGpu>,
    draws: MeshDraws,
    outputs: usize,
    pipeline: Option<PassPipeline>,
}

impl PassExec for MeshFloorPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let shadow_faces = matches!(self.draws.views, MeshViews::ShadowFaces { .. });
        // The views' matrices: the shadow table's faces, or the frame uniforms' camera.
        let region = if shadow_faces {
            &crate::features::shadows::TABLE_REGION
        } else {
            &crate::gpu_scene::FRAME
        };
        let defines = floor_defines(self.outputs, shadow_faces);
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &[(
                region.block,
                Binding::PerFrame(self.scene.per_frame.binding(region)),
            )],
            &GraphicsPipelineDesc {
                vertex: FLOOR_VERTEX,
                fragment: FLOOR_FRAGMENT,
                defines: &defines,
                vertex_input: VertexInput::Positions,
                depth_test: true,
                cull_back: self.draws.cull_back,
                additive_attachments: 0,
                set_layouts: &[],
                bindings: &[],
                push_constant_bytes: std::mem::size_of::<FloorConstants>() as u32,
                specialization: &[],
                name: "mesh floor",
            },
        )?);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        let device = &ctx.gpu.device;
        // Each view's tile, in face order (None: the whole render area, as the executor set
        // it, with the camera).
        let (tiles, edge): (Vec<Option<(u32, u32)>>, u32) = match &self.draws.views {
            MeshViews::Camera => (vec![None], 0),
            MeshViews::ShadowFaces { origins, tile } => {
                (origins.iter().copied().map(Some).collect(), *tile)
            }
        };
        for (face, tile) in tiles.into_iter().enumerate() {
            if let Some(origin) = tile {
                crate::features::util::set_tile_viewport(ctx, origin, edge);
            }
            for draw in &self.scene.draws {
                let constants = FloorConstants {
                    model: draw.constants.model,
                    face: [face as i32, 0, 0, 0],
                };
                // SAFETY: the bound pipeline's layout has this push-constant range.
                unsafe {
                    device.cmd_push_constants(
                        ctx.cmd,
                        pipeline.pipeline.layout,
                        vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                        0,
                        bytemuck::bytes_of(&constants),
                    );
                }
                // The position stream only: no thickness, no surface stream.
                self.scene.meshes[draw.mesh].draw(device, ctx.cmd, ctx.frame, false, false);
            }
        }
    }

    fn destroy(&mut self, gpu: &GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
    }
}

/// One row of the speed-of-light table.
#[derive(Clone, Debug, Serialize)]
pub struct FloorRow {
    /// Physical pass.
    pub pass: String,
    /// The pass's reported median, ms.
    pub pass_ms: f64,
    /// The kind of its floor: `copy`, `draws` or `draws + copy` ([`PassFloor::kind`]).
    pub floor: String,
    /// Its floor's median (isolated; the sum of its parts), ms; `None` when no floor can stand
    /// in for it.
    pub floor_ms: Option<f64>,
    /// `pass_ms / floor_ms`.
    pub ratio: Option<f64>,
    /// Texture taps per pixel.
    pub taps: u32,
    /// Whether the pass declared its taps (else one per image read).
    pub taps_declared: bool,
    /// `pass_ms / taps` (`None` for a pass without taps).
    pub ms_per_tap: Option<f64>,
    /// What the floor draws, reads and writes, as text (`draws (camera) -> 3 out (RGBA8,
    /// RGBA8, D32)`, `2 in (RGBA16F, D32) -> 1 out (RGBA8)`).
    pub io: String,
    /// Above [`FAR_ABOVE_FLOOR`] times its floor.
    pub far_above: bool,
    /// Why there is no floor, when there is none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// What the floor draws, reads and writes, as text: each mesh floor (`draws (6 faces) -> 1
/// out (D32)`), then the copy (`2 in (RGBA16F, D32) -> 1 out (RGBA8)`), joined by ` + `.
pub fn describe_io(floor: &PassFloor) -> String {
    let names = |formats: &mut dyn Iterator<Item = vk::Format>| -> Vec<String> {
        formats.map(format_name).collect()
    };
    let mut parts: Vec<String> = floor
        .meshes
        .iter()
        .map(|m| {
            let views = match &m.draws.views {
                MeshViews::Camera => "camera".to_string(),
                MeshViews::ShadowFaces { origins, .. } => format!("{} faces", origins.len()),
            };
            let writes = names(&mut m.colour_writes.iter().copied().chain([m.depth]));
            format!(
                "draws ({views}) -> {} out ({})",
                writes.len(),
                writes.join(", ")
            )
        })
        .collect();
    if floor.copies {
        let reads = names(&mut floor.reads.iter().map(|i| i.format));
        let writes = names(&mut floor.colour_writes.iter().copied().chain(floor.depth_write));
        parts.push(format!(
            "{} in ({}) -> {} out ({})",
            reads.len(),
            reads.join(", "),
            writes.len(),
            writes.join(", ")
        ));
    }
    parts.join(" + ")
}

/// The table's rows: each floor beside the measured pass of the same name (`pass_ms` looks a
/// pass's reported median up by name).
pub fn rows(
    floors: &[PassFloor],
    floor_times: &[Option<crate::measure::stats::Stats>],
    pass_ms: impl Fn(&str) -> Option<f64>,
) -> Vec<FloorRow> {
    floors
        .iter()
        .zip(floor_times)
        .filter_map(|(floor, time)| {
            let ms = pass_ms(&floor.pass)?;
            // Guarded: a floor measured as 0 ms (timer granularity) gives no ratio, not Inf.
            let floor_ms = time.map(|c| c.median).filter(|&c| c > 0.0);
            let ratio = floor_ms.map(|c| ms / c);
            Some(FloorRow {
                pass: floor.pass.clone(),
                pass_ms: ms,
                floor: floor.kind().to_string(),
                floor_ms,
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
        "| pass | pass ms | floor | floor ms | pass / floor | taps / px | ms per tap | floor draws, reads -> writes |\n\
         |---|---:|---|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {:.3} | {} | {} | {} | {}{} | {} | {} |\n",
            r.pass,
            r.pass_ms,
            r.floor,
            r.floor_ms.map_or("-".into(), |c| format!("{c:.3}")),
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
        "\nFloors, each timed alone (device idle), alternating with the frames: a fullscreen \
         pass against its copy (one texel fetched from each image it reads, every format it \
         writes, same resolution); a mesh pass against its draws (the same objects and views, \
         a trivial shader writing its targets); a merged group against the sum. Taps: declared \
         by the pass, or \"(reads)\": one per image read. ",
    );
    if far.is_empty() {
        out.push_str(&format!(
            "No pass is more than {FAR_ABOVE_FLOOR}x its floor.\n"
        ));
    } else {
        out.push_str(&format!(
            "Far above their floor (more than {FAR_ABOVE_FLOOR}x it): {}.\n",
            far.join(", ")
        ));
    }
    for r in rows.iter().filter(|r| r.note.is_some()) {
        out.push_str(&format!(
            "- no floor: {}\n",
            r.note.as_deref().unwrap_or("")
        ));
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
    fn mesh_passes_are_held_to_their_draws_and_fullscreen_passes_to_their_copy() {
        let plan = plan("smoke", Technique::None);
        let floors = floors(&plan);
        assert_eq!(floors.len(), plan.physical.len());
        // The light-space maps come first: a mesh pass alone, depth only, every face's tile.
        let maps = &floors[0];
        assert_eq!(maps.pass, "light-space maps");
        assert_eq!(maps.kind(), "draws");
        assert!(!maps.copies && maps.reads.is_empty(), "{maps:?}");
        assert_eq!(maps.meshes.len(), 1);
        assert_eq!(maps.meshes[0].pass, "light-space maps");
        assert!(maps.meshes[0].colour_writes.is_empty());
        assert_eq!(maps.meshes[0].depth, vk::Format::D32_SFLOAT);
        assert!(
            !maps.meshes[0].draws.cull_back,
            "open meshes cast from both sides"
        );
        // smoke: a point light (six faces) and a directional light (one).
        match &maps.meshes[0].draws.views {
            MeshViews::ShadowFaces { origins, tile } => {
                assert_eq!(origins.len(), 7, "{origins:?}");
                assert!(*tile > 0);
                let distinct: HashSet<_> = origins.iter().collect();
                assert_eq!(distinct.len(), 7, "each face its own tile");
            }
            other => panic!("light-space maps draw with {other:?}"),
        }
        assert_eq!(describe_io(maps), "draws (7 faces) -> 1 out (D32)");
        // The merged deferred pass: the G-buffer's draws plus a copy of the lighting subpass.
        let deferred = &floors[1];
        assert_eq!(deferred.pass, "gbuffer + lighting");
        assert_eq!(deferred.kind(), "draws + copy");
        assert_eq!(deferred.meshes.len(), 1);
        let gbuffer = &deferred.meshes[0];
        assert_eq!(gbuffer.pass, "gbuffer");
        assert_eq!(gbuffer.draws.views, MeshViews::Camera);
        assert!(gbuffer.draws.cull_back);
        // Albedo and normal at least, and depth.
        assert!(gbuffer.colour_writes.len() >= 2, "{gbuffer:?}");
        assert_eq!(gbuffer.depth, vk::Format::D32_SFLOAT);
        // The lighting subpass reads only the light-space atlas from outside the group, and
        // writes the lit image, no depth.
        assert_eq!(deferred.reads.len(), 1, "{deferred:?}");
        assert_eq!(deferred.reads[0].format, vk::Format::D32_SFLOAT);
        assert_eq!(deferred.depth_write, None);
        assert_eq!(
            deferred.colour_writes,
            [vk::Format::R16G16B16A16_SFLOAT],
            "{deferred:?}"
        );
        // The lighting subpass reads depth, GB0 and GB1 as input attachments: three taps.
        assert!(
            deferred.taps >= 3 && !deferred.taps_declared,
            "{deferred:?}"
        );
        assert!(describe_io(deferred).starts_with("draws (camera) -> "));
        assert!(describe_io(deferred).contains(" + 1 in (D32) -> 1 out (RGBA16F)"));
        let tonemap = &floors[2];
        assert_eq!(tonemap.pass, "tonemap");
        assert_eq!(tonemap.kind(), "copy");
        assert!(tonemap.meshes.is_empty());
        assert_eq!(tonemap.reads.len(), 1);
        assert_eq!(tonemap.reads[0].format, vk::Format::R16G16B16A16_SFLOAT);
        assert_eq!(tonemap.colour_writes, [vk::Format::R8G8B8A8_UNORM]);
        assert_eq!(tonemap.taps, 1);
        assert_eq!(tonemap.extent, (64, 48));
    }

    #[test]
    fn unmerged_passes_keep_their_own_kind_of_floor() {
        let scene = crate::bake::scene::load_scene_baked("smoke").unwrap();
        let settings = FrameSettings {
            technique: Technique::None,
            compile: CompileOptions {
                merge: false,
                ..CompileOptions::default()
            },
            ..FrameSettings::new(64, 48)
        };
        let plan = plan_frame(&settings, &FrameDesc::new(&scene, &settings).unwrap()).unwrap();
        let kinds: Vec<(String, &str)> = floors(&plan)
            .iter()
            .map(|f| (f.pass.clone(), f.kind()))
            .collect();
        assert_eq!(
            kinds,
            [
                ("light-space maps".to_string(), "draws"),
                ("gbuffer".to_string(), "draws"),
                ("lighting".to_string(), "copy"),
                ("tonemap".to_string(), "copy"),
            ]
        );
    }

    #[test]
    fn every_pass_of_every_technique_gets_a_floor_that_can_stand_in_for_it() {
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
            meshes: Vec::new(),
            copies: true,
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
