# SPDX-License-Identifier: MIT
"""Evaluated meshes -> glTF vertex data (numpy, foreach_get), and the per-object extras.

One glTF vertex per face corner (Blender loop): split normals, every UV map (TEXCOORD_n, the
active render map first), every colour attribute (COLOR_n, float RGBA, point colours expanded to
corners), and MikkTSpace tangents (TANGENT) when a material needs them. Data stays in object
space, in Blender's coordinates; the node matrices turn Z-up into Y-up.
"""

import hashlib

import numpy as np

from .. import compat
from .attributes import object_attributes
from .common import ExportCancelled, Phases

MESHLIKE = {"MESH", "CURVE", "SURFACE", "FONT", "META", "CURVES_LEGACY"}


def geometry_key(obj):
    """What identifies an evaluated object's geometry within one depsgraph.

    Mesh objects that share a mesh datablock and have no modifiers (Alt+D duplicates) share one
    evaluated mesh: their evaluated obj.data is the same datablock, measured in Blender 3.4 and
    5.0, so the data alone is the key and the mesh is exported once. With modifiers every object
    evaluates its own mesh (a distinct obj.data, measured too), and other types (curves, text)
    build their mesh per object: the object's name stays part of their key."""
    data = obj.data
    ptr = data.as_pointer() if data is not None else 0
    if obj.type == "MESH" and len(obj.modifiers) == 0:
        return ("mesh", ptr)
    return ("object", obj.name, ptr)


class MeshData:
    """The arrays of one evaluated mesh, ready for the buffer."""

    def __init__(self):
        self.positions = None   # float32 (n, 3)
        self.normals = None     # float32 (n, 3)
        self.uv_sets = []       # [(name, float32 (n, 2))], glTF orientation (v flipped)
        self.color_sets = []    # [(name, float32 (n, 4))], linear RGBA
        self.tangents = None    # float32 (n, 4): xyz + bitangent sign, or None
        self.tangent_uv = None  # the UV map the tangents belong to
        self.indices = None     # uint32 (t, 3)
        self.tri_material = None
        self.texspace = None    # (location, size)

    @property
    def uv(self):
        return self.uv_sets[0][1] if self.uv_sets else None


class RawMesh:
    """What the glTF arrays of an evaluated mesh are computed from, as far as Blender copies it
    at once (foreach_get on contiguous data): positions, topology, face materials, corner
    normals, UV maps, colours, texture space. The loop triangles (which Blender copies
    triangle by triangle, slowly) follow from these, so a digest of them is a digest of the
    mesh's export."""

    def __init__(self):
        self.loop_vert = None    # int32 (n_loops,): each corner's vertex
        self.loop_start = None   # int32 (n_polys,): each face's first corner
        self.face_material = None  # int32 (n_polys,)
        self.co = None           # float32 (n_verts, 3)
        self.normal_domain = None  # "POINT", "FACE" or "CORNER": what `normals` has one of
        self.normals = None      # float32 (n, 3): vertex, face or corner normals (compat.normals)
        self.flat = None         # bool (n_polys,): faces shaded with their triangles' own
        #                          geometric normals, as Cycles does (compat.cycles_normals)
        self.uvs = []            # [(name, float32 (n_loops, 2))], the render map first
        self.colors = []         # [(name, float32 (n_loops or n_verts, 4), domain)]
        self.texspace = None     # (location, size)

    def add_orco(self, orco):
        """Carries undeformed positions (undeformed_positions; None: none) as the point colour
        layer ORCO_LAYER."""
        if orco is not None and len(orco) == len(self.co):
            ones = np.ones((len(orco), 1), np.float32)
            self.colors.append((ORCO_LAYER, np.hstack([orco, ones]), "POINT"))

    def digest(self, *context):
        """blake2b of every array and of `context` (what else the export depends on, e.g. the
        UV maps the materials want tangents for), hex."""
        h = hashlib.blake2b(digest_size=20)
        flat = self.flat if self.flat is not None else np.zeros(0, dtype=bool)
        for a in (self.loop_vert, self.loop_start, self.face_material, self.co, self.normals,
                  flat):
            h.update(b"|%d|" % a.size)
            h.update(np.ascontiguousarray(a).reshape(-1).view(np.uint8))  # bytes, no copy
        for name, a, *domain in self.uvs + self.colors:
            h.update(repr((name, domain, a.size)).encode("utf-8"))
            h.update(np.ascontiguousarray(a).reshape(-1).view(np.uint8))  # bytes, no copy
        h.update(repr((self.texspace, self.normal_domain, context)).encode("utf-8"))
        return h.hexdigest()


