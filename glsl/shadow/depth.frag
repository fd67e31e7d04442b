#version 450
// permutation: LUCENT_SHADOW_IDS
// Depth only; frames with translucency also store the first surface's translucency material ID
// (the GDC 2011 term is not shadowed by its own material: glsl/common/shadows.glsl).
#include "../common/shadows.glsl"

#ifdef LUCENT_SHADOW_IDS
layout(location = 0) out uint out_id;
#endif

void main() {
#ifdef LUCENT_SHADOW_IDS
    out_id = uint(clamp(shadow_object.face_id.y, 0, 255));
#endif
}
