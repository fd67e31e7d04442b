// Diffuse transmission through thickness for screen-space SSS materials with a medium
// (issue 26; src/features/sss/transmission.rs), HDRP's "thick" mode from the medium: per
// light, the light that entered on the far side of the object diffuses through the thickness
// the light-space map measures and leaves here, before the blur (which then spreads it). The
// lighting pass includes this (through sss_medium.glsl) with LUCENT_SHADOWS, the SSS profile
// table and the pixel's profile ID. The thickness is the light's path through the object, so
// a back-lit slab gets its thickness and a side-lit sphere its chords. The f64 twin is
// src/reference/transmission.rs (`transmittance_over_albedo`, `sss_transmitted`): change both
// together.
#ifndef LUCENT_SSS_TRANSMISSION_GLSL
#define LUCENT_SSS_TRANSMISSION_GLSL

#include "dipole.glsl"
#include "sss.glsl"
#include "shadows.glsl"

// Whether profile `id` transmits (its material has a medium and `--no-sss-transmission` is
// not given; the row is zero otherwise, and for ID 0).
bool sss_transmits(int id) {
    return sss_profiles.medium[id * 6].a > 0.0;
}

// The medium's diffuse transmittance through `a` scene units relative to its albedo A (its
// white-sky albedo; src/reference/transmission.rs `transmittance_over_albedo`): the light
// Donner and Jensen's multipole lets through a slab of that thickness, never less than the
// light the semi-infinite dipole diffuses farther than a from its entry (what Li et al.'s
// layered pass adds, layered.glsl `dipole_beyond`; it takes over where a slab thinner than a
// mean free path leaves the multipole invalid), over A, times the albedo where the diffuse
// light's is, so a material whose albedo is the medium's transmits the model's light.
// Held in [0, min(1 / A, 1000)] (the slab lets through at most all the light).
vec3 sss_transmittance(int id, float a) {
    vec4 sigma_tr = sss_profiles.medium[id * 6];
    vec4 z_r = sss_profiles.medium[id * 6 + 1];
    vec4 z_v = sss_profiles.medium[id * 6 + 2];
    vec4 to_light_over_albedo = sss_profiles.medium[id * 6 + 3];
    vec3 most = vec3(z_r.a, z_v.a, to_light_over_albedo.a);
    // Millimetres; held below 1e18 so a^2 stays finite in f32 (the map's far plane is nearer).
    float a_mm = clamp(a * sigma_tr.a, 0.0, 1e18);
    vec3 through = max(dipole_beyond_sum(sigma_tr.rgb, z_r.rgb, z_v.rgb, a_mm),
                       multipole_slab_sum(sigma_tr.rgb, z_r.rgb, z_v.rgb, a_mm));
    return clamp(to_light_over_albedo.rgb * through, vec3(0.0), most);
}

// Light `i`'s radiance diffused through the object to `pos` (outward normal `normal`, the
// light towards `to_light`), before the albedo and 1 / pi: for each of the four map texels
// around the point (bilinearly weighted, as a shadow lookup; the transmittance is filtered,
// not the distance, which would leave a staircase where the first surface along the light
// changes), the entry point P' the texel's depth gives on the segment towards the light, the
// light's radiance x falloff there, times the transmittance through |P' - pos|, times the
// back-facing cosine max(-n . l, 0) (the entry's cosine for a slab, HDRP's "thick" mode).
// As Li et al.'s transmitted_light (glsl/layered/single.frag, which shares these map lookups:
// shadows.glsl's map_*), the lookup is made from a point one map texel inside, so the flat
// facets near the terminator do not find themselves at thickness 0. Lights without
// a map, and points outside it, transmit nothing (nothing measures the thickness).
vec3 sss_transmitted(int id, int i, vec3 pos, vec3 normal, vec3 to_light) {
    float back = -dot(normal, to_light);
    int face = shadow_face(i, pos);
    if (!(back > 0.0) || face < 0) {
        return vec3(0.0);
    }
    vec3 inner = pos - normal * map_texel_size(face, pos);
    vec2 t;
    float d_x;
    // Outside the face's cone or map: nothing measured.
    if (!map_position(face, inner, t, d_x)) {
        return vec3(0.0);
    }
    vec2 corner;
    vec4 w;
    map_bilinear(face, t, corner, w);
    vec4 d = shadow_gather_depth(face, corner);
    Light light = frame.lights[i];
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        // Depth 1: nothing between the light and the far plane there.
        if (!(d[k] < 1.0)) {
            continue;
        }
        // The first surface the light meets on its way to `inner`.
        vec3 p_in = map_entry_point(face, i, inner, to_light, d_x,
                                    shadow_distance(shadows.faces[face].params, d[k]));
        vec3 unused;
        float attenuation;
        light_incidence(light, p_in, unused, attenuation);
        sum += (w[k] * attenuation) * sss_transmittance(id, length(p_in - pos));
    }
    return sum * (back * light.radiance_range.rgb);
}

#endif
