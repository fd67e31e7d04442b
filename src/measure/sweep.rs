//! Stability sweeps: render a technique at extreme parameters and on hostile geometry and count
//! what went wrong in the linear HDR output (NaN, Inf, the largest value, and how many values
//! hit the fp16 ceiling the lighting pass clamps to).
//!
//! `lucent sweep translucency` runs [`translucency_cases`]: the full grid of the GDC 2011
//! parameters (power, distortion, scale, ambient, thickness, each pow form) on a back-lit cube,
//! then the geometric extremes (a light on the surface, inside the mesh, a million units away,
//! a grazing view, intensity 1e5, normals that interpolate to zero length), each with the talk's
//! defaults, with every parameter at its extreme, and with the most light let through. Zero NaN and zero Inf are required.

use std::fmt::Write as _;

use glam::{Mat4, Vec3};

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{render_frame, FrameSettings, Technique};
use crate::scene::generators::{self, Generator};
use crate::scene::material::{PowMode, ThicknessSource, Translucency};
use crate::scene::{Camera, Light, Material, Mesh, Object, Scene};
use crate::Result;

/// The talk's parameters of one case (`scale` is the light's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TranslucencyParams {
    /// `iLTPower`.
    pub power: f32,
    /// `fLTDistortion`.
    pub distortion: f32,
    /// `fLTScale` of every light.
    pub scale: f32,
    /// `fLTAmbient`.
    pub ambient: f32,
    /// Constant local thickness.
    pub thickness: f32,
    /// Exact `pow` or `exp2`.
    pub pow_mode: PowMode,
}

/// The geometric situations the sweep puts the parameters in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// A cube lit from behind, seen from the front.
    BackLit,
    /// The light exactly on the front face (distance 0 at the centre pixel).
    LightOnSurface,
    /// The light at the cube's centre.
    LightInside,
    /// The light a million units behind, with a range that still reaches.
    LightFarAway,
    /// The camera almost in the plane of the top face.
    GrazingView,
    /// The back light at intensity 1e5.
    Intense,
    /// A quad whose vertex normals point opposite ways, so they interpolate through zero.
    ZeroLengthNormals,
}

impl Geometry {
    /// Every situation with its name.
    pub const ALL: &'static [(&'static str, Geometry)] = &[
        ("back-lit", Geometry::BackLit),
        ("light on surface (distance 0)", Geometry::LightOnSurface),
        ("light inside the mesh", Geometry::LightInside),
        ("light 1e6 away", Geometry::LightFarAway),
        ("grazing view", Geometry::GrazingView),
        ("intensity 1e5", Geometry::Intense),
        ("zero-length normals", Geometry::ZeroLengthNormals),
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, g)| *g == self)
            .map_or("?", |(n, _)| n)
    }
}

/// One case of a sweep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SweepCase {
    /// Where.
    pub geometry: Geometry,
    /// With which parameters.
    pub params: TranslucencyParams,
}

/// What one case produced.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepRow {
    /// The case.
    pub case: SweepCase,
    /// NaN channel values in the HDR image.
    pub nan: usize,
    /// Infinite channel values.
    pub inf: usize,
    /// Largest finite channel value.
    pub max: f32,
    /// Channel values at (or above) the fp16 maximum 65504, where the shader clamps.
    pub fp16_overflow: usize,
}

/// The values the sweep takes (issue 4's list).
pub const POWERS: [f32; 5] = [0.0, 1e-3, 1.0, 12.0, 1e4];
/// Distortions.
pub const DISTORTIONS: [f32; 3] = [0.0, 0.2, 10.0];
/// Per-light scales.
pub const SCALES: [f32; 3] = [0.0, 1.0, 1e4];
/// Ambients.
pub const AMBIENTS: [f32; 2] = [0.0, 1.0];
/// Thicknesses.
pub const THICKNESSES: [f32; 2] = [0.0, 1.0];
const POW_MODES: [PowMode; 2] = [PowMode::Exact, PowMode::SphericalGaussian];

/// The talk's defaults, the extreme corner (every parameter at its largest: the lobe collapses
/// to a needle), and the hot corner (a flat lobe at the largest scale and ambient: the most light
/// through), which every geometric case is also run with.
fn defaults_and_extremes(pow_mode: PowMode) -> [TranslucencyParams; 3] {
    [
        TranslucencyParams {
            power: 12.0,
            distortion: 0.2,
            scale: 1.0,
            ambient: 0.1,
            thickness: 1.0,
            pow_mode,
        },
        TranslucencyParams {
            power: 1e4,
            distortion: 10.0,
            scale: 1e4,
            ambient: 1.0,
            thickness: 1.0,
            pow_mode,
        },
        TranslucencyParams {
            power: 1e-3,
            distortion: 0.0,
            scale: 1e4,
            ambient: 1.0,
            thickness: 1.0,
            pow_mode,
        },
    ]
}

