// lucent's per-pixel lighting terms for a host's own lighting pass (lucent::embed::glsl::TERMS):
// self-contained GLSL (no bindings, no includes) a host includes in the shader that loops over
// its lights, so the terms cost what they cost in lucent's own lighting pass, which calls the
// same functions (glsl/common/scene.glsl, glsl/common/translucency.glsl,
// glsl/common/sss_transmission.glsl). The data comes from the Rust side: an environment's nine
// coefficients (`Environment::coefficients`), a translucent material's row
// (`TranslucentMaterial::row`), each light's translucency scale (`Light::translucency_scale`),
// a transmitting material's medium rows (`TransmissionMaterial::rows`). The LEAN texel's
// functions at the end are for a host's G-buffer pass (`GBufferDesc::with_lean_targets`).
// The f64 twins are src/scene/environment.rs (`Environment::ambient_radiance`),
// src/reference/translucency.rs and src/scene/transmittance.rs: change them together.
#ifndef LUCENT_TERMS_GLSL
#define LUCENT_TERMS_GLSL

// The SH environment's diffuse light at unit normal `n`: E(n) / pi, the radiance a Lambertian
// albedo multiplies (src/scene/environment.rs: nine SH coefficients with the clamped cosine
// convolved in and the basis constants folded in). `sh[k].rgb` multiplies basis term k (1, y,
// z, x, xy, yz, 3z^2 - 1, xz, x^2 - y^2); `sh[0].w` is the bands in use (1 constant, 2
// hemisphere, 3 map), so only those are evaluated (a uniform branch). Clamped at 0: the series
// of a map with a small bright sun rings below zero opposite it, and irradiance cannot be
// negative.
vec3 lucent_sh_ambient(vec4 sh[9], vec3 n) {
    vec3 e = sh[0].rgb;
    float bands = sh[0].w;
    if (bands > 1.5) {
        e += sh[1].rgb * n.y + sh[2].rgb * n.z + sh[3].rgb * n.x;
    }
    if (bands > 2.5) {
        e += sh[4].rgb * (n.x * n.y) + sh[5].rgb * (n.y * n.z)
           + sh[6].rgb * (3.0 * n.z * n.z - 1.0)
           + sh[7].rgb * (n.x * n.z)
           + sh[8].rgb * (n.x * n.x - n.y * n.y);
    }
    return max(e, vec3(0.0));
}

// GDC 2011's view-dependent lobe x^n for x in [0, 1], n >= 0, in the form `mode` says: 0 the
// exact pow, 1 the spherical-Gaussian exp2(n x - n) (a row's w; lucent's own rows add 2 when
// other objects' shadows fall on the material's transmitted light, which is skipped here).
// pow(0, 0) is undefined in GLSL (and pow(x, y) for x <= 0 in general): the base is clamped to
// a tiny positive value, so n = 0 gives exactly 1 and large n underflow to 0 instead of NaN;
// exp2(n (x - 1)) <= 1 cannot overflow. A shader that defines LUCENT_POW_MODES (1 exact, 2
// exp2, 3 both) compiles only those forms (a SIMD CPU driver evaluates both sides of a
// branch); otherwise the form is chosen per material.
float lucent_translucency_lobe(float x, float n, float mode) {
    x = clamp(x, 0.0, 1.0);
    mode = mode >= 2.0 ? mode - 2.0 : mode;
#if defined(LUCENT_POW_MODES) && LUCENT_POW_MODES == 1
    return pow(max(x, 1e-30), n);
#elif defined(LUCENT_POW_MODES) && LUCENT_POW_MODES == 2
    return exp2(n * (x - 1.0));
#else
    // Both forms are exp2 of n times an exponent: choose the exponent, not the function.
    float e = mode == 1.0 ? x - 1.0 : log2(max(x, 1e-30));
    return exp2(n * e);
#endif
}

