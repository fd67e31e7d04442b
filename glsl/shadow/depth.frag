#version 450
// permutation: LUCENT_SHADOW_IDS
// permutation: LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=0
// permutation: LUCENT_SHADOW_IDS LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=1
// permutation: LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=0 LUCENT_LAYER_DEPTHS=1 LUCENT_LAYER_DEPTH_LOCATION=1
// permutation: LUCENT_SHADOW_IDS LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=1 LUCENT_LAYER_DEPTHS=2 LUCENT_LAYER_DEPTH_LOCATION=2
// Depth only; frames with translucency also store the first surface's translucency material ID
// (the GDC 2011 term is not shadowed by its own material: glsl/common/shadows.glsl), frames
// with layered media its normal and layered material ID (where light enters: single
// scattering, src/features/layered.rs), and with TexDep media the entry's depth texels
// (`depth_map0` and `depth_map1`: the draw's depth textures, bound after the maps' table).
#include "../common/shadows.glsl"

#ifdef LUCENT_SHADOW_IDS
layout(location = 0) out uint out_id;
#endif
#ifdef LUCENT_SHADOW_ENTRY
#ifndef LUCENT_ENTRY_LOCATION
#define LUCENT_ENTRY_LOCATION 0
#endif
layout(location = 0) in vec3 in_normal;
layout(location = LUCENT_ENTRY_LOCATION) out vec4 out_entry;
#ifdef LUCENT_LAYER_DEPTHS
#include "../common/layer_depths.glsl"
layout(location = 1) in vec2 in_uv;
layout(set = 0) uniform sampler2D depth_map0;
#if LUCENT_LAYER_DEPTHS > 1
layout(set = 0) uniform sampler2D depth_map1;
#endif
layout(location = LUCENT_LAYER_DEPTH_LOCATION) out uvec4 out_layer_depths;
#endif
#endif

void main() {
#ifdef LUCENT_SHADOW_IDS
    out_id = uint(clamp(shadow_object.face_id.y, 0, 255));
#endif
#ifdef LUCENT_SHADOW_ENTRY
    // The outward normal as the mesh has it (layered objects are closed; the back of an open
    // mesh faces away from the light, and single scattering lets no light in there).
    vec3 n = in_normal;
    float len2 = dot(n, n);
    n = (len2 > 1e-12 && !isinf(len2)) ? n * inversesqrt(len2) : vec3(0.0, 1.0, 0.0);
    out_entry = vec4(n * 0.5 + 0.5, float(clamp(shadow_object.face_id.z, 0, 255)) / 255.0);
#ifdef LUCENT_LAYER_DEPTHS
    vec4 second = vec4(0.0);
#if LUCENT_LAYER_DEPTHS > 1
    second = texture(depth_map1, in_uv);
#endif
    out_layer_depths = pack_layer_texels(texture(depth_map0, in_uv), second);
#endif
#endif
}
