#version 450
// permutation: LUCENT_ENTRY LUCENT_SHADOWS
// permutation: LUCENT_LAYER_DEPTHS=1
// permutation: LUCENT_HALF_TERM
// permutation: LUCENT_HALF_TERM LUCENT_FULL_RES_TERM
// permutation: LUCENT_HALF_TERM LUCENT_LAYERED_FILM
// permutation: LUCENT_LAYER_DEPTHS=2 LUCENT_ENTRY LUCENT_ENTRY_DEPTHS LUCENT_SHADOWS
// Li et al.'s single scattering (eqs. 4-11) and the transmitted term L_t, added into the lit
// image (src/features/layered.rs, `single scattering`), weighted by eq. 3's λ4 and λ3.
// Set 0 as glsl/common/layered.glsl, then (media with TexDep layers) the G-buffer's layer
// depth texels, then (lights with maps) the entry atlas, its layer depth texels (with TexDep)
// and the shadow bindings; the multiple-scattering term (LUCENT_HALF_TERM), which this
// pass resolves over 3x3 pixels (LUCENT_FULL_RES_TERM) or, with `--half-gather`, upsamples,
// and adds. With LUCENT_LAYERED_FILM (a layered material has an albedo texture) the sum is
// multiplied by the texel the G-buffer stored beside the material ID.
#include "../common/layered.glsl"
#ifdef LUCENT_HALF_TERM
#include "../common/layered_upsample.glsl"
#endif

#ifdef LUCENT_LAYER_DEPTHS
// Per pixel: the depth-texture texels at x_o (layer_depths.glsl).
layout(set = 0) uniform usampler2D gbuffer_layer_depths;
#endif

#if defined(LUCENT_LAYERED_FILM) && defined(LUCENT_HOST_FILM)
// A host's film: its albedo image (src/embed/layered.rs `LayeredEffectDesc::with_film`).
layout(set = 0) uniform sampler2D host_film;
#endif

#ifdef LUCENT_ENTRY
// Per map texel: the first surface's normal * 0.5 + 0.5 and its layered material ID / 255.
layout(set = 0) uniform sampler2D shadow_entry;
#if defined(LUCENT_LAYER_DEPTHS) && defined(LUCENT_ENTRY_DEPTHS)
// Per map texel: the depth-texture texels at the first surface (where light enters).
layout(set = 0) uniform usampler2D shadow_layer_depths;
#endif
#endif

// The depth texels of light-space texel `texel` (the entry surface's TexDep layers).
uvec4 entry_texels(ivec2 texel, uvec4 fallback) {
#if defined(LUCENT_ENTRY) && defined(LUCENT_LAYER_DEPTHS) && defined(LUCENT_ENTRY_DEPTHS)
    return texelFetch(shadow_layer_depths, texel, 0);
#else
    return fallback;
#endif
}

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// The entry point where the surface at the shaded point (x_o, n_o, depth texels texels_o)
// is taken as a plane: false when the light is below it.
bool light_entry_plane(vec3 m, vec3 to_light, vec3 x_o, vec3 n_o, uvec4 texels_o,
                       out vec3 p_in, out vec3 n_in, out uvec4 texels_in) {
    n_in = n_o;
    texels_in = texels_o;
    float c = dot(to_light, n_o);
    p_in = m;
    if (c <= 1e-4) {
        return false;
    }
    p_in = m + to_light * (max(dot(x_o - m, n_o), 0.0) / c);
    return true;
}

