//! A small deferred engine in ash that inserts lucent's GDC 2011 translucency and screen-space
//! SSS into its own frame, the way a host engine would.
//!
//! Everything here is the engine's, not lucent's: its instance (with the Khronos validation
//! layer and synchronization validation when the layer is installed) and debug messenger, its
//! device (created with what `lucent::embed::requirements()` asks for, plus dynamic rendering
//! for itself), its `gpu-allocator` and pipeline cache (shared with lucent), its shaders (GLSL
//! compiled with shaderc at start-up), three frames in flight with their own command buffers,
//! fences and targets, and a frame of its own layout:
//!
//! 1. **G-buffer** (raster, procedural spheres, a thin jade leaf and a floor): reversed-Z D32
//!    depth with an infinite far plane, octahedral normals in RG16_SNORM, albedo in RGBA8, the
//!    engine's own material numbers in an R8_UINT target (skin 17 (a sphere and a thin ear),
//!    marble 42, blue plastic 5, leaf 9, an apple-flesh ball 23, floor 0) and local thickness in R8_UNORM, which the
//!    leaf's draw takes from the engine's vertex buffer (baked once by
//!    `lucent::embed::bake_thickness`).
//! 2. **Lighting** (fullscreen): a sun and a point light behind the leaf (and, without lucent
//!    or with `--engine-ambient`, the engine's own sky-over-ground ambient term), lit diffuse
//!    and specular apart, in B10G11R11 (RGBA16F where the device cannot render B10G11R11).
//! 3. **lucent's environment** (`EnvironmentEffect`): the same sky-over-ground light as an SH
//!    environment (`lucent::embed::Environment::hemisphere`), added to the lit diffuse at the
//!    engine's normals times its albedo; the frame equals the engine's own ambient within the
//!    B10G11R11 target's rounding.
//! 4. **lucent's translucency** (`TranslucencyEffect`): the light of the engine's two lights
//!    let through the leaf, added to the lit diffuse (the engine's lights, as
//!    `lucent::embed::Light`s).
//! 5. **lucent's layered media** (`LayeredEffect`): Li et al.'s transmitted, single and
//!    multiple scattering of the apple-flesh ball (a `LayeredMedium` with eq. 3's physical
//!    weights: the engine's G-buffer gives the ball no Lambert albedo, `λ1 = 0`), added to the
//!    lit diffuse. lucent draws its light-space maps from the engine's own vertex buffer (a
//!    sphere and a floor quad, f32 positions and R16G16B16A16_SNORM normals, 20 bytes a
//!    vertex, not indexed), each object placed by its model matrix, with the faces the engine
//!    gives: the sun's orthographic one and the back light's six.
//!    The engine renders its own shadow maps of the same faces (depth only, standard Z, drawn
//!    from the same vertex buffer: the sun's face in a D32 atlas, the back light's six in the
//!    layers of a D32 cube array beside it) for:
//! 6. **lucent's SSS transmission** (`TransmissionEffect`): the light of both lights diffused
//!    through the skin's and the marble's thin parts (their rims seen against the lights),
//!    measured in the engine's shadow atlas and cube array (lucent's second shadow map:
//!    `with_second_shadow_map`, `ShadowFace::in_second_map`), added to the lit diffuse
//!    (`--no-transmission` leaves it and the engine's shadow maps out).
//! 7. **lucent's SSS** (`SssEffect`): reads the engine's depth, lit diffuse, specular, albedo
//!    and material IDs as they are, blurs the skin and marble pixels and writes diffuse +
//!    specular into the engine's HDR target. With `--without-lucent` the engine composes
//!    diffuse + specular itself instead (its own ambient, no translucency, no scatter).
//!
//!    With `--fused` the engine adds the environment, the translucency and the transmission
//!    inside its own lighting pass instead, with lucent's GLSL (`lucent::embed::glsl::TERMS`:
//!    `lucent_sh_ambient`, `lucent_translucency`, `lucent_sss_transmitted`) and lucent's data
//!    (the environment's coefficients, the leaf's material row, the lights' translucency
//!    scales, the skin's and marble's medium rows), the transmission's thickness measured in
//!    the engine's own shadow atlas and cube array with lucent's lookup (`lucent_shadow_texels`
//!    on a `sampler2D` or a `sampler2DArray`, the faces' rows from `ShadowFace::terms_rows`):
//!    no pass of lucent's but the layered media and the
//!    SSS, the same picture within the target's rounding.
//! 8. **Tonemap** (fullscreen) into an RGBA8 sRGB image, which the last frame copies out as PNG.
//!
//! ```sh
//! cargo run --release --example host_engine -- --size 640x480 --frames 6 --out f.png
//! cargo run --release --example host_engine -- --without-lucent --out without.png
//! cargo run --release --example host_engine -- --timing     # lucent's passes, GPU timestamps
//! cargo run --release --example host_engine -- --fused      # lucent's terms in its lighting
//! cargo run --release --example host_engine -- --scene mixed --out mixed.png
//! ```
//!
//! With `--scene NAME` the frame is lucent's whole frame of a built-in scene or scene file
//! (`SceneRenderer`) drawn into the engine's sRGB target instead (lucent's shadows, SSS
//! transmission, every technique of a lucent scene). Its PNG equals `lucent render --scene
//! NAME` within 1/255.
//!
//! Exits non-zero when anything fails, including any validation error (counted by the
//! engine's own debug messenger; lucent installs none).

use std::ffi::{c_void, CStr};
use std::path::PathBuf;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use ash::vk;
use glam::{Mat4, Vec3};
use lucent::embed::gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use lucent::embed::gpu_allocator::MemoryLocation;
use lucent::embed::{
    capabilities, requirements, DepthDesc, DiffuseDesc, EffectTimer, EmbedOptions, Environment,
    EnvironmentEffect, EnvironmentEffectDesc, EnvironmentFrame, EnvironmentImages, GBufferDesc,
    HostCamera, HostDevice, HostImage, IdDesc, ImageState, LayeredEffect, LayeredEffectDesc,
    LayeredFrame, LayeredImages, LayeredMaterial, LayeredMedium, LeanLighting, LeanSurface, Light,
    Lucent, MeshDraw, NormalDesc, NormalSpace, OptionalFeatures, SceneRenderer, ShadowFace,
    SpecularSurface, SssEffect, SssEffectDesc, SssFrame, SssImages, SssMaterial, SssProfile,
    SssRegion, ThicknessDesc, TranslucencyEffect, TranslucencyEffectDesc, TranslucencyFrame,
    TranslucencyImages, TranslucentMaterial, TransmissionEffect, TransmissionEffectDesc,
    TransmissionFrame, TransmissionImages, TransmissionMaterial,
};

/// The engine's ambient light: a sky radiance above the horizon and a ground radiance below,
/// blended by the normal's height (its lighting shader's own term, or lucent's
/// `Environment::hemisphere` of the same two, which is that blend exactly).
const AMBIENT_SKY: [f32; 3] = [0.20, 0.24, 0.30];
const AMBIENT_GROUND: [f32; 3] = [0.10, 0.09, 0.08];
/// Frames the engine keeps in flight.
const FRAMES_IN_FLIGHT: usize = 3;
const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
const NORMAL_FORMAT: vk::Format = vk::Format::R16G16_SNORM;
const ALBEDO_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
const ID_FORMAT: vk::Format = vk::Format::R8_UINT;
/// Local thickness (GDC 2011): baked per vertex by lucent, carried through the engine's vertex
/// buffer into this G-buffer target.
const THICKNESS_FORMAT: vk::Format = vk::Format::R8_UNORM;
const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// The engine's material numbers in its ID target (0: the floor; 5 has no SSS).
const SKIN_ID: u8 = 17;
const MARBLE_ID: u8 = 42;
const PLASTIC_ID: u8 = 5;
/// The spheres (skin, marble, plastic): centre and radius in metres.
const SPHERES: [[f32; 4]; 3] = [
    [-0.14, 0.06, 0.0, 0.06],
    [0.0, 0.06, 0.0, 0.06],
    [0.14, 0.06, 0.0, 0.06],
];
/// The thin jade leaf, lit through by GDC 2011 translucency.
const LEAF_ID: u8 = 9;
/// The leaf: an ellipsoid's centre and radii (metres), thin along z.
const LEAF_CENTRE: [f32; 3] = [-0.06, 0.15, -0.12];
const LEAF_RADII: [f32; 3] = [0.06, 0.045, 0.006];
/// A thin ear of skin (an ellipsoid 8 mm thick) beside the leaf, lit from behind by the back
/// light: SSS transmission makes it glow red through its thickness.
const EAR_CENTRE: [f32; 3] = [-0.2, 0.14, -0.17];
const EAR_RADII: [f32; 3] = [0.035, 0.045, 0.004];
/// A point light behind the leaf (position, colour times intensity, range): the engine lights
/// with it, and lucent's translucency lets it through the leaf.
const BACK_LIGHT: [f32; 3] = [-0.08, 0.17, -0.24];
const BACK_LIGHT_RADIANCE: [f32; 3] = [0.16, 0.14, 0.11];
const BACK_LIGHT_RANGE: f32 = 0.6;
/// The ball of Li et al.'s layered medium (an apple's flesh): its material number, and its
/// centre and radius in metres.
const LAYERED_ID: u8 = 23;
const LAYERED_SPHERE: [f32; 4] = [-0.07, 0.03, 0.09, 0.03];
/// lucent's light-space atlas for the layered medium: the sun's 512-texel face on the left,
/// the back light's six 256-texel faces two a row on the right (single scattering finds where
/// light entered the ball per map texel: a coarser sun face shows its texels along the
/// marble's shadow).
const LIGHT_SPACE: vk::Extent2D = vk::Extent2D {
    width: 1024,
    height: 768,
};
const SUN_FACE_EDGE: u32 = 512;
/// The engine's shadow maps: depth, standard Z (lucent reads shadow maps so). Its atlas holds
/// the sun's face; its back light's six faces are the layers of a cube array beside it (lucent
/// reads the array as the effects' second shadow map).
const SHADOW_FORMAT: vk::Format = vk::Format::D32_SFLOAT;
const POINT_FACE_EDGE: u32 = 256;
const SHADOW_ATLAS: vk::Extent2D = vk::Extent2D {
    width: SUN_FACE_EDGE,
    height: SUN_FACE_EDGE,
};
const SHADOW_CUBE: vk::Extent2D = vk::Extent2D {
    width: POINT_FACE_EDGE,
    height: POINT_FACE_EDGE,
};
/// The procedural sphere's tessellation (its vertex count is `6 * STACKS * SLICES`).
const STACKS: u32 = 48;
const SLICES: u32 = 64;

static VALIDATION_ERRORS: AtomicU32 = AtomicU32::new(0);

struct Args {
    width: u32,
    height: u32,
    frames: usize,
    out: PathBuf,
    with_lucent: bool,
    blur: String,
    /// `--marble-blur`: the marble's blur (the LEAN-mapping thesis's LBB by default, the
    /// thesis's own material; `--blur` for the skin).
    marble_blur: String,
    /// `--whole-screen`: the effects draw over the whole screen, not only over the objects'
    /// screen regions (the same picture; a check of the regions).
    whole_screen: bool,
    /// `--engine-ambient`: the engine's lighting adds its own ambient term instead of lucent's
    /// `EnvironmentEffect` adding the same light (a check of the effect).
    engine_ambient: bool,
    /// `--fused`: the engine's lighting pass adds lucent's environment, translucency and
    /// transmission terms itself (`lucent::embed::glsl::TERMS`) instead of lucent's effects
    /// adding them after it.
    fused: bool,
    /// `--no-transmission`: no SSS transmission (and no shadow maps of the engine's).
    no_transmission: bool,
    /// `--timing`: time lucent's passes with GPU timestamps (`record_timed`) and print each
    /// pass's median over the frames.
    timing: bool,
    /// `--scene NAME`: the frame is lucent's whole frame of a built-in scene or scene file
    /// (`SceneRenderer`) instead of the engine's own.
    scene: Option<String>,
}

const USAGE: &str = "usage: host_engine [--size WxH] [--frames N] [--out F.png] \
                     [--blur separable|control|burley|lcb|lbb|bilateral] \
                     [--marble-blur BLUR] [--without-lucent] [--whole-screen] \
                     [--engine-ambient] [--fused] [--no-transmission] [--timing] \
                     [--scene NAME]";

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        width: 320,
        height: 240,
        frames: 6,
        out: PathBuf::from("host_engine.png"),
        with_lucent: true,
        blur: "separable".into(),
        marble_blur: "lbb".into(),
        whole_screen: false,
        engine_ambient: false,
        fused: false,
        no_transmission: false,
        timing: false,
        scene: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        match flag.as_str() {
            "--size" => {
                let v = value()?;
                let (w, h) = v
                    .split_once('x')
                    .ok_or(format!("--size {v}: expected WIDTHxHEIGHT"))?;
                args.width = w.parse().map_err(|_| format!("--size {v}: bad width"))?;
                args.height = h.parse().map_err(|_| format!("--size {v}: bad height"))?;
                if args.width == 0 || args.height == 0 || args.width > 8192 || args.height > 8192 {
                    return Err(format!("--size {v}: 1 to 8192 pixels a side"));
                }
            }
            "--frames" => {
                let v = value()?;
                args.frames = v
                    .parse()
                    .map_err(|_| format!("--frames {v}: not a count"))?;
                if args.frames == 0 {
                    return Err("--frames must be at least 1".into());
                }
            }
            "--out" => args.out = PathBuf::from(value()?),
            "--blur" => args.blur = value()?,
            "--marble-blur" => args.marble_blur = value()?,
            "--without-lucent" => args.with_lucent = false,
            "--whole-screen" => args.whole_screen = true,
            "--engine-ambient" => args.engine_ambient = true,
            "--fused" => args.fused = true,
            "--no-transmission" => args.no_transmission = true,
            "--timing" => args.timing = true,
            "--scene" => args.scene = Some(value()?),
            "--help" | "-h" => return Err(USAGE.into()),
            other => return Err(format!("unknown argument {other}\n{USAGE}")),
        }
    }
    Ok(args)
}

