//! Procedural meshes: UV sphere, icosphere, cube, torus, plane and the Utah teapot, each at a
//! tessellation level or at a target triangle count.
//!
//! Use [`generate`] for a mesh at a quality *level* (what scene files and built-in scenes ask
//! for), and [`generate_with_triangles`] when the triangle count itself is the point (the
//! scaling tables, e.g. Li et al.'s 2,900 to 1,084,450 triangles). [`triangle_count`] and
//! [`triangle_count_at_resolution`] give exact counts without generating anything.
//!
//! # Levels and resolutions
//!
//! Each generator has one integer *resolution* that sets its tessellation (table below). A
//! *level* is a coarse quality step mapped onto it, level 0 being the coarsest sensible mesh:
//!
//! | generator | resolution `r` | level `L` gives | triangles |
//! |---|---|---|---|
//! | `sphere` | rings pole to pole (segments = 2 r), r >= 2 | r = 6 (L + 1) | 4 r (r - 1) |
//! | `icosphere` | segments per icosahedron edge, r >= 1 | r = 2^L (L subdivisions) | 20 r² |
//! | `cube` | quads along each face edge, r >= 1 | r = L + 1 | 12 r² |
//! | `torus` | segments around the tube (around the ring: 3 r), r >= 3 | r = 6 (L + 1) | 6 r² |
//! | `plane` | quads along each edge, r >= 3 | r = L + 3 | 2 r² |
//! | `teapot` | nu + nv, the grid of each of the 32 patches, r >= 4 | r = 4 (L + 1) | 64 nu nv - 8 nv |
//!
//! For the teapot nu = ⌊r / 2⌋ and nv = r - nu; the 8 lid and bottom patches have a pole where
//! one edge collapses to a point, and the nv triangles of each that would have zero area there
//! are dropped. (A 1 x 1 grid is not offered: the four corners of each spout-tip patch lie on
//! one line, so its two triangles would have zero area.) At level 4, for example: sphere 3,480, icosphere 5,120, cube 300, torus 5,400,
//! plane 98, teapot 6,320 triangles. The plane starts at 3 x 3 quads because [`Mesh::generate`],
//! which makes it, never splits a plane into fewer.
//!
//! [`generate_with_triangles`] searches the resolution (not the level), so it lands close to
//! any target. Over every target from 2,900 to 1,100,000 the count it picks is within 2.6 %
//! (plane), 3.8 % (sphere), 4.5 % (torus), 6.1 % (cube), 6.8 % (teapot) and 8.0 % (icosphere)
//! of the target, the worst cases all falling between 2,900 and 4,000 triangles. The error
//! shrinks as the target grows, roughly as 1 / sqrt(target / k) with k the constant in the
//! triangle column; at 1M every generator is within 0.4 %. For Li et al.'s largest row,
//! 1,084,450, the teapot gets 1,080,560 triangles (resolution 260, -0.36 %).
//! `tests/cpu/generators.rs` checks these bounds. Nothing above [`MAX_TRIANGLES`] is generated.
//!
//! # What every mesh has
//!
//! Object space, y up, counter-clockwise triangles facing outwards, unit normals (analytic:
//! from the surface, not from the triangles), UVs in [0, 1], tangents (xyz unit and
//! perpendicular to the normal, w = ±1 so that the bitangent `w * normal x tangent` points along
//! increasing v), no zero-area triangles, no unreferenced vertices, and it passes
//! [`Mesh::validate`]. Sizes:
//!
//! - **sphere**, **icosphere**: radius 1 at the origin; `shape` is `Sphere { radius: 1 }`. The
//!   icosphere's vertices lie on that sphere and its flat faces fall just inside it.
//! - **cube**: half-extent 1 (from -1 to 1 on each axis), volume 8. Each face has its own
//!   vertices (hard edges).
//! - **torus**: around the y axis, major radius 1, minor (tube) radius 0.35.
//! - **plane**: the square from -1 to 1 in x and z at y = 0, facing +y; `shape` is
//!   `Plane { half_size: 1 }` (exact, so the CPU reference can use it).
//! - **teapot**: Newell's 32 Bézier patches (see `teapot_data.rs`), rotated to y up and scaled
//!   by 1.5 / 3.15 so it is 1.5 tall, **sitting on y = 0** (bottom at y = 0, knob top at
//!   y = 1.5), its body's axis on the y axis, the spout towards +x, the handle towards -x. From
//!   about -1.43 to 1.64 in x and -0.95 to 0.95 in z.
//!
//! Meshes other than the spheres and the plane have `shape: None`.
//!
//! # UV layouts
//!
//! Every layout is a unique atlas (no two triangles share texture space), so a thickness map
//! can be baked into it.
//!
//! - sphere, torus: u around the y axis, v along the meridian (sphere: v = 0 at the north
//!   pole) or around the tube. The seam vertices are duplicated.
//! - icosphere: spherical coordinates like the sphere. Triangles that straddle the seam at
//!   u = 0 get duplicated vertices with u continued past 1, and each triangle at a pole gets
//!   its own pole vertex with u between its other two. All u are then divided by the largest u,
//!   so they fit [0, 1]. That largest u is 1.1 at every level: the five triangles around the
//!   south pole are always 72 degrees wide and one of them reaches 36 degrees past the seam.
//!   So u = longitude / (2π · 1.1): an equirectangular texture lands squeezed by 10 % in u, and
//!   no triangle smears the whole texture across the seam.
//! - cube: a 3 x 2 grid of square cells, each 1/3 wide (+x, -x, +y in the top row; -y, +z, -z
//!   below; v from 0 to 2/3), each face inset by 1/32 of its cell as a gutter for dilation, and
//!   upright on the side faces (v grows downwards, like image rows).
//! - teapot: a 6 x 6 grid of square cells, one per patch in table order (4 cells empty), each
//!   inset by 1/32 of its cell. Within a cell, u runs around the teapot (the patch's v
//!   parameter) and v runs from top to bottom (its u parameter).
//! - plane: u along x, v along z (from [`Mesh::generate`]).
//!
//! # Teapot details
//!
//! Normals are the cross product of the patch's partial derivatives. Where that vanishes (the
//! lid's knob top and the bottom's centre, where a whole patch edge is one point), the normal
//! and tangent come from the derivatives a small step (1e-4 in parameter space) inside the
//! patch, which converge to the true limit normal there (the y axis). The result is never NaN.
//! Patches are **not welded**: each keeps its own vertices so it can have its own UV cell
//! and its own analytic normals where patches meet at a crease (the spout and handle joints).
//! Along shared edges the positions are equal (the same control points evaluated the same
//! way). Newell's teapot is not closed: the lid does not touch the body, the spout is open at
//! its tip, and the handle and spout end inside the body. Its signed volume is still positive.

