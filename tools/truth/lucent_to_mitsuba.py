"""A lucent scene file (TOML, docs/scene-format.toml) as a Mitsuba 3 scene dictionary.

This module knows lucent's conventions and nothing about rendering: `convert(path)` reads the
file and returns a `Converted` (the Mitsuba dict, the notes to print, what the mask renders
need). Every key the file gives either does in Mitsuba exactly what it does in lucent, or is
refused with `Refused` naming the file, the key and why. Keys that only tune one of lucent's
approximations of a medium (Li et al.'s weights, a layered material's albedo and specular, the
GDC 2011 and SSS parts beside a medium, a light's translucency_scale) do not describe the
scene; they are listed in `notes` as "not rendered by the truth", never dropped silently.

The conventions matched (each checked against lucent's source, cited where it is used):
  - camera: lucent's `fov_y_degrees` is the vertical field of view (src/scene/mod.rs
    `Camera::projection`, glam `perspective_rh(fov_y, aspect, ..)`), so Mitsuba's `perspective`
    gets `fov_axis = "y"`; the view is `look_at_rh(eye, target, +y)` = Mitsuba `look_at` with
    up +y; near and far are clip planes in both.
  - objects: `Mat4::from_scale_rotation_translation` = T * R * S, R = Rx(x) Ry(y) Rz(z) in
    degrees (glam's intrinsic EulerRot::XYZ, src/scene/file/build.rs `objects`).
  - meshes (src/scene/generators.rs): sphere and icosphere are the unit sphere lucent
    tessellates (its CPU reference traces the analytic one): Mitsuba `sphere`; cube -1..1:
    Mitsuba `cube` (the same 12 flat triangles' surface); plane: the square -1..1 in x and z
    facing +y: Mitsuba `rectangle` turned -90 degrees about x; torus: the same triangles and
    analytic normals, regenerated here and written as PLY; OBJ files as given.
  - lights (glsl/common/lighting.glsl): radiance = colour x intensity; a point light's
    attenuation is window^2 / d^2 with window = clamp(1 - (d / range)^4, 0, 1): it equals
    Mitsuba's `point` with intensity = colour x intensity only where window ~ 1, so the
    converter computes the window at the farthest point of the scene and refuses beyond 0.1%.
    `directional`: the direction light travels in both; irradiance = colour x intensity.
  - environment: constant radiance -> `constant`; the default without [environment] and
    without `ambient` is lucent's constant 0.03; hemisphere (+y sky, ground below) -> an
    `envmap` of two constant halves (Mitsuba's envmap has +y up).
  - media (src/scene/layered.rs): sigma_a and sigma_s in mm^-1, scene units per mm u, so per
    scene unit sigma / u; Mitsuba `homogeneous` with sigma_t = (sigma_a + sigma_s) / u,
    albedo = sigma_s / sigma_t, Henyey-Greenstein g; boundary `null` at eta 1, `dielectric`
    (int_ior = eta, ext_ior = 1) otherwise.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

# Jensen et al. 2001's measured media (src/scene/layered.rs JENSEN_2001): name ->
# (sigma_s' RGB, sigma_a RGB) in mm^-1. lucent's presets are one semi-infinite layer, g = 0
# (so sigma_s = sigma_s'), eta 1.3.
JENSEN_2001 = {
    "apple": ([2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    "chicken1": ([0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    "chicken2": ([0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    "cream": ([7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    "ketchup": ([0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    "marble": ([2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    "potato": ([0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    "skimmilk": ([0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    "skin1": ([0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    "skin2": ([1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    "spectralon": ([11.6, 20.4, 14.9], [0.00, 0.00, 0.00]),
    "wholemilk": ([2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
    # Li et al.'s teapot row: skin1 with Li's blue sigma_a 0.18.
    "li-teapot": ([0.74, 0.88, 1.01], [0.032, 0.17, 0.18]),
}
PRESET_ETA = 1.3  # every single-layer preset's eta (LayeredMedium::preset)
DEFAULT_UNITS_PER_MM = 0.04  # layered.rs DEFAULT_UNITS_PER_MM
MAX_ABS_G = 0.999  # layered.rs MAX_ABS_G: sigma_s' -> sigma_s divides by at least 1 - 0.999

DEFAULT_AMBIENT = [0.03, 0.03, 0.03]  # no [environment] and no `ambient` (build.rs)
DEFAULT_SKY = [0.15, 0.2, 0.3]  # file/mod.rs
DEFAULT_LIGHT_RANGE = 20.0  # build.rs `light`
DEFAULT_SPECULAR = 0.5  # file/materials.rs `material`
# A point or spot light's range window may differ from 1 by this much over the scene.
WINDOW_TOLERANCE = 1e-3
# Rows of the hemisphere environment's map: the horizon lies on a texel edge, so only the
# bilinear band of one texel (180 / rows degrees) mixes sky and ground.
HEMISPHERE_MAP_ROWS = 2048


class Refused(Exception):
    """The scene cannot be rendered exactly: the message names the file, the key and why."""


@dataclass
class Converted:
    """A lucent scene as Mitsuba sees it."""

    scene: dict  # the Mitsuba scene dict, without sensor film size and integrator knobs
    sensor: dict  # the `perspective` sensor (film filled in by the caller)
    sky: list  # radiance where no geometry is (lucent's `sky`)
    environment: dict | None  # the emitter seen where no geometry is, or None (black)
    notes: list = field(default_factory=list)  # keys the truth does not render, and why
    has_dielectric: bool = False


def _rgb(value) -> dict:
    return {"type": "rgb", "value": [float(c) for c in value]}


class _Scene:
    """The file's text parsed, with the error helper every check uses."""

    def __init__(self, path: Path):
        self.path = path
        with open(path, "rb") as f:
            self.toml = tomllib.load(f)

    def refuse(self, key: str, why: str) -> Refused:
        return Refused(f"{self.path}: key `{key}`: {why}")

    def resolve(self, p: str) -> Path:
        q = Path(p)
        return q if q.is_absolute() else self.path.parent / q


