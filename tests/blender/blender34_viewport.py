"""Run inside Blender's GUI (Blender 3.4 under xvfb-run): the Rendered viewport.

    xvfb-run -a blender --factory-startup --addons tesela --python blender34_viewport.py -- OUT_DIR

TESELA_BINARY is the session to use (tests/blender/fake_session.py or the real renderer). A
timer walks through the steps below, screenshots the 3D viewport after each one into OUT_DIR
and writes OUT_DIR/status.json (what the add-on sent and saw, the session pids, the views'
cameras against Blender's own projection) before quitting Blender. The pytest side checks.
"""

import json
import os
import sys
import time

import bpy

OUT = sys.argv[sys.argv.index("--") + 1:][0] if __name__ == "__main__" else None
STEP_TIMEOUT = 60.0
state = {"version": bpy.app.version_string, "steps": [], "error": None}


def addon_viewport():
    import tesela.viewport
    return tesela.viewport


def live_session():
    sessions = [vs for vs in addon_viewport()._SESSIONS if vs.client is not None]
    return sessions[0] if len(sessions) == 1 else None


def area3d():
    for a in bpy.context.window_manager.windows[0].screen.areas:
        if a.type == "VIEW_3D":
            return a
    raise RuntimeError("no 3D viewport")


def region_of(area):
    return next(r for r in area.regions if r.type == "WINDOW")


def setup():
    scene = bpy.context.scene
    scene.render.engine = "TESELA"
    scene.render.dither_intensity = 0.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    scene.tesela.preview_samples = 4
    scene.tesela.max_depth = 4
    scene.tesela.pixel_filter_type = "BOX"
    scene.tesela.filter_width = 1.0
    if scene.camera is not None:
        scene.camera.data.show_passepartout = False
    area = area3d()
    space = area.spaces[0]
    # Nothing over the image: no overlays, gizmos, header or toolbar.
    space.overlay.show_overlays = False
    space.show_gizmo = False
    space.show_region_header = False
    space.show_region_toolbar = False
    space.show_region_ui = False
    if hasattr(space, "show_region_tool_header"):
        space.show_region_tool_header = False
    space.shading.type = "RENDERED"


def window_from_matrix(rv3d):
    """The view's image window from Blender's projection: (left, right, bottom, top) on the
    plane at distance 1 (perspective) or in metres (orthographic)."""
    p = rv3d.window_matrix
    if rv3d.is_perspective:
        return [(-1 + p[0][2]) / p[0][0], (1 + p[0][2]) / p[0][0],
                (-1 + p[1][2]) / p[1][1], (1 + p[1][2]) / p[1][1]]
    return [(-1 - p[0][3]) / p[0][0], (1 - p[0][3]) / p[0][0],
            (-1 - p[1][3]) / p[1][1], (1 - p[1][3]) / p[1][1]]


def record(name):
    """Screenshot the area; note the session's state and the view's cameras."""
    area = area3d()
    region = region_of(area)
    path = os.path.join(OUT, name + ".png")
    win = bpy.context.window_manager.windows[0]
    with bpy.context.temp_override(window=win, area=area, region=region):
        bpy.ops.screen.screenshot_area(filepath=path)
    vs = live_session()
    vc = addon_viewport().view_camera
    rv3d = area.spaces[0].region_3d
    view = vc.view_camera(bpy.context.evaluated_depsgraph_get().scene, area.spaces[0], rv3d,
                          region.width, region.height)
    entry = {"name": name, "shot": path, "area": [area.width, area.height],
             "region": [region.width, region.height, region.x - area.x, region.y - area.y],
             "perspective": rv3d.view_perspective,
             "window_blender": window_from_matrix(rv3d),
             "window_tesela": list(vc.window(view.ext, region.width, region.height)),
             "view_matrix_inv": [list(r) for r in rv3d.view_matrix.inverted()],
             "camera_matrix": view.matrix.tolist(), "type": view.ext["type"],
             "sessions": len([v for v in addon_viewport()._SESSIONS if v.client is not None])}
    if vs is not None:
        c = vs.client
        entry.update(pid=c.proc.pid, dead=c.dead, message=vs.message, errors=list(vs.errors),
                     generation=c.image.generation if c.image else None,
                     image_size=[c.image.view_width, c.image.view_height] if c.image else None,
                     sent=[cmd for cmd, _ in vs.sent])
    state["steps"].append(entry)


def image_ready(min_generation=0):
    vs = live_session()
    if vs is None or vs.client is None:
        return False
    img = vs.client.image
    region = region_of(area3d())
    return (img is not None and img.last and img.generation > min_generation
            and (img.view_width, img.view_height) == (region.width, region.height)
            and vs.display.serial == vs.client.serial)  # drawn


def generation():
    vs = live_session()
    return vs.client.image.generation if vs and vs.client and vs.client.image else 0


def set_view(kind):
    space = area3d().spaces[0]
    rv3d = space.region_3d
    if kind == "camera":
        rv3d.view_perspective = "CAMERA"
        rv3d.view_camera_zoom = 10.0
        rv3d.view_camera_offset = (0.05, -0.02)
    else:
        rv3d.view_perspective = kind
        rv3d.view_location = (0.5, 0.2, 0.3)
    area3d().tag_redraw()


STEPS = []


def step(fn):
    STEPS.append(fn)
    return fn


@step
def s_start(ctx):
    setup()
    live = live_session()
    if live is not None:
        live.record = True
    return lambda: image_ready()


