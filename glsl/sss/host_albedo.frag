#version 450
// Screen-space SSS over a host's lit diffuse (lucent::embed): puts the albedo into the light
// the way each pixel's profile wants it before the blur (sss_albedo_before: all of it for
// `pre`, none for `post`, its square root for `pre-post`; all of it where the pixel does not
// scatter), from a host's light that holds all of it (LUCENT_SSS_HOST_ALBEDO_INCLUDED) or none.
// The chain then multiplies the rest back in after the blur (sss_albedo_after).
#include "../common/scene.glsl"
#include "../common/sss.glsl"

layout(set = 0, binding = 2) uniform sampler2D diffuse_tex;
layout(set = 0, binding = 3) uniform sampler2D albedo_tex;
layout(set = 0, binding = 4) uniform SSS_ID_SAMPLER profile_tex;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// The smallest albedo divided by: a host's black albedo has no light left to recover, and
// dividing by it would turn rounding into Inf.
const float MIN_ALBEDO = 1.0 / 255.0;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 light = texelFetch(diffuse_tex, px, 0);
    // Sanitized where it is read: a host's NaN or out-of-range albedo must not reach the blur.
    vec3 albedo = texelFetch(albedo_tex, px, 0).rgb;
    albedo = clamp(mix(albedo, vec3(0.0), isnan(albedo)), vec3(0.0), vec3(1.0));
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    vec3 before = sss_albedo_before(id, albedo);
#ifdef LUCENT_SSS_HOST_ALBEDO_INCLUDED
    // The light holds the whole albedo: divide out what belongs after the blur.
    vec3 factor = sss_texturing(id) == 0 ? vec3(1.0) : before / max(albedo, vec3(MIN_ALBEDO));
#else
    vec3 factor = before;
#endif
    vec3 rgb = light.rgb * factor;
    rgb = mix(rgb, vec3(0.0), isnan(rgb));
    out_color = vec4(clamp(rgb, vec3(0.0), vec3(65504.0)), light.a);
}
