// GDC 2011 thickness-based translucency (Barre-Brisebois and Bouchard, Frostbite 2), the talk's
// formula exactly, with its pow either exact or in the spherical-Gaussian form exp2(n*x - n)
// (seeds/spherical-gaussian-pow-translucency.txt). The f64 twins are in
// src/reference/translucency.rs (translucency_lobe, and translucency_term + shade_direct for
// shade_incident_translucent): change both together.
#ifndef LUCENT_TRANSLUCENCY_GLSL
#define LUCENT_TRANSLUCENCY_GLSL

#include "gbuffer.glsl"
#include "lighting.glsl"
#include "../embed/lucent_terms.glsl"

#define POW_EXACT 0
#define POW_SPHERICAL_GAUSSIAN 1
// Added to a row's pow mode when other objects' shadows fall on the material's transmitted
// light (src/features/translucency.rs, SHADOWED): lucent's extension; the talk's term is
// attenuated by its local thickness alone.
#define TRANSLUCENCY_SHADOWED 2.0

// x: power (iLTPower), y: distortion (fLTDistortion), z: ambient (fLTAmbient), w: pow mode
// (+ TRANSLUCENCY_SHADOWED). Row 0 is unused: material ID 0 means "not translucent".
layout(std140, set = 0) uniform TranslucencyMaterials {
    vec4 rows[256];
} translucency_materials;

// x^n for x in [0, 1], n >= 0, in a row's pow form (glsl/embed/lucent_terms.glsl: the talk's
// lobe as a host's lighting pass includes it). LUCENT_POW_MODES says which forms the frame's
// materials use (1 exact, 2 exp2, 3 both): a frame compiles only its forms.
float translucency_lobe(float x, float n, float mode) {
    return lucent_translucency_lobe(x, n, mode);
}

// Diffuse + specular + the talk's per-light term from one light:
//   vLTLight = L + N * distortion
//   dot = pow(saturate(dot(V, -vLTLight)), power) * scale
//   lt = attenuation * (dot + ambient) * thickness
//   colour += albedo * lightColour * lt
// computed with what the terms share: diffuse is albedo * lightColour * attenuation *
// n_dot_l / pi, so the talk's term joins it as one more factor of albedo. And `v_dot_n` is
// dot(V, N), the same for every light: dot(V, -(L + N d)) = -(dot(V, L) + d dot(V, N)), so the
// distorted light vector is never built. Equal, up to rounding, to shade_incident plus the
// talk's term (the reference evaluates them separately).
// `reflected` is the light's attenuation times its shadow visibility at the surface,
// `transmitted` the same with the visibility of light through the pixel's own material
// (glsl/common/shadows.glsl): the object's own front faces do not shadow the talk's term.
vec3 shade_incident_translucent(Surface s, vec3 to_eye, float v_dot_n, vec3 to_light,
                                float reflected, float transmitted, Light light,
                                vec4 material, vec3 thickness) {
    float n_dot_l = max(dot(s.normal, to_light), 0.0);
    float spec = blinn_phong(s, to_eye, to_light);
    float back = -(dot(to_eye, to_light) + material.y * v_dot_n);
    float lobe = translucency_lobe(back, material.x, material.w) * light.params.y;
    vec3 diffuse = s.albedo * (n_dot_l / PI * reflected + (lobe + material.z) * thickness * transmitted);
    return (diffuse + vec3(s.specular * spec * n_dot_l * reflected)) * light.radiance_range.rgb;
}

// Whether other objects' shadows fall on the transmitted light of a material (its table row).
bool translucency_shadowed(vec4 material) {
    return material.w >= TRANSLUCENCY_SHADOWED;
}

// The talk's term alone (what shade_incident_translucent adds to diffuse + specular): the
// light let through to the eye, albedo * lightColour * attenuation * (lobe + ambient) *
// thickness. Frames with screen-space SSS add it to the diffuse light, so the blur also
// diffuses the light coming through thin parts (transmission plus diffusion on one skin).
vec3 translucency_transmitted(Surface s, vec3 to_eye, float v_dot_n, vec3 to_light,
                              float attenuation, Light light, vec4 material, vec3 thickness) {
    return lucent_translucency(s.albedo, thickness, material, to_eye, v_dot_n, to_light,
                               light.radiance_range.rgb, attenuation, light.params.y);
}

#endif
