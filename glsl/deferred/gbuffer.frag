#version 450
// permutation: LUCENT_TRANSLUCENCY
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS
// permutation: LUCENT_SSS_STRENGTH
#include "../common/gbuffer.glsl"
#include "object.glsl"

layout(location = 0) in vec3 in_normal;
#ifdef LUCENT_TRANSLUCENCY
layout(location = 1) in vec3 in_thickness;
layout(location = 2) out vec4 out_gb2;
#endif
#ifdef LUCENT_SSS_STRENGTH
// Screen-space SSS strength (0: the pixel does not scatter), for the blur passes.
layout(location = 2) out vec4 out_sss;
#endif

layout(location = 0) out vec4 out_gb0;
layout(location = 1) out vec4 out_gb1;

void main() {
    Surface s;
    s.albedo = object.albedo_specular.rgb;
    s.specular = object.albedo_specular.a;
    s.normal = in_normal;
    s.roughness = object.roughness.x;
    out_gb0 = pack_gb0(s);
    out_gb1 = pack_gb1(s);
#ifdef LUCENT_TRANSLUCENCY
    out_gb2 = pack_gb2(in_thickness, int(object.thickness.w + 0.5));
#endif
#ifdef LUCENT_SSS_STRENGTH
    out_sss = vec4(clamp(object.roughness.y, 0.0, 1.0));
#endif
}
