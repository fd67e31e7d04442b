//! Image files and image comparison: what lucent writes (PNG, EXR, atomic text files) and how
//! it compares two images perceptually (FLIP, with thresholds and difference images).
//!
//! - [`output`]: PNG (sRGB RGBA8) and OpenEXR (linear float) writers, fp16 decoding.
//! - `compare` (feature `measure`): FLIP between two images, and golden-image comparison that
//!   writes the actual and difference PNGs on failure.

#[cfg(feature = "measure")]
pub mod compare;
pub mod output;
