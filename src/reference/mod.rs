//! CPU f64 versions of every shading equation, used by tests and reports to prove the GPU right.
//!
//! Each function mirrors a GLSL function of the same name under `glsl/common/`; when one
//! changes, so does its twin. [`raytrace`] renders a whole scene from the analytic shapes its
//! meshes approximate, as an independent end-to-end reference.

/// The medium's albedo is CPU math of the materials (`crate::scene::albedo`); the f64
/// references name it here too.
pub use crate::scene::albedo;
pub mod dipole;
pub mod fxaa;
pub mod layered;
pub mod lighting;
pub mod raytrace;
pub mod sss;
pub mod tonemap;
pub mod translucency;
pub mod transmission;

/// A 3-vector of f64 (the reference never rounds to f32 until the end).
pub type DVec3 = glam::DVec3;

/// One covered pixel of a read-back G-buffer, decoded as the lighting pass decodes it, with its
/// world position rebuilt from depth in f64.
#[derive(Clone, Debug)]
pub struct GBufferPixel {
    /// Index in the image (row-major, top row first).
    pub index: usize,
    /// World position.
    pub position: DVec3,
    /// Unit normal (+Y when the stored one is degenerate, as the shader sanitises it).
    pub normal: DVec3,
    /// The surface as a material (albedo, specular, roughness as stored).
    pub material: crate::scene::Material,
}

/// Every pixel of `gbuffer` seen through `camera`: `None` where no surface was drawn (sky).
pub fn gbuffer_pixels(
    gbuffer: &crate::frame::GBufferReadback,
    camera: &crate::scene::Camera,
) -> Vec<Option<GBufferPixel>> {
    let (w, h) = (gbuffer.width as usize, gbuffer.height as usize);
    let aspect = gbuffer.width as f32 / gbuffer.height.max(1) as f32;
    // The shader's matrix is the f32 product; invert it in f64.
    let view_proj = camera.projection(aspect) * camera.view();
    let inv_view_proj = view_proj.as_dmat4().inverse();
    (0..w * h)
        .map(|i| {
            let d = f64::from(gbuffer.depth[i]);
            if d >= 1.0 {
                return None;
            }
            let (x, y) = (i % w, i / w);
            let ndc = glam::DVec4::new(
                (x as f64 + 0.5) / w as f64 * 2.0 - 1.0,
                (y as f64 + 0.5) / h as f64 * 2.0 - 1.0,
                d,
                1.0,
            );
            let world = inv_view_proj * ndc;
            let [ar, ag, ab, specular] = gbuffer.gb0[i];
            let [nx, ny, nz, roughness] = gbuffer.gb1[i];
            let n = DVec3::new(nx.into(), ny.into(), nz.into());
            // NaN fails both tests, like the shader's `!(len2 > 1e-12)`.
            let len2 = n.length_squared();
            let normal = if len2.is_finite() && len2 > 1e-12 {
                n / len2.sqrt()
            } else {
                DVec3::Y
            };
            Some(GBufferPixel {
                index: i,
                position: world.truncate() / world.w,
                normal,
                material: crate::scene::Material::opaque(
                    "gbuffer",
                    glam::Vec3::new(ar, ag, ab),
                    specular,
                    roughness,
                ),
            })
        })
        .collect()
}
