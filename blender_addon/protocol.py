# SPDX-License-Identifier: MIT
"""Reader for the Tesela pipe protocol (docs/protocol.md, version 2).

Pure Python (struct) plus numpy for tile payloads; no bpy, so the reader is
usable and testable outside Blender.
"""

import struct
import threading

try:  # numpy ships with Blender; the fallback keeps the module importable.
    import numpy as np
except ImportError:  # pragma: no cover
    np = None

PROTOCOL_VERSION = 2
MAGIC = b"TSLA"
MAX_PAYLOAD = 1 << 30  # 1 GiB

HELLO, TILE, PROGRESS, LOG, ERROR, DONE = 1, 2, 3, 4, 5, 6
KIND_NAMES = {HELLO: "HELLO", TILE: "TILE", PROGRESS: "PROGRESS", LOG: "LOG",
              ERROR: "ERROR", DONE: "DONE"}

_HEADER = struct.Struct("<II")
_HELLO = struct.Struct("<4sIIIII")
_TILE_HEAD = struct.Struct("<IIII")
_PROGRESS = struct.Struct("<IIId")


class ProtocolError(Exception):
    """The byte stream does not follow the protocol."""


COMBINED = ("Combined", "RGBA")


class Hello:
    __slots__ = ("version", "width", "height", "spp", "tile_count", "passes")

    def __init__(self, version, width, height, spp, tile_count, passes=(COMBINED,)):
        self.version, self.width, self.height = version, width, height
        self.spp, self.tile_count = spp, tile_count
        # [(Blender pass name, channel ids)], Combined first: the layout of every tile.
        self.passes = list(passes)

    def __repr__(self):
        return "Hello(v%d, %dx%d, spp=%d, tiles=%d)" % (
            self.version, self.width, self.height, self.spp, self.tile_count)


class Tile:
    __slots__ = ("x", "y", "w", "h", "pixels", "passes")

    def __init__(self, x, y, w, h, pixels, passes=None):
        # pixels: float32 array shaped (h, w, 4), row 0 = top of the tile (Combined).
        # passes: {Blender pass name: float32 array (h, w, channels)} of the other passes.
        self.x, self.y, self.w, self.h, self.pixels = x, y, w, h, pixels
        self.passes = passes or {}

    def __repr__(self):
        return "Tile(%d, %d, %dx%d)" % (self.x, self.y, self.w, self.h)


class Progress:
    __slots__ = ("tiles_done", "tiles_total", "spp", "elapsed")

    def __init__(self, tiles_done, tiles_total, spp, elapsed):
        self.tiles_done, self.tiles_total = tiles_done, tiles_total
        self.spp, self.elapsed = spp, elapsed


class Log:
    __slots__ = ("level", "message")

    def __init__(self, level, message):
        self.level, self.message = level, message


class Error:
    __slots__ = ("message",)

    def __init__(self, message):
        self.message = message


class Done:
    __slots__ = ("stats",)

    def __init__(self, stats):
        self.stats = stats  # dict (may be empty if the JSON was unreadable)


class Eof:
    """The stream ended at a frame boundary."""
    __slots__ = ()


class Failure:
    """The stream broke the protocol; `message` says how."""
    __slots__ = ("message",)

    def __init__(self, message):
        self.message = message


def _read_exact(stream, n):
    """Read exactly n bytes; return fewer only at end of stream."""
    if n == 0:
        return b""
    chunks = []
    remaining = n
    while remaining:
        chunk = stream.read(remaining)
        if not chunk:
            break
        chunks.append(chunk)
        remaining -= len(chunk)
    return chunks[0] if len(chunks) == 1 else b"".join(chunks)


def _read_exact_into(stream, n):
    """Read n bytes into one preallocated buffer (no join copy for big tiles)."""
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    readinto = getattr(stream, "readinto", None)
    while got < n:
        if readinto is not None:
            k = readinto(view[got:])
        else:
            chunk = stream.read(n - got)
            k = len(chunk)
            view[got:got + k] = chunk
        if not k:
            break
        got += k
    return buf, got


def _utf8(payload):
    return bytes(payload).decode("utf-8", errors="replace")


