//! A scene's thickness, made ready for the GPU: what whoever loads a scene calls before
//! rendering it (`scene::load_scene` only parses; it never bakes behind the caller's back).
//!
//! [`prepare_thickness`] puts every translucent mesh's local thickness into its vertex colours:
//! `thickness = "bake"` through the on-disk cache, thickness textures sampled at the vertices.
//! [`load_scene_baked`] is the two steps together, with the default cache directory
//! ([`default_thickness_cache_dir`]: per user, never the source tree); [`load_scene_baked_in`]
//! with the directory the caller chooses (a host engine's own cache).

use glam::Vec3;

use crate::scene::material::ThicknessSource;
use crate::scene::{self, material, texture, Scene};

/// The thickness bake cache used when the caller names none: `thickness` in
/// `crate::files::default_cache_dir`.
pub fn default_thickness_cache_dir() -> std::path::PathBuf {
    crate::files::default_cache_dir().join("thickness")
}

/// Loads a scene by built-in name or `.toml` path ([`scene::load_scene`]) and prepares its
/// thickness ([`prepare_thickness`]) with the bake cache in [`default_thickness_cache_dir`].
pub fn load_scene_baked(name_or_path: &str) -> crate::Result<Scene> {
    load_scene_baked_in(name_or_path, &default_thickness_cache_dir())
}

/// [`load_scene_baked`] with the bake cache in `cache_dir` (created on first use).
pub fn load_scene_baked_in(
    name_or_path: &str,
    cache_dir: &std::path::Path,
) -> crate::Result<Scene> {
    let mut scene = scene::load_scene(name_or_path)?;
    prepare_thickness(&mut scene, cache_dir)?;
    Ok(scene)
}

/// Puts every mesh's local thickness (GDC 2011) into its vertex colours, where the G-buffer
/// pass reads it: meshes drawn with `thickness = "bake"` are baked through the on-disk cache
/// keyed by mesh content (only the first load pays), meshes drawn with a thickness texture
/// sample it at their vertices' UVs (the talk's vertex-colour path: per-vertex, so detail
/// finer than the tessellation is lost; the texture is read as linear data).
///
/// Objects whose term derives from a medium (a material with a `[material.medium]`: its own
/// `[material.translucency]` without `thickness`, or the one a forced `--technique
/// translucency` derives, so every medium object is prepared) get distances instead: their
/// mesh, placed by the object's transform (the thickness is the object's, in world units), is
/// baked as slab-equivalent distances ([`crate::bake::BakeMeasure::Distance`]), converted to
/// millimetres with the medium's `units_per_mm`, and the vertex colours hold the medium's
/// transmittance through them ([`material::Extinction::transmittance`]). A mesh that other
/// translucent objects also draw is copied for them, so each keeps its own thickness.
pub fn prepare_thickness(scene: &mut Scene, cache_dir: &std::path::Path) -> crate::Result<()> {
    sample_thickness_textures(scene)?;
    prepare_medium_thickness(scene, cache_dir)?;
    let mut wanted: Vec<usize> = scene
        .objects
        .iter()
        .filter(|o| {
            o.material.translucency.as_ref().is_some_and(|t| {
                t.thickness == material::ThicknessSource::Bake && t.extinction.is_none()
            })
        })
        .map(|o| o.mesh)
        .collect();
    wanted.sort_unstable();
    wanted.dedup();
    let options = crate::bake::BakeOptions {
        rays: 256,
        max_distance: None,
        seed: 1,
        texture_size: 512,
        progress: false,
        measure: crate::bake::BakeMeasure::Occlusion,
    };
    for m in wanted {
        if !scene.meshes[m].colors.is_empty() {
            continue; // the mesh brought its own (e.g. an OBJ written by bake-thickness)
        }
        let values = crate::bake::cached_per_vertex(&scene.meshes[m], &options, cache_dir)?;
        scene.meshes[m].colors = values.into_iter().map(Vec3::splat).collect();
    }
    Ok(())
}

