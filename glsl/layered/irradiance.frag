#version 450
// permutation: LUCENT_SHADOWS
// permutation: LUCENT_SHADOWS LUCENT_HALF_RES
// Li et al.'s diffuse irradiance image (src/features/layered.rs, `layered irradiance`): per
// pixel of a layered object, the light transmitted into its surface (shadowed), the pixel
// lights multiple scattering gathers. At half resolution each texel takes the top-left pixel
// of its 2x2 block. Set 0 as glsl/common/layered.glsl, then the shadow bindings.
#include "../common/layered.glsl"

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_irradiance;

void main() {
#ifdef LUCENT_HALF_RES
    ivec2 px = ivec2(gl_FragCoord.xy) * 2;
#else
    ivec2 px = ivec2(gl_FragCoord.xy);
#endif
    px = min(px, ivec2(frame.viewport.xy) - 1);
    int id = layered_id_at(px);
    if (id == 0) {
        out_irradiance = vec4(0.0);
        return;
    }
    int mat = layered_row(id);
    vec3 pos = layered_position_at(px);
    vec3 n = layered_normal_at(px);
    // Alpha: the layered material ID, so the gather reads a pixel light's material with it.
    out_irradiance = vec4(finite_term(transmitted_irradiance(pos, n, MAT.info.y, MAT.weights.w)), float(id));
}
