//! The thickness baker against closed forms (slab, sphere), its determinism, the texture bake with
//! dilation, and the on-disk cache. Run with `--nocapture` to see the measured errors.
//!
//! The bake time of a ~10k-triangle mesh (for the README) is an ignored test:
//! `cargo test --release --test cpu -- --ignored --nocapture bake_time`.

use crate::common;
use glam::{Vec2, Vec3};
use lucent::bake::{
    bake_per_vertex, bake_points, bake_report, bake_texture, cache_file, cached_per_vertex,
    cached_per_vertex_with_status, BakeOptions, BakeStats, SamplePoint, DILATION_RINGS,
};
use lucent::scene::{Mesh, Shape};

/// Prints how the bake of `what` compares with `expected` and checks its mean within 0.02;
/// returns the largest per-vertex error.
fn check_mean(what: &str, values: &[f32], expected: f32, stats: &BakeStats) -> f32 {
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let worst = values
        .iter()
        .map(|v| (v - expected).abs())
        .fold(0.0f32, f32::max);
    println!(
        "{what}: expected {expected:.4}, mean {mean:.4} (error {:+.4}), worst per-vertex error \
         {worst:.4}; {}",
        mean - expected,
        bake_report(stats)
    );
    assert!(
        (mean - expected).abs() < 0.02,
        "{what}: mean {mean} vs {expected}"
    );
    worst
}

fn assert_unit_interval(values: &[f32]) {
    for (i, v) in values.iter().enumerate() {
        assert!(v.is_finite() && (0.0..=1.0).contains(v), "value {i} = {v}");
    }
}

/// A closed box `width x d x width` (y is the thin axis) with outward normals; the big top and
/// bottom faces are `n x n` grids so there are vertices near their centres.
fn slab(width: f32, d: f32, n: u32) -> Mesh {
    let mut mesh = Mesh::default();
    let h = width / 2.0;
    let quad = |mesh: &mut Mesh, corners: [Vec3; 4], normal: Vec3| {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(corners);
        mesh.normals.extend([normal; 4]);
        for tri in [[0, 1, 2], [0, 2, 3]] {
            let [a, b, c] = tri.map(|k| corners[k]);
            // Wind counter-clockwise seen from outside.
            let t = if (b - a).cross(c - a).dot(normal) > 0.0 {
                tri
            } else {
                [tri[0], tri[2], tri[1]]
            };
            mesh.indices.extend(t.map(|k| base + k as u32));
        }
    };
    for (y, normal) in [(d / 2.0, Vec3::Y), (-d / 2.0, Vec3::NEG_Y)] {
        let base = mesh.positions.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                let x = -h + width * i as f32 / n as f32;
                let z = -h + width * j as f32 / n as f32;
                mesh.positions.push(Vec3::new(x, y, z));
                mesh.normals.push(normal);
            }
        }
        for j in 0..n {
            for i in 0..n {
                let a = base + j * (n + 1) + i;
                let (b, c, e) = (a + 1, a + n + 1, a + n + 2);
                let up = normal.y > 0.0;
                // (x step) x (z step) = -y: swap for the top face.
                if up {
                    mesh.indices.extend([a, c, b, b, c, e]);
                } else {
                    mesh.indices.extend([a, b, c, b, e, c]);
                }
            }
        }
    }
    let y0 = -d / 2.0;
    let y1 = d / 2.0;
    for (normal, corners) in [
        (Vec3::X, [(h, y0, -h), (h, y0, h), (h, y1, h), (h, y1, -h)]),
        (
            Vec3::NEG_X,
            [(-h, y0, -h), (-h, y0, h), (-h, y1, h), (-h, y1, -h)],
        ),
        (Vec3::Z, [(-h, y0, h), (h, y0, h), (h, y1, h), (-h, y1, h)]),
        (
            Vec3::NEG_Z,
            [(-h, y0, -h), (h, y0, -h), (h, y1, -h), (-h, y1, -h)],
        ),
    ] {
        quad(
            &mut mesh,
            corners.map(|(x, y, z)| Vec3::new(x, y, z)),
            normal,
        );
    }
    mesh.validate("slab").unwrap();
    mesh
}

#[test]
fn slab_matches_one_minus_d_over_d_max_squared() {
    let d = 2.0;
    let mesh = slab(100.0, d, 20);
    // Every grid vertex within 10 of the centre of the top and bottom faces: 2 x 5 x 5.
    let central: Vec<SamplePoint> = mesh
        .positions
        .iter()
        .zip(&mesh.normals)
        .filter(|(p, n)| n.y.abs() == 1.0 && p.x.abs() <= 10.0 && p.z.abs() <= 10.0)
        .map(|(&position, &normal)| SamplePoint {
            position,
            normal,
            triangle: None,
        })
        .collect();
    assert_eq!(central.len(), 50);
    for ratio in [0.25f32, 0.5, 0.75] {
        let options = BakeOptions {
            rays: 1024,
            max_distance: Some(d / ratio),
            seed: 11,
            ..Default::default()
        };
        // The same computation bake_per_vertex does for these vertices (no triangle ignored,
        // origin offset along -N), restricted to the central ones to keep the test fast.
        let (values, stats) = bake_points(&mesh, &central, &options).unwrap();
        assert_unit_interval(&values);
        let expected = 1.0 - ratio * ratio;
        let worst = check_mean(&format!("slab d/D = {ratio}"), &values, expected, &stats);
        // One vertex is a binomial estimate: allow five standard errors.
        assert!(
            worst < 5.0 * stats.std_error as f32,
            "d/D = {ratio}: {worst}"
        );
    }
    // Thicker than the maximum distance: nothing is occluded.
    let options = BakeOptions {
        rays: 256,
        max_distance: Some(d * 0.9),
        ..Default::default()
    };
    let (values, _) = bake_points(&mesh, &central, &options).unwrap();
    assert!(values.iter().all(|&v| v == 0.0), "{values:?}");
}

