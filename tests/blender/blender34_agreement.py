"""Run inside Blender 3.4 (or later) with the add-on enabled: render one scene of
tests/blender/scenes.py with Cycles and with Tesela (through the add-on), both to EXR.

    blender -b --factory-startup --addons tesela --python blender34_agreement.py -- \
        SCENE OUT_DIR SIZE SPP MAX_BOUNCES INTEGRATOR

SCENE: cornell | cornell_spheres | point | spot | sun | area | emissive_sphere | motion_blur
"""

import math
import os
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
kind, out_dir = argv[0], argv[1]
size, spp, bounces, integrator = int(argv[2]), int(argv[3]), int(argv[4]), argv[5]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

if kind == "cornell":
    info = scenes.cornell_box()
elif kind == "cornell_spheres":
    info = scenes.cornell_box(spheres=True)
elif kind in ("point", "spot", "sun"):
    info = scenes.light_over_plane(kind)
elif kind == "area":
    info = scenes.light_over_plane("point")
    bpy.data.objects.remove(bpy.data.objects["Point"], do_unlink=True)
    scenes.add_area_light("Area", (0.3, -0.2, 1.8), (0.2, 0.1, 0.0), 150.0, 0.8)
elif kind == "emissive_sphere":
    info = scenes.emissive_sphere()
elif kind == "motion_blur":
    # The box slides along x from frame 1 to 3 and the camera pans; frame 2 is rendered with
    # a full-frame shutter centred on it.
    info = scenes.light_over_plane("sun")
    box = next(o for o in info.scene.objects if o.type == "MESH" and o.name != "Plane")
    for frame, x in ((1, -0.8), (3, 0.8)):
        box.location.x = x
        box.keyframe_insert("location", frame=frame)
    cam = info.scene.camera
    for frame, dx in ((1, -0.1), (3, 0.1)):
        cam.location.x = dx
        cam.keyframe_insert("location", frame=frame)
    info.scene.frame_set(2)
    info.scene.render.use_motion_blur = True
    info.scene.render.motion_blur_shutter = 1.0
else:
    raise SystemExit("unknown scene " + kind)

# Blender 3.x's Principled BSDF (v1) diffuse is not Lambertian; its Diffuse BSDF (roughness 0) is.
# With "diffuse" as 8th argument, every Lambertian Principled material becomes a Diffuse BSDF.
if len(argv) > 6 and argv[6] == "diffuse":
    for mat in bpy.data.materials:
        if not mat.node_tree:
            continue
        nt = mat.node_tree
        bsdf = next((n for n in nt.nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is None:
            continue
        spec = bsdf.inputs.get("Specular IOR Level") or bsdf.inputs.get("Specular")
        trans = bsdf.inputs.get("Transmission Weight") or bsdf.inputs.get("Transmission")
        if bsdf.inputs["Metallic"].default_value > 0 or trans.default_value > 0 or spec.default_value > 0:
            continue
        emission = bsdf.inputs.get("Emission Color") or bsdf.inputs.get("Emission")
        strength = bsdf.inputs["Emission Strength"].default_value
        if max(emission.default_value[:3]) > 0 and strength > 0:
            continue
        out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
        diff = nt.nodes.new("ShaderNodeBsdfDiffuse")
        diff.inputs["Color"].default_value = bsdf.inputs["Base Color"].default_value
        diff.inputs["Roughness"].default_value = 0.0
        nt.links.new(diff.outputs[0], out.inputs["Surface"])

scene = info.scene
scenes.configure_cycles(scene, size, size, spp, bounces, seed=7)
scenes.render_cycles(os.path.join(out_dir, "cycles.exr"))
scene.render.engine = "TESELA"
t = scene.tesela
scenes.tesela_like_cycles(t)
t.integrator, t.samples, t.max_depth, t.seed = integrator, spp, bounces + 2, 1
bpy.ops.render.render(write_still=False)
bpy.data.images["Render Result"].save_render(os.path.join(out_dir, "tesela.exr"))
print("TESELA_AGREEMENT_DONE")
