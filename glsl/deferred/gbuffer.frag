#version 450
// permutation: LUCENT_TRANSLUCENCY
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS
// permutation: LUCENT_SSS_PROFILE
// permutation: LUCENT_LAYERED
// permutation: LUCENT_SSS_PROFILE LUCENT_LAYERED LUCENT_SSS_LOCATION=2 LUCENT_LAYERED_LOCATION=3
// permutation: LUCENT_LAYERED LUCENT_LAYER_DEPTHS=1 LUCENT_LAYER_DEPTH_LOCATION=3
// permutation: LUCENT_LAYERED LUCENT_LAYER_DEPTHS=2 LUCENT_LAYER_DEPTH_LOCATION=3 LUCENT_ALBEDO_MAP
// permutation: LUCENT_NORMAL_MAP
// permutation: LUCENT_SSS_PROFILE LUCENT_NORMAL_MAP
// permutation: LUCENT_SSS_PROFILE LUCENT_LEAN
// permutation: LUCENT_SSS_PROFILE LUCENT_LEAN LUCENT_NORMAL_MAP
// permutation: LUCENT_ALBEDO_MAP
// permutation: LUCENT_NORMAL_MAP LUCENT_ALBEDO_MAP
// permutation: LUCENT_TRANSLUCENCY LUCENT_SSS_PROFILE LUCENT_GB2_LOCATION=2 LUCENT_SSS_LOCATION=3
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS LUCENT_SSS_PROFILE LUCENT_LEAN LUCENT_NORMAL_MAP LUCENT_ALBEDO_MAP LUCENT_GB2_LOCATION=2 LUCENT_SSS_LOCATION=3 LUCENT_LEAN_LOCATION=4
// The G-buffer pass (src/features/deferred.rs): GB0 and GB1 at locations 0 and 1, then the
// targets the frame's materials need at the locations the defines give (GB2 with
// translucency, the SSS profile ID with SSS, the LEAN target with LCB or LBB blurs, the
// layered ID and TexDep texels with layered media). Set 0: the frame uniforms, then the
// material textures the frame has (normal or LEAN map 1, LEAN map 2, albedo map, layer depth
// textures), each bound by its name (src/features/gbuffer.rs `bindings`).
#ifndef LUCENT_GB2_LOCATION
#define LUCENT_GB2_LOCATION 2
#endif
#ifndef LUCENT_SSS_LOCATION
#define LUCENT_SSS_LOCATION 2
#endif
#ifndef LUCENT_LEAN_LOCATION
#define LUCENT_LEAN_LOCATION 3
#endif
#ifndef LUCENT_LAYERED_LOCATION
#define LUCENT_LAYERED_LOCATION 2
#endif
#ifndef LUCENT_LAYER_DEPTH_LOCATION
#define LUCENT_LAYER_DEPTH_LOCATION 3
#endif
#include "../common/gbuffer.glsl"
#include "object.glsl"
#ifdef LUCENT_LEAN
#include "../common/lean.glsl"
// LCB and LBB: the view-plane LEAN slope y and moments xx, yy, xy (slope x travels in the
// lighting pass's diffuse alpha: the blurs read both targets as two RGBA texels).
layout(location = LUCENT_LEAN_LOCATION) out vec4 out_lean;
#endif

layout(location = 0) in vec3 in_normal;
#if defined(LUCENT_NORMAL_MAP) || defined(LUCENT_ALBEDO_MAP) || defined(LUCENT_LAYER_DEPTHS)
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_tangent;
#endif
#ifdef LUCENT_ALBEDO_MAP
// Albedo texture (decoded from sRGB to linear at load), multiplied with the material's albedo.
layout(set = 0) uniform sampler2D albedo_map;
#endif
#ifdef LUCENT_NORMAL_MAP
// Tangent-space normal map, stored as n * 0.5 + 0.5.
layout(set = 0) uniform sampler2D normal_map;

// The shading normal: the map's normal in the interpolated tangent frame. A degenerate frame
// (zero tangent, or one parallel to the normal) falls back to the vertex normal.
vec3 mapped_normal(vec3 n) {
    vec3 t = in_tangent.xyz - n * dot(n, in_tangent.xyz);
    float t_len2 = dot(t, t);
    if (!(t_len2 > 1e-12)) {
        return n;
    }
    t *= inversesqrt(t_len2);
    vec3 b = cross(n, t) * (in_tangent.w < 0.0 ? -1.0 : 1.0);
    vec3 m = texture(normal_map, in_uv).xyz * 2.0 - 1.0;
    return t * m.x + b * m.y + n * m.z;
}
#ifdef LUCENT_LEAN
// In LEAN frames `normal_map` holds LEAN map 1 (slope mean xy, moments xx yy) instead of the
// normal map, and `lean2_map` LEAN map 2 (moment xy), mip-filtered like any texture: filtering
// moments is what LEAN mapping is for.
layout(set = 0) uniform sampler2D lean2_map;
#endif
#endif
#ifdef LUCENT_TRANSLUCENCY
layout(location = 1) in vec3 in_thickness;
layout(location = LUCENT_GB2_LOCATION) out vec4 out_gb2;
#endif
#ifdef LUCENT_SSS_PROFILE
// Screen-space SSS profile ID / 255 (0: the pixel does not scatter), for the blur passes.
layout(location = LUCENT_SSS_LOCATION) out vec4 out_sss;
#endif

