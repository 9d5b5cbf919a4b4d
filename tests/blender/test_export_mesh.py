"""The mesh writer (blender_addon/export/mesh.py) against a reference built the plain way: every
attribute read per corner through the item-by-item Blender API (one glTF vertex per corner, as
the writer once did). Whatever the writer shares between corners, each triangle corner must
read bitwise what the reference gives it: positions, normals (smooth, sharp edges, custom; flat
triangles: their own normal, as Cycles shades them, within a small step), UV maps, colour
attributes (corner and point), MikkTSpace and n-gon tangents, material indices.
"""

import math
import sys
from pathlib import Path

import bmesh
import bpy
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from blender_addon import compat  # noqa: E402
from blender_addon.export import mesh as export_mesh  # noqa: E402

import scenes  # noqa: E402


def _sphere(name, smooth=True, segments=24, rings=12):
    """A UV sphere with Blender's UV map (a seam down one side) and two materials in bands."""
    me = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=1.0,
                              calc_uvs=True)
    scenes.canonical_order(bm)  # the bands below follow the face order
    bm.to_mesh(me)
    bm.free()
    me.polygons.foreach_set("use_smooth", np.full(len(me.polygons), smooth))
    me.polygons.foreach_set("material_index",
                            (np.arange(len(me.polygons)) // segments % 2).astype(np.int32))
    me.update()
    return me


def _grid(name, n=6):
    """n x n smooth quads, a UV map without seams: every corner of a vertex shares it."""
    verts = [(i, j, 0.1 * math.sin(i + 2 * j)) for j in range(n + 1) for i in range(n + 1)]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i) for j in range(n) for i in range(n)]
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.polygons.foreach_set("use_smooth", np.ones(len(me.polygons), dtype=bool))
    uv = me.uv_layers.new(name="UVMap")
    co = np.array(verts, dtype=np.float32)[:, :2] / n
    lv = np.empty(len(me.loops), dtype=np.int32)
    me.loops.foreach_get("vertex_index", lv)
    uv.data.foreach_set("uv", co[lv].reshape(-1))
    me.update()
    return me


