#!/bin/sh
# bench/scale.sh [FRAC] [N] [POINTS] — the cost of sharding (docs/scale.md):
# CPU time (user + system: perf stat's task-clock, or /usr/bin/time) of
# one single-threaded run of bench/scale.frac against the sum over N
# single-threaded shards plus the merge, the outputs compared with cmp,
# and the merge's time per MiB of parts.
# The single run and the merge both tone-map the histogram and encode the
# PNG (the shards do neither): that share of each (T, from a perf record
# profile: the samples in the functions of runtime/tonemap.c, png.c and
# deflate.c, times the run's CPU time) is reported, and the ratio is given
# twice: of the whole runs, and of the rest (single - T against shards +
# merge - T of the merge), which compares the split work with itself.
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
mib=$(cat "$tmp"/p/*.part | wc -c | awk '{ printf "%.2f", $1 / 1048576 }')
# T: the share of a run's CPU time spent tone-mapping and encoding PNG,
# from a perf record profile of one more run (empty without perf record)
finish_syms=$(nm -l --defined-only "$frac" 2>/dev/null | awk '$4 ~ /runtime\/(tonemap|png|deflate)\.c/ { print $3 }')
finish() { # CPU-SECONDS ARGS…: T in seconds, or nothing
    secs=$1
    shift
    if [ -z "$finish_syms" ] || ! perf record -q -e cpu-clock -F 4000 -o "$tmp/perf.data" "$@" >/dev/null 2>&1; then
        return 0
    fi
    perf report -i "$tmp/perf.data" --no-children --sort sym --stdio 2>/dev/null |
        awk -v syms="$finish_syms" -v s="$secs" '
            BEGIN { n = split(syms, a, "\n"); for (i = 1; i <= n; i++) fin[a[i]] = 1 }
            /^ *[0-9.]+%/ { p = $1; sub("%", "", p); name = $3; sub(/\.(part|constprop|isra|cold)\..*$/, "", name)
                            all += p; if (name in fin) t += p }
            END { if (all > 0) printf "%.3f", s * t / all }'
}
t_single=$(finish "$single" "$frac" -q --threads 1 -D points="$points" -o "$tmp/single2" "$here/scale.frac")
t_merge=$(finish "$merge" "$frac" merge -q --threads 1 -D points="$points" -o "$tmp/m2" "$here/scale.frac" "$tmp"/p/*.part)
echo "single run: ${single} s CPU; $n shards: ${total} s; merge: ${merge} s; parts: ${mib} MiB"
awk -v s="$single" -v t="$total" -v m="$merge" -v mib="$mib" -v n="$n" -v ts="$t_single" -v tm="$t_merge" 'BEGIN {
    printf "overhead: (shards + merge) / single = %.3f (the whole runs)\n", (t + m) / s
    if (ts == "" || tm == "") {
        printf "tone map + PNG: not measured (needs perf record and nm -l)\n"
        printf "merge: %.1f ms per MiB of part (including its tone map + PNG)\n", 1000 * m / mib
    } else {
        printf "tone map + PNG: single run %.3f s, merge %.3f s (perf record samples)\n", ts, tm
        printf "overhead without them: (shards + merge - %.3f) / (single - %.3f) = %.3f\n", tm, ts, (t + m - tm) / (s - ts)
        printf "merge: %.1f ms per MiB of part without its tone map + PNG (%.1f with)\n", 1000 * (m - tm) / mib, 1000 * m / mib
    }
}'
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"