def _hello_passes(payload, at):
    """The version-2 pass list of a HELLO payload from offset `at`."""
    def u32(at):
        if len(payload) < at + 4:
            raise ProtocolError("HELLO pass list truncated")
        return struct.unpack_from("<I", payload, at)[0], at + 4

    count, at = u32(at)
    if count > 1024:
        raise ProtocolError("HELLO announces %d passes" % count)
    passes = []
    for _ in range(count):
        texts = []
        for _ in range(2):
            n, at = u32(at)
            if len(payload) < at + n:
                raise ProtocolError("HELLO pass list truncated")
            texts.append(_utf8(payload[at:at + n]))
            at += n
        passes.append(tuple(texts))
    if not passes or passes[0] != COMBINED:
        raise ProtocolError("HELLO pass list does not start with Combined RGBA")
    return passes


def decode(kind, payload, hello=None):
    """Turn one frame into a message object; None for unknown kinds. Tiles are laid out by
    the passes of `hello` (Combined only without one)."""
    if kind == HELLO:
        if len(payload) < _HELLO.size:
            raise ProtocolError("HELLO payload too short (%d bytes)" % len(payload))
        magic, version, w, h, spp, tiles = _HELLO.unpack_from(payload, 0)
        if magic != MAGIC:
            raise ProtocolError("not a Tesela renderer (bad magic)")
        # Only this version's layout is known; another version is reported by the reader.
        passes = _hello_passes(payload, _HELLO.size) if version == 2 else [COMBINED]
        return Hello(version, w, h, spp, tiles, passes)
    if kind == TILE:
        if len(payload) < _TILE_HEAD.size:
            raise ProtocolError("TILE payload too short (%d bytes)" % len(payload))
        x, y, w, h = _TILE_HEAD.unpack_from(payload, 0)
        layout = hello.passes if hello is not None else [COMBINED]
        channels = sum(len(c) for _, c in layout)
        expected = _TILE_HEAD.size + w * h * 4 * channels
        if len(payload) != expected:
            raise ProtocolError("TILE %dx%d at (%d, %d): payload is %d bytes, expected %d"
                                % (w, h, x, y, len(payload), expected))
        data = np.frombuffer(payload, dtype="<f4", count=w * h * channels,
                             offset=_TILE_HEAD.size)
        at = w * h * 4
        pixels = data[:at].reshape(h, w, 4)
        passes = {}
        for name, ids in layout[1:]:
            k = len(ids)
            passes[name] = data[at:at + w * h * k].reshape(h, w, k)
            at += w * h * k
        return Tile(x, y, w, h, pixels, passes)
    if kind == PROGRESS:
        if len(payload) < _PROGRESS.size:
            raise ProtocolError("PROGRESS payload too short (%d bytes)" % len(payload))
        return Progress(*_PROGRESS.unpack_from(payload, 0))
    if kind == LOG:
        if len(payload) < 4:
            raise ProtocolError("LOG payload too short")
        (level,) = struct.unpack_from("<I", payload, 0)
        return Log(level, _utf8(payload[4:]))
    if kind == ERROR:
        return Error(_utf8(payload))
    if kind == DONE:
        import json
        try:
            stats = json.loads(_utf8(payload))
            if not isinstance(stats, dict):
                stats = {}
        except ValueError:
            stats = {}
        return Done(stats)
    return None


