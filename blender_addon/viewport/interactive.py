# SPDX-License-Identifier: MIT
"""Rendered viewport shading: one `tesela session` per viewport engine, fed by view_update
(scene changes -> commands) and view_draw (view changes -> `view`; the newest image drawn).

The UI thread never waits for the renderer: commands are queued to the client's writer thread,
images arrive through its reader thread, and a timer on the main thread asks Blender to redraw
when a new image or message is there."""

import json
import os
import shutil
import weakref

import bpy

from .. import export, preferences
from ..process import make_tmpdir, sweep_stale_tmpdirs
from ..settings import SceneSettings
from . import updates
from .display import Display, draw_messages
from .session_client import SessionClient
from .view_camera import view_border, view_camera

REDRAW_POLL_SECONDS = 0.03
MAX_ERRORS_SHOWN = 3


def render_seed(settings, frame):
    seed = int(settings.seed)
    if getattr(settings, "use_animated_seed", False):
        seed += int(frame)
    return max(seed, 0)


def session_settings(scene, pixel_size):
    """The `settings` command's fields: the viewport's sampling (preview_*) and the scene's
    light paths and film, as F12 passes them to `tesela render`."""
    s = SceneSettings(scene)
    return {"samples": int(s.preview_samples),
            "start_resolution": int(s.preview_start_resolution),
            "pixel_size": int(pixel_size),
            "denoise": bool(s.use_preview_denoising),
            "seed": render_seed(s, scene.frame_current),
            "max_depth": int(s.max_depth), "integrator": s.integrator,
            "diffuse_bounces": int(s.diffuse_bounces), "glossy_bounces": int(s.glossy_bounces),
            "transmission_bounces": int(s.transmission_bounces),
            "volume_bounces": int(s.volume_bounces),
            "transparent_bounces": int(s.transparent_max_bounces),
            "clamp_direct": float(s.sample_clamp_direct),
            "clamp_indirect": float(s.sample_clamp_indirect),
            "caustics_reflective": bool(s.caustics_reflective),
            "caustics_refractive": bool(s.caustics_refractive),
            "blur_glossy": float(s.blur_glossy),
            "filter": s.pixel_filter_type.lower().replace("_", "-"),
            "filter_width": float(s.filter_width),
            "film_transparent": bool(scene.render.film_transparent)}


def view_command(context, scene, width, height):
    """(`view` fields, key) of the region in `context`; fields None for an empty border."""
    space, rv3d = context.space_data, context.region_data
    cam = view_camera(scene, space, rv3d, width, height)
    border = view_border(scene, space, cam, width, height)
    fields = {"width": width, "height": height, "camera": cam.command_camera()}
    if border is not None:
        if border[2] == 0 or border[3] == 0:
            return None, ("empty", width, height)
        fields["border"] = border
    return fields, json.dumps(fields, sort_keys=True)


def _remove_gltf(path):
    """A .gltf and the .bin the exporter wrote beside it."""
    for p in (path, os.path.splitext(path)[0] + ".bin"):
        try:
            os.remove(p)
        except OSError:
            pass


