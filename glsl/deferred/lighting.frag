#version 450
// permutation: LUCENT_TRANSLUCENCY
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS LUCENT_POW_MODES=1
// permutation: LUCENT_TRANSLUCENCY LUCENT_POW_MODES=2 LUCENT_SINGLE_MATERIAL
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS LUCENT_POW_MODES=3
// permutation: LUCENT_SPLIT_SPECULAR
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_FAULT_INJECTION
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_LEAN
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_LEAN LUCENT_FAULT_INJECTION
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_TRANSLUCENCY LUCENT_POW_MODES=1
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_DEPTH_IN_ALPHA
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_DEPTH_IN_ALPHA LUCENT_SSS_TEXTURING
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_SSS_TEXTURING LUCENT_TRANSLUCENCY LUCENT_POW_MODES=1
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_DEPTH_IN_ALPHA LUCENT_TRANSLUCENCY LUCENT_POW_MODES=3
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_LEAN LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS LUCENT_POW_MODES=3
// permutation: LUCENT_SHADOWS
// permutation: LUCENT_SHADOWS LUCENT_SHADOW_IDS LUCENT_TRANSLUCENCY LUCENT_POW_MODES=1
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_SHADOWS LUCENT_SHADOW_IDS LUCENT_TRANSLUCENCY LUCENT_POW_MODES=3
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_LEAN LUCENT_SHADOWS
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_SSS_TEXTURING LUCENT_SHADOWS LUCENT_SSS_MEDIUM
// permutation: LUCENT_SPLIT_SPECULAR LUCENT_SSS_TEXTURING LUCENT_SSS_MEDIUM
// Deferred lighting, merged with the G-buffer pass as its second subpass: reads the G-buffer
// only at this pixel through input attachments. With LUCENT_TRANSLUCENCY it is the variant
// drawn over the screen tiles translucent objects may cover (src/gpu_scene/tiles.rs):
// GDC 2011's per-light term joins diffuse and specular; opaque pixels in those tiles read
// thickness 0 and get none of it.
#include "../common/gbuffer.glsl"
#include "../common/lighting.glsl"
#ifdef LUCENT_TRANSLUCENCY
#include "../common/translucency.glsl"
#endif
#ifdef LUCENT_LEAN
#include "../common/lean.glsl"
#endif
#ifdef LUCENT_SHADOWS
#include "../common/shadows.glsl"
#endif
#ifdef LUCENT_SSS_TEXTURING
// SSS materials whose albedo is applied after the blur (`Texturing`): the pixel's profile ID
// (an input attachment after GB2's) and the profile table say how much of the albedo goes
// into the diffuse light.
#include "../common/sss.glsl"
#endif
#ifdef LUCENT_SSS_MEDIUM
// SSS materials with a medium: their diffuse light as the medium reflects it, and with
// LUCENT_SHADOWS the light it diffuses through the thickness the light-space maps measure
// (needs LUCENT_SSS_TEXTURING's profile IDs and table).
#include "../common/sss_medium.glsl"
#endif

// How much of light `i` reaches the pixel: x reflected, y transmitted through `material`.
vec2 light_visibility(int i, vec3 pos, vec3 normal, vec3 to_light, int material) {
#ifdef LUCENT_SHADOWS
    return shadow_visibility(i, pos, normal, to_light, material);
#else
    return vec2(1.0);
#endif
}

// How much of light `i` (attenuation `attenuation` at the pixel) reaches the surface to be
// reflected. Light that cannot reach the surface (outside the range, behind it) reflects
// nothing: no shadow lookup for it.
float reflected_visibility(int i, vec3 pos, vec3 normal, vec3 to_light, float attenuation) {
    bool lit_side = attenuation > 0.0 && dot(normal, to_light) > 0.0;
    return lit_side ? light_visibility(i, pos, normal, to_light, 0).x : 0.0;
}

