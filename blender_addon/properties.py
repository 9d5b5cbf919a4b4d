# SPDX-License-Identifier: MIT
"""scene.tesela: render settings, as Cycles keeps scene.cycles (the same property names where
the meaning is the same, so settings and scripts carry over)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

INTEGRATORS = [
    ("path_mis", "Path (MIS)", "Unidirectional path tracing with multiple importance sampling"),
    ("path_mats", "Path (BSDF sampling)", "Path tracing, BSDF sampling only"),
    ("direct_mis", "Direct (MIS)", "Direct lighting with multiple importance sampling"),
    ("direct_ems", "Direct (light sampling)", "Direct lighting, emitter sampling only"),
    ("direct_mats", "Direct (BSDF sampling)", "Direct lighting, BSDF sampling only"),
    ("normals", "Normals", "Debug: shading normals"),
    ("albedo", "Albedo", "Debug: surface albedo"),
]


class TeselaSceneSettings(bpy.types.PropertyGroup):
    integrator: EnumProperty(name="Integrator", items=INTEGRATORS, default="path_mis",
                             description="Light transport algorithm")
    samples: IntProperty(name="Samples", default=1024, min=1, max=1 << 20, soft_max=4096,
                         description="Samples per pixel (the most, with a noise threshold)")
    max_depth: IntProperty(name="Max Depth", default=14, min=1, max=1024,
                           description="Maximum number of path vertices (Cycles' max bounces + 2)")
    seed: IntProperty(name="Seed", default=0, min=0, description="Random seed")
    use_animated_seed: BoolProperty(
        name="Animated Seed", default=False,
        description="Use a different seed for each frame (the seed plus the frame number)")
    threads: IntProperty(name="Threads", default=0, min=0, max=1024,
                         description="Render threads (0: all cores)")
    tile_size: IntProperty(
        name="Tile Size", default=32, min=8, max=4096, subtype="PIXEL",
        description="Edge of the square tiles the image is rendered and shown in (smaller tiles "
                    "appear sooner and balance threads better; larger ones cost less overhead)")
    diffuse_bounces: IntProperty(
        name="Diffuse", default=4, min=0, max=1024,
        description="Maximum number of diffuse reflection bounces, bounded by Max Depth")
    glossy_bounces: IntProperty(
        name="Glossy", default=4, min=0, max=1024,
        description="Maximum number of glossy reflection bounces, bounded by Max Depth")
    transmission_bounces: IntProperty(
        name="Transmission", default=12, min=0, max=1024,
        description="Maximum number of transmission bounces, bounded by Max Depth")
    volume_bounces: IntProperty(
        name="Volume", default=0, min=0, max=1024,
        description="Maximum number of volumetric scattering events (0: light scatters once "
                    "inside a volume)")
    transparent_max_bounces: IntProperty(
        name="Transparent", default=8, min=0, max=1024,
        description="Maximum number of transparent surfaces passed straight through")
    sample_clamp_direct: FloatProperty(
        name="Direct Light", default=0.0, min=0.0,
        description="If non-zero, the maximum value for a direct light sample")
    sample_clamp_indirect: FloatProperty(
        name="Indirect Light", default=10.0, min=0.0,
        description="If non-zero, the maximum value for an indirect light sample")
    blur_glossy: FloatProperty(
        name="Filter Glossy", default=1.0, min=0.0, max=10.0,
        description="Adaptively blur glossy shaders after blurry bounces, to reduce noise at "
                    "the cost of accuracy")
    caustics_reflective: BoolProperty(
        name="Reflective Caustics", default=True,
        description="Use reflective caustics, resulting in a brighter image (more noise but "
                    "added realism)")
    caustics_refractive: BoolProperty(
        name="Refractive Caustics", default=True,
        description="Use refractive caustics, resulting in a brighter image (more noise but "
                    "added realism)")
    use_adaptive_sampling: BoolProperty(
        name="Noise Threshold", default=True,
        description="Automatically stop sampling pixels whose noise falls below the threshold "
                    "(Cycles' adaptive sampling)")
    adaptive_threshold: FloatProperty(
        name="Noise Threshold", default=0.01, min=0.0, max=1.0, soft_min=0.001, precision=4,
        description="Noise level at which a pixel stops (0: automatic from the sample count)")
    adaptive_min_samples: IntProperty(
        name="Min Samples", default=0, min=0, max=4096,
        description="Samples every pixel takes before it may stop (0: automatic)")
    preview_samples: IntProperty(
        name="Viewport Samples", default=1024, min=0, max=1 << 24, soft_min=1,
        description="Number of samples to render in the viewport, unlimited if 0")
    preview_start_resolution: IntProperty(
        name="Start Pixels", default=64, min=0, max=16384, subtype="PIXEL",
        description="Resolution to start rendering the viewport at (its pixel count is about "
                    "this squared), refined up to the full resolution; 0 starts at the pixel size")
    use_preview_denoising: BoolProperty(
        name="Viewport Denoise", default=False,
        description="Denoise the image in the 3D viewport with Intel Open Image Denoise (when "
                    "the renderer finds the library)")
    time_limit: FloatProperty(
        name="Time Limit", default=0.0, min=0.0, subtype="TIME_ABSOLUTE",
        description="Stop rendering after this many seconds (0: no limit)")
    use_denoising: BoolProperty(
        name="Denoise", default=True,
        description="Denoise the final image with Intel Open Image Denoise (when the renderer "
                    "finds the library)")
    denoising_prefilter: EnumProperty(
        name="Prefilter", default="ACCURATE",
        items=[("NONE", "None", "No prefiltering of the albedo and normal passes"),
               ("FAST", "Fast", "Use the albedo and normal passes as rendered"),
               ("ACCURATE", "Accurate", "Denoise the albedo and normal passes first")],
        description="How the denoiser's albedo and normal passes are treated")
    pixel_filter_type: EnumProperty(
        name="Pixel Filter", default="BLACKMAN_HARRIS",
        items=[("BOX", "Box", "Box filter"),
               ("GAUSSIAN", "Gaussian", "Gaussian filter"),
               ("BLACKMAN_HARRIS", "Blackman-Harris", "Blackman-Harris filter")],
        description="Pixel filter type (as Cycles' Film > Pixel Filter)")
    filter_width: FloatProperty(
        name="Width", default=1.5, min=0.01, max=10.0, subtype="PIXEL",
        description="Pixel filter width")
    denoising_store_passes: BoolProperty(
        name="Denoising Data", default=False,
        description="Store the Denoising Normal and Denoising Albedo passes in the render result")


def register():
    bpy.utils.register_class(TeselaSceneSettings)
    bpy.types.Scene.tesela = PointerProperty(type=TeselaSceneSettings)


def unregister():
    if hasattr(bpy.types.Scene, "tesela"):
        del bpy.types.Scene.tesela
    bpy.utils.unregister_class(TeselaSceneSettings)
