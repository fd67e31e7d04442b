//! Error against run time for screen-space SSS: `lucent report sss --out DIR`.
//!
//! The three techniques (the control, LCB, LBB) and every LBB knob (Gaussian count, taps, sum
//! precision, packed ping-pong, screen tiles) are measured two ways:
//! - **time**: frames of the `teapot` scene at the report's size, taken round-robin (one frame
//!   of each variant per round, after warm-up rounds), so a shared, noisy machine slows every
//!   variant alike; medians of the frame and of the SSS passes (blurs + final pass).
//! - **error**: the `edges` scene (an SSS sphere before a bright wall, a thin SSS slab before a
//!   dark pillar) at a quarter of the report's size per side with the profiles widened 4x, so
//!   the blurs span as many pixels as at full size, against the brute-force f64 reference
//!   (the profile convolved over the visible surface, [`crate::reference::sss`]); the SSS
//!   objects' specular is off, so every technique is judged on diffusion alone (LCB and LBB
//!   also blur their highlights, which a physical reference never does). Reported: mean error
//!   over scattering pixels, split into the silhouette band (bleed) and the interior, and
//!   halo pixels (non-scattering pixels the SSS passes changed).
//!
//! Writes `sss.md` and `sss-error-vs-time.png`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::sss::{SssKnobs, SssPrecision};
use crate::frame::{render_frame, FrameDesc, FrameSettings, Technique};
use crate::measure::round_robin::{self, IfUnbuildable};
use crate::measure::stats::Stats;
use crate::reference::sss::{edge_metrics, reference_image, EdgeMetrics, ReferenceSpecular};
use crate::report::plot::{write_scatter_png, PlotPoint, PlotSeries};
use crate::report::section::ReportOptions;
use crate::scene::material::{SssProfile, Texturing};
use crate::scene::profile::fit_profile;
use crate::scene::Scene;
use crate::{LucentError, Result};

/// One configuration to measure.
#[derive(Clone, Debug)]
pub struct SssVariant {
    /// Which knob it turns (the plot's series).
    pub knob: &'static str,
    /// Its setting.
    pub name: String,
    /// Frame settings (size is set per measurement).
    pub settings: FrameSettings,
}

/// What one variant measured.
#[derive(Clone, Debug)]
pub struct SssResult {
    /// The variant.
    pub variant: SssVariant,
    /// Whole frame (submit to fence), ms.
    pub frame: Stats,
    /// The SSS passes (blurs and the final pass), ms: medians of per-frame sums.
    pub sss: Stats,
    /// Blur pairs in the frame.
    pub blur_pairs: usize,
    /// Edge and interior error, halo, against the brute-force reference.
    pub edges: EdgeMetrics,
    /// Mean error over all scattering pixels.
    pub mean_error: f64,
    /// Relative L2 error of the profile fit (largest channel), when the Gaussians were refit.
    pub fit_error: Option<f64>,
}