// GDC 2011's translucency from one light (Barre-Brisebois and Bouchard, Frostbite 2), the
// light let through to the eye:
//   vLTLight = L + N * distortion
//   dot = pow(saturate(dot(V, -vLTLight)), power) * scale
//   lt = attenuation * (dot + ambient) * thickness
//   colour += albedo * lightColour * lt
// `material`: the row (x power, y distortion, z ambient, w pow form); `thickness`: the local
// thickness (0 opaque to 1 thin, tinted where the material has a colour); `to_eye`, `to_light`
// unit vectors from the surface; `v_dot_n` = dot(to_eye, n) (the same for every light:
// dot(V, -(L + N d)) = -(dot(V, L) + d dot(V, N)), so the distorted vector is never built);
// `radiance` the light's colour times intensity; `attenuation` its falloff at the surface;
// `translucency_scale` its fLTScale. The talk's term is unshadowed: its only attenuation is
// the local thickness.
vec3 lucent_translucency(vec3 albedo, vec3 thickness, vec4 material, vec3 to_eye, float v_dot_n,
                         vec3 to_light, vec3 radiance, float attenuation,
                         float translucency_scale) {
    float back = -(dot(to_eye, to_light) + material.y * v_dot_n);
    float lobe = lucent_translucency_lobe(back, material.x, material.w) * translucency_scale;
    return albedo * (lobe + material.z) * thickness * radiance * attenuation;
}

// Diffusion through a thickness: Jensen's dipole (2001) and Donner and Jensen's multipole
// (2005), shared by Li et al.'s layered passes (glsl/common/layered.glsl `dipole_beyond`) and
// screen-space SSS's diffuse transmission (glsl/common/sss_transmission.glsl and a host's
// lighting, below). The f64 twins are src/scene/transmittance.rs (`beyond_sum`,
// `multipole_sum`; `Dipole::transmitted_beyond` in src/reference/dipole.rs): change both together.

// Sum over the real (depth z_r) and virtual (height z_v) sources of z e^(-sigma_tr d) / d,
// d = sqrt(a^2 + z^2), per channel: the light that diffuses out farther than `a` from its
// entry is (alpha' / 2) times this. Every length in one unit (a >= 0). d >= z > 0 (z_r is
// 1 / sigma_t' with sigma_t' held above 1e-12 where the constants are made, so z^2 <= 1e24 and
// z_v^2 < 1e31: no f32 overflow), so z / d <= 1; e^-x of a large x is 0: finite for every
// finite a, and exactly sum(e^(-sigma_tr z)) at a = 0.
vec3 lucent_dipole_beyond_sum(vec3 sigma_tr, vec3 z_r, vec3 z_v, float a) {
    float a2 = a * a;
    vec3 dr = sqrt(a2 + z_r * z_r);
    vec3 dv = sqrt(a2 + z_v * z_v);
    return z_r / dr * exp(-sigma_tr * dr) + z_v / dv * exp(-sigma_tr * dv);
}

// e^x - 1 for x <= 0 without the cancellation of exp(x) - 1 near 0 (|x| < 1e-3: three
// Taylor terms).
vec3 lucent_expm1(vec3 x) {
    return mix(exp(x) - 1.0, x * (1.0 + x * (0.5 + x / 6.0)), lessThan(abs(x), vec3(1e-3)));
}

// One row of the multipole's sources, summed over every image: sum over i of
// sign(x - i P) e^(-sigma |x - i P|) for |x| < P, in closed form (two geometric series):
// sign(x) e^(-sigma |x|) (1 - e^(-sigma (P - 2|x|))) / (1 - e^(-sigma P)), written with expm1 so
// a weak absorber does not cancel, and its limit (P - 2|x|) / P where sigma P -> 0.
vec3 lucent_multipole_row(vec3 sigma, vec3 x, vec3 period) {
    vec3 ax = min(abs(x), period);
    vec3 weak = (period - 2.0 * ax) / period;
    vec3 strong = lucent_expm1(-sigma * (period - 2.0 * ax)) /
                  min(lucent_expm1(-sigma * period), vec3(-1e-30));
    vec3 ratio = mix(strong, weak, lessThan(sigma * period, vec3(1e-6)));
    return sign(x) * exp(-sigma * ax) * ratio;
}

