"""Tests of the Tesela Blender add-on with Blender as a Python module (PyPI bpy 5.x).

Most tests drive the add-on with tests/blender/fake_renderer.py (selected through the
TESELA_BINARY environment variable), whose image is a known pattern and which has fault modes.
The tests that need the real renderer use the `tesela_bin` fixture (skipped when it is absent).
"""

import json
import math
import os
import shutil
import stat
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import bpy
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
FAKE = HERE / "fake_renderer.py"
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import blender_addon  # noqa: E402
from blender_addon import engine as tesela_engine  # noqa: E402
from blender_addon import protocol  # noqa: E402


# --------------------------------------------------------------------------------------------
# helpers

def addon_registered():
    return hasattr(bpy.types.Scene, "tesela") and tesela_engine.TeselaRenderEngine.is_registered


@pytest.fixture(scope="module")
def addon():
    if not addon_registered():
        blender_addon.register()
    yield blender_addon
    if addon_registered():
        blender_addon.unregister()


@pytest.fixture
def private_tmp(tmp_path, monkeypatch):
    """A private TMPDIR for the add-on, so that leftovers can be counted."""
    d = tmp_path / "addon tmp"
    d.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(d))
    return d


@pytest.fixture
def fake(monkeypatch, tmp_path):
    """Use the fake renderer; returns a function to read its run log."""
    log = tmp_path / "fake-log.jsonl"
    monkeypatch.setenv("TESELA_BINARY", str(FAKE))
    monkeypatch.setenv("FAKE_TESELA_LOG", str(log))
    monkeypatch.delenv("FAKE_TESELA_MODE", raising=False)
    monkeypatch.delenv("FAKE_TESELA_DELAY", raising=False)

    def runs():
        if not log.exists():
            return []
        lines = [json.loads(line) for line in log.read_text().splitlines() if line.strip()]
        return [ln for ln in lines if "argv" in ln]  # not the "cancelled_at" lines
    return runs


def use_nodes(idblock):
    if bpy.app.version < (5, 0, 0):  # 5.0 deprecated use_nodes (always on)
        idblock.use_nodes = True


