# SPDX-License-Identifier: MIT
"""Motion blur as Cycles samples it: the scene is re-evaluated at subframes over the shutter
(`RenderEngine.frame_set`), and each moving object's and the camera's world matrices at those
times travel in `TESELA_motion` node extensions (docs/extensions.md); the renderer
interpolates them and gives each camera path a time.

Cycles' rules, followed here: the shutter spans `render.motion_blur_shutter` frames, starting,
centred or ending at the frame (Motion Blur > Position); an object blurs when its Object >
Motion Blur is on (and its instancer's, for instances), with `2^steps + 1` keys spread evenly
over the shutter; the camera likewise with its own object settings. The scene is exported at
the shutter's centre (for Position Start or End, a time other than the frame's), and the frame
is restored afterwards."""

import contextlib
import math

import numpy as np

from .. import compat
from .camera import camera_matrix
from .common import gltf_matrix, matrix

# Key times are compared rounded to this many decimals (frame fractions).
_TIME_DIGITS = 6


def object_steps(obj, parent=None):
    """Keys Cycles samples for `obj` (placed by `parent`, if an instance): 0 when its motion
    blur is off, else `2^steps + 1` (an odd count, so one key falls on the centre)."""
    settings = getattr(obj, "cycles", None)
    if settings is None or not getattr(settings, "use_motion_blur", True):
        return 0
    steps = max(1, int(getattr(settings, "motion_steps", 1)))
    if parent is not None and parent != obj:
        psettings = getattr(parent, "cycles", None)
        if psettings is not None:
            if not getattr(psettings, "use_motion_blur", True):
                return 0
            steps = max(steps, int(getattr(psettings, "motion_steps", 1)))
    return (2 << (steps - 1)) + 1


def _deform_candidate(obj):
    """Whether the shape of `obj` may change over time (modifiers, shape keys, an armature
    parent) and Cycles would blur that (Deformation on)."""
    settings = getattr(obj, "cycles", None)
    if settings is not None and not getattr(settings, "use_deform_motion", True):
        return False
    data = getattr(obj, "data", None)
    return (len(getattr(obj, "modifiers", ())) > 0
            or getattr(data, "shape_keys", None) is not None
            or getattr(getattr(obj, "parent", None), "type", None) == "ARMATURE")


def _instance_key(inst):
    """What identifies one depsgraph instance across subframes (Cycles' object key: the
    instancer, the persistent id and the object)."""
    obj = inst.object
    if not inst.is_instance:
        return (obj.name, None, ())
    parent = inst.parent
    return (obj.name, parent.name if parent is not None else None, tuple(inst.persistent_id))


def _mesh_positions(obj):
    """Vertex positions of the evaluated mesh of `obj` (object space), or None."""
    try:
        mesh = obj.to_mesh()
    except RuntimeError:
        return None
    if mesh is None:
        return None
    try:
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        return co
    finally:
        obj.to_mesh_clear()


class Motion:
    """The keys of one export: for each moving instance and the camera, world matrices at
    shutter-normalised times, and what could not be rendered (reported as warnings)."""

    def __init__(self, shutter, centre):
        self.shutter = shutter     # frames
        self.centre = centre       # the shutter's centre, in frames
        self.instances = {}        # instance key -> (steps, {time index: matrix})
        self.camera = None         # (steps, {time index: matrix}) of the camera
        self.deforming = set()     # names of objects whose shape changes over the shutter
        self.warnings = []

    @staticmethod
    def _keys(steps, samples):
        """The (times, matrices) of an object sampled at `samples` (the union of every
        object's times, by index into `steps` evenly spread times), or None if it holds
        still."""
        times, mats = [], []
        for k in range(steps):
            t = round(k / (steps - 1.0), _TIME_DIGITS)
            m = samples.get(t)
            if m is None:
                return None  # not present at every time (appeared or vanished)
            times.append(t)
            mats.append(m)
        if all(np.array_equal(mats[0], m) for m in mats[1:]):
            return None
        return times, mats

    def node_extension(self, inst):
        """The TESELA_motion extension of instance `inst`, or None when it does not move."""
        entry = self.instances.get(_instance_key(inst))
        if entry is None:
            return None
        keys = self._keys(*entry)
        if keys is None:
            return None
        times, mats = keys
        return {"times": times, "matrices": [gltf_matrix(m) for m in mats]}

    def moves(self, inst):
        """Whether instance `inst` moves over the shutter."""
        entry = self.instances.get(_instance_key(inst))
        return entry is not None and self._keys(*entry) is not None

    def camera_extension(self):
        """The TESELA_motion extension of the camera node, or None when it does not move."""
        if self.camera is None:
            return None
        keys = self._keys(*self.camera)
        if keys is None:
            return None
        times, mats = keys
        return {"times": times, "matrices": [gltf_matrix(m) for m in mats]}


