// Sampling shared by the stochastic gathers (glsl/sss/burley.frag, glsl/layered/multiple.frag):
// a golden-angle spiral rotated by one of nine angles per 3x3 pixel block. Every 3x3 window
// holds all nine rotations, so a resolve that averages a pixel with its 3x3 neighbours sees
// each sample's radius at nine evenly spaced angles: no grain in a still and no repeating
// pattern (a per-pixel random rotation, the engines' choice under TAA, leaves grain a still
// cannot average away; an unrotated spiral leaves copies of a light edge along its directions).
#ifndef LUCENT_SAMPLING_GLSL
#define LUCENT_SAMPLING_GLSL

// The golden angle, radians: consecutive samples of the spiral turn by it.
const float GOLDEN_ANGLE = 2.39996322972865;

// The spiral's rotation at pixel `px`: 2 pi (k + 1/2) / 9 with k from the pixel's place in its
// 3x3 block (neighbours in a row differ by three ninths, in a column by one).
float spiral_rotation(ivec2 px) {
    int k = (px.x % 3) * 3 + (px.y % 3);
    return 6.28318530717959 * (float(k) + 0.5) / 9.0;
}

#endif
