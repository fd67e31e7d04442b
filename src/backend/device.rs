//! Choosing and creating the device: probing every physical device for what lucent needs
//! (Vulkan 1.3, synchronization2, maintenance4, a graphics + compute queue), picking one (a
//! name filter, or discrete > integrated > virtual > CPU) and creating it with one queue.

use std::ffi::CStr;

use ash::vk;

use crate::error::{LucentError, Result, VkResultExt};

use super::desc::{version_string, ContextDesc, DeviceInfo};

/// Preference order when no filter is given: discrete > integrated > virtual > CPU > other.
pub(super) fn device_type_score(t: vk::PhysicalDeviceType) -> u32 {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 4,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 1,
        _ => 0,
    }
}

/// The result of checking a physical device against lucent's requirements.
pub(crate) struct Probe {
    pub(crate) info: DeviceInfo,
    pub(crate) queue_family: u32,
}

pub(super) fn queue_family_usable(family: &vk::QueueFamilyProperties) -> bool {
    family
        .queue_flags
        .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        && family.timestamp_valid_bits > 0
        && family.queue_count > 0
}

/// Checks that `pd` supports what lucent needs (and `VK_KHR_swapchain` when `swapchain`) and
/// collects its [`DeviceInfo`]; the optional feature flags say what is supported (and will be
/// enabled by [`create_device`]).
pub(crate) fn probe_device(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    swapchain: bool,
) -> Result<Probe> {
    // SAFETY: `pd` was enumerated from `instance` (or supplied by a host under wrap's contract).
    let props = unsafe { instance.get_physical_device_properties(pd) };
    let name = props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "unnamed device".to_string());
    let missing = |feature: String| LucentError::MissingFeature {
        device: name.clone(),
        feature,
    };
    if props.api_version < vk::API_VERSION_1_3 {
        return Err(missing(format!(
            "Vulkan 1.3 (device supports {})",
            version_string(props.api_version)
        )));
    }

    // SAFETY: as above; the device supports Vulkan 1.3, so the 1.2 driver-properties and the
    // 1.2/1.3 feature structs are valid in these chains.
    let (driver, core, v12, v13, families) = unsafe {
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
        instance.get_physical_device_properties2(pd, &mut props2);

        let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
        let mut features2 = vk::PhysicalDeviceFeatures2::default()
            .push_next(&mut v12)
            .push_next(&mut v13);
        instance.get_physical_device_features2(pd, &mut features2);
        let core = features2.features;
        let families = instance.get_physical_device_queue_family_properties(pd);
        (driver, core, v12, v13, families)
    };
    if v13.synchronization2 == vk::FALSE {
        return Err(missing("synchronization2 (Vulkan 1.3)".to_string()));
    }
    if v13.maintenance4 == vk::FALSE {
        return Err(missing(
            "maintenance4 (Vulkan 1.3; SPIR-V for Vulkan 1.3 needs it)".to_string(),
        ));
    }
    let (queue_family, family) = families
        .iter()
        .enumerate()
        .find(|(_, f)| queue_family_usable(f))
        .ok_or_else(|| {
            missing(
                "a queue family with graphics + compute and timestamps (timestampValidBits > 0)"
                    .to_string(),
            )
        })?;

    if swapchain {
        // SAFETY: plain query of a physical device of `instance`.
        let extensions = unsafe { instance.enumerate_device_extension_properties(pd) }
            .vk("vkEnumerateDeviceExtensionProperties")?;
        if !extensions.iter().any(|e| {
            e.extension_name_as_c_str()
                .is_ok_and(|n| n == ash::khr::swapchain::NAME)
        }) {
            return Err(missing(
                "VK_KHR_swapchain (presenting to a window)".to_string(),
            ));
        }
    }

    let text = |s: std::result::Result<&CStr, _>| {
        s.map(|s: &CStr| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    };
    let info = DeviceInfo {
        name,
        driver_name: text(driver.driver_name_as_c_str()),
        driver_info: text(driver.driver_info_as_c_str()),
        device_type: props.device_type,
        api_version: props.api_version,
        timestamp_period_ns: props.limits.timestamp_period,
        timestamp_valid_bits: family.timestamp_valid_bits,
        uniform_offset_alignment: props.limits.min_uniform_buffer_offset_alignment.max(1),
        host_query_reset: v12.host_query_reset == vk::TRUE,
        storage_image_write_without_format: core.shader_storage_image_write_without_format
            == vk::TRUE,
        swapchain,
        max_image_dimension_2d: props.limits.max_image_dimension2_d,
        device_local_bytes: {
            // SAFETY: plain query of a physical device of `instance`.
            let memory = unsafe { instance.get_physical_device_memory_properties(pd) };
            memory
                .memory_heaps_as_slice()
                .iter()
                .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
                .map(|h| h.size)
                .max()
                .unwrap_or(0)
        },
    };
    Ok(Probe {
        info,
        queue_family: queue_family as u32,
    })
}

