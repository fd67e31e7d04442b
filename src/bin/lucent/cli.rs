//! The command line as clap parses it: [`Cli`], its [`Command`]s with their arguments, the
//! frame and GPU flags several commands share ([`FrameArgs`], [`GpuArgs`]) and the
//! [`FrameSettings`] they build, and the value parsers that range-check every number as it is
//! parsed (so nothing is ever sized from an absurd count).

use std::fmt::Display;
use std::ops::RangeInclusive;
use std::path::PathBuf;
use std::str::FromStr;

use clap::{Args, Parser, Subcommand};

use lucent::bake::scene as bake;
use lucent::features::antialias::Antialias;
use lucent::features::gbuffer::GBufferPrecision;
use lucent::features::knob::{Given, Knob, Takes};
use lucent::features::layered::LayeredKnobs;
use lucent::features::registry;
use lucent::features::shadows::{ShadowSettings, SHADOW_SIZES};
use lucent::features::sss::SssKnobs;
use lucent::frame::{FrameDesc, FrameSettings, Technique};
use lucent::graph::CompileOptions;
use lucent::measure::bench;
use lucent::{scene, Result};

#[derive(Parser)]
#[command(
    name = "lucent",
    version,
    about = "Real-time translucency and subsurface scattering on Vulkan, measured honestly"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// List the built-in scenes.
    Scenes,
    /// Render one frame headless and write it as PNG (and optionally EXR).
    Render(RenderArgs),
    /// Benchmark: per-pass GPU times, verified to add up, as a Markdown table.
    Bench(BenchArgs),
    /// Open the interactive demo: a window to fly around a scene in, switch techniques, turn
    /// knobs and watch per-pass GPU times (needs a display; see the README's "Demo").
    #[cfg(feature = "window")]
    Demo(DemoArgs),
    /// The gallery: every showcase scene under its techniques, beside plain lighting and
    /// their difference, as PNGs and an index.md with pixels changed and halos per scene.
    Gallery(GalleryArgs),
    /// Print the compiled render graph: passes, merged groups, barriers, lifetimes, memory.
    Plan(PlanArgs),
    /// Stability sweep: render a technique at extreme parameters and on hostile geometry and
    /// count NaN, Inf, the largest value and fp16 overflows per case (fails on any NaN/Inf).
    Sweep(SweepArgs),
    /// The report suite: every technique's passes beside their speed-of-light copies, the
    /// seeds' tables beside ours, scaling curves and error against time, as DIR/report.md with
    /// PNG plots. With a section name (`translucency`, `sss`, `li`), only that error-against-time
    /// section.
    Report(ReportArgs),
    /// Load a mesh, texture, MTL or scene file and summarise it (or say what is wrong with it).
    Inspect(InspectArgs),
    /// Bake a local thickness map (GDC 2011: ambient occlusion with inverted normals).
    BakeThickness(BakeThicknessArgs),
}

/// `lucent render`.
#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Output PNG (tonemapped, sRGB). Default: <scene>.png.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write the linear HDR frame as OpenEXR (RGBA float).
    #[arg(long)]
    pub exr: Option<PathBuf>,
}

