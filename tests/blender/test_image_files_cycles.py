"""Image textures read from files as artists have them, through the add-on against Cycles.

Cycles reads an unpacked image from its file and keeps an sRGB-tagged one sRGB-encoded whatever
its bit depth (`compress_as_srgb`), decoding after interpolation; a packed or generated image
comes from Blender's buffers, float ones already linear. A magnified, high-contrast texture
shows the difference: interpolating encoded values darkens the blends between texels (42%
darker on the 16-bit checker below, 2% on a bright blob in an HDR world). Cases: a 16-bit PNG
colour texture (the common export of texture painters) from its file and packed, an EXR tagged
sRGB, an 8-bit PNG, an sRGB EXR world seen directly and lighting a floor, and UDIM images
(8- and 16-bit PNG tiles, EXR tiles, packed tiles), whose tiles past the first only the files hold.

Criteria as tests/blender/test_lights_cycles.py: means within 2%, 8x8 blocks within 5% at the
95th percentile, edges locally.
"""

import math

import bpy
import numpy as np
import pytest

import scenes
from blender_addon.export.images import write_png
from test_lights_cycles import agrees_with_cycles


def _checker(n=8):
    """(n, n, 4) float colours, rows top to bottom: a strong checker in red, stripes in green,
    a ramp in blue (encoded values in [0, 1])."""
    yy, xx = np.mgrid[0:n, 0:n]
    px = np.ones((n, n, 4), np.float32)
    px[..., 0] = ((xx + yy) % 2) * 0.9 + 0.05
    px[..., 1] = (xx % 2) * 0.8 + 0.1
    px[..., 2] = yy / n
    return px


def _write(path, px):
    """An image file of encoded pixels `px` (rows top to bottom): 16-bit PNG, 8-bit PNG or EXR
    by the suffix."""
    if path.suffix == ".png" and path.stem.endswith("8"):
        img = bpy.data.images.new("tmp8", px.shape[1], px.shape[0], alpha=True)
        img.colorspace_settings.name = "Non-Color"  # store the values as given
        img.pixels.foreach_set(px[::-1].ravel())
        img.filepath_raw = str(path)
        img.file_format = "PNG"
        img.save()
        bpy.data.images.remove(img)
    elif path.suffix == ".png":
        write_png(str(path), px)
    else:
        img = bpy.data.images.new("tmpf", px.shape[1], px.shape[0], alpha=True, float_buffer=True)
        img.colorspace_settings.name = "Non-Color"
        img.pixels.foreach_set(px[::-1].ravel())
        img.filepath_raw = str(path)
        img.file_format = "OPEN_EXR"
        img.save()
        bpy.data.images.remove(img)


def _load(path, pack=False):
    img = bpy.data.images.load(str(path), check_existing=False)
    img.colorspace_settings.name = "sRGB"
    if pack:
        img.pack()
    return img


