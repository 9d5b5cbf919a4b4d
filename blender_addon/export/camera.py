# SPDX-License-Identifier: MIT
"""Blender cameras -> glTF cameras at the render resolution."""

import math

import numpy as np

from .common import matrix


def camera_fields(cam_data, width, height):
    """glTF camera dict for a Blender camera at the render resolution."""
    aspect = width / float(height)
    if cam_data.type == "ORTHO":
        fit = cam_data.sensor_fit
        if fit == "AUTO":
            fit = "HORIZONTAL" if width >= height else "VERTICAL"
        half = cam_data.ortho_scale / 2.0
        if fit == "HORIZONTAL":
            xmag, ymag = half, half / aspect
        else:
            xmag, ymag = half * aspect, half
        return {"type": "orthographic",
                "orthographic": {"xmag": xmag, "ymag": ymag,
                                 "znear": max(1e-4, cam_data.clip_start),
                                 "zfar": max(cam_data.clip_end, cam_data.clip_start + 1e-3)}}
    f = cam_data.lens
    fit = cam_data.sensor_fit
    if fit == "AUTO":
        sensor = cam_data.sensor_width
        if width >= height:
            half_w = sensor / (2.0 * f)
            half_h = half_w / aspect
        else:
            half_h = sensor / (2.0 * f)
    elif fit == "HORIZONTAL":
        half_w = cam_data.sensor_width / (2.0 * f)
        half_h = half_w / aspect
    else:
        half_h = cam_data.sensor_height / (2.0 * f)
    yfov = 2.0 * math.atan(half_h)
    return {"type": "perspective",
            "perspective": {"aspectRatio": aspect, "yfov": yfov,
                            "znear": max(1e-4, cam_data.clip_start),
                            "zfar": max(cam_data.clip_end, cam_data.clip_start + 1e-3)}}


def camera_matrix(obj):
    """World matrix without scale (cameras must not scale their frustum)."""
    m = matrix(obj.matrix_world)
    for i in range(3):
        n = np.linalg.norm(m[:3, i])
        if n > 0:
            m[:3, i] /= n
    return m
