"""Blender light parameters through the add-on (F12 path) against Cycles on the same scene:
point and spot radius (soft falloff on, Blender's default, and off), spot blend, sun angle,
area spread, lights seen by the camera and in mirrors, per-light ray visibility, and a room lit
by a sun through a window with a camera-invisible area light in the way (lights never occlude).

Criteria: each channel's global mean within 2%, 8x8 block means within 5% at the 95th
percentile (imgcompare.compare), and shadow edges that agree locally (``edge_agreement``:
along the reference's strongest edges, the blurred images within 5% and the edge gradients
within 10% in the mean, so a penumbra of the wrong width or place fails). Needs the renderer
binary (conftest.py's ``tesela_bin``).
"""

import math
import os

import bpy
import numpy as np
import pytest

import imgcompare
import scenes
from test_addon import result_pixels

SIZE = 64


def _blur(lum):
    """3x3 box blur with edge replication."""
    p = np.pad(lum, 1, mode="edge")
    h, w = lum.shape
    return sum(p[i:i + h, j:j + w] for i in range(3) for j in range(3)) / 9.0


def edge_agreement(test, ref, fraction=0.12):
    """Compare the images along the reference's strongest edges (shadow boundaries,
    silhouettes): returns (median relative error of the blurred luminance there, ratio of the
    mean gradient magnitudes test/ref there)."""
    w = np.array([0.2126, 0.7152, 0.0722])
    t = _blur(np.asarray(test)[..., :3] @ w)
    r = _blur(np.asarray(ref)[..., :3] @ w)
    gy, gx = np.gradient(r)
    g_ref = np.hypot(gx, gy)
    ty, tx = np.gradient(t)
    g_test = np.hypot(tx, ty)
    mask = g_ref >= np.quantile(g_ref, 1.0 - fraction)
    floor = 0.05 * r.mean()
    err = np.abs(t - r)[mask] / np.maximum(r[mask], floor)
    return float(np.median(err)), float(g_test[mask].mean() / max(g_ref[mask].mean(), 1e-12))


