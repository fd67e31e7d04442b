#version 450
// permutation: LUCENT_OUTPUT_LINEAR
// Fast approximate anti-aliasing (after Lottes' FXAA 3.11 "quality" form), on the tonemapped,
// sRGB-encoded image whose alpha holds its luma (post/tonemap.frag with LUCENT_LUMA_IN_ALPHA).
//
// Per pixel: the luma contrast of the 4-neighbourhood decides whether this is an edge at all
// (below the thresholds the pixel is copied unchanged, so flat regions are bit-exact); the
// 3x3 second differences decide whether the edge runs horizontally or vertically; the edge is
// followed both ways along its length until the luma leaves the edge's mean (up to
// FXAA_STEPS probes, growing strides); the pixel then samples, bilinearly, across the edge by
// how near it sits to the edge's nearer end (a stair step becomes a ramp), or by the
// sub-pixel amount when that is larger (isolated single-pixel features). With
// LUCENT_OUTPUT_LINEAR the result is decoded back to linear for sRGB and float targets.
#include "../common/scene.glsl"
#include "../common/color.glsl"

layout(set = 0, binding = 1) uniform sampler2D ldr;  // bilinear, clamped to the edge

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// Below this contrast relative to the local maximum luma, a pixel is not an edge (1/8: the
// "high quality" preset).
const float EDGE_THRESHOLD = 0.125;
// Below this absolute contrast, dark regions are not edges (1/16: noise in the darks is left
// alone).
const float EDGE_THRESHOLD_MIN = 0.0625;
// How much of the sub-pixel aliasing is removed (0 none, 1 all; 0.75 the preset's default).
const float SUBPIXEL = 0.75;
// Search probes along the edge and their strides in pixels (12 probes reach 27 pixels).
const int FXAA_STEPS = 12;
const float STRIDES[FXAA_STEPS] = float[](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);

float luma_at(vec2 uv) {
    return textureLod(ldr, uv, 0.0).a;
}

void main() {
    vec2 texel = frame.viewport.zw;
    vec2 uv = gl_FragCoord.xy * texel;  // this pixel's centre
    vec4 centre = textureLod(ldr, uv, 0.0);
    float l_m = centre.a;
    // North is the row above: smaller y in Vulkan's image coordinates.
    float l_n = textureLodOffset(ldr, uv, 0.0, ivec2(0, -1)).a;
    float l_s = textureLodOffset(ldr, uv, 0.0, ivec2(0, 1)).a;
    float l_w = textureLodOffset(ldr, uv, 0.0, ivec2(-1, 0)).a;
    float l_e = textureLodOffset(ldr, uv, 0.0, ivec2(1, 0)).a;
    float lo = min(l_m, min(min(l_n, l_s), min(l_w, l_e)));
    float hi = max(l_m, max(max(l_n, l_s), max(l_w, l_e)));
    float range = hi - lo;
    if (range < max(EDGE_THRESHOLD_MIN, hi * EDGE_THRESHOLD)) {
        out_color = centre;
#ifdef LUCENT_OUTPUT_LINEAR
        out_color.rgb = srgb_to_linear(centre.rgb);
#endif
        out_color.a = 1.0;
        return;
    }
    float l_nw = textureLodOffset(ldr, uv, 0.0, ivec2(-1, -1)).a;
    float l_ne = textureLodOffset(ldr, uv, 0.0, ivec2(1, -1)).a;
    float l_sw = textureLodOffset(ldr, uv, 0.0, ivec2(-1, 1)).a;
    float l_se = textureLodOffset(ldr, uv, 0.0, ivec2(1, 1)).a;

    // Sub-pixel aliasing: how far the centre stands out of its 3x3 low-pass, relative to the
    // local contrast (range > 0 here: the threshold above is at least EDGE_THRESHOLD_MIN).
    float average = (2.0 * (l_n + l_s + l_w + l_e) + (l_nw + l_ne + l_sw + l_se)) / 12.0;
    float sub = clamp(abs(average - l_m) / range, 0.0, 1.0);
    sub = smoothstep(0.0, 1.0, sub);
    sub = sub * sub * SUBPIXEL;

    // Second differences across rows (a horizontal edge) and across columns (a vertical one).
    float across_rows = abs(l_nw - 2.0 * l_w + l_sw) + 2.0 * abs(l_n - 2.0 * l_m + l_s)
                      + abs(l_ne - 2.0 * l_e + l_se);
    float across_columns = abs(l_nw - 2.0 * l_n + l_ne) + 2.0 * abs(l_w - 2.0 * l_m + l_e)
                         + abs(l_sw - 2.0 * l_s + l_se);
    bool horizontal = across_rows >= across_columns;

    // The two neighbours across the edge: north/south for a horizontal edge, west/east else.
    float l_before = horizontal ? l_n : l_w;
    float l_after = horizontal ? l_s : l_e;
    float grad_before = abs(l_before - l_m);
    float grad_after = abs(l_after - l_m);
    bool toward_before = grad_before >= grad_after;
    float step_across = horizontal ? texel.y : texel.x;
    if (toward_before) {
        step_across = -step_across;
    }
    float edge_mean = 0.5 * (l_m + (toward_before ? l_before : l_after));
    float gradient_scaled = 0.25 * max(grad_before, grad_after);

    // Walk along the edge, on the boundary between this pixel and its neighbour across it.
    vec2 on_edge = uv;
    vec2 along = horizontal ? vec2(texel.x, 0.0) : vec2(0.0, texel.y);
    if (horizontal) {
        on_edge.y += 0.5 * step_across;
    } else {
        on_edge.x += 0.5 * step_across;
    }
    vec2 p_neg = on_edge - along;
    vec2 p_pos = on_edge + along;
    float end_neg = luma_at(p_neg) - edge_mean;
    float end_pos = luma_at(p_pos) - edge_mean;
    bool done_neg = abs(end_neg) >= gradient_scaled;
    bool done_pos = abs(end_pos) >= gradient_scaled;
    for (int i = 1; i < FXAA_STEPS && !(done_neg && done_pos); ++i) {
        if (!done_neg) {
            p_neg -= along * STRIDES[i];
            end_neg = luma_at(p_neg) - edge_mean;
            done_neg = abs(end_neg) >= gradient_scaled;
        }
        if (!done_pos) {
            p_pos += along * STRIDES[i];
            end_pos = luma_at(p_pos) - edge_mean;
            done_pos = abs(end_pos) >= gradient_scaled;
        }
    }
    float dist_neg = horizontal ? uv.x - p_neg.x : uv.y - p_neg.y;
    float dist_pos = horizontal ? p_pos.x - uv.x : p_pos.y - uv.y;
    bool nearer_neg = dist_neg < dist_pos;
    float dist = min(dist_neg, dist_pos);
    // > 0: the probes move at least one texel each way.
    float span = max(dist_neg + dist_pos, 1e-6);
    // Blend only at the end of the span where the luma crosses to the other side: the edge's
    // step belongs to that end.
    bool centre_below = l_m - edge_mean < 0.0;
    bool good_end = ((nearer_neg ? end_neg : end_pos) < 0.0) != centre_below;
    float offset = good_end ? 0.5 - dist / span : 0.0;
    offset = max(offset, sub);
    vec2 sample_uv = uv;
    if (horizontal) {
        sample_uv.y += offset * step_across;
    } else {
        sample_uv.x += offset * step_across;
    }
    vec3 c = textureLod(ldr, sample_uv, 0.0).rgb;
#ifdef LUCENT_OUTPUT_LINEAR
    c = srgb_to_linear(c);
#endif
    out_color = vec4(c, 1.0);
}
