// Screen-space SSS materials with a [material.medium] (issue 26): the lighting pass shades
// their diffuse light as their medium reflects it, and (with light-space maps) adds the light
// the medium diffuses through the object's thickness (sss_transmission.glsl). Included with
// LUCENT_SSS_MEDIUM, the SSS profile table and the pixel's profile ID.
//
// The reflectance: Chandrasekhar's reflection of an isotropically scattering half-space,
// f = (omega / 4 pi) H(mu0) H(mu) / (mu0 + mu), against a Lambertian surface of the medium's
// albedo A_1 (its white-sky albedo behind an index-matched boundary, what f integrates to), so
// the factor sss_medium_reflectance multiplies the Lambertian diffuse light by is
// omega H(mu0) H(mu) / (4 A_1 (mu0 + mu)): more at grazing light and view, less head-on, and
// 1 on average under a white sky. H is Hapke's (2002) closed form, within 1% of
// Chandrasekhar's. The f64 twin is src/reference/albedo.rs (`hapke_h`, `medium_reflectance`):
// change both together.
#ifndef LUCENT_SSS_MEDIUM_GLSL
#define LUCENT_SSS_MEDIUM_GLSL

#include "sss.glsl"
#ifdef LUCENT_SHADOWS
#include "sss_transmission.glsl"
#endif

// Whether profile `id`'s material has a medium (ID 0's rows are zero).
bool sss_has_medium(int id) {
    return sss_profiles.medium[id * 6 + 4].a > 0.0;
}

// Hapke's H(x) per channel, gamma = sqrt(1 - omega): 1 / (1 - omega x (r0 + (1 - 2 r0 x) / 2
// ln((1 + x) / x))), r0 = (1 - gamma) / (1 + gamma). x is held at 1e-4 or more (ln(1 / 0));
// the bracket stays above 0.3 for every omega <= 1 and x in [0, 1].
vec3 sss_medium_h(int id, float x) {
    vec3 gamma = sss_profiles.medium[id * 6 + 4].rgb;
    vec3 omega = 1.0 - gamma * gamma;
    vec3 r0 = (1.0 - gamma) / (1.0 + gamma);
    x = clamp(x, 1e-4, 1.0);
    return 1.0 / (1.0 - omega * x * (r0 + 0.5 * (1.0 - 2.0 * r0 * x) * log((1.0 + x) / x)));
}

// The factor on the Lambertian diffuse light from a light at cosine `mu0`, seen at cosine
// `mu` whose H the caller computed once per pixel (`h_view`). The cosines' sum is held off 0
// (grazing light and view at once): H is bounded, so the factor stays finite.
vec3 sss_medium_reflectance(int id, float mu0, float mu, vec3 h_view) {
    vec3 scale = sss_profiles.medium[id * 6 + 5].rgb;
    return scale * sss_medium_h(id, mu0) * h_view / max(mu0 + mu, 1e-4);
}

#endif
