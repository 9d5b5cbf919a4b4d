# SPDX-License-Identifier: MIT
"""Small helpers shared by the export modules (matrices, finite numbers, cancellation)."""

import math

import numpy as np

# Blender (x, y, z) -> glTF (x, z, -y)
Z_UP_TO_Y_UP = np.array([[1, 0, 0, 0],
                         [0, 0, 1, 0],
                         [0, -1, 0, 0],
                         [0, 0, 0, 1]], dtype=np.float64)


class ExportCancelled(Exception):
    pass


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
