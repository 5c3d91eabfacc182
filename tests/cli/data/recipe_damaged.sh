#!/bin/sh
# frac info of damaged recipes: each is refused with the line and the
# reason, exit 65 (tests/cli/recipe_damaged.cli). The recipes sit in the
# comment lines of a 1x1 PGM, as frac writes them.
T=$1
n=0
try() { # the header lines after `frac-recipe 1`, one argument each
    n=$((n + 1))
    f="$T/r$n.pgm"
    { printf 'P5\n# frac-recipe 1\n'; for l in "$@"; do printf '# %s\n' "$l"; done; printf '1 1\n255\n\0'; } > "$f"
    rc=0
    frac info "$f" > "$T/info.out" 2>&1 || rc=$?
    sed "s|$T/||" "$T/info.out"
    echo "exit $rc"
}
H="version: 0.1.0"
P="script-path: a.frac"
try "$H" "$P" "seed: 1" "frame: 2" "apng-output: a.png" "apng-delay: 40" "apng-loop: 0" "apng-frame: 2 f.png" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "apng-frame: 2 f.png" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "apng-output: a.png" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "apng-output: d/a.png" "apng-frame: none f.png" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "apng-output: a.png" "apng-delay: 70000" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "apng-output: a.png" "apng-frame: x f.png" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none" "colour: red" "script: omitted"
try "$H" "$P" "seed: -1" "frame: none" "script: omitted"
try "$H" "$P" "seed: 1" "frame: none"
try "$H" "$P" "seed: 1" "frames: 1..3:1" "frame: 2" "script: omitted"
try "$H" "$P" "$P" "seed: 1" "frame: none" "script: omitted"
