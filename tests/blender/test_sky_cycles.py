"""The Sky Texture world through the add-on against Cycles: multiple and single scattering with
the sun at 30° and 25° over the diffuse plane and spheres of test_world_cycles (the sun disc off
frame, its light and shadows on the plane), and the sky alone seen along the horizon (the rows
the table's elevation mapping crowds, and the ground below, which multiple scattering lights);
Preetham's analytic sky over the plane.

Criteria: each channel's mean within 2%, 8x8 block means within 5% at the 95th percentile
(imgcompare.compare). Tesela's max depth = Cycles' max bounces + 2.
"""

import math

import pytest

import imgcompare
import scenes
from test_world_cycles import MEAN_TOL, BLOCK_TOL, _render_both, _world_nodes, base_scene


def _sky_world(scene, sky_type, elevation_deg, rotation_deg, strength):
    world, nt, out = _world_nodes(scene)
    sky = nt.nodes.new("ShaderNodeTexSky")
    sky.sky_type = sky_type
    sky.sun_elevation = math.radians(elevation_deg)
    sky.sun_rotation = math.radians(rotation_deg)
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = strength
    nt.links.new(sky.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs[0], out.inputs["Surface"])
    return scene


def lit_scene(sky_type, elevation_deg):
    # Sun to the right of the view and ahead: shadows fall back and to the left, in frame.
    return _sky_world(base_scene(), sky_type, elevation_deg, 60.0, 0.05)


def horizon_scene():
    """Only the sky: the camera looks level along the horizon, across from the sun."""
    scene = scenes.clear_scene()
    scenes.add_camera((0.0, 0.0, 1.0), (0.0, 10.0, 1.0), fov=math.radians(50.0))
    return _sky_world(scene, "MULTIPLE_SCATTERING", 20.0, 150.0, 1.0)


def preetham_scene():
    """Preetham's analytic sky (no sun disc) over the plane, turbidity 3, sun 35° high."""
    scene = _sky_world(base_scene(), "PREETHAM", 0.0, 0.0, 0.5)
    sky = next(n for n in scene.world.node_tree.nodes if n.bl_idname == "ShaderNodeTexSky")
    e, a = math.radians(35.0), math.radians(40.0)
    sky.sun_direction = (math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e))
    sky.turbidity = 3.0
    return scene


# (id, builder, Cycles max bounces, spp, film_transparent)
CASES = [
    ("multiple_scattering", lambda: lit_scene("MULTIPLE_SCATTERING", 30.0), 3, 128, False),
    ("single_scattering", lambda: lit_scene("SINGLE_SCATTERING", 25.0), 3, 128, False),
    ("horizon", horizon_scene, 1, 16, False),
    ("preetham", preetham_scene, 3, 64, False),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_sky_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name = case[0]
    ref, got = _render_both(tmp_path, monkeypatch, tesela_bin, case)
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
