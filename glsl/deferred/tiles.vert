#version 450
// Screen tiles of the lighting pass (src/passes/translucency.rs `tile_buffer`): positions
// already in NDC, uv in [0,1] over the viewport as glsl/fullscreen.vert gives it.
layout(location = 0) in vec2 in_position;
layout(location = 0) out vec2 out_uv;

void main() {
    out_uv = in_position * 0.5 + 0.5;
    gl_Position = vec4(in_position, 0.0, 1.0);
}
