#!/bin/sh
# frac info prints the recipe of every format with a comment field; the
# script hash is the one sha256sum gives (tests/cli/recipe_info.cli).
set -e
T=$1
S=tests/cli/data/recipe_scene.frac
frac -q --seed 7 -o "$T" $S -D size=8 arg1 > /dev/null
frac info "$T/g.png" > "$T/png.txt"
sed -n '1,9p' "$T/png.txt" | grep -v sha256
sum=$(sha256sum < $S | cut -c1-64)
grep -qx "script-sha256: $sum" "$T/png.txt" && echo "script-sha256 is sha256sum's"
# the PNG's recipe ends with the script text itself
tail -n +11 "$T/png.txt" | cmp - $S && echo "script text is the script"
sed -n '1,9p' "$T/png.txt" > "$T/head.txt"
for f in g.ppm g.pgm m.ply m.obj v.nrrd t.svg t.flame; do
    frac info "$T/$f" > "$T/$f.txt"
    sed -n '1,9p' "$T/$f.txt" | cmp - "$T/head.txt"
    echo "$f: same header; $(sed -n 10p "$T/$f.txt")"
done
for f in v.vtk m.stl; do
    echo "$f: $(frac info "$T/$f" | sed -n 1p | sed "s/$sum/SUM/; s/sha256=$(echo $sum | cut -c1-40)[0-9a-f]*$/sha256=PREFIX/")"
done
if command -v xmllint > /dev/null; then
    xmllint --noout "$T/t.svg" "$T/t.flame" && echo "xmllint: ok"
else
    echo "xmllint: ok (skipped: xmllint is not installed)"
fi
if command -v pngcheck > /dev/null; then
    pngcheck -q "$T/g.png" && echo "pngcheck: ok"
else
    echo "pngcheck: ok (skipped: pngcheck is not installed)"
fi
