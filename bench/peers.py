"""Tesela against Cycles (PyPI bpy) and Mitsuba 3 (PyPI mitsuba) on the same scenes, in one run.

    .venv/bin/pip install mitsuba          # once; llvm_ad_rgb also needs: apt-get install libllvm19
    cargo build --release                  # the tesela binary that is measured
    .venv/bin/python bench/peers.py --quick                  # smoke run, about a minute
    .venv/bin/python bench/peers.py --threads 2 --repeats 5  # the benchmark (bench/README.md)
    .venv/bin/python bench/peers.py --addon                  # Blender scenes via the add-on

Each scene of bench/scenes.py is built once as arrays and written to every peer's format (glTF for
Tesela, bpy objects for Cycles, PLY meshes in a scene dict for Mitsuba). For each scene and mode
(direct: Tesela direct_mis depth 2 / Cycles max_bounces 0 / Mitsuba `direct`; path: Tesela path_mis
depth 7 / Cycles max_bounces 5 / Mitsuba `path` max_depth 7) the script

1. calibrates each peer's speed and picks its spp for the time budget (--budget seconds);
2. renders a converged reference per peer (--ref-factor x the budget's spp) and checks that the
   image means agree within 1% (the table is printed; a disagreement is reported, not hidden);
3. renders every peer at its budget spp in alternation (A B C D A B C D ...) --repeats times with
   different seeds, and reports medians and min-max of samples/s, rays/s (Tesela only), render
   time, and the equal-time error: relMSE against the peer's own converged reference, corrected for
   the reference's own noise and scaled to exactly the budget (variance ~ 1/time).

Only rendering is timed: Tesela's summary line (render seconds; BVH build printed apart), Cycles
from its "Sample 0/N" status to "Finished" (sync + BVH reported apart), Mitsuba around mi.render
(scene load apart; LLVM JIT compilation happens in an untimed warm-up at the same spp).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import importlib.util
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))
import scenes as bench_scenes  # noqa: E402  (bench/scenes.py)

ALL_PEERS = ["tesela", "cycles", "mitsuba-scalar", "mitsuba-llvm"]
OPTIONAL_PEERS = ["tesela-1t"]  # Tesela on one thread: the 2-thread scaling check
MODES = {"direct": {"tesela": ("direct_mis", 2), "cycles": 0, "mitsuba": {"type": "direct"}},
         "path": {"tesela": ("path_mis", 7), "cycles": 5,
                  "mitsuba": {"type": "path", "max_depth": 7}}}
EPS = 1e-2  # relMSE denominator offset: (x - r)^2 / (r^2 + EPS)


def log(*a):
    print(*a, flush=True)


# ------------------------------------------------------------------------------------------------
# image helpers


def read_exr(path):
    """(h, w, 3) float32, first row at the top."""
    import bpy
    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        w, h = img.size
        a = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(a)
    finally:
        bpy.data.images.remove(img)
    return a.reshape(h, w, 4)[::-1, :, :3].copy()


def cpu_seconds(who):
    """User + system CPU seconds of this process (RUSAGE_SELF) or its finished children."""
    import resource
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def rel_mse(img, ref):
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + EPS)))


# ------------------------------------------------------------------------------------------------
# peers: setup(scene, width, height) once per scene, render(mode, spp, seed) -> dict


class Tesela:
    def __init__(self, name, binary, threads, workdir):
        self.name, self.binary, self.threads, self.workdir = name, binary, threads, workdir

    def setup(self, scene, width, height):
        self.w, self.h = width, height
        self.gltf = self.workdir / f"{scene.name}.gltf"
        if not self.gltf.exists():
            bench_scenes.write_gltf(scene, self.gltf, width, height)
        return {}

    def render(self, mode, spp, seed):
        integrator, depth = MODES[mode]["tesela"]
        out = self.workdir / f"{self.name}.exr"
        cmd = [str(self.binary), "render", str(self.gltf), "-o", str(out), "--integrator",
               integrator, "--max-depth", str(depth), "--spp", str(spp), "--width", str(self.w),
               "--height", str(self.h), "--threads", str(self.threads), "--seed", str(seed)]
        import resource
        c0 = cpu_seconds(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        cpu = cpu_seconds(resource.RUSAGE_CHILDREN) - c0
        m = re.search(r"in ([\d.]+) s \(\+([\d.]+) s BVH\): ([\d.]+) M samples/s, ([\d.]+) M rays/s",
                      p.stderr)
        if p.returncode != 0 or not m:
            raise RuntimeError(f"tesela failed ({p.returncode}): {' '.join(cmd)}\n{p.stderr}")
        secs, bvh, msps, mrps = map(float, m.groups())
        samples = self.w * self.h * spp
        # The line prints 2 decimals: take the time from whichever number is more precise.
        if msps > 0 and 0.005 / msps < 0.005 / max(secs, 1e-9):
            secs = samples / (msps * 1e6)
        return {"image": read_exr(out), "seconds": secs, "samples": samples,
                "rays": mrps * 1e6 * secs, "setup_s": bvh, "wall_s": wall, "cpu_s": cpu}


class Cycles:
    name = "cycles"

    def __init__(self, threads, workdir):
        self.threads, self.workdir = threads, workdir
        import bpy
        spec = importlib.util.spec_from_file_location("blender_scenes",
                                                      REPO / "tests/blender/scenes.py")
        self.bs = importlib.util.module_from_spec(spec)
        sys.modules["blender_scenes"] = self.bs  # dataclasses look their module up there
        spec.loader.exec_module(self.bs)
        self.bpy = bpy
        self.events = []
        stamp = lambda tag: (lambda *a: self.events.append((time.perf_counter(), tag, a)))  # noqa
        bpy.app.handlers.render_pre.append(stamp("pre"))
        bpy.app.handlers.render_stats.append(stamp("stats"))
        bpy.app.handlers.render_post.append(stamp("post"))

    def _material(self, m):
        bpy = self.bpy
        mat = bpy.data.materials.new(m.name)
        nt = self.bs._use_nodes(mat)
        nt.nodes.clear()
        out = nt.nodes.new("ShaderNodeOutputMaterial")
        if m.is_emitter:
            node = nt.nodes.new("ShaderNodeEmission")
            s = max(m.emission)
            node.inputs["Color"].default_value = (*(c / s for c in m.emission), 1.0)
            node.inputs["Strength"].default_value = s
            nt.links.new(node.outputs["Emission"], out.inputs["Surface"])
        else:
            node = nt.nodes.new("ShaderNodeBsdfDiffuse")
            node.inputs["Color"].default_value = (*m.albedo, 1.0)
            node.inputs["Roughness"].default_value = 0.0
            nt.links.new(node.outputs["BSDF"], out.inputs["Surface"])
        return mat

    def _mesh(self, mesh, mat):
        bpy = self.bpy
        me = bpy.data.meshes.new(mesh.name)
        nv, nf = len(mesh.vertices), len(mesh.faces)
        me.vertices.add(nv)
        me.vertices.foreach_set("co", mesh.vertices.astype(np.float32).ravel())
        me.loops.add(3 * nf)
        me.loops.foreach_set("vertex_index", mesh.faces.astype(np.int32).ravel())
        me.polygons.add(nf)
        me.polygons.foreach_set("loop_start", np.arange(0, 3 * nf, 3, dtype=np.int32))
        try:
            me.polygons.foreach_set("loop_total", np.full(nf, 3, dtype=np.int32))
        except (AttributeError, TypeError, RuntimeError):
            pass  # Blender 4+: sizes follow from loop_start
        me.update(calc_edges=True)
        me.polygons.foreach_set("use_smooth", np.zeros(nf, dtype=bool))
        me.materials.append(mat)
        ob = bpy.data.objects.new(mesh.name, me)
        bpy.context.scene.collection.objects.link(ob)

    def setup(self, scene, width, height):
        t0 = time.perf_counter()
        bs = self.bs
        sc = bs.clear_scene()
        for coll in (self.bpy.data.meshes, self.bpy.data.materials):
            for block in list(coll):
                if block.users == 0:
                    coll.remove(block)
        mats = {k: self._material(m) for k, m in scene.materials.items()}
        for mesh in scene.meshes:
            self._mesh(mesh, mats[mesh.material])
        c = scene.camera
        bs.add_camera(c.origin, c.target, fov=math.radians(c.fov_deg))
        bs.configure_cycles(sc, width, height, 1, 0, 0, threads=self.threads)
        sc.cycles.use_light_tree = True  # the default, stated
        self.scene = sc
        return {"build_s": time.perf_counter() - t0}

    def render(self, mode, spp, seed):
        b = MODES[mode]["cycles"]
        c = self.scene.cycles
        c.samples, c.seed = spp, seed
        c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = b
        c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
        out = self.workdir / "cycles.exr"
        self.events.clear()
        sys.stdout.flush()
        saved = os.dup(1)  # Blender prints progress lines on fd 1: keep the tables readable
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        try:
            import resource
            c0 = cpu_seconds(resource.RUSAGE_SELF)
            t0 = time.perf_counter()
            self.bs.render_cycles(out)
            wall = time.perf_counter() - t0
            cpu = cpu_seconds(resource.RUSAGE_SELF) - c0
        finally:
            os.dup2(saved, 1)
            os.close(saved)
            os.close(devnull)
        start = next(t for t, tag, a in self.events
                     if tag == "stats" and a and "Sample 0/" in str(a[0]))
        end = next(t for t, tag, a in self.events
                   if tag == "stats" and a and "Finished" in str(a[0]))
        pre = next(t for t, tag, a in self.events if tag == "pre")
        samples = self.scene.render.resolution_x * self.scene.render.resolution_y * spp
        return {"image": read_exr(out), "seconds": end - start, "samples": samples,
                "rays": None, "setup_s": start - pre, "wall_s": wall, "cpu_s": cpu}


class Mitsuba:
    def __init__(self, variant, threads, workdir):
        self.variant, self.workdir = variant, workdir
        self.name = "mitsuba-" + variant.split("_")[0]
        import drjit as dr
        import mitsuba as mi
        self.mi, self.dr = mi, dr
        dr.set_thread_count(threads)
        self.integrators = {}

    def setup(self, scene, width, height):
        mi = self.mi
        mi.set_variant(self.variant)
        t0 = time.perf_counter()
        self.pixels = width * height
        d = {"type": "scene"}
        c = scene.camera
        d["sensor"] = {
            "type": "perspective", "fov": c.fov_deg, "fov_axis": "larger",
            "near_clip": 0.01, "far_clip": 100.0,
            "to_world": mi.ScalarTransform4f().look_at(origin=c.origin, target=c.target, up=c.up),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": 1},
        }
        for i, mesh in enumerate(scene.meshes):
            ply = self.workdir / f"{scene.name}-{i}.ply"
            if not ply.exists():
                bench_scenes.write_ply(mesh, ply)
            m = scene.materials[mesh.material]
            shape = {"type": "ply", "filename": str(ply), "face_normals": True,
                     "bsdf": {"type": "twosided", "bsdf": {
                         "type": "diffuse", "reflectance": {"type": "rgb", "value": list(m.albedo)}}}}
            if m.is_emitter:
                shape["emitter"] = {"type": "area",
                                    "radiance": {"type": "rgb", "value": list(m.emission)}}
            d[f"mesh{i}"] = shape
        t1 = time.perf_counter()
        self.scene = mi.load_dict(d)
        self.integrators.clear()
        return {"write_s": t1 - t0, "load_s": time.perf_counter() - t1}

    def _integrator(self, mode):
        # No samples_per_pass: Mitsuba 3.9 deprecates it and splits large wavefronts itself.
        if mode not in self.integrators:
            self.integrators[mode] = self.mi.load_dict(dict(MODES[mode]["mitsuba"]))
        return self.integrators[mode]

    def render(self, mode, spp, seed):
        mi, dr = self.mi, self.dr
        mi.set_variant(self.variant)
        integ = self._integrator(mode)
        import resource
        c0 = cpu_seconds(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        img = mi.render(self.scene, integrator=integ, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        secs = time.perf_counter() - t0
        cpu = cpu_seconds(resource.RUSAGE_SELF) - c0
        return {"image": np.array(img, dtype=np.float32)[:, :, :3], "seconds": secs,
                "samples": self.pixels * spp, "rays": None, "setup_s": None, "wall_s": secs,
                "cpu_s": cpu}


# ------------------------------------------------------------------------------------------------
# the benchmark


def fmt_range(vals, scale=1.0, digits=3):
    v = [x * scale for x in vals if x is not None]
    if not v:
        return "n/a"
    med = statistics.median(v)
    if len(v) == 1:
        return f"{med:.{digits}g}"
    return f"{med:.{digits}g} ({min(v):.{digits}g}–{max(v):.{digits}g})"


def bench_mode(peers, scene_name, mode, args, W, H):
    pixels = W * H
    seed = iter(range(1000, 10 ** 6))
    rate = {}
    log(f"\n### {scene_name} / {mode}: calibrating")
    budget_spp, compile_s = {}, {}
    for p in peers:  # two rounds: a small spp, then one sized to ~1/4 of the budget
        cold = p.render(mode, 1, next(seed))  # warm-up (caches; Mitsuba LLVM: JIT compilation)
        warm = p.render(mode, 1, next(seed))
        compile_s[p.name] = max(0.0, cold["seconds"] - warm["seconds"])
        spp = args.cal_spp
        r = p.render(mode, spp, next(seed))
        rate[p.name] = r["samples"] / r["seconds"]
        spp = max(1, round(0.25 * args.budget * rate[p.name] / pixels))
        p.render(mode, spp, next(seed))  # warm-up at this spp (Mitsuba LLVM: compile)
        r = p.render(mode, spp, next(seed))
        rate[p.name] = r["samples"] / r["seconds"]
        log(f"  {p.name:16s} ~{rate[p.name] / 1e6:.3f} M samples/s")
    for p in peers:
        spp = max(1, round(args.budget * rate[p.name] / pixels))
        budget_spp[p.name] = spp
    # converged references and the agreement check
    refs, ref_info = {}, {}
    log(f"### {scene_name} / {mode}: references ({args.ref_factor} x budget spp)")
    for p in peers:
        spp = budget_spp[p.name]
        p.render(mode, spp, next(seed))  # untimed warm-up at the budget spp (LLVM: its kernel)
        if p.name == "tesela-1t" and "tesela" in refs:
            continue  # same renderer and image statistics: it shares Tesela's reference
        ref_spp = spp * args.ref_factor
        r = p.render(mode, ref_spp, next(seed))
        refs[p.name] = r["image"]
        ref_info[p.name] = {"spp": ref_spp, "seconds": r["seconds"],
                            "mean": float(r["image"].mean()),
                            "channel_means": r["image"].reshape(-1, 3).mean(axis=0).tolist()}
        log(f"  {p.name:16s} {ref_spp} spp in {r['seconds']:.2f} s, mean {ref_info[p.name]['mean']:.5f}")
    if "tesela-1t" in budget_spp and "tesela-1t" not in refs:
        refs["tesela-1t"] = refs["tesela"]
        ref_info["tesela-1t"] = dict(ref_info["tesela"], shared=True)
    base = "tesela" if "tesela" in refs else next(iter(refs))
    b0 = "tesela" if "tesela" in ref_info else next(iter(ref_info))
    log(f"### {scene_name} / {mode}: agreement of converged means (ratio to {b0}; must be within 1%)")
    for name, info in ref_info.items():
        ratio = info["mean"] / ref_info[b0]["mean"]
        log(f"  {name:16s} mean {info['mean']:.5f}  ratio {ratio:.4f}"
            + ("" if abs(ratio - 1) <= 0.01 else "  ** DISAGREES: renders something else? **"))
    # timed runs, alternating
    runs = {p.name: [] for p in peers}
    log(f"### {scene_name} / {mode}: timed runs, {args.repeats} repeats, budget {args.budget} s")
    for rep in range(args.repeats):
        for p in peers:
            spp = budget_spp[p.name]
            r = p.render(mode, spp, next(seed))
            n_ref = ref_info[p.name]["spp"]
            raw = rel_mse(r["image"], refs[p.name])
            # E[raw] = s2/n + s2/N (test and reference noise): remove the reference's part, then
            # scale to exactly the budget (variance ~ 1/time).
            err = raw / (1 + spp / n_ref) * (r["seconds"] / args.budget)
            runs[p.name].append({"spp": spp, "seconds": r["seconds"], "samples": r["samples"],
                                 "mean": float(r["image"].mean()),
                                 "loadavg_1min": os.getloadavg()[0],
                                 "cores_used": r["cpu_s"] / r["wall_s"] if r.get("wall_s") else None,
                                 "sps": r["samples"] / r["seconds"],
                                 "rps": (r["rays"] / r["seconds"]) if r["rays"] else None,
                                 "setup_s": r["setup_s"], "relmse_raw": raw, "relmse_T": err})
            log(f"  [{rep + 1}/{args.repeats}] {p.name:16s} {spp:5d} spp {r['seconds']:7.3f} s "
                f"{r['samples'] / r['seconds'] / 1e6:7.3f} M samples/s  relMSE@T {err:.3e}")
    agree = []
    for name, info in ref_info.items():
        ch = np.array(info["channel_means"]) / np.array(ref_info[base]["channel_means"])
        # noise of the reference's mean, from the spread of the timed runs' means
        tm = [r["mean"] for r in runs.get(name, [])]
        sem = (statistics.stdev(tm) * math.sqrt(budget_spp[name] / info["spp"])
               if len(tm) > 1 else float("nan"))
        agree.append({"peer": name, "spp": info["spp"], "mean": info["mean"], "mean_sd": sem,
                      "shared_reference": bool(info.get("shared")),
                      "ratio": info["mean"] / ref_info[base]["mean"],
                      "channel_ratios": ch.tolist(),
                      "relmse_vs_" + base: rel_mse(refs[name], refs[base]),
                      "ok": bool(abs(info["mean"] / ref_info[base]["mean"] - 1) <= 0.01
                                 and np.all(np.abs(ch - 1) <= 0.01))})
    return {"scene": scene_name, "mode": mode, "width": W, "height": H, "budget_s": args.budget,
            "budget_spp": budget_spp, "agreement": agree, "agreement_base": base,
            "compile_s": compile_s, "runs": runs}


def tables(result, setup):
    """Markdown tables of one scene/mode result."""
    s, m = result["scene"], result["mode"]
    base = result["agreement_base"]
    out = [f"#### {s} — {m} ({result['width']}x{result['height']}, budget {result['budget_s']} s)", "",
           f"Converged images (mean over pixels and RGB; ratio to {base}; pass = mean and every "
           "channel within 1%):", "",
           f"| peer | spp | mean ± sd (est.) | ratio | R/G/B ratios | relMSE vs {base} | agree |",
           "|---|---:|---:|---:|---|---:|---|"]
    for a in result["agreement"]:
        out.append(f"| {a['peer']} | {a['spp']}{' (shared)' if a.get('shared_reference') else ''} | "
                   f"{a['mean']:.5f} ± {a.get('mean_sd', float('nan')):.5f} | {a['ratio']:.4f} | "
                   + "/".join(f"{c:.4f}" for c in a["channel_ratios"])
                   + f" | {a['relmse_vs_' + base]:.2e} | {'yes' if a['ok'] else '**NO**'} |")
    out += ["", "Timed runs (median (min–max) over repeats; render time only):", "",
            "| peer | spp | render s | M samples/s | M rays/s | relMSE at equal time | "
            "vs tesela (relMSE) | cores used | setup s |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    tes = result["runs"].get("tesela")
    tes_err = statistics.median(r["relmse_T"] for r in tes) if tes else None
    for name, runs in result["runs"].items():
        err = statistics.median(r["relmse_T"] for r in runs)
        rps = [r["rps"] for r in runs if r["rps"]]
        setup_bits = []
        sv = [r["setup_s"] for r in runs if r["setup_s"] is not None]
        if sv:
            setup_bits.append(("BVH " if name.startswith("tesela") else "sync+BVH ")
                              + f"{statistics.median(sv):.2f}")
        st = setup.get(name) or {}
        if "load_s" in st:
            setup_bits.append(f"load {st['load_s']:.2f}")
        if "build_s" in st:
            setup_bits.append(f"bpy build {st['build_s']:.2f}")
        if name == "mitsuba-llvm" and result["compile_s"].get(name) is not None:
            setup_bits.append(f"JIT ~{result['compile_s'][name]:.2f} (1st render − 2nd)")
        out.append(
            f"| {name} | {fmt_range([r['spp'] for r in runs])} | "
            f"{fmt_range([r['seconds'] for r in runs])} | "
            f"{fmt_range([r['sps'] for r in runs], 1e-6)} | "
            f"{fmt_range(rps, 1e-6) if rps else 'n/a'} | "
            f"{fmt_range([r['relmse_T'] for r in runs])} | "
            f"{(err / tes_err) if tes_err else float('nan'):.2f} | "
            f"{fmt_range([r.get('cores_used') for r in runs], digits=2)} | {', '.join(setup_bits)} |")
    return "\n".join(out)


def targets(results, traversal_results=()):
    """The issue's ratio targets, from the medians."""
    med = lambda res, peer, key: (statistics.median(r[key] for r in res["runs"][peer])  # noqa
                                  if peer in res["runs"] else None)
    lines = ["| scene | mode | target | measured | met |", "|---|---|---|---:|---|"]

    def row(res, what, val, goal, better="high"):
        if val is None:
            return
        ok = val >= goal if better == "high" else val <= goal
        lines.append(f"| {res['scene']} | {res['mode']} | {what} | {val:.2f} | "
                     f"{'yes' if ok else 'no'} |")
    for res in results:
        t = med(res, "tesela", "sps")
        if t is None:
            continue
        for peer, goal, label in (("cycles", 2.0, "samples/s ≥ 2× Cycles"),
                                  ("mitsuba-scalar", 1.0, "samples/s ≥ 1× Mitsuba scalar"),
                                  ("mitsuba-llvm", 0.5, "samples/s ≥ ½ Mitsuba llvm (aim)")):
            o = med(res, peer, "sps")
            row(res, label + " (ratio)", t / o if o else None, goal)
        if res["mode"] == "direct":
            c = med(res, "cycles", "relmse_T")
            e = med(res, "tesela", "relmse_T")
            row(res, "equal-time relMSE ≤ ½ Cycles' (ratio)", e / c if c else None, 0.5, "low")
        one = med(res, "tesela-1t", "sps")
        row(res, "2 threads ≥ 1.8× one thread (ratio)", t / one if one else None, 1.8)
        if res["triangles"] >= 1_000_000:
            row(res, "BVH build of ≥ 1M triangles ≤ 1 s (s)", med(res, "tesela", "setup_s"), 1.0,
                "low")
    for tr in traversal_results:
        row(tr, "renderer rays/s ≥ 70% of raw obvhs, same rays (ratio)", tr["renderer_vs_raw"], 0.7)
    return "\n".join(lines)


