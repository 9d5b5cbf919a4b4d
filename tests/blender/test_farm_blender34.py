"""A render-farm worker (Flamenco, Deadline, OpenCue: a "Blender render" job) with Debian's
Blender 3.4: the add-on zip with the real renderer bundled is installed headless in one
Blender, then each job is its own `blender -b --addons tesela SCENE.blend -E TESELA -f 1`
with no TESELA_BIN and no tesela on PATH. The frame renders with farm-parsable progress and
exits 0; a frame whose renderer dies (as under a node's OOM killer) makes Blender exit
non-zero, with an Error line saying why, and leaves no process or temp folder behind."""

import os
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import imgcompare

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
BLENDER = os.environ.get("TESELA_BLENDER") or shutil.which("blender")

pytestmark = pytest.mark.skipif(BLENDER is None,
                                reason="no 'blender' executable (Debian package 'blender')")


@pytest.fixture(scope="module")
def worker(tmp_path_factory, tesela_bin):
    """(base folder, environment) of a farm worker with the bundled add-on installed."""
    base = tmp_path_factory.mktemp("farm worker")
    build = subprocess.run([str(REPO / "scripts" / "build_addon.sh"), "--binary", str(tesela_bin),
                            "--oidn", str(base / "no oidn"), "--out", str(base / "dist")],
                           capture_output=True, text=True, timeout=300)
    assert build.returncode == 0, build.stderr
    zipf = build.stdout.strip().splitlines()[-1]
    env = {k: v for k, v in os.environ.items()
           if k not in ("TESELA_BINARY", "TESELA_BIN", "BLENDER_USER_SCRIPTS")}
    env.update(HOME=str(base / "home"), XDG_CONFIG_HOME=str(base / "xdg"),
               BLENDER_USER_SCRIPTS=str(base / "scripts"), PATH="/usr/bin:/bin",
               TMPDIR=str(base / "tmp"))
    (base / "tmp").mkdir()
    install = subprocess.run(
        [BLENDER, "-b", "--factory-startup", "--python-expr",
         "import bpy; bpy.ops.preferences.addon_install(filepath=%r)" % zipf],
        env=env, capture_output=True, text=True, timeout=300)
    assert (base / "scripts" / "addons" / "tesela" / "bin" / "tesela").is_file(), install.stdout
    scene = base / "shot.blend"
    make = subprocess.run([BLENDER, "-b", "--factory-startup", "--addons", "tesela", "--python",
                           str(HERE / "blender34_make_scene.py"), "--", str(scene), "simple",
                           "48", "32", "16"], env=env, capture_output=True, text=True,
                          timeout=300)
    assert "TESELA_SCENE_SAVED" in make.stdout, make.stdout[-3000:] + make.stderr[-3000:]
    return base, env, scene


def job(scene, out):
    """The command line a farm's Blender job type runs for frame 1."""
    return [BLENDER, "-b", "--addons", "tesela", str(scene), "-E", "TESELA", "-o", str(out),
            "-F", "OPEN_EXR", "-f", "1"]


def test_a_frame_renders_with_the_bundled_renderer_and_progress(worker):
    base, env, scene = worker
    p = subprocess.run(job(scene, base / "frame_###"), env=env, capture_output=True, text=True,
                       timeout=300)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    # What farm log parsers read: Blender's Fra: stats lines, a percentage line per 5%, the
    # saved file.
    assert "Fra:1 " in p.stdout and "Tesela: 100% | Sample 16/16" in p.stdout, p.stdout[-3000:]
    assert "Saved: '%s'" % (base / "frame_001.exr") in p.stdout
    img = imgcompare.read_exr(base / "frame_001.exr")
    assert img.shape[:2] == (32, 48) and np.isfinite(img).all() and img[..., :3].mean() > 0.01
    assert [n for n in os.listdir(base / "tmp") if n.startswith("tesela")] == []


def _renderer_of(blender_pid):
    """Pid of the tesela renderer Blender started, if running."""
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % name) as f:
                stat = f.read()
        except OSError:
            continue
        comm, rest = stat.split("(", 1)[1].rsplit(")", 1)
        if comm == "tesela" and int(rest.split()[1]) == blender_pid:
            return int(name)
    return None


def _start_heavy_frame(base, env, scene, name):
    """Blender rendering a frame of a million samples per pixel (no row of it finishes in
    the test's time), its renderer's pid once the render loop runs, and Blender's output so
    far (a list the reader thread fills)."""
    heavy = ("import bpy; t = bpy.context.scene.tesela; t.samples = 1 << 20; "
             "t.use_adaptive_sampling = False")
    cmd = job(scene, base / name)
    cmd[-2:-2] = ["--python-expr", heavy]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True)
    lines = []
    reader = threading.Thread(target=lambda: lines.extend(p.stdout), daemon=True)
    reader.start()
    renderer = None
    deadline = time.monotonic() + 120
    while p.poll() is None and time.monotonic() < deadline:
        renderer = renderer or _renderer_of(p.pid)
        # The HELLO frame's stats line: the renderer has entered its render loop.
        if renderer and any("Tesela | Sample 0/" in ln for ln in lines):
            break
        time.sleep(0.01)
    else:
        p.kill()
        reader.join(timeout=10)
        pytest.fail("the renderer never started rendering: " + "".join(lines)[-3000:])
    time.sleep(0.5)  # mid-render
    return p, renderer, reader, lines


def _gone(pid):
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


def test_a_frame_whose_renderer_dies_fails_the_blender_job(worker):
    base, env, scene = worker
    p, renderer, reader, lines = _start_heavy_frame(base, env, scene, "dies_###")
    os.kill(renderer, signal.SIGKILL)  # as a node's OOM killer would
    p.wait(timeout=120)
    reader.join(timeout=10)
    out = "".join(lines)
    assert p.returncode != 0, out[-3000:]
    assert "Error: Tesela:" in out and "SIGKILL" in out, out[-3000:]
    assert not (base / "dies_001.exr").exists()
    assert [n for n in os.listdir(base / "tmp") if n.startswith("tesela")] == []


def test_a_job_stopped_by_the_farm_leaves_no_renderer(worker):
    """Farm managers cancel a task with SIGTERM: Blender exits non-zero and its renderer
    (whose stdin closes) stops with it."""
    base, env, scene = worker
    p, renderer, reader, _ = _start_heavy_frame(base, env, scene, "stopped_###")
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=120)
    reader.join(timeout=10)
    assert p.returncode != 0
    deadline = time.monotonic() + 2.0
    while not _gone(renderer) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert _gone(renderer), "the renderer outlived its Blender"
