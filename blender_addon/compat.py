# SPDX-License-Identifier: MIT
"""Every Blender-version-specific detail of the add-on, in one place.

Supported: Blender 3.4 (Debian) through 5.x (PyPI bpy).
Known breaks handled here:
  * 4.0 renamed Principled BSDF sockets (Specular -> Specular IOR Level,
    Transmission -> Transmission Weight, Emission -> Emission Color, ...).
  * 4.1 removed Mesh.calc_normals_split()/MeshLoop.normal in favour of
    Mesh.corner_normals, and changed the shape RenderPass.rect.foreach_set
    accepts (it wants a flat sequence of pixels*channels in 4.1+; older
    versions also accept it flat, so one flat float32 array serves both).
  * 4.4 passes arguments to RenderEngine.__init__ (handled in engine.py by
    always accepting *args, **kwargs).
  * Shader node vocabulary (translate_node): the material graph always uses
    5.x node types and socket identifiers. 4.0 rewrote the Principled BSDF
    (socket renames, coat/sheen/subsurface/specular-tint conversions), merged
    Anisotropic into Glossy (bl_idname ShaderNodeBsdfAnisotropic), removed the
    Sharp distribution, turned Velvet into Sheen and renamed the subsurface
    methods; 4.0/4.1 gave the Noise texture a type and normalize flag and
    merged Musgrave into it; the legacy MixRGB and Separate/Combine RGB/HSV
    nodes are written as Mix and Separate/Combine Color in every version.
    Each conversion follows Blender's own versioning code (versioning_400.cc,
    versioning_410.cc), including the helper nodes it inserts.
"""

import bpy
import numpy as np

VERSION = bpy.app.version


# --- Principled BSDF socket names -------------------------------------------

_PRINCIPLED_3 = {
    "base_color": ("Base Color",),
    "metallic": ("Metallic",),
    "roughness": ("Roughness",),
    "ior": ("IOR",),
    "alpha": ("Alpha",),
    "transmission": ("Transmission",),
    "specular": ("Specular",),
    "emission_color": ("Emission",),
    "emission_strength": ("Emission Strength",),
}
_PRINCIPLED_4 = {
    "base_color": ("Base Color",),
    "metallic": ("Metallic",),
    "roughness": ("Roughness",),
    "ior": ("IOR",),
    "alpha": ("Alpha",),
    "transmission": ("Transmission Weight", "Transmission"),
    "specular": ("Specular IOR Level", "Specular"),
    "emission_color": ("Emission Color", "Emission"),
    "emission_strength": ("Emission Strength",),
}
PRINCIPLED = _PRINCIPLED_4 if VERSION >= (4, 0, 0) else _PRINCIPLED_3


def principled_input(node, key):
    """The Principled BSDF input socket for a version-independent key."""
    for name in PRINCIPLED[key]:
        sock = node.inputs.get(name)
        if sock is not None:
            return sock
    return None


def specular_to_factor(node, value):
    """KHR_materials_specular factor for the node's specular input value.

    3.x 'Specular' 0.5 and 4.x 'Specular IOR Level' 0.5 both mean 'the IOR's
    own reflectance'; 0 means no specular layer.
    """
    return max(0.0, min(1.0, 2.0 * float(value)))


# --- node trees ----------------------------------------------------------------

def node_tree(idblock):
    """The material's/world's shader node tree if it renders with nodes, else None.
    (5.0 deprecated use_nodes: every material and world uses nodes there.)"""
    tree = getattr(idblock, "node_tree", None)
    if tree is None:
        return None
    if VERSION < (5, 0, 0) and not idblock.use_nodes:
        return None
    return tree


def default_surface_shader():
    """The shader node Cycles shades objects and slots without a material with, at its
    defaults (base colour 0.8). Blender 3.x: a Diffuse BSDF; since the Principled v2 rewrite
    (measured on 5.0): a Principled BSDF, whose highlight material-less objects show."""
    return "ShaderNodeBsdfPrincipled" if VERSION >= (4, 0, 0) else "ShaderNodeBsdfDiffuse"


def material_output(tree):
    """The Material Output node Cycles uses: the active one targeting All or Cycles."""
    getter = getattr(tree, "get_output_node", None)
    if getter is not None:
        try:
            node = getter("CYCLES")
        except (TypeError, RuntimeError):
            node = None
        if node is not None:
            return node
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    cand = [n for n in outputs if n.target in ("ALL", "CYCLES")]
    for n in cand:
        if getattr(n, "is_active_output", False):
            return n
    return cand[0] if cand else None


def displacement_method(material):
    """'BUMP' | 'DISPLACEMENT' | 'BOTH' (material setting in 4.x+, Cycles setting before)."""
    value = getattr(material, "displacement_method", None)
    if value is None:
        value = getattr(getattr(material, "cycles", None), "displacement_method", None)
    return value or "BUMP"


def socket_available(sock):
    """Whether a node socket takes part in evaluation (Blender skips unavailable sockets)."""
    if not getattr(sock, "enabled", True):
        return False
    return not getattr(sock, "is_unavailable", False)


# --- mesh data ---------------------------------------------------------------

def _attribute(mesh, name, domain, data_type, n):
    """A mesh attribute read with one foreach_get (3.6+ keeps the mesh's own topology, such as
    .corner_vert, as attributes too), or None where the mesh has no such attribute."""
    attrs = getattr(mesh, "attributes", None)
    attr = attrs.get(name) if attrs is not None else None
    if attr is None or attr.domain != domain or attr.data_type != data_type or len(attr.data) != n:
        return None
    return attr


