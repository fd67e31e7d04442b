//! Shader tests: every shader in `glsl/` compiles (with each declared permutation), include
//! errors name the included file and line, the SPIR-V cache hits and is invalidated by include
//! edits, and the SPIR-V plus pipeline cache work on a real Vulkan device (lavapipe is enough).
//!
//! Permutations are declared in the shader itself, near the top:
//!
//! ```glsl
//! // permutation: COLOURED=1 USE_SG=0
//! // permutation: COLOURED=0
//! // permutations-only
//! ```
//!
//! Each `permutation:` line is one define set (`NAME` alone means `NAME=1`), compiled in addition
//! to the compile without defines, unless `permutations-only` says the file cannot compile without.

// Run-time compilation only exists with the feature (on by default).
#![cfg(feature = "runtime-shaders")]

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use crate::common;
use ash::vk;
use lucent::backend::shader::{create_shader_module, PipelineCache, ShaderCompiler};
use lucent::backend::spirv::ShaderStage;
use lucent::LucentError;

/// A fresh, empty directory under cargo's per-target temporary directory.
fn write(root: &Path, name: &str, text: &str) {
    let path = root.join(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

/// Every `.vert/.frag/.comp` under `dir`, relative to `root`, skipping `common/` (includes only).
fn shader_files(root: &Path, dir: &Path, out: &mut Vec<String>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let relative = path.strip_prefix(root).unwrap();
        if path.is_dir() {
            if relative != Path::new("common") {
                shader_files(root, &path, out);
            }
        } else if ShaderStage::from_path(&path).is_some() {
            out.push(relative.to_str().unwrap().replace('\\', "/"));
        }
    }
}

/// The define sets a shader asks to be compiled with (see the file docs).
fn permutations(source: &str) -> Vec<Vec<(String, String)>> {
    let mut sets = Vec::new();
    let mut only = false;
    for line in source.lines() {
        let Some(comment) = line.trim().strip_prefix("//") else {
            continue;
        };
        let comment = comment.trim();
        if comment == "permutations-only" {
            only = true;
        } else if let Some(list) = comment.strip_prefix("permutation:") {
            let set = list
                .split_whitespace()
                .map(|item| match item.split_once('=') {
                    Some((name, value)) => (name.to_string(), value.to_string()),
                    None => (item.to_string(), "1".to_string()),
                })
                .collect();
            sets.push(set);
        }
    }
    if !only {
        sets.insert(0, Vec::new());
    }
    sets
}

#[test]
fn permutation_lines_are_parsed() {
    let source = "#version 450\n// permutation: A=1 B\n//permutation: C=x\n// permutations-only\n";
    assert_eq!(
        permutations(source),
        vec![
            vec![("A".into(), "1".into()), ("B".into(), "1".into())],
            vec![("C".into(), "x".into())],
        ]
    );
    assert_eq!(permutations("void main() {}"), vec![Vec::new()]);
}

#[test]
fn every_shader_in_glsl_compiles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    let mut files = Vec::new();
    shader_files(&root, &root, &mut files);
    assert!(
        !files.is_empty(),
        "no .vert/.frag/.comp files under {}",
        root.display()
    );

    let mut jobs = Vec::new();
    for file in &files {
        let source = std::fs::read_to_string(root.join(file)).unwrap();
        for defines in permutations(&source) {
            jobs.push((file.clone(), defines));
        }
    }
    // No cache: this test is about the compiler accepting today's sources.
    let compiler = ShaderCompiler::new(&root, None).unwrap();
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                while let Some((file, defines)) = jobs.get(next.fetch_add(1, Ordering::Relaxed)) {
                    let defines: Vec<(&str, &str)> = defines
                        .iter()
                        .map(|(n, v)| (n.as_str(), v.as_str()))
                        .collect();
                    match compiler.compile(file, &defines) {
                        Ok(shader) => assert!(!shader.spirv.is_empty() && !shader.from_cache),
                        Err(e) => failures
                            .lock()
                            .unwrap()
                            .push(format!("{file} {defines:?}: {e}")),
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "{} of {} shader variants failed:\n{}",
        failures.len(),
        jobs.len(),
        failures.join("\n\n")
    );
    eprintln!(
        "compiled {} variants of {} shaders",
        jobs.len(),
        files.len()
    );
}

#[test]
fn error_in_an_include_names_the_included_file_and_line() {
    let root = common::temp_dir("shaders-include-error");
    write(
        &root,
        "common/broken.glsl",
        "// helpers\nfloat ok() { return 1.0; }\nfloat bad() { return undefined_name; }\n",
    );
    write(
        &root,
        "pass/main.frag",
        "#version 450\n#include \"common/broken.glsl\"\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(bad()); }\n",
    );
    let compiler = ShaderCompiler::new(&root, None).unwrap();
    let error = compiler.compile("pass/main.frag", &[]).unwrap_err();
    let LucentError::ShaderCompile { path, message } = &error else {
        panic!("expected ShaderCompile, got {error:?}");
    };
    assert_eq!(path, "pass/main.frag");
    assert!(
        message.contains("common/broken.glsl:3: error"),
        "message must name the include and line:\n{message}"
    );
    assert!(message.contains("undefined_name"), "{message}");

    // An error in the main file names the main file.
    write(
        &root,
        "pass/own.frag",
        "#version 450\n\nvoid main() { nope(); }\n",
    );
    let message = compiler
        .compile("pass/own.frag", &[])
        .unwrap_err()
        .to_string();
    assert!(message.contains("pass/own.frag:3: error"), "{message}");

    // A missing include is a compile error naming the including file.
    write(
        &root,
        "pass/missing.frag",
        "#version 450\n#include \"nothere.glsl\"\nvoid main() {}\n",
    );
    let message = compiler
        .compile("pass/missing.frag", &[])
        .unwrap_err()
        .to_string();
    assert!(message.contains("pass/missing.frag:2"), "{message}");
    assert!(message.contains("nothere.glsl"), "{message}");

    // Defines are named in the error so a failing permutation can be told apart.
    write(
        &root,
        "pass/perm.frag",
        "#version 450\n#if FAIL\n#error permutation failed\n#endif\nvoid main() {}\n",
    );
    assert!(compiler.compile("pass/perm.frag", &[]).is_ok());
    let message = compiler
        .compile("pass/perm.frag", &[("FAIL", "1")])
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("pass/perm.frag:3") && message.contains("FAIL=1"),
        "{message}"
    );
}