#ifdef LUCENT_TRANSLUCENCY
// The translucent variant's visibility of light `i` (attenuation `attenuation` at the pixel):
// x reflected, y transmitted through translucency material `material`. The talk's term is not
// shadowed (its local thickness is its only attenuation): frames without a `shadowed`
// material (no ID atlas) look up reflected light only, and only where the light reaches the
// surface, as the plain variant does. Frames with one look up every light that reaches the
// pixel, from behind too, once, and a material that is not `shadowed` keeps only the
// reflected part: llvmpipe runs both sides of a per-pixel branch, so a branch between the two
// lookups would make every pixel pay for both.
vec2 translucent_visibility(int i, vec3 pos, vec3 normal, vec3 to_light, float attenuation,
                            int material, bool shadowed) {
#ifdef LUCENT_SHADOW_IDS
    vec2 visible = attenuation > 0.0 ? light_visibility(i, pos, normal, to_light, material)
                                     : vec2(0.0);
    return shadowed ? visible : vec2(visible.x, 1.0);
#else
    return vec2(reflected_visibility(i, pos, normal, to_light, attenuation), 1.0);
#endif
}
#endif

layout(input_attachment_index = 0, set = 0) uniform subpassInput gb0;
layout(input_attachment_index = 1, set = 0) uniform subpassInput gb1;
layout(input_attachment_index = 2, set = 0) uniform subpassInput depth;
#ifdef LUCENT_TRANSLUCENCY
layout(input_attachment_index = 3, set = 0) uniform subpassInput gb2;
#endif
#ifdef LUCENT_SSS_TEXTURING
#ifdef LUCENT_TRANSLUCENCY
layout(input_attachment_index = 4, set = 0)
    uniform subpassInput profile_ids;
#else
layout(input_attachment_index = 3, set = 0)
    uniform subpassInput profile_ids;
#endif
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;
#ifdef LUCENT_SPLIT_SPECULAR
// Screen-space SSS blurs the diffuse light only: specular goes to its own target, added back
// after the blur (out_color is then the diffuse part).
layout(location = 1) out vec4 out_specular;
#endif

void main() {
    float d = subpassLoad(depth).r;
    if (d >= 1.0) {
#ifdef LUCENT_DEPTH_IN_ALPHA
        // The separable SSS blur reads linear depth from alpha: the sky is at the far plane.
        out_color = vec4(frame.sky.rgb, frame.camera.y);
#else
        out_color = vec4(frame.sky.rgb, 1.0);
#endif
#ifdef LUCENT_SPLIT_SPECULAR
        out_specular = vec4(0.0);
#endif
        return;
    }
    Surface s = unpack_gbuffer(subpassLoad(gb0), subpassLoad(gb1));
#ifdef LUCENT_SSS_TEXTURING
    // The diffuse light carries only the part of the albedo the profile applies before the
    // blur; the chain's last pass multiplies in the rest (glsl/common/sss.glsl).
    int sss_id = sss_profile_id(subpassLoad(profile_ids).r);
    s.albedo = sss_albedo_before(sss_id, s.albedo);
#endif
    vec3 pos = world_position(gl_FragCoord.xy, d);
    vec3 to_eye = normalize(frame.camera_pos.xyz - pos);
#ifdef LUCENT_SSS_MEDIUM
    // Only pixels whose profile has a medium shade as it and look up thicknesses (a branch
    // the pixels of one object take alike; the rest of the frame skips it).
    bool medium = sss_has_medium(sss_id);
    float n_dot_v = max(dot(s.normal, to_eye), 0.0);
    vec3 h_view = medium ? sss_medium_h(sss_id, n_dot_v) : vec3(1.0);
#ifdef LUCENT_SHADOWS
    bool transmits = medium && sss_transmits(sss_id);
#endif
#endif
    vec3 color = ambient_radiance(s.normal) * s.albedo;
    int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
#ifdef LUCENT_TRANSLUCENCY
    // This variant runs only on tiles translucent objects may cover (the plain variant shades
    // the rest), so it never branches on the material ID to skip work.
    vec4 t = subpassLoad(gb2);
    int material_id = clamp(unpack_material_id(t), 0, 255);
#ifdef LUCENT_SINGLE_MATERIAL
    vec4 material = translucency_materials.rows[1];
#else
    vec4 material = translucency_materials.rows[material_id];
#endif
    vec3 thickness = unpack_thickness(t);
    float v_dot_n = dot(to_eye, s.normal);
    bool shadowed = translucency_shadowed(material);
#endif
#if defined(LUCENT_TRANSLUCENCY) && !defined(LUCENT_SPLIT_SPECULAR)
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
        vec2 visible = translucent_visibility(i, pos, s.normal, to_light, attenuation,
                                              material_id, shadowed);
        color += shade_incident_translucent(s, to_eye, v_dot_n, to_light, attenuation * visible.x,
                                            attenuation * visible.y, light, material, thickness);
    }
