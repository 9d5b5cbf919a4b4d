"""Where baking repeated meshes stops paying: K copies of a T-triangle sphere on a floor under a
sun, rendered by the CLI with every repeated mesh instanced (``--bake-triangles 0``) and with
every one baked into world space, at several totals K x T. Prints, per case, the render's
samples/s of both, their ratio, BVH build seconds and peak resident memory; the loader's
default limit (``LoadOptions::bake_triangles``) should sit where the ratio crosses 1 before
memory grows past what instancing saves.

    .venv/bin/python bench/bake_limit.py [--tesela target/release/tesela] [--spp 16]
"""

import argparse
import json
import math
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parent.parent


def sphere(tris):
    """A UV sphere of radius 0.4 with about `tris` triangles: (vertices, faces)."""
    rings = max(3, int(round(math.sqrt(tris / 4))))
    seg = max(4, tris // (2 * rings))
    v = [(0.0, 0.4, 0.0)]
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(seg):
            ph = 2 * math.pi * j / seg
            v.append((0.4 * math.sin(th) * math.cos(ph), 0.4 * math.cos(th),
                      0.4 * math.sin(th) * math.sin(ph)))
    v.append((0.0, -0.4, 0.0))
    f = []
    for j in range(seg):
        f.append((0, 1 + (j + 1) % seg, 1 + j))
    for i in range(rings - 2):
        a, b = 1 + i * seg, 1 + (i + 1) * seg
        for j in range(seg):
            j1 = (j + 1) % seg
            f += [(a + j, a + j1, b + j), (a + j1, b + j1, b + j)]
    last, base = len(v) - 1, 1 + (rings - 2) * seg
    for j in range(seg):
        f.append((base + j, base + (j + 1) % seg, last))
    return np.asarray(v, np.float32), np.asarray(f, np.uint32)


def look_at(eye, target):
    """glTF node rotation (x, y, z, w) of a camera at `eye` looking at `target`, Y up."""
    f = np.subtract(target, eye, dtype=float)
    f /= np.linalg.norm(f)
    r = np.cross(f, (0.0, 1.0, 0.0))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.column_stack([r, u, -f])
    w = math.sqrt(max(0.0, 1.0 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = (m[2, 1] - m[1, 2]) / (4 * w)
    y = (m[0, 2] - m[2, 0]) / (4 * w)
    z = (m[1, 0] - m[0, 1]) / (4 * w)
    return [x, y, z, w]


def write_scene(path, tris, copies):
    """glTF (Y up): one sphere mesh placed `copies` times on a grid, a floor, a sun, a camera."""
    verts, faces = sphere(tris)
    side = math.ceil(math.sqrt(copies))
    floor_v = np.asarray([(-side, 0, -side), (side, 0, -side), (side, 0, side), (-side, 0, side)],
                         np.float32)
    floor_f = np.asarray([(0, 2, 1), (0, 3, 2)], np.uint32)
    blob, views, accessors, meshes = bytearray(), [], [], []
    for v, f in ((verts, faces), (floor_v, floor_f)):
        for data, target in ((v.tobytes(), 34962), (f.ravel().tobytes(), 34963)):
            while len(blob) % 4:
                blob += b"\0"
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data),
                          "target": target})
            blob += data
        accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": len(v),
                          "type": "VEC3", "min": v.min(0).tolist(), "max": v.max(0).tolist()})
        accessors.append({"bufferView": len(views) - 1, "componentType": 5125,
                          "count": f.size, "type": "SCALAR"})
        meshes.append({"primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                       "indices": len(accessors) - 1, "material": 0}]})
    nodes = [{"mesh": 1}]
    for k in range(copies):
        x, z = k % side - (side - 1) / 2, k // side - (side - 1) / 2
        nodes.append({"mesh": 0, "translation": [x * 1.0, 0.4, z * 1.0]})
    # A sun from above and a camera looking down the grid's diagonal.
    nodes.append({"extensions": {"KHR_lights_punctual": {"light": 0}},
                  "rotation": look_at([0.3, 1.0, 0.5], [0.0, 0.0, 0.0])})
    d = side * 0.9
    eye = [d, d * 0.9, d]
    nodes.append({"camera": 0, "translation": eye, "rotation": look_at(eye, [0.0, 0.0, 0.0])})
    doc = {
        "asset": {"version": "2.0"}, "scene": 0,
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "directional", "intensity": 2000.0}]}},
        "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes, "meshes": meshes,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.7, 0.7, 1],
                                                "metallicFactor": 0, "roughnessFactor": 1}}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "accessors": accessors, "bufferViews": views,
        "buffers": [{"uri": path.with_suffix(".bin").name, "byteLength": len(blob)}],
    }
    path.with_suffix(".bin").write_bytes(bytes(blob))
    path.write_text(json.dumps(doc))
    return len(faces) * copies


def render(tesela, scene, limit, spp, size, threads):
    """(samples/s of the render, BVH seconds, peak RSS in MB) of one render."""
    out = scene.with_name(scene.stem + ".exr")
    cmd = ["/usr/bin/time", "-f", "RSS %M", str(tesela), "render", str(scene), "--spp", str(spp),
           "--width", str(size), "--height", str(size), "--threads", str(threads),
           "--integrator", "path_mis", "--max-depth", "5", "--bake-triangles", str(limit),
           "-o", str(out)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"render failed: {' '.join(cmd)}\n{p.stderr[-2000:]}")
    text = p.stderr + p.stdout
    m = re.search(r"\(\+([\d.]+) s BVH\): ([\d.]+) M samples/s", text)
    rss = re.search(r"RSS (\d+)", text)
    return float(m.group(2)), float(m.group(1)), int(rss.group(1)) / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tesela", default=str(REPO / "target/release/tesela"))
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--mesh-triangles", default="500,5000,20000")
    ap.add_argument("--totals", default="16384,65536,262144,1048576,4194304")
    args = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="tesela-bake-"))
    print("| mesh triangles | copies | total | instanced M samples/s | baked M samples/s | "
          "baked / instanced | BVH s (inst / baked) | peak MB (inst / baked) |")
    print("|---:|---:|---:|---:|---:|---:|---|---|")
    for t in map(int, args.mesh_triangles.split(",")):
        for total in map(int, args.totals.split(",")):
            copies = max(2, total // t)
            scene = work / f"s{t}-{copies}.gltf"
            n = write_scene(scene, t, copies)
            runs = {"inst": [], "bake": []}
            for _ in range(args.repeats):
                for mode, limit in (("inst", 0), ("bake", 1 << 40)):
                    runs[mode].append(render(args.tesela, scene, limit, args.spp, args.size,
                                             args.threads))
            med = {k: [statistics.median(r[i] for r in v) for i in range(3)]
                   for k, v in runs.items()}
            print(f"| {t} | {copies} | {n} | {med['inst'][0]:.3f} | {med['bake'][0]:.3f} | "
                  f"{med['bake'][0] / med['inst'][0]:.2f} | {med['inst'][1]:.2f} / "
                  f"{med['bake'][1]:.2f} | {med['inst'][2]:.0f} / {med['bake'][2]:.0f} |",
                  flush=True)


if __name__ == "__main__":
    main()
