//! Writing a mesh back as OBJ, with one colour per vertex.

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use crate::scene::Mesh;
use crate::{LucentError, Result};

/// Writes `mesh` as OBJ with one linear colour per vertex: `v x y z r g b` per vertex, then `vn`
/// per normal, `vt` per UV (flipped back to OBJ's `v`-up), and faces `f a/b/c` with 1-based
/// indices. The file is written atomically (a crash never leaves half a file).
///
/// Errors when the mesh fails [`Mesh::validate`], or `colors` does not hold one finite colour
/// per vertex.
pub fn write_obj_with_colors(path: &Path, mesh: &Mesh, colors: &[Vec3]) -> Result<()> {
    let what = path.display().to_string();
    mesh.validate(&what)?;
    if colors.len() != mesh.positions.len() {
        return Err(LucentError::InvalidInput(format!(
            "{what}: {} colours for {} vertices",
            colors.len(),
            mesh.positions.len()
        )));
    }
    if let Some(v) = colors.iter().position(|c| !c.is_finite()) {
        return Err(LucentError::InvalidInput(format!(
            "{what}: vertex {v} has a non-finite colour {}",
            colors[v]
        )));
    }
    let mut s = String::with_capacity(mesh.positions.len() * 80 + mesh.indices.len() * 12);
    // Writing to a String cannot fail; the fmt::Result is ignored.
    let _ = writeln!(
        s,
        "# written by lucent: {} vertices (v x y z r g b, linear colour), {} triangles",
        mesh.positions.len(),
        mesh.triangle_count()
    );
    for (p, c) in mesh.positions.iter().zip(colors) {
        let _ = writeln!(s, "v {} {} {} {} {} {}", p.x, p.y, p.z, c.x, c.y, c.z);
    }
    for n in &mesh.normals {
        let _ = writeln!(s, "vn {} {} {}", n.x, n.y, n.z);
    }
    for t in &mesh.uvs {
        let _ = writeln!(s, "vt {} {}", t.x, 1.0 - t.y);
    }
    let (has_uv, has_n) = (!mesh.uvs.is_empty(), !mesh.normals.is_empty());
    for tri in mesh.indices.chunks_exact(3) {
        s.push('f');
        for &i in tri {
            let i = i as u64 + 1;
            let _ = match (has_uv, has_n) {
                (true, true) => write!(s, " {i}/{i}/{i}"),
                (false, true) => write!(s, " {i}//{i}"),
                (true, false) => write!(s, " {i}/{i}"),
                (false, false) => write!(s, " {i}"),
            };
        }
        s.push('\n');
    }
    crate::files::write_file_atomic(path, s.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::super::load_obj;
    use super::super::tests::temp_dir;
    use super::*;

    #[test]
    fn written_obj_reads_back_with_colours() {
        let dir = temp_dir("write");
        let mut mesh = Mesh::generate(crate::scene::Shape::Sphere { radius: 1.0 }, 8, 4);
        mesh.uvs.clear();
        let colors: Vec<Vec3> = mesh.positions.iter().map(|p| p.abs()).collect();
        let path = dir.join("sub/thick.obj");
        write_obj_with_colors(&path, &mesh, &colors).unwrap();
        let back = load_obj(&path).unwrap();
        // tobj renumbers vertices in order of first use: compare corner by corner.
        assert_eq!(back.mesh.triangle_count(), mesh.triangle_count());
        for (a, b) in back.mesh.indices.iter().zip(&mesh.indices) {
            assert_eq!(
                back.mesh.positions[*a as usize],
                mesh.positions[*b as usize]
            );
            assert_eq!(back.mesh.colors[*a as usize], colors[*b as usize]);
        }
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text
            .lines()
            .any(|l| l.starts_with("f ") && l.contains("//")));
        assert!(write_obj_with_colors(&path, &mesh, &colors[1..]).is_err());
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn written_uvs_round_trip() {
        let dir = temp_dir("write-uv");
        let mesh = Mesh::generate(crate::scene::Shape::Plane { half_size: 1.0 }, 2, 2);
        let path = dir.join("plane.obj");
        write_obj_with_colors(&path, &mesh, &vec![Vec3::ONE; mesh.positions.len()]).unwrap();
        let back = load_obj(&path).unwrap();
        for (a, b) in back.mesh.indices.iter().zip(&mesh.indices) {
            let (a, b) = (back.mesh.uvs[*a as usize], mesh.uvs[*b as usize]);
            assert!((a - b).length() < 1e-6, "{a} vs {b}");
        }
        std::fs::remove_dir_all(dir).ok();
    }
}
