// Direct lighting: Lambert diffuse + normalised Blinn-Phong specular; point, spot and
// directional lights. The f64 twin is src/reference/lighting.rs: change both together.
#ifndef LUCENT_LIGHTING_GLSL
#define LUCENT_LIGHTING_GLSL

#include "scene.glsl"

const float PI = 3.14159265358979;

// Blinn-Phong exponent from roughness: 2^(11 - 10 r), in [2, 2048] (glsl/embed/lucent_terms.glsl).
float shininess(float roughness) {
    return lucent_shininess(roughness);
}

// Direction towards the light (normalised) and its attenuation at `pos`.
void light_incidence(Light light, vec3 pos, out vec3 to_light, out float attenuation) {
    if (int(light.position_type.w) == LIGHT_DIRECTIONAL) {
        to_light = -normalize(light.position_type.xyz);
        attenuation = 1.0;
        return;
    }
    vec3 d = light.position_type.xyz - pos;
    // Clamp the distance: a light on the surface would otherwise divide by zero.
    float dist2 = max(dot(d, d), 1e-4);
    to_light = d * inversesqrt(dist2);
    float range = max(light.radiance_range.a, 1e-4);
    float ratio = sqrt(dist2) / range;
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    attenuation = window * window / dist2;
    if (int(light.position_type.w) == LIGHT_SPOT) {
        // Smooth cone edge; the width is clamped so inner == outer cannot divide by zero.
        float cos_angle = dot(-to_light, light.spot.xyz);
        float width = max(light.params.x - light.spot.w, 1e-4);
        float t = clamp((cos_angle - light.spot.w) / width, 0.0, 1.0);
        attenuation *= t * t;
    }
}

// The normalised Blinn-Phong lobe (without the surface's specular intensity).
float blinn_phong(Surface s, vec3 to_eye, vec3 to_light) {
    vec3 h = to_light + to_eye;
    // to_light == -to_eye gives h = 0: no highlight rather than a NaN.
    float h_len2 = dot(h, h);
    h = h_len2 > 1e-12 ? h * inversesqrt(h_len2) : s.normal;
    float n = shininess(s.roughness);
    return (n + 8.0) / (8.0 * PI) * pow(max(dot(s.normal, h), 0.0), n);
}

// Diffuse + specular from one light whose direction and attenuation are known.
vec3 shade_incident(Surface s, vec3 to_eye, vec3 to_light, float attenuation, Light light) {
    float n_dot_l = max(dot(s.normal, to_light), 0.0);
    vec3 brdf = s.albedo / PI + vec3(s.specular * blinn_phong(s, to_eye, to_light));
    return brdf * light.radiance_range.rgb * (n_dot_l * attenuation);
}

vec3 shade_direct(Surface s, vec3 pos, vec3 to_eye, Light light) {
    vec3 to_light;
    float attenuation;
    light_incidence(light, pos, to_light, attenuation);
    return shade_incident(s, to_eye, to_light, attenuation, light);
}

#endif
