"""Run inside Blender's GUI with the real renderer: the Rendered viewport in camera view, its
camera frame filling the region, against an F12 render of the same view.

    xvfb-run -a blender -p 0 0 W H --addons tesela SCENE.blend --python blender34_viewport_f12.py -- OUT_DIR SPP

Writes OUT_DIR/viewport.png (a screenshot of the region), OUT_DIR/f12.png (the Render Result
through the same view transform) and OUT_DIR/status.json, then quits Blender.
"""

import json
import math
import os
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
OUT, SPP = argv[0], int(argv[1])
state = {"error": None}
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender34_viewport as vp  # noqa: E402  (its helpers; its own steps are not run)


def setup():
    vp.setup()
    scene = bpy.context.scene
    s = scene.tesela
    s.samples = s.preview_samples = SPP
    s.preview_start_resolution = 0
    s.use_adaptive_sampling = False
    s.use_denoising = s.use_preview_denoising = False
    s.seed = 5
    scene.render.preview_pixel_size = "1"
    area = vp.area3d()
    region = vp.region_of(area)
    scene.render.resolution_x, scene.render.resolution_y = region.width, region.height
    scene.render.resolution_percentage = 100
    rv3d = area.spaces[0].region_3d
    rv3d.view_perspective = "CAMERA"
    rv3d.view_camera_zoom = 50.0 * (2.0 - math.sqrt(2.0))  # the frame fills the region
    rv3d.view_camera_offset = (0.0, 0.0)
    area.tag_redraw()
    state["region"] = [region.width, region.height]


run = {"phase": 0, "t0": time.monotonic(), "settle": 0}


def done_image():
    vs = vp.live_session()
    if vs is None or vs.client is None or vs.client.image is None:
        return False
    img = vs.client.image
    return img.last and img.samples == SPP and vs.display.serial == vs.client.serial


def finish():
    with open(os.path.join(OUT, "status.json"), "w") as f:
        json.dump(state, f, indent=1)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        if time.monotonic() - run["t0"] > 180:
            state["error"] = "timeout in phase %d" % run["phase"]
            vs = vp.live_session()
            state["dead"] = vs.client.dead if vs and vs.client else None
            finish()
            return None
        if run["phase"] == 0:
            setup()
            run["phase"] = 1
            return 0.1
        if run["phase"] == 1:
            if not done_image():
                return 0.05
            run["phase"], run["settle"] = 2, 3
            return 0.1
        if run["phase"] == 2:
            if run["settle"]:
                run["settle"] -= 1
                vp.area3d().tag_redraw()
                return 0.2
            area = vp.area3d()
            region = vp.region_of(area)
            win = bpy.context.window_manager.windows[0]
            with bpy.context.temp_override(window=win, area=area, region=region):
                bpy.ops.screen.screenshot_area(filepath=os.path.join(OUT, "viewport.png"))
            vs = vp.live_session()
            state["samples"] = vs.client.image.samples
            state["view"] = vs.view_fields
            area.spaces[0].shading.type = "SOLID"
            bpy.ops.render.render()
            scene = bpy.context.scene
            scene.render.image_settings.file_format = "PNG"
            scene.render.image_settings.color_depth = "8"
            bpy.data.images["Render Result"].save_render(os.path.join(OUT, "f12.png"))
            finish()
            return None
    except Exception as exc:  # noqa: BLE001 - report and quit rather than hang
        import traceback
        state["error"] = "%r: %s" % (exc, traceback.format_exc())
        finish()
    return None


bpy.app.timers.register(tick, first_interval=1.0, persistent=True)
