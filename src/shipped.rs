//! The closed set of shader permutations lucent's frames and embedded effects compile, which
//! `build.rs` ships as SPIR-V ([`crate::backend::shader::ShaderCompiler::shipped`]). It sits
//! above both the features and `embed` (it lists what each builds), so neither imports it.
//!
//! A build script cannot call the library, so the set is written down: [`permutations`]
//! enumerates every (shader, defines) pair any pass of any frame may ask for, and
//! `glsl/permutations.txt` holds its [`manifest`] text, which `build.rs` compiles. The test
//! `tests/cpu/shipped_shaders.rs` fails when the committed file differs from [`manifest`] and prints
//! the command that regenerates it:
//!
//! ```text
//! LUCENT_WRITE_MANIFEST=1 cargo test --test cpu shipped_shaders::
//! ```
//!
//! Each pass builds its defines with a function of its shape (the G-buffer layout, which inputs
//! it reads, its knobs), and that same function is what its module's `shader_permutations`
//! calls over every shape the pass can have, so the two cannot drift apart. Binding numbers in
//! defines are derived from the shape too, and a pass declared with
//! [`crate::features::pass::FullscreenPass`] numbers them from the bindings it has declared. The
//! shapes enumerated are the whole input space of each function (every G-buffer layout flag,
//! every knob value the defines distinguish), not only the scenes in the tests. Combinations
//! one frame can never hold (LEAN without SSS, say) are included when the shader compiles them:
//! a few extra permutations are cheaper than a proof that no frame reaches them.
//!
//! To add a permutation: change the pass's define function (and, for a new knob value or flag,
//! the domain its `shader_permutations` walks), then regenerate the manifest with the command
//! above. A new pass or shader: give its module a `shader_permutations` that calls the pass's
//! define function over every shape it can have, add it to [`pipelines`], regenerate. A permutation the bundle lacks fails at pipeline creation with
//! [`crate::LucentError::ShaderNotShipped`], which the test suite (shipped SPIR-V only) catches.

use std::collections::{BTreeMap, BTreeSet};

use crate::backend::shader::{sorted_defines, PipelineShaders};
use crate::{LucentError, Result};

/// Every pipeline any frame (and the speed-of-light copies of its passes) may build, in the
/// features' order, repeats included.
pub fn pipelines() -> Vec<PipelineShaders> {
    use crate::features::{
        antialias, copy_pass, debug_view, gbuffer, lighting, registry, shadows, sss, tonemap,
    };
    let mut out = Vec::new();
    shadows::shader_permutations(&mut out);
    gbuffer::shader_permutations(&mut out);
    lighting::shader_permutations(&mut out);
    for technique in registry::TECHNIQUES {
        technique.shader_permutations(&mut out);
    }
    // The SSS passes over a host's material IDs (lucent::embed).
    sss::host_id_permutations(&mut out);
    // GDC 2011 translucency on a host's G-buffer (lucent::embed::TranslucencyEffect).
    crate::embed::translucency_permutations(&mut out);
    // The SH environment on a host's G-buffer (lucent::embed::EnvironmentEffect).
    crate::embed::environment_permutations(&mut out);
    // SSS transmission through a host's shadow maps (lucent::embed::TransmissionEffect).
    crate::embed::transmission_permutations(&mut out);
    debug_view::shader_permutations(&mut out);
    tonemap::shader_permutations(&mut out);
    antialias::shader_permutations(&mut out);
    copy_pass::shader_permutations(&mut out);
    out
}

/// Every (shader path, defines) permutation of [`pipelines`], as permutation lines
/// (`path NAME=VALUE ...`, defines sorted by name, a repeated name's last value kept: what
/// [`crate::backend::shader::ShaderCompiler::compile`] looks up), sorted, each once.
pub fn permutations() -> Result<Vec<String>> {
    let mut lines = BTreeSet::new();
    for pipeline in pipelines() {
        let defines: Vec<(&str, &str)> = pipeline
            .defines
            .iter()
            .map(|(n, v)| (n.as_str(), v.as_str()))
            .collect();
        for path in [&pipeline.vertex, &pipeline.fragment] {
            let sorted: BTreeMap<&str, &str> = sorted_defines(path, &defines, true)?;
            let name = crate::backend::shader::shader_name(path).ok_or_else(|| {
                LucentError::InvalidInput(format!("shader {path}: not a relative path"))
            })?;
            lines.insert(crate::backend::shader::permutation_line(&name, sorted));
        }
    }
    Ok(lines.into_iter().collect())
}

/// The text of `glsl/permutations.txt`: a header, then [`permutations`], one per line.
pub fn manifest() -> Result<String> {
    let mut text = format!(
        "# Generated: every shader permutation lucent's frames compile \
         (lucent::shipped).\n\
         # build.rs compiles each line into the shipped SPIR-V bundle. Do not edit: \
         regenerate with\n#   {}\n",
        crate::error::MANIFEST_COMMAND
    );
    for line in permutations()? {
        text.push_str(&line);
        text.push('\n');
    }
    Ok(text)
}
