#!/bin/sh
# slurm_local.sh — a one-node Slurm cluster on this machine, for running the
# Slurm recipe of docs/scale.md against real Slurm (tests/shard/slurm_real.sh).
#
#   tools/slurm_local.sh start [DIR]   write DIR/slurm.conf, start munged (if
#                                      none answers), slurmctld and slurmd;
#                                      wait until the node is idle; print
#                                      `export SLURM_CONF=DIR/slurm.conf`
#   tools/slurm_local.sh stop [DIR]    stop the daemons that start started
#   tools/slurm_local.sh status [DIR]  whether the controller answers
#
# DIR defaults to /tmp/frac-slurm (tests/shard/slurm_real.sh looks there when
# SLURM_CONF is unset). Needs root (slurmd starts jobs as their user) and the
# Debian packages slurmctld, slurmd, slurm-client and munge; /etc is not
# touched except for munge's key, created if the package left none.
#
# The node is this machine (NodeName = `hostname -s`, address 127.0.0.1, so
# no name lookup), with plugins that need no cgroups or systemd:
# proctrack/linuxproc, task/none, no accounting, select/cons_tres by CPU. It
# declares 32 CPUs whatever the machine has (SlurmdParameters=
# config_overrides), so that the recipe's `--cpus-per-task=8` fits and four
# tasks run at a time, sharing the real cores. Every wait has a time limit:
# start fails (non-zero, saying what) rather than hang.
set -u
cmd=${1:-}
dir=${2:-/tmp/frac-slurm}
me=slurm_local.sh
die() { echo "$me: error: $*" >&2; exit 1; }
# up to $1 seconds for the command that follows to succeed
wait_for() {
    n=$(($1 * 5))
    shift
    while [ "$n" -gt 0 ]; do
        "$@" >/dev/null 2>&1 && return 0
        sleep 0.2
        n=$((n - 1))
    done
    return 1
}
munge_ok() { timeout 5 munge -n </dev/null | timeout 5 unmunge; }
ping_ok() { timeout 5 scontrol -o ping | grep -q 'is UP'; }
node_idle() { timeout 5 sinfo -h -N -o %t | grep -qx 'idle'; }
stop_pid() { # the daemon whose pid file is $1, if it runs; up to 10 s
    [ -f "$1" ] || return 0
    p=$(cat "$1")
    kill "$p" 2>/dev/null || { rm -f "$1"; return 0; }
    wait_for 10 sh -c "! kill -0 $p" || { kill -9 "$p" 2>/dev/null; sleep 0.5; }
    rm -f "$1"
}

case $cmd in
start) ;;
stop)
    stop_pid "$dir/slurmd.pid"
    stop_pid "$dir/slurmctld.pid"
    stop_pid "$dir/munged.pid" # only when start started munged
    exit 0 ;;
status)
    SLURM_CONF=$dir/slurm.conf
    export SLURM_CONF
    [ -f "$SLURM_CONF" ] || { echo "no cluster in $dir"; exit 1; }
    ping_ok || { echo "the controller of $SLURM_CONF does not answer"; exit 1; }
    echo "up: export SLURM_CONF=$SLURM_CONF"
    exit 0 ;;
*) die "usage: $me start|stop|status [DIR]" ;;
esac

[ "$(id -u)" = 0 ] || die "needs root (slurmd runs jobs as their user)"
for p in slurmctld slurmd scontrol sinfo munged munge unmunge timeout; do
    command -v "$p" >/dev/null 2>&1 ||
        die "$p is not installed (Debian: apt-get install slurmctld slurmd slurm-client munge)"
done
mkdir -p "$dir/state" "$dir/spool" || exit 1
dir=$(cd "$dir" && pwd -P)
SLURM_CONF=$dir/slurm.conf
export SLURM_CONF
[ -f "$SLURM_CONF" ] && ping_ok && node_idle && { echo "export SLURM_CONF=$SLURM_CONF"; exit 0; }

# munge: the one running, or one started now as the munge user
if ! munge_ok >/dev/null 2>&1; then
    key=/etc/munge/munge.key
    if [ ! -s "$key" ]; then
        mkdir -p /etc/munge && dd if=/dev/urandom of="$key" bs=1024 count=1 2>/dev/null || die "cannot write $key"
        chmod 400 "$key"
        id munge >/dev/null 2>&1 && chown munge:munge "$key"
    fi
    mkdir -p /run/munge /var/log/munge /var/lib/munge || exit 1
    if id munge >/dev/null 2>&1; then
        chown munge:munge /run/munge /var/log/munge /var/lib/munge
        timeout 15 runuser -u munge -- munged || die "munged did not start"
    else
        timeout 15 munged --force || die "munged did not start"
    fi
    wait_for 10 munge_ok || die "munged does not answer after 10 s"
    cp /run/munge/munged.pid "$dir/munged.pid" 2>/dev/null
fi

host=$(hostname -s)
cat >"$SLURM_CONF" <<EOF
# written by tools/slurm_local.sh: a one-node cluster on $host
ClusterName=frac-local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=32 State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
stop_pid "$dir/slurmd.pid"
stop_pid "$dir/slurmctld.pid"
# a fresh cluster: no jobs or cluster name of an earlier one
rm -rf "$dir/state" "$dir/spool" && mkdir "$dir/state" "$dir/spool" || exit 1
timeout 15 slurmctld -c -f "$SLURM_CONF" || die "slurmctld did not start (see $dir/slurmctld.log)"
wait_for 15 ping_ok || die "slurmctld does not answer after 15 s (see $dir/slurmctld.log)"
timeout 15 slurmd -f "$SLURM_CONF" || die "slurmd did not start (see $dir/slurmd.log)"
wait_for 15 node_idle || die "node $host not idle after 15 s: $(sinfo -h -N -o '%t %E' 2>&1) (see $dir/slurmd.log)"
echo "export SLURM_CONF=$SLURM_CONF"
