//! `lucent report`: the report suite (every technique's passes beside their speed-of-light
//! copies, the seeds' tables, scaling curves, error against time) or one error-against-time
//! section, as DIR/report.md with PNG plots.

use lucent::{LucentError, Result};

use crate::cli::ReportArgs;
use crate::session::with_session;

/// Writes the suite (or the section `args.technique`) into `--out` and prints its text.
pub fn run(args: ReportArgs) -> Result<()> {
    let gpu_args = &args.gpu;
    if args.technique.as_deref() != Some("truth")
        && (args.truths.is_some() || args.scenes.is_some())
    {
        return Err(LucentError::InvalidInput(
            "report: --truths and --scenes are options of `lucent report truth` only".into(),
        ));
    }
    let (text, files) = match &args.technique {
        Some(technique) if technique == "truth" => {
            let truths = args
                .truths
                .clone()
                .unwrap_or_else(|| std::path::PathBuf::from("tools/truth"));
            let mut options = if args.quick {
                lucent::report::truth::TruthOptions::quick(truths)
            } else {
                lucent::report::truth::TruthOptions::full(truths)
            };
            options.scenes = args.scenes.clone();
            options.size = args.size;
            options.rounds = args.rounds.unwrap_or(options.rounds);
            options.warmup = args.warmup.unwrap_or(options.warmup);
            with_session(gpu_args, |session| {
                lucent::report::truth::write_truth_report(
                    &session.gpu,
                    &session.shaders,
                    &session.pipeline_cache,
                    &args.out,
                    &options,
                )
            })?
        }
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
            let reports = lucent::report::STANDALONE_REPORTS;
            let Some(&(_, write)) = reports.iter().find(|(name, _)| name == technique) else {
                let names: Vec<&str> = reports.iter().map(|(name, _)| *name).collect();
                return Err(LucentError::InvalidInput(format!(
                    "report: unknown section '{technique}'; available: {}, li, truth (or no \
                     section: the whole suite)",
                    names.join(", ")
                )));
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