#[test]
fn sphere_matches_d_over_two_r_squared() {
    let mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 64, 32);
    for d in [0.5f32, 1.0, 1.5, 2.5] {
        let options = BakeOptions {
            rays: 1024,
            max_distance: Some(d),
            seed: 5,
            ..Default::default()
        };
        let (values, stats) = bake_per_vertex(&mesh, &options).unwrap();
        assert_eq!(values.len(), mesh.vertex_count());
        assert_unit_interval(&values);
        let expected = if d >= 2.0 { 1.0 } else { (d / 2.0).powi(2) };
        // The 64 x 32 polyhedron is inscribed in the sphere, so its chords are up to ~0.25%
        // shorter; that bias (< 0.002 here) is well inside the tolerance.
        let worst = check_mean(&format!("sphere D = {d}"), &values, expected, &stats);
        assert!(worst < 6.0 * stats.std_error as f32, "D = {d}: {worst}");
    }
}

#[test]
fn default_max_distance_is_the_bounding_box_diagonal() {
    let mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 12, 6);
    let (values, stats) = bake_per_vertex(
        &mesh,
        &BakeOptions {
            rays: 16,
            ..Default::default()
        },
    )
    .unwrap();
    assert!((stats.max_distance - 12f32.sqrt()).abs() < 1e-3);
    // Every chord of a unit sphere is shorter than its box diagonal.
    assert!(values.iter().all(|&v| v == 1.0));
    assert_eq!(stats.rays, 16 * mesh.vertex_count() as u64);
}

#[test]
fn bakes_are_deterministic_for_a_seed_whatever_the_thread_count() {
    let mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 24, 12);
    let options = BakeOptions {
        rays: 64,
        max_distance: Some(1.2),
        seed: 99,
        ..Default::default()
    };
    let bake = |threads: usize, options: &BakeOptions| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| bake_per_vertex(&mesh, options).unwrap().0)
    };
    let one = bake(1, &options);
    assert_eq!(one, bake(1, &options));
    assert_eq!(one, bake(2, &options));
    assert_eq!(one, bake(3, &options));
    let other_seed = bake(
        2,
        &BakeOptions {
            seed: 100,
            ..options.clone()
        },
    );
    assert_ne!(one, other_seed);
    // Texture bakes too.
    let small = BakeOptions {
        texture_size: 24,
        rays: 16,
        ..options.clone()
    };
    let tex = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| bake_texture(&mesh, &small).unwrap().0)
    };
    assert_eq!(tex(1), tex(2));
}