/// Every case of the translucency sweep: the full parameter grid on the back-lit cube, then each
/// geometric extreme with the defaults and with the extreme corner, for both pow forms.
pub fn translucency_cases() -> Vec<SweepCase> {
    let mut cases = Vec::new();
    for pow_mode in POW_MODES {
        for power in POWERS {
            for distortion in DISTORTIONS {
                for scale in SCALES {
                    for ambient in AMBIENTS {
                        for thickness in THICKNESSES {
                            cases.push(SweepCase {
                                geometry: Geometry::BackLit,
                                params: TranslucencyParams {
                                    power,
                                    distortion,
                                    scale,
                                    ambient,
                                    thickness,
                                    pow_mode,
                                },
                            });
                        }
                    }
                }
            }
        }
    }
    for &(_, geometry) in &Geometry::ALL[1..] {
        for pow_mode in POW_MODES {
            for params in defaults_and_extremes(pow_mode) {
                cases.push(SweepCase { geometry, params });
            }
        }
    }
    cases
}

/// The scene of one case.
pub fn case_scene(case: &SweepCase) -> Result<Scene> {
    let p = case.params;
    let mut translucency = Translucency::new(ThicknessSource::Constant(p.thickness));
    translucency.power = p.power;
    translucency.distortion = p.distortion;
    translucency.ambient = p.ambient;
    translucency.pow_mode = p.pow_mode;
    let mut material = Material::opaque("sweep", Vec3::new(0.8, 0.7, 0.6), 0.5, 0.3);
    material.translucency = Some(translucency);
    let (mesh, transform) = match case.geometry {
        Geometry::ZeroLengthNormals => (opposed_normal_quad(), Mat4::IDENTITY),
        _ => (generators::generate(Generator::Cube, 2)?, Mat4::IDENTITY),
    };
    let mut eye = Vec3::new(0.0, 0.0, 3.0);
    let mut target = Vec3::ZERO;
    let (mut position, mut intensity, mut range) = (Vec3::new(0.3, 0.2, -1.5), 5.0, 10.0);
    match case.geometry {
        Geometry::BackLit | Geometry::ZeroLengthNormals => {}
        Geometry::LightOnSurface => position = Vec3::new(0.0, 0.0, 0.5),
        Geometry::LightInside => position = Vec3::ZERO,
        Geometry::LightFarAway => {
            position = Vec3::new(0.0, 0.0, -1e6);
            range = 2e6;
            intensity = 1e12;
        }
        Geometry::GrazingView => {
            eye = Vec3::new(0.0, 0.5 + 1e-4, 3.0);
            target = Vec3::new(0.0, 0.5, 0.0);
        }
        Geometry::Intense => intensity = 1e5,
    }
    let mut light = Light::point(position, Vec3::ONE, intensity, range);
    light.translucency_scale = p.scale;
    Ok(Scene {
        name: "sweep".into(),
        meshes: vec![mesh],
        objects: vec![Object {
            mesh: 0,
            transform,
            material,
        }],
        lights: vec![light],
        camera: Camera {
            eye,
            target,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 100.0,
        },
        environment: crate::scene::Environment::constant(Vec3::splat(0.03)),
        sky: Vec3::splat(0.02),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    })
}

/// A 1 x 1 quad facing the camera whose left vertices' normals point at it and right ones away:
/// every normal is unit length (the mesh is valid), but they interpolate through zero length
/// down the middle, which the G-buffer's normal guard must catch.
fn opposed_normal_quad() -> Mesh {
    Mesh {
        positions: vec![
            Vec3::new(-0.5, -0.5, 0.0),
            Vec3::new(0.5, -0.5, 0.0),
            Vec3::new(0.5, 0.5, 0.0),
            Vec3::new(-0.5, 0.5, 0.0),
        ],
        normals: vec![Vec3::Z, -Vec3::Z, -Vec3::Z, Vec3::Z],
        indices: vec![0, 1, 2, 0, 2, 3],
        ..Mesh::default()
    }
}

