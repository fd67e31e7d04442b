//! Descriptor binding numbers stated once: a pass declares its set's bindings in order, each
//! with the name its shader gives the resource ([`SetBinding`]), and [`bind_by_name`] writes
//! that order into the shader's SPIR-V, so the GLSL declares `layout(set = 0) uniform
//! sampler2D diffuse_tex;` without counting.
//!
//! GLSL without a `binding` qualifier compiles with glslang's automatic numbering (the
//! compile option is set in `glsl_compile.rs`); the number it picks is overwritten here, by
//! the resource's name: a sampled image or input attachment by its variable's name, a uniform
//! block by its block name (`uniform Frame { ... };`). A shader that still writes a number
//! keeps it, checked against the declaration at that number. Every resource a shader reads is
//! checked: a name no declared binding has, a number whose declared binding is of another
//! kind, two resources on one number, and a set other than 0 are errors that name the shader's
//! resource, before any pipeline is created.
//!
//! The SPIR-V is read as the specification lays it out (a five-word header, then instructions
//! whose first word holds their length and opcode); only the instructions that say what a
//! resource is are read.

use ash::vk;

use super::shader_files::{
    spirv_instructions, DECORATION_DESCRIPTOR_SET, OP_DECORATE, OP_NAME, OP_TYPE_POINTER,
    OP_VARIABLE, SPIRV_HEADER_WORDS,
};

/// One binding of a pass's descriptor set 0, as the pass declares it: binding `i` of the set
/// is the `i`-th of the list.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SetBinding<'a> {
    /// The name the shader gives the resource (its variable, or for a uniform block its block
    /// name), which receives this binding's number; `None`: the shader writes the number.
    pub name: Option<&'a str>,
    /// What is bound.
    pub kind: vk::DescriptorType,
}

/// One resource a SPIR-V module declares in a descriptor set.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShaderResource {
    /// Its name: a uniform block's block name, any other resource's variable name (empty when
    /// the module carries no name).
    pub name: String,
    /// `DescriptorSet` decoration.
    pub set: u32,
    /// `Binding` decoration.
    pub binding: u32,
    /// What it is (a uniform block reads as `UNIFORM_BUFFER`, dynamic or not).
    pub kind: vk::DescriptorType,
    /// Index of the word holding its binding number.
    binding_word: usize,
}

const OP_TYPE_IMAGE: u32 = 25;
const OP_TYPE_SAMPLER: u32 = 26;
const OP_TYPE_SAMPLED_IMAGE: u32 = 27;
const OP_TYPE_ARRAY: u32 = 28;
const OP_TYPE_RUNTIME_ARRAY: u32 = 29;
const OP_TYPE_STRUCT: u32 = 30;
const DECORATION_BINDING: u32 = 33;
const STORAGE_UNIFORM_CONSTANT: u32 = 0;
const STORAGE_UNIFORM: u32 = 2;
const STORAGE_STORAGE_BUFFER: u32 = 12;
const DIM_SUBPASS_DATA: u32 = 6;

/// A type as far as a descriptor's kind depends on it.
#[derive(Clone, Copy)]
enum Type {
    /// `OpTypeImage`: its `Dim` and `Sampled` operands.
    Image {
        dim: u32,
        sampled: u32,
    },
    Sampler,
    SampledImage,
    Struct,
    /// An array of this type id.
    Array(u32),
    /// A pointer to this type id (the variable states the storage class).
    Pointer(u32),
}

