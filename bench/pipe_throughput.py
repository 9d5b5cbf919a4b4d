"""Tile-paste throughput of the Blender add-on for a 3840x2160 frame.

    python bench/pipe_throughput.py [--renderer PATH] [--tile N] [--repeat N]

Run it with a Python that can `import bpy` (e.g. .venv/bin/python). It measures:

1. renderer alone: the producer writing the frame's tiles into a pipe that a reader drains
   without parsing (`os.read` into nothing): the cost of producing and moving the bytes;
2. reader only: the same stream parsed by blender_addon/protocol.py (frames -> numpy tiles);
3. the add-on end to end: `bpy.ops.render.render()` with engine TESELA at 3840x2160, whose
   time minus (1) is the overhead beyond the render itself (issue 3 asks for under 0.5 s); it
   includes Blender's own cost of any 4K render (measured with an engine that writes nothing),
   which is subtracted to give the add-on's share;
4. the pieces of (3) in isolation: pasting all tiles into the full-frame mirror (with the row
   flip) and one `rect.foreach_set` + `update_result` of the whole 4K frame.

The default producer is tests/blender/fake_renderer.py in its 'bench' mode (tiles of a constant
value, so the producer costs almost nothing); --renderer PATH benchmarks a real `tesela` with the
'albedo' integrator at 1 spp instead (then (1) includes its rendering time).
"""

import argparse
import io
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
W, H = 3840, 2160


def producer_cmd(args, gltf):
    if args.renderer:
        return [args.renderer, "render", gltf, "--pipe", "--pipe-version", "2", "--width", str(W), "--height", str(H),
                "--spp", "1", "--integrator", "albedo"]
    return [sys.executable, str(REPO / "tests/blender/fake_renderer.py"), "render", gltf, "--pipe",
            "--width", str(W), "--height", str(H), "--spp", "1"]


def producer_env(args):
    env = dict(os.environ, FAKE_TESELA_MODE="bench", FAKE_TESELA_TILE=str(args.tile))
    env.pop("FAKE_TESELA_LOG", None)
    return env


def run_producer(cmd, env, consume):
    p = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                         env=env, bufsize=0)
    t0 = time.perf_counter()
    n = consume(p.stdout)
    p.wait()
    p.stdin.close()
    return time.perf_counter() - t0, n


def drain(stream):
    n = 0
    while True:
        chunk = os.read(stream.fileno(), 1 << 20)
        if not chunk:
            return n
        n += len(chunk)


def parse(stream):
    from blender_addon import protocol
    r = protocol.FrameReader(stream)
    tiles = 0
    for m in r:
        if isinstance(m, protocol.Tile):
            tiles += 1
    return tiles


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--renderer", help="a real tesela binary (default: the fake renderer)")
    ap.add_argument("--tile", type=int, default=64, help="tile edge for the fake renderer")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="tesela-bench-")
    try:
        run(args, tmp)
    finally:
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)


def run(args, tmp):
    import bpy
    import numpy as np
    import blender_addon
    from blender_addon import compat

    scene = bpy.context.scene
    if not blender_addon.engine.TeselaRenderEngine.is_registered:
        blender_addon.register()
    gltf = os.path.join(tmp, "bench.gltf")
    bpy.ops.export_scene.tesela_gltf(filepath=gltf)
    cmd = producer_cmd(args, gltf)
    env = producer_env(args)

    def best(f):
        return min(f() for _ in range(args.repeat))

    t_prod = best(lambda: run_producer(cmd, env, drain)[0])
    _, nbytes = run_producer(cmd, env, drain)
    t_parse = best(lambda: run_producer(cmd, env, parse)[0])

    # (3) end to end through Blender
    r = scene.render
    r.engine = "TESELA"
    r.resolution_x, r.resolution_y, r.resolution_percentage = W, H, 100
    r.use_border = False
    scene.tesela.samples = 1
    scene.tesela.integrator = "albedo"
    os.environ.update(env)
    os.environ["TESELA_BINARY"] = cmd[0] if args.renderer else str(REPO / "tests/blender/fake_renderer.py")
    times = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        bpy.ops.render.render()
        times.append(time.perf_counter() - t0)
    t_blender = min(times)

    # (4) pieces
    mirror = np.zeros((H, W, 4), dtype=np.float32)
    tile = np.full((args.tile, args.tile, 4), 0.5, dtype=np.float32)
    t0 = time.perf_counter()
    for y in range(0, H, args.tile):
        for x in range(0, W, args.tile):
            h = min(args.tile, H - y)
            w = min(args.tile, W - x)
            mirror[H - y - h:H - y, x:x + w] = tile[:h, :w][::-1]
    t_paste = time.perf_counter() - t0

    class Probe(bpy.types.RenderEngine):
        bl_idname = "TESELA_BENCH_PROBE"
        bl_label = "probe"

        def render(self, depsgraph):
            res = self.begin_result(0, 0, W, H)
            p = compat.combined_pass(res)
            t0 = time.perf_counter()
            compat.pass_rect_set(p, mirror.reshape(-1))
            t1 = time.perf_counter()
            self.update_result(res)
            t2 = time.perf_counter()
            self.end_result(res)
            os.environ["_PROBE"] = "%f %f" % (t1 - t0, t2 - t1)

    class Null(bpy.types.RenderEngine):
        """Blender's own cost of a 4K render: a result begun and ended, nothing written."""
        bl_idname = "TESELA_BENCH_NULL"
        bl_label = "null"

        def render(self, depsgraph):
            self.end_result(self.begin_result(0, 0, W, H))

    bpy.utils.register_class(Probe)
    bpy.utils.register_class(Null)
    r.engine = "TESELA_BENCH_PROBE"
    bpy.ops.render.render()
    t_set, t_update = (float(v) for v in os.environ["_PROBE"].split())
    r.engine = "TESELA_BENCH_NULL"
    nulls = []
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        bpy.ops.render.render()
        nulls.append(time.perf_counter() - t0)
    t_null = min(nulls)
    bpy.utils.unregister_class(Null)
    bpy.utils.unregister_class(Probe)

    tiles = ((W + args.tile - 1) // args.tile) * ((H + args.tile - 1) // args.tile)
    mb = nbytes / 1e6
    print("Tesela pipe throughput, %dx%d frame, %d tiles of %dx%d, %.1f MB of frames, Blender %s"
          % (W, H, tiles, args.tile, args.tile, mb, bpy.app.version_string))
    print("producer: %s" % ("tesela (albedo, 1 spp)" if args.renderer else "fake_renderer.py bench mode"))
    print("(1) producer -> pipe -> drained:          %.3f s  (%.0f MB/s)" % (t_prod, mb / t_prod))
    print("(2) producer -> pipe -> protocol.py:      %.3f s  (parse overhead %.3f s)" % (t_parse, t_parse - t_prod))
    print("(3) producer -> add-on -> render result:  %.3f s  (overhead beyond (1): %.3f s)"
          % (t_blender, t_blender - t_prod))
    print("    of which Blender's own 4K render-result handling (an engine that writes nothing): %.3f s"
          % t_null)
    print("    the add-on's own share: %.3f s" % (t_blender - t_prod - t_null))
    print("(4) paste all tiles into the mirror:      %.3f s" % t_paste)
    print("    rect.foreach_set of the 4K frame:     %.3f s" % t_set)
    print("    update_result of the 4K frame:        %.3f s" % t_update)


if __name__ == "__main__":
    main()