/// `lucent bench`.
#[derive(Args)]
pub struct BenchArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Frames measured (1 to 100000; short runs are noisy).
    #[arg(long, default_value_t = 30, value_parser = whole(1..=bench::MAX_FRAMES))]
    pub frames: usize,
    /// Frames run and discarded first (lazy shader compilation; 0 to 10000).
    #[arg(long, default_value_t = 5, value_parser = whole(0..=bench::MAX_WARMUP))]
    pub warmup: usize,
    /// Also time each pass submitted alone and compare.
    #[arg(long)]
    pub isolate: bool,
    /// Output format on stdout: markdown, csv or json.
    #[arg(long, default_value = "markdown")]
    pub format: String,
    /// Also time every pass's speed-of-light copy (a pass reading and writing the same
    /// formats, nothing else) in the same run, and print pass / copy and ms per tap.
    #[arg(long)]
    pub speed_of_light: bool,
    /// Write the report as JSON to this file too.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the frame as PNG after the benchmark.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also measure the same scene under this technique, alternating frames with the
    /// main one, and print both side by side with the ratio (e.g. `--against none`).
    #[arg(long)]
    pub against: Option<String>,
    /// Print the seeds' published numbers beside ours: the LEAN-mapping thesis's Table 2
    /// (`control`) or Table 1 (`lbb`), each row as a share of its frame; for
    /// `translucency`, GDC 2011's full-screen cost beside the extra cost of translucency
    /// in this scene's lighting pass (measured against `none`, alternating frames); for
    /// `auto` or `layered` on a scene with layered materials, the row of Li et al.'s Table
    /// 1 nearest its triangle count. Alias: --compare-seeds.
    #[arg(long, alias = "compare-seeds")]
    pub compare_thesis: bool,
    /// Also measure the technique as an effect on a host's G-buffer (`lucent::embed`: an SSS
    /// blur a host can run, `translucency`, `layered`, or `none` for the SH environment's light; with a
    /// blur, on a scene with media and shadows, their transmission too) against the same
    /// work in lucent's own frame, frames alternating, and print both with their ratio
    /// (Markdown).
    #[arg(long)]
    pub embed: bool,
    /// Run the speed-of-light gate instead of one benchmark: every built-in scene's passes
    /// against their floors and the techniques that add to shared passes against `none`,
    /// each held under its limit (docs/performance.md); prints each pass, its ratio and its
    /// limit, and fails when a pass is over it. Takes only --validation, --device and
    /// --shaders (the gate sets every other flag itself).
    #[arg(long)]
    pub gate: bool,
    /// With --gate: measure the gate's tables anew instead of judging them: every benchmark
    /// N times (2 to 50), each pass's median, least and largest ratio, and the table lines of
    /// the medians to paste into src/measure/gate.rs (docs/performance.md says when).
    #[arg(long, value_name = "N", requires = "gate", value_parser = whole(2..=50usize))]
    pub gate_baseline: Option<usize>,
}

