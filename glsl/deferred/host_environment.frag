#version 450
// permutation: LUCENT_HOST_ALBEDO
// The SH environment's diffuse light added to a host's lit diffuse light
// (src/embed/environment.rs `EnvironmentEffect`): the ambient term lucent's own lighting pass
// adds to every surface, `ambient_radiance(n) * albedo` (glsl/common/scene.glsl, unshadowed),
// read from the host's G-buffer as the host describes it: its depth (only to tell surfaces
// from the background the host cleared), its normals (xyz or octahedral, world or view space)
// and, when the host's diffuse light has the albedo multiplied in (LUCENT_HOST_ALBEDO), its
// albedo. The output is blended additively into the host's light; background pixels add
// nothing.
#include "../common/scene.glsl"
#include "../common/gbuffer.glsl"
#include "../common/host_normals.glsl"

// The host's encodings (src/embed/environment.rs `HostEnvironmentGpu`).
layout(std140, set = 0) uniform HostEnvironment {
    uvec4 normals;       // host_normals.glsl's encoding
    uvec4 depth;         // x: 1 = linear view depth (else device depth); y: 1 = the
                         // background's device depth is 1 (standard Z), 0: it is 0 (reversed)
    vec4 far;            // x: the view depth from which a depth is the background: the far
                         // plane's less its f32 rounding (3.0e38 for an infinite far plane)
    mat4 view_to_world;  // the inverse of the frame's view matrix
} host;

layout(set = 0) uniform sampler2D depth_image;
layout(set = 0) uniform sampler2D normal_image;
#ifdef LUCENT_HOST_ALBEDO
layout(set = 0) uniform sampler2D albedo_image;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// Whether depth value `d` is the background the host cleared to rather than a surface: the
// far end of the device depth range (1 for standard Z, 0 for reversed), a depth at or past
// the far plane (within its f32 rounding), and any depth no surface has (NaN, Inf, at or
// behind the camera).
bool is_background(float d) {
    float z = linear_depth(d);
    if (!(z > 0.0 && z < 1e30) || z >= host.far.x) {
        return true;
    }
    if (host.depth.x != 0u) {
        return false;
    }
    return host.depth.y != 0u ? d >= 1.0 : d <= 0.0;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    if (is_background(texelFetch(depth_image, px, 0).r)) {
        out_color = vec4(0.0);
        return;
    }
    vec3 n = host_normal(texelFetch(normal_image, px, 0), host.normals, host.view_to_world);
    vec3 color = ambient_radiance(n);
#ifdef LUCENT_HOST_ALBEDO
    // An albedo outside [0, 1] (or NaN) in the host's image is clamped, as lucent's own
    // G-buffer stores it (RGBA8).
    vec3 albedo = texelFetch(albedo_image, px, 0).rgb;
    color *= clamp(mix(albedo, vec3(0.0), isnan(albedo)), 0.0, 1.0);
#endif
    // fp16 targets: clamp to the largest finite value (a real GPU may store +Inf otherwise).
    out_color = vec4(min(color, vec3(65504.0)), 0.0);
}