def traversal(gltf, size, mode):
    """``cargo bench --bench traversal`` on the scene: the renderer's rays/s against raw obvhs
    CWBVH traversal of the same rays (one thread). Returns its report and the ratio."""
    integrator, depth = MODES[mode]["tesela"]
    cmd = ["cargo", "bench", "-q", "--bench", "traversal", "--", str(gltf), "--size", str(size),
           "--spp", "4", "--integrator", integrator, "--max-depth", str(depth)]
    p = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"traversal bench failed: {' '.join(cmd)}\n{p.stderr[-2000:]}")
    text = p.stdout.strip()
    m = re.search(r"renderer \(whole render, every ray cast\)\s+[\d.]+ M rays/s\s+([\d.]+)x", text)
    return {"scene": Path(gltf).stem, "mode": mode, "report": text,
            "renderer_vs_raw": float(m.group(1)) if m else None}


def merge(args):
    """Pool the timed runs of several result files (same scenes and modes) into one table each;
    the agreement tables of every run are kept."""
    docs = [json.loads(Path(f).read_text()) for f in args.merge]
    pooled, order = {}, []
    for d in docs:
        for r in d["results"]:
            key = (r["scene"], r["mode"])
            if key not in pooled:
                pooled[key] = dict(r, runs={k: list(v) for k, v in r["runs"].items()},
                                   agreements=[r["agreement"]])
                order.append(key)
            else:
                p = pooled[key]
                for k, v in r["runs"].items():
                    p["runs"].setdefault(k, []).extend(v)
                p["agreements"].append(r["agreement"])
    head = (f"# Tesela vs peers — {len(docs)} runs pooled\n\n"
            + "\n".join(f"- `{Path(f).name}`: {d['env'].get('date')}, load average at start/end "
                        f"{d['env'].get('load_avg_start', [None])[0]:.1f} / "
                        f"{(d['env'].get('load_avg_end') or [float('nan')])[0]:.1f}, "
                        f"tesela {d['env'].get('tesela_commit')}, binary "
                        f"{d['env'].get('tesela_binary_mtime')} "
                        f"{d['env'].get('tesela_binary_sha256', '')}"
                        for f, d in zip(args.merge, docs)) + "\n")
    bins = {(d["env"].get("tesela_binary_mtime"), d["env"].get("tesela_binary_sha256"))
            for d in docs}
    if len(bins) > 1:
        head += ("\n**Warning: these runs measured different Tesela binaries** (the pooled "
                 "Tesela numbers mix them).\n")
    parts = [head]
    results = []
    for key in order:
        r = pooled[key]
        for i, ag in enumerate(r["agreements"][1:], 2):
            r.setdefault("extra_agreement", []).append((i, ag))
        t = tables(r, r.get("setup", {}))
        for i, ag in r.get("extra_agreement", []):
            t += f"\n\nAgreement in run {i}: " + ", ".join(
                f"{a['peer']} {a['ratio']:.4f}{'' if a['ok'] else ' **NO**'}" for a in ag)
        parts.append(t)
        results.append(r)
    tgt = targets(results)
    text = "\n\n".join(parts) + "\n\n### Targets (issue 5; ratios of pooled medians)\n\n" + tgt + "\n"
    print(text)
    if args.out:
        out = Path(args.out)
        if out.suffix != ".md":
            out.mkdir(parents=True, exist_ok=True)
            out = out / "peers-pooled.md"
        out.write_text(text)
        print(f"wrote {out}")