/// The engine's shaders (GLSL, compiled at start-up).
mod shaders {
    /// A fullscreen triangle.
    pub const FULLSCREEN_VERT: &str = r#"#version 450
void main() {
    vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
"#;

    /// The push constants every pipeline shares (`m`: the G-buffer's view-projection, the
    /// lighting's inverse view-projection).
    const PUSH: &str =
        "layout(push_constant) uniform Push { mat4 m; vec4 eye; vec4 sun; vec4 params; } pc;\n";

    /// Three spheres (instances 0-2), the leaf (3), a floor (4), the layered ball (5) and the
    /// skin ear (6),
    /// generated from the vertex index.
    pub fn gbuffer_vert() -> String {
        format!(
            r#"#version 450
{PUSH}
// The leaf's thickness at this vertex (the engine's vertex buffer: lucent's bake).
layout(location = 0) in float a_thickness;
layout(location = 0) out vec3 v_world;
layout(location = 1) out vec3 v_normal;
layout(location = 2) flat out uint v_object;
layout(location = 3) out float v_thickness;
// Centre (xyz) and radius (w) in metres: the three spheres, then the layered ball.
const vec4 SPHERES[4] = vec4[4]({SPHERES});
void main() {{
    uint object = uint(gl_InstanceIndex);
    vec3 p;
    vec3 n;
    if (object == 4u) {{
        const vec2 corners[6] = vec2[6](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, -1),
                                        vec2(1, 1), vec2(-1, 1));
        vec2 c = corners[gl_VertexIndex % 6];
        p = vec3(c.x, 0.0, c.y);
        n = vec3(0.0, 1.0, 0.0);
    }} else {{
        const uvec2 corner[6] = uvec2[6](uvec2(0, 0), uvec2(1, 0), uvec2(1, 1), uvec2(0, 0),
                                         uvec2(1, 1), uvec2(0, 1));
        uint quad = uint(gl_VertexIndex) / 6u;
        uvec2 k = uvec2(quad / {SLICES}u, quad % {SLICES}u) + corner[uint(gl_VertexIndex) % 6u];
        float theta = float(k.x) / {STACKS}.0 * 3.14159265;
        float phi = float(k.y) / {SLICES}.0 * 6.28318531;
        n = vec3(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
        if (object == 3u || object == 6u) {{
            // The leaf (3) and the ear (6): the unit sphere scaled to an ellipsoid (normals by
            // the inverse).
            vec3 centre = object == 3u ? vec3({LX}, {LY}, {LZ}) : vec3({EX}, {EY}, {EZ});
            vec3 radii = object == 3u ? vec3({RX}, {RY}, {RZ}) : vec3({ERX}, {ERY}, {ERZ});
            p = centre + radii * n;
            n = normalize(n / radii);
        }} else {{
            vec4 s = SPHERES[object == 5u ? 3u : object];
            p = s.xyz + s.w * n;
        }}
    }}
    v_world = p;
    v_normal = n;
    v_object = object;
    v_thickness = object == 3u ? a_thickness : 0.0;
    gl_Position = pc.m * vec4(p, 1.0);
}}
"#,
            SLICES = super::SLICES,
            STACKS = super::STACKS,
            SPHERES = super::SPHERES
                .iter()
                .chain([&super::LAYERED_SPHERE])
                .map(|&[x, y, z, r]| format!("vec4({x:?}, {y:?}, {z:?}, {r:?})"))
                .collect::<Vec<_>>()
                .join(", "),
            LX = super::LEAF_CENTRE[0],
            LY = super::LEAF_CENTRE[1],
            LZ = super::LEAF_CENTRE[2],
            RX = super::LEAF_RADII[0],
            RY = super::LEAF_RADII[1],
            RZ = super::LEAF_RADII[2],
            EX = super::EAR_CENTRE[0],
            EY = super::EAR_CENTRE[1],
            EZ = super::EAR_CENTRE[2],
            ERX = super::EAR_RADII[0],
            ERY = super::EAR_RADII[1],
            ERZ = super::EAR_RADII[2],
        )
    }

    /// The engine's shadow maps: each object's positions from its vertex buffer, depth only
    /// (`m`: the face's view-projection times the object's model matrix).
    pub fn shadow_vert() -> String {
        format!(
            r#"#version 450
{PUSH}
layout(location = 0) in vec3 a_position;
void main() {{
    gl_Position = pc.m * vec4(a_position, 1.0);
}}
"#
        )
    }

    /// Depth only: nothing to write.
    pub const SHADOW_FRAG: &str = "#version 450\nvoid main() {}\n";

    pub fn gbuffer_frag() -> String {
        format!(
            r#"#version 450
layout(location = 0) in vec3 v_world;
layout(location = 1) in vec3 v_normal;
layout(location = 2) flat in uint v_object;
layout(location = 3) in float v_thickness;
layout(location = 0) out vec2 o_normal;  // octahedral (RG16_SNORM)
layout(location = 1) out vec4 o_albedo;  // albedo, a: gloss
layout(location = 2) out uint o_id;      // the engine's material number (R8_UINT)
layout(location = 3) out float o_thickness;  // local thickness (R8_UNORM)
vec2 sign_not_zero(vec2 v) {{ return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }}
vec2 oct_encode(vec3 n) {{
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    return n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
}}
void main() {{
    vec3 albedo;
    float gloss;
    uint id;
    if (v_object == 0u || v_object == 6u) {{ albedo = vec3(0.80, 0.52, 0.40); gloss = {SKIN_GLOSS:?}; id = {SKIN}u; }}
    else if (v_object == 1u) {{ albedo = vec3(0.83, 0.81, 0.78); gloss = {MARBLE_GLOSS:?}; id = {MARBLE}u; }}
    else if (v_object == 2u) {{ albedo = vec3(0.20, 0.35, 0.75); gloss = 0.6; id = {PLASTIC}u; }}
    else if (v_object == 3u) {{ albedo = vec3(0.42, 0.78, 0.50); gloss = 0.7; id = {LEAF}u; }}
    // Li et al.'s eq. 3 with physical weights: no Lambert term (λ1 = 0; the dipole is the
    // medium's diffuse light, which lucent adds), the specular at its own radiance (λ2 = 1).
    else if (v_object == 5u) {{ albedo = vec3(0.0); gloss = 0.6; id = {LAYERED}u; }}
    else {{
        // A floor of 2 cm squares: texture detail the blur must leave sharp.
        ivec2 cell = ivec2(floor(v_world.xz / 0.02));
        albedo = ((cell.x + cell.y) & 1) == 0 ? vec3(0.70) : vec3(0.25);
        gloss = 0.1;
        id = 0u;
    }}
    o_normal = oct_encode(normalize(v_normal));
    o_albedo = vec4(albedo, gloss);
    o_id = id;
    o_thickness = v_thickness;
}}
"#,
            LEAF = super::LEAF_ID,
            LAYERED = super::LAYERED_ID,
            SKIN = super::SKIN_ID,
            MARBLE = super::MARBLE_ID,
            SKIN_GLOSS = super::SKIN_GLOSS,
            MARBLE_GLOSS = super::MARBLE_GLOSS,
            PLASTIC = super::PLASTIC_ID,
        )
    }

    /// What the engine's lighting shader needs to add lucent's terms itself (`--fused`).
    pub struct Fused {
        /// The environment's coefficients (`Environment::coefficients`).
        pub sh: [[f32; 4]; 9],
        /// The leaf's translucency row (`TranslucentMaterial::row`).
        pub leaf_row: [f32; 4],
        /// The sun's and the back light's translucency scales.
        pub scales: [f32; 2],
        /// SSS transmission (none with `--no-transmission`): the skin's and the marble's
        /// medium rows (`TransmissionMaterial::rows`) and the engine's shadow faces.
        pub transmission: Option<FusedTransmission>,
    }

    /// The data of lucent's transmission term in the engine's lighting (`--fused`).
    pub struct FusedTransmission {
        /// The skin's and the marble's rows.
        pub media: [[[f32; 4]; 4]; 2],
        /// The engine's shadow faces as its lighting reads its atlas and cube array
        /// (`ShadowFace::terms_rows`): the sun's, then the back light's six (+X, -X, +Y, -Y,
        /// +Z, -Z), each in its layer.
        pub faces: Vec<[[f32; 4]; 6]>,
    }

    /// Which of lucent's per-object terms a lighting variant adds (`--fused`): each is drawn
    /// only over the tiles of the objects that need it.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct Terms {
        /// GDC 2011 translucency (the leaf).
        pub leaf: bool,
        /// SSS transmission (the skin and the marble).
        pub transmission: bool,
    }

    impl Terms {
        /// No per-object term: the plain lighting (lucent's SH ambient with `--fused`).
        pub const NONE: Terms = Terms {
            leaf: false,
            transmission: false,
        };

        /// The variants `--fused` compiles, the plain one first.
        pub const ALL: [Terms; 4] = [
            Terms::NONE,
            Terms {
                leaf: true,
                transmission: false,
            },
            Terms {
                leaf: false,
                transmission: true,
            },
            Terms {
                leaf: true,
                transmission: true,
            },
        ];

        /// This variant's index in [`Self::ALL`].
        pub fn index(self) -> usize {
            usize::from(self.leaf) + 2 * usize::from(self.transmission)
        }
    }

    /// lucent's transmission on the engine's shadow maps: its atlas (binding 5, standard
    /// Z: the sun's face) and cube array (binding 6: the back light's faces, one a layer),
    /// each face's constants, and lucent's recipe for the thickness a map measures (the point
    /// one map texel inside, the four texels around it, lucent's transmission term per texel
    /// weighted bilinearly: `lucent_sss_transmitted`).
    fn transmission_glsl(t: &FusedTransmission, vec4: &dyn Fn([f32; 4]) -> String) -> String {
        let mat4 = |m: &[[f32; 4]; 4]| format!("mat4({})", m.map(vec4).join(", "));
        format!(
            r#"
const vec4 SKIN_MEDIUM[4] = vec4[4]({SKIN_MEDIUM});
const vec4 MARBLE_MEDIUM[4] = vec4[4]({MARBLE_MEDIUM});
layout(set = 0, binding = 5) uniform sampler2D shadow_atlas;   // the engine's, standard Z
layout(set = 0, binding = 6) uniform sampler2DArray shadow_cube;  // its back light's faces
// Face f's rows (lucent::embed::ShadowFace::terms_rows: its world-to-clip matrix, standard
// Z; its rectangle in the atlas; its texel size, near and far). Chosen by comparisons, not
// read from a constant array: a CPU driver copies a dynamically indexed constant array per
// pixel.
void face_data(int f, out mat4 view_proj, out vec4 rect, out vec4 params) {{
{FACES}
}}

// The light that reaches p (normal n, towards the light l) through the object from face f's
// light (at light_pos; `point` lights fall off as the engine's back light, the sun does not):
// lucent's recipe (lucent_shadow_texels) on the engine's atlas (face 0, the sun's) or cube
// array (the others) and lucent's term per entry.
vec3 transmitted_through(vec4 medium[4], int f, vec3 p, vec3 n, vec3 l, vec3 radiance,
                         bool point, vec3 light_pos) {{
    if (!(dot(n, l) < 0.0)) {{
        return vec3(0.0);  // the lit side: the light does not pass through the object to here
    }}
    mat4 view_proj;
    vec4 rect, params;
    face_data(f, view_proj, rect, params);
    vec3 inner;
    float inner_distance;
    vec4 texel_distances, w;
    bool seen;
    if (f == 0) {{
        seen = lucent_shadow_texels(shadow_atlas, view_proj, rect, params, p, n, inner,
                                    inner_distance, texel_distances, w);
    }} else {{
        seen = lucent_shadow_texels(shadow_cube, view_proj, rect, params, p, n, inner,
                                    inner_distance, texel_distances, w);
    }}
    if (!seen) {{
        return vec3(0.0);  // outside the face: nothing measures the thickness
    }}
    vec3 sum = vec3(0.0);
    for (int k = 0; k < 4; ++k) {{
        if (!(w[k] > 0.0)) {{
            continue;  // the texel holds the far plane: no entry
        }}
        vec3 entry = lucent_map_entry_point(params, light_pos, inner, l, inner_distance,
                                            texel_distances[k]);
        vec3 light = point ? radiance * back_light_falloff(entry) : radiance;
        sum += w[k] * lucent_sss_transmitted(medium, n, l, length(entry - p), light);
    }}
    return sum;
}}
"#,
            FACES = t
                .faces
                .iter()
                .enumerate()
                .map(|(k, f)| format!(
                    // The last face is the else: every output is written.
                    "    {}{{ view_proj = {}; rect = {}; params = {}; }}",
                    match k {
                        0 => format!("if (f == {k}) "),
                        _ if k + 1 == t.faces.len() => "else ".to_string(),
                        _ => format!("else if (f == {k}) "),
                    },
                    mat4(&[f[0], f[1], f[2], f[3]]),
                    vec4(f[4]),
                    vec4(f[5])
                ))
                .collect::<Vec<_>>()
                .join("\n"),
            SKIN_MEDIUM = t.media[0].map(vec4).join(", "),
            MARBLE_MEDIUM = t.media[1].map(vec4).join(", "),
        )
    }

    /// The lighting shader; with `fused`, lucent's GLSL terms and the constants they read
    /// (the engine's own data, compiled in), called where it shades each light: the SH
    /// ambient everywhere, the translucency and the transmission in the variants `terms`
    /// names only (each drawn over the tiles of the objects that need it, the plain one
    /// elsewhere: a CPU driver runs both sides of a branch, so a branch on the ID would cost
    /// the whole screen the term).
    pub fn lighting_frag(fused: Option<&Fused>, terms: Terms) -> String {
        let vec4 = |v: [f32; 4]| format!("vec4({:?}, {:?}, {:?}, {:?})", v[0], v[1], v[2], v[3]);
        let (terms_glsl, ambient, transmitted) = match fused {
            None => (
                String::new(),
                // The engine's own ambient (pc.params.y 1), or none where lucent's
                // EnvironmentEffect adds the same light (0).
                "mix(ground, sky, n.y * 0.5 + 0.5) * pc.params.y".to_string(),
                String::new(),
            ),
            Some(f) => {
                let mut glsl = format!(
                    "{}\nconst vec4 LUCENT_SH[9] = vec4[9]({});\n",
                    lucent::embed::glsl::TERMS,
                    f.sh.iter().map(|&c| vec4(c)).collect::<Vec<_>>().join(", "),
                );
                let mut added = String::new();
                if terms.leaf {
                    glsl += &format!("const vec4 LEAF_ROW = {};\n", vec4(f.leaf_row));
                    added += &leaf_glsl(f);
                }
                if let (true, Some(t)) = (terms.transmission, &f.transmission) {
                    glsl += &transmission_glsl(t, &vec4);
                    added += &format!(
                        r#"
    // SSS transmission through the skin and the marble, from both lights, measured in the
    // engine's shadow atlas and cube array: lucent's term (what its TransmissionEffect adds).
    uint medium_id = texelFetch(id_tex, px, 0).r;
    if (medium_id == {SKIN}u || medium_id == {MARBLE}u) {{
        vec4 medium[4] = medium_id == {SKIN}u ? SKIN_MEDIUM : MARBLE_MEDIUM;
        vec3 through = transmitted_through(medium, 0, p, n, l, sun, false, vec3(0.0));
        vec3 from_back = p - BACK_LIGHT;
        vec3 axes = abs(from_back);
        int axis = (axes.x >= axes.y && axes.x >= axes.z) ? 0 : (axes.y >= axes.z ? 1 : 2);
        int face = 1 + 2 * axis + (from_back[axis] < 0.0 ? 1 : 0);
        through += transmitted_through(medium, face, p, n, to_back * inversesqrt(dist2),
                                       BACK_RADIANCE, true, BACK_LIGHT);
        diffuse += a.rgb * through / 3.14159265;
    }}"#,
                        SKIN = super::SKIN_ID,
                        MARBLE = super::MARBLE_ID,
                    );
                }
                (glsl, "lucent_sh_ambient(LUCENT_SH, n)".to_string(), added)
            }
        };
        lighting_source(&terms_glsl, &ambient, &transmitted)
    }

    /// GDC 2011's translucency through the leaf, from both lights: lucent's term.
    fn leaf_glsl(f: &Fused) -> String {
        format!(
            r#"
    // GDC 2011 translucency through the leaf, from both lights: lucent's term.
    if (texelFetch(id_tex, px, 0).r == {LEAF}u) {{
        vec3 thickness = vec3(texelFetch(thickness_tex, px, 0).r);
        float v_dot_n = dot(v, n);
        diffuse += lucent_translucency(a.rgb, thickness, LEAF_ROW, v, v_dot_n, l, sun, 1.0,
                                       {SUN_SCALE:?});
        diffuse += lucent_translucency(a.rgb, thickness, LEAF_ROW, v, v_dot_n,
                                       to_back * inversesqrt(dist2), BACK_RADIANCE,
                                       back_light_falloff(p), {BACK_SCALE:?});
    }}"#,
            LEAF = super::LEAF_ID,
            SUN_SCALE = f.scales[0],
            BACK_SCALE = f.scales[1],
        )
    }

    /// The lighting shader's source around lucent's terms (`terms`: their GLSL and constants,
    /// `ambient`: the ambient expression, `added`: what main adds to the lit diffuse).
    fn lighting_source(terms: &str, ambient: &str, added: &str) -> String {
        format!(
            r#"#version 450
{PUSH}
// The engine's back light: its position and radiance.
const vec3 BACK_LIGHT = vec3({BX}, {BY}, {BZ});
const vec3 BACK_RADIANCE = vec3({BR}, {BG}, {BB});
// The back light's falloff at q: lucent's point-light falloff (a smooth window to its range).
float back_light_falloff(vec3 q) {{
    vec3 to_back = BACK_LIGHT - q;
    float dist2 = max(dot(to_back, to_back), 1e-4);
    float ratio = sqrt(dist2) / {BRANGE};
    float window = clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    return window * window / dist2;
}}
{terms}
layout(set = 0, binding = 0) uniform sampler2D depth_tex;   // reversed Z, infinite far
layout(set = 0, binding = 1) uniform sampler2D normal_tex;
layout(set = 0, binding = 2) uniform sampler2D albedo_tex;
layout(set = 0, binding = 3) uniform usampler2D id_tex;
layout(set = 0, binding = 4) uniform sampler2D thickness_tex;
layout(location = 0) out vec4 o_diffuse;
layout(location = 1) out vec4 o_specular;
vec2 sign_not_zero(vec2 v) {{ return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }}
vec3 oct_decode(vec2 e) {{
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
    return normalize(n);
}}
void main() {{
    ivec2 px = ivec2(gl_FragCoord.xy);
    float d = texelFetch(depth_tex, px, 0).r;
    if (d <= 0.0) {{
        // The far plane at infinity: the sky.
        o_diffuse = vec4(0.21, 0.27, 0.36, 1.0);
        o_specular = vec4(0.0);
        return;
    }}
    vec2 ndc = (vec2(px) + 0.5) / vec2(textureSize(depth_tex, 0)) * 2.0 - 1.0;
    vec4 w = pc.m * vec4(ndc, d, 1.0);
    vec3 p = w.xyz / w.w;
    vec3 n = oct_decode(texelFetch(normal_tex, px, 0).rg);
    vec4 a = texelFetch(albedo_tex, px, 0);
    vec3 l = normalize(pc.sun.xyz);
    vec3 v = normalize(pc.eye.xyz - p);
    vec3 h = normalize(l + v);
    float nl = max(dot(n, l), 0.0);
    vec3 sun = vec3(1.0, 0.95, 0.88) * pc.sun.w;
    vec3 ground = vec3({GR}, {GG}, {GB}), sky = vec3({SR}, {SG}, {SB});
    vec3 ambient = {ambient};
    // The back light, with lucent's point-light falloff.
    vec3 to_back = BACK_LIGHT - p;
    float dist2 = max(dot(to_back, to_back), 1e-4);
    vec3 back = BACK_RADIANCE * back_light_falloff(p);
    float nb = max(dot(n, to_back * inversesqrt(dist2)), 0.0);
    vec3 diffuse = a.rgb * ((sun * nl + back * nb) / 3.14159265 + ambient);{added}
    o_diffuse = vec4(diffuse, 1.0);
    float shininess = exp2(1.0 + 10.0 * a.a);
    float fresnel = 0.04 + 0.96 * pow(1.0 - max(dot(h, v), 0.0), 5.0);
    float lobe = (shininess + 8.0) / (8.0 * 3.14159265) * pow(max(dot(n, h), 0.0), shininess);
    o_specular = vec4(sun * fresnel * lobe * nl, 1.0);
}}
"#,
            BX = super::BACK_LIGHT[0],
            BY = super::BACK_LIGHT[1],
            BZ = super::BACK_LIGHT[2],
            BR = super::BACK_LIGHT_RADIANCE[0],
            BG = super::BACK_LIGHT_RADIANCE[1],
            BB = super::BACK_LIGHT_RADIANCE[2],
            BRANGE = super::BACK_LIGHT_RANGE,
            GR = super::AMBIENT_GROUND[0],
            GG = super::AMBIENT_GROUND[1],
            GB = super::AMBIENT_GROUND[2],
            SR = super::AMBIENT_SKY[0],
            SG = super::AMBIENT_SKY[1],
            SB = super::AMBIENT_SKY[2],
        )
    }

