"""A Geometry Nodes scatter (Instance on Points) through the add-on: the exported glTF stores the
instanced mesh once and its placements as EXT_mesh_gpu_instancing instances, and Tesela's render
agrees with Cycles (per-channel means within 2%, 8x8 block means within 5% at the 95th
percentile)."""

import json
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from blender_addon.export.gltf import write_gltf  # noqa: E402
from test_addon import result_pixels  # noqa: E402

SIZE = 64
GRID = 10  # 10 x 10 points: 100 instances, past the add-on's GPU-instancing threshold


def scatter():
    """The lit plane with a 10 x 10 grid of points, each instancing a small ico sphere at a
    random scale (one mirrored in x) and rotation; the sphere object itself is not rendered."""
    info = scenes.light_over_plane("point", with_box=False)
    rock = scenes.add_sphere("Rock", (0.0, 0.0, 0.0), 1.0, scenes.lambert("RockMat", (0.7, 0.5, 0.3)),
                             segments=12, rings=8, smooth=False)
    rock.hide_render = True
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=GRID, y_subdivisions=GRID, size=3.0,
                                    location=(0.0, 0.0, 0.3))
    grid = bpy.context.active_object
    grid.name = "Scatter"
    ng = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n = ng.nodes
    gin, gout = n.new("NodeGroupInput"), n.new("NodeGroupOutput")
    pts = n.new("GeometryNodeMeshToPoints")
    iop = n.new("GeometryNodeInstanceOnPoints")
    obj = n.new("GeometryNodeObjectInfo")
    obj.inputs["Object"].default_value = rock
    scale = n.new("FunctionNodeRandomValue")
    scale.data_type = "FLOAT_VECTOR"
    scale.inputs["Min"].default_value = (-0.12, 0.08, 0.08)
    scale.inputs["Max"].default_value = (0.15, 0.15, 0.2)
    rot = n.new("FunctionNodeRandomValue")
    rot.data_type = "FLOAT_VECTOR"
    rot.inputs["Max"].default_value = (3.0, 3.0, 3.0)
    rot.inputs["Seed"].default_value = 5
    ng.links.new(gin.outputs["Geometry"], pts.inputs["Mesh"])
    ng.links.new(pts.outputs["Points"], iop.inputs["Points"])
    ng.links.new(obj.outputs["Geometry"], iop.inputs["Instance"])
    ng.links.new(scale.outputs["Value"], iop.inputs["Scale"])
    ng.links.new(rot.outputs["Value"], iop.inputs["Rotation"])
    ng.links.new(iop.outputs["Instances"], gout.inputs["Geometry"])
    grid.modifiers.new("Scatter", "NODES").node_group = ng
    return info


def assert_agrees_with_cycles(scene, label, spp, tmp_path, before_tesela=None):
    """Cycles and Tesela (through the add-on, direct lighting with MIS) render `scene` at
    `spp`; the images must agree (means within 2%, 8x8-block p95 within 5%). `before_tesela`,
    if given, changes the scene between the two renders (for a Cycles reference built another
    way)."""
    scenes.configure_cycles(scene, SIZE, SIZE, spp, 0, seed=7)
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    if before_tesela is not None:
        before_tesela()
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", spp, 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    got = result_pixels(tmp_path)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    print(f"{label}: {result}")
    assert result.ok, f"{label}: Tesela (add-on) vs Cycles: {result}"


def test_scatter_exports_one_mesh_and_its_instances(addon, tmp_path):
    scatter()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "scatter.gltf"
    res = write_gltf(depsgraph, str(path), width=SIZE, height=SIZE)
    doc = json.loads(path.read_text())
    placed = sum(1 for i in depsgraph.object_instances if i.is_instance)
    assert placed >= GRID * GRID
    instancing = [nd for nd in doc["nodes"] if "EXT_mesh_gpu_instancing" in nd.get("extensions", {})]
    assert len(instancing) == 1, "the placements are one instancing node"
    mi = instancing[0]["mesh"]
    assert [nd for nd in doc["nodes"] if nd.get("mesh") == mi] == instancing, "and one mesh"
    assert len(doc["meshes"]) == 3, [m["name"] for m in doc["meshes"]]  # plane, rock, rock copy
    attrs = instancing[0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]
    counts = {k: doc["accessors"][a]["count"] for k, a in attrs.items()}
    assert counts == {k: placed for k in
                      ("TRANSLATION", "ROTATION", "SCALE", "_TESELA_RANDOM")}, counts
    assert res.instanced_nodes == placed
    assert "EXT_mesh_gpu_instancing" in doc["extensionsUsed"]


def test_scatter_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    assert_agrees_with_cycles(scatter().scene, "scatter", 256, tmp_path)


