"""Benchmark scenes for bench/peers.py, built once as numpy arrays and written to each peer's format.

A scene is triangle meshes (world-space vertex positions in metres, Blender's z-up axes, counter-
clockwise faces, no vertex normals: every peer shades with the flat geometric normal), Lambertian
materials (an albedo, or an emitted radiance on a black surface), and a pinhole camera. This module
needs only numpy; the writers for each peer are:

* ``write_gltf(scene, path, width, height)``: glTF 2.0 for Tesela (y-up: (x, y, z) -> (x, z, -y),
  the axis change Blender's exporter makes), with the conventions of docs/blender-units.md:
  Lambertian = ``KHR_materials_specular.specularFactor 0`` with roughness 1, radiance =
  ``emissiveFactor x KHR_materials_emissive_strength``, ``doubleSided: true`` (two-sided emission,
  as Cycles), camera ``yfov`` from the field of view across the larger image side.
* ``write_ply(mesh, path)``: binary PLY for Mitsuba's ``ply`` shape (z-up kept; Mitsuba takes a
  ``look_at`` camera with an explicit up vector).
* Cycles objects are made from the same arrays in bench/peers.py (it needs ``bpy``).

Scenes:

* ``cornell()``: the 2 m Cornell box of tests/blender/scenes.py (x, y in [-1, 1], z in [0, 2],
  open towards -y; light: a 0.7 m quad of radiance 12 flush in a hole of the ceiling, facing down),
  32 triangles: measures per-sample overhead.
* ``spheres(n)``: the same box with three displaced spheres on and above the floor, about 1.08 M
  triangles at the default resolution: traversal-bound.
"""

from __future__ import annotations

import json
import math
import struct
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

CORNELL_WHITE = (0.725, 0.71, 0.68)
CORNELL_RED = (0.63, 0.065, 0.05)
CORNELL_GREEN = (0.14, 0.45, 0.091)


@dataclass
class Material:
    name: str
    albedo: tuple = (0.0, 0.0, 0.0)
    emission: tuple = (0.0, 0.0, 0.0)  # radiance, W/(m^2 sr), both faces (Mitsuba: front face)

    @property
    def is_emitter(self):
        return max(self.emission) > 0.0


@dataclass
class Mesh:
    name: str
    vertices: np.ndarray  # (n, 3) float32
    faces: np.ndarray  # (m, 3) uint32, counter-clockwise seen from the front
    material: str


@dataclass
class Camera:
    origin: tuple
    target: tuple
    up: tuple = (0.0, 0.0, 1.0)
    fov_deg: float = 38.0  # across the larger image side (Blender's sensor_fit AUTO)


@dataclass
class Scene:
    name: str
    materials: dict
    meshes: list
    camera: Camera
    notes: dict = field(default_factory=dict)

    def triangle_count(self):
        return sum(len(m.faces) for m in self.meshes)


def _quads(name, quads, material):
    """A mesh of quads (4 corners each, counter-clockwise seen from the front), split in two
    triangles each."""
    v = np.asarray(quads, dtype=np.float32).reshape(-1, 3)
    f = []
    for q in range(len(quads)):
        b = 4 * q
        f += [(b, b + 1, b + 2), (b, b + 2, b + 3)]
    return Mesh(name, v, np.asarray(f, dtype=np.uint32), material)


def _box_meshes():
    mats = {
        "white": Material("white", CORNELL_WHITE),
        "red": Material("red", CORNELL_RED),
        "green": Material("green", CORNELL_GREEN),
        "light": Material("light", emission=(12.0, 12.0, 12.0)),
    }
    h = 0.35
    white = [[(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)],  # floor
             [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)]]  # back
    for quad in ([(-1, -1), (-1, 1), (-h, 1), (-h, -1)], [(h, -1), (h, 1), (1, 1), (1, -1)],
                 [(-h, -1), (-h, -h), (h, -h), (h, -1)], [(-h, h), (-h, 1), (h, 1), (h, h)]):
        white.append([(x, y, 2.0) for x, y in quad])  # ceiling around the light's hole
    meshes = [
        _quads("white", white, "white"),
        _quads("left", [[(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)]], "red"),
        _quads("right", [[(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)]], "green"),
        # faces down (-z): its front lights the box
        _quads("light", [[(-h, -h, 2.0), (-h, h, 2.0), (h, h, 2.0), (h, -h, 2.0)]], "light"),
    ]
    return mats, meshes


