//! A host engine's own device-memory allocator (`lucent::embed::HostAllocator`, as a
//! VMA-based engine would plug in): lucent takes every buffer's and image's memory from it,
//! gives every allocation back, and an allocator that fails or returns memory lucent cannot
//! use is an error naming the resource, with nothing kept.

use std::collections::HashMap;
use std::ptr::NonNull;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use lucent::embed::{
    EmbedOptions, HostAllocation, HostAllocator, HostError, ImageState, Lucent, MemoryRequest,
    MemoryUse, SceneRenderer,
};
use lucent::frame::FrameSettings;
use lucent::LucentError;

use crate::common::{self, TestGpu};
use crate::embed::{built, described, host_built_scene, wrap};

/// What the test's allocator does wrong, once, to the first request it matches.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fault {
    /// Returns `ERROR_OUT_OF_DEVICE_MEMORY` for the tenth request (nine are held by then).
    OutOfMemoryAtTenth,
    /// Returns an upload allocation without its CPU address.
    UnmappedUpload,
    /// Returns a device-local allocation one byte short.
    ShortDeviceLocal,
}

/// A host's own allocator as simple as one can be: one `VkDeviceMemory` per request, of the
/// first memory type the request accepts with the properties its use needs, and the
/// resource's range placed one alignment into it (so lucent's offsets and mapped addresses
/// are not the memory's start). It keeps what it handed out, to count it back.
struct PerRequestAllocator {
    device: ash::Device,
    memory_types: vk::PhysicalDeviceMemoryProperties,
    /// The host's handle of each live allocation, with its memory and lucent's name for it.
    live: Mutex<HashMap<u64, (vk::DeviceMemory, String)>>,
    next_handle: AtomicU64,
    /// Every request seen: lucent's name and the use.
    requests: Mutex<Vec<(String, MemoryUse)>>,
    fault: Mutex<Option<Fault>>,
}

impl PerRequestAllocator {
    fn new(test: &TestGpu, fault: Option<Fault>) -> Arc<Self> {
        let gpu = &test.gpu;
        // SAFETY: the test context's own valid handles.
        let memory_types = unsafe {
            gpu.instance
                .get_physical_device_memory_properties(gpu.physical_device)
        };
        Arc::new(Self {
            device: gpu.device.clone(),
            memory_types,
            live: Mutex::new(HashMap::new()),
            next_handle: AtomicU64::new(1),
            requests: Mutex::new(Vec::new()),
            fault: Mutex::new(fault),
        })
    }

    fn live(&self) -> usize {
        self.live.lock().unwrap().len()
    }

    /// Takes the fault if it applies to this request (it applies once).
    fn fault_for(&self, request: &MemoryRequest<'_>, seen: usize) -> Option<Fault> {
        let mut fault = self.fault.lock().unwrap();
        let applies = match (*fault)? {
            Fault::OutOfMemoryAtTenth => seen == 10,
            Fault::UnmappedUpload => request.usage == MemoryUse::Upload,
            Fault::ShortDeviceLocal => request.usage == MemoryUse::DeviceLocal,
        };
        if applies {
            fault.take()
        } else {
            None
        }
    }
}

