// A host's depth (lucent::embed): the world position of a pixel from a texel of the host's
// depth image, a device depth of the frame's projection (standard, reversed or infinite: the
// frame's inverse view-projection unprojects each) or a linear view depth (src/embed/gbuffer.rs
// `DepthEncoding`). Shared by every effect that reads a host's depth positions (GDC 2011
// translucency, SSS transmission, Li et al.'s layered media). Needs scene.glsl.
#ifndef LUCENT_HOST_DEPTH_GLSL
#define LUCENT_HOST_DEPTH_GLSL

// The host's depth image holds linear view depth (DepthEncoding::LinearView): a specialization
// constant of the SSS passes (src/features/sss/mod.rs `SssInputs::specialization`), folded by
// the driver; the other effects' passes leave it false and pass `linear_view` themselves.
layout(constant_id = 21) const bool HOST_DEPTH_LINEAR = false;

// The view-space point on the ray through `frag_coord` at view depth `z`: the ray's direction
// from the frame's inverse view-projection (its point at device depth 0.5 is finite for
// standard, reversed and infinite projections alike).
vec3 view_point_at_depth(vec2 frag_coord, float z) {
    vec3 on_ray = world_position(frag_coord, 0.5);
    vec3 view = (frame.view * vec4(on_ray, 1.0)).xyz;
    return view * (z / max(-view.z, 1e-30));
}

// The world position on the ray through `frag_coord` at view depth `z`
// (view_point_at_depth), brought back to the world by `view_to_world` (the inverse of the
// frame's view matrix).
vec3 position_at_view_depth(vec2 frag_coord, float z, mat4 view_to_world) {
    return (view_to_world * vec4(view_point_at_depth(frag_coord, z), 1.0)).xyz;
}

// The world position at `frag_coord` of depth texel value `d`: unprojected as a device depth,
// or (`linear_view`) taken as the view depth it is.
vec3 host_world_position(vec2 frag_coord, float d, bool linear_view, mat4 view_to_world) {
    return linear_view ? position_at_view_depth(frag_coord, linear_depth(d), view_to_world)
                       : world_position(frag_coord, d);
}

#endif
