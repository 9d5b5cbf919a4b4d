"""Material scenes as artists build them, rendered by Tesela through the add-on (F12 path:
``bpy.ops.render.render`` with engine TESELA, the add-on's graph export, the pipe) and by Cycles:
one small lit scene per feature (packed roughness/metallic image through Separate Color, a
tangent-space normal map under a grazing sun, bump from Noise, Mapping, Mix/Add shaders with Layer
Weight and Fresnel, alpha cut-outs and Transparent mixes casting shadows, a Noise -> Color Ramp
floor, vertex colours and a second UV map, textured emission lighting a room, Principled coat /
sheen / subsurface, rough glass in front of a textured wall).

Criteria (imgcompare.compare): per-channel means within 2%, 8x8-block relative errors within 5% at
the 95th percentile, 64x64 images. Tesela's max depth = Cycles' max bounces + 2. Images are
generated in code. ``test_broken_scene_fails`` shows the comparison can fail: it changes a node
after Tesela has exported the scene and before Cycles renders it. Set ``TESELA_TEST_SAVE=DIR`` to
write both images of every case as PNGs (sRGB) to DIR. Needs the renderer binary (conftest.py's
``tesela_bin``).
"""

import math
import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

import imgcompare
import scenes

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from test_addon import result_pixels  # noqa: E402

SIZE = 64
MEAN_TOL = 0.02
BLOCK_TOL = 0.05


# --------------------------------------------------------------------------------------------
# building blocks


def node_material(name):
    """A material with an empty node tree but for its Material Output: (mat, node tree, output)."""
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    return mat, nt, out


def node(nt, kind, props=None, **inputs):
    """A node of ``kind``: ``props`` first, then inputs by name (``_`` for spaces): a socket
    links, anything else is the default value."""
    n = nt.nodes.new(kind)
    for k, v in (props or {}).items():
        setattr(n, k, v)
    for k, v in inputs.items():
        sock = n.inputs[k.replace("_", " ")]
        if isinstance(v, bpy.types.NodeSocket):
            nt.links.new(v, sock)
        else:
            sock.default_value = v
    return n


def surface(nt, out, sock):
    nt.links.new(sock, out.inputs["Surface"])


def principled(nt, out, **inputs):
    """A Principled BSDF into the output; inputs by (5.x) name, ``_`` for spaces."""
    n = node(nt, "ShaderNodeBsdfPrincipled", **inputs)
    surface(nt, out, n.outputs[0])
    return n


def image(name, px, non_color=False, float_buffer=False):
    """A generated image from (h, w, 4) float pixels, rows bottom to top (Blender's order)."""
    h, w = px.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    img.colorspace_settings.name = "Non-Color" if non_color else (
        "Linear Rec.709" if float_buffer else "sRGB")
    img.pixels.foreach_set(np.ascontiguousarray(px, dtype=np.float32).ravel())
    img.update()
    img.pack()
    return img


def image_node(nt, img, vector=None, interpolation="Linear"):
    n = node(nt, "ShaderNodeTexImage", {"image": img, "interpolation": interpolation})
    if vector is not None:
        nt.links.new(vector, n.inputs["Vector"])
    return n


def uv_quad(name, corners, mat, uv=((0, 0), (1, 0), (1, 1), (0, 1)), extra_uv=None):
    """A quad with UV map "UVMap" (``uv`` per corner) and optionally a second map "UV2"."""
    ob = scenes.add_quad(name, corners, mat)
    layer = ob.data.uv_layers.new(name="UVMap")
    layer.data.foreach_set("uv", [c for p in uv for c in p])
    if extra_uv is not None:
        layer2 = ob.data.uv_layers.new(name="UV2")
        layer2.data.foreach_set("uv", [c for p in extra_uv for c in p])
    ob.data.uv_layers.active = layer
    layer.active_render = True
    return ob


def grid(name, n, half, mat, z=0.0):
    """An n x n quad grid over [-half, half]^2 at height z, with UV map "UVMap" over [0, 1]^2."""
    verts = [(-half + 2 * half * i / n, -half + 2 * half * j / n, z)
             for j in range(n + 1) for i in range(n + 1)]
    faces = [(j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
              (j + 1) * (n + 1) + i) for j in range(n) for i in range(n)]
    ob = scenes.add_mesh(name, verts, faces, mat)
    layer = ob.data.uv_layers.new(name="UVMap")
    uv = []
    for f in ob.data.polygons:
        for li in f.loop_indices:
            v = ob.data.vertices[ob.data.loops[li].vertex_index].co
            uv += [(v.x + half) / (2 * half), (v.y + half) / (2 * half)]
    layer.data.foreach_set("uv", uv)
    return ob


