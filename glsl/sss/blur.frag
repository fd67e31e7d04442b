#version 450
// permutation: LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_LEAN
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=2
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=2 LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=2 LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=1 LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=1 LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_PACKED_OUT
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_PACKED_IN LUCENT_SSS_PACKED_OUT
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_PACKED_IN LUCENT_SSS_PACKED_OUT LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_PACKED_IN LUCENT_SSS_PACKED_OUT LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// permutation: LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=2 LUCENT_SSS_ACCUMULATE
// permutation: LUCENT_SSS_PROFILE_EDGES LUCENT_SSS_LEAN LUCENT_SSS_BILATERAL LUCENT_SSS_HALF_TAPS=2 LUCENT_SSS_ACCUMULATE LUCENT_SSS_SUM_IN
// One direction of a separable screen-space SSS blur (src/features/sss.rs), for one step (one
// Gaussian) of each pixel's own profile: the pixel's profile ID picks its sigma and weight from
// the profile table. The Gaussian's world-space sigma is projected to the screen at the pixel's
// depth (wider up close); pixels whose profile this chain does not blur come out unchanged.
// - LUCENT_SSS_PROFILE_EDGES (frames with several profiles): a tap on a pixel of another
//   profile counts as a depth discontinuity (control: back to the centre colour; bilateral:
//   no weight), so one profile's light never bleeds into another profile's object.
//
// - Control (Jimenez et al. 2009 as the LEAN-mapping thesis gives it, section 3.2.2): a 7-tap
//   kernel at fractional offsets (bilinear taps); a tap across a large depth difference is
//   lerped back to the centre colour.
// - LUCENT_SSS_BILATERAL (the thesis's LBB, section 4.3.2): 2 LUCENT_SSS_HALF_TAPS + 1 point
//   taps (default 7, the thesis's) spaced 3 sigma / LUCENT_SSS_HALF_TAPS apart at whole-texel offsets
//   around the centre, each weighted by the spatial Gaussian at its actual offset times a
//   depth-difference Gaussian (sensitivity over the completed profile Gaussian's width, per world
//   unit: at sensitivity 1 the weight is the profile Gaussian of the tap's 3D distance),
//   normalised by the weights' sum.
// - LUCENT_SSS_LEAN (LCB and LBB): two texels are blurred with the same weights, the lit
//   diffuse + view slope x and the G-buffer's LEAN slope y + moments.
// - LUCENT_SSS_PACKED_IN / _OUT (LBB): the two texels travel between passes as one RGBA32UI
//   texel of eight fp16 halves: one fetch per tap and one write per pass instead of two.
// The vertical pass (LUCENT_SSS_ACCUMULATE) also writes the sum of Gaussians so far: its result
// times the Gaussian's weight (RGB weights for the diffuse light, their mean, which sums to 1
// over the profile too, for the LEAN moments), plus the previous steps' sum read at the pixel
// (LUCENT_SSS_SUM_IN: every step after the first). The sums ping-pong between two targets
// instead of blending into one: a pass that blends one target and overwrites another needs
// per-attachment blend states (`independentBlend`, optional in Vulkan; lavapipe in Mesa 25.0
// applies the first attachment's state to all, see docs/lavapipe-facts.md).
#include "../common/scene.glsl"
#include "../common/sss.glsl"
#ifdef LUCENT_SSS_LEAN
#include "../common/lean.glsl"
#endif

#ifdef LUCENT_SSS_PACKED_IN
layout(set = 0) uniform usampler2D packed_tex;  // both texels, packed (nearest)
#else
layout(set = 0) uniform sampler2D color_tex;    // linear filtering, clamp to edge
#endif
layout(set = 0) uniform sampler2D depth_tex;    // device depth, read with texelFetch
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;  // SSS profile ID, 0 = not SSS
#if defined(LUCENT_SSS_LEAN) && !defined(LUCENT_SSS_PACKED_IN)
layout(set = 0) uniform sampler2D lean_tex;     // slope y, moments (same filter)
#endif
#ifdef LUCENT_SSS_SUM_IN
layout(set = 0) uniform sampler2D sum_in_tex;   // the previous steps' sum (texelFetch)
#ifdef LUCENT_SSS_LEAN
layout(set = 0) uniform sampler2D lean_sum_in_tex;
#endif
#endif

