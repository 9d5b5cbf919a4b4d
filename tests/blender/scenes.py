"""Small Blender scenes built in code, for comparing Tesela with Cycles.

Works in Blender 3.4 (``blender -b --python``) and Blender 4.x/5.x (the PyPI ``bpy`` module).
Everything acts on ``bpy.context.scene``, the scene Blender's glTF exporter and ``render.render``
use; this module keeps no state of its own.

Public API (all lengths in metres, angles in radians, colours linear RGB):

* ``clear_scene()`` -> scene: empty the current scene and remove unused data blocks.
* ``material(name, base_color=..., metallic=..., roughness=..., specular=..., transmission=...,
  ior=..., emission=..., emission_strength=...)`` -> a Principled BSDF material. ``specular`` is
  Blender 4+'s "Specular IOR Level" (0.5 = physically based, 0 = no specular: Lambertian).
  Shortcuts: ``lambert(name, color)``, ``mirror(name, color)``, ``glass(name, ior)``,
  ``emitter(name, color, strength)``.
* geometry: ``add_mesh``, ``add_quad``, ``add_box``, ``add_sphere``, ``uv_sphere_add``
  (Blender's UV sphere operator, its faces in a fixed order: ``canonical_order``).
* lights: ``add_point_light``, ``add_spot_light``, ``add_sun_light``, ``add_area_light``.
  Lights point along their local -Z, aimed with ``look_at``/``direction``.
* ``add_camera(location, target, fov=..., ortho_scale=None)``.
* ``configure_cycles(scene, width, height, spp, max_bounces, seed)``: unbiased, comparable settings.
* ``render_cycles(path)``, ``export_gltf(path)``: render the current scene to an EXR / write glTF.
* ready scenes: ``cornell_box(spheres=False)``, ``light_over_plane(kind)``, ``emissive_sphere()``,
  ``glass_slab(color)``, each returning a ``SceneInfo`` (the scene and a few facts the tests need).

Blender version differences live in ``_principled_socket`` (socket names), ``_use_nodes`` and
``_set_if`` (settings that only some versions have).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import bpy  # first: the PyPI module makes bmesh and mathutils importable
import bmesh
from mathutils import Vector

# --------------------------------------------------------------------------------------------
# version compatibility

# Blender 4.0 renamed these Principled BSDF inputs (new name -> 3.x name).
_OLD_SOCKETS = {
    "Specular IOR Level": "Specular",
    "Transmission Weight": "Transmission",
    "Emission Color": "Emission",
}


def _principled_socket(node, name):
    """The Principled BSDF input called ``name`` (Blender 4+ naming) in any Blender version."""
    sock = node.inputs.get(name)
    if sock is None and name in _OLD_SOCKETS:
        sock = node.inputs.get(_OLD_SOCKETS[name])
    if sock is None:
        raise KeyError(f"Principled BSDF has no input {name!r} in Blender {bpy.app.version_string}")
    return sock


def _use_nodes(idblock):
    """Give a material or world its node tree (5.0+ always has one and deprecates use_nodes)."""
    if bpy.app.version < (5, 0, 0) or idblock.node_tree is None:
        idblock.use_nodes = True
    return idblock.node_tree


def _set_if(obj, attr, value):
    """Set ``obj.attr`` when this Blender version has it (returns whether it did)."""
    if hasattr(obj, attr):
        setattr(obj, attr, value)
        return True
    return False


# --------------------------------------------------------------------------------------------
# scene and materials


def clear_scene():
    """Remove every object of the current scene and every unused mesh, material, light and
    camera, give the scene a new black world, and return the (current) scene.

    The world is replaced rather than edited: a test that changed its settings (sampling
    method, ray visibility, ...) must not change the renders of the tests after it."""
    scene = bpy.context.scene
    # Square pixels: a test of non-square ones must not reshape the next tests' frames.
    scene.render.pixel_aspect_x = scene.render.pixel_aspect_y = 1.0
    # Every object, also those only in collections the scene instances (not linked to it),
    # whose names a later test would otherwise find taken.
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in list(bpy.data.collections):
        bpy.data.collections.remove(coll)
    old_world, scene.world = scene.world, None
    if old_world is not None and old_world.users == 0:
        bpy.data.worlds.remove(old_world)
    for coll in (bpy.data.meshes, bpy.data.materials, bpy.data.lights, bpy.data.cameras,
                 bpy.data.node_groups, getattr(bpy.data, "hair_curves", ()),
                 getattr(bpy.data, "pointclouds", ())):
        for block in list(coll):
            if block.users == 0:
                coll.remove(block)
    world = bpy.data.worlds.new("World")
    scene.world = world
    bg = next((n for n in _use_nodes(world).nodes if n.type == "BACKGROUND"), None)
    if bg is not None:
        bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        bg.inputs["Strength"].default_value = 0.0
    world.color = (0.0, 0.0, 0.0)
    return scene


def material(name, base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, specular=0.5,
             transmission=0.0, ior=1.5, emission=(0.0, 0.0, 0.0), emission_strength=0.0,
             double_sided=True):
    """A new Principled BSDF material. ``double_sided=False`` turns on backface culling, which
    Blender's glTF exporter writes as ``doubleSided: false``."""
    mat = bpy.data.materials.new(name)
    mat.use_backface_culling = not double_sided
    bsdf = next(n for n in _use_nodes(mat).nodes if n.type == "BSDF_PRINCIPLED")
    values = {
        "Base Color": (*base_color, 1.0),
        "Metallic": metallic,
        "Roughness": roughness,
        "Specular IOR Level": specular,
        "Transmission Weight": transmission,
        "IOR": ior,
        "Emission Color": (*emission, 1.0),
    }
    if "Emission Strength" in bsdf.inputs:  # 2.91+
        values["Emission Strength"] = emission_strength
    else:
        values["Emission Color"] = (*(c * emission_strength for c in emission), 1.0)
    for key, value in values.items():
        _principled_socket(bsdf, key).default_value = value
    mat.diffuse_color = (*base_color, 1.0)
    return mat