def _reference(mesh, tangent_uv=None):
    """Per-corner arrays and triangle corners read item by item (no fast paths)."""
    mesh.calc_loop_triangles()
    nt, nl, nv = len(mesh.loop_triangles), len(mesh.loops), len(mesh.vertices)
    tri = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", tri)
    mat = np.empty(nt, dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", mat)
    lv = np.empty(nl, dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", lv)
    co = np.empty(nv * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    nrm = np.empty(nl * 3, dtype=np.float32)
    mesh.corner_normals.foreach_get("vector", nrm)
    nrm = nrm.reshape(-1, 3)
    # Cycles' normals: Blender's corner normals with sharp edges or custom normals; else the
    # smooth faces take the vertex normals and the flat ones each triangle's own normal.
    loop_face_of_tri = np.empty(nt, dtype=np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", loop_face_of_tri)
    smooth = np.array([f.use_smooth for f in mesh.polygons])
    sharp_edges = any(e.use_edge_sharp for e in mesh.edges)
    flat = np.zeros(nt, dtype=bool)
    if mesh.normals_domain == "FACE":
        flat[:] = True
    elif not (mesh.has_custom_normals or sharp_edges):
        vn = np.array([tuple(v.normal) for v in mesh.vertices], dtype=np.float32)
        nrm = vn[lv]
        flat = ~smooth[loop_face_of_tri]
    ref = {"tri": tri.reshape(-1, 3), "mat": mat, "POSITION": co.reshape(-1, 3)[lv],
           "NORMAL": nrm, "flat": flat}
    for i, layer in enumerate(compat.uv_layers(mesh)):
        uv = np.empty(nl * 2, dtype=np.float32)
        layer.data.foreach_get("uv", uv)
        uv = uv.reshape(-1, 2)
        uv[:, 1] = 1.0 - uv[:, 1]
        ref["TEXCOORD_%d" % i] = uv
    loop_face = np.empty(nl, dtype=np.int32)
    for f in mesh.polygons:
        loop_face[f.loop_start:f.loop_start + f.loop_total] = f.index
    for i, (_, domain, data) in enumerate(compat.color_layers(mesh)):
        col = np.array([tuple(c.color) for c in data], dtype=np.float32)
        ref["COLOR_%d" % i] = (col if domain == "CORNER" else col[loop_face]
                               if domain == "FACE" else col[lv])
    if tangent_uv is not None:
        mesh.calc_tangents(uvmap=tangent_uv)
        t = np.empty(nl * 3, dtype=np.float32)
        mesh.loops.foreach_get("tangent", t)
        s = np.empty(nl, dtype=np.float32)
        mesh.loops.foreach_get("bitangent_sign", s)
        mesh.free_tangents()
        ref["TANGENT"] = export_mesh._tangent_vec4(t.reshape(-1, 3), s, ref["NORMAL"])
    return ref


def _written(data):
    arrays = {"POSITION": data.positions, "NORMAL": data.normals}
    for i, (_, uv) in enumerate(data.uv_sets):
        arrays["TEXCOORD_%d" % i] = uv
    for i, (_, col) in enumerate(data.color_sets):
        arrays["COLOR_%d" % i] = col
    if data.tangents is not None:
        arrays["TANGENT"] = data.tangents
    return arrays


def _assert_same_corners(mesh, tangent_uvs=None, tangent_uv=None):
    """The writer's triangles read bitwise what the reference's do; returns the MeshData."""
    data = export_mesh.mesh_arrays(mesh, tangent_uvs=tangent_uvs)
    ref = _reference(mesh, tangent_uv)
    assert np.array_equal(data.tri_material, ref["mat"])
    written = _written(data)
    assert set(written) == set(ref) - {"tri", "mat", "flat"}
    idx = data.indices.astype(np.int64)
    assert idx.shape == ref["tri"].shape and idx.max() < data.positions.shape[0]
    flat = ref["flat"]
    for name, values in written.items():
        assert values.dtype == np.float32 and values.flags.c_contiguous, name
        got, want = values[idx], ref[name][ref["tri"]]
        if name == "NORMAL":
            # Flat triangles: their own geometric normal (within the step that lets the two
            # halves of a planar quad share vertices).
            p = ref["POSITION"][ref["tri"][flat]].astype(np.float64)
            ng = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
            ng /= np.linalg.norm(ng, axis=1, keepdims=True)
            assert not flat.any() or np.abs(got[flat] - ng[:, None, :]).max() < 1e-4, name
            got, want = got[~flat], want[~flat]
        assert np.array_equal(got.view(np.uint32), want.view(np.uint32)), name
    return data


@pytest.fixture
def clean():
    scenes.clear_scene()
    yield
    for me in list(bpy.data.meshes):
        bpy.data.meshes.remove(me)


def test_smooth_grid_shares_every_vertex(clean):
    me = _grid("Grid")
    assert compat.normals(me, len(me.loops))[0] == "POINT"
    data = _assert_same_corners(me)
    assert data.positions.shape[0] == len(me.vertices)  # 144 corners, 49 vertices


def test_uv_seam_and_materials(clean):
    me = _sphere("Ball")
    col = me.color_attributes.new("Paint", "FLOAT_COLOR", "CORNER")
    rgba = np.random.default_rng(3).random((len(me.vertices), 4)).astype(np.float32)
    lv = np.empty(len(me.loops), dtype=np.int32)
    me.loops.foreach_get("vertex_index", lv)
    col.data.foreach_set("color", rgba[lv].reshape(-1))  # painted per vertex
    pt = me.color_attributes.new("Dirt", "FLOAT_COLOR", "POINT")
    pt.data.foreach_set("color", rgba[::-1].copy().reshape(-1))
    data = _assert_same_corners(me)
    # Vertices split where the UV map has a seam (and at the poles' fans), nowhere else.
    uv = me.uv_layers["UVMap"].uv
    distinct = {(int(v), tuple(uv[c].vector)) for c, v in enumerate(lv)}
    assert len(me.vertices) < data.positions.shape[0] <= len(distinct) + len(me.vertices) // 4
    assert data.positions.shape[0] < len(me.loops)


def test_face_colours_reach_every_corner_of_their_face(clean):
    me = _sphere("Tiles")
    face = me.attributes.new("Tiles", "FLOAT_COLOR", "FACE")  # not a colour attribute
    rgba = np.random.default_rng(5).random((len(me.polygons), 4)).astype(np.float32)
    face.data.foreach_set("color", rgba.reshape(-1))
    byte = me.attributes.new("Bytes", "BYTE_COLOR", "FACE")
    byte.data.foreach_set("color", rgba[::-1].copy().reshape(-1))
    data = _assert_same_corners(me)
    assert len(data.color_sets) == 2


def test_named_attributes_travel_as_colour_layers(clean):
    """Float, boolean and vector attributes (Geometry Nodes' Store Named Attribute) reach
    every corner as colour layers in Cycles' conversions: (f, f, f, 1), (x, y, z, 1); UV maps
    and Blender's own attributes stay out."""
    me = _grid("Attrs")
    n, nf = len(me.vertices), len(me.polygons)
    height = np.linspace(0.0, 1.0, n, dtype=np.float32)
    me.attributes.new("height", "FLOAT", "POINT").data.foreach_set("value", height)
    mask = np.arange(n) % 3 == 0
    me.attributes.new("mask", "BOOLEAN", "POINT").data.foreach_set("value", mask)
    flow = np.random.default_rng(9).random((nf, 3)).astype(np.float32)
    me.attributes.new("flow", "FLOAT_VECTOR", "FACE").data.foreach_set("vector", flow.ravel())
    data = export_mesh.mesh_arrays(me)
    layers = dict(data.color_sets)
    assert set(layers) == {"height", "mask", "flow"}
    # glTF vertex -> Blender vertex by position (the grid's are distinct).
    co = np.empty(n * 3, dtype=np.float32)
    me.vertices.foreach_get("co", co)
    key = {tuple(p): i for i, p in enumerate(co.reshape(-1, 3).round(5))}
    vert = np.array([key[tuple(p)] for p in data.positions.round(5)])
    for name, want in (("height", height), ("mask", mask.astype(np.float32))):
        got = layers[name]
        assert np.array_equal(got[:, :3], np.repeat(want[vert][:, None], 3, axis=1)), name
        assert np.all(got[:, 3] == 1.0), name
    # Each triangle's corners carry its face's vector.
    me.calc_loop_triangles()
    tri_face = np.empty(len(me.loop_triangles), dtype=np.int32)
    me.loop_triangles.foreach_get("polygon_index", tri_face)
    got = layers["flow"][data.indices.astype(np.int64)]
    assert np.array_equal(got[..., :3], np.repeat(flow[tri_face][:, None, :], 3, axis=1))


def test_flat_shading(clean):
    me = _sphere("Facets", smooth=False)
    assert compat.normals(me, len(me.loops))[0] == "FACE"
    _assert_same_corners(me)


def test_flat_faces_of_a_smooth_mesh_and_non_planar_faces(clean):
    """Flat faces among smooth ones without sharp edges (Cycles: the smooth faces take the
    vertex normals, the flat ones each triangle's normal), and non-planar flat quads."""
    me = _sphere("Mixed")
    me.polygons.foreach_set("use_smooth", np.arange(len(me.polygons)) % 5 != 0)
    me.update()
    assert compat.normals(me, len(me.loops))[0] == "CORNER"
    assert compat.cycles_normals(me, len(me.loops), len(me.polygons))[0] == "POINT"
    _assert_same_corners(me)
    bumpy = _grid("Bumpy")  # sin-displaced grid: no quad is planar
    bumpy.polygons.foreach_set("use_smooth", np.zeros(len(bumpy.polygons), dtype=bool))
    bumpy.update()
    data = _assert_same_corners(bumpy)
    # Each quad's two triangles have normals of their own: more vertices than corners.
    assert data.positions.shape[0] == 2 * 3 * len(bumpy.polygons)


def test_sharp_edges_and_custom_normals(clean):
    me = _sphere("Sharp")
    me.set_sharp_from_angle(angle=math.radians(10.0))  # 15 degree steps: every edge sharp
    me.edges.foreach_set("use_edge_sharp", np.arange(len(me.edges)) % 3 == 0)
    me.update()
    assert compat.normals(me, len(me.loops))[0] == "CORNER"
    _assert_same_corners(me)
    custom = _sphere("Custom")
    vn = np.empty(3 * len(custom.vertices), dtype=np.float32)
    custom.vertices.foreach_get("co", vn)
    vn = vn.reshape(-1, 3) + (0.4, 0.0, 0.0)
    custom.normals_split_custom_set_from_vertices(vn / np.linalg.norm(vn, axis=1)[:, None])
    assert compat.normals(custom, len(custom.loops))[0] == "CORNER"
    _assert_same_corners(custom)


def test_mikktspace_tangents(clean):
    me = _sphere("Mapped")
    data = _assert_same_corners(me, tangent_uvs={""}, tangent_uv="UVMap")
    assert data.tangent_uv == "UVMap"


def test_ngon_face_tangents(clean):
    """n-gons: Blender refuses MikkTSpace, the writer approximates per face; the shared vertices
    must not change what the approximation gives each corner."""
    me = bpy.data.meshes.new("Prism")
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_cone(bm, cap_ends=True, segments=9, radius1=1.0, radius2=1.0, depth=1.0,
                          calc_uvs=True)
    bm.to_mesh(me)
    bm.free()
    me.polygons.foreach_set("use_smooth", np.ones(len(me.polygons), dtype=bool))
    me.update()
    ref = export_mesh.mesh_arrays(me, tangent_uvs={""})
    warnings = []
    data = export_mesh.mesh_arrays(me, tangent_uvs={""}, warn=warnings.append, label="Prism")
    assert any("n-gons" in w for w in warnings)
    # The approximation from one glTF vertex per corner, as the writer computed it before.
    plain = _reference(me)
    uv = np.empty(2 * len(me.loops), dtype=np.float32)
    me.uv_layers[0].data.foreach_get("uv", uv)
    t, s = export_mesh._face_tangents(plain["POSITION"], plain["NORMAL"], uv.reshape(-1, 2),
                                      plain["tri"])
    want = export_mesh._tangent_vec4(t, s, plain["NORMAL"])[plain["tri"]]
    got = data.tangents[data.indices.astype(np.int64)]
    assert np.array_equal(got.view(np.uint32), want.view(np.uint32))
    assert np.array_equal(ref.tangents, data.tangents)


def test_fast_reads_match_the_item_by_item_api(clean):
    me = _sphere("Reads")
    me.calc_loop_triangles()
    nt, nl = len(me.loop_triangles), len(me.loops)
    tri = np.empty(nt * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("loops", tri)
    assert np.array_equal(compat.loop_triangle_corners(me, nt).reshape(-1), tri)
    lv = np.empty(nl, dtype=np.int32)
    me.loops.foreach_get("vertex_index", lv)
    assert np.array_equal(compat.corner_verts(me, nl), lv)
    faces = np.empty(nt, dtype=np.int32)
    me.loop_triangles.foreach_get("polygon_index", faces)
    assert np.array_equal(compat.loop_triangle_faces(me, nt), faces)
    n_faces = len(me.polygons)
    starts = np.empty(n_faces, dtype=np.int32)
    me.polygons.foreach_get("loop_start", starts)
    assert np.array_equal(compat.face_starts(me, n_faces), starts)
    mats = np.empty(n_faces, dtype=np.int32)
    me.polygons.foreach_get("material_index", mats)
    assert mats.max() == 1 and np.array_equal(compat.face_materials(me, n_faces), mats)
    # In-place reads check what they read: vertex items point at the positions, so reading
    # their normals there must be refused, not return positions.
    nv = len(me.vertices)
    co = np.empty(nv * 3, dtype=np.float32)
    me.vertices.foreach_get("co", co)
    placed = compat._read_in_place(me.vertices, nv, np.float32, 3, "co")
    assert placed is not None and np.array_equal(placed.reshape(-1), co)
    assert compat._read_in_place(me.vertices, nv, np.float32, 3, "normal") is None


def test_hair_particle_systems_are_exported_as_curves(tmp_path):
    """Hair strands (a particle system drawn as paths) are exported as TESELA_curves on a node
    of their own, one strand per particle, without a warning; the emitter itself is still
    exported, and a system disabled for renders, or emitter particles, add nothing."""
    import json

    from blender_addon import export

    scenes.clear_scene()
    ob = scenes.add_sphere("Furry", (0, 0, 0), 0.5)
    hair = ob.modifiers.new("Fur", "PARTICLE_SYSTEM").particle_system
    hair.name = "Fur"
    hair.settings.type, hair.settings.count = "HAIR", 50
    off = scenes.add_sphere("Shaved", (2, 0, 0), 0.5)
    mod = off.modifiers.new("Off", "PARTICLE_SYSTEM")
    mod.particle_system.settings.type = "HAIR"
    mod.show_render = False
    dust = scenes.add_sphere("Dusty", (-2, 0, 0), 0.5)
    dust.modifiers.new("Dust", "PARTICLE_SYSTEM").particle_system.settings.type = "EMITTER"
    scenes.add_camera((0, -5, 0), (0, 0, 0))
    dg = bpy.context.evaluated_depsgraph_get()
    path = tmp_path / "h.gltf"
    res = export.write_gltf(dg, str(path), width=8, height=8)
    assert not [w for w in res.warnings if "hair" in w], res.warnings
    doc = json.loads(path.read_text(encoding="utf-8"))
    strands = [n for n in doc["nodes"] if "TESELA_curves" in n.get("extensions", {})]
    assert [n["name"] for n in strands] == ["Furry Fur"]
    offsets = doc["accessors"][strands[0]["extensions"]["TESELA_curves"]["offsets"]]
    assert offsets["count"] == 51, "one strand per hair particle"
    assert res.triangles >= 3 * 24 * 10, "the emitters are still exported"
