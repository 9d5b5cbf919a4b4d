# SPDX-License-Identifier: MIT
"""Blender lights -> TESELA_light (native parameters, ray visibility) plus a KHR_lights_punctual
copy. The renderer applies Cycles' formulas; this module only reads Blender's settings."""

import math
import os

import bpy
import numpy as np

from .. import compat
from .common import TreeReport, color3, finite
from .material import GRAPH_VERSION, MaterialGraph


def _linked_node(sock):
    """The node feeding input `sock` through any reroutes, or None."""
    while sock is not None and sock.is_linked:
        node = sock.links[0].from_node
        if node.bl_idname != "NodeReroute":
            return node
        sock = node.inputs[0] if node.inputs else None
    return None


def _light_output(tree):
    """The Light Output Cycles uses: the active one, else the first."""
    outs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputLight"]
    return next((n for n in outs if n.is_active_output), outs[0] if outs else None)


class LightGraph(MaterialGraph):
    """A light's node tree -> a graph in TESELA_material_graph's format (`surface`: what reaches
    the active Light Output), for the renderer to evaluate what the add-on cannot reduce."""

    def build(self):
        graph = {"version": GRAPH_VERSION, "nodes": self.nodes, "surface": None}
        out = _light_output(self.material.node_tree)
        if out is not None:
            graph["surface"] = self._root(out, "Surface")
        return graph


def ies_profile(node, light_name, warn):
    """The `ies` member of TESELA_light for an IES Texture node: the LM-63 text of its Text
    datablock ('INTERNAL') or of its file ('EXTERNAL', relative to the .blend), or None (and
    a report) when there is none to read; the renderer parses it."""
    if node.mode == "INTERNAL":
        text = node.ies
        if text is None:
            warn("light '%s': IES node '%s' has no Text; the light renders without a profile"
                 % (light_name, node.name))
            return None
        return {"name": text.name, "data": text.as_string()}
    path = bpy.path.abspath(node.filepath)
    try:
        with open(path, "rb") as f:
            data = f.read().decode("utf-8", errors="replace")
    except OSError as e:
        warn("light '%s': IES file '%s' cannot be read (%s); the light renders without a "
             "profile" % (light_name, node.filepath, e.strerror or e))
        return None
    return {"name": os.path.basename(path), "data": data}


def node_emission(light, name, warn, profile=None, ies_warn=None):
    """The factor a light's node tree puts on its colour: Cycles multiplies the light's own
    strength by what its shader emits. Emission's unlinked Color x Strength, Light Falloff's
    Quadratic (the physical falloff) into Strength, and an IES Texture into Strength (its
    Strength input here, its profile appended to the list `profile`); anything else renders
    with those unlinked values and is reported through `warn` (the renderer may still
    evaluate the tree itself: see convert_light). What the IES node leaves out goes to
    `ies_warn` (default `warn`): the tree itself is rendered."""
    nt = light.node_tree if getattr(light, "use_nodes", False) else None
    if nt is None:
        return (1.0, 1.0, 1.0)
    out = _light_output(nt)
    if out is None:
        return (1.0, 1.0, 1.0)
    node = _linked_node(out.inputs["Surface"])
    if node is None:
        warn("light '%s': its node tree's Light Output has no shader; the light is black" % name)
        return (0.0, 0.0, 0.0)
    if node.bl_idname != "ShaderNodeEmission" or node.mute:
        warn("light '%s': node '%s' in its node tree is not rendered; the light emits its own "
             "colour" % (name, node.name))
        return (1.0, 1.0, 1.0)
    color, strength = node.inputs["Color"], node.inputs["Strength"]
    c = [finite(v) for v in color.default_value[:3]]
    if color.is_linked:
        warn("light '%s': a linked emission colour is not rendered; its unlinked value is used"
             % name)
    k = finite(strength.default_value)
    src = _linked_node(strength)
    if src is not None:
        link = strength.links[0]
        falloff = src.bl_idname == "ShaderNodeLightFalloff" and not src.mute
        ies = src.bl_idname == "ShaderNodeTexIES" and not src.mute
        if (falloff and link.from_socket.identifier == "Quadratic"
                and not src.inputs["Strength"].is_linked
                and not src.inputs["Smooth"].is_linked
                and src.inputs["Smooth"].default_value == 0.0):
            k = finite(src.inputs["Strength"].default_value)
        elif ies and profile is not None and light.type != "SUN":
            k = finite(src.inputs["Strength"].default_value)
            ies_warn = ies_warn or warn
            if src.inputs["Strength"].is_linked:
                ies_warn("light '%s': a linked IES Strength is not rendered; %g is used"
                         % (name, k))
            if src.inputs["Vector"].is_linked:
                ies_warn("light '%s': a linked IES Vector is not rendered; the light's own "
                         "direction is used" % name)
            p = ies_profile(src, name, ies_warn)
            if p is not None:
                profile.append(p)
        else:
            warn("light '%s': emission strength from node '%s' (%s) is not rendered; %g is used"
                 % (name, src.name, link.from_socket.name, k))
    return tuple(v * k for v in c)


def convert_light(light, obj, matrix=None, warnings=None, images=None):
    """TESELA_light and a KHR_lights_punctual copy of `light` placed by `obj`. With `images`
    (the export's ImageTable), a node tree the add-on cannot reduce to a colour also travels as
    a graph: the renderer evaluates it when it is constant over the light (a Blackbody into the
    Emission), and otherwise gives `node_warnings` and renders `color` (the unlinked values)."""
    t = light.type
    base, scale = compat.light_color_and_scale(light)
    notes = []
    profile, ies_notes = [], []
    factor = node_emission(light, obj.name, notes.append, profile, ies_notes.append)
    color = [c * f for c, f in zip(base[:3], factor)]
    ext = {"type": t, "color": color3(color)}
    if profile:
        ext["ies"] = profile[0]
    if notes and images is not None and light.node_tree is not None:
        graph_warnings = []
        ext["graph"] = LightGraph(light, images, TreeReport(graph_warnings, "light")).build()
        ext["base_color"] = color3(base[:3])
        ext["node_warnings"] = notes
        notes = graph_warnings
    if warnings is not None:
        warnings.extend(notes + ies_notes)
        bounces = getattr(getattr(light, "cycles", None), "max_bounces", 1024)
        if bounces != 1024:
            # Cycles stops the light's contribution after that many bounces; Tesela has no
            # per-light limit.
            warnings.append("light '%s': its Max Bounces (%d) is not rendered; the light "
                            "reaches every bounce" % (obj.name, bounces))
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
