// Screen-space SSS: the profile table (src/features/sss.rs `ProfileTableGpu`, std140) and the
// per-pixel profile ID the G-buffer pass writes (R8: ID / 255, 0 = does not scatter).
// Every SSS pass binds it after the frame uniforms; a region of the per-frame buffer, so a
// frame in flight reads its own copy.
#ifndef LUCENT_SSS_GLSL
#define LUCENT_SSS_GLSL

#include "host_ids.glsl"

#define MAX_SSS_PROFILES 32
#define MAX_SSS_STEPS 8

struct SssStep {
    vec4 blur;    // x: sigma this step adds, world units; y: depth term (control: depth
                  // correction; bilateral: sensitivity per world unit of depth difference)
    vec4 weight;  // rgb: the completed Gaussian's weight in the sum; a: their mean
};

layout(std140, set = 0) uniform SssProfiles {
    vec4 info[MAX_SSS_PROFILES];  // x: chain index; y: step count; z: Gaussian count;
                                  // w: texturing (sss_albedo_before)
    SssStep steps[MAX_SSS_PROFILES * MAX_SSS_STEPS];
    // The whole profile's 1-D form in world units: rgb = weight / sqrt(2 pi v), a = 1 / (2 v).
    vec4 gaussians[MAX_SSS_PROFILES * MAX_SSS_STEPS];
    // The material's medium (src/features/sss/transmission.rs), 6 rows per ID. Its diffuse
    // transmission through thickness (`SssTransmission::rows`): the medium's dipole in mm,
    // sigma_tr (a: mm per scene unit, 0 = no transmission), z_r, z_v, and (alpha' / 2) / A
    // (A: the medium's albedo); the alphas of rows 1-3 the largest transmittance per
    // channel, min(1 / A, 1000). Its reflectance (`reflectance_rows`): gamma = sqrt(1 -
    // omega) (a: 1 = the profile has a medium), omega / (4 A_1). Read by the lighting pass
    // (sss_medium.glsl, sss_transmission.glsl).
    vec4 medium[MAX_SSS_PROFILES * 6];
    // The ID image's decode (src/features/sss/mod.rs `IdMap`; a host's: src/embed/gbuffer.rs
    // `IdEncoding`), for the passes that read it without constants: x the
    // channel that holds them, y the bit field's shift, z its mask, w the largest value of a
    // UNORM channel (its integer is value * w). The field is the host's ID; id_profiles maps
    // it to a profile number, one byte per ID (ID i: byte i % 4 of id_profiles[i / 16][i / 4 % 4]).
    uvec4 id_decode;
    uvec4 id_profiles[16];
} sss_profiles;

// The profile ID stored at a texel (exact for UNORM8: rounding recovers the integer).
int sss_profile_id(float stored) {
    return clamp(int(stored * 255.0 + 0.5), 0, MAX_SSS_PROFILES - 1);
}

// The profile IDs' sampler: lucent's own G-buffer stores R8_UNORM (ID / 255); a host's IDs
// may be unsigned integers (LUCENT_SSS_IDS_UINT: an R8_UINT target, a stencil aspect, a
// channel of a UINT target).
#ifdef LUCENT_SSS_IDS_UINT
#define SSS_ID_SAMPLER usampler2D
#else
#define SSS_ID_SAMPLER sampler2D
#endif

