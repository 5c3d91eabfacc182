#!/bin/sh
# parallel.sh — the GNU parallel recipe of docs/scale.md, read from it and run
# as written: its N shards of tests/shard/small.frac (copied as scene.frac)
# under `parallel -j $N frac run … --shard {}/$N`, then `frac merge`; every
# file of out/ must equal the single run's, byte for byte, and parts/ must
# hold the N parts (tests/cli/shard_parallel.cli). Prints "parallel: ok N=…",
# or "parallel: skipped (…)" when GNU parallel is not installed (moreutils'
# `parallel` takes other arguments: it is skipped too); exits non-zero on a
# failure.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
. "$here/recipe.sh"
if ! command -v parallel >/dev/null 2>&1 ||
    ! parallel --version 2>/dev/null </dev/null | grep '^GNU parallel' >/dev/null; then
    echo "parallel: skipped (GNU parallel is not installed; Debian: apt-get install parallel)"
    exit 0
fi
fail() { echo "parallel: FAIL ($*)"; exit 1; }
recipe_setup parallel
# GNU parallel keeps its state in ~/.parallel: a fresh home, not the user's
HOME=$tmp/home
export HOME
mkdir "$HOME" && cp "$here/small.frac" scene.frac || exit 1
frac -q -o single scene.frac || exit 1
recipe_block "tests/shard/parallel.sh runs this block" >recipe.sh
grep -q '^parallel ' recipe.sh || fail "no GNU parallel recipe in docs/scale.md"
n=$(sed -n 's/^N=\([0-9][0-9]*\)$/\1/p' recipe.sh)
[ -n "$n" ] || fail "the recipe sets no N"
sh -e recipe.sh </dev/null >recipe.out 2>&1 || fail "the recipe: $(tail -n 3 recipe.out)"
why=$(recipe_parts "$n") || fail "$why"
why=$(recipe_same single out) || fail "$why"
echo "parallel: ok N=$n, the recipe of docs/scale.md, $(ls out | wc -l) files as the single run"
