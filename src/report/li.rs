//! Error against run time for Li et al.'s layered passes: `lucent report li --out DIR`.
//!
//! Every knob of the technique ([`KNOBS`]: march steps `K`, pixel lights `M`, the light-space
//! map resolution, the phase function, the layer count, the irradiance and the multiple
//! scattering gather resolutions) is turned
//! one at a time from the defaults, and each variant is measured two ways:
//! - **error**: the term of eq. 3 the knob changes, alone (its weight 1, the others 0), on the
//!   comparison sphere ([`crate::measure::layered_error::sphere_scene`] under
//!   [`comparison_lights`]) at a small size, as the relative L1 error against the f64
//!   reference ([`crate::measure::layered_error::term_error`]);
//! - **time**: the same sphere with every term on, at the report's size, technique `auto`,
//!   subpasses unmerged ([`crate::measure::scaling::settings`]); all variants in one
//!   round-robin run ([`crate::measure::scaling::measure`]), so a shared, noisy machine slows
//!   every variant alike. The cost is the sum of the medians of the three layered passes
//!   ([`LAYERED_PASSES`], multiple scattering's with the blur of its term); the frame median
//!   is printed beside it.
//!
//! Identical configurations (a knob's default is every knob's default) are rendered and timed
//! once and shared by their rows. Writes `li.md` and `li-error-vs-time.png`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::features::layered::{LayeredKnobs, PhaseForm};
use crate::frame::{FrameSettings, Technique};
use crate::measure::layered_error::{
    clear_medium, comparison_lights, sphere_scene, term_error_against, Term, TermError,
};
use crate::measure::scaling::{Config, Measured};
use crate::report::plot::{write_scatter_png, PlotPoint, PlotSeries};
use crate::scene::layered::{Layer, LayeredMedium, Thickness};
use crate::{LucentError, Result};

/// The passes whose medians make a variant's cost, one column each.
pub const LAYERED_PASSES: [&str; 3] = [
    "layered irradiance",
    "single scattering",
    "multiple scattering",
];

/// Passes a column's time includes beside the one it is named after: the blur of the gathered
/// term is multiple scattering's (it runs only to finish that term).
const COLUMN_EXTRAS: [(&str, &str); 1] = [("multiple scattering", "multiple scattering blur")];

/// The median of pass `column` in `m` plus those of the passes counted with it (multiple
/// scattering's with `multiple scattering blur`, each when the frame has it); `None` when the
/// frame has no `column` pass.
pub fn column_ms(m: &Measured, column: &str) -> Option<f64> {
    let extras: f64 = COLUMN_EXTRAS
        .iter()
        .filter(|(c, _)| *c == column)
        .filter_map(|(_, extra)| m.pass_ms(extra))
        .sum();
    m.pass_ms(column).map(|ms| ms + extras)
}

/// Every knob the report turns, in order (the Markdown names each).
pub const KNOBS: [&str; 7] = [
    "march steps K",
    "pixel lights M",
    "light-map resolution",
    "phase function",
    "layer count",
    "irradiance resolution",
    "gather resolution",
];

/// The light-map resolution's second series: the transmitted term on the clear medium.
pub const MAPS_TRANSMITTED: &str = "light-map resolution, transmitted";

/// The light-space map size of every variant that does not turn that knob (the layered tests'
/// size, at which their tolerances were measured).
pub const BASE_MAP_SIZE: u32 = 512;

/// The forward-scattering `g` of the phase-function comparison.
pub const PHASE_G: f32 = 0.7;

/// Thickness of the top material of the layer-count stack, mm.
pub const STACK_TOP_MM: f32 = 0.3;

/// How much the report measures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiOptions {
    /// Timing frame size.
    pub width: u32,
    /// Timing frame size.
    pub height: u32,
    /// Measured rounds.
    pub rounds: usize,
    /// Discarded rounds first.
    pub warmup: usize,
    /// Fewer variants per knob.
    pub quick: bool,
    /// Error frame size (square).
    pub error_size: u32,
    /// Every `error_stride`-th pixel compared.
    pub error_stride: u32,
}

