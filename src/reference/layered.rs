//! f64 references for Li et al.'s (2009) layered subsurface scattering: the numbers the GPU
//! passes are checked against.
//!
//! - Phase functions: true Henyey-Greenstein ([`henyey_greenstein`]) and Schlick's
//!   approximation ([`schlick`], `k = 1.55 g - 0.55 g^3`; Li et al.'s eq. 9 is this form with
//!   `g` in place of `k`), and how far apart they are ([`phase_difference`]).
//! - The boundary: exact unpolarised Fresnel transmittance ([`fresnel_transmittance`]) and
//!   refraction with total internal reflection ([`refract`]).
//! - The planar-layer model ([`LayerStack`], [`LayerStack::optical_depth`]), which the GPU uses
//!   too.
//! - [`single_scattering`]: the view ray refracted in and marched to where it leaves the object,
//!   light from every light entering on the straight line to each point (ray traced, shadowed).
//! - [`multiple_scattering`]: Jensen's dipole of the first layer integrated over the object's
//!   whole surface ([`SurfaceSamples`], built once per object and reused across pixels).
//!
//! Direction convention: a direction is the way light travels. The phase functions take the
//! cosine between the incoming and the outgoing propagation directions, so `g > 0` (forward
//! scattering) peaks at `cos = 1`.
//!
//! Geometry: the ray tracing is [`super::raytrace::intersect`] against the objects' analytic
//! shapes (the exact surfaces the meshes approximate). Single scattering needs a closed shape
//! (a sphere); multiple scattering integrates over the object's mesh triangles, each sample
//! projected onto the analytic surface so shadow rays start on it.

use std::f64::consts::PI;

use super::lighting::{light_incidence, radiance};
use super::raytrace::intersect;
use super::DVec3;
use crate::scene::albedo::diffuse_transmittance;
use crate::scene::layered::{
    dipole_constants, Dipole, LayeredMedium, Thickness, MAX_ABS_G,
};
use crate::scene::{Light, LightKind, Scene, Shape};
use crate::{LucentError, Result};

/// Clamps `g` to |g| <= 0.999 ([`MAX_ABS_G`]): both phase functions peak like 1/(1 - |g|)^2 and
/// |g| = 1 is a delta no quadrature resolves. NaN becomes 0 (isotropic).
fn clamp_g(g: f64) -> f64 {
    let m = f64::from(MAX_ABS_G);
    if g.is_nan() {
        0.0
    } else {
        g.clamp(-m, m)
    }
}

/// Henyey-Greenstein per steradian, |g| clamped to 0.999 (the scene's own, which the medium's
/// albedo split integrates with).
pub use crate::scene::albedo::henyey_greenstein;

/// Schlick's `k` for a Henyey-Greenstein `g`: `1.55 g - 0.55 g^3`, clamped to |k| <= 0.999
/// (the cubic exceeds 1 for g above about 0.95, which would make the phase function negative).
pub fn schlick_k(g: f64) -> f64 {
    let g = clamp_g(g);
    let m = f64::from(MAX_ABS_G);
    (1.55 * g - 0.55 * g * g * g).clamp(-m, m)
}

/// Schlick's phase function `(1 - k^2) / (4 pi (1 - k cos)^2)` with `k = schlick_k(g)`, per
/// steradian; normalised exactly for |k| < 1. The base `1 - k cos` is written
/// `(1 - k) + k (1 - cos)` for the same reason as [`henyey_greenstein`]'s.
pub fn schlick(g: f64, cos_theta: f64) -> f64 {
    let k = schlick_k(g);
    let c = cos_theta.clamp(-1.0, 1.0);
    let base = (1.0 - k) + k * (1.0 - c);
    (1.0 - k * k) / (4.0 * PI * base * base)
}

/// Which phase function a reference evaluates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// [`henyey_greenstein`].
    HenyeyGreenstein,
    /// [`schlick`].
    Schlick,
}

impl Phase {
    /// The phase function at `cos_theta` for anisotropy `g`.
    pub fn eval(self, g: f64, cos_theta: f64) -> f64 {
        match self {
            Phase::HenyeyGreenstein => henyey_greenstein(g, cos_theta),
            Phase::Schlick => schlick(g, cos_theta),
        }
    }
}

/// How far Schlick's form is from true HG for `g`: (largest, mean) absolute difference per
/// steradian over 4001 values of cos theta evenly spaced in [-1, 1].
pub fn phase_difference(g: f64) -> (f64, f64) {
    let n = 4001;
    let mut max: f64 = 0.0;
    let mut sum = 0.0;
    for i in 0..n {
        let c = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
        let d = (henyey_greenstein(g, c) - schlick(g, c)).abs();
        max = max.max(d);
        sum += d;
    }
    (max, sum / n as f64)
}

/// Exact unpolarised Fresnel transmittance `1 - (R_s + R_p)/2` of a dielectric boundary for light
/// arriving at `cos_i` (cosine with the normal on its side, clamped to [0, 1]) from a medium of
/// index `n_i` into one of `n_t`, `eta = n_t / n_i`. 0 under total internal reflection
/// (`eta < 1` past the critical angle) and at grazing incidence; 1 exactly at `eta` = 1.
pub fn fresnel_transmittance(cos_i: f64, eta: f64) -> f64 {
    if eta == 1.0 {
        return 1.0;
    }
    if !(eta.is_finite() && eta > 0.0) {
        return 0.0;
    }
    let ci = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - ci * ci) / (eta * eta);
    if sin2_t >= 1.0 {
        return 0.0;
    }
    let ct = (1.0 - sin2_t).sqrt();
    // Both denominators are > 0: ct > 0 here and ci, eta >= 0.
    let rs = (ci - eta * ct) / (ci + eta * ct);
    let rp = (eta * ci - ct) / (eta * ci + ct);
    (1.0 - 0.5 * (rs * rs + rp * rp)).clamp(0.0, 1.0)
}

/// `dir` (unit, travelling) refracted through a boundary with unit normal `normal` on the
/// incident side (`dot(dir, normal) < 0`; a normal facing the other way is flipped), from index
/// `n_i` into `n_t`, `eta = n_t / n_i`. `None` under total internal reflection.
pub fn refract(dir: DVec3, normal: DVec3, eta: f64) -> Option<DVec3> {
    let n = if dir.dot(normal) > 0.0 {
        -normal
    } else {
        normal
    };
    let cos_i = (-dir.dot(n)).clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    // NaN (eta = 0) fails too.
    if sin2_t.is_nan() || sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((dir / eta + n * (cos_i / eta - cos_t)).normalize())
}

