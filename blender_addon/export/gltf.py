# SPDX-License-Identifier: MIT
"""The glTF document of one export: walks the depsgraph's object instances, asks the per-kind
modules (mesh, material, light, camera, world) for their parts and writes .gltf + .bin."""

import json
import os
import struct
import time

import numpy as np

from .. import compat
from .attributes import InstanceAttributes, material_reads
from .buffer import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, FLOAT, UINT, Buffer
from .camera import camera_extension, camera_fields, camera_matrix, pixel_aspect
from .common import ExportCancelled, Phases, gltf_matrix, matrix
from .curves import curves_extension, particle_hair_extension
from .images import ImageTable, Textures
from .instances import collapse
from .light import convert_light
from .linking import LightLinking
from .material import MaterialReport, default_surface, export_material
from .points import points_extension
from .mesh import (MESHLIKE, geometry_key, mesh_arrays, object_extras, read_mesh,
                   undeformed_positions)
from .world import convert_world


class ExportResult:
    def __init__(self):
        self.warnings = []
        self.material_warnings = {}  # material name -> [messages] (what fell back)
        self.triangles = 0
        self.has_camera = False
        self.gltf_path = None
        self.bin_path = None
        self.instanced_nodes = 0  # nodes folded into EXT_mesh_gpu_instancing
        self.phases = Phases()


class Geometry:
    """The accessors of one evaluated mesh, shared by every glTF mesh that places it."""

    def __init__(self, attributes, extras, slots, triangles, texspace):
        self.attributes = attributes  # glTF attribute name -> accessor
        self.extras = extras          # the primitives' extras (UV and colour names)
        self.slots = slots            # [(material slot, index accessor)]
        self.triangles = triangles
        self.texspace = texspace

    def moved(self, first):
        """The same geometry with its accessors numbered from `first` (a buffer file's
        accessors appended to a document)."""
        return Geometry({k: a + first for k, a in self.attributes.items()}, self.extras,
                        [(slot, a + first) for slot, a in self.slots], self.triangles,
                        self.texspace)


def _rendered_hair(obj):
    """Names of the hair particle systems of `obj` that Cycles renders as strands (enabled for
    renders, drawn as paths; object and collection hair arrive as instances)."""
    names = []
    for mod in getattr(obj, "modifiers", ()):
        if mod.type != "PARTICLE_SYSTEM" or not getattr(mod, "show_render", True):
            continue
        ps = mod.particle_system
        if ps.settings.type == "HAIR" and ps.settings.render_type == "PATH":
            names.append(ps.name)
    return names


