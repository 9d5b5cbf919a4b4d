"""tesela-farm on a local Dask cluster of 2 worker processes: a still split into sample ranges,
a 4-frame sequence, a worker killed while its renderer runs, a failing renderer and an
unreachable scheduler. Every image is compared with a render on this machine."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
FARM = REPO / "farm"
# The workers are spawned processes: they inherit this path, so the package needs no install.
if str(FARM) not in sys.path:
    sys.path.insert(0, str(FARM))

OpenEXR = pytest.importorskip("OpenEXR")
try:
    import distributed
    import psutil
except ImportError as exc:  # CI installs them (scripts/test.sh): a missing one is a failure there
    if os.environ.get("CI", "").lower() in ("1", "true", "yes"):
        raise
    pytest.skip(f"dask.distributed is not installed ({exc})", allow_module_level=True)

from tesela_farm import cli, farm, jobs  # noqa: E402

SCENE = REPO / "scenes" / "cornell-box.gltf"
SIZE = ["--width", "40", "--height", "32"]
REL = 1e-5


@pytest.fixture(scope="module")
def cluster():
    c = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                 dashboard_address=None)
    client = distributed.Client(c)
    yield c, client
    client.close()
    c.close()


def test_sample_ranges_tile_the_samples_and_frames_are_numbered():
    for spp, parts in [(24, 5), (7, 7), (3, 8), (4096, 6)]:
        plan = jobs.split_samples(spp, parts)
        assert plan[0].start == 0 and plan[-1].end == spp
        assert all(a.end == b.start for a, b in zip(plan, plan[1:]))
        assert all(p.end > p.start for p in plan) and len(plan) == min(spp, parts)
        sizes = [p.end - p.start for p in plan]
        assert max(sizes) - min(sizes) <= 1
    assert jobs.frame_output("out/f_####.exr", 7) == "out/f_0007.exr"
    assert jobs.frame_output("a#/b_##.png", 123) == "a#/b_123.png"
    with pytest.raises(ValueError):
        jobs.frame_output("out/still.exr", 1)


def test_a_scene_travels_with_its_buffers_and_images(tmp_path):
    doc = {"asset": {"version": "2.0"}, "buffers": [{"uri": "data/mesh%20a.bin",
                                                     "byteLength": 3}],
           "images": [{"uri": "data:image/png;base64,AAAA"}, {"uri": "tex/wood.png"}],
           "extensions": {"TESELA_render": {"spp": 96}}}
    (tmp_path / "data").mkdir()
    (tmp_path / "tex").mkdir()
    (tmp_path / "data" / "mesh a.bin").write_bytes(b"abc")
    (tmp_path / "tex" / "wood.png").write_bytes(b"png")
    scene = tmp_path / "shot.gltf"
    scene.write_text(json.dumps(doc))
    b = jobs.bundle(scene)
    assert b["main"] == "shot.gltf"
    assert b["files"]["data/mesh a.bin"] == b"abc" and b["files"]["tex/wood.png"] == b"png"
    assert len(b["files"]) == 3
    assert jobs.scene_spp(scene) == 96
    doc["images"][1]["uri"] = "../elsewhere.png"
    scene.write_text(json.dumps(doc))
    with pytest.raises(jobs.SceneError, match="outside the scene's folder.*--shared"):
        jobs.bundle(scene)


def channels(path: Path) -> dict[str, np.ndarray]:
    return {k: np.asarray(v.pixels, dtype=np.float64)
            for k, v in OpenEXR.File(str(path)).channels().items()}


def worst_relative_error(want: Path, got: Path) -> float:
    """Largest per-pixel difference relative to the pixel's magnitude, over every layer."""
    a, b = channels(want), channels(got)
    assert a.keys() == b.keys()
    worst = 0.0
    for k in a:
        h, w = a[k].shape[:2]
        x, y = a[k].reshape(h, w, -1), b[k].reshape(h, w, -1)
        err = np.abs(x - y).max(axis=2)
        scale = np.maximum(np.abs(x), np.abs(y)).max(axis=2)
        rel = np.where(err == 0, 0.0, err / np.where(scale == 0, 1.0, scale))
        worst = max(worst, float(rel.max()))
    return worst


def local_render(tesela_bin, scene: Path, out: Path, *args: str) -> Path:
    subprocess.run([str(tesela_bin), "render", str(scene), "-o", str(out), "--quiet", *args],
                   check=True, stdin=subprocess.DEVNULL)
    return out