# The colour layer that carries a deformed mesh's undeformed positions (the renderer's
# Generated coordinates read it; the Attribute node never sees it).
ORCO_LAYER = "tesela:orco"

# Modifiers that only move vertices (Blender's eModifierTypeType_OnlyDeform): Blender builds
# the undeformed coordinates (CD_ORCO) without them.
_DEFORM_ONLY = {"ARMATURE", "CAST", "CLOTH", "COLLISION", "CORRECTIVE_SMOOTH", "CURVE",
                "DISPLACE", "HOOK", "LAPLACIANDEFORM", "LAPLACIANSMOOTH", "LATTICE",
                "MESH_DEFORM", "SHRINKWRAP", "SIMPLE_DEFORM", "SMOOTH", "SOFT_BODY",
                "SURFACE_DEFORM", "WARP", "WAVE", "MESH_CACHE"}
# Modifiers that run on the undeformed mesh too but move no vertex.
_POSITION_NEUTRAL = {"UV_PROJECT", "UV_WARP", "VERTEX_WEIGHT_EDIT", "VERTEX_WEIGHT_MIX",
                     "VERTEX_WEIGHT_PROXIMITY", "DATA_TRANSFER", "NORMAL_EDIT", "WEIGHTED_NORMAL"}


def undeformed_positions(obj, co, render=True):
    """Object-space positions of the evaluated mesh's vertices before its deform modifiers and
    shape keys (what Cycles' Generated coordinates use: Blender's CD_ORCO), for an object whose
    modifiers only deform: the original mesh's (or its Texture Mesh's) vertices, when their
    count is that of the evaluated positions `co`. None when they are `co` already, or
    the stack also builds geometry (its undeformed mesh would have to be evaluated apart; the
    deformed positions are used then)."""
    orig = getattr(obj, "original", None) or obj
    data = getattr(orig, "data", None)
    if getattr(orig, "type", None) != "MESH" or data is None or not hasattr(data, "vertices"):
        return None
    enabled = [m for m in getattr(orig, "modifiers", ())
               if (m.show_render if render else m.show_viewport)]
    if not (any(m.type in _DEFORM_ONLY for m in enabled) or data.shape_keys is not None):
        return None
    if any(m.type not in _DEFORM_ONLY and m.type not in _POSITION_NEUTRAL for m in enabled):
        return None
    src = getattr(data, "texture_mesh", None) or data
    n = len(co)
    if len(src.vertices) != n or n == 0:
        return None
    out = np.empty(n * 3, dtype=np.float32)
    src.vertices.foreach_get("co", out)
    out = out.reshape(-1, 3)
    return None if np.array_equal(out, co) else out


# The face attribute carrying each face's island (Geometry > Random Per Island).
ISLAND_ATTRIBUTE = ".tesela.island"


# The point attribute carrying Geometry > Pointiness.
POINTINESS_ATTRIBUTE = ".tesela.pointiness"
_DERIVED_OUTPUTS = ("Random Per Island", "Pointiness")


def _tree_geometry_outputs(tree, seen, found):
    if tree is None or tree.name in seen:
        return
    seen.add(tree.name)
    for node in tree.nodes:
        if node.bl_idname == "ShaderNodeNewGeometry":
            for name in _DERIVED_OUTPUTS:
                out = node.outputs.get(name)
                if out is not None and out.is_linked:
                    found.add(name)
        elif getattr(node, "node_tree", None) is not None:
            _tree_geometry_outputs(node.node_tree, seen, found)


def _geometry_outputs_used(mesh):
    """Which of the Geometry node's derived outputs (Random Per Island, Pointiness) the
    mesh's materials read: the add-on computes those attributes only then."""
    seen, found = set(), set()
    for m in mesh.materials:
        if m is not None:
            _tree_geometry_outputs(compat.node_tree(m), seen, found)
    return found


def _edges(mesh):
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int64)
    if len(edges):
        mesh.edges.foreach_get("vertices", edges)
    return edges.reshape(-1, 2)


