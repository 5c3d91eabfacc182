#!/bin/sh
# frac rerun runs the embedded script under its original path, so its
# relative imports and loads resolve against the original script's folder:
# they work while that folder has them, and fail with the usual error when
# not (tests/cli/recipe_imports.cli).
set -e
T=$1
mkdir -p "$T/proj"
cat > "$T/proj/colours.frac" <<'END'
let warm = [1, 0.5, 0]
END
cat > "$T/proj/main.frac" <<'END'
import "./colours.frac" as c
let g = gradient([8, 4], from: c.warm, to: [0, 0, 1])
save(g, "g.png")
save(load("tex.png") * 0.5, "half.png")
END
cd "$T"   # run from elsewhere than the script's folder
frac -q -o proj -e 'save(gradient([4, 4], from: 0, to: 1), "tex.png")' > /dev/null
frac -q -o out proj/main.frac
frac -q rerun out/g.png -o again
cmp out/g.png again/g.png && cmp out/half.png again/half.png && echo "identical with the import present"
# the script's own text is embedded: changing the file on disk changes nothing
echo "# edited" >> proj/main.frac
frac -q rerun out/g.png -o again2
cmp out/g.png again2/g.png && echo "identical after the script was edited"
rm proj/colours.frac
frac -q rerun out/g.png -o again3 2>&1 | sed -n 1p || true
