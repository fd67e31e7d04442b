#!/usr/bin/env bash
# tools/truth/validate.sh: the three validation scenes (README "Validation"): renders each truth
# (unless TRUTHS=committed, which compares against tools/truth/truths/), lucent's frames at the
# same size, and prints compare.py's error and energy.
#
#   LUCENT=target/release/lucent tools/truth/validate.sh [OUT_DIR]
#
# SIZE (256x192), SPP (256 per seed, the slab 1024) and NICE (19) are read from the environment.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="${1:-$here/out}"
lucent="${LUCENT:-$here/../../target/release/lucent}"
size="${SIZE:-256x192}"
nice="nice -n ${NICE:-19}"
py="$here/.venv/bin/python"
mkdir -p "$out"
for scene in diffuse-sphere skin1-slab-backlit marble-sphere-sidelit; do
    truth="$out/$scene.exr"
    if [ "${TRUTHS:-}" = committed ]; then
        truth="$here/truths/$scene.exr"
    else
        spp="${SPP:-256}"
        [ "$scene" = skin1-slab-backlit ] && spp="${SPP:-1024}"
        $nice "$py" "$here/truth.py" "$here/scenes/$scene.toml" --out "$truth" --size "$size" \
            --spp "$spp" --seeds 2 2>&1 | grep -E "noise|wrote|refused" || true
    fi
    techniques="none auto"
    [ "$scene" = diffuse-sphere ] && techniques="none"
    for technique in $techniques; do
        frame="$out/$scene.lucent-$technique.exr"
        $nice "$lucent" render --scene "$here/scenes/$scene.toml" --size "$size" \
            --technique "$technique" --exr "$frame" --out "${frame%.exr}.png" >/dev/null
        printf '%-24s lucent --technique %-5s ' "$scene" "$technique"
        "$py" "$here/compare.py" "$frame" "$truth" --mask "${truth%.exr}.coverage.exr"
    done
done
