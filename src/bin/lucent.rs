//! The `lucent` command: list scenes, render headless, benchmark, print the compiled plan.
//!
//! Every failure ends with one line `lucent: error: ...` and a non-zero exit, never a panic.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

use lucent::backend::shader::{PipelineCache, ShaderCompiler};
use lucent::backend::{ContextDesc, GpuContext};
use lucent::bake::scene as bake;
use lucent::features::gbuffer::GBufferPrecision;
use lucent::features::layered::{LayeredKnobs, PhaseForm};
use lucent::features::shadows::ShadowSettings;
use lucent::features::sss::kernel::{KernelShape, SAMPLE_COUNTS};
use lucent::features::sss::{SssBlur, SssKnobs, SssPrecision};
use lucent::frame::{plan_frame, FrameDesc, FrameRunner, FrameSettings, Renderer, Technique};
use lucent::graph::CompileOptions;
use lucent::images::output;
use lucent::measure::bench::{self, BenchOptions};
use lucent::{scene, LucentError, Result};

#[derive(Parser)]
#[command(
    name = "lucent",
    version,
    about = "Real-time translucency and subsurface scattering on Vulkan, measured honestly"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the built-in scenes.
    Scenes,
    /// Render one frame headless and write it as PNG (and optionally EXR).
    Render {
        #[command(flatten)]
        frame: FrameArgs,
        #[command(flatten)]
        gpu: GpuArgs,
        /// Output PNG (tonemapped, sRGB). Default: <scene>.png.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Also write the linear HDR frame as OpenEXR (RGBA float).
        #[arg(long)]
        exr: Option<PathBuf>,
    },
    /// Benchmark: per-pass GPU times, verified to add up, as a Markdown table.
    Bench {
        #[command(flatten)]
        frame: FrameArgs,
        #[command(flatten)]
        gpu: GpuArgs,
        /// Frames measured (1 to 100000; short runs are noisy).
        #[arg(long, default_value_t = 30, value_parser = parse_frames)]
        frames: usize,
        /// Frames run and discarded first (lazy shader compilation; 0 to 10000).
        #[arg(long, default_value_t = 5, value_parser = parse_warmup)]
        warmup: usize,
        /// Also time each pass submitted alone and compare.
        #[arg(long)]
        isolate: bool,
        /// Output format on stdout: markdown, csv or json.
        #[arg(long, default_value = "markdown")]
        format: String,
        /// Also time every pass's speed-of-light copy (a pass reading and writing the same
        /// formats, nothing else) in the same run, and print pass / copy and ms per tap.
        #[arg(long)]
        speed_of_light: bool,
        /// Write the report as JSON to this file too.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write the frame as PNG after the benchmark.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Also measure the same scene under this technique, alternating frames with the
        /// main one, and print both side by side with the ratio (e.g. `--against none`).
        #[arg(long)]
        against: Option<String>,
        /// Print the seeds' published numbers beside ours: the LEAN-mapping thesis's Table 2
        /// (`control`) or Table 1 (`lbb`), each row as a share of its frame; for
        /// `translucency`, GDC 2011's full-screen cost beside the extra cost of translucency
        /// in this scene's lighting pass (measured against `none`, alternating frames); for
        /// `auto` or `layered` on a scene with layered materials, the row of Li et al.'s Table
        /// 1 nearest its triangle count. Alias: --compare-seeds.
        #[arg(long, alias = "compare-seeds")]
        compare_thesis: bool,
    },
    /// Open the interactive demo: a window to fly around a scene in, switch techniques, turn
    /// knobs and watch per-pass GPU times (needs a display; see the README's "Demo").
    #[cfg(feature = "window")]
    Demo {
        /// Scene: a built-in name (see `lucent scenes`) or a .toml scene file.
        #[arg(long, default_value = "cubes")]
        scene: String,
        /// Technique at start (default: the one the scene is made for).
        #[arg(long)]
        technique: Option<String>,
        /// Window size as WIDTHxHEIGHT.
        #[arg(long, default_value = "1280x720", value_parser = parse_size)]
        size: (u32, u32),
        /// Vertical sync: on (FIFO) or off (MAILBOX or IMMEDIATE when available, else FIFO).
        #[arg(long, default_value = "on", value_parser = parse_on_off, action = clap::ArgAction::Set)]
        vsync: bool,
        /// Exit after this many presented frames.
        #[arg(long)]
        frames: Option<u64>,
        /// Scripted input (see the README's "Demo" for the format).
        #[arg(long)]
        script: Option<PathBuf>,
        /// On exit, write the last frame (without the overlay) as PNG.
        #[arg(long)]
        screenshot: Option<PathBuf>,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// The gallery: every showcase scene under its techniques, beside plain lighting and
    /// their difference, as PNGs and an index.md with pixels changed and halos per scene.
    Gallery {
        /// Folder for the PNGs and index.md (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Resolution as WIDTHxHEIGHT.
        #[arg(long, default_value = "640x480", value_parser = parse_size)]
        size: (u32, u32),
        /// Only these scenes (repeatable; default: every showcase scene and `mixed`).
        #[arg(long)]
        scene: Vec<String>,
        /// Anti-aliasing after the tonemap: `off` (default) or `fxaa`.
        #[arg(long, default_value = "off")]
        aa: String,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Print the compiled render graph: passes, merged groups, barriers, lifetimes, memory.
    Plan {
        #[command(flatten)]
        frame: FrameArgs,
    },
    /// Stability sweep: render a technique at extreme parameters and on hostile geometry and
    /// count NaN, Inf, the largest value and fp16 overflows per case (fails on any NaN/Inf).
    Sweep {
        /// The technique to sweep (`translucency` or `layered`).
        technique: String,
        /// Resolution of each case as WIDTHxHEIGHT.
        #[arg(long, default_value = "64x48", value_parser = parse_size)]
        size: (u32, u32),
        /// Also write the table to this Markdown file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Only the quick subset of cases (`layered`: every medium back-lit and every
        /// situation at the two corners).
        #[arg(long)]
        quick: bool,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// The report suite: every technique's passes beside their speed-of-light copies, the
    /// seeds' tables beside ours, scaling curves and error against time, as DIR/report.md with
    /// PNG plots. With a section name (`translucency`, `sss`, `li`), only that error-against-time
    /// section.
    Report {
        /// Only this error-against-time section (`translucency`, `sss` or `li`: Li et al.'s
        /// layered passes, every knob); default: the whole suite.
        technique: Option<String>,
        /// Output directory.
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// The small preset (suite: about 15 s on the project's 2-core lavapipe machine; `li`:
        /// 128x128, fewer variants, 3 rounds; the translucency and sss sections ignore it).
        #[arg(long)]
        quick: bool,
        /// Resolution as WIDTHxHEIGHT (suite: of the per-technique tables; default 1024x768,
        /// --quick 256x192; sections: of the timed frames, default 1024x768, `li` 256x256 and
        /// --quick 128x128).
        #[arg(long, value_parser = parse_size)]
        size: Option<(u32, u32)>,
        /// Measured rounds or frames (1 to 100000; section default 15; suite 25, --quick 3;
        /// `li` --quick 3).
        #[arg(long, value_parser = parse_frames)]
        rounds: Option<usize>,
        /// Discarded rounds first (0 to 10000; section default 3; suite 3, --quick 1; `li`
        /// --quick 1).
        #[arg(long, value_parser = parse_warmup)]
        warmup: Option<usize>,
        #[command(flatten)]
        gpu: GpuArgs,
    },
    /// Load a mesh, texture, MTL or scene file and summarise it (or say what is wrong with it).
    Inspect {
        /// The file (.obj, .mtl, .png, .jpg, .tga, .exr, .hdr, .toml).
        file: PathBuf,
    },
    /// Bake a local thickness map (GDC 2011: ambient occlusion with inverted normals).
    BakeThickness {
        /// The mesh (OBJ).
        mesh: PathBuf,
        /// Write a thickness texture (PNG, grayscale, thin = white; needs UVs).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the mesh back as OBJ with the thickness as vertex colours (`v x y z r g b`).
        #[arg(long)]
        per_vertex: Option<PathBuf>,
        /// Rays per sample (1 to 1048576).
        #[arg(long, default_value_t = 256, value_parser = parse_rays)]
        rays: u32,
        /// Texture size in texels (square, 1 to 8192).
        #[arg(long, default_value_t = 512, value_parser = parse_bake_size)]
        size: u32,
        /// Occlusion distance (default: the mesh's bounding-box diagonal).
        #[arg(long, allow_negative_numbers = true, value_parser = parse_max_distance)]
        max_distance: Option<f32>,
        /// Random seed (the bake is deterministic for a seed).
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
}

#[derive(Args, Clone)]
struct FrameArgs {
    /// Scene: a built-in name (see `lucent scenes`) or a .toml scene file.
    #[arg(long, default_value = "smoke")]
    scene: String,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768", value_parser = parse_size)]
    size: (u32, u32),
    /// What the frame shades: `auto` (default) is what the scene's materials ask for, every
    /// technique composed in one frame; `none` (plain deferred lighting), `translucency`,
    /// `control`, `lcb`, `lbb` (the thesis's per-Gaussian SSS chains), `separable` or
    /// `bilateral` (two-pass SSS) restrict the frame to one technique (A/B runs, the seeds'
    /// tables).
    #[arg(long, default_value = "auto")]
    technique: String,
    /// Do not merge same-pixel passes into subpasses (A/B comparison).
    #[arg(long)]
    no_merge: bool,
    /// Do not alias transient images' memory (A/B comparison).
    #[arg(long)]
    no_alias: bool,
    /// Precision of the G-buffer's colour targets: compact (RGBA8 albedo and translucency,
    /// fp16 normal), half (all RGBA16F) or full (all RGBA32F).
    #[arg(long, default_value = "compact", value_parser = parse_precision)]
    gbuffer: GBufferPrecision,
    /// Store coloured thickness as grayscale (its luminance), the talk's one-channel G-buffer.
    #[arg(long)]
    grayscale: bool,
    /// Run the SSS blurs over the whole screen instead of only the rectangles of objects with
    /// a profile (A/B comparison).
    #[arg(long)]
    no_sss_tiles: bool,
    /// SSS (control, lcb, lbb): refit the profile with this many Gaussians (1-8): fewer blur
    /// pairs, at the fit error `lucent plan` and the report print.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_gaussians)]
    sss_gaussians: Option<usize>,
    /// SSS (control, lcb, lbb): precision of the sum-of-Gaussians targets: half (RGBA16F) or
    /// full (RGBA32F, the default).
    #[arg(long, value_parser = parse_sss_precision)]
    sss_precision: Option<SssPrecision>,
    /// LBB: the bilateral blur's sensitivity to depth differences, relative to each profile
    /// Gaussian's width (a finite number >= 0; 1: weights follow the taps' 3D distance;
    /// default 1).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_sensitivity)]
    sensitivity: Option<f32>,
    /// LBB: blur the light and the LEAN moments as one packed RGBA32UI target (eight fp16
    /// halves) instead of two RGBA16F targets (A/B comparison; slower on lavapipe).
    #[arg(long)]
    sss_packed: bool,
    /// LBB: bilateral taps per direction (3, 5 or 7; default 5; the thesis's shader has 7).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_taps)]
    sss_taps: Option<u32>,
    /// The two-pass blurs (separable, bilateral): samples per direction (11, 17 or 25;
    /// default 17).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_samples)]
    sss_samples: Option<u32>,
    /// The two-pass blurs' 1-D kernel: marginal (each Gaussian's 1-D marginal, the default)
    /// or line (the profile along a line, Jimenez 2015).
    #[arg(long, value_parser = parse_kernel_shape)]
    sss_kernel: Option<KernelShape>,
    /// The separable blur at half resolution per side, upsampled depth-aware.
    #[arg(long)]
    sss_half_res: bool,
    /// The separable blur's taps: bilinear (between texels, Jimenez's) or point (the nearest
    /// texel: one fetch instead of four on a CPU driver).
    #[arg(long, value_parser = parse_filter)]
    sss_filter: Option<bool>,
    /// No light casts shadows (no light-space maps pass; each light's own `shadows = false`
    /// turns off just that light's).
    #[arg(long)]
    no_shadows: bool,
    /// Edge of each light-space map face in texels (16 to 4096; default 1024; Li et al.'s
    /// Table 1 uses 512 and 1024). Halved until every face fits an 8192x8192 atlas.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_shadow_size)]
    shadow_size: Option<u32>,
    /// Layered media (Li et al.): single scattering's march steps along the refracted view
    /// ray (1 to 64; default 4).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_layered_steps)]
    layered_steps: Option<u32>,
    /// Layered media: multiple scattering's pixel lights per pixel (4 to 64; default 12, Li
    /// et al.'s).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_pixel_lights)]
    pixel_lights: Option<u32>,
    /// Layered media: single scattering's phase function: hg (true Henyey-Greenstein, the
    /// default) or schlick (Li et al.'s eq. 9 form with Schlick's k).
    #[arg(long, value_parser = parse_phase)]
    phase: Option<PhaseForm>,
    /// Layered media: the irradiance image multiple scattering gathers from at half
    /// resolution per side.
    #[arg(long)]
    half_irradiance: bool,
    /// Layered media: multiple scattering gathered once per 2x2 block and upsampled by
    /// material and depth (cheaper; a coarser mottling than the full gather's grain).
    #[arg(long)]
    half_gather: bool,
    /// Layered media: single scattering's depth D_max in mean free paths of the first layer
    /// (a finite number > 0; default 4).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_single_depth)]
    single_depth: Option<f32>,
    /// The instant shown, in seconds (a finite number; default 0): a deforming scene
    /// (`dynamic`) is deformed at it; `bench` starts its animation there.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_time)]
    time: Option<f32>,
    /// Light from the environment, replacing the scene's: `scene` (default: the scene's own),
    /// `none`, `constant`, `hemisphere`, `sky` (the built-in procedural sky map) or the path of
    /// an equirectangular map (HDR, EXR, PNG, ...), reduced to nine SH irradiance coefficients.
    #[arg(long, default_value = "scene")]
    environment: String,
    /// Multiplies the environment's radiance (a finite number >= 0; default 1).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0, value_parser = parse_environment_intensity)]
    environment_intensity: f32,
    /// Anti-aliasing after the tonemap: `off` (default) or `fxaa`.
    #[arg(long, default_value = "off")]
    aa: String,
}

impl FrameArgs {
    /// Loads the scene (thickness baked, cached), at `--time`, with `--environment`.
    fn load_scene(&self) -> Result<scene::Scene> {
        // Parsed first: a bad environment is refused before a bake.
        let environment = scene::environment::from_command_line(&self.environment)?;
        let mut scene = bake::load_scene_baked(&self.scene)?;
        // Range-checked by the parser (finite).
        scene.time = self.time.unwrap_or(0.0);
        if let Some(environment) = environment {
            scene.environment = environment;
        }
        // Range-checked by the parser (finite, >= 0).
        scene.environment = scene.environment.scaled(self.environment_intensity);
        Ok(scene)
    }
}

fn parse_environment_intensity(text: &str) -> std::result::Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| format!("'{text}' is not a finite number >= 0"))
}

fn parse_time(text: &str) -> std::result::Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| format!("'{text}' is not a finite number of seconds"))
}

