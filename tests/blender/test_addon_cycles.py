"""Tesela through the add-on (F12 path: bpy.ops.render.render with engine TESELA, the add-on's
own glTF writer, the pipe) against Cycles on the same Blender scene.

Criteria (imgcompare.compare): each channel's global mean within 3%, 8x8 block means within 10%
at the 95th percentile. Tesela's max depth = Cycles' max bounces + 2. Needs the renderer binary
(conftest.py's `tesela_bin`).
"""

import math
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

import blender_addon  # noqa: E402
from blender_addon import engine as tesela_engine  # noqa: E402
from test_addon import result_pixels  # noqa: E402

SIZE = 64


@pytest.fixture(scope="module")
def addon():
    registered = tesela_engine.TeselaRenderEngine.is_registered
    if not registered:
        blender_addon.register()
    yield
    if not registered and tesela_engine.TeselaRenderEngine.is_registered:
        blender_addon.unregister()


def area_over_plane():
    info = scenes.light_over_plane("point")
    bpy.data.objects.remove(bpy.data.objects["Point"], do_unlink=True)
    scenes.add_area_light("Area", (0.3, -0.2, 1.8), (0.2, 0.1, 0.0), 150.0, 0.8)
    return info


def rect_area_over_plane():
    info = scenes.light_over_plane("point")
    bpy.data.objects.remove(bpy.data.objects["Point"], do_unlink=True)
    ob = scenes.add_area_light("Area", (0.0, 0.0, 2.0), (0.0, 0.3, 0.0), 120.0, 1.2)
    ob.data.shape = "RECTANGLE"
    ob.data.size_y = 0.5
    return info


def disk_area_over_plane():
    info = scenes.light_over_plane("point")
    bpy.data.objects.remove(bpy.data.objects["Point"], do_unlink=True)
    ob = scenes.add_area_light("Area", (0.0, -0.5, 2.0), (0.0, 0.0, 0.0), 120.0, 1.0)
    ob.data.shape = "DISK"
    return info


def world_colour():
    """A plane and a box under a constant world (no other light)."""
    info = scenes.light_over_plane("point")
    bpy.data.objects.remove(bpy.data.objects["Point"], do_unlink=True)
    world = info.scene.world
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.6, 0.7, 0.9, 1.0)
    bg.inputs["Strength"].default_value = 1.5
    return info


def _needs(datablock, attr):
    if not hasattr(datablock, attr):
        pytest.skip("Blender %s lights have no '%s'" % (bpy.app.version_string, attr))


def area_unnormalized():
    """4.x 'Normalize' off: Cycles keeps the radiance of a 1 m^2 light of that power."""
    info = area_over_plane()
    light = bpy.data.lights["Area"]
    _needs(light, "normalize")
    light.normalize = False
    ob = bpy.data.objects["Area"]
    ob.scale = (1.5, 0.5, 1.0)  # the object's scale changes the area too
    return info


def point_exposure_temperature():
    """4.x exposure (power * 2^exposure) and blackbody colour."""
    info = scenes.light_over_plane("point")
    light = bpy.data.lights["Point"]
    _needs(light, "exposure")
    light.exposure = 1.5
    light.use_temperature = True
    light.temperature = 3500.0
    return info


# (id, builder, Cycles max_bounces, Tesela integrator, spp)
CASES = [
    ("cornell-direct_mis", lambda: scenes.cornell_box(), 0, "direct_mis", 256),
    ("cornell-path_mis", lambda: scenes.cornell_box(), 8, "path_mis", 1024),
    ("cornell_spheres-path_mis", lambda: scenes.cornell_box(spheres=True), 8, "path_mis", 1024),
    ("point-direct_mis", lambda: scenes.light_over_plane("point"), 0, "direct_mis", 64),
    ("spot-direct_mis", lambda: scenes.light_over_plane("spot"), 0, "direct_mis", 64),
    ("spot_blend0.3-direct_mis", lambda: scenes.light_over_plane("spot", spot_blend=0.3), 0,
     "direct_mis", 64),
    ("sun-direct_mis", lambda: scenes.light_over_plane("sun"), 0, "direct_mis", 64),
    ("sun-path_mis", lambda: scenes.light_over_plane("sun"), 4, "path_mis", 256),
    ("area_square-direct_mis", area_over_plane, 0, "direct_mis", 256),
    ("area_rectangle-direct_mis", rect_area_over_plane, 0, "direct_mis", 256),
    ("area_disk-direct_mis", disk_area_over_plane, 0, "direct_mis", 256),
    ("area_unnormalized_scaled-direct_mis", area_unnormalized, 0, "direct_mis", 256),
    ("point_exposure_temperature-direct_mis", point_exposure_temperature, 0, "direct_mis", 64),
    ("world-path_mis", world_colour, 4, "path_mis", 512),
    ("emissive_sphere-direct_mis", lambda: scenes.emissive_sphere(), 0, "direct_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_addon_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build, bounces, integrator, spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = build()
    scene = info.scene
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))

    scene.render.engine = "TESELA"
    t = scene.tesela
    t.integrator, t.samples, t.max_depth, t.seed = integrator, spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