def write_gltf(depsgraph, filepath, *, width, height, camera=None, render_settings=None,
               check_cancel=None, selection=None, mesh_store=None, motion=None):
    """Write the evaluated scene of `depsgraph` to `filepath` (.gltf) + a .bin beside it.

    width/height: the final render resolution (percentage applied).
    camera: evaluated camera object (defaults to the scene's).
    render_settings: dict for the TESELA_render extension, or None.
    check_cancel: callable returning True to abort (raises ExportCancelled).
    selection: optional set of original object names to restrict the export.
    mesh_store: a MeshStore whose folder holds `filepath`: the meshes' buffers go to its files,
    one per mesh content, written only where no earlier export wrote them (animations).
    motion: a motion.Motion sampled over the shutter (motion blur), or None.
    """
    res = ExportResult()
    warnings = res.warnings
    scene = depsgraph.scene
    buf = Buffer()
    doc = {"asset": {"version": "2.0", "generator": "Tesela Blender add-on"},
           "scene": 0, "scenes": [{"name": scene.name, "nodes": []}],
           "nodes": [], "meshes": [], "materials": [], "cameras": []}
    used_ext = set()
    root_nodes = doc["scenes"][0]["nodes"]
    material_index = {}   # material key -> (glTF index, tangent UV maps)
    out_dir = os.path.dirname(os.path.abspath(filepath))
    stem = os.path.splitext(os.path.basename(filepath))[0]
    textures = Textures(out_dir, stem, warnings)
    report = MaterialReport(warnings, res.material_warnings)
    images = ImageTable(buf, report)
    geometry_cache = {}  # geometry key -> Geometry, or None without triangles
    mesh_cache = {}  # (geometry key, glTF materials) -> (mesh index, triangles, texspace)
    store_files = {}  # mesh store digest -> its first accessor here
    object_cache = {}  # (object name, data) -> the mesh_cache entry
    reads_of = {}  # object name -> what its materials read of it (attributes.material_reads)
    instance_attributes = InstanceAttributes()
    frame = compat.frame_final(depsgraph.scene)
    mesh_nodes = {}  # glTF mesh index -> nodes placing it
    khr_lights = []

    def mat_idx(mat):
        key = getattr(mat, "name_full", mat.name) if mat is not None else None
        if key in material_index:
            return material_index[key]
        tangent_uvs = set()
        if mat is None:
            m = default_surface()
        else:
            exported = export_material(mat, warnings, textures, images, report,
                                       view_layer=depsgraph.view_layer)
            m, tangent_uvs = exported.gltf, exported.tangent_uvs
        for e in m.get("extensions", {}):
            used_ext.add(e)
        doc["materials"].append(m)
        material_index[key] = (len(doc["materials"]) - 1, tangent_uvs)
        return material_index[key]

    def slot_materials(slots):
        """The glTF material of each material of `slots` (None for an empty slot)."""
        return [None if m is None else mat_idx(m)[0] for m in slots]

    def reads(obj):
        """What `obj`'s materials read of it (its materials walked once per object)."""
        found = reads_of.get(obj.name)
        if found is None:
            found = reads_of[obj.name] = material_reads(obj)
        return found

    def tesela_object(inst, obj):
        """extras.tesela_object of instance `inst` of `obj`."""
        return object_extras(inst, obj, depsgraph.view_layer, frame, reads(obj),
                             instance_attributes)

    def linked_node(node, obj, inst):
        """`node` with the light linking of `obj` (instance `inst`), added to the scene."""
        link = linking.extension(obj, inst.parent if inst.is_instance else None)
        if link is not None:
            node.setdefault("extensions", {})["TESELA_light_linking"] = link
            used_ext.add("TESELA_light_linking")
        add_node(node)

    def add_node(node):
        doc["nodes"].append(node)
        root_nodes.append(len(doc["nodes"]) - 1)

    def add_geometry(obj, mesh, n_slots, tangent_uvs, texture_without_uv):
        """The Geometry of an evaluated mesh: its data in this export's buffer, or, with a
        mesh store, in the store's file for its content (written unless a frame before wrote
        it)."""
        raw = read_mesh(mesh, check_cancel, res.phases)
        if raw is None:
            return None
        raw.add_orco(undeformed_positions(obj, raw.co, render=depsgraph.mode == "RENDER"))
        if mesh_store is None:
            return build_geometry(buf, obj, mesh, raw, n_slots, tangent_uvs, texture_without_uv,
                                  warnings.append)
        with res.phases("digest"):
            digest = raw.digest(sorted(tangent_uvs), texture_without_uv, n_slots)
        stored = mesh_store.get(digest)
        if stored is None:
            own, found = Buffer(), []
            geometry = build_geometry(own, obj, mesh, raw, n_slots, tangent_uvs,
                                      texture_without_uv, found.append)
            if geometry is None:
                return None
            with res.phases("write"):
                stored = mesh_store.put(digest, own, geometry, found)
        if digest not in store_files:  # the same content twice in one frame: one buffer
            warnings.extend(stored.warnings)
            store_files[digest] = buf.add_file(stored.uri, stored.byte_length, stored.views,
                                               stored.accessors)
        return stored.geometry.moved(store_files[digest])

    def build_geometry(into, obj, mesh, raw, n_slots, tangent_uvs, texture_without_uv, warn):
        """Convert the mesh and add its accessors to the Buffer `into`."""
        data = mesh_arrays(mesh, check_cancel, tangent_uvs, warn, obj.name, raw=raw,
                           phases=res.phases)
        if data is None:
            return None
        attrs = {"POSITION": into.add(data.positions, FLOAT, "VEC3", ARRAY_BUFFER, True),
                 "NORMAL": into.add(data.normals, FLOAT, "VEC3", ARRAY_BUFFER)}
        for i, (_, uv) in enumerate(data.uv_sets):
            attrs["TEXCOORD_%d" % i] = into.add(uv, FLOAT, "VEC2", ARRAY_BUFFER)
        if not data.uv_sets and texture_without_uv:
            # No UV map: Cycles reads UV (0, 0) everywhere; so does the fallback texture.
            uv = np.zeros((data.positions.shape[0], 2), dtype=np.float32)
            uv[:, 1] = 1.0
            attrs["TEXCOORD_0"] = into.add(uv, FLOAT, "VEC2", ARRAY_BUFFER)
        for i, (_, col) in enumerate(data.color_sets):
            attrs["COLOR_%d" % i] = into.add(col, FLOAT, "VEC4", ARRAY_BUFFER)
        if data.tangents is not None:
            attrs["TANGENT"] = into.add(data.tangents, FLOAT, "VEC4", ARRAY_BUFFER)
        extras = {"tesela_uv_names": [n for n, _ in data.uv_sets],
                  "tesela_color_names": [n for n, _ in data.color_sets]}
        if data.tangent_uv is not None:
            extras["tesela_tangent_uv"] = data.tangent_uv
        tri_mat = np.clip(data.tri_material, 0, n_slots - 1)
        indices = data.indices
        slots = []
        single = tri_mat.min() == tri_mat.max()
        for mi in ([tri_mat[0]] if single else np.unique(tri_mat)):
            sel = indices if single else indices[tri_mat == mi]
            slots.append((int(mi), into.add(sel.reshape(-1), UINT, "SCALAR", ELEMENT_ARRAY_BUFFER,
                                            True)))
        return Geometry(attrs, extras, slots, int(indices.shape[0]), data.texspace)

    def add_mesh(obj, geometry, mat_ids):
        """A glTF mesh of `geometry` with the object's materials: objects that share a mesh
        but not its materials get meshes naming the same accessors."""
        prims = [{"attributes": geometry.attributes, "indices": acc, "mode": 4,
                  "material": mat_ids[slot], "extras": geometry.extras}
                 for slot, acc in geometry.slots]
        doc["meshes"].append({"name": obj.name, "primitives": prims})
        return (len(doc["meshes"]) - 1, geometry.triangles, geometry.texspace)

    def object_mesh(obj):
        """(glTF mesh index, triangles, texture space) of a mesh-like object, or None when it
        has no triangles."""
        # The instances of one object (collections, Geometry Nodes) repeat its name and data:
        # they skip the material lookups.
        with res.phases("to_mesh"):  # a Subdivision Surface last in the stack runs here
            data = obj.data
        okey = (obj.name, data.as_pointer() if data is not None else 0)
        if okey not in object_cache:
            object_cache[okey] = shared_mesh(obj)
        return object_cache[okey]

    def shared_mesh(obj):
        mats = [s.material for s in obj.material_slots] or [None]
        infos = [mat_idx(m) for m in mats]
        mat_ids = tuple(i for i, _ in infos)
        tangent_uvs = frozenset().union(*(t for _, t in infos))
        texture_without_uv = any("baseColorTexture" in doc["materials"][i]["pbrMetallicRoughness"]
                                 for i in mat_ids)
        gkey = (geometry_key(obj), tangent_uvs, texture_without_uv, len(mats))
        key = (gkey, mat_ids)
        if key in mesh_cache:
            return mesh_cache[key]
        if gkey not in geometry_cache:
            if check_cancel is not None and check_cancel():
                raise ExportCancelled()
            geometry_cache[gkey] = None
            try:
                with res.phases("to_mesh"):
                    mesh = obj.to_mesh()
            except RuntimeError:
                mesh = None
            if mesh is not None:
                try:
                    geometry_cache[gkey] = add_geometry(obj, mesh, len(mats), tangent_uvs,
                                                        texture_without_uv)
                finally:
                    obj.to_mesh_clear()
        geometry = geometry_cache[gkey]
        mesh_cache[key] = None if geometry is None else add_mesh(obj, geometry, mat_ids)
        return mesh_cache[key]

    skipped_types = set()
    adaptive_reported = set()
    hair_reported = set()
    linking = LightLinking(depsgraph.objects)
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
        if otype in MESHLIKE and obj.name not in hair_reported:
            hair = _rendered_hair(obj)
            if hair:
                hair_reported.add(obj.name)
                mats = slot_materials([s.material for s in obj.material_slots])
                to_object = np.linalg.inv(matrix(inst.matrix_world))
                for psys in obj.particle_systems:
                    if psys.name not in hair:
                        continue
                    ext = particle_hair_extension(obj, psys, to_object, mats, buf,
                                                  depsgraph.mode == "RENDER")
                    if ext is None:
                        continue
                    used_ext.add("TESELA_curves")
                    linked_node({"name": "%s %s" % (obj.name, psys.name),
                                 "matrix": gltf_matrix(matrix(inst.matrix_world)),
                                 "extensions": {"TESELA_curves": ext},
                                 "extras": {"tesela_object": object_extras(
                                     inst, obj, depsgraph.view_layer, frame)}}, obj, inst)
        if otype in MESHLIKE and not compat.row_is_geometry(obj):
            continue
        if otype in MESHLIKE and not getattr(inst, "show_self", True):
            # A particle system's emitter with Show Emitter off for this mode: only its
            # particles render (as Cycles reads the instance's show_self).
            continue
        if otype in MESHLIKE:
            if obj.name not in adaptive_reported and compat.adaptive_subdivision(obj, scene):
                adaptive_reported.add(obj.name)
                warnings.append("object '%s': adaptive subdivision is not rendered; the mesh "
                                "renders as Blender evaluates it, without Cycles' dicing"
                                % obj.name)
            cached = object_mesh(obj)
            if cached is None:
                continue
            mi, ntri, texspace = cached
            res.triangles += ntri
            extras = {"tesela_object": tesela_object(inst, obj)}
            if texspace is not None:
                extras["tesela_texspace"] = {"location": texspace[0], "size": texspace[1]}
            node = {"name": obj.name, "mesh": mi,
                    "matrix": gltf_matrix(matrix(inst.matrix_world)), "extras": extras}
            keys = motion.node_extension(inst) if motion is not None else None
            if keys is not None:
                node["extensions"] = {"TESELA_motion": keys}
                used_ext.add("TESELA_motion")
            mesh_nodes.setdefault(mi, []).append(len(doc["nodes"]))
            linked_node(node, obj, inst)
        elif otype == "CURVES":
            if motion is not None and motion.moves(inst):
                warnings.append("curves '%s' move over the shutter: their motion blur is not "
                                "rendered; they render at the shutter's centre" % obj.name)
            slots = [s.material for s in obj.material_slots] or list(obj.data.materials)
            ext = curves_extension(obj.data, slot_materials(slots), buf)
            if ext is not None:
                used_ext.add("TESELA_curves")
                linked_node({"name": obj.name, "matrix": gltf_matrix(matrix(inst.matrix_world)),
                             "extensions": {"TESELA_curves": ext},
                             "extras": {"tesela_object": tesela_object(inst, obj)}}, obj, inst)
        elif otype == "POINTCLOUD":
            if motion is not None and motion.moves(inst):
                warnings.append("points '%s' move over the shutter: their motion blur is not "
                                "rendered; they render at the shutter's centre" % obj.name)
            slots = [s.material for s in obj.material_slots] or list(obj.data.materials)
            first = slot_materials(slots[:1])
            ext = points_extension(obj.data, first[0] if first else None,
                                   reads(obj)["GEOMETRY"], buf)
            if ext is not None:
                used_ext.add("TESELA_points")
                linked_node({"name": obj.name, "matrix": gltf_matrix(matrix(inst.matrix_world)),
                             "extensions": {"TESELA_points": ext},
                             "extras": {"tesela_object": tesela_object(inst, obj)}}, obj, inst)
        elif otype in ("VOLUME", "GPENCIL", "GREASEPENCIL"):
            if otype not in skipped_types:
                skipped_types.add(otype)
                warnings.append("%s objects are not supported; '%s' (and any others) left out"
                                % (otype.lower(), obj.name))
        elif otype == "LIGHT" and compat.light_is_portal(obj.data):
            # A portal only guides Cycles' sampling of the world through a window: it emits
            # nothing, and Tesela samples the world without it.
            warnings.append("light '%s' is a portal: left out (Cycles uses portals only to "
                            "sample the world; Tesela samples it without them)" % obj.name)
        elif otype == "LIGHT":
            if motion is not None and motion.moves(inst):
                warnings.append("light '%s' moves over the shutter: lights are not motion "
                                "blurred; it shines from where it is at the shutter's centre"
                                % obj.name)
            ext, khr = convert_light(obj.data, obj, matrix(inst.matrix_world), warnings,
                                     images)
            node = {"name": obj.name, "matrix": gltf_matrix(matrix(inst.matrix_world)),
                    "extensions": {"TESELA_light": ext}}
            used_ext.add("TESELA_light")
            if khr is not None:
                khr["name"] = obj.data.name
                khr_lights.append(khr)
                node["extensions"]["KHR_lights_punctual"] = {"light": len(khr_lights) - 1}
                used_ext.add("KHR_lights_punctual")
            link = linking.extension(obj)
            if link is not None:
                node["extensions"]["TESELA_light_linking"] = link
                used_ext.add("TESELA_light_linking")
            add_node(node)

    res.instanced_nodes = collapse(doc, root_nodes, buf, mesh_nodes, used_ext)

    if motion is not None:
        warnings.extend(motion.warnings)
    elif getattr(scene.render, "use_motion_blur", False):
        # Only a render samples the shutter (it needs the engine to change frames).
        warnings.append("motion blur is not rendered in this export (only renders sample the "
                        "shutter); objects are exported at the frame's instant")
    cam = camera if camera is not None else scene.camera
    if cam is not None and cam.type == "CAMERA":
        aspect = pixel_aspect(scene.render)
        doc["cameras"].append(dict(camera_fields(cam.data, width, height, aspect),
                                   name=cam.data.name))
        cam_node = {"name": cam.name, "camera": 0, "matrix": gltf_matrix(camera_matrix(cam)),
                    "extensions": {"TESELA_camera": camera_extension(cam, warnings, aspect)}}
        keys = motion.camera_extension() if motion is not None else None
        if keys is not None:
            cam_node["extensions"]["TESELA_motion"] = keys
            used_ext.add("TESELA_motion")
        add_node(cam_node)
        used_ext.add("TESELA_camera")
        res.has_camera = True

    world = convert_world(scene.world, warnings, images)
    ext_root = {"TESELA_world": world}
    used_ext.add("TESELA_world")
    if render_settings is not None:
        transparent = bool(getattr(scene.render, "film_transparent", False))
        ext_root["TESELA_render"] = dict(render_settings, film_transparent=transparent)
        glass = compat.film_transparent_glass(scene) if transparent else None
        if glass is not None:
            # Written only when on: scenes without it keep their bytes.
            ext_root["TESELA_render"].update(film_transparent_glass=True,
                                             film_transparent_roughness=glass)
        mist = getattr(scene.world, "mist_settings", None) if scene.world is not None else None
        if mist is not None:
            falloff = {"QUADRATIC": 2.0, "LINEAR": 1.0, "INVERSE_QUADRATIC": 0.5}
            ext_root["TESELA_render"]["mist"] = {
                "start": float(mist.start), "depth": float(mist.depth),
                "falloff": falloff.get(mist.falloff, 2.0)}
        used_ext.add("TESELA_render")
    if khr_lights:
        ext_root["KHR_lights_punctual"] = {"lights": khr_lights}
    if images.images:
        ext_root["TESELA_images"] = {"images": images.images}
        used_ext.add("TESELA_images")
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

    t_write = time.perf_counter()
    base = os.path.splitext(os.path.basename(filepath))[0]
    bin_name = base + ".bin"
    bin_path = os.path.join(os.path.dirname(os.path.abspath(filepath)), bin_name)
    from urllib.parse import quote
    buffers = buf.gltf_buffers(quote(bin_name))
    if buffers is not None:
        doc["buffers"] = buffers
        doc["bufferViews"] = buf.views
        doc["accessors"] = buf.accessors
    if buf.length:
        with open(bin_path, "wb") as f:
            for chunk in buf.chunks:
                f.write(chunk)
        res.bin_path = bin_path
    doc["extensionsUsed"] = sorted(used_ext)
    with open(filepath, "w", encoding="utf-8") as f:
        json.dump(doc, f, ensure_ascii=False, separators=(",", ":"))
    res.gltf_path = filepath
    res.phases.add("write", time.perf_counter() - t_write)
    return res


