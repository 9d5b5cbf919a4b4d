"""The pixel filter against Cycles' (bpy 5): a rotated emissive checker under an orthographic
camera, so every pixel's value is the filter's average of a sharp pattern (no lighting noise).
Cycles with its default filter (Blackman-Harris, 1.5 px) against Tesela with the same, and with
a Gaussian; the box filter must come out visibly sharper (the test can tell blur apart).
"""

import math
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from test_addon import result_pixels  # noqa: E402

W = H = 48
SPP = 256


def checker_scene():
    scenes.clear_scene()
    mat = bpy.data.materials.new("Checker")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    tex = nt.nodes.new("ShaderNodeTexChecker")
    coord = nt.nodes.new("ShaderNodeTexCoord")
    tex.inputs["Color1"].default_value = (1.0, 1.0, 1.0, 1.0)
    tex.inputs["Color2"].default_value = (0.0, 0.0, 0.0, 1.0)
    nt.links.new(coord.outputs["Object"], tex.inputs["Vector"])
    nt.links.new(tex.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    # Checker cells of 0.5 m: with the camera's 6 m frame, 4 pixels each.
    plane = scenes.add_quad("Plane", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], mat)
    tex.inputs["Scale"].default_value = 2.0
    plane.rotation_euler = (0.0, 0.0, math.radians(12.0))
    scenes.add_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ortho_scale=6.0)
    return bpy.context.scene


def tesela(scene, kind, width):
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.pixel_filter_type, t.filter_width = kind, width
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", SPP, 1, 1
    assert bpy.ops.render.render() == {"FINISHED"}
    return result_pixels(Path(bpy.app.tempdir or "/tmp"))


@pytest.mark.parametrize("kind, width", [("BLACKMAN_HARRIS", 1.5), ("GAUSSIAN", 1.5),
                                         ("BLACKMAN_HARRIS", 3.0)])
def test_pixel_filter_matches_cycles(addon, tesela_bin, tmp_path, monkeypatch, kind, width):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = checker_scene()
    scenes.configure_cycles(scene, W, H, SPP, 0, seed=3)
    scene.cycles.pixel_filter_type = kind
    scene.cycles.filter_width = width
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))[..., :3]
    got = tesela(scene, kind, width)[..., :3]
    sharp = tesela(scene, "BOX", 1.0)[..., :3]
    assert 0.3 < ref.mean() < 0.7 and ref.std() > 0.2, "the checker is not in view"
    err = np.abs(got - ref).mean()
    err_box = np.abs(sharp - ref).mean()
    # Local structure: the gradient energy (how sharp the edges are) agrees too.
    grad = lambda a: np.abs(np.diff(a, axis=0)).mean() + np.abs(np.diff(a, axis=1)).mean()
    print(f"{kind} {width}: mean |Tesela - Cycles| {err:.4f}, box filter {err_box:.4f}; "
          f"edge energy {grad(got):.4f} vs Cycles {grad(ref):.4f} (box {grad(sharp):.4f})")
    assert err < 0.02, f"{kind} {width}: per-pixel error {err}"
    assert err_box > 2.0 * err, "the box filter is as close: the test cannot see the blur"
    assert abs(grad(got) / grad(ref) - 1.0) < 0.05
