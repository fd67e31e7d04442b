#version 450
// permutation: LUCENT_TRANSLUCENCY
// permutation: LUCENT_NORMAL_MAP
// permutation: LUCENT_TRANSLUCENCY LUCENT_NORMAL_MAP
// permutation: LUCENT_ALBEDO_MAP
// permutation: LUCENT_LAYER_DEPTHS=1
// UV + tangent stream (binding 2) in frames with normal or albedo maps or TexDep layers.
#include "../common/scene.glsl"
#include "object.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
#ifdef LUCENT_TRANSLUCENCY
layout(location = 2) in vec3 in_thickness; // binding 1: vertex colours, or white
layout(location = 1) out vec3 out_thickness;
#endif
#if defined(LUCENT_NORMAL_MAP) || defined(LUCENT_ALBEDO_MAP) || defined(LUCENT_LAYER_DEPTHS)
layout(location = 3) in vec2 in_uv;        // binding 2
layout(location = 4) in vec4 in_tangent;   // xyz unit, w: bitangent handedness
layout(location = 2) out vec2 out_uv;
layout(location = 3) out vec4 out_tangent;
#endif

layout(location = 0) out vec3 out_normal;

void main() {
    // Inverse-transpose keeps normals perpendicular under non-uniform scale.
    mat3 normal_matrix = transpose(inverse(mat3(object.model)));
    out_normal = normal_matrix * in_normal;
#ifdef LUCENT_TRANSLUCENCY
    out_thickness = in_thickness * object.thickness.rgb;
#endif
#if defined(LUCENT_NORMAL_MAP) || defined(LUCENT_ALBEDO_MAP) || defined(LUCENT_LAYER_DEPTHS)
    out_uv = in_uv;
    // Tangents are directions on the surface: they transform with the model matrix.
    out_tangent = vec4(mat3(object.model) * in_tangent.xyz, in_tangent.w);
#endif
    gl_Position = frame.view_proj * object.model * vec4(in_position, 1.0);
}
