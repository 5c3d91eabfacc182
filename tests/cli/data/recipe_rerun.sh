#!/bin/sh
# frac rerun FILE.png makes the same files again, byte for byte, from the
# recipe in the PNG: same script text, -D params, args, seed (tests/cli/recipe_rerun.cli).
set -e
T=$1
frac -q --seed 5 -o "$T/a" tests/cli/data/recipe_scene.frac -D size=8 -D 'label=x\y
z' one -- -two > "$T/a.out"
frac -q rerun "$T/a/g.png" -o "$T/b" > "$T/b.out"
n=0
for f in "$T"/a/*; do
    cmp "$f" "$T/b/${f##*/}"
    n=$((n + 1))
done
echo "$n files identical"
cmp "$T/a.out" "$T/b.out" && cat "$T/b.out"
# a rerun of the rerun is the same again (the recipe it writes is the original's)
frac -q rerun "$T/b/g.png" -o "$T/c" > /dev/null
cmp "$T/a/g.png" "$T/c/g.png" && echo "rerun of a rerun identical"
# a PLY carries the recipe's header only: no script text to rerun
frac rerun "$T/a/m.ply" 2>&1 | sed -n 1p
