"""IES light profiles (an IES Texture node into a light's Emission Strength) through the add-on
(F12 path) against Cycles on the same scene: a downlight with a narrow beam and a tilted light
with an asymmetric profile over a floor and a wall, a spot with a quadrant-symmetric profile,
an external file with the IES Strength at 2.5 on a light with a radius, and an area light.
Criteria as test_lights_cycles.py (means 2%, 8x8 blocks 5% at the 95th percentile, edges).
The profiles are synthetic LM-63 texts written here; malformed and missing ones are reported.
"""

import json
import math
import subprocess

import bpy
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles


def lm63(v, h, rows, kind=1, multiplier=1.0, tilt="NONE"):
    """An LM-63-2002 text: vertical angles `v`, horizontal `h` (degrees), candela `rows` (one
    per horizontal angle), photometric type `kind`, numbers wrapped as real files wrap them."""
    def wrap(xs):
        xs = ["%g" % x for x in xs]
        return "\n".join(" ".join(xs[i:i + 10]) for i in range(0, len(xs), 10))
    head = ["IESNA:LM-63-2002", "[TEST] synthetic", "[MANUFAC] Tesela tests", "TILT=" + tilt,
            "1 -1 %g %d %d %d 2 0.1 0.1 0.05" % (multiplier, len(v), len(h), kind),
            "1.0 1.0 12"]
    return "\r\n".join(head + [wrap(v), wrap(h)] + [wrap(r) for r in rows]) + "\r\n"


# A downlight: a narrow beam straight down, a little spill up to 90 degrees.
DOWN_V = [0, 5, 10, 15, 20, 25, 30, 40, 50, 60, 70, 80, 90]
DOWN = lm63(DOWN_V, [0], [[1200, 1150, 1000, 760, 480, 260, 130, 60, 30, 15, 6, 2, 0]])

# An asymmetric wall-washer: brighter towards one side, over the whole sphere.
ASYM_V = [0, 22.5, 45, 67.5, 90, 112.5, 135, 157.5, 180]
ASYM_H = [0, 45, 90, 135, 180, 225, 270, 315, 360]
ASYM = lm63(ASYM_V, ASYM_H, [
    [round(600 * math.exp(-((v - 40) / 35) ** 2) * (1.0 + 0.8 * math.cos(math.radians(h - 90)))
           + 20, 1) for v in ASYM_V]
    for h in ASYM_H])

# A quadrant-symmetric profile (0-90 degrees horizontally): a beam wider along one axis.
QUAD_V = [0, 10, 20, 30, 40, 50, 60, 70, 80, 90]
QUAD_H = [0, 30, 60, 90]
QUAD = lm63(QUAD_V, QUAD_H, [
    [round(900 * math.cos(math.radians(v)) ** (1.5 + 4.0 * math.sin(math.radians(h)) ** 2), 1)
     for v in QUAD_V]
    for h in QUAD_H])


def floor_and_wall():
    """A 6 m floor and a wall 1.2 m behind the origin (albedo 0.8), seen from the front and
    above, so that a light's pattern shows on both."""
    scene = scenes.clear_scene()
    mat = scenes.lambert("Diffuse", (0.8, 0.8, 0.8))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 1.2, 0), (-3, 1.2, 0)], mat)
    scenes.add_quad("Wall", [(-3, 1.2, 0), (3, 1.2, 0), (3, 1.2, 3), (-3, 1.2, 3)], mat)
    scenes.add_camera((0.0, -3.0, 1.7), (0.0, 0.6, 0.7), fov=math.radians(62.0))
    return scenes.SceneInfo(scene, "floor_and_wall")


def attach_ies(ob, text=None, filepath=None, strength=1.0, name="profile.ies"):
    """Give light `ob` an IES Texture into its Emission's Strength: a Text datablock of `text`
    ('INTERNAL') or the file `filepath` ('EXTERNAL')."""
    ob.data.use_nodes = True
    nt = ob.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    ies = nt.nodes.new("ShaderNodeTexIES")
    if text is not None:
        ies.mode = "INTERNAL"
        t = bpy.data.texts.new(name)
        t.write(text)
        ies.ies = t
    else:
        ies.mode = "EXTERNAL"
        ies.filepath = str(filepath)
    ies.inputs["Strength"].default_value = strength
    nt.links.new(ies.outputs["Fac"], em.inputs["Strength"])
    return ies


def downlight():
    info = floor_and_wall()
    ob = scenes.add_point_light("Down", (0.3, 0.6, 2.0), 1.5)
    attach_ies(ob, DOWN)
    return info


