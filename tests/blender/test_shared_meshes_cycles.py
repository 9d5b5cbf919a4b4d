"""Objects sharing one mesh datablock through the add-on: Alt+D duplicates export one glTF mesh
placed by a node per object (an object with modifiers gets its own), objects whose material slot
is linked to the Object get a glTF mesh naming the same accessors with their own material, and
Tesela's render of such an override agrees with Cycles (per-channel means within 2%, 8x8 block
means within 5% at the 95th percentile)."""

import json
import os
import sys
from pathlib import Path

import bpy
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from blender_addon.export.gltf import write_gltf  # noqa: E402
from test_addon import result_pixels  # noqa: E402

SIZE = 64


def linked_boxes():
    """The lit plane and three boxes on one mesh: Box, Box.001 (Alt+D) and Box.002 (Alt+D) whose
    slot is linked to the Object and holds a red material."""
    info = scenes.light_over_plane("point", with_box=False)
    box = scenes.add_box("Box", (-0.25, -0.25, 0.0), (0.25, 0.25, 0.5),
                         scenes.lambert("Grey", (0.6, 0.6, 0.6)))
    box.location = (-0.9, 0.0, 0.0)
    copies = []
    for k, x in enumerate((0.0, 0.9)):
        c = box.copy()  # Alt+D: the copy shares box.data
        c.location = (x, 0.0, 0.0)
        bpy.context.scene.collection.objects.link(c)
        copies.append(c)
    red = copies[1]
    red.material_slots[0].link = "OBJECT"
    red.material_slots[0].material = scenes.lambert("Red", (0.8, 0.1, 0.05))
    return info, box, copies


def export(tmp_path):
    path = tmp_path / "shared.gltf"
    write_gltf(bpy.context.evaluated_depsgraph_get(), str(path), width=SIZE, height=SIZE)
    return json.loads(path.read_text())


def placed(doc, name):
    """The glTF mesh the node of object `name` places."""
    return doc["meshes"][next(n["mesh"] for n in doc["nodes"] if n.get("name") == name)]


def test_linked_duplicates_share_one_mesh_and_overrides_share_its_accessors(addon, tmp_path):
    info, box, copies = linked_boxes()
    sub = box.copy()  # a linked duplicate with a modifier evaluates its own mesh
    sub.location = (0.0, 1.0, 0.0)
    sub.modifiers.new("Bevel", "BEVEL")
    bpy.context.scene.collection.objects.link(sub)
    doc = export(tmp_path)
    grey, dup, red, bevel = (placed(doc, o.name) for o in (box, copies[0], copies[1], sub))
    assert dup is grey, "Alt+D duplicates place one glTF mesh"
    assert red is not grey and red["primitives"][0]["attributes"] == grey["primitives"][0]["attributes"]
    assert red["primitives"][0]["indices"] == grey["primitives"][0]["indices"]
    mats = [doc["materials"][m["primitives"][0]["material"]]["name"] for m in (grey, red)]
    assert mats == ["Grey", "Red"]
    assert bevel["primitives"][0]["attributes"]["POSITION"] != grey["primitives"][0]["attributes"]["POSITION"]
    # Plane, the box geometry (twice: grey and red), the bevelled box.
    assert len(doc["meshes"]) == 4, [m["name"] for m in doc["meshes"]]
    positions = {p["attributes"]["POSITION"] for m in doc["meshes"] for p in m["primitives"]}
    assert len(positions) == 3


def test_object_linked_material_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info, _, _ = linked_boxes()
    scene = info.scene
    spp = 256
    scenes.configure_cycles(scene, SIZE, SIZE, spp, 0, seed=7)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", spp, 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    try:
        assert bpy.ops.render.render() == {"FINISHED"}
    finally:  # the scene outlives the module: later tests expect the default settings
        for k in ("integrator", "samples", "max_depth", "seed", "threads"):
            t.property_unset(k)
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    print(f"object-linked material: {result}")
    assert result.ok, f"object-linked material: Tesela (add-on) vs Cycles: {result}"
    # The red box is red in both: its pixels' red channel dominates.
    red = got[..., 0] > 2.0 * got[..., 1] + 0.02
    assert red.sum() > 20, "the override shows"
    assert (ref[red][:, 0] > ref[red][:, 1]).mean() > 0.9
