#!/bin/sh
# frac rerun of one frame of --frames -2..10:4 makes the same file: the
# recipe carries the frame and its range, so clock and %f come back
# (tests/cli/recipe_rerun_frame.cli).
set -e
T=$1
frac -q --frames -2..10:4 -o "$T/a" tests/cli/data/recipe_frames.frac > "$T/a.out"
cat "$T/a.out"
frac -q rerun "$T/a/f02.png" -o "$T/b"
cmp "$T/a/f02.png" "$T/b/f02.png" && echo "frame 2 identical"
frac info "$T/a/f02.png" | grep '^frame'
ls "$T/b"