fn parse_layered_steps(text: &str) -> std::result::Result<u32, String> {
    let r = lucent::features::layered::STEP_RANGE;
    count_in(text, u64::from(*r.start())..=u64::from(*r.end())).map(|v| v as u32)
}

fn parse_pixel_lights(text: &str) -> std::result::Result<u32, String> {
    let r = lucent::features::layered::PIXEL_LIGHT_RANGE;
    count_in(text, u64::from(*r.start())..=u64::from(*r.end())).map(|v| v as u32)
}

fn parse_phase(text: &str) -> std::result::Result<PhaseForm, String> {
    PhaseForm::ALL
        .iter()
        .find(|(n, _)| *n == text)
        .map(|&(_, p)| p)
        .ok_or_else(|| format!("'{text}' is not one of hg, schlick"))
}

fn parse_single_depth(text: &str) -> std::result::Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0 && *v <= 1e3)
        .ok_or_else(|| format!("'{text}' is not a number of mean free paths in (0, 1000]"))
}

fn parse_shadow_size(text: &str) -> std::result::Result<u32, String> {
    let sizes = lucent::features::shadows::SHADOW_SIZES;
    count_in(text, u64::from(*sizes.start())..=u64::from(*sizes.end())).map(|v| v as u32)
}

fn parse_filter(text: &str) -> std::result::Result<bool, String> {
    match text {
        "point" => Ok(true),
        "bilinear" => Ok(false),
        _ => Err(format!("'{text}' is not one of point, bilinear")),
    }
}

