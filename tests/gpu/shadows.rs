//! Light-space maps and shadows (lavapipe, validation on): the floor under an occluder is
//! darker than open floor for every light type, the maps follow the lights that cast (no pass,
//! no image, no ID target where nothing needs them), and the GPU's visibility agrees with a ray
//! traced against the exact meshes.

use glam::{Mat4, Vec3};
use lucent::bake::bvh::Bvh;
use lucent::frame::{FrameDesc, FrameImages, FrameSettings};
use lucent::graph::Plan;
use lucent::scene::generators::{generate, Generator};
use lucent::scene::material::{ThicknessSource, Translucency};
use lucent::scene::{builtin, Light, LightKind, Material, Scene};

use crate::common;

use crate::common::TestGpu;

const W: u32 = 160;
const H: u32 = 120;

/// A floor (y = 0, 8 x 8) and a cube of half-size 0.5 floating at height 1.5 over the origin,
/// seen from the side so the floor under the cube is visible; no ambient light.
fn occluder_scene(light: Light) -> Scene {
    let floor = Material::opaque("floor", Vec3::splat(0.8), 0.0, 1.0);
    let cube = Material::opaque("cube", Vec3::new(0.7, 0.3, 0.2), 0.0, 1.0);
    Scene {
        name: "occluder".into(),
        meshes: vec![
            generate(Generator::Plane, 1).unwrap(),
            generate(Generator::Cube, 1).unwrap(),
        ],
        objects: vec![
            lucent::scene::Object {
                mesh: 0,
                transform: Mat4::from_scale(Vec3::new(4.0, 1.0, 4.0)),
                material: floor,
            },
            lucent::scene::Object {
                mesh: 1,
                transform: Mat4::from_scale_rotation_translation(
                    Vec3::splat(0.5),
                    glam::Quat::IDENTITY,
                    Vec3::new(0.0, 1.5, 0.0),
                ),
                material: cube,
            },
        ],
        lights: vec![light],
        camera: lucent::scene::Camera {
            eye: Vec3::new(4.0, 2.5, 0.0),
            target: Vec3::new(0.0, 0.3, 0.0),
            fov_y_degrees: 50.0,
            near: 0.1,
            far: 50.0,
        },
        environment: lucent::scene::Environment::constant(Vec3::ZERO),
        sky: Vec3::splat(0.1),
        exposure: 1.0,
        deformation: None,
        time: 0.0,
        credits: Vec::new(),
    }
}

fn settings(shadows: bool) -> FrameSettings {
    let mut s = FrameSettings::new(W, H);
    s.export_hdr = true;
    s.export_gbuffer = true;
    s.shadows.enabled = shadows;
    s.shadows.size = 512;
    s
}

/// The pixel a world point lands on.
fn pixel_of(scene: &Scene, p: Vec3) -> (u32, u32) {
    let clip = scene.camera.projection(W as f32 / H as f32) * scene.camera.view() * p.extend(1.0);
    let ndc = clip.truncate() / clip.w;
    (
        ((ndc.x * 0.5 + 0.5) * W as f32) as u32,
        ((ndc.y * 0.5 + 0.5) * H as f32) as u32,
    )
}

fn luminance(images: &FrameImages, (x, y): (u32, u32)) -> f32 {
    let hdr = images.hdr.as_ref().unwrap();
    let i = ((y * W + x) * 4) as usize;
    0.2126 * hdr[i] + 0.7152 * hdr[i + 1] + 0.0722 * hdr[i + 2]
}

fn lights() -> Vec<(&'static str, Light)> {
    vec![
        (
            "directional",
            Light::directional(Vec3::new(0.0, -1.0, 0.0), Vec3::ONE, 3.0),
        ),
        (
            "point",
            Light::point(Vec3::new(0.0, 4.0, 0.0), Vec3::ONE, 40.0, 20.0),
        ),
        (
            "spot",
            Light {
                kind: LightKind::Spot {
                    position: Vec3::new(0.0, 4.0, 0.0),
                    direction: Vec3::NEG_Y,
                    range: 20.0,
                    inner_degrees: 40.0,
                    outer_degrees: 60.0,
                },
                ..Light::point(Vec3::ZERO, Vec3::ONE, 40.0, 20.0)
            },
        ),
    ]
}