def world(strength, color=(1.0, 1.0, 1.0)):
    bg = next(n for n in bpy.context.scene.world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength


def lambert_mat(name, color):
    return scenes.lambert(name, color)


def checker_px(w=32, h=32, n=4, a=(0.8, 0.75, 0.6), b=(0.1, 0.2, 0.35)):
    yy, xx = np.mgrid[0:h, 0:w]
    on = ((xx * n // w + yy * n // h) % 2 == 0)[..., None]
    px = np.ones((h, w, 4), dtype=np.float32)
    px[..., :3] = np.where(on, np.array(a), np.array(b))
    # a gradient across the image so that orientation and scale errors show
    px[..., 0] *= 0.5 + 0.5 * xx / (w - 1)
    return px


# --------------------------------------------------------------------------------------------
# the scenes (each builds the whole current scene)


def _floor_stage(mat, sun_dir=(-0.4, 0.3, -1.0), sun=3.0, world_strength=0.2, half=2.0,
                 camera=((0.0, -3.2, 2.6), (0.0, 0.0, 0.0)), fov=45.0, uv_repeat=1.0):
    r = uv_repeat
    ob = uv_quad("Floor", [(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)],
                 mat, uv=((0, 0), (r, 0), (r, r), (0, r)))
    if sun:
        scenes.add_sun_light("Sun", sun_dir, sun)
    world(world_strength)
    scenes.add_camera(camera[0], camera[1], fov=math.radians(fov))
    return ob


def packed_rough_metal():
    """One packed image: R = roughness, G = metallic (Non-Color), through Separate Color into a
    Principled BSDF, on a floor lit by a sun and a grey world (the metal reflects the world)."""
    h = w = 32
    yy, xx = np.mgrid[0:h, 0:w]
    px = np.ones((h, w, 4), dtype=np.float32)
    px[..., 0] = 0.05 + 0.9 * xx / (w - 1)                           # roughness ramp
    px[..., 1] = ((xx // 8 + yy // 8) % 2).astype(np.float32)        # metal squares
    px[..., 2] = 0.5
    img = image("Packed", px, non_color=True)
    mat, nt, out = node_material("RoughMetal")
    tex = image_node(nt, img)
    sep = node(nt, "ShaderNodeSeparateColor", Color=tex.outputs["Color"])
    principled(nt, out, Base_Color=(0.8, 0.55, 0.3, 1.0), Roughness=sep.outputs["Red"],
               Metallic=sep.outputs["Green"])
    _floor_stage(mat, sun_dir=(0.2, 0.6, -1.0), world_strength=0.5)


def bumpy_normal_px(n=64, k=4, amp=0.08):
    """A tangent-space normal map of the height field amp·sin(2πku)·sin(2πkv) (encoded 0..1;
    amp 0.08: slopes up to 2, normals tilted up to 63 degrees)."""
    yy, xx = np.mgrid[0:n, 0:n]
    u, v = (xx + 0.5) / n, (yy + 0.5) / n
    f = 2 * math.pi * k
    dx = amp * f * np.cos(f * u) * np.sin(f * v)
    dy = amp * f * np.sin(f * u) * np.cos(f * v)
    nrm = np.stack([-dx, -dy, np.ones_like(dx)], axis=-1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    px = np.ones((n, n, 4), dtype=np.float32)
    px[..., :3] = nrm * 0.5 + 0.5
    return px


def normal_map(amp=0.08, sun_dir=(-1.0, 0.3, -0.27), specular=0.5):
    """A tangent-space Normal Map (bumpy generated image) on a rough Principled floor (specular
    0: Lambertian), lit by a sun (default: 15 degrees above the horizon)."""
    img = image("Bumps", bumpy_normal_px(amp=amp), non_color=True)
    mat, nt, out = node_material("NormalMapped")
    tex = image_node(nt, img)
    nm = node(nt, "ShaderNodeNormalMap", {"space": "TANGENT", "uv_map": "UVMap"},
              Strength=1.0, Color=tex.outputs["Color"])
    principled(nt, out, Base_Color=(0.7, 0.7, 0.7, 1.0), Roughness=0.6,
               Specular_IOR_Level=specular, Normal=nm.outputs["Normal"])
    _floor_stage(mat, sun_dir=sun_dir, sun=5.0, world_strength=0.05,
                 camera=((0.0, -2.2, 2.4), (0.0, 0.0, 0.0)))


def normal_map_glossy():
    """A metallic Principled floor (roughness 0.25) under strong normal-map normals (up to 63
    degrees), seen at grazing angles far off, lit by a bright grey world and a high sun: many
    normals would mirror the view below the floor, where Cycles raises them
    (ensure_valid_specular_reflection)."""
    img = image("Bumps", bumpy_normal_px(amp=0.08), non_color=True)
    mat, nt, out = node_material("NormalMappedMetal")
    tex = image_node(nt, img)
    nm = node(nt, "ShaderNodeNormalMap", {"space": "TANGENT", "uv_map": "UVMap"},
              Strength=1.0, Color=tex.outputs["Color"])
    principled(nt, out, Base_Color=(0.9, 0.8, 0.6, 1.0), Metallic=1.0, Roughness=0.25,
               Normal=nm.outputs["Normal"])
    _floor_stage(mat, sun_dir=(-0.3, 0.2, -1.0), sun=3.0, world_strength=1.0,
                 camera=((0.0, -3.0, 0.8), (0.0, 0.5, 0.0)))


def normal_map_glass():
    """A rough Glass BSDF floor (roughness 0.2) under strong normal-map normals, seen at
    grazing angles against a bright world and a high sun: as for the metal, Cycles raises
    normals that would reflect the view below the surface, for glass too."""
    img = image("Bumps", bumpy_normal_px(amp=0.08), non_color=True)
    mat, nt, out = node_material("NormalMappedGlass")
    tex = image_node(nt, img)
    nm = node(nt, "ShaderNodeNormalMap", {"space": "TANGENT", "uv_map": "UVMap"},
              Strength=1.0, Color=tex.outputs["Color"])
    surface(nt, out, node(nt, "ShaderNodeBsdfGlass", Color=(0.9, 0.95, 1.0, 1.0),
                          Roughness=0.2, IOR=1.45, Normal=nm.outputs["Normal"]).outputs[0])
    _floor_stage(mat, sun_dir=(-0.3, 0.2, -1.0), sun=3.0, world_strength=1.0,
                 camera=((0.0, -3.0, 0.8), (0.0, 0.5, 0.0)))


def glass_tinted_ball():
    """A tinted rough Glass BSDF ball (colour (0.9, 0.5, 0.3), roughness 0.1): the colour
    tints every reflection and refraction, as the closure's weight."""
    mat, nt, out = node_material("TintedGlass")
    surface(nt, out, node(nt, "ShaderNodeBsdfGlass", Color=(0.9, 0.5, 0.3, 1.0),
                          Roughness=0.1, IOR=1.45).outputs[0])
    _sphere_stage(mat)


def beckmann_ball(kind, **inputs):
    """A ball of a Glossy or Glass BSDF with the Beckmann distribution (its longer-tailed
    highlight than GGX's)."""
    def build():
        mat, nt, out = node_material("Beckmann" + kind)
        n = node(nt, kind, {"distribution": "BECKMANN"}, **inputs)
        surface(nt, out, n.outputs[0])
        _sphere_stage(mat)
    return build


def projected_image(projection, interpolation="Linear", coords="Object", blend=0.3):
    """A checker image on a ball through the Image Texture's projection (box with a blend,
    sphere or tube) from Object or Generated coordinates, into a Diffuse BSDF; Cubic reads a
    small image, where it differs most from Linear."""
    def build():
        img = image("Proj", checker_px(8, 8, 2) if interpolation == "Cubic" else checker_px())
        mat, nt, out = node_material("Projected")
        tc = node(nt, "ShaderNodeTexCoord")
        tex = image_node(nt, img, tc.outputs[coords], interpolation)
        tex.projection = projection
        if projection == "BOX":
            tex.projection_blend = blend
        surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=tex.outputs["Color"]).outputs[0])
        _sphere_stage(mat)
        ball = bpy.data.objects["Ball"]
        ball.rotation_euler = (0.3, -0.2, 0.7)  # the object's axes are not the world's
    return build


def noise_bump():
    """Bump (strength 0.8) from a Noise texture's Fac into a Principled BSDF, grazing sun."""
    mat, nt, out = node_material("NoiseBump")
    tc = node(nt, "ShaderNodeTexCoord")
    noise = node(nt, "ShaderNodeTexNoise", Vector=tc.outputs["Object"], Scale=3.0, Detail=2.0)
    bump = node(nt, "ShaderNodeBump", Strength=0.8, Distance=0.2, Height=noise.outputs["Fac"])
    principled(nt, out, Base_Color=(0.6, 0.5, 0.4, 1.0), Roughness=0.5,
               Normal=bump.outputs["Normal"])
    _floor_stage(mat, sun_dir=(-1.0, 0.4, -0.35), sun=5.0, world_strength=0.05)


def _displacement_output(mat, nt, out, disp_node):
    nt.links.new(disp_node.outputs["Displacement"], out.inputs["Displacement"])
    for owner in (mat, getattr(mat, "cycles", None)):
        if owner is not None and hasattr(owner, "displacement_method"):
            owner.displacement_method = "BUMP"
            break


def displacement_bump():
    """Noise -> Displacement node (object space, scale 0.15) -> the material output's
    Displacement, method Bump Only (Blender's default): the displaced normal shades a rough
    Principled floor under a low sun; a Geometry Normal tints the base colour, so the surface
    graph must see the displaced N too."""
    mat, nt, out = node_material("Displaced")
    tc = node(nt, "ShaderNodeTexCoord")
    noise = node(nt, "ShaderNodeTexNoise", Vector=tc.outputs["Object"], Scale=3.0, Detail=2.0)
    disp = node(nt, "ShaderNodeDisplacement", Height=noise.outputs["Fac"], Midlevel=0.5,
                Scale=0.15)
    geo = node(nt, "ShaderNodeNewGeometry")
    tint = node(nt, "ShaderNodeMix", {"data_type": "RGBA"}, Factor=0.5,
                A=(0.6, 0.5, 0.4, 1.0), B=geo.outputs["Normal"])
    principled(nt, out, Base_Color=tint.outputs["Result"], Roughness=0.5)
    _displacement_output(mat, nt, out, disp)
    _floor_stage(mat, sun_dir=(-1.0, 0.4, -0.35), sun=5.0, world_strength=0.05)


def true_displacement_terrain(method):
    """A 160 x 160 grid whose vertices a Noise (object space, scale 0.35) displaces along the
    normal ("DISPLACEMENT": the normals come from the moved triangles; "BOTH": the bump of the
    same displacement shades it), a rough Principled BSDF under a low sun that throws the
    hills' shadows."""
    mat, nt, out = node_material("Terrain")
    tc = node(nt, "ShaderNodeTexCoord")
    noise = node(nt, "ShaderNodeTexNoise", Vector=tc.outputs["Object"], Scale=1.2, Detail=3.0)
    disp = node(nt, "ShaderNodeDisplacement", Height=noise.outputs["Fac"], Midlevel=0.5,
                Scale=0.35)
    principled(nt, out, Base_Color=(0.6, 0.55, 0.45, 1.0), Roughness=0.6)
    _displacement_output(mat, nt, out, disp)
    mat.displacement_method = method
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=160, y_subdivisions=160, size=4.0)
    ob = bpy.context.active_object
    ob.data.materials.append(mat)
    scenes.add_sun_light("Sun", (-1.0, 0.4, -0.35), 5.0)
    world(0.1)
    scenes.add_camera((0.0, -3.4, 2.4), (0.0, 0.0, 0.0), fov=math.radians(45.0))


def true_displacement_ball():
    """A smooth UV sphere (its UV seam splits vertices) displaced along its normals by a Wave
    texture's Fac (scale 0.12, Displacement Only): the seam must not crack, and the shading
    follows the normals of the moved triangles."""
    lit_floor((-0.5, 0.6, -0.8), (0.0, 0.0, 0.75))
    mat, nt, out = node_material("Ridged")
    tc = node(nt, "ShaderNodeTexCoord")
    wave = node(nt, "ShaderNodeTexWave", Vector=tc.outputs["Object"], Scale=2.5)
    disp = node(nt, "ShaderNodeDisplacement", Height=wave.outputs["Fac"], Midlevel=0.0,
                Scale=0.12)
    surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=(0.7, 0.7, 0.7, 1.0)).outputs[0])
    _displacement_output(mat, nt, out, disp)
    mat.displacement_method = "DISPLACEMENT"
    scenes.uv_sphere_add(segments=128, ring_count=64, radius=0.6,
                         location=(0.0, 0.0, 0.75))
    ob = bpy.context.active_object
    ob.rotation_euler = (0.0, 0.0, math.radians(200.0))  # the seam faces the camera
    ob.data.materials.append(mat)
    ob.data.polygons.foreach_set("use_smooth", [True] * len(ob.data.polygons))
    ob.data.update()


def vector_displacement_ball(vector=True):
    """A Wave texture's colour as a world-space Vector Displacement of a ball (only its normal
    component bumps; `vector` False: its Fac through an object-space Displacement node),
    Diffuse BSDF, sun and world. Cycles' diffuse sees the displaced normal as the surface's
    own: no bump shadowing."""
    mat, nt, out = node_material("VecDisplaced")
    tc = node(nt, "ShaderNodeTexCoord")
    wave = node(nt, "ShaderNodeTexWave", Vector=tc.outputs["Object"], Scale=4.0, Distortion=2.0)
    if vector:
        disp = node(nt, "ShaderNodeVectorDisplacement", {"space": "WORLD"},
                    Vector=wave.outputs["Color"], Midlevel=0.5, Scale=0.08)
    else:
        disp = node(nt, "ShaderNodeDisplacement", Height=wave.outputs["Fac"], Midlevel=0.5,
                    Scale=0.08)
    surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=(0.7, 0.7, 0.7, 1.0)).outputs[0])
    _displacement_output(mat, nt, out, disp)
    _sphere_stage(mat)


def mapping_image():
    """UV -> Mapping (scale (2, 3), rotation 30 degrees about Z, a location offset) -> Image
    Texture -> Diffuse colour."""
    img = image("Checker", checker_px())
    mat, nt, out = node_material("Mapped")
    tc = node(nt, "ShaderNodeTexCoord")
    mp = node(nt, "ShaderNodeMapping", {"vector_type": "POINT"}, Vector=tc.outputs["UV"],
              Location=(0.1, 0.2, 0.0), Rotation=(0.0, 0.0, math.radians(30.0)),
              Scale=(2.0, 3.0, 1.0))
    tex = image_node(nt, img, mp.outputs["Vector"])
    principled(nt, out, Base_Color=tex.outputs["Color"], Roughness=1.0, Specular_IOR_Level=0.0)
    _floor_stage(mat, camera=((0.0, 0.0, 5.0), (0.0, 0.0, 0.0)), fov=44.0)


def _sphere_stage(mat, floor=(0.5, 0.5, 0.5), world_strength=0.3, sun=3.0,
                  sun_dir=(-0.5, 0.6, -0.8)):
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    lambert_mat("Floor", floor))
    scenes.add_sphere("Ball", (0.0, 0.0, 0.6), 0.6, mat, segments=64, rings=32)
    scenes.add_sun_light("Sun", sun_dir, sun)
    world(world_strength)
    scenes.add_camera((0.0, -2.6, 1.5), (0.0, 0.0, 0.55), fov=math.radians(40.0))