def simple_scene(width=40, height=30, percentage=100, camera=True):
    """A plane, a cube with a material, a point light, an area light, a camera."""
    scene = bpy.context.scene
    for ob in list(scene.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    r = scene.render
    r.engine = "TESELA"
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, percentage
    r.use_border = False
    r.use_crop_to_border = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    # Start from the panel's defaults: other test files leave their settings on the scene.
    for prop in scene.tesela.bl_rna.properties:
        if prop.identifier != "rna_type" and not prop.is_readonly:
            scene.tesela.property_unset(prop.identifier)
    scene.tesela.samples = 4
    scene.tesela.max_depth = 4
    scene.tesela.use_denoising = False  # the F12-equals-CLI tests compare raw renders
    scene.tesela.pixel_filter_type = "BOX"  # ... with the CLI's default filter
    scene.tesela.filter_width = 1.0
    scene.tesela.diffuse_bounces = scene.tesela.glossy_bounces = 1024  # ... and light paths
    scene.tesela.transmission_bounces = 1024
    scene.tesela.sample_clamp_indirect = 0.0

    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("Plane", mesh)
    scene.collection.objects.link(plane)
    cube_mesh = bpy.data.meshes.new("Cube")
    cube_mesh.from_pydata([(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)], [],
                          [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (1, 3, 7, 5), (3, 2, 6, 7),
                           (2, 0, 4, 6)])
    mat = bpy.data.materials.get("TestRed") or bpy.data.materials.new("TestRed")
    use_nodes(mat)
    bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Base Color"].default_value = (0.8, 0.1, 0.1, 1.0)
    cube_mesh.materials.append(mat)
    cube = bpy.data.objects.new("Cube", cube_mesh)
    cube.location = (-0.5, -0.5, 0.0)
    scene.collection.objects.link(cube)
    light = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    light.location = (1, -1, 3)
    scene.collection.objects.link(light)
    area = bpy.data.lights.new("Panel", "AREA")
    area.shape, area.size, area.size_y, area.energy = "RECTANGLE", 1.0, 0.5, 50.0
    area_ob = bpy.data.objects.new("Panel", area)
    area_ob.location = (0, 0, 3)
    scene.collection.objects.link(area_ob)
    if camera:
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        cam.location = (0, -6, 3)
        cam.rotation_euler = (math.radians(65), 0, 0)
        scene.collection.objects.link(cam)
        scene.camera = cam
    else:
        scene.camera = None
    return scene


def result_pixels(tmp):
    """The Render Result as float32 (h, w, 4), rows top to bottom, linear."""
    scene = bpy.context.scene
    s = scene.render.image_settings
    if hasattr(s, "media_type"):
        s.media_type = "IMAGE"
    s.file_format = "OPEN_EXR"
    s.color_mode = "RGBA"
    s.color_depth = "32"
    path = Path(tmp) / ("result-%d.exr" % time.monotonic_ns())
    bpy.data.images["Render Result"].save_render(str(path))
    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        img.colorspace_settings.is_data = True
        w, h = img.size
        buf = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(buf)
    finally:
        bpy.data.images.remove(img)
        path.unlink()
    return buf.reshape(h, w, 4)[::-1].copy()


def fake_pattern(width, height):
    """The fake renderer's full-frame image, rows top to bottom."""
    xs = (np.arange(width) + 0.5) / width
    ys = (np.arange(height) + 0.5) / height
    img = np.empty((height, width, 4), dtype=np.float32)
    img[..., 0] = xs[None, :]
    img[..., 1] = ys[:, None]
    img[..., 2] = 0.25
    img[..., 3] = 1.0
    return img


def pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie still answers kill(0); count it as alive (nobody reaped it).
    return True


def child_renderers():
    """Processes whose parent is this test process and that run the fake renderer."""
    out = []
    me = os.getpid()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                fields = f.read().rsplit(")", 1)[1].split()
            if int(fields[1]) == me:
                out.append(int(entry))
        except (OSError, IndexError, ValueError):
            continue
    return out


def render():
    return bpy.ops.render.render()


# --------------------------------------------------------------------------------------------
# registration

def test_register_unregister_twice():
    if addon_registered():
        blender_addon.unregister()
    for _ in range(2):
        blender_addon.register()
        assert addon_registered()
        assert "TESELA" in bpy.types.EEVEE_MATERIAL_PT_surface.COMPAT_ENGINES
        assert bpy.context.scene.tesela.integrator == "path_mis"
        assert hasattr(bpy.ops.export_scene, "tesela_gltf")
        blender_addon.unregister()
        assert not addon_registered()
        assert "TESELA" not in bpy.types.EEVEE_MATERIAL_PT_surface.COMPAT_ENGINES
    blender_addon.register()
    blender_addon.unregister()


def test_engine_identity(addon):
    eng = tesela_engine.TeselaRenderEngine
    assert eng.bl_idname == "TESELA" and eng.bl_label == "Tesela"
    s = bpy.context.scene.tesela
    for prop in ("integrator", "samples", "max_depth", "seed", "threads"):
        assert hasattr(s, prop)
    assert "blender" in blender_addon.bl_info
    assert (REPO / "blender_addon" / "blender_manifest.toml").read_text().count('id = "tesela"') == 1


# --------------------------------------------------------------------------------------------
# the pipe reader on its own

def _read_all(data):
    import io
    return list(protocol.FrameReader(io.BytesIO(data)))


def test_reader_parses_frames_and_skips_unknown_kinds():
    px = np.arange(2 * 3 * 4, dtype=np.float32)
    data = (protocol.hello_frame(3, 2, 8, 1)
            + protocol.frame(99, b"future stuff")
            + protocol.log_frame(1, "héllo")
            + protocol.tile_frame(0, 0, 3, 2, px.tobytes())
            + protocol.progress_frame(1, 1, 8, 0.5)
            + protocol.done_frame('{"seconds": 1.5, "samples": 48}'))
    msgs = _read_all(data)
    kinds = [type(m).__name__ for m in msgs]
    assert kinds == ["Hello", "Log", "Tile", "Progress", "Done"]
    assert msgs[1].message == "héllo"
    assert np.array_equal(msgs[2].pixels.reshape(-1), px)
    assert msgs[2].pixels.shape == (2, 3, 4)
    assert msgs[3].elapsed == 0.5 and msgs[4].stats["samples"] == 48


def test_reader_splits_tiles_into_the_announced_passes():
    passes = [protocol.COMBINED, ("Depth", "Z"), ("Normal", "XYZ")]
    rgba = np.arange(2 * 3 * 4, dtype=np.float32)
    depth = 100 + np.arange(2 * 3, dtype=np.float32)
    normal = 200 + np.arange(2 * 3 * 3, dtype=np.float32)
    data = (protocol.hello_frame(3, 2, 8, 1, passes=passes)
            + protocol.tile_frame(0, 0, 3, 2, rgba.tobytes() + depth.tobytes() + normal.tobytes())
            + protocol.done_frame("{}"))
    hello, tile, _ = _read_all(data)
    assert hello.passes == passes
    assert np.array_equal(tile.pixels.reshape(-1), rgba)
    assert tile.passes["Depth"].shape == (2, 3, 1)
    assert np.array_equal(tile.passes["Depth"].reshape(-1), depth)
    assert np.array_equal(tile.passes["Normal"].reshape(-1), normal)


@pytest.mark.parametrize("data, message", [
    (b"hello world, I am not a renderer", "bad magic"),
    (protocol.frame(1, b"XXXX" + bytes(20)), "bad magic"),
    (protocol.hello_frame(4, 4, 1, 1, version=1), "renderer speaks 1, add-on speaks 2"),
    (protocol.frame(1, protocol.hello_frame(4, 4, 1, 1)[8:-6]), "HELLO pass list truncated"),
    (protocol.hello_frame(4, 4, 1, 1, passes=[("Depth", "Z")]), "does not start with Combined"),
    (protocol.hello_frame(2, 1, 1, 1, passes=[protocol.COMBINED, ("Depth", "Z")])
     + protocol.tile_frame(0, 0, 2, 1, bytes(2 * 4 * 4)), "expected 56"),
    (protocol.hello_frame(4, 4, 1, 1) + protocol.tile_frame(0, 0, 4, 4, bytes(256))[:100],
     "truncated TILE frame"),
    (protocol.hello_frame(4, 4, 1, 1) + b"\x02\x00\x00", "truncated frame header"),
    (protocol.hello_frame(4, 4, 1, 1) + struct.pack("<II", 2, (1 << 30) + 1), "over 1 GiB"),
    (protocol.hello_frame(4, 4, 1, 1) + protocol.frame(2, struct.pack("<IIII", 0, 0, 4, 4)),
     "expected"),
])
def test_reader_reports_protocol_faults(data, message):
    with pytest.raises(protocol.ProtocolError, match=message.replace("(", r"\(")):
        _read_all(data)


def test_reader_accepts_error_instead_of_hello():
    msgs = _read_all(protocol.error_frame("cannot open scene.gltf"))
    assert isinstance(msgs[0], protocol.Error) and "scene.gltf" in msgs[0].message


# --------------------------------------------------------------------------------------------
# rendering through the add-on with the fake renderer

def test_render_pixels_orientation_and_percentage(addon, fake, private_tmp, tmp_path):
    simple_scene(width=48, height=36, percentage=50)
    assert render() == {"FINISHED"}
    px = result_pixels(tmp_path)
    assert px.shape == (18, 24, 4)
    assert np.array_equal(px, fake_pattern(24, 18))
    (run,) = fake()
    argv = run["argv"]
    assert argv[argv.index("--width") + 1] == "24" and argv[argv.index("--height") + 1] == "18"
    assert argv[argv.index("--integrator") + 1] == "path_mis"
    assert argv[argv.index("--spp") + 1] == "4" and argv[argv.index("--max-depth") + 1] == "4"
    assert argv[argv.index("--tile-size") + 1] == "32"  # the panel's default
    assert "--no-caustics-reflective" not in argv and "--no-caustics-refractive" not in argv
    assert argv[argv.index("--blur-glossy") + 1] == "1.0"  # Cycles' default Filter Glossy
    assert "--region" not in argv
    assert run["bin_exists"] and run["has_camera"]
    assert os.listdir(private_tmp) == []
    assert not pid_alive(run["pid"])


@pytest.mark.parametrize("border, size", [
    ((0.25, 0.75, 0.1, 0.5), (64, 48, 50)),
    ((0.13, 0.61, 0.37, 0.93), (64, 48, 50)),
    ((0.2, 0.6, 0.2, 0.6), (64, 48, 50)),
    # 0.95 * 80 is 76 in single precision (Blender's), 75.99999 in double.
    ((0.55, 0.95, 0.05, 0.45), (80, 60, 100)),
])
def test_render_border(addon, fake, private_tmp, tmp_path, border, size):
    width, height, percentage = size
    scene = simple_scene(width=width, height=height, percentage=percentage)
    r = scene.render
    r.use_border = True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = border
    assert render() == {"FINISHED"}
    px = result_pixels(tmp_path)
    W, H = width * percentage // 100, height * percentage // 100
    assert px.shape == (H, W, 4)
    # Blender's border: pixels trunc(min * size) to trunc(max * size) (bottom-up), the products
    # in single precision, as Cycles fills them (0.1-0.5 of 24 rows is 10 rows, not
    # trunc(0.4 * 24) = 9).
    def at(fraction, n):
        return int(np.float32(fraction) * np.float32(n))
    bw = at(border[1], W) - at(border[0], W)
    bh = at(border[3], H) - at(border[2], H)
    x0, x1 = at(border[0], W), at(border[0], W) + bw
    y1 = H - at(border[2], H)  # rows top to bottom
    y0 = y1 - bh
    (run,) = fake()
    argv = run["argv"]
    i = argv.index("--region")
    assert [int(v) for v in argv[i + 1:i + 5]] == [x0, y0, x1 - x0, y1 - y0]
    expect = np.zeros((H, W, 4), dtype=np.float32)
    expect[y0:y1, x0:x1] = fake_pattern(W, H)[y0:y1, x0:x1]
    assert np.array_equal(px, expect)
    assert os.listdir(private_tmp) == []


def test_border_crop(addon, fake, private_tmp, tmp_path):
    scene = simple_scene(width=40, height=40)
    r = scene.render
    r.use_border, r.use_crop_to_border = True, True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.5, 1.0, 0.0, 0.25
    assert render() == {"FINISHED"}
    px = result_pixels(tmp_path)
    assert px.shape == (10, 20, 4)
    assert np.array_equal(px, fake_pattern(40, 40)[30:40, 20:40])


FAULTS = [
    ("error", "out of memory while building the BVH", True),
    ("loaderror", "accessor 3 is out of bounds", False),
    ("die", "SIGKILL", True),
    ("truncated", "truncated TILE frame", True),
    ("garbage", "not a Tesela renderer (bad magic)", False),
    ("version", "protocol version mismatch: renderer speaks 7, add-on speaks 2", False),
    ("oldcli", "older than this add-on", False),
    ("errorhang", "device lost (fake)", False),
]


@pytest.mark.parametrize("mode, message, partial", FAULTS, ids=[f[0] for f in FAULTS])
def test_renderer_faults(addon, fake, private_tmp, tmp_path, monkeypatch, mode, message, partial):
    simple_scene(width=64, height=48)
    monkeypatch.setenv("FAKE_TESELA_MODE", mode)
    t0 = time.monotonic()
    with pytest.raises(RuntimeError) as info:
        render()
    elapsed = time.monotonic() - t0
    assert message in str(info.value)
    assert "Tesela" in str(info.value)
    assert elapsed < 5.0
    (run,) = fake()
    assert not pid_alive(run["pid"])
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []
    px = result_pixels(tmp_path)
    if partial:  # the tiles that arrived are kept, the rest is empty
        covered = px[..., 3] > 0
        assert 0 < covered.sum() < covered.size
        assert np.array_equal(px[covered], fake_pattern(64, 48)[covered])


def test_stderr_flood_does_not_block(addon, fake, private_tmp, tmp_path, monkeypatch):
    simple_scene(width=32, height=32)
    monkeypatch.setenv("FAKE_TESELA_MODE", "flood")
    t0 = time.monotonic()
    assert render() == {"FINISHED"}
    assert time.monotonic() - t0 < 20
    assert np.array_equal(result_pixels(tmp_path), fake_pattern(32, 32))
    assert os.listdir(private_tmp) == []


def _break_after(seconds, record):
    start = time.monotonic()

    def test_break(self):
        if time.monotonic() - start >= seconds:
            record.setdefault("first_true", time.monotonic())
            return True
        return False
    return test_break


@pytest.mark.parametrize("mode", ["slow", "silent"])
def test_cancel_stops_renderer_quickly(addon, fake, private_tmp, tmp_path, monkeypatch, mode):
    """Esc (test_break) ends the renderer within 0.5 s: a well-behaved one through stdin EOF,
    a silent one that ignores stdin and SIGTERM through SIGKILL."""
    simple_scene(width=64, height=64)
    monkeypatch.setenv("FAKE_TESELA_MODE", mode)
    record = {}
    monkeypatch.setattr(tesela_engine.TeselaRenderEngine, "should_stop",
                        _break_after(0.6, record), raising=False)
    render()
    end = time.monotonic()
    assert "first_true" in record
    assert end - record["first_true"] < 0.5, "cancel took %.3f s" % (end - record["first_true"])
    (run,) = fake()
    assert not pid_alive(run["pid"])
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []
    if mode == "slow":  # some tiles arrived before the cancel and are kept
        covered = result_pixels(tmp_path)[..., 3] > 0
        assert 0 < covered.sum() < covered.size


def test_cancel_during_export(addon, fake, private_tmp, monkeypatch):
    simple_scene()
    monkeypatch.setattr(tesela_engine.TeselaRenderEngine, "should_stop",
                        lambda self: True, raising=False)
    render()
    assert fake() == []  # no renderer was started
    assert os.listdir(private_tmp) == []


def test_renderer_missing(addon, private_tmp, monkeypatch, tmp_path):
    simple_scene()
    missing = tmp_path / "no such dir" / "tesela"
    monkeypatch.setenv("TESELA_BINARY", str(missing))
    with pytest.raises(RuntimeError, match="renderer not found"):
        render()
    assert os.listdir(private_tmp) == []


def test_renderer_not_executable(addon, private_tmp, monkeypatch, tmp_path):
    simple_scene()
    target = tmp_path / "tesela"
    shutil.copy(FAKE, target)
    target.chmod(0o644)
    monkeypatch.setenv("TESELA_BINARY", str(target))
    with pytest.raises(RuntimeError, match="not executable"):
        render()
    assert os.listdir(private_tmp) == []


def test_scene_without_camera(addon, fake, private_tmp):
    simple_scene(camera=False)
    with pytest.raises(RuntimeError, match="(?i)camera"):
        render()
    assert fake() == []
    assert os.listdir(private_tmp) == []


def test_unicode_and_spaces_in_paths(addon, fake, tmp_path, monkeypatch):
    """Temp dir, renderer path and export path with spaces and non-ASCII characters."""
    odd = tmp_path / "dïr with spaces ✓ 日本"
    odd.mkdir()
    tmpdir = odd / "tmp ü"
    tmpdir.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(tmpdir))
    binary = odd / "bin ñ" / "tesela renderer"
    binary.parent.mkdir()
    shutil.copy(FAKE, binary)
    binary.chmod(binary.stat().st_mode | stat.S_IXUSR)
    monkeypatch.setenv("TESELA_BINARY", str(binary))
    simple_scene(width=16, height=12)
    assert render() == {"FINISHED"}
    assert np.array_equal(result_pixels(tmp_path), fake_pattern(16, 12))
    (run,) = fake()
    assert run["bin_exists"] and "tmp ü" in run["scene_dir"]
    assert os.listdir(tmpdir) == []
    out = odd / "scène exportée.gltf"
    assert bpy.ops.export_scene.tesela_gltf(filepath=str(out)) == {"FINISHED"}
    doc = json.loads(out.read_text(encoding="utf-8"))
    from urllib.parse import unquote
    assert (odd / unquote(doc["buffers"][0]["uri"])).is_file()


