//! The layered stability sweep (`lucent sweep layered`, issue 14 deliverable 7): Li et al.'s
//! layered media at the extremes [`LayeredMedium::validate`] accepts, on a sphere over a floor
//! in hostile lighting, each case rendered (NaN, Inf, the largest value and fp16 overflows in
//! the linear HDR, counted as [`super::sweep::count_hdr`] counts them for every sweep) and the
//! f64 references evaluated at a few of the sphere's surface points (single scattering with
//! both phase functions, multiple scattering over the surface samples, the dipole's constants,
//! `Rd` at r = 0, tiny and huge, and its total reflectance). Zero NaN and zero Inf are required,
//! on the GPU and in the references.
//!
//! The media ([`layered_media`]): two presets; `sigma_a = 0`; `sigma_s' = 0`, `1e-6` and
//! `1e6` mm^-1 (the [`MAX_COEFFICIENT`] limit, exactly); both coefficients at the limit and
//! both 0 (a vacuum); `g = -0.999, 0, +0.999` ([`MAX_ABS_G`], exactly), with thin and with
//! limit scattering; `eta = 1` (`F_dr = 0`), 1.5, 3, 0.5 and the absurd 1e-3 and 1e3; a
//! two-layer stack whose top layer is 0 mm, 1e6 mm and `f32::MAX` mm (the largest thickness
//! validate accepts) thick, also at 1000 units per mm (the thickness in scene units overflows
//! f32), three `f32::MAX` mm layers at one unit per mm (the depths add up past f32), and two
//! constant layers with no semi-infinite rest; a single
//! `rest` layer; eight layers (alternating extremes, and eight equal ones); `units_per_mm` 1e-3
//! and 1e3; and two corners where every extreme meets. The situations
//! ([`LayeredGeometry`]): lit from the front, back-lit, a grazing view, a light exactly on the
//! surface (the sphere's pole vertex), a light at the sphere's centre, a directional light, a
//! spot light, two lights without shadows (every other situation casts), two lights at
//! intensity 1e5, and a light a million units away.
//!
//! The frame is rendered with the default settings (`--technique auto`), so whatever passes a
//! layered material gets are the passes swept.

use std::fmt::Write as _;

use glam::{DVec3, Mat4, Vec3};

use super::sweep::{count_hdr, HdrCounts};
use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{render_frame, FrameSettings};
use crate::reference::layered::{
    multiple_scattering, single_scattering, Phase, SingleScatteringOptions, SurfaceSamples,
};
use crate::scene::generators::{self, Generator};
use crate::scene::layered::dipole_constants;
use crate::scene::layered::{Layer, LayeredMedium, Thickness, MAX_ABS_G, MAX_COEFFICIENT};
use crate::scene::{Camera, Light, LightKind, Material, Mesh, Object, Scene, Shape};
use crate::{LucentError, Result};

/// The sphere's centre (it rests on the floor at y = 0).
const CENTRE: Vec3 = Vec3::new(0.0, 0.5, 0.0);
/// The sphere's radius (scene units: 12.5 mm at the default 0.04 units per mm).
const RADIUS: f32 = 0.5;
/// Icosphere level of the sphere (1280 triangles).
const SPHERE_LEVEL: u32 = 3;
/// Quadrature points of the single-scattering reference per channel (small: the sweep looks
/// for non-finite values, not accuracy).
const SS_STEPS: usize = 64;
/// Most surface samples the multiple-scattering reference makes per case.
const MAX_SAMPLES: usize = 8000;

/// The geometric situations the media are put in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayeredGeometry {
    /// A point light in front, above and to the side of the camera.
    Front,
    /// A point light behind the sphere, seen from the front: the light has to come through.
    BackLit,
    /// The camera almost in the tangent plane of the sphere's top.
    Grazing,
    /// A point light exactly on the surface: at the sphere's pole, a vertex of the mesh and a
    /// point of the analytic sphere (distance 0 there).
    LightOnSurface,
    /// A point light at the sphere's centre.
    LightInside,
    /// A directional light.
    Directional,
    /// A spot light aimed at the sphere.
    Spot,
    /// A front and a back point light, neither casting shadows.
    ShadowsOff,
    /// The front and the back light at intensity 1e5 (the fp16 ceiling).
    Intense,
    /// A point light a million units behind the sphere, with a range and an intensity that
    /// still reach it.
    LightFarAway,
}