def test_still_in_sample_ranges_equals_the_local_render(cluster, tesela_bin, tmp_path, capsys):
    c, _ = cluster
    out = tmp_path / "farm.exr"
    passes = "depth,normal,denoising_albedo"
    rc = cli.main(["render", str(SCENE), "--scheduler", c.scheduler_address, "-o", str(out),
                   "--spp", "24", "--parts", "5", "--passes", passes, "--tesela",
                   str(tesela_bin), "--", *SIZE, "--threads", "1"])
    err = capsys.readouterr().err
    assert rc == 0, err
    # Progress: one line per finished part.
    assert err.count("done on tcp://") == 5, err
    want = local_render(tesela_bin, SCENE, tmp_path / "local.exr", "--spp", "24", "--passes",
                        passes, *SIZE)
    e = worst_relative_error(want, out)
    assert e <= REL, f"farm still differs from the local render by {e:.3g}"
    # The comparison can fail: a render of other samples is far off.
    other = local_render(tesela_bin, SCENE, tmp_path / "seed.exr", "--spp", "24", "--passes",
                         passes, "--seed", "9", *SIZE)
    assert worst_relative_error(other, out) > 0.01


def _frames(tmp_path: Path, n: int) -> list[Path]:
    """An animation exported one glTF per frame: the camera dollies in."""
    doc = json.loads(SCENE.read_text())
    cam = next(node for node in doc["nodes"] if "camera" in node)
    paths = []
    for f in range(n):
        cam["matrix"][14] = 1.94 - 0.15 * f
        p = tmp_path / f"shot_{f:02d}.gltf"
        p.write_text(json.dumps(doc))
        paths.append(p)
    return paths


def test_four_frames_one_task_each_equal_local_renders(cluster, tesela_bin, tmp_path, capsys):
    c, client = cluster
    scenes = _frames(tmp_path, 4)
    rc = cli.main(["render", *map(str, scenes), "--frames", "--frame-start", "10",
                   "--scheduler", c.scheduler_address, "-o", str(tmp_path / "out" / "f_###.exr"),
                   "--spp", "8", "--tesela", str(tesela_bin), "--", *SIZE, "--threads", "1"])
    err = capsys.readouterr().err
    assert rc == 0, err
    outs = [tmp_path / "out" / f"f_{10 + i:03d}.exr" for i in range(4)]
    for scene, out in zip(scenes, outs):
        want = local_render(tesela_bin, scene, tmp_path / f"{scene.stem}.exr", "--spp", "8",
                            *SIZE)
        e = worst_relative_error(want, out)
        assert e <= REL, f"{out.name} differs from its local render by {e:.3g}"
    # Frames are not interchangeable (a mix-up of outputs would fail above).
    assert worst_relative_error(outs[0], outs[3]) > 0.01


def test_a_failing_renderer_reports_its_message_and_status(cluster, tesela_bin, tmp_path,
                                                           capsys):
    c, _ = cluster
    rc = cli.main(["render", str(SCENE), "--scheduler", c.scheduler_address, "-o",
                   str(tmp_path / "x.exr"), "--spp", "4", "--tesela", str(tesela_bin), "--",
                   *SIZE, "--integrator", "no_such_integrator"])
    err = capsys.readouterr().err
    assert rc == 1, err
    assert "unknown integrator `no_such_integrator`" in err and "failed on tcp://" in err, err
    assert not (tmp_path / "x.exr").exists()
    # A scene the renderer cannot load: its status (3), the file named as the user names it.
    bad = tmp_path / "broken.gltf"
    bad.write_text(json.dumps({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
                               "meshes": [{"primitives": [{"attributes": {"POSITION": 7}}]}],
                               "scenes": [{"nodes": [0]}]}))
    rc = cli.main(["render", str(bad), "--scheduler", c.scheduler_address, "-o",
                   str(tmp_path / "x.exr"), "--spp", "4", "--tesela", str(tesela_bin)])
    err = capsys.readouterr().err
    assert rc == 3, err
    assert "tesela: error: broken.gltf: accessor 7" in err, err


