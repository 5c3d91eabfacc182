#!/bin/sh
# fake_sbatch.sh — an EMULATION of Slurm's `sbatch`, not Slurm: Slurm cannot
# run here, so tests/shard/slurm.sh puts this script on PATH as `sbatch` and
# runs the Slurm recipe of docs/scale.md through it. It does what sbatch(1)
# and Slurm's job_array page say a job sees, for the options the recipe uses,
# and refuses every other option (so a recipe that needs more fails the test
# instead of passing untested):
#
#   sbatch [--parsable] [--array=A[-B[:S]][%T]] [--cpus-per-task=N | -c N]
#          [--dependency=afterok:ID[:ID…]] (SCRIPT [ARG…] | --wrap=CMD)
#
# - SCRIPT must start with "#!"; its "#SBATCH OPTION" lines, up to the first
#   line that is neither a comment nor blank, are read as options; options
#   on the command line override them. The script is copied at submission
#   and run by its "#!" interpreter in the submitting folder (sbatch's
#   default --chdir). --wrap=CMD submits the script "#!/bin/sh", CMD.
# - Each job gets the next job ID (FAKE_SLURM_STATE/next, from 1000). An
#   array of K tasks takes K IDs: task k runs with SLURM_JOB_ID = the first
#   + k and SLURM_ARRAY_JOB_ID = the first, which is the array's ID. (Slurm
#   22.05 gives the array's ID to its last task and later IDs to the others:
#   frac reads neither.)
# - A task sees SLURM_JOB_ID, SLURM_JOBID, SLURM_SUBMIT_DIR, SLURM_PROCID=0
#   (a batch script is task 0 of its job; no SLURM_NTASKS without --ntasks,
#   as on Slurm 22.05, tests/shard/slurm_real.sh), and for an array
#   SLURM_ARRAY_JOB_ID, SLURM_ARRAY_TASK_ID, SLURM_ARRAY_TASK_COUNT,
#   SLURM_ARRAY_TASK_MIN, SLURM_ARRAY_TASK_MAX, SLURM_ARRAY_TASK_STEP;
#   SLURM_CPUS_PER_TASK only when --cpus-per-task was given (as Slurm).
#   Its stdout and stderr go to slurm-JOBID.out (slurm-ARRAYID_TASK.out for
#   an array task) in the submitting folder; stdin is /dev/null.
# - sbatch only queues the job and prints "Submitted batch job ID" (or
#   "ID" with --parsable); nothing runs until `fake_sbatch.sh --run-queue`
#   (no Slurm command: the stand-in for the cluster, which
#   tests/shard/slurm.sh calls after the recipe's lines). The queue runs one
#   job at a time until none can run: of the jobs whose --dependency=afterok
#   jobs have all ended with every task's exit code 0, the last submitted
#   first. Slurm promises no order between independent jobs; this one is
#   the order that breaks a recipe whose merge lacks its dependency. A job
#   one of whose dependencies failed never runs (Slurm leaves it pending,
#   "DependencyNeverSatisfied"). An array's tasks run concurrently,
#   FAKE_SLURM_SLOTS (default 4) at a time.
# - A task's environment is the queue runner's (the submitter's, as with
#   --export=ALL) plus the variables above. When a job has ended,
#   FAKE_SLURM_STATE/ID.end holds one line: "0" (every task exited 0),
#   "failed" or "DependencyNeverSatisfied"; FAKE_SLURM_STATE/ID.job is its
#   record, written at submission.
set -u
state=${FAKE_SLURM_STATE:?fake sbatch: FAKE_SLURM_STATE (its state folder) is not set}
me="sbatch (emulated)"
die() { echo "$me: error: $*" >&2; exit 1; }

