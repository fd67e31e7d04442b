//! Light from the environment: the ambient every technique's diffuse receives.
//!
//! Three kinds, one representation. A scene's [`Environment`] is a constant radiance (the
//! ambient lucent always had), a hemisphere (a sky radiance above the horizon, a ground
//! radiance below; +y is up) or an equirectangular radiance map (a Radiance `.hdr`, OpenEXR or
//! 8/16-bit file, or the built-in procedural [`BUILTIN_SKY`]). Whatever the kind, what a surface
//! receives is its diffuse irradiance `E(n)` over the cosine lobe around its normal, and that is
//! kept as nine spherical-harmonic coefficients per channel (Ramamoorthi and Hanrahan 2001,
//! "An Efficient Representation for Irradiance Environment Maps"): the radiance is projected on
//! the real SH basis up to band 2 and each band multiplied by the clamped cosine's
//! `Â_l = π, 2π/3, π/4`. Bands 3 and up of the cosine are zero for odd `l` and below 1.2% of
//! `Â_0` for even `l`, which is why nine numbers suffice for diffuse light.
//!
//! The GPU evaluates `E(n) / π` (the "ambient radiance" a Lambertian albedo multiplies) as a
//! polynomial in the normal's components, the SH constants folded into the coefficients on the
//! CPU ([`Environment::coefficients`]): `c0 + c1 y + c2 z + c3 x + c4 xy + c5 yz + c6 (3z² - 1)
//! + c7 xz + c8 (x² - y²)`. A constant environment is `c0` alone (exactly the old ambient); a
//! hemisphere is exact in bands 0 and 1 (`E / π = (sky + ground) / 2 + (sky - ground) / 2 · y`,
//! its band-2 projection is zero because the step is odd about the horizon). A map is
//! approximated; [`Environment::max_error`] measures how far against the brute-force integral
//! ([`Environment::irradiance_exact`]), the number `docs/environment.md` quotes.
//!
//! Numerics: the nine-term series of a map with a small bright sun rings and can go slightly
//! negative opposite the sun; both the shader and [`Environment::ambient_radiance`] clamp at 0
//! (irradiance cannot be negative). Maps with NaN, infinite or negative texels are refused with
//! the file's name (a negative or infinite radiance has no meaning, and one NaN would poison all
//! nine coefficients).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};

use super::texture::{decode_texture, TextureUsage};
use crate::{LucentError, Result};

/// Name of the built-in procedural sky map (`[environment] builtin = "sky"`, `--environment sky`).
pub const BUILTIN_SKY: &str = "sky";

/// Largest map texel count whose SH projection is summed at full resolution; bigger maps are
/// integrated over a box-filtered copy (a 4096x2048 map and a 256x128 copy give the same nine
/// coefficients to better than 1e-4 of the mean: band 2 is far smoother than a texel).
const MAX_INTEGRATED_TEXELS: usize = 1024 * 512;

/// What the environment is, as the scene file said it.
#[derive(Clone, Debug, PartialEq)]
pub enum EnvironmentKind {
    /// A uniform radiance from every direction.
    Constant(Vec3),
    /// `sky` radiance above the horizon (+y), `ground` below.
    Hemisphere {
        /// Radiance of the upper hemisphere.
        sky: Vec3,
        /// Radiance of the lower hemisphere.
        ground: Vec3,
    },
    /// An equirectangular radiance map, scaled by `intensity` and turned `rotation_degrees`
    /// about +y.
    Map {
        /// The file, or `None` for the built-in procedural sky.
        file: Option<PathBuf>,
        /// Radiance multiplier.
        intensity: f32,
        /// Rotation about the up axis, degrees (positive turns the map counter-clockwise seen
        /// from above).
        rotation_degrees: f32,
    },
}

/// An equirectangular radiance map in memory: linear RGB texels, row 0 at the zenith.
#[derive(Clone, Debug, PartialEq)]
pub struct RadianceMap {
    /// Width in texels (longitude).
    pub width: usize,
    /// Height in texels (latitude).
    pub height: usize,
    /// Linear radiance, row-major, top row first; finite and non-negative.
    pub texels: Vec<[f32; 3]>,
}