#ifdef LUCENT_LAYERED
// Li et al.'s layered material ID / 255 (0: not layered) in r, for the scattering passes;
// with albedo maps, the albedo texture's texel in gba (white for a draw without one): the
// pigment film single scattering applies to the light leaving a layered surface
// (glsl/layered/single.frag, LUCENT_LAYERED_FILM). The target is RGBA only when a layered
// material has a texture (GBufferLayout::layered_format); an R8 target drops gba.
layout(location = LUCENT_LAYERED_LOCATION) out vec4 out_layered;
#endif

#ifdef LUCENT_LAYER_DEPTHS
#include "../common/layer_depths.glsl"
// Li et al.'s TexDep: the draw's depth textures (linear data; a draw without them binds a
// zero texture) and their texels at this pixel, packed for single scattering.
layout(set = 0) uniform sampler2D depth_map0;
#if LUCENT_LAYER_DEPTHS > 1
layout(set = 0) uniform sampler2D depth_map1;
#endif
layout(location = LUCENT_LAYER_DEPTH_LOCATION) out uvec4 out_layer_depths;
#endif

layout(location = 0) out vec4 out_gb0;
layout(location = 1) out vec4 out_gb1;

void main() {
    Surface s;
    s.albedo = object.albedo_specular.rgb;
    vec3 albedo_texel = vec3(1.0);
#ifdef LUCENT_ALBEDO_MAP
    albedo_texel = texture(albedo_map, in_uv).rgb;
    s.albedo *= albedo_texel;
#endif
    s.specular = object.albedo_specular.a;
#if defined(LUCENT_LEAN)
    vec3 n = sanitize_normal(in_normal);
    vec3 t, bt;
    vec2 b_t = vec2(0.0);
    vec3 m_t = vec3(0.0);
#ifdef LUCENT_NORMAL_MAP
    t = in_tangent.xyz - n * dot(n, in_tangent.xyz);
    bool frame_ok = dot(t, t) > 1e-12;
    if (frame_ok) {
        vec4 lean1 = texture(normal_map, in_uv);
        b_t = lean1.xy;
        m_t = vec3(lean1.zw, texture(lean2_map, in_uv).x);
    }
#else
    t = vec3(0.0);
    bool frame_ok = false;
#endif
    // Without a map (or a usable tangent) any frame around n serves: the slopes are 0 and the
    // roughness variance is isotropic.
    vec3 any_t, any_bt;
    lucent_any_tangent_frame(n, any_t, any_bt);
    t = frame_ok ? normalize(t) : any_t;
    bt = cross(n, t);
#ifdef LUCENT_NORMAL_MAP
    bt *= in_tangent.w < 0.0 ? -1.0 : 1.0;
#endif
    vec2 b_v;
    vec3 m_v;
    view_plane_lean(n, t, bt, b_t, m_t, roughness_variance(object.roughness.x), s.normal, b_v,
                    m_v);
    out_lean = vec4(b_v.y, m_v);
#elif defined(LUCENT_NORMAL_MAP)
    s.normal = mapped_normal(sanitize_normal(in_normal));
#else
    s.normal = in_normal;
#endif
    s.roughness = object.roughness.x;
    out_gb0 = pack_gb0(s);
    out_gb1 = pack_gb1(s);
#ifdef LUCENT_TRANSLUCENCY
    out_gb2 = pack_gb2(in_thickness, int(object.thickness.w + 0.5));
#endif
#ifdef LUCENT_SSS_PROFILE
    out_sss = vec4(clamp(object.roughness.y, 0.0, 255.0) / 255.0);
#endif
#ifdef LUCENT_LAYERED
    out_layered = vec4(clamp(object.roughness.z, 0.0, 255.0) / 255.0,
                       clamp(albedo_texel, vec3(0.0), vec3(1.0)));
#endif
#ifdef LUCENT_LAYER_DEPTHS
    vec4 second = vec4(0.0);
#if LUCENT_LAYER_DEPTHS > 1
    second = texture(depth_map1, in_uv);
#endif
    out_layer_depths = pack_layer_texels(texture(depth_map0, in_uv), second);
#endif
}
