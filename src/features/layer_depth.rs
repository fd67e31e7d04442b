//! Layer depths: the `TexDep` texels (Li et al.'s per-layer depth textures) that the G-buffer
//! and the light-space maps store per texel for layered media, and the bindings of the depth
//! textures their passes sample. Layout: glsl/common/layer_depths.glsl (two fp16 texels per
//! 32-bit component).

use ash::vk;

use crate::backend::descriptor::Binding;

/// The `TexDep` texels of a G-buffer or light-space map texel for `textures` depth textures
/// (glsl/common/layer_depths.glsl: two fp16 texels per 32-bit component): RG32UI holds four
/// layers, RGBA32UI eight; `None` for 0.
pub fn layer_depth_format(textures: usize) -> Option<vk::Format> {
    match textures {
        0 => None,
        1 => Some(vk::Format::R32G32_UINT),
        _ => Some(vk::Format::R32G32B32A32_UINT),
    }
}

/// The LUCENT_LAYER_DEPTHS define's value for `textures` depth textures (1 or 2).
pub fn layer_depths_define(textures: usize) -> &'static str {
    if textures > 1 {
        "2"
    } else {
        "1"
    }
}

/// The names the maps pass's shaders give a draw's `TexDep` depth textures (glsl/shadow/depth.frag).
pub const DEPTH_MAP_NAMES: [&str; 2] = ["depth_map0", "depth_map1"];

/// The bindings of a draw's `TexDep` depth textures (`textures` of them, 1 or 2) from pair
/// `depth` of [`crate::gpu_scene::MaterialMaps::depth`].
pub fn depth_map_bindings(
    maps: &crate::gpu_scene::MaterialMaps,
    depth: [usize; 2],
    textures: usize,
) -> Vec<(&'static str, Binding)> {
    depth
        .iter()
        .take(textures.clamp(1, 2))
        .filter_map(|&i| maps.depth.get(i).or(maps.depth.first()))
        .zip(DEPTH_MAP_NAMES)
        .map(|(map, name)| (name, Binding::Sampled(map.view, maps.sampler)))
        .collect()
}
