#version 450
// permutations-only
// permutation: LUCENT_SSS_SAMPLES=17
// permutation: LUCENT_SSS_SAMPLES=11 LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_SAMPLES=25 LUCENT_SSS_VERTICAL LUCENT_SSS_PASSTHROUGH LUCENT_SSS_BASE
// permutation: LUCENT_SSS_SAMPLES=17 LUCENT_SSS_VERTICAL LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_SAMPLES=17 LUCENT_SSS_VERTICAL LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ALBEDO
// permutation: LUCENT_SSS_SAMPLES=17 LUCENT_SSS_VERTICAL LUCENT_SHADOWS
// The bilateral SSS blur (the LEAN-mapping SSS thesis's idea in two passes), one direction per
// pass (see two_pass_kernel.glsl): LUCENT_SSS_SAMPLES point taps at whole texels evenly over
// the profile's reach, each weighted per channel by the whole profile at the tap's 3D distance
// (screen offset in world units and depth difference), which is what the brute-force
// reference convolves; the LEAN texel (slope x in the light's alpha, slope y and moments) is
// blurred with the mean of the channels' weights, keeping creases out (lean_crease); the
// vertical pass ends with LEAN specular on the blurred moments (LUCENT_SHADOWS: shadowed by
// the light-space maps).
#include "two_pass_kernel.glsl"
#include "../common/lean.glsl"

layout(set = 0) uniform sampler2D lean_tex;     // slope y, moments
#ifdef LUCENT_SSS_VERTICAL
#define LUCENT_SSS_COMPOSE
layout(set = 0) uniform sampler2D diffuse_tex;  // unblurred diffuse
layout(set = 0) uniform sampler2D specular_tex;
layout(set = 0) uniform sampler2D albedo_tex;   // GB0: a = specular
layout(set = 0) uniform sampler2D normal_tex;   // GB1: a = roughness
#ifdef LUCENT_SSS_BASE
layout(set = 0) uniform sampler2D base_tex;     // the previous chain's
#endif
#else
layout(location = 1) out vec4 out_lean;
#endif

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(color_tex, 0);
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    float device_depth = texelFetch(depth_tex, px, 0).r;
#ifdef LUCENT_SSS_PASSTHROUGH
    bool scatters = false;
#else
    bool scatters = in_this_chain(id) && depth_is_surface(device_depth);
#endif
    vec4 center = finite_or(texelFetch(color_tex, px, 0), vec4(0.0));
    float depth_m = linear_depth(device_depth);
    vec3 blurred = center.rgb;
    vec4 center_lean = finite_or(texelFetch(lean_tex, px, 0), vec4(0.0));
    vec4 blurred_lean = center_lean;
    float blurred_slope_x = center.a;
    if (scatters) {
        // The profile's kernel (as the separable blur's: pre-integrated weights at offsets in
        // world units), as nearest texels; each tap's weight then falls off with the depth
        // difference as the profile does: its 1-D form at the tap's 3D distance over that at
        // its screen offset (exact for every Gaussian of the sum:
        // G(sqrt(x^2 + dz^2)) = G(x) exp(-dz^2 / 2v)).
        vec4 info = sss_kernels.info[id];
        int samples = min(LUCENT_SSS_SAMPLES, kernel_samples(info));
        float scale = kernel_scale(info, depth_m, size);
        vec3 sum = vec3(0.0), total = vec3(0.0);
        vec4 sum_lean = vec4(0.0);
        float sum_slope_x = 0.0, total_lean = 0.0;
        vec2 b_center = vec2(center.a, center_lean.x);
        for (int k = 0; k < samples; ++k) {
            vec4 kernel_tap = sss_kernels.taps[id * MAX_KERNEL_SAMPLES + k];
            float offset = round(kernel_tap.a * scale);
            ivec2 tap = clamp(px + ivec2(blur.step.xy * offset), ivec2(0), size - 1);
            float dz = linear_depth(texelFetch(depth_tex, tap, 0).r) - depth_m;
            // The profile at the tap's 3D distance (its offset in world units and the depth
            // difference) over the profile at its offset: <= 1, as the profile falls off with
            // distance (clamped against the table's interpolation); 0 past the table.
            float dx = kernel_tap.a;
            vec3 falloff = sss_falloff(id, info, sqrt(dx * dx + dz * dz)) *
                sss_kernels.inverse_falloff[id * MAX_KERNEL_SAMPLES + k].rgb;
            vec3 w = kernel_tap.rgb * clamp(falloff, vec3(0.0), vec3(1.0));
#ifdef LUCENT_SSS_PROFILE_EDGES
            int tap_id = sss_decode_id(texelFetch(profile_tex, tap, 0));
            w = tap_id != id && tap_id != 0 ? vec3(0.0) : w;
#endif
            // A NaN weight (from a NaN depth) would poison the sum: no weight.
            w = mix(w, vec3(0.0), isnan(w));
            vec4 color = finite_or(texelFetch(color_tex, tap, 0), center);
            vec4 lean = finite_or(texelFetch(lean_tex, tap, 0), center_lean);
            float w_lean = dot(w, vec3(1.0 / 3.0)) *
                (1.0 - lean_crease(vec2(color.a, lean.x), lean.yzw, b_center, center_lean.yzw,
                                   false));
            sum += w * color.rgb;
            total += w;
            sum_slope_x += w_lean * color.a;
            sum_lean += w_lean * lean;
            total_lean += w_lean;
        }
        // The centre tap (offset 0, depth difference 0) keeps its whole weight: the totals are
        // > 0 for any profile with weight in a channel; a channel without keeps its light.
        blurred = mix(center.rgb, sum / max(total, vec3(1e-30)), greaterThan(total, vec3(0.0)));
        if (total_lean > 0.0) {
            blurred_slope_x = sum_slope_x / total_lean;
            blurred_lean = sum_lean / total_lean;
        }
    }
    // fp16 targets: keep them finite.
    blurred = clamp(blurred, vec3(-65504.0), vec3(65504.0));
#ifdef LUCENT_SSS_COMPOSE
    vec3 color;
    if (scatters) {
        vec4 gb0 = texelFetch(albedo_tex, px, 0);
        vec4 gb1 = texelFetch(normal_tex, px, 0);
#ifdef LUCENT_SSS_ALBEDO
        // The albedo the lighting pass left out of the light (glsl/common/sss.glsl).
        blurred *= sss_albedo_after(id, gb0.rgb);
#endif
        color = blurred + lean_final_specular(gl_FragCoord.xy, device_depth,
                                              vec2(blurred_slope_x, blurred_lean.x),
                                              blurred_lean.yzw, gb1.a, gb0.a);
    } else {
#ifdef LUCENT_SSS_BASE
        color = texelFetch(base_tex, px, 0).rgb;
#else
        color = texelFetch(diffuse_tex, px, 0).rgb + texelFetch(specular_tex, px, 0).rgb;
#endif
    }
    out_color = composed(color);
#else
    out_color = vec4(blurred, clamp(blurred_slope_x, -65504.0, 65504.0));
    out_lean = clamp(blurred_lean, vec4(-65504.0), vec4(65504.0));
#endif
}
