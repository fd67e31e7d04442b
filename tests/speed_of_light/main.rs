//! The speed-of-light gate: every pass of the built-in scenes against its copy, held under a
//! limit, so a change that makes a pass far heavier (a feature that doubles the plain frame)
//! fails a test when it lands instead of being found in a report later.
//!
//! The benchmarks run with the validation layer on, as every test does (an error fails them).
//!
//! Not a timed test: `lucent bench --speed-of-light` measures each pass and its copy (a
//! fullscreen pass moving the same bytes) alternating in one run, and the gate holds the
//! ratio of the two, which the machine's speed and load mostly cancel out of. The limits are
//! today's ratios ([`BASELINE`], measured with the gate's own settings) times [`MARGIN`]: a real
//! doubling of a pass trips them, run-to-run noise (up to about 30% at this size on the shared
//! 2-core machine) does not. A noise spike can still go past a limit once, so a scene whose
//! first run fails is measured again, up to [`RUNS`] times, and each pass is judged by its
//! least ratio: a pass that really got heavier is heavy in every run.
//!
//! The gate is a test binary of its own so that cargo runs it alone: beside the other CLI
//! tests (two cores, several `lucent` processes at once) every fragment-heavy pass reads up to
//! 1.5x higher against its copy, which would hide a real doubling behind the margin.
//!
//! A pass the table does not know, or a pass it lists that the frame no longer has, fails too:
//! a new pass is what a new feature adds. docs/performance.md ("Speed-of-light gate") says how
//! to update the table; `cargo test --test speed_of_light -- --nocapture` prints the
//! measured ratios as table lines.

use std::collections::BTreeMap;

#[path = "../common/mod.rs"]
#[allow(dead_code)] // the harness serves several binaries; this one uses little of it
mod common;

/// Frame size, frames, warm-up and shadow-map size of the gate's benchmarks: small enough that
/// all runs take about half a minute together, large enough that every pass is several times
/// the timer's and the scheduler's noise.
const BENCH: &str = "--validation --size 512x384 --frames 9 --warmup 3 --shadow-size 512";

/// How far above today's ratio a pass may go: a doubling (2x) trips it, noise does not.
const MARGIN: f64 = 1.6;

/// Runs of a scene at most before a pass over its limit fails the gate.
const RUNS: usize = 3;