// Donner and Jensen's (2005) multipole through a slab of thickness `a`: the dipole mirrored
// about both faces (extrapolated boundaries z_b = (z_v - z_r) / 2 beyond each), real sources
// at i P + z_r and virtual ones at i P - z_r - 2 z_b, P = 2 (a + 2 z_b), every integer i. Its
// transmission profile integrated over the far face is (alpha' / 2) times the sum over the
// real sources of sign(a - z) e^(-sigma_tr |a - z|) less the same over the virtual ones
// (2 pi ∫ h (1 + sigma d) e^(-sigma d) / d^3 r dr = sign(h) e^(-sigma |h|), d^2 = r^2 + h^2),
// summed over every i in closed form (lucent_multipole_row; |a - z_r| and a + z_r + 2 z_b are both
// below P since 2 z_b > z_r). A clear slab gets diffusion's 2 (z_r + z_b) / (a + 2 z_b).
// Diffusion through a slab is only valid when the slab holds the real source (a > z_r):
// thinner, the sum goes negative, so lucent_sss_transmittance never takes less than the semi-infinite
// dipole's light beyond a (lucent_dipole_beyond_sum). Finite: each row is at most 1 in size.
vec3 lucent_multipole_slab_sum(vec3 sigma_tr, vec3 z_r, vec3 z_v, float a) {
    vec3 boundaries = z_v - z_r; // 2 z_b
    vec3 period = 2.0 * (a + boundaries);
    return lucent_multipole_row(sigma_tr, a - z_r, period) -
           lucent_multipole_row(sigma_tr, a + z_r + boundaries, period);
}

// A medium's diffuse transmittance through `thickness` (scene units) relative to its albedo
// A: the light Donner and Jensen's multipole lets through a slab of that thickness, never less
// than the light the semi-infinite dipole diffuses farther than the thickness from its entry
// (it takes over where a slab thinner than a mean free path leaves the multipole invalid),
// over A; times the albedo where the diffuse light has it, it is the model's light through the
// slab. `medium` is the material's four rows (lucent::embed::TransmissionMaterial::rows, or
// lucent's SSS profile table): sigma_tr (w: millimetres per scene unit), z_r, z_v (mm), and
// (alpha' / 2) / A; the w of the last three is the most each channel lets through (1 / A, at
// most 1000). Held in [0, that]: a slab lets through at most all the light. The f64 twin is
// src/scene/transmittance.rs `transmittance_over_albedo`.
vec3 lucent_sss_transmittance(vec4 medium[4], float thickness) {
    vec3 most = vec3(medium[1].w, medium[2].w, medium[3].w);
    // Millimetres; held below 1e18 so a^2 stays finite in f32 (the map's far plane is nearer).
    float a_mm = clamp(thickness * medium[0].w, 0.0, 1e18);
    vec3 through = max(lucent_dipole_beyond_sum(medium[0].rgb, medium[1].rgb, medium[2].rgb, a_mm),
                       lucent_multipole_slab_sum(medium[0].rgb, medium[1].rgb, medium[2].rgb, a_mm));
    return clamp(medium[3].rgb * through, vec3(0.0), most);
}

// One light's diffuse transmission through an object to a surface point (HDRP's "thick" mode,
// what lucent's TransmissionEffect and its own lighting add): the light that reached the
// object's far side at its entry point (`light_at_entry`: the light's radiance times its
// falloff there; unshadowed, the entry point is where the light comes in), diffused through
// `thickness` (the distance from the entry point to the shaded point, scene units), times the
// back-facing cosine max(-dot(normal, to_light), 0) (`to_light` unit, from the point). The
// result is light before the albedo and 1 / pi, as a Lambert term's irradiance: multiply by
// albedo / pi where the host's diffuse light has its albedo. The thickness comes from the
// host's shadow map of the light: lucent's recipe (`lucent_shadow_texels` below, which
// glsl/common/sss_transmission.glsl `sss_transmitted` follows on lucent's own maps) looks up
// the map from the point moved one map texel inside along -normal, reads the four texels
// around it, and sums this term over them with their bilinear weights (the transmittance is
// filtered, not the distance, which would leave a staircase).
vec3 lucent_sss_transmitted(vec4 medium[4], vec3 normal, vec3 to_light, float thickness,
                            vec3 light_at_entry) {
    float back = -dot(normal, to_light);
    if (!(back > 0.0)) {
        return vec3(0.0);
    }
    return back * light_at_entry * lucent_sss_transmittance(medium, thickness);
}

// A face of a shadow map, as lucent reads one (lucent::embed::ShadowFace::terms_rows, the
// same rows lucent's own shadow table holds, glsl/common/shadows.glsl): `view_proj` world to
// the face's clip space (standard Z: depth 0 near, 1 far); `rect` xy its corner in the map and
// z its edge (texels), w 1 when the map stores reversed Z (plus 2 x its layer in an array
// map); `params` x * clip.w + y a map texel's world size at a point, z the near plane
// (negative: orthographic), w the far plane.

