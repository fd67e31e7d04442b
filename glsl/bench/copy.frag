#version 450
// permutation: LUCENT_COPY_INPUTS=3 LUCENT_COPY_OUTPUTS=4 LUCENT_COPY_DEPTH=1
// permutation: LUCENT_COPY_INPUTS=8 LUCENT_COPY_OUTPUTS=8
// permutation: LUCENT_COPY_INPUTS=10 LUCENT_COPY_OUTPUTS=1 LUCENT_COPY_IN9_KIND=1
// permutation: LUCENT_COPY_INPUTS=1 LUCENT_COPY_OUTPUTS=1
// permutation: LUCENT_COPY_INPUTS=2 LUCENT_COPY_OUTPUTS=2 LUCENT_COPY_IN0_KIND=1 LUCENT_COPY_OUT1_KIND=1
// permutation: LUCENT_COPY_INPUTS=2 LUCENT_COPY_OUTPUTS=2 LUCENT_COPY_IN1_KIND=2 LUCENT_COPY_OUT0_KIND=2 LUCENT_COPY_DEPTH=1
// The speed-of-light floor of a pass (src/measure/speed_of_light.rs): one texel fetch from each
// of LUCENT_COPY_INPUTS images (bindings 0..), written to each of LUCENT_COPY_OUTPUTS colour
// targets, and with LUCENT_COPY_DEPTH to the depth target too. Every fetched value reaches
// every output, so the compiler can drop no fetch. No ALU work beyond combining them.
//
// Integer formats are read and written as integers (backend/format.rs decides, per image):
// LUCENT_COPY_IN<k>_KIND and LUCENT_COPY_OUT<k>_KIND are 0 (float: sampler2D / vec4, the
// default), 1 (unsigned: usampler2D / uvec4) or 2 (signed: isampler2D / ivec4). Reading an
// RGBA32UI image through a float sampler, or writing a vec4 to an integer attachment, is
// undefined (VUID-vkCmdDraw-format-07753, and an interface type mismatch). Float inputs are
// summed, integer ones XORed; float outputs get the sum plus the XOR's low bit, integer
// outputs the XOR of the sum's bits and the integer inputs.
#ifndef LUCENT_COPY_INPUTS
#define LUCENT_COPY_INPUTS 0
#endif
#ifndef LUCENT_COPY_OUTPUTS
#define LUCENT_COPY_OUTPUTS 1
#endif

#ifndef LUCENT_COPY_IN0_KIND
#define LUCENT_COPY_IN0_KIND 0
#endif
#ifndef LUCENT_COPY_OUT0_KIND
#define LUCENT_COPY_OUT0_KIND 0
#endif
#ifndef LUCENT_COPY_IN1_KIND
#define LUCENT_COPY_IN1_KIND 0
#endif
#ifndef LUCENT_COPY_OUT1_KIND
#define LUCENT_COPY_OUT1_KIND 0
#endif
#ifndef LUCENT_COPY_IN2_KIND
#define LUCENT_COPY_IN2_KIND 0
#endif
#ifndef LUCENT_COPY_OUT2_KIND
#define LUCENT_COPY_OUT2_KIND 0
#endif
#ifndef LUCENT_COPY_IN3_KIND
#define LUCENT_COPY_IN3_KIND 0
#endif
#ifndef LUCENT_COPY_OUT3_KIND
#define LUCENT_COPY_OUT3_KIND 0
#endif
#ifndef LUCENT_COPY_IN4_KIND
#define LUCENT_COPY_IN4_KIND 0
#endif
#ifndef LUCENT_COPY_OUT4_KIND
#define LUCENT_COPY_OUT4_KIND 0
#endif
#ifndef LUCENT_COPY_IN5_KIND
#define LUCENT_COPY_IN5_KIND 0
#endif
#ifndef LUCENT_COPY_OUT5_KIND
#define LUCENT_COPY_OUT5_KIND 0
#endif
#ifndef LUCENT_COPY_IN6_KIND
#define LUCENT_COPY_IN6_KIND 0
#endif
#ifndef LUCENT_COPY_OUT6_KIND
#define LUCENT_COPY_OUT6_KIND 0
#endif
#ifndef LUCENT_COPY_IN7_KIND
#define LUCENT_COPY_IN7_KIND 0
#endif
#ifndef LUCENT_COPY_OUT7_KIND
#define LUCENT_COPY_OUT7_KIND 0
#endif
#ifndef LUCENT_COPY_IN8_KIND
#define LUCENT_COPY_IN8_KIND 0
#endif
#ifndef LUCENT_COPY_IN9_KIND
#define LUCENT_COPY_IN9_KIND 0
#endif

