# SPDX-License-Identifier: MIT
"""The session protocol (docs/session.md, version 1): command frames to `tesela session` and the
frames it answers with. Pure Python (struct, json) plus numpy for the pixels; no bpy."""

import json
import struct

import numpy as np

SESSION_VERSION = 1
MAGIC = b"TSLS"
MAX_PAYLOAD = 1 << 30

COMMAND = 32
HELLO, LOG, ERROR, IMAGE, STATS = 1, 4, 5, 16, 17

_HEADER = struct.Struct("<II")
_IMAGE_HEAD = struct.Struct("<Q11I")  # generation, then 11 u32: 52 bytes

FLAG_LAST = 1      # the sample target of this generation is reached
FLAG_DENOISED = 2


class ProtocolError(Exception):
    """The byte stream from the session does not follow the protocol."""


def command_frame(cmd, **fields):
    """One COMMAND frame: {"cmd": cmd, **fields} as UTF-8 JSON, no attachment."""
    body = json.dumps(dict(fields, cmd=cmd), ensure_ascii=False,
                      separators=(",", ":")).encode("utf-8")
    payload = struct.pack("<I", len(body)) + body
    return _HEADER.pack(COMMAND, len(payload)) + payload


def parse_command(payload):
    """The JSON object of a COMMAND payload (for fake sessions and tests)."""
    if len(payload) < 4:
        raise ProtocolError("COMMAND payload too short (%d bytes)" % len(payload))
    (n,) = struct.unpack_from("<I", payload, 0)
    if 4 + n > len(payload):
        raise ProtocolError("COMMAND JSON length %d beyond the payload" % n)
    return json.loads(bytes(payload[4:4 + n]).decode("utf-8"))


class Hello:
    __slots__ = ("version", "info")

    def __init__(self, version, info):
        self.version, self.info = version, info


class Log:
    __slots__ = ("level", "message")

    def __init__(self, level, message):
        self.level, self.message = level, message


class Error:
    """A non-fatal ERROR answers one command; a fatal one ends the session."""
    __slots__ = ("command", "id", "message", "fatal")

    def __init__(self, command, id_, message, fatal):
        self.command, self.id, self.message, self.fatal = command, id_, message, fatal

    def text(self):
        return "%s: %s" % (self.command, self.message) if self.command else self.message


class Image:
    """One progressive image: `pixels` float32 (data_height, data_width, 4), rows top to bottom,
    linear radiance, for the window (x, y, width, height) of the view (top-left origin). Data
    pixel (i, j) covers the view's pixel_size x pixel_size cell (x // pixel_size + i,
    y // pixel_size + j), as the session renders a border at a reduced resolution."""
    __slots__ = ("generation", "view_width", "view_height", "x", "y", "width", "height",
                 "pixel_size", "samples", "flags", "pixels")

    def __init__(self, generation, view_width, view_height, x, y, width, height, pixel_size,
                 samples, flags, pixels):
        self.generation = generation
        self.view_width, self.view_height = view_width, view_height
        self.x, self.y, self.width, self.height = x, y, width, height
        self.pixel_size, self.samples, self.flags = pixel_size, samples, flags
        self.pixels = pixels

    @property
    def last(self):
        return bool(self.flags & FLAG_LAST)

    @property
    def denoised(self):
        return bool(self.flags & FLAG_DENOISED)


class Stats:
    __slots__ = ("data",)

    def __init__(self, data):
        self.data = data


def _utf8(b):
    return bytes(b).decode("utf-8", errors="replace")


def _json_object(b):
    try:
        v = json.loads(_utf8(b))
    except ValueError:
        return None
    return v if isinstance(v, dict) else None