def oren_nayar_ball(kind):
    """A ball of diffuse roughness 1 (Oren-Nayar with its multiple-scattering term), lit by a
    sun from behind the camera: flat like the full moon, its rim far brighter than a
    Lambertian ball's; a Diffuse BSDF, or the diffuse base of a Principled BSDF (roughness
    0.5) under its specular layer."""
    def build():
        mat, nt, out = node_material("RoughDiffuse")
        color = (0.8, 0.5, 0.3, 1.0)
        if kind == "principled":
            principled(nt, out, Base_Color=color, Roughness=0.5, Diffuse_Roughness=1.0)
        else:
            surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=color,
                                  Roughness=1.0).outputs[0])
        _sphere_stage(mat, world_strength=0.1, sun=4.0, sun_dir=(0.1, 0.85, -0.5))
    return build


def random_per_island():
    """Thirty cubes in one mesh (two Array modifiers, nothing merged), each an island, shown
    by White Noise of Geometry > Random Per Island: every island's colour depends on the exact
    value Cycles derives from the island's representative vertex."""
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(-1.0, -0.8, 0.0))
    cubes = bpy.context.active_object
    for name, count, offset in (("Row", 6, (1.3, 0, 0)), ("Column", 5, (0, 1.3, 0))):
        arr = cubes.modifiers.new(name, "ARRAY")
        arr.count, arr.relative_offset_displace = count, offset
    mat, nt, out = node_material("Islands")
    white = node(nt, "ShaderNodeTexWhiteNoise", {"noise_dimensions": "1D"},
                 W=node(nt, "ShaderNodeNewGeometry").outputs["Random Per Island"])
    surface(nt, out, node(nt, "ShaderNodeEmission", Color=white.outputs["Color"]).outputs[0])
    cubes.data.materials.append(mat)
    scenes.add_camera((0.0, 0.0, 4.0), (0.0, 0.0, 0.0), fov=math.radians(50.0))


def pointiness():
    """Geometry > Pointiness through a steep Color Ramp (0.45 to 0.55) as emission, on a
    subdivided Suzanne and on a row of touching cubes (an Array that does not merge, then
    Bevel): Cycles' curvature estimate, with the coincident vertices where the cubes touch
    welded."""
    mat, nt, out = node_material("Pointiness")
    ramp = node(nt, "ShaderNodeValToRGB",
                Fac=node(nt, "ShaderNodeNewGeometry").outputs["Pointiness"])
    ramp.color_ramp.elements[0].position = 0.45
    ramp.color_ramp.elements[1].position = 0.55
    surface(nt, out, node(nt, "ShaderNodeEmission", Color=ramp.outputs["Color"]).outputs[0])
    bpy.ops.mesh.primitive_monkey_add(size=1.2, location=(-0.8, 0.0, 0.4))
    monkey = bpy.context.active_object
    monkey.modifiers.new("Subdivision", "SUBSURF").render_levels = 1
    monkey.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.35, 0.0, -0.5))
    cubes = bpy.context.active_object
    arr = cubes.modifiers.new("Row", "ARRAY")
    arr.count, arr.relative_offset_displace, arr.use_merge_vertices = 4, (1.0, 0, 0), False
    cubes.modifiers.new("Bevel", "BEVEL").width = 0.03
    cubes.rotation_euler = (0.5, 0.3, 0.2)
    cubes.data.materials.append(mat)
    scenes.add_camera((0.0, -4.0, 0.3), (0.0, 0.0, 0.0), fov=math.radians(40.0))


def principled_ggx(kind):
    """A Principled BSDF set to plain GGX (3.x's default, which older files keep): no
    multiple-scattering energy compensation, so rough lobes lose energy. A rough half-metal
    (metal and specular over diffuse), or rough glass (transmission 1, roughness 0.9)."""
    def build():
        mat, nt, out = node_material("PrincipledGGX")
        if kind == "glass":
            p = principled(nt, out, Base_Color=(0.9, 0.95, 1.0, 1.0), Roughness=0.9,
                           Transmission_Weight=1.0)
        else:
            p = principled(nt, out, Base_Color=(0.9, 0.6, 0.3, 1.0), Roughness=0.8,
                           Metallic=0.5)
        p.distribution = "GGX"
        _sphere_stage(mat, world_strength=1.0)
    return build


def smooth_tinted_metal():
    """A mirror-smooth Principled metal (roughness 0) with a blue Specular Tint in a bright
    world: Cycles' F82-tint Fresnel colours its rim, as it does for rough metal."""
    mat, nt, out = node_material("SmoothMetal")
    principled(nt, out, Base_Color=(0.9, 0.6, 0.3, 1.0), Metallic=1.0, Roughness=0.0,
               Specular_Tint=(0.2, 0.5, 1.0, 1.0))
    _sphere_stage(mat, world_strength=1.0)


def smooth_principled_ball():
    """A Principled BSDF at roughness 0 (a delta specular layer over its diffuse base) with a
    Specular Tint of (0, 0.5, 1) in a bright world: Cycles' generalized Schlick Fresnel, exact
    dielectric reflectance shaped, tints only F0, so the red channel keeps its white rim."""
    mat, nt, out = node_material("SmoothTinted")
    principled(nt, out, Base_Color=(0.1, 0.15, 0.3, 1.0), Roughness=0.0,
               Specular_Tint=(0.0, 0.5, 1.0, 1.0))
    _sphere_stage(mat, world_strength=1.0, sun=2.0)


def no_material_ball():
    """A ball without any material and a floor whose one slot is empty: Cycles shades both
    with its default surface (a default Principled BSDF since 4.0, highlight included)."""
    _sphere_stage(None, sun=4.0, sun_dir=(0.3, 0.6, -0.75))
    floor = bpy.data.objects["Floor"]
    floor.data.materials.clear()
    floor.data.materials.append(None)


def black_base_ball():
    """A Principled BSDF of base colour exactly black (roughness 0.5) in a bright world: all
    its light is the specular layer's, and the diffuse base below samples directions too."""
    mat, nt, out = node_material("BlackBase")
    principled(nt, out, Base_Color=(0.0, 0.0, 0.0, 1.0), Roughness=0.5)
    _sphere_stage(mat, world_strength=1.0)


def named_attribute(data_type, domain, output):
    """Geometry Nodes store 0.33 P + 0.5 (a FLOAT from its x) as the attribute 'myattr' on a
    grid's points or faces; the material's Attribute node reads it into the base colour."""
    def build():
        import bmesh
        mat, nt, out = node_material("NamedAttr")
        a = node(nt, "ShaderNodeAttribute", {"attribute_name": "myattr",
                                             "attribute_type": "GEOMETRY"})
        principled(nt, out, Base_Color=a.outputs[output], Roughness=0.8)
        me = bpy.data.meshes.new("Grid")
        bm = bmesh.new()
        bmesh.ops.create_grid(bm, x_segments=20, y_segments=20, size=1.5)
        bm.to_mesh(me)
        bm.free()
        me.materials.append(mat)
        ob = bpy.data.objects.new("Grid", me)
        bpy.context.scene.collection.objects.link(ob)
        tree = bpy.data.node_groups.new("StoreAttr", "GeometryNodeTree")
        tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
        tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
        gi, go = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
        ob.modifiers.new("StoreAttr", "NODES").node_group = tree
        pos = tree.nodes.new("GeometryNodeInputPosition")
        madd = tree.nodes.new("ShaderNodeVectorMath")
        madd.operation = "MULTIPLY_ADD"
        madd.inputs[1].default_value = (0.33, 0.33, 0.33)
        madd.inputs[2].default_value = (0.5, 0.5, 0.5)
        tree.links.new(pos.outputs[0], madd.inputs[0])
        store = tree.nodes.new("GeometryNodeStoreNamedAttribute")
        store.data_type, store.domain = data_type, domain
        store.inputs["Name"].default_value = "myattr"
        tree.links.new(gi.outputs[0], store.inputs["Geometry"])
        value = next(i for i in store.inputs if i.enabled and i.name == "Value")
        if data_type == "FLOAT":
            sep = tree.nodes.new("ShaderNodeSeparateXYZ")
            tree.links.new(madd.outputs[0], sep.inputs[0])
            tree.links.new(sep.outputs[0], value)
        else:
            tree.links.new(madd.outputs[0], value)
        tree.links.new(store.outputs[0], go.inputs[0])
        scenes.add_sun_light("Sun", (-0.6, 0.4, -0.7), 3.0)
        world(0.2)
        scenes.add_camera((0.0, -3.5, 2.8), (0.0, 0.0, 0.0), fov=math.radians(45.0))
    return build


def coloured_multiscatter(kind):
    """A rough Multiscatter GGX ball of colour 0.5 (Glossy at roughness 1, Glass at 0.8) in a
    bright uniform world: the energy compensation darkens it by the colour's multiple bounces
    (Cycles' F_ss = the colour), far below what a white ball scaled by 0.5 would give."""
    def build():
        mat, nt, out = node_material("MultiGGX")
        if kind == "glossy":
            bsdf = node(nt, "ShaderNodeBsdfAnisotropic", {"distribution": "MULTI_GGX"},
                        Color=(0.5, 0.5, 0.5, 1.0), Roughness=1.0)
        else:
            bsdf = node(nt, "ShaderNodeBsdfGlass", {"distribution": "MULTI_GGX"},
                        Color=(0.6, 0.4, 0.3, 1.0), Roughness=0.8, IOR=1.45)
        surface(nt, out, bsdf.outputs[0])
        _sphere_stage(mat, world_strength=1.0, sun=0.0)
    return build


def lowpoly_smooth_specular():
    """Smooth-shaded low-poly balls (10 x 5 and 8 x 4 faces), a mirror Glossy and a glossy
    Principled, in a bright world over a grey floor: towards their rims the interpolated normals
    would mirror the view below the faces, where Cycles' bump map correction (on for every
    material by default) raises them, for interpolated normals as for mapped ones."""
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    lambert_mat("Floor", (0.5, 0.5, 0.5)))
    mat, nt, out = node_material("Mirror")
    surface(nt, out, node(nt, "ShaderNodeBsdfGlossy", Color=(0.9, 0.9, 0.9, 1.0),
                          Roughness=0.0).outputs[0])
    scenes.add_sphere("Low", (-0.6, 0.0, 0.5), 0.5, mat, segments=10, rings=5)
    plastic = scenes.material("Plastic", (0.2, 0.4, 0.8), roughness=0.1)
    scenes.add_sphere("Low2", (0.6, 0.0, 0.5), 0.5, plastic, segments=8, rings=4)
    world(1.0, (0.9, 0.95, 1.0))
    scenes.add_sun_light("Sun", (-0.3, 0.5, -0.8), 2.0)
    scenes.add_camera((0.0, -3.0, 1.0), (0.0, 0.0, 0.5), fov=math.radians(45.0))


