//! Screen regions a host gives with a frame (its objects' projected bounds), as the tiles
//! lucent's passes draw in: an effect then runs its expensive shader only where its materials
//! may be, as lucent's own frames do with the tiles they project from their objects' bounds
//! (`crate::gpu_scene::tiles`).

use ash::vk;

use glam::Vec3;

use super::HostCamera;
use crate::gpu_scene::tiles::tiles_touched_by;
use crate::gpu_scene::TileRect;

/// [`screen_region`] of the box `lo..hi` (an object's bounds in its own space) placed in the
/// world by `transform`.
pub fn box_screen_region(
    bounds: (Vec3, Vec3),
    transform: glam::Mat4,
    camera: &HostCamera,
    extent: vk::Extent2D,
    reach: f32,
) -> Option<vk::Rect2D> {
    screen_region(&box_corners(bounds, transform), camera, extent, reach)
}

/// The eight corners of the box `lo..hi` placed in the world by `transform`.
fn box_corners((lo, hi): (Vec3, Vec3), transform: glam::Mat4) -> Vec<Vec3> {
    (0..8)
        .map(|i| {
            let p = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            transform.transform_point3(p)
        })
        .collect()
}

/// The view depth of the nearest corner of the box `bounds` placed by `transform` (0 when
/// the box reaches the eye's plane or a corner is not finite), as lucent's own tiles measure
/// how near an object comes.
pub(crate) fn box_nearest_depth(
    bounds: (Vec3, Vec3),
    transform: glam::Mat4,
    camera: &HostCamera,
) -> f32 {
    box_corners(bounds, transform)
        .into_iter()
        .map(|corner| -camera.view.transform_point3(corner).z)
        .fold(f32::MAX, |nearest, depth| {
            if depth.is_finite() && depth > 1e-6 {
                nearest.min(depth)
            } else {
                0.0
            }
        })
}

/// The screen rectangle of the world-space points `corners` (an object's bounding box's eight
/// corners, say) seen by `camera` at `extent`, widened by `reach` world units projected at
/// the points' nearest view depth (for an [`super::SssEffect`], [`super::SssEffect::reach`]:
/// the blurs spread light that far beyond an object; 0 for translucency), as lucent widens
/// its own objects' tiles: what an effect's `regions` want. The widening is at most a quarter
/// of the screen's larger side. `None` when a point is behind the eye (give no region: the
/// whole screen); an empty rectangle when the points are off screen (the effect draws
/// nothing there).
pub fn screen_region(
    corners: &[Vec3],
    camera: &HostCamera,
    extent: vk::Extent2D,
    reach: f32,
) -> Option<vk::Rect2D> {
    let view_projection = camera.projection * camera.view;
    let size = glam::Vec2::new(extent.width as f32, extent.height as f32);
    let (mut low, mut high) = (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN));
    let mut nearest = f32::MAX;
    for &corner in corners {
        let clip = view_projection * corner.extend(1.0);
        // Clip-space w is the view depth for a perspective projection: <= 0 is behind the eye.
        if !clip.is_finite() || clip.w <= 1e-6 {
            return None;
        }
        nearest = nearest.min(clip.w);
        let pixel = (glam::Vec2::new(clip.x, clip.y) / clip.w * 0.5 + 0.5) * size;
        (low, high) = (low.min(pixel), high.max(pixel));
    }
    if corners.is_empty() {
        return Some(vk::Rect2D::default());
    }
    // The reach on screen: world units times the focal length in pixels over the depth,
    // clamped (as lucent's own tiles are) so a huge or non-finite reach stays bounded.
    let focal_px = camera.projection.y_axis.y.abs() * size.y * 0.5;
    let quarter = 0.25 * size.x.max(size.y);
    let margin = (reach.max(0.0) * focal_px / nearest).min(quarter);
    let margin = if margin.is_finite() { margin } else { quarter } + 1.0;
    let low = (low - margin).floor().max(glam::Vec2::ZERO);
    let high = (high + margin).ceil().min(size);
    if high.x <= low.x || high.y <= low.y {
        return Some(vk::Rect2D::default());
    }
    Some(vk::Rect2D {
        offset: vk::Offset2D {
            x: low.x as i32,
            y: low.y as i32,
        },
        extent: vk::Extent2D {
            width: (high.x - low.x) as u32,
            height: (high.y - low.y) as u32,
        },
    })
}

/// The host's regions as tiles the pass draws (all marked), clipped to `extent`; empty ones
/// dropped. No region at all stays no tile (the whole screen); regions that all fall outside
/// the screen become one empty tile, which draws nothing.
pub(crate) fn clipped(regions: &[vk::Rect2D], extent: vk::Extent2D) -> Vec<TileRect> {
    // Each region clipped, as (x0, y0, x1, y1).
    let rects: Vec<(u32, u32, u32, u32)> = regions
        .iter()
        .filter_map(|r| {
            let x0 = i64::from(r.offset.x).clamp(0, i64::from(extent.width));
            let y0 = i64::from(r.offset.y).clamp(0, i64::from(extent.height));
            let x1 = (i64::from(r.offset.x) + i64::from(r.extent.width))
                .clamp(0, i64::from(extent.width));
            let y1 = (i64::from(r.offset.y) + i64::from(r.extent.height))
                .clamp(0, i64::from(extent.height));
            (x1 > x0 && y1 > y0).then_some((x0 as u32, y0 as u32, x1 as u32, y1 as u32))
        })
        .collect();
    if rects.is_empty() {
        return if regions.is_empty() {
            Vec::new()
        } else {
            vec![TileRect {
                x: 0,
                y: 0,
                width: 0,
                height: 0,
                translucent: true,
            }]
        };
    }
    disjoint(&rects)
}

