//! A host's image as lucent sees it: the handles, what it was created with, and the state
//! (layout, stage, access) the host says it is in, checked before anything is recorded.
//!
//! Vulkan cannot be asked which layout an image is in or which usage it was created with, so
//! the host declares both. What lucent can check, it checks up front and refuses with an
//! error naming the image: a usage flag lucent's use of the image needs, a layout the declared
//! usage or the format's aspect does not allow, an access mask the declared stages cannot
//! perform or the declared layout cannot hold, a final layout an image can never be
//! transitioned to, a format lucent cannot use in that role, a size that is not the frame's.
//! Each of those would otherwise surface as a validation error (or undefined behaviour) deep
//! inside a frame; here they are a [`HostError::Image`] (its [`ImageFault`] says which check)
//! before the first command.

use ash::vk;

use crate::backend::format::{format_info, format_name, FormatKind};
use crate::backend::GpuContext;
use crate::error::{HostError, ImageFault};
use crate::Result;

/// How an image was last used (or is to be used next): its layout and the pipeline stages and
/// memory accesses of that use, as in a `VkImageMemoryBarrier2`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageState {
    /// The image's layout.
    pub layout: vk::ImageLayout,
    /// The stages of the use.
    pub stage: vk::PipelineStageFlags2,
    /// The memory accesses of the use.
    pub access: vk::AccessFlags2,
}

impl ImageState {
    /// Contents not needed (as a current state: lucent may discard them).
    pub const UNDEFINED: Self = Self::new(
        vk::ImageLayout::UNDEFINED,
        vk::PipelineStageFlags2::NONE,
        vk::AccessFlags2::NONE,
    );

    /// A state from its three parts.
    pub const fn new(
        layout: vk::ImageLayout,
        stage: vk::PipelineStageFlags2,
        access: vk::AccessFlags2,
    ) -> Self {
        Self {
            layout,
            stage,
            access,
        }
    }

    /// Written as a colour attachment (the state after a host's raster pass).
    pub const fn color_attachment() -> Self {
        Self::new(
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
        )
    }

    /// Written as a depth attachment (the state after a host's depth pass).
    pub const fn depth_attachment() -> Self {
        Self::new(
            vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            vk::PipelineStageFlags2::from_raw(
                vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                    | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
            ),
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
        )
    }

    /// Sampled in fragment shaders.
    pub const fn fragment_sampled() -> Self {
        Self::new(
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            vk::PipelineStageFlags2::FRAGMENT_SHADER,
            vk::AccessFlags2::SHADER_SAMPLED_READ,
        )
    }

    /// Source of a copy (a read-back, a blit to the swapchain).
    pub const fn transfer_src() -> Self {
        Self::new(
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            vk::PipelineStageFlags2::ALL_TRANSFER,
            vk::AccessFlags2::TRANSFER_READ,
        )
    }

    /// Handed to the presentation engine (`vkQueuePresentKHR` waits on a semaphore, so no
    /// stage or access).
    pub const fn present() -> Self {
        Self::new(
            vk::ImageLayout::PRESENT_SRC_KHR,
            vk::PipelineStageFlags2::NONE,
            vk::AccessFlags2::NONE,
        )
    }

    /// A swapchain image just acquired, as the current state of lucent's output: contents
    /// undefined, and its first use ordered after the acquire. The host submits the command
    /// buffer waiting on the acquire semaphore at `COLOR_ATTACHMENT_OUTPUT`; lucent's barrier
    /// out of this state starts at that same stage, so its layout transition happens after the
    /// presentation engine has released the image (the semaphore wait's second scope and the
    /// barrier's first scope meet at that stage). [`ImageState::UNDEFINED`], whose stage is
    /// `NONE`, would let the transition run before the wait.
    pub const fn acquired() -> Self {
        Self::new(
            vk::ImageLayout::UNDEFINED,
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
            vk::AccessFlags2::NONE,
        )
    }

    /// Sampled as a depth-stencil image in a fragment shader (the read-only depth-stencil
    /// layout, which a host may keep its depth buffer in while it also tests against it).
    pub const fn depth_sampled() -> Self {
        Self::new(
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
            vk::PipelineStageFlags2::FRAGMENT_SHADER,
            vk::AccessFlags2::SHADER_SAMPLED_READ,
        )
    }
}

