"""Volumes (a material's Volume input) against Cycles (PyPI bpy 5.x), through the add-on: tinted
glass whose colour deepens with thickness, a volume-only box that casts a coloured shadow, and
scattering media: a fog box lit by a sun with a shaft of shadow through it, a Principled Volume
ball under a point light, a room-filling fog the camera stands in, a glowing volume, a
multiply-scattering cloud, and fog in the world lit by a spot light."""

import math

import bpy
import pytest

import scenes
from test_lights_cycles import agrees_with_cycles


def _absorption(nt, out, color, density):
    vol = nt.nodes.new("ShaderNodeVolumeAbsorption")
    vol.inputs["Color"].default_value = (*color, 1.0)
    vol.inputs["Density"].default_value = density
    nt.links.new(vol.outputs[0], out.inputs["Volume"])


def _stage():
    """A white floor and back wall under a sun and a dim grey world."""
    scenes.clear_scene()
    floor = scenes.lambert("Floor", (0.8, 0.8, 0.8))
    scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    scenes.add_quad("Back", [(-3, 1.5, 0), (3, 1.5, 0), (3, 1.5, 3), (-3, 1.5, 3)],
                    scenes.lambert("Wall", (0.7, 0.7, 0.7)))
    scenes.add_sun_light("Sun", (0.3, 0.5, -0.8), 3.0)
    world = bpy.context.scene.world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    scenes.add_camera((0.0, -4.0, 2.2), (0.0, 0.3, 0.5), fov=math.radians(50.0))


def tinted_glass():
    """A glass ball (IOR 1.45) with a blue-green absorbing interior in front of the wall: the
    colour deepens towards the centre, where the path inside is longest."""
    _stage()
    mat = scenes.glass("Tinted", ior=1.45)
    nt = mat.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    _absorption(nt, out, (0.2, 0.7, 0.9), 1.5)
    scenes.add_sphere("Ball", (0.0, 0.0, 0.7), 0.7, mat)
    return scenes.SceneInfo(bpy.context.scene, "tinted_glass")


def _volume_only(name):
    """A material with only a volume (no surface), its node tree and output."""
    mat = bpy.data.materials.new(name)
    scenes._use_nodes(mat)
    nt = mat.node_tree
    for n in list(nt.nodes):
        if n.type != "OUTPUT_MATERIAL":
            nt.nodes.remove(n)
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    # Blender 5 detects a homogeneous volume itself; 4.x asked (homogeneous_volume).
    if hasattr(getattr(mat, "cycles", None), "homogeneous_volume"):
        mat.cycles.homogeneous_volume = True
    return mat, nt, out


def absorbing_box():
    """A box with only a volume (no surface shader: rays pass its faces) over the floor: the
    floor seen through it and its shadow are tinted by exp(-sigma t)."""
    _stage()
    mat, nt, out = _volume_only("Smoke")
    _absorption(nt, out, (0.9, 0.4, 0.1), 1.2)
    # Lifted off the floor: a face coplanar with the floor would tie with it.
    scenes.add_box("Box", (-0.7, -0.5, 0.02), (0.7, 0.5, 1.0), mat)
    return scenes.SceneInfo(bpy.context.scene, "absorbing_box")


def fog_box():
    """A box of Volume Scatter fog (forward-scattering, anisotropy 0.4) over the floor with an
    opaque pillar inside it: the sun lights the fog except in the pillar's shadow shaft."""
    _stage()
    mat, nt, out = _volume_only("Fog")
    vol = nt.nodes.new("ShaderNodeVolumeScatter")
    vol.inputs["Color"].default_value = (0.9, 0.8, 0.6, 1.0)
    vol.inputs["Density"].default_value = 0.8
    vol.inputs["Anisotropy"].default_value = 0.4
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    scenes.add_box("Fog", (-1.2, -0.8, 0.02), (1.2, 0.8, 1.4), mat)
    scenes.add_box("Pillar", (-0.15, -0.15, 0.0), (0.15, 0.15, 1.8),
                   scenes.lambert("Pillar", (0.6, 0.6, 0.6)))
    return scenes.SceneInfo(bpy.context.scene, "fog_box")


