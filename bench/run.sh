#!/usr/bin/env bash
# Run every benchmark: the interpreter script and each build/bench/* program
# (each prints its engine's ratios against its plain-C baseline). The load
# average is printed before and after each one: on the shared 2-core machine
# a figure taken at a load above ~2 is not a figure of the code.
set -u
build=${1:-build}
cd "$(dirname "$0")/.."
load() { cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || uptime; }
echo "== frac benchmarks, $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc 2>/dev/null || echo '?') cores, load $(load)"
bash bench/interp.sh "$build/frac"
bash bench/interp_bench.sh "$build/frac"
for b in "$build"/bench/*; do
    [ -x "$b" ] || continue
    echo "== $(basename "$b") (load before: $(load))"
    if [ "$(basename "$b")" = png_bench ]; then
        # png_bench prints, per image, the command that deflates the same
        # filtered rows with Python's zlib (levels 2 and 6): run it here, so the
        # ratios the issue states (16-bit speed >= 0.9x zlib-2, default size
        # <= 1.10x zlib-6) come out of the same run.
        out=$("$b")
        echo "$out"
        if command -v python3 > /dev/null; then
            echo "$out" | sed -n 's/^  compare: python3 //p' | while read -r args; do
                echo "  zlib on the same filtered rows: ${args#* }"
                # shellcheck disable=SC2086
                python3 $args
            done
            echo "  (goals, 16-bit turb16 row: speed >= 0.90x zlib level 2; every default size <= 1.10x zlib level 6)"
        else
            echo "  zlib comparison: skipped (python3 is not installed)"
        fi
    else
        "$b"
    fi
    echo "   (load after: $(load))"
done
# sharding overhead (issue 17's goal: 4 shards + merge <= 1.05x one run at 10^8)
echo "== scale: 4 shards + merge vs one run, chaos 1e8 points (load before: $(load))"
sh bench/scale.sh "$build/frac" 4 1e8
