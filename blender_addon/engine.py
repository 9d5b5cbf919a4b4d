# SPDX-License-Identifier: MIT
"""The Tesela RenderEngine: export -> renderer subprocess -> tiles into the result."""

import os
import queue
import shutil
import subprocess
import time

import bpy
import numpy as np

from . import compat, export, passes, preferences, protocol, render_jobs, report, viewport
from .process import StderrTail, _describe_exit, make_tmpdir, stop_process, sweep_stale_tmpdirs
from .settings import SceneSettings

POLL_SECONDS = 0.03        # how often render() looks at the queue and test_break()
PUSH_SECONDS = 0.25        # how often the render result is refreshed


class RenderSession:
    """Everything one render owns: temp dir, process, threads. Never shared."""

    def __init__(self):
        self.tmpdir = None
        self.store = None  # the job's MeshStore when tmpdir is its folder
        self.proc = None
        self.reader = None
        self.stderr = None
        self.messages = queue.Queue()
        self.fallbacks = None  # report.FallbackReport once the scene is exported

    def start(self, args):
        self.proc = subprocess.Popen(args, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, bufsize=0, close_fds=True,
                                     cwd=self.tmpdir)
        self.stderr = StderrTail(self.proc.stderr)
        self.reader = protocol.start_reader(self.proc.stdout, self.messages.put)

    def close(self):
        """Stop the process and the threads, remove the temp dir. Idempotent."""
        code = None
        if self.proc is not None:
            code = stop_process(self.proc)
            if self.reader is not None:
                self.reader.join(timeout=2.0)
            if self.stderr is not None:
                self.stderr.thread.join(timeout=2.0)
            for pipe in (self.proc.stdout, self.proc.stderr):
                try:
                    if pipe is not None:
                        pipe.close()
                except OSError:
                    pass
        if self.store is not None:
            self.store.end_render()  # the folder and its meshes stay for the job's next frame
            self.store = None
        elif self.tmpdir is not None:
            shutil.rmtree(self.tmpdir, ignore_errors=True)
        self.tmpdir = None
        return code


def render_seed(settings, frame):
    """The seed of a frame: Cycles' use_animated_seed adds the frame number (a new noise
    pattern every frame of an animation)."""
    seed = int(settings.seed)
    if getattr(settings, "use_animated_seed", False):
        seed += int(frame)
    return max(seed, 0)


def renderer_args(binary, gltf, settings, width, height, region, pass_names=(), frame=0):
    args = [binary, "render", gltf, "--pipe", "--pipe-version", str(protocol.PROTOCOL_VERSION),
            "--integrator", settings.integrator,
            "--spp", str(settings.samples),
            "--max-depth", str(settings.max_depth),
            "--width", str(width), "--height", str(height),
            "--seed", str(render_seed(settings, frame))]
    if settings.threads > 0:
        args += ["--threads", str(settings.threads)]
    args += ["--tile-size", str(settings.tile_size)]
    if region is not None:
        args += ["--region"] + [str(v) for v in region]
    if pass_names:
        args += ["--passes", ",".join(pass_names)]
    if getattr(settings, "use_adaptive_sampling", False):
        args += ["--adaptive-threshold", repr(float(settings.adaptive_threshold)),
                 "--adaptive-min-samples", str(settings.adaptive_min_samples)]
    for option, prop in (("--diffuse-bounces", "diffuse_bounces"),
                         ("--glossy-bounces", "glossy_bounces"),
                         ("--transmission-bounces", "transmission_bounces"),
                         ("--volume-bounces", "volume_bounces"),
                         ("--transparent-bounces", "transparent_max_bounces")):
        if hasattr(settings, prop):
            args += [option, str(getattr(settings, prop))]
    for option, prop in (("--clamp-direct", "sample_clamp_direct"),
                         ("--clamp-indirect", "sample_clamp_indirect"),
                         ("--blur-glossy", "blur_glossy")):
        if getattr(settings, prop, 0.0) > 0.0:
            args += [option, repr(float(getattr(settings, prop)))]
    for option, prop in (("--no-caustics-reflective", "caustics_reflective"),
                         ("--no-caustics-refractive", "caustics_refractive")):
        if not getattr(settings, prop, True):
            args.append(option)
    filter_type = getattr(settings, "pixel_filter_type", "BOX")
    args += ["--filter", filter_type.lower().replace("_", "-"),
             "--filter-width", repr(float(getattr(settings, "filter_width", 1.0)))]
    if getattr(settings, "use_denoising", False):
        args += ["--denoise", "--denoise-prefilter", settings.denoising_prefilter.lower()]
    if getattr(settings, "time_limit", 0.0) > 0.0:
        args += ["--time-limit", repr(float(settings.time_limit))]
    return args


