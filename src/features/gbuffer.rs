//! The G-buffer: its targets ([`GBufferLayout`]: which a frame's materials ask for, their
//! formats at each [`GBufferPrecision`]) and the MRT pass that fills them ([`gbuffer_pass`]).
//! The lighting pass ([`super::lighting`]) reads them at the same pixel (input attachments), so
//! the graph merges the two into subpasses of one render pass; the later features (SSS, layered
//! media, debug views) read the targets they need from [`GBuffer`].
//!
//! Layout and bit budget: glsl/common/gbuffer.glsl.

use std::sync::Arc;

use ash::vk;

use super::gbuffer_desc::{
    DepthDesc, DiffuseDesc, GBufferDesc, IdDesc, LeanTargetsDesc, NormalDesc, ThicknessDesc,
};
use super::util::HDR_FORMAT;
use crate::backend::shader::PipelineShaders;
use crate::gpu_scene::{SceneGpu, FRAME};
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, MeshDraws, MeshViews, PassExec, PassKind, PrepareContext,
    RecordContext, RenderGraph,
};
use crate::Result;

use super::layer_depth::{depth_map_bindings, layer_depth_format, layer_depths_define};
use super::util::PassPipeline;
use crate::backend::descriptor::{Binding, DescriptorSet};
use crate::backend::pipeline::{GraphicsPipelineDesc, VertexInput};

/// Depth.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Screen-space SSS profile ID per pixel (ID / 255; 0: the pixel does not scatter).
pub const SSS_PROFILE_FORMAT: vk::Format = vk::Format::R8_UNORM;
pub use super::util::LEAN_FORMAT;
/// Layered media: the layered material ID per pixel (ID / 255; 0: not layered), in frames
/// whose layered materials have no albedo texture ([`GBufferLayout::layered_format`]).
pub const LAYERED_ID_FORMAT: vk::Format = vk::Format::R8_UNORM;

/// Precision of the G-buffer's colour targets (the report measures what each costs and how
/// far its image is from the f64 reference).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GBufferPrecision {
    /// The production layout: albedo and translucency 8 bits per channel, normal fp16.
    #[default]
    Compact,
    /// Every colour target RGBA16F.
    Half,
    /// Every colour target RGBA32F: the input of the f64 reference, not for rendering.
    Full,
}

impl GBufferPrecision {
    /// Every precision with its command-line name.
    pub const ALL: &'static [(&'static str, GBufferPrecision)] = &[
        ("compact", GBufferPrecision::Compact),
        ("half", GBufferPrecision::Half),
        ("full", GBufferPrecision::Full),
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, p)| *p == self)
            .map_or("?", |(n, _)| n)
    }
}

/// How local thickness is packed into `GB2` (GDC 2011 translucency, [`super::translucency`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ThicknessPacking {
    /// One channel (the talk's Fig. 20): `R8G8` = thickness, material ID. A coloured
    /// thickness is reduced to its Rec. 709 luminance.
    Grayscale,
    /// Three channels (the talk's coloured variant, unpacked): `R8G8B8A8` = thickness RGB,
    /// material ID.
    Colored,
}

impl ThicknessPacking {
    /// Shader define value and name.
    pub fn name(self) -> &'static str {
        match self {
            ThicknessPacking::Grayscale => "grayscale",
            ThicknessPacking::Colored => "colored",
        }
    }
}