/// One layer of a [`LayerStack`], in scene units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StackLayer {
    /// Depth of its top below the reference surface point (units; -inf for the first layer).
    pub top: f64,
    /// Depth of its bottom (units; +inf for a semi-infinite layer).
    pub bottom: f64,
    /// Extinction `sigma_a + sigma_s` per channel, 1/unit.
    pub sigma_t: DVec3,
    /// Scattering `sigma_s` per channel, 1/unit.
    pub sigma_s: DVec3,
    /// Henyey-Greenstein anisotropy.
    pub g: f64,
}

/// The planar-layer model of a layered medium at one reference surface point `P` with outward
/// unit normal `n`: a point `X` inside lies at depth `dot(P - X, n)`, and layer `j` holds the
/// depths `[top_j, bottom_j)`, the layers stacked from depth 0 in order. Points above the
/// tangent plane (negative depth, inside a concave part) belong to the first layer: its `top`
/// is -inf. Below the last layer's bottom there is no medium (no extinction, no scattering);
/// a `rest` layer has bottom +inf. The GPU evaluates the same model.
#[derive(Clone, Debug, PartialEq)]
pub struct LayerStack {
    /// The layers, outermost first.
    pub layers: Vec<StackLayer>,
}

impl LayerStack {
    /// The stack of `medium` in scene units; `texels` are the depth textures' texels at the
    /// reference point (see [`LayeredMedium::thickness_mm`]; empty reads 0 for texture layers).
    pub fn from_medium(medium: &LayeredMedium, texels: &[[f32; 4]]) -> Self {
        let upm = f64::from(medium.units_per_mm);
        let mut depth = 0.0;
        let layers = medium
            .layers
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let thickness = match l.thickness {
                    Thickness::Rest => f64::INFINITY,
                    _ => f64::from(medium.thickness_mm(i, texels)) * upm,
                };
                let top = if i == 0 { f64::NEG_INFINITY } else { depth };
                depth += thickness;
                StackLayer {
                    top,
                    bottom: depth,
                    sigma_t: l.sigma_t().as_dvec3() / upm,
                    sigma_s: l.sigma_s.as_dvec3() / upm,
                    g: f64::from(l.g),
                }
            })
            .collect();
        Self { layers }
    }

    /// The layer holding `depth`, if any.
    pub fn layer_at(&self, depth: f64) -> Option<&StackLayer> {
        self.layers
            .iter()
            .find(|l| depth >= l.top && depth < l.bottom)
    }

    /// Per layer, the length of segment `a`-`b` whose depth (below `p` with outward normal `n`)
    /// lies in that layer's `[top, bottom)`. The depth is linear along the segment, so each
    /// length is `|b - a|` times the overlap of the layer's parameter interval with [0, 1].
    pub fn lengths(&self, p: DVec3, n: DVec3, a: DVec3, b: DVec3) -> Vec<f64> {
        let len = (b - a).length();
        let (da, db) = ((p - a).dot(n), (p - b).dot(n));
        let slope = db - da;
        self.layers
            .iter()
            .map(|l| {
                if len == 0.0 {
                    return 0.0;
                }
                if slope.abs() < 1e-300 {
                    // Parallel to the layers: all of it or none.
                    return if da >= l.top && da < l.bottom {
                        len
                    } else {
                        0.0
                    };
                }
                let (t0, t1) = ((l.top - da) / slope, (l.bottom - da) / slope);
                let (lo, hi) = (t0.min(t1).max(0.0), t0.max(t1).min(1.0));
                (hi - lo).max(0.0) * len
            })
            .collect()
    }

    /// Optical depth of segment `a`-`b` per channel: `sum_j sigma_t,j * length_j` with the
    /// lengths of [`Self::lengths`] (layers relative to `p`, `n`).
    pub fn optical_depth(&self, p: DVec3, n: DVec3, a: DVec3, b: DVec3) -> DVec3 {
        self.lengths(p, n, a, b)
            .iter()
            .zip(&self.layers)
            .map(|(len, l)| l.sigma_t * *len)
            .sum()
    }
}

/// The layered medium of `scene.objects[object]`, or an error naming what is missing.
fn medium_of(scene: &Scene, object: usize) -> Result<&LayeredMedium> {
    let o = scene.objects.get(object).ok_or_else(|| {
        LucentError::InvalidInput(format!("scene '{}' has no object {object}", scene.name))
    })?;
    o.material.layers.as_ref().ok_or_else(|| {
        LucentError::InvalidInput(format!(
            "object {object} (material '{}') has no layered medium",
            o.material.name
        ))
    })
}

/// The analytic shape and transform of an object, or an error (the reference would miss it).
fn shape_of(scene: &Scene, object: usize) -> Result<(Shape, glam::DMat4)> {
    let o = &scene.objects[object];
    let shape = scene.meshes[o.mesh].shape.ok_or_else(|| {
        LucentError::InvalidInput(format!(
            "object {object}: the layered reference ray-traces analytic shapes and its mesh has none"
        ))
    })?;
    Ok((shape, o.transform.as_dmat4()))
}

/// `p` (world) moved onto the object's analytic surface, with the outward unit normal there.
fn project_to_surface(shape: Shape, transform: &glam::DMat4, p: DVec3) -> (DVec3, DVec3) {
    let inv = transform.inverse();
    let q = inv.transform_point3(p);
    let (q, n) = match shape {
        Shape::Sphere { radius } => {
            let r = f64::from(radius);
            let dir = if q.length_squared() > 0.0 {
                q.normalize()
            } else {
                DVec3::Y
            };
            (dir * r, dir)
        }
        Shape::Plane { .. } => (DVec3::new(q.x, 0.0, q.z), DVec3::Y),
    };
    let normal_matrix = glam::DMat3::from_mat4(inv).transpose();
    (
        transform.transform_point3(q),
        (normal_matrix * n).normalize(),
    )
}

/// Where a ray from `origin`, inside the closed `shape`, leaves it: the far root of the sphere,
/// never negative (a point on the surface leaves at once). Only spheres enclose a volume.
fn exit_distance(shape: Shape, transform: &glam::DMat4, origin: DVec3, dir: DVec3) -> Option<f64> {
    let Shape::Sphere { radius } = shape else {
        return None;
    };
    let inv = transform.inverse();
    let o = inv.transform_point3(origin);
    let d = inv.transform_vector3(dir);
    let r = f64::from(radius);
    let a = d.length_squared();
    let b = o.dot(d);
    // From inside c <= 0 and the discriminant is >= b^2; clamp rounding at the surface.
    let c = (o.length_squared() - r * r).min(0.0);
    let disc = (b * b - a * c).max(0.0);
    Some(((-b + disc.sqrt()) / a).max(0.0))
}

