#!/bin/sh
# mpi.sh — the MPI recipe of docs/scale.md, read from it and run as written:
# the shards of tests/shard/small.frac (copied as scene.frac) under
# `mpirun --oversubscribe -np 3 frac run … --shard auto`, then merge; the
# files must equal the single run's (tests/cli/shard_mpirun.cli). Prints
# "mpirun: ok N=3", or "mpirun: skipped (…)" when mpirun is not installed;
# exits non-zero on a failure.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
. "$here/recipe.sh"
if ! command -v mpirun >/dev/null 2>&1; then
    echo "mpirun: skipped (mpirun is not installed; Debian: apt-get install openmpi-bin)"
    exit 0
fi
recipe_setup mpi
cp "$here/small.frac" scene.frac || exit 1
frac -q -o single scene.frac || exit 1
# Open MPI refuses to run as root unless told so (docs/scale.md)
if [ "$(id -u)" = 0 ]; then
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    export OMPI_ALLOW_RUN_AS_ROOT OMPI_ALLOW_RUN_AS_ROOT_CONFIRM
fi
recipe_block "tests/shard/mpi.sh runs these" >recipe.sh
grep -q '^mpirun ' recipe.sh || { echo "mpirun: FAIL (no mpirun recipe in docs/scale.md)"; exit 1; }
sh -e recipe.sh >recipe.out 2>&1 || { echo "mpirun: FAIL (the recipe: $(tail -n 3 recipe.out))"; exit 1; }
why=$(recipe_same single out) || { echo "mpirun: FAIL ($why)"; exit 1; }
echo "mpirun: ok N=$(ls parts | wc -l), the recipe of docs/scale.md"