fn parse_samples(text: &str) -> std::result::Result<u32, String> {
    SAMPLE_COUNTS
        .iter()
        .copied()
        .find(|n| n.to_string() == text.trim())
        .ok_or_else(|| format!("'{text}' is not one of 11, 17, 25"))
}

fn parse_kernel_shape(text: &str) -> std::result::Result<KernelShape, String> {
    match text {
        "marginal" => Ok(KernelShape::Marginal),
        "line" => Ok(KernelShape::Line),
        _ => Err(format!("'{text}' is not one of marginal, line")),
    }
}

/// A whole number in `range`, for the count flags: the bound is checked here, at parse time,
/// so nothing is ever sized from an absurd count.
fn count_in(text: &str, range: std::ops::RangeInclusive<u64>) -> std::result::Result<u64, String> {
    let (lo, hi) = (range.start(), range.end());
    text.trim()
        .parse::<u64>()
        .ok()
        .filter(|v| range.contains(v))
        .ok_or_else(|| format!("'{text}' is not a whole number from {lo} to {hi}"))
}

fn parse_frames(text: &str) -> std::result::Result<usize, String> {
    count_in(text, 1..=bench::MAX_FRAMES as u64).map(|v| v as usize)
}

fn parse_warmup(text: &str) -> std::result::Result<usize, String> {
    count_in(text, 0..=bench::MAX_WARMUP as u64).map(|v| v as usize)
}

fn parse_rays(text: &str) -> std::result::Result<u32, String> {
    count_in(text, 1..=u64::from(lucent::bake::MAX_RAYS)).map(|v| v as u32)
}

fn parse_bake_size(text: &str) -> std::result::Result<u32, String> {
    count_in(text, 1..=u64::from(lucent::bake::MAX_TEXTURE_SIZE)).map(|v| v as u32)
}

fn parse_gaussians(text: &str) -> std::result::Result<usize, String> {
    count_in(text, 1..=8).map(|v| v as usize)
}

fn parse_sensitivity(text: &str) -> std::result::Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| format!("'{text}' is not a finite number >= 0"))
}

fn parse_max_distance(text: &str) -> std::result::Result<f32, String> {
    text.trim()
        .parse::<f32>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("'{text}' is not a finite number > 0"))
}

fn parse_taps(text: &str) -> std::result::Result<u32, String> {
    match text {
        "3" => Ok(3),
        "5" => Ok(5),
        "7" => Ok(7),
        _ => Err(format!("'{text}' is not one of 3, 5, 7")),
    }
}

fn parse_sss_precision(text: &str) -> std::result::Result<SssPrecision, String> {
    SssPrecision::ALL
        .iter()
        .find(|(n, _)| *n == text)
        .map(|&(_, p)| p)
        .ok_or_else(|| format!("'{text}' is not one of half, full"))
}

