// Diffusion through a thickness: Jensen's dipole (2001) and Donner and Jensen's multipole
// (2005), shared by Li et al.'s layered passes (layered.glsl `dipole_beyond`) and the
// screen-space SSS materials' diffuse transmission (sss_transmission.glsl). The f64 twins are
// src/reference/transmission.rs (`beyond_sum`, `multipole_sum`; `Dipole::transmitted_beyond` in
// src/reference/dipole.rs): change both together.
#ifndef LUCENT_DIPOLE_GLSL
#define LUCENT_DIPOLE_GLSL

// Sum over the real (depth z_r) and virtual (height z_v) sources of z e^(-sigma_tr d) / d,
// d = sqrt(a^2 + z^2), per channel: the light that diffuses out farther than `a` from its
// entry is (alpha' / 2) times this. Every length in one unit (a >= 0). d >= z > 0 (z_r is
// 1 / sigma_t' with sigma_t' held above 1e-12 where the constants are made, so z^2 <= 1e24 and
// z_v^2 < 1e31: no f32 overflow), so z / d <= 1; e^-x of a large x is 0: finite for every
// finite a, and exactly sum(e^(-sigma_tr z)) at a = 0.
vec3 dipole_beyond_sum(vec3 sigma_tr, vec3 z_r, vec3 z_v, float a) {
    float a2 = a * a;
    vec3 dr = sqrt(a2 + z_r * z_r);
    vec3 dv = sqrt(a2 + z_v * z_v);
    return z_r / dr * exp(-sigma_tr * dr) + z_v / dv * exp(-sigma_tr * dv);
}

// e^x - 1 for x <= 0 without the cancellation of exp(x) - 1 near 0 (|x| < 1e-3: three
// Taylor terms).
vec3 dipole_expm1(vec3 x) {
    return mix(exp(x) - 1.0, x * (1.0 + x * (0.5 + x / 6.0)), lessThan(abs(x), vec3(1e-3)));
}

// One row of the multipole's sources, summed over every image: sum over i of
// sign(x - i P) e^(-sigma |x - i P|) for |x| < P, in closed form (two geometric series):
// sign(x) e^(-sigma |x|) (1 - e^(-sigma (P - 2|x|))) / (1 - e^(-sigma P)), written with expm1 so
// a weak absorber does not cancel, and its limit (P - 2|x|) / P where sigma P -> 0.
vec3 multipole_row(vec3 sigma, vec3 x, vec3 period) {
    vec3 ax = min(abs(x), period);
    vec3 weak = (period - 2.0 * ax) / period;
    vec3 strong = dipole_expm1(-sigma * (period - 2.0 * ax)) /
                  min(dipole_expm1(-sigma * period), vec3(-1e-30));
    vec3 ratio = mix(strong, weak, lessThan(sigma * period, vec3(1e-6)));
    return sign(x) * exp(-sigma * ax) * ratio;
}

// Donner and Jensen's (2005) multipole through a slab of thickness `a`: the dipole mirrored
// about both faces (extrapolated boundaries z_b = (z_v - z_r) / 2 beyond each), real sources
// at i P + z_r and virtual ones at i P - z_r - 2 z_b, P = 2 (a + 2 z_b), every integer i. Its
// transmission profile integrated over the far face is (alpha' / 2) times the sum over the
// real sources of sign(a - z) e^(-sigma_tr |a - z|) less the same over the virtual ones
// (2 pi ∫ h (1 + sigma d) e^(-sigma d) / d^3 r dr = sign(h) e^(-sigma |h|), d^2 = r^2 + h^2),
// summed over every i in closed form (multipole_row; |a - z_r| and a + z_r + 2 z_b are both
// below P since 2 z_b > z_r). A clear slab gets diffusion's 2 (z_r + z_b) / (a + 2 z_b).
// Diffusion through a slab is only valid when the slab holds the real source (a > z_r):
// thinner, the sum goes negative, so sss_transmittance never takes less than the semi-infinite
// dipole's light beyond a (dipole_beyond_sum). Finite: each row is at most 1 in size.
vec3 multipole_slab_sum(vec3 sigma_tr, vec3 z_r, vec3 z_v, float a) {
    vec3 boundaries = z_v - z_r; // 2 z_b
    vec3 period = 2.0 * (a + boundaries);
    return multipole_row(sigma_tr, a - z_r, period) -
           multipole_row(sigma_tr, a + z_r + boundaries, period);
}

#endif
