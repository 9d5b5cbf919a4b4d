"""glTF files as other tools write them, with extensions the Khronos samples here do not use:
the ``tesela`` CLI on the file against Cycles on the same file imported into Blender with its
own importer (``import_scene.gltf``), which is what an artist who brings the asset into Blender
sees.

- ``EXT_texture_webp`` (gltfpack, three.js, web pipelines): textures whose only image is a WebP
  file, the extension required.
- ``KHR_draco_mesh_compression`` (Blender's own exporter with Draco compression on, web
  pipelines): quantized, reordered geometry decoded from a Draco bitstream.
- ``EXT_meshopt_compression`` (gltfpack, glTF-Transform): meshoptimizer streams over quantized
  attributes, on views of a fallback buffer that holds no data.
- ``KHR_materials_unlit`` (three.js's MeshBasicMaterial, Sketchfab's shadeless assets, baked
  lighting): Blender's importer makes the base colour an Emission of strength 1 seen by camera
  rays only, every other ray passing through, so the surface shows its colour flat and casts no
  shadow; with alpha a Transparent BSDF mixed in.

The scenes are written here as JSON with an embedded buffer: a grey floor, a ceiling panel that
emits (the only light, so that no light unit conversion is involved), and the objects under
test, seen by the file's own camera.

Criteria as tests/blender/test_lights_cycles.py: means within 2%, 8x8 blocks within 5% at the
95th percentile, edges locally.
"""

import base64
import json
import math
import os
import struct
import shutil
import subprocess
import zlib
from pathlib import Path

import bpy
import mathutils
import numpy as np
import pytest

import imgcompare
import scenes
from test_cycles_gltf import run_tesela
from test_lights_cycles import edge_agreement

SIZE = 64


