//! The look check, measured: how much of a frame a technique changes against plain lighting
//! (`--technique none`), and whether it changes anything it should not (halos: pixels of
//! objects that have none of the frame's techniques). `lucent gallery` prints these numbers
//! beside its pictures, and `tests/gpu/showcase.rs` holds the showcase scenes to them.
//!
//! - *Changed*: the share of pixels whose displayed value moved by more than
//!   [`CHANGED_THRESHOLD`] in some channel: what a viewer comparing the two stills sees.
//! - *Technique pixels*: the pixels some material with translucency, an SSS profile or a
//!   layered medium covers, found by rendering a mask frame of the same view (no lights, a
//!   white constant environment, those materials white and every other one black).
//! - *Halo*: pixels outside that mask whose displayed value moved by more than
//!   [`HALO_THRESHOLD`] (the SSS passes write only scattering pixels, translucency and the
//!   layered terms only their own materials' pixels: any such change is an artefact).

use glam::Vec3;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::GpuContext;
use crate::frame::{render_frame, FrameSettings, Technique};
use crate::scene::{Environment, Scene};
use crate::Result;

/// A pixel counts as changed when some channel moved by more than this (8/255 of the display
/// value: about the smallest step a viewer notices side by side).
pub const CHANGED_THRESHOLD: u8 = 8;

/// A pixel outside the technique mask counts as a halo when some channel moved by more than
/// this (2/255: above the rounding of two encodings of one value).
pub const HALO_THRESHOLD: u8 = 2;

/// What a technique does to a frame, measured against plain lighting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Share of all pixels changed by more than [`CHANGED_THRESHOLD`].
    pub changed: f64,
    /// Pixels covered by materials with a technique.
    pub technique_pixels: usize,
    /// Share of those pixels changed by more than [`CHANGED_THRESHOLD`]: how much of the
    /// objects the technique renders it changes, whatever part of the frame they fill.
    pub changed_on_objects: f64,
    /// Pixels outside them changed by more than [`HALO_THRESHOLD`].
    pub halo_pixels: usize,
    /// The largest change of a pixel outside them (display units, 0-255).
    pub halo_max: u8,
    /// Wall time of the frame with the technique and without, milliseconds (one frame each:
    /// a hint, not a benchmark).
    pub frame_ms: (f64, f64),
}

/// The two frames a look compares and its numbers.
pub struct LookImages {
    /// The frame as `settings` asks (RGBA8).
    pub with: Vec<u8>,
    /// The same frame under `--technique none` (RGBA8).
    pub without: Vec<u8>,
    /// The technique mask, one bool per pixel.
    pub mask: Vec<bool>,
    /// The numbers.
    pub look: Look,
}

/// Renders `scene` as `settings` asks and under `none`, and measures the difference.
pub fn look(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scene: &Scene,
    settings: FrameSettings,
) -> Result<LookImages> {
    let with = render_frame(gpu, shaders, pipeline_cache, scene, settings)?;
    let plain = FrameSettings {
        technique: Technique::None,
        ..settings
    };
    let without = render_frame(gpu, shaders, pipeline_cache, scene, plain)?;
    let masked = render_frame(gpu, shaders, pipeline_cache, &mask_scene(scene), plain)?;
    let mask: Vec<bool> = masked
        .display
        .chunks_exact(4)
        .map(|p| p[..3].iter().any(|&c| c > 32))
        .collect();
    let look = measure(
        &with.display,
        &without.display,
        &mask,
        (with.timing.wall_ms, without.timing.wall_ms),
    );
    Ok(LookImages {
        with: with.display,
        without: without.display,
        mask,
        look,
    })
}

/// The numbers of a look from its two frames (RGBA8) and the technique mask.
pub fn measure(with: &[u8], without: &[u8], mask: &[bool], frame_ms: (f64, f64)) -> Look {
    let mut changed = 0usize;
    let mut changed_on_objects = 0usize;
    let mut halo_pixels = 0usize;
    let mut halo_max = 0u8;
    for ((a, b), &technique) in with.chunks_exact(4).zip(without.chunks_exact(4)).zip(mask) {
        let change = a[..3]
            .iter()
            .zip(&b[..3])
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap_or(0);
        if change > CHANGED_THRESHOLD {
            changed += 1;
            changed_on_objects += usize::from(technique);
        }
        if !technique {
            if change > HALO_THRESHOLD {
                halo_pixels += 1;
            }
            halo_max = halo_max.max(change);
        }
    }
    let technique_pixels = mask.iter().filter(|m| **m).count();
    Look {
        changed: changed as f64 / mask.len().max(1) as f64,
        technique_pixels,
        changed_on_objects: changed_on_objects as f64 / technique_pixels.max(1) as f64,
        halo_pixels,
        halo_max,
        frame_ms,
    }
}

/// The difference of two RGBA8 frames, amplified `gain` times (alpha 255): where a technique
/// acts, for a reader's eye.
pub fn difference_image(with: &[u8], without: &[u8], gain: u32) -> Vec<u8> {
    with.chunks_exact(4)
        .zip(without.chunks_exact(4))
        .flat_map(|(a, b)| {
            let d = |i: usize| (u32::from(a[i].abs_diff(b[i])) * gain).min(255) as u8;
            [d(0), d(1), d(2), 255]
        })
        .collect()
}

/// The mask frame's scene: no lights, a white constant environment, black sky; materials with
/// a technique white (no textures, no specular), every other material black.
fn mask_scene(scene: &Scene) -> Scene {
    let mut mask = scene.clone();
    mask.lights.clear();
    mask.environment = Environment::constant(Vec3::ONE);
    mask.sky = Vec3::ZERO;
    mask.exposure = 1.0;
    for object in &mut mask.objects {
        let m = &mut object.material;
        let technique = m.translucency.is_some() || m.sss.is_some() || m.layers.is_some();
        m.albedo = if technique { Vec3::ONE } else { Vec3::ZERO };
        m.specular = 0.0;
        m.albedo_texture = None;
        m.normal_texture = None;
    }
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changed_and_halo_are_counted_apart() {
        let without = vec![100u8; 4 * 4];
        let mut with = without.clone();
        with[0] = 120; // technique pixel, changed
        with[4] = 103; // outside, a halo, not "changed"
        with[8] = 101; // outside, rounding
        let mask = [true, false, false, false];
        let look = measure(&with, &without, &mask, (1.0, 1.0));
        assert_eq!(look.changed, 0.25);
        assert_eq!(look.halo_pixels, 1);
        assert_eq!(look.halo_max, 3);
        assert_eq!(look.technique_pixels, 1);
        let d = difference_image(&with, &without, 4);
        assert_eq!(&d[..4], &[80, 0, 0, 255]);
    }
}
