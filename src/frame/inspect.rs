//! `lucent inspect FILE`: load any input lucent reads, with every check it would get in a real
//! run (a scene's technique names resolved by the registry too), and summarise it, or fail with
//! the error a render would fail with.
//!
//! Use it to find out whether an asset is usable before building a scene around it. The file
//! type is chosen by extension (case-insensitive):
//!
//! | extension | loaded with | summary |
//! |---|---|---|
//! | `.obj` | [`load_obj`] | vertices, triangles, attributes, bounds, materials, repairs |
//! | `.mtl` | [`load_mtl`] | materials with their colours and textures |
//! | `.png` `.jpg` `.jpeg` `.tga` `.exr` `.hdr` | [`decode_texture`] (as data, no sRGB decode) | size, mips, value range |
//! | `.toml` | [`load_scene_file`] | meshes, objects, lights, camera |

use std::fmt::Write as _;
use std::path::Path;

use glam::Vec3;

use crate::scene::file::load_scene_file;
use crate::scene::obj::{load_mtl, load_obj, ObjMaterial};
use crate::scene::texture::{decode_texture, host_bytes, mip_levels, TextureUsage};
use crate::scene::upload::level_bytes;
use crate::{LucentError, Result};
use rayon::prelude::*;

/// Extensions [`inspect_file`] understands.
pub const SUPPORTED_EXTENSIONS: &[&str] = &[
    "obj", "mtl", "png", "jpg", "jpeg", "tga", "exr", "hdr", "toml",
];

/// Loads `path` the way lucent would use it and returns a multi-line human-readable summary;
/// any problem is the same error a render would report (naming the file and the problem).
pub fn inspect_file(path: &Path) -> Result<String> {
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    // Writing to a String cannot fail; the fmt::Results below are ignored.
    let mut s = String::new();
    match ext.as_str() {
        "obj" => {
            let o = load_obj(path)?;
            let m = &o.mesh;
            let yes = |b: bool| if b { "yes" } else { "no" };
            let _ = writeln!(s, "{}: Wavefront OBJ", path.display());
            let _ = writeln!(s, "  vertices:  {}", m.vertex_count());
            let _ = writeln!(s, "  triangles: {}", m.triangle_count());
            let _ = writeln!(
                s,
                "  normals: yes, uvs: {}, tangents: {}, vertex colours: {}",
                yes(!m.uvs.is_empty()),
                yes(!m.tangents.is_empty()),
                yes(!m.colors.is_empty())
            );
            let (lo, hi) = m.positions.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), p| (lo.min(*p), hi.max(*p)),
            );
            let _ = writeln!(s, "  bounds: {lo} .. {hi}");
            write_materials(&mut s, &o.materials);
            if o.repairs.is_empty() {
                let _ = writeln!(s, "  repairs: none");
            } else {
                let _ = writeln!(s, "  repairs:");
                for r in &o.repairs {
                    let _ = writeln!(s, "    - {r}");
                }
            }
        }
        "mtl" => {
            let (materials, notes) = load_mtl(path)?;
            let _ = writeln!(s, "{}: MTL material library", path.display());
            write_materials(&mut s, &materials);
            for n in &notes {
                let _ = writeln!(s, "  note: {n}");
            }
        }
        "png" | "jpg" | "jpeg" | "tga" | "exr" | "hdr" => {
            // Summarised as stored (its decoded size in memory); the mips a render would make
            // are only counted.
            let t = decode_texture(path, TextureUsage::Data)?;
            let w = t.width as usize;
            let (lo, hi) = (0..w * t.height as usize)
                .into_par_iter()
                .map(|i| {
                    let texel = t.texel(i % w, i / w);
                    (texel, texel)
                })
                .reduce(
                    || ([f32::INFINITY; 4], [f32::NEG_INFINITY; 4]),
                    |(lo, hi), (l, h)| {
                        (
                            std::array::from_fn(|c| lo[c].min(l[c])),
                            std::array::from_fn(|c| hi[c].max(h[c])),
                        )
                    },
                );
            let _ = writeln!(s, "{}: {} image", path.display(), ext.to_uppercase());
            let _ = writeln!(s, "  size: {}x{}", t.width, t.height);
            let _ = writeln!(s, "  mip levels: {}", mip_levels(t.width, t.height));
            let layout = t.upload_layout();
            let gpu: u64 = level_bytes(t.width, t.height, layout).iter().sum();
            let _ = writeln!(
                s,
                "  on the GPU ({layout:?} with mips): {}, about twice that in host memory while \
                 loading",
                crate::error::format_bytes(gpu)
            );
            let _ = writeln!(
                s,
                "  host memory where the CPU computes with it (RGBA f32 with mips): {}",
                crate::error::format_bytes(host_bytes(t.width, t.height).unwrap_or(u64::MAX))
            );
            let _ = writeln!(s, "  value range (RGBA, as stored): {lo:?} .. {hi:?}");
        }
        "toml" => {
            let scene = load_scene_file(path)?;
            // Every technique the materials name must be registered, as a frame checks.
            crate::features::registry::check_names(&scene)?;
            let triangles: usize = scene.meshes.iter().map(|m| m.triangle_count()).sum();
            let _ = writeln!(s, "{}: scene '{}'", path.display(), scene.name);
            let _ = writeln!(
                s,
                "  meshes: {} ({triangles} triangles)",
                scene.meshes.len()
            );
            let _ = writeln!(s, "  objects: {}", scene.objects.len());
            write_scene_materials(&mut s, &scene);
            let _ = writeln!(s, "  lights: {}", scene.lights.len());
            let _ = writeln!(s, "  environment: {}", scene.environment.describe());
            if matches!(
                scene.environment.kind,
                crate::scene::environment::EnvironmentKind::Map { .. }
            ) {
                // What the nine coefficients cost in accuracy for this map.
                let (max, mean) = scene.environment.max_error(200);
                let _ = writeln!(
                    s,
                    "  environment SH9 error against the exact integral: max {:.2}%, mean {:.2}% of the mean irradiance",
                    100.0 * max,
                    100.0 * mean
                );
            }
            let _ = writeln!(
                s,
                "  camera: eye {} target {} fov {} deg",
                scene.camera.eye, scene.camera.target, scene.camera.fov_y_degrees
            );
        }
        _ => {
            let shown = if ext.is_empty() {
                "no extension".to_string()
            } else {
                format!("extension '.{ext}'")
            };
            return Err(LucentError::file(
                path,
                format!(
                    "unsupported file type ({shown}); inspect understands .{}",
                    SUPPORTED_EXTENSIONS.join(", .")
                ),
            ));
        }
    }
    Ok(s)
}

