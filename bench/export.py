"""The add-on's glTF export at scale: ~10 M triangles made the way artists' scenes have them,
written by `write_gltf` alone (no renderer), timed whole and per phase (bench/README.md,
"Export at scale").

The scene (bpy, built with foreach_set; 1,000 x 1,000-quad patches are 2 M triangles each):
- `Sculpt`: a torus with a Subdivision Surface modifier (level 1 over 250 k quads), smooth, a UV map
  with a seam, a Principled material with a tangent-space Normal Map (MikkTSpace tangents);
- `Terrain`: a height field, flat shaded, a UV map, three materials in bands;
- `Hard`: a ribbed torus, smooth with sharp edges where the ribs fold (> 15 degrees), a UV map;
- `Cloth`: a draped sheet, smooth, two UV maps and a corner colour attribute;
- `Custom`: a wavy torus with custom normals (one per vertex, tilted), a UV map.

    .venv/bin/python bench/export.py [--scale 1.0] [--repeats 3] [--store] [--profile]
        [--keep DIR]

`--scale` multiplies every patch's quad count (0.1 = ~1 M triangles, for a quick look). Every
export starts from a freshly evaluated scene, as F12 does (no loop triangles or normals cached
yet). The table gives each phase's seconds in the first export (Blender and numpy touch
their memory for the first time) and the median and fastest over the repeats after it, and the
file sizes.
`--profile` runs one more export under cProfile and prints the top functions by own time.
"""

import argparse
import cProfile
import math
import os
import pstats
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tests" / "blender"))

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import scenes  # noqa: E402
from blender_addon import export  # noqa: E402
from blender_addon.export import mesh_store  # noqa: E402


def patch_mesh(name, nu, nv, surface, wrap_u=False, wrap_v=False):
    """A mesh of nu x nv quads over the parameter square: `surface(u, v)` (arrays in [0, 1])
    gives the (n, 3) positions. A wrapped direction shares its first and last vertex row; the
    UV map (u, v) then has a seam there (corners on the last row read u = 1). Built with
    foreach_set: no per-element Python."""
    pu = nu if wrap_u else nu + 1
    pv = nv if wrap_v else nv + 1
    gu, gv = np.meshgrid(np.arange(pu) / nu, np.arange(pv) / nv, indexing="ij")
    co = surface(gu.reshape(-1), gv.reshape(-1)).astype(np.float32)
    i, j = np.meshgrid(np.arange(nu), np.arange(nv), indexing="ij")
    i, j = i.reshape(-1), j.reshape(-1)
    i1, j1 = (i + 1) % pu, (j + 1) % pv
    # Counter-clockwise seen from the front (+u x +v).
    quad_i = np.stack([i, i1, i1, i], axis=1)
    quad_j = np.stack([j, j, j1, j1], axis=1)
    corner_u = np.stack([i, i + 1, i + 1, i], axis=1) / nu
    corner_v = np.stack([j, j, j + 1, j + 1], axis=1) / nv
    loops = (quad_i * pv + quad_j).reshape(-1).astype(np.int32)
    nq = nu * nv
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(pu * pv)
    mesh.vertices.foreach_set("co", co.reshape(-1))
    mesh.loops.add(4 * nq)
    mesh.loops.foreach_set("vertex_index", loops)
    mesh.polygons.add(nq)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 4 * nq, 4, dtype=np.int32))
    mesh.update(calc_edges=True)
    uv = np.stack([corner_u, corner_v], axis=-1).astype(np.float32).reshape(-1)
    mesh.uv_layers.new(name="UVMap").uv.foreach_set("vector", uv)
    mesh.validate()
    return mesh


def torus(major, minor, ripple=0.0, ribs=0):
    def surface(u, v):
        a, b = 2 * math.pi * u, 2 * math.pi * v
        r = minor * (1.0 + ripple * np.sin(ribs * a) * np.sin(3 * b))
        if ribs and not ripple:  # folded ribs: a sawtooth in the tube's radius
            r = minor * (1.0 + 0.15 * np.abs(((ribs * u) % 1.0) - 0.5))
        return np.stack([(major + r * np.cos(b)) * np.cos(a),
                         (major + r * np.cos(b)) * np.sin(a), r * np.sin(b)], axis=1)
    return surface


def link(name, mesh, mats, location):
    for m in mats:
        mesh.materials.append(m)
    ob = bpy.data.objects.new(name, mesh)
    ob.location = location
    bpy.context.scene.collection.objects.link(ob)
    return ob


