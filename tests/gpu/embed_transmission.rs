//! Screen-space SSS's transmission as an effect on a host's G-buffer
//! (`lucent::embed::TransmissionEffect`) against lucent's own frame of the same scene: the
//! host's lighting is lucent's lit diffuse (before the blur) without transmission, its
//! shadow map lucent's own light-space atlas with each face's matrices as a host describes
//! them, its G-buffer lucent's own re-encoded in host layouts (standard, reversed-Z infinite,
//! D24S8 and linear depth; normals world or view space, xyz or octahedral, float or UNORM; IDs
//! R8_UNORM, R8_UINT, stencil bits, bits of a packed target), and the effect must add what
//! lucent's lighting pass adds: a point light's six faces, a spot light's and a directional
//! light's one.

use std::path::Path;

use crate::common::TestGpu;
use crate::embed::{
    built, changed, compare_host_frame, described, host_error, host_frames, host_id, host_layout,
    options, tonemapped, wrap, HostDepth, HostIds,
};
use crate::embed_translucency::{normal_image, rgba8, HostNormals};

use ash::vk;
use lucent::backend::{GpuImage, ImageDesc};
use lucent::embed::{
    capabilities, DiffuseDesc, Effect, GBufferDesc, HostError, HostImage, IdDesc, ImageState,
    NormalDesc, ShadowFace, TransmissionEffect, TransmissionEffectDesc, TransmissionFrame,
    TransmissionImages, TransmissionMaterial,
};
use lucent::features::registry;
use lucent::features::shadows::ShadowDesc;
use lucent::features::sss::SssProfiles;
use lucent::frame::{FrameSettings, Renderer, Technique};
use lucent::scene::material::Texturing;

/// A thin slab of skin and a ball of marble (1 unit = 20 mm), lit from behind by a point
/// light (six faces), a spot light and a directional light, all casting.
fn scene() -> lucent::scene::Scene {
    let source = r#"name = "host-transmission"
ambient = [0.02, 0.02, 0.02]
sky = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.4, 4.0]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 40.0
[[mesh]]
name = "slab"
generator = "cube"
level = 3
[[mesh]]
name = "ball"
generator = "icosphere"
level = 3
[[material]]
name = "skin"
specular = 0.0
[material.medium]
preset = "skin1"
units_per_mm = 0.05
[[material]]
name = "marble"
specular = 0.0
[material.medium]
preset = "marble"
units_per_mm = 0.05
[[object]]
mesh = "slab"
material = "skin"
translate = [-0.7, 0.0, 0.0]
scale = [0.6, 0.6, 0.08]
[[object]]
mesh = "ball"
material = "marble"
translate = [0.7, 0.0, 0.0]
scale = [0.4, 0.4, 0.4]
[[light]]
type = "point"
position = [-0.7, 0.1, -1.0]
intensity = 12.0
range = 100.0
[[light]]
type = "spot"
position = [0.7, 0.3, -1.6]
direction = [0.0, -0.15, 1.0]
inner_degrees = 20.0
outer_degrees = 30.0
intensity = 30.0
range = 100.0
[[light]]
type = "directional"
direction = [0.3, -0.2, 1.0]
intensity = 1.5
"#;
    lucent::scene::file::parse_scene(Path::new("host-transmission.toml"), source)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// How a host lays out its shadow maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Maps {
    /// One atlas.
    Atlas,
    /// One array, a face per layer.
    Array,
    /// An atlas and an array beside it (`with_second_shadow_map`).
    AtlasAndArray,
}

/// How a host's shadow map stores depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum HostShadowZ {
    /// Standard Z: lucent's own atlas as it is.
    Standard,
    /// Reversed Z with the same planes: 1 - d.
    Reversed,
    /// Reversed Z with an infinite far plane on the perspective faces (near / distance; the
    /// orthographic faces reversed with their planes).
    ReversedInfinite,
}

