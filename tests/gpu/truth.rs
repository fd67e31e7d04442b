//! lucent against the path-traced truth: the truths committed in `tools/truth/truths/` (Mitsuba
//! 3 `volpath` renders of the scenes in `tools/truth/scenes/`, 160x120, their sample counts and
//! noise in each truth's JSON; `tools/truth/README.md`) compared with lucent's linear HDR frame
//! of the same scene, as `tools/truth/compare.py` compares them, so no Mitsuba is needed here:
//! the relative mean absolute error `sum |L - T| / sum T` over the pixels every camera ray of
//! the truth's coverage render hit (eroded one pixel: silhouettes of a tessellated mesh and an
//! analytic shape differ by a fraction of a pixel), and the energy `sum L / sum T` per channel.
//!
//! Each case holds lucent at most a little above today's error (a change that moves a frame
//! away from the truth fails here) and its energy inside the range that says what the
//! technique gets right today. Improving a technique lowers these numbers: tighten the case
//! with the measured values (printed with `--nocapture`) and say so in the commit.

use std::path::{Path, PathBuf};

use lucent::frame::{FrameSettings, Technique};

use crate::common::TestGpu;

/// The truths' frame size (`tools/truth/validate.sh`'s default).
const SIZE: (usize, usize) = (160, 120);

/// How much above its recorded error a case may go: a tenth of the truths' per-pixel noise
/// (0.07) in the mean over thousands of pixels is far less; this is for lucent's own drift
/// (driver versions, float order), not a licence to get worse.
const ERROR_SLACK: f64 = 0.01;

fn truth_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/truth")
}

/// A linear RGB(A) EXR as RGBA f32 rows, with its size.
fn read_exr(path: &Path) -> (usize, usize, Vec<f32>) {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (w, h) = (image.width() as usize, image.height() as usize);
    (w, h, image.to_rgba32f().into_raw())
}

/// The truth's object pixels: fully covered (every ray hit), less `erode` pixels at the edge.
fn object_mask(coverage: &[f32], w: usize, h: usize, erode: usize) -> Vec<bool> {
    let mut mask: Vec<bool> = (0..w * h).map(|i| coverage[i * 4] >= 0.999).collect();
    for _ in 0..erode {
        let inside = |x: i64, y: i64, m: &[bool]| {
            x >= 0
                && y >= 0
                && (x as usize) < w
                && (y as usize) < h
                && m[y as usize * w + x as usize]
        };
        mask = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as i64, (i / w) as i64);
                (-1..=1).all(|dy| (-1..=1).all(|dx| inside(x + dx, y + dy, &mask)))
            })
            .collect();
    }
    mask
}

/// One comparison: a truth scene under a technique, and what lucent must hold against it.
struct Case {
    scene: &'static str,
    technique: Technique,
    /// Today's error against the truth; the case fails above it plus [`ERROR_SLACK`].
    error: f64,
    /// The energy per channel must stay inside this range (all three channels).
    energy: (f64, f64),
    /// What the numbers say.
    why: &'static str,
}

