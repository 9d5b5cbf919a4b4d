# SPDX-License-Identifier: MIT
"""Blender lights -> TESELA_light (native parameters, ray visibility) plus a KHR_lights_punctual
copy. The renderer applies Cycles' formulas; this module only reads Blender's settings."""

import math

import numpy as np

from .. import compat
from .common import color3, finite


def convert_light(light, obj, matrix=None, warnings=None):
    t = light.type
    color, scale = compat.light_color_and_scale(light)
    ext = {"type": t, "color": color3(color)}
    energy = finite(light.energy) * scale
    if t == "SUN":
        ext["strength"] = energy
        ext["angle"] = finite(getattr(light, "angle", 0.0))
    else:
        ext["power"] = energy
    if t in ("POINT", "SPOT"):
        ext["radius"] = finite(getattr(light, "shadow_soft_size", 0.0))
        ext["soft_falloff"] = compat.light_soft_falloff(light)
    if t == "SPOT":
        ext["spot_size"] = finite(light.spot_size)
        ext["spot_blend"] = finite(light.spot_blend)
        if getattr(light, "use_square", False) and warnings is not None:
            warnings.append("light '%s': square spots render as round ones" % obj.name)
    if t == "AREA":
        ext["shape"] = light.shape
        ext["size"] = finite(light.size)
        ext["size_y"] = finite(light.size_y) if light.shape in ("RECTANGLE", "ELLIPSE") else finite(light.size)
        ext["spread"] = finite(getattr(light, "spread", math.pi), math.pi)
    if not compat.light_normalized(light) and t != "SUN":
        # Cycles then keeps the radiance of a 1 m^2 (or 1 m radius disc) emitter:
        # the same picture as a normalized light of power * area.
        sx = sy = 1.0
        if matrix is not None:
            sx = float(np.linalg.norm(matrix[:3, 0]))
            sy = float(np.linalg.norm(matrix[:3, 1]))
        if t == "AREA":
            area = ext["size"] * sx * ext["size_y"] * sy
            if light.shape in ("DISK", "ELLIPSE"):
                area *= math.pi / 4.0
            ext["power"] *= area
        elif ext.get("radius", 0.0) > 0.0:
            ext["power"] *= math.pi * ext["radius"] ** 2
    vis = compat.ray_visibility(obj)
    ext["visible_camera"] = vis["camera"]
    ext["visible_diffuse"] = vis["diffuse"]
    ext["visible_glossy"] = vis["glossy"]
    ext["visible_transmission"] = vis["transmission"]
    ext["cast_shadow"] = bool(getattr(light, "use_shadow", True))
    ext["multiple_importance"] = compat.light_uses_mis(light)

    # A KHR_lights_punctual copy for other tools (Blender exporter's 'SPEC' units).
    khr = None
    color = ext["color"]
    if t in ("POINT", "SPOT"):
        khr = {"type": t.lower(), "color": color,
               "intensity": ext["power"] / (4.0 * math.pi) * 683.0}
        if t == "SPOT":
            outer = min(math.pi / 2, ext["spot_size"] / 2.0)
            inner = outer * (1.0 - min(1.0, max(0.0, ext["spot_blend"])))
            khr["spot"] = {"innerConeAngle": min(inner, outer * 0.999), "outerConeAngle": outer}
    elif t == "SUN":
        khr = {"type": "directional", "color": color, "intensity": ext["strength"] * 683.0}
    return ext, khr
