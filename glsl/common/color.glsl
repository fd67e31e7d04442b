// Tonemapping and output encoding. The f64 twin is src/reference/tonemap.rs.
#ifndef LUCENT_COLOR_GLSL
#define LUCENT_COLOR_GLSL

// Narkowicz's fit of the ACES filmic curve; input clamped to >= 0 and NaN mapped to 0 so a bad
// pixel stays one bad pixel.
vec3 tonemap_aces(vec3 x) {
    x = max(x, vec3(0.0));
    x = mix(x, vec3(0.0), isnan(x));
    x = min(x, vec3(65504.0));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// The sRGB transfer function (IEC 61966-2-1).
vec3 linear_to_srgb(vec3 c) {
    vec3 lo = c * 12.92;
    vec3 hi = 1.055 * pow(max(c, vec3(0.0031308)), vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(c, vec3(0.0031308)));
}

// Its inverse, for targets that store linear values.
vec3 srgb_to_linear(vec3 c) {
    vec3 lo = c / 12.92;
    vec3 hi = pow(max((c + 0.055) / 1.055, vec3(0.0)), vec3(2.4));
    return mix(hi, lo, lessThanEqual(c, vec3(0.04045)));
}

#endif
