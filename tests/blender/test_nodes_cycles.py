"""Per node: Tesela, through the add-on (F12 path), computes what Cycles computes.

Method. An orthographic camera looks straight down at geometry filling its view exactly (the
square [-1, 1]² of the XY plane, N x N pixels, one pixel = 2/N m). The material is an Emission
shader (strength 1) whose Color is the output of the node under test, so the rendered radiance
*is* the node's value (floats reach the colour socket as grey, vectors as RGB). Both renderers
see only that emission (Cycles: max bounces 0; Tesela: max depth 1) and the two 32-bit EXRs are
compared pixel by pixel.

Pixel-centre sampling. Cycles is rendered with 1 sample and a 0.01-pixel filter: its sample lies
within 0.005 px of the pixel centre. Tesela's box filter samples the whole pixel (an
Owen-scrambled Sobol point per sample). So that both evaluate the node at the same point, the
inputs are *snapped*: the coordinate a case reads (Object, UV, Generated, Position) goes through
``floor(v * N / 2) + 0.5`` (Vector Math, exact in binary floating point), which is constant over
each pixel and equals the pixel centre's value, then through an exact affine map (power-of-two
scales, dyadic offsets) into the domain the case wants. Where the geometry itself carries the
value (Normal, Incoming, Backfacing, Layer Weight, Fresnel, Object Info) it is constant per pixel:
one flat facet or one object per pixel block. Tesela then renders 1 sample per pixel, twice with
different seeds; a pixel whose sample fell within rounding distance of a pixel edge (measured:
3 of 819,200 samples on the plane) may land in the neighbouring cell, or slip between two
facets (Tesela's Möller-Trumbore test is not watertight: ~1 in 1,500 samples on the facet dome,
which then see the world), and the two renders then disagree: such pixels (at most 0.2%, in
practice 0-3 per image) are left out, all others are compared. Linear fields that cannot
be snapped (raw coordinates, interpolated vertex colours) use 64 samples per pixel, whose mean is
the centre value to ~1e-5. ``test_pixel_centre_sampling`` measures all this.

What depends on the viewing ray or the camera (Incoming, Reflection, Camera coordinates,
Backfacing, Layer Weight, Fresnel, normals of back faces, Bump, Normal Map) is seen instead
through a Diffuse BSDF (roughness 0) under a constant white world that is not sampled as a
light: one cosine-sampled bounce (Cycles: max bounces 0; Tesela: path_mats, depth 2) returns
exactly the albedo, without noise, on the plane and on the convex facet dome. A few are also
seen through Emission, whose shading point must be the hit's own.

Criteria: continuous outputs: max |Tesela - Cycles| / max(1, |Cycles|) over RGB below ``tol``
(default 1e-3); discontinuous outputs (cells, steps, comparisons): fraction of pixels off by
more than ``OFF`` = 1e-3 below ``frac`` (default 1%). (Measured: snapped cases agree to
< 1e-5, most bit for bit; averaged ones to < 4e-5, a curved Bump height to 3.4e-4.) Outputs
that can be negative get a constant added in the graph (Tesela drops samples with negative
radiance, Cycles does not).
Needs the renderer binary (conftest.py's ``tesela_bin``).
"""

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

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

N = 64           # image side in pixels
OFF = 1e-3       # discontinuous outputs: a pixel is "off" beyond this error
HALF = N // 2    # pixels per metre across the [-1, 1] view


# --------------------------------------------------------------------------------------------
# graph building


def _sock(sockets, key):
    """A socket by identifier, else by name (bpy's [] looks up names, which repeat)."""
    for s in sockets:
        if s.identifier == key:
            return s
    return sockets[key]


class G:
    """A material's node tree with helpers that build the snapped input fields."""

    def __init__(self, mat):
        self.mat = mat
        self.nt = mat.node_tree
        self._snapped = {}

    def new(self, kind, props=None, **inputs):
        """A node of ``kind``; ``props`` set first (they change which sockets exist), then the
        inputs by identifier: a socket links, anything else is the default value."""
        n = self.nt.nodes.new(kind)
        for k, v in (props or {}).items():
            setattr(n, k, v)
        for k, v in inputs.items():
            self.set(n, k, v)
        return n

    def set(self, node, key, v):
        sock = _sock(node.inputs, key)
        if isinstance(v, bpy.types.NodeSocket):
            self.nt.links.new(v, sock)
        else:
            sock.default_value = v

    def out(self, node, key=None):
        return node.outputs[0] if key is None else _sock(node.outputs, key)

    # maths ------------------------------------------------------------------------------

    def math(self, op, a, b=None, c=None, clamp=False):
        ins = {"Value": a}
        if b is not None:
            ins["Value_001"] = b
        if c is not None:
            ins["Value_002"] = c
        return self.new("ShaderNodeMath", {"operation": op, "use_clamp": clamp}, **ins).outputs[0]

    def vmath(self, op, a, b=None, c=None, scale=None, value=False):
        ins = {"Vector": a}
        if b is not None:
            ins["Vector_001"] = b
        if c is not None:
            ins["Vector_002"] = c
        if scale is not None:
            ins["Scale"] = scale
        n = self.new("ShaderNodeVectorMath", {"operation": op}, **ins)
        return _sock(n.outputs, "Value" if value else "Vector")

    def sep(self, v):
        n = self.new("ShaderNodeSeparateXYZ", Vector=v)
        return n.outputs["X"], n.outputs["Y"], n.outputs["Z"]

    def comb(self, x, y, z):
        return self.new("ShaderNodeCombineXYZ", X=x, Y=y, Z=z).outputs[0]

    # snapped fields ----------------------------------------------------------------------

    def snapped(self, source="Object"):
        """The pixel-centre value of a coordinate, constant over each pixel, mapped to
        [-1, 1]² (x right, y up; z = 0): ``source`` is a Texture Coordinate output (Object,
        Generated, UV) or ``Position`` (Geometry), or a UV map name prefixed ``uv:``."""
        if source in self._snapped:
            return self._snapped[source]
        if source == "Position":
            raw = self.new("ShaderNodeNewGeometry").outputs["Position"]
        elif source.startswith("uv:"):
            raw = self.new("ShaderNodeUVMap", {"uv_map": source[3:]}).outputs["UV"]
        else:
            raw = self.new("ShaderNodeTexCoord").outputs[source]
        unit = source in ("Object", "Position")  # [-1, 1] across the view, else [0, 1]
        k = HALF if unit else N
        cell = self.vmath("FLOOR", self.vmath("MULTIPLY", raw, (k, k, 0.0)))
        b = 0.5 if unit else 0.5 - HALF
        s = self.vmath("MULTIPLY", self.vmath("ADD", cell, (b, b, 0.0)),
                       (1.0 / HALF, 1.0 / HALF, 0.0))
        self._snapped[source] = s
        return s

    def p(self, scale=(1.0, 1.0), offset=(0.0, 0.0, 0.0), source="Object"):
        """A 3D input: the snapped [-1, 1]² field times ``scale`` (x, y) plus ``offset``."""
        return self.vmath("MULTIPLY_ADD", self.snapped(source), (scale[0], scale[1], 0.0), offset)

    def xy(self, source="Object"):
        x, y, _ = self.sep(self.snapped(source))
        return x, y

    def lin(self, cx, cy, c0, source="Object"):
        """The float field ``cx * x + cy * y + c0`` over the snapped [-1, 1]²."""
        x, y = self.xy(source)
        return self.math("MULTIPLY_ADD", x, cx, self.math("MULTIPLY_ADD", y, cy, c0))

    def vec(self, rows, source="Object"):
        """A vector field, one ``(cx, cy, c0)`` row per component."""
        return self.comb(*(self.lin(*r, source=source) for r in rows))

    def color_a(self):
        return self.vec([(0.45, 0.0, 0.5), (0.0, 0.45, 0.5), (-0.2, -0.25, 0.5)])

    def color_b(self):
        return self.vec([(0.0, -0.4, 0.5), (0.3, 0.0, 0.35), (0.2, 0.35, 0.55)])


def new_material(name):
    mat = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        mat.use_nodes = True
    nt = mat.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    return mat


def finish(g, sock, offset=0.0, scale=1.0, mode="emission"):
    """``sock`` * ``scale`` + ``offset`` as the colour of an Emission (strength 1), or of a
    Diffuse BSDF (roughness 0) for ``mode="diffuse"``, into the material output."""
    if offset or scale != 1.0:
        if sock.type == "VALUE":
            sock = g.math("MULTIPLY_ADD", sock, scale, offset)
        else:
            sock = g.vmath("MULTIPLY_ADD", sock, (scale,) * 3, (offset,) * 3)
    if mode == "diffuse":
        sh = g.new("ShaderNodeBsdfDiffuse", Color=sock, Roughness=0.0)
    else:
        sh = g.new("ShaderNodeEmission", Color=sock, Strength=1.0)
    out = g.new("ShaderNodeOutputMaterial")
    g.nt.links.new(sh.outputs[0], out.inputs["Surface"])
    return sh


# --------------------------------------------------------------------------------------------
# geometry: everything fills the camera's view [-1, 1]² exactly


def reset_scene():
    scene = scenes.clear_scene()
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.images, bpy.data.node_groups):
        for block in list(coll):
            if block.users == 0:
                coll.remove(block)
    cam = scenes.add_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ortho_scale=2.0)
    cam.rotation_mode = "XYZ"
    cam.rotation_euler = (0.0, 0.0, 0.0)  # x right, y up in the image
    return scene


def mesh_object(name, verts, faces, mat, location=(0.0, 0.0, 0.0)):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    mesh.update()
    mesh.materials.append(mat)
    ob = bpy.data.objects.new(name, mesh)
    ob.location = location
    bpy.context.scene.collection.objects.link(ob)
    return ob