/// A host's image handed to lucent for one call: the image, a view of its first mip level
/// and array layer, what it was created with, the state it is in and the state the host wants
/// it left in. The host keeps owning both handles. Bound when the call records (never
/// remembered by handle): a view recreated between frames, even with a reused handle value,
/// is simply the next frame's view.
///
/// ```
/// # use ash::vk;
/// # use lucent::embed::{HostImage, ImageState};
/// let depth = HostImage::new(
///     "depth",
///     vk::Image::null(),
///     vk::ImageView::null(),
///     vk::Format::D32_SFLOAT,
///     vk::Extent2D { width: 1280, height: 720 },
///     vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
/// )
/// .in_state(ImageState::depth_attachment())
/// .then(ImageState::depth_sampled());
/// assert_eq!(depth.final_state, Some(ImageState::depth_sampled()));
/// ```
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct HostImage {
    /// A name for errors and debug labels (`"scene colour"`).
    pub name: String,
    /// The image.
    pub image: vk::Image,
    /// A 2-D view of mip [`HostImage::mip`], layer [`HostImage::base_layer`] (a depth-stencil
    /// image's view: the aspect lucent reads, depth for depth, stencil for material IDs in
    /// stencil bits); for [`HostImage::layers`] layers, a 2-D array view of them.
    pub view: vk::ImageView,
    /// The format the image (and view) were created with.
    pub format: vk::Format,
    /// Its size: the size of the view's mip level.
    pub extent: vk::Extent2D,
    /// The usage flags it was created with.
    pub usage: vk::ImageUsageFlags,
    /// The state it is in when lucent's commands start (the host's last use of it).
    pub state: ImageState,
    /// The state lucent leaves it in; `None`: the state it came in ([`HostImage::state`]),
    /// which must then not be UNDEFINED.
    pub final_state: Option<ImageState>,
    /// The array layers lucent reads (1: a 2-D image; more: a shadow map's cascades or cube
    /// faces as an array, [`HostImage::with_layers`]), all in [`HostImage::state`].
    pub layers: u32,
    /// The mip level the view shows ([`HostImage::at`]): lucent's barriers cover that level
    /// only, the image's other levels keep their states.
    pub mip: u32,
    /// The first array layer the view shows ([`HostImage::at`]): a stereo renderer's eye in
    /// a layer of a two-layer image, a G-buffer in one layer of an array. lucent's barriers
    /// cover `base_layer..base_layer + layers` only.
    pub base_layer: u32,
}

impl HostImage {
    /// An image in [`ImageState::UNDEFINED`], to be left as it came.
    pub fn new(
        name: impl Into<String>,
        image: vk::Image,
        view: vk::ImageView,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> Self {
        Self {
            name: name.into(),
            image,
            view,
            format,
            extent,
            usage,
            state: ImageState::UNDEFINED,
            final_state: None,
            layers: 1,
            mip: 0,
            base_layer: 0,
        }
    }

    /// The view shows mip `mip` and array layer `base_layer` (the first of
    /// [`HostImage::layers`]) of the image: lucent's barriers cover those subresources only,
    /// and [`HostImage::extent`] is that mip's size.
    pub fn at(mut self, mip: u32, base_layer: u32) -> Self {
        self.mip = mip;
        self.base_layer = base_layer;
        self
    }

    /// The subresources lucent's barriers cover.
    pub(crate) fn subresources(&self) -> crate::graph::Subresources {
        crate::graph::Subresources {
            mip: self.mip,
            base_layer: self.base_layer,
            layers: self.layers,
        }
    }

    /// An array of `layers` layers (from [`HostImage::base_layer`]; the view a 2-D array view
    /// of them): a shadow map whose faces lie in layers ([`super::ShadowFace::layer`], counted
    /// from the view's first layer).
    pub fn with_layers(mut self, layers: u32) -> Self {
        self.layers = layers;
        self
    }

    /// The state the image is in when lucent's commands start.
    pub fn in_state(mut self, state: ImageState) -> Self {
        self.state = state;
        self
    }

    /// The state lucent must leave the image in.
    pub fn then(mut self, state: ImageState) -> Self {
        self.final_state = Some(state);
        self
    }

    /// The state the image is left in: [`HostImage::final_state`], else the one it came in.
    pub fn left_in(&self) -> ImageState {
        self.final_state.unwrap_or(self.state)
    }
}

/// What lucent does with a host image, which decides the usage, formats and layouts it needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// Written as a colour attachment (the output).
    Output,
    /// Added to as a colour attachment, its contents kept and blended with (the light an
    /// effect adds to the host's lighting).
    Accumulate,
    /// Sampled colour (lit diffuse, specular, albedo, colour material IDs, linear depth).
    SampledColor,
    /// Sampled depth (or stencil: material IDs in stencil bits) of a depth-stencil image.
    SampledDepth,
    /// Sampled depth of a host's shadow map: the one input that may be an array of layers
    /// (its faces in layers, [`super::ShadowFace::layer`]).
    ShadowMap,
}

