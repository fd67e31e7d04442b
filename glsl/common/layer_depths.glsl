// Li et al.'s `TexDep` (src/scene/layered.rs): layer i of a layered medium whose thickness is
// "texture" reads channel i % 4 of its depth texture i / 4. The G-buffer pass (at the shaded
// point x_o) and the light-space maps pass (at the light's entry point P') sample the draw's
// depth textures and store all eight texels as fp16 pairs (layer 2k in the low half of
// component k, 2k + 1 in the high half): a RG32UI target holds four layers, RGBA32UI eight
// (LUCENT_LAYER_DEPTHS: how many depth textures the frame's media read, 1 or 2).
#ifndef LUCENT_LAYER_DEPTHS_GLSL
#define LUCENT_LAYER_DEPTHS_GLSL

// A texel as the f64 reference reads it (LayeredMedium::thickness_mm): NaN, infinite and
// negative read 0 (a texture is data from a file), and fp16's largest finite value bounds it,
// so packing never makes an infinity.
vec4 sanitize_layer_texels(vec4 t) {
    bvec4 bad = bvec4(isnan(t.x) || isinf(t.x), isnan(t.y) || isinf(t.y),
                      isnan(t.z) || isinf(t.z), isnan(t.w) || isinf(t.w));
    return clamp(mix(t, vec4(0.0), bad), vec4(0.0), vec4(65504.0));
}

// Texture 0's texels (layers 0-3) and texture 1's (layers 4-7) as the target stores them.
uvec4 pack_layer_texels(vec4 first, vec4 second) {
    first = sanitize_layer_texels(first);
    second = sanitize_layer_texels(second);
    return uvec4(packHalf2x16(first.xy), packHalf2x16(first.zw), packHalf2x16(second.xy),
                 packHalf2x16(second.zw));
}

// Layer j's texel (0 <= j < 8) from a packed target value.
float layer_texel(uvec4 packed, int j) {
    vec2 pair = unpackHalf2x16(packed[clamp(j >> 1, 0, 3)]);
    return (j & 1) == 0 ? pair.x : pair.y;
}

#endif