def _pointiness(co, vertex_normals, edges):
    """Cycles' Pointiness (its attr_create_pointiness) per vertex, as (n, 4) float32 (p, p, p,
    1): coincident vertices welded (within FLT_EPSILON, found along the coordinate sum), each
    vertex's angle between its welded normal and the mean direction of its edges over pi, then
    averaged with its one-ring neighbours."""
    n = co.shape[0]
    eps = np.float32(np.finfo(np.float32).eps)
    co = co.astype(np.float32)
    total = (co[:, 0] + co[:, 1]) + co[:, 2]
    # Ascending coordinate sum; coincident vertices with the higher index first.
    order = np.lexsort((-np.arange(n), total))
    orig = np.arange(n)
    sums = total[order]
    ends = np.searchsorted(sums, sums + 3 * eps, side="right")
    for k in np.nonzero(ends > np.arange(n) + 1)[0].tolist():
        v = order[k]
        for j in range(k + 1, int(ends[k])):
            w = order[j]
            d = co[w] - co[v]
            if float(np.dot(d, d)) < eps:
                orig[v] = w
                break
    for v in np.nonzero(orig != np.arange(n))[0].tolist():
        r = orig[v]
        while orig[r] != r:
            r = orig[r]
        orig[v] = r
    normal = np.zeros((n, 3), np.float32)
    np.add.at(normal, orig, vertex_normals.astype(np.float32))
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    normal = np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)
    # Each edge once between welded vertices, in the mesh's edge order.
    e = orig[edges] if len(edges) else np.zeros((0, 2), np.int64)
    key = np.minimum(e[:, 0], e[:, 1]) * n + np.maximum(e[:, 0], e[:, 1])
    _, first = np.unique(key, return_index=True)
    e = e[np.sort(first)]
    v0, v1 = e[:, 0], e[:, 1]
    d = co[v1] - co[v0]
    dl = np.linalg.norm(d, axis=1, keepdims=True)
    d = np.divide(d, dl, out=np.zeros_like(d), where=dl > 0)
    accum = np.zeros((n, 3), np.float32)
    np.add.at(accum, v0, d)
    np.add.at(accum, v1, -d)
    count = np.zeros(n, np.int64)
    np.add.at(count, v0, 1)
    np.add.at(count, v1, 1)
    raw = np.zeros(n, np.float32)
    has = (count > 0) & (orig == np.arange(n))
    mean = accum[has] / count[has, None].astype(np.float32)
    cos = np.clip(np.sum(normal[has] * mean, axis=1), -1.0, 1.0)
    raw[has] = np.arccos(cos) / np.float32(np.pi)
    data = raw.copy()
    np.add.at(data, v0, raw[v1])
    np.add.at(data, v1, raw[v0])
    data /= (count + 1).astype(np.float32)
    data = data[orig]
    out = np.ones((n, 4), np.float32)
    out[:, :3] = data[:, None]
    return out


def _island_ids(mesh, raw, n_verts):
    """Per face, its island as Cycles numbers it: the representative vertex of the face's
    connected component, from joining every edge's vertices in the mesh's edge order with
    union by rank (Cycles' DisjointSet; the renderer hashes the index). (n_faces, 4) float32
    holding the index's low and high 16 bits, exact for any vertex count."""
    edges = _edges(mesh)
    parent = list(range(n_verts))
    rank = [0] * n_verts

    def find(x):
        root = x
        while parent[root] != root:
            root = parent[root]
        while parent[x] != root:
            parent[x], x = root, parent[x]
        return root

    for a, b in edges.tolist():
        ra, rb = find(a), find(b)
        if ra == rb:
            continue
        if rank[ra] < rank[rb]:
            ra, rb = rb, ra
        parent[rb] = ra
        if rank[ra] == rank[rb]:
            rank[ra] += 1
    first = raw.loop_vert[raw.loop_start].tolist()
    roots = np.array([find(v) for v in first], dtype=np.int64)
    out = np.zeros((len(first), 4), dtype=np.float32)
    out[:, 0] = roots & 0xFFFF
    out[:, 1] = roots >> 16
    out[:, 3] = 1.0
    return out


