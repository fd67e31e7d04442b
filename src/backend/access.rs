//! The one access table: every way a pass can touch a resource, and what Vulkan needs to know
//! about it (pipeline stage, access mask, image layout, usage flag).
//!
//! The render graph derives every barrier, layout transition, subpass dependency and usage flag
//! from this table and nothing else, so a new kind of access is added here, once.

use ash::vk;

/// How a pass touches a resource. One value per declared read or write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Written as a colour attachment of a raster pass.
    ColorAttachmentWrite,
    /// Written (and depth-tested) as the depth attachment of a raster pass.
    DepthAttachmentWrite,
    /// Depth-tested without writing (read-only depth attachment).
    DepthAttachmentRead,
    /// Read at the same pixel as an input attachment (`subpassLoad`), colour aspect.
    InputAttachmentRead,
    /// Read at the same pixel as an input attachment, depth aspect.
    DepthInputAttachmentRead,
    /// Sampled (any texel: neighbourhood reads) in a fragment shader.
    FragmentSampledRead,
    /// Sampled in a compute shader.
    ComputeSampledRead,
    /// Read as a storage image in a compute shader.
    ComputeStorageRead,
    /// Written as a storage image in a compute shader.
    ComputeStorageWrite,
    /// Source of a copy or blit.
    TransferRead,
    /// Destination of a copy, blit or clear.
    TransferWrite,
    /// Handed to the presentation engine.
    Present,
    /// Not yet touched (or contents discarded): the state every transient image starts in.
    Undefined,
}

/// What Vulkan needs to know about one [`Access`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccessInfo {
    /// Pipeline stages that perform the access.
    pub stage: vk::PipelineStageFlags2,
    /// Memory access bits of the access.
    pub access: vk::AccessFlags2,
    /// Image layout the access needs.
    pub layout: vk::ImageLayout,
    /// Image usage flag the image must be created with.
    pub usage: vk::ImageUsageFlags,
    /// Whether the access writes memory (a later access needs a memory dependency on it).
    pub writes: bool,
}

impl Access {
    /// Whether a pass reads or writes the image through a descriptor (sampled, storage or
    /// input attachment), not as an attachment or a transfer's image.
    pub fn through_descriptors(self) -> bool {
        matches!(
            self,
            Access::InputAttachmentRead
                | Access::DepthInputAttachmentRead
                | Access::FragmentSampledRead
                | Access::ComputeSampledRead
                | Access::ComputeStorageRead
                | Access::ComputeStorageWrite
        )
    }

    /// The table. Depth layouts are the combined DEPTH_STENCIL ones, which need no
    /// `separateDepthStencilLayouts` feature. Depth attachments test in both fragment-test stages; load/store ops of
    /// attachments happen in those same stages, so barriers against them cover the ops too.
    pub fn info(self) -> AccessInfo {
        use vk::AccessFlags2 as A;
        use vk::ImageLayout as L;
        use vk::ImageUsageFlags as U;
        use vk::PipelineStageFlags2 as S;
        let depth_tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
        let (stage, access, layout, usage, writes) = match self {
            Access::ColorAttachmentWrite => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
                L::COLOR_ATTACHMENT_OPTIMAL,
                U::COLOR_ATTACHMENT,
                true,
            ),
            Access::DepthAttachmentWrite => (
                depth_tests,
                A::DEPTH_STENCIL_ATTACHMENT_WRITE | A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                U::DEPTH_STENCIL_ATTACHMENT,
                true,
            ),
            Access::DepthAttachmentRead => (
                depth_tests,
                A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                U::DEPTH_STENCIL_ATTACHMENT,
                false,
            ),
            // An input attachment is also an attachment of its render pass: its load op
            // (LOAD) reads it in the colour-output stage before the shader does.
            Access::InputAttachmentRead => (
                S::FRAGMENT_SHADER | S::COLOR_ATTACHMENT_OUTPUT,
                A::INPUT_ATTACHMENT_READ | A::COLOR_ATTACHMENT_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                U::INPUT_ATTACHMENT,
                false,
            ),
            // Likewise a depth input attachment is loaded in the fragment-test stages.
            Access::DepthInputAttachmentRead => (
                S::FRAGMENT_SHADER | depth_tests,
                A::INPUT_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_READ,
                L::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                U::INPUT_ATTACHMENT,
                false,
            ),
            Access::FragmentSampledRead => (
                S::FRAGMENT_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                U::SAMPLED,
                false,
            ),
            Access::ComputeSampledRead => (
                S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                U::SAMPLED,
                false,
            ),
            Access::ComputeStorageRead => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ,
                L::GENERAL,
                U::STORAGE,
                false,
            ),
            Access::ComputeStorageWrite => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_WRITE | A::SHADER_STORAGE_READ,
                L::GENERAL,
                U::STORAGE,
                true,
            ),
            Access::TransferRead => (
                S::ALL_TRANSFER,
                A::TRANSFER_READ,
                L::TRANSFER_SRC_OPTIMAL,
                U::TRANSFER_SRC,
                false,
            ),
            Access::TransferWrite => (
                S::ALL_TRANSFER,
                A::TRANSFER_WRITE,
                L::TRANSFER_DST_OPTIMAL,
                U::TRANSFER_DST,
                true,
            ),
            // The presentation engine's own wait is a semaphore: no stage or access to name.
            Access::Present => (S::NONE, A::NONE, L::PRESENT_SRC_KHR, U::empty(), false),
            Access::Undefined => (S::NONE, A::NONE, L::UNDEFINED, U::empty(), false),
        };
        AccessInfo {
            stage,
            access,
            layout,
            usage,
            writes,
        }
    }

    /// Short name used in plan dumps.
    pub fn short_name(self) -> &'static str {
        match self {
            Access::ColorAttachmentWrite => "color-write",
            Access::DepthAttachmentWrite => "depth-write",
            Access::DepthAttachmentRead => "depth-read",
            Access::InputAttachmentRead => "input",
            Access::DepthInputAttachmentRead => "depth-input",
            Access::FragmentSampledRead => "sampled(frag)",
            Access::ComputeSampledRead => "sampled(comp)",
            Access::ComputeStorageRead => "storage-read",
            Access::ComputeStorageWrite => "storage-write",
            Access::TransferRead => "transfer-src",
            Access::TransferWrite => "transfer-dst",
            Access::Present => "present",
            Access::Undefined => "undefined",
        }
    }

    /// Whether this access happens inside a render pass as an attachment (same-pixel).
    pub fn is_attachment(self) -> bool {
        matches!(
            self,
            Access::ColorAttachmentWrite
                | Access::DepthAttachmentWrite
                | Access::DepthAttachmentRead
                | Access::InputAttachmentRead
                | Access::DepthInputAttachmentRead
        )
    }
}

/// Whether a depth format also has a stencil aspect.
pub fn has_stencil(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::D24_UNORM_S8_UINT
            | vk::Format::D32_SFLOAT_S8_UINT
            | vk::Format::D16_UNORM_S8_UINT
    )
}

/// Whether `format` is a depth format (decides the image aspect).
pub fn is_depth_format(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::D16_UNORM
            | vk::Format::D32_SFLOAT
            | vk::Format::D24_UNORM_S8_UINT
            | vk::Format::D32_SFLOAT_S8_UINT
            | vk::Format::X8_D24_UNORM_PACK32
    )
}