def _read_in_place(collection, n, dtype, width, prop):
    """The n items of a collection whose items are `width` consecutive `dtype` values in one
    array (MeshLoopTriangle.loops, MeshNormalValue.vector), copied in one go, or None.

    Their foreach_get goes item by item through a getter (~100 ns an item: a second a 10 M
    triangle scene). Reading them in place is safe only if they are one array: the item
    addresses must step by the item size from the first to the last, and the first, middle
    and last items must read back what the API gives for them."""
    import ctypes
    itemsize = np.dtype(dtype).itemsize * width
    try:
        first = collection[0].as_pointer()
        if n > 1 and collection[n - 1].as_pointer() - first != (n - 1) * itemsize:
            return None
        out = np.empty((n, width), dtype=dtype)
        ctypes.memmove(out.ctypes.data, first, n * itemsize)
        for i in sorted({0, n // 2, n - 1}):
            if collection[i].as_pointer() != first + i * itemsize:
                return None
            value = np.array(getattr(collection[i], prop), dtype=dtype).reshape(-1)
            if not np.array_equal(value, out[i]):
                return None
    except (AttributeError, IndexError, TypeError, ValueError, OverflowError):
        return None
    return out


def loop_triangle_corners(mesh, n_tris):
    """The corners (loop indices) of each loop triangle, int32 (n_tris, 3); calc_loop_triangles()
    first."""
    out = _read_in_place(mesh.loop_triangles, n_tris, np.int32, 3, "loops")
    if out is None:
        out = np.empty((n_tris, 3), dtype=np.int32)
        mesh.loop_triangles.foreach_get("loops", out.reshape(-1))
    return out


def loop_triangle_faces(mesh, n_tris):
    """The face (polygon) of each loop triangle, int32 (n_tris,)."""
    out = np.empty(n_tris, dtype=np.int32)
    faces = getattr(mesh, "loop_triangle_polygons", None)  # 3.6+: one array
    if faces is not None and len(faces) == n_tris:
        faces.foreach_get("value", out)
    else:
        mesh.loop_triangles.foreach_get("polygon_index", out)
    return out


def face_starts(mesh, n_polys):
    """The first corner of each face, int32 (n_polys,): the face offsets, read in place where
    they are one array (MeshPolygon.loop_start goes face by face)."""
    out = _read_in_place(mesh.polygons, n_polys, np.int32, 1, "loop_start")
    if out is not None:
        return out.reshape(-1)
    out = np.empty(n_polys, dtype=np.int32)
    mesh.polygons.foreach_get("loop_start", out)
    return out


def normals(mesh, n_loops):
    """The split normals as Blender keeps them: (domain, float32 array) with domain "POINT"
    (one per vertex: every face smooth, no sharp edges or custom normals), "FACE" (one per face:
    every face flat) or "CORNER" (one per corner). The corner normals are the POINT or FACE
    values gathered to the corners (4.1+ computes them so); before 4.1 always "CORNER"."""
    domain = getattr(mesh, "normals_domain", "CORNER")
    if domain == "POINT":
        return domain, vertex_normals(mesh, len(mesh.vertices))
    if domain == "FACE":
        out = np.empty(len(mesh.polygons) * 3, dtype=np.float32)
        mesh.polygon_normals.foreach_get("vector", out)
        return domain, out.reshape(-1, 3)
    return "CORNER", corner_normals(mesh, n_loops)


def cycles_normals(mesh, n_loops, n_polys):
    """The normals as Cycles shades them: (domain, float32 array, flat) like normals() plus
    flat, a bool per face (None: none) for the faces Cycles shades with each triangle's own
    geometric normal. Cycles (4.1+) asks Blender for the normal domain allowing sharp faces:
    with every face flat (or every edge sharp), every triangle is flat; without custom normals
    or sharp edges, the flat faces are flat triangles and the smooth ones take the vertex
    normals, which average every face around the vertex, the flat ones too (the corner normals
    Blender computes instead stop at flat faces). Only with sharp edges or custom normals does
    it shade with the corner normals (a flat face's then is its polygon's normal)."""
    domain, values = normals(mesh, n_loops)
    if not hasattr(mesh, "normals_domain"):  # before 4.1: as Blender gives them
        return domain, values, None
    if domain == "FACE":
        return domain, values, np.ones(n_polys, dtype=bool)
    if domain != "CORNER" or getattr(mesh, "has_custom_normals", False) or _any_sharp_edge(mesh):
        return domain, values, None
    smooth = np.empty(n_polys, dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    return "POINT", vertex_normals(mesh, len(mesh.vertices)), ~smooth


def _any_sharp_edge(mesh):
    """Whether any edge of the mesh is marked sharp."""
    attributes = getattr(mesh, "attributes", None)
    a = attributes.get("sharp_edge") if attributes is not None else None
    if a is not None and a.domain == "EDGE" and a.data_type == "BOOLEAN":
        values = np.empty(len(a.data), dtype=bool)
        a.data.foreach_get("value", values)
        return bool(values.any())
    values = np.empty(len(mesh.edges), dtype=bool)
    mesh.edges.foreach_get("use_edge_sharp", values)
    return bool(values.any())


def vertex_normals(mesh, n_verts):
    """Blender's vertex normals, float32 (n_verts, 3) (4.1 moved them off the vertices)."""
    out = np.empty(n_verts * 3, dtype=np.float32)
    if hasattr(mesh, "vertex_normals"):
        mesh.vertex_normals.foreach_get("vector", out)
    else:
        mesh.vertices.foreach_get("normal", out)
    return out.reshape(-1, 3)


def corner_normals(mesh, n_loops):
    """Per-corner (split) normals, float32 (n_loops, 3)."""
    if hasattr(mesh, "corner_normals"):  # 4.1+
        out = _read_in_place(mesh.corner_normals, n_loops, np.float32, 3, "vector")
        if out is None:
            out = np.empty((n_loops, 3), dtype=np.float32)
            mesh.corner_normals.foreach_get("vector", out.reshape(-1))
        return out
    out = np.empty(n_loops * 3, dtype=np.float32)
    if hasattr(mesh, "calc_normals_split"):  # 3.x - 4.0
        mesh.calc_normals_split()
    mesh.loops.foreach_get("normal", out)
    return out.reshape(-1, 3)


def _int_attribute(mesh, name, domain):
    attrs = getattr(mesh, "attributes", None)
    a = attrs.get(name) if attrs is not None else None
    return a if a is not None and a.domain == domain and a.data_type == "INT" else None


def corner_verts(mesh, n_loops):
    """The vertex of each corner, int32 (n_loops,). 4.0+ stores it as the attribute
    .corner_vert, which foreach_get copies at once (about 500x faster than loops.vertex_index,
    which goes corner by corner: 0.02 ms vs 9.8 ms for 61k corners in 5.0)."""
    out = np.empty(n_loops, dtype=np.int32)
    a = _int_attribute(mesh, ".corner_vert", "CORNER")
    if a is not None:
        a.data.foreach_get("value", out)
    else:
        mesh.loops.foreach_get("vertex_index", out)
    return out


def face_materials(mesh, n_polys):
    """The material slot index of each face, int32 (n_polys,). 4.0+ (where corners are
    attributes too) keeps it in the attribute material_index, absent when every face uses slot
    0; before, polygons.material_index."""
    out = np.zeros(n_polys, dtype=np.int32)
    a = _int_attribute(mesh, "material_index", "FACE")
    if a is not None:
        a.data.foreach_get("value", out)
    elif _int_attribute(mesh, ".corner_vert", "CORNER") is None:
        mesh.polygons.foreach_get("material_index", out)
    return out


def vertex_positions(mesh, n_verts):
    out = np.empty(n_verts * 3, dtype=np.float32)
    attr = _attribute(mesh, "position", "POINT", "FLOAT_VECTOR", n_verts)
    if attr is not None:  # one array (MeshVertex.co goes item by item)
        attr.data.foreach_get("vector", out)
    else:
        mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def uv_layers(mesh):
    """The mesh's UV maps, the active render one first (glTF set 0), then the others in order."""
    layers = list(mesh.uv_layers)
    if not layers:
        return []
    first = None
    for uv in layers:
        if getattr(uv, "active_render", False):
            first = uv
            break
    if first is None:
        first = mesh.uv_layers.active or layers[0]
    return [first] + [uv for uv in layers if uv.name != first.name]


def corner_uv(layer, n_loops):
    """One UV map per corner, float32 (n_loops, 2)."""
    out = np.empty(n_loops * 2, dtype=np.float32)
    if hasattr(layer, "uv") and len(layer.uv) == n_loops:  # 3.5+
        layer.uv.foreach_get("vector", out)
    else:
        layer.data.foreach_get("uv", out)
    return out.reshape(-1, 2)


def corner_uvs(mesh, n_loops):
    """Active render UV map per corner, float32 (n_loops, 2), or None."""
    layers = uv_layers(mesh)
    return corner_uv(layers[0], n_loops) if layers else None


def adaptive_subdivision(obj, scene):
    """Whether Cycles would dice `obj` by adaptive subdivision: its last modifier a Subdivision
    Surface with Adaptive Subdivision on (a modifier setting since 5.0; before, the object's
    Cycles setting, used only with the Experimental feature set)."""
    mods = [m for m in getattr(obj, "modifiers", ()) if m.show_render]
    last = mods[-1] if mods else None
    if last is None or last.type != "SUBSURF":
        return False
    if hasattr(last, "use_adaptive_subdivision"):
        return bool(last.use_adaptive_subdivision)
    cycles = getattr(scene, "cycles", None)
    return (getattr(cycles, "feature_set", "") == "EXPERIMENTAL"
            and bool(getattr(getattr(obj, "cycles", None), "use_adaptive_subdivision", False)))


def light_is_portal(light):
    """Whether an area light is a Cycles portal (light.cycles.is_portal, 2.8-5.x)."""
    return bool(getattr(getattr(light, "cycles", None), "is_portal", False))


def light_linking_collections(obj):
    """(receiver collection, blocker collection) of an object's light linking (4.0+; None
    where unset or before 4.0)."""
    link = getattr(obj, "light_linking", None)
    if link is None:
        return None, None
    return (getattr(link, "receiver_collection", None),
            getattr(link, "blocker_collection", None))


def light_linking_states(coll):
    """{object name: 'INCLUDE' | 'EXCLUDE'}: each object's state in a light linking
    collection. A child collection's state covers every object under it; objects met more
    than once take the last state met, children before the collection's own objects (the
    order Blender resolves them in). The link states live on collection_objects and
    collection_children, parallel to objects and children (4.0+)."""
    states = {}

    def under(c, state, seen):
        if c.name in seen:
            return
        seen.add(c.name)
        for child in c.children:
            under(child, state, seen)
        for o in c.objects:
            states[o.name] = state

    for child, link in zip(coll.children, getattr(coll, "collection_children", ())):
        under(child, link.light_linking.link_state, set())
    for o, link in zip(coll.objects, getattr(coll, "collection_objects", ())):
        states[o.name] = link.light_linking.link_state
    return states


def color_layers(mesh):
    """Colour attributes (3.2+ color_attributes; legacy vertex_colors before), the render one
    first: a list of (name, domain, collection of elements with a linear 'color')."""
    attrs = getattr(mesh, "color_attributes", None)
    if attrs is not None:
        items = [a for a in attrs if a.domain in ("CORNER", "POINT", "FACE")]
        first = getattr(attrs, "default_color_name", None)
        if first is None:
            render = getattr(attrs, "render_color_index", -1)
            all_attrs = list(attrs)
            first = all_attrs[render].name if 0 <= render < len(all_attrs) else None
        items.sort(key=lambda a: a.name != first)  # stable: the render one first
        out = [(a.name, a.domain, a.data) for a in items]
        # Colours on faces are generic attributes, not colour attributes; Cycles' Attribute
        # node reads them by name all the same.
        seen = {a.name for a in items}
        for a in getattr(mesh, "attributes", ()):
            if (a.domain == "FACE" and a.data_type in ("FLOAT_COLOR", "BYTE_COLOR")
                    and a.name not in seen and not a.name.startswith(".")):
                out.append((a.name, "FACE", a.data))
        return out
    vcols = getattr(mesh, "vertex_colors", None)
    if vcols is None:
        return []
    items = list(vcols)
    items.sort(key=lambda a: not getattr(a, "active_render", False))
    return [(a.name, "CORNER", a.data) for a in items]


# Blender's own mesh attributes, which no Attribute node means: not exported.
_BUILTIN_ATTRIBUTES = frozenset((
    "position", "sharp_face", "material_index", "sharp_edge", "custom_normal", "crease_vert",
    "crease_edge", "bevel_weight_vert", "bevel_weight_edge", "normal", "id"))

# Generic attribute types the Attribute node reads, with the components `foreach_get` gives.
_GENERIC_TYPES = {"FLOAT": ("value", 1), "INT": ("value", 1), "INT8": ("value", 1),
                  "BOOLEAN": ("value", 1), "FLOAT_VECTOR": ("vector", 3), "FLOAT2": ("vector", 2)}


def generic_attributes(mesh, n_by_domain, skip):
    """Named float, integer, boolean and vector attributes (Geometry Nodes' Store Named
    Attribute, Python) on points, faces or corners, as the Attribute node reads them: a list
    of (name, domain, float32 (n, 4)) with floats as (f, f, f, 1), vectors as (x, y, z, 1) and
    2D vectors as (x, y, 0, 1), Cycles' conversions. Names in `skip` (colour attributes, UV
    maps), internal ('.') and built-in ones are left out."""
    out = []
    for a in getattr(mesh, "attributes", ()):
        kind = _GENERIC_TYPES.get(a.data_type)
        n = n_by_domain.get(a.domain)
        if (kind is None or n is None or a.name in skip or a.name.startswith(".")
                or a.name in _BUILTIN_ATTRIBUTES):
            continue
        prop, k = kind
        flat = np.empty(n * k, dtype=np.float32)
        try:
            a.data.foreach_get(prop, flat)
        except (TypeError, RuntimeError, AttributeError):
            continue
        v = np.zeros((n, 4), dtype=np.float32)
        v[:, 3] = 1.0
        if k == 1:
            v[:, :3] = flat[:, None]
        else:
            v[:, :k] = flat.reshape(n, k)
        out.append((a.name, a.domain, v))
    return out


def point_attributes(pointcloud, n, names):
    """The point-domain attributes of a point cloud named in `names` as the Attribute node
    reads them: a list of (name, float32 (n, 4)); colours as they are, the rest converted as
    generic_attributes does."""
    out = []
    for a in getattr(pointcloud, "attributes", ()):
        if a.name not in names or a.domain != "POINT":
            continue
        if a.data_type in ("FLOAT_COLOR", "BYTE_COLOR"):
            v = np.empty(n * 4, dtype=np.float32)
            try:
                a.data.foreach_get("color", v)
            except (TypeError, RuntimeError, AttributeError):
                continue
            out.append((a.name, v.reshape(n, 4)))
    skip = {name for name, _ in out} | {a.name for a in getattr(pointcloud, "attributes", ())
                                        if a.name not in names}
    out += [(name, values) for name, _, values
            in generic_attributes(pointcloud, {"POINT": n}, skip)]
    return out


def corner_tangents(mesh, uv_name, n_loops):
    """Blender's MikkTSpace tangents for a UV map: (float32 (n, 3), float32 (n,) bitangent sign).
    Raises RuntimeError where Blender cannot compute them (n-gons)."""
    mesh.calc_tangents(uvmap=uv_name)
    try:
        t = np.empty(n_loops * 3, dtype=np.float32)
        mesh.loops.foreach_get("tangent", t)
        sign = np.empty(n_loops, dtype=np.float32)
        mesh.loops.foreach_get("bitangent_sign", sign)
    finally:
        if hasattr(mesh, "free_tangents"):
            mesh.free_tangents()
    return t.reshape(-1, 3), sign


def texture_space(mesh):
    """(location, size) of the mesh's texture space (Generated coordinates), or None."""
    loc = getattr(mesh, "texspace_location", None)
    size = getattr(mesh, "texspace_size", None)
    if loc is None or size is None:
        return None
    return [float(v) for v in loc], [float(v) for v in size]


# --- render result -----------------------------------------------------------

def pass_rect_set(render_pass, flat_rgba):
    """Write a contiguous float32 (w*h*4,) array (rows bottom to top) into a pass."""
    try:
        render_pass.rect.foreach_set(flat_rgba)
    except (TypeError, ValueError, RuntimeError):
        # Some versions insist on (pixels, channels).
        render_pass.rect.foreach_set(flat_rgba.reshape(-1, render_pass.channels))


# Blender 4.2 renamed the short render pass names Cycles registers (IndexOB -> Object Index).
_PASS_NAMES_4_2 = {"IndexOB": "Object Index", "IndexMA": "Material Index", "Emit": "Emission",
                   "Env": "Environment",
                   "DiffDir": "Diffuse Direct", "DiffInd": "Diffuse Indirect",
                   "DiffCol": "Diffuse Color", "GlossDir": "Glossy Direct",
                   "GlossInd": "Glossy Indirect", "GlossCol": "Glossy Color",
                   "TransDir": "Transmission Direct", "TransInd": "Transmission Indirect",
                   "TransCol": "Transmission Color"}


def pass_name(name):
    """This Blender's name of the render pass the renderer calls `name` (Blender 3.x names)."""
    if bpy.app.version >= (4, 2, 0):
        return _PASS_NAMES_4_2.get(name, name)
    return name


def find_pass(result, name):
    """The pass called `name` of the result's first layer, or None."""
    layer = result.layers[0]
    if hasattr(layer.passes, "find_by_name"):
        return layer.passes.find_by_name(name, "")
    for p in layer.passes:
        if p.name == name:
            return p
    return None


def combined_pass(result):
    layer = result.layers[0]
    p = layer.passes.find_by_name("Combined", "") if hasattr(layer.passes, "find_by_name") else None
    if p is None:
        p = layer.passes["Combined"]
    return p


# --- lights --------------------------------------------------------------------

def light_color_and_scale(light):
    """(linear colour, power multiplier) with the settings later Blenders added:
    blackbody temperature (4.x), exposure (power * 2^exposure, 4.x)."""
    color = list(light.color)[:3]
    if getattr(light, "use_temperature", False):
        tc = getattr(light, "temperature_color", None)
        if tc is not None:
            color = [c * t for c, t in zip(color, tc)]
    return color, 2.0 ** float(getattr(light, "exposure", 0.0))


def light_normalized(light):
    """4.x 'Normalize': when off, Cycles does not divide the power by the emitting area."""
    return bool(getattr(light, "normalize", True))


def light_soft_falloff(light):
    """Point/spot 'Soft Falloff' (4.0+, on by default): Cycles then renders the radius as a disk
    facing the lit point; off, as a sphere. Before 4.0 Cycles always used the disk."""
    return bool(getattr(light, "use_soft_falloff", True))


def light_uses_mis(light):
    """Cycles' per-light 'Multiple Importance' setting (on by default)."""
    cyc = getattr(light, "cycles", None)
    return bool(getattr(cyc, "use_multiple_importance_sampling", True)) if cyc is not None else True


# --- object visibility ---------------------------------------------------------

def ray_visibility(obj):
    """The object's ray visibility, Object > Visibility > Ray Visibility:
    {"camera", "diffuse", "glossy", "transmission", "shadow"} (3.0+ `visible_*`, before
    `cycles_visibility`)."""
    out = {}
    cv = getattr(obj, "cycles_visibility", None)
    for key in ("camera", "diffuse", "glossy", "transmission", "shadow"):
        v = getattr(obj, "visible_" + key, None)
        if v is None:
            v = getattr(cv, key, True) if cv is not None else True
        out[key] = bool(v)
    return out


def is_holdout(obj, view_layer):
    """Whether the object renders as a holdout in `view_layer`: its own Object > Visibility >
    Holdout or its collection's (View Layer > Holdout); `holdout_get` (2.91+) answers for the
    original object, the plain flag for older versions."""
    orig = getattr(obj, "original", obj) or obj
    get = getattr(orig, "holdout_get", None)
    if get is not None and view_layer is not None:
        try:
            return bool(get(view_layer=view_layer))
        except (TypeError, RuntimeError, ReferenceError):
            pass
    return bool(getattr(orig, "is_holdout", False))


def row_is_geometry(obj):
    """Whether a depsgraph row's object renders as geometry: only rows whose data is a Mesh (as
    Cycles' object_is_geometry). A curve, text, surface or metaball object's own row carries
    its curve data; its evaluated mesh follows as an instance row of its own (3.0+ geometry
    sets; seen in 3.4 and 5.x), which is the one to export."""
    rna = getattr(getattr(obj, "data", None), "rna_type", None)
    return rna is None or rna.identifier == "Mesh"


def is_indirect_only(obj, view_layer):
    """Whether the object's collection is Indirect Only in `view_layer` (View Layer > Indirect
    Only, 2.91+): Cycles then hides it from camera rays only."""
    orig = getattr(obj, "original", obj) or obj
    get = getattr(orig, "indirect_only_get", None)
    if get is None or view_layer is None:
        return False
    try:
        return bool(get(view_layer=view_layer))
    except (TypeError, RuntimeError, ReferenceError):
        return False


def is_extension_platform():
    return VERSION >= (4, 2, 0)


# --- shader node vocabulary -------------------------------------------------------
#
# translate_node() rewrites one exported node (Blender's identifiers of the running version) into
# the 5.x vocabulary the material graph uses. `entry` is the node's graph dict ({"type", "props",
# "inputs", "internal_links", ...}; inputs hold values or {"link": [node, output]}); `emit(dict)`
# appends a helper node and returns its index. The return value maps an output identifier of the
# Blender node to the [node index, output identifier] that now carries it (only outputs that
# moved). Conversions follow Blender's versioning code (versioning_400.cc, versioning_410.cc).

_ONE = [1.0, 1.0, 1.0, 1.0]


def _is_link(v):
    return isinstance(v, dict) and "link" in v


def _lerp(a, b, t):
    return [float(x) + (float(y) - float(x)) * float(t) for x, y in zip(a, b)]


def _rename(entry, inputs=None, outputs=None):
    """Rename input identifiers (and internal links) of a node entry in place."""
    inputs = inputs or {}
    outputs = outputs or {}
    old = entry["inputs"]
    entry["inputs"] = {inputs.get(k, k): v for k, v in old.items()}
    entry["internal_links"] = {outputs.get(o, o): inputs.get(i, i)
                               for o, i in entry.get("internal_links", {}).items()}


def _helper(entry, what, type_, props, inputs):
    h = {"name": "%s [%s]" % (entry["name"], what), "type": type_, "props": props,
         "inputs": inputs, "internal_links": {}}
    if "group" in entry:
        h["group"] = entry["group"]
    return h


def _math(emit, entry, what, op, a, b, clamp=False):
    idx = emit(_helper(entry, what, "ShaderNodeMath", {"operation": op, "use_clamp": clamp},
                       {"Value": a, "Value_001": b}))
    return {"link": [idx, "Value"]}


def _clamp01(emit, entry, what, value):
    idx = emit(_helper(entry, what, "ShaderNodeClamp", {"clamp_type": "MINMAX"},
                       {"Value": value, "Min": 0.0, "Max": 1.0}))
    return {"link": [idx, "Result"]}


def _mix_color(emit, entry, what, fac, a, b):
    idx = emit(_helper(entry, what, "ShaderNodeMix",
                       {"data_type": "RGBA", "blend_type": "MIX", "factor_mode": "UNIFORM",
                        "clamp_factor": True, "clamp_result": False},
                       {"Factor_Float": fac, "A_Color": a, "B_Color": b}))
    return {"link": [idx, "Result_Color"]}


def _translate_mixrgb(node, entry, index, emit):
    # The legacy node always clamps its factor (Cycles' svm_node_mix); use_alpha is ignored by
    # Cycles; use_clamp clamps the result.
    props = entry["props"]
    entry["type"] = "ShaderNodeMix"
    entry["props"] = {"data_type": "RGBA", "factor_mode": "UNIFORM",
                      "blend_type": props.get("blend_type", "MIX"), "clamp_factor": True,
                      "clamp_result": bool(props.get("use_clamp", False))}
    _rename(entry, {"Fac": "Factor_Float", "Color1": "A_Color", "Color2": "B_Color"},
            {"Color": "Result_Color"})
    return {"Color": [index, "Result_Color"]}


_LEGACY_COLOR_NODES = {
    # bl_idname: (new type, mode, input renames, output renames)
    "ShaderNodeSeparateRGB": ("ShaderNodeSeparateColor", "RGB", {"Image": "Color"},
                              {"R": "Red", "G": "Green", "B": "Blue"}),
    "ShaderNodeCombineRGB": ("ShaderNodeCombineColor", "RGB", {"R": "Red", "G": "Green", "B": "Blue"},
                             {"Image": "Color"}),
    "ShaderNodeSeparateHSV": ("ShaderNodeSeparateColor", "HSV", {},
                              {"H": "Red", "S": "Green", "V": "Blue"}),
    "ShaderNodeCombineHSV": ("ShaderNodeCombineColor", "HSV", {"H": "Red", "S": "Green", "V": "Blue"},
                             {}),
}


def _translate_legacy_color(node, entry, index, emit):
    new_type, mode, ins, outs = _LEGACY_COLOR_NODES[entry["type"]]
    entry["type"] = new_type
    entry["props"] = {"mode": mode}
    _rename(entry, ins, outs)
    return {old: [index, new] for old, new in outs.items()}


def _translate_principled_v1(node, entry, index, emit):
    """Principled BSDF of Blender 3.x -> 4.0's, as versioning_400.cc converts it."""
    inp = entry["inputs"]
    # Transmission Roughness is gone (4.0 uses Roughness for refraction too).
    inp.pop("Transmission Roughness", None)
    # Sheen (version_principled_bsdf_sheen): the tint becomes a colour; a fixed sheen is scaled.
    # A linked tint keeps its link (a float into a colour input, as Blender leaves it).
    sheen = inp.get("Sheen", 0.0)
    tint_linked = _is_link(inp.get("Sheen Tint"))
    if not _is_link(sheen):
        inp["Sheen"] = float(sheen) * 0.2
        if not tint_linked:
            inp["Sheen Tint"] = list(_ONE)
    elif not tint_linked:
        inp["Sheen Tint"] = [0.2, 0.2, 0.2, 1.0]
    # Coat (version_principled_bsdf_coat).
    coat = inp.get("Clearcoat", 0.0)
    if _is_link(coat):
        inp["Coat IOR"] = 1.2
    else:
        inp["Clearcoat"] = float(coat) * 0.25
        inp["Coat IOR"] = 1.5
    # Subsurface (version_principled_bsdf_subsurface).
    ss = inp.get("Subsurface", 0.0)
    ss_color = inp.pop("Subsurface Color", [0.8, 0.8, 0.8, 1.0])
    if not _is_link(ss) and float(ss) == 0.0:
        inp["Subsurface Scale"] = 0.05
    else:
        inp["Subsurface Scale"] = ss
        base = inp.get("Base Color", [0.8, 0.8, 0.8, 1.0])
        if _is_link(ss) or _is_link(ss_color) or _is_link(base):
            inp["Base Color"] = _mix_color(emit, entry, "subsurface colour", ss, base, ss_color)
        else:
            inp["Base Color"] = _lerp(base, ss_color, ss)
        inp["Subsurface"] = 1.0
    # Specular tint (version_principled_bsdf_specular_tint): a colour,
    # mix(one, mix(base_color, one, metallic), old_tint).
    tint = inp.get("Specular Tint", 0.0)
    base = inp.get("Base Color", [0.8, 0.8, 0.8, 1.0])
    metallic = inp.get("Metallic", 0.0)
    if not _is_link(tint) and float(tint) <= 0.0:
        inp["Specular Tint"] = list(_ONE)
    else:
        if _is_link(metallic) or (_is_link(base) and float(metallic) > 0.0):
            metallic_mix = _mix_color(emit, entry, "specular tint metallic", metallic, base, list(_ONE))
        elif _is_link(base):
            metallic_mix = base
        else:
            metallic_mix = _lerp(base, _ONE, metallic)
        if _is_link(tint) or _is_link(metallic_mix):
            inp["Specular Tint"] = _mix_color(emit, entry, "specular tint", tint, list(_ONE), metallic_mix)
        else:
            inp["Specular Tint"] = _lerp(_ONE, metallic_mix, tint)
    _rename(entry, {"Emission": "Emission Color", "Specular": "Specular IOR Level",
                    "Subsurface": "Subsurface Weight", "Transmission": "Transmission Weight",
                    "Clearcoat": "Coat Weight", "Clearcoat Roughness": "Coat Roughness",
                    "Clearcoat Normal": "Coat Normal", "Sheen": "Sheen Weight"})
    return None


# 4.0 renamed the subsurface methods: the old fixed-radius walk is now "Random Walk" and the old
# "Random Walk" (with IOR) is "Random Walk (Skin)".
_SUBSURFACE_METHOD_3X = {"RANDOM_WALK_FIXED_RADIUS": "RANDOM_WALK", "RANDOM_WALK": "RANDOM_WALK_SKIN"}


def _remove_sharp(entry):
    """4.0 removed the Sharp distribution: GGX with roughness 0 (link removed)."""
    if entry["props"].get("distribution") == "SHARP":
        entry["props"]["distribution"] = "GGX"
        entry["inputs"]["Roughness"] = 0.0


def _translate_noise_3x(node, entry, index, emit):
    """Noise before 4.1 (no type): fBM with its roughness clamped (versioning_410); before 4.0
    (no normalize flag either) always normalized (400.16 sets the flag)."""
    entry["props"]["noise_type"] = "FBM"
    entry["props"].setdefault("normalize", True)
    rough = entry["inputs"].get("Roughness")
    if _is_link(rough):
        entry["inputs"]["Roughness"] = _clamp01(emit, entry, "roughness clamp", rough)
    elif rough is not None:
        entry["inputs"]["Roughness"] = min(1.0, max(0.0, float(rough)))
    return None


def _translate_musgrave(node, entry, index, emit):
    """Musgrave (removed in 4.1) -> Noise, as versioning_replace_musgrave_texture_node does."""
    props, inp = entry["props"], entry["inputs"]
    kind = props.get("musgrave_type", "FBM")
    entry["type"] = "ShaderNodeTexNoise"
    entry["props"] = {"noise_dimensions": props.get("musgrave_dimensions", "3D"),
                      "noise_type": kind, "normalize": False}
    _rename(entry, {"Dimension": "Roughness"})
    inp = entry["inputs"]
    outputs = {}
    fac = {"link": [index, "Fac"]}
    detail = inp.get("Detail", 2.0)
    ridged_or_hetero = kind in ("RIDGED_MULTIFRACTAL", "HETERO_TERRAIN")
    if _is_link(detail):
        sub1_b = 1.0
        if ridged_or_hetero:
            sub1_b = _math(emit, entry, "detail > 1", "GREATER_THAN", detail, 1.0)
        sub1 = _math(emit, entry, "detail - 1", "SUBTRACT", detail, sub1_b)
        inp["Detail"] = _math(emit, entry, "detail min", "MINIMUM", sub1, 14.0)
        if not ridged_or_hetero:
            clamp = _clamp01(emit, entry, "detail clamp", detail)
            mul = _math(emit, entry, "fac * detail", "MULTIPLY", fac, clamp)
            if kind == "MULTIFRACTAL":
                sub2 = _math(emit, entry, "1 - detail", "SUBTRACT", 1.0, detail, clamp=True)
                outputs["Fac"] = _math(emit, entry, "fac offset", "ADD", mul, sub2)["link"]
            else:
                outputs["Fac"] = mul["link"]
    else:
        detail = float(detail)
        if detail < 1.0:
            if not ridged_or_hetero:
                mul = _math(emit, entry, "fac * detail", "MULTIPLY", fac, detail)
                if kind == "MULTIFRACTAL":
                    outputs["Fac"] = _math(emit, entry, "fac offset", "ADD", mul, 1.0 - detail)["link"]
                else:
                    outputs["Fac"] = mul["link"]
                inp["Detail"] = 0.0
        else:
            inp["Detail"] = min(detail - 1.0, 14.0)
    rough = inp.get("Roughness", 2.0)
    lac = inp.get("Lacunarity", 2.0)
    if not _is_link(rough):
        rough = max(float(rough), 1e-5)
    if not _is_link(lac):
        lac = max(float(lac), 1e-5)
    if _is_link(rough):
        max1 = _math(emit, entry, "roughness max", "MAXIMUM", rough, -1e-5)
        neg = _math(emit, entry, "-roughness", "MULTIPLY", max1, -1.0)
        if _is_link(lac):
            lac = _math(emit, entry, "lacunarity max", "MAXIMUM", lac, -1e-5)
        inp["Roughness"] = _math(emit, entry, "lacunarity ^ -roughness", "POWER", lac, neg)
        inp["Lacunarity"] = lac
    elif _is_link(lac):
        lac = _math(emit, entry, "lacunarity max", "MAXIMUM", lac, -1e-5)
        inp["Roughness"] = _math(emit, entry, "lacunarity ^ -roughness", "POWER", lac, -rough)
        inp["Lacunarity"] = lac
    else:
        inp["Roughness"] = lac ** (-rough)
        inp["Lacunarity"] = lac
    return {k: list(v) for k, v in outputs.items()}


def _translate_sky(entry):
    """Before 5.0 single scattering was called Nishita and the aerosols dust."""
    props = entry["props"]
    if props.get("sky_type") == "NISHITA":
        props["sky_type"] = "SINGLE_SCATTERING"
    if "dust_density" in props:
        props.setdefault("aerosol_density", props.pop("dust_density"))


def translate_node(node, entry, index, emit):
    """Rewrite `entry` into the 5.x vocabulary (see the comment above). Returns the moved outputs."""
    t = entry["type"]
    if t == "ShaderNodeMixRGB":
        return _translate_mixrgb(node, entry, index, emit)
    if t in _LEGACY_COLOR_NODES:
        return _translate_legacy_color(node, entry, index, emit)
    if t == "ShaderNodeTexMusgrave":
        return _translate_musgrave(node, entry, index, emit)
    if t == "ShaderNodeTexNoise" and "noise_type" not in entry["props"]:
        return _translate_noise_3x(node, entry, index, emit)
    if t == "ShaderNodeBsdfPrincipled":
        method = entry["props"].get("subsurface_method")
        if VERSION < (4, 0, 0) and method in _SUBSURFACE_METHOD_3X:
            entry["props"]["subsurface_method"] = _SUBSURFACE_METHOD_3X[method]
        if node.inputs.get("Subsurface Color") is not None or node.inputs.get("Clearcoat") is not None:
            return _translate_principled_v1(node, entry, index, emit)
        return None
    if t == "ShaderNodeSubsurfaceScattering":
        falloff = entry["props"].get("falloff")
        if VERSION < (4, 0, 0) and falloff in _SUBSURFACE_METHOD_3X:
            entry["props"]["falloff"] = _SUBSURFACE_METHOD_3X[falloff]
        return None
    if t == "ShaderNodeBsdfGlossy":
        # 4.0 merged Anisotropic into Glossy under the Anisotropic node's bl_idname.
        entry["type"] = "ShaderNodeBsdfAnisotropic"
        _remove_sharp(entry)
        return None
    if t in ("ShaderNodeBsdfAnisotropic", "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"):
        _remove_sharp(entry)
        return None
    if t == "ShaderNodeBsdfVelvet":
        entry["type"] = "ShaderNodeBsdfSheen"
        entry["props"] = {"distribution": "ASHIKHMIN"}
        _rename(entry, {"Sigma": "Roughness"})
        return None
    if t == "ShaderNodeTexSky":
        _translate_sky(entry)
        return None
    if t == "ShaderNodeBsdfHairPrincipled" and "model" not in entry["props"]:
        entry["props"]["model"] = "CHIANG"
        return None
    return None


# --- viewport drawing ------------------------------------------------------------------------
# Since Blender 2.91 the 3D viewport keeps a scene-linear colour buffer and applies the view
# transform, look and exposure itself when it shows the region; an engine's
# bind_display_space_shader binds Blender's builtin image shader (measured with Blender 3.4:
# the region's framebuffer holds the texture's linear values, the screen their view transform).
# Python cannot draw with "the bound shader", so the texture is drawn with that same builtin
# shader, between the engine's bind/unbind calls as Cycles makes them.

def draw_scene_linear_texture(engine, scene, texture, rect, uv):
    """Draw `texture` into rect (x, y, w, h; region pixels, bottom-left origin), texture
    coordinates uv (u0, v0, u1, v1)."""
    import gpu
    from gpu_extras.batch import batch_for_shader
    x, y, w, h = rect
    u0, v0, u1, v1 = uv
    shader = gpu.shader.from_builtin("IMAGE")
    batch = batch_for_shader(  # triangles: Blender 4+ backends have no triangle fans
        shader, "TRIS",
        {"pos": ((x, y), (x + w, y), (x + w, y + h), (x, y + h)),
         "texCoord": ((u0, v0), (u1, v0), (u1, v1), (u0, v1))},
        indices=((0, 1, 2), (2, 3, 0)))
    engine.bind_display_space_shader(scene)
    shader.bind()
    shader.uniform_sampler("image", texture)
    batch.draw(shader)
    engine.unbind_display_space_shader()


def blf_size(font, size):
    """blf.size: Blender 3.x also takes a dpi (deprecated in 3.4, gone in 4.0)."""
    import blf
    if VERSION >= (4, 0, 0):
        blf.size(font, size)
    else:
        blf.size(font, size, 72)


def frame_final(scene):
    """The scene's current frame with its subframe (what a particle's age is counted to)."""
    final = getattr(scene, "frame_current_final", None)
    return float(scene.frame_current if final is None else final)


def motion_blur_position(scene):
    """Motion Blur > Position ('START', 'CENTER', 'END'): the render settings' since Blender
    4.x, Cycles' scene settings before."""
    position = getattr(scene.render, "motion_blur_position", None)
    if position is None:
        position = getattr(getattr(scene, "cycles", None), "motion_blur_position", "CENTER")
    return position


def film_transparent_glass(scene):
    """Cycles' Film > Transparent > Transparent Glass: its roughness threshold
    (``cycles.film_transparent_roughness``) when ``cycles.film_transparent_glass`` is on, else
    None. Both live in Cycles' scene settings (``scene.cycles``) from Blender 2.80 through 5.x;
    without them (Cycles not loaded) the setting is off."""
    cyc = getattr(scene, "cycles", None)
    if not bool(getattr(cyc, "film_transparent_glass", False)):
        return None
    return float(getattr(cyc, "film_transparent_roughness", 0.1))


def rolling_shutter_type(scene):
    """Cycles' rolling shutter type ('NONE', 'TOP'), or None without Cycles' settings."""
    return getattr(getattr(scene, "cycles", None), "rolling_shutter_type", None)


def shutter_curve_is_flat(render):
    """Whether the Motion Blur > Shutter Curve is flat (Cycles' default: the shutter is open
    evenly over its interval)."""
    curve = getattr(render, "motion_blur_shutter_curve", None)
    if curve is None or not len(curve.curves):
        return True
    ys = [p.location[1] for p in curve.curves[0].points]
    return not ys or max(ys) - min(ys) <= 1e-6
