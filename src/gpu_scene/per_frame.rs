//! What changes from frame to frame, once per frame in flight: the frame uniforms (camera,
//! lights), the translucency material table, the SSS profile and kernel tables and the
//! light-space maps' table, each a region of one
//! host-visible uniform buffer with one slot per frame in flight, and the screen tiles the
//! passes draw their expensive variants in.
//!
//! A frame recorded for slot `k` reads only slot `k` (passes bind the regions as dynamic
//! uniform buffers at offset `k * stride`), so the CPU writes slot `k + 1` while the GPU still
//! reads slot `k`: N frames can be recorded and submitted before the first completes. Writing
//! a knob that only changes these values (a light, a material's translucency power, an SSS
//! width) never re-uploads the scene.

use std::sync::{Mutex, MutexGuard};

use ash::vk;
use glam::Vec3;

use super::tiles::TileRect;
use crate::backend::{GpuBuffer, GpuContext};
use crate::scene::{LightKind, Scene, MAX_LIGHTS};
use crate::{LucentError, Result};

/// Frame uniforms, std140 (glsl/common/scene.glsl `Frame`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    view_proj: [[f32; 4]; 4],
    inv_view_proj: [[f32; 4]; 4],
    view: [[f32; 4]; 4],
    camera_pos: [f32; 4],
    /// The environment's nine SH irradiance coefficients (`E(n) / π` as a polynomial in n).
    ambient_sh: [[f32; 4]; 9],
    sky: [f32; 4],
    viewport: [f32; 4],
    exposure: [f32; 4],
    light_count: [i32; 4],
    camera: [f32; 4],
    /// Robustness tests (LUCENT_FAULT_INJECTION): x, y pixel; z 1 NaN, 2 +Inf.
    pub fault: [i32; 4],
    lights: [[[f32; 4]; 4]; MAX_LIGHTS],
}

impl FrameUniforms {
    /// Fills the uniforms from a scene at a size.
    pub fn new(scene: &Scene, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let view_proj = scene.camera.projection(aspect) * scene.camera.view();
        let mut lights = [[[0.0; 4]; 4]; MAX_LIGHTS];
        for (slot, light) in lights.iter_mut().zip(&scene.lights) {
            let radiance = light.radiance();
            let scale = light.translucency_scale;
            *slot = match light.kind {
                LightKind::Directional { direction } => [
                    direction.extend(0.0).to_array(),
                    radiance.extend(0.0).to_array(),
                    [0.0; 4],
                    [1.0, scale, 0.0, 0.0],
                ],
                LightKind::Point { position, range } => [
                    position.extend(1.0).to_array(),
                    radiance.extend(range).to_array(),
                    [0.0; 4],
                    [1.0, scale, 0.0, 0.0],
                ],
                LightKind::Spot {
                    position,
                    direction,
                    range,
                    inner_degrees,
                    outer_degrees,
                } => [
                    position.extend(2.0).to_array(),
                    radiance.extend(range).to_array(),
                    direction
                        .normalize_or(Vec3::NEG_Y)
                        .extend(outer_degrees.to_radians().cos())
                        .to_array(),
                    [inner_degrees.to_radians().cos(), scale, 0.0, 0.0],
                ],
            };
        }
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            view: scene.camera.view().to_cols_array_2d(),
            camera_pos: scene.camera.eye.extend(1.0).to_array(),
            ambient_sh: scene.environment.coefficients(),
            sky: scene.sky.extend(0.0).to_array(),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            exposure: [scene.exposure, 0.0, 0.0, 0.0],
            light_count: [scene.lights.len().min(MAX_LIGHTS) as i32, 0, 0, 0],
            camera: [
                scene.camera.near,
                scene.camera.far,
                scene.camera.focal_px(height),
                0.0,
            ],
            fault: [0; 4],
            lights,
        }
    }
}

/// A region of every slot of the per-frame buffer: one table, declared as a `static` by the
/// feature that writes it (`features::translucency::TABLE_REGION`, ...) and known by its
/// address, so a new feature's table is a new static, not an edit here. [`FRAME`] (the frame
/// uniforms) is in every frame; a table is in a frame when its feature lists it among the
/// frame's [`TableRegion`]s.
#[derive(Debug)]
pub struct Region {
    /// What it holds, for errors (never empty: two statics never share an address).
    pub name: &'static str,
}

impl Region {
    /// A region holding `name`.
    pub const fn new(name: &'static str) -> Self {
        Self { name }
    }
}

impl PartialEq for Region {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

impl Eq for Region {}

/// The frame uniforms ([`FrameUniforms`]): every pass's binding 0.
pub static FRAME: Region = Region::new("frame uniforms");

/// A table region of a frame and its size in bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TableRegion {
    /// The region.
    pub region: &'static Region,
    /// Its bytes (> 0).
    pub bytes: u64,
}

/// The rectangles the passes draw in this slot's frame.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SlotTiles {
    /// The lighting pass's rectangles, each marked where translucent objects may be (frames
    /// with translucency).
    pub lighting: Vec<TileRect>,
    /// Per SSS chain (in the frame's chain order): its rectangles, marked where objects of the
    /// chain's blur (widened by their profile's reach) may be; `None`: the whole screen.
    pub sss: Vec<Option<Vec<TileRect>>>,
    /// The layered passes' rectangles, marked where layered objects may be (frames with
    /// layered materials).
    pub layered: Vec<TileRect>,
    /// The multiple-scattering term's blur's rectangles: marked where layered objects whose
    /// medium the blur acts on at their distance may be (none: the blur draws nothing).
    pub layered_blur: Vec<TileRect>,
}

