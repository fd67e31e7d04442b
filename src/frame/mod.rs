//! The frame: what a scene's materials ask for, declared as one render graph, and the renderer
//! that records it.
//!
//! - [`settings`]: how a frame is built ([`FrameSettings`]) and the A/B technique override
//!   ([`Technique`]; `auto`, the default, lets the materials decide).
//! - [`desc`]: the frame description derived from the scene's materials ([`FrameDesc`]).
//! - [`declare`]: [`declare_frame`], the one place that decides which passes a frame has;
//!   `lucent plan` calls it without a GPU, [`Renderer`] with one.
//! - [`renderer`]: a scene compiled into an executable frame on a device.
//! - [`inspect`]: `lucent inspect FILE`, any input loaded with every check and summarised.
//! - [`readback`]: images and G-buffers read back and decoded.
//! - [`runner`]: [`FrameRunner`] submits frames either as one command buffer (in-frame
//!   timestamps) or one submission per physical pass (isolated timing).

pub mod declare;
pub mod desc;
pub mod inspect;
pub mod readback;
pub mod renderer;
pub mod runner;
pub mod settings;

pub use declare::{compile_options, declare_frame, plan_frame, FrameOutputs, GBufferOutputs};
pub use desc::{FrameDesc, TranslucencyDesc};
pub use readback::{decode_texels, FrameImages, GBufferReadback, LitReadback};
pub use renderer::{render_frame, Renderer};
pub use runner::{destroy_after_idle, FrameRunner, FrameTiming};
pub use settings::{Fault, FrameSettings, TargetDesc, Technique};
