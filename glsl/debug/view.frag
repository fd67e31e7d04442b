#version 450
// Debug views of the G-buffer and of the lit image before screen-space SSS (src/passes/debug_view.rs).
// One permutation per view (LUCENT_VIEW_*); the result is written sRGB-encoded like the tonemap's.
// permutations-only
// permutation: LUCENT_VIEW_ALBEDO
// permutation: LUCENT_VIEW_NORMAL
// permutation: LUCENT_VIEW_DEPTH
// permutation: LUCENT_VIEW_THICKNESS
// permutation: LUCENT_VIEW_THICKNESS LUCENT_COLORED_THICKNESS
// permutation: LUCENT_VIEW_MATERIAL
// permutation: LUCENT_VIEW_MATERIAL LUCENT_COLORED_THICKNESS
// permutation: LUCENT_VIEW_LIT
// permutation: LUCENT_VIEW_LIT LUCENT_VIEW_SECOND
#include "../common/scene.glsl"
#include "../common/color.glsl"
#include "../common/gbuffer.glsl"

layout(set = 0, binding = 1) uniform sampler2D source;
#ifdef LUCENT_VIEW_SECOND
layout(set = 0, binding = 2) uniform sampler2D second;
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
#else
#error "no LUCENT_VIEW_* defined"
#endif
    out_color = vec4(c, 1.0);
}
