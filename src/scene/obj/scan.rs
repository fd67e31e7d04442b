//! Checking an OBJ file's text line by line before tobj sees it (what tobj would panic on or
//! pass silently), and rewriting it into the text tobj parses.

use std::fmt::Write as _;
use std::str::{FromStr, SplitWhitespace};

use glam::DVec3;

use super::text::quote;
use super::{MAX_TRIANGLES, MAX_VERTICES};
use crate::scene::polygon;

/// What [`scan_obj`] learnt about a file that passed it.
#[derive(Debug, Default)]
pub(super) struct ObjScan {
    pub(super) vertices: usize,
    pub(super) faces: usize,
    pub(super) polylines: usize,
    /// `mtllib` lines: (line number, file name as tobj extracts it).
    pub(super) mtllibs: Vec<(usize, String)>,
    /// Comments after data, polylines or concave polygons: the text tobj gets must be
    /// rewritten.
    pub(super) needs_rewrite: bool,
    /// Every vertex position so far (after dividing by `w`), for triangulating polygons.
    positions: Vec<DVec3>,
    /// Concave polygons, ear-clipped: (line number, triangles as corner numbers of the face).
    /// tobj would fan them; the rewrite writes these triangles instead.
    pub(super) clipped: Vec<(usize, Vec<[usize; 3]>)>,
    /// Lines of polygons that cross themselves (or are too large to ear-clip): partly fanned.
    pub(super) unclean: Vec<usize>,
}

/// The tokens of a data line after its keyword, up to a `#` comment.
pub(super) fn data_tokens<'a>(words: impl Iterator<Item = &'a str>) -> (Vec<&'a str>, bool) {
    let mut out = Vec::new();
    for w in words {
        if w.starts_with('#') {
            return (out, true);
        }
        out.push(w);
    }
    (out, false)
}

/// Parses a finite `f32`; `what` names the quantity in the error.
pub(super) fn finite(token: &str, line: usize, what: &str) -> std::result::Result<f32, String> {
    let v = f32::from_str(token)
        .map_err(|_| format!("line {line}: {} is not a number ({what})", quote(token)))?;
    // NaN and infinity parse ("nan", "inf", or a value beyond f32 like 1e39) but would reach
    // the GPU; tobj passes them through silently.
    if !v.is_finite() {
        return Err(format!(
            "line {line}: {what} is not finite ({}); NaN and infinity are not allowed",
            quote(token)
        ));
    }
    Ok(v)
}

/// Which face-corner attribute an index refers to.
#[derive(Clone, Copy)]
enum Attr {
    Position,
    Texcoord,
    Normal,
}

impl Attr {
    fn plural(self) -> &'static str {
        match self {
            Attr::Position => "vertices",
            Attr::Texcoord => "texture coordinates",
            Attr::Normal => "normals",
        }
    }
}

/// Checks an OBJ face index against the `count` elements defined so far; tobj resolves the
/// same way (positive: 1-based; negative: relative to the count so far) but does not check:
/// 0 and out-of-range negatives wrap to huge `usize`s that overflow (a panic in debug builds).
fn check_index(
    part: &str,
    count: usize,
    attr: Attr,
    line: usize,
) -> std::result::Result<(), String> {
    let index = isize::from_str(part).map_err(|_| {
        format!(
            "line {line}: face index {} is not an integer in range",
            quote(part)
        )
    })?;
    let kind = attr.plural();
    if index == 0 {
        return Err(format!(
            "line {line}: face index 0 is invalid (OBJ indices start at 1)"
        ));
    }
    if index < 0 && index.unsigned_abs() > count {
        return Err(format!(
            "line {line}: relative face index {index} points before the first of the {count} \
             {kind} defined so far"
        ));
    }
    if index > 0 && index.unsigned_abs() > count {
        return Err(format!(
            "line {line}: face index {index} is out of range: only {count} {kind} are defined \
             before this line"
        ));
    }
    Ok(())
}