def read_mesh(mesh, check_cancel=None, phases=None):
    """The RawMesh of an evaluated mesh, or None if it has no faces; phases: a Phases adding up
    the seconds of each step."""
    def checkpoint():
        if check_cancel is not None and check_cancel():
            raise ExportCancelled()
    phases = phases or Phases()
    n_polys = len(mesh.polygons)
    if n_polys == 0:
        return None
    raw = RawMesh()
    n_loops = len(mesh.loops)
    n_verts = len(mesh.vertices)
    with phases("positions"):
        raw.loop_vert = compat.corner_verts(mesh, n_loops)
        raw.loop_start = compat.face_starts(mesh, n_polys)
        raw.face_material = compat.face_materials(mesh, n_polys)
        raw.co = compat.vertex_positions(mesh, n_verts)
    checkpoint()
    with phases("normals"):
        raw.normal_domain, raw.normals, raw.flat = compat.cycles_normals(mesh, n_loops, n_polys)
    checkpoint()
    with phases("uvs"):
        for layer in compat.uv_layers(mesh):
            raw.uvs.append((layer.name, compat.corner_uv(layer, n_loops)))
    checkpoint()
    with phases("colors"):
        counts = {"CORNER": n_loops, "POINT": n_verts, "FACE": n_polys}
        for name, domain, data in compat.color_layers(mesh):
            col = np.empty(counts[domain] * 4, dtype=np.float32)
            try:
                data.foreach_get("color", col)
            except (TypeError, RuntimeError, AttributeError):
                continue
            raw.colors.append((name, col.reshape(-1, 4), domain))
        # Named float and vector attributes travel as colour layers too: the Attribute node
        # reads both by name.
        skip = {name for name, _, _ in raw.colors} | {name for name, _ in raw.uvs}
        raw.colors += [(name, values, domain) for name, domain, values
                       in compat.generic_attributes(mesh, counts, skip)]
        uses = _geometry_outputs_used(mesh)
        if "Random Per Island" in uses:
            raw.colors.append((ISLAND_ATTRIBUTE, _island_ids(mesh, raw, n_verts), "FACE"))
        if "Pointiness" in uses:
            p = _pointiness(raw.co, compat.vertex_normals(mesh, n_verts), _edges(mesh))
            raw.colors.append((POINTINESS_ATTRIBUTE, p, "POINT"))
        if any(domain == "FACE" for _, _, domain in raw.colors):
            # Each corner takes its face's value (faces' corners are consecutive).
            face_corners = np.diff(np.append(raw.loop_start, n_loops))
            raw.colors = [(name, np.repeat(col, face_corners, axis=0), "CORNER")
                          if domain == "FACE" else (name, col, domain)
                          for name, col, domain in raw.colors]
    checkpoint()
    raw.texspace = compat.texture_space(mesh)
    return raw