# ---------------------------------------------------------------------------------------------
# Transforms and geometry


def object_matrix(obj: dict) -> np.ndarray:
    """lucent's object -> world: T * R * S, R = Rx Ry Rz (glam EulerRot::XYZ, intrinsic)."""
    t = np.array(obj.get("translate", [0.0, 0.0, 0.0]), dtype=float)
    rx, ry, rz = (math.radians(a) for a in obj.get("rotate_degrees", [0.0, 0.0, 0.0]))
    s = obj.get("scale", 1.0)
    s = np.array([s, s, s] if isinstance(s, (int, float)) else s, dtype=float)

    def rot(axis, a):
        c, n = math.cos(a), math.sin(a)
        m = np.eye(3)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        m[i, i], m[i, j], m[j, i], m[j, j] = c, -n, n, c
        return m

    m = np.eye(4)
    m[:3, :3] = rot(0, rx) @ rot(1, ry) @ rot(2, rz) @ np.diag(s)
    m[:3, 3] = t
    return m


def torus_triangles(minor: int):
    """generators.rs `torus`: major radius 1, tube 0.35, `minor` segments around the tube and
    3 x minor around the ring; the same vertex order, triangles and analytic normals."""
    major = 3 * minor
    i = np.arange(major + 1)[:, None]
    j = np.arange(minor + 1)[None, :]
    phi = 2 * np.pi * i / major
    theta = 2 * np.pi * j / minor
    n = np.stack(
        np.broadcast_arrays(np.cos(theta) * np.cos(phi), np.sin(theta), np.cos(theta) * np.sin(phi)),
        axis=-1,
    ).reshape(-1, 3)
    centre = np.stack(np.broadcast_arrays(np.cos(phi), 0 * phi, np.sin(phi)), axis=-1)
    centre = np.broadcast_to(centre, (major + 1, minor + 1, 3)).reshape(-1, 3)
    positions = centre + 0.35 * n
    stride = minor + 1
    faces = []
    for a in range(major):
        for b in range(minor):
            p00 = a * stride + b
            p01, p10, p11 = p00 + 1, p00 + stride, p00 + stride + 1
            faces += [(p00, p01, p11), (p00, p11, p10)]
    return positions.astype(np.float32), n.astype(np.float32), np.array(faces, dtype=np.uint32)