def principled_volume_ball():
    """A ball of Principled Volume (orange scattering colour, blue-green absorption colour,
    backward-scattering) beside a point light of radius 0.1, over the floor."""
    _stage()
    bpy.data.objects.remove(bpy.data.objects["Sun"], do_unlink=True)
    scenes.add_point_light("Lamp", (0.9, -0.6, 1.6), 60.0, radius=0.1)
    mat, nt, out = _volume_only("Smoke")
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Color"].default_value = (0.9, 0.5, 0.2, 1.0)
    vol.inputs["Absorption Color"].default_value = (0.3, 0.6, 0.5, 1.0)
    vol.inputs["Density"].default_value = 2.5
    vol.inputs["Anisotropy"].default_value = -0.3
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    scenes.add_sphere("Ball", (0.0, 0.0, 0.75), 0.7, mat)
    return scenes.SceneInfo(bpy.context.scene, "principled_volume_ball")


def coefficients_ball():
    """A ball of Volume Coefficients (Blender 5.0: absorption, scattering and emission given
    per channel in 1/m): reddish scattering, blue-absorbing, a faint green glow, lit by a point
    light."""
    _stage()
    bpy.data.objects.remove(bpy.data.objects["Sun"], do_unlink=True)
    scenes.add_point_light("Lamp", (0.9, -0.6, 1.6), 60.0, radius=0.1)
    mat, nt, out = _volume_only("Coefficients")
    vol = nt.nodes.new("ShaderNodeVolumeCoefficients")
    vol.inputs["Absorption Coefficients"].default_value = (0.2, 0.6, 1.8)
    vol.inputs["Scatter Coefficients"].default_value = (2.0, 1.2, 0.6)
    vol.inputs["Anisotropy"].default_value = 0.3
    vol.inputs["Emission Coefficients"].default_value = (0.0, 0.15, 0.05)
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    scenes.add_sphere("Ball", (0.0, 0.0, 0.75), 0.7, mat)
    return scenes.SceneInfo(bpy.context.scene, "coefficients_ball")


def camera_in_fog():
    """Thin fog filling a large box around the whole stage, camera included: the floor and
    wall fade with distance and the sun's light scatters towards the camera."""
    _stage()
    mat, nt, out = _volume_only("Haze")
    vol = nt.nodes.new("ShaderNodeVolumeScatter")
    vol.inputs["Color"].default_value = (0.8, 0.85, 1.0, 1.0)
    vol.inputs["Density"].default_value = 0.15
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    scenes.add_box("Haze", (-6, -6, -1), (6, 6, 6), mat)
    scenes.add_box("Block", (-0.4, -0.3, 0.0), (0.4, 0.3, 0.8),
                   scenes.lambert("Block", (0.7, 0.3, 0.2)))
    return scenes.SceneInfo(bpy.context.scene, "camera_in_fog")