/// The G-buffer's targets: formats, and whether (and how) it carries translucency.
/// Layout and bit budget: glsl/common/gbuffer.glsl.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GBufferLayout {
    /// Target precision.
    pub precision: GBufferPrecision,
    /// `None`: the frame has no translucency and no GB2.
    pub translucency: Option<TranslucencyLayout>,
    /// Screen-space SSS: the G-buffer stores each pixel's SSS profile ID (R8) and the
    /// lighting pass writes diffuse and specular to separate targets, so the blur sees diffuse
    /// only.
    pub sss: bool,
    /// Some SSS profile applies its albedo after the blur (`Texturing::Post` or `PrePost`): the
    /// lighting pass reads the profile IDs (an input attachment) and the profile table, and
    /// the SSS chains' last passes multiply the albedo (GB0) back in.
    pub sss_texturing: bool,
    /// Some SSS profile's material has a medium: the lighting pass reads the profile IDs and
    /// table (as for texturing), shades those pixels' diffuse light as their medium reflects
    /// it, and (when some light casts shadows) adds the light the medium diffuses through the
    /// object's thickness, which the light-space maps measure ([`super::sss::transmission`]).
    pub sss_medium: bool,
    /// LCB and LBB: the G-buffer pass projects LEAN data to the view plane (a LEAN target:
    /// slope y + moments) and the lighting pass stores slope x in the diffuse alpha.
    pub lean: bool,
    /// LCB: the LEAN target is cleared first (see [`gbuffer_pass`]).
    pub lean_clear: bool,
    /// Some object has a normal map: the G-buffer pass reads UVs and tangents and samples it.
    pub normal_maps: bool,
    /// Some object has an albedo texture: the G-buffer pass reads UVs and multiplies the
    /// albedo by it.
    pub albedo_maps: bool,
    /// The separable SSS blur reads linear depth from the lit diffuse's alpha (frames with a
    /// separable chain and no LEAN chain).
    pub depth_in_alpha: bool,
    /// Layered media (Li et al.): the G-buffer stores each pixel's layered material ID.
    pub layered: bool,
    /// Some layered material has an albedo texture: the layered target holds the texel beside
    /// the ID (RGBA at GB0's precision instead of R8), which single scattering applies to the
    /// light leaving the surface as a pigment film.
    pub layered_film: bool,
    /// `TexDep` depth textures the layered media read per object (0: none, 1 or 2): the
    /// G-buffer samples them at each pixel's UV and stores the texels (layer depth target).
    pub layer_depth_textures: usize,
    /// Robustness tests: the lighting pass poisons the pixel the frame uniforms name.
    pub fault_injection: bool,
}

/// How a frame's translucency is stored and shaded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TranslucencyLayout {
    /// GB2's thickness packing.
    pub packing: ThicknessPacking,
    /// The pow forms the frame's materials use (bit 0 exact, bit 1 `exp2`): the shader
    /// compiles only those.
    pub pow_modes: u8,
    /// Only one translucent material: the shader reads its row without the per-pixel ID.
    pub single_material: bool,
}

/// A G-buffer target beyond GB0 and GB1, each present only in frames whose materials need it;
/// they take the colour locations after GB1 in this order (glsl/deferred/gbuffer.frag reads
/// each location from its define).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExtraTarget {
    /// GB2: thickness + translucency material ID.
    Translucency,
    /// The SSS profile ID.
    SssProfile,
    /// The view-plane LEAN slope y + moments.
    Lean,
    /// The layered material ID.
    Layered,
    /// The `TexDep` texels at each pixel (glsl/common/layer_depths.glsl).
    LayerDepths,
}

impl ExtraTarget {
    /// The define that carries the target's location.
    fn location_define(self) -> &'static str {
        match self {
            ExtraTarget::Translucency => "LUCENT_GB2_LOCATION",
            ExtraTarget::SssProfile => "LUCENT_SSS_LOCATION",
            ExtraTarget::Lean => "LUCENT_LEAN_LOCATION",
            ExtraTarget::Layered => "LUCENT_LAYERED_LOCATION",
            ExtraTarget::LayerDepths => "LUCENT_LAYER_DEPTH_LOCATION",
        }
    }
}

/// Location values as shader define strings (at most 2 + five extra targets).
const LOCATIONS: [&str; 8] = ["0", "1", "2", "3", "4", "5", "6", "7"];

