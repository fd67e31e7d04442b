#version 450
// permutation: LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_BASE
// permutation: LUCENT_SSS_BASE LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SHADOWS
// LCB and LBB, the final lighting pass (the thesis's BRDF shader, Annex A 8.1.3): on the pixels
// of this chain's profiles, the blurred diffuse light plus LEAN specular with Fresnel evaluated
// on the blurred view-plane slopes and moments, for every light; elsewhere the previous chain's
// result (LUCENT_SSS_BASE, frames with several chains) or the lighting pass's diffuse +
// specular. Half vectors come from the depth (no position or half-vector targets:
// the thesis stored both; the depth buffer already holds what they encode).
#include "../common/lean.glsl"
#include "../common/sss.glsl"

layout(set = 0) uniform sampler2D sum_tex;       // blurred diffuse rgb + slope x
layout(set = 0) uniform sampler2D lean_sum_tex;  // blurred slope y + moments
layout(set = 0) uniform sampler2D diffuse_tex;   // unblurred diffuse (non-SSS)
layout(set = 0) uniform sampler2D specular_tex;  // lighting pass specular (non-SSS)
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;   // SSS profile ID
layout(set = 0) uniform sampler2D depth_tex;
layout(set = 0) uniform sampler2D albedo_tex;    // GB0: a = specular intensity
layout(set = 0) uniform sampler2D normal_tex;    // GB1: a = roughness
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;     // the previous chain's result
#endif

layout(push_constant) uniform Chain {
    vec4 step;  // w: this chain's index
} chain;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef LUCENT_SSS_PASSTHROUGH
    // Drawn on the screen rectangles no object of this chain can touch.
    bool scatters = false;
    int id = 0;
#else
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    bool scatters = sss_in_chain(id, int(chain.step.w + 0.5));
#endif
    vec3 color;
    if (scatters) {
        vec4 s0 = texelFetch(sum_tex, px, 0);
        vec4 s1 = texelFetch(lean_sum_tex, px, 0);
        vec4 gb0 = texelFetch(albedo_tex, px, 0);
        vec4 gb1 = texelFetch(normal_tex, px, 0);
        float d = texelFetch(depth_tex, px, 0).r;
        vec3 specular =
            lean_final_specular(gl_FragCoord.xy, d, vec2(s0.a, s1.x), s1.yzw, gb1.a, gb0.a);
        vec3 diffused = s0.rgb;
#ifdef LUCENT_SSS_ALBEDO
        // The albedo the lighting pass left out of the light (glsl/common/sss.glsl).
        diffused *= sss_albedo_after(id, gb0.rgb);
#endif
        color = diffused + specular;
    } else {
#ifdef LUCENT_SSS_BASE
        color = texelFetch(base_tex, px, 0).rgb;
#else
        color = texelFetch(diffuse_tex, px, 0).rgb + texelFetch(specular_tex, px, 0).rgb;
#endif
    }
    // Into fp16's range; a NaN (which clamp need not catch) becomes black.
    color = any(isnan(color)) ? vec3(0.0) : clamp(color, vec3(0.0), vec3(65504.0));
    out_color = vec4(color, 1.0);
}
