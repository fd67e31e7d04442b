//! GDC 2011 translucency as an effect on a host's G-buffer (`lucent::embed::TranslucencyEffect`)
//! against lucent's own frame of the same scene: the host's lighting is lucent's frame without
//! translucency, its G-buffer lucent's own re-encoded in four host layouts (depth standard,
//! reversed-Z infinite, D24S8, linear; normals world or view space, xyz or octahedral, float
//! or UNORM; IDs in a packed target's alpha, R8_UINT, stencil bits, R8_UNORM), and the effect
//! must add what lucent's lighting pass adds.

use crate::common::TestGpu;
use crate::embed::{
    built, changed, compare_host_frame, described, host_error, host_frames, host_id, host_layout,
    options, tonemapped, wrap, HostDepth, HostIds,
};

use ash::vk;
use glam::{Mat3, Vec3};
use lucent::backend::{GpuImage, ImageDesc};
use lucent::embed::{
    HostError, IdDesc, NormalDesc, NormalSpace, ThicknessDesc, TranslucencyEffect,
    TranslucencyEffectDesc, TranslucencyFrame, TranslucencyImages, TranslucentMaterial,
};
use lucent::frame::{FrameSettings, Renderer, Technique};

/// How a test host stores its normals.
#[derive(Clone, Copy, Debug)]
pub(crate) enum HostNormals {
    /// World xyz in RGBA16F (lucent's own GB1).
    WorldHalf,
    /// View-space octahedral in RG16_UNORM.
    ViewOctahedralUnorm,
    /// World xyz in RGBA16_UNORM (`2v - 1`).
    WorldUnorm,
    /// World octahedral in RG32F.
    WorldOctahedralFloat,
}

/// Octahedral encoding (Cigolle et al. 2014), the inverse of the shader's decode.
fn octahedral(n: Vec3) -> [f32; 2] {
    let n = n / (n.x.abs() + n.y.abs() + n.z.abs());
    let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
    if n.z >= 0.0 {
        [n.x, n.y]
    } else {
        [(1.0 - n.y.abs()) * sign(n.x), (1.0 - n.x.abs()) * sign(n.y)]
    }
}

fn unorm16(v: f32) -> [u8; 2] {
    ((v.clamp(0.0, 1.0) * 65535.0).round() as u16).to_le_bytes()
}

/// The normal image of `kind` from lucent's world normals, seen through `view`.
pub(crate) fn normal_image(
    test: &TestGpu,
    kind: HostNormals,
    w: u32,
    h: u32,
    normals: &[[f32; 4]],
    view: glam::Mat4,
) -> (GpuImage, NormalDesc) {
    let world: Vec<Vec3> = normals
        .iter()
        .map(|n| Vec3::new(n[0], n[1], n[2]).normalize_or(Vec3::Y))
        .collect();
    let (format, desc, bytes): (vk::Format, NormalDesc, Vec<u8>) = match kind {
        HostNormals::WorldHalf => (
            vk::Format::R16G16B16A16_SFLOAT,
            NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT),
            normals
                .iter()
                .flat_map(|n| n.map(|v| half::f16::from_f32(v).to_le_bytes()))
                .flatten()
                .collect(),
        ),
        HostNormals::ViewOctahedralUnorm => {
            let to_view = Mat3::from_mat4(view);
            (
                vk::Format::R16G16_UNORM,
                NormalDesc::octahedral(vk::Format::R16G16_UNORM, NormalSpace::View),
                world
                    .iter()
                    .flat_map(|&n| {
                        let e = octahedral((to_view * n).normalize());
                        [unorm16(e[0] * 0.5 + 0.5), unorm16(e[1] * 0.5 + 0.5)]
                    })
                    .flatten()
                    .collect(),
            )
        }
        HostNormals::WorldUnorm => (
            vk::Format::R16G16B16A16_UNORM,
            NormalDesc::world(vk::Format::R16G16B16A16_UNORM),
            world
                .iter()
                .flat_map(|n| {
                    [
                        unorm16(n.x * 0.5 + 0.5),
                        unorm16(n.y * 0.5 + 0.5),
                        unorm16(n.z * 0.5 + 0.5),
                        unorm16(1.0),
                    ]
                })
                .flatten()
                .collect(),
        ),
        HostNormals::WorldOctahedralFloat => (
            vk::Format::R32G32_SFLOAT,
            NormalDesc::octahedral(vk::Format::R32G32_SFLOAT, NormalSpace::World),
            world
                .iter()
                .flat_map(|&n| octahedral(n).map(f32::to_le_bytes))
                .flatten()
                .collect(),
        ),
    };
    let image = test
        .gpu
        .upload_image(
            &ImageDesc::color(w, h, format, vk::ImageUsageFlags::SAMPLED),
            &[bytes],
            "host normals",
        )
        .unwrap();
    (image, desc)
}

