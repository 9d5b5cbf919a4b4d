"""Planning a farm render: which scene files travel with a task, how many samples a still
has, and how its samples are split into ranges."""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import unquote

#: Samples per pixel `tesela render` uses when neither the command line nor the scene says.
DEFAULT_SPP = 64

_GLB_MAGIC = b"glTF"
_GLB_JSON = 0x4E4F534A


class SceneError(Exception):
    """A scene file that cannot be read or shipped (the message names the file)."""


def gltf_json(path: Path) -> dict:
    """The JSON of a .gltf file, or the JSON chunk of a .glb file."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise SceneError(f"{path}: cannot read the scene: {exc.strerror or exc}") from exc
    try:
        if data[:4] == _GLB_MAGIC:
            if len(data) < 20:
                raise ValueError("truncated GLB header")
            length, kind = struct.unpack_from("<II", data, 12)
            if kind != _GLB_JSON or 20 + length > len(data):
                raise ValueError("the GLB's first chunk is not JSON")
            return json.loads(data[20:20 + length])
        return json.loads(data)
    except (ValueError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: not a glTF file: {exc}") from exc


def scene_spp(path: Path) -> int:
    """The samples per pixel `tesela render` would use for the scene: its `TESELA_render`
    setting (docs/extensions.md), else the renderer's default."""
    render = gltf_json(path).get("extensions", {}).get("TESELA_render", {})
    spp = render.get("spp") if isinstance(render, dict) else None
    return spp if isinstance(spp, int) and spp > 0 else DEFAULT_SPP


def bundle(path: Path) -> dict:
    """The scene as a task carries it: the scene file and every external buffer and image it
    names (relative URIs below its folder), as `{"main": name, "files": {name: bytes}}`."""
    doc = gltf_json(path)
    folder = path.parent
    files = {path.name: path.read_bytes()}
    for kind in ("buffers", "images"):
        for item in doc.get(kind, []) or []:
            uri = item.get("uri") if isinstance(item, dict) else None
            if not isinstance(uri, str) or uri.startswith("data:"):
                continue
            rel = Path(unquote(uri))
            if rel.is_absolute() or ".." in rel.parts:
                raise SceneError(
                    f"{path}: {kind} URI `{uri}` lies outside the scene's folder; "
                    "put the scene on a path every worker reads and use --shared")
            try:
                files[rel.as_posix()] = (folder / rel).read_bytes()
            except OSError as exc:
                raise SceneError(f"{path}: {kind} file {folder / rel}: "
                                 f"{exc.strerror or exc}") from exc
    return {"main": path.name, "files": files}


@dataclass(frozen=True)
class Part:
    """Samples `[start, end)` of a still."""

    index: int
    start: int
    end: int

    @property
    def range(self) -> str:
        return f"{self.start}:{self.end}"


def split_samples(spp: int, parts: int) -> list[Part]:
    """`spp` samples in `parts` contiguous ranges as equal as they can be (fewer ranges when
    there are fewer samples than parts)."""
    if spp < 1:
        raise ValueError(f"samples per pixel {spp} must be at least 1")
    n = max(1, min(parts, spp))
    bounds = [spp * i // n for i in range(n + 1)]
    return [Part(i, a, b) for i, (a, b) in enumerate(zip(bounds, bounds[1:]))]


def frame_output(pattern: str, frame: int) -> str:
    """Blender's output convention: the last run of `#` becomes the zero-padded frame number
    (`out/frame_####.exr` -> `out/frame_0007.exr`)."""
    end = pattern.rfind("#")
    if end < 0:
        raise ValueError(f"{pattern}: a frame sequence's output needs # for the frame number")
    start = end
    while start > 0 and pattern[start - 1] == "#":
        start -= 1
    width = end - start + 1
    return f"{pattern[:start]}{frame:0{width}d}{pattern[end + 1:]}"