/// Every variant: the SSS techniques of the registry at their defaults, then one knob at a time (the
/// per-Gaussian blurs' Gaussian counts and LBB's knobs, the two-pass blurs' samples, taps,
/// kernel and resolution).
pub fn sss_variants() -> Vec<SssVariant> {
    let base = |technique| FrameSettings {
        technique,
        ..FrameSettings::new(1, 1)
    };
    let mut v = Vec::new();
    for t in crate::features::registry::sss_techniques().map(Technique::Only) {
        v.push(SssVariant {
            knob: "technique",
            name: t.name().into(),
            settings: base(t),
        });
    }
    for n in [4, 3, 2] {
        for t in [
            Technique::Only(&crate::features::sss::control::CONTROL),
            Technique::Only(&crate::features::sss::lbb::LBB),
        ] {
            let mut s = base(t);
            s.sss.gaussians = Some(n);
            v.push(SssVariant {
                knob: if t == Technique::Only(&crate::features::sss::lbb::LBB) {
                    "LBB Gaussians"
                } else {
                    "control Gaussians"
                },
                name: format!("{} {n} Gaussians", t.name()),
                settings: s,
            });
        }
    }
    for taps in [7, 3] {
        let mut s = base(Technique::Only(&crate::features::sss::lbb::LBB));
        s.sss.taps = taps;
        v.push(SssVariant {
            knob: "LBB taps",
            name: format!("lbb {taps} taps"),
            settings: s,
        });
    }
    let mut half = base(Technique::Only(&crate::features::sss::lbb::LBB));
    half.sss.precision = SssPrecision::Half;
    v.push(SssVariant {
        knob: "LBB sum precision",
        name: "lbb fp16 sums".into(),
        settings: half,
    });
    let mut packed = base(Technique::Only(&crate::features::sss::lbb::LBB));
    packed.sss.packed = true;
    v.push(SssVariant {
        knob: "LBB packed ping-pong",
        name: "lbb packed".into(),
        settings: packed,
    });
    let mut whole = base(Technique::Only(&crate::features::sss::lbb::LBB));
    whole.sss_tiles = false;
    v.push(SssVariant {
        knob: "LBB screen tiles",
        name: "lbb whole screen".into(),
        settings: whole,
    });
    let defaults = crate::features::sss::SssKnobs::default();
    for t in [
        Technique::Only(&crate::features::sss::separable::SEPARABLE),
        Technique::Only(&crate::features::sss::bilateral::BILATERAL),
    ] {
        for samples in crate::features::sss::kernel::SAMPLE_COUNTS {
            if samples == defaults.samples {
                continue;
            }
            let mut s = base(t);
            s.sss.samples = samples;
            v.push(SssVariant {
                knob: if t == Technique::Only(&crate::features::sss::separable::SEPARABLE) {
                    "separable samples"
                } else {
                    "bilateral samples"
                },
                name: format!("{} {samples} samples", t.name()),
                settings: s,
            });
        }
    }
    let mut filter = base(Technique::Only(&crate::features::sss::separable::SEPARABLE));
    filter.sss.point_taps = !defaults.point_taps;
    v.push(SssVariant {
        knob: "separable taps",
        name: format!(
            "separable {} taps",
            if filter.sss.point_taps {
                "point"
            } else {
                "bilinear"
            }
        ),
        settings: filter,
    });
    let mut line = base(Technique::Only(&crate::features::sss::separable::SEPARABLE));
    line.sss.shape = crate::features::sss::kernel::KernelShape::Line;
    v.push(SssVariant {
        knob: "separable kernel",
        name: "separable line kernel".into(),
        settings: line,
    });
    let mut half_res = base(Technique::Only(&crate::features::sss::separable::SEPARABLE));
    half_res.sss.half_res = true;
    v.push(SssVariant {
        knob: "separable resolution",
        name: "separable half resolution".into(),
        settings: half_res,
    });
    let burley = Technique::Only(&crate::features::sss::burley::BURLEY);
    // Burley with one knob turned: the row's knob, its name and the turn.
    let mut burley_with = |knob, name: String, turn: &dyn Fn(&mut SssKnobs)| {
        let mut settings = base(burley);
        turn(&mut settings.sss);
        v.push(SssVariant {
            knob,
            name,
            settings,
        });
    };
    // Each budget beside the default (8).
    for budget in [4, 20, 40] {
        burley_with(
            "Burley sample budget",
            format!("burley budget {budget}"),
            &|k| k.burley_budget = budget,
        );
    }
    burley_with("Burley rotation", "burley without rotation".into(), &|k| {
        k.burley_rotation = false
    });
    burley_with("Burley resolution", "burley half resolution".into(), &|k| {
        k.burley_half_res = true
    });
    // Each texturing mode beside the default (post), every material forced to it; the
    // reference applies the albedo the same way.
    for (name, texturing) in Texturing::ALL {
        if texturing != Texturing::default() {
            burley_with(
                "Burley texturing",
                format!("burley texturing {name}"),
                &|k| k.texturing = Some(texturing),
            );
        }
    }
    v
}

fn sized(settings: &FrameSettings, width: u32, height: u32) -> FrameSettings {
    FrameSettings {
        width,
        height,
        ..*settings
    }
}

/// `scene` with its profiles widened by `factor` and, with `no_specular`, its SSS objects'
/// specular off.
fn error_scene(scene: &Scene, factor: f32, no_specular: bool) -> Scene {
    let mut s = scene.clone();
    for o in &mut s.objects {
        if let Some(p) = &mut o.material.sss {
            p.units_per_mm *= factor;
            if no_specular {
                o.material.specular = 0.0;
            }
        }
    }
    s
}

