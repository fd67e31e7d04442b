//! The LEAN-mapping thesis's blurs (LCB, LBB, the two-pass bilateral blur) as a host's
//! `lucent::embed::SssEffect` against lucent's own frame of the same scene: the host's lit
//! diffuse and specular are lucent's lighting pass's, its normals lucent's GB1 re-encoded, its
//! shadow map lucent's light-space atlas with each face's matrices, its G-buffer in host layouts
//! (reversed-Z infinite depth with R8_UINT IDs and view-space octahedral normals, D24S8 with the
//! IDs in stencil bits, linear depth with the IDs in bits of a packed target). The effect builds
//! the LEAN target from the normals, blurs it with the light and relights the specular with the
//! host's lights: its output must be lucent's own frame.

use std::path::Path;

use crate::common::TestGpu;
use crate::embed::{
    built, compare_host_frame, described, host_error, host_frames, host_id, host_layout, options,
    tonemapped, wrap, HostDepth, HostIds,
};
use crate::embed_translucency::{normal_image, rgba8, HostNormals};
use crate::embed_transmission::{upload_host_shadow_map, upload_split_shadow_maps, HostShadowZ};

use ash::vk;
use lucent::backend::ImageDesc;
use lucent::embed::{
    capabilities, DepthDesc, DiffuseDesc, Effect, GBufferDesc, HostError, IdDesc, ImageState,
    LeanLighting, LeanSurface, LeanTargetImages, LeanTargetsDesc, NormalDesc, ShadowFace,
    SpecularSurface, SssEffect, SssEffectDesc, SssFrame, SssImages, SssMaterial,
};
use lucent::features::registry;
use lucent::features::shadows::ShadowDesc;
use lucent::features::sss::SssProfiles;
use lucent::frame::{FrameSettings, Renderer, Technique};
use lucent::scene::material::{SssProfile, Texturing};

