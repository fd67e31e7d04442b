// Frame uniforms shared by every pass: camera, lights, ambient, sky.
// Layout must match `FrameUniforms` in src/gpu_scene/per_frame.rs (std140); a region of the per-frame buffer, bound at each frame-in-flight slot.
#ifndef LUCENT_SCENE_GLSL
#define LUCENT_SCENE_GLSL

#include "../embed/lucent_terms.glsl"

#define MAX_LIGHTS 64
#define LIGHT_DIRECTIONAL 0
#define LIGHT_POINT 1
#define LIGHT_SPOT 2

struct Light {
    vec4 position_type;   // xyz: position (point, spot) or direction the light travels (directional); w: type
    vec4 radiance_range;  // rgb: colour * intensity; a: range (point and spot lights fade to 0 there)
    vec4 spot;            // xyz: unit direction the cone points; w: cos(outer half-angle)
    vec4 params;          // x: cos(inner half-angle); y: translucency scale (GDC 2011 fLTScale)
};

layout(std140, set = 0) uniform Frame {
    mat4 view_proj;
    mat4 inv_view_proj;
    mat4 view;            // world to view space (right-handed, the camera looks down -z)
    vec4 camera_pos;      // xyz
    vec4 ambient_sh[9];   // rgb: the environment's E(n) / pi as nine polynomial coefficients;
                          // [0].w: SH bands in use (1 constant, 2 hemisphere, 3 map)
    vec4 sky;             // rgb: colour of pixels no geometry covers
    vec4 viewport;        // xy: size in pixels, zw: 1 / size
    vec4 exposure;        // x: exposure multiplier applied before tonemapping
    ivec4 light_count;    // x
    vec4 camera;          // x: near, y: far, z: focal length in pixels (height / 2 tan(fov / 2))
    vec4 depth_decode;    // view-space depth from the depth image's value d: (x + y d) / (z + w d),
                          // from the projection (any near and far, standard or reversed, finite
                          // or infinite far) or the identity for a linear depth image (embedding)
    ivec4 fault;          // robustness tests (LUCENT_FAULT_INJECTION): x, y pixel; z 1 NaN, 2 +Inf
    Light lights[MAX_LIGHTS];
} frame;

// The environment's diffuse light at unit normal n: E(n) / pi, the radiance a Lambertian
// albedo multiplies (glsl/embed/lucent_terms.glsl, which a host's lighting pass includes too).
vec3 ambient_radiance(vec3 n) {
    return lucent_sh_ambient(frame.ambient_sh, n);
}

// World position of the surface at window position `frag_coord` (gl_FragCoord.xy) with device
// depth `device_depth`.
vec3 world_position(vec2 frag_coord, float device_depth) {
    vec2 ndc = frag_coord * frame.viewport.zw * 2.0 - 1.0;
    vec4 world = frame.inv_view_proj * vec4(ndc, device_depth, 1.0);
    return world.xyz / world.w;
}

// View-space distance along the view axis from the depth image's value (a device depth of the
// frame's projection, or a host's linear depth). The coefficients are scaled so that the larger
// of z and w is 1 and the denominator is positive over the depth range: the clamp keeps the far
// plane of an infinite projection (d = 0 reversed, d = 1 standard) finite instead of Inf.
float linear_depth(float device_depth) {
    vec4 k = frame.depth_decode;
    return (k.x + k.y * device_depth) / max(k.z + k.w * device_depth, 1e-7);
}

// Whether a pixel's device depth is a surface's a blur may use: its linear depth positive and
// finite (a NaN or Inf in a depth image keeps the pixel out of the blur rather than poisoning
// its neighbours). The background is told by its material ID (0), not by its depth: "1.0 is
// the far plane" holds for none of a host's reversed, infinite or linear depth images.
bool depth_is_surface(float device_depth) {
    float z = linear_depth(device_depth);
    return z > 0.0 && z < 1e30;
}

#endif
