"""Run inside Blender 3.4 (test_material_graph.py::test_blender34_graph_uses_5x_vocabulary):
materials made of 3.x nodes (Principled v1, MixRGB, Separate RGB, Musgrave, Glossy Sharp, Velvet,
a 3.x Noise), a node group, a muted node and a reroute, and a world with a Nishita sky, exported
with the add-on.

    blender -b --factory-startup --addons tesela --python blender34_material_graph.py -- OUT.gltf
"""

import sys

import bpy

out_path = sys.argv[sys.argv.index("--") + 1]
scene = bpy.context.scene
for ob in list(scene.objects):
    bpy.data.objects.remove(ob, do_unlink=True)
scene.render.engine = "TESELA"
scene.render.resolution_x = scene.render.resolution_y = 8
cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
scene.collection.objects.link(cam)
scene.camera = cam


def material(name):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    return mat, nt, nt.nodes.new("ShaderNodeOutputMaterial")


def plane(name, mat, uvs=("UVMap",), x=0.0):
    me = bpy.data.meshes.new(name)
    me.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    for uv in uvs:
        me.uv_layers.new(name=uv)
    me.materials.append(mat)
    ob = bpy.data.objects.new(name, me)
    ob.location.x = x
    scene.collection.objects.link(ob)


img = bpy.data.images.new("Tex34", 2, 2)
img.pixels.foreach_set([0.5] * 16)

# Principled BSDF v1 with everything 4.0 converts.
mat, nt, out = material("Legacy Principled")
p = nt.nodes.new("ShaderNodeBsdfPrincipled")
nt.links.new(p.outputs[0], out.inputs["Surface"])
tex = nt.nodes.new("ShaderNodeTexImage")
tex.image = img
nt.links.new(tex.outputs["Color"], p.inputs["Base Color"])
p.inputs["Subsurface"].default_value = 0.5
p.inputs["Subsurface Color"].default_value = (0.9, 0.1, 0.1, 1.0)
p.inputs["Clearcoat"].default_value = 0.6
p.inputs["Sheen"].default_value = 0.5
p.inputs["Specular"].default_value = 0.4
p.inputs["Transmission"].default_value = 0.1
p.inputs["Emission"].default_value = (1.0, 0.5, 0.25, 1.0)
p.subsurface_method = "RANDOM_WALK"
sep = nt.nodes.new("ShaderNodeSeparateRGB")
nt.links.new(tex.outputs["Color"], sep.inputs["Image"])
mix = nt.nodes.new("ShaderNodeMixRGB")
mix.blend_type = "MULTIPLY"
nt.links.new(sep.outputs["R"], mix.inputs["Color1"])
nt.links.new(mix.outputs["Color"], p.inputs["Roughness"])
nmap = nt.nodes.new("ShaderNodeNormalMap")
nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
nt.links.new(nmap.outputs["Normal"], p.inputs["Normal"])
plane("Legacy", mat, uvs=("UVMap", "Second"))