# ---- the queue (fake_sbatch.sh --run-queue): the stand-in for the cluster
end() { echo "$2" >"$state/$1.end.tmp" && mv "$state/$1.end.tmp" "$state/$1.end"; }
task() { # TASK_JOB_ID OUTPUT [ARRAY_TASK_ID], then the script's arguments
    tj=$1 out=$2 ti=$3
    shift 3
    (
        cd "$submit_dir" || exit 1
        SLURM_JOB_ID=$tj SLURM_JOBID=$tj SLURM_SUBMIT_DIR=$submit_dir SLURM_PROCID=0
        export SLURM_JOB_ID SLURM_JOBID SLURM_SUBMIT_DIR SLURM_PROCID
        if [ -n "$cpus" ]; then SLURM_CPUS_PER_TASK=$cpus && export SLURM_CPUS_PER_TASK; fi
        if [ -n "$ti" ]; then
            SLURM_ARRAY_JOB_ID=$jid SLURM_ARRAY_TASK_ID=$ti SLURM_ARRAY_TASK_COUNT=$count
            SLURM_ARRAY_TASK_MIN=$lo SLURM_ARRAY_TASK_MAX=$max SLURM_ARRAY_TASK_STEP=$step
            export SLURM_ARRAY_JOB_ID SLURM_ARRAY_TASK_ID SLURM_ARRAY_TASK_COUNT
            export SLURM_ARRAY_TASK_MIN SLURM_ARRAY_TASK_MAX SLURM_ARRAY_TASK_STEP
        fi
        exec "$state/$jid.sh" "$@"
    ) </dev/null >"$submit_dir/$out" 2>&1
    echo $? >"$state/$tj.rc"
}
run_job() { # the job of the record just read; its arguments follow
    slots=${FAKE_SLURM_SLOTS:-4}
    if [ -n "$ids" ]; then
        k=0
        pids=
        for i in $ids; do
            task $((jid + k)) "slurm-${jid}_$i.out" "$i" "$@" &
            pids="$pids $!"
            k=$((k + 1))
            if [ $((k % slots)) = 0 ]; then wait $pids; pids=; fi
        done
        wait $pids
        k=0
        for i in $ids; do
            [ "$(cat "$state/$((jid + k)).rc")" = 0 ] || { end "$jid" failed; return; }
            k=$((k + 1))
        done
    else
        task "$jid" "slurm-$jid.out" "" "$@"
        [ "$(cat "$state/$jid.rc")" = 0 ] || { end "$jid" failed; return; }
    fi
    end "$jid" 0
}
if [ "${1:-}" = "--run-queue" ]; then
    [ $# -eq 1 ] || die "--run-queue takes nothing more"
    while :; do
        pick=
        for id in $(ls "$state" 2>/dev/null | sed -n 's/\.job$//p' | sort -rn); do
            [ -f "$state/$id.end" ] && continue
            ready=1
            for d in $(cat "$state/$id.deps"); do
                if [ ! -f "$state/$d.end" ]; then
                    ready=0
                elif [ "$(cat "$state/$d.end")" != 0 ]; then
                    end "$id" DependencyNeverSatisfied
                    ready=0
                    break
                fi
            done
            [ "$ready" = 1 ] && [ ! -f "$state/$id.end" ] && { pick=$id; break; }
        done
        [ -n "$pick" ] || exit 0
        (
            . "$state/$pick.job"
            set --
            while IFS= read -r a; do set -- "$@" "$a"; done <"$state/$pick.args"
            run_job "$@"
        )
    done
fi

# ---- sbatch: read the options, queue the job
parsable=0 array= cpus= deps= wrap= have_wrap=0
option() { # NAME VALUE: one option, from the command line or an #SBATCH line
    case $1 in
    --parsable) parsable=1 ;;
    --array | -a) array=$2 ;;
    --cpus-per-task | -c) cpus=$2 ;;
    --dependency | -d) deps=$2 ;;
    --wrap) wrap=$2 have_wrap=1 ;;
    *) die "option '$1' is not emulated (tests/shard/fake_sbatch.sh)" ;;
    esac
}
takes_value() {
    case $1 in
    --parsable) return 1 ;;
    --array | -a | --cpus-per-task | -c | --dependency | -d | --wrap) return 0 ;;
    *) die "option '$1' is not emulated (tests/shard/fake_sbatch.sh)" ;;
    esac
}

# the command line: options, then SCRIPT and its arguments
cl_opts=$(mktemp "${TMPDIR:-/tmp}/fake-sbatch-XXXXXX") || exit 1
trap 'rm -f "$cl_opts" "$cl_opts.d"' EXIT
while [ $# -gt 0 ]; do
    case $1 in
    --*=*) printf '%s\n%s\n' "${1%%=*}" "${1#*=}" >>"$cl_opts" ;;
    -*)
        if takes_value "$1"; then
            [ $# -ge 2 ] || die "option '$1' needs a value"
            printf '%s\n%s\n' "$1" "$2" >>"$cl_opts"
            shift
        else
            printf '%s\n\n' "$1" >>"$cl_opts"
        fi ;;
    *) break ;;
    esac
    shift
