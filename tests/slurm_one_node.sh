#!/usr/bin/env bash
# A throwaway one-node Slurm cluster on loopback for the dispatch test, following
# ../shared/cluster/slurm-one-node.md: munged + slurmctld + slurmd with their own state, ports
# and config under T (a fresh folder owned by the test).
#   tests/slurm_one_node.sh start T CTLD_PORT SLURMD_PORT   -> prints SLURM_CONF=..., exit 0 when idle
#   tests/slurm_one_node.sh stop T                           -> waits for the queue, stops the daemons
set -uo pipefail
cmd=$1 T=$2
export SLURM_CONF=$T/etc/slurm.conf

stop_pid() {  # by the saved pid only; wait until it is gone
  local f=$1 pid
  [[ -f $f ]] || return 0
  pid=$(cat "$f")
  kill "$pid" 2> /dev/null
  for _ in $(seq 100); do kill -0 "$pid" 2> /dev/null || break; sleep 0.1; done
  rm -f "$f"
}

if [[ $cmd == start ]]; then
  ctld_port=$3 d_port=$4
  mkdir -p "$T"/{etc,munge,spool/ctld,spool/d,log,run}
  chmod 755 "$T/munge"  # munged refuses a socket directory of mode 700
  mungekey -c -k "$T/munge/munge.key" || exit 1
  munged -F --key-file="$T/munge/munge.key" --socket="$T/munge/munge.socket.2" --pid-file="$T/munge/munged.pid" \
    --log-file="$T/munge/munged.log" --seed-file="$T/munge/munged.seed" > /dev/null 2>&1 &
  echo $! > "$T/run/munged.saved"
  cat > "$SLURM_CONF" <<CONF
ClusterName=test
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$T/munge/munge.socket.2
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
StateSaveLocation=$T/spool/ctld
SlurmdSpoolDir=$T/spool/d
SlurmctldPidFile=$T/run/slurmctld.pid
SlurmdPidFile=$T/run/slurmd.pid
SlurmctldLogFile=$T/log/slurmctld.log
SlurmdLogFile=$T/log/slurmd.log
ReturnToService=2
SchedulerParameters=batch_sched_delay=0
SlurmdParameters=config_overrides
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
  for _ in $(seq 50); do [[ -S $T/munge/munge.socket.2 ]] && break; sleep 0.1; done
  slurmctld -D -f "$SLURM_CONF" > "$T/log/slurmctld.out" 2>&1 &
  echo $! > "$T/run/slurmctld.saved"
  slurmd -D -N localhost -f "$SLURM_CONF" > "$T/log/slurmd.out" 2>&1 &
  echo $! > "$T/run/slurmd.saved"
  for _ in $(seq 300); do
    if [[ $(sinfo -h -o %t 2> /dev/null) == idle ]]; then
      echo "SLURM_CONF=$SLURM_CONF"
      exit 0
    fi
    sleep 0.1
  done
  echo "slurm did not come up; see $T/log" >&2
  exit 1
fi

if [[ $cmd == stop ]]; then
  for _ in $(seq 600); do [[ -z $(squeue -h 2> /dev/null) ]] && break; sleep 0.1; done
  stop_pid "$T/run/slurmd.saved"
  stop_pid "$T/run/slurmctld.saved"
  stop_pid "$T/run/munged.saved"
  exit 0
fi
echo "usage: $0 start T CTLD_PORT SLURMD_PORT | stop T" >&2
exit 2