/// `occluder_scene` moved by `offset` (objects, lights and camera).
fn moved(mut scene: Scene, offset: Vec3) -> Scene {
    for o in &mut scene.objects {
        o.transform = Mat4::from_translation(offset) * o.transform;
    }
    for l in &mut scene.lights {
        match &mut l.kind {
            LightKind::Directional { .. } => {}
            LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
                *position += offset
            }
        }
    }
    scene.camera.eye += offset;
    scene.camera.target += offset;
    scene
}

#[test]
fn the_floor_under_an_occluder_is_darker_than_open_floor_for_every_light_type() {
    let test = TestGpu::new();
    // Far from the origin too: a directional light's map must cover the objects wherever
    // they are (and plain materials, without translucency or SSS).
    let cases = lights().into_iter().flat_map(|(name, light)| {
        [Vec3::ZERO, Vec3::new(7.0, 0.0, -5.0)].map(|offset| (name, light, offset))
    });
    for (name, light, offset) in cases {
        let scene = moved(occluder_scene(light), offset);
        let under = pixel_of(&scene, offset);
        let open = pixel_of(&scene, offset + Vec3::new(0.0, 0.0, 1.6));
        let lit = test.render(&scene, settings(false));
        let shadowed = test.render(&scene, settings(true));
        let (lit_under, lit_open) = (luminance(&lit, under), luminance(&lit, open));
        let (shadow_under, shadow_open) = (luminance(&shadowed, under), luminance(&shadowed, open));
        println!(
            "{name}: without shadows under {lit_under:.4} open {lit_open:.4}; \
             with shadows under {shadow_under:.4} open {shadow_open:.4}"
        );
        // Both points are lit floor without shadows (the light is above the origin: the point
        // under the cube gets at least as much).
        assert!(lit_under > 0.05 && lit_open > 0.05, "{name}");
        assert!(lit_under >= 0.8 * lit_open, "{name}");
        // With shadows the open floor keeps its light and the floor under the cube loses it.
        assert!(
            (shadow_open - lit_open).abs() <= 0.02 * lit_open,
            "{name}: open floor changed"
        );
        assert!(
            shadow_under < 0.02 * shadow_open,
            "{name}: no shadow under the cube"
        );
    }
    test.finish();
}

/// Whether `light` reaches `p` by a ray against the scene's exact meshes (the f64 reference's
/// visibility).
fn ray_visible(scene: &Scene, bvhs: &[(Bvh, Mat4)], light: &Light, p: Vec3) -> bool {
    let (dir, dist) = match light.kind {
        LightKind::Directional { direction } => (-direction.normalize(), 1e9),
        LightKind::Point { position, .. } | LightKind::Spot { position, .. } => {
            let d = position - p;
            (d.normalize(), d.length())
        }
    };
    let _ = scene;
    bvhs.iter().all(|(bvh, transform)| {
        // The ray in object space (the transforms are scale + translation here).
        let inverse = transform.inverse();
        let origin = inverse.transform_point3(p + dir * 1e-3);
        let far = inverse.transform_point3(p + dir * dist.min(1e4));
        let local = far - origin;
        let length = local.length();
        !bvh.any_hit(origin, local / length, length, None)
    })
}

