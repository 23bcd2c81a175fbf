#!/usr/bin/env bash
# A throwaway single-node Slurm cluster on this machine, every piece of state under DIR.
#
#   scripts/slurm/local-cluster.sh start DIR   # prints `export SLURM_CONF=DIR/slurm.conf`
#   scripts/slurm/local-cluster.sh stop DIR    # cancels its jobs, ends its daemons
#
# Needs the Debian packages slurmctld, slurmd, slurm-client and munge (it installs
# nothing) and root, because slurmd starts jobs as their owner. It touches no file under
# /etc and no system service: munged, slurmctld and slurmd run with their key, sockets,
# spool, pid and log files in DIR, on free ports, and `stop` ends exactly the processes
# named by DIR's pid files. Point the Slurm clients at it with SLURM_CONF=DIR/slurm.conf.
#
# Made for machines without systemd or cgroups: processes are tracked through /proc and
# jobs are not confined, so a job must cap its own threads (tile.sbatch does).
set -euo pipefail

usage() {
    echo "usage: $0 start|stop DIR" >&2
    exit 2
}
[ $# -eq 2 ] || usage
cmd=$1
mkdir -p "$2"
dir=$(cd "$2" && pwd)
conf=$dir/slurm.conf

die() {
    echo "local-cluster: $*" >&2
    exit 1
}

# A TCP port nothing listens on, so two clusters (or a real Slurm) can share the machine.
free_port() {
    local port
    for _ in $(seq 100); do
        port=$((20000 + RANDOM % 30000))
        if ! ss -Hltn "sport = :$port" | grep -q .; then
            echo "$port"
            return
        fi
    done
    die "no free TCP port found"
}

alive() {
    [ -s "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null
}

start() {
    for b in munged mungekey slurmctld slurmd sinfo; do
        command -v "$b" >/dev/null ||
            die "$b is not installed (apt-get install slurmctld slurmd slurm-client munge)"
    done
    [ "$(id -u)" -eq 0 ] || die "must run as root: slurmd starts jobs as their owner"
    alive "$dir/slurmctld.pid" && die "a cluster already runs in $dir (stop it first)"
    # munged wants its socket folder searchable by all and writable by none but root.
    chmod 0755 "$dir"
    mkdir -p "$dir/log" "$dir/spool/ctld" "$dir/spool/d"
    [ -f "$dir/munge.key" ] || mungekey -c -k "$dir/munge.key"
    chmod 0600 "$dir/munge.key"
    munged --socket="$dir/munge.socket" --key-file="$dir/munge.key" \
        --pid-file="$dir/munged.pid" --log-file="$dir/log/munged.log" \
        --seed-file="$dir/munge.seed" ||
        die "munged did not start; see $dir/log/munged.log"

    local host node
    host=$(hostname -s)
    # Advertising more CPUs or memory than slurmd finds drains the node; take its own.
    node=$(slurmd -C | sed -n 's/^NodeName=[^ ]* //p')
    [ -n "$node" ] || die "slurmd -C printed no node line"
    cat >"$conf" <<EOF
# Written by scripts/slurm/local-cluster.sh: a single-node cluster, state in this folder.
ClusterName=unitrace
# The hostname may not resolve: give the address with it.
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/spool/ctld
SlurmdSpoolDir=$dir/spool/d
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# No cgroups here: track processes through /proc, confine nothing, account nothing.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
# One CPU is the unit of allocation, so array tasks of one CPU each fill the node.
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/backfill
# Start each wave of array tasks about 1 s after the last instead of 3.
SchedulerParameters=batch_sched_delay=0
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 $node State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF=$conf
    # -c: start clean, whatever an earlier cluster in DIR left in its state folder.
    slurmctld -c -f "$conf" || die "slurmctld did not start; see $dir/log/slurmctld.log"
    slurmd -f "$conf" || die "slurmd did not start; see $dir/log/slurmd.log"
    for _ in $(seq 300); do
        if [ "$(sinfo -h -N -o %T 2>/dev/null)" = idle ]; then
            echo "export SLURM_CONF=$conf"
            return
        fi
        sleep 0.1
    done
    die "the node did not become idle in 30 s; see $dir/log/slurmctld.log and slurmd.log"
}

stop_pid_file() {
    local file=$1 pid
    [ -s "$file" ] || return 0
    pid=$(cat "$file")
    if kill -0 "$pid" 2>/dev/null; then
        kill "$pid" 2>/dev/null || true
        for _ in $(seq 100); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        kill -0 "$pid" 2>/dev/null && kill -9 "$pid" 2>/dev/null
    fi
    rm -f "$file"
}

stop() {
    if [ -f "$conf" ] && alive "$dir/slurmctld.pid"; then
        export SLURM_CONF=$conf
        # Job steps outlive slurmd: cancel the jobs while slurmd can still end them.
        local jobs
        jobs=$(squeue -h -o %A 2>/dev/null || true)
        if [ -n "$jobs" ]; then
            # shellcheck disable=SC2086 # one argument per job id
            scancel $jobs 2>/dev/null || true
            for _ in $(seq 100); do
                [ -z "$(squeue -h -o %A 2>/dev/null)" ] && break
                sleep 0.1
            done
        fi
    fi
    stop_pid_file "$dir/slurmd.pid"
    stop_pid_file "$dir/slurmctld.pid"
    stop_pid_file "$dir/munged.pid"
}

case $cmd in
start) start ;;
stop) stop ;;
*) usage ;;
esac