# Textures and BSDFs 4.x replaced; a group, a muted node, a reroute; ramp and curves.
mat, nt, out = material("Legacy Textures")
gloss = nt.nodes.new("ShaderNodeBsdfGlossy")
gloss.distribution = "SHARP"
velvet = nt.nodes.new("ShaderNodeBsdfVelvet")
velvet.inputs["Sigma"].default_value = 0.7
musgrave = nt.nodes.new("ShaderNodeTexMusgrave")
musgrave.musgrave_type = "RIDGED_MULTIFRACTAL"
musgrave.inputs["Detail"].default_value = 4.0
musgrave.inputs["Dimension"].default_value = 1.0
musgrave.inputs["Lacunarity"].default_value = 2.0
mixs = nt.nodes.new("ShaderNodeMixShader")
nt.links.new(musgrave.outputs["Fac"], mixs.inputs["Fac"])
nt.links.new(gloss.outputs[0], mixs.inputs[1])
nt.links.new(velvet.outputs[0], mixs.inputs[2])
group = bpy.data.node_groups.new("LegacyGroupTree", "ShaderNodeTree")
group.inputs.new("NodeSocketFloat", "In")
gain = group.inputs.new("NodeSocketFloat", "Gain")
gain.default_value = 0.9
group.outputs.new("NodeSocketFloat", "Out")
gin = group.nodes.new("NodeGroupInput")
gout = group.nodes.new("NodeGroupOutput")
gmul = group.nodes.new("ShaderNodeMath")
gmul.operation = "MULTIPLY"
group.links.new(gin.outputs["In"], gmul.inputs[0])
group.links.new(gin.outputs["Gain"], gmul.inputs[1])
group.links.new(gmul.outputs[0], gout.inputs["Out"])
gnode = nt.nodes.new("ShaderNodeGroup")
gnode.node_tree = group
gnode.name = "LegacyGroup"
val = nt.nodes.new("ShaderNodeValue")
val.outputs[0].default_value = 0.3
muted = nt.nodes.new("ShaderNodeMath")
muted.name = "Muted Math"
muted.mute = True
reroute = nt.nodes.new("NodeReroute")
nt.links.new(val.outputs[0], muted.inputs[0])
nt.links.new(muted.outputs[0], reroute.inputs[0])
nt.links.new(reroute.outputs[0], gnode.inputs["In"])
ramp = nt.nodes.new("ShaderNodeValToRGB")
ramp.color_ramp.interpolation = "CONSTANT"
nt.links.new(gnode.outputs["Out"], ramp.inputs["Fac"])
curves = nt.nodes.new("ShaderNodeRGBCurve")
nt.links.new(ramp.outputs["Color"], curves.inputs["Color"])
noise = nt.nodes.new("ShaderNodeTexNoise")
emit = nt.nodes.new("ShaderNodeEmission")
nt.links.new(curves.outputs["Color"], emit.inputs["Color"])
nt.links.new(noise.outputs["Fac"], emit.inputs["Strength"])
add = nt.nodes.new("ShaderNodeAddShader")
nt.links.new(mixs.outputs[0], add.inputs[0])
nt.links.new(emit.outputs[0], add.inputs[1])
nt.links.new(add.outputs[0], out.inputs["Surface"])
plane("LegacyTex", mat, x=3.0)

# A float image with values above 1.
hdr = bpy.data.images.new("HDR34", 2, 1, float_buffer=True)
hdr.pixels.foreach_set([6.5, 0.25, 1.0, 1.0, 0.5, 2.0, 3.0, 1.0])
mat, nt, out = material("Legacy HDR")
em = nt.nodes.new("ShaderNodeEmission")
t = nt.nodes.new("ShaderNodeTexImage")
t.image = hdr
nt.links.new(t.outputs["Color"], em.inputs["Color"])
nt.links.new(em.outputs[0], out.inputs["Surface"])
plane("LegacyHDR", mat, x=6.0)

# A world lit by 3.x's Nishita sky (5.0: single scattering; "dust" became "aerosol").
world = bpy.data.worlds.new("Legacy Sky")
world.use_nodes = True
wnt = world.node_tree
for n in list(wnt.nodes):
    wnt.nodes.remove(n)
sky = wnt.nodes.new("ShaderNodeTexSky")
sky.name = "Nishita Sky"
sky.sky_type = "NISHITA"
sky.dust_density = 2.5
sky.sun_elevation = 0.5
bg = wnt.nodes.new("ShaderNodeBackground")
wnt.links.new(sky.outputs["Color"], bg.inputs["Color"])
wnt.links.new(bg.outputs[0], wnt.nodes.new("ShaderNodeOutputWorld").inputs["Surface"])
scene.world = world

assert bpy.ops.export_scene.tesela_gltf(filepath=out_path) == {"FINISHED"}
print("TESELA_GRAPH_EXPORTED", out_path)
