#version 450
// Screen-space SSS, final composite: the sum of Gaussians where the pixel scatters, the lit
// diffuse elsewhere, plus the specular the blur kept out.
#include "../common/scene.glsl"

layout(set = 0, binding = 1) uniform sampler2D sum_tex;
layout(set = 0, binding = 2) uniform sampler2D diffuse_tex;
layout(set = 0, binding = 3) uniform sampler2D specular_tex;
layout(set = 0, binding = 4) uniform sampler2D strength_tex;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    float strength = texelFetch(strength_tex, px, 0).r;
    vec3 diffuse = strength > 0.0 ? texelFetch(sum_tex, px, 0).rgb : texelFetch(diffuse_tex, px, 0).rgb;
    vec3 color = diffuse + texelFetch(specular_tex, px, 0).rgb;
    out_color = vec4(min(color, vec3(65504.0)), 1.0);
}