class GltfBuilder:
    """A glTF 2.0 document with one embedded buffer, built mesh by mesh."""

    def __init__(self):
        self.doc = {"asset": {"version": "2.0", "generator": "tesela tests"},
                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [], "meshes": [],
                    "materials": [], "accessors": [], "bufferViews": [], "buffers": []}
        self.blob = bytearray()
        self.used = set()

    def _view(self, data, target):
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data)}
        if target is not None:
            view["target"] = target
        self.doc["bufferViews"].append(view)
        self.blob += data
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, array, kind, target=None):
        array = np.ascontiguousarray(array)
        comp = {np.dtype(np.float32): 5126, np.dtype(np.uint32): 5125,
                np.dtype(np.uint16): 5123}[array.dtype]
        acc = {"bufferView": self._view(array.tobytes(), target), "componentType": comp,
               "count": int(array.shape[0]), "type": kind}
        if kind == "VEC3" and comp == 5126:
            acc["min"] = array.min(axis=0).tolist()
            acc["max"] = array.max(axis=0).tolist()
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def material(self, mat):
        self.doc["materials"].append(mat)
        for ext in mat.get("extensions", {}):
            self.used.add(ext)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, positions, normals, uvs, indices, material, translation=(0, 0, 0),
             skin=None):
        """``skin``: (joints, weights) per vertex (4 each) and the skin index of the node."""
        attrs = {"POSITION": self._accessor(np.asarray(positions, np.float32), "VEC3", 34962),
                 "NORMAL": self._accessor(np.asarray(normals, np.float32), "VEC3", 34962),
                 "TEXCOORD_0": self._accessor(np.asarray(uvs, np.float32), "VEC2", 34962)}
        if skin is not None:
            joints, weights, _ = skin
            attrs["JOINTS_0"] = self._accessor(np.asarray(joints, np.uint16), "VEC4", 34962)
            attrs["WEIGHTS_0"] = self._accessor(np.asarray(weights, np.float32), "VEC4", 34962)
        ind = self._accessor(np.asarray(indices, np.uint32).reshape(-1), "SCALAR", 34963)
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": attrs, "indices": ind, "material": material}]})
        node = {"name": name, "mesh": len(self.doc["meshes"]) - 1,
                "translation": list(translation)}
        if skin is not None:
            node["skin"] = skin[2]
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def quad(self, name, corners, material, translation=(0, 0, 0)):
        """Two triangles over four corners (counter-clockwise seen from the front)."""
        c = np.asarray(corners, np.float64)
        n = np.cross(c[1] - c[0], c[2] - c[0])
        n /= np.linalg.norm(n)
        self.mesh(name, c, [n] * 4, [(0, 1), (1, 1), (1, 0), (0, 0)], [0, 1, 2, 0, 2, 3],
                  material, translation)

    def box(self, name, half, material, translation):
        """A closed box of half-extents ``half``, faces outward, flat normals."""
        pos, nor, uv, ind = [], [], [], []
        for axis in range(3):
            for sign in (-1.0, 1.0):
                n = np.zeros(3)
                n[axis] = sign
                u, v = np.zeros(3), np.zeros(3)
                u[(axis + 1) % 3], v[(axis + 2) % 3] = 1.0, 1.0
                if sign < 0:
                    u, v = v, u
                base = len(pos)
                for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                    pos.append((n + a * u + b * v) * np.asarray(half))
                    nor.append(n)
                    uv.append(((a + 1) / 2, (b + 1) / 2))
                ind += [base, base + 1, base + 2, base, base + 2, base + 3]
        self.mesh(name, pos, nor, uv, ind, material, translation)

    def png_texture(self, rgba):
        """An embedded PNG (RGBA8, rows top to bottom) as texture, with a nearest sampler."""
        h, w, _ = rgba.shape
        raw = b"".join(b"\x00" + bytes(rgba[y].astype(np.uint8).tobytes()) for y in range(h))

        def chunk(kind, data):
            c = kind + data
            return struct.pack(">I", len(data)) + c + struct.pack(">I", zlib.crc32(c))
        png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
               + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
        self.doc.setdefault("images", []).append(
            {"uri": "data:image/png;base64," + base64.b64encode(png).decode()})
        self.doc.setdefault("samplers", []).append({"magFilter": 9728, "minFilter": 9728})
        self.doc.setdefault("textures", []).append(
            {"source": len(self.doc["images"]) - 1, "sampler": len(self.doc["samplers"]) - 1})
        return len(self.doc["textures"]) - 1

    def webp_texture(self, rgba, tmp_path):
        """An embedded WebP image (written by Blender) as the only source of a texture
        (``EXT_texture_webp``, required), with a nearest sampler."""
        h, w, _ = rgba.shape
        img = bpy.data.images.new("webp", w, h, alpha=True)
        img.pixels.foreach_set((rgba[::-1] / 255.0).astype(np.float32).ravel())
        path = tmp_path / "texture.webp"
        img.filepath_raw, img.file_format = str(path), "WEBP"
        img.save()
        bpy.data.images.remove(img)
        data = path.read_bytes()
        assert data[8:12] == b"WEBP", "Blender did not write a WebP file"
        self.doc.setdefault("images", []).append(
            {"uri": "data:image/webp;base64," + base64.b64encode(data).decode()})
        self.doc.setdefault("samplers", []).append({"magFilter": 9728, "minFilter": 9728})
        self.doc.setdefault("textures", []).append(
            {"sampler": len(self.doc["samplers"]) - 1,
             "extensions": {"EXT_texture_webp": {"source": len(self.doc["images"]) - 1}}})
        self.used.add("EXT_texture_webp")
        self.doc.setdefault("extensionsRequired", []).append("EXT_texture_webp")
        return len(self.doc["textures"]) - 1

    def camera(self, eye, target, yfov):
        """A perspective camera at ``eye`` looking at ``target`` (glTF: it looks along -Z)."""
        eye, target = np.asarray(eye, float), np.asarray(target, float)
        f = target - eye
        f /= np.linalg.norm(f)
        up = (0.0, 1.0, 0.0) if abs(f[1]) < 0.99 else (0.0, 0.0, -1.0)
        r = np.cross(f, up)
        r /= np.linalg.norm(r)
        u = np.cross(r, f)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
        self.doc["cameras"] = [{"type": "perspective", "perspective": {
            "yfov": yfov, "aspectRatio": 1.0, "znear": 0.01}}]
        self.doc["nodes"].append({"name": "Camera", "camera": 0,
                                  "matrix": m.T.reshape(-1).tolist()})
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, path):
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": "data:application/"
                                "octet-stream;base64," + base64.b64encode(self.blob).decode()}]
        if self.used:
            self.doc["extensionsUsed"] = sorted(self.used)
        path.write_text(json.dumps(self.doc))
        return path


