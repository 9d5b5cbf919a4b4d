"""Scenes built the way artists build them (bpy.ops primitives and modifiers, node materials
from the default Principled, several light types, a world), through the add-on against Cycles.

Each combines many features at once, so a regression in any of them, or in how they interact
(a bump on a procedural, a Mix Shader by Layer Weight over a checker, glass, a disk light with
spread, a spot with blend and radius, a sun with an angle; modifiers, metaballs, text, curves
with bevel, negative scale, n-gons; layered Principled lobes; UV maps by name, face-corner
colours, box projection, a 16-bit normal map file; light tricks in the world), shows as a
disagreement with Cycles.

Criteria as tests/blender/test_lights_cycles.py: means within 2%, 8x8 blocks within 5% at the
95th percentile, edges locally.
"""

import math
import tempfile
from pathlib import Path

import bpy
import numpy as np
import pytest

import scenes
from blender_addon.export.images import write_png
from test_lights_cycles import agrees_with_cycles


def _principled(name):
    """A material as Blender makes one: nodes on, its default Principled BSDF."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    return m, m.node_tree, m.node_tree.nodes["Principled BSDF"]


def _world(color, strength):
    bg = bpy.context.scene.world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (*color, 1.0)
    bg.inputs["Strength"].default_value = strength


def procedural_studio():
    """Suzanne subdivided and smooth, Noise -> Color Ramp base colour, Voronoi -> Map Range
    roughness, a noise Bump; a checker floor mixing Diffuse and Glossy by Layer Weight; a rough
    glass ball; a disk light with spread, a spot with blend and radius, a sun with an angle."""
    scenes.clear_scene()
    bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0, 0, 0.6))
    mk = bpy.context.active_object
    mk.rotation_euler = (0.3, 0, 0.4)
    sub = mk.modifiers.new("Subd", "SUBSURF")
    sub.levels, sub.render_levels = 1, 2
    bpy.ops.object.shade_smooth()
    m, nt, p = _principled("Monkey")
    noise = nt.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 6.0
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.8, 0.2, 0.05, 1)
    ramp.color_ramp.elements[1].color = (0.9, 0.8, 0.3, 1)
    nt.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], p.inputs["Base Color"])
    vor = nt.nodes.new("ShaderNodeTexVoronoi")
    vor.inputs["Scale"].default_value = 8.0
    rng = nt.nodes.new("ShaderNodeMapRange")
    rng.inputs["To Min"].default_value, rng.inputs["To Max"].default_value = 0.2, 0.7
    nt.links.new(vor.outputs["Distance"], rng.inputs["Value"])
    nt.links.new(rng.outputs["Result"], p.inputs["Roughness"])
    bump = nt.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.3
    nt.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    nt.links.new(bump.outputs["Normal"], p.inputs["Normal"])
    mk.data.materials.append(m)
    bpy.ops.mesh.primitive_plane_add(size=8)
    floor = bpy.context.active_object
    m2, nt2, mix = scenes.shader_only("Floor", "ShaderNodeMixShader")
    chk = nt2.nodes.new("ShaderNodeTexChecker")
    chk.inputs["Scale"].default_value = 8.0
    chk.inputs["Color1"].default_value = (0.8, 0.8, 0.8, 1)
    chk.inputs["Color2"].default_value = (0.1, 0.1, 0.12, 1)
    dif, gl = nt2.nodes.new("ShaderNodeBsdfDiffuse"), nt2.nodes.new("ShaderNodeBsdfGlossy")
    gl.inputs["Roughness"].default_value = 0.15
    lw = nt2.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.3
    nt2.links.new(chk.outputs["Color"], dif.inputs["Color"])
    nt2.links.new(lw.outputs["Facing"], mix.inputs["Fac"])
    nt2.links.new(dif.outputs[0], mix.inputs[1])
    nt2.links.new(gl.outputs[0], mix.inputs[2])
    floor.data.materials.append(m2)
    scenes.uv_sphere_add(radius=0.35, location=(1.1, -0.4, 0.35))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    m3, _, glass = scenes.shader_only("Glass", "ShaderNodeBsdfGlass")
    glass.inputs["Roughness"].default_value = 0.1
    ball.data.materials.append(m3)
    disk = scenes.add_area_light("Disk", (-1.5, -1.0, 2.5), (0, 0, 0.5), 300.0, 1.0)
    disk.data.shape, disk.data.spread = "DISK", math.radians(70)
    scenes.add_spot_light("Spot", (1.5, -2.0, 2.0), (0, 0, 0.5), 400.0, math.radians(40),
                          blend=0.3, radius=0.1)
    scenes.add_sun_light("Sun", (0.4, 0.6, -1.0), 1.5, angle=math.radians(5))
    _world((0.3, 0.4, 0.6), 0.3)
    scenes.add_camera((0.5, -3.5, 1.8), (0.2, 0, 0.5), fov=math.radians(45))
    return scenes.SceneInfo(bpy.context.scene, "procedural_studio")


def modelled_props():
    """An array of bevelled cubes with point colours through Color Attribute, an anisotropic
    metal torus, an emissive strip, a point light with a radius; the camera focused with DOF."""
    scenes.clear_scene()
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(-1.2, 0, 0.15))
    cube = bpy.context.active_object
    arr = cube.modifiers.new("Arr", "ARRAY")
    arr.count, arr.relative_offset_displace = 6, (1.4, 0, 0)
    bev = cube.modifiers.new("Bev", "BEVEL")
    bev.width, bev.segments = 0.03, 2
    colors = cube.data.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    for i, v in enumerate(colors.data):
        v.color = ((i % 3) / 2.0, ((i // 3) % 3) / 2.0, 0.6, 1.0)
    m, nt, p = _principled("VC")
    attr = nt.nodes.new("ShaderNodeVertexColor")
    attr.layer_name = "Col"
    nt.links.new(attr.outputs["Color"], p.inputs["Base Color"])
    cube.data.materials.append(m)
    bpy.ops.mesh.primitive_torus_add(location=(0.2, 0.8, 0.4), major_radius=0.5,
                                     minor_radius=0.15)
    torus = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    torus.rotation_euler = (1.0, 0, 0)
    m2, _, p2 = _principled("Metal")
    p2.inputs["Metallic"].default_value, p2.inputs["Roughness"].default_value = 1.0, 0.3
    p2.inputs["Base Color"].default_value = (0.9, 0.6, 0.3, 1)
    p2.inputs["Anisotropic"].default_value = 0.6
    torus.data.materials.append(m2)
    bpy.ops.mesh.primitive_plane_add(size=10)
    m3, _, p3 = _principled("Ground")
    p3.inputs["Base Color"].default_value, p3.inputs["Roughness"].default_value = (0.5,) * 3 + (1,), 0.8
    bpy.context.active_object.data.materials.append(m3)
    bpy.ops.mesh.primitive_plane_add(size=1, location=(0, 2.0, 1.0))
    strip = bpy.context.active_object
    strip.scale, strip.rotation_euler = (2.0, 0.1, 1), (math.radians(90), 0, 0)
    m4, _, p4 = _principled("Strip")
    p4.inputs["Emission Color"].default_value = (1.0, 0.9, 0.7, 1)
    p4.inputs["Emission Strength"].default_value = 20.0
    p4.inputs["Base Color"].default_value = (0, 0, 0, 1)
    strip.data.materials.append(m4)
    scenes.add_point_light("Pt", (-1.0, -1.0, 2.0), 200.0, radius=0.3)
    _world((0.05, 0.05, 0.05), 1.0)
    cam = scenes.add_camera((0.0, -3.0, 1.2), (0, 0.3, 0.3), fov=math.radians(50))
    cam.data.dof.use_dof = True
    cam.data.dof.focus_distance, cam.data.dof.aperture_fstop = 3.1, 2.0
    return scenes.SceneInfo(bpy.context.scene, "modelled_props")


def geometry_kinds():
    """Smooth by angle, negative scale, text, a bevelled curve, a metaball, an n-gon prism, all
    glossy so that their normals show; a sun and an area light."""
    scenes.clear_scene()

    def glossy(name, color, rough, metal=0.0):
        m, _, p = _principled(name)
        p.inputs["Base Color"].default_value = (*color, 1)
        p.inputs["Roughness"].default_value, p.inputs["Metallic"].default_value = rough, metal
        return m
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, radius=0.35, depth=0.8,
                                        location=(-1.2, 0.3, 0.4))
    cyl = bpy.context.active_object
    if hasattr(bpy.ops.object, "shade_auto_smooth"):
        bpy.ops.object.shade_auto_smooth(angle=math.radians(40))
    else:
        bpy.ops.object.shade_smooth()
    cyl.data.materials.append(glossy("Cyl", (0.8, 0.3, 0.2), 0.2, 1.0))
    scenes.uv_sphere_add(radius=0.35, location=(-0.2, 0.6, 0.35))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    ball.scale = (-1, 1, 1)
    ball.data.materials.append(glossy("Sph", (0.2, 0.5, 0.8), 0.15))
    bpy.ops.object.text_add(location=(-0.9, -0.6, 0.02))
    text = bpy.context.active_object
    text.data.body, text.data.extrude, text.data.size = "Tesela", 0.05, 0.45
    text.data.materials.append(glossy("Txt", (0.9, 0.8, 0.2), 0.3, 1.0))
    bpy.ops.curve.primitive_bezier_circle_add(radius=0.3, location=(0.9, 0.5, 0.3))
    ring = bpy.context.active_object
    ring.data.bevel_depth = 0.06
    ring.data.materials.append(glossy("Ring", (0.7, 0.7, 0.7), 0.1, 1.0))
    ring.rotation_euler = (math.radians(60), 0, 0)
    bpy.ops.object.metaball_add(type="BALL", radius=0.3, location=(0.9, -0.4, 0.3))
    bpy.context.active_object.data.materials.append(glossy("Meta", (0.3, 0.8, 0.3), 0.4))
    n = 6
    ring_xy = [(0.25 * math.cos(2 * math.pi * i / n), 0.25 * math.sin(2 * math.pi * i / n))
               for i in range(n)]
    verts = [(x, y, 0.0) for x, y in ring_xy] + [(x, y, 0.5) for x, y in ring_xy]
    faces = [list(range(n))[::-1], list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    scenes.add_mesh("Prism", verts, faces, glossy("Pr", (0.8, 0.8, 0.8), 0.05),
                    location=(0.2, -0.2, 0))
    bpy.ops.mesh.primitive_plane_add(size=8)
    bpy.context.active_object.data.materials.append(glossy("Fl", (0.5, 0.5, 0.5), 0.8))
    scenes.add_sun_light("Sun", (0.5, 0.7, -0.8), 2.0, angle=math.radians(3))
    scenes.add_area_light("Box", (1.5, -2.0, 2.5), (0, 0, 0.3), 200.0, 1.5)
    _world((0.5, 0.5, 0.5), 0.5)
    scenes.add_camera((0.0, -3.2, 1.8), (0, 0.1, 0.3), fov=math.radians(45))
    return scenes.SceneInfo(bpy.context.scene, "geometry_kinds")


def world_tricks():
    """A world whose camera rays see a gradient while lighting comes from a dim colour (Light
    Path > Is Camera Ray into a Mix Shader), a Blackbody light and emitter, a Wave texture
    through Vector Rotate and a Float Curve into roughness, a checker in another object's
    coordinates."""
    scenes.clear_scene()
    nt = bpy.context.scene.world.node_tree
    seen = nt.nodes["Background"]
    grad, tc = nt.nodes.new("ShaderNodeTexGradient"), nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(tc.outputs["Generated"], grad.inputs["Vector"])
    ramp = nt.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.9, 0.5, 0.2, 1)
    ramp.color_ramp.elements[1].color = (0.2, 0.4, 1.0, 1)
    nt.links.new(grad.outputs["Fac"], ramp.inputs["Fac"])
    nt.links.new(ramp.outputs["Color"], seen.inputs["Color"])
    seen.inputs["Strength"].default_value = 1.5
    lighting = nt.nodes.new("ShaderNodeBackground")
    lighting.inputs["Color"].default_value = (0.6, 0.7, 0.8, 1)
    lighting.inputs["Strength"].default_value = 0.4
    path, mix = nt.nodes.new("ShaderNodeLightPath"), nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    nt.links.new(lighting.outputs[0], mix.inputs[1])
    nt.links.new(seen.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], nt.nodes["World Output"].inputs["Surface"])
    warm = scenes.add_point_light("Warm", (0.8, -0.8, 1.5), 150.0, radius=0.1)
    warm.data.use_nodes = True
    lnt = warm.data.node_tree
    bb = lnt.nodes.new("ShaderNodeBlackbody")
    bb.inputs["Temperature"].default_value = 3200
    lnt.links.new(bb.outputs["Color"], lnt.nodes["Emission"].inputs["Color"])
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.5, location=(0, 0.3, 0.5))
    ball = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    m, mt, p = _principled("Waves")
    wave, rot = mt.nodes.new("ShaderNodeTexWave"), mt.nodes.new("ShaderNodeVectorRotate")
    wave.inputs["Scale"].default_value, wave.inputs["Distortion"].default_value = 4.0, 2.0
    rot.inputs["Angle"].default_value = 0.7
    coords = mt.nodes.new("ShaderNodeTexCoord")
    mt.links.new(coords.outputs["Object"], rot.inputs["Vector"])
    mt.links.new(rot.outputs["Vector"], wave.inputs["Vector"])
    curve = mt.nodes.new("ShaderNodeFloatCurve")
    curve.mapping.curves[0].points[0].location = (0, 0.1)
    curve.mapping.curves[0].points[1].location = (1, 0.8)
    curve.mapping.update()
    mt.links.new(wave.outputs["Fac"], curve.inputs["Value"])
    mt.links.new(curve.outputs["Value"], p.inputs["Roughness"])
    p.inputs["Base Color"].default_value = (0.8, 0.75, 0.7, 1)
    ball.data.materials.append(m)
    bpy.ops.object.empty_add(location=(0.3, 0.2, 0))
    empty = bpy.context.active_object
    empty.scale, empty.rotation_euler = (0.5, 0.5, 0.5), (0, 0, 0.4)
    bpy.ops.mesh.primitive_plane_add(size=6)
    m2, nt2, p2 = _principled("ObjChecker")
    tc2, chk = nt2.nodes.new("ShaderNodeTexCoord"), nt2.nodes.new("ShaderNodeTexChecker")
    tc2.object = empty
    nt2.links.new(tc2.outputs["Object"], chk.inputs["Vector"])
    nt2.links.new(chk.outputs["Color"], p2.inputs["Base Color"])
    bpy.context.active_object.data.materials.append(m2)
    bpy.ops.mesh.primitive_plane_add(size=1, location=(-1.2, 0.8, 0.6))
    strip = bpy.context.active_object
    strip.scale, strip.rotation_euler = (0.15, 1, 1), (0, math.radians(90), 0.3)
    m3, n3, em = scenes.shader_only("Strip", "ShaderNodeEmission")
    bb3 = n3.nodes.new("ShaderNodeBlackbody")
    bb3.inputs["Temperature"].default_value = 8000
    em.inputs["Strength"].default_value = 6
    n3.links.new(bb3.outputs[0], em.inputs["Color"])
    strip.data.materials.append(m3)
    scenes.add_camera((0.0, -3.0, 1.6), (0, 0.2, 0.4), fov=math.radians(50))
    return scenes.SceneInfo(bpy.context.scene, "world_tricks")


def layered_principled():
    """Car paint (metallic under a clear coat), velvet (sheen), subsurface skin, brushed
    anisotropic metal, on a grey floor under two area lights."""
    scenes.clear_scene()

    def ball(name, location):
        scenes.uv_sphere_add(radius=0.4, location=location, segments=48,
                             ring_count=24)
        ob = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        m, _, p = _principled(name)
        ob.data.materials.append(m)
        return p
    p = ball("Paint", (-1.3, 0, 0.4))
    p.inputs["Base Color"].default_value = (0.6, 0.02, 0.03, 1)
    p.inputs["Metallic"].default_value, p.inputs["Roughness"].default_value = 0.7, 0.35
    p.inputs["Coat Weight"].default_value, p.inputs["Coat Roughness"].default_value = 1.0, 0.03
    p = ball("Velvet", (-0.45, 0.6, 0.4))
    p.inputs["Base Color"].default_value = (0.1, 0.2, 0.6, 1)
    p.inputs["Sheen Weight"].default_value, p.inputs["Sheen Roughness"].default_value = 1.0, 0.4
    p.inputs["Roughness"].default_value = 0.8
    p = ball("Skin", (0.45, 0.6, 0.4))
    p.inputs["Base Color"].default_value = (0.8, 0.55, 0.45, 1)
    p.inputs["Subsurface Weight"].default_value = 1.0
    p.inputs["Subsurface Radius"].default_value = (1.0, 0.4, 0.2)
    p.inputs["Subsurface Scale"].default_value = 0.1
    p = ball("Brushed", (1.2, -0.3, 0.4))
    p.inputs["Metallic"].default_value, p.inputs["Roughness"].default_value = 1.0, 0.3
    p.inputs["Anisotropic"].default_value = 0.8
    bpy.ops.mesh.primitive_plane_add(size=10)
    m, _, p = _principled("Floor")
    p.inputs["Base Color"].default_value = (0.4, 0.4, 0.4, 1)
    bpy.context.active_object.data.materials.append(m)
    scenes.add_area_light("Key", (-2, -2, 3), (0, 0, 0.4), 500.0, 2.0)
    scenes.add_area_light("Rim", (2, 2, 2), (0, 0, 0.4), 200.0, 1.0)
    _world((0.8, 0.85, 1.0), 0.3)
    scenes.add_camera((0.0, -3.6, 1.6), (0, 0.1, 0.4), fov=math.radians(45))
    return scenes.SceneInfo(bpy.context.scene, "layered_principled")


def uv_workflows():
    """A second UV map through a UV Map node, an Attribute node reading a UV map by name,
    face-corner byte colours multiplied in by a Mix node, a 16-bit Non-Color normal map file,
    a box-projected image in object coordinates, Generated coordinates on a scaled object."""
    scenes.clear_scene()
    folder = Path(tempfile.mkdtemp())
    n = 32
    yy, xx = np.mgrid[0:n, 0:n]
    f = 2 * math.pi * 3
    dx, dy = 0.3 * np.cos(f * xx / n), 0.3 * np.cos(f * yy / n)
    nrm = np.stack([-dx, -dy, np.ones_like(dx)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    px = np.ones((n, n, 4), np.float32)
    px[..., :3] = nrm * 0.5 + 0.5
    write_png(str(folder / "normals.png"), px)
    cp = np.ones((n, n, 4), np.float32)
    cp[..., 0] = (xx % 8 < 4) * 0.8 + 0.1
    cp[..., 1] = (yy % 8 < 4) * 0.6 + 0.2
    cp[..., 2] = 0.3
    write_png(str(folder / "colour.png"), cp)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-0.8, 0, 0.5))
    cube = bpy.context.active_object
    second = cube.data.uv_layers.new(name="Second")
    for loop in second.data:
        loop.uv = (loop.uv[0] * 2.0, loop.uv[1] * 0.5 + 0.25)
    corner = cube.data.color_attributes.new("Corner", "BYTE_COLOR", "CORNER")
    for i, c in enumerate(corner.data):
        c.color = ((i % 4) / 3.0, 0.5, 1.0 - (i % 4) / 3.0, 1.0)
    m, nt, p = _principled("Cube")
    uvmap, chk = nt.nodes.new("ShaderNodeUVMap"), nt.nodes.new("ShaderNodeTexChecker")
    uvmap.uv_map = "Second"
    chk.inputs["Scale"].default_value = 4
    nt.links.new(uvmap.outputs["UV"], chk.inputs["Vector"])
    vc = nt.nodes.new("ShaderNodeVertexColor")
    vc.layer_name = "Corner"
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
    mix.inputs["Factor"].default_value = 1.0
    nt.links.new(chk.outputs["Color"], mix.inputs[6])
    nt.links.new(vc.outputs["Color"], mix.inputs[7])
    nt.links.new(mix.outputs[2], p.inputs["Base Color"])
    nimg = nt.nodes.new("ShaderNodeTexImage")
    nimg.image = bpy.data.images.load(str(folder / "normals.png"))
    nimg.image.colorspace_settings.name = "Non-Color"
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "UVMap"
    nt.links.new(attr.outputs["Vector"], nimg.inputs["Vector"])
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nt.links.new(nimg.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], p.inputs["Normal"])
    p.inputs["Roughness"].default_value = 0.3
    cube.data.materials.append(m)
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.45, location=(0.6, 0.3, 0.45))
    egg = bpy.context.active_object
    egg.scale = (1.0, 1.0, 1.4)
    m2, nt2, p2 = _principled("Boxed")
    img = nt2.nodes.new("ShaderNodeTexImage")
    img.image = bpy.data.images.load(str(folder / "colour.png"))
    img.projection, img.projection_blend = "BOX", 0.2
    tc = nt2.nodes.new("ShaderNodeTexCoord")
    nt2.links.new(tc.outputs["Object"], img.inputs["Vector"])
    nt2.links.new(img.outputs["Color"], p2.inputs["Base Color"])
    grad = nt2.nodes.new("ShaderNodeTexGradient")
    grad.gradient_type = "SPHERICAL"
    nt2.links.new(tc.outputs["Generated"], grad.inputs["Vector"])
    nt2.links.new(grad.outputs["Fac"], p2.inputs["Roughness"])
    egg.data.materials.append(m2)
    bpy.ops.mesh.primitive_plane_add(size=8)
    m3, _, p3 = _principled("Fl")
    p3.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
    bpy.context.active_object.data.materials.append(m3)
    scenes.add_sun_light("Sun", (0.4, 0.7, -0.9), 3.0, angle=math.radians(2))
    _world((0.05, 0.05, 0.05), 1.0)
    scenes.add_camera((0.2, -2.6, 1.5), (0, 0.1, 0.4), fov=math.radians(45))
    return scenes.SceneInfo(bpy.context.scene, "uv_workflows")


# (id, builder, Cycles max_bounces, Tesela integrator, spp)
CASES = [
    ("procedural_studio", procedural_studio, 6, "path_mis", 2048),
    ("modelled_props", modelled_props, 6, "path_mis", 256),
    ("geometry_kinds", geometry_kinds, 6, "path_mis", 512),
    ("world_tricks", world_tricks, 6, "path_mis", 256),
    ("layered_principled", layered_principled, 6, "path_mis", 512),
    ("uv_workflows", uv_workflows, 6, "path_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_artist_scenes_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)
