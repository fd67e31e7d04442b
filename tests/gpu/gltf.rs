//! glTF assets render the frame of their lucent TOML equivalent (within 1/255 per channel,
//! lavapipe, validation on): a sphere whose material is `KHR_materials_volume` +
//! `_volume_scatter` + `_ior` against `[material.medium]`, one with
//! `KHR_materials_diffuse_transmission` against `[material.translucency]`, and a textured,
//! node-transformed two-primitive asset (base colour texture in a GLB buffer view with
//! `KHR_texture_transform`, a normal map in a data URI with `normalTexture.scale`) against
//! OBJ meshes, image files and object transforms. The assets are written here
//! (`tests/common/gltf.rs`); the TOML's numbers are the loaded asset's, printed exactly.

use std::path::Path;

use glam::{Vec2, Vec3};
use lucent::frame::FrameSettings;
use lucent::scene::generators::{generate, Generator};
use lucent::scene::gltf::{lucent_roughness, lucent_specular, volume_medium, GLTF_UNITS_PER_MM};
use lucent::scene::{Mesh, Scene};
use serde_json::json;

use crate::common::{self, max_difference, TestGpu};
use crate::gltf_file::{base64, GltfBuilder};

const W: u32 = 160;
const H: u32 = 120;

fn load(path: &Path) -> Scene {
    lucent::bake::scene::load_scene_baked(&path.to_string_lossy()).unwrap()
}

/// `[x, y, z]` with every f32 printed so that it reads back as the same f32.
fn v3(v: Vec3) -> String {
    format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
}

/// A camera node at `eye` looking down -Z and a point light node, added to scene 0.
fn camera_and_light(b: &mut GltfBuilder, eye: [f32; 3], light: [f32; 3]) {
    let camera = b.push(
        "cameras",
        json!({"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 50.0}}),
    );
    let n = b.push("nodes", json!({"camera": camera, "translation": eye}));
    b.add_root(n);
    b.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
    b.json["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1.0, 0.95, 0.9], "intensity": 20.0, "range": 15.0}
    ]}});
    let n = b.push(
        "nodes",
        json!({"translation": light, "extensions": {"KHR_lights_punctual": {"light": 0}}}),
    );
    b.add_root(n);
}

/// The TOML `[camera]` and `[[light]]` of `scene` (the glTF scene's, loaded).
fn camera_and_light_toml(scene: &Scene) -> String {
    let c = &scene.camera;
    let lucent::scene::LightKind::Point { position, range } = scene.lights[0].kind else {
        panic!("not a point light");
    };
    format!(
        "[camera]\neye = {}\ntarget = {}\nfov_y_degrees = {:?}\nnear = {:?}\nfar = {:?}\n\n\
         [[light]]\ntype = \"point\"\nposition = {}\ncolor = {}\nintensity = {:?}\nrange = {:?}\n\n",
        v3(c.eye),
        v3(c.target),
        c.fov_y_degrees,
        c.near,
        c.far,
        v3(position),
        v3(scene.lights[0].color),
        scene.lights[0].intensity,
        range
    )
}

/// Renders both scenes and checks they are within 1/255; returns the difference.
fn same_frame(test: &TestGpu, gltf: &Scene, toml: &Scene, name: &str) -> u8 {
    let settings = FrameSettings::new(W, H);
    let a = test.render(gltf, settings).display;
    let b = test.render(toml, settings).display;
    let d = max_difference(&a, &b);
    // Not a black frame: the asset is in view and lit.
    assert!(
        a.chunks_exact(4).any(|p| p[0] > 40),
        "{name}: nothing lit in view"
    );
    println!("{name}: glTF vs TOML, largest difference {d}/255");
    assert!(d <= 1, "{name}: glTF and TOML frames differ by {d}/255");
    d
}

/// A UV sphere drawn by one node with material 0, camera and light; returns the builder.
fn sphere_asset(material: serde_json::Value) -> (GltfBuilder, Mesh) {
    let mesh = generate(Generator::UvSphere, 2).unwrap();
    let mut b = GltfBuilder::new();
    b.push("materials", material);
    let primitive = b.primitive(&mesh, Some(0));
    b.mesh_node(vec![primitive], json!({}));
    camera_and_light(&mut b, [0.0, 0.0, 3.2], [-1.5, 2.0, -2.5]);
    (b, mesh)
}

