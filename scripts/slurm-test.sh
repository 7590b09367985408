#!/usr/bin/env bash
# A real Slurm run of a latvox batch on this machine.
#
# Starts a one-node Slurm cluster on loopback — munged, slurmctld and slurmd from Debian's
# slurm-wlm and munge, with their key, configuration, state and logs in a temporary folder and
# ports that are free — submits a job file as an `sbatch --array` (each array task runs
# `latvox batch`, which takes its shard from SLURM_ARRAY_TASK_*), waits with a timeout, and
# checks that every job's output exists exactly once and is valid: each job is in exactly one
# task's summary, done, its STL passes `latvox check` (CGAL), and `latvox batch --dry-run` finds
# every job's report and outputs intact. The daemons are stopped on every exit, failure included.
#
# Usage: scripts/slurm-test.sh [LATVOX_BINARY] [WORK_DIR]
#   LATVOX_BINARY  default target/release/latvox
#   WORK_DIR       where the job file, the parts and the logs go (kept); default a new temp dir
# Needs: scripts/install-deps.sh (slurm-wlm, munge). Run as root (slurmd starts the jobs).
set -euo pipefail

say() { echo "slurm-test: $*" >&2; }
die() { say "FAILED: $*"; exit 1; }

LATVOX=$(realpath "${1:-target/release/latvox}")
[ -x "$LATVOX" ] || die "no latvox binary at $LATVOX (cargo build --release)"
WORK=${2:-$(mktemp -d /tmp/latvox-slurm-work.XXXXXX)}
mkdir -p "$WORK"
WORK=$(realpath "$WORK")
TASKS=${SLURM_TEST_TASKS:-3}
TIMEOUT=${SLURM_TEST_TIMEOUT:-240}

for tool in munged slurmctld slurmd sbatch squeue sinfo scontrol scancel; do
  command -v "$tool" >/dev/null || die "$tool not found: run scripts/install-deps.sh (Debian's slurm-wlm and munge)"
done
[ "$(id -u)" -eq 0 ] || die "run as root: slurmd must be able to start jobs"

# A test run inside a Slurm job must not inherit that job's identity.
while read -r v; do unset "$v"; done < <(compgen -e | grep '^SLURM_' || true)

CLUSTER=$(mktemp -d /tmp/latvox-slurm.XXXXXX)
chmod 755 "$CLUSTER"
export SLURM_CONF=$CLUSTER/slurm.conf
PIDS=()
JOBID=

