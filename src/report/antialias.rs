//! The report's anti-aliasing section: what FXAA costs (its pass and the frame, with and
//! without it, alternating frames in one run) and what it changes (the share of pixels it
//! touches against the same frame without it), on a scene of hard silhouettes (`cubes`) and
//! one of soft ones (`showcase-skin`).

use std::fmt::Write as _;

use crate::bake::scene::load_scene_baked;
use crate::features::antialias::Antialias;
use crate::frame::{FrameSettings, Renderer};
use crate::measure::bench;
use crate::report::{SectionOutput, SuiteContext};
use crate::Result;

/// The scenes measured.
const SCENES: [&str; 2] = ["cubes", "showcase-skin"];

/// Measures FXAA on `cubes` and `showcase-skin` at the suite's size.
pub fn antialias_section(ctx: &SuiteContext<'_>) -> Result<SectionOutput> {
    let o = ctx.options;
    let mut out = SectionOutput::default();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "## Anti-aliasing: FXAA\n\n{}x{}, {} frames after {} warm-up, alternating with the same \
         frame without FXAA; *changed*: pixels FXAA moved (any channel).\n\n\
         | scene | fxaa pass (ms) | frame without / with (ms) | share of the frame | changed |\n\
         |---|---:|---:|---:|---:|",
        o.width, o.height, o.frames, o.warmup
    );
    for name in SCENES {
        let scene = load_scene_baked(name)?;
        let base = FrameSettings::new(o.width, o.height);
        let build = |antialias| {
            Renderer::new(
                ctx.gpu,
                ctx.shaders,
                ctx.pipeline_cache,
                &scene,
                FrameSettings { antialias, ..base },
            )
        };
        let off = build(Antialias::Off)?;
        let on = match build(Antialias::Fxaa) {
            Ok(r) => r,
            Err(e) => {
                off.destroy(ctx.gpu);
                return Err(e);
            }
        };
        let measured = (|| {
            let compared = bench::compare(
                ctx.gpu,
                [("off", &off), ("fxaa", &on)],
                &scene,
                o.frames,
                o.warmup,
            )?;
            let plain = off.read_display(ctx.gpu)?;
            let smoothed = on.read_display(ctx.gpu)?;
            Ok::<_, crate::LucentError>((compared, plain, smoothed))
        })();
        let idle = ctx.gpu.wait_idle();
        off.destroy(ctx.gpu);
        on.destroy(ctx.gpu);
        idle?;
        let (compared, plain, smoothed) = measured?;
        let fxaa = compared
            .passes
            .iter()
            .find(|(pass, _)| pass == "fxaa")
            .and_then(|(_, sides)| sides[1])
            .map_or(0.0, |s| s.median);
        let [without, with] = compared.frame.map(|s| s.median);
        let changed = plain
            .chunks_exact(4)
            .zip(smoothed.chunks_exact(4))
            .filter(|(a, b)| a[..3] != b[..3])
            .count() as f64
            / (plain.len() / 4).max(1) as f64;
        let share = fxaa / with.max(1e-9);
        let _ = writeln!(
            md,
            "| `{name}` | {fxaa:.2} | {without:.2} / {with:.2} | {:.1}% | {:.1}% |",
            100.0 * share,
            100.0 * changed
        );
        out.summary.push(format!(
            "FXAA on `{name}`: {:.1}% of the frame ({fxaa:.2} ms), {:.1}% of pixels changed",
            100.0 * share,
            100.0 * changed
        ));
    }
    let _ = writeln!(
        md,
        "\nOff by default: see docs/antialias.md (the same pass against its f64 twin, and why)."
    );
    out.markdown = md;
    Ok(out)
}
