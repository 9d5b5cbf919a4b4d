"""Many lights: does Tesela's power-proportional light choice hold up with hundreds of Blender
lights, and would a light tree pay? (bench/README.md, "Many lights").

One Blender scene (built with bpy): a 24 x 24 m floor with a grid of pillars, lit by N lights
spread over it (spheres and soft-falloff points with radii, spots, area lights with and without
spread, a few delta points; powers log-uniform over 3 decades, random colours). It is written with
the add-on's exporter and rendered by the tesela CLI with `--light-choice power` and `uniform`;
Cycles renders the same scene with its light tree on and off. For each, at a fixed sample count:
seconds and RMSE against that renderer's own high-sample reference; efficiency = 1 / (RMSE² · s)
(higher is better; equal-time error ratios are square roots of efficiency ratios).

    .venv/bin/python bench/many_lights.py [--lights 300] [--size 96] [--spp 64] [--ref-spp 4096]
        [--threads 2] [--tesela target/release/tesela] [--skip-cycles]
"""

import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(REPO / "tests" / "blender"))
sys.path.insert(0, str(REPO))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import imgcompare  # noqa: E402
import scenes  # noqa: E402
from blender_addon import export  # noqa: E402


def build(n_lights, seed=3):
    rng = random.Random(seed)
    scene = scenes.clear_scene()
    floor = scenes.lambert("Floor", (0.7, 0.7, 0.7))
    scenes.add_quad("Floor", [(-12, -12, 0), (12, -12, 0), (12, 12, 0), (-12, 12, 0)], floor)
    pillar = scenes.lambert("Pillar", (0.5, 0.55, 0.6))
    for i in range(6):
        for j in range(6):
            x, y = -10 + 4 * i, -10 + 4 * j
            scenes.add_box(f"P{i}{j}", (x - 0.3, y - 0.3, 0), (x + 0.3, y + 0.3, 2.5), pillar)
    kinds = ["sphere", "soft", "spot", "area", "area_spread", "point"]
    for k in range(n_lights):
        kind = kinds[k % len(kinds)]
        x, y = rng.uniform(-11, 11), rng.uniform(-11, 11)
        z = rng.uniform(0.5, 3.0)
        power = 10 ** rng.uniform(0.0, 3.0)
        color = tuple(rng.uniform(0.3, 1.0) for _ in range(3))
        if kind in ("sphere", "soft", "point"):
            r = 0.0 if kind == "point" else rng.uniform(0.05, 0.3)
            ob = scenes.add_point_light(f"L{k}", (x, y, z), power, color, radius=r)
            ob.data.use_soft_falloff = kind == "soft"
        elif kind == "spot":
            ob = scenes.add_spot_light(f"L{k}", (x, y, z), (x + rng.uniform(-1, 1), y, 0), power,
                                       math.radians(rng.uniform(30, 90)), 0.2, color,
                                       radius=rng.uniform(0.05, 0.2))
        else:
            ob = scenes.add_area_light(f"L{k}", (x, y, z), (x, y + rng.uniform(-1, 1), 0), power,
                                       rng.uniform(0.2, 1.0), color)
            if kind == "area_spread":
                ob.data.spread = math.radians(rng.uniform(20, 120))
    scenes.add_camera((0.0, -13.0, 9.0), (0.0, -1.0, 0.0), fov=math.radians(70.0))
    return scene


def rmse(a, b):
    return float(np.sqrt(np.mean((a[..., :3].astype(np.float64) - b[..., :3]) ** 2)))


def tesela(binary, gltf, out, spp, choice, threads, size):
    cmd = [binary, "render", str(gltf), "-o", str(out), "--spp", str(spp), "--integrator",
           "direct_mis", "--max-depth", "2", "--light-choice", choice, "--threads",
           str(threads), "--width", str(size), "--height", str(size), "--quiet"]
    t = time.perf_counter()
    subprocess.run(cmd, check=True)
    return time.perf_counter() - t, imgcompare.read_exr(out)


def cycles(scene, out, spp, tree, threads, size):
    scenes.configure_cycles(scene, size, size, spp, 0, seed=5, threads=threads)
    scene.cycles.use_light_tree = tree
    t = time.perf_counter()
    scenes.render_cycles(out)
    return time.perf_counter() - t, imgcompare.read_exr(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--lights", type=int, default=300)
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--tesela", default=str(REPO / "target" / "release" / "tesela"))
    ap.add_argument("--skip-cycles", action="store_true")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="many_lights_"))
    scene = build(args.lights)
    scenes.configure_cycles(scene, args.size, args.size, args.spp, 0)
    gltf = tmp / "scene.gltf"
    res = export.write_gltf(bpy.context.evaluated_depsgraph_get(), str(gltf), width=args.size,
                            height=args.size)
    if res.warnings:
        print("export warnings:", res.warnings[:5])
    rows = []
    _, ref = tesela(args.tesela, gltf, tmp / "ref.exr", args.ref_spp, "flat", args.threads,
                    args.size)
    for choice in ("power", "flat", "uniform"):
        s, img = tesela(args.tesela, gltf, tmp / f"{choice}.exr", args.spp, choice, args.threads,
                        args.size)
        rows.append(("tesela", choice, s, rmse(img, ref), float(img[..., :3].mean())))
    if not args.skip_cycles:
        _, cref = cycles(scene, tmp / "cref.exr", args.ref_spp, True, args.threads, args.size)
        for tree in (True, False):
            s, img = cycles(scene, tmp / f"c{tree}.exr", args.spp, tree, args.threads, args.size)
            rows.append(("cycles", "light tree" if tree else "power (no tree)", s, rmse(img, cref),
                         float(img[..., :3].mean())))
        rows.append(("tesela/cycles", "reference means", 0.0, 0.0,
                     float(ref[..., :3].mean() / cref[..., :3].mean())))
    print(f"{args.lights} lights, {args.size}x{args.size}, {args.spp} spp (refs {args.ref_spp}), "
          f"{args.threads} threads, direct light")
    print(f"{'renderer':<14} {'light choice':<18} {'seconds':>8} {'RMSE':>10} {'1/(RMSE²·s)':>12} "
          f"{'mean':>9}")
    for r, c, s, e, m in rows:
        eff = 1.0 / (e * e * s) if e > 0 and s > 0 else float("nan")
        print(f"{r:<14} {c:<18} {s:>8.2f} {e:>10.5f} {eff:>12.1f} {m:>9.5f}")
    print(json.dumps({"rows": rows}))


if __name__ == "__main__":
    main()
