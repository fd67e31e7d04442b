//! Screen tiles: which rectangles of the screen objects of a kind may cover this frame, so a
//! pass draws its expensive variant only there (the lighting pass's translucency variant, the
//! SSS blurs, LEAN final lighting). Each object's bounding box is projected on the CPU every
//! frame and widened by how far its effect spreads; the marked tiles are merged into few
//! rectangles, each drawn as the fullscreen triangle under a scissor.
//!
//! Only rasterisation reliably skips work on every driver: lavapipe shades both sides of a
//! per-pixel branch (docs/translucency.md).

use glam::Vec3;

use crate::scene::Scene;

/// Side of the screen tiles the lighting pass is split into, in pixels.
pub const TILE_SIZE: u32 = 64;

/// Which screen tiles translucent objects may cover: each translucent object's bounding box
/// (object space, `bounds[mesh]`) is projected, and every tile its screen rectangle touches is
/// marked. Conservative: a box crossing the near plane marks every tile, one wholly behind the
/// camera or outside the frustum marks none. Row-major, `columns x rows` tiles of
/// [`TILE_SIZE`]. `ids` are the objects' translucency material IDs (0: not translucent in
/// this frame; a forced technique makes media translucent).
pub fn translucent_tiles(
    scene: &Scene,
    ids: &[u8],
    bounds: &[(Vec3, Vec3)],
    width: u32,
    height: u32,
) -> (u32, u32, Vec<bool>) {
    object_tiles(scene, bounds, width, height, |i, _| {
        ids.get(i).is_some_and(|&id| id > 0).then_some(0.0)
    })
}

/// The tiles objects may cover, for the objects `reach` selects (by index and object): it returns how far (world
/// units, at the object) their effect spreads beyond their surface, which widens their
/// rectangles by that distance projected at the object's nearest point (clamped to a quarter
/// of the screen, as the SSS blur clamps its reach). See [`translucent_tiles`].
pub fn object_tiles(
    scene: &Scene,
    bounds: &[(Vec3, Vec3)],
    width: u32,
    height: u32,
    reach: impl Fn(usize, &crate::scene::Object) -> Option<f32>,
) -> (u32, u32, Vec<bool>) {
    object_tiles_at_depth(scene, bounds, width, height, |i, object, _| {
        reach(i, object)
    })
}

/// [`object_tiles`] for a `reach` that also depends on how near the object comes to the eye:
/// its third argument is the view depth of the nearest corner of the object's box (scene
/// units; 0 when the box reaches the eye's plane).
pub fn object_tiles_at_depth(
    scene: &Scene,
    bounds: &[(Vec3, Vec3)],
    width: u32,
    height: u32,
    reach: impl Fn(usize, &crate::scene::Object, f32) -> Option<f32>,
) -> (u32, u32, Vec<bool>) {
    let (columns, rows) = (width.div_ceil(TILE_SIZE), height.div_ceil(TILE_SIZE));
    let mut tiles = vec![false; (columns * rows) as usize];
    let aspect = width as f32 / height.max(1) as f32;
    let view_proj = scene.camera.projection(aspect) * scene.camera.view();
    let focal_px = scene.camera.focal_px(height);
    let max_margin = 0.25 * width.max(height) as f32;
    for (index, object) in scene.objects.iter().enumerate() {
        let (lo, hi) = bounds[object.mesh];
        let clip_from_object = view_proj * object.transform;
        let corners = (0..8).map(|i| {
            let p = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            clip_from_object * p.extend(1.0)
        });
        let corners: Vec<glam::Vec4> = corners.collect();
        // Clip-space w is the view depth: <= 0 is behind the eye.
        let behind = corners.iter().filter(|c| c.w <= 1e-6).count();
        if behind == corners.len() {
            continue;
        }
        let nearest = if behind == 0 {
            corners.iter().fold(f32::MAX, |m, c| m.min(c.w))
        } else {
            0.0
        };
        let Some(reach_world) = reach(index, object, nearest) else {
            continue;
        };
        // A box crossing the near plane covers the whole screen.
        let (mut min, mut max) = (glam::Vec2::splat(-1.0), glam::Vec2::splat(1.0));
        if behind == 0 {
            let ndc = corners.iter().map(|c| c.truncate().truncate() / c.w);
            let (lo, hi) = ndc.fold(
                (glam::Vec2::splat(f32::MAX), glam::Vec2::splat(f32::MIN)),
                |(lo, hi), p| (lo.min(p), hi.max(p)),
            );
            // Guarded: a non-finite reach counts as the largest.
            let margin = (reach_world * focal_px / nearest).clamp(0.0, max_margin);
            let margin = if margin.is_finite() {
                margin
            } else {
                max_margin
            };
            let ndc_margin =
                glam::Vec2::new(2.0 * margin / width as f32, 2.0 * margin / height as f32);
            if hi.x + ndc_margin.x < -1.0
                || hi.y + ndc_margin.y < -1.0
                || lo.x - ndc_margin.x > 1.0
                || lo.y - ndc_margin.y > 1.0
            {
                continue;
            }
            (min, max) = (
                (lo - ndc_margin).max(glam::Vec2::splat(-1.0)),
                (hi + ndc_margin).min(glam::Vec2::splat(1.0)),
            );
        }
        // NDC to pixels (Vulkan: y = -1 is the top row), one pixel of margin for rasterisation.
        let to_px = |v: f32, size: u32| ((v + 1.0) * 0.5 * size as f32).clamp(0.0, size as f32);
        let x0 = (to_px(min.x, width) - 1.0).max(0.0) as u32 / TILE_SIZE;
        let x1 = ((to_px(max.x, width) + 1.0) as u32).min(width - 1) / TILE_SIZE;
        let y0 = (to_px(min.y, height) - 1.0).max(0.0) as u32 / TILE_SIZE;
        let y1 = ((to_px(max.y, height) + 1.0) as u32).min(height - 1) / TILE_SIZE;
        for y in y0..=y1.min(rows - 1) {
            for x in x0..=x1.min(columns - 1) {
                tiles[(y * columns + x) as usize] = true;
            }
        }
    }
    (columns, rows, tiles)
}