#[test]
fn a_volume_scatter_ior_sphere_renders_as_its_toml_medium() {
    let dir = common::temp_dir("gltf-medium");
    let (color, distance, multiscatter, g, ior) = (
        Vec3::new(0.5, 0.3, 0.2),
        0.004f32,
        Vec3::new(0.9, 0.6, 0.4),
        0.3f32,
        1.4f32,
    );
    let (b, _) = sphere_asset(json!({
        "pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.5},
        "extensions": {
            "KHR_materials_volume": {
                "attenuationColor": color.to_array(), "attenuationDistance": distance,
                "thicknessFactor": 0.5
            },
            "KHR_materials_volume_scatter": {
                "multiscatterColor": multiscatter.to_array(), "scatterAnisotropy": g
            },
            "KHR_materials_ior": {"ior": ior}
        }
    }));
    let glb = dir.join("medium.glb");
    std::fs::write(&glb, b.glb()).unwrap();
    let gltf = load(&glb);
    let medium = volume_medium(
        "m",
        distance,
        color,
        multiscatter,
        g,
        ior,
        GLTF_UNITS_PER_MM,
    )
    .unwrap();
    let layer = &medium.layers[0];
    let toml = format!(
        "{}[[mesh]]\nname = \"ball\"\ngenerator = \"sphere\"\nlevel = 2\n\n\
         [[material]]\nname = \"m\"\nspecular = {:?}\nroughness = {:?}\n\n\
         [material.medium]\nsigma_a = {}\nsigma_s = {}\ng = {:?}\neta = {:?}\n\
         units_per_mm = {:?}\n\n[[object]]\nmesh = \"ball\"\nmaterial = \"m\"\n",
        camera_and_light_toml(&gltf),
        lucent_specular(Vec3::ONE, 0.0, ior),
        lucent_roughness(0.5),
        v3(layer.sigma_a),
        v3(layer.sigma_s),
        layer.g,
        ior,
        GLTF_UNITS_PER_MM
    );
    let toml_path = dir.join("medium.toml");
    std::fs::write(&toml_path, toml).unwrap();
    let toml = load(&toml_path);
    // The same medium, to the bit, before anything is rendered.
    let (a, b) = (&gltf.objects[0].material, &toml.objects[0].material);
    assert_eq!(
        a.layers.as_ref().unwrap().layers,
        b.layers.as_ref().unwrap().layers
    );
    assert_eq!(a.albedo, b.albedo);
    let test = TestGpu::new();
    same_frame(&test, &gltf, &toml, "volume + volume_scatter + ior");
    test.finish();
}

#[test]
fn a_diffuse_transmission_sphere_renders_as_its_toml_translucency() {
    let dir = common::temp_dir("gltf-diffuse-transmission");
    let base = Vec3::new(0.8, 0.7, 0.6);
    let (b, _) = sphere_asset(json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [base.x, base.y, base.z, 1.0],
            "metallicFactor": 0.0, "roughnessFactor": 0.4
        },
        "extensions": {"KHR_materials_diffuse_transmission": {
            "diffuseTransmissionFactor": 0.6,
            "diffuseTransmissionColorFactor": [1.0, 0.5, 0.3]
        }}
    }));
    let glb = dir.join("transmission.glb");
    std::fs::write(&glb, b.glb()).unwrap();
    let gltf = load(&glb);
    let toml = format!(
        "{}[[mesh]]\nname = \"ball\"\ngenerator = \"sphere\"\nlevel = 2\n\n\
         [[material]]\nname = \"m\"\nalbedo = {}\nspecular = {:?}\nroughness = {:?}\n\n\
         [material.translucency]\nthickness = 0.6\ncolor = [1.0, 0.5, 0.3]\n\n\
         [[object]]\nmesh = \"ball\"\nmaterial = \"m\"\n",
        camera_and_light_toml(&gltf),
        v3(base),
        lucent_specular(base, 0.0, 1.5),
        lucent_roughness(0.4)
    );
    let toml_path = dir.join("transmission.toml");
    std::fs::write(&toml_path, toml).unwrap();
    let toml = load(&toml_path);
    assert_eq!(
        gltf.objects[0].material.translucency,
        toml.objects[0].material.translucency
    );
    let test = TestGpu::new();
    same_frame(&test, &gltf, &toml, "diffuse transmission");
    test.finish();
}

/// A `n` x `n`-quad grid in the XY plane facing +Z, `size` wide, centred on `centre`, UVs
/// k/n (exact binary fractions for n a power of two).
fn grid(n: usize, size: f32, centre: Vec3) -> Mesh {
    let mut mesh = Mesh::default();
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            mesh.positions
                .push(centre + Vec3::new((u - 0.5) * size, (0.5 - v) * size, 0.0));
            mesh.normals.push(Vec3::Z);
            mesh.uvs.push(Vec2::new(u, v));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = (j * (n + 1) + i) as u32;
            let (b, c, d) = (a + 1, a + n as u32 + 1, a + n as u32 + 2);
            mesh.indices.extend([a, c, b, b, c, d]);
        }
    }
    mesh
}

