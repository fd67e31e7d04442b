//! Accessors read with every bound checked (glTF 2.0 §3.6): the accessor inside its buffer
//! view, the view inside its buffer, strides no smaller than an element (overlapping
//! elements) and at most 252 bytes, counts under the OBJ loader's caps, all arithmetic in
//! checked `u64`, so a count of 2^32 or an offset past the end is an error naming the
//! accessor, never a wrapped index or an allocation the data does not back.

use ::gltf::json;
use ::gltf::json::accessor::{ComponentType, Type};
use ::gltf::json::validation::Checked;
use glam::{Vec2, Vec3, Vec4};

/// The largest `byteStride` glTF allows (§3.6.2.4).
const MAX_STRIDE: u64 = 252;

/// The buffers of a document, read by accessor.
pub struct Accessors<'a> {
    pub root: &'a json::Root,
    pub buffers: &'a [std::sync::Arc<[u8]>],
}

/// One accessor's elements located in its buffer.
struct Located<'a> {
    /// The buffer bytes from the first element's start to the last element's end.
    bytes: &'a [u8],
    stride: usize,
    count: usize,
    component: ComponentType,
    components: usize,
    normalized: bool,
}

fn component_bytes(c: ComponentType) -> u64 {
    match c {
        ComponentType::I8 | ComponentType::U8 => 1,
        ComponentType::I16 | ComponentType::U16 => 2,
        ComponentType::U32 | ComponentType::F32 => 4,
    }
}

fn component_count(t: Type) -> u64 {
    match t {
        Type::Scalar => 1,
        Type::Vec2 => 2,
        Type::Vec3 => 3,
        Type::Vec4 | Type::Mat2 => 4,
        Type::Mat3 => 9,
        Type::Mat4 => 16,
    }
}