def decode(kind, payload):
    """A message object for one frame; None for kinds this add-on does not know."""
    if kind == HELLO:
        if len(payload) < 8 or bytes(payload[:4]) != MAGIC:
            raise ProtocolError("not a Tesela session (bad magic)")
        (version,) = struct.unpack_from("<I", payload, 4)
        return Hello(version, _json_object(payload[8:]) or {})
    if kind == LOG:
        if len(payload) < 4:
            raise ProtocolError("LOG payload too short")
        return Log(struct.unpack_from("<I", payload, 0)[0], _utf8(payload[4:]))
    if kind == ERROR:
        obj = _json_object(payload)
        if obj is None:
            return Error(None, None, _utf8(payload), False)
        return Error(obj.get("command"), obj.get("id"), str(obj.get("message", "")),
                     bool(obj.get("fatal", False)))
    if kind == IMAGE:
        if len(payload) < _IMAGE_HEAD.size:
            raise ProtocolError("IMAGE payload too short (%d bytes)" % len(payload))
        (gen, vw, vh, x, y, w, h, ps, dw, dh, spp, flags) = _IMAGE_HEAD.unpack_from(payload, 0)
        expected = _IMAGE_HEAD.size + 16 * dw * dh
        if len(payload) != expected:
            raise ProtocolError("IMAGE %dx%d: payload is %d bytes, expected %d"
                                % (dw, dh, len(payload), expected))
        # The data may be cut at the view's edges, and its grid of pixel_size cells starts at
        # the cell holding the window's corner, so it spans at most one cell more.
        if ps == 0 or dw > -(-w // ps) + 1 or dh > -(-h // ps) + 1:
            raise ProtocolError("IMAGE data %dx%d does not fit a %dx%d window at pixel size %d"
                                % (dw, dh, w, h, ps))
        pixels = np.frombuffer(payload, dtype="<f4", count=dw * dh * 4,
                               offset=_IMAGE_HEAD.size).reshape(dh, dw, 4)
        return Image(gen, vw, vh, x, y, w, h, ps, spp, flags, pixels)
    if kind == STATS:
        return Stats(_json_object(payload) or {})
    return None


def _read_exact(stream, n):
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    while got < n:
        k = stream.readinto(view[got:])
        if not k:
            break
        got += k
    return buf, got


class FrameReader:
    """Reads the session's frames; the first must be a HELLO of version 1."""

    def __init__(self, stream):
        self.stream = stream
        self.hello = None

    def read_message(self):
        """The next message, or None at a clean end of stream; raises ProtocolError."""
        while True:
            header, got = _read_exact(self.stream, _HEADER.size)
            if got == 0:
                return None
            if got < _HEADER.size:
                raise ProtocolError("truncated frame header (%d of 8 bytes)" % got)
            kind, length = _HEADER.unpack(header)
            if self.hello is None and kind not in (HELLO, ERROR):
                raise ProtocolError("not a Tesela session (its first frame is of kind %d)" % kind)
            if length > MAX_PAYLOAD:
                raise ProtocolError("frame of kind %d announces %d bytes" % (kind, length))
            payload, got = _read_exact(self.stream, length)
            if got < length:
                raise ProtocolError("truncated frame of kind %d (%d of %d bytes)"
                                    % (kind, got, length))
            msg = decode(kind, payload)
            if isinstance(msg, Hello):
                if self.hello is not None:
                    raise ProtocolError("second HELLO frame")
                if msg.version != SESSION_VERSION:
                    raise ProtocolError("session protocol version mismatch: renderer speaks %d, "
                                        "add-on speaks %d" % (msg.version, SESSION_VERSION))
                self.hello = msg
            if msg is not None:
                return msg


# --- writer side of the session's frames (fake sessions in the tests) ------------------------

def frame(kind, payload):
    return _HEADER.pack(kind, len(payload)) + bytes(payload)


def hello_frame(version=SESSION_VERSION, info=None, magic=MAGIC):
    return frame(HELLO, magic + struct.pack("<I", version)
                 + json.dumps(info or {"renderer": "fake"}).encode("utf-8"))


def error_frame(command, message, id_=None, fatal=False):
    return frame(ERROR, json.dumps({"command": command, "id": id_, "message": message,
                                    "fatal": fatal}).encode("utf-8"))


def image_frame(generation, view_width, view_height, window, pixel_size, samples, flags, rgba):
    """rgba: float32 (data_height, data_width, 4), rows top to bottom."""
    x, y, w, h = window
    dh, dw = rgba.shape[:2]
    head = _IMAGE_HEAD.pack(generation, view_width, view_height, x, y, w, h, pixel_size,
                            dw, dh, samples, flags)
    return frame(IMAGE, head + np.ascontiguousarray(rgba, "<f4").tobytes())


def stats_frame(data):
    return frame(STATS, json.dumps(data).encode("utf-8"))
