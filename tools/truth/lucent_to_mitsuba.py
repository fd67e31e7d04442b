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
    (int_ior = eta, ext_ior = 1) otherwise; a medium behind a dielectric lit by point lights is
    left to refracted_nee.py (`Converted.refracted_nee` holds its configuration, or why not).
  - layer stacks ([material.layered] with several layers, `skin-layered`): nested media on the
    analytic sphere, layer i inside the concentric sphere r - u x (the thicknesses above it),
    index-matched interfaces between layers (lucent's Li et al. layers are planar, of constant
    thickness in mm along the normal).
  - an albedo texture on a medium: a pigment film at the surface (film.py), whose exponents
    follow lucent's `texturing` mode (FILM_EXPONENTS); sphere UVs matched to lucent's.
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
    # refracted_nee.py's configuration (a dict) where it applies, else why not (a string)
    refracted_nee: object = None


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


def convert(path: Path, work_dir: Path, allow_dielectric_delta_lights: bool = False,
            refracted_nee: bool = False, texturing_override: str | None = None) -> Converted:
    """`path` (a lucent scene file) as a Mitsuba scene; generated meshes go to `work_dir`.
    `refracted_nee`: the caller renders with refracted_nee.py, so a medium behind a dielectric
    lit by point lights is accepted where that integrator applies. `texturing_override`:
    lucent's `--sss-texturing` (which film an albedo texture on a medium is)."""
    sc = _Scene(path)
    t = sc.toml
    notes: list[str] = []
    known_top = {"name", "credits", "technique", "ambient", "environment", "sky", "exposure",
                 "camera", "mesh", "material", "object", "light", "deformation"}
    for key in t:
        if key not in known_top:
            raise sc.refuse(key, "unknown key (lucent refuses it too)")
    if "technique" in t:
        raise sc.refuse("technique", "the scene-level technique key is gone from lucent")
    if "deformation" in t:
        raise sc.refuse("deformation", "a deforming mesh is not converted: the truth would "
                        "have to re-run lucent's CPU wave at the same --time")
    for credit in t.get("credits", []):
        # Kept with the truth (its JSON's notes): the assets' licences ask for credit.
        notes.append(f"credit: {credit}")
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
    spheres = []  # per object: the analytic sphere (centre, radius) with its parts, or None
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
        parts = material_parts(sc, ma_index, material, notes, texturing_override)
        is_sphere = shape["type"] == "sphere"
        radius = float(np.linalg.norm(matrix[:3, 0])) if is_sphere else None
        spheres.append((matrix[:3, 3].copy(), radius, parts) if is_sphere else None)
        if parts.layers:
            if not closed:
                raise sc.refuse(f"{okey}.mesh", f"mesh {mesh['name']!r} is not a closed surface; "
                                "a medium needs one to be inside of")
            shape["interior"] = parts.layers[0].medium
            if parts.eta != 1.0 and dielectric_key is None:
                dielectric_key = f"material[{ma_index}].{parts.table}.eta"
            has_dielectric |= parts.eta != 1.0
        bsdf = parts.bsdf
        if parts.texture is not None:
            if not is_sphere:
                raise sc.refuse(parts.texture["key"], f"on mesh {mesh['name']!r}: a texture is "
                                "converted on the analytic sphere only (its UVs are matched to "
                                "lucent's latitude-longitude sphere; other meshes' are not)")
            bsdf = film_bsdf(parts.texture)
            # Mitsuba's sphere: u = atan2(y, x) / 2 pi, v = acos(z) / pi in its local frame;
            # lucent's (mesh.rs Shape::Sphere): u = atan2(z, x) / 2 pi, v = acos(y) / pi.
            # Rx(-90 degrees) takes Mitsuba's local (x, y, z) to lucent's (x, -z, y)... i.e.
            # lucent (x, y, z) = (x_M, z_M, -y_M): v agrees and u_M = 1 - u_L (film_bsdf
            # flips the texture's columns).
            turn = mi_transform().rotate(axis=[1, 0, 0], angle=-90.0)
            shape["to_world"] = shape["to_world"] @ turn
        shape["bsdf"] = bsdf
        scene[f"object{k}"] = shape
        if len(parts.layers) > 1:
            # A stack: nested media. Layer i fills the sphere of radius r - (the thicknesses
            # above it) inside the one above: concentric spheres, index-matched (null)
            # interfaces between layers; thickness along the normal in scene units (lucent's
            # Li et al. layers: planar layers of constant thickness in mm along the normal,
            # units_per_mm scene units per mm).
            if not is_sphere:
                raise sc.refuse(f"material[{ma_index}].{parts.table}", f"a stack of "
                                f"{len(parts.layers)} layers on mesh {mesh['name']!r}: stacks are "
                                "converted on the analytic sphere only (nested concentric "
                                "spheres); a mesh would need its surface offset inward")
            depth = 0.0
            for i in range(1, len(parts.layers)):
                depth += parts.layers[i - 1].thickness
                inner = radius - depth
                if inner <= 0.0:
                    notes.append(f"object[{k}]: layers {i}.. lie deeper than the sphere's "
                                 "centre: not there")
                    break
                to_world = mi_transform().translate(matrix[:3, 3].tolist()).scale(inner)
                scene[f"object{k}_layer{i}"] = {
                    "type": "sphere", "to_world": to_world, "bsdf": {"type": "null"},
                    "interior": parts.layers[i].medium, "exterior": parts.layers[i - 1].medium}
                notes.append(f"object[{k}]: layer {i} inside radius {inner:.6g} "
                             f"({depth:.6g} units under the surface)")
    if not corners:
        raise sc.refuse("object", "the scene has no [[object]]")
    corners = np.concatenate(corners)

    for k, light in enumerate(t.get("light", [])):
        scene[f"light{k}"] = light_emitter(sc, k, light, corners, notes)
    nee = refracted_nee_setup(t, spheres, environment)
    if has_dielectric and t.get("light") and not allow_dielectric_delta_lights and not (
            refracted_nee and isinstance(nee, dict)):
        why = ("" if not refracted_nee else
               f" (--integrator refracted-nee does not apply: {nee})")
        raise sc.refuse(
            dielectric_key,
            "a medium behind a dielectric boundary (eta != 1) cannot be lit by point, spot or "
            "directional lights in Mitsuba's volpath: its shadow rays do not cross a smooth "
            "dielectric, so only paths that hit an emitter by chance carry light, and a delta "
            "light is never hit (../../shared/truth-notes.md). Use eta = 1, the refracted "
            "next-event estimation of refracted_nee.py (truth.py --integrator refracted-nee: "
            "one sphere, point lights), or pass --allow-dielectric-delta-lights to render "
            "anyway (the medium then receives only the environment)" + why)
    return Converted(scene=scene, sensor=sensor, sky=list(sky), environment=environment,
                     notes=notes, has_dielectric=has_dielectric, refracted_nee=nee)