/// The literal string starting at `words[0]` (nul-terminated, packed little-endian).
fn literal_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .take_while(|&b| b != 0)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The resources `spirv` declares in descriptor sets. Errors say what is malformed.
pub fn resources(spirv: &[u32]) -> Result<Vec<ShaderResource>, String> {
    if spirv.len() < SPIRV_HEADER_WORDS || spirv[0] != super::spirv::SPIRV_MAGIC {
        return Err("not a SPIR-V module (no magic number)".into());
    }
    let mut names = std::collections::HashMap::new();
    let mut types = std::collections::HashMap::new();
    let mut bindings = std::collections::HashMap::new();
    let mut sets = std::collections::HashMap::new();
    let mut variables = Vec::new();
    for instruction in spirv_instructions(spirv) {
        let (at, instruction) = instruction?;
        let opcode = instruction[0] & 0xffff;
        let ops = &instruction[1..];
        let operand = |i: usize| {
            ops.get(i)
                .copied()
                .ok_or_else(|| format!("instruction {opcode} at word {at} lacks operand {i}"))
        };
        match opcode {
            OP_NAME => {
                names.insert(operand(0)?, literal_string(&ops[1..]));
            }
            OP_DECORATE => match operand(1)? {
                DECORATION_BINDING => {
                    bindings.insert(operand(0)?, (operand(2)?, at + 3));
                }
                DECORATION_DESCRIPTOR_SET => {
                    sets.insert(operand(0)?, operand(2)?);
                }
                _ => {}
            },
            OP_TYPE_IMAGE => {
                let (dim, sampled) = (operand(2)?, operand(6)?);
                types.insert(operand(0)?, Type::Image { dim, sampled });
            }
            OP_TYPE_SAMPLER => {
                types.insert(operand(0)?, Type::Sampler);
            }
            OP_TYPE_SAMPLED_IMAGE => {
                types.insert(operand(0)?, Type::SampledImage);
            }
            OP_TYPE_STRUCT => {
                types.insert(operand(0)?, Type::Struct);
            }
            OP_TYPE_ARRAY | OP_TYPE_RUNTIME_ARRAY => {
                types.insert(operand(0)?, Type::Array(operand(1)?));
            }
            OP_TYPE_POINTER => {
                types.insert(operand(0)?, Type::Pointer(operand(2)?));
            }
            OP_VARIABLE => variables.push((operand(0)?, operand(1)?, operand(2)?)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    for (pointer, id, storage) in variables {
        let Some(&set) = sets.get(&id) else {
            continue;
        };
        let Some(&(binding, binding_word)) = bindings.get(&id) else {
            return Err(format!(
                "variable {} in set {set} has no binding number",
                names.get(&id).map_or("?", String::as_str)
            ));
        };
        let Some(Type::Pointer(mut pointee)) = types.get(&pointer).copied() else {
            return Err(format!("variable {id}'s type is not a pointer"));
        };
        while let Some(Type::Array(element)) = types.get(&pointee).copied() {
            pointee = element;
        }
        let kind = match (storage, types.get(&pointee).copied()) {
            (STORAGE_UNIFORM, Some(Type::Struct)) => vk::DescriptorType::UNIFORM_BUFFER,
            (STORAGE_STORAGE_BUFFER, Some(Type::Struct)) => vk::DescriptorType::STORAGE_BUFFER,
            (STORAGE_UNIFORM_CONSTANT, Some(Type::SampledImage)) => {
                vk::DescriptorType::COMBINED_IMAGE_SAMPLER
            }
            (STORAGE_UNIFORM_CONSTANT, Some(Type::Sampler)) => vk::DescriptorType::SAMPLER,
            (STORAGE_UNIFORM_CONSTANT, Some(Type::Image { dim, sampled })) => {
                if dim == DIM_SUBPASS_DATA {
                    vk::DescriptorType::INPUT_ATTACHMENT
                } else if sampled == 2 {
                    vk::DescriptorType::STORAGE_IMAGE
                } else {
                    vk::DescriptorType::SAMPLED_IMAGE
                }
            }
            _ => {
                return Err(format!(
                "variable {} in set {set} (storage class {storage}) is no descriptor lucent knows",
                names.get(&id).map_or("?", String::as_str)
            ))
            }
        };
        // A uniform block goes by its block's name (`uniform Frame { ... } frame;`: `Frame`),
        // as the GLSL interface names it; anything else by its variable's.
        let named = if matches!(types.get(&pointee), Some(Type::Struct)) {
            pointee
        } else {
            id
        };
        let name = names.get(&named).cloned().unwrap_or_default();
        out.push(ShaderResource {
            name,
            set,
            binding,
            kind,
            binding_word,
        });
    }
    out.sort_by_key(|r| (r.set, r.binding));
    Ok(out)
}

/// Whether a shader resource of kind `shader` may be bound through a declared `declared`
/// (SPIR-V cannot tell a dynamic uniform buffer from a plain one).
fn kinds_agree(shader: vk::DescriptorType, declared: vk::DescriptorType) -> bool {
    shader == declared
        || (shader == vk::DescriptorType::UNIFORM_BUFFER
            && declared == vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC)
        || (shader == vk::DescriptorType::STORAGE_BUFFER
            && declared == vk::DescriptorType::STORAGE_BUFFER_DYNAMIC)
}

/// The declared bindings, listed for an error message.
fn listed(declared: &[SetBinding<'_>]) -> String {
    if declared.is_empty() {
        return "it declares none".into();
    }
    let each: Vec<String> = declared
        .iter()
        .enumerate()
        .map(|(i, b)| {
            format!(
                "{i}: {} {:?}",
                b.name.unwrap_or("(numbered by the shader)"),
                b.kind
            )
        })
        .collect();
    format!("it declares {}", each.join(", "))
}

/// Gives each resource of `spirv` the number of the declared binding of its name (see the
/// module docs) and checks every resource against `declared`. The error names the resource
/// and lists what is declared.
pub fn bind_by_name(spirv: &mut [u32], declared: &[SetBinding<'_>]) -> Result<(), String> {
    let found = resources(spirv)?;
    let mut taken: Vec<(u32, &str)> = Vec::new();
    for resource in &found {
        let name = resource.name.as_str();
        if resource.set != 0 {
            return Err(format!(
                "`{name}` is in descriptor set {}: lucent's passes bind set 0 only",
                resource.set
            ));
        }
        let named = declared
            .iter()
            .position(|b| b.name.is_some_and(|n| n == name && !n.is_empty()));
        let number = match named {
            Some(i) => i as u32,
            None => match declared.get(resource.binding as usize) {
                Some(b) if b.name.is_none() => resource.binding,
                _ => {
                    return Err(format!(
                        "`{name}` ({:?} at binding {}) is bound by none of the pass's bindings: {}",
                        resource.kind,
                        resource.binding,
                        listed(declared)
                    ))
                }
            },
        };
        if let Some(&(_, other)) = taken.iter().find(|(b, n)| *b == number && *n != name) {
            return Err(format!(
                "`{name}` and `{other}` are both at binding {number}"
            ));
        }
        let binding = declared[number as usize];
        if !kinds_agree(resource.kind, binding.kind) {
            return Err(format!(
                "`{name}` is a {:?} but the pass binds a {:?} at binding {number}",
                resource.kind, binding.kind
            ));
        }
        taken.push((number, name));
        spirv[resource.binding_word] = number;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Words of the literal string `s` (nul-terminated, padded to a word).
    fn string_words(s: &str) -> Vec<u32> {
        let mut bytes = s.as_bytes().to_vec();
        bytes.push(0);
        while !bytes.len().is_multiple_of(4) {
            bytes.push(0);
        }
        bytes
            .chunks(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    }

    fn instruction(out: &mut Vec<u32>, opcode: u32, operands: &[u32]) {
        out.push(((operands.len() as u32 + 1) << 16) | opcode);
        out.extend_from_slice(operands);
    }

    /// A module with a uniform block `Frame` (instance `frame`) at binding `frame`, a sampled
    /// image `diffuse_tex` at `diffuse` and an input attachment `gb0` at `input`.
    fn module(frame: u32, diffuse: u32, input: u32) -> Vec<u32> {
        let mut m = vec![super::super::spirv::SPIRV_MAGIC, 0x0001_0600, 0, 100, 0];
        let name = |m: &mut Vec<u32>, id: u32, s: &str| {
            let mut ops = vec![id];
            ops.extend(string_words(s));
            instruction(m, OP_NAME, &ops);
        };
        name(&mut m, 10, "Frame");
        name(&mut m, 11, "frame");
        name(&mut m, 21, "diffuse_tex");
        name(&mut m, 31, "gb0");
        for (id, binding) in [(11, frame), (21, diffuse), (31, input)] {
            instruction(&mut m, OP_DECORATE, &[id, DECORATION_DESCRIPTOR_SET, 0]);
            instruction(&mut m, OP_DECORATE, &[id, DECORATION_BINDING, binding]);
        }
        instruction(&mut m, OP_TYPE_STRUCT, &[10, 99]);
        instruction(&mut m, OP_TYPE_POINTER, &[12, STORAGE_UNIFORM, 10]);
        instruction(&mut m, OP_VARIABLE, &[12, 11, STORAGE_UNIFORM]);
        instruction(&mut m, OP_TYPE_IMAGE, &[18, 98, 1, 0, 0, 0, 1, 0]);
        instruction(&mut m, OP_TYPE_SAMPLED_IMAGE, &[19, 18]);
        instruction(&mut m, OP_TYPE_POINTER, &[20, STORAGE_UNIFORM_CONSTANT, 19]);
        instruction(&mut m, OP_VARIABLE, &[20, 21, STORAGE_UNIFORM_CONSTANT]);
        instruction(
            &mut m,
            OP_TYPE_IMAGE,
            &[28, 98, DIM_SUBPASS_DATA, 0, 0, 0, 2, 0],
        );
        instruction(&mut m, OP_TYPE_POINTER, &[30, STORAGE_UNIFORM_CONSTANT, 28]);
        instruction(&mut m, OP_VARIABLE, &[30, 31, STORAGE_UNIFORM_CONSTANT]);
        m
    }

    const UNIFORM: vk::DescriptorType = vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC;
    const SAMPLED: vk::DescriptorType = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
    const INPUT: vk::DescriptorType = vk::DescriptorType::INPUT_ATTACHMENT;

    fn named(name: &str, kind: vk::DescriptorType) -> SetBinding<'_> {
        SetBinding {
            name: Some(name),
            kind,
        }
    }

    #[test]
    fn resources_are_read_with_their_names_and_kinds() {
        let found = resources(&module(0, 5, 7)).unwrap();
        let summary: Vec<_> = found
            .iter()
            .map(|r| (r.name.as_str(), r.binding, r.kind))
            .collect();
        assert_eq!(
            summary,
            [
                ("Frame", 0, vk::DescriptorType::UNIFORM_BUFFER),
                ("diffuse_tex", 5, SAMPLED),
                ("gb0", 7, INPUT)
            ]
        );
    }

    #[test]
    fn names_take_the_declared_numbers() {
        // glslang's automatic numbers (9, 9, 9) are overwritten by the declaration's order.
        let mut spirv = module(9, 9, 9);
        let declared = [
            named("gb0", INPUT),
            named("Frame", UNIFORM),
            named("diffuse_tex", SAMPLED),
        ];
        bind_by_name(&mut spirv, &declared).unwrap();
        let numbers: Vec<_> = resources(&spirv)
            .unwrap()
            .into_iter()
            .map(|r| (r.name, r.binding))
            .collect();
        assert_eq!(
            numbers,
            [
                ("gb0".to_string(), 0),
                ("Frame".to_string(), 1),
                ("diffuse_tex".to_string(), 2)
            ]
        );
    }

    #[test]
    fn a_number_the_shader_writes_is_kept_and_checked() {
        let mut spirv = module(0, 1, 2);
        let unnamed = |kind| SetBinding { name: None, kind };
        let declared = [unnamed(UNIFORM), unnamed(SAMPLED), unnamed(INPUT)];
        bind_by_name(&mut spirv, &declared).unwrap();
        assert_eq!(spirv, module(0, 1, 2));
        // The shader's binding 1 is a sampled image; the declaration says input attachment.
        let wrong = [unnamed(UNIFORM), unnamed(INPUT), unnamed(INPUT)];
        let error = bind_by_name(&mut module(0, 1, 2), &wrong).unwrap_err();
        assert!(error.contains("`diffuse_tex` is a"), "{error}");
    }

    #[test]
    fn a_resource_the_pass_does_not_declare_is_an_error_naming_it() {
        let declared = [named("Frame", UNIFORM), named("diffuse", SAMPLED)];
        let error = bind_by_name(&mut module(0, 1, 2), &declared).unwrap_err();
        assert!(
            error.contains("`diffuse_tex`") && error.contains("1: diffuse"),
            "{error}"
        );
        // Two resources on one number (the shader writes both).
        let declared = [
            named("Frame", UNIFORM),
            SetBinding {
                name: None,
                kind: SAMPLED,
            },
        ];
        let error = bind_by_name(&mut module(0, 1, 1), &declared).unwrap_err();
        assert!(error.contains("both at binding 1"), "{error}");
    }

    #[test]
    fn malformed_modules_are_errors() {
        assert!(resources(&[1, 2, 3]).is_err());
        let mut cut = module(0, 1, 2);
        cut.truncate(cut.len() - 1);
        assert!(resources(&cut).is_err());
    }
}
