# SPDX-License-Identifier: MIT
"""Render passes: which of Blender's View Layer > Passes toggles Tesela renders, under the
names, channels and types Cycles registers them with. No bpy import: tests use it directly."""

# (view layer toggle, renderer pass name, Blender 3.x pass name (compat.pass_name gives this
# Blender's), channel ids, pass type)
PASSES = (
    ("use_pass_z", "depth", "Depth", "Z", "VALUE"),
    ("use_pass_mist", "mist", "Mist", "Z", "VALUE"),
    ("use_pass_normal", "normal", "Normal", "XYZ", "VECTOR"),
    ("use_pass_position", "position", "Position", "XYZ", "VECTOR"),
    ("use_pass_uv", "uv", "UV", "UVA", "VECTOR"),
    ("use_pass_object_index", "object_index", "IndexOB", "X", "VALUE"),
    ("use_pass_material_index", "material_index", "IndexMA", "X", "VALUE"),
    ("use_pass_emit", "emission", "Emit", "RGB", "COLOR"),
    ("use_pass_environment", "environment", "Env", "RGB", "COLOR"),
)
DENOISING = (
    ("denoising_normal", "Denoising Normal", "XYZ", "VECTOR"),
    ("denoising_albedo", "Denoising Albedo", "RGB", "COLOR"),
)
# Toggles Tesela does not render yet: reported once per render, never silently empty.
UNSUPPORTED = (
    ("use_pass_diffuse_direct", "Diffuse Direct"),
    ("use_pass_diffuse_indirect", "Diffuse Indirect"),
    ("use_pass_diffuse_color", "Diffuse Color"),
    ("use_pass_glossy_direct", "Glossy Direct"),
    ("use_pass_glossy_indirect", "Glossy Indirect"),
    ("use_pass_glossy_color", "Glossy Color"),
    ("use_pass_transmission_direct", "Transmission Direct"),
    ("use_pass_transmission_indirect", "Transmission Indirect"),
    ("use_pass_transmission_color", "Transmission Color"),
    ("use_pass_ambient_occlusion", "Ambient Occlusion"),
    ("use_pass_shadow", "Shadow"),
    ("use_pass_vector", "Vector"),
    ("use_pass_cryptomatte_object", "Cryptomatte Object"),
    ("use_pass_cryptomatte_material", "Cryptomatte Material"),
    ("use_pass_cryptomatte_asset", "Cryptomatte Asset"),
)


def store_denoising_data(view_layer, settings):
    """Cycles keeps "Denoising Data" per view layer (view_layer.cycles); Tesela's own scene
    setting asks for it too."""
    cycles = getattr(view_layer, "cycles", None)
    return bool(getattr(cycles, "denoising_store_passes", False)
                or getattr(settings, "denoising_store_passes", False))


def enabled(view_layer, settings):
    """[(renderer name, Blender name, channel ids, type)] of the passes to render."""
    out = [(name, bname, ids, kind) for toggle, name, bname, ids, kind in PASSES
           if getattr(view_layer, toggle, False)]
    if store_denoising_data(view_layer, settings):
        out += list(DENOISING)
    return out


def unsupported(view_layer):
    """Blender names of the enabled passes Tesela leaves out."""
    return [label for toggle, label in UNSUPPORTED if getattr(view_layer, toggle, False)]