def mi_transform():
    import mitsuba as mi  # the caller has chosen the variant

    return mi.ScalarTransform4f()


def film_bsdf(texture: dict) -> dict:
    """The pigment film (film.py) of an albedo texture: lucent decodes the PNG as sRGB, so the
    linear albedo A is the sRGB decode of its 8-bit values; the film passes A^a_in of light
    entering and A^a_out of light leaving. Columns flipped: Mitsuba's sphere u = 1 - lucent's."""
    import mitsuba as mi

    raw = np.array(mi.Bitmap(str(texture["file"])), dtype=np.float64)
    if raw.ndim == 2:
        raw = raw[:, :, None]
    rgb = raw[:, :, :3] if raw.shape[2] >= 3 else np.repeat(raw[:, :, :1], 3, axis=2)
    c = rgb / 255.0
    albedo = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    albedo = np.ascontiguousarray(albedo[:, ::-1, :], dtype=np.float32)
    a_in, a_out = texture["exponents"]
    return {"type": "truth_film", "albedo": {
        "type": "bitmap", "bitmap": mi.Bitmap(albedo, mi.Bitmap.PixelFormat.RGB), "raw": True,
        "filter_type": "bilinear", "wrap_mode": "repeat"},
        "a_in": a_in, "a_out": a_out}


