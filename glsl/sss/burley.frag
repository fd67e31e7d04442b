#version 450
// permutation: LUCENT_SSS_DEPTH_IN_ALPHA
// permutation:
// permutation: LUCENT_SSS_DEPTH_IN_ALPHA LUCENT_SSS_HALF_RES
// The gather pass of 2-D Burley SSS (src/features/sss/burley.rs): Christensen and Burley's
// normalized diffusion profile importance-sampled around each pixel; writes the diffused light
// and the pixel's linear depth in alpha (negative where it does not scatter), which
// glsl/sss/burley_resolve.frag averages over 3x3 pixels and composes.
//
// - LUCENT_SSS_DEPTH_IN_ALPHA: the lit diffuse's alpha holds linear depth (else read depth).
// - LUCENT_SSS_HALF_RES: the target is half the size per side; each texel gathers around the
//   top-left pixel of its 2x2 block, its spiral rotated by the texel's place in its own 3x3
//   block (the resolve averages 3x3 texels).
#include "../common/scene.glsl"
#include "../common/sss.glsl"
#include "../common/sampling.glsl"

#define BURLEY_RADII 128
// Per profile ID: rgb d per channel (world units), a the widest; knobs: x the sample budget,
// y 1 to rotate the spiral per pixel, z the reach in units of d; radii: the inverse CDF r / d
// at BURLEY_RADII + 1 evenly spaced fractions of the profile within the reach (four a vec4).
layout(std140, set = 0) uniform SssBurley {
    vec4 distance[MAX_SSS_PROFILES];
    vec4 knobs;
    vec4 radii[BURLEY_RADII / 4 + 1];
    // r / (e^(-r) + e^(-r/3)) at the same fractions (r in units of d): the sample's
    // 1 / pdf up to constants.
    vec4 inverse_pdf[BURLEY_RADII / 4 + 1];
} burley;

layout(set = 0) uniform sampler2D diffuse_tex;   // lit diffuse (+ depth)
layout(set = 0) uniform sampler2D depth_tex;     // device depth
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;   // profile IDs

