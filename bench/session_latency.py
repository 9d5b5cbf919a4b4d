"""Latency of `tesela session` (docs/session.md): from a command on the pipe to the first IMAGE
of the new generation, driven the way the viewport add-on drives it (load, then camera moves, a
material change, a light change, replacing a mesh) while the session keeps refining.

    python bench/session_latency.py [--tesela target/release/tesela] [--threads 2]
                                    [--width 640] [--height 360] [--repeat 5]

Scenes (bench/scenes.py): the Cornell box (32 triangles) and the displaced spheres (1.08 M
triangles) with a fourth sphere of 99.5 k triangles, the mesh that gets replaced. Issue
targets: camera move <= 30 ms (Cornell), <= 100 ms (1 M); material / light <= 50 ms; replacing
the 100 k mesh in the 1 M scene <= 1 s. Prints one line per scene and command kind: median,
worst and first of --repeat runs, in milliseconds. The first move or replacement of a mesh
the file placed once takes it out of the world-space BVH (built again); later ones only build
the instances' top level and the new mesh's bottom level.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes  # noqa: E402

IMAGE, COMMAND = 16, 32


def command(obj):
    j = json.dumps(obj).encode()
    payload = struct.pack("<I", len(j)) + j
    return struct.pack("<II", COMMAND, len(payload)) + payload


class Session:
    """A session process whose IMAGE generations a reader thread timestamps."""

    def __init__(self, binary, threads):
        self.proc = subprocess.Popen([binary, "session", "--threads", str(threads)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL)
        self.cond = threading.Condition()
        self.first_image = {}  # generation -> time of its first IMAGE
        self.errors = []
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        out = self.proc.stdout
        while True:
            head = out.read(8)
            if len(head) < 8:
                return
            kind, n = struct.unpack("<II", head)
            payload = out.read(n)
            now = time.perf_counter()
            with self.cond:
                if kind == IMAGE:
                    gen = struct.unpack_from("<Q", payload)[0]
                    self.first_image.setdefault(gen, now)
                elif kind == 5:
                    self.errors.append(payload.decode())
                self.cond.notify_all()

    def send(self, obj):
        self.proc.stdin.write(command(obj))
        self.proc.stdin.flush()
        return time.perf_counter()

    def wait_generation(self, gen, timeout=120.0):
        with self.cond:
            ok = self.cond.wait_for(lambda: gen in self.first_image or self.errors, timeout)
            if self.errors:
                raise RuntimeError(self.errors[-1])
            if not ok:
                raise TimeoutError("no image of generation %d" % gen)
            return self.first_image[gen]

    def close(self):
        self.proc.stdin.close()
        self.proc.wait(timeout=30)


def camera_matrix(origin, target):
    """The camera's world matrix in glTF's y-up space, column-major (as a node's `matrix`)."""
    rot = scenes._Z_TO_Y_UP @ scenes.look_at_matrix(origin, target, (0.0, 0.0, 1.0))
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = scenes._Z_TO_Y_UP @ np.asarray(origin, float)
    return [float(v) for v in m.T.reshape(-1)]


def build(folder):
    """The benchmark scenes as files: {name: (scene path, camera, replacement mesh path)}."""
    out = {}
    cornell = scenes.cornell()
    out["cornell"] = (scenes.write_gltf(cornell, folder / "cornell.gltf", 640, 360), cornell.camera, None)
    big = scenes.spheres()
    big.meshes.append(scenes.displaced_sphere("sphere_d", (-0.5, -0.5, 1.4), 0.2, "orange", 250, 200, 0.1, 4))
    path = scenes.write_gltf(big, folder / "spheres.gltf", 640, 360)
    piece = scenes.Scene("piece", big.materials, [scenes.displaced_sphere(
        "sphere_d", (-0.45, -0.5, 1.45), 0.22, "orange", 250, 200, 0.12, 5)], big.camera)
    folder_piece = folder / "piece"
    folder_piece.mkdir(exist_ok=True)
    mesh = scenes.write_gltf(piece, folder_piece / "sphere_d.gltf", 640, 360)
    out["spheres"] = (path, big.camera, mesh)
    return out, big.triangle_count()


def view(args, cam, step):
    """The camera orbited by `step` small turns about the box's centre."""
    a = 0.02 * step
    ox, oy, oz = cam.origin
    tx, ty, tz = cam.target
    dx, dy = ox - tx, oy - ty
    origin = (tx + dx * math.cos(a) - dy * math.sin(a), ty + dx * math.sin(a) + dy * math.cos(a), oz)
    return {"cmd": "view", "width": args.width, "height": args.height,
            "camera": {"matrix": camera_matrix(origin, cam.target),
                       "camera": {"type": "PERSP", "lens": 36.0 / (2 * math.tan(math.radians(cam.fov_deg) / 2)),
                                  "sensor_width": 36.0, "sensor_fit": "AUTO"}}}


def measure(args, name, path, cam, mesh):
    s = Session(args.tesela, args.threads)
    gen = 0
    results = {}

    def timed(kind, obj, settle=0.15):
        nonlocal gen
        time.sleep(settle)  # the session refines meanwhile: the command lands mid-pass
        t0 = s.send(obj)
        gen += 1
        t1 = s.wait_generation(gen)
        results.setdefault(kind, []).append((t1 - t0) * 1e3)

    s.send({"cmd": "settings", "samples": 0})
    gen += 1
    t0 = time.perf_counter()
    s.send({"cmd": "load", "path": str(path)})
    gen += 1
    s.send(view(args, cam, 0))
    gen += 1
    s.wait_generation(gen)
    results["load + first image"] = [(time.perf_counter() - t0) * 1e3]
    for k in range(args.repeat):
        timed("camera move", view(args, cam, k + 1))
    for k in range(args.repeat):
        c = 0.3 + 0.1 * k
        timed("material", {"cmd": "material", "name": "white", "material": {
            "name": "white", "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorFactor": [c, c, 0.6, 1.0], "metallicFactor": 0.0,
                                     "roughnessFactor": 1.0},
            "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}})
    lamp = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.0, 1.5, 0.0, 1]
    s.send({"cmd": "light", "node": "lamp", "matrix": lamp, "light": {"type": "POINT", "power": 10.0}})
    gen += 1
    for k in range(args.repeat):
        timed("light", {"cmd": "light", "node": "lamp", "light": {"type": "POINT", "power": 10.0 + 5 * k}})
    obj = "sphere_a" if mesh is not None else "left"  # the spheres' 359 k, the box's left wall
    for k in range(args.repeat):
        m = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.02 * (k + 1), 0.0, 0.0, 1]
        timed("object move", {"cmd": "transform", "node": obj, "matrix": m}, settle=0.3)
    if mesh is not None:
        for k in range(args.repeat):
            timed("replace 100k mesh", {"cmd": "mesh", "name": "sphere_d", "path": str(mesh)}, settle=0.3)
    s.close()
    for kind, v in results.items():
        print("%-8s %-20s median %8.1f ms  worst %8.1f ms  first %8.1f ms  (%d runs)"
              % (name, kind, statistics.median(v), max(v), v[0], len(v)))
    return results


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tesela", default=str(Path(__file__).resolve().parent.parent / "target/release/tesela"))
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=360)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="tesela-session-bench-") as d:
        files, tris = build(Path(d))
        print("tesela session latency: %dx%d view, %d threads; spheres scene %d triangles"
              % (args.width, args.height, args.threads, tris))
        for name, (path, cam, mesh) in files.items():
            measure(args, name, path, cam, mesh)


if __name__ == "__main__":
    main()
