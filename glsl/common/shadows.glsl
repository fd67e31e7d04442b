// Light-space maps (src/features/shadows.rs): the per-frame shadow table and, in lighting
// passes, the lookup. The table's layout must match `ShadowUniforms` (std140).
//
// The light-space maps pass includes this file with no define: it reads the table, and its
// push constants name the object and face. Lighting passes define LUCENT_SHADOWS (they read
// the depth atlas too, and with LUCENT_SHADOW_IDS the ID atlas) and include scene.glsl first.
// Every resource here is bound by its name (`Shadows`, `shadow_depth`, `shadow_ids`), at the
// number the pass declares (src/backend/bindings.rs).
#ifndef LUCENT_SHADOWS_GLSL
#define LUCENT_SHADOWS_GLSL

// The lookups themselves, on a face's rows as arguments (shared with a host's lighting pass).
#include "../embed/lucent_terms.glsl"

#define MAX_SHADOW_LIGHTS 64
#define MAX_SHADOW_FACES 384

struct ShadowFace {
    mat4 view_proj;  // world to the face's clip space (standard Z: depth 0 near, 1 far)
    vec4 rect;       // xy: the tile's top-left texel in the atlas; z: its edge in texels;
                     // w: a host's map's (LUCENT_SHADOW_REVERSIBLE): 1 if it stores reversed
                     // Z, plus 2 x its array layer (LUCENT_SHADOW_ARRAY); with a second map
                     // (LUCENT_SHADOW_SECOND_MAP), a face in it has -1 minus those flags
                     // (its layer of the second map, an array)
    vec4 params;     // a map texel's world size at a point: x * clip.w + y
};

layout(std140, set = 0) uniform Shadows {
    vec4 atlas;                          // xy: size in texels; zw: 1 / size
    ivec4 lights[MAX_SHADOW_LIGHTS];     // x: first face (-1: no map); y: face count (1 or 6)
    ShadowFace faces[MAX_SHADOW_FACES];
} shadows;

#ifndef LUCENT_SHADOWS
// The light-space maps pass: the object and the face it is drawn into.
layout(push_constant) uniform ShadowObject {
    mat4 model;
    ivec4 face_id;  // x: face; y: the object's translucency material ID (0: none); z: layered ID
} shadow_object;
#else
#ifdef LUCENT_SHADOW_ARRAY
// A host's shadow map as an array of layers (cascades, a cube's faces), each face in its own.
layout(set = 0) uniform sampler2DArray shadow_depth;
#else
layout(set = 0) uniform sampler2D shadow_depth;
#endif
#ifdef LUCENT_SHADOW_SECOND_MAP
// A host's second shadow map beside the first (an atlas): an array of layers (a cube array's
// faces, cascades) of its own size. Faces in it have a negative rect.w.
layout(set = 0) uniform sampler2DArray shadow_layers;
#endif
#ifdef LUCENT_SHADOW_IDS
layout(set = 0) uniform usampler2D shadow_ids;
#endif

// Whether face `face` lies in the second map (LUCENT_SHADOW_SECOND_MAP; never otherwise).
bool shadow_in_second_map(int face) {
#ifdef LUCENT_SHADOW_SECOND_MAP
    return shadows.faces[face].rect.w < 0.0;
#else
    return false;
#endif
}

// Face `face`'s flags (rect.w as lucent_stored_depth reads it: 1 for reversed Z, plus 2 x its
// layer), whichever map it lies in.
float shadow_face_flags(int face) {
    float w = shadows.faces[face].rect.w;
    return shadow_in_second_map(face) ? -w - 1.0 : w;
}

// One over the size in texels of the map face `face` lies in: the first map's (the table's
// atlas), or the second's.
vec2 shadow_inv_map_size(int face) {
#ifdef LUCENT_SHADOW_SECOND_MAP
    if (shadow_in_second_map(face)) {
        return 1.0 / vec2(textureSize(shadow_layers, 0).xy);
    }
#endif
    return shadows.atlas.zw;
}

