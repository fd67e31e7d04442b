#!/usr/bin/env bash
# The main job (README, command (a)): the interactive demo when a display is present ($DISPLAY or
# $WAYLAND_DISPLAY set), otherwise the headless benchmark of the built-in `smoke` scene.
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ -n "${DISPLAY:-}" || -n "${WAYLAND_DISPLAY:-}" ]]; then
    exec cargo run -- demo --scene cubes --size 1024x768
fi
exec cargo run -- bench --scene smoke --size 1024x768 --frames 30 --isolate --json bench.json --out smoke.png
