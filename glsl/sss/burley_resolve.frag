#version 450
// permutation:
// permutation: LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ALBEDO LUCENT_SSS_HALF_RES
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
// - LUCENT_SSS_ALBEDO: the diffused light is multiplied by the albedo the lighting pass left
//   out of it (glsl/common/sss.glsl `sss_albedo_after`).
// - LUCENT_SSS_HALF_RES: the gather ran at half resolution per side (each texel for the
//   top-left pixel of its 2x2 block): a pixel averages the 3x3 texels around its own of its
//   profile within its depth (read from the depth buffer), all nine rotations; a pixel whose
//   profile reaches under two pixels keeps its own light (the gather would only blur it).
#include "../common/scene.glsl"
#include "../common/sss.glsl"

// The Burley table (glsl/sss/burley.frag): per profile ID, a = the widest d in world units.
layout(std140, set = 0) uniform SssBurley {
    vec4 distance[MAX_SSS_PROFILES];
    vec4 knobs;  // z: the reach in units of d
} burley;

layout(set = 0) uniform sampler2D gathered_tex;  // diffused light, depth in alpha
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;   // profile IDs
layout(set = 0) uniform sampler2D diffuse_tex;   // lit diffuse
layout(set = 0) uniform sampler2D specular_tex;  // lit specular
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;      // the previous chain's result
#endif
#ifdef LUCENT_SSS_ALBEDO
// GB0: the albedo the lighting pass left out of the light (sss_albedo_after).
layout(set = 0) uniform sampler2D albedo_tex;
#endif
#ifdef LUCENT_SSS_HALF_RES
// Device depth.
layout(set = 0) uniform sampler2D depth_tex;
#endif

layout(push_constant) uniform Blur {
    vec4 step;  // w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

#ifdef LUCENT_SSS_HALF_RES
// The weight of texel `i` (0-3) of a row of four whose pixel lies a fraction `f` past texel 1.
float axis_weight(int i, float f) {
    return i == 0 ? 1.0 - f : (i == 3 ? f : 1.0);
}
#endif

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(profile_tex, 0);  // full resolution
#ifdef LUCENT_SSS_PASSTHROUGH
    bool scatters = false;
    int id = 0;
#else
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    bool scatters = sss_in_chain(id, int(blur.step.w + 0.5));
#endif
    vec3 color;
    if (scatters) {
#ifdef LUCENT_SSS_HALF_RES
        // This pixel's own depth (its block's corner may lie on another surface).
        float depth_m = linear_depth(texelFetch(depth_tex, px, 0).r);
        // Texel q gathered for pixel 2q: this pixel sits at px / 2 among them. Four texels a
        // side from `home`, weighted (1 - f, 1, 1, f): a bilinear step between two 3x3
        // averages, so every rotation keeps an equal share (texels 0 and 3 of a row share
        // one) and a block's light blends into the next without steps.
        vec2 at = vec2(px) * 0.5;
        ivec2 home = ivec2(floor(at)) - 1;
        vec2 f = at - floor(at);
        ivec2 grid = textureSize(gathered_tex, 0);
        // A profile that reaches under two pixels here gains nothing from a gather a block
        // wide: the pixel keeps its own light (the full-resolution gather skips under one).
        float reach_px = burley.knobs.z * burley.distance[id].a * frame.camera.z /
                         max(depth_m, 1e-4);
        bool own_light = reach_px < 2.0;
#else
        float depth_m = abs(texelFetch(gathered_tex, px, 0).a);
        ivec2 home = px;
        ivec2 grid = size;
        bool own_light = false;
#endif
        // A neighbour more than the profile's widest d away in depth is another surface.
        float depth_step = max(burley.distance[id].a, 1e-6 * depth_m);
        vec3 sum = vec3(0.0);
        float count = 0.0;
#ifdef LUCENT_SSS_HALF_RES
        for (int dy = 0; dy <= 3 && !own_light; ++dy) {
            for (int dx = 0; dx <= 3; ++dx) {
#else
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
#endif
                ivec2 q = clamp(home + ivec2(dx, dy), ivec2(0), grid - 1);
#ifdef LUCENT_SSS_HALF_RES
                ivec2 q_px = min(q * 2, size - 1);
#else
                ivec2 q_px = q;
#endif
#ifdef LUCENT_SSS_PROFILE_EDGES
                if (sss_decode_id(texelFetch(profile_tex, q_px, 0)) != id) {
                    continue;
                }
#endif
                // (The gather writes finite values only: no check here.)
                vec4 g = texelFetch(gathered_tex, q, 0);
                float keep = g.a > 0.0 && abs(g.a - depth_m) <= depth_step ? 1.0 : 0.0;
#ifdef LUCENT_SSS_HALF_RES
                keep *= axis_weight(dx, f.x) * axis_weight(dy, f.y);
#endif
                sum += keep * g.rgb;
                count += keep;
            }
        }
        // At full resolution the pixel itself always counts (a scattering pixel's gathered
        // depth is positive); at half resolution none may (a pixel unlike its block's corner).
        vec3 diffused = count > 1e-6 ? sum / count : texelFetch(diffuse_tex, px, 0).rgb;
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
