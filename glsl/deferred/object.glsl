// Per-object push constants of the G-buffer pass (`ObjectConstants` in src/gpu_scene/mod.rs).
#ifndef LUCENT_OBJECT_GLSL
#define LUCENT_OBJECT_GLSL

layout(push_constant) uniform Object {
    mat4 model;
    vec4 albedo_specular;
    vec4 roughness;   // x: roughness; y: screen-space SSS profile ID (0: none); z: layered material ID
    vec4 thickness;   // rgb: tint x constant thickness; w: translucency material ID (0: none)
} object;

#endif
