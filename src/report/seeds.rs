//! The seeds' published measurements, as data, so benchmarks can print lucent's numbers beside
//! them. Each table quotes its source; numbers are as printed (the thesis gives no totals: the
//! sums here are of its rows).
//!
//! - the LEAN-mapping thesis's Tables 1 and 2 (per-pass ms of LBB and the control): [`beside`];
//! - GDC 2011's full-screen translucency cost per platform: [`gdc_beside`];
//! - Li et al.'s Table 1 (FPS from 2,900 to 1,084,450 triangles at 512 and 1024 dynamic-texture
//!   resolution): [`li_beside`] (with their claim as ratios, [`li_claim`]) and, for one bench,
//!   [`li_bench_beside`].
//!
//! Absolute times on a CPU Vulkan driver and on 2008-2013 GPUs are not comparable; every table
//! shows shares and ratios beside the milliseconds, and names both devices.

use std::fmt::Write as _;

use crate::measure::bench::BenchReport;

pub use crate::features::sss::control::THESIS_TABLE_2_CONTROL;
pub use crate::features::sss::lbb::THESIS_TABLE_1_LBB;
pub use crate::features::technique::{SeedRow, SeedTable};

/// The thesis's LBB / control cost ratio beside ours, when `compared` measured a LEAN technique
/// (`lbb` or `lcb`) against `control` in one run (alternating frames).
pub fn thesis_ratio_line(compared: &crate::measure::bench::Comparison) -> Option<String> {
    // Which side the thesis timed as LBB (Table 1: LBB, or LCB, which runs its pipeline) and
    // which as the control (Table 2), by the tables the techniques' modules publish.
    let published = |name: &str| {
        crate::frame::Technique::parse(name)
            .ok()
            .and_then(|t| t.module())
            .and_then(|m| m.published_timing())
    };
    let is =
        |name: &str, table: &SeedTable| published(name).is_some_and(|t| std::ptr::eq(t, table));
    let [a, b] = &compared.names;
    let (lean, control) = if is(a, &THESIS_TABLE_1_LBB) && is(b, &THESIS_TABLE_2_CONTROL) {
        (0, 1)
    } else if is(b, &THESIS_TABLE_1_LBB) && is(a, &THESIS_TABLE_2_CONTROL) {
        (1, 0)
    } else {
        return None;
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
fn matching_pass<'a>(
    report: &'a BenchReport,
    seed_row: &str,
) -> Option<&'a crate::measure::bench::PassRow> {
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

/// GDC 2011 (Barré-Brisebois and Bouchard), "Performance" slide: the translucency term at
/// full-screen coverage, per platform, and its instruction count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GdcCost {
    /// Platform as printed.
    pub platform: &'static str,
    /// Full-screen coverage, ms.
    pub ms: f64,
    /// Shader instructions.
    pub instructions: u32,
}

/// The talk's table, as printed.
pub const GDC2011_FULL_SCREEN: &[GdcCost] = &[
    GdcCost {
        platform: "XBOX 360",
        ms: 0.6,
        instructions: 13,
    },
    GdcCost {
        platform: "PLAYSTATION 3",
        ms: 1.0,
        instructions: 17,
    },
    GdcCost {
        platform: "PC (DX11)",
        ms: 0.03,
        instructions: 12,
    },
];

/// What lucent measured for the GDC comparison: the same scene lit without and with
/// translucency, all of it translucent, alternating frames in one run.
#[derive(Clone, Debug, PartialEq)]
pub struct TranslucencyCost {
    /// Device.
    pub device: String,
    /// Scene and size, as text.
    pub setup: String,
    /// Lighting pass median without translucency, ms.
    pub lighting_none_ms: f64,
    /// Lighting pass median with translucency, ms.
    pub lighting_translucency_ms: f64,
    /// Frame medians without and with.
    pub frame_ms: [f64; 2],
}