layout(push_constant) uniform Blur {
    vec4 step;    // xy: direction (1,0) or (0,1); z: the step (Gaussian) index; w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
#ifdef LUCENT_SSS_PACKED_OUT
layout(location = 0) out uvec4 out_packed;
#define SUM_LOCATION 1
#else
layout(location = 0) out vec4 out_color;
#ifdef LUCENT_SSS_LEAN
layout(location = 1) out vec4 out_lean;
#define SUM_LOCATION 2
#endif
#endif
#ifdef LUCENT_SSS_ACCUMULATE
#ifdef LUCENT_SSS_LEAN
layout(location = SUM_LOCATION) out vec4 out_sum;
layout(location = SUM_LOCATION + 1) out vec4 out_lean_sum;
#else
layout(location = 1) out vec4 out_sum;
#endif
#endif

// A NaN or Inf sample would poison every tap that reads it: replace it where it is read.
vec4 finite_or(vec4 c, vec4 fallback) {
    bool bad = any(isnan(c)) || any(isinf(c));
    return bad ? fallback : c;
}

#ifdef LUCENT_SSS_PACKED_IN
// Both texels at `p` from the packed target.
void fetch_texels(ivec2 p, out vec4 color, out vec4 lean) {
    uvec4 u = texelFetch(packed_tex, p, 0);
    color = vec4(unpackHalf2x16(u.x), unpackHalf2x16(u.y));
    lean = vec4(unpackHalf2x16(u.z), unpackHalf2x16(u.w));
}
#elif defined(LUCENT_SSS_LEAN)
void fetch_texels(ivec2 p, out vec4 color, out vec4 lean) {
    color = texelFetch(color_tex, p, 0);
    lean = texelFetch(lean_tex, p, 0);
}
#endif

void main() {
    ivec2 size = textureSize(depth_tex, 0);
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef LUCENT_SSS_LEAN
    vec4 center, center_lean;
    fetch_texels(px, center, center_lean);
    center = finite_or(center, vec4(0.0));
    center_lean = finite_or(center_lean, vec4(0.0));
#else
    vec4 center = finite_or(texelFetch(color_tex, px, 0), vec4(0.0));
#endif
    float device_depth = texelFetch(depth_tex, px, 0).r;
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    SssStep profile_step = sss_step(id, int(blur.step.z + 0.5));
    // Pixels of other chains' profiles (and of none) are left as they are; sky pixels have no
    // surface to scatter in.
    float strength = sss_in_chain(id, int(blur.step.w + 0.5)) && depth_is_surface(device_depth) ? 1.0 : 0.0;
    float depth_term = profile_step.blur.y;
    float depth_m = linear_depth(device_depth);
    float sigma_px = profile_step.blur.x * frame.camera.z / max(depth_m, 1e-4) * strength;
    // Clamp the reach (3 sigma) to a quarter of the screen: an extreme strength or a surface at
    // the near plane must not sample across the whole image.
    sigma_px = min(sigma_px, 0.25 / 3.0 * float(max(size.x, size.y)));
#ifdef LUCENT_SSS_BILATERAL
#ifndef LUCENT_SSS_HALF_TAPS
#define LUCENT_SSS_HALF_TAPS 3
#endif
    // Point taps at k * spacing (k = -h..h, spacing 3 sigma / h) rounded to whole texels,
    // weighted where they land. Below half a texel every tap rounds onto the centre: the pixel
    // stays as it is.
    float sigma = sigma_px < 0.5 ? 0.0 : sigma_px;
    float spacing = sigma * (3.0 / float(LUCENT_SSS_HALF_TAPS));
    vec4 sum = vec4(0.0);
#ifdef LUCENT_SSS_LEAN
    // The LEAN texels (slope x in the light's alpha, slope y and moments) have weights of
    // their own: a tap across a crease adds light but no slopes (lean_crease).
    vec4 sum_lean = vec4(0.0);
    float sum_slope_x = 0.0;
    float total_lean = 0.0;
    vec2 b_center = vec2(center.a, center_lean.x);
#endif
    float total = 0.0;
    for (int k = -LUCENT_SSS_HALF_TAPS; k <= LUCENT_SSS_HALF_TAPS; ++k) {
        float offset = round(float(k) * spacing);
        ivec2 tap = clamp(px + ivec2(blur.step.xy * offset), ivec2(0), size - 1);
        float dz = (linear_depth(texelFetch(depth_tex, tap, 0).r) - depth_m) * depth_term;
        float r = sigma > 0.0 ? offset / sigma : 0.0;
        float w = exp(-0.5 * (r * r + dz * dz));
#ifdef LUCENT_SSS_PROFILE_EDGES
        int tap_id = sss_decode_id(texelFetch(profile_tex, tap, 0));
        w = tap_id != id && tap_id != 0 ? 0.0 : w;
#endif
        // A NaN depth would poison the sum: such a tap gets no weight.
        w = w >= 0.0 ? w : 0.0;
#ifdef LUCENT_SSS_LEAN
        vec4 color, lean;
        fetch_texels(tap, color, lean);
        color = finite_or(color, center);
        lean = finite_or(lean, center_lean);
        float w_lean =
            w * (1.0 - lean_crease(vec2(color.a, lean.x), lean.yzw, b_center, center_lean.yzw,
                                   false));
        sum += w * color;
        sum_slope_x += w_lean * color.a;
        sum_lean += w_lean * lean;
        total_lean += w_lean;
#else
        sum += w * finite_or(texelFetch(color_tex, tap, 0), center);
#endif
        total += w;
    }
    // The centre tap has weight 1 (offset 0, no depth difference): total >= 1.
    vec4 blurred = sum / max(total, 1e-6);
#ifdef LUCENT_SSS_LEAN
    // The centre's LEAN weight is 1 too: total_lean >= 1.
    blurred.a = sum_slope_x / max(total_lean, 1e-6);
    vec4 blurred_lean = sum_lean / max(total_lean, 1e-6);
#endif
#else
    // Jimenez's kernel: centre 0.382, six taps at +-1/3, +-2/3, +-1 of the reach (sums to 1).
    const float w[6] = float[](0.006, 0.061, 0.242, 0.242, 0.061, 0.006);
    const float o[6] = float[](-1.0, -0.6667, -0.3333, 0.3333, 0.6667, 1.0);
    // A Gaussian narrower than a pixel is about a delta at this resolution: blurring it anyway
    // would only add the bilinear taps' own filtering (measured against the brute-force
    // reference: twelve such passes end further from it than no blur at all).
    float reach_px = sigma_px < 1.0 ? 0.0 : 3.0 * sigma_px;
    vec2 final_step = blur.step.xy * reach_px * frame.viewport.zw;
    vec2 uv = (vec2(px) + 0.5) * frame.viewport.zw;
    vec4 blurred = center * 0.382;
#ifdef LUCENT_SSS_LEAN
    vec4 blurred_lean = center_lean * 0.382;
#endif
    for (int i = 0; i < 6; ++i) {
        vec2 offset = uv + o[i] * final_step;
        ivec2 tap = clamp(ivec2(offset * frame.viewport.xy), ivec2(0), size - 1);
        float depth = linear_depth(texelFetch(depth_tex, tap, 0).r);
        // A huge depth difference (another object, the background): back to the centre colour.
        float s = min(depth_term * abs(depth_m - depth), 1.0);
#ifdef LUCENT_SSS_PROFILE_EDGES
        int tap_id = sss_decode_id(texelFetch(profile_tex, tap, 0));
        s = tap_id != id && tap_id != 0 ? 1.0 : s;
#endif
#ifdef LUCENT_SSS_LEAN
        vec4 color = finite_or(textureLod(color_tex, offset, 0.0), center);
        vec4 lean = finite_or(textureLod(lean_tex, offset, 0.0), center_lean);
        // Across a crease the tap adds light but no slopes (lean_crease).
        float s_lean = max(s, lean_crease(vec2(color.a, lean.x), lean.yzw,
                                          vec2(center.a, center_lean.x), center_lean.yzw, true));
        vec4 tap_color = mix(color, center, s);
        tap_color.a = mix(color.a, center.a, s_lean);
        blurred += w[i] * tap_color;
        blurred_lean += w[i] * mix(lean, center_lean, s_lean);
#else
        blurred += w[i] * mix(finite_or(textureLod(color_tex, offset, 0.0), center), center, s);
#endif
    }
#endif
    // fp16 targets: keep them finite.
    blurred = clamp(blurred, vec4(-65504.0), vec4(65504.0));
#ifdef LUCENT_SSS_LEAN
    blurred_lean = clamp(blurred_lean, vec4(-65504.0), vec4(65504.0));
#endif
#ifdef LUCENT_SSS_PACKED_OUT
    out_packed = uvec4(packHalf2x16(blurred.xy), packHalf2x16(blurred.zw),
                       packHalf2x16(blurred_lean.xy), packHalf2x16(blurred_lean.zw));
#else
    out_color = blurred;
#ifdef LUCENT_SSS_LEAN
    out_lean = blurred_lean;
#endif
#endif
#ifdef LUCENT_SSS_ACCUMULATE
#ifdef LUCENT_SSS_LEAN
    // Pixels this chain does not blur add nothing (their profile's weights are not this
    // chain's); a profile with fewer steps than the chain has zero weights past its last.
    vec4 weight = strength > 0.0 ? profile_step.weight : vec4(0.0);
    out_sum = vec4(blurred.rgb * weight.rgb, blurred.a * weight.a);
    out_lean_sum = blurred_lean * weight.a;
#ifdef LUCENT_SSS_SUM_IN
    out_sum += texelFetch(sum_in_tex, px, 0);
    out_lean_sum += texelFetch(lean_sum_in_tex, px, 0);
#endif
#else
    vec4 weight = strength > 0.0 ? profile_step.weight : vec4(0.0);
    out_sum = vec4(blurred.rgb * weight.rgb, 0.0);
#ifdef LUCENT_SSS_SUM_IN
    out_sum += texelFetch(sum_in_tex, px, 0);
#endif
#endif
#endif
}
