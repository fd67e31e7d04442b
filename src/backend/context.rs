//! The one Vulkan context: instance, device, queue, memory allocator and debug tooling.
//!
//! Everything else in lucent borrows a [`GpuContext`]. There are two ways to get one:
//!
//! - [`GpuContext::new`] owns everything: it loads the Vulkan loader, creates an instance (with
//!   `VK_LAYER_KHRONOS_validation` and synchronization validation when [`ContextDesc::validation`]
//!   is set), picks a physical device (or the one matching [`ContextDesc::device_filter`]), probes
//!   the features lucent needs and creates a device with one graphics + compute queue. Use this for
//!   the command-line tool, the benchmark and tests.
//! - [`GpuContext::wrap`] borrows a host engine's instance, device and queue. lucent then creates
//!   only its own allocator, a command pool for one-shot submits and (when asked, and the host
//!   enabled `VK_EXT_debug_utils`) a debug messenger, and destroys only those on drop, without
//!   waiting on the host's device.
//!
//! Setup copies (uploads) are submitted and waited for, except on a thread inside
//! [`GpuContext::record_setup_into`]: there they are recorded into a command buffer the caller
//! submits, and their staging buffers are handed back to be freed once it has run.
//!
//! Failures are values: a missing loader, a missing driver, a device without a required feature
//! or a missing validation layer each produce their own [`LucentError`] variant; nothing here
//! panics. Validation messages go to the `log` crate (target `lucent::vulkan`), and errors are
//! counted so tests can assert [`GpuContext::validation_error_count`] is zero.
//!
//! Debug names ([`GpuContext::set_name`]) and command-buffer labels
//! ([`GpuContext::begin_label`]) are no-ops when `VK_EXT_debug_utils` is absent; when it is present
//! they show up in validation messages and in RenderDoc captures.

use std::fmt;
use std::mem::ManuallyDrop;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::thread::ThreadId;

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use gpu_allocator::AllocatorDebugSettings;

use crate::error::{LucentError, Result, VkResultExt};

use super::buffer::GpuBuffer;
use super::memory::MemorySource;
use super::desc::{c_string, lock};
pub use super::desc::{ContextDesc, DeviceInfo};
use super::device::{create_device, pick_device, probe_device, queue_family_usable};
use super::instance::{create_instance, messenger_create_info, CreatedInstance, MessengerState};

/// The command pool, command buffer and fence behind [`GpuContext::submit_and_wait`].
struct OneShot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

/// A thread's setup work recorded into a caller's command buffer instead of submitted
/// ([`GpuContext::record_setup_into`]).
struct SetupRecording {
    thread: ThreadId,
    cmd: vk::CommandBuffer,
    /// What the recorded copies use: freed only after the caller's submission ran.
    kept: SetupKept,
}

/// The Vulkan context every other part of lucent uses (see the module docs).
///
/// Access to [`GpuContext::queue`] must be externally synchronized as Vulkan requires; lucent's
/// own one-shot submits hold an internal lock while they use it.
pub struct GpuContext {
    /// The loaded Vulkan loader.
    pub entry: ash::Entry,
    /// The instance (lucent's own, or the host's when wrapped).
    pub instance: ash::Instance,
    /// The physical device in use.
    pub physical_device: vk::PhysicalDevice,
    /// The logical device (lucent's own, or the host's when wrapped).
    pub device: ash::Device,
    /// A queue with graphics, compute and timestamp support.
    pub queue: vk::Queue,
    /// The family of [`GpuContext::queue`].
    pub queue_family: u32,
    /// Names, versions, limits and enabled optional features of the device.
    pub info: DeviceInfo,
    /// Where buffers' and images' memory comes from: lucent's own allocator, a host's shared
    /// `gpu-allocator` or a host's own allocator.
    memory: ManuallyDrop<MemorySource>,
    debug_instance: Option<ash::ext::debug_utils::Instance>,
    debug_device: Option<ash::ext::debug_utils::Device>,
    messenger: vk::DebugUtilsMessengerEXT,
    messenger_state: Box<MessengerState>,
    owns_handles: bool,
    validation: bool,
    one_shot: Mutex<OneShot>,
    /// Threads whose setup work goes into a caller's command buffer (usually none, at most a
    /// few: one per thread building a renderer at the same time).
    setup_recordings: Mutex<Vec<SetupRecording>>,
}