def stage(camera=((1.2, 2.4, 4.2), (0.0, 0.4, 0.0), math.radians(45.0))):
    """Floor, emitting ceiling panel (glTF is Y-up) and the file's camera (eye, target, yfov)."""
    g = GltfBuilder()
    floor = g.material({"name": "Floor", "pbrMetallicRoughness": {
        "baseColorFactor": [0.8, 0.8, 0.8, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}})
    g.quad("Floor", [(-3, 0, 3), (3, 0, 3), (3, 0, -3), (-3, 0, -3)], floor)
    panel = g.material({"name": "Panel", "emissiveFactor": [1.0, 1.0, 1.0],
                        "extensions": {"KHR_materials_emissive_strength": {
                            "emissiveStrength": 6.0}},
                        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                                 "metallicFactor": 0.0}})
    # Facing down, lighting the stage from the left and above.
    g.quad("Panel", [(-2.2, 2.6, -0.8), (-0.6, 2.6, -0.8), (-0.6, 2.6, 0.8), (-2.2, 2.6, 0.8)],
           panel)
    g.camera(*camera)
    return g


def unlit_scene():
    """An unlit orange box (it must look flat and cast no shadow), an unlit card whose texture
    has transparent cells (alpha BLEND, double-sided), and a lit grey ball-less box beside
    them for comparison."""
    g = stage()
    orange = g.material({"name": "UnlitOrange", "extensions": {"KHR_materials_unlit": {}},
                         "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.35, 0.05, 1.0]}})
    g.box("UnlitBox", (0.4, 0.4, 0.4), orange, (-0.6, 0.4, 0.2))
    cells = np.zeros((4, 4, 4), np.uint8)
    for y in range(4):
        for x in range(4):
            cells[y, x] = (40, 120, 230, 255) if (x + y) % 2 == 0 else (250, 250, 250, 0)
    card = g.material({"name": "UnlitCard", "alphaMode": "BLEND", "doubleSided": True,
                       "extensions": {"KHR_materials_unlit": {}},
                       "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 0.9],
                                                "baseColorTexture": {
                                                    "index": g.png_texture(cells)}}})
    g.quad("UnlitCard", [(0.3, 0.0, 0.0), (1.5, 0.0, 0.0), (1.5, 1.2, 0.0), (0.3, 1.2, 0.0)],
           card)
    lit = g.material({"name": "Lit", "pbrMetallicRoughness": {
        "baseColorFactor": [0.5, 0.5, 0.5, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}})
    g.box("LitBox", (0.25, 0.25, 0.25), lit, (0.6, 0.25, 1.2))
    return g


def webp_scene(tmp_path):
    """A box and a standing card textured from WebP images only: an opaque colour grid on the
    box, and a card whose cut-out cells come from the WebP's alpha (MASK)."""
    g = stage()
    grid = np.zeros((8, 8, 4), np.uint8)
    for y in range(8):
        for x in range(8):
            grid[y, x] = (40 + 26 * x, 200 - 20 * y, 90 + 15 * ((x + y) % 4), 255)
    boxmat = g.material({"name": "WebpBox", "pbrMetallicRoughness": {
        "baseColorTexture": {"index": g.webp_texture(grid, tmp_path)},
        "metallicFactor": 0.0, "roughnessFactor": 0.7}})
    g.box("WebpBox", (0.45, 0.45, 0.45), boxmat, (-0.5, 0.45, 0.3))
    cells = np.zeros((4, 4, 4), np.uint8)
    for y in range(4):
        for x in range(4):
            cells[y, x] = (230, 120, 30, 255) if (x + y) % 2 == 0 else (30, 30, 30, 0)
    card = g.material({"name": "WebpCard", "alphaMode": "MASK", "doubleSided": True,
                       "pbrMetallicRoughness": {"baseColorTexture": {
                           "index": g.webp_texture(cells, tmp_path)},
                           "metallicFactor": 0.0}})
    g.quad("WebpCard", [(0.3, 0.0, 0.0), (1.5, 0.0, 0.0), (1.5, 1.2, 0.0), (0.3, 1.2, 0.0)],
           card)
    return g


def skinned_scene(tmp_path):
    """A bent arm: a square tube along X whose outer half follows a second joint turned 50
    degrees up, in the pose the joint nodes give (no animation); its mesh node carries a
    translation that glTF says a skinned mesh ignores."""
    g = stage()
    arm = g.material({"name": "Arm", "pbrMetallicRoughness": {
        "baseColorFactor": [0.7, 0.5, 0.3, 1.0], "metallicFactor": 0.0,
        "roughnessFactor": 0.5}})
    xs = np.linspace(-1.0, 1.0, 9)
    h = 0.15
    ring = [(-h, -h), (h, -h), (h, h), (-h, h)]  # (y, z) offsets about the axis
    pos, nor, uv, joints, weights, ind = [], [], [], [], [], []
    for side in range(4):
        (y0, z0), (y1, z1) = ring[side], ring[(side + 1) % 4]
        n = np.array([0.0, y0 + y1, z0 + z1])
        n /= np.linalg.norm(n)
        base = len(pos)
        for x in xs:
            w1 = float(np.clip((x + 0.25) / 0.5, 0.0, 1.0))  # joint 1 from x = -0.25 to 0.25
            for y, z in ((y0, z0), (y1, z1)):
                pos.append((x, 0.4 + y, z))
                nor.append(n)
                uv.append(((x + 1) / 2, side / 4))
                joints.append((0, 1, 0, 0))
                weights.append((1.0 - w1, w1, 0.0, 0.0))
        for k in range(len(xs) - 1):
            a, b = base + 2 * k, base + 2 * k + 2
            ind += [a, b + 1, b, a, a + 1, b + 1]
    first_joint = len(g.doc["nodes"])
    g.doc["nodes"].append({"name": "Shoulder", "translation": [-1.0, 0.4, 0.0],
                           "children": [first_joint + 1]})
    c, s_ = math.cos(math.radians(25.0)), math.sin(math.radians(25.0))
    g.doc["nodes"].append({"name": "Elbow", "translation": [1.0, 0.0, 0.0],
                           "rotation": [0.0, 0.0, s_, c]})
    g.doc["scenes"][0]["nodes"].append(first_joint)
    inverse_bind = np.stack([np.eye(4), np.eye(4)]).astype(np.float32)
    inverse_bind[0][:3, 3] = (1.0, -0.4, 0.0)   # the joints' bind poses: translations
    inverse_bind[1][:3, 3] = (0.0, -0.4, 0.0)
    ib = g._accessor(inverse_bind.transpose(0, 2, 1).reshape(-1, 16), "MAT4")
    g.doc.setdefault("skins", []).append(
        {"joints": [first_joint, first_joint + 1], "inverseBindMatrices": ib})
    g.mesh("Arm", pos, nor, uv, ind, arm, translation=(3.0, 0.0, 0.0),
           skin=(joints, weights, len(g.doc["skins"]) - 1))
    return g


def cycles_of_import(gltf, tmp_path, spp, bounces, world=None):
    """The file imported by Blender's importer into an empty scene, rendered by Cycles through
    the file's camera; the world black or of constant radiance ``world`` (RGB)."""
    scene = scenes.clear_scene()
    if world is not None:
        bg = scene.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = (*world, 1.0)
        bg.inputs["Strength"].default_value = 1.0
    bpy.ops.import_scene.gltf(filepath=str(gltf))
    scene.camera = next(ob for ob in scene.objects if ob.type == "CAMERA")
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    return imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))


