#!/usr/bin/env bash
# A one-node Slurm cluster on localhost for the Slurm tests (docs/testing.md §Slurm), as root and
# without systemd: its own munged (own key and socket), slurmctld and slurmd on free ports, every
# file in one temporary folder, so that it collides with nothing already running (a site's Slurm,
# another test run). A watchdog stops it after a bounded life even if `stop` is never called.
#
#   local_cluster.sh start STATE   # starts it; STATE (a file) receives the folder; prints SLURM_CONF=…
#   local_cluster.sh start-or-skip STATE  # the same; when this machine cannot run it, STATE says
#                                         # why (the tests then skip), unless CI is set: then it fails
#   local_cluster.sh stop STATE    # stops the daemons by their PIDs and removes the folder
#   local_cluster.sh check         # exit 0 when this machine can run it (root, packages), else why
set -euo pipefail
export PATH=$PATH:/usr/sbin:/sbin  # the daemons live there; a root shell's PATH may lack them (su without -)

max_life_seconds=${CAPSFLOW_SLURM_MAX_LIFE:-1800}  # the watchdog's bound: longer than any test run

die() { echo "local_cluster: $*" >&2; exit 1; }

check() {
  [[ $(id -u) -eq 0 ]] || { echo "not root (slurmd must run as root to start jobs)"; return 1; }
  local b
  for b in munged slurmctld slurmd sbatch squeue scontrol python3; do
    command -v "$b" >/dev/null || { echo "$b not found (apt-get install slurm-wlm munge)"; return 1; }
  done
}

free_port() {  # a TCP port the kernel hands out now; the daemons bind it a moment later
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

pid_of() { [[ -s $1 ]] && cat "$1" || true; }

stop_dir() {
  local dir=$1 f pid
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid" "$dir/watchdog.pid"; do
    pid=$(pid_of "$f")
    [[ -n $pid ]] && kill "$pid" 2>/dev/null || true
  done
  for _ in $(seq 50); do  # up to 5 s for a clean exit, then SIGKILL
    local alive=0
    for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
      pid=$(pid_of "$f")
      [[ -n $pid ]] && kill -0 "$pid" 2>/dev/null && alive=1
    done
    ((alive)) || break
    sleep 0.1
  done
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    pid=$(pid_of "$f")
    [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null || true
  done
  rm -rf "$dir"
}

start() {
  local state=$1 why
  why=$(check) || die "cannot start: $why"
  local dir host cpus mem ctld_port slurmd_port
  dir=$(mktemp -d /tmp/capsflow-slurm.XXXXXX)  # short: unix socket paths are limited to 108 bytes
  chmod 755 "$dir"
  echo "$dir" >"$state"
  host=$(hostname -s)
  # munged runs as the munge user on its own key and socket.
  mkdir "$dir/munge"
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chown -R munge:munge "$dir/munge"
  chmod 711 "$dir/munge"  # clients must reach the socket; the key itself stays private
  chmod 400 "$dir/munge/munge.key"
  runuser -u munge -- munged --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed" \
    </dev/null >"$dir/start.log" 2>&1 || { cat "$dir/start.log" >&2; stop_dir "$dir"; die "munged did not start"; }
  # The node as slurmd sees it (CPUs, memory): jobs that ask for memory must fit.
  read -r cpus mem < <(slurmd -C | sed -n 's/.*CPUs=\([0-9]*\).*RealMemory=\([0-9]*\).*/\1 \2/p')
  ctld_port=$(free_port)
  slurmd_port=$(free_port)
  [[ $ctld_port != "$slurmd_port" ]] || slurmd_port=$(free_port)
  mkdir -p "$dir/state" "$dir/spool"
  cat >"$dir/slurm.conf" <<CONF
ClusterName=capsflowtest
SlurmctldHost=$host
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
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
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
KillWait=10
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  # slurmd 22.05 fails with CgroupPlugin=disabled; autodetect without systemd works.
  cat >"$dir/cgroup.conf" <<CONF
CgroupPlugin=autodetect
IgnoreSystemd=yes
CONF
  export SLURM_CONF=$dir/slurm.conf
  # The daemons' own output goes to a file: an inherited pipe would keep ctest waiting for them.
  slurmctld -f "$SLURM_CONF" </dev/null >>"$dir/start.log" 2>&1 \
    || { tail -n 20 "$dir/slurmctld.log" "$dir/start.log" >&2; stop_dir "$dir"; die "slurmctld did not start"; }
  slurmd -f "$SLURM_CONF" </dev/null >>"$dir/start.log" 2>&1 \
    || { tail -n 20 "$dir/slurmd.log" "$dir/start.log" >&2; stop_dir "$dir"; die "slurmd did not start"; }
  # The watchdog: detached, so it outlives this script, and stopped by `stop`.
  setsid bash -c "sleep $max_life_seconds; exec '$0' stop '$state'" </dev/null >/dev/null 2>&1 &
  echo $! >"$dir/watchdog.pid"
  for _ in $(seq 150); do  # the node turns idle within ~3 s
    if [[ $(sinfo -h -N -o %t 2>/dev/null) == idle ]]; then
      echo "SLURM_CONF=$SLURM_CONF"
      return 0
    fi
    sleep 0.2
  done
  echo "local_cluster: the node did not become idle in 30 s; slurmd log:" >&2
  tail -n 20 "$dir/slurmd.log" >&2 || true
  stop_dir "$dir"
  rm -f "$state"
  exit 1
}

stop() {
  local state=$1
  [[ -f $state ]] || return 0
  local dir
  dir=$(cat "$state")
  if [[ $dir == /tmp/capsflow-slurm.* && -d $dir ]]; then stop_dir "$dir"; fi
  rm -f "$state"
}

case "${1:-}" in
  start) [[ $# -eq 2 ]] || die "usage: $0 start STATE"; start "$2" ;;
  start-or-skip)
    [[ $# -eq 2 ]] || die "usage: $0 start-or-skip STATE"
    if ! why=$(check) && [[ -z ${CI:-} ]]; then
      echo "skip: $why" >"$2"
      echo "local_cluster: cannot run here ($why): the Slurm tests skip"
      exit 0
    fi
    start "$2" ;;
  stop) [[ $# -eq 2 ]] || die "usage: $0 stop STATE"; stop "$2" ;;
  check) check ;;
  *) die "usage: $0 start STATE | stop STATE | check" ;;
esac