/// What GDC 2011's term takes from a medium (`derived`, [`crate::scene::material::Medium`]'s)
/// and what the material's own `[material.translucency]` (`written`) keeps.
fn gdc_from_medium(
    written: Option<&crate::scene::material::Translucency>,
    derived: &crate::scene::material::Translucency,
) -> String {
    let Some(e) = derived.extinction else {
        return String::new();
    };
    let per_mm = e.transmittance(1.0);
    let through: Vec<String> = [1.0f32, 4.0, 16.0]
        .iter()
        .map(|&mm| {
            let t = e.transmittance(mm) * derived.color;
            format!("{mm} mm {:.3} / {:.3} / {:.3}", t.x, t.y, t.z)
        })
        .collect();
    let lobe = |t: &crate::scene::material::Translucency| {
        format!(
            "power {}, distortion {}, ambient {}, gain {:?}",
            t.power,
            t.distortion,
            t.ambient,
            t.color.to_array()
        )
    };
    let whose = match written {
        None => "under a forced --technique translucency".to_string(),
        Some(w) if w.extinction.is_some() => {
            format!("its [material.translucency] over it: {}", lobe(w))
        }
        Some(w) => format!(
            "not used: its [material.translucency] writes an artistic thickness ({})",
            lobe(w)
        ),
    };
    format!(
        "GDC 2011 translucency from it ({whose}): sigma_tr {:?} mm^-1 (attenuation {:.3} / \
         {:.3} / {:.3} per mm), thickness = the baked distance in mm, {}; colour through {}",
        e.sigma_tr.to_array(),
        per_mm.x,
        per_mm.y,
        per_mm.z,
        lobe(derived),
        through.join(", ")
    )
}