stop() {
  local rc=$?
  set +e
  if [ -n "$JOBID" ]; then scancel "$JOBID" 2>/dev/null; fi
  # slurmd, slurmctld, munged: newest first, TERM then KILL.
  for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do kill "${PIDS[i]}" 2>/dev/null; done
  for _ in $(seq 50); do
    alive=0
    for p in "${PIDS[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive -eq 0 ] && break
    sleep 0.2
  done
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; done
  # Job steps this cluster started (slurmstepd and its children) carry its SLURM_CONF.
  for env in /proc/[0-9]*/environ; do
    if { tr '\0' '\n' <"$env"; } 2>/dev/null | grep -qx "SLURM_CONF=$SLURM_CONF"; then
      p=${env#/proc/}; p=${p%/environ}
      [ "$p" != "$$" ] && kill -9 "$p" 2>/dev/null
    fi
  done
  if [ $rc -ne 0 ]; then
    for log in "$CLUSTER"/log/*.log; do
      [ -f "$log" ] && { say "--- $(basename "$log")"; tail -n 20 "$log" >&2; }
    done
  fi
  rm -rf "$CLUSTER"
  say "daemons stopped"
  exit $rc
}
trap stop EXIT
trap 'exit 130' INT TERM

# Two free TCP ports on loopback (nothing answers a connection to them).
free_port() {
  local p
  while :; do
    p=$((20000 + RANDOM % 40000))
    (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null || { echo "$p"; return; }
  done
}
CTLD_PORT=$(free_port)
SLURMD_PORT=$(free_port)
while [ "$SLURMD_PORT" = "$CTLD_PORT" ]; do SLURMD_PORT=$(free_port); done

# munge: its own key and socket.
mkdir -p "$CLUSTER/munge" "$CLUSTER/state" "$CLUSTER/spool" "$CLUSTER/log"
chmod 700 "$CLUSTER/state" "$CLUSTER/spool"
dd if=/dev/urandom of="$CLUSTER/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$CLUSTER/munge/munge.key"
munged --foreground --force --key-file="$CLUSTER/munge/munge.key" \
  --socket="$CLUSTER/munge/munge.sock" --pid-file="$CLUSTER/munge/munged.pid" \
  --seed-file="$CLUSTER/munge/munged.seed" >"$CLUSTER/log/munged.log" 2>&1 &
PIDS+=($!)

cat >"$SLURM_CONF" <<EOF
ClusterName=latvoxtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$CLUSTER/munge/munge.sock
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$CLUSTER/state
SlurmdSpoolDir=$CLUSTER/spool
SlurmctldPidFile=$CLUSTER/slurmctld.pid
SlurmdPidFile=$CLUSTER/slurmd.pid
SlurmctldLogFile=$CLUSTER/log/slurmctld.log
SlurmdLogFile=$CLUSTER/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
InactiveLimit=0
MinJobAge=600
KillWait=5
NodeName=latvox1 NodeHostname=localhost NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=latvox Nodes=latvox1 Default=YES MaxTime=INFINITE State=UP
EOF

for _ in $(seq 50); do [ -S "$CLUSTER/munge/munge.sock" ] && break; sleep 0.1; done
[ -S "$CLUSTER/munge/munge.sock" ] || die "munged did not start"
slurmctld -D -i -f "$SLURM_CONF" >"$CLUSTER/log/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" -N latvox1 >"$CLUSTER/log/slurmd.out" 2>&1 &
PIDS+=($!)
say "cluster up in $CLUSTER (slurmctld :$CTLD_PORT, slurmd :$SLURMD_PORT)"

state=
for _ in $(seq 60); do
  state=$(sinfo -h -n latvox1 -o %t 2>/dev/null || true)
  [ "$state" = idle ] && break
  sleep 0.5
done
[ "$state" = idle ] || die "node latvox1 not idle after 30 s (state '$state')"

# The batch: 2 types × 4 densities, small parts.
cd "$WORK"
rm -rf out logs ./*-summary*
mkdir -p logs
cat >jobs.toml <<'EOF'
[defaults]
cells = 2
cell-size = 5
resolution = 16

[[sweep]]
command = "tpms"
output = "out/{type}-{structure}-{density}.stl"
type = ["gyroid", "d"]
structure = "net"
density = [0.2, 0.3, 0.4, 0.5]
EOF
NJOBS=$("$LATVOX" batch jobs.toml --dry-run | grep -c '^#')
[ "$NJOBS" -eq 8 ] || die "expected 8 jobs, the job file has $NJOBS"

# What a user submits (README shows the same script).
cat >array.sbatch <<EOF
#!/bin/bash
#SBATCH --job-name=latvox-batch
#SBATCH --array=1-$TASKS
#SBATCH --cpus-per-task=1
#SBATCH --output=logs/%A_%a.out
#SBATCH --time=00:10:00
# Each array task runs its shard of the batch: latvox reads SLURM_ARRAY_TASK_ID itself.
exec "$LATVOX" batch jobs.toml --threads "\${SLURM_CPUS_PER_TASK:-1}" --workers 1
EOF

JOBID=$(sbatch --parsable --chdir="$WORK" array.sbatch)
JOBID=${JOBID%%;*}
say "submitted array job $JOBID ($TASKS tasks, $NJOBS latvox jobs)"
start=$SECONDS
while [ -n "$(squeue -h -j "$JOBID" -o %i 2>/dev/null)" ]; do
  [ $((SECONDS - start)) -lt "$TIMEOUT" ] || die "array job $JOBID not done after $TIMEOUT s: $(squeue -j "$JOBID" 2>&1 | tail -n +2)"
  sleep 1
done
say "array job finished in $((SECONDS - start)) s"

# Every task completed with exit code 0.
tasks=$(scontrol -o show job "$JOBID")
ndone=$(grep -c 'JobState=COMPLETED' <<<"$tasks" || true)
if [ "$ndone" -ne "$TASKS" ] || grep -v -q 'ExitCode=0:0' <<<"$tasks"; then
  cat logs/*.out >&2 || true
  die "array tasks: $ndone of $TASKS completed: $(grep -o 'JobId=[0-9]* ArrayJobId=[0-9]* ArrayTaskId=[0-9]*\|JobState=[A-Z]*\|ExitCode=[0-9:]*' <<<"$tasks" | tr '\n' ' ')"
fi

# Each job in exactly one task's summary, and done there.
for k in $(seq "$TASKS"); do
  [ -f "jobs-summary-shard-$k-of-$TASKS.csv" ] || die "no summary from shard $k of $TASKS"
done
rows=$(tail -q -n +2 jobs-summary-shard-*-of-"$TASKS".csv)
[ "$(wc -l <<<"$rows")" -eq "$NJOBS" ] || die "summaries list $(wc -l <<<"$rows") jobs, not $NJOBS"
[ "$(cut -d, -f1 <<<"$rows" | sort -n | uniq | wc -l)" -eq "$NJOBS" ] || die "a job appears in two summaries"
bad=$(awk -F, '$2 != "ok"' <<<"$rows")
[ -z "$bad" ] || die "jobs not ok: $bad"

# Exactly one file per job output and report; no temporaries; every part a valid solid.
nstl=$(find out -name '*.stl' | wc -l)
njson=$(find out -name '*.json' | wc -l)
nother=$(find out -type f ! -name '*.stl' ! -name '*.json' | wc -l)
[ "$nstl" -eq "$NJOBS" ] && [ "$njson" -eq "$NJOBS" ] && [ "$nother" -eq 0 ] ||
  die "out/ holds $nstl STL, $njson reports and $nother other files for $NJOBS jobs"
for stl in out/*.stl; do
  "$LATVOX" check "$stl" >/dev/null || die "latvox check: $stl is not a valid solid"
done
todo=$("$LATVOX" batch jobs.toml --dry-run | grep -c 'to run' || true)
[ "$todo" -eq 0 ] || die "$todo jobs are not done according to their reports"
say "ok: $NJOBS jobs over $TASKS array tasks, each output once, all valid"