/// A scene's environment light: its description and its nine SH irradiance coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    /// What it is.
    pub kind: EnvironmentKind,
    /// `E(n) / π` as the polynomial of the module docs: coefficient `k` multiplies basis term
    /// `k` (1, y, z, x, xy, yz, 3z² - 1, xz, x² - y²), per channel.
    coefficients: [DVec3; 9],
    /// The radiance map (kind `Map`) as it was projected (box-filtered to at most
    /// [`MAX_INTEGRATED_TEXELS`]), kept for the brute-force reference and error reports.
    map: Option<std::sync::Arc<RadianceMap>>,
    /// A multiplier over everything above (`--environment-intensity`, the demo's knob): 1 as
    /// loaded.
    scale: f32,
}

/// SH normalisation constants of the nine real basis functions, in the polynomial order.
const SH_K: [f64; 9] = [
    0.282_094_791_773_878_1,  // 1 / (2 sqrt(pi))
    0.488_602_511_902_919_9,  // sqrt(3 / (4 pi)) y
    0.488_602_511_902_919_9,  // z
    0.488_602_511_902_919_9,  // x
    1.092_548_430_592_079_2,  // sqrt(15 / (4 pi)) xy
    1.092_548_430_592_079_2,  // yz
    0.315_391_565_252_520_05, // sqrt(5 / (16 pi)) (3z² - 1)
    1.092_548_430_592_079_2,  // xz
    0.546_274_215_296_039_6,  // sqrt(15 / (16 pi)) (x² - y²)
];

/// The clamped cosine's band weights divided by π (`Â_l / π` = 1, 2/3, 1/4), per coefficient.
const BAND_OVER_PI: [f64; 9] = [
    1.0,
    2.0 / 3.0,
    2.0 / 3.0,
    2.0 / 3.0,
    0.25,
    0.25,
    0.25,
    0.25,
    0.25,
];

/// The nine polynomial basis terms at unit direction `d`.
fn basis(d: DVec3) -> [f64; 9] {
    [
        1.0,
        d.y,
        d.z,
        d.x,
        d.x * d.y,
        d.y * d.z,
        3.0 * d.z * d.z - 1.0,
        d.x * d.z,
        d.x * d.x - d.y * d.y,
    ]
}

impl Environment {
    /// A uniform radiance `radiance` from every direction (lucent's classic ambient).
    pub fn constant(radiance: Vec3) -> Self {
        let mut coefficients = [DVec3::ZERO; 9];
        coefficients[0] = radiance.as_dvec3();
        Self {
            kind: EnvironmentKind::Constant(radiance),
            coefficients,
            map: None,
            scale: 1.0,
        }
    }

    /// A sky radiance above the horizon and a ground radiance below (exact in SH: see the
    /// module docs).
    pub fn hemisphere(sky: Vec3, ground: Vec3) -> Self {
        let (s, g) = (sky.as_dvec3(), ground.as_dvec3());
        let mut coefficients = [DVec3::ZERO; 9];
        coefficients[0] = (s + g) * 0.5;
        coefficients[1] = (s - g) * 0.5;
        Self {
            kind: EnvironmentKind::Hemisphere { sky, ground },
            coefficients,
            map: None,
            scale: 1.0,
        }
    }

    /// An equirectangular map read from `path` (HDR, EXR, PNG, JPEG, TGA; 8/16-bit files are
    /// sRGB-decoded), scaled and turned about +y. Errors name the file.
    pub fn from_file(path: &Path, intensity: f32, rotation_degrees: f32) -> Result<Self> {
        let map = load_radiance_map(path)?;
        Self::from_map(map, Some(path.to_path_buf()), intensity, rotation_degrees)
    }

    /// The built-in procedural sky ([`builtin_sky_map`]), scaled and turned about +y.
    pub fn builtin_sky(intensity: f32, rotation_degrees: f32) -> Result<Self> {
        Self::from_map(builtin_sky_map(), None, intensity, rotation_degrees)
    }