@step
def s_shot_first(ctx):
    vs = live_session()
    vs.record = True
    record("first")
    ctx["gen"] = generation()
    set_view("PERSP")
    rv3d = area3d().spaces[0].region_3d
    rv3d.view_distance = 9.0
    area3d().tag_redraw()
    return lambda: image_ready(ctx["gen"])


@step
def s_persp(ctx):
    record("persp")
    ctx["gen"] = generation()
    set_view("ORTHO")
    return lambda: image_ready(ctx["gen"])


@step
def s_ortho(ctx):
    record("ortho")
    ctx["gen"] = generation()
    space = area3d().spaces[0]
    space.use_render_border = True
    space.render_border_min_x, space.render_border_max_x = 0.25, 0.75
    space.render_border_min_y, space.render_border_max_y = 0.5, 0.9
    area3d().tag_redraw()
    return lambda: image_ready(ctx["gen"])


@step
def s_border(ctx):
    record("border")
    vs = live_session()
    state["border_sent"] = vs.view_fields.get("border")
    img = vs.client.image
    state["border_image"] = [img.x, img.y, img.width, img.height]
    area3d().spaces[0].use_render_border = False
    ctx["gen"] = generation()
    set_view("camera")
    return lambda: image_ready(ctx["gen"])


@step
def s_camera(ctx):
    record("camera")
    ctx["gen"] = generation()
    bpy.data.objects["Cube"].location.x += 0.5
    return lambda: image_ready(ctx["gen"])


@step
def s_moved(ctx):
    record("moved")
    ctx["pid"] = live_session().client.proc.pid
    os.kill(ctx["pid"], 9)
    return lambda: live_session() is not None and live_session().client.dead is not None


@step
def s_killed(ctx):
    area3d().tag_redraw()
    return lambda: True


@step
def s_killed_drawn(ctx):
    record("killed")
    ctx["gen"] = 0
    rv3d = area3d().spaces[0].region_3d
    rv3d.view_camera_zoom = 5.0  # a view change starts a new session
    area3d().tag_redraw()
    return lambda: (live_session() is not None and live_session().client.proc.pid != ctx["pid"]
                    and image_ready())


@step
def s_restarted(ctx):
    record("restarted")
    ctx["last_pid"] = live_session().client.proc.pid
    area3d().spaces[0].shading.type = "SOLID"
    area3d().tag_redraw()
    return lambda: live_session() is None


@step
def s_left(ctx):
    record("left")
    area3d().spaces[0].shading.type = "RENDERED"
    return lambda: image_ready()


@step
def s_engine_switch(ctx):
    ctx["pid"] = live_session().client.proc.pid
    bpy.context.scene.render.engine = "BLENDER_WORKBENCH"
    area3d().tag_redraw()
    return lambda: live_session() is None


@step
def s_engine_back(ctx):
    state["engine_switch_alive"] = pid_alive(ctx["pid"])
    bpy.context.scene.render.engine = "TESELA"
    area3d().tag_redraw()
    return lambda: image_ready()


@step
def s_area_switch(ctx):
    ctx["pid"] = live_session().client.proc.pid
    area3d().type = "TEXT_EDITOR"
    return lambda: live_session() is None


@step
def s_area_back(ctx):
    state["area_switch_alive"] = pid_alive(ctx["pid"])
    for a in bpy.context.window_manager.windows[0].screen.areas:
        if a.type == "TEXT_EDITOR":
            a.type = "VIEW_3D"
    return lambda: image_ready()


@step
def s_again(ctx):
    record("again")
    ctx["again_pid"] = live_session().client.proc.pid
    # Opening a file ends the session at once (load_pre), before the new file's UI exists.
    bpy.ops.wm.open_mainfile(filepath=bpy.data.filepath)
    state["after_open_alive"] = pid_alive(ctx["again_pid"])
    return lambda: True


@step
def s_opened(ctx):
    setup()
    return lambda: image_ready()


@step
def s_quit(ctx):
    record("before_quit")
    state["pids"] = [s.get("pid") for s in state["steps"] if s.get("pid")]
    return None


def pid_alive(pid):
    try:
        os.kill(pid, 0)
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (ProcessLookupError, OSError):
        return False


def finish():
    # The last session still runs: quitting Blender must end it (the pytest side checks).
    state["alive_before_quit"] = sorted(p for p in set(state.get("pids", [])) if pid_alive(p))
    with open(os.path.join(OUT, "status.json"), "w") as f:
        json.dump(state, f, indent=1)
    bpy.ops.wm.quit_blender()


run = {"i": 0, "wait": None, "t0": None, "ctx": {}, "settle": 0}


def tick():
    try:
        if run["wait"] is not None:
            if not run["wait"]():
                if time.monotonic() - run["t0"] > STEP_TIMEOUT:
                    state["error"] = "timeout in step %s" % STEPS[run["i"] - 1].__name__
                    finish()
                    return None
                return 0.05
            run["wait"] = None
            run["settle"] = 2  # let Blender draw the frame it was told of
        if run["settle"]:
            run["settle"] -= 1
            for a in bpy.context.window_manager.windows[0].screen.areas:
                a.tag_redraw()
            return 0.2
        if run["i"] >= len(STEPS):
            finish()
            return None
        fn = STEPS[run["i"]]
        run["i"] += 1
        run["wait"] = fn(run["ctx"])
        run["t0"] = time.monotonic()
        return 0.05
    except Exception as exc:  # noqa: BLE001 - report and quit rather than hang
        import traceback
        state["error"] = "%s: %s" % (repr(exc), traceback.format_exc())
        finish()
        return None


if __name__ == "__main__":
    bpy.app.timers.register(tick, first_interval=1.0, persistent=True)
