#!/usr/bin/env python3
"""lucent against every committed truth: one row per (scene, technique) with compare.py's
numbers (error over the object's pixels, over 4x4 block means, energy per channel).

    tools/truth/.venv/bin/python tools/truth/measure.py --lucent target/release/lucent \
        [--techniques none,auto,separable,burley,translucency] [--scenes a,b] [--out DIR]

Each truth `truths/NAME.exr` is compared with `lucent render --scene scenes/SCENE.toml --size
WxH --technique T --exr ...` at the truth's size (its JSON names the scene; a truth rendered
with `--sss-texturing MODE` gets lucent's flag of the same name). Prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--lucent", required=True, help="the lucent binary")
    p.add_argument("--techniques", default="none,auto,separable,burley,translucency")
    p.add_argument("--scenes", help="truth names (default: every truths/*.json)")
    p.add_argument("--out", type=Path, default=Path("/tmp/lucent-truth-measure"))
    p.add_argument("--json", type=Path, help="also write every row here")
    args = p.parse_args(argv)

    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    sys.path.insert(0, str(HERE))
    import images

    names = (args.scenes.split(",") if args.scenes else
             sorted(q.stem for q in (HERE / "truths").glob("*.json")))
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    print("| truth | technique | error | error 4x4 | energy R / G / B |")
    print("|---|---|---:|---:|---|")
    for name in names:
        meta = json.loads((HERE / "truths" / f"{name}.json").read_text())
        scene = HERE / meta["scene"]
        width, height = meta["size"]
        truth = images.read_exr(HERE / "truths" / f"{name}.exr")
        coverage = images.read_exr(HERE / "truths" / f"{name}.coverage.exr")
        mask = images.erode(coverage[:, :, 0] >= 0.999, 1)
        for technique in args.techniques.split(","):
            exr = args.out / f"{name}.{technique}.exr"
            cmd = [args.lucent, "render", "--scene", str(scene), "--size", f"{width}x{height}",
                   "--technique", technique, "--exr", str(exr),
                   "--out", str(exr.with_suffix(".png"))]
            if meta.get("sss_texturing"):
                cmd += ["--sss-texturing", meta["sss_texturing"]]
            run = subprocess.run(cmd, capture_output=True, text=True)
            if run.returncode != 0:
                why = (run.stderr.strip().splitlines() or ["?"])[-1]
                print(f"| {name} | {technique} | refused: {why} | | |")
                rows.append({"truth": name, "technique": technique, "refused": why})
                continue
            lucent = images.read_exr(exr)
            error, energy = images.relative_error(lucent, truth, mask)
            blocks = images.block_error(lucent, truth, mask, 4)
            print(f"| {name} | {technique} | {error:.4f} | {blocks:.4f} | "
                  f"{energy[0]:.3f} / {energy[1]:.3f} / {energy[2]:.3f} |", flush=True)
            rows.append({"truth": name, "technique": technique, "error": round(error, 4),
                         "error_4x4": round(blocks, 4), "energy": [round(e, 4) for e in energy],
                         "noise_4x4": meta.get("noise_4x4")})
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
