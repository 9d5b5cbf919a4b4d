# SPDX-License-Identifier: MIT
"""Drawing the session's newest image into the 3D viewport with the gpu module (no bgl), and
messages with blf. Runs in view_draw (Blender's draw thread, a GPU context bound)."""

import numpy as np

from .. import compat


class Display:
    """One GPU texture holding the newest image, rebuilt only when a new image arrived."""

    def __init__(self):
        self.texture = None
        self.serial = None
        self.image = None

    def free(self):
        self.texture = None
        self.image = None
        self.serial = None

    def update(self, image, serial):
        """Upload `image` (session_protocol.Image) unless `serial` is already on the GPU."""
        if serial == self.serial:
            return
        import gpu
        # Blender's textures run bottom to top; the session's rows top to bottom.
        rgba = np.ascontiguousarray(image.pixels[::-1], dtype=np.float32)
        dh, dw = rgba.shape[:2]
        buf = gpu.types.Buffer("FLOAT", dw * dh * 4, rgba.reshape(-1))
        self.texture = gpu.types.GPUTexture((dw, dh), format="RGBA32F", data=buf)
        self.image = image
        self.serial = serial

    def draw(self, engine, scene, region_height):
        """Draw the image into its window of the view (region pixels, bottom-left origin)."""
        image = self.image
        if self.texture is None or image is None:
            return
        import gpu
        ps = image.pixel_size
        dh, dw = image.pixels.shape[:2]
        # The data covers dw*ps x dh*ps view pixels from the window's top-left corner; the last
        # column and row are cut by the window's edge, so the texture coordinates stop there.
        u1 = image.width / float(dw * ps)
        v0 = 1.0 - image.height / float(dh * ps)
        x0 = image.x
        y0 = region_height - image.y - image.height
        gpu.state.blend_set("ALPHA_PREMULT")
        compat.draw_scene_linear_texture(engine, scene, self.texture,
                                         (x0, y0, image.width, image.height), (0.0, v0, u1, 1.0))
        gpu.state.blend_set("NONE")


def draw_messages(lines, region_width, region_height):
    """Lines of text at the top left of the region, below Blender's own overlay text."""
    import blf
    font = 0
    size = 13
    compat.blf_size(font, size)
    y = region_height - 4 * size
    for line in lines:
        for part in _wrap(line, max(20, int(region_width / (0.55 * size)) - 4)):
            blf.color(font, 0.0, 0.0, 0.0, 1.0)
            blf.position(font, 13, y - 1, 0)
            blf.draw(font, part)
            blf.color(font, 1.0, 0.35, 0.3, 1.0)
            blf.position(font, 12, y, 0)
            blf.draw(font, part)
            y -= int(size * 1.5)


def _wrap(text, width):
    words = text.split()
    out, line = [], ""
    for w in words:
        if line and len(line) + 1 + len(w) > width:
            out.append(line)
            line = w
        else:
            line = (line + " " + w) if line else w
    if line:
        out.append(line)
    return out or [""]
