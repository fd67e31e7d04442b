// lucent's per-pixel lighting terms for a host's own lighting pass (lucent::embed::glsl::TERMS):
// self-contained GLSL (no bindings, no includes) a host includes in the shader that loops over
// its lights, so the terms cost what they cost in lucent's own lighting pass, which calls the
// same functions (glsl/common/scene.glsl, glsl/common/translucency.glsl). The data comes from
// the Rust side: an environment's nine coefficients (`Environment::coefficients`), a
// translucent material's row (`TranslucentMaterial::row`), each light's translucency scale
// (`Light::translucency_scale`). The f64 twins are src/scene/environment.rs
// (`Environment::ambient_radiance`) and src/reference/translucency.rs: change them together.
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

#endif
