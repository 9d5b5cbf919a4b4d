# SPDX-License-Identifier: MIT
"""Blender materials -> glTF materials.

Two parts: the glTF metallic-roughness fallback other tools read (convert_material: factors and a
base-colour texture), and TESELA_material_graph, the shader node tree flattened into the format of
docs/extensions.md (MaterialGraph: groups inlined, reroutes and muted nodes resolved, Blender's
5.x vocabulary through compat.translate_node). Tesela renders the graph.
"""

import math

import bpy

from .. import compat
from . import attributes
from .common import color3, finite

GRAPH_VERSION = 1
RAMP_TABLE_SIZE = 256      # Cycles' RAMP_TABLE_SIZE: tables hold RAMP_TABLE_SIZE + 1 samples


def default_surface():
    """The glTF material for surfaces without a material: Cycles' default shader node, with
    its metallic-roughness equivalent as the fallback."""
    node = compat.default_surface_shader()
    principled = node == "ShaderNodeBsdfPrincipled"
    graph = {"version": GRAPH_VERSION, "surface": [0, "BSDF"],
             "nodes": [{"name": "Default Surface", "type": node, "props": {}, "inputs": {},
                        "internal_links": {}}]}
    return {"name": "__tesela_default", "doubleSided": True,
            "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                                     "metallicFactor": 0.0,
                                     "roughnessFactor": 0.5 if principled else 1.0},
            "extensions": {"TESELA_material_graph": graph}}


# --- the glTF metallic-roughness fallback ------------------------------------------------

def _input_value(sock, default):
    if sock is None:
        return default
    return sock.default_value


def _surface_node(material):
    tree = compat.node_tree(material)
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"]
    if not outputs:
        return None
    chosen = None
    for n in outputs:
        if getattr(n, "is_active_output", False) and n.target in ("ALL", "CYCLES"):
            chosen = n
            break
    if chosen is None:
        cand = [n for n in outputs if n.target in ("ALL", "CYCLES")] or outputs
        chosen = cand[0]
    sock = chosen.inputs.get("Surface")
    if sock is None or not sock.is_linked:
        return None
    node = sock.links[0].from_node
    # Follow reroutes.
    while node.bl_idname == "NodeReroute" and node.inputs[0].is_linked:
        node = node.inputs[0].links[0].from_node
    return node


