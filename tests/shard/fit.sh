#!/bin/sh
# fit.sh — merge takes the fitted windows from the parts and runs no window
# pre-pass of its own; every shard runs it (each needs the window to bin its
# points). Counts the instructions executed inside the pre-pass (callgrind
# with --toggle-collect) for the single run, each of 3 shards and the merge:
# chaos_fit in tests/shard/small.frac (chaos) and fset_chaos_fit in
# tests/shard/fit_fset.frac (chaos_fset) (tests/cli/shard_fit.cli). Prints
# "fit: ok …" per script and exits 0, or says what is wrong and exits 1;
# "fit: skipped (…)" without valgrind or for an ASan build.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
if ! command -v valgrind >/dev/null 2>&1; then
    echo "fit: skipped (valgrind is not installed to count the pre-pass's instructions)"
    exit 0
fi
if nm "$(command -v "$frac")" 2>/dev/null | grep -q __asan_init; then
    echo "fit: skipped (an AddressSanitizer build, which valgrind cannot run)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-fit-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fit() { # OUT-NAME FUNCTION ARGS…: the instructions executed in FUNCTION by frac ARGS… into $tmp/n.OUT-NAME
    out=$1
    fn=$2
    shift 2
    if ! valgrind -q --tool=callgrind --callgrind-out-file="$tmp/cg" --toggle-collect="$fn" "$frac" -q --threads 1 "$@" \
        >/dev/null 2>"$tmp/err"; then
        echo "fit: frac $* failed: $(head -n 1 "$tmp/err")"
        exit 1
    fi
    sed -n 's/^summary: //p' "$tmp/cg" >"$tmp/n.$out"
}
check() { # SCRIPT FUNCTION OUTPUT
    s=$here/$1
    fn=$2
    rm -rf "$tmp/single" "$tmp/p" "$tmp/m"
    fit single "$fn" -o "$tmp/single" "$s"
    for i in 0 1 2; do
        fit shard$i "$fn" run --shard $i/3 -o "$tmp/p" "$s"
    done
    fit merge "$fn" merge -o "$tmp/m" "$s" "$tmp"/p/*.part
    single=$(cat "$tmp/n.single")
    shards="$(cat "$tmp/n.shard0") $(cat "$tmp/n.shard1") $(cat "$tmp/n.shard2")"
    merge=$(cat "$tmp/n.merge")
    cmp -s "$tmp/m/$3" "$tmp/single/$3" || { echo "fit: the merged $3 differs from the single run's"; exit 1; }
    [ "$(echo $single $shards $merge | wc -w)" = 5 ] || { echo "fit: no count from callgrind"; exit 1; }
    for n in $single $shards; do
        [ "$n" -gt 0 ] || { echo "fit: $1: a run without the pre-pass: single $single, shards $shards"; exit 1; }
    done
    [ "$merge" = 0 ] || { echo "fit: $1: the merge ran the pre-pass ($merge instructions in $fn)"; exit 1; }
    echo "fit: ok $1: instructions in $fn: single run $single, shards $shards, merge $merge"
}
check small.frac chaos_fit a.png
check fit_fset.frac fset_chaos_fit flat.png
