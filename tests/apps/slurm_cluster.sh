#!/usr/bin/env bash
# A one-node Slurm cluster on the loopback address, for tests: munged with a generated key,
# slurmctld and slurmd as the current user (root here), all state, sockets and logs in DIR, no
# systemd. Needs Debian's slurm-wlm (which brings munge); installs nothing.
#   slurm_cluster.sh start DIR   # writes DIR/slurm.conf; export SLURM_CONF=DIR/slurm.conf to use it
#   slurm_cluster.sh stop DIR    # ends the daemons started by 'start' (by their pid files)
set -u
cmd=$1; dir=$(mkdir -p "$2" && cd "$2" && pwd)
stop() {
  local f pids="" t p alive
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$f" ] && pids="$pids $(cat "$f")"
  done
  [ -n "$pids" ] && kill $pids 2>/dev/null
  for t in $(seq 100); do  # gone within 5 s; an exited daemon may stay a zombie (state Z) until
    alive=0                # the container's init reaps it, up to a second later: that counts as gone
    for p in $pids; do
      [ -e "/proc/$p" ] && [ "$(cut -d' ' -f3 "/proc/$p/stat" 2>/dev/null)" != Z ] && alive=1
    done
    [ $alive = 0 ] && break
    sleep 0.05
  done
  return 0
}
case "$cmd" in
stop) stop; exit 0 ;;
start) ;;
*) echo "slurm_cluster.sh: start or stop, not $cmd" >&2; exit 2 ;;
esac

rm -rf "$dir"/{munge,state,spool,log}; mkdir -p "$dir"/{munge,state,spool,log}
chmod 755 "$dir/munge"
mungekey --create --keyfile="$dir/munge/munge.key" --force || exit 1
chmod 600 "$dir/munge/munge.key"
munged --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" --pid-file="$dir/munge/munged.pid" \
       --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/seed" --force || exit 1

# Ports from the process id, so that two test runs on one machine do not meet.
port=$((20000 + ($$ % 20000) * 2))
host=$(hostname -s)
cat > "$dir/slurm.conf" <<CONF
ClusterName=vdbhairtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
# Schedule on the next pass after a submission or a job's end (Slurm's default batch_sched_delay
# waits 3 s between passes). The first pass still comes 3 s after slurmctld starts.
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
# The node claims at least 4 CPUs (config_overrides: slurmd takes the configured count over the
# hardware's), so that a test's 4-task array starts in one scheduling pass on a 2-core machine.
SlurmdParameters=config_overrides
SwitchType=switch/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(( $(nproc) > 4 ? $(nproc) : 4 )) RealMemory=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 * 9 / 10 )) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=YES
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld -f "$SLURM_CONF" || { stop; exit 1; }
slurmd -f "$SLURM_CONF" || { stop; exit 1; }
# Ready when the node is idle.
for t in $(seq 100); do
  sinfo -h -o %t 2>/dev/null | grep -q idle && exit 0
  sleep 0.1
done
echo "slurm_cluster.sh: the node did not come up in 10 s" >&2
stop
exit 1