def plane(mat):
    """The quad [-1, 1]² at z = 0 (object = world coordinates) with two UV maps: "UVMap"
    (0..1 across the view) and "Second" (turned a quarter, halved: u = 0.5 - y / 4,
    v = 0.35 + x / 4)."""
    ob = mesh_object("Plane", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [(0, 1, 2, 3)], mat)
    me = ob.data
    uv = me.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1])
    uv2 = me.uv_layers.new(name="Second")
    uv2.data.foreach_set("uv", [0.75, 0.1, 0.75, 0.6, 0.25, 0.6, 0.25, 0.1])
    me.uv_layers.active = uv
    return ob


def transformed_plane(mat):
    """A larger quad of an object turned 30 degrees about Z, scaled (1.5, 0.75, 2) and moved:
    its Object and Generated coordinates and its object-space normal differ from world ones."""
    ob = mesh_object("Moved", [(-3, -3, 0.2), (3, -3, 0.2), (3, 3, 0.2), (-3, 3, 0.2)],
                     [(0, 1, 2, 3)], mat, location=(0.1, -0.2, -0.4))
    ob.rotation_euler = (0.0, 0.0, math.radians(30.0))
    ob.scale = (1.5, 0.75, 2.0)
    uv = ob.data.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1])
    return ob


DOME = 1.1  # the dome z = 0.3 - DOME * (x² + y²): facets steepen to 72 degrees at the corners


def facets(mat, transform=None):
    """A convex dome of flat facets, one per pixel: the tangent planes of the paraboloid
    z = 0.3 - DOME (x² + y²) at the pixel centres. For a paraboloid the region where one tangent
    plane is the lowest is exactly the Voronoi cell of its point of contact, so the planes meet
    along the pixel edges (a closed surface) and each facet covers exactly its pixel in the
    view: normal, incoming direction and whatever depends on them only are constant per
    pixel. The dome is convex, so no ray leaving a facet outwards meets it again. In the
    bottom-right quarter (x > 0.5, y < -0.5) the quads are wound backwards: the camera sees
    their back faces. ``transform`` (rotation, scale) is the object's; the vertices are placed
    so that the world-space facets stay the same."""
    from mathutils import Euler, Matrix, Vector
    # The facets share the grid's vertices (so the surface is watertight), each vertex on the
    # four tangent planes around it: z = 0.3 - DOME (|x|² - step² / 2).
    step = 2.0 / N
    verts = []
    for j in range(N + 1):
        for i in range(N + 1):
            x, y = -1.0 + i * step, -1.0 + j * step
            verts.append((x, y, 0.3 - DOME * (x * x + y * y - step * step / 2)))
    faces = []
    for j in range(N):
        for i in range(N):
            v0 = j * (N + 1) + i
            quad = [v0, v0 + 1, v0 + N + 2, v0 + N + 1]
            if -1.0 + (i + 0.5) * step > 0.5 and -1.0 + (j + 0.5) * step < -0.5:
                quad.reverse()
            faces.append(quad)
    ob = mesh_object("Facets", verts, faces, mat)
    uv = ob.data.uv_layers.new(name="UVMap")  # planar: u, v = (x + 1) / 2, (y + 1) / 2
    loops = np.array([lp.vertex_index for lp in ob.data.loops])
    xy = np.array(verts)[loops, :2]
    uv.data.foreach_set("uv", ((xy + 1.0) / 2.0).ravel())
    if transform is not None:
        rot, scale = transform
        m = Matrix.LocRotScale(Vector((0.0, 0.0, 0.0)), Euler(rot), Vector(scale))
        inv = m.inverted()
        me = ob.data
        for v in me.vertices:
            v.co = inv @ v.co
        me.update()
        ob.matrix_world = m
    return ob


OBJ_GRID = 4  # Object Info: 4 x 4 objects, each covering N/4 x N/4 pixels


def object_grid(mat):
    """16 objects, one per N/4-pixel block: each its own location (z varies), colour and pass
    index; names hash to Object Info > Random."""
    size = 2.0 / OBJ_GRID
    obs = []
    for j in range(OBJ_GRID):
        for i in range(OBJ_GRID):
            cx, cy = -1.0 + (i + 0.5) * size, -1.0 + (j + 0.5) * size
            h = size / 2
            ob = mesh_object("Obj.%d.%d" % (i, j), [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)],
                             [(0, 1, 2, 3)], mat, location=(cx, cy, 0.1 * (i - j)))
            ob.pass_index = 3 * i + 5 * j
            ob.color = (0.1 + 0.25 * i, 0.9 - 0.2 * j, 0.05 * (i + j), 0.5 + 0.1 * i)
            obs.append(ob)
    return obs


def colour_triangle(mat):
    """One triangle covering the view ((-3, -3), (7, -3), (-3, 7)), so that per-corner and
    per-point colours interpolate linearly over the whole view: "Col" (float, point domain),
    "Paint" (byte, corner domain, the render default), and a UV map "UVMap"."""
    ob = mesh_object("Tri", [(-3, -3, 0), (7, -3, 0), (-3, 7, 0)], [(0, 1, 2)], mat)
    me = ob.data
    paint = me.color_attributes.new("Paint", "BYTE_COLOR", "CORNER")
    paint.data.foreach_set("color", [0.9, 0.1, 0.2, 1.0, 0.1, 0.8, 0.3, 0.5, 0.2, 0.3, 0.95, 0.0])
    col = me.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    col.data.foreach_set("color", [2.0, 0.0, 0.5, 1.0, 0.0, 1.5, 0.25, 0.2, 0.5, 0.25, 3.0, 0.7])
    me.color_attributes.render_color_index = me.color_attributes.find("Paint")
    me.color_attributes.active_color = paint
    uv = me.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", [0.1, 0.2, 0.9, 0.3, 0.2, 0.8])
    return ob


def colour_tiles(mat):
    """A 3 x 3 grid of quads covering the view with a colour per face: "Tiles", a generic
    FLOAT_COLOR attribute on the FACE domain (not a colour attribute; Attribute nodes read it)."""
    verts = [(-1.125 + 0.75 * i, -1.125 + 0.75 * j, 0.0) for j in range(4) for i in range(4)]
    faces = [(j * 4 + i, j * 4 + i + 1, (j + 1) * 4 + i + 1, (j + 1) * 4 + i)
             for j in range(3) for i in range(3)]
    ob = mesh_object("Tiles", verts, faces, mat)
    tiles = ob.data.attributes.new("Tiles", "FLOAT_COLOR", "FACE")
    tiles.data.foreach_set("color", [v for k in range(9) for v in
                                     (0.1 + 0.1 * k, 0.9 - 0.08 * k, (k % 3) * 0.4, 1.0)])
    return ob


# --------------------------------------------------------------------------------------------
# cases


@dataclass
class Case:
    id: str
    build: Callable            # G -> output socket
    disc: bool = False         # discontinuous: judge by the fraction of pixels off
    tol: float = 1e-3          # continuous: max relative error
    frac: float = 0.01         # discontinuous: max fraction of pixels off by > OFF
    offset: float = 0.0        # added to the output (Tesela drops negative radiance)
    scale: float = 1.0         # the output is multiplied by this first
    mode: str = "emission"     # "diffuse": a Diffuse BSDF under a white world (see below)
    geometry: Callable = plane
    snapped: bool = True       # constant per pixel: 1 spp, unstable pixels left out
    spp: int = 1               # Tesela's samples per pixel
    stable_tol: float = 1e-5   # two seeds agreeing this well: the pixel's input was the same
    xfail: Optional[str] = None


CASES = []


def case(id, build, **kw):
    if not kw.get("snapped", True):
        kw.setdefault("spp", 64)
    CASES.append(Case(id, build, **kw))


def tex(kind, output, props=None, vector=None, **inputs):
    """A texture node case's builder: the Vector input is ``vector(g)``."""
    def build(g):
        ins = dict(inputs)
        if vector is not None:
            ins["Vector"] = vector(g)
        for k, v in list(ins.items()):
            if callable(v):
                ins[k] = v(g)
        return g.out(g.new(kind, props, **ins), output)
    return build


P3 = lambda g: g.p((1.5, 1.5), (0.3125, -0.1875, 0.4375))      # noqa: E731
P3_BIG = lambda g: g.p((4.0, 4.0), (0.3125, -0.1875, 0.4375))  # noqa: E731
W_FIELD = lambda g: g.lin(0.75, 0.5, 0.3125)                  # noqa: E731


# -- procedural textures ---------------------------------------------------------------------

NOISE_COMMON = dict(Scale=3.0, Detail=3.5, Roughness=0.6, Lacunarity=2.2, Distortion=0.4)
for dims in ("1D", "2D", "3D", "4D"):
    for output in ("Fac", "Color"):
        case("noise-%s-fbm-%s" % (dims, output.lower()),
             tex("ShaderNodeTexNoise", output, {"noise_dimensions": dims, "noise_type": "FBM"},
                 vector=P3, W=W_FIELD, **NOISE_COMMON))
for dims in ("2D", "3D", "4D"):
    case("noise-%s-fbm-unnormalized" % dims,
         tex("ShaderNodeTexNoise", "Fac", {"noise_dimensions": dims, "noise_type": "FBM",
                                           "normalize": False},
             vector=P3, W=W_FIELD, **NOISE_COMMON), offset=2.0)