def test_collection_instances_share_one_mesh(addon, tmp_path):
    """Three collection-instance empties of a collection holding one box, and the box itself:
    one glTF mesh, placed by four nodes (below the GPU-instancing threshold)."""
    scenes.light_over_plane("point", with_box=False)
    coll = bpy.data.collections.new("Rocks")
    bpy.context.scene.collection.children.link(coll)
    box = scenes.add_box("Rock", (-0.1, -0.1, 0.0), (0.1, 0.1, 0.2), scenes.lambert("RockMat", (0.5, 0.5, 0.5)))
    for c in box.users_collection:
        c.objects.unlink(box)
    coll.objects.link(box)
    for k in range(3):
        e = bpy.data.objects.new(f"Copy{k}", None)
        e.instance_type = "COLLECTION"
        e.instance_collection = coll
        e.location = (0.5 * k - 0.5, 0.8, 0.0)
        e.scale = (1.0, 1.0, -1.0) if k == 1 else (1.0, 1.0, 1.0)
        bpy.context.scene.collection.objects.link(e)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "coll.gltf"
    write_gltf(depsgraph, str(path), width=SIZE, height=SIZE)
    doc = json.loads(path.read_text())
    rocks = [i for i, m in enumerate(doc["meshes"]) if m["name"] == "Rock"]
    assert len(rocks) == 1, [m["name"] for m in doc["meshes"]]
    users = [nd for nd in doc["nodes"] if nd.get("mesh") == rocks[0]]
    assert len(users) == 4
    dets = sorted(round(float(np.linalg.det(np.array(nd["matrix"]).reshape(4, 4)[:3, :3])), 3)
                  for nd in users)
    assert dets == [-1.0, 1.0, 1.0, 1.0], dets


def particle_host_hidden():
    """A plane emitting 30 hair particles rendered as small spheres, its own mesh hidden from
    the render (Show Emitter off), over a lit floor: only the particles render (a hair
    particle scales its object by the hair length: spheres of radius 0.12)."""
    import bmesh

    scenes.clear_scene()
    me = bpy.data.meshes.new("Grid")
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.5)
    bm.to_mesh(me)
    bm.free()
    me.materials.append(scenes.lambert("HostMat", (0.8, 0.3, 0.2)))
    host = bpy.data.objects.new("Host", me)
    bpy.context.scene.collection.objects.link(host)
    host.location.z = 0.2
    # The instanced sphere itself stands out of view.
    src = scenes.add_sphere("Src", (9.0, 9.0, 0.0), 0.6, scenes.lambert("S", (0.2, 0.6, 0.9)),
                            segments=12, rings=6)
    ps = host.modifiers.new("P", "PARTICLE_SYSTEM").particle_system
    st = ps.settings
    st.type = "HAIR"
    st.count = 30
    st.render_type = "OBJECT"
    st.instance_object = src
    st.hair_length = 0.2
    st.particle_size = 1.0
    host.show_instancer_for_render = False
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("F", (0.5, 0.5, 0.5)))
    scenes.add_sun_light("Sun", (-0.3, 0.4, -1.0), 3.0)
    scenes.add_camera((0.0, -3.5, 3.0), (0.0, 0.0, 0.2), fov=0.87)
    return bpy.context.scene


