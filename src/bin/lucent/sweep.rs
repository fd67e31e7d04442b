//! `lucent sweep`: a technique rendered at extreme parameters and on hostile geometry, with
//! NaN, Inf, the largest value and fp16 overflows counted per case.

use std::path::PathBuf;

use lucent::features::layered::LAYERED;
use lucent::features::sss::burley::BURLEY;
use lucent::features::technique::TechniqueModule;
use lucent::features::translucency::TRANSLUCENCY;
use lucent::{LucentError, Result};

use crate::cli::{GpuArgs, SweepArgs};
use crate::session::with_session;

/// Sweeps `args.technique` and prints (and writes) the table; fails on any NaN or Inf.
pub fn run(args: SweepArgs) -> Result<()> {
    let SweepArgs {
        technique,
        size: (width, height),
        out,
        quick,
        gpu: gpu_args,
    } = args;
    // The techniques with a sweep: their cases live in `lucent::measure::sweep`.
    let (translucency, layered, burley) = (TRANSLUCENCY.name(), LAYERED.name(), BURLEY.name());
    let technique = technique.as_str();
    if ![translucency, layered, burley].contains(&technique) {
        return Err(LucentError::InvalidInput(format!(
            "sweep: unknown technique '{technique}'; available: {translucency}, {layered}, \
             {burley}"
        )));
    }
    if quick && technique != layered {
        return Err(LucentError::InvalidInput(format!(
            "sweep: --quick applies to `sweep {layered}` only"
        )));
    }
    if let Some(out) = &out {
        lucent::files::check_outputs(&[], &[("--out", out)])?;
    }
    if technique == layered {
        return sweep_layered((width, height), out, quick, &gpu_args);
    }
    if technique == burley {
        return sweep_burley((width, height), out, &gpu_args);
    }
    let cases = lucent::measure::sweep::translucency_cases();
    let (rows, device) = with_session(&gpu_args, |session| {
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

/// `sweep layered`: Li et al.'s media, every case (or the quick subset), with progress on a
/// terminal.
fn sweep_layered(
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

/// `sweep burley`: Burley's extreme distances, albedos and views.
fn sweep_burley(
    (width, height): (u32, u32),
    out: Option<PathBuf>,
    gpu_args: &GpuArgs,
) -> Result<()> {
    use lucent::measure::sweep_burley;
    let cases = sweep_burley::burley_cases();
    let (rows, device) = with_session(gpu_args, |session| {
        let rows = sweep_burley::run_burley(
            &session.gpu,
            &session.shaders,
            &session.pipeline_cache,
            width,
            height,
            &cases,
        )?;
        Ok((rows, session.gpu.info.describe()))
    })?;
    let table = sweep_burley::markdown(&rows, width, height, &device);
    println!("{table}");
    if let Some(out) = &out {
        lucent::files::write_file_atomic(out, table.as_bytes())?;
        println!("wrote {}", out.display());
    }
    let bad: usize = rows.iter().map(|r| r.nan + r.inf).sum();
    if bad > 0 {
        return Err(LucentError::InvalidInput(format!(
            "sweep burley: {bad} NaN/Inf values (see the table)"
        )));
    }
    Ok(())
}