for kind in ("MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "HETERO_TERRAIN"):
    for dims in ("1D", "2D", "3D", "4D"):
        case("noise-%s-%s" % (dims, kind.lower()),
             tex("ShaderNodeTexNoise", "Fac", {"noise_dimensions": dims, "noise_type": kind},
                 vector=P3, W=W_FIELD, Scale=2.5, Detail=2.7, Roughness=0.55, Lacunarity=2.3,
                 Offset=0.8, Gain=1.3, Distortion=0.3), offset=4.0)
case("noise-3D-fbm-detail0",
     tex("ShaderNodeTexNoise", "Color", {"noise_dimensions": "3D"}, vector=P3, Scale=4.0,
         Detail=0.0, Distortion=0.0))
case("noise-3D-fbm-high-detail",
     tex("ShaderNodeTexNoise", "Fac", {"noise_dimensions": "3D"}, vector=P3, Scale=2.0,
         Detail=12.25, Roughness=0.7, Distortion=1.5))

for dims in ("1D", "2D", "3D", "4D"):
    for output in ("Value", "Color"):
        case("white_noise-%s-%s" % (dims, output.lower()),
             tex("ShaderNodeTexWhiteNoise", output, {"noise_dimensions": dims}, vector=P3_BIG,
                 W=W_FIELD))
# Unlinked, White Noise's Vector is (0, 0, 0), not the Generated coordinates of the other
# textures: one colour all over (4D: varying with W only).
case("white_noise-3D-color-unlinked",
     tex("ShaderNodeTexWhiteNoise", "Color", {"noise_dimensions": "3D"}))
case("white_noise-4D-value-unlinked",
     tex("ShaderNodeTexWhiteNoise", "Value", {"noise_dimensions": "4D"}, W=W_FIELD))

VORONOI = dict(Scale=3.0, Randomness=0.8)
for dims in ("1D", "2D", "3D", "4D"):
    case("voronoi-%s-f1-distance" % dims,
         tex("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": dims}, vector=P3,
             W=W_FIELD, **VORONOI))
    case("voronoi-%s-f1-color" % dims,
         tex("ShaderNodeTexVoronoi", "Color", {"voronoi_dimensions": dims}, vector=P3,
             W=W_FIELD, **VORONOI), disc=True)
for dims, output in (("2D", "Position"), ("3D", "Position"), ("1D", "W"), ("4D", "W")):
    case("voronoi-%s-f1-%s" % (dims, output.lower()),
         tex("ShaderNodeTexVoronoi", output, {"voronoi_dimensions": dims}, vector=P3,
             W=W_FIELD, **VORONOI), disc=True, offset=4.0)
for feature, output, disc in (("F2", "Distance", False), ("F2", "Color", True),
                              ("SMOOTH_F1", "Distance", False), ("SMOOTH_F1", "Color", False),
                              ("DISTANCE_TO_EDGE", "Distance", False),
                              ("N_SPHERE_RADIUS", "Radius", True)):
    for dims in ("1D", "2D", "3D", "4D"):
        case("voronoi-%s-%s-%s" % (dims, feature.lower(), output.lower()),
             tex("ShaderNodeTexVoronoi", output, {"voronoi_dimensions": dims, "feature": feature},
                 vector=P3, W=W_FIELD, Smoothness=0.6, **VORONOI), disc=disc, offset=1.0)
for metric in ("MANHATTAN", "CHEBYCHEV", "MINKOWSKI"):
    for dims in ("2D", "3D", "4D"):
        case("voronoi-%s-%s" % (dims, metric.lower()),
             tex("ShaderNodeTexVoronoi", "Distance",
                 {"voronoi_dimensions": dims, "distance": metric},
                 vector=P3, W=W_FIELD, Exponent=1.5, **VORONOI))
for dims in ("2D", "3D"):
    case("voronoi-%s-fractal-f1" % dims,
         tex("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": dims, "normalize": True},
             vector=P3, Detail=2.5, Roughness=0.6, Lacunarity=2.1, **VORONOI))
    case("voronoi-%s-fractal-f2-color" % dims,
         tex("ShaderNodeTexVoronoi", "Color", {"voronoi_dimensions": dims, "feature": "F2"},
             vector=P3, Detail=1.5, **VORONOI), disc=True)
    case("voronoi-%s-fractal-smooth-f1" % dims,
         tex("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": dims,
                                                  "feature": "SMOOTH_F1", "normalize": True},
             vector=P3, Detail=2.25, Smoothness=0.4, **VORONOI))
    case("voronoi-%s-fractal-edge" % dims,
         tex("ShaderNodeTexVoronoi", "Distance", {"voronoi_dimensions": dims,
                                                  "feature": "DISTANCE_TO_EDGE", "normalize": True},
             vector=P3, Detail=1.75, **VORONOI))

for output in ("Color", "Fac"):
    case("checker-%s" % output.lower(),
         tex("ShaderNodeTexChecker", output, vector=P3, Scale=3.0,
             Color1=(0.9, 0.3, 0.1, 1.0), Color2=(0.1, 0.4, 0.8, 1.0)), disc=True)

P_GRAD = lambda g: g.p((1.25, 1.25), (0.125, -0.0625, 0.25))  # noqa: E731
for kind in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL", "QUADRATIC_SPHERE",
             "RADIAL"):
    case("gradient-%s" % kind.lower(),
         tex("ShaderNodeTexGradient", "Fac", {"gradient_type": kind}, vector=P_GRAD),
         disc=kind == "RADIAL")
case("gradient-radial-color", tex("ShaderNodeTexGradient", "Color", {"gradient_type": "RADIAL"},
                                  vector=P_GRAD), disc=True)

WAVE = dict(Scale=2.0, Distortion=2.0, Detail=2.5, **{"Detail Scale": 1.5,
                                                       "Detail Roughness": 0.6,
                                                       "Phase Offset": 0.7})
for wtype, key, directions in (("BANDS", "bands_direction", ("X", "Y", "Z", "DIAGONAL")),
                               ("RINGS", "rings_direction", ("X", "Y", "Z", "SPHERICAL"))):
    for d in directions:
        for profile in ("SIN", "SAW", "TRI"):
            if profile != "SIN" and d not in ("X", "SPHERICAL", "DIAGONAL"):
                continue
            case("wave-%s-%s-%s" % (wtype.lower(), d.lower(), profile.lower()),
                 tex("ShaderNodeTexWave", "Fac", {"wave_type": wtype, key: d,
                                                  "wave_profile": profile},
                     vector=P3, **WAVE), disc=profile == "SAW")
case("wave-bands-x-sin-color",
     tex("ShaderNodeTexWave", "Color", {"wave_type": "BANDS"}, vector=P3, Scale=3.0))

for depth in (0, 1, 2, 5, 10):
    case("magic-depth%d" % depth,
         tex("ShaderNodeTexMagic", "Color", {"turbulence_depth": depth}, vector=P3, Scale=2.5,
             Distortion=1.5))
case("magic-fac", tex("ShaderNodeTexMagic", "Fac", {"turbulence_depth": 3}, vector=P3,
                      Scale=2.5, Distortion=2.5))

# Gabor (Blender 4.3+): 2D and 3D, isotropic to fully anisotropic, each output.
GABOR = [("2D", 0.0, {"Orientation 2D": 0.6}), ("2D", 0.7, {"Orientation 2D": -1.1}),
         ("2D", 1.0, {}), ("3D", 0.0, {}), ("3D", 0.6, {"Orientation 3D": (0.3, -0.5, 0.8)}),
         ("3D", 1.0, {"Orientation 3D": (0.0, 0.0, 1.0)})]
for gtype, aniso, extra in GABOR:
    for output in ("Value", "Phase", "Intensity"):
        case("gabor-%s-aniso%g-%s" % (gtype, aniso, output.lower()),
             tex("ShaderNodeTexGabor", output, {"gabor_type": gtype}, vector=P3, Scale=2.5,
                 Frequency=2.5, Anisotropy=aniso, **extra), disc=output == "Phase")

BRICK = {"Color1": (0.8, 0.2, 0.1, 1.0), "Color2": (0.2, 0.6, 0.3, 1.0),
         "Mortar": (0.05, 0.05, 0.1, 1.0), "Scale": 2.5}
for output in ("Color", "Fac"):
    case("brick-default-%s" % output.lower(),
         tex("ShaderNodeTexBrick", output, vector=P3, **BRICK), disc=True)
    case("brick-custom-%s" % output.lower(),
         tex("ShaderNodeTexBrick", output, {"offset": 0.3, "offset_frequency": 3,
                                            "squash": 0.7, "squash_frequency": 2},
             vector=P3, **BRICK, **{"Mortar Size": 0.05, "Mortar Smooth": 0.4, "Bias": -0.3,
                                    "Brick Width": 0.6, "Row Height": 0.3}), disc=True)


# -- Math, Vector Math, Map Range, Clamp, Mix --------------------------------------------------

def math_case(op, a=(1.0, 0.0), b=(1.0, 0.0), c=None, clamp=False):
    """Math ``op`` of a = ka * x + oa, b = kb * y + ob (and a constant c)."""
    def build(g):
        av = g.lin(a[0], 0.0, a[1])
        bv = g.lin(0.0, b[0], b[1])
        return g.math(op, av, bv, c, clamp)
    return build