// Where light `i` reaching `m` (inside material `id`, towards the light `to_light`) entered
// the object, with the outward normal and the depth texels there. From the light's map when
// it has one: the map's first surface on the line through m (its distance, normal, material
// and texels); false when that surface is of another material (the light is blocked before it
// reaches this object). A light without a map (or a point outside it) takes the tangent plane
// at the shaded point as the surface (light_entry_plane).
bool light_entry(int i, vec3 m, vec3 to_light, int id, vec3 x_o, vec3 n_o, uvec4 texels_o,
                 out vec3 p_in, out vec3 n_in, out uvec4 texels_in) {
#ifdef LUCENT_ENTRY
    int face = shadow_face(i, m);
    vec2 t;
    float d_m;
    if (face >= 0 && map_position(face, m, t, d_m)) {
        ivec2 texel = map_texel(face, t);
        vec4 entry = texelFetch(shadow_entry, texel, 0);
        // The entry distance, interpolated bilinearly between the four texel centres around t
        // where all four are this material's surface (a nearest texel's staircase is a tenth
        // of a millimetre at 512^2, as thick as a skin layer); else the nearest texel's. The
        // entry target is not cleared: a texel no surface was drawn into (depth 1) has no
        // entry data.
        vec2 corner;
        vec4 w;
        map_bilinear(face, t, corner, w);
        vec4 d = textureGather(shadow_depth, corner, 0);
        vec4 ids = textureGather(shadow_entry, corner, 3) * 255.0;
        vec4 params = shadows.faces[face].params;
        float d_map;
        if (all(lessThan(abs(ids - float(id)), vec4(0.5))) && all(lessThan(d, vec4(1.0)))) {
            d_map = dot(w, vec4(shadow_distance(params, d.x), shadow_distance(params, d.y),
                                shadow_distance(params, d.z), shadow_distance(params, d.w)));
            // The normal too, with the same weights: the nearest texel's changed at every
            // texel edge, a staircase in the Fresnel transmittance into the medium (issue 25:
            // part of the structure the grain metric counted).
            entry.xyz = vec3(dot(w, textureGather(shadow_entry, corner, 0)),
                             dot(w, textureGather(shadow_entry, corner, 1)),
                             dot(w, textureGather(shadow_entry, corner, 2)));
        } else {
            float raw = texelFetch(shadow_depth, texel, 0).r;
            if (raw >= 1.0) {
                return light_entry_plane(m, to_light, x_o, n_o, texels_o, p_in, n_in,
                                         texels_in);
            }
            if (int(entry.a * 255.0 + 0.5) != id) {
                texels_in = texels_o;
                return false; // another material's surface is first: blocked
            }
            d_map = shadow_distance(params, raw);
        }
        p_in = map_entry_point(face, i, m, to_light, d_m, d_map);
        n_in = sanitize_normal(entry.xyz * 2.0 - 1.0);
        texels_in = entry_texels(texel, texels_o);
        return true;
    }
#endif
    return light_entry_plane(m, to_light, x_o, n_o, texels_o, p_in, n_in, texels_in);
}

// Radiance a light delivers into the medium at entry point p_in (normal n_in, light arriving
// along -to_light): radiance x falloff x Fresnel transmittance (0 when it arrives from behind).
vec3 entering(int i, vec3 p_in, vec3 n_in, vec3 to_light, float eta) {
    float cos_in = dot(to_light, n_in);
    if (cos_in <= 0.0) {
        return vec3(0.0);
    }
    vec3 unused;
    float attenuation;
    light_incidence(frame.lights[i], p_in, unused, attenuation);
    return frame.lights[i].radiance_range.rgb *
           (max(attenuation, 0.0) * fresnel_transmittance(cos_in, eta));
}

// How much of the light that entered at `p` (outward normal `n`) the view does not hold
// already: the multiple-scattering gather carries the irradiance of the surface the camera
// sees, so the diffusion through the thickness adds only light that entered on the far side
// (a back-lit object's back), 1 where the entry faces away from the eye, 0 where it faces it,
// with a smooth ramp between (a hard test toggled across the facets of the entry map and drew
// a hatching at the boundary). A side-lit sphere's entry points face the eye: it is unchanged.
float unseen_entry(vec3 p, vec3 n) {
    vec3 from_eye = p - frame.camera_pos.xyz;
    float len2 = dot(from_eye, from_eye);
    return len2 > 1e-20 ? smoothstep(0.0, 0.3, dot(n, from_eye * inversesqrt(len2))) : 0.0;
}

