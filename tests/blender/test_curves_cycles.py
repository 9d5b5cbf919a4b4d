"""Curves objects (Blender's hair system: hair, fur, grass) through the add-on against Cycles:
round tubes through the control points (Catmull-Rom, or straight for poly curves), their radii
from the radius attribute, shaded by the object's material with Hair Info. Criteria as the other
Cycles tests: means within 2%, 8x8 blocks within 5% at the 95th percentile, edges locally."""

import math
import os

import bpy
import numpy as np
import pytest

import imgcompare
import scenes
from test_addon import result_pixels
from test_lights_cycles import edge_agreement

SIZE = 64


def strands(n, keys, radius, mat, poly=False, seed=1, spread=1.2, height=1.2, radii=True):
    """`n` wavy strands of `keys` control points rising from the floor, their radius tapering
    from `radius` to half of it (or no radius attribute: Cycles' default 0.005)."""
    rng = np.random.default_rng(seed)
    cv = bpy.data.hair_curves.new("Strands")
    cv.add_curves([keys] * n)
    pts = []
    for c in range(n):
        x0, y0 = rng.uniform(-spread, spread), rng.uniform(-0.7 * spread, 0.7 * spread)
        phase = rng.uniform(0.0, 6.0)
        for k in range(keys):
            t = k / (keys - 1)
            pts.append((x0 + 0.5 * t * math.sin(2.5 * t + phase),
                        y0 + 0.3 * t * math.cos(3.0 * t + phase), 0.02 + height * t))
    cv.position_data.foreach_set("vector", np.array(pts, np.float32).ravel())
    if radii:
        r = cv.attributes.new("radius", "FLOAT", "POINT")
        taper = [radius * (1.0 - 0.5 * (i % keys) / (keys - 1)) for i in range(n * keys)]
        r.data.foreach_set("value", np.array(taper, np.float32))
    if poly:
        cv.set_types(type="POLY")
    ob = bpy.data.objects.new("Strands", cv)
    bpy.context.scene.collection.objects.link(ob)
    cv.materials.append(mat)
    return ob


def hair_info_material():
    """A Principled BSDF coloured by Hair Info: red from Intercept, green from Random, blue
    from Thickness."""
    mat = scenes.material("HairInfo", roughness=0.4)
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    info = nt.nodes.new("ShaderNodeHairInfo")
    rgb = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(info.outputs["Intercept"], rgb.inputs[0])
    nt.links.new(info.outputs["Random"], rgb.inputs[1])
    thick = nt.nodes.new("ShaderNodeMath")
    thick.operation = "MULTIPLY"
    thick.inputs[1].default_value = 8.0
    nt.links.new(info.outputs["Thickness"], thick.inputs[0])
    nt.links.new(thick.outputs[0], rgb.inputs[2])
    nt.links.new(rgb.outputs[0], bsdf.inputs["Base Color"])
    return mat


def stage(build):
    def scene():
        scenes.clear_scene()
        scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                        scenes.lambert("Floor", (0.5, 0.5, 0.5)))
        build()
        scenes.add_sun_light("Sun", (-0.3, 0.4, -1.0), 3.0, angle=math.radians(5.0))
        bg = bpy.context.scene.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (0.3, 0.32, 0.35, 1.0)
        bg.inputs["Strength"].default_value = 1.0
        scenes.add_camera((0.0, -4.0, 2.2), (0.0, 0.0, 0.6), fov=math.radians(45.0))
        return bpy.context.scene
    return scene