impl HostAllocator for PerRequestAllocator {
    fn allocate(&self, request: &MemoryRequest<'_>) -> Result<HostAllocation, vk::Result> {
        let seen = {
            let mut requests = self.requests.lock().unwrap();
            requests.push((request.name.to_string(), request.usage));
            requests.len()
        };
        let fault = self.fault_for(request, seen);
        if fault == Some(Fault::OutOfMemoryAtTenth) {
            return Err(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY);
        }
        let wanted = match request.usage {
            MemoryUse::DeviceLocal => vk::MemoryPropertyFlags::DEVICE_LOCAL,
            _ => vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT,
        };
        let types = &self.memory_types;
        let type_index = (0..types.memory_type_count)
            .find(|&i| {
                request.requirements.memory_type_bits & (1 << i) != 0
                    && types.memory_types[i as usize]
                        .property_flags
                        .contains(wanted)
            })
            .ok_or(vk::Result::ERROR_OUT_OF_DEVICE_MEMORY)?;
        let offset = request.requirements.alignment.max(1);
        let info = vk::MemoryAllocateInfo::default()
            .allocation_size(offset + request.requirements.size)
            .memory_type_index(type_index);
        // SAFETY: a valid allocate info for a memory type of this device.
        let memory = unsafe { self.device.allocate_memory(&info, None) }?;
        let handle = self.next_handle.fetch_add(1, Ordering::Relaxed);
        let size = if fault == Some(Fault::ShortDeviceLocal) {
            request.requirements.size - 1
        } else {
            request.requirements.size
        };
        let mut allocation = HostAllocation::new(memory, offset, size, handle);
        if request.usage != MemoryUse::DeviceLocal && fault != Some(Fault::UnmappedUpload) {
            // SAFETY: host-visible memory, mapped once, unmapped by `free`.
            let base = unsafe {
                self.device
                    .map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
            }?;
            let first = NonNull::new(base.cast::<u8>().wrapping_add(offset as usize)).unwrap();
            allocation = allocation.mapped_at(first);
        }
        self.live
            .lock()
            .unwrap()
            .insert(handle, (memory, request.name.to_string()));
        Ok(allocation)
    }

    fn free(&self, allocation: HostAllocation) {
        let (memory, _) = self
            .live
            .lock()
            .unwrap()
            .remove(&allocation.host_handle)
            .expect("lucent frees only what this allocator gave it, once");
        assert_eq!(
            memory, allocation.memory,
            "the host's handle came back untouched"
        );
        // SAFETY: lucent is done with the memory (its contract); freeing unmaps it.
        unsafe { self.device.free_memory(memory, None) };
    }
}

fn with_memory(allocator: &Arc<PerRequestAllocator>) -> EmbedOptions {
    EmbedOptions {
        frames_in_flight: 2,
        memory: Some(allocator.clone()),
        ..Default::default()
    }
}

