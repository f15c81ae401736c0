#!/usr/bin/env bash
# Starts a one-node Slurm cluster on this machine for the Slurm job-array test, without
# systemd: munged with a freshly generated key, then slurmctld and slurmd, all as root, with
# a slurm.conf written to a state folder (the node's real CPU count and memory).
# Installs Debian's slurm-wlm and munge if they are missing. Does nothing when a cluster
# already answers.
# Usage: .ci/slurm-up.sh   (as root; state in $ADHESIM_SLURM_DIR, default /tmp/adhesim-slurm)
set -euo pipefail

state=${ADHESIM_SLURM_DIR:-/tmp/adhesim-slurm}
if [ "$(id -u)" -ne 0 ]; then
  echo "slurm-up: needs root (to run munged, slurmctld and slurmd)" >&2
  exit 1
fi
if ! command -v sbatch >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
# sinfo retries for a minute when no controller answers: a few seconds are enough here.
node_up() { timeout 5 sinfo -h -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; }
if node_up; then
  echo "slurm-up: a cluster is already running"
  exit 0
fi

mkdir -p "$state"/spool/ctld "$state"/spool/d "$state"/log /run/munge /var/lib/munge /var/log/munge
# munge: a new key, the default socket (which Slurm's auth/munge uses).
if ! munge -n </dev/null >/dev/null 2>&1; then
  dd if=/dev/urandom of="$state/munge.key" bs=1024 count=1 status=none
  chmod 400 "$state/munge.key"
  munged --force --key-file="$state/munge.key" 2>/dev/null
fi

host=$(uname -n)
node=$(slurmd -C | head -n 1)   # NodeName=<host> CPUs=... RealMemory=...
conf="$state/slurm.conf"
cat >"$conf" <<CONF
ClusterName=adhesim-ci
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
StateSaveLocation=$state/spool/ctld
SlurmdSpoolDir=$state/spool/d
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/log/slurmctld.log
SlurmdLogFile=$state/log/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
KillWait=10
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
# The commands read /etc/slurm/slurm.conf unless SLURM_CONF says otherwise.
if [ ! -e /etc/slurm/slurm.conf ] || [ -L /etc/slurm/slurm.conf ]; then
  mkdir -p /etc/slurm
  ln -sf "$conf" /etc/slurm/slurm.conf
fi
export SLURM_CONF=$conf

slurmctld -c -f "$conf"
slurmd -f "$conf"
for _ in $(seq 60); do
  if node_up; then
    sinfo
    exit 0
  fi
  sleep 1
done
echo "slurm-up: the node did not come up; logs in $state/log" >&2
tail -n 20 "$state"/log/*.log >&2 || true
exit 1
