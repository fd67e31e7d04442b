//! `lucent bench --embed`: what an effect costs in a host's frame against the same work in
//! lucent's own frame, measured in one run with frames alternating.
//!
//! lucent's own frame of the scene is rendered once to export what a host's G-buffer would
//! hold (depth, lit diffuse and specular, albedo, normals, thickness, material IDs); those
//! become host images in a host's formats, and the effect (`lucent::embed`) is built on the
//! same device through the public API. Then, frame by frame, lucent's own frame and the
//! host's effect alone are each submitted and timed with GPU timestamps; the table gives each
//! pass's median in both and their ratio.
//!
//! - **Screen-space SSS** (`--technique separable|control|burley|lcb|lbb|bilateral`): each
//!   pass of the `SssEffect` (its regions the scattering objects' screen bounds widened by the blurs'
//!   reach; its diffuse with linear depth in the alpha where lucent's own frame has it)
//!   against lucent's pass of the same name (the host's diffuse and
//!   specular in RGBA16F, lucent's own HDR format; its depth D32; its IDs R8_UNORM). The
//!   host's diffuse is lucent's as its lighting pass writes it for the scene's own texturing
//!   (`DiffuseAlbedo::AsTexturing`), with GB0 as the albedo image where a profile applies
//!   the albedo after the scatter; each material at its own profile's scale
//!   (`SssMaterial::with_metres_per_unit`). For the
//!   LEAN blurs (`lcb|lbb|bilateral`) the host writes the LEAN targets as lucent's G-buffer
//!   pass does (`GBufferDesc::with_lean_targets`: lucent's own targets, uploaded once).
//! - **SSS transmission** (with an SSS blur, on a scene with a `[material.medium]` and a
//!   light casting shadows): lucent's term inside its lighting pass (the lighting with
//!   transmission minus without) against the `TransmissionEffect`'s pass over the media's
//!   screen bounds, its shadow map lucent's own atlas with each face as a host describes it;
//!   rows `transmission: ...` after the blur's.
//! - **The SH environment** (`--technique none`, plain lighting, whose ambient term is what a
//!   host inserts of it): lucent's ambient inside its lighting pass is the lighting pass with
//!   the scene's environment minus the lighting pass with none, against the
//!   `EnvironmentEffect`'s one pass over the whole screen.
//! - **Li et al.'s layered media** (`--technique layered`): each pass of the `LayeredEffect`
//!   (its light-space maps drawn from the scene's meshes in host vertex and index buffers, its
//!   regions the layered objects' screen bounds, its faces lucent's own) against lucent's pass
//!   of the same name.
//! - **GDC 2011 translucency** (`--technique translucency`): lucent adds the term inside its
//!   lighting pass, so its cost there is the lighting pass with translucency minus the
//!   lighting pass without (`none`, a third frame in the rotation, lighting unmerged as
//!   `report`'s GDC table measures it), against the `TranslucencyEffect`'s one pass, drawn
//!   over the translucent objects' screen bounds (`TranslucencyFrame::regions`, from
//!   `embed::screen_region`, as a host gives them).
//!
//! For the three lighting terms (translucency, the environment, the transmission) the table
//! also times a host's own lighting pass that adds the term through
//! `lucent::embed::glsl::TERMS` ([`crate::measure::host_lighting`]), with and without it, and
//! sets the difference beside lucent's own term: what the term costs a host that fuses it, as
//! docs/embedding.md recommends.

use std::collections::BTreeMap;

use ash::vk;

use crate::backend::shader::{PipelineCache, ShaderCompiler};
use crate::backend::{GpuContext, GpuImage, ImageDesc};
use crate::embed::{
    DepthDesc, DiffuseDesc, EffectMemory, EffectTimer, EmbedOptions, EnvironmentEffect,
    EnvironmentEffectDesc, EnvironmentFrame, EnvironmentImages, GBufferDesc, HostCamera,
    HostDevice, HostImage, IdDesc, ImageState, IndexBuffer, LayeredEffect, LayeredEffectDesc,
    LayeredFrame, LayeredImages, LayeredMaterial, LeanLighting, LeanSurface, LeanTargetImages,
    LeanTargetsDesc, Lucent, MeshDraw, NormalDesc, OptionalFeatures, ShadowFace, SssEffect,
    SssEffectDesc, SssFrame, SssImages, SssMaterial, SssRegion, ThicknessDesc, TranslucencyEffect,
    TranslucencyEffectDesc, TranslucencyFrame, TranslucencyImages, TranslucentMaterial,
    TransmissionEffect, TransmissionEffectDesc, TransmissionFrame, TransmissionImages,
    TransmissionMaterial, VertexLayout,
};
use crate::features::registry;
use crate::features::sss::SssProfiles;
use crate::features::technique::TechniqueModule;
use crate::frame::{FrameSettings, Renderer, Technique};
use crate::measure::host_lighting::{self, HostLighting, HostLightingFrame, TermData};
use crate::measure::stats::Stats;
use crate::scene::material::Texturing;
use crate::scene::Scene;
use crate::{LucentError, Result};

/// One pass: its median in lucent's frame and in the host's.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EmbedCostRow {
    /// The pass (for translucency: the term, and the lighting passes it is measured from).
    pub pass: String,
    /// Median milliseconds in lucent's own frame (`None`: the pass is not in it).
    pub lucent_ms: Option<f64>,
    /// Median milliseconds as the host's effect (`None`: the effect has no such pass).
    pub host_ms: Option<f64>,
}

/// What `lucent bench --embed` prints.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EmbedCost {
    /// The device.
    pub device: String,
    /// Scene, size, effect, frames.
    pub setup: String,
    /// Per pass.
    pub rows: Vec<EmbedCostRow>,
    /// What each effect measured held in memory ([`EffectMemory`]), by its type.
    #[serde(skip)]
    pub memory: Vec<(&'static str, EffectMemory)>,
}

impl EmbedCost {
    /// A Markdown table: pass, lucent's frame, the host's effect, host / lucent.
    pub fn markdown(&self) -> String {
        let mut out = format!(
            "**The effect in a host's frame against lucent's own** ({}; {}; GPU timestamps, \
             medians)\n\n| pass | lucent's frame (ms) | host effect (ms) | host / lucent |\n\
             |---|---:|---:|---:|\n",
            self.device, self.setup
        );
        let ms = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.3}"));
        for row in &self.rows {
            let ratio = match (row.lucent_ms, row.host_ms) {
                (Some(a), Some(b)) if a > 0.0 => format!("{:.3}", b / a),
                _ => "-".into(),
            };
            out.push_str(&format!(
                "| {} | {} | {} | {ratio} |\n",
                row.pass,
                ms(row.lucent_ms),
                ms(row.host_ms)
            ));
        }
        for (effect, memory) in &self.memory {
            out.push_str(&format!(
                "\n{effect} holds {:.2} MiB of intermediate images and {:.1} KiB of per-frame \
                 parameters (`memory()`).\n",
                memory.images as f64 / (1024.0 * 1024.0),
                memory.parameters as f64 / 1024.0
            ));
        }
        out
    }
}

/// The host's handles of `gpu`: lucent borrows its own device as a host's.
fn host_device(gpu: &GpuContext) -> HostDevice {
    HostDevice {
        entry: gpu.entry.clone(),
        instance: gpu.instance.clone(),
        physical_device: gpu.physical_device,
        device: gpu.device.clone(),
        queue: gpu.queue,
        queue_family: gpu.queue_family,
        enabled: OptionalFeatures {
            host_query_reset: gpu.info.host_query_reset,
            storage_image_write_without_format: gpu.info.storage_image_write_without_format,
        },
    }
}