#elif defined(LUCENT_SPLIT_SPECULAR)
    vec3 specular = vec3(0.0);
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
#ifdef LUCENT_TRANSLUCENCY
        vec2 visible = translucent_visibility(i, pos, s.normal, to_light, attenuation,
                                              material_id, shadowed);
#else
        vec2 visible = light_visibility(i, pos, s.normal, to_light, 0);
#endif
        float n_dot_l = max(dot(s.normal, to_light), 0.0);
        vec3 incident = light.radiance_range.rgb * (n_dot_l * attenuation * visible.x);
        specular += s.specular * blinn_phong(s, to_eye, to_light) * incident;
#ifdef LUCENT_SSS_MEDIUM
        if (medium) {
            incident *= sss_medium_reflectance(sss_id, n_dot_l, n_dot_v, h_view);
        }
#endif
        color += s.albedo / PI * incident;
#if defined(LUCENT_SSS_MEDIUM) && defined(LUCENT_SHADOWS)
        // Light diffused through the object from its far side joins the diffuse before the
        // blur, which spreads it, with the albedo's part the diffuse light carries.
        if (transmits) {
            color += s.albedo / PI * sss_transmitted(sss_id, i, pos, s.normal, to_light);
        }
#endif
#ifdef LUCENT_TRANSLUCENCY
        // Transmitted light joins the diffuse: the SSS blur diffuses it too.
        color += translucency_transmitted(s, to_eye, v_dot_n, to_light, attenuation * visible.y,
                                          light, material, thickness);
#endif
    }
    out_specular = vec4(min(specular, vec3(65504.0)), 1.0);
#ifdef LUCENT_LEAN
    // LCB and LBB blur (diffuse.rgb, view slope x) as one texel: the G-buffer's LEAN target
    // holds the rest. The slope is the mean normal's, as the G-buffer pass computed it.
    float slope_x = view_slope(mat3(frame.view) * s.normal).x;
#endif
#else
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
        float visible = reflected_visibility(i, pos, s.normal, to_light, attenuation);
        color += shade_incident(s, to_eye, to_light, attenuation * visible, light);
    }
#endif
    // fp16 target: clamp to its largest finite value (a real GPU may store +Inf otherwise).
#ifdef LUCENT_LEAN
    out_color = vec4(min(color, vec3(65504.0)), slope_x);
#elif defined(LUCENT_DEPTH_IN_ALPHA)
    // The separable SSS blur's taps read the light and its depth in one fetch.
    out_color = vec4(min(color, vec3(65504.0)), linear_depth(d));
#else
    out_color = vec4(min(color, vec3(65504.0)), 1.0);
#endif
#ifdef LUCENT_FAULT_INJECTION
    // Robustness tests: one poisoned pixel, to prove later passes keep it from spreading.
    if (all(equal(ivec2(gl_FragCoord.xy), frame.fault.xy)) && frame.fault.z != 0) {
        float bad = uintBitsToFloat(frame.fault.z == 1 ? 0x7fc00000u : 0x7f800000u);
        out_color = vec4(vec3(bad), 1.0);
    }
#endif
}
