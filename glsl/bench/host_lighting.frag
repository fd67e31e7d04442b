#version 450
// permutation: LUCENT_BENCH_TERM=0
// permutation: LUCENT_BENCH_TERM=1 LUCENT_POW_MODES=1
// permutation: LUCENT_BENCH_TERM=1 LUCENT_POW_MODES=2
// permutation: LUCENT_BENCH_TERM=1 LUCENT_POW_MODES=3
// permutation: LUCENT_BENCH_TERM=2
// permutation: LUCENT_BENCH_TERM=3
// The benchmark's stand-in for a host engine's own deferred lighting pass
// (src/measure/host_lighting.rs, `lucent bench --embed`): it reads the host's G-buffer (device
// depth, world normals, albedo), loops over the host's lights (Lambert) and, in the variant
// LUCENT_BENCH_TERM names, adds one of lucent's terms the way a host that wants lucent's cost
// adds it: by calling lucent::embed::glsl::TERMS, the only lucent GLSL it includes, with the
// data the Rust side hands a host.
//   0  none: the host's own constant ambient
//   1  GDC 2011 translucency (`lucent_translucency`, a material's row per ID; the thickness
//      and the ID from one target), with LUCENT_POW_MODES the lobe's forms its materials use
//      (TERMS compiles only those, as lucent's own lighting does)
//   2  the SH environment (`lucent_sh_ambient` in place of the constant ambient)
//   3  SSS transmission (`lucent_shadow_texels` on the host's shadow atlas,
//      `lucent_map_entry_point`, `lucent_sss_transmitted`, a medium's rows per ID)
// The host draws variant 0 over the whole screen, or the term's variant in the screen tiles
// its objects touch and variant 0 in the others, as lucent's own lighting pass does: what the
// term costs a host is the difference of the two, the same difference lucent's frames time.
#include "../embed/lucent_terms.glsl"

#ifndef LUCENT_BENCH_TERM
#define LUCENT_BENCH_TERM 0
#endif

#define BENCH_MAX_LIGHTS 64
#define BENCH_MAX_FACES 384
#define BENCH_MAX_MEDIA 32
#define BENCH_PI 3.14159265358979

// src/measure/host_lighting.rs `HostLightingGpu` (std140).
layout(std140, set = 0) uniform BenchHostLighting {
    mat4 clip_to_world;   // inverse of the camera's view-projection (standard Z)
    vec4 eye;             // xyz: the camera's position
    vec4 ambient;         // rgb: the host's constant ambient (variant 0)
    ivec4 counts;         // x: lights; y: the ID's channel of the thickness target; z: 1 when
                          // its thickness is rgb (else its first channel)
    // Per light: position or direction (w: 0 directional, 1 point, 2 spot), radiance (a:
    // range), the spot's axis (w: cos outer), x cos inner, y the translucency scale.
    vec4 lights[BENCH_MAX_LIGHTS * 4];
    ivec4 light_faces[BENCH_MAX_LIGHTS];  // x: the light's first shadow face, y: its faces
    vec4 sh[9];                           // Environment::coefficients
    vec4 rows[256];                       // by ID: TranslucentMaterial::row
    vec4 media[BENCH_MAX_MEDIA * 4];      // by ID: TransmissionMaterial::rows
    vec4 faces[BENCH_MAX_FACES * 6];      // ShadowFace::terms_rows
} host;

layout(set = 0) uniform sampler2D depth_image;
layout(set = 0) uniform sampler2D normal_image;
layout(set = 0) uniform sampler2D albedo_image;
#if LUCENT_BENCH_TERM == 1
layout(set = 0) uniform sampler2D thickness_image;
#elif LUCENT_BENCH_TERM == 3
layout(set = 0) uniform sampler2D id_image;
layout(set = 0) uniform sampler2D shadow_map;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// The host's falloff of light `i` at `p`: the unit vector to it and its attenuation (an
// inverse square windowed to the range, a spot's smooth cone).
void incidence(int i, vec3 p, out vec3 to_light, out float attenuation) {
    vec4 position = host.lights[i * 4];
    if (position.w < 0.5) {
        to_light = -normalize(position.xyz);
        attenuation = 1.0;
        return;
    }
    vec3 d = position.xyz - p;
    float dist2 = max(dot(d, d), 1e-4);
    to_light = d * inversesqrt(dist2);
    float ratio = sqrt(dist2) / max(host.lights[i * 4 + 1].a, 1e-4);
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    attenuation = window * window / dist2;
    if (position.w > 1.5) {
        vec4 spot = host.lights[i * 4 + 2];
        float width = max(host.lights[i * 4 + 3].x - spot.w, 1e-4);
        float t = clamp((dot(-to_light, spot.xyz) - spot.w) / width, 0.0, 1.0);
        attenuation *= t * t;
    }
}