    /// An environment from a radiance map already in memory.
    pub fn from_map(
        map: RadianceMap,
        file: Option<PathBuf>,
        intensity: f32,
        rotation_degrees: f32,
    ) -> Result<Self> {
        let name = || {
            file.as_ref()
                .map_or_else(|| BUILTIN_SKY.to_string(), |p| p.display().to_string())
        };
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(LucentError::InvalidInput(format!(
                "environment {}: intensity {intensity} must be finite and >= 0",
                name()
            )));
        }
        if !rotation_degrees.is_finite() {
            return Err(LucentError::InvalidInput(format!(
                "environment {}: rotation_degrees {rotation_degrees} must be finite",
                name()
            )));
        }
        // Filtered once: the projection and every later brute-force integral read this copy.
        let map = integration_copy(map);
        let coefficients = project(&map, f64::from(intensity), rotation_degrees);
        Ok(Self {
            kind: EnvironmentKind::Map {
                file,
                intensity,
                rotation_degrees,
            },
            coefficients,
            map: Some(std::sync::Arc::new(map)),
            scale: 1.0,
        })
    }

    /// `E(n) / π` for unit normal `n` from the nine coefficients, clamped at 0 (the series of a
    /// map with a bright sun rings below zero opposite it): what the shaders compute, in f64.
    pub fn ambient_radiance(&self, n: DVec3) -> DVec3 {
        let b = basis(n);
        let e = self
            .coefficients
            .iter()
            .zip(b)
            .fold(DVec3::ZERO, |sum, (c, b)| sum + *c * b);
        (e * f64::from(self.scale)).max(DVec3::ZERO)
    }

    /// `E(n) / π` integrated exactly over the radiance (brute force over every texel of the
    /// map at the resolution it was projected from; closed forms for the constant and the
    /// hemisphere): the reference the SH approximation is measured against.
    pub fn irradiance_exact(&self, n: DVec3) -> DVec3 {
        match (&self.kind, &self.map) {
            (
                EnvironmentKind::Map {
                    intensity,
                    rotation_degrees,
                    ..
                },
                Some(map),
            ) => {
                let mut e = DVec3::ZERO;
                for_each_texel(map, *rotation_degrees, |d, solid_angle, radiance| {
                    let cos = d.dot(n);
                    if cos > 0.0 {
                        e += radiance * (cos * solid_angle);
                    }
                });
                e * (f64::from(*intensity) * f64::from(self.scale)) / PI
            }
            _ => self.ambient_radiance(n),
        }
    }

    /// The largest and mean relative error of the nine-coefficient irradiance against
    /// [`Self::irradiance_exact`] over `samples` normals spread evenly over the sphere
    /// (a Fibonacci lattice), relative to the mean exact irradiance (luminance): (max, mean).
    pub fn max_error(&self, samples: usize) -> (f64, f64) {
        let samples = samples.max(1);
        let lum = |c: DVec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        let mut errors = Vec::with_capacity(samples);
        let mut mean_exact = 0.0;
        for i in 0..samples {
            let n = fibonacci_direction(i, samples);
            let exact = self.irradiance_exact(n);
            mean_exact += lum(exact);
            errors.push(lum((self.ambient_radiance(n) - exact).abs()));
        }
        mean_exact /= samples as f64;
        if mean_exact <= 0.0 {
            return (0.0, 0.0);
        }
        let max = errors.iter().copied().fold(0.0, f64::max) / mean_exact;
        let mean = errors.iter().sum::<f64>() / samples as f64 / mean_exact;
        (max, mean)
    }

    /// The nine coefficients as the GPU's uniform buffer holds them (RGB); the first one's w
    /// is [`Self::bands`], so the shader evaluates only the bands in use (a constant
    /// environment costs what the old constant ambient cost).
    pub fn coefficients(&self) -> [[f32; 4]; 9] {
        let scale = f64::from(self.scale);
        let mut out = self.coefficients.map(|c| {
            let c = c * scale;
            [c.x as f32, c.y as f32, c.z as f32, 0.0]
        });
        out[0][3] = self.bands() as f32;
        out
    }

    /// The SH bands whose coefficients can be non-zero: 1 for a constant, 2 for a hemisphere
    /// (its band 2 is zero), 3 for a map.
    pub fn bands(&self) -> u32 {
        match self.kind {
            EnvironmentKind::Constant(_) => 1,
            EnvironmentKind::Hemisphere { .. } => 2,
            EnvironmentKind::Map { .. } => 3,
        }
    }

    /// The mean radiance over the sphere (band 0): what a constant environment of the same
    /// energy would be.
    pub fn mean_radiance(&self) -> Vec3 {
        (self.coefficients[0] * f64::from(self.scale)).as_vec3()
    }

    /// The multiplier over the environment as loaded (1 as loaded).
    pub fn intensity(&self) -> f32 {
        self.scale
    }

    /// Sets the multiplier over the environment as loaded (`--environment-intensity`, the
    /// demo's knob); a value that is not finite or is negative is taken as 0 (guarded where
    /// it is born: the uniforms never see NaN).
    pub fn set_intensity(&mut self, scale: f32) {
        self.scale = if scale.is_finite() {
            scale.max(0.0)
        } else {
            0.0
        };
    }

    /// This environment with its radiance multiplied by `factor`.
    pub fn scaled(&self, factor: f32) -> Self {
        let mut out = self.clone();
        out.set_intensity(self.scale * factor);
        out
    }

    /// One line for `lucent inspect` and logs.
    pub fn describe(&self) -> String {
        let what = match &self.kind {
            EnvironmentKind::Constant(c) => format!("constant radiance {}", fmt3(*c)),
            EnvironmentKind::Hemisphere { sky, ground } => {
                format!("hemisphere: sky {}, ground {}", fmt3(*sky), fmt3(*ground))
            }
            EnvironmentKind::Map {
                file,
                intensity,
                rotation_degrees,
            } => format!(
                "map {} x{intensity} turned {rotation_degrees} deg (SH9 irradiance, mean radiance {})",
                file.as_ref()
                    .map_or_else(|| format!("builtin:{BUILTIN_SKY}"), |p| p.display().to_string()),
                fmt3(self.mean_radiance())
            ),
        };
        if self.scale == 1.0 {
            what
        } else {
            format!("{what}, intensity x{}", self.scale)
        }
    }
}

