//! `lucent report truth --quick --out DIR` from the command line, validation on, on the
//! committed truths (tools/truth): it finishes, writes `truth.md` and one plot per truth scene
//! (and per region a truth names) that decodes as a PNG, has a section per scene with one row
//! per technique (every row a finite error, FLIP, energies and a positive time), and the
//! budget table names a best technique for every scene. A truth directory that does not exist, and a scene it does not hold, are clear
//! errors.

use std::path::{Path, PathBuf};

use crate::common;
use lucent::frame::Technique;

fn truths() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/truth")
}

/// The table rows (cells trimmed) after the line starting with `header`.
fn rows_after<'a>(text: &'a str, header: &str) -> Vec<Vec<&'a str>> {
    text.lines()
        .skip_while(|l| !l.starts_with(header))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect()
}

#[test]
fn quick_truth_report_measures_every_technique_on_every_truth() {
    let truths = truths();
    let dir = common::report(
        &["truth", "--quick", "--truths", truths.to_str().unwrap()],
        "report-truth-quick",
    );
    let text = std::fs::read_to_string(dir.join("truth.md")).unwrap();
    println!("{text}");
    let scenes = lucent::measure::truth::truth_names(&truths).unwrap();
    assert!(scenes.len() >= 5, "{scenes:?}");
    // Every truth, then each region it names (`NAME-REGION`, measured apart: a head's ear).
    let mut names = scenes.clone();
    for scene in &scenes {
        let truth = lucent::measure::truth::load_truth(&truths, scene).unwrap();
        names.extend(truth.regions.iter().map(|r| format!("{scene}-{}", r.name)));
    }
    assert!(names.iter().any(|n| n.ends_with("-ear")), "{names:?}");
    assert!(
        !text.contains("NaN") && !text.contains("not rendered"),
        "{text}"
    );
    let budget = rows_after(&text, "| scene |");
    assert_eq!(budget.len(), names.len(), "{text}");
    for name in &names {
        let image = image::open(dir.join(format!("truth-{name}.png"))).unwrap();
        assert!(image.width() > 100 && image.height() > 100);
        let row = budget.iter().find(|r| r[0] == name.as_str()).unwrap();
        assert!(
            row[row.len() - 1].starts_with('`'),
            "no best technique: {row:?}"
        );
        assert!(
            text.contains(&format!("- **{name}**: closest `")),
            "no choice for {name}"
        );
        // The scene's own table: one row per technique, in `Technique::all` order.
        let section = text
            .split(&format!("\n## {name}\n"))
            .nth(1)
            .unwrap_or_else(|| panic!("no section for {name}"));
        let rows = rows_after(section, "| variant |");
        let techniques = Technique::all();
        assert_eq!(rows.len(), techniques.len(), "{section}");
        for (row, (technique, _)) in rows.iter().zip(&techniques) {
            // "`lbb` (= `none`)" where the scene has nothing for the technique to act on.
            assert!(row[0].starts_with(&format!("`{technique}`")), "{row:?}");
            let ms: f64 = row[1].parse().unwrap();
            assert!(ms.is_finite() && ms > 0.0, "{row:?}");
            for cell in &row[3..8] {
                let value: f64 = cell.parse().unwrap_or_else(|_| panic!("{row:?}"));
                assert!(value.is_finite() && value >= 0.0, "{row:?}");
            }
        }
    }
}

#[test]
fn truth_report_names_what_is_missing() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("report-truth-missing");
    let run = |args: &[&str]| {
        let output = common::lucent_command()
            .arg("report")
            .arg("truth")
            .args(args)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!output.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&output.stderr).to_string()
    };
    let missing = run(&["--truths", "/nonexistent/truths"]);
    assert!(missing.contains("/nonexistent/truths/scenes"), "{missing}");
    let truths = truths();
    let unknown = run(&[
        "--truths",
        truths.to_str().unwrap(),
        "--scenes",
        "no-such-scene",
    ]);
    assert!(
        unknown.contains("no truth 'no-such-scene'") && unknown.contains("diffuse-sphere"),
        "{unknown}"
    );
    let elsewhere = common::lucent_command()
        .args(["report", "sss", "--scenes", "x", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!elsewhere.status.success());
    assert!(String::from_utf8_lossy(&elsewhere.stderr).contains("`lucent report truth` only"));
}
