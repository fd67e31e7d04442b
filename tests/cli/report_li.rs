//! `lucent report li --quick --out DIR` from the command line, validation on: it finishes,
//! writes `li.md` and `li-error-vs-time.png`, every variant has a finite error and a finite,
//! positive time, and the Markdown names every knob of Li et al.'s technique.

use crate::common;
use lucent::report::li::{li_variants, KNOBS};

#[test]
fn quick_li_report_times_and_measures_every_knob() {
    let dir = common::report(&["li", "--quick"], "report-li-quick");

    let text = std::fs::read_to_string(dir.join("li.md")).unwrap();
    println!("{text}");
    let image = image::open(dir.join("li-error-vs-time.png")).unwrap();
    assert!(image.width() > 100 && image.height() > 100);
    assert!(!text.contains("NaN") && !text.contains("| inf"), "{text}");
    for knob in KNOBS {
        assert!(text.contains(knob), "the Markdown does not name '{knob}'");
    }
    assert!(text.contains("phase_difference"), "{text}");
    // One row per variant, each with a finite error and finite, positive times.
    let header = text
        .lines()
        .find(|l| l.starts_with("| knob |"))
        .expect("the table");
    let columns: Vec<&str> = header.trim_matches('|').split('|').map(str::trim).collect();
    let col = |name: &str| columns.iter().position(|c| *c == name).unwrap();
    let (error, layered, frame) = (col("relative L1"), col("layered ms"), col("frame ms"));
    let rows: Vec<Vec<String>> = text
        .lines()
        .skip_while(|l| !l.starts_with("| knob |"))
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    let variants = li_variants(true);
    assert_eq!(rows.len(), variants.len(), "{text}");
    for (row, v) in rows.iter().zip(&variants) {
        assert_eq!(row[0], v.knob, "{row:?}");
        assert_eq!(row[1], v.name, "{row:?}");
        let e: f64 = row[error].parse().unwrap_or_else(|_| panic!("{row:?}"));
        assert!(e.is_finite() && e >= 0.0, "{row:?}");
        for c in [layered, frame] {
            let ms: f64 = row[c].parse().unwrap_or_else(|_| panic!("{row:?}"));
            assert!(ms.is_finite() && ms > 0.0, "{row:?}");
        }
    }
}
