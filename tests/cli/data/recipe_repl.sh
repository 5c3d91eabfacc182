#!/bin/sh
# A file saved in the REPL carries the session so far as its script: the
# entries that ran without error, then the saving one; frac rerun of it
# gives the same bytes (tests/cli/recipe_repl.cli).
set -e
T=$1
printf '%s\n' 'import "ifs"' 'let n = 2e4' 'nope()' 'let img = chaos(sierpinski, points: n, size: 24)' \
    'save(img, "a.png")' 'let later = 1' ':reset' 'let g = image([2, 2], [0.5, 0.5, 0.5])' 'save(g, "b.png")' \
    | frac repl -o "$T/r" > /dev/null 2>&1 || echo "repl exit $? (one entry failed)"
frac info "$T/r/a.png" | sed -n '/^script-path/p;/^script:/,$p'
frac -q rerun "$T/r/a.png" -o "$T/s"
cmp "$T/r/a.png" "$T/s/a.png" && echo "a.png identical"
frac info "$T/r/b.png" | sed -n '/^script:/,$p'
frac -q rerun "$T/r/b.png" -o "$T/s"
cmp "$T/r/b.png" "$T/s/b.png" && echo "b.png identical"