/// GDC 2011's full-screen cost beside ours, as a share of the lighting pass and of the frame.
/// The talk prints no lighting-pass or frame time, so its share can only be formed against a
/// frame budget; the table says so.
pub fn gdc_beside(ours: &TranslucencyCost) -> String {
    let mut out = String::new();
    let extra = ours.lighting_translucency_ms - ours.lighting_none_ms;
    // Guarded: shares of a 0 ms pass are meaningless, shown as 0.
    let share = |x: f64, of: f64| if of > 0.0 { x / of * 100.0 } else { 0.0 };
    let _ = writeln!(
        out,
        "## Beside GDC 2011's translucency cost (full-screen coverage)\n\n\
         - theirs: the talk's \"Performance\" slide (Xbox 360, PS3 on SPUs, PC DX11 compute); \
          it gives no lighting-pass or frame time, so their cost is shown against a 33.3 ms \
          (30 Hz) frame\n- ours: {}, {}; technique `none` and `translucency` alternating frames\n\n\
         | platform | full-screen ms | instructions | share of a 33.3 ms frame |\n|---|---:|---:|---:|",
        ours.device, ours.setup
    );
    for c in GDC2011_FULL_SCREEN {
        let _ = writeln!(
            out,
            "| {} | {:.2} | {} | {:.2}% |",
            c.platform,
            c.ms,
            c.instructions,
            c.ms / 33.3 * 100.0
        );
    }
    let _ = writeln!(
        out,
        "\n| ours | lighting ms | translucency extra ms | extra / lighting without | frame ms | extra / frame |\n\
         |---|---:|---:|---:|---:|---:|\n\
         | `none` | {:.3} | | | {:.3} | |\n\
         | `translucency` | {:.3} | {extra:+.3} | {:+.1}% | {:.3} | {:+.1}% |",
        ours.lighting_none_ms,
        ours.frame_ms[0],
        ours.lighting_translucency_ms,
        share(extra, ours.lighting_none_ms),
        ours.frame_ms[1],
        share(ours.frame_ms[1] - ours.frame_ms[0], ours.frame_ms[0]),
    );
    out
}

/// One row of Li et al.'s Table 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiRow {
    /// Model.
    pub object: &'static str,
    /// Triangles.
    pub triangles: u64,
    /// FPS with 512x512 dynamic textures.
    pub fps_512: f64,
    /// FPS with 1024x1024 dynamic textures.
    pub fps_1024: f64,
}

const fn li(object: &'static str, triangles: u64, fps_512: f64, fps_1024: f64) -> LiRow {
    LiRow {
        object,
        triangles,
        fps_512,
        fps_1024,
    }
}

/// Li et al., "real-time subsurface scattering for dynamic objects", Table 1 ("Experiment
/// Data"), the triangle and FPS columns.
pub const LI_TABLE_1: &[LiRow] = &[
    li("deformed frog", 2_900, 231.0, 71.0),
    li("teapot", 6_400, 230.0, 70.0),
    li("goddess", 63_932, 208.0, 68.0),
    li("bunny", 69_451, 205.0, 66.0),
    li("maitreya", 86_994, 185.0, 63.0),
    li("dragon", 100_000, 178.0, 59.0),
    li("monster", 345_944, 124.0, 52.0),
    li("Happy buddha", 1_084_450, 63.0, 42.0),
];

/// The machine Li et al. measured on.
pub const LI_DEVICE: &str = "Pentium 4 3.0 GHz, NVIDIA GeForce 8800 GTS 512M, DirectX 9.0c, SM 3.0";

/// Our frame at one of Li et al.'s triangle counts, with 512^2 and 1024^2 light-space maps
/// (their "dynamic texture" resolutions) at one output size.
#[derive(Clone, Debug, PartialEq)]
pub struct LiOurs {
    /// Triangles drawn.
    pub triangles: u64,
    /// Frame medians with 512^2 and 1024^2 maps, ms.
    pub frame_ms: [f64; 2],
    /// The `light-space maps` pass's medians, ms (`None`: no such pass).
    pub maps_ms: [Option<f64>; 2],
    /// Li et al.'s three passes (irradiance, single and multiple scattering), sums of their
    /// medians, ms (`None`: a pass is missing).
    pub layered_ms: [Option<f64>; 2],
}