/// A destruction put off until a caller's submission of recorded setup work has run.
type DeferredDestroy = Box<dyn FnOnce(&GpuContext) + Send>;

/// What setup work recorded into a caller's command buffer ([`GpuContext::record_setup_into`])
/// uses, kept until the caller's submission of it has completed: the staging buffers its
/// copies read, and the resources the build destroyed meanwhile (a build that failed halfway
/// destroys what it had made, which its recorded copies write). So the command buffer stays
/// valid to submit whether the build succeeded or not.
#[derive(Default)]
pub struct SetupKept {
    /// The staging buffers the recorded copies read.
    pub staging: Vec<GpuBuffer>,
    /// Destructions put off, in the order they were asked for.
    destroyed: Vec<DeferredDestroy>,
}

impl SetupKept {
    /// Bytes of staging memory held.
    pub fn staging_bytes(&self) -> u64 {
        self.staging.iter().map(|b| b.size).sum()
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.staging.is_empty() && self.destroyed.is_empty()
    }

    /// Adds what another recording kept.
    pub fn extend(&mut self, other: SetupKept) {
        self.staging.extend(other.staging);
        self.destroyed.extend(other.destroyed);
    }

    /// Frees the staging buffers and carries out the destructions put off. The submission
    /// holding the recorded work has completed (or was never made).
    pub fn destroy(self, gpu: &GpuContext) {
        for buffer in self.staging {
            gpu.destroy_buffer(buffer);
        }
        for destroy in self.destroyed {
            destroy(gpu);
        }
    }
}

impl fmt::Debug for SetupKept {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SetupKept")
            .field("staging_buffers", &self.staging.len())
            .field("staging_bytes", &self.staging_bytes())
            .field("destructions_put_off", &self.destroyed.len())
            .finish()
    }
}

impl fmt::Debug for GpuContext {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("GpuContext")
            .field("device", &self.info.describe())
            .field("driver", &self.info.driver())
            .field("queue_family", &self.queue_family)
            .field("owns_handles", &self.owns_handles)
            .field("validation", &self.validation)
            .finish_non_exhaustive()
    }
}

impl GpuContext {
    /// Creates lucent's own instance and device as described by `desc`.
    ///
    /// Errors: [`LucentError::NoVulkanLoader`] without libvulkan, [`LucentError::NoVulkanDriver`]
    /// without a driver, [`LucentError::NoValidationLayer`] when validation is requested but not
    /// installed, [`LucentError::NoMatchingDevice`] when no device name contains the filter, and
    /// [`LucentError::MissingFeature`] when the chosen device lacks something lucent needs.
    pub fn new(desc: &ContextDesc) -> Result<Self> {
        // SAFETY: loading libvulkan runs its initialisation code; the system Vulkan loader is
        // trusted, as in every Vulkan program.
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| LucentError::NoVulkanLoader(e.to_string()))?;
        // Declared before the instance so it is dropped after it on every path: the instance's
        // create/destroy-time messenger points at it.
        let messenger_state = Box::new(MessengerState::default());
        let created = create_instance(&entry, desc, &messenger_state)?;
        let CreatedInstance {
            instance,
            debug_instance,
            messenger,
        } = created;

        let destroy_instance = || {
            // SAFETY: the messenger (present exactly when debug utils are) and the instance were
            // created above and nothing else uses them; the messenger goes first.
            unsafe {
                if let Some(debug) = &debug_instance {
                    debug.destroy_debug_utils_messenger(messenger, None);
                }
                instance.destroy_instance(None);
            }
        };

        let (physical_device, probe) = match pick_device(&instance, desc) {
            Ok(picked) => picked,
            Err(e) => {
                destroy_instance();
                return Err(e);
            }
        };
        let device = match create_device(&instance, physical_device, &probe) {
            Ok(device) => device,
            Err(e) => {
                destroy_instance();
                return Err(e);
            }
        };
        let debug_device = debug_instance
            .as_ref()
            .map(|_| ash::ext::debug_utils::Device::new(&instance, &device));

