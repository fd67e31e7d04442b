//! Error against run time: `lucent report translucency --out DIR`.
//!
//! Every approximation the GDC 2011 technique offers is rendered as a variant of one scene and
//! measured two ways: its lighting-pass time, and its image error against the exact-f64
//! reference (the lighting equations evaluated in f64 with exact `pow` and coloured thickness
//! from a full-precision RGBA32F G-buffer of the same scene). Times are medians over frames
//! taken round-robin (one frame of each variant per round, after warm-up rounds), so a noisy,
//! shared machine slows every variant alike and the ratios hold; the G-buffer and lighting run
//! as separate render passes so each has its own timestamp pair.
//!
//! The report writes `translucency.md` (tables) and `translucency-error-vs-time.png` (max abs
//! error against lighting ms, one colour per knob). [`translucency_section`] is the same as one
//! section of the full suite ([`crate::report`]).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::gbuffer::GBufferPrecision;
use crate::frame::{render_frame, FrameDesc, FrameRunner, FrameSettings, Renderer, Technique};
use crate::graph::CompileOptions;
use crate::images::compare::flip_rgba8;
use crate::measure::stats::Stats;
use crate::reference::tonemap::display_rgba8;
use crate::reference::translucency::{shade_gbuffer, LightingInputs};
use crate::report::plot::{write_scatter_png, PlotPoint, PlotSeries};
use crate::report::section::{with_lights, ReportOptions};
use crate::scene::material::PowMode;
use crate::scene::Scene;
use crate::{LucentError, Result};

/// One configuration to measure.
#[derive(Clone)]
pub struct Variant {
    /// Which knob it turns (the plot's series).
    pub knob: String,
    /// Its setting of the knob.
    pub name: String,
    /// The scene as rendered.
    pub scene: Scene,
    /// The frame settings.
    pub settings: FrameSettings,
    /// The scene its exact reference is computed from (`None`: no error measured).
    pub reference: Option<Scene>,
}

/// What one variant measured.
#[derive(Clone, Debug, PartialEq)]
pub struct VariantResult {
    /// Knob.
    pub knob: String,
    /// Setting.
    pub name: String,
    /// Lighting pass, ms.
    pub lighting: Stats,
    /// G-buffer pass, ms.
    pub gbuffer: Stats,
    /// Whole frame (submit to fence), ms.
    pub frame: Stats,
    /// Image error against the exact reference, when measured.
    pub error: Option<ImageError>,
}

/// Image error of linear HDR (all pixels, all three channels) and of the display image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    /// Largest |GPU - reference|.
    pub max_abs: f64,
    /// Mean |GPU - reference|.
    pub mean_abs: f64,
    /// The reference's largest value (to read the others relative to it).
    pub peak: f64,
    /// Mean FLIP of the display image against the tonemapped reference.
    pub flip_mean: f32,
}

fn settings(opts: &ReportOptions, technique: Technique) -> FrameSettings {
    FrameSettings {
        technique,
        export_hdr: true,
        // Separate render passes: the lighting pass gets its own timestamp pair.
        compile: CompileOptions {
            merge: false,
            alias: true,
            ..CompileOptions::default()
        },
        // The error measured is the translucency term's against its f64 twin, which shades
        // without shadows: the frames are unshadowed too (shadows have their own test).
        shadows: crate::features::shadows::ShadowSettings {
            enabled: false,
            ..Default::default()
        },
        ..FrameSettings::new(opts.width, opts.height)
    }
}

fn with_pow(scene: &Scene, mode: PowMode) -> Scene {
    let mut s = scene.clone();
    for o in &mut s.objects {
        if let Some(t) = &mut o.material.translucency {
            t.pow_mode = mode;
        }
    }
    s
}

