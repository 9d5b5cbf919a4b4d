# SPDX-License-Identifier: MIT
"""Images: the TESELA_images table (raw pixels in the .bin, one entry per Blender image, shared by
every node and material that uses it) and the PNG files of the glTF fallback textures."""

import os

import numpy as np


def write_png(path, pixels):
    """Write float RGBA (h, w, 4), rows top to bottom, values already encoded, as a 16-bit PNG."""
    import struct
    import zlib
    h, w = pixels.shape[:2]
    data = np.clip(np.nan_to_num(pixels, nan=0.0), 0.0, 1.0)
    data = (data * 65535.0 + 0.5).astype(">u2").view(np.uint8).reshape(h, w * 8)
    raw = np.zeros((h, w * 8 + 1), dtype=np.uint8)  # filter byte 0 per row
    raw[:, 1:] = data

    def chunk(tag, body):
        return (struct.pack(">I", len(body)) + tag + body
                + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 16, 6, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw.tobytes(), 6)))
        f.write(chunk(b"IEND", b""))


def _linear_to_srgb(c):
    c = np.maximum(c, 0.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def _read_from_file(image):
    """Whether Cycles reads `image` from its file (OIIO, the file's own encoding) rather than
    taking Blender's pixels: a file image that is not packed (generated, packed and movie
    images come from Blender, float ones already linear)."""
    return (getattr(image, "source", "FILE") in ("FILE", "SEQUENCE", "TILED")
            and not getattr(image, "packed_file", None))


def _tile_path(pattern, number):
    """A UDIM tile's file from the image's path pattern (``<UDIM>``: 1001..., ``<UVTILE>``:
    u1_v1...)."""
    u, v = (number - 1001) % 10 + 1, (number - 1001) // 10 + 1
    return pattern.replace("<UDIM>", str(number)).replace("<UVTILE>", "u%d_v%d" % (u, v))


def _tile_files(image):
    """(tile number, file bytes or None, path, packed) of each tile of a UDIM image: packed
    data when the image is packed, else the file on disk."""
    import bpy
    pattern = bpy.path.abspath(image.filepath_raw or image.filepath, library=image.library)
    packed = {}
    for pf in getattr(image, "packed_files", None) or ():
        if getattr(pf, "packed_file", None) is not None:
            packed[int(getattr(pf, "tile_number", 1001))] = pf.packed_file
    out = []
    for tile in image.tiles:
        number = int(tile.number)
        path = os.path.normpath(_tile_path(pattern, number))
        data = None
        if number in packed:
            data = bytes(packed[number].data)
            out.append((number, data, path, True))
            continue
        elif os.path.isfile(path):
            try:
                with open(path, "rb") as f:
                    data = f.read()
            except OSError:
                data = None
        out.append((number, data, path, False))
    return out


def _tile_is_float(data):
    """Whether the renderer decodes the file to floats: more than 8 bits per PNG sample
    (the IHDR's bit depth), OpenEXR, Radiance HDR."""
    fmt = _tile_format(data)
    if fmt == "png":
        return len(data) > 24 and data[24] > 8
    return fmt in ("exr", "hdr")


def _tile_format(data):
    """The file format the renderer decodes, from the file's signature, or None."""
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "png"
    if data.startswith(b"\xff\xd8\xff"):
        return "jpeg"
    if data.startswith(b"\x76\x2f\x31\x01"):
        return "exr"
    if data.startswith((b"#?RADIANCE", b"#?RGBE")):
        return "hdr"
    return None


class Textures:
    """Images, samplers and textures of one export; images are PNG files beside the .gltf."""

    def __init__(self, folder, stem, warnings):
        self.folder, self.stem, self.warnings = folder, stem, warnings
        self.images, self.samplers, self.textures = [], [], []
        self._image_index, self._sampler_index, self._texture_index = {}, {}, {}

    def image_texture(self, sock, material_name, warnings=None):
        """glTF texture index for an Image Texture node feeding `sock` directly, else None."""
        if warnings is None:
            warnings = self.warnings
        if sock is None or not sock.is_linked:
            return None
        link = sock.links[0]
        node = link.from_node
        while node.bl_idname == "NodeReroute" and node.inputs[0].is_linked:
            link = node.inputs[0].links[0]
            node = link.from_node
        if node.bl_idname != "ShaderNodeTexImage" or node.image is None:
            return None
        if link.from_socket.name != "Color":
            return None
        vec = node.inputs.get("Vector")
        if vec is not None and vec.is_linked:
            warnings.append("material '%s': texture coordinates of '%s' are linked; the active "
                                 "UV map is used" % (material_name, node.name))
        img = self._image(node.image, warnings)
        if img is None:
            return None
        closest = getattr(node, "interpolation", "Linear") == "Closest"
        filt = 9728 if closest else 9729  # NEAREST or LINEAR; no mipmaps, as Cycles
        wrap = {"REPEAT": 10497, "EXTEND": 33071, "CLIP": 33071, "MIRROR": 33648}.get(
            getattr(node, "extension", "REPEAT"), 10497)
        if getattr(node, "extension", "") == "CLIP":
            warnings.append("material '%s': texture clipping renders as 'Extend'" % material_name)
        skey = (filt, wrap)
        if skey not in self._sampler_index:
            self.samplers.append({"magFilter": filt, "minFilter": filt, "wrapS": wrap, "wrapT": wrap})
            self._sampler_index[skey] = len(self.samplers) - 1
        tkey = (img, self._sampler_index[skey])
        if tkey not in self._texture_index:
            self.textures.append({"source": img, "sampler": self._sampler_index[skey]})
            self._texture_index[tkey] = len(self.textures) - 1
        return self._texture_index[tkey]

    def _image(self, image, warnings):
        key = image.name
        if key in self._image_index:
            return self._image_index[key]
        self._image_index[key] = None
        w, h = image.size[0], image.size[1]
        if w == 0 or h == 0:
            warnings.append("image '%s' has no pixels (missing file?); texture ignored" % image.name)
            return None
        channels = image.channels
        buf = np.empty(w * h * channels, dtype=np.float32)
        image.pixels.foreach_get(buf)
        buf = buf.reshape(h, w, channels)[::-1]  # Blender's rows run bottom to top
        rgba = np.ones((h, w, 4), dtype=np.float32)
        rgba[..., :min(channels, 4)] = buf[..., :4]
        if channels < 3:
            rgba[..., 1] = rgba[..., 2] = rgba[..., 0]
        cs = image.colorspace_settings.name
        if image.is_float or cs not in ("sRGB",):
            # Linear values (float buffers, non-sRGB colour spaces): glTF wants sRGB.
            rgba[..., :3] = _linear_to_srgb(rgba[..., :3])
        name = "%s_%d.png" % (self.stem, len(self.images))
        write_png(os.path.join(self.folder, name), rgba)
        from urllib.parse import quote
        self.images.append({"uri": quote(name), "name": image.name, "mimeType": "image/png"})
        self._image_index[key] = len(self.images) - 1
        return self._image_index[key]


class ImageTable:
    """TESELA_images: raw pixel rows (top to bottom) of each Blender image in the .bin.

    Byte images travel as u8 (Blender's float view of the bytes x 255, rounded: exact, still in
    the image's colour space, straight alpha); float images as f32, or f16 when every value
    survives the round trip (a half-float source), in scene linear and premultiplied as Blender
    holds them (Cycles uses them as they are), except sRGB files Cycles reads itself: their
    pixels are encoded to sRGB again and tagged "sRGB", so the renderer filters encoded values
    and decodes after, as Cycles does.
    """

    def __init__(self, buffer, report):
        self.buffer = buffer
        self.report = report        # report(material, node, message): once per material and node
        self.images = []
        self._index = {}

    def add(self, image, node, material_name):
        """Index into TESELA_images.images for `image` used by `node`, or None without pixels."""
        source = getattr(image, "source", "FILE")
        frame = None
        if source in ("SEQUENCE", "MOVIE"):
            user = getattr(node, "image_user", None)
            frame = getattr(user, "frame_current", None)
            self.report(material_name, node, "image '%s' is a %s: the frame Blender has loaded is "
                        "used, which may not be the current frame" % (image.name, source.lower()))
        elif source == "TILED":
            self.report(material_name, node, "image '%s' has no UDIM tile file Tesela can read: "
                        "only Blender's first tile is rendered" % image.name)
        key = (getattr(image, "name_full", image.name), frame)
        if key in self._index:
            idx = self._index[key]
            if idx is None:
                self._missing(image, node, material_name)
            return idx
        self._index[key] = None
        w, h = int(image.size[0]), int(image.size[1])
        channels = int(image.channels)
        n = w * h * channels
        if w == 0 or h == 0 or n == 0 or len(image.pixels) != n:
            self._missing(image, node, material_name)
            return None
        buf = np.empty(n, dtype=np.float32)
        image.pixels.foreach_get(buf)
        rows = buf.reshape(h, w, channels)[::-1]  # Blender's rows run bottom to top
        is_float = bool(image.is_float)
        cs = image.colorspace_settings.name
        colorspace = "Non-Color" if is_float else cs
        if is_float and cs == "sRGB" and _read_from_file(image):
            # Cycles reads such an image from its file and keeps it sRGB-encoded, decoding after
            # interpolation (its compress_as_srgb); Blender's float pixels are linear, so encode
            # them again for the renderer to filter the same values.
            # Alpha stays associated as Cycles' loader leaves it: encoded straight colour times
            # alpha (Blender's pixels are premultiplied linear).
            rows = rows.copy()
            colour = slice(0, 3) if channels >= 3 else slice(0, 1)
            alpha = rows[..., 3:4] if channels == 4 else np.ones_like(rows[..., :1])
            straight = np.divide(rows[..., colour], alpha, out=np.zeros_like(rows[..., colour]),
                                 where=alpha > 0)
            rows[..., colour] = _linear_to_srgb(straight) * alpha
            colorspace = "sRGB"
        if is_float:
            half = rows.astype(np.float16)
            if np.array_equal(half.astype(np.float32), rows, equal_nan=True):
                data, component = half, "f16"
            else:
                data, component = rows, "f32"
        else:
            data = np.clip(np.rint(rows * 255.0), 0, 255).astype(np.uint8)
            component = "u8"
        view = self.buffer.add_view(np.ascontiguousarray(data).tobytes())
        entry = {"name": image.name, "width": w, "height": h, "channels": channels,
                 "component": component, "bufferView": view,
                 # Float pixels are scene linear (Blender converted them on load), but for
                 # sRGB files Cycles reads itself (encoded again above).
                 "colorspace": colorspace,
                 "source_colorspace": cs,
                 "alpha_mode": getattr(image, "alpha_mode", "STRAIGHT"),
                 "premultiplied": is_float}
        if frame is not None:
            entry["frame"] = int(frame)
        self.images.append(entry)
        self._index[key] = len(self.images) - 1
        return self._index[key]

    def add_tiles(self, image, node, material_name):
        """``[[tile number, TESELA_images index], ...]`` of a UDIM image whose every tile file
        can be read (from disk, or packed), or None (``add`` then gives the first tile from
        Blender's pixels, which hold that tile only). The files travel whole, for the
        renderer to decode as Cycles' loader does."""
        key = (getattr(image, "name_full", image.name), "tiles")
        if key in self._index:
            return self._index[key]
        tiles = []
        for number, data, path, packed in _tile_files(image):
            if data is None:
                # As in Cycles, a tile without its file renders as a missing image.
                self.report(material_name, node, "image '%s': UDIM tile %d has no file at '%s'; "
                            "it renders as a missing image" % (image.name, number, path))
            elif _tile_format(data) is None:
                self.report(material_name, node, "image '%s': UDIM tile %d ('%s') is not PNG, "
                            "JPEG, OpenEXR or Radiance HDR; it renders as a missing image"
                            % (image.name, number, os.path.basename(path)))
            else:
                tiles.append((number, data, path, packed))
        if not tiles:
            self._index[key] = None
            return None
        cs = image.colorspace_settings.name
        alpha_mode = getattr(image, "alpha_mode", "STRAIGHT")
        out = []
        for number, data, path, packed in tiles:
            # Cycles reads files itself, keeping sRGB floats encoded (as `add`); packed tiles
            # come from Blender's buffers, float ones linear.
            linearize = packed and _tile_is_float(data) and cs == "sRGB"
            entry = {"name": "%s.%d" % (image.name, number), "encoded": True,
                     "file": os.path.basename(path), "bufferView": self.buffer.add_view(data),
                     "colorspace": "Non-Color" if linearize else cs, "source_colorspace": cs,
                     "alpha_mode": alpha_mode, "linearize": linearize,
                     # Straight-alpha float files (16-bit PNG) are associated on load.
                     "premultiply": alpha_mode not in ("CHANNEL_PACKED", "NONE")
                     and cs not in ("Non-Color", "Raw", "Generic Data")}
            self.images.append(entry)
            out.append([number, len(self.images) - 1])
        self._index[key] = out
        return out

    def _missing(self, image, node, material_name):
        self.report(material_name, node, "image '%s' has no pixels (missing file?); it renders "
                    "as Cycles renders a missing image" % image.name)
