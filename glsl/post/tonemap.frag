#version 450
// permutation: LUCENT_OUTPUT_LINEAR
// HDR -> display: exposure, ACES fit, sRGB encoding into an UNORM target; with
// LUCENT_OUTPUT_LINEAR (sRGB and float targets) the tonemapped values are written linear.
#include "../common/scene.glsl"
#include "../common/color.glsl"

layout(set = 0, binding = 1) uniform sampler2D hdr;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * frame.exposure.x;
#ifdef LUCENT_OUTPUT_LINEAR
    out_color = vec4(tonemap_aces(c), 1.0);
#else
    out_color = vec4(linear_to_srgb(tonemap_aces(c)), 1.0);
#endif
}
