// What the two-pass screen-space SSS blurs share (glsl/sss/separable.frag and
// glsl/sss/bilateral.frag; src/features/sss/two_pass.rs): the images every pass reads, the push
// constant, and the profile's kernel (sss_kernels: N samples, pre-integrated weights at offsets
// in world units) scaled to pixels. Each blur runs one direction per pass: the horizontal pass
// blurs the lit diffuse into a temporary, the vertical pass blurs that and writes the chain's
// result (the blurred light plus specular on the chain's pixels, the previous chain's result or
// the lit diffuse + specular elsewhere), so the whole blur is two passes.
//
// Defines both blurs read: LUCENT_SSS_VERTICAL (the second pass); LUCENT_SSS_PROFILE_EDGES
// (several profiles in the frame: a tap on another profile's pixel counts as an edge);
// LUCENT_SSS_PASSTHROUGH (the vertical pass's variant for rectangles no object of the chain
// covers: compose only); LUCENT_SSS_BASE (elsewhere, the previous chain's result).
#ifndef LUCENT_SSS_TWO_PASS_KERNEL_GLSL
#define LUCENT_SSS_TWO_PASS_KERNEL_GLSL

#define LUCENT_SSS_KERNELS
#include "../common/scene.glsl"
#include "../common/sss.glsl"

// The images every pass samples (each shader's own inputs are declared after them).
layout(set = 0) uniform sampler2D color_tex;        // light (+ alpha)
layout(set = 0) uniform sampler2D depth_tex;    // device depth, full res
layout(set = 0) uniform SSS_ID_SAMPLER profile_tex;  // profile IDs, full res

layout(push_constant) uniform Blur {
    vec4 step;  // xy: direction (1,0) or (0,1); w: the chain
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// A NaN or Inf sample would poison every tap that reads it: replace it where it is read.
vec4 finite_or(vec4 c, vec4 fallback) {
    bool bad = any(isnan(c)) || any(isinf(c));
    return bad ? fallback : c;
}

// Whether profile `id` is blurred by this pass's chain.
bool in_this_chain(int id) {
    return sss_in_chain(id, int(blur.step.w + 0.5));
}

// The number of samples of the kernel whose `sss_kernels.info` is `info`.
int kernel_samples(vec4 info) {
    return clamp(int(info.x + 0.5), 1, MAX_KERNEL_SAMPLES);
}

// Pixels per world unit of the kernel's offsets, for a pixel at linear depth `depth_m` in an
// image of `size` (at half resolution, half as many). The taps' reach (info.z, world units) is
// clamped to a quarter of the screen: an extreme profile or a surface at the near plane must
// not sample across the whole image.
float kernel_scale(vec4 info, float depth_m, ivec2 size) {
    float px_per_unit = frame.camera.z / max(depth_m, 1e-4) * float(size.y) / frame.viewport.y;
    float max_px = 0.25 * float(max(size.x, size.y));
    return min(px_per_unit, max_px / max(info.z, 1e-9));
}

// A composed pixel as the vertical pass writes it: into fp16's range, and a NaN (which clamp
// need not catch) becomes black.
vec4 composed(vec3 color) {
    color = any(isnan(color)) ? vec3(0.0) : clamp(color, vec3(0.0), vec3(65504.0));
    return vec4(color, 1.0);
}

#endif
