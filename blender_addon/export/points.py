# SPDX-License-Identifier: MIT
"""Point clouds (Geometry Nodes points: Mesh to Points, Distribute Points on Faces, Points) ->
TESELA_points on the object's node (docs/extensions.md): the centres in object space, their
radii, the object's first material (Cycles shades every point with it) and the point
attributes its Attribute nodes read. The renderer builds the spheres Cycles renders."""

import numpy as np

from .. import compat
from .buffer import FLOAT


def points_extension(pointcloud, material, reads, buf):
    """The TESELA_points dict of evaluated point cloud data `pointcloud`, its accessors added to
    `buf`; `material`: the glTF material of the object's first slot (or None); `reads`: the
    names of the geometry attributes its materials read. None when there are no points."""
    attrs = pointcloud.attributes
    position = attrs.get("position")
    n = len(position.data) if position is not None else 0
    if n == 0:
        return None
    points = np.empty(n * 3, dtype=np.float32)
    position.data.foreach_get("vector", points)
    ext = {"points": buf.add(points, FLOAT, "VEC3", None), "material": material}
    radius = attrs.get("radius")
    if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
        r = np.empty(n, dtype=np.float32)
        radius.data.foreach_get("value", r)
        ext["radius"] = buf.add(r, FLOAT, "SCALAR", None)
    wanted = {name for name in reads if name}
    if wanted:
        found = compat.point_attributes(pointcloud, n, wanted)
        if found:
            ext["attributes"] = {name: buf.add(values.ravel(), FLOAT, "VEC4", None)
                                 for name, values in found}
    return ext