impl Role {
    fn usage(self) -> (vk::ImageUsageFlags, &'static str) {
        match self {
            Role::Output | Role::Accumulate => (
                vk::ImageUsageFlags::COLOR_ATTACHMENT,
                "VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT (lucent writes it as a colour attachment)",
            ),
            Role::SampledColor | Role::SampledDepth | Role::ShadowMap => (
                vk::ImageUsageFlags::SAMPLED,
                "VK_IMAGE_USAGE_SAMPLED_BIT (lucent samples it)",
            ),
        }
    }

    fn format_feature(self) -> (vk::FormatFeatureFlags, &'static str) {
        match self {
            Role::Output => (vk::FormatFeatureFlags::COLOR_ATTACHMENT, "COLOR_ATTACHMENT"),
            // Additive blending.
            Role::Accumulate => (
                vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND,
                "COLOR_ATTACHMENT_BLEND",
            ),
            Role::SampledColor | Role::SampledDepth | Role::ShadowMap => {
                (vk::FormatFeatureFlags::SAMPLED_IMAGE, "SAMPLED_IMAGE")
            }
        }
    }

    /// The state lucent's own commands use the image in (the graph's import state).
    pub(crate) fn working_state(self) -> ImageState {
        match self {
            Role::Output | Role::Accumulate => ImageState::color_attachment(),
            Role::SampledColor | Role::SampledDepth | Role::ShadowMap => {
                ImageState::fragment_sampled()
            }
        }
    }
}

fn invalid(image: &str, kind: ImageFault, problem: String) -> crate::LucentError {
    HostError::Image {
        image: image.to_string(),
        kind,
        problem,
    }
    .into()
}

