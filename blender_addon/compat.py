# SPDX-License-Identifier: MIT
"""Every Blender-version-specific detail of the add-on, in one place.

Supported: Blender 3.4 (Debian) through 5.x (PyPI bpy).
Known breaks handled here:
  * 4.0 renamed Principled BSDF sockets (Specular -> Specular IOR Level,
    Transmission -> Transmission Weight, Emission -> Emission Color, ...).
  * 4.1 removed Mesh.calc_normals_split()/MeshLoop.normal in favour of
    Mesh.corner_normals, and changed the shape RenderPass.rect.foreach_set
    accepts (it wants a flat sequence of pixels*channels in 4.1+; older
    versions also accept it flat, so one flat float32 array serves both).
  * 4.4 passes arguments to RenderEngine.__init__ (handled in engine.py by
    always accepting *args, **kwargs).
"""

import bpy
import numpy as np

VERSION = bpy.app.version


# --- Principled BSDF socket names -------------------------------------------

_PRINCIPLED_3 = {
    "base_color": ("Base Color",),
    "metallic": ("Metallic",),
    "roughness": ("Roughness",),
    "ior": ("IOR",),
    "alpha": ("Alpha",),
    "transmission": ("Transmission",),
    "specular": ("Specular",),
    "emission_color": ("Emission",),
    "emission_strength": ("Emission Strength",),
}
_PRINCIPLED_4 = {
    "base_color": ("Base Color",),
    "metallic": ("Metallic",),
    "roughness": ("Roughness",),
    "ior": ("IOR",),
    "alpha": ("Alpha",),
    "transmission": ("Transmission Weight", "Transmission"),
    "specular": ("Specular IOR Level", "Specular"),
    "emission_color": ("Emission Color", "Emission"),
    "emission_strength": ("Emission Strength",),
}
PRINCIPLED = _PRINCIPLED_4 if VERSION >= (4, 0, 0) else _PRINCIPLED_3


def principled_input(node, key):
    """The Principled BSDF input socket for a version-independent key."""
    for name in PRINCIPLED[key]:
        sock = node.inputs.get(name)
        if sock is not None:
            return sock
    return None


def specular_to_factor(node, value):
    """KHR_materials_specular factor for the node's specular input value.

    3.x 'Specular' 0.5 and 4.x 'Specular IOR Level' 0.5 both mean 'the IOR's
    own reflectance'; 0 means no specular layer.
    """
    return max(0.0, min(1.0, 2.0 * float(value)))


# --- node trees ----------------------------------------------------------------

def node_tree(idblock):
    """The material's/world's shader node tree if it renders with nodes, else None.
    (5.0 deprecated use_nodes: every material and world uses nodes there.)"""
    tree = getattr(idblock, "node_tree", None)
    if tree is None:
        return None
    if VERSION < (5, 0, 0) and not idblock.use_nodes:
        return None
    return tree


# --- mesh data ---------------------------------------------------------------

def corner_normals(mesh, n_loops):
    """Per-corner (split) normals, float32 (n_loops, 3)."""
    out = np.empty(n_loops * 3, dtype=np.float32)
    if hasattr(mesh, "corner_normals"):  # 4.1+
        mesh.corner_normals.foreach_get("vector", out)
    else:  # 3.x - 4.0
        if hasattr(mesh, "calc_normals_split"):
            mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", out)
    return out.reshape(-1, 3)


def vertex_positions(mesh, n_verts):
    out = np.empty(n_verts * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def corner_uvs(mesh, n_loops):
    """Active render UV map per corner, float32 (n_loops, 2), or None."""
    layers = mesh.uv_layers
    if not len(layers):
        return None
    layer = None
    for uv in layers:
        if getattr(uv, "active_render", False):
            layer = uv
            break
    if layer is None:
        layer = layers.active or layers[0]
    out = np.empty(n_loops * 2, dtype=np.float32)
    if hasattr(layer, "uv") and len(layer.uv) == n_loops:  # 3.5+
        layer.uv.foreach_get("vector", out)
    else:
        layer.data.foreach_get("uv", out)
    return out.reshape(-1, 2)


# --- render result -----------------------------------------------------------

def pass_rect_set(render_pass, flat_rgba):
    """Write a contiguous float32 (w*h*4,) array (rows bottom to top) into a pass."""
    try:
        render_pass.rect.foreach_set(flat_rgba)
    except (TypeError, ValueError, RuntimeError):
        # Some versions insist on (pixels, channels).
        render_pass.rect.foreach_set(flat_rgba.reshape(-1, render_pass.channels))


def combined_pass(result):
    layer = result.layers[0]
    p = layer.passes.find_by_name("Combined", "") if hasattr(layer.passes, "find_by_name") else None
    if p is None:
        p = layer.passes["Combined"]
    return p


# --- lights --------------------------------------------------------------------

def light_color_and_scale(light):
    """(linear colour, power multiplier) with the settings later Blenders added:
    blackbody temperature (4.x), exposure (power * 2^exposure, 4.x)."""
    color = list(light.color)[:3]
    if getattr(light, "use_temperature", False):
        tc = getattr(light, "temperature_color", None)
        if tc is not None:
            color = [c * t for c, t in zip(color, tc)]
    return color, 2.0 ** float(getattr(light, "exposure", 0.0))


def light_normalized(light):
    """4.x 'Normalize': when off, Cycles does not divide the power by the emitting area."""
    return bool(getattr(light, "normalize", True))


# --- object visibility ---------------------------------------------------------

def visible_camera(obj):
    v = getattr(obj, "visible_camera", None)
    if v is not None:
        return bool(v)
    cv = getattr(obj, "cycles_visibility", None)  # pre-3.0
    return bool(getattr(cv, "camera", True)) if cv is not None else True


def is_extension_platform():
    return VERSION >= (4, 2, 0)
