#version 450
// permutation: LUCENT_SSS_BASE
// permutation: LUCENT_SSS_BASE LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_PASSTHROUGH
// The separable blur at half resolution, composed at full resolution (src/features/sss/
// two_pass.rs): on the chain's pixels the blurred light from the four nearest half-resolution
// texels, each weighted bilinearly and by how close its depth (carried in alpha) is to the
// pixel's (a texel across a depth step as deep as the kernel is wide gets no weight, so light
// never leaks over silhouettes), plus the specular; elsewhere the previous chain's result or
// the lit diffuse + specular.
#define LUCENT_SSS_KERNELS
#include "../common/scene.glsl"
#include "../common/sss.glsl"

layout(set = 0) uniform sampler2D blurred_tex;   // half res: rgb, a linear depth
layout(set = 0) uniform sampler2D depth_tex;
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;
layout(set = 0) uniform sampler2D diffuse_tex;
layout(set = 0) uniform sampler2D specular_tex;
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;
#endif
#ifdef LUCENT_SSS_ALBEDO
// GB0: the albedo the lighting pass left out of the light (sss_albedo_after).
layout(set = 0) uniform sampler2D albedo_tex;
#endif

layout(push_constant) uniform Chain {
    vec4 step;  // w: the chain
} chain;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    float device_depth = texelFetch(depth_tex, px, 0).r;
#ifdef LUCENT_SSS_PASSTHROUGH
    bool scatters = false;
#else
    bool scatters = sss_in_chain(id, int(chain.step.w + 0.5)) && depth_is_surface(device_depth);
#endif
    vec3 color;
    if (scatters) {
        float depth = linear_depth(device_depth);
        float edge = sss_kernels.info[id].y;
        ivec2 half_size = textureSize(blurred_tex, 0);
        // This pixel in half-resolution texel coordinates, and its four nearest texels.
        vec2 p = (vec2(px) + 0.5) * 0.5 - 0.5;
        ivec2 base_texel = ivec2(floor(p));
        vec2 f = p - vec2(base_texel);
        vec3 sum = vec3(0.0);
        float total = 0.0;
        vec3 nearest = vec3(0.0);
        float nearest_dz = 1e30;
        for (int j = 0; j < 2; ++j) {
            for (int i = 0; i < 2; ++i) {
                ivec2 t = clamp(base_texel + ivec2(i, j), ivec2(0), half_size - 1);
                vec4 texel = texelFetch(blurred_tex, t, 0);
                if (any(isnan(texel)) || any(isinf(texel))) {
                    continue;
                }
                float bilinear = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
                // The half-resolution pass passes depth on signed (negative: not scattering).
                float dz = abs(abs(texel.a) - depth);
                float w = bilinear * (1.0 - clamp(dz * edge, 0.0, 1.0));
                sum += w * texel.rgb;
                total += w;
                if (dz < nearest_dz) {
                    nearest_dz = dz;
                    nearest = texel.rgb;
                }
            }
        }
        // Every neighbour across an edge (a one-pixel sliver): the nearest in depth.
        vec3 blurred = total > 1e-4 ? sum / total : nearest;
#ifdef LUCENT_SSS_ALBEDO
        blurred *= sss_albedo_after(id, texelFetch(albedo_tex, px, 0).rgb);
#endif
        color = blurred + texelFetch(specular_tex, px, 0).rgb;
    } else {
#ifdef LUCENT_SSS_BASE
        color = texelFetch(base_tex, px, 0).rgb;
#else
        color = texelFetch(diffuse_tex, px, 0).rgb + texelFetch(specular_tex, px, 0).rgb;
#endif
    }
    color = any(isnan(color)) ? vec3(0.0) : clamp(color, vec3(0.0), vec3(65504.0));
    out_color = vec4(color, 1.0);
}
