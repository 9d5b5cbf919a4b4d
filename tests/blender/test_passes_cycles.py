"""Render passes through the add-on against Cycles' passes on the same scene (bpy 5).

A sun-lit floor, a UV sphere and a box (each its own object and material pass index), a small
emitter, a constant world seen at the top of the frame; View Layer > Passes: Depth, Mist,
Normal, Position, UV, Object Index, Material Index, Emission, Environment, Denoising Data. Both
renders are saved as multi-layer EXRs and read back channel by channel.

Criteria: the passes Cycles writes from the pixel's first sample (Depth, Position, indices)
agree per pixel up to where the two first samples fall in the pixel (edges): at least 96% of
pixels within 1% (depth) / 1 cm (position) / exactly (indices); averaged passes (Normal, UV,
Mist) within 0.02 per pixel for 95% of pixels; light passes (Emit, Env) with the agreement
thresholds (means within 2%, 8x8-block p95 within 5%); Combined unchanged by the passes.
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

OpenEXR = pytest.importorskip("OpenEXR")

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))


W, H = 80, 60
SPP = 32


def build_scene():
    scenes.clear_scene()
    scene = bpy.context.scene
    floor_mat = scenes.lambert("Floor", (0.6, 0.6, 0.6))
    floor_mat.pass_index = 1
    ball_mat = scenes.material("Ball", base_color=(0.8, 0.3, 0.2), roughness=0.4)
    ball_mat.pass_index = 2
    box_mat = scenes.lambert("Box", (0.2, 0.5, 0.8))
    box_mat.pass_index = 3
    glow = scenes.emitter("Glow", (1.0, 0.7, 0.4), 6.0)
    floor = scenes.add_quad("Floor", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], floor_mat)
    # A quad has no UV map unless asked for: give the floor one.
    floor.data.uv_layers.new(name="UVMap")
    for i, loop_uv in enumerate(floor.data.uv_layers[0].data):
        loop_uv.uv = [(0, 0), (1, 0), (1, 1), (0, 1)][i % 4]
    ball = scenes.add_sphere("Ball", (-0.6, 0.3, 0.7), 0.7, ball_mat)
    box = scenes.add_box("Box", (0.4, -0.6, 0.0), (1.3, 0.3, 0.9), box_mat)
    lamp = scenes.add_sphere("Lamp", (-1.7, -1.2, 0.3), 0.3, glow, segments=24, rings=12)
    for i, ob in enumerate((floor, ball, box, lamp)):
        ob.pass_index = 4 + i
    scenes.add_sun_light("Sun", (-0.4, 0.3, -0.85), 3.0)
    scenes.add_camera((0.0, -5.5, 2.2), (0.0, 0.6, 0.5), fov=math.radians(50.0))
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.3, 0.4, 0.6, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    world.mist_settings.start = 2.0
    world.mist_settings.depth = 6.0
    world.mist_settings.falloff = "LINEAR"
    vl = scene.view_layers[0]
    for toggle in ("use_pass_z", "use_pass_mist", "use_pass_normal", "use_pass_position",
                   "use_pass_uv", "use_pass_object_index", "use_pass_material_index",
                   "use_pass_emit", "use_pass_environment"):
        setattr(vl, toggle, True)
    vl.cycles.denoising_store_passes = True
    return scene


def render_multilayer(path):
    """Renders the scene and writes every pass to a multi-layer EXR; returns its passes, each
    (h, w, c) at the scene's resolution."""
    scene = bpy.context.scene
    pct = scene.render.resolution_percentage / 100.0
    h, w = round(scene.render.resolution_y * pct), round(scene.render.resolution_x * pct)
    s = scene.render.image_settings
    if hasattr(s, "media_type"):
        s.media_type = "MULTI_LAYER_IMAGE"
    s.file_format = "OPEN_EXR_MULTILAYER"
    s.color_depth = "32"
    scene.render.use_file_extension = False
    scene.render.filepath = str(path)
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    layers = {}
    for part in OpenEXR.File(str(path)).parts:  # Blender 5 writes one part per pass
        for name, ch in part.channels.items():
            px = np.asarray(ch.pixels, dtype=np.float32)
            layers[name.split(".", 1)[1] if "." in name else name] = px.reshape(h, w, -1)
    return layers


def pass_of(layers, name):
    """One pass (h, w, c) from the channels OpenEXR grouped (e.g. 'Depth.Z' or 'Normal')."""
    if name in layers:
        return layers[name]
    parts = sorted((k, v) for k, v in layers.items() if k.split(".")[0] == name)
    assert parts, f"no {name} pass in {sorted(layers)}"
    return np.concatenate([v for _, v in parts], axis=-1)


@pytest.fixture(scope="module")
def renders(addon, tesela_bin, tmp_path_factory):
    tmp = tmp_path_factory.mktemp("passes")
    os.environ["TESELA_BINARY"] = str(tesela_bin)
    scene = build_scene()
    scenes.configure_cycles(scene, W, H, SPP, 0, seed=3)
    ref = render_multilayer(tmp / "cycles.exr")
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    t.integrator, t.samples, t.max_depth, t.seed = "direct_mis", SPP * 4, 2, 1
    got = render_multilayer(tmp / "tesela.exr")
    # The same render without passes: Combined must not change.
    vl = scene.view_layers[0]
    for toggle in ("use_pass_z", "use_pass_mist", "use_pass_normal", "use_pass_position",
                   "use_pass_uv", "use_pass_object_index", "use_pass_material_index",
                   "use_pass_emit", "use_pass_environment"):
        setattr(vl, toggle, False)
    vl.cycles.denoising_store_passes = False
    plain = render_multilayer(tmp / "plain.exr")
    del os.environ["TESELA_BINARY"]
    return ref, got, plain


