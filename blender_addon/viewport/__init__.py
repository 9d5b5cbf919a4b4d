# SPDX-License-Identifier: MIT
"""Rendered viewport shading with a live `tesela session` (docs/session.md).

session_protocol and session_client have no bpy (tests drive them alone); view_camera turns the
viewport's view into a camera, updates turns depsgraph updates into commands, display draws,
and interactive ties them to the engine's view_update / view_draw."""

if "interactive" in locals():  # reload support (F3 > Reload Scripts): submodules first
    import importlib
    for _m in (session_protocol, session_client, view_camera, updates, display,  # noqa: F821
               interactive):  # noqa: F821
        importlib.reload(_m)

import weakref  # noqa: E402

import bpy  # noqa: E402

from . import session_protocol, session_client, view_camera, updates, display  # noqa: E402,F401
from . import interactive  # noqa: E402

_SESSIONS = weakref.WeakSet()


def new_session(engine):
    """The ViewportSession of a viewport engine; every one ends when another file loads."""
    vs = interactive.ViewportSession(engine)
    _SESSIONS.add(vs)
    return vs


def close_all():
    for vs in list(_SESSIONS):
        vs.close()
    session_client.close_all()


@bpy.app.handlers.persistent
def _on_load_pre(*_args):
    close_all()


def register():
    if _on_load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(_on_load_pre)


def unregister():
    if _on_load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_on_load_pre)
    close_all()
