#version 450
// The demo's comparison views (src/demo/compare.rs): plain lighting (technique `none`) against
// the technique, both display images (RGBA8, sRGB-encoded) of the same view and size.
// Split: x < split_x shows the plain frame, the rest the technique (or the difference).
// Difference: |technique - plain| x gain, on the display-encoded values.
layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, rgba8) uniform readonly image2D plain_image;
layout(set = 0, rgba8) uniform readonly image2D technique_image;
layout(set = 0, rgba8) uniform writeonly image2D out_image;

layout(push_constant) uniform Compare {
    // Columns left of it show the plain frame (0: none do).
    int split_x;
    // 1: the technique's side shows the amplified difference.
    int difference;
    float gain;
} compare;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_image);
    if (p.x >= size.x || p.y >= size.y) {
        return;
    }
    vec3 plain = imageLoad(plain_image, p).rgb;
    vec3 result;
    if (p.x < compare.split_x) {
        result = plain;
    } else {
        vec3 technique = imageLoad(technique_image, p).rgb;
        result = compare.difference != 0
            ? clamp(abs(technique - plain) * compare.gain, 0.0, 1.0)
            : technique;
    }
    imageStore(out_image, p, vec4(result, 1.0));
}
