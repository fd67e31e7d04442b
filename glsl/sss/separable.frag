#version 450
// permutation: LUCENT_SSS_DEPTH_IN_ALPHA
// permutation: LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_VERTICAL LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_VERTICAL LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_VERTICAL LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_VERTICAL LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_HALF_RES
// permutation: LUCENT_SSS_POINT_TAPS LUCENT_SSS_DEPTH_IN_ALPHA
// permutation: LUCENT_SSS_POINT_TAPS LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_HALF_RES LUCENT_SSS_VERTICAL
// The separable SSS blur (Jimenez 2015), one direction per pass (see two_pass_kernel.glsl):
// the pixel's profile's kernel as bilinear taps, each followed back to the centre colour
// across a depth step as deep as the kernel is wide ("follow surface").
//
// - LUCENT_SSS_DEPTH_IN_ALPHA: the light's alpha holds linear depth (frames without a LEAN
//   chain, and always after the first pass), so a tap is one fetch.
// - LUCENT_SSS_POINT_TAPS: nearest-texel taps instead of bilinear ones.
// - LUCENT_SSS_HALF_RES: both passes at half resolution per side (the first reads the light at
//   the centre of each 2x2 block, bilinear: their mean), writing linear depth in alpha for the
//   depth-aware upsample (glsl/sss/upsample.frag) that then composes the result.
#include "two_pass_kernel.glsl"

#if defined(LUCENT_SSS_VERTICAL) && !defined(LUCENT_SSS_HALF_RES)
#define LUCENT_SSS_COMPOSE
layout(set = 0) uniform sampler2D diffuse_tex;  // unblurred diffuse
layout(set = 0) uniform sampler2D specular_tex;
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;     // the previous chain's
#endif
#ifdef LUCENT_SSS_ALBEDO
// GB0: the albedo the lighting pass left out of the light (sss_albedo_after).
layout(set = 0) uniform sampler2D albedo_tex;
#endif
#endif

// The full-resolution pixel this pass's pixel stands for (the top-left of its 2x2 block at
// half resolution).
ivec2 full_res_pixel(ivec2 px) {
#ifdef LUCENT_SSS_HALF_RES
    return px * 2;
#else
    return px;
#endif
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(color_tex, 0);
    ivec2 full_px = full_res_pixel(px);
#if defined(LUCENT_SSS_VERTICAL) && !defined(LUCENT_SSS_HALF_RES) && !defined(LUCENT_SSS_PROFILE_EDGES)
    // One profile in the frame (ID 1), and the horizontal pass marked the pixels that scatter
    // by the sign of the depth it passes on: no profile fetch.
#define SCATTER_FROM_ALPHA
    int id = 1;
#else
    int id = sss_decode_id(texelFetch(profile_tex, full_px, 0));
#endif
#if !(defined(LUCENT_SSS_HALF_RES) && !defined(LUCENT_SSS_VERTICAL)) && (defined(LUCENT_SSS_DEPTH_IN_ALPHA) || defined(LUCENT_SSS_VERTICAL))
    // The pixel's linear depth travels with its light (sky: the far plane; its profile ID is
    // 0, so it never scatters): one fetch fewer per pixel.
#define DEPTH_FROM_ALPHA
#endif
#ifdef DEPTH_FROM_ALPHA
    float device_depth = 0.0;
#else
    float device_depth = texelFetch(depth_tex, full_px, 0).r;
#endif
#ifdef LUCENT_SSS_PASSTHROUGH
    bool scatters = false;
#elif defined(SCATTER_FROM_ALPHA)
    bool scatters = texelFetch(color_tex, px, 0).a > 0.0;
#elif defined(DEPTH_FROM_ALPHA)
    bool scatters = in_this_chain(id);
#else
    bool scatters = in_this_chain(id) && depth_is_surface(device_depth);
#endif
#if defined(LUCENT_SSS_HALF_RES) && !defined(LUCENT_SSS_VERTICAL)
    // The light at the block's centre: bilinear between its four pixels.
    vec2 centre_uv = (vec2(full_px) + 1.0) * frame.viewport.zw;
    vec4 center = finite_or(textureLod(color_tex, centre_uv, 0.0), vec4(0.0));
    vec2 texel = frame.viewport.zw;
#else
    vec2 centre_uv = (vec2(px) + 0.5) / vec2(size);
    vec4 center = finite_or(texelFetch(color_tex, px, 0), vec4(0.0));
    vec2 texel = 1.0 / vec2(size);
#endif
#ifdef DEPTH_FROM_ALPHA
    float depth_m = abs(center.a);
#else
    float depth_m = linear_depth(device_depth);
#endif
    vec3 blurred = center.rgb;
    if (scatters) {
        vec4 info = sss_kernels.info[id];
        int samples = kernel_samples(info);
        float scale = kernel_scale(info, depth_m, size);
        vec3 sum = vec3(0.0);
        for (int k = 0; k < samples; ++k) {
            vec4 tap = sss_kernels.taps[id * MAX_KERNEL_SAMPLES + k];
            vec2 uv = centre_uv + blur.step.xy * (tap.a * scale) * texel;
#ifdef LUCENT_SSS_POINT_TAPS
            // The nearest texel: one fetch where a bilinear tap costs four on a CPU driver.
            vec4 color =
                texelFetch(color_tex, clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1), 0);
#else
            vec4 color = textureLod(color_tex, uv, 0.0);
#endif
#if defined(LUCENT_SSS_DEPTH_IN_ALPHA) || defined(LUCENT_SSS_VERTICAL)
            // (The horizontal pass passes depth on signed: negative where nothing scatters.)
            float depth = abs(color.a);
#else
            float depth = linear_depth(texelFetch(depth_tex, ivec2(uv * frame.viewport.xy), 0).r);
#endif
            // Follow the surface: a depth step as deep as the kernel is wide is an edge.
            float s = clamp(abs(depth - depth_m) * info.y, 0.0, 1.0);
#ifdef LUCENT_SSS_PROFILE_EDGES
            ivec2 tap_px = ivec2(uv * frame.viewport.xy);
            int tap_id = sss_decode_id(texelFetch(profile_tex, tap_px, 0));
            s = tap_id != id && tap_id != 0 ? 1.0 : s;
#endif
            sum += tap.rgb * mix(color.rgb, center.rgb, s);
        }
        // A NaN or Inf tap would poison the pixel: checked once on the sum (a poisoned sum
        // keeps the pixel's own light), so one bad pixel never spreads.
        blurred = any(isnan(sum)) || any(isinf(sum)) ? center.rgb : sum;
    }
    // fp16 targets: keep them finite.
    blurred = clamp(blurred, vec3(-65504.0), vec3(65504.0));
#ifdef LUCENT_SSS_COMPOSE
    vec3 color;
    if (scatters) {
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
    out_color = composed(color);
#else
    // The pixel's linear depth travels in alpha, so the next pass's taps read it with the
    // light; negative where the pixel does not scatter (the vertical pass then needs no
    // profile ID in one-profile frames).
    out_color = vec4(blurred, scatters ? depth_m : -depth_m);
#endif
}