#[test]
fn texture_bake_fills_charts_and_a_dilated_ring_and_writes_a_png() {
    // Squeeze the sphere's UVs into the centre quarter so there is room around the chart.
    let mut mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 32, 16);
    for uv in &mut mesh.uvs {
        *uv = *uv * 0.5 + Vec2::splat(0.25);
    }
    let options = BakeOptions {
        rays: 32,
        max_distance: Some(1.0),
        texture_size: 64,
        seed: 3,
        ..Default::default()
    };
    let (map, stats) = bake_texture(&mesh, &options).unwrap();
    assert_eq!(map.size, 64);
    assert_eq!(map.values.len(), 64 * 64);
    assert_unit_interval(&map.values);
    let covered = map.coverage.iter().filter(|&&c| c).count();
    assert_eq!(stats.samples, covered);
    // The chart spans texel centres 16..=47 in x (u in [0.25, 0.75]).
    assert!(covered > 30 * 30 && covered <= 32 * 32, "{covered}");
    let mean = map
        .values
        .iter()
        .zip(&map.coverage)
        .filter(|(_, &c)| c)
        .map(|(v, _)| v)
        .sum::<f32>()
        / covered as f32;
    println!("texture: {covered} texels, mean {mean:.4} (sphere closed form 0.25)");
    assert!((mean - 0.25).abs() < 0.03, "{mean}");
    let rings = DILATION_RINGS;
    let y = 32;
    for x in 0..64u32 {
        let i = (y * 64 + x) as usize;
        let inside = (16..48).contains(&x);
        let ring = (16 - rings..16).contains(&x) || (48..48 + rings).contains(&x);
        assert_eq!(map.coverage[i], inside, "x = {x}");
        if ring {
            assert!(map.values[i] > 0.05, "ring texel {x} not dilated");
        } else if !inside {
            assert_eq!(map.values[i], 0.0, "texel {x} beyond the dilation");
        }
    }
    let dir = common::temp_dir("bake-png");
    let path = dir.join("thickness.png");
    map.write_png(&path).unwrap();
    let (w, h, rgba) = lucent::images::output::read_png_rgba8(&path).unwrap();
    assert_eq!((w, h), (64, 64));
    let grey: Vec<u8> = rgba.chunks_exact(4).map(|p| p[0]).collect();
    assert_eq!(grey, map.to_luma8());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn texture_bake_needs_uvs_and_survives_odd_charts() {
    let mut mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 8, 4);
    let options = BakeOptions {
        rays: 8,
        texture_size: 16,
        ..Default::default()
    };
    // Out-of-range and degenerate UVs: clipped or skipped, never a panic or NaN.
    for (i, uv) in mesh.uvs.iter_mut().enumerate() {
        *uv = match i % 3 {
            0 => Vec2::new(-3.0, 1e30),
            1 => Vec2::splat(0.5),
            _ => *uv * 4.0 - Vec2::ONE,
        };
    }
    let (map, _) = bake_texture(&mesh, &options).unwrap();
    assert_unit_interval(&map.values);
    // Opposite normals on one triangle cancel when interpolated: the face normal takes over.
    let mut mesh = Mesh::generate(Shape::Plane { half_size: 1.0 }, 1, 1);
    mesh.normals[1] = Vec3::NEG_Y;
    mesh.normals[2] = Vec3::ZERO;
    let (map, _) = bake_texture(&mesh, &options).unwrap();
    assert_unit_interval(&map.values);
    mesh.uvs.clear();
    let err = bake_texture(&mesh, &options).unwrap_err().to_string();
    assert!(err.contains("texture coordinates"), "{err}");
}

#[test]
fn cache_hits_misses_and_survives_corruption() {
    let dir = common::temp_dir("bake-cache");
    let mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 16, 8);
    let options = BakeOptions {
        rays: 32,
        max_distance: Some(1.0),
        seed: 1,
        ..Default::default()
    };
    let (first, hit) = cached_per_vertex_with_status(&mesh, &options, &dir).unwrap();
    assert!(!hit);
    assert_eq!(first, bake_per_vertex(&mesh, &options).unwrap().0);
    let (second, hit) = cached_per_vertex_with_status(&mesh, &options, &dir).unwrap();
    assert!(hit);
    assert_eq!(first, second);
    assert_eq!(cached_per_vertex(&mesh, &options, &dir).unwrap(), first);

    // A different mesh or different options: a different key.
    let mut moved = mesh.clone();
    moved.positions[3].x += 1e-3;
    assert!(
        !cached_per_vertex_with_status(&moved, &options, &dir)
            .unwrap()
            .1
    );
    let more_rays = BakeOptions {
        rays: 33,
        ..options.clone()
    };
    assert!(
        !cached_per_vertex_with_status(&mesh, &more_rays, &dir)
            .unwrap()
            .1
    );

    // Corrupt the file: a miss that re-bakes the same values and repairs the cache.
    let file = cache_file(&mesh, &options, &dir);
    let mut bytes = std::fs::read(&file).unwrap();
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x40;
    std::fs::write(&file, &bytes).unwrap();
    let (again, hit) = cached_per_vertex_with_status(&mesh, &options, &dir).unwrap();
    assert!(!hit);
    assert_eq!(again, first);
    assert!(
        cached_per_vertex_with_status(&mesh, &options, &dir)
            .unwrap()
            .1
    );
    std::fs::write(&file, b"short").unwrap();
    assert!(
        !cached_per_vertex_with_status(&mesh, &options, &dir)
            .unwrap()
            .1
    );

    // A cache directory that cannot be created: the bake still comes back.
    let blocker = dir.join("not-a-directory");
    std::fs::write(&blocker, b"x").unwrap();
    let (values, hit) =
        cached_per_vertex_with_status(&mesh, &options, &blocker.join("cache")).unwrap();
    assert!(!hit);
    assert_eq!(values, first);

    // Invalid meshes are errors even through the cache.
    let mut broken = mesh.clone();
    broken.positions[0].y = f32::NAN;
    assert!(cached_per_vertex(&broken, &options, &dir).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The README's bake-time figure: a 100 x 50 UV sphere (9,800 triangles, 5,151 vertices) at 256
/// rays per vertex. `cargo test --release --test cpu -- --ignored --nocapture bake_time`
#[test]
#[ignore]
fn bake_time_of_a_10k_triangle_mesh() {
    let mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 100, 50);
    let options = BakeOptions {
        rays: 256,
        max_distance: Some(1.0),
        ..Default::default()
    };
    let (values, stats) = bake_per_vertex(&mesh, &options).unwrap();
    assert_unit_interval(&values);
    println!(
        "{} triangles, {} threads: {}",
        mesh.triangle_count(),
        rayon::current_num_threads(),
        bake_report(&stats)
    );
}
