//! Property-based fuzzing of the OBJ (+ MTL) loader.
//!
//! OBJ text is generated from a grammar of mostly-valid lines (vertices, texture coordinates,
//! normals, faces with every index form, polylines, groups, materials) whose numbers and indices
//! are sometimes corrupted (NaN, infinity, beyond `f32`, garbage, 0, negative, huge), plus random
//! lines, and then sometimes damaged as bytes (truncated, random bytes inserted, a byte
//! changed, re-encoded as UTF-16). Three in four files start valid (some with a few lines
//! replaced or inserted), so many cases reach tobj and the checks after it; the rest are soups
//! of grammar lines. Files may name `fuzz.mtl`, which is generated the same way (or absent).
//! Each file goes through `load_obj`, which must never panic (nor report that tobj
//! panicked under it), and whose every `Ok` mesh must pass `Mesh::validate` with unit normals,
//! finite values and no degenerate triangles.
//!
//! 256 cases by default (well under a second); more with, for example:
//!
//! ```text
//! PROPTEST_CASES=100000 cargo test --test cpu fuzz_mesh::
//! ```
//!
//! (about 3 minutes on 2 cores). Prefer the default test profile over `--release`: it keeps
//! overflow checks on, and some of tobj's panics (out-of-range negative indices) only happen
//! with them.

use std::path::PathBuf;

use crate::common;
use lucent::scene::obj::load_obj;
use proptest::prelude::*;
use proptest::sample::{select, Index};

/// A float as text: usually ordinary, sometimes something a parser must refuse.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        20 => (-10.0f32..10.0).prop_map(|v| v.to_string()),
        2 => (0i32..4).prop_map(|v| v.to_string()),
        1 => select(vec![
            "nan", "NaN", "inf", "-inf", "infinity", "1e39", "-1e39", "3.4e38", "1e-45", "-0",
            "+2", "abc", "1,5", "0x10", ".", "1e", "--1", "", "#",
        ])
        .prop_map(String::from),
    ]
}

/// A face index as text: usually in range for a small file, sometimes not.
fn index() -> impl Strategy<Value = String> {
    prop_oneof![
        20 => (1i64..=8).prop_map(|i| i.to_string()),
        4 => (-8i64..=-1).prop_map(|i| i.to_string()),
        1 => Just("0".to_string()),
        1 => any::<i64>().prop_map(|i| i.to_string()),
        1 => select(vec!["99999999999999999999999", "1000000000000", "x", "", "-", "1.5", "+1"])
            .prop_map(String::from),
    ]
}

/// One face corner in any of OBJ's forms.
fn corner() -> impl Strategy<Value = String> {
    prop_oneof![
        index(),
        (index(), index()).prop_map(|(v, t)| format!("{v}/{t}")),
        (index(), index(), index()).prop_map(|(v, t, n)| format!("{v}/{t}/{n}")),
        (index(), index()).prop_map(|(v, n)| format!("{v}//{n}")),
        (index(), index(), index(), index()).prop_map(|(a, b, c, d)| format!("{a}/{b}/{c}/{d}")),
    ]
}

fn numbers(
    keyword: &'static str,
    count: impl Into<prop::collection::SizeRange>,
) -> BoxedStrategy<String> {
    prop::collection::vec(number(), count)
        .prop_map(move |v| format!("{keyword} {}", v.join(" ")))
        .boxed()
}

fn obj_line() -> impl Strategy<Value = String> {
    prop_oneof![
        12 => numbers("v", 3),
        1 => numbers("v", 4),
        1 => numbers("v", 6),
        1 => numbers("v", 0..9),
        3 => numbers("vt", 2),
        1 => numbers("vt", 0..5),
        3 => numbers("vn", 3),
        1 => numbers("vn", 0..5),
        10 => prop::collection::vec(corner(), 3..6).prop_map(|c| format!("f {}", c.join(" "))),
        1 => prop::collection::vec(corner(), 0..3).prop_map(|c| format!("f {}", c.join(" "))),
        1 => prop::collection::vec(index(), 0..5).prop_map(|c| format!("l {}", c.join(" "))),
        2 => select(vec![
            "o part", "g", "g a b", "s 1", "usemtl red", "usemtl", "usemtl nothing",
            "mtllib fuzz.mtl", "mtllib", "mtllib\tfuzz.mtl", "mtllib missing.mtl",
            "mtllib fuzz.mtl fuzz.mtl", "# comment", "", "   ", "\u{feff}v 1 2 3", "v 1 2 3 # c",
            "f 1 2 3 # c", "vp 0.5", "\r",
        ])
        .prop_map(String::from),
        1 => "\\PC{0,30}",
    ]
}