/// The state of [`scan_obj`] while it reads a file: what it learnt so far, the counts that
/// face indices are checked against, and the first lines that show each side of an
/// all-or-none rule.
#[derive(Default)]
struct Scanner {
    scan: ObjScan,
    texcoords: usize,
    normals: usize,
    triangles: usize,
    /// First line of a vertex with a colour.
    colored: Option<usize>,
    /// First line of a vertex without one.
    plain: Option<usize>,
    /// First line of a face corner with a texture coordinate.
    with_uv: Option<usize>,
    /// First line of a face corner without one.
    without_uv: Option<usize>,
}

/// Checks every line of an OBJ file for what tobj would panic on or pass silently.
pub(super) fn scan_obj(text: &str) -> std::result::Result<ObjScan, String> {
    let mut s = Scanner::default();
    for (i, raw) in text.lines().enumerate() {
        let ln = i + 1;
        let mut words = raw.split_whitespace();
        let Some(key) = words.next() else {
            continue;
        };
        match key {
            "v" => s.vertex(words, ln)?,
            "vt" => s.texcoord(words, ln)?,
            "vn" => s.normal(words, ln)?,
            "f" => s.face(words, ln)?,
            "l" => {
                s.scan.polylines += 1;
                s.scan.needs_rewrite = true;
            }
            "mtllib" | "usemtl" => s.library(key, raw, ln)?,
            _ => {}
        }
    }
    Ok(s.scan)
}

