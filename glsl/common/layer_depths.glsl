// Li et al.'s `TexDep` (src/scene/layered.rs): layer i of a layered medium whose thickness is
// "texture" reads channel i % 4 of its depth texture i / 4. The G-buffer pass (at the shaded
// point x_o) and the light-space maps pass (at the light's entry point P') sample the draw's
// depth textures and store all eight texels as fp16 pairs (layer 2k in the low half of
// component k, 2k + 1 in the high half): a RG32UI target holds four layers, RGBA32UI eight
// (LUCENT_LAYER_DEPTHS: how many depth textures the frame's media read, 1 or 2).
#ifndef LUCENT_LAYER_DEPTHS_GLSL
#define LUCENT_LAYER_DEPTHS_GLSL

#include "../embed/lucent_terms.glsl"

// Texture 0's texels (layers 0-3) and texture 1's (layers 4-7) as the target stores them: the
// packing a host's G-buffer pass writes too (glsl/embed/lucent_terms.glsl).
uvec4 pack_layer_texels(vec4 first, vec4 second) {
    return lucent_pack_layer_texels(first, second);
}

// Layer j's texel (0 <= j < 8) from a packed target value.
float layer_texel(uvec4 packed, int j) {
    vec2 pair = unpackHalf2x16(packed[clamp(j >> 1, 0, 3)]);
    return (j & 1) == 0 ? pair.x : pair.y;
}

#endif
