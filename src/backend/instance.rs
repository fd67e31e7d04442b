//! The instance and its debug messenger: loading the layers (the Khronos validation layer with
//! synchronization validation on request) and routing validation messages to the log, where
//! errors are counted.

use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::Mutex;

use ash::vk;

use crate::error::{LucentError, Result, VkResultExt};

use super::desc::{
    c_string, lock, version_string, ContextDesc, LOG_TARGET, MAX_STORED_MESSAGES, VALIDATION_LAYER,
};

/// Heap state the debug messenger callback writes into. It lives in a `Box` owned by the context
/// and is dropped only after the messenger (and, for owned contexts, the instance) is destroyed.
#[derive(Default)]
pub(super) struct MessengerState {
    pub(super) errors: AtomicU32,
    pub(super) messages: Mutex<Vec<String>>,
}

pub(super) fn messenger_create_info(
    state: &MessengerState,
) -> vk::DebugUtilsMessengerCreateInfoEXT<'static> {
    vk::DebugUtilsMessengerCreateInfoEXT::default()
        // VERBOSE is left out: it is loader chatter.
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(state as *const MessengerState as *mut c_void)
}

pub(super) struct CreatedInstance {
    pub(super) instance: ash::Instance,
    pub(super) debug_instance: Option<ash::ext::debug_utils::Instance>,
    pub(super) messenger: vk::DebugUtilsMessengerEXT,
}

pub(super) fn create_instance(
    entry: &ash::Entry,
    desc: &ContextDesc,
    state: &MessengerState,
) -> Result<CreatedInstance> {
    // SAFETY: plain queries of the loaded loader.
    let loader_version = unsafe { entry.try_enumerate_instance_version() }
        .vk("vkEnumerateInstanceVersion")?
        .unwrap_or(vk::API_VERSION_1_0);
    if loader_version < vk::API_VERSION_1_3 {
        return Err(LucentError::NoVulkanDriver(format!(
            " for Vulkan 1.3 (the loader supports {})",
            version_string(loader_version)
        )));
    }
    // SAFETY: plain queries of the loaded loader.
    let extensions = unsafe { entry.enumerate_instance_extension_properties(None) }
        .vk("vkEnumerateInstanceExtensionProperties")?;
    let has_extension = |list: &[vk::ExtensionProperties], name: &CStr| {
        list.iter()
            .any(|e| e.extension_name_as_c_str().is_ok_and(|n| n == name))
    };

    let mut layer_extensions = Vec::new();
    if desc.validation {
        // SAFETY: plain queries of the loaded loader.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .vk("vkEnumerateInstanceLayerProperties")?;
        if !layers
            .iter()
            .any(|l| l.layer_name_as_c_str().is_ok_and(|n| n == VALIDATION_LAYER))
        {
            return Err(LucentError::NoValidationLayer);
        }
        // SAFETY: the layer name is a valid NUL-terminated string of an installed layer.
        layer_extensions =
            unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }
                .vk("vkEnumerateInstanceExtensionProperties")?;
    }

    let debug_utils = ash::ext::debug_utils::NAME;
    let has_debug_utils =
        has_extension(&extensions, debug_utils) || has_extension(&layer_extensions, debug_utils);
    if desc.validation && !has_debug_utils {
        // Without the messenger validation errors could not be seen or counted.
        return Err(LucentError::Vulkan {
            call: "vkCreateInstance (VK_EXT_debug_utils)",
            result: vk::Result::ERROR_EXTENSION_NOT_PRESENT,
        });
    }
    let validation_features = ash::ext::validation_features::NAME;
    let has_validation_features = desc.validation
        && (has_extension(&layer_extensions, validation_features)
            || has_extension(&extensions, validation_features));

    let mut extension_names = Vec::new();
    for wanted in &desc.instance_extensions {
        if !has_extension(&extensions, wanted) {
            return Err(LucentError::MissingFeature {
                device: "the Vulkan loader".to_string(),
                feature: format!(
                    "instance extension {} (asked for by the window system)",
                    wanted.to_string_lossy()
                ),
            });
        }
        extension_names.push(wanted.as_ptr());
    }
    if has_debug_utils {
        extension_names.push(debug_utils.as_ptr());
    }
    if has_validation_features {
        extension_names.push(validation_features.as_ptr());
    }
    let layer_names = if desc.validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        Vec::new()
    };

    let app_name = c_string(&desc.app_name);
    let app_info = vk::ApplicationInfo::default()
        .application_name(&app_name)
        .application_version(0)
        .engine_name(c"lucent")
        .engine_version(vk::make_api_version(0, 0, 1, 0))
        .api_version(vk::API_VERSION_1_3);
    let enabled_validation = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features =
        vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled_validation);
    let mut messenger_info = messenger_create_info(state);
    let mut create_info = vk::InstanceCreateInfo::default()
        .application_info(&app_info)
        .enabled_layer_names(&layer_names)
        .enabled_extension_names(&extension_names);
    if has_debug_utils {
        // Also captures messages from vkCreateInstance / vkDestroyInstance themselves.
        create_info = create_info.push_next(&mut messenger_info);
    }
    if has_validation_features {
        create_info = create_info.push_next(&mut features);
    } else if desc.validation {
        log::warn!("VK_EXT_validation_features missing: synchronization validation is off");
    }

    // SAFETY: every pointer in `create_info` refers to locals that outlive the call; the
    // messenger user data points to `state`, which the caller keeps alive past the instance.
    let instance = match unsafe { entry.create_instance(&create_info, None) } {
        Ok(instance) => instance,
        Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
            return Err(LucentError::NoVulkanDriver(
                " (vkCreateInstance: ERROR_INCOMPATIBLE_DRIVER)".to_string(),
            ))
        }
        Err(vk::Result::ERROR_LAYER_NOT_PRESENT) => return Err(LucentError::NoValidationLayer),
        Err(result) => {
            return Err(LucentError::Vulkan {
                call: "vkCreateInstance",
                result,
            })
        }
    };

    let debug_instance =
        has_debug_utils.then(|| ash::ext::debug_utils::Instance::new(entry, &instance));
    let messenger = match &debug_instance {
        Some(debug) => {
            let info = messenger_create_info(state);
            // SAFETY: the instance enables VK_EXT_debug_utils; user data outlives the messenger.
            match unsafe { debug.create_debug_utils_messenger(&info, None) } {
                Ok(m) => m,
                Err(result) => {
                    // SAFETY: the instance was created above and has no children.
                    unsafe { instance.destroy_instance(None) };
                    return Err(LucentError::Vulkan {
                        call: "vkCreateDebugUtilsMessengerEXT",
                        result,
                    });
                }
            }
        }
        None => vk::DebugUtilsMessengerEXT::null(),
    };
    Ok(CreatedInstance {
        instance,
        debug_instance,
        messenger,
    })
}

