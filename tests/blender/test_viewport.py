"""The add-on's Rendered viewport under bpy 5 headless: the session protocol and client (against
tests/blender/fake_session.py and, when it has the subcommand, the real `tesela session`), the
view-to-camera conversion, and the translation of depsgraph updates into session commands.
What needs a window (drawing, a real SpaceView3D) runs in Blender 3.4's GUI:
test_viewport_blender34.py."""

import json
import math
import os
import struct
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import pytest
from mathutils import Matrix

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
FAKE = HERE / "fake_session.py"
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import blender_addon  # noqa: E402
from blender_addon import export, process  # noqa: E402
from blender_addon.viewport import interactive, session_client, updates  # noqa: E402
from blender_addon.viewport import session_protocol as sp  # noqa: E402
from blender_addon.viewport import view_camera as vc  # noqa: E402

from test_addon import simple_scene, use_nodes  # noqa: E402


@pytest.fixture(scope="module", autouse=True)
def addon():
    if not hasattr(bpy.types.Scene, "tesela"):
        blender_addon.register()
    yield


def wait_for(pred, timeout=10.0):
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        if pred():
            return True
        time.sleep(0.005)
    return pred()


def fake_log(path):
    if not path.exists():
        return []
    return [json.loads(ln) for ln in path.read_text().splitlines() if ln.strip()]


@pytest.fixture
def fake(monkeypatch, tmp_path):
    log = tmp_path / "session-log.jsonl"
    monkeypatch.setenv("TESELA_BINARY", str(FAKE))
    monkeypatch.setenv("FAKE_SESSION_LOG", str(log))
    monkeypatch.delenv("FAKE_SESSION_MODE", raising=False)
    return log


# --------------------------------------------------------------------------------------------
# protocol

def test_command_frame_layout():
    data = sp.command_frame("transform", id=7, node="Cubé", matrix=[1.0] * 16)
    kind, length = struct.unpack_from("<II", data, 0)
    assert kind == 32 and length == len(data) - 8
    (n,) = struct.unpack_from("<I", data, 8)
    assert n == length - 4  # no attachment
    obj = json.loads(data[12:].decode("utf-8"))
    assert obj == {"cmd": "transform", "id": 7, "node": "Cubé", "matrix": [1.0] * 16}
    assert sp.parse_command(data[8:]) == obj


def test_image_frame_decodes_window_and_rows():
    rgba = np.arange(3 * 2 * 4, dtype=np.float32).reshape(2, 3, 4)
    data = sp.image_frame(5, 40, 30, (10, 4, 5, 3), 2, 8, sp.FLAG_LAST, rgba)
    kind, length = struct.unpack_from("<II", data, 0)
    msg = sp.decode(kind, data[8:])
    assert (msg.generation, msg.view_width, msg.view_height) == (5, 40, 30)
    assert (msg.x, msg.y, msg.width, msg.height, msg.pixel_size) == (10, 4, 5, 3, 2)
    assert msg.samples == 8 and msg.last and not msg.denoised
    assert np.array_equal(msg.pixels, rgba)
    with pytest.raises(sp.ProtocolError, match="expected"):
        sp.decode(kind, data[8:-4])
    bad = sp.image_frame(5, 40, 30, (0, 0, 2, 2), 2, 8, 0, rgba)  # 3 columns for 2 pixels
    with pytest.raises(sp.ProtocolError, match="does not fit"):
        sp.decode(sp.IMAGE, bad[8:])


def test_image_placement_on_the_cell_grid():
    from blender_addon.viewport.display import Display

    def image(window, ps, dw, dh, view=(40, 30)):
        return sp.Image(1, view[0], view[1], *window, ps, 1, 0,
                        np.zeros((dh, dw, 4), np.float32))
    # Full resolution: the whole texture, where the window is.
    assert Display.placement(image((3, 5, 10, 6), 1, 10, 6)) == ((3, 5, 10, 6), (0, 0, 1, 1))
    # Pixel size 4, window at (6, 5) 10x7: cells start at (4, 4); 3x2 cells cover 4..16 x 4..12.
    rect, uv = Display.placement(image((6, 5, 10, 7), 4, 3, 2))
    assert rect == (6, 5, 10, 7)
    assert uv == pytest.approx((2 / 12, 1 - 8 / 8, 12 / 12, 1 - 1 / 8))
    # Fewer cells than the window spans: only what they cover is drawn (cells 28..36).
    rect, uv = Display.placement(image((30, 0, 8, 8), 4, 2, 2))
    assert rect == (30, 0, 6, 8) and uv[0] == pytest.approx(2 / 8) and uv[2] == 1.0
    rect, uv = Display.placement(image((29, 0, 11, 8), 4, 2, 2))
    assert rect == (29, 0, 7, 8)


