#version 450
// permutation: LUCENT_HOST_IDS_UINT LUCENT_HOST_ALBEDO
// Screen-space SSS's transmission through thin parts added to a host's lit diffuse light
// (src/embed/transmission.rs `TransmissionEffect`): for each pixel whose material has a
// medium, the light each of the host's lights sends in on the object's far side, diffused
// through the thickness the host's shadow map measures, exactly what lucent's own lighting
// pass adds (glsl/common/sss_transmission.glsl `sss_transmitted`, through lucent's shadow
// table, which the effect fills from the host's faces). Read from the host's G-buffer as the
// host describes it: its depth (device or linear), its normals (xyz or octahedral, world or
// view space), its material IDs (any of lucent::embed's encodings, mapped to media by the
// table's ID-to-profile bytes) and, when its diffuse light has the albedo multiplied in
// (LUCENT_HOST_ALBEDO), its albedo. Blended additively into the host's light; pixels without
// a medium add nothing.
#include "../common/scene.glsl"
#include "../common/gbuffer.glsl"
#include "../common/lighting.glsl"
// The media (lucent's SSS profile table, only its medium rows and host ID map filled) and
// the shadow table and map (src/embed/transmission.rs `declare`).
#define LUCENT_SHADOWS 1
// The host's shadow map may store reversed Z (glsl/common/shadows.glsl shadow_gather_flagged).
#define LUCENT_SHADOW_REVERSIBLE 1
#include "../common/sss_transmission.glsl"
#include "../common/host_ids.glsl"
#include "../common/host_normals.glsl"
#include "../common/host_depth.glsl"

// The host's encodings (src/embed/transmission.rs `HostTransmissionGpu`).
layout(std140, set = 0) uniform HostTransmission {
    uvec4 normals;         // host_normals.glsl's encoding
    uvec4 depth;           // x: 1 = linear view depth (else device depth)
    mat4 view_to_world;    // the inverse of the frame's view matrix
} host;

layout(set = 0) uniform sampler2D depth_image;
layout(set = 0) uniform sampler2D normal_image;
#ifdef LUCENT_HOST_IDS_UINT
layout(set = 0) uniform usampler2D id_image;
#else
layout(set = 0) uniform sampler2D id_image;
#endif
#ifdef LUCENT_HOST_ALBEDO
layout(set = 0) uniform sampler2D albedo_image;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int id = sss_host_profile(host_material_id(texelFetch(id_image, px, 0),
                                               sss_profiles.id_decode));
    float d = texelFetch(depth_image, px, 0).r;
    float z = linear_depth(d);
    // Pixels without a medium, and depths no surface has (NaN, Inf, behind the camera), add
    // nothing.
    if (!sss_transmits(id) || !(z > 0.0 && z < 1e30)) {
        out_color = vec4(0.0);
        return;
    }
    vec3 pos = host_world_position(gl_FragCoord.xy, d, host.depth.x != 0u, host.view_to_world);
    vec3 n = host_normal(texelFetch(normal_image, px, 0), host.normals, host.view_to_world);
    vec3 color = vec3(0.0);
    int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
    for (int i = 0; i < count; ++i) {
        vec3 to_light;
        float attenuation;
        light_incidence(frame.lights[i], pos, to_light, attenuation);
        color += sss_transmitted(id, i, pos, n, to_light);
    }
    color /= PI;
#ifdef LUCENT_HOST_ALBEDO
    vec3 albedo = texelFetch(albedo_image, px, 0).rgb;
    color *= clamp(mix(albedo, vec3(0.0), isnan(albedo)), 0.0, 1.0);
#endif
    // fp16 targets: clamp to the largest finite value (a real GPU may store +Inf otherwise).
    out_color = vec4(min(color, vec3(65504.0)), 0.0);
}
