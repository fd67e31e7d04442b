//! Deferred shading: the MRT G-buffer pass and the lighting pass that reads it at the same pixel
//! (input attachments), so the graph merges the two into subpasses of one render pass.
//!
//! With translucency (GDC 2011) the G-buffer gains GB2 (thickness + material ID), and the
//! lighting pass is drawn as scissored rectangles of screen tiles: tiles that translucent objects
//! may cover (their projected bounding boxes, on the CPU each frame) get the shader with the
//! talk's per-light term, the others the plain shader. Only rasterisation reliably skips work on every
//! driver: lavapipe shades both sides of a per-pixel branch, and it runs input-attachment
//! shaders with late depth/stencil tests, so neither a material-ID branch nor a stencil mask
//! saves anything there (measured in docs/translucency.md).
//! G-buffer layout and bit budget: glsl/common/gbuffer.glsl.

use std::sync::Arc;

use ash::vk;

use crate::backend::access::Access;
use crate::graph::{
    Handle, Image, ImageInfo, LoadOp, PassExec, PassKind, PrepareContext, RecordContext,
    RenderGraph, ResourceId,
};
use crate::Result;

use super::shadows::{self, ShadowMaps};
use super::shipped::PipelineShaders;
use super::translucency::ThicknessPacking;
use super::util::{
    check_bindings, clamp_sampler, Binding, Defines, DescriptorSet, GraphicsPipeline,
    GraphicsPipelineDesc, PassPipeline, VertexInput,
};
use crate::gpu_scene::{Region, SceneGpu};

/// Depth.
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
/// Lit HDR colour.
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Screen-space SSS profile ID per pixel (ID / 255; 0: the pixel does not scatter).
pub const SSS_PROFILE_FORMAT: vk::Format = vk::Format::R8_UNORM;
/// LCB and LBB: view-plane LEAN slope y and moments (blurred, so at least fp16).
pub const LEAN_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

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

/// The `TexDep` texels of a G-buffer or light-space map texel for `textures` depth textures
/// (glsl/common/layer_depths.glsl: two fp16 texels per 32-bit component): RG32UI holds four
/// layers, RGBA32UI eight; `None` for 0.
pub fn layer_depth_format(textures: usize) -> Option<vk::Format> {
    match textures {
        0 => None,
        1 => Some(vk::Format::R32G32_UINT),
        _ => Some(vk::Format::R32G32B32A32_UINT),
    }
}

