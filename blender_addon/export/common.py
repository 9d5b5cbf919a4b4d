# SPDX-License-Identifier: MIT
"""Small helpers shared by the export modules (matrices, finite numbers, cancellation)."""

import contextlib
import math
import time

import numpy as np

# Blender (x, y, z) -> glTF (x, z, -y)
Z_UP_TO_Y_UP = np.array([[1, 0, 0, 0],
                         [0, 0, 1, 0],
                         [0, -1, 0, 0],
                         [0, 0, 0, 1]], dtype=np.float64)


class ExportCancelled(Exception):
    pass


class Phases:
    """Wall-clock seconds of one export per phase (to_mesh, normals, write, ...), summed over
    the meshes, in the order the phases first ran: what the render log and bench/export.py
    print."""

    def __init__(self):
        self.seconds = {}

    def add(self, name, seconds):
        self.seconds[name] = self.seconds.get(name, 0.0) + seconds

    @contextlib.contextmanager
    def __call__(self, name):
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.add(name, time.perf_counter() - t0)

    def summary(self):
        """'to_mesh 0.52 s, normals 0.31 s, ...' (phases under 5 ms left out)."""
        return ", ".join("%s %.2f s" % (k, v) for k, v in self.seconds.items() if v >= 0.005)


def matrix(mat):
    """A Blender Matrix (4x4, row-major) -> numpy float64."""
    return np.array([list(row) for row in mat], dtype=np.float64)


def gltf_matrix(np_mat):
    """glTF wants column-major flattening."""
    m = Z_UP_TO_Y_UP @ np_mat
    return [float(v) for v in m.T.reshape(-1)]


def finite(v, default=0.0):
    v = float(v)
    return v if math.isfinite(v) else default


def color3(c):
    return [max(0.0, finite(c[0])), max(0.0, finite(c[1])), max(0.0, finite(c[2]))]


class TreeReport:
    """report(owner_name, node, message, kind=None), as MaterialReport, for the node tree of a
    world or a light (`what`): each problem once, as `world 'NAME': node 'NODE' (TYPE): ...`."""

    def __init__(self, warnings, what):
        self.warnings, self.what = warnings, what
        self._seen = set()

    def __call__(self, owner_name, node, message, kind=None):
        node_name = node if node is None or isinstance(node, str) else node.name
        key = (owner_name, node_name, kind or message)
        if key in self._seen:
            return
        self._seen.add(key)
        if node_name is None:
            text = "%s '%s': %s" % (self.what, owner_name, message)
        else:
            idname = getattr(node, "bl_idname", None)
            text = "%s '%s': node '%s'%s: %s" % (
                self.what, owner_name, node_name, " (%s)" % idname if idname else "", message)
        self.warnings.append(text)