    /// The engine's own composition when lucent is left out: diffuse + specular.
    pub const COMPOSE_FRAG: &str = r#"#version 450
layout(set = 0, binding = 0) uniform sampler2D diffuse_tex;
layout(set = 0, binding = 1) uniform sampler2D specular_tex;
layout(location = 0) out vec4 o_hdr;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_hdr = vec4(texelFetch(diffuse_tex, px, 0).rgb + texelFetch(specular_tex, px, 0).rgb, 1.0);
}
"#;

    pub fn tonemap_frag() -> String {
        format!(
            r#"#version 450
{PUSH}
layout(set = 0, binding = 0) uniform sampler2D hdr_tex;
layout(location = 0) out vec4 o_ldr;    // an sRGB target: the hardware encodes
void main() {{
    vec3 c = max(texelFetch(hdr_tex, ivec2(gl_FragCoord.xy), 0).rgb, vec3(0.0)) * pc.params.x;
    o_ldr = vec4(vec3(1.0) - exp(-c), 1.0);
}}
"#
        )
    }
}

/// The push constants of every pipeline (`shaders::PUSH`).
#[repr(C)]
#[derive(Clone, Copy)]
struct Push {
    m: [f32; 16],
    eye: [f32; 4],
    sun: [f32; 4],
    params: [f32; 4],
}

impl Push {
    fn bytes(&self) -> &[u8] {
        // SAFETY: `Push` is plain f32s, repr(C), without padding.
        unsafe {
            std::slice::from_raw_parts(
                (self as *const Self).cast::<u8>(),
                std::mem::size_of::<Self>(),
            )
        }
    }
}

unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        VALIDATION_ERRORS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the loader passes valid callback data whose message is a C string.
        let message = unsafe { (*data).message_as_c_str() }
            .map(|m| m.to_string_lossy().into_owned())
            .unwrap_or_default();
        eprintln!("host_engine: validation error: {message}");
    }
    vk::FALSE
}

/// The engine's Vulkan objects.
struct Engine {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    physical_device: vk::PhysicalDevice,
    device: ash::Device,
    queue: vk::Queue,
    queue_family: u32,
    enabled: OptionalFeatures,
    validation: bool,
}

fn create_engine() -> Result<Engine, String> {
    // SAFETY: loading the system's Vulkan loader.
    let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("no Vulkan loader: {e}"))?;
    let layer = c"VK_LAYER_KHRONOS_validation";
    // SAFETY: plain queries of the loader.
    let validation = unsafe { entry.enumerate_instance_layer_properties() }
        .map_err(|e| format!("vkEnumerateInstanceLayerProperties: {e}"))?
        .iter()
        .any(|l| l.layer_name_as_c_str() == Ok(layer));
    let app = vk::ApplicationInfo::default()
        .application_name(c"host_engine")
        .api_version(requirements().api_version);
    let layers = if validation {
        vec![layer.as_ptr()]
    } else {
        vec![]
    };
    let extensions = if validation {
        vec![ash::ext::debug_utils::NAME.as_ptr()]
    } else {
        vec![]
    };
    let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    if validation {
        info = info.push_next(&mut features);
    }
    // SAFETY: every pointer in `info` refers to locals that outlive the call.
    let instance = unsafe { entry.create_instance(&info, None) }
        .map_err(|e| format!("vkCreateInstance: {e}"))?;
    let debug = if validation {
        let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE
                    | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
            )
            .pfn_user_callback(Some(on_message));
        // SAFETY: the instance enabled VK_EXT_debug_utils.
        let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }
            .map_err(|e| format!("vkCreateDebugUtilsMessengerEXT: {e}"))?;
        Some((loader, messenger))
    } else {
        None
    };

    // The first device lucent's requirements accept.
    let needs = requirements();
    // SAFETY: plain query of the instance.
    let devices = unsafe { instance.enumerate_physical_devices() }
        .map_err(|e| format!("vkEnumeratePhysicalDevices: {e}"))?;
    let mut refusals = Vec::new();
    let mut picked = None;
    for pd in devices {
        // SAFETY: `pd` was enumerated from `instance`.
        match unsafe { needs.check(&instance, pd) } {
            Ok(family) => {
                picked = Some((pd, family));
                break;
            }
            Err(e) => refusals.push(e.to_string()),
        }
    }
    let (physical_device, queue_family) = picked.ok_or(format!(
        "no device meets lucent's requirements: {refusals:?}"
    ))?;

    // lucent's required features, plus the optional ones it uses when the device has them.
    // SAFETY: plain queries of a device of this instance.
    let (supported, supported12) = unsafe {
        let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut v12);
        instance.get_physical_device_features2(physical_device, &mut features2);
        (features2.features, v12.host_query_reset)
    };
    let enabled = OptionalFeatures {
        host_query_reset: supported12 == vk::TRUE,
        storage_image_write_without_format: supported.shader_storage_image_write_without_format
            == vk::TRUE,
    };
    let core = vk::PhysicalDeviceFeatures::default()
        .shader_storage_image_write_without_format(enabled.storage_image_write_without_format);
    let mut v12 =
        vk::PhysicalDeviceVulkan12Features::default().host_query_reset(enabled.host_query_reset);
    // The engine draws with dynamic rendering (its own choice; lucent needs only what
    // `requirements()` lists).
    let mut v13 = needs.vulkan13().dynamic_rendering(true);
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .features(core)
        .push_next(&mut v12)
        .push_next(&mut v13);
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(queue_family)
        .queue_priorities(&priorities)];
    let extensions: Vec<*const std::ffi::c_char> =
        needs.device_extensions.iter().map(|e| e.as_ptr()).collect();
    let info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&extensions)
        .push_next(&mut features2);
    // SAFETY: the features were reported as supported; pointers refer to live locals.
    let device = unsafe { instance.create_device(physical_device, &info, None) }
        .map_err(|e| format!("vkCreateDevice: {e}"))?;
    // SAFETY: one queue of this family was requested.
    let queue = unsafe { device.get_device_queue(queue_family, 0) };
    Ok(Engine {
        entry,
        instance,
        debug,
        physical_device,
        device,
        queue,
        queue_family,
        enabled,
        validation,
    })
}

fn check(what: &str, r: Result<(), vk::Result>) -> Result<(), String> {
    r.map_err(|e| format!("{what}: {e}"))
}

/// One of the engine's images, its memory, and the state the engine tracks it in (the state
/// it tells lucent, and the one lucent hands back).
struct Target {
    image: vk::Image,
    /// The whole image's view (a 2-D array view for an array).
    view: vk::ImageView,
    /// Its array layers (1: a 2-D image), and for an array a 2-D view of each to render into.
    layers: u32,
    layer_views: Vec<vk::ImageView>,
    memory: Option<Allocation>,
    format: vk::Format,
    usage: vk::ImageUsageFlags,
    aspect: vk::ImageAspectFlags,
    state: ImageState,
    name: String,
}

fn create_target(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    extent: vk::Extent2D,
    format: vk::Format,
    usage: vk::ImageUsageFlags,
    name: String,
) -> Result<Target, String> {
    create_layered_target(engine, allocator, (extent, 1), format, usage, name)
}

/// [`create_target`] with `layers` array layers (more than 1: an array, its view a 2-D array
/// view, each layer with a 2-D view of its own to render into).
fn create_layered_target(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    (extent, layers): (vk::Extent2D, u32),
    format: vk::Format,
    usage: vk::ImageUsageFlags,
    name: String,
) -> Result<Target, String> {
    let device = &engine.device;
    let aspect = if format == DEPTH_FORMAT {
        vk::ImageAspectFlags::DEPTH
    } else {
        vk::ImageAspectFlags::COLOR
    };
    // SAFETY: plain object creation on the engine's device; destroyed in `destroy_target`.
    unsafe {
        let image = device
            .create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width: extent.width,
                        height: extent.height,
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(layers)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .tiling(vk::ImageTiling::OPTIMAL)
                    .usage(usage),
                None,
            )
            .map_err(|e| format!("vkCreateImage ({name}): {e}"))?;
        let memory = allocator
            .lock()
            .map_err(|_| "allocator lock poisoned".to_string())?
            .allocate(&AllocationCreateDesc {
                name: &name,
                requirements: device.get_image_memory_requirements(image),
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| format!("allocate {name}: {e}"))?;
        check(
            "vkBindImageMemory",
            device.bind_image_memory(image, memory.memory(), memory.offset()),
        )?;
        let view_of = |first: u32, count: u32, view_type| {
            device
                .create_image_view(
                    &vk::ImageViewCreateInfo::default()
                        .image(image)
                        .view_type(view_type)
                        .format(format)
                        .subresource_range(vk::ImageSubresourceRange {
                            base_array_layer: first,
                            layer_count: count,
                            ..range(aspect, 1)
                        }),
                    None,
                )
                .map_err(|e| format!("vkCreateImageView ({name}): {e}"))
        };
        let (view, layer_views) = if layers > 1 {
            let views = (0..layers)
                .map(|layer| view_of(layer, 1, vk::ImageViewType::TYPE_2D))
                .collect::<Result<Vec<_>, _>>()?;
            (view_of(0, layers, vk::ImageViewType::TYPE_2D_ARRAY)?, views)
        } else {
            (view_of(0, 1, vk::ImageViewType::TYPE_2D)?, Vec::new())
        };
        Ok(Target {
            image,
            view,
            layers,
            layer_views,
            memory: Some(memory),
            format,
            usage,
            aspect,
            state: ImageState::UNDEFINED,
            name,
        })
    }
}

fn range(aspect: vk::ImageAspectFlags, layers: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: layers,
    }
}

fn destroy_target(engine: &Engine, allocator: &Mutex<Allocator>, mut target: Target) {
    // SAFETY: the device is idle (the caller waited) and the handles are the target's own.
    unsafe {
        for view in target.layer_views.drain(..) {
            engine.device.destroy_image_view(view, None);
        }
        engine.device.destroy_image_view(target.view, None);
        engine.device.destroy_image(target.image, None);
    }
    if let (Some(memory), Ok(mut allocator)) = (target.memory.take(), allocator.lock()) {
        if let Err(e) = allocator.free(memory) {
            eprintln!("host_engine: freeing {}: {e}", target.name);
        }
    }
}

impl Target {
    /// Records the barrier from the tracked state to `to` (`discard`: the contents are not
    /// needed, the old layout is UNDEFINED) and tracks `to`.
    fn transition(
        &mut self,
        device: &ash::Device,
        cmd: vk::CommandBuffer,
        to: ImageState,
        discard: bool,
    ) {
        let from = self.state;
        let barrier = [vk::ImageMemoryBarrier2::default()
            .src_stage_mask(from.stage)
            .src_access_mask(from.access)
            .dst_stage_mask(to.stage)
            .dst_access_mask(to.access)
            .old_layout(if discard {
                vk::ImageLayout::UNDEFINED
            } else {
                from.layout
            })
            .new_layout(to.layout)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(self.image)
            .subresource_range(range(self.aspect, self.layers))];
        // SAFETY: `cmd` is recording, outside any rendering.
        unsafe {
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&barrier),
            )
        };
        self.state = to;
    }

    /// This image as lucent sees it: in the tracked state, left as lucent leaves it.
    fn host_image(&self, extent: vk::Extent2D) -> HostImage {
        HostImage::new(
            self.name.clone(),
            self.image,
            self.view,
            self.format,
            extent,
            self.usage,
        )
        .with_layers(self.layers)
        .in_state(self.state)
    }
}

/// One frame in flight: its command pool and buffer, its fence, its targets and their
/// descriptor sets.
struct FrameSlot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    depth: Target,
    normal: Target,
    albedo: Target,
    ids: Target,
    thickness: Target,
    diffuse: Target,
    specular: Target,
    hdr: Target,
    ldr: Target,
    /// The engine's shadow atlas (the sun's face of `shadow_faces`) and cube array (the back
    /// light's six faces, one a layer; both none with `--no-transmission`
    /// or without lucent).
    shadow: Option<Target>,
    cube: Option<Target>,
    /// Lighting (depth, normals, albedo), compose (diffuse, specular), tonemap (HDR).
    lighting_set: vk::DescriptorSet,
    compose_set: vk::DescriptorSet,
    tonemap_set: vk::DescriptorSet,
    /// `--timing`: the engine's own two timestamps around its lighting pass (what lucent's
    /// terms cost inside it with `--fused`).
    lighting_queries: Option<vk::QueryPool>,
}

/// The engine's pipelines and what they share.
struct Pipelines {
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    sampler: vk::Sampler,
    pool: vk::DescriptorPool,
    gbuffer: vk::Pipeline,
    lighting: vk::Pipeline,
    /// `--fused`: the lighting's variants with lucent's per-object terms (the leaf's
    /// translucency, the skin's and marble's transmission), each drawn over the tiles of the
    /// objects that need it ([`shaders::Terms`]).
    lighting_terms: Vec<(shaders::Terms, vk::Pipeline)>,
    compose: vk::Pipeline,
    tonemap: vk::Pipeline,
    /// The shadow maps (depth only, standard Z).
    shadow: vk::Pipeline,
}

fn compile(
    device: &ash::Device,
    compiler: &shaderc::Compiler,
    source: &str,
    kind: shaderc::ShaderKind,
    name: &str,
) -> Result<vk::ShaderModule, String> {
    let mut options =
        shaderc::CompileOptions::new().map_err(|e| format!("shaderc options: {e}"))?;
    options.set_target_env(
        shaderc::TargetEnv::Vulkan,
        shaderc::EnvVersion::Vulkan1_3 as u32,
    );
    // Optimized, as an engine ships its shaders (and as lucent compiles its own).
    options.set_optimization_level(shaderc::OptimizationLevel::Performance);
    let spirv = compiler
        .compile_into_spirv(source, kind, name, "main", Some(&options))
        .map_err(|e| format!("{name}: {e}"))?;
    // SAFETY: valid SPIR-V words from shaderc.
    unsafe {
        device.create_shader_module(
            &vk::ShaderModuleCreateInfo::default().code(spirv.as_binary()),
            None,
        )
    }
    .map_err(|e| format!("vkCreateShaderModule ({name}): {e}"))
}

/// What a pipeline reads from vertex buffers.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Vertices {
    /// Nothing (fullscreen passes).
    None,
    /// The G-buffer's float of local thickness per vertex drawn.
    Thickness,
    /// The mesh buffer's positions (`mesh_vertices`).
    Positions,
}