impl GBufferLayout {
    /// The targets after GB0 and GB1, in location order (2, 3, ...).
    pub fn extra_targets(&self) -> Vec<ExtraTarget> {
        let mut targets = Vec::new();
        if self.translucency.is_some() {
            targets.push(ExtraTarget::Translucency);
        }
        if self.sss {
            targets.push(ExtraTarget::SssProfile);
        }
        if self.lean {
            targets.push(ExtraTarget::Lean);
        }
        if self.layered {
            targets.push(ExtraTarget::Layered);
        }
        if self.layered && self.layer_depth_textures > 0 {
            targets.push(ExtraTarget::LayerDepths);
        }
        targets
    }

    /// The G-buffer pass reads the UV + tangent stream.
    pub fn surface_stream(&self) -> bool {
        self.normal_maps || self.albedo_maps || self.layer_depths()
    }

    /// The G-buffer stores `TexDep` texels.
    pub fn layer_depths(&self) -> bool {
        self.layered && self.layer_depth_textures > 0
    }

    /// This G-buffer, and the lighting pass's images of a frame with it, described as a host
    /// describes its own to the effects (`lucent::embed`): the effects' passes read lucent's
    /// frame through the same description and the same declaration as a host's.
    ///
    /// | input | lucent's image |
    /// |---|---|
    /// | depth | `gbuffer.depth`, D32 with standard Z |
    /// | diffuse | the lighting pass's RGBA16F, the albedo as each SSS material's texturing asks, linear depth in alpha when a blur reads it there ([`Self::depth_in_alpha`]) |
    /// | specular | the lighting pass's RGBA16F (frames with SSS) |
    /// | albedo | GB0 |
    /// | material IDs | `gbuffer.sss`, the SSS profile numbers as `R8_UNORM` (frames with SSS) |
    /// | normals | GB1's world normal |
    /// | thickness | GB2's (frames with GDC 2011 translucency) |
    /// | LEAN targets | `gbuffer.lean`, GB0 and GB1 (frames with LCB or LBB) |
    ///
    /// The world scale is left at a metre: lucent's profiles each carry their own
    /// (`units_per_mm`), as a host's materials may (`SssMaterial::with_metres_per_unit`).
    pub fn described(&self, width: u32, height: u32) -> GBufferDesc {
        let mut diffuse = DiffuseDesc::with_albedo_as_texturing(HDR_FORMAT);
        if self.depth_in_alpha {
            diffuse = diffuse.with_depth_in_alpha();
        }
        let mut desc = GBufferDesc::new(width, height, DepthDesc::device(DEPTH_FORMAT), diffuse)
            .with_albedo(self.gb0_format())
            .with_normals(NormalDesc::world(self.gb1_format()));
        if self.sss {
            desc = desc
                .with_specular(HDR_FORMAT)
                .with_material_ids(IdDesc::value(SSS_PROFILE_FORMAT));
        }
        if let (Some(format), Some(t)) = (self.gb2_format(), self.translucency) {
            desc = desc.with_thickness(match t.packing {
                ThicknessPacking::Grayscale => ThicknessDesc::channel(format, 0),
                ThicknessPacking::Colored => ThicknessDesc::rgb(format),
            });
        }
        if let Some(format) = layer_depth_format(self.layer_depth_textures).filter(|_| self.layer_depths()) {
            desc = desc.with_layer_depths(format);
        }
        if self.lean {
            desc = desc.with_lean_targets(LeanTargetsDesc::new(
                LEAN_FORMAT,
                self.gb0_format(),
                self.gb1_format(),
            ));
        }
        desc
    }

    /// GB0: albedo rgb + specular.
    pub fn gb0_format(&self) -> vk::Format {
        match self.precision {
            GBufferPrecision::Compact => vk::Format::R8G8B8A8_UNORM,
            GBufferPrecision::Half => vk::Format::R16G16B16A16_SFLOAT,
            GBufferPrecision::Full => vk::Format::R32G32B32A32_SFLOAT,
        }
    }