fn parse_precision(text: &str) -> std::result::Result<GBufferPrecision, String> {
    GBufferPrecision::ALL
        .iter()
        .find(|(n, _)| *n == text)
        .map(|&(_, p)| p)
        .ok_or_else(|| format!("'{text}' is not one of compact, half, full"))
}

#[derive(Args, Clone)]
struct GpuArgs {
    /// Pick the first device whose name contains this (case-insensitive).
    #[arg(long)]
    device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation (also
    /// LUCENT_VALIDATION=1); any validation error makes the command fail.
    #[arg(long)]
    validation: bool,
}

#[cfg(feature = "window")]
fn parse_on_off(text: &str) -> std::result::Result<bool, String> {
    match text {
        "on" => Ok(true),
        "off" => Ok(false),
        other => Err(format!("'{other}' is not on or off")),
    }
}

fn parse_size(text: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("'{text}' is not WIDTHxHEIGHT"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<u32>()
            .ok()
            .filter(|&v| (1..=16384).contains(&v))
            .ok_or_else(|| format!("'{s}' is not a size between 1 and 16384"))
    };
    Ok((parse(w)?, parse(h)?))
}

impl FrameArgs {
    fn settings(&self, export_hdr: bool) -> Result<FrameSettings> {
        Ok(FrameSettings {
            width: self.size.0,
            height: self.size.1,
            technique: Technique::parse(&self.technique)?,
            compile: CompileOptions {
                merge: !self.no_merge,
                alias: !self.no_alias,
                ..CompileOptions::default()
            },
            export_hdr,
            export_gbuffer: false,
            export_lit: false,
            gbuffer: self.gbuffer,
            force_grayscale: self.grayscale,
            sss_tiles: !self.no_sss_tiles,
            fault: None,
            sss: {
                let defaults = SssKnobs::default();
                SssKnobs {
                    gaussians: self.sss_gaussians,
                    precision: self.sss_precision.unwrap_or(defaults.precision),
                    packed: self.sss_packed,
                    taps: self.sss_taps.unwrap_or(defaults.taps),
                    // Range-checked by the parser (finite, >= 0).
                    sensitivity: self.sensitivity.unwrap_or(defaults.sensitivity),
                    samples: self.sss_samples.unwrap_or(defaults.samples),
                    shape: self.sss_kernel.unwrap_or(defaults.shape),
                    half_res: self.sss_half_res,
                    point_taps: self.sss_filter.unwrap_or(defaults.point_taps),
                }
            },
            debug_view: None,
            frames_in_flight: 1,
            target: None,
            shadows: ShadowSettings {
                enabled: !self.no_shadows,
                size: self.shadow_size.unwrap_or(ShadowSettings::default().size),
            },
            antialias: lucent::features::antialias::Antialias::parse(&self.aa)?,
            export_ldr: false,
            layered: {
                let defaults = LayeredKnobs::default();
                LayeredKnobs {
                    steps: self.layered_steps.unwrap_or(defaults.steps),
                    pixel_lights: self.pixel_lights.unwrap_or(defaults.pixel_lights),
                    phase: self.phase.unwrap_or(defaults.phase),
                    half_irradiance: self.half_irradiance,
                    half_gather: self.half_gather,
                    max_depth_mfp: self.single_depth.unwrap_or(defaults.max_depth_mfp),
                }
            },
        })
    }

    /// The knobs given on the command line that do nothing in this frame (`desc`, of `scene`
    /// under `settings`), each as a warning naming the technique they need.
    fn inapplicable_knobs(
        &self,
        scene: &scene::Scene,
        settings: &FrameSettings,
        desc: &FrameDesc,
    ) -> Vec<String> {
        let chains = desc.sss.as_ref().map(|s| s.chains()).unwrap_or_default();
        let lbb_chain = chains.contains(&SssBlur::LeanBilateral);
        let separable = chains.contains(&SssBlur::Separable);
        let two_pass = chains.iter().any(|b| !b.iterative());
        let iterative = chains.iter().any(|b| b.iterative());
        let sss = !chains.is_empty();
        let translucent = desc.translucency.is_some();
        let lbb = "the bilateral blur: --technique lbb (or SSS materials with blur = \"lbb\")";
        let blur = "screen-space SSS: --technique control, lcb, lbb, separable or bilateral \
                    (or auto) on a scene with SSS materials";
        let per_gaussian = "the per-Gaussian blurs: --technique control, lcb or lbb (or SSS \
                            materials with one of those blurs)";
        let two = "the two-pass blurs: --technique separable or bilateral (or SSS materials \
                   with one of those blurs)";
        let sep = "the separable blur: --technique separable (or SSS materials with blur = \
                   \"separable\")";
        let layered = "Li et al.'s layered media: --technique layered (or auto) on a scene \
                       with layered materials";
        let gdc = "GDC 2011 translucency: --technique translucency (or auto) on a scene with \
                   translucent materials";
        let knobs = [
            (self.sss_taps.is_some(), "--sss-taps", lbb, lbb_chain),
            (self.sss_packed, "--sss-packed", lbb, lbb_chain),
            (self.sensitivity.is_some(), "--sensitivity", lbb, lbb_chain),
            (self.sss_gaussians.is_some(), "--sss-gaussians", blur, sss),
            (
                self.sss_precision.is_some(),
                "--sss-precision",
                per_gaussian,
                iterative,
            ),
            (self.sss_samples.is_some(), "--sss-samples", two, two_pass),
            (self.sss_kernel.is_some(), "--sss-kernel", two, two_pass),
            (self.sss_half_res, "--sss-half-res", sep, separable),
            (self.sss_filter.is_some(), "--sss-filter", sep, separable),
            (self.no_sss_tiles, "--no-sss-tiles", blur, sss),
            (self.grayscale, "--grayscale", gdc, translucent),
            (
                self.time.is_some(),
                "--time",
                "a deforming scene (one with a [deformation] table, e.g. dynamic)",
                scene.deformation.is_some(),
            ),
            (
                self.shadow_size.is_some(),
                "--shadow-size",
                "a light that casts shadows (without --no-shadows; lights with shadows = true)",
                desc.shadows.is_some(),
            ),
        ];
        let layered_knobs = [
            (self.layered_steps.is_some(), "--layered-steps"),
            (self.pixel_lights.is_some(), "--pixel-lights"),
            (self.phase.is_some(), "--phase"),
            (self.half_irradiance, "--half-irradiance"),
            (self.half_gather, "--half-gather"),
            (self.single_depth.is_some(), "--single-depth"),
        ]
        .map(|(given, flag)| (given, flag, layered, desc.layered.is_some()));
        let technique = settings.technique;
        knobs
            .iter()
            .chain(&layered_knobs)
            .filter(|(given, _, _, applies)| *given && !applies)
            .map(|(_, flag, needs, _)| {
                format!(
                    "{flag} has no effect with --technique {} on scene '{}': it applies to \
                     {needs}",
                    technique.name(),
                    scene.name
                )
            })
            .collect()
    }