def flat_and_mixed_shading():
    """How Cycles shades flat faces: a flat-shaded cube twisted by a Simple Deform modifier (its
    side quads are not planar: each shows its two triangles, each with its own normal), and a
    12-sided cylinder with smooth sides and flat caps, no sharp edge (its sides take the vertex
    normals, which average the caps in: the rims look rounded, as in Cycles but not in the
    viewport); beside it the same cylinder with one edge marked sharp, which Cycles shades with
    Blender's corner normals (the sides' normals stop at the caps)."""
    scenes.add_quad("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)],
                    lambert_mat("Floor", (0.5, 0.5, 0.5)))
    bpy.ops.mesh.primitive_cube_add(size=0.7, location=(-0.9, 0.2, 0.4))
    cube = bpy.context.active_object
    cube.data.materials.append(scenes.material("Twist", (0.7, 0.7, 0.2), roughness=0.3))
    twist = cube.modifiers.new("Twist", "SIMPLE_DEFORM")
    twist.deform_method, twist.angle = "TWIST", 1.2
    for x, sharp in ((0.1, False), (1.0, True)):
        bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=0.4, depth=0.8,
                                            location=(x, 0.0, 0.4))
        cyl = bpy.context.active_object
        cyl.data.materials.append(scenes.material("Cyl", (0.8, 0.4, 0.2), roughness=0.35))
        for face in cyl.data.polygons:
            face.use_smooth = abs(face.normal.z) < 0.5
        cyl.data.edges[0].use_edge_sharp = sharp
    scenes.add_sun_light("Sun", (0.4, 0.6, -0.8), 3.0, angle=math.radians(3.0))
    world(0.6, (0.4, 0.45, 0.5))
    scenes.add_camera((0.0, -3.2, 2.0), (0.0, 0.0, 0.4), fov=math.radians(45.0))


def mix_layer_weight():
    """Mix Shader of Diffuse (fac 0) and Glossy (fac 1) by Layer Weight's Facing (blend 0.4)."""
    mat, nt, out = node_material("LayerMix")
    lw = node(nt, "ShaderNodeLayerWeight", Blend=0.4)
    dif = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.7, 0.2, 0.1, 1.0))
    glo = node(nt, "ShaderNodeBsdfAnisotropic", Color=(0.9, 0.9, 0.9, 1.0), Roughness=0.25)
    mix = node(nt, "ShaderNodeMixShader", Fac=lw.outputs["Facing"])
    nt.links.new(dif.outputs[0], mix.inputs[1])
    nt.links.new(glo.outputs[0], mix.inputs[2])
    surface(nt, out, mix.outputs[0])
    _sphere_stage(mat)


def add_fresnel():
    """Add Shader: Diffuse + Glossy whose colour is Fresnel (IOR 1.45)."""
    mat, nt, out = node_material("AddFresnel")
    fr = node(nt, "ShaderNodeFresnel", IOR=1.45)
    dif = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.1, 0.3, 0.6, 1.0))
    glo = node(nt, "ShaderNodeBsdfAnisotropic", Color=fr.outputs["Fac"], Roughness=0.2)
    add = node(nt, "ShaderNodeAddShader")
    nt.links.new(dif.outputs[0], add.inputs[0])
    nt.links.new(glo.outputs[0], add.inputs[1])
    surface(nt, out, add.outputs[0])
    _sphere_stage(mat)


def _card_stage(card_mat):
    """An upright 1.2 m card (UV over [0, 1]^2) on a floor, a sun behind-left casting its shadow
    towards the camera."""
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    lambert_mat("Floor", (0.8, 0.8, 0.8)))
    uv_quad("Card", [(-0.6, 0.3, 0.1), (0.6, 0.3, 0.1), (0.6, 0.3, 1.3), (-0.6, 0.3, 1.3)],
            card_mat)
    scenes.add_sun_light("Sun", (0.3, -0.8, -0.6), 3.0)
    world(0.1)
    scenes.add_camera((0.6, -3.0, 2.2), (0.0, 0.0, 0.4), fov=math.radians(45.0))


def alpha_cutout():
    """An image with a transparent round hole, Alpha into Principled Alpha."""
    n = 32
    yy, xx = np.mgrid[0:n, 0:n]
    px = np.ones((n, n, 4), dtype=np.float32)
    px[..., :3] = checker_px(n, n)[..., :3]
    r = np.hypot((xx + 0.5) / n - 0.45, (yy + 0.5) / n - 0.55)
    px[..., 3] = np.where(r < 0.28, 0.0, 1.0)
    img = image("Holed", px)
    mat, nt, out = node_material("Cutout")
    tex = image_node(nt, img)
    principled(nt, out, Base_Color=tex.outputs["Color"], Alpha=tex.outputs["Alpha"],
               Roughness=0.8)
    _card_stage(mat)


def transparent_mix():
    """Mix Shader: Transparent BSDF (tinted) and Diffuse at fac 0.4 (40% diffuse)."""
    mat, nt, out = node_material("HalfTransparent")
    tr = node(nt, "ShaderNodeBsdfTransparent", Color=(0.9, 0.6, 0.3, 1.0))
    dif = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.2, 0.5, 0.8, 1.0))
    mix = node(nt, "ShaderNodeMixShader", Fac=0.4)
    nt.links.new(tr.outputs[0], mix.inputs[1])
    nt.links.new(dif.outputs[0], mix.inputs[2])
    surface(nt, out, mix.outputs[0])
    _card_stage(mat)


def noise_ramp_floor(shader="principled"):
    """Noise (Object coordinates) -> Color Ramp (three stops, linear) -> the base colour of a
    Principled BSDF (roughness 0.9), or the colour of a Diffuse BSDF."""
    mat, nt, out = node_material("RampFloor")
    tc = node(nt, "ShaderNodeTexCoord")
    noise = node(nt, "ShaderNodeTexNoise", Vector=tc.outputs["Object"], Scale=2.0, Detail=3.0)
    ramp = node(nt, "ShaderNodeValToRGB", Fac=noise.outputs["Fac"])
    el = ramp.color_ramp.elements
    el[0].position, el[0].color = 0.35, (0.05, 0.1, 0.4, 1.0)
    el[1].position, el[1].color = 0.65, (0.9, 0.8, 0.2, 1.0)
    mid = el.new(0.5)
    mid.color = (0.8, 0.1, 0.1, 1.0)
    if shader == "principled":
        principled(nt, out, Base_Color=ramp.outputs["Color"], Roughness=0.9)
    else:
        d = node(nt, "ShaderNodeBsdfDiffuse", Color=ramp.outputs["Color"])
        surface(nt, out, d.outputs[0])
    _floor_stage(mat, camera=((0.0, 0.0, 5.0), (0.0, 0.0, 0.0)), fov=44.0)


def vertex_colour_uv2():
    """A 4x4 grid with a colour attribute "Col" (per corner) multiplied by an image read through a
    second UV map "UV2" (rotated, repeated), UVMap being the active one."""
    mat, nt, out = node_material("VcolUV2")
    ob = grid("Floor", 4, 2.0, mat)
    mesh = ob.data
    attr = mesh.color_attributes.new("Col", "FLOAT_COLOR", "CORNER")
    cols = []
    for li in range(len(mesh.loops)):
        v = mesh.vertices[mesh.loops[li].vertex_index].co
        cols += [0.2 + 0.2 * (v.x + 2), 0.9 - 0.2 * (v.y + 2), 0.3 + 0.1 * abs(v.x * v.y), 1.0]
    attr.data.foreach_set("color", cols)
    uv2 = mesh.uv_layers.new(name="UV2")
    uv = []
    for li in range(len(mesh.loops)):
        v = mesh.vertices[mesh.loops[li].vertex_index].co
        uv += [0.6 * v.y + 0.3, -0.6 * v.x + 0.1]
    uv2.data.foreach_set("uv", uv)
    mesh.uv_layers.active = mesh.uv_layers["UVMap"]
    mesh.uv_layers["UVMap"].active_render = True
    img = image("Checker2", checker_px(a=(0.9, 0.9, 0.9), b=(0.3, 0.3, 0.3)))
    uvn = node(nt, "ShaderNodeUVMap", {"uv_map": "UV2"})
    tex = image_node(nt, img, uvn.outputs["UV"])
    vc = node(nt, "ShaderNodeVertexColor", {"layer_name": "Col"})
    mix = node(nt, "ShaderNodeMix", {"data_type": "RGBA", "blend_type": "MULTIPLY"})
    mix.inputs["Factor"].default_value = 1.0
    nt.links.new(vc.outputs["Color"], mix.inputs[6])
    nt.links.new(tex.outputs["Color"], mix.inputs[7])
    principled(nt, out, Base_Color=mix.outputs[2], Roughness=1.0, Specular_IOR_Level=0.0)
    scenes.add_sun_light("Sun", (-0.4, 0.3, -1.0), 3.0)
    world(0.1)
    scenes.add_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), fov=math.radians(44.0))


def emission_room():
    """A closed 2 m room (Lambertian walls, camera inside) lit only by a panel on the ceiling whose
    Emission colour is an image texture."""
    white = lambert_mat("White", (0.7, 0.7, 0.7))
    red = lambert_mat("Red", (0.6, 0.1, 0.08))
    scenes.add_quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    scenes.add_quad("Ceiling", [(-1, -1, 2), (-1, 1, 2), (1, 1, 2), (1, -1, 2)], white)
    scenes.add_quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    scenes.add_quad("Front", [(-1, -1, 0), (-1, -1, 2), (1, -1, 2), (1, -1, 0)], white)
    scenes.add_quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    scenes.add_quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], white)
    scenes.add_box("Block", (-0.1, 0.0, 0.0), (0.5, 0.6, 0.7), lambert_mat("Blk", (0.5, 0.6, 0.4)))
    px = checker_px(16, 16, 2, a=(1.0, 0.9, 0.7), b=(0.2, 0.5, 1.0))
    img = image("Panel", px)
    mat, nt, out = node_material("Panel")
    tex = image_node(nt, img)
    em = node(nt, "ShaderNodeEmission", Color=tex.outputs["Color"], Strength=12.0)
    surface(nt, out, em.outputs[0])
    uv_quad("Panel", [(-0.5, -0.5, 1.99), (-0.5, 0.5, 1.99), (0.5, 0.5, 1.99), (0.5, -0.5, 1.99)],
            mat)
    scenes.add_camera((0.0, -0.95, 1.0), (0.0, 1.0, 0.9), fov=math.radians(80.0))