#[test]
fn includes_resolve_next_to_the_includer_first_then_from_the_root() {
    let root = common::temp_dir("shaders-include-order");
    write(
        &root,
        "value.glsl",
        "#error the root copy must not be used from pass/\n",
    );
    write(&root, "pass/value.glsl", "#include \"common/value.glsl\"\n");
    write(
        &root,
        "pass/main.comp",
        "#version 450\n#include \"value.glsl\"\n#include <common/value.glsl>\nlayout(local_size_x = 1) in;\nlayout(set = 0, binding = 0) buffer B { float v[]; };\nvoid main() { v[0] = VALUE; }\n",
    );
    write(
        &root,
        "common/value.glsl",
        "#ifndef VALUE_GLSL\n#define VALUE_GLSL\nconst float VALUE = 1.0;\n#endif\n",
    );
    let compiler = ShaderCompiler::new(&root, None).unwrap();
    let shader = compiler.compile("pass/main.comp", &[]).unwrap();
    assert_eq!(shader.stage, ShaderStage::Compute);
    let root = root.canonicalize().unwrap();
    assert_eq!(
        shader.dependencies,
        vec![
            root.join("pass/main.comp"),
            root.join("pass/value.glsl"),
            root.join("common/value.glsl"),
        ]
    );
}

#[test]
fn cache_hits_and_is_invalidated_by_an_include_change() {
    let root = common::temp_dir("shaders-cache");
    let cache = root.join("cache");
    write(&root, "common/k.glsl", "const float K = 1.0;\n");
    write(
        &root,
        "a.frag",
        "#version 450\n#include \"common/k.glsl\"\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(K * SCALE); }\n",
    );
    let compiler = ShaderCompiler::new(root.join("."), Some(cache.clone())).unwrap();
    let first = compiler.compile("a.frag", &[("SCALE", "2.0")]).unwrap();
    assert!(!first.from_cache);
    let second = compiler.compile("a.frag", &[("SCALE", "2.0")]).unwrap();
    assert!(second.from_cache, "second compile must come from the cache");
    assert_eq!(first.spirv, second.spirv);
    assert_eq!(first.dependencies, second.dependencies);

    // Another permutation is another entry.
    assert!(
        !compiler
            .compile("a.frag", &[("SCALE", "3.0")])
            .unwrap()
            .from_cache
    );
    // A new compiler (a new run) finds the entries on disk.
    let next_run = ShaderCompiler::new(&root, Some(cache.clone())).unwrap();
    assert!(
        next_run
            .compile("a.frag", &[("SCALE", "2.0")])
            .unwrap()
            .from_cache
    );

    // Editing the include invalidates the entry even though a.frag did not change.
    write(&root, "common/k.glsl", "const float K = 5.0;\n");
    let edited = compiler.compile("a.frag", &[("SCALE", "2.0")]).unwrap();
    assert!(!edited.from_cache, "an include change must recompile");
    assert_ne!(edited.spirv, first.spirv);
    assert!(
        compiler
            .compile("a.frag", &[("SCALE", "2.0")])
            .unwrap()
            .from_cache
    );

    // No temporary files are left in the cache directory.
    for entry in std::fs::read_dir(&cache).unwrap() {
        let name = entry.unwrap().file_name();
        assert!(name.to_string_lossy().ends_with(".spvcache"), "{name:?}");
    }
}