# ------------------------------------------------------------------------------------------------
# scenes through the Blender add-on (--addon): Blender node materials and worlds, as users have them

ADDON_SCENES = {
    # The Blender-built Cornell box (tests/blender/scenes.py): Principled walls, an emissive
    # ceiling quad.
    "cornell": ("scenes", "cornell_box"),
    # A rough Principled floor with a tangent-space Normal Map from an image, lit by a low sun
    # and a dim world (tests/blender/test_material_scenes_cycles.py: normal_map).
    "normalmap": ("test_material_scenes_cycles", "normal_map"),
    # A diffuse and a glossy sphere on a plane under an HDRI world with a small bright sun, the
    # sky behind them (tests/blender/test_world_cycles.py: hdri_world).
    "hdri_product": ("test_world_cycles", "hdri_world"),
    # A room lit by a sun through a window, a ceiling area light and a dim sky: planks (image),
    # noise roughness, normal and bump maps, a Brick rug, textured metal (bench/interior.py).
    "interior": ("interior", "textured_interior"),
}


def _addon_render(engine, spp, seed):
    """Render the current scene with `engine` ("CYCLES" or "TESELA") at `spp`: wall seconds of
    bpy.ops.render.render (scene sync/export and BVH build included, for both)."""
    import bpy
    sc = bpy.context.scene
    sc.render.engine = engine
    if engine == "CYCLES":
        sc.cycles.samples, sc.cycles.seed = spp, seed
    else:
        sc.tesela.samples, sc.tesela.seed = spp, seed
    sys.stdout.flush()
    saved = os.dup(1)  # Blender prints progress lines on fd 1
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    try:
        t0 = time.perf_counter()
        assert bpy.ops.render.render() == {"FINISHED"}
        wall = time.perf_counter() - t0
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)
    return wall


