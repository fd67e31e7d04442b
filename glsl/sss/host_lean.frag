#version 450
// LCB, LBB and the bilateral blur over a host's G-buffer (lucent::embed::SssEffect): the
// G-buffer targets those blurs read, made from what a host has. lucent's own G-buffer pass
// writes them beside GB0 and GB1 (glsl/deferred/gbuffer.frag); a host's G-buffer has no LEAN
// target, so this pass builds one from its normals:
// - location 0: the lit diffuse (with the albedo where each profile wants it before the blur,
//   as glsl/sss/host_albedo.frag does) and the view-plane LEAN slope x in alpha;
// - location 1: the LEAN slope y and moments xx, yy, xy (glsl/common/lean.glsl);
// - location 2: GB0's counterpart, albedo (white without one) and specular intensity;
// - location 3: GB1's, the normal and roughness.
// A host normal is one direction per pixel, so its LEAN texel is that of a surface without a
// LEAN map: slope mean the normal's, moments its square plus the roughness's own variance
// (view_plane_lean with zero tangent-space slopes), exactly what lucent's G-buffer writes for
// a material without a normal map. The spread a normal map has inside one pixel (what LEAN maps
// keep) is not in a host's normal image; what the blur mixes across pixels is.
// The specular intensity and roughness are the host material's (`SssMaterial::with_surface`),
// per profile; pixels without a profile get LEAN_HOST_DEFAULT_ROUGHNESS (their texels only
// weigh in where a blur's tap lands on them). LUCENT_SSS_PASSTHROUGH: the variant drawn
// outside the chains' tiles, the light alone.
#include "../common/scene.glsl"
#include "../common/sss.glsl"
#include "../common/lean.glsl"
#include "../common/host_normals.glsl"

// The host's encodings and its materials' surfaces (src/embed/sss.rs `HostLeanGpu`, std140).
layout(std140, set = 0) uniform HostLean {
    uvec4 normals;          // host_normals.glsl's encoding
    mat4 view_to_world;     // the inverse of the frame's view matrix
    vec4 surface[MAX_SSS_PROFILES];  // per profile: x roughness, y specular intensity
} host;

layout(set = 0) uniform sampler2D diffuse_tex;
layout(set = 0) uniform sampler2D normal_tex;
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;
#ifdef LUCENT_SSS_HOST_ALBEDO
layout(set = 0) uniform sampler2D albedo_tex;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_diffuse;
layout(location = 1) out vec4 out_lean;
layout(location = 2) out vec4 out_gb0;
layout(location = 3) out vec4 out_gb1;

// The roughness of a pixel no profile owns (a mid value: its LEAN texel only matters where a
// scattering pixel's tap lands on it at a similar depth).
const float LEAN_HOST_DEFAULT_ROUGHNESS = 0.5;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int id = sss_decode_id(texelFetch(profile_tex, px, 0));
    vec3 light = texelFetch(diffuse_tex, px, 0).rgb;
    vec3 albedo = vec3(1.0);
#ifdef LUCENT_SSS_HOST_ALBEDO
    albedo = sss_host_albedo(texelFetch(albedo_tex, px, 0).rgb);
    // 1: the host's light holds none of the albedo; 2: all of it.
    light *= sss_host_albedo_factor(id, albedo, LUCENT_SSS_HOST_ALBEDO == 2);
#endif
    light = clamp(mix(light, vec3(0.0), isnan(light)), vec3(0.0), vec3(65504.0));
#ifdef LUCENT_SSS_PASSTHROUGH
    // Outside every chain's tiles (the host's regions): no blur reads the LEAN texels here,
    // only the final passes' pass-through reads the light.
    out_diffuse = vec4(light, 0.0);
    out_lean = vec4(0.0);
    out_gb0 = vec4(0.0);
    out_gb1 = vec4(0.0);
    return;
#endif
    vec4 surface = id > 0 ? host.surface[id] : vec4(LEAN_HOST_DEFAULT_ROUGHNESS, 0.0, 0.0, 0.0);
    float roughness = clamp(surface.x, 0.0, 1.0);
    float specular = clamp(surface.y, 0.0, 1.0);
    vec3 n = host_normal(texelFetch(normal_tex, px, 0), host.normals, host.view_to_world);
    // Any frame around n: the tangent-space slopes are 0 and the variance isotropic.
    vec3 t, bt;
    lucent_any_tangent_frame(n, t, bt);
    vec3 n_world;
    vec2 b_v;
    vec3 m_v;
    view_plane_lean(n, t, bt, vec2(0.0), vec3(0.0), roughness_variance(roughness), n_world,
                    b_v, m_v);
    out_diffuse = vec4(light, b_v.x);
    out_lean = vec4(b_v.y, m_v);
    out_gb0 = vec4(albedo, specular);
    out_gb1 = vec4(n, roughness);
}