/// Whether the segment from `from` towards `light` reaches it unblocked by any object of the
/// scene (shadow ray from a surface point, nudged off the surface along `normal`).
fn visible(scene: &Scene, from: DVec3, normal: DVec3, light: &Light, to_light: DVec3) -> bool {
    // Off the surface by a relative epsilon: the shadow ray must not hit the surface it leaves.
    let origin = from + normal * (1e-7 * (1.0 + from.length()));
    let max_t = match light.kind {
        LightKind::Directional { .. } => f64::INFINITY,
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
            (position.as_dvec3() - origin).length()
        }
    };
    for o in &scene.objects {
        if let Some(shape) = scene.meshes[o.mesh].shape {
            if let Some((t, _)) = intersect(shape, &o.transform.as_dmat4(), origin, to_light) {
                if t < max_t {
                    return false;
                }
            }
        }
    }
    true
}

/// Light from `light` entering the closed `shape` on its way to inside point `m`: where the
/// segment from `m` towards the light leaves the shape, and what crosses the boundary there.
struct EnteringLight {
    /// Direction from `m` towards the light.
    to_light: DVec3,
    /// The entry point `P'` on the analytic surface.
    point: DVec3,
    /// The outward normal there.
    normal: DVec3,
    /// Radiance x falloff at `P'` x Fresnel transmittance (RGB).
    radiance: DVec3,
}

/// [`EnteringLight`] of `light` for `m`, or `None` when none enters: the light arrives from
/// behind the entry surface, its falloff is 0 there, or another object blocks it.
fn entering_light(
    scene: &Scene,
    shape: Shape,
    transform: &glam::DMat4,
    light: &Light,
    m: DVec3,
    eta: f64,
) -> Option<EnteringLight> {
    let (to_light, _) = light_incidence(light, m);
    let d = exit_distance(shape, transform, m, to_light)?;
    let (point, normal) = project_to_surface(shape, transform, m + to_light * d);
    let (_, attenuation) = light_incidence(light, point);
    let cos_in = to_light.dot(normal);
    if attenuation == 0.0 || cos_in <= 0.0 || !visible(scene, point, normal, light, to_light) {
        return None;
    }
    Some(EnteringLight {
        to_light,
        point,
        normal,
        radiance: radiance(light) * (attenuation * fresnel_transmittance(cos_in, eta)),
    })
}

/// Settings of [`single_scattering`].
#[derive(Clone, Debug, PartialEq)]
pub struct SingleScatteringOptions {
    /// Phase function.
    pub phase: Phase,
    /// Quadrature points along the refracted view ray, per channel.
    pub steps: usize,
    /// Depth-texture texels for layers with thickness from a texture (constant over the
    /// object in the reference: the texel at the shaded point).
    pub depth_texels: Vec<[f32; 4]>,
    /// Li et al.'s `D_max` (eq. 5): the march stops at depth `D_max` below the surface
    /// (`D_max / (n . w)` along the refracted ray) if the ray has not left the object before;
    /// `None` integrates to where it leaves.
    pub max_depth: Option<f64>,
}

impl Default for SingleScatteringOptions {
    fn default() -> Self {
        Self {
            phase: Phase::HenyeyGreenstein,
            steps: 512,
            depth_texels: Vec::new(),
            max_depth: None,
        }
    }
}

