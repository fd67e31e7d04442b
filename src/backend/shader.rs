//! Shaders: where pipelines get their SPIR-V ([`ShaderCompiler`]), shader modules, and the Vulkan
//! pipeline cache.
//!
//! # When to use what
//!
//! - [`ShaderCompiler::shipped`]: the SPIR-V compiled with the crate. `build.rs` compiles every
//!   permutation in `glsl/permutations.txt` (a shader path and its defines per line) with shaderc
//!   into a bundle the library embeds, so a host needs neither `glsl/` nor shaderc at run time.
//!   That manifest is generated from [`crate::shipped::permutations`], which enumerates
//!   every permutation any frame lucent can build may ask for; a test fails when the committed
//!   file differs from it. Asking for a permutation the bundle lacks is
//!   [`LucentError::ShaderNotShipped`]. This is what the `lucent` command, the tests and an
//!   embedding host use.
//! - `ShaderCompiler::new` (feature `runtime-shaders`, on by default): compiles a GLSL file
//!   under the GLSL root (`glsl/` in the repository, or `LUCENT_GLSL_DIR`) at run time. The
//!   demo uses it so that edited shaders reload while it runs; `tests/gpu/shaders.rs` uses it to
//!   compile what is not in a frame. The stage comes from the extension (`.vert`, `.frag`,
//!   `.comp`), the GLSL version from the file's `#version` line. `#include "x.glsl"` is looked
//!   up next to the including file first, then under the GLSL root, so
//!   `#include "common/gbuffer.glsl"` works from any directory. Keep one compiler for the whole
//!   program: creating a shaderc compiler is costly.
//! - Both take macro permutations as `defines` through the same [`ShaderCompiler::compile`];
//!   pipelines (`features/util.rs`) do not know which kind they have.
//! - The run-time compiler's SPIR-V disk cache (the `cache_dir` of `ShaderCompiler::new`, by
//!   default [`crate::files::default_cache_dir`], never the source tree) skips glslang
//!   entirely when nothing changed; see `shader_runtime.rs`. Pass `None` to always compile
//!   (tests that must see the compiler run). One case is not detected: a new file that would
//!   shadow an include previously found elsewhere (e.g. a new `pass/x.glsl` beside a shader
//!   that included the root's `x.glsl`); delete the cache directory after such a move.
//! - [`CompiledShader::dependencies`] lists the main file and every include (absolute paths), which
//!   is what a hot-reloader watches.
//! - [`create_shader_module`] wraps the SPIR-V in a `VkShaderModule`. The SPIR-V targets
//!   Vulkan 1.3 / SPIR-V 1.6, so the device must enable `maintenance4` (DESIGN.md, "Facts measured").
//! - [`PipelineCache`] is the driver's own pipeline cache (compiled machine code), loaded from and
//!   saved to one file. It is independent of the SPIR-V: that saves glslang time, this one
//!   saves the driver's time in `vkCreate*Pipelines`. A file written by another driver or device is
//!   detected from its header and ignored. [`PipelineCache::load_default`] keeps it in the
//!   default cache directory, [`PipelineCache::load_for_device`] wherever the host says.
//!
//! Compile errors (run time, or `build.rs` for the shipped bundle) are
//! [`LucentError::ShaderCompile`] whose message holds shaderc's `file:line: error: ...` lines,
//! with files named relative to the GLSL root (an error inside an include names the include, not
//! the shader that included it).

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ash::vk;

use super::shader_files::{decode_bundle, define_problem};
pub(crate) use super::shader_files::{permutation_line, shader_name};
#[cfg(feature = "runtime-shaders")]
use super::shader_runtime::RuntimeCompiler;
use super::spirv::{CompiledShader, ShaderStage, SPIRV_MAGIC};
use crate::error::{LucentError, Result, VkResultExt};
use crate::files::{read_optional, write_file_atomic};

/// The bundle `build.rs` compiled from `glsl/permutations.txt`.
static SHIPPED_BUNDLE: &[u8] = include_bytes!(concat!(env!("OUT_DIR"), "/shaders.bundle"));

/// Largest pipeline cache file read.
const MAX_PIPELINE_CACHE_BYTES: u64 = 1 << 30;

/// The decoded shipped bundle: permutation line -> module, and the modules.
struct ShippedBundle {
    index: HashMap<String, u32>,
    modules: Vec<Vec<u32>>,
}

