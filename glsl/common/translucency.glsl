// GDC 2011 thickness-based translucency (Barre-Brisebois and Bouchard, Frostbite 2), the talk's
// formula exactly, with its pow either exact or in the spherical-Gaussian form exp2(n*x - n)
// (seeds/spherical-gaussian-pow-translucency.txt). The f64 twin is src/reference/translucency.rs:
// change both together.
#ifndef LUCENT_TRANSLUCENCY_GLSL
#define LUCENT_TRANSLUCENCY_GLSL

#define POW_EXACT 0
#define POW_SPHERICAL_GAUSSIAN 1

// x: power (iLTPower), y: distortion (fLTDistortion), z: ambient (fLTAmbient), w: pow mode.
// Row 0 is unused: material ID 0 means "not translucent".
layout(std140, set = 0, binding = 5) uniform TranslucencyMaterials {
    vec4 rows[256];
} translucency_materials;

// x^n for x in [0, 1], n >= 0. pow(0, 0) is undefined in GLSL (and pow(x, y) for x <= 0 in
// general): the base is clamped to a tiny positive value, so n = 0 gives exactly 1 and large n
// underflow to 0 instead of NaN.
float translucency_lobe(float x, float n, float mode) {
    x = clamp(x, 0.0, 1.0);
    if (mode == float(POW_SPHERICAL_GAUSSIAN)) {
        // exp2(n*x - n) = exp2(n (x - 1)) <= 1: no overflow for any n >= 0.
        return exp2(n * (x - 1.0));
    }
    return pow(max(x, 1e-30), n);
}

// The talk's per-light term:
//   vLTLight = L + N * distortion
//   dot = pow(saturate(dot(V, -vLTLight)), power) * scale
//   lt = attenuation * (dot + ambient) * thickness
//   colour += albedo * lightColour * lt
// `to_light` is L, `to_eye` V, `radiance` the light's colour times intensity.
vec3 translucency_term(vec3 albedo, vec3 normal, vec3 to_eye, vec3 to_light, float attenuation,
                       vec3 radiance, float scale, vec4 material, vec3 thickness) {
    vec3 lt_light = to_light + normal * material.y;
    float lobe = translucency_lobe(dot(to_eye, -lt_light), material.x, material.w) * scale;
    vec3 lt = attenuation * (lobe + material.z) * thickness;
    return albedo * radiance * lt;
}

#endif