    /// The layered target: the material ID alone, or (`layered_film`) the ID in r and the
    /// albedo texel in gba at GB0's precision (the film is an albedo: the same bits as the
    /// albedo Lambert reads).
    pub fn layered_format(&self) -> vk::Format {
        if self.layered_film {
            self.gb0_format()
        } else {
            LAYERED_ID_FORMAT
        }
    }

    /// GB1: world normal xyz + roughness.
    pub fn gb1_format(&self) -> vk::Format {
        match self.precision {
            GBufferPrecision::Compact | GBufferPrecision::Half => vk::Format::R16G16B16A16_SFLOAT,
            GBufferPrecision::Full => vk::Format::R32G32B32A32_SFLOAT,
        }
    }

    /// GB2: local thickness + material ID (grayscale: two channels; coloured: four).
    pub fn gb2_format(&self) -> Option<vk::Format> {
        let packing = self.translucency?.packing;
        Some(match (self.precision, packing) {
            (GBufferPrecision::Compact, ThicknessPacking::Grayscale) => vk::Format::R8G8_UNORM,
            (GBufferPrecision::Compact, ThicknessPacking::Colored) => vk::Format::R8G8B8A8_UNORM,
            (GBufferPrecision::Half, ThicknessPacking::Grayscale) => vk::Format::R16G16_SFLOAT,
            (GBufferPrecision::Half, ThicknessPacking::Colored) => vk::Format::R16G16B16A16_SFLOAT,
            (GBufferPrecision::Full, ThicknessPacking::Grayscale) => vk::Format::R32G32_SFLOAT,
            (GBufferPrecision::Full, ThicknessPacking::Colored) => vk::Format::R32G32B32A32_SFLOAT,
        })
    }

    /// G-buffer pass defines: the features, each extra target's location, and the binding of
    /// each material texture (set 0: 0 the frame uniforms, then normal or LEAN map 1, LEAN
    /// map 2, albedo map, those the frame has).
    pub(crate) fn gbuffer_defines(&self) -> Vec<(&'static str, &'static str)> {
        let mut defines = self.defines();
        if self.sss {
            defines.push(("LUCENT_SSS_PROFILE", "1"));
        }
        if self.normal_maps {
            defines.push(("LUCENT_NORMAL_MAP", "1"));
        }
        if self.lean {
            defines.push(("LUCENT_LEAN", "1"));
        }
        if self.layered {
            defines.push(("LUCENT_LAYERED", "1"));
        }
        if self.albedo_maps {
            defines.push(("LUCENT_ALBEDO_MAP", "1"));
        }
        if self.layer_depths() {
            defines.push((
                "LUCENT_LAYER_DEPTHS",
                layer_depths_define(self.layer_depth_textures),
            ));
        }
        for (i, target) in self.extra_targets().into_iter().enumerate() {
            defines.push((target.location_define(), LOCATIONS[2 + i]));
        }
        defines
    }

    /// Shader defines selecting the translucency code, its packing, pow forms and material
    /// lookup (nothing for frames without translucency).
    pub(crate) fn defines(&self) -> Vec<(&'static str, &'static str)> {
        let Some(t) = self.translucency else {
            return Vec::new();
        };
        let mut defines = vec![("LUCENT_TRANSLUCENCY", "1")];
        if t.packing == ThicknessPacking::Colored {
            defines.push(("LUCENT_COLORED_THICKNESS", "1"));
        }
        defines.push((
            "LUCENT_POW_MODES",
            match t.pow_modes {
                1 => "1",
                2 => "2",
                _ => "3",
            },
        ));
        if t.single_material {
            defines.push(("LUCENT_SINGLE_MATERIAL", "1"));
        }
        defines
    }
}

