"""Shadow catchers (Object > Visibility > Shadow Catcher) through the add-on against Cycles
(PyPI bpy 5.x): a box on a catcher floor under a sun and a grey world, with a transparent film
(the matte of the box over black shadows whose alpha is the light the box takes from the
floor: RGBA compared), with an opaque one (the shadow over the world behind the floor), and a
glossy catcher, in which the box's reflection darkens the alpha where it is darker than the
world it hides.

Criteria: each channel's mean within 2%, 8x8 block means within 5% at the 95th percentile
(imgcompare.compare), alpha likewise. Tesela's max depth = Cycles' max bounces + 2.
"""

import json
import math
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from test_addon import result_pixels  # noqa: E402

SIZE = 64
MEAN_TOL = 0.02
BLOCK_TOL = 0.05


def box_on_catcher(floor_mat, box=(0.8, 0.35, 0.1)):
    """A 1 m box (colour `box`, orange clay by default) on a 20 m catcher floor (material `floor_mat()`), a sun from the
    back right casting its shadow across the floor, a grey world; the camera sees floor, box
    and sky."""
    scenes.clear_scene()
    floor = scenes.add_quad("Floor", [(-10, -10, 0), (10, -10, 0), (10, 10, 0), (-10, 10, 0)],
                            floor_mat())
    floor.is_shadow_catcher = True
    scenes.add_box("Box", (-0.5, -0.5, 0.0), (0.5, 0.5, 1.0),
                   scenes.lambert("Clay", box))
    scenes.add_sun_light("Sun", (-0.6, -0.4, -0.5), 3.0)
    world = bpy.context.scene.world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scenes.add_camera((0.3, -3.2, 1.6), (0.2, 0.4, 0.3), fov=math.radians(50.0))
    return bpy.context.scene


def diffuse_floor():
    return scenes.lambert("Floor", (0.8, 0.8, 0.8))


def glossy_floor():
    return scenes.material("Polished", base_color=(0.8, 0.8, 0.8), roughness=0.1)


# (id, floor material, box colour, film_transparent, spp); the glossy floor mirrors a dark box,
# darker than the sky it hides.
CASES = [
    ("transparent", diffuse_floor, (0.8, 0.35, 0.1), True, 256),
    ("opaque", diffuse_floor, (0.8, 0.35, 0.1), False, 256),
    ("glossy_transparent", glossy_floor, (0.05, 0.05, 0.05), True, 256),
]


def _render_both(tmp_path, monkeypatch, tesela_bin, floor_mat, box, transparent, spp):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = box_on_catcher(floor_mat, box)
    scenes.configure_cycles(scene, SIZE, SIZE, spp, 4, seed=7)
    scene.render.film_transparent = transparent
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", spp, 6, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return ref, result_pixels(tmp_path)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_shadow_catcher_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, floor_mat, box, transparent, spp = case
    ref, got = _render_both(tmp_path, monkeypatch, tesela_bin, floor_mat, box, transparent, spp)
    assert ref.mean() > 0.01, "the Cycles reference is empty: the scene is broken"
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"{name}: {result}")
    if transparent:
        a_ref, a_got = ref[..., 3], got[..., 3]
        # Sky (alpha 0), shadow (partial) and box (1) are all in the frame.
        assert 0.1 < a_ref.mean() < 0.9, a_ref.mean()
        assert np.mean((a_ref > 0.05) & (a_ref < 0.95)) > 0.05, "no partial (shadow) alpha"
        alpha = imgcompare.compare(np.repeat(a_got[..., None], 3, -1),
                                   np.repeat(a_ref[..., None], 3, -1),
                                   mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
        print(f"{name} alpha: {alpha}")
        assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
        assert alpha.ok, f"{name}: alpha differs from Cycles': {alpha}"
    else:
        assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
        assert np.all(got[..., 3] == 1.0), "an opaque film has alpha 1 everywhere"


def test_shadow_catcher_is_exported(addon, tmp_path):  # noqa: F811
    """tesela_object.shadow_catcher marks the catcher (and instances of a catcher instancer);
    other objects carry nothing, and nothing is reported."""
    box_on_catcher(diffuse_floor)
    path = tmp_path / "c.gltf"
    from blender_addon import export
    res = export.write_gltf(bpy.context.evaluated_depsgraph_get(), str(path), width=8, height=8)
    assert not any("shadow catcher" in w for w in res.warnings), res.warnings
    doc = json.loads(path.read_text(encoding="utf-8"))
    flags = {n["name"]: n.get("extras", {}).get("tesela_object", {}).get("shadow_catcher")
             for n in doc["nodes"] if "mesh" in n}
    assert flags == {"Floor": True, "Box": None}, flags


def test_shadow_catcher_pass_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch):
    """View Layer > Passes > Shadow Catcher (view_layer.cycles.use_pass_shadow_catcher): the
    pass (the shadow over white) and Combined, which becomes the matte alone (the box over
    transparency), both as Cycles writes them."""
    from test_passes_cycles import pass_of, render_multilayer

    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = box_on_catcher(diffuse_floor)
    scenes.configure_cycles(scene, SIZE, SIZE, 256, 4, seed=7)
    scene.render.film_transparent = True
    scene.view_layers[0].cycles.use_pass_shadow_catcher = True
    ref = render_multilayer(tmp_path / "cycles.exr")
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", 256, 6, 1
    got = render_multilayer(tmp_path / "tesela.exr")
    for name in ("Shadow Catcher", "Combined"):
        r, g = pass_of(ref, name), pass_of(got, name)
        rgb = imgcompare.compare(g[..., :3], r[..., :3], mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
        print(f"{name}: {rgb}")
        assert rgb.ok, f"{name}: Tesela (add-on) vs Cycles: {rgb}"
    shadow = pass_of(ref, "Shadow Catcher")[..., :3].mean(axis=-1)
    assert np.mean(shadow < 0.9) > 0.05, "the Cycles pass shows no shadow: the scene is broken"
