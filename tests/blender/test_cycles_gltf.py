"""Tesela against Blender's Cycles, on scenes exported with Blender's own glTF exporter.

Three groups (the facts behind them are written up in docs/blender-units.md):

* ``test_export_*``: what ``bpy.ops.export_scene.gltf`` writes for Blender lights, materials and
  cameras (the units the renderer's glTF import relies on).
* ``test_cycles_*``: Cycles against closed-form values (point/spot/sun/area lights, emission), so
  that a change in Blender's conventions shows up here first, not as a renderer "bug".
* ``test_agreement``: the same exported scene rendered by Cycles and by the ``tesela`` CLI,
  compared with ``imgcompare.compare`` (global means within 3%, 8x8 block means within 10% at the
  95th percentile). Needs the binary (see conftest.py).

Run: ``.venv/bin/python -m pytest tests/blender -v``.
"""

import json
import math
import os
import subprocess

import numpy as np
import pytest

bpy = pytest.importorskip("bpy", reason="needs Blender's Python module 'bpy'")

import imgcompare  # noqa: E402
import scenes  # noqa: E402

BLENDER_4 = bpy.app.version >= (4, 0, 0)
LUMENS_PER_WATT = 683.0
SIZE = 64  # every render here is SIZE x SIZE


# --------------------------------------------------------------------------------------------
# helpers


def run_tesela(binary, gltf, out, integrator, spp, max_depth, width=SIZE, height=SIZE, seed=1,
               extra=()):
    cmd = [str(binary), "render", str(gltf), "-o", str(out), "--integrator", integrator,
           "--spp", str(spp), "--max-depth", str(max_depth), "--width", str(width),
           "--height", str(height), "--seed", str(seed), "--quiet", *extra]
    threads = os.environ.get("TESELA_TEST_THREADS")
    if threads:
        cmd += ["--threads", threads]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if proc.returncode != 0:
        raise AssertionError(f"tesela failed ({proc.returncode}): {' '.join(cmd)}\n"
                             f"stdout:\n{proc.stdout}\nstderr:\n{proc.stderr}")
    return imgcompare.read_exr(out)


def export_and_render_cycles(tmp_path, info, spp, max_bounces, width=SIZE, height=SIZE, seed=7):
    """Configure Cycles (this sets the resolution, which the exported camera's yfov and
    aspectRatio depend on), export the glTF, render the Cycles reference.
    Returns (gltf path, Cycles image)."""
    scenes.configure_cycles(info.scene, width, height, spp, max_bounces, seed=seed)
    gltf = scenes.export_gltf(tmp_path / f"{info.name}.gltf")
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    return gltf, ref


def ortho_plane_setup(albedo=0.8, size=4.0):
    """Empty scene with a Lambertian plane at z = 0 and an orthographic camera looking down on
    it from z = 5, ``size`` metres across; returns pixel-centre x, y grids (4x4 supersampled)."""
    scenes.clear_scene()
    scenes.add_quad("Plane", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("Floor", (albedo,) * 3))
    scenes.add_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ortho_scale=size)
    ss = 4
    o = (np.arange(SIZE * ss) + 0.5) / (SIZE * ss) * size - size / 2
    x, y = np.meshgrid(o, -o)  # rows top to bottom = +y to -y
    return x, y


def pixel_mean(a, ss=4):
    return a.reshape(SIZE, ss, SIZE, ss).mean(axis=(1, 3))


def render_ortho(tmp_path, spp=16, name="cycles"):
    scenes.configure_cycles(bpy.context.scene, SIZE, SIZE, spp, 0, seed=3)
    return imgcompare.read_exr(scenes.render_cycles(tmp_path / f"{name}.exr"))[..., 0]


def assert_ratio(got, expected, tol, label):
    mask = expected > 0.05 * expected.max()
    ratio = got[mask].sum() / expected[mask].sum()
    worst = np.percentile(np.abs(got[mask] / expected[mask] - 1.0), 95)
    assert abs(ratio - 1.0) <= tol, f"{label}: Cycles/analytic = {ratio:.4f} (tol {tol})"
    return ratio, worst


