// Li et al. 2009's layered media (src/features/layered.rs): the per-frame material table, the
// G-buffer inputs the three layered passes share, and the optics they evaluate. Every
// function has its f64 twin in src/reference/layered.rs (and the dipole in
// src/reference/dipole.rs): change both together.
//
// Set 0: the frame uniforms, the layered table, depth, GB1 (normal), the layered IDs; then the
// pass's own bindings (each bound by its name). lucent's own G-buffer and a host's
// (src/embed/layered.rs `LayeredEffect`: its depth, normals and material IDs) are read by the
// same code: the ID decode, how IDs map to materials and the normal encoding are
// specialization constants (below; their defaults are lucent's own G-buffer), the ID-to-material
// table and the inverse view matrix are in the layered table; LUCENT_HOST_IDS_UINT when the
// IDs are an unsigned-integer image, LUCENT_HOST_LINEAR_DEPTH when the depth is linear view
// depth (a define, not a constant: a CPU driver runs both sides of a branch, and the gather
// rebuilds a position per sample). Every pass reads the G-buffer through layered_id_at,
// layered_position_at, layered_normal_at and layered_view_depth_at.
#ifndef LUCENT_LAYERED_GLSL
#define LUCENT_LAYERED_GLSL

#include "gbuffer.glsl"
#include "lighting.glsl"
#include "layer_depths.glsl"
#include "../embed/lucent_terms.glsl"
#ifdef LUCENT_SHADOWS
#include "shadows.glsl"
#endif
#include "host_ids.glsl"
#include "host_normals.glsl"
#include "host_depth.glsl"

#define MAX_LAYERED_MATERIALS 16
#define MAX_MEDIUM_LAYERS 8
// |g| at most 0.999: both phase functions peak like 1 / (1 - |g|)^2 (MAX_ABS_G).
#define MAX_ABS_G 0.999

struct LayeredMaterial {
    vec4 info;                                   // x layers, y eta, z D_max, w gather radius
    vec4 weights;                                // x λ3 (transmitted), y λ4 (single), z λ5,
                                                 // w c: the ambient let in, and how light
                                                 // leaving diffusely is spread (F_t / (pi c))
    vec4 sigma_t_g[MAX_MEDIUM_LAYERS];           // rgb extinction (1/unit), a: g
    vec4 sigma_s_thickness[MAX_MEDIUM_LAYERS];   // rgb scattering, a: thickness (-1: rest)
    vec4 thickness_scale[2];                     // layer j: units per texel of its TexDep
                                                 // texel ([j / 4][j % 4]; 0: not a texture)
    vec4 sigma_tr;                               // the first layer's dipole, per channel
    vec4 z_r;
    vec4 z_v;
    vec4 alpha_prime;
    vec4 total;                                  // what multiple scattering scales its
                                                 // profile to (AlbedoSplit::multiple_scale)
    vec4 ambient_single;                         // the ambient's single scattering, S / c
};

layout(std140, set = 0) uniform Layered {
    ivec4 knobs;  // x march steps, y pixel lights, z phase (0 HG, 1 Schlick), w downscale
    LayeredMaterial materials[MAX_LAYERED_MATERIALS];
    mat4 view_to_world;    // the inverse of the frame's view matrix
    uvec4 id_materials[64];  // ID k's layered material at [k / 4][k % 4] (0: none)
} layered;

// How the G-buffer is read (src/features/layered/mod.rs `LayeredDecode`), fixed when the pass
// is made: the driver folds them. (The layered passes include no other constants but
// host_depth.glsl's, constant_id 21.)
// - The ID decode (host_ids.glsl): channel, bit field shift and mask, a UNORM channel's largest
//   value.
// - LAYERED_IDS_UP_TO: n (1 to 16) when IDs 1 to n are layered materials 1 to n and every other
//   ID none; LAYERED_IDS_ONLY_MATERIALS when the image holds nothing but material numbers
//   (lucent's own G-buffer); 0: each ID's material is in id_materials.
// - The normal encoding (host_normals.glsl): octahedral, view space, UNORM channels.
#define LAYERED_IDS_ONLY_MATERIALS 256
layout(constant_id = 0) const uint LAYERED_ID_CHANNEL = 0u;
layout(constant_id = 1) const uint LAYERED_ID_SHIFT = 0u;
layout(constant_id = 2) const uint LAYERED_ID_MASK = 255u;
layout(constant_id = 3) const uint LAYERED_ID_UNORM_MAX = 255u;
layout(constant_id = 4) const uint LAYERED_IDS_UP_TO = LAYERED_IDS_ONLY_MATERIALS;
layout(constant_id = 5) const uint LAYERED_NORMALS_OCTAHEDRAL = 0u;
layout(constant_id = 6) const uint LAYERED_NORMALS_VIEW = 0u;
layout(constant_id = 7) const uint LAYERED_NORMALS_UNORM = 0u;
#define LAYERED_ID_DECODE \
    uvec4(LAYERED_ID_CHANNEL, LAYERED_ID_SHIFT, LAYERED_ID_MASK, LAYERED_ID_UNORM_MAX)