def _camera():
    return Camera(origin=(0.0, -3.8, 1.0), target=(0.0, 0.0, 1.0), fov_deg=38.0)


def cornell():
    mats, meshes = _box_meshes()
    return Scene("cornell", mats, meshes, _camera(), {"light_radiance": 12.0})


def displaced_sphere(name, center, radius, material, segments, rings, amplitude, seed):
    """A latitude-longitude sphere (``segments`` around, ``rings`` bands, one vertex at each pole)
    whose radius is modulated by a sum of smooth random waves of relative ``amplitude``. Triangles:
    2 * segments * (rings - 1)."""
    rng = np.random.default_rng(seed)
    theta = np.linspace(0.0, math.pi, rings + 1)[1:-1]  # interior latitudes
    phi = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    th, ph = np.meshgrid(theta, phi, indexing="ij")  # (rings-1, segments)
    dirs = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    dirs = dirs.reshape(-1, 3)
    dirs = np.concatenate([[(0.0, 0.0, 1.0)], dirs, [(0.0, 0.0, -1.0)]])
    disp = np.zeros(len(dirs))
    for k in range(12):  # waves of increasing frequency, decreasing amplitude
        freq = 3.0 * 1.6 ** k
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        disp += np.sin(freq * dirs @ d + rng.uniform(0, 2 * math.pi)) / (1.0 + k)
    disp *= amplitude / np.abs(disp).max()
    v = np.asarray(center) + dirs * (radius * (1.0 + disp))[:, None]
    s = segments
    faces = []
    first, last = 0, len(dirs) - 1
    ring = lambda r: 1 + r * s + np.arange(s)  # noqa: E731 (vertex ids of interior ring r)
    a, b = ring(0), np.roll(ring(0), -1)
    faces.append(np.stack([np.full(s, first), b, a], axis=1))  # top cap
    for r in range(rings - 2):
        a, b = ring(r), np.roll(ring(r), -1)
        c, d = ring(r + 1), np.roll(ring(r + 1), -1)
        faces.append(np.stack([a, d, c], axis=1))
        faces.append(np.stack([a, b, d], axis=1))
    a, b = ring(rings - 2), np.roll(ring(rings - 2), -1)
    faces.append(np.stack([np.full(s, last), a, b], axis=1))  # bottom cap
    faces = np.concatenate(faces)[:, ::-1]  # the rows above wind clockwise seen from outside
    return Mesh(name, v.astype(np.float32), np.ascontiguousarray(faces, dtype=np.uint32), material)


def spheres(segments=600, rings=300):
    """The Cornell box with three displaced spheres (default: 3 x 358,800 = 1,076,400 triangles
    plus the box's 16)."""
    mats, meshes = _box_meshes()
    mats["blue"] = Material("blue", (0.2, 0.3, 0.7))
    mats["orange"] = Material("orange", (0.8, 0.45, 0.15))
    meshes += [
        displaced_sphere("sphere_a", (-0.45, 0.3, 0.45), 0.42, "white", segments, rings, 0.08, 1),
        displaced_sphere("sphere_b", (0.5, -0.25, 0.42), 0.36, "blue", segments, rings, 0.1, 2),
        displaced_sphere("sphere_c", (0.1, 0.45, 1.3), 0.3, "orange", segments, rings, 0.12, 3),
    ]
    return Scene("spheres", mats, meshes, _camera())


SCENES = {"cornell": cornell, "spheres": spheres}

# ------------------------------------------------------------------------------------------------
# writers


def look_at_matrix(origin, target, up):
    """The camera-to-world rotation (columns: right, up, backward), looking along -z."""
    o, t, u = (np.asarray(x, dtype=np.float64) for x in (origin, target, up))
    fwd = t - o
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, u)
    right /= np.linalg.norm(right)
    true_up = np.cross(right, fwd)
    return np.stack([right, true_up, -fwd], axis=1)