# --------------------------------------------------------------------------------------------
# what Blender's exporter writes


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    scenes.clear_scene()
    scenes.add_point_light("Point", (0, 0, 2), 100.0, color=(1.0, 0.5, 0.25))
    scenes.add_spot_light("Spot", (0, 0, 2), (0, 0, 0), 100.0, math.radians(60.0), 0.3)
    scenes.add_sun_light("Sun", (0, 0, -1), 3.0)
    scenes.add_area_light("Area", (0, 0, 2), (0, 0, 0), 50.0, 2.0)
    mats = [scenes.lambert("Lambert", (0.8, 0.6, 0.4)), scenes.mirror("Mirror"),
            scenes.glass("Glass", 1.5), scenes.glass("Glass145", 1.45),
            scenes.emitter("Emit", (1.0, 0.9, 0.8), 5.0), scenes.emitter("EmitLow", (1, 1, 1), 0.5),
            scenes.material("OneSided", emission=(1, 1, 1), emission_strength=2.0,
                            double_sided=False)]
    for i, m in enumerate(mats):
        scenes.add_quad(f"Q{i}", [(i, 0, 0), (i + 1, 0, 0), (i + 1, 1, 0), (i, 1, 0)], m)
    scenes.add_camera((0, -4, 1), (0, 0, 0), fov=math.radians(40.0))
    bpy.context.scene.render.resolution_x = 128
    bpy.context.scene.render.resolution_y = 96
    path = scenes.export_gltf(tmp_path_factory.mktemp("export") / "units.gltf")
    with open(path) as f:
        doc = json.load(f)
    lights = {l["name"]: l for l in doc["extensions"]["KHR_lights_punctual"]["lights"]}
    materials = {m["name"]: m for m in doc["materials"]}
    return doc, lights, materials


def test_export_lights(exported):
    doc, lights, _ = exported
    assert "KHR_lights_punctual" in doc.get("extensionsRequired", [])
    point_cd = 100.0 / (4 * math.pi) * LUMENS_PER_WATT  # 'SPEC' mode: W/(4π) sr⁻¹ × 683 lm/W
    assert lights["Point"]["type"] == "point"
    assert lights["Point"]["intensity"] == pytest.approx(point_cd, rel=1e-6)
    assert lights["Point"]["color"] == pytest.approx([1.0, 0.5, 0.25])
    spot = lights["Spot"]
    assert spot["intensity"] == pytest.approx(point_cd, rel=1e-6)  # not concentrated in the cone
    outer = math.radians(60.0) / 2
    assert spot["spot"]["outerConeAngle"] == pytest.approx(outer, rel=1e-6)
    assert spot["spot"]["innerConeAngle"] == pytest.approx(outer * (1 - 0.3), rel=1e-6)
    assert lights["Sun"]["type"] == "directional"
    assert lights["Sun"]["intensity"] == pytest.approx(3.0 * LUMENS_PER_WATT, rel=1e-6)
    assert "Area" not in lights  # Blender's exporter drops area lights
    area = next(n for n in doc["nodes"] if n["name"] == "Area")
    assert "extensions" not in area


