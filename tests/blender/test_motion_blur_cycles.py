"""Motion blur through the add-on against Cycles (per-channel means within 2%, 8x8 block
means within 5% at the 95th percentile): a cube crossing the view (shutter 0.5 and 1 frame,
Position Center, Start and End), a propeller-like plate turning 90 degrees over the shutter,
and a panning camera. Without motion blur, a moving scene exports and renders exactly as
before (no TESELA_motion, no time drawn), and the frame is restored after sampling the
shutter."""

import json
import math
import os

import bpy
import pytest

import scenes
from test_addon import result_pixels
from test_instances_cycles import assert_agrees_with_cycles

SPP = 256


def _linear(obj):
    """Keyframes of `obj` interpolate linearly (the motion is then exactly what was keyed)."""
    action = obj.animation_data.action
    fcurves = getattr(action, "fcurves", None)
    if fcurves is None:  # Blender 5.0: layered actions
        fcurves = [fc for layer in action.layers for strip in layer.strips
                   for bag in strip.channelbags for fc in bag.fcurves]
    for fc in fcurves:
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"


def _key(obj, path, frames):
    """Keys `path` of `obj` at {frame: value}, linear, and puts the scene at frame 1."""
    for frame, value in frames.items():
        setattr(obj, path, value)
        obj.keyframe_insert(path, frame=frame)
    _linear(obj)
    bpy.context.scene.frame_set(1)


def _lit_floor():
    """A dark floor (albedo 0.15, 8 m square) under a sun, two still boxes and a camera close
    enough that moving objects cover much of the 64-pixel frame."""
    scene = scenes.clear_scene()
    scenes.add_quad("Plane", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)],
                    scenes.lambert("Floor", (0.15, 0.15, 0.15)))
    scenes.add_sun_light("Sun", (-0.4, 0.3, -1.0), 3.0)
    scenes.add_box("Left", (-1.6, 0.6, 0.0), (-1.1, 1.1, 0.5), scenes.lambert("L", (0.2, 0.8, 0.2)))
    scenes.add_box("Right", (1.1, -0.4, 0.0), (1.5, 0.0, 0.8), scenes.lambert("R", (0.9, 0.3, 0.2)))
    scenes.add_camera((0.0, -3.2, 2.6), (0.0, 0.0, 0.3), fov=math.radians(50.0))
    return scenes.SceneInfo(scene, "motion_floor", {})


def moving_cube():
    """A white 0.6 m cube crossing the view at 2 m per frame (x = -2 at frame 0, +2 at
    frame 2), rendered at frame 1."""
    info = _lit_floor()
    cube = scenes.add_box("Mover", (-0.3, -0.3, 0.0), (0.3, 0.3, 0.6),
                          scenes.lambert("M", (0.9, 0.9, 0.9)))
    _key(cube, "location", {0: (-2.0, 0.0, 0.1), 2: (2.0, 0.0, 0.1)})
    return info


def propeller():
    """A white 2 x 0.25 m plate 0.6 m above the floor turning 90 degrees per frame about z."""
    info = _lit_floor()
    plate = scenes.add_box("Propeller", (-1.0, -0.125, -0.02), (1.0, 0.125, 0.02),
                           scenes.lambert("P", (0.9, 0.9, 0.9)))
    plate.location = (0.0, 0.0, 0.6)
    _key(plate, "rotation_euler", {0: (0.0, 0.0, -math.pi / 2), 2: (0.0, 0.0, math.pi / 2)})
    return info


def camera_pan():
    """The camera turning 8 degrees per frame about the vertical over the boxes."""
    from mathutils import Quaternion

    info = _lit_floor()
    scenes.add_box("Middle", (-0.3, -0.3, 0.0), (0.3, 0.3, 0.6), scenes.lambert("C", (0.9, 0.9, 0.9)))
    cam = bpy.context.scene.camera
    q = cam.rotation_quaternion.copy()  # scenes.add_camera aims it with a quaternion
    turn = {f: Quaternion((0.0, 0.0, 1.0), math.radians(8.0 * (f - 1))) @ q for f in (0, 2)}
    _key(cam, "rotation_quaternion", turn)
    return info


def _blur(scene, shutter, position="CENTER"):
    from blender_addon import compat

    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = shutter
    if hasattr(scene.render, "motion_blur_position"):
        scene.render.motion_blur_position = position
    else:
        scene.cycles.motion_blur_position = position
    assert compat.motion_blur_position(scene) == position


@pytest.fixture
def with_binary(tesela_bin, monkeypatch):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))


@pytest.mark.parametrize("shutter", [0.5, 1.0])
def test_translating_cube_agrees_with_cycles(addon, with_binary, tmp_path, shutter):
    scene = moving_cube().scene
    _blur(scene, shutter)
    assert_agrees_with_cycles(scene, f"cube shutter {shutter}", SPP, tmp_path)
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0