fn mtl_line() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => select(vec!["newmtl red", "newmtl", "newmtl wood grain"]).prop_map(String::from),
        6 => (select(vec!["Ka", "Kd", "Ks", "Ke"]), prop::collection::vec(number(), 0..5))
            .prop_map(|(k, v)| format!("{k} {}", v.join(" "))),
        2 => (select(vec!["Ns", "Ni", "d", "illum", "Tr"]), prop::collection::vec(number(), 0..3))
            .prop_map(|(k, v)| format!("{k} {}", v.join(" "))),
        3 => (
            select(vec!["map_Kd", "map_Ka", "map_Bump", "bump", "map_d", "map_Ns", "disp"]),
            select(vec!["tex.png", "missing.png", "-s 1 1 1 tex.png", "-bm", ""]),
        )
            .prop_map(|(k, v)| format!("{k} {v}")),
        1 => "\\PC{0,30}",
    ]
}

/// Damage applied to the file's bytes after it is generated.
#[derive(Clone, Debug)]
enum Damage {
    None,
    Truncate(Index),
    Insert(Index, Vec<u8>),
    Replace(Index, u8),
    Utf16,
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        30 => Just(Damage::None),
        2 => any::<Index>().prop_map(Damage::Truncate),
        1 => (any::<Index>(), prop::collection::vec(any::<u8>(), 1..16))
            .prop_map(|(i, b)| Damage::Insert(i, b)),
        1 => (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Damage::Replace(i, b)),
        1 => Just(Damage::Utf16),
    ]
}

fn apply(text: String, damage: &Damage) -> Vec<u8> {
    let mut bytes = text.into_bytes();
    match damage {
        Damage::None => {}
        Damage::Truncate(i) => {
            let at = i.index(bytes.len() + 1);
            bytes.truncate(at);
        }
        Damage::Insert(i, b) => {
            let at = i.index(bytes.len() + 1);
            bytes.splice(at..at, b.iter().copied());
        }
        Damage::Replace(i, b) => {
            if !bytes.is_empty() {
                let at = i.index(bytes.len());
                bytes[at] = *b;
            }
        }
        Damage::Utf16 => {
            let text = String::from_utf8_lossy(&bytes).into_owned();
            bytes = text.encode_utf16().flat_map(u16::to_le_bytes).collect();
        }
    }
    bytes
}

/// The corners of one face over `n` vertices, each with "relative index" flag: usually distinct
/// vertices, sometimes any (repeats make degenerate triangles, which are dropped).
fn face(n: usize) -> impl Strategy<Value = Vec<(usize, bool)>> {
    prop_oneof![
        3 => (Just((0..n).collect::<Vec<_>>()).prop_shuffle(), 3..6usize, any::<[bool; 6]>())
            .prop_map(|(order, k, relative)| {
                order.into_iter().take(k).zip(relative).collect()
            }),
        1 => prop::collection::vec((0..n, any::<bool>()), 3..6),
    ]
}

/// A valid file: `n` vertices (with colours or not), as many texture coordinates and normals
/// when the corner form uses them, and faces over them with positive or relative indices.
fn valid_obj() -> impl Strategy<Value = Vec<String>> {
    (3usize..10)
        .prop_flat_map(|n| {
            (
                prop::collection::vec(prop::collection::vec(-5.0f32..5.0, 6), n),
                any::<bool>(),
                0usize..4,
                prop::collection::vec(face(n), 1..10),
                any::<bool>(),
            )
        })
        .prop_map(|(vertices, colored, form, faces, mtl)| {
            let n = vertices.len();
            let mut lines = Vec::new();
            if mtl {
                lines.push("mtllib fuzz.mtl".to_string());
                lines.push("usemtl red".to_string());
            }
            for v in &vertices {
                lines.push(if colored {
                    format!(
                        "v {} {} {} {} {} {}",
                        v[0],
                        v[1],
                        v[2],
                        v[3].abs(),
                        v[4].abs(),
                        v[5].abs()
                    )
                } else {
                    format!("v {} {} {}", v[0], v[1], v[2])
                });
            }
            let (uv, normal) = (form & 1 != 0, form & 2 != 0);
            for v in vertices.iter().filter(|_| uv) {
                lines.push(format!("vt {} {}", v[3], v[4]));
            }
            for v in vertices.iter().filter(|_| normal) {
                lines.push(format!("vn {} {} {}", v[5], v[4], v[3]));
            }
            for face in faces {
                let corners: Vec<String> = face
                    .into_iter()
                    .map(|(i, relative)| {
                        // All elements precede the faces: index i is i + 1, or -(n - i).
                        let k = if relative {
                            -((n - i) as i64)
                        } else {
                            i as i64 + 1
                        };
                        match (uv, normal) {
                            (false, false) => format!("{k}"),
                            (true, false) => format!("{k}/{k}"),
                            (false, true) => format!("{k}//{k}"),
                            (true, true) => format!("{k}/{k}/{k}"),
                        }
                    })
                    .collect();
                lines.push(format!("f {}", corners.join(" ")));
            }
            lines
        })
}

