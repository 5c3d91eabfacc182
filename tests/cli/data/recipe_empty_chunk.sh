#!/bin/sh
# frac info of a PNG whose frac:recipe chunk is empty (tests/cli/recipe_empty_chunk.cli).
T=$1
python3 tests/cli/data/recipe_empty_chunk.py "$T/empty.png" || exit 1
rc=0
frac info "$T/empty.png" 2> "$T/err" || rc=$?
sed "s|$T/||" "$T/err"
echo "exit $rc"
