// LEAN mapping projected to the view plane (the LEAN-mapping SSS thesis, section 4.3.1), the
// form LCB and LBB blur: a pixel's microfacet slopes are described by their mean `b` (the
// "bump centre") and second moments `m = (E[x^2], E[y^2], E[xy])`, both in slopes of the view
// plane (a normal n has slope n.xy / n.z in view space). Moments, unlike normals, stay exact
// under blurring: a blend of slope distributions has the blend of their moments, so the
// covariance `m - b b^T` after a blur is the spread of everything the blur mixed.
// The f64 twins are src/reference/sss.rs (`view_plane_lean`, `lean_specular`) and
// src/scene/lean.rs (`covariance_of`): change both.
#ifndef LUCENT_LEAN_GLSL
#define LUCENT_LEAN_GLSL

#include "gbuffer.glsl"
#include "lighting.glsl"
#include "host_depth.glsl"
#ifdef LUCENT_SHADOWS
// (A host's shadow map may store reversed Z: its passes define LUCENT_SHADOW_REVERSIBLE,
// shadows.glsl shadow_gather_flagged.)
#include "shadows.glsl"
#endif

// The LEAN texel's functions are lucent::embed::glsl::TERMS' (glsl/embed/lucent_terms.glsl), which
// a host's G-buffer pass calls to write the LEAN targets the blurs read
// (lucent::embed::GBufferDesc::with_lean_targets): one source.
const float LEAN_MIN_NZ = LUCENT_LEAN_MIN_NZ;

vec2 view_slope(vec3 n_view) {
    return lucent_view_slope(n_view);
}

vec3 lean_covariance(vec2 b, vec3 m) {
    return lucent_lean_covariance(b, m);
}

// A covariance held to at least `c_base` (the material's own roughness): a blur mixes slope
// distributions, which only widens them, but fp16 moments at large slopes lose the difference
// m - b b^T to rounding (400 +- 0.25 against a variance of 0.01), and a covariance rounded
// towards 0 is a lobe of unbounded height. Where the determinant falls below the base's, part
// of the base is added back (k = 1 - det / det_base), which keeps the lobe's peak within 1.16x
// of the base lobe's (det(A + B) >= det(A) + det(B) for 2x2 PSD matrices) and leaves every
// covariance above the base unchanged.
vec3 lean_bounded_covariance(vec3 c, vec3 c_base) {
    float det = max(c.x * c.y - c.z * c.z, 0.0);
    float det_base = max(c_base.x * c_base.y - c_base.z * c_base.z, 1e-20);
    float k = clamp(1.0 - det / det_base, 0.0, 1.0);
    return c + k * c_base;
}

