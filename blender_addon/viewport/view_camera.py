# SPDX-License-Identifier: MIT
"""The 3D viewport's view as a Tesela camera (a node matrix plus TESELA_camera), as Cycles' Blender
sync builds its viewport camera (`blender_camera_from_view`, `blender_camera_viewplane`).

Cycles describes a view by a camera (lens, sensor, fit, shift), a `zoom` that scales the image
window and an `offset` that moves it. Tesela's TESELA_camera has no zoom or offset, so they are
folded into an equivalent camera: a window `zoom` times larger is a lens `zoom` times shorter
(an orthographic scale `zoom` times larger), and the offset becomes shift. In Cycles' units,
    window = zoom * [-xaspect, xaspect] x [-yaspect, yaspect] + 2 (aspect * shift + 2 offset * (xaspect, yaspect))
with (xaspect, yaspect) = (aspect, 1) for a horizontal fit and (1, aspect) for a vertical one
(aspect >= the fitted dimension's share), so the equivalent camera has
    lens' = lens / zoom,   ortho_scale' = ortho_scale * zoom,
    shift' = (shift + 2 offset * (xaspect, yaspect) / aspect) / zoom,
and, to keep the lens radius lens / (2 fstop), fstop' = fstop / zoom.
"""

import math

import numpy as np

from ..export.camera import camera_extension, camera_matrix
from ..export.common import gltf_matrix, matrix

# Blender's viewport camera outside camera view (DEFAULT_SENSOR_WIDTH/HEIGHT, the zoom of a free
# view: CAMERA_PARAM_ZOOM_INIT_PERSP).
VIEW_SENSOR_WIDTH = 36.0
VIEW_SENSOR_HEIGHT = 24.0
VIEW_ZOOM = 2.0


def camera_view_zoom(view_camera_zoom):
    """The window scale of camera view at Blender's `view_camera_zoom` (Cycles' "magic zoom
    formula" times the free view's 2): 4 / (sqrt(2) + zoom / 50)^2; 1 when the camera's frame
    fills the view."""
    return 4.0 / (math.sqrt(2.0) + view_camera_zoom / 50.0) ** 2


def horizontal_fit(sensor_fit, width, height):
    """Cycles' fit: AUTO fits the width when the view is wider than tall."""
    if sensor_fit == "AUTO":
        return width > height
    return sensor_fit == "HORIZONTAL"


def fold_zoom(ext, width, height, zoom, offset):
    """The TESELA_camera `ext` with Cycles' window `zoom` and `offset` folded into lens, ortho
    scale, shift and f-stop (module doc). Returns a new dict."""
    ext = dict(ext)
    hfit = horizontal_fit(ext.get("sensor_fit", "AUTO"), width, height)
    aspect = width / float(height) if hfit else height / float(width)
    xaspect, yaspect = (aspect, 1.0) if hfit else (1.0, aspect)
    ext["shift_x"] = (ext.get("shift_x", 0.0) + 2.0 * offset[0] * xaspect / aspect) / zoom
    ext["shift_y"] = (ext.get("shift_y", 0.0) + 2.0 * offset[1] * yaspect / aspect) / zoom
    if ext.get("type") == "ORTHO":
        ext["ortho_scale"] = ext.get("ortho_scale", 6.0) * zoom
    elif ext.get("type") == "PERSP":
        ext["lens"] = ext.get("lens", 50.0) / zoom
        if "dof" in ext:
            ext["dof"] = dict(ext["dof"], aperture_fstop=ext["dof"]["aperture_fstop"] / zoom)
    return ext


def window(ext, width, height):
    """The image window of camera `ext` on a width x height image as TESELA_camera defines it:
    (left, right, bottom, top) on the plane at distance 1 (perspective) or in metres
    (orthographic), camera space (x right, y up)."""
    hfit = horizontal_fit(ext.get("sensor_fit", "AUTO"), width, height)
    if ext.get("type") == "ORTHO":
        fitted = ext.get("ortho_scale", 6.0)
    else:
        sensor = ext.get("sensor_height", 24.0) if ext.get("sensor_fit") == "VERTICAL" \
            else ext.get("sensor_width", 36.0)
        fitted = sensor / ext.get("lens", 50.0)
    if hfit:
        w, h = fitted, fitted * height / float(width)
    else:
        w, h = fitted * width / float(height), fitted
    cx, cy = ext.get("shift_x", 0.0) * fitted, ext.get("shift_y", 0.0) * fitted
    return (cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2)


class ViewCamera:
    """The camera of one viewport view: `matrix` (Blender world from camera, numpy 4x4, no
    scale), `ext` (TESELA_camera), `camera_object` (the scene camera in camera view, else None)."""

    def __init__(self, matrix_world, ext, camera_object=None):
        self.matrix = matrix_world
        self.ext = ext
        self.camera_object = camera_object

    def command_camera(self):
        """The `camera` field of the session's `view` command."""
        return {"matrix": gltf_matrix(self.matrix), "camera": self.ext}


