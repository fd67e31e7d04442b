// Multiple scattering read back by the single scattering pass, which adds it with its own
// terms. At full resolution (LUCENT_FULL_RES_TERM) each pixel averages its 3x3 neighbours of
// its own material and depth: the gather rotated its spiral by one of nine angles per 3x3
// block (glsl/common/sampling.glsl), so the average sees every radius at nine angles and no
// grain is left. Gathered at half resolution (src/features/layered.rs, `--half-gather`), it is
// brought back to full resolution here (one full-screen pass fewer: on lavapipe a pass over
// the screen costs ~15 ms at 1024^2 whatever it does). The half-resolution gather rotated its
// spiral by one of nine angles per 3x3 block of texels, so the resolve weighs the 4x4 texels
// around each pixel with a tent of per-axis weights (1 - f, 1, 1, f): a 3x3 box placed at the
// pixel's own position, in which every rotation has the same total weight (the two outer
// texels of an axis hold the same rotation, 1 - f + f = 1). It keeps only texels of the
// pixel's material and at its depth (a texel holds its 2x2 block's top-left pixel), so no
// term leaks across silhouettes or between
// objects. Include after layered.glsl with LUCENT_HALF_TERM defined.
#ifndef LUCENT_LAYERED_UPSAMPLE_GLSL
#define LUCENT_LAYERED_UPSAMPLE_GLSL

// rgb: the weighted multiple-scattering term; alpha: the texel's layered material ID.
layout(set = 0) uniform sampler2D half_term;

#ifdef LUCENT_FULL_RES_TERM
// The full-resolution term at pixel `px` of material `id`: the mean over its 3x3 neighbours of
// that material within ~1% of its depth (the pixel itself always counts).
vec3 upsampled_multiple(ivec2 px, int id) {
    ivec2 size = textureSize(half_term, 0);
    float here = layered_view_depth_at(px);
    vec3 sum = vec3(0.0);
    float count = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(px + ivec2(dx, dy), ivec2(0), size - 1);
            vec4 texel = texelFetch(half_term, q, 0);
            float d = layered_view_depth_at(q);
            float keep = int(texel.a + 0.5) == id && abs(d - here) <= 0.01 * here ? 1.0 : 0.0;
            sum += keep * texel.rgb;
            count += keep;
        }
    }
    return count > 0.0 ? sum / count : vec3(0.0);
}
#else
// The half-resolution term at full-resolution pixel `px` of material `id` (0 where no texel
// around it is of that material at that depth: a sliver thinner than a texel).
vec3 upsampled_multiple(ivec2 px, int id) {
    ivec2 size = ivec2(frame.viewport.xy);
    ivec2 half_size = textureSize(half_term, 0);
    float here = layered_view_depth_at(px);
    // Texel k samples pixel 2k: pixel px lies at px / 2 in texel units.
    vec2 t = vec2(px) * 0.5;
    ivec2 base = ivec2(floor(t));
    vec2 f = t - vec2(base);
    vec4 wx = vec4(1.0 - f.x, 1.0, 1.0, f.x);
    vec4 wy = vec4(1.0 - f.y, 1.0, 1.0, f.y);
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int k = 0; k < 16; ++k) {
        ivec2 o = ivec2(k & 3, k >> 2);
        ivec2 q = clamp(base + o - 1, ivec2(0), half_size - 1);
        vec4 texel = texelFetch(half_term, q, 0);
        if (int(texel.a + 0.5) != id) {
            continue;
        }
        float d = layered_view_depth_at(min(q * 2, size - 1));
        // Depth agreement within ~1% of the depth: a texel across a fold of the same object
        // (or behind it) gets no say.
        float rel = abs(d - here) / max(0.01 * here, 1e-6);
        float w = (wx[o.x] * wy[o.y] + 1e-4) / (1.0 + rel * rel);
        sum += texel.rgb * w;
        total += w;
    }
    return total > 0.0 ? sum / total : vec3(0.0);
}
#endif

#endif
