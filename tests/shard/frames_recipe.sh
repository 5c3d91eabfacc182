#!/bin/sh
# frames_recipe.sh — the --frames block of docs/scale.md, read from it and
# run as written: three shards of 48 frames run concurrently, then one
# `frac merge --frames`, on tests/shard/frames.frac copied as anim.frac
# (with 2e4 points a frame: the block names no size); every file of out/
# must equal `frac run --frames 0..47`'s, byte for byte, and parts/ must
# hold a part a shard and frame (tests/cli/shard_frames_recipe.cli). Prints
# "frames recipe: ok …"; exits non-zero on a failure.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-frames-recipe-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "frames recipe: FAIL ($*)"; exit 1; }
# the block calls `frac`: the one under test, first on PATH
bin=$(mktemp -d "$tmp/bin-XXXXXX") && ln -s "$(command -v "$frac")" "$bin/frac" || exit 1
PATH=$bin:$PATH
export PATH
sed 's/^param n = 2e5$/param n = 2e4/' "$here/frames.frac" >"$tmp/anim.frac" && cd "$tmp" || exit 1
grep -q '^param n = 2e4$' anim.frac || fail "tests/shard/frames.frac has no 'param n = 2e5'"
awk '/tests\/shard\/frames_recipe.sh runs this block/ { on = 1; next } on && /^```sh/ { inb = 1; next }
     inb && /^```/ { exit } inb { print }' "$here/../../docs/scale.md" >recipe.sh
grep -q '^frac merge --frames ' recipe.sh || fail "no --frames block in docs/scale.md"
frac -q --frames 0..47 -o single anim.frac >single.out || exit 1
sh -e recipe.sh </dev/null >recipe.out 2>&1 || fail "the block: $(tail -n 3 recipe.out)"
[ "$(ls parts | wc -l)" -eq 144 ] || fail "$(ls parts | wc -l) parts, not 3 shards of 48 frames"
[ "$(ls single)" = "$(ls out)" ] || fail "out/ holds other files than the single run"
for f in $(ls single); do
    cmp -s "single/$f" "out/$f" || fail "$f differs"
done
# the merge prints what the single run prints (the block's shards are quiet)
grep '^frame ' recipe.out | cmp -s - single.out || fail "the merge printed other lines"
echo "frames recipe: ok, 3 shards of 48 frames, $(ls out | wc -l) files as the single run"
