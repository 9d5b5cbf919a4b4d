# SPDX-License-Identifier: MIT
"""Blender cameras -> glTF cameras at the render resolution, and TESELA_camera (their native
data: sensor fit, shift, clipping, depth of field, panoramas)."""

import math

import numpy as np

from .common import finite, matrix


def camera_fields(cam_data, width, height, pixel_aspect=1.0):
    """glTF camera dict for a Blender camera at the render resolution (`pixel_aspect`: a
    pixel's width over its height; the glTF camera gets the image's physical shape)."""
    aspect = width * pixel_aspect / float(height)
    if cam_data.type == "ORTHO":
        fit = cam_data.sensor_fit
        if fit == "AUTO":
            fit = "HORIZONTAL" if aspect >= 1.0 else "VERTICAL"
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
        if aspect >= 1.0:
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


# Panoramic settings: on the camera since Blender 4.0, on its Cycles settings (cam.cycles) before.
PANORAMA_FIELDS = (
    "fisheye_fov", "fisheye_lens", "latitude_min", "latitude_max", "longitude_min",
    "longitude_max", "fisheye_polynomial_k0", "fisheye_polynomial_k1", "fisheye_polynomial_k2",
    "fisheye_polynomial_k3", "fisheye_polynomial_k4", "central_cylindrical_range_u_min",
    "central_cylindrical_range_u_max", "central_cylindrical_range_v_min",
    "central_cylindrical_range_v_max", "central_cylindrical_radius")


def _panorama_setting(cam_data, name):
    if hasattr(cam_data, name):
        return getattr(cam_data, name)
    return getattr(getattr(cam_data, "cycles", None), name, None)


def focus_distance(cam_obj):
    """The depth of field's focus distance as Cycles takes it: `dof.focus_distance`, or with a
    focus object (or one of its bones) the distance of its origin along the camera's view axis."""
    dof = cam_obj.data.dof
    target = dof.focus_object
    if target is None:
        return finite(dof.focus_distance)
    m = matrix(target.matrix_world)
    sub = getattr(dof, "focus_subtarget", "")
    pose = getattr(target, "pose", None)
    if sub and pose is not None and sub in pose.bones:
        m = m @ matrix(pose.bones[sub].matrix)
    cm = camera_matrix(cam_obj)
    view = cm[:3, 2] / max(np.linalg.norm(cm[:3, 2]), 1e-30)
    return finite(abs(float(np.dot(view, cm[:3, 3] - m[:3, 3]))))


def camera_extension(cam_obj, warnings, pixel_aspect=1.0):
    """TESELA_camera (docs/extensions.md) for a Blender camera object: its native data, the
    renderer applies Cycles' formulas to it."""
    cd = cam_obj.data
    ext = {"type": cd.type,
           "lens": finite(cd.lens), "sensor_width": finite(cd.sensor_width),
           "sensor_height": finite(cd.sensor_height), "sensor_fit": cd.sensor_fit,
           "ortho_scale": finite(cd.ortho_scale),
           "shift_x": finite(cd.shift_x), "shift_y": finite(cd.shift_y),
           "clip_start": finite(cd.clip_start), "clip_end": finite(cd.clip_end, 1e30)}
    if pixel_aspect != 1.0:
        ext["pixel_aspect"] = pixel_aspect
    if cd.type == "CUSTOM":
        warnings.append("camera '%s': custom (OSL) cameras are not supported; rendering it as "
                        "a perspective camera" % cam_obj.name)
    if cd.type == "PANO":
        pano = _panorama_setting(cd, "panorama_type")
        if pano is not None:
            ext["panorama_type"] = pano
        for name in PANORAMA_FIELDS:
            v = _panorama_setting(cd, name)
            if v is not None:
                ext[name] = finite(v)
    dof = getattr(cd, "dof", None)
    if dof is not None and dof.use_dof:
        ext["dof"] = {"focus_distance": focus_distance(cam_obj),
                      "aperture_fstop": finite(dof.aperture_fstop),
                      "aperture_blades": int(dof.aperture_blades),
                      "aperture_rotation": finite(dof.aperture_rotation),
                      "aperture_ratio": finite(dof.aperture_ratio, 1.0)}
    return ext


def pixel_aspect(render):
    """A pixel's width over its height (Render Properties > Format > Aspect X / Y)."""
    x, y = finite(render.pixel_aspect_x, 1.0), finite(render.pixel_aspect_y, 1.0)
    return x / y if x > 0.0 and y > 0.0 else 1.0