def emitter_hidden_from_camera():
    """A panel whose shader is Mix(Emission, Transparent) by Light Path's Is Camera Ray, the
    artists' way to hide a light from the camera: the camera sees through it, while light
    sampling and bounced rays (no camera bit) see its emission and light the floor and wall."""
    white = lambert_mat("White", (0.7, 0.7, 0.7))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], white)
    scenes.add_quad("Back", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], white)
    scenes.add_box("Block", (-0.3, -0.2, 0.0), (0.3, 0.4, 0.5), lambert_mat("Blk", (0.6, 0.3, 0.2)))
    mat, nt, out = node_material("HiddenPanel")
    lp = node(nt, "ShaderNodeLightPath")
    em = node(nt, "ShaderNodeEmission", Color=(1.0, 0.9, 0.8, 1.0), Strength=8.0)
    tr = node(nt, "ShaderNodeBsdfTransparent")
    mix = node(nt, "ShaderNodeMixShader", Fac=lp.outputs["Is Camera Ray"])
    nt.links.new(em.outputs[0], mix.inputs[1])
    nt.links.new(tr.outputs[0], mix.inputs[2])
    surface(nt, out, mix.outputs[0])
    scenes.add_quad("Panel", [(-0.5, -0.6, 1.3), (-0.5, 0.4, 1.3), (0.5, 0.4, 1.3),
                              (0.5, -0.6, 1.3)], mat)
    world(0.02)
    scenes.add_camera((0.0, -3.0, 1.6), (0.0, 0.5, 0.6), fov=math.radians(50.0))


def emission_light_falloff():
    """A floor and a back wall lit by a 0.6 m panel 1.2 m up whose Emission strength is a Light
    Falloff node's Linear output (strength 6, smooth 0.3): brighter with the distance each ray
    travels to it, and softened near it; the camera sees the panel too."""
    white = lambert_mat("White", (0.7, 0.7, 0.7))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], white)
    scenes.add_quad("Back", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)], white)
    mat, nt, out = node_material("FalloffPanel")
    fall = node(nt, "ShaderNodeLightFalloff", Strength=6.0, Smooth=0.3)
    em = node(nt, "ShaderNodeEmission", Color=(1.0, 0.9, 0.8, 1.0),
              Strength=fall.outputs["Linear"])
    surface(nt, out, em.outputs[0])
    scenes.add_quad("Panel", [(-0.3, -0.3, 1.2), (-0.3, 0.3, 1.2), (0.3, 0.3, 1.2),
                              (0.3, -0.3, 1.2)], mat)
    world(0.0)
    scenes.add_camera((0.0, -3.0, 1.6), (0.0, 0.5, 0.6), fov=math.radians(50.0))


def principled_variant(kind):
    def build():
        mat, nt, out = node_material("P_" + kind)
        ins = dict(Base_Color=(0.7, 0.15, 0.1, 1.0), Roughness=0.5)
        if kind == "coat":
            ins.update(Coat_Weight=1.0, Coat_Roughness=0.05, Coat_IOR=1.5,
                       Coat_Tint=(0.8, 0.9, 1.0, 1.0))
        elif kind == "sheen":
            ins.update(Base_Color=(0.1, 0.1, 0.3, 1.0), Sheen_Weight=1.0, Sheen_Roughness=0.3,
                       Sheen_Tint=(1.0, 0.8, 0.6, 1.0))
        elif kind == "subsurface":
            ins.update(Base_Color=(0.8, 0.6, 0.5, 1.0), Subsurface_Weight=1.0,
                       Subsurface_Radius=(1.0, 0.4, 0.2), Subsurface_Scale=0.05)
        elif kind == "subsurface_wide":
            # Ten times the radius: light walks a good part of the ball (red mean free path
            # 4 cm against its 60 cm radius), which glows through where the sun does not reach.
            ins.update(Base_Color=(0.8, 0.6, 0.5, 1.0), Subsurface_Weight=1.0,
                       Subsurface_Radius=(1.0, 0.4, 0.2), Subsurface_Scale=0.5)
        elif kind == "sheen_over_coat":
            # Velvet-like sheen over a coat over the dielectric base (specular over diffuse):
            # three layers, as Cycles stacks them.
            ins.update(Base_Color=(0.1, 0.03, 0.03, 1.0), Coat_Weight=1.0, Coat_Roughness=0.2,
                       Sheen_Weight=1.0, Sheen_Roughness=0.3, Sheen_Tint=(0.9, 0.9, 1.0, 1.0))
        elif kind == "emission_coat_sheen":
            # Cycles sets the emission up below the sheen and the coat: their albedo for the
            # view direction, and the coat's tint along the view ray refracted into it, take
            # their share (a glowing ball under a blue coat glows bluish, darker at its rim).
            # Its light samples see the tint alone (Cycles evaluates them without closures), as
            # do rays that end at the ball: with 2 bounces the floor's rays go on from it.
            ins.update(Base_Color=(0.05, 0.05, 0.05, 1.0), Emission_Color=(1.0, 0.7, 0.4, 1.0),
                       Emission_Strength=3.0, Coat_Weight=1.0, Coat_Roughness=0.2,
                       Coat_Tint=(0.4, 0.7, 1.0, 1.0), Sheen_Weight=1.0, Sheen_Roughness=0.3)
        elif kind.startswith("thin_film"):
            # Interference colours that change across the ball with the angle of incidence;
            # a dark base so that the specular layer carries them.
            ins.update(Base_Color=(0.05, 0.05, 0.08, 1.0), Roughness=0.25,
                       Thin_Film_Thickness=500.0, Thin_Film_IOR=1.33)
            if kind == "thin_film_smooth":
                ins.update(Roughness=0.0, Thin_Film_Thickness=320.0, Thin_Film_IOR=1.8)
            elif kind == "thin_film_glass":
                ins.update(Base_Color=(1.0, 1.0, 1.0, 1.0), Transmission_Weight=1.0,
                           Roughness=0.15, Thin_Film_Thickness=380.0)
            elif kind == "thin_film_bubble":
                ins.update(Base_Color=(1.0, 1.0, 1.0, 1.0), Transmission_Weight=1.0,
                           Roughness=0.0, IOR=1.0, Thin_Film_Thickness=420.0)
        principled(nt, out, **ins)
        _sphere_stage(mat)
    return build


def coated_normal_map(kind):
    """A coat over a normal-mapped base, whose layers Cycles gives normals of their own: the
    coat the Coat Normal input, else the surface's (unbumped) normal; the metal or specular
    base the bumped normal raised to reflect above the surface; a sheen the bumped one.
    ``flakes``: car paint, a red metal with a Voronoi cell normal per flake under a smooth
    coat; ``tilted``: one strongly tilted normal over the whole ball (the coat keeps the
    ball's); ``tilted_coat_normal``: the same normal linked to Coat Normal too;
    ``flakes_sheen``: the flakes under a sheen instead; ``flakes_plastic``: under a coat over
    a dielectric base."""
    def build():
        mat, nt, out = node_material("Coated_" + kind)
        ins = dict(Base_Color=(0.5, 0.02, 0.02, 1.0), Metallic=1.0, Roughness=0.35,
                   Coat_Weight=1.0, Coat_Roughness=0.03)
        if kind.startswith("flakes"):
            vor = node(nt, "ShaderNodeTexVoronoi", Scale=60.0)
            nm = node(nt, "ShaderNodeNormalMap", Strength=0.4, Color=vor.outputs["Color"])
        else:
            nm = node(nt, "ShaderNodeNormalMap", Color=(0.85, 0.5, 0.8, 1.0))
            ins.update(Base_Color=(0.9, 0.8, 0.6, 1.0), Roughness=0.25)
        if kind == "flakes_sheen":
            ins.update(Coat_Weight=0.0, Sheen_Weight=1.0, Sheen_Roughness=0.3)
        elif kind == "flakes_plastic":
            # Varnish over a normal-mapped dielectric: three normals (coat, raised specular,
            # mapped diffuse).
            ins.update(Metallic=0.0)
        p = principled(nt, out, **ins)
        nt.links.new(nm.outputs["Normal"], p.inputs["Normal"])
        if kind == "tilted_coat_normal":
            nt.links.new(nm.outputs["Normal"], p.inputs["Coat Normal"])
        _sphere_stage(mat)
        # A ball as Blender makes one, with its UV map (tangent-space normal maps need one).
        bpy.data.objects.remove(bpy.data.objects["Ball"])
        scenes.uv_sphere_add(radius=0.6, location=(0.0, 0.0, 0.6),
                             segments=64, ring_count=32)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(mat)
    return build


def metallic_bsdf(fresnel):
    """Blender 4.3+'s Metallic BSDF on the ball: F82 (base colour and edge tint, anisotropic
    along the sphere's radial tangent) or a physical conductor (Blender's default gold IOR and
    extinction)."""
    def build():
        mat, nt, out = node_material("Metal_" + fresnel)
        if fresnel == "F82":
            tan = node(nt, "ShaderNodeTangent", {"direction_type": "RADIAL", "axis": "Z"})
            m = node(nt, "ShaderNodeBsdfMetallic", {"fresnel_type": "F82"},
                     Base_Color=(0.9, 0.6, 0.3, 1.0), Edge_Tint=(0.95, 0.8, 0.6, 1.0),
                     Roughness=0.35, Anisotropy=0.6, Rotation=0.1)
            nt.links.new(tan.outputs["Tangent"], m.inputs["Tangent"])
        else:
            m = node(nt, "ShaderNodeBsdfMetallic", {"fresnel_type": "PHYSICAL_CONDUCTOR"},
                     Roughness=0.3)
        surface(nt, out, m.outputs[0])
        _sphere_stage(mat)
    return build