def convert_material(material, warnings, textures=None):
    """A Blender material -> glTF material dict (plus extensions used)."""
    name = material.name
    base = list(material.diffuse_color)[:3]
    alpha = 1.0
    metallic = finite(getattr(material, "metallic", 0.0))
    roughness = finite(getattr(material, "roughness", 0.5), 0.5)
    ior = 1.5
    transmission = 0.0
    specular = None
    emission = [0.0, 0.0, 0.0]
    strength = 0.0
    base_tex = None

    node = _surface_node(material)
    if node is not None:
        kind = node.bl_idname
        color_sock = None
        if kind == "ShaderNodeBsdfPrincipled":
            color_sock = compat.principled_input(node, "base_color")
        elif kind in ("ShaderNodeBsdfDiffuse", "ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic",
                      "ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"):
            color_sock = node.inputs.get("Color")
        if textures is not None and color_sock is not None:
            base_tex = textures.image_texture(color_sock, name, warnings)
        for sock in node.inputs:
            if sock == color_sock and base_tex is not None:
                continue
            if sock.is_linked and sock.name not in ("Normal", "Tangent", "Clearcoat Normal",
                                                    "Coat Normal", "Weight"):
                warnings.append("material '%s': input '%s' of %s is linked; its unlinked value is used"
                                % (name, sock.name, node.name))
        if kind == "ShaderNodeBsdfPrincipled":
            P = compat.principled_input
            base = list(_input_value(P(node, "base_color"), (0.8, 0.8, 0.8, 1)))[:3]
            metallic = finite(_input_value(P(node, "metallic"), 0.0))
            roughness = finite(_input_value(P(node, "roughness"), 0.5), 0.5)
            ior = finite(_input_value(P(node, "ior"), 1.5), 1.5)
            alpha = finite(_input_value(P(node, "alpha"), 1.0), 1.0)
            transmission = finite(_input_value(P(node, "transmission"), 0.0))
            spec_sock = P(node, "specular")
            if spec_sock is not None:
                specular = compat.specular_to_factor(node, spec_sock.default_value)
            emission = list(_input_value(P(node, "emission_color"), (0, 0, 0, 1)))[:3]
            strength = finite(_input_value(P(node, "emission_strength"), 1.0), 1.0)
        elif kind == "ShaderNodeEmission":
            base = [0.0, 0.0, 0.0]
            metallic, roughness = 0.0, 1.0
            emission = list(_input_value(node.inputs.get("Color"), (1, 1, 1, 1)))[:3]
            strength = finite(_input_value(node.inputs.get("Strength"), 1.0), 1.0)
            specular = 0.0
        elif kind == "ShaderNodeBsdfDiffuse":
            base = list(_input_value(node.inputs.get("Color"), (0.8, 0.8, 0.8, 1)))[:3]
            metallic, roughness, specular = 0.0, 1.0, 0.0
        elif kind in ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic"):
            base = list(_input_value(node.inputs.get("Color"), (0.8, 0.8, 0.8, 1)))[:3]
            metallic = 1.0
            roughness = finite(_input_value(node.inputs.get("Roughness"), 0.5), 0.5)
        elif kind in ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"):
            base = list(_input_value(node.inputs.get("Color"), (1, 1, 1, 1)))[:3]
            metallic = 0.0
            roughness = finite(_input_value(node.inputs.get("Roughness"), 0.0))
            ior = finite(_input_value(node.inputs.get("IOR"), 1.45), 1.45)
            transmission = 1.0
        else:
            warnings.append("material '%s': shader node %s is not supported; using its viewport colour"
                            % (name, kind))

    base = [min(1.0, max(0.0, finite(c))) for c in base]
    pbr = {"baseColorFactor": base + [min(1.0, max(0.0, alpha))],
           "metallicFactor": min(1.0, max(0.0, metallic)),
           "roughnessFactor": min(1.0, max(0.0, roughness))}
    if base_tex is not None:
        pbr["baseColorFactor"] = [1.0, 1.0, 1.0, pbr["baseColorFactor"][3]]
        pbr["baseColorTexture"] = {"index": base_tex}
    out = {"name": name, "pbrMetallicRoughness": pbr,
           "doubleSided": not getattr(material, "use_backface_culling", False)}
    ext = {}
    emission = color3(emission)
    peak = max(emission)
    if peak > 0.0 and strength > 0.0:
        out["emissiveFactor"] = [c / peak for c in emission]
        total = peak * strength
        if abs(total - 1.0) > 1e-7:
            ext["KHR_materials_emissive_strength"] = {"emissiveStrength": total}
        ext["TESELA_emission"] = {"two_sided": True}
    if transmission > 0.0:
        ext["KHR_materials_transmission"] = {"transmissionFactor": min(1.0, transmission)}
    if abs(ior - 1.5) > 1e-6:
        ext["KHR_materials_ior"] = {"ior": max(1.0, ior) if ior >= 1.0 else 1.0}
    if specular is not None and abs(specular - 1.0) > 1e-6:
        ext["KHR_materials_specular"] = {"specularFactor": specular}
    if alpha < 1.0:
        out["alphaMode"] = "BLEND"
    if ext:
        out["extensions"] = ext
    return out


# --- TESELA_material_graph ---------------------------------------------------------------

_GROUP_TYPES = ("ShaderNodeGroup", "NodeGroup", "ShaderNodeCustomGroup")
_SIMPLE_PROP_TYPES = ("ENUM", "BOOLEAN", "INT", "FLOAT", "STRING")
_SKIP_PROPS = {"bytecode", "bytecode_hash"}  # a Script node's compiled OSL: large, of no use
MENU_SWITCH = "GeometryNodeMenuSwitch"  # shader trees use it too (Blender 4.5+)
_MAX_DEPTH = 400           # link hops from the output; Blender forbids cycles, this guards anyway
# Nodes Cycles does not compile (EEVEE only): it leaves them out with their links, so that the
# inputs they feed keep their own values.
_NOT_IN_CYCLES = {"ShaderNodeShaderToRGB"}
_base_props = None


def _base_prop_ids():
    global _base_props
    if _base_props is None:
        _base_props = {p.identifier for p in bpy.types.ShaderNode.bl_rna.properties}
        _base_props.add("rna_type")
    return _base_props


