#!/usr/bin/env bash
# The interpreter against Lua 5.4 on the same programs (issue 15):
#   fib        fn fib(n) = if n < 2 then n else fib(n-1) + fib(n-2)   per call
#   range      for i in range(n) do s = s + i*i end                    per iteration
#   closure    make a closure per iteration and call it                 per iteration
#   concat     s = concat(s, [i]) (frac) / s[#s+1] = i (Lua)            per item
#   string     s = s + "x" (frac) / s = s .. "x" (Lua)                  per item
# (string building copies the string each time in both, so its slope is an
# average cost per item over the sizes run, not a constant; concat extends
# the list in place since x = concat(x, …) does that.)
# Each program runs at two sizes; the rate is the slope (CPU seconds, user +
# system, from /usr/bin/time) between them, so start-up and fixed costs drop
# out. Prints ns per operation for both, the ratio and the load average.
# Usage: bash bench/interp_bench.sh [build/frac]     (best of REPS=3 runs;
#        ONLY=fib runs one program)
set -eu
frac=${1:-build/frac}
reps=${REPS:-3}
lua=$(command -v lua5.4 || true)
if [ -z "$lua" ]; then
    echo "interp_bench: skipped (lua5.4 is not installed: apt-get install lua5.4)"
    exit 0
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# cpu FILE CMD...: best user+system seconds of $reps runs
cpu() {
    local best=999999 out=$1 r t
    shift
    for ((r = 0; r < reps; r++)); do
        /usr/bin/time -f '%U %S' -o "$tmp/t" "$@" > "$out"
        t=$(awk '{print $1 + $2}' "$tmp/t")
        best=$(awk -v a="$t" -v b="$best" 'BEGIN{print (a < b) ? a : b}')
    done
    echo "$best"
}

# prog NAME: writes $tmp/NAME.frac and $tmp/NAME.lua taking the size as N
prog() {
    case $1 in
    fib)
        printf 'param N = 20\nfn fib(n) = if n < 2 then n else fib(n - 1) + fib(n - 2)\nprint(fib(N))\n' > "$tmp/fib.frac"
        printf 'local N = tonumber(arg[1])\nlocal function fib(n) if n < 2 then return n end return fib(n-1) + fib(n-2) end\nprint(fib(N))\n' > "$tmp/fib.lua" ;;
    range)
        printf 'param N = 10\nlet s = 0\nfor i in range(N) do\n  s = s + i * i\nend\nprint(s)\n' > "$tmp/range.frac"
        printf 'local N = tonumber(arg[1])\nlocal s = 0\nfor i = 0, N - 1 do s = s + i * i end\nprint(s)\n' > "$tmp/range.lua" ;;
    closure)
        printf 'param N = 10\nfn adder(k) = x => x + k\nlet s = 0\nfor i in range(N) do\n  let f = adder(i)\n  s = s + f(1)\nend\nprint(s)\n' > "$tmp/closure.frac"
        printf 'local N = tonumber(arg[1])\nlocal function adder(k) return function(x) return x + k end end\nlocal s = 0\nfor i = 0, N - 1 do local f = adder(i) s = s + f(1) end\nprint(s)\n' > "$tmp/closure.lua" ;;
    concat)
        printf 'param N = 10\nlet s = []\nfor i in range(N) do\n  s = concat(s, [i])\nend\nprint(len(s))\n' > "$tmp/concat.frac"
        printf 'local N = tonumber(arg[1])\nlocal s = {}\nfor i = 0, N - 1 do s[#s + 1] = i end\nprint(#s)\n' > "$tmp/concat.lua" ;;
    string)
        printf 'param N = 10\nlet s = ""\nfor i in range(N) do\n  s = s + "x"\nend\nprint(len(s))\n' > "$tmp/string.frac"
        printf 'local N = tonumber(arg[1])\nlocal s = ""\nfor i = 0, N - 1 do s = s .. "x" end\nprint(#s)\n' > "$tmp/string.lua" ;;
    esac
}

# ops NAME N: operations the program performs at size N
ops() {
    if [ "$1" = fib ]; then # calls of fib(N) = 2 F(N+1) - 1
        awk -v n="$2" 'BEGIN{a = 0; b = 1; for (i = 0; i < n + 1; i++) { t = a + b; a = b; b = t } print 2 * a - 1}'
    else
        echo "$2"
    fi
}

load=$(cut -d' ' -f1-3 /proc/loadavg)
printf '%-8s %12s %12s %8s   (load average %s)\n' program 'frac ns/op' 'Lua ns/op' ratio "$load"
# name, two frac sizes, two Lua sizes (Lua needs larger ones to take measurable time).
# /usr/bin/time counts CPU time in 10 ms steps: the difference between the two
# sizes must take a few hundred ms, or the slope is mostly rounding (fib 22..27
# was ~580 K calls, ~20 ms: a 17 ns/call step).
for spec in "fib 27 32 27 32" "range 3000000 30000000 3000000 30000000" "closure 300000 1000000 1000000 3000000" \
    "concat 300000 1000000 1000000 5000000" "string 20000 80000 20000 80000"; do
    set -- $spec
    name=$1 n1=$2 n2=$3 m1=$4 m2=$5
    [ -n "${ONLY:-}" ] && [ "$ONLY" != "$name" ] && continue
    prog "$name"
    f1=$(cpu "$tmp/f1" "$frac" -D N="$n1" "$tmp/$name.frac")
    f2=$(cpu "$tmp/f2" "$frac" -D N="$n2" "$tmp/$name.frac")
    l1=$(cpu "$tmp/l1" "$lua" "$tmp/$name.lua" "$m1")
    l2=$(cpu "$tmp/l2" "$lua" "$tmp/$name.lua" "$m2")
    o1=$(ops "$name" "$n1") o2=$(ops "$name" "$n2")
    p1=$(ops "$name" "$m1") p2=$(ops "$name" "$m2")
    awk -v name="$name" -v f1="$f1" -v f2="$f2" -v l1="$l1" -v l2="$l2" -v o1="$o1" -v o2="$o2" \
        -v p1="$p1" -v p2="$p2" 'BEGIN{
        fr = (f2 - f1) / (o2 - o1) * 1e9; lr = (l2 - l1) / (p2 - p1) * 1e9
        printf "%-8s %12.1f %12.1f %8s\n", name, fr, lr, (lr > 0 ? sprintf("%.1fx", fr / lr) : "n/a") }'
done
echo "(slopes between two sizes; CPU time of the best of $reps runs; load average now $(cut -d' ' -f1-3 /proc/loadavg))"
