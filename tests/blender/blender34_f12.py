"""Run inside Blender's GUI (e.g. Blender 3.4 under xvfb-run): the real F12 path.

    xvfb-run -a blender --addons tesela SCENE.blend --python blender34_f12.py -- OUT.exr STATUS.json

A timer calls bpy.ops.render.render('INVOKE_DEFAULT'), so the engine's render() runs in
Blender's render job thread, as it does for an artist pressing F12. The script waits for the
job, saves the Render Result as a linear EXR, writes a JSON status and quits Blender.
"""

import json
import os
import sys
import threading
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
OUT, STATUS = argv[0], argv[1]
TIMEOUT = float(argv[2]) if len(argv) > 2 else 120.0
# Optional: quit Blender this many seconds after the render started (the user closing
# Blender mid-render; Blender stops the render job, i.e. test_break() turns true).
QUIT_AFTER = float(argv[3]) if len(argv) > 3 else None
state = {"started": False, "render_pre_thread_is_main": None, "complete": False,
         "cancelled": False, "t0": None, "error": None, "version": bpy.app.version_string}


def on_pre(*_):
    state["render_pre_thread_is_main"] = threading.current_thread() is threading.main_thread()


def on_complete(*_):
    state["complete"] = True


def on_cancel(*_):
    state["cancelled"] = True


bpy.app.handlers.render_pre.append(on_pre)
bpy.app.handlers.render_complete.append(on_complete)
bpy.app.handlers.render_cancel.append(on_cancel)


def finish():
    try:
        img = bpy.data.images.get("Render Result")
        if img is not None and state["complete"]:
            img.save_render(OUT)
            state["saved"] = OUT
    except Exception as exc:  # noqa: BLE001
        state["error"] = "save failed: %r" % exc
    state["seconds"] = time.monotonic() - (state["t0"] or time.monotonic())
    with open(STATUS, "w") as f:
        json.dump(state, f)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        if not state["started"]:
            win = bpy.context.window_manager.windows[0]
            state["t0"] = time.monotonic()
            with bpy.context.temp_override(window=win):
                r = bpy.ops.render.render("INVOKE_DEFAULT")
            state["invoke_result"] = sorted(r)
            state["started"] = True
            return 0.1
        running = bpy.app.is_job_running("RENDER")
        if running and QUIT_AFTER is not None and time.monotonic() - state["t0"] >= QUIT_AFTER:
            state["quit_at"] = time.time()
            with open(STATUS, "w") as f:
                json.dump(state, f)
            bpy.ops.wm.quit_blender()
            return None
        if running and time.monotonic() - state["t0"] < TIMEOUT:
            return 0.02
        state["job_ended_at"] = time.time()
        if running:
            state["error"] = "timeout"
        finish()
    except Exception as exc:  # noqa: BLE001
        state["error"] = repr(exc)
        finish()
    return None


# Optionally take the renderer from the add-on preferences instead of the environment, so the
# preference lookup runs in the render job thread too.
_pref = os.environ.pop("TESELA_F12_PREF_BINARY", None)
if _pref:
    os.environ.pop("TESELA_BINARY", None)
    os.environ.pop("TESELA_BIN", None)
    try:
        import addon_utils
        # --addons enables without listing the add-on in the preferences; list it.
        addon_utils.enable("tesela", default_set=True)
        bpy.context.preferences.use_preferences_save = False  # never write userpref.blend
        bpy.context.preferences.addons["tesela"].preferences.binary_path = _pref
    except Exception as exc:  # noqa: BLE001 - report and quit rather than hang
        state["error"] = "cannot set the preference: %r" % exc
        with open(STATUS, "w") as f:
            json.dump(state, f)
        bpy.ops.wm.quit_blender()

bpy.app.timers.register(tick, first_interval=1.0)