def refracted_nee_setup(t: dict, spheres: list, environment: dict | None):
    """refracted_nee.py's configuration when the scene is what it renders (one analytic sphere
    with one homogeneous medium, point lights, a constant or no environment), else why not."""
    if len(spheres) != 1 or spheres[0] is None:
        return "it renders exactly one object, an analytic sphere"
    centre, radius, parts = spheres[0]
    if len(parts.layers) != 1 or parts.texture is not None:
        return "it renders one homogeneous medium without a texture"
    if not (1.0 <= parts.eta < 2.0):
        return f"eta {parts.eta} outside [1, 2)"
    if environment is not None and environment.get("type") != "constant":
        return "the environment must be constant (or none)"
    lights = []
    for light in t.get("light", []):
        if light.get("type") != "point":
            return "point lights only"
        radiance = np.array(light.get("color", [1.0, 1.0, 1.0]), dtype=float) * light["intensity"]
        position = np.array(light["position"], dtype=float)
        if np.linalg.norm(position - centre) <= radius:
            return "a light inside the sphere"
        lights.append((position.tolist(), radiance.tolist()))
    layer = parts.layers[0]
    return {"centre": centre.tolist(), "radius": radius, "eta": parts.eta,
            "sigma_t": layer.sigma_t.tolist(), "albedo": layer.albedo.tolist(), "g": layer.g,
            "lights": lights}


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
        if key not in {"name", "obj", "mtl", "generator", "level", "triangles"}:
            raise sc.refuse(f"{mkey}.{key}", "unknown key")
    to_world = mi.ScalarTransform4f(matrix.tolist())
    if "obj" in mesh:
        file = sc.resolve(mesh["obj"])
        if not file.exists():
            raise sc.refuse(f"{mkey}.obj", f"mesh file {file} not found")
        text = file.read_text(errors="replace")
        # `mtl = false`: lucent draws the faces with the object's material alone, and
        # Mitsuba's OBJ loader ignores `mtllib` and `usemtl`, so both see one surface.
        uses_mtl = mesh.get("mtl", True) is not False
        if uses_mtl and any(line.split()[:1] in (["usemtl"], ["mtllib"])
                            for line in text.splitlines()):
            raise sc.refuse(f"{mkey}.obj", f"{file} uses MTL materials (lucent splits it into "
                            "parts with the MTL's Kd, map_Kd and norm); not converted (`mtl = "
                            "false` draws it with the object's material alone)")
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


@dataclass
class Layer:
    """One homogeneous layer of a material's medium, per scene unit."""

    medium: dict  # the Mitsuba `homogeneous` medium
    sigma_t: np.ndarray  # extinction per scene unit, RGB
    albedo: np.ndarray  # sigma_s / sigma_t, RGB
    g: float
    thickness: float | None  # along the normal, scene units; None: the rest of the object


@dataclass
class MaterialParts:
    """What `[[material]]` number `index` is to the truth."""

    bsdf: dict  # the boundary (a surface material when `layers` is empty)
    layers: list  # [Layer], outermost first; empty: an opaque surface
    eta: float
    table: str = ""  # "medium" or "layered": where eta was given
    texture: dict | None = None  # {"file", "texturing", "key"}: a pigment film (below)


