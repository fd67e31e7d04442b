//! Ray-traces a scene's analytic shapes in f64: the reference image a rasterised frame is
//! compared against. Objects without an analytic shape are an error (the reference would
//! silently miss them).

use super::{lighting, tonemap, DVec3};
use crate::scene::{Scene, Shape};
use crate::{LucentError, Result};

/// A reference frame: linear HDR radiance per pixel (row-major, top row first) and whether a
/// surface covers the pixel.
pub struct ReferenceImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear radiance.
    pub hdr: Vec<DVec3>,
    /// Surface distance along the ray per pixel (`None`: sky).
    pub hit: Vec<Option<f64>>,
}

impl ReferenceImage {
    /// The display image as the tonemap pass encodes it.
    pub fn display_rgba8(&self, exposure: f64) -> Vec<u8> {
        self.hdr
            .iter()
            .flat_map(|&c| tonemap::display_rgba8(c, exposure))
            .collect()
    }
}

/// Renders `scene` at `width` x `height`, one ray through each pixel centre.
pub fn render(scene: &Scene, width: u32, height: u32) -> Result<ReferenceImage> {
    let cam = &scene.camera;
    let aspect = f64::from(width) / f64::from(height);
    let eye = cam.eye.as_dvec3();
    let forward = (cam.target.as_dvec3() - eye).normalize();
    let right = forward.cross(DVec3::Y).normalize();
    let up = right.cross(forward);
    let tan_half = (f64::from(cam.fov_y_degrees).to_radians() * 0.5).tan();
    let mut shapes = Vec::new();
    for object in &scene.objects {
        let shape = scene.meshes[object.mesh].shape.ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "scene '{}': the ray-traced reference needs analytic shapes",
                scene.name
            ))
        })?;
        shapes.push((shape, object.transform.as_dmat4(), object));
    }
    let mut hdr = Vec::with_capacity((width * height) as usize);
    let mut hits = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let ndc_x = (f64::from(x) + 0.5) / f64::from(width) * 2.0 - 1.0;
            let ndc_y = 1.0 - (f64::from(y) + 0.5) / f64::from(height) * 2.0;
            let dir = (forward + right * (ndc_x * tan_half * aspect) + up * (ndc_y * tan_half))
                .normalize();
            let mut best: Option<(f64, DVec3, usize)> = None;
            for (i, (shape, transform, _)) in shapes.iter().enumerate() {
                if let Some((t, n)) = intersect(*shape, transform, eye, dir) {
                    let near = f64::from(cam.near);
                    // Depth along the view axis must lie between the clip planes.
                    let view_depth = t * dir.dot(forward);
                    if view_depth >= near
                        && view_depth <= f64::from(cam.far)
                        && best.is_none_or(|(bt, _, _)| t < bt)
                    {
                        best = Some((t, n, i));
                    }
                }
            }
            match best {
                Some((t, n, i)) => {
                    let pos = eye + dir * t;
                    let c = lighting::shade(
                        &shapes[i].2.material,
                        n,
                        pos,
                        eye,
                        scene.environment.ambient_radiance(n),
                        &scene.lights,
                    );
                    hdr.push(c);
                    hits.push(Some(t));
                }
                None => {
                    hdr.push(scene.sky.as_dvec3());
                    hits.push(None);
                }
            }
        }
    }
    Ok(ReferenceImage {
        width,
        height,
        hdr,
        hit: hits,
    })
}

/// Nearest hit of a ray with a transformed shape: (distance, world unit normal). Hits closer
/// than 1e-9 are skipped (a ray leaving a surface does not hit it again).
pub fn intersect(
    shape: Shape,
    transform: &glam::DMat4,
    origin: DVec3,
    dir: DVec3,
) -> Option<(f64, DVec3)> {
    let inv = transform.inverse();
    let o = inv.transform_point3(origin);
    let d = inv.transform_vector3(dir);
    let normal_matrix = glam::DMat3::from_mat4(inv).transpose();
    let (t, n_obj) = match shape {
        Shape::Sphere { radius } => {
            let r = f64::from(radius);
            let a = d.length_squared();
            let b = o.dot(d);
            let c = o.length_squared() - r * r;
            let disc = b * b - a * c;
            if disc < 0.0 {
                return None;
            }
            let s = disc.sqrt();
            let t0 = (-b - s) / a;
            let t1 = (-b + s) / a;
            let t = if t0 > 1e-9 { t0 } else { t1 };
            if t <= 1e-9 {
                return None;
            }
            (t, (o + d * t) / r)
        }
        Shape::Plane { half_size } => {
            if d.y.abs() < 1e-12 {
                return None;
            }
            let t = -o.y / d.y;
            let p = o + d * t;
            let h = f64::from(half_size);
            if t <= 1e-9 || p.x.abs() > h || p.z.abs() > h {
                return None;
            }
            (t, DVec3::Y)
        }
    };
    Some((t, (normal_matrix * n_obj).normalize()))
}