def quat_from_matrix(m):
    """(x, y, z, w) unit quaternion of a rotation matrix."""
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        w, x, y, z = 0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        w, x, y, z = (m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        w, x, y, z = (m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        w, x, y, z = (m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s
    q = np.array([x, y, z, w])
    return q / np.linalg.norm(q)


_Z_TO_Y_UP = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], dtype=np.float64)  # (x,y,z)->(x,z,-y)


def yfov(fov_deg, width, height):
    """glTF's vertical field of view for a field of view across the larger image side."""
    half = math.radians(fov_deg) / 2
    if width >= height:
        return 2 * math.atan(math.tan(half) * height / width)
    return 2 * half


def write_gltf(scene, path, width, height):
    """Write ``scene`` as glTF 2.0 (``path`` .gltf plus a .bin next to it)."""
    path = Path(path)
    bin_path = path.with_suffix(".bin")
    blob = bytearray()
    accessors, views, meshes, nodes, materials = [], [], [], [], []
    mat_index = {}
    for name, m in scene.materials.items():
        mat_index[name] = len(materials)
        entry = {
            "name": name,
            "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorFactor": [*map(float, m.albedo), 1.0],
                                     "metallicFactor": 0.0, "roughnessFactor": 1.0},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}},
        }
        if m.is_emitter:
            strength = max(m.emission)
            entry["emissiveFactor"] = [float(c / strength) for c in m.emission]
            entry["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
        materials.append(entry)

    def add_view(data, target):
        nonlocal blob
        while len(blob) % 4:
            blob += b"\0"
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                      "target": target})
        blob += data
        return len(views) - 1

    for mesh in scene.meshes:
        v = (mesh.vertices.astype(np.float64) @ _Z_TO_Y_UP.T).astype(np.float32)
        pv = add_view(v.tobytes(), 34962)
        accessors.append({"bufferView": pv, "componentType": 5126, "count": len(v), "type": "VEC3",
                          "min": v.min(axis=0).tolist(), "max": v.max(axis=0).tolist()})
        iv = add_view(mesh.faces.astype(np.uint32).ravel().tobytes(), 34963)
        accessors.append({"bufferView": iv, "componentType": 5125, "count": mesh.faces.size,
                          "type": "SCALAR"})
        meshes.append({"name": mesh.name, "primitives": [{
            "attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1,
            "material": mat_index[mesh.material]}]})
        nodes.append({"name": mesh.name, "mesh": len(meshes) - 1})
    cam = scene.camera
    rot = _Z_TO_Y_UP @ look_at_matrix(cam.origin, cam.target, cam.up)
    nodes.append({"name": "camera", "camera": 0,
                  "translation": (_Z_TO_Y_UP @ np.asarray(cam.origin, float)).tolist(),
                  "rotation": quat_from_matrix(rot).tolist()})
    doc = {
        "asset": {"version": "2.0", "generator": "tesela bench/scenes.py"},
        "extensionsUsed": ["KHR_materials_specular", "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": yfov(cam.fov_deg, width, height), "aspectRatio": width / height,
            "znear": 0.01, "zfar": 100.0}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"uri": bin_path.name, "byteLength": len(blob)}],
    }
    bin_path.write_bytes(bytes(blob))
    path.write_text(json.dumps(doc))
    return path


def write_ply(mesh, path):
    """Binary little-endian PLY of one mesh (float positions, uint32 triangle indices)."""
    v = np.ascontiguousarray(mesh.vertices, dtype="<f4")
    f = np.empty(len(mesh.faces), dtype=[("n", "u1"), ("i", "<u4", 3)])
    f["n"] = 3
    f["i"] = mesh.faces
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(v)}\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {len(f)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    with open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(v.tobytes())
        fh.write(f.tobytes())
    return Path(path)


if __name__ == "__main__":  # quick self-check: triangle counts
    for name, make in SCENES.items():
        s = make()
        print(name, s.triangle_count(), "triangles", struct.calcsize("f"))
