#version 450
// permutations-only
// permutation: LUCENT_SSS_SEPARABLE
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_DEPTH_IN_ALPHA
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_VERTICAL LUCENT_SSS_PASSTHROUGH
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_VERTICAL LUCENT_SSS_BASE LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_HALF_RES
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_POINT_TAPS LUCENT_SSS_DEPTH_IN_ALPHA
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_POINT_TAPS LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_SEPARABLE LUCENT_SSS_HALF_RES LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_BILATERAL2 LUCENT_SSS_SAMPLES=17
// permutation: LUCENT_SSS_BILATERAL2 LUCENT_SSS_SAMPLES=11 LUCENT_SSS_VERTICAL
// permutation: LUCENT_SSS_BILATERAL2 LUCENT_SSS_SAMPLES=25 LUCENT_SSS_VERTICAL LUCENT_SSS_PASSTHROUGH LUCENT_SSS_BASE
// permutation: LUCENT_SSS_BILATERAL2 LUCENT_SSS_SAMPLES=17 LUCENT_SSS_VERTICAL LUCENT_SSS_PROFILE_EDGES
// permutation: LUCENT_SSS_BILATERAL2 LUCENT_SSS_SAMPLES=17 LUCENT_SSS_VERTICAL LUCENT_SHADOWS LUCENT_SHADOW_BINDING=20
// The two-pass screen-space SSS blurs (src/features/sss/two_pass.rs), one direction per pass:
// the horizontal pass blurs the lit diffuse into a temporary, the vertical pass blurs that and
// writes the chain's result (the blurred light plus specular on the chain's pixels, the
// previous chain's result or the lit diffuse + specular elsewhere), so the whole blur is two
// passes.
//
// - LUCENT_SSS_SEPARABLE (Jimenez 2015): the pixel's profile's kernel (sss_kernels: N samples,
//   offsets in world units scaled to pixels at the pixel's depth), bilinear taps, each followed
//   back to the centre colour across a depth step as deep as the kernel is wide ("follow
//   surface"). LUCENT_SSS_DEPTH_IN_ALPHA: the light's alpha holds linear depth (frames without
//   a LEAN chain, and always after the first pass), so a tap is one fetch.
//   LUCENT_SSS_HALF_RES: both passes at half resolution per side (the first reads the light
//   at the centre of each 2x2 block, bilinear: their mean), writing linear depth in alpha for
//   the depth-aware upsample (glsl/sss/upsample.frag) that then composes the result.
// - LUCENT_SSS_BILATERAL2 (the thesis's idea in two passes): LUCENT_SSS_SAMPLES point taps at
//   whole texels evenly over the profile's reach, each weighted per channel by the whole
//   profile at the tap's 3D distance (screen offset in world units and depth difference), which
//   is what the brute-force reference convolves; the LEAN texel (slope x in the light's alpha,
//   slope y and moments) is blurred with the mean of the channels' weights, keeping creases
//   out (lean_crease); the vertical pass ends with LEAN specular on the blurred moments.
// - LUCENT_SSS_PROFILE_EDGES (several profiles in the frame): a tap on another profile's pixel
//   counts as an edge. LUCENT_SSS_PASSTHROUGH: the vertical pass's variant for rectangles no
//   object of the chain covers (compose only).
#define LUCENT_SSS_KERNELS
#include "../common/scene.glsl"
#include "../common/sss.glsl"
#ifdef LUCENT_SSS_BILATERAL2
#include "../common/lean.glsl"
#endif