def specular_glossiness_scene(tmp_path):
    """KHR_materials_pbrSpecularGlossiness (older exporters, Sketchfab's legacy assets): a box
    with diffuse and specular-glossiness textures (the gloss in the alpha, from glossy to
    rough cells), and a card with factors only. The extension is required, as such files
    often have no metallic-roughness fallback."""
    g = stage()
    ext = "KHR_materials_pbrSpecularGlossiness"
    diffuse = np.zeros((4, 4, 4), np.uint8)
    spec = np.zeros((4, 4, 4), np.uint8)
    for y in range(4):
        for x in range(4):
            diffuse[y, x] = (180 - 30 * x, 90 + 30 * y, 60, 255)
            spec[y, x] = ((40, 40, 40) if (x + y) % 2 else (200, 170, 90)) + (255 - 70 * x,)
    box = g.material({"name": "SpecGlossBox", "extensions": {ext: {
        "diffuseTexture": {"index": g.png_texture(diffuse)},
        "specularGlossinessTexture": {"index": g.png_texture(spec)},
        "glossinessFactor": 0.9}}})
    g.box("SpecGlossBox", (0.45, 0.45, 0.45), box, (-0.5, 0.45, 0.3))
    card = g.material({"name": "SpecGlossCard", "doubleSided": True, "extensions": {ext: {
        "diffuseFactor": [0.2, 0.4, 0.8, 1.0], "specularFactor": [0.5, 0.45, 0.4],
        "glossinessFactor": 0.6}}})
    g.quad("SpecGlossCard", [(0.3, 0.0, 0.0), (1.5, 0.0, 0.0), (1.5, 1.2, 0.0), (0.3, 1.2, 0.0)],
           card)
    g.doc.setdefault("extensionsRequired", []).append(ext)
    return g


