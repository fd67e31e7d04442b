#!/usr/bin/env python3
"""Render the path-traced truth of a lucent scene file with Mitsuba 3.

    tools/truth/.venv/bin/python tools/truth/truth.py SCENE.toml --out OUT.exr \
        [--size 256x192] [--spp 256] [--seed 1] [--seeds 2] [--variant llvm_ad_rgb]

Writes OUT.exr (linear RGB radiance, the mean of the seeds), OUT.coverage.exr (the fraction of
each pixel's camera rays that hit an object: 1 inside, 0 outside, between on silhouettes) and
OUT.json (spp, seeds, seconds, noise, the variant, the notes). With two or more seeds it prints
the noise: half the relative mean absolute difference of the first two seeds' 4x4-pixel block
means over the object (images.py).

The scene is converted by lucent_to_mitsuba.py (what is matched and what is refused is written
there and in README.md). Rendering: `volpath` with max_depth -1 (no path is cut short except by
Russian roulette, which is unbiased), one `independent` sampler stream per seed, a box pixel
filter (each pixel is the mean radiance over its area; lucent shades one sample at the centre).

Where no object is, lucent shows its `sky` colour while its lighting comes from the
environment; Mitsuba shows the environment. The truth is made to show `sky` there as well:
two cheap renders of the same camera with every object opaque black (path, max_depth 1) give
the uncovered fraction of each pixel and the environment seen through it, and the image becomes
render - environment_seen + uncovered x sky.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

LLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"


def choose_variant(requested: str | None) -> str:
    """llvm_ad_rgb with Debian's LLVM 19 when it is there (LLVM 15 crashes it, 14 is refused:
    truth-notes), scalar_rgb otherwise. Must run before mitsuba is imported."""
    if requested:
        variant = requested
    elif os.path.exists(LLVM19) or os.environ.get("DRJIT_LIBLLVM_PATH"):
        variant = "llvm_ad_rgb"
    else:
        variant = "scalar_rgb"
        print("truth: LLVM 19 not found (run tools/truth/setup.sh as root); using the slower "
              "scalar_rgb variant", file=sys.stderr)
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        os.environ["DRJIT_LIBLLVM_PATH"] = LLVM19
    return variant


def parse_size(text: str):
    w, h = text.lower().split("x")
    return int(w), int(h)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene", type=Path, help="a lucent scene file (.toml)")
    p.add_argument("--out", type=Path, required=True, help="the linear EXR to write")
    p.add_argument("--size", default="256x192", help="WIDTHxHEIGHT (default 256x192)")
    p.add_argument("--spp", type=int, default=256, help="samples per pixel per seed")
    p.add_argument("--seed", type=int, default=1, help="the first seed (the others follow)")
    p.add_argument("--seeds", type=int, default=2,
                   help="seeds rendered and averaged; 2 or more also measures the noise")
    p.add_argument("--variant", help="Mitsuba variant (default llvm_ad_rgb with LLVM 19, "
                   "else scalar_rgb)")
    p.add_argument("--rr-depth", type=int, default=1_000_000,
                   help="bounces before Russian roulette starts (default: never, in practice)")
    p.add_argument("--threads", type=int, help="worker threads (default: every core)")
    p.add_argument("--allow-dielectric-delta-lights", action="store_true",
                   help="render a medium behind eta != 1 lit by point/spot/directional lights "
                   "anyway (volpath cannot light it through the dielectric: it gets only the "
                   "environment)")
    p.add_argument("--integrator", choices=["auto", "volpath", "refracted-nee"], default="auto",
                   help="volpath, or refracted_nee.py's refracted next-event estimation (one "
                   "sphere, point lights; what auto picks for a medium behind a dielectric)")
    p.add_argument("--sss-texturing", choices=["post", "pre-post", "pre"],
                   help="as lucent's flag: which film an albedo texture on a medium is "
                   "(default: the material's [material.sss] texturing, else post)")
    p.add_argument("--with-camera-reflection", action="store_true",
                   help="refracted-nee: also count the camera ray's specular reflection of the "
                   "environment off the boundary (not counted by default: lucent's truth "
                   "scenes have specular 0)")
    p.add_argument("--per-channel", action="store_true",
                   help="volpath: render R, G and B apart, each with every medium grey at that "
                   "channel's coefficients (volpath's one-channel-per-path spectral sampling "
                   "weighs the other channels by exp((sigma_t,hero - sigma_t,c) t) per flight, "
                   "which explodes in dense media whose channels differ: fireflies)")
    p.add_argument("--pass-spp", type=int, default=32,
                   help="refracted-nee: samples per pixel per render pass (memory)")
    args = p.parse_args(argv)

    variant = choose_variant(args.variant)
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(variant)
    if args.threads:
        dr.set_thread_count(args.threads)
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import film  # noqa: F401  (registers the `truth_film` BSDF)
    import images
    import refracted_nee
    from lucent_to_mitsuba import Refused, convert

    width, height = parse_size(args.size)
    with tempfile.TemporaryDirectory(prefix="truth-") as work:
        try:
            converted = convert(args.scene, Path(work), args.allow_dielectric_delta_lights,
                                refracted_nee=args.integrator != "volpath",
                                texturing_override=args.sss_texturing)
        except Refused as e:
            print(f"truth: refused: {e}", file=sys.stderr)
            return 2
        nee = converted.refracted_nee
        if args.integrator == "refracted-nee" and not isinstance(nee, dict):
            print(f"truth: refused: {args.scene}: --integrator refracted-nee: {nee}",
                  file=sys.stderr)
            return 2
        use_nee = args.integrator == "refracted-nee" or (
            args.integrator == "auto" and converted.has_dielectric and isinstance(nee, dict)
            and not args.allow_dielectric_delta_lights)
        integrator_name = "refracted-nee" if use_nee else "volpath"
        if use_nee:
            if variant != "llvm_ad_rgb":
                print("truth: refused: refracted-nee needs the llvm_ad_rgb variant", file=sys.stderr)
                return 2
            nee_integrator = refracted_nee.RefractedNee()
            nee_integrator.configure(nee["centre"], nee["radius"], nee["eta"], nee["sigma_t"],
                                     nee["albedo"], nee["g"], nee["lights"],
                                     args.with_camera_reflection)
            converted.notes.append(
                "integrator: refracted next-event estimation (refracted_nee.py); the camera "
                "ray's specular reflection off the boundary is "
                + ("counted" if args.with_camera_reflection else "not counted"))
        for note in converted.notes:
            print(f"truth: note: {note}", file=sys.stderr)
        if converted.has_dielectric and args.allow_dielectric_delta_lights:
            print("truth: WARNING: point/spot/directional lights do not reach media behind a "
                  "dielectric boundary in volpath: the truth holds only environment light "
                  "there", file=sys.stderr)

        def sensor(spp):
            s = dict(converted.sensor)
            s["film"] = {"type": "hdrfilm", "width": width, "height": height,
                         "pixel_format": "rgb", "component_format": "float32",
                         "rfilter": {"type": "box"}}
            s["sampler"] = {"type": "independent", "sample_count": spp}
            return s

        main_scene = dict(converted.scene)
        main_scene["sensor"] = sensor(args.spp)
        # Russian roulette would stop paths with survival capped at 0.95 per bounce: unbiased,
        # but a marble path needs thousands of scattering events, which roulette turns into
        # rare huge-weight fireflies. Paths end by leaving the object instead.
        main_scene["integrator"] = {"type": "volpath", "max_depth": -1,
                                    "rr_depth": args.rr_depth}
        scene = mi.load_dict(main_scene)
        channel_scenes = []
        if args.per_channel and not use_nee:
            def grey(value, c):
                # An `rgb` dict {"type": "rgb", "value": [r, g, b]} -> channel c everywhere.
                v = value["value"][c]
                return {"type": "rgb", "value": [v, v, v]}

            for c in range(3):
                d = {}
                for name, shape in main_scene.items():
                    if isinstance(shape, dict) and any(
                            isinstance(shape.get(side), dict) for side in ("interior", "exterior")):
                        shape = dict(shape)
                        for side in ("interior", "exterior"):
                            medium = shape.get(side)
                            if isinstance(medium, dict) and medium.get("type") == "homogeneous":
                                medium = dict(medium)
                                medium["sigma_t"] = grey(medium["sigma_t"], c)
                                medium["albedo"] = grey(medium["albedo"], c)
                                shape[side] = medium
                    d[name] = shape
                d["sensor"] = main_scene["sensor"]
                channel_scenes.append(mi.load_dict(d))
            converted.notes.append("rendered per channel (--per-channel): each of R, G, B with "
                                   "every medium grey at that channel's coefficients")

        def render(seed):
            if channel_scenes:
                out = None
                for c, cs in enumerate(channel_scenes):
                    image = np.array(mi.render(cs, seed=seed, spp=args.spp), dtype=np.float64)
                    if out is None:
                        out = image[:, :, :3].copy()
                    out[:, :, c] = image[:, :, c]
                return out
            if not use_nee:
                return np.array(mi.render(scene, seed=seed, spp=args.spp), dtype=np.float64)
            # The Python integrator's wavefront holds every sample of a pass: render in passes
            # of --pass-spp, each with its own seed stream (seed x 100003 + pass).
            passes = max(1, -(-args.spp // args.pass_spp))
            total = 0.0
            for k in range(passes):
                spp = min(args.pass_spp, args.spp - k * args.pass_spp)
                image = np.array(mi.render(scene, integrator=nee_integrator,
                                           seed=seed * 100003 + k, spp=spp), dtype=np.float64)
                total = total + image * spp
            return total / args.spp

        renders, seconds = [], []
        for k in range(args.seeds):
            start = time.perf_counter()
            image = render(args.seed + k)
            seconds.append(time.perf_counter() - start)
            renders.append(image[:, :, :3])
            print(f"truth: seed {args.seed + k}: {args.spp} spp in {seconds[-1]:.1f} s",
                  file=sys.stderr)

        # Where no object is: the uncovered fraction and the environment seen through it.
        def black_scene(emitter):
            d = {"type": "scene", "sensor": sensor(64),
                 "integrator": {"type": "path", "max_depth": 1}}
            for name, value in converted.scene.items():
                if name.startswith("object"):
                    shape = {k: v for k, v in value.items() if k not in ("bsdf", "interior", "exterior")}
                    shape["bsdf"] = {"type": "diffuse", "reflectance": 0.0}
                    d[name] = shape
            if emitter is not None:
                d["environment"] = emitter
            return d

        one = {"type": "constant", "radiance": 1.0}
        uncovered = np.array(mi.render(mi.load_dict(black_scene(one)), seed=0), dtype=np.float64)
        uncovered = np.clip(uncovered[:, :, :1], 0.0, 1.0)
        environment_seen = 0.0
        if converted.environment is not None:
            environment_seen = np.array(
                mi.render(mi.load_dict(black_scene(converted.environment)), seed=0),
                dtype=np.float64)[:, :, :3]
        sky = np.array(converted.sky, dtype=np.float64)
        correction = uncovered * sky - environment_seen
        renders = [r + correction for r in renders]
        truth = sum(renders) / len(renders)

        args.out.parent.mkdir(parents=True, exist_ok=True)
        images.write_exr(args.out, truth)
        # The committed file is half floats: how far its rounding moves the object's pixels.
        object_pixels = uncovered[:, :, 0] == 0.0
        written = images.read_exr(args.out)
        rounding = float(np.abs(written - truth)[object_pixels].sum()
                         / max(np.abs(truth[object_pixels]).sum(), 1e-30))
        coverage_path = args.out.with_suffix(".coverage.exr")
        images.write_exr(coverage_path, np.repeat(1.0 - uncovered, 3, axis=2))

        summary = {
            # The scene relative to tools/truth (what measure.py and the tests resolve).
            "scene": os.path.relpath(args.scene.resolve(), Path(__file__).resolve().parent),
            "size": [width, height], "spp_per_seed": args.spp,
            "sss_texturing": args.sss_texturing,
            "seeds": [args.seed + k for k in range(args.seeds)],
            "spp_total": args.spp * args.seeds, "seconds": [round(s, 2) for s in seconds],
            "variant": variant, "integrator": integrator_name,
            "per_channel": bool(channel_scenes), "exr": "RGB half float, PIZ (lossless)",
            "half_rounding": round(rounding, 6), "notes": converted.notes,
        }
        if args.seeds >= 2:
            mask = images.erode(uncovered[:, :, 0] == 0.0, 1)
            blocks, pixels, count = images.two_seed_noise(renders[0], renders[1], mask)
            summary.update(noise_4x4=round(blocks, 5), noise_per_pixel=round(pixels, 5),
                           noise_blocks=count)
            print(f"truth: noise (half the relative difference of two seeds, 4x4 block means "
                  f"over {count} object blocks): {blocks:.4f}; per pixel {pixels:.4f}",
                  file=sys.stderr)
        args.out.with_suffix(".json").write_text(json.dumps(summary, indent=1) + "\n")
        print(f"wrote {args.out} ({width}x{height}, {args.spp} spp x {args.seeds} seeds, "
              f"{sum(seconds):.1f} s, {variant}, {integrator_name}) and {coverage_path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
