"""The scatter case through the add-on: GRID x GRID instances of a ~5,000-triangle rock (Geometry
Nodes, Instance on Points) over a lit plane, rendered by Cycles and by Tesela (F12 path: the add-on
exports, the renderer loads, builds its BVHs and renders) at the same spp; prints wall times and
samples/s of each, and the exported glTF's meshes and instancing nodes.

    TESELA_BINARY=target/release/tesela .venv/bin/python bench/scatter.py [--grid 45] [--spp 64]
"""

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests" / "blender"))

import bpy  # noqa: E402

import blender_addon  # noqa: E402
import scenes  # noqa: E402
import test_instances_cycles as scatter_scene  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid", type=int, default=45, help="points per side (45: 2,025 instances)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    scatter_scene.GRID = args.grid - 1  # the grid primitive has subdivisions + 1 points a side
    info = scatter_scene.scatter()
    rock = bpy.data.objects["Rock"]
    rock.data = scenes.add_sphere("RockHi", (0.0, 0.0, 0.0), 1.0, rock.data.materials[0],
                                  segments=72, rings=36, smooth=False).data
    bpy.data.objects.remove(bpy.data.objects["RockHi"], do_unlink=True)
    scene = info.scene
    scene.render.threads_mode = "FIXED"
    scene.render.threads = args.threads
    scenes.configure_cycles(scene, args.size, args.size, args.spp, 0, seed=7, threads=args.threads)
    tmp = Path(tempfile.mkdtemp())
    tris = len(rock.data.polygons) * 2
    t0 = time.time()
    scenes.render_cycles(tmp / "cycles.exr")
    cycles = time.time() - t0
    blender_addon.register()
    scene.render.engine = "TESELA"
    t = scene.tesela
    t.integrator, t.samples, t.max_depth, t.seed, t.threads = "direct_mis", args.spp, 2, 1, args.threads
    scene.render.filepath = str(tmp / "tesela.exr")
    t0 = time.time()
    bpy.ops.render.render(write_still=True)
    tesela = time.time() - t0
    from blender_addon.export.gltf import write_gltf
    doc_path = tmp / "scatter.gltf"
    write_gltf(bpy.context.evaluated_depsgraph_get(), str(doc_path), width=args.size, height=args.size)
    doc = json.loads(doc_path.read_text())
    inst = [n for n in doc["nodes"] if "EXT_mesh_gpu_instancing" in n.get("extensions", {})]
    n_inst = sum(doc["accessors"][n["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
                                  ["TRANSLATION"]]["count"] for n in inst)
    samples = args.size * args.size * args.spp
    print(f"scatter: {n_inst} instances of a {tris}-triangle rock; glTF: {len(doc['meshes'])} meshes, "
          f"{len(doc['nodes'])} nodes, {len(inst)} instancing node(s)")
    print(f"cycles: {cycles:.2f} s wall, {samples / cycles / 1e6:.3f} M samples/s (incl. sync + BVH)")
    print(f"tesela: {tesela:.2f} s wall, {samples / tesela / 1e6:.3f} M samples/s "
          f"(incl. export + load + BVH)")
    print(f"files in {tmp}")


if __name__ == "__main__":
    main()