/// The translucency report's variants on `cubes` (and its light-count series), and the
/// grid125 coverage series (technique none against translucency at 0%, 50%, 100%, and 100%
/// with exact pow instead of the grid's exp2).
pub fn translucency_variants(opts: &ReportOptions) -> Result<Vec<Variant>> {
    let cubes = crate::bake::scene::load_scene_baked("cubes")?;
    let t = settings(
        opts,
        Technique::Only(&crate::features::translucency::TRANSLUCENCY),
    );
    let exact = with_pow(&cubes, PowMode::Exact);
    let mut variants = vec![
        Variant {
            knob: "pow".into(),
            name: "exact pow".into(),
            scene: exact.clone(),
            settings: t,
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "pow".into(),
            name: "exp2 (spherical Gaussian)".into(),
            scene: with_pow(&cubes, PowMode::SphericalGaussian),
            settings: t,
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "pow".into(),
            name: "exp2, scaled (n+1)/ln 2".into(),
            scene: with_pow(&cubes, PowMode::SphericalGaussianScaled),
            settings: t,
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "thickness".into(),
            name: "coloured".into(),
            scene: exact.clone(),
            settings: t,
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "thickness".into(),
            name: "grayscale".into(),
            scene: exact.clone(),
            settings: FrameSettings {
                force_grayscale: true,
                ..t
            },
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "G-buffer".into(),
            name: "RGBA8".into(),
            scene: exact.clone(),
            settings: t,
            reference: Some(exact.clone()),
        },
        Variant {
            knob: "G-buffer".into(),
            name: "RGBA16F".into(),
            scene: exact.clone(),
            settings: FrameSettings {
                gbuffer: GBufferPrecision::Half,
                ..t
            },
            reference: Some(exact.clone()),
        },
    ];
    for n in [1, 3, 8, 32] {
        let lit = with_lights(&exact, n);
        variants.push(Variant {
            knob: "lights".into(),
            name: format!("{n} light{}", if n == 1 { "" } else { "s" }),
            scene: lit.clone(),
            settings: t,
            reference: Some(lit),
        });
    }
    let grid = |name: &str| crate::bake::scene::load_scene_baked(name);
    let coverage = [
        ("0% translucent", grid("grid125:0")?),
        ("50% translucent", grid("grid125:50")?),
        ("100% translucent", grid("grid125")?),
        (
            "100% translucent, exact pow",
            with_pow(&grid("grid125")?, PowMode::Exact),
        ),
    ];
    for (label, scene) in coverage {
        for technique in [
            Technique::None,
            Technique::Only(&crate::features::translucency::TRANSLUCENCY),
        ] {
            variants.push(Variant {
                knob: format!("grid125 {label}"),
                name: technique.name().into(),
                scene: scene.clone(),
                settings: settings(opts, technique),
                reference: None,
            });
        }
    }
    Ok(variants)
}

/// Renders each variant's frames round-robin and measures times and errors.
pub fn run(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    variants: &[Variant],
    opts: &ReportOptions,
) -> Result<Vec<VariantResult>> {
    let mut renderers = Vec::with_capacity(variants.len());
    let mut runners = Vec::with_capacity(variants.len());
    let result = (|| -> Result<Vec<VariantResult>> {
        for v in variants {
            let r = Renderer::new(gpu, shaders, pipeline_cache, &v.scene, v.settings)?;
            runners.push(FrameRunner::new(gpu, r.executable.plan.physical.len())?);
            renderers.push(r);
        }
        let mut samples = vec![(Vec::new(), Vec::new(), Vec::new()); variants.len()];
        for round in 0..opts.warmup + opts.rounds {
            for (i, (renderer, runner)) in renderers.iter().zip(&mut runners).enumerate() {
                let timing = runner.run_frame(gpu, &renderer.executable)?;
                if round < opts.warmup {
                    continue;
                }
                let pass = |name: &str| {
                    timing
                        .passes
                        .iter()
                        .find(|p| p.name == name)
                        .map_or(0.0, |p| p.ms)
                };
                samples[i].0.push(pass("lighting"));
                samples[i].1.push(pass("gbuffer"));
                samples[i].2.push(timing.wall_ms);
            }
        }
        let mut results = Vec::with_capacity(variants.len());
        for ((v, renderer), (lighting, gbuffer, frame)) in
            variants.iter().zip(&renderers).zip(&samples)
        {
            let error = match &v.reference {
                Some(reference) => Some(image_error(
                    gpu,
                    shaders,
                    pipeline_cache,
                    reference,
                    &renderer.read_hdr(gpu)?,
                    &renderer.read_display(gpu)?,
                    opts,
                )?),
                None => None,
            };
            results.push(VariantResult {
                knob: v.knob.clone(),
                name: v.name.clone(),
                lighting: Stats::of(lighting),
                gbuffer: Stats::of(gbuffer),
                frame: Stats::of(frame),
                error,
            });
        }
        Ok(results)
    })();
    crate::frame::destroy_after_idle(gpu, renderers, runners)?;
    result
}

