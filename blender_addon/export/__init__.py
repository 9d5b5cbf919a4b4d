# SPDX-License-Identifier: MIT
"""Tesela's own glTF 2.0 writer, fed by an evaluated depsgraph.

Works in any thread (it never touches bpy.context), reads mesh data with foreach_get into numpy,
and writes one .gltf plus one .bin. Blender's Z-up world becomes glTF's Y-up through the node
matrices (mesh data stays in object space). Conventions: docs/extensions.md.

One module per kind: mesh, material (fallback + TESELA_material_graph), images (TESELA_images
and the fallback PNGs), light, world, camera; gltf assembles the document, buffer holds the .bin.
"""

if "gltf" in locals():  # reload support (F3 > Reload Scripts): submodules first
    import importlib
    for _m in (common, buffer, images, material, mesh, mesh_store, light, camera, world,  # noqa: F821
               motion, gltf):  # noqa: F821
        importlib.reload(_m)

from . import common, buffer, images, material, mesh, mesh_store, light, camera, world  # noqa: E402,F401
from . import motion  # noqa: E402,F401
from . import gltf  # noqa: E402,F401
from .buffer import ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER, FLOAT, UINT, Buffer  # noqa: E402,F401
from .camera import camera_extension, camera_fields, camera_matrix  # noqa: E402,F401
from .common import ExportCancelled, color3, finite, gltf_matrix, matrix  # noqa: E402,F401
from .gltf import ExportResult, border_region, render_size, write_gltf  # noqa: E402,F401
from .images import ImageTable, Textures, write_png  # noqa: E402,F401
from .light import convert_light  # noqa: E402,F401
from .material import (MaterialGraph, MaterialReport,  # noqa: E402,F401
                       convert_material, export_material)
from .mesh import MESHLIKE, mesh_arrays, object_extras, random_id, read_mesh  # noqa: E402,F401
from .mesh_store import MeshStore  # noqa: E402,F401
from .world import convert_world  # noqa: E402,F401