/// `lucent demo`.
#[cfg(feature = "window")]
#[derive(Args)]
pub struct DemoArgs {
    /// Scene: a built-in name (see `lucent scenes`) or a .toml scene file.
    #[arg(long, default_value = "showcase-skin")]
    pub scene: String,
    /// Technique at start (default: the one the scene is made for).
    #[arg(long)]
    pub technique: Option<String>,
    /// Window size as WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Vertical sync: on (FIFO) or off (MAILBOX or IMMEDIATE when available, else FIFO).
    #[arg(long, default_value = "on", value_parser = parse_on_off, action = clap::ArgAction::Set)]
    pub vsync: bool,
    /// Exit after this many presented frames.
    #[arg(long)]
    pub frames: Option<u64>,
    /// Scripted input (see the README's "Demo" for the format).
    #[arg(long)]
    pub script: Option<PathBuf>,
    /// On exit, write the last frame (without the overlay) as PNG.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// `lucent gallery`.
#[derive(Args)]
pub struct GalleryArgs {
    /// Folder for the PNGs and index.md (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, default_value = "640x480", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Only these scenes (repeatable; default: every showcase scene and `mixed`, and
    /// `showcase-skin` under `burley` too).
    #[arg(long)]
    pub scene: Vec<String>,
    /// Show every scene under this technique (as `lucent render --technique`) instead of the
    /// techniques its materials ask for; the file names end in `-TECHNIQUE`.
    #[arg(long)]
    pub technique: Option<String>,
    /// Anti-aliasing after the tonemap: `off` (default) or `fxaa`.
    #[arg(long, default_value = "off")]
    pub aa: String,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// `lucent plan`.
#[derive(Args)]
pub struct PlanArgs {
    #[command(flatten)]
    pub frame: FrameArgs,
}

/// `lucent sweep`.
#[derive(Args)]
pub struct SweepArgs {
    /// The technique to sweep (`translucency`, `layered` or `burley`).
    pub technique: String,
    /// Resolution of each case as WIDTHxHEIGHT.
    #[arg(long, default_value = "64x48", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Also write the table to this Markdown file.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Only the quick subset of cases (`layered`: every medium back-lit and every
    /// situation at the two corners).
    #[arg(long)]
    pub quick: bool,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// `lucent report`.
#[derive(Args)]
pub struct ReportArgs {
    /// Only this error-against-time section (`translucency`, `sss`, `li`: Li et al.'s
    /// layered passes, every knob, or `truth`: every technique and knob against the
    /// path-traced truths); default: the whole suite.
    pub technique: Option<String>,
    /// Output directory.
    #[arg(long, default_value = "report")]
    pub out: PathBuf,
    /// The small preset (suite: about 15 s on the project's 2-core lavapipe machine; `li`:
    /// 128x128, fewer variants, 3 rounds; the translucency and sss sections ignore it).
    #[arg(long)]
    pub quick: bool,
    /// Resolution as WIDTHxHEIGHT (suite: of the per-technique tables; default 1024x768,
    /// --quick 256x192; sections: of the timed frames, default 1024x768, `li` 256x256 and
    /// --quick 128x128).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Measured rounds or frames (1 to 100000; section default 15; suite 25, --quick 3;
    /// `li` --quick 3).
    #[arg(long, value_parser = whole(1..=bench::MAX_FRAMES))]
    pub rounds: Option<usize>,
    /// Discarded rounds first (0 to 10000; section default 3; suite 3, --quick 1; `li`
    /// --quick 1).
    #[arg(long, value_parser = whole(0..=bench::MAX_WARMUP))]
    pub warmup: Option<usize>,
    /// `truth` only: the truth directory, with `scenes/NAME.toml` and `truths/NAME.exr`
    /// (default `tools/truth`, tools/truth/README.md).
    #[arg(long)]
    pub truths: Option<PathBuf>,
    /// `truth` only: these scenes, comma-separated (default: every scene with a truth).
    #[arg(long, value_delimiter = ',')]
    pub scenes: Option<Vec<String>>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

/// `lucent inspect`.
#[derive(Args)]
pub struct InspectArgs {
    /// The file (.obj, .mtl, .png, .jpg, .tga, .exr, .hdr, .toml).
    pub file: PathBuf,
}

/// `lucent bake-thickness`.
#[derive(Args)]
pub struct BakeThicknessArgs {
    /// The mesh (OBJ).
    pub mesh: PathBuf,
    /// Write a thickness texture (PNG, grayscale, thin = white; needs UVs).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the mesh back as OBJ with the thickness as vertex colours (`v x y z r g b`).
    #[arg(long)]
    pub per_vertex: Option<PathBuf>,
    /// Rays per sample (1 to 1048576).
    #[arg(long, default_value_t = 256, value_parser = whole(1..=lucent::bake::MAX_RAYS))]
    pub rays: u32,
    /// Texture size in texels (square, 1 to 8192).
    #[arg(long, default_value_t = 512, value_parser = whole(1..=lucent::bake::MAX_TEXTURE_SIZE))]
    pub size: u32,
    /// Occlusion distance (default: the mesh's bounding-box diagonal).
    #[arg(long, allow_negative_numbers = true, value_parser = finite(|v| v > 0.0, "a finite number > 0"))]
    pub max_distance: Option<f32>,
    /// Bake distances instead of the talk's occlusion: each value is the slab-equivalent
    /// thickness (half the cosine-weighted mean chord along the inward rays) over the maximum
    /// distance, what materials with a [material.medium] read (docs/translucency.md).
    #[arg(long)]
    pub distances: bool,
    /// Random seed (the bake is deterministic for a seed).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// The frame a command renders: scene, size, technique and every knob of the techniques.
#[derive(Args, Clone)]
pub struct FrameArgs {
    /// Scene: a built-in name (see `lucent scenes`) or a .toml scene file.
    #[arg(long, default_value = "smoke")]
    pub scene: String,
    /// Resolution as WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768", value_parser = parse_size)]
    size: (u32, u32),
    /// What the frame shades: `auto` (default) is what the scene's materials ask for, every
    /// technique composed in one frame; `none` (plain deferred lighting), `translucency`,
    /// `control`, `lcb`, `lbb` (the thesis's per-Gaussian SSS chains), `separable` or
    /// `bilateral` (two-pass SSS) restrict the frame to one technique (A/B runs, the seeds'
    /// tables).
    #[arg(long, default_value = "auto")]
    pub technique: String,
    /// Do not merge same-pixel passes into subpasses (A/B comparison).
    #[arg(long)]
    no_merge: bool,
    /// Do not alias transient images' memory (A/B comparison).
    #[arg(long)]
    no_alias: bool,
    /// Precision of the G-buffer's colour targets: compact (RGBA8 albedo and translucency,
    /// fp16 normal), half (all RGBA16F) or full (all RGBA32F).
    #[arg(long, default_value = "compact", value_parser = one_of(GBufferPrecision::ALL.iter().copied()))]
    gbuffer: GBufferPrecision,
    /// The technique knobs, as their modules declare them (`registry::knobs`).
    #[command(flatten)]
    pub knobs: TechniqueKnobArgs,
    /// No light casts shadows (no light-space maps pass; each light's own `shadows = false`
    /// turns off just that light's).
    #[arg(long)]
    no_shadows: bool,
    /// Edge of each light-space map face in texels (16 to 4096; default 1024; Li et al.'s
    /// Table 1 uses 512 and 1024). Halved until every face fits an 8192x8192 atlas.
    #[arg(long, allow_negative_numbers = true, value_parser = ranged(SHADOW_SIZES))]
    shadow_size: Option<u32>,
    /// The instant shown, in seconds (a finite number; default 0): a deforming scene
    /// (`dynamic`) is deformed at it; `bench` starts its animation there.
    #[arg(long, allow_negative_numbers = true, value_parser = finite(|_| true, "a finite number of seconds"))]
    time: Option<f32>,
    /// Light from the environment, replacing the scene's: `scene` (default: the scene's own),
    /// `none`, `constant`, `hemisphere`, `sky` (the built-in procedural sky map) or the path of
    /// an equirectangular map (HDR, EXR, PNG, ...), reduced to nine SH irradiance coefficients.
    #[arg(long, default_value = "scene")]
    environment: String,
    /// Multiplies the environment's radiance (a finite number >= 0; default 1).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0, value_parser = finite(|v| v >= 0.0, "a finite number >= 0"))]
    environment_intensity: f32,
    /// Anti-aliasing after the tonemap: `off` (default) or `fxaa`.
    #[arg(long, default_value = "off")]
    aa: String,
}

/// The flags that pick and check the GPU.
#[derive(Args, Clone)]
pub struct GpuArgs {
    /// Pick the first device whose name contains this (case-insensitive).
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation (also
    /// LUCENT_VALIDATION=1); any validation error makes the command fail.
    #[arg(long)]
    pub validation: bool,
    /// Compile the GLSL under this directory at run time instead of using the SPIR-V built into
    /// the binary: measure an edited copy of `glsl/` without rebuilding (docs/performance.md).
    #[arg(long, value_name = "DIR")]
    pub shaders: Option<std::path::PathBuf>,
}

/// A whole number in `range`, for the count flags whose messages the tests and docs quote:
/// `'TEXT' is not a whole number from LO to HI`.
fn whole<T>(range: RangeInclusive<T>) -> impl Fn(&str) -> std::result::Result<T, String> + Clone
where
    T: FromStr + PartialOrd + Display + Copy + Send + Sync + 'static,
{
    move |text| {
        text.trim()
            .parse::<T>()
            .ok()
            .filter(|v| range.contains(v))
            .ok_or_else(|| {
                let (lo, hi) = (range.start(), range.end());
                format!("'{text}' is not a whole number from {lo} to {hi}")
            })
    }
}

/// clap's own ranged parser over one of the library's `u32` ranges.
fn ranged(range: RangeInclusive<u32>) -> clap::builder::RangedI64ValueParser<u32> {
    clap::value_parser!(u32).range(i64::from(*range.start())..=i64::from(*range.end()))
}

/// A finite number that `accept` takes, else `'TEXT' is not NOUN`.
fn finite(
    accept: fn(f32) -> bool,
    noun: &'static str,
) -> impl Fn(&str) -> std::result::Result<f32, String> + Clone {
    move |text| {
        text.trim()
            .parse::<f32>()
            .ok()
            .filter(|v| v.is_finite() && accept(*v))
            .ok_or_else(|| format!("'{text}' is not {noun}"))
    }
}

/// One of `choices` by its name, else `'TEXT' is not one of a, b, c`.
fn one_of<N, T>(
    choices: impl IntoIterator<Item = (N, T)>,
) -> impl Fn(&str) -> std::result::Result<T, String> + Clone
where
    N: Display,
    T: Clone + Send + Sync + 'static,
{
    let choices: Vec<(String, T)> = choices
        .into_iter()
        .map(|(name, value)| (name.to_string(), value))
        .collect();
    move |text| {
        choices
            .iter()
            .find(|(name, _)| name == text.trim())
            .map(|(_, value)| value.clone())
            .ok_or_else(|| {
                let names: Vec<&str> = choices.iter().map(|(name, _)| name.as_str()).collect();
                format!("'{text}' is not one of {}", names.join(", "))
            })
    }
}

/// `on` or `off`.
#[cfg(feature = "window")]
fn parse_on_off(text: &str) -> std::result::Result<bool, String> {
    match text {
        "on" => Ok(true),
        "off" => Ok(false),
        other => Err(format!("'{other}' is not on or off")),
    }
}

/// `WIDTHxHEIGHT`, each from 1 to 16384.
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
    /// Loads the scene (thickness baked, cached), at `--time`, with `--environment`.
    pub fn load_scene(&self) -> Result<scene::Scene> {
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

    /// The frame's settings; `export_hdr` keeps the linear HDR frame for reading back.
    pub fn settings(&self, export_hdr: bool) -> Result<FrameSettings> {
        let mut settings = FrameSettings {
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
            force_grayscale: false,
            sss_tiles: true,
            fault: None,
            sss: SssKnobs::default(),
            debug_view: None,
            frames_in_flight: 1,
            target: None,
            shadows: ShadowSettings {
                enabled: !self.no_shadows,
                size: self.shadow_size.unwrap_or(ShadowSettings::default().size),
            },
            antialias: Antialias::parse(&self.aa)?,
            export_ldr: false,
            export_shadows: false,
            layered: LayeredKnobs::default(),
        };
        for &(knob, value) in &self.knobs.given {
            settings.set_knob(knob, value);
        }
        Ok(settings)
    }

    /// Prints a warning (on stderr) for every knob that does nothing in this frame.
    pub fn warn_inapplicable(
        &self,
        scene: &scene::Scene,
        settings: &FrameSettings,
        desc: &FrameDesc,
    ) {
        for warning in self.inapplicable_knobs(scene, settings, desc) {
            eprintln!("lucent: warning: {warning}");
        }
    }

    /// The knobs given on the command line that do nothing in this frame (`desc`, of `scene`
    /// under `settings`), each as a warning naming what they need. A technique's knobs are
    /// the ones its module lists ([`registry::TechniqueModule::knobs`]): a knob applies when
    /// some technique of the frame lists it.
    fn inapplicable_knobs(
        &self,
        scene: &scene::Scene,
        settings: &FrameSettings,
        desc: &FrameDesc,
    ) -> Vec<String> {
        let techniques = desc.techniques();
        let mut unused: Vec<(&str, String)> = self
            .knobs
            .given
            .iter()
            .filter(|(knob, _)| {
                !techniques
                    .iter()
                    .any(|t| t.knobs().iter().any(|k| std::ptr::eq(*k, *knob)))
            })
            .map(|(knob, _)| (knob.flag, technique_knob_needs(knob)))
            .collect();
        // Knobs of the scene rather than of a technique.
        if self.time.is_some() && scene.deformation.is_none() {
            unused.push((
                "--time",
                "a deforming scene (one with a [deformation] table, e.g. dynamic)".into(),
            ));
        }
        if self.shadow_size.is_some() && desc.shadows.is_none() {
            unused.push((
                "--shadow-size",
                "a light that casts shadows (without --no-shadows; lights with shadows = true)"
                    .into(),
            ));
        }
        unused
            .into_iter()
            .map(|(flag, needs)| {
                format!(
                    "{flag} has no effect with --technique {} on scene '{}': it applies to \
                     {needs}",
                    settings.technique.name(),
                    scene.name
                )
            })
            .collect()
    }
}

/// What a technique knob needs, from the registry: the techniques that list it, as
/// `--technique` choices (`a, b or c`), or `auto` on a scene whose materials use them.
fn technique_knob_needs(knob: &Knob) -> String {
    let names: Vec<&str> = registry::with_knob(knob).map(|t| t.name()).collect();
    let listed = match names.split_last() {
        Some((last, [])) => last.to_string(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => "no technique".to_string(),
    };
    format!(
        "--technique {listed} (or auto on a scene whose materials use {})",
        if names.len() == 1 {
            "it"
        } else {
            "one of them"
        }
    )
}

/// The technique knobs given on the command line. Its flags are not written here: clap's
/// arguments are built from the registry's knobs ([`registry::knobs`]), each with the flag,
/// help and range check its technique's module declares.
#[derive(Clone, Default)]
pub struct TechniqueKnobArgs {
    /// Each knob given, with its checked value, in registry order.
    pub given: Vec<(&'static Knob, Given)>,
}

impl clap::FromArgMatches for TechniqueKnobArgs {
    fn from_arg_matches(matches: &clap::ArgMatches) -> std::result::Result<Self, clap::Error> {
        let given = registry::knobs()
            .into_iter()
            .filter_map(|knob| {
                let value = match knob.takes {
                    Takes::Switch => matches.get_flag(knob.long()).then_some(Given::Switch),
                    _ => matches.get_one::<Given>(knob.long()).copied(),
                };
                value.map(|value| (knob, value))
            })
            .collect();
        Ok(Self { given })
    }

    fn update_from_arg_matches(
        &mut self,
        matches: &clap::ArgMatches,
    ) -> std::result::Result<(), clap::Error> {
        *self = Self::from_arg_matches(matches)?;
        Ok(())
    }
}

impl Args for TechniqueKnobArgs {
    fn augment_args(command: clap::Command) -> clap::Command {
        registry::knobs()
            .into_iter()
            .fold(command, |command, knob| {
                let arg = clap::Arg::new(knob.long())
                    .long(knob.long())
                    .help(knob.help);
                let arg = match knob.takes.placeholder() {
                    None => arg.action(clap::ArgAction::SetTrue),
                    Some(placeholder) => arg
                        .value_name(placeholder)
                        .allow_negative_numbers(true)
                        .value_parser(move |text: &str| knob.takes.parse(text)),
                };
                command.arg(arg)
            })
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        Self::augment_args(command)
    }
}