        let parts = match create_owned_parts(
            &instance,
            physical_device,
            &device,
            probe.queue_family,
            None,
        ) {
            Ok(parts) => parts,
            Err(e) => {
                // SAFETY: the device was created above and has no child objects left.
                unsafe { device.destroy_device(None) };
                destroy_instance();
                return Err(e);
            }
        };
        // SAFETY: the queue family was requested with one queue at device creation.
        let queue = unsafe { device.get_device_queue(probe.queue_family, 0) };
        log::info!(
            "lucent device: {} — driver {} — Vulkan {}{}",
            probe.info.describe(),
            probe.info.driver(),
            probe.info.api_version_string(),
            if desc.validation {
                " — validation on"
            } else {
                ""
            }
        );
        let ctx = Self {
            entry,
            instance,
            physical_device,
            device,
            queue,
            queue_family: probe.queue_family,
            info: probe.info,
            memory: ManuallyDrop::new(parts.memory),
            debug_instance,
            debug_device,
            messenger,
            messenger_state,
            owns_handles: true,
            validation: desc.validation,
            one_shot: Mutex::new(parts.one_shot),
            setup_recordings: Mutex::new(Vec::new()),
        };
        ctx.name_own_objects();
        Ok(ctx)
    }

    /// Wraps a host engine's existing instance, device and queue.
    ///
    /// lucent creates only its allocator, a command pool and fence for
    /// [`GpuContext::submit_and_wait`], and a debug messenger when the instance has
    /// `VK_EXT_debug_utils` enabled (so validation errors caused by lucent are logged and counted);
    /// on drop it destroys only those, without waiting for the device (the host's contract: its
    /// fences say lucent's work is done). The host's handles are never destroyed.
    ///
    /// The device's support for lucent's requirements (Vulkan 1.3, `synchronization2`,
    /// `maintenance4`, a graphics + compute queue family with timestamps) is checked and a
    /// [`LucentError::MissingFeature`] returned otherwise. Whether optional features were enabled
    /// cannot be queried from a `VkDevice`, so [`DeviceInfo::host_query_reset`] and
    /// [`DeviceInfo::storage_image_write_without_format`] start out `false`; a host that
    /// enabled them may set them in [`GpuContext::info`].
    ///
    /// # Safety
    ///
    /// - All handles must be valid, belong together (`device` created from `physical_device` of
    ///   `instance`, `queue` from family `queue_family` of `device`) and outlive the returned
    ///   context.
    /// - `device` must have been created with Vulkan 1.3 and the features `synchronization2` and
    ///   `maintenance4` enabled.
    /// - The host must synchronize its own use of `queue` with lucent's (Vulkan requires external
    ///   synchronization of queue access).
    pub unsafe fn wrap(
        entry: ash::Entry,
        instance: ash::Instance,
        physical_device: vk::PhysicalDevice,
        device: ash::Device,
        queue: vk::Queue,
        queue_family: u32,
    ) -> Result<Self> {
        // SAFETY: the caller's contract is this function's.
        unsafe {
            Self::wrap_with_memory(
                entry,
                instance,
                physical_device,
                device,
                queue,
                queue_family,
                None,
                true,
            )
        }
    }

    /// [`GpuContext::wrap`] with the host's memory (`Some`): its shared `gpu-allocator` or its
    /// own allocator ([`MemorySource`]). Every buffer and image lucent creates is allocated
    /// from it and freed back to it; dropping the context drops only lucent's reference (and
    /// logs, by name, what lucent still holds from a host's own allocator). `None`: lucent
    /// creates its own `gpu-allocator`.
    ///
    /// `debug_messenger`: whether lucent installs a debug messenger of its own on the host's
    /// instance (when it has `VK_EXT_debug_utils`). A host with its own messenger would see every
    /// message twice, and lucent would count the host's errors as its own: embedding leaves it
    /// off unless asked ([`crate::embed::EmbedOptions::debug_messenger`]). Debug names and
    /// labels need only the extension, not the messenger.
    ///
    /// # Safety
    ///
    /// As [`GpuContext::wrap`]; the host's allocator must allocate memory of the same
    /// device.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn wrap_with_memory(
        entry: ash::Entry,
        instance: ash::Instance,
        physical_device: vk::PhysicalDevice,
        device: ash::Device,
        queue: vk::Queue,
        queue_family: u32,
        memory: Option<MemorySource>,
        debug_messenger: bool,
    ) -> Result<Self> {
        let mut probe = probe_device(&instance, physical_device, false)?;
        let families =
            // SAFETY: the caller guarantees `physical_device` is a valid handle of `instance`.
            unsafe { instance.get_physical_device_queue_family_properties(physical_device) };
        let family = families.get(queue_family as usize).ok_or_else(|| {
            LucentError::InvalidInput(format!(
                "queue family {queue_family} does not exist on '{}' ({} families)",
                probe.info.name,
                families.len()
            ))
        })?;
        if !queue_family_usable(family) {
            return Err(LucentError::MissingFeature {
                device: probe.info.name.clone(),
                feature: format!(
                    "queue family {queue_family} with graphics + compute and timestamps"
                ),
            });
        }
        probe.queue_family = queue_family;
        probe.info.timestamp_valid_bits = family.timestamp_valid_bits;
        probe.info.host_query_reset = false;
        probe.info.storage_image_write_without_format = false;
        probe.info.swapchain = false;

        let messenger_state = Box::new(MessengerState::default());
        // vkGetInstanceProcAddr returns null for debug-utils commands when the instance did not
        // enable the extension (checked with loader 1.3.239), so that answer decides;
        // vkGetDeviceProcAddr returns a pointer either way and is only an extra guard.
        // SAFETY: the caller guarantees `instance` and `device` are valid handles.
        let (has_instance_debug, has_device_debug) = unsafe {
            (
                entry
                    .get_instance_proc_addr(
                        instance.handle(),
                        c"vkCreateDebugUtilsMessengerEXT".as_ptr(),
                    )
                    .is_some(),
                instance
                    .get_device_proc_addr(device.handle(), c"vkSetDebugUtilsObjectNameEXT".as_ptr())
                    .is_some(),
            )
        };
        let debug_instance =
            has_instance_debug.then(|| ash::ext::debug_utils::Instance::new(&entry, &instance));
        let debug_device = (has_instance_debug && has_device_debug)
            .then(|| ash::ext::debug_utils::Device::new(&instance, &device));
        let messenger = match debug_instance.as_ref().filter(|_| debug_messenger) {
            Some(debug) => {
                let info = messenger_create_info(&messenger_state);
                // SAFETY: the instance has VK_EXT_debug_utils enabled (checked above) and the
                // user-data pointer stays valid until the messenger is destroyed in `drop`.
                unsafe { debug.create_debug_utils_messenger(&info, None) }
                    .vk("vkCreateDebugUtilsMessengerEXT")?
            }
            None => vk::DebugUtilsMessengerEXT::null(),
        };

        let parts = match create_owned_parts(
            &instance,
            physical_device,
            &device,
            queue_family,
            memory,
        ) {
            Ok(parts) => parts,
            Err(e) => {
                if let Some(debug) = &debug_instance {
                    if messenger != vk::DebugUtilsMessengerEXT::null() {
                        // SAFETY: the messenger was created above and is not used elsewhere.
                        unsafe { debug.destroy_debug_utils_messenger(messenger, None) };
                    }
                }
                return Err(e);
            }
        };
        log::info!(
            "lucent wrapping host device: {} — driver {}",
            probe.info.describe(),
            probe.info.driver()
        );
        let ctx = Self {
            entry,
            instance,
            physical_device,
            device,
            queue,
            queue_family,
            info: probe.info,
            memory: ManuallyDrop::new(parts.memory),
            debug_instance,
            debug_device,
            messenger,
            messenger_state,
            owns_handles: false,
            validation: false,
            one_shot: Mutex::new(parts.one_shot),
            setup_recordings: Mutex::new(Vec::new()),
        };
        ctx.name_own_objects();
        Ok(ctx)
    }

    /// Whether lucent enabled the validation layer. Always `false` for wrapped contexts (the host
    /// decides); validation errors are still counted there when the host enabled debug utils.
    pub fn validation_enabled(&self) -> bool {
        self.validation
    }

    /// Number of ERROR-severity messages the debug messenger received since creation.
    pub fn validation_error_count(&self) -> u32 {
        self.messenger_state.errors.load(Ordering::Relaxed)
    }

    /// Takes the stored validation error messages (the first 50 since creation or since the last
    /// call), for printing when a test fails.
    pub fn take_validation_messages(&self) -> Vec<String> {
        std::mem::take(&mut *lock(&self.messenger_state.messages))
    }

    /// Gives `handle` a debug name (shown by validation messages and RenderDoc). No-op without
    /// `VK_EXT_debug_utils`.
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        let name = c_string(name);
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // SAFETY: `handle` is an object of this device (callers pass their own objects) and the
        // name outlives the call.
        if let Err(e) = unsafe { debug.set_debug_utils_object_name(&info) } {
            log::debug!("vkSetDebugUtilsObjectNameEXT failed: {e:?}");
        }
    }

    /// Opens a debug label region in `cmd` (closed by [`GpuContext::end_label`]). No-op without
    /// `VK_EXT_debug_utils`.
    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        let name = c_string(name);
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        // SAFETY: `cmd` is a command buffer of this device in the recording state (the caller's
        // contract for any vkCmd call) and the label outlives the call.
        unsafe { debug.cmd_begin_debug_utils_label(cmd, &label) };
    }

    /// Closes the innermost label region opened by [`GpuContext::begin_label`].
    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        // SAFETY: `cmd` is recording and has an open label region (caller's contract).
        unsafe { debug.cmd_end_debug_utils_label(cmd) };
    }

    /// Where buffers' and images' memory comes from.
    pub fn memory(&self) -> &MemorySource {
        &self.memory
    }

    /// Records commands with `record`, submits them on the queue and waits for completion.
    ///
    /// For uploads, readbacks and setup work, not for frames. The command buffer is a primary one
    /// in the recording state; `record` must not call `submit_and_wait` itself (it would
    /// deadlock).
    ///
    /// Refused on a thread inside [`GpuContext::record_setup_into`]: work recorded there runs
    /// when the caller submits it, so nothing can be waited for (a read-back, say).
    pub fn submit_and_wait(&self, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
        if self.recording_setup_cmd().is_some() {
            return Err(LucentError::InvalidInput(
                "a submission was asked for while setup work is recorded into the caller's \
                 command buffer (nothing may be submitted or waited for there)"
                    .into(),
            ));
        }
        let one_shot = lock(&self.one_shot);
        let cmd = one_shot.cmd;
        // SAFETY: the pool, command buffer and fence belong to this device and are used only
        // under the `one_shot` lock; the previous submission was waited for before the lock was
        // released, so the pool's command buffer is not pending.
        unsafe {
            self.device
                .reset_command_pool(one_shot.pool, vk::CommandPoolResetFlags::empty())
                .vk("vkResetCommandPool")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.device
                .begin_command_buffer(cmd, &begin)
                .vk("vkBeginCommandBuffer")?;
        }
        record(cmd);
        // SAFETY: as above; the command buffer is in the recording state, then executable, and
        // the fence is unsignaled (it is reset after every wait).
        unsafe {
            self.device
                .end_command_buffer(cmd)
                .vk("vkEndCommandBuffer")?;
            let cmd_infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmd_infos);
            self.device
                .queue_submit2(self.queue, &[submit], one_shot.fence)
                .vk("vkQueueSubmit2")?;
            self.device
                .wait_for_fences(&[one_shot.fence], true, u64::MAX)
                .vk("vkWaitForFences")?;
            self.device
                .reset_fences(&[one_shot.fence])
                .vk("vkResetFences")?;
        }
        Ok(())
    }

    /// Runs `build` with this thread's setup work (uploads: their copies and barriers)
    /// recorded into `cmd` instead of submitted and waited for, and returns what `build`
    /// returned with what those copies use ([`SetupKept`]: the staging buffers they read, and
    /// every image, buffer and memory block `build` destroyed meanwhile, put off). The caller
    /// frees it ([`SetupKept::destroy`]) once the submission holding `cmd` has completed, on
    /// success or failure: a failed build leaves `cmd` valid to submit (its copies write
    /// resources nothing else uses), so the caller's other work in it is not lost.
    ///
    /// Each recorded copy ends with a full memory barrier, so every later command in the same
    /// queue's submission order sees its result. Other threads keep submitting their setup
    /// work as usual. A nested call on the same thread is refused.
    ///
    /// # Safety
    ///
    /// `cmd` is a primary command buffer of this device, in the recording state, outside any
    /// render pass, for a queue of [`GpuContext::queue_family`]; nothing else records into it
    /// until this returns.
    pub unsafe fn record_setup_into<T>(
        &self,
        cmd: vk::CommandBuffer,
        build: impl FnOnce() -> Result<T>,
    ) -> (Result<T>, SetupKept) {
        let thread = std::thread::current().id();
        if self.recording_setup_cmd().is_some() {
            return (
                Err(LucentError::InvalidInput(
                    "setup work is already being recorded on this thread".into(),
                )),
                SetupKept::default(),
            );
        }
        lock(&self.setup_recordings).push(SetupRecording {
            thread,
            cmd,
            kept: SetupKept::default(),
        });
        // A panic in `build` leaves this thread's entry behind; the next call on the thread
        // would be refused, which is loud rather than wrong.
        let built = build();
        let mut recordings = lock(&self.setup_recordings);
        let kept = match recordings.iter().position(|r| r.thread == thread) {
            Some(at) => recordings.swap_remove(at).kept,
            None => SetupKept::default(),
        };
        (built, kept)
    }

    /// Runs `destroy` now or, on a thread recording setup work into a caller's command buffer
    /// (whose copies may write what is destroyed), once the caller's submission of it has run
    /// ([`SetupKept::destroy`]).
    pub(crate) fn destroy_after_setup(&self, destroy: impl FnOnce(&GpuContext) + Send + 'static) {
        let thread = std::thread::current().id();
        {
            let mut recordings = lock(&self.setup_recordings);
            if let Some(recording) = recordings.iter_mut().find(|r| r.thread == thread) {
                recording.kept.destroyed.push(Box::new(destroy));
                return;
            }
        }
        destroy(self);
    }

    /// The command buffer this thread's setup work is recorded into, if any.
    fn recording_setup_cmd(&self) -> Option<vk::CommandBuffer> {
        let thread = std::thread::current().id();
        lock(&self.setup_recordings)
            .iter()
            .find(|r| r.thread == thread)
            .map(|r| r.cmd)
    }

    /// Runs one setup copy reading `staging`: recorded into this thread's setup command buffer
    /// (the staging buffer kept until the caller's submission ran) or submitted and waited for
    /// (the staging buffer freed at once).
    pub(crate) fn setup_copy(
        &self,
        staging: GpuBuffer,
        record: impl FnOnce(vk::CommandBuffer),
    ) -> Result<()> {
        let thread = std::thread::current().id();
        {
            let mut recordings = lock(&self.setup_recordings);
            if let Some(recording) = recordings.iter_mut().find(|r| r.thread == thread) {
                record(recording.cmd);
                recording.kept.staging.push(staging);
                return Ok(());
            }
        }
        let copied = self.submit_and_wait(record);
        self.destroy_buffer(staging);
        copied
    }

    /// Waits until the device is idle.
    pub fn wait_idle(&self) -> Result<()> {
        // SAFETY: the device is valid for the context's lifetime; vkDeviceWaitIdle requires
        // external synchronization of the queues, which callers provide (see the type docs).
        unsafe { self.device.device_wait_idle() }.vk("vkDeviceWaitIdle")
    }

    /// Names the objects lucent created for itself.
    fn name_own_objects(&self) {
        let one_shot = lock(&self.one_shot);
        self.set_name(one_shot.pool, "lucent one-shot pool");
        self.set_name(one_shot.cmd, "lucent one-shot commands");
        self.set_name(one_shot.fence, "lucent one-shot fence");
        if self.owns_handles {
            self.set_name(self.queue, "lucent queue");
        }
    }
}

