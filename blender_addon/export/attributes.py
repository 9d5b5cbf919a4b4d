# SPDX-License-Identifier: MIT
"""The Attribute node's Object, Instancer and View Layer types: values Blender looks up by name
on data-blocks rather than on the geometry, as Cycles resolves them
(`BKE_object_dupli_find_rgba_attribute`, `BKE_view_layer_find_rgba_attribute`).

A name is a custom property of the data-block (``obj["tint"]``) or else a property path on it
(``color``, ``location``, ``modifiers["Array"].count``); a number or boolean reads as
``(v, v, v, 1)``, an array of up to four numbers fills RGBA from ``(0, 0, 0, 1)``. A name that
nothing has reads as zero. The values travel per object in ``tesela_object.attributes`` and, for
the View Layer type, in the node's ``value``.
"""

import bpy
import numpy as np

_NO_ID = 2147483647  # an unused level of a depsgraph instance's persistent_id

# Attribute data type -> (element property, components): how an instance attribute converts
# to RGBA as Blender's lookup as ColorGeometry4f does.
_INSTANCE_TYPES = {
    "FLOAT": ("value", 1), "INT": ("value", 1), "BOOLEAN": ("value", 1),
    "INT8": ("value", 1), "FLOAT2": ("vector", 2), "INT32_2D": ("value", 2),
    "FLOAT_VECTOR": ("vector", 3), "FLOAT_COLOR": ("color", 4), "BYTE_COLOR": ("color", 4),
}

ATTRIBUTE_NODE = "ShaderNodeAttribute"


def _rgba(value):
    """A property value as an RGBA list, or None when it is not numeric."""
    if isinstance(value, bool):
        value = 1.0 if value else 0.0
    if isinstance(value, (int, float)):
        v = float(value)
        return [v, v, v, 1.0]
    try:
        items = list(value)
    except TypeError:
        return None
    if not 0 < len(items) <= 4:
        return None
    out = [0.0, 0.0, 0.0, 1.0]
    for i, x in enumerate(items):
        if isinstance(x, bool):
            x = 1.0 if x else 0.0
        if not isinstance(x, (int, float)):
            return None
        out[i] = float(x)
    return out


def find_rgba(owner, name):
    """`name` on `owner` (a data-block or a view layer) as RGBA, or None."""
    if owner is None or not name:
        return None
    try:
        if name in owner.keys():
            return _rgba(owner[name])
    except (TypeError, AttributeError):
        pass
    try:
        value = owner.path_resolve(name)
    except (ValueError, AttributeError, TypeError):
        return None
    return _rgba(value)


def view_layer_value(view_layer, name):
    """The View Layer type's value: the view layer, its scene, then the scene's world."""
    scene = getattr(view_layer, "id_data", None) if view_layer is not None else None
    for owner in (view_layer, scene, getattr(scene, "world", None)):
        v = find_rgba(owner, name)
        if v is not None:
            return v
    return None


def material_reads(obj):
    """What `obj`'s materials (and their node groups) read of the object, found in one walk
    of their trees: {"OBJECT": names, "INSTANCER": names, "GEOMETRY": names} of their
    Attribute nodes of those types, and "PARTICLE_INFO": whether one has a Particle Info
    node."""
    out = {"OBJECT": set(), "INSTANCER": set(), "GEOMETRY": set(), "PARTICLE_INFO": False}
    seen = set()

    def walk(tree):
        if tree is None or tree.as_pointer() in seen:
            return
        seen.add(tree.as_pointer())
        for node in tree.nodes:
            if node.bl_idname == ATTRIBUTE_NODE:
                kind = getattr(node, "attribute_type", "GEOMETRY")
                if kind in ("OBJECT", "INSTANCER", "GEOMETRY") and node.attribute_name:
                    out[kind].add(node.attribute_name)
            elif node.bl_idname == "ShaderNodeParticleInfo":
                out["PARTICLE_INFO"] = True
            elif node.bl_idname == "ShaderNodeGroup":
                walk(node.node_tree)

    for slot in getattr(obj, "material_slots", ()):
        if slot.material is not None:
            walk(slot.material.node_tree)
    return out