def _settings_warnings(scene):
    """Cycles' motion blur settings Tesela does not render."""
    warnings = []
    if not compat.shutter_curve_is_flat(scene.render):
        warnings.append("motion blur: the shutter curve is not rendered; Tesela's shutter is "
                        "open evenly over its interval (Cycles' default flat curve)")
    rolling = compat.rolling_shutter_type(scene)
    if rolling not in (None, "NONE"):
        warnings.append("motion blur: rolling shutter (%s) is not rendered; every row is "
                        "exposed over the same interval" % rolling)
    return warnings


@contextlib.contextmanager
def sampled(engine, depsgraph, camera):
    """Within the block, the scene is evaluated at the shutter's centre and the value is the
    Motion sampled over the shutter (None without motion blur: then nothing changes). The
    scene's frame is restored when the block ends, however it ends."""
    scene = depsgraph.scene
    if not getattr(scene.render, "use_motion_blur", False) or engine is None:
        yield None
        return
    frame, subframe = scene.frame_current, scene.frame_subframe
    shutter = float(scene.render.motion_blur_shutter)
    position = compat.motion_blur_position(scene)
    delta = {"START": 0.5 * shutter, "END": -0.5 * shutter}.get(position, 0.0)
    motion = Motion(shutter, frame + subframe + delta)
    motion.warnings.extend(_settings_warnings(scene))

    def go(time):
        whole = math.floor(time)
        engine.frame_set(int(whole), time - whole)

    try:
        _sample(motion, go, depsgraph, camera, frame + subframe)
        go(motion.centre)
        yield motion
    finally:
        engine.frame_set(frame, subframe)


def _sample(motion, go, depsgraph, camera, frame_time):
    """Fills `motion` with the keys of every moving object and the camera (`frame_time`: the
    frame being rendered, with its subframe)."""
    # Which objects may move, and with how many keys, at the shutter's centre.
    go(motion.centre)
    steps_of = {}
    deform = {}  # object name -> its positions at the centre
    for inst in depsgraph.object_instances:
        obj = inst.object
        parent = inst.parent if inst.is_instance else None
        n = object_steps(getattr(obj, "original", obj),
                         getattr(parent, "original", parent) if parent is not None else None)
        if n:
            steps_of[_instance_key(inst)] = n
            if (not inst.is_instance and obj.type == "MESH"
                    and _deform_candidate(getattr(obj, "original", obj))):
                deform[obj.name] = _mesh_positions(obj)
    cam_steps = object_steps(camera) if camera is not None else 0
    counts = set(steps_of.values()) | ({cam_steps} if cam_steps else set())
    if not counts:
        return
    times = sorted({round(k / (n - 1.0), _TIME_DIGITS) for n in counts for k in range(n)})
    for key, n in steps_of.items():
        motion.instances[key] = (n, {})
    if cam_steps:
        motion.camera = (cam_steps, {})
    for t in times:
        go(motion.centre + (t - 0.5) * motion.shutter)
        for inst in depsgraph.object_instances:
            entry = motion.instances.get(_instance_key(inst))
            if entry is not None:
                entry[1][t] = matrix(inst.matrix_world)
            obj = inst.object
            if (t in (0.0, 1.0) and not inst.is_instance and obj.name in deform
                    and obj.name not in motion.deforming):
                centre = deform[obj.name]
                now = _mesh_positions(obj)
                if (centre is None) != (now is None) or (
                        centre is not None and (centre.shape != now.shape
                                                or not np.allclose(centre, now, atol=1e-6))):
                    motion.deforming.add(obj.name)
        if cam_steps:
            cam = camera.evaluated_get(depsgraph) if hasattr(camera, "evaluated_get") else camera
            motion.camera[1][t] = camera_matrix(cam)
    when = "the frame's instant" if motion.centre == frame_time else "the shutter's centre"
    for name in sorted(motion.deforming):
        motion.warnings.append("object '%s': deformation motion blur is not rendered; it "
                               "renders at %s" % (name, when))