/// The smallest rectangle holding every pixel whose ID is not 0, widened by one pixel.
pub(crate) fn bounds(w: u32, h: u32, ids: &[u8]) -> vk::Rect2D {
    let inside: Vec<(u32, u32)> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| ids[(y * w + x) as usize] > 0)
        .collect();
    let x0 = inside.iter().map(|p| p.0).min().unwrap().saturating_sub(1);
    let y0 = inside.iter().map(|p| p.1).min().unwrap().saturating_sub(1);
    let x1 = (inside.iter().map(|p| p.0).max().unwrap() + 2).min(w);
    let y1 = (inside.iter().map(|p| p.1).max().unwrap() + 2).min(h);
    assert!(
        (x1 - x0) * (y1 - y0) < w * h * 9 / 10,
        "the bounds must leave part of the screen out"
    );
    vk::Rect2D {
        offset: vk::Offset2D {
            x: x0 as i32,
            y: y0 as i32,
        },
        extent: vk::Extent2D {
            width: x1 - x0,
            height: y1 - y0,
        },
    }
}

pub(crate) fn rgba8(texels: &[[f32; 4]]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect()
}

#[test]
fn the_translucency_effect_on_host_layouts_equals_lucents_own_frame() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (240, 180);
    // Coloured thickness (a red tint), two materials' worth of lights in front and behind.
    let scene = lucent::bake::scene::load_scene_baked("cubes").unwrap();
    let render = |technique| {
        let settings = FrameSettings {
            technique,
            export_hdr: true,
            export_gbuffer: true,
            ..FrameSettings::new(w, h)
        };
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings).unwrap();
        let images = renderer.render_once(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        images
    };
    let with = render(Technique::Only(
        &lucent::features::translucency::TRANSLUCENCY,
    ));
    let without = render(Technique::None);
    let exposure = f64::from(scene.exposure);
    let want = tonemapped(with.hdr.as_ref().unwrap(), exposure);
    let plain = tonemapped(without.hdr.as_ref().unwrap(), exposure);
    // The term must be visible, or the comparison below proves nothing.
    let lit_through = want
        .chunks_exact(4)
        .zip(plain.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(
        lit_through * 50 > (w * h) as usize,
        "translucency changes only {lit_through} pixels of cubes"
    );
    let gb = with.gbuffer.unwrap();
    let gb2 = gb.gb2.clone().expect("a translucency frame has GB2");
    // lucent's material IDs (coloured layout: the alpha) and the materials in ID order.
    let ids: Vec<u8> = gb2.iter().map(|t| (t[3] * 255.0).round() as u8).collect();
    let table = lucent::features::translucency::MaterialTable::new(&scene, true).unwrap();
    let rows = table.rows.clone();
    let parameters: Vec<lucent::scene::material::Translucency> = scene
        .objects
        .iter()
        .filter_map(|o| o.material.translucency_under(true).cloned())
        .collect();

    let usage = vk::ImageUsageFlags::SAMPLED;
    let albedo = gpu
        .upload_image(
            &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
            &[rgba8(&gb.gb0)],
            "host albedo",
        )
        .unwrap();
    let mut report = Vec::new();
    for (name, depth_kind, ids_kind, normals_kind) in [
        (
            "D32, world RGBA16F normals, thickness rgb + IDs in one RGBA8 (lucent's own)",
            HostDepth::Standard,
            None,
            HostNormals::WorldHalf,
        ),
        (
            "reversed-Z infinite D32, view-space octahedral RG16 normals, R8_UINT IDs",
            HostDepth::ReversedInfinite,
            Some(HostIds::Uint),
            HostNormals::ViewOctahedralUnorm,
        ),
        (
            "D24S8 with IDs in stencil bits 4-7, world RGBA16_UNORM normals",
            HostDepth::D24Stencil,
            Some(HostIds::Stencil),
            HostNormals::WorldUnorm,
        ),
        (
            "linear R32F depth, world octahedral RG32F normals, R8_UNORM IDs",
            HostDepth::Linear,
            Some(HostIds::Unorm),
            HostNormals::WorldOctahedralFloat,
        ),
    ] {
        let id_kind = ids_kind.unwrap_or(HostIds::Unorm);
        let mut layout = host_layout(
            &test, depth_kind, id_kind, w, h, &scene, &gb.depth, &ids, 1.0,
        );
        if depth_kind == HostDepth::ReversedInfinite {
            // The same pixels as lucent's frame: its clip-space y convention.
            let mut projection = layout.camera.projection;
            projection.y_axis.y = -projection.y_axis.y;
            layout.camera = lucent::embed::HostCamera::new(layout.camera.view, projection);
        }
        let (normals, normal_desc) =
            normal_image(&test, normals_kind, w, h, &gb.gb1, layout.camera.view);
        // Thickness: lucent's GB2 itself (rgb, and the IDs in its alpha), or its rgb in RGBA8.
        let thickness = gpu
            .upload_image(
                &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
                &[rgba8(&gb2)],
                "host thickness",
            )
            .unwrap();
        let mut desc = layout
            .desc
            .clone()
            .with_normals(normal_desc)
            .with_albedo(vk::Format::R8G8B8A8_UNORM)
            .with_thickness(ThicknessDesc::rgb(vk::Format::R8G8B8A8_UNORM));
        if ids_kind.is_none() {
            desc = desc.with_material_ids(IdDesc::bits(vk::Format::R8G8B8A8_UNORM, 3, 0, 8));
        }
        let materials: Vec<TranslucentMaterial> = (0..rows.len())
            .map(|i| {
                let id = (i + 1) as u8;
                let t = parameters
                    .iter()
                    .find(|t| lucent::features::translucency::material_row(t) == rows[i])
                    .expect("each row is a material's");
                TranslucentMaterial::from_translucency(host_id(id_kind, id), t).unwrap()
            })
            .collect();
        let lucent = wrap(&test, options(3));
        let mut effect = built(&test, &lucent, |u| {
            TranslucencyEffect::new(
                &lucent,
                u,
                TranslucencyEffectDesc::new(desc.clone(), materials),
            )
        })
        .unwrap();
        assert_eq!(effect.plan().passes.len(), 1, "one pass");
        // One layout draws over the translucent pixels' bounds only (a host's projected
        // object bounds), the others over the whole screen.
        let regions: Vec<vk::Rect2D> = if depth_kind == HostDepth::ReversedInfinite {
            vec![bounds(w, h, &ids)]
        } else {
            Vec::new()
        };
        let frames = host_frames(
            &test,
            &layout,
            &desc,
            bytemuck::cast_slice(without.hdr.as_ref().unwrap()),
            |k, cmd, images| {
                let thickness_image = described(&thickness, "host thickness", usage);
                effect
                    .record(
                        &lucent,
                        cmd,
                        &TranslucencyFrame {
                            slot: k,
                            view: 0,
                            camera: layout.camera,
                            lights: &scene.lights,
                            images: TranslucencyImages {
                                depth: images.depth,
                                normals: &described(&normals, "host normals", usage),
                                albedo: &described(&albedo, "host albedo", usage),
                                thickness: &thickness_image,
                                // Without an ID kind the IDs share the thickness's target.
                                material_ids: match ids_kind {
                                    None => &thickness_image,
                                    Some(_) => images.ids.unwrap(),
                                },
                            },
                            regions: &regions,
                            lighting: images.lighting,
                        },
                    )
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            },
        );
        for (k, texels) in frames.iter().enumerate() {
            report.push(compare_host_frame(
                &want,
                &tonemapped(texels, exposure),
                (w, h),
                0,
                &format!("{name}, frame {k}"),
                &format!("embed-translucency-{k}"),
            ));
        }
        effect.destroy(&lucent);
        drop(lucent);
        for image in [normals, thickness] {
            gpu.destroy_image(image);
        }
        layout.destroy(&test);
    }
    gpu.destroy_image(albedo);
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

#[test]
fn a_translucency_description_missing_an_input_or_out_of_range_is_a_typed_error() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(2));
    let gbuffer = lucent::embed::GBufferDesc::new(
        64,
        48,
        lucent::embed::DepthDesc::device(vk::Format::D32_SFLOAT),
        lucent::embed::DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
    .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT))
    .with_albedo(vk::Format::R8G8B8A8_UNORM)
    .with_thickness(ThicknessDesc::channel(vk::Format::R8_UNORM, 0));
    let material = TranslucentMaterial::new(7, 12.0, 0.2, 0.0);
    let build = |desc: TranslucencyEffectDesc| {
        built(&test, &lucent, |u| {
            TranslucencyEffect::new(&lucent, u, desc)
        })
    };
    // Each input the term reads, left out.
    for (input, gbuffer) in [
        ("normals", changed(&gbuffer, |g| g.normals = None)),
        ("thickness", changed(&gbuffer, |g| g.thickness = None)),
        ("albedo", changed(&gbuffer, |g| g.albedo = None)),
        ("material IDs", changed(&gbuffer, |g| g.material_ids = None)),
    ] {
        let e = host_error(build(TranslucencyEffectDesc::new(gbuffer, vec![material])));
        assert!(
            matches!(&e, HostError::Missing { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    // Encodings the formats cannot hold.
    for (input, gbuffer) in [
        (
            "normals",
            gbuffer
                .clone()
                .with_normals(NormalDesc::world(vk::Format::R16G16_SFLOAT)),
        ),
        (
            "normals",
            gbuffer
                .clone()
                .with_normals(NormalDesc::world(vk::Format::R8G8B8A8_UINT)),
        ),
        (
            "thickness",
            gbuffer
                .clone()
                .with_thickness(ThicknessDesc::rgb(vk::Format::R8G8_UNORM)),
        ),
        (
            "thickness",
            gbuffer
                .clone()
                .with_thickness(ThicknessDesc::channel(vk::Format::R8G8B8A8_UNORM, 4)),
        ),
    ] {
        let e = host_error(build(TranslucencyEffectDesc::new(gbuffer, vec![material])));
        assert!(
            matches!(&e, HostError::Unsupported { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    // Materials: none, an ID twice, an ID past a 4-bit field.
    let narrow =
        gbuffer
            .clone()
            .with_material_ids(IdDesc::bits(vk::Format::R8G8B8A8_UINT, 3, 4, 4));
    for (gbuffer, materials) in [
        (gbuffer.clone(), vec![]),
        (gbuffer.clone(), vec![material, material]),
        (narrow, vec![TranslucentMaterial::new(40, 12.0, 0.2, 0.0)]),
    ] {
        let e = host_error(build(TranslucencyEffectDesc::new(gbuffer, materials)));
        assert!(matches!(&e, HostError::Description { .. }), "{e}");
    }
    // And a good one builds.
    let effect = build(TranslucencyEffectDesc::new(gbuffer, vec![material])).unwrap();
    effect.destroy(&lucent);
    drop(lucent);
    test.finish();
}