/// Picks the physical device: the best-scored (or filter-matching) device that passes
/// [`probe_device`]; when none passes, the best candidate's error is returned.
pub(super) fn pick_device(
    instance: &ash::Instance,
    desc: &ContextDesc,
) -> Result<(vk::PhysicalDevice, Probe)> {
    // SAFETY: plain query of a valid instance.
    let devices = match unsafe { instance.enumerate_physical_devices() } {
        Ok(devices) => devices,
        Err(vk::Result::ERROR_INITIALIZATION_FAILED) => {
            return Err(LucentError::NoVulkanDriver(
                " (vkEnumeratePhysicalDevices: ERROR_INITIALIZATION_FAILED)".to_string(),
            ))
        }
        Err(result) => {
            return Err(LucentError::Vulkan {
                call: "vkEnumeratePhysicalDevices",
                result,
            })
        }
    };
    if devices.is_empty() {
        return Err(LucentError::NoVulkanDriver(
            " (no physical devices)".to_string(),
        ));
    }
    let mut candidates: Vec<(vk::PhysicalDevice, String, u32)> = devices
        .iter()
        .map(|&pd| {
            // SAFETY: `pd` was just enumerated from `instance`.
            let props = unsafe { instance.get_physical_device_properties(pd) };
            let name = props
                .device_name_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            (pd, name, device_type_score(props.device_type))
        })
        .collect();
    if let Some(filter) = &desc.device_filter {
        let wanted = filter.to_lowercase();
        let available = candidates
            .iter()
            .map(|(_, name, _)| name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        candidates.retain(|(_, name, _)| name.to_lowercase().contains(&wanted));
        if candidates.is_empty() {
            return Err(LucentError::NoMatchingDevice {
                wanted: filter.clone(),
                available,
            });
        }
    }
    // Stable sort: equal scores keep the driver's enumeration order.
    candidates.sort_by_key(|(_, _, score)| std::cmp::Reverse(*score));
    let mut first_error = None;
    for (pd, name, _) in &candidates {
        match probe_device(instance, *pd, desc.swapchain) {
            Ok(probe) => return Ok((*pd, probe)),
            Err(e) => {
                log::info!("skipping Vulkan device '{name}': {e}");
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.unwrap_or_else(|| LucentError::NoVulkanDriver(String::new())))
}

pub(super) fn create_device(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    probe: &Probe,
) -> Result<ash::Device> {
    let priorities = [1.0f32];
    let queue_infos = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(probe.queue_family)
        .queue_priorities(&priorities)];
    let core = vk::PhysicalDeviceFeatures::default()
        .shader_storage_image_write_without_format(probe.info.storage_image_write_without_format);
    let mut v12 =
        vk::PhysicalDeviceVulkan12Features::default().host_query_reset(probe.info.host_query_reset);
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .maintenance4(true);
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut v12)
        .push_next(&mut v13);
    let extensions = if probe.info.swapchain {
        vec![ash::khr::swapchain::NAME.as_ptr()]
    } else {
        Vec::new()
    };
    let create_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_infos)
        .enabled_extension_names(&extensions)
        .push_next(&mut features2);
    // SAFETY: `pd` belongs to `instance`; every enabled feature was reported as supported by
    // probe_device, and all pointers refer to locals that outlive the call.
    unsafe { instance.create_device(pd, &create_info, None) }.vk("vkCreateDevice")
}