// How a pixel's profile is read from the ID image (src/features/sss/mod.rs `IdMap`): the decode
// and the ID-to-profile map as specialization constants (`IdMap::specialization`), fixed when
// the pass is made: the driver folds them into the pass's code. lucent's own G-buffer and a
// host's are read by the same code; only the constants differ.
// - The decode: the channel, the bit field's shift and mask, a UNORM channel's largest value
//   (lucent's own G-buffer: R8_UNORM, the profile number k stored as k / 255).
// - IDs that are the profile numbers (SSS_IDS_PROFILES_UP_TO = n > 0: IDs 1 to n are profiles 1
//   to n, every other ID none): lucent's own G-buffer, and a host whose SSS materials have
//   IDs 1 to n in the description's order.
// - Otherwise up to eight materials: SSS_IDS_LISTED of them, material k's ID in SSS_ID_k and
//   its profile number in SSS_PROFILE_k. A pixel's profile is then found by comparisons with
//   constants, where the ID-to-profile table (id_profiles) costs a load from a per-pixel
//   address: with the table the control's combine was 1.10-1.16x lucent's own pass, with the
//   comparisons 0.87-0.91x (lucent bench --embed, skin, 1024x768). More materials
//   (SSS_IDS_LISTED = 0) read the table.
layout(constant_id = 0) const uint SSS_ID_CHANNEL = 0u;
layout(constant_id = 1) const uint SSS_ID_SHIFT = 0u;
layout(constant_id = 2) const uint SSS_ID_MASK = 255u;
layout(constant_id = 3) const uint SSS_ID_UNORM_MAX = 255u;
#define SSS_ID_DECODE uvec4(SSS_ID_CHANNEL, SSS_ID_SHIFT, SSS_ID_MASK, SSS_ID_UNORM_MAX)
layout(constant_id = 4) const uint SSS_IDS_LISTED = 0u;
// (256: no ID; a decoded ID is at most 255.)
layout(constant_id = 5) const uint SSS_ID_1 = 256u;
layout(constant_id = 6) const uint SSS_ID_2 = 256u;
layout(constant_id = 7) const uint SSS_ID_3 = 256u;
layout(constant_id = 8) const uint SSS_ID_4 = 256u;
layout(constant_id = 9) const uint SSS_ID_5 = 256u;
layout(constant_id = 10) const uint SSS_ID_6 = 256u;
layout(constant_id = 11) const uint SSS_ID_7 = 256u;
layout(constant_id = 12) const uint SSS_ID_8 = 256u;
layout(constant_id = 13) const int SSS_PROFILE_1 = 0;
layout(constant_id = 14) const int SSS_PROFILE_2 = 0;
layout(constant_id = 15) const int SSS_PROFILE_3 = 0;
layout(constant_id = 16) const int SSS_PROFILE_4 = 0;
layout(constant_id = 17) const int SSS_PROFILE_5 = 0;
layout(constant_id = 18) const int SSS_PROFILE_6 = 0;
layout(constant_id = 19) const int SSS_PROFILE_7 = 0;
layout(constant_id = 20) const int SSS_PROFILE_8 = 0;
// (constant_id 21 is host_depth.glsl's HOST_DEPTH_LINEAR.)
layout(constant_id = 22) const uint SSS_IDS_PROFILES_UP_TO = 0u;

// The profile number of a host's material ID (0: does not scatter); IDs past 255 have none.
int sss_host_profile(uint host_id) {
    if (SSS_IDS_PROFILES_UP_TO > 0u) {
        return host_id <= min(SSS_IDS_PROFILES_UP_TO, uint(MAX_SSS_PROFILES - 1)) ? int(host_id)
                                                                                    : 0;
    }
    if (SSS_IDS_LISTED > 0u) {
        // Unlisted slots hold ID 256, which no decoded ID equals.
        int p = 0;
        p = host_id == SSS_ID_1 ? SSS_PROFILE_1 : p;
        p = host_id == SSS_ID_2 ? SSS_PROFILE_2 : p;
        p = host_id == SSS_ID_3 ? SSS_PROFILE_3 : p;
        p = host_id == SSS_ID_4 ? SSS_PROFILE_4 : p;
        p = host_id == SSS_ID_5 ? SSS_PROFILE_5 : p;
        p = host_id == SSS_ID_6 ? SSS_PROFILE_6 : p;
        p = host_id == SSS_ID_7 ? SSS_PROFILE_7 : p;
        p = host_id == SSS_ID_8 ? SSS_PROFILE_8 : p;
        return p;
    }
    if (host_id > 255u) {
        return 0;
    }
    uint word = sss_profiles.id_profiles[host_id / 16u][(host_id / 4u) % 4u];
    return int((word >> (8u * (host_id % 4u))) & 255u) % MAX_SSS_PROFILES;
}

// A key of the profile ID image's texel `t` (texelFetch's result) that equals a scattering
// pixel's key exactly when `t` has the same profile, for the taps of a pixel that scatters:
// lucent's profile number, or a host's material ID itself (each of the host's SSS materials has
// a profile of its own, and an ID without one differs from every ID with one). A tap then
// skips the ID-to-profile table (Burley's gather: 1.08x lucent's own pass with the table per
// tap, 1.05x without).
int sss_id_key(vec4 t) {
    return int(host_material_id(t, SSS_ID_DECODE));
}

int sss_id_key(uvec4 t) {
    return int(host_material_id(t, SSS_ID_DECODE));
}

// The profile number of the texel `t` of the profile ID image.
int sss_decode_id(vec4 t) {
    if (SSS_IDS_PROFILES_UP_TO > 0u && SSS_ID_UNORM_MAX == 255u && SSS_ID_SHIFT == 0u &&
        SSS_ID_MASK == 255u) {
        // A whole 8-bit UNORM channel of profile numbers (lucent's own G-buffer): its value is
        // in [0, 1], so the general decode's clamp and mask are left out (they made the blurs'
        // taps 2% dearer). Negative values (a float channel) read 0, as NaN's do.
        int k = int(t[min(SSS_ID_CHANNEL, 3u)] * 255.0 + 0.5);
        return k >= 0 && k <= int(min(SSS_IDS_PROFILES_UP_TO, uint(MAX_SSS_PROFILES - 1))) ? k : 0;
    }
    return sss_host_profile(uint(sss_id_key(t)));
}

