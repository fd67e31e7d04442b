//! GLSL a host includes in its own shaders: lucent's per-pixel lighting terms as functions of
//! plain values, for a host that adds them inside the lighting pass that loops over its lights
//! instead of recording an effect's fullscreen pass after it. That is where lucent's own
//! lighting pass adds them: no extra read of the G-buffer, no extra pass (docs/embedding.md
//! measures what each costs inside `examples/host_engine.rs`'s lighting).
//!
//! | function | the effect it replaces | the data, from the Rust side |
//! |---|---|---|
//! | `vec3 lucent_sh_ambient(vec4 sh[9], vec3 n)` | [`super::EnvironmentEffect`] | `sh`: [`crate::scene::Environment::coefficients`]; times the albedo where the host's diffuse has it |
//! | `vec3 lucent_translucency(albedo, thickness, material, to_eye, v_dot_n, to_light, radiance, attenuation, translucency_scale)` | [`super::TranslucencyEffect`] | `material`: [`super::TranslucentMaterial::row`]; `translucency_scale`: [`super::Light::translucency_scale`]; per light, added to the diffuse |
//! | `vec3 lucent_sss_transmitted(vec4 medium[4], normal, to_light, thickness, light_at_entry)` (and `lucent_sss_transmittance(medium, thickness)` under it) | [`super::TransmissionEffect`] | `medium`: [`super::TransmissionMaterial::rows`] in the host's unit; per light and map texel, weighted bilinearly, times albedo / pi |
//! | `bool lucent_shadow_texels(map, view_proj, rect, params, pos, normal, out inner, out inner_distance, out texel_distances, out weights)`, `vec3 lucent_map_entry_point(params, light_position, inner, to_light, inner_distance, texel_distance)` | the thickness [`super::TransmissionEffect`] measures | the host's shadow map (a `sampler2D`, or a `sampler2DArray` whose face's layer is in its rows) and each face's rows, [`super::ShadowFace::terms_rows`]: the texels around the point and where the light enters through each (docs/embedding.md) |
//! | `void lucent_view_plane_lean(mat3 view, n, t, bt, b_t, m_t, base, out n_world, out b_v, out m_v)`, `float lucent_roughness_variance(roughness)`, `vec2 lucent_view_slope(n_view)`, `void lucent_any_tangent_frame(n, out t, out bt)` (the frame of a surface without a normal or LEAN map) | `sss lean in`, the pass [`super::SssEffect`]'s LEAN blurs build their targets with from the host's normals | in the host's **G-buffer** pass, not its lighting: the LEAN targets of [`super::LeanTargetsDesc`] (`vec4(b_v.y, m_v)`, albedo and specular, `n_world` and roughness; the slope x `lucent_view_slope(view * n_world).x` in the lit diffuse's alpha) |
//! | `uvec4 lucent_pack_layer_texels(vec4 first, vec4 second)` | none: lucent's own G-buffer pass writes the same texel | in the host's **G-buffer** pass, for layered materials whose layers read their thickness from depth textures (Li et al.'s `TexDep`): the mesh's depth textures sampled at the pixel, packed into [`super::GBufferDesc::with_layer_depths`]' image |
//!
//! The text is self-contained (no bindings, no includes; every name starts with `lucent_`),
//! GLSL 450. lucent's own shaders include the same file (`glsl/embed/lucent_terms.glsl`), so
//! the terms are one source. `examples/host_engine.rs --fused` is a host that does this; its
//! frame equals the one with the effects within the rounding of its light target.
//!
//! ```
//! // A host's lighting shader, assembled at start-up:
//! let source = format!("#version 450\n{}\n{}", lucent::embed::glsl::TERMS, "void main() {}");
//! assert!(source.contains("vec3 lucent_translucency("));
//! assert!(source.contains("vec3 lucent_sss_transmitted("));
//! assert!(source.contains("bool lucent_shadow_texels("));
//! assert!(source.contains("void lucent_view_plane_lean("));
//! assert!(source.contains("uvec4 lucent_pack_layer_texels("));
//! ```

/// lucent's lighting terms as GLSL functions (see the module docs).
pub const TERMS: &str = include_str!("../../glsl/embed/lucent_terms.glsl");
