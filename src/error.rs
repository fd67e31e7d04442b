//! The one error type of lucent.
//!
//! Every fallible function returns [`Result`]. Variants carry enough context to print a one-line
//! reason a user can act on (which file, which pass, which missing feature, which package to
//! install); nothing in the library panics on bad input or on a missing driver. Sizes in
//! messages are written by [`format_bytes`].

use std::path::PathBuf;

/// Everything that can go wrong in lucent. New kinds of error may be added: match it with a
/// wildcard arm.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LucentError {
    /// The Vulkan loader library (libvulkan) could not be loaded at all.
    #[error(
        "Vulkan loader not found ({0}); install it: apt-get install libvulkan1 mesa-vulkan-drivers"
    )]
    NoVulkanLoader(String),
    /// The loader works but no driver (ICD) offers a usable device.
    #[error("no Vulkan driver found{0}; install one: apt-get install mesa-vulkan-drivers (lavapipe, CPU) or your GPU vendor's driver")]
    NoVulkanDriver(String),
    /// No physical device matched `--device SUBSTRING`.
    #[error("no Vulkan device matches '{wanted}'; available: {available}")]
    NoMatchingDevice { wanted: String, available: String },
    /// The chosen device lacks something lucent needs.
    #[error("device '{device}' lacks required feature: {feature}")]
    MissingFeature { device: String, feature: String },
    /// The validation layer was requested but is not installed.
    #[error("Vulkan validation layer VK_LAYER_KHRONOS_validation not found; install it: apt-get install vulkan-validationlayers")]
    NoValidationLayer,
    /// A Vulkan call failed.
    #[error("Vulkan call {call} failed: {result:?}")]
    Vulkan {
        call: &'static str,
        result: ash::vk::Result,
    },
    /// GPU memory allocation failed: what for, how much, and what to try.
    #[error(
        "GPU memory allocation '{name}' of {size} failed: {source}; render at a smaller --size \
         (the frame's images grow with it) or use smaller textures",
        size = format_bytes(*.bytes)
    )]
    Allocation {
        name: String,
        /// Bytes asked for.
        bytes: u64,
        #[source]
        source: gpu_allocator::AllocationError,
    },
    /// A host engine's own allocator (`lucent::embed::HostAllocator`) could not give the
    /// memory of one of lucent's resources.
    #[error(
        "the host's allocator could not give '{name}' {size}: {result:?}",
        size = format_bytes(*.bytes)
    )]
    HostAllocation {
        /// The resource the memory was for.
        name: String,
        /// Bytes asked for.
        bytes: u64,
        /// What the host's allocator returned.
        result: ash::vk::Result,
    },
    /// A shader failed to compile; `message` carries file:line diagnostics from shaderc.
    #[error("shader {path} failed to compile:\n{message}")]
    ShaderCompile { path: String, message: String },
    /// A shader permutation (path and defines, as one `glsl/permutations.txt` line) that the
    /// shipped SPIR-V bundle does not hold.
    #[error(
        "shader permutation not in the shipped SPIR-V: {permutation}; glsl/permutations.txt is \
         stale (or the permutation is not one lucent's frames build): regenerate it with `{}` \
         and rebuild",
        MANIFEST_COMMAND
    )]
    ShaderNotShipped { permutation: String },
    /// The shipped SPIR-V bundle holds no shader at all: this build was made while
    /// `glsl/permutations.txt` was being regenerated (`LUCENT_WRITE_MANIFEST` set, which makes
    /// `build.rs` compile nothing), so every permutation is missing until the next build.
    #[error(
        "shader permutation {permutation}: this build of lucent ships no SPIR-V at all; it was \
         built with LUCENT_WRITE_MANIFEST set (`{}` regenerates glsl/permutations.txt and \
         compiles no shader): rebuild without it",
        MANIFEST_COMMAND
    )]
    ShadersNotBuilt { permutation: String },
    /// A shader's descriptor bindings disagree with what its pass declares
    /// (`crate::backend::bindings`): a resource the pass binds under no name or number, or
    /// of another kind.
    #[error("pipeline '{pipeline}': {shader}: {message}")]
    ShaderBindings {
        pipeline: String,
        shader: String,
        message: String,
    },
    /// The render graph is malformed (e.g. a pass reads a resource nothing wrote).
    #[error("render graph: {0}")]
    Graph(String),
    /// A named scene or technique does not exist, or an option is out of range.
    #[error("{0}")]
    InvalidInput(String),
    /// Timing could not be trusted (the benchmark refuses to print numbers it cannot prove).
    #[error("timing: {0}")]
    Timing(String),
    /// The GPU stopped answering (driver crash, reset, hang): nothing on it can be trusted or
    /// continued. Commands exit non-zero instead of retrying.
    #[error(
        "the GPU device was lost during {call} (driver crash or reset); lucent cannot continue"
    )]
    DeviceLost { call: &'static str },
    /// The window's surface went away (the window system closed it or the display died).
    #[error("the window surface was lost during {call} (the display or window went away)")]
    SurfaceLost { call: &'static str },
    /// Reading or writing a file failed.
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    /// A host engine's description or images cannot be used as given (`lucent::embed`),
    /// refused before anything was recorded.
    #[error(transparent)]
    Host(#[from] HostError),
}

/// What is wrong with what a host engine gave lucent (`lucent::embed`): typed, so a host can
/// match on the kind of mistake, each naming the input at fault and, where there is a choice,
/// what lucent would accept. Refused before any command is recorded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum HostError {
    /// An input's format (or its encoding: a depth convention, an ID bit field) is not one
    /// lucent reads for it.
    #[error("{input}: {found} cannot be used here; lucent accepts {accepted}")]
    Unsupported {
        /// The input (`"depth"`, `"material IDs"`, `"output"`, ...).
        input: String,
        /// What was given.
        found: String,
        /// What would be accepted.
        accepted: String,
    },
    /// An effect needs an input the host did not describe or give.
    #[error("{input} is missing: {needed_by}")]
    Missing {
        /// The input.
        input: String,
        /// Who needs it, and why.
        needed_by: String,
    },
    /// A host image cannot be used as declared.
    #[error("host image '{image}': {problem}")]
    Image {
        /// The image's name (`HostImage::name`).
        image: String,
        /// Which check it failed.
        kind: ImageFault,
        /// What exactly.
        problem: String,
    },
    /// A frame slot or view index outside what the effect was built for.
    #[error("{what} {index}: the effect was built for {count} (0..{count})")]
    OutOfRange {
        /// `"frame slot"` or `"view"`.
        what: &'static str,
        /// The index given.
        index: usize,
        /// How many there are.
        count: usize,
    },
    /// Memory a host's own allocator (`lucent::embed::HostAllocator`) returned that the
    /// resource cannot use (null, too small, misaligned, not mapped where lucent writes or
    /// reads it); the allocation was handed back to the allocator's `free`.
    #[error("host allocation for '{allocation}': {problem}")]
    Memory {
        /// The resource the memory was for.
        allocation: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A description's value out of range (a size, a count, a scale, a camera matrix).
    #[error("{field}: {problem}")]
    Description {
        /// The field.
        field: String,
        /// What is wrong with it.
        problem: String,
    },
}

/// Which check a host image failed ([`HostError::Image`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum ImageFault {
    /// A null image or view.
    Handles,
    /// Not the size the effect was built for.
    Size,
    /// Created without a usage flag lucent's use of it needs.
    Usage,
    /// A declared layout the image's usage or aspect does not allow, or one no image can be
    /// left in.
    Layout,
    /// A declared access its stages cannot perform, or its layout cannot hold.
    Access,
    /// Not the format the effect was built for, or one the device cannot use in that role.
    Format,
    /// The same image as two inputs with different states, or as an input and the output.
    Aliased,
}

/// The command that regenerates `glsl/permutations.txt`, the shipped SPIR-V's manifest (named
/// by [`LucentError::ShaderNotShipped`], the manifest's header and its test).
pub const MANIFEST_COMMAND: &str =
    "LUCENT_WRITE_MANIFEST=1 cargo test --test cpu shipped_shaders::";

/// Result with [`LucentError`].
pub type Result<T, E = LucentError> = std::result::Result<T, E>;

/// Adds the name of the Vulkan call to an `ash` result: `unsafe { device.f(..) }.vk("vkF")?`.
pub trait VkResultExt<T> {
    /// Converts a `VkResult` into a lucent [`Result`] naming `call`.
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkResultExt<T> for std::result::Result<T, ash::vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| LucentError::vulkan(call, result))
    }
}