layout(set = 0) uniform sampler2D gbuffer_depth;
layout(set = 0) uniform sampler2D gbuffer_normal;
#ifdef LUCENT_HOST_IDS_UINT
layout(set = 0) uniform usampler2D gbuffer_layered;
#else
layout(set = 0) uniform sampler2D gbuffer_layered;
#endif

// The layered material ID at a full-resolution pixel (0: not layered).
int layered_id_at(ivec2 px) {
#ifndef LUCENT_HOST_IDS_UINT
    if (LAYERED_IDS_UP_TO >= uint(LAYERED_IDS_ONLY_MATERIALS) && LAYERED_ID_UNORM_MAX == 255u &&
        LAYERED_ID_SHIFT == 0u && LAYERED_ID_MASK == 255u) {
        // Nothing but material numbers in a whole 8-bit UNORM channel (lucent's own G-buffer):
        // the number itself (layered_row clamps it).
        return int(texelFetch(gbuffer_layered, px, 0)[min(LAYERED_ID_CHANNEL, 3u)] * 255.0 + 0.5);
    }
#endif
    // The ID (at most 255 after its bit field: the table has 256 entries).
    uint id = min(host_material_id(texelFetch(gbuffer_layered, px, 0), LAYERED_ID_DECODE), 255u);
    if (LAYERED_IDS_UP_TO >= uint(LAYERED_IDS_ONLY_MATERIALS)) {
        return int(id);
    }
    if (LAYERED_IDS_UP_TO > 0u) {
        return id <= LAYERED_IDS_UP_TO ? int(id) : 0;
    }
    return int(layered.id_materials[id >> 2u][id & 3u]);
}

// The view depth (along the view axis) of the surface at a full-resolution pixel.
float layered_view_depth_at(ivec2 px) {
    return linear_depth(texelFetch(gbuffer_depth, px, 0).r);
}

// The world position of the surface at a full-resolution pixel.
vec3 layered_position_at(ivec2 px) {
    float depth = texelFetch(gbuffer_depth, px, 0).r;
#ifdef LUCENT_HOST_LINEAR_DEPTH
    return position_at_view_depth(vec2(px) + 0.5, linear_depth(depth), layered.view_to_world);
#else
    return world_position(vec2(px) + 0.5, depth);
#endif
}

// The unit world normal at a full-resolution pixel (a NaN, Inf or zero normal: +Y).
vec3 layered_normal_at(ivec2 px) {
    uvec4 encoding = uvec4(LAYERED_NORMALS_OCTAHEDRAL, LAYERED_NORMALS_VIEW, LAYERED_NORMALS_UNORM, 0u);
    return host_normal(texelFetch(gbuffer_normal, px, 0), encoding, layered.view_to_world);
}

// The table row of material `id` (read fields through it: copying a row into a local
// struct makes llvmpipe spill it to scratch memory).
int layered_row(int id) {
    return clamp(id - 1, 0, MAX_LAYERED_MATERIALS - 1);
}

#define MAT layered.materials[mat]

// Exact unpolarised Fresnel transmittance for light arriving at `cos_i` into a medium of
// relative index `eta` (fresnel_transmittance).
float fresnel_transmittance(float cos_i, float eta) {
    if (eta == 1.0) {
        return 1.0;
    }
    if (!(eta > 0.0)) {
        return 0.0;
    }
    float ci = clamp(cos_i, 0.0, 1.0);
    float sin2_t = (1.0 - ci * ci) / (eta * eta);
    if (sin2_t >= 1.0) {
        return 0.0;
    }
    float ct = sqrt(1.0 - sin2_t);
    // Both denominators > 0 here (ct > 0, eta > 0); at ci = 0 rs = -1 and T = 0.
    float rs = (ci - eta * ct) / (ci + eta * ct);
    float rp = (eta * ci - ct) / (eta * ci + ct);
    return clamp(1.0 - 0.5 * (rs * rs + rp * rp), 0.0, 1.0);
}

