#version 450
// permutation: LUCENT_OUTPUT_LINEAR
// permutation: LUCENT_LUMA_IN_ALPHA
// HDR -> display: exposure, ACES fit, sRGB encoding into an UNORM target; with
// LUCENT_OUTPUT_LINEAR (sRGB and float targets) the tonemapped values are written linear.
// With LUCENT_LUMA_IN_ALPHA (frames with anti-aliasing) it writes the sRGB-encoded colour
// into an intermediate UNORM image and its luma (Rec. 601 weights of the encoded values, the
// perceptual contrast FXAA looks for) into alpha, for post/fxaa.frag.
#include "../common/scene.glsl"
#include "../common/color.glsl"

layout(set = 0) uniform sampler2D hdr;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb * frame.exposure.x;
#if defined(LUCENT_LUMA_IN_ALPHA)
    vec3 encoded = linear_to_srgb(tonemap_aces(c));
    out_color = vec4(encoded, dot(encoded, vec3(0.299, 0.587, 0.114)));
#elif defined(LUCENT_OUTPUT_LINEAR)
    out_color = vec4(tonemap_aces(c), 1.0);
#else
    out_color = vec4(linear_to_srgb(tonemap_aces(c)), 1.0);
#endif
}
