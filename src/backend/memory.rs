//! Where lucent's buffers and images get their device memory: from `gpu-allocator` (lucent's
//! own, or a host engine's shared one) or from a host engine's own allocator behind
//! [`HostAllocator`] (a VMA-based engine's, or one it wrote itself).
//!
//! Everything above this module sees one [`Allocation`] type whichever source made it, and
//! [`GpuContext`](super::GpuContext) asks its [`MemorySource`] for memory by what the
//! memory is for ([`MemoryUse`]), not by an allocator's own vocabulary.

use std::collections::BTreeMap;
use std::ptr::NonNull;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{AllocationCreateDesc, AllocationScheme, Allocator};
use gpu_allocator::MemoryLocation;

use super::desc::lock;
use crate::error::{format_bytes, HostError, LucentError, Result};

/// What a piece of memory is for, which decides the memory type's properties.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum MemoryUse {
    /// Only the GPU reads and writes it (images, vertex and index buffers, constants uploaded
    /// once): `DEVICE_LOCAL` where the device has it. Never mapped.
    DeviceLocal,
    /// lucent writes it from the CPU and the GPU reads it (staging of uploads, per-frame
    /// parameters): `HOST_VISIBLE | HOST_COHERENT`, mapped for the allocation's whole life
    /// (lucent never flushes).
    Upload,
    /// The GPU writes it and lucent reads it on the CPU (read-backs):
    /// `HOST_VISIBLE | HOST_COHERENT` (`HOST_CACHED` where there is such a type), mapped for
    /// the allocation's whole life.
    Readback,
}

impl MemoryUse {
    /// Whether lucent reads or writes the memory through a mapped pointer.
    pub fn is_mapped(self) -> bool {
        self != MemoryUse::DeviceLocal
    }

    /// gpu-allocator's name for the same use.
    fn location(self) -> MemoryLocation {
        match self {
            MemoryUse::DeviceLocal => MemoryLocation::GpuOnly,
            MemoryUse::Upload => MemoryLocation::CpuToGpu,
            MemoryUse::Readback => MemoryLocation::GpuToCpu,
        }
    }
}

/// One request lucent makes of a [`HostAllocator`].
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct MemoryRequest<'a> {
    /// What the memory is for, as lucent names the resource (a debug name: `"sss.sum"`,
    /// `"sss effect params"`): the name a leak report or an allocator's statistics can show.
    pub name: &'a str,
    /// The resource's memory requirements (size, alignment, the memory types it accepts).
    /// The memory given must be of a type in `memory_type_bits`, at least `size` bytes from
    /// an offset that is a multiple of `alignment`.
    pub requirements: vk::MemoryRequirements,
    /// What the memory is for: the properties its type must have.
    pub usage: MemoryUse,
    /// `true` for a buffer, `false` for an optimal-tiling image or a block that several
    /// images are bound into (what `bufferImageGranularity` separates when the host
    /// sub-allocates both from one `VkDeviceMemory`).
    pub linear: bool,
}

/// Device memory a [`HostAllocator`] gives lucent: a range of one `VkDeviceMemory`.
#[derive(Debug)]
#[non_exhaustive]
pub struct HostAllocation {
    /// The memory object (the host may sub-allocate it for many resources).
    pub memory: vk::DeviceMemory,
    /// Where lucent's range starts in `memory`.
    pub offset: vk::DeviceSize,
    /// The range's size (at least the request's `requirements.size`).
    pub size: vk::DeviceSize,
    /// For an [`Upload`](MemoryUse::Upload) or [`Readback`](MemoryUse::Readback) request:
    /// the CPU address of the range's first byte (of `offset`, not of the memory's start),
    /// valid until lucent frees the allocation.
    pub mapped: Option<NonNull<u8>>,
    /// The host's own handle for this allocation (a `VmaAllocation`, an index, a pointer),
    /// handed back to [`HostAllocator::free`] untouched.
    pub host_handle: u64,
}

impl HostAllocation {
    /// A range of `size` bytes at `offset` in `memory`, not mapped, with the host's own handle
    /// for it.
    pub fn new(
        memory: vk::DeviceMemory,
        offset: vk::DeviceSize,
        size: vk::DeviceSize,
        host_handle: u64,
    ) -> Self {
        Self {
            memory,
            offset,
            size,
            mapped: None,
            host_handle,
        }
    }

    /// The same range, mapped at `pointer` (the CPU address of its first byte).
    pub fn mapped_at(mut self, pointer: NonNull<u8>) -> Self {
        self.mapped = Some(pointer);
        self
    }