def wireframe_ball():
    """Dark wires over a light diffuse ball by the Wireframe node (world size 0.03 m)."""
    mat, nt, out = node_material("Wire")
    wire = node(nt, "ShaderNodeWireframe", Size=0.03)
    light = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.8, 0.8, 0.75, 1.0))
    dark = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.05, 0.1, 0.4, 1.0))
    mix = node(nt, "ShaderNodeMixShader", Fac=wire.outputs["Fac"])
    nt.links.new(light.outputs[0], mix.inputs[1])
    nt.links.new(dark.outputs[0], mix.inputs[2])
    surface(nt, out, mix.outputs[0])
    _sphere_stage(mat)


def ambient_occlusion(inside_local=False):
    """The Ambient Occlusion node. Floor: its Color output (a warm grey times the open
    fraction within 0.8 m) as a Diffuse colour, so the floor darkens towards the ball and a
    box beside it. Inside + Only Local: the ball's colour is the fraction of inward rays that
    leave the ball within 0.5 m (analytically cos^2 = (0.5 / 1.2)^2, 0.17, everywhere)."""
    def build():
        if inside_local:
            mat, nt, out = node_material("AOInside")
            ao = node(nt, "ShaderNodeAmbientOcclusion",
                      {"samples": 8, "inside": True, "only_local": True}, Distance=0.5)
            dif = node(nt, "ShaderNodeBsdfDiffuse", Color=ao.outputs["AO"])
            surface(nt, out, dif.outputs[0])
            _sphere_stage(mat)
            return
        fmat, fnt, fout = node_material("DirtFloor")
        ao = node(fnt, "ShaderNodeAmbientOcclusion", {"samples": 16},
                  Color=(0.8, 0.75, 0.7, 1.0), Distance=0.8)
        dif = node(fnt, "ShaderNodeBsdfDiffuse", Color=ao.outputs["Color"])
        surface(fnt, fout, dif.outputs[0])
        scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], fmat)
        scenes.add_sphere("Ball", (0.0, 0.0, 0.6), 0.6, lambert_mat("Ball", (0.6, 0.6, 0.6)),
                          segments=64, rings=32)
        scenes.add_box("Crate", (0.8, -0.2, 0.0), (1.3, 0.4, 0.5),
                       lambert_mat("Crate", (0.5, 0.4, 0.3)))
        scenes.add_sun_light("Sun", (-0.5, 0.6, -0.8), 3.0)
        world(0.6)
        scenes.add_camera((0.0, -2.6, 1.5), (0.0, 0.0, 0.55), fov=math.radians(40.0))
    return build


def bevel_box():
    """A 1 m box whose Principled (roughness 0.35) takes its normal from a Bevel node
    (radius 0.2 m, 8 samples), seen from near a corner: the edges shade as if rounded,
    catching the sun (with flat normals block p95 0.14)."""
    mat, nt, out = node_material("Bevelled")
    bev = node(nt, "ShaderNodeBevel", {"samples": 8}, Radius=0.2)
    p = node(nt, "ShaderNodeBsdfPrincipled", Base_Color=(0.6, 0.3, 0.2, 1.0), Roughness=0.35,
             Normal=bev.outputs["Normal"])
    surface(nt, out, p.outputs[0])
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    lambert_mat("Floor", (0.5, 0.5, 0.5)))
    scenes.add_box("Box", (-0.5, -0.5, 0.0), (0.5, 0.5, 1.0), mat)
    scenes.add_sun_light("Sun", (-0.4, 0.7, -0.6), 3.0)
    world(0.3)
    scenes.add_camera((1.1, -1.4, 1.6), (0.1, -0.1, 0.6), fov=math.radians(40.0))


def toon_ball(component):
    """The Toon BSDF on the ball: Diffuse (size 0.4, smooth 0.1), or Glossy (size 0.15,
    smooth 0.1) added to a dark Diffuse, under the sun and a dim world."""
    def build():
        mat, nt, out = node_material("Toon_" + component)
        size = 0.4 if component == "DIFFUSE" else 0.15
        toon = node(nt, "ShaderNodeBsdfToon", {"component": component},
                    Color=(0.8, 0.4, 0.2, 1.0), Size=size, Smooth=0.1)
        if component == "DIFFUSE":
            surface(nt, out, toon.outputs[0])
        else:
            dif = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.1, 0.1, 0.15, 1.0))
            add = node(nt, "ShaderNodeAddShader")
            nt.links.new(dif.outputs[0], add.inputs[0])
            nt.links.new(toon.outputs[0], add.inputs[1])
            surface(nt, out, add.outputs[0])
        _sphere_stage(mat)
    return build


def shader_to_rgb_toon():
    """The EEVEE toon set-up: Diffuse -> Shader to RGB -> a Constant Color Ramp -> Emission.
    Cycles leaves Shader to RGB out with its links, so the ramp reads its own Fac (0.6, not
    the default 0.5: past the second stop at 0.55) and the ball glows blue all over."""
    mat, nt, out = node_material("Toon")
    dif = node(nt, "ShaderNodeBsdfDiffuse")
    to_rgb = node(nt, "ShaderNodeShaderToRGB", Shader=dif.outputs[0])
    ramp = node(nt, "ShaderNodeValToRGB")
    ramp.color_ramp.interpolation = "CONSTANT"
    ramp.color_ramp.elements[0].color = (0.9, 0.4, 0.1, 1.0)
    ramp.color_ramp.elements[1].color = (0.2, 0.4, 0.9, 1.0)
    ramp.color_ramp.elements[1].position = 0.55
    ramp.inputs["Fac"].default_value = 0.6
    nt.links.new(to_rgb.outputs["Color"], ramp.inputs["Fac"])
    em = node(nt, "ShaderNodeEmission", Color=ramp.outputs["Color"])
    surface(nt, out, em.outputs[0])
    _sphere_stage(mat)


def sheen_bsdf():
    """The Sheen BSDF added to a dark Diffuse: the fabric look."""
    mat, nt, out = node_material("Velvet")
    dif = node(nt, "ShaderNodeBsdfDiffuse", Color=(0.05, 0.02, 0.1, 1.0))
    sh = node(nt, "ShaderNodeBsdfSheen", Color=(0.9, 0.5, 0.4, 1.0), Roughness=0.4)
    add = node(nt, "ShaderNodeAddShader")
    nt.links.new(dif.outputs[0], add.inputs[0])
    nt.links.new(sh.outputs[0], add.inputs[1])
    surface(nt, out, add.outputs[0])
    _sphere_stage(mat)


def rough_glass():
    """A 1.2 x 1.2 x 0.05 m Glass BSDF slab (roughness 0.3, GGX) 0.4 m in front of a textured
    wall, under a white world."""
    wall_img = image("WallTex", checker_px(32, 32, 8))
    wmat, wnt, wout = node_material("Wall")
    tex = image_node(wnt, wall_img)
    principled(wnt, wout, Base_Color=tex.outputs["Color"], Roughness=1.0, Specular_IOR_Level=0.0)
    uv_quad("Wall", [(-2, 1, -1), (2, 1, -1), (2, 1, 3), (-2, 1, 3)], wmat)
    gmat, gnt, gout = node_material("RoughGlass")
    g = node(gnt, "ShaderNodeBsdfGlass", {"distribution": "GGX"}, Color=(1, 1, 1, 1),
             Roughness=0.3, IOR=1.5)
    surface(gnt, gout, g.outputs[0])
    scenes.add_box("Pane", (-0.6, 0.55, 0.4), (0.6, 0.6, 1.6), gmat)
    # Lit by the world alone: a sun would light the wall through the rough glass (a caustic) and
    # reach rays inside the pane through its faces, both very noisy in both renderers.
    world(1.0)
    scenes.add_camera((0.0, -2.5, 1.0), (0.0, 1.0, 1.0), fov=math.radians(40.0))


# --------------------------------------------------------------------------------------------
# the cases

GLASS_NORMAL_MAP_REASON = (
    "rough glass under strong normal-map normals at grazing views: means 0.992x, block p95 "
    "0.054 against the 0.05 tolerance (max 0.17 in the far corner; before the glass normals "
    "were raised above the surface 0.82x, p95 0.69)")


def light_path_emitter(output):
    """Emission 0.2 + the Light Path output ``output`` (a depth), as a Math Multiply Add."""
    mat, nt, out = node_material("LightPath" + output.replace(" ", ""))
    lp = node(nt, "ShaderNodeLightPath")
    m = node(nt, "ShaderNodeMath", {"operation": "MULTIPLY_ADD"}, Value=lp.outputs[output])
    m.inputs[1].default_value = 1.0
    m.inputs[2].default_value = 0.2
    surface(nt, out, node(nt, "ShaderNodeEmission", Color=m.outputs[0], Strength=1.0).outputs[0])
    return mat


def light_path_depths_in_mirror():
    """Two emissive walls whose colour is 0.2 + Ray Depth (left) and 0.2 + Glossy Depth
    (right), seen directly and in a perfect mirror floor: 0.2 direct, 1.2 mirrored (Cycles
    counts the mirror bounce)."""
    scenes.clear_scene()
    scenes.add_quad("Mirror", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], scenes.mirror("M"))
    for name, output, x0, x1 in (("Left", "Ray Depth", -2, 0), ("Right", "Glossy Depth", 0, 2)):
        scenes.add_quad(name, [(x0, 1.5, 0.0), (x1, 1.5, 0.0), (x1, 1.5, 3), (x0, 1.5, 3)],
                        light_path_emitter(output))
    scenes.add_camera((0, -1.0, 0.5), (0, 1.0, 0.0), fov=math.radians(50))


def light_path_depth_lighting():
    """An emissive ball of colour 0.2 + Ray Depth lighting a diffuse floor: the floor is lit
    by 1.2 (light samples and bounce rays reach the ball one bounce in), the camera sees 0.2."""
    scenes.clear_scene()
    scenes.add_quad("Floor", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)],
                    scenes.lambert("D", (0.8, 0.8, 0.8)))
    scenes.add_sphere("Ball", (0, 0.5, 0.5), 0.4, light_path_emitter("Ray Depth"))
    scenes.add_camera((0, -2.5, 0.3), (0, 0.0, 0.2), fov=math.radians(50))


