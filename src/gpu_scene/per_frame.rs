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
use crate::scene::{Light, LightKind, Scene, MAX_LIGHTS};
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
    /// View-space depth from a depth image's value ([`depth_decode`]).
    depth_decode: [f32; 4],
    /// Robustness tests (LUCENT_FAULT_INJECTION): x, y pixel; z 1 NaN, 2 +Inf.
    pub fault: [i32; 4],
    lights: [[[f32; 4]; 4]; MAX_LIGHTS],
}

impl FrameUniforms {
    /// Fills the uniforms from a scene at a size.
    pub fn new(scene: &Scene, width: u32, height: u32) -> Self {
        let aspect = width as f32 / height.max(1) as f32;
        let projection = scene.camera.projection(aspect);
        let view_proj = projection * scene.camera.view();
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
            light_count: [0; 4],
            camera: [
                scene.camera.near,
                scene.camera.far,
                scene.camera.focal_px(height),
                0.0,
            ],
            depth_decode: depth_decode(&projection),
            fault: [0; 4],
            lights: [[[0.0; 4]; 4]; MAX_LIGHTS],
        }
        .with_lights(&scene.lights)
    }

    /// The uniforms of a host's view (embedding): its view and projection matrices, the
    /// decode of its depth image (`depth_decode`: [`projection_depth_decode`], or the identity
    /// for a linear depth image) and the image size; no lights, environment or sky (the
    /// effects that read a scene's fill those in themselves).
    pub fn for_view(
        view: glam::Mat4,
        projection: glam::Mat4,
        width: u32,
        height: u32,
        depth_decode: [f32; 4],
    ) -> Self {
        let view_proj = projection * view;
        let eye = view.inverse().w_axis.truncate();
        let linear = |d: f32| {
            let v = decoded_depth(depth_decode, d);
            if v.is_finite() {
                v
            } else {
                f32::MAX
            }
        };
        let (a, b) = (linear(0.0), linear(1.0));
        Self {
            view_proj: view_proj.to_cols_array_2d(),
            inv_view_proj: view_proj.inverse().to_cols_array_2d(),
            view: view.to_cols_array_2d(),
            camera_pos: eye.extend(1.0).to_array(),
            ambient_sh: [[0.0; 4]; 9],
            sky: [0.0; 4],
            viewport: [
                width as f32,
                height as f32,
                1.0 / width.max(1) as f32,
                1.0 / height.max(1) as f32,
            ],
            exposure: [1.0, 0.0, 0.0, 0.0],
            light_count: [0; 4],
            // Near and far as the decode reads the depth range's two ends; the focal length
            // from the projection's vertical scale (its sign is the host's y convention).
            camera: [
                a.min(b),
                a.max(b),
                projection.y_axis.y.abs() * height as f32 * 0.5,
                0.0,
            ],
            depth_decode,
            fault: [0; 4],
            lights: [[[0.0; 4]; 4]; MAX_LIGHTS],
        }
    }

    /// These uniforms with an environment's nine SH coefficients
    /// ([`crate::scene::Environment::coefficients`]) instead of their own.
    pub fn with_environment(mut self, coefficients: [[f32; 4]; 9]) -> Self {
        self.ambient_sh = coefficients;
        self
    }

    /// These uniforms with `lights` (at most [`MAX_LIGHTS`]; the rest are dropped: callers
    /// refuse more) instead of their own.
    pub fn with_lights(mut self, lights: &[Light]) -> Self {
        self.lights = [[[0.0; 4]; 4]; MAX_LIGHTS];
        for (slot, light) in self.lights.iter_mut().zip(lights) {
            *slot = light_rows(light);
        }
        self.light_count = [lights.len().min(MAX_LIGHTS) as i32, 0, 0, 0];
        self
    }
}

/// One light as glsl/common/scene.glsl's `Light` holds it.
pub(crate) fn light_rows(light: &Light) -> [[f32; 4]; 4] {
    let radiance = light.radiance();
    let scale = light.translucency_scale;
    match light.kind {
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
    }
}

/// The coefficients `[x, y, z, w]` of view-space depth `(x + y d) / (z + w d)` from the device
/// depth `d` that `projection` (view to Vulkan clip space, any perspective: standard or reversed
/// Z, finite or infinite far) writes: from `clip.z = P22 z + P32`, `clip.w = P23 z + P33` and
/// view depth `-z`. Scaled so that the larger of |z| and |w| is 1 and the denominator is
/// positive at mid-range (glsl/common/scene.glsl `linear_depth` clamps it there). `None` when
/// the matrix has no finite, non-degenerate depth mapping.
pub fn projection_depth_decode(projection: &glam::Mat4) -> Option<[f32; 4]> {
    let c = projection.to_cols_array_2d();
    // c[col][row]: P22 = c[2][2], P32 = c[3][2], P23 = c[2][3], P33 = c[3][3].
    let mut k = [-c[3][2], c[3][3], -c[2][2], c[2][3]];
    let scale = k[2].abs().max(k[3].abs());
    if !(scale.is_finite() && scale > 0.0) || k.iter().any(|v| !v.is_finite()) {
        return None;
    }
    k.iter_mut().for_each(|v| *v /= scale);
    if k[2] + 0.5 * k[3] < 0.0 {
        k.iter_mut().for_each(|v| *v = -*v);
    }
    // Both terms zero would be a projection that maps every depth to one value.
    (k[0] != 0.0 || k[1] != 0.0).then_some(k)
}