def test_reader_rejects_other_versions_and_programs():
    import io
    r = sp.FrameReader(io.BytesIO(sp.hello_frame(version=2)))
    with pytest.raises(sp.ProtocolError, match="renderer speaks 2, add-on speaks 1"):
        r.read_message()
    r = sp.FrameReader(io.BytesIO(sp.frame(sp.IMAGE, b"x" * 60)))
    with pytest.raises(sp.ProtocolError, match="not a Tesela session"):
        r.read_message()
    stream = io.BytesIO(sp.hello_frame() + sp.frame(99, b"future") + sp.error_frame("view", "bad"))
    r = sp.FrameReader(stream)
    assert isinstance(r.read_message(), sp.Hello)
    err = r.read_message()  # the unknown kind 99 is skipped
    assert isinstance(err, sp.Error) and err.text() == "view: bad"
    assert r.read_message() is None


# --------------------------------------------------------------------------------------------
# the client against the fake session

def test_client_keeps_the_newest_image(fake):
    c = session_client.SessionClient(str(FAKE)).start()
    try:
        c.send("load", path=str(FAKE))
        c.send("view", width=30, height=20, camera={})
        assert wait_for(lambda: c.image is not None and c.image.last)
        first = c.image
        assert first.pixel_size == 1 and first.pixels.shape == (20, 30, 4)
        assert first.pixels[0, 0, 0] == pytest.approx(0.5 / 30)
        assert first.pixels[19, 0, 1] == pytest.approx(19.5 / 20)  # rows top to bottom
        c.send("view", width=16, height=8, camera={})
        assert wait_for(lambda: c.image.generation > first.generation and c.image.last)
        assert c.image.pixels.shape == (8, 16, 4)
        assert c.serial == 4  # two images per view, each one counted
        cmds = [e.get("cmd") for e in fake_log(fake) if "cmd" in e]
        assert cmds == ["load", "view", "view"]
    finally:
        c.close()
    assert c.proc.returncode is not None and c.dead is None


def test_client_collects_error_frames_and_survives(fake, monkeypatch):
    monkeypatch.setenv("FAKE_SESSION_MODE", "error")
    c = session_client.SessionClient(str(FAKE)).start()
    try:
        cid = c.send("material", name="Nope", material={})
        assert wait_for(lambda: c.errors)
        errors = c.take_errors()
        assert [e.text() for e in errors] == ["material: no material named 'Nope'"]
        assert errors[0].id == cid and not errors[0].fatal
        assert c.take_errors() == [] and c.alive()
    finally:
        c.close()


def test_client_reports_a_session_killed_mid_frame(fake, monkeypatch):
    monkeypatch.setenv("FAKE_SESSION_MODE", "die")
    changes = []
    c = session_client.SessionClient(str(FAKE), on_change=lambda: changes.append(1)).start()
    try:
        c.send("load", path=str(FAKE))
        c.send("view", width=8, height=8, camera={})
        assert wait_for(lambda: c.image is not None and c.image.last)
        c.send("view", width=9, height=9, camera={})
        assert wait_for(lambda: c.dead is not None)
        assert "killed by signal SIGKILL" in c.dead and "truncated frame" in c.dead
        assert not c.alive() and changes
        assert c.image.view_width == 8  # the half frame was never taken for an image
        assert not process._pid_alive(c.proc.pid)
    finally:
        c.close()


@pytest.mark.parametrize("mode, words", [
    ("nosession", "has no 'session' subcommand"),
    ("oldversion", "session protocol version mismatch: renderer speaks 99, add-on speaks 1")])
