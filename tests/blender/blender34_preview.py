"""Run inside Blender's GUI with the real renderer: a material's preview icon rendered by Tesela.

    xvfb-run -a blender --addons tesela SCENE.blend --python blender34_preview.py -- STATUS.json

Gives the scene's "Cube" a green material, shows the Properties editor's Material tab (Blender
then renders the material's icon in its preview job) and writes the icon's mean colour.
"""

import json
import sys
import time

import bpy
import numpy as np

OUT = sys.argv[sys.argv.index("--") + 1]
state = {"phase": 0, "t0": time.monotonic(), "error": None}


def finish():
    with open(OUT, "w") as f:
        json.dump(state, f)
    bpy.ops.wm.quit_blender()


def tick():
    try:
        screen = bpy.context.window_manager.windows[0].screen
        if state["phase"] == 0:
            ob = bpy.data.objects["Cube"]
            mat = bpy.data.materials.new("PreviewGreen")
            mat.use_nodes = True
            bsdf = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
            bsdf.inputs["Base Color"].default_value = (0.05, 0.8, 0.05, 1.0)
            ob.data.materials.append(mat)
            bpy.context.view_layer.objects.active = ob
            ob.select_set(True)
            state["phase"] = 1
            return 0.5
        if state["phase"] == 1:
            for a in screen.areas:
                if a.type == "PROPERTIES":
                    a.spaces[0].context = "MATERIAL"
                    a.tag_redraw()
            state["phase"] = 2
            return 0.5
        preview = bpy.data.materials["PreviewGreen"].preview
        icon = np.array(preview.icon_pixels_float[:]).reshape(-1, 4) if preview else None
        if icon is not None and icon.size and icon[:, 3].max() > 0:
            state["icon_mean"] = icon.mean(axis=0).tolist()
            state["icon_size"] = list(preview.icon_size)
            finish()
            return None
        if time.monotonic() - state["t0"] > 150:  # a loaded machine renders slowly
            state["error"] = "no icon after 150 s"
            finish()
            return None
        return 0.5
    except Exception as exc:  # noqa: BLE001 - report and quit rather than hang
        state["error"] = repr(exc)
        finish()
        return None


bpy.app.timers.register(tick, first_interval=1.0)