/// The usage flags an image must have been created with to be in `layout` (the layout
/// rules of `VkImageMemoryBarrier2`, VUID-VkImageMemoryBarrier2-oldLayout-01208 and
/// following), and whether the layout is one for depth, for colour or for either aspect.
/// `None`: a layout lucent does not accept from a host.
fn layout_rule(layout: vk::ImageLayout) -> Option<(vk::ImageUsageFlags, Aspect)> {
    use vk::ImageLayout as L;
    use vk::ImageUsageFlags as U;
    let any = U::empty();
    Some(match layout {
        L::UNDEFINED | L::GENERAL => (any, Aspect::Either),
        L::COLOR_ATTACHMENT_OPTIMAL => (U::COLOR_ATTACHMENT, Aspect::Color),
        L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL
        | L::DEPTH_STENCIL_READ_ONLY_OPTIMAL
        | L::DEPTH_ATTACHMENT_OPTIMAL
        | L::DEPTH_READ_ONLY_OPTIMAL
        | L::DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL
        | L::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL => {
            (U::DEPTH_STENCIL_ATTACHMENT, Aspect::Depth)
        }
        L::SHADER_READ_ONLY_OPTIMAL => (U::SAMPLED | U::INPUT_ATTACHMENT, Aspect::Either),
        L::READ_ONLY_OPTIMAL => (
            U::SAMPLED | U::INPUT_ATTACHMENT | U::DEPTH_STENCIL_ATTACHMENT,
            Aspect::Either,
        ),
        L::ATTACHMENT_OPTIMAL => (
            U::COLOR_ATTACHMENT | U::DEPTH_STENCIL_ATTACHMENT,
            Aspect::Either,
        ),
        L::TRANSFER_SRC_OPTIMAL => (U::TRANSFER_SRC, Aspect::Either),
        L::TRANSFER_DST_OPTIMAL => (U::TRANSFER_DST, Aspect::Either),
        L::PRESENT_SRC_KHR => (any, Aspect::Color),
        _ => return None,
    })
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Aspect {
    Color,
    Depth,
    Either,
}

/// The stages that can perform `access` (one bit), for the "declared access the declared
/// stages cannot perform" check (VUID-VkImageMemoryBarrier2-srcAccessMask-03900 and
/// following). `None` for bits lucent does not check.
fn stages_for(access: vk::AccessFlags2) -> Option<vk::PipelineStageFlags2> {
    use vk::AccessFlags2 as A;
    use vk::PipelineStageFlags2 as S;
    let shaders = S::VERTEX_SHADER
        | S::TESSELLATION_CONTROL_SHADER
        | S::TESSELLATION_EVALUATION_SHADER
        | S::GEOMETRY_SHADER
        | S::FRAGMENT_SHADER
        | S::COMPUTE_SHADER
        | S::PRE_RASTERIZATION_SHADERS;
    let depth_tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    let transfer = S::ALL_TRANSFER | S::COPY | S::BLIT | S::RESOLVE | S::CLEAR;
    Some(match access {
        A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE => S::COLOR_ATTACHMENT_OUTPUT,
        A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE => depth_tests,
        A::SHADER_READ
        | A::SHADER_WRITE
        | A::SHADER_SAMPLED_READ
        | A::SHADER_STORAGE_READ
        | A::SHADER_STORAGE_WRITE
        | A::UNIFORM_READ => shaders,
        A::INPUT_ATTACHMENT_READ => S::FRAGMENT_SHADER,
        A::TRANSFER_READ | A::TRANSFER_WRITE => transfer,
        A::HOST_READ | A::HOST_WRITE => S::HOST,
        _ => return None,
    })
}

/// The layouts an image can be written in by `access` (one bit): a write the layout cannot
/// hold means the declared layout is not the one the host last wrote the image in.
fn write_layouts(access: vk::AccessFlags2) -> Option<&'static [vk::ImageLayout]> {
    use vk::AccessFlags2 as A;
    use vk::ImageLayout as L;
    Some(match access {
        A::COLOR_ATTACHMENT_WRITE => &[
            L::COLOR_ATTACHMENT_OPTIMAL,
            L::ATTACHMENT_OPTIMAL,
            L::GENERAL,
        ],
        A::DEPTH_STENCIL_ATTACHMENT_WRITE => &[
            L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
            L::DEPTH_ATTACHMENT_OPTIMAL,
            L::DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL,
            L::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL,
            L::ATTACHMENT_OPTIMAL,
            L::GENERAL,
        ],
        A::TRANSFER_WRITE => &[L::TRANSFER_DST_OPTIMAL, L::GENERAL],
        A::SHADER_WRITE | A::SHADER_STORAGE_WRITE => &[L::GENERAL],
        _ => return None,
    })
}

