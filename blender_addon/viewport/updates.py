# SPDX-License-Identifier: MIT
"""Depsgraph updates -> the smallest session commands (docs/session.md).

`SceneIndex` remembers what the last full export gave the session (node names, which objects use
which light, which materials and world need images); `translate` turns one view_update's
`depsgraph.updates`, and the objects now present, into commands, or asks for a full `load` when
the change cannot be expressed as one (an object added, an instancer moved, a texture edited)."""

import bpy

from .. import compat, export
from ..export.common import gltf_matrix, matrix
from ..export.mesh import MESHLIKE

LOAD = "load"
EXPORTED_TYPES = set(MESHLIKE) | {"LIGHT"}


def _original(idblock):
    return getattr(idblock, "original", idblock) or idblock


class SceneIndex:
    """What the session holds after a full export of `depsgraph` into the glTF `doc`."""

    def __init__(self, depsgraph, doc):
        counts = {}
        self.instanced = set()  # node names that stand for several placements
        for node in doc.get("nodes", []):
            name = node.get("name")
            counts[name] = counts.get(name, 0) + 1
            if "EXT_mesh_gpu_instancing" in node.get("extensions", {}):
                self.instanced.add(name)
        self.instanced |= {n for n, c in counts.items() if c > 1}
        self.objects = {}        # object name -> original object pointer (identity)
        self.instancers = set()  # objects whose instances the export placed
        self.light_users = {}    # light datablock name -> object names
        self.ray_visibility = {}  # object name -> its Ray Visibility flags as exported
        for inst in depsgraph.object_instances:
            if inst.is_instance:
                par = _original(inst.parent)
                if par is not None:
                    self.instancers.add(par.name)
                continue
            obj = inst.object
            if obj.type not in EXPORTED_TYPES:
                continue
            self.objects[obj.name] = _original(obj).as_pointer()
            self.ray_visibility[obj.name] = ray_visibility_key(obj)
            if obj.type == "LIGHT":
                self.light_users.setdefault(obj.data.name, []).append(obj.name)
        self.visible = {name: True for name in self.objects}
        scene = depsgraph.scene
        self.world = scene.world.name if scene.world is not None else None


def ray_visibility_key(obj):
    """An object's Ray Visibility flags, comparable between updates."""
    return tuple(sorted(compat.ray_visibility(obj).items()))


def present_objects(depsgraph):
    """{object name: original pointer} of the exportable objects the depsgraph now draws."""
    out = {}
    for inst in depsgraph.object_instances:
        if inst.is_instance:
            continue
        obj = inst.object
        if obj.type in EXPORTED_TYPES:
            out[obj.name] = _original(obj).as_pointer()
    return out


class Translation:
    """The result of `translate`: `commands` [(cmd, fields)], or `load` True (send a full load
    instead), and `warnings` from the exporters."""

    def __init__(self):
        self.commands = []
        self.load = False
        self.reason = ""
        self.warnings = []

    def need_load(self, reason):
        if not self.load:
            self.load, self.reason = True, reason


def _material_command(mat, out, scratch_dir):
    """The material's JSON, or None when it needs images (a new load)."""
    warnings = out.warnings
    buf = export.Buffer()
    textures = export.Textures(scratch_dir, "material", warnings)
    report = export.MaterialReport(warnings, {})
    images = export.ImageTable(buf, report)
    exported = export.export_material(mat, warnings, textures, images, report)
    if images.images or textures.images:
        return None
    return exported.gltf


def _world_command(world, out):
    warnings = out.warnings
    buf = export.Buffer()
    images = export.ImageTable(buf, export.MaterialReport(warnings, {}))
    ext = export.convert_world(world, warnings, images)
    if images.images:
        return None
    return ext


def light_fields(obj, warnings):
    mw = matrix(obj.matrix_world)
    images = export.ImageTable(export.Buffer(), export.MaterialReport(warnings, {}))
    ext, _ = export.convert_light(obj.data, obj, mw, warnings, images)
    if images.images:
        # A light command carries no pixels: a tree reading an image renders its unlinked
        # values (the renderer would not evaluate an image on a light anyway).
        ext.pop("graph", None)
        warnings.extend(ext.pop("node_warnings", []))
    return {"node": obj.name, "light": ext, "matrix": gltf_matrix(mw)}