layout(push_constant) uniform Blur {
    vec4 step;  // w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

const float PI = 3.14159265358979;

// The radius (in units of d) within which a fraction t in [0, 1] of the profile's reach lies:
// the exact inverse CDF (src/scene/profile.rs `burley_radius`), tabulated on the CPU and
// interpolated (a log, a pow and a sqrt per sample cost more than the sample's fetches on a
// CPU driver).
// The radius and 1 / pdf at fraction t: x and y.
vec2 burley_sample(float t) {
    float x = clamp(t, 0.0, 1.0) * float(BURLEY_RADII);
    int k = min(int(x), BURLEY_RADII - 1);
    int j = k + 1;
    vec2 a = vec2(burley.radii[k >> 2][k & 3], burley.inverse_pdf[k >> 2][k & 3]);
    vec2 b = vec2(burley.radii[j >> 2][j & 3], burley.inverse_pdf[j >> 2][j & 3]);
    return mix(a, b, x - float(k));
}


vec4 finite_or(vec4 c, vec4 fallback) {
    return any(isnan(c)) || any(isinf(c)) ? fallback : c;
}

float depth_at(ivec2 px, vec4 light) {
#ifdef LUCENT_SSS_DEPTH_IN_ALPHA
    return abs(light.a);
#else
    return linear_depth(texelFetch(depth_tex, px, 0).r);
#endif
}

void main() {
    ivec2 size = textureSize(diffuse_tex, 0);
#ifdef LUCENT_SSS_HALF_RES
    ivec2 texel = ivec2(gl_FragCoord.xy);
    ivec2 px = min(texel * 2, size - 1);
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 texel = px;
#endif
    vec4 center = finite_or(texelFetch(diffuse_tex, px, 0), vec4(0.0));
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    bool scatters = sss_in_chain(id, int(blur.step.w + 0.5));
    vec3 blurred = center.rgb;
    if (scatters) {
        int key = sss_id_key(texelFetch(profile_tex, px, 0));
        float depth_m = depth_at(px, center);
        vec4 dist = burley.distance[id];
        // Guarded: a zero d would divide by zero in the shape; the table holds d > 0.
        vec3 d = max(dist.rgb, vec3(1e-9));
        float d_max = max(dist.a, 1e-9);
        // e^(-r/d) = exp2(-r k) with k = log2(e) / d, per channel, and its third.
        vec3 k1 = 1.44269504 / d;
        vec3 k3 = k1 / 3.0;
        // Pixels per world unit at this depth; the reach is held to a quarter of the screen (a
        // surface at the near plane must not sample the whole image).
        float px_per_unit = frame.camera.z / max(depth_m, 1e-4);
        float reach_px = min(burley.knobs.z * d_max * px_per_unit, 0.25 * float(max(size.x, size.y)));
        // Samples from the kernel's area on screen, under the budget; under one pixel of
        // reach the profile stays inside the pixel.
        int budget = clamp(int(burley.knobs.x + 0.5), 1, 256);
        int samples = clamp(int(PI * reach_px * reach_px * 0.25 + 0.5), 0, budget);
        if (reach_px >= 1.0 && samples > 0) {
            float rotation = burley.knobs.y > 0.5 ? spiral_rotation(texel) : 0.0;
            // The spiral's direction turns by the golden angle per sample: one rotation
            // matrix instead of a cos and a sin per sample.
            vec2 direction = vec2(cos(rotation), sin(rotation));
            const mat2 turn = mat2(cos(GOLDEN_ANGLE), sin(GOLDEN_ANGLE),
                                   -sin(GOLDEN_ANGLE), cos(GOLDEN_ANGLE));
            // The radii follow the widest channel (stratified fractions of the profile within
            // the reach); every channel is weighted by its own profile over that pdf.
            vec3 sum = vec3(0.0);
            vec3 weights = vec3(0.0);
            for (int i = 0; i < samples; ++i) {
                vec2 radius_pdf = burley_sample((float(i) + 0.5) / float(samples));
                float r = radius_pdf.x * d_max;
                vec2 offset = direction * (r * px_per_unit);
                direction = turn * direction;
                ivec2 tap_px = clamp(px + ivec2(round(offset)), ivec2(0), size - 1);
                // Other profiles and pixels that do not scatter are rejected.
                if (sss_id_key(texelFetch(profile_tex, tap_px, 0)) != key) {
                    continue;
                }
                vec4 light = texelFetch(diffuse_tex, tap_px, 0);
                if (any(isnan(light)) || any(isinf(light))) {
                    continue;
                }
                float dz = depth_at(tap_px, light) - depth_m;
                float r3 = max(sqrt(r * r + dz * dz), 1e-9);
                // R_c(r3) / pdf(r): ((e^(-r3/d_c) + e^(-r3/3d_c)) / (d_c r3)) times the
                // tabulated r / (e^(-r/d) + e^(-r/3d)) of the widest channel, constants
                // dropped (they cancel in the normalisation).
                vec3 w = (exp2(-r3 * k1) + exp2(-r3 * k3)) / (d * r3) * radius_pdf.y;
                sum += w * light.rgb;
                weights += w;
            }
            vec3 result = sum / max(weights, vec3(1e-30));
            // A channel no sample reached keeps the pixel's own light.
            result = mix(center.rgb, result, step(vec3(1e-30), weights));
            blurred = any(isnan(result)) || any(isinf(result)) ? center.rgb : result;
        }
    }
    // fp16 target: in range; the depth travels in alpha, negative where the pixel does not
    // scatter (the resolve averages only its own profile's pixels).
    blurred = clamp(blurred, vec3(0.0), vec3(65504.0));
    float depth_m = depth_at(px, center);
    out_color = vec4(blurred, scatters ? depth_m : -depth_m);
}