def test_client_explains_a_renderer_that_cannot_serve(fake, monkeypatch, mode, words):
    monkeypatch.setenv("FAKE_SESSION_MODE", mode)
    c = session_client.SessionClient(str(FAKE)).start()
    try:
        assert wait_for(lambda: c.dead is not None)
        assert words in c.dead
    finally:
        c.close()


def test_close_all_ends_every_session(fake):
    clients = [session_client.SessionClient(str(FAKE)).start() for _ in range(2)]
    assert wait_for(lambda: all(c.hello is not None for c in clients))
    session_client.close_all()
    for c in clients:
        assert c.proc.returncode is not None
        assert not process._pid_alive(c.proc.pid)


# --------------------------------------------------------------------------------------------
# view -> camera

def cycles_viewplane(ext, width, height, zoom, offset):
    """Cycles' blender_camera_viewplane (intern/cycles/blender/camera.cpp), in its own units,
    for a perspective camera, then scaled to the plane at distance 1."""
    xratio, yratio = float(width), float(height)
    fit = ext["sensor_fit"]
    horizontal = xratio > yratio if fit == "AUTO" else fit == "HORIZONTAL"
    sensor = ext["sensor_height"] if fit == "VERTICAL" else ext["sensor_width"]
    if horizontal:
        aspect = xratio / yratio
        xaspect, yaspect = aspect, 1.0
    else:
        aspect = yratio / xratio
        xaspect, yaspect = 1.0, aspect
    left, right, bottom, top = -xaspect * zoom, xaspect * zoom, -yaspect * zoom, yaspect * zoom
    dx = 2.0 * (aspect * ext["shift_x"] + offset[0] * xaspect * 2.0)
    dy = 2.0 * (aspect * ext["shift_y"] + offset[1] * yaspect * 2.0)
    tan_half = (0.5 * sensor) / ext["lens"] / aspect  # tan(fov / 2), Cycles' fov
    return tuple(v * tan_half for v in (left + dx, right + dx, bottom + dy, top + dy))


@pytest.mark.parametrize("fit, size, shift, zoom, offset", [
    ("AUTO", (64, 40), (0.0, 0.0), 1.0, (0.0, 0.0)),
    ("AUTO", (40, 64), (0.1, -0.2), 2.0, (0.05, 0.1)),
    ("HORIZONTAL", (50, 70), (0.3, 0.0), 0.7, (-0.2, 0.05)),
    ("VERTICAL", (90, 40), (0.0, 0.25), 1.6, (0.1, -0.3))])
def test_folded_zoom_matches_cycles_viewplane(fit, size, shift, zoom, offset):
    ext = {"type": "PERSP", "lens": 35.0, "sensor_width": 36.0, "sensor_height": 24.0,
           "sensor_fit": fit, "shift_x": shift[0], "shift_y": shift[1],
           "dof": {"focus_distance": 3.0, "aperture_fstop": 2.0}}
    folded = vc.fold_zoom(ext, size[0], size[1], zoom, offset)
    got = vc.window(folded, *size)
    want = cycles_viewplane(ext, size[0], size[1], zoom, offset)
    assert got == pytest.approx(want, rel=1e-9, abs=1e-12)
    # The lens radius (lens / (2 fstop)) is the camera's.
    assert folded["lens"] / folded["dof"]["aperture_fstop"] == pytest.approx(35.0 / 2.0)


def fake_view(perspective, *, matrix=None, zoom=0.0, offset=(0.0, 0.0), distance=10.0,
              lens=50.0, border=None):
    space = SimpleNamespace(lens=lens, clip_start=0.01, clip_end=1000.0, camera=None,
                            use_local_camera=False, use_render_border=border is not None,
                            render_border_min_x=(border or (0, 0, 1, 1))[0],
                            render_border_min_y=(border or (0, 0, 1, 1))[1],
                            render_border_max_x=(border or (0, 0, 1, 1))[2],
                            render_border_max_y=(border or (0, 0, 1, 1))[3])
    rv3d = SimpleNamespace(view_perspective=perspective, view_matrix=matrix or Matrix.Identity(4),
                           view_camera_zoom=zoom, view_camera_offset=offset,
                           view_distance=distance)
    return space, rv3d