/// The union of `rects` (x0, y0, x1, y1) as rectangles that do not overlap: passes that add
/// into the host's light draw each pixel once however the host's regions overlap (two
/// objects' boxes on screen). Vertical strips between the rectangles' x edges, each strip's
/// covered y spans merged, then strips with the same span side by side merged back.
fn disjoint(rects: &[(u32, u32, u32, u32)]) -> Vec<TileRect> {
    let mut xs: Vec<u32> = rects.iter().flat_map(|r| [r.0, r.2]).collect();
    xs.sort_unstable();
    xs.dedup();
    let mut out: Vec<TileRect> = Vec::new();
    for strip in xs.windows(2) {
        let (a, b) = (strip[0], strip[1]);
        let mut spans: Vec<(u32, u32)> = rects
            .iter()
            .filter(|r| r.0 <= a && r.2 >= b)
            .map(|r| (r.1, r.3))
            .collect();
        spans.sort_unstable();
        let mut merged: Vec<(u32, u32)> = Vec::new();
        for (y0, y1) in spans {
            match merged.last_mut() {
                Some(last) if y0 <= last.1 => last.1 = last.1.max(y1),
                _ => merged.push((y0, y1)),
            }
        }
        for (y0, y1) in merged {
            // The same span ending where this strip starts: widen it.
            match out
                .iter_mut()
                .find(|t| t.x + t.width == a && t.y == y0 && t.y + t.height == y1)
            {
                Some(t) => t.width += b - a,
                None => out.push(TileRect {
                    x: a,
                    y: y0,
                    width: b - a,
                    height: y1 - y0,
                    translucent: true,
                }),
            }
        }
    }
    out
}

/// The screen as tiles of [`crate::gpu_scene::tiles::TILE_SIZE`] (merged into rectangles), marked where `regions` touch
/// them, for passes that draw their own shader in the marked tiles and a pass-through variant
/// elsewhere (the SSS chains, each with its own materials' regions): with no region, none is
/// marked (a chain none of whose materials has a region passes the light through everywhere).
pub(crate) fn tiles_marked_by(regions: &[vk::Rect2D], extent: vk::Extent2D) -> Vec<TileRect> {
    tiles_touched_by(clipped(regions, extent), extent.width, extent.height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_are_clipped_to_the_screen_and_none_means_the_whole_screen() {
        let extent = vk::Extent2D {
            width: 100,
            height: 50,
        };
        let rect = |x, y, w, h| vk::Rect2D {
            offset: vk::Offset2D { x, y },
            extent: vk::Extent2D {
                width: w,
                height: h,
            },
        };
        assert!(clipped(&[], extent).is_empty());
        let tiles = clipped(&[rect(-10, 40, 30, 30), rect(90, 0, u32::MAX, 5)], extent);
        assert_eq!(
            tiles
                .iter()
                .map(|t| (t.x, t.y, t.width, t.height))
                .collect::<Vec<_>>(),
            [(0, 40, 20, 10), (90, 0, 10, 5)]
        );
        // Overlapping regions become rectangles that cover their union once.
        let tiles = clipped(&[rect(10, 10, 40, 20), rect(30, 0, 40, 20)], extent);
        let mut covered = vec![0u8; 100 * 50];
        for t in &tiles {
            for y in t.y..t.y + t.height {
                for x in t.x..t.x + t.width {
                    covered[(y * 100 + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c <= 1), "{tiles:?}");
        assert_eq!(
            covered.iter().filter(|&&c| c == 1).count(),
            40 * 20 * 2 - 20 * 10
        );
        // Regions all off screen draw nothing (one empty tile), not the whole screen.
        let off = clipped(&[rect(200, 0, 10, 10)], extent);
        assert_eq!(off.len(), 1);
        assert_eq!(off[0].width * off[0].height, 0);
    }

    #[test]
    fn marked_tiles_cover_the_screen_and_mark_what_the_regions_touch_or_none() {
        let extent = vk::Extent2D {
            width: 200,
            height: 100,
        };
        let region = vk::Rect2D {
            offset: vk::Offset2D { x: 70, y: 10 },
            extent: vk::Extent2D {
                width: 10,
                height: 10,
            },
        };
        let tiles = tiles_marked_by(&[region], extent);
        let area: u32 = tiles.iter().map(|t| t.width * t.height).sum();
        assert_eq!(area, 200 * 100, "every pixel in exactly one rectangle");
        let marked: Vec<_> = tiles.iter().filter(|t| t.translucent).collect();
        assert_eq!(marked.len(), 1);
        assert_eq!((marked[0].x, marked[0].y, marked[0].width), (64, 0, 64));
        // No region: the whole screen in tiles, none marked.
        let none = tiles_marked_by(&[], extent);
        assert_eq!(
            none.iter().map(|t| t.width * t.height).sum::<u32>(),
            200 * 100
        );
        assert!(none.iter().all(|t| !t.translucent));
    }
}
