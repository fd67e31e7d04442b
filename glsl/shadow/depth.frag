#version 450
// permutation: LUCENT_SHADOW_IDS
// permutation: LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=0
// permutation: LUCENT_SHADOW_IDS LUCENT_SHADOW_ENTRY LUCENT_ENTRY_LOCATION=1
// Depth only; frames with translucency also store the first surface's translucency material ID
// (the GDC 2011 term is not shadowed by its own material: glsl/common/shadows.glsl), frames
// with layered media its normal and layered material ID (where light enters: single
// scattering, src/features/layered.rs).
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
#endif
}