def test_camera_view_filling_the_region_is_the_f12_camera(tmp_path):
    scene = simple_scene(64, 40)
    cam = scene.camera
    cam.data.shift_x, cam.data.lens = 0.1, 40.0
    depsgraph = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "f12.gltf"
    export.write_gltf(depsgraph, str(path), width=64, height=40, camera=cam.evaluated_get(depsgraph))
    doc = json.loads(path.read_text())
    node = next(n for n in doc["nodes"] if n["name"] == "Cam")
    # view_camera_zoom at which Cycles' window scale is 1: the frame fills the view.
    zoom = 50.0 * (2.0 - math.sqrt(2.0))
    space, rv3d = fake_view("CAMERA", zoom=zoom)
    view = vc.view_camera(scene, space, rv3d, 64, 40)
    got = view.command_camera()
    assert got["matrix"] == pytest.approx(node["matrix"], abs=1e-6)
    f12 = node["extensions"]["TESELA_camera"]
    assert set(got["camera"]) == set(f12)
    for k, v in f12.items():
        assert got["camera"][k] == (pytest.approx(v, rel=1e-6) if isinstance(v, float) else v), k
    # Zoomed out (the default camera view) the lens halves and the frame covers the middle
    # half of the view (shift moves the view with the frame, as in Blender's camera view).
    view = vc.view_camera(scene, *fake_view("CAMERA", zoom=0.0), 64, 40)
    assert view.ext["lens"] == pytest.approx(20.0)
    assert vc.camera_frame(scene, cam, view.ext, 64, 40) == pytest.approx((0.25, 0.75, 0.25, 0.75))
    # Panned by the camera offset: the frame moves the other way by twice the offset.
    view = vc.view_camera(scene, *fake_view("CAMERA", zoom=0.0, offset=(0.1, 0.0)), 64, 40)
    assert vc.camera_frame(scene, cam, view.ext, 64, 40) == pytest.approx((0.15, 0.65, 0.25, 0.75))


def test_free_views_follow_cycles_viewport_camera():
    scene = simple_scene(64, 40)
    view_from_world = Matrix.Translation((1.0, -2.0, -5.0)) @ Matrix.Rotation(0.4, 4, "X")
    persp = vc.view_camera(scene, *fake_view("PERSP", matrix=view_from_world, lens=50.0), 80, 60)
    # Cycles' viewport: a 36 mm sensor and twice the window (the lens halves).
    assert persp.ext["lens"] == pytest.approx(25.0) and persp.ext["sensor_width"] == 36.0
    assert (persp.ext["clip_start"], persp.ext["clip_end"]) == (0.01, 1000.0)
    want = np.array(view_from_world.inverted())
    assert persp.matrix == pytest.approx(want, abs=1e-6)  # mathutils is float32
    ortho = vc.view_camera(scene, *fake_view("ORTHO", matrix=view_from_world, distance=8.0),
                           80, 60)
    assert ortho.ext["type"] == "ORTHO"
    assert ortho.ext["ortho_scale"] == pytest.approx(2.0 * 8.0 * 36.0 / 50.0)
    # The slab -far/2 .. far/2 around the view point: the camera stands far/2 behind it.
    assert ortho.matrix[:3, 3] == pytest.approx(want[:3, 3] + want[:3, 2] * 500.0, abs=1e-4)
    assert (ortho.ext["clip_start"], ortho.ext["clip_end"]) == (0.0, 1000.0)


def test_view_border_in_free_and_camera_views():
    scene = simple_scene(64, 40)
    space, rv3d = fake_view("PERSP", border=(0.25, 0.5, 0.75, 1.0))
    view = vc.view_camera(scene, space, rv3d, 80, 60)
    assert vc.view_border(scene, space, view, 80, 60) == [20, 0, 40, 30]
    scene.render.use_border = True
    scene.render.border_min_x, scene.render.border_max_x = 0.0, 0.5
    scene.render.border_min_y, scene.render.border_max_y = 0.0, 1.0
    space, rv3d = fake_view("CAMERA", zoom=0.0)
    view = vc.view_camera(scene, space, rv3d, 64, 40)
    # The frame is the middle half of the view; the border its left half.
    assert vc.view_border(scene, space, view, 64, 40) == [16, 10, 16, 20]
    scene.render.use_border = False
    assert vc.view_border(scene, space, view, 64, 40) is None