/// `mesh` as OBJ text (`v` flipped as OBJ's `vt` points up; exact for binary-fraction UVs).
fn obj(mesh: &Mesh) -> String {
    let mut s = String::new();
    for ((p, n), t) in mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs) {
        s += &format!(
            "v {:?} {:?} {:?}\nvn {:?} {:?} {:?}\nvt {:?} {:?}\n",
            p.x,
            p.y,
            p.z,
            n.x,
            n.y,
            n.z,
            t.x,
            1.0 - t.y
        );
    }
    for f in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [f[0] + 1, f[1] + 1, f[2] + 1];
        s += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\n");
    }
    s
}

/// An 8x8 RGB image as PNG bytes.
fn png(pixel: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let image = image::RgbImage::from_fn(8, 8, |x, y| image::Rgb(pixel(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    image.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

#[test]
fn a_textured_node_transformed_two_primitive_asset_renders_as_its_toml() {
    let dir = common::temp_dir("gltf-textured");
    let checker = png(|x, y| {
        if (x + y) % 2 == 0 {
            [230, 200, 60]
        } else {
            [40, 90, 200]
        }
    });
    // Bumps in x and y: a normal map whose scale shows.
    let normals = png(|x, y| [128 + 10 * (x as u8 % 4), 128 + 9 * (y as u8 % 3), 235]);
    let a = grid(4, 1.0, Vec3::new(-0.6, 0.0, 0.0));
    let b_mesh = grid(4, 1.0, Vec3::new(0.6, 0.0, 0.0));
    let mut builder = GltfBuilder::new();
    let view = builder.view(&checker, None);
    builder.push(
        "images",
        json!({"bufferView": view, "mimeType": "image/png"}),
    );
    builder.push(
        "images",
        json!({"uri": format!("data:image/png;base64,{}", base64(&normals))}),
    );
    builder.push("textures", json!({"source": 0}));
    builder.push("textures", json!({"source": 1}));
    builder.json["extensionsUsed"] = json!(["KHR_texture_transform"]);
    builder.push(
        "materials",
        json!({"pbrMetallicRoughness": {
            "metallicFactor": 0.0, "roughnessFactor": 0.6,
            "baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                "offset": [0.5, 0.25], "scale": [2.0, 2.0]
            }}}
        }}),
    );
    builder.push("materials", json!({
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.7, 0.6, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.3
        },
        "normalTexture": {"index": 1, "scale": 0.5}
    }));
    let pa = builder.primitive(&a, Some(0));
    let pb = builder.primitive(&b_mesh, Some(1));
    let angle = 25f32.to_radians();
    let q = glam::Quat::from_rotation_y(angle);
    let mesh = builder.push("meshes", json!({"primitives": [pa, pb]}));
    let child = builder.push("nodes", json!({"mesh": mesh, "scale": [0.8, 0.8, 0.8]}));
    let parent = builder.push(
        "nodes",
        json!({
            "translation": [0.2, -0.1, 0.0], "rotation": q.to_array(), "children": [child]
        }),
    );
    builder.add_root(parent);
    camera_and_light(&mut builder, [0.0, 0.0, 2.5], [1.0, 1.5, 2.5]);
    let glb = dir.join("textured.glb");
    std::fs::write(&glb, builder.glb()).unwrap();
    let gltf = load(&glb);
    assert_eq!(gltf.objects.len(), 2);

    // The TOML twin: UVs transformed by hand (exact: quarters), the normal map scaled by
    // the library's own scale_normals and written as a PNG, the nodes as one object
    // transform (translate, rotate about y, scale).
    let mut a_twin = a.clone();
    for t in &mut a_twin.uvs {
        *t = Vec2::new(2.0 * t.x + 0.5, 2.0 * t.y + 0.25);
    }
    std::fs::write(dir.join("a.obj"), obj(&a_twin)).unwrap();
    std::fs::write(dir.join("b.obj"), obj(&b_mesh)).unwrap();
    std::fs::write(dir.join("checker.png"), &checker).unwrap();
    let scaled =
        lucent::scene::texture::scale_normals(image::load_from_memory(&normals).unwrap(), 0.5);
    scaled.save(dir.join("normals.png")).unwrap();
    let toml = format!(
        "{}[[mesh]]\nname = \"a\"\nobj = \"a.obj\"\n\n[[mesh]]\nname = \"b\"\nobj = \"b.obj\"\n\n\
         [[material]]\nname = \"checker\"\nalbedo = [1.0, 1.0, 1.0]\nspecular = {:?}\n\
         roughness = {:?}\nalbedo_texture = \"checker.png\"\n\n\
         [[material]]\nname = \"bumpy\"\nalbedo = [0.7, 0.6, 0.5]\nspecular = {:?}\n\
         roughness = {:?}\nnormal_texture = \"normals.png\"\n\n\
         [[object]]\nmesh = \"a\"\nmaterial = \"checker\"\ntranslate = [0.2, -0.1, 0.0]\n\
         rotate_degrees = [0.0, 25.0, 0.0]\nscale = 0.8\n\n\
         [[object]]\nmesh = \"b\"\nmaterial = \"bumpy\"\ntranslate = [0.2, -0.1, 0.0]\n\
         rotate_degrees = [0.0, 25.0, 0.0]\nscale = 0.8\n",
        camera_and_light_toml(&gltf),
        lucent_specular(Vec3::ONE, 0.0, 1.5),
        lucent_roughness(0.6),
        lucent_specular(Vec3::new(0.7, 0.6, 0.5), 0.0, 1.5),
        lucent_roughness(0.3)
    );
    let toml_path = dir.join("textured.toml");
    std::fs::write(&toml_path, toml).unwrap();
    let toml = load(&toml_path);
    for (g, t) in gltf.objects.iter().zip(&toml.objects) {
        let (gm, tm) = (&gltf.meshes[g.mesh], &toml.meshes[t.mesh]);
        // The same UVs (the OBJ loader numbers the vertices in another order).
        let sorted = |m: &Mesh| {
            let mut uvs: Vec<[u32; 2]> = m
                .uvs
                .iter()
                .map(|t| [t.x.to_bits(), t.y.to_bits()])
                .collect();
            uvs.sort_unstable();
            uvs
        };
        assert_eq!(sorted(gm), sorted(tm), "UVs differ");
        assert!(
            g.transform.abs_diff_eq(t.transform, 1e-6),
            "{} vs {}",
            g.transform,
            t.transform
        );
    }
    let test = TestGpu::new();
    same_frame(
        &test,
        &gltf,
        &toml,
        "textured, node-transformed, two primitives",
    );
    test.finish();
}