// The standard-Z depths of texels `d` stored in the face's map: a reversed-Z map (rect.w odd)
// stores 1 - d, exactly the standard depth of the same planes (its face's view_proj is the
// projection with z flipped).
vec4 lucent_stored_depth(vec4 rect, vec4 d) {
    return mod(rect.w, 2.0) > 0.5 ? 1.0 - d : d;
}

// Distance from the face's eye along its axis (world units) of a standard-Z depth `d`.
float lucent_face_distance(vec4 params, float d) {
    float near = abs(params.z), far = params.w;
    if (params.z < 0.0) {
        return near + d * (far - near); // orthographic: linear
    }
    // Perspective: depth 1 is the far plane; the max keeps d = 1 from dividing by zero.
    return near * far / max(far - d * (far - near), 1e-12);
}

// A map texel's world size at `p`: how far a lookup moves to step one texel.
float lucent_map_texel_size(mat4 view_proj, vec4 params, vec3 p) {
    vec4 clip = view_proj * vec4(p, 1.0);
    return params.x * abs(clip.w) + params.y;
}

// Where `p` falls in the face's map: its map position `t` in texels (texel k's centre at
// k + 0.5) and its distance along the face's axis; false outside the face's cone (w <= 0
// would divide by zero) or map.
bool lucent_map_position(mat4 view_proj, vec4 rect, vec4 params, vec3 p, out vec2 t,
                         out float distance) {
    vec4 clip = view_proj * vec4(p, 1.0);
    vec3 ndc = clip.xyz / clip.w;
    if (!(clip.w > 0.0 && all(lessThanEqual(abs(ndc.xy), vec2(1.0))) && ndc.z >= 0.0 &&
          ndc.z <= 1.0)) {
        t = vec2(0.0);
        distance = 0.0;
        return false;
    }
    t = rect.xy + (ndc.xy * 0.5 + 0.5) * rect.z;
    distance = lucent_face_distance(params, ndc.z);
    return true;
}

// The 2x2 texels of the face's tile whose centres surround map position `t` (kept inside the
// tile): the textureGather coordinate that returns them (`inv_map_size`: 1 / the map's size)
// and their bilinear weights, in gather order (x0 y1, x1 y1, x1 y0, x0 y0).
void lucent_map_bilinear(vec4 rect, vec2 inv_map_size, vec2 t, out vec2 corner,
                         out vec4 weights) {
    vec2 c = clamp(t - 0.5, rect.xy, rect.xy + rect.z - 1.001);
    vec2 base = floor(c);
    corner = (base + 1.0) * inv_map_size;
    vec2 f = c - base;
    weights = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
}

// Where the light's ray to `p` (at distance `d_p` along the face's axis) meets a surface the
// map holds at distance `d_map`: along the light's direction `to_light` on an orthographic
// (directional) face; on a perspective one, on the ray from the light at `light_position`,
// where axial distances scale with the distance from it (d_p > 0 there; the max guards a
// point on the light's eye). A point nearer than the surface is its own entry point.
vec3 lucent_map_entry_point(vec4 params, vec3 light_position, vec3 p, vec3 to_light, float d_p,
                            float d_map) {
    if (params.z < 0.0) {
        return p + to_light * max(d_p - d_map, 0.0);
    }
    return light_position + (p - light_position) * min(d_map / max(d_p, 1e-12), 1.0);
}

// lucent_shadow_texels' lookup before the map's read: `pos` moved one map texel inside
// (`inner`, at `inner_distance`), the gather coordinate of the four texels around it in a map
// of `map_size` texels and their bilinear weights; false where the face does not see it.
bool lucent_shadow_corner(mat4 view_proj, vec4 rect, vec4 params, vec2 map_size, vec3 pos,
                          vec3 normal, out vec3 inner, out float inner_distance,
                          out vec2 corner, out vec4 weights) {
    inner = pos - normal * lucent_map_texel_size(view_proj, params, pos);
    corner = vec2(0.0);
    weights = vec4(0.0);
    vec2 t;
    if (!lucent_map_position(view_proj, rect, params, inner, t, inner_distance)) {
        return false;
    }
    lucent_map_bilinear(rect, 1.0 / map_size, t, corner, weights);
    return true;
}

