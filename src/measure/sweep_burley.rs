//! `lucent sweep burley`: 2-D Burley SSS at extreme distances and albedos and in hostile views,
//! with NaN, Inf, the largest value and fp16 overflows counted per case.
//!
//! The cases: Burley's `d` from 1e-4 mm (far under a pixel: the gather leaves pixels alone) to
//! 1e3 mm (wider than the scene: the reach is clamped to a quarter of the screen), given
//! directly; a mean free path at albedo 0, 0.5 and 1 under each of Christensen and Burley's
//! fits; each in three views of an SSS sphere over an SSS floor: in front, grazing (the eye a
//! hair above the floor's plane, depth differences across a tap as large as they get) and close
//! (the eye just outside the sphere, near the near plane). Zero NaN and zero Inf are required.

use std::fmt::Write as _;

use glam::{Mat4, Vec3};

use super::sweep::count_hdr;
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{render_frame, FrameSettings, Technique};
use crate::scene::generators::{self, Generator};
use crate::scene::material::{BurleyDistance, SssProfile};
use crate::scene::profile::BurleyFit;
use crate::scene::{Camera, Light, Material, Object, Scene};
use crate::Result;

/// Where a case looks from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The sphere and floor from the front.
    Front,
    /// The eye 1e-4 units above the floor's plane, looking along it.
    Grazing,
    /// The eye just outside the sphere, the surface at the near plane.
    Close,
}

impl View {
    /// Every view with its name.
    pub const ALL: &'static [(&'static str, View)] = &[
        ("front", View::Front),
        ("grazing", View::Grazing),
        ("close", View::Close),
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, v)| *v == self)
            .map_or("?", |(n, _)| n)
    }
}

/// One case: the distances, the fit, the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BurleyCase {
    /// What the material gives.
    pub distance: BurleyDistance,
    /// The fit a mean free path goes through.
    pub fit: BurleyFit,
    /// Where it is seen from.
    pub view: View,
}

impl BurleyCase {
    /// The case's parameters in words.
    pub fn label(&self) -> String {
        match self.distance {
            BurleyDistance::Scattering(d) => format!("d = {:e} mm", d.x),
            BurleyDistance::MeanFreePath { mfp, albedo } => {
                let fit = BurleyFit::ALL
                    .iter()
                    .find(|(_, f)| *f == self.fit)
                    .map_or("?", |(n, _)| n);
                format!("l = {} mm, A = {}, {fit}", mfp.x, albedo.x)
            }
        }
    }
}

/// What one case produced.
#[derive(Clone, Debug, PartialEq)]
pub struct BurleyRow {
    /// The case.
    pub case: BurleyCase,
    /// NaN channel values in the HDR image.
    pub nan: usize,
    /// Infinite channel values.
    pub inf: usize,
    /// Largest finite channel value.
    pub max: f32,
    /// Channel values at the fp16 maximum.
    pub fp16_overflow: usize,
}

/// Burley's `d` the sweep gives directly, mm (red; green and blue half and a quarter of it).
pub const DISTANCES: [f32; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e3];
/// Albedos of the mean-free-path cases.
pub const ALBEDOS: [f32; 3] = [0.0, 0.5, 1.0];

/// Every case (see the module docs).
pub fn burley_cases() -> Vec<BurleyCase> {
    let mut distances: Vec<(BurleyDistance, BurleyFit)> = DISTANCES
        .iter()
        .map(|&d| {
            (
                BurleyDistance::Scattering(Vec3::new(d, d * 0.5, d * 0.25)),
                BurleyFit::default(),
            )
        })
        .collect();
    for &a in &ALBEDOS {
        for &(_, fit) in BurleyFit::ALL {
            distances.push((
                BurleyDistance::MeanFreePath {
                    mfp: Vec3::new(2.0, 1.0, 0.5),
                    albedo: Vec3::splat(a),
                },
                fit,
            ));
        }
    }
    let mut cases = Vec::new();
    for &(_, view) in View::ALL {
        for &(distance, fit) in &distances {
            cases.push(BurleyCase {
                distance,
                fit,
                view,
            });
        }
    }
    cases
}

