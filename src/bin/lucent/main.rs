//! The `lucent` command: list scenes, render headless, benchmark, print the compiled plan.
//!
//! Every failure ends with one line `lucent: error: ...` and a non-zero exit, never a panic.
//! [`cli`] is the command line as clap parses it; each command is one module with a `run`.

use std::process::ExitCode;

use lucent::Result;

use crate::cli::{Cli, Command};

mod bake_thickness;
mod bench;
mod cli;
#[cfg(feature = "window")]
mod demo;
mod gallery;
mod gate;
mod inspect;
mod plan;
mod render;
mod report;
mod scenes;
mod session;
mod sweep;

/// Runs the command the command line names.
fn run(command: Command) -> Result<()> {
    match command {
        Command::Scenes => scenes::run(),
        Command::Render(args) => render::run(args),
        Command::Bench(args) if args.gate => match args.gate_baseline {
            Some(runs) => gate::baseline(&args.gpu, runs),
            None => gate::run(&args.gpu),
        },
        Command::Bench(args) => bench::run(args),
        #[cfg(feature = "window")]
        Command::Demo(args) => demo::run(args),
        Command::Gallery(args) => gallery::run(args),
        Command::Plan(args) => plan::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Report(args) => report::run(args),
        Command::Inspect(args) => inspect::run(args),
        Command::BakeThickness(args) => bake_thickness::run(args),
    }
}

/// `bench --gate` sets every benchmark's flags itself: refuses any other `bench` flag given
/// with it on the command line (but the GPU's: --validation, --device, --shaders), naming
/// them, rather than ignoring them.
fn refuse_with_gate(cli: &Cli, matches: &clap::ArgMatches) -> std::result::Result<(), String> {
    let (Command::Bench(args), Some(("bench", bench))) = (&cli.command, matches.subcommand())
    else {
        return Ok(());
    };
    if !args.gate {
        return Ok(());
    }
    const TAKEN: [&str; 5] = ["gate", "gate_baseline", "validation", "device", "shaders"];
    let command = <Cli as clap::CommandFactory>::command();
    let Some(bench_command) = command.find_subcommand("bench") else {
        return Ok(());
    };
    // Arguments only (the ids also name the flattened groups).
    let is_argument = |id: &str| bench_command.get_arguments().any(|a| a.get_id() == id);
    let given: Vec<String> = bench
        .ids()
        .map(|id| id.as_str())
        .filter(|id| !TAKEN.contains(id) && is_argument(id))
        .filter(|id| bench.value_source(id) == Some(clap::parser::ValueSource::CommandLine))
        .map(|id| format!("--{}", id.replace('_', "-")))
        .collect();
    if given.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "--gate sets the benchmarks' flags itself and takes only --gate-baseline, \
             --validation, --device and --shaders; remove {}",
            given.join(", ")
        ))
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
    let mut first = first.trim_start_matches("error: ").to_string();
    if first.ends_with(':') {
        // A list follows on its own lines (the missing arguments): keep it in the one line.
        let listed: Vec<&str> = lines
            .clone()
            .take_while(|l| l.starts_with('-') || l.starts_with('<'))
            .collect();
        first = format!("{first} {}", listed.join(", "));
    }
    let mut parts = vec![first];
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
    let parsed = <Cli as clap::CommandFactory>::command()
        .try_get_matches()
        .and_then(|matches| {
            let cli = <Cli as clap::FromArgMatches>::from_arg_matches(&matches)?;
            Ok((cli, matches))
        });
    let cli = match parsed {
        Ok((cli, matches)) => match refuse_with_gate(&cli, &matches) {
            Ok(()) => cli,
            Err(why) => {
                eprintln!("lucent: error: {why} (see `lucent bench --help`)");
                return ExitCode::from(2);
            }
        },
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
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("lucent: error: {e}");
            ExitCode::FAILURE
        }
    }
}
