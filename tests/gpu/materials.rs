//! The frame follows its materials (lavapipe, validation and synchronization validation on):
//! features from materials under `auto` and restricted by the named techniques, techniques
//! composed in one frame, each SSS material diffused with its own profile, albedo textures
//! and MTL `map_Kd`, knobs that change only values, rendering into a caller's image, and
//! frames in flight.

use std::path::Path;

use crate::common::blur;
use ash::vk;
use glam::Vec3;
use lucent::backend::access::Access;
use lucent::backend::{GpuImage, ImageDesc};
use lucent::bake::scene::load_scene_baked;
use lucent::features::sss::SssBlur;
use lucent::frame::{
    FrameDesc, FrameImages, FrameRunner, FrameSettings, Renderer, TargetDesc, Technique,
};
use lucent::graph::Plan;
use lucent::reference::translucency::{shade_gbuffer, LightingInputs};
use lucent::scene::material::TechniqueName;
use lucent::scene::texture::TextureSource;
use lucent::scene::Scene;

use crate::common;

use crate::common::{submit_back_to_back, TestGpu};

fn settings(technique: Technique, w: u32, h: u32) -> FrameSettings {
    FrameSettings {
        technique,
        // The f64 references shade without shadows (tests/gpu/shadows.rs checks those).
        shadows: lucent::features::shadows::ShadowSettings {
            enabled: false,
            ..Default::default()
        },
        ..FrameSettings::new(w, h)
    }
}

fn plan(scene: &Scene, technique: Technique) -> Plan {
    common::plan(scene, &settings(technique, 320, 240))
}

fn pass_names(plan: &Plan) -> Vec<String> {
    plan.physical.iter().map(|p| p.name.clone()).collect()
}

fn has_image(plan: &Plan, name: &str) -> bool {
    plan.resources
        .iter()
        .any(|r| r.name == name && r.lifetime.is_some())
}

fn has_sss_image(plan: &Plan) -> bool {
    plan.resources
        .iter()
        .any(|r| (r.name.starts_with("sss.") || r.name == "gbuffer.sss") && r.lifetime.is_some())
}

/// `mixed` with the marble sphere blurred by LBB: two chains in one frame.
/// `mixed` with its marble blurred by LBB and its other SSS materials by `other`.
fn mixed_two_chains(other: SssBlur) -> Scene {
    let mut scene = load_scene_baked("mixed").unwrap();
    for o in &mut scene.objects {
        if let Some(sss) = o.material.sss.as_mut() {
            sss.blur = Some(TechniqueName::new(if o.material.name == "marble" {
                blur(&lucent::features::sss::lbb::LBB).name()
            } else {
                other.name()
            }));
        }
    }
    scene
}