/// The LUCENT_LAYER_DEPTHS define's value for `textures` depth textures (1 or 2).
pub fn layer_depths_define(textures: usize) -> &'static str {
    if textures > 1 {
        "2"
    } else {
        "1"
    }
}

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

    /// GB0: albedo rgb + specular.
    pub fn gb0_format(&self) -> vk::Format {
        match self.precision {
            GBufferPrecision::Compact => vk::Format::R8G8B8A8_UNORM,
            GBufferPrecision::Half => vk::Format::R16G16B16A16_SFLOAT,
            GBufferPrecision::Full => vk::Format::R32G32B32A32_SFLOAT,
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
            let binding = 1 + usize::from(self.normal_maps) * (1 + usize::from(self.lean));
            defines.push(("LUCENT_ALBEDO_BINDING", LOCATIONS[binding]));
        }
        if self.layer_depths() {
            defines.push((
                "LUCENT_LAYER_DEPTHS",
                layer_depths_define(self.layer_depth_textures),
            ));
            let binding = 1
                + usize::from(self.normal_maps) * (1 + usize::from(self.lean))
                + usize::from(self.albedo_maps);
            defines.push(("LUCENT_DEPTH_MAP_BINDING", LOCATIONS[binding]));
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
        layered: layout.layered.then(|| {
            graph.create_image("gbuffer.layered", image(super::layered::LAYERED_ID_FORMAT))
        }),
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

/// The bindings of a draw's `TexDep` depth textures (`textures` of them, 1 or 2) from pair
/// `depth` of [`crate::gpu_scene::MaterialMaps::depth`].
pub fn depth_map_bindings(
    maps: &crate::gpu_scene::MaterialMaps,
    depth: [usize; 2],
    textures: usize,
) -> Vec<Binding> {
    depth
        .iter()
        .take(textures.clamp(1, 2))
        .filter_map(|&i| maps.depth.get(i).or(maps.depth.first()))
        .map(|map| Binding::Sampled(map.view, maps.sampler))
        .collect()
}

/// What the lighting pass writes.
pub struct Lit {
    /// Lit HDR colour; with SSS, the diffuse part only.
    pub color: Handle<Image>,
    /// With SSS: the specular part, added back after the blurs.
    pub specular: Option<Handle<Image>>,
}

/// Declares the lighting pass: reads the G-buffer at the same pixel (and the light-space maps,
/// when some light casts shadows), writes lit HDR colour (with SSS: diffuse and specular
/// apart).
pub fn lighting_pass(
    graph: &mut RenderGraph,
    gb: &GBuffer,
    shadows: Option<&ShadowMaps>,
    scene: Option<&Arc<SceneGpu>>,
) -> Lit {
    let info = graph.resources()[gb.gb0.id()].info;
    let hdr_info = ImageInfo {
        format: HDR_FORMAT,
        ..info
    };
    let mut hdr = graph.create_image(
        if gb.layout.sss {
            "lighting.diffuse"
        } else {
            "hdr"
        },
        hdr_info,
    );
    let mut specular = gb
        .layout
        .sss
        .then(|| graph.create_image("lighting.specular", hdr_info));
    let mut pass = graph.add_pass("lighting", PassKind::Raster);
    pass.input(&gb.gb0).input(&gb.gb1).input(&gb.depth);
    if let Some(gb2) = &gb.gb2 {
        pass.input(gb2);
    }
    if let Some(maps) = shadows {
        pass.sample(&maps.depth);
        if let Some(ids) = &maps.ids {
            pass.sample(ids);
        }
    }
    pass.color(&mut hdr, LoadOp::DontCare);
    if let Some(specular) = &mut specular {
        pass.color(specular, LoadOp::DontCare);
    }
    let inputs = LightingInputs {
        gb0: gb.gb0.id(),
        gb1: gb.gb1.id(),
        depth: gb.depth.id(),
        gb2: gb.gb2.as_ref().map(|h| h.id()),
        shadow_depth: shadows.map(|m| m.depth.id()),
        shadow_ids: shadows.and_then(|m| m.ids.as_ref().map(|h| h.id())),
    };
    match scene {
        Some(scene) => pass.execute(LightingPass {
            scene: scene.clone(),
            inputs,
            layout: gb.layout,
            pipeline: None,
            translucent: None,
            sampler: vk::Sampler::null(),
        }),
        None => pass.finish(),
    }
    Lit {
        color: hdr,
        specular,
    }
}

/// The G-buffer pass's shaders.
const GBUFFER_VERTEX: &str = "deferred/gbuffer.vert";
const GBUFFER_FRAGMENT: &str = "deferred/gbuffer.frag";
/// The lighting pass's fragment shader.
const LIGHTING_FRAGMENT: &str = "deferred/lighting.frag";

/// The lighting pass's descriptor bindings before the shadow bindings
/// (glsl/deferred/lighting.frag): 0-3 always, 4 (GB2) and 5 (material table) with translucency.
fn lighting_bindings_before_shadows(layout: &GBufferLayout) -> usize {
    4 + 2 * usize::from(layout.translucency.is_some())
}

/// The lighting pass's defines: the plain shader's, and with translucency the extra ones of the
/// translucent variant (drawn on the tiles translucent objects may cover). `shadows`: some
/// light casts shadows, `Some(true)` when the atlas stores translucency IDs.
pub(crate) fn lighting_defines(
    layout: &GBufferLayout,
    shadows: Option<bool>,
) -> (Defines, Option<Defines>) {
    let mut plain: Vec<(&'static str, &'static str)> = Vec::new();
    if shadows.is_some() {
        plain.extend(shadows::lighting_defines(lighting_bindings_before_shadows(
            layout,
        )));
    }
    if layout.sss {
        plain.push(("LUCENT_SPLIT_SPECULAR", "1"));
    }
    if layout.lean {
        plain.push(("LUCENT_LEAN", "1"));
    }
    if layout.depth_in_alpha {
        plain.push(("LUCENT_DEPTH_IN_ALPHA", "1"));
    }
    if layout.fault_injection {
        plain.push(("LUCENT_FAULT_INJECTION", "1"));
    }
    let translucent = layout.translucency.map(|_| {
        // The plain variant's defines (split specular, LEAN slope) plus the translucency's.
        let mut extra = layout.defines();
        if shadows == Some(true) {
            // Only the translucent variant shades transmission: only it reads the IDs.
            extra.push(("LUCENT_SHADOW_IDS", "1"));
        }
        extra
    });
    (plain, translucent)
}

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
        for flags in 0u32..1 << 7 {
            let bit = |i: u32| flags & (1 << i) != 0;
            // LEAN and depth-in-alpha are properties of SSS chains
            // (`FrameDesc::gbuffer_layout`): a frame without SSS has neither.
            if !bit(0) && (bit(1) || bit(4)) {
                continue;
            }
            for layer_depth_textures in 0..=2 {
                layouts.push(GBufferLayout {
                    precision: GBufferPrecision::Compact,
                    translucency,
                    sss: bit(0),
                    lean: bit(1),
                    lean_clear: false,
                    normal_maps: bit(2),
                    albedo_maps: bit(3),
                    depth_in_alpha: bit(4),
                    layered: bit(5),
                    layer_depth_textures,
                    fault_injection: bit(6),
                });
            }
        }
    }
    layouts
}