def blender_scene(tmp_path, name, **export):
    """A scene built in Blender and written by Blender's own exporter with the options
    ``export``: a smooth UV sphere with an image texture, a subdivided Suzanne of flat and
    smooth faces in a glossy dielectric, a floor, and an emitting panel, seen by the scene's
    camera."""
    scenes.clear_scene()
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.material("Floor", (0.55, 0.55, 0.5), roughness=0.7))
    img = bpy.data.images.new("Checks", 8, 8)
    px = np.zeros((8, 8, 4), np.float32)
    px[..., 3] = 1.0
    for y in range(8):
        for x in range(8):
            px[y, x, :3] = (0.9, 0.5, 0.1) if (x + y) % 2 else (0.1, 0.3, 0.8)
    img.pixels.foreach_set(px.ravel())
    img.pack()
    checks = scenes.material("Checks", roughness=0.5)
    nt = checks.node_tree
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = img
    tex.interpolation = "Closest"
    principled = next(n for n in nt.nodes if n.type == "BSDF_PRINCIPLED")
    nt.links.new(tex.outputs["Color"], principled.inputs["Base Color"])
    ball = scenes.uv_sphere_add(radius=0.6, location=(-0.7, 0.2, 0.6), segments=32,
                                ring_count=16)
    ball.rotation_euler = (0.0, 0.0, math.radians(30.0))
    ball.data.materials.append(checks)
    bpy.ops.object.shade_smooth()
    bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0.8, -0.1, 0.55))
    suzanne = bpy.context.active_object
    suzanne.rotation_euler = (0.0, 0.0, math.radians(-20.0))
    suzanne.modifiers.new("Subdivision", "SUBSURF").levels = 1
    suzanne.data.materials.append(scenes.material("Glossy", (0.8, 0.15, 0.1), roughness=0.25))
    for i, poly in enumerate(suzanne.data.polygons):
        poly.use_smooth = i % 3 != 0
    panel = scenes.emitter("Panel", (1.0, 0.95, 0.9), 12.0)
    scenes.add_quad("Panel", [(-1.0, -1.0, 3.0), (-1.0, 0.5, 3.0), (0.5, 0.5, 3.0),
                              (0.5, -1.0, 3.0)], panel)
    scenes.add_camera((1.8, -4.2, 2.2), (0.0, 0.0, 0.5), fov=math.radians(40.0))
    scene = bpy.context.scene
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    path = tmp_path / name / f"{name}.gltf"
    path.parent.mkdir()
    bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLTF_SEPARATE",
                              export_cameras=True, **export)
    return path


