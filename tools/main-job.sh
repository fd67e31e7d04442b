#!/usr/bin/env bash
# The main job (README, command (a)): what lucent is for, on whatever this machine has.
# - With a display ($DISPLAY or $WAYLAND_DISPLAY set): the interactive demo on `showcase-skin`
#   (a sculpted head, d'Eon's skin profile, ears glowing from a back light; the panel picks
#   scenes and techniques and shows each pass's GPU time, `C` splits the view against plain
#   lighting).
# - Without one: the headless benchmark of the built-in `mixed` scene (every technique in one
#   frame: GDC 2011 translucency, skin and marble SSS, translucency and SSS on one object,
#   shadows), each pass against its speed-of-light floor, timed in-frame and alone. It prints the
#   table and writes it to bench.md, the numbers to bench.json and the frame to mixed.png.
#   About 15 s of benchmark on lavapipe with 2 cores, after the build.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ -n "${DISPLAY:-}" || -n "${WAYLAND_DISPLAY:-}" ]]; then
    exec cargo run -- demo --scene showcase-skin --size 1024x768
fi
cargo run -- bench --scene mixed --size 1024x768 --frames 30 --isolate --speed-of-light \
    --json bench.json --out mixed.png | tee bench.md