/// lucent's light-space atlas (`depths`, `size`) and its `faces` as a host storing depth as
/// `z` hands them over: each face's projection changed to store that depth, each texel of its
/// rectangle re-encoded (texels outside every face: the reversed clear value, 0).
fn host_shadow_map(
    depths: &[f32],
    (width, _height): (u32, u32),
    faces: &[ShadowFace],
    z: HostShadowZ,
) -> (Vec<f32>, Vec<ShadowFace>) {
    if z == HostShadowZ::Standard {
        return (depths.to_vec(), faces.to_vec());
    }
    let mut out = vec![0.0f32; depths.len()];
    let mut host_faces = Vec::with_capacity(faces.len());
    // z' = w - z: depth 1 - d with the same planes.
    let flip = glam::Mat4::from_cols(
        glam::Vec4::X,
        glam::Vec4::Y,
        glam::Vec4::new(0.0, 0.0, -1.0, 0.0),
        glam::Vec4::new(0.0, 0.0, 1.0, 1.0),
    );
    for face in faces {
        let p = face.projection;
        let orthographic = p.w_axis.w != 0.0;
        let (near, far) = lucent::gpu_scene::projection_depth_ends(&p).unwrap();
        let infinite = z == HostShadowZ::ReversedInfinite && !orthographic;
        let projection = if infinite {
            // Clip z = near, w = the distance: depth near / distance (glam's
            // perspective_infinite_reverse_rh).
            let mut q = p;
            q.z_axis.z = 0.0;
            q.w_axis.z = near as f32;
            q
        } else {
            flip * p
        };
        let r = face.rect;
        for y in r.offset.y as u32..r.offset.y as u32 + r.extent.height {
            for x in r.offset.x as u32..r.offset.x as u32 + r.extent.width {
                let i = (y * width + x) as usize;
                let d = f64::from(depths[i]);
                out[i] = if d >= 1.0 {
                    0.0
                } else if infinite {
                    let distance = near * far / (far - d * (far - near));
                    (near / distance) as f32
                } else {
                    (1.0 - d) as f32
                };
            }
        }
        host_faces.push(ShadowFace::new(
            face.light, face.view, projection, face.rect,
        ));
    }
    (out, host_faces)
}

/// lucent's light-space atlas (`depths`, `size`) and its `faces` as a host keeping each face in
/// a layer of its own hands them over: an array of square layers as large as the largest face,
/// each face at the top left of its layer (the rest cleared to depth 1), each face's layer
/// given. Returns the layers' texels one after the other, their edge, and the faces.
fn host_shadow_array(
    depths: &[f32],
    (width, _height): (u32, u32),
    faces: &[ShadowFace],
) -> (Vec<f32>, u32, Vec<ShadowFace>) {
    let edge = faces.iter().map(|f| f.rect.extent.width).max().unwrap();
    let layer_texels = (edge * edge) as usize;
    let mut out = vec![1.0f32; layer_texels * faces.len()];
    let mut host_faces = Vec::with_capacity(faces.len());
    for (layer, face) in faces.iter().enumerate() {
        let r = face.rect;
        for y in 0..r.extent.height {
            for x in 0..r.extent.width {
                let from = ((r.offset.y as u32 + y) * width + r.offset.x as u32 + x) as usize;
                out[layer * layer_texels + (y * edge + x) as usize] = depths[from];
            }
        }
        let rect = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: r.extent,
        };
        host_faces.push(
            ShadowFace::new(face.light, face.view, face.projection, rect).in_layer(layer as u32),
        );
    }
    (out, edge, host_faces)
}

/// A host's shadow map made from lucent's atlas (`depths`, `size`) and `faces`: stored as `z`
/// in one atlas, or (`array`, standard Z) with each face in a layer of its own; uploaded, with
/// its `HostImage` (sampled in the fragment shader) and the faces as the host gives them.
pub(crate) struct HostShadowMap {
    pub(crate) image: GpuImage,
    pub(crate) host: HostImage,
    pub(crate) faces: Vec<ShadowFace>,
}

