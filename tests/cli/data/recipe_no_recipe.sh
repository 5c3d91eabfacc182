#!/bin/sh
# --no-recipe leaves the script text out (hash, params and seed stay), and
# such a file cannot be rerun; nor can a file that holds only the header
# (tests/cli/recipe_no_recipe.cli).
T=$1
S=tests/cli/data/recipe_scene.frac
frac -q --no-recipe -o "$T" $S -D size=8 > /dev/null || exit 1
frac info "$T/g.png" | grep -v sha256
frac rerun "$T/g.png" -o "$T/b" 2>&1
echo "exit $?"
frac rerun "$T/m.ply" 2>&1 | sed -n 1p
frac rerun "$T/v.vtk" 2>&1 | sed "s/sha256=[0-9a-f]*/sha256=SUM/"