    /// Checks the allocation against the request it answers; the problem in words.
    fn check(&self, request: &MemoryRequest<'_>) -> std::result::Result<(), String> {
        let wanted = request.requirements;
        if self.memory == vk::DeviceMemory::null() {
            return Err("the allocator returned a null VkDeviceMemory".into());
        }
        if self.size < wanted.size {
            return Err(format!(
                "the allocator returned {} where the resource needs {}",
                format_bytes(self.size),
                format_bytes(wanted.size)
            ));
        }
        if !self.offset.is_multiple_of(wanted.alignment.max(1)) {
            return Err(format!(
                "the allocator returned offset {} where the resource needs a multiple of {}",
                self.offset, wanted.alignment
            ));
        }
        if request.usage.is_mapped() && self.mapped.is_none() {
            return Err(format!(
                "{:?} memory must be mapped (HostAllocation::mapped_at) but the allocator \
                 returned no CPU address",
                request.usage
            ));
        }
        Ok(())
    }
}

// SAFETY: a `HostAllocation` is plain data: handles, numbers and the address of mapped memory,
// which stays valid until the allocation is freed. lucent reads or writes through the address
// only through `Allocation::mapped_slice(_mut)`, borrowed from the one owner of the
// allocation, so moving or sharing it between threads adds no unsynchronized access.
unsafe impl Send for HostAllocation {}
// SAFETY: as for `Send`: `&HostAllocation` gives no write access to the mapped memory.
unsafe impl Sync for HostAllocation {}

/// A host engine's own device-memory allocator, which lucent takes every buffer's and
/// image's memory from ([`crate::embed::EmbedOptions::memory`]).
///
/// lucent calls it from whichever thread builds or destroys an effect (effects are `Send`),
/// so it must be callable from several threads at once. lucent binds each allocation to one
/// resource (or to a block several of its images alias), never maps, unmaps or frees the
/// `VkDeviceMemory` itself, and returns each allocation once, through [`free`], after the GPU
/// is done with the resource (the host's fences said so before it destroyed the effect).
///
/// [`free`]: HostAllocator::free
pub trait HostAllocator: Send + Sync {
    /// Allocates memory for `request`. An error (`ERROR_OUT_OF_DEVICE_MEMORY`, ...) is
    /// returned to the caller that asked lucent for the resource, as
    /// [`LucentError::HostAllocation`] naming it.
    fn allocate(&self, request: &MemoryRequest<'_>) -> std::result::Result<HostAllocation, vk::Result>;

    /// Takes back an allocation [`allocate`](HostAllocator::allocate) returned. Also called,
    /// at once, for an allocation lucent refused (too small, misaligned, not mapped).
    fn free(&self, allocation: HostAllocation);
}

/// Memory from either source, bound to one of lucent's resources.
#[derive(Debug)]
pub struct Allocation(Source);

#[derive(Debug)]
enum Source {
    GpuAllocator(gpu_allocator::vulkan::Allocation),
    Host {
        allocation: HostAllocation,
        /// The allocation's number in its [`MemorySource`]'s list of live allocations.
        serial: u64,
    },
}

impl Allocation {
    /// The `VkDeviceMemory` the range lives in (shared with other ranges: never free it).
    pub fn memory(&self) -> vk::DeviceMemory {
        match &self.0 {
            // SAFETY: only the handle is read; gpu-allocator marks this unsafe because freeing
            // or sub-allocating the memory behind its back would be unsound, which lucent never
            // does.
            Source::GpuAllocator(allocation) => unsafe { allocation.memory() },
            Source::Host { allocation, .. } => allocation.memory,
        }
    }

    /// Where the range starts in [`Allocation::memory`].
    pub fn offset(&self) -> u64 {
        match &self.0 {
            Source::GpuAllocator(allocation) => allocation.offset(),
            Source::Host { allocation, .. } => allocation.offset,
        }
    }

    /// The range's size in bytes.
    pub fn size(&self) -> u64 {
        match &self.0 {
            Source::GpuAllocator(allocation) => allocation.size(),
            Source::Host { allocation, .. } => allocation.size,
        }
    }

    /// The range's bytes when it is mapped ([`MemoryUse::Upload`] or
    /// [`MemoryUse::Readback`]).
    pub fn mapped_slice(&self) -> Option<&[u8]> {
        match &self.0 {
            Source::GpuAllocator(allocation) => allocation.mapped_slice(),
            Source::Host { allocation, .. } => {
                let pointer = allocation.mapped?;
                let len = usize::try_from(allocation.size).ok()?;
                // SAFETY: the host's contract (`HostAllocation::mapped`): the address maps the
                // range's `size` bytes until the allocation is freed, which needs this
                // `Allocation` by value; the borrow of `self` keeps it alive meanwhile.
                Some(unsafe { std::slice::from_raw_parts(pointer.as_ptr(), len) })
            }
        }
    }