def _render_result_mean():
    return _render_result_image().reshape(-1, 3).mean(axis=0)


def _addon_setup(args):
    """Registers the add-on (renderer `args.tesela`) and returns the Blender tests' scene module
    (tests/blender/scenes.py: the test modules import their own `scenes`, not bench/scenes.py)."""
    tests = REPO / "tests" / "blender"
    for path in (REPO, tests):
        sys.path.insert(0, str(path))
    sys.modules.pop("scenes", None)
    import blender_addon
    import scenes as bs
    from blender_addon import engine as tesela_engine
    if not tesela_engine.TeselaRenderEngine.is_registered:
        blender_addon.register()
    os.environ["TESELA_BINARY"] = str(args.tesela)
    return bs


def addon_bench(args):
    """Tesela (through the add-on, path_mis depth b + 2) against Cycles (max bounces b) on Blender
    scenes at the same spp: median wall time of `repeats` renders in alternation, and the
    marginal samples/s `pixels (spp - 1) / (t(spp) - t(1))`, which leaves out the per-render
    costs (sync, export, BVH, process start) that both have."""
    import bpy
    import importlib
    bs = _addon_setup(args)
    size = args.size or (48 if args.quick else 256)
    spp = 4 if args.quick else args.addon_spp
    bounces = 3
    repeats = args.repeats or (2 if args.quick else 3)
    lines = [f"#### Blender scenes through the add-on: {size}x{size}, {spp} spp, Cycles max "
             f"bounces {bounces} / Tesela path_mis depth {bounces + 2}, {args.threads} threads",
             "", "| scene | peer | median wall s | marginal samples/s | mean RGB |",
             "| --- | --- | --- | --- | --- |"]
    ratios = {}
    for name in [n.strip() for n in args.addon_scenes.split(",") if n.strip()]:
        module, builder = ADDON_SCENES[name]
        bs.clear_scene()
        getattr(importlib.import_module(module), builder)()
        sc = bpy.context.scene
        bs.configure_cycles(sc, size, size, spp, bounces, seed=1, threads=args.threads)
        t = sc.tesela
        bs.tesela_like_cycles(t)  # the same spp as Cycles: no noise threshold, no denoiser
        t.integrator, t.max_depth, t.threads = "path_mis", bounces + 2, args.threads
        _addon_render("TESELA", 1, 0)  # warm-up: caches, page faults
        _addon_render("CYCLES", 1, 0)
        walls = {"cycles": [], "tesela": []}
        ones = {"cycles": [], "tesela": []}
        means = {}
        for r in range(repeats):
            for peer, engine in (("cycles", "CYCLES"), ("tesela", "TESELA")):
                ones[peer].append(_addon_render(engine, 1, r))
                walls[peer].append(_addon_render(engine, spp, r))
                means[peer] = _render_result_mean()
        rate = {}
        for peer in ("cycles", "tesela"):
            w, o = statistics.median(walls[peer]), statistics.median(ones[peer])
            rate[peer] = size * size * (spp - 1) / max(w - o, 1e-9)
            m = ", ".join(f"{v:.4f}" for v in means[peer])
            lines.append(f"| {name} | {peer} | {w:.2f} | {rate[peer]:,.0f} | {m} |")
            log(f"  {name} {peer}: wall {walls[peer]} (1 spp: {ones[peer]}), mean {m}")
        ratios[name] = (rate["tesela"] / rate["cycles"],
                        statistics.median(walls["cycles"]) / statistics.median(walls["tesela"]))
    lines.append("")
    for name, (r, w) in ratios.items():
        lines.append(f"- {name}: Tesela / Cycles marginal samples/s {r:.2f}x; "
                     f"wall-time ratio (Cycles / Tesela) {w:.2f}x")
    text = "\n".join(lines)
    log("\n" + text)
    return text


