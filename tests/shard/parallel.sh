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
if ! command -v parallel >/dev/null 2>&1 ||
    ! parallel --version 2>/dev/null </dev/null | grep '^GNU parallel' >/dev/null; then
    echo "parallel: skipped (GNU parallel is not installed; Debian: apt-get install parallel)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-parallel-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "parallel: FAIL ($*)"; exit 1; }
# the recipe calls `frac`: the one under test, first on PATH
bin=$(mktemp -d "$tmp/bin-XXXXXX") && ln -s "$(command -v "$frac")" "$bin/frac" || exit 1
PATH=$bin:$PATH
# GNU parallel keeps its state in ~/.parallel: a fresh home, not the user's
HOME=$tmp/home
export PATH HOME
mkdir "$HOME" && cp "$here/small.frac" "$tmp/scene.frac" && cd "$tmp" || exit 1
frac -q -o single scene.frac || exit 1
# the recipe: the sh block after the marker naming this file in docs/scale.md
awk '/tests\/shard\/parallel.sh runs this block/ { on = 1; next } on && /^```sh/ { inb = 1; next }
     inb && /^```/ { exit } inb { print }' "$here/../../docs/scale.md" >recipe.sh
grep -q '^parallel ' recipe.sh || fail "no GNU parallel recipe in docs/scale.md"
n=$(sed -n 's/^N=\([0-9][0-9]*\)$/\1/p' recipe.sh)
[ -n "$n" ] || fail "the recipe sets no N"
sh -e recipe.sh </dev/null >recipe.out 2>&1 || fail "the recipe: $(tail -n 3 recipe.out)"
# one part a shard, of N, and nothing else
i=0
while [ "$i" -lt "$n" ]; do
    [ -f "parts/scene.shard-$i-of-$n.part" ] || fail "no part of shard $i of $n"
    i=$((i + 1))
done
[ "$(ls parts | wc -l)" -eq "$n" ] || fail "parts/ holds $(ls parts | tr '\n' ' ')"
[ "$(ls single)" = "$(ls out)" ] || fail "out/ holds $(ls out | tr '\n' ' '), the single run $(ls single | tr '\n' ' ')"
for f in $(ls single); do
    cmp -s "single/$f" "out/$f" || fail "$f differs"
done
echo "parallel: ok N=$n, the recipe of docs/scale.md, $(ls out | wc -l) files as the single run"
