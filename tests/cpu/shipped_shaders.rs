//! The shipped SPIR-V: `glsl/permutations.txt` is exactly what the features enumerate
//! (`lucent::shipped`), the bundle build.rs compiled holds exactly that, and its SPIR-V
//! is what the run-time compiler makes of the same sources.
//!
//! Regenerate the manifest after changing a pass's defines (or adding a shader):
//!
//! ```text
//! LUCENT_WRITE_MANIFEST=1 cargo test --test cpu shipped_shaders::
//! ```

use std::path::Path;

use lucent::backend::shader::ShaderCompiler;
use lucent::error::MANIFEST_COMMAND;
use lucent::shipped;

fn manifest_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl/permutations.txt")
}

#[test]
fn the_manifest_is_what_the_features_enumerate() {
    let expected = shipped::manifest().unwrap();
    let path = manifest_path();
    if std::env::var_os("LUCENT_WRITE_MANIFEST").is_some() {
        std::fs::write(&path, &expected).unwrap();
        eprintln!(
            "wrote {} ({} permutations); rebuild to ship them",
            path.display(),
            shipped::permutations().unwrap().len()
        );
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != expected {
        let committed: std::collections::BTreeSet<&str> = committed.lines().collect();
        let expected: std::collections::BTreeSet<&str> = expected.lines().collect();
        let missing: Vec<&&str> = expected.difference(&committed).take(5).collect();
        let extra: Vec<&&str> = committed.difference(&expected).take(5).collect();
        panic!(
            "glsl/permutations.txt is stale: {} permutations missing (first: {missing:?}), {} no \
             longer built (first: {extra:?}); regenerate it with `{MANIFEST_COMMAND}`",
            expected.difference(&committed).count(),
            committed.difference(&expected).count(),
        );
    }
}

#[test]
fn the_bundle_holds_the_manifest() {
    let shipped = ShaderCompiler::shipped_permutations().unwrap();
    let committed: Vec<String> = std::fs::read_to_string(manifest_path())
        .unwrap()
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with('#'))
        .map(str::to_string)
        .collect();
    assert_eq!(
        shipped, committed,
        "the bundle was built from another manifest (cargo rebuilds it when glsl/ changes)"
    );
    assert!(!shipped.is_empty());
}

/// Every `step`-th permutation compiled at run time gives the shipped words: build.rs and the
/// run-time compiler share their options and include lookup.
#[cfg(feature = "runtime-shaders")]
#[test]
fn shipped_spirv_is_what_the_run_time_compiler_makes() {
    let shipped = ShaderCompiler::shipped().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    let runtime = ShaderCompiler::new(&root, None).unwrap();
    let lines = ShaderCompiler::shipped_permutations().unwrap();
    let step = (lines.len() / 40).max(1);
    for line in lines.iter().step_by(step) {
        let mut parts = line.split(' ');
        let path = parts.next().unwrap();
        let defines: Vec<(&str, &str)> = parts.map(|p| p.split_once('=').unwrap()).collect();
        let a = shipped.compile(path, &defines).unwrap();
        let b = runtime.compile(path, &defines).unwrap();
        assert!(
            a.spirv == b.spirv,
            "{line}: shipped and run-time SPIR-V differ"
        );
        assert_eq!(a.stage, b.stage);
    }
}

/// Every shipped permutation names each resource it declares, and carries neither source text,
/// line numbers nor member names: passes bind by those names (`lucent::backend::bindings`), so a compiler that
/// stripped them would leave every pipeline unbindable, and one that kept the source text
/// would grow the bundle.
#[test]
fn every_shipped_resource_keeps_its_name_and_no_source_text_or_lines_are_left() {
    const OP_SOURCE: u32 = 3;
    const OP_MEMBER_NAME: u32 = 6;
    const OP_STRING: u32 = 7;
    const OP_LINE: u32 = 8;
    let shipped = ShaderCompiler::shipped().unwrap();
    for line in ShaderCompiler::shipped_permutations().unwrap() {
        let mut parts = line.split(' ');
        let path = parts.next().unwrap();
        let defines: Vec<(&str, &str)> = parts.map(|p| p.split_once('=').unwrap()).collect();
        let spirv = shipped.compile(path, &defines).unwrap().spirv;
        for resource in lucent::backend::bindings::resources(&spirv).unwrap() {
            assert!(
                !resource.name.is_empty(),
                "{line}: the resource at binding {} has no name",
                resource.binding
            );
        }
        let mut at = 5;
        while at < spirv.len() {
            let opcode = spirv[at] & 0xffff;
            assert!(
                ![OP_SOURCE, OP_MEMBER_NAME, OP_STRING, OP_LINE].contains(&opcode),
                "{line}: debug instruction {opcode} left in"
            );
            at += (spirv[at] >> 16).max(1) as usize;
        }
    }
}
