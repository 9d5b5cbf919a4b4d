"""A textured interior for the add-on benchmarks (bench/peers.py --clean, --addon): a closed
4 x 4 x 2.6 m room with a window, lit by a sun through it, a ceiling area light and a dim sky,
its materials node graphs as artists make them:

- floor: planks (an image) into a Principled base colour, roughness from a Noise texture through
  a Map Range, a tangent-space Normal Map;
- rug: a Brick texture into a Principled base colour, with a Bump from the same texture;
- walls and ceiling: an off-white Principled (specular layer on);
- a table and a glossy vase-like box: Principled with textured roughness and metallic 1.

Built with the Blender tests' helpers (tests/blender/scenes.py, test_material_scenes_cycles.py).
"""

import math

import numpy as np

import scenes
from test_material_scenes_cycles import (bumpy_normal_px, image, image_node, node, node_material,
                                         principled, uv_quad, world)


def _planks_px(w=128, h=128, planks=8):
    """Wood-like planks: bands of slightly different browns with grain stripes (sRGB)."""
    yy, xx = np.mgrid[0:h, 0:w]
    band = yy * planks // h
    rng = np.random.default_rng(3)
    tone = rng.uniform(0.75, 1.0, planks)[band]
    grain = 0.85 + 0.15 * np.sin(xx * 0.35 + band * 1.7 + 3.0 * np.sin(yy * 0.2))
    gap = ((yy * planks) % h) < 2
    px = np.ones((h, w, 4), dtype=np.float32)
    base = np.array([0.55, 0.36, 0.2])
    px[..., :3] = base * (tone * grain)[..., None]
    px[gap, :3] = 0.08
    return px


def textured_interior():
    x0, x1, y0, y1 = -2.0, 2.0, -2.0, 2.0

    # Floor: planks, noise roughness, normal map.
    mat, nt, out = node_material("Planks")
    tex = image_node(nt, image("Planks", _planks_px()))
    noise = node(nt, "ShaderNodeTexNoise", Scale=6.0, Detail=4.0)
    rough = node(nt, "ShaderNodeMapRange", From_Min=0.3, From_Max=0.7, To_Min=0.25,
                 To_Max=0.6, Value=noise.outputs["Fac"])
    nimg = image("PlankBumps", bumpy_normal_px(amp=0.02), non_color=True)
    ntex = image_node(nt, nimg)
    nm = node(nt, "ShaderNodeNormalMap", {"space": "TANGENT", "uv_map": "UVMap"}, Strength=1.0,
              Color=ntex.outputs["Color"])
    principled(nt, out, Base_Color=tex.outputs["Color"], Roughness=rough.outputs["Result"],
               Normal=nm.outputs["Normal"])
    uv_quad("Floor", [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], mat,
            uv=((0, 0), (3, 0), (3, 3), (0, 3)))

    # Walls and ceiling.
    wall, nt, out = node_material("Wall")
    principled(nt, out, Base_Color=(0.75, 0.72, 0.66, 1.0), Roughness=0.7)
    scenes.add_room(wall)

    # Rug: Brick texture colour and bump.
    rug, nt, out = node_material("Rug")
    coord = node(nt, "ShaderNodeTexCoord")
    brick = node(nt, "ShaderNodeTexBrick", Vector=coord.outputs["UV"], Scale=4.0,
                 Color1=(0.5, 0.08, 0.06, 1.0), Color2=(0.7, 0.5, 0.2, 1.0),
                 Mortar=(0.1, 0.1, 0.12, 1.0))
    bump = node(nt, "ShaderNodeBump", Strength=0.4, Height=brick.outputs["Fac"])
    principled(nt, out, Base_Color=brick.outputs["Color"], Roughness=0.9,
               Normal=bump.outputs["Normal"])
    uv_quad("Rug", [(-1.2, -0.6, 0.005), (0.8, -0.6, 0.005), (0.8, 1.0, 0.005),
                    (-1.2, 1.0, 0.005)], rug)

    # A table and a metal box on it, with textured roughness.
    table, nt, out = node_material("Table")
    principled(nt, out, Base_Color=(0.3, 0.2, 0.12, 1.0), Roughness=0.35)
    scenes.add_box("TableTop", (-0.6, 0.2, 0.7), (0.6, 1.0, 0.76), table)
    for i, (x, y) in enumerate([(-0.55, 0.25), (0.5, 0.25), (-0.55, 0.9), (0.5, 0.9)]):
        scenes.add_box(f"Leg{i}", (x, y, 0.0), (x + 0.05, y + 0.05, 0.7), table)
    metal, nt, out = node_material("Metal")
    wave = node(nt, "ShaderNodeTexWave", Scale=3.0, Distortion=2.0)
    mr = node(nt, "ShaderNodeMapRange", To_Min=0.15, To_Max=0.45, Value=wave.outputs["Fac"])
    principled(nt, out, Base_Color=(0.9, 0.7, 0.45, 1.0), Metallic=1.0,
               Roughness=mr.outputs["Result"])
    scenes.add_box("Box", (-0.2, 0.45, 0.76), (0.15, 0.8, 1.2), metal)

    scenes.add_sun_light("Sun", (0.3, 1.0, -0.7), 5.0, angle=math.radians(2.0))
    scenes.add_area_light("Ceiling light", (0.0, 0.3, 2.55), (0.0, 0.3, 0.0), 120.0, 0.8)
    world(0.3, (0.6, 0.75, 1.0))
    scenes.add_camera((1.7, -1.6, 1.6), (-0.4, 0.6, 0.6), fov=math.radians(75.0))