impl LayeredGeometry {
    /// Every situation with its name.
    pub const ALL: &'static [(&'static str, LayeredGeometry)] = &[
        ("front", LayeredGeometry::Front),
        ("back-lit", LayeredGeometry::BackLit),
        ("grazing view", LayeredGeometry::Grazing),
        ("light on surface", LayeredGeometry::LightOnSurface),
        ("light inside", LayeredGeometry::LightInside),
        ("directional", LayeredGeometry::Directional),
        ("spot", LayeredGeometry::Spot),
        ("shadows off", LayeredGeometry::ShadowsOff),
        ("intensity 1e5", LayeredGeometry::Intense),
        ("light 1e6 away", LayeredGeometry::LightFarAway),
    ];

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, g)| *g == self)
            .map_or("?", |(n, _)| n)
    }
}

/// One case of the layered sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredCase {
    /// What the medium is (the table's first column).
    pub label: String,
    /// The sphere's medium.
    pub medium: LayeredMedium,
    /// Where it is.
    pub geometry: LayeredGeometry,
}

/// What the f64 references gave in one case.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReferenceCounts {
    /// Values evaluated (radiances per channel, dipole constants and profile values, surface
    /// sample irradiances).
    pub values: usize,
    /// Of them NaN or infinite.
    pub non_finite: usize,
    /// Of them negative (radiance or reflectance below 0; not a failure, reported).
    pub negative: usize,
    /// Largest finite radiance of single and multiple scattering at the surface points.
    pub max_radiance: f64,
    /// Surface samples the multiple-scattering reference used.
    pub samples: usize,
    /// Errors the references returned, and which values were non-finite.
    pub notes: Vec<String>,
    /// The first few negative quantities (name = value of its first negative channel).
    pub negatives: Vec<String>,
}

impl ReferenceCounts {
    /// Counts `v` (named `what` in a note if it is not finite).
    fn check(&mut self, what: &str, v: f64) {
        self.values += 1;
        if !v.is_finite() {
            self.non_finite += 1;
            if self.notes.len() < 6 {
                self.notes.push(format!("{what} = {v}"));
            }
        } else if v < 0.0 {
            self.negative += 1;
            // One note per quantity (the channels' alike), at most five.
            let kind = what
                .replace("[0]", "")
                .replace("[1]", "")
                .replace("[2]", "");
            if self.negatives.len() < 5 && !self.negatives.iter().any(|n| n.starts_with(&kind)) {
                self.negatives.push(format!("{kind} = {v:.3e}"));
            }
        }
    }

    /// Counts a radiance and keeps the largest.
    fn radiance(&mut self, what: &str, v: DVec3) {
        for (c, x) in v.to_array().into_iter().enumerate() {
            self.check(&format!("{what}[{c}]"), x);
            if x.is_finite() {
                self.max_radiance = self.max_radiance.max(x);
            }
        }
    }

    /// Notes a reference's error.
    fn error(&mut self, what: &str, e: &LucentError) {
        self.notes.push(format!("{what}: {e}"));
    }
}

/// What one case produced.
#[derive(Clone, Debug, PartialEq)]
pub struct LayeredRow {
    /// The case.
    pub case: LayeredCase,
    /// The rendered HDR's counts.
    pub hdr: HdrCounts,
    /// The references' counts.
    pub reference: ReferenceCounts,
}

impl LayeredRow {
    /// NaN and Inf values, GPU and references together: the sweep requires 0.
    pub fn bad(&self) -> usize {
        self.hdr.nan + self.hdr.inf + self.reference.non_finite
    }
}

/// A layer with RGB-equal coefficients (mm^-1).
fn layer(sigma_a: f32, sigma_s: f32, g: f32, thickness: Thickness) -> Layer {
    Layer {
        sigma_a: Vec3::splat(sigma_a),
        sigma_s: Vec3::splat(sigma_s),
        g,
        thickness,
    }
}