def draco_scene(tmp_path):
    """:func:`blender_scene` with Draco compression on (the exporter's defaults: positions
    quantized to 14 bits, normals 10, UVs 12)."""
    path = blender_scene(tmp_path, "draco", export_draco_mesh_compression_enable=True)
    doc = json.loads(path.read_text())
    assert "KHR_draco_mesh_compression" in doc.get("extensionsRequired", []), \
        "the exporter did not compress the meshes"
    return path


def file_agrees(tesela_bin, tmp_path, name, gltf, spp, bounces, world, imported=None):
    """Asserts that the CLI's render of ``gltf`` agrees with Cycles' render of Blender's import
    of it, or of the file ``imported`` (means, 8x8 blocks, edges), both under the constant
    world ``world`` (None: black)."""
    ref = cycles_of_import(imported or gltf, tmp_path, spp, bounces, world)
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    extra = ["--background", *map(str, world)] if world else []
    got = run_tesela(tesela_bin, gltf, tmp_path / "tesela.exr", "path_mis", spp, bounces + 2,
                     extra=extra)
    result = imgcompare.compare(got, ref, mean_tol=0.02, block_tol=0.05)
    edge_err, grad_ratio = edge_agreement(got, ref)
    print(f"{name}: {result}; edges: blurred median err {edge_err:.4f}, "
          f"gradient ratio {grad_ratio:.4f}")
    assert result.ok, f"{name}: Tesela (CLI) vs Cycles (import): {result}"
    assert edge_err <= 0.05, f"{name}: edges differ locally: median error {edge_err:.4f}"
    assert abs(grad_ratio - 1.0) <= 0.10, f"{name}: edge gradients differ: ratio {grad_ratio:.4f}"


# (name, builder, world radiance or None for black)
CASES = [("unlit", lambda tmp_path: unlit_scene(), None), ("webp", webp_scene, None),
         ("skinned", skinned_scene, None),
         ("specular_glossiness", specular_glossiness_scene, (0.3, 0.3, 0.33))]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_file_agrees_with_cycles_import(tesela_bin, tmp_path, case):
    name, build, world = case
    gltf = build(tmp_path).write(tmp_path / f"{name}.gltf")
    file_agrees(tesela_bin, tmp_path, name, gltf, 256, 4, world)


def test_draco_file_from_blender_agrees_with_cycles_import(tesela_bin, tmp_path):
    file_agrees(tesela_bin, tmp_path, "draco", draco_scene(tmp_path), 256, 4, (0.2, 0.2, 0.22))