#[test]
fn auto_puts_in_the_frame_exactly_what_the_materials_ask_for() {
    // Nothing translucent, nothing scattering: the plain deferred frame.
    let smoke = load_scene_baked("smoke").unwrap();
    let p = plan(&smoke, Technique::Auto);
    assert_eq!(pass_names(&p), ["gbuffer + lighting", "tonemap"]);
    assert!(!has_image(&p, "gbuffer.translucency") && !has_sss_image(&p));
    assert_eq!(p.dump(), plan(&smoke, Technique::None).dump());

    // The GDC 2011 demo shows translucency without a flag, and nothing of SSS.
    let cubes = load_scene_baked("cubes").unwrap();
    let p = plan(&cubes, Technique::Auto);
    assert!(has_image(&p, "gbuffer.translucency") && !has_sss_image(&p));
    assert_eq!(
        p.dump(),
        plan(
            &cubes,
            Technique::Only(&lucent::features::translucency::TRANSLUCENCY)
        )
        .dump()
    );

    // Skin: its blur (the default, the separable blur), no GB2.
    let skin = load_scene_baked("skin").unwrap();
    let p = plan(&skin, Technique::Auto);
    assert!(!has_image(&p, "gbuffer.translucency") && has_sss_image(&p));
    assert_eq!(
        lucent::features::registry::default_sss_blur(),
        blur(&lucent::features::sss::separable::SEPARABLE)
    );
    assert_eq!(
        p.dump(),
        plan(
            &skin,
            Technique::Only(&lucent::features::sss::separable::SEPARABLE)
        )
        .dump()
    );

    // Mixed: translucency and SSS in one frame, both G-buffer targets, one blur pair for both
    // profiles, the vertical pass composing the frame.
    let mixed = load_scene_baked("mixed").unwrap();
    let p = plan(&mixed, Technique::Auto);
    assert!(has_image(&p, "gbuffer.translucency") && has_image(&p, "gbuffer.sss"));
    assert!(
        !has_image(&p, "gbuffer.lean"),
        "no LEAN chain: no LEAN target"
    );
    assert_eq!(
        pass_names(&p),
        [
            "gbuffer + lighting",
            "horizontal blur",
            "vertical blur",
            "tonemap"
        ]
    );
    // Named techniques restrict the frame to theirs.
    let p = plan(
        &mixed,
        Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
    );
    assert!(has_image(&p, "gbuffer.translucency") && !has_sss_image(&p));
    let p = plan(
        &mixed,
        Technique::Only(&lucent::features::sss::control::CONTROL),
    );
    assert!(!has_image(&p, "gbuffer.translucency") && has_sss_image(&p));
    let p = plan(&mixed, Technique::None);
    assert_eq!(pass_names(&p), ["gbuffer + lighting", "tonemap"]);

    // Two blurs: one chain each, told apart by name, the LEAN target for the LBB chain only
    // once; the LBB chain's final pass keeps the control chain's result elsewhere.
    let two = mixed_two_chains(blur(&lucent::features::sss::control::CONTROL));
    let p = plan(&two, Technique::Auto);
    let names = pass_names(&p);
    assert_eq!(names[0], "projection + lighting");
    for chain in ["control", "lbb"] {
        assert!(
            names.contains(&format!("{chain} horizontal blur #1")),
            "{names:?}"
        );
        assert!(
            names.contains(&format!("{chain} vertical blur #6")),
            "{names:?}"
        );
    }
    assert!(names.contains(&"control combine".to_string()));
    assert_eq!(names[names.len() - 2], "lbb final lighting");
    assert!(has_image(&p, "gbuffer.lean") && has_image(&p, "sss.control.result"));
    let final_pass = p
        .passes
        .iter()
        .find(|q| q.name == "lbb final lighting")
        .unwrap();
    let control_result = p.resource_by_name("sss.control.result").unwrap();
    assert!(final_pass
        .reads
        .iter()
        .any(|u| u.resource == control_result));

    // Maps only where a material has one.
    let s = settings(Technique::Auto, 64, 48);
    let teapot = load_scene_baked("teapot").unwrap();
    let layout = FrameDesc::new(&teapot, &s).unwrap().gbuffer_layout(&s);
    assert!(layout.normal_maps && !layout.albedo_maps);
    let layout = FrameDesc::new(&mixed, &s).unwrap().gbuffer_layout(&s);
    assert!(!layout.normal_maps && !layout.albedo_maps);
}

#[test]
fn frames_in_flight_wait_for_the_previous_frames_last_use_of_each_transient() {
    let mixed = load_scene_baked("mixed").unwrap();
    let one = settings(Technique::Auto, 320, 240);
    let three = FrameSettings {
        frames_in_flight: 3,
        ..one
    };
    let first_barrier = |s: &FrameSettings| {
        let plan = common::plan(&mixed, s);
        let gb0 = plan.resource_by_name("gbuffer.albedo").unwrap();
        plan.physical[0]
            .barriers
            .iter()
            .find(|b| b.resource == gb0)
            .cloned()
            .unwrap()
    };
    // One frame at a time (the caller waits): the G-buffer starts from nothing.
    assert_eq!(first_barrier(&one).src_stage, vk::PipelineStageFlags2::NONE);
    // Frames in flight: its first write waits for the previous frame's last use of its memory
    // (the lighting pass's read, or a later image sharing the memory slot).
    let chained = first_barrier(&three);
    assert_ne!(
        chained.src_stage,
        vk::PipelineStageFlags2::NONE,
        "{chained:?}"
    );

    assert_eq!(chained.old_layout, vk::ImageLayout::UNDEFINED);
}