    /// The range's bytes, writable, when it is mapped.
    pub fn mapped_slice_mut(&mut self) -> Option<&mut [u8]> {
        match &mut self.0 {
            Source::GpuAllocator(allocation) => allocation.mapped_slice_mut(),
            Source::Host { allocation, .. } => {
                let pointer = allocation.mapped?;
                let len = usize::try_from(allocation.size).ok()?;
                // SAFETY: as in `mapped_slice`; `&mut self` makes this the only borrow.
                Some(unsafe { std::slice::from_raw_parts_mut(pointer.as_ptr(), len) })
            }
        }
    }
}

/// Where a context's memory comes from: `gpu-allocator` (lucent's own or a host's shared
/// one) or a host's own [`HostAllocator`].
pub struct MemorySource(Kind);

enum Kind {
    /// `gpu-allocator`: lucent's own (leaks logged when it is dropped) or a host's shared one.
    GpuAllocator(Arc<Mutex<Allocator>>),
    /// A host's own allocator, and the names and sizes of what lucent holds from it (the
    /// leak report: a host allocator need not keep names).
    Host {
        allocator: Arc<dyn HostAllocator>,
        live: Mutex<BTreeMap<u64, (String, u64)>>,
        next_serial: AtomicU64,
    },
}

impl MemorySource {
    /// A `gpu-allocator` (created for the context's device).
    pub fn gpu_allocator(allocator: Arc<Mutex<Allocator>>) -> Self {
        MemorySource(Kind::GpuAllocator(allocator))
    }

    /// A host's own allocator.
    pub fn host(allocator: Arc<dyn HostAllocator>) -> Self {
        MemorySource(Kind::Host {
            allocator,
            live: Mutex::new(BTreeMap::new()),
            next_serial: AtomicU64::new(0),
        })
    }

    /// Allocates `requirements` for the resource `name`.
    pub fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        usage: MemoryUse,
        linear: bool,
    ) -> Result<Allocation> {
        match &self.0 {
            Kind::GpuAllocator(allocator) => lock(allocator)
                .allocate(&AllocationCreateDesc {
                    name,
                    requirements,
                    location: usage.location(),
                    linear,
                    allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                })
                .map(|allocation| Allocation(Source::GpuAllocator(allocation)))
                .map_err(|source| LucentError::Allocation {
                    name: name.to_string(),
                    bytes: requirements.size,
                    source,
                }),
            Kind::Host {
                allocator,
                live,
                next_serial,
            } => {
                let request = MemoryRequest {
                    name,
                    requirements,
                    usage,
                    linear,
                };
                let allocation = allocator.allocate(&request).map_err(|result| {
                    LucentError::HostAllocation {
                        name: name.to_string(),
                        bytes: requirements.size,
                        result,
                    }
                })?;
                if let Err(problem) = allocation.check(&request) {
                    // Refused: it goes straight back, so nothing leaks on this path.
                    allocator.free(allocation);
                    return Err(HostError::Memory {
                        allocation: name.to_string(),
                        problem,
                    }
                    .into());
                }
                let serial = next_serial.fetch_add(1, Ordering::Relaxed);
                lock(live).insert(serial, (name.to_string(), allocation.size));
                Ok(Allocation(Source::Host { allocation, serial }))
            }
        }
    }

    /// Returns an allocation to the source it came from; a failure (gpu-allocator's double
    /// free) is logged, not fatal.
    pub fn free(&self, allocation: Allocation, name: &str) {
        match (&self.0, allocation.0) {
            (Kind::GpuAllocator(allocator), Source::GpuAllocator(allocation)) => {
                if let Err(e) = lock(allocator).free(allocation) {
                    log::error!("freeing GPU memory '{name}' failed: {e}");
                }
            }
            (Kind::Host { allocator, live, .. }, Source::Host { allocation, serial }) => {
                lock(live).remove(&serial);
                allocator.free(allocation);
            }
            // A context has one source for its whole life, so every allocation it frees
            // came from it.
            _ => log::error!("GPU memory '{name}' was freed to another allocator than its own"),
        }
    }

    /// Logs every allocation still held from a host's allocator (gpu-allocator reports its
    /// own when lucent's is dropped): a resource lucent forgot to destroy, named.
    pub fn report_leaks(&self) {
        if let Kind::Host { live, .. } = &self.0 {
            for (name, bytes) in lock(live).values() {
                log::error!(
                    "lucent still holds '{name}' ({}) from the host's allocator: a resource \
                     was not destroyed",
                    format_bytes(*bytes)
                );
            }
        }
    }
}