/// One semi-infinite layer with RGB-equal full (not reduced) coefficients.
fn single(name: &str, sigma_a: f32, sigma_s: f32, g: f32, eta: f32) -> LayeredMedium {
    let mut m = LayeredMedium::homogeneous(name, Vec3::ONE, Vec3::ONE, 0.0, eta);
    m.layers = vec![layer(sigma_a, sigma_s, g, Thickness::Rest)];
    m
}

/// Every medium of the sweep with its label (see the module docs); each passes
/// [`LayeredMedium::validate`].
pub fn layered_media() -> Result<Vec<(String, LayeredMedium)>> {
    let apple = LayeredMedium::preset("apple")?;
    let (apple_sp, apple_sa) = (apple.layers[0].sigma_s_prime(), apple.layers[0].sigma_a);
    let with_apple = |name: &str, f: &dyn Fn(&mut LayeredMedium)| {
        let mut m = apple.clone();
        m.name = name.to_string();
        f(&mut m);
        m
    };
    let g_max = MAX_ABS_G;
    let c_max = MAX_COEFFICIENT;
    // A two-layer stack: apple with Li's teapot row below, the top `t` mm thick.
    let two = |t: Thickness| {
        let mut m = LayeredMedium::preset("li-teapot").unwrap_or_else(|_| apple.clone());
        m.name = "two-layer".into();
        let below = m.layers[0];
        m.layers = vec![
            Layer {
                thickness: t,
                ..apple.layers[0]
            },
            below,
        ];
        m
    };
    let mut media: Vec<(String, LayeredMedium)> = vec![
        ("apple (1 rest layer)".into(), apple.clone()),
        (
            "skin-layered (2 layers)".into(),
            LayeredMedium::preset("skin-layered")?,
        ),
        (
            "sigma_a = 0".into(),
            with_apple("sigma_a=0", &|m| m.layers[0].sigma_a = Vec3::ZERO),
        ),
        (
            "sigma_s' = 0".into(),
            with_apple("sigma_s'=0", &|m| m.layers[0].sigma_s = Vec3::ZERO),
        ),
        (
            "sigma_s' = 1e-6".into(),
            with_apple("sigma_s'=1e-6", &|m| {
                m.layers[0].sigma_s = Vec3::splat(1e-6);
            }),
        ),
        (
            "sigma_s' = 1e6".into(),
            with_apple("sigma_s'=1e6", &|m| {
                m.layers[0].sigma_s = Vec3::splat(c_max)
            }),
        ),
        (
            "sigma_a = sigma_s = 1e6".into(),
            single("dense", c_max, c_max, 0.0, 1.3),
        ),
        (
            "vacuum (sigma_a = sigma_s = 0)".into(),
            single("vacuum", 0.0, 0.0, 0.0, 1.3),
        ),
    ];
    for g in [-g_max, g_max] {
        let mut thin = LayeredMedium::homogeneous("g", apple_sp, apple_sa, g, 1.3);
        thin.name = format!("g={g}");
        media.push((format!("g = {g}"), thin));
        media.push((
            format!("g = {g}, sigma_s = 1e6"),
            single("g-dense", 1e-3, c_max, g, 1.3),
        ));
    }
    for eta in [1.0, 1.5, 3.0, 0.5, 1e-3, 1e3] {
        let label = if eta == 1.0 {
            "eta = 1 (F_dr = 0)".to_string()
        } else {
            format!("eta = {eta}")
        };
        media.push((label, with_apple("eta", &|m| m.eta = eta)));
    }
    media.push(("2 layers, top 0 mm".into(), two(Thickness::Mm(0.0))));
    media.push(("2 layers, top 1e6 mm".into(), two(Thickness::Mm(1e6))));
    media.push((
        "2 layers, top f32::MAX mm".into(),
        two(Thickness::Mm(f32::MAX)),
    ));
    // In scene units the thickness overflows f32: f32::MAX mm at 1000 units per mm, and a
    // stack whose depths add up past f32::MAX at one unit per mm.
    let mut overflow = two(Thickness::Mm(f32::MAX));
    overflow.units_per_mm = 1e3;
    media.push((
        "2 layers, top f32::MAX mm, units_per_mm = 1e3".into(),
        overflow,
    ));
    let mut deep = two(Thickness::Mm(f32::MAX));
    deep.layers.insert(1, deep.layers[0]);
    deep.layers.insert(1, deep.layers[0]);
    deep.units_per_mm = 1.0;
    media.push((
        "3 layers of f32::MAX mm over rest, units_per_mm = 1".into(),
        deep,
    ));
    let mut no_rest = two(Thickness::Mm(1.0));
    no_rest.layers[1].thickness = Thickness::Mm(2.0);
    media.push(("2 constant layers, no rest".into(), no_rest));
    let mut alternating = apple.clone();
    alternating.name = "8-extremes".into();
    alternating.layers = vec![
        layer(0.0, c_max, g_max, Thickness::Mm(0.1)),
        layer(c_max, 0.0, -g_max, Thickness::Mm(0.0)),
        layer(0.0, 0.0, 0.0, Thickness::Mm(0.1)),
        layer(c_max, c_max, 0.5, Thickness::Mm(0.05)),
        layer(0.0, 1e-6, -g_max, Thickness::Mm(0.1)),
        layer(1e-3, 10.0, g_max, Thickness::Mm(0.0)),
        layer(0.05, 2.0, -0.5, Thickness::Mm(0.2)),
        Layer {
            thickness: Thickness::Rest,
            ..apple.layers[0]
        },
    ];
    media.push(("8 layers, alternating extremes".into(), alternating));
    let mut equal = apple.clone();
    equal.name = "8-equal".into();
    equal.layers = vec![
        Layer {
            thickness: Thickness::Mm(0.5),
            ..apple.layers[0]
        };
        8
    ];
    equal.layers[7].thickness = Thickness::Rest;
    media.push(("8 equal layers".into(), equal));
    for upm in [1e-3, 1e3] {
        media.push((
            format!("units_per_mm = {upm}"),
            with_apple("units", &|m| m.units_per_mm = upm),
        ));
    }
    // Every extreme at once: no absorption, limit scattering, the sharpest forward lobe, no
    // boundary; and the other way round.
    media.push((
        "corner: sigma_a 0, sigma_s 1e6, g 0.999, eta 1".into(),
        single("corner-dense", 0.0, c_max, g_max, 1.0),
    ));
    let mut clear = single("corner-clear", 0.0, 1e-6, -g_max, 1.0);
    clear
        .layers
        .insert(0, layer(0.0, 0.0, g_max, Thickness::Mm(f32::MAX)));
    media.push((
        "corner: vacuum f32::MAX mm over sigma_s 1e-6, g -0.999, eta 1".into(),
        clear,
    ));
    for (label, m) in &media {
        m.validate().map_err(|e| {
            LucentError::InvalidInput(format!("sweep layered: medium '{label}' is invalid: {e}"))
        })?;
    }
    Ok(media)
}