/// A graphics pipeline of `vert` + `frag` for dynamic rendering into `colours` (and `depth`,
/// tested and written with its compare op).
fn pipeline(
    device: &ash::Device,
    cache: vk::PipelineCache,
    layout: vk::PipelineLayout,
    (vert, frag): (vk::ShaderModule, vk::ShaderModule),
    colours: &[vk::Format],
    depth: Option<(vk::Format, vk::CompareOp)>,
    vertices: Vertices,
) -> Result<vk::Pipeline, String> {
    let stages = [
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::VERTEX)
            .module(vert)
            .name(c"main"),
        vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(frag)
            .name(c"main"),
    ];
    // One attribute at location 0: the G-buffer's thickness, or the mesh buffer's position.
    let (stride, format) = match vertices {
        Vertices::Positions => (MESH_STRIDE, vk::Format::R32G32B32_SFLOAT),
        _ => (4, vk::Format::R32_SFLOAT),
    };
    let bindings = [vk::VertexInputBindingDescription::default()
        .binding(0)
        .stride(stride)
        .input_rate(vk::VertexInputRate::VERTEX)];
    let attributes = [vk::VertexInputAttributeDescription::default()
        .location(0)
        .binding(0)
        .format(format)
        .offset(0)];
    let vertex_input = if vertices == Vertices::None {
        vk::PipelineVertexInputStateCreateInfo::default()
    } else {
        vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(&attributes)
    };
    let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .polygon_mode(vk::PolygonMode::FILL)
        .cull_mode(vk::CullModeFlags::NONE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth_state = vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(depth.is_some())
        .depth_write_enable(depth.is_some())
        .depth_compare_op(depth.map_or(vk::CompareOp::ALWAYS, |(_, op)| op));
    let blend: Vec<vk::PipelineColorBlendAttachmentState> = colours
        .iter()
        .map(|_| {
            vk::PipelineColorBlendAttachmentState::default()
                .color_write_mask(vk::ColorComponentFlags::RGBA)
        })
        .collect();
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
    let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(colours)
        .depth_attachment_format(depth.map_or(vk::Format::UNDEFINED, |(format, _)| format));
    let info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .depth_stencil_state(&depth_state)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(layout)
        .push_next(&mut rendering);
    // SAFETY: every pointer in `info` refers to locals that outlive the call.
    unsafe { device.create_graphics_pipelines(cache, &[info], None) }
        .map(|p| p[0])
        .map_err(|(_, e)| format!("vkCreateGraphicsPipelines: {e}"))
}

/// The combined image samplers of the engine's one set layout: the lighting reads depth,
/// normals, albedo, IDs, thickness and (with `--fused` transmission) its shadow atlas and cube
/// array; the other passes' sets read fewer.
const BINDINGS: u32 = 7;

fn create_pipelines(
    engine: &Engine,
    cache: vk::PipelineCache,
    light_format: vk::Format,
    fused: Option<&shaders::Fused>,
) -> Result<Pipelines, String> {
    let device = &engine.device;
    let compiler = shaderc::Compiler::new().map_err(|e| format!("shaderc: {e}"))?;
    use shaderc::ShaderKind::{Fragment, Vertex};
    let fullscreen = compile(
        device,
        &compiler,
        shaders::FULLSCREEN_VERT,
        Vertex,
        "fullscreen.vert",
    )?;
    let modules = [
        fullscreen,
        compile(
            device,
            &compiler,
            &shaders::gbuffer_vert(),
            Vertex,
            "gbuffer.vert",
        )?,
        compile(
            device,
            &compiler,
            &shaders::gbuffer_frag(),
            Fragment,
            "gbuffer.frag",
        )?,
        compile(
            device,
            &compiler,
            &shaders::lighting_frag(fused, shaders::Terms::NONE),
            Fragment,
            "lighting.frag",
        )?,
        compile(
            device,
            &compiler,
            shaders::COMPOSE_FRAG,
            Fragment,
            "compose.frag",
        )?,
        compile(
            device,
            &compiler,
            &shaders::tonemap_frag(),
            Fragment,
            "tonemap.frag",
        )?,
        compile(
            device,
            &compiler,
            &shaders::shadow_vert(),
            Vertex,
            "shadow.vert",
        )?,
        compile(
            device,
            &compiler,
            shaders::SHADOW_FRAG,
            Fragment,
            "shadow.frag",
        )?,
    ];
    // --fused: the lighting's variants with lucent's per-object terms (the transmission's
    // only where the engine renders shadow maps).
    let mut term_modules = Vec::new();
    if let Some(f) = fused {
        for terms in shaders::Terms::ALL.into_iter().skip(1) {
            if terms.transmission && f.transmission.is_none() {
                continue;
            }
            let name = format!("lighting_{terms:?}.frag");
            let source = shaders::lighting_frag(fused, terms);
            match compile(device, &compiler, &source, Fragment, &name) {
                Ok(module) => term_modules.push((terms, module)),
                Err(e) => {
                    for module in modules
                        .into_iter()
                        .chain(term_modules.into_iter().map(|t| t.1))
                    {
                        // SAFETY: made above, used by nothing yet.
                        unsafe { device.destroy_shader_module(module, None) };
                    }
                    return Err(e);
                }
            }
        }
    }
    // SAFETY: plain object creation on the engine's device; destroyed in `destroy_pipelines`.
    let made = unsafe {
        let bindings: Vec<vk::DescriptorSetLayoutBinding> = (0..BINDINGS)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::FRAGMENT)
            })
            .collect();
        let set_layout = device
            .create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                None,
            )
            .map_err(|e| format!("vkCreateDescriptorSetLayout: {e}"))?;
        let push = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            .size(std::mem::size_of::<Push>() as u32)];
        let set_layouts = [set_layout];
        let layout = device
            .create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default()
                    .set_layouts(&set_layouts)
                    .push_constant_ranges(&push),
                None,
            )
            .map_err(|e| format!("vkCreatePipelineLayout: {e}"))?;
        let sampler = device
            .create_sampler(
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::NEAREST)
                    .min_filter(vk::Filter::NEAREST)
                    .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE),
                None,
            )
            .map_err(|e| format!("vkCreateSampler: {e}"))?;
        let sets = 3 * FRAMES_IN_FLIGHT as u32;
        let sizes = [vk::DescriptorPoolSize::default()
            .ty(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .descriptor_count(BINDINGS * sets)];
        let pool = device
            .create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default()
                    .max_sets(sets)
                    .pool_sizes(&sizes),
                None,
            )
            .map_err(|e| format!("vkCreateDescriptorPool: {e}"))?;
        let [_, gbuffer_vert, gbuffer_frag, lighting_frag, compose_frag, tonemap_frag, shadow_vert, shadow_frag] =
            modules;
        let gbuffer = pipeline(
            device,
            cache,
            layout,
            (gbuffer_vert, gbuffer_frag),
            &[NORMAL_FORMAT, ALBEDO_FORMAT, ID_FORMAT, THICKNESS_FORMAT],
            // Reversed Z.
            Some((DEPTH_FORMAT, vk::CompareOp::GREATER)),
            Vertices::Thickness,
        )?;
        // Standard Z, as lucent reads shadow maps.
        let shadow = pipeline(
            device,
            cache,
            layout,
            (shadow_vert, shadow_frag),
            &[],
            Some((SHADOW_FORMAT, vk::CompareOp::LESS)),
            Vertices::Positions,
        )?;
        let lighting = pipeline(
            device,
            cache,
            layout,
            (fullscreen, lighting_frag),
            &[light_format, light_format],
            None,
            Vertices::None,
        )?;
        let mut lighting_terms = Vec::new();
        for &(terms, module) in &term_modules {
            lighting_terms.push((
                terms,
                pipeline(
                    device,
                    cache,
                    layout,
                    (fullscreen, module),
                    &[light_format, light_format],
                    None,
                    Vertices::None,
                )?,
            ));
        }
        let compose = pipeline(
            device,
            cache,
            layout,
            (fullscreen, compose_frag),
            &[HDR_FORMAT],
            None,
            Vertices::None,
        )?;
        let tonemap = pipeline(
            device,
            cache,
            layout,
            (fullscreen, tonemap_frag),
            &[LDR_FORMAT],
            None,
            Vertices::None,
        )?;
        Ok(Pipelines {
            set_layout,
            layout,
            sampler,
            pool,
            gbuffer,
            lighting,
            lighting_terms,
            compose,
            tonemap,
            shadow,
        })
    };
    for module in modules
        .into_iter()
        .chain(term_modules.into_iter().map(|(_, module)| module))
    {
        // SAFETY: the pipelines are made (or failed); the modules are no longer needed.
        unsafe { device.destroy_shader_module(module, None) };
    }
    made
}

fn destroy_pipelines(device: &ash::Device, p: &Pipelines) {
    // SAFETY: the device is idle; the objects are the engine's own.
    unsafe {
        let pipelines = [p.gbuffer, p.lighting, p.compose, p.tonemap, p.shadow];
        for pipeline in pipelines
            .into_iter()
            .chain(p.lighting_terms.iter().map(|&(_, pipeline)| pipeline))
        {
            device.destroy_pipeline(pipeline, None);
        }
        device.destroy_descriptor_pool(p.pool, None);
        device.destroy_sampler(p.sampler, None);
        device.destroy_pipeline_layout(p.layout, None);
        device.destroy_descriptor_set_layout(p.set_layout, None);
    }
}

/// The lit light's format: B10G11R11 where the device renders to it, else RGBA16F.
fn light_format(engine: &Engine) -> vk::Format {
    let wanted = vk::FormatFeatureFlags::COLOR_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE;
    // SAFETY: plain query of the physical device.
    let props = unsafe {
        engine.instance.get_physical_device_format_properties(
            engine.physical_device,
            vk::Format::B10G11R11_UFLOAT_PACK32,
        )
    };
    if props.optimal_tiling_features.contains(wanted) {
        vk::Format::B10G11R11_UFLOAT_PACK32
    } else {
        vk::Format::R16G16B16A16_SFLOAT
    }
}

fn create_slot(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    pipelines: &Pipelines,
    extent: vk::Extent2D,
    light_format: vk::Format,
    index: usize,
    // The engine's own timestamps around its lighting; its shadow atlas.
    (timing, shadow_maps): (bool, bool),
) -> Result<FrameSlot, String> {
    let device = &engine.device;
    use vk::ImageUsageFlags as U;
    let target = |format, usage, what: &str| {
        create_target(
            engine,
            allocator,
            extent,
            format,
            usage,
            format!("{what} {index}"),
        )
    };
    let attachment_sampled = U::COLOR_ATTACHMENT | U::SAMPLED;
    let depth = target(
        DEPTH_FORMAT,
        U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED,
        "depth",
    )?;
    let normal = target(NORMAL_FORMAT, attachment_sampled, "normals")?;
    let albedo = target(ALBEDO_FORMAT, attachment_sampled, "albedo")?;
    let ids = target(ID_FORMAT, attachment_sampled, "material IDs")?;
    let thickness = target(THICKNESS_FORMAT, attachment_sampled, "thickness")?;
    let diffuse = target(light_format, attachment_sampled, "lit diffuse")?;
    let specular = target(light_format, attachment_sampled, "lit specular")?;
    let hdr = target(HDR_FORMAT, attachment_sampled, "hdr")?;
    let ldr = target(LDR_FORMAT, U::COLOR_ATTACHMENT | U::TRANSFER_SRC, "ldr")?;
    let (shadow, cube) = if shadow_maps {
        let usage = U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED;
        (
            Some(create_target(
                engine,
                allocator,
                SHADOW_ATLAS,
                SHADOW_FORMAT,
                usage,
                format!("shadow atlas {index}"),
            )?),
            Some(create_layered_target(
                engine,
                allocator,
                (SHADOW_CUBE, 6),
                SHADOW_FORMAT,
                usage,
                format!("shadow cube array {index}"),
            )?),
        )
    } else {
        (None, None)
    };
    // SAFETY: plain object creation on the engine's device; destroyed in `destroy_slot`.
    unsafe {
        let pool = device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER)
                    .queue_family_index(engine.queue_family),
                None,
            )
            .map_err(|e| format!("vkCreateCommandPool: {e}"))?;
        let cmd = device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
            .map_err(|e| format!("vkAllocateCommandBuffers: {e}"))?[0];
        let fence = device
            .create_fence(
                &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                None,
            )
            .map_err(|e| format!("vkCreateFence: {e}"))?;
        let layouts = [pipelines.set_layout; 3];
        let sets = device
            .allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default()
                    .descriptor_pool(pipelines.pool)
                    .set_layouts(&layouts),
            )
            .map_err(|e| format!("vkAllocateDescriptorSets: {e}"))?;
        let sampled = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let writes: Vec<(vk::DescriptorSet, u32, vk::ImageView, vk::ImageLayout)> = vec![
            (sets[0], 0, depth.view, ImageState::depth_sampled().layout),
            (sets[0], 1, normal.view, sampled),
            (sets[0], 2, albedo.view, sampled),
            (sets[1], 0, diffuse.view, sampled),
            (sets[1], 1, specular.view, sampled),
            (sets[2], 0, hdr.view, sampled),
            // The bindings a set's shader does not read are written too (with an image of the
            // same set, never read): lavapipe (Mesa 22.3.6) crashes on its queue thread when a
            // set with a never-written combined image sampler is bound, draw or no draw.
            (sets[1], 2, diffuse.view, sampled),
            (sets[2], 1, hdr.view, sampled),
            (sets[2], 2, hdr.view, sampled),
            // The IDs and the thickness: the lighting reads them to add lucent's translucency
            // itself (--fused); the other sets' never-read bindings as above.
            (sets[0], 3, ids.view, sampled),
            (sets[0], 4, thickness.view, sampled),
            (sets[1], 3, ids.view, sampled),
            (sets[1], 4, diffuse.view, sampled),
            (sets[2], 3, ids.view, sampled),
            (sets[2], 4, hdr.view, sampled),
            // The shadow atlas: the lighting reads it to add lucent's transmission itself
            // (--fused); without one (and in the other sets), never read.
            (
                sets[0],
                5,
                shadow.as_ref().map_or(depth.view, |s| s.view),
                ImageState::depth_sampled().layout,
            ),
            (sets[1], 5, diffuse.view, sampled),
            (sets[2], 5, hdr.view, sampled),
            // The cube array (its 2-D array view) likewise.
            (
                sets[0],
                6,
                cube.as_ref().map_or(depth.view, |c| c.view),
                ImageState::depth_sampled().layout,
            ),
            (sets[1], 6, diffuse.view, sampled),
            (sets[2], 6, hdr.view, sampled),
        ];
        let infos: Vec<[vk::DescriptorImageInfo; 1]> = writes
            .iter()
            .map(|&(_, _, view, layout)| {
                [vk::DescriptorImageInfo::default()
                    .sampler(pipelines.sampler)
                    .image_view(view)
                    .image_layout(layout)]
            })
            .collect();
        let writes: Vec<vk::WriteDescriptorSet> = writes
            .iter()
            .zip(&infos)
            .map(|(&(set, binding, _, _), info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(binding)
                    .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                    .image_info(info)
            })
            .collect();
        device.update_descriptor_sets(&writes, &[]);
        Ok(FrameSlot {
            pool,
            cmd,
            fence,
            depth,
            normal,
            albedo,
            ids,
            thickness,
            diffuse,
            specular,
            hdr,
            ldr,
            shadow,
            cube,
            lighting_set: sets[0],
            compose_set: sets[1],
            tonemap_set: sets[2],
            lighting_queries: if timing {
                Some(
                    device
                        .create_query_pool(
                            &vk::QueryPoolCreateInfo::default()
                                .query_type(vk::QueryType::TIMESTAMP)
                                .query_count(2),
                            None,
                        )
                        .map_err(|e| format!("vkCreateQueryPool: {e}"))?,
                )
            } else {
                None
            },
        })
    }
}

fn destroy_slot(engine: &Engine, allocator: &Mutex<Allocator>, slot: FrameSlot) {
    // SAFETY: the device is idle (the caller waited) and the handles are the slot's own.
    unsafe {
        engine.device.destroy_fence(slot.fence, None);
        engine.device.destroy_command_pool(slot.pool, None);
        if let Some(pool) = slot.lighting_queries {
            engine.device.destroy_query_pool(pool, None);
        }
    }
    for target in [
        slot.depth,
        slot.normal,
        slot.albedo,
        slot.ids,
        slot.thickness,
        slot.diffuse,
        slot.specular,
        slot.hdr,
        slot.ldr,
    ]
    .into_iter()
    .chain(slot.shadow)
    .chain(slot.cube)
    {
        destroy_target(engine, allocator, target);
    }
}