def test_hidden_particle_emitter_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch):
    """Show Emitter off: Cycles renders the particles, not the emitting mesh (the depsgraph's
    show_self); rendering the host plane too puts a red square over the floor."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    assert_agrees_with_cycles(particle_host_hidden(), "hidden particle emitter", 128, tmp_path)


def particle_info(outputs, physics="NO"):
    """A plane emitting 40 particles (all born at frame 1, random sizes and lifetimes) rendered
    as small spheres, seen at frame 5 (age 4), over a lit floor; the spheres' Diffuse colour is
    made of three Particle Info outputs, each scaled into [0, 1] (``outputs``: (output,
    component or None, scale) per channel). The emitter itself is not rendered."""
    scenes.clear_scene()
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=2.4, location=(0.0, 0.0, 0.25))
    host = bpy.context.active_object
    src = scenes.add_sphere("Src", (9.0, 9.0, 0.0), 1.0, None, segments=12, rings=6)
    mat = bpy.data.materials.new("ByParticle")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(diffuse.outputs[0], out.inputs["Surface"])
    info = nt.nodes.new("ShaderNodeParticleInfo")
    combine = nt.nodes.new("ShaderNodeCombineXYZ")
    for axis, (name, component, scale) in zip("XYZ", outputs):
        value = info.outputs[name]
        if component is not None:
            sep = nt.nodes.new("ShaderNodeSeparateXYZ")
            nt.links.new(value, sep.inputs[0])
            value = sep.outputs[component]
        mul = nt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY_ADD"
        mul.use_clamp = True
        mul.inputs[1].default_value = scale
        mul.inputs[2].default_value = 0.5 if component is not None else 0.0
        nt.links.new(value, mul.inputs[0])
        nt.links.new(mul.outputs[0], combine.inputs[axis])
    nt.links.new(combine.outputs[0], diffuse.inputs["Color"])
    src.data.materials.append(mat)
    ps = host.modifiers.new("P", "PARTICLE_SYSTEM").particle_system
    ps.seed = 3
    st = ps.settings
    st.type = "EMITTER"
    st.count = 40
    st.frame_start = st.frame_end = 1
    st.lifetime = 40
    st.lifetime_random = 0.6
    st.physics_type = physics
    st.normal_factor = 0.6
    st.effector_weights.gravity = 0.0
    st.render_type = "OBJECT"
    st.instance_object = src
    st.particle_size = 0.1
    st.size_random = 0.7
    host.show_instancer_for_render = False
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("F", (0.5, 0.5, 0.5)))
    scenes.add_sun_light("Sun", (-0.3, 0.4, -1.0), 3.0)
    scenes.add_camera((0.0, -3.2, 3.0), (0.0, 0.0, 0.3), fov=0.8)
    scene.frame_start = 1
    for frame in range(1, 6):
        scene.frame_set(frame)
    return scene


PARTICLE_CASES = [
    ("random_index_age", [("Random", None, 1.0), ("Index", None, 1 / 40), ("Age", None, 0.2)],
     "NO"),
    ("lifetime_size_location", [("Lifetime", None, 1 / 40), ("Size", None, 5.0),
                                ("Location", "X", 0.4)], "NO"),
    ("velocity", [("Velocity", "X", 1.0), ("Velocity", "Y", 1.0),
                  ("Velocity", "Z", 0.8)], "NEWTON"),
]


@pytest.mark.parametrize("case", PARTICLE_CASES, ids=[c[0] for c in PARTICLE_CASES])
def test_particle_info_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    """Particle Info on the instances of an emitter particle system: each sphere coloured by
    its particle's index, random number, age, lifetime, size, location or velocity (the
    previous renderer dropped the node: every sphere black or one colour)."""
    name, outputs, physics = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    assert_agrees_with_cycles(particle_info(outputs, physics), f"particle info {name}", 128,
                              tmp_path)


def curve_text_meta_surface():
    """A bevelled Bezier circle, a text, a metaball and a NURBS sphere: objects whose evaluated
    mesh the depsgraph yields as an instance row after the object's own (curve data) row."""
    scenes.clear_scene()
    bpy.ops.curve.primitive_bezier_circle_add(location=(0.0, 0.0, 0.3))
    bpy.context.active_object.data.bevel_depth = 0.1
    bpy.ops.object.text_add(location=(1.5, 0.0, 0.0))
    bpy.ops.object.metaball_add(location=(-1.5, 0.0, 0.5))
    bpy.ops.surface.primitive_nurbs_surface_sphere_add(radius=0.4, location=(0.0, 1.5, 0.5))
    bpy.context.view_layer.update()


def test_curve_text_metaball_and_surface_export_their_mesh_once(addon, tmp_path):
    """Cycles renders only the mesh rows of the depsgraph; the objects' own rows carry curve
    data (exporting them too doubled every triangle)."""
    curve_text_meta_surface()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    want = 0
    for inst in depsgraph.object_instances:
        if inst.object.type == "MESH":
            me = inst.object.to_mesh()
            me.calc_loop_triangles()
            want += len(me.loop_triangles)
            inst.object.to_mesh_clear()
    assert want > 1000
    res = write_gltf(depsgraph, str(tmp_path / "c.gltf"), width=SIZE, height=SIZE)
    assert res.triangles == want


def gn_pipe():
    """A Bezier curve made a pipe by Geometry Nodes (Curve to Mesh with a Curve Circle, Set
    Material orange) over the lit plane: the curve object itself has no material slots."""
    info = scenes.light_over_plane("point", with_box=False)
    cu = bpy.data.curves.new("Path", "CURVE")
    cu.dimensions = "3D"
    s = cu.splines.new("BEZIER")
    s.bezier_points.add(2)
    for bp, p in zip(s.bezier_points, [(-1.2, 0, 0.2), (0, 0.4, 1.0), (1.2, -0.2, 0.2)]):
        bp.co = p
        bp.handle_left_type = bp.handle_right_type = "AUTO"
    ob = bpy.data.objects.new("Path", cu)
    bpy.context.scene.collection.objects.link(ob)
    ng = bpy.data.node_groups.new("Pipe", "GeometryNodeTree")
    ng.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    ng.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    n = ng.nodes
    gin, gout = n.new("NodeGroupInput"), n.new("NodeGroupOutput")
    cc = n.new("GeometryNodeCurvePrimitiveCircle")
    cc.inputs["Radius"].default_value = 0.1
    c2m = n.new("GeometryNodeCurveToMesh")
    sm = n.new("GeometryNodeSetMaterial")
    sm.inputs["Material"].default_value = scenes.lambert("PipeM", (0.9, 0.4, 0.2))
    ng.links.new(gin.outputs["Geometry"], c2m.inputs["Curve"])
    ng.links.new(cc.outputs[0], c2m.inputs["Profile Curve"])
    ng.links.new(c2m.outputs[0], sm.inputs[0])
    ng.links.new(sm.outputs[0], gout.inputs[0])
    ob.modifiers.new("Pipe", "NODES").node_group = ng
    return info


def test_geometry_nodes_pipe_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    assert_agrees_with_cycles(gn_pipe().scene, "geometry nodes pipe", 128, tmp_path)
