# SPDX-License-Identifier: MIT
"""What fell back in the last render, per material, for the Tesela panel of the Material tab.

Each render (or File > Export) builds a fresh FallbackReport from the exporter's per-material
list and the renderer's log lines of the form ``material 'NAME': node 'NODE' (TYPE) ...``, then
publishes it for its scene, replacing that scene's previous report whole: nothing carries over
from one render to the next. Blender-free (the panel and the engine import it; tests drive it
without bpy). Loading another .blend file clears everything (see clear()).
"""

import re
import threading

# `material 'NAME': node 'NODE' (TYPE) message` (the material name ends at the first
# "': node '", the node name at the first "' (TYPE)" after it).
_RENDERER_LINE = re.compile(
    r"material '(?P<material>.*?)': (?:shader )?node '(?P<node>.*?)' \((?P<type>[A-Za-z0-9_]+)\)"
    r"(?P<rest>.*)$")

_lock = threading.Lock()
_published = {}  # scene name -> FallbackReport


class FallbackReport:
    """Messages per material name, each once, from the add-on and from the renderer."""

    def __init__(self):
        self.addon = {}
        self.renderer = {}
        self._seen = set()

    def add_addon(self, material, message):
        if (material, message) not in self._seen:
            self._seen.add((material, message))
            self.addon.setdefault(material, []).append(message)

    def add_addon_all(self, per_material):
        for material, messages in per_material.items():
            for message in messages:
                self.add_addon(material, message)

    def add_renderer_line(self, line):
        """File a renderer log line under its material; False if it names no material node."""
        line = line.strip()
        m = _RENDERER_LINE.search(line)
        if m is None:
            return False
        material = m.group("material")
        text = line[m.start():]
        if (material, text) not in self._seen:
            self._seen.add((material, text))
            self.renderer.setdefault(material, []).append(text)
        return True

    def add_renderer_text(self, text):
        for line in text.splitlines():
            self.add_renderer_line(line)

    def for_material(self, material):
        """(add-on messages, renderer messages) for one material name."""
        return list(self.addon.get(material, ())), list(self.renderer.get(material, ()))


def publish(scene_name, report):
    with _lock:
        _published[scene_name] = report


def get(scene_name):
    """The last published report of a scene, or None (not rendered since the file was loaded)."""
    with _lock:
        return _published.get(scene_name)


def clear():
    with _lock:
        _published.clear()