def mesh_arrays(mesh, check_cancel=None, tangent_uvs=None, warn=None, label="", raw=None,
                phases=None):
    """MeshData for an evaluated mesh (None if it has no triangles).

    tangent_uvs: UV map names whose tangents the materials need ("" = the active render map);
    warn(message): where problems go; raw: the mesh's RawMesh if already read; phases: a
    Phases adding up the seconds of each step.

    Every corner's values are what Blender gives for that corner; corners of one vertex whose
    values are bitwise equal share one glTF vertex (see _weld), so each triangle corner reads
    exactly what it would with one vertex per corner.
    """
    def checkpoint():
        if check_cancel is not None and check_cancel():
            raise ExportCancelled()
    warn = warn or (lambda message: None)
    phases = phases or Phases()
    if raw is None:
        raw = read_mesh(mesh, check_cancel, phases)
        if raw is None:
            return None
    with phases("triangles"):
        mesh.calc_loop_triangles()
        checkpoint()
        nt = len(mesh.loop_triangles)
        if nt == 0:
            return None
        tri = compat.loop_triangle_corners(mesh, nt)
        tri_face = compat.loop_triangle_faces(mesh, nt)
        tri_mat = np.take(raw.face_material, tri_face)
    loop_vert, co, normals = raw.loop_vert, raw.co, raw.normals
    n_loops, n_verts = loop_vert.shape[0], co.shape[0]
    with phases("normals"):
        if raw.normal_domain == "FACE":
            # Loop triangles cover every corner: each corner's face from its triangles'.
            loop_face = np.empty(n_loops, dtype=np.int32)
            loop_face[tri.reshape(-1)] = np.repeat(tri_face, 3)
            corner_normals = _take(normals, loop_face)
        elif raw.normal_domain == "POINT":
            corner_normals = None  # equal for every corner of a vertex
        else:
            corner_normals = normals
    checkpoint()

    out = MeshData()
    layers = raw.uvs
    blender_uvs = dict(layers)
    # (name, per-corner or per-vertex float32 (n, 4), per vertex?)
    colors = [(name, col, domain != "CORNER") for name, col, domain in raw.colors]

    tangents = None
    with phases("tangents"):
        if tangent_uvs and layers:
            names = sorted({(u or layers[0][0]) for u in tangent_uvs})
            known = [u for u in names if u in blender_uvs]
            for u in names:
                if u not in blender_uvs:
                    warn("mesh '%s': a normal map reads UV map '%s', which the mesh does not have"
                         % (label, u))
            if len(known) > 1:
                warn("mesh '%s': normal maps read several UV maps (%s); tangents are written for "
                     "'%s' only" % (label, ", ".join(known), known[0]))
            if known:
                uv_name = known[0]
                try:
                    t, sign = compat.corner_tangents(mesh, uv_name, n_loops)
                except RuntimeError:
                    # Blender computes MikkTSpace on triangles and quads only.
                    warn("mesh '%s' has n-gons: its tangents are per-face approximations, not "
                         "MikkTSpace (triangulate it to match Cycles exactly)" % label)
                    nrm = _unit_normals(_take(normals, loop_vert) if corner_normals is None
                                        else corner_normals)
                    t, sign = _face_tangents(_finite(_take(co, loop_vert)), nrm,
                                             blender_uvs[uv_name], tri)
                tangents = (t, sign)
                out.tangent_uv = uv_name
                checkpoint()
        elif tangent_uvs:
            warn("mesh '%s' has no UV map for its normal map" % label)

    with phases("weld"):
        if raw.normal_domain == "FACE":
            # Flat shading: corners of one vertex lie on faces of different normals, so each
            # corner is a glTF vertex (the rare coplanar neighbours are not worth a search).
            src, remap, vert = None, None, loop_vert
        else:
            keys = list(blender_uvs.values()) + [c for _, c, per_vertex in colors
                                                 if not per_vertex]
            if corner_normals is not None:
                keys.append(corner_normals)
            if tangents is not None:
                keys += [tangents[0], tangents[1]]
            src, remap = _weld(loop_vert, n_verts, keys)
            vert = np.take(loop_vert, src)  # the Blender vertex of each glTF vertex

    with phases("vertices"):
        def per_corner(a):  # a corner array's values at the glTF vertices
            return a if src is None else _take(a, src)
        out.positions = _finite(_take(co, vert))
        out.normals = _unit_normals(_take(normals, vert) if corner_normals is None
                                    else per_corner(corner_normals))
        out.indices = (tri if remap is None else np.take(remap, tri)).view(np.uint32)
        out.tri_material = tri_mat
        for name, uv in blender_uvs.items():
            flipped = per_corner(uv)
            flipped = flipped.copy() if flipped is uv else flipped
            flipped[:, 1] = 1.0 - flipped[:, 1]  # glTF's UV origin is the top-left corner
            out.uv_sets.append((name, flipped))
        for name, col, per_vertex in colors:
            out.color_sets.append((name, _finite(_take(col, vert) if per_vertex
                                                 else per_corner(col))))
        if tangents is not None:
            out.tangents = _tangent_vec4(per_corner(tangents[0]), per_corner(tangents[1]),
                                         out.normals)

    if raw.flat is not None:
        with phases("flat triangles"):
            flat_tri = np.take(raw.flat, tri_face)
            if flat_tri.any():
                _flat_shade(out, flat_tri)
    out.texspace = raw.texspace
    return out


# Flat triangles share a glTF vertex where their normals agree to this many steps per unit
# (the two halves of a planar quad, whose computed normals differ in the last bits).
FLAT_NORMAL_STEPS = 1 << 16


