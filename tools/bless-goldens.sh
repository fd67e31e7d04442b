#!/usr/bin/env bash
# Regenerates golden images on purpose: golden tests never create or update them.
#
#   tools/bless-goldens.sh          # every golden in tests/golden/LIST
#   tools/bless-goldens.sh NAME     # only NAME
#
# Each line of tests/golden/LIST is `NAME ARGS...`; this runs
# `cargo run -- ARGS --validation --out tests/golden/NAME.png` (a debug build: the GPU does the
# rendering, so the image is the same as a release build's). Look at the new images (and at the
# `git diff`) before committing them. Blank lines and lines starting with # are ignored.
set -euo pipefail
cd "$(dirname "$0")/.."

list=tests/golden/LIST
only=${1:-}
if (($# > 1)); then
    echo "usage: $0 [NAME]" >&2
    exit 2
fi

found=0
while read -r name args; do
    [[ -z "$name" || "$name" == \#* ]] && continue
    [[ -n "$only" && "$name" != "$only" ]] && continue
    found=$((found + 1))
    out="tests/golden/$name.png"
    # ARGS are split on whitespace on purpose: LIST holds plain command-line words.
    # shellcheck disable=SC2086
    cargo run --quiet -- $args --validation --out "$out" </dev/null
    echo "bless-goldens: wrote $out ($args)"
done <"$list"

if ((found == 0)); then
    if [[ -n "$only" ]]; then
        echo "bless-goldens: no golden named '$only' in $list" >&2
    else
        echo "bless-goldens: $list lists no goldens" >&2
    fi
    exit 1
fi