/// The G-buffer's handles.
pub struct GBuffer {
    /// Albedo + specular.
    pub gb0: Handle<Image>,
    /// Normal + roughness.
    pub gb1: Handle<Image>,
    /// Local thickness + material ID, in frames with translucency.
    pub gb2: Option<Handle<Image>>,
    /// Screen-space SSS profile ID per pixel, in frames with SSS.
    pub sss: Option<Handle<Image>>,
    /// View-plane LEAN slope y + moments, in LCB and LBB frames.
    pub lean: Option<Handle<Image>>,
    /// Layered material ID per pixel, in frames with layered media.
    pub layered: Option<Handle<Image>>,
    /// `TexDep` texels per pixel, in frames whose layered media read depth textures.
    pub layer_depths: Option<Handle<Image>>,
    /// Depth.
    pub depth: Handle<Image>,
    /// The layout it was declared with.
    pub layout: GBufferLayout,
}

/// Declares the G-buffer pass. `scene` is `None` for plan-only graphs (`lucent plan`).
pub fn gbuffer_pass(
    graph: &mut RenderGraph,
    width: u32,
    height: u32,
    layout: GBufferLayout,
    scene: Option<&Arc<SceneGpu>>,
) -> GBuffer {
    let image = |format| ImageInfo {
        width,
        height,
        format,
    };
    let mut gb = GBuffer {
        gb0: graph.create_image("gbuffer.albedo", image(layout.gb0_format())),
        gb1: graph.create_image("gbuffer.normal", image(layout.gb1_format())),
        gb2: layout
            .gb2_format()
            .map(|f| graph.create_image("gbuffer.translucency", image(f))),
        sss: layout
            .sss
            .then(|| graph.create_image("gbuffer.sss", image(SSS_PROFILE_FORMAT))),
        lean: layout
            .lean
            .then(|| graph.create_image("gbuffer.lean", image(LEAN_FORMAT))),
        layered: layout
            .layered
            .then(|| graph.create_image("gbuffer.layered", image(layout.layered_format()))),
        layer_depths: layout
            .layer_depths()
            .then(|| layer_depth_format(layout.layer_depth_textures))
            .flatten()
            .map(|f| graph.create_image("gbuffer.layer-depth", image(f))),
        depth: graph.create_image("gbuffer.depth", image(DEPTH_FORMAT)),
        layout,
    };
    // LCB and LBB: the G-buffer pass is the thesis's projection pass (its Table 1's first row).
    let name = if layout.lean { "projection" } else { "gbuffer" };
    let mut pass = graph.add_pass(name, PassKind::Raster);
    pass.color(&mut gb.gb0, LoadOp::Clear([0.0; 4]))
        .color(&mut gb.gb1, LoadOp::Clear([0.0, 1.0, 0.0, 1.0]));
    if let Some(gb2) = &mut gb.gb2 {
        // Cleared to material ID 0: sky and opaque pixels skip the translucency math.
        pass.color(gb2, LoadOp::Clear([0.0; 4]));
    }
    if let Some(sss) = &mut gb.sss {
        // Cleared to 0: sky and non-scattering pixels are left alone by the blurs.
        pass.color(sss, LoadOp::Clear([0.0; 4]));
    }
    if let Some(lean) = &mut gb.lean {
        // LUCENT_LEAN_LOCATION of glsl/deferred/gbuffer.frag. LCB clears it: the control-style blur's
        // bilinear taps straddle silhouettes and would filter undefined sky texels into the
        // moments. LBB's point taps give sky texels zero weight (depth) and replace non-finite
        // ones, so it skips the clear.
        let load = if layout.lean_clear {
            LoadOp::Clear([0.0; 4])
        } else {
            LoadOp::DontCare
        };
        pass.color(lean, load);
    }
    if let Some(layered) = &mut gb.layered {
        // Cleared to 0: the scattering passes leave non-layered pixels alone.
        pass.color(layered, LoadOp::Clear([0.0; 4]));
    }
    if let Some(depths) = &mut gb.layer_depths {
        // Not cleared: single scattering reads it only at layered pixels, which every draw
        // writes (zero texels for media without TexDep layers).
        pass.color(depths, LoadOp::DontCare);
    }
    pass.depth(&mut gb.depth, LoadOp::Clear([1.0; 4]));
    // Every object once with the camera, back faces culled (the benchmark's floor draws the
    // same).
    pass.mesh_draws(MeshDraws {
        views: MeshViews::Camera,
        cull_back: true,
    });
    match scene {
        Some(scene) => pass.execute(GBufferPass {
            scene: scene.clone(),
            layout,
            pipeline: None,
            map_sets: Vec::new(),
        }),
        None => pass.finish(),
    }
    gb
}