    /// Prints a warning (on stderr) for every knob that does nothing in this frame.
    fn warn_inapplicable(&self, scene: &scene::Scene, settings: &FrameSettings, desc: &FrameDesc) {
        for warning in self.inapplicable_knobs(scene, settings, desc) {
            eprintln!("lucent: warning: {warning}");
        }
    }
}

/// The GPU objects every GPU command needs, torn down in order.
struct Session {
    gpu: GpuContext,
    shaders: ShaderCompiler,
    pipeline_cache: PipelineCache,
}

impl Session {
    fn new(args: &GpuArgs) -> Result<Self> {
        let gpu = GpuContext::new(&ContextDesc::from_env(args.validation, args.device.clone()))?;
        log::info!("device: {} ({})", gpu.info.describe(), gpu.info.driver());
        // The SPIR-V compiled with the crate (the demo compiles at run time, for hot reload).
        let shaders = ShaderCompiler::shipped()?;
        let pipeline_cache = PipelineCache::load_default(&gpu)?;
        Ok(Self {
            gpu,
            shaders,
            pipeline_cache,
        })
    }

    /// Saves the pipeline cache and fails if validation reported errors.
    fn finish(self) -> Result<()> {
        if let Err(e) = self.pipeline_cache.save(&self.gpu.device) {
            log::warn!("pipeline cache not saved: {e}");
        }
        let errors = self.gpu.validation_error_count();
        self.pipeline_cache.destroy(&self.gpu.device);
        if errors > 0 {
            // The messages themselves went to the log as they arrived.
            return Err(LucentError::InvalidInput(format!(
                "the validation layer reported {errors} error(s)"
            )));
        }
        Ok(())
    }
}

/// Builds the frame of `frame`'s scene, runs `work` with it, and tears everything down in order
/// whatever `work` returned; validation errors fail the command.
fn with_renderer(
    frame: &FrameArgs,
    gpu_args: &GpuArgs,
    export_hdr: bool,
    work: impl FnOnce(&Session, &Renderer, &scene::Scene) -> Result<()>,
) -> Result<()> {
    let settings = frame.settings(export_hdr)?;
    let scene = frame.load_scene()?;
    frame.warn_inapplicable(&scene, &settings, &FrameDesc::new(&scene, &settings)?);
    // Texture headers first: one too large is refused before the device is even opened.
    scene::texture::scene_texture_sizes(&scene, None)?;
    with_session(gpu_args, |session| {
        check_device_fits(&session.gpu, &scene, &settings)?;
        let renderer = Renderer::new(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            &scene,
            settings,
        )?;
        let worked = work(session, &renderer, &scene);
        let idle = session.gpu.wait_idle();
        renderer.destroy(&session.gpu);
        worked.and(idle)
    })
}

/// Refuses textures larger than the device's `maxImageDimension2D`, and warns when the
/// frame's images and the textures will not fit the device's largest memory heap (naming the
/// largest image and what to try): an out-of-memory error later would be less clear. Only a
/// warning, because some drivers (lavapipe: 2 GiB reported) allocate beyond the heap they
/// report.
fn check_device_fits(
    gpu: &GpuContext,
    scene: &scene::Scene,
    settings: &FrameSettings,
) -> Result<()> {
    let info = &gpu.info;
    let textures = scene::texture::scene_texture_sizes(scene, Some(info.max_image_dimension_2d))?;
    let plan = plan_frame(settings, &FrameDesc::new(scene, settings)?)?;
    let (frame_bytes, largest) = plan.frame_memory();
    // Maps go up as RGBA16F with mips (4/3); in LEAN frames a normal map as two such maps.
    let lean = FrameDesc::new(scene, settings)?.lean();
    let texture_bytes: u64 = textures
        .iter()
        .map(|(_, w, h, normal)| {
            let copies = if *normal && lean { 2 } else { 1 };
            u64::from(*w) * u64::from(*h) * 8 * 4 / 3 * copies
        })
        .sum();
    let heap = info.device_local_bytes;
    if heap > 0 && frame_bytes.saturating_add(texture_bytes) > heap {
        let size = lucent::error::format_bytes;
        let largest = largest.map_or(String::new(), |r| {
            format!(
                "; largest image '{}' {}x{} {}, {}",
                r.name,
                r.info.width,
                r.info.height,
                lucent::backend::format::format_name(r.info.format),
                size(r.estimated_bytes())
            )
        });
        eprintln!(
            "lucent: warning: the frame at {}x{} needs about {} of GPU memory for its images{largest}{}, \
             more than the device's largest memory heap ({}): it may fail with out of memory; \
             try a smaller --size",
            settings.width,
            settings.height,
            size(frame_bytes),
            if texture_bytes > 0 {
                format!(", and {} for textures", size(texture_bytes))
            } else {
                String::new()
            },
            size(heap)
        );
    }
    Ok(())
}

/// Opens a session, runs `work` with it, and closes it whatever `work` returned; `work`'s error
/// comes first, then validation errors fail the command.
fn with_session<T>(gpu_args: &GpuArgs, work: impl FnOnce(&Session) -> Result<T>) -> Result<T> {
    let session = Session::new(gpu_args)?;
    let result = work(&session);
    let finished = session.finish();
    let value = result?;
    finished?;
    Ok(value)
}

fn render(
    frame: &FrameArgs,
    gpu_args: &GpuArgs,
    out: Option<PathBuf>,
    exr: Option<PathBuf>,
) -> Result<()> {
    let out = out.unwrap_or_else(|| PathBuf::from(format!("{}.png", frame.scene)));
    let mut outputs = vec![("--out", out.as_path())];
    outputs.extend(exr.as_deref().map(|e| ("--exr", e)));
    check_scene_outputs(&frame.scene, &outputs)?;
    with_renderer(frame, gpu_args, exr.is_some(), |session, renderer, _| {
        let gpu = &session.gpu;
        let (width, height) = (renderer.settings.width, renderer.settings.height);
        let mut runner = FrameRunner::new(gpu, renderer.executable.plan.physical.len())?;
        let timing = runner.run_frame(gpu, &renderer.executable);
        runner.destroy(gpu);
        let timing = timing?;
        output::write_png_rgba8(&out, width, height, &renderer.read_display(gpu)?)?;
        println!(
            "wrote {} ({width}x{height}, frame {:.2} ms on {})",
            out.display(),
            timing.wall_ms,
            gpu.info.describe()
        );
        if let Some(exr) = &exr {
            output::write_exr_rgba32f(exr, width, height, &renderer.read_hdr(gpu)?)?;
            println!("wrote {}", exr.display());
        }
        Ok(())
    })
}

fn bench_command(
    frame: &FrameArgs,
    gpu_args: &GpuArgs,
    options: BenchOptions,
    output: BenchOutput,
) -> Result<()> {
    let BenchOutput {
        format,
        speed_of_light,
        json,
        out,
        against,
        compare_thesis,
    } = output;
    let format = bench::Format::parse(&format)?;
    let against = against.map(|t| Technique::parse(&t)).transpose()?;
    let technique = Technique::parse(&frame.technique)?;
    let thesis_table =
        lucent::report::seeds::thesis_table(technique.name()).filter(|_| compare_thesis);
    let gdc = compare_thesis && technique == Technique::Translucency;
    // Li et al.'s Table 1: their technique, alone or in `auto` (checked against the scene's
    // materials once it is loaded).
    let li = compare_thesis && matches!(technique, Technique::Auto | Technique::Layered);
    if compare_thesis && thesis_table.is_none() && !gdc && !li {
        return Err(LucentError::InvalidInput(format!(
            "--compare-seeds needs --technique control (the thesis's Table 2), lcb or lbb (its \
             Table 1), translucency (GDC 2011's cost), or auto or layered on a scene with \
             layered materials (Li et al.'s Table 1); '{}' has no published table",
            technique.name()
        )));
    }
    if format != bench::Format::Markdown && (compare_thesis || against.is_some()) {
        return Err(LucentError::InvalidInput(
            "--compare-thesis and --against print Markdown tables; use them with --format markdown"
                .into(),
        ));
    }
    let outputs: Vec<(&str, &std::path::Path)> = [("--json", &json), ("--out", &out)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    check_scene_outputs(&frame.scene, &outputs)?;
    // With CSV or JSON on stdout, messages go to stderr so stdout stays parseable.
    let note = |text: String| {
        if format == bench::Format::Markdown {
            println!("{text}");
        } else {
            eprintln!("{text}");
        }
    };
    with_renderer(frame, gpu_args, false, |session, renderer, scene| {
        let gpu = &session.gpu;
        if li && FrameDesc::new(scene, &renderer.settings)?.layered.is_none() {
            return Err(LucentError::InvalidInput(format!(
                "--compare-seeds with --technique {}: scene '{}' has no layered material, so \
                 Li et al.'s Table 1 has nothing to compare (try --scene scaling:N or layered)",
                technique.name(),
                frame.scene
            )));
        }
        let report = if speed_of_light {
            let mut copies = lucent::measure::speed_of_light::CopyFrame::for_plan(
                gpu,
                &session.shaders,
                &session.pipeline_cache,
                &renderer.executable.plan,
            )?;
            let report = bench::run_with_floor(
                gpu,
                renderer,
                Some(&mut copies),
                scene,
                &frame.scene,
                &options,
            );
            let idle = gpu.wait_idle();
            copies.destroy(gpu);
            idle?;
            report?
        } else {
            bench::run(gpu, renderer, scene, &frame.scene, &options)?
        };
        print!("{}", report.format(format));
        if format != bench::Format::Csv {
            println!();
        }
        if let Some(table) = &thesis_table {
            println!("{}", lucent::report::seeds::beside(&report, table));
        }
        if li {
            let shadows = renderer.settings.shadows;
            println!(
                "{}",
                lucent::report::seeds::li_bench_beside(
                    &report,
                    lucent::measure::scaling::triangles(scene),
                    shadows.enabled.then_some(shadows.size),
                )
            );
        }
        if gdc {
            let cost = lucent::report::gdc_cost(
                gpu,
                &session.shaders,
                &session.pipeline_cache,
                scene,
                &format!("`{}`", frame.scene),
                (renderer.settings.width, renderer.settings.height),
                (options.frames, options.warmup),
            )?;
            println!("{}", lucent::report::seeds::gdc_beside(&cost));
        }
        if let Some(technique) = against {
            let other = Renderer::new(
                gpu,
                &session.shaders,
                &session.pipeline_cache,
                scene,
                FrameSettings {
                    technique,
                    ..renderer.settings
                },
            )?;
            let compared = bench::compare(
                gpu,
                [
                    (technique.name(), &other),
                    (renderer.settings.technique.name(), renderer),
                ],
                scene,
                options.frames,
                options.warmup,
            );
            let idle = gpu.wait_idle();
            other.destroy(gpu);
            idle?;
            let compared = compared?;
            println!("{}", compared.markdown(&gpu.info.describe()));
            if thesis_table.is_some() {
                if let Some(line) = lucent::report::seeds::thesis_ratio_line(&compared) {
                    println!("{line}");
                }
            }
        }
        if let Some(json) = &json {
            lucent::files::write_file_atomic(json, report.json().as_bytes())?;
            note(format!("wrote {}", json.display()));
        }
        if let Some(out) = &out {
            let (width, height) = (renderer.settings.width, renderer.settings.height);
            output::write_png_rgba8(out, width, height, &renderer.read_display(gpu)?)?;
            note(format!("wrote {}", out.display()));
        }
        if report.trusted {
            Ok(())
        } else {
            // Tiny runs fail the checks by chance on a shared machine: say so.
            let short = if options.frames < bench::SHORT_RUN_FRAMES {
                format!(
                    "; {} measured frames is a short run, and short runs are noisy: try \
                     --frames {} or more",
                    options.frames,
                    bench::SHORT_RUN_FRAMES * 3
                )
            } else {
                String::new()
            };
            Err(LucentError::Timing(format!(
                "the per-pass times could not be verified (see the checks above){short}"
            )))
        }
    })
}

/// Refuses, before any work, outputs that are the scene file or a file it names, or that are
/// the same file twice.
fn check_scene_outputs(scene: &str, outputs: &[(&str, &std::path::Path)]) -> Result<()> {
    let inputs = scene::inputs::scene_inputs(scene);
    let inputs: Vec<(&str, &std::path::Path)> = inputs
        .iter()
        .map(|(what, path)| (what.as_str(), path.as_path()))
        .collect();
    lucent::files::check_outputs(&inputs, outputs)
}

/// What `bench` prints and writes besides the measurement itself.
struct BenchOutput {
    format: String,
    speed_of_light: bool,
    json: Option<PathBuf>,
    out: Option<PathBuf>,
    against: Option<String>,
    compare_thesis: bool,
}

fn bake_thickness(
    mesh_path: &std::path::Path,
    out: Option<PathBuf>,
    per_vertex: Option<PathBuf>,
    rays: u32,
    size: u32,
    max_distance: Option<f32>,
    seed: u64,
) -> Result<()> {
    if out.is_none() && per_vertex.is_none() {
        return Err(LucentError::InvalidInput(
            "bake-thickness needs --out FILE.png and/or --per-vertex OUT.obj".into(),
        ));
    }
    // --rays, --size and --max-distance were range-checked by their parsers.
    let outputs: Vec<(&str, &std::path::Path)> = [("--out", &out), ("--per-vertex", &per_vertex)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    lucent::files::check_outputs(&[("the input mesh", mesh_path)], &outputs)?;
    let loaded = scene::obj::load_obj(mesh_path)?;
    let options = lucent::bake::BakeOptions {
        rays,
        max_distance,
        seed,
        texture_size: size,
        progress: true,
    };
    if let Some(out) = &out {
        let (map, stats) = lucent::bake::bake_texture(&loaded.mesh, &options)?;
        let covered: Vec<f32> = (map.values.iter().zip(&map.coverage))
            .filter_map(|(&v, &c)| c.then_some(v))
            .collect();
        if let Some(warning) = lucent::bake::constant_warning(&covered, &stats) {
            eprintln!("lucent: warning: {warning}");
        }
        map.write_png(out)?;
        println!("{}", lucent::bake::bake_report(&stats));
        println!(
            "wrote {} ({size}x{size}; the UVs cover {} texels, {:.1}%)",
            out.display(),
            covered.len(),
            100.0 * covered.len() as f64 / f64::from(size).powi(2)
        );
    }
    if let Some(per_vertex) = &per_vertex {
        let (values, stats) = lucent::bake::bake_per_vertex(&loaded.mesh, &options)?;
        if let Some(warning) = lucent::bake::constant_warning(&values, &stats) {
            eprintln!("lucent: warning: {warning}");
        }
        let colors: Vec<glam::Vec3> = values.iter().map(|&v| glam::Vec3::splat(v)).collect();
        scene::obj::write_obj_with_colors(per_vertex, &loaded.mesh, &colors)?;
        println!("{}", lucent::bake::bake_report(&stats));
        println!("wrote {} ({} vertices)", per_vertex.display(), values.len());
    }
    Ok(())
}

fn sweep_command(
    technique: &str,
    (width, height): (u32, u32),
    out: Option<PathBuf>,
    quick: bool,
    gpu_args: &GpuArgs,
) -> Result<()> {
    if !matches!(technique, "translucency" | "layered") {
        return Err(LucentError::InvalidInput(format!(
            "sweep: unknown technique '{technique}'; available: translucency, layered"
        )));
    }
    if quick && technique != "layered" {
        return Err(LucentError::InvalidInput(
            "sweep: --quick applies to `sweep layered` only".into(),
        ));
    }
    if let Some(out) = &out {
        lucent::files::check_outputs(&[], &[("--out", out)])?;
    }
    if technique == "layered" {
        return sweep_layered_command((width, height), out, quick, gpu_args);
    }
    let cases = lucent::measure::sweep::translucency_cases();
    let (rows, device) = with_session(gpu_args, |session| {
        let rows = lucent::measure::sweep::run_translucency(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            width,
            height,
            &cases,
        )?;
        Ok((rows, session.gpu.info.describe()))
    })?;
    let table = lucent::measure::sweep::markdown(&rows, width, height, &device);
    println!("{table}");
    if let Some(out) = &out {
        lucent::files::write_file_atomic(out, table.as_bytes())?;
        println!("wrote {}", out.display());
    }
    let bad: usize = rows.iter().map(|r| r.nan + r.inf).sum();
    if bad > 0 {
        return Err(LucentError::InvalidInput(format!(
            "sweep: {bad} NaN/Inf values (see the table)"
        )));
    }
    Ok(())
}

fn sweep_layered_command(
    (width, height): (u32, u32),
    out: Option<PathBuf>,
    quick: bool,
    gpu_args: &GpuArgs,
) -> Result<()> {
    use lucent::measure::sweep_layered;
    let cases = if quick {
        sweep_layered::quick_layered_cases()?
    } else {
        sweep_layered::layered_cases()?
    };
    let total = cases.len();
    let terminal = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let (rows, device) = with_session(gpu_args, |session| {
        let rows = sweep_layered::run_layered(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            width,
            height,
            &cases,
            |i, row| {
                if terminal {
                    eprint!(
                        "\rsweep layered: {}/{total} ({} / {})\x1b[K",
                        i + 1,
                        row.case.label,
                        row.case.geometry.name()
                    );
                }
            },
        )?;
        if terminal {
            eprintln!();
        }
        Ok((rows, session.gpu.info.describe()))
    })?;
    let table = sweep_layered::markdown(&rows, width, height, &device);
    println!("{table}");
    if let Some(out) = &out {
        lucent::files::write_file_atomic(out, table.as_bytes())?;
        println!("wrote {}", out.display());
    }
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| r.bad() > 0)
        .map(|r| format!("{} / {}", r.case.label, r.case.geometry.name()))
        .collect();
    if !bad.is_empty() {
        let values: usize = rows.iter().map(|r| r.bad()).sum();
        return Err(LucentError::InvalidInput(format!(
            "sweep layered: {values} NaN/Inf values in {} cases (see the table): {}",
            bad.len(),
            bad.join(", ")
        )));
    }
    Ok(())
}

/// `report` as given on the command line.
struct ReportArgs {
    technique: Option<String>,
    out: PathBuf,
    quick: bool,
    size: Option<(u32, u32)>,
    rounds: Option<usize>,
    warmup: Option<usize>,
}

fn report_command(args: ReportArgs, gpu_args: &GpuArgs) -> Result<()> {
    if args.rounds == Some(0) {
        return Err(LucentError::InvalidInput(
            "report: --rounds must be at least 1".into(),
        ));
    }
    let (text, files) = match &args.technique {
        Some(technique) if technique == "li" => {
            let mut options = if args.quick {
                lucent::report::li::LiOptions::quick()
            } else {
                lucent::report::li::LiOptions::full()
            };
            if let Some((w, h)) = args.size {
                (options.width, options.height) = (w, h);
            }
            options.rounds = args.rounds.unwrap_or(options.rounds);
            options.warmup = args.warmup.unwrap_or(options.warmup);
            with_session(gpu_args, |session| {
                lucent::report::li::write_li_report(
                    &session.gpu,
                    &session.shaders,
                    &session.pipeline_cache,
                    &args.out,
                    &options,
                )
            })?
        }
        Some(technique) => {
            let write = match technique.as_str() {
                "translucency" => lucent::report::translucency::write_translucency_report,
                "sss" => lucent::report::sss::write_sss_report,
                _ => {
                    return Err(LucentError::InvalidInput(format!(
                        "report: unknown section '{technique}'; available: translucency, sss, li \
                         (or no section: the whole suite)"
                    )))
                }
            };
            let (width, height) = args.size.unwrap_or((1024, 768));
            let options = lucent::report::section::ReportOptions {
                width,
                height,
                rounds: args.rounds.unwrap_or(15),
                warmup: args.warmup.unwrap_or(3),
            };
            with_session(gpu_args, |session| {
                write(
                    &session.gpu,
                    &session.shaders,
                    &session.pipeline_cache,
                    &args.out,
                    &options,
                )
            })?
        }
        None => {
            let mut options = if args.quick {
                lucent::report::SuiteOptions::quick()
            } else {
                lucent::report::SuiteOptions::full()
            };
            if let Some((w, h)) = args.size {
                (options.width, options.height) = (w, h);
            }
            options.frames = args.rounds.unwrap_or(options.frames);
            options.warmup = args.warmup.unwrap_or(options.warmup);
            with_session(gpu_args, |session| {
                lucent::report::run(
                    &session.gpu,
                    &session.shaders,
                    &session.pipeline_cache,
                    &args.out,
                    options,
                )
            })?
        }
    };
    println!("{text}");
    for f in files {
        println!("wrote {}", f.display());
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Scenes => {
            for (name, description) in scene::BUILTIN_SCENES {
                println!("{name:<12} {description}");
            }
            Ok(())
        }
        Command::Render {
            frame,
            gpu,
            out,
            exr,
        } => render(&frame, &gpu, out, exr),
        Command::Bench {
            frame,
            gpu,
            frames,
            warmup,
            isolate,
            format,
            speed_of_light,
            json,
            out,
            against,
            compare_thesis,
        } => bench_command(
            &frame,
            &gpu,
            BenchOptions {
                frames,
                warmup,
                isolate,
            },
            BenchOutput {
                format,
                speed_of_light,
                json,
                out,
                against,
                compare_thesis,
            },
        ),
        Command::Sweep {
            technique,
            size,
            out,
            quick,
            gpu,
        } => sweep_command(&technique, size, out, quick, &gpu),
        Command::Report {
            technique,
            out,
            quick,
            size,
            rounds,
            warmup,
            gpu,
        } => report_command(
            ReportArgs {
                technique,
                out,
                quick,
                size,
                rounds,
                warmup,
            },
            &gpu,
        ),
        Command::Inspect { file } => {
            print!("{}", scene::inspect::inspect_file(&file)?);
            Ok(())
        }
        Command::BakeThickness {
            mesh,
            out,
            per_vertex,
            rays,
            size,
            max_distance,
            seed,
        } => bake_thickness(&mesh, out, per_vertex, rays, size, max_distance, seed),
        #[cfg(feature = "window")]
        Command::Demo {
            scene,
            technique,
            size,
            vsync,
            frames,
            script,
            screenshot,
            gpu,
        } => lucent::demo::run(lucent::demo::DemoOptions {
            scene,
            technique: technique.as_deref().map(Technique::parse).transpose()?,
            size,
            vsync,
            frames,
            script,
            screenshot,
            validation: gpu.validation,
            device: gpu.device,
            base: FrameSettings::new(size.0, size.1),
        }),
        Command::Gallery {
            out,
            size,
            scene,
            aa,
            gpu,
        } => {
            let settings = FrameSettings {
                antialias: lucent::features::antialias::Antialias::parse(&aa)?,
                ..FrameSettings::new(size.0, size.1)
            };
            let scenes: Vec<&str> = if scene.is_empty() {
                lucent::measure::gallery::GALLERY_SCENES
                    .iter()
                    .map(|(n, _)| *n)
                    .collect()
            } else {
                scene.iter().map(String::as_str).collect()
            };
            with_session(&gpu, |session| {
                let entries = lucent::measure::gallery::gallery(
                    &session.gpu,
                    &session.shaders,
                    &session.pipeline_cache,
                    &scenes,
                    settings,
                    &out,
                    |name| eprintln!("gallery: {name}"),
                )?;
                for e in &entries {
                    println!(
                        "{}: {:.1}% of pixels changed, {} halo pixels",
                        e.scene,
                        100.0 * e.look.changed,
                        e.look.halo_pixels
                    );
                }
                println!("wrote {}", out.join("index.md").display());
                Ok(())
            })
        }
        Command::Plan { frame } => {
            let settings = frame.settings(false)?;
            let scene = bake::load_scene_baked(&frame.scene)?;
            let desc = FrameDesc::new(&scene, &settings)?;
            frame.warn_inapplicable(&scene, &settings, &desc);
            let plan = plan_frame(&settings, &desc)?;
            print!("{}", plan.dump());
            Ok(())
        }
    }
}

/// A command-line error as the one line `lucent: error:` carries: clap's message, its tips,
/// and where the usage is (clap's own text spreads over several lines with a usage block).
fn usage_error(error: &clap::Error) -> String {
    use clap::error::ErrorKind;
    if error.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
        let commands: Vec<String> = <Cli as clap::CommandFactory>::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .collect();
        return format!(
            "no command given; commands: {} (see `lucent --help`)",
            commands.join(", ")
        );
    }
    let text = error.render().to_string();
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or("invalid command line");
    let mut parts = vec![first.trim_start_matches("error: ").to_string()];
    parts.extend(
        lines
            .filter_map(|l| l.strip_prefix("tip: "))
            .map(str::to_string),
    );
    // The command the help is for: the first argument that names one.
    let cli = <Cli as clap::CommandFactory>::command();
    let command = std::env::args()
        .skip(1)
        .find(|a| cli.find_subcommand(a).is_some())
        .map_or("lucent".to_string(), |c| format!("lucent {c}"));
    format!("{} (see `{command} --help`)", parts.join("; "))
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                // --help and --version: clap's text on stdout, success.
                let _ = e.print();
                return ExitCode::SUCCESS;
            }
            // A usage error: one line, exit code 2 (clap's convention).
            eprintln!("lucent: error: {}", usage_error(&e));
            return ExitCode::from(2);
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("lucent: error: {e}");
            ExitCode::FAILURE
        }
    }
}
