#version 450
// permutation: LUCENT_SSS_BASE
// permutation: LUCENT_SSS_BASE LUCENT_SSS_ALBEDO
// Screen-space SSS, the control chain's final composite: on the pixels of this chain's
// profiles the sum of Gaussians plus the specular the blur kept out; elsewhere the previous
// chain's result (LUCENT_SSS_BASE, frames with several chains) or the lit diffuse + specular.
#include "../common/scene.glsl"
#include "../common/sss.glsl"

layout(set = 0) uniform sampler2D sum_tex;
layout(set = 0) uniform sampler2D diffuse_tex;
layout(set = 0) uniform sampler2D specular_tex;
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;
#endif
#ifdef LUCENT_SSS_ALBEDO
// GB0: the albedo the lighting pass left out of the light (sss_albedo_after).
layout(set = 0) uniform sampler2D albedo_tex;
#endif

layout(push_constant) uniform Chain {
    vec4 step;  // w: this chain's index
} chain;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    vec3 color;
    if (sss_in_chain(id, int(chain.step.w + 0.5))) {
        vec3 diffused = texelFetch(sum_tex, px, 0).rgb;
#ifdef LUCENT_SSS_ALBEDO
        diffused *= sss_albedo_after(id, texelFetch(albedo_tex, px, 0).rgb);
#endif
        color = diffused + texelFetch(specular_tex, px, 0).rgb;
    } else {
#ifdef LUCENT_SSS_BASE
        color = texelFetch(base_tex, px, 0).rgb;
#else
        color = texelFetch(diffuse_tex, px, 0).rgb + texelFetch(specular_tex, px, 0).rgb;
#endif
    }
    out_color = vec4(min(color, vec3(65504.0)), 1.0);
}
