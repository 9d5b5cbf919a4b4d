# SPDX-License-Identifier: MIT
"""The binary buffer of one export: data chunks plus the bufferViews/accessors describing them."""

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

    def add_view(self, raw, target=None):
        """Append raw bytes (4-byte aligned) as a bufferView; returns its index."""
        pad = (-self.length) % 4
        if pad:
            self.chunks.append(b"\0" * pad)
            self.length += pad
        view = {"buffer": 0, "byteOffset": self.length, "byteLength": len(raw)}
        if target is not None:
            view["target"] = target
        self.views.append(view)
        self.chunks.append(raw)
        self.length += len(raw)
        return len(self.views) - 1

    def add(self, array, component, type_, target, minmax=False):
        data = np.ascontiguousarray(array)
        view = self.add_view(data.tobytes(), target)
        ncomp = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}[type_]
        acc = {"bufferView": view, "componentType": component,
               "count": int(data.size // ncomp), "type": type_}
        if minmax and data.size:
            d = data.reshape(-1, ncomp)
            if component == FLOAT:
                acc["min"] = [float(v) for v in d.min(axis=0)]
                acc["max"] = [float(v) for v in d.max(axis=0)]
            else:
                acc["min"] = [int(v) for v in d.min(axis=0)]
                acc["max"] = [int(v) for v in d.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1
