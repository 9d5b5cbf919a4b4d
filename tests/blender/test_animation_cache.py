"""The mesh store of an animation render: a 3-frame Render Animation of a scene whose meshes
stand still while the camera moves writes each mesh once (the render log's per-frame "meshes
written N, reused M"), a mesh deformed every frame (a Wave modifier) is written every frame,
no temp folder is left after the job, and every frame equals an F12 render of it alone (its
own job, so a full export) pixel for pixel."""

import os
import re
import sys
import tempfile
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

from blender_addon.process import TMP_PREFIX  # noqa: E402

SIZE = 32
FRAME_LINE = re.compile(r"Tesela: frame (\d+): meshes written (\d+), reused (\d+)")


def animated_camera_scene(tmp_path):
    """light_over_plane's plane and box, a wave-deformed grid, and a camera panning over
    frames 1-3; renders go to tmp_path/frame_####.exr."""
    info = scenes.light_over_plane("point")
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=1.0,
                                    location=(0.8, 0.4, 0.3))
    grid = bpy.context.active_object
    grid.data.materials.append(scenes.lambert("GridMat", (0.3, 0.6, 0.3)))
    wave = grid.modifiers.new("Wave", "WAVE")
    wave.height, wave.width, wave.speed = 0.1, 0.3, 0.2
    scene = info.scene
    cam = scene.camera
    for frame, x in ((1, -0.3), (3, 0.3)):
        cam.location.x = x
        cam.keyframe_insert("location", frame=frame)
    scene.frame_start, scene.frame_end = 1, 3
    r = scene.render
    r.engine = "TESELA"
    r.resolution_x, r.resolution_y, r.resolution_percentage = SIZE, SIZE, 100
    s = r.image_settings
    if hasattr(s, "media_type"):
        s.media_type = "IMAGE"
    s.file_format, s.color_mode, s.color_depth = "OPEN_EXR", "RGBA", "32"
    r.filepath, r.use_file_extension = str(tmp_path / "frame_####"), True
    t = scene.tesela
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", 4, 2, 3
    t.threads = 2
    return scene


@pytest.fixture
def restored_scene():
    """The settings the test changes, put back afterwards (the scene outlives the module)."""
    scene = bpy.context.scene
    r, s = scene.render, scene.render.image_settings
    saved = [(r, k, getattr(r, k)) for k in ("engine", "resolution_x", "resolution_y",
                                             "resolution_percentage", "filepath",
                                             "use_file_extension")]
    saved += [(s, k, getattr(s, k)) for k in ("file_format", "color_mode", "color_depth")]
    saved += [(scene, k, getattr(scene, k)) for k in ("frame_start", "frame_end", "frame_current")]
    yield
    for owner, k, v in saved:
        setattr(owner, k, v)
    for k in ("integrator", "samples", "max_depth", "seed", "threads"):
        scene.tesela.property_unset(k)
    scenes.clear_scene()


def our_tmpdirs():
    prefix = "%s%d-" % (TMP_PREFIX, os.getpid())
    return {n for n in os.listdir(tempfile.gettempdir()) if n.startswith(prefix)}


def frame_counts(text):
    return [tuple(int(v) for v in m.groups()) for m in FRAME_LINE.finditer(text)]


def test_static_meshes_are_written_once_per_animation(addon, tesela_bin, tmp_path, monkeypatch,
                                                      capfd, restored_scene):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = animated_camera_scene(tmp_path)
    before = our_tmpdirs()
    capfd.readouterr()
    assert bpy.ops.render.render(animation=True) == {"FINISHED"}
    log = capfd.readouterr().out
    # Plane, box and grid written by frame 1; then only the waving grid.
    assert frame_counts(log) == [(1, 3, 0), (2, 1, 2), (3, 1, 2)], log[-2000:]
    assert our_tmpdirs() == before, "the job's folder is removed when it ends"
    frames = [imgcompare.read_exr(tmp_path / ("frame_%04d.exr" % f)) for f in (1, 2, 3)]
    assert not np.array_equal(frames[0], frames[2]), "the camera moves"

    for f in (2, 3):
        scene.frame_set(f)
        scene.render.filepath = str(tmp_path / ("single_%d_" % f))
        capfd.readouterr()
        assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
        assert frame_counts(capfd.readouterr().out) == [(f, 3, 0)], "a job of its own"
        single = imgcompare.read_exr(tmp_path / ("single_%d_.exr" % f))
        assert np.array_equal(single, frames[f - 1]), "frame %d: cached == full export" % f
    assert our_tmpdirs() == before


def test_the_store_forgets_meshes_two_frames_unused(tmp_path):
    """A mesh no render of the current or the previous frame used is removed with its file; the
    frame's own files go after each render, the folder at the job's end."""
    from blender_addon.export.buffer import FLOAT, Buffer
    from blender_addon.export.mesh_store import MeshStore

    store = MeshStore(str(tmp_path / "job"))

    def put(digest):
        b = Buffer()
        b.add(np.zeros((3, 3), dtype=np.float32), FLOAT, "VEC3", None)
        return store.put(digest, b, None, [])

    store.begin_render(1)
    a, b = put("a"), put("b")
    (tmp_path / "job" / "scene.gltf").write_text("{}")
    store.end_render()
    assert sorted(os.listdir(tmp_path / "job")) == ["meshes"]
    store.begin_render(2)
    assert store.get("a") is a and (store.written, store.reused) == (0, 1)
    store.begin_render(3)  # b: unused by frame 2, but frame 1 was the one before
    assert store.get("b") is b
    store.begin_render(4)
    store.begin_render(5)  # a: unused by frames 3 and 4; b used by 3
    assert os.listdir(tmp_path / "job" / "meshes") == ["b.bin"]
    assert store.get("a") is None
    store.begin_render(6)
    assert os.listdir(tmp_path / "job" / "meshes") == []
    store.close()
    assert not (tmp_path / "job").exists()