/// The pipelines the G-buffer and lighting passes of any frame build.
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for layout in all_layouts() {
        out.push(PipelineShaders::new(
            GBUFFER_VERTEX,
            GBUFFER_FRAGMENT,
            &layout.gbuffer_defines(),
        ));
        for shadows in [None, Some(false), Some(true)] {
            let (plain, translucent) = lighting_defines(&layout, shadows);
            let fullscreen =
                |defines: &[(&str, &str)]| PipelineShaders::fullscreen(LIGHTING_FRAGMENT, defines);
            out.push(fullscreen(&plain));
            if let Some(extra) = translucent {
                let mut all = plain.clone();
                all.extend(extra);
                out.push(fullscreen(&all));
            }
        }
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
    fn bindings(&self, index: usize) -> Vec<Binding> {
        let mut bindings = vec![Binding::PerFrame(
            self.scene.per_frame.binding(Region::Frame),
        )];
        if let Some(maps) = &self.scene.maps {
            let set = maps.sets.get(index).copied().unwrap_or_default();
            let (normal, albedo) = (set.normal, set.albedo);
            if let Some(map) = maps.normal.get(normal) {
                bindings.push(Binding::Sampled(map.view, maps.sampler));
                // LEAN frames: the second LEAN map follows.
                if let Some(lean2) = maps.lean2.get(normal) {
                    bindings.push(Binding::Sampled(lean2.view, maps.sampler));
                }
            }
            if let Some(map) = maps.albedo.get(albedo) {
                bindings.push(Binding::Sampled(map.view, maps.sampler));
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
                push_constant_bytes: std::mem::size_of::<crate::gpu_scene::ObjectConstants>()
                    as u32,
                name: "gbuffer",
            },
        )?);
        let sets = self.scene.maps.as_ref().map_or(0, |m| m.sets.len());
        for index in 1..sets {
            // Identically defined layouts are compatible: these sets bind to the pipeline's.
            let set = DescriptorSet::new(
                ctx,
                &self.bindings(index),
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                "gbuffer material maps",
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

/// The G-buffer images the lighting pass reads.
struct LightingInputs {
    gb0: ResourceId,
    gb1: ResourceId,
    depth: ResourceId,
    gb2: Option<ResourceId>,
    /// The light-space maps' depth and ID atlases, when some light casts shadows.
    shadow_depth: Option<ResourceId>,
    shadow_ids: Option<ResourceId>,
}

struct LightingPass {
    scene: Arc<SceneGpu>,
    inputs: LightingInputs,
    layout: GBufferLayout,
    /// The plain shader: every pixel, or with translucency the tiles no translucent object
    /// touches.
    pipeline: Option<PassPipeline>,
    /// With translucency: the translucency shader for the other tiles (same set).
    translucent: Option<GraphicsPipeline>,
    /// Nearest clamp sampler for the light-space maps (null without shadows).
    sampler: vk::Sampler,
}

impl PassExec for LightingPass {
    fn prepare(&mut self, ctx: &PrepareContext<'_>) -> Result<()> {
        let inputs = &self.inputs;
        let color_layout = Access::InputAttachmentRead.info().layout;
        let depth_layout = Access::DepthInputAttachmentRead.info().layout;
        let views = ctx.descriptor_views;
        // Bindings 0-3 always; 4 (GB2) and 5 (material table) only with translucency
        // (glsl/deferred/lighting.frag).
        let mut bindings = vec![
            Binding::PerFrame(self.scene.per_frame.binding(Region::Frame)),
            Binding::InputAttachment(views[inputs.gb0], color_layout),
            Binding::InputAttachment(views[inputs.gb1], color_layout),
            Binding::InputAttachment(views[inputs.depth], depth_layout),
        ];
        if let Some(gb2) = inputs.gb2 {
            bindings.push(Binding::InputAttachment(views[gb2], color_layout));
            bindings.push(Binding::PerFrame(
                self.scene.per_frame.binding(Region::Translucency),
            ));
        }
        let shadow_ids = inputs.shadow_depth.map(|_| inputs.shadow_ids.is_some());
        let (plain_defines, translucent_defines) = lighting_defines(&self.layout, shadow_ids);
        if let Some(depth) = inputs.shadow_depth {
            self.sampler = clamp_sampler(ctx, vk::Filter::NEAREST)?;
            // The shadow table, then the atlases (glsl/common/shadows.glsl).
            check_bindings(
                "lighting",
                bindings.len(),
                lighting_bindings_before_shadows(&self.layout),
            )?;
            bindings.extend(shadows::lighting_bindings(
                &self.scene,
                depth,
                inputs.shadow_ids,
                views,
                self.sampler,
            ));
        }
        let plain = GraphicsPipelineDesc::fullscreen(LIGHTING_FRAGMENT, &plain_defines, "lighting");
        let mut pipeline = PassPipeline::new(ctx, &bindings, &plain)?;
        if let Some(extra) = translucent_defines {
            let (plain_pipeline, translucent) =
                pipeline.with_variant(ctx, &plain, &extra, "lighting (translucent)")?;
            pipeline = plain_pipeline;
            self.translucent = Some(translucent);
        }
        self.pipeline = Some(pipeline);
        Ok(())
    }

    fn record(&self, ctx: &RecordContext<'_>) {
        let Some(pipeline) = &self.pipeline else {
            return;
        };
        let Some(translucent) = &self.translucent else {
            pipeline.draw_fullscreen(ctx);
            return;
        };
        let rects = self.scene.per_frame.tiles(ctx.frame).lighting.clone();
        pipeline.bind(ctx);
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| !r.translucent));
        // SAFETY: made for this subpass with the bound set's layout.
        unsafe {
            ctx.gpu.device.cmd_bind_pipeline(
                ctx.cmd,
                vk::PipelineBindPoint::GRAPHICS,
                translucent.pipeline,
            );
        }
        PassPipeline::draw_fullscreen_in(ctx, rects.iter().filter(|r| r.translucent));
    }

    fn destroy(&mut self, gpu: &crate::backend::GpuContext) {
        if let Some(mut p) = self.pipeline.take() {
            p.destroy(&gpu.device);
        }
        if let Some(mut p) = self.translucent.take() {
            p.destroy(&gpu.device);
        }
        // SAFETY: created in prepare (or null); the GPU is done (caller's contract).
        unsafe { gpu.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}
