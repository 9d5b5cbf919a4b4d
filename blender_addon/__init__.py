# SPDX-License-Identifier: MIT
"""Tesela: a physically based renderer as a Blender render engine."""

bl_info = {
    "name": "Tesela",
    "author": "Tesela developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > Tesela; File > Export > Tesela glTF",
    "description": "Physically based renderer (Rust) streaming tiles into Blender",
    "category": "Render",
}

if "bpy" in locals():  # reload support (F3 > Reload Scripts)
    import importlib
    for _m in (compat, protocol, process, report, export, properties, preferences,  # noqa: F821
               render_jobs, viewport, engine, ui):  # noqa: F821
        importlib.reload(_m)

import bpy  # noqa: E402

from . import compat, protocol, process, report, export, properties, preferences  # noqa: E402,F401
from . import render_jobs, viewport, engine, ui  # noqa: E402

_MODULES = (properties, preferences, render_jobs, viewport, engine, ui)


def register():
    for m in _MODULES:
        m.register()


def unregister():
    for m in reversed(_MODULES):
        m.unregister()