#[test]
fn a_hosts_own_allocator_gives_every_allocation_and_gets_every_one_back() {
    let test = TestGpu::new();
    let gpu = &test.gpu;
    let (w, h) = (96, 72);
    let allocator = PerRequestAllocator::new(&test, None);
    let lucent = wrap(&test, with_memory(&allocator));
    let mut scene = host_built_scene();
    lucent.prepare_scene(&mut scene).unwrap();
    // lucent's own frame of the same scene, on lucent's own allocator.
    let expected = lucent::frame::render_frame(
        gpu,
        &test.shaders,
        &test.cache,
        &scene,
        FrameSettings::new(w, h),
    )
    .unwrap()
    .display;

    let mut renderer = built(&test, &lucent, |u| {
        SceneRenderer::new(&lucent, u, &scene, w, h, vk::Format::R8G8B8A8_UNORM)
    })
    .unwrap();
    let uses: Vec<MemoryUse> = allocator
        .requests
        .lock()
        .unwrap()
        .iter()
        .map(|(name, usage)| {
            assert!(!name.is_empty(), "every request names its resource");
            *usage
        })
        .collect();
    assert!(
        uses.contains(&MemoryUse::DeviceLocal) && uses.contains(&MemoryUse::Upload),
        "images and buffers on the GPU, staging and per-frame parameters mapped: {uses:?}"
    );
    let held = allocator.live();
    assert!(
        held > 5,
        "the renderer's buffers and images live in the host's memory ({held} allocations)"
    );
    assert!(
        held < uses.len(),
        "the uploads' staging went back once released ({held} held of {} given)",
        uses.len()
    );
    let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
    let image = gpu
        .create_image(
            &lucent::backend::ImageDesc::color(w, h, vk::Format::R8G8B8A8_UNORM, usage),
            "host output",
        )
        .unwrap();
    test.gpu
        .submit_and_wait(|cmd| {
            let output = described(&image, "host output", usage)
                .in_state(ImageState::UNDEFINED)
                .then(ImageState::transfer_src());
            renderer.record(&lucent, cmd, 0, &scene, &output).unwrap();
        })
        .unwrap();
    let got = gpu
        .read_image(&image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .unwrap();
    let worst = common::max_difference(&got, &expected);
    assert!(
        worst <= 1,
        "the frame on the host's memory differs from lucent's own by {worst}/255"
    );
    renderer.destroy(&lucent);
    assert_eq!(
        allocator.live(),
        0,
        "a destroyed renderer gave every allocation back: {:?}",
        allocator.live.lock().unwrap().values().collect::<Vec<_>>()
    );
    drop(lucent);
    gpu.destroy_image(image);
    test.finish();
}

#[test]
fn a_hosts_allocator_that_fails_or_gives_unusable_memory_is_an_error_naming_the_resource() {
    let test = TestGpu::new();
    let scene = {
        let lucent = wrap(&test, super::embed::options(1));
        let mut scene = host_built_scene();
        lucent.prepare_scene(&mut scene).unwrap();
        scene
    };
    let build = |allocator: &Arc<PerRequestAllocator>| {
        let lucent = wrap(&test, with_memory(allocator));
        let result = built(&test, &lucent, |u| {
            SceneRenderer::new(&lucent, u, &scene, 64, 48, vk::Format::R8G8B8A8_UNORM)
        });
        let error = match result {
            Ok(renderer) => {
                renderer.destroy(&lucent);
                panic!("the renderer was built on a faulty allocator")
            }
            Err(e) => e,
        };
        drop(lucent);
        // Whatever lucent had been given before the fault went back with the error.
        assert_eq!(
            allocator.live(),
            0,
            "after {error}: still held {:?}",
            allocator.live.lock().unwrap().values().collect::<Vec<_>>()
        );
        error
    };

    let allocator = PerRequestAllocator::new(&test, Some(Fault::OutOfMemoryAtTenth));
    match build(&allocator) {
        LucentError::HostAllocation {
            name,
            bytes,
            result,
        } => {
            let tenth = allocator.requests.lock().unwrap()[9].0.clone();
            assert_eq!(name, tenth, "the error names the resource asked for");
            assert!(bytes > 0);
            assert_eq!(result, vk::Result::ERROR_OUT_OF_DEVICE_MEMORY);
        }
        other => panic!("expected LucentError::HostAllocation, got {other}"),
    }

    for (fault, says) in [
        (Fault::UnmappedUpload, "must be mapped"),
        (Fault::ShortDeviceLocal, "where the resource needs"),
    ] {
        let allocator = PerRequestAllocator::new(&test, Some(fault));
        match build(&allocator) {
            LucentError::Host(HostError::Memory {
                allocation,
                problem,
            }) => {
                let usage = match fault {
                    Fault::UnmappedUpload => MemoryUse::Upload,
                    _ => MemoryUse::DeviceLocal,
                };
                let first = allocator
                    .requests
                    .lock()
                    .unwrap()
                    .iter()
                    .find(|(_, u)| *u == usage)
                    .unwrap()
                    .0
                    .clone();
                assert_eq!(allocation, first, "{fault:?}: names the resource");
                assert!(problem.contains(says), "{fault:?}: {problem}");
            }
            other => panic!("{fault:?}: expected HostError::Memory, got {other}"),
        }
    }

    // One allocator, not two.
    let allocator = PerRequestAllocator::new(&test, None);
    let shared = Arc::new(Mutex::new(
        lucent::embed::gpu_allocator::vulkan::Allocator::new(
            &lucent::embed::gpu_allocator::vulkan::AllocatorCreateDesc {
                instance: test.gpu.instance.clone(),
                device: test.gpu.device.clone(),
                physical_device: test.gpu.physical_device,
                debug_settings: Default::default(),
                buffer_device_address: false,
                allocation_sizes: Default::default(),
            },
        )
        .unwrap(),
    ));
    let both = EmbedOptions {
        allocator: Some(shared),
        ..with_memory(&allocator)
    };
    let host = crate::embed::host_device(&test, test.gpu.device.clone());
    // SAFETY: the test context's handles, as `wrap` gives them.
    match unsafe { Lucent::new(host, both) } {
        Err(LucentError::Host(HostError::Description { field, .. })) => {
            assert_eq!(field, "EmbedOptions::memory")
        }
        Err(other) => panic!("expected HostError::Description, got {other}"),
        Ok(_) => panic!("two allocators were accepted"),
    }
    assert_eq!(allocator.requests.lock().unwrap().len(), 0);
    test.finish();
}