/// The distance bake of every object whose term derives from a medium (see
/// [`prepare_thickness`]).
fn prepare_medium_thickness(scene: &mut Scene, cache_dir: &std::path::Path) -> crate::Result<()> {
    let options = crate::bake::BakeOptions {
        rays: 256,
        max_distance: None,
        seed: 1,
        texture_size: 512,
        progress: false,
        measure: crate::bake::BakeMeasure::Distance,
    };
    // (mesh, transform, extinction, thickness) -> the mesh index its objects draw.
    type Key = (usize, glam::Mat4, material::Extinction, ThicknessSource);
    let mut done: Vec<(Key, usize)> = Vec::new();
    for i in 0..scene.objects.len() {
        let object = &scene.objects[i];
        let Some((extinction, thickness)) = medium_term(&object.material) else {
            continue;
        };
        let (mesh, transform) = (object.mesh, object.transform);
        let key: Key = (mesh, transform, extinction, thickness);
        if let Some((_, m)) = done.iter().find(|(k, _)| *k == key) {
            scene.objects[i].mesh = *m;
            continue;
        }
        // The object's own copy when another translucent object (or another medium, or the
        // same mesh placed differently) reads the mesh's colours; the mesh itself otherwise.
        let shared = scene.objects.iter().enumerate().any(|(j, o)| {
            j != i
                && o.mesh == mesh
                && o.material.translucency_in_table().is_some()
                && !(o.transform == transform
                    && medium_term(&o.material) == Some((extinction, key.3.clone())))
        }) || done.iter().any(|((m, ..), _)| *m == mesh);
        let target = if shared {
            scene.meshes.push(scene.meshes[mesh].clone());
            scene.meshes.len() - 1
        } else {
            mesh
        };
        let distances_mm = match &key.3 {
            ThicknessSource::Volume { factor, texture } => {
                volume_distances(&scene.meshes[mesh], *factor, texture.as_ref(), transform)?
                    .into_iter()
                    .map(|units| units * extinction.mm_per_unit)
                    .collect::<Vec<f32>>()
            }
            _ => {
                let mut placed = scene.meshes[mesh].clone();
                placed.colors.clear();
                let normal_matrix = transform.inverse().transpose();
                for p in &mut placed.positions {
                    *p = transform.transform_point3(*p);
                }
                for n in &mut placed.normals {
                    // Outward stays outward (a mirroring transform flips the winding the baker
                    // does not read: it casts along -N). Zero normals stay zero (the baker
                    // falls back).
                    *n = normal_matrix.transform_vector3(*n);
                }
                let values = crate::bake::cached_per_vertex(&placed, &options, cache_dir)?;
                // The values are t / D, D the placed mesh's diagonal (the bake's default
                // distance).
                let diagonal = crate::bake::bounding_box_diagonal(&placed);
                let mm_per_value = diagonal * extinction.mm_per_unit;
                values.into_iter().map(|v| v * mm_per_value).collect()
            }
        };
        scene.meshes[target].colors = distances_mm
            .into_iter()
            .map(|mm| extinction.transmittance(mm))
            .collect();
        scene.objects[i].mesh = target;
        done.push((key, target));
    }
    Ok(())
}

/// The extinction and thickness of `material`'s GDC 2011 term when it derives from a medium.
fn medium_term(material: &material::Material) -> Option<(material::Extinction, ThicknessSource)> {
    let term = material.translucency_in_table()?;
    Some((term.extinction?, term.thickness.clone()))
}

/// The distance under each vertex of `mesh` placed by `transform`, in scene units, from a
/// glTF volume's thickness: `factor` times the texture's green channel at the vertex's UV
/// (`factor` alone without a texture), times the transform's mean scale (glTF gives the
/// thickness in the mesh's own units).
fn volume_distances(
    mesh: &crate::scene::Mesh,
    factor: f32,
    texture: Option<&material::TextureSource>,
    transform: glam::Mat4,
) -> crate::Result<Vec<f32>> {
    // The cube root of the volume scale: a uniform scale exactly, the mean of a non-uniform
    // one. Finite (validated transforms), >= 0.
    let scale = glam::Mat3::from_mat4(transform).determinant().abs().cbrt();
    let units = |g: f32| (factor * g * scale).max(0.0);
    let Some(source) = texture else {
        return Ok(vec![units(1.0); mesh.positions.len()]);
    };
    let Some(texels) = sample_at_vertices(mesh, source, "a volume's thickness texture")? else {
        return Err(crate::LucentError::InvalidInput(format!(
            "{}: a procedural texture cannot be a volume's thickness",
            source.describe()
        )));
    };
    Ok(texels
        .into_iter()
        .map(|[_, g, _, _]| {
            // glTF: the thickness is in the green channel, 0-1.
            units(if g.is_finite() {
                g.clamp(0.0, 1.0)
            } else {
                0.0
            })
        })
        .collect())
}