// The depth texels around map coordinate `corner` (textureGather's order) of a face with flags
// `flags` (shadow_face_flags) in the second map (`second`, LUCENT_SHADOW_SECOND_MAP) or the
// first, from its layer where the map is an array, as standard Z. A lookup of several gathers
// decodes the face once and calls this for each. lucent's own maps store standard Z. A host's
// map may store reversed Z (src/embed/shadow_faces.rs): its face's view_proj is then the
// host's projection with z flipped (depth 1 - d), so positions project to standard Z, and only
// the stored texels are flipped here. Passes reading a host's maps define
// LUCENT_SHADOW_REVERSIBLE; lucent's own compile the identity.
vec4 shadow_gather_flagged(bool second, float flags, vec2 corner) {
    vec4 d;
#ifdef LUCENT_SHADOW_SECOND_MAP
    if (second) {
        d = textureGather(shadow_layers, vec3(corner, floor(flags * 0.5)), 0);
    } else
#endif
    {
#ifdef LUCENT_SHADOW_ARRAY
        d = textureGather(shadow_depth, vec3(corner, floor(flags * 0.5)), 0);
#else
        d = textureGather(shadow_depth, corner, 0);
#endif
    }
#ifdef LUCENT_SHADOW_REVERSIBLE
    d = lucent_stored_depth(vec4(0.0, 0.0, 0.0, flags), d);
#endif
    return d;
}

// The depth texels of face `face`'s map around map coordinate `corner` (textureGather's
// order), from its layer where the map is an array (LUCENT_SHADOW_ARRAY), as standard Z.
vec4 shadow_gather_depth(int face, vec2 corner) {
    return shadow_gather_flagged(shadow_in_second_map(face), shadow_face_flags(face), corner);
}

// The face of `light`'s map that sees `pos` (-1: the light casts no shadow). A point light's
// six faces are +X, -X, +Y, -Y, +Z, -Z: the major axis of (pos - light) picks one.
int shadow_face(int light, vec3 pos) {
    ivec4 l = shadows.lights[clamp(light, 0, MAX_SHADOW_LIGHTS - 1)];
    if (l.x < 0 || l.y <= 0) {
        return -1;
    }
    if (l.y == 1) {
        return l.x;
    }
    vec3 d = pos - frame.lights[light].position_type.xyz;
    vec3 a = abs(d);
    int axis = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
    return clamp(l.x + 2 * axis + (d[axis] < 0.0 ? 1 : 0), 0, MAX_SHADOW_FACES - 1);
}

// Distance from the face's eye along its axis (world units) of a device depth `d`.
float shadow_distance(vec4 params, float d) {
    return lucent_face_distance(params, d);
}

// The device depth of a distance `z` from the face's eye along its axis (the inverse of
// `shadow_distance`, both increasing): a tap compares its stored depth with the point's
// converted once, instead of converting every tap's depth to a distance. A distance before
// the near plane maps below 0 (every occluder lies beyond it: lit), as it compared before.
float shadow_device_depth(vec4 params, float z) {
    float near = abs(params.z), far = params.w;
    float range = max(far - near, 1e-12);
    if (params.z < 0.0) {
        return (z - near) / range; // orthographic: linear
    }
    // Perspective: d = far (z - near) / (z (far - near)); z is held positive (a point on the
    // eye would divide by zero; it lies before the near plane anyway).
    return far * (z - near) / (max(z, 1e-12) * range);
}

// A map texel's world size at `p` on face `face`: how far a lookup moves to step one texel.
float map_texel_size(int face, vec3 p) {
    return lucent_map_texel_size(shadows.faces[face].view_proj, shadows.faces[face].params, p);
}

// Where `p` falls in face `face`'s map: its atlas position `t` in texels (texel k's centre at
// k + 0.5) and its distance along the face's axis; false outside the face's cone (w <= 0
// would divide by zero) or map.
bool map_position(int face, vec3 p, out vec2 t, out float distance) {
    return lucent_map_position(shadows.faces[face].view_proj, shadows.faces[face].rect,
                               shadows.faces[face].params, p, t, distance);
}

// The texel of face `face`'s tile nearest atlas position `t`.
ivec2 map_texel(int face, vec2 t) {
    vec4 rect = shadows.faces[face].rect;
    ivec2 lo = ivec2(rect.xy);
    return clamp(ivec2(t), lo, lo + ivec2(rect.z) - 1);
}

// The 2x2 texels of face `face`'s tile whose centres surround atlas position `t` (kept inside
// the tile): the textureGather coordinate that returns them and their bilinear weights, in
// gather order (x0 y1, x1 y1, x1 y0, x0 y0).
void map_bilinear(int face, vec2 t, out vec2 corner, out vec4 weights) {
    lucent_map_bilinear(shadows.faces[face].rect, shadow_inv_map_size(face), t, corner, weights);
}