/// The exact reference of `scene` (full-precision G-buffer, f64 shading, exact pow, coloured
/// thickness) compared with a variant's HDR and display images.
fn image_error(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scene: &Scene,
    hdr: &[f32],
    display: &[u8],
    opts: &ReportOptions,
) -> Result<ImageError> {
    let exact = with_pow(scene, PowMode::Exact);
    let settings = FrameSettings {
        export_gbuffer: true,
        gbuffer: GBufferPrecision::Full,
        ..settings(
            opts,
            Technique::Only(&crate::features::translucency::TRANSLUCENCY),
        )
    };
    let features = FrameDesc::new(&exact, &settings)?;
    let gbuffer = render_frame(gpu, shaders, pipeline_cache, &exact, settings)?
        .gbuffer
        .ok_or_else(|| LucentError::InvalidInput("reference G-buffer not exported".into()))?;
    let reference = shade_gbuffer(
        &gbuffer,
        &LightingInputs {
            scene: &exact,
            translucency: features
                .translucency()
                .map(|t| (t.table.rows.as_slice(), t.packing)),
        },
    );
    let (mut max_abs, mut sum, mut peak) = (0.0f64, 0.0f64, 0.0f64);
    for (i, r) in reference.iter().enumerate() {
        peak = peak.max(r.max_element());
        for c in 0..3 {
            let e = (f64::from(hdr[i * 4 + c]) - r[c]).abs();
            max_abs = max_abs.max(e);
            sum += e;
        }
    }
    let exposure = f64::from(exact.exposure);
    let expected: Vec<u8> = reference
        .iter()
        .flat_map(|&c| display_rgba8(c, exposure))
        .collect();
    let flip = flip_rgba8(&expected, display, opts.width, opts.height)?;
    Ok(ImageError {
        max_abs,
        mean_abs: sum / (reference.len() * 3).max(1) as f64,
        peak,
        flip_mean: flip.mean,
    })
}