pub(crate) fn upload_host_shadow_map(
    test: &TestGpu,
    depths: &[f32],
    size: (u32, u32),
    faces: &[ShadowFace],
    z: HostShadowZ,
    array: bool,
) -> HostShadowMap {
    let usage = vk::ImageUsageFlags::SAMPLED;
    let (texels, (w, h), layers, faces) = if array {
        let (texels, edge, faces) = host_shadow_array(depths, size, faces);
        let layers = faces.len() as u32;
        (texels, (edge, edge), layers, faces)
    } else {
        let (texels, faces) = host_shadow_map(depths, size, faces, z);
        (texels, size, 1, faces)
    };
    let image = test
        .gpu
        .upload_image(
            &ImageDesc::depth(w, h, vk::Format::D32_SFLOAT, usage).with_layers(layers),
            &[bytemuck::cast_slice(&texels).to_vec()],
            "host shadow map",
        )
        .unwrap();
    let host = HostImage::new(
        "host shadow map",
        image.image,
        image.view,
        vk::Format::D32_SFLOAT,
        vk::Extent2D {
            width: w,
            height: h,
        },
        usage,
    )
    .with_layers(layers)
    .in_state(ImageState::fragment_sampled());
    HostShadowMap { image, host, faces }
}

/// lucent's atlas (`depths`, `size`) and its `faces` as a host keeping the faces of the lights
/// `in_array` picks (a point light's cube faces, say) in an array beside an atlas of its
/// other faces hands them over: the atlas stored as `z` (the moved faces' tiles unread), and
/// a second map, an array with each moved face in a layer of its own ([`host_shadow_array`],
/// standard Z; at least two faces, so that its view is a 2-D array view), its faces
/// [`ShadowFace::in_second_map`]. Returns the atlas (with every face) and the array.
pub(crate) fn upload_split_shadow_maps(
    test: &TestGpu,
    depths: &[f32],
    size: (u32, u32),
    faces: &[ShadowFace],
    lights: &[lucent::scene::Light],
    in_array: impl Fn(&lucent::scene::Light) -> bool,
    z: HostShadowZ,
) -> (HostShadowMap, HostShadowMap) {
    let moved = |f: &ShadowFace| in_array(&lights[f.light]);
    let cube: Vec<ShadowFace> = faces.iter().filter(|f| moved(f)).copied().collect();
    assert!(cube.len() > 1 && cube.len() < faces.len());
    let array = upload_host_shadow_map(test, depths, size, &cube, HostShadowZ::Standard, true);
    let mut atlas = upload_host_shadow_map(test, depths, size, faces, z, false);
    // The faces in the frame's order: each moved face in its layer of the second map, the
    // others in the atlas as `z` stores them.
    let mut in_second = array.faces.iter();
    atlas.faces = faces
        .iter()
        .zip(atlas.faces.clone())
        .map(|(f, in_atlas)| match moved(f) {
            true => {
                let face = in_second.next().unwrap();
                face.in_second_map(face.layer)
            }
            false => in_atlas,
        })
        .collect();
    (atlas, array)
}