# lucent's texturing modes (src/scene/material.rs `Texturing`) as a film at the surface: the
# fraction A^a_in of light entering the medium and A^a_out of light leaving it passes, A the
# albedo texture (linear). `pre-post` is a physical (reciprocal) film of transmittance sqrt(A)
# crossed on the way in and on the way out; `post` and `pre` are the non-reciprocal readings of
# lucent's approximations (A on light leaving only: the albedo multiplies the diffused light at
# the exit pixel; A on light entering only: the albedo goes into the blurred light).
FILM_EXPONENTS = {"pre-post": (0.5, 0.5), "post": (0.0, 1.0), "pre": (1.0, 0.0)}
# lucent's texturing of a profile its material does not write (Texturing::default()).
DEFAULT_TEXTURING = "post"

# `skin-layered` (layered.rs SKIN_LAYERED): (thickness mm, sigma_s' RGB, sigma_a RGB, g),
# epidermis then dermis (None: the semi-infinite rest), and its eta.
SKIN_LAYERED = [
    (0.25, [4.6657, 5.8637, 8.7214], [0.2054, 0.3722, 0.8156], 0.9),
    (None, [2.3329, 2.9318, 4.3607], [0.0339, 0.2629, 0.4627], 0.8),
]
SKIN_LAYERED_ETA = 1.4


def _sigma_s_from_reduced(sigma_s_prime, g):
    # lucent stores sigma_s = sigma_s' / (1 - g), |g| clamped to 0.999.
    one_minus_g = max(1.0 - max(-MAX_ABS_G, min(MAX_ABS_G, g)), 1.0 - MAX_ABS_G)
    return [s / one_minus_g for s in sigma_s_prime]


def material_parts(sc, index, m, notes, texturing_override=None) -> MaterialParts:
    """The truth's view of `[[material]]` number `index`."""
    key = f"material[{index}]"
    known = {"name", "albedo", "specular", "roughness", "albedo_texture", "normal_texture",
             "translucency", "sss", "layered", "layers", "medium"}
    for k in m:
        if k not in known:
            raise sc.refuse(f"{key}.{k}", "unknown key")
    if "normal_texture" in m:
        raise sc.refuse(f"{key}.normal_texture", "normal maps are not converted")
    if "layers" in m:
        raise sc.refuse(f"{key}.layers", "gone from lucent: use [material.layered]")
    layered = m.get("layered")
    if "medium" in m:
        parts = _medium_parts(sc, key, m, notes)
    elif layered is not None:
        parts = _layered_parts(sc, key, m, layered, notes)
    else:
        if "albedo_texture" in m:
            raise sc.refuse(f"{key}.albedo_texture", "a texture on a plain (Lambertian) "
                            "material is not converted (only the pigment film on a medium)")
        for part in ("sss", "translucency"):
            if part in m:
                raise sc.refuse(f"{key}.{part}", f"a [material.{part}] alone describes no "
                                "medium (an SSS profile or GDC 2011's artistic thickness term); "
                                "the truth needs a [material.medium] or [material.layered]")
        specular = m.get("specular", DEFAULT_SPECULAR)
        if specular != 0:
            raise sc.refuse(f"{key}.specular", f"{specular}{' (the default)' if 'specular' not in m else ''}: "
                            "lucent adds a normalised Blinn-Phong lobe (lighting.glsl), which no "
                            "Mitsuba BSDF is; write specular = 0 for a Lambertian truth")
        return MaterialParts({"type": "diffuse", "reflectance": _rgb(m.get("albedo", [0.8] * 3))},
                             [], 1.0)
    if "albedo_texture" in m:
        parts.texture = _film(sc, key, m, parts, notes, texturing_override)
    return parts