/// A rectangle of the lighting pass in pixels, shaded with the translucency variant or not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TileRect {
    /// Left column.
    pub x: u32,
    /// Top row.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
    /// Whether translucent objects may cover it.
    pub translucent: bool,
}

/// Merges marked tiles into few rectangles (runs along each row, then equal runs of
/// consecutive rows), clipped to `width` x `height`. Each rectangle is drawn as the fullscreen
/// triangle under a scissor: whole rasteriser bins stay fully covered, so a frame without
/// translucent pixels costs what one fullscreen draw costs (two triangles per tile would split
/// every bin along the diagonal, onto lavapipe's slower partial-coverage path).
pub fn tile_rects(columns: u32, tiles: &[bool], width: u32, height: u32) -> Vec<TileRect> {
    let mut runs: Vec<(u32, u32, u32, bool)> = Vec::new(); // (row, first column, end column, class)
    for (row, cells) in tiles.chunks(columns.max(1) as usize).enumerate() {
        let mut start = 0usize;
        while start < cells.len() {
            let marked = cells[start];
            let end = cells[start..]
                .iter()
                .position(|&t| t != marked)
                .map_or(cells.len(), |n| start + n);
            runs.push((row as u32, start as u32, end as u32, marked));
            start = end;
        }
    }
    let mut rects: Vec<(u32, u32, u32, u32, bool)> = Vec::new(); // (row0, row1, c0, c1, class)
    for (row, c0, c1, marked) in runs {
        match rects
            .iter_mut()
            .find(|r| r.1 == row && r.2 == c0 && r.3 == c1 && r.4 == marked)
        {
            Some(r) => r.1 = row + 1,
            None => rects.push((row, row + 1, c0, c1, marked)),
        }
    }
    rects
        .into_iter()
        .map(|(r0, r1, c0, c1, translucent)| {
            let (x, y) = (c0 * TILE_SIZE, r0 * TILE_SIZE);
            TileRect {
                x,
                y,
                width: (c1 * TILE_SIZE).min(width) - x,
                height: (r1 * TILE_SIZE).min(height) - y,
                translucent,
            }
        })
        .collect()
}

/// The `width` x `height` screen as [`tile_rects`], marked where any of `rects` (pixel
/// rectangles inside the screen) touches a tile: for passes that draw their own shader in
/// the marked tiles and a pass-through elsewhere (the SSS chains). No rectangle: none marked.
pub fn tiles_touched_by(
    rects: impl IntoIterator<Item = TileRect>,
    width: u32,
    height: u32,
) -> Vec<TileRect> {
    let columns = width.div_ceil(TILE_SIZE);
    let rows = height.div_ceil(TILE_SIZE);
    let mut marked = vec![false; (columns * rows) as usize];
    for r in rects.into_iter().filter(|r| r.width * r.height > 0) {
        for row in r.y / TILE_SIZE..(r.y + r.height).div_ceil(TILE_SIZE) {
            for column in r.x / TILE_SIZE..(r.x + r.width).div_ceil(TILE_SIZE) {
                marked[(row * columns + column) as usize] = true;
            }
        }
    }
    tile_rects(columns, &marked, width, height)
}