impl Drop for GpuContext {
    fn drop(&mut self) {
        // SAFETY: nothing lucent created is in use: its own device is waited for here, and a
        // host's fences said its work was done before it dropped the wrapper (the host's
        // contract; waiting on a host's device would stall its other queues and race its
        // other threads' submissions). The one-shot fence is only signalled inside
        // submit_and_wait, which waits for it. Each object is destroyed once, children before
        // parents (allocator memory and pool before the device, messenger before the
        // instance), and the host's handles are left alone when wrapped. The messenger state
        // box is dropped after this body, i.e. after the messenger is gone.
        unsafe {
            if self.owns_handles {
                if let Err(e) = self.device.device_wait_idle() {
                    log::error!("vkDeviceWaitIdle failed while dropping the GPU context: {e:?}");
                }
            }
            let recordings = std::mem::take(
                self.setup_recordings
                    .get_mut()
                    .unwrap_or_else(|poisoned| poisoned.into_inner()),
            );
            for recording in recordings {
                recording.kept.destroy(self);
            }
            let one_shot = self
                .one_shot
                .get_mut()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            self.device.destroy_fence(one_shot.fence, None);
            self.device.destroy_command_pool(one_shot.pool, None);
            // lucent's own allocator reports leaked allocations (log_leaks_on_shutdown) and
            // frees its memory blocks here; a host's shared one only loses this reference,
            // and what lucent still holds from a host's own allocator is logged by name.
            self.memory.report_leaks();
            ManuallyDrop::drop(&mut self.memory);
            if self.owns_handles {
                self.device.destroy_device(None);
            }
            if let Some(debug) = &self.debug_instance {
                if self.messenger != vk::DebugUtilsMessengerEXT::null() {
                    debug.destroy_debug_utils_messenger(self.messenger, None);
                }
            }
            if self.owns_handles {
                self.instance.destroy_instance(None);
            }
        }
    }
}

