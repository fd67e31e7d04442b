//! Li et al.'s layered media as an effect on a host's G-buffer and meshes
//! (`lucent::embed::LayeredEffect`) against lucent's own frame of the same scene: the host's
//! lighting is lucent's lit frame with the layered terms weighted 0 (eq. 3's `λ3 = λ4 = λ5 =
//! 0`: the same G-buffer, passes adding nothing), its G-buffer lucent's own re-encoded in host
//! layouts (standard, reversed-Z infinite, D24S8 and linear depth; normals world or view
//! space, xyz or octahedral; IDs R8_UNORM, R8_UINT, stencil bits, bits of a packed target),
//! its meshes lucent's own in the host's vertex and index buffers (interleaved f32 with 32-bit
//! indices; positions and half-float normals in two bindings with 16-bit indices; not
//! indexed), and lucent must draw its light-space maps from them with the faces' matrices and
//! add what its own frame adds: a point light's six faces, a spot light's and a sun's one.

use std::path::Path;

use crate::common::TestGpu;
use crate::embed::{
    built, changed, compare_host_frame, described, host_error, host_frames, host_id, host_layout,
    options, tonemapped, wrap, HostDepth, HostIds,
};
use crate::embed_translucency::{normal_image, HostNormals};

use ash::vk;
use glam::Mat4;
use lucent::backend::{GpuBuffer, ImageDesc};
use lucent::embed::{
    capabilities, DiffuseDesc, Effect, GBufferDesc, HostError, IdDesc, IndexBuffer, LayeredEffect,
    LayeredEffectDesc, LayeredFrame, LayeredImages, LayeredMaterial, MeshDraw, NormalDesc,
    ShadowFace, VertexAttribute, VertexLayout,
};
use lucent::features::layered::LayeredDesc;
use lucent::features::shadows::ShadowDesc;
use lucent::frame::{FrameSettings, Renderer};

/// An apple ball with a striped albedo texture (its film) and a two-layer skin slab (1 unit =
/// 20 mm) over a plain floor that casts, lit by a point light (six faces), a spot light and a
/// directional light, all casting; `weights` are both media's eq. 3 weights.
fn scene(weights: [f32; 5]) -> lucent::scene::Scene {
    let stripes = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/truth/scenes/stripes.png");
    let stripes = stripes.display();
    let source = format!(
        r#"name = "host-layered"
ambient = [0.05, 0.05, 0.06]
sky = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 1.0, 4.0]
target = [0.0, 0.1, 0.0]
fov_y_degrees = 40.0
[[mesh]]
name = "ball"
generator = "icosphere"
level = 3
[[mesh]]
name = "slab"
generator = "cube"
level = 3
[[mesh]]
name = "floor"
generator = "plane"
[[material]]
name = "apple"
albedo_texture = "{stripes}"
[material.layered]
preset = "apple"
units_per_mm = 0.05
weights = {weights:?}
[[material]]
name = "skin"
[material.layered]
preset = "skin-layered"
units_per_mm = 0.05
weights = {weights:?}
[[material]]
name = "floor"
[[object]]
mesh = "ball"
material = "apple"
translate = [0.7, 0.35, 0.0]
scale = [0.45, 0.45, 0.45]
[[object]]
mesh = "slab"
material = "skin"
translate = [-0.7, 0.35, 0.0]
scale = [0.5, 0.5, 0.12]
[[object]]
mesh = "floor"
material = "floor"
scale = [4.0, 1.0, 4.0]
[[light]]
type = "point"
position = [-0.7, 0.6, -1.2]
intensity = 10.0
range = 100.0
[[light]]
type = "spot"
position = [1.6, 1.6, 1.2]
direction = [-0.6, -0.8, -0.8]
inner_degrees = 20.0
outer_degrees = 30.0
intensity = 30.0
range = 100.0
[[light]]
type = "directional"
direction = [0.3, -0.6, -1.0]
intensity = 1.5
"#
    );
    lucent::scene::file::parse_scene(Path::new("host-layered.toml"), &source)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// How the test's host lays out its meshes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum HostMeshes {
    /// Interleaved f32 position and normal (24 bytes), 32-bit indices.
    Interleaved,
    /// Binding 0: f32 positions with w (16 bytes); binding 1: 4 bytes of the host's own, then
    /// a half-float normal (12 bytes); 16-bit indices.
    TwoBindings,
    /// Interleaved, no index buffer (the triangles' vertices in order).
    NotIndexed,
}