def _render_result_image():
    import bpy
    path = Path(tempfile.mkdtemp(prefix="tesela-clean-")) / "r.exr"
    st = bpy.context.scene.render.image_settings
    if hasattr(st, "media_type"):
        st.media_type = "IMAGE"
    st.file_format, st.color_depth = "OPEN_EXR", "32"
    bpy.data.images["Render Result"].save_render(str(path))
    img = read_exr(path)
    shutil.rmtree(path.parent, ignore_errors=True)
    return img


CLEAN_SCENES = {
    "cornell": ("scenes", "cornell_box"),
    "hdri_product": ("test_world_cycles", "hdri_world"),
    "interior": ("interior", "textured_interior"),
}


def clean_bench(args):
    """Time to a clean image: each renderer with its artist-facing defaults for a final render
    (noise threshold 0.01, OIDN with albedo/normal guides; Cycles 4096 max samples, Tesela's
    add-on 1024), wall time of bpy.ops.render.render and relMSE against the renderer's own
    converged reference (no denoising, `--clean-ref-spp` samples in two halves of different
    seeds, whose difference gives the reference's own noise, removed from the relMSE: at 2048
    spp that noise is most of a clean image's measured error). Tesela is also run at other
    noise thresholds, and its time at Cycles' error is interpolated between them (log-log)."""
    import bpy
    import importlib
    bs = _addon_setup(args)
    size = args.size or (48 if args.quick else 128)
    ref_spp = 64 if args.quick else args.clean_ref_spp
    bounces = 3
    lines = [f"#### Time to a clean image: {size}x{size}, Cycles max bounces {bounces} / Tesela "
             f"path_mis depth {bounces + 2}, {args.threads} threads; relMSE against each "
             f"renderer's own {ref_spp} spp reference", "",
             "| scene | peer | settings | wall s | relMSE (reference noise removed) | measured | mean RGB |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    readoff = []
    for name in [n.strip() for n in args.clean_scenes.split(",") if n.strip()]:
        module, builder = CLEAN_SCENES[name]
        bs.clear_scene()
        getattr(importlib.import_module(module), builder)()
        sc = bpy.context.scene
        bs.configure_cycles(sc, size, size, ref_spp, bounces, seed=1, threads=args.threads)
        t = sc.tesela
        t.integrator, t.max_depth, t.threads = "path_mis", bounces + 2, args.threads
        # The references: plain sampling, no denoiser.
        bs.tesela_like_cycles(t)
        ref, ref_noise = {}, {}
        for peer, engine in (("cycles", "CYCLES"), ("tesela", "TESELA")):
            _addon_render(engine, ref_spp // 2, 7)
            a = _render_result_image()
            _addon_render(engine, ref_spp // 2, 8)
            b = _render_result_image()
            ref[peer] = (a + b) / 2
            # E[(x - r)^2] = E[(x - mu)^2] + Var(r) for x independent of r, and
            # ((a - b) / 2)^2 estimates Var(r) per pixel.
            ref_noise[peer] = float(np.mean(((a - b) / 2) ** 2 / (ref[peer] ** 2 + EPS)))
            log(f"  {name} {peer} reference: own relMSE {ref_noise[peer]:.3e}")
        c = sc.cycles
        c.use_adaptive_sampling, c.adaptive_threshold, c.adaptive_min_samples = True, 0.01, 0
        c.use_denoising = True
        if hasattr(c, "denoiser"):
            c.denoiser = "OPENIMAGEDENOISE"
        if hasattr(c, "denoising_input_passes"):
            c.denoising_input_passes = "RGB_ALBEDO_NORMAL"
        runs = [("cycles", "CYCLES", "defaults: threshold 0.01, OIDN, 4096 max", 4096, None)]
        for thr in (0.0075, 0.01, 0.0125, 0.015, 0.02, 0.05):
            runs.append(("tesela", "TESELA", f"threshold {thr}, OIDN, 1024 max", 1024, thr))
        points = []
        for peer, engine, label, spp, thr in runs:
            if thr is not None:
                t.use_adaptive_sampling, t.adaptive_threshold, t.use_denoising = True, thr, True
            walls, errs = [], []
            for r in range(args.repeats or (1 if args.quick else 3)):
                walls.append(_addon_render(engine, spp, 11 + r))
                img = _render_result_image()
                errs.append(rel_mse(img, ref[peer]))
            m = ", ".join(f"{v:.4f}" for v in img.reshape(-1, 3).mean(axis=0))
            wall, err = statistics.median(walls), statistics.median(errs)
            points.append((peer, wall, max(err - ref_noise[peer], 1e-12)))
            lines.append(f"| {name} | {peer} | {label} | {wall:.2f} | {points[-1][2]:.2e} | "
                         f"{err:.2e} | {m} |")
            log(lines[-1])
        readoff.append(_time_at_error(name, points))
    lines += [""] + readoff
    text = "\n".join(lines)
    log("\n" + text)
    return text


def _time_at_error(name, points):
    """The read-off line: Tesela's wall time at Cycles' error, interpolated log-log between the
    two Tesela runs whose errors bracket it (time ~ error^-k locally), over Cycles' time."""
    (_, t_c, e_c), tes = points[0], sorted((e, w) for p, w, e in points[1:])
    for (e0, w0), (e1, w1) in zip(tes, tes[1:]):
        if e0 <= e_c <= e1 and e1 > e0:
            f = math.log(e_c / e0) / math.log(e1 / e0)
            w = math.exp(math.log(w0) + f * (math.log(w1) - math.log(w0)))
            return (f"- {name}: Tesela reaches Cycles' error ({e_c:.2e}) in {w:.2f} s, "
                    f"{w / t_c:.2f}x Cycles' {t_c:.2f} s")
    side = "below" if e_c < tes[0][0] else "above"
    return f"- {name}: Cycles' error {e_c:.2e} is {side} every Tesela run's (no read-off)"


def equal_time_bench(args):
    """Equal-time error through the add-on, plain Monte Carlo on both sides (fixed spp, no noise
    threshold, no denoiser): Cycles renders `--addon-spp` samples; Tesela's spp is chosen from two
    calibration renders (1 and that spp) so that its wall time, export and process start included,
    matches Cycles' median; each is compared with its own `--clean-ref-spp` reference (relMSE
    corrected for the reference's own noise, which is the error at spp scaled by spp / ref spp)."""
    import bpy
    import importlib
    bs = _addon_setup(args)
    size = args.size or (48 if args.quick else 128)
    ref_spp = 64 if args.quick else args.clean_ref_spp
    spp = 4 if args.quick else args.addon_spp
    repeats = args.repeats or (2 if args.quick else 3)
    bounces = 3
    lines = [f"#### Equal time through the add-on: {size}x{size}, Cycles {spp} spp, max bounces "
             f"{bounces} / Tesela path_mis depth {bounces + 2}, {args.threads} threads; relMSE against "
             f"each renderer's own {ref_spp} spp reference (its noise removed)", "",
             "| scene | peer | spp | median wall s | relMSE | mean RGB |",
             "| --- | --- | --- | --- | --- | --- |"]
    ratios = {}
    for name in [n.strip() for n in args.addon_scenes.split(",") if n.strip()]:
        module, builder = ADDON_SCENES[name]
        bs.clear_scene()
        getattr(importlib.import_module(module), builder)()
        sc = bpy.context.scene
        bs.configure_cycles(sc, size, size, ref_spp, bounces, seed=1, threads=args.threads)
        t = sc.tesela
        bs.tesela_like_cycles(t)
        t.integrator, t.max_depth, t.threads = "path_mis", bounces + 2, args.threads
        ref = {}
        for peer, engine in (("cycles", "CYCLES"), ("tesela", "TESELA")):
            _addon_render(engine, ref_spp, 7)
            ref[peer] = _render_result_image()
        ones = [_addon_render("TESELA", 1, 100 + r) for r in range(repeats)]
        fulls = [_addon_render("TESELA", spp, 200 + r) for r in range(repeats)]
        cyc = []
        for r in range(repeats):
            cyc.append((_addon_render("CYCLES", spp, 300 + r), _render_result_image()))
        t_c = statistics.median(w for w, _ in cyc)
        t1, ts = statistics.median(ones), statistics.median(fulls)
        per_sample = max(ts - t1, 1e-9) / max(spp - 1, 1)
        spp_t = max(1, round(1 + (t_c - t1) / per_sample))
        tes = []
        for r in range(repeats):
            tes.append((_addon_render("TESELA", spp_t, 400 + r), _render_result_image()))
        row = {}
        for peer, runs, n in (("cycles", cyc, spp), ("tesela", tes, spp_t)):
            errs = [rel_mse(img, ref[peer]) / (1 + n / ref_spp) for _, img in runs]
            wall = statistics.median(w for w, _ in runs)
            row[peer] = (wall, statistics.median(errs))
            m = ", ".join(f"{v:.4f}" for v in runs[-1][1].reshape(-1, 3).mean(axis=0))
            lines.append(f"| {name} | {peer} | {n} | {wall:.2f} | {row[peer][1]:.3e} | {m} |")
            log(lines[-1])
        # Scaled to exactly Cycles' wall time (error ~ 1 / time) where the walls differ a little.
        scaled = row["tesela"][1] * row["tesela"][0] / row["cycles"][0]
        ratios[name] = scaled / row["cycles"][1]
    lines.append("")
    for name, r in ratios.items():
        lines.append(f"- {name}: Tesela / Cycles relMSE at Cycles' wall time {r:.2f}x")
    text = "\n".join(lines)
    log("\n" + text)
    return text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="tiny sizes: a smoke run")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=None, help="timed runs per peer (default 5; quick 2)")
    ap.add_argument("--peers", default=",".join(ALL_PEERS),
                    help=f"comma list of {ALL_PEERS + OPTIONAL_PEERS}")
    ap.add_argument("--scenes", default="cornell,spheres")
    ap.add_argument("--modes", default="direct,path")
    ap.add_argument("--size", type=int, default=None, help="image width = height (default 256; quick 48)")
    ap.add_argument("--budget", type=float, default=None,
                    help="equal-time budget in seconds per render (default 2; quick 0.2)")
    ap.add_argument("--ref-factor", type=int, default=None,
                    help="reference spp = this x budget spp (default 16; quick 8)")
    ap.add_argument("--cal-spp", type=int, default=None)
    ap.add_argument("--tesela", default=str(REPO / "target/release/tesela"))
    ap.add_argument("--no-traversal", action="store_true",
                    help="skip the raw-obvhs comparison (cargo bench --bench traversal)")
    ap.add_argument("--out", default=None, help="directory for the .md/.json result "
                    "(default bench/results; quick: a temporary directory)")
    ap.add_argument("--merge", nargs="+", metavar="JSON",
                    help="no rendering: pool the timed runs of earlier full runs' .json files "
                         "and print (and with --out, write) the combined tables")
    ap.add_argument("--addon", action="store_true",
                    help="only the Blender scenes through the add-on (Tesela vs Cycles, same spp)")
    ap.add_argument("--addon-scenes", default=",".join(ADDON_SCENES))
    ap.add_argument("--addon-spp", type=int, default=64)
    ap.add_argument("--clean", action="store_true",
                    help="time to a clean image with each renderer's defaults (adaptive + OIDN)")
    ap.add_argument("--clean-ref-spp", type=int, default=2048)
    ap.add_argument("--clean-scenes", default=",".join(CLEAN_SCENES))
    ap.add_argument("--equal-time", action="store_true",
                    help="Blender scenes through the add-on: relMSE at Cycles' wall time, plain MC")
    args = ap.parse_args()
    if args.merge:
        return merge(args)
    if args.addon or args.clean or args.equal_time:
        import bpy  # noqa: F401
        if args.equal_time:
            text = equal_time_bench(args)
        else:
            text = clean_bench(args) if args.clean else addon_bench(args)
        if args.out:
            Path(args.out).mkdir(parents=True, exist_ok=True)
            stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%d-%H%M")
            kind = "equal-time" if args.equal_time else "clean" if args.clean else "addon"
            (Path(args.out) / f"{kind}-{stamp}.md").write_text(text + "\n")
        return None
    q = args.quick
    args.repeats = args.repeats or (2 if q else 5)
    args.budget = args.budget or (0.2 if q else 2.0)
    args.ref_factor = args.ref_factor or (8 if q else 16)
    args.cal_spp = args.cal_spp or (1 if q else 2)
    size = args.size or (48 if q else 256)
    names = [n.strip() for n in args.peers.split(",") if n.strip()]
    unknown = set(names) - set(ALL_PEERS + OPTIONAL_PEERS)
    if unknown:
        ap.error(f"unknown peers {sorted(unknown)}")

    work = Path(tempfile.mkdtemp(prefix="tesela-peers-"))
    log(f"work directory {work}")
    binary = Path(args.tesela)
    if any(n.startswith("tesela") for n in names):
        if not binary.exists():
            sys.exit(f"{binary} not found: run `cargo build --release` (or pass --tesela PATH)")
        snap = work / "tesela"  # a snapshot: a rebuild during the run does not change what runs
        shutil.copy2(binary, snap)
        binary = snap
    if any(n.startswith("mitsuba") for n in names):
        llvm = Path("/usr/lib/x86_64-linux-gnu/libLLVM-19.so")
        if "DRJIT_LIBLLVM_PATH" not in os.environ and llvm.exists():
            os.environ["DRJIT_LIBLLVM_PATH"] = str(llvm)
        try:
            import mitsuba  # noqa: F401
        except ImportError:
            sys.exit("mitsuba is missing: `.venv/bin/pip install mitsuba` (and for llvm_ad_rgb: "
                     "`apt-get install libllvm19`), or leave it out with --peers")
    import bpy  # noqa: F401  (Cycles, and the EXR reader)

    peers = []
    for n in names:
        if n == "tesela":
            peers.append(Tesela("tesela", binary, args.threads, work))
        elif n == "tesela-1t":
            peers.append(Tesela("tesela-1t", binary, 1, work))
        elif n == "cycles":
            peers.append(Cycles(args.threads, work))
        elif n == "mitsuba-scalar":
            peers.append(Mitsuba("scalar_rgb", args.threads, work))
        elif n == "mitsuba-llvm":
            peers.append(Mitsuba("llvm_ad_rgb", args.threads, work))

    env = {"date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
           "threads": args.threads, "cpus": os.cpu_count(), "size": size,
           "budget_s": args.budget, "repeats": args.repeats, "ref_factor": args.ref_factor,
           "peers": names, "quick": q, "load_avg_start": os.getloadavg()}
    try:
        env["tesela_commit"] = subprocess.run(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"],
                                              capture_output=True, text=True).stdout.strip()
        if binary.exists():
            import hashlib
            env["tesela_binary_sha256"] = hashlib.sha256(binary.read_bytes()).hexdigest()[:16]
        env["tesela_binary_mtime"] = _dt.datetime.fromtimestamp(
            Path(args.tesela).stat().st_mtime, _dt.timezone.utc).isoformat(timespec="seconds")
        import bpy as _b
        env["blender"] = _b.app.version_string
        if any(n.startswith("mitsuba") for n in names):
            import drjit
            import mitsuba
            env["mitsuba"], env["drjit"] = mitsuba.__version__, drjit.__version__
    except Exception as e:  # noqa: BLE001 (informational only)
        env["env_error"] = str(e)
    log(json.dumps(env))

    results, md = [], []
    for sname in [s.strip() for s in args.scenes.split(",") if s.strip()]:
        make = bench_scenes.SCENES[sname]
        scene = make(60, 30) if (q and sname == "spheres") else make()
        log(f"\n## scene {sname}: {scene.triangle_count()} triangles")
        setup = {}
        for p in peers:
            t0 = time.perf_counter()
            info = p.setup(scene, size, size)
            info["total_s"] = time.perf_counter() - t0
            setup[p.name] = info
            log(f"  setup {p.name}: {json.dumps({k: round(v, 3) for k, v in info.items()})}")
        for mode in [m.strip() for m in args.modes.split(",") if m.strip()]:
            res = bench_mode(peers, sname, mode, args, size, size)
            res["triangles"] = scene.triangle_count()
            res["setup"] = setup
            results.append(res)
            t = tables(res, setup)
            md.append(t)
            log("\n" + t + "\n")
    traversal_results = []
    if not args.no_traversal and any(p.name == "tesela" for p in peers):
        for res in results:
            if res["triangles"] < 1_000_000 and not q:
                continue
            gltf = work / f"{res['scene']}.gltf"
            log(f"\n## traversal: {res['scene']} {res['mode']} (cargo bench --bench traversal)")
            tr = traversal(gltf, size, res["mode"])
            log(tr["report"])
            traversal_results.append(tr)
            md.append(f"#### {res['scene']} — {res['mode']}: Tesela's rays against raw obvhs "
                      f"(`cargo bench --bench traversal`, one thread)\n\n```\n{tr['report']}\n```")
    env["load_avg_end"] = os.getloadavg()
    tgt = targets(results, traversal_results)
    log("\n### Targets (issue 5; ratios of medians)\n\n" + tgt)
    outdir = Path(args.out) if args.out else (work if q else HERE / "results")
    outdir.mkdir(parents=True, exist_ok=True)
    stamp = _dt.datetime.now(_dt.timezone.utc).strftime("%Y%m%d-%H%M")
    kind = "quick" if q else "full"
    text = (f"# Tesela vs peers — {env['date']}\n\n```\n{json.dumps(env, indent=1)}\n```\n\n"
            + "\n\n".join(md) + "\n\n### Targets (issue 5; ratios of medians)\n\n" + tgt + "\n")
    (outdir / f"peers-{stamp}-{kind}.md").write_text(text)
    for r in results:
        for runs in r["runs"].values():
            for x in runs:
                x.pop("image", None)
    (outdir / f"peers-{stamp}-{kind}.json").write_text(json.dumps({"env": env, "results": results},
                                                                  indent=1, default=str))
    log(f"\nwrote {outdir}/peers-{stamp}-{kind}.md and .json")


if __name__ == "__main__":
    main()
