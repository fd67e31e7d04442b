//! The techniques and features, each adding its passes to a
//! [`RenderGraph`](crate::graph::RenderGraph): handles in, handles out. The frame
//! ([`crate::frame`]) decides which are in a frame; a feature never reads the scene's CPU model
//! or the f64 reference, only what [`crate::gpu_scene`] put on the GPU.
//!
//! - [`deferred`]: the MRT G-buffer and per-light deferred lighting (merged as subpasses).
//! - [`translucency`]: GDC 2011 thickness-based translucency: its material table and thickness
//!   packing (its shading runs inside the deferred lighting pass).
//! - [`sss`]: screen-space subsurface scattering, separable blurs of the lit diffuse light.
//! - [`shadows`]: light-space maps: shadows for direct light, light entry points for layered
//!   media.
//! - [`layered`]: Li et al. 2009's layered media: image-space single and dipole multiple
//!   scattering.
//! - [`tonemap`]: HDR to display (exposure, ACES fit, sRGB).
//! - [`antialias`]: FXAA after the tonemap (a knob, off by default).
//! - [`debug_view`]: a G-buffer target or the pre-SSS lit image instead of the frame.
//! - [`pass`]: the fullscreen pass builder: each input stated once, for the graph and the
//!   shader's bindings.
//! - [`util`]: pass-level pipeline helpers (a pipeline with its descriptor set, tile draws).
//! - [`shipped`]: every shader permutation the passes compile (the shipped SPIR-V's manifest).

pub mod antialias;
pub mod debug_view;
pub mod deferred;
pub mod layered;
pub mod pass;
pub mod shadows;
pub mod shipped;
pub mod sss;
pub mod tonemap;
pub mod translucency;
pub mod util;