/// Medians of named samples.
#[derive(Default)]
struct Samples(BTreeMap<String, Vec<f64>>);

impl Samples {
    fn push(&mut self, name: &str, ms: f64) {
        self.0.entry(name.to_string()).or_default().push(ms);
    }

    fn median(&self, name: &str) -> Option<f64> {
        self.0.get(name).map(|v| Stats::of(v).median)
    }
}

/// Measures the effect of `technique` (an SSS blur a host can run, `translucency`, `layered`,
/// or `none` for the SH environment) on
/// `scene` at `width` x `height`: `warmup` rounds discarded, `frames` measured.
#[allow(clippy::too_many_arguments)]
pub fn embed_cost(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    scene: &Scene,
    scene_label: &str,
    technique: Technique,
    (width, height): (u32, u32),
    (frames, warmup): (usize, usize),
) -> Result<EmbedCost> {
    let module = technique.module();
    let translucency =
        module.is_some_and(|m| m.name() == crate::features::translucency::TRANSLUCENCY.name());
    // `none`, plain lighting: what a host inserts of it is the SH environment's light.
    let environment = matches!(technique, Technique::None);
    let layered = module.is_some_and(|m| m.name() == crate::features::layered::LAYERED.name());
    let blur = module.and_then(|m| registry::sss_blurs().find(|b| b.name() == m.name()));
    if !translucency && !environment && !layered && blur.is_none() {
        let blurs: Vec<&str> = registry::sss_blurs().map(|b| b.name()).collect();
        return Err(LucentError::InvalidInput(format!(
            "--embed measures an effect a host can insert: --technique {}, translucency, \
             layered or none (the SH environment) (not '{}')",
            blurs.join(", "),
            technique.name()
        )));
    }
    // SAFETY: the handles are `gpu`'s own, valid until it is dropped, after `lucent`.
    let lucent = unsafe {
        Lucent::new(
            host_device(gpu),
            EmbedOptions {
                frames_in_flight: 1,
                ..Default::default()
            },
        )
    }?;
    let setup = format!(
        "`{scene_label}`, {width}x{height}, {} as `{}`, {frames} frames after {warmup}, \
         alternating",
        if translucency {
            "TranslucencyEffect"
        } else if environment {
            "EnvironmentEffect"
        } else if layered {
            "LayeredEffect"
        } else {
            "SssEffect"
        },
        technique.name()
    );
    let mut memory = Vec::new();
    let rows = if layered {
        measure_layered(
            gpu,
            shaders,
            pipeline_cache,
            &lucent,
            scene,
            technique,
            (width, height),
            (frames, warmup),
            &mut memory,
        )
    } else if environment {
        measure_environment(
            gpu,
            shaders,
            pipeline_cache,
            &lucent,
            scene,
            (width, height),
            (frames, warmup),
            &mut memory,
        )
    } else if translucency {
        measure_translucency(
            gpu,
            shaders,
            pipeline_cache,
            &lucent,
            scene,
            (width, height),
            (frames, warmup),
            &mut memory,
        )
    } else {
        measure_sss(
            gpu,
            shaders,
            pipeline_cache,
            &lucent,
            scene,
            technique,
            (width, height),
            (frames, warmup),
            &mut memory,
        )
    };
    // An SSS blur on a scene with media also times their transmission.
    let rows = match (rows, blur.is_some()) {
        (Ok(mut rows), true) => measure_transmission(
            gpu,
            shaders,
            pipeline_cache,
            &lucent,
            scene,
            technique,
            (width, height),
            (frames, warmup),
            &mut memory,
        )
        .map(|more| {
            rows.extend(more.unwrap_or_default());
            rows
        }),
        (rows, _) => rows,
    };
    let idle = gpu.wait_idle();
    drop(lucent);
    idle?;
    Ok(EmbedCost {
        device: gpu.info.describe(),
        setup,
        rows: rows?,
        memory,
    })
}

/// lucent's light-space atlas of `renderer`'s last frame (its scene's `shadows`) as a host's
/// shadow map: uploaded into `images`, with each face's matrices as a host gives them
/// ([`crate::features::shadows::ShadowDesc::face_matrices`]).
fn atlas_as_host_map(
    gpu: &GpuContext,
    renderer: &Renderer,
    scene: &Scene,
    shadows: &crate::features::shadows::ShadowDesc,
    images: &mut Images,
) -> Result<(HostImage, Vec<ShadowFace>)> {
    let faces: Vec<ShadowFace> = shadows
        .face_matrices(scene, &crate::gpu_scene::tiles::mesh_bounds(scene))
        .into_iter()
        .map(ShadowFace::from)
        .collect();
    let (width, height, depths) = renderer.read_shadow_map(gpu)?;
    let sampled = vk::ImageUsageFlags::SAMPLED;
    let map = images.upload(
        gpu,
        &ImageDesc::depth(width, height, vk::Format::D32_SFLOAT, sampled),
        bytemuck::cast_slice(&depths).to_vec(),
        "host shadow map",
    )?;
    let map = host_image(
        map,
        "host shadow map",
        vk::Format::D32_SFLOAT,
        (width, height),
        sampled,
    );
    Ok((map, faces))
}

/// The images of one measurement, destroyed together.
#[derive(Default)]
struct Images(Vec<GpuImage>);

impl Images {
    fn upload(
        &mut self,
        gpu: &GpuContext,
        desc: &ImageDesc,
        bytes: Vec<u8>,
        name: &str,
    ) -> Result<(vk::Image, vk::ImageView)> {
        let image = gpu.upload_image(desc, &[bytes], name)?;
        let handles = (image.image, image.view);
        self.0.push(image);
        Ok(handles)
    }

    fn destroy(self, gpu: &GpuContext) {
        for image in self.0 {
            gpu.destroy_image(image);
        }
    }
}

fn rgba8(texels: &[[f32; 4]]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8))
        .collect()
}

fn rgba16f(texels: &[[f32; 4]]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.map(|v| half::f16::from_f32(v).to_le_bytes()))
        .flatten()
        .collect()
}

fn host_image(
    (image, view): (vk::Image, vk::ImageView),
    name: &str,
    format: vk::Format,
    (width, height): (u32, u32),
    usage: vk::ImageUsageFlags,
) -> HostImage {
    HostImage::new(
        name,
        image,
        view,
        format,
        vk::Extent2D { width, height },
        usage,
    )
    .in_state(ImageState::fragment_sampled())
}

/// Records `record` into a command buffer, submits it and waits: the host's frame.
fn host_frame(
    gpu: &GpuContext,
    record: impl FnOnce(vk::CommandBuffer) -> Result<()>,
) -> Result<()> {
    let mut recorded = Ok(());
    gpu.submit_and_wait(|cmd| recorded = record(cmd))?;
    recorded
}

