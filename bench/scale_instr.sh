#!/bin/sh
# bench/scale_instr.sh [FRAC] [N] [POINTS] — the cost of sharding in
# instructions (valgrind's callgrind), which the load of a shared machine
# does not change: one single-threaded run of bench/scale.frac against the
# sum over N single-threaded shards plus the merge (outputs compared with
# cmp). Instructions leave out what the kernel does (starting a process,
# page faults, writing and fsyncing the part): bench/scale.sh measures that
# too, in CPU time. The tone map and PNG encoding, which the single run and
# the merge both do, are reported too, and the ratio without them. Slow (callgrind runs ~50× slower): by hand, not in
# make bench; at 10^8 points it takes ~10 minutes on the shared machine.
set -eu
frac=${1:-build/frac}
n=${2:-4}
points=${3:-1e7}
here=$(dirname "$0")
command -v valgrind >/dev/null 2>&1 || { echo "scale_instr: skipped (valgrind is not installed)"; exit 0; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-scale-instr-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
ir() { # command…: prints the instructions it executed
    valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.out" "$@" 2>&1 >/dev/null | sed -n 's/.*refs: *//p' | tr -d ,
}
# T: the instructions of the tone map and the PNG encoding (inclusive:
# tonemap_apply and png_encode), which the single run and the merge both do
fin() {
    command -v callgrind_annotate >/dev/null 2>&1 || return 0
    callgrind_annotate --inclusive=yes "$tmp/cg.out" 2>/dev/null | tr -d , |
        awk '$0 !~ /=>/ && ($0 ~ /:png_encode \[/ || $0 ~ /:tonemap_apply \[/) { t += $1 } END { print t + 0 }'
}
single=$(ir "$frac" -q --threads 1 -D points="$points" -o "$tmp/single" "$here/scale.frac")
t_single=$(fin)
total=0
i=0
while [ "$i" -lt "$n" ]; do
    t=$(ir "$frac" run -q --threads 1 --shard "$i/$n" -D points="$points" -o "$tmp/p" "$here/scale.frac")
    total=$((total + t))
    i=$((i + 1))
done
merge=$(ir "$frac" merge -q --threads 1 -D points="$points" -o "$tmp/m" "$here/scale.frac" "$tmp"/p/*.part)
t_merge=$(fin)
cmp "$tmp/single/fern.png" "$tmp/m/fern.png"
echo "points $points: single run $single instructions; $n shards $total; merge $merge"
awk -v s="$single" -v t="$total" -v m="$merge" -v ts="${t_single:-}" -v tm="${t_merge:-}" 'BEGIN {
    printf "overhead: (shards + merge) / single = %.3f in instructions\n", (t + m) / s
    if (ts != "" && tm != "" && ts > 0)
        printf "tone map + PNG: single run %d, merge %d; without them: (shards + merge - %d) / (single - %d) = %.3f\n",
            ts, tm, tm, ts, (t + m - tm) / (s - ts) }'
