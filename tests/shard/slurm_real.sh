#!/bin/sh
# slurm_real.sh — the Slurm recipe of docs/scale.md, read from it and run as
# written against a real Slurm controller (slurm.sh runs the same blocks under
# an emulated sbatch): render.sbatch submitted as a job array with `sbatch
# --parsable`, then the merge job with --dependency=afterok, both through the
# cluster's own sbatch. Every array task and the merge job must have
# COMPLETED with exit code 0, the merge must have started no earlier than the
# last task ended, there must be one slurm-ARRAY_TASK.out a task, parts/ must
# hold one part a task, and out/ must equal the single run's files, byte for
# byte (tests/cli/shard_slurm_real.cli). On tools/slurm_local.sh's cluster the
# merge job is first made free to start before the array (below). Then, when
# mpirun is installed, the doc's mpi.sbatch (mpirun in a batch job) runs the
# same way: one job, COMPLETED 0:0, its merged files equal to the single run.
#
# The cluster: the one of $SLURM_CONF, else /tmp/frac-slurm/slurm.conf when it
# exists (what `tools/slurm_local.sh start` writes), else Slurm's default
# configuration. Prints "slurm (real Slurm): ok N=…" (and a line for
# mpi.sbatch), or "slurm (real Slurm): skipped (…)" when Slurm is not installed or no controller answers; exits
# non-zero on a failure. The test folder is made in $TMPDIR (default /tmp):
# on a cluster of several machines set TMPDIR to a folder every node sees,
# with the frac under test in one too. Every wait has a time limit
# (FRAC_SLURM_WAIT seconds for the jobs, default 90); jobs still queued when
# the test ends are cancelled.
set -u
frac=${FRAC:-frac}
here=$(cd "$(dirname "$0")" && pwd)
. "$here/recipe.sh"
say() { echo "slurm (real Slurm): $*"; }
fail() { say "FAIL ($*)"; exit 1; }
for p in sbatch scontrol squeue scancel timeout; do
    command -v "$p" >/dev/null 2>&1 ||
        { say "skipped ($p is not installed; Debian: apt-get install slurm-client, and tools/slurm_local.sh start)"; exit 0; }
done
if [ -z "${SLURM_CONF:-}" ] && [ -f /tmp/frac-slurm/slurm.conf ]; then
    SLURM_CONF=/tmp/frac-slurm/slurm.conf
    export SLURM_CONF
fi
if [ -n "${SLURM_CONF:-}" ] && [ ! -f "$SLURM_CONF" ]; then
    say "skipped (SLURM_CONF=$SLURM_CONF does not exist)"
    exit 0
fi
# scontrol retries for a minute without a configuration: at most 10 s here
ping=$(timeout 10 scontrol -o ping 2>&1)
case $ping in
*"is UP"*) ;;
*) say "skipped (no Slurm controller answers${SLURM_CONF:+ for $SLURM_CONF}: $( (echo "$ping" | grep -e 'is DOWN' -e 'fatal:'; echo "$ping") | head -n 1 | cut -c 1-120); tools/slurm_local.sh start brings one up)"
   exit 0 ;;
esac
recipe_setup slurm-real
# a cluster that answers but cannot run a job here (a container without what
# slurmd needs) says nothing about the recipe: a trivial job first, skipped
# when it does not complete within 40 s
probe=$(cd / && timeout 40 sbatch --wait --parsable -o /dev/null --wrap true </dev/null 2>&1) # not in $wd: jobs_here counts those
rc=$?
case $rc in
0) ;;
*) say "skipped (the controller answers but a trivial job did not complete: sbatch --wait --wrap true exited $rc, $(echo "$probe" | tail -n 1 | cut -c 1-120))"
   exit 0 ;;
esac
wd=$(pwd -P)
# a task sees Slurm's variables only, as in a job (none of another launcher's)
unset SLURM_ARRAY_TASK_ID SLURM_ARRAY_TASK_COUNT SLURM_ARRAY_TASK_MIN SLURM_PROCID SLURM_NTASKS
unset SLURM_CPUS_PER_TASK OMPI_COMM_WORLD_RANK OMPI_COMM_WORLD_SIZE PMI_RANK PMI_SIZE
# the jobs of this test: those whose working folder is this one or its mpi/
jobs_here() { timeout 10 scontrol -o show job 2>/dev/null | grep -e " WorkDir=$wd " -e " WorkDir=$wd/mpi " ; }
field() { sed -n "s/^\(.* \)\{0,1\}$1=\([^ ]*\).*/\2/p"; } # NAME=VALUE of each line
own=0 # 1: the cluster is tools/slurm_local.sh's (below)
part_up() { [ "$own" = 0 ] || timeout 10 scontrol update PartitionName=local State=UP; }
cleanup() {
    part_up 2>/dev/null
    ids=$(jobs_here | field JobId | tr '\n' ' ')
    [ -z "$ids" ] || timeout 10 scancel $ids 2>/dev/null
    rm -rf "$tmp"
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP
recipe_slurm_files
# On a cluster of tools/slurm_local.sh (ClusterName frac-local, nobody
# else's) the test makes the merge job free to start before the array, as
# the emulation does: the partition is DOWN during the submission, then the
# array is held, the partition UP, and the merge must stay pending for 5 s
# (without its afterok it would run, and fail for want of parts); then the
# array is released. On another cluster the jobs run in the order it picks.
timeout 10 scontrol show config 2>/dev/null | grep -q '^ClusterName *= frac-local$' && own=1
[ "$own" = 0 ] || timeout 10 scontrol update PartitionName=local State=DOWN || fail "cannot set the partition DOWN"
timeout 60 sh -e submit.sh </dev/null >submit.out 2>&1 || { part_up; fail "the submission: $(tail -n 3 submit.out)"; }
if [ "$own" = 1 ]; then
    arr=$(jobs_here | field ArrayJobId | sort -u)
    [ -n "$arr" ] && timeout 10 scontrol hold "$arr" || { part_up; fail "cannot hold the array"; }
    part_up || fail "cannot set the partition UP"
    sleep 5
    merge=$(jobs_here | grep -v " ArrayJobId=")
    case $merge in
    *" JobState=PENDING "*) ;;
    *) fail "the merge job did not wait for the array: $(echo "$merge" | field JobState) $(echo "$merge" | field ExitCode); $(cat slurm-*.out 2>/dev/null | tail -n 2)" ;;
    esac
    timeout 10 scontrol release "$arr" || fail "cannot release the array"
