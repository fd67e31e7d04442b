#version 450
// permutation: LUCENT_HALF_GATHER
// Li et al.'s multiple scattering (eqs. 12-13), added into the lit image weighted by eq. 3's
// λ5 (src/features/layered.rs, `multiple scattering`): Jensen's dipole of the first layer
// gathered over M pixel lights of the irradiance image. Set 0 as glsl/common/layered.glsl,
// then the irradiance image (`irradiance_tex`). It stores the weighted term with the material ID in
// alpha, twice (the second copy is what the term's blur overwrites where it blurs), which
// single scattering reads back (glsl/common/layered_upsample.glsl): at full
// resolution the spiral is rotated by one of nine angles per 3x3 block
// (glsl/common/sampling.glsl) and single scattering averages each pixel's 3x3 neighbours; with
// LUCENT_HALF_GATHER each texel of a half-resolution target gathers for its 2x2 block's
// top-left pixel, its spiral rotated by one of nine angles per 3x3 block of texels, and single
// scattering resolves it over the texels around each pixel (every rotation an equal share).
#include "../common/layered.glsl"
#include "../common/sampling.glsl"

layout(set = 0) uniform sampler2D irradiance_tex;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;
// The same term again: the blur's target (src/features/layered/mod.rs `term_blur`), which the
// blur then overwrites only over the objects it blurs; elsewhere single scattering reads this.
layout(location = 1) out vec4 out_copy;

void main() {
#ifdef LUCENT_HALF_GATHER
    ivec2 px = min(ivec2(gl_FragCoord.xy) * 2, ivec2(frame.viewport.xy) - 1);
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
#endif
    int id = layered_id_at(px);
    out_color = vec4(0.0);
    out_copy = vec4(0.0);
    if (id == 0) {
        return;
    }
    int mat = layered_row(id);
    float eta = MAT.info.y;
    vec3 x_o = layered_position_at(px);
    vec3 n_o = layered_normal_at(px);
    vec3 view = x_o - frame.camera_pos.xyz;
    float view_len2 = dot(view, view);
    vec3 view_dir = view_len2 > 1e-20 ? view * inversesqrt(view_len2) : -n_o;
    n_o = facing_normal(n_o, view_dir);
    float cos_o = dot(-view_dir, n_o);
    float radius = MAT.info.w;
    vec3 t, b;
    lucent_any_tangent_frame(n_o, t, b);
    // Radii drawn from p(r) ~ e^(-sigma r) on [0, radius] (sigma: the green channel's
    // sigma_tr, at least 1 / radius, so a clear medium is sampled nearly uniformly in r).
    float sigma = max(MAT.sigma_tr.g, 1.0 / radius);
    float span = 1.0 - exp(-sigma * radius);
    int count = clamp(layered.knobs.y, 4, 64);
    int scale = max(layered.knobs.w, 1);
    ivec2 size = ivec2(frame.viewport.xy);
    // One of nine rotations per 3x3 block of this pass's texels (half-resolution texels with
    // LUCENT_HALF_GATHER): the resolve in single scattering gives each an equal share.
    float rotation = spiral_rotation(ivec2(gl_FragCoord.xy));
    vec3 gathered = vec3(0.0), weight = vec3(0.0);
    for (int i = 0; i < count; ++i) {
        float u = (float(i) + 0.5) / float(count);
        float r_plane = -log(max(1.0 - u * span, 1e-30)) / sigma;
        // The area a sample stands for: 1 / (count x its density on the tangent plane).
        float pdf_r = sigma * exp(-sigma * r_plane) / span;
        float area = 6.28318530718 * r_plane / (float(count) * max(pdf_r, 1e-30));
        float phi = float(i) * GOLDEN_ANGLE + rotation;
        vec3 y = x_o + r_plane * (cos(phi) * t + sin(phi) * b);
        vec4 clip = frame.view_proj * vec4(y, 1.0);
        if (!(clip.w > 0.0)) {
            continue;
        }
        vec2 q = (clip.xy / clip.w * 0.5 + 0.5) * frame.viewport.xy;
        if (any(lessThan(q, vec2(0.0))) || any(greaterThanEqual(q, frame.viewport.xy))) {
            continue; // off screen
        }
        ivec2 qp = min(ivec2(q), size - 1);
        // The irradiance texel carries its pixel's material in alpha.
        vec4 light = texelFetch(irradiance_tex, qp / scale, 0);
        if (int(light.a + 0.5) != id) {
            continue; // another object or material: rejected
        }
        vec3 p = layered_position_at(qp);
        float r = length(p - x_o);
        vec3 e = light.rgb;
        vec3 rd = dipole_rd(mat, r) * area;
        gathered += rd * e;
        weight += rd;
    }
    // Energy normalised: the Rd- and area-weighted mean of the accepted pixel lights' E
    // times the medium's multiple scattering (MAT.total: its white-sky albedo less single
    // scattering's share, over c^2; src/scene/layered.rs `albedo_split`), so a
    // uniformly lit surface gets exactly that whatever the rejected samples (normalising by
    // the weights at the samples' own r, not their tangent-plane radii, halved the error on
    // the test spheres).
    // (No accepted sample: both sums are 0, and so is the term.)
    vec3 l_ms = fresnel_transmittance(cos_o, eta) / PI * MAT.total.rgb * gathered /
                max(weight, vec3(1e-30));
    out_color = vec4(finite_term(MAT.weights.z * l_ms), float(id));
    out_copy = out_color;
}