S = (1.0, 0.0)         # [-1, 1]
POS = (1.0, 1.25)      # [0.25, 2.25]
MATH = [  # op, a, b, c, discontinuous, offset
    ("ADD", S, S, None, False, 3.0),
    ("SUBTRACT", S, (0.5, 0.25), None, False, 3.0),
    ("MULTIPLY", (2.0, 0.0), (1.5, 0.0), None, False, 4.0),
    ("DIVIDE", (2.0, 0.0), POS, None, False, 9.0),
    ("DIVIDE", S, S, None, False, 70.0),           # division near and through zero
    ("MULTIPLY_ADD", (2.0, 0.0), (1.5, 0.0), -0.75, False, 5.0),
    ("POWER", (2.0, 0.0), (2.5, 0.0), None, False, 0.0),   # negative bases, non-integer powers
    ("POWER", (1.0, 1.125), (4.0, 0.0), None, False, 0.0),
    ("LOGARITHM", (2.0, 2.125), (0.5, 2.75), None, False, 3.0),
    ("LOGARITHM", (2.0, 2.125), (0.25, 0.5), None, False, 8.0),    # bases below 1
    ("SQRT", (2.0, 1.0), S, None, False, 0.0),
    ("INVERSE_SQRT", (1.0, 1.125), S, None, False, 0.0),
    ("ABSOLUTE", S, S, None, False, 0.0),
    ("EXPONENT", (2.0, 0.0), S, None, False, 0.0),
    ("MINIMUM", S, S, None, False, 1.0),
    ("MAXIMUM", S, S, None, False, 1.0),
    ("LESS_THAN", S, S, None, True, 0.0),
    ("GREATER_THAN", S, S, None, True, 0.0),
    ("SIGN", S, S, None, True, 1.0),
    ("COMPARE", S, S, 0.3, True, 0.0),
    ("SMOOTH_MIN", S, S, 0.4, False, 2.0),
    ("SMOOTH_MAX", S, S, 0.4, False, 1.0),
    ("ROUND", (3.0, 0.0), S, None, True, 3.0),
    ("FLOOR", (3.0, 0.0), S, None, True, 4.0),
    ("CEIL", (3.0, 0.0), S, None, True, 3.0),
    ("TRUNC", (3.0, 0.0), S, None, True, 3.0),
    ("FRACT", (3.0, 0.0), S, None, True, 0.0),
    ("MODULO", (3.0, 0.0), POS, None, True, 3.0),
    ("MODULO", (3.0, 0.0), (1.0, -1.25), None, True, 3.0),   # negative divisors
    ("FLOORED_MODULO", (3.0, 0.0), POS, None, True, 0.0),
    ("FLOORED_MODULO", (3.0, 0.0), (1.0, -1.25), None, True, 3.0),
    ("WRAP", (3.0, 0.0), POS, -0.5, True, 1.0),
    ("WRAP", (3.0, 0.0), (0.5, 0.0), 0.25, True, 1.0),       # max below min at places
    ("SNAP", (3.0, 0.0), (0.5, 0.75), None, True, 4.0),
    ("PINGPONG", (3.0, 0.0), (0.5, 0.75), None, False, 0.0),
    ("PINGPONG", (3.0, 0.0), (0.5, 0.0), None, False, 1.0),   # scale through zero
    ("SINE", (3.0, 0.0), S, None, False, 1.0),
    ("COSINE", (3.0, 0.0), S, None, False, 1.0),
    ("TANGENT", (1.375, 0.0), S, None, False, 6.0),
    ("ARCSINE", (1.25, 0.0), S, None, False, 2.0),
    ("ARCCOSINE", (1.25, 0.0), S, None, False, 0.0),
    ("ARCTANGENT", (3.0, 0.0), S, None, False, 2.0),
    ("ARCTAN2", S, S, None, True, 4.0),
    ("SINH", (2.0, 0.0), S, None, False, 4.0),
    ("COSH", (2.0, 0.0), S, None, False, 0.0),
    ("TANH", (2.0, 0.0), S, None, False, 1.0),
    ("RADIANS", (90.0, 0.0), S, None, False, 2.0),
    ("DEGREES", (2.0, 0.0), S, None, False, 120.0),
]
_seen = {}
for op, a, b, c, disc, offset in MATH:
    n = _seen[op] = _seen.get(op, 0) + 1
    case("math-%s%s" % (op.lower(), "" if n == 1 else "-%d" % n), math_case(op, a, b, c),
         disc=disc, offset=offset)
case("math-multiply-clamp", math_case("MULTIPLY", (2.0, 0.0), (1.5, 0.0), clamp=True))
case("math-subtract-clamp", math_case("SUBTRACT", S, (0.5, 0.25), clamp=True))


def vmath_case(op, value=False, scale=None):
    def build(g):
        a = g.vec([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0625), (0.5, -0.5, 0.25)])
        b = g.vec([(0.0, 0.75, 0.5), (-0.5, 0.0, 0.75), (0.25, 0.25, -0.5)])
        c = (0.3, -0.2, 0.6) if op in ("MULTIPLY_ADD", "WRAP", "FACEFORWARD") else None
        if op == "REFRACT":
            a = g.vmath("NORMALIZE", a)
            b = g.vmath("NORMALIZE", b)
        return g.vmath(op, a, b, c, scale, value=value)
    return build


VMATH = {  # op: (discontinuous, offset, uses the Value output)
    "ADD": (False, 3.0, False), "SUBTRACT": (False, 3.0, False), "MULTIPLY": (False, 2.0, False),
    "DIVIDE": (False, 1000.0, False), "MULTIPLY_ADD": (False, 3.0, False),
    "CROSS_PRODUCT": (False, 3.0, False), "PROJECT": (False, 5.0, False),
    "REFLECT": (False, 4.0, False), "FACEFORWARD": (False, 3.0, False),
    "DOT_PRODUCT": (False, 3.0, True), "DISTANCE": (False, 0.0, True),
    "LENGTH": (False, 0.0, True), "SCALE": (False, 3.0, False), "NORMALIZE": (False, 1.0, False),
    "ABSOLUTE": (False, 0.0, False), "POWER": (False, 0.0, False), "SIGN": (True, 1.0, False),
    "MINIMUM": (False, 2.0, False), "MAXIMUM": (False, 2.0, False), "FLOOR": (True, 2.0, False),
    "CEIL": (True, 1.0, False), "FRACTION": (True, 0.0, False), "MODULO": (True, 2.0, False),
    "WRAP": (True, 2.0, False), "SNAP": (True, 3.0, False), "SINE": (False, 1.0, False),
    "COSINE": (False, 0.0, False), "TANGENT": (False, 3.0, False),
}
for op, (disc, offset, value) in VMATH.items():
    case("vector_math-%s" % op.lower(), vmath_case(op, value, -1.5 if op == "SCALE" else None),
         disc=disc, offset=offset)
case("vector_math-refract", vmath_case("REFRACT", scale=1.45), offset=2.0)
case("vector_math-refract-total", vmath_case("REFRACT", scale=0.6), offset=2.0)


def map_range_case(kind, clamp, vector=False, reverse=False):
    def build(g):
        props = {"interpolation_type": kind, "clamp": clamp,
                 "data_type": "FLOAT_VECTOR" if vector else "FLOAT"}
        lo, hi = (0.7, -0.5) if reverse else (-0.5, 0.7)
        if vector:
            v = g.vec([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5, 0.0)])
            return g.out(g.new("ShaderNodeMapRange", props, Vector=v,
                               From_Min_FLOAT3=(lo, -0.8, 0.0), From_Max_FLOAT3=(hi, 0.6, 0.9),
                               To_Min_FLOAT3=(0.2, 1.0, -0.4), To_Max_FLOAT3=(1.3, 0.1, 1.5),
                               Steps_FLOAT3=(4.0, 3.0, 5.5)), "Vector")
        n = g.new("ShaderNodeMapRange", props, Value=g.lin(1.0, 0.25, 0.0),
                  **{"From Min": lo, "From Max": hi, "To Min": 0.2, "To Max": 1.3, "Steps": 4.0})
        return g.out(n, "Result")
    return build


for kind in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP"):
    disc = kind == "STEPPED"
    case("map_range-%s" % kind.lower(), map_range_case(kind, True), disc=disc)
    case("map_range-%s-unclamped" % kind.lower(), map_range_case(kind, False), disc=disc,
         offset=2.0)
    case("map_range-%s-vector" % kind.lower(), map_range_case(kind, False, vector=True),
         disc=disc, offset=5.0)
case("map_range-linear-reversed", map_range_case("LINEAR", True, reverse=True))
case("map_range-stepped-reversed-vector",
     map_range_case("STEPPED", True, vector=True, reverse=True), disc=True, offset=1.0)

for kind in ("MINMAX", "RANGE"):
    case("clamp-%s" % kind.lower(),
         lambda g, kind=kind: g.out(g.new("ShaderNodeClamp", {"clamp_type": kind},
                                          Value=g.lin(1.0, 0.0, 0.0), Min=g.lin(0.0, 0.5, -0.2),
                                          Max=0.4)),
         offset=1.0)


def mix_float(clamp):
    return lambda g: g.out(g.new("ShaderNodeMix", {"data_type": "FLOAT", "clamp_factor": clamp},
                                 Factor_Float=g.lin(0.75, 0.0, 0.5), A_Float=g.lin(0.0, 1.0, 0.2),
                                 B_Float=0.7), "Result_Float")


def mix_vector(mode, clamp):
    def build(g):
        f = (g.vec([(0.75, 0.0, 0.5), (0.0, 0.75, 0.5), (0.5, 0.5, 0.5)])
             if mode == "NON_UNIFORM" else g.lin(0.75, 0.0, 0.5))
        key = "Factor_Vector" if mode == "NON_UNIFORM" else "Factor_Float"
        n = g.new("ShaderNodeMix", {"data_type": "VECTOR", "factor_mode": mode,
                                    "clamp_factor": clamp},
                  A_Vector=g.vec([(0.0, 1.0, 0.0), (1.0, 0.0, 0.0), (0.5, 0.5, 0.0)]),
                  B_Vector=(0.6, -0.3, 0.9), **{key: f})
        return g.out(n, "Result_Vector")
    return build


def mix_color(blend, clamp_factor=True, clamp_result=False, legacy=False):
    def build(g):
        fac = g.lin(0.75, 0.0, 0.5) if not clamp_factor else g.lin(0.625, 0.125, 0.5)
        if legacy:
            n = g.new("ShaderNodeMixRGB", {"blend_type": blend, "use_clamp": clamp_result},
                      Fac=fac, Color1=g.color_a(), Color2=g.color_b())
            return g.out(n, "Color")
        n = g.new("ShaderNodeMix", {"data_type": "RGBA", "blend_type": blend,
                                    "clamp_factor": clamp_factor, "clamp_result": clamp_result},
                  Factor_Float=fac, A_Color=g.color_a(), B_Color=g.color_b())
        return g.out(n, "Result_Color")
    return build


case("mix-float", mix_float(True), offset=1.0)
case("mix-float-unclamped", mix_float(False), offset=2.0)
for mode in ("UNIFORM", "NON_UNIFORM"):
    for clamp in (True, False):
        case("mix-vector-%s%s" % (mode.lower(), "" if clamp else "-unclamped"),
             mix_vector(mode, clamp), offset=2.0)
BLENDS = ["MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD", "OVERLAY",
          "SOFT_LIGHT", "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT", "DIVIDE", "HUE",
          "SATURATION", "COLOR", "VALUE"]
for blend in BLENDS:
    case("mix-color-%s" % blend.lower(), mix_color(blend), offset=2.0)