def _zero(sock_type):
    """The value Blender gives an output with nothing behind it (a muted node without an
    internal link, an empty group output): the socket type's zero; None for closures."""
    if sock_type in ("VALUE", "INT"):
        return 0.0
    if sock_type == "BOOLEAN":
        return False
    if sock_type == "VECTOR":
        return [0.0, 0.0, 0.0]
    if sock_type == "RGBA":
        return [0.0, 0.0, 0.0, 1.0]
    if sock_type == "STRING":
        return ""
    return None


def _is_group(node):
    kind = node.bl_idname
    return kind in _GROUP_TYPES or (getattr(node, "node_tree", None) is not None
                                    and kind.endswith("Group"))


def _group_output_socket(group, out):
    """The socket inside `group`'s tree that its output `out` passes on: on the active Group
    Output (else the first), None without one."""
    tree = getattr(group, "node_tree", None)
    if tree is None:
        return None
    gouts = [n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"]
    gout = next((n for n in gouts if getattr(n, "is_active_output", False)), None)
    gout = gout or (gouts[0] if gouts else None)
    if gout is None:
        return None
    return next((s for s in gout.inputs if s.identifier == out.identifier), None)


def _rows(m):
    return [[float(v) for v in row] for row in m]


class MaterialReport:
    """What the add-on could not translate, once per material and node: appended to the export's
    warnings and kept per material (for the Tesela panel in the Material Properties)."""

    def __init__(self, warnings, per_material):
        self.warnings = warnings
        self.per_material = per_material
        self._seen = set()

    def __call__(self, material_name, node, message, kind=None):
        """Report `message` unless this material and node already reported `kind` (default:
        the message itself)."""
        if node is None or isinstance(node, str):
            node_name, tree = node, None
        else:  # nodes of one name may live in several trees (the material's, groups')
            node_name = node.name
            tree = getattr(getattr(node, "id_data", None), "name", None)
        key = (material_name, tree, node_name, kind or message)
        if key in self._seen:
            return
        self._seen.add(key)
        if node_name is None:
            text = "material '%s': %s" % (material_name, message)
        else:
            idname = getattr(node, "bl_idname", None)
            text = "material '%s': node '%s'%s: %s" % (
                material_name, node_name, " (%s)" % idname if idname else "", message)
        self.warnings.append(text)
        self.per_material.setdefault(material_name, []).append(text)


class MaterialGraph:
    """One material's node tree -> the TESELA_material_graph dict."""

    def __init__(self, material, images, report, view_layer=None):
        self.material = material
        self.view_layer = view_layer
        self.name = material.name
        self.images = images
        self.report = report
        self.nodes = []
        self._memo = {}
        self._busy = set()
        self.tangent_uvs = set()      # UV maps tangent-space normal maps read ("" = the default)

    # -- public -------------------------------------------------------------------------------

    def build(self):
        tree = compat.node_tree(self.material)
        if tree is None:
            # Cycles renders a material without nodes as a Diffuse BSDF of its viewport colour.
            self.nodes.append({"name": "Diffuse BSDF", "type": "ShaderNodeBsdfDiffuse", "props": {},
                               "inputs": {"Color": self._floats(self.material.diffuse_color, None, "Color")},
                               "internal_links": {}})
            return {"version": GRAPH_VERSION, "nodes": self.nodes, "surface": [0, "BSDF"]}
        out = compat.material_output(tree)
        graph = {"version": GRAPH_VERSION, "nodes": self.nodes, "surface": None}
        if out is None:
            self.report(self.name, None, "no Material Output for Cycles; the surface is empty")
            return graph
        graph["surface"] = self._root(out, "Surface")
        disp = self._root(out, "Displacement")
        if disp is not None:
            graph["displacement"] = disp
            graph["displacement_method"] = compat.displacement_method(self.material)
        volume = self._root(out, "Volume")
        if volume is not None:
            graph["volume"] = volume
        self._mark_alpha_links(graph)
        return graph

    def _mark_alpha_links(self, graph):
        """props.alpha_linked of every Image Texture: whether its Alpha output is used (Cycles
        then un-premultiplies the Color output; the graph holds only nodes the output reaches)."""
        used = {tuple(graph[k]) for k in ("surface", "displacement", "volume") if graph.get(k)}
        for entry in self.nodes:
            for v in entry["inputs"].values():
                if isinstance(v, dict) and "link" in v:
                    used.add(tuple(v["link"]))
        for i, entry in enumerate(self.nodes):
            if entry["type"] == "ShaderNodeTexImage":
                entry["props"]["alpha_linked"] = (i, "Alpha") in used

    # -- resolution ----------------------------------------------------------------------------

    def _root(self, out, identifier):
        sock = next((s for s in out.inputs if s.identifier == identifier), None)
        if sock is None or not compat.socket_available(sock):
            return None
        v = self._input((), sock, 0)
        return v["link"] if isinstance(v, dict) else None

    @classmethod
    def _link_into(cls, sock, _depth=0):
        """The link Blender evaluates into an input socket: muted, invalid and unavailable links
        count as absent, and so do links from dangling reroutes (a reroute chain with nothing at
        its start: the input keeps its own value, as Blender's is_dangling_reroute rule says)."""
        if not sock.is_linked:
            return None
        for link in sock.links:
            if getattr(link, "is_muted", False) or not getattr(link, "is_valid", True):
                continue
            if not compat.socket_available(link.from_socket):
                continue
            node = link.from_node
            if node.bl_idname == "NodeReroute":
                if (_depth > _MAX_DEPTH or not node.inputs
                        or cls._link_into(node.inputs[0], _depth + 1) is None):
                    continue
            return link
        return None

    def _input(self, ctx, sock, depth):
        """An input socket in group context `ctx` -> {"link": [i, out]}, a value, or None."""
        link = self._link_into(sock)
        if link is None:
            return self._value(sock, ctx)
        if link.from_node.bl_idname in _NOT_IN_CYCLES:
            self.report(self.name, link.from_node,
                        "EEVEE only: Cycles leaves it out, and the inputs it feeds keep their "
                        "own values, as rendered here")
            return self._value(sock, ctx)
        if depth > _MAX_DEPTH:
            self.report(self.name, sock.node, "the node graph is too deep; input '%s' is cut"
                        % sock.identifier)
            return None
        return self._output(ctx, link.from_node, link.from_socket, depth + 1)

    def _output(self, ctx, node, sock, depth):
        """What an output socket carries: a link to an exported node or a constant."""
        kind = node.bl_idname
        if kind == "NodeReroute":
            if not node.inputs:
                return _zero(sock.type)
            inner = node.inputs[0]
            if self._link_into(inner) is None:
                return _zero(sock.type)
            return self._input(ctx, inner, depth)
        if node.mute:
            for il in node.internal_links:
                if il.to_socket.identifier == sock.identifier and compat.socket_available(il.from_socket):
                    return self._input(ctx, il.from_socket, depth)
            return _zero(sock.type)
        if kind == MENU_SWITCH:
            return self._menu_switch(ctx, node, sock, depth)
        if kind == "NodeGroupInput":
            if not ctx:
                return _zero(sock.type)
            group = ctx[-1]
            outer = next((s for s in group.inputs if s.identifier == sock.identifier), None)
            if outer is None:
                return _zero(sock.type)
            return self._input(ctx[:-1], outer, depth)
        if _is_group(node):
            if getattr(node, "node_tree", None) is None:
                self.report(self.name, node, "node group without a node tree; its outputs are zero")
                return _zero(sock.type)
            inner = _group_output_socket(node, sock)
            if inner is None:
                return _zero(sock.type)
            return self._input(ctx + (node,), inner, depth)
        idx, moved = self._export(ctx, node, depth)
        if idx is None:
            return None
        target = moved.get(sock.identifier, [idx, sock.identifier])
        return {"link": [target[0], target[1]]}

    def _menu_switch(self, ctx, node, sock, depth):
        """A Menu Switch passes on the input of the item its menu selects (Blender resolves the
        menu when it compiles the tree: it is a constant, from the node or a group's input);
        its per-item outputs are true for the selected item."""
        chosen = self._menu_choice(ctx, node, depth)
        if sock.identifier != "Output":
            return chosen is not None and sock.name == chosen.name
        if chosen is None:
            return _zero(sock.type)
        return self._input(ctx, chosen, depth)

    def _menu_choice(self, ctx, node, depth):
        """The item input a Menu Switch selects in group context `ctx`, or None (reported)."""
        menu = next((s for s in node.inputs if s.type == "MENU"), None)
        name = self._menu_value(ctx, menu, depth) if menu is not None else None
        for s in node.inputs:
            if s.type not in ("MENU", "CUSTOM") and s.name == name and compat.socket_available(s):
                return s
        self.report(self.name, node, "the menu's item could not be found; its output is zero")
        return None

    def _menu_value(self, ctx, sock, depth):
        """The item name a menu socket carries: its own value, or what a reroute, a group's
        input or output, or another Menu Switch passes into it."""
        link = self._link_into(sock)
        if link is None:
            return getattr(sock, "default_value", None)
        if depth > _MAX_DEPTH:
            return None
        node, out = link.from_node, link.from_socket
        kind = node.bl_idname
        if kind == "NodeReroute":
            return self._menu_value(ctx, node.inputs[0], depth + 1)
        if kind == "NodeGroupInput":
            outer = next((s for s in ctx[-1].inputs if s.identifier == out.identifier),
                         None) if ctx else None
            return self._menu_value(ctx[:-1], outer, depth + 1) if outer is not None else None
        if kind == MENU_SWITCH and out.identifier == "Output":
            chosen = self._menu_choice(ctx, node, depth + 1)
            return self._menu_value(ctx, chosen, depth + 1) if chosen is not None else None
        inner = _group_output_socket(node, out) if _is_group(node) else None
        if inner is not None:
            return self._menu_value(ctx + (node,), inner, depth + 1)
        return None

    # -- node export ----------------------------------------------------------------------------

    def _emit(self, entry):
        self.nodes.append(entry)
        return len(self.nodes) - 1

    def _export(self, ctx, node, depth):
        key = (tuple(g.as_pointer() for g in ctx), node.as_pointer())
        if key in self._memo:
            return self._memo[key]
        if key in self._busy:  # a cycle: Blender marks such links invalid, so this is paranoia
            self.report(self.name, node, "the node graph has a cycle; it is cut here")
            return None, {}
        self._busy.add(key)
        try:
            entry = {"name": node.name, "type": node.bl_idname}
            if ctx:
                entry["group"] = "/".join(g.name for g in ctx)
            entry["props"] = self._props(node, ctx)
            inputs = {}
            for sock in node.inputs:
                if not compat.socket_available(sock):
                    continue
                v = self._input(ctx, sock, depth)
                if v is not None:
                    inputs[sock.identifier] = v
            entry["inputs"] = inputs
            entry["internal_links"] = {
                il.to_socket.identifier: il.from_socket.identifier for il in node.internal_links
                if compat.socket_available(il.from_socket) and compat.socket_available(il.to_socket)}
            idx = self._emit(entry)
            moved = compat.translate_node(node, entry, idx, self._emit) or {}
            self._note(entry)
            self._memo[key] = (idx, moved)
            return idx, moved
        finally:
            self._busy.discard(key)

    def _note(self, entry):
        """Facts about the graph the mesh export needs (tangents for normal maps)."""
        t, props = entry["type"], entry["props"]
        if t == "ShaderNodeNormalMap" and props.get("space", "TANGENT") == "TANGENT":
            self.tangent_uvs.add(props.get("uv_map", ""))
        elif t == "ShaderNodeTangent" and props.get("direction_type") == "UV_MAP":
            self.tangent_uvs.add(props.get("uv_map", ""))

    # -- values -----------------------------------------------------------------------------

    def _floats(self, value, node, what):
        out = []
        bad = False
        for v in value:
            if isinstance(v, (list, tuple)) or hasattr(v, "__len__"):
                row = self._floats(v, node, what)
                out.append(row)
                continue
            f = float(v)
            if not math.isfinite(f):
                f, bad = 0.0, True
            out.append(f)
        if bad:
            self.report(self.name, node, "%s is not finite (NaN or infinite); 0 is used" % what,
                        "non-finite")
        return out

    def _scalar(self, v, node, what):
        if isinstance(v, bool):
            return v
        if isinstance(v, int):
            return v
        f = float(v)
        if not math.isfinite(f):
            self.report(self.name, node, "%s is not finite (NaN or infinite); 0 is used" % what,
                        "non-finite")
            return 0.0
        return f

    def _value(self, sock, ctx):
        """The unlinked value of an input socket (None for closures and value-less sockets)."""
        if sock.type == "SHADER" or not hasattr(sock, "default_value"):
            return None
        if getattr(sock, "hide_value", False):
            # No editable value (a texture's Vector, a BSDF's Normal): Blender's implicit default
            # (UV/Generated coordinates, the shading normal, ...), which absence means.
            return None
        v = sock.default_value
        what = "input '%s'" % sock.identifier
        if isinstance(v, str):
            return None  # string sockets (OSL Script nodes) have no meaning for the renderer
        if isinstance(v, (bool, int, float)):
            return self._scalar(v, sock.node, what)
        try:
            return self._floats(v, sock.node, what)
        except TypeError:
            return None

    # -- properties -------------------------------------------------------------------------

    def _props(self, node, ctx):
        props = {}
        base = _base_prop_ids()
        for p in node.bl_rna.properties:
            ident = p.identifier
            if ident in base or ident in _SKIP_PROPS or p.type not in _SIMPLE_PROP_TYPES:
                continue
            try:
                v = getattr(node, ident)
            except (AttributeError, RuntimeError):
                continue
            if p.type == "ENUM":
                props[ident] = sorted(v) if getattr(p, "is_enum_flag", False) else v
            elif p.type == "STRING":
                props[ident] = str(v)
            elif getattr(p, "is_array", False) or getattr(p, "array_length", 0):
                props[ident] = self._floats(v, node, "property '%s'" % ident) \
                    if p.type == "FLOAT" else [x for x in v]
            else:
                props[ident] = self._scalar(v, node, "property '%s'" % ident)
        kind = node.bl_idname
        special = _SPECIAL_PROPS.get(kind)
        if special is not None:
            special(self, node, props)
        mapping = getattr(node, "texture_mapping", None)
        if mapping is not None:
            tm = _texture_mapping(mapping)
            if tm is not None:
                props["texture_mapping"] = tm
        return props

    def _props_image(self, node, props):
        image = getattr(node, "image", None)
        if image is None:
            return
        tiles = None
        if getattr(image, "source", "FILE") == "TILED" and node.bl_idname == "ShaderNodeTexImage":
            tiles = self.images.add_tiles(image, node, self.name)
        if tiles:
            props["tiles"] = tiles
            idx = tiles[0][1]
        else:
            idx = self.images.add(image, node, self.name)
        props["image"] = idx
        if idx is not None:  # how the pixels as written are to be read (see TESELA_images)
            entry = self.images.images[idx]
            props["colorspace"] = entry["colorspace"]
            props["source_colorspace"] = entry["source_colorspace"]
            props["alpha_mode"] = entry["alpha_mode"]
        else:
            props["colorspace"] = image.colorspace_settings.name
            props["source_colorspace"] = image.colorspace_settings.name
            props["alpha_mode"] = getattr(image, "alpha_mode", "STRAIGHT")

    def _props_normal(self, node, props):
        # The Normal node keeps its direction as its output's value.
        out = node.outputs.get("Normal") if hasattr(node.outputs, "get") else node.outputs[0]
        if out is not None and hasattr(out, "default_value"):
            props["direction"] = self._floats(out.default_value, node, "direction")

    def _props_attribute(self, node, props):
        if getattr(node, "attribute_type", "GEOMETRY") == "VIEW_LAYER":
            layer = self.view_layer or attributes.current_view_layer()
            value = attributes.view_layer_value(layer, node.attribute_name)
            if value is not None:
                props["value"] = value

    def _props_object_info(self, node, props):
        # Object Info's Material Index is the material's Pass Index.
        props["material_pass_index"] = int(getattr(self.material, "pass_index", 0) or 0)

    def _props_texcoord(self, node, props):
        ob = getattr(node, "object", None)
        if ob is not None:
            props["object"] = _rows(ob.matrix_world)

    def _props_ramp(self, node, props):
        ramp = node.color_ramp
        props["interpolation"] = ramp.interpolation
        props["color_mode"] = ramp.color_mode
        props["hue_interpolation"] = ramp.hue_interpolation
        props["elements"] = [{"position": float(e.position),
                              "color": self._floats(e.color, node, "ramp colour")}
                             for e in ramp.elements]
        # Cycles bakes the ramp with Blender's own evaluation (colorramp_to_array); so do we.
        table = []
        for i in range(RAMP_TABLE_SIZE + 1):
            table.append(self._floats(ramp.evaluate(i / RAMP_TABLE_SIZE), node, "ramp colour"))
        props["table"] = table

    def _props_curves(self, node, props):
        # Cycles' curvemapping_color_to_array / curvemapping_float_to_array (blender/util.h):
        # the range spans the curves' first to last points (curvemapping_minmax), sampled at
        # RAMP_TABLE_SIZE + 1 points with Blender's CurveMapping.evaluate; RGB Curves apply the
        # combined curve first.
        mapping = node.mapping
        kind = node.bl_idname
        n = {"ShaderNodeRGBCurve": 4, "ShaderNodeVectorCurve": 3}.get(kind, 1)
        curves = list(mapping.curves)[:n]
        for step in ("initialize", "update"):  # as Cycles: tables up to date before evaluate()
            fn = getattr(mapping, step, None)
            if fn is not None:
                try:
                    fn()
                except (RuntimeError, TypeError):
                    pass
        lo = min(float(c.points[0].location[0]) for c in curves)
        hi = max(float(c.points[len(c.points) - 1].location[0]) for c in curves)
        ev = mapping.evaluate
        table = []
        for i in range(RAMP_TABLE_SIZE + 1):
            t = lo + (i / RAMP_TABLE_SIZE) * (hi - lo)
            if kind == "ShaderNodeRGBCurve":
                c = ev(curves[3], t)
                table.append([ev(curves[0], c), ev(curves[1], c), ev(curves[2], c)])
            elif kind == "ShaderNodeVectorCurve":
                table.append([ev(curves[0], t), ev(curves[1], t), ev(curves[2], t)])
            else:
                table.append(ev(curves[0], t))
        props["table"] = self._floats(table, node, "curve table")
        props["min_x"], props["max_x"] = lo, hi
        props["extrapolate"] = getattr(mapping, "extend", "HORIZONTAL") == "EXTRAPOLATED"

    def _props_constant(self, node, props):
        # RGB and Value nodes keep their value in the output socket (Cycles reads it there).
        if node.outputs:
            v = node.outputs[0].default_value
            props["value"] = self._scalar(v, node, "value") if isinstance(v, (int, float)) \
                else self._floats(v, node, "value")


def _texture_mapping(m):
    """A texture node's (rarely used) TexMapping, when it is not the identity."""
    try:
        d = {"vector_type": m.vector_type,
             "translation": [float(v) for v in m.translation],
             "rotation": [float(v) for v in m.rotation],
             "scale": [float(v) for v in m.scale],
             "mapping_x": m.mapping_x, "mapping_y": m.mapping_y, "mapping_z": m.mapping_z,
             "use_min": bool(m.use_min), "use_max": bool(m.use_max),
             "min": [float(v) for v in m.min], "max": [float(v) for v in m.max]}
    except AttributeError:
        return None
    identity = (d["translation"] == [0.0] * 3 and d["rotation"] == [0.0] * 3
                and d["scale"] == [1.0] * 3 and (d["mapping_x"], d["mapping_y"], d["mapping_z"])
                == ("X", "Y", "Z") and not d["use_min"] and not d["use_max"])
    return None if identity else d


_SPECIAL_PROPS = {
    "ShaderNodeTexImage": MaterialGraph._props_image,
    "ShaderNodeTexEnvironment": MaterialGraph._props_image,
    "ShaderNodeTexCoord": MaterialGraph._props_texcoord,
    "ShaderNodeObjectInfo": MaterialGraph._props_object_info,
    "ShaderNodeAttribute": MaterialGraph._props_attribute,
    "ShaderNodeValToRGB": MaterialGraph._props_ramp,
    "ShaderNodeRGBCurve": MaterialGraph._props_curves,
    "ShaderNodeVectorCurve": MaterialGraph._props_curves,
    "ShaderNodeFloatCurve": MaterialGraph._props_curves,
    "ShaderNodeRGB": MaterialGraph._props_constant,
    "ShaderNodeValue": MaterialGraph._props_constant,
    "ShaderNodeNormal": MaterialGraph._props_normal,
}


class MaterialExport:
    """The glTF material dict (fallback + graph) and what the mesh export must know about it."""

    def __init__(self, gltf, tangent_uvs):
        self.gltf = gltf
        self.tangent_uvs = tangent_uvs


def export_material(material, warnings, textures, images, report, view_layer=None):
    """A Blender material -> MaterialExport: the metallic-roughness fallback with the
    TESELA_material_graph extension beside it (`view_layer`: where the Attribute node's View
    Layer type looks its values up; the context's without one)."""
    graph = MaterialGraph(material, images, report, view_layer)
    ext = graph.build()
    if getattr(material, "pass_index", 0):
        ext["pass_index"] = int(material.pass_index)  # the Material Index pass
    # The fallback's own shortcomings concern other tools only: Tesela renders the graph.
    out = convert_material(material, [], textures)
    out.setdefault("extensions", {})["TESELA_material_graph"] = ext
    return MaterialExport(out, graph.tangent_uvs)