/// Single scattering leaving surface point `x_o` of `scene.objects[object]` along `-view_dir`
/// (`view_dir`: the camera ray's travelling direction), RGB radiance:
///
/// `L_ss = T(x_o) L_amb(n_o) S / c
///       + T(x_o) / eta^2 ∫_0^{s_max} sigma_s(M) Σ_lights V(P') T(P') E(P') (cos_in / cos_t)
///         p(cos θ) exp(-tau(P_in -> M) - tau(M -> x_o)) ds`
///
/// - the first term: the ambient's single scattering, a white sky's share `S`
///   ([`crate::scene::layered::AlbedoSplit::single`]) spread as `T / (pi c)`, `c`
///   [`diffuse_transmittance`] (the march takes the lights only);
///
/// - `w = refract(view_dir)` at `x_o` (eta; under total internal reflection nothing enters:
///   0), `M = x_o + s w`, `s_max` where the ray leaves the object (exact, analytic);
/// - `P'` = where the segment from `M` towards the light leaves the object; the light
///   refracts there (cosines `cos_in` outside, `cos_t` inside) and reaches `M` along the
///   refracted direction from `P_in` on `P'`'s tangent plane (Jensen's refracted distance),
///   its beam narrowed by `cos_in / cos_t`; `1 / eta^2` because radiance inside is `eta^2` the
///   radiance it leaves as;
/// - `E(P')` = the light's radiance times [`light_incidence`]'s falloff at `P'` (the GPU's
///   light falloff), `V(P')` its visibility ray-traced against every object (shadows);
/// - `T(x) = fresnel_transmittance(cos, eta)` at `x_o` (the view's angle) and `P'` (the
///   light's);
/// - `tau` is [`LayerStack::optical_depth`] with layers relative to `P'` for the light segment
///   and to `x_o` for the view segment; `sigma_s(M)` that of the layer `M` lies in (relative to
///   `x_o`); `cos θ = dot(-to_light, -w)` between the light's and the scattered light's
///   directions of travel, `p` = HG or Schlick with the layer's `g`.
///
/// The integral is taken per channel with `steps` midpoints equally spaced in the view
/// transmittance of the first layer (`s = -ln(1 - u (1 - e^{-sigma_t s_max})) / sigma_t`), so
/// media of any density are resolved near the surface. Needs a sphere (a closed shape).
pub fn single_scattering(
    scene: &Scene,
    object: usize,
    x_o: DVec3,
    view_dir: DVec3,
    options: &SingleScatteringOptions,
) -> Result<DVec3> {
    let medium = medium_of(scene, object)?;
    let (shape, transform) = shape_of(scene, object)?;
    if !matches!(shape, Shape::Sphere { .. }) {
        return Err(LucentError::InvalidInput(format!(
            "object {object}: single scattering needs a closed shape (a sphere)"
        )));
    }
    let eta = f64::from(medium.eta);
    let stack = LayerStack::from_medium(medium, &options.depth_texels);
    let (x_o, n_o) = project_to_surface(shape, &transform, x_o);
    let view_dir = view_dir.normalize();
    let cos_o = (-view_dir).dot(n_o);
    if cos_o <= 0.0 {
        return Ok(DVec3::ZERO); // seen from behind: no light leaves towards the eye
    }
    let Some(w) = refract(view_dir, n_o, eta) else {
        return Ok(DVec3::ZERO);
    };
    let t_o = fresnel_transmittance(cos_o, eta);
    let mut s_max = exit_distance(shape, &transform, x_o, w).unwrap_or(0.0);
    if let Some(d) = options.max_depth {
        // The GPU bounds cos beta at 0.05 for grazing refraction; so does this.
        s_max = s_max.min(d.max(0.0) / (-w.dot(n_o)).max(0.05));
    }
    let steps = options.steps.max(1);
    let mut out = [0.0; 3];
    for (c, out_c) in out.iter_mut().enumerate() {
        let sigma = stack.layers[0].sigma_t[c];
        // 1 - e^{-sigma s_max}, and the map from u to s; a thin or clear medium is sampled
        // uniformly (the exponential's substitution degenerates as sigma s_max -> 0).
        let span = -(-sigma * s_max).exp_m1();
        let uniform = (sigma * s_max).is_nan() || sigma * s_max <= 1e-6;
        let mut sum = 0.0;
        for k in 0..steps {
            let u = (k as f64 + 0.5) / steps as f64;
            let (s, ds) = if uniform {
                (u * s_max, s_max / steps as f64)
            } else {
                // ds/du = span / (sigma (1 - u span)); 1 - u span >= e^{-sigma s_max} > 0
                // unless it underflows, so floor it to keep s finite.
                let rest = (1.0 - u * span).max(f64::MIN_POSITIVE);
                (
                    (-rest.ln() / sigma).min(s_max),
                    span / (sigma * rest) / steps as f64,
                )
            };
            let m = x_o + w * s;
            let Some(layer) = stack.layer_at((x_o - m).dot(n_o)) else {
                continue; // below the stack: no medium scatters
            };
            let sigma_s = layer.sigma_s[c];
            if sigma_s == 0.0 {
                continue;
            }
            let tau_view = stack.optical_depth(x_o, n_o, m, x_o)[c];
            for light in &scene.lights {
                let Some(entry) = entering_light(scene, shape, &transform, light, m, eta) else {
                    continue;
                };
                // The light refracts as it enters: it reaches m along `down` from the entry's
                // tangent plane (Jensen's refracted distance; the GPU's plane too), its beam
                // narrowed by cos_in / cos_t.
                let Some(down) = refract(-entry.to_light, entry.normal, eta) else {
                    continue;
                };
                let cos_t = -down.dot(entry.normal);
                if cos_t <= 1e-4 {
                    continue;
                }
                let cos_in = entry.to_light.dot(entry.normal);
                let p_in = m - down * ((entry.point - m).dot(entry.normal).max(0.0) / cos_t);
                // The light's falloff where the refracted path starts, not at P' (a point
                // light's falls off across the distance between them; the GPU's too).
                let (_, attenuation) = light_incidence(light, p_in);
                let (_, at_entry) = light_incidence(light, entry.point);
                let falloff = if at_entry > 0.0 { attenuation / at_entry } else { 0.0 };
                // The same stack, placed at the entry point.
                let tau_light = stack.optical_depth(entry.point, entry.normal, p_in, m)[c];
                let phase = options.phase.eval(layer.g, (-down).dot(w));
                sum += sigma_s * phase * entry.radiance[c] * falloff * (cos_in / cos_t)
                    * (-(tau_light + tau_view)).exp()
                    * ds;
            }
        }
        // Radiance inside is eta^2 the radiance it leaves as.
        *out_c = t_o * sum / (eta * eta);
    }
    // The ambient's single scattering: a white sky's share (S / c of its radiance). Its split
    // costs about 0.3 ms: only a scene with ambient light pays it, per pixel.
    let ambient = scene.environment.ambient_radiance(n_o);
    if ambient == DVec3::ZERO {
        return Ok(DVec3::from_array(out));
    }
    let split = medium.albedo_split();
    let ambient_single = split.single.as_dvec3() / f64::from(split.diffuse_transmittance);
    Ok(DVec3::from_array(out) + ambient * ambient_single * t_o)
}

/// Li et al.'s refraction light `L_t` as lucent reads it (see [`crate::features::layered`]):
/// light that crossed the object from where it entered on the light's side to `x_o` on the
/// far side, leaving diffusely towards `-view_dir`: unscattered, and (issue 26) diffused
/// through the thickness `a = |P' - x_o|` by the first layer's dipole
/// ([`crate::scene::layered::Dipole::transmitted_beyond`]):
///
/// `L_t = T(x_o) / pi Σ_lights V(P') T(P') E(P') [cos(x_o) exp(-tau(P' -> x_o)) + cos(P') Tb(a)]`
///
/// for each light `x_o` faces away from (`dot(to_light, n) < 0`); `P'` = where the segment from
/// `x_o` towards the light leaves the object (exact), `tau` the planar-layer optical depth
/// relative to `P'`, `cos(x_o)` the light's cosine to the normal at `x_o` (the unscattered
/// beam's flux through the surface it leaves by), `cos(P')` the light's cosine to the normal
/// there (the diffusing light is the irradiance that entered). The diffused part is weighted by `smoothstep(0, 0.3, n(P') .
/// (P' - eye) / |P' - eye|)`: 1 where `P'` faces away from the eye, 0 where the camera sees it
/// (light that entered in view is multiple scattering's, which gathers it from the visible
/// surface). Needs a sphere.
pub fn transmitted(
    scene: &Scene,
    object: usize,
    x_o: DVec3,
    view_dir: DVec3,
    depth_texels: &[[f32; 4]],
) -> Result<DVec3> {
    let medium = medium_of(scene, object)?;
    let (shape, transform) = shape_of(scene, object)?;
    let eta = f64::from(medium.eta);
    let stack = LayerStack::from_medium(medium, depth_texels);
    let (x_o, n_o) = project_to_surface(shape, &transform, x_o);
    let cos_o = (-view_dir.normalize()).dot(n_o);
    if cos_o <= 0.0 {
        return Ok(DVec3::ZERO);
    }
    // The first layer's dipole in scene units, per channel, as the GPU's table holds it.
    let dipoles = medium.first_layer_dipoles();
    let mut sum = DVec3::ZERO;
    for light in &scene.lights {
        let (to_light, _) = light_incidence(light, x_o);
        if to_light.dot(n_o) >= 0.0 {
            continue;
        }
        let Some(entry) = entering_light(scene, shape, &transform, light, x_o, eta) else {
            continue;
        };
        let tau = stack.optical_depth(entry.point, entry.normal, entry.point, x_o);
        let thickness = (entry.point - x_o).length();
        let from_eye = (entry.point - scene.camera.eye.as_dvec3()).normalize_or_zero();
        let unseen = smoothstep(0.0, 0.3, entry.normal.dot(from_eye));
        let cos_in = unseen * entry.to_light.dot(entry.normal).max(0.0);
        // The unscattered beam's flux through x_o's surface: the cosine at the exit.
        let cos_exit = (-to_light.dot(n_o)).max(0.0);
        let crossed = |c: usize| {
            cos_exit * (-tau[c]).exp() + cos_in * dipoles[c].transmitted_beyond(thickness)
        };
        sum += entry.radiance * DVec3::new(crossed(0), crossed(1), crossed(2));
    }
    // Light leaving diffusely through the boundary is spread as F_t(mu_o) / (pi c).
    Ok(sum * (fresnel_transmittance(cos_o, eta) / (PI * diffuse_transmittance(eta))))
}

