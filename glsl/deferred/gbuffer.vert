#version 450
#include "../common/scene.glsl"

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(push_constant) uniform Object {
    mat4 model;
    vec4 albedo_specular;
    vec4 roughness;
} object;

layout(location = 0) out vec3 out_normal;

void main() {
    // Inverse-transpose keeps normals perpendicular under non-uniform scale.
    mat3 normal_matrix = transpose(inverse(mat3(object.model)));
    out_normal = normal_matrix * in_normal;
    gl_Position = frame.view_proj * object.model * vec4(in_position, 1.0);
}
