"""TESELA_material_graph, TESELA_images and the mesh/object data the graph reads, as the add-on
writes them (docs/extensions.md), with Blender as a Python module (PyPI bpy 5.x); one test runs
Debian's Blender 3.4 (blender34_material_graph.py) and checks that its legacy nodes arrive in the
5.x vocabulary; one renders Object Info > Random with Cycles.
"""

import json
import math
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import bpy
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

import blender_addon  # noqa: E402
from blender_addon import compat, report  # noqa: E402
from blender_addon import engine as tesela_engine  # noqa: E402
from blender_addon.export import mesh as export_mesh  # noqa: E402

BLENDER34 = os.environ.get("TESELA_BLENDER") or shutil.which("blender")


# --------------------------------------------------------------------------------------------
# helpers

@pytest.fixture(scope="module")
def addon():
    registered = hasattr(bpy.types.Scene, "tesela") and tesela_engine.TeselaRenderEngine.is_registered
    if not registered:
        blender_addon.register()
    yield blender_addon
    if not registered:
        blender_addon.unregister()


def fresh_scene():
    """An empty scene (a camera), and no unused data left from earlier tests (names stay free)."""
    scene = bpy.context.scene
    for ob in list(scene.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.node_groups, bpy.data.images,
                 bpy.data.collections):
        for d in list(coll):
            if d.users == 0:
                coll.remove(d)
    scene.render.engine = "TESELA"
    scene.render.resolution_x, scene.render.resolution_y = 8, 8
    scene.render.resolution_percentage = 100
    if scene.camera is None or scene.camera.name not in scene.objects:
        cam = bpy.data.objects.new("GraphCam", bpy.data.cameras.new("GraphCam"))
        cam.location = (0, 0, 5)
        scene.collection.objects.link(cam)
        scene.camera = cam
    return scene


def new_material(name):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    return mat, nt, out


def plane(scene, name, materials, uv_names=("UVMap",), size=1.0, location=(0, 0, 0)):
    mesh = bpy.data.meshes.new(name)
    s = size
    mesh.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    for uv in uv_names:
        layer = mesh.uv_layers.new(name=uv)
    # A second UV map turned a quarter: different tangents per map.
    if len(uv_names) > 1:
        data = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float32)
        layer = mesh.uv_layers[uv_names[1]]
        layer.data.foreach_set("uv", data[[1, 2, 3, 0]].ravel())
    for m in materials:
        mesh.materials.append(m)
    ob = bpy.data.objects.new(name, mesh)
    ob.location = location
    scene.collection.objects.link(ob)
    return ob


def export(tmp_path, name="graph.gltf"):
    path = Path(tmp_path) / name
    assert bpy.ops.export_scene.tesela_gltf(filepath=str(path)) == {"FINISHED"}
    return json.loads(path.read_text(encoding="utf-8")), path


def graph_of(doc, material_name):
    mat = next(m for m in doc["materials"] if m["name"] == material_name)
    return mat["extensions"]["TESELA_material_graph"]


def nodes_by_name(graph):
    out = {}
    for i, n in enumerate(graph["nodes"]):
        key = (n.get("group"), n["name"])
        assert key not in out, "node %s exported twice" % (key,)
        out[key] = (i, n)
    return out


def node(graph, name, group=None):
    return nodes_by_name(graph)[(group, name)]


def link_to(graph, name, output, group=None):
    return {"link": [node(graph, name, group)[0], output]}


def read_view(doc, path, view_index):
    view = doc["bufferViews"][view_index]
    data = (Path(path).parent / doc["buffers"][0]["uri"]).read_bytes()
    return data[view.get("byteOffset", 0):view.get("byteOffset", 0) + view["byteLength"]]


def read_accessor(doc, path, index):
    acc = doc["accessors"][index]
    ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[acc["type"]]
    dtype = {5126: np.float32, 5125: np.uint32}[acc["componentType"]]
    raw = read_view(doc, path, acc["bufferView"])
    return np.frombuffer(raw, dtype=dtype).reshape(acc["count"], ncomp)


def image_rows(doc, path, entry):
    dtype = {"u8": np.uint8, "f16": np.float16, "f32": np.float32}[entry["component"]]
    raw = read_view(doc, path, entry["bufferView"])
    return np.frombuffer(raw, dtype=dtype).reshape(entry["height"], entry["width"], entry["channels"])


def ident(sockets, identifier):
    """A socket by identifier (bpy's [] looks sockets up by name)."""
    return next(s for s in sockets if s.identifier == identifier)


def set_pixels(img, rows_top_to_bottom):
    """Blender pixels from rows given top to bottom (Blender stores them bottom to top)."""
    img.pixels.foreach_set(np.ascontiguousarray(rows_top_to_bottom[::-1], np.float32).ravel())


def new_group(name, inputs=(), outputs=()):
    """A shader node group with (name, socket type, default) inputs and (name, type) outputs."""
    g = bpy.data.node_groups.new(name, "ShaderNodeTree")
    for sname, stype, default in inputs:
        s = g.interface.new_socket(sname, in_out="INPUT", socket_type=stype)
        if default is not None:
            s.default_value = default
    for sname, stype in outputs:
        g.interface.new_socket(sname, in_out="OUTPUT", socket_type=stype)
    gin = g.nodes.new("NodeGroupInput")
    gout = g.nodes.new("NodeGroupOutput")
    return g, gin, gout


# --------------------------------------------------------------------------------------------
# a PBR asset: image textures on several inputs, a normal map on the second UV map