/// Every case: each medium in each situation.
pub fn layered_cases() -> Result<Vec<LayeredCase>> {
    let media = layered_media()?;
    let mut cases = Vec::with_capacity(media.len() * LayeredGeometry::ALL.len());
    for (label, medium) in media {
        for &(_, geometry) in LayeredGeometry::ALL {
            cases.push(LayeredCase {
                label: label.clone(),
                medium: medium.clone(),
                geometry,
            });
        }
    }
    Ok(cases)
}

/// The quick subset (`--quick`, the test): every medium back-lit (the situation with the
/// most light through the medium), and every situation with the two media where the extremes
/// meet (the corners).
pub fn quick_layered_cases() -> Result<Vec<LayeredCase>> {
    Ok(layered_cases()?
        .into_iter()
        .filter(|c| c.geometry == LayeredGeometry::BackLit || c.label.starts_with("corner"))
        .collect())
}

/// The camera of `geometry`.
fn camera(geometry: LayeredGeometry) -> Camera {
    let (eye, target) = match geometry {
        // Just above the tangent plane of the sphere's top (y = 1).
        LayeredGeometry::Grazing => (Vec3::new(0.0, 1.0 + 1e-4, 3.0), Vec3::new(0.0, 1.0, 0.0)),
        _ => (Vec3::new(0.0, 1.1, 2.4), CENTRE),
    };
    Camera {
        eye,
        target,
        fov_y_degrees: 45.0,
        near: 0.05,
        far: 50.0,
    }
}