def test_unreachable_scheduler_is_a_clear_error(tesela_bin, tmp_path):
    with socket.socket() as s:  # a port nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = dict(os.environ, PYTHONPATH=str(FARM), TESELA_BIN=str(tesela_bin))
    proc = subprocess.run(
        [sys.executable, "-m", "tesela_farm", "render", str(SCENE), "--scheduler",
         f"tcp://127.0.0.1:{port}", "--connect-timeout", "2", "-o", str(tmp_path / "x.exr")],
        capture_output=True, text=True, env=env, timeout=120, stdin=subprocess.DEVNULL)
    assert proc.returncode == 1, proc.stderr
    assert f"cannot reach the Dask scheduler at tcp://127.0.0.1:{port}" in proc.stderr, proc.stderr


def _renderers(client) -> list[psutil.Process]:
    """The tesela processes the cluster's workers are running."""
    found = []
    for pid in client.run(os.getpid).values():
        try:
            found += [k for k in psutil.Process(pid).children() if k.name() == "tesela"]
        except psutil.NoSuchProcess:
            pass
    return found


def test_a_cancelled_farm_render_stops_the_running_renderers(cluster, tesela_bin, tmp_path):
    """SIGTERM to tesela-farm (a user's Ctrl-C, or a job manager): exit status 130, and the
    renderers already running on the workers stop (Dask itself cannot stop a running task)."""
    c, client = cluster
    client.wait_for_workers(2)
    env = dict(os.environ, PYTHONPATH=str(FARM))
    proc = subprocess.Popen(
        [sys.executable, "-m", "tesela_farm", "render", str(SCENE), "--scheduler",
         c.scheduler_address, "-o", str(tmp_path / "x.exr"), "--spp", "1000000", "--parts", "2",
         "--tesela", str(tesela_bin), "--", *SIZE, "--threads", "1"],
        env=env, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        text=True)
    try:
        deadline = time.monotonic() + 60
        while len(_renderers(client)) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        running = _renderers(client)
        assert len(running) == 2, "the parts never started"
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "cancelled" in err, err
    # Each task looks at the cancel event twice a second.
    deadline = time.monotonic() + 10
    while any(map(_running, running)) and time.monotonic() < deadline:
        time.sleep(0.05)
    left = [r.pid for r in running if _running(r)]
    for r in running:
        if _running(r):
            r.kill()
    assert left == [], "renderers kept running after the farm render was cancelled"


def _running(p: psutil.Process) -> bool:
    """Alive and not a zombie (a killed orphan waits as a zombie until its new parent reaps
    it)."""
    try:
        return p.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _kill_a_worker_while_it_renders(client, killed: dict, stop: threading.Event):
    """SIGKILLs the first worker process seen running a tesela child; records both pids."""
    pids = client.run(os.getpid)
    while not stop.is_set():
        for pid in pids.values():
            try:
                kids = [k for k in psutil.Process(pid).children() if k.name() == "tesela"]
            except psutil.NoSuchProcess:
                continue
            if kids:
                os.kill(pid, signal.SIGKILL)
                killed["worker"] = pid
                # A part renders for seconds: a renderer still there a second later was left
                # behind by its worker.
                deadline = time.monotonic() + 1.0
                while time.monotonic() < deadline and any(map(_running, kids)):
                    time.sleep(0.02)
                killed["left_behind"] = [k.pid for k in kids if _running(k)]
                for k in kids:
                    if _running(k):
                        k.kill()
                return
        time.sleep(0.02)


def test_a_worker_killed_mid_task_is_rescheduled_and_the_still_is_exact(cluster, tesela_bin,
                                                                         tmp_path, capsys):
    c, client = cluster
    client.wait_for_workers(2)
    out = tmp_path / "farm.exr"
    args = ["--width", "64", "--height", "64", "--threads", "1"]
    killed: dict = {}
    stop = threading.Event()
    killer = threading.Thread(target=_kill_a_worker_while_it_renders,
                              args=(client, killed, stop))
    killer.start()
    try:
        farm.render_still(client, SCENE, out, farm.Settings(tesela=str(tesela_bin),
                                                            render_args=args),
                          parts=4, spp=320)
    finally:
        stop.set()
        killer.join()
    assert "worker" in killed, "no worker was seen rendering"
    assert killed["left_behind"] == [], "the renderer outlived its killed worker"
    want = local_render(tesela_bin, SCENE, tmp_path / "local.exr", "--spp", "320", *args[:4])
    e = worst_relative_error(want, out)
    assert e <= REL, f"farm still after a killed worker differs by {e:.3g}"