/// What went wrong in one linear HDR image (see [`count_hdr`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HdrCounts {
    /// NaN channel values.
    pub nan: usize,
    /// Infinite channel values.
    pub inf: usize,
    /// Largest finite channel value (0 for an image of none).
    pub max: f32,
    /// Channel values at (or above) the fp16 maximum 65504, where the shader clamps.
    pub fp16_overflow: usize,
}

/// Counts NaN, Inf, the largest finite value and fp16 overflows in RGBA f32 `hdr` (alpha
/// ignored): the numbers every stability sweep reports.
pub fn count_hdr(hdr: &[f32]) -> HdrCounts {
    let mut c = HdrCounts::default();
    for v in hdr.chunks_exact(4).flat_map(|p| &p[..3]) {
        if v.is_nan() {
            c.nan += 1;
        } else if v.is_infinite() {
            c.inf += 1;
        } else {
            c.max = c.max.max(*v);
            c.fp16_overflow += usize::from(*v >= 65504.0);
        }
    }
    c
}

/// Counts what went wrong in RGBA f32 `hdr` (alpha ignored).
pub fn measure(case: SweepCase, hdr: &[f32]) -> SweepRow {
    let c = count_hdr(hdr);
    SweepRow {
        case,
        nan: c.nan,
        inf: c.inf,
        max: c.max,
        fp16_overflow: c.fp16_overflow,
    }
}

/// Renders every case at `width` x `height` and measures it.
pub fn run_translucency(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    width: u32,
    height: u32,
    cases: &[SweepCase],
) -> Result<Vec<SweepRow>> {
    let settings = FrameSettings {
        technique: Technique::Only(&crate::features::translucency::TRANSLUCENCY),
        export_hdr: true,
        ..FrameSettings::new(width, height)
    };
    let mut rows = Vec::with_capacity(cases.len());
    for case in cases {
        let scene = case_scene(case)?;
        let images = render_frame(gpu, shaders, pipeline_cache, &scene, settings)?;
        let hdr = images.hdr.unwrap_or_default();
        rows.push(measure(*case, &hdr));
    }
    Ok(rows)
}

/// The sweep as a Markdown table, one row per case, with a verdict line.
pub fn markdown(rows: &[SweepRow], width: u32, height: u32, device: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "## lucent sweep translucency, {width}x{height}\n");
    let _ = writeln!(out, "- device: {device}");
    let _ = writeln!(out, "- cases: {}", rows.len());
    let (nan, inf) = (
        rows.iter().map(|r| r.nan).sum::<usize>(),
        rows.iter().map(|r| r.inf).sum::<usize>(),
    );
    let _ = writeln!(
        out,
        "- verdict: {} ({nan} NaN, {inf} Inf in all cases)\n",
        if nan + inf == 0 { "stable" } else { "UNSTABLE" }
    );
    out.push_str("| geometry | pow | power | distortion | scale | ambient | thickness | NaN | Inf | max | fp16 overflow |\n");
    out.push_str("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for r in rows {
        let p = r.case.params;
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.4e} | {} |",
            r.case.geometry.name(),
            match p.pow_mode {
                PowMode::Exact => "pow",
                PowMode::SphericalGaussian => "exp2",
                PowMode::SphericalGaussianScaled => "exp2-scaled",
            },
            p.power,
            p.distortion,
            p.scale,
            p.ambient,
            p.thickness,
            r.nan,
            r.inf,
            r.max,
            r.fp16_overflow
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_covers_every_listed_value_and_each_geometry() {
        let cases = translucency_cases();
        assert_eq!(cases.len(), 2 * 5 * 3 * 3 * 2 * 2 + 6 * 2 * 3);
        for &(_, g) in Geometry::ALL {
            assert!(cases.iter().any(|c| c.geometry == g));
        }
        for case in &cases {
            let scene = case_scene(case).unwrap();
            for m in &scene.meshes {
                m.validate("sweep").unwrap();
            }
            for o in &scene.objects {
                o.material.validate().unwrap();
            }
        }
    }

    #[test]
    fn measure_counts_nan_inf_and_the_fp16_ceiling() {
        let case = translucency_cases()[0];
        let hdr = [f32::NAN, 1.0, f32::INFINITY, 1.0, 65504.0, 2.0, 3.0, 1.0];
        let row = measure(case, &hdr);
        assert_eq!((row.nan, row.inf, row.fp16_overflow), (1, 1, 1));
        assert_eq!(row.max, 65504.0);
    }
}
