//! lucent against the path-traced truth: the truths committed in `tools/truth/truths/` (Mitsuba
//! 3 `volpath` renders of the scenes in `tools/truth/scenes/`, their sample counts and noise in
//! each truth's JSON; `tools/truth/README.md`) compared with lucent's linear HDR frame of the
//! same scene by [`lucent::measure::truth`], as `tools/truth/compare.py` compares them, so no
//! Mitsuba is needed here: the relative mean absolute error `sum |L - T| / sum T` over the
//! object's pixels, and the energy `sum L / sum T` per channel.
//!
//! Each case holds lucent at most a little above today's error (a change that moves a frame
//! away from the truth fails here) and its energy inside the range that says what the
//! technique gets right today. Improving a technique lowers these numbers: tighten the case
//! with the measured values (printed with `--nocapture`) and say so in the commit.

use std::path::{Path, PathBuf};

use lucent::frame::{FrameSettings, Technique};
use lucent::measure::truth::{load_truth, measure};

use crate::common::TestGpu;

/// How much above its recorded error a case may go: a tenth of the truths' per-pixel noise
/// (0.07) in the mean over thousands of pixels is far less; this is for lucent's own drift
/// (driver versions, float order), not a licence to get worse.
const ERROR_SLACK: f64 = 0.01;