def _flat_shade(out, flat_tri):
    """Gives the triangles flagged in flat_tri (bool per triangle) their own geometric normal,
    as Cycles shades a flat face: a non-planar face (a twisted quad, an n-gon) then shows its
    triangles, not the polygon's one normal. A glTF vertex is shared by the corners of
    triangles whose normals agree (and by the smooth triangles' corners, which keep theirs);
    degenerate triangles keep the normals they had."""
    tri = out.indices.astype(np.int64)
    p = out.positions.astype(np.float64)
    flat = np.flatnonzero(flat_tri)
    a = _take(p, tri[flat, 0])
    n = np.cross(_take(p, tri[flat, 1]) - a, _take(p, tri[flat, 2]) - a)
    length = np.linalg.norm(n, axis=1)
    ok = length > 1e-30
    flat, n = flat[ok], n[ok] / length[ok, None]
    # A key per triangle corner: its vertex, then its triangle's normal in steps (a flat one) or
    # a value no normal takes (a smooth or degenerate one: the vertex's own normal).
    keys = np.full((tri.shape[0], 3, 4), 4 * FLAT_NORMAL_STEPS, dtype=np.int64)
    keys[:, :, 0] = tri
    keys[flat, :, 1:] = np.rint(n * FLAT_NORMAL_STEPS).astype(np.int64)[:, None, :]
    keys = keys.reshape(-1, 4)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    src = keys[first, 0]
    normals = np.repeat(n.astype(np.float32), 3, axis=0)  # per flat triangle corner
    corner_normal = np.full(tri.shape[0] * 3, -1, dtype=np.int64)
    corner_normal[(flat[:, None] * 3 + np.arange(3)).reshape(-1)] = np.arange(normals.shape[0])
    which = corner_normal[first]
    out.normals = _take(out.normals, src)
    mine = which >= 0
    out.normals[mine] = normals[which[mine]]
    out.positions = _take(out.positions, src)
    out.uv_sets = [(name, _take(uv, src)) for name, uv in out.uv_sets]
    out.color_sets = [(name, _take(col, src)) for name, col in out.color_sets]
    if out.tangents is not None:
        out.tangents = _take(out.tangents, src)
    out.indices = inverse.reshape(-1, 3).astype(np.uint32)


def _finite(a):
    """`a` with NaN and infinities as 0 (a copy only if it has any)."""
    if np.isfinite(a).all():
        return a
    return np.nan_to_num(a, nan=0.0, posinf=0.0, neginf=0.0)


def _unit_normals(nrm):
    """Normals as they are if all have unit length (within 1e-4 in the squared length), else
    all renormalised, with zero or NaN ones as +Z."""
    sq = np.einsum("ij,ij->i", nrm, nrm)
    if (np.abs(sq - 1.0) < 1e-4).all():
        return nrm
    length = np.sqrt(sq.astype(np.float64))
    bad = ~(length > 1e-12)
    length[bad] = 1.0
    nrm = (nrm / length[:, None]).astype(np.float32)
    nrm[bad] = (0.0, 0.0, 1.0)
    return nrm


# Corners left after this many rounds of _weld, or once a round joins fewer than this share of
# the corners it looked at, get a glTF vertex each: flat-shaded corners seldom join.
WELD_ROUNDS = 4
WELD_MIN_SHARE = 1.0 / 8.0


def _weld(corner_vert, n_verts, keys):
    """glTF vertices for the corners: corners of one Blender vertex whose `keys` rows (per-corner
    arrays, (n_corners, k) or (n_corners,), of 4-byte items) are bitwise equal share one.

    Returns (src, remap): src (m,) intp, the corner each glTF vertex takes its values from;
    remap (n_corners,) int32, the glTF vertex of each corner. In each round every vertex with
    corners left picks one of them; those equal to it join it. Each corner's values are its
    own, so a triangle reads the same through remap as it would with one glTF vertex per
    corner.
    """
    n = corner_vert.shape[0]
    cols = [_key_columns(k, n) for k in keys]
    srcs = []
    next_id = 0
    todo = None  # None: every corner (the first round)
    cv = corner_vert.astype(np.intp)
    pick = np.empty(n_verts, dtype=np.intp)
    remap = None
    for _ in range(WELD_ROUNDS):
        count = n if todo is None else todo.shape[0]
        pick.fill(-1)
        pick[cv] = np.arange(n, dtype=np.intp) if todo is None else todo  # numpy keeps the last
        picked = np.take(pick, cv)
        joins = np.ones(count, dtype=bool)
        for k in cols:
            mine = k if todo is None else np.take(k, todo, axis=0)
            theirs = np.take(k, picked, axis=0)
            for c in range(k.shape[1]):
                joins &= mine[:, c] == theirs[:, c]
        has = pick >= 0
        ids = np.cumsum(has, dtype=np.int32)
        ids += next_id - 1
        # Every corner left gets its picked corner's vertex; those that did not join get
        # another in a later round.
        if todo is None:
            remap = np.take(ids, cv)
        else:
            remap[todo] = np.take(ids, cv)
        srcs.append(pick[has])
        next_id += srcs[-1].shape[0]
        share = (int(np.count_nonzero(joins)) - srcs[-1].shape[0]) / count  # joined another
        left = np.flatnonzero(~joins)
        todo = left if todo is None else todo[left]
        cv = np.take(cv, left)
        if todo.shape[0] == 0 or share < WELD_MIN_SHARE:
            break
    remap[todo] = np.arange(next_id, next_id + todo.shape[0], dtype=np.int32)
    srcs.append(todo)
    return np.concatenate(srcs), remap


