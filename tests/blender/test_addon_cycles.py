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

from test_addon import result_pixels  # noqa: E402

SIZE = 64


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


def textured_plane(float_image=False, interpolation="Linear"):
    """A sun-lit plane whose Lambertian base colour is an image texture (generated in code: an
    8-bit sRGB image, or a 32-bit float linear one), repeated twice across the plane."""
    import numpy as np
    info = scenes.light_over_plane("sun", with_box=False)
    plane = bpy.data.objects["Plane"]
    mesh = plane.data
    uv = mesh.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", [0, 0, 2, 0, 2, 2, 0, 2])
    w, h = 16, 12
    img = bpy.data.images.new("Checker", w, h, alpha=True, float_buffer=float_image)
    yy, xx = np.mgrid[0:h, 0:w]
    px = np.ones((h, w, 4), dtype=np.float32)
    px[..., 0] = 0.15 + 0.8 * (xx / (w - 1))
    px[..., 1] = np.where((xx // 4 + yy // 4) % 2 == 0, 0.9, 0.1)
    px[..., 2] = 0.2 + 0.6 * (yy / (h - 1))
    if not float_image:
        img.colorspace_settings.name = "sRGB"
    img.pixels.foreach_set(px.ravel())
    img.update()
    mat = plane.data.materials[0]
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = interpolation
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
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
    ("texture_srgb8_closest-direct_mis", lambda: textured_plane(interpolation="Closest"), 0,
     "direct_mis", 64),
    # Cycles interpolates 8-bit sRGB textures in sRGB and decodes afterwards
    # (NODE_IMAGE_COMPRESS_AS_SRGB); so does Tesela, as glTF images are 8-bit files.
    ("texture_srgb8_linear-direct_mis", textured_plane, 0, "direct_mis", 64),
    # A float image travels unclipped in TESELA_images and is filtered linearly, as Cycles does.
    ("texture_float-direct_mis", lambda: textured_plane(float_image=True), 0, "direct_mis", 64),
    ("emissive_sphere-direct_mis", lambda: scenes.emissive_sphere(), 0, "direct_mis", 256),
]


def _case_id(c):
    return (c.values[0] if hasattr(c, "values") else c)[0]


@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_addon_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build, bounces, integrator, spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = build()
    scene = info.scene
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))

    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = integrator, spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