impl<'a> Accessors<'a> {
    /// Accessor `index` located, its type one of `types`, at most `max_count` elements.
    fn locate(&self, index: usize, types: &[Type], max_count: u64) -> Result<Located<'a>, String> {
        let what = format!("accessors[{index}]");
        let accessor = self
            .root
            .accessors
            .get(index)
            .ok_or_else(|| format!("{what} does not exist"))?;
        if accessor.sparse.is_some() {
            return Err(format!("{what}: sparse accessors are not supported"));
        }
        let (Checked::Valid(json::accessor::GenericComponentType(component)), Checked::Valid(ty)) =
            (&accessor.component_type, &accessor.type_)
        else {
            return Err(format!("{what}: invalid componentType or type"));
        };
        let (component, ty) = (*component, *ty);
        if !types.contains(&ty) {
            return Err(format!("{what}: type {ty:?}, expected one of {types:?}"));
        }
        let count = accessor.count.0;
        if count == 0 {
            return Err(format!("{what}: count is 0"));
        }
        if count > max_count {
            return Err(format!(
                "{what}: count {count} is more than the {max_count} lucent accepts"
            ));
        }
        let view_index = accessor
            .buffer_view
            .ok_or_else(|| {
                format!("{what} has no bufferView (all zeros): no geometry to read from it")
            })?
            .value();
        let view = self
            .root
            .buffer_views
            .get(view_index)
            .ok_or_else(|| format!("{what}: bufferViews[{view_index}] does not exist"))?;
        let view_what = format!("bufferViews[{view_index}]");
        let buffer_index = view.buffer.value();
        let buffer = self
            .buffers
            .get(buffer_index)
            .ok_or_else(|| format!("{view_what}: buffers[{buffer_index}] does not exist"))?;
        let view_offset = view.byte_offset.map_or(0, |o| o.0);
        let view_length = view.byte_length.0;
        let view_end = view_offset
            .checked_add(view_length)
            .filter(|&end| end <= buffer.len() as u64)
            .ok_or_else(|| {
                format!(
                    "{view_what} (offset {view_offset}, length {view_length}) runs past the end \
                     of buffers[{buffer_index}] ({} bytes)",
                    buffer.len()
                )
            })?;
        let element = component_bytes(component) * component_count(ty);
        let stride = match view.byte_stride {
            None => element,
            Some(json::buffer::Stride(s)) => {
                let s = s as u64;
                if s < element {
                    return Err(format!(
                        "{view_what}: byteStride {s} is less than the {element}-byte elements of \
                         {what}: its elements would overlap"
                    ));
                }
                if s > MAX_STRIDE || !s.is_multiple_of(component_bytes(component)) {
                    return Err(format!(
                        "{view_what}: byteStride {s} must be a multiple of {} and at most \
                         {MAX_STRIDE}",
                        component_bytes(component)
                    ));
                }
                s
            }
        };
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        // The last element ends at offset + stride (count - 1) + element, inside the view.
        let span = stride
            .checked_mul(count - 1)
            .and_then(|s| s.checked_add(element))
            .and_then(|s| s.checked_add(offset))
            .filter(|&end| end <= view_length)
            .ok_or_else(|| {
                format!(
                    "{what} ({count} elements of {element} bytes, stride {stride}, offset \
                     {offset}) runs past the end of {view_what} ({view_length} bytes)"
                )
            })?;
        let start = (view_offset + offset) as usize;
        let end = (view_offset + span) as usize;
        debug_assert!(end as u64 <= view_end);
        Ok(Located {
            bytes: &buffer[start..end],
            stride: stride as usize,
            count: count as usize,
            component,
            components: component_count(ty) as usize,
            normalized: accessor.normalized,
        })
    }

    /// Accessor `index` as floats (`components` per element): F32 as stored, normalized
    /// integers mapped to [0, 1] or [-1, 1] (glTF 2.0 §3.11); anything else an error.
    fn floats(
        &self,
        index: usize,
        ty: Type,
        max_count: u64,
        normalized_ok: bool,
    ) -> Result<Vec<f32>, String> {
        let l = self.locate(index, &[ty], max_count)?;
        let what = format!("accessors[{index}]");
        let size = component_bytes(l.component) as usize;
        if l.component != ComponentType::F32 && !(normalized_ok && l.normalized) {
            return Err(format!(
                "{what}: component type {:?}{} is not accepted here (FLOAT{})",
                l.component,
                if l.normalized { " normalized" } else { "" },
                if normalized_ok {
                    ", or a normalized integer"
                } else {
                    ""
                }
            ));
        }
        let mut out = Vec::with_capacity(l.count * l.components);
        for e in 0..l.count {
            for c in 0..l.components {
                let at = e * l.stride + c * size;
                let b = &l.bytes[at..at + size];
                let v = match l.component {
                    ComponentType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                    ComponentType::U8 => f32::from(b[0]) / 255.0,
                    ComponentType::I8 => (f32::from(b[0] as i8) / 127.0).max(-1.0),
                    ComponentType::U16 => f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
                    ComponentType::I16 => {
                        (f32::from(i16::from_le_bytes([b[0], b[1]])) / 32767.0).max(-1.0)
                    }
                    ComponentType::U32 => {
                        return Err(format!("{what}: UNSIGNED_INT is not a float component"))
                    }
                };
                if !v.is_finite() {
                    return Err(format!("{what}: element {e} has a non-finite value ({v})"));
                }
                out.push(v);
            }
        }
        Ok(out)
    }

    /// A VEC3 float accessor (positions, normals).
    pub fn vec3s(&self, index: usize, max_count: u64) -> Result<Vec<Vec3>, String> {
        Ok(self
            .floats(index, Type::Vec3, max_count, false)?
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect())
    }

    /// A VEC2 accessor of floats or normalized integers (texture coordinates).
    pub fn vec2s(&self, index: usize, max_count: u64) -> Result<Vec<Vec2>, String> {
        Ok(self
            .floats(index, Type::Vec2, max_count, true)?
            .chunks_exact(2)
            .map(Vec2::from_slice)
            .collect())
    }

    /// A VEC4 float accessor (tangents).
    pub fn vec4s(&self, index: usize, max_count: u64) -> Result<Vec<Vec4>, String> {
        Ok(self
            .floats(index, Type::Vec4, max_count, false)?
            .chunks_exact(4)
            .map(Vec4::from_slice)
            .collect())
    }

    /// A SCALAR accessor of unsigned integers (indices), each below `vertices`.
    pub fn indices(
        &self,
        index: usize,
        max_count: u64,
        vertices: usize,
    ) -> Result<Vec<u32>, String> {
        let l = self.locate(index, &[Type::Scalar], max_count)?;
        let what = format!("accessors[{index}]");
        let mut out = Vec::with_capacity(l.count);
        for e in 0..l.count {
            let b = &l.bytes[e * l.stride..];
            let v = match l.component {
                ComponentType::U8 => u32::from(b[0]),
                ComponentType::U16 => u32::from(u16::from_le_bytes([b[0], b[1]])),
                ComponentType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                other => {
                    return Err(format!(
                        "{what}: indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, \
                         not {other:?}"
                    ))
                }
            };
            if v as usize >= vertices {
                return Err(format!(
                    "{what}: index {v} (element {e}) is out of range for {vertices} vertices"
                ));
            }
            out.push(v);
        }
        Ok(out)
    }
}
