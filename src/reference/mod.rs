//! CPU f64 versions of every shading equation, used by tests and reports to prove the GPU right.
//!
//! Each function mirrors a GLSL function of the same name under `glsl/common/`; when one
//! changes, so does its twin. [`raytrace`] renders a whole scene from the analytic shapes its
//! meshes approximate, as an independent end-to-end reference.

pub mod dipole;
pub mod lighting;
pub mod raytrace;
pub mod sss;
pub mod tonemap;
pub mod translucency;

/// A 3-vector of f64 (the reference never rounds to f32 until the end).
pub type DVec3 = glam::DVec3;