def _shown(img, name):
    """An emission material showing `img` (linear interpolation)."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image, tex.interpolation = img, "Linear"
    em = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(tex.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return mat


def textured_plane(tmp_path, name, pack=False):
    """An emissive plane showing a magnified 8x8 texture from the file `name`, filling the view."""
    scenes.clear_scene()
    path = tmp_path / name
    _write(path, _checker())
    img = _load(path, pack)
    assert img.is_float == (not name.endswith("8.png")), "the file loads as the test means"
    mat = _shown(img, "Shown")
    scenes.add_quad("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], mat)
    scenes.add_camera((0.0, 0.0, 2.2), (0.0, 0.0, 0.0), fov=math.radians(50.0))
    return scenes.SceneInfo(bpy.context.scene, "textured_plane")


def hdr_world(tmp_path, floor):
    """A world from an sRGB-tagged EXR with a small bright blob, seen directly (the camera
    aimed at the blob) or lighting a grey floor."""
    scenes.clear_scene()
    h, w = 32, 64
    yy, xx = np.mgrid[0:h, 0:w]
    px = np.ones((h, w, 4), np.float32) * 0.2
    px[..., 2] = 0.4
    blob = np.exp(-(((xx - 20) / 3.0) ** 2 + ((yy - 7) / 3.0) ** 2)) * 8.0
    px[..., 0] += blob
    px[..., 1] += blob
    px[..., 2] += 0.8 * blob
    px[..., 3] = 1.0
    path = tmp_path / "sky.exr"
    _write(path, px)
    world = bpy.context.scene.world
    nt = world.node_tree
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = _load(path)
    bg = nt.nodes["Background"]
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    bg.inputs["Strength"].default_value = 1.0
    if floor:
        scenes.add_quad("Floor", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
                        scenes.lambert("Grey", (0.6, 0.6, 0.6)))
        scenes.add_camera((0.0, -4.0, 2.5), (0.0, 0.0, 0.2), fov=math.radians(50.0))
    else:
        cam = scenes.add_camera((0.0, 0.0, 0.0), (0.287, 0.607, 0.741), fov=math.radians(60.0))
        cam.location = (0.0, 0.0, 0.0)
    return scenes.SceneInfo(bpy.context.scene, "hdr_world")


def _write_tile(path, px, kind):
    """A UDIM tile file: ``png8`` (through Blender), ``png16`` or ``exr``."""
    if kind == "png16":
        write_png(str(path), px)
        return
    img = bpy.data.images.new("tile", px.shape[1], px.shape[0], alpha=True,
                              float_buffer=kind == "exr")
    img.colorspace_settings.name = "Non-Color"  # store the values as given
    img.pixels.foreach_set(px[::-1].ravel())
    img.filepath_raw = str(path)
    img.file_format = "OPEN_EXR" if kind == "exr" else "PNG"
    img.save()
    bpy.data.images.remove(img)


def udim_plane(tmp_path, kinds, pack=False):
    """An emissive 10x10-face grid whose UVs span [0, 2]^2: four UDIM tiles 1001, 1002, 1011
    and 1012, of which the image has the first three (files of ``kinds``, each a differently
    tinted magnified checker; the fourth renders Cycles' missing-image magenta). Each face lies
    in one tile, so Cycles keeps every tile (it culls tiles no triangle's centroid is in)."""
    scenes.clear_scene()
    numbers = (1001, 1002, 1011)
    for number, kind, tint in zip(numbers, kinds, ((1, 1, 1), (0.3, 1, 0.6), (0.5, 0.6, 1))):
        px = _checker()
        px[..., :3] *= np.array(tint, np.float32)
        ext = "exr" if kind == "exr" else "png"
        _write_tile(tmp_path / ("skin.%d.%s" % (number, ext)), px, kind)
    ext = "exr" if kinds[0] == "exr" else "png"
    img = bpy.data.images.load(str(tmp_path / ("skin.1001.%s" % ext)), check_existing=False)
    img.source = "TILED"
    img.colorspace_settings.name = "sRGB"
    assert [t.number for t in img.tiles] == list(numbers), "Blender finds the tiles"
    if pack:
        img.pack()
    mat = _shown(img, "Skin")
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=11, y_subdivisions=11, size=2.0)
    grid = bpy.context.active_object
    grid.data.materials.append(mat)
    for loop_uv in grid.data.uv_layers.active.data:
        loop_uv.uv = (loop_uv.uv[0] * 2.0, loop_uv.uv[1] * 2.0)
    scenes.add_camera((0.0, 0.0, 2.2), (0.0, 0.0, 0.0), fov=math.radians(50.0))
    return scenes.SceneInfo(bpy.context.scene, "udim_plane")


# (id, builder taking tmp_path, Cycles max_bounces, Tesela integrator, spp)
CASES = [
    ("png16_file", lambda t: textured_plane(t, "checker.png"), 0, "direct_mis", 16),
    ("png16_packed", lambda t: textured_plane(t, "checker.png", pack=True), 0, "direct_mis", 16),
    ("exr_srgb_file", lambda t: textured_plane(t, "checker.exr"), 0, "direct_mis", 16),
    ("png8_file", lambda t: textured_plane(t, "checker8.png"), 0, "direct_mis", 16),
    ("srgb_exr_world_seen", lambda t: hdr_world(t, floor=False), 0, "direct_mis", 16),
    ("srgb_exr_world_lights_a_floor", lambda t: hdr_world(t, floor=True), 1, "path_mis", 256),
    ("udim_png8_png16_files", lambda t: udim_plane(t, ("png8", "png16", "png8")), 0,
     "direct_mis", 16),
    ("udim_exr_files", lambda t: udim_plane(t, ("exr",) * 3), 0, "direct_mis", 16),
    ("udim_png16_packed", lambda t: udim_plane(t, ("png16",) * 3, pack=True), 0,
     "direct_mis", 16),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_image_files_agree_with_cycles(addon, tesela_bin, tmp_path, monkeypatch, case):  # noqa: F811
    name, build, bounces, integrator, spp = case
    agrees_with_cycles(tesela_bin, tmp_path, monkeypatch,
                       (name, lambda: build(tmp_path), bounces, integrator, spp))