def asymmetric_tilted():
    info = floor_and_wall()
    ob = scenes.add_point_light("Washer", (-0.2, 0.3, 1.9), 1.0, color=(1.0, 0.85, 0.7))
    ob.rotation_euler = (0.35, -0.25, 0.9)
    attach_ies(ob, ASYM)
    return info


def asymmetric_scaled():
    """An unevenly scaled light: Cycles takes the direction into the light's object space as a
    normal (by the transpose of its matrix), which the scale distorts."""
    info = floor_and_wall()
    ob = scenes.add_point_light("Washer", (-0.2, 0.3, 1.9), 1.0)
    ob.rotation_euler = (0.2, 0.0, 0.6)
    ob.scale = (1.8, 0.6, 1.0)
    attach_ies(ob, ASYM)
    return info


def spot_quadrant():
    info = floor_and_wall()
    ob = scenes.add_spot_light("Spot", (-0.4, -0.6, 2.2), (0.3, 0.9, 0.4), 2.0,
                               math.radians(100.0), blend=0.25)
    attach_ies(ob, QUAD)
    return info


def external_strength(tmp_path):
    def build():
        path = tmp_path / "washer.ies"
        path.write_text(ASYM, encoding="utf-8")
        info = floor_and_wall()
        ob = scenes.add_point_light("Lamp", (0.2, 0.4, 1.8), 0.4, radius=0.15)
        ob.rotation_euler = (0.0, 0.0, 2.2)
        attach_ies(ob, filepath=path, strength=2.5)
        return info
    return build


def area_light():
    info = floor_and_wall()
    ob = scenes.add_area_light("Panel", (0.0, 0.2, 2.0), (0.3, 0.6, 0.0), 3.0, 0.4)
    attach_ies(ob, ASYM)
    return info


# (id, builder, Cycles max_bounces, Tesela integrator, spp)
CASES = [
    ("downlight", downlight, 0, "direct_mis", 64),
    ("asymmetric_tilted", asymmetric_tilted, 0, "direct_mis", 64),
    ("asymmetric_scaled", asymmetric_scaled, 0, "direct_mis", 64),
    ("spot_quadrant", spot_quadrant, 0, "direct_mis", 64),
    ("area_light", area_light, 0, "direct_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_ies_profiles_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)


def test_an_external_ies_file_and_its_strength_agree_with_cycles(  # noqa: F811
        addon, tesela_bin, tmp_path, monkeypatch):
    case = ("external_strength", external_strength(tmp_path), 0, "direct_mis", 256)
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)


def test_ies_profiles_are_exported_and_bad_ones_reported(addon, tesela_bin, tmp_path):  # noqa: F811
    """The profile's text travels in TESELA_light.ies with its name, the IES Strength in the
    colour; a missing file is reported by the add-on and a malformed profile by the renderer,
    each naming the light and the file, and both lights render without their profile."""
    from blender_addon import export

    scenes.clear_scene()
    good = scenes.add_point_light("Good", (0, 0, 1), 10.0)
    attach_ies(good, DOWN, strength=3.0, name="down.ies")
    gone = scenes.add_point_light("Gone", (1, 0, 1), 10.0)
    attach_ies(gone, filepath=tmp_path / "nowhere.ies")
    bad = scenes.add_spot_light("Bad", (0, 1, 1), (0, 1, 0), 10.0, math.radians(60.0))
    attach_ies(bad, DOWN.replace("\r\n0 5 10", "\r\n0 five 10"), name="broken.ies")
    path = tmp_path / "l.gltf"
    res = export.write_gltf(bpy.context.evaluated_depsgraph_get(), str(path), width=8, height=8)
    doc = json.loads(path.read_text(encoding="utf-8"))
    lights = {n["name"]: n["extensions"]["TESELA_light"] for n in doc["nodes"]
              if "TESELA_light" in n.get("extensions", {})}
    assert lights["Good"]["ies"] == {"name": "down.ies", "data": DOWN.replace("\r\n", "\n")} \
        or lights["Good"]["ies"] == {"name": "down.ies", "data": DOWN}
    assert lights["Good"]["color"] == pytest.approx([3.0, 3.0, 3.0])
    assert "graph" not in lights["Good"], "an IES tree is read, not left to the renderer"
    assert "ies" not in lights["Gone"]
    assert any("light 'Gone'" in w and "nowhere.ies" in w for w in res.warnings), res.warnings
    run = subprocess.run([str(tesela_bin), "render", str(path), "-o", str(tmp_path / "l.exr"),
                          "--spp", "1"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "light 'Bad'" in run.stderr and "broken.ies" in run.stderr \
        and "five" in run.stderr, run.stderr
    assert "light 'Good'" not in run.stderr, run.stderr