/// Begins dynamic rendering into `colours` (cleared to 0 when `clear`) and `depth` (cleared
/// to the far plane's depth given with it), with the viewport and scissor of `extent`.
fn begin_rendering(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    extent: vk::Extent2D,
    colours: &[vk::ImageView],
    depth: Option<(vk::ImageView, f32)>,
    clear: bool,
) {
    let load = if clear {
        vk::AttachmentLoadOp::CLEAR
    } else {
        vk::AttachmentLoadOp::DONT_CARE
    };
    let colour_attachments: Vec<vk::RenderingAttachmentInfo> = colours
        .iter()
        .map(|&view| {
            vk::RenderingAttachmentInfo::default()
                .image_view(view)
                .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                .load_op(load)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue::default())
        })
        .collect();
    let depth_attachment = depth.map(|(view, far)| {
        vk::RenderingAttachmentInfo::default()
            .image_view(view)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: far,
                    stencil: 0,
                },
            })
    });
    let area = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent,
    };
    let mut info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1)
        .color_attachments(&colour_attachments);
    if let Some(depth) = &depth_attachment {
        info = info.depth_attachment(depth);
    }
    // SAFETY: `cmd` is recording, outside any rendering; the views are live.
    unsafe {
        device.cmd_begin_rendering(cmd, &info);
        device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: extent.width as f32,
                height: extent.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        device.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// The engine's camera for frame `frame`: a slow orbit, reversed Z with an infinite far plane,
/// y down (Vulkan's clip space).
fn camera(frame: usize, aspect: f32) -> (Mat4, Mat4, Vec3) {
    let angle = 0.35 + 0.03 * frame as f32;
    let eye = Vec3::new(0.40 * angle.sin(), 0.15, 0.40 * angle.cos());
    let view = Mat4::look_at_rh(eye, Vec3::new(0.0, 0.05, 0.0), Vec3::Y);
    let mut projection = Mat4::perspective_infinite_reverse_rh(35f32.to_radians(), aspect, 0.01);
    projection.y_axis.y = -projection.y_axis.y;
    (view, projection, eye)
}

/// The leaf's GDC 2011 material: a broad lobe, the talk's distortion, a little light from
/// every angle.
fn leaf_material() -> TranslucentMaterial {
    TranslucentMaterial::new(LEAF_ID, 6.0, 0.25, 0.02)
}

/// The engine's ambient light as lucent's SH environment: the same sky and ground.
fn engine_environment() -> Environment {
    Environment::hemisphere(Vec3::from(AMBIENT_SKY), Vec3::from(AMBIENT_GROUND))
}

/// The engine's lights as lucent's effects read them: the sun (`sun` points towards it) and
/// the point light behind the leaf, as the engine's lighting shader has them.
fn engine_lights(sun: Vec3) -> [Light; 2] {
    let mut back = Light::point(
        Vec3::from(BACK_LIGHT),
        Vec3::from(BACK_LIGHT_RADIANCE),
        1.0,
        BACK_LIGHT_RANGE,
    );
    // How strongly the back light shines through the leaf (GDC 2011's fLTScale).
    back.translucency_scale = 1.0;
    let mut sun = Light::directional(-sun, Vec3::new(1.0, 0.95, 0.88), 9.0);
    // The sun is high: little of it comes through the leaf towards the camera.
    sun.translucency_scale = 0.2;
    [sun, back]
}

/// Whether the frame inserts lucent's SSS transmission (and so renders its shadow maps).
fn transmission_on(args: &Args) -> bool {
    args.with_lucent && args.scene.is_none() && !args.no_transmission
}

/// Whether lucent's `TransmissionEffect` adds the transmission (not with `--fused`, where the
/// engine's lighting adds it).
fn transmission_effect_on(args: &Args) -> bool {
    transmission_on(args) && !args.fused
}

/// The engine's gloss of the skin and the marble (its G-buffer's albedo alpha).
const SKIN_GLOSS: f32 = 0.5;
const MARBLE_GLOSS: f32 = 0.8;

/// lucent's surface for an engine gloss: the engine's Blinn-Phong exponent `2^(1 + 10 gloss)`
/// is lucent's `2 / r^4 - 2` at roughness r, and its Schlick Fresnel starts at 0.04.
fn engine_surface(gloss: f32) -> SpecularSurface {
    let shininess = (1.0 + 10.0 * gloss).exp2();
    SpecularSurface::new((2.0 / (shininess + 2.0)).powf(0.25), 0.04)
}

/// The skin's and the marble's media, through which their transmission diffuses (lucent's
/// `[material.medium]`: Jensen's skin1 and marble, in metres as the engine's world).
fn transmission_materials() -> Result<Vec<TransmissionMaterial>, String> {
    let medium = |preset: &str| {
        LayeredMedium::preset(preset)
            .map(lucent::embed::Medium::new)
            .map_err(|e| e.to_string())
    };
    Ok(vec![
        TransmissionMaterial::new(SKIN_ID, medium("skin1")?),
        TransmissionMaterial::new(MARBLE_ID, medium("marble")?),
    ])
}

/// lucent's transmission as the engine's lighting adds it (`--fused`): the skin's and the
/// marble's medium rows in the engine's metres, its shadow faces as its lighting reads them.
fn fused_transmission() -> Result<shaders::FusedTransmission, String> {
    let rows = |m: &TransmissionMaterial| m.rows(1.0).map_err(|e| e.to_string());
    let [skin, marble] = <[TransmissionMaterial; 2]>::try_from(transmission_materials()?)
        .map_err(|_| "two transmitting materials".to_string())?;
    Ok(shaders::FusedTransmission {
        media: [rows(&skin)?, rows(&marble)?],
        faces: shadow_faces(sun_direction())
            .iter()
            .map(|face| {
                let map = if face.map == 0 {
                    SHADOW_ATLAS
                } else {
                    SHADOW_CUBE
                };
                face.terms_rows(map).map_err(|e| e.to_string())
            })
            .collect::<Result<_, _>>()?,
    })
}

/// The layered ball's medium: Jensen's apple with eq. 3's physical weights.
fn layered_medium() -> Result<LayeredMedium, String> {
    let mut medium = LayeredMedium::preset("apple").map_err(|e| e.to_string())?;
    medium.weights = lucent::scene::layered::PHYSICAL_WEIGHTS;
    Ok(medium)
}

/// Vertices of the sphere the G-buffer's vertex shader makes (6 per quad of the STACKS x
/// SLICES grid, unit radius), then the floor's quad: the engine's vertex buffer for lucent's
/// light-space maps, each vertex an f32 position and an R16G16B16A16_SNORM normal (20 bytes).
fn mesh_vertices() -> Vec<u8> {
    const CORNERS: [(u32, u32); 6] = [(0, 0), (1, 0), (1, 1), (0, 0), (1, 1), (0, 1)];
    let snorm = |v: f32| ((v.clamp(-1.0, 1.0) * 32767.0).round() as i16).to_le_bytes();
    let vertex = |p: Vec3, n: Vec3| -> Vec<u8> {
        let mut bytes = Vec::with_capacity(MESH_STRIDE as usize);
        for c in p.to_array() {
            bytes.extend(c.to_le_bytes());
        }
        for c in [n.x, n.y, n.z, 0.0] {
            bytes.extend(snorm(c));
        }
        bytes
    };
    let sphere = (0..STACKS * SLICES).flat_map(|quad| {
        CORNERS.map(|(di, dj)| {
            let (i, j) = (quad / SLICES + di, quad % SLICES + dj);
            let theta = i as f32 / STACKS as f32 * std::f32::consts::PI;
            let phi = j as f32 / SLICES as f32 * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            vertex(n, n)
        })
    });
    let floor = [
        (-1.0, -1.0),
        (1.0, -1.0),
        (1.0, 1.0),
        (-1.0, -1.0),
        (1.0, 1.0),
        (-1.0, 1.0),
    ]
    .map(|(x, z)| vertex(Vec3::new(x, 0.0, z), Vec3::Y));
    sphere.chain(floor).flatten().collect()
}

/// Bytes of one vertex of [`mesh_vertices`].
const MESH_STRIDE: u32 = 20;

/// The engine's objects as lucent draws them into its light-space maps: the sphere mesh
/// placed and scaled per object (the leaf an ellipsoid), then the floor, each with its
/// material number.
fn mesh_draws(buffer: vk::Buffer) -> Vec<MeshDraw> {
    let sphere_vertices = 6 * STACKS * SLICES;
    let ball = |[x, y, z, r]: [f32; 4]| {
        Mat4::from_translation(Vec3::new(x, y, z)) * Mat4::from_scale(Vec3::splat(r))
    };
    let ids = [SKIN_ID, MARBLE_ID, PLASTIC_ID];
    let mut draws: Vec<MeshDraw> = SPHERES
        .iter()
        .zip(ids)
        .map(|(&s, id)| MeshDraw::new(buffer, sphere_vertices, ball(s), id))
        .collect();
    // The unit sphere's bounds (the floor's below): lucent's layered terms then blur only over
    // the objects whose medium they act on at their distance.
    let unit = (Vec3::splat(-1.0), Vec3::ONE);
    let leaf =
        Mat4::from_translation(Vec3::from(LEAF_CENTRE)) * Mat4::from_scale(Vec3::from(LEAF_RADII));
    draws.push(MeshDraw::new(buffer, sphere_vertices, leaf, LEAF_ID));
    let ear =
        Mat4::from_translation(Vec3::from(EAR_CENTRE)) * Mat4::from_scale(Vec3::from(EAR_RADII));
    draws.push(MeshDraw::new(buffer, sphere_vertices, ear, SKIN_ID));
    draws.push(MeshDraw::new(
        buffer,
        sphere_vertices,
        ball(LAYERED_SPHERE),
        LAYERED_ID,
    ));
    let mut floor = MeshDraw::new(buffer, 6, Mat4::IDENTITY, 0)
        .with_bounds(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
    floor.first = sphere_vertices;
    draws.push(floor);
    draws
        .into_iter()
        .map(|d| match d.bounds {
            Some(_) => d,
            None => d.with_bounds(unit.0, unit.1),
        })
        .collect()
}

/// The faces lucent draws its light-space maps with, as the engine gives them: the sun's
/// orthographic face over the objects (light 0), then the back light's six (light 1, +X, -X,
/// +Y, -Y, +Z, -Z), standard Z, each a square tile of the atlas ([`LIGHT_SPACE`]).
fn light_faces(sun: Vec3) -> Vec<ShadowFace> {
    let square = |x: u32, y: u32, edge: u32| vk::Rect2D {
        offset: vk::Offset2D {
            x: x as i32,
            y: y as i32,
        },
        extent: vk::Extent2D {
            width: edge,
            height: edge,
        },
    };
    let tile = |k: u32| {
        square(
            SUN_FACE_EDGE + (k % 2) * POINT_FACE_EDGE,
            (k / 2) * POINT_FACE_EDGE,
            POINT_FACE_EDGE,
        )
    };
    let centre = Vec3::new(0.0, 0.05, 0.0);
    let mut faces = vec![ShadowFace::new(
        0,
        Mat4::look_to_rh(centre + sun, -sun, Vec3::Y),
        Mat4::orthographic_rh(-0.35, 0.35, -0.35, 0.35, 0.05, 2.0),
        square(0, 0, SUN_FACE_EDGE),
    )];
    let axes = [
        Vec3::X,
        Vec3::NEG_X,
        Vec3::Y,
        Vec3::NEG_Y,
        Vec3::Z,
        Vec3::NEG_Z,
    ];
    for (k, axis) in axes.into_iter().enumerate() {
        let up = if axis.y != 0.0 { Vec3::Z } else { Vec3::Y };
        faces.push(ShadowFace::new(
            1,
            Mat4::look_to_rh(Vec3::from(BACK_LIGHT), axis, up),
            Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, 0.005, BACK_LIGHT_RANGE),
            tile(k as u32),
        ));
    }
    faces
}

/// The faces of the engine's own shadow maps, as it hands them to lucent's transmission and
/// LEAN blurs: the sun's in its atlas ([`SHADOW_ATLAS`], the same tile as in
/// [`light_faces`]), the back light's six each filling its layer of the cube array
/// ([`SHADOW_CUBE`], lucent's second shadow map).
fn shadow_faces(sun: Vec3) -> Vec<ShadowFace> {
    let whole = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: SHADOW_CUBE,
    };
    light_faces(sun)
        .into_iter()
        .map(|face| match face.light {
            0 => face,
            _ => ShadowFace::new(face.light, face.view, face.projection, whole),
        })
        .enumerate()
        .map(|(k, face)| match k {
            0 => face,
            _ => face.in_second_map(k as u32 - 1),
        })
        .collect()
}

/// The sun's direction (towards it).
fn sun_direction() -> Vec3 {
    Vec3::new(0.9, 0.75, -0.35).normalize()
}

/// The screen rectangle the layered ball covers: where Li et al.'s passes draw.
fn layered_region(
    camera: &HostCamera,
    extent: vk::Extent2D,
    whole_screen: bool,
) -> Vec<vk::Rect2D> {
    let [x, y, z, r] = LAYERED_SPHERE;
    let (centre, half) = (Vec3::new(x, y, z), Vec3::splat(r));
    let ball = (centre - half, centre + half);
    let region = lucent::embed::box_screen_region(ball, Mat4::IDENTITY, camera, extent, 0.0);
    region.filter(|_| !whole_screen).into_iter().collect()
}

/// The lighting's draws with `--fused`: the screen in 64-pixel tiles, each with the terms
/// whose objects' rectangles it touches (`leaf`: the leaf's translucency, `media`: the
/// transmission), runs of equal tiles along a row merged, sorted by their terms (one bind
/// each). Every pixel is drawn once.
fn term_tiles(
    extent: vk::Extent2D,
    leaf: &[vk::Rect2D],
    media: &[vk::Rect2D],
) -> Vec<(shaders::Terms, vk::Rect2D)> {
    const TILE: u32 = 64;
    let touches = |rects: &[vk::Rect2D], x: u32, y: u32| {
        rects.iter().any(|r| {
            let (x0, y0) = (r.offset.x.max(0) as u32, r.offset.y.max(0) as u32);
            let (x1, y1) = (
                (r.offset.x + r.extent.width as i32).max(0) as u32,
                (r.offset.y + r.extent.height as i32).max(0) as u32,
            );
            x0 < x + TILE && x < x1 && y0 < y + TILE && y < y1
        })
    };
    let mut draws: Vec<(shaders::Terms, vk::Rect2D)> = Vec::new();
    for y in (0..extent.height).step_by(TILE as usize) {
        let mut row: Vec<(shaders::Terms, u32, u32)> = Vec::new();
        for x in (0..extent.width).step_by(TILE as usize) {
            let terms = shaders::Terms {
                leaf: touches(leaf, x, y),
                transmission: touches(media, x, y),
            };
            let right = (x + TILE).min(extent.width);
            match row.last_mut() {
                Some((last, _, end)) if *last == terms => *end = right,
                _ => row.push((terms, x, right)),
            }
        }
        let height = TILE.min(extent.height - y);
        draws.extend(row.into_iter().map(|(terms, x0, x1)| {
            (
                terms,
                vk::Rect2D {
                    offset: vk::Offset2D {
                        x: x0 as i32,
                        y: y as i32,
                    },
                    extent: vk::Extent2D {
                        width: x1 - x0,
                        height,
                    },
                },
            )
        }));
    }
    draws.sort_by_key(|(terms, _)| terms.index());
    draws
}

/// The screen rectangle the leaf covers: where the translucency pass draws (none, the whole
/// screen, when the engine asks for it or the leaf crosses the eye's plane).
fn leaf_region(camera: &HostCamera, extent: vk::Extent2D, whole_screen: bool) -> Vec<vk::Rect2D> {
    let (centre, half) = (Vec3::from(LEAF_CENTRE), Vec3::from(LEAF_RADII));
    let leaf = (centre - half, centre + half);
    let region = lucent::embed::box_screen_region(leaf, Mat4::IDENTITY, camera, extent, 0.0);
    region.filter(|_| !whole_screen).into_iter().collect()
}

/// The objects that scatter: the skin sphere, the marble sphere and the skin ear, each with
/// its material and its bounds (lowest and highest corner, metres).
fn scattering_objects() -> [(u8, (Vec3, Vec3)); 3] {
    let sphere = |[x, y, z, r]: [f32; 4]| {
        let (centre, radius) = (Vec3::new(x, y, z), Vec3::splat(r));
        (centre - radius, centre + radius)
    };
    let (ear_centre, ear_half) = (Vec3::from(EAR_CENTRE), Vec3::from(EAR_RADII));
    [
        (SKIN_ID, sphere(SPHERES[0])),
        (MARBLE_ID, sphere(SPHERES[1])),
        (SKIN_ID, (ear_centre - ear_half, ear_centre + ear_half)),
    ]
}

/// The scattering objects' screen rectangles, each widened by `reach` of its material: `None`
/// when one crosses the eye's plane, or with `--whole-screen` (no region: the whole screen).
fn scattering_rects(
    camera: &HostCamera,
    extent: vk::Extent2D,
    reach: impl Fn(u8) -> f32,
    whole_screen: bool,
) -> Option<Vec<(u8, vk::Rect2D)>> {
    let regions: Option<Vec<(u8, vk::Rect2D)>> = scattering_objects()
        .into_iter()
        .map(|(id, bounds)| {
            lucent::embed::box_screen_region(bounds, Mat4::IDENTITY, camera, extent, reach(id))
                .map(|rect| (id, rect))
        })
        .collect();
    regions.filter(|_| !whole_screen)
}