/// The lights of `geometry`.
fn lights(geometry: LayeredGeometry) -> Vec<Light> {
    let front = Light::point(Vec3::new(1.2, 2.0, 2.0), Vec3::ONE, 20.0, 10.0);
    let back = Light::point(Vec3::new(0.0, 0.7, -1.5), Vec3::ONE, 20.0, 10.0);
    match geometry {
        LayeredGeometry::Front | LayeredGeometry::Grazing => vec![front],
        LayeredGeometry::BackLit => vec![back],
        LayeredGeometry::LightOnSurface => vec![Light::point(
            CENTRE + Vec3::Y * RADIUS,
            Vec3::ONE,
            5.0,
            10.0,
        )],
        LayeredGeometry::LightInside => vec![Light::point(CENTRE, Vec3::ONE, 5.0, 10.0)],
        LayeredGeometry::Directional => vec![Light::directional(
            Vec3::new(-0.4, -1.0, -0.5),
            Vec3::ONE,
            3.0,
        )],
        LayeredGeometry::Spot => {
            let position = Vec3::new(0.8, 2.2, 1.6);
            vec![Light {
                kind: LightKind::Spot {
                    position,
                    direction: CENTRE - position,
                    range: 10.0,
                    inner_degrees: 15.0,
                    outer_degrees: 30.0,
                },
                ..Light::point(position, Vec3::ONE, 30.0, 10.0)
            }]
        }
        LayeredGeometry::ShadowsOff => vec![
            Light {
                shadows: false,
                ..front
            },
            Light {
                shadows: false,
                ..back
            },
        ],
        LayeredGeometry::Intense => vec![
            Light {
                intensity: 1e5,
                ..front
            },
            Light {
                intensity: 1e5,
                ..back
            },
        ],
        LayeredGeometry::LightFarAway => vec![Light::point(
            Vec3::new(0.0, 0.5, -1e6),
            Vec3::ONE,
            1e12,
            2e6,
        )],
    }
}

/// The scene of one case: the layered sphere (object 0) on a floor (object 1).
pub fn case_scene(case: &LayeredCase) -> Result<Scene> {
    let sphere = generators::generate(Generator::Icosphere, SPHERE_LEVEL)?;
    let floor = Mesh::generate(Shape::Plane { half_size: 4.0 }, 1, 1);
    let mut material = Material::opaque("layered-sweep", Vec3::new(0.8, 0.7, 0.6), 0.3, 0.4);
    material.layers = Some(case.medium.clone());
    Ok(Scene {
        name: "sweep-layered".into(),
        meshes: vec![sphere, floor],
        objects: vec![
            Object {
                mesh: 0,
                transform: Mat4::from_translation(CENTRE) * Mat4::from_scale(Vec3::splat(RADIUS)),
                material,
            },
            Object {
                mesh: 1,
                transform: Mat4::IDENTITY,
                material: Material::opaque("floor", Vec3::new(0.55, 0.55, 0.5), 0.1, 0.8),
            },
        ],
        lights: lights(case.geometry),
        camera: camera(case.geometry),
        environment: crate::scene::Environment::constant(Vec3::splat(0.03)),
        sky: Vec3::splat(0.02),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    })
}