/// Routes debug-utils messages to `log` and counts errors in the [`MessengerState`] that
/// `user_data` points to.
pub(super) unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user_data: *mut c_void,
) -> vk::Bool32 {
    // A panic must not unwind into the Vulkan implementation.
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        if data.is_null() {
            return;
        }
        // SAFETY: the implementation passes a valid callback-data struct for this call's duration.
        let data = unsafe { &*data };
        // SAFETY: the strings are null or valid NUL-terminated strings (Vulkan spec).
        let (id_name, message) = unsafe {
            (
                data.message_id_name_as_c_str()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default(),
                data.message_as_c_str()
                    .map(|s| s.to_string_lossy())
                    .unwrap_or_default(),
            )
        };
        if severity == vk::DebugUtilsMessageSeverityFlagsEXT::INFO && id_name == "Loader Message" {
            // The loader reports every layer and driver it looks at: harmless spam.
            return;
        }
        let level = if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            log::Level::Error
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            log::Level::Warn
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::INFO) {
            log::Level::Info
        } else {
            log::Level::Debug
        };
        log::log!(target: LOG_TARGET, level, "{message}");
        if level == log::Level::Error && !user_data.is_null() {
            // SAFETY: user_data is the address of the context's boxed MessengerState, which
            // outlives the messenger (see MessengerState).
            let state = unsafe { &*(user_data as *const MessengerState) };
            state.errors.fetch_add(1, Ordering::Relaxed);
            let mut messages = lock(&state.messages);
            if messages.len() < MAX_STORED_MESSAGES {
                messages.push(if message.contains(id_name.as_ref()) {
                    message.into_owned()
                } else {
                    format!("[{id_name}] {message}")
                });
            }
        }
    }));
    vk::FALSE
}
