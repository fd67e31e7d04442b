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

// Smallest view-space n.z (relative to |n|) a slope is taken from: grazing and back-facing
// normals (normal maps tilt some past the silhouette) are clamped so slopes stay within +-20.
const float LEAN_MIN_NZ = 0.05;

// Slope of a view-space direction (not necessarily unit).
vec2 view_slope(vec3 n_view) {
    float z = max(n_view.z, LEAN_MIN_NZ * length(n_view));
    return n_view.xy / z;
}

// Covariance (xx, yy, xy) of moments `m` about mean `b`: diagonal clamped at 0 and the
// off-diagonal shrunk so the determinant stays >= 0 (rounding and blurring can break both).
vec3 lean_covariance(vec2 b, vec3 m) {
    float xx = max(m.x - b.x * b.x, 0.0);
    float yy = max(m.y - b.y * b.y, 0.0);
    float limit = sqrt(xx * yy);
    return vec3(xx, yy, clamp(m.z - b.x * b.y, -limit, limit));
}

// The LEAN specular lobe for half vector `h_view` (unit, view space): the slope-space Gaussian
// of mean `b` and covariance `c`, turned into a half-vector density (1 / h.z^4), times Schlick's
// Fresnel for `v_dot_h` from normal-incidence reflectance `f0`, times Cook-Torrance's
// shadowing-masking term (without it, grazing views light every silhouette as a rim), over
// 4 n.v (n.v >= 0.1 so silhouettes cannot blow up); the n.l of the microfacet BRDF cancels
// against the irradiance's. The thesis uses F0 = 0.028 (skin); lucent takes the material's
// specular intensity, which the lighting pass's Blinn-Phong lobe scales the same way, and a
// material without specular (f0 = 0) reflects nothing, as in the lighting pass (Schlick's
// grazing term would otherwise add a reflection to a material that declares none). A tiny
// variance floor keeps the determinant > 0 for a perfectly flat, perfectly smooth surface.
float lean_lobe(vec2 b, vec3 c, vec3 h_view, float v_dot_h, float n_dot_v, float n_dot_l,
                float n_dot_h, float f0) {
    c.xy += vec2(1e-5);
    float det = max(c.x * c.y - c.z * c.z, 1e-10);
    float hz = max(h_view.z, LEAN_MIN_NZ);
    vec2 x = h_view.xy / hz - b;
    float e = (x.x * x.x * c.y + x.y * x.y * c.x - 2.0 * x.x * x.y * c.z) / det;
    float density = exp(-0.5 * e) / (2.0 * PI * sqrt(det));
    float f = 1.0 - clamp(v_dot_h, 0.0, 1.0);
    float f2 = f * f;
    float fresnel = f0 > 0.0 ? f0 + (1.0 - f0) * (f2 * f2 * f) : 0.0;
    float vh = max(v_dot_h, 1e-4);
    float g = min(1.0, 2.0 * max(n_dot_h, 0.0) * min(max(n_dot_v, 0.0), max(n_dot_l, 0.0)) / vh);
    return fresnel * g * density / (4.0 * hz * hz * hz * hz * max(n_dot_v, 0.1));
}

// The base variance of the material's own roughness (the thesis adds 1 / (s + 2) for
// specular power s): the Blinn-Phong lobe of the lighting pass, as a slope variance.
float roughness_variance(float roughness) {
    return 1.0 / (shininess(roughness) + 2.0);
}

// A pixel's LEAN data projected to the view plane. `n` is the unit world-space geometric
// normal, `t` and `bt` a world-space tangent frame around it, `b_t` and `m_t` the tangent-space
// slope mean and moments (from the LEAN maps), `base` the roughness variance. Returns the mean
// world normal in `n_world` and writes the view-plane slope mean `b_v` and moments `m_v`.
// Slopes map from tangent plane to view plane non-linearly (u = R (s, 1), s' = u.xy / u.z):
// the covariance is carried through the mapping's Jacobian at the mean.
void view_plane_lean(vec3 n, vec3 t, vec3 bt, vec2 b_t, vec3 m_t, float base,
                     out vec3 n_world, out vec2 b_v, out vec3 m_v) {
    vec3 c_t = lean_covariance(b_t, m_t) + vec3(base, base, 0.0);
    mat3 view = mat3(frame.view);
    vec3 t_v = view * t, bt_v = view * bt, n_v = view * n;
    vec3 u = t_v * b_t.x + bt_v * b_t.y + n_v;
    n_world = normalize(t * b_t.x + bt * b_t.y + n);
    float z = max(u.z, LEAN_MIN_NZ * length(u));
    b_v = u.xy / z;
    // Jacobian columns d(s')/d(s_x), d(s')/d(s_y).
    vec2 j0 = (t_v.xy * z - u.xy * t_v.z) / (z * z);
    vec2 j1 = (bt_v.xy * z - u.xy * bt_v.z) / (z * z);
    mat2 j = mat2(j0, j1);
    mat2 c = j * mat2(c_t.x, c_t.z, c_t.z, c_t.y) * transpose(j);
    m_v = vec3(c[0][0] + b_v.x * b_v.x, c[1][1] + b_v.y * b_v.y, c[1][0] + b_v.x * b_v.y);
    // fp16 targets: moments beyond its range mean a surface seen edge-on; keep them finite.
    m_v = clamp(m_v, vec3(0.0, 0.0, -60000.0), vec3(60000.0));
}

#endif