def _key_columns(key, n):
    """A per-corner key as (n, c) unsigned integers holding its bits, two 4-byte values to a
    column where they pair up (fewer, wider comparisons)."""
    k = np.ascontiguousarray(key).reshape(n, -1).view(np.uint32)
    if k.shape[1] % 2 == 0:
        return k.view(np.uint64)
    return k


def _take(a, idx):
    """a[idx] along the first axis (np.take: several times faster than fancy indexing of rows)."""
    return np.take(a, idx, axis=0)


def _tangent_vec4(t, sign, nrm):
    """glTF TANGENT (unit xyz, w = +-1) from Blender's tangents and bitangent signs; degenerate
    tangents become any unit vector perpendicular to the normal."""
    t = np.nan_to_num(t.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    length = np.sqrt(np.einsum("ij,ij->i", t, t))
    bad = ~(length > 1e-12)
    if bad.any():
        n = nrm[bad]
        axis = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        alt = axis - n * np.einsum("ij,ij->i", axis, n)[:, None]
        alt /= np.maximum(np.linalg.norm(alt, axis=1), 1e-12)[:, None]
        t[bad] = alt
        length[bad] = 1.0
    out = np.empty((t.shape[0], 4), dtype=np.float32)
    out[:, :3] = t / length[:, None]
    out[:, 3] = np.where(sign < 0.0, -1.0, 1.0)
    return out


def _face_tangents(positions, normals, uv, tri):
    """Per-corner tangents from each triangle's UV gradient (for meshes Blender's MikkTSpace
    refuses), orthogonalised against the corner normals."""
    c = tri.reshape(-1, 3)
    p0, p1, p2 = positions[c[:, 0]], positions[c[:, 1]], positions[c[:, 2]]
    w0, w1, w2 = uv[c[:, 0]], uv[c[:, 1]], uv[c[:, 2]]
    e1, e2 = p1 - p0, p2 - p0
    d1, d2 = w1 - w0, w2 - w0
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    r = np.where(np.abs(det) > 1e-20, 1.0 / np.where(det == 0, 1.0, det), 0.0)[:, None]
    tan = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    bit = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    n = positions.shape[0]
    t = np.zeros((n, 3), dtype=np.float64)
    b = np.zeros((n, 3), dtype=np.float64)
    for k in range(3):
        np.add.at(t, c[:, k], tan)
        np.add.at(b, c[:, k], bit)
    t -= normals * np.einsum("ij,ij->i", t, normals)[:, None]
    sign = np.where(np.einsum("ij,ij->i", np.cross(normals, t), b) < 0.0, -1.0, 1.0)
    return t.astype(np.float32), sign.astype(np.float32)


# --- per-object data (Cycles' object sync: blender/object.cpp) ---------------------------

def _final(a, b, c):
    m = 0xFFFFFFFF

    def rot(x, k):
        return ((x << k) | (x >> (32 - k))) & m
    c ^= b
    c = (c - rot(b, 14)) & m
    a ^= c
    a = (a - rot(c, 11)) & m
    b ^= a
    b = (b - rot(a, 25)) & m
    c ^= b
    c = (c - rot(b, 16)) & m
    a ^= c
    a = (a - rot(c, 4)) & m
    b ^= a
    b = (b - rot(a, 14)) & m
    c ^= b
    c = (c - rot(b, 24)) & m
    return c


def hash_uint2(kx, ky):
    """Cycles' hash_uint2 (Jenkins lookup3 'final')."""
    a = b = c = (0xDEADBEEF + (2 << 2) + 13) & 0xFFFFFFFF
    b = (b + ky) & 0xFFFFFFFF
    a = (a + kx) & 0xFFFFFFFF
    return _final(a, b, c)


def hash_string(s):
    """Cycles' hash_string: i = i * 37 + c over the UTF-8 bytes (Blender is built with
    -funsigned-char: bytes >= 128 count as themselves; checked against Cycles renders)."""
    i = 0
    for byte in s.encode("utf-8"):
        i = (i * 37 + byte) & 0xFFFFFFFF
    return i


def random_id(inst, obj):
    """The object's random id as Cycles sets it: the instance's random_id for instances, else
    hash_uint2(hash_string(name), 0)."""
    if inst.is_instance:
        return int(inst.random_id) & 0xFFFFFFFF
    return hash_uint2(hash_string(obj.name), 0)


def random_number(rid):
    """Object Info > Random: (float)random_id * (1.0f / (float)0xFFFFFFFF) in float32."""
    return float(np.float32(rid)) * 2.0 ** -32  # (float)0xFFFFFFFF rounds to 2^32


def particle_extras(inst, frame):
    """tesela_object.particle: the particle that placed instance `inst`, as Cycles reads it for
    Particle Info (index, age in frames at `frame`, lifetime, location, size, velocity and
    angular velocity, Blender's world coordinates); None for other objects and for child
    particles (Cycles has no data for them either)."""
    psys = getattr(inst, "particle_system", None) if inst.is_instance else None
    if psys is None:
        return None
    index = int(inst.persistent_id[0])
    particles = psys.particles
    if not 0 <= index < len(particles):
        return None
    pa = particles[index]
    return {"index": index, "age": float(frame - pa.birth_time), "lifetime": float(pa.lifetime),
            "location": [float(v) for v in pa.location], "size": float(pa.size),
            "velocity": [float(v) for v in pa.velocity],
            "angular_velocity": [float(v) for v in pa.angular_velocity]}


def object_extras(inst, obj, view_layer=None, frame=0.0, reads=None, instance_attributes=None):
    """extras.tesela_object: what Object Info reads (Blender's world coordinates), and what
    the object's materials read of it (`reads`, see attributes.material_reads): Particle Info
    (`frame` is the render's frame, for a particle's age) and the values of the Attribute
    node's Object and Instancer types (`instance_attributes` an
    attributes.InstanceAttributes); the ray visibility (Indirect Only clearing the camera's)
    and whether the object is a holdout or a shadow catcher (its own or its instancer's)."""
    rid = random_id(inst, obj)
    m = inst.matrix_world
    out = {"random": random_number(rid), "random_id": rid,
           "pass_index": int(getattr(obj, "pass_index", 0)),
           "color": [float(v) for v in getattr(obj, "color", (1.0, 1.0, 1.0, 1.0))],
           "location": [float(m[0][3]), float(m[1][3]), float(m[2][3])]}
    if reads is not None:
        particle = particle_extras(inst, frame) if reads["PARTICLE_INFO"] else None
        if particle is not None:
            out["particle"] = particle
        values = object_attributes(inst, obj, reads, instance_attributes)
        if values is not None:
            out["attributes"] = values
    # An instance is hidden from the rays its object or its instancer is hidden from, and is
    # a holdout where either is.
    instancer = inst.parent if inst.is_instance else None
    vis = compat.ray_visibility(obj)
    if instancer is not None:
        parent = compat.ray_visibility(instancer)
        vis = {k: v and parent[k] for k, v in vis.items()}
    holdout = compat.is_holdout(obj, view_layer) or (
        instancer is not None and compat.is_holdout(instancer, view_layer))
    # Indirect Only (of the object, or of an instance's instancer, as Cycles reads it): the
    # camera does not see it; everything else does.
    if not holdout and compat.is_indirect_only(instancer or obj, view_layer):
        vis["camera"] = False
    if not all(vis.values()):
        out["visibility"] = vis
    if holdout:
        out["holdout"] = True
    if getattr(obj, "is_shadow_catcher", False) or getattr(instancer, "is_shadow_catcher", False):
        out["shadow_catcher"] = True
    return out
