//! `lucent bench`: per-pass GPU times of a frame, verified to add up, with the optional
//! speed-of-light copies, a second technique alternated with the first, and the seeds'
//! published tables beside ours.

use lucent::features::technique::TechniqueModule;
use lucent::frame::{FrameDesc, FrameSettings, Renderer, Technique};
use lucent::images::output;
use lucent::measure::bench::{self, BenchOptions, BenchReport, Format};
use lucent::report::seeds::{self as seed_tables, SeedTable};
use lucent::{scene, LucentError, Result};

use crate::cli::BenchArgs;
use crate::session::{check_scene_outputs, with_renderer, Session};

/// The seeds' numbers `--compare-thesis` prints beside ours, as the technique allows.
struct Seeds {
    /// The LEAN-mapping thesis's table (control, lcb, lbb).
    thesis: Option<&'static SeedTable>,
    /// GDC 2011's cost of translucency.
    gdc: bool,
    /// Li et al.'s Table 1 (checked against the scene's materials once it is loaded).
    li: bool,
}

impl Seeds {
    /// What `--compare-thesis` (`wanted`) compares under `technique`; an error when it has
    /// nothing to compare.
    fn new(wanted: bool, technique: Technique) -> Result<Self> {
        let seeds = Self {
            thesis: technique
                .module()
                .and_then(|m| m.published_timing())
                .filter(|_| wanted),
            gdc: wanted
                && technique == Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
            // Li et al.'s Table 1: their technique, alone or in `auto`.
            li: wanted
                && (technique == Technique::Auto
                    || technique == Technique::Only(&lucent::features::layered::LAYERED)),
        };
        if wanted && seeds.thesis.is_none() && !seeds.gdc && !seeds.li {
            // The techniques with a published per-pass table, from the registry.
            let per_pass: Vec<String> = lucent::features::registry::TECHNIQUES
                .iter()
                .filter_map(|t| {
                    let table = t.published_timing()?;
                    Some(format!("{} ({})", t.name(), table.source))
                })
                .collect();
            return Err(LucentError::InvalidInput(format!(
                "--compare-seeds needs --technique {}, {} (GDC 2011's cost), or auto or {} on a \
                 scene with layered materials (Li et al.'s Table 1); '{}' has no published table",
                per_pass.join(", "),
                lucent::features::translucency::TRANSLUCENCY.name(),
                lucent::features::layered::LAYERED.name(),
                technique.name()
            )));
        }
        Ok(seeds)
    }
}