def transparent_depth_stack():
    """Four stacked planes, each Mix(Emission, Transparent, 0.7) coloured by a ramp over 0.25
    x Transparent Depth, seen from above: each plane farther down the stack is bluer."""
    scenes.clear_scene()
    mat, nt, out = node_material("TransparentDepth")
    lp = node(nt, "ShaderNodeLightPath")
    m = node(nt, "ShaderNodeMath", {"operation": "MULTIPLY"}, Value=lp.outputs["Transparent Depth"])
    m.inputs[1].default_value = 0.25
    ramp = node(nt, "ShaderNodeValToRGB", Fac=m.outputs[0])
    ramp.color_ramp.elements[0].color = (1.0, 0.2, 0.1, 1.0)
    ramp.color_ramp.elements[1].color = (0.1, 0.3, 1.0, 1.0)
    em = node(nt, "ShaderNodeEmission", Color=ramp.outputs["Color"], Strength=1.0)
    tr = node(nt, "ShaderNodeBsdfTransparent")
    mix = node(nt, "ShaderNodeMixShader", Fac=0.7)
    nt.links.new(em.outputs[0], mix.inputs[1])
    nt.links.new(tr.outputs[0], mix.inputs[2])
    surface(nt, out, mix.outputs[0])
    for i in range(4):
        z, o = 0.2 + 0.3 * i, 0.15 * i
        scenes.add_quad("Q%d" % i, [(-1 + o, -1 + o, z), (1, -1 + o, z), (1, 1, z), (-1 + o, 1, z)],
                        mat)
    scenes.add_camera((0, 0, 5), (0, 0, 0), ortho_scale=2.2)
    world(0.5)


def ray_portal_window():
    """A tinted Ray Portal BSDF (Blender 4.2+) pane with its Position and Direction unlinked:
    rays go on through it from where they hit, so the box behind it, the floor and the sun's
    shadow of the box are seen through the tint, and the pane's own shadow is tinted."""
    lit_floor((-0.3, 0.4, -1.0), (0.0, 0.0, 0.5))
    mat, nt, out = node_material("Portal")
    rp = node(nt, "ShaderNodeBsdfRayPortal")
    rp.inputs["Color"].default_value = (0.9, 0.6, 0.3, 1.0)
    surface(nt, out, rp.outputs[0])
    scenes.add_quad("Pane", [(-1.0, -0.5, 0.1), (1.0, -0.5, 0.1), (1.0, -0.5, 1.3),
                             (-1.0, -0.5, 1.3)], mat)
    scenes.add_box("Box", (-0.3, 0.2, 0.0), (0.3, 0.8, 0.6), scenes.lambert("B", (0.3, 0.6, 0.8)))


def lit_floor(sun_direction, camera_target):
    """A cleared scene with a 6 m grey floor under a sun of strength 3 along `sun_direction`,
    a dim world (0.3) and a camera at (0, -4, 3) looking at `camera_target` (40 degrees)."""
    scenes.clear_scene()
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("FloorMat", (0.8, 0.8, 0.8)))
    scenes.add_sun_light("Sun", sun_direction, 3.0)
    world(0.3)
    scenes.add_camera((0.0, -4.0, 3.0), camera_target, fov=math.radians(40.0))


def rounded_cube(make_material, custom_from_vertices):
    """A unit cube turned 0.6 rad, smooth, with normals bent outwards from its centre (the
    low-poly "rounded box" look): custom normals set from its vertices, or a Normal Edit
    modifier (Radial). Near its edges the normals turn away from the camera while the faces
    face it: Cycles shades such normals as they are (diffuse lights them, the specular layer
    reflects about them raised above the surface); flipping them towards the viewer left dark
    wedges."""
    lit_floor((-0.8, 0.3, -0.6), (0.0, 0.0, 0.4))
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, 0.0, 0.5))
    ob = bpy.context.active_object
    ob.data.materials.append(make_material())
    ob.rotation_euler = (0.0, 0.0, 0.6)
    me = ob.data
    me.polygons.foreach_set("use_smooth", [True] * len(me.polygons))
    if custom_from_vertices:
        me.normals_split_custom_set_from_vertices([tuple(v.co.normalized()) for v in me.vertices])
    else:
        ob.modifiers.new("Round", "NORMAL_EDIT").mode = "RADIAL"
    me.update()


def material_pass_index():
    """Three quads whose materials (Pass Index 1, 2, 3) emit 0.4 x Object Info's Material
    Index, seen from above: 0.4, 0.8 and 1.2."""
    scenes.clear_scene()
    for i in range(3):
        mat, nt, out = node_material("Index%d" % i)
        mat.pass_index = i + 1
        oi = node(nt, "ShaderNodeObjectInfo")
        m = node(nt, "ShaderNodeMath", {"operation": "MULTIPLY"}, Value=oi.outputs["Material Index"])
        m.inputs[1].default_value = 0.4
        surface(nt, out, node(nt, "ShaderNodeEmission", Color=m.outputs[0], Strength=1.0).outputs[0])
        x = -1.5 + i
        scenes.add_quad("Q%d" % i, [(x, -1.5, 0), (x + 1, -1.5, 0), (x + 1, 1.5, 0), (x, 1.5, 0)],
                        mat)
    scenes.add_camera((0, 0, 5), (0, 0, 0), ortho_scale=3.2)
    world(0.0)


def deformed_checker_ball(kind):
    """A smooth ball whose Diffuse colour is a Checker (scale 4) at its default Generated
    coordinates, deformed by a Displace modifier (0.3 along X), a Simple Deform twist or a
    shape key: Generated follows the undeformed shape, so the checks stay where they were on
    the ball and stretch with it."""
    def build():
        lit_floor((-0.4, 0.3, -1.0), (0.0, 0.0, 0.5))
        mat, nt, out = node_material("Checks")
        ch = node(nt, "ShaderNodeTexChecker", Scale=4.0)
        surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=ch.outputs["Color"]).outputs[0])
        ob = scenes.add_sphere("Ball", (0.0, 0.0, 0.7), 0.6, mat, segments=24, rings=12)
        if kind == "displace":
            m = ob.modifiers.new("D", "DISPLACE")
            m.strength, m.direction = 0.3, "X"
        elif kind == "twist":
            m = ob.modifiers.new("D", "SIMPLE_DEFORM")
            m.deform_method, m.angle = "TWIST", 1.2
        else:
            ob.shape_key_add(name="Basis")
            key = ob.shape_key_add(name="Squash")
            for v in key.data:
                v.co.z *= 0.6
                v.co.x *= 1.3
            key.value = 1.0
    return build


def checker_from_empty():
    """A ball whose Diffuse colour is a Checker over Texture Coordinate > Object with an Empty
    set (moved, turned and scaled unevenly): the checks sit in the Empty's space."""
    lit_floor((-0.4, 0.3, -1.0), (0.0, 0.0, 0.5))
    empty = bpy.data.objects.new("Placer", None)
    bpy.context.scene.collection.objects.link(empty)
    empty.location = (0.3, -0.2, 0.5)
    empty.rotation_euler = (0.4, 0.2, 0.9)
    empty.scale = (0.5, 1.0, 2.0)
    mat, nt, out = node_material("Placed")
    tc = node(nt, "ShaderNodeTexCoord", {"object": empty})
    ch = node(nt, "ShaderNodeTexChecker", Scale=2.0, Vector=tc.outputs["Object"])
    surface(nt, out, node(nt, "ShaderNodeBsdfDiffuse", Color=ch.outputs["Color"]).outputs[0])
    scenes.add_sphere("Ball", (0.0, 0.0, 0.7), 0.6, mat, segments=32, rings=16)


def normals_up_ball():
    """A low-poly smooth ball (10 x 6) whose custom normals all point up (the soft look of
    foliage), Principled at roughness 0.3, under a low sun: on its lower half the normals
    point against the faces' winding; a face is seen from the front by its winding, not by
    the normal. Cycles' shadow terminator offset is off (Tesela has none)."""
    lit_floor((-0.8, 0.3, -0.6), (0.0, 0.0, 0.4))
    scenes.uv_sphere_add(segments=10, ring_count=6, radius=0.6,
                         location=(0.0, 0.0, 0.6))
    ob = bpy.context.active_object
    ob.data.materials.append(scenes.material("Ball", base_color=(0.8, 0.8, 0.8), roughness=0.3))
    ob.shadow_terminator_geometry_offset = 0.0
    me = ob.data
    me.polygons.foreach_set("use_smooth", [True] * len(me.polygons))
    me.normals_split_custom_set([(0.0, 0.0, 1.0)] * len(me.loops))
    me.update()