/// The scene's meshes in the host's buffers, laid out as `kind` says.
struct MeshBuffers {
    layout: VertexLayout,
    /// Per mesh: binding 0, binding 1 (or null), the index buffer (or none), the count.
    meshes: Vec<(GpuBuffer, Option<GpuBuffer>, Option<GpuBuffer>, u32)>,
}

impl MeshBuffers {
    fn new(test: &TestGpu, scene: &lucent::scene::Scene, kind: HostMeshes) -> Self {
        let gpu = &test.gpu;
        let vertex_usage = vk::BufferUsageFlags::VERTEX_BUFFER;
        let index_usage = vk::BufferUsageFlags::INDEX_BUFFER;
        let half = |v: f32| half::f16::from_f32(v).to_bits();
        let meshes = scene
            .meshes
            .iter()
            .map(|mesh| {
                let interleaved = |order: &[u32]| -> Vec<f32> {
                    order
                        .iter()
                        .flat_map(|&i| {
                            let (p, n) = (mesh.positions[i as usize], mesh.normals[i as usize]);
                            [p.x, p.y, p.z, n.x, n.y, n.z]
                        })
                        .collect()
                };
                match kind {
                    HostMeshes::Interleaved => {
                        let all: Vec<u32> = (0..mesh.positions.len() as u32).collect();
                        let vertices = gpu
                            .upload_buffer(&interleaved(&all), vertex_usage, "host vertices")
                            .unwrap();
                        let indices = gpu
                            .upload_buffer(&mesh.indices, index_usage, "host indices")
                            .unwrap();
                        (vertices, None, Some(indices), mesh.indices.len() as u32)
                    }
                    HostMeshes::TwoBindings => {
                        let positions: Vec<f32> = mesh
                            .positions
                            .iter()
                            .flat_map(|p| [p.x, p.y, p.z, 1.0])
                            .collect();
                        let normals: Vec<u16> = mesh
                            .normals
                            .iter()
                            .flat_map(|n| [0xbeef, 0xbeef, half(n.x), half(n.y), half(n.z), 0])
                            .collect();
                        let short: Vec<u16> = mesh.indices.iter().map(|&i| i as u16).collect();
                        assert!(mesh.positions.len() <= 1 << 16);
                        (
                            gpu.upload_buffer(&positions, vertex_usage, "host positions")
                                .unwrap(),
                            Some(
                                gpu.upload_buffer(&normals, vertex_usage, "host normals")
                                    .unwrap(),
                            ),
                            Some(
                                gpu.upload_buffer(&short, index_usage, "host indices")
                                    .unwrap(),
                            ),
                            mesh.indices.len() as u32,
                        )
                    }
                    HostMeshes::NotIndexed => (
                        gpu.upload_buffer(
                            &interleaved(&mesh.indices),
                            vertex_usage,
                            "host triangles",
                        )
                        .unwrap(),
                        None,
                        None,
                        mesh.indices.len() as u32,
                    ),
                }
            })
            .collect();
        let layout = match kind {
            HostMeshes::Interleaved | HostMeshes::NotIndexed => {
                VertexLayout::interleaved(24, 0, 12)
            }
            HostMeshes::TwoBindings => VertexLayout::new(
                [16, 12],
                VertexAttribute::new(0, vk::Format::R32G32B32A32_SFLOAT, 0),
                VertexAttribute::new(1, vk::Format::R16G16B16A16_SFLOAT, 4),
            ),
        };
        Self { layout, meshes }
    }

    /// The scene's objects as the host's draws, each of the host ID `id_of(object)`.
    fn draws(&self, scene: &lucent::scene::Scene, id_of: impl Fn(usize) -> u8) -> Vec<MeshDraw> {
        scene
            .objects
            .iter()
            .enumerate()
            .map(|(k, object)| {
                let (vertices, second, indices, count) = &self.meshes[object.mesh];
                let index_type = if second.is_some() {
                    vk::IndexType::UINT16
                } else {
                    vk::IndexType::UINT32
                };
                let draw = MeshDraw::new(vertices.buffer, *count, object.transform, id_of(k));
                let draw = match indices {
                    Some(indices) => draw.with_indices(IndexBuffer {
                        buffer: indices.buffer,
                        offset: 0,
                        index_type,
                    }),
                    None => draw,
                };
                match second {
                    Some(buffer) => draw.with_second_binding(buffer.buffer, 0),
                    None => draw,
                }
            })
            .collect()
    }

    fn destroy(self, test: &TestGpu) {
        for (a, b, c, _) in self.meshes {
            for buffer in [Some(a), b, c].into_iter().flatten() {
                test.gpu.destroy_buffer(buffer);
            }
        }
    }
}