def test_two_renders_use_distinct_temp_dirs(addon, fake, private_tmp):
    simple_scene(width=8, height=8)
    render()
    render()
    a, b = fake()
    assert a["scene_dir"] != b["scene_dir"]
    assert os.listdir(private_tmp) == []


# --------------------------------------------------------------------------------------------
# the glTF writer

def _export(path, **kw):
    assert bpy.ops.export_scene.tesela_gltf(filepath=str(path), **kw) == {"FINISHED"}
    return json.loads(Path(path).read_text(encoding="utf-8"))


def test_export_contents(addon, tmp_path):
    scene = simple_scene(width=40, height=20)
    glow = bpy.data.materials.new("Glow")
    use_nodes(glow)
    nt = glow.node_tree
    nt.nodes.clear()
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (1.0, 0.5, 0.25, 1.0)
    em.inputs["Strength"].default_value = 8.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    scene.objects["Plane"].data.materials.append(glow)
    world = scene.world or bpy.data.worlds.new("W")
    scene.world = world
    use_nodes(world)
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.1, 0.2, 0.3, 1)
    bg.inputs["Strength"].default_value = 2.0
    doc = _export(tmp_path / "s.gltf")
    assert doc["asset"]["version"] == "2.0"
    assert "extensionsRequired" not in doc
    assert {"TESELA_light", "TESELA_world", "TESELA_emission", "TESELA_render",
            "KHR_materials_emissive_strength", "KHR_lights_punctual"} <= set(doc["extensionsUsed"])
    world_ext = doc["extensions"]["TESELA_world"]
    assert world_ext["strength"] == pytest.approx(2.0)
    assert world_ext["color"] == pytest.approx([0.1, 0.2, 0.3], rel=1e-6)
    assert doc["extensions"]["TESELA_render"]["width"] == 40
    mats = {m["name"]: m for m in doc["materials"]}
    g = mats["Glow"]
    assert g["emissiveFactor"] == pytest.approx([1.0, 0.5, 0.25])
    assert g["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == pytest.approx(8.0)
    assert g["extensions"]["TESELA_emission"] == {"two_sided": True}
    assert mats["TestRed"]["pbrMetallicRoughness"]["baseColorFactor"][:3] == pytest.approx([0.8, 0.1, 0.1])
    lights = {n["name"]: n["extensions"]["TESELA_light"] for n in doc["nodes"]
              if "TESELA_light" in n.get("extensions", {})}
    assert lights["Panel"]["type"] == "AREA" and lights["Panel"]["shape"] == "RECTANGLE"
    assert lights["Panel"]["size_y"] == pytest.approx(0.5) and lights["Panel"]["power"] == 50.0
    assert lights["Lamp"]["type"] == "POINT"
    cam = doc["cameras"][0]["perspective"]
    assert cam["aspectRatio"] == pytest.approx(2.0)
    # Blender default: 50 mm lens, 36 mm sensor fitted to the wider side.
    assert cam["yfov"] == pytest.approx(2 * math.atan(18 / 50 / 2.0))
    # Z-up -> Y-up: the lamp at Blender (1, -1, 3) sits at glTF (1, 3, 1).
    lamp = next(n for n in doc["nodes"] if n["name"] == "Lamp")
    assert lamp["matrix"][12:15] == pytest.approx([1, 3, 1])
    # 2 triangles for the plane + 12 for the cube
    tri = sum(doc["accessors"][p["indices"]]["count"] for m in doc["meshes"] for p in m["primitives"])
    assert tri == 3 * 14


def test_export_portrait_camera_fov(addon, tmp_path):
    scene = simple_scene(width=20, height=40)
    scene.camera.data.sensor_fit = "AUTO"
    doc = _export(tmp_path / "p.gltf")
    cam = doc["cameras"][0]["perspective"]
    assert cam["aspectRatio"] == pytest.approx(0.5)
    assert cam["yfov"] == pytest.approx(2 * math.atan(18 / 50))  # sensor on the taller side
    scene.camera.data.sensor_fit = "VERTICAL"
    scene.camera.data.sensor_height = 24
    scene.render.resolution_x = 80
    doc = _export(tmp_path / "v.gltf")
    assert doc["cameras"][0]["perspective"]["yfov"] == pytest.approx(2 * math.atan(12 / 50))


def test_export_instances_and_modifiers(addon, tmp_path):
    scene = simple_scene()
    cube = scene.objects["Cube"]
    mod = cube.modifiers.new("Sub", "SUBSURF")
    mod.levels = mod.render_levels = 1
    arr = scene.objects["Plane"].modifiers.new("Arr", "ARRAY")
    arr.count = 3
    doc = _export(tmp_path / "m.gltf")
    counts = {m["name"]: sum(doc["accessors"][p["indices"]]["count"] // 3 for p in m["primitives"])
              for m in doc["meshes"]}
    assert counts["Cube"] == 6 * 4 * 2  # subdivided once
    assert counts["Plane"] == 3 * 2
    # collection instances: one mesh, several nodes
    coll = bpy.data.collections.new("Inst")
    coll.objects.link(bpy.data.objects.new("Inner", cube.data))
    for i in range(3):
        e = bpy.data.objects.new("Empty%d" % i, None)
        e.instance_type = "COLLECTION"
        e.instance_collection = coll
        e.location = (i * 3, 5, 0)
        scene.collection.objects.link(e)
    doc = _export(tmp_path / "i.gltf")
    inner = [n for n in doc["nodes"] if n["name"] == "Inner"]
    assert len(inner) == 3 and len({n["mesh"] for n in inner}) == 1
    for o in list(scene.objects):
        if o.name.startswith("Empty"):
            bpy.data.objects.remove(o)
    cube.modifiers.clear()


def _validator():
    node = shutil.which("node")
    npm = shutil.which("npm")
    if node is None:
        pytest.skip("node not available for the Khronos glTF validator")
    # scripts/test.sh installs it into .venv/node; otherwise npm installs it into a cache.
    cache = REPO / ".venv" / "node"
    if not (cache / "node_modules" / "gltf-validator").is_dir():
        cache = Path(os.environ.get("TESELA_NPM_CACHE",
                                    Path(tempfile.gettempdir()) / "tesela-gltf-validator"))
    if not (cache / "node_modules" / "gltf-validator").is_dir():
        if npm is None:
            pytest.skip("npm not available to install the Khronos glTF validator")
        cache.mkdir(parents=True, exist_ok=True)
        r = subprocess.run([npm, "install", "--prefix", str(cache), "gltf-validator"],
                           capture_output=True, text=True, timeout=300)
        if r.returncode != 0:
            pytest.skip("cannot install gltf-validator with npm: " + r.stderr[-500:])
    return node, cache


VALIDATE_JS = r"""
const fs = require('fs'), path = require('path');
const validator = require(process.argv[2]);
const file = process.argv[3];
validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
  uri: file, maxIssues: 200,
  externalResourceFunction: (uri) => new Promise((resolve, reject) => {
    fs.readFile(path.resolve(path.dirname(file), decodeURIComponent(uri)),
                (err, data) => err ? reject(err.toString()) : resolve(new Uint8Array(data)));
  }),
}).then((report) => { console.log(JSON.stringify(report)); })
  .catch((e) => { console.error(e); process.exit(2); });
"""


def validate(path):
    node, cache = _validator()
    script = Path(path).parent / "validate.js"
    script.write_text(VALIDATE_JS)
    r = subprocess.run([node, str(script), str(cache / "node_modules" / "gltf-validator"), str(path)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_export_passes_khronos_validator(addon, tmp_path):
    scene = simple_scene()
    mesh = bpy.data.meshes.new("Sphere")
    import bmesh
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=16, v_segments=8, radius=0.5)
    bm.to_mesh(mesh)
    bm.free()
    mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
    glass = bpy.data.materials.new("Glass")
    use_nodes(glass)
    nt = glass.node_tree
    nt.nodes.clear()
    g = nt.nodes.new("ShaderNodeBsdfGlass")
    o = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(g.outputs[0], o.inputs["Surface"])
    mesh.materials.append(glass)
    sph = bpy.data.objects.new("Sphere", mesh)
    sph.location = (1, 0, 0.5)
    scene.collection.objects.link(sph)
    mesh.uv_layers.new(name="UV") if not mesh.uv_layers else None
    for kind in ("SPOT", "SUN"):
        ob = bpy.data.objects.new(kind, bpy.data.lights.new(kind, kind))
        scene.collection.objects.link(ob)
    # an image texture (written as a PNG beside the .gltf)
    img = bpy.data.images.new("Tex ü", 8, 4, alpha=True)
    img.pixels.foreach_set(np.linspace(0, 1, 8 * 4 * 4, dtype=np.float32))
    red = bpy.data.materials["TestRed"]
    tex = red.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = img
    bsdf = next(n for n in red.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    red.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    dest = tmp_path / "valid dïr"
    dest.mkdir()
    doc = _export(dest / "scene.gltf")
    red.node_tree.nodes.remove(tex)
    assert len(doc["images"]) == 1 and doc["images"][0]["mimeType"] == "image/png"
    mat = next(m for m in doc["materials"] if m["name"] == "TestRed")
    assert mat["pbrMetallicRoughness"]["baseColorTexture"] == {"index": 0}
    from urllib.parse import unquote
    assert (dest / unquote(doc["images"][0]["uri"])).read_bytes()[:4] == b"\x89PNG"
    report = validate(dest / "scene.gltf")
    issues = report["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, \
        json.dumps(issues["messages"], indent=1)[:3000]
    assert report["info"]["totalTriangleCount"] > 100


# --------------------------------------------------------------------------------------------
# the real renderer: F12 pixels equal the CLI's render of the same glTF

def _cli_render(tesela_bin, gltf, args):
    """Run `tesela render --pipe` and assemble its tiles (rows top to bottom)."""
    import io
    import threading
    # stdin stays open until the renderer is done (its EOF means "cancel").
    proc = subprocess.Popen([str(tesela_bin), "render", str(gltf), "--pipe", "--pipe-version",
                             str(protocol.PROTOCOL_VERSION)] + args,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    out = {}
    readers = [threading.Thread(target=lambda k, f: out.__setitem__(k, f.read()), args=(k, f))
               for k, f in (("stdout", proc.stdout), ("stderr", proc.stderr))]
    for t in readers:
        t.start()
    code = proc.wait(timeout=300)
    for t in readers:
        t.join()
    proc.stdin.close()
    assert code == 0, out["stderr"].decode(errors="replace")[-2000:]
    img = None
    for msg in protocol.FrameReader(io.BytesIO(out["stdout"])):
        if isinstance(msg, protocol.Hello):
            img = np.zeros((msg.height, msg.width, 4), dtype=np.float32)
        elif isinstance(msg, protocol.Tile):
            img[msg.y:msg.y + msg.h, msg.x:msg.x + msg.w] = msg.pixels
    return img


def test_f12_pixels_equal_cli(addon, tesela_bin, tmp_path, monkeypatch, private_tmp):
    """Render through the add-on, keeping a copy of the glTF it wrote (a wrapper script copies
    it before exec'ing the real renderer), then render that file with the CLI: bit-identical."""
    keep = tmp_path / "kept"
    wrapper = tmp_path / "tesela-wrapper"
    wrapper.write_text('#!/bin/sh\ncp -r "$(dirname "$2")" "%s"\nexec "%s" "$@"\n' % (keep, tesela_bin))
    wrapper.chmod(0o755)
    monkeypatch.setenv("TESELA_BINARY", str(wrapper))
    scene = simple_scene(width=40, height=30, percentage=100)
    scene.tesela.samples = 4
    assert render() == {"FINISHED"}
    blender_img = result_pixels(tmp_path)
    s = scene.tesela
    cli = _cli_render(tesela_bin, keep / "scene.gltf",
                      ["--integrator", s.integrator, "--spp", str(s.samples), "--max-depth",
                       str(s.max_depth), "--width", "40", "--height", "30", "--seed", str(s.seed),
                       "--blur-glossy", repr(float(s.blur_glossy))])
    assert cli.shape == blender_img.shape
    assert np.isfinite(cli).all() and cli[..., :3].max() > 0
    assert np.array_equal(cli, blender_img)
    assert os.listdir(private_tmp) == []


def _coated_ball_scene():
    """simple_scene with a ball from Blender's UV sphere operator: coat, sheen, a procedural
    normal map through its UV map (tangents) and a generated image as base colour."""
    import scenes

    scenes.clear_scene()  # the data blocks of a previous build: the names stay the same
    if "Grid" in bpy.data.images:
        bpy.data.images.remove(bpy.data.images["Grid"])
    scene = simple_scene(width=48, height=32)
    ball = scenes.uv_sphere_add(radius=0.7, location=(0.8, 0.3, 0.7), segments=48,
                                ring_count=24)
    ball.data.polygons.foreach_set("use_smooth", [True] * len(ball.data.polygons))
    mat = bpy.data.materials.new("CoatedFlakes")
    use_nodes(mat)
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    for name, value in (("Coat Weight", 1.0), ("Coat Roughness", 0.1), ("Sheen Weight", 1.0),
                        ("Roughness", 0.4)):
        bsdf.inputs[name].default_value = value
    vor = nt.nodes.new("ShaderNodeTexVoronoi")
    vor.inputs["Scale"].default_value = 30.0
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.inputs["Strength"].default_value = 0.5
    nt.links.new(vor.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = bpy.data.images.new("Grid", 16, 16)
    tex.image.generated_type = "COLOR_GRID"
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    ball.data.materials.append(mat)
    return scene


def test_scene_built_twice_exports_and_renders_identically(addon, tesela_bin, tmp_path,
                                                           monkeypatch, private_tmp):
    """The same scene, built twice, gives the same glTF bytes and bit-identical F12 renders.
    Blender's UV sphere lists its faces in an order that changes from call to call (it decides
    the last bits of the vertex normals and the triangles' order), so the test scenes put them
    in a fixed order (scenes.uv_sphere_add); the coat, sheen, normal map and image would show
    any other export or render path that depends on the run."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    files, images = [], []
    for run in range(2):
        scene = _coated_ball_scene()
        scene.tesela.samples = 16
        out = tmp_path / str(run)
        out.mkdir()
        assert bpy.ops.export_scene.tesela_gltf(filepath=str(out / "scene.gltf")) == {"FINISHED"}
        files.append({f.name: f.read_bytes() for f in sorted(out.iterdir())})
        assert render() == {"FINISHED"}
        images.append(result_pixels(tmp_path))
    assert files[0].keys() == files[1].keys() and len(files[0]) >= 2
    for name in files[0]:
        assert files[0][name] == files[1][name], name
    assert images[0][..., :3].max() > 0
    assert np.array_equal(images[0], images[1])


def test_f12_denoises_or_says_why_not(addon, tesela_bin, private_tmp, tmp_path, monkeypatch, capsys):
    """Denoising on (the default): the renderer denoises with OIDN when it finds the library,
    and otherwise the render still completes with a warning naming the problem."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = simple_scene(width=48, height=32, percentage=100)
    scene.tesela.use_denoising = True
    monkeypatch.setenv("TESELA_OIDN_LIB", str(tmp_path / "no-such-libOpenImageDenoise.so"))
    assert render() == {"FINISHED"}
    out = capsys.readouterr().out
    assert "denoising unavailable" in out and "no-such-libOpenImageDenoise" in out, out
    assert np.isfinite(result_pixels(tmp_path)).all()
    # Without the setting the renderer looks for it (beside itself, a .venv with pyoidn).
    monkeypatch.delenv("TESELA_OIDN_LIB")
    assert render() == {"FINISHED"}
    out = capsys.readouterr().out
    if "denoising unavailable" in out:
        pytest.skip("no Open Image Denoise on this machine: " + out.strip().splitlines()[-1])
    assert "denoised with Open Image Denoise" in out, out


def test_real_renderer_cancel(addon, tesela_bin, private_tmp, monkeypatch):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = simple_scene(width=320, height=240)
    scene.tesela.samples = 4096
    record = {}
    monkeypatch.setattr(tesela_engine.TeselaRenderEngine, "should_stop",
                        _break_after(1.0, record), raising=False)
    render()
    end = time.monotonic()
    assert end - record["first_true"] < 0.5
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []


# --------------------------------------------------------------------------------------------
# leaks and speed

def _fds():
    return len(os.listdir("/proc/self/fd"))


def test_repeated_renders_leak_no_fds_threads_or_processes(addon, fake, private_tmp, monkeypatch):
    import threading
    simple_scene(width=16, height=16)
    render()  # warm up (Blender allocates its own things on the first render)
    fds, threads = _fds(), threading.active_count()
    for mode in ["ok", "error", "die", "garbage", "ok", "flood", "ok"]:
        monkeypatch.setenv("FAKE_TESELA_MODE", mode)
        try:
            render()
        except RuntimeError:
            pass
    assert _fds() == fds
    assert threading.active_count() == threads
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []


def test_stale_temp_dirs_of_dead_blenders_are_swept(addon, fake, private_tmp):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = private_tmp / ("tesela-render-%d-abc" % dead.pid)
    stale.mkdir()
    (stale / "scene.gltf").write_text("{}")
    alive = private_tmp / ("tesela-render-%d-xyz" % os.getppid())  # a live process: kept
    alive.mkdir()
    simple_scene(width=8, height=8)
    render()
    assert sorted(os.listdir(private_tmp)) == [alive.name]
    alive.rmdir()


def _big_grid(scene, n=708):
    """A grid mesh object of 2 (n-1)^2 triangles (n=708: ~1.0M)."""
    mesh = bpy.data.meshes.new("Grid")
    xs = np.linspace(-1, 1, n, dtype=np.float32)
    gx, gy = np.meshgrid(xs, xs)
    co = np.stack([gx.ravel(), gy.ravel(), np.zeros(n * n, np.float32)], axis=1)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).ravel()
    quads = np.stack([a, a + 1, a + n + 1, a + n], axis=1)
    mesh.vertices.add(n * n)
    mesh.vertices.foreach_set("co", co.ravel())
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads.ravel().astype(np.int32))
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", (np.arange(len(quads)) * 4).astype(np.int32))
    if hasattr(mesh.polygons[0], "loop_total") and bpy.app.version < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, np.int32))
    mesh.update()
    mesh.uv_layers.new(name="UV")
    ob = bpy.data.objects.new("Grid", mesh)
    scene.collection.objects.link(ob)
    return ob


def test_export_million_triangles(addon, tmp_path):
    """A ~1M-triangle grid exports whole (its speed is measured by bench/export.py, not here)."""
    scene = simple_scene()
    n = 708
    ob = _big_grid(scene, n)
    mesh = ob.data
    try:
        doc = _export(tmp_path / "big.gltf")
        tri = sum(doc["accessors"][p["indices"]]["count"] // 3
                  for m in doc["meshes"] if m["name"] == "Grid" for p in m["primitives"])
        assert tri == 2 * (n - 1) ** 2
    finally:
        bpy.data.objects.remove(ob)
        bpy.data.meshes.remove(mesh)


def test_real_renderer_error_reaches_blender(addon, tesela_bin, tmp_path, monkeypatch, private_tmp):
    """The real renderer refuses a broken scene: its message is what Blender reports."""
    wrapper = tmp_path / "break-scene"
    wrapper.write_text('#!/bin/sh\nprintf \'{"asset": {"version": "2.0"}, "nodes": [{"mesh": 7}]}\' > "$2"\n'
                       'exec "%s" "$@"\n' % tesela_bin)
    wrapper.chmod(0o755)
    monkeypatch.setenv("TESELA_BINARY", str(wrapper))
    simple_scene(width=16, height=16)
    with pytest.raises(RuntimeError, match="Tesela: renderer error: ") as info:
        render()
    print(info.value)
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []


def test_render_log_says_where_the_time_went(addon, tesela_bin, monkeypatch, private_tmp, capfd):
    """F12 with the real renderer prints the export's phases, then one line with the export,
    the renderer's load, BVH, render and tile stream, and the copies into the result."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    simple_scene(width=16, height=16)
    capfd.readouterr()
    assert render() == {"FINISHED"}
    out = capfd.readouterr().out
    assert len([ln for ln in out.splitlines() if ln.startswith("Tesela: export ")]) == 1, out
    line = [ln for ln in out.splitlines() if ln.startswith("Tesela: 14 triangles | ")]
    assert len(line) == 1, out
    names = [part.rsplit(" ", 2)[0] for part in line[0].split(" | ")[1:]]
    assert names == ["export", "load", "BVH", "render", "tile stream", "result"], line
    seconds = [float(part.rsplit(" ", 2)[1]) for part in line[0].split(" | ")[1:]]
    assert all(0.0 <= s < 60.0 for s in seconds), line
    assert os.listdir(private_tmp) == []


def test_real_renderer_killed_mid_frame(addon, tesela_bin, tmp_path, monkeypatch, private_tmp):
    """SIGKILL the real renderer mid-render: a clear message, the tiles so far kept."""
    wrapper = tmp_path / "kill-renderer"
    wrapper.write_text(
        "#!%s\nimport os, signal, subprocess, sys, time\n"
        "p = subprocess.Popen([%r] + sys.argv[1:])\n"
        "time.sleep(1.5)\n"
        "p.kill(); p.wait()\n"
        "os.kill(os.getpid(), signal.SIGKILL)\n" % (sys.executable, str(tesela_bin)))
    wrapper.chmod(0o755)
    monkeypatch.setenv("TESELA_BINARY", str(wrapper))
    scene = simple_scene(width=200, height=150)
    scene.tesela.samples = 512
    # Tile by tile (with adaptive sampling a first round would cover the frame at once).
    scene.tesela.use_adaptive_sampling = False
    with pytest.raises(RuntimeError, match="SIGKILL") as info:
        render()
    print(info.value)
    assert "mid-render" in str(info.value) or "truncated" in str(info.value)
    covered = result_pixels(tmp_path)[..., 3] > 0
    assert 0 < covered.sum() < covered.size, "expected a partial image"
    assert child_renderers() == []
    assert os.listdir(private_tmp) == []


def test_cancel_during_export_of_a_big_mesh(addon, fake, private_tmp, monkeypatch):
    """Esc while a ~1M-triangle mesh is being exported: render() returns within 0.5 s."""
    scene = simple_scene()
    ob = _big_grid(scene)
    subsurf = ob.modifiers.new("Sub", "SUBSURF")  # makes the evaluation itself take a while
    subsurf.levels = subsurf.render_levels = 1
    record = {}
    monkeypatch.setattr(tesela_engine.TeselaRenderEngine, "should_stop",
                        _break_after(0.3, record), raising=False)
    try:
        render()
        end = time.monotonic()
    finally:
        mesh = ob.data
        bpy.data.objects.remove(ob)
        bpy.data.meshes.remove(mesh)
    assert "first_true" in record
    assert end - record["first_true"] < 0.5, "export cancel took %.2f s" % (end - record["first_true"])
    assert fake() == []
    assert os.listdir(private_tmp) == []


def test_two_view_layers(addon, fake, private_tmp, tmp_path):
    """render() runs once per view layer; each fills its own layer."""
    scene = simple_scene(width=16, height=8)
    second = scene.view_layers.new("Second Layer")
    try:
        assert render() == {"FINISHED"}
        assert len(fake()) == 2
        # save_render writes the first layer; the second got its own renderer run
        assert np.array_equal(result_pixels(tmp_path), fake_pattern(16, 8))
    finally:
        scene.view_layers.remove(second)
    assert os.listdir(private_tmp) == []


def test_export_selection_only(addon, tmp_path):
    scene = simple_scene()
    for ob in scene.objects:
        ob.select_set(ob.name == "Cube")
    doc = _export(tmp_path / "sel.gltf", use_selection=True)
    names = {n["name"] for n in doc["nodes"]}
    assert names == {"Cube", "Cam"}


def test_progress_lines_for_farms_and_time_left():
    lines = tesela_engine.progress_lines(step=0.05)
    printed = [f for f in [i / 200 for i in range(201)] if lines.due(f)]
    # One line per 5% (21 with 0% and 100%), never two for the same step.
    assert len(printed) == 21 and printed[0] == 0.0 and printed[-1] == 1.0
    assert tesela_engine.format_time_left(30.0, 0.25) == "Time 00:30 | Remaining 01:30"
    assert tesela_engine.format_time_left(5.0, 1.0) == "Time 00:05"


def test_animated_seed_adds_the_frame():
    class S:
        seed, use_animated_seed = 7, False
    assert tesela_engine.render_seed(S, 12) == 7
    S.use_animated_seed = True
    assert tesela_engine.render_seed(S, 12) == 19
    assert tesela_engine.render_seed(S, -20) == 0


def test_light_passes_are_registered_with_blenders_names_and_channels():
    from types import SimpleNamespace
    from blender_addon import passes
    toggles = {t: True for t, *_ in passes.PASSES}
    toggles["use_pass_shadow"] = True
    layer = SimpleNamespace(cycles=SimpleNamespace(use_denoising=True,
                                                   denoising_store_passes=False), **toggles)
    settings = SimpleNamespace(integrator="path_mis", use_denoising=True)
    got = {b: (name, ids, kind) for name, b, ids, kind in passes.enabled(layer, settings)}
    assert got["DiffDir"] == ("diffuse_direct", "RGB", "COLOR")
    assert got["TransCol"] == ("transmission_color", "RGB", "COLOR")
    assert got["Noisy Image"] == ("noisy_image", "RGBA", "COLOR")
    assert passes.unsupported(layer, settings) == ["Shadow"]
    # Shader AOVs and light groups the view layer adds are reported by name.
    layer.aovs = [SimpleNamespace(name="Dirt")]
    layer.lightgroups = [SimpleNamespace(name="Key"), SimpleNamespace(name="")]
    assert passes.unsupported(layer, settings) == ["Shadow", "AOV 'Dirt'", "light group 'Key'"]
    layer.aovs, layer.lightgroups = [], []
    # A view layer that opts out of denoising has no Noisy Image; neither has a render without
    # denoising.
    layer.cycles.use_denoising = False
    assert "Noisy Image" not in {b for _, b, _, _ in passes.enabled(layer, settings)}
    # An integrator that does not split its light: Direct/Indirect are left out and said so,
    # the Color passes stay.
    settings.integrator = "normals"
    names = {b for _, b, _, _ in passes.enabled(layer, settings)}
    assert "DiffCol" in names and "DiffDir" not in names and "GlossInd" not in names
    assert set(passes.unsupported(layer, settings)) == {
        "Shadow", "DiffDir", "DiffInd", "GlossDir", "GlossInd", "TransDir", "TransInd"}
    # Blender 4.2+ names through compat.
    from blender_addon import compat
    if bpy.app.version >= (4, 2, 0):
        assert compat.pass_name("GlossInd") == "Glossy Indirect"
        assert compat.pass_name("Noisy Image") == "Noisy Image"


def test_settings_follow_the_scenes_cycles_settings_until_set(addon):
    """An artist's scene carries its Light Paths, Sampling and Film choices in scene.cycles:
    a Tesela render takes them (Max Bounces as path vertices) until scene.tesela sets its
    own, and the Tesela panel shows (and edits) the Cycles setting it follows."""
    from blender_addon.settings import FOLLOWS_CYCLES, SceneSettings
    scene = bpy.context.scene
    t, c = scene.tesela, scene.cycles
    changed = {"samples": 77, "max_bounces": 5, "sample_clamp_indirect": 3.0,
               "filter_width": 2.0, "caustics_refractive": False, "pixel_filter_type": "GAUSSIAN"}
    saved_cycles = {k: getattr(c, k) for k in changed}
    names = FOLLOWS_CYCLES + ("max_depth",)
    saved_tesela = {k: getattr(t, k) for k in names if t.is_property_set(k)}
    try:
        for k in names:
            t.property_unset(k)
        for k, v in changed.items():
            setattr(c, k, v)
        s = SceneSettings(scene)
        args = tesela_engine.renderer_args("tesela", "s.gltf", s, 8, 8, None)
        joined = " ".join(args)
        for want in ("--spp 77", "--max-depth 7", "--clamp-indirect 3.0", "--filter gaussian",
                     "--filter-width 2.0", "--no-caustics-refractive"):
            assert want in joined, (want, joined)
        assert s.follows_cycles("samples") and not s.follows_cycles("integrator")
        # Set for Tesela: its own value, whatever Cycles says.
        t.samples, t.max_depth, t.caustics_refractive = 5, 3, True
        joined = " ".join(tesela_engine.renderer_args("tesela", "s.gltf", s, 8, 8, None))
        assert "--spp 5" in joined and "--max-depth 3" in joined
        assert "--no-caustics-refractive" not in joined and "--filter-width 2.0" in joined
        assert not s.follows_cycles("samples")
    finally:
        for k, v in saved_cycles.items():
            setattr(c, k, v)
        for k in names:
            t.property_unset(k)
        for k, v in saved_tesela.items():
            setattr(t, k, v)


class _Layout:
    """Records what a panel draws (bpy layouts cannot be made without a window)."""

    def __init__(self, drawn):
        self.drawn = drawn
        self.use_property_split = self.use_property_decorate = self.active = None

    def column(self, **kw):
        return self

    row = box = column

    def prop(self, owner, name, **kw):
        self.drawn.append((owner, name, kw.get("text")))

    def label(self, **kw):
        self.drawn.append((None, "label", kw.get("text")))


def test_render_panel_shows_the_cycles_setting_a_tesela_setting_follows(addon):
    from types import SimpleNamespace

    from blender_addon import ui
    scene = bpy.context.scene
    t = scene.tesela
    was_set = t.is_property_set("samples"), t.samples
    t.property_unset("samples")
    t.glossy_bounces = t.glossy_bounces
    try:
        drawn = []
        panel = SimpleNamespace(layout=_Layout(drawn))
        ui.TESELA_PT_render.draw(panel, SimpleNamespace(scene=scene, engine="TESELA"))
        owners = {name: owner for owner, name, _ in drawn}
        assert owners["samples"] == scene.cycles
        assert owners["glossy_bounces"] == t and owners["integrator"] == t
        assert any(n == "label" and "Cycles" in (text or "") for _, n, text in drawn)
    finally:
        if was_set[0]:
            t.samples = was_set[1]