/// The environments `--environment` names besides a file path.
pub const COMMAND_LINE_ENVIRONMENTS: &[(&str, &str)] = &[
    ("scene", "the scene's own (the default)"),
    ("none", "no environment light (black)"),
    (
        "constant",
        "the classic constant ambient, radiance [0.03, 0.035, 0.04]",
    ),
    (
        "hemisphere",
        "a blue-grey sky [0.25, 0.3, 0.4] over a brown ground [0.08, 0.07, 0.06]",
    ),
    ("sky", "the built-in procedural sky map (SH9)"),
];

/// The environment a command line asks for: one of [`COMMAND_LINE_ENVIRONMENTS`] or the path
/// of an equirectangular map; `None` for `scene` (keep the scene's).
pub fn from_command_line(spec: &str) -> Result<Option<Environment>> {
    let environment = match spec {
        "scene" => return Ok(None),
        "none" => Environment::constant(Vec3::ZERO),
        "constant" => Environment::constant(Vec3::new(0.03, 0.035, 0.04)),
        "hemisphere" => {
            Environment::hemisphere(Vec3::new(0.25, 0.3, 0.4), Vec3::new(0.08, 0.07, 0.06))
        }
        "sky" => Environment::builtin_sky(1.0, 0.0)?,
        path => {
            let path = Path::new(path);
            if !path.exists() {
                return Err(LucentError::file(
                    path,
                    format!(
                        "environment map not found (--environment takes a file or one of: {})",
                        COMMAND_LINE_ENVIRONMENTS
                            .iter()
                            .map(|(n, _)| *n)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
            Environment::from_file(path, 1.0, 0.0)?
        }
    };
    Ok(Some(environment))
}

fn fmt3(v: Vec3) -> String {
    format!("[{:.3}, {:.3}, {:.3}]", v.x, v.y, v.z)
}

/// Direction `i` of `count` spread evenly over the sphere (a spherical Fibonacci lattice).
pub fn fibonacci_direction(i: usize, count: usize) -> DVec3 {
    let golden = PI * (3.0 - 5f64.sqrt());
    let y = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
    let r = (1.0 - y * y).max(0.0).sqrt();
    let phi = golden * i as f64;
    DVec3::new(r * phi.cos(), y, r * phi.sin())
}

/// The map's SH projection with the cosine convolved in, in polynomial form.
fn project(map: &RadianceMap, intensity: f64, rotation_degrees: f32) -> [DVec3; 9] {
    let mut sh = [DVec3::ZERO; 9];
    for_each_texel(map, rotation_degrees, |d, solid_angle, radiance| {
        for (k, b) in basis(d).into_iter().enumerate() {
            // L_k = ∫ L Y_k dω with Y_k = K_k b_k.
            sh[k] += radiance * (b * SH_K[k] * solid_angle);
        }
    });
    std::array::from_fn(|k| sh[k] * (BAND_OVER_PI[k] * SH_K[k] * intensity))
}

/// `map`, or a box-filtered copy of at most [`MAX_INTEGRATED_TEXELS`] texels.
fn integration_copy(map: RadianceMap) -> RadianceMap {
    let mut factor = 1;
    while (map.width / factor).max(1) * (map.height / factor).max(1) > MAX_INTEGRATED_TEXELS {
        factor *= 2;
    }
    if factor == 1 {
        return map;
    }
    let (w, h) = ((map.width / factor).max(1), (map.height / factor).max(1));
    let mut texels = vec![[0.0f32; 3]; w * h];
    for (y, row) in texels.chunks_mut(w).enumerate() {
        for (x, out) in row.iter_mut().enumerate() {
            let mut sum = [0.0f64; 3];
            let mut n = 0.0f64;
            for sy in y * factor..((y + 1) * factor).min(map.height) {
                for sx in x * factor..((x + 1) * factor).min(map.width) {
                    let t = map.texels[sy * map.width + sx];
                    for c in 0..3 {
                        sum[c] += f64::from(t[c]);
                    }
                    n += 1.0;
                }
            }
            *out = sum.map(|s| (s / n.max(1.0)) as f32);
        }
    }
    RadianceMap {
        width: w,
        height: h,
        texels,
    }
}

/// Calls `f(direction, solid angle, radiance)` for every texel of an equirectangular map
/// turned `rotation_degrees` about +y (counter-clockwise seen from above, as a positive
/// rotation about +y turns a direction). Texel (x, y) covers longitudes
/// `φ ∈ [2π x / w, 2π (x + 1) / w) - π - rotation` and polar angles `θ ∈ [π y / h, π (y + 1) / h)`;
/// its direction is its centre's, `(sin θ sin φ, cos θ, -sin θ cos φ)` (the map's centre
/// column looks down -z), and its solid angle exact: `(cos θ0 - cos θ1) Δφ`.
fn for_each_texel(map: &RadianceMap, rotation_degrees: f32, mut f: impl FnMut(DVec3, f64, DVec3)) {
    let (w, h) = (map.width.max(1), map.height.max(1));
    let d_phi = 2.0 * PI / w as f64;
    let rotation = f64::from(rotation_degrees).to_radians();
    for y in 0..h {
        let theta0 = PI * y as f64 / h as f64;
        let theta1 = PI * (y + 1) as f64 / h as f64;
        let theta = 0.5 * (theta0 + theta1);
        let solid_angle = (theta0.cos() - theta1.cos()) * d_phi;
        let (sin_t, cos_t) = theta.sin_cos();
        for x in 0..w {
            let phi = d_phi * (x as f64 + 0.5) - PI - rotation;
            let (sin_p, cos_p) = phi.sin_cos();
            let d = DVec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p);
            let t = map.texels[y * w + x];
            f(
                d,
                solid_angle,
                DVec3::new(t[0].into(), t[1].into(), t[2].into()),
            );
        }
    }
}

/// Reads an equirectangular radiance map. Float files (HDR, EXR) are linear; 8/16-bit ones are
/// sRGB-decoded. NaN, infinite or negative texels are an error naming the file and a texel.
pub fn load_radiance_map(path: &Path) -> Result<RadianceMap> {
    let decoded = decode_texture(path, TextureUsage::Color)?;
    let bad = decoded.non_finite();
    if bad > 0 {
        return Err(LucentError::file(
            path,
            format!(
                "environment map has {bad} NaN or infinite values; a radiance map must be finite"
            ),
        ));
    }
    let (w, h) = (decoded.width as usize, decoded.height as usize);
    if w == 0 || h == 0 {
        return Err(LucentError::file(
            path,
            format!("environment map is {w}x{h}: it has no texels"),
        ));
    }
    if w != 2 * h {
        log::warn!(
            "{}: environment map is {w}x{h}, not 2:1; read as equirectangular all the same",
            path.display()
        );
    }
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let t = decoded.texel(x, y);
            if let Some(c) = t[..3].iter().find(|v| **v < 0.0) {
                return Err(LucentError::file(
                    path,
                    format!("environment map texel ({x}, {y}) has negative radiance {c}"),
                ));
            }
            texels.push([t[0], t[1], t[2]]);
        }
    }
    Ok(RadianceMap {
        width: w,
        height: h,
        texels,
    })
}

/// The built-in sky, 256x128 texels of linear radiance, scaled to the range of lucent's
/// scenes (mean radiance about 0.1, a fill beside their point lights of intensity 10-30): a
/// blue zenith paling to a bright horizon, a warm sun 35° above the horizon in the -x, -z quadrant (about 0.5° wide stretched
/// to 4° so a 256-texel map resolves it, radiance scaled so its irradiance is a plausible
/// late-afternoon sun's share), and a dim brown-green ground. Everything is a closed form of
/// the direction, so the map is the same on every machine.
pub fn builtin_sky_map() -> RadianceMap {
    let (w, h) = (256usize, 128usize);
    let sun = DVec3::new(-0.55, 35f64.to_radians().sin(), -0.45).normalize();
    let sun_cos = (2f64).to_radians().cos();
    let mut texels = Vec::with_capacity(w * h);
    for y in 0..h {
        let theta = PI * (y as f64 + 0.5) / h as f64;
        for x in 0..w {
            let phi = 2.0 * PI * (x as f64 + 0.5) / w as f64 - PI;
            let d = DVec3::new(
                theta.sin() * phi.sin(),
                theta.cos(),
                -theta.sin() * phi.cos(),
            );
            let radiance = if d.y >= 0.0 {
                let zenith = DVec3::new(0.045, 0.08, 0.155);
                let horizon = DVec3::new(0.19, 0.205, 0.225);
                let t = (1.0 - d.y).powi(4);
                let sky = zenith.lerp(horizon, t);
                // A soft glow around the sun, then the disc.
                let c = d.dot(sun);
                let glow = DVec3::new(1.0, 0.75, 0.5) * (0.15 * c.max(0.0).powi(24));
                let disc = if c >= sun_cos {
                    DVec3::new(15.0, 13.0, 10.5)
                } else {
                    DVec3::ZERO
                };
                sky + glow + disc
            } else {
                // The ground: darker straight down, a little lighter toward the horizon.
                let t = (-d.y).sqrt();
                DVec3::new(0.04, 0.035, 0.025).lerp(DVec3::new(0.018, 0.02, 0.012), t)
            };
            texels.push([radiance.x as f32, radiance.y as f32, radiance.z as f32]);
        }
    }
    RadianceMap {
        width: w,
        height: h,
        texels,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_constant_environment_is_the_old_ambient_exactly() {
        let env = Environment::constant(Vec3::new(0.03, 0.035, 0.04));
        for i in 0..50 {
            let n = fibonacci_direction(i, 50);
            assert_eq!(
                env.ambient_radiance(n),
                Vec3::new(0.03, 0.035, 0.04).as_dvec3()
            );
        }
    }

    #[test]
    fn a_hemisphere_is_exact_against_its_closed_form() {
        let (sky, ground) = (Vec3::new(0.4, 0.5, 0.8), Vec3::new(0.1, 0.08, 0.05));
        let env = Environment::hemisphere(sky, ground);
        // Up sees only the sky, down only the ground, sideways half of each.
        assert!((env.ambient_radiance(DVec3::Y) - sky.as_dvec3()).length() < 1e-12);
        assert!((env.ambient_radiance(DVec3::NEG_Y) - ground.as_dvec3()).length() < 1e-12);
        let side = (sky.as_dvec3() + ground.as_dvec3()) * 0.5;
        assert!((env.ambient_radiance(DVec3::X) - side).length() < 1e-12);
        // A map of the same hemisphere projects to the same coefficients.
        let (w, h) = (512, 256);
        let texels = (0..w * h)
            .map(|i| {
                let c = if i / w < h / 2 { sky } else { ground };
                [c.x, c.y, c.z]
            })
            .collect();
        let map = Environment::from_map(
            RadianceMap {
                width: w,
                height: h,
                texels,
            },
            None,
            1.0,
            0.0,
        )
        .unwrap();
        for i in 0..64 {
            let n = fibonacci_direction(i, 64);
            let (a, b) = (map.ambient_radiance(n), env.ambient_radiance(n));
            assert!((a - b).abs().max_element() < 2e-3, "{n}: {a} vs {b}");
            // The brute-force integral of the map agrees with the closed form too.
            let exact = map.irradiance_exact(n);
            assert!(
                (exact - b).abs().max_element() < 2e-3,
                "{n}: {exact} vs {b}"
            );
        }
    }

    #[test]
    fn the_builtin_sky_is_within_the_measured_sh9_error() {
        let env = Environment::builtin_sky(1.0, 0.0).unwrap();
        let (max, mean) = env.max_error(200);
        eprintln!("built-in sky, SH9 against the exact integral: max {max:.4}, mean {mean:.4}");
        // Measured: max 0.029, mean 0.0094 of the mean irradiance (docs/environment.md); a
        // small sun is the hardest case for nine coefficients.
        assert!(max < 0.05 && mean < 0.02, "max {max}, mean {mean}");
        for i in 0..200 {
            let e = env.ambient_radiance(fibonacci_direction(i, 200));
            assert!(e.is_finite() && e.min_element() >= 0.0);
        }
    }

    #[test]
    fn rotating_the_map_turns_the_light() {
        let a = Environment::builtin_sky(1.0, 0.0).unwrap();
        let b = Environment::builtin_sky(1.0, 90.0).unwrap();
        // Turning the map by 90° about +y moves what -x saw to a direction 90° away about y.
        let n = DVec3::new(-0.8, 0.6, 0.0);
        let turned = glam::DQuat::from_rotation_y(90f64.to_radians()) * n;
        let (ea, eb) = (a.ambient_radiance(n), b.ambient_radiance(turned));
        assert!((ea - eb).abs().max_element() < 1e-3, "{ea} vs {eb}");
    }

    #[test]
    fn extreme_maps_stay_finite_and_non_negative() {
        // A single blinding texel in a black map: the worst ringing nine coefficients can have.
        let (w, h) = (64, 32);
        let mut texels = vec![[0.0f32; 3]; w * h];
        texels[10 * w + 20] = [6.0e4, 6.0e4, 6.0e4];
        let env = Environment::from_map(
            RadianceMap {
                width: w,
                height: h,
                texels,
            },
            None,
            1.0e3,
            0.0,
        )
        .unwrap();
        for i in 0..500 {
            let e = env.ambient_radiance(fibonacci_direction(i, 500));
            assert!(e.is_finite() && e.min_element() >= 0.0, "{e}");
        }
        assert!(Environment::builtin_sky(f32::NAN, 0.0).is_err());
        assert!(Environment::builtin_sky(-1.0, 0.0).is_err());
        assert!(Environment::builtin_sky(1.0, f32::INFINITY).is_err());
    }

    #[test]
    fn large_maps_are_integrated_over_a_filtered_copy_with_the_same_result() {
        let sky = builtin_sky_map();
        // Upsample the sky 8x per side (2048x1024 = 2M texels, filtered back for the
        // projection): the coefficients must agree with the original's.
        let (w, h) = (sky.width * 8, sky.height * 8);
        let texels = (0..w * h)
            .map(|i| sky.texels[(i / w / 8) * sky.width + (i % w) / 8])
            .collect();
        let big = Environment::from_map(
            RadianceMap {
                width: w,
                height: h,
                texels,
            },
            None,
            1.0,
            0.0,
        )
        .unwrap();
        let small = Environment::builtin_sky(1.0, 0.0).unwrap();
        for (a, b) in big.coefficients().iter().zip(small.coefficients()) {
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() < 2e-3, "{a:?} vs {b:?}");
            }
        }
    }
}