/// Today's ratio of each pass to its copy, per benchmark (a built-in scene, with the options
/// after its name), with [`BENCH`]'s settings: medians of five runs on the project's 2-core
/// lavapipe machine (Mesa 22.3.6), the machine otherwise idle. Every built-in scene under its
/// own materials (`auto`), and the techniques no built-in scene picks by itself on `skin`
/// (Burley, the bilateral blur, LBB, LCB, the 12-pass control) and FXAA on `smoke`.
const BASELINE: &[(&str, &[(&str, f64)])] = &[
    (
        "smoke",
        &[
            ("light-space maps", 1.31),
            ("gbuffer + lighting", 8.02),
            ("tonemap", 1.75),
        ],
    ),
    (
        "cubes",
        &[
            ("light-space maps", 1.30),
            ("gbuffer + lighting", 8.32),
            ("tonemap", 1.93),
        ],
    ),
    (
        "grid125",
        &[
            ("light-space maps", 3.72),
            ("gbuffer + lighting", 12.54),
            ("tonemap", 1.83),
        ],
    ),
    (
        "teapot",
        &[
            ("light-space maps", 1.01),
            ("gbuffer + lighting", 6.91),
            ("horizontal blur", 3.64),
            ("vertical blur", 2.68),
            ("tonemap", 1.90),
        ],
    ),
    (
        "skin",
        &[
            ("light-space maps", 1.91),
            ("gbuffer + lighting", 6.54),
            ("horizontal blur", 2.97),
            ("vertical blur", 2.36),
            ("tonemap", 1.86),
        ],
    ),
    (
        "mixed",
        &[
            ("light-space maps", 1.46),
            ("gbuffer + lighting", 6.97),
            ("horizontal blur", 2.81),
            ("vertical blur", 2.23),
            ("tonemap", 1.92),
        ],
    ),
    (
        "edges",
        &[
            ("light-space maps", 1.05),
            ("gbuffer + lighting", 6.72),
            ("horizontal blur", 3.61),
            ("vertical blur", 2.79),
            ("tonemap", 1.96),
        ],
    ),
    (
        "layered",
        &[
            ("light-space maps", 2.40),
            ("gbuffer + lighting", 7.94),
            ("layered irradiance", 2.17),
            ("multiple scattering", 3.52),
            ("multiple scattering blur", 0.12),
            ("single scattering", 4.30),
            ("tonemap", 2.25),
        ],
    ),
    (
        "dynamic",
        &[
            ("light-space maps", 1.18),
            ("gbuffer + lighting", 7.66),
            ("layered irradiance", 4.23),
            ("multiple scattering", 7.41),
            ("multiple scattering blur", 0.12),
            ("single scattering", 9.44),
            ("tonemap", 2.24),
        ],
    ),
    (
        "scaling",
        &[
            ("light-space maps", 5.34),
            ("gbuffer + lighting", 10.19),
            ("layered irradiance", 3.98),
            ("multiple scattering", 6.77),
            ("multiple scattering blur", 0.14),
            ("single scattering", 6.92),
            ("tonemap", 2.14),
        ],
    ),
    (
        "showcase-translucency",
        &[
            ("light-space maps", 1.68),
            ("gbuffer + lighting", 7.84),
            ("tonemap", 1.98),
        ],
    ),
    (
        "showcase-skin",
        &[
            ("light-space maps", 1.91),
            ("gbuffer + lighting", 5.70),
            ("horizontal blur", 4.63),
            ("vertical blur", 3.30),
            ("tonemap", 2.03),
        ],
    ),
    (
        "showcase-marble",
        &[
            ("light-space maps", 1.42),
            ("gbuffer + lighting", 8.99),
            ("horizontal blur", 5.39),
            ("vertical blur", 3.65),
            ("tonemap", 2.04),
        ],
    ),
    (
        "showcase-layered",
        &[
            ("light-space maps", 2.23),
            ("gbuffer + lighting", 8.39),
            ("layered irradiance", 3.05),
            ("multiple scattering", 5.01),
            ("multiple scattering blur", 0.83),
            ("single scattering", 5.83),
            ("tonemap", 2.17),
        ],
    ),
    (
        "skin --technique burley",
        &[
            ("light-space maps", 1.76),
            ("gbuffer + lighting", 6.33),
            ("burley", 3.67),
            ("burley resolve", 2.00),
            ("tonemap", 1.81),
        ],
    ),
    (
        "skin --technique bilateral",
        &[
            ("light-space maps", 1.82),
            ("projection + lighting", 6.02),
            ("horizontal blur", 5.47),
            ("vertical blur", 5.16),
            ("tonemap", 1.91),
        ],
    ),
    (
        "skin --technique lbb",
        &[
            ("light-space maps", 1.80),
            ("projection + lighting", 6.03),
            ("horizontal blur #1", 2.54),
            ("vertical blur #1", 2.71),
            ("horizontal blur #2", 2.61),
            ("vertical blur #2", 1.46),
            ("horizontal blur #3", 2.55),
            ("vertical blur #3", 1.52),
            ("horizontal blur #4", 2.58),
            ("vertical blur #4", 1.55),
            ("horizontal blur #5", 2.59),
            ("vertical blur #5", 1.60),
            ("horizontal blur #6", 2.64),
            ("vertical blur #6", 1.64),
            ("final lighting", 2.30),
            ("tonemap", 1.97),
        ],
    ),
    (
        "skin --technique lcb",
        &[
            ("light-space maps", 1.73),
            ("projection + lighting", 6.03),
            ("horizontal blur #1", 5.64),
            ("vertical blur #1", 5.28),
            ("horizontal blur #2", 6.09),
            ("vertical blur #2", 3.30),
            ("horizontal blur #3", 6.05),
            ("vertical blur #3", 3.42),
            ("horizontal blur #4", 6.17),
            ("vertical blur #4", 3.66),
            ("horizontal blur #5", 6.13),
            ("vertical blur #5", 3.82),
            ("horizontal blur #6", 6.18),
            ("vertical blur #6", 3.86),
            ("final lighting", 2.46),
            ("tonemap", 2.02),
        ],
    ),
    (
        "skin --technique control",
        &[
            ("light-space maps", 1.80),
            ("gbuffer + lighting", 6.17),
            ("horizontal blur #1", 4.74),
            ("vertical blur #1", 3.97),
            ("horizontal blur #2", 5.08),
            ("vertical blur #2", 2.69),
            ("horizontal blur #3", 5.10),
            ("vertical blur #3", 2.75),
            ("horizontal blur #4", 5.10),
            ("vertical blur #4", 2.89),
            ("horizontal blur #5", 4.97),
            ("vertical blur #5", 2.85),
            ("horizontal blur #6", 5.01),
            ("vertical blur #6", 2.95),
            ("combine", 1.50),
            ("tonemap", 2.03),
        ],
    ),
    (
        "smoke --aa fxaa",
        &[
            ("light-space maps", 1.44),
            ("gbuffer + lighting", 7.83),
            ("tonemap", 1.72),
            ("fxaa", 2.84),
        ],
    ),
];