/// OBJ lines: a valid file with a few lines replaced by grammar lines, or a soup of grammar
/// lines after a few valid vertices.
fn obj_lines() -> impl Strategy<Value = Vec<String>> {
    prop_oneof![
        3 => (valid_obj(), prop_oneof![
            Just(Vec::new()),
            prop::collection::vec((any::<Index>(), obj_line(), any::<bool>()), 1..3),
        ])
            .prop_map(|(mut lines, edits)| {
                for (at, line, replace) in edits {
                    let i = at.index(lines.len());
                    if replace {
                        lines[i] = line;
                    } else {
                        lines.insert(i, line);
                    }
                }
                lines
            }),
        1 => (
            prop::collection::vec(
                prop::collection::vec(-5.0f32..5.0, 3)
                    .prop_map(|p| format!("v {} {} {}", p[0], p[1], p[2])),
                0..8,
            ),
            prop::collection::vec(obj_line(), 0..24),
        )
            .prop_map(|(mut a, b)| {
                a.extend(b);
                a
            }),
    ]
}

/// MTL lines: a valid material with a few lines replaced, or a soup.
fn mtl_lines() -> impl Strategy<Value = Vec<String>> {
    let valid = vec![
        "newmtl red".to_string(),
        "Ka 0 0 0".to_string(),
        "Kd 0.8 0.1 0.1".to_string(),
        "Ks 0.5 0.5 0.5".to_string(),
        "Ns 32".to_string(),
        "map_Kd tex.png".to_string(),
    ];
    prop_oneof![
        2 => prop::collection::vec((any::<Index>(), mtl_line()), 0..2).prop_map(move |edits| {
            let mut lines = valid.clone();
            for (at, line) in edits {
                let i = at.index(lines.len());
                lines[i] = line;
            }
            lines
        }),
        1 => prop::collection::vec(mtl_line(), 0..8),
    ]
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(256)
}

fn work_dir() -> PathBuf {
    let dir = common::temp_dir("fuzz-mesh");
    // A texture file that exists, for MTL lines naming tex.png.
    std::fs::write(dir.join("tex.png"), b"existence is all that is checked").expect("write");
    dir
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn obj_loader_never_panics_and_accepts_only_valid_meshes(
        lines in obj_lines(),
        obj_damage in damage(),
        mtl in prop::option::weighted(0.8, (mtl_lines(), damage())),
    ) {
        let dir = work_dir();
        let obj_path = dir.join("fuzz.obj");
        let mtl_path = dir.join("fuzz.mtl");
        let text = lines.join("\n");
        std::fs::write(&obj_path, apply(text, &obj_damage)).expect("write obj");
        match &mtl {
            Some((lines, d)) => std::fs::write(&mtl_path, apply(lines.join("\n"), d)).expect("write mtl"),
            None => {
                let _ = std::fs::remove_file(&mtl_path);
            }
        }

        match load_obj(&obj_path) {
            Ok(loaded) => {
                let m = &loaded.mesh;
                prop_assert!(m.validate("fuzz").is_ok(), "{:?}", m.validate("fuzz"));
                prop_assert!(m.triangle_count() > 0);
                for n in &m.normals {
                    prop_assert!((n.length() - 1.0).abs() < 1e-3, "normal {}", n);
                }
                for t in m.indices.chunks_exact(3) {
                    prop_assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "degenerate {:?}", t);
                }
                prop_assert_eq!(m.tangents.len(), m.uvs.len());
                for t in &m.tangents {
                    prop_assert!(t.w.abs() == 1.0 && (t.truncate().length() - 1.0).abs() < 1e-3);
                }
                for material in &loaded.materials {
                    prop_assert!(material.diffuse.is_none_or(|d| d.is_finite()));
                }
            }
            Err(e) => {
                let message = e.to_string();
                prop_assert!(message.contains("fuzz.obj"), "error does not name the file: {}", message);
                prop_assert!(!message.contains("crashed"), "tobj panicked: {}", message);
            }
        }
    }
}