for blend in ("MIX", "BURN", "DODGE", "LINEAR_LIGHT", "DIVIDE", "HUE"):
    case("mix-color-%s-unclamped-factor" % blend.lower(), mix_color(blend, clamp_factor=False),
         offset=25.0)
for blend in ("ADD", "SUBTRACT", "LINEAR_LIGHT", "DODGE"):
    case("mix-color-%s-clamp-result" % blend.lower(), mix_color(blend, clamp_result=True))
for blend, clamp in (("MIX", False), ("OVERLAY", False), ("SOFT_LIGHT", False), ("HUE", False),
                     ("ADD", True), ("LINEAR_LIGHT", True)):
    case("mixrgb-%s%s" % (blend.lower(), "-clamp" if clamp else ""),
         mix_color(blend, clamp_result=clamp, legacy=True), offset=0.0 if clamp else 2.0)


# -- colour nodes, ramps, curves ---------------------------------------------------------------

def ramp_case(interpolation, color_mode="RGB", hue="NEAR", output="Color"):
    def build(g):
        n = g.new("ShaderNodeValToRGB", Fac=g.lin(0.6, 0.0625, 0.5))
        r = n.color_ramp
        r.color_mode = color_mode
        r.hue_interpolation = hue
        r.interpolation = interpolation
        r.elements[0].position = 0.1
        r.elements[0].color = (0.9, 0.1, 0.05, 1.0)
        r.elements[1].position = 0.85
        r.elements[1].color = (0.1, 0.2, 0.95, 0.2)
        e = r.elements.new(0.4)
        e.color = (0.2, 0.9, 0.3, 0.6)
        e = r.elements.new(0.55)
        e.color = (0.95, 0.85, 0.1, 0.9)
        return g.out(n, output)
    return build


for interp in ("CONSTANT", "LINEAR", "EASE", "B_SPLINE", "CARDINAL"):
    case("color_ramp-%s" % interp.lower(), ramp_case(interp), disc=interp == "CONSTANT")
case("color_ramp-linear-alpha", ramp_case("LINEAR", output="Alpha"))
for mode in ("HSV", "HSL"):
    for hue in ("NEAR", "FAR", "CW", "CCW"):
        case("color_ramp-%s-%s" % (mode.lower(), hue.lower()), ramp_case("LINEAR", mode, hue))


def rgb_curves(g):
    n = g.new("ShaderNodeRGBCurve", Fac=0.9, Color=g.color_a())
    m = n.mapping
    c = m.curves
    c[0].points.new(0.3, 0.7)
    c[1].points[0].location = (0.1, 0.2)
    c[1].points.new(0.6, 0.3)
    c[2].points[1].location = (0.8, 0.6)
    c[3].points.new(0.5, 0.65)
    m.update()
    return g.out(n, "Color")


def float_curve(extrapolate):
    def build(g):
        n = g.new("ShaderNodeFloatCurve", Factor=1.0, Value=g.lin(0.7, 0.0, 0.5))
        m = n.mapping
        pts = m.curves[0].points
        pts[0].location = (0.1, 0.3)
        pts[1].location = (0.8, 0.9)
        p = pts.new(0.45, 0.1)
        p.handle_type = "VECTOR"
        if extrapolate:
            m.extend = "EXTRAPOLATED"
        m.update()
        return g.out(n, "Value")
    return build


def vector_curves(g):
    n = g.new("ShaderNodeVectorCurve", Fac=1.0,
              Vector=g.vec([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, -0.5, 0.0)]))
    m = n.mapping
    m.curves[0].points.new(0.2, 0.6)
    m.curves[1].points[0].location = (-1.0, 0.5)
    m.curves[2].points.new(-0.4, -0.8)
    m.update()
    return g.out(n, "Vector")


case("rgb_curves", rgb_curves)
case("float_curve", float_curve(False))
case("float_curve-extrapolated", float_curve(True), offset=1.0)
case("vector_curves", vector_curves, offset=2.0)


def separate_color(mode):
    def build(g):
        n = g.new("ShaderNodeSeparateColor", {"mode": mode}, Color=g.color_a())
        return g.comb(*n.outputs)
    return build


def combine_color(mode):
    def build(g):
        n = g.new("ShaderNodeCombineColor", {"mode": mode}, Red=g.lin(0.6, 0.0, 0.5),
                  Green=g.lin(0.0, 0.5, 0.5), Blue=g.lin(0.2, 0.25, 0.55))
        return g.out(n)
    return build


for mode in ("RGB", "HSV", "HSL"):
    case("separate_color-%s" % mode.lower(), separate_color(mode))
    case("combine_color-%s" % mode.lower(), combine_color(mode), offset=1.0)

case("hue_saturation_value",
     lambda g: g.out(g.new("ShaderNodeHueSaturation", Hue=g.lin(0.3, 0.0, 0.5),
                           Saturation=g.lin(0.0, 0.8, 1.0), Value=1.2, Fac=0.9,
                           Color=g.color_a())))
case("brightness_contrast",
     lambda g: g.out(g.new("ShaderNodeBrightContrast", Color=g.color_a(),
                           Bright=g.lin(0.25, 0.0, 0.05), Contrast=g.lin(0.0, 0.6, 0.2))),
     offset=1.0)
case("gamma", lambda g: g.out(g.new("ShaderNodeGamma", Color=g.color_a(),
                                    Gamma=g.lin(0.0, 1.0, 1.4))))
case("invert", lambda g: g.out(g.new("ShaderNodeInvert", Fac=g.lin(0.0, 0.6, 0.5),
                                     Color=g.color_a())), offset=1.0)
case("rgb_to_bw", lambda g: g.out(g.new("ShaderNodeRGBToBW", Color=g.color_b())))
case("blackbody", lambda g: g.out(g.new("ShaderNodeBlackbody",
                                        Temperature=g.lin(5000.0, 1000.0, 7000.0))))
case("wavelength", lambda g: g.out(g.new("ShaderNodeWavelength",
                                         Wavelength=g.lin(200.0, 10.0, 560.0))))


# -- Mapping -------------------------------------------------------------------------------

def mapping_case(kind):
    def build(g):
        v = g.vec([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.5, 0.5, 0.25)])
        ins = dict(Vector=v, Rotation=(0.4, -0.7, 1.1), Scale=(1.5, 0.5, -2.0))
        if kind in ("POINT", "TEXTURE"):
            ins["Location"] = (0.3, -0.2, 0.5)
        return g.out(g.new("ShaderNodeMapping", {"vector_type": kind}, **ins), "Vector")
    return build


for kind in ("POINT", "TEXTURE", "VECTOR", "NORMAL"):
    case("mapping-%s" % kind.lower(), mapping_case(kind), offset=5.0)


# -- inputs: coordinates, attributes, geometry, object info, layer weight, Fresnel -------------

def persp_plane(mat):
    """A plane larger than the view of a perspective camera looking down at it at an angle."""
    ob = mesh_object("Big", [(-4, -4, 0), (4, -4, 0), (4, 4, 0), (-4, 4, 0)], [(0, 1, 2, 3)], mat)
    uv = ob.data.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", [0, 0, 1, 0, 1, 1, 0, 1])
    cam = bpy.context.scene.camera
    cam.data.type = "PERSP"
    cam.data.angle = math.radians(40.0)
    cam.location = (0.4, -0.9, 3.0)
    scenes._aim(cam, (0.1, 0.2, 0.0))
    return ob


def coord(name, kind="ShaderNodeTexCoord", props=None):
    return lambda g: g.out(g.new(kind, props), name)


def transformed_facets(mat):
    return facets(mat, ((0.3, -0.2, 0.5), (1.5, 0.6, 1.2)))


# Linear fields, averaged over the pixel (64 spp).
for output, geom, offset in (("Generated", transformed_plane, 3.0),
                             ("Object", transformed_plane, 4.0), ("UV", transformed_plane, 0.0)):
    case("tex_coord-%s" % output.lower(), coord(output), geometry=geom, offset=offset,
         snapped=False)
# What depends on the camera or the viewing direction: seen through a Diffuse BSDF under a
# white world (the BSDF's shading point is the hit's own), and once through Emission.
for output, geom, scale in (("Camera", plane, 0.08), ("Camera", persp_plane, 0.12),
                            ("Reflection", persp_plane, 0.5)):
    case("tex_coord-%s-%s" % (output.lower(), geom.__name__), coord(output), geometry=geom,
         scale=scale, offset=0.5, snapped=False, mode="diffuse")
case("tex_coord-normal-facets", coord("Normal"), geometry=transformed_facets, scale=0.5,
     offset=0.5, mode="diffuse")
case("tex_coord-reflection-facets", coord("Reflection"), geometry=facets, scale=0.5,
     offset=0.5, mode="diffuse")
case("uv_map-second", coord("UV", "ShaderNodeUVMap", {"uv_map": "Second"}), snapped=False)
case("uv_map-first-by-name", coord("UV", "ShaderNodeUVMap", {"uv_map": "UVMap"}),
     geometry=transformed_plane, snapped=False)
for name, output in (("Col", "Color"), ("Col", "Fac"), ("Col", "Alpha"), ("Paint", "Color"),
                     ("UVMap", "Vector")):
    case("attribute-%s-%s" % (name.lower(), output.lower()),
         coord(output, "ShaderNodeAttribute", {"attribute_name": name}), geometry=colour_triangle,
         snapped=False)
case("attribute-face-tiles", coord("Color", "ShaderNodeAttribute", {"attribute_name": "Tiles"}),
     geometry=colour_tiles, disc=True)
for name, output in (("Paint", "Color"), ("Col", "Color"), ("Col", "Alpha"), ("", "Color")):
    case("color_attribute-%s-%s" % (name.lower() or "default", output.lower()),
         coord(output, "ShaderNodeVertexColor", {"layer_name": name}), geometry=colour_triangle,
         snapped=False)

GEO = "ShaderNodeNewGeometry"
case("geometry-position", coord("Position", GEO), geometry=transformed_plane, offset=3.0,
     snapped=False)
