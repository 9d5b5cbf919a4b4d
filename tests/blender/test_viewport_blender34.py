"""The Rendered viewport in a real Blender GUI (Debian's Blender 3.4 under xvfb-run; TESELA_BLENDER
overrides): blender34_viewport.py switches a 3D viewport to Rendered with Tesela, screenshots it
after each step, and these tests read the screenshots and the add-on's state back.

The session is tests/blender/fake_session.py, whose image is a known pattern: the screenshot
must show it through Blender's view transform (Standard: sRGB), the view's cameras must be
Blender's own projection, moves must reach the session, a killed session must be reported in
the viewport and replaced on the next change, and leaving Rendered must end the process.
"""

import json
import os
from pathlib import Path

import numpy as np
import pytest

from test_addon_blender34 import BLENDER, XVFB, env34, leftovers, make_scene, private_tmp, run  # noqa: F401

HERE = Path(__file__).resolve().parent
FAKE_SESSION = HERE / "fake_session.py"

pytestmark = [
    pytest.mark.skipif(BLENDER is None, reason="no 'blender' executable (Debian package 'blender')"),
    pytest.mark.skipif(XVFB is None, reason="no xvfb-run (Debian package 'xvfb')"),
]


def srgb(c):
    c = np.clip(c, 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def screenshot(path):
    """The PNG as float (h, w, 3) display values, rows top to bottom."""
    import bpy
    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        w, h = img.size
        buf = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(buf)
    finally:
        bpy.data.images.remove(img)
    return buf.reshape(h, w, 4)[::-1, :, :3].copy()


def fake_display(width, height, generation):
    """What the fake session's image looks like on screen through the Standard view transform."""
    xs = (np.arange(width) + 0.5) / width
    ys = (np.arange(height) + 0.5) / height
    img = np.empty((height, width, 3))
    img[..., 0] = srgb(xs)[None, :]
    img[..., 1] = srgb(ys)[:, None]
    img[..., 2] = srgb(np.array((generation % 8) / 8.0))
    return img


def interior(img, margin=12):
    """Away from the region's edges and corner widgets."""
    return img[margin:-margin, margin:-margin]


@pytest.fixture(scope="module")
def gui_run(env34):
    base, env = env34
    blend = make_scene(base, env, "viewport.blend", w=64, h=48)
    tmp = private_tmp(base, "tmp viewport")
    out = base / "viewport out"
    out.mkdir()
    log = base / "viewport-session.jsonl"
    env = dict(env, TESELA_BINARY=str(FAKE_SESSION), FAKE_SESSION_LOG=str(log))
    # TMPDIR only for Blender (xvfb-run keeps its X authority file in TMPDIR).
    p = run([XVFB, "-a", "-s", "-screen 0 1280x800x24", "env", "TMPDIR=" + str(tmp),
             BLENDER, "-p", "0", "0", "800", "600",
             "--addons", "tesela", str(blend), "--python", str(HERE / "blender34_viewport.py"),
             "--", str(out)], env, timeout=240)
    status_path = out / "status.json"
    assert status_path.is_file(), p.stdout[-3000:] + p.stderr[-3000:]
    status = json.loads(status_path.read_text())
    assert status["error"] is None, status["error"] + p.stdout[-3000:]
    steps = {s["name"]: s for s in status["steps"]}
    cmds = [json.loads(ln) for ln in log.read_text().splitlines() if ln.strip()]
    return status, steps, cmds, tmp


def test_viewport_shows_the_session_image(gui_run):
    _, steps, _, _ = gui_run
    for name in ("first", "persp", "ortho", "camera", "moved"):
        s = steps[name]
        w, h = s["region"][:2]
        assert s["image_size"] == [w, h] and s["area"] == [w, h], name
        got = interior(screenshot(s["shot"]))
        want = interior(fake_display(w, h, s["generation"]))
        err = np.abs(got - want).max(axis=-1)
        # 8-bit screenshots; the camera view's frame outline is the only thing drawn over it.
        assert (err <= 2.5 / 255).mean() > 0.99, (name, (err > 2.5 / 255).mean())


def test_viewport_border_draws_its_window(gui_run):
    status, steps, _, _ = gui_run
    s = steps["border"]
    w, h = s["region"][:2]
    x0, x1 = int(0.25 * w), int(0.75 * w)
    top, bottom = h - int(0.9 * h), h - int(0.5 * h)
    assert status["border_sent"] == [x0, top, x1 - x0, bottom - top]
    assert status["border_image"] == status["border_sent"]
    shot = screenshot(s["shot"])
    want = fake_display(w, h, s["generation"])
    inside = (slice(top + 2, bottom - 2), slice(x0 + 2, x1 - 2))
    err = np.abs(shot[inside] - want[inside]).max(axis=-1)
    assert (err <= 2.5 / 255).mean() > 0.99
    # Outside the border the previous view's image is not drawn.
    below = (slice(bottom + 5, h - 12), slice(12, w - 12))
    assert (np.abs(shot[below] - want[below]).max(axis=-1) > 0.05).mean() > 0.5


def test_views_are_blenders_projection(gui_run):
    _, steps, _, _ = gui_run
    for name, kind in (("persp", "PERSP"), ("ortho", "ORTHO"), ("camera", "CAMERA")):
        s = steps[name]
        assert s["perspective"] == kind
        assert s["window_tesela"] == pytest.approx(s["window_blender"], rel=1e-5, abs=1e-6), name
        cam = np.array(s["camera_matrix"])
        want = np.array(s["view_matrix_inv"])
        assert cam[:3, :3] == pytest.approx(want[:3, :3], abs=1e-5), name
        if kind != "ORTHO":  # an ortho camera stands far/2 behind the view point
            assert cam[:3, 3] == pytest.approx(want[:3, 3], abs=1e-4), name
    assert steps["ortho"]["type"] == "ORTHO"


def test_view_and_object_moves_reach_the_session(gui_run):
    _, steps, cmds, _ = gui_run
    gens = [steps[n]["generation"] for n in ("first", "persp", "ortho", "camera", "moved")]
    assert gens == sorted(set(gens))  # every change rendered anew
    assert steps["moved"]["sent"][-1] == "transform"
    moves = [c for c in cmds if c.get("cmd") == "transform"]
    assert [c["node"] for c in moves] == ["Cube"]
    views = [c for c in cmds if c.get("cmd") == "view"]
    assert len(views) >= 4 and all(v["width"] == steps["first"]["region"][0] for v in views)


def test_killed_session_is_reported_and_replaced(gui_run):
    status, steps, cmds, _ = gui_run
    killed, moved = steps["killed"], steps["moved"]
    assert "killed by signal SIGKILL" in killed["dead"]
    a, b = screenshot(killed["shot"]), screenshot(moved["shot"])
    diff = np.abs(a - b).max(axis=-1) > 0.1
    # The message is drawn at the top left; the last image stays everywhere else.
    assert diff[20:70, :500].sum() > 200
    assert diff[80:, :].sum() == 0
    restarted = steps["restarted"]
    assert restarted["pid"] != killed["pid"] and restarted["dead"] is None
    assert restarted["sent"][-3:] == ["load", "settings", "view"]
    starts = [c["start"] for c in cmds if "start" in c]
    assert starts[:2] == [killed["pid"], restarted["pid"]]


def test_leaving_rendered_opening_a_file_and_quitting_end_the_session(gui_run):
    status, steps, cmds, tmp = gui_run
    assert steps["left"]["sessions"] == 0
    assert steps["restarted"]["pid"] not in status["alive_before_quit"]
    assert status["after_open_alive"] is False
    assert status["engine_switch_alive"] is False  # another render engine
    assert status["area_switch_alive"] is False    # the area became another editor
    last = steps["before_quit"]["pid"]
    assert status["alive_before_quit"] == [last]  # only the newest file's session ran
    assert not pid_alive(last)  # Blender quit: gone
    assert len([c for c in cmds if "start" in c]) == 6  # the first, restart, 4 re-entries
    assert leftovers(tmp) == []


def pid_alive(pid):
    try:
        os.kill(pid, 0)
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (ProcessLookupError, OSError):
        return False


def session_binary():
    """The real renderer when it has the session subcommand (TESELA_SESSION_BIN, TESELA_BIN,
    else target/release/tesela)."""
    import subprocess
    repo = HERE.parent.parent
    path = os.environ.get("TESELA_SESSION_BIN") or os.environ.get("TESELA_BIN") \
        or str(repo / "target" / "release" / "tesela")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        pytest.skip("no tesela binary at %s (set TESELA_SESSION_BIN or TESELA_BIN)" % path)
    if subprocess.run([path, "session", "--help"], capture_output=True, timeout=30).returncode:
        pytest.skip("%s has no 'session' subcommand yet (branch session lands it)" % path)
    return path


def test_camera_view_equals_f12(env34):
    """Real renderer: the viewport in camera view (frame filling the region, 8 samples, pixel
    size 1) shows what F12 renders of the same view, through the same view transform."""
    binary = session_binary()
    base, env = env34
    blend = make_scene(base, env, "viewport f12.blend", w=64, h=48)
    tmp = private_tmp(base, "tmp viewport f12")
    out = base / "viewport f12 out"
    out.mkdir()
    env = dict(env, TESELA_BINARY=binary)
    p = run([XVFB, "-a", "-s", "-screen 0 1280x800x24", "env", "TMPDIR=" + str(tmp),
             BLENDER, "-p", "0", "0", "400", "300", "--addons", "tesela", str(blend),
             "--python", str(HERE / "blender34_viewport_f12.py"), "--", str(out), "8"],
            env, timeout=300)
    status_path = out / "status.json"
    assert status_path.is_file(), p.stdout[-3000:] + p.stderr[-3000:]
    status = json.loads(status_path.read_text())
    assert status["error"] is None, status
    assert status["samples"] == 8
    view = screenshot(out / "viewport.png")
    f12 = screenshot(out / "f12.png")
    w, h = status["region"]
    assert f12.shape == (h, w, 3) and view.shape[:2] == (h, w)
    err = np.abs(interior(view) - interior(f12)).max(axis=-1)
    assert (err <= 2.5 / 255).mean() > 0.99, (err > 2.5 / 255).mean()
    assert leftovers(tmp) == []


def test_material_preview_icon_is_rendered_by_tesela(env34):
    """bl_use_preview: Blender's preview job renders the material icon with Tesela."""
    binary = env34_renderer()
    base, env = env34
    blend = make_scene(base, env, "preview.blend", w=64, h=48)
    tmp = private_tmp(base, "tmp preview")
    status_path = base / "preview status.json"
    env = dict(env, TESELA_BINARY=binary)
    p = run([XVFB, "-a", "-s", "-screen 0 1280x800x24", "env", "TMPDIR=" + str(tmp),
             BLENDER, "-p", "0", "0", "1000", "700", "--addons", "tesela", str(blend),
             "--python", str(HERE / "blender34_preview.py"), "--", str(status_path)],
            env, timeout=300)
    assert status_path.is_file(), p.stdout[-3000:] + p.stderr[-3000:]
    status = json.loads(status_path.read_text())
    assert status["error"] is None, (status, p.stdout[-2000:])
    r, g, b, _ = status["icon_mean"]
    assert g > 1.5 * r and g > 1.5 * b  # the green material
    assert "Tesela: 100% | Sample 64/64" in p.stdout, p.stdout[-2000:]  # by Tesela, 64 spp
    assert leftovers(tmp) == []


def env34_renderer():
    """The real renderer for F12-like renders (TESELA_BIN, else target/release/tesela)."""
    repo = HERE.parent.parent
    path = os.environ.get("TESELA_BIN") or str(repo / "target" / "release" / "tesela")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        pytest.skip("no tesela binary at %s (set TESELA_BIN)" % path)
    return path
