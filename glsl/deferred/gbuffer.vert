#version 450
// permutation: LUCENT_TRANSLUCENCY
#include "../common/scene.glsl"
#include "object.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;
#ifdef LUCENT_TRANSLUCENCY
layout(location = 2) in vec3 in_thickness; // binding 1: vertex colours, or white
layout(location = 1) out vec3 out_thickness;
#endif

layout(location = 0) out vec3 out_normal;

void main() {
    // Inverse-transpose keeps normals perpendicular under non-uniform scale.
    mat3 normal_matrix = transpose(inverse(mat3(object.model)));
    out_normal = normal_matrix * in_normal;
#ifdef LUCENT_TRANSLUCENCY
    out_thickness = in_thickness * object.thickness.rgb;
#endif
    gl_Position = frame.view_proj * object.model * vec4(in_position, 1.0);
}