#[allow(clippy::too_many_arguments)]
fn measure_sss(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    lucent: &Lucent,
    scene: &Scene,
    technique: Technique,
    (width, height): (u32, u32),
    (frames, warmup): (usize, usize),
    memory: &mut Vec<(&'static str, EffectMemory)>,
) -> Result<Vec<EmbedCostRow>> {
    let module = technique.module().expect("checked by the caller");
    let blur = registry::sss_blur(module.name())?;
    let settings = FrameSettings {
        technique,
        export_gbuffer: true,
        export_lit: true,
        // The LEAN blurs' specular is shadowed: the host's shadow map is lucent's atlas.
        export_shadows: blur.lean(),
        ..FrameSettings::new(width, height)
    };
    let renderer = Renderer::new(gpu, shaders, pipeline_cache, scene, settings)?;
    let mut images = Images::default();
    let measured = (|| {
        renderer.render_once(gpu)?;
        let gb = renderer.read_gbuffer(gpu)?;
        let lit = renderer.read_lit(gpu)?;
        let ids: Vec<u8> = gb
            .sss
            .as_ref()
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "--embed with --technique {}: the scene has no screen-space SSS material",
                    module.name()
                ))
            })?
            .iter()
            .map(|&v| v as u8)
            .collect();
        let frame_profiles =
            SssProfiles::new(scene, Some(blur), None, None, &registry::blur_of)?
                .ok_or_else(|| LucentError::InvalidInput("the scene has no SSS profile".into()))?;
        // lucent's lighting pass writes linear depth in the diffuse's alpha for the blurs
        // that read it there; the host's light then holds it too (the export keeps it).
        let depth_in_alpha = frame_profiles.depth_in_alpha();
        let profiles: Vec<_> = frame_profiles
            .profiles
            .into_iter()
            .map(|(mut p, b)| {
                p.blur = Some(b.name().into());
                p
            })
            .collect();
        // lucent's lighting pass writes each SSS pixel's light with the albedo as its
        // profile's texturing asks (the host describes its light so), and the blurs apply
        // the rest of the albedo from GB0 after the scatter.
        let post_albedo = profiles.iter().any(|p| p.texturing != Texturing::Pre);
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let size = (width, height);
        let hdr = vk::Format::R16G16B16A16_SFLOAT;
        let depth = images.upload(
            gpu,
            &ImageDesc::depth(width, height, vk::Format::D32_SFLOAT, sampled),
            bytemuck::cast_slice(&gb.depth).to_vec(),
            "host depth",
        )?;
        let id_image = images.upload(
            gpu,
            &ImageDesc::color(width, height, vk::Format::R8_UNORM, sampled),
            ids,
            "host IDs",
        )?;
        let colour = ImageDesc::color(width, height, hdr, sampled);
        let diffuse = images.upload(gpu, &colour, rgba16f(&lit.diffuse), "host diffuse")?;
        let specular = images.upload(gpu, &colour, rgba16f(&lit.specular), "host specular")?;
        let output_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let output = images.upload(
            gpu,
            &ImageDesc::color(width, height, hdr, output_usage),
            rgba16f(&lit.diffuse),
            "host output",
        )?;
        let diffuse_desc = DiffuseDesc::with_albedo_as_texturing(hdr);
        let mut gbuffer = GBufferDesc::new(
            width,
            height,
            DepthDesc::device(vk::Format::D32_SFLOAT),
            if depth_in_alpha {
                diffuse_desc.with_depth_in_alpha()
            } else {
                diffuse_desc
            },
        )
        .with_specular(hdr)
        .with_material_ids(IdDesc::value(vk::Format::R8_UNORM));
        // GB0 (albedo and specular intensity), uploaded once: the albedo the blurs apply after
        // the scatter, and the LEAN blurs' albedo and specular target.
        let gb0 = vk::Format::R8G8B8A8_UNORM;
        let gb0_image = (post_albedo || blur.lean())
            .then(|| {
                images.upload(
                    gpu,
                    &ImageDesc::color(width, height, gb0, sampled),
                    rgba8(&gb.gb0),
                    "host GB0",
                )
            })
            .transpose()?;
        if post_albedo {
            gbuffer = gbuffer.with_albedo(gb0);
        }
        let albedo_image = gb0_image
            .filter(|_| post_albedo)
            .map(|image| host_image(image, "host albedo", gb0, size, sampled));
        // The LEAN blurs: the host writes the LEAN targets in its G-buffer pass as lucent's
        // own frame does (lucent's targets; the diffuse's alpha holds the slope x), with the
        // scene's lights and, where they cast, lucent's light-space atlas with each face's
        // matrices.
        let lean = if blur.lean() {
            gbuffer = gbuffer.with_lean_targets(LeanTargetsDesc::new(hdr, gb0, hdr));
            let moments = gb.lean.as_deref().ok_or_else(|| {
                LucentError::InvalidInput("lucent's LEAN frame has no LEAN target".into())
            })?;
            let moments = images.upload(gpu, &colour, rgba16f(moments), "host LEAN moments")?;
            let albedo = gb0_image.expect("uploaded for the LEAN blurs");
            let normal = images.upload(gpu, &colour, rgba16f(&gb.gb1), "host normal")?;
            let targets = [
                host_image(moments, "host LEAN moments", hdr, size, sampled),
                host_image(albedo, "host albedo and specular", gb0, size, sampled),
                host_image(normal, "host normal and roughness", hdr, size, sampled),
            ];
            let shadows =
                crate::features::shadows::ShadowDesc::new(scene, &settings.shadows, false)
                    .map(|desc| atlas_as_host_map(gpu, &renderer, scene, &desc, &mut images))
                    .transpose()?;
            Some((targets, shadows))
        } else {
            None
        };
        // (The LEAN blurs' surfaces are the targets' roughness and specular intensity.) Each
        // material at its own profile's scale, as the scene's materials are.
        let materials = profiles
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                let metres_per_unit = 1.0 / (1000.0 * p.units_per_mm);
                SssMaterial::new(i as u8 + 1, p).with_metres_per_unit(metres_per_unit)
            })
            .collect();
        let mut desc = SssEffectDesc::new(gbuffer, materials, hdr).with_knobs(settings.sss);
        if let Some((_, Some(_))) = &lean {
            desc = desc.with_shadow_maps(vk::Format::D32_SFLOAT);
        }
        let mut effect = build(gpu, lucent, |u| SssEffect::new(lucent, u, desc))?;
        memory.push(("SssEffect", effect.memory()));
        let camera = HostCamera::new(
            scene.camera.view(),
            scene.camera.projection(width as f32 / height as f32),
        );
        // Each scattering object's screen bounds widened by its own profile's reach (its host
        // ID is its profile number), given for its material: each blur chain draws on its own
        // objects' tiles, as lucent's own frame does.
        let object_id = |i: usize| frame_profiles.object_ids.get(i).copied().unwrap_or(0);
        let regions: Vec<SssRegion> =
            object_regions_each(scene, &camera, (width, height), |i, _| {
                let id = object_id(i);
                effect.reach_of(id).filter(|_| id > 0)
            })
            .into_iter()
            .map(|(i, rect)| SssRegion::of(object_id(i), rect))
            .collect();
        let depth = host_image(depth, "host depth", vk::Format::D32_SFLOAT, size, sampled);
        let diffuse = host_image(diffuse, "host diffuse", hdr, size, sampled);
        let specular = host_image(specular, "host specular", hdr, size, sampled);
        let id_image = host_image(id_image, "host IDs", vk::Format::R8_UNORM, size, sampled);
        let output = host_image(output, "host output", hdr, size, output_usage)
            .in_state(ImageState::UNDEFINED)
            .then(ImageState::fragment_sampled());
        let rows = time_passes(gpu, lucent, &renderer, (frames, warmup), |cmd, timer| {
            effect.record_timed(
                lucent,
                cmd,
                &SssFrame {
                    slot: 0,
                    view: 0,
                    camera,
                    images: SssImages {
                        depth: &depth,
                        diffuse: &diffuse,
                        specular: Some(&specular),
                        albedo: albedo_image.as_ref(),
                        material_ids: &id_image,
                    },
                    regions: &regions,
                    output: &output,
                    lean: lean.as_ref().map(|(targets, shadows)| LeanLighting {
                        surface: LeanSurface::Targets(LeanTargetImages {
                            moments: &targets[0],
                            albedo_specular: &targets[1],
                            normal_roughness: &targets[2],
                        }),
                        lights: &scene.lights,
                        shadow_map: shadows.as_ref().map(|(map, _)| map),
                        second_shadow_map: None,
                        shadow_faces: shadows.as_ref().map_or(&[], |(_, faces)| faces),
                    }),
                },
                timer,
            )
        });
        effect.destroy(lucent);
        rows
    })();
    let idle = gpu.wait_idle();
    images.destroy(gpu);
    renderer.destroy(gpu);
    idle?;
    measured
}

