//! `lucent bake-thickness`: a local thickness map baked from a mesh (GDC 2011: ambient
//! occlusion with inverted normals), as a texture and/or as vertex colours.

use lucent::{scene, LucentError, Result};

use crate::cli::BakeThicknessArgs;

/// Bakes `args.mesh` into `--out` (texture) and/or `--per-vertex` (OBJ with colours).
pub fn run(args: BakeThicknessArgs) -> Result<()> {
    let BakeThicknessArgs {
        mesh: mesh_path,
        out,
        per_vertex,
        rays,
        size,
        max_distance,
        distances,
        seed,
    } = args;
    if out.is_none() && per_vertex.is_none() {
        return Err(LucentError::InvalidInput(
            "bake-thickness needs --out FILE.png and/or --per-vertex OUT.obj".into(),
        ));
    }
    // --rays, --size and --max-distance were range-checked by their parsers.
    let outputs: Vec<(&str, &std::path::Path)> = [("--out", &out), ("--per-vertex", &per_vertex)]
        .into_iter()
        .filter_map(|(flag, p)| p.as_deref().map(|p| (flag, p)))
        .collect();
    lucent::files::check_outputs(&[("the input mesh", mesh_path.as_path())], &outputs)?;
    let loaded = scene::obj::load_obj(&mesh_path)?;
    let options = lucent::bake::BakeOptions {
        rays,
        max_distance,
        seed,
        texture_size: size,
        progress: true,
        measure: if distances {
            lucent::bake::BakeMeasure::Distance
        } else {
            lucent::bake::BakeMeasure::Occlusion
        },
    };
    if let Some(out) = &out {
        let (map, stats) = lucent::bake::bake_texture(&loaded.mesh, &options)?;
        let covered: Vec<f32> = (map.values.iter().zip(&map.coverage))
            .filter_map(|(&v, &c)| c.then_some(v))
            .collect();
        if let Some(warning) = lucent::bake::constant_warning(&covered, &stats) {
            eprintln!("lucent: warning: {warning}");
        }
        map.write_png(out)?;
        println!("{}", lucent::bake::bake_report(&stats));
        println!(
            "wrote {} ({size}x{size}; the UVs cover {} texels, {:.1}%)",
            out.display(),
            covered.len(),
            100.0 * covered.len() as f64 / f64::from(size).powi(2)
        );
    }
    if let Some(per_vertex) = &per_vertex {
        let (values, stats) = lucent::bake::bake_per_vertex(&loaded.mesh, &options)?;
        if let Some(warning) = lucent::bake::constant_warning(&values, &stats) {
            eprintln!("lucent: warning: {warning}");
        }
        let colors: Vec<glam::Vec3> = values.iter().map(|&v| glam::Vec3::splat(v)).collect();
        scene::obj::write_obj_with_colors(per_vertex, &loaded.mesh, &colors)?;
        println!("{}", lucent::bake::bake_report(&stats));
        println!("wrote {} ({} vertices)", per_vertex.display(), values.len());
    }
    Ok(())
}