def shader_only(name, kind):
    """A new material whose surface is one node of type ``kind`` (Blender's default Principled
    BSDF removed): returns the material, its node tree and the node."""
    m = bpy.data.materials.new(name)
    nt = _use_nodes(m)
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    node = nt.nodes.new(kind)
    nt.links.new(node.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
    return m, nt, node


def lambert(name, color):
    """A Lambertian reflector: Principled with no specular layer, roughness 1."""
    return material(name, base_color=color, roughness=1.0, specular=0.0)


def mirror(name, color=(1.0, 1.0, 1.0)):
    """A perfect mirror: metallic 1, roughness 0."""
    return material(name, base_color=color, metallic=1.0, roughness=0.0)


def glass(name, ior=1.5, color=(1.0, 1.0, 1.0)):
    """Ideal clear glass: transmission 1, roughness 0 (``color`` tints the refraction)."""
    return material(name, base_color=color, roughness=0.0, transmission=1.0, ior=ior)


def emitter(name, color, strength):
    """A black, non-reflecting surface emitting radiance ``color * strength`` (W/(m² sr))."""
    return material(name, base_color=(0.0, 0.0, 0.0), roughness=1.0, specular=0.0,
                    emission=color, emission_strength=strength)


# --------------------------------------------------------------------------------------------
# geometry


def add_mesh(name, verts, faces, mat=None, smooth=False, location=(0.0, 0.0, 0.0)):
    """An object made of ``verts`` (xyz tuples) and ``faces`` (vertex index tuples, counter-
    clockwise seen from the front)."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
    mesh.update()
    if smooth:
        mesh.polygons.foreach_set("use_smooth", [True] * len(mesh.polygons))
        mesh.update()
    if mat is not None:
        mesh.materials.append(mat)
    ob = bpy.data.objects.new(name, mesh)
    ob.location = location
    bpy.context.scene.collection.objects.link(ob)
    return ob


def add_quad(name, corners, mat=None):
    """A quad through four corners, counter-clockwise seen from its front side."""
    return add_mesh(name, corners, [(0, 1, 2, 3)], mat)


def add_box(name, lo, hi, mat=None):
    """An axis-aligned box with outward normals."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    f = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return add_mesh(name, v, f, mat)


def add_room(walls, floor=None, size=(4.0, 4.0, 2.6), window=(1.4, 1.0, 2.0)):
    """A closed room centred on the origin, floor at z = 0 (material `floor`, or none: the
    caller lays its own), ceiling and walls of material `walls`; the -y wall has a window
    `window = (width, bottom, top)` (metres) centred in x."""
    sx, sy, h = size
    x0, x1, y0, y1 = -sx / 2, sx / 2, -sy / 2, sy / 2
    if floor is not None:
        add_quad("Floor", [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], floor)
    add_quad("Ceiling", [(x0, y0, h), (x0, y1, h), (x1, y1, h), (x1, y0, h)], walls)
    add_quad("Back", [(x0, y1, 0), (x1, y1, 0), (x1, y1, h), (x0, y1, h)], walls)
    add_quad("Left", [(x0, y0, 0), (x0, y1, 0), (x0, y1, h), (x0, y0, h)], walls)
    add_quad("Right", [(x1, y0, 0), (x1, y0, h), (x1, y1, h), (x1, y1, 0)], walls)
    # The front wall (y = y0, facing +y) around the window.
    wx, wz0, wz1 = window[0] / 2, window[1], window[2]
    front = [[(x0, 0), (-wx, 0), (-wx, h), (x0, h)], [(wx, 0), (x1, 0), (x1, h), (wx, h)],
             [(-wx, 0), (wx, 0), (wx, wz0), (-wx, wz0)], [(-wx, wz1), (wx, wz1), (wx, h), (-wx, h)]]
    for i, q in enumerate(front):
        add_quad(f"Front{i}", [(x, y0, z) for x, z in q][::-1], walls)


def canonical_order(bm):
    """Sorts the faces and edges of BMesh ``bm`` by their vertex indices, and returns it.

    Blender's UV sphere (``bmesh.ops.create_uvsphere``, and so ``primitive_uv_sphere_add``) lists
    the same faces and edges in an order that changes from call to call. The face order decides
    the last bits of Blender's vertex normals (summed face by face) and the triangles' order in
    a renderer's BVH, so a scene built twice would not render bit-identically."""
    bm.verts.index_update()
    n = len(bm.verts)

    def verts(elem):
        return tuple(v.index for v in elem.verts)

    rank = {key: i for i, key in enumerate(sorted(verts(f) for f in bm.faces))}
    bm.faces.sort(key=lambda f: rank[verts(f)])  # sort() wants numbers
    bm.edges.sort(key=lambda e: min(verts(e)) * n + max(verts(e)))
    bm.faces.index_update()
    bm.edges.index_update()
    return bm


def uv_sphere_add(**kwargs):
    """``bpy.ops.mesh.primitive_uv_sphere_add(**kwargs)`` with its faces in a fixed order (see
    :func:`canonical_order`); returns the new (active) object."""
    bpy.ops.mesh.primitive_uv_sphere_add(**kwargs)
    ob = bpy.context.active_object
    me = ob.data
    bm = bmesh.new()
    bm.from_mesh(me)
    canonical_order(bm).to_mesh(me)
    bm.free()
    # Its edges' directions vary too (a BMesh edge's cannot be changed).
    ends = [0] * (2 * len(me.edges))
    me.edges.foreach_get("vertices", ends)
    for i in range(0, len(ends), 2):
        ends[i], ends[i + 1] = sorted(ends[i:i + 2])
    me.edges.foreach_set("vertices", ends)
    me.update()
    return ob


def add_sphere(name, center, radius, mat=None, segments=48, rings=24, smooth=True):
    """A UV sphere with outward normals."""
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    canonical_order(bm)
    verts = [tuple(v.co) for v in bm.verts]
    faces = [tuple(v.index for v in f.verts) for f in bm.faces]
    bm.free()
    return add_mesh(name, verts, faces, mat, smooth=smooth, location=center)


# --------------------------------------------------------------------------------------------
# lights and camera


def _aim(ob, target=None, direction=None):
    """Rotate ``ob`` so that its local -Z points at ``target`` (or along ``direction``)."""
    if direction is None:
        direction = Vector(target) - Vector(ob.location)
    ob.rotation_mode = "QUATERNION"
    ob.rotation_quaternion = Vector(direction).to_track_quat("-Z", "Y")


def _add_light(name, kind, location, color, target=None, direction=None, **settings):
    data = bpy.data.lights.new(name, kind)
    data.color = color
    for key, value in settings.items():
        setattr(data, key, value)
    ob = bpy.data.objects.new(name, data)
    ob.location = location
    if target is not None or direction is not None:
        _aim(ob, target, direction)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def add_point_light(name, location, power, color=(1.0, 1.0, 1.0), radius=0.0):
    """A point light of ``power`` W (Cycles: intensity power/(4π) W/sr); radius 0 = hard shadows."""
    return _add_light(name, "POINT", location, color, energy=power, shadow_soft_size=radius)


def add_spot_light(name, location, target, power, spot_size, blend=0.0, color=(1.0, 1.0, 1.0),
                   radius=0.0):
    """A spot light aimed at ``target``; ``spot_size`` is the full cone angle."""
    return _add_light(name, "SPOT", location, color, target=target, energy=power,
                      shadow_soft_size=radius, spot_size=spot_size, spot_blend=blend)


def add_sun_light(name, direction, strength, color=(1.0, 1.0, 1.0), angle=0.0):
    """A sun whose light travels along ``direction``; ``strength`` is the irradiance in W/m²."""
    return _add_light(name, "SUN", (0.0, 0.0, 10.0), color, direction=direction,
                      energy=strength, angle=angle)


def add_area_light(name, location, target, power, size, color=(1.0, 1.0, 1.0)):
    """A square area light (side ``size``) facing ``target``; Blender's exporter drops it."""
    return _add_light(name, "AREA", location, color, target=target, energy=power,
                      shape="SQUARE", size=size)


def add_camera(location, target, fov=math.radians(40.0), ortho_scale=None, name="Camera"):
    """Make the scene camera: perspective with ``fov`` across the larger image side, or
    orthographic ``ortho_scale`` metres across the larger side."""
    cam = bpy.data.cameras.new(name)
    cam.sensor_fit = "AUTO"
    if ortho_scale is None:
        cam.type = "PERSP"
        cam.angle = fov
    else:
        cam.type = "ORTHO"
        cam.ortho_scale = ortho_scale
    cam.clip_start = 0.01
    cam.clip_end = 100.0
    ob = bpy.data.objects.new(name, cam)
    ob.location = location
    _aim(ob, target)
    bpy.context.scene.collection.objects.link(ob)
    bpy.context.scene.camera = ob
    return ob


# --------------------------------------------------------------------------------------------
# rendering and export


def configure_cycles(scene, width=64, height=64, spp=64, max_bounces=8, seed=0, threads=0):
    """Cycles on the CPU with settings that make it an unbiased reference: no denoiser, no
    adaptive sampling, no clamping, no glossy filter, no light threshold, a 1-pixel box filter,
    caustics on, and every bounce limit equal to ``max_bounces`` (0 = direct light only, which
    is Tesela's ``--max-depth 2``; in general depth = max_bounces + 2)."""
    scene.render.engine = "CYCLES"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.cycles.film_transparent_glass = False
    scene.cycles.film_transparent_roughness = 0.1
    scene.render.use_persistent_data = False
    if threads:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads
    else:
        scene.render.threads_mode = "AUTO"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.seed = seed
    c.use_animated_seed = False
    _set_if(c, "use_adaptive_sampling", False)
    _set_if(c, "use_denoising", False)
    _set_if(c, "use_preview_denoising", False)
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = max_bounces
    c.diffuse_bounces = max_bounces
    c.glossy_bounces = max_bounces
    c.transmission_bounces = max_bounces
    c.volume_bounces = 0
    c.transparent_max_bounces = max(8, max_bounces)
    c.min_light_bounces = 0
    c.min_transparent_bounces = 0
    _set_if(c, "use_light_tree", True)
    _set_if(c, "use_guiding", False)
    _set_if(c, "use_auto_tile", False)
    _set_if(c, "film_exposure", 1.0)
    return scene


def tesela_like_cycles(settings):
    """Tesela's render settings (``scene.tesela``) matched to :func:`configure_cycles`'
    reference: fixed samples (no noise threshold, no denoiser), a 1-pixel box filter, every
    kind of bounce up to the total, no clamping, caustics on, no Filter Glossy. Integrator,
    samples and depth stay the caller's."""
    settings.use_adaptive_sampling = settings.use_denoising = False
    settings.pixel_filter_type, settings.filter_width = "BOX", 1.0
    settings.diffuse_bounces = settings.glossy_bounces = settings.transmission_bounces = 1024
    if hasattr(settings, "volume_bounces"):
        settings.volume_bounces = 0  # configure_cycles' (and Cycles' default)
    settings.sample_clamp_direct = settings.sample_clamp_indirect = 0.0
    if hasattr(settings, "caustics_reflective"):
        settings.caustics_reflective = settings.caustics_refractive = True
    if hasattr(settings, "blur_glossy"):
        settings.blur_glossy = 0.0


def render_cycles(path):
    """Render the current scene with its current settings to a 32-bit linear EXR at ``path``."""
    scene = bpy.context.scene
    settings = scene.render.image_settings
    _set_if(settings, "media_type", "IMAGE")  # 5.0+
    settings.file_format = "OPEN_EXR"
    settings.color_mode = "RGBA"
    settings.color_depth = "32"
    settings.exr_codec = "ZIP"
    scene.render.use_file_extension = False
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    return str(path)


def export_gltf(path):
    """Write the current scene with Blender's glTF exporter: default settings, plus cameras and
    lights (so punctual lights use the default 'SPEC' photometric units). The camera's ``yfov``
    and ``aspectRatio`` follow the scene's resolution *at export time*: set it first (e.g. with
    ``configure_cycles``)."""
    path = str(path)
    fmt = "GLB" if path.lower().endswith(".glb") else "GLTF_SEPARATE"
    bpy.ops.export_scene.gltf(filepath=path, export_format=fmt, export_cameras=True,
                              export_lights=True)
    return path


# --------------------------------------------------------------------------------------------
# ready scenes


@dataclass
class SceneInfo:
    """What a builder made: the scene, and facts the tests and the doc rely on."""
    scene: object
    name: str
    notes: dict = field(default_factory=dict)


CORNELL_WHITE = (0.725, 0.71, 0.68)
CORNELL_RED = (0.63, 0.065, 0.05)
CORNELL_GREEN = (0.14, 0.45, 0.091)


def cornell_box(spheres=False, light_strength=12.0):
    """A 2 m Lambertian Cornell box (x, y in [-1, 1], z in [0, 2], open towards -y) lit by a
    0.7 m two-sided emissive quad filling a hole in the ceiling. ``spheres`` adds a mirror sphere and a
    glass sphere (IOR 1.5), radius 0.4, on the floor. Camera at (0, -3.8, 1), 38° field of view."""
    scene = clear_scene()
    white = lambert("White", CORNELL_WHITE)
    red = lambert("Red", CORNELL_RED)
    green = lambert("Green", CORNELL_GREEN)
    add_quad("Floor", [(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], white)
    h = 0.35
    # The ceiling has a square hole that the light fills, flush: a light hanging under a closed
    # ceiling would light it from a few millimetres through its back face (emission is
    # two-sided), a near-singular configuration that makes emitter sampling very noisy.
    ceiling = [[(-1, -1), (-1, 1), (-h, 1), (-h, -1)], [(h, -1), (h, 1), (1, 1), (1, -1)],
               [(-h, -1), (-h, -h), (h, -h), (h, -1)], [(-h, h), (-h, 1), (h, 1), (h, h)]]
    for i, quad in enumerate(ceiling):
        add_quad(f"Ceiling{i}", [(x, y, 2.0) for x, y in quad], white)
    add_quad("Back", [(-1, 1, 0), (1, 1, 0), (1, 1, 2), (-1, 1, 2)], white)
    add_quad("Left", [(-1, -1, 0), (-1, 1, 0), (-1, 1, 2), (-1, -1, 2)], red)
    add_quad("Right", [(1, -1, 0), (1, -1, 2), (1, 1, 2), (1, 1, 0)], green)
    light = emitter("Light", (1.0, 1.0, 1.0), light_strength)
    add_quad("LightQuad", [(-h, -h, 2.0), (-h, h, 2.0), (h, h, 2.0), (h, -h, 2.0)], light)
    if spheres:
        add_sphere("MirrorSphere", (-0.45, 0.35, 0.4), 0.4, mirror("Mirror"))
        add_sphere("GlassSphere", (0.45, -0.3, 0.4), 0.4, glass("Glass", 1.5))
    add_camera((0.0, -3.8, 1.0), (0.0, 0.0, 1.0), fov=math.radians(38.0))
    return SceneInfo(scene, "cornell_spheres" if spheres else "cornell",
                     {"light_radiance": light_strength, "light_area": (2 * h) ** 2})


def light_over_plane(kind, power=100.0, spot_size=math.radians(70.0), spot_blend=0.0,
                     sun_strength=3.0, with_box=True):
    """A 6 m Lambertian plane (albedo 0.8) at z = 0 with a 0.6 m box on it, lit by one light:
    ``kind`` = "point" (``power`` W at (0.5, -0.3, 2)), "spot" (``power`` W at (0, 0, 2.5) aimed
    at (0.3, 0.2, 0), cone ``spot_size``, ``spot_blend``) or "sun" (``sun_strength`` W/m²,
    light travelling along (-0.4, 0.3, -1)). Camera at (0, -4.5, 3.5) looking at the origin."""
    scene = clear_scene()
    floor = lambert("Floor", (0.8, 0.8, 0.8))
    add_quad("Plane", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], floor)
    if with_box:
        add_box("Box", (-0.9, 0.2, 0.0), (-0.3, 0.8, 0.6), lambert("BoxMat", (0.5, 0.6, 0.7)))
    notes = {"albedo": 0.8}
    if kind == "point":
        add_point_light("Point", (0.5, -0.3, 2.0), power)
        notes.update(position=(0.5, -0.3, 2.0), power=power)
    elif kind == "spot":
        add_spot_light("Spot", (0.0, 0.0, 2.5), (0.3, 0.2, 0.0), power, spot_size, spot_blend)
        notes.update(position=(0.0, 0.0, 2.5), power=power, spot_size=spot_size,
                     spot_blend=spot_blend)
    elif kind == "sun":
        add_sun_light("Sun", (-0.4, 0.3, -1.0), sun_strength)
        notes.update(direction=(-0.4, 0.3, -1.0), strength=sun_strength)
    else:
        raise ValueError(f"unknown light kind {kind!r}")
    add_camera((0.0, -4.5, 3.5), (0.0, 0.0, 0.0), fov=math.radians(50.0))
    return SceneInfo(scene, f"{kind}_plane", notes)


def emissive_sphere(strength=4.0, color=(1.0, 0.6, 0.3)):
    """An emissive sphere (radius 0.5 at (0, 0, 0.8), radiance ``color * strength``) over a
    Lambertian plane (albedo 0.8), the only light in the scene."""
    scene = clear_scene()
    add_quad("Plane", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
             lambert("Floor", (0.8, 0.8, 0.8)))
    add_sphere("Sphere", (0.0, 0.0, 0.8), 0.5, emitter("Glow", color, strength))
    add_camera((0.0, -4.0, 2.5), (0.0, 0.0, 0.5), fov=math.radians(45.0))
    return SceneInfo(scene, "emissive_sphere", {"radiance": [c * strength for c in color]})


def glass_slab(color=(0.5, 0.5, 0.5), ior=1.5):
    """A closed glass slab (4 x 4 x 0.2 m, base colour ``color``) 1 m above a two-sided emitter of
    radiance 1, seen straight down through the slab by an orthographic camera 1 m across. Cycles
    4.0+ transmits ``color * (1 - F) / (1 + F)`` (F = 0.04 for IOR 1.5): 0.461 for colour 0.5, since
    it tints each refraction by sqrt(colour) (Cycles 3.x: by the colour, 0.230)."""
    scene = clear_scene()
    add_quad("Glow", [(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)],
             emitter("Glow", (1.0, 1.0, 1.0), 1.0))
    add_box("Slab", (-2, -2, 1.0), (2, 2, 1.2), glass("Glass", ior, color))
    add_camera((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ortho_scale=1.0)
    f = ((ior - 1) / (ior + 1)) ** 2
    return SceneInfo(scene, "glass_slab",
                     {"transmitted": [c * (1 - f) / (1 + f) for c in color]})