def particle_hair(children=False):
    """A plane growing hair particles drawn as paths (Cycles renders them as strands): thick
    parents, or thinner interpolated children with some roughness; radius from root 1 to
    tip 0.3 (times the scale), its shape curved, the tip closed."""
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.2, 0.02))
    host = bpy.context.active_object
    host.data.materials.append(scenes.lambert("Skin", (0.3, 0.3, 0.3)))
    host.data.materials.append(glossy())
    ps = host.modifiers.new("Hair", "PARTICLE_SYSTEM").particle_system
    ps.seed = 2
    st = ps.settings
    st.type = "HAIR"
    st.count = 40
    st.hair_length = 0.8
    st.material = 2
    st.root_radius, st.tip_radius, st.radius_scale, st.shape = 1.0, 0.3, 0.04, -0.3
    st.use_close_tip = True
    st.roughness_1 = 0.3
    if children:
        st.child_type = "INTERPOLATED"
        st.child_percent = 4
        st.rendered_child_count = 4
        st.radius_scale = 0.015
        st.roughness_endpoint = 0.2
    return host


def principled_hair(parametrization="COLOR", **inputs):
    """A Principled Hair BSDF (Chiang) with `parametrization` and the given inputs."""
    mat = bpy.data.materials.new("Hair" + parametrization.title())
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    hair = nt.nodes.new("ShaderNodeBsdfHairPrincipled")
    hair.model = "CHIANG"
    hair.parametrization = parametrization
    for name, value in inputs.items():
        hair.inputs[name].default_value = value
    nt.links.new(hair.outputs[0], out.inputs["Surface"])
    return mat


def glossy():
    return scenes.material("Strand", (0.8, 0.25, 0.1), roughness=0.4)


CASES = [
    ("catmull_rom", stage(lambda: strands(12, 5, 0.04, glossy()))),
    ("poly", stage(lambda: strands(12, 5, 0.04, glossy(), poly=True))),
    ("hair_info", stage(lambda: strands(12, 5, 0.04, hair_info_material()))),
    # Known gap: Tesela's Principled Hair is 3.5% darker (direct colouring) and up to 2.7%
    # bluer (melanin), block p95 0.12-0.13, not yet explained (the tilt is not the cause).
    pytest.param("principled_hair_color", stage(lambda: strands(30, 6, 0.03, principled_hair(
        "COLOR", Color=(0.6, 0.35, 0.2, 1.0), Roughness=0.25))),
        marks=pytest.mark.xfail(reason="Principled Hair: 3.5% darker than Cycles")),
    pytest.param("principled_hair_melanin", stage(lambda: strands(30, 6, 0.03, principled_hair(
        "MELANIN", Melanin=0.4, **{"Melanin Redness": 0.6, "Random Color": 0.5,
                                   "Random Roughness": 0.4, "Coat": 0.3}))),
        marks=pytest.mark.xfail(reason="Principled Hair: up to 2.7% bluer than Cycles")),
    ("principled_hair_absorption", stage(lambda: strands(30, 6, 0.03, principled_hair(
        "ABSORPTION", **{"Absorption Coefficient": (0.3, 0.8, 2.0),
                         "Radial Roughness": 0.6})))),
    ("particle_hair", stage(lambda: particle_hair())),
    ("particle_hair_children", stage(lambda: particle_hair(children=True))),
    # Fur: many thin strands, no radius attribute (Cycles' default radius 0.005).
    ("fur_default_radius", stage(lambda: strands(400, 6, 0.0, glossy(), seed=4, spread=0.9,
                                                 height=0.5, radii=False))),
]


@pytest.mark.parametrize("name, build", CASES, ids=[
    c.values[0] if hasattr(c, "marks") else c[0] for c in CASES])
def test_curves_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, name, build):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = build()
    scenes.configure_cycles(scene, SIZE, SIZE, 256, 4, seed=7)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", 256, 6, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    edge_err, grad_ratio = edge_agreement(got, ref)
    print(f"curves {name}: {result}; edges {edge_err:.4f}, gradient ratio {grad_ratio:.4f}")
    assert result.ok, f"curves {name}: Tesela (add-on) vs Cycles: {result}"
    assert edge_err <= 0.05 and abs(grad_ratio - 1.0) <= 0.10, (edge_err, grad_ratio)