def glowing_volume():
    """A box whose volume is an Emission (radiance per metre) mixed with absorption: it glows,
    brightest where the path through it is longest, and lights the floor."""
    _stage()
    bpy.context.scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (
        0.05, 0.05, 0.05, 1.0)
    bpy.data.objects.remove(bpy.data.objects["Sun"], do_unlink=True)
    mat, nt, out = _volume_only("Glow")
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (1.0, 0.5, 0.2, 1.0)
    em.inputs["Strength"].default_value = 1.5
    ab = nt.nodes.new("ShaderNodeVolumeAbsorption")
    ab.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    ab.inputs["Density"].default_value = 1.0
    add = nt.nodes.new("ShaderNodeAddShader")
    nt.links.new(em.outputs[0], add.inputs[0])
    nt.links.new(ab.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    scenes.add_box("Glow", (-0.6, -0.4, 0.2), (0.6, 0.4, 1.0), mat)
    return scenes.SceneInfo(bpy.context.scene, "glowing_volume")


def white_cloud():
    """A dense, nearly white Volume Scatter ball (albedo 0.95, optical radius 4) lit by a sun,
    with eight volume bounces: multiple scattering carries light through to its shadowed side
    (with Cycles' default of none, that side would be dark)."""
    _stage()
    mat, nt, out = _volume_only("Cloud")
    vol = nt.nodes.new("ShaderNodeVolumeScatter")
    vol.inputs["Color"].default_value = (0.95, 0.95, 0.95, 1.0)
    vol.inputs["Density"].default_value = 6.0
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    scenes.add_sphere("Cloud", (0.0, 0.0, 0.8), 0.65, mat)
    return scenes.SceneInfo(bpy.context.scene, "white_cloud", {"volume_bounces": 8})


def fog_lit_by_the_world(volume_bounces):
    """A box of Principled Volume fog around a block, lit by the world alone (a grey sky):
    at a scattering point the world is sampled as a light and reached by the phase function's
    rays, which leave the fog through its boundary (a surface without a shader) even at the
    last volume bounce, as in Cycles. Cycles' default of 0 volume bounces, and 1."""
    def build():
        _stage()
        bpy.data.objects.remove(bpy.data.objects["Sun"], do_unlink=True)
        bg = next(n for n in bpy.context.scene.world.node_tree.nodes if n.type == "BACKGROUND")
        bg.inputs["Color"].default_value = (0.8, 0.85, 1.0, 1.0)
        bg.inputs["Strength"].default_value = 1.0
        mat, nt, out = _volume_only("WorldLitFog")
        vol = nt.nodes.new("ShaderNodeVolumePrincipled")
        vol.inputs["Color"].default_value = (0.8, 0.85, 0.9, 1.0)
        vol.inputs["Density"].default_value = 0.4
        nt.links.new(vol.outputs[0], out.inputs["Volume"])
        scenes.add_box("Fog", (-1.5, -1.2, 0.01), (1.5, 1.2, 2.0), mat)
        scenes.add_box("Block", (-0.4, -0.3, 0.0), (0.4, 0.3, 0.8),
                       scenes.lambert("Block", (0.7, 0.3, 0.2)))
        return scenes.SceneInfo(bpy.context.scene, "fog_lit_by_the_world",
                                {"volume_bounces": volume_bounces})
    return build


def world_fog():
    """Fog in the world (the World Output's Volume: a Principled Volume) lit by a spot light,
    whose cone shows in the fog, and a small area light; the sun is removed, as Cycles' world
    fog extinguishes light from infinitely far away (and the sky behind it)."""
    _stage()
    bpy.data.objects.remove(bpy.data.objects["Sun"], do_unlink=True)
    scenes.add_spot_light("Spot", (0.8, -0.4, 2.6), (0.0, 0.3, 0.0), 400.0,
                          math.radians(40.0), blend=0.3, radius=0.05)
    scenes.add_area_light("Panel", (-1.5, -1.0, 2.0), (0.0, 0.0, 0.5), 60.0, 0.5)
    scenes.add_box("Block", (-0.4, -0.3, 0.0), (0.4, 0.3, 0.8),
                   scenes.lambert("Block", (0.7, 0.3, 0.2)))
    world = bpy.context.scene.world
    nt = world.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_WORLD")
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Color"].default_value = (0.9, 0.9, 0.85, 1.0)
    vol.inputs["Density"].default_value = 0.12
    vol.inputs["Anisotropy"].default_value = 0.2
    nt.links.new(vol.outputs[0], out.inputs["Volume"])
    return scenes.SceneInfo(bpy.context.scene, "world_fog")


CASES = [
    ("tinted_glass", tinted_glass, 8, "path_mis", 512),
    ("absorbing_box", absorbing_box, 4, "path_mis", 512),
    ("fog_box", fog_box, 4, "path_mis", 512),
    ("principled_volume_ball", principled_volume_ball, 4, "path_mis", 512),
    ("camera_in_fog", camera_in_fog, 4, "path_mis", 512),
    pytest.param(("coefficients_ball", coefficients_ball, 4, "path_mis", 512),
                 id="coefficients_ball",
                 marks=pytest.mark.skipif(not hasattr(bpy.types, "ShaderNodeVolumeCoefficients"),
                                          reason="Volume Coefficients is a Blender 5.0 node")),
    ("glowing_volume", glowing_volume, 4, "path_mis", 1024),
    ("white_cloud", white_cloud, 12, "path_mis", 512),
    ("world_fog", world_fog, 4, "path_mis", 512),
    ("fog_lit_by_the_world_0", fog_lit_by_the_world(0), 2, "path_mis", 256),
    ("fog_lit_by_the_world_1", fog_lit_by_the_world(1), 2, "path_mis", 256),
]


@pytest.mark.parametrize("case", CASES, ids=[None if hasattr(c, "marks") else c[0] for c in CASES])
def test_volume_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch, case)