# --------------------------------------------------------------------------------------------
# depsgraph updates -> commands

class UpdateRecorder:
    """Runs `translate` in depsgraph_update_post, where depsgraph.updates is valid."""

    def __init__(self, tmp_path):
        self.tmp = tmp_path
        depsgraph = bpy.context.evaluated_depsgraph_get()
        path = tmp_path / "scene.gltf"
        export.write_gltf(depsgraph, str(path), width=16, height=16)
        self.index = updates.SceneIndex(depsgraph, json.loads(path.read_text()))
        self.results = []
        self.meshes = []
        bpy.app.handlers.depsgraph_update_post.append(self.handler)

    def write_mesh(self, obj):
        self.meshes.append(obj.name)
        return "mesh-%s.gltf" % obj.name

    def handler(self, scene, depsgraph):
        self.results.append(updates.translate(depsgraph, self.index, self.write_mesh,
                                              str(self.tmp)))

    def run(self, change):
        self.results.clear()
        change()
        bpy.context.evaluated_depsgraph_get().update()
        load = any(r.load for r in self.results)
        return load, [c for r in self.results for c in r.commands]

    def close(self):
        bpy.app.handlers.depsgraph_update_post.remove(self.handler)


@pytest.fixture
def recorder(tmp_path):
    simple_scene()
    rec = UpdateRecorder(tmp_path)
    yield rec
    rec.close()


def names(cmds):
    return [(c, f.get("node", f.get("name"))) for c, f in cmds]


def test_move_sends_one_transform(recorder):
    cube = bpy.data.objects["Cube"]
    load, cmds = recorder.run(lambda: setattr(cube, "location", (1.0, 2.0, 0.5)))
    assert not load and names(cmds) == [("transform", "Cube")]
    m = cmds[0][1]["matrix"]
    # glTF Y-up, column-major: Blender (1, 2, 0.5) is glTF (1, 0.5, -2).
    assert m[12:15] == pytest.approx([1.0, 0.5, -2.0])


def test_light_edit_sends_light(recorder):
    lamp = bpy.data.objects["Lamp"].data
    load, cmds = recorder.run(lambda: setattr(lamp, "energy", 123.0))
    assert not load and names(cmds) == [("light", "Lamp")]
    assert cmds[0][1]["light"]["power"] == pytest.approx(123.0)
    moved = recorder.run(lambda: setattr(bpy.data.objects["Panel"], "location", (0, 0, 4)))
    assert names(moved[1]) == [("transform", "Panel")]


def test_material_edit_sends_material(recorder):
    mat = bpy.data.materials["TestRed"]
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    load, cmds = recorder.run(
        lambda: bsdf.inputs["Base Color"].__setattr__("default_value", (0.1, 0.7, 0.2, 1.0)))
    assert not load and names(cmds) == [("material", "TestRed")]
    graph = cmds[0][1]["material"]["extensions"]["TESELA_material_graph"]
    node = next(n for n in graph["nodes"] if n["type"] == "ShaderNodeBsdfPrincipled")
    assert node["inputs"]["Base Color"] == pytest.approx([0.1, 0.7, 0.2, 1.0])
    assert recorder.meshes == []  # a material edit re-exports no mesh


def test_material_with_an_image_asks_for_a_load(recorder):
    mat = bpy.data.materials["TestRed"]
    img = bpy.data.images.new("Tex", 4, 4)
    tex = mat.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    try:
        load, _ = recorder.run(lambda: mat.node_tree.links.new(tex.outputs[0],
                                                               bsdf.inputs["Base Color"]))
        assert load
    finally:  # the other tests share the material
        mat.node_tree.nodes.remove(tex)
        bpy.data.images.remove(img)


def test_geometry_edit_sends_mesh(recorder):
    cube = bpy.data.objects["Cube"]

    def edit():
        cube.data.vertices[0].co.x -= 0.25
        cube.data.update()
    load, cmds = recorder.run(edit)
    assert not load and names(cmds) == [("mesh", "Cube")]
    assert cmds[0][1]["path"] == "mesh-Cube.gltf"