def test_export_materials(exported):
    _, _, m = exported
    lam = m["Lambert"]
    spec = lam["extensions"]["KHR_materials_specular"]
    if BLENDER_4:
        assert spec == {"specularFactor": 0}
    else:  # Blender 3.x writes the colour instead
        assert spec == {"specularColorFactor": [0, 0, 0]}
    assert "roughnessFactor" not in lam["pbrMetallicRoughness"]  # 1 = default
    assert lam["pbrMetallicRoughness"]["metallicFactor"] == 0
    mir = m["Mirror"]["pbrMetallicRoughness"]
    assert mir.get("metallicFactor", 1) == 1 and mir.get("roughnessFactor", 1) == 0
    for name, ior in (("Glass", 1.5), ("Glass145", 1.45)):
        g = m[name]
        assert g["extensions"]["KHR_materials_transmission"] == {"transmissionFactor": 1}
        assert g["extensions"].get("KHR_materials_ior", {"ior": 1.5})["ior"] == pytest.approx(ior)
        assert g["pbrMetallicRoughness"]["roughnessFactor"] == 0
    emit = m["Emit"]
    assert emit["emissiveFactor"] == pytest.approx([1.0, 0.9, 0.8])
    assert emit["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] == 5
    low = m["EmitLow"]  # strength <= 1 is folded into the factor, without the extension
    assert low["emissiveFactor"] == pytest.approx([0.5, 0.5, 0.5])
    assert "KHR_materials_emissive_strength" not in low.get("extensions", {})
    for name in ("Lambert", "Mirror", "Glass", "Emit"):
        assert m[name]["doubleSided"] is True  # backface culling off (Blender's default)
    assert "doubleSided" not in m["OneSided"]  # culling on -> false, yet Cycles emits both sides


def test_export_camera(exported):
    doc, _, _ = exported
    cam = doc["cameras"][0]["perspective"]
    # cam.angle is the field of view across the larger image side (sensor_fit AUTO)
    assert cam["aspectRatio"] == pytest.approx(128 / 96)
    yfov = 2 * math.atan(math.tan(math.radians(40.0) / 2) * 96 / 128)
    assert cam["yfov"] == pytest.approx(yfov, rel=1e-5)


# --------------------------------------------------------------------------------------------
# Cycles against closed-form values (top view of a Lambertian plane, albedo 0.8)


def test_cycles_point_light(tmp_path):
    x, y = ortho_plane_setup()
    power, h = 100.0, 2.0
    scenes.add_point_light("P", (0, 0, h), power)
    got = render_ortho(tmp_path)
    r2 = x * x + y * y + h * h
    intensity = power / (4 * math.pi)  # W/sr
    expected = pixel_mean(0.8 / math.pi * intensity * h / r2 ** 1.5)
    assert_ratio(got, expected, 0.005, "point light")


@pytest.mark.parametrize("blend", [0.0, 0.3, 1.0])
def test_cycles_spot_light(tmp_path, blend):
    x, y = ortho_plane_setup()
    power, h, size = 100.0, 2.0, math.radians(60.0)
    scenes.add_spot_light("S", (0, 0, h), (0, 0, 0), power, size, blend)
    got = render_ortho(tmp_path)
    r2 = x * x + y * y + h * h
    cos = h / np.sqrt(r2)
    cos_half = math.cos(size / 2)
    smooth = (1 - cos_half) * blend
    if smooth > 0:
        t = np.clip((cos - cos_half) / smooth, 0.0, 1.0)
        falloff = t * t * (3 - 2 * t)
    else:
        falloff = (cos > cos_half).astype(float)
    if not BLENDER_4:
        falloff = falloff * cos  # Cycles before 4.0 also multiplied by cos(angle to the axis)
    expected = pixel_mean(0.8 / math.pi * power / (4 * math.pi) * h / r2 ** 1.5 * falloff)
    assert_ratio(got, expected, 0.01, f"spot light blend {blend}")


@pytest.mark.parametrize("tilt_deg", [0.0, 60.0])
def test_cycles_sun_light(tmp_path, tilt_deg):
    ortho_plane_setup()
    strength = 3.0
    tilt = math.radians(tilt_deg)
    scenes.add_sun_light("Sun", (0, math.sin(tilt), -math.cos(tilt)), strength)
    got = render_ortho(tmp_path)
    expected = 0.8 / math.pi * strength * math.cos(tilt)
    if not BLENDER_4 and tilt_deg > 0:
        pytest.skip("Blender 3.x's Principled diffuse is not Lambertian (+3% at 60°)")
    assert got.mean() == pytest.approx(expected, rel=0.005)


def test_cycles_area_light(tmp_path):
    x, y = ortho_plane_setup()
    power, h, side = 100.0, 2.0, 1.0
    scenes.add_area_light("A", (0, 0, h), (0, 0, 0), power, side)
    got = render_ortho(tmp_path, spp=64)
    radiance = power / (math.pi * side * side)
    if not BLENDER_4:
        radiance *= math.pi / 4  # Cycles before 4.0: power / (4 area)
    n = 16
    u = (np.arange(n) + 0.5) / n * side - side / 2
    irradiance = np.zeros_like(x)
    for lx in u:
        for ly in u:
            r2 = (x - lx) ** 2 + (y - ly) ** 2 + h * h
            irradiance += radiance * h * h / (r2 * r2) * (side / n) ** 2
    assert_ratio(got, pixel_mean(0.8 / math.pi * irradiance), 0.01, "area light")


@pytest.mark.parametrize("side", ["front", "back"])
def test_cycles_emission_two_sided(tmp_path, side):
    scenes.clear_scene()
    color, strength = (1.0, 0.5, 0.25), 5.0
    scenes.add_quad("E", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.emitter("Glow", color, strength))
    z = 5.0 if side == "front" else -5.0
    scenes.add_camera((0.0, 0.0, z), (0.0, 0.0, 0.0), ortho_scale=4.0)
    scenes.configure_cycles(bpy.context.scene, SIZE, SIZE, 4, 0)
    img = imgcompare.read_exr(scenes.render_cycles(tmp_path / "emission.exr"))
    got = img[..., :3].reshape(-1, 3).mean(axis=0)
    assert got == pytest.approx([c * strength for c in color], rel=1e-4)


@pytest.mark.skipif(not BLENDER_4, reason="Principled v2 (Blender 4.0+) glass")
def test_cycles_glass_tint(tmp_path):
    """A closed slab tints by the base colour once; one open sheet by its square root."""
    info = scenes.glass_slab((0.5, 0.5, 0.5))
    scenes.configure_cycles(info.scene, 16, 16, 256, 16)
    img = imgcompare.read_exr(scenes.render_cycles(tmp_path / "slab.exr"))
    assert img[..., :3].mean(axis=(0, 1)) == pytest.approx(info.notes["transmitted"], rel=0.01)
    bpy.data.objects.remove(bpy.data.objects["Slab"], do_unlink=True)
    scenes.add_quad("Sheet", [(-2, -2, 1), (2, -2, 1), (2, 2, 1), (-2, 2, 1)],
                    scenes.glass("Sheet", 1.5, (0.5, 0.5, 0.5)))
    img = imgcompare.read_exr(scenes.render_cycles(tmp_path / "sheet.exr"))
    # one refraction: sqrt(0.5) * (1 - F), and no 1/eta^2 radiance scaling
    assert img[..., :3].mean() == pytest.approx(math.sqrt(0.5) * 0.96, rel=0.01)


# --------------------------------------------------------------------------------------------
# Tesela against Cycles

# (case id, builder, Cycles max_bounces, tesela integrator, spp[, (width, height)]).
# Tesela's --max-depth = max_bounces + 2.
CASES = [
    ("cornell-direct_mis", lambda: scenes.cornell_box(), 0, "direct_mis", 256),
    ("cornell-direct_ems", lambda: scenes.cornell_box(), 0, "direct_ems", 256),
    ("cornell-direct_mats", lambda: scenes.cornell_box(), 0, "direct_mats", 1024),
    ("cornell-path_mis", lambda: scenes.cornell_box(), 8, "path_mis", 1024),
    ("cornell-path_mats", lambda: scenes.cornell_box(), 8, "path_mats", 1024),
    ("cornell_spheres-path_mis", lambda: scenes.cornell_box(spheres=True), 8, "path_mis", 1024),
    ("point-direct_mis", lambda: scenes.light_over_plane("point"), 0, "direct_mis", 64),
    ("point-direct_mis-96x64", lambda: scenes.light_over_plane("point"), 0, "direct_mis", 64,
     (96, 64)),
    ("point-path_mis", lambda: scenes.light_over_plane("point"), 4, "path_mis", 256),
    ("spot-direct_mis", lambda: scenes.light_over_plane("spot"), 0, "direct_mis", 64),
    # Blender's exporter writes innerConeAngle = outer * (1 - blend); the KHR ramp over that range
    # is not Cycles' smoothstep (docs/blender-units.md): the renderer must recover the blend.
    ("spot_blend0.3-direct_mis", lambda: scenes.light_over_plane("spot", spot_blend=0.3), 0,
     "direct_mis", 64),
    ("spot_blend1-direct_mis", lambda: scenes.light_over_plane("spot", spot_blend=1.0), 0,
     "direct_mis", 64),
    ("sun-direct_mis", lambda: scenes.light_over_plane("sun"), 0, "direct_mis", 64),
    ("sun-path_mis", lambda: scenes.light_over_plane("sun"), 4, "path_mis", 256),
    ("emissive_sphere-direct_mis", lambda: scenes.emissive_sphere(), 0, "direct_mis", 256),
    ("emissive_sphere-path_mis", lambda: scenes.emissive_sphere(), 4, "path_mis", 512),
    # Tinted glass: Cycles tints each refraction by sqrt(base colour), a solid by the colour.
    ("glass_slab_tinted-path_mis", lambda: scenes.glass_slab((0.5, 0.5, 0.5)), 8, "path_mis", 64),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_agreement(tmp_path, tesela_bin, case):
    name, build, bounces, integrator, spp = case[:5]
    width, height = case[5] if len(case) > 5 else (SIZE, SIZE)
    info = build()
    gltf, ref = export_and_render_cycles(tmp_path, info, spp, bounces, width, height)
    got = run_tesela(tesela_bin, gltf, tmp_path / "tesela.exr", integrator, spp, bounces + 2,
                     width, height)
    result = imgcompare.compare(got, ref)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela vs Cycles: {result}"