/// The G-buffer pass's shaders.
const GBUFFER_VERTEX: &str = "deferred/gbuffer.vert";
const GBUFFER_FRAGMENT: &str = "deferred/gbuffer.frag";

/// Every G-buffer layout that differs in a way a shader sees (precision and the LEAN clear
/// only change formats and load ops): translucency off or each packing, pow-form set and
/// material lookup, and every combination of the other features that
/// [`crate::frame::FrameDesc::gbuffer_layout`] can give.
pub(crate) fn all_layouts() -> Vec<GBufferLayout> {
    let mut translucency = vec![None];
    for packing in [ThicknessPacking::Grayscale, ThicknessPacking::Colored] {
        for pow_modes in [1, 2, 3] {
            for single_material in [false, true] {
                translucency.push(Some(TranslucencyLayout {
                    packing,
                    pow_modes,
                    single_material,
                }));
            }
        }
    }
    let mut layouts = Vec::new();
    for &translucency in &translucency {
        for flags in 0u32..1 << 9 {
            let bit = |i: u32| flags & (1 << i) != 0;
            // LEAN, depth-in-alpha, texturing and transmission are properties of SSS chains
            // (`FrameDesc::gbuffer_layout`): a frame without SSS has none of them.
            if !bit(0) && (bit(1) || bit(4) || bit(7) || bit(8)) {
                continue;
            }
            for layer_depth_textures in 0..=2 {
                layouts.push(GBufferLayout {
                    precision: GBufferPrecision::Compact,
                    translucency,
                    sss: bit(0),
                    sss_texturing: bit(7),
                    sss_medium: bit(8),
                    lean: bit(1),
                    lean_clear: false,
                    normal_maps: bit(2),
                    albedo_maps: bit(3),
                    depth_in_alpha: bit(4),
                    layered: bit(5),
                    // Only the layered target's format: the shader is the same.
                    layered_film: false,
                    layer_depth_textures,
                    fault_injection: bit(6),
                });
            }
        }
    }
    layouts
}

/// The pipelines the G-buffer pass of any frame builds.
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for layout in all_layouts() {
        out.push(PipelineShaders::new(
            GBUFFER_VERTEX,
            GBUFFER_FRAGMENT,
            &layout.gbuffer_defines(),
        ));
    }
}

struct GBufferPass {
    scene: Arc<SceneGpu>,
    layout: GBufferLayout,
    pipeline: Option<PassPipeline>,
    /// Frames with maps: one set per material-texture pair after the first (which is the
    /// pipeline's own), each `frame uniforms + those maps`, bound per draw.
    map_sets: Vec<DescriptorSet>,
}

impl GBufferPass {
    /// Set 0's bindings with material-texture set `index` of the scene's maps
    /// (glsl/deferred/gbuffer.frag): the frame uniforms, then the normal (or LEAN 1) map, LEAN
    /// map 2, the albedo map and the depth maps, those the frame has.
    fn bindings(&self, index: usize) -> Vec<(&'static str, Binding)> {
        let frame = Binding::PerFrame(self.scene.per_frame.binding(&FRAME));
        let mut bindings = vec![(FRAME.block, frame)];
        if let Some(maps) = &self.scene.maps {
            let set = maps.sets.get(index).copied().unwrap_or_default();
            let (normal, albedo) = (set.normal, set.albedo);
            let sampled = |map: &crate::backend::resources::GpuImage| {
                Binding::Sampled(map.view, maps.sampler)
            };
            if let Some(map) = maps.normal.get(normal) {
                bindings.push(("normal_map", sampled(map)));
                // LEAN frames: the second LEAN map.
                if let Some(lean2) = maps.lean2.get(normal) {
                    bindings.push(("lean2_map", sampled(lean2)));
                }
            }
            if let Some(map) = maps.albedo.get(albedo) {
                bindings.push(("albedo_map", sampled(map)));
            }
            if self.layout.layer_depths() {
                bindings.extend(depth_map_bindings(
                    maps,
                    set.depth,
                    self.layout.layer_depth_textures,
                ));
            }
        }
        bindings
    }
}