/// Appends one line per material the scene's objects use, with the parts that decide what a
/// frame of the scene shades under `--technique auto`.
fn write_scene_materials(s: &mut String, scene: &crate::scene::Scene) {
    let mut seen: Vec<&str> = Vec::new();
    for o in &scene.objects {
        let m = &o.material;
        if seen.contains(&m.name.as_str()) {
            continue;
        }
        seen.push(&m.name);
        let mut parts: Vec<String> = Vec::new();
        if let Some(t) = &m.albedo_texture {
            parts.push(format!("albedo texture {}", texture_name(t)));
        }
        if let Some(t) = &m.normal_texture {
            parts.push(format!("normal map {}", texture_name(t)));
        }
        if m.translucency.is_some() {
            parts.push("translucency".into());
        }
        if let Some(p) = &m.sss {
            parts.push(format!(
                "SSS profile {} ({} Gaussians, {} units/mm, blur {})",
                p.name,
                p.gaussians.len(),
                p.units_per_mm,
                crate::features::registry::blur_of(p).map_or("?", |b| b.name())
            ));
        }
        if let Some(l) = &m.layers {
            let textured = l.layers.iter().any(|x| {
                matches!(
                    x.thickness,
                    crate::scene::layered::Thickness::Texture { .. }
                )
            });
            parts.push(format!(
                "layered {} ({} layer{}{})",
                l.name,
                l.layers.len(),
                if l.layers.len() == 1 { "" } else { "s" },
                if textured {
                    "; thickness from depth textures (TexDep), read per pixel at the shaded \
                     point and at the light's entry point"
                } else {
                    ""
                }
            ));
        }
        if let Some(
            whole @ crate::scene::material::Medium {
                layered: medium,
                profile,
                fit_error: errors,
                translucency: derived,
                ..
            },
        ) = &m.medium
        {
            // What each technique took from the medium, and what the material wrote itself.
            let (albedo, rd) = (whole.albedo, medium.total_diffuse_reflectance());
            let layer = &medium.layers[0];
            parts.push(format!(
                "medium {} (sigma_a {:?}, sigma_s {:?} mm^-1, g {}, eta {}, {} units/mm): albedo \
                 {}, layered {}",
                medium.name,
                layer.sigma_a.to_array(),
                layer.sigma_s.to_array(),
                layer.g,
                medium.eta,
                medium.units_per_mm,
                if m.albedo == albedo {
                    format!(
                        "{:?} = its white-sky albedo (the dipole's R_d: {:?})",
                        albedo.to_array(),
                        rd.to_array()
                    )
                } else {
                    format!(
                        "written (its white-sky albedo would be {:?})",
                        albedo.to_array()
                    )
                },
                if m.layers.as_ref() == Some(medium) {
                    "= the medium, one semi-infinite layer"
                } else if m.layers.is_some() {
                    "written ([material.layered])"
                } else {
                    "none (the material names another technique)"
                }
            ));
            if m.sss.is_none() {
                // What a forced screen-space technique (`--technique separable`, ...) blurs with.
                let burley = match profile.burley {
                    Some(crate::scene::material::BurleyDistance::MeanFreePath { mfp, .. }) => {
                        format!(", Burley: mean free path {:?} mm", mfp.to_array())
                    }
                    _ => String::new(),
                };
                parts.push(format!(
                    "under a forced SSS technique: {} Gaussians fitted to its dipole (relative \
                     L2 error {:.3} / {:.3} / {:.3}){burley}",
                    profile.gaussians.len(),
                    errors[0],
                    errors[1],
                    errors[2]
                ));
            }
            // What a screen-space technique transmits through thickness (times the albedo).
            let t = crate::features::sss::transmission::SssTransmission::of(whole);
            let through: Vec<String> = [1.0, 4.0, 16.0]
                .iter()
                .map(|mm| {
                    let [r, g, b] = t.transmittance(mm * f64::from(medium.units_per_mm));
                    format!("{mm} mm {r:.3} / {g:.3} / {b:.3}")
                })
                .collect();
            parts.push(format!(
                "screen-space transmission through thickness (x albedo): {}",
                through.join(", ")
            ));
            parts.push(gdc_from_medium(m.translucency.as_ref(), derived));
        }
        let layer_lines = m.layers.as_ref().map(layered_lines).unwrap_or_default();
        let parts = if parts.is_empty() {
            "opaque".to_string()
        } else {
            parts.join(", ")
        };
        let _ = writeln!(s, "  material {}: {parts}", m.name);
        s.push_str(&layer_lines);
    }
}

