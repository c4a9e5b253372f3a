#!/usr/bin/env bash
# A one-node Slurm on this machine, for the tests and for trying the cluster path without a
# cluster: installs Slurm and munge when missing (root, apt), writes a minimal configuration
# into a temporary directory, starts munged, slurmctld and slurmd directly (no systemd), and
# waits until the node is idle.
#
#   scripts/slurm-local.sh -- COMMAND ARGS...   run COMMAND with that Slurm up (SLURM_CONF set),
#                                               stop it, exit with COMMAND's status
#   scripts/slurm-local.sh                      start it and leave it running; prints the
#                                               SLURM_CONF to export and how to stop it
#   scripts/slurm-local.sh --stop DIR           stop one left running (DIR as printed)
#   scripts/slurm-local.sh --install            only install the packages when missing
#
# The node is this host (its short name) with all its logical CPUs, in one partition "local";
# SLURM_LOCAL_CPUS=N declares N instead (more than there are oversubscribes them: the tests use
# it so that a job sleeping out its time limit does not hold up the others).
# There is no accounting daemon, so `sacct` does not work: use `sbatch --wait` (it returns the
# job's exit status), `squeue` and `scontrol show job`.
set -euo pipefail

die() {
    echo "slurm-local: $*" >&2
    exit 2
}

# Stops the daemons started in $1, waits until they are gone (up to 10 s) and removes $1.
cleanup() {
    local dir=$1 pids=() pid
    for pidfile in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munged.pid"; do
        if [ -f "$pidfile" ]; then
            pids+=("$(cat "$pidfile")")
        fi
    done
    [ -f "$dir/slurm.conf" ] && SLURM_CONF="$dir/slurm.conf" scontrol shutdown >/dev/null 2>&1 || true
    for pid in ${pids[@]+"${pids[@]}"}; do
        kill "$pid" 2>/dev/null || true
    done
    for _ in $(seq 100); do
        local alive=0
        for pid in ${pids[@]+"${pids[@]}"}; do
            kill -0 "$pid" 2>/dev/null && alive=1
        done
        [ "$alive" = 0 ] && break
        sleep 0.1
    done
    rm -rf "$dir"
}

stop() {
    [ -f "$1/slurm.conf" ] || die "$1 is not a directory this script started"
    cleanup "$1"
}

install() {
    if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null \
        || ! command -v sbatch >/dev/null || ! command -v munged >/dev/null; then
        [ "$(id -u)" = 0 ] || die "Slurm is not installed; run as root to install it (apt), or install slurm-wlm and munge"
        echo "installing Slurm and munge (apt)..." >&2
        export DEBIAN_FRONTEND=noninteractive
        apt-get update -qq >/dev/null
        apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null
    fi
}

if [ "${1:-}" = "--install" ]; then
    install
    exit 0
fi
if [ "${1:-}" = "--stop" ]; then
    [ $# -eq 2 ] || die "usage: scripts/slurm-local.sh --stop DIR"
    stop "$2"
    exit 0
fi
command=()
if [ $# -gt 0 ]; then
    [ "$1" = "--" ] || die "usage: scripts/slurm-local.sh [-- COMMAND ARGS...] | --stop DIR | --install"
    shift
    [ $# -gt 0 ] || die "nothing to run after --"
    command=("$@")
fi

install
[ "$(id -u)" = 0 ] || die "starting slurmd needs root"
if pgrep -x slurmctld >/dev/null || pgrep -x slurmd >/dev/null; then
    die "a Slurm daemon is already running on this machine; stop it first (scripts/slurm-local.sh --stop DIR for one this script left running)"
fi

# The daemons talk over the loopback address, whether or not the host name resolves.
dir=$(mktemp -d /tmp/slurm-local.XXXXXX)
# Whatever fails from here on leaves nothing running and nothing behind.
trap 'cleanup "$dir"' EXIT
chmod 755 "$dir"
host=$(hostname -s)
cpus=${SLURM_LOCAL_CPUS:-$(nproc --all)}
[[ "$cpus" =~ ^[1-9][0-9]*$ ]] || die "SLURM_LOCAL_CPUS must be a whole number of at least 1"

# munge: its own key (a private directory) and socket (one every user can reach) in $dir, run
# as the munge user as it insists.
mkdir -p "$dir/munge" "$dir/munge-socket"
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$dir/munge"
chmod 400 "$dir/munge/munge.key"
chmod 755 "$dir/munge-socket"
chown -R munge:munge "$dir/munge" "$dir/munge-socket"
runuser -u munge -- munged --key-file="$dir/munge/munge.key" \
    --socket="$dir/munge-socket/munge.socket" --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" ||
    die "munged did not start; see $dir/munge/munged.log"
ln -s "$dir/munge/munged.pid" "$dir/munged.pid"

mkdir -p "$dir/state" "$dir/spool"
cat >"$dir/slurm.conf" <<EOF
ClusterName=local
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge-socket/munge.socket
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
MpiDefault=none
MinJobAge=600
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$dir/slurm.conf"
slurmctld || die "slurmctld did not start; see $dir/slurmctld.log"
slurmd || die "slurmd did not start; see $dir/slurmd.log"

ready=0
for _ in $(seq 150); do
    state=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
    if [ "$state" = "idle" ]; then
        ready=1
        break
    fi
    sleep 0.2
done
if [ "$ready" = 0 ]; then
    echo "slurm-local: the node did not become idle (state: ${state:-unknown}); logs:" >&2
    tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
    exit 1
fi

if [ ${#command[@]} -eq 0 ]; then
    trap - EXIT
    echo "Slurm is up: node $host ($cpus CPUs), partition local."
    echo "  export SLURM_CONF=$dir/slurm.conf"
    echo "  scripts/slurm-local.sh --stop $dir      (when done)"
    exit 0
fi
status=0
"${command[@]}" || status=$?
exit "$status"
