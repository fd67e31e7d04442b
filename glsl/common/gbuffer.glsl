// G-buffer layout and packing (the `smoke` slice; the translucency issue extends it).
//
// | target | format              | bits | contents                                   |
// |--------|---------------------|------|--------------------------------------------|
// | GB0    | R8G8B8A8_UNORM      | 32   | albedo.rgb (linear, 8 bit), specular (a)   |
// | GB1    | R16G16B16A16_SFLOAT | 64   | world normal xyz (fp16), roughness (a)     |
// | depth  | D32_SFLOAT          | 32   | device depth; position rebuilt from it     |
// Total 128 bits per pixel.
#ifndef LUCENT_GBUFFER_GLSL
#define LUCENT_GBUFFER_GLSL

struct Surface {
    vec3 albedo;
    float specular;
    vec3 normal;
    float roughness;
};

// Guarded at write: a NaN here would poison every later pass that reads the pixel.
vec3 sanitize_normal(vec3 n) {
    float len2 = dot(n, n);
    // Zero-length or non-finite normals (degenerate triangles) fall back to +Y.
    if (!(len2 > 1e-12) || isinf(len2)) {
        return vec3(0.0, 1.0, 0.0);
    }
    return n * inversesqrt(len2);
}

vec4 pack_gb0(Surface s) {
    return vec4(clamp(s.albedo, 0.0, 1.0), clamp(s.specular, 0.0, 1.0));
}

vec4 pack_gb1(Surface s) {
    return vec4(sanitize_normal(s.normal), clamp(s.roughness, 0.0, 1.0));
}

Surface unpack_gbuffer(vec4 gb0, vec4 gb1) {
    Surface s;
    s.albedo = gb0.rgb;
    s.specular = gb0.a;
    s.normal = sanitize_normal(gb1.xyz);
    s.roughness = gb1.a;
    return s;
}

#endif