/// The embedded bundle, decoded on first use.
fn shipped_bundle() -> Result<&'static ShippedBundle> {
    static BUNDLE: OnceLock<std::result::Result<ShippedBundle, String>> = OnceLock::new();
    BUNDLE
        .get_or_init(|| {
            decode_bundle(SHIPPED_BUNDLE).map(|b| ShippedBundle {
                index: b.entries.into_iter().collect(),
                modules: b.modules,
            })
        })
        .as_ref()
        .map_err(|e| {
            LucentError::InvalidInput(format!("the shipped SPIR-V bundle is corrupt: {e}"))
        })
}

/// The error for a permutation the shipped bundle lacks: a stale manifest, or (`empty`: the
/// bundle holds nothing) a build made while the manifest was being regenerated.
fn not_shipped(empty: bool, permutation: String) -> LucentError {
    if empty {
        LucentError::ShadersNotBuilt { permutation }
    } else {
        LucentError::ShaderNotShipped { permutation }
    }
}

/// Where a [`ShaderCompiler`] gets SPIR-V.
#[derive(Debug)]
enum Source {
    /// The embedded bundle.
    Shipped,
    /// shaderc at run time.
    #[cfg(feature = "runtime-shaders")]
    Runtime(RuntimeCompiler),
}

/// Gives pipelines their SPIR-V: from the bundle compiled with the crate
/// ([`ShaderCompiler::shipped`]) or, with the `runtime-shaders` feature, from GLSL files compiled
/// at run time (`ShaderCompiler::new`). See the module docs.
///
/// `ShaderCompiler` is `Send + Sync`; one instance can serve several threads.
#[derive(Debug)]
pub struct ShaderCompiler {
    source: Source,
}

impl ShaderCompiler {
    /// Serves the SPIR-V compiled with the crate (no GLSL files, no shaderc). Fails only when
    /// the embedded bundle is corrupt.
    pub fn shipped() -> Result<Self> {
        shipped_bundle()?;
        Ok(Self {
            source: Source::Shipped,
        })
    }

    /// A run-time compiler for the GLSL files under `glsl_root`, caching SPIR-V in `cache_dir`
    /// if given (feature `runtime-shaders`).
    ///
    /// Fails when `glsl_root` is not a directory or shaderc cannot be initialised. The cache
    /// directory is created on first use; if it cannot be, compiles still work (with a warning).
    #[cfg(feature = "runtime-shaders")]
    pub fn new(glsl_root: impl Into<PathBuf>, cache_dir: Option<PathBuf>) -> Result<Self> {
        Ok(Self {
            source: Source::Runtime(RuntimeCompiler::new(glsl_root.into(), cache_dir)?),
        })
    }

    /// The GLSL root a run-time compiler uses when none is given: `$LUCENT_GLSL_DIR`; else the
    /// first shader tree found from the running executable: `glsl/` beside it,
    /// `../share/lucent/glsl` (an installed layout), or `glsl/` in a directory above it (the
    /// repository a `target/` build runs from: `cargo run`, the tests); else the source tree the
    /// library was compiled from, when it still exists. A tree is recognised by its
    /// `fullscreen.vert`. Only run-time compilation reads GLSL: shipped SPIR-V needs no tree.
    #[cfg(feature = "runtime-shaders")]
    pub fn default_glsl_root() -> PathBuf {
        if let Some(dir) = std::env::var_os("LUCENT_GLSL_DIR").filter(|d| !d.is_empty()) {
            return PathBuf::from(dir);
        }
        let compiled_from = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
        let exe_dir = std::env::current_exe()
            .ok()
            .and_then(|exe| exe.canonicalize().ok())
            .and_then(|exe| exe.parent().map(Path::to_path_buf));
        if let Some(dir) = exe_dir {
            let beside = [dir.join("glsl"), dir.join("../share/lucent/glsl")];
            let above = dir.ancestors().skip(1).map(|a| a.join("glsl"));
            if let Some(found) = beside
                .into_iter()
                .chain(above)
                .find(|d| Self::is_glsl_root(d))
            {
                return found;
            }
        }
        compiled_from
    }

    /// Whether `dir` is a GLSL tree (a copy of the repository's `glsl/`), recognised by its
    /// [`FULLSCREEN_VERTEX`].
    pub fn is_glsl_root(dir: &Path) -> bool {
        dir.join(FULLSCREEN_VERTEX).is_file()
    }

