"""Khronos glTF samples imported into Blender with its own importer (``import_scene.gltf``), as
an artist brings in an asset, then rendered by Cycles and by Tesela through the add-on.

What the importer builds is Blender's idea of glTF: Principled BSDFs fed by Separate Color,
Normal Map, Mapping (texture transforms), Math (specular textures), Color Attribute nodes,
Volume Absorption for KHR_materials_volume, and objects without any material (the Cameras
sample), which Cycles shades with its default surface. The scene gets a camera framing the
model, an area light and a grey world.

Criteria as tests/blender/test_lights_cycles.py (means within 2%, 8x8 blocks within 5% at the
95th percentile, edges locally). Skips when ../shared/gltf-samples is absent.
"""

import math
from pathlib import Path

import bpy
import mathutils
import numpy as np
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles

SAMPLES = Path(__file__).resolve().parents[3] / "shared" / "gltf-samples"


def _sample_file(name):
    for variant in ("glTF", "glTF-Binary", "glTF-Embedded"):
        folder = SAMPLES / name / variant
        if folder.is_dir():
            files = sorted(p for p in folder.iterdir() if p.suffix in (".gltf", ".glb"))
            if files:
                return files[0]
    return None


def imported(name):
    """The sample imported, framed by a camera from the front right and above, with an area
    light over the camera's left shoulder and a dim grey world."""
    path = _sample_file(name)
    if path is None:
        pytest.skip(f"glTF sample {name} not found under {SAMPLES}")

    def build():
        scenes.clear_scene()
        bpy.ops.import_scene.gltf(filepath=str(path))
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for ob in list(bpy.context.scene.objects):
            if ob.type in ("CAMERA", "LIGHT"):
                bpy.data.objects.remove(ob)
            elif ob.type == "MESH":
                for corner in ob.bound_box:
                    w = np.array(ob.matrix_world @ mathutils.Vector(corner))
                    lo, hi = np.minimum(lo, w), np.maximum(hi, w)
        centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) / 2
        scenes.add_camera(tuple(centre + np.array([0.6, -2.2, 0.9]) * radius), tuple(centre),
                          fov=math.radians(40.0))
        scenes.add_area_light("Key", tuple(centre + np.array([-1.5, -1.5, 2.0]) * radius),
                              tuple(centre), 300.0 * radius * radius, radius)
        world = bpy.context.scene.world
        bg = world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (0.5, 0.5, 0.55, 1.0)
        bg.inputs["Strength"].default_value = 0.6
        return scenes.SceneInfo(bpy.context.scene, name)
    return build


# (sample, Cycles max bounces, Tesela integrator, spp)
CASES = [
    ("Cameras", 2, "path_mis", 128),                  # no material: Cycles' default surface
    ("SpecularTest", 2, "path_mis", 512),             # Specular IOR Level and (black) tints
    ("TextureTransformTest", 2, "path_mis", 128),     # Mapping nodes
    ("TextureSettingsTest", 2, "path_mis", 128),      # extension modes, double-sidedness
    ("NegativeScaleTest", 2, "path_mis", 128),
    ("EmissiveStrengthTest", 2, "path_mis", 128),
    ("BoxVertexColors", 2, "path_mis", 128),          # Color Attribute
    ("IridescenceSuzanne", 2, "path_mis", 512),
    ("OrientationTest", 2, "path_mis", 128),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_imported_sample_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    name, bounces, integrator, spp = case
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch,
                       (name, imported(name), bounces, integrator, spp))
