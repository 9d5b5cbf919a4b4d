# SPDX-License-Identifier: MIT
"""Mesh buffers kept across the renders of one render job (an animation, or one F12).

Each evaluated mesh's glTF data goes to <folder>/meshes/<digest>.bin, named by a blake2b of the
Blender arrays it is computed from (mesh.RawMesh.digest) and of what the materials ask of it;
each frame's .gltf, written in <folder>, refers to the files it needs. A mesh whose data did
not change since an earlier frame is neither converted nor written again. Files no frame used
since the frame before last are removed; the job removes the folder at its end.

No bpy: the engine owns a store per job and tests drive it outside Blender."""

import os
import shutil

SUBDIR = "meshes"


class StoredMesh:
    """One mesh's buffer file and what the glTF needs to refer to it."""

    def __init__(self, uri, byte_length, views, accessors, geometry, warnings):
        self.uri = uri                  # relative to the store's folder
        self.byte_length = byte_length
        self.views = views              # bufferViews into the file (buffer 0 = the file)
        self.accessors = accessors      # accessors indexing `views`
        self.geometry = geometry        # gltf.Geometry, accessor indices into `accessors`
        self.warnings = warnings        # what converting the mesh reported


class MeshStore:
    def __init__(self, folder):
        self.folder = folder
        os.makedirs(os.path.join(folder, SUBDIR), exist_ok=True)
        self._meshes = {}       # digest -> StoredMesh
        self._frame = None
        self._used = set()      # digests used by the renders of the current frame
        self._used_before = set()
        self.written = 0        # meshes written by the current render
        self.reused = 0         # meshes the current render found stored

    def begin_render(self, frame):
        """Start one render() (Blender calls it once per view layer): a new frame forgets the
        meshes neither it nor the frame before used."""
        if frame != self._frame:
            keep = self._used | self._used_before
            for digest in [d for d in self._meshes if d not in keep]:
                self._remove(digest)
            self._used_before, self._used = self._used, set()
            self._frame = frame
        self.written = self.reused = 0

    def get(self, digest):
        """The stored mesh of `digest`, or None."""
        stored = self._meshes.get(digest)
        if stored is not None:
            self._used.add(digest)
            self.reused += 1
        return stored

    def put(self, digest, buffer, geometry, warnings):
        """Write `buffer` (a Buffer holding only this mesh) as the file of `digest`."""
        uri = "%s/%s.bin" % (SUBDIR, digest)
        with open(os.path.join(self.folder, uri), "wb") as f:
            for chunk in buffer.chunks:
                f.write(chunk)
        stored = StoredMesh(uri, buffer.length, buffer.views, buffer.accessors, geometry,
                            list(warnings))
        self._meshes[digest] = stored
        self._used.add(digest)
        self.written += 1
        return stored

    def end_render(self):
        """Remove the render's own files (its .gltf, .bin, textures), keeping the meshes."""
        try:
            names = os.listdir(self.folder)
        except OSError:  # the job ended first (closed)
            return
        for name in names:
            if name == SUBDIR:
                continue
            path = os.path.join(self.folder, name)
            if os.path.isdir(path):
                shutil.rmtree(path, ignore_errors=True)
            else:
                try:
                    os.remove(path)
                except OSError:
                    pass

    def close(self):
        """Remove the folder and everything in it."""
        self._meshes.clear()
        shutil.rmtree(self.folder, ignore_errors=True)

    def _remove(self, digest):
        stored = self._meshes.pop(digest)
        try:
            os.remove(os.path.join(self.folder, stored.uri))
        except OSError:
            pass