def normal_map_material():
    """A Principled material whose normal comes from an image through a tangent-space Normal
    Map on UVMap: the export writes MikkTSpace tangents for it."""
    n = 64
    y, x = np.mgrid[0:n, 0:n] / n
    nx, ny = 0.2 * np.sin(8 * math.pi * x), 0.2 * np.cos(8 * math.pi * y)
    nz = np.sqrt(1 - nx * nx - ny * ny)
    px = np.stack([nx * 0.5 + 0.5, ny * 0.5 + 0.5, nz * 0.5 + 0.5, np.ones_like(nz)], axis=-1)
    img = bpy.data.images.new("Bumps", n, n, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    img.pixels.foreach_set(px.astype(np.float32).reshape(-1))
    img.pack()
    mat = scenes.material("NormalMapped", base_color=(0.7, 0.7, 0.7), roughness=0.6)
    nt = mat.node_tree
    bsdf = next(nd for nd in nt.nodes if nd.type == "BSDF_PRINCIPLED")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nm.space, nm.uv_map = "TANGENT", "UVMap"
    nt.links.new(tex.outputs["Color"], nm.inputs["Color"])
    nt.links.new(nm.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


def build(scale=1.0):
    """The benchmark scene (evaluated)."""
    scenes.clear_scene()
    side = max(2, int(round(1000 * math.sqrt(scale))))
    half = max(2, side // 2)
    # Sculpt: a Subdivision Surface level 1 turns its side/2 x side/2 quads into side x side.
    sculpt = patch_mesh("Sculpt", half, half, torus(1.0, 0.4, ripple=0.05, ribs=7),
                        wrap_u=True, wrap_v=True)
    sculpt.polygons.foreach_set("use_smooth", np.ones(len(sculpt.polygons), dtype=bool))
    ob = link("Sculpt", sculpt, [normal_map_material()], (0.0, 0.0, 1.0))
    sub = ob.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = sub.render_levels = 1

    terrain = patch_mesh("Terrain", side, side, lambda u, v: np.stack(
        [8 * u - 4, 8 * v - 4, 0.3 * np.sin(9 * u) * np.cos(7 * v) + 0.05 * np.sin(60 * u * v)],
        axis=1))
    bands = (np.arange(len(terrain.polygons)) // side * 3 // side).astype(np.int32)
    terrain.polygons.foreach_set("material_index", bands)
    terrain.polygons.foreach_set("use_smooth", np.zeros(len(terrain.polygons), dtype=bool))
    link("Terrain", terrain, [scenes.lambert("Grass", (0.2, 0.5, 0.1)),
                              scenes.lambert("Rock", (0.4, 0.4, 0.4)),
                              scenes.material("Snow", (0.9, 0.9, 0.95), roughness=0.3)],
         (0.0, 0.0, 0.0))

    hard = patch_mesh("Hard", side, side, torus(0.8, 0.25, ribs=24), wrap_u=True, wrap_v=True)
    hard.polygons.foreach_set("use_smooth", np.ones(len(hard.polygons), dtype=bool))
    hard.set_sharp_from_angle(angle=math.radians(15.0))
    link("Hard", hard, [scenes.material("Metal", (0.8, 0.7, 0.5), metallic=1.0, roughness=0.3)],
         (2.5, 0.0, 1.0))

    cloth = patch_mesh("Cloth", side, side, lambda u, v: np.stack(
        [2 * u - 1, 2 * v - 1, 0.2 * np.cos(5 * u) * np.sin(4 * v) + 0.02 * np.sin(80 * u)],
        axis=1))
    cloth.polygons.foreach_set("use_smooth", np.ones(len(cloth.polygons), dtype=bool))
    uv2 = cloth.uv_layers.new(name="Detail")
    detail = np.empty(2 * len(cloth.loops), dtype=np.float32)
    cloth.uv_layers["UVMap"].uv.foreach_get("vector", detail)
    uv2.uv.foreach_set("vector", detail * 8.0)
    col = cloth.color_attributes.new("Dirt", "FLOAT_COLOR", "CORNER")
    # Painted per corner, the same on every corner of a vertex (as vertex painting leaves it).
    co = np.empty(3 * len(cloth.vertices), dtype=np.float32)
    cloth.vertices.foreach_get("co", co)
    corner_vert = np.empty(len(cloth.loops), dtype=np.int32)
    cloth.loops.foreach_get("vertex_index", corner_vert)
    rgba = np.ones((len(cloth.loops), 4), dtype=np.float32)
    rgba[:, :3] = 0.5 + 0.5 * np.sin(6.0 * co.reshape(-1, 3)[corner_vert])
    col.data.foreach_set("color", rgba.reshape(-1))
    link("Cloth", cloth, [scenes.material("Fabric", (0.6, 0.2, 0.2), roughness=0.8)],
         (-2.5, 0.0, 1.5))

    custom = patch_mesh("Custom", side, side, torus(0.6, 0.2, ripple=0.1, ribs=11),
                        wrap_u=True, wrap_v=True)
    custom.polygons.foreach_set("use_smooth", np.ones(len(custom.polygons), dtype=bool))
    vn = np.empty(3 * len(custom.vertices), dtype=np.float32)
    custom.vertices.foreach_get("normal", vn)
    vn = vn.reshape(-1, 3) + np.array([0.3, 0.0, 0.0], dtype=np.float32)
    vn /= np.linalg.norm(vn, axis=1, keepdims=True)
    custom.normals_split_custom_set_from_vertices(vn)
    link("Custom", custom, [scenes.lambert("Clay", (0.6, 0.5, 0.4))], (0.0, 2.5, 1.0))

    scenes.add_camera((0.0, -9.0, 5.0), (0.0, 0.0, 0.5))
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 64, 64


def cold_depsgraph():
    """The scene evaluated anew, as F12 has it: a render evaluates its own depsgraph, whose
    meshes have no loop triangles, normals or tangents cached yet (the export computes them).
    mesh.update() drops the caches of the original meshes too, which evaluated meshes
    without modifiers share."""
    for mesh in bpy.data.meshes:
        mesh.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    return depsgraph


def subdivide(depsgraph):
    """Seconds Blender takes to finish evaluating the meshes: a Subdivision Surface modifier
    last in the stack is deferred until its mesh is first asked for (Object.data, to_mesh),
    which the export would otherwise do; Cycles' sync pays the same."""
    t0 = time.perf_counter()
    for ob in depsgraph.objects:
        if ob.type == "MESH":
            ob.data
    return time.perf_counter() - t0


def export_once(path, store=False):
    """One export of the freshly evaluated scene into fresh files (as a render's new temporary
    folder has): the result and {phase: seconds}, with "other" for what no phase covers and
    "total". store: through an empty mesh store, as F12 does (each mesh digested, then written
    to a file of its own)."""
    for old in (path, path.with_suffix(".bin")):
        if old.exists():
            old.unlink()
    shutil.rmtree(path.parent / mesh_store.SUBDIR, ignore_errors=True)
    meshes = None
    if store:
        meshes = mesh_store.MeshStore(str(path.parent))
        meshes.begin_render(1)
    depsgraph = cold_depsgraph()
    subdivision = subdivide(depsgraph)
    t0, cpu0 = time.perf_counter(), time.process_time()
    res = export.write_gltf(depsgraph, str(path), width=64, height=64, mesh_store=meshes)
    total, cpu = time.perf_counter() - t0, time.process_time() - cpu0
    phases = dict(res.phases.seconds) if hasattr(res, "phases") else {}
    phases["other"] = total - sum(phases.values())
    phases["total"] = total
    phases["CPU seconds (all threads)"] = cpu
    phases["subdivision (before, untimed)"] = subdivision
    return res, phases


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scale", type=float, default=1.0)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--profile", action="store_true")
    ap.add_argument("--store", action="store_true",
                    help="export through a mesh store, as F12 does (digests, a file per mesh)")
    ap.add_argument("--keep", help="write the glTF here (default: a temporary folder)")
    args = ap.parse_args()
    t0 = time.perf_counter()
    build(args.scale)
    print(f"scene built in {time.perf_counter() - t0:.1f} s")
    out = Path(args.keep or tempfile.mkdtemp())
    out.mkdir(parents=True, exist_ok=True)
    path = out / "export.gltf"
    res, first = export_once(path, args.store)
    print(f"{res.triangles:,} triangles")
    runs = [export_once(path, args.store)[1] for _ in range(args.repeats)]
    names = list(runs[0])
    print("| phase | first export s | median s | min s |")
    print("| --- | ---: | ---: | ---: |")
    for k in names:
        vals = [r.get(k, 0.0) for r in runs]
        print(f"| {k} | {first.get(k, 0.0):.3f} | {statistics.median(vals):.3f} | "
              f"{min(vals):.3f} |")
    size = sum(f.stat().st_size for f in out.rglob("*") if f.is_file())
    print(f"files: {size / 1e6:.0f} MB (.gltf, .bin, stored meshes) in {out}")
    for w in res.warnings:
        print("warning:", w)
    if args.profile:
        prof = cProfile.Profile()
        prof.enable()
        export_once(path, args.store)
        prof.disable()
        pstats.Stats(prof).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