fn cases() -> Vec<Case> {
    vec![
        Case {
            scene: "diffuse-sphere",
            technique: Technique::None,
            error: 0.0006,
            energy: (0.995, 1.005),
            why: "a lone Lambertian sphere under a point light: lucent's shading is exact, so \
                  this holds the conventions (camera, transforms, light units) to the truth",
        },
        Case {
            scene: "skin1-slab-backlit",
            technique: Technique::Auto,
            error: 0.385,
            energy: (0.25, 1.2),
            why: "a 4 mm skin1 slab lit from behind: the layered medium lets through 71% of the \
                  truth's red, 34% of its green and 28% of its blue with the dipole's diffusion \
                  through the thickness (22-26% without it; it once let through none)",
        },
        Case {
            scene: "marble-sphere-sidelit",
            technique: Technique::Auto,
            error: 0.166,
            energy: (1.0, 1.2),
            why: "Li et al.'s layered marble, side-lit: 11-15% too bright",
        },
        Case {
            scene: "marble-sphere-sidelit",
            technique: Technique::None,
            error: 0.148,
            energy: (0.8, 0.9),
            why: "plain Lambert with the medium's total diffuse reflectance as albedo: 13-15% \
                  too dark, the light the truth carries past the terminator",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: Technique::None,
            error: 0.106,
            energy: (0.85, 0.95),
            why: "the same marble given as one [material.medium]: plain Lambert with the \
                  derived albedo (the medium's total diffuse reflectance)",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: Technique::Auto,
            error: 0.114,
            energy: (1.0, 1.1),
            why: "the medium as Li et al.'s layered material (what `auto` renders a medium \
                  with): 5-7% too bright",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: technique("separable"),
            error: 0.101,
            energy: (0.85, 0.95),
            why: "the separable blur with six Gaussians fitted to the medium's dipole: at \
                  0.35 mm per pixel the kernel softens the terminator and carries little past it",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: technique("burley"),
            error: 0.106,
            energy: (0.85, 0.95),
            why: "Burley's normalized diffusion from the medium's mean free path and R_d",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: Technique::None,
            error: 0.389,
            energy: (0.5, 0.7),
            why: "a skin1 sphere as one [material.medium], plain Lambert with its R_d: 36-45% \
                  too dark, the light skin1 carries millimetres past the terminator",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: Technique::Auto,
            error: 0.216,
            energy: (0.85, 1.0),
            why: "the skin1 medium as Li et al.'s layered material: 5-9% too dark",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: technique("separable"),
            error: 0.376,
            energy: (0.5, 0.7),
            why: "the separable blur of the Gaussians fitted to skin1's dipole: a little of \
                  the wrap, at 0.35 mm per pixel",
        },
    ]
}

/// A registered technique by name.
fn technique(name: &str) -> Technique {
    Technique::parse(name).unwrap_or_else(|e| panic!("{name}: {e}"))
}

#[test]
fn lucent_stays_within_its_recorded_distance_of_the_path_traced_truth() {
    let test = TestGpu::new();
    let mut failures = Vec::new();
    for case in cases() {
        let dir = truth_dir();
        let scene_path = dir.join(format!("scenes/{}.toml", case.scene));
        let scene = lucent::scene::load_scene(scene_path.to_str().unwrap())
            .unwrap_or_else(|e| panic!("{e}"));
        let (tw, th, truth) = read_exr(&dir.join(format!("truths/{}.exr", case.scene)));
        let (cw, ch, coverage) = read_exr(&dir.join(format!("truths/{}.coverage.exr", case.scene)));
        assert_eq!((tw, th), SIZE, "{}: the truth's size", case.scene);
        assert_eq!((cw, ch), SIZE, "{}: the coverage's size", case.scene);
        let mask = object_mask(&coverage, tw, th, 1);
        let pixels = mask.iter().filter(|&&m| m).count();
        assert!(pixels > 1000, "{}: {pixels} object pixels", case.scene);
        let settings = FrameSettings {
            technique: case.technique,
            export_hdr: true,
            ..FrameSettings::new(tw as u32, th as u32)
        };
        let frame = test.render(&scene, settings).hdr.unwrap();
        let (mut diff, mut total) = (0.0f64, 0.0f64);
        let (mut lucent_sum, mut truth_sum) = ([0.0f64; 3], [0.0f64; 3]);
        for i in (0..tw * th).filter(|&i| mask[i]) {
            for c in 0..3 {
                let (l, t) = (f64::from(frame[i * 4 + c]), f64::from(truth[i * 4 + c]));
                assert!(l.is_finite(), "{}: lucent pixel {i}: {l}", case.scene);
                diff += (l - t).abs();
                total += t;
                lucent_sum[c] += l;
                truth_sum[c] += t;
            }
        }
        let error = diff / total;
        let energy: Vec<f64> = (0..3).map(|c| lucent_sum[c] / truth_sum[c]).collect();
        println!(
            "{} under {:?}: error {error:.4} (recorded {}), energy {energy:.4?} over {pixels} px",
            case.scene, case.technique, case.error
        );
        if error > case.error + ERROR_SLACK {
            failures.push(format!(
                "{} under {:?}: error {error:.4} against the truth, recorded {} ({})",
                case.scene, case.technique, case.error, case.why
            ));
        }
        if energy
            .iter()
            .any(|&e| !(case.energy.0..=case.energy.1).contains(&e))
        {
            failures.push(format!(
                "{} under {:?}: energy {energy:.4?} outside {:?} ({})",
                case.scene, case.technique, case.energy, case.why
            ));
        }
    }
    test.finish();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
