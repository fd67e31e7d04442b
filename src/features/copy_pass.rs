//! The benchmark's shaders: the speed-of-light floors, of two kinds,
//! - the copy (`glsl/bench/copy.frag`): a fullscreen pass that fetches one texel from each
//!   image it reads and writes every colour image (and depth) it has, nothing else: the
//!   cheapest pass that moves a given fullscreen pass's bytes;
//! - the mesh floor (`glsl/bench/floor.vert`, `floor.frag`): the objects a mesh pass draws,
//!   with its views, transformed by one matrix and writing a constant to each target: the
//!   cheapest pass that draws a given mesh pass's geometry;
//!
//! and a host engine's own lighting pass (`glsl/bench/host_lighting.frag`), which adds one of
//! lucent's terms through `lucent::embed::glsl::TERMS` as a host does.
//!
//! The speed of light (`crate::measure::speed_of_light`, feature `measure`) puts the floors in
//! place of each pass of a plan; `lucent bench --embed` (`crate::measure::host_lighting`)
//! times the host's lighting with and without a term. Their defines and every permutation of
//! them are here, so the shipped SPIR-V ([`crate::shipped`]) holds them whatever features the
//! library is built with.

use crate::backend::shader::PipelineShaders;

/// Images one copy pass can read or write (`glsl/bench/copy.frag` declares eight of each, the
/// colour-attachment count every Vulkan device supports).
pub const MAX_COPY_IMAGES: usize = 8;
/// Most images the copy reads (LEAN's final pass reads nine with the light-space maps).
pub const MAX_COPY_INPUTS: usize = 10;

/// The copy's fragment shader.
pub const COPY_FRAGMENT: &str = "bench/copy.frag";

/// The copy shader's names for its inputs, in binding order (`in0` ... `in9`).
pub const COPY_INPUT_NAMES: [&str; MAX_COPY_INPUTS] = [
    "in0", "in1", "in2", "in3", "in4", "in5", "in6", "in7", "in8", "in9",
];
/// The mesh floor's vertex shader.
pub const FLOOR_VERTEX: &str = "bench/floor.vert";
/// The mesh floor's fragment shader.
pub const FLOOR_FRAGMENT: &str = "bench/floor.frag";

/// The host lighting pass's fragment shader.
pub const HOST_LIGHTING_FRAGMENT: &str = "bench/host_lighting.frag";

/// Which of lucent's terms a host's lighting pass adds (`glsl/bench/host_lighting.frag`'s
/// `LUCENT_BENCH_TERM`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostTerm {
    /// None: the host's own lighting with its constant ambient.
    None,
    /// GDC 2011 translucency, compiled with the lobe's forms its materials use
    /// (`LUCENT_POW_MODES`: 1 the exact `pow`, 2 `exp2`, 3 both).
    Translucency {
        /// 1, 2 or 3.
        pow_modes: u8,
    },
    /// The SH environment in place of the constant ambient.
    Environment,
    /// SSS transmission through the host's shadow atlas.
    Transmission,
}

impl HostTerm {
    /// Every term the shader compiles, `None` first.
    pub const ALL: [HostTerm; 6] = [
        HostTerm::None,
        HostTerm::Translucency { pow_modes: 1 },
        HostTerm::Translucency { pow_modes: 2 },
        HostTerm::Translucency { pow_modes: 3 },
        HostTerm::Environment,
        HostTerm::Transmission,
    ];

    /// The host lighting shader's defines for this term.
    pub fn defines(self) -> &'static [(&'static str, &'static str)] {
        match self {
            HostTerm::None => &[("LUCENT_BENCH_TERM", "0")],
            HostTerm::Translucency { pow_modes: 1 } => {
                &[("LUCENT_BENCH_TERM", "1"), ("LUCENT_POW_MODES", "1")]
            }
            HostTerm::Translucency { pow_modes: 2 } => {
                &[("LUCENT_BENCH_TERM", "1"), ("LUCENT_POW_MODES", "2")]
            }
            HostTerm::Translucency { .. } => {
                &[("LUCENT_BENCH_TERM", "1"), ("LUCENT_POW_MODES", "3")]
            }
            HostTerm::Environment => &[("LUCENT_BENCH_TERM", "2")],
            HostTerm::Transmission => &[("LUCENT_BENCH_TERM", "3")],
        }
    }
}

/// Image counts as define strings (at most [`MAX_COPY_INPUTS`]).
const COUNTS: [&str; MAX_COPY_INPUTS + 1] =
    ["0", "1", "2", "3", "4", "5", "6", "7", "8", "9", "10"];

/// The copy's defines: images read, colour images written, and whether it writes depth.
pub fn copy_defines(
    inputs: usize,
    outputs: usize,
    depth: bool,
) -> Vec<(&'static str, &'static str)> {
    let count = |n: usize| COUNTS[n.min(MAX_COPY_INPUTS)];
    let mut defines = vec![
        ("LUCENT_COPY_INPUTS", count(inputs)),
        ("LUCENT_COPY_OUTPUTS", count(outputs)),
    ];
    if depth {
        defines.push(("LUCENT_COPY_DEPTH", "1"));
    }
    defines
}

/// The mesh floor's defines: colour targets written (at most [`MAX_COPY_IMAGES`]) and whether
/// its views are light-space faces (else the camera).
pub fn floor_defines(outputs: usize, shadow_faces: bool) -> Vec<(&'static str, &'static str)> {
    let mut defines = vec![("LUCENT_FLOOR_OUTPUTS", COUNTS[outputs.min(MAX_COPY_IMAGES)])];
    if shadow_faces {
        defines.push(("LUCENT_FLOOR_SHADOW_FACES", "1"));
    }
    defines
}

/// The pipelines the floors of any plan's passes build (the speed of light leaves out passes
/// with more images than the copy has).
pub(crate) fn shader_permutations(out: &mut Vec<PipelineShaders>) {
    for inputs in 0..=MAX_COPY_INPUTS {
        for outputs in 0..=MAX_COPY_IMAGES {
            for depth in [false, true] {
                out.push(PipelineShaders::fullscreen(
                    COPY_FRAGMENT,
                    &copy_defines(inputs, outputs, depth),
                ));
            }
        }
    }
    for term in HostTerm::ALL {
        out.push(PipelineShaders::fullscreen(
            HOST_LIGHTING_FRAGMENT,
            term.defines(),
        ));
    }
    for outputs in 0..=MAX_COPY_IMAGES {
        for shadow_faces in [false, true] {
            out.push(PipelineShaders::new(
                FLOOR_VERTEX,
                FLOOR_FRAGMENT,
                &floor_defines(outputs, shadow_faces),
            ));
        }
    }
}
