#version 450
// permutation: LUCENT_SHADOW_IDS
// permutation: LUCENT_SHADOW_ENTRY
// The light-space maps pass (src/features/shadows.rs): every object drawn into one face's tile
// of the atlas with that face's matrix (the viewport places the tile).
#include "../common/shadows.glsl"

layout(location = 0) in vec3 in_position;
#ifdef LUCENT_SHADOW_ENTRY
// Layered frames: the world normal at the light's entry point (single scattering).
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec3 out_normal;
#endif

void main() {
    ShadowFace face = shadows.faces[clamp(shadow_object.face_id.x, 0, MAX_SHADOW_FACES - 1)];
    gl_Position = face.view_proj * shadow_object.model * vec4(in_position, 1.0);
#ifdef LUCENT_SHADOW_ENTRY
    out_normal = transpose(inverse(mat3(shadow_object.model))) * in_normal;
#endif
}
