# SPDX-License-Identifier: MIT
"""Tesela's own glTF 2.0 writer, fed by an evaluated depsgraph.

Works in any thread (it never touches bpy.context), reads mesh data with
foreach_get into numpy, and writes one .gltf plus one .bin. Blender's Z-up
world becomes glTF's Y-up through the node matrices (mesh data stays in
object space). Conventions: docs/extensions.md.
"""

import json
import math
import os

import numpy as np

from . import compat

# Blender (x, y, z) -> glTF (x, z, -y)
_Z_UP_TO_Y_UP = np.array([[1, 0, 0, 0],
                          [0, 0, 1, 0],
                          [0, -1, 0, 0],
                          [0, 0, 0, 1]], dtype=np.float64)

FLOAT, UINT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963

DEFAULT_MATERIAL = {  # Cycles renders material-less surfaces as 0.8 grey diffuse
    "name": "__tesela_default",
    "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1.0],
                             "metallicFactor": 0.0, "roughnessFactor": 1.0},
    "doubleSided": True,
}


class ExportCancelled(Exception):
    pass


class ExportResult:
    def __init__(self):
        self.warnings = []
        self.triangles = 0
        self.has_camera = False
        self.gltf_path = None
        self.bin_path = None


def _matrix(mat):
    """A Blender Matrix (4x4, row-major) -> numpy float64."""
    return np.array([list(row) for row in mat], dtype=np.float64)


def _gltf_matrix(np_mat):
    """glTF wants column-major flattening."""
    m = _Z_UP_TO_Y_UP @ np_mat
    return [float(v) for v in m.T.reshape(-1)]


def _finite(v, default=0.0):
    v = float(v)
    return v if math.isfinite(v) else default


def _color3(c):
    return [max(0.0, _finite(c[0])), max(0.0, _finite(c[1])), max(0.0, _finite(c[2]))]