class InstanceAttributes:
    """The Geometry Nodes instance attributes of the instancers of one export, read once per
    instancer (Blender 4.3+ gives an evaluated object's instances as a point cloud)."""

    def __init__(self):
        self._instancers = {}

    def _instancer(self, parent):
        key = parent.name
        if key not in self._instancers:
            self._instancers[key] = self._read(parent)
        return self._instancers[key]

    @staticmethod
    def _read(parent):
        """(persistent id -> instance index or None for the identity, point cloud) of
        `parent`'s instances, or None."""
        get = getattr(parent, "evaluated_geometry", None)
        if get is None:
            return None
        try:
            geometry = get()
            cloud = geometry.instances_pointcloud()
        except (RuntimeError, AttributeError):
            return None
        if cloud is None:
            return None
        # The point cloud lives as long as this call's geometry: read every column now.
        # A depsgraph instance's id is the instance's "id" attribute where it has one (as
        # Distribute Points on Faces writes it), else its index.
        ids = cloud.attributes.get("id")
        index = None
        if ids is not None and ids.data_type == "INT":
            values = np.zeros(len(ids.data), dtype=np.int32)
            ids.data.foreach_get("value", values)
            index = {int(v): i for i, v in enumerate(values)}
            if len(index) != len(values):
                return None  # ids Blender had to make unique: no way to match them here
        columns = {}
        for attr in cloud.attributes:
            column = _column(attr)
            if column is not None:
                columns[attr.name] = column
        return index, columns

    def value(self, inst, name):
        """RGBA of instance attribute `name` for depsgraph instance `inst`, or None."""
        parent = inst.parent if inst.is_instance else None
        if parent is None:
            return None
        found = self._instancer(parent)
        if found is None:
            return None
        index, columns = found
        levels = [v for v in inst.persistent_id if v != _NO_ID]
        if len(levels) != 2:
            return None  # an instance of an instance: its attributes live a level deeper
        i = levels[-1] if index is None else index.get(levels[-1])
        column = columns.get(name)
        if column is None or i is None or not 0 <= i < len(column):
            return None
        return [float(x) for x in column[i]]


def _column(attr):
    """An instance attribute as an (n, 4) RGBA array, or None (internal and non-numeric
    ones)."""
    if attr.domain != "POINT" or attr.name.startswith(".") or attr.name in (
            "position", "instance_transform"):
        return None
    kind = _INSTANCE_TYPES.get(attr.data_type)
    if kind is None:
        return None
    prop, width = kind
    n = len(attr.data)
    flat = np.zeros(n * width, dtype=np.float64)
    if attr.data_type == "BOOLEAN":
        raw = np.zeros(n, dtype=bool)
        attr.data.foreach_get(prop, raw)
        flat[:] = raw
    elif attr.data_type in ("INT", "INT8", "INT32_2D"):
        raw = np.zeros(n * width, dtype=np.int32)
        attr.data.foreach_get(prop, raw)
        flat[:] = raw
    else:
        raw = np.zeros(n * width, dtype=np.float32)
        attr.data.foreach_get(prop, raw)
        flat[:] = raw
    out = np.zeros((n, 4))
    out[:, 3] = 1.0
    cols = flat.reshape(n, width)
    if width == 1:
        out[:, :3] = cols
    else:
        out[:, :width] = cols
    return out


def object_attributes(inst, obj, names, instance_attributes=None):
    """``tesela_object.attributes`` for instance `inst` of `obj`: the values of the requested
    names, each found in Cycles' order (Object: the object, then its data; Instancer: an
    instance's particle settings, its Geometry Nodes instance attributes (through
    `instance_attributes`, an InstanceAttributes), its instancer, then the object and its
    data). None if nothing is requested or found."""
    out = {}
    data = getattr(obj, "data", None)
    if names["OBJECT"]:
        found = {n: find_rgba(obj, n) or find_rgba(data, n) for n in sorted(names["OBJECT"])}
        found = {n: v for n, v in found.items() if v is not None}
        if found:
            out["object"] = found
    if names["INSTANCER"]:
        psys = getattr(inst, "particle_system", None) if inst.is_instance else None
        parent = inst.parent if inst.is_instance else None
        owners = [getattr(psys, "settings", None), parent, obj, data]
        found = {}
        for n in sorted(names["INSTANCER"]):
            v = find_rgba(owners[0], n)
            if v is None and instance_attributes is not None:
                v = instance_attributes.value(inst, n)
            for owner in owners[1:]:
                if v is not None:
                    break
                v = find_rgba(owner, n)
            if v is not None:
                found[n] = v
        if found:
            out["instancer"] = found
    return out or None


def current_view_layer():
    """The view layer of the context, for material exports that have no depsgraph (the
    viewport's incremental updates)."""
    return getattr(bpy.context, "view_layer", None)
