# SPDX-License-Identifier: MIT
"""Add-on preferences and discovery of the renderer binary."""

import os
import shutil

import bpy
from bpy.props import StringProperty

ADDON_ID = __package__
BINARY_NAME = "tesela.exe" if os.name == "nt" else "tesela"
_HERE = os.path.dirname(os.path.abspath(__file__))


class TeselaPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_ID

    binary_path: StringProperty(
        name="Renderer binary", subtype="FILE_PATH", default="",
        description="Path to the tesela executable (empty: discover it automatically)")

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "binary_path")
        path, tried = find_renderer(context)
        if path:
            layout.label(text="Using: " + path, icon="CHECKMARK")
        else:
            layout.label(text=not_found_message(tried), icon="ERROR")


def _prefs(context=None):
    try:
        prefs = (context or bpy.context).preferences
        addon = prefs.addons.get(ADDON_ID)
        return addon.preferences if addon is not None else None
    except (AttributeError, KeyError, TypeError, RuntimeError):
        return None


def _is_exe(path):
    return bool(path) and os.path.isfile(path) and os.access(path, os.X_OK)


def candidates(context=None):
    """Ordered (label, path) candidates."""
    out = []
    for var in ("TESELA_BINARY", "TESELA_BIN"):
        env = os.environ.get(var)
        if env:
            out.append((var, env))
            break
    p = _prefs(context)
    if p is not None and p.binary_path:
        out.append(("preferences", bpy.path.abspath(p.binary_path)))
    out.append(("bundled", os.path.join(_HERE, "bin", BINARY_NAME)))
    out.append(("bundled", os.path.join(_HERE, BINARY_NAME)))
    on_path = shutil.which(BINARY_NAME)
    if on_path:
        out.append(("PATH", on_path))
    # The project checkout: blender_addon/ sits beside target/.
    repo = os.path.dirname(_HERE)
    out.append(("repository", os.path.join(repo, "target", "release", BINARY_NAME)))
    return out


def find_renderer(context=None):
    """(path or None, list of paths tried). An explicit setting (TESELA_BINARY or the
    preference) that is not executable is not silently skipped: it is returned as
    not found, so the user learns that the path they chose is wrong."""
    tried = []
    for label, path in candidates(context):
        tried.append(path)
        if label == "bundled" and os.path.isfile(path) and not os.access(path, os.X_OK):
            # Blender's extension installer unpacks zips without the executable bit.
            try:
                os.chmod(path, os.stat(path).st_mode | 0o755)
            except OSError:
                pass
        if _is_exe(path):
            return os.path.abspath(path), tried  # the renderer runs in the temp dir
        if label in ("TESELA_BINARY", "TESELA_BIN", "preferences"):
            return None, tried
    return None, tried


def not_found_message(tried):
    return ("Tesela renderer not found or not executable (tried: %s). Set its path in "
            "Preferences > Add-ons > Tesela, put 'tesela' on PATH, or build it with "
            "'cargo build --release'." % ", ".join(tried))


def register():
    bpy.utils.register_class(TeselaPreferences)


def unregister():
    bpy.utils.unregister_class(TeselaPreferences)
