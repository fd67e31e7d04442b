//! `lucent bench --gate`: the speed-of-light gate ([`lucent::measure::gate`]) run on this
//! machine. Each benchmark of the gate's tables runs as its own `lucent bench` process (this
//! executable, so the binary measured is the one asked), alone, one after another: each pass
//! against its floor, and the techniques of [`gate::AGAINST`] against `none`. Prints every pass
//! with its ratio (the median of [`gate::RUNS`] runs), its limit and the verdict, then the
//! paste-ready table lines, and fails when a pass is over its limit, new, or gone.

use std::collections::BTreeMap;
use std::io::Write as _;

use lucent::measure::gate::{self, Judged};
use lucent::{LucentError, Result};

use crate::cli::GpuArgs;

/// What a benchmark of the gate holds a pass against.
#[derive(Clone, Copy)]
enum Held {
    /// Its speed-of-light floor (`--speed-of-light`).
    Floor,
    /// The same pass under `none` (`--against none`).
    AgainstNone,
}

impl Held {
    /// The words the verdicts use.
    fn what(self) -> &'static str {
        match self {
            Held::Floor => "its floor",
            Held::AgainstNone => "`none`",
        }
    }

    /// The limit of a pass whose ratio is `today` in the table.
    fn limit(self) -> fn(f64) -> f64 {
        match self {
            Held::Floor => gate::floor_limit,
            Held::AgainstNone => gate::against_limit,
        }
    }

    /// The benchmark's command line after `bench --scene`.
    fn flags(self) -> String {
        match self {
            // --isolate: each pass is also timed alone with the device idle, as its floor is.
            Held::Floor => format!("{} --isolate --speed-of-light --format json", gate::BENCH),
            Held::AgainstNone => format!("{} --against none --format json", gate::AGAINST_BENCH),
        }
    }
}

/// This executable, and `gpu`'s flags (device, validation, shaders) as every benchmark of the
/// gate is given them.
fn lucent_and_flags(gpu: &GpuArgs) -> Result<(std::path::PathBuf, Vec<String>)> {
    let exe = std::env::current_exe()
        .map_err(|e| LucentError::InvalidInput(format!("the gate cannot find lucent: {e}")))?;
    let mut forwarded: Vec<String> = Vec::new();
    if gpu.validation {
        forwarded.push("--validation".into());
    }
    if let Some(device) = &gpu.device {
        forwarded.extend(["--device".into(), device.clone()]);
    }
    if let Some(shaders) = &gpu.shaders {
        forwarded.extend(["--shaders".into(), shaders.display().to_string()]);
    }
    Ok((exe, forwarded))
}

/// Every benchmark of the gate's tables, with what it holds its passes against.
fn benchmarks() -> impl Iterator<Item = (&'static str, Held)> {
    gate::floor_benchmarks()
        .map(|b| (b, Held::Floor))
        .chain(gate::AGAINST.iter().map(|(b, _)| (*b, Held::AgainstNone)))
}

/// Today's ratios of `bench`'s passes: the machine's floor table, or the one `none` table.
fn table_of(bench: &str, held: Held, choice: &gate::TableChoice) -> Vec<(&'static str, f64)> {
    match held {
        Held::Floor => choice.baseline(bench),
        Held::AgainstNone => gate::AGAINST
            .iter()
            .find(|(b, _)| *b == bench)
            .map(|(_, t)| t.to_vec())
            .unwrap_or_default(),
    }
}

/// The device a benchmark ran on and its driver, as its report names them: a machine's table
/// is chosen by both.
#[derive(Clone, Debug, Default)]
struct RanOn {
    device: String,
    driver: String,
}

/// The table this machine is judged by: its kind's, from the device and driver a benchmark
/// ran on and the CPU (lavapipe compiles every shader for the CPU).
fn choose_table(on: &RanOn) -> gate::TableChoice {
    let cpu = gate::CpuKind::this_machine();
    let choice = gate::TableChoice::for_machine(&on.device, &on.driver, &cpu);
    println!(
        "Machine: {} / {}, CPU {cpu}; judged by {}.\n",
        on.device,
        on.driver,
        choice.describe()
    );
    choice
}