/// Checks that `state` is a state `image` can be in: a layout its usage and aspect allow,
/// accesses its stages can perform, writes its layout can hold. `what` says which state
/// ("current", "final") for the message; `is_final` refuses layouts no barrier may end in.
pub(crate) fn check_state(
    image: &HostImage,
    state: &ImageState,
    what: &str,
    is_final: bool,
) -> Result<()> {
    let layout = state.layout;
    if is_final
        && matches!(
            layout,
            vk::ImageLayout::UNDEFINED | vk::ImageLayout::PREINITIALIZED
        )
    {
        return Err(invalid(
            &image.name,
            ImageFault::Layout,
            format!("the {what} layout {layout:?} is not one an image can be transitioned to"),
        ));
    }
    let (needs, aspect) = layout_rule(layout).ok_or_else(|| {
        invalid(
            &image.name,
            ImageFault::Layout,
            format!(
                "the {what} layout {layout:?} is not one lucent accepts (GENERAL, the attachment, \
                 read-only, transfer and present layouts)"
            ),
        )
    })?;
    if !needs.is_empty() && !image.usage.intersects(needs) {
        return Err(invalid(
            &image.name,
            ImageFault::Layout,
            format!(
                "the {what} layout {layout:?} needs usage {needs:?}, but the image was declared \
                 with {:?}: the declared layout is wrong or the usage is missing",
                image.usage
            ),
        ));
    }
    let depth = is_depth(image.format);
    let aspect_ok = match aspect {
        Aspect::Either => true,
        Aspect::Color => !depth,
        Aspect::Depth => depth,
    };
    if !aspect_ok {
        return Err(invalid(
            &image.name,
            ImageFault::Layout,
            format!(
                "the {what} layout {layout:?} is a {} layout, but the image's format {} is a {} \
                 format",
                if depth { "colour" } else { "depth" },
                format_name(image.format),
                if depth { "depth" } else { "colour" },
            ),
        ));
    }
    let declared = expand_meta_stages(state.stage);
    for bit in bits(state.access.as_raw()) {
        let access = vk::AccessFlags2::from_raw(bit);
        if let Some(stages) = stages_for(access) {
            if !declared.intersects(stages) {
                return Err(invalid(
                    &image.name,
                    ImageFault::Access,
                    format!(
                        "the {what} access {access:?} cannot be performed by the declared stages \
                         {:?}",
                        state.stage
                    ),
                ));
            }
        }
        if let Some(layouts) = write_layouts(access) {
            if !layouts.contains(&layout) {
                return Err(invalid(
                    &image.name,
                    ImageFault::Access,
                    format!(
                        "the {what} state writes {access:?}, which layout {layout:?} cannot hold: \
                         the declared layout is not the one the image was written in"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// `stage` with ALL_COMMANDS and ALL_GRAPHICS replaced by the stages they stand for (every
/// stage lucent's checks name, and the graphics ones).
fn expand_meta_stages(stage: vk::PipelineStageFlags2) -> vk::PipelineStageFlags2 {
    use vk::PipelineStageFlags2 as S;
    let graphics = S::DRAW_INDIRECT
        | S::VERTEX_INPUT
        | S::VERTEX_SHADER
        | S::TESSELLATION_CONTROL_SHADER
        | S::TESSELLATION_EVALUATION_SHADER
        | S::GEOMETRY_SHADER
        | S::PRE_RASTERIZATION_SHADERS
        | S::FRAGMENT_SHADER
        | S::EARLY_FRAGMENT_TESTS
        | S::LATE_FRAGMENT_TESTS
        | S::COLOR_ATTACHMENT_OUTPUT;
    let mut out = stage;
    if stage.contains(S::ALL_GRAPHICS) {
        out |= graphics;
    }
    if stage.contains(S::ALL_COMMANDS) {
        out |= graphics
            | S::COMPUTE_SHADER
            | S::ALL_TRANSFER
            | S::COPY
            | S::BLIT
            | S::RESOLVE
            | S::CLEAR
            | S::HOST;
    }
    out
}

/// The set bits of `raw`, one at a time.
fn bits(raw: u64) -> impl Iterator<Item = u64> {
    (0..64).map(|i| 1u64 << i).filter(move |b| raw & b != 0)
}

pub(crate) fn is_depth(format: vk::Format) -> bool {
    format_info(format).is_some_and(|f| f.kind == FormatKind::Depth)
}

/// Checks everything about `image` lucent's use of it as `role` at `extent` needs, with the
/// state it is in now and the one it is left in ([`HostImage::left_in`]). `input` names the
/// input for format errors and `format_ok` says which formats the role accepts, `formats` how
/// to say so.
pub(crate) fn check_image(
    gpu: &GpuContext,
    image: &HostImage,
    input: &str,
    role: Role,
    extent: vk::Extent2D,
    format_ok: impl Fn(vk::Format) -> bool,
    formats: &str,
) -> Result<()> {
    if image.image == vk::Image::null() || image.view == vk::ImageView::null() {
        return Err(invalid(
            &image.name,
            ImageFault::Handles,
            "needs an image and a view".into(),
        ));
    }
    // Only a shadow map's faces lie in layers (ShadowFace::layer); lucent reads one layer of
    // everything else.
    if image.layers == 0 || (image.layers > 1 && role != Role::ShadowMap) {
        return Err(invalid(
            &image.name,
            ImageFault::Size,
            format!(
                "has {} array layers; the {input} is one layer (only a shadow map may be an \
                 array)",
                image.layers
            ),
        ));
    }
    // A mip level past the device's largest chain, or layers past u32: no image has them (a
    // mistake, or garbage in the description), and a barrier naming them is invalid.
    let max_mip = 31 - gpu.info.max_image_dimension_2d.max(1).leading_zeros();
    if image.mip > max_mip || image.base_layer.checked_add(image.layers).is_none() {
        return Err(invalid(
            &image.name,
            ImageFault::Size,
            format!(
                "names mip {} and layers {} to {}; this device's images have mips 0 to \
                 {max_mip}",
                image.mip,
                image.base_layer,
                u64::from(image.base_layer) + u64::from(image.layers) - 1
            ),
        ));
    }
    if image.extent != extent {
        return Err(invalid(
            &image.name,
            ImageFault::Size,
            format!(
                "is {}x{}, the frame {}x{}",
                image.extent.width, image.extent.height, extent.width, extent.height
            ),
        ));
    }
    let depth_role = matches!(role, Role::SampledDepth | Role::ShadowMap);
    if !format_ok(image.format) || is_depth(image.format) != depth_role {
        return Err(HostError::Unsupported {
            input: format!("{input} ('{}')", image.name),
            found: format!("format {}", format_name(image.format)),
            accepted: formats.to_string(),
        }
        .into());
    }
    let (usage, flag) = role.usage();
    if !image.usage.contains(usage) {
        return Err(invalid(
            &image.name,
            ImageFault::Usage,
            format!("lacks usage {flag}"),
        ));
    }
    let (feature, feature_name) = role.format_feature();
    // SAFETY: the physical device is valid for the context's lifetime.
    let properties = unsafe {
        gpu.instance
            .get_physical_device_format_properties(gpu.physical_device, image.format)
    };
    if !properties.optimal_tiling_features.contains(feature) {
        return Err(invalid(
            &image.name,
            ImageFault::Format,
            format!(
                "the device cannot use format {} as {feature_name} with optimal tiling",
                format_name(image.format)
            ),
        ));
    }
    check_state(image, &image.state, "current", false)?;
    if role != Role::Output && image.state.layout == vk::ImageLayout::UNDEFINED {
        return Err(invalid(
            &image.name,
            ImageFault::Layout,
            if role == Role::Accumulate {
                "is added to but its current layout is UNDEFINED (its contents would be lost)"
                    .into()
            } else {
                "is an input but its current layout is UNDEFINED (its contents would be lost)"
                    .into()
            },
        ));
    }
    if image.final_state.is_none() && image.state.layout == vk::ImageLayout::UNDEFINED {
        return Err(invalid(
            &image.name,
            ImageFault::Layout,
            "comes in UNDEFINED and says no final state (HostImage::then): lucent cannot \
             leave it as it came"
                .into(),
        ));
    }
    check_state(image, &image.left_in(), "final", true)
}

/// The inputs of one frame, one per distinct Vulkan image (the depth and stencil IDs of one
/// depth-stencil image are transitioned once, so both must declare the same states); an input
/// that is also `output` is refused.
pub(crate) fn distinct_inputs<'a>(
    inputs: impl IntoIterator<Item = &'a HostImage>,
    output: &HostImage,
) -> Result<Vec<&'a HostImage>> {
    let mut distinct: Vec<&HostImage> = Vec::new();
    for image in inputs {
        if image.image == output.image {
            return Err(invalid(
                &output.name,
                ImageFault::Aliased,
                format!("is both an input ('{}') and the output", image.name),
            ));
        }
        match distinct.iter().find(|i| i.image == image.image) {
            Some(first) if first.state != image.state || first.left_in() != image.left_in() => {
                return Err(invalid(
                    &image.name,
                    ImageFault::Aliased,
                    format!(
                        "is the same image as '{}' with other states: one image is in one state",
                        first.name
                    ),
                ))
            }
            Some(_) => {}
            None => distinct.push(image),
        }
    }
    Ok(distinct)
}

/// Records one barrier moving `image` from `from` to `to` (the old contents kept unless
/// `from` is UNDEFINED).
pub(crate) fn record_transition(
    gpu: &GpuContext,
    cmd: vk::CommandBuffer,
    image: &HostImage,
    from: &ImageState,
    to: &ImageState,
) {
    // The aspect the graph's own barriers use for an image of this format.
    let aspect = crate::graph::ImageInfo {
        width: image.extent.width,
        height: image.extent.height,
        format: image.format,
    }
    .aspect();
    let barrier = vk::ImageMemoryBarrier2::default()
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(to.stage)
        .dst_access_mask(to.access)
        .old_layout(from.layout)
        .new_layout(to.layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image.image)
        .subresource_range(image.subresources().vk(aspect));
    let barriers = [barrier];
    let dependency = vk::DependencyInfo::default().image_memory_barriers(&barriers);
    // SAFETY: `cmd` is recording (the caller's contract) and the image is the host's valid
    // image, whose declared states were checked by `check_image`.
    unsafe { gpu.device.cmd_pipeline_barrier2(cmd, &dependency) };
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(format: vk::Format, usage: vk::ImageUsageFlags, state: ImageState) -> HostImage {
        HostImage::new(
            "test",
            vk::Image::null(),
            vk::ImageView::null(),
            format,
            vk::Extent2D {
                width: 4,
                height: 4,
            },
            usage,
        )
        .in_state(state)
    }

    #[test]
    fn a_layout_the_usage_does_not_allow_is_refused_by_name() {
        let img = image(
            vk::Format::R16G16B16A16_SFLOAT,
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
            ImageState::fragment_sampled(),
        );
        let e = check_state(&img, &img.state, "current", false).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("'test'") && text.contains("SHADER_READ_ONLY_OPTIMAL"),
            "{text}"
        );
        // With SAMPLED usage the same state is fine.
        let img = HostImage {
            usage: vk::ImageUsageFlags::SAMPLED,
            ..img
        };
        check_state(&img, &img.state, "current", false).unwrap();
    }

    #[test]
    fn depth_layouts_on_colour_formats_and_back_are_refused() {
        let colour = image(
            vk::Format::R8G8B8A8_UNORM,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            ImageState::depth_attachment(),
        );
        assert!(check_state(&colour, &colour.state, "current", false).is_err());
        let depth = image(
            vk::Format::D32_SFLOAT,
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            ImageState::color_attachment(),
        );
        assert!(check_state(&depth, &depth.state, "current", false).is_err());
        let depth = HostImage {
            usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            state: ImageState::depth_attachment(),
            ..depth
        };
        check_state(&depth, &depth.state, "current", false).unwrap();
    }

    #[test]
    fn accesses_must_match_stages_and_writes_the_layout() {
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        // A colour write declared at the fragment shader stage.
        let wrong_stage = ImageState {
            stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
            ..ImageState::color_attachment()
        };
        let img = image(vk::Format::R8G8B8A8_UNORM, usage, wrong_stage);
        assert!(check_state(&img, &img.state, "current", false).is_err());
        // ALL_COMMANDS covers any access.
        let all = ImageState {
            stage: vk::PipelineStageFlags2::ALL_COMMANDS,
            ..ImageState::color_attachment()
        };
        check_state(&img, &all, "current", false).unwrap();
        // A colour write while in SHADER_READ_ONLY_OPTIMAL: the layout is not the written one.
        let contradiction = ImageState {
            layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
            ..ImageState::color_attachment()
        };
        let e = check_state(&img, &contradiction, "current", false).unwrap_err();
        assert!(e.to_string().contains("cannot hold"), "{e}");
    }

    #[test]
    fn final_states_cannot_be_undefined_and_odd_layouts_are_refused() {
        let img = image(
            vk::Format::R8G8B8A8_UNORM,
            vk::ImageUsageFlags::COLOR_ATTACHMENT,
            ImageState::UNDEFINED,
        );
        check_state(&img, &ImageState::UNDEFINED, "current", false).unwrap();
        assert!(check_state(&img, &ImageState::UNDEFINED, "final", true).is_err());
        let odd = ImageState {
            layout: vk::ImageLayout::FRAGMENT_SHADING_RATE_ATTACHMENT_OPTIMAL_KHR,
            ..ImageState::UNDEFINED
        };
        assert!(check_state(&img, &odd, "current", false).is_err());
    }
}
