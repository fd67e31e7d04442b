//! lucent's SH environment as an effect on a host's G-buffer (`lucent::embed::EnvironmentEffect`)
//! against lucent's own frame of the same scene and against the f64 twin of its irradiance:
//! the host's lighting is lucent's frame without the environment, its G-buffer lucent's own
//! re-encoded in host layouts (standard D32, reversed-Z infinite cleared to 0, D24S8, linear
//! R32F; normals world or view space, xyz or octahedral, float or UNORM; the diffuse light
//! with or without the albedo), and the effect must add what lucent's lighting pass adds.

use crate::common::TestGpu;
use crate::embed::{
    built, changed, compare_host_frame, described, host_error, host_frames, host_layout, options,
    tonemapped, wrap, HostDepth, HostIds,
};
use crate::embed_translucency::{normal_image, rgba8, HostNormals};

use ash::vk;
use glam::{DVec3, Vec3};
use lucent::backend::ImageDesc;
use lucent::embed::{
    capabilities, DiffuseDesc, Effect, Environment, EnvironmentEffect, EnvironmentEffectDesc,
    EnvironmentFrame, EnvironmentImages, GBufferDesc, HostError, HostImage, ImageState, NormalDesc,
};
use lucent::frame::{FrameSettings, Renderer, Technique};

/// How a test host keeps its lit diffuse light.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Lit {
    /// lucent's frame without the environment, the albedo multiplied in: compared after
    /// tonemapping with lucent's frame with it.
    WithAlbedo,
    /// Black, without the albedo: what the effect adds is the irradiance alone, compared with
    /// the f64 twin (`Environment::ambient_radiance`).
    WithoutAlbedo,
}