def view_camera(scene, space, rv3d, width, height, warnings=None):
    """The ViewCamera of a viewport: `space` a SpaceView3D, `rv3d` its RegionView3D, the region
    width x height pixels. Objects must be evaluated ones (they are read, never changed)."""
    warnings = warnings if warnings is not None else []
    persp = rv3d.view_perspective
    if persp == "CAMERA":
        cam = space.camera if getattr(space, "use_local_camera", False) else scene.camera
        if cam is not None and cam.type == "CAMERA":
            ext = camera_extension(cam, warnings)
            if ext["type"] == "PANO":
                # Cycles maps a panorama's image onto the camera frame; Tesela draws the whole
                # panorama over the view.
                return ViewCamera(camera_matrix(cam), ext, cam)
            zoom = camera_view_zoom(rv3d.view_camera_zoom)
            offset = tuple(rv3d.view_camera_offset)
            return ViewCamera(camera_matrix(cam), fold_zoom(ext, width, height, zoom, offset), cam)
        persp = "PERSP"  # no camera: Blender draws the free view
    view_from_world = matrix(rv3d.view_matrix)
    world_from_view = np.linalg.inv(view_from_world)
    for i in range(3):
        n = np.linalg.norm(world_from_view[:3, i])
        if n > 0:
            world_from_view[:3, i] /= n
    clip_start, clip_end = float(space.clip_start), float(space.clip_end)
    ext = {"type": "PERSP", "lens": float(space.lens), "sensor_width": VIEW_SENSOR_WIDTH,
           "sensor_height": VIEW_SENSOR_HEIGHT, "sensor_fit": "AUTO", "ortho_scale": 6.0,
           "shift_x": 0.0, "shift_y": 0.0, "clip_start": clip_start, "clip_end": clip_end}
    if persp == "ORTHO":
        # Cycles clips an orthographic view at -far/2 .. far/2 around the view point; a camera
        # far/2 behind it with clip 0 .. far sees the same slab.
        half = clip_end * 0.5
        world_from_view[:3, 3] += world_from_view[:3, 2] * half
        ext.update(type="ORTHO", clip_start=0.0, clip_end=clip_end,
                   ortho_scale=float(rv3d.view_distance) * VIEW_SENSOR_WIDTH / float(space.lens))
    return ViewCamera(world_from_view, fold_zoom(ext, width, height, VIEW_ZOOM, (0.0, 0.0)))


def _pixel_rect(frame, width, height):
    """(x, y, w, h), top-left origin, of the fractions (x0, x1, y0, y1) (bottom-left origin) of
    a width x height view, clipped to it; None when empty."""
    x0, x1, y0, y1 = frame
    xmin = max(0, int(math.floor(x0 * width + 1e-6)))
    xmax = min(width, int(math.floor(x1 * width + 1e-6)))
    ymin = max(0, int(math.floor(y0 * height + 1e-6)))
    ymax = min(height, int(math.floor(y1 * height + 1e-6)))
    if xmax <= xmin or ymax <= ymin:
        return None
    return (xmin, height - ymax, xmax - xmin, ymax - ymin)


def camera_frame(scene, cam, view_ext, width, height):
    """Where the camera's render frame lies in camera view: fractions (x0, x1, y0, y1) of the
    view, bottom-left origin (Cycles' `blender_camera_view_subset`)."""
    from ..export.gltf import render_size
    rw, rh = render_size(scene.render)
    cam_ext = camera_extension(cam, [])
    l0, r0, b0, t0 = window(view_ext, width, height)
    l1, r1, b1, t1 = window(cam_ext, rw, rh)
    return ((l1 - l0) / (r0 - l0), (r1 - l0) / (r0 - l0),
            (b1 - b0) / (t0 - b0), (t1 - b0) / (t0 - b0))


def view_border(scene, space, view, width, height):
    """The viewport's render border as the `view` command's [x, y, w, h] (top-left origin), or
    None: in camera view the scene's render border inside the camera frame, else the
    viewport's own border (View > Render Region)."""
    if view.camera_object is not None:
        r = scene.render
        if not r.use_border or view.ext.get("type") == "PANO":
            return None
        fx0, fx1, fy0, fy1 = camera_frame(scene, view.camera_object, view.ext, width, height)
        bx0, bx1 = sorted((r.border_min_x, r.border_max_x))
        by0, by1 = sorted((r.border_min_y, r.border_max_y))
        frac = (fx0 + bx0 * (fx1 - fx0), fx0 + bx1 * (fx1 - fx0),
                fy0 + by0 * (fy1 - fy0), fy0 + by1 * (fy1 - fy0))
    else:
        if not getattr(space, "use_render_border", False):
            return None
        bx0, bx1 = sorted((space.render_border_min_x, space.render_border_max_x))
        by0, by1 = sorted((space.render_border_min_y, space.render_border_max_y))
        frac = (bx0, bx1, by0, by1)
    rect = _pixel_rect(frac, width, height)
    if rect is None:
        return [0, 0, 0, 0]
    if rect == (0, 0, width, height):
        return None
    return list(rect)