#define IMAGE0 3
layout(set = 0, binding = IMAGE0) uniform sampler2D color_tex;        // light (+ alpha)
layout(set = 0, binding = IMAGE0 + 1) uniform sampler2D depth_tex;    // device depth, full res
layout(set = 0, binding = IMAGE0 + 2) uniform sampler2D profile_tex;  // profile IDs, full res
#ifdef LUCENT_SSS_BILATERAL2
layout(set = 0, binding = IMAGE0 + 3) uniform sampler2D lean_tex;     // slope y, moments
#define COMPOSE0 (IMAGE0 + 4)
#else
#define COMPOSE0 (IMAGE0 + 3)
#endif
#if defined(LUCENT_SSS_VERTICAL) && !defined(LUCENT_SSS_HALF_RES)
#define LUCENT_SSS_COMPOSE
layout(set = 0, binding = COMPOSE0) uniform sampler2D diffuse_tex;    // unblurred diffuse
layout(set = 0, binding = COMPOSE0 + 1) uniform sampler2D specular_tex;
#ifdef LUCENT_SSS_BILATERAL2
layout(set = 0, binding = COMPOSE0 + 2) uniform sampler2D albedo_tex; // GB0: a = specular
layout(set = 0, binding = COMPOSE0 + 3) uniform sampler2D normal_tex; // GB1: a = roughness
#define BASE_BINDING (COMPOSE0 + 4)
#else
#define BASE_BINDING (COMPOSE0 + 2)
#endif
#ifdef LUCENT_SSS_BASE
layout(set = 0, binding = BASE_BINDING) uniform sampler2D base_tex;   // the previous chain's
#endif
#endif

layout(push_constant) uniform Blur {
    vec4 step;  // xy: direction (1,0) or (0,1); w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;
#if defined(LUCENT_SSS_BILATERAL2) && !defined(LUCENT_SSS_COMPOSE)
layout(location = 1) out vec4 out_lean;
#endif

// A NaN or Inf sample would poison every tap that reads it: replace it where it is read.
vec4 finite_or(vec4 c, vec4 fallback) {
    bool bad = any(isnan(c)) || any(isinf(c));
    return bad ? fallback : c;
}

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
#if defined(LUCENT_SSS_SEPARABLE) && defined(LUCENT_SSS_VERTICAL) && !defined(LUCENT_SSS_HALF_RES) && !defined(LUCENT_SSS_PROFILE_EDGES)
    // One profile in the frame (ID 1), and the horizontal pass marked the pixels that scatter
    // by the sign of the depth it passes on: no profile fetch.
#define SCATTER_FROM_ALPHA
    int id = 1;
#else
    int id = sss_profile_id(texelFetch(profile_tex, full_px, 0).r);
#endif
#if defined(LUCENT_SSS_SEPARABLE) && !(defined(LUCENT_SSS_HALF_RES) && !defined(LUCENT_SSS_VERTICAL)) && (defined(LUCENT_SSS_DEPTH_IN_ALPHA) || defined(LUCENT_SSS_VERTICAL))
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
    bool scatters = sss_in_chain(id, int(blur.step.w + 0.5));
#else
    bool scatters = sss_in_chain(id, int(blur.step.w + 0.5)) && device_depth < 1.0;
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
    // Pixels per world unit at the pixel's depth (at half resolution, half as many).
    float px_per_unit = frame.camera.z / max(depth_m, 1e-4) * float(size.y) / frame.viewport.y;
    // The taps' reach is clamped to a quarter of the screen: an extreme profile or a surface at
    // the near plane must not sample across the whole image.
    float max_px = 0.25 * float(max(size.x, size.y));
    vec3 blurred = center.rgb;
#ifdef LUCENT_SSS_BILATERAL2
    vec4 center_lean = finite_or(texelFetch(lean_tex, px, 0), vec4(0.0));
    vec4 blurred_lean = center_lean;
    float blurred_slope_x = center.a;
#endif
    if (scatters) {
#ifdef LUCENT_SSS_SEPARABLE
        vec4 info = sss_kernels.info[id];
        int samples = clamp(int(info.x + 0.5), 1, MAX_KERNEL_SAMPLES);
        float scale = min(px_per_unit, max_px / max(info.z, 1e-9));
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
            int tap_id = sss_profile_id(texelFetch(profile_tex, tap_px, 0).r);
            s = tap_id != id && tap_id != 0 ? 1.0 : s;
#endif
            sum += tap.rgb * mix(color.rgb, center.rgb, s);
        }
        // A NaN or Inf tap would poison the pixel: checked once on the sum (a poisoned sum
        // keeps the pixel's own light), so one bad pixel never spreads.
        blurred = any(isnan(sum)) || any(isinf(sum)) ? center.rgb : sum;
#else
        // The profile's kernel (as the separable blur's: pre-integrated weights at offsets in
        // world units), as nearest texels; each tap's weight then falls off with the depth
        // difference as the profile does: its 1-D form at the tap's 3D distance over that at
        // its screen offset (exact for every Gaussian of the sum:
        // G(sqrt(x^2 + dz^2)) = G(x) exp(-dz^2 / 2v)).
        vec4 info = sss_kernels.info[id];
        int samples = min(LUCENT_SSS_SAMPLES, clamp(int(info.x + 0.5), 1, MAX_KERNEL_SAMPLES));
        float scale = min(px_per_unit, max_px / max(info.z, 1e-9));
        {
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
                // difference) over the profile at its offset: <= 1, as the profile falls off
                // with distance (clamped against the table's interpolation); 0 past the table.
                float dx = kernel_tap.a;
                vec3 falloff = sss_falloff(id, info, sqrt(dx * dx + dz * dz)) *
                    sss_kernels.inverse_falloff[id * MAX_KERNEL_SAMPLES + k].rgb;
                vec3 w = kernel_tap.rgb * clamp(falloff, vec3(0.0), vec3(1.0));
#ifdef LUCENT_SSS_PROFILE_EDGES
                int tap_id = sss_profile_id(texelFetch(profile_tex, tap, 0).r);
                w = tap_id != id && tap_id != 0 ? vec3(0.0) : w;
#endif
                // A NaN weight (from a NaN depth) would poison the sum: no weight.
                w = mix(w, vec3(0.0), isnan(w));
                vec4 color = finite_or(texelFetch(color_tex, tap, 0), center);
                vec4 lean = finite_or(texelFetch(lean_tex, tap, 0), center_lean);
                float w_lean = dot(w, vec3(1.0 / 3.0)) *
                    (1.0 - lean_crease(vec2(color.a, lean.x), lean.yzw, b_center,
                                       center_lean.yzw, false));
                sum += w * color.rgb;
                total += w;
                sum_slope_x += w_lean * color.a;
                sum_lean += w_lean * lean;
                total_lean += w_lean;
            }
            // The centre tap (offset 0, depth difference 0) keeps its whole weight: the totals
            // are > 0 for any profile with weight in a channel; a channel without keeps its
            // light.
            blurred = mix(center.rgb, sum / max(total, vec3(1e-30)), greaterThan(total, vec3(0.0)));
            if (total_lean > 0.0) {
                blurred_slope_x = sum_slope_x / total_lean;
                blurred_lean = sum_lean / total_lean;
            }
        }
