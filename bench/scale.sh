#!/bin/sh
# bench/scale.sh [FRAC] [N] [POINTS] — the cost of sharding (docs/scale.md):
# CPU time (user + system: perf stat's task-clock, or /usr/bin/time) of
# one single-threaded run of bench/scale.frac against the sum over N
# single-threaded shards plus the merge, the outputs compared with cmp,
# and the merge's time per MiB of parts.
# Run it once, not in a loop: the machine is shared.
set -eu
frac=${1:-build/frac}
n=${2:-4}
points=${3:-1e8}
here=$(dirname "$0")
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-scale-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
# CPU seconds of a command (user + system, every thread): perf stat's
# task-clock in ms where perf works, else /usr/bin/time (10 ms steps, which
# is ±20 ms over four shards of a 10^8 render).
if perf stat -x, -e task-clock -o "$tmp/t" true >/dev/null 2>&1 && grep -q task-clock "$tmp/t"; then
    clock="perf stat task-clock"
    cpu() {
        perf stat -x, -e task-clock -o "$tmp/t" "$@" >/dev/null 2>&1
        awk -F, '/task-clock/ { printf "%.3f", $1 / 1000 }' "$tmp/t"
    }
else
    clock="/usr/bin/time user + system"
    cpu() {
        /usr/bin/time -f "%U %S" -o "$tmp/t" "$@" >/dev/null 2>&1
        awk '{ printf "%.3f", $1 + $2 }' "$tmp/t"
    }
fi
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg); CPU time from $clock"
single=$(cpu "$frac" -q --threads 1 -D points="$points" -o "$tmp/single" "$here/scale.frac")
total=0
i=0
while [ "$i" -lt "$n" ]; do
    t=$(cpu "$frac" run -q --threads 1 --shard "$i/$n" -D points="$points" -o "$tmp/p" "$here/scale.frac")
    total=$(awk -v a="$total" -v b="$t" 'BEGIN { printf "%.3f", a + b }')
    i=$((i + 1))
done
merge=$(cpu "$frac" merge -q --threads 1 -D points="$points" -o "$tmp/m" "$here/scale.frac" "$tmp"/p/*.part)
cmp "$tmp/single/fern.png" "$tmp/m/fern.png"
mib=$(du -cm "$tmp"/p/*.part | tail -n 1 | cut -f1)
echo "single run: ${single} s CPU; $n shards: ${total} s; merge: ${merge} s; parts: ${mib} MiB"
awk -v s="$single" -v t="$total" -v m="$merge" -v mib="$mib" -v n="$n" 'BEGIN {
    printf "overhead: (shards + merge) / single = %.3f; merge %.1f ms per MiB of part (includes tone map + PNG)\n",
        (t + m) / s, 1000 * m / mib }'
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
