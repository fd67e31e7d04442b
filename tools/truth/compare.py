#!/usr/bin/env python3
"""Compare a lucent frame with its truth over the object's pixels.

    tools/truth/.venv/bin/python tools/truth/compare.py LUCENT.exr TRUTH.exr \
        [--mask MASK.exr] [--erode 1] [--json OUT.json]

Prints the relative mean absolute error sum |L - T| / sum T over the object's pixels (all three
channels together), the energy per channel sum L / sum T, and the same error over 4x4-pixel
block means (the scale truth.py states the noise at; what two truths of one scene are compared
by) (images.py).

The object's pixels: by default TRUTH.coverage.exr, which truth.py writes beside the truth (the
fraction of each pixel's camera rays that hit an object, from a Mitsuba render of the same
camera with every object opaque black in front of a white constant environment, 64 rays a
pixel); a pixel counts when every ray hit. `--mask` takes any EXR instead (a pixel counts where
its first channel is >= 0.999). The mask is then eroded by `--erode` pixels (default 1) so
silhouettes, where lucent's tessellated mesh and the truth's analytic surface differ by a
fraction of a pixel, do not count.

lucent's frame: `lucent render --scene S.toml --size WxH --exr L.exr --out L.png` (linear HDR,
before exposure and tonemapping), at the truth's size.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("lucent", type=Path)
    p.add_argument("truth", type=Path)
    p.add_argument("--mask", type=Path, help="object mask EXR (default TRUTH.coverage.exr)")
    p.add_argument("--erode", type=int, default=1, help="pixels taken off the mask's edge")
    p.add_argument("--json", type=Path, help="also write the numbers here")
    args = p.parse_args(argv)

    # Reading EXR needs only a Mitsuba variant, the scalar one is always there.
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import images

    lucent, truth = images.read_exr(args.lucent), images.read_exr(args.truth)
    if lucent.shape != truth.shape:
        print(f"compare: sizes differ: {args.lucent} {lucent.shape[1]}x{lucent.shape[0]}, "
              f"{args.truth} {truth.shape[1]}x{truth.shape[0]}", file=sys.stderr)
        return 2
    mask_path = args.mask or args.truth.with_suffix(".coverage.exr")
    mask = images.read_exr(mask_path)[:, :, 0] >= 0.999
    mask = images.erode(mask, args.erode)
    if not mask.any():
        print(f"compare: the mask {mask_path} is empty", file=sys.stderr)
        return 2
    error, energy = images.relative_error(lucent, truth, mask)
    blocks = images.block_error(lucent, truth, mask, 4)
    numbers = {"lucent": str(args.lucent), "truth": str(args.truth), "mask": str(mask_path),
               "pixels": int(mask.sum()), "error": round(error, 4), "error_4x4": round(blocks, 4),
               "energy": [round(e, 4) for e in energy]}
    print(f"error {error:.4f}  energy R {energy[0]:.4f} G {energy[1]:.4f} B {energy[2]:.4f}  "
          f"over {numbers['pixels']} pixels (4x4 block means: {blocks:.4f})")
    if args.json:
        args.json.write_text(json.dumps(numbers, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