def torus_resolution(mesh: dict) -> int:
    """The tube segments lucent uses: level L -> 6 (L + 1); `triangles` T -> the resolution
    whose 6 r^2 is closest to T (ties to the smaller), as generators.rs picks it."""
    if "triangles" in mesh:
        target = mesh["triangles"]
        r = max(3, math.isqrt(max(target // 6, 0)))
        candidates = [c for c in (r - 1, r, r + 1, r + 2) if c >= 3]
        return min(candidates, key=lambda c: (abs(6 * c * c - target), c))
    return 6 * (mesh.get("level", 2) + 1)


def write_ply(path: Path, positions, normals, faces):
    """A binary little-endian PLY with per-vertex normals (Mitsuba's `ply` reads it)."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(positions)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    vertices = np.concatenate([positions, normals], axis=1).astype("<f4")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<u4", 3)])
    rows["n"], rows["i"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(vertices.tobytes())
        f.write(rows.tobytes())


# Object-space bounding boxes of the generators (generators.rs module docs), for the light
# window and spot cone checks; OBJ files are measured.
GENERATOR_BOUNDS = {
    "sphere": ([-1, -1, -1], [1, 1, 1]),
    "uv-sphere": ([-1, -1, -1], [1, 1, 1]),
    "icosphere": ([-1, -1, -1], [1, 1, 1]),
    "cube": ([-1, -1, -1], [1, 1, 1]),
    "torus": ([-1.35, -0.35, -1.35], [1.35, 0.35, 1.35]),
    "plane": ([-1, 0, -1], [1, 0, 1]),
}
CLOSED_GENERATORS = {"sphere", "uv-sphere", "icosphere", "cube", "torus"}


def obj_bounds(path: Path):
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                p = np.array([float(x) for x in line.split()[1:4]])
                lo, hi = np.minimum(lo, p), np.maximum(hi, p)
    return lo, hi


def box_corners(lo, hi, matrix) -> np.ndarray:
    """The 8 corners of an object-space box in world space (a convex box's farthest point
    from any point, and its widest angle from a cone's apex, is a corner)."""
    c = np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    return (matrix @ c.T).T[:, :3]


# ---------------------------------------------------------------------------------------------
# The converter


def convert(path: Path, work_dir: Path, allow_dielectric_delta_lights: bool = False) -> Converted:
    """`path` (a lucent scene file) as a Mitsuba scene; generated meshes go to `work_dir`."""
    sc = _Scene(path)
    t = sc.toml
    notes: list[str] = []
    known_top = {"name", "technique", "ambient", "environment", "sky", "exposure", "camera",
                 "mesh", "material", "object", "light", "deformation"}
    for key in t:
        if key not in known_top:
            raise sc.refuse(key, "unknown key (lucent refuses it too)")
    if "technique" in t:
        raise sc.refuse("technique", "the scene-level technique key is gone from lucent")
    if "deformation" in t:
        raise sc.refuse("deformation", "a deforming mesh is not converted: the truth would "
                        "have to re-run lucent's CPU wave at the same --time")
    if "exposure" in t:
        notes.append("`exposure`: a tonemapping multiplier; lucent's --exr and this EXR are "
                     "both linear radiance before it")

    scene: dict = {"type": "scene"}
    sensor = camera(sc, t.get("camera"))

    environment = environment_emitter(sc, t)
    if environment is not None:
        scene["environment"] = environment
    sky = t.get("sky", DEFAULT_SKY)

    meshes = {m.get("name"): (i, m) for i, m in enumerate(t.get("mesh", []))}
    materials = {m.get("name"): (i, m) for i, m in enumerate(t.get("material", []))}
    corners = []  # world-space bounding-box corners of every object
    has_dielectric = False
    dielectric_key = None  # the first material with eta != 1, for the refusal below
    for k, obj in enumerate(t.get("object", [])):
        okey = f"object[{k}]"
        if obj.get("mesh") not in meshes:
            raise sc.refuse(f"{okey}.mesh", f"no mesh named {obj.get('mesh')!r}")
        if obj.get("material") not in materials:
            raise sc.refuse(f"{okey}.material", f"no material named {obj.get('material')!r}")
        mi_index, mesh = meshes[obj["mesh"]]
        ma_index, material = materials[obj["material"]]
        matrix = object_matrix(obj)
        shape, bounds, closed = mesh_shape(sc, mi_index, mesh, obj, okey, matrix, work_dir)
        corners.append(box_corners(*bounds, matrix))
        bsdf, medium, eta = material_parts(sc, ma_index, material, notes)
        if medium is not None:
            if not closed:
                raise sc.refuse(f"{okey}.mesh", f"mesh {mesh['name']!r} is not a closed surface; "
                                "a medium needs one to be inside of")
            shape["interior"] = medium
            if eta != 1.0 and dielectric_key is None:
                table = "medium" if "medium" in material else "layered"
                dielectric_key = f"material[{ma_index}].{table}.eta"
            has_dielectric |= eta != 1.0
        shape["bsdf"] = bsdf
        scene[f"object{k}"] = shape
    if not corners:
        raise sc.refuse("object", "the scene has no [[object]]")
    corners = np.concatenate(corners)

    for k, light in enumerate(t.get("light", [])):
        scene[f"light{k}"] = light_emitter(sc, k, light, corners, notes)
    if has_dielectric and t.get("light") and not allow_dielectric_delta_lights:
        raise sc.refuse(
            dielectric_key,
            "a medium behind a dielectric boundary (eta != 1) cannot be lit by point, spot or "
            "directional lights in Mitsuba's volpath: its shadow rays do not cross a smooth "
            "dielectric, so only paths that hit an emitter by chance carry light, and a delta "
            "light is never hit (../../shared/truth-notes.md). Use eta = 1, or pass "
            "--allow-dielectric-delta-lights to render anyway (the medium then receives only "
            "the environment)")
    return Converted(scene=scene, sensor=sensor, sky=list(sky), environment=environment,
                     notes=notes, has_dielectric=has_dielectric)


def camera(sc: _Scene, cam: dict | None) -> dict:
    if cam is None:
        raise sc.refuse("camera", "no [camera] table")
    for key in cam:
        if key not in {"eye", "target", "fov_y_degrees", "near", "far"}:
            raise sc.refuse(f"camera.{key}", "unknown key")
    import mitsuba as mi  # the caller has chosen the variant

    return {
        "type": "perspective",
        # lucent's fov_y_degrees is vertical (glam perspective_rh's fov_y): Mitsuba's fov
        # is along `fov_axis`, so "y".
        "fov_axis": "y",
        "fov": float(cam.get("fov_y_degrees", 45.0)),
        "near_clip": float(cam.get("near", 0.1)),
        "far_clip": float(cam.get("far", 100.0)),
        # lucent: Mat4::look_at_rh(eye, target, Vec3::Y). Mitsuba's look_at gives the same
        # upright, unmirrored view (checked by the lit side of an off-axis light: README).
        "to_world": mi.ScalarTransform4f().look_at(
            origin=cam["eye"], target=cam["target"], up=[0.0, 1.0, 0.0]),
    }


def environment_emitter(sc: _Scene, t: dict) -> dict | None:
    """lucent's environment (build.rs `environment`) as a Mitsuba emitter, or None for black."""
    env = t.get("environment")
    if env is None:
        radiance = t.get("ambient", DEFAULT_AMBIENT)
        return {"type": "constant", "radiance": _rgb(radiance)} if max(radiance) > 0 else None
    if "ambient" in t:
        raise sc.refuse("ambient", "give either `ambient` or [environment], not both (lucent "
                        "refuses it too)")
    kind = env.get("kind")
    allowed = {"constant": {"kind", "radiance"}, "hemisphere": {"kind", "sky", "ground"},
               "map": {"kind", "file", "builtin", "intensity", "rotation_degrees"}}
    if kind not in allowed:
        raise sc.refuse("environment.kind", f"unknown kind {kind!r}")
    for key in env:
        if key not in allowed[kind]:
            raise sc.refuse(f"environment.{key}", f"does not apply to kind = {kind!r}")
    if kind == "constant":
        radiance = env["radiance"]
        return {"type": "constant", "radiance": _rgb(radiance)} if max(radiance) > 0 else None
    if kind == "hemisphere":
        import mitsuba as mi

        # Mitsuba's envmap is latitude-longitude with +y up: the top half of the rows is the
        # upper hemisphere. The horizon falls on a texel edge; bilinear lookup blends sky and
        # ground only within half a texel row of it (180 / 2048 / 2 = 0.04 degrees).
        rows = HEMISPHERE_MAP_ROWS
        image = np.empty((rows, 2 * rows, 3), dtype=np.float32)
        image[: rows // 2] = env["sky"]
        image[rows // 2:] = env["ground"]
        return {"type": "envmap", "bitmap": mi.Bitmap(image)}
    raise sc.refuse(
        "environment.kind",
        "kind = \"map\" is not converted: lucent lights with the map's nine spherical-harmonic "
        "coefficients and its orientation convention (row 0 the zenith, the centre column "
        "looking down -z, rotation about +y) has not been matched against Mitsuba's envmap "
        "here; use constant or hemisphere")


def mesh_shape(sc, index, mesh, obj, okey, matrix, work_dir):
    """The Mitsuba shape of `mesh` placed by `matrix`; its object-space bounds; closed?"""
    import mitsuba as mi

    mkey = f"mesh[{index}]"
    for key in mesh:
        if key not in {"name", "obj", "generator", "level", "triangles"}:
            raise sc.refuse(f"{mkey}.{key}", "unknown key")
    to_world = mi.ScalarTransform4f(matrix.tolist())
    if "obj" in mesh:
        file = sc.resolve(mesh["obj"])
        if not file.exists():
            raise sc.refuse(f"{mkey}.obj", f"mesh file {file} not found")
        text = file.read_text(errors="replace")
        if any(line.split()[:1] in (["usemtl"], ["mtllib"]) for line in text.splitlines()):
            raise sc.refuse(f"{mkey}.obj", f"{file} uses MTL materials (lucent splits it into "
                            "parts with the MTL's Kd and map_Kd); not converted")
        # Closedness of an OBJ is not checked: a medium inside an open OBJ is the user's call.
        return ({"type": "obj", "filename": str(file), "to_world": to_world},
                obj_bounds(file), True)
    generator = str(mesh.get("generator", "")).strip().lower()
    bounds = GENERATOR_BOUNDS.get(generator)
    if generator in ("sphere", "uv-sphere", "icosphere"):
        s = obj.get("scale", 1.0)
        if not isinstance(s, (int, float)) and not (s[0] == s[1] == s[2]):
            raise sc.refuse(f"{okey}.scale", f"{s}: Mitsuba's analytic sphere takes a uniform "
                            "scale only (an ellipsoid would have to be lucent's tessellation)")
        # The unit sphere lucent tessellates (its `shape` is Sphere { radius: 1 }).
        return {"type": "sphere", "to_world": to_world}, bounds, True
    if generator == "cube":
        # Mitsuba's cube is the same -1..1 box (flat faces: tessellation changes nothing).
        return {"type": "cube", "to_world": to_world}, bounds, True
    if generator == "plane":
        # lucent: -1..1 in x and z at y = 0 facing +y; Mitsuba's rectangle: -1..1 in x and y
        # at z = 0 facing +z. Rx(-90 degrees) takes +z to +y and +y to -z.
        turn = mi.ScalarTransform4f().rotate(axis=[1, 0, 0], angle=-90.0)
        return {"type": "rectangle", "to_world": to_world @ turn}, bounds, False
    if generator == "torus":
        r = torus_resolution(mesh)
        positions, normals, faces = torus_triangles(r)
        file = work_dir / f"torus_{r}.ply"
        write_ply(file, positions, normals, faces)
        return {"type": "ply", "filename": str(file), "to_world": to_world}, bounds, True
    if generator == "teapot":
        raise sc.refuse(f"{mkey}.generator", "the teapot's Bezier tessellation "
                        "(generators.rs) is not ported here; export it as OBJ")
    raise sc.refuse(f"{mkey}.generator", f"unknown generator {generator!r}")


def material_parts(sc, index, m, notes):
    """(bsdf, medium or None, eta) of `[[material]]` number `index`."""
    key = f"material[{index}]"
    known = {"name", "albedo", "specular", "roughness", "albedo_texture", "normal_texture",
             "translucency", "sss", "layered", "layers", "medium"}
    for k in m:
        if k not in known:
            raise sc.refuse(f"{key}.{k}", "unknown key")
    for k in ("albedo_texture", "normal_texture"):
        if k in m:
            raise sc.refuse(f"{key}.{k}", "textures are not converted")
    if "layers" in m:
        raise sc.refuse(f"{key}.layers", "gone from lucent: use [material.layered]")
    layered = m.get("layered")
    if "medium" in m:
        return _medium_parts(sc, key, m, notes)
    if layered is None:
        for part in ("sss", "translucency"):
            if part in m:
                raise sc.refuse(f"{key}.{part}", f"a [material.{part}] alone describes no "
                                "medium (an SSS profile or GDC 2011's artistic thickness term); "
                                "the truth needs a [material.layered] medium")
        specular = m.get("specular", DEFAULT_SPECULAR)
        if specular != 0:
            raise sc.refuse(f"{key}.specular", f"{specular}{' (the default)' if 'specular' not in m else ''}: "
                            "lucent adds a normalised Blinn-Phong lobe (lighting.glsl), which no "
                            "Mitsuba BSDF is; write specular = 0 for a Lambertian truth")
        return {"type": "diffuse", "reflectance": _rgb(m.get("albedo", [0.8] * 3))}, None, 1.0

    # A medium: its single homogeneous semi-infinite layer is the object's interior.
    lkey = f"{key}.layered"
    for k in layered:
        if k not in {"preset", "layer", "eta", "weights", "units_per_mm", "depth_texture"}:
            raise sc.refuse(f"{lkey}.{k}", "unknown key")
    if "depth_texture" in layered:
        raise sc.refuse(f"{lkey}.depth_texture", "per-texel layer depths are not converted")
    preset, layers = layered.get("preset"), layered.get("layer")
    if (preset is None) == (layers is None):
        raise sc.refuse(lkey, "give a `preset` or [[material.layered.layer]] tables")
    if preset is not None:
        if preset == "skin-layered":
            raise sc.refuse(f"{lkey}.preset", "skin-layered is a two-layer stack (epidermis "
                            "0.25 mm over dermis): multi-layer stacks are not converted")
        if preset not in JENSEN_2001:
            raise sc.refuse(f"{lkey}.preset", f"unknown preset {preset!r}")
        sigma_s_prime, sigma_a = JENSEN_2001[preset]
        sigma_s, g = list(sigma_s_prime), 0.0
    else:
        if len(layers) != 1:
            raise sc.refuse(f"{lkey}.layer", f"{len(layers)} layers: multi-layer stacks are "
                            "not converted (only one homogeneous layer)")
        layer = layers[0]
        ykey = f"{lkey}.layer[0]"
        for k in layer:
            if k not in {"sigma_a", "sigma_s", "sigma_s_prime", "g", "thickness"}:
                raise sc.refuse(f"{ykey}.{k}", "not converted")
        if layer.get("thickness") != "rest":
            raise sc.refuse(f"{ykey}.thickness", f"{layer.get('thickness')!r}: only "
                            "thickness = \"rest\" (the medium fills the object) is converted")
        g = float(layer.get("g", 0.0))
        sigma_a = layer["sigma_a"]
        if "sigma_s" in layer and "sigma_s_prime" in layer:
            raise sc.refuse(f"{ykey}.sigma_s_prime", "give sigma_s or sigma_s_prime, not both")
        if "sigma_s" in layer:
            sigma_s = layer["sigma_s"]
        else:
            # lucent stores sigma_s = sigma_s' / (1 - g), |g| clamped to 0.999.
            one_minus_g = max(1.0 - max(-MAX_ABS_G, min(MAX_ABS_G, g)), 1.0 - MAX_ABS_G)
            sigma_s = [s / one_minus_g for s in layer["sigma_s_prime"]]
    eta = float(layered.get("eta", PRESET_ETA if preset is not None else 1.3))
    units_per_mm = float(layered.get("units_per_mm", DEFAULT_UNITS_PER_MM))

    # Knobs of lucent's approximations, not of the medium: listed, not rendered.
    knobs = [k for k in ("albedo", "specular", "roughness") if k in m]
    knobs += [f"layered.{k}" for k in ("weights",) if k in layered]
    knobs += [k for k in ("sss", "translucency") if k in m]
    return _interior(key, m, knobs, sigma_a, sigma_s, g, eta, units_per_mm, notes)


def _medium_parts(sc, key, m, notes):
    """(bsdf, medium, eta) of a material with `[material.medium]`: the one medium lucent's
    techniques derive their parameters from (src/scene/file/materials.rs `medium`), so the
    truth renders it; a `[material.layered]` beside it is one of lucent's approximations."""
    medium = m["medium"]
    mkey = f"{key}.medium"
    for k in medium:
        if k not in {"preset", "sigma_a", "sigma_s", "sigma_s_prime", "g", "eta", "units_per_mm"}:
            raise sc.refuse(f"{mkey}.{k}", "unknown key")
    preset = medium.get("preset")
    coefficients = [k for k in ("sigma_a", "sigma_s", "sigma_s_prime", "g") if k in medium]
    if preset is not None:
        if coefficients:
            raise sc.refuse(f"{mkey}.preset", "give a preset or the coefficients, not both")
        if preset not in JENSEN_2001:
            raise sc.refuse(f"{mkey}.preset", f"{preset!r} is not one of Jensen 2001's media "
                            f"({', '.join(sorted(JENSEN_2001))})")
        sigma_s_prime, sigma_a = JENSEN_2001[preset]
        sigma_s, g = list(sigma_s_prime), 0.0
    else:
        if "sigma_a" not in medium:
            raise sc.refuse(mkey, "missing sigma_a")
        g = float(medium.get("g", 0.0))
        sigma_a = medium["sigma_a"]
        if ("sigma_s" in medium) == ("sigma_s_prime" in medium):
            raise sc.refuse(mkey, "give sigma_s or sigma_s_prime (one of them)")
        if "sigma_s" in medium:
            sigma_s = medium["sigma_s"]
        else:
            one_minus_g = max(1.0 - max(-MAX_ABS_G, min(MAX_ABS_G, g)), 1.0 - MAX_ABS_G)
            sigma_s = [s / one_minus_g for s in medium["sigma_s_prime"]]
    # lucent's defaults for a medium: eta 1.3 (presets and coefficients alike), 0.04 units/mm.
    eta = float(medium.get("eta", PRESET_ETA if preset is not None else 1.3))
    units_per_mm = float(medium.get("units_per_mm", DEFAULT_UNITS_PER_MM))
    knobs = [k for k in ("albedo", "specular", "roughness", "layered", "sss", "translucency")
             if k in m]
    return _interior(key, m, knobs, sigma_a, sigma_s, g, eta, units_per_mm, notes)


def _interior(key, m, knobs, sigma_a, sigma_s, g, eta, units_per_mm, notes):
    """(bsdf, medium, eta) of a homogeneous interior in mm^-1 at `units_per_mm`; `knobs`:
    the material's keys that tune lucent's techniques only (noted, not rendered)."""
    if knobs:
        notes.append(f"{key} ({m.get('name')}): {', '.join(knobs)} tune lucent's techniques, "
                     "not the medium: not rendered by the truth")
    # Physical units: mm^-1 -> per scene unit (1 unit = 1 / units_per_mm mm).
    sigma_a = np.array(sigma_a, dtype=float) / units_per_mm
    sigma_s = np.array(sigma_s, dtype=float) / units_per_mm
    sigma_t = sigma_a + sigma_s
    albedo = np.divide(sigma_s, sigma_t, out=np.zeros(3), where=sigma_t > 0)
    # Mitsuba reads an RGB sigma_t as a reflectance (each channel <= 1): give it sigma_t over
    # its largest channel and that largest channel as `scale` (exact: scale x rgb).
    sigma_t_scale = float(sigma_t.max()) if sigma_t.max() > 0 else 1.0
    medium = {
        "type": "homogeneous",
        "sigma_t": _rgb(sigma_t / sigma_t_scale),
        "scale": sigma_t_scale,
        "albedo": _rgb(albedo),
        "phase": {"type": "hg", "g": g},
    }
    notes.append(f"{key} ({m.get('name')}): medium sigma_t {np.round(sigma_t, 4).tolist()} per "
                 f"unit, albedo {np.round(albedo, 5).tolist()}, g {g}, eta {eta} "
                 f"({'null' if eta == 1.0 else 'dielectric'} boundary)")
    if eta == 1.0:
        bsdf = {"type": "null"}  # index-matched: no boundary at all
    else:
        bsdf = {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0}
    return bsdf, medium, eta


def light_emitter(sc, k, light, corners, notes):
    key = f"light[{k}]"
    for kk in light:
        if kk not in {"type", "color", "intensity", "position", "direction", "range",
                      "inner_degrees", "outer_degrees", "translucency_scale", "shadows"}:
            raise sc.refuse(f"{key}.{kk}", "unknown key")
    if light.get("shadows", True) is False:
        raise sc.refuse(f"{key}.shadows", "false: a path tracer cannot light through occluders")
    if light.get("translucency_scale", 1.0) != 1.0:
        notes.append(f"{key}.translucency_scale: GDC 2011's per-light knob, not rendered")
    # lighting.glsl: radiance = colour x intensity.
    radiance = np.array(light.get("color", [1.0, 1.0, 1.0]), dtype=float) * light["intensity"]
    kind = light.get("type")
    if kind == "directional":
        for kk in ("position", "range", "inner_degrees", "outer_degrees"):
            if kk in light:
                raise sc.refuse(f"{key}.{kk}", "a directional light has no " + kk)
        # lucent: to_light = -normalize(direction); Mitsuba: the direction light travels.
        return {"type": "directional", "direction": [float(x) for x in light["direction"]],
                "irradiance": _rgb(radiance)}
    if kind not in ("point", "spot"):
        raise sc.refuse(f"{key}.type", f"unknown light type {kind!r}")
    position = np.array(light["position"], dtype=float)
    rng = float(light.get("range", DEFAULT_LIGHT_RANGE))
    # lighting.glsl: attenuation = window^2 / d^2, window = clamp(1 - (d / range)^4, 0, 1).
    d_far = float(np.max(np.linalg.norm(corners - position, axis=1)))
    window = max(0.0, 1.0 - (d_far / rng) ** 4) ** 2
    if 1.0 - window > WINDOW_TOLERANCE:
        raise sc.refuse(f"{key}.range", f"{rng}: lucent's range window is {window:.4f} at the "
                        f"scene's farthest point ({d_far:.3f} units from the light), "
                        f"{(1 - window) * 100:.2f}% below Mitsuba's inverse-square light; "
                        f"a range of at least {d_far / (1 - math.sqrt(1 - WINDOW_TOLERANCE)) ** 0.25:.1f} "
                        "makes them agree within 0.1%")
    notes.append(f"{key}: range window >= {window:.6f} over the scene (d <= {d_far:.3f})")
    if kind == "point":
        for kk in ("direction", "inner_degrees", "outer_degrees"):
            if kk in light:
                raise sc.refuse(f"{key}.{kk}", "a point light has no " + kk)
        return {"type": "point", "position": position.tolist(), "intensity": _rgb(radiance)}
    # Spot: lucent's edge is ((cos a - cos outer) / (cos inner - cos outer))^2, Mitsuba's is
    # linear in the angle: they agree only where both are 1, inside the inner cone.
    direction = np.array(light["direction"], dtype=float)
    direction /= np.linalg.norm(direction)
    inner = float(light.get("inner_degrees", 20.0))
    outer = float(light.get("outer_degrees", 30.0))
    to_corners = corners - position
    cosines = to_corners @ direction / np.linalg.norm(to_corners, axis=1)
    widest = math.degrees(math.acos(float(np.clip(cosines.min(), -1, 1))))
    if widest > inner or inner >= 90.0:
        raise sc.refuse(f"{key}.inner_degrees", f"{inner}: the scene reaches {widest:.2f} "
                        "degrees off the spot's axis; lucent's cone edge (squared, in cosine) "
                        "and Mitsuba's (linear in angle) differ there, so the whole scene must "
                        "lie inside the inner cone")
    import mitsuba as mi

    return {"type": "spot", "intensity": _rgb(radiance), "cutoff_angle": outer,
            "beam_width": inner,
            "to_world": mi.ScalarTransform4f().look_at(
                origin=position.tolist(), target=(position + direction).tolist(),
                up=[0, 1, 0] if abs(direction[1]) < 0.99 else [1, 0, 0])}
