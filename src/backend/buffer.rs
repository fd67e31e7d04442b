//! [`GpuBuffer`]: a buffer and its memory, as [`super::resources`] creates and frees them. A
//! module of its own so that the context, which keeps staging buffers of recorded setup
//! copies, and the resources, which make buffers on the context, do not import each other.

use ash::vk;
use super::memory::Allocation;

/// A buffer and its memory.
#[derive(Debug)]
pub struct GpuBuffer {
    /// The buffer.
    pub buffer: vk::Buffer,
    /// Size in bytes as requested (the allocation may be larger).
    pub size: u64,
    /// Debug name of the buffer and its memory.
    pub name: String,
    /// Its memory (`None` once freed).
    pub(super) allocation: Option<Allocation>,
}

impl GpuBuffer {
    /// The buffer's bytes when its memory is host-visible (`MemoryUse::Upload` / `MemoryUse::Readback`), else `None`.
    ///
    /// Memory from those locations is host-coherent; the caller must make sure the GPU is not
    /// writing the buffer while the slice is read.
    pub fn mapped_slice(&self) -> Option<&[u8]> {
        let slice = self.allocation.as_ref()?.mapped_slice()?;
        slice.get(..usize::try_from(self.size).ok()?)
    }

    /// Mutable access to the buffer's bytes when its memory is host-visible, else `None`.
    ///
    /// The caller must make sure the GPU is not using the buffer while it is written.
    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = usize::try_from(self.size).ok()?;
        let slice = self.allocation.as_mut()?.mapped_slice_mut()?;
        slice.get_mut(..size)
    }
}