#if LUCENT_COPY_INPUTS > 0
#if LUCENT_COPY_IN0_KIND == 1
layout(set = 0, binding = 0) uniform usampler2D in0;
#elif LUCENT_COPY_IN0_KIND == 2
layout(set = 0, binding = 0) uniform isampler2D in0;
#else
layout(set = 0, binding = 0) uniform sampler2D in0;
#endif
#endif
#if LUCENT_COPY_INPUTS > 1
#if LUCENT_COPY_IN1_KIND == 1
layout(set = 0, binding = 1) uniform usampler2D in1;
#elif LUCENT_COPY_IN1_KIND == 2
layout(set = 0, binding = 1) uniform isampler2D in1;
#else
layout(set = 0, binding = 1) uniform sampler2D in1;
#endif
#endif
#if LUCENT_COPY_INPUTS > 2
#if LUCENT_COPY_IN2_KIND == 1
layout(set = 0, binding = 2) uniform usampler2D in2;
#elif LUCENT_COPY_IN2_KIND == 2
layout(set = 0, binding = 2) uniform isampler2D in2;
#else
layout(set = 0, binding = 2) uniform sampler2D in2;
#endif
#endif
#if LUCENT_COPY_INPUTS > 3
#if LUCENT_COPY_IN3_KIND == 1
layout(set = 0, binding = 3) uniform usampler2D in3;
#elif LUCENT_COPY_IN3_KIND == 2
layout(set = 0, binding = 3) uniform isampler2D in3;
#else
layout(set = 0, binding = 3) uniform sampler2D in3;
#endif
#endif
#if LUCENT_COPY_INPUTS > 4
#if LUCENT_COPY_IN4_KIND == 1
layout(set = 0, binding = 4) uniform usampler2D in4;
#elif LUCENT_COPY_IN4_KIND == 2
layout(set = 0, binding = 4) uniform isampler2D in4;
#else
layout(set = 0, binding = 4) uniform sampler2D in4;
#endif
#endif
#if LUCENT_COPY_INPUTS > 5
#if LUCENT_COPY_IN5_KIND == 1
layout(set = 0, binding = 5) uniform usampler2D in5;
#elif LUCENT_COPY_IN5_KIND == 2
layout(set = 0, binding = 5) uniform isampler2D in5;
#else
layout(set = 0, binding = 5) uniform sampler2D in5;
#endif
#endif
#if LUCENT_COPY_INPUTS > 6
#if LUCENT_COPY_IN6_KIND == 1
layout(set = 0, binding = 6) uniform usampler2D in6;
#elif LUCENT_COPY_IN6_KIND == 2
layout(set = 0, binding = 6) uniform isampler2D in6;
#else
layout(set = 0, binding = 6) uniform sampler2D in6;
#endif
#endif
#if LUCENT_COPY_INPUTS > 7
#if LUCENT_COPY_IN7_KIND == 1
layout(set = 0, binding = 7) uniform usampler2D in7;
#elif LUCENT_COPY_IN7_KIND == 2
layout(set = 0, binding = 7) uniform isampler2D in7;
#else
layout(set = 0, binding = 7) uniform sampler2D in7;
#endif
#endif

#if LUCENT_COPY_INPUTS > 8
#if LUCENT_COPY_IN8_KIND == 1
layout(set = 0, binding = 8) uniform usampler2D in8;
#elif LUCENT_COPY_IN8_KIND == 2
layout(set = 0, binding = 8) uniform isampler2D in8;
#else
layout(set = 0, binding = 8) uniform sampler2D in8;
#endif
#endif
#if LUCENT_COPY_INPUTS > 9
#if LUCENT_COPY_IN9_KIND == 1
layout(set = 0, binding = 9) uniform usampler2D in9;
#elif LUCENT_COPY_IN9_KIND == 2
layout(set = 0, binding = 9) uniform isampler2D in9;
#else
layout(set = 0, binding = 9) uniform sampler2D in9;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 0
#if LUCENT_COPY_OUT0_KIND == 1
layout(location = 0) out uvec4 out0;
#elif LUCENT_COPY_OUT0_KIND == 2
layout(location = 0) out ivec4 out0;
#else
layout(location = 0) out vec4 out0;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 1
#if LUCENT_COPY_OUT1_KIND == 1
layout(location = 1) out uvec4 out1;
#elif LUCENT_COPY_OUT1_KIND == 2
layout(location = 1) out ivec4 out1;
#else
layout(location = 1) out vec4 out1;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 2
#if LUCENT_COPY_OUT2_KIND == 1
layout(location = 2) out uvec4 out2;
#elif LUCENT_COPY_OUT2_KIND == 2
layout(location = 2) out ivec4 out2;
#else
layout(location = 2) out vec4 out2;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 3
#if LUCENT_COPY_OUT3_KIND == 1
layout(location = 3) out uvec4 out3;
#elif LUCENT_COPY_OUT3_KIND == 2
layout(location = 3) out ivec4 out3;
#else
layout(location = 3) out vec4 out3;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 4
#if LUCENT_COPY_OUT4_KIND == 1
layout(location = 4) out uvec4 out4;
#elif LUCENT_COPY_OUT4_KIND == 2
layout(location = 4) out ivec4 out4;
#else
layout(location = 4) out vec4 out4;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 5
#if LUCENT_COPY_OUT5_KIND == 1
layout(location = 5) out uvec4 out5;
#elif LUCENT_COPY_OUT5_KIND == 2
layout(location = 5) out ivec4 out5;
#else
layout(location = 5) out vec4 out5;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 6
#if LUCENT_COPY_OUT6_KIND == 1
layout(location = 6) out uvec4 out6;
#elif LUCENT_COPY_OUT6_KIND == 2
layout(location = 6) out ivec4 out6;
#else
layout(location = 6) out vec4 out6;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 7
#if LUCENT_COPY_OUT7_KIND == 1
layout(location = 7) out uvec4 out7;
#elif LUCENT_COPY_OUT7_KIND == 2
layout(location = 7) out ivec4 out7;
#else
layout(location = 7) out vec4 out7;
#endif
#endif