/// The surface points the references are evaluated at, each with the camera ray's direction:
/// the point facing the camera, points 60 and 89.9 degrees from it (towards +x), and the point
/// nearest the light (the light's own point when it is on the surface; any point when it is
/// at the centre).
fn surface_points(scene: &Scene) -> Vec<(&'static str, DVec3, DVec3)> {
    let c = CENTRE.as_dvec3();
    let r = f64::from(RADIUS);
    let eye = scene.camera.eye.as_dvec3();
    let v = (eye - c).normalize();
    let u = {
        let u = DVec3::Y.cross(v);
        if u.length_squared() > 1e-12 {
            u.normalize()
        } else {
            DVec3::X
        }
    };
    let at = |deg: f64| {
        let t = deg.to_radians();
        c + (v * t.cos() + u * t.sin()) * r
    };
    let mut points = vec![
        ("front", at(0.0)),
        ("60 deg", at(60.0)),
        ("89.9 deg", at(89.9)),
    ];
    if let Some(light) = scene.lights.first() {
        let towards = match light.kind {
            LightKind::Directional { direction } => -direction.as_dvec3(),
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                position.as_dvec3() - c
            }
        };
        let n = if towards.length_squared() > 0.0 {
            towards.normalize()
        } else {
            DVec3::Y
        };
        points.push(("nearest the light", c + n * r));
    }
    points
        .into_iter()
        .map(|(name, x)| (name, x, (x - eye).normalize()))
        .collect()
}

/// The spacing of the multiple-scattering reference's samples: the reference's default for
/// the medium, at least a fortieth of the sphere's diameter, and coarse enough that at most
/// [`MAX_SAMPLES`] samples are made (so [`SurfaceSamples::new`] never refuses it).
fn sample_spacing(scene: &Scene, medium: &LayeredMedium) -> f64 {
    let mesh = &scene.meshes[0];
    let transform = scene.objects[0].transform.as_dmat4();
    let mut longest: f64 = 0.0;
    for t in 0..mesh.triangle_count() {
        let [a, b, c] = mesh
            .triangle(t)
            .map(|p| transform.transform_point3(p.as_dvec3()));
        longest = longest
            .max((b - a).length())
            .max((c - b).length())
            .max((a - c).length());
    }
    // Each triangle is split into n^2 with n = ceil(edge / spacing) <= k.
    let k = ((MAX_SAMPLES / mesh.triangle_count().max(1)) as f64)
        .sqrt()
        .floor()
        .max(1.0);
    let floor = longest / k * (1.0 + 1e-9);
    SurfaceSamples::default_spacing(medium)
        .max(f64::from(RADIUS) / 20.0)
        .max(floor)
}

/// Evaluates the f64 references of `scene`'s layered sphere (object 0) and counts what they
/// gave.
pub fn check_references(scene: &Scene) -> ReferenceCounts {
    let mut counts = ReferenceCounts::default();
    let Some(medium) = scene.objects[0].material.layers.clone() else {
        counts.notes.push("no layered medium".into());
        return counts;
    };
    let points = surface_points(scene);
    for phase in [Phase::HenyeyGreenstein, Phase::Schlick] {
        let options = SingleScatteringOptions {
            phase,
            steps: SS_STEPS,
            ..Default::default()
        };
        for &(name, x, view) in &points {
            let what = format!("single {phase:?} at {name}");
            match single_scattering(scene, 0, x, view, &options) {
                Ok(l) => counts.radiance(&what, l),
                Err(e) => counts.error(&what, &e),
            }
        }
    }
    let spacing = sample_spacing(scene, &medium);
    match SurfaceSamples::new(scene, 0, spacing) {
        Ok(samples) => {
            counts.samples = samples.samples.len();
            for s in &samples.samples {
                for (c, e) in s.irradiance.to_array().into_iter().enumerate() {
                    counts.check(&format!("sample irradiance[{c}]"), e);
                }
            }
            for &(name, x, view) in &points {
                let what = format!("multiple at {name}");
                match multiple_scattering(scene, &samples, x, view) {
                    Ok(l) => counts.radiance(&what, l),
                    Err(e) => counts.error(&what, &e),
                }
            }
        }
        Err(e) => counts.error(&format!("surface samples (spacing {spacing:e})"), &e),
    }
    // The dipole of the first layer per channel in f64, the reference's own constants.
    let r = medium.first_layer_reduced();
    for c in 0..3 {
        let d = dipole_constants(
            f64::from(r.sigma_s_prime[c]),
            f64::from(r.sigma_a[c]),
            f64::from(medium.eta),
        );
        for (what, v) in [
            ("sigma_t'", d.sigma_t_prime),
            ("sigma_tr", d.sigma_tr),
            ("alpha'", d.alpha_prime),
            ("z_r", d.z_r),
            ("z_v", d.z_v),
            ("F_dr", d.f_dr),
            ("A", d.a),
        ] {
            counts.check(&format!("dipole[{c}] {what}"), v);
        }
        for radius in [0.0, 1e-12, 1e-6, d.z_r, 1.0, 1e6, 1e30] {
            counts.check(&format!("dipole[{c}] Rd({radius:e})"), d.rd(radius));
        }
        counts.check(
            &format!("dipole[{c}] total reflectance"),
            d.total_reflectance(),
        );
        for a in [0.0, 2.0 * spacing, f64::INFINITY] {
            counts.check(
                &format!("dipole[{c}] reflectance within {a:e}"),
                d.reflectance_within(a),
            );
        }
    }
    // The same constants in f32, as the scene hands them to the GPU.
    let d = medium.dipole_constants();
    for (what, v) in [
        ("sigma_tr", d.sigma_tr),
        ("z_r", d.z_r),
        ("z_v", d.z_v),
        ("alpha'", d.alpha_prime),
    ] {
        for (c, x) in v.to_array().into_iter().enumerate() {
            counts.check(&format!("f32 dipole {what}[{c}]"), f64::from(x));
        }
    }
    counts.check("f32 dipole F_dr", f64::from(d.f_dr));
    counts.check("f32 dipole A", f64::from(d.a));
    for i in 0..medium.layers.len() {
        for (c, x) in medium
            .sigma_t_per_unit(i)
            .to_array()
            .into_iter()
            .enumerate()
        {
            counts.check(&format!("layer[{i}] sigma_t per unit[{c}]"), f64::from(x));
        }
    }
    counts
}