impl LiOptions {
    /// The default run: 256x256, 15 rounds after 3 warm-up, every variant.
    pub fn full() -> Self {
        Self {
            width: 256,
            height: 256,
            rounds: 15,
            warmup: 3,
            quick: false,
            error_size: 96,
            error_stride: 3,
        }
    }

    /// `--quick`: 128x128, 7 rounds after 2 warm-up, fewer variants.
    pub fn quick() -> Self {
        Self {
            width: 128,
            height: 128,
            rounds: 7,
            warmup: 2,
            quick: true,
            ..Self::full()
        }
    }
}

/// One configuration to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct LiVariant {
    /// Which knob it turns (one of [`KNOBS`], or [`MAPS_TRANSMITTED`]; the plot's series).
    pub knob: &'static str,
    /// Its setting.
    pub name: String,
    /// The sphere's medium.
    pub medium: LayeredMedium,
    /// The medium as the table names it.
    pub medium_label: String,
    /// The term whose error is measured.
    pub term: Term,
    /// The layered knobs.
    pub layered: LayeredKnobs,
    /// The light-space map size (texels per face).
    pub map_size: u32,
    /// The phase function the reference evaluates (true HG for the Schlick variant: the
    /// approximation's error).
    pub reference_phase: PhaseForm,
}

impl LiVariant {
    fn settings(&self, mut settings: FrameSettings) -> FrameSettings {
        settings.layered = self.layered;
        settings.shadows.enabled = true;
        settings.shadows.size = self.map_size;
        settings
    }

    /// The error frame's settings.
    pub fn error_settings(&self, size: u32) -> FrameSettings {
        self.settings(FrameSettings::new(size, size))
    }

    /// The timing frame's settings: technique `auto`, unmerged.
    pub fn timing_settings(&self, width: u32, height: u32) -> FrameSettings {
        self.settings(crate::measure::scaling::settings(
            Technique::Auto,
            width,
            height,
        ))
    }
}

/// What one variant measured.
#[derive(Clone, Debug, PartialEq)]
pub struct LiResult {
    /// The variant.
    pub variant: LiVariant,
    /// Its term against the reference.
    pub error: TermError,
    /// The Schlick variant: its error against a Schlick reference too (the implementation's
    /// share of the error).
    pub own_form_error: Option<f64>,
    /// Medians of [`LAYERED_PASSES`], ms (`None`: the frame has no such pass).
    pub passes_ms: [Option<f64>; 3],
    /// Frame median (submit to fence), ms.
    pub frame_ms: f64,
    /// Triangles drawn per frame.
    pub triangles: u64,
}

impl LiResult {
    /// The cost: the sum of the three passes' medians; `None` when one is missing or the sum
    /// is not a positive finite number.
    pub fn layered_ms(&self) -> Option<f64> {
        sum_positive(self.passes_ms)
    }
}

/// The sum of the medians of [`LAYERED_PASSES`] in `m`; `None` when one is missing or the sum
/// is not a positive finite number.
pub fn layered_sum(m: &Measured) -> Option<f64> {
    sum_positive(LAYERED_PASSES.map(|p| column_ms(m, p)))
}

fn sum_positive(parts: [Option<f64>; 3]) -> Option<f64> {
    let mut sum = 0.0;
    for p in parts {
        sum += p?;
    }
    (sum.is_finite() && sum > 0.0).then_some(sum)
}

/// Li et al.'s teapot medium in lucent's `scaling:N` (Jensen's skin1).
fn skin1() -> LayeredMedium {
    LayeredMedium::preset("skin1").expect("a preset")
}

/// Jensen's skin1 with forward scattering `g` (the presets are isotropic; the reduced
/// coefficients are kept, so `sigma_s = sigma_s' / (1 - g)`).
pub fn forward_medium(g: f32) -> LayeredMedium {
    let (_, sp, sa) = crate::scene::layered::JENSEN_2001
        .iter()
        .find(|p| p.0 == "skin1")
        .copied()
        .expect("skin1 is a Jensen 2001 medium");
    LayeredMedium::homogeneous(
        &format!("skin1 g = {g}"),
        Vec3::from(sp),
        Vec3::from(sa),
        g,
        1.3,
    )
}

