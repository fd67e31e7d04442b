//! The techniques and features, each adding its passes to a
//! [`RenderGraph`](crate::graph::RenderGraph): handles in, handles out. The frame
//! ([`crate::frame`]) decides which are in a frame; a feature never reads the scene's CPU model
//! or the f64 reference, only what [`crate::gpu_scene`] put on the GPU.
//!
//! - [`gbuffer`]: the MRT G-buffer: its targets, their formats, the pass that fills them.
//! - [`capabilities`]: which effects a described G-buffer can run, and what each lacks.
//! - [`gbuffer_desc`]: a G-buffer described as the effects read it (formats, encodings, world
//!   scale): a host's, as `lucent::embed` takes it, or lucent's own
//!   ([`gbuffer::GBufferLayout::described`]), so both are read through one description.
//! - [`lighting`]: per-light deferred lighting at each G-buffer pixel (merged with the
//!   G-buffer pass as subpasses).
//! - [`translucency`]: GDC 2011 thickness-based translucency: its material table and thickness
//!   packing (its shading runs inside the deferred lighting pass).
//! - [`sss`]: screen-space subsurface scattering, separable blurs of the lit diffuse light.
//! - [`shadows`]: light-space maps: shadows for direct light, light entry points for layered
//!   media.
//! - [`layered`]: Li et al. 2009's layered media: image-space single and dipole multiple
//!   scattering.
//! - [`layer_depth`]: the layered media's per-layer depth texels, stored by the G-buffer and
//!   the light-space maps.
//! - [`tonemap`]: HDR to display (exposure, ACES fit, sRGB).
//! - [`antialias`]: FXAA after the tonemap (a knob, off by default).
//! - [`debug_view`]: a G-buffer target or the pre-SSS lit image instead of the frame.
//! - [`pass`]: the fullscreen pass builder: each input stated once, for the graph and the
//!   shader's bindings.
//! - [`util`]: pass-level pipeline helpers (a pipeline with its descriptor set, tile draws).
//! - [`technique`] and [`registry`]: the contract a technique module implements (with the part
//!   of a frame each family of techniques declares: its G-buffer needs, tables, uploads and
//!   passes) and the one list of them, which everything that names techniques iterates.

pub mod antialias;
pub mod capabilities;
pub mod copy_pass;
pub mod debug_view;
pub mod gbuffer;
pub mod gbuffer_desc;
pub mod knob;
pub mod layer_depth;
pub mod layered;
pub mod lighting;
pub mod pass;
pub mod registry;
pub mod shadows;
pub mod sss;
pub mod technique;
pub mod tonemap;
pub mod translucency;
pub mod util;
