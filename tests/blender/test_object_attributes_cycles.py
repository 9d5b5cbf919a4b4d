"""The Attribute node's Object, Instancer and View Layer types through the add-on against
Cycles: values Blender looks up by name on data-blocks (custom properties, property paths such
as ``color``), not on the geometry. Criteria as tests/blender/test_instances_cycles.py."""

import math

import bpy
import pytest

import scenes
from test_instances_cycles import assert_agrees_with_cycles


def attribute_material(name, attr_type, attr_name, output="Color"):
    """A Diffuse BSDF whose colour is an Attribute node's output (a float output as grey)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_type = attr_type
    attr.attribute_name = attr_name
    nt.links.new(attr.outputs[output], bsdf.inputs["Color"])
    return mat


def stage():
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("Floor", (0.5, 0.5, 0.5)))
    scenes.add_sun_light("Sun", (-0.3, 0.4, -1.0), 3.0)
    scenes.add_camera((0.0, -4.0, 2.6), (0.0, 0.0, 0.4), fov=math.radians(45.0))


def object_type():
    """Three balls sharing one material that reads the Object attribute ``tint`` (a custom
    property: an RGB array, an RGBA array, a number), and a box whose material reads the
    object's ``color`` property path and one reading a custom property of its mesh."""
    scenes.clear_scene()
    mat = attribute_material("Tint", "OBJECT", "tint")
    for i, tint in enumerate([(0.9, 0.2, 0.1), (0.1, 0.7, 0.3, 0.5), 0.35]):
        ball = scenes.add_sphere(f"Ball{i}", (-1.4 + 1.1 * i, 0.3, 0.4), 0.4, mat,
                                 segments=24, rings=12)
        ball["tint"] = tint
    box = scenes.add_box("Box", (1.0, -0.6, 0.0), (1.6, 0.0, 0.6),
                         attribute_material("ByColor", "OBJECT", "color"))
    box.color = (0.2, 0.3, 0.95, 1.0)
    card = scenes.add_box("Card", (-0.3, -1.0, 0.0), (0.3, -0.8, 0.5),
                          attribute_material("ByMesh", "OBJECT", "shade", "Fac"))
    card.data["shade"] = (0.9, 0.6, 0.3)
    stage()
    return bpy.context.scene


def instancer_type():
    """A collection of one ball instanced by three empties, each with its own ``tint``: the
    Instancer attribute gives each instance its instancer's colour (the ball has a ``tint``
    too, which the Object type would read)."""
    scenes.clear_scene()
    coll = bpy.data.collections.new("Balls")
    ball = scenes.add_sphere("Ball", (0.0, 0.0, 0.4), 0.4,
                             attribute_material("ByInstancer", "INSTANCER", "tint"),
                             segments=24, rings=12)
    ball["tint"] = (1.0, 1.0, 1.0)
    for c in ball.users_collection:
        c.objects.unlink(ball)
    coll.objects.link(ball)
    for i, tint in enumerate([(0.9, 0.2, 0.1), (0.1, 0.7, 0.3), (0.2, 0.3, 0.95)]):
        empty = bpy.data.objects.new(f"Placer{i}", None)
        empty.instance_type = "COLLECTION"
        empty.instance_collection = coll
        empty.location = (-1.2 + 1.2 * i, 0.2, 0.0)
        empty["tint"] = tint
        bpy.context.scene.collection.objects.link(empty)
    stage()
    return bpy.context.scene


def view_layer_type():
    """The View Layer type: one value for the render, from the view layer's custom property,
    else the scene's, else the world's (each layer tried by one ball)."""
    scenes.clear_scene()
    scene = bpy.context.scene
    bpy.context.view_layer["accent"] = (0.9, 0.5, 0.1)
    scene["mood"] = (0.1, 0.4, 0.9)
    scene.world["haze"] = 0.6
    for i, name in enumerate(["accent", "mood", "haze"]):
        scenes.add_sphere(f"Ball{i}", (-1.2 + 1.2 * i, 0.2, 0.4), 0.4,
                          attribute_material(f"VL{i}", "VIEW_LAYER", name),
                          segments=24, rings=12)
    stage()
    return scene


def geometry_nodes_instances(distribute):
    """A Geometry Nodes scatter whose instances carry a random colour and a random number
    stored on the instance domain, read by Attribute nodes of the Instancer type (colour into
    the base colour, the number into the roughness of a glossy layer). ``distribute``: points
    from Distribute Points on Faces (which gives each point an ``id``, the instance's id in the
    depsgraph) instead of the grid's vertices."""
    scenes.clear_scene()
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=5, y_subdivisions=4, size=3.0,
                                    location=(0.0, 0.2, 0.15))
    grid = bpy.context.active_object
    ball = scenes.add_sphere("Pebble", (9.0, 9.0, 0.0), 0.18, None, segments=16, rings=8)
    mat = bpy.data.materials.new("ByInstance")
    mat.use_nodes = True
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    col = nt.nodes.new("ShaderNodeAttribute")
    col.attribute_type, col.attribute_name = "INSTANCER", "col"
    rough = nt.nodes.new("ShaderNodeAttribute")
    rough.attribute_type, rough.attribute_name = "INSTANCER", "rough"
    nt.links.new(col.outputs["Color"], bsdf.inputs["Base Color"])
    nt.links.new(rough.outputs["Fac"], bsdf.inputs["Roughness"])
    ball.data.materials.append(mat)
    ng = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n, link = ng.nodes, ng.links.new
    gin, gout = n.new("NodeGroupInput"), n.new("NodeGroupOutput")
    if distribute:
        pts = n.new("GeometryNodeDistributePointsOnFaces")
        pts.inputs["Density"].default_value = 4.0
        pts.inputs["Seed"].default_value = 3
    else:
        pts = n.new("GeometryNodeMeshToPoints")
    iop = n.new("GeometryNodeInstanceOnPoints")
    info = n.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = ball
    link(gin.outputs["Geometry"], pts.inputs[0])
    link(pts.outputs["Points"], iop.inputs["Points"])
    link(info.outputs["Geometry"], iop.inputs["Instance"])
    geometry = iop.outputs["Instances"]
    for name, kind, seed in (("col", "FLOAT_COLOR", 1), ("rough", "FLOAT", 2)):
        rnd = n.new("FunctionNodeRandomValue")
        rnd.data_type = "FLOAT_VECTOR" if kind == "FLOAT_COLOR" else "FLOAT"
        rnd.inputs["Seed"].default_value = seed
        store = n.new("GeometryNodeStoreNamedAttribute")
        store.data_type, store.domain = kind, "INSTANCE"
        store.inputs["Name"].default_value = name
        link(geometry, store.inputs["Geometry"])
        value = rnd.outputs[0] if kind == "FLOAT_COLOR" else rnd.outputs[1]
        link(value, store.inputs["Value"])
        geometry = store.outputs["Geometry"]
    link(geometry, gout.inputs["Geometry"])
    grid.modifiers.new("Scatter", "NODES").node_group = ng
    stage()
    return bpy.context.scene


CASES = [("object", object_type), ("instancer", instancer_type),
         ("view_layer", view_layer_type),
         ("geometry_nodes_grid", lambda: geometry_nodes_instances(False)),
         ("geometry_nodes_distributed", lambda: geometry_nodes_instances(True))]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_attribute_types_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    assert_agrees_with_cycles(build(), f"attribute {name}", 128, tmp_path)