/// Where the transmission is drawn: the scattering objects' screen rectangles.
fn transmission_regions(
    camera: &HostCamera,
    extent: vk::Extent2D,
    whole_screen: bool,
) -> Vec<vk::Rect2D> {
    scattering_rects(camera, extent, |_| 0.0, whole_screen)
        .map(|rects| rects.into_iter().map(|(_, rect)| rect).collect())
        .unwrap_or_default()
}

/// The SSS blurs' regions: each scattering object's rectangle widened by its own material's
/// reach and given for that material, so each blur chain (the skin's, the marble's) draws
/// only on its own objects' tiles and passes the light through elsewhere.
fn sss_regions(
    camera: &HostCamera,
    extent: vk::Extent2D,
    sss: &SssEffect,
    whole_screen: bool,
) -> Vec<SssRegion> {
    let reach = |id| sss.reach_of(id).unwrap_or_else(|| sss.reach());
    scattering_rects(camera, extent, reach, whole_screen)
        .map(|rects| {
            rects
                .into_iter()
                .map(|(id, rect)| SssRegion::of(id, rect))
                .collect()
        })
        .unwrap_or_default()
}

/// One frame slot's timers, one per effect (`--timing`).
struct Timers {
    environment: Option<EffectTimer>,
    translucency: Option<EffectTimer>,
    layered: EffectTimer,
    transmission: Option<EffectTimer>,
    sss: EffectTimer,
}

/// What lucent adds to the engine: the effect, and the `Lucent` it was built from.
struct Effects {
    lucent: Lucent,
    inserted: Inserted,
    /// `--whole-screen`: no regions.
    whole_screen: bool,
    /// A scattering material has a LEAN blur: the SSS effect reads the normals and lights.
    sss_lean: bool,
    /// `--timing`: per frame slot, the effects' timers.
    timers: Vec<Timers>,
    /// Each timed pass's milliseconds, frame by frame (`effect: pass`).
    times: std::collections::BTreeMap<String, Vec<f64>>,
}

impl Effects {
    /// Reads the times of the frame slot `k` last recorded (its fence has signalled: the
    /// engine waited for it before reusing the slot, or for the device at the end).
    fn collect_times(&mut self, k: usize, engine_lighting_ms: Option<f64>) -> Result<(), String> {
        if let Some(ms) = engine_lighting_ms {
            let key = "engine: lighting".to_string();
            self.times.entry(key).or_default().push(ms);
        }
        let Some(timers) = self.timers.get(k) else {
            return Ok(());
        };
        let named = [
            ("environment", timers.environment.as_ref()),
            ("translucency", timers.translucency.as_ref()),
            ("layered", Some(&timers.layered)),
            ("transmission", timers.transmission.as_ref()),
            ("sss", Some(&timers.sss)),
        ];
        for (effect, timer) in named {
            let Some(timer) = timer else { continue };
            let passes = timer.results(&self.lucent).map_err(|e| e.to_string())?;
            for pass in passes.unwrap_or_default() {
                let key = format!("{effect}: {}", pass.name);
                self.times.entry(key).or_default().push(pass.ms);
            }
        }
        Ok(())
    }

    /// Each timed pass's median, one line.
    fn timing_report(&self) -> String {
        let median = |v: &[f64]| {
            let mut v = v.to_vec();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        self.times
            .iter()
            .map(|(pass, ms)| format!("{pass} {:.3} ms", median(ms)))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// What the engine's frame gets from lucent.
enum Inserted {
    /// Effects over the engine's own G-buffer and lighting: the SH environment, GDC 2011
    /// translucency and Li et al.'s layered media added to its lit diffuse, then SSS.
    Effects {
        /// The engine's ambient as lucent's SH environment (none with `--engine-ambient`).
        environment: Option<Box<EnvironmentEffect>>,
        /// The leaf's translucency (none with `--fused`).
        translucency: Option<Box<TranslucencyEffect>>,
        /// The apple-flesh ball's layered medium.
        layered: Box<LayeredEffect>,
        /// The skin's and marble's transmission (none with `--no-transmission` or `--fused`).
        transmission: Option<Box<TransmissionEffect>>,
        sss: Box<SssEffect>,
    },
    /// lucent's whole frame of a scene (`--scene`): every technique its materials ask for.
    Scene(Box<(lucent::scene::Scene, SceneRenderer)>),
}

/// Builds the effects over the engine's G-buffer; on an error, destroys those already built
/// (nothing of them was recorded or used yet).
fn build_effects(
    lucent: &Lucent,
    uploads: &mut lucent::embed::Uploads,
    environment: Option<EnvironmentEffectDesc>,
    translucency: Option<TranslucencyEffectDesc>,
    layered: LayeredEffectDesc,
    transmission: Option<TransmissionEffectDesc>,
    sss: SssEffectDesc,
) -> lucent::Result<Inserted> {
    let environment = environment
        .map(|desc| EnvironmentEffect::new(lucent, uploads, desc))
        .transpose()?;
    let translucency = match translucency
        .map(|desc| TranslucencyEffect::new(lucent, uploads, desc))
        .transpose()
    {
        Ok(t) => t,
        Err(e) => {
            if let Some(environment) = environment {
                environment.destroy(lucent);
            }
            return Err(e);
        }
    };
    let built = LayeredEffect::new(lucent, uploads, layered).and_then(|layered| {
        let transmission = match transmission
            .map(|desc| TransmissionEffect::new(lucent, uploads, desc))
            .transpose()
        {
            Ok(t) => t,
            Err(e) => {
                layered.destroy(lucent);
                return Err(e);
            }
        };
        match SssEffect::new(lucent, uploads, sss) {
            Ok(sss) => Ok((layered, transmission, sss)),
            Err(e) => {
                layered.destroy(lucent);
                if let Some(transmission) = transmission {
                    transmission.destroy(lucent);
                }
                Err(e)
            }
        }
    });
    match built {
        Ok((layered, transmission, sss)) => Ok(Inserted::Effects {
            environment: environment.map(Box::new),
            translucency: translucency.map(Box::new),
            layered: Box::new(layered),
            transmission: transmission.map(Box::new),
            sss: Box::new(sss),
        }),
        Err(e) => {
            if let Some(environment) = environment {
                environment.destroy(lucent);
            }
            if let Some(translucency) = translucency {
                translucency.destroy(lucent);
            }
            Err(e)
        }
    }
}

/// `--scene`: the frame is lucent's whole frame of the scene, drawn into the engine's LDR
/// target and left for the copy out.
fn record_scene_frame(
    lucent: &Lucent,
    renderer: &mut SceneRenderer,
    scene: &lucent::scene::Scene,
    slot: &mut FrameSlot,
    slot_index: usize,
    extent: vk::Extent2D,
) -> Result<(), String> {
    // Every pixel is drawn: the old contents may be discarded.
    let output = slot
        .ldr
        .host_image(extent)
        .in_state(ImageState {
            layout: vk::ImageLayout::UNDEFINED,
            ..slot.ldr.state
        })
        .then(ImageState::transfer_src());
    slot.ldr.state = renderer
        .record(lucent, slot.cmd, slot_index, scene, &output)
        .map_err(|e| format!("lucent: {e}"))?;
    Ok(())
}

/// Copies `slot`'s image (in TRANSFER_SRC_OPTIMAL, as lucent left it) to host memory.
fn read_back(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    slot: &FrameSlot,
    width: u32,
    height: u32,
) -> Result<Vec<u8>, String> {
    let device = &engine.device;
    let bytes = u64::from(width) * u64::from(height) * 4;
    // SAFETY: objects of the engine's device; the copy is waited for before the buffer is
    // read and everything is destroyed after.
    unsafe {
        let buffer = device
            .create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(bytes)
                    .usage(vk::BufferUsageFlags::TRANSFER_DST),
                None,
            )
            .map_err(|e| format!("vkCreateBuffer: {e}"))?;
        let memory = allocator
            .lock()
            .map_err(|_| "allocator lock poisoned".to_string())?
            .allocate(&AllocationCreateDesc {
                name: "host read-back",
                requirements: device.get_buffer_memory_requirements(buffer),
                location: MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| format!("allocate read-back buffer: {e}"))?;
        check(
            "vkBindBufferMemory",
            device.bind_buffer_memory(buffer, memory.memory(), memory.offset()),
        )?;
        let cmd = slot.cmd;
        check(
            "vkResetCommandBuffer",
            device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()),
        )?;
        check(
            "vkBeginCommandBuffer",
            device.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default()),
        )?;
        device.cmd_copy_image_to_buffer(
            cmd,
            slot.ldr.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer,
            &[vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                })],
        );
        let to_host = [vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::ALL_TRANSFER)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)];
        device.cmd_pipeline_barrier2(
            cmd,
            &vk::DependencyInfo::default().memory_barriers(&to_host),
        );
        check("vkEndCommandBuffer", device.end_command_buffer(cmd))?;
        check("vkResetFences", device.reset_fences(&[slot.fence]))?;
        let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
        check(
            "vkQueueSubmit2",
            device.queue_submit2(engine.queue, &[submit], slot.fence),
        )?;
        check(
            "vkWaitForFences",
            device.wait_for_fences(&[slot.fence], true, u64::MAX),
        )?;
        let pixels = memory
            .mapped_slice()
            .ok_or("the read-back buffer is not mapped")?[..bytes as usize]
            .to_vec();
        device.destroy_buffer(buffer, None);
        if let Ok(mut allocator) = allocator.lock() {
            allocator.free(memory).map_err(|e| e.to_string())?;
        }
        Ok(pixels)
    }
}