use std::collections::HashMap;
use std::f64::consts::{PI, TAU};
use std::fmt;
use std::str::FromStr;

use glam::{DVec3, Vec2, Vec3, Vec4};

use super::mesh::{Mesh, Shape};
use crate::{LucentError, Result};

#[path = "teapot_data.rs"]
mod teapot_data;

/// The most triangles any generator produces; larger levels, resolutions and targets are
/// refused with [`LucentError::InvalidInput`] before anything is allocated.
pub const MAX_TRIANGLES: u64 = 20_000_000;

/// Gutter around each chart in the cube and teapot atlases, as a fraction of its cell's side.
const ATLAS_GUTTER: f32 = 1.0 / 32.0;

/// Torus major radius (centre of the tube to the y axis).
const TORUS_MAJOR: f64 = 1.0;
/// Torus minor radius (radius of the tube).
const TORUS_MINOR: f64 = 0.35;

/// Height of the generated teapot (the patch data is 3.15 tall).
const TEAPOT_HEIGHT: f64 = 1.5;

/// Resolutions searched by [`generate_with_triangles`] never exceed this (every generator is far
/// past [`MAX_TRIANGLES`] here).
const MAX_SEARCH_RESOLUTION: u64 = 1 << 16;

/// A procedural mesh generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Generator {
    /// Latitude-longitude sphere, radius 1 (name `sphere`, also `uv-sphere`).
    UvSphere,
    /// Subdivided icosahedron projected onto the unit sphere (name `icosphere`).
    Icosphere,
    /// Axis-aligned cube from -1 to 1 with hard edges (name `cube`).
    Cube,
    /// Torus around the y axis, major radius 1, minor radius 0.35 (name `torus`).
    Torus,
    /// Square from -1 to 1 in x and z, facing +y (name `plane`).
    Plane,
    /// Newell's Utah teapot, 1.5 tall, sitting on y = 0 (name `teapot`).
    Teapot,
}

