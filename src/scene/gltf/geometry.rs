//! Mesh primitives as lucent [`Mesh`]es: triangle lists only (any other mode is refused by
//! name), indexed or not, positions required, normals generated where the file has none,
//! the material's texture coordinates (its `KHR_texture_transform` applied), tangents from
//! the file or generated from the UVs; attributes lucent does not draw are warned about.

use std::collections::BTreeSet;

use ::gltf::json::mesh::{Mode, Semantic};
use ::gltf::json::validation::Checked;

use super::accessors::Accessors;
use super::materials::UvMapping;
use crate::scene::normals::{angle_weighted_normals, generate_tangents};
use crate::scene::obj::{MAX_TRIANGLES, MAX_VERTICES};
use crate::scene::Mesh;

/// glTF's name of a primitive mode.
fn mode_name(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "POINTS",
        Mode::Lines => "LINES",
        Mode::LineLoop => "LINE_LOOP",
        Mode::LineStrip => "LINE_STRIP",
        Mode::Triangles => "TRIANGLES",
        Mode::TriangleStrip => "TRIANGLE_STRIP",
        Mode::TriangleFan => "TRIANGLE_FAN",
    }
}

/// Primitive `p` of mesh `m` as a validated mesh, its UVs mapped as `uv` says. `ignored`
/// collects the attribute names lucent does not draw (warned once per file by the caller).
pub fn primitive(
    data: &Accessors<'_>,
    m: usize,
    p: usize,
    uv: Option<UvMapping>,
    ignored: &mut BTreeSet<String>,
) -> Result<Mesh, String> {
    let mesh = &data.root.meshes[m];
    let primitive = &mesh.primitives[p];
    let what = match &mesh.name {
        Some(name) => format!("meshes[{m}] \"{name}\" primitives[{p}]"),
        None => format!("meshes[{m}].primitives[{p}]"),
    };
    let in_what = |e: String| format!("{what}: {e}");
    match primitive.mode {
        Checked::Valid(Mode::Triangles) => {}
        Checked::Valid(other) => {
            return Err(format!(
                "{what}: mode {} is not supported: lucent draws triangle lists (mode 4, \
                 TRIANGLES) only",
                mode_name(other)
            ))
        }
        Checked::Invalid => return Err(format!("{what}: invalid mode")),
    }
    let attribute = |s: Semantic| {
        primitive
            .attributes
            .get(&Checked::Valid(s))
            .map(|i| i.value())
    };
    // A material without textures samples nothing, but the mesh keeps its first UV set
    // (and tangents) as an OBJ's: what a thickness bake or a scene file's material reads.
    let uv = uv.or_else(|| {
        attribute(Semantic::TexCoords(0)).map(|_| UvMapping {
            set: 0,
            transform: None,
        })
    });
    let positions_at =
        attribute(Semantic::Positions).ok_or_else(|| format!("{what} has no POSITION"))?;
    let positions = data
        .vec3s(positions_at, MAX_VERTICES as u64)
        .map_err(in_what)?;
    let n = positions.len();
    let same_count = |name: &str, len: usize| -> Result<(), String> {
        if len == n {
            Ok(())
        } else {
            Err(format!("{what}: {len} {name} for {n} positions"))
        }
    };
    let indices = match primitive.indices {
        Some(i) => data
            .indices(i.value(), MAX_TRIANGLES as u64 * 3, n)
            .map_err(in_what)?,
        None => (0..n as u32).collect(),
    };
    if indices.len() % 3 != 0 {
        return Err(format!(
            "{what}: {} {} is not a whole number of triangles",
            indices.len(),
            if primitive.indices.is_some() {
                "indices"
            } else {
                "vertices (not indexed)"
            }
        ));
    }
    let mut normals = match attribute(Semantic::Normals) {
        Some(i) => {
            let normals = data.vec3s(i, MAX_VERTICES as u64).map_err(in_what)?;
            same_count("normals", normals.len())?;
            normals
        }
        None => Vec::new(),
    };
    if !normals.is_empty() {
        if normals.iter().any(|v| v.length_squared() < 1e-20) {
            log::warn!("{what}: zero-length normals; generated them all instead");
            normals.clear();
        } else {
            for v in &mut normals {
                *v = v.normalize();
            }
        }
    }
    if normals.is_empty() {
        normals = angle_weighted_normals(&positions, &indices);
    }
    let uvs = match uv {
        None => Vec::new(),
        Some(mapping) => match attribute(Semantic::TexCoords(mapping.set)) {
            Some(i) => {
                let uvs = data.vec2s(i, MAX_VERTICES as u64).map_err(in_what)?;
                same_count("texture coordinates", uvs.len())?;
                let uvs: Vec<_> = uvs.into_iter().map(|t| mapping.apply(t)).collect();
                if uvs.iter().any(|t| !t.is_finite()) {
                    return Err(format!(
                        "{what}: KHR_texture_transform makes texture coordinates non-finite"
                    ));
                }
                uvs
            }
            None => {
                return Err(format!(
                    "{what}: its material's textures read TEXCOORD_{}, which it does not have",
                    mapping.set
                ))
            }
        },
    };
    let tangents = match (attribute(Semantic::Tangents), uvs.is_empty()) {
        (_, true) => Vec::new(),
        (Some(i), false) if uv.is_some_and(|m| m.transform.is_none()) => {
            let t = data.vec4s(i, MAX_VERTICES as u64).map_err(in_what)?;
            same_count("tangents", t.len())?;
            t
        }
        (_, false) => generate_tangents(&positions, &normals, &uvs, &indices),
    };
    for semantic in primitive.attributes.keys() {
        let name = match semantic {
            Checked::Valid(Semantic::Positions | Semantic::Normals) => continue,
            Checked::Valid(Semantic::Tangents) if !uvs.is_empty() => continue,
            Checked::Valid(Semantic::TexCoords(s)) if uv.is_some_and(|m| m.set == *s) => continue,
            Checked::Valid(Semantic::Tangents) => "TANGENT".to_string(),
            Checked::Valid(Semantic::TexCoords(s)) => format!("TEXCOORD_{s}"),
            Checked::Valid(Semantic::Colors(s)) => format!("COLOR_{s}"),
            Checked::Valid(Semantic::Joints(s)) => format!("JOINTS_{s}"),
            Checked::Valid(Semantic::Weights(s)) => format!("WEIGHTS_{s}"),
            Checked::Valid(Semantic::Extras(s)) => format!("_{s}"),
            Checked::Invalid => "an invalid attribute".to_string(),
        };
        ignored.insert(name);
    }
    if primitive.targets.as_ref().is_some_and(|t| !t.is_empty()) {
        ignored.insert("morph targets".into());
    }
    let out = Mesh {
        positions,
        normals,
        uvs,
        tangents,
        colors: Vec::new(),
        indices,
        shape: None,
    };
    out.validate(&what).map_err(|e| e.to_string())?;
    Ok(out)
}
