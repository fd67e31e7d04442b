#version 450
// permutation: LUCENT_FLOOR_OUTPUTS=3
// The speed-of-light floor of a mesh pass (src/measure/speed_of_light.rs): a constant written
// to each of LUCENT_FLOOR_OUTPUTS colour targets, depth from the rasteriser (no gl_FragDepth,
// so early depth tests stay on, as in the passes it stands for). Integer targets are given the
// float format of the same texel size by the floor frame, so every output is a vec4.
#ifndef LUCENT_FLOOR_OUTPUTS
#define LUCENT_FLOOR_OUTPUTS 0
#endif

#if LUCENT_FLOOR_OUTPUTS > 0
layout(location = 0) out vec4 out0;
#endif
#if LUCENT_FLOOR_OUTPUTS > 1
layout(location = 1) out vec4 out1;
#endif
#if LUCENT_FLOOR_OUTPUTS > 2
layout(location = 2) out vec4 out2;
#endif
#if LUCENT_FLOOR_OUTPUTS > 3
layout(location = 3) out vec4 out3;
#endif
#if LUCENT_FLOOR_OUTPUTS > 4
layout(location = 4) out vec4 out4;
#endif
#if LUCENT_FLOOR_OUTPUTS > 5
layout(location = 5) out vec4 out5;
#endif
#if LUCENT_FLOOR_OUTPUTS > 6
layout(location = 6) out vec4 out6;
#endif
#if LUCENT_FLOOR_OUTPUTS > 7
layout(location = 7) out vec4 out7;
#endif

void main() {
    const vec4 v = vec4(0.5, 0.25, 0.75, 1.0);
#if LUCENT_FLOOR_OUTPUTS > 0
    out0 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 1
    out1 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 2
    out2 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 3
    out3 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 4
    out4 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 5
    out5 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 6
    out6 = v;
#endif
#if LUCENT_FLOOR_OUTPUTS > 7
    out7 = v;
#endif
}