def _film(sc, key, m, parts, notes, texturing_override):
    """The albedo texture of a medium as a pigment film at its surface (FILM_EXPONENTS)."""
    tkey = f"{key}.albedo_texture"
    file = sc.resolve(m["albedo_texture"])
    if not file.exists():
        raise sc.refuse(tkey, f"texture file {file} not found")
    if file.suffix.lower() != ".png":
        raise sc.refuse(tkey, f"{file.name}: only PNG (sRGB, 8-bit) albedo textures are converted")
    if parts.eta != 1.0:
        raise sc.refuse(tkey, f"a pigment film on a medium behind a dielectric (eta "
                        f"{parts.eta}) is not converted: the film and the refracting boundary "
                        "would be two interfaces; use eta = 1")
    written = (m.get("sss") or {}).get("texturing")
    mode = texturing_override or written or DEFAULT_TEXTURING
    where = ("--sss-texturing" if texturing_override else
             f"{key}.sss.texturing" if written else
             f"lucent's default for a profile derived from the medium ({DEFAULT_TEXTURING})")
    if mode not in FILM_EXPONENTS:
        raise sc.refuse(f"{key}.sss.texturing", f"unknown texturing {mode!r}")
    a_in, a_out = FILM_EXPONENTS[mode]
    notes.append(f"{key} ({m.get('name')}): albedo_texture {file.name} rendered as a film at "
                 f"the surface passing A^{a_in} of light entering and A^{a_out} of light "
                 f"leaving: texturing {mode!r} ({where})"
                 + ("; the reciprocal, physical film" if mode == "pre-post" else
                    "; non-reciprocal: the exact reading of lucent's mode, not a physical film"))
    return {"file": file, "texturing": mode, "key": tkey, "exponents": (a_in, a_out)}


def _layered_parts(sc, key, m, layered, notes):
    """A `[material.layered]` medium: one or more homogeneous layers (a stack is rendered as
    nested media, `convert`)."""
    lkey = f"{key}.layered"
    for k in layered:
        if k not in {"preset", "layer", "eta", "weights", "units_per_mm", "depth_texture"}:
            raise sc.refuse(f"{lkey}.{k}", "unknown key")
    if "depth_texture" in layered:
        raise sc.refuse(f"{lkey}.depth_texture", "per-texel layer depths are not converted")
    preset, tables = layered.get("preset"), layered.get("layer")
    if (preset is None) == (tables is None):
        raise sc.refuse(lkey, "give a `preset` or [[material.layered.layer]] tables")
    # (sigma_a, sigma_s, g, thickness mm or None) per layer, outermost first.
    raw = []
    if preset == "skin-layered":
        for t, sp, sa, g in SKIN_LAYERED:
            raw.append((sa, _sigma_s_from_reduced(sp, g), g, t))
        default_eta = SKIN_LAYERED_ETA
    elif preset is not None:
        if preset not in JENSEN_2001:
            raise sc.refuse(f"{lkey}.preset", f"unknown preset {preset!r}")
        sigma_s_prime, sigma_a = JENSEN_2001[preset]
        raw.append((sigma_a, list(sigma_s_prime), 0.0, None))
        default_eta = PRESET_ETA
    else:
        for i, layer in enumerate(tables):
            ykey = f"{lkey}.layer[{i}]"
            for k in layer:
                if k not in {"sigma_a", "sigma_s", "sigma_s_prime", "g", "thickness"}:
                    raise sc.refuse(f"{ykey}.{k}", "not converted")
            thickness = layer.get("thickness")
            last = i + 1 == len(tables)
            if thickness == "rest":
                if not last:
                    raise sc.refuse(f"{ykey}.thickness", "\"rest\" only on the last layer "
                                    "(lucent refuses it too)")
                thickness = None
            elif isinstance(thickness, (int, float)) and not isinstance(thickness, bool):
                if last:
                    raise sc.refuse(f"{ykey}.thickness", f"{thickness}: the last layer of a "
                                    "stack must be \"rest\" for the truth (what lies under a "
                                    "finite stack is not defined)")
                if not (thickness >= 0 and math.isfinite(thickness)):
                    raise sc.refuse(f"{ykey}.thickness", f"{thickness} must be >= 0 (mm)")
                thickness = float(thickness)
            else:
                raise sc.refuse(f"{ykey}.thickness", f"{thickness!r}: only a constant in mm "
                                "or \"rest\" is converted (not per-texel \"texture\" depths)")
            g = float(layer.get("g", 0.0))
            if "sigma_s" in layer and "sigma_s_prime" in layer:
                raise sc.refuse(f"{ykey}.sigma_s_prime", "give sigma_s or sigma_s_prime, not both")
            sigma_s = (layer["sigma_s"] if "sigma_s" in layer
                       else _sigma_s_from_reduced(layer["sigma_s_prime"], g))
            raw.append((layer["sigma_a"], sigma_s, g, thickness))
        default_eta = 1.3
    eta = float(layered.get("eta", default_eta))
    units_per_mm = float(layered.get("units_per_mm", DEFAULT_UNITS_PER_MM))
    # Knobs of lucent's approximations, not of the medium: listed, not rendered.
    knobs = [k for k in ("albedo", "specular", "roughness") if k in m]
    knobs += [f"layered.{k}" for k in ("weights",) if k in layered]
    knobs += [k for k in ("sss", "translucency") if k in m]
    if knobs:
        notes.append(f"{key} ({m.get('name')}): {', '.join(knobs)} tune lucent's techniques, "
                     "not the medium: not rendered by the truth")
    layers = [_layer(key, m, i, sa, ss, g, t, units_per_mm, notes)
              for i, (sa, ss, g, t) in enumerate(raw)]
    return MaterialParts(_boundary(eta, notes, key, m), layers, eta, "layered")