// `dir` (unit, travelling towards the surface) refracted into the medium through outward unit
// normal `n` (refract); false under total internal reflection.
bool refract_into(vec3 dir, vec3 n, float eta, out vec3 refracted) {
    float cos_i = clamp(-dot(dir, n), 0.0, 1.0);
    float sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if (!(sin2_t <= 1.0)) {
        refracted = -n;
        return false;
    }
    float cos_t = sqrt(1.0 - sin2_t);
    vec3 t = dir / eta + n * (cos_i / eta - cos_t);
    float len2 = dot(t, t);
    refracted = len2 > 1e-20 ? t * inversesqrt(len2) : -n;
    return true;
}

// Henyey-Greenstein (henyey_greenstein): the base written (1 - g)^2 + 2 g (1 - cos) so
// |g| -> 1 near cos = 1 does not cancel.
float phase_hg(float g, float c) {
    g = clamp(g, -MAX_ABS_G, MAX_ABS_G);
    c = clamp(c, -1.0, 1.0);
    float base = (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c);
    return (1.0 - g * g) / (4.0 * PI * base * sqrt(base));
}

// Schlick's form with k = 1.55 g - 0.55 g^3 (schlick; Li et al.'s eq. 9 writes g for k).
float phase_schlick(float g, float c) {
    g = clamp(g, -MAX_ABS_G, MAX_ABS_G);
    float k = clamp(1.55 * g - 0.55 * g * g * g, -MAX_ABS_G, MAX_ABS_G);
    c = clamp(c, -1.0, 1.0);
    float base = (1.0 - k) + k * (1.0 - c);
    return (1.0 - k * k) / (4.0 * PI * base * base);
}

float phase(float g, float c) {
    return layered.knobs.z == 1 ? phase_schlick(g, c) : phase_hg(g, c);
}

// Layer j's thickness (units; -1: the semi-infinite rest). `texels` are the depth-texture
// texels at the point the layers hang below (layer_depths.glsl; frames without TexDep media
// pass uvec4(0) and read the table's constants only).
float layer_thickness(int mat, int j, uvec4 texels) {
    float t = MAT.sigma_s_thickness[j].a;
#ifdef LUCENT_LAYER_DEPTHS
    float scale = MAT.thickness_scale[j >> 2][j & 3];
    if (scale > 0.0) {
        // Sanitized when packed: finite and >= 0; times a finite scale, at most ~6.6e4 x 1e6.
        t = layer_texel(texels, j) * scale;
    }
#endif
    return t;
}

// The bottom depth of layer j whose top is at depth `top` (units below the reference surface;
// a `rest` layer has no bottom: 1e30).
float layer_bottom(int mat, int j, float top, uvec4 texels) {
    float t = layer_thickness(mat, j, texels);
    float bottom = t < 0.0 ? 1e30 : top + t;
    return bottom;
}

// The layer holding depth `d` below the reference point (depths above the tangent plane belong
// to the first layer; below the last layer's bottom: -1, no medium) (LayerStack::layer_at).
int layer_at(int mat, float d, uvec4 texels) {
    int count = clamp(int(MAT.info.x + 0.5), 1, MAX_MEDIUM_LAYERS);
    float top = 0.0;
    for (int j = 0; j < count; ++j) {
        float bottom = layer_bottom(mat, j, top, texels);
        if (d < bottom) {
            return j;
        }
        top = bottom;
    }
    return -1;
}

// Optical depth per channel of segment a-b through the planar layers below surface point p
// with outward unit normal n and depth texels `texels` (LayerStack::optical_depth): each
// layer's share of the segment times its extinction.
vec3 optical_depth(int mat, vec3 p, vec3 n, vec3 a, vec3 b, uvec4 texels) {
    float len = length(b - a);
    if (!(len > 0.0)) {
        return vec3(0.0);
    }
    float da = dot(p - a, n), db = dot(p - b, n);
    float slope = db - da;
    int count = clamp(int(MAT.info.x + 0.5), 1, MAX_MEDIUM_LAYERS);
    vec3 tau = vec3(0.0);
    float top = -1e30;
    float running = 0.0;
    for (int j = 0; j < count; ++j) {
        float bottom = layer_bottom(mat, j, running, texels);
        running = bottom;
        float share;
        if (abs(slope) < 1e-30) {
            share = (da >= top && da < bottom) ? 1.0 : 0.0;
        } else {
            float t0 = (top - da) / slope, t1 = (bottom - da) / slope;
            share = max(min(max(t0, t1), 1.0) - max(min(t0, t1), 0.0), 0.0);
        }
        tau += MAT.sigma_t_g[j].rgb * (share * len);
        top = bottom;
        if (bottom >= 1e30) {
            break;
        }
    }
    return tau;
}