impl LucentError {
    /// The error for a failed Vulkan call: device and surface loss get their own variants (a
    /// clear message, never a retry), everything else is [`LucentError::Vulkan`].
    pub fn vulkan(call: &'static str, result: ash::vk::Result) -> Self {
        match result {
            ash::vk::Result::ERROR_DEVICE_LOST => LucentError::DeviceLost { call },
            ash::vk::Result::ERROR_SURFACE_LOST_KHR => LucentError::SurfaceLost { call },
            result => LucentError::Vulkan { call, result },
        }
    }

    /// A file error from an `std::io::Error` (or anything displayable), naming the path.
    pub fn file(path: impl Into<PathBuf>, message: impl std::fmt::Display) -> Self {
        LucentError::File {
            path: path.into(),
            message: message.to_string(),
        }
    }
}

/// The value named `name` in a table of command-line names (`ALL` of `crate::frame::Technique`,
/// the benchmark's formats, `crate::features::antialias::Antialias`), or the error
/// `unknown WHAT 'NAME'; available: a, b, c`.
pub fn parse_named<T: Copy>(table: &[(&str, T)], name: &str, what: &str) -> Result<T> {
    table
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(_, value)| value)
        .ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "unknown {what} '{name}'; available: {}",
                table.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
            ))
        })
}

/// The name of `value` in a table of command-line names (`?` when it is not there).
pub fn name_of<T: PartialEq>(table: &[(&'static str, T)], value: &T) -> &'static str {
    table
        .iter()
        .find(|(_, v)| v == value)
        .map_or("?", |(n, _)| n)
}

/// `bytes` for a message: exact below 1 KiB, else in KiB, MiB or GiB with the exact count.
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if bytes >= size {
            let value = bytes as f64 / size as f64;
            return if bytes.is_multiple_of(size) {
                format!("{} {unit}", bytes / size)
            } else {
                format!("{value:.1} {unit} ({bytes} bytes)")
            };
        }
    }
    format!("{bytes} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn out_of_memory_names_the_resource_its_size_and_what_to_try() {
        let e = LucentError::Allocation {
            name: "graph slot 9: sss.temp, hdr".into(),
            bytes: 4 << 30,
            source: gpu_allocator::AllocationError::OutOfMemory,
        }
        .to_string();
        assert!(
            e.contains("'graph slot 9: sss.temp, hdr'")
                && e.contains("4 GiB")
                && e.contains("smaller --size"),
            "{e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }

    #[test]
    fn byte_counts_read_well() {
        assert_eq!(format_bytes(12), "12 bytes");
        assert_eq!(format_bytes(4 << 20), "4 MiB");
        assert_eq!(format_bytes(1536), "1.5 KiB (1536 bytes)");
    }
}