@pytest.mark.parametrize("flags", [["-c"], ["-cc"], ["-c", "-vpf"]], ids=["c", "cc", "c_vpf"])
def test_meshopt_file_from_gltfpack_agrees_with_cycles(tesela_bin, tmp_path, flags):
    """gltfpack (meshoptimizer's glTF packer; npm) compresses Blender's export with
    EXT_meshopt_compression over quantized attributes (octahedral normal filters; ``-vpf``
    float positions through the exponential filter). Blender's importer does not read meshopt,
    so Cycles renders its import of the uncompressed file the packed one was made from."""
    gltfpack = os.environ.get("GLTFPACK") or shutil.which("gltfpack")
    if not gltfpack or not Path(gltfpack).exists():
        pytest.skip("gltfpack (npm) is not installed")
    plain = blender_scene(tmp_path, "plain")
    packed = tmp_path / "packed.glb"
    subprocess.run([gltfpack, "-i", str(plain), "-o", str(packed), *flags], check=True,
                   capture_output=True, timeout=120)
    header = packed.read_bytes()[:4096]
    assert b"EXT_meshopt_compression" in header, "gltfpack did not compress the meshes"
    file_agrees(tesela_bin, tmp_path, "meshopt", packed, 256, 4, (0.2, 0.2, 0.22),
                imported=plain)


def test_unlit_is_flat_and_casts_no_shadow(tesela_bin, tmp_path):
    """Without Cycles: the unlit box's pixels are exactly its colour; and looking down on the
    floor beside it, where its shadow would fall, the floor is as bright as with no box at all,
    while an ordinary box in its place darkens it."""
    img = run_tesela(tesela_bin, unlit_scene().write(tmp_path / "unlit.gltf"),
                     tmp_path / "unlit.exr", "path_mis", 64, 6)
    px = img[..., :3].reshape(-1, 3)
    orange = np.all(np.abs(px - (1.0, 0.35, 0.05)) < 1e-4, axis=1)
    assert orange.sum() > 60, f"only {orange.sum()} pixels show the unlit colour exactly"

    def floor_beside(box_material):
        g = stage(camera=((1.0, 6.0, 0.2), (1.0, 0.0, 0.2), math.radians(20.0)))
        if box_material is not None:
            g.box("Box", (0.4, 0.4, 0.4), g.material(box_material), (-0.6, 0.4, 0.2))
        path = g.write(tmp_path / "beside.gltf")
        return run_tesela(tesela_bin, path, tmp_path / "beside.exr", "path_mis", 256, 6)[
            ..., :3].mean()

    bare = floor_beside(None)
    unlit = floor_beside({"name": "U", "extensions": {"KHR_materials_unlit": {}},
                          "pbrMetallicRoughness": {"baseColorFactor": [1, 0.35, 0.05, 1]}})
    lit = floor_beside({"name": "L", "pbrMetallicRoughness": {
        "baseColorFactor": [1, 0.35, 0.05, 1], "metallicFactor": 0.0}})
    print(f"floor beside the box: none {bare:.5f}, unlit {unlit:.5f}, lit {lit:.5f}")
    assert lit < 0.97 * bare, "the view does not show where the box's shadow falls"
    assert abs(unlit / bare - 1.0) < 0.005


# --------------------------------------------------------------------------------------------
# Khronos samples: the file as it is, with a camera and a light added to it


SAMPLES = Path(__file__).resolve().parents[3] / "shared" / "gltf-samples"


def _to_gltf(v):
    """Blender's Z-up coordinates to glTF's Y-up ones."""
    return (v[0], v[2], -v[1])