# (id, builder, Cycles max_bounces, Cycles spp, Tesela spp)
CASES = [
    ("custom_normals_all_up", normals_up_ball, 0, 128, 512),
    ("texture_coordinates_of_an_empty", checker_from_empty, 0, 128, 512),
    ("generated_under_displace", deformed_checker_ball("displace"), 0, 128, 512),
    ("generated_under_twist", deformed_checker_ball("twist"), 0, 128, 512),
    ("generated_under_shape_key", deformed_checker_ball("shape_key"), 0, 128, 512),
    ("material_pass_index", material_pass_index, 0, 16, 64),
    ("rounded_cube_normal_edit_lambert",
     lambda: rounded_cube(lambda: scenes.lambert("D", (0.2, 0.3, 0.8)), False), 0, 128, 512),
    ("rounded_cube_custom_normals_principled",
     lambda: rounded_cube(lambda: scenes.material("Blue", base_color=(0.2, 0.3, 0.8),
                                                  roughness=0.3), True), 0, 128, 512),
    ("light_path_depths_in_mirror", light_path_depths_in_mirror, 2, 16, 64),
    ("light_path_depth_lighting", light_path_depth_lighting, 2, 256, 1024),
    ("transparent_depth_stack", transparent_depth_stack, 2, 64, 256),
    pytest.param(("ray_portal_window", ray_portal_window, 2, 64, 256), id="ray_portal_window",
                 marks=pytest.mark.skipif(not hasattr(bpy.types, "ShaderNodeBsdfRayPortal"),
                                          reason="the Ray Portal BSDF is a Blender 4.2 node")),
    ("packed_roughness_metallic", packed_rough_metal, 0, 256, 1024),
    ("normal_map_gentle_lambert", lambda: normal_map(0.02, (-0.3, 0.2, -1.0), 0.0), 0, 128, 512),
    ("normal_map_gentle_principled", lambda: normal_map(0.02, (-0.3, 0.2, -1.0)), 0, 128, 512),
    ("normal_map_metal_grazing_view", normal_map_glossy, 0, 128, 512),
    pytest.param(("normal_map_glass_grazing_view", normal_map_glass, 2, 128, 512),
                 marks=pytest.mark.xfail(reason=GLASS_NORMAL_MAP_REASON, strict=False)),
    ("glass_tinted_ball", glass_tinted_ball, 6, 128, 512),
    ("beckmann_glossy_ball", beckmann_ball("ShaderNodeBsdfGlossy", Color=(0.9, 0.6, 0.3, 1.0),
                                           Roughness=0.35), 2, 256, 1024),
    ("beckmann_anisotropic_ball", beckmann_ball("ShaderNodeBsdfGlossy", Roughness=0.5,
                                                Anisotropy=0.6), 2, 256, 1024),
    ("beckmann_glass_ball", beckmann_ball("ShaderNodeBsdfGlass", Roughness=0.3, IOR=1.45),
     6, 256, 1024),
    ("normal_map_grazing_sun_lambert", lambda: normal_map(specular=0.0), 0, 128, 512),
    # Mapped normals up to 63 degrees off under a sun 15 degrees high: Cycles' bump shadowing
    # of the diffuse part, the raised normal of the specular part, and diffuse shading from
    # normals that turn away from the viewer all show here.
    ("normal_map_grazing_sun", normal_map, 0, 128, 512),
    ("noise_bump", noise_bump, 0, 128, 512),
    ("displacement_bump_noise", displacement_bump, 0, 128, 512),
    ("vector_displacement_ball", vector_displacement_ball, 0, 128, 512),
    ("true_displacement_terrain", lambda: true_displacement_terrain("DISPLACEMENT"), 0, 128, 512),
    ("true_displacement_and_bump", lambda: true_displacement_terrain("BOTH"), 0, 128, 512),
    ("true_displacement_ball_seam", true_displacement_ball, 0, 128, 512),
    ("displacement_wave_ball", lambda: vector_displacement_ball(False), 0, 128, 512),
    ("image_box_projection", projected_image("BOX"), 0, 64, 256),
    ("image_sphere_projection_cubic", projected_image("SPHERE", "Cubic", "Generated"), 0, 64, 256),
    ("image_tube_projection", projected_image("TUBE", coords="Generated"), 0, 64, 256),
    ("mapping_scale_rotation", mapping_image, 0, 64, 256),
    ("mix_diffuse_glossy_layer_weight", mix_layer_weight, 0, 256, 1024),
    ("lowpoly_smooth_specular", lowpoly_smooth_specular, 2, 256, 1024),
    ("flat_and_mixed_shading", flat_and_mixed_shading, 2, 128, 512),
    ("oren_nayar_diffuse_ball", oren_nayar_ball("diffuse"), 2, 128, 512),
    ("oren_nayar_principled_ball", oren_nayar_ball("principled"), 2, 128, 512),
    ("principled_black_base", black_base_ball, 2, 128, 512),
    ("no_material_default_surface", no_material_ball, 2, 128, 512),
    ("principled_smooth_tinted", smooth_principled_ball, 2, 128, 512),
    ("principled_smooth_metal_f82_tint", smooth_tinted_metal, 2, 128, 512),
    ("random_per_island", random_per_island, 0, 64, 256),
    ("principled_ggx_half_metal", principled_ggx("metal"), 2, 128, 512),
    ("principled_ggx_rough_glass", principled_ggx("glass"), 6, 128, 512),
    ("pointiness", pointiness, 0, 64, 256),
    ("named_float_attribute_points", named_attribute("FLOAT", "POINT", "Fac"), 0, 64, 256),
    ("named_float_attribute_faces", named_attribute("FLOAT", "FACE", "Color"), 0, 64, 256),
    ("named_vector_attribute_points", named_attribute("FLOAT_VECTOR", "POINT", "Vector"),
     0, 64, 256),
    ("multiscatter_glossy_coloured", coloured_multiscatter("glossy"), 2, 128, 512),
    ("multiscatter_glass_coloured", coloured_multiscatter("glass"), 6, 128, 512),
    ("add_diffuse_glossy_fresnel", add_fresnel, 0, 256, 1024),
    ("alpha_cutout_shadow", alpha_cutout, 0, 128, 512),
    ("transparent_mix_shadow", transparent_mix, 0, 128, 512),
    # Principled at roughness 0.9: the specular layer's albedo decides the diffuse below.
    ("noise_color_ramp_floor", noise_ramp_floor, 0, 64, 256),
    ("noise_color_ramp_diffuse", lambda: noise_ramp_floor("diffuse"), 0, 64, 256),
    ("vertex_colour_second_uv", vertex_colour_uv2, 0, 64, 256),
    ("emission_image_room", emission_room, 3, 256, 2048),
    ("emission_light_falloff", emission_light_falloff, 2, 256, 1024),
    ("emitter_hidden_from_camera", emitter_hidden_from_camera, 2, 256, 1024),
    ("principled_coat", principled_variant("coat"), 0, 256, 1024),
    ("coat_over_normal_mapped_flakes", coated_normal_map("flakes"), 0, 256, 1024),
    ("coat_over_normal_mapped_dielectric", coated_normal_map("flakes_plastic"), 0, 256, 1024),
    ("coat_over_tilted_normal", coated_normal_map("tilted"), 0, 256, 1024),
    ("coat_normal_linked_tilted", coated_normal_map("tilted_coat_normal"), 0, 256, 1024),
    ("principled_sheen", principled_variant("sheen"), 0, 256, 1024),
    ("principled_sheen_over_coat", principled_variant("sheen_over_coat"), 0, 256, 1024),
    ("principled_emission_under_coat_and_sheen", principled_variant("emission_coat_sheen"),
     2, 256, 1024),
    ("wireframe_ball", wireframe_ball, 0, 128, 512),
    ("ambient_occlusion_floor", ambient_occlusion(), 2, 128, 512),
    ("ambient_occlusion_inside_local", ambient_occlusion(True), 0, 128, 512),
    ("bevel_box_edges", bevel_box, 0, 256, 1024),
    ("toon_diffuse_ball", toon_ball("DIFFUSE"), 0, 128, 512),
    ("toon_glossy_ball", toon_ball("GLOSSY"), 0, 256, 1024),
    ("shader_to_rgb_left_out", shader_to_rgb_toon, 0, 64, 256),
    ("metallic_bsdf_f82_anisotropic", metallic_bsdf("F82"), 0, 256, 1024),
    ("metallic_bsdf_physical_conductor", metallic_bsdf("PHYSICAL_CONDUCTOR"), 0, 256, 1024),
    # The Sheen BSDF is a sheen layer over a black base: it took the black-base bug's toll.
    ("sheen_bsdf_over_diffuse", sheen_bsdf, 0, 256, 1024),
    ("principled_subsurface", principled_variant("subsurface"), 2, 512, 2048),
    ("principled_thin_film", principled_variant("thin_film"), 0, 256, 1024),
    ("principled_thin_film_smooth", principled_variant("thin_film_smooth"), 0, 256, 1024),
    ("principled_thin_film_glass", principled_variant("thin_film_glass"), 6, 256, 1024),
    ("principled_thin_film_bubble", principled_variant("thin_film_bubble"), 6, 256, 1024),
    ("principled_subsurface_wide", principled_variant("subsurface_wide"), 2, 256, 1024),
    ("rough_glass_textured_wall", rough_glass, 4, 256, 1024),
]


def _case_id(c):
    return (c.values[0] if hasattr(c, "values") else c)[0]


def _save_png(arr, path):
    """Write a linear float (h, w, 4) array (rows top to bottom) as an sRGB PNG."""
    h, w = arr.shape[:2]
    img = bpy.data.images.new(path.stem, w, h, alpha=True, float_buffer=True)
    try:
        img.pixels.foreach_set(np.ascontiguousarray(arr[::-1], dtype=np.float32).ravel())
        img.filepath_raw = str(path)
        img.file_format = "PNG"
        img.save()
    finally:
        bpy.data.images.remove(img)


def _save(name, got, ref):
    out = os.environ.get("TESELA_TEST_SAVE")
    if not out:
        return
    d = Path(out)
    d.mkdir(parents=True, exist_ok=True)
    _save_png(got, d / f"{name}-tesela.png")
    _save_png(ref, d / f"{name}-cycles.png")
    np.save(d / f"{name}-tesela.npy", got)
    np.save(d / f"{name}-cycles.npy", ref)


def render_cycles(tmp_path, bounces, spp):
    scene = bpy.context.scene
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    return imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))


def render_tesela(tmp_path, bounces, spp):
    scene = bpy.context.scene
    scenes.configure_cycles(scene, SIZE, SIZE, 1, bounces, seed=7)  # resolution etc.
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return result_pixels(tmp_path)


@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_material_scene_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, build, bounces, cycles_spp, tesela_spp = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scenes.clear_scene()
    build()
    ref = render_cycles(tmp_path, bounces, cycles_spp)
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    got = render_tesela(tmp_path, bounces, tesela_spp)
    _save(name, got, ref)
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"


def test_broken_scene_fails(addon, tesela_bin, tmp_path, monkeypatch):
    """The comparison can fail: Tesela renders the Mapping scene, then the Mapping node's rotation
    changes (30 -> 40 degrees) before Cycles renders it; the images must then disagree."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scenes.clear_scene()
    mapping_image()
    got = render_tesela(tmp_path, 0, 256)
    mp = next(n for n in bpy.data.materials["Mapped"].node_tree.nodes if n.type == "MAPPING")
    mp.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(40.0))
    ref = render_cycles(tmp_path, 0, 64)
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"broken mapping: {result}")
    assert not result.ok, f"a 10-degree rotation change went unnoticed: {result}"