#[test]
fn gpu_visibility_matches_rays_against_the_exact_meshes() {
    let test = TestGpu::new();
    for (name, light) in lights() {
        let scene = occluder_scene(light);
        let bvhs: Vec<(Bvh, Mat4)> = scene
            .objects
            .iter()
            .map(|o| {
                let m = &scene.meshes[o.mesh];
                (Bvh::new(&m.positions, &m.indices).unwrap(), o.transform)
            })
            .collect();
        let lit = test.render(&scene, settings(false));
        let shadowed = test.render(&scene, settings(true));
        let gb = lit.gbuffer.as_ref().unwrap();
        let inv = (scene.camera.projection(W as f32 / H as f32) * scene.camera.view()).inverse();
        let (mut compared, mut disagree, mut occluded) = (0usize, 0usize, 0usize);
        for y in 0..H {
            for x in 0..W {
                let i = (y * W + x) as usize;
                let d = gb.depth[i];
                let unshadowed = luminance(&lit, (x, y));
                if d >= 1.0 || unshadowed < 1e-3 {
                    continue; // sky, or a surface the light does not face
                }
                let ndc = Vec3::new(
                    (x as f32 + 0.5) / W as f32 * 2.0 - 1.0,
                    (y as f32 + 0.5) / H as f32 * 2.0 - 1.0,
                    d,
                );
                let p = inv.project_point3(ndc);
                let normal = Vec3::new(gb.gb1[i][0], gb.gb1[i][1], gb.gb1[i][2]).normalize();
                let visible = ray_visible(&scene, &bvhs, &scene.lights[0], p + normal * 1e-3);
                let ratio = luminance(&shadowed, (x, y)) / unshadowed;
                compared += 1;
                occluded += usize::from(!visible);
                // Penumbra pixels (the filter's 3-texel width) count as either.
                if (visible && ratio < 0.2) || (!visible && ratio > 0.8) {
                    disagree += 1;
                }
            }
        }
        let fraction = disagree as f64 / compared as f64;
        println!(
            "{name}: {disagree} of {compared} lit pixels ({occluded} occluded by the rays) \
             disagree with the rays ({fraction:.4})"
        );
        assert!(compared > (W * H / 4) as usize, "{name}");
        assert!(
            occluded > 200,
            "{name}: the shadow is not in view ({occluded} pixels)"
        );
        assert!(fraction < 0.01, "{name}: {fraction}");
    }
    test.finish();
}

fn has(plan: &Plan, image: &str) -> bool {
    plan.resources
        .iter()
        .any(|r| r.name == image && r.lifetime.is_some())
}

fn has_pass(plan: &Plan) -> bool {
    plan.physical.iter().any(|p| p.name == "light-space maps")
}

#[test]
fn maps_exist_exactly_for_the_lights_that_cast() {
    let s = FrameSettings::new(320, 240);
    // Built-in scenes: every light casts by default. The translucent cubes have the talk's
    // term, which no shadow falls on: no ID target; `mixed`'s cube and disc ask for shadows on
    // their transmitted light (`shadowed`): the atlas carries the IDs.
    let cubes = builtin("cubes").unwrap();
    let p = common::plan(&cubes, &s);
    assert!(has_pass(&p) && has(&p, "light-space.depth"));
    assert!(!has(&p, "light-space.ids"), "the talk's term: no ID target");
    let mixed = builtin("mixed").unwrap();
    let p = common::plan(&mixed, &s);
    assert!(
        has(&p, "light-space.ids"),
        "shadowed transmission: the ID target"
    );
    let layered = builtin("layered").unwrap();
    let p = common::plan(&layered, &s);
    assert!(has_pass(&p) && has(&p, "light-space.depth"));
    assert!(!has(&p, "light-space.ids"), "no translucency: no ID target");
    let desc = FrameDesc::new(&layered, &s).unwrap();
    assert_eq!(desc.shadows.as_ref().unwrap().faces(), 7);

    // One light off: its faces go; all off, or --no-shadows: no pass, no image.
    let mut one_off = layered.clone();
    one_off.lights[0].shadows = false;
    let desc = FrameDesc::new(&one_off, &s).unwrap();
    assert_eq!(desc.shadows.as_ref().unwrap().faces(), 1);
    let mut all_off = layered.clone();
    for l in &mut all_off.lights {
        l.shadows = false;
    }
    for (scene, settings) in [
        (&all_off, s),
        (
            &layered,
            FrameSettings {
                shadows: lucent::features::shadows::ShadowSettings {
                    enabled: false,
                    ..s.shadows
                },
                ..s
            },
        ),
    ] {
        let p = common::plan(scene, &settings);
        assert!(!has_pass(&p));
        assert!(!p
            .resources
            .iter()
            .any(|r| r.name.starts_with("light-space")));
        assert!(FrameDesc::new(scene, &settings).unwrap().shadows.is_none());
    }
    // The map size knob sizes the atlas: 7 faces in a 3 x 3 grid.
    let small = FrameSettings {
        shadows: lucent::features::shadows::ShadowSettings {
            size: 512,
            ..s.shadows
        },
        ..s
    };
    let p = common::plan(&layered, &small);
    assert_eq!(common::image_size(&p, "light-space.depth"), (1536, 1536));
}