// L_t's light from light `i` at x_o (facing away from it): the light that entered on the
// light's side and crossed the object, unscattered (its transmittance) and by diffusion
// (dipole_beyond, issue 26: a back-lit thin slab glows as the path-traced truth does), from the
// entry point, filtered like a shadow lookup (each of the four texels around x_o's map
// position gives its own entry distance, normal and transmittance, bilinearly weighted; texels
// of another material block): filtering the distance instead would leave a staircase where
// the first surface along the light changes (the object's rim and its self-occlusion as the
// light sees it). Lights without a map give none (the plane at x_o is its own entry).
vec3 transmitted_light(int i, vec3 x_o, vec3 n_o, vec3 to_light, int id, float eta, int mat,
                       uvec4 texels_o) {
#ifdef LUCENT_ENTRY
    int face = shadow_face(i, x_o);
    if (face < 0) {
        return vec3(0.0);
    }
    // Near the terminator the mesh's flat facets can face the light where the interpolated
    // normal does not: the map's first surface is then x_o's own facet, a thickness of ~0 and
    // a bright hatching along the facets. So the lookup is made from a point one map texel
    // inside (as shadow lookups move out), whose ray to the light gives the entry point, and
    // the term fades in over the first 3 texels of thickness. (The cost: on the clear test
    // sphere the term comes out 8% high, against 3% from x_o itself, docs/layered.md.)
    float texel_size = map_texel_size(face, x_o);
    vec3 inner = x_o - n_o * texel_size;
    vec2 t;
    float d_x;
    if (!map_position(face, inner, t, d_x)) {
        return vec3(0.0);
    }
    // The entry's layers as the nearest texel has them (the four filtered texels share them).
    uvec4 texels_in = entry_texels(map_texel(face, t), texels_o);
    vec2 corner;
    vec4 w;
    map_bilinear(face, t, corner, w);
    vec4 d = textureGather(shadow_depth, corner, 0);
    vec4 ids = textureGather(shadow_entry, corner, 3) * 255.0;
    // Each texel's own entry normal (encoded n * 0.5 + 0.5): one normal for all four, the
    // nearest texel's, jumped at every texel edge where the first surface changes (the other
    // candle's shadow on a back-lit one) and drew a diamond moire across the band (issue 25:
    // the converged frame's grain, 1.16x plain lighting's, fell to 1.10x).
    vec4 normal_x = textureGather(shadow_entry, corner, 0);
    vec4 normal_y = textureGather(shadow_entry, corner, 1);
    vec4 normal_z = textureGather(shadow_entry, corner, 2);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        if (!(abs(ids[k] - float(id)) < 0.5 && d[k] < 1.0)) {
            continue;
        }
        vec3 p_in = map_entry_point(face, i, inner, to_light, d_x,
                                    shadow_distance(shadows.faces[face].params, d[k]));
        float thickness = length(p_in - x_o);
        float fade = smoothstep(0.0, 3.0 * texel_size, thickness);
        vec3 n_in = sanitize_normal(vec3(normal_x[k], normal_y[k], normal_z[k]) * 2.0 - 1.0);
        vec3 e = entering(i, p_in, n_in, to_light, eta);
        // Unscattered: the beam's flux through x_o's surface, so the cosine at the exit (the
        // beam spreads over 1 / |cos| of it; without it the rim just past a side light's
        // terminator, where the chord is short and the exit grazing, drew a bright band). And
        // diffused through the thickness by the first layer's dipole: the light that entered,
        // the irradiance, so the cosine at the entry.
        vec3 crossed = max(-dot(to_light, n_o), 0.0) *
                           exp(-optical_depth(mat, p_in, n_in, p_in, x_o, texels_in)) +
                       (unseen_entry(p_in, n_in) * max(dot(to_light, n_in), 0.0)) *
                           dipole_beyond(mat, thickness);
        sum += (w[k] * fade) * e * crossed;
    }
    return sum;
#else
    return vec3(0.0);