    /// Whether this compiler serves the shipped bundle (no GLSL is read).
    pub fn is_shipped(&self) -> bool {
        matches!(self.source, Source::Shipped)
    }

    /// The (absolute) GLSL root directory of a run-time compiler; `None` for shipped SPIR-V.
    pub fn glsl_root(&self) -> Option<&Path> {
        match &self.source {
            Source::Shipped => None,
            #[cfg(feature = "runtime-shaders")]
            Source::Runtime(r) => Some(&r.glsl_root),
        }
    }

    /// The SPIR-V cache directory of a run-time compiler, if caching is on.
    pub fn cache_dir(&self) -> Option<&Path> {
        match &self.source {
            Source::Shipped => None,
            #[cfg(feature = "runtime-shaders")]
            Source::Runtime(r) => r.cache_dir.as_deref(),
        }
    }

    /// The SPIR-V of `path` (relative to the GLSL root, `/`-separated, e.g.
    /// `"smoke/gbuffer.frag"`) with the given macro definitions (`("NAME", "VALUE")`; an empty
    /// value defines the name as empty; when a name repeats, the last value wins).
    ///
    /// Errors: an unknown extension or a bad define is [`LucentError::InvalidInput`]; shipped,
    /// a permutation the bundle lacks is [`LucentError::ShaderNotShipped`]; at run time, an
    /// unreadable main file is [`LucentError::File`], and a GLSL error (including a missing
    /// include) is [`LucentError::ShaderCompile`] with shaderc's `file:line: error:` lines.
    pub fn compile(&self, path: &str, defines: &[(&str, &str)]) -> Result<CompiledShader> {
        let stage = ShaderStage::from_path(path).ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "shader {path}: unknown stage; the file name must end in .vert, .frag or .comp"
            ))
        })?;
        let name = shader_name(path).ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "shader {path}: the path must be relative to the GLSL root and stay inside it"
            ))
        })?;
        let defines = sorted_defines(path, defines, self.is_shipped())?;
        match &self.source {
            Source::Shipped => {
                let bundle = shipped_bundle()?;
                let line = permutation_line(&name, defines.iter().map(|(n, v)| (*n, *v)));
                let module = bundle
                    .index
                    .get(&line)
                    .ok_or_else(|| not_shipped(bundle.index.is_empty(), line.clone()))?;
                Ok(CompiledShader {
                    spirv: bundle.modules[*module as usize].clone(),
                    stage,
                    dependencies: Vec::new(),
                    from_cache: false,
                })
            }
            #[cfg(feature = "runtime-shaders")]
            Source::Runtime(runtime) => runtime.compile(&name, stage, &defines),
        }
    }

    /// Every permutation line the shipped bundle holds, sorted (what `glsl/permutations.txt`
    /// held when the crate was built).
    pub fn shipped_permutations() -> Result<Vec<String>> {
        let mut lines: Vec<String> = shipped_bundle()?.index.keys().cloned().collect();
        lines.sort();
        Ok(lines)
    }
}

/// Validates defines and orders them by name (last value of a repeated name wins, as in
/// shaderc). `line_safe`: values must also fit a permutation line (no whitespace).
pub(crate) fn sorted_defines<'a>(
    path: &str,
    defines: &[(&'a str, &'a str)],
    line_safe: bool,
) -> Result<BTreeMap<&'a str, &'a str>> {
    let mut sorted = BTreeMap::new();
    for &(name, value) in defines {
        if let Some(problem) = define_problem(name, value, line_safe) {
            return Err(LucentError::InvalidInput(format!(
                "shader {path}: {problem}"
            )));
        }
        sorted.insert(name, value);
    }
    Ok(sorted)
}

/// The vertex shader of every fullscreen pass: one triangle covering the render area, from
/// `gl_VertexIndex` alone (no vertex buffer). Its presence also marks a GLSL root
/// (`ShaderCompiler::default_glsl_root`).
pub const FULLSCREEN_VERTEX: &str = "fullscreen.vert";

/// The shaders one graphics pipeline compiles: its vertex and fragment shader, both with the
/// same defines (as `backend::pipeline::GraphicsPipeline::new` compiles them). What each pass's
/// `shader_permutations` lists for the shipped SPIR-V (`crate::shipped`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PipelineShaders {
    /// Vertex shader path under `glsl/`.
    pub vertex: String,
    /// Fragment shader path under `glsl/`.
    pub fragment: String,
    /// The defines, in the order the pass gives them.
    pub defines: Vec<(String, String)>,
}

