//! `lucent report --quick --out DIR` from the command line, validation on: it finishes, and
//! `report.md` has a table for every technique, a speed-of-light ratio for every pass, the seeds'
//! tables beside ours, the three scaling axes, the error-against-time sections, and every plot
//! it links decodes as a PNG.

use crate::common;

/// One bench table of the report: its title, its pass names, and the (pass, pass / copy) rows
/// of the speed-of-light table after it.
type Table = (String, Vec<String>, Vec<(String, String)>);

/// The pass rows of each bench table, and the rows of the speed-of-light table that follows it.
fn tables(report: &str) -> Vec<Table> {
    let mut out = Vec::new();
    for section in report.split("### lucent bench: ").skip(1) {
        let title = section.lines().next().unwrap_or("").to_string();
        let (bench, rest) = section
            .split_once("#### Speed of light")
            .unwrap_or_else(|| panic!("no speed-of-light table after {title}"));
        let cells = |line: &str| -> Vec<String> {
            line.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        };
        let passes: Vec<String> = bench
            .lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| pass") && !l.starts_with("| **"))
            .map(|l| cells(l)[0].clone())
            .collect();
        let floors: Vec<(String, String)> = rest
            .lines()
            .skip_while(|l| !l.starts_with("| pass"))
            .skip(2)
            .take_while(|l| l.starts_with('|'))
            .map(|l| {
                let c = cells(l);
                (c[0].clone(), c[3].clone())
            })
            .collect();
        out.push((title, passes, floors));
    }
    out
}

#[test]
fn quick_report_has_every_table_and_plot() {
    let dir = common::report(&["--quick"], "report-quick");

    let report = std::fs::read_to_string(dir.join("report.md")).unwrap();
    let tables = tables(&report);
    let techniques = common::techniques();
    assert_eq!(tables.len(), techniques.len(), "{report}");
    for name in techniques.iter().map(|t| t.name()) {
        assert!(
            tables
                .iter()
                .any(|(t, _, _)| t.contains(&format!("technique `{name}`"))),
            "no table for {name}"
        );
    }
    for (title, passes, floors) in &tables {
        assert!(!passes.is_empty(), "{title}");
        for pass in passes {
            let (_, ratio) = floors
                .iter()
                .find(|(n, _)| n == pass)
                .unwrap_or_else(|| panic!("{title}: '{pass}' has no speed-of-light row"));
            let x: f64 = ratio
                .split('x')
                .next()
                .and_then(|v| v.parse().ok())
                .unwrap_or_else(|| panic!("{title}: '{pass}' ratio '{ratio}'"));
            assert!(x.is_finite() && x > 0.0, "{title}: {pass} {x}");
        }
    }
    for needle in [
        "Beside LEAN-mapping SSS thesis, section 5.1.2, Table 2",
        "Beside GDC 2011's translucency cost",
        "| XBOX 360 | 0.60 |",
        "Beside Li et al.'s Table 1",
        "| deformed frog | 2900 | 231 | 71 |",
        "with Li et al.'s passes (layered irradiance, single and multiple scattering) in the frame",
        "Cost follows the texture resolution, not the triangle count?",
        "| theirs | 3.25x | 3.06x | 1.11x | 1.04x |",
        "### Against triangles",
        "### Against resolution",
        "### Against lights",
        "Growth along lights",
        "error against run time",
        "Screen-space SSS: error against run time",
        "## Anti-aliasing: FXAA",
        "| `showcase-skin` |",
    ] {
        assert!(report.contains(needle), "missing '{needle}'");
    }
    // Li et al.'s claim as ratios: ours finite and positive, whatever lavapipe shows.
    let ours = report
        .lines()
        .skip_while(|l| !l.starts_with("| theirs | 3.25x"))
        .nth(1)
        .unwrap_or_else(|| panic!("no ratio row of ours"));
    assert!(ours.starts_with("| ours | "), "{ours}");
    println!("Li et al.'s claim, {ours}");
    for cell in ours.trim_matches('|').split('|').skip(1) {
        let x: f64 = cell
            .trim()
            .trim_end_matches('x')
            .parse()
            .unwrap_or_else(|_| panic!("ratio '{cell}' in {ours}"));
        assert!(x.is_finite() && x > 0.0, "{ours}");
    }
    // Every linked plot exists and decodes.
    let mut plots = 0;
    for link in report.split("](").skip(1) {
        let file = link.split(')').next().unwrap();
        if file.ends_with(".png") {
            let image = image::open(dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
            assert!(image.width() > 100 && image.height() > 100, "{file}");
            plots += 1;
        }
    }
    // Bars per technique, Li et al., three scaling axes, translucency and SSS error against
    // time.
    assert!(plots >= techniques.len() + 6, "{plots} plots");
}
