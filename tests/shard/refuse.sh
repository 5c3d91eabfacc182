#!/bin/sh
# refuse.sh — what `frac merge` refuses, and `--shard auto` (tests/cli/shard_refuse.cli).
#
# Makes the 3 parts of tests/shard/small.frac, then runs merge on broken
# sets of parts and prints, per case, its exit code and frac's first error
# line (with the temporary folder's name replaced by TMP), and whether the
# output folder stayed empty. Then --shard auto under each launcher's
# variables prints the part it wrote.
set -u
frac=${FRAC:-frac}
here=$(dirname "$0")
s=$here/small.frac
tmp=$(mktemp -d "${TMPDIR:-/tmp}/frac-refuse-XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT
for i in 0 1 2; do
    "$frac" run -q --shard $i/3 -o "$tmp/p" "$s" || exit 1
done
p=$tmp/p/small.shard
case_() { # NAME, then the merge arguments after the script
    name=$1
    shift
    rm -rf "$tmp/out"
    "$frac" merge -q -o "$tmp/out" "$@" >/dev/null 2>"$tmp/err"
    rc=$?
    files=$(ls "$tmp/out" 2>/dev/null | wc -l)
    echo "$name: exit $rc, $files files written: $(head -n 1 "$tmp/err" | sed "s|$tmp|TMP|g")"
}
case_ "missing" "$s" "$p-0-of-3.part" "$p-2-of-3.part"
case_ "duplicated" "$s" "$p-0-of-3.part" "$p-1-of-3.part" "$p-1-of-3.part" "$p-2-of-3.part"
case_ "other seed" --seed 2 "$s" "$p-0-of-3.part" "$p-1-of-3.part" "$p-2-of-3.part"
case_ "other params" -D n=5e4 "$s" "$p-0-of-3.part" "$p-1-of-3.part" "$p-2-of-3.part"
cp "$s" "$tmp/small.frac"
echo "# changed" >>"$tmp/small.frac"
case_ "other script" "$tmp/small.frac" "$p-0-of-3.part" "$p-1-of-3.part" "$p-2-of-3.part"
"$frac" run -q --shard 1/2 -o "$tmp/q" "$s" || exit 1
case_ "other N" "$s" "$p-0-of-3.part" "$tmp/q/small.shard-1-of-2.part" "$p-2-of-3.part"
# cut inside the payload of the first record (the 32x32 counts of a call
# of one chunk, which shard 1 does not compute: one run of 1024 zeros, the
# 3 bytes from byte 203 on: after the 123 bytes of the header and the 80 of
# the record's head)
head -c 204 "$p-1-of-3.part" >"$tmp/trunc.part"
case_ "truncated" "$s" "$p-0-of-3.part" "$tmp/trunc.part" "$p-2-of-3.part"
# flip one byte of shard 1's first record (its payload's second)
cp "$p-1-of-3.part" "$tmp/bad.part"
printf 'Z' | dd of="$tmp/bad.part" bs=1 seek=204 conv=notrunc 2>/dev/null
case_ "corrupt" "$s" "$p-0-of-3.part" "$tmp/bad.part" "$p-2-of-3.part"
# a part of format 3 (the format field, after the magic, set to 3): made
# by a frac before the runs of zeros in sums
cp "$p-1-of-3.part" "$tmp/v3.part"
printf '\003' | dd of="$tmp/v3.part" bs=1 seek=8 conv=notrunc 2>/dev/null
case_ "format 3" "$s" "$p-0-of-3.part" "$tmp/v3.part" "$p-2-of-3.part"
case_ "not a part" "$s" "$p-0-of-3.part" "$s" "$p-2-of-3.part"
case_ "unreadable" "$s" "$p-0-of-3.part" "$tmp/none.part" "$p-2-of-3.part"
# --shard auto: each launcher's variables (the others unset)
unset SLURM_ARRAY_TASK_ID SLURM_ARRAY_TASK_COUNT SLURM_ARRAY_TASK_MIN SLURM_ARRAY_TASK_STEP SLURM_PROCID SLURM_NTASKS
unset OMPI_COMM_WORLD_RANK OMPI_COMM_WORLD_SIZE PMI_RANK PMI_SIZE
auto() { # NAME, then VAR=VALUE words
    name=$1
    shift
    rm -rf "$tmp/a"
    env "$@" "$frac" run --shard auto -o "$tmp/a" "$s" >/dev/null 2>"$tmp/err"
    echo "auto $name: exit $?: $(ls "$tmp/a" 2>/dev/null)$(head -n 1 "$tmp/err" | grep -v '^wrote')"
}
auto "slurm array" SLURM_ARRAY_TASK_ID=3 SLURM_ARRAY_TASK_COUNT=4 SLURM_ARRAY_TASK_MIN=1
auto "slurm tasks" SLURM_PROCID=2 SLURM_NTASKS=5
auto "open mpi" OMPI_COMM_WORLD_RANK=0 OMPI_COMM_WORLD_SIZE=2
auto "pmi" PMI_RANK=1 PMI_SIZE=3
auto "bad" PMI_RANK=3 PMI_SIZE=3
# --array=0-6:2 (Slurm sets the step); --array=1,4,7 (a list: Slurm sets step 1)
auto "slurm array step" SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_COUNT=4 SLURM_ARRAY_TASK_MIN=0 SLURM_ARRAY_TASK_STEP=2
auto "slurm array list" SLURM_ARRAY_TASK_ID=4 SLURM_ARRAY_TASK_COUNT=3 SLURM_ARRAY_TASK_MIN=1 SLURM_ARRAY_TASK_STEP=1
# mpirun in a Slurm batch job: every rank has the job's SLURM_PROCID=0;
# srun in an array task: SLURM_PROCID=0 of 1 beside the task's number
auto "mpirun in sbatch" OMPI_COMM_WORLD_RANK=1 OMPI_COMM_WORLD_SIZE=3 SLURM_PROCID=0 SLURM_NTASKS=3
auto "srun in an array" SLURM_ARRAY_TASK_ID=2 SLURM_ARRAY_TASK_COUNT=4 SLURM_ARRAY_TASK_MIN=0 SLURM_PROCID=0 SLURM_NTASKS=1
auto "none" X=1