// The LEAN specular lobe for half vector `h` (unit, view space), from the view-plane slope
// mean `b` and covariance `c` and the material's base roughness variance `base`.
// The view plane is where LEAN is blurred, but it is the wrong frame to turn slopes into a
// half-vector density: a view-plane slope is measured from the view axis, so at silhouettes
// (mean normal nearly perpendicular to the view) the slope-space Gaussian's conversion 1 /
// h.z^4 divides by the fourth power of a small number and a light behind the object draws a
// rim of fireflies (100x the unblurred frame's brightest pixel on `edges`). So the lobe is
// evaluated in the frame of the mean normal n = normalize(b, 1): the covariance is carried back
// through the inverse of the slope mapping's Jacobian at the mean (the same Jacobian
// view_plane_lean uses to go forward, so for an unblurred pixel this recovers its own
// tangent-space covariance), held to at least the base roughness (lean_bounded_covariance: a
// blur only widens a distribution, rounding can narrow it), and the density is the usual
// microfacet D = p(slope) / (n.h)^4, at most 1.16 / (2 pi base): the unblurred BRDF's own
// peak. Times Schlick's Fresnel for `v_dot_h` from normal-incidence reflectance `f0`, times
// Cook-Torrance's shadowing-masking term, over 4 n.v (n.v >= 0.1); the n.l of the microfacet
// BRDF cancels against the irradiance's. A material without specular (f0 = 0) reflects
// nothing, as in the lighting pass.
float lean_lobe(vec2 b, vec3 c, float base, vec3 h, float v_dot_h, float n_dot_v,
                float n_dot_l, float f0) {
    vec3 n = normalize(vec3(b, 1.0));
    float n_dot_h = dot(n, h);
    if (!(n_dot_h > 0.0)) {
        return 0.0;
    }
    vec3 t, bt;
    lucent_any_tangent_frame(n, t, bt);
    // Jacobian of the view-plane slope with respect to the normal-frame slope, at the mean.
    float z = max(n.z, LEAN_MIN_NZ);
    vec2 j0 = (t.xy * z - n.xy * t.z) / (z * z);
    vec2 j1 = (bt.xy * z - n.xy * bt.z) / (z * z);
    float j_det = j0.x * j1.y - j1.x * j0.y;
    // |det J| >= 1 for unit n (it grows towards silhouettes); guarded all the same.
    mat2 j_inv = mat2(j1.y, -j0.y, -j1.x, j0.x) / (abs(j_det) > 1e-12 ? j_det : 1e-12);
    mat2 c_n = j_inv * mat2(c.x, c.z, c.z, c.y) * transpose(j_inv);
    vec3 cn = lean_bounded_covariance(vec3(c_n[0][0], c_n[1][1], c_n[1][0]),
                                      vec3(base, base, 0.0));
    float det = max(cn.x * cn.y - cn.z * cn.z, 0.75 * base * base);
    vec2 x = vec2(dot(h, t), dot(h, bt)) / n_dot_h;
    float e = (x.x * x.x * cn.y + x.y * x.y * cn.x - 2.0 * x.x * x.y * cn.z) / det;
    float nh2 = n_dot_h * n_dot_h;
    float density = exp(-0.5 * e) / (2.0 * PI * sqrt(det) * nh2 * nh2);
    float f = 1.0 - clamp(v_dot_h, 0.0, 1.0);
    float f2 = f * f;
    float fresnel = f0 > 0.0 ? f0 + (1.0 - f0) * (f2 * f2 * f) : 0.0;
    float vh = max(v_dot_h, 1e-4);
    float g = min(1.0, 2.0 * n_dot_h * min(max(n_dot_v, 0.0), max(n_dot_l, 0.0)) / vh);
    return fresnel * g * density / (4.0 * max(n_dot_v, 0.1));
}

// The base variance of the material's own roughness: the Blinn-Phong lobe of the lighting
// pass, as a slope variance (lucent_roughness_variance).
float roughness_variance(float roughness) {
    return lucent_roughness_variance(roughness);
}

// Slopes further apart than this (normals about 45 degrees apart and more) are a crease (a face
// seen edge-on beside one seen face-on: the `edges` slab's side, slope -3.2, beside its front,
// 0.3), not a distribution to blend: the blurs keep such taps out of the LEAN moments, as depth
// edges are kept out of the light. A normal map's bumps vary the slope by a few tenths.
const float LEAN_CREASE = 1.0;

// How much of a tap's LEAN texel (slope mean `b`, moments `m`) to replace by the centre's: 0
// within a smooth surface, 1 across a crease, where the slope means are LEAN_CREASE to twice it
// apart. `filtered`: the tap is bilinear (LCB), and one that straddles the crease mixes both
// faces' slopes into a mean that looks smooth, but not into a narrow spread (30% of the slab's
// side in a tap is a slope variance of 2.6): a tap whose spread exceeds the centre's by as much
// counts as a crease too. Point taps (LBB) mix nothing, and a one-sided spread test would only
// bias their covariance low.
float lean_crease(vec2 b_tap, vec3 m_tap, vec2 b_center, vec3 m_center, bool filtered) {
    // View-plane slopes stretch as 1 / n.z^2 towards silhouettes: so does the threshold, or a
    // normal map's bumps near a silhouette would count as creases.
    float z = 1.0 / sqrt(1.0 + dot(b_center, b_center));
    float crease = LEAN_CREASE / max(z * z, 0.05);
    float apart = smoothstep(crease, 2.0 * crease, length(b_tap - b_center));
    if (!filtered) {
        return apart;
    }
    float spread_tap = m_tap.x - b_tap.x * b_tap.x + m_tap.y - b_tap.y * b_tap.y;
    float spread_center = m_center.x - b_center.x * b_center.x + m_center.y -
                          b_center.y * b_center.y;
    float spread = smoothstep(0.25 * crease * crease, crease * crease,
                              spread_tap - spread_center);
    return max(apart, spread);
}