class ViewportSession:
    """Everything one Rendered viewport owns: the client, its temp folder, what was sent."""

    def __init__(self, engine):
        self._engine = weakref.ref(engine)
        self.client = None
        self.tmpdir = None
        self.index = None
        self.view_key = None
        self.view_fields = None
        self.settings = None
        self.display = Display()
        self.message = None          # why there is no session (shown until the next change)
        self.errors = []             # the latest ERROR frames, newest last
        self.sent = []               # (cmd, fields) of every command, for tests and debugging
        self.record = False
        self._files = 0
        self._timer = None
        self._depsgraph = None
        self._mesh_files = {}        # object name -> (id, path) of its newest `mesh` command
        self._superseded = set()     # ids of commands whose errors no longer matter

    # -- life ---------------------------------------------------------------------------------

    def close(self):
        """End the session process, drop the texture, remove the temp folder. Idempotent."""
        if self.client is not None:
            self.client.close()
            self.client = None
        if self.tmpdir is not None:
            shutil.rmtree(self.tmpdir, ignore_errors=True)
            self.tmpdir = None
        self.display.free()
        self.index = None
        self._mesh_files.clear()
        self._superseded.clear()  # command ids start again with the next session

    def _send(self, cmd, **fields):
        if self.record:
            self.sent.append((cmd, fields))
        return self.client.send(cmd, **fields)

    def _mesh_sent(self, name, command_id, path):
        """Only an object's newest mesh file is kept: an older one the session has not read
        yet can only fail, and its ERROR is then ignored (the newer mesh follows it)."""
        old = self._mesh_files.pop(name, None)
        if old is not None:
            self._superseded.add(old[0])
            _remove_gltf(old[1])
        self._mesh_files[name] = (command_id, path)

    def _start(self, depsgraph):
        """A new session with the whole scene; False (and `message`) when it cannot start."""
        self.close()
        self.view_key = None
        self.settings = None
        self.errors = []
        binary, tried = preferences.find_renderer()
        if binary is None:
            self.message = preferences.not_found_message(tried)
            return False
        sweep_stale_tmpdirs()
        self.tmpdir = make_tmpdir()
        threads = int(depsgraph.scene.tesela.threads)
        self.client = SessionClient(binary, threads=threads, cwd=self.tmpdir)
        try:
            self.client.start()
        except OSError as exc:
            self.client = None
            self.message = "cannot start the renderer %s: %s" % (binary, exc)
            return False
        self.message = None
        self._load(depsgraph)
        self._watch()
        return True

    def _path(self, stem):
        self._files += 1
        return os.path.join(self.tmpdir, "%s-%d.gltf" % (stem, self._files))

    def _load(self, depsgraph):
        """Export the whole scene as F12 does and send `load` (the files of earlier loads and
        meshes are no longer read by the session once this one is queued after them)."""
        self._superseded.update(cid for cid, _ in self._mesh_files.values())
        self._mesh_files.clear()
        for name in os.listdir(self.tmpdir):
            path = os.path.join(self.tmpdir, name)
            if os.path.isdir(path):
                shutil.rmtree(path, ignore_errors=True)
            else:
                os.remove(path)
        scene = depsgraph.scene
        width, height = export.render_size(scene.render)
        path = self._path("scene")
        res = export.write_gltf(depsgraph, path, width=width, height=height, camera=scene.camera)
        for w in res.warnings[:10]:
            print("Tesela: " + w)
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
        self.index = updates.SceneIndex(depsgraph, doc)
        self._send("load", path=path)

    def _write_mesh(self, obj):
        """One object's mesh (its materials by name) for the `mesh` command."""
        path = self._path("mesh")
        export.write_gltf(self._depsgraph, path, width=16, height=16, selection={obj.name})
        return path

    def _watch(self):
        """A main-thread timer that turns the reader's news into engine.tag_redraw()."""
        if self._timer is not None:
            return
        seen = {"serial": -1, "errors": 0, "dead": None}
        me = weakref.ref(self)

        def poll():
            session = me()
            engine = session._engine() if session is not None else None
            if engine is None or session.client is None:
                if session is not None:
                    session._timer = None
                return None
            c = session.client
            with c.lock:
                news = (c.serial, len(c.errors), c.dead)
            if news != (seen["serial"], seen["errors"], seen["dead"]):
                seen["serial"], seen["errors"], seen["dead"] = news
                try:
                    engine.tag_redraw()
                except ReferenceError:
                    session._timer = None
                    return None
            return REDRAW_POLL_SECONDS

        self._timer = poll
        bpy.app.timers.register(poll, first_interval=REDRAW_POLL_SECONDS)

    # -- view_update ----------------------------------------------------------------------------

    def update(self, engine, context, depsgraph):
        """Blender's view_update: the first call (or the first after the session died) sends
        the whole scene, later ones the smallest commands for what changed."""
        self._depsgraph = depsgraph
        self.errors = []
        if self.client is None or not self.client.alive():
            if not self._start(depsgraph):
                return
        else:
            tr = updates.translate(depsgraph, self.index, self._write_mesh, self.tmpdir)
            for w in tr.warnings[:5]:
                print("Tesela: " + w)
            if tr.load:
                self._load(depsgraph)
            else:
                for cmd, fields in tr.commands:
                    cid = self._send(cmd, **fields)
                    if cmd == "mesh":
                        self._mesh_sent(fields["name"], cid, fields["path"])
        self._send_settings(engine, depsgraph.scene)
        self._send_view(context, depsgraph.scene)

    def _send_settings(self, engine, scene):
        settings = session_settings(scene, engine.get_preview_pixel_size(scene))
        if settings != self.settings:
            self.settings = settings
            self._send("settings", **settings)

    def _send_view(self, context, scene):
        region = context.region
        fields, key = view_command(context, scene, region.width, region.height)
        if key == self.view_key:
            return False
        self.view_key = key
        self.view_fields = fields
        if fields is not None:
            self._send("view", **fields)
        return True

    def take_errors(self):
        """The texts of the client's new ERROR frames that still matter."""
        return [e.text() for e in self.client.take_errors() if e.id not in self._superseded]

    # -- view_draw ------------------------------------------------------------------------------

    def draw(self, engine, context, depsgraph):
        """Blender's view_draw: a changed view sends `view` (a dead session restarts on it),
        then the newest image of this view is drawn, and any message over it."""
        self._depsgraph = depsgraph
        region = context.region
        scene = depsgraph.scene
        if self.client is not None and self.client.alive():
            self._send_view(context, scene)
        else:
            _, key = view_command(context, scene, region.width, region.height)
            if key != self.view_key and self._start(depsgraph):
                self._send_settings(engine, scene)
                self._send_view(context, scene)
            self.view_key = key
        client = self.client
        image = serial = dead = None
        if client is not None:
            with client.lock:
                image, serial, dead = client.image, client.serial, client.dead
            self.errors = (self.errors + self.take_errors())[-MAX_ERRORS_SHOWN:]
        if (image is not None and self.view_fields is not None
                and (image.view_width, image.view_height) == (region.width, region.height)):
            self.display.update(image, serial)
            self.display.draw(engine, scene, region.height)
        lines = []
        if dead is not None or self.message is not None:
            lines.append("Tesela: " + (dead or self.message))
        lines += ["Tesela: renderer error: " + e for e in self.errors]
        if lines:
            draw_messages(lines, region.width, region.height)
            engine.update_stats("", lines[0])
        elif image is not None:
            target = self.settings["samples"] if self.settings else 0
            engine.update_stats("", "Tesela | Sample %d/%s%s" % (
                image.samples, target if target else "∞", " | Denoised" if image.denoised else ""))