/// One run of `scene`: each pass's ratio to its copy, or why the run measured nothing (the
/// bench's own timing checks can refuse a run on a loaded machine).
fn ratios(scene: &str) -> Result<BTreeMap<String, f64>, String> {
    let line = format!("bench --scene {scene} {BENCH} --speed-of-light --format json");
    let out = common::lucent(&common::words(&line));
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        // Only the benchmark's timing checks may refuse a run; anything else is a failure.
        assert!(
            stderr.contains("lucent: error: timing:"),
            "{line}: {stderr}"
        );
        return Err(stderr.trim().to_string());
    }
    let json: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{line}: {e}: {}", String::from_utf8_lossy(&out.stdout)));
    let rows = json["speed_of_light"]
        .as_array()
        .expect("speed_of_light rows");
    Ok(rows
        .iter()
        .map(|row| {
            let pass = row["pass"].as_str().expect("a pass name").to_string();
            let ratio = row["ratio"]
                .as_f64()
                .unwrap_or_else(|| panic!("{scene}: no copy stands in for '{pass}': {row}"));
            (pass, ratio)
        })
        .collect())
}

#[test]
fn no_pass_of_the_built_in_scenes_drifts_far_above_its_copy() {
    let mut failures = Vec::new();
    for &(scene, baseline) in BASELINE {
        let known: BTreeMap<&str, f64> = baseline.iter().copied().collect();
        // Each pass's least ratio over the runs so far.
        let mut least: BTreeMap<String, f64> = BTreeMap::new();
        let mut refused = Vec::new();
        let mut measured_runs = 0;
        for _ in 0..RUNS {
            match ratios(scene) {
                Ok(measured) => {
                    measured_runs += 1;
                    for (pass, ratio) in measured {
                        let entry = least.entry(pass).or_insert(f64::INFINITY);
                        *entry = entry.min(ratio);
                    }
                }
                Err(why) => refused.push(why),
            }
            let over: Vec<String> = least
                .iter()
                .filter(|(pass, &r)| known.get(pass.as_str()).is_some_and(|&b| r > b * MARGIN))
                .map(|(pass, r)| format!("'{pass}' {r:.2}x"))
                .collect();
            if !least.is_empty() && over.is_empty() {
                break;
            }
            println!("{scene}: over the limit after {measured_runs} run(s): {over:?}");
        }
        assert!(
            !least.is_empty(),
            "{scene}: every run was refused by the benchmark's timing checks: {refused:?}"
        );
        // Paste-ready lines for BASELINE (docs/performance.md says when to).
        println!("{scene}: least ratios of {measured_runs} run(s)");
        for (pass, ratio) in &least {
            println!("{scene}: (\"{pass}\", {ratio:.2}),");
        }
        for (pass, &ratio) in &least {
            match known.get(pass.as_str()) {
                None => failures.push(format!(
                    "{scene}: pass '{pass}' ({ratio:.2}x its copy) has no limit: a new pass; add \
                     it to BASELINE in tests/speed_of_light/main.rs (docs/performance.md)"
                )),
                Some(&b) if ratio > b * MARGIN => failures.push(format!(
                    "{scene}: '{pass}' is {ratio:.2}x its copy at least, in each of \
                     {measured_runs} runs, over its limit {:.2}x (today {b:.2}x times {MARGIN}): \
                     the pass got that much heavier",
                    b * MARGIN
                )),
                Some(_) => {}
            }
        }
        for &(pass, _) in baseline {
            if !least.contains_key(pass) {
                failures.push(format!(
                    "{scene}: the frame has no pass '{pass}' any more: update BASELINE in \
                     tests/speed_of_light/main.rs (docs/performance.md)"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
