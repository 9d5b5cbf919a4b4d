"""Run inside Blender (3.4 or later): build a small test scene and save it as a .blend.

    blender -b --factory-startup --addons tesela --python blender34_make_scene.py -- OUT.blend KIND W H SPP

KIND: "simple" (plane, cube, point light), "animcam" (simple, its camera moving over frames 1-3)
or "cornell" (tests/blender/scenes.py's Cornell box).
The render engine is set to TESELA, so the add-on must be enabled (--addons tesela with
BLENDER_USER_SCRIPTS pointing at a folder holding addons/tesela).
"""

import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out, kind, width, height, spp = argv[0], argv[1], int(argv[2]), int(argv[3]), int(argv[4])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

if kind == "cornell":
    import scenes
    scenes.cornell_box()
    scene = bpy.context.scene
else:
    scene = bpy.context.scene
    for ob in list(scene.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    mesh = bpy.data.meshes.new("Plane")
    mesh.from_pydata([(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], [], [(0, 1, 2, 3)])
    scene.collection.objects.link(bpy.data.objects.new("Plane", mesh))
    cube = bpy.data.meshes.new("Cube")
    cube.from_pydata([(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)], [],
                     [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (1, 3, 7, 5), (3, 2, 6, 7), (2, 0, 4, 6)])
    scene.collection.objects.link(bpy.data.objects.new("Cube", cube))
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", "POINT"))
    lamp.data.energy = 500.0
    lamp.location = (1, -1, 3)
    scene.collection.objects.link(lamp)
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    cam.location = (0, -6, 3)
    cam.rotation_euler = (math.radians(65), 0, 0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    if kind == "animcam":
        for frame, x in ((1, -0.4), (3, 0.4)):
            cam.location.x = x
            cam.keyframe_insert("location", frame=frame)

r = scene.render
r.engine = "TESELA"
r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
scene.tesela.samples = spp
scene.tesela.max_depth = 6
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
r.image_settings.file_format = "OPEN_EXR"
r.image_settings.color_depth = "32"
bpy.ops.wm.save_as_mainfile(filepath=out)
print("TESELA_SCENE_SAVED", out)
