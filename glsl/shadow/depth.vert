#version 450
// permutation: LUCENT_SHADOW_IDS
// permutation: LUCENT_SHADOW_ENTRY
// permutation: LUCENT_SHADOW_ENTRY LUCENT_LAYER_DEPTHS=1
// The light-space maps pass (src/features/shadows.rs): every object drawn into one face's tile
// of the atlas with that face's matrix (the viewport places the tile).
#include "../common/shadows.glsl"

layout(location = 0) in vec3 in_position;
#ifdef LUCENT_SHADOW_ENTRY
// Layered frames: the world normal at the light's entry point (single scattering).
layout(location = 1) in vec3 in_normal;
layout(location = 0) out vec3 out_normal;
#ifdef LUCENT_LAYER_DEPTHS
// TexDep media: the UV where their depth textures are read (binding 2 of the mesh streams).
layout(location = 3) in vec2 in_uv;
layout(location = 1) out vec2 out_uv;
#endif
#endif

void main() {
    ShadowFace face = shadows.faces[clamp(shadow_object.face_id.x, 0, MAX_SHADOW_FACES - 1)];
    gl_Position = face.view_proj * shadow_object.model * vec4(in_position, 1.0);
#ifdef LUCENT_SHADOW_ENTRY
    out_normal = transpose(inverse(mat3(shadow_object.model))) * in_normal;
#ifdef LUCENT_LAYER_DEPTHS
    out_uv = in_uv;
#endif
#endif
}
