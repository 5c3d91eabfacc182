#!/bin/sh
# mpi.sh — the shards of tests/shard/small.frac run under `mpirun -np 3 frac
# run --shard auto`, then merge; the files must equal the single run's
# (tests/cli/shard_mpirun.cli). Prints "mpirun: ok N=3", or
# "mpirun: skipped (…)" when mpirun is not installed; exits non-zero on a failure.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
if ! command -v mpirun >/dev/null 2>&1; then
    echo "mpirun: skipped (mpirun is not installed; Debian: apt-get install openmpi-bin)"
    exit 0
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-mpi-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
fracpath=$(command -v "$frac")
"$frac" -q -o "$tmp/single" "$s" || exit 1
# Open MPI refuses to run as root unless told; --oversubscribe: more ranks than cores
OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 \
    mpirun --oversubscribe -np 3 "$fracpath" run -q --threads 1 --shard auto -o "$tmp/p" "$s" ||
    { echo "mpirun: FAIL (mpirun exited $?)"; exit 1; }
"$frac" merge -q -o "$tmp/m" "$s" "$tmp/p"/*.part || { echo "mpirun: FAIL (merge)"; exit 1; }
for f in a.png b.pfm; do
    cmp -s "$tmp/single/$f" "$tmp/m/$f" || { echo "mpirun: FAIL ($f differs)"; exit 1; }
done
echo "mpirun: ok N=$(ls "$tmp/p" | wc -l)"