#[test]
fn a_volumes_thickness_is_the_distance_the_mediums_gdc_2011_term_reads() {
    // KHR_materials_volume's thicknessFactor (mesh units: metres) times its texture's green
    // channel replaces the baked distance in the term derived from the medium: the vertex
    // colours are the medium's transmittance through exactly that distance.
    use lucent::scene::material::ThicknessSource;
    let dir = common::temp_dir("gltf-thickness");
    let volume = |thickness: serde_json::Value| {
        let mut ext = json!({
            "attenuationColor": [0.5, 0.3, 0.2], "attenuationDistance": 0.004,
            "thicknessFactor": 0.003
        });
        if !thickness.is_null() {
            ext["thicknessTexture"] = thickness;
        }
        json!({
            "extensions": {
                "KHR_materials_volume": ext,
                "KHR_materials_volume_scatter": {"multiscatterColor": [0.9, 0.6, 0.4]}
            }
        })
    };
    let check = |scene: &Scene, green: f32| {
        let object = &scene.objects[0];
        let term = &object.material.medium.as_ref().unwrap().translucency;
        assert!(
            matches!(term.thickness, ThicknessSource::Volume { factor, .. } if factor == 0.003),
            "{:?}",
            term.thickness
        );
        // 3 mm (a glTF unit is a metre) times the green channel, the node unscaled.
        let expected = term.extinction.unwrap().transmittance(3.0 * green);
        let colors = &scene.meshes[object.mesh].colors;
        assert_eq!(colors.len(), scene.meshes[object.mesh].positions.len());
        for c in colors {
            assert!(
                (*c - expected).abs().max_element() < 1e-4,
                "{c} vs {expected}"
            );
        }
        expected
    };
    let (b, _) = sphere_asset(volume(serde_json::Value::Null));
    let plain = dir.join("factor.glb");
    std::fs::write(&plain, b.glb()).unwrap();
    let whole = check(&load(&plain), 1.0);

    // A uniform green of 128/255 halves the distance: more light through.
    let (mut b, _) = sphere_asset(volume(json!({"index": 0})));
    let half = png(|_, _| [0, 128, 0]);
    b.push(
        "images",
        json!({"uri": format!("data:image/png;base64,{}", base64(&half))}),
    );
    b.push("textures", json!({"source": 0}));
    let textured = dir.join("texture.glb");
    std::fs::write(&textured, b.glb()).unwrap();
    let halved = check(&load(&textured), 128.0 / 255.0);
    assert!(halved.x > whole.x, "{halved} {whole}");

    // Under a forced `--technique translucency` the frame renders, finite, validation clean.
    let test = TestGpu::new();
    let settings = FrameSettings {
        technique: lucent::frame::Technique::parse("translucency").unwrap(),
        export_hdr: true,
        ..FrameSettings::new(W, H)
    };
    let frame = test.render(&load(&textured), settings);
    assert!(frame.hdr.unwrap().iter().all(|v| v.is_finite()));
    test.finish();
}
