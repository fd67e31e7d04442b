#!/usr/bin/env bash
# tools/truth/setup.sh: the truth renderer's own environment, idempotent and quiet on success.
#
#   tools/truth/setup.sh            # creates tools/truth/.venv, installs requirements.txt
#
# - A virtual environment at tools/truth/.venv with the pinned Mitsuba 3 and numpy.
# - LLVM 19 for Mitsuba's vectorised `llvm_ad_rgb` variant: Debian's libllvm15 crashes it
#   ("Cannot select fminimum"), LLVM 14 is refused, libllvm19 works (../../shared/truth-notes.md).
#   Installed with apt-get when running as root and the package is available; otherwise
#   truth.py falls back to `scalar_rgb` (one ray at a time, several times slower) and says so.
#   truth.py finds the library itself (DRJIT_LIBLLVM_PATH is set for you when it exists).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
llvm=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1

if [ ! -e "$llvm" ]; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null \
        && [[ "$(apt-cache policy libllvm19 2>/dev/null)" == *"Candidate: "[0-9]* ]]; then
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19 >/dev/null 2>&1 \
            || echo "setup.sh: apt-get install libllvm19 failed; truth.py will use scalar_rgb" >&2
    else
        echo "setup.sh: libllvm19 not installed (needs root and Debian's package);" \
             "truth.py will use the slower scalar_rgb variant" >&2
    fi
fi

if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
# pip is quiet when everything is already installed at the pinned versions.
"$venv/bin/python" -m pip install -q -r "$here/requirements.txt"
# A last check that the pinned Mitsuba imports.
"$venv/bin/python" -c "import mitsuba, numpy" \
    || { echo "setup.sh: mitsuba does not import from $venv" >&2; exit 1; }