#[allow(clippy::too_many_arguments)]
fn measure_translucency(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    lucent: &Lucent,
    scene: &Scene,
    size: (u32, u32),
    frames: (usize, usize),
    memory: &mut Vec<(&'static str, EffectMemory)>,
) -> Result<Vec<EmbedCostRow>> {
    let with = Technique::Only(&crate::features::translucency::TRANSLUCENCY);
    let pair = RendererPair::new(
        gpu,
        shaders,
        pipeline_cache,
        (scene, term_settings(with, size)),
        (scene, term_settings(Technique::None, size)),
    )?;
    let mut images = Images::default();
    let measured = (|| {
        let (width, height) = size;
        let (host, gb) = HostGBuffer::of(gpu, &pair.lit, &mut images, size)?;
        let gb2 = gb.gb2.clone().ok_or_else(|| {
            LucentError::InvalidInput(
                "--embed with --technique translucency: the scene has no translucent material"
                    .into(),
            )
        })?;
        let coloured = gb.layout.gb2_format().is_some_and(|f| {
            crate::backend::format::format_info(f).is_some_and(|i| i.channels == 4)
        });
        let sampled = vk::ImageUsageFlags::SAMPLED;
        // lucent's own GB2 layout: thickness and the ID in one RGBA8 (or RG8) target.
        let (gb2_format, thickness_desc, id_desc, gb2_bytes) = if coloured {
            (
                vk::Format::R8G8B8A8_UNORM,
                ThicknessDesc::rgb(vk::Format::R8G8B8A8_UNORM),
                IdDesc::bits(vk::Format::R8G8B8A8_UNORM, 3, 0, 8),
                rgba8(&gb2),
            )
        } else {
            let bytes = rgba8(&gb2)
                .chunks_exact(4)
                .flat_map(|t| [t[0], t[1]])
                .collect();
            (
                vk::Format::R8G8_UNORM,
                ThicknessDesc::channel(vk::Format::R8G8_UNORM, 0),
                IdDesc::bits(vk::Format::R8G8_UNORM, 1, 0, 8),
                bytes,
            )
        };
        let gb2_image = images.upload(
            gpu,
            &ImageDesc::color(width, height, gb2_format, sampled),
            gb2_bytes,
            "host thickness and IDs",
        )?;
        let gbuffer = host
            .desc
            .clone()
            .with_thickness(thickness_desc)
            .with_material_ids(id_desc);
        let table = crate::features::translucency::MaterialTable::new(scene, true)?;
        let parameters: Vec<&crate::scene::material::Translucency> = scene
            .objects
            .iter()
            .filter_map(|o| o.material.translucency_under(true))
            .collect();
        let materials = table
            .rows
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let t = parameters
                    .iter()
                    .find(|t| crate::features::translucency::material_row(t) == *row)
                    .expect("each row is a material's");
                TranslucentMaterial::from_translucency(i as u8 + 1, t)
            })
            .collect::<Result<Vec<_>>>()?;
        let material_rows: Vec<(u8, [f32; 4])> =
            materials.iter().map(|m| (m.id, m.row())).collect();
        let term = TermData::Translucency {
            rows: &material_rows,
            id_channel: if coloured { 3 } else { 1 },
            coloured,
        };
        let lit = host_lit_target(gpu, &mut images, size)?;
        let mut lighting = build(gpu, lucent, |u| {
            HostLighting::new(lucent, u, &gbuffer, &term)
        })?;
        let effect = build(gpu, lucent, |u| {
            TranslucencyEffect::new(lucent, u, TranslucencyEffectDesc::new(gbuffer, materials))
        });
        let mut effect = match effect {
            Ok(e) => e,
            Err(e) => {
                lighting.destroy(lucent);
                return Err(e);
            }
        };
        memory.push(("TranslucencyEffect", effect.memory()));
        let camera = HostCamera::new(
            scene.camera.view(),
            scene.camera.projection(width as f32 / height as f32),
        );
        // The host draws the effect over its translucent objects' screen bounds, as lucent's
        // lighting pass runs the term over the tiles they touch.
        let regions = object_regions(scene, &camera, (width, height), |_, o| {
            o.material.translucency_under(true).map(|_| 0.0)
        });
        let gb2_image = host_image(
            gb2_image,
            "host thickness and IDs",
            gb2_format,
            size,
            sampled,
        );
        let rows = time_term(
            gpu,
            lucent,
            (&pair.lit, &pair.plain),
            ("translucency", "none"),
            frames,
            |cmd, timer| {
                effect.record_timed(
                    lucent,
                    cmd,
                    &TranslucencyFrame {
                        slot: 0,
                        view: 0,
                        camera,
                        lights: &scene.lights,
                        images: TranslucencyImages {
                            depth: &host.depth,
                            normals: &host.normals,
                            albedo: &host.albedo,
                            thickness: &gb2_image,
                            material_ids: &gb2_image,
                        },
                        regions: &regions,
                        lighting: &host.lighting,
                    },
                    timer,
                )
            },
            &mut |cmd, timer| {
                lighting.record_timed(
                    lucent,
                    cmd,
                    &HostLightingFrame {
                        camera,
                        lights: &scene.lights,
                        regions: &regions,
                        depth: &host.depth,
                        normals: &host.normals,
                        albedo: &host.albedo,
                        ids: Some(&gb2_image),
                        shadow_map: None,
                        lit: &lit,
                    },
                    timer,
                )
            },
        );
        effect.destroy(lucent);
        lighting.destroy(lucent);
        rows
    })();
    pair.finish(gpu, images, measured)
}

