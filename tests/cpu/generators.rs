//! Procedural generators: geometry invariants (validation, outward faces, unit normals, tangent
//! frames matching the UVs, no degenerate triangles), exact triangle counts, target-count
//! accuracy, and refusal of absurd sizes. CPU only, no GPU needed.

use glam::{Vec2, Vec3};
use lucent::scene::generators::{
    self, generate, generate_at_resolution, generate_with_triangles, resolution_for_triangles,
    triangle_count, triangle_count_at_resolution, Generator, MAX_TRIANGLES,
};
use lucent::scene::{Mesh, Shape};

/// Sum over triangles of the signed volume of the tetrahedron they span with the origin.
fn signed_volume(m: &Mesh) -> f64 {
    (0..m.triangle_count())
        .map(|t| {
            let [a, b, c] = m.triangle(t).map(|p| p.as_dvec3());
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// Twice the UV-space signed area of triangle `t`.
fn uv_cross(m: &Mesh, t: usize) -> f32 {
    let i = &m.indices[t * 3..t * 3 + 3];
    let [a, b, c]: [Vec2; 3] = [0, 1, 2].map(|k| m.uvs[i[k] as usize]);
    (b - a).perp_dot(c - a)
}

/// Everything every generated mesh promises (module docs of `generators`).
fn check_invariants(m: &Mesh, what: &str) {
    m.validate(what).unwrap();
    let n = m.vertex_count();
    assert_eq!(m.uvs.len(), n, "{what}: uvs");
    assert_eq!(m.tangents.len(), n, "{what}: tangents");
    let mut referenced = vec![false; n];
    for &i in &m.indices {
        referenced[i as usize] = true;
    }
    assert!(referenced.iter().all(|&r| r), "{what}: unreferenced vertex");
    for v in 0..n {
        let (nrm, t, uv) = (m.normals[v], m.tangents[v], m.uvs[v]);
        assert!(
            (nrm.length() - 1.0).abs() < 1e-4,
            "{what}: normal {v} = {nrm}"
        );
        assert!(
            (t.truncate().length() - 1.0).abs() < 1e-4,
            "{what}: tangent {v} = {t}"
        );
        assert!(
            t.truncate().dot(nrm).abs() < 1e-4,
            "{what}: tangent {v} not perpendicular to its normal"
        );
        assert!(t.w == 1.0 || t.w == -1.0, "{what}: tangent {v} w = {}", t.w);
        assert!(
            (0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y),
            "{what}: uv {v} = {uv}"
        );
    }
    let scale = m
        .positions
        .iter()
        .fold(0.0f32, |s, p| s.max(p.abs().max_element()));
    for t in 0..m.triangle_count() {
        let [a, b, c] = m.triangle(t);
        let area = (b - a).cross(c - a).length() / 2.0;
        assert!(
            area > 1e-12 * scale * scale,
            "{what}: triangle {t} is degenerate (area {area})"
        );
        // The handedness w must agree with the UV winding of every (outward, CCW) triangle:
        // that is what makes normal maps bend the right way.
        let uvc = uv_cross(m, t);
        assert!(uvc.abs() > 0.0, "{what}: triangle {t} has zero UV area");
        for k in 0..3 {
            let w = m.tangents[m.indices[t * 3 + k] as usize].w;
            assert_eq!(
                w,
                uvc.signum(),
                "{what}: triangle {t} corner {k}: tangent handedness disagrees with the UVs"
            );
        }
    }
}

/// Fraction of triangles whose face normal agrees with the mean of its vertex normals.
fn normal_agreement(m: &Mesh) -> f64 {
    let agree = (0..m.triangle_count())
        .filter(|&t| {
            let [a, b, c] = m.triangle(t);
            let i = &m.indices[t * 3..t * 3 + 3];
            let vn: Vec3 = i.iter().map(|&k| m.normals[k as usize]).sum();
            (b - a).cross(c - a).dot(vn) > 0.0
        })
        .count();
    agree as f64 / m.triangle_count() as f64
}

/// Every triangle faces away from `inside(centroid)`.
fn faces_outward(m: &Mesh, what: &str, inside: impl Fn(Vec3) -> Vec3) {
    for t in 0..m.triangle_count() {
        let [a, b, c] = m.triangle(t);
        let centroid = (a + b + c) / 3.0;
        assert!(
            (b - a).cross(c - a).dot(centroid - inside(centroid)) > 0.0,
            "{what}: triangle {t} faces inwards"
        );
    }
}

#[test]
fn every_generator_at_levels_0_to_3_keeps_every_invariant() {
    for &g in Generator::ALL {
        for level in 0..=3 {
            let what = format!("{g} level {level}");
            let m = generate(g, level).unwrap();
            check_invariants(&m, &what);
            assert_eq!(
                m.triangle_count() as u64,
                triangle_count(g, level),
                "{what}"
            );
            let volume = signed_volume(&m);
            match g {
                Generator::UvSphere | Generator::Icosphere | Generator::Cube => {
                    assert!(volume > 0.0, "{what}: volume {volume}");
                    faces_outward(&m, &what, |_| Vec3::ZERO);
                }
                Generator::Torus => {
                    assert!(volume > 0.0, "{what}: volume {volume}");
                    // Outward from the nearest point of the tube's centre circle.
                    faces_outward(&m, &what, |p| Vec3::new(p.x, 0.0, p.z).normalize_or_zero());
                }
                Generator::Plane => {
                    for t in 0..m.triangle_count() {
                        let [a, b, c] = m.triangle(t);
                        assert!((b - a).cross(c - a).y > 0.0, "{what}: triangle {t}");
                    }
                }
                Generator::Teapot => {
                    assert!(volume > 0.0, "{what}: volume {volume}");
                    let agreement = normal_agreement(&m);
                    assert!(agreement > 0.99, "{what}: normals agree on {agreement}");
                }
            }
            match g {
                Generator::UvSphere | Generator::Icosphere => {
                    assert_eq!(m.shape, Some(Shape::Sphere { radius: 1.0 }));
                    for p in &m.positions {
                        assert!((p.length() - 1.0).abs() < 1e-5, "{what}: {p}");
                    }
                }
                Generator::Plane => assert_eq!(m.shape, Some(Shape::Plane { half_size: 1.0 })),
                _ => assert_eq!(m.shape, None, "{what}"),
            }
        }
    }
}

#[test]
fn smallest_resolutions_are_valid_meshes_too() {
    for &g in Generator::ALL {
        let r = g.min_resolution();
        let m = generate_at_resolution(g, r).unwrap();
        check_invariants(&m, &format!("{g} resolution {r}"));
        assert_eq!(
            m.triangle_count() as u64,
            triangle_count_at_resolution(g, u64::from(r))
        );
        assert!(generate_at_resolution(g, r - 1).is_err());
        assert_eq!(triangle_count_at_resolution(g, u64::from(r) - 1), 0);
        // Odd teapot resolutions (nu != nv) and a few more of each, counted exactly.
        for r in r..r + 5 {
            let m = generate_at_resolution(g, r).unwrap();
            check_invariants(&m, &format!("{g} resolution {r}"));
            assert_eq!(
                m.triangle_count() as u64,
                triangle_count_at_resolution(g, u64::from(r)),
                "{g} resolution {r}"
            );
        }
    }
}

#[test]
fn documented_counts_at_level_4() {
    let counts: Vec<u64> = Generator::ALL
        .iter()
        .map(|&g| triangle_count(g, 4))
        .collect();
    assert_eq!(counts, [3_480, 5_120, 300, 5_400, 98, 6_320]);
    // The classic count for a 10 x 10 teapot: 32 * 2 * 100 minus the 8 * 10 pole triangles.
    assert_eq!(triangle_count_at_resolution(Generator::Teapot, 20), 6_320);
}

#[test]
fn cube_and_torus_volumes_match_their_closed_forms() {
    for level in [0, 5] {
        let v = signed_volume(&generate(Generator::Cube, level).unwrap());
        assert!((v - 8.0).abs() < 1e-4, "cube level {level}: volume {v}");
    }
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.35 * 0.35;
    let v = signed_volume(&generate(Generator::Torus, 5).unwrap());
    assert!((v - exact).abs() < 0.01 * exact, "torus {v} vs {exact}");
    let v = signed_volume(&generate(Generator::UvSphere, 5).unwrap());
    let sphere = 4.0 / 3.0 * std::f64::consts::PI;
    assert!((v - sphere).abs() < 0.01 * sphere, "sphere {v} vs {sphere}");
}

#[test]
fn icosphere_volume_approaches_the_sphere_as_the_level_rises() {
    let exact = 4.0 / 3.0 * std::f64::consts::PI;
    let mut previous = f64::INFINITY;
    for level in 0..=5 {
        let m = generate(Generator::Icosphere, level).unwrap();
        let v = signed_volume(&m);
        let error = exact - v;
        // Inscribed: always a little less, and less so each level.
        assert!(error > 0.0 && error < previous, "level {level}: {v}");
        previous = error;
    }
    assert!(previous < 0.002 * exact, "level 5 error {previous}");
}

#[test]
fn icosphere_uvs_are_longitude_squeezed_by_the_documented_1_1() {
    for level in [0, 3] {
        let m = generate(Generator::Icosphere, level).unwrap();
        for (p, uv) in m.positions.iter().zip(&m.uvs) {
            let theta = p.y.clamp(-1.0, 1.0).acos();
            assert!((uv.y - theta / std::f32::consts::PI).abs() < 1e-5);
            if p.x.abs() + p.z.abs() < 1e-6 {
                continue; // A pole: u is the middle of its triangle.
            }
            let u = p.z.atan2(p.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU;
            // Either the longitude, or (a seam duplicate) the longitude continued past 1.
            let d = (uv.x * 1.1 - u).min((uv.x * 1.1 - u - 1.0).abs()).abs();
            assert!(
                d < 1e-4,
                "level {level}: {p} has u {} for longitude {u}",
                uv.x
            );
        }
    }
}

#[test]
fn teapot_is_1_5_tall_sitting_on_the_floor() {
    let m = generate(Generator::Teapot, 2).unwrap();
    let (lo, hi) = m.positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    assert!(lo.y.abs() < 1e-6 && (hi.y - 1.5).abs() < 1e-5, "{lo} {hi}");
    // Spout towards +x, handle towards -x, symmetric in z, about 1.9 deep.
    assert!(hi.x > 1.55 && hi.x < 1.7, "spout tip at x = {}", hi.x);
    assert!(lo.x < -1.35 && lo.x > -1.45, "handle at x = {}", lo.x);
    assert!(
        (lo.z + hi.z).abs() < 1e-5 && (hi.z - 0.952).abs() < 0.01,
        "{lo} {hi}"
    );
    // Every part faces outwards (a patch turned inside out would keep its winding and normals
    // consistent, so check directions): the bottom disk faces down, the lid's top faces up,
    // and the body (away from the spout and handle) faces away from the axis.
    for (p, n) in m.positions.iter().zip(&m.normals) {
        let radial = Vec3::new(p.x, 0.0, p.z);
        if p.y < 1e-4 && radial.length() < 0.6 {
            assert!(n.y < -0.99, "bottom at {p} has normal {n}");
        }
        if p.y > 1.499 {
            assert!(n.y > 0.99, "knob top at {p} has normal {n}");
        }
        if radial.length() > 0.85 && (0.2..0.8).contains(&p.y) && p.z.abs() > 0.3 {
            assert!(
                n.dot(radial.normalize()) > 0.5,
                "body at {p} has normal {n}"
            );
        }
    }
    // The knob top and the centre of the bottom have axis-aligned normals (the pole fallback).
    for (p, n) in m.positions.iter().zip(&m.normals) {
        if p.x.abs() < 1e-6 && p.z.abs() < 1e-6 {
            let expected = if p.y > 0.75 { Vec3::Y } else { Vec3::NEG_Y };
            assert!(n.dot(expected) > 0.999, "pole at {p} has normal {n}");
        }
    }
}

#[test]
fn triangle_count_is_exact_beyond_the_tested_levels() {
    for &g in Generator::ALL {
        for level in [4, 7] {
            if triangle_count(g, level) > 200_000 {
                continue;
            }
            let m = generate(g, level).unwrap();
            assert_eq!(
                m.triangle_count() as u64,
                triangle_count(g, level),
                "{g} {level}"
            );
        }
    }
}

#[test]
fn target_triangle_counts_are_reached_within_ten_percent() {
    for target in [2_900u64, 10_000, 100_000] {
        for &g in Generator::ALL {
            let (m, resolution) = generate_with_triangles(g, target).unwrap();
            let got = m.triangle_count() as u64;
            assert_eq!(got, triangle_count_at_resolution(g, u64::from(resolution)));
            let error = (got as f64 - target as f64).abs() / target as f64;
            assert!(
                error < 0.10,
                "{g}: {got} triangles for a target of {target}"
            );
            if target == 10_000 {
                check_invariants(&m, &format!("{g} at {target} triangles"));
            }
        }
    }
}

#[test]
fn a_million_triangle_teapot_for_li_et_al_s_largest_row() {
    let target = 1_084_450;
    let (m, resolution) = generate_with_triangles(Generator::Teapot, target).unwrap();
    let got = m.triangle_count() as u64;
    let error = (got as f64 - target as f64).abs() / target as f64;
    assert!(error < 0.01, "{got} triangles for {target}");
    assert_eq!(resolution, 260);
    m.validate("teapot 1M").unwrap();
    assert!(signed_volume(&m) > 0.0);
    assert!(normal_agreement(&m) > 0.99);
    assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
}

/// The accuracy table in the module docs, checked over the whole range from 2,900 to 1.1M.
#[test]
fn documented_worst_case_accuracy_holds_from_2900_to_1_1m() {
    for (g, bound) in [
        (Generator::Plane, 0.026),
        (Generator::UvSphere, 0.038),
        (Generator::Torus, 0.045),
        (Generator::Cube, 0.061),
        (Generator::Teapot, 0.068),
        (Generator::Icosphere, 0.080),
    ] {
        let mut worst = 0.0f64;
        // Every target where the steps between resolutions are coarsest, then sparser.
        let mut target = 2_900u64;
        while target <= 1_100_000 {
            let r = resolution_for_triangles(g, target).unwrap();
            let got = triangle_count_at_resolution(g, u64::from(r));
            worst = worst.max((got as f64 - target as f64).abs() / target as f64);
            target += if target < 5_000 { 1 } else { 1 + target / 300 };
        }
        assert!(
            worst <= bound,
            "{g}: worst error {worst} > documented {bound}"
        );
        assert!(
            worst > bound - 0.001,
            "{g}: docs overstate the error ({worst})"
        );
        let r = resolution_for_triangles(g, 1_000_000).unwrap();
        let got = triangle_count_at_resolution(g, u64::from(r)) as f64;
        assert!((got - 1e6).abs() < 4e3, "{g}: {got}");
    }
}

#[test]
fn absurd_sizes_are_refused_without_allocating() {
    for &g in Generator::ALL {
        for target in [0, MAX_TRIANGLES + 1, 1_000_000_000_000, u64::MAX] {
            let e = generate_with_triangles(g, target).unwrap_err().to_string();
            assert!(e.contains("out of range"), "{g} {target}: {e}");
        }
        for level in [10_000, 100_000, u32::MAX] {
            assert!(triangle_count(g, level) > MAX_TRIANGLES, "{g} {level}");
            let e = generate(g, level).unwrap_err().to_string();
            assert!(e.contains("limit"), "{g} {level}: {e}");
        }
        assert!(generate_at_resolution(g, u32::MAX).is_err());
        assert_eq!(triangle_count_at_resolution(g, u64::MAX), u64::MAX);
        // The largest target is still served (by counting only: nothing is generated here).
        let r = resolution_for_triangles(g, MAX_TRIANGLES).unwrap();
        assert!(triangle_count_at_resolution(g, u64::from(r)) <= MAX_TRIANGLES);
    }
    // Icosphere levels are subdivisions: level 9 is the last under the limit.
    assert_eq!(triangle_count(Generator::Icosphere, 9), 5_242_880);
    assert!(generate(Generator::Icosphere, 10).is_err());
}

#[test]
fn names_parse_and_round_trip() {
    for &g in Generator::ALL {
        assert_eq!(Generator::parse(g.name()).unwrap(), g);
        assert_eq!(g.to_string().parse::<Generator>().unwrap(), g);
    }
    assert_eq!(Generator::parse("uv-sphere").unwrap(), Generator::UvSphere);
    assert_eq!(Generator::parse(" Teapot ").unwrap(), Generator::Teapot);
    let e = Generator::parse("dodecahedron").unwrap_err().to_string();
    for name in [
        "dodecahedron",
        "sphere",
        "uv-sphere",
        "icosphere",
        "cube",
        "torus",
        "plane",
        "teapot",
    ] {
        assert!(e.contains(name), "{e}");
    }
    assert_eq!(Generator::ALL.len(), 6);
    assert_eq!(generators::MAX_TRIANGLES, 20_000_000);
}
