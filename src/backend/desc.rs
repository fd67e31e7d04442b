//! What a context is asked for ([`ContextDesc`]) and what it found ([`DeviceInfo`]), with the
//! small helpers the context, instance and device code share.

use std::ffi::{CStr, CString};
use std::sync::{Mutex, MutexGuard};

use ash::vk;

/// How to create a [`GpuContext`](super::GpuContext) with [`GpuContext::new`](super::GpuContext::new).
#[derive(Clone, Debug)]
pub struct ContextDesc {
    /// Enable `VK_LAYER_KHRONOS_validation` with synchronization validation.
    pub validation: bool,
    /// Case-insensitive substring of the device name to pick; `None` picks the best device
    /// (discrete > integrated > virtual > CPU > other).
    pub device_filter: Option<String>,
    /// Application name reported to the driver (and shown by tools such as RenderDoc).
    pub app_name: String,
    /// Instance extensions to enable beyond lucent's own, e.g. the surface extensions a window
    /// system needs (`ash_window::enumerate_required_extensions`). Each must be present.
    pub instance_extensions: Vec<CString>,
    /// Enable `VK_KHR_swapchain` on the device, for presenting to a window; devices without it
    /// are skipped. Off for headless use.
    pub swapchain: bool,
}

impl Default for ContextDesc {
    fn default() -> Self {
        Self {
            validation: false,
            device_filter: None,
            app_name: "lucent".to_string(),
            instance_extensions: Vec::new(),
            swapchain: false,
        }
    }
}

impl ContextDesc {
    /// A description for command-line use: validation is on when `validation_flag` is set or the
    /// environment variable `LUCENT_VALIDATION` is `1` (or `true`/`yes`/`on`).
    pub fn from_env(validation_flag: bool, device_filter: Option<String>) -> Self {
        let env_validation = std::env::var("LUCENT_VALIDATION")
            .map(|v| {
                matches!(
                    v.trim().to_ascii_lowercase().as_str(),
                    "1" | "true" | "yes" | "on"
                )
            })
            .unwrap_or(false);
        Self {
            validation: validation_flag || env_validation,
            device_filter,
            ..Self::default()
        }
    }
}

/// What lucent knows about the device it runs on.
#[derive(Clone, Debug)]
pub struct DeviceInfo {
    /// Device name, e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`.
    pub name: String,
    /// Driver name, e.g. `llvmpipe`.
    pub driver_name: String,
    /// Driver details, e.g. `Mesa 22.3.6 (LLVM 15.0.6)`.
    pub driver_info: String,
    /// Discrete, integrated, virtual, CPU or other.
    pub device_type: vk::PhysicalDeviceType,
    /// Vulkan version the device supports (`vk::make_api_version` encoding).
    pub api_version: u32,
    /// Nanoseconds per timestamp tick (`limits.timestampPeriod`).
    pub timestamp_period_ns: f32,
    /// Valid bits of timestamps written on lucent's queue family.
    pub timestamp_valid_bits: u32,
    /// `limits.minUniformBufferOffsetAlignment`: how per-frame uniform slots are aligned.
    pub uniform_offset_alignment: u64,
    /// `hostQueryReset` (Vulkan 1.2) is enabled: query pools may be reset from the host.
    pub host_query_reset: bool,
    /// `shaderStorageImageWriteWithoutFormat` is enabled.
    pub storage_image_write_without_format: bool,
    /// `VK_KHR_swapchain` is enabled (asked for with [`ContextDesc::swapchain`]).
    pub swapchain: bool,
    /// `limits.maxImageDimension2D`: the widest or tallest 2D image the device creates.
    pub max_image_dimension_2d: u32,
    /// Size of the largest device-local memory heap (on a CPU driver such as lavapipe, host
    /// memory): what a frame's images and a scene's textures must fit in.
    pub device_local_bytes: u64,
}

impl DeviceInfo {
    /// Device name and type, e.g. `llvmpipe (LLVM 15.0.6, 256 bits) [CPU]`.
    pub fn describe(&self) -> String {
        format!("{} [{}]", self.name, device_type_name(self.device_type))
    }

    /// Driver name and details, e.g. `llvmpipe Mesa 22.3.6 (LLVM 15.0.6)`.
    pub fn driver(&self) -> String {
        if self.driver_info.is_empty() {
            self.driver_name.clone()
        } else {
            format!("{} {}", self.driver_name, self.driver_info)
        }
    }

    /// The device's Vulkan version as text, e.g. `1.3.230`.
    pub fn api_version_string(&self) -> String {
        version_string(self.api_version)
    }
}

/// Name of the Khronos validation layer.
pub(super) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// How many validation error messages are kept for [`GpuContext::take_validation_messages`].
pub(super) const MAX_STORED_MESSAGES: usize = 50;

/// `log` target of messages coming from the Vulkan debug messenger.
pub(super) const LOG_TARGET: &str = "lucent::vulkan";

/// Locks a mutex, recovering from poisoning (a panic in another thread does not make the
/// protected Vulkan state invalid).
pub(super) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A C string from `s`, dropping interior NULs instead of failing.
pub(super) fn c_string(s: &str) -> CString {
    CString::new(s.replace('\0', "")).unwrap_or_default()
}

pub(super) fn version_string(v: u32) -> String {
    format!(
        "{}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    )
}

pub fn device_type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
        vk::PhysicalDeviceType::CPU => "CPU",
        _ => "other",
    }
}