/// GLSL's `smoothstep(edge0, edge1, x)`: 0 below edge0, 1 above edge1, a cubic between.
fn smoothstep(edge0: f64, edge1: f64, x: f64) -> f64 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// One area sample of an object's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceSample {
    /// Position on the analytic surface (world).
    pub position: DVec3,
    /// Outward unit normal.
    pub normal: DVec3,
    /// Area it stands for (units^2): its sub-triangle of the mesh.
    pub area: f64,
    /// Irradiance transmitted into the medium: `sum_lights V T(cos) E cos` (RGB).
    pub irradiance: DVec3,
}

/// An object's surface as area samples with their transmitted irradiance, built once and
/// reused for every pixel of [`multiple_scattering`].
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceSamples {
    /// The object's index in the scene.
    pub object: usize,
    /// The spacing the triangles were subdivided to (units).
    pub spacing: f64,
    /// The samples.
    pub samples: Vec<SurfaceSample>,
    /// The object's medium's [`crate::scene::layered::AlbedoSplit::multiple_scale`], which
    /// [`multiple_scattering`] scales the dipole to (computed once here, not per pixel).
    pub multiple_scale: DVec3,
}

/// Most samples [`SurfaceSamples::new`] makes (about 100 MB); finer spacings are an error.
pub const MAX_SURFACE_SAMPLES: usize = 1 << 20;

/// Irradiance transmitted into the medium at surface point `p` (outward normal `n`):
/// `sum_lights V(p) T(cos, eta) radiance falloff cos`, plus the environment's `E(n) c`, `c`
/// the boundary's [`diffuse_transmittance`] (the caller's, computed once, not per sample).
fn transmitted_irradiance(scene: &Scene, p: DVec3, n: DVec3, eta: f64, c: f64) -> DVec3 {
    // The environment's irradiance at the normal, E(n) = pi ambient_radiance(n), of which the
    // boundary lets c through (diffuse light: the cosine-weighted average of the Fresnel
    // transmittance; unshadowed, as every pass's ambient).
    let ambient_in = PI * c;
    let mut e = scene.environment.ambient_radiance(n) * ambient_in;
    for light in &scene.lights {
        let (to_light, attenuation) = light_incidence(light, p);
        let cos = to_light.dot(n);
        if cos <= 0.0 || attenuation == 0.0 || !visible(scene, p, n, light, to_light) {
            continue;
        }
        e += radiance(light) * (attenuation * cos * fresnel_transmittance(cos, eta));
    }
    e
}

impl SurfaceSamples {
    /// A spacing well below the diffusion length: a quarter of the smallest `1 / sigma_tr` of
    /// the first layer's channels, in scene units (a channel without absorption, `sigma_tr` = 0,
    /// is bounded by its mean free path instead).
    pub fn default_spacing(medium: &LayeredMedium) -> f64 {
        let r = medium.first_layer_reduced();
        (0..3)
            .map(|c| {
                let d = dipole_constants(
                    f64::from(r.sigma_s_prime[c]),
                    f64::from(r.sigma_a[c]),
                    f64::from(medium.eta),
                );
                if d.sigma_tr > 0.0 {
                    0.25 / d.sigma_tr
                } else {
                    0.25 * d.z_r
                }
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// Samples the surface of `scene.objects[object]`: each mesh triangle split into `n^2`
    /// congruent sub-triangles, `n = ceil(longest edge / spacing)`, one sample at each
    /// centroid (projected onto the analytic surface) with the sub-triangle's area, and its
    /// transmitted irradiance ray-traced (shadows from every object).
    pub fn new(scene: &Scene, object: usize, spacing: f64) -> Result<Self> {
        let medium = medium_of(scene, object)?;
        let eta = f64::from(medium.eta);
        let boundary = diffuse_transmittance(eta);
        let (shape, transform) = shape_of(scene, object)?;
        if !(spacing.is_finite() && spacing > 0.0) {
            return Err(LucentError::InvalidInput(format!(
                "surface sample spacing {spacing} must be finite and > 0"
            )));
        }
        let mesh = &scene.meshes[scene.objects[object].mesh];
        let world: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| transform.transform_point3(p.as_dvec3()))
            .collect();
        let mut samples = Vec::new();
        for tri in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| world[tri[k] as usize]);
            let longest = (b - a).length().max((c - b).length()).max((a - c).length());
            let n = (longest / spacing).ceil().max(1.0) as usize;
            let area = 0.5 * (b - a).cross(c - a).length() / (n * n) as f64;
            if samples.len() + n * n > MAX_SURFACE_SAMPLES {
                return Err(LucentError::InvalidInput(format!(
                    "spacing {spacing} needs more than {MAX_SURFACE_SAMPLES} surface samples"
                )));
            }
            let (e1, e2) = ((b - a) / n as f64, (c - a) / n as f64);
            for i in 0..n {
                for j in 0..n - i {
                    // Upward sub-triangle (i, j), and the downward one beside it.
                    let base = a + e1 * i as f64 + e2 * j as f64;
                    let mut centroids = vec![base + (e1 + e2) / 3.0];
                    if i + j + 1 < n {
                        centroids.push(base + (e1 + e2) * (2.0 / 3.0));
                    }
                    for q in centroids {
                        let (position, normal) = project_to_surface(shape, &transform, q);
                        samples.push(SurfaceSample {
                            position,
                            normal,
                            area,
                            irradiance: transmitted_irradiance(scene, position, normal, eta, boundary),
                        });
                    }
                }
            }
        }
        Ok(Self {
            object,
            spacing,
            samples,
            multiple_scale: medium.albedo_split().multiple_scale.as_dvec3(),
        })
    }
}