/// Records frame `frame` into `slot.cmd`: the engine's G-buffer and lighting, lucent's SSS (or
/// the engine's own composition), the tonemap; the LDR image left as a copy source.
fn record_frame(
    engine: &Engine,
    pipelines: &Pipelines,
    effects: Option<&mut Effects>,
    slot: &mut FrameSlot,
    frame: usize,
    extent: vk::Extent2D,
    (leaf_thickness, meshes): (vk::Buffer, vk::Buffer),
) -> Result<(), String> {
    let device = &engine.device;
    let cmd = slot.cmd;
    // The frame-in-flight slot (`slot` is the engine's for it).
    let slot_index = frame % FRAMES_IN_FLIGHT;
    let (view, projection, eye) = camera(frame, extent.width as f32 / extent.height as f32);
    let sun = sun_direction();
    // The engine adds its own ambient unless lucent's environment effect adds it.
    let engine_ambient = match effects.as_deref() {
        Some(Effects {
            inserted: Inserted::Effects { environment, .. },
            ..
        }) => environment.is_none(),
        _ => true,
    };
    let push = |m: Mat4| Push {
        m: m.to_cols_array(),
        eye: [eye.x, eye.y, eye.z, 1.0],
        sun: [sun.x, sun.y, sun.z, 9.0],
        params: [1.2, if engine_ambient { 1.0 } else { 0.0 }, 0.0, 0.0],
    };
    let bind = |pipeline, set: Option<vk::DescriptorSet>, m: Mat4| {
        // SAFETY: `cmd` is recording inside the pass's rendering; the objects are live.
        unsafe {
            device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            if let Some(set) = set {
                device.cmd_bind_descriptor_sets(
                    cmd,
                    vk::PipelineBindPoint::GRAPHICS,
                    pipelines.layout,
                    0,
                    &[set],
                    &[],
                );
            }
            device.cmd_push_constants(
                cmd,
                pipelines.layout,
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                push(m).bytes(),
            );
        }
    };
    let fragment_sampled = ImageState::fragment_sampled();
    // The engine's objects and its lights' faces: what its shadow maps draw, and what it hands
    // lucent's layered media and transmission.
    let draws = mesh_draws(meshes);
    let faces = light_faces(sun);
    let engine_faces = shadow_faces(sun);

    // 0. The shadow maps lucent's transmission reads (when it is inserted): every object into
    // the sun's tile of the atlas and into each of the back light's layers of the cube array,
    // depth only, standard Z.
    if let (Some(shadow), Some(cube)) = (&mut slot.shadow, &mut slot.cube) {
        let depth_attachment = ImageState {
            layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            ..ImageState::depth_attachment()
        };
        shadow.transition(device, cmd, depth_attachment, true);
        cube.transition(device, cmd, depth_attachment, true);
        for face in &engine_faces {
            let (view, extent) = match face.map {
                0 => (shadow.view, SHADOW_ATLAS),
                _ => (cube.layer_views[face.layer as usize], SHADOW_CUBE),
            };
            begin_rendering(device, cmd, extent, &[], Some((view, 1.0)), true);
            // SAFETY: inside the map's rendering.
            unsafe {
                device.cmd_set_viewport(
                    cmd,
                    0,
                    &[vk::Viewport {
                        x: face.rect.offset.x as f32,
                        y: face.rect.offset.y as f32,
                        width: face.rect.extent.width as f32,
                        height: face.rect.extent.height as f32,
                        min_depth: 0.0,
                        max_depth: 1.0,
                    }],
                );
                device.cmd_set_scissor(cmd, 0, &[face.rect]);
            }
            for draw in &draws {
                bind(
                    pipelines.shadow,
                    None,
                    face.projection * face.view * draw.transform,
                );
                // SAFETY: inside the map's rendering, the shadow pipeline bound.
                unsafe {
                    device.cmd_bind_vertex_buffers(cmd, 0, &[meshes], &[0]);
                    device.cmd_draw(cmd, draw.count, 1, draw.first, 0);
                }
            }
            // SAFETY: inside the map's rendering.
            unsafe { device.cmd_end_rendering(cmd) };
        }
        shadow.transition(device, cmd, ImageState::depth_sampled(), false);
        cube.transition(device, cmd, ImageState::depth_sampled(), false);
    }

    // 1. The G-buffer.
    for target in [
        &mut slot.normal,
        &mut slot.albedo,
        &mut slot.ids,
        &mut slot.thickness,
    ] {
        target.transition(device, cmd, ImageState::color_attachment(), true);
    }
    let depth_attachment = ImageState {
        layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
        ..ImageState::depth_attachment()
    };
    slot.depth.transition(device, cmd, depth_attachment, true);
    begin_rendering(
        device,
        cmd,
        extent,
        &[
            slot.normal.view,
            slot.albedo.view,
            slot.ids.view,
            slot.thickness.view,
        ],
        // Reversed Z: the far plane is 0.
        Some((slot.depth.view, 0.0)),
        true,
    );
    bind(pipelines.gbuffer, None, projection * view);
    // SAFETY: inside the G-buffer's rendering, its pipeline bound; the thickness buffer holds
    // one float per vertex of a sphere draw.
    unsafe {
        device.cmd_bind_vertex_buffers(cmd, 0, &[leaf_thickness], &[0]);
        // The three spheres and the leaf, the floor, then the layered ball.
        device.cmd_draw(cmd, 6 * STACKS * SLICES, 4, 0, 0);
        device.cmd_draw(cmd, 6, 1, 0, 4);
        device.cmd_draw(cmd, 6 * STACKS * SLICES, 1, 0, 5);
        device.cmd_draw(cmd, 6 * STACKS * SLICES, 1, 0, 6);
        device.cmd_end_rendering(cmd);
    }
    for target in [
        &mut slot.normal,
        &mut slot.albedo,
        &mut slot.ids,
        &mut slot.thickness,
    ] {
        target.transition(device, cmd, fragment_sampled, false);
    }
    slot.depth
        .transition(device, cmd, ImageState::depth_sampled(), false);

    // 2. Lighting (timed by the engine itself with --timing).
    for target in [&mut slot.diffuse, &mut slot.specular] {
        target.transition(device, cmd, ImageState::color_attachment(), true);
    }
    if let Some(pool) = slot.lighting_queries {
        // SAFETY: `cmd` is recording outside rendering; the pool is the slot's, its last use
        // completed (the slot's fence).
        unsafe {
            device.cmd_reset_query_pool(cmd, pool, 0, 2);
            device.cmd_write_timestamp2(cmd, vk::PipelineStageFlags2::ALL_COMMANDS, pool, 0);
        }
    }
    begin_rendering(
        device,
        cmd,
        extent,
        &[slot.diffuse.view, slot.specular.view],
        None,
        false,
    );
    let inverse = (projection * view).inverse();
    if pipelines.lighting_terms.is_empty() {
        bind(pipelines.lighting, Some(slot.lighting_set), inverse);
        // SAFETY: inside the lighting's rendering, its pipeline and set bound.
        unsafe { device.cmd_draw(cmd, 3, 1, 0, 0) };
    } else {
        // --fused: lucent's translucency and transmission only on the tiles their objects
        // touch, the plain lighting elsewhere (as lucent's own lighting pass draws its
        // variants on the tiles of the objects that need them).
        let camera = HostCamera::new(view, projection);
        let whole = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent,
        };
        let or_whole = |rects: Vec<vk::Rect2D>| if rects.is_empty() { vec![whole] } else { rects };
        let leaf = or_whole(leaf_region(&camera, extent, false));
        let transmitting = pipelines
            .lighting_terms
            .iter()
            .any(|(terms, _)| terms.transmission);
        let media = if transmitting {
            or_whole(transmission_regions(&camera, extent, false))
        } else {
            Vec::new()
        };
        let mut bound = None;
        for (terms, rect) in term_tiles(extent, &leaf, &media) {
            if bound != Some(terms) {
                let pipeline = pipelines
                    .lighting_terms
                    .iter()
                    .find(|(t, _)| *t == terms)
                    .map_or(pipelines.lighting, |&(_, pipeline)| pipeline);
                bind(pipeline, Some(slot.lighting_set), inverse);
                bound = Some(terms);
            }
            // SAFETY: inside the lighting's rendering, its pipeline and set bound.
            unsafe {
                device.cmd_set_scissor(cmd, 0, &[rect]);
                device.cmd_draw(cmd, 3, 1, 0, 0);
            }
        }
        // SAFETY: as above: the scissor back to the whole target.
        unsafe { device.cmd_set_scissor(cmd, 0, &[whole]) };
    }
    // SAFETY: inside the lighting's rendering.
    unsafe {
        device.cmd_end_rendering(cmd);
        if let Some(pool) = slot.lighting_queries {
            device.cmd_write_timestamp2(cmd, vk::PipelineStageFlags2::ALL_COMMANDS, pool, 1);
        }
    }
    for target in [&mut slot.diffuse, &mut slot.specular] {
        target.transition(device, cmd, fragment_sampled, false);
    }

    // 3. lucent's translucency added to the lit diffuse, then its SSS into the HDR target;
    // or the engine's own diffuse + specular.
    match effects {
        Some(effects) => {
            let Inserted::Effects {
                environment,
                translucency,
                layered,
                transmission,
                sss,
            } = &mut effects.inserted
            else {
                return Err("record_frame is the engine's own frame, not --scene's".into());
            };
            let camera = HostCamera::new(view, projection);
            let depth = slot.depth.host_image(extent);
            let normals = slot.normal.host_image(extent);
            let albedo = slot.albedo.host_image(extent);
            let ids = slot.ids.host_image(extent);
            let thickness = slot.thickness.host_image(extent);
            let lighting = slot.diffuse.host_image(extent);
            if let Some(environment) = environment {
                let frame = EnvironmentFrame {
                    slot: slot_index,
                    view: 0,
                    camera,
                    environment: &engine_environment(),
                    images: EnvironmentImages {
                        depth: &depth,
                        normals: &normals,
                        albedo: Some(&albedo),
                    },
                    // Every surface has the ambient: the whole screen.
                    regions: &[],
                    lighting: &lighting,
                };
                let timer = effects
                    .timers
                    .get_mut(slot_index)
                    .and_then(|t| t.environment.as_mut());
                match timer {
                    Some(timer) => environment.record_timed(&effects.lucent, cmd, &frame, timer),
                    None => environment.record(&effects.lucent, cmd, &frame),
                }
                .map_err(|e| format!("lucent: {e}"))?;
            }
            if let Some(translucency) = translucency {
                let translucency_frame = TranslucencyFrame {
                    slot: slot_index,
                    view: 0,
                    camera,
                    lights: &engine_lights(sun),
                    images: TranslucencyImages {
                        depth: &depth,
                        normals: &normals,
                        albedo: &albedo,
                        thickness: &thickness,
                        material_ids: &ids,
                    },
                    // The leaf's projected bounds: the pass draws nothing elsewhere.
                    regions: &leaf_region(&camera, extent, effects.whole_screen),
                    lighting: &lighting,
                };
                let timer = effects
                    .timers
                    .get_mut(slot_index)
                    .and_then(|t| t.translucency.as_mut());
                match timer {
                    Some(timer) => {
                        translucency.record_timed(&effects.lucent, cmd, &translucency_frame, timer)
                    }
                    None => translucency.record(&effects.lucent, cmd, &translucency_frame),
                }
                .map_err(|e| format!("lucent: {e}"))?;
            }
            // Li et al.'s terms of the layered ball, its light-space maps drawn from the
            // engine's vertex buffer.
            let lights = engine_lights(sun);
            let layered_frame = LayeredFrame {
                slot: slot_index,
                view: 0,
                camera,
                lights: &lights,
                environment: Some(&engine_environment()),
                light_faces: &faces,
                meshes: &draws,
                images: LayeredImages {
                    depth: &depth,
                    normals: &normals,
                    material_ids: &ids,
                    albedo: None,
                    layer_depths: None,
                },
                regions: &layered_region(&camera, extent, effects.whole_screen),
                lighting: &lighting,
            };
            match effects.timers.get_mut(slot_index) {
                Some(t) => {
                    layered.record_timed(&effects.lucent, cmd, &layered_frame, &mut t.layered)
                }
                None => layered.record(&effects.lucent, cmd, &layered_frame),
            }
            .map_err(|e| format!("lucent: {e}"))?;
            // SSS transmission through the skin and the marble, measured in the engine's own
            // shadow atlas and cube array (rendered above with the same faces).
            if let (Some(transmission), Some(shadow), Some(cube)) =
                (transmission, &slot.shadow, &slot.cube)
            {
                let shadow_map = shadow.host_image(SHADOW_ATLAS);
                let cube_map = cube.host_image(SHADOW_CUBE);
                let transmission_frame = TransmissionFrame {
                    slot: slot_index,
                    view: 0,
                    camera,
                    lights: &lights,
                    shadow_faces: &engine_faces,
                    images: TransmissionImages {
                        depth: &depth,
                        normals: &normals,
                        material_ids: &ids,
                        albedo: Some(&albedo),
                        shadow_map: &shadow_map,
                        second_shadow_map: Some(&cube_map),
                    },
                    // The skin's and the marble's projected bounds.
                    regions: &transmission_regions(&camera, extent, effects.whole_screen),
                    lighting: &lighting,
                };
                let timer = effects
                    .timers
                    .get_mut(slot_index)
                    .and_then(|t| t.transmission.as_mut());
                match timer {
                    Some(timer) => {
                        transmission.record_timed(&effects.lucent, cmd, &transmission_frame, timer)
                    }
                    None => transmission.record(&effects.lucent, cmd, &transmission_frame),
                }
                .map_err(|e| format!("lucent: {e}"))?;
            }
            slot.normal.state = normals.left_in();
            slot.thickness.state = thickness.left_in();
            // (The other images come back as they came: the SSS reads them below.)
            let diffuse = slot.diffuse.host_image(extent);
            let specular = slot.specular.host_image(extent);
            // Every pixel is written: the old contents may be discarded.
            let output = slot
                .hdr
                .host_image(extent)
                .in_state(ImageState {
                    layout: vk::ImageLayout::UNDEFINED,
                    ..slot.hdr.state
                })
                .then(fragment_sampled);
            // The engine's shadow atlas and cube array (when it renders them), as the
            // transmission left them.
            let sss_shadow_map = slot
                .shadow
                .as_ref()
                .filter(|_| effects.sss_lean)
                .map(|shadow| shadow.host_image(SHADOW_ATLAS));
            let sss_cube_map = slot
                .cube
                .as_ref()
                .filter(|_| effects.sss_lean)
                .map(|cube| cube.host_image(SHADOW_CUBE));
            let frame = SssFrame {
                slot: slot_index,
                view: 0,
                camera,
                images: SssImages {
                    depth: &depth,
                    diffuse: &diffuse,
                    specular: Some(&specular),
                    albedo: Some(&albedo),
                    material_ids: &ids,
                },
                // The skin's and the marble's projected bounds, each for its own blur chain:
                // elsewhere a pass-through.
                regions: &sss_regions(&camera, extent, sss, effects.whole_screen),
                output: &output,
                // A LEAN blur's LEAN moments come from the engine's normals, its specular is
                // relit with the engine's lights, shadowed in the engine's shadow maps.
                lean: effects.sss_lean.then(|| LeanLighting {
                    surface: LeanSurface::Normals(&normals),
                    lights: &lights,
                    shadow_map: sss_shadow_map.as_ref(),
                    second_shadow_map: sss_cube_map.as_ref(),
                    shadow_faces: if sss_shadow_map.is_some() {
                        &engine_faces
                    } else {
                        &[]
                    },
                }),
            };
            match effects.timers.get_mut(slot_index) {
                Some(t) => sss.record_timed(&effects.lucent, cmd, &frame, &mut t.sss),
                None => sss.record(&effects.lucent, cmd, &frame),
            }
            .map_err(|e| format!("lucent: {e}"))?;
            // lucent left each image in its final state (here: as each came, the output
            // sampled); the engine tracks what it says.
            slot.depth.state = depth.left_in();
            slot.diffuse.state = diffuse.left_in();
            slot.specular.state = specular.left_in();
            slot.albedo.state = albedo.left_in();
            slot.ids.state = ids.left_in();
            slot.hdr.state = output.left_in();
        }
        None => {
            slot.hdr
                .transition(device, cmd, ImageState::color_attachment(), true);
            begin_rendering(device, cmd, extent, &[slot.hdr.view], None, false);
            bind(pipelines.compose, Some(slot.compose_set), Mat4::IDENTITY);
            // SAFETY: inside the composition's rendering.
            unsafe {
                device.cmd_draw(cmd, 3, 1, 0, 0);
                device.cmd_end_rendering(cmd);
            }
            slot.hdr.transition(device, cmd, fragment_sampled, false);
        }
    }

    // 4. Tonemap (lucent left the pipeline, sets and push constants undefined: bound again).
    slot.ldr
        .transition(device, cmd, ImageState::color_attachment(), true);
    begin_rendering(device, cmd, extent, &[slot.ldr.view], None, false);
    bind(pipelines.tonemap, Some(slot.tonemap_set), Mat4::IDENTITY);
    // SAFETY: inside the tonemap's rendering.
    unsafe {
        device.cmd_draw(cmd, 3, 1, 0, 0);
        device.cmd_end_rendering(cmd);
    }
    slot.ldr
        .transition(device, cmd, ImageState::transfer_src(), false);
    Ok(())
}

/// Submits `cmd` with `fence` (reset first).
fn submit(engine: &Engine, cmd: vk::CommandBuffer, fence: vk::Fence) -> Result<(), String> {
    let infos = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
    let submit = vk::SubmitInfo2::default().command_buffer_infos(&infos);
    // SAFETY: `cmd` is executable; the fence is signalled and unused.
    unsafe {
        check("vkResetFences", engine.device.reset_fences(&[fence]))?;
        check(
            "vkQueueSubmit2",
            engine.device.queue_submit2(engine.queue, &[submit], fence),
        )
    }
}

/// Waits for the slot's last submission and begins its command buffer again.
/// The milliseconds of the engine's lighting pass in the frame `slot` last recorded (its fence
/// has signalled), when it is timed.
fn lighting_ms(engine: &Engine, slot: &FrameSlot) -> Option<f64> {
    let pool = slot.lighting_queries?;
    let mut stamps = [0u64; 2];
    // SAFETY: the pool is live; the frame that wrote it completed (no wait is asked for).
    unsafe {
        engine
            .device
            .get_query_pool_results(pool, 0, &mut stamps, vk::QueryResultFlags::TYPE_64)
            .ok()?;
    }
    // SAFETY: a plain query of the engine's physical device.
    let properties = unsafe {
        engine
            .instance
            .get_physical_device_properties(engine.physical_device)
    };
    let ticks = stamps[1].wrapping_sub(stamps[0]) as f64;
    Some(ticks * f64::from(properties.limits.timestamp_period) / 1e6)
}

fn begin_slot(engine: &Engine, slot: &FrameSlot) -> Result<(), String> {
    let device = &engine.device;
    // SAFETY: the slot's own objects; the fence wait frees its command buffer (and lucent's
    // parameters of this slot) for reuse.
    unsafe {
        check(
            "vkWaitForFences",
            device.wait_for_fences(&[slot.fence], true, u64::MAX),
        )?;
        check(
            "vkResetCommandBuffer",
            device.reset_command_buffer(slot.cmd, vk::CommandBufferResetFlags::empty()),
        )?;
        check(
            "vkBeginCommandBuffer",
            device.begin_command_buffer(
                slot.cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            ),
        )
    }
}

/// lucent on the engine's device, and its SSS effect for the engine's G-buffer, its uploads
/// recorded into `slot`'s command buffer (submitted, and waited for here at start-up: the
/// engine's choice).
fn create_effects(
    args: &Args,
    engine: &Engine,
    allocator: &Arc<Mutex<Allocator>>,
    pipeline_cache: vk::PipelineCache,
    slot: &FrameSlot,
    light_format: vk::Format,
) -> Result<Effects, String> {
    let host = HostDevice {
        entry: engine.entry.clone(),
        instance: engine.instance.clone(),
        physical_device: engine.physical_device,
        device: engine.device.clone(),
        queue: engine.queue,
        queue_family: engine.queue_family,
        enabled: engine.enabled,
    };
    let options = EmbedOptions {
        frames_in_flight: FRAMES_IN_FLIGHT,
        pipeline_cache: Some(pipeline_cache),
        allocator: Some(allocator.clone()),
        ..EmbedOptions::default()
    };
    // SAFETY: the handles are the engine's, created together, and outlive `lucent` (dropped
    // before the engine is destroyed).
    let lucent = unsafe { Lucent::new(host, options) }.map_err(|e| e.to_string())?;
    // Each material with its blur; a LEAN blur (LCB, LBB, bilateral) relights the specular
    // from its blurred LEAN moments, with the surface the engine's own specular has.
    let material = |id: u8, preset: &str, blur: &str, surface: SpecularSurface| {
        let mut profile = SssProfile::preset(preset).map_err(|e| e.to_string())?;
        profile.blur = Some(blur.into());
        // A blur that relights the specular (LCB, LBB, bilateral) takes the engine's gloss.
        SssMaterial::new(id, profile)
            .with_surface_if_relit(surface)
            .map_err(|e| e.to_string())
    };
    let gbuffer = GBufferDesc::new(
        args.width,
        args.height,
        DepthDesc::device(DEPTH_FORMAT),
        DiffuseDesc::with_albedo(light_format),
    )
    .with_specular(light_format)
    .with_albedo(ALBEDO_FORMAT)
    .with_material_ids(IdDesc::value(ID_FORMAT))
    .with_normals(NormalDesc::octahedral(NORMAL_FORMAT, NormalSpace::World))
    .with_thickness(ThicknessDesc::channel(THICKNESS_FORMAT, 0))
    .with_metres_per_unit(1.0);
    for (effect, support) in capabilities(&gbuffer).map_err(|e| e.to_string())? {
        eprintln!("host_engine: lucent effect {}: {support:?}", effect.name());
    }
    // With --fused the engine's lighting adds both terms itself.
    let translucency_desc =
        (!args.fused).then(|| TranslucencyEffectDesc::new(gbuffer.clone(), vec![leaf_material()]));
    let environment_desc =
        (!args.engine_ambient && !args.fused).then(|| EnvironmentEffectDesc::new(gbuffer.clone()));
    let layered_desc = LayeredEffectDesc::new(
        gbuffer.clone(),
        vec![LayeredMaterial::new(LAYERED_ID, layered_medium()?)],
        lucent::embed::VertexLayout::new(
            [MESH_STRIDE, 0],
            lucent::embed::VertexAttribute::new(0, vk::Format::R32G32B32_SFLOAT, 0),
            lucent::embed::VertexAttribute::new(0, vk::Format::R16G16B16A16_SNORM, 12),
        ),
        LIGHT_SPACE,
    );
    let transmission_desc = if transmission_effect_on(args) {
        Some(
            TransmissionEffectDesc::new(gbuffer.clone(), transmission_materials()?, SHADOW_FORMAT)
                .with_second_shadow_map(SHADOW_FORMAT),
        )
    } else {
        None
    };
    let desc = SssEffectDesc::new(
        gbuffer,
        vec![
            material(SKIN_ID, "skin", &args.blur, engine_surface(SKIN_GLOSS))?,
            material(
                MARBLE_ID,
                "marble",
                &args.marble_blur,
                engine_surface(MARBLE_GLOSS),
            )?,
        ],
        HDR_FORMAT,
    );
    // A blur that relights the specular (its material has a surface) reads the normals and
    // the lights; the engine's shadow maps shadow that specular too, when it renders them.
    let sss_lean = desc.materials.iter().any(|m| m.surface.is_some());
    let desc = if sss_lean && transmission_on(args) {
        desc.with_shadow_maps(SHADOW_FORMAT)
            .with_second_shadow_map(SHADOW_FORMAT)
    } else {
        desc
    };
    begin_slot(engine, slot)?;
    // SAFETY: the slot's command buffer is recording, outside rendering, on lucent's queue
    // family; it is submitted below before any frame records the effect.
    let mut uploads = unsafe { lucent.uploads(slot.cmd) };
    let built = match &args.scene {
        None => build_effects(
            &lucent,
            &mut uploads,
            environment_desc,
            translucency_desc,
            layered_desc,
            transmission_desc,
            desc,
        ),
        Some(name) => lucent.load_scene(name).and_then(|scene| {
            let extent = (args.width, args.height);
            SceneRenderer::new(
                &lucent,
                &mut uploads,
                &scene,
                extent.0,
                extent.1,
                LDR_FORMAT,
            )
            .map(|renderer| Inserted::Scene(Box::new((scene, renderer))))
        }),
    };
    let device = &engine.device;
    // SAFETY: the command buffer is recording.
    check("vkEndCommandBuffer", unsafe {
        device.end_command_buffer(slot.cmd)
    })?;
    submit(engine, slot.cmd, slot.fence)?;
    // SAFETY: waiting for the submission that holds the uploads.
    check("vkWaitForFences", unsafe {
        device.wait_for_fences(&[slot.fence], true, u64::MAX)
    })?;
    let staging_bytes = uploads.staging_bytes();
    // SAFETY: that submission has completed.
    unsafe { uploads.release(&lucent) }.map_err(|e| e.to_string())?;
    let inserted = built.map_err(|e| format!("lucent: {e}"))?;
    match &args.scene {
        None => eprintln!(
            "host_engine: lucent effects: {}layered media (apple flesh, ID {LAYERED_ID}; its \
             light-space maps drawn from the engine's vertex buffer), {}sss (skin ID {SKIN_ID} \
             with the {} blur, marble ID {MARBLE_ID} with the {} blur; {staging_bytes} staging \
             bytes uploaded)",
            match (args.fused, args.engine_ambient) {
                (true, _) => format!(
                    "environment, translucency (the leaf){} in the engine's lighting pass \
                     (lucent::embed::glsl::TERMS), ",
                    if transmission_on(args) {
                        " and transmission (skin and marble, lucent's lookup of the engine's \
                         shadow atlas and cube array)"
                    } else {
                        ""
                    }
                ),
                (false, true) => format!("translucency (leaf ID {LEAF_ID}), "),
                (false, false) => format!(
                    "environment (the engine's sky and ground), translucency (leaf ID \
                     {LEAF_ID}), "
                ),
            },
            if transmission_effect_on(args) {
                "transmission (skin and marble, through the engine's shadow maps), "
            } else {
                ""
            },
            args.blur,
            args.marble_blur
        ),
        Some(name) => eprintln!(
            "host_engine: lucent's whole frame of scene '{name}' ({staging_bytes} staging \
             bytes uploaded)"
        ),
    }
    let timers = if args.timing && args.scene.is_none() {
        let made: Result<Vec<Timers>, String> = (0..FRAMES_IN_FLIGHT)
            .map(|_| {
                let timer = || EffectTimer::new(&lucent, 32).map_err(|e| e.to_string());
                Ok(Timers {
                    environment: if args.engine_ambient {
                        None
                    } else {
                        Some(timer()?)
                    },
                    translucency: if args.fused { None } else { Some(timer()?) },
                    layered: timer()?,
                    transmission: if transmission_effect_on(args) {
                        Some(timer()?)
                    } else {
                        None
                    },
                    sss: timer()?,
                })
            })
            .collect();
        made?
    } else {
        Vec::new()
    };
    Ok(Effects {
        lucent,
        inserted,
        whole_screen: args.whole_screen,
        sss_lean,
        timers,
        times: Default::default(),
    })
}

