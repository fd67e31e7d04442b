#version 450
// permutation: LUCENT_HOST_IDS_UINT
// GDC 2011 thickness-based translucency added to a host's lit diffuse light
// (src/embed/translucency.rs `TranslucencyEffect`): the talk's per-light term, exactly the one
// lucent's own lighting pass adds (glsl/common/translucency.glsl `translucency_transmitted`),
// read from the host's G-buffer as the host describes it: its depth (device or linear, decoded
// through its projection), its normals (xyz or octahedral, world or view space), its albedo,
// its thickness (one channel or rgb) and its material IDs (any of lucent::embed's encodings).
// The output is blended additively into the host's light; pixels whose ID has no material add
// nothing.
#include "../common/scene.glsl"
#include "../common/gbuffer.glsl"
#include "../common/lighting.glsl"
// Materials choose their pow form per row (a host's table may hold both).
#define LUCENT_POW_MODES 3
#include "../common/translucency.glsl"
#include "../common/host_ids.glsl"
#include "../common/host_normals.glsl"
#include "../common/host_depth.glsl"

// The host's encodings (src/embed/translucency.rs `HostTranslucencyGpu`).
layout(std140, set = 0) uniform HostTranslucency {
    uvec4 ids;         // host_ids.glsl's decode
    uvec4 normals;     // x: octahedral; y: view space; z: UNORM channels mapped from [0, 1]
    uvec4 thickness;   // x: the channel (0-3), 4 = rgb
    uvec4 depth;       // x: 1 = linear view depth (else device depth)
    uvec4 translucent[2];  // bit i of the 256: host ID i has a material
    mat4 view_to_world;    // the inverse of the frame's view matrix
} host;

layout(set = 0) uniform sampler2D depth_image;
layout(set = 0) uniform sampler2D normal_image;
layout(set = 0) uniform sampler2D albedo_image;
layout(set = 0) uniform sampler2D thickness_image;
#ifdef LUCENT_HOST_IDS_UINT
layout(set = 0) uniform usampler2D id_image;
#else
layout(set = 0) uniform sampler2D id_image;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

bool has_material(uint id) {
    if (id > 255u) {
        return false;
    }
    uint word = host.translucent[id / 128u][(id / 32u) % 4u];
    return ((word >> (id % 32u)) & 1u) != 0u;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    uint id = host_material_id(texelFetch(id_image, px, 0), host.ids);
    float d = texelFetch(depth_image, px, 0).r;
    float z = linear_depth(d);
    // Pixels without a material, and depths no surface has (NaN, Inf, behind the camera),
    // add nothing.
    if (!has_material(id) || !(z > 0.0 && z < 1e30)) {
        out_color = vec4(0.0);
        return;
    }
    vec3 pos = host_world_position(gl_FragCoord.xy, d, host.depth.x != 0u, host.view_to_world);
    Surface s;
    s.albedo = clamp(texelFetch(albedo_image, px, 0).rgb, 0.0, 1.0);
    s.specular = 0.0;
    s.normal = host_normal(texelFetch(normal_image, px, 0), host.normals, host.view_to_world);
    s.roughness = 1.0;
    vec4 t = texelFetch(thickness_image, px, 0);
    vec3 thickness = host.thickness.x >= 4u ? t.rgb : vec3(t[host.thickness.x]);
    // A fraction of light let through: NaN to 0, clamped to [0, 1] (as pack_gb2 does).
    thickness = clamp(mix(thickness, vec3(0.0), isnan(thickness)), 0.0, 1.0);
    s.albedo = mix(s.albedo, vec3(0.0), isnan(s.albedo));
    vec4 material = translucency_materials.rows[id];
    vec3 to_eye = normalize(frame.camera_pos.xyz - pos);
    float v_dot_n = dot(to_eye, s.normal);
    vec3 color = vec3(0.0);
    int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
        color += translucency_transmitted(s, to_eye, v_dot_n, to_light, attenuation, light,
                                          material, thickness);
    }
    // fp16 targets: clamp to the largest finite value (a real GPU may store +Inf otherwise).
    out_color = vec4(min(color, vec3(65504.0)), 0.0);
}
