#version 450
#include "../common/gbuffer.glsl"

layout(location = 0) in vec3 in_normal;

layout(push_constant) uniform Object {
    mat4 model;
    vec4 albedo_specular;
    vec4 roughness;
} object;

layout(location = 0) out vec4 out_gb0;
layout(location = 1) out vec4 out_gb1;

void main() {
    Surface s;
    s.albedo = object.albedo_specular.rgb;
    s.specular = object.albedo_specular.a;
    s.normal = in_normal;
    s.roughness = object.roughness.x;
    out_gb0 = pack_gb0(s);
    out_gb1 = pack_gb1(s);
}
