"""Cycles' light passes through the add-on against Cycles' own (bpy 5).

The Cornell box (Lambertian walls, an emissive ceiling quad) with a rough metal sphere
(glossy), a rough glass sphere (glossy reflection and transmission) and a ball mixing a
Diffuse and a Glossy BSDF (two classes in one material); View Layer > Passes:
every Diffuse, Glossy and Transmission pass. Both renders are multi-layer EXRs read back.

Criteria: the Color passes with the agreement thresholds (means within 2%, 8x8-block p95
within 5%) of Cycles'; each Direct and Indirect pass likewise, compared as the light it stands
for (pass x Color, what the compositor multiplies back): divided by a glass sphere's Fresnel
albedo of ~0.05, the pass itself is too noisy to compare at a test's sample count (Cycles
against itself with another seed: Glossy Indirect mean 3-8% apart, block p95 0.24-0.28). Glossy
Indirect's block p95 is allowed 15% for the same reason (Cycles against itself: 0.12; its mean
still within 2%). In each renderer the passes add up to Combined ((Direct + Indirect) x Color
over the three classes, plus Emission and Environment).
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
import test_passes_cycles
from test_passes_cycles import render_multilayer

OpenEXR = pytest.importorskip("OpenEXR")

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


W, H = 32, 32
SPP = 2048
BOUNCES = 4
CLASSES = ("Diffuse", "Glossy", "Transmission")
TOGGLES = ["use_pass_emit", "use_pass_environment"] + [
    f"use_pass_{c.lower()}_{k}" for c in CLASSES for k in ("direct", "indirect", "color")]


def diffuse_and_glossy():
    """Two closures in one material: Mix Shader (0.35) of a blue Diffuse BSDF and a rough
    white Glossy BSDF."""
    mat = bpy.data.materials.new("Ball")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.2, 0.35, 0.8, 1.0)
    # Blender 4.0 merged Anisotropic into Glossy under the older node's idname.
    glossy = nodes.new("ShaderNodeBsdfAnisotropic")
    glossy.inputs["Roughness"].default_value = 0.3
    mix = nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.35
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(diffuse.outputs[0], mix.inputs[1])
    links.new(glossy.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def build_scene():
    info = scenes.cornell_box(spheres=True)
    metal = bpy.data.materials["Mirror"]
    bsdf = next(n for n in metal.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Roughness"].default_value = 0.3
    bsdf.inputs["Base Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    # Rough glass: its reflection of the lamp is found by light sampling (a smooth sphere's
    # few-pixel highlight, reflected with probability F ~ 0.05, stays noisy for thousands of
    # samples in both renderers).
    glass = bpy.data.materials["Glass"]
    bsdf = next(n for n in glass.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Roughness"].default_value = 0.25
    scenes.add_sphere("Ball", (-0.05, -0.6, 0.2), 0.2, diffuse_and_glossy())
    vl = info.scene.view_layers[0]
    for toggle in TOGGLES:
        setattr(vl, toggle, True)
    return info.scene


def pass_of(layers, name):
    """The RGB of one pass (see test_passes_cycles.pass_of)."""
    return test_passes_cycles.pass_of(layers, name)[..., :3]


@pytest.fixture(scope="module")
def renders(addon, tesela_bin, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("light_passes")
    os.environ["TESELA_BINARY"] = str(tesela_bin)
    scene = build_scene()
    scenes.configure_cycles(scene, W, H, SPP, BOUNCES, seed=2)
    ref = render_multilayer(tmp / "cycles.exr")
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", SPP, BOUNCES + 2, 1
    got = render_multilayer(tmp / "tesela.exr")
    del os.environ["TESELA_BINARY"]
    return ref, got


def _names():
    return [f"{c} {k}" for c in CLASSES for k in ("Direct", "Indirect", "Color")]


@pytest.mark.parametrize("name", _names())
def test_light_pass_matches_cycles(renders, name):
    ref, got = renders
    r, g = pass_of(ref, name), pass_of(got, name)
    block_tol = 0.15 if name == "Glossy Indirect" else 0.05
    if not name.endswith("Color"):
        color = name.split()[0] + " Color"
        r, g = r * pass_of(ref, color), g * pass_of(got, color)
    if name == "Transmission Direct":
        # The lamp is on the camera's side of the glass: light reaches the sphere's first
        # vertex through it only after a second refraction, which is indirect.
        assert r.max() < 1e-6 and g.max() < 1e-6, (r.max(), g.max())
        return
    assert r.mean() > 1e-3, f"{name}: the reference is black"
    pad = lambda a: np.concatenate([a, np.ones(a.shape[:2] + (1,), np.float32)], -1)
    result = imgcompare.compare(pad(g), pad(r), mean_tol=0.02, block_tol=block_tol)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: {result}"


@pytest.mark.parametrize("which", [0, 1])
def test_light_passes_add_up_to_combined(renders, which):
    layers = renders[which]
    total = pass_of(layers, "Emission") + pass_of(layers, "Environment")
    for c in CLASSES:
        col = pass_of(layers, f"{c} Color")
        total = total + (pass_of(layers, f"{c} Direct") + pass_of(layers, f"{c} Indirect")) * col
    combined = pass_of(layers, "Combined")
    err = np.abs(total - combined) / (1e-3 + np.abs(combined))
    print(f"{('Cycles', 'Tesela')[which]}: worst relative error {err.max():.2e}")
    assert np.percentile(err, 99) < 1e-3