#endif
}

// How fast the march's importance falls with the view ray's optical depth: light scattered
// at depth reaches it through the medium and leaves through it, e^-(tau_view + tau_light),
// and tau_light is about tau_view for light from above, so 2.
#ifndef MARCH_DENSITY
#define MARCH_DENSITY 2.0
#endif

// Layer j of the stack below x_o (its top at depth `top`) along the refracted ray of length
// s_end: its bottom depth, the ray lengths [s0, s1) it holds (depth / cos_w, cos_w = -n_o . w;
// a ray along the surface stays in the first layer; s1 at most s_end), and its rgb-mean
// extinction times MARCH_DENSITY and scattering. False when the layer starts past the march.
bool march_segment(int mat, int j, float top, float cos_w, float s_end, uvec4 texels,
                   out float bottom, out float s0, out float s1, out float sigma_t,
                   out float sigma_s) {
    bottom = layer_bottom(mat, j, top, texels);
    if (cos_w > 1e-6) {
        s0 = top / cos_w;
        s1 = bottom >= 1e30 ? 1e30 : bottom / cos_w;
    } else {
        s0 = j == 0 ? 0.0 : 1e30;
        s1 = 1e30;
    }
    s1 = min(s1, s_end);
    sigma_t = MARCH_DENSITY * dot(MAT.sigma_t_g[j].rgb, vec3(1.0 / 3.0));
    sigma_s = dot(MAT.sigma_s_thickness[j].rgb, vec3(1.0 / 3.0));
    return s0 < s_end;
}

// The march's whole importance (the normaliser of march_step), once per pixel; < 0 when the
// stack scatters ~nothing along the ray (uniform steps).
float march_total(int mat, float cos_w, float s_end, uvec4 texels) {
    int count = clamp(int(MAT.info.x + 0.5), 1, MAX_MEDIUM_LAYERS);
    float total = 0.0, top = 0.0, t_acc = 0.0;
    for (int j = 0; j < count; ++j) {
        float bottom, s0, s1, sigma_t, sigma_s;
        if (!march_segment(mat, j, top, cos_w, s_end, texels, bottom, s0, s1, sigma_t,
                           sigma_s)) {
            break;
        }
        float t_seg = sigma_t * (s1 - s0);
        if (sigma_t > 0.0) {
            // e^-a (1 - e^-b) without cancellation for a thin segment.
            total += sigma_s / sigma_t * exp(-t_acc) * -expm1_approx(-t_seg);
        }
        t_acc += t_seg;
        top = bottom;
    }
    return (total > 1e-30 && t_acc > 1e-6) ? total : -1.0;
}

