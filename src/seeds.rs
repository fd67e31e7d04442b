//! The seeds' published measurements, as data, so benchmarks can print lucent's numbers beside
//! them. Each table quotes its source; numbers are as printed (the thesis gives no totals: the
//! sums here are of its rows).

use std::fmt::Write as _;

use crate::bench::BenchReport;

/// One row of a published per-pass table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedRow {
    /// The row's name as printed.
    pub name: &'static str,
    /// Milliseconds.
    pub ms: f64,
}

/// A published per-pass table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeedTable {
    /// Where it comes from.
    pub source: &'static str,
    /// The machine it was measured on.
    pub device: &'static str,
    /// Its rows in order.
    pub rows: &'static [SeedRow],
}

impl SeedTable {
    /// Sum of the rows, ms.
    pub fn total(&self) -> f64 {
        self.rows.iter().map(|r| r.ms).sum()
    }
}

const fn row(name: &'static str, ms: f64) -> SeedRow {
    SeedRow { name, ms }
}

const THESIS_DEVICE: &str =
    "NVIDIA GTX 770, 1024x768 (Visual Studio Graphics Debugger, average of ten runs)";

/// The LEAN-mapping SSS thesis, section 5.1.2, Table 1: "Performance figures for bilateral
/// blur" (LBB, marble, four blurs).
pub const THESIS_TABLE_1_LBB: SeedTable = SeedTable {
    source: "LEAN-mapping SSS thesis, section 5.1.2, Table 1 (LBB)",
    device: THESIS_DEVICE,
    rows: &[
        row("Projection", 0.20),
        row("Horizontal Blur #1", 0.24),
        row("Vertical Blur #1", 0.63),
        row("Horizontal Blur #2", 0.36),
        row("Vertical Blur #2", 0.63),
        row("Horizontal Blur #3", 0.36),
        row("Vertical Blur #3", 0.63),
        row("Horizontal Blur #4", 0.35),
        row("Vertical Blur #4", 0.63),
        row("Final Lighting Pass", 0.09862),
    ],
};

/// The thesis, section 5.1.2, Table 2: "Performance figures for the control screen space
/// shader" (Jimenez's blur, marble, four blurs; "Vertical Blur #3" is printed without a unit).
pub const THESIS_TABLE_2_CONTROL: SeedTable = SeedTable {
    source: "LEAN-mapping SSS thesis, section 5.1.2, Table 2 (control)",
    device: THESIS_DEVICE,
    rows: &[
        row("Lighting calculations", 0.05174),
        row("Horizontal Blur #1", 0.10),
        row("Vertical Blur #1", 0.16),
        row("Horizontal Blur #2", 0.11),
        row("Vertical Blur #2", 0.16),
        row("Horizontal Blur #3", 0.14),
        row("Vertical Blur #3", 0.15),
        row("Horizontal Blur #4", 0.14),
        row("Vertical Blur #4", 0.21),
    ],
};

/// The thesis's LBB / control cost ratio beside ours, when `compared` measured a LEAN technique
/// (`lbb` or `lcb`) against `control` in one run (alternating frames).
pub fn thesis_ratio_line(compared: &crate::bench::Comparison) -> Option<String> {
    let [a, b] = &compared.names;
    let (lean, control) = match (a.as_str(), b.as_str()) {
        ("control", "lbb" | "lcb") => (1, 0),
        ("lbb" | "lcb", "control") => (0, 1),
        _ => return None,
    };
    let theirs = THESIS_TABLE_1_LBB.total() / THESIS_TABLE_2_CONTROL.total();
    let ours = compared.frame[lean].median / compared.frame[control].median.max(1e-9);
    Some(format!(
        "\n**{} / control, frame total:** ours {ours:.3}x (same run, alternating frames); the \
         thesis's LBB / control {theirs:.2}x (sums of its Tables 1 and 2: {:.3} / {:.3} ms)\n",
        compared.names[lean],
        THESIS_TABLE_1_LBB.total(),
        THESIS_TABLE_2_CONTROL.total()
    ))
}

/// lucent's pass for a thesis row: blurs by name (case-insensitive), the lighting rows by role.
fn matching_pass<'a>(report: &'a BenchReport, seed_row: &str) -> Option<&'a crate::bench::PassRow> {
    let wanted = seed_row.to_ascii_lowercase();
    report.passes.iter().find(|p| {
        let name = p.name.to_ascii_lowercase();
        match wanted.as_str() {
            "lighting calculations" | "projection" => name.contains("lighting"),
            "final lighting pass" => name == "combine" || name == "final lighting",
            _ => name == wanted,
        }
    })
}

/// Our measured rows beside `table`'s, each as a share of its own frame (absolute times on a
/// CPU driver and a 2013 GPU are not comparable; shares are).
pub fn beside(report: &BenchReport, table: &SeedTable) -> String {
    let mut out = String::new();
    let total = table.total();
    let _ = writeln!(
        out,
        "## Beside {}\n\n- theirs: {}; the table prints no total, its rows sum to {total:.3} ms\n\
         - ours: {}, {}x{}, scene `{}`, technique `{}`; frame {:.3} ms\n\n\
         | row | theirs ms | theirs share | ours | ours ms | ours share |\n|---|---:|---:|---|---:|---:|",
        table.source,
        table.device,
        report.device,
        report.width,
        report.height,
        report.scene,
        report.technique,
        report.frame_ms.median
    );
    for r in table.rows {
        let ours = matching_pass(report, r.name);
        let _ = writeln!(
            out,
            "| {} | {:.3} | {:.1}% | {} | {} | {} |",
            r.name,
            r.ms,
            r.ms / total * 100.0,
            ours.map_or("-", |p| p.name.as_str()),
            ours.map_or("-".into(), |p| format!("{:.3}", p.median_ms)),
            ours.map_or("-".into(), |p| format!("{:.1}%", p.share * 100.0)),
        );
    }
    let unmatched: Vec<&str> = report
        .passes
        .iter()
        .filter(|p| {
            !table
                .rows
                .iter()
                .any(|r| matching_pass(report, r.name).is_some_and(|m| m.name == p.name))
        })
        .map(|p| p.name.as_str())
        .collect();
    if !unmatched.is_empty() {
        let _ = writeln!(
            out,
            "\nOurs without a row of theirs: {} (lucent's profiles have six Gaussians, the \
             thesis's marble four; tonemapping is outside its tables).",
            unmatched.join(", ")
        );
    }
    let _ = writeln!(
        out,
        "\nThesis LBB / control: {:.2}x (from its rows: {:.3} / {:.3} ms).",
        THESIS_TABLE_1_LBB.total() / THESIS_TABLE_2_CONTROL.total(),
        THESIS_TABLE_1_LBB.total(),
        THESIS_TABLE_2_CONTROL.total()
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_tables_sum_as_printed() {
        assert!((THESIS_TABLE_1_LBB.total() - 4.12862).abs() < 1e-9);
        assert!((THESIS_TABLE_2_CONTROL.total() - 1.22174).abs() < 1e-9);
        assert_eq!(THESIS_TABLE_1_LBB.rows.len(), 10);
        assert_eq!(THESIS_TABLE_2_CONTROL.rows.len(), 9);
    }
}