/// The SH environment: lucent's ambient term inside its lighting pass (the scene's lighting
/// with its environment minus with none) against the `EnvironmentEffect`'s pass over the
/// whole screen (every surface has the ambient), on a host G-buffer of lucent's own frame
/// (D32, world RGBA16F normals, RGBA8 albedo, RGBA16F light with the albedo).
#[allow(clippy::too_many_arguments)]
fn measure_environment(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    lucent: &Lucent,
    scene: &Scene,
    size: (u32, u32),
    frames: (usize, usize),
    memory: &mut Vec<(&'static str, EffectMemory)>,
) -> Result<Vec<EmbedCostRow>> {
    let dark = Scene {
        environment: crate::scene::Environment::constant(glam::Vec3::ZERO),
        ..scene.clone()
    };
    let pair = RendererPair::new(
        gpu,
        shaders,
        pipeline_cache,
        (scene, term_settings(Technique::None, size)),
        (&dark, term_settings(Technique::None, size)),
    )?;
    let mut images = Images::default();
    let measured = (|| {
        let (host, _) = HostGBuffer::of(gpu, &pair.lit, &mut images, size)?;
        let term = TermData::Environment(scene.environment.coefficients());
        let lit = host_lit_target(gpu, &mut images, size)?;
        let mut lighting = build(gpu, lucent, |u| {
            HostLighting::new(lucent, u, &host.desc, &term)
        })?;
        let effect = build(gpu, lucent, |u| {
            EnvironmentEffect::new(lucent, u, EnvironmentEffectDesc::new(host.desc.clone()))
        });
        let mut effect = match effect {
            Ok(e) => e,
            Err(e) => {
                lighting.destroy(lucent);
                return Err(e);
            }
        };
        memory.push(("EnvironmentEffect", effect.memory()));
        let camera = HostCamera::new(
            scene.camera.view(),
            scene.camera.projection(size.0 as f32 / size.1 as f32),
        );
        let rows = time_term(
            gpu,
            lucent,
            (&pair.lit, &pair.plain),
            ("environment", "no environment"),
            frames,
            |cmd, timer| {
                effect.record_timed(
                    lucent,
                    cmd,
                    &EnvironmentFrame {
                        slot: 0,
                        view: 0,
                        camera,
                        environment: &scene.environment,
                        images: EnvironmentImages {
                            depth: &host.depth,
                            normals: &host.normals,
                            albedo: Some(&host.albedo),
                        },
                        regions: &[],
                        lighting: &host.lighting,
                    },
                    timer,
                )
            },
            &mut |cmd, timer| {
                lighting.record_timed(
                    lucent,
                    cmd,
                    &HostLightingFrame {
                        camera,
                        lights: &scene.lights,
                        regions: &[],
                        depth: &host.depth,
                        normals: &host.normals,
                        albedo: &host.albedo,
                        ids: None,
                        shadow_map: None,
                        lit: &lit,
                    },
                    timer,
                )
            },
        );
        effect.destroy(lucent);
        lighting.destroy(lucent);
        rows
    })();
    pair.finish(gpu, images, measured)
}

/// A frame of `technique` for timing a term of its lighting pass: the pass unmerged (timed
/// alone), the G-buffer exported.
fn term_settings(technique: Technique, (width, height): (u32, u32)) -> FrameSettings {
    FrameSettings {
        export_gbuffer: true,
        ..crate::measure::scaling::settings(technique, width, height)
    }
}

/// SSS transmission: lucent's term inside its lighting pass (the lighting with
/// transmission minus without) against the `TransmissionEffect`'s pass over the scattering
/// objects' screen bounds, on a host G-buffer of lucent's own frame whose shadow map is
/// lucent's own light-space atlas with each face's matrices
/// ([`crate::features::shadows::ShadowDesc::face_matrices`]). `None` when the scene has no
/// material with a medium or no light casting shadows.
#[allow(clippy::too_many_arguments)]
fn measure_transmission(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    lucent: &Lucent,
    scene: &Scene,
    technique: Technique,
    size: (u32, u32),
    frames: (usize, usize),
    memory: &mut Vec<(&'static str, EffectMemory)>,
) -> Result<Option<Vec<EmbedCostRow>>> {
    let settings = |transmission: bool| {
        let mut s = FrameSettings {
            export_shadows: true,
            ..term_settings(technique, size)
        };
        s.sss.texturing = Some(Texturing::Pre);
        s.sss.transmission = transmission;
        s
    };
    let Some(shadows) =
        crate::features::shadows::ShadowDesc::new(scene, &settings(true).shadows, false)
    else {
        return Ok(None);
    };
    let media: Vec<&crate::scene::material::Medium> = scene
        .objects
        .iter()
        .filter_map(|o| o.material.medium.as_ref())
        .collect();
    if media.is_empty() {
        return Ok(None);
    }
    let pair = RendererPair::new(
        gpu,
        shaders,
        pipeline_cache,
        (scene, settings(true)),
        (scene, settings(false)),
    )?;
    let mut images = Images::default();
    let measured = (|| {
        let (width, height) = size;
        let (host, gb) = HostGBuffer::of(gpu, &pair.lit, &mut images, size)?;
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let (shadow_map, faces) = atlas_as_host_map(gpu, &pair.lit, scene, &shadows, &mut images)?;
        // lucent's profile numbers as the host's IDs, each with its object's medium.
        let ids: Vec<u8> = gb
            .sss
            .as_ref()
            .map(|v| v.iter().map(|&k| k as u8).collect())
            .unwrap_or_default();
        let id_image = images.upload(
            gpu,
            &ImageDesc::color(width, height, vk::Format::R8_UNORM, sampled),
            ids,
            "host IDs",
        )?;
        let id_image = host_image(id_image, "host IDs", vk::Format::R8_UNORM, size, sampled);
        let profiles = SssProfiles::new(
            scene,
            technique
                .module()
                .and_then(|m| registry::sss_blur(m.name()).ok()),
            None,
            Some(Texturing::Pre),
            &registry::blur_of,
        )?
        .ok_or_else(|| LucentError::InvalidInput("the scene has no SSS profile".into()))?;
        let materials = (1..=profiles.profiles.len())
            .filter_map(|k| {
                let object = profiles
                    .object_ids
                    .iter()
                    .position(|&id| usize::from(id) == k)?;
                let medium = scene.objects[object].material.medium.clone()?;
                Some(TransmissionMaterial::new(k as u8, medium))
            })
            .collect::<Vec<_>>();
        let units_per_mm = media[0].layered.units_per_mm;
        let metres_per_unit = 1.0 / (1000.0 * units_per_mm);
        let gbuffer = host
            .desc
            .clone()
            .with_material_ids(IdDesc::value(vk::Format::R8_UNORM))
            .with_metres_per_unit(metres_per_unit);
        let media_rows = materials
            .iter()
            .map(|m| Ok((m.id, m.rows(metres_per_unit)?)))
            .collect::<Result<Vec<_>>>()?;
        let face_rows = faces
            .iter()
            .map(|f| Ok((f.light, f.terms_rows(shadow_map.extent)?)))
            .collect::<Result<Vec<_>>>()?;
        let term = TermData::Transmission {
            media: &media_rows,
            faces: &face_rows,
            shadow_format: vk::Format::D32_SFLOAT,
        };
        let lit = host_lit_target(gpu, &mut images, size)?;
        let mut lighting = build(gpu, lucent, |u| {
            HostLighting::new(lucent, u, &gbuffer, &term)
        })?;
        let effect = build(gpu, lucent, |u| {
            TransmissionEffect::new(
                lucent,
                u,
                TransmissionEffectDesc::new(gbuffer, materials, vk::Format::D32_SFLOAT),
            )
        });
        let mut effect = match effect {
            Ok(e) => e,
            Err(e) => {
                lighting.destroy(lucent);
                return Err(e);
            }
        };
        memory.push(("TransmissionEffect", effect.memory()));
        let camera = HostCamera::new(
            scene.camera.view(),
            scene.camera.projection(width as f32 / height as f32),
        );
        let regions = object_regions(scene, &camera, size, |_, o| {
            o.material.medium.as_ref().map(|_| 0.0)
        });
        let rows = time_term(
            gpu,
            lucent,
            (&pair.lit, &pair.plain),
            ("transmission", "no transmission"),
            frames,
            |cmd, timer| {
                effect.record_timed(
                    lucent,
                    cmd,
                    &TransmissionFrame {
                        slot: 0,
                        view: 0,
                        camera,
                        lights: &scene.lights,
                        shadow_faces: &faces,
                        images: TransmissionImages {
                            depth: &host.depth,
                            normals: &host.normals,
                            material_ids: &id_image,
                            albedo: Some(&host.albedo),
                            shadow_map: &shadow_map,
                            second_shadow_map: None,
                        },
                        regions: &regions,
                        lighting: &host.lighting,
                    },
                    timer,
                )
            },
            &mut |cmd, timer| {
                lighting.record_timed(
                    lucent,
                    cmd,
                    &HostLightingFrame {
                        camera,
                        lights: &scene.lights,
                        regions: &regions,
                        depth: &host.depth,
                        normals: &host.normals,
                        albedo: &host.albedo,
                        ids: Some(&id_image),
                        shadow_map: Some(&shadow_map),
                        lit: &lit,
                    },
                    timer,
                )
            },
        );
        effect.destroy(lucent);
        lighting.destroy(lucent);
        rows
    })();
    pair.finish(gpu, images, measured).map(|rows| {
        Some(
            rows.into_iter()
                .map(|row| EmbedCostRow {
                    pass: format!("transmission: {}", row.pass),
                    ..row
                })
                .collect(),
        )
    })
}

/// Li et al.'s layered media: each pass of the `LayeredEffect` against lucent's pass of the
/// same name, on a host G-buffer of lucent's own frame (its layered material numbers as the
/// host's R8_UNORM IDs), the scene's meshes in host buffers (interleaved f32 positions and
/// normals, 32-bit indices), lucent's own light-space faces, the layered objects' screen
/// bounds as the regions.
#[allow(clippy::too_many_arguments)]
fn measure_layered(
    gpu: &GpuContext,
    shaders: &ShaderCompiler,
    pipeline_cache: &PipelineCache,
    lucent: &Lucent,
    scene: &Scene,
    technique: Technique,
    size: (u32, u32),
    (frames, warmup): (usize, usize),
    memory: &mut Vec<(&'static str, EffectMemory)>,
) -> Result<Vec<EmbedCostRow>> {
    let settings = FrameSettings {
        export_shadows: true,
        ..term_settings(technique, size)
    };
    let desc = crate::features::layered::LayeredDesc::new(scene)?
        .ok_or_else(|| LucentError::InvalidInput("the scene has no layered material".into()))?;
    let shadows = crate::features::shadows::ShadowDesc::new(scene, &settings.shadows, false);
    let renderer = Renderer::new(gpu, shaders, pipeline_cache, scene, settings)?;
    let mut images = Images::default();
    let mut buffers: Vec<crate::backend::GpuBuffer> = Vec::new();
    let measured = (|| {
        let (width, height) = size;
        let (host, gb) = HostGBuffer::of(gpu, &renderer, &mut images, size)?;
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let ids: Vec<u8> = gb
            .layered
            .as_ref()
            // The material ID / 255 in red (UNORM8: rounding recovers the integer).
            .map(|v| v.iter().map(|t| (t[0] * 255.0).round() as u8).collect())
            .unwrap_or_default();
        let id_image = images.upload(
            gpu,
            &ImageDesc::color(width, height, vk::Format::R8_UNORM, sampled),
            ids,
            "host IDs",
        )?;
        let id_image = host_image(id_image, "host IDs", vk::Format::R8_UNORM, size, sampled);
        // Media whose layers read depth textures (TexDep): the host's G-buffer holds lucent's
        // texels, its vertices the texture coordinate, and each such draw its medium's
        // textures, uploaded as lucent uploads its own.
        let texdep = desc.depth_textures();
        let layer_depths = match (texdep > 0, &gb.layer_depths) {
            (true, Some(bytes)) => {
                let format = crate::features::layer_depth::layer_depth_format(texdep)
                    .expect("TexDep frames store texels");
                let (image, view) = images.upload(
                    gpu,
                    &ImageDesc::color(width, height, format, sampled),
                    bytes.clone(),
                    "host layer depths",
                )?;
                Some((
                    host_image((image, view), "host layer depths", format, size, sampled),
                    format,
                ))
            }
            _ => None,
        };
        let mut medium_textures: Vec<Option<[vk::ImageView; 2]>> = Vec::new();
        for medium in &desc.materials {
            let mut views = [vk::ImageView::null(); 2];
            for (k, source) in medium.depth_textures.iter().take(2).enumerate() {
                let texture = crate::gpu_scene::upload_source(
                    gpu,
                    source,
                    crate::scene::texture::TextureUsage::Data,
                    "host depth texture",
                )?;
                views[k] = texture.view;
                images.0.push(texture);
            }
            medium_textures.push((!medium.depth_textures.is_empty()).then_some(views));
        }
        // Every mesh in a host vertex buffer and index buffer of its own (with the texture
        // coordinate when a medium reads depth textures).
        let mut meshes = Vec::with_capacity(scene.meshes.len());
        for mesh in &scene.meshes {
            let vertices: Vec<f32> = (0..mesh.positions.len())
                .flat_map(|i| {
                    let (p, n) = (mesh.positions[i], mesh.normals[i]);
                    let uv = mesh.uvs.get(i).copied().unwrap_or_default();
                    let all = [p.x, p.y, p.z, n.x, n.y, n.z, uv.x, uv.y];
                    all.into_iter().take(if texdep > 0 { 8 } else { 6 })
                })
                .collect();
            let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
            buffers.push(gpu.upload_buffer(&vertices, usage, "host vertices")?);
            let usage = vk::BufferUsageFlags::INDEX_BUFFER;
            buffers.push(gpu.upload_buffer(&mesh.indices, usage, "host indices")?);
            let n = buffers.len();
            meshes.push((
                buffers[n - 2].buffer,
                buffers[n - 1].buffer,
                mesh.indices.len(),
            ));
        }
        // Each with its mesh's bounds, so the term's blur draws where lucent's does.
        let bounds = crate::gpu_scene::tiles::mesh_bounds(scene);
        let draws: Vec<MeshDraw> = scene
            .objects
            .iter()
            .zip(&desc.object_ids)
            .map(|(o, &id)| {
                let (vertices, indices, count) = meshes[o.mesh];
                let (low, high) = bounds[o.mesh];
                let draw = MeshDraw::new(vertices, count as u32, o.transform, id)
                    .with_indices(IndexBuffer {
                        buffer: indices,
                        offset: 0,
                        index_type: vk::IndexType::UINT32,
                    })
                    .with_bounds(low, high);
                let textures = usize::from(id)
                    .checked_sub(1)
                    .and_then(|k| medium_textures.get(k).copied().flatten());
                match textures {
                    Some([first, second]) => draw.with_depth_textures(first, Some(second)),
                    None => draw,
                }
            })
            .collect();
        let (faces, atlas) = match &shadows {
            Some(s) => (
                s.face_matrices(scene, &crate::gpu_scene::tiles::mesh_bounds(scene))
                    .into_iter()
                    .map(ShadowFace::from)
                    .collect(),
                s.extent(),
            ),
            None => (Vec::new(), (64, 64)),
        };
        let units_per_mm = desc.materials[0].units_per_mm;
        let mut gbuffer = host
            .desc
            .clone()
            .with_material_ids(IdDesc::value(vk::Format::R8_UNORM))
            .with_metres_per_unit(1.0 / (1000.0 * units_per_mm));
        if let Some((_, format)) = &layer_depths {
            gbuffer = gbuffer.with_layer_depths(*format);
        }
        let materials = desc
            .materials
            .iter()
            .enumerate()
            .map(|(k, m)| {
                // The host gives the textures with its draws.
                let mut medium = m.clone();
                medium.depth_textures.clear();
                LayeredMaterial::new(k as u8 + 1, medium)
            })
            .collect();
        let vertices = if texdep > 0 {
            VertexLayout::interleaved(32, 0, 12).with_uv(crate::embed::VertexAttribute::new(
                0,
                vk::Format::R32G32_SFLOAT,
                24,
            ))
        } else {
            VertexLayout::interleaved(24, 0, 12)
        };
        let effect_desc = LayeredEffectDesc::new(
            gbuffer,
            materials,
            vertices,
            vk::Extent2D {
                width: atlas.0,
                height: atlas.1,
            },
        )
        .with_knobs(renderer.settings.layered);
        // A scene whose layered materials have albedo textures has the film: the host's
        // albedo image stands for it (one texel read per pixel, as lucent's).
        let effect_desc = if desc.film {
            effect_desc.with_film()
        } else {
            effect_desc
        };
        let mut effect = build(gpu, lucent, |u| LayeredEffect::new(lucent, u, effect_desc))?;
        memory.push(("LayeredEffect", effect.memory()));
        let camera = HostCamera::new(
            scene.camera.view(),
            scene.camera.projection(width as f32 / height as f32),
        );
        let regions = object_regions(scene, &camera, size, |i, _| {
            (desc.object_ids.get(i).copied().unwrap_or(0) > 0).then_some(0.0)
        });
        let rows = time_passes(gpu, lucent, &renderer, (frames, warmup), |cmd, timer| {
            effect.record_timed(
                lucent,
                cmd,
                &LayeredFrame {
                    slot: 0,
                    view: 0,
                    camera,
                    lights: &scene.lights,
                    environment: Some(&scene.environment),
                    light_faces: &faces,
                    meshes: &draws,
                    images: LayeredImages {
                        depth: &host.depth,
                        normals: &host.normals,
                        material_ids: &id_image,
                        albedo: desc.film.then_some(&host.albedo),
                        layer_depths: layer_depths.as_ref().map(|(image, _)| image),
                    },
                    regions: &regions,
                    lighting: &host.lighting,
                },
                timer,
            )
        });
        effect.destroy(lucent);
        rows
    })();
    let idle = gpu.wait_idle();
    for buffer in buffers {
        gpu.destroy_buffer(buffer);
    }
    images.destroy(gpu);
    renderer.destroy(gpu);
    idle?;
    measured
}

/// lucent's frame of a scene with a lighting term (`lit`) and without (`plain`), each
/// exporting its G-buffer, destroyed together.
struct RendererPair {
    lit: Renderer,
    plain: Renderer,
}

impl RendererPair {
    fn new(
        gpu: &GpuContext,
        shaders: &ShaderCompiler,
        pipeline_cache: &PipelineCache,
        lit: (&Scene, FrameSettings),
        plain: (&Scene, FrameSettings),
    ) -> Result<Self> {
        let make = |(scene, settings): (&Scene, FrameSettings)| {
            Renderer::new(gpu, shaders, pipeline_cache, scene, settings)
        };
        let lit = make(lit)?;
        match make(plain) {
            Ok(plain) => Ok(Self { lit, plain }),
            Err(e) => {
                lit.destroy(gpu);
                Err(e)
            }
        }
    }

    /// Waits for the GPU, destroys the renderers and `images`, and returns `measured`.
    fn finish<T>(self, gpu: &GpuContext, images: Images, measured: Result<T>) -> Result<T> {
        let idle = gpu.wait_idle();
        images.destroy(gpu);
        self.lit.destroy(gpu);
        self.plain.destroy(gpu);
        idle?;
        measured
    }
}

/// A host G-buffer made from lucent's own frame: depth (D32), albedo (RGBA8), world normals
/// and the lit light (RGBA16F, the albedo in it), described and ready to bind.
struct HostGBuffer {
    desc: GBufferDesc,
    depth: HostImage,
    albedo: HostImage,
    normals: HostImage,
    lighting: HostImage,
}

impl HostGBuffer {
    /// Renders `renderer` once and uploads its G-buffer into `images` as a host's; returns it
    /// with lucent's G-buffer as read back.
    fn of(
        gpu: &GpuContext,
        renderer: &Renderer,
        images: &mut Images,
        size: (u32, u32),
    ) -> Result<(Self, crate::frame::GBufferReadback)> {
        let (width, height) = size;
        renderer.render_once(gpu)?;
        let gb = renderer.read_gbuffer(gpu)?;
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let hdr = vk::Format::R16G16B16A16_SFLOAT;
        let rgba8_format = vk::Format::R8G8B8A8_UNORM;
        let depth = images.upload(
            gpu,
            &ImageDesc::depth(width, height, vk::Format::D32_SFLOAT, sampled),
            bytemuck::cast_slice(&gb.depth).to_vec(),
            "host depth",
        )?;
        let albedo = images.upload(
            gpu,
            &ImageDesc::color(width, height, rgba8_format, sampled),
            rgba8(&gb.gb0),
            "host albedo",
        )?;
        let normals = images.upload(
            gpu,
            &ImageDesc::color(width, height, hdr, sampled),
            rgba16f(&gb.gb1),
            "host normals",
        )?;
        let lighting_usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let lighting = images.upload(
            gpu,
            &ImageDesc::color(width, height, hdr, lighting_usage),
            rgba16f(&gb.gb1),
            "host lighting",
        )?;
        let desc = GBufferDesc::new(
            width,
            height,
            DepthDesc::device(vk::Format::D32_SFLOAT),
            DiffuseDesc::with_albedo(hdr),
        )
        .with_albedo(rgba8_format)
        .with_normals(NormalDesc::world(hdr));
        let host = Self {
            desc,
            depth: host_image(depth, "host depth", vk::Format::D32_SFLOAT, size, sampled),
            albedo: host_image(albedo, "host albedo", rgba8_format, size, sampled),
            normals: host_image(normals, "host normals", hdr, size, sampled),
            lighting: host_image(lighting, "host lighting", hdr, size, lighting_usage),
        };
        Ok((host, gb))
    }
}

/// Times lucent's frame of `renderer` against the passes `record` records (into the timer it
/// is given, reset in its command buffer), frames alternating; `warmup` rounds are discarded,
/// `frames` measured. A row per pass of the effect, in the order it records them, beside
/// lucent's pass of the same name.
fn time_passes(
    gpu: &GpuContext,
    lucent: &Lucent,
    renderer: &Renderer,
    (frames, warmup): (usize, usize),
    mut record: impl FnMut(vk::CommandBuffer, &mut EffectTimer) -> Result<()>,
) -> Result<Vec<EmbedCostRow>> {
    let mut timer = EffectTimer::new(lucent, 64)?;
    let (mut ours, mut theirs) = (Samples::default(), Samples::default());
    let mut order: Vec<String> = Vec::new();
    let mut run = || -> Result<()> {
        for round in 0..warmup + frames {
            let frame = renderer.render_once(gpu)?;
            host_frame(gpu, |cmd| record(cmd, &mut timer))?;
            if round < warmup {
                continue;
            }
            for pass in &frame.timing.passes {
                ours.push(&pass.name, pass.ms);
            }
            for pass in timer.results(lucent)?.unwrap_or_default() {
                if !order.contains(&pass.name) {
                    order.push(pass.name.clone());
                }
                theirs.push(&pass.name, pass.ms);
            }
        }
        Ok(())
    };
    let result = run();
    timer.destroy(lucent);
    result?;
    Ok(order
        .into_iter()
        .map(|name| EmbedCostRow {
            lucent_ms: ours.median(&name),
            host_ms: theirs.median(&name),
            pass: name,
        })
        .collect())
}

/// Times a lighting term lucent adds inside its lighting pass against the effect a host
/// records for it: lucent's cost is the lighting pass of `lit` (with the term, labelled
/// `labels.0`) minus that of `plain` (without it, `labels.1`), frame by frame; the host's is
/// each pass `record` times (into the timer it is given, reset in its command buffer). The
/// three frames alternate; `warmup` rounds are discarded, `frames` measured.
#[allow(clippy::too_many_arguments)]
fn time_term(
    gpu: &GpuContext,
    lucent: &Lucent,
    (lit, plain): (&Renderer, &Renderer),
    labels: (&str, &str),
    (frames, warmup): (usize, usize),
    mut record: impl FnMut(vk::CommandBuffer, &mut EffectTimer) -> Result<()>,
    host_lighting: &mut HostLightingRun<'_>,
) -> Result<Vec<EmbedCostRow>> {
    let mut timer = EffectTimer::new(lucent, 8)?;
    let mut lighting_timer = match EffectTimer::new(lucent, 8) {
        Ok(t) => t,
        Err(e) => {
            timer.destroy(lucent);
            return Err(e);
        }
    };
    let (with_label, without_label) = (
        format!("lighting ({})", labels.0),
        format!("lighting ({})", labels.1),
    );
    let (mut ours, mut theirs) = (Samples::default(), Samples::default());
    let mut run = || -> Result<()> {
        for round in 0..warmup + frames {
            let with_term = lit.render_once(gpu)?;
            let without = plain.render_once(gpu)?;
            host_frame(gpu, |cmd| record(cmd, &mut timer))?;
            host_frame(gpu, |cmd| host_lighting(cmd, &mut lighting_timer))?;
            if round < warmup {
                continue;
            }
            let passes = lighting_timer.results(lucent)?.unwrap_or_default();
            let ms = |name: &str| passes.iter().find(|p| p.name == name).map(|p| p.ms);
            if let (Some(a), Some(b)) =
                (ms(host_lighting::TERM_PASS), ms(host_lighting::PLAIN_PASS))
            {
                theirs.push(HOST_WITH_TERM_ROW, a);
                theirs.push(HOST_PLAIN_ROW, b);
                theirs.push(HOST_TERM_ROW, a - b);
            }
            let lighting_ms = |frame: &crate::frame::FrameImages| {
                frame
                    .timing
                    .passes
                    .iter()
                    .find(|p| p.name == "lighting")
                    .map(|p| p.ms)
            };
            if let (Some(a), Some(b)) = (lighting_ms(&with_term), lighting_ms(&without)) {
                ours.push(&with_label, a);
                ours.push(&without_label, b);
                ours.push("the term", a - b);
            }
            for pass in timer.results(lucent)?.unwrap_or_default() {
                theirs.push("the term", pass.ms);
                theirs.push(&pass.name, pass.ms);
            }
        }
        Ok(())
    };
    let result = run();
    timer.destroy(lucent);
    lighting_timer.destroy(lucent);
    result?;
    let mut rows: Vec<EmbedCostRow> = [without_label.as_str(), with_label.as_str(), "the term"]
        .iter()
        .map(|name| EmbedCostRow {
            pass: name.to_string(),
            lucent_ms: ours.median(name),
            host_ms: theirs.median(name),
        })
        .collect();
    // The host's own lighting: its two passes (nothing of lucent's frame to set beside them),
    // then the term they differ by beside lucent's.
    for name in [HOST_PLAIN_ROW, HOST_WITH_TERM_ROW] {
        rows.push(EmbedCostRow {
            pass: name.to_string(),
            lucent_ms: None,
            host_ms: theirs.median(name),
        });
    }
    rows.push(EmbedCostRow {
        pass: HOST_TERM_ROW.to_string(),
        lucent_ms: ours.median("the term"),
        host_ms: theirs.median(HOST_TERM_ROW),
    });
    Ok(rows)
}

/// Records the benchmark's host lighting (both its passes) into a command buffer, timed into
/// the timer it is given.
type HostLightingRun<'a> = dyn FnMut(vk::CommandBuffer, &mut EffectTimer) -> Result<()> + 'a;

/// The host lighting's rows, and the row of the term they differ by.
const HOST_PLAIN_ROW: &str = "host's lighting (TERMS), without the term";
const HOST_WITH_TERM_ROW: &str = "host's lighting (TERMS), with the term";
const HOST_TERM_ROW: &str = "the term in the host's lighting (TERMS)";

/// A lit target of the host's (RGBA16F, a colour attachment) for its own lighting pass.
fn host_lit_target(gpu: &GpuContext, images: &mut Images, size: (u32, u32)) -> Result<HostImage> {
    let hdr = vk::Format::R16G16B16A16_SFLOAT;
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
    let bytes = vec![0u8; size.0 as usize * size.1 as usize * 8];
    let image = images.upload(
        gpu,
        &ImageDesc::color(size.0, size.1, hdr, usage),
        bytes,
        "host lit",
    )?;
    Ok(host_image(image, "host lit", hdr, size, usage))
}

/// The screen regions of the objects `reach` selects, each widened by the reach it gives (the
/// whole screen, no region, when one crosses the eye's plane).
fn object_regions(
    scene: &Scene,
    camera: &HostCamera,
    size: (u32, u32),
    reach: impl Fn(usize, &crate::scene::Object) -> Option<f32>,
) -> Vec<vk::Rect2D> {
    object_regions_each(scene, camera, size, reach)
        .into_iter()
        .map(|(_, rect)| rect)
        .collect()
}

/// [`object_regions`], each with its object's index.
fn object_regions_each(
    scene: &Scene,
    camera: &HostCamera,
    (width, height): (u32, u32),
    reach: impl Fn(usize, &crate::scene::Object) -> Option<f32>,
) -> Vec<(usize, vk::Rect2D)> {
    let bounds = crate::gpu_scene::tiles::mesh_bounds(scene);
    let extent = vk::Extent2D { width, height };
    let regions: Option<Vec<(usize, vk::Rect2D)>> = scene
        .objects
        .iter()
        .enumerate()
        .filter_map(|(i, o)| reach(i, o).map(|r| (i, o, r)))
        .map(|(i, o, r)| {
            crate::embed::box_screen_region(bounds[o.mesh], o.transform, camera, extent, r)
                .map(|rect| (i, rect))
        })
        .collect();
    regions.unwrap_or_default()
}

/// Builds an effect with its uploads recorded into one command buffer, submitted and waited
/// for here (the benchmark is the host), then released.
fn build<T>(
    gpu: &GpuContext,
    lucent: &Lucent,
    make: impl FnOnce(&mut crate::embed::Uploads) -> Result<T>,
) -> Result<T> {
    let mut made = None;
    let mut uploads = None;
    gpu.submit_and_wait(|cmd| {
        // SAFETY: `cmd` is recording, on lucent's queue family, submitted by submit_and_wait.
        let mut u = unsafe { lucent.uploads(cmd) };
        made = Some(make(&mut u));
        uploads = Some(u);
    })?;
    if let Some(mut u) = uploads {
        // SAFETY: submit_and_wait waited for the submission holding the uploads.
        unsafe { u.release(lucent) }?;
    }
    made.expect("the closure ran")
}