/// Multiple scattering leaving `x_o` of the samples' object along `-view_dir`, RGB radiance:
///
/// `L_ms = (T(x_o, w_o) / pi) (k / R_d,total) ∫_surface Rd(|x_o - y|) E(y) dA(y)`
///
/// with Jensen's dipole `Rd` of the first layer ([`Dipole::rd`], scene units) for the
/// profile's shape, rescaled from the dipole's total `R_d,total` to the medium's multiple
/// scattering `k` ([`crate::scene::layered::AlbedoSplit::multiple_scale`], computed with
/// the samples), `E(y)` each sample's
/// transmitted irradiance. The peak of `Rd` at r -> 0 is narrower than a sample: the
/// disc of radius `2 spacing` around `x_o` is integrated in closed form
/// ([`Dipole::reflectance_within`]) with `E(x_o)`, the samples beyond it as `Rd E A`.
pub fn multiple_scattering(
    scene: &Scene,
    samples: &SurfaceSamples,
    x_o: DVec3,
    view_dir: DVec3,
) -> Result<DVec3> {
    let object = samples.object;
    let medium = medium_of(scene, object)?;
    let (shape, transform) = shape_of(scene, object)?;
    let eta = f64::from(medium.eta);
    let (x_o, n_o) = project_to_surface(shape, &transform, x_o);
    let cos_o = (-view_dir.normalize()).dot(n_o);
    if cos_o <= 0.0 {
        return Ok(DVec3::ZERO);
    }
    let r = medium.first_layer_reduced();
    let dipoles: [Dipole; 3] = [0, 1, 2]
        .map(|c| dipole_constants(f64::from(r.sigma_s_prime[c]), f64::from(r.sigma_a[c]), eta));
    let near = 2.0 * samples.spacing;
    let e_o = transmitted_irradiance(scene, x_o, n_o, eta, diffuse_transmittance(eta));
    // The profile's shape is the dipole's, its energy the medium's multiple scattering
    // (`AlbedoSplit::multiple_scale`, which the GPU's table holds).
    let scale = samples.multiple_scale;
    let mut out = [0.0; 3];
    for (c, d) in dipoles.iter().enumerate() {
        let mut sum = e_o[c] * d.reflectance_within(near);
        for s in &samples.samples {
            let dist = (s.position - x_o).length();
            if dist >= near {
                sum += d.rd(dist) * s.irradiance[c] * s.area;
            }
        }
        let total = d.total_reflectance();
        out[c] = if total > 0.0 { sum * scale[c] / total } else { 0.0 };
    }
    Ok(DVec3::from_array(out) * (fresnel_transmittance(cos_o, eta) / PI))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::generators::{self, Generator};
    use crate::scene::layered::Layer;
    use crate::scene::{Camera, Material, Mesh, Object};
    use glam::{Mat4, Vec3};

    /// Adaptive Simpson of `f` on [a, b] to `eps`.
    fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, eps: f64) -> f64 {
        #[allow(clippy::too_many_arguments)]
        fn rec(
            f: &dyn Fn(f64) -> f64,
            a: f64,
            b: f64,
            fa: f64,
            fm: f64,
            fb: f64,
            whole: f64,
            eps: f64,
            depth: u32,
        ) -> f64 {
            let m = 0.5 * (a + b);
            let (lm, rm) = (0.5 * (a + m), 0.5 * (m + b));
            let (flm, frm) = (f(lm), f(rm));
            let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
            let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
            if depth == 0 || (left + right - whole).abs() <= 15.0 * eps {
                return left + right + (left + right - whole) / 15.0;
            }
            rec(f, a, m, fa, flm, fm, left, eps / 2.0, depth - 1)
                + rec(f, m, b, fm, frm, fb, right, eps / 2.0, depth - 1)
        }
        let (fa, fm, fb) = (f(a), f(0.5 * (a + b)), f(b));
        rec(
            f,
            a,
            b,
            fa,
            fm,
            fb,
            (b - a) / 6.0 * (fa + 4.0 * fm + fb),
            eps,
            50,
        )
    }

    #[test]
    fn phase_functions_integrate_to_one_and_match_at_g_zero() {
        for g in [-0.999, -0.9, -0.3, 0.0, 0.5, 0.9, 0.99, 0.999, 1.0, 5.0] {
            for phase in [Phase::HenyeyGreenstein, Phase::Schlick] {
                let total = 2.0 * PI * simpson(&|c| phase.eval(g, c), -1.0, 1.0, 1e-10);
                assert!((total - 1.0).abs() < 1e-6, "{phase:?} g {g}: {total}");
            }
        }
        assert!((henyey_greenstein(0.0, 0.3) - 1.0 / (4.0 * PI)).abs() < 1e-15);
        assert_eq!(phase_difference(0.0), (0.0, 0.0));
        // Closed form of HG at cos = 1: (1 + g) / (4 pi (1 - g)^2).
        let g = 0.999;
        assert!(
            (henyey_greenstein(g, 1.0) / ((1.0 + g) / (4.0 * PI * (1.0 - g).powi(2))) - 1.0).abs()
                < 1e-9
        );
        let (max, mean) = phase_difference(0.9);
        assert!(max > mean && mean > 0.0 && max.is_finite());
        // Schlick's k stays inside (-1, 1) where the cubic overshoots.
        assert!(schlick_k(0.97) < 1.0 && schlick(0.97, -1.0) > 0.0);
    }

    #[test]
    fn fresnel_and_refraction() {
        // Normal incidence: ((eta - 1) / (eta + 1))^2 reflected.
        let t = fresnel_transmittance(1.0, 1.5);
        assert!((t - (1.0 - 0.04)).abs() < 1e-12, "{t}");
        assert_eq!(fresnel_transmittance(0.7, 1.0), 1.0);
        assert_eq!(fresnel_transmittance(0.0, 1.5), 0.0);
        // Past the critical angle from inside glass.
        assert_eq!(fresnel_transmittance(0.3, 1.0 / 1.5), 0.0);
        assert!(fresnel_transmittance(0.9, 1.0 / 1.5) > 0.0);
        // Snell: sin_i = eta sin_t.
        let d = DVec3::new(0.6, -0.8, 0.0);
        let t = refract(d, DVec3::Y, 1.3).unwrap();
        assert!((0.6 - 1.3 * t.x).abs() < 1e-12 && t.y < 0.0, "{t}");
        assert_eq!(refract(d, DVec3::Y, 1.0).unwrap(), d);
        assert!(refract(DVec3::new(0.8, -0.6, 0.0), DVec3::Y, 1.0 / 1.5).is_none());
        assert!(refract(d, DVec3::Y, 1.0 / 1.5).is_some());
        // A normal on the wrong side is flipped.
        assert!((refract(d, -DVec3::Y, 1.3).unwrap() - t).length() < 1e-12);
    }

    fn layer(sigma_a: f32, sigma_s: f32, thickness: Thickness) -> Layer {
        Layer {
            sigma_a: Vec3::splat(sigma_a),
            sigma_s: Vec3::splat(sigma_s),
            g: 0.0,
            thickness,
        }
    }

    #[test]
    fn optical_depth_sums_each_layers_share_of_the_segment() {
        let mut m = LayeredMedium::preset("apple").unwrap();
        m.units_per_mm = 1.0;
        m.layers = vec![
            layer(1.0, 0.0, Thickness::Mm(1.0)),
            layer(2.0, 8.0, Thickness::Mm(2.0)),
        ];
        let stack = LayerStack::from_medium(&m, &[]);
        let (p, n) = (DVec3::ZERO, DVec3::Y);
        // Straight down from the surface to depth 4: 1 in layer 0, 2 in layer 1, 1 below.
        let tau = stack.optical_depth(p, n, DVec3::ZERO, DVec3::new(0.0, -4.0, 0.0));
        assert!((tau.x - (1.0 + 20.0)).abs() < 1e-12, "{tau}");
        // At 60 degrees from the normal the lengths double.
        let b = DVec3::new(4.0 * 3f64.sqrt(), -4.0, 0.0);
        let l = stack.lengths(p, n, DVec3::ZERO, b);
        assert!(
            (l[0] - 2.0).abs() < 1e-12 && (l[1] - 4.0).abs() < 1e-12,
            "{l:?}"
        );
        // Parallel to the layers inside layer 1; and above the tangent plane = layer 0.
        let l = stack.lengths(p, n, DVec3::new(0.0, -2.0, 0.0), DVec3::new(3.0, -2.0, 0.0));
        assert_eq!(l, vec![0.0, 3.0]);
        let l = stack.lengths(p, n, DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, 0.5, 0.0));
        assert_eq!(l, vec![0.5, 0.0]);
        assert_eq!(stack.layer_at(2.5).unwrap().sigma_s.x, 8.0);
        assert!(stack.layer_at(3.5).is_none());
    }

    /// One sphere of radius `radius` at the origin with `medium`, and `lights`.
    fn sphere_scene(medium: LayeredMedium, radius: f32, lights: Vec<Light>) -> Scene {
        let mesh: Mesh = generators::generate(Generator::Icosphere, 3).unwrap();
        let mut material = Material::opaque("m", Vec3::splat(0.8), 0.0, 1.0);
        material.layers = Some(medium);
        Scene {
            name: "test".into(),
            meshes: vec![mesh],
            objects: vec![Object {
                mesh: 0,
                transform: Mat4::from_scale(Vec3::splat(radius)),
                material,
            }],
            lights,
            camera: Camera {
                eye: Vec3::new(0.0, 0.0, 5.0),
                target: Vec3::ZERO,
                fov_y_degrees: 45.0,
                near: 0.1,
                far: 100.0,
            },
            environment: crate::scene::Environment::constant(Vec3::ZERO),
            sky: Vec3::ZERO,
            exposure: 1.0,
            deformation: None,
            time: 0.0,
            credits: Vec::new(),
        }
    }

    fn homogeneous(sigma_a: f32, sigma_s: f32, g: f32, eta: f32) -> LayeredMedium {
        let mut m = LayeredMedium::preset("apple").unwrap();
        m.units_per_mm = 1.0;
        m.eta = eta;
        m.layers = vec![Layer {
            g,
            ..layer(sigma_a, sigma_s, Thickness::Rest)
        }];
        m
    }

    #[test]
    fn single_scattering_matches_the_closed_forms_through_a_sphere() {
        // View ray through the centre of a sphere of radius R, eta = 1, isotropic, a
        // directional light. Light behind the sphere shining at the eye: every point of the
        // diameter gets e^{-sigma_t (2R - s)} and sends e^{-sigma_t s}: L = sigma_s p E 2R
        // e^{-2 sigma_t R}. Light from the eye's side: L = sigma_s p E (1 - e^{-4 sigma_t R}) /
        // (2 sigma_t).
        let (sa, ss, r) = (0.3, 1.2, 0.5);
        let st = f64::from(sa + ss);
        let p = 1.0 / (4.0 * PI);
        let x_o = DVec3::new(0.0, 0.0, f64::from(r));
        let view = DVec3::NEG_Z;
        let options = SingleScatteringOptions {
            steps: 4096,
            ..Default::default()
        };
        let behind = Light::directional(Vec3::Z, Vec3::ONE, 2.0);
        let scene = sphere_scene(homogeneous(sa, ss, 0.0, 1.0), r, vec![behind]);
        let l = single_scattering(&scene, 0, x_o, view, &options).unwrap();
        let want = f64::from(ss) * p * 2.0 * 2.0 * f64::from(r) * (-2.0 * st * f64::from(r)).exp();
        assert!((l.x / want - 1.0).abs() < 1e-3, "{l} vs {want}");
        let front = Light::directional(Vec3::NEG_Z, Vec3::ONE, 2.0);
        let scene = sphere_scene(homogeneous(sa, ss, 0.0, 1.0), r, vec![front]);
        let l = single_scattering(&scene, 0, x_o, view, &options).unwrap();
        let want = f64::from(ss) * p * 2.0 * (1.0 - (-4.0 * st * f64::from(r)).exp()) / (2.0 * st);
        assert!((l.y / want - 1.0).abs() < 1e-3, "{l} vs {want}");
        // The boundary: eta 1.5 at normal incidence scales both ends by Fresnel's 0.96 (the
        // refracted rays stay on the axis, so the beam keeps its width), and the radiance
        // that leaves is 1 / eta^2 of the radiance inside.
        let scene = sphere_scene(homogeneous(sa, ss, 0.0, 1.5), r, vec![front]);
        let l15 = single_scattering(&scene, 0, x_o, view, &options).unwrap();
        assert!(
            (l15.z / (want * 0.96 * 0.96 / 2.25) - 1.0).abs() < 1e-3,
            "{l15}"
        );
        // A shadowing sphere between the light and the object leaves nothing.
        let mut shadowed = sphere_scene(homogeneous(sa, ss, 0.0, 1.0), r, vec![front]);
        let mut blocker = shadowed.objects[0].clone();
        blocker.transform = Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0)) * blocker.transform;
        shadowed.objects.push(blocker);
        let l = single_scattering(&shadowed, 0, x_o, view, &options).unwrap();
        assert_eq!(l, DVec3::ZERO);
    }

    #[test]
    fn a_stack_of_two_equal_layers_scatters_as_one() {
        // Splitting a medium into two equal layers changes nothing; a different second layer
        // does, and so does the phase function for g != 0.
        let lights = vec![Light::point(
            Vec3::new(0.5, 0.8, 1.5),
            Vec3::ONE,
            10.0,
            10.0,
        )];
        let x_o = DVec3::new(0.1, 0.05, (0.25f64 - 0.0125).sqrt());
        let options = SingleScatteringOptions::default();
        let one = homogeneous(0.5, 3.0, 0.6, 1.3);
        let mut two = one.clone();
        two.layers[0].thickness = Thickness::Mm(0.1);
        two.layers.push(one.layers[0]);
        let run = |m: LayeredMedium, o: &SingleScatteringOptions| {
            single_scattering(
                &sphere_scene(m, 0.5, lights.clone()),
                0,
                x_o,
                DVec3::NEG_Z,
                o,
            )
            .unwrap()
        };
        let (a, b) = (run(one.clone(), &options), run(two.clone(), &options));
        assert!(
            a.min_element() > 0.0 && ((a - b).abs() / a).max_element() < 1e-9,
            "{a} {b}"
        );
        two.layers[1].sigma_a = Vec3::splat(5.0);
        assert!(run(two, &options).x < a.x);
        let schlick = SingleScatteringOptions {
            phase: Phase::Schlick,
            ..Default::default()
        };
        let c = run(one, &schlick);
        assert!(c.x != a.x && (c.x / a.x - 1.0).abs() < 0.5, "{a} {c}");
    }

    #[test]
    fn multiple_scattering_of_a_lit_plane_is_the_medium_s_multiple_scattering() {
        // A large plane under a unit directional light at normal incidence, eta = 1: the
        // gather at the centre is (E / pi) (k / R_d) 2 pi ∫ Rd r dr, between the closed form
        // within the plane's inscribed disc and k, the medium's multiple scattering (its
        // white-sky albedo less single scattering's share).
        let (sp, sa) = (1.0f32, 0.5f32);
        let mut m = homogeneous(sa, sp, 0.0, 1.0);
        m.units_per_mm = 1.0;
        let mut scene = sphere_scene(
            m,
            1.0,
            vec![Light::directional(Vec3::NEG_Y, Vec3::ONE, 1.0)],
        );
        scene.meshes[0] = generators::generate(Generator::Plane, 1).unwrap();
        scene.objects[0].transform = Mat4::from_scale(Vec3::new(5.0, 1.0, 5.0));
        let samples = SurfaceSamples::new(&scene, 0, 0.06).unwrap();
        let area: f64 = samples.samples.iter().map(|s| s.area).sum();
        assert!((area - 100.0).abs() < 1e-6, "{area}");
        let l = multiple_scattering(&scene, &samples, DVec3::ZERO, DVec3::NEG_Y).unwrap();
        let d = dipole_constants(f64::from(sp), f64::from(sa), 1.0);
        let k = f64::from(medium_of(&scene, 0).unwrap().albedo_split().multiple_scale.x);
        let (lo, hi) = (
            d.reflectance_within(5.0) / d.total_reflectance() * k / PI,
            k / PI,
        );
        assert!(
            l.x > lo * 0.995 && l.x < hi * 1.005,
            "{} not in [{lo}, {hi}]",
            l.x
        );
        // Halving the spacing changes the result by under 0.5%.
        let finer = SurfaceSamples::new(&scene, 0, 0.03).unwrap();
        let l2 = multiple_scattering(&scene, &finer, DVec3::ZERO, DVec3::NEG_Y).unwrap();
        assert!((l2.x / l.x - 1.0).abs() < 5e-3, "{l} vs {l2}");
    }

    #[test]
    fn surface_samples_are_reused_across_pixels_in_seconds() {
        let m = LayeredMedium::preset("skin1").unwrap();
        let spacing = SurfaceSamples::default_spacing(&m);
        let lights = vec![Light::point(
            Vec3::new(1.0, 2.0, 2.0),
            Vec3::ONE,
            20.0,
            15.0,
        )];
        let scene = sphere_scene(m, 0.5, lights);
        let start = std::time::Instant::now();
        let samples = SurfaceSamples::new(&scene, 0, spacing).unwrap();
        let area: f64 = samples.samples.iter().map(|s| s.area).sum();
        // The icosphere's area is a little under the sphere's.
        assert!(area < PI && area > 0.97 * PI, "{area}");
        for x in [-0.3, 0.0, 0.3] {
            let p = DVec3::new(x, 0.2, 0.5);
            let l = multiple_scattering(&scene, &samples, p, DVec3::NEG_Z).unwrap();
            assert!(l.is_finite() && l.min_element() > 0.0, "{l}");
        }
        assert!(start.elapsed().as_secs() < 30, "{:?}", start.elapsed());
    }

    #[test]
    fn extreme_media_stay_finite() {
        let lights = vec![
            Light::point(Vec3::new(0.0, 0.0, 2.0), Vec3::ONE, 5.0, 10.0),
            Light::directional(Vec3::NEG_Z, Vec3::ONE, 1.0),
        ];
        let options = SingleScatteringOptions {
            steps: 32,
            ..Default::default()
        };
        let x_o = DVec3::new(0.1, 0.1, 0.5);
        for (sa, ss) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (0.0, 0.0),
            (0.0, 1e6),
            (1e6, 1e6),
            (1e6, 0.0),
        ] {
            for g in [-0.999, 0.0, 0.999] {
                for eta in [1.0, 1.3] {
                    for thickness in [Thickness::Mm(0.0), Thickness::Mm(1e6), Thickness::Rest] {
                        let mut m = homogeneous(sa, ss, g, eta);
                        m.units_per_mm = 0.04;
                        m.layers[0].thickness = thickness;
                        m.layers.push(layer(0.1, 1.0, Thickness::Rest));
                        if thickness == Thickness::Rest {
                            m.layers.pop();
                        }
                        let scene = sphere_scene(m, 0.5, lights.clone());
                        let l = single_scattering(&scene, 0, x_o, DVec3::NEG_Z, &options).unwrap();
                        assert!(
                            l.is_finite() && l.min_element() >= 0.0,
                            "{sa} {ss} {g} {eta}: {l}"
                        );
                        let samples = SurfaceSamples::new(&scene, 0, 0.2).unwrap();
                        let l = multiple_scattering(&scene, &samples, x_o, DVec3::NEG_Z).unwrap();
                        assert!(
                            l.is_finite() && l.min_element() >= 0.0,
                            "{sa} {ss} {g} {eta}: {l}"
                        );
                    }
                }
            }
        }
        for g in [-0.999, 0.999, 1.0, -1.0, f64::NAN] {
            for c in [-1.0, 0.0, 1.0] {
                assert!(henyey_greenstein(g, c).is_finite() && schlick(g, c).is_finite());
            }
        }
    }
}