/// A layered medium's numbers, one indented line for the medium and one per layer.
fn layered_lines(l: &crate::scene::layered::LayeredMedium) -> String {
    use crate::scene::layered::Thickness;
    let mut s = String::new();
    let w = l.weights;
    let _ = writeln!(
        s,
        "    eta {}, weights (diffuse, specular, transmitted, single, multiple) {} {} {} {} {}, \
         {} units/mm",
        l.eta, w[0], w[1], w[2], w[3], w[4], l.units_per_mm
    );
    // What the passes make of it (docs/layered.md, "The boundary and the energy").
    let split = l.albedo_split();
    let v = |x: glam::Vec3| format!("{:.3} / {:.3} / {:.3}", x.x, x.y, x.z);
    let _ = writeln!(
        s,
        "    the boundary lets in {:.3} of a white sky; single scattering carries {} of it, \
         multiple scattering the dipole's profile scaled to {} (the white-sky albedo less single \
         scattering, over c^2)",
        split.diffuse_transmittance,
        v(split.single),
        v(split.multiple_scale)
    );
    for (i, layer) in l.layers.iter().enumerate() {
        let thickness = match layer.thickness {
            Thickness::Mm(t) => format!("{t} mm"),
            Thickness::Rest => "rest (semi-infinite)".into(),
            Thickness::Texture { scale } => format!(
                "texture {} channel {} x {scale} mm",
                l.depth_textures
                    .get(i / 4)
                    .map_or_else(|| "?".into(), texture_name),
                ["r", "g", "b", "a"][i % 4]
            ),
        };
        let v = |v: glam::Vec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
        let _ = writeln!(
            s,
            "    layer {i}: thickness {thickness}, sigma_a {} /mm, sigma_s {} /mm, g {}",
            v(layer.sigma_a),
            v(layer.sigma_s),
            layer.g
        );
    }
    s
}

fn texture_name(t: &crate::scene::material::TextureSource) -> String {
    t.describe()
}

/// Appends one line per material.
fn write_materials(s: &mut String, materials: &[ObjMaterial]) {
    let _ = writeln!(s, "  materials: {}", materials.len());
    for m in materials {
        let _ = write!(s, "    - {}", m.name);
        if let Some(kd) = m.diffuse {
            let _ = write!(s, ", Kd {kd}");
        }
        if let Some(t) = &m.diffuse_texture {
            let _ = write!(s, ", map_Kd {}", t.display());
        }
        if let Some(t) = &m.normal_texture {
            let _ = write!(s, ", normal map {}", t.display());
        }
        s.push('\n');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summarises_an_obj_and_refuses_unknown_extensions() {
        let dir = std::env::temp_dir().join(format!("lucent-inspect-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let obj = dir.join("tri.OBJ");
        std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        let s = inspect_file(&obj).unwrap();
        assert!(
            s.contains("triangles: 1") && s.contains("repairs: none"),
            "{s}"
        );
        let e = inspect_file(&dir.join("points.xyz"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("points.xyz") && e.contains("unsupported file type"),
            "{e}"
        );
        let e = inspect_file(&dir.join("README")).unwrap_err().to_string();
        assert!(e.contains("no extension"), "{e}");
        std::fs::remove_dir_all(dir).ok();
    }

    #[test]
    fn layered_materials_print_every_layer() {
        let scene = crate::scene::builtin("layered").unwrap();
        let mut s = String::new();
        write_scene_materials(&mut s, &scene);
        assert!(
            s.contains("material teapot: layered skin1 (1 layer)")
                && s.contains("eta 1.3, weights (diffuse, specular, transmitted, single, multiple) 0 1 1 1 1, 0.04 units/mm")
                && s.contains("layer 0: thickness rest (semi-infinite), sigma_a [0.032, 0.17, 0.48] /mm, sigma_s [0.74, 0.88, 1.01] /mm, g 0"),
            "{s}"
        );
        let mut m = crate::scene::Material::opaque("skin", glam::Vec3::ONE, 0.5, 0.5);
        m.layers = Some(crate::scene::layered::LayeredMedium::preset("skin-layered").unwrap());
        let s = layered_lines(m.layers.as_ref().unwrap());
        assert!(
            s.contains("layer 0: thickness 0.25 mm") && s.contains("layer 1: thickness rest"),
            "{s}"
        );
        assert!(s.contains("g 0.9") && s.contains("g 0.8"), "{s}");
        // The albedo split the passes use: skin1 at eta 1 lets in all of a white sky, and
        // single scattering carries 0.2046 omega of it (omega 0.959 in red).
        let skin1 = crate::scene::layered::LayeredMedium::homogeneous(
            "skin1",
            glam::Vec3::new(0.74, 0.88, 1.01),
            glam::Vec3::new(0.032, 0.17, 0.48),
            0.0,
            1.0,
        );
        let s = layered_lines(&skin1);
        assert!(
            s.contains("the boundary lets in 1.000 of a white sky; single scattering carries 0.196 /"),
            "{s}"
        );
    }
}