/// The scene of one case: a sphere of radius 0.7 on an SSS floor, both with the case's
/// profile, one point light.
pub fn case_scene(case: &BurleyCase) -> Result<Scene> {
    let mut material = Material::opaque("burley sweep", Vec3::new(0.8, 0.6, 0.5), 0.3, 0.5);
    material.sss = Some(SssProfile {
        burley: Some(case.distance),
        units_per_mm: 0.01,
        ..SssProfile::preset("skin")?
    });
    let sphere = generators::generate(Generator::Icosphere, 3)?;
    let floor = generators::generate(Generator::Plane, 1)?;
    let (eye, target) = match case.view {
        View::Front => (Vec3::new(0.0, 0.8, 3.0), Vec3::new(0.0, 0.5, 0.0)),
        View::Grazing => (Vec3::new(0.0, 1e-4, 4.0), Vec3::new(0.0, 1e-4, 0.0)),
        View::Close => (Vec3::new(0.0, 0.7, 0.8), Vec3::new(0.0, 0.7, 0.0)),
    };
    Ok(Scene {
        name: "burley sweep".into(),
        meshes: vec![sphere, floor],
        objects: vec![
            Object {
                mesh: 0,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.7),
                    glam::Quat::IDENTITY,
                    Vec3::new(0.0, 0.7, 0.0),
                ),
                material: material.clone(),
            },
            Object {
                mesh: 1,
                transform: Mat4::from_scale(Vec3::splat(5.0)),
                material,
            },
        ],
        lights: vec![Light::point(
            Vec3::new(1.5, 2.5, 2.0),
            Vec3::ONE,
            20.0,
            15.0,
        )],
        camera: Camera {
            eye,
            target,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 100.0,
        },
        environment: crate::scene::Environment::constant(Vec3::splat(0.05)),
        sky: Vec3::splat(0.02),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    })
}

/// Renders every case at `width` x `height` under Burley and counts what went wrong.
pub fn run_burley(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    width: u32,
    height: u32,
    cases: &[BurleyCase],
) -> Result<Vec<BurleyRow>> {
    let mut rows = Vec::with_capacity(cases.len());
    for case in cases {
        let mut settings = FrameSettings {
            technique: Technique::Only(&crate::features::sss::burley::BURLEY),
            export_hdr: true,
            ..FrameSettings::new(width, height)
        };
        settings.sss.burley_fit = case.fit;
        let scene = case_scene(case)?;
        let images = render_frame(gpu, shaders, pipeline_cache, &scene, settings)?;
        let c = count_hdr(&images.hdr.unwrap_or_default());
        rows.push(BurleyRow {
            case: *case,
            nan: c.nan,
            inf: c.inf,
            max: c.max,
            fp16_overflow: c.fp16_overflow,
        });
    }
    Ok(rows)
}

/// The sweep as a Markdown table with a verdict line.
pub fn markdown(rows: &[BurleyRow], width: u32, height: u32, device: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "## lucent sweep burley, {width}x{height}\n");
    let _ = writeln!(out, "- device: {device}\n");
    let _ = writeln!(out, "| view | case | NaN | Inf | max | fp16 overflows |");
    let _ = writeln!(out, "|---|---|---:|---:|---:|---:|");
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.4} | {} |",
            r.case.view.name(),
            r.case.label(),
            r.nan,
            r.inf,
            r.max,
            r.fp16_overflow
        );
    }
    let bad: usize = rows.iter().map(|r| r.nan + r.inf).sum();
    let _ = writeln!(
        out,
        "\n{} cases, {bad} NaN/Inf values{}",
        rows.len(),
        if bad == 0 { ": stable" } else { "" }
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cases_cover_every_distance_albedo_fit_and_view() {
        let cases = burley_cases();
        let per_view = DISTANCES.len() + ALBEDOS.len() * BurleyFit::ALL.len();
        assert_eq!(cases.len(), per_view * View::ALL.len());
        for case in &cases {
            let scene = case_scene(case).unwrap();
            assert_eq!(scene.objects.len(), 2);
            assert!(!case.label().is_empty());
        }
    }
}
