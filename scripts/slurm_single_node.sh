#!/usr/bin/env bash
# A throwaway single-node Slurm cluster in one folder, for trying the README's Slurm recipe on
# this machine (python/tests/test_slurm.py runs the recipe against it in CI).
#
#   scripts/slurm_single_node.sh start DIR   install slurm-wlm and munge from the distribution's
#                                            packages when missing (apt-get, needs root), write
#                                            DIR/slurm.conf, start munged, slurmctld and slurmd
#                                            with everything (key, socket, state, logs, pids) under
#                                            DIR, and wait until the node is idle
#   scripts/slurm_single_node.sh stop DIR    stop the three daemons started in DIR
#
# Then point Slurm's commands at the cluster: export SLURM_CONF=DIR/slurm.conf. The cluster has
# one node (this host, at 127.0.0.1, all its CPUs) and one partition, runs jobs as root
# (ProctrackType=proctrack/linuxproc, TaskPlugin=task/none: no cgroups needed), keeps no
# accounting, and listens on two free ports chosen at start. Nothing is written outside DIR
# except by apt-get. Exit status: 0 when done; 1 with a message on stderr saying what failed
# (the last lines of the daemon's log included).
set -euo pipefail

die() {
    echo "slurm_single_node.sh: $*" >&2
    exit 1
}

need_packages() {
    command -v slurmctld >/dev/null && command -v slurmd >/dev/null && command -v sbatch >/dev/null \
        && command -v munged >/dev/null && command -v mungekey >/dev/null && return 0
    [ "$(id -u)" = 0 ] || die "slurm-wlm and munge are not installed and this is not root: install them (apt-get install slurm-wlm munge)"
    command -v apt-get >/dev/null || die "slurm-wlm and munge are not installed and there is no apt-get to install them"
    echo "installing slurm-wlm and munge (apt-get)" >&2
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends slurm-wlm munge >/dev/null \
        || { apt-get update -q >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends slurm-wlm munge >/dev/null; } \
        || die "apt-get install slurm-wlm munge failed"
}

# A TCP port nobody listens on (the kernel picks it).
free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# Print the last lines of a log and fail.
fail_with_log() {
    local what=$1 log=$2
    echo "slurm_single_node.sh: $what; last lines of $log:" >&2
    tail -n 20 "$log" >&2 2>/dev/null || echo "(no log)" >&2
    exit 1
}

write_conf() {
    local d=$1 host=$2
    local cpus
    cpus=$(nproc)
    cat >"$d/slurm.conf" <<EOF
# Written by scripts/slurm_single_node.sh: one node (this host), one partition, no accounting.
ClusterName=vehsim
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$d/munge/munge.socket
StateSaveLocation=$d/state
SlurmdSpoolDir=$d/spool
SlurmctldPidFile=$d/slurmctld.pid
SlurmdPidFile=$d/slurmd.pid
SlurmctldLogFile=$d/log/slurmctld.log
SlurmdLogFile=$d/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
SwitchType=switch/none
ReturnToService=2
MinJobAge=600
PlugStackConfig=$d/plugstack.conf
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    : >"$d/plugstack.conf"
}

# munged refuses a socket whose folders are not all open to everyone (o+x): say which is not.
check_traversable() {
    local p=$1
    while [ "$p" != / ]; do
        [ "$(( 8#$(stat -c %a "$p") & 1 ))" = 1 ] \
            || die "$p is not open to all (mode $(stat -c %a "$p")); munged needs o+x on every folder above its socket: use another DIR"
        p=$(dirname "$p")
    done
}

start_munge() {
    local m=$1/munge
    # munged wants its socket folder open to all and its key private
    chmod 755 "$1"
    check_traversable "$1"
    mkdir -p "$m/key"
    chmod 755 "$m"
    chmod 700 "$m/key"
    [ -f "$m/key/munge.key" ] || mungekey --create --keyfile="$m/key/munge.key" || die "mungekey failed"
    munged --key-file="$m/key/munge.key" --socket="$m/munge.socket" --pid-file="$m/munged.pid" \
        --log-file="$m/munged.log" --seed-file="$m/munged.seed" \
        || fail_with_log "munged did not start" "$m/munged.log"
    munge -n -S "$m/munge.socket" | unmunge -S "$m/munge.socket" >/dev/null \
        || fail_with_log "munge cannot encode and decode a credential" "$m/munged.log"
}

# Wait until sinfo shows the node idle (at most 30 s).
wait_idle() {
    local d=$1 state=""
    for _ in $(seq 60); do
        state=$(SLURM_CONF="$d/slurm.conf" sinfo -h -o %T 2>/dev/null || true)
        [ "$state" = idle ] && return 0
        sleep 0.5
    done
    fail_with_log "the node is not idle after 30 s (state '${state:-none}')" "$d/log/slurmd.log"
}

start() {
    local d=$1
    need_packages
    mkdir -p "$d"
    d=$(cd "$d" && pwd)
    [ ! -e "$d/slurmctld.pid" ] || die "$d holds a running cluster (slurmctld.pid); stop it first"
    mkdir -p "$d/state" "$d/spool" "$d/log"
    local host
    host=$(hostname -s)
    write_conf "$d" "$host"
    start_munge "$d"
    slurmctld -f "$d/slurm.conf" || fail_with_log "slurmctld did not start" "$d/log/slurmctld.log"
    slurmd -f "$d/slurm.conf" || fail_with_log "slurmd did not start" "$d/log/slurmd.log"
    wait_idle "$d"
    echo "single-node Slurm up: export SLURM_CONF=$d/slurm.conf" >&2
}

# Stop the daemons of the given pid files together: SIGTERM to each, then SIGKILL to any still
# running after 10 s.
stop_pids() {
    local pids=() f pid
    for f in "$@"; do
        [ -f "$f" ] && pid=$(cat "$f") && kill "$pid" 2>/dev/null && pids+=("$pid")
        rm -f "$f"
    done
    for _ in $(seq 100); do
        local alive=0
        for pid in "${pids[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
        [ "$alive" = 0 ] && return 0
        sleep 0.1
    done
    for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null || true; done
}

stop() {
    local d=$1
    [ -d "$d" ] || die "$d: no such folder"
    stop_pids "$d/slurmd.pid" "$d/slurmctld.pid" "$d/munge/munged.pid"
}

case "${1:-}:${2:-}" in
    start:?*) start "$2" ;;
    stop:?*) stop "$2" ;;
    *) die "usage: $0 start DIR | stop DIR" ;;
esac