/// The report as Markdown.
pub fn markdown(results: &[VariantResult], opts: &ReportOptions, device: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Translucency (GDC 2011): error against run time\n");
    let _ = writeln!(
        out,
        "- device: {device}\n- size: {}x{}\n- timing: medians of {} rounds after {} warm-up \
         rounds, one frame of every variant per round (round-robin, so machine noise hits all \
         alike); G-buffer and lighting as separate render passes, in-frame timestamps\n\
         - reference: f64 shading of a full-precision (RGBA32F) G-buffer of the same scene, \
         exact pow, coloured thickness\n",
        opts.width, opts.height, opts.rounds, opts.warmup
    );
    let _ = writeln!(out, "## Knobs on `cubes` (3 lights unless stated)\n");
    out.push_str("| knob | setting | lighting ms | vs first | G-buffer ms | frame ms | max abs | max / peak | mean abs | FLIP mean |\n");
    out.push_str("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    let mut first_of_knob: Option<(&str, f64)> = None;
    for r in results.iter().filter(|r| r.error.is_some()) {
        let base = match first_of_knob {
            Some((k, ms)) if k == r.knob => ms,
            _ => {
                first_of_knob = Some((&r.knob, r.lighting.median));
                r.lighting.median
            }
        };
        let e = r.error.unwrap_or(ImageError {
            max_abs: 0.0,
            mean_abs: 0.0,
            peak: 1.0,
            flip_mean: 0.0,
        });
        let _ = writeln!(
            out,
            "| {} | {} | {:.3} | {:.2}x | {:.3} | {:.3} | {:.3e} | {:.2e} | {:.3e} | {:.4} |",
            r.knob,
            r.name,
            r.lighting.median,
            r.lighting.median / base.max(1e-9),
            r.gbuffer.median,
            r.frame.median,
            e.max_abs,
            e.max_abs / e.peak.max(1e-12),
            e.mean_abs,
            e.flip_mean
        );
    }
    let _ = writeln!(
        out,
        "\n## Cost of translucency on `grid125` (3 point lights)\n\n\
         Technique `none` against `translucency` on the same scene, measured in the same run.\n"
    );
    out.push_str("| translucent share | `none` lighting ms | `translucency` lighting ms | extra (medians) | extra (minima) | `none` G-buffer ms | `translucency` G-buffer ms | frame extra |\n");
    out.push_str("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    let grid: Vec<&VariantResult> = results.iter().filter(|r| r.error.is_none()).collect();
    for pair in grid.chunks(2) {
        if let [none, with] = pair {
            let _ = writeln!(
                out,
                "| {} | {:.3} | {:.3} | {:+.1}% | {:+.1}% | {:.3} | {:.3} | {:+.1}% |",
                none.knob.trim_start_matches("grid125 "),
                none.lighting.median,
                with.lighting.median,
                (with.lighting.median / none.lighting.median.max(1e-9) - 1.0) * 100.0,
                (with.lighting.min / none.lighting.min.max(1e-9) - 1.0) * 100.0,
                none.gbuffer.median,
                with.gbuffer.median,
                (with.frame.median / none.frame.median.max(1e-9) - 1.0) * 100.0,
            );
        }
    }
    out
}

/// Runs the translucency report and writes `translucency.md` and the plot under `dir`.
pub fn write_translucency_report(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    dir: &Path,
    opts: &ReportOptions,
) -> Result<(String, Vec<PathBuf>)> {
    let variants = translucency_variants(opts)?;
    let results = run(gpu, shaders, pipeline_cache, &variants, opts)?;
    let text = markdown(&results, opts, &gpu.info.describe());
    std::fs::create_dir_all(dir).map_err(|e| LucentError::file(dir, e))?;
    let md = dir.join("translucency.md");
    let png = dir.join("translucency-error-vs-time.png");
    let mut series: Vec<PlotSeries> = Vec::new();
    for r in results.iter().filter(|r| r.error.is_some()) {
        let e = r.error.expect("filtered");
        let point = PlotPoint {
            label: r.name.clone(),
            x: r.lighting.median,
            y: e.max_abs,
        };
        match series.iter_mut().find(|s| s.name == r.knob) {
            Some(s) => s.points.push(point),
            None => series.push(PlotSeries {
                name: r.knob.clone(),
                points: vec![point],
            }),
        }
    }
    write_scatter_png(
        &png,
        "GDC 2011 translucency on cubes: error against lighting-pass time",
        "lighting pass ms (median)",
        "max abs error vs exact f64 reference",
        &series,
        true,
    )?;
    let text = format!(
        "{text}\n![error against time]({})\n",
        png.file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned())
    );
    crate::files::write_file_atomic(&md, text.as_bytes())?;
    Ok((text, vec![md, png]))
}

/// The translucency report as a section of the suite: written beside `report.md`, and its
/// tables embedded one heading level down. Full run: 1024x768 (the size of the technique
/// tables), the suite's rounds; quick: 128x96, 2 rounds.
pub fn translucency_section(
    ctx: &crate::report::SuiteContext<'_>,
) -> Result<crate::report::SectionOutput> {
    let opts = if ctx.options.quick {
        ReportOptions {
            width: 128,
            height: 96,
            rounds: 2,
            warmup: 1,
        }
    } else {
        ReportOptions {
            width: ctx.options.width,
            height: ctx.options.height,
            rounds: ctx.options.frames,
            warmup: ctx.options.warmup,
        }
    };
    let (text, files) =
        write_translucency_report(ctx.gpu, ctx.shaders, ctx.pipeline_cache, ctx.dir, &opts)?;
    Ok(crate::report::SectionOutput {
        markdown: crate::report::embed(&text),
        files,
        ..Default::default()
    })
}