/// The top and rest materials of the layer-count stack (a forward-scattering epidermis-like
/// top over a clearer rest, the layered tests' two layers).
fn stack_materials() -> (Layer, Layer) {
    (
        Layer {
            sigma_a: Vec3::new(0.2, 0.4, 0.8),
            sigma_s: Vec3::new(6.0, 7.0, 9.0),
            g: PHASE_G,
            thickness: Thickness::Mm(STACK_TOP_MM),
        },
        Layer {
            sigma_a: Vec3::new(0.01, 0.03, 0.1),
            sigma_s: Vec3::new(1.5, 2.0, 2.5),
            g: 0.0,
            thickness: Thickness::Rest,
        },
    )
}

/// The stack in `n` layers: the top material's [`STACK_TOP_MM`] divided into `n - 1` identical
/// sub-layers over the rest; `n = 1` is the rest material alone (no top).
pub fn stack_medium(n: usize) -> LayeredMedium {
    let (top, rest) = stack_materials();
    let mut m = LayeredMedium::preset("apple").expect("a preset");
    m.name = format!("stack of {n}");
    m.layers = (1..n)
        .map(|_| Layer {
            thickness: Thickness::Mm(STACK_TOP_MM / (n - 1) as f32),
            ..top
        })
        .chain([rest])
        .collect();
    m
}

/// Every variant: one knob at a time from the defaults (quick: fewer settings per knob).
pub fn li_variants(quick: bool) -> Vec<LiVariant> {
    let defaults = LayeredKnobs::default();
    let base = |knob, name: String, medium: LayeredMedium, label: &str, term| LiVariant {
        knob,
        name,
        medium,
        medium_label: label.to_string(),
        term,
        layered: defaults,
        map_size: BASE_MAP_SIZE,
        reference_phase: defaults.phase,
    };
    let pick = |full: &[u32], quick_list: &[u32]| -> Vec<u32> {
        if quick {
            quick_list.to_vec()
        } else {
            full.to_vec()
        }
    };
    let mut v = Vec::new();
    for k in pick(&[1, 2, 4, 8, 16, 32, 64], &[1, 4, 8, 64]) {
        let mut x = base(KNOBS[0], format!("K = {k}"), skin1(), "skin1", Term::Single);
        x.layered.steps = k;
        v.push(x);
    }
    for m in pick(&[4, 8, 12, 24, 48, 64], &[4, 12, 64]) {
        let mut x = base(
            KNOBS[1],
            format!("M = {m}"),
            skin1(),
            "skin1",
            Term::Multiple,
        );
        x.layered.pixel_lights = m;
        v.push(x);
    }
    let maps = pick(&[128, 256, 512, 1024], &[256, 1024]);
    for &size in &maps {
        let mut x = base(
            KNOBS[2],
            format!("{size}^2 maps"),
            skin1(),
            "skin1",
            Term::Single,
        );
        x.map_size = size;
        v.push(x);
    }
    for &size in &maps {
        let mut x = base(
            MAPS_TRANSMITTED,
            format!("{size}^2 maps"),
            clear_medium(),
            "clear",
            Term::Transmitted,
        );
        x.map_size = size;
        v.push(x);
    }
    for (name, phase) in PhaseForm::ALL {
        let mut x = base(
            KNOBS[3],
            format!("{name} (against HG)"),
            forward_medium(PHASE_G),
            &format!("skin1, g = {PHASE_G}"),
            Term::Single,
        );
        x.layered.phase = *phase;
        v.push(x);
    }
    let layers: &[usize] = if quick { &[1, 4, 8] } else { &[1, 2, 4, 8] };
    for &n in layers {
        v.push(base(
            KNOBS[4],
            format!("{n} layer{}", if n == 1 { "" } else { "s" }),
            stack_medium(n),
            &format!("stack of {n}"),
            Term::Single,
        ));
    }
    for half in [false, true] {
        let mut x = base(
            KNOBS[5],
            if half { "half" } else { "full" }.to_string(),
            skin1(),
            "skin1",
            Term::Multiple,
        );
        x.layered.half_irradiance = half;
        v.push(x);
    }
    for half in [false, true] {
        let mut x = base(
            KNOBS[6],
            if half { "half" } else { "full" }.to_string(),
            skin1(),
            "skin1",
            Term::Multiple,
        );
        x.layered.half_gather = half;
        v.push(x);
    }
    v
}