def _medium_parts(sc, key, m, notes):
    """A material with `[material.medium]`: the one medium lucent's techniques derive their
    parameters from (src/scene/file/materials.rs `medium`), so the truth renders it; a
    `[material.layered]` beside it is one of lucent's approximations."""
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
        sigma_s = (medium["sigma_s"] if "sigma_s" in medium
                   else _sigma_s_from_reduced(medium["sigma_s_prime"], g))
    # lucent's defaults for a medium: eta 1.3 (presets and coefficients alike), 0.04 units/mm.
    eta = float(medium.get("eta", PRESET_ETA if preset is not None else 1.3))
    units_per_mm = float(medium.get("units_per_mm", DEFAULT_UNITS_PER_MM))
    knobs = [k for k in ("albedo", "specular", "roughness", "layered", "sss", "translucency")
             if k in m]
    if knobs:
        notes.append(f"{key} ({m.get('name')}): {', '.join(knobs)} tune lucent's techniques, "
                     "not the medium: not rendered by the truth")
    layer = _layer(key, m, 0, sigma_a, sigma_s, g, None, units_per_mm, notes)
    return MaterialParts(_boundary(eta, notes, key, m), [layer], eta, "medium")


def _layer(key, m, i, sigma_a, sigma_s, g, thickness_mm, units_per_mm, notes) -> Layer:
    """A homogeneous layer in mm^-1 at `units_per_mm` as a Mitsuba medium per scene unit."""
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
    thickness = None if thickness_mm is None else thickness_mm * units_per_mm
    notes.append(f"{key} ({m.get('name')}): layer {i}: medium sigma_t "
                 f"{np.round(sigma_t, 4).tolist()} per unit, albedo "
                 f"{np.round(albedo, 5).tolist()}, g {g}, thickness "
                 + ("rest" if thickness is None else
                    f"{thickness_mm} mm = {thickness:.6g} units"))
    return Layer(medium, sigma_t, albedo, float(g), thickness)


def _boundary(eta, notes, key, m):
    notes.append(f"{key} ({m.get('name')}): eta {eta} "
                 f"({'null' if eta == 1.0 else 'dielectric'} boundary)")
    if eta == 1.0:
        return {"type": "null"}  # index-matched: no boundary at all
    return {"type": "dielectric", "int_ior": eta, "ext_ior": 1.0}


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
