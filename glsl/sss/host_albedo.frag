#version 450
// Screen-space SSS over a host's lit diffuse (lucent::embed): puts the albedo into the light
// the way each pixel's profile wants it before the blur (sss_albedo_before: all of it for
// `pre`, none for `post`, its square root for `pre-post`; all of it where the pixel does not
// scatter), from a host's light that holds all of it (LUCENT_SSS_HOST_ALBEDO_INCLUDED) or none.
// The chain then multiplies the rest back in after the blur (sss_albedo_after).
#include "../common/scene.glsl"
#include "../common/sss.glsl"

layout(set = 0) uniform sampler2D diffuse_tex;
layout(set = 0) uniform sampler2D albedo_tex;
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 light = texelFetch(diffuse_tex, px, 0);
    vec3 albedo = sss_host_albedo(texelFetch(albedo_tex, px, 0).rgb);
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
#ifdef LUCENT_SSS_HOST_ALBEDO_INCLUDED
    vec3 rgb = light.rgb * sss_host_albedo_factor(id, albedo, true);
#else
    vec3 rgb = light.rgb * sss_host_albedo_factor(id, albedo, false);
#endif
    rgb = mix(rgb, vec3(0.0), isnan(rgb));
    out_color = vec4(clamp(rgb, vec3(0.0), vec3(65504.0)), light.a);
}