// Jensen's diffuse reflectance Rd(r) of the first layer per channel (Dipole::rd): each source
// with its own distance, d_r >= z_r > 0 so r = 0 is finite; exp(-e) of a large e is 0.
vec3 dipole_rd(int mat, float r) {
    float r2 = r * r;
    vec3 dr = sqrt(r2 + MAT.z_r.rgb * MAT.z_r.rgb);
    vec3 dv = sqrt(r2 + MAT.z_v.rgb * MAT.z_v.rgb);
    vec3 er = MAT.sigma_tr.rgb * dr, ev = MAT.sigma_tr.rgb * dv;
    vec3 real = MAT.z_r.rgb * (er + 1.0) * exp(-er) / (dr * dr * dr);
    vec3 virt = MAT.z_v.rgb * (ev + 1.0) * exp(-ev) / (dv * dv * dv);
    return MAT.alpha_prime.rgb / (4.0 * PI) * (real + virt);
}

// The first layer's diffuse transmission through a thickness a (scene units): the part of
// the light that entered which diffuses out farther than a from its entry,
// 2 pi ∫_a^inf Rd(r) r dr = (alpha'/2) sum over z_r, z_v of z e^(-sigma_tr d) / d with
// d = sqrt(a^2 + z^2) (Dipole::transmitted_beyond; HDRP's thick transmission reads its profile
// at the thickness the same way). The sum is glsl/embed/lucent_terms.glsl's, which screen-space SSS materials
// with a medium read too (sss_transmission.glsl): both techniques diffuse through a thickness
// alike.
vec3 dipole_beyond(int mat, float a) {
    return 0.5 * MAT.alpha_prime.rgb *
           lucent_dipole_beyond_sum(MAT.sigma_tr.rgb, MAT.z_r.rgb, MAT.z_v.rgb, a);
}

// The light transmitted into the surface at p (outward normal n): radiance x falloff x cos x
// Fresnel transmittance of every light, shadowed where the light casts, and the ambient's
// (transmitted_irradiance).
vec3 transmitted_irradiance(vec3 p, vec3 n, float eta, float ambient_transmittance) {
    // The environment's irradiance at the normal, pi ambient_radiance(n), of which the
    // boundary lets c through (unshadowed, as every pass's ambient).
    vec3 e = ambient_radiance(n) * (PI * ambient_transmittance);
    int count = min(frame.light_count.x, MAX_LIGHTS);
    for (int i = 0; i < count; ++i) {
        vec3 to_light;
        float attenuation;
        light_incidence(frame.lights[i], p, to_light, attenuation);
        float c = dot(to_light, n);
        if (c <= 0.0 || attenuation <= 0.0) {
            continue;
        }
        float visible = 1.0;
#ifdef LUCENT_SHADOWS
        visible = shadow_visibility(i, p, n, to_light, 0).x;
#endif
        e += frame.lights[i].radiance_range.rgb *
             (attenuation * c * fresnel_transmittance(c, eta) * visible);
    }
    return e;
}

// e^x - 1 without the cancellation of exp(x) - 1 near 0 (|x| < 1e-3: three Taylor terms).
float expm1_approx(float x) {
    return abs(x) < 1e-3 ? x * (1.0 + x * (0.5 + x / 6.0)) : exp(x) - 1.0;
}

// The shading normal bent into the hemisphere the eye sees (cos at least 0.05): at
// silhouettes an interpolated normal can face away from the eye while its facet faces it, and
// the terms, which need light to leave towards the eye, left those pixels black.
vec3 facing_normal(vec3 n, vec3 view_dir) {
    const float MIN_COS = 0.05;
    float c = dot(-view_dir, n);
    return c >= MIN_COS ? n : normalize(n - view_dir * (MIN_COS - c));
}

// Keeps a term finite and inside fp16 before it is added to the lit image.
vec3 finite_term(vec3 v) {
    bvec3 bad = bvec3(isnan(v.x) || isinf(v.x), isnan(v.y) || isinf(v.y),
                      isnan(v.z) || isinf(v.z));
    return clamp(mix(v, vec3(0.0), bad), vec3(0.0), vec3(65504.0));
}

#endif