/// Benchmarks `--scene` and prints the report in `--format`, then what the flags add.
pub fn run(args: BenchArgs) -> Result<()> {
    let format = Format::parse(&args.format)?;
    let against = args.against.as_deref().map(Technique::parse).transpose()?;
    let technique = Technique::parse(&args.frame.technique)?;
    let seeds = Seeds::new(args.compare_thesis, technique)?;
    if format != Format::Markdown && args.compare_thesis {
        return Err(LucentError::InvalidInput(
            "--compare-thesis prints Markdown tables; use it with --format markdown".into(),
        ));
    }
    if format != Format::Markdown && args.embed {
        return Err(LucentError::InvalidInput(
            "--embed prints a Markdown table; use it with --format markdown".into(),
        ));
    }
    if format == Format::Csv && against.is_some() {
        return Err(LucentError::InvalidInput(
            "--against prints a Markdown table (or an `against` object with --format json); \
             use it with --format markdown or json"
                .into(),
        ));
    }
    let outputs: Vec<(&str, &std::path::Path)> = [("--json", &args.json), ("--out", &args.out)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    check_scene_outputs(&args.frame.scene, &outputs)?;
    let options = BenchOptions {
        frames: args.frames,
        warmup: args.warmup,
        isolate: args.isolate,
    };
    with_renderer(&args.frame, &args.gpu, false, |session, renderer, scene| {
        if seeds.li
            && FrameDesc::new(scene, &renderer.settings)?
                .layered()
                .is_none()
        {
            return Err(LucentError::InvalidInput(format!(
                "--compare-seeds with --technique {}: scene '{}' has no layered material, so \
                 Li et al.'s Table 1 has nothing to compare (try --scene scaling:N or layered)",
                technique.name(),
                args.frame.scene
            )));
        }
        let mut report = measure(session, renderer, scene, &args, &options)?;
        let compared = against
            .map(|technique| compare(session, renderer, scene, technique, &options))
            .transpose()?;
        report.against = compared.as_ref().map(bench::Comparison::against);
        print!("{}", report.format(format));
        if format != Format::Csv {
            println!();
        }
        print_seeds(session, renderer, scene, &args, &options, &seeds, &report)?;
        if let (Some(compared), Format::Markdown) = (&compared, format) {
            println!("{}", compared.markdown(&session.gpu.info.describe()));
            if seeds.thesis.is_some() {
                if let Some(line) = seed_tables::thesis_ratio_line(compared) {
                    println!("{line}");
                }
            }
        }
        if args.embed {
            let cost = lucent::measure::embed_cost::embed_cost(
                &session.gpu,
                &session.shaders,
                &session.pipeline_cache,
                scene,
                &args.frame.scene,
                technique,
                (renderer.settings.width, renderer.settings.height),
                (options.frames, options.warmup),
            )?;
            println!("{}", cost.markdown());
        }
        write_outputs(session, renderer, &args, format, &report)?;
        trusted(&report, &options)
    })
}

/// The benchmark itself, with the speed-of-light copies when `--speed-of-light` asks.
fn measure(
    session: &Session,
    renderer: &Renderer,
    scene: &scene::Scene,
    args: &BenchArgs,
    options: &BenchOptions,
) -> Result<BenchReport> {
    let gpu = &session.gpu;
    if !args.speed_of_light {
        return bench::run(gpu, renderer, scene, &args.frame.scene, options);
    }
    let mut copies = lucent::measure::speed_of_light::FloorFrame::for_renderer(
        gpu,
        &session.shaders,
        &session.pipeline_cache,
        renderer,
    )?;
    let report = bench::run_with_floor(
        gpu,
        renderer,
        Some(&mut copies),
        scene,
        &args.frame.scene,
        options,
    );
    let idle = gpu.wait_idle();
    copies.destroy(gpu);
    idle?;
    report
}

/// Prints the seeds' tables beside `report`: the thesis's, Li et al.'s, GDC 2011's cost.
fn print_seeds(
    session: &Session,
    renderer: &Renderer,
    scene: &scene::Scene,
    args: &BenchArgs,
    options: &BenchOptions,
    seeds: &Seeds,
    report: &BenchReport,
) -> Result<()> {
    if let Some(table) = &seeds.thesis {
        println!("{}", seed_tables::beside(report, table));
    }
    if seeds.li {
        let shadows = renderer.settings.shadows;
        println!(
            "{}",
            seed_tables::li_bench_beside(
                report,
                lucent::measure::scaling::triangles(scene),
                shadows.enabled.then_some(shadows.size),
            )
        );
    }
    if seeds.gdc {
        let cost = lucent::report::gdc_cost(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            scene,
            &format!("`{}`", args.frame.scene),
            (renderer.settings.width, renderer.settings.height),
            (options.frames, options.warmup),
        )?;
        println!("{}", seed_tables::gdc_beside(&cost));
    }
    Ok(())
}

/// `--against`: the same scene under `technique`, alternating frames with the main one.
fn compare(
    session: &Session,
    renderer: &Renderer,
    scene: &scene::Scene,
    technique: Technique,
    options: &BenchOptions,
) -> Result<bench::Comparison> {
    let gpu = &session.gpu;
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
    compared
}

/// Writes `--json` and `--out`; with CSV or JSON on stdout, the `wrote` lines go to stderr so
/// stdout stays parseable.
fn write_outputs(
    session: &Session,
    renderer: &Renderer,
    args: &BenchArgs,
    format: Format,
    report: &BenchReport,
) -> Result<()> {
    let note = |text: String| {
        if format == Format::Markdown {
            println!("{text}");
        } else {
            eprintln!("{text}");
        }
    };
    if let Some(json) = &args.json {
        lucent::files::write_file_atomic(json, report.json().as_bytes())?;
        note(format!("wrote {}", json.display()));
    }
    if let Some(out) = &args.out {
        let (width, height) = (renderer.settings.width, renderer.settings.height);
        output::write_png_rgba8(out, width, height, &renderer.read_display(&session.gpu)?)?;
        note(format!("wrote {}", out.display()));
    }
    Ok(())
}

/// Fails when the per-pass times could not be verified, saying when the run was short.
fn trusted(report: &BenchReport, options: &BenchOptions) -> Result<()> {
    if report.trusted {
        return Ok(());
    }
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