// Step u (in (0, 1)) of `steps` along the refracted ray (length s_end): the point s and its
// share ds of the ray, placed by the importance sigma_s(s) e^(-MARCH_DENSITY tau(s)) of the
// stack below x_o (rgb means per layer; tau the view ray's optical depth): in each layer it
// integrates to sigma_s / (D sigma_t) (e^-T(s0) - e^-T(s1)), T = D tau, inverted in closed
// form. Each layer gets steps in proportion to the light it can scatter back, so a thin top
// over a denser layer resolves both (spacing by the first layer's transmittance alone put
// the steps into the top: 28% error at K = 4 on a 0.1 mm top over a 20 mm^-1 layer). Layers
// that scatter nothing hold no step; a stack that scatters ~nothing (total < 0) gets uniform
// steps.
void march_step(int mat, float cos_w, float s_end, float total, float u, int steps,
                uvec4 texels, out float s, out float ds) {
    s = s_end;
    ds = s_end / float(steps);
    if (!(total > 0.0)) {
        s = u * s_end;
        return;
    }
    // The layer where the importance reaches u of the total, and the point in it (rounding
    // can leave the target past the last layer that scatters: its end).
    int count = clamp(int(MAT.info.x + 0.5), 1, MAX_MEDIUM_LAYERS);
    float target = u * total;
    float acc = 0.0, top = 0.0, t_acc = 0.0;
    for (int j = 0; j < count; ++j) {
        float bottom, s0, s1, sigma_t, sigma_s;
        if (!march_segment(mat, j, top, cos_w, s_end, texels, bottom, s0, s1, sigma_t,
                           sigma_s)) {
            break;
        }
        float t_seg = sigma_t * (s1 - s0);
        if (sigma_t > 0.0 && sigma_s > 0.0) {
            float a = sigma_s / sigma_t;
            float e0 = exp(-t_acc);
            float mass = a * e0 * -expm1_approx(-t_seg);
            // e^-T(s) = e0 - (target - acc) / a, kept inside the segment.
            float e = clamp(e0 - (target - acc) / a, e0 * exp(-t_seg), e0);
            float t = -log(max(e, 1e-30));
            s = clamp(s0 + (t - t_acc) / sigma_t, s0, s1);
            // pdf(s) = sigma_s e^-T(s) / total.
            ds = total / (float(steps) * sigma_s * max(e, 1e-30));
            if (acc + mass >= target) {
                return;
            }
            acc += mass;
        }
        t_acc += t_seg;
        top = bottom;
    }
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int id = layered_id_at(px);
    out_color = vec4(0.0);
    if (id == 0) {
        return;
    }
    int mat = layered_row(id);
    float eta = MAT.info.y;
    vec3 x_o = layered_position_at(px);
    vec3 n_o = layered_normal_at(px);
    uvec4 texels_o = uvec4(0);
#ifdef LUCENT_LAYER_DEPTHS
    texels_o = texelFetch(gbuffer_layer_depths, px, 0);
#endif
    vec3 view = x_o - frame.camera_pos.xyz;
    float view_len2 = dot(view, view);
    vec3 view_dir = view_len2 > 1e-20 ? view * inversesqrt(view_len2) : -n_o;
    n_o = facing_normal(n_o, view_dir);
    float cos_o = dot(-view_dir, n_o);
    float t_o = fresnel_transmittance(cos_o, eta);
    int lights = min(frame.light_count.x, MAX_LIGHTS);
    vec3 w;
    bool refracted = refract_into(view_dir, n_o, eta, w);
    // The march (eqs. 4-6): to D_max / (N . T), grazing refraction bounded at cos beta = 0.05
    // (20 D_max along the ray); steps equally spaced in the view ray's mean transmittance
    // through the layer stack (march_step).
    float cos_w = max(dot(-n_o, w), 0.0);
    float s_end = MAT.info.z / max(cos_w, 0.05);
    int steps = clamp(layered.knobs.x, 1, 64);
    // The middle of the march, where each light's entry point is looked up once.
    float total = march_total(mat, cos_w, s_end, texels_o);
    float s_mid, unused_ds;
    march_step(mat, cos_w, s_end, total, 0.5, steps, texels_o, s_mid, unused_ds);
    vec3 m_mid = x_o + w * s_mid;

    vec3 l_t = vec3(0.0), sum = vec3(0.0);
    for (int i = 0; i < lights; ++i) {
        // One map lookup per light and pixel: the entry surface (point and normal) where the
        // light reaching the middle of the march entered; every step's entry point is where
        // its own ray to the light crosses that surface's tangent plane. The steps lie within
        // D_max of the surface (a few mean free paths), so the plane misses only the surface's
        // curvature over that distance: on a 12.5 mm apple sphere the term comes out 4% low
        // (against 1% with a lookup per step, which costs 1.5x as much: docs/layered.md).
        vec3 to_mid;
        float unused;
        light_incidence(frame.lights[i], m_mid, to_mid, unused);
        vec3 p_ref, n_ref;
        uvec4 texels_ref = texels_o;
        bool entered = refracted && light_entry(i, m_mid, to_mid, id, x_o, n_o, texels_o, p_ref,
                                                n_ref, texels_ref);
        // L_t: light that crossed the object unscattered from its entry on the light's side
        // to x_o (a lit point is its own entry point: its light is L_d's); its own lookup,
        // made only where x_o faces away from the light.
        vec3 to_light;
        light_incidence(frame.lights[i], x_o, to_light, unused);
        if (dot(to_light, n_o) < 0.0) {
            l_t += transmitted_light(i, x_o, n_o, to_light, id, eta, mat, texels_o);
        }
        if (!entered) {
            continue; // blocked by another material, or below the plane
        }
        for (int k = 0; k < steps; ++k) {
            float u = (float(k) + 0.5) / float(steps);
            float s, ds;
            march_step(mat, cos_w, s_end, total, u, steps, texels_o, s, ds);
            vec3 m = x_o + w * s;
            int layer = layer_at(mat, dot(x_o - m, n_o), texels_o);
            if (layer < 0) {
                continue; // below the last layer: no medium scatters
            }
            light_incidence(frame.lights[i], m, to_light, unused);
            float c = dot(to_light, n_ref);
            if (c <= 1e-4) {
                continue;
            }
            // The light refracts where it enters: it reaches m along `down`, from the point
            // of the entry plane that path starts at, and the beam it was outside narrows to
            // cos_in / cos_t of its width (its irradiance across the path rises by that).
            vec3 down;
            if (!refract_into(-to_light, n_ref, eta, down)) {
                continue;
            }
            float cos_t = -dot(down, n_ref);
            if (cos_t <= 1e-4) {
                continue;
            }
            vec3 p_in = m - down * (max(dot(p_ref - m, n_ref), 0.0) / cos_t);
            vec3 e = entering(i, p_in, n_ref, to_light, eta) * (c / cos_t);
            vec3 tau = optical_depth(mat, p_in, n_ref, p_in, m, texels_ref) +
                       optical_depth(mat, x_o, n_o, m, x_o, texels_o);
            sum += MAT.sigma_s_thickness[layer].rgb * phase(MAT.sigma_t_g[layer].a, dot(-down, w)) *
                   e * exp(-tau) * ds;
        }
    }
    // Light leaving diffusely through the boundary is spread as F_t(mu_o) / (pi c)
    // (MAT.weights.w: c, scene::albedo::diffuse_transmittance).
    l_t *= t_o / (PI * max(MAT.weights.w, 1e-3));
    // Radiance inside the medium is eta^2 the radiance it leaves as (the solid angle widens
    // as it leaves): without 1 / eta^2 a skin1 sphere at eta 1.5 came out 1.7-2.3x the
    // path-traced truth's green and blue (issue 37).
    vec3 l_ss = t_o * sum / (eta * eta);
    // The ambient's single scattering, which the march (lights only) leaves out: a white
    // sky's share of it (src/scene/layered.rs `albedo_split`), unshadowed as
    // every pass's ambient. Without it the multiple scattering, scaled to the orders past the
    // first, left an ambient-lit skin1 sphere 40% too dark.
    l_ss += t_o * ambient_radiance(n_o) * MAT.ambient_single.rgb;
    vec3 terms = MAT.weights.x * l_t + MAT.weights.y * l_ss;
#ifdef LUCENT_HALF_TERM
    terms += upsampled_multiple(px, id); // already weighted by λ5
#endif
#ifdef LUCENT_LAYERED_FILM
    // The albedo texture as a pigment film on the light leaving the surface (the screen-space
    // blurs' `post` texturing): every term here leaves through x_o, while the light entering
    // (the irradiance gathered, the entry points) is left alone. The G-buffer stores the
    // texel beside the material ID (white for untextured draws).
#ifdef LUCENT_HOST_FILM
    // The host's albedo texel; a NaN or out-of-range one is guarded here.
    vec3 film = texelFetch(host_film, px, 0).rgb;
    terms *= clamp(mix(film, vec3(0.0), isnan(film)), 0.0, 1.0);
#else
    terms *= texelFetch(gbuffer_layered, px, 0).gba;
#endif
#endif
    out_color = vec4(finite_term(terms), 0.0);
}
