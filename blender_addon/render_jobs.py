# SPDX-License-Identifier: MIT
"""The mesh store of the render job under way.

Blender makes a new RenderEngine for every frame of an animation (for -a and for
Render Animation alike, unless Persistent Data is on), so nothing an engine holds outlives its
frame. A job runs from the render_init handler (once, before its first frame) to
render_complete or render_cancel (once, after its last): the store lives exactly that long,
and its folder goes with it. Renders outside a job (previews, a job started before the add-on
was enabled) export without a store."""

import bpy

from .export.mesh_store import MeshStore
from .process import make_tmpdir


class RenderJob:
    """Whether a job is under way, and its store once a Tesela render asked for one (jobs of
    other engines make none)."""

    def __init__(self):
        self.running = False
        self.store = None

    def start(self):
        self.end()
        self.running = True

    def end(self):
        self.running = False
        if self.store is not None:
            self.store.close()
            self.store = None

    def current_store(self):
        if self.running and self.store is None:
            self.store = MeshStore(make_tmpdir())
        return self.store


_job = None  # the RenderJob while the add-on is registered


@bpy.app.handlers.persistent
def _render_init(*_args):
    if _job is not None:
        _job.start()


@bpy.app.handlers.persistent
def _render_end(*_args):
    if _job is not None:
        _job.end()


_HANDLERS = (("render_init", _render_init), ("render_complete", _render_end),
             ("render_cancel", _render_end))


def current_store():
    """The MeshStore of the job under way, or None."""
    return _job.current_store() if _job is not None else None


def register():
    global _job
    _job = RenderJob()
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if fn not in handlers:
            handlers.append(fn)


def unregister():
    global _job
    for name, fn in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        while fn in handlers:
            handlers.remove(fn)
    if _job is not None:
        _job.end()
    _job = None
