#!/usr/bin/env bash
# The fail-N-th-allocation loop over every language test and example, outside
# `make test` (tests/README.md, "Allocation failure"). For each script: one
# run counts its allocations (`--fail-alloc` past the end says how many),
# then the runner's loop (`runner --fail-alloc SCRIPT`) fails allocation
# 1, 2, … with a stride that keeps it to about MAXRUNS runs (every N up to
# 64 always; FA_HEAD=H in the environment changes that, e.g. FA_HEAD=0 for
# an ASan scan of small scripts, whose first allocations are the start-up
# every script shares). One line per script: count, stride, ok or FAIL.
#
#   tools/failalloc_scan.sh [FRAC [RUNNER [MAXRUNS [SCRIPT…]]]]
#
# FRAC defaults to build/frac (give build-asan/frac to catch leaks on the
# failure paths), RUNNER to build/runner, MAXRUNS to 2000; the scripts to
# tests/lang/**/*.frac (not _helpers) and examples/*.frac. The runner's
# report of a failing script goes to stdout after its FAIL line.
set -u
cd "$(dirname "$0")/.."
frac=${1:-build/frac}
runner=${2:-build/runner}
maxruns=${3:-2000}
shift $(($# < 3 ? $# : 3))
if [ $# -gt 0 ]; then
    scripts=("$@")
else
    mapfile -t scripts < <(find tests/lang -name '*.frac' ! -name '_*' | sort; ls examples/*.frac)
fi
tmp=$(mktemp -d /tmp/frac-fascan-XXXXXX)
trap 'rm -rf "$tmp"' EXIT
bad=0
for f in "${scripts[@]}"; do
    # the script's own "# args:" and "# stdin:" lines, as the runner reads them
    args=$(grep -h '# args: ' "$f" | head -1 | sed 's/.*# args: //')
    grep -h '# stdin: ' "$f" | sed 's/.*# stdin: //' > "$tmp/stdin"
    # shellcheck disable=SC2086
    count=$("$frac" --quiet --fail-alloc 2000000000 -o "$tmp" $args "$f" < "$tmp/stdin" 2>&1 >/dev/null |
        sed -n 's/.*the run made \([0-9]*\) allocations.*/\1/p')
    count=${count:-0}
    stride=$(((count - ${FA_HEAD:-64}) / maxruns + 1))
    [ "$stride" -lt 1 ] && stride=1
    if FA_STRIDE=$stride "$runner" --frac "$frac" --fail-alloc "$f" > "$tmp/out" 2>&1; then
        echo "$f $count $stride ok"
    else
        echo "$f $count $stride FAIL"
        cat "$tmp/out"
        bad=1
    fi
done
exit $bad
