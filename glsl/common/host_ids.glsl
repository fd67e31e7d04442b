// A host's material IDs (lucent::embed): the integer a texel of the host's ID image holds,
// decoded as src/embed/gbuffer.rs `IdDesc::decode` describes it. `decode`: x the channel that
// holds the IDs, y the bit field's shift, z its mask, w the largest value of a UNORM channel
// (its integer is value * w; 0 for unsigned formats). Shared by every effect that reads a
// host's IDs (screen-space SSS, GDC 2011 translucency).
#ifndef LUCENT_HOST_IDS_GLSL
#define LUCENT_HOST_IDS_GLSL

// The bit field of a host's ID in its integer channel value.
uint host_id_field(uint raw, uvec4 decode) {
    return (raw >> decode.y) & decode.z;
}

// The ID in a texel of a UNORM (or float) ID image: the channel's integer is exact for UNORM
// formats, whose values are integers / max; out-of-range values are clamped first.
uint host_material_id(vec4 t, uvec4 decode) {
    float stored = t[min(decode.x, 3u)];
    uint raw = uint(clamp(stored, 0.0, 1.0) * float(decode.w) + 0.5);
    return host_id_field(raw, decode);
}

// The ID in a texel of an unsigned-integer ID image (R8_UINT, a stencil aspect, a channel of
// a UINT target).
uint host_material_id(uvec4 t, uvec4 decode) {
    return host_id_field(t[min(decode.x, 3u)], decode);
}

#endif
