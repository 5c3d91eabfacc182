#!/bin/sh
# fit.sh — merge takes the fitted window from the parts and runs no window
# pre-pass of its own; every shard runs it (each needs the window to bin its
# points). Counts the instructions executed inside chaos_fit (callgrind
# with --toggle-collect) for the single run, each of the 3 shards and the
# merge of tests/shard/small.frac (tests/cli/shard_fit.cli). Prints
# "fit: ok …" and exits 0, or says what is wrong and exits 1; "fit: skipped
# (…)" without valgrind.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
if ! command -v valgrind >/dev/null 2>&1; then
    echo "fit: skipped (valgrind is not installed to count the pre-pass's instructions)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-fit-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fit() { # OUT-NAME ARGS…: the instructions executed in chaos_fit by frac ARGS… into $tmp/OUT-NAME
    out=$1
    shift
    if ! valgrind -q --tool=callgrind --callgrind-out-file="$tmp/cg" --toggle-collect=chaos_fit "$frac" -q --threads 1 "$@" \
        >/dev/null 2>"$tmp/err"; then
        echo "fit: frac $* failed: $(head -n 1 "$tmp/err")"
        exit 1
    fi
    sed -n 's/^summary: //p' "$tmp/cg" >"$tmp/n.$out"
}
fit single -o "$tmp/single" "$s"
for i in 0 1 2; do
    fit shard$i run --shard $i/3 -o "$tmp/p" "$s"
done
fit merge merge -o "$tmp/m" "$s" "$tmp"/p/small.shard-*-of-3.part
single=$(cat "$tmp/n.single")
shards="$(cat "$tmp/n.shard0") $(cat "$tmp/n.shard1") $(cat "$tmp/n.shard2")"
merge=$(cat "$tmp/n.merge")
cmp -s "$tmp/m/a.png" "$tmp/single/a.png" || { echo "fit: the merged a.png differs from the single run's"; exit 1; }
[ "$(echo $single $shards $merge | wc -w)" = 5 ] || { echo "fit: no count from callgrind"; exit 1; }
for n in $single $shards; do
    [ "$n" -gt 0 ] || { echo "fit: a run without the pre-pass: single $single, shards $shards"; exit 1; }
done
[ "$merge" = 0 ] || { echo "fit: the merge ran the pre-pass ($merge instructions in chaos_fit)"; exit 1; }
echo "fit: ok: instructions in chaos_fit: single run $single, shards $shards, merge $merge"