impl Scanner {
    /// The tokens of a data line after its keyword; a `#` comment after them means the text
    /// tobj gets must be rewritten.
    fn data<'a>(&mut self, words: SplitWhitespace<'a>) -> Vec<&'a str> {
        let (tokens, comment) = data_tokens(words);
        self.scan.needs_rewrite |= comment;
        tokens
    }

    /// A `v` line: 3, 4 (with `w`) or 6 (with a colour) finite numbers.
    fn vertex(&mut self, words: SplitWhitespace<'_>, ln: usize) -> std::result::Result<(), String> {
        let nums = self.data(words);
        let n = nums.len();
        if n < 3 {
            return Err(format!(
                "line {ln}: vertex position needs 3 numbers (x y z), found {n}"
            ));
        }
        if n != 3 && n != 4 && n != 6 {
            return Err(format!(
                "line {ln}: vertex has {n} numbers; expected 3 (x y z), 4 (x y z w) or \
                 6 (x y z r g b)"
            ));
        }
        let mut p = [0.0f32; 3];
        for (k, t) in nums[..3].iter().enumerate() {
            p[k] = finite(t, ln, "vertex position")?;
        }
        let mut w = 1.0;
        if n == 4 {
            w = finite(nums[3], ln, "vertex weight w")?;
            if w == 0.0 {
                return Err(format!("line {ln}: vertex weight w is 0"));
            }
            // tobj divides x, y, z by w: a tiny w can overflow to infinity.
            if p.iter().any(|c| !(c / w).is_finite()) {
                return Err(format!(
                    "line {ln}: vertex position divided by w = {w} is not finite"
                ));
            }
        }
        self.scan
            .positions
            .push(DVec3::new(p[0].into(), p[1].into(), p[2].into()) / f64::from(w));
        if n == 6 {
            for t in &nums[3..] {
                finite(t, ln, "vertex colour")?;
            }
            self.colored.get_or_insert(ln);
        } else {
            self.plain.get_or_insert(ln);
        }
        // tobj keeps one colour array for all vertices: if only some have colours, the
        // colours land on the wrong vertices.
        if let (Some(c), Some(p)) = (self.colored, self.plain) {
            let (has, lacks) = if ln == c { (c, p) } else { (c, ln) };
            return Err(format!(
                "line {ln}: vertex colours must be on every vertex or none (line {has} \
                 has one, line {lacks} has none)"
            ));
        }
        self.scan.vertices += 1;
        if self.scan.vertices > MAX_VERTICES {
            return Err(format!(
                "line {ln}: more than {MAX_VERTICES} vertices; refusing an absurd count"
            ));
        }
        Ok(())
    }

    /// A `vt` line: 2 or 3 finite numbers.
    fn texcoord(
        &mut self,
        words: SplitWhitespace<'_>,
        ln: usize,
    ) -> std::result::Result<(), String> {
        let nums = self.data(words);
        let n = nums.len();
        if n < 2 {
            return Err(format!(
                "line {ln}: texture coordinate needs 2 numbers (u v), found {n}"
            ));
        }
        if n > 3 {
            return Err(format!(
                "line {ln}: texture coordinate has {n} numbers; expected 2 (u v) or 3 \
                 (u v w)"
            ));
        }
        for t in &nums {
            finite(t, ln, "texture coordinate")?;
        }
        self.texcoords += 1;
        if self.texcoords > MAX_VERTICES {
            return Err(format!(
                "line {ln}: more than {MAX_VERTICES} texture coordinates; refusing an \
                 absurd count"
            ));
        }
        Ok(())
    }

    /// A `vn` line: 3 finite numbers.
    fn normal(&mut self, words: SplitWhitespace<'_>, ln: usize) -> std::result::Result<(), String> {
        let nums = self.data(words);
        let n = nums.len();
        if n != 3 {
            return Err(format!(
                "line {ln}: normal needs 3 numbers (x y z), found {n}"
            ));
        }
        for t in &nums {
            finite(t, ln, "normal")?;
        }
        self.normals += 1;
        if self.normals > MAX_VERTICES {
            return Err(format!(
                "line {ln}: more than {MAX_VERTICES} normals; refusing an absurd count"
            ));
        }
        Ok(())
    }

    /// An `f` line: at least 3 corners, each with indices in range; a polygon is triangulated
    /// here to find out whether it is concave (ear-clipped) or crosses itself.
    fn face(&mut self, words: SplitWhitespace<'_>, ln: usize) -> std::result::Result<(), String> {
        let corners = self.data(words);
        let n = corners.len();
        if n < 3 {
            return Err(format!(
                "line {ln}: face has {n} vertices; a face needs at least 3"
            ));
        }
        for corner in &corners {
            self.face_corner(corner, ln)?;
        }
        if n > 3 {
            self.polygon(&corners, ln);
        }
        self.scan.faces += 1;
        self.triangles = self.triangles.saturating_add(n - 2);
        if self.triangles > MAX_TRIANGLES {
            return Err(format!(
                "line {ln}: more than {MAX_TRIANGLES} triangles; refusing an absurd count"
            ));
        }
        Ok(())
    }

    /// One `v/vt/vn` corner of a face on line `ln`.
    fn face_corner(&mut self, corner: &str, ln: usize) -> std::result::Result<(), String> {
        let parts: Vec<&str> = corner.split('/').collect();
        if parts.len() > 3 {
            return Err(format!(
                "line {ln}: face corner {} has more than 3 parts (v/vt/vn)",
                quote(corner)
            ));
        }
        if parts[0].is_empty() {
            return Err(format!(
                "line {ln}: face corner {} has no vertex index",
                quote(corner)
            ));
        }
        check_index(parts[0], self.scan.vertices, Attr::Position, ln)?;
        let uv = parts.get(1).filter(|p| !p.is_empty());
        if let Some(p) = uv {
            check_index(p, self.texcoords, Attr::Texcoord, ln)?;
            self.with_uv.get_or_insert(ln);
        } else {
            self.without_uv.get_or_insert(ln);
        }
        if let Some(p) = parts.get(2).filter(|p| !p.is_empty()) {
            check_index(p, self.normals, Attr::Normal, ln)?;
        }
        // Corners without texcoords leave tobj's texcoord array shorter than the
        // positions (a "short texcoord array"): UVs would land on the wrong vertices.
        if let (Some(has), Some(lacks)) = (self.with_uv, self.without_uv) {
            return Err(format!(
                "line {ln}: texture coordinates must be on every face corner or none \
                 (line {has} has one, line {lacks} has a corner without)"
            ));
        }
        Ok(())
    }

    /// Triangulates the polygon of more than 3 `corners` on line `ln` (every index already
    /// checked), recording it when it is concave or not clean.
    fn polygon(&mut self, corners: &[&str], ln: usize) {
        let positions = &self.scan.positions;
        let corners: Vec<DVec3> = corners
            .iter()
            .map(|c| {
                let i = c.split('/').next().and_then(|t| isize::from_str(t).ok());
                let i = i.unwrap_or(1);
                let at = if i > 0 {
                    i.unsigned_abs() - 1
                } else {
                    positions.len() - i.unsigned_abs()
                };
                positions[at]
            })
            .collect();
        let t = polygon::triangulate(&corners);
        if !t.clean {
            self.scan.unclean.push(ln);
        }
        if !t.convex {
            self.scan.clipped.push((ln, t.triangles));
            self.scan.needs_rewrite = true;
        }
    }

    /// An `mtllib` or `usemtl` line (`key`): it must name something.
    fn library(&mut self, key: &str, raw: &str, ln: usize) -> std::result::Result<(), String> {
        // Extracted exactly as tobj does (the rest after the first space, trimmed).
        let name = raw.split_once(' ').map_or("", |(_, rest)| rest.trim());
        if name.is_empty() {
            let what = if key == "mtllib" {
                "file (separate it with a space)"
            } else {
                "material"
            };
            return Err(format!("line {ln}: {key} names no {what}"));
        }
        if key == "mtllib" {
            self.scan.mtllibs.push((ln, name.to_string()));
        }
        Ok(())
    }
}

