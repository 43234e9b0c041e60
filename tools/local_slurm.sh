#!/usr/bin/env bash
# A private single-node Slurm on this machine (Debian's slurm-wlm and munge), for tests and
# for trying the batch recipe of docs/clusters.md without a cluster. Needs root.
#
#   tools/local_slurm.sh install
#       install slurmctld, slurmd, slurm-client and munge with apt-get, only if missing
#   tools/local_slurm.sh start DIR [--ports CTLD,SLURMD] [--watch PID]
#       write a munge key and a slurm.conf under DIR, start munged, slurmctld and slurmd with
#       every path (sockets, pid and log files, state, spool) under DIR, wait until the node
#       takes jobs, and print the line `export SLURM_CONF=DIR/slurm.conf` for the clients.
#       --ports: the two TCP ports (default 6817,6818); give free ones when another Slurm
#       runs here. --watch PID: stop the daemons as soon as process PID ends (a guard that
#       keeps them from outliving a test run that is killed before it can stop them).
#   tools/local_slurm.sh stop DIR
#       stop the daemons started in DIR (by the PIDs in DIR/run/*.pid) and the guard
#
# Exit codes: 0 done; 1 failure (the message and the tail of the failing daemon's log on
# stderr); 2 usage, or a DIR with other characters than letters, digits and . _ / + -.
set -euo pipefail

packages=(slurmctld slurmd slurm-client munge)
daemons=(slurmd slurmctld munged)

die() {
  echo "local_slurm: $*" >&2
  exit 1
}

usage() {
  sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}

install_packages() {
  local missing=() p
  for p in "${packages[@]}"; do
    # not `dpkg -s`: it succeeds for a removed package whose configuration files remain
    [ "$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null)" = "install ok installed" ] || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  [ "$(id -u)" -eq 0 ] || die "installing ${missing[*]} needs root"
  echo "local_slurm: installing ${missing[*]}" >&2
  # update the package lists only when the packages are not known yet (one update at most)
  if ! apt-cache show "${missing[@]}" >/dev/null 2>&1; then
    apt-get update -qq
  fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null \
    || { apt-get update -qq && DEBIAN_FRONTEND=noninteractive \
         apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }
}

pid_of() {  # the PID recorded for daemon $2 in directory $1, if it is still running
  local file="$1/run/$2.pid" pid
  [ -s "$file" ] || return 1
  pid=$(tr -dc '0-9' <"$file")
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null && echo "$pid"
}