def test_hide_and_show_send_visibility_only(recorder):
    cube = bpy.data.objects["Cube"]
    load, cmds = recorder.run(lambda: cube.hide_set(True))
    assert not load and ("visibility", "Cube") in names(cmds)
    assert [f["visible"] for c, f in cmds if c == "visibility"] == [False]
    load, cmds = recorder.run(lambda: cube.hide_set(False))
    assert not load and [f["visible"] for c, f in cmds if c == "visibility"] == [True]
    assert recorder.meshes == []


def test_ray_visibility_edits_reach_the_session(recorder):
    # An object's Ray Visibility is in its glTF node: a load; a light's travels in its fields.
    cube = bpy.data.objects["Cube"]
    try:
        load, _ = recorder.run(lambda: setattr(cube, "visible_shadow", False))
        assert load and "ray visibility" in next(r.reason for r in recorder.results if r.load)
    finally:
        recorder.run(lambda: setattr(cube, "visible_shadow", True))
    lamp = bpy.data.objects["Lamp"]
    try:
        load, cmds = recorder.run(lambda: setattr(lamp, "visible_diffuse", False))
        assert not load and names(cmds) == [("light", "Lamp")]
        assert cmds[0][1]["light"]["visible_diffuse"] is False
    finally:
        recorder.run(lambda: setattr(lamp, "visible_diffuse", True))


def test_world_edit_sends_world(recorder):
    # A world of its own: one left by other test files may read images, which asks for a load.
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("ViewportEditWorld")
    recorder.index.world = scene.world.name
    load, cmds = recorder.run(lambda: setattr(scene.world, "color", (0.2, 0.3, 0.4)))
    assert not load and [c for c, _ in cmds] == ["world"]


def test_deleted_object_is_hidden(recorder):
    load, cmds = recorder.run(lambda: bpy.data.objects.remove(bpy.data.objects["Cube"]))
    assert not load and names(cmds) == [("visibility", "Cube")]
    assert cmds[0][1]["visible"] is False


def test_added_object_asks_for_a_load(recorder):
    def add():
        ob = bpy.data.objects.new("Another", bpy.data.meshes["Cube"])
        bpy.context.scene.collection.objects.link(ob)
    load, _ = recorder.run(add)
    assert load


# --------------------------------------------------------------------------------------------
# ViewportSession: view_update without a window

class StandInEngine:
    def __init__(self):
        self.redraws = 0
        self.stats = []

    def get_preview_pixel_size(self, scene):
        return 1

    def tag_redraw(self):
        self.redraws += 1

    def update_stats(self, a, b):
        self.stats.append(b)


def stand_in_context(width=32, height=24):
    space, rv3d = fake_view("CAMERA", zoom=50.0 * (2.0 - math.sqrt(2.0)))
    return SimpleNamespace(region=SimpleNamespace(width=width, height=height),
                           space_data=space, region_data=rv3d)


def test_viewport_session_commands_and_restart(fake, tmp_path, monkeypatch):
    import tempfile
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    simple_scene(32, 24)
    engine = StandInEngine()
    vs = interactive.ViewportSession(engine)
    vs.record = True
    try:
        ctx = stand_in_context()
        vs.update(engine, ctx, bpy.context.evaluated_depsgraph_get())
        assert [c for c, _ in vs.sent] == ["load", "settings", "view"]
        load = vs.sent[0][1]["path"]
        assert os.path.isfile(load) and load.startswith(vs.tmpdir)
        settings = vs.sent[1][1]
        assert settings["samples"] == 1024 and settings["start_resolution"] == 64
        assert settings["pixel_size"] == 1 and settings["denoise"] is False
        assert vs.sent[2][1]["width"] == 32 and "border" not in vs.sent[2][1]
        first = vs.client
        assert wait_for(lambda: first.image is not None and first.image.last)
        # Nothing changed: nothing is sent.
        vs.sent.clear()
        vs.update(engine, ctx, bpy.context.evaluated_depsgraph_get())
        assert vs.sent == []
        # The session dies: the next change starts a new one with the whole scene.
        first.proc.kill()
        assert wait_for(lambda: first.dead is not None)
        old_tmp = vs.tmpdir
        vs.update(engine, ctx, bpy.context.evaluated_depsgraph_get())
        assert [c for c, _ in vs.sent] == ["load", "settings", "view"]
        assert vs.client is not first and vs.client.alive()
        assert not os.path.exists(old_tmp)
        assert wait_for(lambda: len([e for e in fake_log(fake) if "start" in e]) == 2)
        starts = [e["start"] for e in fake_log(fake) if "start" in e]
    finally:
        vs.close()
    assert vs.client is None
    assert [n for n in os.listdir(tmp_path) if n.startswith("tesela")] == []
    for pid in starts:
        assert not process._pid_alive(pid)