def _plane_with_box():
    """A 6 m Lambertian plane (albedo 0.8) with a 0.6 m box at the origin, seen from close by,
    from the front and above, so that the box's shadows fill much of the frame."""
    scene = scenes.clear_scene()
    scenes.add_quad("Plane", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    scenes.add_box("Box", (-0.3, -0.3, 0.0), (0.3, 0.3, 0.6), scenes.lambert("BoxMat", (0.5, 0.6, 0.7)))
    scenes.add_camera((0.0, -2.6, 2.4), (0.0, 0.3, 0.0), fov=math.radians(55.0))
    return scenes.SceneInfo(scene, "box_stage")


def point_radius(soft):
    def build():
        info = _plane_with_box()
        # Behind the box as the camera sees it: the soft shadow falls towards the camera.
        ob = scenes.add_point_light("Point", (-0.2, 1.5, 1.5), 100.0, radius=0.35)
        ob.data.use_soft_falloff = soft
        return info
    return build


def spot_radius_blend():
    info = _plane_with_box()
    ob = scenes.add_spot_light("Spot", (0.2, -0.4, 2.2), (-0.3, 0.3, 0.0), 200.0,
                               math.radians(60.0), blend=0.4, radius=0.3)
    ob.data.use_soft_falloff = False
    return info


def spot_radius_soft():
    info = _plane_with_box()
    scenes.add_spot_light("Spot", (0.2, -0.4, 2.2), (-0.3, 0.3, 0.0), 200.0,
                          math.radians(45.0), blend=0.15, radius=0.2)
    return info


def spot_scaled(scale, radius=0.0):
    """A spot whose object is scaled: Cycles takes the cone's angle in the light's unscaled
    space, so an uneven scale across the beam makes the cone elliptic, and a scale along the
    beam narrows or widens it."""
    def build():
        info = _plane_with_box()
        ob = scenes.add_spot_light("Spot", (0.2, -0.4, 2.2), (-0.3, 0.3, 0.0), 200.0,
                                   math.radians(50.0), blend=0.2, radius=radius)
        ob.scale = scale
        return info
    return build


def light_nodes():
    """Lights with node trees: a spot whose Emission is coloured and scaled, and a point light
    whose strength comes through Light Falloff's Quadratic output."""
    info = _plane_with_box()
    spot = scenes.add_spot_light("Spot", (0.2, -0.4, 2.2), (-0.3, 0.3, 0.0), 120.0,
                                 math.radians(60.0), blend=0.3, radius=0.1)
    spot.data.use_nodes = True
    em = next(n for n in spot.data.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
    em.inputs["Color"].default_value = (1.0, 0.55, 0.25, 1.0)
    em.inputs["Strength"].default_value = 1.8
    pt = scenes.add_point_light("Point", (-0.8, 1.2, 1.2), 40.0, radius=0.1)
    pt.data.use_nodes = True
    nt = pt.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    em.inputs["Color"].default_value = (0.3, 0.6, 1.0, 1.0)
    falloff = nt.nodes.new("ShaderNodeLightFalloff")
    falloff.inputs["Strength"].default_value = 2.5
    nt.links.new(falloff.outputs["Quadratic"], em.inputs["Strength"])
    return info


def light_nodes_evaluated():
    """Light node trees only the renderer can reduce: a spot coloured by a Blackbody node
    (3200 K) into its Emission, and an area light whose Emission colour is an RGB node times a
    Math node's strength, through a reroute (constant trees: Cycles multiplies the light's
    strength by what they emit)."""
    info = _plane_with_box()
    spot = scenes.add_spot_light("Warm", (0.2, -0.4, 2.2), (-0.3, 0.3, 0.0), 150.0,
                                 math.radians(60.0), blend=0.3, radius=0.1)
    spot.data.use_nodes = True
    nt = spot.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    bb = nt.nodes.new("ShaderNodeBlackbody")
    bb.inputs["Temperature"].default_value = 3200.0
    nt.links.new(bb.outputs["Color"], em.inputs["Color"])
    area = scenes.add_area_light("Cool", (-0.8, 1.0, 1.6), (0.0, 0.0, 0.0), 60.0, 0.6)
    area.data.use_nodes = True
    nt = area.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    rgb = nt.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.2, 0.5, 1.0, 1.0)
    reroute = nt.nodes.new("NodeReroute")
    nt.links.new(rgb.outputs[0], reroute.inputs[0])
    nt.links.new(reroute.outputs[0], em.inputs["Color"])
    math_node = nt.nodes.new("ShaderNodeMath")
    math_node.operation = "MULTIPLY"
    math_node.inputs[0].default_value, math_node.inputs[1].default_value = 1.5, 2.0
    nt.links.new(math_node.outputs[0], em.inputs["Strength"])
    return info


def sun_angle():
    """A 25° sun whose soft shadow of the box falls towards the camera."""
    info = scenes.light_over_plane("sun", sun_strength=3.0)
    bpy.data.lights["Sun"].angle = math.radians(25.0)
    scenes._aim(bpy.data.objects["Sun"], direction=(0.5, -0.6, -1.0))
    return info


def _mirror_stage():
    """A mirror floor and a diffuse back wall, seen from the front, slightly from above."""
    scene = scenes.clear_scene()
    scenes.add_quad("Mirror", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.mirror("Chrome", (0.9, 0.9, 0.9)))
    scenes.add_quad("Wall", [(-3, 2, 0), (3, 2, 0), (3, 2, 3), (-3, 2, 3)],
                    scenes.lambert("Wall", (0.6, 0.6, 0.6)))
    scenes.add_camera((0.0, -3.0, 1.2), (0.0, 0.5, 0.6), fov=math.radians(45.0))
    return scenes.SceneInfo(scene, "mirror_stage")


def lights_seen_in_a_mirror():
    """A sphere light and a soft-falloff point light in view and reflected by the mirror floor,
    and a rectangular area light facing the camera."""
    info = _mirror_stage()
    a = scenes.add_point_light("Ball", (-0.8, 0.5, 0.7), 40.0, radius=0.25)
    a.data.use_soft_falloff = False
    a.visible_camera = True
    b = scenes.add_point_light("Disk", (0.7, 0.3, 1.0), 30.0, radius=0.18)
    b.visible_camera = True
    c = scenes.add_area_light("Panel", (0.0, 1.2, 1.6), (0.0, -3.0, 1.2), 60.0, 0.5)
    c.data.shape = "RECTANGLE"
    c.data.size_y = 0.25
    c.visible_camera = True
    return info


def sun_in_a_mirror():
    """A camera looking at the horizon over a mirror floor: a 10° sun 15° above the horizon in
    front of it, seen directly (visible to the camera) and reflected, and a diffuse box it lights."""
    scene = scenes.clear_scene()
    scenes.add_quad("Mirror", [(-6, -6, 0), (6, -6, 0), (6, 6, 0), (-6, 6, 0)],
                    scenes.mirror("Chrome", (0.9, 0.9, 0.9)))
    scenes.add_box("Box", (-1.2, -0.5, 0.0), (-0.6, 0.1, 0.6), scenes.lambert("Box", (0.6, 0.5, 0.4)))
    scenes.add_camera((0.0, -3.0, 0.6), (0.0, 0.0, 0.6), fov=math.radians(60.0))
    e = math.radians(15.0)
    ob = scenes.add_sun_light("Sun", (0.0, -math.cos(e), -math.sin(e)), 2.0,
                              angle=math.radians(10.0))
    ob.visible_camera = True
    return scenes.SceneInfo(scene, "sun_in_a_mirror")


def area_spread(shape, spread_deg):
    def build():
        info = _plane_with_box()
        ob = scenes.add_area_light("Area", (0.3, -0.2, 1.5), (0.1, 0.1, 0.0), 150.0, 0.9)
        ob.data.shape = shape
        if shape in ("RECTANGLE", "ELLIPSE"):
            ob.data.size_y = 0.5
        ob.data.spread = math.radians(spread_deg)
        return info
    return build


def visibility_flags():
    """A glossy sphere and a diffuse box: a point light excluded from diffuse closures, an area
    light excluded from glossy ones, and a sphere light that casts no shadow."""
    info = _plane_with_box()
    scenes.add_sphere("Ball", (0.7, 0.4, 0.5), 0.5,
                      scenes.material("Gloss", (0.8, 0.8, 0.8), metallic=1.0, roughness=0.25))
    p = scenes.add_point_light("NoDiffuse", (1.2, -1.0, 1.8), 80.0, radius=0.1)
    p.visible_diffuse = False
    a = scenes.add_area_light("NoGlossy", (-0.5, -0.8, 2.0), (0.0, 0.0, 0.0), 120.0, 0.8)
    a.visible_glossy = False
    s = scenes.add_point_light("NoShadow", (-0.6, 0.5, 1.3), 30.0, radius=0.15)
    s.data.use_shadow = False
    return info


def sunlit_room():
    """A closed 4 x 4 x 2.6 m room with a window in the -y wall: a sun shines through it onto the
    floor, and a camera-invisible area light hangs in the sunbeam facing down. Lights do not
    occlude, so the sun's patch on the floor has no dark blotch under the area light."""
    scene = scenes.clear_scene()
    white = scenes.lambert("White", (0.7, 0.7, 0.7))
    # A 1.4 x 1 m window from z = 1.0 to 2.0.
    scenes.add_room(white, white)
    scenes.add_sun_light("Sun", (0.0, 1.0, -0.8), 6.0, angle=math.radians(3.0))
    a = scenes.add_area_light("Fill", (0.0, -0.9, 0.9), (0.0, -0.9, 0.0), 40.0, 0.6)
    a.visible_camera = False
    scenes.add_camera((1.6, 1.7, 1.8), (-0.2, -0.8, 0.3), fov=math.radians(70.0))
    return scenes.SceneInfo(scene, "sunlit_room")


def negative_lights():
    """Lights of negative strength take light away (Cycles renders them so): a point light of
    -60 W with a radius darkens the box's left side, a -40 W area light a patch of the floor,
    both against a 400 W point light; the negative sphere is seen by the camera. A renderer
    that skips or clamps them is 10-30% too bright."""
    info = _plane_with_box()
    scenes.add_point_light("Key", (0.8, -0.5, 1.6), 400.0, radius=0.1)
    scenes.add_point_light("Darken", (-0.7, -0.3, 0.9), -60.0, radius=0.1)
    scenes.add_area_light("DarkPatch", (0.9, 0.9, 1.2), (0.9, 0.9, 0.0), -40.0, 0.5)
    return info


def negative_emission():
    """An Emission shader of strength -3 on a sphere beside the box (Blender clamps colours at
    0, not strengths): a surface that takes light away from what it would light, as in Cycles,
    and shows negative radiance itself. A Principled BSDF's negative Emission Strength typed
    in emits nothing in Cycles (its emission is on only above a small positive strength): the
    black ball beside the box stays black."""
    info = _plane_with_box()
    scenes.add_point_light("Key", (0.8, -0.5, 1.6), 400.0, radius=0.1)
    sink, _, e = scenes.shader_only("Sink", "ShaderNodeEmission")
    e.inputs["Color"].default_value = (1.0, 0.8, 0.6, 1.0)
    e.inputs["Strength"].default_value = -3.0
    scenes.add_sphere("Sink", (-0.8, 0.3, 0.4), 0.3, sink)
    scenes.add_sphere("Off", (0.75, 0.55, 0.3), 0.25, scenes.emitter("Off", (1.0, 1.0, 1.0), -3.0))
    return info


# (id, builder, Cycles max_bounces, Tesela integrator, spp)
CASES = [
    ("point_radius_soft", point_radius(True), 0, "direct_mis", 512),
    ("point_radius_sphere", point_radius(False), 0, "direct_mis", 512),
    ("spot_radius_blend_sphere", spot_radius_blend, 0, "direct_mis", 512),
    ("spot_radius_soft", spot_radius_soft, 0, "direct_mis", 512),
    ("spot_scaled_elliptic", spot_scaled((2.0, 0.7, 1.0)), 0, "direct_mis", 256),
    ("spot_scaled_along_beam", spot_scaled((1.5, 1.5, 0.8), radius=0.1), 0, "direct_mis", 512),
    ("sun_angle", sun_angle, 0, "direct_mis", 512),
    ("light_node_trees", light_nodes, 0, "direct_mis", 512),
    ("light_node_trees_evaluated", light_nodes_evaluated, 0, "direct_mis", 512),
    ("lights_in_a_mirror", lights_seen_in_a_mirror, 1, "path_mis", 512),
    ("sun_in_a_mirror", sun_in_a_mirror, 1, "path_mis", 256),
    ("area_square_spread60", area_spread("SQUARE", 60.0), 0, "direct_mis", 512),
    ("area_rectangle_spread25", area_spread("RECTANGLE", 25.0), 0, "direct_mis", 512),
    ("area_disk_spread90", area_spread("DISK", 90.0), 0, "direct_mis", 512),
    ("area_square_spread0", area_spread("SQUARE", 0.0), 0, "direct_mis", 64),
    ("visibility_flags", visibility_flags, 1, "path_mis", 1024),
    ("sunlit_room", sunlit_room, 2, "path_mis", 1024),
    ("negative_lights", negative_lights, 2, "path_mis", 1024),
    ("negative_emission", negative_emission, 2, "path_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_light_parameters_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)


def agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case):
    """Renders case (id, builder, Cycles max_bounces, Tesela integrator, spp) with Cycles and
    through the add-on, and asserts they agree: means and 8x8 blocks, edges locally."""
    name, build, bounces, integrator, spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = build()
    scene = info.scene
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    volume_bounces = info.notes.get("volume_bounces")  # else configure_cycles' 0
    if volume_bounces is not None:
        scene.cycles.volume_bounces = volume_bounces
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))

    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = integrator, spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    if volume_bounces is not None:
        t.volume_bounces = volume_bounces
    assert bpy.ops.render.render() == {"FINISHED"}
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    edge_err, grad_ratio = edge_agreement(got, ref)
    print(f"{name}: {result}; edges: blurred median err {edge_err:.4f}, "
          f"gradient ratio {grad_ratio:.4f}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
    assert edge_err <= 0.05, f"{name}: edges differ locally: median error {edge_err:.4f}"
    assert abs(grad_ratio - 1.0) <= 0.10, f"{name}: edge gradients differ: ratio {grad_ratio:.4f}"


def test_light_fields_are_exported(addon, tmp_path):  # noqa: F811
    """TESELA_light carries every light parameter and the object's ray visibility."""
    import json

    scenes.clear_scene()
    p = scenes.add_point_light("Ball", (0, 0, 1), 10.0, radius=0.2)
    p.data.use_soft_falloff = False
    p.data.use_shadow = False
    p.visible_glossy = False
    p.visible_camera = True
    a = scenes.add_area_light("Panel", (0, 0, 2), (0, 0, 0), 20.0, 0.5)
    a.data.spread = math.radians(40.0)
    a.visible_diffuse = False
    a.data.cycles.use_multiple_importance_sampling = False
    s = scenes.add_sun_light("Sun", (0, 0, -1), 2.0, angle=math.radians(5.0))
    s.visible_transmission = False
    path = tmp_path / "l.gltf"
    assert bpy.ops.export_scene.tesela_gltf(filepath=str(path)) == {"FINISHED"}
    doc = json.loads(path.read_text(encoding="utf-8"))
    lights = {n["name"]: n["extensions"]["TESELA_light"] for n in doc["nodes"]
              if "TESELA_light" in n.get("extensions", {})}
    ball, panel, sun = lights["Ball"], lights["Panel"], lights["Sun"]
    assert ball["radius"] == pytest.approx(0.2) and ball["soft_falloff"] is False
    assert ball["cast_shadow"] is False and ball["visible_glossy"] is False
    assert ball["visible_camera"] is True and ball["visible_diffuse"] is True
    assert panel["spread"] == pytest.approx(math.radians(40.0))
    assert panel["visible_diffuse"] is False and panel["multiple_importance"] is False
    assert panel["cast_shadow"] is True and panel["visible_camera"] is False
    assert sun["angle"] == pytest.approx(math.radians(5.0)) and sun["visible_transmission"] is False


def test_light_node_trees_are_read_or_reported(addon, tesela_bin, tmp_path):  # noqa: F811
    """A light's Emission Color x Strength scales its colour; a tree the add-on cannot reduce
    travels as a graph, and what the renderer cannot evaluate either (a texture: it varies over
    the light) is reported by the renderer, naming the light and the node."""
    import json
    import subprocess

    from blender_addon import export

    scenes.clear_scene()
    ob = scenes.add_point_light("Lamp", (0, 0, 1), 10.0, radius=0.1)
    ob.data.color = (1.0, 1.0, 0.5)
    ob.data.use_nodes = True
    nt = ob.data.node_tree
    em = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeEmission")
    em.inputs["Color"].default_value = (0.5, 1.0, 1.0, 1.0)
    em.inputs["Strength"].default_value = 3.0
    tex = nt.nodes.new("ShaderNodeTexNoise")
    nt.links.new(tex.outputs["Fac"], em.inputs["Strength"])
    dg = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "l.gltf"
    res = export.write_gltf(dg, str(path), width=8, height=8)
    doc = json.loads(path.read_text(encoding="utf-8"))
    light = next(n["extensions"]["TESELA_light"] for n in doc["nodes"] if n["name"] == "Lamp")
    assert light["color"] == pytest.approx([1.5, 3.0, 1.5])
    assert light["base_color"] == pytest.approx([1.0, 1.0, 0.5]) and light["graph"]["surface"]
    assert any("light 'Lamp'" in w and tex.name in w for w in light["node_warnings"]), light
    assert not any(tex.name in w for w in res.warnings), "the renderer decides, and reports"
    run = subprocess.run([str(tesela_bin), "render", str(path), "-o", str(tmp_path / "l.exr"),
                          "--spp", "1"], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "light 'Lamp'" in run.stderr and tex.name in run.stderr, run.stderr


def test_portals_are_left_out_motion_blur_reported_and_light_linking_exported(addon, tmp_path):  # noqa: F811
    """A Cycles portal only guides world sampling: it is not exported as a light (it would
    emit), and says so; motion blur, which Tesela does not render, is reported; light linking
    travels as TESELA_light_linking (the emitter names its collection, the member its state)."""
    import json

    from blender_addon import export

    scenes.clear_scene()
    portal = scenes.add_area_light("Window", (0, -2, 1.5), (0, 0, 1.5), 10.0, 1.0)
    portal.data.cycles.is_portal = True
    lamp = scenes.add_point_light("Lamp", (0, 0, 1), 10.0)
    box = scenes.add_box("Box", (-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), scenes.lambert("W", (0.8,) * 3))
    if hasattr(lamp, "light_linking"):
        coll = bpy.data.collections.new("Lit")
        coll.objects.link(box)
        lamp.light_linking.receiver_collection = coll
    bpy.context.scene.render.use_motion_blur = True
    try:
        dg = bpy.context.evaluated_depsgraph_get()
        path = tmp_path / "p.gltf"
        res = export.write_gltf(dg, str(path), width=8, height=8)
    finally:
        bpy.context.scene.render.use_motion_blur = False
    doc = json.loads(path.read_text(encoding="utf-8"))
    lights = [n["name"] for n in doc["nodes"] if "TESELA_light" in n.get("extensions", {})]
    assert lights == ["Lamp"]
    assert any("light 'Window' is a portal" in w for w in res.warnings), res.warnings
    assert any("motion blur is not rendered" in w for w in res.warnings), res.warnings
    if hasattr(lamp, "light_linking"):
        assert not any("light linking" in w for w in res.warnings), res.warnings
        ext = {n["name"]: n.get("extensions", {}).get("TESELA_light_linking")
               for n in doc["nodes"]}
        assert ext["Lamp"] == {"receivers": 0}, ext
        assert ext["Box"] == {"links": [[0, "INCLUDE"]]}, ext


def test_a_lights_own_max_bounces_is_reported(addon, tmp_path):  # noqa: F811
    """Cycles' per-light Max Bounces has no counterpart in Tesela: a light that changes it is
    reported, naming the light; one at the default (1024) is not."""
    from blender_addon import export
    scenes.clear_scene()
    limited = scenes.add_point_light("Limited", (0, 0, 2), 100.0)
    limited.data.cycles.max_bounces = 3
    scenes.add_point_light("Plain", (1, 0, 2), 100.0)
    scenes.add_camera((0, -5, 1), (0, 0, 0))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    res = export.write_gltf(depsgraph, str(tmp_path / "b.gltf"), width=8, height=8)
    about = [w for w in res.warnings if "Max Bounces" in w]
    assert len(about) == 1 and "'Limited'" in about[0] and "(3)" in about[0], res.warnings


def test_export_warnings_reach_blenders_reports(addon, tesela_bin, tmp_path, monkeypatch,  # noqa: F811
                                                capfd):
    """What the export leaves out besides materials (here a portal light) is shown in
    Blender's reports of the render (which Blender prints as "Warning: ..." without a window),
    not only printed to the console."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = scenes.light_over_plane("point")
    portal = scenes.add_area_light("Window", (0, -2, 1.5), (0, 0, 1.5), 10.0, 1.0)
    portal.data.cycles.is_portal = True
    scene = info.scene
    scenes.configure_cycles(scene, 16, 16, 4, 0, seed=1)
    scene.render.engine = "TESELA"
    scene.tesela.samples = 4
    capfd.readouterr()
    assert bpy.ops.render.render() == {"FINISHED"}
    out = capfd.readouterr().out
    assert "Warning: Tesela: light 'Window' is a portal" in out, out


@pytest.mark.skipif("use_adaptive_subdivision" not in bpy.types.SubsurfModifier.bl_rna.properties,
                    reason="Adaptive Subdivision is a modifier setting from Blender 5.0")
def test_adaptive_subdivision_is_reported(addon, tmp_path):  # noqa: F811
    """Cycles dices a mesh whose last modifier is an adaptive Subdivision Surface; Tesela
    renders the evaluated mesh and says so, naming the object (once)."""
    from blender_addon import export

    scenes.clear_scene()
    rock = scenes.add_box("Rock", (-0.5, -0.5, 0.0), (0.5, 0.5, 1.0),
                          scenes.lambert("R", (0.8,) * 3))
    plain = scenes.add_box("Plain", (1.0, -0.5, 0.0), (2.0, 0.5, 1.0),
                           scenes.lambert("P", (0.8,) * 3))
    rock.modifiers.new("Subdivision", "SUBSURF").use_adaptive_subdivision = True
    plain.modifiers.new("Subdivision", "SUBSURF")
    res = export.write_gltf(bpy.context.evaluated_depsgraph_get(), str(tmp_path / "a.gltf"),
                            width=8, height=8)
    said = [w for w in res.warnings if "adaptive subdivision" in w]
    assert len(said) == 1 and "'Rock'" in said[0], res.warnings
