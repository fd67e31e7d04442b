#version 450
// permutation: LUCENT_SSS_ACCUMULATE
// Screen-space SSS, the control (Jimenez et al. 2009, as the LEAN-mapping thesis gives it,
// section 3.2.2): one direction of a separable 7-tap Gaussian whose width is the profile's
// Gaussian projected to the screen (wider up close: divided by the pixel's linear depth), scaled
// by the pixel's SSS strength; a tap across a large depth difference is lerped back to the centre
// colour. The vertical pass also adds its result, times the Gaussian's RGB weight, into the
// sum-of-Gaussians target (additive blending). Non-SSS pixels (strength 0) come out unchanged.
#include "../common/scene.glsl"

layout(set = 0, binding = 1) uniform sampler2D color_tex;  // linear filtering, clamp to edge
layout(set = 0, binding = 2) uniform sampler2D depth_tex;  // device depth, read with texelFetch
layout(set = 0, binding = 3) uniform sampler2D strength_tex; // SSS strength, 0 = not SSS

layout(push_constant) uniform Blur {
    vec4 step;    // xy: direction (1,0) or (0,1); z: this step's sigma, world units;
                  // w: depth correction, per world unit of depth difference
    vec4 weight;  // rgb: the Gaussian's weight in the sum (vertical pass)
} blur;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;
#ifdef LUCENT_SSS_ACCUMULATE
layout(location = 1) out vec4 out_sum;
#endif

// A NaN or Inf sample would poison every tap that reads it: replace it where it is read.
vec3 finite_or(vec3 c, vec3 fallback) {
    bool bad = any(isnan(c)) || any(isinf(c));
    return bad ? fallback : c;
}

void main() {
    // Jimenez's kernel: centre 0.382, six taps at +-1/3, +-2/3, +-1 of the step (sums to 1).
    const float w[6] = float[](0.006, 0.061, 0.242, 0.242, 0.061, 0.006);
    const float o[6] = float[](-1.0, -0.6667, -0.3333, 0.3333, 0.6667, 1.0);
    ivec2 size = textureSize(depth_tex, 0);
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 center = finite_or(texelFetch(color_tex, px, 0).rgb, vec3(0.0));
    float device_depth = texelFetch(depth_tex, px, 0).r;
    float strength = clamp(texelFetch(strength_tex, px, 0).r, 0.0, 1.0);
    // Sky pixels have no surface to scatter in.
    strength = device_depth < 1.0 ? strength : 0.0;
    float depth_m = linear_depth(device_depth);
    // The kernel spans +-3 sigma at offset 1: sigma_world projected to pixels, then to UV.
    float sigma_px = blur.step.z * frame.camera.z / max(depth_m, 1e-4);
    // Clamp the reach to a quarter of the screen: an extreme strength or a surface at the near
    // plane must not sample across the whole image.
    float reach_px = min(3.0 * sigma_px * strength, 0.25 * float(max(size.x, size.y)));
    // A Gaussian narrower than a pixel is about a delta at this resolution: blurring it anyway
    // would only add the bilinear taps' own filtering (measured against the brute-force
    // reference: twelve such passes end further from it than no blur at all).
    reach_px = sigma_px * strength < 1.0 ? 0.0 : reach_px;
    vec2 final_step = blur.step.xy * reach_px * frame.viewport.zw;
    vec2 uv = (vec2(px) + 0.5) * frame.viewport.zw;
    vec3 blurred = center * 0.382;
    for (int i = 0; i < 6; ++i) {
        vec2 offset = uv + o[i] * final_step;
        vec3 color = finite_or(textureLod(color_tex, offset, 0.0).rgb, center);
        ivec2 tap = clamp(ivec2(offset * frame.viewport.xy), ivec2(0), size - 1);
        float depth = linear_depth(texelFetch(depth_tex, tap, 0).r);
        // A huge depth difference (another object, the background): back to the centre colour.
        float s = min(blur.step.w * abs(depth_m - depth), 1.0);
        blurred += w[i] * mix(color, center, s);
    }
    // fp16 target: keep it finite.
    blurred = min(blurred, vec3(65504.0));
    out_color = vec4(blurred, 1.0);
#ifdef LUCENT_SSS_ACCUMULATE
    out_sum = vec4(blurred * blur.weight.rgb, 0.0);
#endif
}
