#!/bin/sh
# slurm.sh — the Slurm recipe of docs/scale.md, read from it and run as
# written, under an EMULATED sbatch: Slurm itself cannot run here, so
# tests/shard/fake_sbatch.sh stands in for it on PATH (sbatch queues the
# jobs; then the emulated cluster runs a job array's script once a task with
# the variables Slurm sets, and a job with --dependency=afterok only once
# the array has ended well, the last submitted first; see its header).
# What is tested is the recipe and `--shard auto` under Slurm's variables,
# not Slurm. The recipe's job script (render.sbatch) and its two submission
# lines render tests/shard/small.frac (copied as scene.frac) as the array's
# shards and merge them in the dependent job; every file of out/ must equal
# the single run's, byte for byte, parts/ must hold one part a task, and
# every job must have ended with exit code 0 (tests/cli/shard_slurm.cli).
# Prints "slurm (emulated sbatch): ok N=…"; exits non-zero on a failure.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
. "$here/recipe.sh"
fail() { echo "slurm (emulated sbatch): FAIL ($*)"; exit 1; }
recipe_setup slurm
# the recipe calls `sbatch`: the emulation, next to the frac under test
ln -s "$here/fake_sbatch.sh" "$bin/sbatch" || exit 1
FAKE_SLURM_STATE=$tmp/slurm
export FAKE_SLURM_STATE
# a task sees Slurm's variables only, as in a job (none of another launcher's)
unset SLURM_ARRAY_TASK_ID SLURM_ARRAY_TASK_COUNT SLURM_ARRAY_TASK_MIN SLURM_PROCID SLURM_NTASKS
unset SLURM_CPUS_PER_TASK OMPI_COMM_WORLD_RANK OMPI_COMM_WORLD_SIZE PMI_RANK PMI_SIZE
recipe_slurm_files
sh -e submit.sh </dev/null >submit.out 2>&1 || fail "the submission: $(tail -n 3 submit.out)"
# the emulated cluster runs the queue: the merge job first if it could
"$here/fake_sbatch.sh" --run-queue || fail "the queue"
for j in slurm/*.job; do
    [ -f "$j" ] || fail "no job was submitted"
    id=$(basename "$j" .job)
    [ -f "slurm/$id.end" ] || fail "job $id never ran"
    [ "$(cat "slurm/$id.end")" = 0 ] || fail "job $id: $(cat "slurm/$id.end"): $(cat slurm-*.out | tail -n 3)"
done
[ "$(ls slurm/*.job | wc -l)" -eq 2 ] || fail "$(ls slurm/*.job | wc -l) jobs submitted, not 2"
[ "$(ls slurm-*_*.out | wc -l)" -eq "$n" ] || fail "$(ls slurm-*_*.out | wc -l) array tasks ran, not $n"
why=$(recipe_parts "$n") || fail "$why"
why=$(recipe_same single out) || fail "$why"
echo "slurm (emulated sbatch): ok N=$n, the recipe of docs/scale.md, $(ls out | wc -l) files as the single run"
