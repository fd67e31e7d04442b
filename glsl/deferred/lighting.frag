#version 450
// permutation: LUCENT_TRANSLUCENCY
// permutation: LUCENT_TRANSLUCENCY LUCENT_COLORED_THICKNESS
// Deferred lighting, merged with the G-buffer pass as its second subpass: reads the G-buffer
// only at this pixel through input attachments. With LUCENT_TRANSLUCENCY, adds GDC 2011's
// per-light translucency for pixels whose material ID is translucent; the others skip it.
#include "../common/gbuffer.glsl"
#include "../common/lighting.glsl"
#ifdef LUCENT_TRANSLUCENCY
#include "../common/translucency.glsl"
#endif

layout(input_attachment_index = 0, set = 0, binding = 1) uniform subpassInput gb0;
layout(input_attachment_index = 1, set = 0, binding = 2) uniform subpassInput gb1;
layout(input_attachment_index = 2, set = 0, binding = 3) uniform subpassInput depth;
#ifdef LUCENT_TRANSLUCENCY
layout(input_attachment_index = 3, set = 0, binding = 4) uniform subpassInput gb2;
#endif

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    float d = subpassLoad(depth).r;
    if (d >= 1.0) {
        out_color = vec4(frame.sky.rgb, 1.0);
        return;
    }
    Surface s = unpack_gbuffer(subpassLoad(gb0), subpassLoad(gb1));
    vec2 ndc = gl_FragCoord.xy * frame.viewport.zw * 2.0 - 1.0;
    vec4 world = frame.inv_view_proj * vec4(ndc, d, 1.0);
    vec3 pos = world.xyz / world.w;
    vec3 to_eye = normalize(frame.camera_pos.xyz - pos);
    vec3 color = frame.ambient.rgb * s.albedo;
    int count = clamp(frame.light_count.x, 0, MAX_LIGHTS);
#ifdef LUCENT_TRANSLUCENCY
    // One loop for every pixel: diffuse and specular, plus the talk's term where the material
    // ID says translucent (sharing the light's direction and attenuation). The test sits
    // inside the loop rather than around a second copy of it: a GPU skips the term for
    // coherent opaque pixels, and a SIMD CPU driver (lavapipe runs both sides of a branch)
    // pays only for the term, never for two loops. Opaque pixels read row 0 and thickness 0.
    vec4 t = subpassLoad(gb2);
    int material_id = unpack_material_id(t);
    vec4 material = translucency_materials.rows[clamp(material_id, 0, 255)];
    vec3 thickness = unpack_thickness(t);
    for (int i = 0; i < count; ++i) {
        Light light = frame.lights[i];
        vec3 to_light;
        float attenuation;
        light_incidence(light, pos, to_light, attenuation);
        color += shade_incident(s, to_eye, to_light, attenuation, light);
        if (material_id > 0) {
            color += translucency_term(s.albedo, s.normal, to_eye, to_light, attenuation,
                                       light.radiance_range.rgb, light.params.y, material,
                                       thickness);
        }
    }
#else
    for (int i = 0; i < count; ++i) {
        color += shade_direct(s, pos, to_eye, frame.lights[i]);
    }
#endif
    // fp16 target: clamp to its largest finite value (a real GPU may store +Inf otherwise).
    out_color = vec4(min(color, vec3(65504.0)), 1.0);
}