#[test]
fn the_layered_effect_on_host_layouts_and_meshes_equals_lucents_own_frame() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (200, 150);
    let weights = [0.3, 0.3, 1.0, 1.0, 1.0];
    let settings = FrameSettings {
        export_gbuffer: true,
        export_hdr: true,
        export_shadows: true,
        ..FrameSettings::new(w, h)
    };
    let render = |scene: &lucent::scene::Scene| {
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, scene, settings).unwrap();
        let frame = renderer.render_once(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        (frame.gbuffer.unwrap(), frame.hdr.unwrap())
    };
    let scene = scene(weights);
    let (gb, with) = render(&scene);
    let (_, without) = render(&self::scene([0.3, 0.3, 0.0, 0.0, 0.0]));
    let exposure = f64::from(scene.exposure);
    let want = tonemapped(&with, exposure);
    let plain = tonemapped(&without, exposure);
    // The terms must be visible, or the comparison below proves nothing.
    let changed_pixels = want
        .chunks_exact(4)
        .zip(plain.chunks_exact(4))
        .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(
        changed_pixels * 20 > (w * h) as usize,
        "the layered terms change only {changed_pixels} pixels"
    );
    // The layered target: the material ID / 255 in red, the film texel in green, blue, alpha.
    let layered = gb.layered.as_ref().unwrap();
    let ids: Vec<u8> = layered
        .iter()
        .map(|t| (t[0] * 255.0).round() as u8)
        .collect();
    let film: Vec<u8> = layered
        .iter()
        .flat_map(|t| [t[1], t[2], t[3], 1.0].map(|v| (v * 255.0).round() as u8))
        .collect();
    let film_image = gpu
        .upload_image(
            &ImageDesc::color(
                w,
                h,
                vk::Format::R8G8B8A8_UNORM,
                vk::ImageUsageFlags::SAMPLED,
            ),
            &[film],
            "host albedo (the film)",
        )
        .unwrap();
    let media = LayeredDesc::new(&scene).unwrap().unwrap().materials;
    assert_eq!(media.len(), 2);
    assert_eq!(*ids.iter().max().unwrap(), 2, "both media on screen");
    let shadow_desc = ShadowDesc::new(&scene, &settings.shadows, false).unwrap();
    let faces: Vec<ShadowFace> = shadow_desc
        .face_matrices(&scene, &lucent::gpu_scene::tiles::mesh_bounds(&scene))
        .into_iter()
        .map(ShadowFace::from)
        .collect();
    assert_eq!(
        faces.len(),
        8,
        "a point light's six faces, a spot's, a sun's"
    );
    let (aw, ah) = shadow_desc.extent();
    let object_ids = LayeredDesc::new(&scene).unwrap().unwrap().object_ids;
    let usage = vk::ImageUsageFlags::SAMPLED;
    let mut report = Vec::new();
    for (name, depth_kind, ids_kind, normals_kind, meshes_kind) in [
        (
            "D32, world RGBA16F normals, R8_UNORM IDs, interleaved vertices",
            HostDepth::Standard,
            HostIds::Unorm,
            HostNormals::WorldHalf,
            HostMeshes::Interleaved,
        ),
        (
            "reversed-Z infinite D32, view-space octahedral RG16 normals, R8_UINT IDs, two \
             vertex bindings and 16-bit indices",
            HostDepth::ReversedInfinite,
            HostIds::Uint,
            HostNormals::ViewOctahedralUnorm,
            HostMeshes::TwoBindings,
        ),
        (
            "D24S8 with IDs in stencil bits 4-7, world RGBA16_UNORM normals, no index buffer",
            HostDepth::D24Stencil,
            HostIds::Stencil,
            HostNormals::WorldUnorm,
            HostMeshes::NotIndexed,
        ),
        (
            "linear R32F depth, IDs in bits of a packed RGBA8 alpha, world octahedral RG32F \
             normals",
            HostDepth::Linear,
            HostIds::AlphaBits,
            HostNormals::WorldOctahedralFloat,
            HostMeshes::Interleaved,
        ),
    ] {
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
        assert!(capabilities(&desc).unwrap()[3].1.runs());
        let materials: Vec<LayeredMaterial> = media
            .iter()
            .enumerate()
            .map(|(k, m)| LayeredMaterial::new(host_id(ids_kind, k as u8 + 1), m.clone()))
            .collect();
        let buffers = MeshBuffers::new(&test, &scene, meshes_kind);
        let mut draws = buffers.draws(&scene, |k| host_id(ids_kind, object_ids[k]));
        if meshes_kind == HostMeshes::TwoBindings {
            // With the meshes' bounds the term's blur draws over the objects it acts on only:
            // the same frame.
            let bounds = lucent::gpu_scene::tiles::mesh_bounds(&scene);
            for (draw, object) in draws.iter_mut().zip(&scene.objects) {
                let (low, high) = bounds[object.mesh];
                *draw = draw.with_bounds(low, high);
            }
        }
        let lucent = wrap(&test, options(3));
        let mut effect = built(&test, &lucent, |u| {
            LayeredEffect::new(
                &lucent,
                u,
                LayeredEffectDesc::new(
                    desc.clone(),
                    materials,
                    buffers.layout,
                    vk::Extent2D {
                        width: aw,
                        height: ah,
                    },
                )
                .with_film(),
            )
        })
        .unwrap_or_else(|e| panic!("{name}: {e}"));
        let names: Vec<&str> = effect
            .plan()
            .passes
            .iter()
            .map(|p| p.name.as_str())
            .collect();
        assert_eq!(names[0], "light-space maps", "{names:?}");
        let frames = host_frames(
            &test,
            &layout,
            &desc,
            bytemuck::cast_slice(&without),
            |k, cmd, images| {
                effect
                    .record(
                        &lucent,
                        cmd,
                        &LayeredFrame {
                            slot: k,
                            view: 0,
                            camera: layout.camera,
                            lights: &scene.lights,
                            environment: Some(&scene.environment),
                            light_faces: &faces,
                            meshes: &draws,
                            images: LayeredImages {
                                depth: images.depth,
                                normals: &described(&normals, "host normals", usage),
                                material_ids: images.ids.unwrap(),
                                albedo: Some(&described(&film_image, "host albedo", usage)),
                            },
                            regions: &[],
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
                // Measured: no channel value off by more than 1/255 on any layout.
                0,
                &format!("{name}, frame {k}"),
                &format!("embed-layered-{k}"),
            ));
        }
        effect.destroy(&lucent);
        drop(lucent);
        gpu.destroy_image(normals);
        buffers.destroy(&test);
        layout.destroy(&test);
    }
    gpu.destroy_image(film_image);
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

#[test]
fn a_layered_description_missing_an_input_or_with_bad_meshes_is_a_typed_error() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(2));
    let gbuffer = GBufferDesc::new(
        64,
        48,
        lucent::embed::DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT))
    .with_normals(NormalDesc::world(vk::Format::R16G16B16A16_SFLOAT));
    let medium = LayeredDesc::new(&scene([0.3; 5]))
        .unwrap()
        .unwrap()
        .materials[0]
        .clone();
    let material = LayeredMaterial::new(7, medium.clone());
    let atlas = vk::Extent2D {
        width: 256,
        height: 256,
    };
    let build = |gbuffer: GBufferDesc, materials: Vec<LayeredMaterial>, vertices, atlas| {
        built(&test, &lucent, |u| {
            LayeredEffect::new(
                &lucent,
                u,
                LayeredEffectDesc::new(gbuffer, materials, vertices, atlas),
            )
        })
    };
    let interleaved = VertexLayout::interleaved(24, 0, 12);
    for (input, gbuffer) in [
        ("material IDs", changed(&gbuffer, |g| g.material_ids = None)),
        ("normals", changed(&gbuffer, |g| g.normals = None)),
    ] {
        let e = host_error(build(gbuffer, vec![material.clone()], interleaved, atlas));
        assert!(
            matches!(&e, HostError::Missing { input: i, .. } if i == input),
            "{input}: {e}"
        );
    }
    assert_eq!(Effect::ALL[3], Effect::LayeredMedia);
    // Vertex layouts: a normal past its stride, a format vertex buffers cannot hold, an
    // attribute in an unused binding.
    let vec3 = vk::Format::R32G32B32_SFLOAT;
    for (field, vertices) in [
        ("vertices.normal", VertexLayout::interleaved(20, 0, 12)),
        (
            "vertices.position",
            VertexLayout::new(
                [24, 0],
                VertexAttribute::new(0, vk::Format::R8G8B8A8_UNORM, 0),
                VertexAttribute::new(0, vec3, 12),
            ),
        ),
        (
            "vertices.normal",
            VertexLayout::new(
                [24, 0],
                VertexAttribute::new(0, vec3, 0),
                VertexAttribute::new(1, vec3, 0),
            ),
        ),
    ] {
        let e = host_error(build(
            gbuffer.clone(),
            vec![material.clone()],
            vertices,
            atlas,
        ));
        let named = match &e {
            HostError::Description { field: f, .. } => f == field,
            HostError::Unsupported { input, .. } => input == field,
            _ => false,
        };
        assert!(named, "{field}: {e}");
    }
    // No material; an ID twice; a depth-texture layer; an atlas out of range.
    assert!(build(gbuffer.clone(), vec![], interleaved, atlas).is_err());
    assert!(build(
        gbuffer.clone(),
        vec![material.clone(), material.clone()],
        interleaved,
        atlas
    )
    .is_err());
    let mut texdep = medium.clone();
    texdep.layers[0].thickness = lucent::embed::Thickness::Texture { scale: 1.0 };
    let e = host_error(build(
        gbuffer.clone(),
        vec![LayeredMaterial::new(7, texdep)],
        interleaved,
        atlas,
    ));
    assert!(matches!(e, HostError::Unsupported { .. }), "{e}");
    let tiny = vk::Extent2D {
        width: 8,
        height: 256,
    };
    assert!(build(gbuffer.clone(), vec![material.clone()], interleaved, tiny).is_err());

    // A built effect refuses a bad mesh before recording anything.
    let mut effect = build(gbuffer.clone(), vec![material], interleaved, atlas).unwrap();
    let usage = vk::ImageUsageFlags::SAMPLED;
    let depth = test
        .gpu
        .create_image(
            &ImageDesc::depth(64, 48, vk::Format::D32_SFLOAT, usage),
            "depth",
        )
        .unwrap();
    let normals = test
        .gpu
        .create_image(
            &ImageDesc::color(64, 48, vk::Format::R16G16B16A16_SFLOAT, usage),
            "normals",
        )
        .unwrap();
    let ids = test
        .gpu
        .create_image(&ImageDesc::color(64, 48, vk::Format::R8_UINT, usage), "ids")
        .unwrap();
    let lighting_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
    let lighting = test
        .gpu
        .create_image(
            &ImageDesc::color(64, 48, vk::Format::R16G16B16A16_SFLOAT, lighting_usage),
            "lighting",
        )
        .unwrap();
    let vertices = test
        .gpu
        .upload_buffer(&[0.0f32; 18], vk::BufferUsageFlags::VERTEX_BUFFER, "v")
        .unwrap();
    let good = MeshDraw::new(vertices.buffer, 3, Mat4::IDENTITY, 7);
    let changed_mesh = |change: &dyn Fn(&mut MeshDraw)| {
        let mut mesh = good;
        change(&mut mesh);
        mesh
    };
    let view = Mat4::look_at_rh(
        glam::Vec3::new(0.0, 0.0, 3.0),
        glam::Vec3::ZERO,
        glam::Vec3::Y,
    );
    let camera =
        lucent::embed::HostCamera::new(view, Mat4::perspective_rh(0.8, 64.0 / 48.0, 0.1, 20.0));
    for (problem, mesh) in [
        (
            "not finite",
            changed_mesh(&|m| m.transform = Mat4::from_scale(glam::Vec3::splat(f32::NAN))),
        ),
        ("not whole triangles", changed_mesh(&|m| m.count = 4)),
        (
            "null buffer",
            changed_mesh(&|m| m.vertex_buffers = [(vk::Buffer::null(), 0); 2]),
        ),
        (
            "8-bit indices",
            good.with_indices(IndexBuffer {
                buffer: vertices.buffer,
                offset: 0,
                index_type: vk::IndexType::UINT8_EXT,
            }),
        ),
    ] {
        let (d, n, i) = (
            described(&depth, "depth", usage),
            described(&normals, "normals", usage),
            described(&ids, "ids", usage),
        );
        let l = described(&lighting, "lighting", lighting_usage);
        let e = test.gpu.submit_and_wait(|cmd| {
            let result = effect.record(
                &lucent,
                cmd,
                &LayeredFrame {
                    slot: 0,
                    view: 0,
                    camera,
                    lights: &[],
                    environment: None,
                    light_faces: &[],
                    meshes: &[mesh],
                    images: LayeredImages {
                        depth: &d,
                        normals: &n,
                        material_ids: &i,
                        albedo: None,
                    },
                    regions: &[],
                    lighting: &l,
                },
            );
            let e = host_error(result);
            assert!(
                matches!(&e, HostError::Description { field, .. } if field == "meshes[0]"),
                "{problem}: {e}"
            );
        });
        e.unwrap();
    }
    effect.destroy(&lucent);
    drop(lucent);
    for image in [depth, normals, ids, lighting] {
        test.gpu.destroy_image(image);
    }
    test.gpu.destroy_buffer(vertices);
    test.finish();
}