/// What lucent creates on any device, owned or wrapped.
struct OwnedParts {
    memory: MemorySource,
    one_shot: OneShot,
}

/// lucent's own allocator for a device (leaks logged when it is dropped).
fn own_allocator(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    device: &ash::Device,
) -> Result<Allocator> {
    Allocator::new(&AllocatorCreateDesc {
        instance: instance.clone(),
        device: device.clone(),
        physical_device: pd,
        debug_settings: AllocatorDebugSettings {
            log_leaks_on_shutdown: true,
            ..Default::default()
        },
        buffer_device_address: false,
        allocation_sizes: Default::default(),
    })
    .map_err(|source| {
        LucentError::InvalidInput(format!(
            "the GPU memory allocator could not be created: {source}"
        ))
    })
}

fn create_owned_parts(
    instance: &ash::Instance,
    pd: vk::PhysicalDevice,
    device: &ash::Device,
    queue_family: u32,
    memory: Option<MemorySource>,
) -> Result<OwnedParts> {
    let memory = match memory {
        Some(host) => host,
        None => MemorySource::gpu_allocator(Arc::new(Mutex::new(own_allocator(
            instance, pd, device,
        )?))),
    };
    let pool_info = vk::CommandPoolCreateInfo::default()
        .flags(vk::CommandPoolCreateFlags::TRANSIENT)
        .queue_family_index(queue_family);
    // SAFETY: `device` is valid and `queue_family` is one of its queue families; each object
    // created here is destroyed on the error paths below or in GpuContext::drop.
    unsafe {
        let pool = device
            .create_command_pool(&pool_info, None)
            .vk("vkCreateCommandPool")?;
        let alloc_info = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = match device.allocate_command_buffers(&alloc_info) {
            Ok(cmds) if !cmds.is_empty() => cmds[0],
            Ok(_) => {
                device.destroy_command_pool(pool, None);
                return Err(LucentError::Vulkan {
                    call: "vkAllocateCommandBuffers",
                    result: vk::Result::ERROR_UNKNOWN,
                });
            }
            Err(result) => {
                device.destroy_command_pool(pool, None);
                return Err(LucentError::Vulkan {
                    call: "vkAllocateCommandBuffers",
                    result,
                });
            }
        };
        let fence = match device.create_fence(&vk::FenceCreateInfo::default(), None) {
            Ok(fence) => fence,
            Err(result) => {
                device.destroy_command_pool(pool, None);
                return Err(LucentError::Vulkan {
                    call: "vkCreateFence",
                    result,
                });
            }
        };
        Ok(OwnedParts {
            memory,
            one_shot: OneShot { pool, cmd, fence },
        })
    }
}
