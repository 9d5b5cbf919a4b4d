# SPDX-License-Identifier: MIT
"""Curves objects (Blender's hair and fur, grass, strands from Geometry Nodes) ->
TESELA_curves on the object's node (docs/extensions.md): the control points in object space,
their radii, where each curve starts, whether the curves are poly lines, and the material of
each curve. The renderer builds the round tubes Cycles renders from them."""

import numpy as np

from .buffer import FLOAT, UINT

POLY = 1  # Blender's CURVE_TYPE_POLY


def _read(attr, prop, width, dtype=np.float32):
    data = np.zeros(len(attr.data) * width, dtype=dtype)
    attr.data.foreach_get(prop, data)
    return data


def curves_extension(curves, material_indices, buf):
    """The TESELA_curves dict of evaluated Curves data `curves`, its accessors added to `buf`;
    `material_indices`: the glTF material of each of the object's slots (None for empty);
    None when there is nothing to render."""
    attrs = curves.attributes
    position = attrs.get("position")
    if position is None or len(position.data) < 2 or len(curves.curves) == 0:
        return None
    points = _read(position, "vector", 3)
    offsets = np.zeros(len(curves.curve_offset_data), dtype=np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    ext = {"points": buf.add(points, FLOAT, "VEC3", None),
           "offsets": buf.add(offsets.astype(np.uint32), UINT, "SCALAR", None)}
    radius = attrs.get("radius")
    if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
        ext["radius"] = buf.add(_read(radius, "value", 1), FLOAT, "SCALAR", None)
    # Cycles looks at the first curve's type only.
    types = attrs.get("curve_type")
    if types is not None and len(types.data) and types.data[0].value == POLY:
        ext["linear"] = True
    ext["materials"] = list(material_indices) or [None]
    index = attrs.get("material_index")
    if index is not None and index.domain == "CURVE" and len(material_indices) > 1:
        values = _read(index, "value", 1, np.int32).astype(np.float32)
        ext["material_index"] = buf.add(values, FLOAT, "SCALAR", None)
    return ext