def test_only_the_newest_mesh_file_is_kept(fake, tmp_path, monkeypatch):
    """Two geometry edits in a row: the first mesh file goes at once; the slow session's ERROR
    for it (it cannot read it any more) is not shown, since the second mesh supersedes it."""
    import tempfile
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    monkeypatch.setenv("FAKE_SESSION_DELAY", "0.05")
    simple_scene(32, 24)
    engine = StandInEngine()
    vs = interactive.ViewportSession(engine)
    vs.record = True
    ctx = stand_in_context()

    def handler(scene, depsgraph):
        vs.update(engine, ctx, depsgraph)
    bpy.app.handlers.depsgraph_update_post.append(handler)
    cube = bpy.data.objects["Cube"]
    try:
        vs.update(engine, ctx, bpy.context.evaluated_depsgraph_get())
        for dz in (0.1, 0.2):
            cube.data.vertices[7].co.z += dz
            cube.data.update()
            bpy.context.evaluated_depsgraph_get().update()
        meshes = [f["path"] for c, f in vs.sent if c == "mesh"]
        assert len(meshes) == 2
        assert not os.path.exists(meshes[0]) and os.path.isfile(meshes[1])
        assert wait_for(lambda: len([e for e in fake_log(fake) if e.get("cmd") == "mesh"]) == 2)
        assert wait_for(lambda: vs.client.errors)  # the fake could not read the first one
        assert vs.take_errors() == []
        vs.sent.clear()
        cube.data.vertices[7].co.z += 0.3  # a mesh the session cannot read is shown
        cube.data.update()
        bpy.context.evaluated_depsgraph_get().update()
        _remove = [f["path"] for c, f in vs.sent if c == "mesh"][0]
        os.remove(_remove)
        assert wait_for(lambda: vs.client.errors)
        assert vs.take_errors() == ["mesh: cannot read %s" % _remove]
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
        vs.close()


def test_viewport_session_without_renderer_says_why(monkeypatch, tmp_path):
    monkeypatch.setenv("TESELA_BINARY", str(tmp_path / "missing-tesela"))
    simple_scene(32, 24)
    engine = StandInEngine()
    vs = interactive.ViewportSession(engine)
    vs.update(engine, stand_in_context(), bpy.context.evaluated_depsgraph_get())
    assert vs.client is None and "not found" in vs.message
    vs.close()


# --------------------------------------------------------------------------------------------
# the real session

def session_binary():
    path = os.environ.get("TESELA_SESSION_BIN") or os.environ.get("TESELA_BIN") \
        or str(REPO / "target" / "release" / "tesela")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        pytest.skip("no tesela binary at %s (set TESELA_SESSION_BIN or TESELA_BIN)" % path)
    p = subprocess.run([path, "session", "--help"], capture_output=True, text=True, timeout=30)
    if p.returncode != 0:
        pytest.skip("%s has no 'session' subcommand yet (branch session lands it)" % path)
    return path


def test_real_session_equals_f12_render(tmp_path):
    binary = session_binary()
    scene = simple_scene(24, 16)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "scene.gltf"
    export.write_gltf(depsgraph, str(path), width=24, height=16,
                      camera=scene.camera.evaluated_get(depsgraph))
    spp = 4
    cli = tmp_path / "cli.exr"
    subprocess.run([binary, "render", str(path), "--spp", str(spp), "--width", "24",
                    "--height", "16", "--seed", "3", "--max-depth", "4", "--filter", "box",
                    "--filter-width", "1.0", "--threads", "2", "-q", "-o", str(cli)],
                   check=True, capture_output=True, timeout=120)
    import imgcompare
    want = imgcompare.read_exr(cli)
    c = session_client.SessionClient(binary, threads=1, cwd=str(tmp_path)).start()
    try:
        c.send("settings", samples=spp, start_resolution=0, pixel_size=1, seed=3, max_depth=4,
               filter="box", filter_width=1.0, denoise=False)
        c.send("load", path=str(path))
        space, rv3d = fake_view("CAMERA", zoom=50.0 * (2.0 - math.sqrt(2.0)))
        view = vc.view_camera(scene, space, rv3d, 24, 16)
        c.send("view", width=24, height=16, camera=view.command_camera())
        assert wait_for(lambda: c.image is not None and c.image.last, timeout=60), c.dead
        got = c.image
    finally:
        c.close()
    assert got.samples == spp and got.pixel_size == 1
    assert np.array_equal(got.pixels[..., :3], want[..., :3])


