# SPDX-License-Identifier: MIT
"""The binary buffers of one export: buffer 0's data chunks (the .bin beside the .gltf), buffers
already written to files of their own (the mesh store's), and the bufferViews/accessors
describing both."""

import numpy as np

FLOAT, UINT = 5126, 5125
ARRAY_BUFFER, ELEMENT_ARRAY_BUFFER = 34962, 34963


class Buffer:
    """Accumulates binary data and the bufferViews/accessors that describe it."""

    def __init__(self):
        self.chunks = []
        self.length = 0
        self.views = []
        self.accessors = []
        self.files = []  # [(uri relative to the .gltf, byteLength)]: buffers 1, 2, ...

    def add_file(self, uri, byte_length, views, accessors):
        """Reference a buffer file whose own bufferViews (buffer 0, offsets into the file) and
        accessors (indexing those views) are `views` and `accessors`, as another Buffer built
        them. Returns the index of its first accessor here: its accessor k is first + k."""
        self.files.append((uri, byte_length))
        index, first_view, first = len(self.files), len(self.views), len(self.accessors)
        self.views.extend(dict(v, buffer=index) for v in views)
        self.accessors.extend(dict(a, bufferView=a["bufferView"] + first_view) for a in accessors)
        return first

    def gltf_buffers(self, bin_uri):
        """The document's `buffers` (buffer 0 at `bin_uri`), renumbering the views when buffer 0
        is empty (glTF forbids empty buffers), or None without data."""
        buffers = [{"uri": uri, "byteLength": n} for uri, n in self.files]
        if self.length:
            return [{"uri": bin_uri, "byteLength": self.length}] + buffers
        if not buffers:
            return None
        for v in self.views:
            v["buffer"] -= 1
        return buffers

    def add_view(self, raw, target=None):
        """Append raw bytes (4-byte aligned) as a bufferView; returns its index. `raw` is any
        contiguous buffer (bytes, a numpy array), kept as it is until the .bin is written: it
        must not change before then."""
        pad = (-self.length) % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.length += pad
        size = memoryview(raw).nbytes
        view = {"buffer": 0, "byteOffset": self.length, "byteLength": size}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        self.chunks.append(raw)
        self.length += size
        return len(self.views) - 1

    def add(self, array, component, type_, target, minmax=False):
        """An accessor over `array` (float32 for FLOAT, uint32 for UINT; not copied if it is
        contiguous: it must not change until the .bin is written); returns its index."""
        data = np.ascontiguousarray(array)
        view = self.add_view(data, target)
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[type_]
        acc = {"bufferView": view, "componentType": component,
               "count": int(data.size // ncomp), "type": type_}
        if minmax and data.size:
            d = data.reshape(-1, ncomp)
            # Column by column: numpy's min(axis=0) over narrow rows is ~4x slower.
            cast = float if component == FLOAT else int
            acc["min"] = [cast(d[:, i].min()) for i in range(ncomp)]
            acc["max"] = [cast(d[:, i].max()) for i in range(ncomp)]
        self.accessors.append(acc)
        return len(self.accessors) - 1
