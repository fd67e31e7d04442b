#!/usr/bin/env bash
# Writes `lucent plan` of every built-in scene under every technique into DIR (one file per
# pair, stdout then stderr, then the exit code), so two builds can be compared with `diff -r`:
#   tools/plan-identity.sh path/to/old/lucent old-plans
#   tools/plan-identity.sh target/debug/lucent new-plans && diff -r old-plans new-plans
# The scenes come from `lucent scenes`, the techniques from the error `lucent plan` gives for
# an unknown one (it lists every registered name), so neither list is written here.
set -euo pipefail
lucent=$1
out=$2
mkdir -p "$out"
scenes=$("$lucent" scenes | awk '{print $1}')
techniques=$( ("$lucent" plan --scene smoke --technique '?' 2>&1 || true) |
    sed -n 's/.*available: //p' | tr -d ',')
for scene in $scenes; do
    for technique in $techniques; do
        file="$out/$scene.$technique.txt"
        set +e
        "$lucent" plan --scene "$scene" --technique "$technique" >"$file" 2>&1
        echo "exit $?" >>"$file"
        set -e
    done
done
echo "$(ls "$out" | wc -l) plans in $out"