def render_size(render):
    """Final render resolution (percentage applied), as Blender computes it."""
    pct = render.resolution_percentage
    return (max(1, int(render.resolution_x * pct / 100)),
            max(1, int(render.resolution_y * pct / 100)))


def _f32_trunc(fraction, size):
    """trunc(fraction * size) with the product rounded to single precision first (the double
    product of a float32 and a pixel count is exact, so this is the float32 product)."""
    return int(struct.unpack("f", struct.pack("f", fraction * size))[0])


def border_region(render, width, height):
    """The border as (x, y, w, h), top-left origin, or None for the full frame.

    Blender's render result for a border spans pixels trunc(min * size) to trunc(max * size)
    (Blender 5.0: a border of 0.2-0.6 on 64 pixels is 26 wide, not trunc(0.4 * 64) = 25),
    the products taken in single precision as Blender takes them (0.95 * 80 is 76, not the
    75.99999 of double precision).
    """
    if not render.use_border:
        return None
    bx0, bx1 = sorted((render.border_min_x, render.border_max_x))
    by0, by1 = sorted((render.border_min_y, render.border_max_y))
    bx0, by0 = max(0.0, bx0), max(0.0, by0)
    bx1, by1 = min(1.0, bx1), min(1.0, by1)
    xmin = _f32_trunc(bx0, width)
    ymin = _f32_trunc(by0, height)
    w = _f32_trunc(bx1, width) - xmin
    h = _f32_trunc(by1, height) - ymin
    w = max(1, min(w, width - xmin))
    h = max(1, min(h, height - ymin))
    if (xmin, ymin, w, h) == (0, 0, width, height):
        return None
    return (xmin, height - ymin - h, w, h)
