"""Worlds through the add-on (TESELA_world's node graph) against Cycles on the same scene: an
HDRI generated in code (a gradient sky over a dark ground with a small bright "sun"), with and
without a Mapping rotation, a procedural gradient world, a Light Path "Is Camera Ray" backdrop
and a transparent film (alpha compared too). A diffuse and a glossy sphere on a diffuse plane
show the lighting, the camera sees the sky behind them.

Criteria: each channel's mean within 2%, 8x8 block means within 5% at the 95th percentile
(imgcompare.compare). Tesela's max depth = Cycles' max bounces + 2.
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

# The sun: a 3 x 3 texel patch of an HDRI_W x HDRI_H image, at azimuth ~62° (from +X towards
# +Y) and elevation ~42°, so shadows fall towards -X/-Y.
HDRI_W, HDRI_H = 128, 64
SUN_COL, SUN_ROW = 40, 47      # column from the left, row from the bottom (Blender's rows)
SUN_RADIANCE = 300.0


def hdri():
    """A float equirectangular image: a sky from pale blue at the horizon to deep blue at the
    zenith, a dark brown ground, and the sun patch."""
    img = bpy.data.images.new("TestSky", HDRI_W, HDRI_H, alpha=False, float_buffer=True)
    rows = (np.arange(HDRI_H) + 0.5) / HDRI_H          # Blender rows, bottom to top: v
    elevation = (rows - 0.5) * math.pi                  # -90° .. 90°
    px = np.ones((HDRI_H, HDRI_W, 4), dtype=np.float32)
    up = np.clip(np.sin(elevation), 0.0, 1.0)[:, None]
    sky = np.array([0.9, 1.0, 1.2]) * (1 - up[..., None]) + np.array([0.15, 0.3, 0.9]) * up[..., None]
    ground = np.array([0.12, 0.09, 0.06])
    px[..., :3] = np.where((elevation > 0)[:, None, None], sky, ground)
    # A slight azimuthal variation, so that a mirrored or rotated map shows.
    cols = (np.arange(HDRI_W) + 0.5) / HDRI_W
    px[..., 0] *= (1.0 + 0.3 * np.cos(2 * math.pi * cols))[None, :]
    px[SUN_ROW - 1:SUN_ROW + 2, SUN_COL - 1:SUN_COL + 2, :3] = [SUN_RADIANCE, 0.9 * SUN_RADIANCE,
                                                               0.75 * SUN_RADIANCE]
    img.pixels.foreach_set(px.ravel())
    img.update()
    return img


def base_scene():
    """The plane, a diffuse and a glossy sphere, and the camera looking at them with the
    horizon behind; no lights (the world lights everything)."""
    scene = scenes.clear_scene()
    scenes.add_quad("Plane", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                    scenes.lambert("Floor", (0.8, 0.8, 0.8)))
    scenes.add_sphere("Diffuse", (-0.65, 0.2, 0.5), 0.5, scenes.lambert("Clay", (0.7, 0.5, 0.3)))
    glossy = bpy.data.materials.new("Metal")
    nt = scenes._use_nodes(glossy)
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    g = nt.nodes.new("ShaderNodeBsdfGlossy")
    if hasattr(g, "distribution"):
        g.distribution = "GGX"
    g.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    g.inputs["Roughness"].default_value = 0.3
    nt.links.new(g.outputs[0], out.inputs["Surface"])
    scenes.add_sphere("Glossy", (0.65, -0.2, 0.5), 0.5, glossy)
    scenes.add_camera((0.4, -4.2, 1.5), (0.0, 0.0, 0.7), fov=math.radians(55.0))
    return scene


def _world_nodes(scene):
    world = scene.world
    nt = scenes._use_nodes(world)
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputWorld")
    return world, nt, out


def _env_background(nt, rotation_z=0.0, strength=1.0):
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = hdri()
    if rotation_z:
        tc = nt.nodes.new("ShaderNodeTexCoord")
        mp = nt.nodes.new("ShaderNodeMapping")
        mp.vector_type = "POINT"
        mp.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
        nt.links.new(tc.outputs["Generated"], mp.inputs["Vector"])
        nt.links.new(mp.outputs["Vector"], env.inputs["Vector"])
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = strength
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    return bg


def hdri_world(rotation_z=0.0):
    scene = base_scene()
    world, nt, out = _world_nodes(scene)
    nt.links.new(_env_background(nt, rotation_z).outputs[0], out.inputs["Surface"])
    return scene


def gradient_world():
    """A procedural world: a Gradient Texture (linear, along Blender's X: bright towards +X)
    mixing a deep blue and a warm white, strength 2."""
    scene = base_scene()
    world, nt, out = _world_nodes(scene)
    grad = nt.nodes.new("ShaderNodeTexGradient")
    grad.gradient_type = "LINEAR"
    tc = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(tc.outputs["Generated"], grad.inputs["Vector"])
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    sock = lambda socks, ident: next(s for s in socks if s.identifier == ident)  # noqa: E731
    sock(mix.inputs, "A_Color").default_value = (0.05, 0.08, 0.3, 1.0)
    sock(mix.inputs, "B_Color").default_value = (1.0, 0.9, 0.7, 1.0)
    nt.links.new(grad.outputs["Fac"], sock(mix.inputs, "Factor_Float"))
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = 2.0
    nt.links.new(sock(mix.outputs, "Result_Color"), bg.inputs["Color"])
    nt.links.new(bg.outputs[0], out.inputs["Surface"])
    return scene


def hidden_world(kinds):
    """The HDRI world hidden from the rays of ``kinds`` (world ray visibility), with a sun so
    that something stays lit: no sky light on diffuse closures, or no sky in the glossy
    sphere's reflections."""
    scene = hdri_world()
    scenes.add_sun_light("Sun", (0.3, 0.5, -0.8), 2.0)
    vis = scene.world.cycles_visibility
    for kind in kinds:
        setattr(vis, kind, False)
    return scene


def backdrop_world():
    """Light Path: the camera sees a flat red-orange backdrop, everything else the HDRI."""
    scene = base_scene()
    world, nt, out = _world_nodes(scene)
    lit = _env_background(nt)
    flat = nt.nodes.new("ShaderNodeBackground")
    flat.inputs["Color"].default_value = (0.9, 0.35, 0.2, 1.0)
    flat.inputs["Strength"].default_value = 1.0
    lp = nt.nodes.new("ShaderNodeLightPath")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(lp.outputs["Is Camera Ray"], mix.inputs["Fac"])
    nt.links.new(lit.outputs[0], mix.inputs[1])
    nt.links.new(flat.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    return scene


def mirror_ball_world():
    """The HDRI read with the Mirror Ball projection (the image taken as a photo of a chrome
    ball, seen from -Y), turned by a Mapping rotation."""
    scene = hdri_world(math.radians(-60.0))
    env = next(n for n in scene.world.node_tree.nodes if n.bl_idname == "ShaderNodeTexEnvironment")
    env.projection = "MIRROR_BALL"
    return scene


def transparent_film():
    scene = hdri_world()
    return scene


def holdout_film():
    """The transparent film with holdouts: the clay ball is Mix(Clay, Holdout) at 0.6, and a
    full Holdout box stands on the floor, in the glossy ball's reflection too; the camera sees
    holes (alpha 0.4 and 0) where Cycles cuts them, reflections and shadows stay."""
    scene = hdri_world()
    clay = bpy.data.materials["Clay"]
    nt = clay.node_tree
    out = next(n for n in nt.nodes if n.type == "OUTPUT_MATERIAL")
    bsdf = out.inputs["Surface"].links[0].from_node
    hold = nt.nodes.new("ShaderNodeHoldout")
    mix = nt.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.6
    nt.links.new(bsdf.outputs[0], mix.inputs[1])
    nt.links.new(hold.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    cut = bpy.data.materials.new("Cut")
    cnt = scenes._use_nodes(cut)
    cnt.nodes.clear()
    cout = cnt.nodes.new("ShaderNodeOutputMaterial")
    cnt.links.new(cnt.nodes.new("ShaderNodeHoldout").outputs[0], cout.inputs["Surface"])
    scenes.add_box("Cutout", (-0.2, -1.2, 0.0), (0.3, -0.7, 0.6), cut)
    return scene


def object_holdout():
    """The clay ball is a holdout object (Object > Visibility > Holdout): the camera sees a hole
    (black on an opaque film), the glossy ball still reflects the clay ball, which still
    shadows the floor."""
    scene = hdri_world()
    bpy.data.objects["Diffuse"].is_holdout = True
    return scene


def collection_holdout():
    """As object_holdout, the clay ball held out by a holdout collection of the view layer
    (Object > Visibility > Holdout stays off)."""
    scene = hdri_world()
    col = bpy.data.collections.new("Held")
    scene.collection.children.link(col)
    ball = bpy.data.objects["Diffuse"]
    for c in list(ball.users_collection):
        c.objects.unlink(ball)
    col.objects.link(ball)
    bpy.context.view_layer.layer_collection.children["Held"].holdout = True
    return scene


# (id, builder, Cycles max bounces, spp, film_transparent)
CASES = [
    ("hdri", lambda: hdri_world(), 4, 256, False),
    ("hdri_mapping_rot90", lambda: hdri_world(math.radians(90.0)), 4, 256, False),
    ("gradient", gradient_world, 4, 256, False),
    ("hdri_hidden_from_diffuse", lambda: hidden_world(["diffuse"]), 4, 256, False),
    ("hdri_hidden_from_glossy_transmission",
     lambda: hidden_world(["glossy", "transmission"]), 4, 256, False),
    ("light_path_backdrop", backdrop_world, 4, 256, False),
    ("film_transparent", transparent_film, 4, 256, True),
    ("film_transparent_holdout", holdout_film, 4, 256, True),
    ("mirror_ball", lambda: mirror_ball_world(), 4, 256, False),
    ("object_holdout_transparent", object_holdout, 4, 256, True),
    ("object_holdout_opaque", object_holdout, 4, 256, False),
    ("collection_holdout_transparent", collection_holdout, 4, 256, True),
]


# Film > Transparent > Transparent Glass: (id, glass builder, Cycles max bounces, spp,
# roughness threshold). Each sphere stands on the floor in front of the coloured world: the sky
# seen through the clear and the slightly rough glass (below the threshold) is transparent, the
# floor seen through it and the sky in its reflections are not; the rough glass (above the
# threshold) stays opaque, as without the setting.
GLASS_CASES = [
    ("transparent_glass_clear", lambda: glass_film("GLASS", 0.0), 8, 256, 0.1),
    ("transparent_glass_rough_below", lambda: glass_film("GLASS", 0.05), 8, 256, 0.1),
    ("transparent_glass_rough_above", lambda: glass_film("GLASS", 0.3), 8, 256, 0.1),
    ("transparent_glass_principled", lambda: glass_film("PRINCIPLED", 0.0), 8, 256, 0.1),
]


def glass_film(kind, roughness):
    """A glass sphere (a Glass BSDF, GGX, of ``roughness``, or a Principled BSDF with
    Transmission 1) on a small grey floor in front of a constant world (0.5, 0.55, 0.6), lit
    by a sun; the camera sees the sky above the floor's far edge, through the sphere too."""
    scene = scenes.clear_scene()
    scenes.add_quad("Floor", [(-1.5, -1.5, 0), (1.5, -1.5, 0), (1.5, 1.5, 0), (-1.5, 1.5, 0)],
                    scenes.lambert("Grey", (0.6, 0.6, 0.6)))
    if kind == "PRINCIPLED":
        mat = scenes.material("Glass", base_color=(1.0, 1.0, 1.0), roughness=roughness,
                              transmission=1.0, ior=1.45)
    else:
        mat, nt, g = scenes.shader_only("Glass", "ShaderNodeBsdfGlass")
        if hasattr(g, "distribution"):
            g.distribution = "GGX"
        g.inputs["Roughness"].default_value = roughness
        g.inputs["IOR"].default_value = 1.45
    scenes.add_sphere("Ball", (0.0, 0.0, 0.6), 0.6, mat)
    scenes.add_sun_light("Sun", (0.3, 0.5, -0.8), 2.0)
    world, nt, out = _world_nodes(scene)
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (0.5, 0.55, 0.6, 1.0)
    nt.links.new(bg.outputs[0], out.inputs["Surface"])
    scenes.add_camera((0.0, -4.0, 1.1), (0.0, 0.0, 0.6), fov=math.radians(40.0))
    return scene


def _render_both(tmp_path, monkeypatch, tesela_bin, case, glass=None):
    """Cycles' and Tesela's render of ``case``; ``glass``: Film > Transparent Glass on with
    that roughness threshold."""
    name, build, bounces, spp, transparent = case
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    scene = build()
    scenes.configure_cycles(scene, SIZE, SIZE, spp, bounces, seed=7)
    scene.render.film_transparent = transparent
    if glass is not None:
        scene.cycles.film_transparent_glass = True
        scene.cycles.film_transparent_roughness = glass
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "path_mis", spp, bounces + 2, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    assert bpy.ops.render.render() == {"FINISHED"}
    return ref, result_pixels(tmp_path)


def _case_id(c):
    return (c.values[0] if hasattr(c, "values") else c)[0]


@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_world_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    name, transparent = case[0], case[4]
    ref, got = _render_both(tmp_path, monkeypatch, tesela_bin, case)
    _check(name, ref, got, transparent)


@pytest.mark.parametrize("case", GLASS_CASES, ids=[_case_id(c) for c in GLASS_CASES])
def test_transparent_glass_agrees_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):
    """Film > Transparent Glass: colour and alpha as Cycles'."""
    name, build, bounces, spp, threshold = case
    ref, got = _render_both(tmp_path, monkeypatch, tesela_bin,
                            (name, build, bounces, spp, True), glass=threshold)
    _check(name, ref, got, True)


def _check(name, ref, got, transparent):
    """Colour (and, on a transparent film, alpha) within the module's tolerances."""
    assert ref[..., :3].mean() > 0.01, "the Cycles reference is black: the scene is broken"
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: Tesela (add-on) vs Cycles: {result}"
    if transparent:
        a_ref, a_got = ref[..., 3], got[..., 3]
        # The sky is a good part of the frame: some pixels are transparent, some opaque.
        assert 0.1 < a_ref.mean() < 0.9, a_ref.mean()
        alpha = imgcompare.compare(np.repeat(a_got[..., None], 3, -1),
                                   np.repeat(a_ref[..., None], 3, -1),
                                   mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
        print(f"{name} alpha: {alpha}")
        assert alpha.ok, f"{name}: alpha differs from Cycles': {alpha}"
    else:
        assert np.all(got[..., 3] == 1.0), "an opaque film has alpha 1 everywhere"


def test_world_hidden_from_camera_lights_but_shows_black(addon, tesela_bin, tmp_path,
                                                         monkeypatch):
    """world.cycles_visibility.camera off: the backdrop is black (alpha 1), the lighting stays."""
    case = ("camera_invisible", lambda: hdri_world(), 4, 256, False)

    def build():
        scene = hdri_world()
        scene.world.cycles_visibility.camera = False
        return scene
    ref, got = _render_both(tmp_path, monkeypatch, tesela_bin, (case[0], build) + case[2:])
    result = imgcompare.compare(got, ref, mean_tol=MEAN_TOL, block_tol=BLOCK_TOL)
    print(f"camera_invisible: {result}")
    assert result.ok, f"camera_invisible: Tesela (add-on) vs Cycles: {result}"
    # The top rows are sky: black in both.
    assert got[:4, :, :3].max() == 0.0 and ref[:4, :, :3].max() < 1e-6