class _Buffer:
    """Accumulates binary data and the bufferViews/accessors that describe it."""

    def __init__(self):
        self.chunks = []
        self.length = 0
        self.views = []
        self.accessors = []

    def add(self, array, component, type_, target, minmax=False):
        data = np.ascontiguousarray(array)
        raw = data.tobytes()
        pad = (-self.length) % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.length += pad
        self.views.append({"buffer": 0, "byteOffset": self.length,
                           "byteLength": len(raw), "target": target})
        self.chunks.append(raw)
        self.length += len(raw)
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[type_]
        acc = {"bufferView": len(self.views) - 1, "componentType": component,
               "count": int(data.size // ncomp), "type": type_}
        if minmax and data.size:
            d = data.reshape(-1, ncomp)
            if component == FLOAT:
                acc["min"] = [float(v) for v in d.min(axis=0)]
                acc["max"] = [float(v) for v in d.max(axis=0)]
            else:
                acc["min"] = [int(v) for v in d.min(axis=0)]
                acc["max"] = [int(v) for v in d.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


# --- materials -----------------------------------------------------------------

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


def write_png(path, pixels):
    """Write float RGBA (h, w, 4), rows top to bottom, values already encoded, as a 16-bit PNG."""
    import struct
    import zlib
    h, w = pixels.shape[:2]
    data = np.clip(np.nan_to_num(pixels, nan=0.0), 0.0, 1.0)
    data = (data * 65535.0 + 0.5).astype(">u2").view(np.uint8).reshape(h, w * 8)
    raw = np.zeros((h, w * 8 + 1), dtype=np.uint8)  # filter byte 0 per row
    raw[:, 1:] = data

    def chunk(tag, body):
        return (struct.pack(">I", len(body)) + tag + body
                + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 6, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)))
        f.write(chunk(b"IEND", b""))


def _linear_to_srgb(c):
    c = np.maximum(c, 0.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


class _Textures:
    """Images, samplers and textures of one export; images are PNG files beside the .gltf."""

    def __init__(self, folder, stem, warnings):
        self.folder, self.stem, self.warnings = folder, stem, warnings
        self.images, self.samplers, self.textures = [], [], []
        self._image_index, self._sampler_index, self._texture_index = {}, {}, {}

    def image_texture(self, sock, material_name):
        """glTF texture index for an Image Texture node feeding `sock` directly, else None."""
        if sock is None or not sock.is_linked:
            return None
        link = sock.links[0]
        node = link.from_node
        while node.bl_idname == "NodeReroute" and node.inputs[0].is_linked:
            link = node.inputs[0].links[0]
            node = link.from_node
        if node.bl_idname != "ShaderNodeTexImage" or node.image is None:
            return None
        if link.from_socket.name != "Color":
            return None
        vec = node.inputs.get("Vector")
        if vec is not None and vec.is_linked:
            self.warnings.append("material '%s': texture coordinates of '%s' are linked; the active "
                                 "UV map is used" % (material_name, node.name))
        img = self._image(node.image)
        if img is None:
            return None
        closest = getattr(node, "interpolation", "Linear") == "Closest"
        filt = 9728 if closest else 9729  # NEAREST or LINEAR; no mipmaps, as Cycles
        wrap = {"REPEAT": 10497, "EXTEND": 33071, "CLIP": 33071, "MIRROR": 33648}.get(
            getattr(node, "extension", "REPEAT"), 10497)
        if getattr(node, "extension", "") == "CLIP":
            self.warnings.append("material '%s': texture clipping renders as 'Extend'" % material_name)
        skey = (filt, wrap)
        if skey not in self._sampler_index:
            self.samplers.append({"magFilter": filt, "minFilter": filt, "wrapS": wrap, "wrapT": wrap})
            self._sampler_index[skey] = len(self.samplers) - 1
        tkey = (img, self._sampler_index[skey])
        if tkey not in self._texture_index:
            self.textures.append({"source": img, "sampler": self._sampler_index[skey]})
            self._texture_index[tkey] = len(self.textures) - 1
        return self._texture_index[tkey]

    def _image(self, image):
        key = image.name
        if key in self._image_index:
            return self._image_index[key]
        self._image_index[key] = None
        w, h = image.size[0], image.size[1]
        if w == 0 or h == 0:
            self.warnings.append("image '%s' has no pixels (missing file?); texture ignored" % image.name)
            return None
        channels = image.channels
        buf = np.empty(w * h * channels, dtype=np.float32)
        image.pixels.foreach_get(buf)
        buf = buf.reshape(h, w, channels)[::-1]  # Blender's rows run bottom to top
        rgba = np.ones((h, w, 4), dtype=np.float32)
        rgba[..., :min(channels, 4)] = buf[..., :4]
        if channels < 3:
            rgba[..., 1] = rgba[..., 2] = rgba[..., 0]
        cs = image.colorspace_settings.name
        if image.is_float or cs not in ("sRGB",):
            # Linear values (float buffers, non-sRGB colour spaces): glTF wants sRGB.
            rgba[..., :3] = _linear_to_srgb(rgba[..., :3])
        name = "%s_%d.png" % (self.stem, len(self.images))
        write_png(os.path.join(self.folder, name), rgba)
        from urllib.parse import quote
        self.images.append({"uri": quote(name), "name": image.name, "mimeType": "image/png"})
        self._image_index[key] = len(self.images) - 1
        return self._image_index[key]


def convert_material(material, warnings, textures=None):
    """A Blender material -> glTF material dict (plus extensions used)."""
    name = material.name
    base = list(material.diffuse_color)[:3]
    alpha = 1.0
    metallic = _finite(getattr(material, "metallic", 0.0))
    roughness = _finite(getattr(material, "roughness", 0.5), 0.5)
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
            base_tex = textures.image_texture(color_sock, name)
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
            metallic = _finite(_input_value(P(node, "metallic"), 0.0))
            roughness = _finite(_input_value(P(node, "roughness"), 0.5), 0.5)
            ior = _finite(_input_value(P(node, "ior"), 1.5), 1.5)
            alpha = _finite(_input_value(P(node, "alpha"), 1.0), 1.0)
            transmission = _finite(_input_value(P(node, "transmission"), 0.0))
            spec_sock = P(node, "specular")
            if spec_sock is not None:
                specular = compat.specular_to_factor(node, spec_sock.default_value)
            emission = list(_input_value(P(node, "emission_color"), (0, 0, 0, 1)))[:3]
            strength = _finite(_input_value(P(node, "emission_strength"), 1.0), 1.0)
        elif kind == "ShaderNodeEmission":
            base = [0.0, 0.0, 0.0]
            metallic, roughness = 0.0, 1.0
            emission = list(_input_value(node.inputs.get("Color"), (1, 1, 1, 1)))[:3]
            strength = _finite(_input_value(node.inputs.get("Strength"), 1.0), 1.0)
            specular = 0.0
        elif kind == "ShaderNodeBsdfDiffuse":
            base = list(_input_value(node.inputs.get("Color"), (0.8, 0.8, 0.8, 1)))[:3]
            metallic, roughness, specular = 0.0, 1.0, 0.0
        elif kind in ("ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic"):
            base = list(_input_value(node.inputs.get("Color"), (0.8, 0.8, 0.8, 1)))[:3]
            metallic = 1.0
            roughness = _finite(_input_value(node.inputs.get("Roughness"), 0.5), 0.5)
        elif kind in ("ShaderNodeBsdfGlass", "ShaderNodeBsdfRefraction"):
            base = list(_input_value(node.inputs.get("Color"), (1, 1, 1, 1)))[:3]
            metallic = 0.0
            roughness = _finite(_input_value(node.inputs.get("Roughness"), 0.0))
            ior = _finite(_input_value(node.inputs.get("IOR"), 1.45), 1.45)
            transmission = 1.0
        else:
            warnings.append("material '%s': shader node %s is not supported; using its viewport colour"
                            % (name, kind))

    base = [min(1.0, max(0.0, _finite(c))) for c in base]
    pbr = {"baseColorFactor": base + [min(1.0, max(0.0, alpha))],
           "metallicFactor": min(1.0, max(0.0, metallic)),
           "roughnessFactor": min(1.0, max(0.0, roughness))}
    if base_tex is not None:
        pbr["baseColorFactor"] = [1.0, 1.0, 1.0, pbr["baseColorFactor"][3]]
        pbr["baseColorTexture"] = {"index": base_tex}
    out = {"name": name, "pbrMetallicRoughness": pbr,
           "doubleSided": not getattr(material, "use_backface_culling", False)}
    ext = {}
    emission = _color3(emission)
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


# --- lights ----------------------------------------------------------------------

def convert_light(light, obj, matrix=None, warnings=None):
    t = light.type
    color, scale = compat.light_color_and_scale(light)
    ext = {"type": t, "color": _color3(color)}
    energy = _finite(light.energy) * scale
    if t == "SUN":
        ext["strength"] = energy
        ext["angle"] = _finite(getattr(light, "angle", 0.0))
    else:
        ext["power"] = energy
    if t in ("POINT", "SPOT"):
        ext["radius"] = _finite(getattr(light, "shadow_soft_size", 0.0))
    if t == "SPOT":
        ext["spot_size"] = _finite(light.spot_size)
        ext["spot_blend"] = _finite(light.spot_blend)
        if getattr(light, "use_square", False) and warnings is not None:
            warnings.append("light '%s': square spots render as round ones" % obj.name)
    if t == "AREA":
        ext["shape"] = light.shape
        ext["size"] = _finite(light.size)
        ext["size_y"] = _finite(light.size_y) if light.shape in ("RECTANGLE", "ELLIPSE") else _finite(light.size)
        spread = getattr(light, "spread", math.pi)
        if spread < math.pi - 1e-4 and warnings is not None:
            warnings.append("light '%s': area light spread is ignored" % obj.name)
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
    ext["visible_camera"] = compat.visible_camera(obj)

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


# --- camera ----------------------------------------------------------------------

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


def _camera_matrix(obj):
    """World matrix without scale (cameras must not scale their frustum)."""
    m = _matrix(obj.matrix_world)
    for i in range(3):
        n = np.linalg.norm(m[:3, i])
        if n > 0:
            m[:3, i] /= n
    return m


# --- world ---------------------------------------------------------------------

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
                strength = _finite(s.default_value, 1.0)
            else:
                warnings.append("world: shader %s not supported; black background" % node.bl_idname)
                color, strength = [0.0, 0.0, 0.0], 1.0
        elif sock is not None:
            color, strength = [0.0, 0.0, 0.0], 1.0
    return {"color": _color3(color), "strength": max(0.0, strength)}


# --- meshes ----------------------------------------------------------------------

_MESHLIKE = {"MESH", "CURVE", "SURFACE", "FONT", "META", "CURVES_LEGACY"}


def _mesh_arrays(mesh, check_cancel=None):
    """(positions, normals, uvs, tri_corners, tri_material) for an evaluated mesh."""
    def checkpoint():
        if check_cancel is not None and check_cancel():
            raise ExportCancelled()
    mesh.calc_loop_triangles()
    checkpoint()
    nt = len(mesh.loop_triangles)
    if nt == 0:
        return None
    n_loops = len(mesh.loops)
    n_verts = len(mesh.vertices)
    tri = np.empty(nt * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", tri)
    tri_mat = np.empty(nt, dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", tri_mat)
    loop_vert = np.empty(n_loops, dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", loop_vert)
    co = compat.vertex_positions(mesh, n_verts)
    checkpoint()
    normals = compat.corner_normals(mesh, n_loops)
    checkpoint()
    uvs = compat.corner_uvs(mesh, n_loops)
    checkpoint()

    # One glTF vertex per corner (face corner = Blender loop): loop triangles cover every
    # loop of every polygon, so the loop indices are the glTF indices as they are.
    positions = co[loop_vert]
    nrm = normals
    sq = np.einsum("ij,ij->i", nrm, nrm)
    if not (np.abs(sq - 1.0) < 1e-4).all():  # rare: renormalise, repair zero/NaN normals
        length = np.sqrt(sq.astype(np.float64))
        bad = ~(length > 1e-12)
        length[bad] = 1.0
        nrm = (nrm / length[:, None]).astype(np.float32)
        nrm[bad] = (0.0, 0.0, 1.0)
    uv = None
    if uvs is not None:
        uv = uvs
        uv[:, 1] = 1.0 - uv[:, 1]  # glTF's UV origin is the top-left corner
    indices = tri.view(np.uint32)
    if not np.isfinite(positions).all():
        positions = np.nan_to_num(positions, nan=0.0, posinf=0.0, neginf=0.0)
    return positions, nrm, uv, indices.reshape(-1, 3), tri_mat


def write_gltf(depsgraph, filepath, *, width, height, camera=None, render_settings=None,
               check_cancel=None, selection=None):
    """Write the evaluated scene of `depsgraph` to `filepath` (.gltf) + a .bin beside it.

    width/height: the final render resolution (percentage applied).
    camera: evaluated camera object (defaults to the scene's).
    render_settings: dict for the TESELA_render extension, or None.
    check_cancel: callable returning True to abort (raises ExportCancelled).
    selection: optional set of original object names to restrict the export.
    """
    res = ExportResult()
    warnings = res.warnings
    scene = depsgraph.scene
    buf = _Buffer()
    doc = {"asset": {"version": "2.0", "generator": "Tesela Blender add-on"},
           "scene": 0, "scenes": [{"name": scene.name, "nodes": []}],
           "nodes": [], "meshes": [], "materials": [], "cameras": []}
    used_ext = set()
    root_nodes = doc["scenes"][0]["nodes"]
    material_index = {}
    out_dir = os.path.dirname(os.path.abspath(filepath))
    stem = os.path.splitext(os.path.basename(filepath))[0]
    textures = _Textures(out_dir, stem, warnings)
    mesh_cache = {}
    khr_lights = []

    def mat_idx(mat):
        key = getattr(mat, "name_full", mat.name) if mat is not None else None
        if key in material_index:
            return material_index[key]
        if mat is None:
            m = dict(DEFAULT_MATERIAL)
        else:
            m = convert_material(mat, warnings, textures)
        for e in m.get("extensions", {}):
            used_ext.add(e)
        doc["materials"].append(m)
        material_index[key] = len(doc["materials"]) - 1
        return material_index[key]

    def add_node(node):
        doc["nodes"].append(node)
        root_nodes.append(len(doc["nodes"]) - 1)

    count = 0
    for inst in depsgraph.object_instances:
        count += 1
        if check_cancel is not None and count % 64 == 0 and check_cancel():
            raise ExportCancelled()
        obj = inst.object
        if selection is not None:
            orig = inst.instance_object if inst.is_instance else obj
            orig = getattr(orig, "original", orig)
            if inst.is_instance:
                par = getattr(inst.parent, "original", inst.parent)
                if par is None or par.name not in selection:
                    continue
            elif orig.name not in selection:
                continue
        otype = obj.type
        if otype in _MESHLIKE:
            data = obj.data
            key = (obj.name, data.as_pointer() if data is not None else 0)
            if key not in mesh_cache:
                if check_cancel is not None and check_cancel():
                    raise ExportCancelled()
                mesh_cache[key] = None
                mesh = None
                try:
                    mesh = obj.to_mesh()
                except RuntimeError:
                    mesh = None
                if mesh is not None:
                    try:
                        arrays = _mesh_arrays(mesh, check_cancel)
                        if arrays is not None:
                            mats = [s.material for s in obj.material_slots] or [None]
                            positions, nrm, uv, indices, tri_mat = arrays
                            mat_ids = [mat_idx(m) for m in mats]
                            if uv is None and any("baseColorTexture" in doc["materials"][i]["pbrMetallicRoughness"]
                                                  for i in mat_ids):
                                # No UV map: Cycles reads UV (0, 0) everywhere; so do we.
                                uv = np.zeros((positions.shape[0], 2), dtype=np.float32)
                                uv[:, 1] = 1.0
                            attrs = {"POSITION": buf.add(positions, FLOAT, "VEC3", ARRAY_BUFFER, True),
                                     "NORMAL": buf.add(nrm, FLOAT, "VEC3", ARRAY_BUFFER)}
                            if uv is not None:
                                attrs["TEXCOORD_0"] = buf.add(uv, FLOAT, "VEC2", ARRAY_BUFFER)
                            tri_mat = np.clip(tri_mat, 0, len(mats) - 1)
                            prims = []
                            single = tri_mat.min() == tri_mat.max()
                            for mi in ([tri_mat[0]] if single else np.unique(tri_mat)):
                                sel = indices if single else indices[tri_mat == mi]
                                acc = buf.add(sel.reshape(-1), UINT, "SCALAR", ELEMENT_ARRAY_BUFFER, True)
                                prims.append({"attributes": attrs, "indices": acc, "mode": 4,
                                              "material": mat_ids[int(mi)]})
                            doc["meshes"].append({"name": obj.name, "primitives": prims})
                            mesh_cache[key] = (len(doc["meshes"]) - 1, int(indices.shape[0]))
                    finally:
                        obj.to_mesh_clear()
            cached = mesh_cache[key]
            if cached is None:
                continue
            if not compat.visible_camera(obj):
                warnings.append("object '%s' is hidden from the camera; Tesela renders it anyway" % obj.name)
            mi, ntri = cached
            res.triangles += ntri
            add_node({"name": obj.name, "mesh": mi, "matrix": _gltf_matrix(_matrix(inst.matrix_world))})
        elif otype in ("CURVES", "POINTCLOUD", "VOLUME", "GPENCIL", "GREASEPENCIL"):
            if ("skip", otype) not in mesh_cache:
                mesh_cache[("skip", otype)] = None
                warnings.append("%s objects are not supported; '%s' (and any others) left out"
                                % (otype.lower(), obj.name))
        elif otype == "LIGHT":
            ext, khr = convert_light(obj.data, obj, _matrix(inst.matrix_world), warnings)
            node = {"name": obj.name, "matrix": _gltf_matrix(_matrix(inst.matrix_world)),
                    "extensions": {"TESELA_light": ext}}
            used_ext.add("TESELA_light")
            if khr is not None:
                khr["name"] = obj.data.name
                khr_lights.append(khr)
                node["extensions"]["KHR_lights_punctual"] = {"light": len(khr_lights) - 1}
                used_ext.add("KHR_lights_punctual")
            add_node(node)

    cam = camera if camera is not None else scene.camera
    if cam is not None and cam.type == "CAMERA":
        cd = cam.data
        if cd.type == "PANO":
            warnings.append("camera '%s': panoramic cameras are not supported; rendering it as "
                            "a perspective camera" % cam.name)
        if abs(cd.shift_x) > 1e-6 or abs(cd.shift_y) > 1e-6:
            warnings.append("camera '%s': lens shift is ignored" % cam.name)
        if getattr(getattr(cd, "dof", None), "use_dof", False):
            warnings.append("camera '%s': depth of field is ignored" % cam.name)
        doc["cameras"].append(dict(camera_fields(cam.data, width, height), name=cam.data.name))
        add_node({"name": cam.name, "camera": 0, "matrix": _gltf_matrix(_camera_matrix(cam))})
        res.has_camera = True

    world = convert_world(scene.world, warnings)
    ext_root = {"TESELA_world": world}
    used_ext.add("TESELA_world")
    if render_settings is not None:
        ext_root["TESELA_render"] = render_settings
        used_ext.add("TESELA_render")
    if khr_lights:
        ext_root["KHR_lights_punctual"] = {"lights": khr_lights}
    doc["extensions"] = ext_root

    if textures.images:
        doc["images"] = textures.images
        doc["samplers"] = textures.samplers
        doc["textures"] = textures.textures
    # Remove empty top-level arrays (glTF forbids empty arrays).
    for k in ("nodes", "meshes", "materials", "cameras"):
        if not doc[k]:
            del doc[k]
    if not root_nodes:
        del doc["scenes"][0]["nodes"]

    base = os.path.splitext(os.path.basename(filepath))[0]
    bin_name = base + ".bin"
    bin_path = os.path.join(os.path.dirname(os.path.abspath(filepath)), bin_name)
    if buf.length:
        from urllib.parse import quote
        doc["buffers"] = [{"uri": quote(bin_name), "byteLength": buf.length}]
        doc["bufferViews"] = buf.views
        doc["accessors"] = buf.accessors
        with open(bin_path, "wb") as f:
            for chunk in buf.chunks:
                f.write(chunk)
        res.bin_path = bin_path
    doc["extensionsUsed"] = sorted(used_ext)
    with open(filepath, "w", encoding="utf-8") as f:
        json.dump(doc, f, ensure_ascii=False, separators=(",", ":"))
    res.gltf_path = filepath
    return res


def render_size(render):
    """Final render resolution (percentage applied), as Blender computes it."""
    pct = render.resolution_percentage
    return (max(1, int(render.resolution_x * pct / 100)),
            max(1, int(render.resolution_y * pct / 100)))


def border_region(render, width, height):
    """The border as (x, y, w, h), top-left origin, or None for the full frame.

    Blender's render result for a border is trunc((max - min) * size) pixels wide (measured
    with Blender 3.4 and 5.0), placed at trunc(min * size).
    """
    if not render.use_border:
        return None
    bx0, bx1 = sorted((render.border_min_x, render.border_max_x))
    by0, by1 = sorted((render.border_min_y, render.border_max_y))
    bx0, by0 = max(0.0, bx0), max(0.0, by0)
    bx1, by1 = min(1.0, bx1), min(1.0, by1)
    xmin = int(bx0 * width)
    ymin = int(by0 * height)
    w = int((bx1 - bx0) * width)
    h = int((by1 - by0) * height)
    w = max(1, min(w, width - xmin))
    h = max(1, min(h, height - ymin))
    if (xmin, ymin, w, h) == (0, 0, width, height):
        return None
    return (xmin, height - ymin - h, w, h)