#[test]
fn cubes_render_translucent_without_a_flag() {
    let dir = common::temp_dir("materials-cubes-cli");
    let run = |extra: &[&str], out: &Path| {
        let status = common::lucent_command()
            .args(["render", "--scene", "cubes", "--size", "96x72", "--out"])
            .arg(out)
            .args(extra)
            .output()
            .unwrap();
        assert!(status.status.success(), "{status:?}");
        std::fs::read(out).unwrap()
    };
    let default = run(&[], &dir.join("default.png"));
    let named = run(&["--technique", "translucency"], &dir.join("named.png"));
    let plain = run(&["--technique", "none"], &dir.join("plain.png"));
    assert_eq!(
        default, named,
        "auto renders cubes as --technique translucency"
    );
    assert_ne!(default, plain, "and that is not plain lighting");
}

fn exported(technique: Technique, w: u32, h: u32) -> FrameSettings {
    FrameSettings {
        export_hdr: true,
        export_gbuffer: true,
        ..settings(technique, w, h)
    }
}

/// Mean absolute change of each channel (SSS frame against the frame without SSS) over the
/// pixels of profile `id`: how much light the blur moves, per channel (it moves light around
/// the object, so the signed mean is about zero).
fn mean_change(sss: &FrameImages, plain: &FrameImages, id: f32) -> (Vec3, usize) {
    let ids = sss.gbuffer.as_ref().unwrap().sss.as_ref().unwrap();
    let (a, b) = (sss.hdr.as_ref().unwrap(), plain.hdr.as_ref().unwrap());
    let mut sum = Vec3::ZERO;
    let mut n = 0;
    for (i, &p) in ids.iter().enumerate() {
        if p == id {
            sum += Vec3::new(
                a[i * 4] - b[i * 4],
                a[i * 4 + 1] - b[i * 4 + 1],
                a[i * 4 + 2] - b[i * 4 + 2],
            )
            .abs();
            n += 1;
        }
    }
    (sum / n.max(1) as f32, n)
}

/// `scene` with only the SSS materials named in `keep` still scattering (the geometry stays,
/// so every object covers the same pixels).
fn only_scattering(scene: &Scene, keep: &[&str]) -> Scene {
    let mut s = scene.clone();
    for o in &mut s.objects {
        if !keep.contains(&o.material.name.as_str()) {
            o.material.sss = None;
        }
    }
    s
}

#[test]
fn each_sss_material_is_diffused_with_its_own_profile_without_bleeding() {
    let test = TestGpu::new();
    let (w, h) = (320, 200);
    let mixed = load_scene_baked("mixed").unwrap();
    let s = exported(Technique::Auto, w, h);
    let desc = FrameDesc::new(&mixed, &s).unwrap();
    let profiles = desc.sss().unwrap();
    let id_of = |name: &str| {
        let i = mixed
            .objects
            .iter()
            .position(|o| o.material.name == name)
            .unwrap();
        f32::from(profiles.object_ids[i])
    };
    let (skin, marble) = (id_of("skin"), id_of("marble"));
    assert!(skin > 0.0 && marble > 0.0 && skin != marble);

    // Against the same frame without SSS (translucency kept: the disc is both).
    let plain = test.render(
        &mixed,
        exported(
            Technique::Only(&lucent::features::translucency::TRANSLUCENCY),
            w,
            h,
        ),
    );
    let together = test.render(&mixed, s);
    // The skin sphere and the disc share the skin profile (one ID); the marble has its own.
    for (names, id) in [(&["skin", "ear"][..], skin), (&["marble"][..], marble)] {
        let alone_scene = only_scattering(&mixed, names);
        let alone = test.render(&alone_scene, s);
        let alone_id = {
            let d = FrameDesc::new(&alone_scene, &s).unwrap();
            let i = alone_scene
                .objects
                .iter()
                .position(|o| o.material.name == names[0])
                .unwrap();
            f32::from(d.sss().unwrap().object_ids[i])
        };
        let (in_mixed, n) = mean_change(&together, &plain, id);
        let (by_itself, m) = mean_change(&alone, &plain, alone_id);
        let name = names[0];
        eprintln!(
            "{name}: {n} pixels; light moved per pixel in mixed {in_mixed:.4}, alone {by_itself:.4}"
        );
        assert!(n > 500 && n == m, "{name}: {n} / {m} pixels");
        assert!(
            by_itself.max_element() > 1e-3,
            "{name}: the blur changes the object"
        );
        let off = (in_mixed - by_itself).abs().max_element();
        assert!(
            off <= 0.05 * by_itself.max_element() + 1e-5,
            "{name}: its light in the mixed frame differs from alone by {off:.2e}"
        );
    }
    // The two profiles read differently: skin moves red far more than blue (its wide
    // Gaussians are red), marble moves its channels alike.
    let (skin_change, _) = mean_change(&together, &plain, skin);
    let (marble_change, _) = mean_change(&together, &plain, marble);
    let spread = |c: Vec3| c.min_element() / c.max_element().max(1e-9);
    eprintln!(
        "blue / red balance: skin {:.3}, marble {:.3}",
        spread(skin_change),
        spread(marble_change)
    );
    assert!(spread(marble_change) > spread(skin_change) + 0.2);

    // No halo: pixels that do not scatter come out as in the plain frame (up to fp16 rounding
    // of diffuse and specular stored apart).
    let ids = together.gbuffer.as_ref().unwrap().sss.as_ref().unwrap();
    let (a, b) = (together.hdr.as_ref().unwrap(), plain.hdr.as_ref().unwrap());
    let changed = ids
        .iter()
        .enumerate()
        .filter(|&(i, &id)| {
            id == 0.0
                && (0..3).any(|c| {
                    (a[i * 4 + c] - b[i * 4 + c]).abs()
                        > 2e-3 * b[i * 4 + c].abs().max(a[i * 4 + c].abs()) + 1e-5
                })
        })
        .count();
    // Non-scattering translucent pixels (the cube) differ: the plain frame has no translucency.
    let gb2 = together.gbuffer.as_ref().unwrap().gb2.as_ref().unwrap();
    let translucent_only = ids
        .iter()
        .zip(gb2)
        .filter(|(&id, t)| id == 0.0 && t[3] > 0.0)
        .count();
    assert!(
        changed <= translucent_only,
        "{changed} non-scattering pixels changed, {translucent_only} of them translucent"
    );
    test.finish();
}