/// The text tobj parses: polylines blanked (tobj would read `l 1 2 3` as a triangle),
/// trailing `#` comments cut from data lines (tobj rejects them), and each concave polygon of
/// `clipped` (line number, triangles as corner numbers) written as its triangles, one `f` line
/// each with the face's own corner tokens (no `v` line moves, so relative indices still hold).
/// tobj reports no line numbers; ours come from the original text.
pub(super) fn rewrite_for_tobj(text: &str, clipped: &[(usize, Vec<[usize; 3]>)]) -> String {
    let mut out = String::with_capacity(text.len());
    let mut clipped = clipped.iter().peekable();
    for (i, line) in text.lines().enumerate() {
        let key = line.split_whitespace().next().unwrap_or("");
        match key {
            "l" => {}
            "v" | "vt" | "vn" | "f" => {
                let cut = line
                    .match_indices('#')
                    .map(|(i, _)| i)
                    .find(|&i| line[..i].ends_with(char::is_whitespace))
                    .unwrap_or(line.len());
                let data = &line[..cut];
                match clipped.peek() {
                    Some((ln, triangles)) if *ln == i + 1 => {
                        let corners: Vec<&str> = data.split_whitespace().skip(1).collect();
                        for t in triangles {
                            let _ = writeln!(
                                out,
                                "f {} {} {}",
                                corners[t[0]], corners[t[1]], corners[t[2]]
                            );
                        }
                        clipped.next();
                        continue;
                    }
                    _ => out.push_str(data),
                }
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    out
}
#[cfg(test)]
mod tests {
    use super::super::tests::{err, load_str, QUAD};
    use super::*;
    use crate::scene::Mesh;

    /// Total area of a loaded mesh's triangles.
    fn mesh_area(mesh: &Mesh) -> f64 {
        mesh.indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[t[k] as usize].as_dvec3());
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    #[test]
    fn concave_polygons_are_ear_clipped_to_their_true_area_and_reported() {
        // A U (area 7 of its 3x3 box) as one face.
        let u = "v 0 0 0\nv 3 0 0\nv 3 3 0\nv 2 3 0\nv 2 1 0\nv 1 1 0\nv 1 3 0\nv 0 3 0\n\
                 f 1 2 3 4 5 6 7 8 # the U\n";
        let o = load_str("u", u).unwrap();
        assert_eq!(o.mesh.triangle_count(), 6);
        assert!(
            (mesh_area(&o.mesh) - 7.0).abs() < 1e-5,
            "{}",
            mesh_area(&o.mesh)
        );
        assert!(
            o.repairs.iter().any(|r| r.contains(
                "triangulated 1 concave polygon(s) by ear \
                 clipping (line 9)"
            )),
            "{:?}",
            o.repairs
        );
        // A ring (radii 2 and 1, 16 segments) as one face bridged from the outside in, with
        // relative indices, UVs and normals: it keeps its hole.
        let n = 16;
        let mut text = String::new();
        for r in [2.0f64, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                let _ = writeln!(text, "v {} {} 0", r * a.cos(), r * a.sin());
                let _ = writeln!(text, "vt {} {}", a.cos() * 0.5 + 0.5, a.sin() * 0.5 + 0.5);
            }
        }
        text.push_str("vn 0 0 1\nf");
        let corner = |v: usize| format!(" {}/{}/1", v as isize - 2 * n as isize, v + 1);
        let mut face: Vec<usize> = (0..n).collect();
        face.push(0);
        face.push(n);
        face.extend((n + 1..2 * n).rev());
        face.push(n);
        for v in face {
            text.push_str(&corner(v));
        }
        text.push('\n');
        let o = load_str("ring", &text).unwrap();
        let want = 3.0 * 8.0 * (std::f64::consts::TAU / 16.0).sin();
        assert!(
            (mesh_area(&o.mesh) - want).abs() < 1e-4,
            "{} vs {want}",
            mesh_area(&o.mesh)
        );
        // Every triangle faces +z like the face (winding kept), none covers the centre.
        for t in o.mesh.indices.chunks_exact(3) {
            let [a, b, c] = [0, 1, 2].map(|k| o.mesh.positions[t[k] as usize]);
            assert!((b - a).cross(c - a).z > 0.0);
            let centroid = (a + b + c) / 3.0;
            assert!(
                centroid.length() > 0.9,
                "a triangle inside the hole: {centroid}"
            );
        }
        assert!(
            o.repairs.iter().any(|r| r.contains("ear clipping")),
            "{:?}",
            o.repairs
        );
        // A convex quad is not a repair.
        assert!(load_str("quad2", &format!("{QUAD}f 1 2 3 4\n"))
            .unwrap()
            .repairs
            .is_empty());
    }

    #[test]
    fn errors_name_line_and_problem() {
        let cases = [
            ("zero", format!("{QUAD}f 0 1 2\n"), "line 5: face index 0"),
            ("big", format!("{QUAD}f 1 2 1000000000000\n"), "line 5"),
            (
                "neg",
                format!("{QUAD}f -5 1 2\n"),
                "points before the first",
            ),
            (
                "nan",
                "v 0 0 0\nv nan 0 0\n".into(),
                "line 2: vertex position is not finite",
            ),
            ("inf", "v 0 0 1e39\n".into(), "not finite"),
            (
                "vt",
                format!("{QUAD}vt 0.5\n"),
                "line 5: texture coordinate needs 2",
            ),
            ("vtnan", format!("{QUAD}vt 0.5 NaN\n"), "not finite"),
            (
                "two",
                format!("{QUAD}f 1 2\n"),
                "line 5: face has 2 vertices",
            ),
            (
                "trunc",
                "v 1 2 3\nv 1.0 2".into(),
                "line 2: vertex position needs 3",
            ),
            ("empty", "\n  \n# nothing\n".into(), "empty"),
            ("nofaces", QUAD.into(), "no faces"),
            (
                "mixuv",
                format!("{QUAD}vt 0 0\nf 1/1 2/1 3/1\nf 1 3 4\n"),
                "line 7",
            ),
            ("five", "v 1 2 3 4 5\n".into(), "expected 3"),
            ("w0", "v 1 2 3 0\n".into(), "w is 0"),
            ("tab", "mtllib\tx.mtl\n".into(), "mtllib names no file"),
            (
                "color",
                "v 0 0 0 1 1 1\nv 1 0 0\n".into(),
                "line 2: vertex colours",
            ),
            (
                "parts",
                format!("{QUAD}f 1/1/1/1 2 3\n"),
                "more than 3 parts",
            ),
            (
                "huge",
                format!("{QUAD}f 1 2 99999999999999999999999\n"),
                "not an integer",
            ),
        ];
        for (name, text, want) in cases {
            let e = err(name, &text);
            assert!(e.contains(want), "{name}: {e}");
        }
    }
}
