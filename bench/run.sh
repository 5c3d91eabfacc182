#!/usr/bin/env bash
# Run every benchmark: the interpreter script and each build/bench/* program.
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
bash bench/interp.sh "$build/frac"
bash bench/interp_bench.sh "$build/frac"
for b in "$build"/bench/*; do
    [ -x "$b" ] || continue
    echo "== $(basename "$b")"
    "$b"
done