#[test]
fn two_blur_chains_compose_in_one_frame() {
    let test = TestGpu::new();
    let (w, h) = (256, 160);
    // The marble's LBB chain beside the thesis's control chain (LBB last), and beside the
    // default separable chain (LBB first, the separable chain's vertical pass composing).
    for (other, chains) in [
        (
            blur(&lucent::features::sss::control::CONTROL),
            [
                blur(&lucent::features::sss::control::CONTROL),
                blur(&lucent::features::sss::lbb::LBB),
            ],
        ),
        (
            blur(&lucent::features::sss::separable::SEPARABLE),
            [
                blur(&lucent::features::sss::lbb::LBB),
                blur(&lucent::features::sss::separable::SEPARABLE),
            ],
        ),
    ] {
        let two = mixed_two_chains(other);
        let s = exported(Technique::Auto, w, h);
        let both = test.render(&two, s);
        // The same frame without the LBB chain: the other chain alone.
        let other_only = test.render(&only_scattering(&two, &["skin", "ear"]), s);
        let hdr = both.hdr.as_ref().unwrap();
        assert!(hdr.iter().all(|v| v.is_finite()), "non-finite output");
        let ids = both.gbuffer.as_ref().unwrap().sss.as_ref().unwrap();
        let desc = FrameDesc::new(&two, &s).unwrap();
        let profiles = desc.sss().unwrap();
        assert_eq!(profiles.chains(), chains);
        let skin = {
            let i = two
                .objects
                .iter()
                .position(|o| o.material.name == "skin")
                .unwrap();
            f32::from(profiles.object_ids[i])
        };
        // The later chain keeps the earlier chain's result on the earlier chain's pixels (the
        // LEAN G-buffer pass shades their normals alike, up to rounding).
        let other_hdr = other_only.hdr.as_ref().unwrap();
        let (mut diff, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
        for (i, &id) in ids.iter().enumerate() {
            if id == skin {
                for c in 0..3 {
                    diff += f64::from((hdr[i * 4 + c] - other_hdr[i * 4 + c]).abs());
                    sum += f64::from(other_hdr[i * 4 + c].abs());
                }
                n += 1;
            }
        }
        eprintln!(
            "{} chain's pixels in a two-chain frame: {n}, mean relative change {:.2e}",
            other.name(),
            diff / sum
        );
        assert!(
            n > 500 && diff <= 1e-2 * sum,
            "{}: {diff} of {sum}",
            other.name()
        );
    }
    test.finish();
}

#[test]
fn mixed_translucent_pixels_match_the_f64_reference() {
    let test = TestGpu::new();
    let mixed = load_scene_baked("mixed").unwrap();
    let s = exported(Technique::Auto, 320, 200);
    let images = test.render(&mixed, s);
    let desc = FrameDesc::new(&mixed, &s).unwrap();
    let t = desc.translucency().unwrap();
    let gbuffer = images.gbuffer.as_ref().unwrap();
    let reference = shade_gbuffer(
        gbuffer,
        &LightingInputs {
            scene: &mixed,
            translucency: Some((&t.table.rows, t.packing)),
        },
    );
    let hdr = images.hdr.as_ref().unwrap();
    let ids = gbuffer.sss.as_ref().unwrap();
    let gb2 = gbuffer.gb2.as_ref().unwrap();
    let peak = reference
        .iter()
        .map(|c| c.max_element())
        .fold(0.0, f64::max);
    let (mut max, mut compared) = (0.0f64, 0usize);
    for (i, r) in reference.iter().enumerate() {
        // Translucent pixels the blur leaves alone (the cube): the lit value itself.
        if ids[i] != 0.0 || gb2[i][3] <= 0.0 {
            continue;
        }
        compared += 1;
        for c in 0..3 {
            let gpu = f64::from(hdr[i * 4 + c]);
            assert!(gpu.is_finite());
            max = max.max((gpu - r[c]).abs());
        }
    }
    eprintln!(
        "mixed: {compared} translucent pixels, max |GPU - f64| = {:.2e} of peak {peak:.3}",
        max / peak
    );
    assert!(compared > 1000, "{compared} translucent pixels");
    assert!(max <= 2e-3 * peak, "max error {max:.3e} of peak {peak:.3}");
    test.finish();
}

/// Writes an 8x8 PNG of one sRGB colour.
fn solid_png(path: &Path, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(8, 8, image::Rgb(rgb))
        .save(path)
        .unwrap();
}

fn srgb_to_linear(v: u8) -> f32 {
    let c = f32::from(v) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// GB0 albedo at the centre of the left and right halves of the image.
fn albedo_left_right(images: &FrameImages, w: u32, h: u32) -> (Vec3, Vec3) {
    let gb0 = &images.gbuffer.as_ref().unwrap().gb0;
    let at = |x: u32| {
        let t = gb0[(h / 2 * w + x) as usize];
        Vec3::new(t[0], t[1], t[2])
    };
    (at(w / 4), at(3 * w / 4))
}

#[test]
fn albedo_textures_and_mtl_map_kd_are_applied() {
    let test = TestGpu::new();
    let dir = common::temp_dir("materials-albedo");
    let (w, h) = (64, 48);
    solid_png(&dir.join("orange.png"), [230, 120, 40]);
    let orange = Vec3::new(srgb_to_linear(230), srgb_to_linear(120), srgb_to_linear(40));
    let write_scene = |name: &str, mesh: &str, material: &str| -> Scene {
        let path = dir.join(name);
        std::fs::write(
            &path,
            std::fs::read_to_string(common::data("quad.toml"))
                .unwrap()
                .replace("MESH", mesh)
                .replace("MATERIAL", material),
        )
        .unwrap();
        lucent::scene::load_scene(path.to_str().unwrap()).unwrap()
    };
    let close = |a: Vec3, b: Vec3| (a - b).abs().max_element() <= 1.5 / 255.0;

    // A scene material's texture, times its albedo.
    let textured = write_scene(
        "textured.toml",
        "generator = \"plane\"",
        "albedo = [1.0, 0.5, 1.0]\nalbedo_texture = \"orange.png\"",
    );
    let s = exported(Technique::Auto, w, h);
    assert!(FrameDesc::new(&textured, &s).unwrap().albedo_maps);
    let images = test.render(&textured, s);
    let (left, right) = albedo_left_right(&images, w, h);
    let expected = orange * Vec3::new(1.0, 0.5, 1.0);
    assert!(
        close(left, expected) && close(right, expected),
        "{left} {right} vs {expected}"
    );
    let untextured = write_scene(
        "plain.toml",
        "generator = \"plane\"",
        "albedo = [1.0, 0.5, 1.0]",
    );
    let (left, _) = albedo_left_right(&test.render(&untextured, s), w, h);
    assert!(close(left, Vec3::new(1.0, 0.5, 1.0)), "{left}");

    // MTL: one face's material has Kd, the other's map_Kd; both are rendered.
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl green\nKd 0.2 0.6 0.3\nnewmtl painted\nKd 1 1 1\nmap_Kd orange.png\nnorm flat.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 0 -1\nv 0 0 -1\nv 0 0 1\nv -1 0 1\nv 1 0 -1\nv 1 0 1\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\n\
         usemtl green\nf 1/1/1 4/4/1 3/3/1 2/2/1\n\
         usemtl painted\nf 2/1/1 3/4/1 6/3/1 5/2/1\n",
    )
    .unwrap();
    // A flat tangent-space normal map: `norm` is the part's normal map, drawn (it leaves
    // the normals as they are).
    solid_png(&dir.join("flat.png"), [128, 128, 255]);
    let obj = write_scene("obj.toml", "obj = \"quad.obj\"", "specular = 0.2");
    assert_eq!(obj.objects.len(), 2, "one object per MTL material");
    let normal_maps: Vec<_> = obj
        .objects
        .iter()
        .map(|o| o.material.normal_texture.clone())
        .collect();
    assert_eq!(
        normal_maps,
        [None, Some(TextureSource::File(dir.join("flat.png")))],
        "the MTL's norm"
    );
    let images = test.render(&obj, s);
    let (left, right) = albedo_left_right(&images, w, h);
    assert!(close(left, Vec3::new(0.2, 0.6, 0.3)), "Kd: {left}");
    assert!(close(right, orange), "map_Kd: {right} vs {orange}");
    // `mtl = false`: one mesh, the object's own material on every face.
    let plain = write_scene(
        "no-mtl.toml",
        "obj = \"quad.obj\"\nmtl = false",
        "albedo = [1.0, 0.5, 1.0]",
    );
    assert_eq!(plain.objects.len(), 1);
    assert_eq!(plain.objects[0].material.albedo_texture, None);
    let (left, right) = albedo_left_right(&test.render(&plain, s), w, h);
    assert!(
        close(left, Vec3::new(1.0, 0.5, 1.0)) && close(right, Vec3::new(1.0, 0.5, 1.0)),
        "{left} {right}"
    );

    // A corrupt texture is an error naming the file.
    std::fs::write(dir.join("orange.png"), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let err = match Renderer::new(&test.gpu, &test.shaders, &test.cache, &textured, s) {
        Ok(_) => panic!("a corrupt texture rendered"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("orange.png"), "{err}");
    test.finish();
}

#[test]
fn knobs_that_change_values_update_the_frame_without_rebuilding_it() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (160, 100);
    let mixed = load_scene_baked("mixed").unwrap();
    let s = settings(Technique::Auto, w, h);
    let mut renderer = Renderer::new(gpu, &test.shaders, &test.cache, &mixed, s).unwrap();
    // Translucency power and distortion, an SSS width, a light: values only.
    let mut tuned = mixed.clone();
    for o in &mut tuned.objects {
        if let Some(t) = o.material.translucency.as_mut() {
            t.power *= 0.5;
            t.distortion = 0.4;
        }
        if let Some(p) = o.material.sss.as_mut() {
            p.units_per_mm *= 2.0;
        }
    }
    tuned.lights[0].intensity *= 1.5;
    assert!(renderer.can_update(&tuned).unwrap());
    renderer.update(&tuned).unwrap();
    let mut runner = FrameRunner::new(gpu, renderer.executable.plan.physical.len()).unwrap();
    runner.run_frame(gpu, &renderer.executable).unwrap();
    let updated = renderer.read_display(gpu).unwrap();
    let fresh = test.render(&tuned, s).display;
    let before = test.render(&mixed, s).display;
    assert_eq!(
        updated, fresh,
        "an updated frame is the frame built for the values"
    );
    assert_ne!(updated, before);
    // A new pow form is a new shader permutation: the frame must be rebuilt.
    let mut other = mixed.clone();
    for o in &mut other.objects {
        if let Some(t) = o.material.translucency.as_mut() {
            t.pow_mode = lucent::scene::material::PowMode::SphericalGaussian;
        }
    }
    assert!(!renderer.can_update(&other).unwrap());
    assert!(renderer.update(&other).is_err());
    gpu.wait_idle().unwrap();
    runner.destroy(gpu);
    renderer.destroy(gpu);
    test.finish();
}

/// A colour image the frame can render into and the test can read back.
fn target_image(test: &TestGpu, w: u32, h: u32, format: vk::Format, name: &str) -> GpuImage {
    test.gpu
        .create_image(
            &ImageDesc::color(
                w,
                h,
                format,
                vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC,
            ),
            name,
        )
        .unwrap()
}

/// Records frame k of `renderer` (slot k, camera k, target k) into its own command buffer
/// and submits them back to back, waiting only once at the end.
fn frames_in_flight(
    test: &TestGpu,
    renderer: &mut Renderer,
    scenes: &[Scene],
    targets: &[GpuImage],
) {
    let gpu = &test.gpu;
    submit_back_to_back(gpu, scenes.len(), |slot, cmd| {
        renderer.update_slot(&scenes[slot], slot).unwrap();
        let target = &targets[slot];
        renderer
            .bind_target(gpu, slot, target.image, target.view)
            .unwrap();
        renderer.record(gpu, cmd, slot, None).unwrap();
    });
}

#[test]
fn frames_in_flight_into_given_images_match_frames_one_at_a_time() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (128, 80);
    let mixed = load_scene_baked("mixed").unwrap();
    // Three cameras, so a frame reading another slot's uniforms would show.
    let scenes: Vec<Scene> = (0..3)
        .map(|k| {
            let mut s = mixed.clone();
            s.camera.eye.x += 0.6 * (k as f32 - 1.0);
            s.camera.eye.y += 0.2 * k as f32;
            s
        })
        .collect();
    // One at a time, lucent's own display image.
    let mut one = Renderer::new(
        gpu,
        &test.shaders,
        &test.cache,
        &mixed,
        settings(Technique::Auto, w, h),
    )
    .unwrap();
    let mut runner = FrameRunner::new(gpu, one.executable.plan.physical.len()).unwrap();
    let mut expected = Vec::new();
    for scene in &scenes {
        one.update(scene).unwrap();
        runner.run_frame(gpu, &one.executable).unwrap();
        expected.push(one.read_display(gpu).unwrap());
    }
    gpu.wait_idle().unwrap();
    runner.destroy(gpu);
    one.destroy(gpu);
    assert_ne!(expected[0], expected[2], "the cameras differ");

    for (format, name) in [
        (vk::Format::R8G8B8A8_UNORM, "UNORM"),
        (vk::Format::R8G8B8A8_SRGB, "SRGB"),
        (vk::Format::R16G16B16A16_SFLOAT, "RGBA16F"),
    ] {
        let target = TargetDesc {
            format,
            initial: Access::Undefined,
            final_access: Access::TransferRead,
        };
        let s = FrameSettings {
            frames_in_flight: 3,
            target: Some(target),
            ..settings(Technique::Auto, w, h)
        };
        let mut renderer = Renderer::new(gpu, &test.shaders, &test.cache, &mixed, s).unwrap();
        assert!(
            renderer.read_display(gpu).is_err(),
            "the frame has no display of its own"
        );
        let targets: Vec<GpuImage> = (0..3)
            .map(|k| target_image(&test, w, h, format, &format!("target {k}")))
            .collect();
        frames_in_flight(&test, &mut renderer, &scenes, &targets);
        for (k, image) in targets.iter().enumerate() {
            let bytes = gpu
                .read_image(image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                .unwrap();
            let got: Vec<u8> = match format {
                // Written sRGB-encoded by the shader (UNORM) or by the hardware (SRGB).
                vk::Format::R16G16B16A16_SFLOAT => lucent::images::output::f16_bytes_to_f32(&bytes)
                    .chunks_exact(4)
                    .flat_map(|t| {
                        let enc = |v: f32| {
                            let v = v.clamp(0.0, 1.0);
                            let s = if v <= 0.0031308 {
                                v * 12.92
                            } else {
                                1.055 * v.powf(1.0 / 2.4) - 0.055
                            };
                            (s * 255.0).round() as u8
                        };
                        [enc(t[0]), enc(t[1]), enc(t[2]), 255]
                    })
                    .collect(),
                _ => bytes,
            };
            let worst = common::max_difference(&got, &expected[k]);
            eprintln!("{name} target, frame {k}: largest difference {worst}/255");
            let allowed = if format == vk::Format::R8G8B8A8_UNORM {
                0
            } else {
                1
            };
            assert!(worst <= allowed, "{name} frame {k}: {worst}/255 off");
        }
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        for t in targets {
            gpu.destroy_image(t);
        }
    }
    test.finish();
}