@pytest.mark.parametrize("position", ["START", "END"])
def test_motion_position_agrees_with_cycles(addon, with_binary, tmp_path, position):
    scene = moving_cube().scene
    _blur(scene, 1.0, position)
    assert_agrees_with_cycles(scene, f"cube position {position}", SPP, tmp_path)
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0


def test_rotating_propeller_agrees_with_cycles(addon, with_binary, tmp_path):
    scene = propeller().scene
    _blur(scene, 1.0)
    assert_agrees_with_cycles(scene, "propeller", SPP, tmp_path)


def test_camera_pan_agrees_with_cycles(addon, with_binary, tmp_path):
    scene = camera_pan().scene
    _blur(scene, 1.0)
    assert_agrees_with_cycles(scene, "camera pan", SPP, tmp_path)


def _render_capturing(tmp_path, monkeypatch, name):
    """Renders the scene through the add-on; returns (the glTF text it wrote, the pixels)."""
    from blender_addon import export

    written = {}
    real = export.write_gltf

    def capture(depsgraph, filepath, **kwargs):
        res = real(depsgraph, filepath, **kwargs)
        with open(filepath, encoding="utf-8") as f:
            written["gltf"] = f.read()
        return res

    monkeypatch.setattr(export, "write_gltf", capture)
    assert bpy.ops.render.render() == {"FINISHED"}
    monkeypatch.setattr(export, "write_gltf", real)
    return written["gltf"], result_pixels(tmp_path / name)


def _tesela(scene, spp=16):
    scene.render.engine = "TESELA"
    scenes.configure_cycles(scene, 32, 32, spp, 0, seed=7)
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", spp, 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))


def test_motion_blur_off_renders_as_before(addon, with_binary, tmp_path, monkeypatch):
    """A moving scene with motion blur off: the export is the plain one (the nodes, materials,
    camera and extensions write_gltf gives without an engine, no TESELA_motion) and the frame is untouched; and a
    render with motion blur on where nothing blurs (every object's and the camera's Motion
    Blur off) is bit-identical to it: no time is drawn where nothing moves."""
    scene = moving_cube().scene
    _tesela(scene)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    scene.render.use_motion_blur = False
    text, off = _render_capturing(tmp_path, monkeypatch, "a")
    assert "TESELA_motion" not in text
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0
    from blender_addon import export

    direct = tmp_path / "direct.gltf"
    dg = bpy.context.evaluated_depsgraph_get()
    export.write_gltf(dg, str(direct), width=32, height=32, camera=scene.camera,
                      render_settings=json.loads(text)["extensions"]["TESELA_render"])
    # The render's meshes live in its mesh store's files: compare what is not buffer layout.
    ours, theirs = json.loads(text), json.loads(direct.read_text(encoding="utf-8"))
    for k in ("nodes", "materials", "cameras", "extensions", "extensionsUsed"):
        assert ours.get(k) == theirs.get(k), k

    _blur(scene, 1.0)
    for obj in scene.objects:
        obj.cycles.use_motion_blur = False
    text2, still = _render_capturing(tmp_path, monkeypatch, "b")
    assert "TESELA_motion" not in text2
    assert (off == still).all(), "a render where nothing blurs must not change"
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0


def test_motion_keys_are_exported(addon, with_binary, tmp_path, monkeypatch):
    """With motion blur on, the moving cube's node carries 2^steps + 1 keys over the shutter
    (3 by default, 5 with 2 steps), the still boxes none, and the blurred render differs from
    the still one."""
    scene = moving_cube().scene
    _tesela(scene)
    _blur(scene, 1.0)
    (tmp_path / "a").mkdir()
    text, _ = _render_capturing(tmp_path, monkeypatch, "a")
    doc = json.loads(text)
    keyed = {n["name"]: n["extensions"]["TESELA_motion"] for n in doc["nodes"]
             if "TESELA_motion" in n.get("extensions", {})}
    assert list(keyed) == ["Mover"], keyed
    assert keyed["Mover"]["times"] == [0.0, 0.5, 1.0]
    xs = [m[12] for m in keyed["Mover"]["matrices"]]
    assert xs == pytest.approx([-1.0, 0.0, 1.0], abs=1e-5), xs
    assert "TESELA_motion" in doc["extensionsUsed"]
    scene.objects["Mover"].cycles.motion_steps = 2
    (tmp_path / "b").mkdir()
    text, _ = _render_capturing(tmp_path, monkeypatch, "b")
    keys = [n for n in json.loads(text)["nodes"] if n["name"] == "Mover"][0]
    assert keys["extensions"]["TESELA_motion"]["times"] == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert scene.frame_current == 1 and scene.frame_subframe == 0.0
