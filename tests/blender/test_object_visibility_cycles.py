"""Object > Visibility > Ray Visibility against Cycles (PyPI bpy 5.x): objects hidden from the
camera, from shadow rays, from diffuse, glossy or transmission rays, and Indirect Only
collections, through the add-on."""

import json
import math

import bpy
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles


def _stage(floor_mat):
    """A 6 m floor (material `floor_mat()`) and a back wall under a sun from the front left and
    a dim grey world."""
    scenes.clear_scene()
    floor_mat = floor_mat()
    wall = scenes.lambert("Wall", (0.7, 0.7, 0.7))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor_mat)
    scenes.add_quad("Back", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], wall)
    scenes.add_sun_light("Sun", (0.5, 0.6, -0.7), 3.0)
    world = bpy.context.scene.world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scenes.add_camera((0.0, -4.0, 2.2), (0.0, 0.3, 0.5), fov=math.radians(50.0))


def camera_and_shadow():
    """A red ball hidden from the camera (its shadow and red bounce light stay), a green box that
    casts no shadow (seen, lit, no shadow), and a panel hidden from the camera that lights the
    wall."""
    _stage(lambda: scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    ball = scenes.add_sphere("Ball", (-0.8, 0.0, 0.5), 0.5, scenes.lambert("Red", (0.8, 0.1, 0.1)))
    ball.visible_camera = False
    box = scenes.add_box("Box", (0.3, -0.4, 0.0), (1.1, 0.4, 0.8),
                         scenes.lambert("Green", (0.1, 0.7, 0.2)))
    box.visible_shadow = False
    panel = scenes.add_quad("Panel", [(-0.4, 1.0, 2.4), (0.4, 1.0, 2.4), (0.4, 1.0, 1.8),
                                      (-0.4, 1.0, 1.8)],
                            scenes.emitter("Glow", (1.0, 0.8, 0.5), 6.0))
    panel.visible_camera = False
    return scenes.SceneInfo(bpy.context.scene, "camera_and_shadow")


def glossy_and_diffuse():
    """A glossy metal floor (roughness 0.3: sharper, the sun's caustics on the wall would need
    thousands of samples to agree): a yellow ball hidden from glossy rays is seen but not mirrored in
    it; a blue ball hidden from diffuse rays is mirrored, but sheds no blue light on the white
    wall beside it."""
    _stage(lambda: scenes.material("Metal", base_color=(0.9, 0.9, 0.9), metallic=1.0,
                                   roughness=0.3))
    yellow = scenes.add_sphere("Yellow", (-0.8, 0.0, 0.5), 0.5,
                               scenes.lambert("Yellow", (0.8, 0.7, 0.1)))
    yellow.visible_glossy = False
    blue = scenes.add_sphere("Blue", (0.9, 1.0, 0.5), 0.5, scenes.lambert("Blue", (0.1, 0.2, 0.9)))
    blue.visible_diffuse = False
    return scenes.SceneInfo(bpy.context.scene, "glossy_and_diffuse")


def transmission():
    """A glass ball in front of two balls, one hidden from transmission rays: it is seen beside
    the glass and in no refraction through it."""
    _stage(lambda: scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    scenes.add_sphere("Lens", (-0.2, -1.6, 0.9), 0.7, scenes.glass("Glass", ior=1.45))
    a = scenes.add_sphere("Hidden", (-0.5, 0.2, 0.5), 0.5, scenes.lambert("Red", (0.8, 0.1, 0.1)))
    a.visible_transmission = False
    scenes.add_sphere("Seen", (0.7, 0.2, 0.5), 0.5, scenes.lambert("Green", (0.1, 0.7, 0.2)))
    return scenes.SceneInfo(bpy.context.scene, "transmission")


def indirect_only():
    """A red ball and a large white card in a View Layer > Indirect Only collection: the
    camera sees neither (the back wall shows through the card), their shadows and the light
    they bounce stay."""
    _stage(lambda: scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    ball = scenes.add_sphere("Ball", (-0.8, 0.0, 0.5), 0.5, scenes.lambert("Red", (0.8, 0.1, 0.1)))
    card = scenes.add_quad("Card", [(0.2, -0.6, 0.0), (1.4, 0.2, 0.0), (1.4, 0.2, 1.6),
                                    (0.2, -0.6, 1.6)], scenes.lambert("White", (0.9, 0.9, 0.9)))
    coll = bpy.data.collections.new("Indirect")
    bpy.context.scene.collection.children.link(coll)
    for ob in (ball, card):
        for c in list(ob.users_collection):
            c.objects.unlink(ob)
        coll.objects.link(ob)
    bpy.context.view_layer.layer_collection.children["Indirect"].indirect_only = True
    return scenes.SceneInfo(bpy.context.scene, "indirect_only")


CASES = [
    ("camera_and_shadow", camera_and_shadow, 2, "path_mis", 512),
    ("indirect_only", indirect_only, 2, "path_mis", 512),
    ("glossy_and_diffuse", glossy_and_diffuse, 2, "path_mis", 512),
    ("transmission", transmission, 4, "path_mis", 512),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_ray_visibility_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)


def test_ray_visibility_is_exported_and_instances_inherit_it(addon, tmp_path):  # noqa: F811
    """tesela_object.visibility lists the kinds an object is hidden from; an instance of a
    collection is hidden from what its instancer is hidden from, and visible objects carry
    nothing."""
    scenes.clear_scene()
    ball = scenes.add_sphere("Ball", (0, 0, 0), 0.5, segments=8, rings=4)
    ball.visible_glossy = False
    scenes.add_sphere("Plain", (2, 0, 0), 0.5, segments=8, rings=4)
    coll = bpy.data.collections.new("Rocks")
    rock = scenes.add_sphere("Rock", (0, 0, 0), 0.3, segments=8, rings=4)
    for c in list(rock.users_collection):
        c.objects.unlink(rock)
    coll.objects.link(rock)
    empty = bpy.data.objects.new("Scatter", None)
    empty.instance_type, empty.instance_collection = "COLLECTION", coll
    empty.location = (0, 3, 0)
    empty.visible_shadow = False
    bpy.context.scene.collection.objects.link(empty)
    scenes.add_camera((0, -6, 1), (0, 0, 0))
    path = tmp_path / "v.gltf"
    from blender_addon import export
    res = export.write_gltf(bpy.context.evaluated_depsgraph_get(), str(path), width=8, height=8)
    doc = json.loads(path.read_text(encoding="utf-8"))
    vis = {}
    for n in doc["nodes"]:
        obj = n.get("extras", {}).get("tesela_object")
        if obj is not None:
            vis[n["name"]] = obj.get("visibility")
    assert vis["Ball"] == {"camera": True, "diffuse": True, "glossy": False,
                           "transmission": True, "shadow": True}
    assert vis["Plain"] is None
    rocks = [v for name, v in vis.items() if name.startswith("Rock")]
    assert rocks and all(v is not None and v["shadow"] is False and v["camera"] is True
                         for v in rocks), vis