# Export warnings shown in Blender's reports, the rest in the console.
MAX_SHOWN_WARNINGS = 8

OLD_RENDERER = ("the renderer %s is older than this add-on: it does not speak pipe protocol "
                "version %d (install the renderer that came with the add-on)")


def timing_line(triangles, export_seconds, stats, result_seconds):
    """The render log's account of where the time went: the add-on's export, the renderer's
    scene load, BVH build, render and tile stream (from its DONE statistics; phases an older
    renderer does not report are left out), and the add-on's copies of the tiles into
    Blender's render result."""
    parts = ["%s triangles" % format(int(triangles), ","), "export %.2f s" % export_seconds]
    for key, name in (("load_seconds", "load"), ("bvh_seconds", "BVH"),
                      ("seconds", "render"), ("stream_seconds", "tile stream")):
        value = stats.get(key)
        if isinstance(value, (int, float)):
            parts.append("%s %.2f s" % (name, value))
    parts.append("result %.2f s" % result_seconds)
    return "Tesela: " + " | ".join(parts)


def format_time_left(elapsed, fraction):
    """'Remaining mm:ss' from the time so far and the fraction done (Cycles' stats wording)."""
    if fraction <= 0.0 or fraction >= 1.0:
        return "Time %s" % _mmss(elapsed)
    return "Time %s | Remaining %s" % (_mmss(elapsed), _mmss(elapsed * (1.0 - fraction) / fraction))


def _mmss(seconds):
    seconds = max(0, int(round(seconds)))
    return "%02d:%02d" % divmod(seconds, 60)


class progress_lines:
    """When to print a progress line: every `step` of the fraction done, and at the end."""

    def __init__(self, step=0.05):
        self.step = step
        self.next = 0.0

    def due(self, fraction):
        if fraction + 1e-9 < self.next:
            return False
        self.next = (int(fraction / self.step + 1e-9) + 1) * self.step
        return True


PREVIEW_SAMPLES_MAX = 64


class PreviewSettings:
    """scene.tesela for a material, light or world preview (the Properties editor's sphere and
    the icons): the viewport's sample count, at most PREVIEW_SAMPLES_MAX, and no denoiser, so a
    preview stays a short render in Blender's preview job."""

    def __init__(self, settings):
        self._settings = settings

    def __getattr__(self, name):
        if name == "samples":
            wanted = int(self._settings.preview_samples) or PREVIEW_SAMPLES_MAX
            return max(1, min(wanted, PREVIEW_SAMPLES_MAX))
        if name == "use_denoising":
            return False
        return getattr(self._settings, name)


