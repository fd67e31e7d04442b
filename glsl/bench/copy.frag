#version 450
// permutation: LUCENT_COPY_INPUTS=3 LUCENT_COPY_OUTPUTS=4 LUCENT_COPY_DEPTH=1
// permutation: LUCENT_COPY_INPUTS=8 LUCENT_COPY_OUTPUTS=8
// permutation: LUCENT_COPY_INPUTS=10 LUCENT_COPY_OUTPUTS=1
// permutation: LUCENT_COPY_INPUTS=1 LUCENT_COPY_OUTPUTS=1
// permutation: LUCENT_COPY_INPUTS=0 LUCENT_COPY_OUTPUTS=0 LUCENT_COPY_DEPTH=1
// The speed-of-light floor of a pass (src/measure/speed_of_light.rs): one texel fetch from each
// of LUCENT_COPY_INPUTS images (`in0`, `in1`, ...), written to each of LUCENT_COPY_OUTPUTS colour
// targets, and with LUCENT_COPY_DEPTH to the depth target too. Every fetched value reaches
// every output, so the compiler can drop no fetch. No ALU work beyond combining them.
//
// Every image is a float format: the copy frame replaces an integer format by the float format
// of the same texel size (speed_of_light.rs, `copy_format`), so a fetch moves the same bytes and
// the shader's permutations are only the counts (which the shipped SPIR-V can enumerate).
#ifndef LUCENT_COPY_INPUTS
#define LUCENT_COPY_INPUTS 0
#endif
#ifndef LUCENT_COPY_OUTPUTS
#define LUCENT_COPY_OUTPUTS 1
#endif

#if LUCENT_COPY_INPUTS > 0
layout(set = 0) uniform sampler2D in0;
#endif
#if LUCENT_COPY_INPUTS > 1
layout(set = 0) uniform sampler2D in1;
#endif
#if LUCENT_COPY_INPUTS > 2
layout(set = 0) uniform sampler2D in2;
#endif
#if LUCENT_COPY_INPUTS > 3
layout(set = 0) uniform sampler2D in3;
#endif
#if LUCENT_COPY_INPUTS > 4
layout(set = 0) uniform sampler2D in4;
#endif
#if LUCENT_COPY_INPUTS > 5
layout(set = 0) uniform sampler2D in5;
#endif
#if LUCENT_COPY_INPUTS > 6
layout(set = 0) uniform sampler2D in6;
#endif
#if LUCENT_COPY_INPUTS > 7
layout(set = 0) uniform sampler2D in7;
#endif
#if LUCENT_COPY_INPUTS > 8
layout(set = 0) uniform sampler2D in8;
#endif
#if LUCENT_COPY_INPUTS > 9
layout(set = 0) uniform sampler2D in9;
#endif
#if LUCENT_COPY_OUTPUTS > 0
layout(location = 0) out vec4 out0;
#endif
#if LUCENT_COPY_OUTPUTS > 1
layout(location = 1) out vec4 out1;
#endif
#if LUCENT_COPY_OUTPUTS > 2
layout(location = 2) out vec4 out2;
#endif
#if LUCENT_COPY_OUTPUTS > 3
layout(location = 3) out vec4 out3;
#endif
#if LUCENT_COPY_OUTPUTS > 4
layout(location = 4) out vec4 out4;
#endif
#if LUCENT_COPY_OUTPUTS > 5
layout(location = 5) out vec4 out5;
#endif
#if LUCENT_COPY_OUTPUTS > 6
layout(location = 6) out vec4 out6;
#endif
#if LUCENT_COPY_OUTPUTS > 7
layout(location = 7) out vec4 out7;
#endif

layout(location = 0) in vec2 in_uv;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    // A pass without image inputs (a G-buffer pass) still writes something that varies.
    vec4 v = vec4(in_uv, 0.0, 1.0);
#if LUCENT_COPY_INPUTS > 0
    v += texelFetch(in0, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 1
    v += texelFetch(in1, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 2
    v += texelFetch(in2, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 3
    v += texelFetch(in3, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 4
    v += texelFetch(in4, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 5
    v += texelFetch(in5, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 6
    v += texelFetch(in6, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 7
    v += texelFetch(in7, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 8
    v += texelFetch(in8, px, 0);
#endif
#if LUCENT_COPY_INPUTS > 9
    v += texelFetch(in9, px, 0);
#endif
#if LUCENT_COPY_OUTPUTS > 0
    out0 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 1
    out1 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 2
    out2 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 3
    out3 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 4
    out4 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 5
    out5 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 6
    out6 = v;
#endif
#if LUCENT_COPY_OUTPUTS > 7
    out7 = v;
#endif
#ifdef LUCENT_COPY_DEPTH
    // Depth inputs are in [0, 1]; the target is cleared to 1 and tested LESS.
    gl_FragDepth = clamp(fract(v.r) * 0.5, 0.0, 0.99);
#endif
}