/// A ball of skin and a slab of marble, glossy, lit by a sun and a point light that both cast
/// shadows, 1 unit = 20 mm, the profiles widened so the blur spans many pixels. A small grey
/// cube between the point light and the ball shadows the ball where the point light's
/// highlight is: the relit LEAN specular is shadowed there (with the point light's faces
/// cleared to depth 1 in the host's map the frames differ by 21/255 at 1,292 values), so the
/// comparisons see the host's shadow maps read.
fn scene() -> lucent::scene::Scene {
    let source = r#"name = "host-lean"
ambient = [0.03, 0.03, 0.03]
sky = [0.0, 0.0, 0.0]
[camera]
eye = [0.0, 0.6, 3.2]
target = [0.0, 0.0, 0.0]
fov_y_degrees = 40.0
[[mesh]]
name = "ball"
generator = "icosphere"
level = 3
[[mesh]]
name = "slab"
generator = "cube"
level = 2
[[material]]
name = "skin"
albedo = [0.85, 0.6, 0.5]
specular = 0.35
roughness = 0.35
[material.sss]
preset = "skin"
units_per_mm = 0.4
[[material]]
name = "marble"
albedo = [0.9, 0.9, 0.85]
specular = 0.6
roughness = 0.2
[material.sss]
preset = "marble"
units_per_mm = 0.4
[[material]]
name = "blocker"
albedo = [0.3, 0.3, 0.3]
specular = 0.0
[[object]]
mesh = "slab"
material = "blocker"
translate = [0.4, 0.5, 1.0]
scale = [0.06, 0.06, 0.06]
[[object]]
mesh = "ball"
material = "skin"
translate = [-0.35, 0.1, 0.3]
scale = [0.45, 0.45, 0.45]
[[object]]
mesh = "slab"
material = "marble"
translate = [0.3, -0.2, -0.3]
scale = [0.7, 0.5, 0.2]
[[light]]
type = "directional"
direction = [-0.5, -0.6, -0.6]
intensity = 2.5
[[light]]
type = "point"
position = [1.2, 0.9, 1.5]
intensity = 10.0
range = 50.0
"#;
    lucent::scene::file::parse_scene(Path::new("host-lean.toml"), source)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A host layout of the comparison: its name, depth, IDs and normals.
type Layout = (&'static str, HostDepth, HostIds, HostNormals);

/// The three layouts every LEAN blur is compared on.
const LAYOUTS: [Layout; 3] = [
    (
        "reversed-Z infinite D32, R8_UINT IDs, view-space octahedral RG16 normals",
        HostDepth::ReversedInfinite,
        HostIds::Uint,
        HostNormals::ViewOctahedralUnorm,
    ),
    (
        "D24S8 with IDs in stencil bits 4-7, world RGBA16F normals",
        HostDepth::D24Stencil,
        HostIds::Stencil,
        HostNormals::WorldHalf,
    ),
    (
        "linear R32F depth, IDs in bits of a packed RGBA8 alpha, world octahedral RG32F normals",
        HostDepth::Linear,
        HostIds::AlphaBits,
        HostNormals::WorldOctahedralFloat,
    ),
];

#[test]
fn the_lean_blurs_on_host_layouts_equal_lucents_own_lean_frames() {
    let test = TestGpu::new();
    let mut report = Vec::new();
    for blur in ["lbb", "lcb", "bilateral"] {
        compare_lean(
            &test,
            blur,
            Texturing::Pre,
            &LAYOUTS,
            Surface::Normals,
            &mut report,
        );
    }
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

/// A host whose G-buffer pass writes the LEAN targets itself (`GBufferDesc::with_lean_targets`:
/// here lucent's own, in the host's formats): no `sss lean in` pass, and the LEAN maps' spread
/// inside a pixel is kept, so the frame is lucent's own within 1/255 everywhere.
#[test]
fn the_lean_blurs_on_a_hosts_own_lean_targets_equal_lucents_own_lean_frames() {
    let test = TestGpu::new();
    let mut report = Vec::new();
    for blur in ["lbb", "lcb", "bilateral"] {
        compare_lean(
            &test,
            blur,
            Texturing::Pre,
            &LAYOUTS,
            Surface::Targets,
            &mut report,
        );
    }
    compare_lean(
        &test,
        "lbb",
        Texturing::Post,
        &LAYOUTS[1..2],
        Surface::Targets,
        &mut report,
    );
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

/// Where a host's LEAN blurs get their moments.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Surface {
    /// Made by the effect from the host's normals and each material's surface.
    Normals,
    /// The LEAN targets the host's G-buffer pass wrote.
    Targets,
}

/// The albedo after the scatter (`Texturing::Post`): the host's light holds the whole albedo,
/// the effect's LEAN pass divides it out before the blur (the `sss albedo in` it replaces) and
/// the final pass multiplies the host's albedo image back in.
#[test]
fn a_lean_blur_with_the_albedo_after_the_scatter_equals_lucents_own_frame() {
    let test = TestGpu::new();
    let mut report = Vec::new();
    compare_lean(
        &test,
        "lbb",
        Texturing::Post,
        &LAYOUTS[1..2],
        Surface::Normals,
        &mut report,
    );
    for line in &report {
        println!("{line}");
    }
    test.finish();
}

/// Renders `scene()` with `blur` and `texturing` in lucent's own frame and through a host's
/// `SssEffect` on each of `layouts` (three frames in flight, views recreated) with the LEAN
/// moments from `surface`, and compares them, pushing a line per frame into `report`.
fn compare_lean(
    test: &TestGpu,
    blur: &str,
    texturing: Texturing,
    layouts: &[Layout],
    surface: Surface,
    report: &mut Vec<String>,
) {
    let targets = surface == Surface::Targets;
    let gpu = &test.gpu;
    let (w, h) = (192, 144);
    let scene = scene();
    let exposure = f64::from(scene.exposure);
    let usage = vk::ImageUsageFlags::SAMPLED;
    {
        let mut settings = FrameSettings {
            technique: Technique::parse(blur).unwrap(),
            export_hdr: true,
            export_gbuffer: true,
            export_lit: true,
            export_shadows: true,
            ..FrameSettings::new(w, h)
        };
        settings.sss.texturing = Some(texturing);
        let renderer = Renderer::new(gpu, &test.shaders, &test.cache, &scene, settings)
            .unwrap_or_else(|e| panic!("{blur}: {e}"));
        let images = renderer.render_once(gpu).unwrap();
        let lit = renderer.read_lit(gpu).unwrap();
        let (sw, sh, shadow_depths) = renderer.read_shadow_map(gpu).unwrap();
        gpu.wait_idle().unwrap();
        renderer.destroy(gpu);
        let gb = images.gbuffer.unwrap();
        assert!(
            gb.lean.is_some(),
            "{blur}: lucent's frame has its LEAN target"
        );
        let want = tonemapped(&images.hdr.unwrap(), exposure);
        let ids: Vec<u8> = gb.sss.as_ref().unwrap().iter().map(|&v| v as u8).collect();

        // The blurred frame must differ from the lit one, or the comparison proves nothing;
        // and so must its specular (the LEAN specular is relit from the blurred moments).
        let unblurred: Vec<f32> = lit
            .diffuse
            .iter()
            .zip(&lit.specular)
            .flat_map(|(d, s)| [d[0] + s[0], d[1] + s[1], d[2] + s[2], 1.0])
            .collect();
        let plain = tonemapped(&unblurred, exposure);
        let changed = want
            .chunks_exact(4)
            .zip(plain.chunks_exact(4))
            .filter(|(a, b)| a.iter().zip(*b).any(|(x, y)| x.abs_diff(*y) > 4))
            .count();
        assert!(
            changed * 20 > (w * h) as usize,
            "{blur}: the blur changes only {changed} pixels"
        );

        // lucent's profiles in its ID order, each material's surface from the scene.
        let frame_profiles = SssProfiles::new(
            &scene,
            Some(registry::sss_blur(blur).unwrap()),
            None,
            Some(texturing),
            &registry::blur_of,
        )
        .unwrap()
        .unwrap();
        let surface_of = |k: u8| {
            let object = frame_profiles
                .object_ids
                .iter()
                .position(|&id| id == k)
                .expect("each profile is an object's");
            let m = &scene.objects[object].material;
            SpecularSurface::new(m.roughness, m.specular)
        };
        let profiles: Vec<SssProfile> = frame_profiles
            .profiles
            .iter()
            .map(|(p, b)| SssProfile {
                blur: Some(b.name().into()),
                ..p.clone()
            })
            .collect();
        let metres_per_unit = 1.0 / (1000.0 * profiles[0].units_per_mm);

        let faces: Vec<ShadowFace> = ShadowDesc::new(&scene, &settings.shadows, false)
            .unwrap()
            .face_matrices(&scene, &lucent::gpu_scene::tiles::mesh_bounds(&scene))
            .into_iter()
            .map(ShadowFace::from)
            .collect();
        assert_eq!(faces.len(), 7, "a sun's face and a point light's six");

        let rgba32 = |t: &[[f32; 4]], name| {
            gpu.upload_image(
                &ImageDesc::color(w, h, vk::Format::R32G32B32A32_SFLOAT, usage),
                &[bytemuck::cast_slice(t).to_vec()],
                name,
            )
            .unwrap()
        };
        // The host's light holds the whole albedo (lucent's leaves it out of a scattering
        // pixel's light when it goes after the scatter); its alpha is its own, or with LEAN
        // targets the LEAN slope x, as lucent's.
        let post = texturing != Texturing::Pre;
        let albedo_bytes = rgba8(&gb.gb0);
        let diffuse_rgb: Vec<[f32; 4]> = lit
            .diffuse
            .iter()
            .zip(albedo_bytes.chunks_exact(4))
            .zip(&ids)
            .map(|((d, a), &id)| {
                let f = |c: usize| {
                    if post && id > 0 {
                        f32::from(a[c]) / 255.0
                    } else {
                        1.0
                    }
                };
                let alpha = if targets { d[3] } else { 0.25 };
                [d[0] * f(0), d[1] * f(1), d[2] * f(2), alpha]
            })
            .collect();
        let albedo = gpu
            .upload_image(
                &ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
                &[albedo_bytes],
                "host albedo",
            )
            .unwrap();
        let diffuse = rgba32(&diffuse_rgb, "host diffuse");
        let specular = rgba32(&lit.specular, "host specular");
        // The LEAN targets as the host's G-buffer pass writes them: lucent's, the albedo and
        // specular intensity in the albedo image above.
        let moments = rgba32(gb.lean.as_ref().unwrap(), "host LEAN moments");
        let normal_roughness = rgba32(&gb.gb1, "host normal and roughness");

        for &(name, depth_kind, ids_kind, normals_kind) in layouts {
            // The reversed-Z G-buffer's host stores its shadow map reversed too, the
            // linear-depth one reversed with an infinite far plane.
            let shadow_z = match depth_kind {
                HostDepth::ReversedInfinite => HostShadowZ::Reversed,
                HostDepth::Linear => HostShadowZ::ReversedInfinite,
                _ => HostShadowZ::Standard,
            };
            // The D24S8 one keeps each face in a layer of an array; the reversed-Z one writing
            // its own LEAN targets keeps the point light's six faces (standard Z) in an array
            // beside its atlas of the sun's (a second map).
            let array = depth_kind == HostDepth::D24Stencil;
            let split = targets && depth_kind == HostDepth::ReversedInfinite;
            let (shadow_map, second) = if split {
                let maps = upload_split_shadow_maps(
                    test,
                    &shadow_depths,
                    (sw, sh),
                    &faces,
                    &scene.lights,
                    |l| matches!(l.kind, lucent::scene::LightKind::Point { .. }),
                    shadow_z,
                );
                (maps.0, Some(maps.1))
            } else {
                let map =
                    upload_host_shadow_map(test, &shadow_depths, (sw, sh), &faces, shadow_z, array);
                (map, None)
            };
            let mut layout = host_layout(
                test,
                depth_kind,
                ids_kind,
                w,
                h,
                &scene,
                &gb.depth,
                &ids,
                metres_per_unit,
            );
            if depth_kind == HostDepth::ReversedInfinite {
                // The same pixels as lucent's frame: its clip-space y convention.
                let mut projection = layout.camera.projection;
                projection.y_axis.y = -projection.y_axis.y;
                layout.camera = lucent::embed::HostCamera::new(layout.camera.view, projection);
            }
            let (normals, normal_desc) =
                normal_image(test, normals_kind, w, h, &gb.gb1, layout.camera.view);
            let mut desc = layout.desc.clone();
            desc = if targets {
                let float = vk::Format::R32G32B32A32_SFLOAT;
                desc.with_lean_targets(LeanTargetsDesc::new(
                    float,
                    vk::Format::R8G8B8A8_UNORM,
                    float,
                ))
            } else {
                desc.with_normals(normal_desc)
            };
            if post {
                desc = desc.with_albedo(vk::Format::R8G8B8A8_UNORM);
            }
            assert!(capabilities(&desc).unwrap()[5].1.runs(), "{name}");
            let materials: Vec<SssMaterial> = profiles
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    let k = i as u8 + 1;
                    let material = SssMaterial::new(host_id(ids_kind, k), p.clone());
                    // With LEAN targets the surface is theirs.
                    if targets {
                        material
                    } else {
                        material.with_surface(surface_of(k))
                    }
                })
                .collect();
            let lucent = wrap(test, options(3));
            let effect_desc =
                SssEffectDesc::new(desc.clone(), materials, vk::Format::R32G32B32A32_SFLOAT)
                    .with_knobs(settings.sss)
                    .with_shadow_maps(vk::Format::D32_SFLOAT);
            let effect_desc = if array {
                effect_desc.with_shadow_array()
            } else if split {
                effect_desc.with_second_shadow_map(vk::Format::D32_SFLOAT)
            } else {
                effect_desc
            };
            let mut effect = built(test, &lucent, |u| SssEffect::new(&lucent, u, effect_desc))
                .unwrap_or_else(|e| panic!("{blur} on {name}: {e}"));
            let normals_host = described(&normals, "host normals", usage);
            let diffuse_host = described(&diffuse, "host diffuse", usage);
            let specular_host = described(&specular, "host specular", usage);
            let albedo_host = described(&albedo, "host albedo", usage);
            let moments_host = described(&moments, "host LEAN moments", usage);
            let normal_roughness_host =
                described(&normal_roughness, "host normal and roughness", usage);
            let lean_surface = if targets {
                LeanSurface::Targets(LeanTargetImages {
                    moments: &moments_host,
                    albedo_specular: &albedo_host,
                    normal_roughness: &normal_roughness_host,
                })
            } else {
                LeanSurface::Normals(&normals_host)
            };
            // The frames' output is host_frames' lighting image (its start is overwritten).
            let frames = host_frames(
                test,
                &layout,
                &desc,
                bytemuck::cast_slice(&diffuse_rgb),
                |k, cmd, images| {
                    let output = images.lighting.clone().in_state(ImageState::UNDEFINED);
                    effect
                        .record(
                            &lucent,
                            cmd,
                            &SssFrame {
                                slot: k,
                                view: 0,
                                camera: layout.camera,
                                images: SssImages {
                                    depth: images.depth,
                                    diffuse: &diffuse_host,
                                    specular: Some(&specular_host),
                                    albedo: post.then_some(&albedo_host),
                                    material_ids: images.ids.unwrap(),
                                },
                                regions: &[],
                                output: &output,
                                lean: Some(LeanLighting {
                                    surface: lean_surface,
                                    lights: &scene.lights,
                                    shadow_map: Some(&shadow_map.host),
                                    second_shadow_map: second.as_ref().map(|array| &array.host),
                                    shadow_faces: &shadow_map.faces,
                                }),
                            },
                        )
                        .unwrap_or_else(|e| panic!("{blur} on {name}: {e}"));
                },
            );
            for (k, texels) in frames.iter().enumerate() {
                let have = tonemapped(texels, exposure);
                // The normals come re-encoded (octahedral, 16-bit) and the positions through
                // another depth: the LEAN slopes move by a hair, and the specular with them
                // where it is steep. At most 0.1% of the channel values over 1/255. The
                // host's own LEAN targets are lucent's: none.
                let over = if targets { 0 } else { want.len() / 1000 };
                let source = if targets { "targets" } else { "normals" };
                report.push(compare_host_frame(
                    &want,
                    &have,
                    (w, h),
                    over,
                    &format!(
                        "{blur} ({}, from {source}) on {name}, frame {k}",
                        texturing.name()
                    ),
                    &format!("embed-lean-{blur}-{}-{source}-{k}", texturing.name()),
                ));
            }
            effect.destroy(&lucent);
            drop(lucent);
            gpu.destroy_image(normals);
            gpu.destroy_image(shadow_map.image);
            if let Some(array) = second {
                gpu.destroy_image(array.image);
            }
            layout.destroy(test);
        }
        gpu.destroy_image(diffuse);
        gpu.destroy_image(specular);
        gpu.destroy_image(albedo);
        gpu.destroy_image(moments);
        gpu.destroy_image(normal_roughness);
    }
}

#[test]
fn a_lean_blur_without_normals_a_surface_or_its_lighting_is_a_typed_error() {
    let test = TestGpu::new();
    let lucent = wrap(&test, options(2));
    let gbuffer = GBufferDesc::new(
        64,
        48,
        DepthDesc::device(vk::Format::D32_SFLOAT),
        DiffuseDesc::with_albedo(vk::Format::R16G16B16A16_SFLOAT),
    )
    .with_material_ids(IdDesc::value(vk::Format::R8_UINT));
    let lbb = |surface: bool| {
        let profile = SssProfile {
            blur: Some("lbb".into()),
            texturing: Texturing::Pre,
            ..SssProfile::preset("skin").unwrap()
        };
        let material = SssMaterial::new(1, profile);
        if surface {
            material.with_surface(SpecularSurface::new(0.4, 0.3))
        } else {
            material
        }
    };
    let format = vk::Format::R16G16B16A16_SFLOAT;
    let build = |desc: SssEffectDesc| built(&test, &lucent, |u| SssEffect::new(&lucent, u, desc));
    // No normals in the description: what capabilities says too.
    let e = host_error(build(SssEffectDesc::new(
        gbuffer.clone(),
        vec![lbb(true)],
        format,
    )));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input == "normals"),
        "{e}"
    );
    let Some((Effect::LeanSss, support)) = capabilities(&gbuffer).unwrap().get(5).cloned() else {
        panic!("the LEAN blurs' entry")
    };
    assert!(!support.runs());
    let with_normals = gbuffer
        .clone()
        .with_normals(NormalDesc::world(vk::Format::A2B10G10R10_UNORM_PACK32));
    // A LEAN blur without a surface; a surface with a blur that keeps the host's specular; a
    // roughness out of range; a shadow format without a LEAN blur, and one that is not depth.
    let e = host_error(build(SssEffectDesc::new(
        with_normals.clone(),
        vec![lbb(false)],
        format,
    )));
    assert!(
        matches!(&e, HostError::Missing { input, .. } if input.ends_with(".surface")),
        "{e}"
    );
    let separable = SssMaterial::new(
        1,
        SssProfile {
            blur: Some("separable".into()),
            texturing: Texturing::Pre,
            ..SssProfile::preset("skin").unwrap()
        },
    );
    let e = host_error(build(SssEffectDesc::new(
        with_normals.clone(),
        vec![separable
            .clone()
            .with_surface(SpecularSurface::new(0.4, 0.3))],
        format,
    )));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input.ends_with(".surface")),
        "{e}"
    );
    let rough =
        SssMaterial::new(1, lbb(false).profile).with_surface(SpecularSurface::new(1.5, 0.3));
    let e = host_error(build(SssEffectDesc::new(
        with_normals.clone(),
        vec![rough],
        format,
    )));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field.ends_with("roughness")),
        "{e}"
    );
    let e = host_error(build(
        SssEffectDesc::new(with_normals.clone(), vec![separable], format)
            .with_shadow_maps(vk::Format::D32_SFLOAT),
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "shadow map"),
        "{e}"
    );
    let e = host_error(build(
        SssEffectDesc::new(with_normals.clone(), vec![lbb(true)], format).with_shadow_array(),
    ));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field == "shadow_array"),
        "{e}"
    );
    let e = host_error(build(
        SssEffectDesc::new(with_normals.clone(), vec![lbb(true)], format)
            .with_shadow_maps(vk::Format::R32_SFLOAT),
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "shadow map"),
        "{e}"
    );
    // A second shadow map without a first, or beside a first that is an array.
    let second = SssEffectDesc::new(with_normals.clone(), vec![lbb(true)], format)
        .with_second_shadow_map(vk::Format::D32_SFLOAT);
    let e = host_error(build(second.clone()));
    assert!(
        matches!(&e, HostError::Description { field, .. } if field == "second_shadow_format"),
        "{e}"
    );
    let e = host_error(build(
        second
            .with_shadow_maps(vk::Format::D32_SFLOAT)
            .with_shadow_array(),
    ));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "second shadow map"),
        "{e}"
    );
    // Built right, it has its LEAN pass.
    let effect = build(SssEffectDesc::new(with_normals, vec![lbb(true)], format)).unwrap();
    let passes = pass_names(&effect);
    assert!(passes.iter().any(|p| p == "sss lean in"), "{passes:?}");
    effect.destroy(&lucent);

    // The host's own LEAN targets: no normals needed, no surface taken (the targets hold the
    // roughness and specular), each target's format checked, the diffuse's alpha a float.
    let (rgba16f, rgba8) = (format, vk::Format::R8G8B8A8_UNORM);
    let with_targets = gbuffer
        .clone()
        .with_lean_targets(LeanTargetsDesc::new(rgba16f, rgba8, rgba16f));
    assert!(capabilities(&with_targets).unwrap()[5].1.runs());
    let e = host_error(build(SssEffectDesc::new(
        with_targets.clone(),
        vec![lbb(true)],
        format,
    )));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input.ends_with(".surface")),
        "{e}"
    );
    for (targets, input) in [
        (
            LeanTargetsDesc::new(rgba8, rgba8, rgba16f),
            "lean targets: moments",
        ),
        (
            LeanTargetsDesc::new(rgba16f, vk::Format::R8G8_UNORM, rgba16f),
            "lean targets: albedo and specular",
        ),
        (
            LeanTargetsDesc::new(rgba16f, rgba8, rgba8),
            "lean targets: normal and roughness",
        ),
    ] {
        let e = host_error(build(SssEffectDesc::new(
            gbuffer.clone().with_lean_targets(targets),
            vec![lbb(false)],
            format,
        )));
        assert!(
            matches!(&e, HostError::Unsupported { input: i, .. } if i == input),
            "{e}"
        );
    }
    let mut packed_light = with_targets.clone();
    packed_light.diffuse = DiffuseDesc::with_albedo(vk::Format::B10G11R11_UFLOAT_PACK32);
    let e = host_error(build(SssEffectDesc::new(
        packed_light,
        vec![lbb(false)],
        format,
    )));
    assert!(
        matches!(&e, HostError::Unsupported { input, .. } if input == "diffuse"),
        "{e}"
    );
    // Built right, it reads the targets as they are: no LEAN pass of its own, the LEAN
    // final lighting.
    let effect = build(SssEffectDesc::new(with_targets, vec![lbb(false)], format)).unwrap();
    let passes = pass_names(&effect);
    assert!(!passes.iter().any(|p| p == "sss lean in"), "{passes:?}");
    assert!(passes.iter().any(|p| p == "final lighting"), "{passes:?}");
    effect.destroy(&lucent);
    drop(lucent);
    test.finish();
}

/// The names of the passes `effect` records.
fn pass_names(effect: &SssEffect) -> Vec<String> {
    effect
        .plan()
        .passes
        .iter()
        .map(|p| p.name.clone())
        .collect()
}
