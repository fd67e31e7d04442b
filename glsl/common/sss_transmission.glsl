// Diffuse transmission through thickness for screen-space SSS materials with a medium
// (issue 26; src/features/sss/transmission.rs), HDRP's "thick" mode from the medium: per
// light, the light that entered on the far side of the object diffuses through the thickness
// the light-space map measures and leaves here, before the blur (which then spreads it). The
// lighting pass includes this (through sss_medium.glsl) with LUCENT_SHADOWS, the SSS profile
// table and the pixel's profile ID. The thickness is the light's path through the object, so
// a back-lit slab gets its thickness and a side-lit sphere its chords. The f64 twins are
// src/reference/transmission.rs (`sss_transmitted`) and src/scene/transmittance.rs
// (`transmittance_over_albedo`): change them together.
#ifndef LUCENT_SSS_TRANSMISSION_GLSL
#define LUCENT_SSS_TRANSMISSION_GLSL

#include "../embed/lucent_terms.glsl"
#include "sss.glsl"
#include "shadows.glsl"

// Whether profile `id` transmits (its material has a medium and `--no-sss-transmission` is
// not given; the row is zero otherwise, and for ID 0).
bool sss_transmits(int id) {
    return sss_profiles.medium[id * 6].a > 0.0;
}

// The medium's diffuse transmittance through `a` scene units relative to its albedo (its
// white-sky albedo): glsl/embed/lucent_terms.glsl `lucent_sss_transmittance` on profile `id`'s
// four transmission rows, the same function a host's lighting pass calls.
vec3 sss_transmittance(int id, float a) {
    vec4 medium[4] = vec4[4](sss_profiles.medium[id * 6], sss_profiles.medium[id * 6 + 1],
                             sss_profiles.medium[id * 6 + 2], sss_profiles.medium[id * 6 + 3]);
    return lucent_sss_transmittance(medium, a);
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
