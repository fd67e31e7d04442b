"""Linear EXR in and out (through Mitsuba's Bitmap, so nothing else is needed), the object mask
and the noise and error measures truth.py and compare.py share.

Definitions (../../shared/truth-notes.md):
  - noise of a two-seed truth: half the relative mean absolute difference of the two seeds'
    4x4-pixel block means over the object's blocks, sum |B1 - B2| / 2 / sum (B1 + B2) / 2: the
    typical error of their mean at that scale.
  - error of an image L against the truth T: sum |L - T| / sum T over the object's pixels
    (all three channels); energy per channel: sum L / sum T.
"""

from __future__ import annotations

import numpy as np


def read_exr(path) -> np.ndarray:
    """An EXR's first three channels as float64 H x W x 3 (lucent writes RGBA)."""
    import mitsuba as mi

    array = np.array(mi.Bitmap(str(path)), dtype=np.float64)
    if array.ndim == 2:
        array = array[:, :, None]
    if array.shape[2] == 1:
        array = np.repeat(array, 3, axis=2)
    return array[:, :, :3]


def write_exr(path, rgb: np.ndarray, half: bool = True):
    """Linear RGB EXR, losslessly PIZ-compressed (Mitsuba's default for EXR), in half floats
    unless `half` is False: a half keeps 11 significant bits (relative rounding <= 2^-11 =
    0.05%, far below any truth's noise) and makes the committed files about half as large."""
    import mitsuba as mi

    bitmap = mi.Bitmap(np.ascontiguousarray(rgb, dtype=np.float32), mi.Bitmap.PixelFormat.RGB)
    if half:
        bitmap = bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float16, False)
    bitmap.write(str(path))


def erode(mask: np.ndarray, pixels: int) -> np.ndarray:
    """The mask shrunk by `pixels` (a pixel stays when its (2p+1)^2 neighbourhood is in)."""
    out = mask.copy()
    for _ in range(pixels):
        padded = np.pad(out, 1, constant_values=False)
        shrunk = np.ones_like(out)
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                shrunk &= padded[dy:dy + out.shape[0], dx:dx + out.shape[1]]
        out = shrunk
    return out


def block_means(image: np.ndarray, block: int = 4) -> np.ndarray:
    h, w = (image.shape[0] // block) * block, (image.shape[1] // block) * block
    b = image[:h, :w].reshape(h // block, block, w // block, block, -1)
    return b.mean(axis=(1, 3))


def two_seed_noise(first: np.ndarray, second: np.ndarray, mask: np.ndarray, block: int = 4):
    """Half the relative mean absolute difference of 4x4 block means over blocks wholly inside
    `mask`; also the same per pixel (what a per-pixel error inherits)."""
    inside = block_means(mask[:, :, None].astype(float), block)[:, :, 0] == 1.0
    b1, b2 = block_means(first, block)[inside], block_means(second, block)[inside]
    blocks = 0.5 * np.abs(b1 - b2).sum() / (0.5 * (b1 + b2)).sum()
    p1, p2 = first[mask], second[mask]
    pixels = 0.5 * np.abs(p1 - p2).sum() / (0.5 * (p1 + p2)).sum()
    return float(blocks), float(pixels), int(inside.sum())


def relative_error(lucent: np.ndarray, truth: np.ndarray, mask: np.ndarray):
    """sum |L - T| / sum T over the mask, and per-channel energy sum L / sum T."""
    l, t = lucent[mask], truth[mask]
    error = np.abs(l - t).sum() / t.sum()
    energy = l.sum(axis=0) / t.sum(axis=0)
    return float(error), energy.tolist()


def block_error(lucent: np.ndarray, truth: np.ndarray, mask: np.ndarray, block: int = 4):
    """sum |L - T| / sum T of `block` x `block` block means over blocks wholly inside `mask`:
    the error at the scale the noise is stated at (two truths of the same scene should differ
    by about the sum of their 4x4 noises here)."""
    inside = block_means(mask[:, :, None].astype(float), block)[:, :, 0] == 1.0
    bl, bt = block_means(lucent, block)[inside], block_means(truth, block)[inside]
    return float(np.abs(bl - bt).sum() / bt.sum())