for output in ("Normal", "True Normal"):
    case("geometry-%s-facets" % output.lower().replace(" ", "_"), coord(output, GEO),
         geometry=transformed_facets, scale=0.5, offset=0.5, mode="diffuse")
case("geometry-incoming-persp", coord("Incoming", GEO), geometry=persp_plane, scale=0.5,
     offset=0.5, snapped=False, mode="diffuse")
case("geometry-backfacing-facets", coord("Backfacing", GEO), geometry=facets, mode="diffuse",
     scale=0.5, offset=0.25)

for output, scale, offset in (("Random", 1.0, 0.0), ("Color", 1.0, 0.0), ("Alpha", 1.0, 0.0),
                              ("Location", 1.0, 2.0), ("Object Index", 0.05, 0.0)):
    def build(g, output=output, scale=scale):
        s = g.out(g.new("ShaderNodeObjectInfo"), output)
        return s if scale == 1.0 else g.math("MULTIPLY", s, scale)
    case("object_info-%s" % output.lower().replace(" ", "_"), build, geometry=object_grid,
         offset=offset)

for output in ("Fresnel", "Facing"):
    for blend in (0.5, "field"):
        def build(g, output=output, blend=blend):
            b = g.lin(0.45, 0.0, 0.5, source="Position") if blend == "field" else blend
            return g.out(g.new("ShaderNodeLayerWeight", Blend=b), output)
        case("layer_weight-%s-%s" % (output.lower(), blend), build, geometry=facets,
             mode="diffuse")
    case("layer_weight-%s-normal-input" % output.lower(),
         lambda g, output=output: g.out(g.new(
             "ShaderNodeLayerWeight", Blend=0.3,
             Normal=g.vmath("NORMALIZE", g.vec([(0.3, 0.0, 0.1), (0.0, 0.3, -0.2), (0.0, 0.0, 1.0)],
                                               source="Position"))), output),
         geometry=facets, mode="diffuse")
case("fresnel-ior-field",
     lambda g: g.out(g.new("ShaderNodeFresnel", IOR=g.lin(0.0, 0.9, 2.0, source="Position"))),
     geometry=facets, mode="diffuse")
case("fresnel-ior-1.45", lambda g: g.out(g.new("ShaderNodeFresnel", IOR=1.45)), geometry=facets,
     mode="diffuse")

# The same through Emission: the emitter is shaded at the hit's own shading point.
case("emission-tex_coord-camera", coord("Camera"), offset=6.0, snapped=False)
case("emission-geometry-incoming", coord("Incoming", GEO), geometry=persp_plane, offset=1.0,
     snapped=False)
case("emission-geometry-backfacing", coord("Backfacing", GEO), geometry=facets)
case("emission-layer_weight-facing", lambda g: g.out(g.new("ShaderNodeLayerWeight"), "Facing"),
     geometry=facets)
case("emission-geometry-normal-backfaces", coord("Normal", GEO), geometry=facets, offset=1.0)


# -- Vector Rotate, Vector Transform, Normal, Camera Data, Tangent ---------------------------

def rotate_case(kind, invert):
    def build(g):
        v = g.vec([(1.0, 0.0, 0.1), (0.0, 1.0, -0.2), (0.5, 0.5, 0.25)])
        ins = dict(Vector=v, Center=(0.2, -0.1, 0.3))
        if kind == "AXIS_ANGLE":
            ins["Axis"] = (0.3, 0.5, 0.8)
        if kind == "EULER_XYZ":
            ins["Rotation"] = (0.4, -0.7, 1.1)
        else:
            ins["Angle"] = g.lin(0.5, 0.3, 0.7)
        return g.out(g.new("ShaderNodeVectorRotate", {"rotation_type": kind, "invert": invert},
                           **ins), "Vector")
    return build


for kind in ("AXIS_ANGLE", "X_AXIS", "Y_AXIS", "Z_AXIS", "EULER_XYZ"):
    for invert in (False, True):
        case("vector_rotate-%s%s" % (kind.lower(), "-invert" if invert else ""),
             rotate_case(kind, invert), offset=5.0)


def transform_case(kind, src, dst):
    def build(g):
        v = g.vec([(1.0, 0.0, 0.1), (0.0, 1.0, -0.2), (0.5, 0.5, 0.25)], source="Position")
        return g.out(g.new("ShaderNodeVectorTransform", {
            "vector_type": kind, "convert_from": src, "convert_to": dst}, Vector=v), "Vector")
    return build


for kind in ("POINT", "VECTOR", "NORMAL"):
    for src, dst in (("WORLD", "OBJECT"), ("OBJECT", "WORLD"), ("WORLD", "CAMERA"),
                     ("CAMERA", "WORLD"), ("OBJECT", "CAMERA"), ("CAMERA", "OBJECT")):
        case("vector_transform-%s-%s-%s" % (kind.lower(), src.lower(), dst.lower()),
             transform_case(kind, src, dst), geometry=transformed_plane, offset=8.0)


def normal_node(output):
    def build(g):
        n = g.new("ShaderNodeNormal", Normal=g.vec([(0.5, 0.0, 0.1), (0.0, 0.5, -0.2),
                                                    (0.0, 0.0, 1.0)]))
        n.outputs["Normal"].default_value = (0.3, -0.5, 0.8)
        return g.out(n, output)
    return build


case("normal-normal", normal_node("Normal"), offset=1.0)
case("normal-dot", normal_node("Dot"), offset=1.0)
for output, scale, offset in (("View Vector", 0.5, 0.5), ("View Z Depth", 0.1, 0.2),
                              ("View Distance", 0.1, 0.2)):
    # (Orthographic, the plane's depth is the same everywhere: a flat reference tests nothing.)
    for geom in ((plane, persp_plane) if output != "View Z Depth" else (persp_plane,)):
        case("camera_data-%s-%s" % (output.lower().replace(" ", "_"), geom.__name__),
             coord(output, "ShaderNodeCameraData"), geometry=geom, scale=scale, offset=offset,
             snapped=False, mode="diffuse")
for axis in ("X", "Y", "Z"):
    # The radial tangent is normalised, so a pixel's mean (64 spp over the pixel) is not its
    # centre value where it turns quickly (measured: off by ~1e-3 over 2-5% of the dome, more
    # at facet edges): judged by the fraction of pixels off; a wrong axis or sign is off nearly
    # everywhere.
    case("tangent-radial-%s" % axis.lower(),
         coord("Tangent", "ShaderNodeTangent", {"direction_type": "RADIAL", "axis": axis}),
         geometry=transformed_facets, scale=0.5, offset=0.5, mode="diffuse", snapped=False,
         disc=True, frac=0.08)
case("tangent-uv_map", coord("Tangent", "ShaderNodeTangent",
                             {"direction_type": "UV_MAP", "uv_map": "UVMap"}),
     geometry=transformed_plane, scale=0.5, offset=0.5, mode="diffuse", snapped=False)


# -- Image Texture -----------------------------------------------------------------------------

def make_image(kind):
    """A small image made in code: "srgb8" (8 x 6 bytes, sRGB, alpha), "data8" (the same,
    Non-Color) or "float" (5 x 7 linear floats up to 8, alpha)."""
    rng = np.random.default_rng(12)
    if kind == "float":
        w, h = 5, 7
        img = bpy.data.images.new("Float", w, h, alpha=True, float_buffer=True)
        px = rng.uniform(0.0, 1.0, (h, w, 4)).astype(np.float32)
        px[..., :3] *= np.array([8.0, 2.0, 0.5], np.float32)
        px[..., 3] = rng.uniform(0.2, 1.0, (h, w))
        img.colorspace_settings.name = "Linear Rec.709"
    else:
        w, h = 8, 6
        img = bpy.data.images.new("Bytes-" + kind, w, h, alpha=True)
        px = (rng.integers(0, 256, (h, w, 4)) / 255.0).astype(np.float32)
        px[..., 3] = (rng.integers(60, 256, (h, w)) / 255.0).astype(np.float32)
        img.colorspace_settings.name = "sRGB" if kind == "srgb8" else "Non-Color"
    img.pixels.foreach_set(px.ravel())
    img.update()
    img.pack()
    return img


def image_case(kind, interpolation, extension, output="Color", alpha_mode=None):
    """An Image Texture lookup at snapped UVs mapped to [-0.69, 1.81]² (every extension mode
    is exercised). ``output`` "Color+Alpha" views (R, G, Alpha): with the Alpha output linked,
    Cycles un-premultiplies the colour, otherwise the colour of a byte image is premultiplied."""
    def build(g):
        n = g.new("ShaderNodeTexImage", {"interpolation": interpolation, "extension": extension},
                  Vector=g.p((1.25, 1.25), (0.5625, 0.5625, 0.0), source="UV"))
        n.image = make_image(kind)
        if alpha_mode is not None:
            n.image.alpha_mode = alpha_mode
        if output == "Color+Alpha":
            r, gr, _ = g.new("ShaderNodeSeparateColor", Color=g.out(n, "Color")).outputs
            return g.comb(r, gr, g.out(n, "Alpha"))
        return g.out(n, output)
    return build


for interp in ("Linear", "Closest"):
    for ext in ("REPEAT", "EXTEND", "CLIP", "MIRROR"):
        case("image-srgb8-%s-%s" % (interp.lower(), ext.lower()), image_case("srgb8", interp, ext),
             )
case("image-srgb8-linear-repeat-alpha", image_case("srgb8", "Linear", "REPEAT", "Alpha"))
case("image-data8-linear-repeat", image_case("data8", "Linear", "REPEAT"))
case("image-data8-closest-mirror", image_case("data8", "Closest", "MIRROR"))
for interp in ("Linear", "Closest"):
    for ext in ("REPEAT", "EXTEND"):
        case("image-float-%s-%s" % (interp.lower(), ext.lower()), image_case("float", interp, ext))