// A pixel's LEAN data projected to this frame's view plane (lucent_view_plane_lean: `n` the
// unit world normal, `t` and `bt` a tangent frame, `b_t` and `m_t` the tangent-space slope
// mean and moments, `base` the roughness variance).
void view_plane_lean(vec3 n, vec3 t, vec3 bt, vec2 b_t, vec3 m_t, float base,
                     out vec3 n_world, out vec2 b_v, out vec3 m_v) {
    lucent_view_plane_lean(mat3(frame.view), n, t, bt, b_t, m_t, base, n_world, b_v, m_v);
}

// The final lighting's LEAN specular at window position `frag_coord` (device depth `d`), for
// every light, from the (blurred) view-plane slope mean `b` and moments `m`, the material's
// `roughness` and specular intensity `ks`. The lobe is never sharper than the roughness allows
// (lean_lobe), and never brighter than the unblurred BRDF's own maximum: the lighting pass's
// normalised Blinn-Phong peak ks (s + 8) / (8 pi), which it reaches with n.h = n.l = 1. The
// microfacet lobe's Fresnel and 1 / n.v would otherwise light silhouettes facing away from a
// back light as a rim the frame without SSS never has. The f64 twin is
// src/reference/sss.rs `lean_specular`.
vec3 lean_final_specular(vec2 frag_coord, float d, vec2 b, vec3 m, float roughness, float ks) {
    vec3 c = lean_covariance(b, m);
    float base = roughness_variance(roughness);
    float peak = ks * (shininess(roughness) + 8.0) / (8.0 * PI);
    mat3 view = mat3(frame.view);
    // A device depth of any projection (lucent's own, a host's standard, reversed or
    // infinite) unprojects through the frame's inverse view-projection; a host's linear view
    // depth (HOST_DEPTH_LINEAR, a constant of the pipeline: false for lucent's own frames)
    // cannot be, and the point on the pixel's ray at its view depth (host_depth.glsl) is
    // brought back to the world through the view matrix inverted as the rotation and
    // translation it is. (That path for every encoding made the final lighting 1.04-1.08x
    // lucent's own pass.)
    vec3 pos = HOST_DEPTH_LINEAR
                   ? transpose(view) * (view_point_at_depth(frag_coord, linear_depth(d)) -
                                        frame.view[3].xyz)
                   : world_position(frag_coord, d);
    vec3 to_eye = view * normalize(frame.camera_pos.xyz - pos);
    vec3 n = normalize(vec3(b, 1.0));
    float n_dot_v = dot(n, to_eye);
    vec3 specular = vec3(0.0);
    int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
#ifdef LUCENT_SHADOWS
        // The light-space maps shadow the LEAN specular as the lighting pass's (the view
        // matrix is a rotation: its transpose takes the mean normal back to world space).
        attenuation *= shadow_visibility(i, pos, transpose(view) * n, to_light, 0).x;
#endif
        vec3 l = view * to_light;
        vec3 h = l + to_eye;
        float h_len2 = dot(h, h);
        // Light exactly behind the surface point as seen from the eye: no half vector.
        float n_dot_l = dot(n, l);
        if (!(h_len2 > 1e-12) || n_dot_l <= 0.0) {
            continue;
        }
        h *= inversesqrt(h_len2);
        float lobe = min(lean_lobe(b, c, base, h, dot(to_eye, h), n_dot_v, n_dot_l, ks), peak);
        specular += lobe * light.radiance_range.rgb * attenuation;
    }
    return specular;
}

#endif
