#version 450
// Debug views of the G-buffer and of the lit image before screen-space SSS (src/features/debug_view.rs).
// One permutation per view (LUCENT_VIEW_*); the result is written sRGB-encoded like the tonemap's.
// permutations-only
// permutation: LUCENT_VIEW_ALBEDO
// permutation: LUCENT_VIEW_ALBEDO LUCENT_OUTPUT_LINEAR
// permutation: LUCENT_VIEW_NORMAL
// permutation: LUCENT_VIEW_DEPTH
// permutation: LUCENT_VIEW_THICKNESS
// permutation: LUCENT_VIEW_THICKNESS LUCENT_COLORED_THICKNESS
// permutation: LUCENT_VIEW_MATERIAL
// permutation: LUCENT_VIEW_MATERIAL LUCENT_COLORED_THICKNESS
// permutation: LUCENT_VIEW_LIT
// permutation: LUCENT_VIEW_LIT LUCENT_VIEW_SECOND
// permutation: LUCENT_VIEW_TERM LUCENT_POW_MODES=3
// permutation: LUCENT_VIEW_TERM LUCENT_POW_MODES=3 LUCENT_COLORED_THICKNESS
#include "../common/scene.glsl"
#include "../common/color.glsl"
#include "../common/gbuffer.glsl"
#ifdef LUCENT_VIEW_TERM
// The GDC 2011 translucency term alone: `source` is GB0, then GB1, GB2 and depth, and the
// material table (glsl/common/translucency.glsl).
#include "../common/translucency.glsl"
layout(set = 0) uniform sampler2D gb1_tex;
layout(set = 0) uniform sampler2D gb2_tex;
layout(set = 0) uniform sampler2D depth_tex;
#endif

layout(set = 0) uniform sampler2D source;
#ifdef LUCENT_VIEW_SECOND
layout(set = 0) uniform sampler2D second;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 t = texelFetch(source, p, 0);
    vec3 c;
#if defined(LUCENT_VIEW_ALBEDO)
    c = linear_to_srgb(clamp(t.rgb, 0.0, 1.0));
#elif defined(LUCENT_VIEW_NORMAL)
    // World normal mapped from [-1, 1] to [0, 1] per axis, shown as stored (no encoding);
    // pixels no geometry wrote (a zero normal) black.
    c = dot(t.xyz, t.xyz) < 1e-6 ? vec3(0.0) : sanitize_normal(t.xyz) * 0.5 + 0.5;
#elif defined(LUCENT_VIEW_DEPTH)
    // Log of the view distance between the planes: near white, far black; sky black.
    float n = frame.camera.x, f = frame.camera.y;
    float v = t.r >= 1.0 ? 0.0 : 1.0 - log(max(linear_depth(t.r), n) / n) / log(f / n);
    c = vec3(clamp(v, 0.0, 1.0));
#elif defined(LUCENT_VIEW_THICKNESS)
    c = linear_to_srgb(clamp(unpack_thickness(t), 0.0, 1.0));
#elif defined(LUCENT_VIEW_MATERIAL)
    // Material ID as a colour that differs between neighbouring IDs; 0 (not translucent) black.
    int id = unpack_material_id(t);
    c = id == 0 ? vec3(0.0) : fract(vec3(id) * vec3(0.618034, 0.414214, 0.732051)) * 0.75 + 0.25;
#elif defined(LUCENT_VIEW_LIT)
    // The lit frame before the SSS blur: diffuse (+ specular when lit separately), tonemapped.
    vec3 hdr = t.rgb;
#ifdef LUCENT_VIEW_SECOND
    hdr += texelFetch(second, p, 0).rgb;
#endif
    c = linear_to_srgb(tonemap_aces(hdr * frame.exposure.x));
#elif defined(LUCENT_VIEW_TERM)
    // Sum over the lights of the talk's term (lobe + ambient) x thickness x albedo x light,
    // without diffuse and specular, tonemapped like the frame.
    float d = texelFetch(depth_tex, p, 0).r;
    vec3 hdr = vec3(0.0);
    vec4 g2 = texelFetch(gb2_tex, p, 0);
    int id = clamp(unpack_material_id(g2), 0, 255);
    if (d < 1.0 && id != 0) {
        Surface s = unpack_gbuffer(t, texelFetch(gb1_tex, p, 0));
        vec4 material = translucency_materials.rows[id];
        vec3 thickness = unpack_thickness(g2);
        vec3 pos = world_position(gl_FragCoord.xy, d);
        vec3 to_eye = normalize(frame.camera_pos.xyz - pos);
        float v_dot_n = dot(to_eye, s.normal);
        int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
        for (int i = 0; i < count; ++i) {
            Light light = frame.lights[i];
            vec3 to_light;
            float attenuation;
            light_incidence(light, pos, to_light, attenuation);
            float back = -(dot(to_eye, to_light) + material.y * v_dot_n);
            float lobe = translucency_lobe(back, material.x, material.w) * light.params.y;
            hdr += s.albedo * (lobe + material.z) * thickness * light.radiance_range.rgb
                   * attenuation;
        }
    }
    c = linear_to_srgb(tonemap_aces(hdr * frame.exposure.x));
#else
#error "no LUCENT_VIEW_* defined"
#endif
#ifdef LUCENT_OUTPUT_LINEAR
    // sRGB and float targets take linear values: undo the encoding the views above apply.
    c = srgb_to_linear(c);
#endif
    out_color = vec4(c, 1.0);
}
