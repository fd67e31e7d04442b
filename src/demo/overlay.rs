//! The demo's on-screen text: lines rasterized on the CPU (ab_glyph) into an opaque panel.
//!
//! The panel is a tightly packed 4-byte-per-pixel image in the swapchain's channel order; the
//! presenter copies it over the top-left corner of the swapchain image after the frame was
//! blitted there. Copying an opaque panel needs no pipeline, works on every driver (lavapipe
//! included), and never touches the renderer's own display image, so screenshots are the frame
//! without the overlay.

use std::path::Path;

use ab_glyph::{point, Font, FontVec, PxScale, ScaleFont};

use crate::{LucentError, Result};

/// Text height in pixels.
const TEXT_PX: f32 = 15.0;
/// Padding around the text, pixels.
const PAD: u32 = 6;
/// Panel background (linear bytes as written: a dark grey).
const BACKGROUND: [u8; 3] = [24, 24, 28];

/// Colour of a line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tone {
    /// Ordinary text (light grey).
    Normal,
    /// Errors (red).
    Error,
    /// Headings and the current selection (yellow).
    Accent,
}

impl Tone {
    fn rgb(self) -> [u8; 3] {
        match self {
            Tone::Normal => [225, 225, 225],
            Tone::Error => [255, 90, 80],
            Tone::Accent => [255, 210, 90],
        }
    }
}

/// A rasterized panel: `width * height * 4` bytes, rows top first.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, 4 bytes each, in the order asked for ([`TextRenderer::render`]'s `bgra`).
    pub pixels: Vec<u8>,
}

/// Rasterizes lines of text with one font.
pub struct TextRenderer {
    font: FontVec,
}

impl TextRenderer {
    /// Loads the TrueType/OpenType font at `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let bytes = std::fs::read(path)
            .map_err(|e| LucentError::file(path, format!("cannot read font: {e}")))?;
        let font = FontVec::try_from_vec(bytes)
            .map_err(|_| LucentError::file(path, "not a TrueType/OpenType font"))?;
        Ok(Self { font })
    }

    /// Lays `lines` out top to bottom and rasterizes them into a panel no larger than
    /// `max_width` x `max_height` (text beyond is cut off). `None` when there is nothing to show
    /// or no room. `bgra`: write pixels as B, G, R, A (else R, G, B, A).
    pub fn render(
        &self,
        lines: &[(String, Tone)],
        max_width: u32,
        max_height: u32,
        bgra: bool,
    ) -> Option<Panel> {
        if lines.is_empty() {
            return None;
        }
        let scaled = self.font.as_scaled(PxScale::from(TEXT_PX));
        let line_height = (scaled.height() + scaled.line_gap()).ceil().max(1.0);
        let text_width = lines
            .iter()
            .map(|(l, _)| self.line_width(l))
            .fold(0.0f32, f32::max);
        let width = (text_width.ceil() as u32 + 2 * PAD).min(max_width);
        let height = ((line_height * lines.len() as f32).ceil() as u32 + 2 * PAD).min(max_height);
        if width == 0 || height == 0 {
            return None;
        }
        let mut coverage = vec![0.0f32; (width * height) as usize];
        let mut tone_of_row = vec![Tone::Normal; height as usize];
        for (index, (line, tone)) in lines.iter().enumerate() {
            let top = PAD as f32 + index as f32 * line_height;
            if top >= height as f32 {
                break;
            }
            let first = top as usize;
            let last = ((top + line_height) as usize).min(height as usize);
            for t in &mut tone_of_row[first..last] {
                *t = *tone;
            }
            let baseline = top + scaled.ascent();
            let mut x = PAD as f32;
            let mut previous = None;
            for c in line.chars() {
                let id = scaled.glyph_id(c);
                if let Some(p) = previous {
                    x += scaled.kern(p, id);
                }
                let glyph = id.with_scale_and_position(PxScale::from(TEXT_PX), point(x, baseline));
                x += scaled.h_advance(id);
                previous = Some(id);
                let Some(outlined) = self.font.outline_glyph(glyph) else {
                    continue; // spaces and glyphs without outlines
                };
                let bounds = outlined.px_bounds();
                outlined.draw(|gx, gy, c| {
                    let px = bounds.min.x as i64 + i64::from(gx);
                    let py = bounds.min.y as i64 + i64::from(gy);
                    if px >= 0 && py >= 0 && (px as u32) < width && (py as u32) < height {
                        let slot = &mut coverage[(py as u32 * width + px as u32) as usize];
                        *slot = (*slot + c).min(1.0);
                    }
                });
            }
        }
        let mut pixels = Vec::with_capacity(coverage.len() * 4);
        for (i, &c) in coverage.iter().enumerate() {
            let fg = tone_of_row[i / width as usize].rgb();
            let mix =
                |k: usize| (f32::from(BACKGROUND[k]) * (1.0 - c) + f32::from(fg[k]) * c) as u8;
            let (r, g, b) = (mix(0), mix(1), mix(2));
            if bgra {
                pixels.extend_from_slice(&[b, g, r, 255]);
            } else {
                pixels.extend_from_slice(&[r, g, b, 255]);
            }
        }
        Some(Panel {
            width,
            height,
            pixels,
        })
    }

    fn line_width(&self, line: &str) -> f32 {
        let scaled = self.font.as_scaled(PxScale::from(TEXT_PX));
        let mut width = 0.0;
        let mut previous = None;
        for c in line.chars() {
            let id = scaled.glyph_id(c);
            if let Some(p) = previous {
                width += scaled.kern(p, id);
            }
            width += scaled.h_advance(id);
            previous = Some(id);
        }
        width
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_draws_foreground_pixels_within_the_limits() {
        let Ok(path) = crate::font::font_file() else {
            panic!("no font: run tools/setup.sh (fonts-dejavu-core)");
        };
        let text = TextRenderer::load(&path).unwrap();
        let lines = vec![
            ("lighting 1.23 ms".to_string(), Tone::Normal),
            ("error: x".to_string(), Tone::Error),
        ];
        let panel = text.render(&lines, 1000, 1000, false).unwrap();
        assert_eq!(panel.pixels.len() as u32, panel.width * panel.height * 4);
        assert!(panel.width > 2 * PAD && panel.height > 2 * PAD);
        let bright = panel.pixels.chunks_exact(4).filter(|p| p[0] > 200).count();
        assert!(bright > 20, "{bright} text pixels");
        // Red text exists (the error line) and BGRA swaps the channels.
        assert!(panel
            .pixels
            .chunks_exact(4)
            .any(|p| p[0] > 200 && p[2] < 120));
        let swapped = text.render(&lines, 1000, 1000, true).unwrap();
        assert!(swapped
            .pixels
            .chunks_exact(4)
            .any(|p| p[2] > 200 && p[0] < 120));
        // Clipped to the limits, and nothing for no room or no text.
        let small = text.render(&lines, 30, 10, false).unwrap();
        assert_eq!((small.width, small.height), (30, 10));
        assert!(text.render(&lines, 0, 10, false).is_none());
        assert!(text.render(&[], 100, 100, false).is_none());
    }
}