/// `x / of` when both are positive finite numbers.
fn ratio_of(x: f64, of: f64) -> Option<f64> {
    (x.is_finite() && of.is_finite() && x > 0.0 && of > 0.0).then(|| x / of)
}

/// `Some(x)` as "1.23x", `None` as "-".
fn times(x: Option<f64>) -> String {
    x.map_or("-".into(), |x| format!("{x:.2}x"))
}

/// `Some(ms)` with 2 decimals, 0, missing or not finite as "-".
fn ms_cell(x: Option<f64>) -> String {
    match x {
        Some(v) if v.is_finite() && v > 0.0 => format!("{v:.2}"),
        _ => "-".into(),
    }
}

/// Li et al.'s claim "cost follows the texture resolution, not the triangle count", as
/// frame-time ratios, theirs (from 1000 / FPS) over the rows we measured and ours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiRatios {
    /// Rows compared (the first `rows` of [`LI_TABLE_1`]).
    pub rows: usize,
    /// Theirs: 1024 / 512 at the smallest and at the largest triangle count compared.
    pub theirs_resolution: [f64; 2],
    /// Ours: the same.
    pub ours_resolution: [Option<f64>; 2],
    /// Theirs: largest / smallest triangle count at 512 and at 1024.
    pub theirs_triangles: [f64; 2],
    /// Ours: the same.
    pub ours_triangles: [Option<f64>; 2],
}

/// The ratios of [`LiRatios`] over `ours` (in [`LI_TABLE_1`]'s order, its first rows).
pub fn li_ratios(ours: &[LiOurs]) -> LiRatios {
    let rows = ours.len().clamp(1, LI_TABLE_1.len());
    let (first, last) = (LI_TABLE_1[0], LI_TABLE_1[rows - 1]);
    let ms = |fps: f64| 1000.0 / fps;
    let (o_first, o_last) = (ours.first(), ours.last());
    let ours_res = |o: Option<&LiOurs>| o.and_then(|o| ratio_of(o.frame_ms[1], o.frame_ms[0]));
    let ours_tri = |i: usize| match (o_first, o_last) {
        (Some(a), Some(b)) => ratio_of(b.frame_ms[i], a.frame_ms[i]),
        _ => None,
    };
    LiRatios {
        rows,
        theirs_resolution: [first.fps_512 / first.fps_1024, last.fps_512 / last.fps_1024],
        ours_resolution: [ours_res(o_first), ours_res(o_last)],
        theirs_triangles: [
            ms(last.fps_512) / ms(first.fps_512),
            ms(last.fps_1024) / ms(first.fps_1024),
        ],
        ours_triangles: [ours_tri(0), ours_tri(1)],
    }
}

/// Which of the two a set of ratios says the cost follows (stated whatever it shows).
fn follows(resolution: Option<f64>, triangles: Option<f64>) -> &'static str {
    match (resolution, triangles) {
        (Some(r), Some(t)) if r > 1.1 * t => "the texture resolution more than the triangle count",
        (Some(r), Some(t)) if t > 1.1 * r => "the triangle count more than the texture resolution",
        (Some(_), Some(_)) => "both about alike (within 10%)",
        _ => "nothing measurable (a ratio is missing)",
    }
}