#if LUCENT_BENCH_TERM == 3
// Light `i`'s radiance diffused through the object to `p` (normal `n`, towards the light
// `l`): the face of its shadow atlas that sees `p` (a point light's by the axis), lucent's
// recipe on it (lucent_shadow_texels) and lucent's term per texel, each at the light's
// falloff where it enters.
vec3 transmitted(vec4 medium[4], int i, vec3 p, vec3 n, vec3 l) {
    ivec4 faces = host.light_faces[i];
    if (faces.y <= 0 || !(dot(n, l) < 0.0)) {
        return vec3(0.0);
    }
    vec3 light_position = host.lights[i * 4].xyz;
    int f = faces.x;
    if (faces.y == 6) {
        vec3 d = p - light_position;
        vec3 a = abs(d);
        int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
        f += 2 * axis + (d[axis] < 0.0 ? 1 : 0);
    }
    f = clamp(f, 0, BENCH_MAX_FACES - 1);
    mat4 view_proj = mat4(host.faces[f * 6], host.faces[f * 6 + 1], host.faces[f * 6 + 2],
                          host.faces[f * 6 + 3]);
    vec4 rect = host.faces[f * 6 + 4];
    vec4 params = host.faces[f * 6 + 5];
    vec3 inner;
    float inner_distance;
    vec4 distances, w;
    if (!lucent_shadow_texels(shadow_map, view_proj, rect, params, p, n, inner, inner_distance,
                              distances, w)) {
        return vec3(0.0);
    }
    vec3 radiance = host.lights[i * 4 + 1].rgb;
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {
        if (!(w[k] > 0.0)) {
            continue;
        }
        vec3 entry = lucent_map_entry_point(params, light_position, inner, l, inner_distance,
                                            distances[k]);
        vec3 unused;
        float attenuation;
        incidence(i, entry, unused, attenuation);
        sum += w[k] * lucent_sss_transmitted(medium, n, l, length(entry - p),
                                             radiance * attenuation);
    }
    return sum;
}
#endif

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    float d = texelFetch(depth_image, px, 0).r;
    if (!(d < 1.0)) {
        out_color = vec4(0.0);  // no surface: the host's sky is another pass
        return;
    }
    vec2 ndc = gl_FragCoord.xy / vec2(textureSize(depth_image, 0)) * 2.0 - 1.0;
    vec4 w = host.clip_to_world * vec4(ndc, d, 1.0);
    vec3 p = w.xyz / w.w;
    vec3 n = normalize(texelFetch(normal_image, px, 0).xyz);
    vec3 albedo = texelFetch(albedo_image, px, 0).rgb;
    vec3 v = normalize(host.eye.xyz - p);
#if LUCENT_BENCH_TERM == 1
    vec4 t = texelFetch(thickness_image, px, 0);
    int id = int(round(t[clamp(host.counts.y, 0, 3)] * 255.0));
    // ID 0 is not translucent: no light let through (a factor, not a branch per light).
    vec3 thickness = (host.counts.z != 0 ? t.rgb : vec3(t.r)) * (id > 0 ? 1.0 : 0.0);
    vec4 row = host.rows[clamp(id, 0, 255)];
    float v_dot_n = dot(v, n);
#elif LUCENT_BENCH_TERM == 3
    int id = int(round(texelFetch(id_image, px, 0).r * 255.0));
    bool has_medium = id > 0 && id < BENCH_MAX_MEDIA && host.media[id * 4].w > 0.0;
    int m = clamp(id, 0, BENCH_MAX_MEDIA - 1) * 4;
    vec4 medium[4] = vec4[4](host.media[m], host.media[m + 1], host.media[m + 2],
                             host.media[m + 3]);
#endif
    vec3 lit = vec3(0.0);
    vec3 added = vec3(0.0);
    int count = clamp(host.counts.x, 0, BENCH_MAX_LIGHTS);
    for (int i = 0; i < count; ++i) {
        vec3 l;
        float attenuation;
        incidence(i, p, l, attenuation);
        vec3 radiance = host.lights[i * 4 + 1].rgb;
        lit += radiance * (attenuation * max(dot(n, l), 0.0));
#if LUCENT_BENCH_TERM == 1
        added += lucent_translucency(albedo, thickness, row, v, v_dot_n, l, radiance,
                                     attenuation, host.lights[i * 4 + 3].y);
#elif LUCENT_BENCH_TERM == 3
        if (has_medium) {
            added += transmitted(medium, i, p, n, l);
        }
#endif
    }
#if LUCENT_BENCH_TERM == 2
    vec3 ambient = lucent_sh_ambient(host.sh, n);
#else
    vec3 ambient = host.ambient.rgb;
#endif
#if LUCENT_BENCH_TERM == 3
    added *= albedo / BENCH_PI;
#endif
    vec3 color = albedo * (lit / BENCH_PI + ambient) + added;
    out_color = vec4(min(color, vec3(65504.0)), 1.0);
}
