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
        """Draw the image where it lies in the view (region pixels, bottom-left origin)."""
        rect = self.placement(self.image)
        if self.texture is None or rect is None:
            return
        import gpu
        (x0, top, w, h), uv = rect
        gpu.state.blend_set("ALPHA_PREMULT")
        compat.draw_scene_linear_texture(engine, scene, self.texture,
                                         (x0, region_height - top - h, w, h), uv)
        gpu.state.blend_set("NONE")

    @staticmethod
    def placement(image):
        """((x, y, w, h) in view pixels, top-left origin; (u0, v0, u1, v1) texture coordinates
        of the flipped texture) of the part of the window the image's data covers, or None."""
        if image is None:
            return None
        ps = image.pixel_size
        dh, dw = image.pixels.shape[:2]
        # The data's cells start at the cell holding the window's corner; the data may end
        # before the window does (cut at the view's edge) or after it (the last cell).
        ox, oy = (image.x // ps) * ps, (image.y // ps) * ps
        x1 = min(image.x + image.width, ox + dw * ps)
        y1 = min(image.y + image.height, oy + dh * ps)
        if x1 <= image.x or y1 <= image.y:
            return None
        u0, u1 = (image.x - ox) / (dw * ps), (x1 - ox) / (dw * ps)
        v1, v0 = 1.0 - (image.y - oy) / (dh * ps), 1.0 - (y1 - oy) / (dh * ps)
        return (image.x, image.y, x1 - image.x, y1 - image.y), (u0, v0, u1, v1)


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