// And after it: the four texels' stored depths `stored` as distances along the face's axis,
// the weight of a texel holding the far plane (nothing between the light and it) zeroed.
void lucent_texel_distances(vec4 rect, vec4 params, vec4 stored, inout vec4 weights,
                            out vec4 texel_distances) {
    vec4 d = lucent_stored_depth(rect, stored);
    weights *= vec4(lessThan(d, vec4(1.0)));
    texel_distances = vec4(lucent_face_distance(params, d.x), lucent_face_distance(params, d.y),
                           lucent_face_distance(params, d.z), lucent_face_distance(params, d.w));
}

// lucent's recipe for the thickness a shadow map measures, which SSS transmission diffuses
// through: from `pos` (outward normal `normal`) moved one map texel inside (`inner`, at
// `inner_distance` along the face's axis), the four texels of the face's map around it, the
// distance along the axis each holds (`texel_distances`) and their bilinear weights
// (`weights`; 0 where a texel holds the far plane: nothing there). False where the face does
// not see the point (nothing measures the thickness). For each texel k with a weight, the
// light enters the object at lucent_map_entry_point(params, light_position, inner, to_light,
// inner_distance, texel_distances[k]); a host sums weights[k] * lucent_sss_transmitted(medium,
// normal, to_light, length(entry - pos), its light's radiance and falloff at the entry), as
// lucent does. The entries are made one at a time in that loop: returning all four (twelve
// values held per pixel where the distances are four) made examples/host_engine.rs's whole
// lighting pass 1.25x on llvmpipe.
bool lucent_shadow_texels(sampler2D map, mat4 view_proj, vec4 rect, vec4 params, vec3 pos,
                          vec3 normal, out vec3 inner, out float inner_distance,
                          out vec4 texel_distances, out vec4 weights) {
    vec2 corner;
    if (!lucent_shadow_corner(view_proj, rect, params, vec2(textureSize(map, 0)), pos, normal,
                              inner, inner_distance, corner, weights)) {
        texel_distances = vec4(0.0);
        return false;
    }
    lucent_texel_distances(rect, params, textureGather(map, corner, 0), weights,
                           texel_distances);
    return true;
}

// The same for a face in a layer of an array map (cascades, a cube's faces: `map` a 2-D array
// view; the layer is in the face's rect.w, ShadowFace::terms_rows).
bool lucent_shadow_texels(sampler2DArray map, mat4 view_proj, vec4 rect, vec4 params,
                          vec3 pos, vec3 normal, out vec3 inner, out float inner_distance,
                          out vec4 texel_distances, out vec4 weights) {
    vec2 corner;
    if (!lucent_shadow_corner(view_proj, rect, params, vec2(textureSize(map, 0).xy), pos,
                              normal, inner, inner_distance, corner, weights)) {
        texel_distances = vec4(0.0);
        return false;
    }
    float layer = floor(rect.w * 0.5);
    lucent_texel_distances(rect, params, textureGather(map, vec3(corner, layer), 0), weights,
                           texel_distances);
    return true;
}

// ---- LEAN texels: what LCB, LBB and the bilateral blur read of a G-buffer ----
// A host whose G-buffer pass writes LEAN targets (lucent::embed::GBufferDesc::with_lean_targets)
// writes, per pixel, what lucent's own G-buffer and lighting passes write (glsl/common/lean.glsl,
// glsl/deferred/gbuffer.frag and lighting.frag call these functions):
// - the moments target: vec4(b_v.y, m_v) from lucent_view_plane_lean;
// - the albedo target: vec4(albedo, specular intensity);
// - the normal target: vec4(n_world, roughness);
// - its lit diffuse's alpha: lucent_view_slope(view * n_world).x.
// The view-plane slope mean `b_v` and second moments `m_v` are the LEAN-mapping SSS thesis's
// (section 4.3.1); the f64 twins are src/reference/sss.rs (`view_plane_lean`) and
// src/scene/lean.rs (`covariance_of`): change them together.

// Smallest view-space n.z (relative to |n|) a slope is taken from: grazing and back-facing
// normals (normal maps tilt some past the silhouette) are clamped so slopes stay within +-20.
const float LUCENT_LEAN_MIN_NZ = 0.05;

// The Blinn-Phong exponent of a roughness: 2^(11 - 10 r), in [2, 2048].
float lucent_shininess(float roughness) {
    return exp2(11.0 - 10.0 * clamp(roughness, 0.0, 1.0));
}

