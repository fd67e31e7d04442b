//! The layered stability sweep (issue 14, deliverable 7) on lavapipe with validation and
//! synchronization validation on: every case's frame and f64 references free of NaN and Inf,
//! and `lucent sweep layered` writing its table and exiting 0.

use lucent::measure::sweep_layered::{layered_cases, run_layered, LayeredGeometry};

use crate::common;

use crate::common::TestGpu;

#[test]
fn layered_sweep_has_no_nan_or_inf_in_any_case() {
    let test = TestGpu::new();
    let (gpu, shaders, cache) = (&test.gpu, &test.shaders, &test.cache);
    let cases = layered_cases().unwrap();
    let rows = run_layered(gpu, shaders, cache, 32, 24, &cases, |_, _| {}).unwrap();
    assert_eq!(rows.len(), cases.len());
    let bad: Vec<String> = rows
        .iter()
        .filter(|r| r.bad() > 0)
        .map(|r| {
            format!(
                "{} / {}: {} NaN, {} Inf, {} non-finite reference values {:?}",
                r.case.label,
                r.case.geometry.name(),
                r.hdr.nan,
                r.hdr.inf,
                r.reference.non_finite,
                r.reference.notes
            )
        })
        .collect();
    assert!(bad.is_empty(), "unstable cases:\n{}", bad.join("\n"));
    // No reference refused a case (every medium passes validate).
    let refused: Vec<String> = rows
        .iter()
        .filter(|r| !r.reference.notes.is_empty())
        .map(|r| format!("{}: {:?}", r.case.label, r.reference.notes))
        .collect();
    assert!(refused.is_empty(), "{}", refused.join("\n"));
    // The cases light something, on the GPU and in the references: a sweep of black frames or
    // zero radiances would prove nothing.
    assert!(rows.iter().any(|r| r.hdr.max > 1.0));
    assert!(rows
        .iter()
        .filter(|r| r.case.geometry == LayeredGeometry::Front)
        .any(|r| r.reference.max_radiance > 0.1));
    assert!(rows.iter().all(|r| r.reference.samples > 0));
    test.finish();
}

#[test]
fn sweep_layered_command_writes_the_table_and_exits_zero() {
    let table = common::temp_dir("sweep-layered").join("sweep.md");
    let out = common::succeeded(
        common::lucent_command()
            .args(common::words(
                "sweep layered --quick --validation --size 24x16",
            ))
            .arg("--out")
            .arg(&table),
    );
    let written = std::fs::read_to_string(&table).unwrap();
    assert!(
        written.contains("## lucent sweep layered, 24x16"),
        "{written}"
    );
    assert!(written.contains("- verdict: stable"), "{written}");
    assert!(String::from_utf8_lossy(&out.stdout).contains(&written));
    // One row per quick case.
    let cases = lucent::measure::sweep_layered::quick_layered_cases().unwrap();
    let rows = written.lines().filter(|l| l.starts_with("| ")).count();
    assert_eq!(rows, cases.len() + 1, "{written}");
    // `--quick` belongs to the layered sweep only; unknown sweeps name the available ones.
    for (args, want) in [
        (
            &["sweep", "translucency", "--quick"][..],
            "--quick applies to `sweep layered` only",
        ),
        (
            &["sweep", "nonsense"][..],
            "available: translucency, layered",
        ),
    ] {
        let out = common::lucent(args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(want), "{stderr}");
    }
}
