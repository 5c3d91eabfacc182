#!/bin/sh
# frames.sh — `frac run --frames A..B --shard I/N` then `frac merge --frames
# A..B` equals `frac run --frames A..B` byte for byte, for N = 1, 2, 3 and 7 over
# the 3 frames -1..3:2 of tests/shard/frames.frac (clock -> 0, 0.5, 1), the
# shards run concurrently (tests/cli/shard_frames.cli). Prints the parts of
# N = 3 and "ok frames N=1,2,3,7", or what differs; exits non-zero on a failure.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/frames.frac
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-frames-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL frames: $*"; exit 1; }
r=-1..3:2
"$frac" run -q --frames $r -o "$tmp/single" "$s" >"$tmp/single.out" 2>"$tmp/err" || fail "single: $(cat "$tmp/err")"
for n in 1 2 3 7; do
    i=0
    pids=
    while [ "$i" -lt "$n" ]; do
        "$frac" run -q --threads 1 --frames $r --shard "$i/$n" -o "$tmp/p$n" "$s" >"$tmp/s$i.out" 2>"$tmp/s$i.err" &
        pids="$pids $!"
        i=$((i + 1))
    done
    for p in $pids; do
        wait "$p" || fail "a shard of N=$n failed: $(cat "$tmp"/s*.err)"
    done
    [ "$n" = 3 ] && ls "$tmp/p$n"
    "$frac" merge -q --frames $r -o "$tmp/m$n" "$s" "$tmp/p$n"/*.part >"$tmp/m$n.out" 2>"$tmp/err" ||
        fail "merge N=$n: $(cat "$tmp/err")"
    cmp -s "$tmp/single.out" "$tmp/m$n.out" || fail "merge N=$n: stdout differs"
    [ "$(ls "$tmp/single")" = "$(ls "$tmp/m$n")" ] || fail "merge N=$n: other files: $(ls "$tmp/m$n")"
    for f in $(ls "$tmp/single"); do
        cmp -s "$tmp/single/$f" "$tmp/m$n/$f" || fail "merge N=$n: $f differs"
    done
done
cmp -s "$tmp/single/a-1.png" "$tmp/single/a3.png" && fail "frames -1 and 3 are the same image"
cat "$tmp/single.out"
echo "ok frames N=1,2,3,7"
# a frame's parts given to another frame's merge, and a range that misses a part
"$frac" merge -q --frames 1..1 -o "$tmp/x" "$s" "$tmp/p2"/frames.f1.*.part 2>&1 | sed "s|$tmp|TMP|g"
"$frac" merge -q --frames -1..1:2 -o "$tmp/x" "$s" "$tmp/p2"/*.part 2>&1 | sed "s|$tmp|TMP|g"
"$frac" merge -q -o "$tmp/x" "$s" "$tmp/p2"/frames.f1.*.part 2>&1 | sed "s|$tmp|TMP|g"
