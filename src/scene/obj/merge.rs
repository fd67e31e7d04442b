//! From tobj's models to one mesh: merging them, dropping degenerate triangles, finishing the
//! normals.

use glam::{DVec3, Vec2, Vec3};

use crate::scene::normals::angle_weighted_normals;
use crate::scene::Mesh;

/// Concatenates tobj's models into one mesh (UVs flipped to image space), checking that every
/// attribute array has the length tobj promises. The flag is true when the file has normals on
/// some face corners but not all (the mesh's normals are then incomplete).
/// Merges the parser's models into one mesh; returns it with each triangle's material index and
/// whether normals were only on some face corners.
#[allow(clippy::type_complexity)]
pub(super) fn merge_models(
    models: &[tobj::Model],
) -> std::result::Result<(Mesh, Vec<Option<usize>>, bool), String> {
    let mut mesh = Mesh::default();
    let mut triangle_materials = Vec::new();
    let (mut uv_models, mut plain_models) = (0, 0);
    let (mut any_normals, mut normals_complete) = (false, true);
    for model in models {
        let m = &model.mesh;
        if m.indices.is_empty() {
            continue;
        }
        let n = m.positions.len() / 3;
        if m.positions.len() % 3 != 0 {
            return Err(format!(
                "object '{}': parser returned {} position values (not a multiple of 3)",
                model.name,
                m.positions.len()
            ));
        }
        let base = mesh.positions.len();
        if base + n > u32::MAX as usize {
            return Err("more vertices than 32-bit indices can address".into());
        }
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2])),
        );
        any_normals |= !m.normals.is_empty();
        if m.normals.len() == n * 3 {
            mesh.normals.extend(
                m.normals
                    .chunks_exact(3)
                    .map(|p| Vec3::new(p[0], p[1], p[2])),
            );
        } else {
            normals_complete = false;
        }
        match m.texcoords.len() {
            0 => plain_models += 1,
            len if len == n * 2 => {
                uv_models += 1;
                // OBJ's v points up the image; image-space v (Vulkan's) points down.
                mesh.uvs.extend(
                    m.texcoords
                        .chunks_exact(2)
                        .map(|t| Vec2::new(t[0], 1.0 - t[1])),
                );
            }
            len => {
                return Err(format!(
                    "object '{}': {} texture coordinates for {n} vertices: some face corners \
                     lack texture coordinates",
                    model.name,
                    len / 2
                ))
            }
        }
        match m.vertex_color.len() {
            0 => {}
            len if len == n * 3 => mesh.colors.extend(
                m.vertex_color
                    .chunks_exact(3)
                    .map(|c| Vec3::new(c[0], c[1], c[2])),
            ),
            len => {
                return Err(format!(
                    "object '{}': {} vertex colours for {n} vertices",
                    model.name,
                    len / 3
                ))
            }
        }
        for &i in &m.indices {
            if i as usize >= n {
                return Err(format!(
                    "object '{}': parser returned index {i} for {n} vertices",
                    model.name
                ));
            }
            mesh.indices.push((base + i as usize) as u32);
        }
        triangle_materials.extend(std::iter::repeat_n(m.material_id, m.indices.len() / 3));
    }
    if uv_models > 0 && plain_models > 0 {
        return Err(
            "texture coordinates must be on every face or none: some objects have them and \
             others do not"
                .into(),
        );
    }
    if !mesh.colors.is_empty() && mesh.colors.len() != mesh.positions.len() {
        return Err("vertex colours must be on every vertex or none".into());
    }
    if !normals_complete {
        mesh.normals.clear();
    }
    Ok((mesh, triangle_materials, any_normals && !normals_complete))
}

/// Drops triangles with a repeated vertex or zero area; errors when none is left.
pub(super) fn drop_degenerate_triangles(
    mesh: &mut Mesh,
    triangle_materials: &mut Vec<Option<usize>>,
    repairs: &mut Vec<String>,
) -> std::result::Result<(), String> {
    let total = mesh.triangle_count();
    let positions = &mesh.positions;
    let mut kept = Vec::with_capacity(mesh.indices.len());
    let mut kept_materials = Vec::with_capacity(triangle_materials.len());
    for (i, t) in mesh.indices.chunks_exact(3).enumerate() {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            continue;
        }
        // f64: exact zero test without f32 overflow for huge coordinates.
        let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize].as_dvec3());
        if (b - a).cross(c - a) == DVec3::ZERO {
            continue;
        }
        kept.extend_from_slice(t);
        kept_materials.push(triangle_materials.get(i).copied().flatten());
    }
    *triangle_materials = kept_materials;
    let dropped = total - kept.len() / 3;
    if kept.is_empty() {
        return Err(format!(
            "all {total} triangles are degenerate (zero area or a repeated vertex)"
        ));
    }
    if dropped > 0 {
        repairs.push(format!(
            "dropped {dropped} of {total} degenerate triangles (zero area or a repeated vertex)"
        ));
    }
    mesh.indices = kept;
    Ok(())
}

/// Normalises the file's normals, generating angle-weighted ones where the file has none (or
/// only some) and in place of zero-length ones.
pub(super) fn finish_normals(mesh: &mut Mesh, repairs: &mut Vec<String>) {
    if mesh.normals.len() != mesh.positions.len() {
        mesh.normals = angle_weighted_normals(&mesh.positions, &mesh.indices);
        return;
    }
    let generated = angle_weighted_normals(&mesh.positions, &mesh.indices);
    let mut replaced = 0;
    for (n, g) in mesh.normals.iter_mut().zip(generated) {
        // f64: squaring components near f32::MAX overflows f32 to infinity.
        match n.as_dvec3().try_normalize() {
            Some(u) => *n = u.as_vec3(),
            None => {
                *n = g;
                replaced += 1;
            }
        }
    }
    if replaced > 0 {
        repairs.push(format!(
            "replaced {replaced} zero-length normals with generated ones"
        ));
    }
}
#[cfg(test)]
mod tests {
    use super::super::tests::{err, load_str, QUAD};

    #[test]
    fn degenerate_triangles_are_dropped_and_counted() {
        let text = format!("{QUAD}v 2 0 0\nf 1 2 3\nf 1 1 2\nf 1 2 5\n");
        let o = load_str("degen", &text).unwrap();
        assert_eq!(o.mesh.triangle_count(), 1);
        assert!(o.repairs[0].contains("dropped 2 of 3"), "{:?}", o.repairs);
        let e = err("alldegen", &format!("{QUAD}f 1 1 2\nf 1 2 1\n"));
        assert!(e.contains("all 2 triangles are degenerate"), "{e}");
    }
}