class TeselaRenderEngine(bpy.types.RenderEngine):
    bl_idname = "TESELA"
    bl_label = "Tesela"
    bl_use_preview = True
    bl_use_postprocess = True
    bl_use_shading_nodes_custom = False
    bl_use_eevee_viewport = True

    def __init__(self, *args, **kwargs):
        # Blender 4.4+ passes arguments here; older versions pass none.
        super().__init__(*args, **kwargs)
        self.viewport = None

    def __del__(self):
        # Blender frees a viewport's engine when Rendered shading ends, the area closes or the
        # engine changes: the session process ends with it.
        vs = getattr(self, "viewport", None)
        if vs is not None:
            vs.close()

    # -- viewport -----------------------------------------------------------------------------

    def view_update(self, context, depsgraph):
        if self.viewport is None:
            self.viewport = viewport.new_session(self)
        try:
            self.viewport.update(self, context, depsgraph)
        except Exception as exc:  # noqa: BLE001 - never take Blender down, always say why
            import traceback
            traceback.print_exc()
            self.viewport.message = "internal error in the add-on: %s: %s" % (
                type(exc).__name__, exc)

    def view_draw(self, context, depsgraph):
        if self.viewport is None:
            return
        try:
            self.viewport.draw(self, context, depsgraph)
        except Exception as exc:  # noqa: BLE001
            import traceback
            traceback.print_exc()
            self.viewport.message = "internal error in the add-on: %s: %s" % (
                type(exc).__name__, exc)

    # -- helpers --------------------------------------------------------------

    def should_stop(self):
        """Esc pressed (or Blender quitting). One place, so tests can simulate it."""
        return self.test_break()

    def _fail(self, message):
        message = "Tesela: " + message
        print(message)
        self.report({"ERROR"}, message)
        if hasattr(self, "error_set"):
            try:
                self.error_set(message)
            except (TypeError, RuntimeError):
                pass

    # -- passes -----------------------------------------------------------------

    def update_render_passes(self, scene=None, renderlayer=None):
        """Declares the passes Blender's compositor and render result will have."""
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        for _, bname, ids, kind in passes.enabled(renderlayer, SceneSettings(scene)):
            self.register_pass(scene, renderlayer, compat.pass_name(bname), len(ids), ids, kind)

    # -- render -----------------------------------------------------------------

    def render(self, depsgraph):
        scene = depsgraph.scene
        r = scene.render
        settings = SceneSettings(scene)
        if self.is_preview:
            settings = PreviewSettings(settings)
        width, height = export.render_size(r)
        region = export.border_region(r, width, height)
        _, _, rw, rh = region if region is not None else (0, 0, width, height)
        session = RenderSession()
        try:
            self._render(depsgraph, scene, settings, width, height, region, rw, rh, session)
        except Exception as exc:  # noqa: BLE001 - never take Blender down, always say why
            import traceback
            traceback.print_exc()
            self._fail("internal error in the add-on: %s: %s" % (type(exc).__name__, exc))
        finally:
            session.close()
            self._publish_fallbacks(scene, session)

    @staticmethod
    def _publish_fallbacks(scene, session):
        """This render's per-material fallbacks (add-on and renderer) replace the last ones."""
        fallbacks = session.fallbacks
        if fallbacks is None:
            return
        if session.stderr is not None:
            fallbacks.add_renderer_text(session.stderr.text(max_lines=1 << 20))
        report.publish(scene.name, fallbacks)

    def _render(self, depsgraph, scene, settings, width, height, region, rw, rh, session):
        self.update_stats("", "Tesela | Exporting scene")
        sweep_stale_tmpdirs()
        store = None if self.is_preview else render_jobs.current_store()
        if store is not None:
            store.begin_render(scene.frame_current)
            session.store, session.tmpdir = store, store.folder
        else:
            session.tmpdir = make_tmpdir()
        gltf = os.path.join(session.tmpdir, "scene.gltf")
        camera = getattr(self, "camera_override", None) or scene.camera
        if camera is None:
            self._fail("the scene has no camera (add one and make it the active camera)")
            return
        render_settings = {"width": width, "height": height, "spp": settings.samples,
                           "max_depth": settings.max_depth, "seed": settings.seed,
                           "integrator": settings.integrator}
        t0 = time.monotonic()
        try:
            # With motion blur, the scene is sampled over the shutter and exported at its
            # centre; the frame is restored when the export ends.
            with export.motion.sampled(self, depsgraph, camera) as motion:
                res = export.write_gltf(depsgraph, gltf, width=width, height=height,
                                        camera=camera, render_settings=render_settings,
                                        check_cancel=self.should_stop, mesh_store=store,
                                        motion=motion)
        except export.ExportCancelled:
            return
        if store is not None:
            print("Tesela: frame %d: meshes written %d, reused %d (export %.2f s)" % (
                scene.frame_current, store.written, store.reused, time.monotonic() - t0),
                flush=True)
        session.fallbacks = report.FallbackReport()
        session.fallbacks.add_addon_all(res.material_warnings)
        for w in res.warnings[:20]:
            print("Tesela: " + w)
        if len(res.warnings) > 20:
            print("Tesela: ... and %d more warnings" % (len(res.warnings) - 20))
        # What is left out or approximated besides materials (objects, lights, camera, world,
        # motion blur) is shown in Blender too; materials are summed up below.
        per_material = {t for texts in res.material_warnings.values() for t in texts}
        others = [w for w in res.warnings if w not in per_material]
        for w in others[:MAX_SHOWN_WARNINGS]:
            self.report({"WARNING"}, "Tesela: " + w)
        if len(others) > MAX_SHOWN_WARNINGS:
            self.report({"WARNING"}, "Tesela: ... and %d more (see the console)"
                        % (len(others) - MAX_SHOWN_WARNINGS))
        if res.material_warnings:
            self.report({"WARNING"}, "Tesela: %d material(s) could not be translated fully (see "
                        "Material Properties > Tesela)" % len(res.material_warnings))
        if self.should_stop():
            return
        t_export = time.monotonic() - t0
        phases = res.phases.summary()
        print("Tesela: export %.2f s%s" % (t_export, ": " + phases if phases else ""))

        binary, tried = preferences.find_renderer()
        if binary is None:
            self._fail(preferences.not_found_message(tried))
            return
        # Blender calls render() once per view layer; fill that layer.
        result = self.begin_result(0, 0, rw, rh, layer=depsgraph.view_layer.name)
        target = compat.combined_pass(result)
        if (result.resolution_x, result.resolution_y) != (rw, rh) and region is not None:
            # Blender rounded the border differently: follow the result it allocated,
            # keeping the border's lower-left corner.
            ymin = height - region[1] - region[3]
            rw, rh = result.resolution_x, result.resolution_y
            region = (region[0], height - ymin - rh, rw, rh)
        if len(target.rect) != rw * rh:
            self._fail("render result is %d pixels (%dx%d), expected %dx%d" % (
                len(target.rect), result.resolution_x, result.resolution_y, rw, rh))
            self.end_result(result)
            return
        # Full-frame mirror of the result, rows bottom to top (Blender's order).
        mirror = np.zeros((rh, rw, 4), dtype=np.float32)
        # The other passes: {Blender name: (render pass, mirror)}.
        pass_targets = {}
        pass_names = []
        for name, bname, ids, _ in passes.enabled(depsgraph.view_layer, settings):
            rp = compat.find_pass(result, compat.pass_name(bname))
            if rp is None or rp.channels != len(ids):
                self.report({"WARNING"}, "Tesela: the render result has no %s pass"
                            % compat.pass_name(bname))
                continue
            pass_names.append(name)
            pass_targets[bname] = (rp, np.zeros((rh, rw, len(ids)), dtype=np.float32))
        left_out = [compat.pass_name(n) for n in passes.unsupported(depsgraph.view_layer, settings)]
        if left_out:
            message = "Tesela does not render these passes yet (left empty): " + ", ".join(left_out)
            if not passes.splits_light(settings):
                message += " (the %s view has no light passes)" % settings.integrator
            print("Tesela: " + message)
            self.report({"WARNING"}, "Tesela: " + message)

        args = renderer_args(binary, gltf, settings, width, height, region, pass_names,
                             frame=scene.frame_current)
        try:
            session.start(args)
        except OSError as exc:
            self.end_result(result)
            self._fail("cannot start the renderer %s: %s" % (binary, exc))
            return

        hello = None
        done = None
        error = None
        error_from_renderer = False
        cancelled = False
        dirty = False
        tiles_done = 0
        tiles_total = 0
        spp_now = 0
        last_push = time.monotonic()
        t_start = last_push

        # Estimated cost of one refresh (~1 GB/s through foreach_set and update_result) until
        # measured: a 4K frame is refreshed every ~0.8 s, a small one every 0.25 s.
        push_cost = [rw * rh * 16 / 1e9]

        result_seconds = [0.0]  # copying tiles into the mirror and the result

        def push(final=False):
            t = time.monotonic()
            compat.pass_rect_set(target, mirror.reshape(-1))
            for rp, m in pass_targets.values():
                compat.pass_rect_set(rp, m.reshape(-1))
            if not final:  # end_result() publishes the final image itself
                self.update_result(result)
            push_cost[0] = time.monotonic() - t
            result_seconds[0] += push_cost[0]

        progress_dirty = False
        last_stats = 0.0
        elapsed = 0.0

        farm = progress_lines()

        def report_progress():
            frac = min(1.0, tiles_done / tiles_total) if tiles_total else 0.0
            if tiles_total:
                self.update_progress(frac)
            line = "Tesela | Sample %d/%d | Tile %d/%d | %s" % (
                spp_now, settings.samples, tiles_done, tiles_total,
                format_time_left(elapsed, frac))
            if farm.due(frac):
                # Background renders: one line per few percent, for farm log parsers.
                print("Tesela: %3d%% | %s" % (int(frac * 100), line[len("Tesela | "):]),
                      flush=True)
            if not bpy.app.background:
                self.update_stats("", line)

        end_deadline = None
        finished = False
        while not finished:
            if self.should_stop():
                cancelled = True
                break
            try:
                msg = session.messages.get(timeout=POLL_SECONDS)
            except queue.Empty:
                # After DONE or ERROR the renderer must exit; don't wait forever for it.
                if (done is not None or error is not None) and time.monotonic() > end_deadline:
                    break
                continue
            batch = [msg]
            while len(batch) < 4096:
                try:
                    batch.append(session.messages.get_nowait())
                except queue.Empty:
                    break
            for msg in batch:
                if isinstance(msg, protocol.Tile):
                    t_tile = time.monotonic()
                    if hello is None:
                        error = "tile before HELLO"
                        finished = True
                        break
                    x, y, w, h = msg.x, msg.y, msg.w, msg.h
                    if x + w > rw or y + h > rh:
                        error = "renderer sent a tile outside the image (%d,%d %dx%d in %dx%d)" % (
                            x, y, w, h, rw, rh)
                        finished = True
                        break
                    mirror[rh - y - h:rh - y, x:x + w] = msg.pixels[::-1]
                    for bname, data in msg.passes.items():
                        t = pass_targets.get(bname)
                        if t is not None:
                            t[1][rh - y - h:rh - y, x:x + w] = data[::-1]
                    dirty = True
                    result_seconds[0] += time.monotonic() - t_tile
                elif isinstance(msg, protocol.Progress):
                    tiles_done, tiles_total, spp_now = msg.tiles_done, msg.tiles_total, msg.spp
                    elapsed = msg.elapsed
                    progress_dirty = True
                elif isinstance(msg, protocol.Hello):
                    hello = msg
                    if (msg.width, msg.height) != (rw, rh):
                        error = "renderer announced %dx%d, expected %dx%d" % (
                            msg.width, msg.height, rw, rh)
                        finished = True
                        break
                    tiles_total = msg.tile_count
                    self.update_stats("", "Tesela | Sample 0/%d | Tile 0/%d | %.1f s" % (
                        msg.spp, msg.tile_count, time.monotonic() - t_start))
                elif isinstance(msg, protocol.Log):
                    print("Tesela renderer: " + msg.message)
                    session.fallbacks.add_renderer_line(msg.message)
                    if msg.level >= 2:
                        self.report({"WARNING"}, "Tesela: " + msg.message)
                elif isinstance(msg, protocol.Error):
                    end_deadline = time.monotonic() + 2.0
                    error = msg.message
                    error_from_renderer = True  # then Eof follows as the renderer exits
                elif isinstance(msg, protocol.Done):
                    end_deadline = time.monotonic() + 2.0
                    done = msg.stats
                elif isinstance(msg, protocol.Failure):
                    error = msg.message
                    finished = True
                    break
                elif isinstance(msg, protocol.Eof):
                    finished = True
                    break
            now = time.monotonic()
            # Progress and stats at most ~10 times a second (each call has a cost, and
            # `blender -b` prints a line for every stats update).
            if progress_dirty and (now - last_stats >= 0.1 or tiles_done == tiles_total):
                report_progress()
                last_stats = now
                progress_dirty = False
            # A few refreshes a second, but never more than ~15% of the time on them
            # (a 4K refresh costs ~0.2 s).
            if dirty and now - last_push >= max(PUSH_SECONDS, 6.0 * push_cost[0]):
                push()
                dirty = False
                last_push = now

        if cancelled:
            # Stop the renderer first (the 0.5 s budget), then keep the partial image.
            session.close()
        if dirty:
            push(final=True)
        self.end_result(result)
        if cancelled:
            self.update_stats("", "Tesela | Cancelled")
            return
        # Normal end or failure: let a finishing renderer exit by itself briefly.
        code = None
        if error is None and done is not None:
            try:
                code = session.proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                code = None
        if code is None:
            code = session.close()
        if error is not None:
            if session.proc.poll() is None:
                code = session.close()
            code = session.proc.returncode
            if error_from_renderer:
                msg = "renderer error: " + error
            else:
                msg = "%s (renderer %s)" % (error, _describe_exit(code))
                tail = session.stderr.text() if session.stderr is not None else ""
                if tail:
                    msg += "; stderr: " + tail
            self._fail(msg)
            return
        if done is None:
            tail = session.stderr.text() if session.stderr is not None else ""
            if hello is None and code == 2 and "--pipe-version" in tail:
                msg = OLD_RENDERER % (binary, protocol.PROTOCOL_VERSION)
            elif hello is None:
                msg = "the renderer exited without starting the render (%s)" % _describe_exit(code)
            else:
                msg = "the renderer stopped mid-render (%s)" % _describe_exit(code)
            if tail:
                msg += ": " + tail
            self._fail(msg)
            return
        if code not in (0, None):
            self.report({"WARNING"}, "Tesela: renderer finished but exited with %s" % _describe_exit(code))
        print(timing_line(res.triangles, t_export, done, result_seconds[0]))
        secs = done.get("seconds", time.monotonic() - t_start)
        self.update_stats("", "Tesela | Sample %d/%d | Tile %d/%d | %.1f s (export %.2f s)" % (
            spp_now or settings.samples, settings.samples, tiles_done, tiles_total, secs, t_export))
        self.update_progress(1.0)


def register():
    bpy.utils.register_class(TeselaRenderEngine)


def unregister():
    bpy.utils.unregister_class(TeselaRenderEngine)