/// One screen's worth of tile rectangles whose marked tiles are those marked in any of
/// `partitions` (each [`tile_rects`] of the same screen: several passes' tiles, such as the
/// SSS chains', for a pass that must cover all of them once). Laying the partitions over each
/// other instead would draw a pixel once per partition, a pass-through over a marked one.
pub fn union_of_marked<'a>(partitions: impl IntoIterator<Item = &'a [TileRect]>) -> Vec<TileRect> {
    let rects: Vec<TileRect> = partitions.into_iter().flatten().copied().collect();
    // Every partition covers the whole screen: its far corner is the screen's.
    let width = rects.iter().map(|r| r.x + r.width).max().unwrap_or(0);
    let height = rects.iter().map(|r| r.y + r.height).max().unwrap_or(0);
    tiles_touched_by(rects.into_iter().filter(|r| r.translucent), width, height)
}

/// Object-space bounding box of each mesh.
pub fn mesh_bounds(scene: &Scene) -> Vec<(Vec3, Vec3)> {
    bounds_of(&scene.meshes)
}

/// Object-space bounding box of each of `meshes`.
pub fn bounds_of(meshes: &[crate::scene::Mesh]) -> Vec<(Vec3, Vec3)> {
    meshes
        .iter()
        .map(|m| {
            m.positions.iter().fold(
                (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
                |(lo, hi), &p| (lo.min(p), hi.max(p)),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::builtin;

    #[test]
    fn tiles_cover_translucent_objects_and_nothing_behind_the_camera() {
        let (w, h) = (320, 240);
        let ids = |s: &Scene| {
            crate::features::translucency::MaterialTable::new(s, false)
                .unwrap()
                .object_ids
        };
        let full = builtin("grid125").unwrap();
        let (columns, rows, tiles) =
            translucent_tiles(&full, &ids(&full), &mesh_bounds(&full), w, h);
        assert_eq!((columns, rows), (5, 4));
        assert!(tiles.iter().filter(|&&t| t).count() > tiles.len() * 3 / 4);
        let none = builtin("grid125:0").unwrap();
        let (_, _, tiles) = translucent_tiles(&none, &ids(&none), &mesh_bounds(&none), w, h);
        assert!(
            tiles.iter().all(|&t| !t),
            "the cube behind the camera marks no tile"
        );
        let rects = tile_rects(columns, &tiles, w, h);
        assert_eq!(
            rects,
            unmarked_screen(w, h),
            "no translucent tile: one rectangle, the whole screen"
        );
        // A marked tile in the middle splits the screen into rectangles that cover every
        // pixel exactly once.
        let mut one = vec![false; (columns * rows) as usize];
        one[(columns + 2) as usize] = true;
        let rects = tile_rects(columns, &one, w, h);
        let mut covered = vec![0u8; (w * h) as usize];
        for r in &rects {
            for y in r.y..r.y + r.height {
                for x in r.x..r.x + r.width {
                    covered[(y * w + x) as usize] += 1;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
        assert_eq!(rects.iter().filter(|r| r.translucent).count(), 1);
    }

    #[test]
    fn the_union_of_two_partitions_covers_each_pixel_once_marked_where_either_is() {
        // 150 x 100: 3 x 2 tiles, the last column and row clipped.
        let (w, h, columns) = (150, 100, 3);
        let a = tile_rects(columns, &[true, false, false, false, false, false], w, h);
        let b = tile_rects(columns, &[false, false, false, false, false, true], w, h);
        let union = union_of_marked([&a[..], &b[..]]);
        let mut covered = vec![0u8; (w * h) as usize];
        let mut marked = vec![false; (w * h) as usize];
        for r in &union {
            for y in r.y..r.y + r.height {
                for x in r.x..r.x + r.width {
                    covered[(y * w + x) as usize] += 1;
                    marked[(y * w + x) as usize] = r.translucent;
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1), "{union:?}");
        let at = |x: u32, y: u32| marked[(y * w + x) as usize];
        assert!(at(0, 0) && at(63, 63) && at(149, 99) && at(128, 64));
        assert!(!at(64, 0) && !at(0, 64) && !at(127, 99));
        // Nothing marked anywhere: one unmarked rectangle, the whole screen.
        let none = tile_rects(columns, &[false; 6], w, h);
        assert_eq!(
            union_of_marked([&none[..], &none[..]]),
            unmarked_screen(w, h)
        );
    }

    /// The whole `w` x `h` screen as one unmarked rectangle.
    fn unmarked_screen(w: u32, h: u32) -> Vec<TileRect> {
        vec![TileRect {
            x: 0,
            y: 0,
            width: w,
            height: h,
            translucent: false,
        }]
    }
}