/// `--gate-baseline N`: every benchmark of the gate `runs` times; prints each pass's median,
/// least and largest ratio and its spread, then the table lines of the medians.
pub fn baseline(gpu: &GpuArgs, runs: usize) -> Result<()> {
    let (exe, forwarded) = lucent_and_flags(gpu)?;
    println!(
        "## lucent bench --gate --gate-baseline {runs}\n\n\
         | benchmark | pass | against | median ratio | least | largest | largest / least |\n\
         |---|---|---|---:|---:|---:|---:|"
    );
    let mut table_lines = String::new();
    for (bench, held) in benchmarks() {
        // Only the `none` comparison filters by its table, which is the same on every machine.
        let table = table_of(bench, held, &gate::TableChoice::Envelope(None));
        let mut samples: BTreeMap<String, Vec<f64>> = BTreeMap::new();
        for _ in 0..runs {
            // A run the benchmark's timing checks refuse adds nothing.
            if let Ok((measured, _)) = ratios(&exe, &forwarded, bench, &table, held)? {
                for (pass, ratio) in measured {
                    samples.entry(pass).or_default().push(ratio);
                }
            }
        }
        table_lines.push_str(&format!("// {bench} (against {})\n", held.what()));
        for (pass, ratios) in &samples {
            let stats = lucent::measure::stats::Stats::of(ratios);
            println!(
                "| {bench} | {pass} | {} | {:.2}x | {:.2}x | {:.2}x | {:.2} |",
                held.what(),
                stats.median,
                stats.min,
                stats.max,
                stats.max / stats.min.max(1e-9)
            );
            table_lines.push_str(&format!("(\"{pass}\", {:.2}),\n", stats.median));
        }
        let _ = std::io::stdout().flush();
    }
    println!(
        "\nTable lines (src/measure/gate.rs), medians of {runs} runs:\n\n```text\n{table_lines}```"
    );
    Ok(())
}

/// Runs the gate with `gpu`'s flags (device, validation, shaders) passed to every benchmark.
pub fn run(gpu: &GpuArgs) -> Result<()> {
    let (exe, forwarded) = lucent_and_flags(gpu)?;
    println!(
        "## lucent bench --gate\n\n\
         Each pass's ratio (the median of {} runs) against its limit (today's ratio times {}; \
         against `none`, today's extra cost times it, plus {}: docs/performance.md).\n",
        gate::RUNS,
        gate::MARGIN,
        gate::AGAINST_NOISE
    );
    let mut failures = Vec::new();
    let mut table_lines = String::new();
    let mut choice = None;
    for (bench, held) in benchmarks() {
        let against = table_of(bench, held, &gate::TableChoice::Envelope(None));
        let (mut samples, ran_on) = measure(&exe, &forwarded, bench, &against, held)?;
        let choice = *choice.get_or_insert_with(|| {
            let chosen = choose_table(&ran_on);
            println!(
                "| benchmark | pass | against | ratio | limit | verdict |\n\
                 |---|---|---|---:|---:|---|"
            );
            chosen
        });
        let table = table_of(bench, held, &choice);
        let mut judged = gate::judge(&gate::median_of_runs(&samples), &table, held.limit());
        // A pass over its limit is measured again before it fails the gate: a transient load
        // on the machine (another process, a CPU's frequency step) moves a few runs, a pass
        // that got heavier stays heavy in twice as many (the median of all of them decides).
        if judged.iter().any(Judged::over) {
            println!(
                "| {bench} | (over its limit: measured {} more times) | | | | |",
                gate::RUNS
            );
            let (more, _) = measure(&exe, &forwarded, bench, &against, held)?;
            samples.extend(more);
            judged = gate::judge(&gate::median_of_runs(&samples), &table, held.limit());
        }
        let runs = samples.len();
        print!("{}", gate::markdown_rows(bench, held.what(), &judged));
        let _ = std::io::stdout().flush();
        failures.extend(judged.iter().filter_map(|j| j.failure(bench, held.what())));
        table_lines.push_str(&format!(
            "// {bench} (against {}, median of {runs} run(s))\n",
            held.what()
        ));
        for j in &judged {
            if let Some(ratio) = j.ratio {
                table_lines.push_str(&format!("(\"{}\", {ratio:.2}),\n", j.pass));
            }
        }
    }
    println!("\nTable lines (src/measure/gate.rs), as measured:\n\n```text\n{table_lines}```");
    if failures.is_empty() {
        println!("\nThe gate passes: every pass is under its limit.");
        Ok(())
    } else {
        Err(LucentError::InvalidInput(format!(
            "the speed-of-light gate failed:\n{}",
            failures.join("\n")
        )))
    }
}

