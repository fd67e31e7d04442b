//! SPIR-V as the shader compilers hand it out: the stage a file compiles to (from its
//! extension) and a [`CompiledShader`], whichever compiler made it (the shipped bundle or the
//! run-time one, both in [`super::shader`]).

use std::path::{Path, PathBuf};

use ash::vk;

/// The SPIR-V magic number, first word of every module.
pub(crate) const SPIRV_MAGIC: u32 = 0x0723_0203;

/// A programmable pipeline stage, decided by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ShaderStage {
    /// `.vert`
    Vertex,
    /// `.frag`
    Fragment,
    /// `.comp`
    Compute,
}

impl ShaderStage {
    /// The stage for a file name ending in `.vert`, `.frag` or `.comp`; `None` for anything else.
    pub fn from_path(path: impl AsRef<Path>) -> Option<Self> {
        match path.as_ref().extension()?.to_str()? {
            "vert" => Some(Self::Vertex),
            "frag" => Some(Self::Fragment),
            "comp" => Some(Self::Compute),
            _ => None,
        }
    }

    /// The Vulkan stage flag, for pipeline stage create infos and descriptor set layouts.
    pub fn vk_stage(self) -> vk::ShaderStageFlags {
        match self {
            Self::Vertex => vk::ShaderStageFlags::VERTEX,
            Self::Fragment => vk::ShaderStageFlags::FRAGMENT,
            Self::Compute => vk::ShaderStageFlags::COMPUTE,
        }
    }

    /// The file extension (without dot), also used as the stage's name in cache keys.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Vertex => "vert",
            Self::Fragment => "frag",
            Self::Compute => "comp",
        }
    }
}

/// What [`ShaderCompiler::compile`](super::shader::ShaderCompiler::compile) gives.
#[derive(Debug, Clone)]
pub struct CompiledShader {
    /// SPIR-V words, ready for
    /// [`create_shader_module`](super::shader::create_shader_module).
    pub spirv: Vec<u32>,
    /// The stage, from the file extension.
    pub stage: ShaderStage,
    /// Absolute paths of the main file (first) and every file it included, each once (empty
    /// for shipped SPIR-V: no file is read).
    pub dependencies: Vec<PathBuf>,
    /// True when the SPIR-V came from the run-time compiler's disk cache and glslang did not
    /// run (false for shipped SPIR-V).
    pub from_cache: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_from_extension() {
        assert_eq!(
            ShaderStage::from_path("a/b.vert"),
            Some(ShaderStage::Vertex)
        );
        assert_eq!(
            ShaderStage::from_path("b.frag"),
            Some(ShaderStage::Fragment)
        );
        assert_eq!(ShaderStage::from_path("b.comp"), Some(ShaderStage::Compute));
        assert_eq!(ShaderStage::from_path("common/b.glsl"), None);
        assert_eq!(
            ShaderStage::Compute.vk_stage(),
            vk::ShaderStageFlags::COMPUTE
        );
    }
}
