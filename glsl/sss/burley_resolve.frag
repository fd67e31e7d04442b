#version 450
// permutation:
// permutation: LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_PASSTHROUGH
// The resolve pass of 2-D Burley SSS (src/features/sss/burley.rs): each scattering pixel's
// diffused light averaged with its 3x3 neighbours of the same profile at a similar depth
// (glsl/sss/burley.frag rotates the sample spiral by one of nine angles per 3x3 block, so the
// average sees every radius at nine evenly spaced angles), then the chain's result composed:
// the diffused light plus specular where the chain scatters, the previous chain's result (or
// the lit diffuse plus specular) elsewhere.
//
// - LUCENT_SSS_BASE: pixels the chain does not scatter keep the previous chain's result.
// - LUCENT_SSS_PROFILE_EDGES: several profiles in the frame: a neighbour of another profile is
//   left out (with one, the sign of the gathered depth says whether a neighbour scatters).
// - LUCENT_SSS_PASSTHROUGH: the variant for rectangles no object of the chain covers.
#include "../common/scene.glsl"
#include "../common/sss.glsl"

// The Burley table (glsl/sss/burley.frag): per profile ID, a = the widest d in world units.
layout(std140, set = 0, binding = 2) uniform SssBurley {
    vec4 distance[MAX_SSS_PROFILES];
} burley;

layout(set = 0, binding = 3) uniform sampler2D gathered_tex;  // diffused light, depth in alpha
layout(set = 0, binding = 4) uniform sampler2D profile_tex;   // profile IDs
layout(set = 0, binding = 5) uniform sampler2D diffuse_tex;   // lit diffuse
layout(set = 0, binding = 6) uniform sampler2D specular_tex;  // lit specular
#ifdef LUCENT_SSS_BASE
layout(set = 0, binding = 7) uniform sampler2D base_tex;      // the previous chain's result
#endif
#ifdef LUCENT_SSS_ALBEDO
// GB0, the last binding: the albedo the lighting pass left out of the light (sss_albedo_after).
#ifdef LUCENT_SSS_BASE
layout(set = 0, binding = 8) uniform sampler2D albedo_tex;
#else
layout(set = 0, binding = 7) uniform sampler2D albedo_tex;
#endif
#endif

layout(push_constant) uniform Blur {
    vec4 step;  // w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(gathered_tex, 0);
#ifdef LUCENT_SSS_PASSTHROUGH
    bool scatters = false;
    int id = 0;
#else
    int id = sss_profile_id(texelFetch(profile_tex, px, 0).r);
    bool scatters = sss_in_chain(id, int(blur.step.w + 0.5));
#endif
    vec3 color;
    if (scatters) {
        vec4 center = texelFetch(gathered_tex, px, 0);
        float depth_m = abs(center.a);
        // A neighbour more than the profile's widest d away in depth is another surface.
        float depth_step = max(burley.distance[id].a, 1e-6 * depth_m);
        vec3 sum = vec3(0.0);
        float count = 0.0;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                ivec2 q = clamp(px + ivec2(dx, dy), ivec2(0), size - 1);
#ifdef LUCENT_SSS_PROFILE_EDGES
                if (sss_profile_id(texelFetch(profile_tex, q, 0).r) != id) {
                    continue;
                }
#endif
                // (The gather writes finite values only: no check here.)
                vec4 g = texelFetch(gathered_tex, q, 0);
                float keep = g.a > 0.0 && abs(g.a - depth_m) <= depth_step ? 1.0 : 0.0;
                sum += keep * g.rgb;
                count += keep;
            }
        }
        // The pixel itself always counts (a scattering pixel's gathered depth is positive).
        vec3 diffused = count > 0.0 ? sum / count : texelFetch(diffuse_tex, px, 0).rgb;
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
    // fp16 targets: in range, and a NaN becomes black.
    color = any(isnan(color)) ? vec3(0.0) : clamp(color, vec3(0.0), vec3(65504.0));
    out_color = vec4(color, 1.0);
}