/// The view depths `projection` puts at the two ends of the device depth range (depth 0, depth
/// 1), from [`projection_depth_decode`] evaluated in f64 (near an end the decode's denominator
/// is a difference of nearly equal terms): +infinity at an end where the denominator vanishes
/// (an infinite far plane). `None` where the matrix has no depth mapping.
pub fn projection_depth_ends(projection: &glam::Mat4) -> Option<(f64, f64)> {
    let k = projection_depth_decode(projection)?.map(f64::from);
    let at = |d: f64| {
        let denominator = k[2] + k[3] * d;
        let depth = (k[0] + k[1] * d) / denominator;
        if denominator <= 1e-9 * k[2].abs().max(k[3].abs()) || !depth.is_finite() {
            f64::INFINITY
        } else {
            depth
        }
    };
    Some((at(0.0), at(1.0)))
}

/// The view depth the decode `k` ([`projection_depth_decode`]) gives a depth image's value `d`:
/// glsl/common/scene.glsl's `linear_depth`, its denominator clamped the same way.
fn decoded_depth(k: [f32; 4], d: f32) -> f32 {
    (k[0] + k[1] * d) / (k[2] + k[3] * d).max(1e-7)
}

/// [`projection_depth_decode`] for lucent's own cameras (always a finite perspective); the
/// identity if a degenerate matrix ever reached it.
fn depth_decode(projection: &glam::Mat4) -> [f32; 4] {
    projection_depth_decode(projection).unwrap_or([0.0, 1.0, 1.0, 0.0])
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
    /// The name of the uniform block the shaders read it as (`uniform Frame { ... };`), by
    /// which a pass binding it gives the block its number ([`crate::backend::bindings`]).
    pub block: &'static str,
}

impl Region {
    /// A region holding `name`, read by the shaders as the uniform block `block`.
    pub const fn new(name: &'static str, block: &'static str) -> Self {
        Self { name, block }
    }
}

impl PartialEq for Region {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
    }
}

impl Eq for Region {}

/// The frame uniforms ([`FrameUniforms`]): every pass's binding 0.
pub static FRAME: Region = Region::new("frame uniforms", "Frame");

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
            crate::backend::memory::MemoryUse::Upload,
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

    /// Bytes of the buffer: every slot's regions.
    pub fn bytes(&self) -> u64 {
        self.stride * self.slots as u64
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

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec4};

    /// The view depth a device depth `d` stands for under `projection`: the f64 twin of
    /// glsl/common/scene.glsl's `linear_depth` with `projection_depth_decode`'s coefficients.
    fn decoded(k: [f32; 4], d: f64) -> f64 {
        let k = k.map(f64::from);
        (k[0] + k[1] * d) / (k[2] + k[3] * d).max(1e-7)
    }

    /// The device depth `projection` writes for a point at view depth `z` (> 0, on the axis).
    fn device_depth(projection: &Mat4, z: f32) -> f64 {
        let clip = *projection * Vec4::new(0.0, 0.0, -z, 1.0);
        f64::from(clip.z) / f64::from(clip.w)
    }

    #[test]
    fn depth_decodes_for_every_projection_a_host_uses() {
        let fov = 1.0_f32;
        let (n, f) = (0.1_f32, 50.0_f32);
        let mut flipped = Mat4::perspective_rh(fov, 1.5, n, f);
        flipped.y_axis.y = -flipped.y_axis.y;
        let projections = [
            ("standard", Mat4::perspective_rh(fov, 1.5, n, f)),
            ("standard, y flipped (lucent's own)", flipped),
            ("reversed", Mat4::perspective_rh(fov, 1.5, f, n)),
            ("infinite", Mat4::perspective_infinite_rh(fov, 1.5, n)),
            (
                "infinite reversed",
                Mat4::perspective_infinite_reverse_rh(fov, 1.5, n),
            ),
        ];
        for (name, p) in projections {
            let k = projection_depth_decode(&p).unwrap_or_else(|| panic!("{name}"));
            for z in [0.1_f32, 0.5, 3.0, 17.0, 49.0] {
                let got = decoded(k, device_depth(&p, z));
                // Relative: f32 device depths near the far plane carry little precision.
                let tolerance = 2e-3 * f64::from(z).max(1.0) * f64::from(z) / f64::from(n).max(1.0);
                assert!(
                    (got - f64::from(z)).abs() <= tolerance.max(1e-4),
                    "{name}: z {z} decoded as {got}"
                );
            }
        }
        // The far plane of an infinite projection decodes finite, not Inf.
        let k =
            projection_depth_decode(&Mat4::perspective_infinite_reverse_rh(fov, 1.5, n)).unwrap();
        assert!(decoded(k, 0.0).is_finite());
        let k = projection_depth_decode(&Mat4::perspective_infinite_rh(fov, 1.5, n)).unwrap();
        assert!(decoded(k, 1.0).is_finite());
    }

    #[test]
    fn a_degenerate_projection_has_no_depth_decode() {
        assert!(projection_depth_decode(&Mat4::ZERO).is_none());
        assert!(projection_depth_decode(&Mat4::from_cols_array(&[f32::NAN; 16])).is_none());
    }
}