stop_all() {
  # all at once (each takes 1-2 s to shut down), then wait; KILL what is left after 5 s
  local dir=$1 name pid pids=() waited
  for name in watch "${daemons[@]}"; do
    pid=$(pid_of "$dir" "$name") || continue
    [ "$pid" = "$$" ] && continue   # the guard itself, stopping the daemons
    kill -TERM "$pid" 2>/dev/null || true
    pids+=("$pid")
  done
  for pid in "${pids[@]}"; do
    for waited in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -KILL "$pid" 2>/dev/null || true
  done
  rm -f "$dir"/run/*.pid
}

log_tail() {  # why a daemon did not come up
  echo "--- $1 (last lines)" >&2
  tail -n 20 "$1" >&2 2>/dev/null || true
}

wait_for_pid_file() {  # $1 dir, $2 daemon, $3 log: the daemon wrote its pid file and runs
  local i
  for i in $(seq 100); do
    pid_of "$1" "$2" >/dev/null && return 0
    sleep 0.1
  done
  log_tail "$3"
  stop_all "$1"
  die "$2 did not start (see $3)"
}

write_config() {
  local dir=$1 ctld_port=$2 slurmd_port=$3 host cpus memory
  host=$(hostname -s)
  cpus=$(nproc --all)
  memory=$(awk '/^MemTotal:/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
  cat >"$dir/slurm.conf" <<EOF
# A private single-node cluster written by tools/local_slurm.sh: everything under $dir.
ClusterName=localtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
# no cgroups, no systemd: track processes by their parent links, no CPU binding
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
# memory is consumable, as on most clusters: a job without --mem gets this much per CPU
DefMemPerCPU=$(( memory / cpus ))
MpiDefault=none
MailProg=/bin/true
ReturnToService=2
# the grace period between SIGTERM and SIGKILL (scancel, time limit): a task's trap writes
# its run record then; 2 s was too short on a loaded 2-core machine, 10 s costs nothing when
# the task ends at once
KillWait=10
# keep finished jobs visible to scontrol for ten minutes (there is no accounting database)
MinJobAge=600
SchedulerParameters=sched_min_interval=100000
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
}

start_all() {
  local dir=$1 ports=$2 watch=$3 ctld_port slurmd_port host i
  command -v slurmctld >/dev/null && command -v munged >/dev/null \
    || die "Slurm is not installed: run '$0 install' first"
  [ "$(id -u)" -eq 0 ] || die "the private Slurm runs its daemons as root"
  ctld_port=${ports%,*}
  slurmd_port=${ports#*,}
  [[ $ctld_port =~ ^[0-9]+$ && $slurmd_port =~ ^[0-9]+$ ]] || die "--ports $ports: expected two port numbers, CTLD,SLURMD"
  mkdir -p "$dir"
  dir=$(cd "$dir" && pwd)
  stop_all "$dir"   # a cluster left in this directory by an earlier run
  mkdir -p "$dir"/{munge,run,log,state,spool}
  # munged refuses a socket directory others cannot enter, and a key others can read
  chmod 755 "$dir" "$dir/munge"
  rm -f "$dir/munge/munge.key"
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$dir/munge/munge.key"
  write_config "$dir" "$ctld_port" "$slurmd_port"
  host=$(hostname -s)

  if [ -n "$watch" ]; then
    # the guard, started before the daemons: a detached loop that stops them (by the pid
    # files they write) once the watched process is gone
    nohup setsid bash -c 'while kill -0 "$1" 2>/dev/null; do sleep 1; done; exec bash "$2" stop "$3"' \
      guard "$watch" "$(cd "$(dirname "$0")" && pwd)/$(basename "$0")" "$dir" >/dev/null 2>&1 &
    echo $! >"$dir/run/watch.pid"
  fi

  munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
    --pid-file="$dir/run/munged.pid" --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" \
    || { log_tail "$dir/log/munged.log"; stop_all "$dir"; die "munged did not start"; }
  wait_for_pid_file "$dir" munged "$dir/log/munged.log"
  slurmctld -i -f "$dir/slurm.conf" || { log_tail "$dir/log/slurmctld.log"; stop_all "$dir"; die "slurmctld did not start"; }
  wait_for_pid_file "$dir" slurmctld "$dir/log/slurmctld.log"
  slurmd -f "$dir/slurm.conf" -N "$host" || { log_tail "$dir/log/slurmd.log"; stop_all "$dir"; die "slurmd did not start"; }
  wait_for_pid_file "$dir" slurmd "$dir/log/slurmd.log"

  # the node registers with the controller within a second or two; wait until it is idle
  for i in $(seq 150); do
    if [ "$(SLURM_CONF=$dir/slurm.conf sinfo -h -N -o %t 2>/dev/null)" = "idle" ]; then
      echo "export SLURM_CONF=$dir/slurm.conf"
      return 0
    fi
    sleep 0.1
  done
  log_tail "$dir/log/slurmctld.log"
  log_tail "$dir/log/slurmd.log"
  SLURM_CONF=$dir/slurm.conf sinfo -N >&2 || true
  stop_all "$dir"
  die "the node did not become idle within 15 s"
}

[ $# -ge 1 ] || usage
command=$1
shift
case "$command" in
  install)
    install_packages
    ;;
  start)
    [ $# -ge 1 ] || usage
    dir=$1
    shift
    # DIR goes into slurm.conf and the daemons' command lines: one plain path, nothing a
    # configuration line or a shell would split or read
    if [[ ! $dir =~ ^[A-Za-z0-9._/+-]+$ ]]; then
      echo "local_slurm: DIR '$dir' is not allowed; allowed: letters, digits and . _ / + -" >&2
      exit 2
    fi
    ports=6817,6818
    watch=""
    while [ $# -gt 0 ]; do
      case "$1" in
        --ports) ports=${2:?--ports needs CTLD,SLURMD}; shift 2 ;;
        --watch) watch=${2:?--watch needs a PID}; shift 2 ;;
        *) usage ;;
      esac
    done
    start_all "$dir" "$ports" "$watch"
    ;;
  stop)
    [ $# -eq 1 ] || usage
    [ -d "$1" ] && stop_all "$(cd "$1" && pwd)"
    ;;
  *)
    usage
    ;;
esac