impl PassExec for GBufferPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        self.pipeline = Some(PassPipeline::new(
            ctx,
            &self.bindings(0),
            &GraphicsPipelineDesc {
                vertex: GBUFFER_VERTEX,
                fragment: GBUFFER_FRAGMENT,
                defines: &self.layout.gbuffer_defines(),
                vertex_input: VertexInput::Mesh {
                    thickness: self.layout.translucency.is_some(),
                    surface: self.layout.surface_stream(),
                },
                depth_test: true,
                cull_back: true,
                additive_attachments: 0,
                set_layouts: &[],
                bindings: &[],
                push_constant_bytes: std::mem::size_of::<crate::gpu_scene::ObjectConstants>()
                    as u32,
                specialization: &[],
                name: "gbuffer",
            },
        )?);
        let sets = self.scene.maps.as_ref().map_or(0, |m| m.sets.len());
        for index in 1..sets {
            // Identically defined layouts are compatible: these sets bind to the pipeline's.
            let bindings: Vec<Binding> = self.bindings(index).into_iter().map(|b| b.1).collect();
            let set = DescriptorSet::new(
                ctx,
                &bindings,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                "gbuffer material maps",
                ctx.slots,
            )?;
            self.map_sets.push(set);
        }
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        pipeline.bind(ctx);
        let device = &ctx.gpu.device;
        let mut bound_maps = 0usize;
        for draw in &self.scene.draws {
            let mesh = &self.scene.meshes[draw.mesh];
            if draw.maps != bound_maps {
                let set = match draw.maps {
                    0 => &pipeline.set,
                    i => &self.map_sets[i - 1],
                };
                set.bind(ctx, pipeline.pipeline.layout, 0);
                bound_maps = draw.maps;
            }
            // SAFETY: the pipeline is bound inside this pass's subpass; buffers are alive.
            unsafe {
                device.cmd_push_constants(
                    ctx.cmd,
                    pipeline.pipeline.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&draw.constants),
                );
            }
            mesh.draw(
                device,
                ctx.cmd,
                ctx.frame,
                self.layout.translucency.is_some(),
                self.layout.surface_stream(),
            );
        }
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        for mut set in self.map_sets.drain(..) {
            set.destroy(&gpu.device);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layout lucent's frames declare is a G-buffer the effects' checks accept, so its
    /// passes read it through the description a host gives.
    #[test]
    fn lucents_own_gbuffer_is_a_valid_host_description() {
        // A LEAN chain keeps its slope in the diffuse's alpha: no frame has depth there too
        // (`SssProfiles::depth_in_alpha`).
        let layouts = all_layouts()
            .into_iter()
            .filter(|l| !(l.lean && l.depth_in_alpha));
        let mut checked = 0;
        for layout in layouts {
            for &(_, precision) in GBufferPrecision::ALL {
                let layout = GBufferLayout {
                    precision,
                    ..layout
                };
                let desc = layout.described(640, 360);
                desc.check()
                    .unwrap_or_else(|e| panic!("{layout:?}: {e}"));
                assert_eq!(desc.material_ids.is_some(), layout.sss);
                assert_eq!(desc.specular.is_some(), layout.sss);
                assert_eq!(desc.lean_targets.is_some(), layout.lean);
                assert_eq!(desc.diffuse.depth_in_alpha, layout.depth_in_alpha);
                assert_eq!(desc.thickness.is_some(), layout.translucency.is_some());
                checked += 1;
            }
        }
        assert!(checked > 1000, "{checked} layouts");
    }
}
