# SPDX-License-Identifier: MIT
"""The Blender world -> TESELA_world (docs/extensions.md).

The world's node tree travels as a graph in TESELA_material_graph's format (the material
translator, MaterialGraph, reused: groups inlined, reroutes and mutes resolved, images in
TESELA_images); `surface` is what reaches the World Output's Surface. `color`/`strength` stay as
the constant fallback (other tools, and the renderer when the graph cannot be used): the
Background's unlinked values when a Background feeds the output directly, else the world's
viewport colour. Camera visibility and Cycles' importance-sampling settings come along.
"""

from .. import compat
from .common import TreeReport, color3, finite
from .material import GRAPH_VERSION, MaterialGraph


def world_output(tree):
    """The World Output Cycles uses: the active one targeting All or Cycles."""
    getter = getattr(tree, "get_output_node", None)
    if getter is not None:
        try:
            node = getter("CYCLES")
        except (TypeError, RuntimeError):
            node = None
        if node is not None and node.bl_idname == "ShaderNodeOutputWorld":
            return node
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputWorld"]
    cand = [n for n in outputs if getattr(n, "target", "ALL") in ("ALL", "CYCLES")]
    for n in cand:
        if getattr(n, "is_active_output", False):
            return n
    return cand[0] if cand else None


class WorldGraph(MaterialGraph):
    """A world's node tree -> the graph of TESELA_world."""

    def build(self):
        tree = compat.node_tree(self.material)
        if tree is None:
            return None
        graph = {"version": GRAPH_VERSION, "nodes": self.nodes, "surface": None}
        out = world_output(tree)
        if out is None:
            self.report(self.name, None, "no World Output for Cycles; the world is black")
            return graph
        graph["surface"] = self._root(out, "Surface")
        graph["volume"] = self._root(out, "Volume")
        return graph


def _direct_background(tree):
    """The Background node feeding the World Output directly (through reroutes), or None."""
    out = world_output(tree)
    sock = out.inputs.get("Surface") if out is not None else None
    link = MaterialGraph._link_into(sock) if sock is not None else None
    if link is None:
        return None
    node = link.from_node
    while node.bl_idname == "NodeReroute":
        inner = MaterialGraph._link_into(node.inputs[0]) if node.inputs else None
        if inner is None:
            return None
        node = inner.from_node
    return node if node.bl_idname == "ShaderNodeBackground" and not node.mute else None


def convert_world(world, warnings, images=None):
    """The TESELA_world dict of `world` (None: black). With `images` (the export's ImageTable)
    the node tree is exported as a graph; without, only the constant colour."""
    if world is None:
        return {"color": [0.0, 0.0, 0.0], "strength": 1.0}
    out = {"name": world.name, "color": color3(world.color), "strength": 1.0}
    tree = compat.node_tree(world)
    if tree is not None:
        bg = _direct_background(tree)
        if bg is not None:
            c, s = bg.inputs.get("Color"), bg.inputs.get("Strength")
            if c is not None and MaterialGraph._link_into(c) is None and \
                    s is not None and MaterialGraph._link_into(s) is None:
                out["color"] = color3(c.default_value)
                out["strength"] = max(0.0, finite(s.default_value, 1.0))
        elif world_output(tree) is None or MaterialGraph._link_into(
                world_output(tree).inputs.get("Surface")) is None:
            out["color"], out["strength"] = [0.0, 0.0, 0.0], 1.0
    if tree is not None and images is not None:
        report = TreeReport(warnings, "world")
        saved = images.report  # missing-image messages name the world, not a material
        images.report = report
        try:
            out["graph"] = WorldGraph(world, images, report).build()
        finally:
            images.report = saved
    vis = getattr(world, "cycles_visibility", None)
    if vis is not None:
        for kind in ("camera", "diffuse", "glossy", "transmission"):
            out["visible_" + kind] = bool(getattr(vis, kind, True))
        if not getattr(vis, "scatter", True):
            warnings.append("world '%s': ray visibility (volume scatter off) is not supported; "
                            "the world is visible to volume scattering" % world.name)
    cw = getattr(world, "cycles", None)
    if cw is not None:
        method = getattr(cw, "sampling_method", "AUTOMATIC")
        out["sampling"] = method if method in ("AUTOMATIC", "MANUAL", "NONE") else "AUTOMATIC"
        out["map_resolution"] = int(getattr(cw, "sample_map_resolution", 1024))
    return out
