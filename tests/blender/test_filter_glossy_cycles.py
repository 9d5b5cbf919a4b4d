"""Cycles' Filter Glossy (``blur_glossy``) copied to Tesela gives Cycles' image (bpy 5): a
Lambertian floor lit only through a metal ceiling by a small area light facing it, a caustic
that Filter Glossy blurs (after the floor's diffuse bounce the metal is a GGX lobe of alpha at
least sqrt(1 - 1/π)/2). A sharp mirror becomes a lobe without energy compensation; a metal of
roughness 0.5 (alpha 0.25) keeps the compensation of its own roughness (found at the blurred
one, Tesela was 1.19x Cycles). The same scene without the filter must miss Cycles' blurred
image by more than the tolerance, so the test can fail.
"""

import os

import bpy
import numpy as np
import pytest

import imgcompare
import scenes
from test_addon import result_pixels

SIZE = 48
BOUNCES = 4
MIRROR = 1.0  # side of the mirror, m


def caustic_scene(roughness=0.0):
    """The floor (6 m, albedo 0.8) at z = 0; a white metal of ``roughness``, side ``MIRROR``,
    at z = 2 facing down; a 0.3 m area light at z = 1 facing up at it; the camera at z = 0.8
    looking straight down, so that it sees the floor and nothing else."""
    scene = scenes.clear_scene()
    floor = scenes.lambert("Floor", (0.8, 0.8, 0.8))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    h = MIRROR / 2
    scenes.add_quad("Mirror", [(-h, -h, 2), (-h, h, 2), (h, h, 2), (h, -h, 2)],
                    scenes.material("Mirror", (1.0, 1.0, 1.0), metallic=1.0,
                                    roughness=roughness))
    scenes.add_area_light("Light", (0.0, 0.0, 1.0), (0.0, 0.0, 2.0), 20.0, 0.3)
    scenes.add_camera((0.0, 0.0, 0.8), (0.0, 0.0, 0.0), fov=1.2)
    return scene


def render_tesela(scene, blur_glossy, spp, tmp_path):
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.blur_glossy = blur_glossy
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", spp, BOUNCES + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return result_pixels(tmp_path)


@pytest.mark.parametrize("roughness", [0.0, 0.5])
def test_filter_glossy_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, roughness):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = caustic_scene(roughness)
    scenes.configure_cycles(scene, SIZE, SIZE, 256, BOUNCES, seed=2)
    scene.cycles.blur_glossy = 1.0
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    got = render_tesela(scene, 1.0, 512, tmp_path)
    sharp = render_tesela(scene, 0.0, 256, tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    off = imgcompare.compare(sharp, ref, mean_tol=0.02, block_tol=0.05)
    print(f"roughness {roughness}, filter glossy 1: {result}; without the filter: {off}")
    assert not off.ok and float(np.max(off.mean_rel_err)) > 0.05, \
        f"the filter changes too little to be tested: {off}"
    assert result.ok, f"Tesela vs Cycles: {result}"