def lit_sample(name, tmp_path):
    """A copy of sample ``name`` (its .gltf variant and the files beside it) with a camera
    framing it from the front right and above and an emitting panel over the camera's left
    shoulder added to the file: the one file both renderers read. The model's bounds come
    from Blender's import of the original."""
    folder = SAMPLES / name / "glTF"
    files = sorted(folder.glob("*.gltf")) if folder.is_dir() else []
    if not files:
        pytest.skip(f"glTF sample {name} not found under {SAMPLES}")
    copy = tmp_path / name
    shutil.copytree(folder, copy)
    src = copy / files[0].name
    scenes.clear_scene()
    bpy.ops.import_scene.gltf(filepath=str(src))
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for ob in bpy.context.scene.objects:
        if ob.type == "MESH":
            for corner in ob.bound_box:
                w = np.array(ob.matrix_world @ mathutils.Vector(corner))
                lo, hi = np.minimum(lo, w), np.maximum(hi, w)
    centre, radius = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) / 2

    g = GltfBuilder()
    g.doc = json.loads(src.read_text())
    for key in ("nodes", "meshes", "materials", "accessors", "bufferViews", "buffers"):
        g.doc.setdefault(key, [])
    scene = g.doc["scenes"][g.doc.get("scene", 0)]
    g.doc["scene"] = g.doc.get("scene", 0)
    # The builder appends to scene 0's node list and to a new buffer of its own.
    g.doc["scenes"] = [scene] + [s for s in g.doc["scenes"] if s is not scene]
    g.doc["scene"] = 0
    own = len(g.doc["buffers"])
    for node in g.doc["nodes"]:
        node.pop("camera", None)  # the camera added below is the one
    panel = g.material({"name": "KeyPanel", "emissiveFactor": [1.0, 1.0, 1.0],
                        "extensions": {"KHR_materials_emissive_strength": {
                            "emissiveStrength": 95.0}},
                        "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                                 "metallicFactor": 0.0}})
    key = centre + np.array([-1.5, -1.5, 2.0]) * radius
    f = centre - key
    f /= np.linalg.norm(f)
    u = np.cross(f, (0.0, 0.0, 1.0))
    u /= np.linalg.norm(u)
    v = np.cross(u, f)
    h = radius / 2
    corners = [key - h * u - h * v, key - h * u + h * v, key + h * u + h * v, key + h * u - h * v]
    g.quad("KeyPanel", [_to_gltf(c) for c in corners], panel)
    eye = centre + np.array([0.6, -2.2, 0.9]) * radius
    g.camera(_to_gltf(eye), _to_gltf(centre), math.radians(40.0))
    # The builder's buffer views point at buffer 0; its data is buffer `own`.
    first_own_view = len(g.doc["bufferViews"]) - 4
    for view in g.doc["bufferViews"][first_own_view:]:
        view["buffer"] = own
    blob = base64.b64encode(bytes(g.blob)).decode()
    g.doc["buffers"].append({"byteLength": len(g.blob),
                             "uri": "data:application/octet-stream;base64," + blob})
    used = set(g.doc.get("extensionsUsed", [])) | g.used
    g.doc["extensionsUsed"] = sorted(used)
    out = copy / ("lit_" + files[0].name)
    out.write_text(json.dumps(g.doc))
    return out


# (sample, spp): what each exercises in the preset material. Not here: samples whose meshes
# have no material (BoxVertexColors, Cameras), where glTF's default material (white, metallic
# 1, roughness 1) and Blender's importer (a default Principled, metallic 0) part ways; and
# TransmissionRoughnessTest, whose rough thin glass agrees in the means (0.4%) but not yet in
# every block (p95 0.048, one block 11% off at 2048 samples).
SAMPLE_CASES = [
    ("BoxTextured", 128),            # base colour texture on the default dielectric
    ("Box With Spaces", 128),        # normal map, metallic-roughness texture
    ("SpecularTest", 512),           # KHR_materials_specular factors and tints
    ("TextureTransformTest", 128),   # KHR_texture_transform
    ("TextureSettingsTest", 128),    # samplers, double-sidedness
    ("EmissiveStrengthTest", 128),
]


@pytest.mark.parametrize("case", SAMPLE_CASES, ids=[c[0] for c in SAMPLE_CASES])
def test_sample_file_agrees_with_cycles_import(tesela_bin, tmp_path, case):
    name, spp = case
    file_agrees(tesela_bin, tmp_path, name, lit_sample(name, tmp_path), spp, 2,
                (0.3, 0.3, 0.33))