/// A minimal Vulkan 1.3 device with `maintenance4` (what SPIR-V 1.6 needs) and, when installed,
/// the validation layer with a messenger that counts errors.
struct TestDevice {
    _entry: ash::Entry,
    instance: ash::Instance,
    device: ash::Device,
    properties: vk::PhysicalDeviceProperties,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

static VALIDATION_ERRORS: AtomicUsize = AtomicUsize::new(0);

unsafe extern "system" fn count_errors(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut std::ffi::c_void,
) -> vk::Bool32 {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        VALIDATION_ERRORS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: the layer passes a valid callback data struct.
        if let Some(message) = unsafe { data.as_ref().and_then(|d| d.message_as_c_str()) } {
            eprintln!("validation error: {}", message.to_string_lossy());
        }
    }
    vk::FALSE
}

impl TestDevice {
    fn new() -> Self {
        let hint = "run tools/setup.sh (needs mesa-vulkan-drivers for lavapipe)";
        // SAFETY: loading the system Vulkan loader.
        let entry = unsafe { ash::Entry::load() }
            .unwrap_or_else(|e| panic!("no Vulkan loader ({e}); {hint}"));
        let validation = c"VK_LAYER_KHRONOS_validation";
        // SAFETY: plain enumeration.
        let has_validation = unsafe { entry.enumerate_instance_layer_properties() }
            .unwrap()
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(validation));
        let layers = if has_validation {
            vec![validation.as_ptr()]
        } else {
            Vec::new()
        };
        let extensions = if has_validation {
            vec![ash::ext::debug_utils::NAME.as_ptr()]
        } else {
            Vec::new()
        };
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
        let info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        // SAFETY: valid create info.
        let instance = unsafe { entry.create_instance(&info, None) }.unwrap();
        let debug = has_validation.then(|| {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                )
                .pfn_user_callback(Some(count_errors));
            // SAFETY: valid create info; the callback is a plain function.
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }.unwrap();
            (loader, messenger)
        });
        // SAFETY: plain enumeration and queries on a live instance.
        let (physical, properties) = unsafe {
            let devices = instance.enumerate_physical_devices().unwrap();
            let physical = *devices
                .iter()
                .find(|&&d| {
                    instance.get_physical_device_properties(d).api_version >= vk::API_VERSION_1_3
                })
                .unwrap_or_else(|| panic!("no Vulkan 1.3 device; {hint}"));
            (physical, instance.get_physical_device_properties(physical))
        };
        let priorities = [1.0];
        let queues = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(0)
            .queue_priorities(&priorities)];
        let mut features13 = vk::PhysicalDeviceVulkan13Features::default().maintenance4(true);
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queues)
            .push_next(&mut features13);
        // SAFETY: valid create info for a device of this instance.
        let device = unsafe { instance.create_device(physical, &info, None) }.unwrap();
        Self {
            _entry: entry,
            instance,
            device,
            properties,
            debug,
        }
    }
}

