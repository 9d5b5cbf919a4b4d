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
from .common import ExportCancelled

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
        self.normals = None      # float32 (n_loops, 3), corner normals
        self.uvs = []            # [(name, float32 (n_loops, 2))], the render map first
        self.colors = []         # [(name, float32 (n_loops or n_verts, 4), domain)]
        self.texspace = None     # (location, size)

    def digest(self, *context):
        """blake2b of every array and of `context` (what else the export depends on, e.g. the
        UV maps the materials want tangents for), hex."""
        h = hashlib.blake2b(digest_size=20)
        for a in (self.loop_vert, self.loop_start, self.face_material, self.co, self.normals):
            h.update(b"|%d|" % a.size)
            h.update(np.ascontiguousarray(a).tobytes())
        for name, a, *domain in self.uvs + self.colors:
            h.update(repr((name, domain, a.size)).encode("utf-8"))
            h.update(np.ascontiguousarray(a).tobytes())
        h.update(repr((self.texspace, context)).encode("utf-8"))
        return h.hexdigest()


def read_mesh(mesh, check_cancel=None):
    """The RawMesh of an evaluated mesh, or None if it has no faces."""
    def checkpoint():
        if check_cancel is not None and check_cancel():
            raise ExportCancelled()
    n_polys = len(mesh.polygons)
    if n_polys == 0:
        return None
    raw = RawMesh()
    n_loops = len(mesh.loops)
    n_verts = len(mesh.vertices)
    raw.loop_vert = compat.corner_verts(mesh, n_loops)
    raw.loop_start = np.empty(n_polys, dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", raw.loop_start)
    raw.face_material = compat.face_materials(mesh, n_polys)
    raw.co = compat.vertex_positions(mesh, n_verts)
    checkpoint()
    raw.normals = compat.corner_normals(mesh, n_loops)
    checkpoint()
    for layer in compat.uv_layers(mesh):
        raw.uvs.append((layer.name, compat.corner_uv(layer, n_loops)))
    checkpoint()
    for name, domain, data in compat.color_layers(mesh):
        n = n_loops if domain == "CORNER" else n_verts
        col = np.empty(n * 4, dtype=np.float32)
        try:
            data.foreach_get("color", col)
        except (TypeError, RuntimeError, AttributeError):
            continue
        raw.colors.append((name, col.reshape(-1, 4), domain))
    checkpoint()
    raw.texspace = compat.texture_space(mesh)
    return raw


def mesh_arrays(mesh, check_cancel=None, tangent_uvs=None, warn=None, label="", raw=None):
    """MeshData for an evaluated mesh (None if it has no triangles).

    tangent_uvs: UV map names whose tangents the materials need ("" = the active render map);
    warn(message): where problems go; raw: the mesh's RawMesh if already read.
    """
    def checkpoint():
        if check_cancel is not None and check_cancel():
            raise ExportCancelled()
    warn = warn or (lambda message: None)
    if raw is None:
        raw = read_mesh(mesh, check_cancel)
        if raw is None:
            return None
    mesh.calc_loop_triangles()
    checkpoint()
    nt = len(mesh.loop_triangles)
    if nt == 0:
        return None
    tri = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", tri)
    tri_mat = np.empty(nt, dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", tri_mat)
    loop_vert, co, normals = raw.loop_vert, raw.co, raw.normals
    n_loops = loop_vert.shape[0]

    out = MeshData()
    # One glTF vertex per corner (face corner = Blender loop): loop triangles cover every
    # loop of every polygon, so the loop indices are the glTF indices as they are.
    positions = co[loop_vert]
    nrm = normals
    sq = np.einsum("ij,ij->i", nrm, nrm)
    if not (np.abs(sq - 1.0) < 1e-4).all():  # rare: renormalise, repair zero/NaN normals
        length = np.sqrt(sq.astype(np.float64))
        bad = ~(length > 1e-12)
        length[bad] = 1.0
        nrm = (nrm / length[:, None]).astype(np.float32)
        nrm[bad] = (0.0, 0.0, 1.0)
    if not np.isfinite(positions).all():
        positions = np.nan_to_num(positions, nan=0.0, posinf=0.0, neginf=0.0)
    out.positions, out.normals = positions, nrm
    out.indices = tri.view(np.uint32).reshape(-1, 3)
    out.tri_material = tri_mat

    layers = raw.uvs
    blender_uvs = {}
    for name, uv in layers:
        blender_uvs[name] = uv
        flipped = uv.copy()
        flipped[:, 1] = 1.0 - flipped[:, 1]  # glTF's UV origin is the top-left corner
        out.uv_sets.append((name, flipped))
    checkpoint()

    for name, col, domain in raw.colors:
        if domain != "CORNER":
            col = col[loop_vert]
        if not np.isfinite(col).all():
            col = np.nan_to_num(col, nan=0.0, posinf=0.0, neginf=0.0)
        out.color_sets.append((name, np.ascontiguousarray(col)))
    checkpoint()

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
                t, sign = _face_tangents(positions, nrm, blender_uvs[uv_name], tri)
            out.tangents = _tangent_vec4(t, sign, nrm)
            out.tangent_uv = uv_name
            checkpoint()
    elif tangent_uvs:
        warn("mesh '%s' has no UV map for its normal map" % label)

    out.texspace = raw.texspace
    return out


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


def object_extras(inst, obj):
    """extras.tesela_object: what Object Info reads (Blender's world coordinates)."""
    rid = random_id(inst, obj)
    m = inst.matrix_world
    return {"random": random_number(rid), "random_id": rid,
            "pass_index": int(getattr(obj, "pass_index", 0)),
            "color": [float(v) for v in getattr(obj, "color", (1.0, 1.0, 1.0, 1.0))],
            "location": [float(m[0][3]), float(m[1][3]), float(m[2][3])]}
