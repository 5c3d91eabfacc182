#!/bin/sh
# How many report lines each form prints when stderr is not a terminal
# (tests/cli/report_lines.cli): none without --stats, exactly one with it.
S=tests/cli/data/report_scene.frac
for opts in "" "--quiet" "--stats" "--stats --quiet"; do
    n=$(frac $opts $S 2>&1 >/dev/null | grep -c "^frac: done in ")
    all=$(frac $opts $S 2>&1 >/dev/null | wc -l)
    echo "[$opts] report lines: $n, stderr lines: $all"
done
