# SPDX-License-Identifier: MIT
"""The render settings a Tesela render uses: scene.tesela's where they were set, else the
scene's Cycles settings of the same meaning (an artist's scene carries its Light Paths,
Sampling and Film choices there), else Tesela's defaults, which are Cycles' defaults."""

# scene.tesela settings that follow scene.cycles' property of the same name until set. Not
# tile_size: Cycles' tiles bound memory, Tesela's are what the image appears in.
FOLLOWS_CYCLES = (
    "samples", "seed", "use_animated_seed", "diffuse_bounces", "glossy_bounces",
    "transmission_bounces", "volume_bounces", "transparent_max_bounces",
    "sample_clamp_direct", "sample_clamp_indirect", "blur_glossy", "caustics_reflective",
    "caustics_refractive", "use_adaptive_sampling", "adaptive_threshold",
    "adaptive_min_samples", "preview_samples", "use_preview_denoising", "time_limit",
    "use_denoising", "denoising_prefilter", "pixel_filter_type", "filter_width",
)
# Tesela's path length counts vertices: Cycles' Max Bounces plus the camera and the last one.
MAX_DEPTH_FROM_BOUNCES = 2


def source(tesela, cycles, name):
    """(owner, property) holding the value setting `name` takes: scene.tesela's when it was
    set or Cycles has no counterpart, else the Cycles property it follows (max_depth follows
    Max Bounces)."""
    if cycles is None or tesela.is_property_set(name):
        return tesela, name
    if name == "max_depth":
        return (cycles, "max_bounces") if hasattr(cycles, "max_bounces") else (tesela, name)
    if name in FOLLOWS_CYCLES and hasattr(cycles, name):
        prop = tesela.bl_rna.properties[name]
        if prop.type == "ENUM" and getattr(cycles, name) not in prop.enum_items.keys():
            return tesela, name
        return cycles, name
    return tesela, name


class SceneSettings:
    """Attribute access to the settings a render of `scene` uses (see the module's text)."""

    def __init__(self, scene):
        self._tesela = scene.tesela
        self._cycles = getattr(scene, "cycles", None)

    def __getattr__(self, name):
        owner, prop = source(self._tesela, self._cycles, name)
        value = getattr(owner, prop)
        if owner is not self._tesela and name == "max_depth":
            value = int(value) + MAX_DEPTH_FROM_BOUNCES
        return value

    def follows_cycles(self, name):
        """Whether setting `name` takes its value from the scene's Cycles settings."""
        return source(self._tesela, self._cycles, name)[0] is not self._tesela