/// Renders every case at `width` x `height` with the default frame settings, measures the
/// HDR and evaluates the references. `progress` is called after each case with its index.
pub fn run_layered(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    width: u32,
    height: u32,
    cases: &[LayeredCase],
    mut progress: impl FnMut(usize, &LayeredRow),
) -> Result<Vec<LayeredRow>> {
    let settings = FrameSettings {
        export_hdr: true,
        ..FrameSettings::new(width, height)
    };
    let mut rows = Vec::with_capacity(cases.len());
    for (i, case) in cases.iter().enumerate() {
        let scene = case_scene(case)?;
        let images = render_frame(gpu, shaders, pipeline_cache, &scene, settings).map_err(|e| {
            LucentError::InvalidInput(format!(
                "sweep layered: case '{}' / {}: {e}",
                case.label,
                case.geometry.name()
            ))
        })?;
        let hdr = count_hdr(&images.hdr.unwrap_or_default());
        let row = LayeredRow {
            case: case.clone(),
            hdr,
            reference: check_references(&scene),
        };
        progress(i, &row);
        rows.push(row);
    }
    Ok(rows)
}

/// The sweep as a Markdown table, one row per case, with a verdict line.
pub fn markdown(rows: &[LayeredRow], width: u32, height: u32, device: &str) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "## lucent sweep layered, {width}x{height}\n");
    let _ = writeln!(out, "- device: {device}");
    let _ = writeln!(out, "- cases: {}", rows.len());
    let sum = |f: &dyn Fn(&LayeredRow) -> usize| rows.iter().map(f).sum::<usize>();
    let (nan, inf) = (sum(&|r| r.hdr.nan), sum(&|r| r.hdr.inf));
    let (values, ref_bad) = (
        sum(&|r| r.reference.values),
        sum(&|r| r.reference.non_finite),
    );
    let errors = rows
        .iter()
        .filter(|r| !r.reference.notes.is_empty())
        .count();
    let _ = writeln!(
        out,
        "- verdict: {} ({nan} NaN, {inf} Inf in the frames; {ref_bad} non-finite of {values} \
         reference values; {errors} cases with notes)\n",
        if nan + inf + ref_bad == 0 {
            "stable"
        } else {
            "UNSTABLE"
        }
    );
    out.push_str(
        "| medium | situation | NaN | Inf | max | fp16 overflow | ref values | ref non-finite \
         | ref < 0 | ref max radiance | notes |\n",
    );
    out.push_str("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    for r in rows {
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {:.4e} | {} | {} | {} | {} | {:.4e} | {} |",
            r.case.label,
            r.case.geometry.name(),
            r.hdr.nan,
            r.hdr.inf,
            r.hdr.max,
            r.hdr.fp16_overflow,
            r.reference.values,
            r.reference.non_finite,
            r.reference.negative,
            r.reference.max_radiance,
            r.reference
                .notes
                .iter()
                .cloned()
                .chain(
                    (!r.reference.negatives.is_empty())
                        .then(|| format!("< 0: {}", r.reference.negatives.join(", "))),
                )
                .collect::<Vec<_>>()
                .join("; ")
                .replace('|', "/")
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_is_valid_and_every_extreme_is_there() {
        let cases = layered_cases().unwrap();
        let media = layered_media().unwrap();
        assert_eq!(cases.len(), media.len() * LayeredGeometry::ALL.len());
        for &(_, g) in LayeredGeometry::ALL {
            assert!(cases.iter().any(|c| c.geometry == g));
        }
        let any = |f: &dyn Fn(&LayeredMedium) -> bool| media.iter().any(|(_, m)| f(m));
        let layers = |m: &LayeredMedium| m.layers.clone();
        assert!(any(&|m| layers(m)
            .iter()
            .any(|l| l.sigma_s.max_element() == MAX_COEFFICIENT)));
        assert!(any(&|m| layers(m).iter().any(|l| l.sigma_a == Vec3::ZERO)));
        assert!(any(&|m| layers(m).iter().any(|l| l.sigma_s == Vec3::ZERO)));
        assert!(any(&|m| layers(m).iter().any(|l| l.g == MAX_ABS_G)));
        assert!(any(&|m| layers(m).iter().any(|l| l.g == -MAX_ABS_G)));
        assert!(any(&|m| m.eta == 1.0));
        assert!(any(&|m| layers(m)
            .iter()
            .any(|l| l.thickness == Thickness::Mm(0.0))));
        assert!(any(&|m| layers(m)
            .iter()
            .any(|l| l.thickness == Thickness::Mm(f32::MAX))));
        assert!(any(&|m| m.layers.len() == 1));
        assert!(any(&|m| m.layers.len() == 8));
        for case in &cases {
            let scene = case_scene(case).unwrap();
            for m in &scene.meshes {
                m.validate("sweep").unwrap();
            }
            for o in &scene.objects {
                o.material.validate().unwrap();
            }
            for (i, l) in scene.lights.iter().enumerate() {
                l.validate(&format!("light {i}")).unwrap();
            }
        }
        let quick = quick_layered_cases().unwrap();
        assert!(quick.len() < cases.len() / 3);
        for &(_, g) in LayeredGeometry::ALL {
            assert!(quick.iter().any(|c| c.geometry == g));
        }
    }

    #[test]
    fn the_light_on_the_surface_is_on_the_mesh_and_the_sphere() {
        let case = LayeredCase {
            label: "x".into(),
            medium: LayeredMedium::preset("apple").unwrap(),
            geometry: LayeredGeometry::LightOnSurface,
        };
        let scene = case_scene(&case).unwrap();
        let LightKind::Point { position, .. } = scene.lights[0].kind else {
            panic!("a point light");
        };
        let t = scene.objects[0].transform;
        assert!(scene.meshes[0]
            .positions
            .iter()
            .any(|p| t.transform_point3(*p) == position));
        assert_eq!((position - CENTRE).length(), RADIUS);
    }

    #[test]
    fn the_references_of_a_plain_medium_are_finite_and_lit() {
        let case = LayeredCase {
            label: "apple".into(),
            medium: LayeredMedium::preset("apple").unwrap(),
            geometry: LayeredGeometry::Front,
        };
        let scene = case_scene(&case).unwrap();
        let counts = check_references(&scene);
        assert_eq!(counts.non_finite, 0, "{:?}", counts.notes);
        assert!(counts.notes.is_empty(), "{:?}", counts.notes);
        assert!(counts.samples > 0 && counts.samples <= MAX_SAMPLES);
        assert!(counts.max_radiance > 0.0);
    }
}