#endif
    }
    // fp16 targets: keep them finite.
    blurred = clamp(blurred, vec3(-65504.0), vec3(65504.0));
#ifdef LUCENT_SSS_COMPOSE
    vec3 color;
    if (scatters) {
#ifdef LUCENT_SSS_BILATERAL2
        vec4 gb0 = texelFetch(albedo_tex, px, 0);
        vec4 gb1 = texelFetch(normal_tex, px, 0);
        color = blurred + lean_final_specular(gl_FragCoord.xy, device_depth,
                                              vec2(blurred_slope_x, blurred_lean.x),
                                              blurred_lean.yzw, gb1.a, gb0.a);
#else
        color = blurred + texelFetch(specular_tex, px, 0).rgb;
#endif
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
#elif defined(LUCENT_SSS_BILATERAL2)
    out_color = vec4(blurred, clamp(blurred_slope_x, -65504.0, 65504.0));
    out_lean = clamp(blurred_lean, vec4(-65504.0), vec4(65504.0));
#else
    // The pixel's linear depth travels in alpha, so the next pass's taps read it with the
    // light; negative where the pixel does not scatter (the vertical pass then needs no
    // profile ID in one-profile frames).
    out_color = vec4(blurred, scatters ? depth_m : -depth_m);
#endif
}