#[test]
fn the_transmission_effect_on_host_layouts_equals_lucents_own_frame() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (200, 150);
    let scene = scene();
    let technique = Technique::parse("separable").unwrap();
    let settings = |transmission: bool| {
        let mut s = FrameSettings {
            technique,
            export_gbuffer: true,
            export_lit: true,
            export_shadows: true,
            ..FrameSettings::new(w, h)
        };
        // The host's diffuse carries the whole albedo (profiles blurred as they are).
        s.sss.texturing = Some(Texturing::Pre);
        s.sss.transmission = transmission;
        s
    };
    let render = |transmission: bool| {
        let renderer = Renderer::new(
            gpu,
            &test.shaders,
            &test.cache,
            &scene,
            settings(transmission),
        )
        .unwrap();
        renderer.render_once(gpu).unwrap();
        let gb = renderer.read_gbuffer(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        let shadow_map = renderer.read_shadow_map(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        (gb, lit, shadow_map)
    };
    let (gb, with, (sw, sh, depths)) = render(true);
    let (_, without, _) = render(false);
    let exposure = f64::from(scene.exposure);
    let flat = |t: &[[f32; 4]]| -> Vec<f32> { t.iter().flatten().copied().collect() };
    let want = tonemapped(&flat(&with.diffuse), exposure);
    let plain = tonemapped(&flat(&without.diffuse), exposure);
    // The transmitted light must be visible, or the comparison below proves nothing.
    let lit_through = want
        .chunks_exact(4)
        .zip(plain.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(
        lit_through * 50 > (w * h) as usize,
        "transmission changes only {lit_through} pixels"
    );
    // lucent's profile numbers (the G-buffer's IDs) and each one's medium.
    let ids: Vec<u8> = gb.sss.as_ref().unwrap().iter().map(|&v| v as u8).collect();
    let profiles = SssProfiles::new(
        &scene,
        Some(registry::sss_blur("separable").unwrap()),
        None,
        Some(Texturing::Pre),
        &registry::blur_of,
    )
    .unwrap()
    .unwrap();
    let medium_of = |k: u8| {
        let object = profiles
            .object_ids
            .iter()
            .position(|&id| id == k)
            .expect("each profile is an object's");
        scene.objects[object].material.medium.clone().unwrap()
    };
    let profile_count = ids.iter().copied().max().unwrap();
    assert_eq!(profile_count, 2, "two media");
    // The host's shadow map: lucent's atlas, each face with its matrices and tile.
    let faces: Vec<ShadowFace> = ShadowDesc::new(&scene, &settings(true).shadows, false)
        .unwrap()
        .face_matrices(&scene, &lucent::gpu_scene::tiles::mesh_bounds(&scene))
        .into_iter()
        .map(ShadowFace::from)
        .collect();
    assert_eq!(
        faces.len(),
        8,
        "a point light's six faces, a spot's and a sun's"
    );
    let usage = vk::ImageUsageFlags::SAMPLED;
    let albedo = gpu
        .upload_image(
            &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
            &[rgba8(&gb.gb0)],
            "host albedo",
        )
        .unwrap();
    let mut report = Vec::new();
    for (name, depth_kind, ids_kind, normals_kind, shadow_z, maps) in [
        (
            "D32, world RGBA16F normals, R8_UNORM IDs",
            HostDepth::Standard,
            HostIds::Unorm,
            HostNormals::WorldHalf,
            HostShadowZ::Standard,
            Maps::Atlas,
        ),
        (
            "reversed-Z infinite D32, view-space octahedral RG16 normals, R8_UINT IDs, a \
             reversed-Z shadow map",
            HostDepth::ReversedInfinite,
            HostIds::Uint,
            HostNormals::ViewOctahedralUnorm,
            HostShadowZ::Reversed,
            Maps::Atlas,
        ),
        (
            "D24S8 with IDs in stencil bits 4-7, world RGBA16_UNORM normals",
            HostDepth::D24Stencil,
            HostIds::Stencil,
            HostNormals::WorldUnorm,
            HostShadowZ::Standard,
            Maps::Atlas,
        ),
        (
            "linear R32F depth, IDs in bits of a packed RGBA8 alpha, world octahedral RG32F \
             normals, a reversed-Z infinite-far shadow map",
            HostDepth::Linear,
            HostIds::AlphaBits,
            HostNormals::WorldOctahedralFloat,
            HostShadowZ::ReversedInfinite,
            Maps::Atlas,
        ),
        (
            "D32, world RGBA16F normals, R8_UNORM IDs, each shadow face in a layer of an array",
            HostDepth::Standard,
            HostIds::Unorm,
            HostNormals::WorldHalf,
            HostShadowZ::Standard,
            Maps::Array,
        ),
        (
            "D32, world RGBA16F normals, R8_UNORM IDs, the spot's and sun's faces in an atlas, \
             the point light's six in a second map, an array",
            HostDepth::Standard,
            HostIds::Unorm,
            HostNormals::WorldHalf,
            HostShadowZ::Standard,
            Maps::AtlasAndArray,
        ),
    ] {
        let (shadow_map, second) = if maps == Maps::AtlasAndArray {
            let split = upload_split_shadow_maps(
                &test,
                &depths,
                (sw, sh),
                &faces,
                &scene.lights,
                |l| matches!(l.kind, lucent::scene::LightKind::Point { .. }),
                shadow_z,
            );
            (split.0, Some(split.1))
        } else {
            let array = maps == Maps::Array;
            let map = upload_host_shadow_map(&test, &depths, (sw, sh), &faces, shadow_z, array);
            (map, None)
        };
        let mut layout = host_layout(
            &test, depth_kind, ids_kind, w, h, &scene, &gb.depth, &ids, 0.02,
        );
        if depth_kind == HostDepth::ReversedInfinite {
            // The same pixels as lucent's frame: its clip-space y convention.
            let mut projection = layout.camera.projection;
            projection.y_axis.y = -projection.y_axis.y;
            layout.camera = lucent::embed::HostCamera::new(layout.camera.view, projection);
        }
        let (normals, normal_desc) =
            normal_image(&test, normals_kind, w, h, &gb.gb1, layout.camera.view);
        let desc = layout
            .desc
            .clone()
            .with_normals(normal_desc)
            .with_albedo(vk::Format::R8G8B8A8_UNORM);
        assert!(capabilities(&desc).unwrap()[2].1.runs());
        let materials: Vec<TransmissionMaterial> = (1..=profile_count)
            .map(|k| TransmissionMaterial::new(host_id(ids_kind, k), medium_of(k)))
            .collect();
        let lucent = wrap(&test, options(3));
        let mut effect = built(&test, &lucent, |u| {
            TransmissionEffect::new(&lucent, u, {
                let effect =
                    TransmissionEffectDesc::new(desc.clone(), materials, vk::Format::D32_SFLOAT);
                match maps {
                    Maps::Atlas => effect,
                    Maps::Array => effect.with_shadow_array(),
                    Maps::AtlasAndArray => effect.with_second_shadow_map(vk::Format::D32_SFLOAT),
                }
            })
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(effect.plan().passes.len(), 1, "one pass");
        let frames = host_frames(
            &test,
            &layout,
            &desc,
            bytemuck::cast_slice(&without.diffuse),
            |k, cmd, images| {
                let normals = described(&normals, "host normals", usage);
                let albedo = described(&albedo, "host albedo", usage);
                let frame = TransmissionFrame {
                    slot: k,
                    view: 0,
                    camera: layout.camera,
                    lights: &scene.lights,
                    shadow_faces: &shadow_map.faces,
                    images: TransmissionImages {
                        depth: images.depth,
                        normals: &normals,
                        material_ids: images.ids.unwrap(),
                        albedo: Some(&albedo),
                        shadow_map: &shadow_map.host,
                        second_shadow_map: second.as_ref().map(|array| &array.host),
                    },
                    regions: &[],
                    lighting: images.lighting,
                };
                if k == 0 && maps == Maps::AtlasAndArray {
                    // Without the second map, or with the cube faces said to be in the
                    // first: typed errors, before anything is recorded.
                    let mut without = frame;
                    without.images.second_shadow_map = None;
                    let e = host_error(effect.record(&lucent, cmd, &without));
                    assert!(
                        matches!(&e, HostError::Missing { input, .. } if input == "second shadow map"),
                        "{e}"
                    );
                    let in_first: Vec<ShadowFace> = shadow_map
                        .faces
                        .iter()
                        .map(|f| changed(f, |f| f.map = 0))
                        .collect();
                    let mut misplaced = frame;
                    misplaced.shadow_faces = &in_first;
                    // (The cube faces' layers 1 to 5 are past the atlas's one layer.)
                    let e = host_error(effect.record(&lucent, cmd, &misplaced));
                    assert!(matches!(&e, HostError::Description { .. }), "{e}");
                }
                effect
                    .record(&lucent, cmd, &frame)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
            },
        );
        for (k, texels) in frames.iter().enumerate() {
            let have = tonemapped(texels, exposure);
            // A position or normal the host encodes otherwise (reversed or linear depth,
            // octahedral normals) moves the point the map is read from (one texel inside along
            // the normal) by a hair: where that crosses to another map texel on a silhouette,
            // the thickness jumps (measured: 2 channel values of 120,000, one pixel). At most
            // 0.05% of the channel values may differ by more than 1/255.
            report.push(compare_host_frame(
                &want,
                &have,
                (w, h),
                want.len() / 2000,
                &format!("{name}, frame {k}"),
                &format!("embed-transmission-{k}"),
            ));
        }
        effect.destroy(&lucent);
        drop(lucent);
        gpu.destroy_image(normals);
        gpu.destroy_image(shadow_map.image);
        if let Some(array) = second {
            gpu.destroy_image(array.image);
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
fn a_transmission_description_missing_an_input_or_with_bad_faces_is_a_typed_error() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(2));
    let gbuffer = GBufferDesc::new(
        64,
        48,
        lucent::embed::DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
    .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT))
    .with_albedo(vk::Format::R8G8B8A8_UNORM);
    let medium = scene().objects[0].material.medium.clone().unwrap();
    let material = TransmissionMaterial::new(7, medium);
    let build = |gbuffer: GBufferDesc, materials: Vec<TransmissionMaterial>, format| {
        built(&test, &lucent, |u| {
            TransmissionEffect::new(
                &lucent,
                u,
                TransmissionEffectDesc::new(gbuffer, materials, format),
            )
        })
    };
    let d32 = vk::Format::D32_SFLOAT;
    for (input, gbuffer) in [
        ("material IDs", changed(&gbuffer, |g| g.material_ids = None)),
        ("normals", changed(&gbuffer, |g| g.normals = None)),
        ("albedo", changed(&gbuffer, |g| g.albedo = None)),
    ] {
        let e = host_error(build(gbuffer, vec![material.clone()], d32));
        assert!(
            matches!(&e, HostError::Missing { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    assert!(
        !capabilities(&changed(&gbuffer, |g| g.normals = None)).unwrap()[2]
            .1
            .runs()
    );
    assert_eq!(Effect::ALL[2], Effect::SssTransmission);
    // A shadow map that is not a depth format; no material; an ID twice.
    let e = host_error(build(
        gbuffer.clone(),
        vec![material.clone()],
        vk::Format::R32_SFLOAT,
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "shadow map"),
        "{e}"
    );
    for materials in [vec![], vec![material.clone(), material.clone()]] {
        let e = host_error(build(gbuffer.clone(), materials, d32));
        assert!(matches!(&e, HostError::Description { .. }), "{e}");
    }
    // A second shadow map beside a first that is an array; one that is not a depth format;
    // the albedo as each SSS texturing asks, which the transmitted light cannot follow.
    let desc = |second| {
        TransmissionEffectDesc::new(gbuffer.clone(), vec![material.clone()], d32)
            .with_second_shadow_map(second)
    };
    for (desc, input) in [
        (desc(d32).with_shadow_array(), "second shadow map"),
        (desc(vk::Format::R32_SFLOAT), "second shadow map"),
        (
            TransmissionEffectDesc::new(
                changed(&gbuffer, |g| {
                    g.diffuse =
                        DiffuseDesc::with_albedo_as_texturing(vk::Format::R16G16B16A16_SFLOAT)
                }),
                vec![material.clone()],
                d32,
            ),
            "diffuse",
        ),
    ] {
        let e = host_error(built(&test, &lucent, |u| {
            TransmissionEffect::new(&lucent, u, desc)
        }));
        assert!(
            matches!(&e, HostError::Unsupported { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    let effect = build(gbuffer, vec![material], d32).unwrap();
    effect.destroy(&lucent);
    drop(lucent);
    test.finish();
}