/// The engine's vertex buffer of the leaf's local thickness: one float per vertex the sphere
/// draw emits (6 per quad of the STACKS x SLICES grid), baked by lucent from the leaf's mesh.
struct VertexBuffer {
    buffer: vk::Buffer,
    memory: Allocation,
}

/// The leaf's mesh as the G-buffer's vertex shader makes it (the grid's vertices, two
/// triangles a quad), baked with `lucent::embed::bake_thickness` and laid out per vertex drawn.
fn leaf_thickness_buffer(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
) -> Result<VertexBuffer, String> {
    let (centre, radii) = (Vec3::from(LEAF_CENTRE), Vec3::from(LEAF_RADII));
    let columns = SLICES + 1;
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for i in 0..=STACKS {
        for j in 0..=SLICES {
            let theta = i as f32 / STACKS as f32 * std::f32::consts::PI;
            let phi = j as f32 / SLICES as f32 * std::f32::consts::TAU;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            positions.push(centre + radii * n);
            normals.push((n / radii).normalize());
        }
    }
    const CORNERS: [(u32, u32); 6] = [(0, 0), (1, 0), (1, 1), (0, 0), (1, 1), (0, 1)];
    let drawn: Vec<u32> = (0..STACKS * SLICES)
        .flat_map(|quad| {
            CORNERS.map(|(di, dj)| (quad / SLICES + di) * columns + quad % SLICES + dj)
        })
        .collect();
    // The bake wants counter-clockwise triangles seen from outside: the grid's are the other
    // way round, so each triangle's last two corners swap.
    let indices: Vec<u32> = drawn
        .chunks_exact(3)
        .flat_map(|t| [t[0], t[2], t[1]])
        .collect();
    // Parts thicker than 1.2 cm read as opaque: the leaf's middle is, its rim lets light
    // through.
    let baked = lucent::embed::bake_thickness(&positions, &normals, &indices, Some(0.012))
        .map_err(|e| format!("bake the leaf's thickness: {e}"))?;
    let per_vertex: Vec<f32> = drawn.iter().map(|&v| baked[v as usize]).collect();
    let bytes: Vec<u8> = per_vertex.iter().flat_map(|v| v.to_le_bytes()).collect();
    let (low, high) = baked
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    eprintln!(
        "host_engine: the leaf's thickness baked by lucent at {} vertices ({low:.2} to \
         {high:.2})",
        baked.len()
    );
    host_buffer(engine, allocator, &bytes, "leaf thickness")
}

/// A host-visible vertex buffer of the engine's holding `bytes`.
fn host_buffer(
    engine: &Engine,
    allocator: &Mutex<Allocator>,
    bytes: &[u8],
    name: &str,
) -> Result<VertexBuffer, String> {
    let device = &engine.device;
    // SAFETY: plain object creation on the engine's device; destroyed at the end of `run`.
    unsafe {
        let buffer = device
            .create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(bytes.len() as u64)
                    .usage(vk::BufferUsageFlags::VERTEX_BUFFER),
                None,
            )
            .map_err(|e| format!("vkCreateBuffer: {e}"))?;
        let allocated = allocator
            .lock()
            .map_err(|_| "allocator lock poisoned".to_string())
            .and_then(|mut allocator| {
                allocator
                    .allocate(&AllocationCreateDesc {
                        name,
                        requirements: device.get_buffer_memory_requirements(buffer),
                        location: MemoryLocation::CpuToGpu,
                        linear: true,
                        allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                    })
                    .map_err(|e| format!("allocate {name}: {e}"))
            });
        let mut memory = match allocated {
            Ok(memory) => memory,
            Err(e) => {
                device.destroy_buffer(buffer, None);
                return Err(e);
            }
        };
        let filled = check(
            "vkBindBufferMemory",
            device.bind_buffer_memory(buffer, memory.memory(), memory.offset()),
        )
        .and_then(|()| {
            memory
                .mapped_slice_mut()
                .ok_or(format!("{name}: the buffer is not mapped"))
                .map(|mapped| mapped[..bytes.len()].copy_from_slice(bytes))
        });
        if let Err(e) = filled {
            device.destroy_buffer(buffer, None);
            if let Ok(mut allocator) = allocator.lock() {
                allocator.free(memory).ok();
            }
            return Err(e);
        }
        Ok(VertexBuffer { buffer, memory })
    }
}

fn run(args: &Args, engine: &Engine) -> Result<(), String> {
    let device = &engine.device;
    let allocator = Arc::new(Mutex::new(
        Allocator::new(&AllocatorCreateDesc {
            instance: engine.instance.clone(),
            device: device.clone(),
            physical_device: engine.physical_device,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| format!("gpu-allocator: {e}"))?,
    ));
    // SAFETY: plain object creation.
    let pipeline_cache =
        unsafe { device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }
            .map_err(|e| format!("vkCreatePipelineCache: {e}"))?;
    let light_format = light_format(engine);
    let extent = vk::Extent2D {
        width: args.width,
        height: args.height,
    };
    let leaf_thickness = leaf_thickness_buffer(engine, &allocator)?;
    let meshes = match host_buffer(engine, &allocator, &mesh_vertices(), "meshes") {
        Ok(buffer) => buffer,
        Err(e) => {
            // SAFETY: nothing used the buffer yet.
            unsafe { device.destroy_buffer(leaf_thickness.buffer, None) };
            if let Ok(mut allocator) = allocator.lock() {
                allocator.free(leaf_thickness.memory).ok();
            }
            return Err(e);
        }
    };
    let mut result = Ok(());
    let mut slots = Vec::with_capacity(FRAMES_IN_FLIGHT);
    let mut pipelines = None;
    let mut effects = None;
    let setup = (|| {
        let fused = match (args.fused && args.with_lucent, transmission_on(args)) {
            (false, _) => None,
            (true, transmits) => Some(shaders::Fused {
                sh: engine_environment().coefficients(),
                leaf_row: leaf_material().row(),
                scales: engine_lights(Vec3::Y).map(|l| l.translucency_scale),
                transmission: if transmits {
                    Some(fused_transmission()?)
                } else {
                    None
                },
            }),
        };
        let made = create_pipelines(engine, pipeline_cache, light_format, fused.as_ref())?;
        let made = pipelines.insert(made);
        for k in 0..FRAMES_IN_FLIGHT {
            slots.push(create_slot(
                engine,
                &allocator,
                made,
                extent,
                light_format,
                k,
                (
                    args.timing && args.with_lucent && args.scene.is_none(),
                    transmission_on(args),
                ),
            )?);
        }
        if args.with_lucent {
            effects = Some(create_effects(
                args,
                engine,
                &allocator,
                pipeline_cache,
                &slots[0],
                light_format,
            )?);
        }
        Ok::<(), String>(())
    })();
    if let Err(e) = setup {
        result = Err(e);
    }
    if let (Ok(()), Some(pipelines)) = (&result, &pipelines) {
        for frame in 0..args.frames {
            let k = frame % FRAMES_IN_FLIGHT;
            let slot = &mut slots[k];
            let recorded = begin_slot(engine, slot)
                .and_then(|()| match effects.as_mut() {
                    // The slot's previous frame has completed: its times are there.
                    Some(effects) if frame >= FRAMES_IN_FLIGHT => {
                        effects.collect_times(k, lighting_ms(engine, slot))
                    }
                    _ => Ok(()),
                })
                .and_then(|()| match effects.as_mut() {
                    Some(Effects {
                        lucent,
                        inserted: Inserted::Scene(scene),
                        ..
                    }) => {
                        let (scene, renderer) = &mut **scene;
                        record_scene_frame(lucent, renderer, scene, slot, k, extent)
                    }
                    other => record_frame(
                        engine,
                        pipelines,
                        other,
                        slot,
                        frame,
                        extent,
                        (leaf_thickness.buffer, meshes.buffer),
                    ),
                })
                // SAFETY: the command buffer is recording.
                .and_then(|()| {
                    check("vkEndCommandBuffer", unsafe {
                        device.end_command_buffer(slot.cmd)
                    })
                })
                .and_then(|()| submit(engine, slot.cmd, slot.fence));
            if let Err(e) = recorded {
                result = Err(format!("frame {frame}: {e}"));
                break;
            }
        }
    }
    // SAFETY: waits for every frame the engine submitted.
    let idle = unsafe { device.device_wait_idle() };
    if result.is_ok() {
        result = check("vkDeviceWaitIdle", idle).and_then(|()| {
            let last = &slots[(args.frames - 1) % FRAMES_IN_FLIGHT];
            let pixels = read_back(engine, &allocator, last, args.width, args.height)?;
            lucent::images::output::write_png_rgba8(&args.out, args.width, args.height, &pixels)
                .map_err(|e| e.to_string())
        });
    }
    if let (Ok(()), Some(effects)) = (&result, effects.as_mut()) {
        // The last frame of each slot (the device is idle).
        let first = args.frames.saturating_sub(FRAMES_IN_FLIGHT);
        result = (first..args.frames).try_for_each(|frame| {
            let k = frame % FRAMES_IN_FLIGHT;
            effects.collect_times(k, lighting_ms(engine, &slots[k]))
        });
        if !effects.timers.is_empty() && result.is_ok() {
            eprintln!(
                "host_engine: lucent's passes (GPU timestamps, medians of {} frames): {}",
                args.frames,
                effects.timing_report()
            );
        }
    }
    if let Some(effects) = effects {
        for timers in effects.timers {
            for timer in timers.environment.into_iter() {
                timer.destroy(&effects.lucent);
            }
            for timer in timers.translucency.into_iter() {
                timer.destroy(&effects.lucent);
            }
            timers.layered.destroy(&effects.lucent);
            for timer in timers.transmission.into_iter() {
                timer.destroy(&effects.lucent);
            }
            timers.sss.destroy(&effects.lucent);
        }
        match effects.inserted {
            Inserted::Effects {
                environment,
                translucency,
                layered,
                transmission,
                sss,
            } => {
                if let Some(environment) = environment {
                    (*environment).destroy(&effects.lucent);
                }
                if let Some(translucency) = translucency {
                    (*translucency).destroy(&effects.lucent);
                }
                (*layered).destroy(&effects.lucent);
                if let Some(transmission) = transmission {
                    (*transmission).destroy(&effects.lucent);
                }
                (*sss).destroy(&effects.lucent);
            }
            Inserted::Scene(scene) => (*scene).1.destroy(&effects.lucent),
        }
        drop(effects.lucent);
    }
    for slot in slots {
        destroy_slot(engine, &allocator, slot);
    }
    if let Some(pipelines) = &pipelines {
        destroy_pipelines(device, pipelines);
    }
    // SAFETY: lucent is gone and the device idle: nothing uses the cache or the buffer.
    unsafe {
        device.destroy_pipeline_cache(pipeline_cache, None);
        device.destroy_buffer(leaf_thickness.buffer, None);
        device.destroy_buffer(meshes.buffer, None);
    }
    if let Ok(mut allocator) = allocator.lock() {
        allocator.free(leaf_thickness.memory).ok();
        allocator.free(meshes.memory).ok();
    }
    drop(allocator);
    result
}

fn main() {
    let args = match parse_args() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("host_engine: {e}");
            std::process::exit(2);
        }
    };
    let engine = match create_engine() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("host_engine: {e}");
            std::process::exit(1);
        }
    };
    // SAFETY: plain query of the physical device.
    let name = unsafe {
        engine
            .instance
            .get_physical_device_properties(engine.physical_device)
    }
    .device_name_as_c_str()
    .map(CStr::to_string_lossy)
    .map(|n| n.into_owned())
    .unwrap_or_default();
    eprintln!(
        "host_engine: {name}, {}x{}, {} frames, {FRAMES_IN_FLIGHT} in flight, lucent {}, \
         validation {}",
        args.width,
        args.height,
        args.frames,
        if args.with_lucent { "on" } else { "left out" },
        if engine.validation {
            "on (synchronization validation included)"
        } else {
            "off (VK_LAYER_KHRONOS_validation is not installed)"
        }
    );
    let outcome = run(&args, &engine);
    // SAFETY: everything created from the device is gone (run destroyed it); the device is
    // idle.
    unsafe {
        let _ = engine.device.device_wait_idle();
        engine.device.destroy_device(None);
        if let Some((loader, messenger)) = &engine.debug {
            loader.destroy_debug_utils_messenger(*messenger, None);
        }
        engine.instance.destroy_instance(None);
    }
    let errors = VALIDATION_ERRORS.load(Ordering::Relaxed);
    match outcome {
        Ok(()) if errors == 0 => {
            eprintln!(
                "host_engine: wrote {} (0 validation errors)",
                args.out.display()
            );
        }
        Ok(()) => {
            eprintln!("host_engine: {errors} validation error(s)");
            std::process::exit(1);
        }
        Err(e) => {
            eprintln!("host_engine: {e} ({errors} validation error(s))");
            std::process::exit(1);
        }
    }
}
