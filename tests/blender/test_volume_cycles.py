"""Absorbing volumes (a material's Volume input: Volume Absorption) against Cycles (PyPI bpy 5.x),
through the add-on: tinted glass whose colour deepens with thickness, and a volume-only box that
casts a coloured shadow."""

import math

import bpy
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles


def _absorption(nt, out, color, density):
    vol = nt.nodes.new("ShaderNodeVolumeAbsorption")
    vol.inputs["Color"].default_value = (*color, 1.0)
    vol.inputs["Density"].default_value = density
    nt.links.new(vol.outputs[0], out.inputs["Volume"])


def _stage():
    """A white floor and back wall under a sun and a dim grey world."""
    scenes.clear_scene()
    floor = scenes.lambert("Floor", (0.8, 0.8, 0.8))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    scenes.add_quad("Back", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)],
                    scenes.lambert("Wall", (0.7, 0.7, 0.7)))
    scenes.add_sun_light("Sun", (0.3, 0.5, -0.8), 3.0)
    world = bpy.context.scene.world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    scenes.add_camera((0.0, -4.0, 2.2), (0.0, 0.3, 0.5), fov=math.radians(50.0))


def tinted_glass():
    """A glass ball (IOR 1.45) with a blue-green absorbing interior in front of the wall: the
    colour deepens towards the centre, where the path inside is longest."""
    _stage()
    mat = scenes.glass("Tinted", ior=1.45)
    nt = mat.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    _absorption(nt, out, (0.2, 0.7, 0.9), 1.5)
    scenes.add_sphere("Ball", (0.0, 0.0, 0.7), 0.7, mat)
    return scenes.SceneInfo(bpy.context.scene, "tinted_glass")


def absorbing_box():
    """A box with only a volume (no surface shader: rays pass its faces) over the floor: the
    floor seen through it and its shadow are tinted by exp(-sigma t)."""
    _stage()
    mat = bpy.data.materials.new("Smoke")
    scenes._use_nodes(mat)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    _absorption(nt, out, (0.9, 0.4, 0.1), 1.2)
    # Lifted off the floor: a face coplanar with the floor would tie with it.
    scenes.add_box("Box", (-0.7, -0.5, 0.02), (0.7, 0.5, 1.0), mat)
    return scenes.SceneInfo(bpy.context.scene, "absorbing_box")


CASES = [
    ("tinted_glass", tinted_glass, 8, "path_mis", 512),
    ("absorbing_box", absorbing_box, 4, "path_mis", 512),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_absorbing_volume_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)
