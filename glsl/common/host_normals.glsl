// A host's normals (lucent::embed): a texel of the host's normal image decoded to a unit
// world-space normal, as src/embed/gbuffer.rs `NormalDesc::decode` describes the encoding.
// `encoding`: x 1 = octahedral (else xyz), y 1 = view space (else world), z 1 = UNORM channels
// mapped from [0, 1] (else SNORM or float, already in [-1, 1]). Shared by every effect that
// reads a host's normals (GDC 2011 translucency, the SH environment). Needs gbuffer.glsl's
// sanitize_normal.
#ifndef LUCENT_HOST_NORMALS_GLSL
#define LUCENT_HOST_NORMALS_GLSL

// Octahedral decode (Cigolle et al. 2014, z the folded axis), e in [-1, 1]^2.
vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float fold = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -fold : fold;
    n.y += n.y >= 0.0 ? -fold : fold;
    return n;
}

// The world-space unit normal in texel `t`; `view_to_world` rotates view-space normals.
vec3 host_normal(vec4 t, uvec4 encoding, mat4 view_to_world) {
    vec3 n;
    if (encoding.x != 0u) {
        vec2 e = encoding.z != 0u ? t.xy * 2.0 - 1.0 : t.xy;
        n = octahedral_decode(clamp(e, -1.0, 1.0));
    } else {
        n = encoding.z != 0u ? t.xyz * 2.0 - 1.0 : t.xyz;
    }
    if (encoding.y != 0u) {
        n = mat3(view_to_world) * n;
    }
    // A NaN, Inf or zero normal in the host's image falls back to +Y (sanitize_normal).
    return sanitize_normal(n);
}

#endif