fn truth_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/truth")
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
            why: "a lone Lambertian sphere under a point light: lucent's shading is exact, so this holds the conventions (camera, transforms, light units) to the truth",
        },
        Case {
            scene: "skin1-slab-backlit",
            technique: Technique::Auto,
            error: 0.406,
            energy: (0.2, 0.75),
            why: "a 4 mm skin1 slab lit from behind: Li et al.'s layered medium lets through about 70% of the truth's red and a third of its green and blue (the dipole's diffusion through the thickness; it once let through none)",
        },
        Case {
            scene: "skin1-slab-backlit",
            technique: technique("separable"),
            error: 0.237,
            energy: (0.15, 1.25),
            why: "the slab under a screen-space blur: the medium's multipole transmission through the light-space map's thickness (every blur rendered it black before); red a fifth too bright, blue a fifth of the truth's",
        },
        Case {
            scene: "skin1-slab-backlit",
            technique: technique("burley"),
            error: 0.238,
            energy: (0.15, 1.25),
            why: "as separable: the transmission is added before the blur",
        },
        Case {
            scene: "skin1-slab-backlit",
            technique: technique("translucency"),
            error: 0.424,
            energy: (0.05, 0.85),
            why: "GDC 2011's term from the medium, fitted on this slab (power 2, distortion 0, gain 0.53): the attenuation exp(-sigma_tr t) lets too little blue through",
        },
        Case {
            scene: "marble-sphere-sidelit",
            technique: Technique::Auto,
            error: 0.090,
            energy: (0.85, 1.02),
            why: "Li et al.'s layered marble, side-lit: 4-10% too dark (8-14% too bright, error 0.139, until issue 37 took single scattering out of the dipole and the boundary's eta^2 into single scattering)",
        },
        Case {
            scene: "marble-sphere-sidelit",
            technique: Technique::None,
            error: 0.159,
            energy: (0.75, 0.95),
            why: "plain Lambert with the scene's written albedo (the dipole's R_d): 14-17% too dark, the light the truth carries past the terminator",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: Technique::None,
            error: 0.099,
            energy: (0.8, 1.0),
            why: "marble as one [material.medium], plain Lambert with its white-sky albedo: 7-11% too dark",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: Technique::Auto,
            error: 0.070,
            energy: (0.88, 1.02),
            why: "the medium as Li et al.'s layered material (what auto renders a medium with): 3-7% too dark, the closest of every technique (0.098 and 2-6% too bright before issue 37)",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: technique("separable"),
            error: 0.091,
            energy: (0.85, 1.05),
            why: "the separable blur of six Gaussians fitted to the medium's dipole, the medium's reflectance (Chandrasekhar's) and transmission",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: technique("burley"),
            error: 0.093,
            energy: (0.85, 1.05),
            why: "Burley's normalized diffusion from the medium's mean free path and albedo, with its reflectance and transmission",
        },
        Case {
            scene: "marble-medium-sidelit",
            technique: technique("translucency"),
            error: 0.081,
            energy: (0.9, 1.15),
            why: "GDC 2011's term from the medium: the best technique on marble, its broad lobe carrying light past the terminator (red 5% too bright)",
        },
        Case {
            scene: "marble-medium-sidelit-eta14",
            technique: Technique::None,
            error: 0.112,
            energy: (0.85, 1.05),
            why: "marble behind an eta 1.4 boundary (refracted next-event truth, about 1% low): Lambert with the medium's albedo at eta 1.4",
        },
        Case {
            scene: "marble-medium-sidelit-eta14",
            technique: Technique::Auto,
            error: 0.118,
            energy: (0.82, 0.97),
            why: "Li et al.'s layered marble at eta 1.4: 9-12% too dark (28-31% too dark, error 0.304, before issue 37: the ambient let in as 1 - F_dr, the share of light inside that gets out, and no 1 / c for the light leaving)",
        },
        Case {
            scene: "marble-medium-sidelit-eta14",
            technique: technique("separable"),
            error: 0.118,
            energy: (0.9, 1.1),
            why: "the separable blur at eta 1.4: the energy within 3%, the shape a little softer than plain Lambert's",
        },
        Case {
            scene: "marble-medium-sidelit-eta14",
            technique: technique("burley"),
            error: 0.121,
            energy: (0.9, 1.1),
            why: "Burley at eta 1.4",
        },
        Case {
            scene: "marble-medium-sidelit-eta14",
            technique: technique("translucency"),
            error: 0.124,
            energy: (0.9, 1.15),
            why: "GDC 2011's term from the medium at eta 1.4: red 9% too bright",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: Technique::None,
            error: 0.246,
            energy: (0.65, 0.9),
            why: "a skin1 sphere as one [material.medium], plain Lambert with its white-sky albedo: 18-26% too dark, the light skin1 carries past the terminator (0.389 with the dipole's R_d)",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: Technique::Auto,
            error: 0.157,
            energy: (0.75, 0.98),
            why: "the skin1 medium as Li et al.'s layered material, lit at 90 degrees: 7-19% too dark, red most (the f64 reference, gathering over the whole surface, is as dark: the model, not the screen-space gather; docs/layered.md); in front light (skin1-medium-front35) it is within 1-3%",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: technique("separable"),
            error: 0.16,
            energy: (0.75, 1.0),
            why: "the separable blur with the medium's reflectance (Chandrasekhar's; 0.236 with Lambert's) and transmission: 6-17% too dark",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: technique("burley"),
            error: 0.17,
            energy: (0.75, 1.0),
            why: "Burley with the medium's reflectance and transmission",
        },
        Case {
            scene: "skin1-medium-sidelit",
            technique: technique("translucency"),
            error: 0.237,
            energy: (0.7, 0.9),
            why: "GDC 2011's term from the medium: a little light past the terminator",
        },
        Case {
            scene: "skin1-medium-sidelit-eta14",
            technique: Technique::None,
            error: 0.195,
            energy: (0.7, 1.0),
            why: "skin1 behind an eta 1.4 boundary (refracted next-event truth): Lambert with the albedo at eta 1.4",
        },
        Case {
            scene: "skin1-medium-sidelit-eta14",
            technique: Technique::Auto,
            error: 0.196,
            energy: (0.7, 1.0),
            why: "Li et al.'s layered skin1 at eta 1.4: 4-24% too dark, red most, as at eta 1 (red 31% too dark and blue 34% too bright, error 0.389, before issue 37)",
        },
        Case {
            scene: "skin1-medium-sidelit-eta14",
            technique: technique("separable"),
            error: 0.14,
            energy: (0.8, 1.15),
            why: "the separable blur at eta 1.4 with the medium's reflectance (index-matched shape, energy at eta 1.4) and transmission",
        },
        Case {
            scene: "skin1-medium-sidelit-eta14",
            technique: technique("burley"),
            error: 0.151,
            energy: (0.8, 1.15),
            why: "Burley at eta 1.4",
        },
        Case {
            scene: "skin1-medium-sidelit-eta14",
            technique: technique("translucency"),
            error: 0.184,
            energy: (0.7, 1.0),
            why: "GDC 2011's term from the medium at eta 1.4",
        },
        Case {
            scene: "skin-layered-sidelit",
            technique: Technique::None,
            error: 0.487,
            energy: (0.5, 0.9),
            why: "the two-layer skin (nested media; the truth's noise is 0.16, so this bounds lucent loosely): Lambert with the top layer's written albedo",
        },
        Case {
            scene: "skin-layered-sidelit",
            technique: Technique::Auto,
            error: 0.475,
            energy: (0.68, 0.85),
            why: "Li et al.'s two-layer skin against the nested-media truth (noise 0.16)",
        },
        Case {
            scene: "jade-medium-sidelit",
            technique: Technique::None,
            error: 0.227,
            energy: (0.7, 0.9),
            why: "a jade medium (lucent's artistic coefficients): Lambert with its white-sky albedo, 18-22% too dark",
        },
        Case {
            scene: "jade-medium-sidelit",
            technique: Technique::Auto,
            error: 0.153,
            energy: (0.8, 1.05),
            why: "jade as Li et al.'s layered material",
        },
        Case {
            scene: "jade-medium-sidelit",
            technique: technique("separable"),
            error: 0.141,
            energy: (0.8, 1.05),
            why: "jade under the separable blur with the medium's reflectance and transmission: the best technique on jade",
        },
        Case {
            scene: "jade-medium-sidelit",
            technique: technique("burley"),
            error: 0.15,
            energy: (0.75, 1.05),
            why: "jade under Burley",
        },
        Case {
            scene: "jade-medium-sidelit",
            technique: technique("translucency"),
            error: 0.224,
            energy: (0.7, 0.9),
            why: "jade under GDC 2011's term from the medium",
        },
        Case {
            scene: "textured-medium-sidelit",
            technique: Technique::None,
            error: 0.263,
            energy: (0.65, 0.85),
            why: "an albedo-textured skin1 sphere (the truth: a pigment film on the light leaving, lucent's default `post`): Lambert with the texture",
        },
        Case {
            scene: "textured-medium-sidelit",
            technique: Technique::Auto,
            error: 0.165,
            energy: (0.78, 0.97),
            why: "the textured medium under Li et al.'s layered passes, the texture a film on the light leaving (it was not applied at all: error 0.402, 17-34% too bright). 0.116 before issue 37: the dipole's second count of single scattering made up for the model's darkness in side light, as on skin1-medium-sidelit, which it is now as far off as",
        },
        Case {
            scene: "textured-medium-sidelit",
            technique: technique("separable"),
            error: 0.164,
            energy: (0.75, 1.0),
            why: "the textured medium under the separable blur, the texture applied after the scatter",
        },
        Case {
            scene: "textured-medium-sidelit",
            technique: technique("burley"),
            error: 0.171,
            energy: (0.7, 1.0),
            why: "the textured medium under Burley",
        },
        Case {
            scene: "textured-medium-sidelit",
            technique: technique("translucency"),
            error: 0.256,
            energy: (0.65, 0.85),
            why: "the textured medium under GDC 2011's term from the medium",
        },
        Case {
            scene: "mixed-medium",
            technique: Technique::None,
            error: 0.168,
            energy: (0.75, 1.0),
            why: "the mixed scene with every material a medium (tools/truth/scenes/mixed-medium.toml): plain Lambert, 6-17% too dark",
        },
        Case {
            scene: "mixed-medium",
            technique: Technique::Auto,
            error: 0.148,
            energy: (0.8, 1.0),
            why: "mixed-medium under auto (Li et al.'s layered passes for every medium): 6-14% too dark; 0.132 before issue 37, whose energy fix takes away the second count of single scattering that made up for the side light's darkness (skin1-medium-sidelit)",
        },
        Case {
            scene: "mixed-medium",
            technique: technique("separable"),
            error: 0.143,
            energy: (0.8, 1.0),
            why: "mixed-medium with every medium forced to the separable blur",
        },
        Case {
            scene: "mixed-medium",
            technique: technique("burley"),
            error: 0.145,
            energy: (0.8, 1.0),
            why: "mixed-medium with every medium forced to Burley",
        },
        Case {
            scene: "mixed-medium",
            technique: technique("translucency"),
            error: 0.155,
            energy: (0.8, 1.05),
            why: "mixed-medium with every medium forced to GDC 2011's term from it",
        },
        Case {
            scene: "textured-medium-sidelit-prepost",
            technique: technique("separable"),
            error: 0.173,
            energy: (0.73, 0.99),
            why: "the textured medium as a physical pigment film (lucent's `pre-post`, which \
                  a [material.sss] without a profile states beside the medium): the blur keeps \
                  the stripes, 7-22% too dark",
        },
        Case {
            scene: "textured-medium-sidelit-prepost",
            technique: Technique::Auto,
            error: 0.173,
            energy: (0.73, 0.99),
            why: "auto renders the material with its [material.sss] table's blur (separable), \
                  not Li et al.'s passes, which would ignore the texture",
        },
        Case {
            scene: "skin1-medium-front35",
            technique: Technique::Auto,
            error: 0.054,
            energy: (0.95, 1.03),
            why: "skin1 lit 35 degrees off the view, eta 1: Li et al.'s layered passes within 1-3% of the truth's energy (0.150 and 10-16% too bright before issue 37 took single scattering out of the dipole)",
        },
        Case {
            scene: "skin1-medium-front35",
            technique: Technique::None,
            error: 0.124,
            energy: (1.0, 1.09),
            why: "skin1 in front light as a Lambertian surface of its white-sky albedo: 1-7% too bright",
        },
        Case {
            scene: "skin1-medium-front35-eta15",
            technique: Technique::Auto,
            error: 0.077,
            energy: (0.9, 1.0),
            why: "skin1 at eta 1.5, lit 35 degrees off the view: 2-8% too dark (0.362, blue 2.0x the truth's, before issue 37 divided single scattering by eta^2, the radiance law at the boundary)",
        },
        Case {
            scene: "skin1-medium-front35-eta15",
            technique: Technique::None,
            error: 0.106,
            energy: (0.86, 0.96),
            why: "skin1 at eta 1.5 in front light as a Lambertian surface of its white-sky albedo",
        },
        Case {
            scene: "marble-medium-front35",
            technique: Technique::Auto,
            error: 0.060,
            energy: (0.95, 1.0),
            why: "marble lit 35 degrees off the view, eta 1: 2% too dark (0.139 and 13-14% too bright before issue 37)",
        },
        Case {
            scene: "marble-medium-front35",
            technique: Technique::None,
            error: 0.059,
            energy: (0.97, 1.03),
            why: "marble in front light as a Lambertian surface of its white-sky albedo: within 1%",
        },
        Case {
            scene: "marble-medium-front35-eta15",
            technique: Technique::Auto,
            error: 0.106,
            energy: (0.92, 1.0),
            why: "marble at eta 1.5, lit 35 degrees off the view (truth noise 0.047 per 4x4 block): 3-5% too dark",
        },
        Case {
            scene: "marble-medium-front35-eta15",
            technique: Technique::None,
            error: 0.122,
            energy: (0.88, 0.96),
            why: "marble at eta 1.5 in front light as a Lambertian surface of its white-sky albedo",
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
        let truth = load_truth(&truth_dir(), case.scene).unwrap_or_else(|e| panic!("{e}"));
        let pixels = truth.object_pixels();
        assert!(pixels > 1000, "{}: {pixels} object pixels", case.scene);
        let settings = FrameSettings {
            technique: case.technique,
            export_hdr: true,
            ..FrameSettings::new(truth.width, truth.height)
        };
        let frame = test.render(&truth.scene, settings).hdr.unwrap();
        let measured = measure(&truth, &frame).unwrap_or_else(|e| panic!("{e}"));
        let (error, energy) = (measured.error, measured.energy);
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

#[test]
fn the_scanned_head_and_its_ear_stay_within_their_recorded_distance_of_the_truth() {
    // Issue 36: Lee Perry-Smith's head as skin1 (eta 1, untextured), side-lit and back-lit,
    // the whole head and its ear (`truths/head-skin1-*.regions.toml`). Recorded with `lucent
    // report truth --scenes head-skin1-sidelit,head-skin1-backlit --quick`.
    struct HeadCase {
        scene: &'static str,
        region: Option<&'static str>,
        technique: &'static str,
        error: f64,
        /// The red channel's energy must stay inside this range.
        red: (f64, f64),
    }
    let cases = [
        HeadCase {
            scene: "head-skin1-sidelit",
            region: None,
            technique: "none",
            error: 0.1125,
            red: (0.95, 1.02),
        },
        HeadCase {
            scene: "head-skin1-sidelit",
            region: None,
            technique: "separable",
            error: 0.0822,
            red: (0.90, 0.97),
        },
        HeadCase {
            scene: "head-skin1-sidelit",
            region: None,
            technique: "burley",
            error: 0.0820,
            red: (0.90, 0.97),
        },
        HeadCase {
            scene: "head-skin1-sidelit",
            region: Some("ear"),
            technique: "burley",
            error: 0.1214,
            red: (0.84, 0.91),
        },
        HeadCase {
            scene: "head-skin1-backlit",
            region: None,
            technique: "none",
            error: 0.2746,
            red: (0.72, 0.80),
        },
        HeadCase {
            scene: "head-skin1-backlit",
            region: None,
            technique: "separable",
            error: 0.1707,
            red: (0.84, 0.91),
        },
        // The back-lit ear: every technique lets through 52-67% of the truth's red.
        HeadCase {
            scene: "head-skin1-backlit",
            region: Some("ear"),
            technique: "none",
            error: 0.5678,
            red: (0.32, 0.39),
        },
        HeadCase {
            scene: "head-skin1-backlit",
            region: Some("ear"),
            technique: "separable",
            error: 0.3562,
            red: (0.56, 0.64),
        },
    ];
    let test = TestGpu::new();
    let mut failures = Vec::new();
    for case in cases {
        let whole = load_truth(&truth_dir(), case.scene).unwrap_or_else(|e| panic!("{e}"));
        let truth = match case.region {
            None => whole.clone(),
            Some(name) => {
                let region = whole.regions.iter().find(|r| r.name == name).unwrap();
                whole.region(region)
            }
        };
        assert!(
            truth.object_pixels() > 500,
            "{}: {}",
            truth.name,
            truth.object_pixels()
        );
        let settings = FrameSettings {
            technique: technique(case.technique),
            export_hdr: true,
            ..FrameSettings::new(truth.width, truth.height)
        };
        let frame = test.render(&truth.scene, settings).hdr.unwrap();
        let measured = measure(&truth, &frame).unwrap_or_else(|e| panic!("{e}"));
        println!(
            "{} under {}: error {:.4} (recorded {}), energy {:.3?}",
            truth.name, case.technique, measured.error, case.error, measured.energy
        );
        if measured.error > case.error + ERROR_SLACK
            || !(case.red.0..=case.red.1).contains(&measured.energy[0])
        {
            failures.push(format!(
                "{} under {}: error {:.4} (recorded {}), red energy {:.3} (range {:?})",
                truth.name,
                case.technique,
                measured.error,
                case.error,
                measured.energy[0],
                case.red
            ));
        }
    }
    test.finish();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The slab truth's scene with its skin1 layer given as one `[material.medium]` (the same
/// medium: Jensen 2001's skin1 at eta 1, 0.05 units/mm), no `[material.layered]`, the albedo
/// derived (its white-sky albedo), and GDC 2011's term as derived from the medium with
/// `power` and `distortion` and gain 1; its thickness prepared (the distance bake).
fn slab_with_medium(
    truth: &lucent::measure::truth::Truth,
    power: f32,
    distortion: f32,
) -> lucent::scene::Scene {
    use lucent::scene::material::Medium;
    let mut scene = truth.scene.clone();
    for o in &mut scene.objects {
        let m = &mut o.material;
        let mut layered = m.layers.take().expect("the slab's layered skin1");
        layered.weights = lucent::scene::layered::PHYSICAL_WEIGHTS;
        m.albedo = layered.white_sky_albedo();
        let mut medium = Medium::new(layered);
        medium.translucency.power = power;
        medium.translucency.distortion = distortion;
        medium.translucency.color = glam::Vec3::ONE;
        m.medium = Some(medium);
    }
    let cache = std::env::temp_dir().join(format!("lucent-gdc-fit-{}", std::process::id()));
    lucent::bake::scene::prepare_thickness(&mut scene, &cache).unwrap();
    scene
}

/// The gain `k` minimising `sum |k L - T|` over the object's pixels (the term is linear in
/// the gain below GB2's clamp), scanned on a log grid, and its error.
fn best_gain(truth: &lucent::measure::truth::Truth, frame: &[f32]) -> (f64, f64) {
    let mut best = (1.0, f64::INFINITY);
    for i in 0..=160 {
        let k = 10f64.powf(-1.0 + 2.0 * f64::from(i) / 160.0);
        let scaled: Vec<f32> = frame
            .chunks_exact(4)
            .flat_map(|p| [p[0] * k as f32, p[1] * k as f32, p[2] * k as f32, p[3]])
            .collect();
        let e = measure(truth, &scaled).unwrap().error;
        if e < best.1 {
            best = (k, e);
        }
    }
    best
}

/// GDC 2011's power and distortion for materials with a medium, fitted once against the
/// back-lit 4 mm skin1 slab's truth (the committed `skin1-slab-backlit`; the published fit
/// was made on its 160x120 render): each (power, distortion) of the grid rendered under `--technique translucency` with the term
/// derived from the medium at gain 1, the best gain found for it, and the error grid printed
/// (docs/translucency.md, "From the medium", publishes it; the chosen values are
/// `lucent::scene::material::MEDIUM_POWER`, `MEDIUM_DISTORTION`, `MEDIUM_GAIN`).
/// `cargo test --test gpu translucency_fit -- --ignored --nocapture`.
#[test]
#[ignore = "the fit: about 40 frames; run by hand when the model changes"]
fn translucency_fit_against_the_slab_truth() {
    let test = TestGpu::new();
    let truth = load_truth(&truth_dir(), "skin1-slab-backlit").unwrap();
    let powers = [0.0f32, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 12.0];
    let distortions = [0.0f32, 0.1, 0.2, 0.4, 0.8];
    let mut best = (0.0, 0.0, 0.0, f64::INFINITY);
    println!("error (gain) by power (rows) x distortion (columns {distortions:?})");
    for &power in &powers {
        let mut row = format!("power {power:>5}:");
        for &distortion in &distortions {
            let scene = slab_with_medium(&truth, power, distortion);
            let settings = FrameSettings {
                technique: technique("translucency"),
                export_hdr: true,
                ..FrameSettings::new(truth.width, truth.height)
            };
            let frame = test.render(&scene, settings).hdr.unwrap();
            let (k, e) = best_gain(&truth, &frame);
            row += &format!(" {e:.4} ({k:.2})");
            if e < best.3 {
                best = (power, distortion, k, e);
            }
        }
        println!("{row}");
    }
    println!(
        "best: power {}, distortion {}, gain {:.3}: error {:.4}",
        best.0, best.1, best.2, best.3
    );
    test.finish();
}