done
# #SBATCH lines first, so that the command line overrides them
if grep -q '^--wrap$' "$cl_opts"; then
    [ $# -eq 0 ] || die "a script and --wrap"
    script=
else
    [ $# -ge 1 ] || die "no batch script (sbatch reads stdin then: not emulated)"
    script=$1
    shift
    [ -f "$script" ] || die "Unable to open file $script"
    head -c 2 "$script" | grep -q '^#!' ||
        die "This does not look like a batch script. The first line must start with #! followed by the path to an interpreter."
    # one option a line: --NAME=VALUE, --NAME VALUE, -X VALUE or --parsable
    awk 'NR == 1 { next } /^#SBATCH[ \t]/ { sub(/^#SBATCH[ \t]+/, ""); sub(/[ \t]+$/, ""); print; next }
         /^[ \t]*#/ || /^[ \t]*$/ { next } { exit }' "$script" >"$cl_opts.d"
    while IFS= read -r d; do
        case $d in
        --*=*) option "${d%%=*}" "${d#*=}" ;;
        *[\ \	]*) option "${d%%[ 	]*}" "${d#*[ 	]}" ;;
        *) option "$d" "" ;;
        esac
    done <"$cl_opts.d"
fi
while IFS= read -r name && IFS= read -r value; do
    option "$name" "$value"
done <"$cl_opts"

# the array: A, A-B or A-B:S, with an optional %T (the throttle, ignored)
ids=
if [ -n "$array" ]; then
    spec=${array%%%*}
    case $spec in
    *[!0-9:-]* | "") die "--array=$array: only A, A-B and A-B:S are emulated" ;;
    *-*) lo=${spec%%-*} rest=${spec#*-} ;;
    *) lo=$spec rest=$spec ;;
    esac
    hi=${rest%%:*}
    step=1
    case $rest in *:*) step=${rest#*:} ;; esac
    [ "$step" -ge 1 ] && [ "$lo" -le "$hi" ] 2>/dev/null || die "--array=$array: bad range"
    i=$lo
    while [ "$i" -le "$hi" ]; do
        ids="$ids $i"
        max=$i
        i=$((i + step))
    done
    count=$(echo $ids | wc -w)
fi
# the dependency: afterok:ID[:ID…] only
dep_ids=
if [ -n "$deps" ]; then
    case $deps in
    afterok:*) dep_ids=$(echo "${deps#afterok:}" | tr ':' ' ') ;;
    *) die "--dependency=$deps: only afterok:ID[:ID…] is emulated" ;;
    esac
    for d in $dep_ids; do
        [ -f "$state/$d.job" ] || die "Job dependency problem (no job $d)"
    done
fi

# a job ID (IDs for the tasks of an array), the script copied now, and the
# job's record for the queue: shell assignments, its dependencies, its arguments
mkdir -p "$state" || exit 1
jid=$(cat "$state/next" 2>/dev/null || echo 1000)
if [ -n "$ids" ]; then next=$((jid + count)); else next=$((jid + 1)); fi
echo "$next" >"$state/next"
if [ "$have_wrap" = 1 ]; then
    printf '#!/bin/sh\n%s\n' "$wrap" >"$state/$jid.sh"
else
    cp "$script" "$state/$jid.sh"
fi
chmod +x "$state/$jid.sh"
q() { printf "'%s'" "$(printf '%s' "$1" | sed "s/'/'\\\\''/g")"; }
for a in "$@"; do printf '%s\n' "$a"; done >"$state/$jid.args"
echo "$dep_ids" >"$state/$jid.deps"
{
    echo "jid=$jid ids='$ids' cpus=$(q "$cpus") submit_dir=$(q "$(pwd)")"
    [ -z "$ids" ] || echo "count=$count lo=$lo max=$max step=$step"
} >"$state/$jid.job"
if [ "$parsable" = 1 ]; then echo "$jid"; else echo "Submitted batch job $jid"; fi