// Where light `light`'s ray to `p` (at distance `d_p` along face `face`'s axis) meets a
// surface the map holds at distance `d_map`: along the light's direction on an orthographic
// (directional) face; on a perspective one, on the ray from the light, where axial distances
// scale with the distance from it (d_p > 0 there; the max guards a point on the light's eye).
// A point nearer than the surface is its own entry point.
vec3 map_entry_point(int face, int light, vec3 p, vec3 to_light, float d_p, float d_map) {
    return lucent_map_entry_point(shadows.faces[face].params,
                                  frame.lights[light].position_type.xyz, p, to_light, d_p, d_map);
}

// How much of `light` reaches `pos` (normal `normal`, towards the light `to_light`): x for light
// reflected at the surface, y for light transmitted through translucency material `material`
// (GDC 2011: occluders of the pixel's own material do not shadow it; material 0 = not
// translucent). A 4x4-texel tent (a 3x3 box, bilinearly placed) read with four gathers, the
// taps compared as device depths with the point's distance from the light converted once
// (distance and depth grow together, so the comparison is the same): the point is first moved one map texel
// along its normal, and a tap counts as lit when its occluder lies no nearer than the point's
// distance minus a bias that grows with the slope (a tap two texels away on a surface at angle
// theta to the light lies 2 tan(theta) texels nearer; capped at 8 texels, grazing light).
vec2 shadow_visibility(int light, vec3 pos, vec3 normal, vec3 to_light, int material) {
    int index = shadow_face(light, pos);
    if (index < 0) {
        return vec2(1.0);
    }
    ShadowFace face = shadows.faces[index];
    vec4 clip = face.view_proj * vec4(pos, 1.0);
    float texel = face.params.x * abs(clip.w) + face.params.y;
    clip = face.view_proj * vec4(pos + normal * texel, 1.0);
    if (!(clip.w > 0.0)) {
        return vec2(1.0); // behind a perspective face's eye: outside its cone
    }
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))) || !(ndc.z >= 0.0 && ndc.z <= 1.0)) {
        return vec2(1.0); // outside the map: nothing there casts
    }
    float cos_theta = clamp(abs(dot(normal, to_light)), 0.05, 1.0);
    float tan_theta = sqrt(1.0 - cos_theta * cos_theta) / cos_theta;
    float bias = texel * (1.0 + min(2.0 * tan_theta, 8.0));
    // The point's distance less the bias, as a device depth the taps compare with directly.
    float reference = shadow_device_depth(face.params, shadow_distance(face.params, ndc.z) - bias);
    // Texel-centre coordinates in the atlas; the 4x4 block starts one texel before the
    // bilinear footprint and is kept inside the tile (a neighbour's tile is another face).
    vec2 t = face.rect.xy + (ndc.xy * 0.5 + 0.5) * face.rect.z - 0.5;
    vec2 base = floor(t);
    vec2 f = t - base;
    vec2 first = clamp(base - 1.0, face.rect.xy, face.rect.xy + face.rect.z - 4.0);
    vec4 wx = vec4(1.0 - f.x, 1.0, 1.0, f.x);
    vec4 wy = vec4(1.0 - f.y, 1.0, 1.0, f.y);
    // The face's map, layer and depth encoding, decoded once for the four gathers.
    vec2 inv_map_size = shadow_inv_map_size(index);
    bool second = shadow_in_second_map(index);
    float flags = shadow_face_flags(index);
    vec2 visible = vec2(0.0);
    for (int by = 0; by < 2; ++by) {
        for (int bx = 0; bx < 2; ++bx) {
            // The corner shared by texels (first + 2 bx, first + 2 by) .. (+1, +1): a gather
            // there returns them as (x0 y1, x1 y1, x1 y0, x0 y0).
            vec2 corner = (first + vec2(2 * bx + 1, 2 * by + 1)) * inv_map_size;
            vec4 occluder = shadow_gather_flagged(second, flags, corner);
            vec4 lit = step(vec4(reference), occluder);
            float x0 = wx[2 * bx], x1 = wx[2 * bx + 1];
            float y0 = wy[2 * by], y1 = wy[2 * by + 1];
            vec4 w = vec4(x0 * y1, x1 * y1, x1 * y0, x0 * y0);
            visible.x += dot(lit, w);
#ifdef LUCENT_SHADOW_IDS
            uvec4 ids = textureGather(shadow_ids, corner, 0);
            vec4 own = material > 0 ? vec4(equal(ids, uvec4(uint(material)))) : vec4(0.0);
            visible.y += dot(max(lit, own), w);
#else
            visible.y += dot(lit, w);
#endif
        }
    }
    // The weights sum to 3 x 3.
    return visible / 9.0;
}
#endif

#endif