int sss_decode_id(uvec4 t) {
    return sss_host_profile(uint(sss_id_key(t)));
}

// Whether profile `id` is blurred by chain `chain` (0 never is).
bool sss_in_chain(int id, int chain) {
    return id > 0 && int(sss_profiles.info[id].x + 0.5) == chain;
}

// Where profile `id`'s albedo meets the blur (src/scene/material.rs `Texturing`, info.w):
// 0 pre (in the blurred light), 1 post (after the blur), 2 pre-post (its square root before
// and after). ID 0's row is zero: a pixel that does not scatter keeps its albedo in its light.
int sss_texturing(int id) {
    return int(sss_profiles.info[id].w + 0.5);
}

// The albedo's factor in the light the lighting pass writes for the blur to diffuse.
vec3 sss_albedo_before(int id, vec3 albedo) {
    int mode = sss_texturing(id);
    return mode == 1 ? vec3(1.0) : (mode == 2 ? sqrt(max(albedo, vec3(0.0))) : albedo);
}

// The albedo's factor that multiplies the diffused light when the chain composes it.
vec3 sss_albedo_after(int id, vec3 albedo) {
    int mode = sss_texturing(id);
    return mode == 1 ? albedo : (mode == 2 ? sqrt(max(albedo, vec3(0.0))) : vec3(1.0));
}

// A host's albedo texel (lucent::embed), sanitized where it is read: a NaN or out-of-range
// albedo must not reach the blur.
vec3 sss_host_albedo(vec3 texel) {
    return clamp(mix(texel, vec3(0.0), isnan(texel)), vec3(0.0), vec3(1.0));
}

// The smallest albedo divided by: a host's black albedo has no light left to recover, and
// dividing by it would turn rounding into Inf.
const float SSS_MIN_HOST_ALBEDO = 1.0 / 255.0;

// What a host's light is multiplied by to hold the albedo as profile `id` wants it before the
// blur (sss_albedo_before), from a light that holds all of the albedo (`included`: what belongs
// after the blur is divided out) or none of it (glsl/sss/host_albedo.frag, host_lean.frag).
vec3 sss_host_albedo_factor(int id, vec3 albedo, bool included) {
    vec3 before = sss_albedo_before(id, albedo);
    if (!included) {
        return before;
    }
    return sss_texturing(id) == 0 ? vec3(1.0) : before / max(albedo, vec3(SSS_MIN_HOST_ALBEDO));
}

SssStep sss_step(int id, int step) {
    return sss_profiles.steps[id * MAX_SSS_STEPS + clamp(step, 0, MAX_SSS_STEPS - 1)];
}

// The profile of `id` in its 1-D form (the sum of its Gaussians' marginals) per channel at
// squared world distance `d2`: the two-pass bilateral blur's tap weight.
vec3 sss_profile_at(int id, float d2) {
    vec3 r = vec3(0.0);
    int count = clamp(int(sss_profiles.info[id].z + 0.5), 0, MAX_SSS_STEPS);
    for (int i = 0; i < count; ++i) {
        vec4 g = sss_profiles.gaussians[id * MAX_SSS_STEPS + i];
        r += g.rgb * exp(-d2 * g.a);
    }
    return r;
}

#ifdef LUCENT_SSS_KERNELS
#define MAX_KERNEL_SAMPLES 25
#define FALLOFF_ENTRIES 25
// The two-pass blurs' kernels (src/features/sss/kernel.rs `KernelTableGpu`), bound after the
// profile table: per profile x the sample count, y one over the kernel's reach (world units),
// z that reach, w one over the falloff table's reach.
layout(std140, set = 0) uniform SssKernels {
    vec4 info[MAX_SSS_PROFILES];
    vec4 taps[MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES];  // rgb weight, a offset (world units)
    vec4 falloff[MAX_SSS_PROFILES * FALLOFF_ENTRIES];  // rgb 1-D profile, a its distance
    vec4 inverse_falloff[MAX_SSS_PROFILES * MAX_KERNEL_SAMPLES];  // rgb 1 / falloff at offset
} sss_kernels;

// A bilateral profile's 1-D form per channel at world distance `d`: its falloff table
// (entries at reach * u^2), interpolated; 0 past the table.
vec3 sss_falloff(int id, vec4 info, float d) {
    float x = d * info.w;
    float u = sqrt(clamp(x, 0.0, 1.0)) * float(FALLOFF_ENTRIES - 1);
    int i = min(int(u), FALLOFF_ENTRIES - 2);
    vec3 a = sss_kernels.falloff[id * FALLOFF_ENTRIES + i].rgb;
    vec3 b = sss_kernels.falloff[id * FALLOFF_ENTRIES + i + 1].rgb;
    return x >= 1.0 ? vec3(0.0) : mix(a, b, u - float(i));
}
#endif

#endif
