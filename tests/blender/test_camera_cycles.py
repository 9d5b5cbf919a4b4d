"""Blender cameras through the add-on (TESELA_camera) against Cycles on the same scene: depth of
field with a polygonal, rotated, anamorphic bokeh and a focus object, lens shift on a wide image,
an orthographic camera with vertical sensor fit and shift, Window texture coordinates (a camera projection,
perspective and orthographic, shifted), non-square pixels, clip start and end, and panoramic cameras
(fisheye equisolid, equidistant and a partial equirectangular).

Criteria (imgcompare.compare): each RGB channel's mean within 2%, 8x8 block means within 5% at
the 95th percentile, and the mean alpha (an opaque film: 1 also outside a fisheye's circle). Small renders (96x64), direct light only. Needs the renderer binary (conftest.py).
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

W, H = 96, 64


def lit_scene(world=0.0):
    """The sun-lit plane and box of scenes.light_over_plane, a few small bright spheres (bokeh
    sources) at several depths, and optionally a constant grey world."""
    info = scenes.light_over_plane("sun")
    glow = scenes.emitter("Glow", (1.0, 0.8, 0.5), 40.0)
    for i, p in enumerate([(0.9, -1.5, 0.9), (-1.2, 1.5, 0.4), (0.4, 0.6, 1.2), (1.6, 2.2, 0.3)]):
        scenes.add_sphere("Dot%d" % i, p, 0.06, glow, segments=16, rings=8)
    if world:
        bg = info.scene.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (0.5, 0.6, 0.8, 1.0)
        bg.inputs["Strength"].default_value = world
    return info


def camera():
    return bpy.context.scene.camera.data


def dof_hexagon():
    """Bright dots between the camera and the focus object (the box, 5.6 m away) blur into
    hexagons 15-30 px across; the floor and box edges blur a little."""
    info = lit_scene()
    glow = scenes.emitter("Bokeh", (0.6, 0.9, 1.0), 300.0)
    for i, p in enumerate([(-0.45, -3.0, 2.35), (0.35, -2.7, 2.1), (0.05, -2.2, 1.75)]):
        scenes.add_sphere("Near%d" % i, p, 0.025, glow, segments=12, rings=6)
    cam = camera()
    cam.dof.use_dof = True
    cam.dof.focus_object = bpy.data.objects["Box"]  # resolved along the view axis
    cam.dof.aperture_fstop = 0.1
    cam.dof.aperture_blades = 6
    cam.dof.aperture_rotation = math.radians(20.0)
    cam.dof.aperture_ratio = 1.4
    return info


def bokeh_hexagon():
    """One small bright sphere 1 m from the camera on black, the focus at 10 m: its image is
    the aperture, a rotated hexagon squeezed by the anamorphic ratio, about 28 x 40 px."""
    scene = scenes.clear_scene()
    scenes.add_sphere("Dot", (0.08, -3.0, 1.05), 0.03,
                      scenes.emitter("Bokeh", (1.0, 0.9, 0.7), 100.0), segments=16, rings=8)
    scenes.add_camera((0.0, -4.0, 1.0), (0.0, 0.0, 1.0), fov=math.radians(50.0))
    dof = camera().dof
    dof.use_dof = True
    dof.focus_distance = 10.0
    dof.aperture_fstop = 0.12
    dof.aperture_blades = 6
    dof.aperture_rotation = math.radians(20.0)
    dof.aperture_ratio = 1.4
    return scenes.SceneInfo(scene, "bokeh")


def lens_shift():
    info = lit_scene()
    camera().shift_x = 0.18
    camera().shift_y = -0.12
    return info


def ortho_vertical_shift():
    info = lit_scene()
    cam = camera()
    cam.type = "ORTHO"
    cam.ortho_scale = 4.0
    cam.sensor_fit = "VERTICAL"
    cam.shift_x = 0.1
    return info


def window_projection(ortho):
    """Every surface shows a checker through Window coordinates (a camera projection, as for
    a matte painting) with the lens shifted: the squares stay square to the frame whatever
    the geometry; orthographic with vertical sensor fit too."""
    info = lit_scene()
    mat = bpy.data.materials.new("Projected")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    coords = nt.nodes.new("ShaderNodeTexCoord")
    checker = nt.nodes.new("ShaderNodeTexChecker")
    checker.inputs["Scale"].default_value = 6.0
    emission = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(coords.outputs["Window"], checker.inputs["Vector"])
    nt.links.new(checker.outputs["Color"], emission.inputs["Color"])
    nt.links.new(emission.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    for ob in bpy.context.scene.objects:
        if ob.type == "MESH":
            ob.data.materials.clear()
            ob.data.materials.append(mat)
    cam = camera()
    cam.shift_x, cam.shift_y = 0.12, -0.08
    if ortho:
        cam.type = "ORTHO"
        cam.ortho_scale = 5.0
        cam.sensor_fit = "VERTICAL"
    return info


def pixel_aspect(x, y, then=lit_scene):
    """Non-square pixels (Format > Aspect X/Y): the image's shape is width·x : height·y, which
    picks AUTO's fitted dimension (96x64 pixels twice as tall are a portrait frame) and the other
    dimension's extent; with a lens shift."""
    info = then()
    info.scene.render.pixel_aspect_x, info.scene.render.pixel_aspect_y = x, y
    camera().shift_x = 0.1
    return info


