#!/bin/sh
# frac rerun of an APNG that frac apng assembled from --frames frames gives
# the same file byte for byte (tests/cli/recipe_rerun_apng.cli).
set -e
T=$1
D=tests/cli/data
# 1. a subset of frames 1..10, out of order, with options: %f is 2 wide
frac -q --frames 1..10 -o "$T/a" $D/recipe_rerun_apng.frac
frac -q apng -o "$T/a/anim.png" --delay 50 --loop 2 "$T/a/f_03.png" "$T/a/f_01.png" "$T/a/f_10.png"
frac info "$T/a/anim.png" | grep '^apng' | sed "s|$T|TMP|g"
frac -q rerun "$T/a/anim.png" -o "$T/b"
cmp "$T/a/anim.png" "$T/b/anim.png" && echo "subset identical"
ls "$T/b"
# a rerun of the rerun
frac -q rerun "$T/b/anim.png" -o "$T/c"
cmp "$T/a/anim.png" "$T/c/anim.png" && echo "rerun of rerun identical"
# 2. a script that reads clock: the range comes back with each frame
frac -q --frames -2..10:4 -o "$T/k" $D/recipe_frames.frac > /dev/null
frac -q apng -o "$T/k/clock.png" "$T/k/f-02.png" "$T/k/f02.png" "$T/k/f06.png" "$T/k/f10.png"
frac -q rerun "$T/k/clock.png" -o "$T/l" > /dev/null
cmp "$T/k/clock.png" "$T/l/clock.png" && echo "clock identical"
# 3. frames of two different runs: no common recipe, said once
frac -q --seed 2 --frames 1..1 -o "$T/s" $D/recipe_rerun_apng.frac
frac apng -o "$T/mixed.png" "$T/a/f_01.png" "$T/s/f_1.png" 2>&1 | sed "s|$T|TMP|g"
rc=0
frac info "$T/mixed.png" > "$T/info.out" 2>&1 || rc=$?
sed "s|$T|TMP|g" "$T/info.out"
echo "info exit $rc"
# 4. renamed frames of a script that writes two PNGs per frame: no match
frac -q --frames 1..2 -o "$T/r" $D/recipe_rerun_apng2.frac
cp "$T/r/a_1.png" "$T/r/one.png"
cp "$T/r/a_2.png" "$T/r/two.png"
frac -q apng -o "$T/r/renamed.png" "$T/r/one.png" "$T/r/two.png"
rc=0
frac -q rerun "$T/r/renamed.png" -o "$T/q" 2> "$T/err.out" || rc=$?
sed "s|$T|TMP|g" "$T/err.out"
echo "rerun exit $rc"
ls "$T/q"