// The slope variance of a roughness's own lobe (the thesis adds 1 / (s + 2) for specular
// power s): what lucent_view_plane_lean's `base` takes.
float lucent_roughness_variance(float roughness) {
    return 1.0 / (lucent_shininess(roughness) + 2.0);
}

// Slope of a view-space direction (not necessarily unit).
vec2 lucent_view_slope(vec3 n_view) {
    float z = max(n_view.z, LUCENT_LEAN_MIN_NZ * length(n_view));
    return n_view.xy / z;
}

// Covariance (xx, yy, xy) of moments `m` about mean `b`: diagonal clamped at 0 and the
// off-diagonal shrunk so the determinant stays >= 0 (rounding and blurring can break both).
vec3 lucent_lean_covariance(vec2 b, vec3 m) {
    float xx = max(m.x - b.x * b.x, 0.0);
    float yy = max(m.y - b.y * b.y, 0.0);
    float limit = sqrt(xx * yy);
    return vec3(xx, yy, clamp(m.z - b.x * b.y, -limit, limit));
}

// A right-handed unit tangent frame (`t`, `bt`, `n`) around the unit normal `n`, any one: for
// a surface without a LEAN or normal map (its slopes are 0 and its roughness isotropic, so the
// frame's turn about `n` changes nothing), and wherever a frame is only a basis to work in.
void lucent_any_tangent_frame(vec3 n, out vec3 t, out vec3 bt) {
    vec3 helper = abs(n.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    t = normalize(cross(helper, n));
    bt = cross(n, t);
}

// A pixel's LEAN data projected to the view plane. `view` is the world-to-view rotation
// (mat3 of the view matrix), `n` the unit world-space geometric normal, `t` and `bt` a
// world-space tangent frame around it (lucent_any_tangent_frame when there is no LEAN or normal
// map: the slopes are then 0), `b_t` and `m_t` the tangent-space slope mean and moments (from LEAN
// maps; 0 without), `base` the roughness variance (lucent_roughness_variance). Returns the
// mean world normal in `n_world` and writes the view-plane slope mean `b_v` and moments `m_v`.
// Slopes map from tangent plane to view plane non-linearly (u = R (s, 1), s' = u.xy / u.z):
// the covariance is carried through the mapping's Jacobian at the mean.
void lucent_view_plane_lean(mat3 view, vec3 n, vec3 t, vec3 bt, vec2 b_t, vec3 m_t,
                            float base, out vec3 n_world, out vec2 b_v, out vec3 m_v) {
    vec3 c_t = lucent_lean_covariance(b_t, m_t) + vec3(base, base, 0.0);
    vec3 t_v = view * t, bt_v = view * bt, n_v = view * n;
    vec3 u = t_v * b_t.x + bt_v * b_t.y + n_v;
    n_world = normalize(t * b_t.x + bt * b_t.y + n);
    float z = max(u.z, LUCENT_LEAN_MIN_NZ * length(u));
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

// Li et al.'s `TexDep` texels, packed as lucent reads them from a G-buffer texel
// (`GBufferDesc::with_layer_depths`), for a host's G-buffer pass: `first` is the mesh's depth
// texture 0 sampled at the pixel (layers 0-3 in r, g, b, a), `second` texture 1 (layers 4-7;
// vec4(0) without one); two fp16 texels per 32-bit component, layer 2k in the low half of
// component k. Write `.xy` to an R32G32_UINT target (one texture), all four to an
// R32G32B32A32_UINT one. A texel as the f64 reference reads it (LayeredMedium::thickness_mm):
// NaN, infinite and negative read 0 (a texture is data from a file), and fp16's largest finite
// value bounds it, so packing never makes an infinity.
vec4 lucent_sanitize_layer_texels(vec4 t) {
    bvec4 bad = bvec4(isnan(t.x) || isinf(t.x), isnan(t.y) || isinf(t.y),
                      isnan(t.z) || isinf(t.z), isnan(t.w) || isinf(t.w));
    return clamp(mix(t, vec4(0.0), bad), vec4(0.0), vec4(65504.0));
}

uvec4 lucent_pack_layer_texels(vec4 first, vec4 second) {
    first = lucent_sanitize_layer_texels(first);
    second = lucent_sanitize_layer_texels(second);
    return uvec4(packHalf2x16(first.xy), packHalf2x16(first.zw), packHalf2x16(second.xy),
                 packHalf2x16(second.zw));
}

#endif