/// A binding of one region of the per-frame buffer: a dynamic uniform buffer whose offset the
/// pass adds at bind time (`slot * stride`).
pub type PerFrameBinding = crate::backend::descriptor::DynamicUniform;

/// The per-frame buffer and tiles, one slot per frame in flight (see the module docs).
pub struct PerFrame {
    /// Locked only while the CPU writes a slot (passes bind `handle`).
    buffer: Mutex<GpuBuffer>,
    handle: vk::Buffer,
    /// Each region of a slot: the region, its offset in the slot, its bytes (the frame
    /// uniforms first).
    regions: Vec<(&'static Region, u64, u64)>,
    stride: u64,
    slots: usize,
    tiles: Vec<Mutex<SlotTiles>>,
}

impl PerFrame {
    /// Creates the buffer for `slots` frames in flight (1 to [`MAX_FRAMES_IN_FLIGHT`]), with
    /// the frame uniforms and `tables` in each slot.
    pub fn new(gpu: &GpuContext, slots: usize, tables: &[TableRegion], name: &str) -> Result<Self> {
        if !(1..=MAX_FRAMES_IN_FLIGHT).contains(&slots) {
            return Err(LucentError::InvalidInput(format!(
                "{slots} frames in flight: 1 to {MAX_FRAMES_IN_FLIGHT} are supported"
            )));
        }
        let align = gpu.info.uniform_offset_alignment.max(16);
        let round = |v: u64| v.div_ceil(align) * align;
        let frame = TableRegion {
            region: &FRAME,
            bytes: std::mem::size_of::<FrameUniforms>() as u64,
        };
        let mut regions: Vec<(&'static Region, u64, u64)> = Vec::new();
        let mut end = 0u64;
        for table in std::iter::once(&frame).chain(tables) {
            if table.bytes == 0 || regions.iter().any(|(r, _, _)| *r == table.region) {
                return Err(LucentError::InvalidInput(format!(
                    "per-frame region '{}' listed twice or empty",
                    table.region.name
                )));
            }
            regions.push((table.region, end, table.bytes));
            end = round(end + table.bytes);
        }
        let stride = end;
        let buffer = gpu.create_buffer(
            stride * slots as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            gpu_allocator::MemoryLocation::CpuToGpu,
            &format!("{name} per-frame parameters"),
        )?;
        Ok(Self {
            handle: buffer.buffer,
            buffer: Mutex::new(buffer),
            regions,
            stride,
            slots,
            tiles: (0..slots)
                .map(|_| Mutex::new(SlotTiles::default()))
                .collect(),
        })
    }

    /// Frames in flight (slots).
    pub fn slots(&self) -> usize {
        self.slots
    }

    /// Whether the frame has `region`.
    pub fn has(&self, region: &Region) -> bool {
        self.find(region).is_some()
    }

    /// `region`'s offset in a slot and bytes.
    fn find(&self, region: &Region) -> Option<(u64, u64)> {
        self.regions
            .iter()
            .find(|(r, _, _)| *r == region)
            .map(|&(_, offset, bytes)| (offset, bytes))
    }

    /// The descriptor binding of `region` (bound with the slot's offset, see [`Self::offset`]).
    /// A region the frame lacks binds the slot's first 16 bytes: a pass may declare a table it
    /// only reads behind a specialization its frame never takes.
    pub fn binding(&self, region: &Region) -> PerFrameBinding {
        let (offset, bytes) = self.find(region).unwrap_or((0, 16));
        PerFrameBinding {
            buffer: self.handle,
            offset,
            range: bytes.max(16),
            stride: self.stride,
        }
    }

    /// The dynamic offset of `slot` (the same for every region).
    pub fn offset(&self, slot: usize) -> u32 {
        // At most MAX_FRAMES_IN_FLIGHT slots of a few tens of kilobytes: fits u32.
        (self.stride * slot.min(self.slots - 1) as u64) as u32
    }

    /// Writes `bytes` into `region` of `slot`. The GPU must not be reading that slot (its
    /// last frame has completed).
    pub fn write(&self, slot: usize, region: &Region, bytes: &[u8]) -> Result<()> {
        let (offset, size) = self.find(region).unwrap_or((0, 0));
        if slot >= self.slots || bytes.len() as u64 > size {
            return Err(LucentError::InvalidInput(format!(
                "per-frame write of {} bytes into slot {slot} region '{}' (slots {}, size {size})",
                bytes.len(),
                region.name,
                self.slots,
            )));
        }
        let start = (self.stride * slot as u64 + offset) as usize;
        // A poisoned lock only means a writer panicked mid-copy; the bytes are plain data.
        let mut buffer = self.buffer.lock().unwrap_or_else(|e| e.into_inner());
        let mapped = buffer.mapped_mut().ok_or_else(|| {
            LucentError::InvalidInput("the per-frame buffer is not host-visible".into())
        })?;
        mapped[start..start + bytes.len()].copy_from_slice(bytes);
        Ok(())
    }

    /// The tiles of `slot`, for the renderer to write before recording and the passes to read
    /// while recording (never contended: one slot is recorded by one thread at a time).
    pub fn tiles(&self, slot: usize) -> MutexGuard<'_, SlotTiles> {
        // A poisoned lock only means a recording thread panicked; the data is plain.
        self.tiles[slot.min(self.slots - 1)]
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    }

    /// Frees the buffer. The GPU must be done with it.
    pub fn destroy(self, gpu: &GpuContext) {
        gpu.destroy_buffer(self.buffer.into_inner().unwrap_or_else(|e| e.into_inner()));
    }
}

/// Most frames in flight a renderer takes (engines use 2 or 3).
pub const MAX_FRAMES_IN_FLIGHT: usize = 4;
