# SPDX-License-Identifier: MIT
"""scene.tesela: render settings, as Cycles keeps scene.cycles."""

import bpy
from bpy.props import EnumProperty, IntProperty, PointerProperty

INTEGRATORS = [
    ("path_mis", "Path (MIS)", "Unidirectional path tracing with multiple importance sampling"),
    ("path_mats", "Path (BSDF sampling)", "Path tracing, BSDF sampling only"),
    ("direct_mis", "Direct (MIS)", "Direct lighting with multiple importance sampling"),
    ("direct_ems", "Direct (light sampling)", "Direct lighting, emitter sampling only"),
    ("direct_mats", "Direct (BSDF sampling)", "Direct lighting, BSDF sampling only"),
    ("normals", "Normals", "Debug: shading normals"),
    ("albedo", "Albedo", "Debug: surface albedo"),
]


class TeselaSceneSettings(bpy.types.PropertyGroup):
    integrator: EnumProperty(name="Integrator", items=INTEGRATORS, default="path_mis",
                             description="Light transport algorithm")
    samples: IntProperty(name="Samples", default=64, min=1, max=1 << 20, soft_max=4096,
                         description="Samples per pixel")
    max_depth: IntProperty(name="Max Depth", default=14, min=1, max=1024,
                           description="Maximum number of path vertices (Cycles' max bounces + 2)")
    seed: IntProperty(name="Seed", default=0, min=0, description="Random seed")
    threads: IntProperty(name="Threads", default=0, min=0, max=1024,
                         description="Render threads (0: all cores)")


def register():
    bpy.utils.register_class(TeselaSceneSettings)
    bpy.types.Scene.tesela = PointerProperty(type=TeselaSceneSettings)


def unregister():
    if hasattr(bpy.types.Scene, "tesela"):
        del bpy.types.Scene.tesela
    bpy.utils.unregister_class(TeselaSceneSettings)