/// Measures `bench` [`gate::RUNS`] times: each run's ratios (the runs the benchmark's timing
/// checks did not refuse), and the device and driver they ran on.
fn measure(
    exe: &std::path::Path,
    forwarded: &[String],
    bench: &str,
    table: &[(&str, f64)],
    held: Held,
) -> Result<(Vec<BTreeMap<String, f64>>, RanOn)> {
    let mut runs = Vec::new();
    let mut refused = Vec::new();
    let mut ran_on = RanOn::default();
    for _ in 0..gate::RUNS {
        match ratios(exe, forwarded, bench, table, held)? {
            Ok((measured, on)) => {
                runs.push(measured);
                ran_on = on;
            }
            Err(why) => refused.push(why),
        }
    }
    if runs.is_empty() {
        return Err(LucentError::Timing(format!(
            "gate: {bench}: every run was refused by the benchmark's timing checks: {}",
            refused.join("; ")
        )));
    }
    Ok((runs, ran_on))
}

/// What one run measured: each pass's ratio, and the device and driver it ran on.
type OneRun = (BTreeMap<String, f64>, RanOn);

/// One run of `bench`: each pass's ratio (to its floor; against `none`, only the passes the
/// two techniques share and `table` holds) and the device and driver it ran on, or why the
/// run measured nothing (the benchmark's own timing checks can refuse a run on a loaded
/// machine).
fn ratios(
    exe: &std::path::Path,
    forwarded: &[String],
    bench: &str,
    table: &[(&str, f64)],
    held: Held,
) -> Result<std::result::Result<OneRun, String>> {
    let line = format!("bench --scene {bench} {}", held.flags());
    let out = std::process::Command::new(exe)
        .args(line.split_whitespace())
        .args(forwarded)
        .output()
        .map_err(|e| LucentError::InvalidInput(format!("gate: {line}: {e}")))?;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        // Only the benchmark's timing checks may refuse a run; anything else is a failure.
        if stderr.contains("lucent: error: timing:") {
            return Ok(Err(stderr.trim().to_string()));
        }
        return Err(LucentError::InvalidInput(format!(
            "gate: `lucent {line}` failed: {}",
            stderr.trim()
        )));
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).map_err(|e| {
        LucentError::InvalidInput(format!("gate: `lucent {line}` printed no JSON report: {e}"))
    })?;
    let rows = match held {
        Held::Floor => &json["speed_of_light"],
        Held::AgainstNone => &json["against"]["passes"],
    };
    let rows = rows.as_array().ok_or_else(|| {
        LucentError::InvalidInput(format!("gate: `lucent {line}`: the report has no rows"))
    })?;
    // Against its floor, each pass's isolated time: alone with the device idle, as the floor
    // was timed (the report's own ratio takes the in-frame time when the checks pass, the
    // isolated one when they do not, and on lavapipe the two differ by up to 2x for a short
    // pass: the ratio would change with the run's timing mode).
    let isolated: BTreeMap<&str, f64> = json["passes"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|p| Some((p["name"].as_str()?, p["isolated_ms"].as_f64()?)))
        .collect();
    let mut ratios = BTreeMap::new();
    for row in rows {
        let pass = row["pass"].as_str().unwrap_or_default().to_string();
        let ratio = match held {
            Held::Floor => isolated
                .get(pass.as_str())
                .zip(row["floor_ms"].as_f64())
                .filter(|&(_, floor)| floor > 0.0)
                .map(|(pass_ms, floor)| pass_ms / floor),
            Held::AgainstNone => row["ratio"].as_f64(),
        };
        match (ratio, held) {
            (Some(ratio), Held::Floor) => {
                ratios.insert(pass, ratio);
            }
            (Some(ratio), Held::AgainstNone) => {
                if table.iter().any(|(p, _)| *p == pass) {
                    ratios.insert(pass, ratio);
                }
            }
            // A pass only one technique has (a blur): nothing to compare.
            (None, Held::AgainstNone) => {}
            (None, Held::Floor) => {
                return Err(LucentError::InvalidInput(format!(
                    "gate: {bench}: no floor stands in for '{pass}': {row}"
                )))
            }
        }
    }
    let ran_on = RanOn {
        device: json["device"].as_str().unwrap_or("unknown").to_string(),
        driver: json["driver"]
            .as_str()
            .unwrap_or("unknown driver")
            .to_string(),
    };
    Ok(Ok((ratios, ran_on)))
}