case("image-float-linear-repeat-alpha", image_case("float", "Linear", "REPEAT", "Alpha"))
for kind in ("srgb8", "data8", "float"):
    for interp in ("Linear", "Closest"):
        case("image-%s-%s-color+alpha" % (kind, interp.lower()),
             image_case(kind, interp, "REPEAT", "Color+Alpha"))
for mode in ("CHANNEL_PACKED", "NONE", "PREMUL"):
    for output in ("Color", "Color+Alpha"):
        case("image-srgb8-linear-%s-%s" % (mode.lower(), output.lower()),
             image_case("srgb8", "Linear", "REPEAT", output, mode))
        case("image-float-linear-%s-%s" % (mode.lower(), output.lower()),
             image_case("float", "Linear", "REPEAT", output, mode))


# -- constants, Light Path, Bump, Normal Map -----------------------------------------------------

def constants_case(g):
    rgb = g.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.8, 0.25, 0.6, 1.0)
    val = g.new("ShaderNodeValue")
    val.outputs[0].default_value = 0.375
    v = g.vmath("MULTIPLY_ADD", g.snapped(), (0.25, 0.25, 0.0), rgb.outputs[0])
    return g.vmath("SCALE", v, scale=val.outputs[0])


case("value_rgb", constants_case, offset=1.0)


def light_path_case(output, scale=1.0):
    """``output`` of Light Path scaled, plus a field (a flat image would test nothing)."""
    def build(g):
        lp = g.out(g.new("ShaderNodeLightPath"), output)
        return g.math("MULTIPLY_ADD", lp, scale, g.lin(0.25, 0.25, 0.5))
    return build


for output in ("Is Camera Ray", "Is Shadow Ray", "Is Diffuse Ray", "Is Glossy Ray",
               "Is Singular Ray", "Is Reflection Ray", "Is Transmission Ray", "Ray Depth",
               "Diffuse Depth", "Glossy Depth", "Transparent Depth", "Transmission Depth"):
    for mode in ("emission", "diffuse"):
        case("light_path-%s-%s" % (output.lower().replace(" ", "_"), mode),
             light_path_case(output, 0.5), mode=mode, offset=0.25 if mode == "diffuse" else 0.0,
             scale=0.5 if mode == "diffuse" else 1.0)
case("light_path-ray_length", light_path_case("Ray Length", 0.1))


def raw_height(g, cx, cy, c0):
    x, y, _ = g.sep(g.new("ShaderNodeTexCoord").outputs["Object"])
    return g.math("MULTIPLY_ADD", x, cx, g.math("MULTIPLY_ADD", y, cy, c0))


def bump_case(strength=0.8, distance=0.5, invert=False, height="linear"):
    """Bump's Normal over the plane, seen through the diffuse set-up (normal * 0.5 + 0.5). A
    linear height has the same gradient however it is differentiated (Cycles: forward
    differences over the ray differentials; Tesela: over a small fixed step)."""
    def build(g):
        if height == "linear":
            h = raw_height(g, 0.4, -0.25, 0.1)
        else:
            n = g.new("ShaderNodeTexNoise", Vector=g.new("ShaderNodeTexCoord").outputs["Object"],
                      Scale=1.5, Detail=0.0)
            h = g.math("MULTIPLY", g.out(n, "Fac"), 0.3)
        n = g.new("ShaderNodeBump", {"invert": invert}, Strength=strength, Distance=distance,
                  Height=h)
        return g.out(n, "Normal")
    return build


case("bump-linear", bump_case(), mode="diffuse", scale=0.5, offset=0.5, snapped=False)
case("bump-linear-invert-strong", bump_case(1.0, 2.0, True), mode="diffuse", scale=0.5,
     offset=0.5, snapped=False)
case("bump-linear-facets", bump_case(0.6, 1.0), geometry=facets, mode="diffuse", scale=0.5,
     offset=0.5, stable_tol=1e-3)  # a linear height: one normal per facet, up to the
# rounding of the finite differences (~5e-5 between samples)
case("bump-noise", bump_case(0.7, 0.2, height="noise"), mode="diffuse", scale=0.5, offset=0.5,
     snapped=False)


def normal_map_case(space, uv_map="", strength=0.9, source="Object"):
    def build(g):
        color = g.vec([(0.2, 0.0, 0.6), (0.0, -0.2, 0.45), (0.05, 0.05, 0.85)], source=source)
        n = g.new("ShaderNodeNormalMap", {"space": space, "uv_map": uv_map}, Strength=strength,
                  Color=color)
        return g.out(n, "Normal")
    return build


for space, uv, geom, k in (("TANGENT", "", plane, 1.0), ("TANGENT", "Second", plane, 1.0),
                           ("TANGENT", "", facets, 1.0), ("TANGENT", "", plane, 0.6),
                           ("OBJECT", "", transformed_plane, 0.9), ("WORLD", "", plane, 0.9),
                           ("WORLD", "", facets, 0.7)):
    cid = "normal_map-%s%s-%s-strength%g" % (space.lower(), "-" + uv.lower() if uv else "",
                                             geom.__name__, k)
    case(cid, normal_map_case(space, uv, k, "Object" if geom is plane else "Position"),
         geometry=geom, mode="diffuse", scale=0.5, offset=0.5,
         xfail=None)


# -- node groups and muted nodes -----------------------------------------------------------------

def group_case(g):
    """A group: a linked Vector and Fac, an unlinked input with its group default (Gain), a
    noise and a mix inside."""
    grp = bpy.data.node_groups.new("Tint", "ShaderNodeTree")
    grp.interface.new_socket("Vector", in_out="INPUT", socket_type="NodeSocketVector")
    grp.interface.new_socket("Fac", in_out="INPUT", socket_type="NodeSocketFloat")
    s = grp.interface.new_socket("Gain", in_out="INPUT", socket_type="NodeSocketFloat")
    s.default_value = 0.75
    grp.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    gin = grp.nodes.new("NodeGroupInput")
    gout = grp.nodes.new("NodeGroupOutput")
    noise = grp.nodes.new("ShaderNodeTexNoise")
    noise.inputs["Scale"].default_value = 3.0
    grp.links.new(gin.outputs["Vector"], noise.inputs["Vector"])
    mul = grp.nodes.new("ShaderNodeMath")
    mul.operation = "MULTIPLY"
    grp.links.new(gin.outputs["Fac"], mul.inputs[0])
    grp.links.new(gin.outputs["Gain"], mul.inputs[1])
    mix = grp.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "OVERLAY"
    grp.links.new(mul.outputs[0], _sock(mix.inputs, "Factor_Float"))
    grp.links.new(noise.outputs["Color"], _sock(mix.inputs, "A_Color"))
    _sock(mix.inputs, "B_Color").default_value = (0.2, 0.7, 0.4, 1.0)
    grp.links.new(_sock(mix.outputs, "Result_Color"), gout.inputs["Color"])
    node = g.new("ShaderNodeGroup")
    node.node_tree = grp
    g.set(node, "Vector", P3(g))
    g.set(node, "Fac", g.lin(0.5, 0.5, 1.0))
    return g.out(node)


case("node_group", group_case)


def group_snapped_case(g):
    grp = bpy.data.node_groups.new("Warp", "ShaderNodeTree")
    grp.interface.new_socket("Vector", in_out="INPUT", socket_type="NodeSocketVector")
    s = grp.interface.new_socket("Scale", in_out="INPUT", socket_type="NodeSocketFloat")
    s.default_value = 2.5
    grp.interface.new_socket("Value", in_out="OUTPUT", socket_type="NodeSocketFloat")
    gin = grp.nodes.new("NodeGroupInput")
    gout = grp.nodes.new("NodeGroupOutput")
    vor = grp.nodes.new("ShaderNodeTexVoronoi")
    vor.feature = "SMOOTH_F1"
    grp.links.new(gin.outputs["Vector"], vor.inputs["Vector"])
    grp.links.new(gin.outputs["Scale"], vor.inputs["Scale"])
    reroute = grp.nodes.new("NodeReroute")
    grp.links.new(vor.outputs["Distance"], reroute.inputs[0])
    grp.links.new(reroute.outputs[0], gout.inputs["Value"])
    node = g.new("ShaderNodeGroup")
    node.node_tree = grp
    g.set(node, "Vector", P3(g))
    return g.out(node)


case("node_group-snapped", group_snapped_case, offset=1.0)


def menu_switch_case(g):
    """Menu Switches as node groups use them: a group whose Menu input picks one of three
    items (a noise, a linked field, a constant colour), set to the second by the group node,
    and a switch on the node itself whose per-item boolean output scales the result."""
    grp = bpy.data.node_groups.new("Pick", "ShaderNodeTree")
    grp.interface.new_socket("Vector", in_out="INPUT", socket_type="NodeSocketVector")
    grp.interface.new_socket("Mode", in_out="INPUT", socket_type="NodeSocketMenu")
    grp.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    gin = grp.nodes.new("NodeGroupInput")
    gout = grp.nodes.new("NodeGroupOutput")
    sw = grp.nodes.new("GeometryNodeMenuSwitch")
    sw.data_type = "RGBA"
    sw.enum_items[0].name, sw.enum_items[1].name = "Noise", "Field"
    sw.enum_items.new("Flat")
    noise = grp.nodes.new("ShaderNodeTexNoise")
    grp.links.new(gin.outputs["Vector"], noise.inputs["Vector"])
    grp.links.new(noise.outputs["Color"], sw.inputs["Noise"])
    grp.links.new(gin.outputs["Vector"], sw.inputs["Field"])
    sw.inputs["Flat"].default_value = (0.9, 0.1, 0.1, 1.0)
    grp.links.new(gin.outputs["Mode"], sw.inputs["Menu"])
    grp.links.new(sw.outputs["Output"], gout.inputs["Color"])
    node = g.new("ShaderNodeGroup")
    node.node_tree = grp
    g.set(node, "Vector", g.vmath("ABSOLUTE", P3(g)))
    node.inputs["Mode"].default_value = "Field"
    gate = g.new("GeometryNodeMenuSwitch", {"data_type": "FLOAT"})
    gate.inputs["Menu"].default_value = "B"
    on = g.math("MULTIPLY_ADD", gate.outputs["B"], 0.5, 0.25)
    return g.out(g.new("ShaderNodeMix", {"data_type": "RGBA", "blend_type": "MULTIPLY"},
                       Factor_Float=1.0, A_Color=g.out(node), B_Color=g.comb(on, on, on)),
                 "Result_Color")


