"""Light and shadow linking (Blender 4.0+, Object > Shading > Light Linking) through the
add-on against Cycles: lights and emissive meshes that light only the objects their receiver
collection includes (or all but those it excludes), and a blocker collection that picks which
objects cast a light's shadows. Criteria as test_lights_cycles.py (means within 2%, 8x8 block
p95 within 5%, edges locally)."""

import math

import bpy
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles

pytestmark = pytest.mark.skipif(bpy.app.version < (4, 0, 0),
                                reason="light linking needs Blender 4.0+")


def _stage():
    """A Lambertian floor with two boxes, seen from the front and above."""
    scene = scenes.clear_scene()
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("FloorMat", (0.8, 0.8, 0.8)))
    left = scenes.add_box("Left", (-0.8, -0.3, 0.0), (-0.2, 0.3, 0.6),
                          scenes.lambert("LeftMat", (0.7, 0.5, 0.4)))
    right = scenes.add_box("Right", (0.2, -0.3, 0.0), (0.8, 0.3, 0.6),
                           scenes.lambert("RightMat", (0.4, 0.6, 0.7)))
    scenes.add_camera((0.0, -2.8, 2.4), (0.0, 0.3, 0.0), fov=math.radians(55.0))
    return scene, left, right


def _collection(name, members):
    """A light linking collection: `members` is a list of (object, 'INCLUDE' | 'EXCLUDE')."""
    coll = bpy.data.collections.new(name)
    for obj, state in members:
        coll.objects.link(obj)
    for (obj, state), link in zip(members, coll.collection_objects):
        link.light_linking.link_state = state
    return coll


def lamp_linked_to_one_box():
    """A warm area light that lights only the left box (its receiver collection includes
    it alone), and a cool point light that lights everything: the floor and the right box get
    the cool light only, and the warm light casts no light on the floor; diffuse bounces see
    the area light's shape (MIS with a light the floor may not sample)."""
    scene, left, right = _stage()
    warm = scenes.add_area_light("Warm", (-1.0, -1.0, 2.0), (-0.5, 0.0, 0.3), 300.0, 0.8,
                                 color=(1.0, 0.7, 0.4))
    scenes.add_point_light("Cool", (1.2, -0.8, 2.2), 250.0, color=(0.5, 0.7, 1.0), radius=0.2)
    warm.light_linking.receiver_collection = _collection("WarmLights", [(left, "INCLUDE")])
    return scenes.SceneInfo(scene, "lamp_linked_to_one_box")


def emissive_mesh_excluding_the_floor():
    """An emissive sphere whose receiver collection excludes the floor (only an exclusion:
    it lights everything else), over the two boxes, with a dim sun so the floor is not
    black."""
    scene, left, right = _stage()
    lamp = scenes.add_sphere("Lamp", (0.0, -0.6, 1.2), 0.25,
                             scenes.emitter("LampMat", (1.0, 0.9, 0.7), 8.0), segments=24,
                             rings=12)
    scenes.add_sun_light("Sun", (0.3, 0.5, -1.0), 1.0, angle=math.radians(5.0))
    floor = bpy.data.objects["Floor"]
    lamp.light_linking.receiver_collection = _collection("NotFloor", [(floor, "EXCLUDE")])
    return scenes.SceneInfo(scene, "emissive_mesh_excluding_the_floor")


def blocker_collection():
    """A spot light whose blocker collection includes only the right box: the left box casts
    no shadow from it (it is still lit by it), and a second, unlinked point light shadows
    both."""
    scene, left, right = _stage()
    key = scenes.add_point_light("Key", (0.0, 1.5, 2.0), 400.0, radius=0.15)
    scenes.add_point_light("Fill", (-1.5, -1.5, 2.5), 150.0, color=(0.6, 0.7, 1.0), radius=0.3)
    key.light_linking.blocker_collection = _collection("Blockers", [(right, "INCLUDE")])
    return scenes.SceneInfo(scene, "blocker_collection")


def nested_states():
    """A light linking collection with a child collection: the child (holding the floor and
    the right box) is excluded, the left box included directly; a point light linked to it
    lights only the left box, and a blocker collection of the right box alone (excluded)
    keeps its shadow off the floor for a second light."""
    scene, left, right = _stage()
    key = scenes.add_point_light("Key", (0.5, -1.0, 2.2), 300.0, color=(1.0, 0.8, 0.6), radius=0.2)
    fill = scenes.add_point_light("Fill", (0.9, 1.2, 1.8), 200.0, color=(0.6, 0.7, 1.0), radius=0.1)
    coll = _collection("KeyLights", [(left, "INCLUDE")])
    child = bpy.data.collections.new("Rest")
    child.objects.link(bpy.data.objects["Floor"])
    child.objects.link(right)
    coll.children.link(child)
    coll.collection_children[0].light_linking.link_state = "EXCLUDE"
    key.light_linking.receiver_collection = coll
    fill.light_linking.blocker_collection = _collection("NoRight", [(right, "EXCLUDE")])
    return scenes.SceneInfo(scene, "nested_states")


def strands_in_a_receiver_collection():
    """Hair strands (a Curves object) that a warm spot light alone lights, by its receiver
    collection, beside the two boxes, which only a cool point light reaches; the strands shadow
    the floor from both lights."""
    from test_curves_cycles import glossy, strands

    scene, left, right = _stage()
    hair = strands(24, 5, 0.03, glossy(), spread=0.5, height=0.7)
    hair.location = (0.0, 0.8, 0.0)
    warm = scenes.add_point_light("Warm", (-0.4, -0.5, 1.8), 300.0, color=(1.0, 0.7, 0.4),
                                  radius=0.2)
    scenes.add_point_light("Cool", (1.2, -0.8, 2.2), 200.0, color=(0.5, 0.7, 1.0), radius=0.2)
    warm.light_linking.receiver_collection = _collection("HairOnly", [(hair, "INCLUDE")])
    return scenes.SceneInfo(scene, "strands_in_a_receiver_collection")


CASES = [
    ("lamp_linked_to_one_box", lamp_linked_to_one_box, 2, "path_mis", 256),
    ("emissive_mesh_excluding_the_floor", emissive_mesh_excluding_the_floor, 2, "path_mis", 256),
    ("blocker_collection", blocker_collection, 1, "path_mis", 256),
    ("nested_states", nested_states, 1, "path_mis", 256),
    ("strands_in_a_receiver_collection", strands_in_a_receiver_collection, 1, "path_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_light_linking_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)
