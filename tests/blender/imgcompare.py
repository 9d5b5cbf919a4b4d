"""Read linear EXR images through Blender and compare two renders statistically.

Public API:

* ``read_exr(path)`` -> float32 array (height, width, 4), linear RGBA, rows top to bottom.
  Uses Blender's own image loader (``bpy.data.images.load``), so it needs only ``bpy`` and numpy;
  the temporary image data block is removed again.
* ``compare(test, ref, ...)`` -> ``Comparison``: per-channel global means and 8x8-pixel block
  means of RGB. ``Comparison.ok`` says whether both criteria hold; ``str(comparison)`` prints
  the figures.
* ``assert_close(test, ref, ...)``: ``compare`` and raise ``AssertionError`` with the figures.

The criteria (defaults): each channel's global mean within 3% of the reference's, and the 95th
percentile of the block-mean relative errors within 10%. A block's relative error is
``|t - r| / max(r, floor)`` with ``floor = 0.05 * (reference channel mean)``, so that nearly black
blocks (shadows, background) do not turn noise into huge relative errors.
"""

from __future__ import annotations

from dataclasses import dataclass

import os

import numpy as np


def read_exr(path):
    """Load an EXR (or any image Blender reads) as float32 (height, width, 4), rows top to
    bottom, values as stored in the file (linear; no view transform)."""
    import bpy

    img = bpy.data.images.load(str(path), check_existing=False)
    try:
        try:
            # Non-colour data: Blender converts nothing on the way in.
            img.colorspace_settings.is_data = True
        except (AttributeError, TypeError):
            pass
        w, h = img.size
        channels = img.channels
        if w == 0 or h == 0:
            raise OSError(f"Blender could not read image {path}")
        buf = np.empty(w * h * channels, dtype=np.float32)
        img.pixels.foreach_get(buf)
    finally:
        bpy.data.images.remove(img)
    buf = buf.reshape(h, w, channels)[::-1]  # Blender's rows run bottom to top
    if channels == 4:
        return np.ascontiguousarray(buf)
    out = np.ones((h, w, 4), dtype=np.float32)
    out[..., :channels] = buf
    return out


def block_means(img, block=8):
    """Means of ``block`` x ``block`` pixel tiles of an (h, w, c) image (edge remainders dropped)."""
    h, w = img.shape[:2]
    hb, wb = h // block, w // block
    tiles = img[: hb * block, : wb * block].reshape(hb, block, wb, block, -1)
    return tiles.mean(axis=(1, 3))


@dataclass
class Comparison:
    """The figures of one comparison (RGB channels)."""
    test_mean: np.ndarray
    ref_mean: np.ndarray
    mean_rel_err: np.ndarray  # per channel
    block_p95: float  # 95th percentile of block relative errors, over all RGB channels
    block_max: float
    worst_block: tuple  # (row, col, channel) of the largest block error, in block units
    mean_tol: float
    block_tol: float

    @property
    def ok(self):
        return bool(np.all(self.mean_rel_err <= self.mean_tol) and self.block_p95 <= self.block_tol)

    def __str__(self):
        f = lambda v: "[" + ", ".join(f"{x:.5g}" for x in v) + "]"  # noqa: E731
        ratio = self.test_mean / np.maximum(self.ref_mean, 1e-12)
        return (f"means test {f(self.test_mean)} ref {f(self.ref_mean)} ratio {f(ratio)} "
                f"rel.err {f(self.mean_rel_err)} (tol {self.mean_tol:.3g}); "
                f"block rel.err p95 {self.block_p95:.4f} (tol {self.block_tol:.3g}), "
                f"max {self.block_max:.4f} at block(row, col, ch) {self.worst_block}")


def compare(test, ref, mean_tol=0.03, block=8, block_tol=0.10, percentile=95.0):
    """Compare image ``test`` against reference ``ref`` (arrays (h, w, >=3), same shape).
    With TESELA_TEST_DUMP set to a folder, both images are saved there (got.npy, ref.npy) to
    look at a failure."""
    dump = os.environ.get("TESELA_TEST_DUMP")
    if dump:
        os.makedirs(dump, exist_ok=True)
        np.save(os.path.join(dump, "got.npy"), np.asarray(test))
        np.save(os.path.join(dump, "ref.npy"), np.asarray(ref))
    test = np.asarray(test, dtype=np.float64)[..., :3]
    ref = np.asarray(ref, dtype=np.float64)[..., :3]
    if test.shape != ref.shape:
        raise ValueError(f"image shapes differ: test {test.shape}, reference {ref.shape}")
    tm = test.mean(axis=(0, 1))
    rm = ref.mean(axis=(0, 1))
    scale = np.maximum(np.abs(rm), 1e-6)
    mean_err = np.abs(tm - rm) / scale
    tb = block_means(test, block)
    rb = block_means(ref, block)
    floor = 0.05 * scale
    err = np.abs(tb - rb) / np.maximum(np.abs(rb), floor)
    worst = np.unravel_index(int(np.argmax(err)), err.shape)
    return Comparison(tm, rm, mean_err, float(np.percentile(err, percentile)), float(err.max()),
                      tuple(int(i) for i in worst), mean_tol, block_tol)


def assert_close(test, ref, label="", **kwargs):
    """Raise ``AssertionError`` with the figures unless ``compare(test, ref, **kwargs).ok``."""
    result = compare(test, ref, **kwargs)
    if not result.ok:
        raise AssertionError(f"{label}: images differ: {result}")
    return result