case("menu_switch", menu_switch_case)


def muted_case(kind):
    def build(g):
        if kind == "math":
            n = g.new("ShaderNodeMath", {"operation": "POWER"}, Value=g.lin(0.5, 0.25, 0.5),
                      Value_001=3.0)
        elif kind == "mix":
            n = g.new("ShaderNodeMix", {"data_type": "RGBA", "blend_type": "MULTIPLY"},
                      Factor_Float=0.7, A_Color=g.color_a(), B_Color=g.color_b())
        else:  # muted Map Range: Value passes through to Result
            n = g.new("ShaderNodeMapRange", Value=g.lin(0.5, 0.25, 0.5),
                      **{"From Min": 0.2, "To Max": 3.0})
        n.mute = True
        return g.out(n, {"math": "Value", "mix": "Result_Color", "map_range": "Result"}[kind])
    return build


for kind in ("math", "mix", "map_range"):
    case("muted-%s" % kind, muted_case(kind), offset=1.0)


# --------------------------------------------------------------------------------------------
# rendering and comparing


def render_both(tmp_path, spp, seeds=(1, 2), mode="emission"):
    """Cycles (1 sample at the pixel centre) and Tesela through the add-on (``spp`` samples,
    one render per seed) of the current scene: float32 (N, N, 4) arrays, rows top to bottom.
    Emission: Cycles max bounces 0, Tesela direct_mis at depth 1 (emission seen directly);
    diffuse: Cycles max bounces 0, Tesela path_mats at depth 2 (one BSDF-sampled bounce)."""
    scene = bpy.context.scene
    scenes.configure_cycles(scene, N, N, 1, 0, seed=3)
    scene.cycles.filter_width = 0.01
    ref = imgcompare.read_exr(scenes.render_cycles(tmp_path / "cycles.exr"))
    scene.render.engine = "TESELA"
    t = scene.tesela
    scenes.tesela_like_cycles(t)
    if mode == "diffuse":
        t.integrator, t.samples, t.max_depth = "path_mats", spp, 2
    else:
        t.integrator, t.samples, t.max_depth = "direct_mis", spp, 1
    t.threads = int(os.environ.get("TESELA_TEST_THREADS", "0"))
    out = []
    for seed in seeds:
        t.seed = seed
        assert bpy.ops.render.render() == {"FINISHED"}
        out.append(result_pixels(tmp_path))
    return ref, out


def build_case(c):
    reset_scene()
    mat = new_material("Node")
    g = G(mat)
    sock = c.build(g)
    finish(g, sock, c.offset, c.scale, c.mode)
    c.geometry(mat)
    if c.mode == "diffuse":
        white_world()
    return g


def white_world():
    """A constant world of radiance 1 that is not sampled as a light: a Lambertian surface
    (roughness 0) that sees only the world then reflects exactly its albedo along every
    cosine-sampled path (Cycles: max bounces 0, where the BSDF ray still collects the world;
    Tesela: path_mats at depth 2), with no noise."""
    world = bpy.context.scene.world
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    world.color = (1.0, 1.0, 1.0)
    world.cycles.sampling_method = "NONE"


def measure(c, ref, renders):
    """Per-pixel figures: (error per pixel (relative, RGB max), mask of compared pixels)."""
    r = ref[..., :3].astype(np.float64)
    a = renders[0][..., :3].astype(np.float64)
    if c.snapped and len(renders) > 1:
        d = np.abs(a - renders[1][..., :3]) / np.maximum(1.0, np.abs(a))
        stable = np.all(d <= c.stable_tol, axis=-1)  # rounding (a quad's two triangles) stays in
    else:
        stable = np.ones(r.shape[:2], bool)
    err = (np.abs(a - r) / np.maximum(1.0, np.abs(r))).max(axis=-1)
    return err, stable


@pytest.mark.parametrize("c", [pytest.param(c, id=c.id, marks=[pytest.mark.xfail(
    strict=True, reason=c.xfail)] if c.xfail else []) for c in CASES])
def test_node_matches_cycles(addon, tesela_bin, tmp_path, monkeypatch, c):
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    build_case(c)
    ref, renders = render_both(tmp_path, c.spp, seeds=(1, 2) if c.snapped else (1,),
                               mode=c.mode)
    r = ref[..., :3]
    assert np.all(np.isfinite(r)), "%s: the Cycles reference has NaN/inf pixels" % c.id
    assert r.min() >= 0.0, ("%s: the Cycles reference goes negative (%g): raise the case's "
                            "offset" % (c.id, r.min()))
    assert np.ptp(r) > 1e-3, "%s: the Cycles reference is flat: the case tests nothing" % c.id
    err, stable = measure(c, ref, renders)
    unstable = int(np.count_nonzero(~stable))
    e = err[stable]
    worst = np.unravel_index(int(np.argmax(np.where(stable, err, -1.0))), err.shape)
    off = float(np.mean(e > OFF))
    print("NODECASE %s: max %.3g, p99 %.3g, off %.4f, unstable %d, worst px %s "
          "tesela %s cycles %s" % (c.id, e.max(), np.percentile(e, 99), off, unstable, worst,
                                   np.round(renders[0][worst][:3], 5), np.round(r[worst], 5)))
    assert unstable <= N * N // 500, (
        "%s: %d pixels differ between two Tesela seeds: the input is not constant per pixel"
        % (c.id, unstable))
    if c.disc:
        assert off <= c.frac, "%s: %.2f%% of pixels off by more than %g (max %.3g at %s)" % (
            c.id, 100 * off, OFF, e.max(), worst)
    else:
        assert e.max() <= c.tol, "%s: max error %.3g at pixel %s (Tesela %s, Cycles %s)" % (
            c.id, e.max(), worst, renders[0][worst][:3], r[worst])


# --------------------------------------------------------------------------------------------
# the method itself, and what the add-on writes for the fixes above


def test_pixel_centre_sampling(addon, tesela_bin, tmp_path, monkeypatch):
    """Measures what the method rests on: Cycles' sample (1 spp, 0.01-px filter) sits at the
    pixel centre; Tesela's 1-spp sample anywhere in the pixel (so raw coordinates differ by up
    to half a pixel), its 64-spp mean at the centre, and snapped coordinates are the pixel
    centre's in both, except for the odd sample that rounds across a pixel edge."""
    monkeypatch.setenv("TESELA_BINARY", str(tesela_bin))
    ys, xs = np.mgrid[0:N, 0:N]
    centre = np.stack([-1.0 + (xs + 0.5) * 2.0 / N, 1.0 - (ys + 0.5) * 2.0 / N], axis=-1)
    px = 2.0 / N
    figures = {}
    for name, snapped, spp in (("raw-1spp", False, 1), ("raw-64spp", False, 64),
                               ("snapped-1spp", True, 1)):
        c = Case(name, (lambda g: g.snapped()) if snapped else coord("Object"), offset=2.0,
                 snapped=snapped, spp=spp)
        build_case(c)
        ref, renders = render_both(tmp_path, spp, seeds=(1, 2) if snapped else (1,))
        cyc = np.abs(ref[..., :2] - 2.0 - centre).max() / px
        tes = np.abs(renders[0][..., :2] - 2.0 - centre).max() / px
        err, stable = measure(c, ref, renders)
        figures[name] = (cyc, tes, float(err[stable].max()), int(np.count_nonzero(~stable)))
        print("CENTRE %s: Cycles off the centre by %.4f px, Tesela by %.4f px; max error %.3g, "
              "unstable %d" % ((name,) + figures[name]))
    assert all(f[0] < 0.006 for f in figures.values())       # Cycles: within the 0.01-px filter
    assert figures["raw-1spp"][1] > 0.4                        # Tesela 1 spp: anywhere
    assert figures["raw-64spp"][1] < 0.02                       # its mean: the centre
    assert figures["snapped-1spp"][2] == 0.0 and figures["snapped-1spp"][3] <= 2


def test_image_alpha_props_exported(addon, tmp_path):
    """The add-on tells the renderer whether an Image Texture's Alpha output is used and the
    image's own colour space (docs/extensions.md), which Cycles' alpha association needs."""
    import json
    reset_scene()
    mat = new_material("Img")
    g = G(mat)
    used = g.new("ShaderNodeTexImage")
    used.name = "Used"
    used.image = make_image("float")
    unused = g.new("ShaderNodeTexImage")
    unused.name = "Unused"
    unused.image = make_image("srgb8")
    dangling = g.new("ShaderNodeMath", Value=g.out(unused, "Alpha"))  # reaches nothing
    assert dangling.outputs[0].is_linked is False
    r, gr, _ = g.new("ShaderNodeSeparateColor", Color=g.out(used, "Color")).outputs
    mix = g.vmath("ADD", g.comb(r, gr, g.out(used, "Alpha")), g.out(unused, "Color"))
    finish(g, mix)
    plane(mat)
    path = tmp_path / "alpha.gltf"
    assert bpy.ops.export_scene.tesela_gltf(filepath=str(path)) == {"FINISHED"}
    doc = json.loads(path.read_text(encoding="utf-8"))
    graph = next(m for m in doc["materials"] if m["name"] == "Img")["extensions"][
        "TESELA_material_graph"]
    props = {n["name"]: n["props"] for n in graph["nodes"] if n["type"] == "ShaderNodeTexImage"}
    assert props["Used"]["alpha_linked"] is True
    assert props["Unused"]["alpha_linked"] is False
    assert props["Used"]["colorspace"] == "Non-Color"  # float pixels travel converted ...
    assert props["Used"]["source_colorspace"] == "Linear Rec.709"  # ... from their own space
    assert props["Unused"]["source_colorspace"] == props["Unused"]["colorspace"] == "sRGB"