/// The SSS technique's share of a frame's pass times: every pass after the (G-buffer +)
/// lighting pass and before the tonemap, which is where a frame declares its SSS chains (so a
/// new chain's passes count without naming them here).
fn sss_ms(passes: &[crate::backend::timer::ScopeTime]) -> f64 {
    let lighting = passes.iter().position(|p| p.name.contains("lighting"));
    let tonemap = passes.iter().position(|p| p.name.contains("tonemap"));
    match (lighting, tonemap) {
        (Some(a), Some(b)) if a < b => passes[a + 1..b].iter().map(|p| p.ms).sum(),
        _ => 0.0,
    }
}

/// Measures every variant: times on `teapot` at the options' size, errors on `edges`.
pub fn run(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    variants: &[SssVariant],
    opts: &ReportOptions,
) -> Result<Vec<SssResult>> {
    if opts.rounds == 0 {
        return Err(LucentError::InvalidInput(
            "report: --rounds must be at least 1".into(),
        ));
    }
    // Errors first (small frames); the widened profile keeps the blur's pixel footprint.
    let (ew, eh) = ((opts.width / 4).max(64), (opts.height / 4).max(48));
    let edges = crate::bake::scene::load_scene_baked("edges")?;
    let edges = error_scene(&edges, 4.0, true);
    let reference_frame = FrameSettings {
        technique: Technique::Only(&crate::features::sss::lbb::LBB),
        export_hdr: true,
        export_gbuffer: true,
        ..FrameSettings::new(ew, eh)
    };
    let frame = render_frame(gpu, shaders, cache, &edges, reference_frame)?;
    let gbuffer = frame
        .gbuffer
        .ok_or_else(|| LucentError::InvalidInput("reference G-buffer not exported".into()))?;
    // The edges scene has one profile (its skin): the reference convolves with it.
    let (profile, _) = FrameDesc::new(&edges, &reference_frame)?
        .sss()
        .and_then(|s| s.profiles.first().cloned())
        .ok_or_else(|| LucentError::InvalidInput("the edges scene has no SSS profile".into()))?;
    // Specular is off on the SSS objects: both specular models add nothing there. One
    // reference per texturing mode the variants use (the profile's own unless a variant
    // forces every material's), the albedo applied as that mode says.
    let mut references: Vec<(Texturing, Vec<glam::DVec3>)> = Vec::new();
    let mut reference_for = |texturing: Texturing| {
        if let Some(i) = references.iter().position(|(t, _)| *t == texturing) {
            return i;
        }
        let profile = SssProfile {
            texturing,
            ..profile.clone()
        };
        let image = reference_image(&edges, &gbuffer, &profile, ReferenceSpecular::Lean);
        references.push((texturing, image));
        references.len() - 1
    };
    let reference_of: Vec<usize> = variants
        .iter()
        .map(|v| reference_for(v.settings.sss.texturing.unwrap_or(profile.texturing)))
        .collect();
    let strength = gbuffer.sss.clone().unwrap_or_default();
    let plain = render_frame(
        gpu,
        shaders,
        cache,
        &edges,
        FrameSettings {
            technique: Technique::None,
            ..reference_frame
        },
    )?
    .hdr
    .unwrap_or_default();
    let mut errors = Vec::with_capacity(variants.len());
    for (v, &r) in variants.iter().zip(&reference_of) {
        let reference = &references[r].1;
        let settings = FrameSettings {
            export_hdr: true,
            ..sized(&v.settings, ew, eh)
        };
        let hdr = render_frame(gpu, shaders, cache, &edges, settings)?
            .hdr
            .unwrap_or_default();
        let m = edge_metrics(ew as usize, &strength, &plain, &hdr, reference, 2);
        let n = (m.edge_pixels + m.interior_pixels).max(1) as f64;
        let mean =
            (m.edge_error * m.edge_pixels as f64 + m.interior_error * m.interior_pixels as f64) / n;
        let fit = v
            .settings
            .sss
            .gaussians
            .map(|g| fit_profile(&profile, g).map(|(_, e)| e.iter().fold(0.0f64, |a, &b| a.max(b))))
            .transpose()?;
        errors.push((m, mean, fit));
    }
    // Times: every variant's frames round-robin.
    let teapot = crate::bake::scene::load_scene_baked("teapot")?;
    let frames = round_robin::time_frames(
        gpu,
        shaders,
        cache,
        variants
            .iter()
            .map(|v| (&teapot, sized(&v.settings, opts.width, opts.height))),
        IfUnbuildable::Fail,
        opts.rounds,
        opts.warmup,
        |_, _| {},
    )?;
    Ok(variants
        .iter()
        .zip(&frames)
        .zip(errors)
        .map(|((v, frames), (edges, mean_error, fit_error))| SssResult {
            variant: v.clone(),
            frame: frames.wall(),
            sss: frames.stats_of(|t| sss_ms(&t.passes)),
            blur_pairs: frames
                .pass_names
                .iter()
                .filter(|name| name.starts_with("vertical blur"))
                .count(),
            edges,
            mean_error,
            fit_error,
        })
        .collect())
}

