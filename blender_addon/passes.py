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
    ("use_pass_diffuse_direct", "diffuse_direct", "DiffDir", "RGB", "COLOR"),
    ("use_pass_diffuse_indirect", "diffuse_indirect", "DiffInd", "RGB", "COLOR"),
    ("use_pass_diffuse_color", "diffuse_color", "DiffCol", "RGB", "COLOR"),
    ("use_pass_glossy_direct", "glossy_direct", "GlossDir", "RGB", "COLOR"),
    ("use_pass_glossy_indirect", "glossy_indirect", "GlossInd", "RGB", "COLOR"),
    ("use_pass_glossy_color", "glossy_color", "GlossCol", "RGB", "COLOR"),
    ("use_pass_transmission_direct", "transmission_direct", "TransDir", "RGB", "COLOR"),
    ("use_pass_transmission_indirect", "transmission_indirect", "TransInd", "RGB", "COLOR"),
    ("use_pass_transmission_color", "transmission_color", "TransCol", "RGB", "COLOR"),
)
# Passes whose toggles Cycles keeps in the view layer's Cycles settings (view_layer.cycles).
CYCLES_PASSES = (
    ("use_pass_shadow_catcher", "shadow_catcher", "Shadow Catcher", "RGB", "COLOR"),
)
# The Direct and Indirect light passes: only the integrators that split their light have them.
LIGHT = ("diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect",
         "transmission_direct", "transmission_indirect")
# The debug views have no light to split.
NO_LIGHT_SPLIT = ("normals", "albedo")
# Combined before denoising, registered as Cycles does when the view layer is denoised.
NOISY = ("noisy_image", "Noisy Image", "RGBA", "COLOR")
DENOISING = (
    ("denoising_normal", "Denoising Normal", "XYZ", "VECTOR"),
    ("denoising_albedo", "Denoising Albedo", "RGB", "COLOR"),
)
# Toggles Tesela does not render yet: reported once per render, never silently empty.
UNSUPPORTED = (
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


def splits_light(settings):
    """True when the chosen integrator renders the Direct and Indirect light passes."""
    return getattr(settings, "integrator", "path_mis") not in NO_LIGHT_SPLIT


def denoised(view_layer, settings):
    """Cycles denoises a view layer when the scene asks for it and the layer does not opt out
    (view_layer.cycles.use_denoising)."""
    cycles = getattr(view_layer, "cycles", None)
    return bool(getattr(settings, "use_denoising", False)
                and getattr(cycles, "use_denoising", True))


def enabled(view_layer, settings):
    """[(renderer name, Blender name, channel ids, type)] of the passes to render."""
    light = splits_light(settings)
    out = [(name, bname, ids, kind) for toggle, name, bname, ids, kind in PASSES
           if getattr(view_layer, toggle, False) and (light or name not in LIGHT)]
    cycles = getattr(view_layer, "cycles", None)
    out += [(name, bname, ids, kind) for toggle, name, bname, ids, kind in CYCLES_PASSES
            if getattr(cycles, toggle, False)]
    if denoised(view_layer, settings):
        out.append(NOISY)
    if store_denoising_data(view_layer, settings):
        out += list(DENOISING)
    return out


def unsupported(view_layer, settings=None):
    """Blender names (3.x) of the enabled passes Tesela leaves out: those it never renders,
    and the light passes under an integrator that does not split its light."""
    out = [label for toggle, label in UNSUPPORTED if getattr(view_layer, toggle, False)]
    if settings is not None and not splits_light(settings):
        out += [bname for toggle, name, bname, _, _ in PASSES
                if name in LIGHT and getattr(view_layer, toggle, False)]
    # Shader AOVs (AOV Output nodes) and Cycles' light groups: passes the view layer adds by
    # name.
    out += ["AOV '%s'" % a.name for a in getattr(view_layer, "aovs", ()) if a.name]
    out += ["light group '%s'" % g.name for g in getattr(view_layer, "lightgroups", ())
            if g.name]
    return out