def translate(depsgraph, index, write_mesh, scratch_dir):
    """Commands for the updates of `depsgraph` against `index` (updated in place: visibility).
    write_mesh(obj) exports one object's mesh and returns the file's path; scratch_dir takes
    the fallback textures a material export may write."""
    out = Translation()
    lights, materials, meshes, moved = {}, {}, {}, {}
    world_changed = False
    updates = list(depsgraph.updates)
    # Adding, deleting, hiding or showing an object updates a collection or the scene; other
    # edits leave the set of objects as it was, and walking every instance can be skipped.
    structural = any(isinstance(u.id, (bpy.types.Collection, bpy.types.Scene)) for u in updates)
    if structural or any(isinstance(u.id, bpy.types.Object) and u.id.name not in index.objects
                         and u.id.type in EXPORTED_TYPES for u in updates):
        present = present_objects(depsgraph)
    else:
        present = {name: ptr for name, ptr in index.objects.items() if index.visible[name]}
    for name, ptr in present.items():
        if index.objects.get(name) != ptr:
            out.need_load("object '%s' added" % name)
            return out
    for u in updates:
        idb = u.id
        if isinstance(idb, bpy.types.Object):
            name = idb.name
            if idb.type not in EXPORTED_TYPES and name not in index.instancers:
                continue
            if name in index.instancers and (u.is_updated_transform or u.is_updated_geometry):
                out.need_load("instancer '%s' changed" % name)
                continue
            if name not in present:
                continue  # hidden or deleted: only its visibility changes
            if name in index.instanced:
                if u.is_updated_transform or u.is_updated_geometry:
                    out.need_load("instanced object '%s' changed" % name)
                continue
            vis = ray_visibility_key(idb)
            if vis != index.ray_visibility.get(name, vis):
                index.ray_visibility[name] = vis
                if idb.type == "LIGHT":
                    lights[name] = idb
                else:
                    out.need_load("object '%s' ray visibility changed" % name)
                    continue
            # Hiding and showing an object re-evaluates it: that is no new geometry.
            if u.is_updated_geometry and index.visible[name]:
                if idb.type == "LIGHT":
                    lights[name] = idb
                else:
                    meshes[name] = idb
            if u.is_updated_transform:
                moved[name] = idb
        elif isinstance(idb, bpy.types.Material):
            materials[idb.name] = idb
        elif isinstance(idb, bpy.types.Light):
            for user in index.light_users.get(idb.name, ()):
                obj = depsgraph.objects.get(user)
                if obj is not None:
                    lights[user] = obj
        elif isinstance(idb, bpy.types.World):
            world_changed = True
        elif isinstance(idb, bpy.types.Scene):
            world = idb.world.name if idb.world is not None else None
            if world != index.world:
                index.world = world
                world_changed = True

    if out.load:
        return out

    cmds = out.commands
    for name, obj in meshes.items():
        cmds.append(("mesh", {"name": name, "path": write_mesh(obj)}))
    for name, obj in moved.items():
        if name not in lights:
            cmds.append(("transform", {"node": name, "matrix": gltf_matrix(matrix(obj.matrix_world))}))
    for name, obj in lights.items():
        cmds.append(("light", light_fields(obj, out.warnings)))
    for name, mat in materials.items():
        gltf = _material_command(mat, out, scratch_dir)
        if gltf is None:
            out.need_load("material '%s' uses images" % name)
            return out
        cmds.append(("material", {"name": name, "material": gltf}))
    if world_changed:
        world = depsgraph.scene.world
        ext = _world_command(world, out)
        if ext is None:
            out.need_load("the world uses images")
            return out
        cmds.append(("world", {"world": ext}))
    for name in index.objects:
        shown = name in present
        if shown != index.visible[name]:
            index.visible[name] = shown
            cmds.append(("visibility", {"node": name, "visible": shown}))
    return out
