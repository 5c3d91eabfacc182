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
. "$here/recipe.sh"
fail() { echo "frames recipe: FAIL ($*)"; exit 1; }
recipe_setup frames-recipe
sed 's/^param n = 2e5$/param n = 2e4/' "$here/frames.frac" >anim.frac || exit 1
grep -q '^param n = 2e4$' anim.frac || fail "tests/shard/frames.frac has no 'param n = 2e5'"
recipe_block "tests/shard/frames_recipe.sh runs this block" >recipe.sh
grep -q '^frac merge --frames ' recipe.sh || fail "no --frames block in docs/scale.md"
frac -q --frames 0..47 -o single anim.frac >single.out || exit 1
sh -e recipe.sh </dev/null >recipe.out 2>&1 || fail "the block: $(tail -n 3 recipe.out)"
[ "$(ls parts | wc -l)" -eq 144 ] || fail "$(ls parts | wc -l) parts, not 3 shards of 48 frames"
why=$(recipe_same single out) || fail "$why"
# the merge prints what the single run prints (the block's shards are quiet)
grep '^frame ' recipe.out | cmp -s - single.out || fail "the merge printed other lines"
echo "frames recipe: ok, 3 shards of 48 frames, $(ls out | wc -l) files as the single run"