/// Li et al.'s Table 1 beside our frame times at the same triangle counts: lucent's frame of
/// `setup` (Li et al.'s technique included) with 512^2 and 1024^2 light-space maps, their
/// dynamic-texture resolutions, at one output size; then their claim as ratios.
pub fn li_beside(device: &str, setup: &str, ours: &[LiOurs]) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Beside Li et al.'s Table 1 (FPS against triangles)\n\n\
         - theirs: {LI_DEVICE}; 512 and 1024 are their dynamic-texture resolutions\n\
         - ours: {device}; {setup}, with Li et al.'s passes (layered irradiance, single and \
          multiple scattering) in the frame; 512 and 1024 are the light-space maps' texels per \
          face, the textures lucent's passes read the light's entry points from (a point light: \
          six faces)\n\
         - \"1024 / 512\": the frame-time ratio between the two texture resolutions (theirs \
          from 1000 / FPS); \"maps\": the `light-space maps` pass; \"Li passes\": the sum of \
          the three layered passes' medians\n\n\
         | object | triangles | theirs FPS 512 | theirs FPS 1024 | theirs ms 512 | theirs 1024 / 512 | ours triangles | ours ms 512 | ours ms 1024 | ours FPS 512 | ours FPS 1024 | ours 1024 / 512 | ours maps ms 512 / 1024 | ours Li passes ms 512 / 1024 |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    let fps = |ms: f64| ratio_of(1000.0, ms).map_or("-".into(), |f| format!("{f:.1}"));
    for (i, row) in LI_TABLE_1.iter().enumerate() {
        let o = ours.get(i);
        let _ =
            writeln!(
            out,
            "| {} | {} | {:.0} | {:.0} | {:.2} | {:.2}x | {} | {} | {} | {} | {} | {} | {} | {} |",
            row.object,
            row.triangles,
            row.fps_512,
            row.fps_1024,
            1000.0 / row.fps_512,
            row.fps_512 / row.fps_1024,
            o.map_or("-".into(), |o| o.triangles.to_string()),
            o.map_or("-".into(), |o| ms_cell(Some(o.frame_ms[0]))),
            o.map_or("-".into(), |o| ms_cell(Some(o.frame_ms[1]))),
            o.map_or("-".into(), |o| fps(o.frame_ms[0])),
            o.map_or("-".into(), |o| fps(o.frame_ms[1])),
            o.map_or("-".into(), |o| times(ratio_of(o.frame_ms[1], o.frame_ms[0]))),
            o.map_or("-".into(), |o| format!(
                "{} / {}",
                ms_cell(o.maps_ms[0]),
                ms_cell(o.maps_ms[1])
            )),
            o.map_or("-".into(), |o| format!(
                "{} / {}",
                ms_cell(o.layered_ms[0]),
                ms_cell(o.layered_ms[1])
            )),
        );
    }
    out.push_str(&li_claim(ours));
    out
}

/// Li et al.'s claim, "cost follows the texture resolution, not the triangle count", as
/// ratios of frame times: theirs and ours over the same rows.
pub fn li_claim(ours: &[LiOurs]) -> String {
    let r = li_ratios(ours);
    let (first, last) = (LI_TABLE_1[0], LI_TABLE_1[r.rows - 1]);
    let whole = LI_TABLE_1[LI_TABLE_1.len() - 1];
    let mut out = String::new();
    let _ = writeln!(
        out,
        "\n### Cost follows the texture resolution, not the triangle count?\n\n\
         Li et al. find their cost follows the dynamic textures' resolution rather than the \
         triangle count (their whole table: {:.0} times the triangles cost {:.2}x at 512 and \
         {:.2}x at 1024; the resolution 1024 / 512 costs {:.2}x at {} triangles). As \
         frame-time ratios over the rows measured here ({} to {} triangles):\n\n\
         | | texture 1024 / 512 at {} triangles | texture 1024 / 512 at {} triangles | triangles {} / {} at 512 | triangles {} / {} at 1024 |\n\
         |---|---:|---:|---:|---:|\n\
         | theirs | {:.2}x | {:.2}x | {:.2}x | {:.2}x |\n\
         | ours | {} | {} | {} | {} |\n",
        whole.triangles as f64 / LI_TABLE_1[0].triangles as f64,
        LI_TABLE_1[0].fps_512 / whole.fps_512,
        LI_TABLE_1[0].fps_1024 / whole.fps_1024,
        LI_TABLE_1[0].fps_512 / LI_TABLE_1[0].fps_1024,
        LI_TABLE_1[0].triangles,
        first.triangles,
        last.triangles,
        first.triangles,
        last.triangles,
        last.triangles,
        first.triangles,
        last.triangles,
        first.triangles,
        r.theirs_resolution[0],
        r.theirs_resolution[1],
        r.theirs_triangles[0],
        r.theirs_triangles[1],
        times(r.ours_resolution[0]),
        times(r.ours_resolution[1]),
        times(r.ours_triangles[0]),
        times(r.ours_triangles[1]),
    );
    let _ = writeln!(
        out,
        "At the smallest count and 512 textures, theirs follows {}; ours follows {}. With \
         1024 textures and the largest count: theirs {}, ours {}.",
        follows(Some(r.theirs_resolution[0]), Some(r.theirs_triangles[0])),
        follows(r.ours_resolution[0], r.ours_triangles[0]),
        follows(Some(r.theirs_resolution[1]), Some(r.theirs_triangles[1])),
        follows(r.ours_resolution[1], r.ours_triangles[1]),
    );
    out
}

