#version 450
// permutation: LUCENT_HALF_GATHER
// The multiple-scattering term's blur (src/features/layered/mod.rs, `multiple scattering
// blur`), between the gather and its resolve in single scattering: each texel of a medium
// whose diffusion reaches far on screen becomes the mean of the 3x3 texels around it of its
// own material and depth. The gather rotated its spiral by one of nine angles per 3x3 block,
// so the mean holds every rotation once, and single scattering's resolve then averages these
// means again: twice the footprint of the resolve alone, which halves what is left of the
// gather's sampling noise where the medium is clear (the wax candles of `showcase-layered`).
// A medium whose narrowest channel diffuses over fewer than BLUR_FULL_KERNEL_PX pixels is
// blurred less, and not at all under BLUR_NO_KERNEL_PX: its term has detail at the scale of
// the blur (jade's red), which a blur would wash out. The pass draws only over objects whose
// medium reaches that at their nearest point (src/features/layered/mod.rs `blurs_on_screen`,
// whose BLUR_MIN_KERNEL_TEXELS is the same number); elsewhere its target keeps the gather's
// copy of the term. Set 0 as glsl/common/layered.glsl, then the term (`term_tex`: rgb the
// weighted term, alpha the material ID). With LUCENT_HALF_GATHER the term is at half
// resolution and texel k holds pixel 2k.
#include "../common/layered.glsl"

layout(set = 0) uniform sampler2D term_tex;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_term;

// The narrowest channel's diffusion length 1 / sigma_tr in screen pixels at or above which the
// term is the full 3x3 mean, and under which it is left as gathered (a smooth ramp between,
// so the blur does not switch on along a visible line where the depth changes). The mean's
// box is 3 texels (6 pixels at half resolution): a profile at least 4 boxes wide changes
// little over one.
#ifdef LUCENT_HALF_GATHER
#define TEXEL_PX 2.0
#else
#define TEXEL_PX 1.0
#endif
const float BLUR_FULL_KERNEL_PX = 12.0 * TEXEL_PX;
const float BLUR_NO_KERNEL_PX = 6.0 * TEXEL_PX;

// The full-resolution pixel texel `t` of the term holds.
ivec2 term_pixel(ivec2 t) {
    ivec2 px = t * int(TEXEL_PX);
    return min(px, ivec2(frame.viewport.xy) - 1);
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 own = texelFetch(term_tex, t, 0);
    out_term = own;
    int id = int(own.a + 0.5);
    if (id == 0) {
        return;
    }
    int mat = layered_row(id);
    float here = layered_view_depth_at(term_pixel(t));
    // Pixels per scene unit at this depth (the focal length in pixels over the depth), and
    // the narrowest channel's diffusion length on screen.
    float px_per_unit = frame.camera.z / max(here, 1e-6);
    float sigma_max = max(max(MAT.sigma_tr.r, MAT.sigma_tr.g), max(MAT.sigma_tr.b, 1e-12));
    float kernel_px = px_per_unit / sigma_max;
    float amount = smoothstep(BLUR_NO_KERNEL_PX, BLUR_FULL_KERNEL_PX, kernel_px);
    if (!(amount > 0.0)) {
        return;
    }
    ivec2 size = textureSize(term_tex, 0);
    vec3 sum = vec3(0.0);
    float count = 0.0;
    for (int k = 0; k < 9; ++k) {
        ivec2 q = t + ivec2(k % 3, k / 3) - 1;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) {
            continue;
        }
        vec4 texel = texelFetch(term_tex, q, 0);
        float d = layered_view_depth_at(term_pixel(q));
        // Same material, within ~1% of the depth (the resolve's rule): no term crosses a
        // silhouette or a fold of the same object.
        if (int(texel.a + 0.5) == id && abs(d - here) <= 0.01 * here) {
            sum += texel.rgb;
            count += 1.0;
        }
    }
    // The texel itself always counts, so count >= 1.
    out_term = vec4(mix(own.rgb, sum / max(count, 1.0), amount), own.a);
}
