"""Cycles' Light Paths settings copied to Tesela give Cycles' light paths (bpy 5): per-kind
bounce limits and sample clamping on the Cornell box with mirror and glass spheres. Each case
must also differ from the unlimited render by more than the tolerance, so it can fail.
"""

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

SIZE = 48
BOUNCES = 6


CASES = [
    # (id, Cycles/Tesela settings, Cycles spp, Tesela spp)
    ("diffuse_1", {"diffuse_bounces": 1}, 512, 1024),
    ("glossy_0_transmission_1", {"glossy_bounces": 0, "transmission_bounces": 1}, 512, 1024),
    ("clamp_indirect_0.3", {"sample_clamp_indirect": 0.3}, 512, 1024),
    ("clamp_direct_1", {"sample_clamp_direct": 1.0}, 512, 1024),
    # Rays leaving the walls and floor meet neither the mirror's nor the glass's lobes.
    ("no_caustics", {"caustics_reflective": False, "caustics_refractive": False}, 512, 1024),
    ("no_refractive_caustics", {"caustics_refractive": False}, 512, 1024),
    # After the walls' diffuse bounces the mirror and the glass are blurred (Filter Glossy).
    ("blur_glossy_1", {"blur_glossy": 1.0}, 512, 1024),
]


def render_tesela(scene, settings, spp, tmp_path):
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    for k, v in settings.items():
        setattr(t, k, v)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", spp, BOUNCES + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return result_pixels(tmp_path)


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_light_paths_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, settings, cycles_spp, tesela_spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = scenes.cornell_box(spheres=True)
    scene = info.scene if hasattr(info, "scene") else bpy.context.scene
    scenes.configure_cycles(scene, SIZE, SIZE, cycles_spp, BOUNCES, seed=2)
    for k, v in settings.items():
        setattr(scene.cycles, k, v)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    got = render_tesela(scene, settings, tesela_spp, tmp_path)
    unlimited = render_tesela(scene, {}, tesela_spp // 2, tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    change = float(np.abs(unlimited[..., :3].mean() / ref[..., :3].mean() - 1.0))
    print(f"{name}: {result}; the unlimited render differs by {change:.3f} in the mean")
    assert change > 0.02, f"{name}: the setting changes too little to be tested"
    assert result.ok, f"{name}: Tesela vs Cycles: {result}"
