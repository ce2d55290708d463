#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for tests of `gilab sweep --on slurm`:
#
#   scripts/slurm_local.sh start DIR   munged on a private socket and key, slurmctld and
#                                      slurmd from a slurm.conf generated in DIR (one node:
#                                      this host with its cores and memory, private ports);
#                                      prints the SLURM_CONF line clients need
#   scripts/slurm_local.sh stop DIR    stops the daemons started in DIR by their pid files
#
# It installs nothing: it needs the Debian packages slurm-wlm and munge (setup.sh installs
# them) and root, since SlurmUser is root. Everything it writes (key, state, logs, pid
# files) stays under DIR.
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action="$1"
dir="$2"

stop() {
    # slurmd first, so the controller does not see its node vanish mid-job; munged last.
    for daemon in slurmd slurmctld munged; do
        pid_file="$dir/$daemon.pid"
        [ -s "$pid_file" ] || continue
        pid="$(cat "$pid_file")"
        kill "$pid" 2>/dev/null || true
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
        rm -f "$pid_file"
    done
}

# A TCP port nobody listens on, from a range unlikely to hold system services.
free_port() {
    local port
    for _ in $(seq 100); do
        port=$(( 20000 + RANDOM % 30000 ))
        if ! ss -Hltn "sport = :$port" 2>/dev/null | grep -q .; then echo "$port"; return; fi
    done
    echo "slurm_local: no free TCP port found" >&2
    exit 1
}

wait_for() {  # wait_for SECONDS DESCRIPTION COMMAND...
    local seconds="$1" what="$2"
    shift 2
    for _ in $(seq $(( seconds * 10 ))); do
        if "$@" >/dev/null 2>&1; then return 0; fi
        sleep 0.1
    done
    echo "slurm_local: $what did not happen within ${seconds}s; logs in $dir" >&2
    return 1
}

start() {
    for tool in munged slurmctld slurmd sinfo; do
        command -v "$tool" >/dev/null || {
            echo "slurm_local: $tool not found; install the Debian packages slurm-wlm and munge" \
                 "(apt-get install slurm-wlm munge, or ./setup.sh test)" >&2
            exit 1
        }
    done
    [ "$(id -u)" -eq 0 ] || { echo "slurm_local: must run as root (the generated slurm.conf has SlurmUser=root)" >&2; exit 1; }
    mkdir -p "$dir"
    dir="$(cd "$dir" && pwd)"
    chmod 700 "$dir"
    mkdir -p "$dir/state" "$dir/spool"

    # munge: a fresh key and a socket of our own, so a system munged is neither needed nor touched.
    dd if=/dev/urandom of="$dir/munge.key" bs=1 count=1024 status=none
    chmod 400 "$dir/munge.key"
    munged --force --socket="$dir/munge.socket" --key-file="$dir/munge.key" --pid-file="$dir/munged.pid" \
           --log-file="$dir/munged.log" --seed-file="$dir/munged.seed"
    wait_for 10 "munged's socket" test -S "$dir/munge.socket"

    # The node as slurmd sees it (CPUs, sockets, cores, memory), a little memory left to the system.
    local node
    node="$(slurmd -C | head -1)"
    local memory
    memory="$(sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p' <<<"$node")"
    node="${node/RealMemory=$memory/RealMemory=$(( memory * 9 / 10 ))}"
    local host
    host="$(sed -n 's/^NodeName=\([^ ]*\).*/\1/p' <<<"$node")"

    cat >"$dir/slurm.conf" <<EOF
ClusterName=gilab-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
SchedulerType=sched/backfill
# A core that frees up takes the next array task at once; by default the controller starts
# batch jobs at most every 3 s (batch_sched_delay), which left a core idle between short
# tasks (20 tasks of 0.3 s on 2 cores: 30 s by default, 10 s with this).
SchedulerParameters=batch_sched_delay=0
MinJobAge=300
# Without a default, a job would take the whole node's memory and array tasks would run one at a time.
DefMemPerCPU=1024
MaxArraySize=100001
MaxJobCount=100000
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF="$dir/slurm.conf"
    slurmctld -c
    wait_for 20 "slurmctld answering" scontrol ping
    slurmd
    wait_for 30 "the node becoming idle" bash -c "sinfo -h -o %t | grep -qx idle"
    echo "export SLURM_CONF=$dir/slurm.conf"
}

case "$action" in
    start)
        trap 'status=$?; [ $status -eq 0 ] || stop; exit $status' EXIT
        start
        ;;
    stop) stop ;;
    *) usage ;;
esac