layout(location = 0) in vec2 in_uv;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    // A pass without image inputs (a G-buffer pass) still writes something that varies.
    vec4 v = vec4(in_uv, 0.0, 1.0);
    uvec4 bits = uvec4(0u);
#if LUCENT_COPY_INPUTS > 0
#if LUCENT_COPY_IN0_KIND == 0
    v += texelFetch(in0, px, 0);
#else
    bits ^= uvec4(texelFetch(in0, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 1
#if LUCENT_COPY_IN1_KIND == 0
    v += texelFetch(in1, px, 0);
#else
    bits ^= uvec4(texelFetch(in1, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 2
#if LUCENT_COPY_IN2_KIND == 0
    v += texelFetch(in2, px, 0);
#else
    bits ^= uvec4(texelFetch(in2, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 3
#if LUCENT_COPY_IN3_KIND == 0
    v += texelFetch(in3, px, 0);
#else
    bits ^= uvec4(texelFetch(in3, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 4
#if LUCENT_COPY_IN4_KIND == 0
    v += texelFetch(in4, px, 0);
#else
    bits ^= uvec4(texelFetch(in4, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 5
#if LUCENT_COPY_IN5_KIND == 0
    v += texelFetch(in5, px, 0);
#else
    bits ^= uvec4(texelFetch(in5, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 6
#if LUCENT_COPY_IN6_KIND == 0
    v += texelFetch(in6, px, 0);
#else
    bits ^= uvec4(texelFetch(in6, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 7
#if LUCENT_COPY_IN7_KIND == 0
    v += texelFetch(in7, px, 0);
#else
    bits ^= uvec4(texelFetch(in7, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 8
#if LUCENT_COPY_IN8_KIND == 0
    v += texelFetch(in8, px, 0);
#else
    bits ^= uvec4(texelFetch(in8, px, 0));
#endif
#endif
#if LUCENT_COPY_INPUTS > 9
#if LUCENT_COPY_IN9_KIND == 0
    v += texelFetch(in9, px, 0);
#else
    bits ^= uvec4(texelFetch(in9, px, 0));
#endif
#endif
    vec4 f = v + vec4(bits & uvec4(1u));
    uvec4 u = floatBitsToUint(v) ^ bits;
#if LUCENT_COPY_OUTPUTS > 0
#if LUCENT_COPY_OUT0_KIND == 1
    out0 = u;
#elif LUCENT_COPY_OUT0_KIND == 2
    out0 = ivec4(u);
#else
    out0 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 1
#if LUCENT_COPY_OUT1_KIND == 1
    out1 = u;
#elif LUCENT_COPY_OUT1_KIND == 2
    out1 = ivec4(u);
#else
    out1 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 2
#if LUCENT_COPY_OUT2_KIND == 1
    out2 = u;
#elif LUCENT_COPY_OUT2_KIND == 2
    out2 = ivec4(u);
#else
    out2 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 3
#if LUCENT_COPY_OUT3_KIND == 1
    out3 = u;
#elif LUCENT_COPY_OUT3_KIND == 2
    out3 = ivec4(u);
#else
    out3 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 4
#if LUCENT_COPY_OUT4_KIND == 1
    out4 = u;
#elif LUCENT_COPY_OUT4_KIND == 2
    out4 = ivec4(u);
#else
    out4 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 5
#if LUCENT_COPY_OUT5_KIND == 1
    out5 = u;
#elif LUCENT_COPY_OUT5_KIND == 2
    out5 = ivec4(u);
#else
    out5 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 6
#if LUCENT_COPY_OUT6_KIND == 1
    out6 = u;
#elif LUCENT_COPY_OUT6_KIND == 2
    out6 = ivec4(u);
#else
    out6 = f;
#endif
#endif
#if LUCENT_COPY_OUTPUTS > 7
#if LUCENT_COPY_OUT7_KIND == 1
    out7 = u;
#elif LUCENT_COPY_OUT7_KIND == 2
    out7 = ivec4(u);
#else
    out7 = f;
#endif
#endif
#ifdef LUCENT_COPY_DEPTH
    // Depth inputs are in [0, 1]; the target is cleared to 1 and tested LESS.
    gl_FragDepth = clamp(fract(f.r) * 0.5, 0.0, 0.99);
#endif
}
