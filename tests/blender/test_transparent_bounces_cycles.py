"""Light Paths > Transparent max bounces as Cycles honours it (bpy 5), through the add-on: a
shadow ray that would cross more alpha surfaces than the path has left (the limit minus the
transparent surfaces the path passed) is blocked, and a camera path that passed the limit's
worth ends at the next surface (its emission only). Means within 2%, 8x8-block p95 within 5%.
"""

import os
import sys
import math
from pathlib import Path

import bpy
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from test_addon import result_pixels  # noqa: E402

SIZE = 48


def alpha_card_material(name, color, alpha):
    """A Lambertian Principled BSDF (no specular layer) with Alpha ``alpha``."""
    m = scenes.lambert(name, color)
    bsdf = next(n for n in m.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    bsdf.inputs["Alpha"].default_value = alpha
    return m


def staircase(mat, count, z0, dz, camera_visible=True):
    """``count`` horizontal cards from height ``z0`` up in steps ``dz``, card i spanning
    x in [-2, 1.6 - 0.7 i] (wider than the view in y): from +x to -x the floor has 0, 1, ...,
    ``count`` cards above it."""
    for i in range(count):
        z, x1 = z0 + dz * i, 1.6 - 3.2 * i / count
        ob = scenes.add_quad("Card%d" % i, [(-2.5, -2.5, z), (x1, -2.5, z), (x1, 2.5, z),
                                             (-2.5, 2.5, z)], mat)
        ob.visible_camera = camera_visible


def shadow_stack():
    """A grey floor under a straight-down sun, shadowed by a staircase of 4 alpha-0.5 cards
    the camera does not see: floor regions under 0 to 4 cards."""
    scene = scenes.clear_scene()
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    scenes.add_sun_light("Sun", (0.0, 0.0, -1.0), 3.0)
    staircase(alpha_card_material("Card", (0.5, 0.5, 0.5), 0.5), 4, 0.5, 0.2,
              camera_visible=False)
    scenes.add_camera((0.0, 0.0, 6.0), (0.0, 0.0, 0.0), ortho_scale=3.6)
    return scene


def camera_cards():
    """Four alpha-0.5 cards (a staircase) in front of an emissive wall, lit by a tilted sun,
    seen from the front: regions behind 0 to 4 cards."""
    scene = scenes.clear_scene()
    scenes.add_quad("Wall", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.emitter("Wall", (1.0, 0.9, 0.8), 1.0))
    scenes.add_sun_light("Sun", (0.3, 0.2, -1.0), 2.0)
    staircase(alpha_card_material("Card", (0.2, 0.7, 0.3), 0.5), 4, 0.5, 0.2)
    scenes.add_camera((0.0, 0.0, 6.0), (0.0, 0.0, 0.0), ortho_scale=3.6)
    return scene


def foliage():
    """A canopy of 10 layers of faint leaf cards (alpha 0.15) over a grey floor, lit by a
    straight-down sun and seen obliquely through the canopy: paths pass several leaves before
    the floor and the floor's shadow rays cross up to 10 more, past Cycles' default 8."""
    scene = scenes.clear_scene()
    scenes.add_quad("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)],
                    scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    scenes.add_sun_light("Sun", (0.0, 0.0, -1.0), 3.0)
    staircase(alpha_card_material("Leaf", (0.2, 0.6, 0.15), 0.15), 10, 0.4, 0.12)
    scenes.add_camera((1.5, -3.0, 4.0), (0.0, 0.0, 0.3), fov=math.radians(55.0))
    return scene


def render_tesela(scene, limit, integrator, spp, bounces, tmp_path):
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.transparent_max_bounces = limit
    t.integrator, t.samples, t.max_depth, t.seed = integrator, spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return result_pixels(tmp_path)


CASES = [
    # (id, scene, transparent_max_bounces, Tesela integrator, bounces, Cycles spp, Tesela spp)
    ("shadow_stack_limit_2", shadow_stack, 2, "direct_mis", 0, 64, 64),
    ("shadow_stack_limit_2_path", shadow_stack, 2, "path_mis", 2, 1024, 1024),
    ("camera_cards_limit_2", camera_cards, 2, "path_mis", 2, 512, 512),
    ("foliage_default_8", foliage, 8, "direct_mis", 0, 256, 256),
    ("foliage_default_8_path", foliage, 8, "path_mis", 1, 512, 512),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_transparent_bounces_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, make, limit, integrator, bounces, cycles_spp, tesela_spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = make()
    scenes.configure_cycles(scene, SIZE, SIZE, cycles_spp, bounces, seed=2)
    scene.cycles.transparent_max_bounces = limit
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    got = render_tesela(scene, limit, integrator, tesela_spp, bounces, tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
