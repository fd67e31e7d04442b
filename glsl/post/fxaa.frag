#version 450
// permutation: LUCENT_OUTPUT_LINEAR
// Fast approximate anti-aliasing (after Lottes' FXAA 3.11 "quality" form), on the tonemapped,
// sRGB-encoded image whose alpha holds its luma (post/tonemap.frag with LUCENT_LUMA_IN_ALPHA).
//
// Per pixel: the luma contrast of the 4-neighbourhood decides whether this is an edge at all
// (below the thresholds the pixel is copied unchanged, so flat regions are bit-exact); the
// 3x3 second differences decide whether the edge runs horizontally or vertically; the edge is
// followed both ways along its length until the luma leaves the edge's mean (up to
// FXAA_STEPS probes, growing strides); the pixel then moves across the edge by how near it
// sits to the edge's nearer end (a stair step becomes a ramp), or by the sub-pixel amount when
// that is larger (isolated single-pixel features). With LUCENT_OUTPUT_LINEAR the result is
// decoded back to linear for sRGB and float targets.
//
// Cost on lavapipe (docs/antialias.md): every read is a texel fetch, never a filtered tap (a
// bilinear tap costs about four fetches there, and the first in a shader several more);
// the values FXAA 3.11 reads between texels are means of two texels, computed here. llvmpipe
// runs both sides of every branch and each loop as long as any of its 8 lanes needs it, so
// the search's first probe comes from the 3x3 already read, and each loop trip probes one
// direction (two fetches) rather than both (four).
#include "../common/scene.glsl"
#include "../common/color.glsl"

layout(set = 0) uniform sampler2D ldr;  // read with texelFetch only

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
// Search probes each way along the edge (12 probes reach 27 pixels).
const int FXAA_STEPS = 12;

// The stride of probe i in whole pixels: 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 4, 8. Whole strides keep
// every probe on a pixel pair (FXAA 3.11's 1.5 would put the later ones between four texels);
// computed rather than read from a constant array, which lavapipe indexes per lane (7.9 -> 7.1
// ms at 1024x768).
int stride(int i) {
    return i < 5 ? 1 : (i < 10 ? 2 : (i == 10 ? 4 : 8));
}

// The last texel of the image: every fetch is clamped to it, as a clamp-to-edge sampler would.
ivec2 last_texel;

vec4 texel_at(ivec2 p) {
    return texelFetch(ldr, clamp(p, ivec2(0), last_texel), 0);
}

float luma_at(ivec2 p) {
    return texel_at(p).a;
}

void main() {
    last_texel = textureSize(ldr, 0) - 1;
    ivec2 p = ivec2(gl_FragCoord.xy);  // this pixel, inside the image
    vec4 centre = texelFetch(ldr, p, 0);
    float l_m = centre.a;
    // North is the row above: smaller y in Vulkan's image coordinates.
    vec4 t_n = texel_at(p + ivec2(0, -1));
    vec4 t_s = texel_at(p + ivec2(0, 1));
    vec4 t_w = texel_at(p + ivec2(-1, 0));
    vec4 t_e = texel_at(p + ivec2(1, 0));
    float l_n = t_n.a;
    float l_s = t_s.a;
    float l_w = t_w.a;
    float l_e = t_e.a;
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
    float l_nw = luma_at(p + ivec2(-1, -1));
    float l_ne = luma_at(p + ivec2(1, -1));
    float l_sw = luma_at(p + ivec2(-1, 1));
    float l_se = luma_at(p + ivec2(1, 1));

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
    // One pixel across the edge (toward the steeper neighbour), and one along it.
    ivec2 across = horizontal ? ivec2(0, 1) : ivec2(1, 0);
    if (toward_before) {
        across = -across;
    }
    ivec2 along = horizontal ? ivec2(1, 0) : ivec2(0, 1);
    float edge_mean = 0.5 * (l_m + (toward_before ? l_before : l_after));
    float gradient_scaled = 0.25 * max(grad_before, grad_after);

    // Walk along the edge both ways. A probe d pixels away reads the mean luma of the pixel
    // pair that straddles the edge there (this pixel's row or column and the one across),
    // what a bilinear tap on the boundary between them would read. The first probe each way
    // (d = 1) is a pair of the 3x3 neighbourhood.
    float l_neg_pair = horizontal ? (toward_before ? l_nw : l_sw) : (toward_before ? l_nw : l_ne);
    float l_pos_pair = horizontal ? (toward_before ? l_ne : l_se) : (toward_before ? l_sw : l_se);
    int d_neg = 1;
    int d_pos = 1;
    float end_neg = 0.5 * ((horizontal ? l_w : l_n) + l_neg_pair) - edge_mean;
    float end_pos = 0.5 * ((horizontal ? l_e : l_s) + l_pos_pair) - edge_mean;
    bool done_neg = abs(end_neg) >= gradient_scaled;
    bool done_pos = abs(end_pos) >= gradient_scaled;
    // Trip k probes step k / 2 of the negative (even k) or positive (odd k) direction.
    for (int k = 2; k < 2 * FXAA_STEPS && !(done_neg && done_pos); ++k) {
        bool neg = (k & 1) == 0;
        if (neg ? !done_neg : !done_pos) {
            int d = (neg ? d_neg : d_pos) + stride(k >> 1);
            ivec2 q = p + (neg ? -d : d) * along;
            float e = 0.5 * (luma_at(q) + luma_at(q + across)) - edge_mean;
            bool done = abs(e) >= gradient_scaled;
            if (neg) {
                d_neg = d;
                end_neg = e;
                done_neg = done;
            } else {
                d_pos = d;
                end_pos = e;
                done_pos = done;
            }
        }
    }
    bool nearer_neg = d_neg < d_pos;
    // >= 2: the probes move at least one pixel each way.
    float span = float(d_neg + d_pos);
    float dist = float(min(d_neg, d_pos));
    // Blend only at the end of the span where the luma crosses to the other side: the edge's
    // step belongs to that end.
    bool centre_below = l_m - edge_mean < 0.0;
    bool good_end = ((nearer_neg ? end_neg : end_pos) < 0.0) != centre_below;
    float offset = good_end ? 0.5 - dist / span : 0.0;
    offset = max(offset, sub);
    // Move the pixel by `offset` toward the pixel across the edge (a 4-neighbour already
    // read): the blend a bilinear tap there would return.
    vec3 across_rgb = horizontal ? (toward_before ? t_n.rgb : t_s.rgb)
                                 : (toward_before ? t_w.rgb : t_e.rgb);
    vec3 c = mix(centre.rgb, across_rgb, offset);
#ifdef LUCENT_OUTPUT_LINEAR
    c = srgb_to_linear(c);
#endif
    out_color = vec4(c, 1.0);
}