impl Drop for TestDevice {
    fn drop(&mut self) {
        // SAFETY: all child objects were destroyed by the test.
        unsafe {
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

#[test]
fn shader_module_and_pipeline_cache_on_a_device() {
    let root = common::temp_dir("shaders-device");
    write(
        &root,
        "fill.comp",
        "#version 450\nlayout(local_size_x = 64) in;\nlayout(set = 0, binding = 0) buffer B { float v[]; };\nvoid main() { v[gl_GlobalInvocationID.x] = VALUE; }\n",
    );
    let compiler = ShaderCompiler::new(&root, None).unwrap();
    let shader = compiler.compile("fill.comp", &[("VALUE", "0.5")]).unwrap();

    let gpu = TestDevice::new();
    let device = &gpu.device;
    let cache_path = root.join("pipelines/cache.bin");
    let module = create_shader_module(device, &shader.spirv).unwrap();
    let cache =
        PipelineCache::load_for_device(device, Some(cache_path.clone()), &gpu.properties).unwrap();

    let binding = [vk::DescriptorSetLayoutBinding::default()
        .binding(0)
        .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
        .descriptor_count(1)
        .stage_flags(shader.stage.vk_stage())];
    // SAFETY: valid create infos; every object is destroyed below.
    unsafe {
        let set_layout = device
            .create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&binding),
                None,
            )
            .unwrap();
        let set_layouts = [set_layout];
        let layout = device
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts),
                None,
            )
            .unwrap();
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(shader.stage.vk_stage())
            .module(module)
            .name(c"main");
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)];
        let pipeline = device
            .create_compute_pipelines(cache.handle, &info, None)
            .map_err(|(_, e)| e)
            .unwrap()[0];
        cache.save(device).unwrap();
        device.destroy_pipeline(pipeline, None);
        device.destroy_pipeline_layout(layout, None);
        device.destroy_descriptor_set_layout(set_layout, None);
        device.destroy_shader_module(module, None);
    }
    cache.destroy(device);

    // The saved file carries this device's header and is accepted on the next run.
    let saved = std::fs::read(&cache_path).unwrap();
    assert!(saved.len() >= 32);
    assert_eq!(
        u32::from_ne_bytes(saved[8..12].try_into().unwrap()),
        gpu.properties.vendor_id
    );
    let reloaded =
        PipelineCache::load_for_device(device, Some(cache_path.clone()), &gpu.properties).unwrap();
    assert_eq!(reloaded.path(), Some(cache_path.as_path()));
    reloaded.destroy(device);

    // A corrupt file and a file from another device start empty instead of failing.
    std::fs::write(&cache_path, b"corrupt").unwrap();
    PipelineCache::load(device, Some(cache_path.clone()))
        .unwrap()
        .destroy(device);
    let mut other_device = saved.clone();
    other_device[12] ^= 0xff;
    std::fs::write(&cache_path, &other_device).unwrap();
    PipelineCache::load_for_device(device, Some(cache_path.clone()), &gpu.properties)
        .unwrap()
        .destroy(device);
    PipelineCache::load(device, Some(cache_path))
        .unwrap()
        .destroy(device);
    // A cache without a file saves nothing and still works.
    let in_memory = PipelineCache::load(device, None).unwrap();
    in_memory.save(device).unwrap();
    in_memory.destroy(device);

    // Not SPIR-V at all is an error, not a driver crash.
    assert!(create_shader_module(device, &[1, 2, 3]).is_err());
    drop(gpu);
    assert_eq!(
        VALIDATION_ERRORS.load(Ordering::SeqCst),
        0,
        "validation errors (see stderr)"
    );
}