def test_pbr_asset_images_uvs_tangents(addon, tmp_path):
    scene = fresh_scene()
    albedo = bpy.data.images.new("Albedo", 4, 2, alpha=True)
    albedo_rows = np.array([[[10, 20, 30, 255], [40, 50, 60, 255], [70, 80, 90, 255], [1, 2, 3, 128]],
                            [[250, 240, 230, 255], [0, 0, 0, 0], [128, 64, 32, 255], [5, 6, 7, 8]]],
                           np.float32) / 255.0
    set_pixels(albedo, albedo_rows)
    albedo.pack()  # packed images travel through image.pixels as well
    assert albedo.packed_file is not None
    rm = bpy.data.images.new("RoughMetal", 2, 2)
    set_pixels(rm, np.full((2, 2, 4), 0.5, np.float32))
    rm.colorspace_settings.name = "Non-Color"
    normal = bpy.data.images.new("Normal", 2, 2)
    set_pixels(normal, np.tile(np.array([0.5, 0.5, 1.0, 1.0], np.float32), (2, 2, 1)))
    normal.colorspace_settings.name = "Non-Color"
    hdr = bpy.data.images.new("Sky HDR", 2, 2, float_buffer=True)
    hdr_rows = np.array([[[7.25, 0.1, 1e-3, 1.0], [100.0, 2.0, 3.0, 1.0]],
                         [[0.0, 0.5, 1.5, 1.0], [12345.678, 0.2, 0.3, 1.0]]], np.float32)
    set_pixels(hdr, hdr_rows)

    mat, nt, out = new_material("PBR")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    t_albedo = nt.nodes.new("ShaderNodeTexImage")
    t_albedo.name = "Albedo Tex"
    t_albedo.image = albedo
    t_albedo.interpolation = "Closest"
    t_albedo.extension = "MIRROR"
    nt.links.new(t_albedo.outputs["Color"], bsdf.inputs["Base Color"])
    t_rm = nt.nodes.new("ShaderNodeTexImage")
    t_rm.name = "RM Tex"
    t_rm.image = rm
    t_rm.projection = "BOX"
    t_rm.projection_blend = 0.25
    sep = nt.nodes.new("ShaderNodeSeparateColor")
    nt.links.new(t_rm.outputs["Color"], sep.inputs["Color"])
    nt.links.new(sep.outputs["Green"], bsdf.inputs["Roughness"])
    nt.links.new(sep.outputs["Blue"], bsdf.inputs["Metallic"])
    uvnode = nt.nodes.new("ShaderNodeUVMap")
    uvnode.uv_map = "Detail"
    t_n = nt.nodes.new("ShaderNodeTexImage")
    t_n.name = "Normal Tex"
    t_n.image = normal
    nt.links.new(uvnode.outputs["UV"], t_n.inputs["Vector"])
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.uv_map = "Detail"
    nmap.inputs["Strength"].default_value = 0.75
    nt.links.new(t_n.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    t_hdr = nt.nodes.new("ShaderNodeTexImage")
    t_hdr.name = "HDR Tex"
    t_hdr.image = hdr
    nt.links.new(t_hdr.outputs["Color"], bsdf.inputs["Emission Color"])
    bsdf.inputs["Emission Strength"].default_value = 2.0

    # A second material sharing the albedo image.
    mat2, nt2, out2 = new_material("PBR Copy")
    d = nt2.nodes.new("ShaderNodeBsdfDiffuse")
    t2 = nt2.nodes.new("ShaderNodeTexImage")
    t2.image = albedo
    nt2.links.new(t2.outputs["Color"], d.inputs["Color"])
    nt2.links.new(d.outputs["BSDF"], out2.inputs["Surface"])

    ob = plane(scene, "Asset", [mat], uv_names=("UVMap", "Detail"))
    plane(scene, "Other", [mat2], uv_names=("UVMap",), location=(3, 0, 0))
    doc, path = export(tmp_path)

    g = graph_of(doc, "PBR")
    assert g["version"] == 1
    bi, b = node(g, "Principled BSDF")
    assert g["surface"] == [bi, "BSDF"]
    assert b["type"] == "ShaderNodeBsdfPrincipled"
    assert b["inputs"]["Base Color"] == link_to(g, "Albedo Tex", "Color")
    assert b["inputs"]["Roughness"] == link_to(g, "Separate Color", "Green")
    assert b["inputs"]["Metallic"] == link_to(g, "Separate Color", "Blue")
    assert b["inputs"]["Normal"] == link_to(g, "Normal Map", "Normal")
    assert b["inputs"]["Emission Color"] == link_to(g, "HDR Tex", "Color")
    assert b["inputs"]["Emission Strength"] == 2.0
    assert "Weight" not in b["inputs"]  # disabled socket
    _, nm = node(g, "Normal Map")
    assert nm["props"] == {"space": "TANGENT", "uv_map": "Detail"}
    assert nm["inputs"] == {"Strength": 0.75, "Color": link_to(g, "Normal Tex", "Color")}
    _, tn = node(g, "Normal Tex")
    assert tn["inputs"] == {"Vector": link_to(g, "UV Map", "UV")}
    assert node(g, "UV Map")[1]["props"]["uv_map"] == "Detail"
    _, ta = node(g, "Albedo Tex")
    assert "Vector" not in ta["inputs"]  # unlinked implicit input: absent (UV by default)
    assert ta["props"]["interpolation"] == "Closest" and ta["props"]["extension"] == "MIRROR"
    assert ta["props"]["projection"] == "FLAT"
    _, trm = node(g, "RM Tex")
    assert trm["props"]["projection"] == "BOX" and trm["props"]["projection_blend"] == pytest.approx(0.25)

    # TESELA_images: one entry per Blender image, shared between materials.
    assert "TESELA_images" in doc["extensionsUsed"]
    imgs = doc["extensions"]["TESELA_images"]["images"]
    by_name = {e["name"]: i for i, e in enumerate(imgs)}
    assert sorted(by_name) == ["Albedo", "Normal", "RoughMetal", "Sky HDR"]
    g2 = graph_of(doc, "PBR Copy")
    assert node(g2, "Image Texture")[1]["props"]["image"] == by_name["Albedo"] == ta["props"]["image"]
    assert trm["props"]["image"] == by_name["RoughMetal"]
    e = imgs[by_name["Albedo"]]
    assert (e["width"], e["height"], e["channels"], e["component"]) == (4, 2, 4, "u8")
    assert e["colorspace"] == "sRGB" and ta["props"]["colorspace"] == "sRGB"
    assert ta["props"]["alpha_mode"] == e["alpha_mode"] == albedo.alpha_mode
    assert np.array_equal(image_rows(doc, path, e), np.rint(albedo_rows * 255).astype(np.uint8))
    assert imgs[by_name["RoughMetal"]]["colorspace"] == "Non-Color"
    eh = imgs[by_name["Sky HDR"]]
    assert eh["component"] == "f32" and eh["premultiplied"] is True
    got = image_rows(doc, path, eh)
    assert np.array_equal(got, hdr_rows)  # float pixels: not clipped, not quantised
    assert got.max() > 1.0
    assert node(g, "HDR Tex")[1]["props"]["colorspace"] == eh["colorspace"]

    # Mesh: every UV map (render-active first), tangents for the normal map's UV map.
    mesh = next(m for m in doc["meshes"] if m["name"] == "Asset")
    prim = mesh["primitives"][0]
    assert prim["extras"]["tesela_uv_names"] == ["UVMap", "Detail"]
    assert prim["extras"]["tesela_tangent_uv"] == "Detail"
    assert {"TEXCOORD_0", "TEXCOORD_1", "TANGENT"} <= set(prim["attributes"])
    uv1 = read_accessor(doc, path, prim["attributes"]["TEXCOORD_1"])
    blender_uv = np.empty(8, np.float32)
    ob.data.uv_layers["Detail"].data.foreach_get("uv", blender_uv)
    blender_uv = blender_uv.reshape(-1, 2)
    assert np.allclose(uv1[:, 0], blender_uv[:, 0]) and np.allclose(uv1[:, 1], 1.0 - blender_uv[:, 1])
    tan = read_accessor(doc, path, prim["attributes"]["TANGENT"])
    ob.data.calc_tangents(uvmap="Detail")
    want = np.array([tuple(lp.tangent) + (lp.bitangent_sign,) for lp in ob.data.loops], np.float32)
    assert np.allclose(tan, want, atol=1e-6)
    assert np.allclose(np.linalg.norm(tan[:, :3], axis=1), 1.0) and set(np.abs(tan[:, 3])) == {1.0}
    other = next(m for m in doc["meshes"] if m["name"] == "Other")["primitives"][0]
    assert "TANGENT" not in other["attributes"]  # no normal map there
    # The metallic-roughness fallback stays for other tools.
    pbr = next(m for m in doc["materials"] if m["name"] == "PBR")["pbrMetallicRoughness"]
    assert "baseColorTexture" in pbr
    assert doc["images"][0]["mimeType"] == "image/png"


def test_half_float_image_travels_as_f16(addon, tmp_path):
    scene = fresh_scene()
    img = bpy.data.images.new("Half", 2, 1, float_buffer=True)
    rows = np.array([[[2.5, 0.125, 1024.0, 1.0], [-3.0, 0.5, 65504.0, 0.25]]], np.float32)
    set_pixels(img, rows)
    mat, nt, out = new_material("HalfMat")
    em = nt.nodes.new("ShaderNodeEmission")
    tex = nt.nodes.new("ShaderNodeTexEnvironment")
    tex.image = img
    nt.links.new(tex.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    plane(scene, "H", [mat])
    doc, path = export(tmp_path)
    (entry,) = doc["extensions"]["TESELA_images"]["images"]
    assert entry["component"] == "f16"
    assert np.array_equal(image_rows(doc, path, entry).astype(np.float32), rows)
    g = graph_of(doc, "HalfMat")
    assert node(g, "Environment Texture")[1]["props"]["image"] == 0
    assert node(g, "Environment Texture")[1]["props"]["projection"] == "EQUIRECTANGULAR"


# --------------------------------------------------------------------------------------------
# Mix Shader of Diffuse and Glossy by Layer Weight

def test_mix_shader_by_layer_weight(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Layered")
    lw = nt.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.3
    diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
    diff.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    gloss = nt.nodes.new("ShaderNodeBsdfGlossy")
    gloss.distribution = "GGX"
    gloss.inputs["Roughness"].default_value = 0.15
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(lw.outputs["Facing"], mix.inputs["Fac"])
    nt.links.new(diff.outputs["BSDF"], mix.inputs[1])
    nt.links.new(gloss.outputs["BSDF"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    plane(scene, "L", [mat])
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Layered")
    mi, m = node(g, "Mix Shader")
    assert g["surface"] == [mi, "Shader"]
    assert m["type"] == "ShaderNodeMixShader"
    assert m["inputs"] == {"Fac": link_to(g, "Layer Weight", "Facing"),
                           "Shader": link_to(g, "Diffuse BSDF", "BSDF"),
                           "Shader_001": link_to(g, "Glossy BSDF", "BSDF")}
    _, gl = node(g, "Glossy BSDF")
    assert gl["type"] == "ShaderNodeBsdfAnisotropic"  # the 5.x Glossy BSDF
    assert gl["props"] == {"distribution": "GGX"}
    assert gl["inputs"]["Roughness"] == pytest.approx(0.15)
    assert node(g, "Diffuse BSDF")[1]["inputs"]["Color"] == pytest.approx([0.2, 0.4, 0.6, 1.0])
    assert node(g, "Layer Weight")[1]["inputs"] == {"Blend": pytest.approx(0.3)}
    assert len(g["nodes"]) == 4
    assert "displacement" not in g


# --------------------------------------------------------------------------------------------
# node groups nested twice, group socket defaults, a group used twice

def test_nested_groups_are_inlined(addon, tmp_path):
    scene = fresh_scene()
    inner, iin, iout = new_group("Inner", [("Scale", "NodeSocketFloat", 3.0),
                                           ("Gain", "NodeSocketFloat", 0.5)],
                                 [("Fac", "NodeSocketFloat")])
    noise = inner.nodes.new("ShaderNodeTexNoise")
    mul = inner.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    inner.links.new(iin.outputs["Scale"], noise.inputs["Scale"])
    inner.links.new(noise.outputs["Fac"], mul.inputs[0])
    inner.links.new(iin.outputs["Gain"], mul.inputs[1])
    inner.links.new(mul.outputs[0], iout.inputs["Fac"])

    outer, oin, oout = new_group("Outer", [("Gain", "NodeSocketFloat", 0.1)],
                                 [("Result", "NodeSocketFloat")])
    ginner = outer.nodes.new("ShaderNodeGroup")
    ginner.node_tree = inner
    ginner.name = "InnerNode"
    ginner.inputs["Scale"].default_value = 4.5  # the group node's own default, not the interface's
    reroute = outer.nodes.new("NodeReroute")
    outer.links.new(oin.outputs["Gain"], ginner.inputs["Gain"])
    outer.links.new(ginner.outputs["Fac"], reroute.inputs[0])
    outer.links.new(reroute.outputs[0], oout.inputs["Result"])

    mat, nt, out = new_material("Grouped")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    g1 = nt.nodes.new("ShaderNodeGroup")
    g1.node_tree = outer
    g1.name = "OuterA"
    g1.inputs["Gain"].default_value = 0.7
    g2 = nt.nodes.new("ShaderNodeGroup")
    g2.node_tree = outer
    g2.name = "OuterB"
    val = nt.nodes.new("ShaderNodeValue")
    val.outputs[0].default_value = 0.25
    nt.links.new(val.outputs[0], g2.inputs["Gain"])
    nt.links.new(g1.outputs["Result"], bsdf.inputs["Roughness"])
    nt.links.new(g2.outputs["Result"], bsdf.inputs["Metallic"])
    plane(scene, "G", [mat])
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Grouped")
    types = [n["type"] for n in g["nodes"]]
    assert not {"ShaderNodeGroup", "NodeGroupInput", "NodeGroupOutput", "NodeReroute"} & set(types)
    assert types.count("ShaderNodeMath") == 2 and types.count("ShaderNodeTexNoise") == 2
    _, b = node(g, "Principled BSDF")
    ma_i, ma = node(g, "Math", "OuterA/InnerNode")
    mb_i, mb = node(g, "Math", "OuterB/InnerNode")
    assert b["inputs"]["Roughness"] == {"link": [ma_i, "Value"]}
    assert b["inputs"]["Metallic"] == {"link": [mb_i, "Value"]}
    assert ma["props"]["operation"] == "MULTIPLY"
    assert ma["inputs"]["Value"] == link_to(g, "Noise Texture", "Fac", "OuterA/InnerNode")
    assert ma["inputs"]["Value_001"] == pytest.approx(0.7)   # through two Group Inputs
    assert mb["inputs"]["Value_001"] == link_to(g, "Value", "Value")
    assert node(g, "Value")[1]["props"]["value"] == pytest.approx(0.25)
    _, na = node(g, "Noise Texture", "OuterA/InnerNode")
    assert na["inputs"]["Scale"] == pytest.approx(4.5)
    assert "Vector" not in na["inputs"]


def test_unlinked_group_output_and_empty_group(addon, tmp_path):
    scene = fresh_scene()
    grp, gin, gout = new_group("Constant", [], [("Value", "NodeSocketFloat"), ("Col", "NodeSocketColor")])
    gout.inputs["Value"].default_value = 0.375
    mat, nt, out = new_material("GroupConst")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    gn = nt.nodes.new("ShaderNodeGroup")
    gn.node_tree = grp
    nt.links.new(gn.outputs["Value"], bsdf.inputs["Roughness"])
    nt.links.new(gn.outputs["Col"], bsdf.inputs["Base Color"])
    plane(scene, "C", [mat])
    doc, _ = export(tmp_path)
    b = node(graph_of(doc, "GroupConst"), "Principled BSDF")[1]
    assert b["inputs"]["Roughness"] == pytest.approx(0.375)
    assert len(b["inputs"]["Base Color"]) == 4


# --------------------------------------------------------------------------------------------
# muted nodes, muted and invalid links, reroute chains

def test_muted_nodes_links_and_reroutes(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Muted")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    val = nt.nodes.new("ShaderNodeValue")
    val.outputs[0].default_value = 0.3
    r1, r2, r3 = (nt.nodes.new("NodeReroute") for _ in range(3))
    nt.links.new(val.outputs[0], r1.inputs[0])
    nt.links.new(r1.outputs[0], r2.inputs[0])
    nt.links.new(r2.outputs[0], r3.inputs[0])
    add = nt.nodes.new("ShaderNodeMath")
    add.name = "Muted Add"
    add.inputs[1].default_value = 100.0
    nt.links.new(r3.outputs[0], add.inputs[0])
    add.mute = True
    nt.links.new(add.outputs[0], bsdf.inputs["Roughness"])
    # A muted node without an internal link for the output used: its zero.
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.mute = True
    nt.links.new(noise.outputs["Fac"], bsdf.inputs["Metallic"])
    # A muted link: the input's own value.
    rgb = nt.nodes.new("ShaderNodeRGB")
    bsdf.inputs["Base Color"].default_value = (0.1, 0.2, 0.3, 1.0)
    lk = nt.links.new(rgb.outputs[0], bsdf.inputs["Base Color"])
    lk.is_muted = True
    # An invalid link (a closure into a float input): absent as well.
    sub = nt.nodes.new("ShaderNodeMath")
    sub.name = "IOR Math"
    sub.inputs[0].default_value = 1.25
    sub.inputs[1].default_value = 0.0
    bad = nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], sub.inputs[0])
    assert not bad.is_valid
    nt.links.new(sub.outputs[0], bsdf.inputs["IOR"])
    # Dangling reroutes (nothing at the chain's start): the input keeps its own value.
    r4, r5 = nt.nodes.new("NodeReroute"), nt.nodes.new("NodeReroute")
    nt.links.new(r5.outputs[0], r4.inputs[0])
    nt.links.new(r4.outputs[0], bsdf.inputs["Alpha"])
    bsdf.inputs["Alpha"].default_value = 0.625
    plane(scene, "M", [mat])
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Muted")
    _, b = node(g, "Principled BSDF")
    assert b["inputs"]["Roughness"] == link_to(g, "Value", "Value")  # through the mute + 3 reroutes
    assert b["inputs"]["Metallic"] == 0.0
    assert b["inputs"]["Base Color"] == pytest.approx([0.1, 0.2, 0.3, 1.0])
    _, ior = node(g, "IOR Math")
    assert ior["inputs"]["Value"] == pytest.approx(1.25)
    assert b["inputs"]["IOR"] == link_to(g, "IOR Math", "Value")
    assert b["inputs"]["Alpha"] == 0.625
    names = {n["name"] for n in g["nodes"]}
    assert not {"Muted Add", "Noise Texture", "RGB", "Diffuse BSDF"} & names
    assert not any(n["type"] == "NodeReroute" for n in g["nodes"])


# --------------------------------------------------------------------------------------------
# Color Ramp, RGB/Float/Vector Curves, the Mix node's unused sockets

def test_color_ramp_props_and_table(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Ramp")
    em = nt.nodes.new("ShaderNodeEmission")
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    cr = ramp.color_ramp
    cr.interpolation = "EASE"
    cr.color_mode = "HSV"
    cr.hue_interpolation = "FAR"
    cr.elements[0].position = 0.1
    cr.elements[0].color = (1.0, 0.0, 0.0, 1.0)
    cr.elements[1].position = 0.8
    cr.elements[1].color = (0.0, 0.0, 1.0, 0.5)
    mid = cr.elements.new(0.4)
    mid.color = (0.0, 1.0, 0.0, 1.0)
    nt.links.new(ramp.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    plane(scene, "R", [mat])
    doc, _ = export(tmp_path)
    _, r = node(graph_of(doc, "Ramp"), "Color Ramp")
    p = r["props"]
    assert (p["interpolation"], p["color_mode"], p["hue_interpolation"]) == ("EASE", "HSV", "FAR")
    assert [e["position"] for e in p["elements"]] == pytest.approx([0.1, 0.4, 0.8])
    assert p["elements"][2]["color"] == pytest.approx([0.0, 0.0, 1.0, 0.5])
    assert len(p["table"]) == 257
    for i in (0, 37, 128, 200, 256):
        assert p["table"][i] == pytest.approx(list(cr.evaluate(i / 256)), abs=1e-6)
    assert r["inputs"] == {"Fac": 0.5}


def test_curves_are_baked_like_cycles(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Curves")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    rgb = nt.nodes.new("ShaderNodeRGBCurve")
    m = rgb.mapping
    m.use_clip = False  # (with clipping, update() would move the points back into the clip box)
    m.curves[3].points[1].location = (1.0, 0.6)           # C (combined) curve
    m.curves[0].points.new(0.5, 0.9)                     # R curve
    m.curves[2].points[0].location = (-0.5, 0.2)         # B curve reaches below 0
    m.update()
    nt.links.new(rgb.outputs["Color"], bsdf.inputs["Base Color"])
    fc = nt.nodes.new("ShaderNodeFloatCurve")
    fm = fc.mapping
    fm.use_clip = False
    fm.curves[0].points[0].location = (-1.0, 0.0)
    fm.curves[0].points[1].location = (2.0, 3.0)
    fm.extend = "EXTRAPOLATED"
    fm.update()
    nt.links.new(fc.outputs["Value"], bsdf.inputs["Roughness"])
    vc = nt.nodes.new("ShaderNodeVectorCurve")
    vc.mapping.curves[1].points.new(0.0, 0.5)
    vc.mapping.update()
    nt.links.new(vc.outputs["Vector"], bsdf.inputs["Normal"])
    plane(scene, "C", [mat])
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Curves")
    _, r = node(g, "RGB Curves")
    p = r["props"]
    assert len(p["table"]) == 257 and len(p["table"][0]) == 3
    assert (p["min_x"], p["max_x"]) == (pytest.approx(-0.5), pytest.approx(1.0))
    m.initialize()
    for i in (0, 100, 256):
        t = -0.5 + i / 256 * 1.5
        c = m.evaluate(m.curves[3], t)
        want = [m.evaluate(m.curves[k], c) for k in range(3)]
        assert p["table"][i] == pytest.approx(want, abs=1e-6)
    assert p["extrapolate"] is (m.extend == "EXTRAPOLATED")
    _, f = node(g, "Float Curve")
    assert (f["props"]["min_x"], f["props"]["max_x"]) == (-1.0, 2.0)
    assert f["props"]["extrapolate"] is True
    assert len(f["props"]["table"]) == 257
    assert f["props"]["table"][256] == pytest.approx(3.0, abs=1e-5)
    assert f["props"]["table"][128] == pytest.approx(fm.evaluate(fm.curves[0], 0.5), abs=1e-6)
    _, v = node(g, "Vector Curves")
    assert len(v["props"]["table"][0]) == 3
    assert v["props"]["table"][128][1] == pytest.approx(
        vc.mapping.evaluate(vc.mapping.curves[1], 0.0), abs=1e-6)
    assert set(f["inputs"]) == {"Factor", "Value"}


def test_mix_node_unused_sockets_are_skipped_and_props_written(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("MixNodes")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    mf = nt.nodes.new("ShaderNodeMix")
    mf.name = "MixFloat"
    mf.clamp_factor = False
    ident(mf.inputs, "A_Float").default_value = 0.25
    nt.links.new(ident(mf.outputs, "Result_Float"), bsdf.inputs["Roughness"])
    mc = nt.nodes.new("ShaderNodeMix")
    mc.name = "MixColor"
    mc.data_type = "RGBA"
    mc.blend_type = "MULTIPLY"
    mc.clamp_result = True
    nt.links.new(ident(mc.outputs, "Result_Color"), bsdf.inputs["Base Color"])
    legacy = nt.nodes.new("ShaderNodeMixRGB")
    legacy.blend_type = "SCREEN"
    legacy.use_clamp = True
    legacy.inputs["Color2"].default_value = (0.9, 0.8, 0.7, 1.0)
    nt.links.new(legacy.outputs["Color"], bsdf.inputs["Emission Color"])
    voro = nt.nodes.new("ShaderNodeTexVoronoi")
    voro.voronoi_dimensions = "4D"
    voro.feature = "SMOOTH_F1"
    voro.distance = "MINKOWSKI"
    nt.links.new(voro.outputs["Distance"], bsdf.inputs["Coat Weight"])
    plane(scene, "X", [mat])
    doc, _ = export(tmp_path)
    g = graph_of(doc, "MixNodes")
    _, b = node(g, "Principled BSDF")
    assert b["inputs"]["Roughness"] == link_to(g, "MixFloat", "Result_Float")
    assert b["inputs"]["Base Color"] == link_to(g, "MixColor", "Result_Color")
    _, f = node(g, "MixFloat")
    assert set(f["inputs"]) == {"Factor_Float", "A_Float", "B_Float"}
    assert f["props"]["data_type"] == "FLOAT" and f["props"]["clamp_factor"] is False
    _, c = node(g, "MixColor")
    assert set(c["inputs"]) == {"Factor_Float", "A_Color", "B_Color"}
    assert c["props"]["blend_type"] == "MULTIPLY" and c["props"]["clamp_result"] is True
    # The legacy MixRGB arrives as a Mix node, its output renamed.
    li, lm = node(g, "Mix (Legacy)")
    assert b["inputs"]["Emission Color"] == {"link": [li, "Result_Color"]}
    assert lm["type"] == "ShaderNodeMix"
    assert lm["props"] == {"data_type": "RGBA", "factor_mode": "UNIFORM", "blend_type": "SCREEN",
                           "clamp_factor": True, "clamp_result": True}
    assert set(lm["inputs"]) == {"Factor_Float", "A_Color", "B_Color"}
    assert lm["inputs"]["B_Color"] == pytest.approx([0.9, 0.8, 0.7, 1.0])
    _, v = node(g, "Voronoi Texture")
    assert (v["props"]["voronoi_dimensions"], v["props"]["feature"], v["props"]["distance"]) == \
        ("4D", "SMOOTH_F1", "MINKOWSKI")
    assert {"W", "Smoothness", "Exponent"} <= set(v["inputs"])


def test_texture_coordinate_object_and_attribute_props(addon, tmp_path):
    scene = fresh_scene()
    empty = bpy.data.objects.new("Projector", None)
    empty.location = (1.0, 2.0, 3.0)
    empty.rotation_euler = (0.0, 0.0, math.pi / 2)
    scene.collection.objects.link(empty)
    mat, nt, out = new_material("Coords")
    em = nt.nodes.new("ShaderNodeEmission")
    tc = nt.nodes.new("ShaderNodeTexCoord")
    tc.object = empty
    tc.from_instancer = True
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "TEXTURE"
    mapping.inputs["Scale"].default_value = (2.0, 3.0, 4.0)
    wave = nt.nodes.new("ShaderNodeTexWave")
    wave.wave_type = "RINGS"
    wave.rings_direction = "Z"
    wave.wave_profile = "TRI"
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "Col"
    attr.attribute_type = "GEOMETRY"
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    nt.links.new(tc.outputs["Object"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], wave.inputs["Vector"])
    nt.links.new(wave.outputs["Color"], ident(mix.inputs, "A_Color"))
    nt.links.new(attr.outputs["Color"], ident(mix.inputs, "B_Color"))
    nt.links.new(ident(mix.outputs, "Result_Color"), em.inputs["Color"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    plane(scene, "T", [mat])
    bpy.context.view_layer.update()
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Coords")
    _, t = node(g, "Texture Coordinate")
    assert t["props"]["from_instancer"] is True
    assert np.allclose(t["props"]["object"], np.array(empty.matrix_world), atol=1e-6)
    _, mp = node(g, "Mapping")
    assert mp["props"] == {"vector_type": "TEXTURE"}
    assert mp["inputs"]["Vector"] == link_to(g, "Texture Coordinate", "Object")
    assert mp["inputs"]["Scale"] == pytest.approx([2.0, 3.0, 4.0])
    assert "Location" in mp["inputs"] and "Rotation" in mp["inputs"]
    _, w = node(g, "Wave Texture")
    assert (w["props"]["wave_type"], w["props"]["rings_direction"], w["props"]["wave_profile"]) == \
        ("RINGS", "Z", "TRI")
    _, a = node(g, "Attribute")
    assert a["props"] == {"attribute_type": "GEOMETRY", "attribute_name": "Col"}


# --------------------------------------------------------------------------------------------
# what the add-on reports, and the panel's store

def test_reports_once_per_material_and_node(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Troubled")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    inf = nt.nodes.new("ShaderNodeMath")
    inf.name = "Infinite"
    inf.inputs[0].default_value = float("nan")  # (RNA clamps infinities to FLT_MAX)
    inf.inputs[1].default_value = float("nan")
    nt.links.new(inf.outputs[0], bsdf.inputs["Roughness"])
    missing = bpy.data.images.new("Gone", 4, 4)
    missing.source = "FILE"
    missing.filepath = str(tmp_path / "does-not-exist.png")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.name = "Lost Texture"
    tex.image = missing
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    tex2 = nt.nodes.new("ShaderNodeTexImage")  # the same missing image on a second node
    tex2.name = "Lost Again"
    tex2.image = missing
    nt.links.new(tex2.outputs["Color"], bsdf.inputs["Emission Color"])
    plane(scene, "A", [mat])
    plane(scene, "B", [mat], location=(3, 0, 0))  # the same material twice: still once
    doc, _ = export(tmp_path)
    g = graph_of(doc, "Troubled")
    _, m = node(g, "Infinite")
    assert m["inputs"]["Value"] == 0.0 and m["inputs"]["Value_001"] == 0.0
    _, t = node(g, "Lost Texture")
    assert t["props"]["image"] is None
    assert "TESELA_images" not in doc.get("extensions", {})
    last = report.get(scene.name)
    assert last is not None
    addon_lines, renderer_lines = last.for_material("Troubled")
    assert renderer_lines == []
    text = "\n".join(addon_lines)
    # The Volume is exported for the renderer, which reports what it cannot render there.
    vi, _ = node(g, vol.name)
    assert g["volume"] == [vi, "Volume"]
    assert not any("volume" in ln for ln in addon_lines)
    assert sum("node 'Infinite'" in ln and "not finite" in ln for ln in addon_lines) == 1
    lost = [ln for ln in addon_lines if "'Gone' has no pixels" in ln]
    assert len(lost) == 2 and "node 'Lost Texture'" in text and "node 'Lost Again'" in text
    assert all(ln.startswith("material 'Troubled': ") for ln in addon_lines)
    # Another material's entry is empty; a new export replaces the report.
    assert last.for_material("Other") == ([], [])
    bsdf.inputs["Roughness"].default_value = 0.5
    nt.links.remove(next(lk for lk in nt.links if lk.to_socket == out.inputs["Volume"]))
    export(tmp_path, "again.gltf")
    again = report.get(scene.name)
    assert again is not last
    assert not any("volume" in ln for ln in again.for_material("Troubled")[0])


def test_fallback_report_parses_renderer_lines():
    r = report.FallbackReport()
    assert r.add_renderer_line("material 'Wood's \"best\"': node 'Noise (fine)' (ShaderNodeTexNoise) "
                               "is not supported: evaluated as muted")
    assert not r.add_renderer_line("rendering 64 samples")
    assert r.add_renderer_line("warning: material 'B': node 'X' (ShaderNodeScript) unsupported (OSL)")
    r.add_renderer_line("material 'B': node 'X' (ShaderNodeScript) unsupported (OSL)")  # duplicate
    # A shader node the renderer mutes says so in its own words.
    assert r.add_renderer_line("material 'Portal': shader node 'Ray Portal BSDF' "
                               "(ShaderNodeBsdfRayPortal) is not supported; it renders as muted")
    assert len(r.for_material("Portal")[1]) == 1
    addon_lines, lines = r.for_material("Wood's \"best\"")
    assert addon_lines == [] and len(lines) == 1 and "node 'Noise (fine)'" in lines[0]
    assert r.for_material("B")[1] == ["material 'B': node 'X' (ShaderNodeScript) unsupported (OSL)"]


FAKE_WITH_LOGS = r'''#!%(python)s
import os, sys, json
sys.path.insert(0, %(repo)r)
from blender_addon import protocol
args = sys.argv[1:]
w = int(args[args.index("--width") + 1]); h = int(args[args.index("--height") + 1])
out = sys.stdout.buffer
doc = json.load(open(args[1]))
names = [m["name"] for m in doc.get("materials", [])]
out.write(protocol.hello_frame(w, h, 1, 1))
out.write(protocol.log_frame(2, "material '%%s': node 'Magic' (ShaderNodeTexMagic) is not "
                             "supported; evaluated as muted" %% names[0]))
out.write(protocol.tile_frame(0, 0, w, h, bytes(w * h * 16)))
out.write(protocol.done_frame("{}"))
out.flush()
sys.stderr.write("material '%%s': node 'Bright' (ShaderNodeTexBrick) falls back to grey\n" %% names[0])
'''


def test_engine_files_renderer_lines_under_materials(addon, tmp_path, monkeypatch):
    scene = fresh_scene()
    mat, nt, out = new_material("Rendered")
    vol = nt.nodes.new("ShaderNodeVolumeScatter")
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    inf = nt.nodes.new("ShaderNodeMath")  # a value the add-on reports (written as 0)
    inf.name = "Infinite"
    inf.inputs[0].default_value = inf.inputs[1].default_value = float("nan")
    nt.links.new(inf.outputs[0], vol.inputs["Density"])
    plane(scene, "P", [mat])
    fake = tmp_path / "fake-logs"
    fake.write_text(FAKE_WITH_LOGS % {"python": sys.executable, "repo": str(REPO)})
    fake.chmod(0o755)
    monkeypatch.setenv("TESELA_BINARY", str(fake))
    report.clear()
    assert bpy.ops.render.render() == {"FINISHED"}
    last = report.get(scene.name)
    addon_lines, renderer_lines = last.for_material("Rendered")
    assert any("node 'Magic' (ShaderNodeTexMagic)" in ln for ln in renderer_lines)
    assert any("node 'Bright' (ShaderNodeTexBrick)" in ln for ln in renderer_lines)
    # The Material tab panel lists both.
    panel = bpy.types.TESELA_PT_material_fallbacks
    assert panel.bl_context == "material" and "TESELA" in panel.COMPAT_ENGINES
    drawn = []

    class Layout:
        def label(self, text="", icon="NONE"):
            drawn.append(text)

        def box(self):
            return self

        def column(self, align=False):
            return self

    from types import SimpleNamespace
    ctx = SimpleNamespace(material=mat, scene=scene, engine="TESELA")
    assert panel.poll(ctx)
    panel.draw(SimpleNamespace(layout=Layout()), ctx)
    assert "Add-on" in drawn and "Renderer" in drawn
    assert any(t.startswith("node 'Infinite'") for t in drawn)  # material prefix dropped
    assert any("node 'Magic' (ShaderNodeTexMagic)" in t for t in drawn)
    drawn.clear()
    panel.draw(SimpleNamespace(layout=Layout()), SimpleNamespace(material=bpy.data.materials.new("Clean"),
                                                                 scene=scene, engine="TESELA"))
    assert drawn == ["Nothing fell back in the last render"]


# --------------------------------------------------------------------------------------------
# mesh attributes and per-object data

def test_colors_texspace_and_object_info(addon, tmp_path):
    scene = fresh_scene()
    mat, nt, out = new_material("Painted")
    nt.links.new(nt.nodes.new("ShaderNodeBsdfDiffuse").outputs[0], out.inputs["Surface"])
    ob = plane(scene, "Painted", [mat], uv_names=())
    me = ob.data
    corner = me.color_attributes.new("Corner", "BYTE_COLOR", "CORNER")
    corner_vals = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1], [1, 1, 1, 0.5]], np.float32)
    corner.data.foreach_set("color", corner_vals.ravel())
    point = me.color_attributes.new("Point", "FLOAT_COLOR", "POINT")
    point_vals = np.array([[2.0, 0, 0, 1], [0, 3.0, 0, 1], [0, 0, 4.0, 1], [0.5, 0.5, 0.5, 1]], np.float32)
    point.data.foreach_set("color", point_vals.ravel())
    me.color_attributes.default_color_name = "Point"  # the render one: it comes first
    ob.pass_index = 7
    ob.color = (0.25, 0.5, 0.75, 1.0)
    ob.location = (1.0, -2.0, 0.5)
    doc, path = export(tmp_path)
    prim = next(m for m in doc["meshes"] if m["name"] == "Painted")["primitives"][0]
    assert prim["extras"]["tesela_color_names"] == ["Point", "Corner"]
    assert prim["extras"]["tesela_uv_names"] == []
    loop_vert = np.array([lp.vertex_index for lp in me.loops])
    c0 = read_accessor(doc, path, prim["attributes"]["COLOR_0"])
    assert np.allclose(c0, point_vals[loop_vert])
    c1 = read_accessor(doc, path, prim["attributes"]["COLOR_1"])
    want = np.empty(16, np.float32)
    corner.data.foreach_get("color", want)  # linear floats of the sRGB bytes
    assert np.allclose(c1, want.reshape(-1, 4), atol=1e-6)
    n = next(n for n in doc["nodes"] if n["name"] == "Painted")
    info = n["extras"]["tesela_object"]
    assert info["pass_index"] == 7
    assert info["color"] == pytest.approx([0.25, 0.5, 0.75, 1.0])
    assert info["location"] == pytest.approx([1.0, -2.0, 0.5])
    assert info["random_id"] == export_mesh.hash_uint2(export_mesh.hash_string("Painted"), 0)
    assert 0.0 <= info["random"] <= 1.0
    ts = n["extras"]["tesela_texspace"]
    assert ts["location"] == pytest.approx(list(me.texspace_location))
    assert ts["size"] == pytest.approx(list(me.texspace_size))


def _cycles_pixels(scene, tmp_path):
    scene.render.engine = "CYCLES"
    scene.cycles.samples = 1
    scene.cycles.device = "CPU"
    scene.cycles.use_denoising = False  # (the denoiser changes even a constant image)
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    s = scene.render.image_settings
    if hasattr(s, "media_type"):
        s.media_type = "IMAGE"
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    bpy.ops.render.render()
    p = tmp_path / "cycles.exr"
    bpy.data.images["Render Result"].save_render(str(p))
    img = bpy.data.images.load(str(p), check_existing=False)
    img.colorspace_settings.is_data = True
    buf = np.empty(len(img.pixels), np.float32)
    img.pixels.foreach_get(buf)
    w, h = img.size
    bpy.data.images.remove(img)
    scene.render.engine = "TESELA"
    return buf.reshape(h, w, 4)[::-1]


def test_object_info_random_matches_cycles(addon, tmp_path):
    """extras.tesela_object.random is the value Cycles' Object Info > Random gives, for an object
    (hash of its name) and for a collection instance (the instance's random_id)."""
    scene = fresh_scene()
    scene.render.resolution_x, scene.render.resolution_y = 8, 4
    scene.cycles.filter_width = 0.01  # every sample at its pixel's centre: no blending
    mat, nt, out = new_material("RandomEmit")
    em = nt.nodes.new("ShaderNodeEmission")
    info = nt.nodes.new("ShaderNodeObjectInfo")
    nt.links.new(info.outputs["Random"], em.inputs["Strength"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    left = plane(scene, "Left ü", [mat], uv_names=(), size=1.5, location=(-1.5, 0, 0))
    coll = bpy.data.collections.new("RandomInst")
    inner = bpy.data.objects.new("InstancedPlane", left.data)
    coll.objects.link(inner)
    empty = bpy.data.objects.new("Instancer", None)
    empty.instance_type = "COLLECTION"
    empty.instance_collection = coll
    empty.location = (1.5, 0, 0)
    scene.collection.objects.link(empty)
    cam = scene.camera
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 4.0
    cam.location = (0, 0, 5)
    cam.rotation_euler = (0, 0, 0)
    try:
        doc, _ = export(tmp_path)
        by_name = {n["name"]: n["extras"]["tesela_object"]["random"] for n in doc["nodes"]
                   if "extras" in n and "tesela_object" in n["extras"]}
        img = _cycles_pixels(scene, tmp_path)
    finally:
        cam.data.type = "PERSP"
        bpy.data.objects.remove(empty)
        bpy.data.objects.remove(inner)
        bpy.data.collections.remove(coll)
    assert set(by_name) == {"Left ü", "InstancedPlane"}
    assert by_name["Left ü"] != by_name["InstancedPlane"]
    # Emission strength = random: the pixels (white emission) carry it exactly.
    assert img.shape[:2] == (4, 8)
    assert img[1, 1, 0] == pytest.approx(by_name["Left ü"], rel=1e-5)
    assert img[2, 6, 0] == pytest.approx(by_name["InstancedPlane"], rel=1e-5)


def test_ngon_tangents_fall_back(addon, tmp_path):
    import bmesh
    scene = fresh_scene()
    mat, nt, out = new_material("NgonNormal")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    nm = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(nm.outputs[0], bsdf.inputs["Normal"])
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    me = bpy.data.meshes.new("Hexagon")
    bm = bmesh.new()
    bmesh.ops.create_circle(bm, cap_ends=True, segments=6, radius=1.0, calc_uvs=True)
    bm.to_mesh(me)
    bm.free()
    if not me.uv_layers:
        me.uv_layers.new(name="UVMap")
    me.materials.append(mat)
    ob = bpy.data.objects.new("Hexagon", me)
    scene.collection.objects.link(ob)
    doc, path = export(tmp_path)
    prim = next(m for m in doc["meshes"] if m["name"] == "Hexagon")["primitives"][0]
    tan = read_accessor(doc, path, prim["attributes"]["TANGENT"])
    assert np.allclose(np.linalg.norm(tan[:, :3], axis=1), 1.0)
    nrm = read_accessor(doc, path, prim["attributes"]["NORMAL"])
    assert np.allclose(np.einsum("ij,ij->i", tan[:, :3], nrm), 0.0, atol=1e-5)
    last = report.get(scene.name)
    assert last is not None
    assert any("n-gons" in w for w in scene_warnings(tmp_path))


def scene_warnings(tmp_path):
    from blender_addon import export as export_pkg
    dg = bpy.context.evaluated_depsgraph_get()
    res = export_pkg.write_gltf(dg, str(tmp_path / "w.gltf"), width=8, height=8)
    return res.warnings


# --------------------------------------------------------------------------------------------
# the 5.x vocabulary: compat.translate_node on legacy (3.x) nodes, checked without Blender 3.4

class _FakeSockets(dict):
    def get(self, key, default=None):
        return dict.get(self, key, default)


class _FakeNode:
    def __init__(self, sockets):
        self.inputs = _FakeSockets({k: object() for k in sockets})


def _translate(entry, sockets=()):
    nodes = [entry]

    def emit(e):
        nodes.append(e)
        return len(nodes) - 1
    moved = compat.translate_node(_FakeNode(sockets or entry["inputs"].keys()), entry, 0, emit)
    return nodes, moved or {}


def test_compat_principled_v1_fixed_values():
    entry = {"name": "P", "type": "ShaderNodeBsdfPrincipled",
             "props": {"distribution": "GGX", "subsurface_method": "BURLEY"},
             "inputs": {"Base Color": [0.8, 0.2, 0.2, 1.0], "Subsurface": 0.5,
                        "Subsurface Color": [0.2, 0.8, 0.2, 1.0], "Metallic": 0.25,
                        "Specular": 0.5, "Specular Tint": 0.5, "Sheen": 0.5, "Sheen Tint": 0.5,
                        "Clearcoat": 0.8, "Clearcoat Roughness": 0.1, "Transmission": 0.3,
                        "Transmission Roughness": 0.2, "Emission": [1.0, 0.5, 0.0, 1.0],
                        "Emission Strength": 2.0}, "internal_links": {}}
    nodes, moved = _translate(entry)
    assert len(nodes) == 1 and moved == {}
    i = entry["inputs"]
    assert "Transmission Roughness" not in i and "Subsurface Color" not in i
    assert i["Base Color"] == pytest.approx([0.5, 0.5, 0.2, 1.0])
    assert i["Subsurface Weight"] == 1.0 and i["Subsurface Scale"] == 0.5
    assert i["Coat Weight"] == pytest.approx(0.2) and i["Coat IOR"] == 1.5
    assert i["Coat Roughness"] == 0.1
    assert i["Sheen Weight"] == pytest.approx(0.1) and i["Sheen Tint"] == [1.0] * 4
    # tint = mix(one, mix(base, one, metallic), 0.5) with the post-subsurface base colour
    mm = [0.5 + 0.5 * 0.25, 0.5 + 0.5 * 0.25, 0.2 + 0.8 * 0.25, 1.0]
    assert i["Specular Tint"] == pytest.approx([1 + (m - 1) * 0.5 for m in mm])
    assert i["Specular IOR Level"] == 0.5 and i["Transmission Weight"] == 0.3
    assert i["Emission Color"] == [1.0, 0.5, 0.0, 1.0] and i["Emission Strength"] == 2.0
    assert not {"Subsurface", "Specular", "Transmission", "Clearcoat", "Sheen", "Emission"} & set(i)


def test_compat_principled_v1_linked_inputs_get_helper_nodes():
    tex = {"link": [7, "Color"]}
    fac = {"link": [8, "Fac"]}
    entry = {"name": "P", "type": "ShaderNodeBsdfPrincipled", "props": {},
             "inputs": {"Base Color": tex, "Subsurface": fac, "Subsurface Color": [0, 0, 1, 1],
                        "Metallic": 0.0, "Specular Tint": 0.3, "Sheen": fac, "Sheen Tint": 0.5,
                        "Clearcoat": fac}, "internal_links": {}}
    nodes, _ = _translate(entry)
    i = entry["inputs"]
    assert i["Subsurface Scale"] == fac and i["Subsurface Weight"] == 1.0
    mix = nodes[i["Base Color"]["link"][0]]
    assert mix["type"] == "ShaderNodeMix" and mix["props"]["data_type"] == "RGBA"
    assert mix["inputs"] == {"Factor_Float": fac, "A_Color": tex, "B_Color": [0, 0, 1, 1]}
    tint = nodes[i["Specular Tint"]["link"][0]]  # metallic 0: mix(one, base colour, 0.3)
    assert tint["inputs"] == {"Factor_Float": 0.3, "A_Color": [1.0] * 4, "B_Color": i["Base Color"]}
    assert i["Sheen Tint"] == [0.2, 0.2, 0.2, 1.0] and i["Sheen Weight"] == fac
    assert i["Coat IOR"] == 1.2 and i["Coat Weight"] == fac


def test_compat_musgrave_becomes_noise():
    entry = {"name": "M", "type": "ShaderNodeTexMusgrave",
             "props": {"musgrave_dimensions": "2D", "musgrave_type": "MULTIFRACTAL"},
             "inputs": {"Scale": 5.0, "Detail": 0.5, "Dimension": 1.5, "Lacunarity": 3.0},
             "internal_links": {}}
    nodes, moved = _translate(entry)
    assert entry["type"] == "ShaderNodeTexNoise"
    assert entry["props"] == {"noise_dimensions": "2D", "noise_type": "MULTIFRACTAL", "normalize": False}
    i = entry["inputs"]
    assert i["Roughness"] == pytest.approx(3.0 ** -1.5) and i["Lacunarity"] == 3.0
    assert i["Detail"] == 0.0
    add = nodes[moved["Fac"][0]]  # Fac * detail + (1 - detail)
    assert add["props"]["operation"] == "ADD" and add["inputs"]["Value_001"] == pytest.approx(0.5)
    mul = nodes[add["inputs"]["Value"]["link"][0]]
    assert mul["props"]["operation"] == "MULTIPLY"
    assert mul["inputs"] == {"Value": {"link": [0, "Fac"]}, "Value_001": 0.5}
    entry = {"name": "M", "type": "ShaderNodeTexMusgrave",
             "props": {"musgrave_dimensions": "3D", "musgrave_type": "FBM"},
             "inputs": {"Detail": 20.0, "Dimension": {"link": [3, "Value"]}, "Lacunarity": 2.0},
             "internal_links": {}}
    nodes, moved = _translate(entry)
    assert moved == {} and entry["inputs"]["Detail"] == 14.0
    pow_node = nodes[entry["inputs"]["Roughness"]["link"][0]]
    assert pow_node["props"]["operation"] == "POWER" and pow_node["inputs"]["Value"] == 2.0


def test_compat_legacy_nodes():
    e = {"name": "S", "type": "ShaderNodeSeparateRGB", "props": {},
         "inputs": {"Image": [1, 0, 0, 1]}, "internal_links": {}}
    _, moved = _translate(e)
    assert e["type"] == "ShaderNodeSeparateColor" and e["props"] == {"mode": "RGB"}
    assert e["inputs"] == {"Color": [1, 0, 0, 1]} and moved["G"] == [0, "Green"]
    e = {"name": "C", "type": "ShaderNodeCombineHSV", "props": {},
         "inputs": {"H": 0.1, "S": 0.2, "V": 0.3}, "internal_links": {"Color": "H"}}
    _, moved = _translate(e)
    assert e["type"] == "ShaderNodeCombineColor" and e["props"] == {"mode": "HSV"}
    assert e["inputs"] == {"Red": 0.1, "Green": 0.2, "Blue": 0.3}
    assert e["internal_links"] == {"Color": "Red"}
    e = {"name": "G", "type": "ShaderNodeBsdfGlossy", "props": {"distribution": "SHARP"},
         "inputs": {"Roughness": {"link": [2, "Fac"]}}, "internal_links": {}}
    _translate(e)
    assert e["type"] == "ShaderNodeBsdfAnisotropic"
    assert e["props"] == {"distribution": "GGX"} and e["inputs"]["Roughness"] == 0.0
    e = {"name": "V", "type": "ShaderNodeBsdfVelvet", "props": {}, "inputs": {"Sigma": 0.7},
         "internal_links": {}}
    _translate(e)
    assert e["type"] == "ShaderNodeBsdfSheen" and e["props"] == {"distribution": "ASHIKHMIN"}
    assert e["inputs"] == {"Roughness": 0.7}
    e = {"name": "N", "type": "ShaderNodeTexNoise", "props": {"noise_dimensions": "3D"},
         "inputs": {"Roughness": 1.5}, "internal_links": {}}
    _translate(e)
    assert e["props"] == {"noise_dimensions": "3D", "noise_type": "FBM", "normalize": True}
    assert e["inputs"]["Roughness"] == 1.0


def test_cycles_hashes():
    # Reference values computed from Cycles' util/hash.h (hash_string, hash_uint2).
    assert export_mesh.hash_string("") == 0
    assert export_mesh.hash_string("ab") == (97 * 37 + 98)
    assert export_mesh.hash_string("\u00fc") == 0xC3 * 37 + 0xBC  # UTF-8 bytes, unsigned
    assert export_mesh.random_number(0xFFFFFFFF) == 1.0
    assert export_mesh.random_number(0) == 0.0


# --------------------------------------------------------------------------------------------
# glTF validity of everything at once

def test_graph_scene_passes_khronos_validator(addon, tmp_path):
    from test_addon import validate
    (tmp_path / "a").mkdir()
    test_pbr_asset_images_uvs_tangents(addon, tmp_path / "a")
    scene = bpy.context.scene
    ob = scene.objects["Asset"]
    col = ob.data.color_attributes.new("Col", "FLOAT_COLOR", "CORNER")
    col.data.foreach_set("color", np.full(16, 0.5, np.float32))
    dest = tmp_path / "v"
    dest.mkdir()
    doc, path = export(dest, "scene.gltf")
    assert "TANGENT" in doc["meshes"][0]["primitives"][0]["attributes"]
    rep = validate(path)
    issues = rep["issues"]
    assert issues["numErrors"] == 0 and issues["numWarnings"] == 0, \
        json.dumps(issues["messages"], indent=1)[:3000]


# --------------------------------------------------------------------------------------------
# Blender 3.4: legacy nodes and sockets arrive in the 5.x vocabulary

@pytest.mark.skipif(BLENDER34 is None, reason="no 'blender' executable (Debian package 'blender')")
def test_blender34_graph_uses_5x_vocabulary(tmp_path):
    base = tmp_path
    scripts = base / "scripts"
    shutil.copytree(REPO / "blender_addon", scripts / "addons" / "tesela",
                    ignore=shutil.ignore_patterns("__pycache__"))
    env = dict(os.environ, BLENDER_USER_SCRIPTS=str(scripts), HOME=str(base / "home"),
               XDG_CONFIG_HOME=str(base / "xdg"), BLENDER_USER_CONFIG=str(base / "config"))
    out = base / "graph34.gltf"
    t0 = time.monotonic()
    p = subprocess.run([BLENDER34, "-b", "--factory-startup", "--addons", "tesela", "--python",
                        str(HERE / "blender34_material_graph.py"), "--", str(out)],
                       env=env, capture_output=True, text=True, timeout=180)
    assert "TESELA_GRAPH_EXPORTED" in p.stdout, p.stdout[-3000:] + p.stderr[-3000:]
    print("Blender 3.4 export in %.1f s" % (time.monotonic() - t0))
    doc = json.loads(out.read_text(encoding="utf-8"))
    legacy = {"ShaderNodeMixRGB", "ShaderNodeSeparateRGB", "ShaderNodeCombineRGB",
              "ShaderNodeTexMusgrave", "ShaderNodeBsdfVelvet", "ShaderNodeBsdfGlossy",
              "ShaderNodeGroup", "NodeReroute", "NodeGroupInput", "NodeGroupOutput"}
    for m in doc["materials"]:
        g = m.get("extensions", {}).get("TESELA_material_graph")
        if g is not None:
            assert not legacy & {n["type"] for n in g["nodes"]}, m["name"]

    g = graph_of(doc, "Legacy Principled")
    _, b = node(g, "Principled BSDF")
    i = b["inputs"]
    assert not {"Clearcoat", "Subsurface", "Subsurface Color", "Specular", "Sheen", "Emission",
                "Transmission", "Transmission Roughness"} & set(i)
    assert i["Coat Weight"] == pytest.approx(0.25 * 0.6) and i["Coat IOR"] == 1.5
    assert i["Sheen Weight"] == pytest.approx(0.2 * 0.5) and i["Sheen Tint"] == [1.0] * 4
    assert i["Subsurface Weight"] == 1.0 and i["Subsurface Scale"] == pytest.approx(0.5)
    # Base colour mixed with the subsurface colour (linked texture: a helper Mix node).
    mix = g["nodes"][i["Base Color"]["link"][0]]
    assert mix["type"] == "ShaderNodeMix" and mix["inputs"]["Factor_Float"] == pytest.approx(0.5)
    assert mix["inputs"]["A_Color"] == link_to(g, "Image Texture", "Color")
    assert i["Emission Color"] == pytest.approx([1.0, 0.5, 0.25, 1.0])
    assert i["Specular IOR Level"] == pytest.approx(0.4)
    assert i["Transmission Weight"] == pytest.approx(0.1)
    assert b["props"]["subsurface_method"] == "RANDOM_WALK_SKIN"  # 3.x "Random Walk"
    assert i["Roughness"] == link_to(g, "Mix (Legacy)", "Result_Color")  # MixRGB's output, renamed
    _, mx = node(g, "Mix (Legacy)")
    assert mx["type"] == "ShaderNodeMix" and mx["props"]["blend_type"] == "MULTIPLY"
    assert mx["props"]["data_type"] == "RGBA" and mx["props"]["clamp_factor"] is True
    assert mx["inputs"]["A_Color"] == link_to(g, "Separate RGB (Legacy)", "Red")
    _, sep = node(g, "Separate RGB (Legacy)")
    assert sep["type"] == "ShaderNodeSeparateColor" and sep["props"] == {"mode": "RGB"}
    assert sep["inputs"] == {"Color": link_to(g, "Image Texture", "Color")}
    # Normal map: tangents in the mesh
    prim = next(m for m in doc["meshes"] if m["name"] == "Legacy")["primitives"][0]
    assert "TANGENT" in prim["attributes"]
    assert prim["extras"]["tesela_uv_names"] == ["UVMap", "Second"]

    wg = doc["extensions"]["TESELA_world"]["graph"]
    _, sky = node(wg, "Nishita Sky")
    assert sky["props"]["sky_type"] == "SINGLE_SCATTERING"
    assert sky["props"]["aerosol_density"] == pytest.approx(2.5)
    assert "dust_density" not in sky["props"]
    assert sky["props"]["sun_elevation"] == pytest.approx(0.5)

    g = graph_of(doc, "Legacy Textures")
    _, mus = node(g, "Musgrave Texture")
    assert mus["type"] == "ShaderNodeTexNoise"
    assert mus["props"] == {"noise_dimensions": "3D", "noise_type": "RIDGED_MULTIFRACTAL",
                            "normalize": False}
    assert mus["inputs"]["Roughness"] == pytest.approx(2.0 ** -1.0)
    assert mus["inputs"]["Detail"] == pytest.approx(3.0)
    _, noise = node(g, "Noise Texture")
    assert noise["props"]["noise_type"] == "FBM" and noise["props"]["normalize"] is True
    assert noise["inputs"]["Roughness"] == 0.5
    assert "Lacunarity" not in noise["inputs"]  # 3.x noise: always 2, the 5.x default
    _, gl = node(g, "Glossy BSDF")
    assert gl["type"] == "ShaderNodeBsdfAnisotropic"
    assert gl["props"]["distribution"] == "GGX" and gl["inputs"]["Roughness"] == 0.0  # was Sharp
    _, velvet = node(g, "Velvet BSDF")
    assert velvet["type"] == "ShaderNodeBsdfSheen" and velvet["inputs"]["Roughness"] == pytest.approx(0.7)
    # groups, reroutes, mutes in 3.4
    _, mth = node(g, "Math", "LegacyGroup")
    assert mth["inputs"]["Value_001"] == pytest.approx(0.9)
    assert mth["inputs"]["Value"] == link_to(g, "Value", "Value")  # through a muted node
    _, ramp = node(g, "ColorRamp")
    assert len(ramp["props"]["table"]) == 257 and ramp["props"]["interpolation"] == "CONSTANT"
    _, curves = node(g, "RGB Curves")
    assert len(curves["props"]["table"]) == 257
    imgs = doc["extensions"]["TESELA_images"]["images"]
    fl = next(e for e in imgs if e["name"] == "HDR34")
    assert fl["component"] in ("f16", "f32")
    assert image_rows(doc, out, fl).max() == pytest.approx(6.5)


# --------------------------------------------------------------------------------------------
# the renderer loads what the add-on writes

GRAPH_SCENES = ("test_pbr_asset_images_uvs_tangents", "test_half_float_image_travels_as_f16",
                "test_mix_shader_by_layer_weight", "test_nested_groups_are_inlined",
                "test_unlinked_group_output_and_empty_group", "test_muted_nodes_links_and_reroutes",
                "test_color_ramp_props_and_table", "test_curves_are_baked_like_cycles",
                "test_mix_node_unused_sockets_are_skipped_and_props_written",
                "test_texture_coordinate_object_and_attribute_props",
                "test_colors_texspace_and_object_info", "test_reports_once_per_material_and_node")


@pytest.mark.parametrize("name", GRAPH_SCENES)
def test_renderer_loads_the_graph(addon, tesela_bin, tmp_path, name):
    globals()[name](addon, tmp_path)
    r = subprocess.run([str(tesela_bin), "render", str(tmp_path / "graph.gltf"), "-o",
                        str(tmp_path / "out.exr"), "--spp", "1", "--width", "8", "--height", "8",
                        "--threads", "1", "-q"], capture_output=True, text=True, timeout=120)
    print(r.stderr[-3000:])
    assert r.returncode == 0, r.stderr[-3000:]
    assert (tmp_path / "out.exr").is_file()