/// Position of `item` in `list`, appended when new.
fn index_of<T: PartialEq>(list: &mut Vec<T>, item: T) -> usize {
    match list.iter().position(|x| *x == item) {
        Some(i) => i,
        None => {
            list.push(item);
            list.len() - 1
        }
    }
}

/// Measures every variant: errors at the options' error size, then all timing configurations
/// in one round-robin run. Prints one progress line per error computed to stderr.
pub fn run(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    variants: &[LiVariant],
    opts: &LiOptions,
) -> Result<Vec<LiResult>> {
    if opts.rounds == 0 {
        return Err(LucentError::InvalidInput(
            "report: --rounds must be at least 1".into(),
        ));
    }
    let started = Instant::now();
    // Errors: each distinct (medium, settings, term, reference phase) once.
    type ErrorKey = (LayeredMedium, FrameSettings, Term, PhaseForm);
    let mut keys: Vec<ErrorKey> = Vec::new();
    let mut error_of = Vec::with_capacity(variants.len());
    let mut own_of = Vec::with_capacity(variants.len());
    for v in variants {
        let settings = v.error_settings(opts.error_size);
        error_of.push(index_of(
            &mut keys,
            (v.medium.clone(), settings, v.term, v.reference_phase),
        ));
        own_of.push((v.layered.phase != v.reference_phase).then(|| {
            index_of(
                &mut keys,
                (v.medium.clone(), settings, v.term, v.layered.phase),
            )
        }));
    }
    let mut errors = Vec::with_capacity(keys.len());
    for (i, (medium, settings, term, phase)) in keys.iter().enumerate() {
        let scene = sphere_scene(medium.clone(), comparison_lights())?;
        let e = term_error_against(
            gpu,
            shaders,
            cache,
            &scene,
            settings,
            *term,
            opts.error_stride,
            *phase,
        )?;
        eprintln!(
            "report li: [{}/{}] error of {} ({}): relative L1 {:.4} ({:.0} s so far)",
            i + 1,
            keys.len(),
            term.name(),
            medium.name,
            e.relative_l1,
            started.elapsed().as_secs_f64()
        );
        errors.push(e);
    }
    // Times: each distinct (medium, settings) once, all in one round-robin run.
    let mut timing_keys: Vec<(LayeredMedium, FrameSettings)> = Vec::new();
    let timing_of: Vec<usize> = variants
        .iter()
        .map(|v| {
            index_of(
                &mut timing_keys,
                (v.medium.clone(), v.timing_settings(opts.width, opts.height)),
            )
        })
        .collect();
    let mut configs = Vec::with_capacity(timing_keys.len());
    for (i, (medium, settings)) in timing_keys.iter().enumerate() {
        configs.push(Config {
            label: format!("{i}"),
            x: i as f64,
            scene: sphere_scene(medium.clone(), comparison_lights())?,
            settings: *settings,
        });
    }
    eprintln!(
        "report li: timing {} configurations round-robin, {} rounds after {} warm-up ({:.0} s \
         so far)",
        configs.len(),
        opts.rounds,
        opts.warmup,
        started.elapsed().as_secs_f64()
    );
    let measured: Vec<Measured> = crate::measure::scaling::measure(
        gpu,
        shaders,
        cache,
        &configs,
        opts.rounds,
        opts.warmup,
        |_, _| {},
    )?;
    Ok(variants
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let m = &measured[timing_of[i]];
            LiResult {
                variant: v.clone(),
                error: errors[error_of[i]],
                own_form_error: own_of[i].map(|k| errors[k].relative_l1),
                passes_ms: LAYERED_PASSES.map(|p| column_ms(m, p)),
                frame_ms: m.frame.median,
                triangles: m.triangles,
            }
        })
        .collect())
}