/// The report as Markdown.
pub fn markdown(results: &[SssResult], opts: &ReportOptions, device: &str) -> String {
    let mut out = String::new();
    // Every variant's cost is set against the thesis's control.
    let control_name = Technique::Only(&crate::features::sss::control::CONTROL).name();
    let control = results
        .iter()
        .find(|r| r.variant.name == control_name)
        .map_or(f64::NAN, |r| r.frame.median);
    let (ew, eh) = ((opts.width / 4).max(64), (opts.height / 4).max(48));
    let _ = writeln!(
        out,
        "# Screen-space SSS: error against run time\n\n\
         - device: {device}\n\
         - time: scene `teapot`, {}x{}, {} rounds round-robin after {} warm-up rounds, in-frame \
         timestamps; frame = submit to fence\n\
         - error: scene `edges`, {ew}x{eh}, profiles widened so the blurs span the pixels they \
         span at {}x{}; SSS objects' specular off (diffusion only); against the brute-force f64 \
         convolution of the profile over the visible surface\n\
         - generated by `lucent report sss --out DIR --size {}x{} --rounds {} --warmup {}`\n",
        opts.width,
        opts.height,
        opts.rounds,
        opts.warmup,
        opts.width,
        opts.height,
        opts.width,
        opts.height,
        opts.rounds,
        opts.warmup
    );
    let _ = writeln!(
        out,
        "| knob | variant | blur pairs | frame ms | / control | SSS passes ms | mean error | \
         silhouette band | interior | halo px | profile fit error |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in results {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {:.2} | {:.3}x | {:.2} | {:.3e} | {:.3e} | {:.3e} | {} | {} |",
            r.variant.knob,
            r.variant.name,
            r.blur_pairs,
            r.frame.median,
            r.frame.median / control,
            r.sss.median,
            r.mean_error,
            r.edges.edge_error,
            r.edges.interior_error,
            r.edges.halo_pixels,
            r.fit_error
                .map_or("-".into(), |e| format!("{:.1}%", e * 100.0)),
        );
    }
    out.push_str(
        "\nRatios are against the control (Jimenez, d'Eon's six Gaussians) measured in the same \
         run. Silhouette band: scattering pixels within 2 pixels of a non-scattering one (where \
         background light bleeds in); halo: non-scattering pixels the SSS passes changed. \
         Texturing rows: the `edges` scene's albedo is uniform, so where the albedo meets the \
         blur changes the picture there only by rounding and the rows differ in time; what \
         each mode does to a texture is measured on `showcase-marble`'s veins (docs/sss.md, \
         \"Albedo after the scatter\").\n",
    );
    out
}

/// Runs the SSS report and writes `sss.md` and `sss-error-vs-time.png` into `out`. Returns the
/// Markdown and the files written.
pub fn write_sss_report(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    out: &Path,
    opts: &ReportOptions,
) -> Result<(String, Vec<PathBuf>)> {
    let results = run(gpu, shaders, cache, &sss_variants(), opts)?;
    let text = markdown(&results, opts, &gpu.info.describe());
    std::fs::create_dir_all(out)
        .map_err(|e| LucentError::InvalidInput(format!("{}: {e}", out.display())))?;
    let md = out.join("sss.md");
    crate::files::write_file_atomic(&md, text.as_bytes())?;
    let mut series: Vec<PlotSeries> = Vec::new();
    for r in &results {
        let point = PlotPoint {
            label: r.variant.name.clone(),
            x: r.frame.median,
            y: r.mean_error,
        };
        match series.iter_mut().find(|s| s.name == r.variant.knob) {
            Some(s) => s.points.push(point),
            None => series.push(PlotSeries {
                name: r.variant.knob.into(),
                points: vec![point],
            }),
        }
    }
    let png = out.join("sss-error-vs-time.png");
    write_scatter_png(
        &png,
        "Screen-space SSS: error against frame time",
        "frame ms (teapot)",
        "mean |GPU - brute-force reference| (edges, diffusion)",
        &series,
        true,
    )?;
    Ok((text, vec![md, png]))
}