/// `source` sampled bilinearly at each vertex's UV of `mesh`, decoded as stored (its decoded
/// size in memory: no mip or f32 copy is ever needed); `None` for a procedural texture, which
/// has no texels to decode. `what` names the map in the error for a mesh without texture
/// coordinates.
fn sample_at_vertices(
    mesh: &crate::scene::Mesh,
    source: &material::TextureSource,
    what: &str,
) -> crate::Result<Option<Vec<[f32; 4]>>> {
    if mesh.uvs.len() != mesh.positions.len() {
        return Err(crate::LucentError::InvalidInput(format!(
            "{}: {what}: its mesh has no texture coordinates",
            source.describe()
        )));
    }
    let Some(texture) = source.decode(texture::TextureUsage::Data)? else {
        return Ok(None);
    };
    Ok(Some(
        mesh.uvs
            .iter()
            .map(|&uv| texture.sample_bilinear(uv))
            .collect(),
    ))
}

/// Samples each thickness texture into the vertex colours of the meshes drawn with it.
fn sample_thickness_textures(scene: &mut Scene) -> crate::Result<()> {
    let mut done: Vec<(usize, material::TextureSource)> = Vec::new();
    for object in &scene.objects {
        let Some(material::ThicknessSource::Texture(source)) =
            object.material.translucency.as_ref().map(|t| &t.thickness)
        else {
            continue;
        };
        if let material::TextureSource::Procedural(_) = source {
            return Err(crate::LucentError::InvalidInput(format!(
                "material '{}': a procedural texture cannot be a thickness map",
                object.material.name
            )));
        }
        if done.iter().any(|(m, s)| *m == object.mesh && s == source) {
            continue;
        }
        let mesh = &scene.meshes[object.mesh];
        if let Some((m, other)) = done.iter().find(|(m, _)| *m == object.mesh) {
            return Err(crate::LucentError::InvalidInput(format!(
                "mesh {m} is drawn with two thickness textures ({} and {}); give each its own mesh",
                other.describe(),
                source.describe()
            )));
        }
        let what = format!("thickness texture of material '{}'", object.material.name);
        let Some(texels) = sample_at_vertices(mesh, source, &what)? else {
            continue;
        };
        let colors = texels
            .into_iter()
            // Thickness is a fraction of light let through: [0, 1], whatever the file held.
            .map(|[r, g, b, _]| Vec3::new(r, g, b).clamp(Vec3::ZERO, Vec3::ONE))
            .collect();
        scene.meshes[object.mesh].colors = colors;
        done.push((object.mesh, source.clone()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::material::{ThicknessSource, Translucency};
    use crate::scene::{builtin, Material, Mesh, Object, Shape};
    use glam::Mat4;

    fn plane_scene(thickness: ThicknessSource) -> Scene {
        let mut scene = builtin("smoke").unwrap();
        scene.meshes = vec![Mesh::generate(Shape::Plane { half_size: 1.0 }, 4, 1)];
        let mut material = Material::opaque("t", Vec3::splat(0.8), 0.1, 0.5);
        material.translucency = Some(Translucency::new(thickness));
        scene.objects = vec![Object {
            mesh: 0,
            transform: Mat4::IDENTITY,
            material,
        }];
        scene
    }

    #[test]
    fn thickness_textures_are_sampled_into_vertex_colours() {
        let dir = std::env::temp_dir().join(format!("lucent-thickness-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ramp.png");
        // A horizontal ramp: red rises with u, green is constant, blue falls.
        let image = image::RgbImage::from_fn(64, 8, |x, _| {
            let t = (x as f32 + 0.5) / 64.0;
            image::Rgb([(t * 255.0) as u8, 128, ((1.0 - t) * 255.0) as u8])
        });
        image.save(&path).unwrap();
        let mut scene = plane_scene(ThicknessSource::Texture(material::TextureSource::File(
            path.clone(),
        )));
        prepare_thickness(&mut scene, &dir).unwrap();
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.colors.len(), mesh.positions.len());
        for (uv, c) in mesh.uvs.iter().zip(&mesh.colors) {
            // Inside the texture (away from the wrapped edge), bilinear follows the ramp.
            if (0.05..0.95).contains(&uv.x) {
                assert!((c.x - uv.x).abs() < 0.03, "uv {uv} -> {c}");
                assert!((c.z - (1.0 - uv.x)).abs() < 0.03, "uv {uv} -> {c}");
            }
            assert!((c.y - 128.0 / 255.0).abs() < 1e-3);
        }
        // A mesh without UVs cannot take a texture: an error naming the file.
        let mut no_uvs = scene.clone();
        no_uvs.meshes[0].uvs.clear();
        no_uvs.meshes[0].colors.clear();
        let err = prepare_thickness(&mut no_uvs, &dir)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("ramp.png") && err.contains("texture coordinates"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
