# SPDX-License-Identifier: MIT
"""The Blender world -> TESELA_world."""

from .. import compat
from .common import color3, finite


def convert_world(world, warnings):
    if world is None:
        return {"color": [0.0, 0.0, 0.0], "strength": 1.0}
    color, strength = list(world.color)[:3], 1.0
    tree = compat.node_tree(world)
    if tree is not None:
        out = None
        for n in tree.nodes:
            if n.bl_idname == "ShaderNodeOutputWorld" and getattr(n, "is_active_output", True):
                out = n
                break
        sock = out.inputs.get("Surface") if out is not None else None
        if sock is not None and sock.is_linked:
            node = sock.links[0].from_node
            if node.bl_idname == "ShaderNodeBackground":
                c = node.inputs.get("Color")
                s = node.inputs.get("Strength")
                if c.is_linked or s.is_linked:
                    warnings.append("world: linked Background inputs are not supported; using their values")
                color = list(c.default_value)[:3]
                strength = finite(s.default_value, 1.0)
            else:
                warnings.append("world: shader %s not supported; black background" % node.bl_idname)
                color, strength = [0.0, 0.0, 0.0], 1.0
        elif sock is not None:
            color, strength = [0.0, 0.0, 0.0], 1.0
    return {"color": color3(color), "strength": max(0.0, strength)}