def test_real_session_takes_every_edit(monkeypatch, tmp_path):
    """view_update's commands against the real session: each edit is accepted (no ERROR
    frame), renders a new generation, and changes the image."""
    import tempfile
    binary = session_binary()
    monkeypatch.setenv("TESELA_BINARY", binary)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    scene = simple_scene(24, 16)
    scene.tesela.preview_samples = 2
    # A new world: one left by an earlier test may feed its Background's Color from a node
    # (a sky), and then the edit below changes nothing.
    scene.world = bpy.data.worlds.new("World")
    use_nodes(scene.world)
    background = next(n for n in scene.world.node_tree.nodes if n.type == "BACKGROUND")
    engine = StandInEngine()
    vs = interactive.ViewportSession(engine)
    vs.record = True
    ctx = stand_in_context(24, 16)

    def handler(scene, depsgraph):
        vs.update(engine, ctx, depsgraph)
    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        vs.update(engine, ctx, bpy.context.evaluated_depsgraph_get())

        def settled():
            c = vs.client
            return c.image is not None and c.image.last and c.image.samples == 2
        assert wait_for(settled, 60), vs.client.dead
        cube = bpy.data.objects["Cube"]
        bsdf = next(n for n in bpy.data.materials["TestRed"].node_tree.nodes
                    if n.type == "BSDF_PRINCIPLED")

        def edit_mesh():
            cube.data.vertices[7].co.z += 0.5
            cube.data.update()
        edits = [("transform", lambda: setattr(cube, "location", (-0.2, -0.5, 0.0))),
                 ("light", lambda: setattr(bpy.data.objects["Lamp"].data, "energy", 2000.0)),
                 ("material", lambda: bsdf.inputs["Base Color"].__setattr__(
                     "default_value", (0.1, 0.1, 0.9, 1.0))),
                 ("mesh", edit_mesh),
                 ("visibility", lambda: cube.hide_set(True)),
                 ("world", lambda: background.inputs["Color"].__setattr__(
                     "default_value", (0.3, 0.3, 0.05, 1.0)))]
        for cmd, edit in edits:
            before = vs.client.image
            vs.sent.clear()
            edit()
            bpy.context.evaluated_depsgraph_get().update()
            assert cmd in [c for c, _ in vs.sent], (cmd, vs.sent)
            assert wait_for(lambda: settled() and vs.client.image.generation > before.generation,
                            60), (cmd, vs.client.dead, vs.client.errors)
            assert vs.client.errors == [] and vs.client.dead is None, cmd
            assert not np.array_equal(vs.client.image.pixels, before.pixels), cmd
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
        vs.close()



def test_light_edit_carries_its_node_tree():
    """A light edited in the viewport carries the node tree the add-on cannot reduce (a
    Blackbody colour) for the session's renderer to evaluate, as a render's export does."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    data = bpy.data.lights.new("Warm", "POINT")
    ob = bpy.data.objects.new("Warm", data)
    bpy.context.scene.collection.objects.link(ob)
    data.use_nodes = True
    nt = data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    bb = nt.nodes.new("ShaderNodeBlackbody")
    bb.inputs["Temperature"].default_value = 3200.0
    nt.links.new(bb.outputs["Color"], em.inputs["Color"])
    warnings = []
    light = updates.light_fields(ob, warnings)["light"]
    assert warnings == [], warnings
    types = [n["type"] for n in light["graph"]["nodes"]]
    assert "ShaderNodeBlackbody" in types and light["graph"]["surface"], light
    assert light["base_color"] == [1.0, 1.0, 1.0]