class FrameReader:
    """Reads frames from a binary stream and yields message objects.

    The first frame must be a HELLO carrying the magic and protocol version 2;
    anything else is reported as a ProtocolError with the protocol's wording.
    """

    def __init__(self, stream):
        self.stream = stream
        self.seen_hello = False
        self.hello = None
        self.finished = False  # DONE or ERROR seen

    def read_message(self):
        """Next message, Eof at a clean end of stream; raises ProtocolError."""
        while True:
            header = _read_exact(self.stream, _HEADER.size)
            if not header:
                return Eof()
            if not self.seen_hello:
                # Detect a foreign program as early as possible.
                if len(header) < _HEADER.size:
                    if b"\x01\x00\x00\x00".startswith(header):
                        raise ProtocolError("truncated frame header (%d of 8 bytes)" % len(header))
                    raise ProtocolError("not a Tesela renderer (bad magic)")
                if _HEADER.unpack(header)[0] not in (HELLO, ERROR):
                    raise ProtocolError("not a Tesela renderer (bad magic)")
            if len(header) < _HEADER.size:
                raise ProtocolError("truncated frame header (%d of 8 bytes)" % len(header))
            kind, length = _HEADER.unpack(header)
            if length > MAX_PAYLOAD:
                raise ProtocolError("frame of kind %d announces %d bytes (over 1 GiB)" % (kind, length))
            if kind == TILE:
                payload, got = _read_exact_into(self.stream, length)
            else:
                payload = _read_exact(self.stream, length)
                got = len(payload)
            if got < length:
                if not self.seen_hello and kind == HELLO and got >= 4 and bytes(payload[:4]) != MAGIC:
                    raise ProtocolError("not a Tesela renderer (bad magic)")
                raise ProtocolError("truncated %s frame (%d of %d payload bytes)"
                                    % (KIND_NAMES.get(kind, "kind %d" % kind), got, length))
            if not self.seen_hello and kind == ERROR:
                # A scene that fails to load sends ERROR instead of HELLO.
                self.finished = True
                self.seen_hello = True
                return decode(ERROR, payload)
            if not self.seen_hello:
                msg = decode(HELLO, payload)
                if msg.version != PROTOCOL_VERSION:
                    raise ProtocolError(
                        "protocol version mismatch: renderer speaks %d, add-on speaks %d"
                        % (msg.version, PROTOCOL_VERSION))
                self.seen_hello = True
                self.hello = msg
                return msg
            if kind == HELLO:
                raise ProtocolError("second HELLO frame")
            if self.finished:
                raise ProtocolError("%s frame after the end of the render"
                                    % KIND_NAMES.get(kind, "kind %d" % kind))
            msg = decode(kind, payload, self.hello)
            if msg is None:
                continue  # unknown kind: skipped (forward compatibility)
            if isinstance(msg, (Done, Error)):
                self.finished = True
            return msg

    def __iter__(self):
        while True:
            msg = self.read_message()
            if isinstance(msg, Eof):
                return
            yield msg


def reader_thread(stream, put):
    """Body of the add-on's reader thread: every message, then Eof or Failure,
    goes to `put` (a queue's put). Never raises."""
    reader = FrameReader(stream)
    try:
        while True:
            msg = reader.read_message()
            put(msg)
            if isinstance(msg, Eof):
                return
    except ProtocolError as exc:
        put(Failure(str(exc)))
    except (OSError, ValueError) as exc:  # stream closed under us
        put(Failure("pipe read failed: %s" % exc))
    except Exception as exc:  # noqa: BLE001 - the thread must always report
        put(Failure("reader crashed: %r" % exc))


def start_reader(stream, put):
    t = threading.Thread(target=reader_thread, args=(stream, put),
                         name="tesela-pipe-reader", daemon=True)
    t.start()
    return t


# --- writer side (used by the fake renderer and the tests) -----------------

def frame(kind, payload):
    return _HEADER.pack(kind, len(payload)) + payload


def hello_frame(width, height, spp, tile_count, version=PROTOCOL_VERSION, magic=MAGIC,
                passes=(COMBINED,)):
    payload = _HELLO.pack(magic, version, width, height, spp, tile_count)
    if version >= 2:
        payload += struct.pack("<I", len(passes))
        for name, ids in passes:
            for text in (name, ids):
                b = text.encode("utf-8")
                payload += struct.pack("<I", len(b)) + b
    return frame(HELLO, payload)


def tile_frame(x, y, w, h, rgba_bytes):
    return frame(TILE, _TILE_HEAD.pack(x, y, w, h) + bytes(rgba_bytes))


def progress_frame(done, total, spp, elapsed):
    return frame(PROGRESS, _PROGRESS.pack(done, total, spp, elapsed))


def log_frame(level, message):
    return frame(LOG, struct.pack("<I", level) + message.encode("utf-8"))


def error_frame(message):
    return frame(ERROR, message.encode("utf-8"))


def done_frame(stats_json):
    return frame(DONE, stats_json.encode("utf-8"))