/// `x` with `digits` decimals, or "-" when it is not a finite number (or `positive` and not
/// above 0).
fn num(x: Option<f64>, digits: usize, positive: bool) -> String {
    match x {
        Some(v) if v.is_finite() && (!positive || v > 0.0) => format!("{v:.digits$}"),
        _ => "-".into(),
    }
}

/// The report as Markdown.
pub fn markdown(results: &[LiResult], opts: &LiOptions, device: &str) -> String {
    let mut out = String::new();
    let defaults = LayeredKnobs::default();
    let triangles = results.first().map_or(0, |r| r.triangles);
    let _ = writeln!(
        out,
        "# Li et al.'s layered scattering: error against run time\n\n\
         - device: {device}\n\
         - error: the term the knob changes, alone (its weight in eq. 3 set to 1, the others to \
         0, no ambient), on the comparison sphere (`sphere_scene`: an icosphere of 5,120 \
         triangles, radius 0.5, two point lights, `comparison_lights`) at {e}x{e}, every \
         {s}{nd} pixel of the sphere's interior; relative L1 `sum |GPU - ref| / sum ref` \
         against the f64 reference (`crate::reference::layered`: single scattering in 256 steps \
         to the GPU's D_max, multiple scattering over the whole surface, the transmitted term \
         ray-traced)\n\
         - time: the same sphere with every term on ({triangles} triangles), {w}x{h}, technique \
         `auto`, subpasses unmerged, {r} rounds round-robin after {wu} warm-up, every \
         configuration in one run; \"layered ms\" is the sum of the medians of `{p0}`, `{p1}` \
         and `{p2}` (with `multiple scattering blur`, the blur of its term); frame: submit to \
         fence\n\
         - defaults where a row does not turn the knob: K = {k}, M = {m}, {phase}, \
         full-resolution irradiance, {gather} gather, {map}^2-texel light-space maps, D_max = \
         {d} mean free paths\n\
         - media: skin1 (Jensen's, Li et al.'s teapot medium; isotropic), clear (a medium that \
         lets e^-1.5 through the sphere: its transmitted term is large), skin1 with g = {g} \
         (reduced coefficients kept), and the stack (a top of sigma_s (6, 7, 9), sigma_a \
         (0.2, 0.4, 0.8) mm^-1, g = {g}, {top} mm thick, over a rest of sigma_s (1.5, 2, 2.5), \
         sigma_a (0.01, 0.03, 0.1) mm^-1, g = 0): n layers are the top in n - 1 identical \
         sub-layers over the rest, 1 layer is the rest alone; each against its own medium's \
         reference, so the layer count's cost is the layer loop's\n\
         - generated by `lucent report li --out DIR --size {w}x{h} --rounds {r} --warmup {wu}{q}`\n",
        gather = if LayeredKnobs::default().half_gather {
            "half-resolution"
        } else {
            "full-resolution"
        },
        e = opts.error_size,
        s = opts.error_stride,
        nd = match opts.error_stride {
            1 => "st",
            2 => "nd",
            3 => "rd",
            _ => "th",
        },
        w = opts.width,
        h = opts.height,
        r = opts.rounds,
        wu = opts.warmup,
        p0 = LAYERED_PASSES[0],
        p1 = LAYERED_PASSES[1],
        p2 = LAYERED_PASSES[2],
        k = defaults.steps,
        m = defaults.pixel_lights,
        phase = defaults.phase.name(),
        map = BASE_MAP_SIZE,
        d = defaults.max_depth_mfp,
        g = PHASE_G,
        top = STACK_TOP_MM,
        q = if opts.quick { " --quick" } else { "" },
    );
    let _ = writeln!(
        out,
        "| knob | variant | medium | term | relative L1 | pixels | layered ms | irradiance ms | \
         single ms | multiple ms | frame ms |\n\
         |---|---|---|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for r in results {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.variant.knob,
            r.variant.name,
            r.variant.medium_label,
            r.variant.term.name(),
            num(Some(r.error.relative_l1), 4, false),
            r.error.pixels,
            num(r.layered_ms(), 3, true),
            num(r.passes_ms[0], 3, true),
            num(r.passes_ms[1], 3, true),
            num(r.passes_ms[2], 3, true),
            num(Some(r.frame_ms), 3, true),
        );
    }
    // The phase function: the f64 difference and the GPU's two errors.
    let (max, mean) = crate::reference::layered::phase_difference(f64::from(PHASE_G));
    let _ = writeln!(
        out,
        "\n**Phase function** at g = {PHASE_G}: Schlick's form against true Henyey-Greenstein \
         in f64 (`phase_difference`): largest difference {max:.4} /sr, mean {mean:.4} /sr over \
         cos theta in [-1, 1]."
    );
    if let Some(s) = results
        .iter()
        .find(|r| r.variant.knob == KNOBS[3] && r.own_form_error.is_some())
    {
        let _ = writeln!(
            out,
            "Schlick's single scattering on the GPU: relative L1 {} against the HG reference \
             (what the approximation costs; mean {} against HG's {}) and {} against a Schlick \
             reference (the implementation's share).",
            num(Some(s.error.relative_l1), 4, false),
            num(Some(s.error.gpu_mean), 5, false),
            num(Some(s.error.reference_mean), 5, false),
            num(s.own_form_error, 4, false),
        );
    }
    // Per knob: first and last variant.
    out.push_str("\nPer knob, from its first variant to its last:\n\n");
    let mut knobs: Vec<&str> = Vec::new();
    for r in results {
        if !knobs.contains(&r.variant.knob) {
            knobs.push(r.variant.knob);
        }
    }
    for knob in knobs {
        let rows: Vec<&LiResult> = results.iter().filter(|r| r.variant.knob == knob).collect();
        let (Some(a), Some(b)) = (rows.first(), rows.last()) else {
            continue;
        };
        let _ = writeln!(
            out,
            "- {knob}: {} -> {}: error {} -> {}, layered {} -> {} ms, frame {} -> {} ms",
            a.variant.name,
            b.variant.name,
            num(Some(a.error.relative_l1), 4, false),
            num(Some(b.error.relative_l1), 4, false),
            num(a.layered_ms(), 3, true),
            num(b.layered_ms(), 3, true),
            num(Some(a.frame_ms), 3, true),
            num(Some(b.frame_ms), 3, true),
        );
    }
    out.push_str(
        "\nThe layered passes draw only the screen rectangles the sphere may cover. The \
         light-map rows change the light-space maps, so their frame time moves with the maps \
         pass, which \"layered ms\" leaves out. Times on lavapipe (a CPU driver) rank the knobs; \
         they say nothing of a GPU's absolute costs (docs/lavapipe-facts.md).\n",
    );
    out
}

