#version 450
// permutation: LUCENT_FLOOR_SHADOW_FACES
// The speed-of-light floor of a mesh pass (src/measure/speed_of_light.rs): the same objects
// drawn with the same views as the pass, and nothing else. The position stream only, one
// matrix product per vertex: the camera's (the frame uniforms' first member), or with
// LUCENT_FLOOR_SHADOW_FACES the light-space face's from the shadow table, which is what the
// G-buffer and light-space maps passes transform by.
layout(location = 0) in vec3 in_position;

layout(push_constant) uniform FloorObject {
    mat4 model;
    ivec4 face;  // x: the light-space face (with LUCENT_FLOOR_SHADOW_FACES)
} object;

#ifdef LUCENT_FLOOR_SHADOW_FACES
// The table of glsl/common/shadows.glsl up to the faces, as std140 lays it out.
#define MAX_SHADOW_LIGHTS 64
#define MAX_SHADOW_FACES 384
struct ShadowFace {
    mat4 view_proj;
    vec4 rect;
    vec4 params;
};
layout(std140, set = 0) uniform Shadows {
    vec4 atlas;
    ivec4 lights[MAX_SHADOW_LIGHTS];
    ShadowFace faces[MAX_SHADOW_FACES];
} shadows;
#else
// The first member of glsl/common/scene.glsl's frame uniforms.
layout(std140, set = 0) uniform Frame {
    mat4 view_proj;
} frame;
#endif

void main() {
#ifdef LUCENT_FLOOR_SHADOW_FACES
    mat4 view_proj = shadows.faces[clamp(object.face.x, 0, MAX_SHADOW_FACES - 1)].view_proj;
#else
    mat4 view_proj = frame.view_proj;
#endif
    gl_Position = view_proj * object.model * vec4(in_position, 1.0);
}