#[test]
fn translucent_objects_are_not_shadowed_by_their_own_faces() {
    // A translucent cube lit from behind, its transmitted light shadowed by other objects
    // (`shadowed`): it survives shadows (its own faces do not shadow it) while an opaque wall
    // between light and cube removes it. With the talk's term (not `shadowed`) the wall
    // leaves it as it is.
    let test = TestGpu::new();
    let light = Light::point(Vec3::new(-3.0, 1.5, 0.0), Vec3::ONE, 40.0, 20.0);
    let mut scene = occluder_scene(light);
    let mut glass = Material::opaque("glass", Vec3::splat(0.9), 0.0, 1.0);
    let mut term = Translucency::new(ThicknessSource::Constant(1.0));
    term.shadowed = true;
    glass.translucency = Some(term);
    scene.objects[1].material = glass;
    let cube_pixel = pixel_of(&scene, Vec3::new(0.5, 1.5, 0.0));
    let lit = test.render(&scene, settings(false));
    let shadowed = test.render(&scene, settings(true));
    let (a, b) = (
        luminance(&lit, cube_pixel),
        luminance(&shadowed, cube_pixel),
    );
    println!("back-lit translucent face: without shadows {a:.4}, with {b:.4}");
    assert!(a > 0.01, "the face transmits light");
    assert!(
        (a - b).abs() <= 0.05 * a,
        "own faces shadowed the transmission: {a} -> {b}"
    );
    // A wall between the light and the cube: the transmitted light is gone.
    scene.meshes.push(generate(Generator::Cube, 1).unwrap());
    scene.objects.push(lucent::scene::Object {
        mesh: 2,
        transform: Mat4::from_scale_rotation_translation(
            Vec3::new(0.05, 2.0, 2.0),
            glam::Quat::IDENTITY,
            Vec3::new(-1.5, 1.5, 0.0),
        ),
        material: Material::opaque("wall", Vec3::splat(0.5), 0.0, 1.0),
    });
    let walled = test.render(&scene, settings(true));
    let c = luminance(&walled, cube_pixel);
    println!("with a wall between: {c:.4}");
    assert!(
        c < 0.1 * a,
        "the wall does not shadow the transmission: {c}"
    );
    // The talk's term: the wall shadows no transmitted light, and the atlas has no IDs.
    if let Some(t) = &mut scene.objects[1].material.translucency {
        t.shadowed = false;
    }
    assert!(!has(
        &common::plan(&scene, &settings(true)),
        "light-space.ids"
    ));
    let unshadowed = test.render(&scene, settings(true));
    let d = luminance(&unshadowed, cube_pixel);
    println!("the talk's term with the wall between: {d:.4}");
    assert!(
        (d - a).abs() <= 0.05 * a,
        "the wall shadowed the talk's term: {a} -> {d}"
    );
    test.finish();
}