def clip_start():
    """The near clip plane cuts away the front of the floor (the world shows there)."""
    info = lit_scene(world=0.5)
    camera().clip_start = 5.0
    return info


def clip_end():
    """The far clip plane (5.8 m, the scene's centre is 5.7 m away) cuts away the back of the
    floor and half the box: the world shows behind them; with a near clip too."""
    info = lit_scene(world=0.5)
    camera().clip_start = 1.0
    camera().clip_end = 5.8
    return info


def _pano(kind, **settings):
    info = lit_scene(world=0.6)
    ob = bpy.context.scene.camera
    ob.location = (0.0, -3.0, 1.2)
    scenes._aim(ob, (0.0, 0.0, 0.6))
    cam = ob.data
    cam.type = "PANO"
    target = cam if hasattr(cam, "panorama_type") else cam.cycles  # 4.0 moved them
    target.panorama_type = kind
    for k, v in settings.items():
        setattr(target, k, v)
    return info


CASES = [
    ("dof_hexagon_anamorphic_focus_object", dof_hexagon, 1024),
    ("bokeh_hexagon_anamorphic", bokeh_hexagon, 2048),
    ("lens_shift", lens_shift, 256),
    ("ortho_vertical_shift", ortho_vertical_shift, 256),
    ("window_projection_perspective", lambda: window_projection(False), 64),
    ("window_projection_orthographic", lambda: window_projection(True), 64),
    ("pixel_aspect_wide", lambda: pixel_aspect(1.6, 1.0), 256),
    ("pixel_aspect_tall_auto_fit", lambda: pixel_aspect(1.0, 2.0), 256),
    ("pixel_aspect_window_projection",
     lambda: pixel_aspect(1.0, 1.5, lambda: window_projection(False)), 64),
    ("clip_start", clip_start, 256),
    ("clip_end", clip_end, 256),
    ("fisheye_equisolid", lambda: _pano("FISHEYE_EQUISOLID", fisheye_lens=8.0,
                                        fisheye_fov=math.radians(180.0)), 256),
    ("fisheye_equidistant", lambda: _pano("FISHEYE_EQUIDISTANT",
                                          fisheye_fov=math.radians(160.0)), 256),
    ("equirectangular_partial", lambda: _pano("EQUIRECTANGULAR",
                                              latitude_min=math.radians(-60.0),
                                              latitude_max=math.radians(30.0),
                                              longitude_min=math.radians(-120.0),
                                              longitude_max=math.radians(100.0)), 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_camera_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build, spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = build()
    scene = info.scene
    scenes.configure_cycles(scene, W, H, spp, 0, seed=3)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))

    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", spp, 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    alpha = (float(got[..., 3].mean()), float(ref[..., 3].mean()))
    print(f"{name}: {result}; mean alpha {alpha[0]:.4f} (Cycles {alpha[1]:.4f})")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
    assert abs(alpha[0] - alpha[1]) <= 0.02 * max(alpha[1], 1e-3), f"{name}: alpha {alpha}"
