// G-buffer layout and packing. Compare the talk's Fig. 20 (GB0-GB3, translucency in one 8-bit
// channel of GB2 beside the material ID).
//
// | target | format (compact)    | bits | contents                                        |
// |--------|---------------------|------|-------------------------------------------------|
// | GB0    | R8G8B8A8_UNORM      | 32   | albedo.rgb (linear), specular (a)               |
// | GB1    | R16G16B16A16_SFLOAT | 64   | world normal xyz (fp16), roughness (a)          |
// | GB2    | R8G8_UNORM          | 16   | grayscale: thickness (r), material ID / 255 (g) |
// |        | R8G8B8A8_UNORM      | 32   | coloured: thickness rgb, material ID / 255 (a)  |
// | depth  | D32_SFLOAT          | 32   | device depth; position rebuilt from it          |
// Total 128 bits per pixel without translucency, 144 with grayscale, 160 with coloured thickness.
// GB2 exists only in frames that shade translucency (LUCENT_TRANSLUCENCY).
//
// Coloured thickness: the talk packs a third channel into the material-ID channel (ID + B with a
// 3/255 offset) because its GB2 is full. lucent gives GB2 its own four channels instead: the
// thickness keeps its full 8 bits per channel (quantisation error <= 1/510) and the ID its 8
// bits; the cost is 16 bits per pixel, and only in frames with a coloured thickness. The
// "half" and "full" precisions (RGBA16F / RGBA32F targets) exist to measure what 8 bits cost.
// Per-material power, distortion and ambient live in a material table indexed by the ID
// (glsl/common/translucency.glsl); the scale is per light.
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

// Rec. 709 luminance: a coloured thickness written to a grayscale GB2.
float thickness_luminance(vec3 t) {
    return dot(t, vec3(0.2126, 0.7152, 0.0722));
}

// GB2. Thickness is clamped to [0, 1] (and NaN to 0) at write: it is a fraction of light let
// through, and an out-of-range vertex colour must not become an out-of-range light.
vec4 pack_gb2(vec3 thickness, int material_id) {
    vec3 t = clamp(mix(thickness, vec3(0.0), isnan(thickness)), 0.0, 1.0);
    float id = float(clamp(material_id, 0, 255)) / 255.0;
#ifdef LUCENT_COLORED_THICKNESS
    return vec4(t, id);
#else
    return vec4(thickness_luminance(t), id, 0.0, 0.0);
#endif
}

// Material ID from GB2 (0: not translucent); rounding recovers the exact integer from UNORM8
// and from the float formats alike.
int unpack_material_id(vec4 gb2) {
#ifdef LUCENT_COLORED_THICKNESS
    return int(gb2.a * 255.0 + 0.5);
#else
    return int(gb2.g * 255.0 + 0.5);
#endif
}

vec3 unpack_thickness(vec4 gb2) {
#ifdef LUCENT_COLORED_THICKNESS
    return gb2.rgb;
#else
    return vec3(gb2.r);
#endif
}

#endif