impl PipelineShaders {
    /// A pipeline of `vertex` and `fragment` with `defines`.
    pub fn new(vertex: &str, fragment: &str, defines: &[(&str, &str)]) -> Self {
        Self {
            vertex: vertex.to_string(),
            fragment: fragment.to_string(),
            defines: defines
                .iter()
                .map(|(n, v)| (n.to_string(), v.to_string()))
                .collect(),
        }
    }

    /// A fullscreen pass's pipeline: [`FULLSCREEN_VERTEX`] and `fragment`.
    pub fn fullscreen(fragment: &str, defines: &[(&str, &str)]) -> Self {
        Self::new(FULLSCREEN_VERTEX, fragment, defines)
    }
}

/// Creates a `VkShaderModule` from SPIR-V words (e.g. [`CompiledShader::spirv`]).
///
/// The caller destroys it (`vkDestroyShaderModule`), usually right after creating the pipelines.
pub fn create_shader_module(device: &ash::Device, spirv: &[u32]) -> Result<vk::ShaderModule> {
    if spirv.first() != Some(&SPIRV_MAGIC) {
        return Err(LucentError::InvalidInput(
            "create_shader_module: the words are not SPIR-V (bad magic number)".to_string(),
        ));
    }
    let info = vk::ShaderModuleCreateInfo::default().code(spirv);
    // SAFETY: `info` points at valid SPIR-V words that outlive the call.
    unsafe { device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")
}

/// Size of `VkPipelineCacheHeaderVersionOne`: header length, header version, vendor id, device id
/// (4 bytes each) and the 16-byte pipeline cache UUID.
const PIPELINE_CACHE_HEADER_SIZE: usize = 32;

/// The driver's pipeline cache, persisted to one file between runs.
///
/// Create it with [`PipelineCache::load`] (or [`PipelineCache::load_for_device`], which also
/// checks that the file was written for this exact device), pass [`PipelineCache::handle`] to
/// every `vkCreate*Pipelines`, [`PipelineCache::save`] before shutdown and then
/// [`PipelineCache::destroy`].
#[derive(Debug)]
pub struct PipelineCache {
    /// The Vulkan pipeline cache object.
    pub handle: vk::PipelineCache,
    path: Option<PathBuf>,
}

impl PipelineCache {
    /// Creates a pipeline cache seeded from `path` when that file exists and looks valid.
    ///
    /// A missing file starts an empty cache; a file with a malformed header, or one the driver
    /// rejects, logs a warning and starts an empty cache. `None` gives a cache that is never saved.
    /// Vulkan itself ignores data whose vendor, device or UUID differ from the device's; use
    /// [`PipelineCache::load_for_device`] to check that here too and get a warning when it happens.
    pub fn load(device: &ash::Device, path: Option<PathBuf>) -> Result<Self> {
        Self::load_checked(device, path, None)
    }

    /// The device's cache in the default cache directory
    /// ([`crate::files::default_cache_dir`]`/pipelines.bin`), checked against the device as
    /// [`PipelineCache::load_for_device`] does: what every command and the demo use.
    pub fn load_default(gpu: &crate::backend::GpuContext) -> Result<Self> {
        // SAFETY: the physical device handle belongs to this instance.
        let properties = unsafe {
            gpu.instance
                .get_physical_device_properties(gpu.physical_device)
        };
        Self::load_for_device(
            &gpu.device,
            Some(crate::files::default_cache_dir().join("pipelines.bin")),
            &properties,
        )
    }

    /// Like [`PipelineCache::load`], and also ignores (with a warning) a file whose header names
    /// another vendor, device or pipeline cache UUID than `properties`.
    pub fn load_for_device(
        device: &ash::Device,
        path: Option<PathBuf>,
        properties: &vk::PhysicalDeviceProperties,
    ) -> Result<Self> {
        Self::load_checked(device, path, Some(properties))
    }

    fn load_checked(
        device: &ash::Device,
        path: Option<PathBuf>,
        properties: Option<&vk::PhysicalDeviceProperties>,
    ) -> Result<Self> {
        let data = match &path {
            None => Vec::new(),
            Some(path) => match read_optional(path, MAX_PIPELINE_CACHE_BYTES, "pipeline cache") {
                Ok(None) => Vec::new(),
                Ok(Some(data)) => match check_pipeline_cache_header(&data, properties) {
                    Ok(()) => data,
                    Err(why) => {
                        log::warn!(
                            "pipeline cache {} ignored ({why}); starting empty",
                            path.display()
                        );
                        Vec::new()
                    }
                },
                Err(e) => {
                    log::warn!(
                        "pipeline cache {} unreadable ({e}); starting empty",
                        path.display()
                    );
                    Vec::new()
                }
            },
        };
        let create = |initial: &[u8]| {
            let info = vk::PipelineCacheCreateInfo::default().initial_data(initial);
            // SAFETY: `info` and `initial` outlive the call.
            unsafe { device.create_pipeline_cache(&info, None) }.vk("vkCreatePipelineCache")
        };
        let handle = match create(&data) {
            Ok(handle) => handle,
            Err(e) if !data.is_empty() => {
                log::warn!("pipeline cache data rejected by the driver ({e}); starting empty");
                create(&[])?
            }
            Err(e) => return Err(e),
        };
        Ok(Self { handle, path })
    }

    /// A host's pipeline cache, used as it is: never loaded, saved or (the host owns it)
    /// destroyed by lucent; do not call [`PipelineCache::destroy`] on the result.
    pub fn borrowed(handle: vk::PipelineCache) -> Self {
        Self { handle, path: None }
    }

    /// The file this cache is loaded from and saved to, if any.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// Writes the cache's current data to its file (atomically: temporary file, then rename),
    /// creating parent directories. Does nothing for a cache without a path.
    pub fn save(&self, device: &ash::Device) -> Result<()> {
        let Some(path) = &self.path else {
            return Ok(());
        };
        // SAFETY: `handle` is a live pipeline cache created on `device`.
        let data =
            unsafe { device.get_pipeline_cache_data(self.handle) }.vk("vkGetPipelineCacheData")?;
        write_file_atomic(path, &data)
    }

    /// Destroys the Vulkan object. Call [`PipelineCache::save`] first to keep its contents.
    pub fn destroy(self, device: &ash::Device) {
        // SAFETY: the caller guarantees no pipeline creation using this cache is in flight.
        unsafe { device.destroy_pipeline_cache(self.handle, None) };
    }
}

/// Checks a pipeline cache file's header (`VkPipelineCacheHeaderVersionOne`), and when
/// `properties` is given that it was written for this vendor, device and cache UUID.
fn check_pipeline_cache_header(
    data: &[u8],
    properties: Option<&vk::PhysicalDeviceProperties>,
) -> std::result::Result<(), String> {
    if data.len() < PIPELINE_CACHE_HEADER_SIZE {
        return Err(format!("{} bytes, shorter than the header", data.len()));
    }
    let word = |i: usize| u32::from_ne_bytes(data[i * 4..i * 4 + 4].try_into().unwrap_or([0; 4]));
    let (header_len, version, vendor_id, device_id) = (word(0), word(1), word(2), word(3));
    if (header_len as usize) < PIPELINE_CACHE_HEADER_SIZE || header_len as usize > data.len() {
        return Err(format!("bad header length {header_len}"));
    }
    if version != vk::PipelineCacheHeaderVersion::ONE.as_raw() as u32 {
        return Err(format!("unknown header version {version}"));
    }
    if let Some(props) = properties {
        let uuid = &data[16..32];
        if vendor_id != props.vendor_id
            || device_id != props.device_id
            || uuid != props.pipeline_cache_uuid
        {
            return Err(format!(
                "written for vendor {vendor_id:#x} device {device_id:#x}, this is vendor {:#x} device {:#x} (or the driver changed)",
                props.vendor_id, props.device_id
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defines_are_validated_and_sorted() {
        let sorted = sorted_defines("x", &[("B", "1"), ("A", "2"), ("B", "3")], false).unwrap();
        assert_eq!(permutation_line("x.frag", sorted), "x.frag A=2 B=3");
        assert!(sorted_defines("x", &[("1A", "1")], false).is_err());
        assert!(sorted_defines("x", &[("A B", "1")], false).is_err());
        assert!(sorted_defines("x", &[("A", "1\n#define X")], false).is_err());
        assert!(sorted_defines("x", &[("A", "1 2")], false).is_ok());
        assert!(sorted_defines("x", &[("A", "1 2")], true).is_err());
    }

    #[test]
    fn permutation_lines_round_trip() {
        use super::super::shader_files::parse_permutation_line;
        let (name, defines) = parse_permutation_line("sss/blur.frag A=1 B= C=x").unwrap();
        assert_eq!(name, "sss/blur.frag");
        let pairs: Vec<(&str, &str)> = defines
            .iter()
            .map(|(n, v)| (n.as_str(), v.as_str()))
            .collect();
        assert_eq!(pairs, [("A", "1"), ("B", ""), ("C", "x")]);
        assert_eq!(permutation_line(&name, pairs), "sss/blur.frag A=1 B= C=x");
        for bad in [
            "../a.frag",
            "a.frag B=1 A=1",
            "a.frag A=1 A=2",
            "a.frag A",
            "a.frag 1A=1",
        ] {
            assert!(parse_permutation_line(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_bundle_built_while_regenerating_the_manifest_says_to_rebuild() {
        let empty = not_shipped(true, "a.frag".into()).to_string();
        assert!(
            empty.contains("a.frag") && empty.contains("LUCENT_WRITE_MANIFEST"),
            "{empty}"
        );
        assert!(matches!(
            not_shipped(false, "a.frag".into()),
            LucentError::ShaderNotShipped { .. }
        ));
    }

    #[test]
    fn shipped_bundle_serves_its_permutations_and_names_a_miss() {
        let shaders = ShaderCompiler::shipped().unwrap();
        assert!(shaders.is_shipped() && shaders.glsl_root().is_none());
        let lines = ShaderCompiler::shipped_permutations().unwrap();
        let first = lines.first().expect("the shipped bundle is empty");
        let (name, defines) = super::super::shader_files::parse_permutation_line(first).unwrap();
        let pairs: Vec<(&str, &str)> = defines
            .iter()
            .map(|(n, v)| (n.as_str(), v.as_str()))
            .collect();
        let shader = shaders.compile(&name, &pairs).unwrap();
        assert_eq!(shader.spirv[0], SPIRV_MAGIC);
        assert!(!shader.from_cache && shader.dependencies.is_empty());
        let mut extra = pairs.clone();
        extra.push(("LUCENT_NOT_A_PERMUTATION", "1"));
        match shaders.compile(&name, &extra) {
            Err(LucentError::ShaderNotShipped { permutation }) => {
                assert!(
                    permutation.starts_with(&name)
                        && permutation.contains("LUCENT_NOT_A_PERMUTATION=1")
                );
            }
            other => panic!("expected ShaderNotShipped, got {other:?}"),
        }
        assert!(matches!(
            shaders.compile("../x.frag", &[]),
            Err(LucentError::InvalidInput(_))
        ));
    }

    #[cfg(feature = "runtime-shaders")]
    #[test]
    fn the_default_glsl_root_is_found_from_the_executable() {
        // This test runs from target/<profile>/deps: the repository's tree is found above it
        // (unless the target directory is elsewhere: then the source tree it was built from).
        if std::env::var_os("LUCENT_GLSL_DIR").is_none() {
            let found = ShaderCompiler::default_glsl_root().canonicalize().unwrap();
            let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("glsl")
                .canonicalize()
                .unwrap();
            assert_eq!(found, repo);
        }
    }

    #[test]
    fn pipeline_cache_header_checks() {
        let mut props = vk::PhysicalDeviceProperties {
            vendor_id: 0x10005,
            device_id: 7,
            ..Default::default()
        };
        props.pipeline_cache_uuid = [3; 16];
        let mut data = Vec::new();
        for word in [32u32, 1, 0x10005, 7] {
            data.extend_from_slice(&word.to_ne_bytes());
        }
        data.extend_from_slice(&[3; 16]);
        data.extend_from_slice(b"driver data");
        assert!(check_pipeline_cache_header(&data, Some(&props)).is_ok());
        assert!(check_pipeline_cache_header(&data[..20], None).is_err());
        let mut other_device = data.clone();
        other_device[12] = 8;
        assert!(check_pipeline_cache_header(&other_device, None).is_ok());
        assert!(check_pipeline_cache_header(&other_device, Some(&props)).is_err());
        let mut bad_version = data.clone();
        bad_version[4] = 9;
        assert!(check_pipeline_cache_header(&bad_version, None).is_err());
    }
}
