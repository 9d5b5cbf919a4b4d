"""Point clouds (Geometry Nodes points rendered as they are: Mesh to Points, Distribute Points
on Faces) through the add-on (TESELA_points) against Cycles, which renders each point as a
sphere: radii from a field, the object's material, Point Info (Position, Radius, Random), a
named point attribute read by the Attribute node, and many small points (coarser spheres).
Criteria as the other Cycles tests (means within 2%, 8x8-block p95 within 5%)."""

import json
import sys
from pathlib import Path

import bpy
import pytest

import scenes
from test_instances_cycles import assert_agrees_with_cycles

REPO = Path(__file__).resolve().parent.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))
from blender_addon.export.gltf import write_gltf  # noqa: E402

pytestmark = pytest.mark.skipif(bpy.app.version < (4, 0, 0),
                                reason="the scenes are built with Blender 4.0+'s node API")


def _tree(name):
    ng = bpy.data.node_groups.new(name, "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    return ng, ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")


def _points_on_grid(material, subdivisions=7, size=2.4, radius=(0.04, 0.16), store=None):
    """A grid of `subdivisions`² points (Mesh to Points) above the plane, each of a random
    radius in `radius`, shaded with `material` (Set Material); `store`: a float attribute of
    that name on the points (the x coordinate, stored by Store Named Attribute)."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=subdivisions, y_subdivisions=subdivisions,
                                    size=size, location=(0.0, 0.0, 0.45))
    grid = bpy.context.active_object
    grid.name = "Points"
    ng, gin, gout = _tree("ToPoints")
    n = ng.nodes
    pts = n.new("GeometryNodeMeshToPoints")
    rnd = n.new("FunctionNodeRandomValue")
    rnd.data_type = "FLOAT"
    rnd.inputs["Min"].default_value, rnd.inputs["Max"].default_value = radius
    rnd.inputs["Seed"].default_value = 3
    setmat = n.new("GeometryNodeSetMaterial")
    setmat.inputs["Material"].default_value = material
    ng.links.new(gin.outputs["Geometry"], pts.inputs["Mesh"])
    ng.links.new(rnd.outputs["Value"], pts.inputs["Radius"])
    ng.links.new(pts.outputs["Points"], setmat.inputs["Geometry"])
    last = setmat.outputs["Geometry"]
    if store is not None:
        st = n.new("GeometryNodeStoreNamedAttribute")
        st.data_type = "FLOAT"
        st.domain = "POINT"
        st.inputs["Name"].default_value = store
        pos = n.new("GeometryNodeInputPosition")
        sep = n.new("ShaderNodeSeparateXYZ")
        ng.links.new(pos.outputs["Position"], sep.inputs[0])
        ng.links.new(last, st.inputs["Geometry"])
        ng.links.new(sep.outputs["X"], st.inputs["Value"])
        last = st.outputs["Geometry"]
    ng.links.new(last, gout.inputs["Geometry"])
    grid.modifiers.new("ToPoints", "NODES").node_group = ng
    return grid


def _dust(material, density=4000.0):
    """Small points scattered on a plane (Distribute Points on Faces, Poisson-free random),
    radius 0.012: thousands of points, which the renderer builds as coarser spheres."""
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.0, 0.3))
    plane = bpy.context.active_object
    plane.name = "Dust"
    ng, gin, gout = _tree("Dust")
    n = ng.nodes
    dist = n.new("GeometryNodeDistributePointsOnFaces")
    dist.inputs["Density"].default_value = density
    radius = n.new("GeometryNodeSetPointRadius")
    radius.inputs["Radius"].default_value = 0.012
    setmat = n.new("GeometryNodeSetMaterial")
    setmat.inputs["Material"].default_value = material
    ng.links.new(gin.outputs["Geometry"], dist.inputs["Mesh"])
    ng.links.new(dist.outputs["Points"], radius.inputs["Points"])
    ng.links.new(radius.outputs["Points"], setmat.inputs["Geometry"])
    ng.links.new(setmat.outputs["Geometry"], gout.inputs["Geometry"])
    plane.modifiers.new("Dust", "NODES").node_group = ng
    return plane


def _info_material():
    """Base colour (Random, Radius · 5, Position.x / 2 + 0.5) from Point Info."""
    mat = scenes.material("PointInfo", roughness=0.5)
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    info = nt.nodes.new("ShaderNodePointInfo")
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(info.outputs["Position"], sep.inputs[0])
    x = nt.nodes.new("ShaderNodeMath")
    x.operation = "MULTIPLY_ADD"
    x.inputs[1].default_value, x.inputs[2].default_value = 0.5, 0.5
    nt.links.new(sep.outputs["X"], x.inputs[0])
    r = nt.nodes.new("ShaderNodeMath")
    r.operation = "MULTIPLY"
    r.inputs[1].default_value = 5.0
    nt.links.new(info.outputs["Radius"], r.inputs[0])
    rgb = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(info.outputs["Random"], rgb.inputs[0])
    nt.links.new(r.outputs[0], rgb.inputs[1])
    nt.links.new(x.outputs[0], rgb.inputs[2])
    nt.links.new(rgb.outputs[0], bsdf.inputs["Base Color"])
    return mat


def _attribute_material(name):
    """Base colour through a ramp of the point attribute `name` (x in [-1.2, 1.2])."""
    mat = scenes.material("Heat", roughness=0.6)
    nt = mat.node_tree
    bsdf = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = name
    ramp = nt.nodes.new("ShaderNodeMapRange")
    ramp.inputs["From Min"].default_value, ramp.inputs["From Max"].default_value = -1.2, 1.2
    nt.links.new(attr.outputs["Fac"], ramp.inputs["Value"])
    cr = nt.nodes.new("ShaderNodeValToRGB")
    cr.color_ramp.elements[0].color = (0.05, 0.1, 0.8, 1.0)
    cr.color_ramp.elements[1].color = (0.9, 0.3, 0.05, 1.0)
    nt.links.new(ramp.outputs["Result"], cr.inputs["Fac"])
    nt.links.new(cr.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def _stage(build):
    info = scenes.light_over_plane("sun", with_box=False)
    bg = info.scene.world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.35, 0.4, 0.5, 1.0)
    bg.inputs["Strength"].default_value = 0.6
    build()
    return info


CASES = [
    ("random_radii", lambda: _points_on_grid(
        scenes.material("Balls", (0.8, 0.3, 0.1), roughness=0.35)), 256),
    ("point_info", lambda: _points_on_grid(_info_material()), 256),
    ("dust", lambda: _dust(scenes.lambert("DustMat", (0.9, 0.85, 0.7))), 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_points_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build, spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = _stage(build)
    assert_agrees_with_cycles(info.scene, "points " + name, spp, tmp_path)


def test_point_attribute_agrees_with_instanced_spheres(addon, tesela_bin, tmp_path, monkeypatch):
    """A float attribute stored on the points, read by the Attribute node. Cycles 5.0 reads
    named attributes of a point cloud as zero (measured: float, vector and colour alike), so
    its reference is the same points instancing smooth UV spheres of the points' radii, whose
    instance attribute Cycles reads (Attribute type Instancer); Tesela renders the points
    themselves, read as geometry attributes."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    info = _stage(lambda: _points_on_grid(_attribute_material("heat"), store="heat"))
    ng = bpy.data.objects["Points"].modifiers["ToPoints"].node_group
    mat = next(x for x in ng.nodes if x.bl_idname == "GeometryNodeSetMaterial").inputs[
        "Material"].default_value
    n = ng.nodes
    store = next(x for x in n if x.bl_idname == "GeometryNodeStoreNamedAttribute")
    out = next(x for x in n if x.bl_idname == "NodeGroupOutput")
    iop = n.new("GeometryNodeInstanceOnPoints")
    sphere = n.new("GeometryNodeMeshUVSphere")
    sphere.inputs["Segments"].default_value, sphere.inputs["Rings"].default_value = 64, 32
    smooth = n.new("GeometryNodeSetShadeSmooth")
    setmat = n.new("GeometryNodeSetMaterial")
    setmat.inputs["Material"].default_value = mat
    radius = n.new("GeometryNodeInputRadius")
    ng.links.new(sphere.outputs["Mesh"], smooth.inputs["Geometry"])
    ng.links.new(smooth.outputs["Geometry"], setmat.inputs["Geometry"])
    ng.links.new(store.outputs["Geometry"], iop.inputs["Points"])
    ng.links.new(setmat.outputs["Geometry"], iop.inputs["Instance"])
    ng.links.new(radius.outputs["Radius"], iop.inputs["Scale"])
    ng.links.new(iop.outputs["Instances"], out.inputs["Geometry"])
    attr = next(x for x in mat.node_tree.nodes if x.bl_idname == "ShaderNodeAttribute")
    attr.attribute_type = "INSTANCER"

    def points_themselves():
        ng.links.new(store.outputs["Geometry"], out.inputs["Geometry"])
        attr.attribute_type = "GEOMETRY"

    assert_agrees_with_cycles(info.scene, "points point_attribute (Cycles: instanced spheres)",
                              256, tmp_path, before_tesela=points_themselves)


def test_points_export_as_tesela_points(addon, tmp_path):
    """The Mesh to Points cloud reaches the file as one TESELA_points node with a radius per
    point, the material and the stored attribute its material reads."""
    _stage(lambda: _points_on_grid(_attribute_material("heat"), store="heat"))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "points.gltf"
    write_gltf(depsgraph, str(path), width=32, height=32)
    doc = json.loads(path.read_text())
    nodes = [nd for nd in doc["nodes"] if "TESELA_points" in nd.get("extensions", {})]
    assert len(nodes) == 1, [nd.get("name") for nd in doc["nodes"]]
    ext = nodes[0]["extensions"]["TESELA_points"]
    count = doc["accessors"][ext["points"]]["count"]
    assert count == len(bpy.data.objects["Points"].data.vertices) > 40
    assert doc["accessors"][ext["radius"]]["count"] == count
    assert doc["accessors"][ext["attributes"]["heat"]]["count"] == count
    assert doc["materials"][ext["material"]]["name"].startswith("Heat")
    assert "TESELA_points" in doc["extensionsUsed"]