fi
# until every job of this folder has ended (a job pending on a dependency
# that can never be satisfied has ended too)
limit=${FRAC_SLURM_WAIT:-90}
wait_jobs() {
    t=0
    while :; do
        open=$(jobs_here | grep -v -e ' JobState=COMPLETED ' -e ' JobState=FAILED ' -e ' JobState=CANCELLED ' \
            -e ' JobState=TIMEOUT ' -e ' JobState=OUT_OF_MEMORY ' -e ' JobState=NODE_FAIL ' -e ' Reason=DependencyNeverSatisfied ')
        [ -n "$open" ] || break
        [ "$t" -lt "$limit" ] || fail "jobs not done after $limit s: $(echo "$open" | sed -n 's/.* JobState=\([^ ]*\) Reason=\([^ ]*\).*/\1 (\2)/p' | sort | uniq -c | sed 's/^ *//' | paste -sd, -)"
        sleep 1
        t=$((t + 1))
    done
}
wait_jobs
jobs_here | grep " WorkDir=$wd " >jobs.txt
arrays=$(field ArrayJobId <jobs.txt | sort -u)
[ "$(echo "$arrays" | grep -c .)" -eq 1 ] || fail "$(echo "$arrays" | grep -c .) job arrays, not 1"
grep -v " ArrayJobId=" jobs.txt >merge.txt
[ "$(grep -c . merge.txt)" -eq 1 ] || fail "$(grep -c . merge.txt) jobs besides the array, not 1"
grep " ArrayJobId=$arrays " jobs.txt >tasks.txt
[ "$(grep -c . tasks.txt)" -eq "$n" ] || fail "$(grep -c . tasks.txt) array tasks ran, not $n"
while IFS= read -r j; do
    st="$(echo "$j" | field JobState) $(echo "$j" | field ExitCode)"
    [ "$st" = "COMPLETED 0:0" ] ||
        fail "job $(echo "$j" | field JobId) (array task $(echo "$j" | field ArrayTaskId)): $st $(echo "$j" | field Reason); $(cat slurm-*.out 2>/dev/null | tail -n 3)"
done <jobs.txt
# afterok: the merge started when every task had ended (times in seconds)
last=$(field EndTime <tasks.txt | sort | tail -n 1)
start=$(field StartTime <merge.txt)
[ "$(printf '%s\n%s\n' "$last" "$start" | sort | head -n 1)" = "$last" ] ||
    fail "the merge job started at $start, before the last task ended at $last"
[ "$(ls slurm-"$arrays"_*.out | wc -l)" -eq "$n" ] || fail "$(ls slurm-"$arrays"_*.out | wc -l) task outputs, not $n"
why=$(recipe_parts "$n") || fail "$why"
why=$(recipe_same single out) || fail "$why"
say "ok N=$n, the recipe of docs/scale.md, $(ls out | wc -l) files as the single run$([ "$own" = 1 ] && echo ", the merge held back by its dependency")"

# mpirun in a batch job (docs/scale.md's mpi.sbatch): every rank inherits the
# job's SLURM_PROCID=0; --shard auto must take mpirun's rank instead
if ! command -v mpirun >/dev/null 2>&1; then
    say "mpirun in a batch job: skipped (mpirun is not installed; Debian: apt-get install openmpi-bin)"
    exit 0
fi
if [ "$(id -u)" = 0 ]; then
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    export OMPI_ALLOW_RUN_AS_ROOT OMPI_ALLOW_RUN_AS_ROOT_CONFIRM
fi
mkdir mpi && cp scene.frac mpi/ && cd mpi || exit 1
recipe_block "tests/shard/slurm_real.sh runs this block as mpi.sbatch" >mpi.sbatch
grep -q '^mpirun ' mpi.sbatch || fail "no mpirun batch script in docs/scale.md"
m=$(sed -n 's/^mpirun .*-np \([0-9][0-9]*\) .*/\1/p' mpi.sbatch)
[ -n "$m" ] || fail "mpi.sbatch: no -np N"
timeout 60 sbatch --parsable mpi.sbatch </dev/null >submit.out 2>&1 || fail "the submission of mpi.sbatch: $(tail -n 3 submit.out)"
wait_jobs
j=$(jobs_here | grep " WorkDir=$wd/mpi ")
st="$(echo "$j" | field JobState) $(echo "$j" | field ExitCode)"
[ "$st" = "COMPLETED 0:0" ] || fail "mpi.sbatch: $st; $(tail -n 3 slurm-*.out)"
why=$(recipe_parts "$m") || fail "mpi.sbatch: $why"
why=$(recipe_same ../single out) || fail "mpi.sbatch: $why"
say "mpirun in a batch job: ok N=$m, mpi.sbatch of docs/scale.md, $(ls out | wc -l) files as the single run"
