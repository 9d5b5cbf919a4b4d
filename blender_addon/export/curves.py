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


def _shape_radius(shape, root, tip, time):
    """Cycles' hair radius along a particle strand at `time` (0 root .. 1 tip): from root to
    tip, curved by the Shape setting (negative thins it early, positive late)."""
    r = 1.0 - time
    if shape < 0.0:
        r = r ** (1.0 + shape)
    elif shape > 0.0:
        r = r ** (1.0 / (1.0 - shape))
    return r * (root - tip) + tip


def particle_hair_extension(obj, psys, world_to_object, material_indices, buf, render):
    """TESELA_curves of hair particle system `psys` of evaluated object `obj`, as Cycles reads
    it: the strand paths Blender caches (its render steps in a final render, display steps
    otherwise; children instead of parents when there are any), in the object's space through
    `world_to_object` (4x4 numpy), radii from the system's root and tip radius, scale, shape
    and close tip, the system's material slot. None without strands."""
    st = psys.settings
    steps = (1 << (st.render_step if render else st.display_step)) + 1
    if st.kink == "SPIRAL":
        steps += st.kink_extra_steps
    parents = len(psys.particles)
    children = len(psys.child_particles)
    if not render:
        children = int(children * st.display_percentage / 100.0)
    if st.child_type != "NONE" and children:
        first, count = parents, children
    else:
        first, count = 0, parents
    # The settings give widths: half of them is the radius.
    root = 0.5 * st.root_radius * st.radius_scale
    tip = 0.5 * st.tip_radius * st.radius_scale
    points, radii, offsets = [], [], [0]
    for p in range(first, first + count):
        keys = []
        for s in range(steps):
            co = psys.co_hair(object=obj, particle_no=p, step=s)
            if keys and co[:] == keys[-1]:
                continue  # Cycles drops repeated points
            keys.append(co[:])
        if len(keys) < 2:
            continue
        k = np.array(keys, dtype=np.float64)
        seg = np.linalg.norm(np.diff(k, axis=0), axis=1)
        total = seg.sum()
        if not total > 0.0:
            continue
        along = np.concatenate([[0.0], np.cumsum(seg)]) / total
        r = [_shape_radius(st.shape, root, tip, t) for t in along]
        if st.use_close_tip:
            r[-1] = 0.0
        local = (world_to_object[:3, :3] @ k.T).T + world_to_object[:3, 3]
        points.append(local)
        radii.extend(r)
        offsets.append(offsets[-1] + len(keys))
    if not points:
        return None
    points = np.concatenate(points).astype(np.float32)
    slot = min(max(st.material - 1, 0), max(len(material_indices) - 1, 0))
    return {"points": buf.add(points, FLOAT, "VEC3", None),
            "radius": buf.add(np.array(radii, dtype=np.float32), FLOAT, "SCALAR", None),
            "offsets": buf.add(np.array(offsets, dtype=np.uint32), UINT, "SCALAR", None),
            "materials": [material_indices[slot] if material_indices else None]}