/// Runs the report and writes `li.md` and `li-error-vs-time.png` into `dir`. Returns the
/// Markdown and the files written.
pub fn write_li_report(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    cache: &PipelineCache,
    dir: &Path,
    opts: &LiOptions,
) -> Result<(String, Vec<PathBuf>)> {
    let results = run(gpu, shaders, cache, &li_variants(opts.quick), opts)?;
    let text = markdown(&results, opts, &gpu.info.describe());
    std::fs::create_dir_all(dir).map_err(|e| LucentError::file(dir, e))?;
    let md = dir.join("li.md");
    crate::files::write_file_atomic(&md, text.as_bytes())?;
    let mut series: Vec<PlotSeries> = Vec::new();
    for r in &results {
        let Some(x) = r.layered_ms() else {
            continue;
        };
        if !(r.error.relative_l1.is_finite() && r.error.relative_l1 > 0.0) {
            continue;
        }
        let point = PlotPoint {
            label: r.variant.name.clone(),
            x,
            y: r.error.relative_l1,
        };
        match series.iter_mut().find(|s| s.name == r.variant.knob) {
            Some(s) => s.points.push(point),
            None => series.push(PlotSeries {
                name: r.variant.knob.into(),
                points: vec![point],
            }),
        }
    }
    let png = dir.join("li-error-vs-time.png");
    write_scatter_png(
        &png,
        "Li et al.'s layered passes: error against time",
        &format!("layered passes ms (sphere, {}x{})", opts.width, opts.height),
        "relative L1 against the f64 reference",
        &series,
        true,
    )?;
    Ok((text, vec![md, png]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_knob_has_variants_and_the_quick_set_is_smaller() {
        let (full, quick) = (li_variants(false), li_variants(true));
        assert!(quick.len() < full.len());
        for knob in KNOBS {
            assert!(
                full.iter().filter(|v| v.knob == knob).count() >= 2,
                "{knob}"
            );
            assert!(
                quick.iter().filter(|v| v.knob == knob).count() >= 2,
                "{knob}"
            );
        }
        for v in &full {
            v.medium.validate().unwrap();
        }
    }

    #[test]
    fn the_stack_keeps_its_total_thickness() {
        for n in [2, 4, 8] {
            let m = stack_medium(n);
            assert_eq!(m.layers.len(), n);
            let total: f32 = (0..n - 1).map(|i| m.thickness_mm(i, &[])).sum();
            assert!((total - STACK_TOP_MM).abs() < 1e-6, "{n}: {total}");
            assert_eq!(m.layers[n - 1].thickness, Thickness::Rest);
        }
        assert_eq!(stack_medium(1).layers.len(), 1);
    }

    #[test]
    fn missing_passes_give_no_cost() {
        let v = li_variants(true).remove(0);
        let mut r = LiResult {
            variant: v,
            error: TermError {
                term: Term::Single,
                pixels: 1,
                relative_l1: 0.1,
                gpu_mean: 0.0,
                reference_mean: 0.0,
                frame_ms: 0.0,
            },
            own_form_error: None,
            passes_ms: [Some(1.0), Some(2.0), None],
            frame_ms: 5.0,
            triangles: 0,
        };
        assert_eq!(r.layered_ms(), None);
        r.passes_ms[2] = Some(0.5);
        assert_eq!(r.layered_ms(), Some(3.5));
        let text = markdown(&[r.clone()], &LiOptions::quick(), "llvmpipe");
        assert!(text.contains("| 3.500 |"), "{text}");
        r.passes_ms = [Some(0.0); 3];
        let text = markdown(&[r], &LiOptions::quick(), "llvmpipe");
        assert!(!text.contains("NaN") && text.contains("| - |"), "{text}");
    }

    #[test]
    fn multiple_scatterings_column_counts_the_blur_of_its_term() {
        let stats = |median| crate::measure::stats::Stats {
            median,
            min: median,
            max: median,
        };
        let mut m = Measured {
            label: String::new(),
            x: 0.0,
            passes: vec![
                ("layered irradiance".into(), stats(1.0)),
                ("multiple scattering".into(), stats(2.0)),
                ("multiple scattering blur".into(), stats(0.5)),
                ("single scattering".into(), stats(4.0)),
            ],
            frame: stats(10.0),
            triangles: 0,
        };
        assert_eq!(column_ms(&m, "multiple scattering"), Some(2.5));
        assert_eq!(column_ms(&m, "single scattering"), Some(4.0));
        assert_eq!(layered_sum(&m), Some(7.5));
        // A frame without the blur (or without the gather) is measured as it is.
        m.passes.remove(2);
        assert_eq!(column_ms(&m, "multiple scattering"), Some(2.0));
        m.passes.remove(1);
        assert_eq!(column_ms(&m, "multiple scattering"), None);
    }
}