#[test]
fn the_environment_effect_on_host_layouts_equals_lucents_own_frame_and_the_f64_twin() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (240, 180);
    // The built-in sky: all nine coefficients non-zero (a sun, a sky and a ground).
    let mut scene = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    let environment = Environment::builtin_sky(1.5, 40.0).unwrap();
    assert_eq!(environment.bands(), 3);
    let render = |scene: &lucent::scene::Scene| {
        let settings = FrameSettings {
            technique: Technique::None,
            export_hdr: true,
            export_gbuffer: true,
            ..FrameSettings::new(w, h)
        };
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, scene, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        images
    };
    scene.environment = environment.clone();
    let with = render(&scene);
    let black = Environment::constant(Vec3::ZERO);
    scene.environment = black.clone();
    let without = render(&scene);
    let exposure = f64::from(scene.exposure);
    let want = tonemapped(with.hdr.as_ref().unwrap(), exposure);
    let plain = tonemapped(without.hdr.as_ref().unwrap(), exposure);
    // The environment must be visible, or the comparison below proves nothing.
    let lit = want
        .chunks_exact(4)
        .zip(plain.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(
        lit * 4 > (w * h) as usize,
        "the environment changes only {lit} pixels of cubes"
    );
    let gb = with.gbuffer.unwrap();
    let background: Vec<bool> = gb.depth.iter().map(|&d| d >= 1.0).collect();
    assert!(background.iter().any(|&b| b) && !background.iter().all(|&b| b));
    let ids = vec![0u8; (w * h) as usize];

    let usage = vk::ImageUsageFlags::SAMPLED;
    let albedo = gpu
        .upload_image(
            &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
            &[rgba8(&gb.gb0)],
            "host albedo",
        )
        .unwrap();
    let mut report = Vec::new();
    for (name, depth_kind, ids_kind, normals_kind, lit) in [
        (
            "D32, world RGBA16F normals, albedo in the light",
            HostDepth::Standard,
            HostIds::Unorm,
            HostNormals::WorldHalf,
            Lit::WithAlbedo,
        ),
        (
            "reversed-Z infinite D32 cleared to 0, view-space octahedral RG16 normals, albedo in \
             the light",
            HostDepth::ReversedInfinite,
            HostIds::Uint,
            HostNormals::ViewOctahedralUnorm,
            Lit::WithAlbedo,
        ),
        (
            "D24S8, world RGBA16_UNORM normals, albedo in the light",
            HostDepth::D24Stencil,
            HostIds::Stencil,
            HostNormals::WorldUnorm,
            Lit::WithAlbedo,
        ),
        (
            "linear R32F depth, world octahedral RG32F normals, the light without the albedo",
            HostDepth::Linear,
            HostIds::Unorm,
            HostNormals::WorldOctahedralFloat,
            Lit::WithoutAlbedo,
        ),
    ] {
        let mut layout = host_layout(
            &test, depth_kind, ids_kind, w, h, &scene, &gb.depth, &ids, 1.0,
        );
        if depth_kind == HostDepth::ReversedInfinite {
            // The same pixels as lucent's frame: its clip-space y convention.
            let mut projection = layout.camera.projection;
            projection.y_axis.y = -projection.y_axis.y;
            layout.camera = lucent::embed::HostCamera::new(layout.camera.view, projection);
            // A reversed-Z host clears its depth to 0, the infinitely far background (the
            // layout helper keeps lucent's far plane, n / f, there).
            let (near, far) = (scene.camera.near, scene.camera.far);
            let reversed: Vec<f32> = gb
                .depth
                .iter()
                .map(|&d| {
                    if d >= 1.0 {
                        0.0
                    } else {
                        let z = near * far / (far - d * (far - near));
                        near / z
                    }
                })
                .collect();
            gpu.destroy_image(std::mem::replace(
                &mut layout.depth,
                gpu.upload_image(
                    &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
                    &[bytemuck::cast_slice(&reversed).to_vec()],
                    "host reversed depth cleared to 0",
                )
                .unwrap(),
            ));
        }
        let (normals, normal_desc) =
            normal_image(&test, normals_kind, w, h, &gb.gb1, layout.camera.view);
        let diffuse = match lit {
            Lit::WithAlbedo => DiffuseDesc::with_albedo(vk::Format::R32G32B32A32_SFLOAT),
            Lit::WithoutAlbedo => DiffuseDesc::without_albedo(vk::Format::R32G32B32A32_SFLOAT),
        };
        let mut desc = changed(&layout.desc, |g| g.diffuse = diffuse).with_normals(normal_desc);
        if lit == Lit::WithAlbedo {
            desc = desc.with_albedo(vk::Format::R8G8B8A8_UNORM);
        }
        assert!(capabilities(&desc).unwrap()[4].1.runs());
        let lucent = wrap(&test, options(3));
        let mut effect = built(&test, &lucent, |u| {
            EnvironmentEffect::new(&lucent, u, EnvironmentEffectDesc::new(desc.clone()))
        })
        .unwrap();
        assert_eq!(effect.plan().passes.len(), 1, "one pass");
        // It blends into the host's light: no image of its own.
        assert_eq!(effect.memory().images, 0, "{:?}", effect.memory());
        assert!(effect.memory().parameters > 0);
        let start: Vec<u8> = match lit {
            Lit::WithAlbedo => bytemuck::cast_slice(without.hdr.as_ref().unwrap()).to_vec(),
            Lit::WithoutAlbedo => vec![0; (w * h * 16) as usize],
        };
        // The environment changes per frame: the third frame's is black (adds nothing).
        let environments = [&environment, &environment, &black];
        let frames = host_frames(&test, &layout, &desc, &start, |k, cmd, images| {
            let albedo_image = described(&albedo, "host albedo", usage);
            effect
                .record(
                    &lucent,
                    cmd,
                    &EnvironmentFrame {
                        slot: k,
                        view: 0,
                        camera: layout.camera,
                        environment: environments[k],
                        images: EnvironmentImages {
                            depth: images.depth,
                            normals: &described(&normals, "host normals", usage),
                            albedo: (lit == Lit::WithAlbedo).then_some(&albedo_image),
                        },
                        regions: &[],
                        lighting: images.lighting,
                    },
                )
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        });
        for (k, texels) in frames.iter().enumerate() {
            match lit {
                Lit::WithAlbedo => {
                    let have = tonemapped(texels, exposure);
                    let frame = if k == 2 { &plain } else { &want };
                    report.push(compare_host_frame(
                        frame,
                        &have,
                        (w, h),
                        0,
                        &format!("{name}, frame {k}"),
                        &format!("embed-environment-{k}"),
                    ));
                }
                Lit::WithoutAlbedo => {
                    let env = environments[k];
                    report.push(compare_with_twin(env, texels, &gb.gb1, &background, name));
                }
            }
        }
        effect.destroy(&lucent);
        drop(lucent);
        gpu.destroy_image(normals);
        layout.destroy(&test);
    }
    gpu.destroy_image(albedo);
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

/// The effect's light without the albedo (`texels`, RGBA32F) against the f64 twin of the
/// environment's irradiance at lucent's normals: the background exactly 0, every surface
/// within 1e-3 relative (plus 1e-5 absolute). Returns the report line.
fn compare_with_twin(
    environment: &Environment,
    texels: &[f32],
    normals: &[[f32; 4]],
    background: &[bool],
    name: &str,
) -> String {
    let mut worst = 0.0f64;
    for (i, texel) in texels.chunks_exact(4).enumerate() {
        let have = DVec3::new(texel[0].into(), texel[1].into(), texel[2].into());
        if background[i] {
            assert_eq!(have, DVec3::ZERO, "{name}: background pixel {i} lit");
            continue;
        }
        let n = normals[i];
        let n = DVec3::new(n[0].into(), n[1].into(), n[2].into()).normalize();
        let want = environment.ambient_radiance(n);
        let error = (have - want).abs().max_element() / (want.max_element() + 1e-2);
        assert!(
            (have - want).abs().max_element() <= 1e-3 * want.max_element() + 1e-5,
            "{name}: pixel {i}: {have} against the twin's {want}"
        );
        worst = worst.max(error);
    }
    format!("{name}: against the f64 twin, worst relative error {worst:.2e}")
}

#[test]
fn an_environment_description_missing_an_input_or_a_bad_environment_is_a_typed_error() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(2));
    let gbuffer = GBufferDesc::new(
        64,
        48,
        lucent::embed::DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT))
    .with_albedo(vk::Format::R8G8B8A8_UNORM);
    let build = |gbuffer: GBufferDesc| {
        built(&test, &lucent, |u| {
            EnvironmentEffect::new(&lucent, u, EnvironmentEffectDesc::new(gbuffer))
        })
    };
    for (input, gbuffer) in [
        ("normals", changed(&gbuffer, |g| g.normals = None)),
        ("albedo", changed(&gbuffer, |g| g.albedo = None)),
    ] {
        let e = host_error(build(gbuffer));
        assert!(
            matches!(&e, HostError::Missing { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    // Without the albedo in the diffuse light, none is needed; normals it cannot hold are
    // named.
    let without_albedo = changed(&gbuffer, |g| {
        g.diffuse = DiffuseDesc::without_albedo(vk::Format::R16G16B16A16_SFLOAT);
        g.albedo = None;
    });
    build(without_albedo.clone()).unwrap().destroy(&lucent);
    let e = host_error(build(
        gbuffer
            .clone()
            .with_normals(NormalDesc::world(vk::Format::R16G16_SFLOAT)),
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "normals"),
        "{e}"
    );
    assert!(
        !capabilities(&changed(&gbuffer, |g| g.normals = None)).unwrap()[4]
            .1
            .runs()
    );
    assert_eq!(Effect::ALL[4], Effect::Environment);

    // A frame: a NaN environment, an albedo given to a description without one, none given
    // to one with one; each refused before anything is recorded.
    let (w, h) = (64, 48);
    let usage = vk::ImageUsageFlags::SAMPLED;
    let image = |format, name| {
        test.gpu
            .upload_image(
                &ImageDesc::color(w, h, format, usage | vk::ImageUsageFlags::COLOR_ATTACHMENT),
                &[vec![0u8; (w * h) as usize * 16]],
                name,
            )
            .unwrap()
    };
    let depth = test
        .gpu
        .upload_image(
            &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage),
            &[vec![0u8; (w * h) as usize * 4]],
            "depth",
        )
        .unwrap();
    let normals = image(vk::Format::R16G16B16A16_SFLOAT, "normals");
    let albedo = image(vk::Format::R8G8B8A8_UNORM, "albedo");
    let lighting = image(vk::Format::R16G16B16A16_SFLOAT, "lighting");
    let depth_image = HostImage::new(
        "depth",
        depth.image,
        depth.view,
        vk::Format::D32_SFLOAT,
        vk::Extent2D {
            width: w,
            height: h,
        },
        usage,
    )
    .in_state(ImageState::fragment_sampled());
    let normal_image = described(&normals, "normals", usage);
    let albedo_image = described(&albedo, "albedo", usage);
    let lighting_usage = usage | vk::ImageUsageFlags::COLOR_ATTACHMENT;
    let lighting_image = described(&lighting, "lighting", lighting_usage);
    let camera = lucent::embed::HostCamera::new(
        glam::Mat4::look_at_rh(Vec3::new(0.0, 1.0, 3.0), Vec3::ZERO, Vec3::Y),
        glam::Mat4::perspective_rh(1.0, w as f32 / h as f32, 0.1, 50.0),
    );
    let mut with_albedo = build(gbuffer).unwrap();
    let mut without = build(without_albedo).unwrap();
    let nan = Environment::constant(Vec3::new(f32::NAN, 0.0, 0.0));
    let sky = Environment::hemisphere(Vec3::ONE, Vec3::splat(0.2));
    let frame = |environment, albedo| EnvironmentFrame {
        slot: 0,
        view: 0,
        camera,
        environment,
        images: EnvironmentImages {
            depth: &depth_image,
            normals: &normal_image,
            albedo,
        },
        regions: &[],
        lighting: &lighting_image,
    };
    // Nothing is recorded: a null command buffer would be a validation error if anything was.
    let cmd = vk::CommandBuffer::null();
    let e = host_error(with_albedo.record(&lucent, cmd, &frame(&nan, Some(&albedo_image))));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field == "environment"),
        "{e}"
    );
    let e = host_error(with_albedo.record(&lucent, cmd, &frame(&sky, None)));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "albedo"),
        "{e}"
    );
    let e = host_error(without.record(&lucent, cmd, &frame(&sky, Some(&albedo_image))));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field == "albedo"),
        "{e}"
    );
    with_albedo.destroy(&lucent);
    without.destroy(&lucent);
    drop(lucent);
    for image in [depth, normals, albedo, lighting] {
        test.gpu.destroy_image(image);
    }
    test.finish();
}