impl Generator {
    /// Every generator, in the order scene documentation lists them.
    pub const ALL: &'static [Generator] = &[
        Generator::UvSphere,
        Generator::Icosphere,
        Generator::Cube,
        Generator::Torus,
        Generator::Plane,
        Generator::Teapot,
    ];

    /// The generator called `name`: `sphere` (or `uv-sphere`), `icosphere`, `cube`, `torus`,
    /// `plane` or `teapot`, ignoring ASCII case and surrounding spaces. Any other name is
    /// [`LucentError::InvalidInput`] listing the valid ones.
    pub fn parse(name: &str) -> Result<Self> {
        let wanted = name.trim().to_ascii_lowercase();
        if wanted == "uv-sphere" {
            return Ok(Generator::UvSphere);
        }
        Generator::ALL
            .iter()
            .copied()
            .find(|g| g.name() == wanted)
            .ok_or_else(|| {
                LucentError::InvalidInput(format!(
                    "unknown mesh generator '{name}'; valid generators: {}",
                    Generator::ALL
                        .iter()
                        .map(|g| match g {
                            Generator::UvSphere => "sphere (or uv-sphere)",
                            other => other.name(),
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })
    }

    /// The canonical name ([`Generator::parse`] accepts it).
    pub fn name(self) -> &'static str {
        match self {
            Generator::UvSphere => "sphere",
            Generator::Icosphere => "icosphere",
            Generator::Cube => "cube",
            Generator::Torus => "torus",
            Generator::Plane => "plane",
            Generator::Teapot => "teapot",
        }
    }

    /// The smallest resolution this generator accepts (see the [module docs](self)).
    pub fn min_resolution(self) -> u32 {
        match self {
            Generator::UvSphere => 2,
            Generator::Torus => 3,
            Generator::Teapot => 4,
            Generator::Plane => 3,
            Generator::Icosphere | Generator::Cube => 1,
        }
    }

    /// The resolution that tessellation `level` stands for (see the [module docs](self));
    /// saturates at `u64::MAX` for absurd levels.
    pub fn resolution(self, level: u32) -> u64 {
        let steps = u64::from(level) + 1;
        match self {
            Generator::UvSphere | Generator::Torus => 6 * steps,
            Generator::Icosphere => 1u64.checked_shl(level).unwrap_or(u64::MAX),
            Generator::Cube => steps,
            Generator::Plane => steps + 2,
            Generator::Teapot => 4 * steps,
        }
    }
}

impl fmt::Display for Generator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Generator {
    type Err = LucentError;

    fn from_str(s: &str) -> Result<Self> {
        Generator::parse(s)
    }
}

/// The exact number of triangles [`generate`] makes for `generator` at `level`, without making
/// them. Saturates at `u64::MAX` for absurd levels.
pub fn triangle_count(generator: Generator, level: u32) -> u64 {
    triangle_count_at_resolution(generator, generator.resolution(level))
}

/// The exact number of triangles [`generate_at_resolution`] makes, without making them; 0 below
/// [`Generator::min_resolution`], saturating at `u64::MAX`.
pub fn triangle_count_at_resolution(generator: Generator, resolution: u64) -> u64 {
    if resolution < u64::from(generator.min_resolution()) {
        return 0;
    }
    // In u128 a square of any u64 fits; the constant factors saturate.
    let r = u128::from(resolution);
    let square = r * r;
    let count = match generator {
        Generator::UvSphere => (r * (r - 1)).saturating_mul(4),
        Generator::Icosphere => square.saturating_mul(20),
        Generator::Cube => square.saturating_mul(12),
        Generator::Torus => square.saturating_mul(6),
        Generator::Plane => square.saturating_mul(2),
        Generator::Teapot => {
            let (nu, nv) = teapot_grid(resolution);
            let (nu, nv) = (u128::from(nu), u128::from(nv));
            teapot_collapsed_edges().iter().fold(0u128, |count, edges| {
                // One triangle per quad along each collapsed edge has zero area and is dropped.
                let dropped: u128 = (0..4)
                    .filter(|&e| edges[e])
                    .map(|e| if e < 2 { nv } else { nu })
                    .sum();
                count.saturating_add((nu * nv).saturating_mul(2) - dropped)
            })
        }
    };
    u64::try_from(count).unwrap_or(u64::MAX)
}

/// `generator`'s mesh at tessellation `level` (0 = coarsest sensible; see the
/// [module docs](self) for what each level means and the sizes).
///
/// Levels whose mesh would exceed [`MAX_TRIANGLES`] are [`LucentError::InvalidInput`].
pub fn generate(generator: Generator, level: u32) -> Result<Mesh> {
    let triangles = triangle_count(generator, level);
    if triangles > MAX_TRIANGLES {
        return Err(LucentError::InvalidInput(format!(
            "{generator} level {level} would have {triangles} triangles, more than the limit of \
             {MAX_TRIANGLES}"
        )));
    }
    generate_at_resolution(generator, generator.resolution(level) as u32)
}

/// `generator`'s mesh at `resolution` (the per-generator parameter in the
/// [module docs](self)); finer-grained than [`generate`]'s levels.
///
/// Resolutions below [`Generator::min_resolution`] or above [`MAX_TRIANGLES`] triangles are
/// [`LucentError::InvalidInput`].
pub fn generate_at_resolution(generator: Generator, resolution: u32) -> Result<Mesh> {
    let min = generator.min_resolution();
    if resolution < min {
        return Err(LucentError::InvalidInput(format!(
            "{generator} resolution {resolution} is below its minimum of {min}"
        )));
    }
    let triangles = triangle_count_at_resolution(generator, u64::from(resolution));
    if triangles > MAX_TRIANGLES {
        return Err(LucentError::InvalidInput(format!(
            "{generator} resolution {resolution} would have {triangles} triangles, more than \
             the limit of {MAX_TRIANGLES}"
        )));
    }
    let mut mesh = match generator {
        Generator::UvSphere => uv_sphere(resolution),
        Generator::Icosphere => icosphere(resolution),
        Generator::Cube => cube(resolution),
        Generator::Torus => torus(resolution),
        Generator::Plane => plane(resolution),
        Generator::Teapot => teapot(resolution),
    };
    compact(&mut mesh);
    debug_assert_eq!(mesh.triangle_count() as u64, triangles);
    mesh.validate(generator.name())?;
    Ok(mesh)
}

/// The resolution whose triangle count is closest to `target` (ties go to the smaller mesh),
/// as [`generate_with_triangles`] picks it, without generating anything.
///
/// A `target` of 0 or above [`MAX_TRIANGLES`] is [`LucentError::InvalidInput`].
pub fn resolution_for_triangles(generator: Generator, target: u64) -> Result<u32> {
    if target == 0 || target > MAX_TRIANGLES {
        return Err(LucentError::InvalidInput(format!(
            "target of {target} triangles for {generator} is out of range (1 to {MAX_TRIANGLES})"
        )));
    }
    let count = |r: u64| triangle_count_at_resolution(generator, r);
    // Smallest resolution with at least `target` triangles (counts grow with the resolution).
    let (mut lo, mut hi) = (u64::from(generator.min_resolution()), MAX_SEARCH_RESOLUTION);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if count(mid) >= target {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let above = lo;
    let mut best = above;
    if above > u64::from(generator.min_resolution()) {
        let below = above - 1;
        if count(above) > MAX_TRIANGLES || target - count(below) <= count(above) - target {
            best = below;
        }
    }
    Ok(best as u32)
}

/// `generator`'s mesh with the triangle count closest to `target`, and the **resolution** it
/// was generated at (the parameter in the [module docs](self), not a level: levels are too
/// coarse to land near an arbitrary count).
///
/// Reaches any target from 1 to [`MAX_TRIANGLES`]; the module docs give how close it gets
/// (within 8 % from 2,900 triangles up for every generator, within 0.4 % at 1M). A `target` of 0 or above
/// [`MAX_TRIANGLES`] is [`LucentError::InvalidInput`], refused before anything is allocated.
pub fn generate_with_triangles(generator: Generator, target: u64) -> Result<(Mesh, u32)> {
    let resolution = resolution_for_triangles(generator, target)?;
    Ok((generate_at_resolution(generator, resolution)?, resolution))
}

/// Tangent (xyz unit, perpendicular to `n`) with handedness w = ±1, from the derivatives of the
/// position along the texture's u and v (only their directions matter).
fn tangent(n: Vec3, dpdu: Vec3, dpdv: Vec3) -> Vec4 {
    let t = (dpdu - n * n.dot(dpdu))
        .try_normalize()
        .or_else(|| (dpdv - n * n.dot(dpdv)).cross(n).try_normalize())
        .unwrap_or_else(|| n.any_orthonormal_vector());
    let w = if n.cross(t).dot(dpdv) < 0.0 {
        -1.0
    } else {
        1.0
    };
    t.extend(w)
}

/// Drops vertices no triangle references (pole vertices left over by dropped or re-pointed
/// triangles), keeping the order of the rest.
fn compact(mesh: &mut Mesh) {
    let n = mesh.positions.len();
    let mut used = vec![false; n];
    for &i in &mesh.indices {
        used[i as usize] = true;
    }
    if used.iter().all(|&u| u) {
        return;
    }
    let mut remap = vec![u32::MAX; n];
    let mut next = 0u32;
    for (v, &u) in used.iter().enumerate() {
        if u {
            remap[v] = next;
            next += 1;
        }
    }
    fn keep<T: Copy>(v: &mut Vec<T>, used: &[bool]) {
        if !v.is_empty() {
            let mut k = used.iter();
            v.retain(|_| *k.next().unwrap_or(&false));
        }
    }
    keep(&mut mesh.positions, &used);
    keep(&mut mesh.normals, &used);
    keep(&mut mesh.uvs, &used);
    keep(&mut mesh.tangents, &used);
    keep(&mut mesh.colors, &used);
    for i in &mut mesh.indices {
        *i = remap[*i as usize];
    }
}

/// Derivatives of the unit-sphere point at longitude `phi` and colatitude `theta` along phi and
/// theta (the first has length 1, not sin theta, so it stays defined at the poles).
fn sphere_derivatives(phi: f32, theta: f32) -> (Vec3, Vec3) {
    (
        Vec3::new(-phi.sin(), 0.0, phi.cos()),
        Vec3::new(
            theta.cos() * phi.cos(),
            -theta.sin(),
            theta.cos() * phi.sin(),
        ),
    )
}

/// UV sphere: [`Mesh::generate`] with `rings` rings and 2 `rings` segments, plus tangents.
fn uv_sphere(rings: u32) -> Mesh {
    let mut mesh = Mesh::generate(Shape::Sphere { radius: 1.0 }, 2 * rings, rings);
    mesh.tangents = mesh
        .normals
        .iter()
        .zip(&mesh.uvs)
        .map(|(&n, uv)| {
            let (dpdu, dpdv) =
                sphere_derivatives(std::f32::consts::TAU * uv.x, std::f32::consts::PI * uv.y);
            tangent(n, dpdu, dpdv)
        })
        .collect();
    mesh
}

/// Icosphere: each icosahedron edge split into `frequency` segments, each face into
/// `frequency`² triangles, every vertex projected onto the unit sphere.
fn icosphere(frequency: u32) -> Mesh {
    let nu = frequency;
    // Icosahedron with vertices at the poles: 0 = north, 1 = south, then an upper ring of 5 at
    // longitudes 0, 72, ... and a lower ring of 5 halfway between.
    let mut base = vec![DVec3::Y, DVec3::NEG_Y];
    let (ring_y, ring_r) = (1.0 / 5f64.sqrt(), 2.0 / 5f64.sqrt());
    for k in 0..5 {
        let phi = TAU * k as f64 / 5.0;
        base.push(DVec3::new(ring_r * phi.cos(), ring_y, ring_r * phi.sin()));
    }
    for k in 0..5 {
        let phi = TAU * (k as f64 + 0.5) / 5.0;
        base.push(DVec3::new(ring_r * phi.cos(), -ring_y, ring_r * phi.sin()));
    }
    let upper = |k: u32| 2 + k % 5;
    let lower = |k: u32| 7 + k % 5;
    let mut faces = Vec::with_capacity(20);
    for k in 0..5 {
        faces.push([0, upper(k), upper(k + 1)]);
        faces.push([upper(k), lower(k), upper(k + 1)]);
        faces.push([upper(k + 1), lower(k), lower(k + 1)]);
        faces.push([1, lower(k), lower(k + 1)]);
    }
    for f in &mut faces {
        let [a, b, c] = f.map(|i| base[i as usize]);
        if (b - a).cross(c - a).dot(a + b + c) < 0.0 {
            f.swap(1, 2);
        }
    }

    // Shared vertices: corners are the base vertices, edge vertices are keyed by their edge
    // (low index, high index, steps from the low end) so both faces compute them identically.
    let mut positions: Vec<DVec3> = base.clone();
    let mut edge_vertices: HashMap<(u32, u32, u32), u32> = HashMap::new();
    let mut on_edge = |p: u32, q: u32, t: u32, positions: &mut Vec<DVec3>| -> u32 {
        if t == 0 {
            return p;
        }
        if t == nu {
            return q;
        }
        let key = if p < q { (p, q, t) } else { (q, p, nu - t) };
        *edge_vertices.entry(key).or_insert_with(|| {
            let (lo, hi, k) = key;
            let f = k as f64 / nu as f64;
            positions.push((base[lo as usize] * (1.0 - f) + base[hi as usize] * f).normalize());
            positions.len() as u32 - 1
        })
    };
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(20 * (nu * nu) as usize);
    for &[a, b, c] in &faces {
        // grid[i][j]: the point a + i/nu (b - a) + j/nu (c - a), for i + j <= nu.
        let mut grid: Vec<Vec<u32>> = Vec::with_capacity(nu as usize + 1);
        for i in 0..=nu {
            let mut row = Vec::with_capacity((nu - i) as usize + 1);
            for j in 0..=nu - i {
                let index = if j == 0 {
                    on_edge(a, b, i, &mut positions)
                } else if i == 0 {
                    on_edge(a, c, j, &mut positions)
                } else if i + j == nu {
                    on_edge(b, c, j, &mut positions)
                } else {
                    let (fa, fb, fc) = ((nu - i - j) as f64, i as f64, j as f64);
                    let p = base[a as usize] * fa + base[b as usize] * fb + base[c as usize] * fc;
                    positions.push(p.normalize());
                    positions.len() as u32 - 1
                };
                row.push(index);
            }
            grid.push(row);
        }
        for i in 0..nu as usize {
            for j in 0..nu as usize - i {
                triangles.push([grid[i][j], grid[i + 1][j], grid[i][j + 1]]);
                if i + j + 1 < nu as usize {
                    triangles.push([grid[i + 1][j], grid[i + 1][j + 1], grid[i][j + 1]]);
                }
            }
        }
    }

    // Spherical UVs with the seam and the poles split (module docs).
    let longitude = |p: DVec3| (p.z.atan2(p.x).rem_euclid(TAU) / TAU).clamp(0.0, 1.0);
    let mut u: Vec<f64> = positions.iter().map(|&p| longitude(p)).collect();
    let mut wrapped: HashMap<u32, u32> = HashMap::new();
    let is_pole = |i: u32| i < 2;
    for tri in &mut triangles {
        let us: Vec<f64> = tri
            .iter()
            .filter(|&&i| !is_pole(i))
            .map(|&i| u[i as usize])
            .collect();
        let span =
            us.iter().cloned().fold(f64::MIN, f64::max) - us.iter().cloned().fold(1.0, f64::min);
        if span > 0.5 {
            for i in tri.iter_mut().filter(|i| !is_pole(**i)) {
                let old = *i as usize;
                if u[old] < 0.5 {
                    *i = *wrapped.entry(*i).or_insert_with(|| {
                        positions.push(positions[old]);
                        u.push(u[old] + 1.0);
                        positions.len() as u32 - 1
                    });
                }
            }
        }
        if let Some(k) = tri.iter().position(|&i| is_pole(i)) {
            let others: f64 = (0..3).filter(|&m| m != k).map(|m| u[tri[m] as usize]).sum();
            positions.push(positions[tri[k] as usize]);
            u.push(others / 2.0);
            tri[k] = positions.len() as u32 - 1;
        }
    }
    let u_max = u.iter().cloned().fold(1.0, f64::max);
    let mut mesh = Mesh {
        shape: Some(Shape::Sphere { radius: 1.0 }),
        ..Mesh::default()
    };
    for (&p, &pu) in positions.iter().zip(&u) {
        let theta = p.y.clamp(-1.0, 1.0).acos();
        let n = p.as_vec3();
        let (dpdu, dpdv) = sphere_derivatives((TAU * pu) as f32, theta as f32);
        mesh.positions.push(n);
        mesh.normals.push(n);
        mesh.uvs
            .push(Vec2::new((pu / u_max) as f32, (theta / PI) as f32));
        mesh.tangents.push(tangent(n, dpdu, dpdv));
    }
    mesh.indices = triangles.into_iter().flatten().collect();
    mesh
}

/// Where chart `cell` of a `columns`-wide grid of square cells of side `1 / columns` maps the
/// chart coordinates `st` in [0, 1]², inset by [`ATLAS_GUTTER`].
fn atlas(columns: u32, cell: u32, st: Vec2) -> Vec2 {
    let side = 1.0 / columns as f32;
    let origin = Vec2::new((cell % columns) as f32, (cell / columns) as f32) * side;
    origin + Vec2::splat(side * ATLAS_GUTTER) + st * side * (1.0 - 2.0 * ATLAS_GUTTER)
}

/// Cube from -1 to 1, each face an `n` x `n` grid of quads with its own vertices.
fn cube(n: u32) -> Mesh {
    // (normal, a, b) with a x b = normal: faces are counter-clockwise in (a, b).
    let faces = [
        (Vec3::X, Vec3::NEG_Z, Vec3::Y),
        (Vec3::NEG_X, Vec3::Z, Vec3::Y),
        (Vec3::Y, Vec3::X, Vec3::NEG_Z),
        (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        (Vec3::Z, Vec3::X, Vec3::Y),
        (Vec3::NEG_Z, Vec3::NEG_X, Vec3::Y),
    ];
    let mut mesh = Mesh::default();
    let stride = n + 1;
    for (f, &(normal, a, b)) in faces.iter().enumerate() {
        let first = mesh.positions.len() as u32;
        // uv.x grows along a, uv.y against b (images are stored top row first).
        let frame = tangent(normal, a, -b);
        for t in 0..=n {
            for s in 0..=n {
                let (fs, ft) = (s as f32 / n as f32, t as f32 / n as f32);
                mesh.positions
                    .push(normal + a * (2.0 * fs - 1.0) + b * (2.0 * ft - 1.0));
                mesh.normals.push(normal);
                mesh.uvs.push(atlas(3, f as u32, Vec2::new(fs, 1.0 - ft)));
                mesh.tangents.push(frame);
            }
        }
        for t in 0..n {
            for s in 0..n {
                let p00 = first + t * stride + s;
                let (p10, p01, p11) = (p00 + 1, p00 + stride, p00 + stride + 1);
                mesh.indices
                    .extend_from_slice(&[p00, p10, p11, p00, p11, p01]);
            }
        }
    }
    mesh
}

/// Torus around the y axis: `minor` segments around the tube, 3 `minor` around the ring.
fn torus(minor: u32) -> Mesh {
    let major = 3 * minor;
    let mut mesh = Mesh::default();
    for i in 0..=major {
        let phi = TAU * i as f64 / major as f64;
        for j in 0..=minor {
            let theta = TAU * j as f64 / minor as f64;
            let n = DVec3::new(
                theta.cos() * phi.cos(),
                theta.sin(),
                theta.cos() * phi.sin(),
            );
            let centre = DVec3::new(phi.cos(), 0.0, phi.sin()) * TORUS_MAJOR;
            let dpdu = DVec3::new(-phi.sin(), 0.0, phi.cos());
            let dpdv = DVec3::new(
                -theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            );
            let n32 = n.as_vec3();
            mesh.positions.push((centre + n * TORUS_MINOR).as_vec3());
            mesh.normals.push(n32);
            mesh.uvs
                .push(Vec2::new(i as f32 / major as f32, j as f32 / minor as f32));
            mesh.tangents
                .push(tangent(n32, dpdu.as_vec3(), dpdv.as_vec3()));
        }
    }
    let stride = minor + 1;
    for i in 0..major {
        for j in 0..minor {
            let p00 = i * stride + j;
            let (p01, p10, p11) = (p00 + 1, p00 + stride, p00 + stride + 1);
            // d/dtheta x d/dphi points outwards.
            mesh.indices
                .extend_from_slice(&[p00, p01, p11, p00, p11, p10]);
        }
    }
    mesh
}

/// Plane: [`Mesh::generate`] with `n` x `n` quads, plus tangents.
fn plane(n: u32) -> Mesh {
    let mut mesh = Mesh::generate(Shape::Plane { half_size: 1.0 }, n, n);
    let frame = tangent(Vec3::Y, Vec3::X, Vec3::Z);
    mesh.tangents = vec![frame; mesh.positions.len()];
    mesh
}

/// Teapot patch grid (nu, nv) for `resolution` = nu + nv.
fn teapot_grid(resolution: u64) -> (u64, u64) {
    let nu = resolution / 2;
    (nu, resolution - nu)
}

/// The 16 control points of teapot patch `p` as `[row (u)][column (v)]`, in the data's z-up
/// coordinates.
fn teapot_control_points(p: usize) -> [[DVec3; 4]; 4] {
    let patch = &teapot_data::PATCHES[p];
    std::array::from_fn(|r| {
        std::array::from_fn(|c| {
            let [x, y, z] = teapot_data::POINTS[patch[4 * r + c] as usize - 1];
            DVec3::new(x as f64, y as f64, z as f64)
        })
    })
}

/// Which edges of each teapot patch collapse to a single point: `[u = 0, u = 1, v = 0, v = 1]`.
fn teapot_collapsed_edges() -> [[bool; 4]; 32] {
    std::array::from_fn(|p| {
        let c = teapot_control_points(p);
        let same = |pts: [DVec3; 4]| pts.iter().all(|&q| q == pts[0]);
        [
            same(c[0]),
            same(c[3]),
            same(std::array::from_fn(|r| c[r][0])),
            same(std::array::from_fn(|r| c[r][3])),
        ]
    })
}

/// Cubic Bernstein polynomials and their derivatives at `t`.
fn bernstein(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// Position and partial derivatives along u and v of a bicubic patch at (u, v).
fn bezier_patch(c: &[[DVec3; 4]; 4], u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
    let (bu, dbu) = bernstein(u);
    let (bv, dbv) = bernstein(v);
    let (mut p, mut du, mut dv) = (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    for (row, (&bu, &dbu)) in c.iter().zip(bu.iter().zip(&dbu)) {
        for (&q, (&bv, &dbv)) in row.iter().zip(bv.iter().zip(&dbv)) {
            p += q * (bu * bv);
            du += q * (dbu * bv);
            dv += q * (bu * dbv);
        }
    }
    (p, du, dv)
}

/// The Utah teapot, each patch a grid of nu x nv quads (`resolution` = nu + nv).
fn teapot(resolution: u32) -> Mesh {
    let (nu, nv) = teapot_grid(u64::from(resolution));
    let (nu, nv) = (nu as u32, nv as u32);
    let collapsed = teapot_collapsed_edges();
    let scale = TEAPOT_HEIGHT / 3.15;
    // z up -> y up (a rotation about x, so orientation is kept), then scale.
    let to_y_up = |p: DVec3| DVec3::new(p.x, p.z, -p.y);
    let mut mesh = Mesh::default();
    for (p, edges) in collapsed.iter().enumerate() {
        let c = teapot_control_points(p);
        let first = mesh.positions.len() as u32;
        for i in 0..=nu {
            let u = i as f64 / nu as f64;
            for j in 0..=nv {
                let v = j as f64 / nv as f64;
                let (pos, du, dv) = bezier_patch(&c, u, v);
                // Every patch faces outwards along dP/dv x dP/du.
                let mut frame = (du, dv);
                if dv.cross(du).length_squared() < 1e-14 {
                    // A collapsed edge: take the derivatives just inside the patch.
                    let step = |t: f64| if t < 0.5 { t + 1e-4 } else { t - 1e-4 };
                    let (_, du2, dv2) = bezier_patch(&c, step(u), step(v));
                    frame = (
                        if du.length_squared() > 1e-14 { du } else { du2 },
                        if dv.length_squared() > 1e-14 { dv } else { dv2 },
                    );
                    if frame.1.cross(frame.0).length_squared() < 1e-14 {
                        frame = (du2, dv2);
                    }
                }
                let (du, dv) = (to_y_up(frame.0), to_y_up(frame.1));
                let n = dv.cross(du).try_normalize().unwrap_or(DVec3::Y).as_vec3();
                mesh.positions.push((to_y_up(pos) * scale).as_vec3());
                mesh.normals.push(n);
                // uv.x runs around (v), uv.y from top to bottom (u).
                mesh.uvs
                    .push(atlas(6, p as u32, Vec2::new(v as f32, u as f32)));
                mesh.tangents.push(tangent(n, dv.as_vec3(), du.as_vec3()));
            }
        }
        let stride = nv + 1;
        // A triangle with two corners on a collapsed edge has zero area.
        let degenerate = |tri: [(u32, u32); 3]| {
            let on = |e: usize, (i, j): (u32, u32)| match e {
                0 => i == 0,
                1 => i == nu,
                2 => j == 0,
                _ => j == nv,
            };
            (0..4).any(|e| edges[e] && tri.iter().filter(|&&q| on(e, q)).count() >= 2)
        };
        for i in 0..nu {
            for j in 0..nv {
                let quad = [(i, j), (i, j + 1), (i + 1, j + 1), (i + 1, j)];
                for tri in [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]] {
                    if !degenerate(tri) {
                        mesh.indices
                            .extend(tri.map(|(a, b)| first + a * stride + b));
                    }
                }
            }
        }
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Teapot table transcription checks: symmetry and shared edges.
    #[test]
    fn teapot_data_is_symmetric_and_watertight_where_it_should_be() {
        let cp = |p: usize| teapot_control_points(p);
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-6;
        // Rim, body and lid patches come in fours, each the previous turned by -90 degrees
        // about z; the bottom turns the other way.
        for (group, sign) in [
            (0..4, 1.0),
            (4..8, 1.0),
            (8..12, 1.0),
            (20..24, 1.0),
            (24..28, 1.0),
            (28..32, -1.0),
        ] {
            let g: Vec<usize> = group.collect();
            for k in 0..4 {
                let (a, b) = (cp(g[k]), cp(g[(k + 1) % 4]));
                for r in 0..4 {
                    for c in 0..4 {
                        let p = a[r][c];
                        let turned = DVec3::new(sign * p.y, -sign * p.x, p.z);
                        assert!(
                            close(turned, b[r][c]),
                            "patch {} vs {}",
                            g[k],
                            g[(k + 1) % 4]
                        );
                    }
                }
            }
        }
        // Handle and spout patches pair up as mirror images in y.
        for (a, b) in [(12, 13), (14, 15), (16, 17), (18, 19)] {
            let mut pa: Vec<[i64; 3]> = cp(a)
                .iter()
                .flatten()
                .map(|p| [p.x, -p.y, p.z].map(|x| (x * 1e4).round() as i64))
                .collect();
            let mut pb: Vec<[i64; 3]> = cp(b)
                .iter()
                .flatten()
                .map(|p| [p.x, p.y, p.z].map(|x| (x * 1e4).round() as i64))
                .collect();
            pa.sort();
            pb.sort();
            assert_eq!(pa, pb, "patches {a} and {b}");
        }
        // Every patch boundary is another patch's boundary, except the known open ones.
        let boundary = |p: usize, e: usize| -> [DVec3; 4] {
            let c = cp(p);
            match e {
                0 => c[0],
                1 => c[3],
                2 => std::array::from_fn(|r| c[r][0]),
                _ => std::array::from_fn(|r| c[r][3]),
            }
        };
        let collapsed = teapot_collapsed_edges();
        let mut open = Vec::new();
        for (p, edges) in collapsed.iter().enumerate() {
            for (e, &edge_collapsed) in edges.iter().enumerate() {
                if edge_collapsed {
                    continue;
                }
                let mine = boundary(p, e);
                let mut reversed = mine;
                reversed.reverse();
                let shared = (0..32).any(|q| {
                    (0..4).any(|f| {
                        (q, f) != (p, e) && {
                            let theirs = boundary(q, f);
                            (0..4).all(|k| close(mine[k], theirs[k]))
                                || (0..4).all(|k| close(reversed[k], theirs[k]))
                        }
                    })
                });
                if !shared {
                    open.push((p + 1, e));
                }
            }
        }
        // Rim inner edge, handle ends, spout ends, lid outer edge (1-based patch numbers).
        let expected = vec![
            (1, 0),
            (2, 0),
            (3, 0),
            (4, 0),
            (13, 0),
            (14, 0),
            (15, 1),
            (16, 1),
            (17, 0),
            (18, 0),
            (19, 1),
            (20, 1),
            (25, 1),
            (26, 1),
            (27, 1),
            (28, 1),
        ];
        assert_eq!(open, expected);
        // Only the lid-top and bottom patches have a collapsed edge, each exactly one (the
        // triangle count formula relies on it).
        for (p, edges) in collapsed.iter().enumerate() {
            let n = edges.iter().filter(|&&c| c).count();
            let pole = (20..24).contains(&p) || (28..32).contains(&p);
            assert_eq!(n, usize::from(pole), "patch {}", p + 1);
            assert!(!pole || edges[0]);
        }
    }

    #[test]
    fn compact_drops_unreferenced_vertices_only() {
        let mut m = Mesh::generate(Shape::Sphere { radius: 1.0 }, 6, 3);
        let before = m.triangle_count();
        let corners: Vec<[Vec3; 3]> = (0..before).map(|t| m.triangle(t)).collect();
        compact(&mut m);
        assert_eq!(m.triangle_count(), before);
        assert_eq!(m.positions.len(), m.normals.len());
        assert_eq!(m.positions.len(), m.uvs.len());
        for (t, c) in corners.iter().enumerate() {
            assert_eq!(&m.triangle(t), c);
        }
    }
}