/// The row of Li et al.'s Table 1 nearest `triangles` (in ratio).
pub fn li_nearest_row(triangles: u64) -> LiRow {
    let t = (triangles.max(1) as f64).ln();
    *LI_TABLE_1
        .iter()
        .min_by(|a, b| {
            let d = |r: &LiRow| ((r.triangles as f64).ln() - t).abs();
            d(a).total_cmp(&d(b))
        })
        .expect("the table has rows")
}

/// `lucent bench --compare-seeds` on a layered scene: the row of Li et al.'s Table 1 nearest
/// the scene's triangle count beside the bench (`map_size`: the light-space maps' texels per
/// face, `None` when no light casts).
pub fn li_bench_beside(report: &BenchReport, triangles: u64, map_size: Option<u32>) -> String {
    let row = li_nearest_row(triangles);
    let layered: Vec<&crate::measure::bench::PassRow> = report
        .passes
        .iter()
        // Every layered pass (`contains`: multiple scattering's blur counts with it, as in
        // `report li`).
        .filter(|p| {
            crate::report::li::LAYERED_PASSES
                .iter()
                .any(|n| p.name.contains(n))
        })
        .collect();
    let layered_ms: f64 = layered.iter().map(|p| p.median_ms).sum();
    let maps = report
        .passes
        .iter()
        .find(|p| p.name.contains("light-space maps"));
    let frame = report.frame_ms.median;
    let share = |x: f64| ratio_of(x, frame).map_or("-".into(), |s| format!("{:.1}%", s * 100.0));
    let fps = ratio_of(1000.0, frame).map_or("-".into(), |f| format!("{f:.1}"));
    let mut out = String::new();
    let _ = writeln!(
        out,
        "## Beside Li et al.'s Table 1 (the row nearest this scene's triangles)\n\n\
         - theirs: {LI_DEVICE}; row `{}`, {} triangles; 512 and 1024 are their dynamic-texture \
          resolutions\n\
         - ours: {}, {}x{}, scene `{}` ({triangles} triangles), technique `{}`, {}; Li et al.'s \
          passes: {}\n\n\
         | | triangles | texture | FPS | frame ms | Li passes ms | Li passes share | light-space maps ms |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|\n\
         | theirs | {} | 512 | {:.0} | {:.2} | - | - | - |\n\
         | theirs | {} | 1024 | {:.0} | {:.2} | - | - | - |\n\
         | ours | {triangles} | {} | {fps} | {} | {} | {} | {} |",
        row.object,
        row.triangles,
        report.device,
        report.width,
        report.height,
        report.scene,
        report.technique,
        map_size.map_or("no light-space maps (no light casts)".into(), |s| format!(
            "light-space maps {s}^2 texels per face"
        )),
        if layered.is_empty() {
            "none in this frame".to_string()
        } else {
            layered
                .iter()
                .map(|p| format!("`{}`", p.name))
                .collect::<Vec<_>>()
                .join(", ")
        },
        row.triangles,
        row.fps_512,
        1000.0 / row.fps_512,
        row.triangles,
        row.fps_1024,
        1000.0 / row.fps_1024,
        map_size.map_or("-".into(), |s| s.to_string()),
        ms_cell(Some(frame)),
        ms_cell((!layered.is_empty()).then_some(layered_ms)),
        if layered.is_empty() {
            "-".into()
        } else {
            share(layered_ms)
        },
        ms_cell(maps.map(|p| p.median_ms)),
    );
    let _ = writeln!(
        out,
        "\nTheirs 1024 / 512 at this row: {:.2}x. Ours at one texture size only; `lucent \
         report` measures both sizes at every row in one run (and bench with `--shadow-size \
         512` or `1024` picks the size).",
        row.fps_512 / row.fps_1024
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn li_table_spans_the_issue_s_range() {
        assert_eq!(LI_TABLE_1.len(), 8);
        assert_eq!(LI_TABLE_1[0].triangles, 2_900);
        assert_eq!(LI_TABLE_1[7].triangles, 1_084_450);
        // Their text: "its efficiency may decline to a quarter" for the simplest scene.
        assert!((LI_TABLE_1[0].fps_512 / LI_TABLE_1[0].fps_1024 - 3.25).abs() < 0.01);
        let ours: Vec<LiOurs> = LI_TABLE_1
            .iter()
            .enumerate()
            .map(|(i, r)| LiOurs {
                triangles: r.triangles,
                frame_ms: [2.0 + i as f64, 6.0 + i as f64],
                maps_ms: [Some(1.0), Some(4.0)],
                layered_ms: [Some(0.5), None],
            })
            .collect();
        let text = li_beside("llvmpipe", "`scaling:N`, technique `auto`", &ours);
        assert!(
            text.contains("| Happy buddha | 1084450 | 63 | 42 |"),
            "{text}"
        );
        assert!(
            text.contains("| 2.00 | 6.00 | 500.0 | 166.7 | 3.00x | 1.00 / 4.00 | 0.50 / - |"),
            "{text}"
        );
        assert!(!text.contains("not implemented"), "{text}");
        assert!(
            text.contains("374 times the triangles cost 3.67x at 512 and 1.69x at 1024"),
            "{text}"
        );
        // The claim: theirs 231 / 71 against 231 / 63 (ms ratios), ours 6 / 2 against 9 / 2.
        let r = li_ratios(&ours);
        assert!((r.theirs_resolution[0] - 231.0 / 71.0).abs() < 1e-9);
        assert!((r.theirs_triangles[0] - 231.0 / 63.0).abs() < 1e-9);
        assert_eq!(r.ours_resolution[0], Some(3.0));
        assert_eq!(r.ours_triangles[0], Some(4.5));
        assert!(
            text.contains("| theirs | 3.25x | 1.50x | 3.67x | 1.69x |"),
            "{text}"
        );
        assert!(
            text.contains("| ours | 3.00x | 1.44x | 4.50x | 2.17x |"),
            "{text}"
        );
        assert!(
            text.contains("ours follows the triangle count more than the texture resolution"),
            "{text}"
        );
        // Guarded: no frame gives "-", never NaN.
        let none = [LiOurs {
            triangles: 2_900,
            frame_ms: [0.0, f64::NAN],
            maps_ms: [None, None],
            layered_ms: [None, None],
        }];
        let text = li_beside("llvmpipe", "x", &none);
        assert!(!text.contains("NaN") && !text.contains("inf |"), "{text}");
        assert_eq!(li_ratios(&none).ours_resolution, [None, None]);
        assert_eq!(li_nearest_row(5_000).object, "teapot");
        assert_eq!(li_nearest_row(2_000_000).triangles, 1_084_450);
    }

    #[test]
    fn gdc_shares_are_of_our_lighting_pass() {
        let text = gdc_beside(&TranslucencyCost {
            device: "llvmpipe".into(),
            setup: "grid125".into(),
            lighting_none_ms: 10.0,
            lighting_translucency_ms: 11.0,
            frame_ms: [20.0, 21.0],
        });
        assert!(
            text.contains("| `translucency` | 11.000 | +1.000 | +10.0% | 21.000 | +5.0% |"),
            "{text}"
        );
        assert!(text.contains("| XBOX 360 | 0.60 | 13 | 1.80% |"), "{text}");
    }

    #[test]
    fn thesis_tables_sum_as_printed() {
        assert!((THESIS_TABLE_1_LBB.total() - 4.12862).abs() < 1e-9);
        assert!((THESIS_TABLE_2_CONTROL.total() - 1.22174).abs() < 1e-9);
        assert_eq!(THESIS_TABLE_1_LBB.rows.len(), 10);
        assert_eq!(THESIS_TABLE_2_CONTROL.rows.len(), 9);
    }
}
