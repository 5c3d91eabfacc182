#!/bin/sh
# check.sh [-n "N…"] SCRIPT [FRAC OPTIONS…] — shard + merge equals the single run.
#
# Runs `frac run SCRIPT` once, then for each N in -n (or $SHARD_NS; default 1 2 3 7)
# the N shards `frac run --shard I/N` concurrently as separate processes (one
# thread each), then `frac merge` (three threads) on their parts, and compares
# every output file (cmp, byte for byte) and stdout with the single run's.
# With --frames A..B among the options, every shard writes a part a frame and
# the merge takes them all.
# Prints one line "ok NAME N=…" or what differs; exits non-zero on a failure.
# FRAC (default: frac on PATH) is the binary.
set -u
frac=${FRAC:-frac}
if [ "$1" = "-n" ]; then
    SHARD_NS=$2
    shift 2
fi
script=$1
shift
name=$(basename "$script" .frac)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-shard-XXXXXX") || exit 1
[ -n "${SHARD_KEEP:-}" ] || trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL $name: $*"; exit 1; }
"$frac" -q --threads 2 "$@" -o "$tmp/single" "$script" >"$tmp/single.out" 2>"$tmp/single.err" ||
    fail "single run: $(cat "$tmp/single.err")"
[ -d "$tmp/single" ] || mkdir "$tmp/single"
ns=${SHARD_NS:-1 2 3 7}
for n in $ns; do
    i=0
    pids=
    while [ "$i" -lt "$n" ]; do
        "$frac" run -q --threads 1 --shard "$i/$n" "$@" -o "$tmp/p$n" "$script" >"$tmp/s$n-$i.out" 2>"$tmp/s$n-$i.err" &
        pids="$pids $!"
        i=$((i + 1))
    done
    i=0
    for p in $pids; do
        wait "$p" || fail "shard $i/$n: $(cat "$tmp/s$n-$i.err")"
        [ -s "$tmp/s$n-$i.out" ] && fail "shard $i/$n printed to stdout"
        i=$((i + 1))
    done
    # one part a shard (one a shard and frame with --frames): as many of each
    # shard as of shard 0, and nothing else
    n_parts=$(ls "$tmp/p$n" | wc -l)
    per=$(ls "$tmp/p$n" | grep -c "\.shard-0-of-$n\.part\$")
    i=0
    while [ "$i" -lt "$n" ]; do
        k=$(ls "$tmp/p$n" | grep -c "\.shard-$i-of-$n\.part\$")
        [ "$k" -eq "$per" ] || fail "N=$n: $k parts of shard $i, $per of shard 0"
        i=$((i + 1))
    done
    [ "$per" -ge 1 ] && [ "$n_parts" -eq $((n * per)) ] ||
        fail "N=$n: $n_parts files in the shards' folder, expected $n parts (a frame)"
    "$frac" merge -q --threads 3 "$@" -o "$tmp/m$n" "$script" "$tmp/p$n"/*.part >"$tmp/m$n.out" 2>"$tmp/m$n.err" ||
        fail "merge N=$n: $(cat "$tmp/m$n.err")"
    [ -d "$tmp/m$n" ] || mkdir "$tmp/m$n"
    cmp -s "$tmp/single.out" "$tmp/m$n.out" || fail "merge N=$n: stdout differs"
    (cd "$tmp/single" && find . -type f | sort) >"$tmp/a.lst"
    (cd "$tmp/m$n" && find . -type f | sort) >"$tmp/b.lst"
    cmp -s "$tmp/a.lst" "$tmp/b.lst" || fail "merge N=$n: other files: $(diff "$tmp/a.lst" "$tmp/b.lst" | tr '\n' ' ')"
    while read -r f; do
        cmp -s "$tmp/single/$f" "$tmp/m$n/$f" || fail "merge N=$n: $f differs"
    done <"$tmp/a.lst"
done
echo "ok $name N=$(echo $ns | tr ' ' ,)"
