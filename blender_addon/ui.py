# SPDX-License-Identifier: MIT
"""Render panel, the Material tab's fallback list, reuse of Blender's own panels, and the
File > Export entry."""

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from . import export, preferences, report
from .settings import FOLLOWS_CYCLES, SceneSettings, source

ENGINE = "TESELA"

# Engine-specific panels worth sharing (they draw node-based surfaces, lights, worlds).
_EXTRA_PANELS = (
    "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface",
    "EEVEE_WORLD_PT_surface", "DATA_PT_EEVEE_light", "NODE_DATA_PT_EEVEE_light",
    "DATA_PT_spot", "DATA_PT_area",
)
# Generic ("BLENDER_RENDER") panels that would duplicate or mislead.
_SKIP_PANELS = ("DATA_PT_light", "NODE_DATA_PT_light")


def _compat_panels():
    for name in dir(bpy.types):
        cls = getattr(bpy.types, name, None)
        engines = getattr(cls, "COMPAT_ENGINES", None)
        if not isinstance(engines, set):
            continue
        if "lightprobe" in name.lower() or name in _SKIP_PANELS:
            continue
        if "BLENDER_RENDER" in engines or name in _EXTRA_PANELS:
            yield cls


class TESELA_PT_render(bpy.types.Panel):
    bl_label = "Tesela"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        scene = context.scene
        s = SceneSettings(scene)

        def prop(col, name, **kw):
            # A setting not set for Tesela shows (and edits) the Cycles setting it follows.
            owner, attr = source(scene.tesela, getattr(scene, "cycles", None), name)
            if attr == "max_bounces":
                kw.setdefault("text", "Max Bounces")
            col.prop(owner, attr, **kw)

        # Laid out as Cycles' render properties, with Cycles' property names.
        col = layout.column(heading="Sampling")
        row = col.row(heading="Noise Threshold", align=True)
        prop(row, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = s.use_adaptive_sampling
        prop(sub, "adaptive_threshold", text="")
        prop(col, "samples", text="Max Samples" if s.use_adaptive_sampling else "Samples")
        sub = col.column()
        sub.active = s.use_adaptive_sampling
        prop(sub, "adaptive_min_samples")
        prop(col, "time_limit")
        col = layout.column(heading="Viewport")
        prop(col, "preview_samples", text="Samples")
        prop(col, "preview_start_resolution")
        col.prop(scene.render, "preview_pixel_size", text="Pixel Size")
        prop(col, "use_preview_denoising")
        row = col.row(align=True)
        prop(row, "seed")
        prop(row, "use_animated_seed", text="", icon="TIME")
        col = layout.column(heading="Denoise")
        prop(col, "use_denoising")
        sub = col.column()
        sub.active = s.use_denoising
        prop(sub, "denoising_prefilter")
        prop(layout, "denoising_store_passes")
        col = layout.column(heading="Light Paths")
        prop(col, "max_depth")
        for name in ("diffuse_bounces", "glossy_bounces", "transmission_bounces",
                     "volume_bounces", "transparent_max_bounces"):
            prop(col, name)
        col = layout.column(heading="Clamping")
        prop(col, "sample_clamp_direct")
        prop(col, "sample_clamp_indirect")
        col = layout.column()
        prop(col, "blur_glossy")
        col = layout.column(heading="Caustics")
        prop(col, "caustics_reflective", text="Reflective")
        prop(col, "caustics_refractive", text="Refractive")
        col = layout.column(heading="Film")
        col.prop(scene.render, "film_transparent", text="Transparent")
        cyc = getattr(scene, "cycles", None)
        if cyc is not None and hasattr(cyc, "film_transparent_glass"):
            # Cycles' own settings (scene.cycles), which Tesela follows.
            sub = col.column()
            sub.active = scene.render.film_transparent
            sub.prop(cyc, "film_transparent_glass", text="Transparent Glass")
            sub = sub.column()
            sub.active = scene.render.film_transparent and cyc.film_transparent_glass
            sub.prop(cyc, "film_transparent_roughness", text="Roughness Threshold")
        prop(col, "pixel_filter_type")
        prop(col, "filter_width")
        col = layout.column(heading="Performance")
        prop(col, "threads")
        prop(col, "tile_size")
        col = layout.column(heading="Debug")
        prop(col, "integrator")
        if any(s.follows_cycles(n) for n in FOLLOWS_CYCLES + ("max_depth",)):
            layout.label(text="Settings not changed for Tesela are the scene's Cycles settings",
                         icon="INFO")
        path, tried = preferences.find_renderer(context)
        if path is None:
            box = layout.box()
            box.label(text="Renderer binary not found", icon="ERROR")
            box.label(text="Set it in Preferences > Add-ons > Tesela")


class TESELA_PT_material_fallbacks(bpy.types.Panel):
    """What Tesela could not translate or render for the active material in the last render."""
    bl_label = "Tesela"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"
    bl_options = {"DEFAULT_CLOSED"}
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES and getattr(context, "material", None) is not None

    def draw(self, context):
        layout = self.layout
        mat = context.material
        last = report.get(context.scene.name)
        if last is None:
            layout.label(text="Not rendered with Tesela since the file was opened", icon="INFO")
            return
        addon, renderer = last.for_material(mat.name)
        if not addon and not renderer:
            layout.label(text="Nothing fell back in the last render", icon="CHECKMARK")
            return
        prefix = "material '%s': " % mat.name
        for title, lines in (("Add-on", addon), ("Renderer", renderer)):
            if not lines:
                continue
            box = layout.box()
            box.label(text=title, icon="ERROR")
            col = box.column(align=True)
            for line in lines:
                col.label(text=line[len(prefix):] if line.startswith(prefix) else line)


class TESELA_OT_export_gltf(bpy.types.Operator, ExportHelper):
    """Export the evaluated scene as Tesela glTF (.gltf + .bin) for the command line renderer"""
    bl_idname = "export_scene.tesela_gltf"
    bl_label = "Export Tesela glTF"
    bl_options = {"PRESET"}

    filename_ext = ".gltf"
    filter_glob: StringProperty(default="*.gltf", options={"HIDDEN"})
    use_selection: BoolProperty(name="Selected Objects Only", default=False)

    def execute(self, context):
        depsgraph = context.evaluated_depsgraph_get()
        scene = depsgraph.scene
        width, height = export.render_size(scene.render)
        s = scene.tesela
        settings = {"width": width, "height": height, "spp": s.samples, "max_depth": s.max_depth,
                    "seed": s.seed, "integrator": s.integrator}
        selection = None
        if self.use_selection:
            selection = {o.name for o in context.selected_objects}
            if scene.camera is not None:
                selection.add(scene.camera.name)
        camera = scene.camera.evaluated_get(depsgraph) if scene.camera is not None else None
        res = export.write_gltf(depsgraph, self.filepath, width=width, height=height,
                                camera=camera, render_settings=settings, selection=selection)
        fallbacks = report.FallbackReport()
        fallbacks.add_addon_all(res.material_warnings)
        report.publish(scene.name, fallbacks)
        for w in res.warnings[:20]:
            self.report({"WARNING"}, w)
        self.report({"INFO"}, "Tesela: wrote %s (%d triangles)" % (self.filepath, res.triangles))
        return {"FINISHED"}


def _menu_export(self, context):
    self.layout.operator(TESELA_OT_export_gltf.bl_idname, text="Tesela glTF (.gltf)")


_added = []  # panels we added the engine to (registration state, not render state)


@bpy.app.handlers.persistent
def _on_load(*_args):
    report.clear()  # another file: the last render's fallbacks belong to the old one


def register():
    bpy.utils.register_class(TESELA_PT_render)
    bpy.utils.register_class(TESELA_PT_material_fallbacks)
    bpy.utils.register_class(TESELA_OT_export_gltf)
    if _on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_on_load)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)
    for cls in _compat_panels():
        if ENGINE not in cls.COMPAT_ENGINES:
            cls.COMPAT_ENGINES.add(ENGINE)
            _added.append(cls)


def unregister():
    while _added:
        cls = _added.pop()
        cls.COMPAT_ENGINES.discard(ENGINE)
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    if _on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_on_load)
    bpy.utils.unregister_class(TESELA_OT_export_gltf)
    bpy.utils.unregister_class(TESELA_PT_material_fallbacks)
    bpy.utils.unregister_class(TESELA_PT_render)
