#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for testing sweeps as job
# arrays (docs/compare.md): Debian's slurm-wlm and munge, configured for a
# container (no cgroups, localhost, every CPU of the machine), all state in
# one scratch folder. Needs root (munged runs as the munge user).
#
#   scripts/slurm-local.sh up     start munged, slurmctld and slurmd; wait until the node is idle
#   scripts/slurm-local.sh down   stop them (by their pid files) and remove the scratch folder
#
# The configuration is not installed in /etc/slurm: Slurm's commands find it
# through SLURM_CONF, which `up` prints (export it, as the cluster test does).
# OFV_SLURM_DIR picks the scratch folder (default /tmp/ofv-slurm).
set -euo pipefail

dir=${OFV_SLURM_DIR:-/tmp/ofv-slurm}
conf=$dir/slurm.conf

down() {
  for daemon in slurmd slurmctld munged; do
    local pid_file=$dir/$daemon.pid
    [ "$daemon" = munged ] && pid_file=$dir/munge/munged.pid
    [ -f "$pid_file" ] || continue
    local pid
    pid=$(cat "$pid_file")
    if kill "$pid" 2>/dev/null; then
      for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null || true
    fi
  done
  rm -rf "$dir"
}

up() {
  [ "$(id -u)" -eq 0 ] || { echo "slurm-local: needs root" >&2; exit 2; }
  for tool in munged slurmctld slurmd sinfo sbatch; do
    command -v "$tool" >/dev/null || { echo "slurm-local: $tool not found (apt-get install slurm-wlm munge)" >&2; exit 2; }
  done
  down
  mkdir -p "$dir"/{state,spool,log,munge}
  chmod 755 "$dir"
  runuser -u munge -- test -x "$dir" || { echo "slurm-local: the munge user cannot reach $dir (a parent folder is private)" >&2; exit 2; }
  chown munge:munge "$dir/munge"
  runuser -u munge -- /usr/sbin/munged --socket="$dir/munge/munge.socket" --pid-file="$dir/munge/munged.pid" \
    --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munge.seed"
  local host cpus
  host=$(hostname)
  cpus=$(nproc)
  cat > "$conf" <<CONF
ClusterName=ofv-local
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
ReturnToService=2
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
MpiDefault=none
NodeName=$host CPUs=$cpus State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$conf
  slurmctld
  slurmd
  for _ in $(seq 100); do
    if sinfo -h -o '%t' 2>/dev/null | grep -qx idle; then
      echo "slurm-local: node $host idle with $cpus CPUs; export SLURM_CONF=$conf"
      return 0
    fi
    sleep 0.2
  done
  echo "slurm-local: the node did not come up within 20 s; logs in $dir/log:" >&2
  tail -n 5 "$dir"/log/*.log "$dir"/munge/munged.log >&2 || true
  down
  exit 1
}

case "${1:-}" in
  up) up ;;
  down) down ;;
  *) echo "usage: $0 up|down" >&2; exit 2 ;;
esac