def test_combined_is_unchanged_by_passes(renders):
    _, got, plain = renders
    assert np.array_equal(pass_of(got, "Combined"), pass_of(plain, "Combined"))


def _fraction(ok):
    return float(np.count_nonzero(ok)) / ok.size


def _surface_blocks(depth, block=4):
    """Means of block x block tiles lying wholly on surfaces (no sky), and their mask."""
    h, w = depth.shape[:2]
    t = depth[: h // block * block, : w // block * block]
    t = t.reshape(h // block, block, w // block, block, -1)
    solid = (t < 1e9).all(axis=(1, 3, 4))
    return solid


def _block_means(img, block=4):
    h, w = img.shape[:2]
    t = img[: h // block * block, : w // block * block]
    return t.reshape(h // block, block, w // block, block, -1).mean(axis=(1, 3))


def test_depth_matches(renders):
    # Depth comes from each pixel's first sample, which falls elsewhere in the pixel in each
    # renderer: compare 4x4 block means on surfaces, and the sky mask per pixel.
    ref, got, _ = renders
    r, g = pass_of(ref, "Depth"), pass_of(got, "Depth")
    bg_r, bg_g = r[..., 0] > 1e9, g[..., 0] > 1e9
    assert bg_r.any() and (~bg_r).any(), "the scene must show both sky and surfaces"
    assert _fraction(bg_r == bg_g) >= 0.97, "background masks differ"
    solid = _surface_blocks(r) & _surface_blocks(g)
    rb, gb = _block_means(r)[solid], _block_means(g)[solid]
    rel = np.abs(gb - rb) / rb
    print("depth: %d blocks, median rel %.2e, 95th pct %.2e" % (
        len(rel), np.median(rel), np.percentile(rel, 95)))
    assert np.percentile(rel, 95) < 0.01


def test_depth_is_the_view_axis_distance_of_the_position(renders):
    # The definition itself, per pixel (both passes come from the same first sample).
    cam = bpy.context.scene.camera.matrix_world
    origin = np.array(cam.translation)
    forward = -np.array(cam.to_3x3().col[2])
    for which, layers in zip(("Cycles", "Tesela"), renders[:2]):
        depth, pos = pass_of(layers, "Depth")[..., 0], pass_of(layers, "Position")
        surf = depth < 1e9
        z = (pos - origin) @ forward
        err = np.abs(z[surf] - depth[surf]) / depth[surf]
        print(f"{which}: depth vs position, max rel {err.max():.2e}")
        assert err.max() < 1e-3, which


def test_position_matches(renders):
    ref, got, _ = renders
    solid = _surface_blocks(pass_of(ref, "Depth")) & _surface_blocks(pass_of(got, "Depth"))
    r, g = _block_means(pass_of(ref, "Position")), _block_means(pass_of(got, "Position"))
    d = np.linalg.norm(r - g, axis=-1)[solid]
    print("position: 95th pct %.4f m" % np.percentile(d, 95))
    # 1% of the scene's extent (6 m); a far floor pixel spans ~10 cm.
    assert np.percentile(d, 95) < 0.06


@pytest.mark.parametrize("name", ["Object Index", "Material Index"])
def test_indices_match(renders, name):
    ref, got, _ = renders
    r, g = pass_of(ref, name)[..., 0], pass_of(got, name)[..., 0]
    assert len(np.unique(r)) >= 4, f"{name}: the reference shows too few objects"
    print(f"{name}: agree on {_fraction(r == g):.4f} of pixels")
    assert _fraction(r == g) >= 0.96


@pytest.mark.parametrize("name, tol", [("Normal", 0.02), ("UV", 0.02), ("Mist", 0.02)])
def test_averaged_passes_match(renders, name, tol):
    ref, got, _ = renders
    r, g = pass_of(ref, name), pass_of(got, name)
    assert r.shape == g.shape
    assert np.abs(r).max() > 0.1, f"{name}: the reference is empty"
    err = np.abs(r - g).max(axis=-1)
    print(f"{name}: 95th pct error {np.percentile(err, 95):.4f}, mean {err.mean():.4f}")
    assert np.percentile(err, 95) < tol


@pytest.mark.parametrize("name", ["Emission", "Environment"])
def test_light_passes_match(renders, name):
    ref, got, _ = renders
    r, g = pass_of(ref, name), pass_of(got, name)
    assert r[..., :3].mean() > 0.005, f"{name}: the reference is black"
    pad = lambda a: np.concatenate([a[..., :3], np.ones(a.shape[:2] + (1,), np.float32)], -1)
    result = imgcompare.compare(pad(g), pad(r), mean_tol=0.02, block_tol=0.05)
    print(f"{name}: {result}")
    assert result.ok, f"{name}: {result}"


def test_denoising_data_is_written(renders):
    _, got, _ = renders
    albedo, normal = pass_of(got, "Denoising Albedo"), pass_of(got, "Denoising Normal")
    surf = pass_of(got, "Depth")[..., 0] < 1e9
    # The floor's albedo is its grey; normals are unit length on surfaces.
    assert 0.3 < float(np.median(albedo[surf][:, 0])) < 0.9
    n = np.linalg.norm(normal[surf], axis=-1)
    assert np.percentile(np.abs(n - 1.0), 90) < 0.05
