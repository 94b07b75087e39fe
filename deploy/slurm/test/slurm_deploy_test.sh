#!/usr/bin/env bash
# Deploy test (label "deploy"): Debian's slurm-wlm on this machine (slurmctld + slurmd on localhost, a private
# configuration and private ports), deploy/slurm/drapegen.sbatch submitted with sbatch, the manifest checked; then a
# gap diagnosis on the job's workers, its report checked against a local run's.
# Needs root (installs slurm-wlm and munge if missing, starts munged if it is not running).
# Usage: slurm_deploy_test.sh DRAPEGEN_BINARY WORK_DIR
set -euo pipefail
DRAPEGEN=$(readlink -f "$1")
WORK=$2
SCRIPT=$(readlink -f "$(dirname "$0")/../drapegen.sbatch")
fail() { echo "slurm_deploy_test: FAILED: $*" >&2; exit 1; }

if ! command -v slurmctld > /dev/null || ! command -v munged > /dev/null || ! command -v sqlite3 > /dev/null; then
  [ "$(id -u)" -eq 0 ] || fail "slurm-wlm is not installed and this is not root"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge sqlite3 > /dev/null
fi

rm -rf "$WORK"
mkdir -p "$WORK/state" "$WORK/spool" "$WORK/run"
WORK=$(readlink -f "$WORK")
node=$(hostname -s)
cpus=$(nproc)
# Private ports (from the pid, away from Slurm's defaults 6817/6818) so that a real cluster or a parallel test is
# not disturbed.
base=$((20000 + ($$ % 20000)))
cat > "$WORK/slurm.conf" <<CONF
ClusterName=drapegentest
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$base
SlurmdPort=$((base + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation="$WORK/state"
SlurmdSpoolDir="$WORK/spool"
SlurmctldPidFile="$WORK/slurmctld.pid"
SlurmdPidFile="$WORK/slurmd.pid"
SlurmctldLogFile="$WORK/slurmctld.log"
SlurmdLogFile="$WORK/slurmd.log"
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
ReturnToService=2
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$WORK/slurm.conf

started_munge=0
if ! pgrep -x munged > /dev/null; then
  mkdir -p /run/munge && chown munge:munge /run/munge 2> /dev/null || true
  if [ ! -s /etc/munge/munge.key ]; then
    (command -v mungekey > /dev/null && mungekey --create) || dd if=/dev/urandom of=/etc/munge/munge.key bs=128 count=1
    chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
  fi
  runuser -u munge -- munged || munged --force
  started_munge=1
fi
cleanup() {
  for pidfile in "$WORK/slurmd.pid" "$WORK/slurmctld.pid"; do
    [ -s "$pidfile" ] && kill "$(cat "$pidfile")" 2> /dev/null || true
  done
  if [ "$started_munge" = 1 ] && [ -s /run/munge/munged.pid ]; then kill "$(cat /run/munge/munged.pid)" 2> /dev/null || true; fi
}
trap cleanup EXIT
slurmctld -f "$SLURM_CONF" -i
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 100); do
  state=$(sinfo -h -n "$node" -o %t 2> /dev/null || true)
  [ "$state" = "idle" ] && break
  sleep 0.2
done
[ "$state" = "idle" ] || { tail -20 "$WORK/slurmctld.log" "$WORK/slurmd.log" >&2; fail "node state '$state', not idle"; }

cat > "$WORK/run/run.toml" <<TOML
seed = 3
samples = 3
states_per_sample = 2
orientations = 1
resolution = 15
output = "$WORK/run/out"
[solver]
max_self_intersections = 1000000
TOML
cd "$WORK/run"
# Tests talk to 127.0.0.1 only: bind and connect there (a cluster uses the defaults, 0.0.0.0 and the hostname).
DRAPEGEN=$DRAPEGEN DRAPEGEN_BIND=127.0.0.1 DRAPEGEN_HOST=127.0.0.1 DRAPEGEN_GIVE_UP=60 \
  sbatch --wait --ntasks="$cpus" --cpus-per-task=1 --time=10 --output="$WORK/run/job.out" \
  --export=ALL "$SCRIPT" "$WORK/run/run.toml" || { cat "$WORK/run/job.out" >&2; fail "sbatch job failed"; }
grep -q "coordinator exit 0" job.out || { cat job.out >&2; fail "the coordinator did not complete"; }
grep -q "run complete: 6 done, 0 failed of 6 jobs" job.out || { cat job.out >&2; fail "not every job done"; }
"$DRAPEGEN" stats "$WORK/run/out/manifest.sqlite" --json > stats.json
grep -q '"done": 6' stats.json || fail "stats: $(cat stats.json)"
grep -q '"state": "complete"' stats.json || fail "run state not complete"
# Every job done names the worker that did it (the manifest's own record, read with SQLite's shell, installed above).
manifest="$WORK/run/out/manifest.sqlite"
unnamed=$(sqlite3 "$manifest" "SELECT count(*) FROM jobs WHERE state = 'done' AND coalesce(worker, '') = ''")
[ "$unnamed" -eq 0 ] || fail "the manifest has $unnamed done jobs with no worker"
workers=$(sqlite3 "$manifest" "SELECT count(DISTINCT worker) FROM jobs WHERE state = 'done'")
{ [ "$workers" -ge 1 ] && [ "$workers" -le "$cpus" ]; } || fail "the manifest names $workers workers ($cpus started)"

# --resume MANIFEST --retry-failed through the script: one job made failed (its result forgotten; its files, now
# listed nowhere, the resume removes) is computed again.
sqlite3 "$manifest" "DELETE FROM files WHERE job_id = 1; DELETE FROM results WHERE job_id = 1;
  UPDATE jobs SET state = 'failed', failure_reason = 'worker_lost' WHERE id = 1"
DRAPEGEN=$DRAPEGEN DRAPEGEN_BIND=127.0.0.1 DRAPEGEN_HOST=127.0.0.1 DRAPEGEN_GIVE_UP=60 \
  sbatch --wait --ntasks="$cpus" --cpus-per-task=1 --time=10 --output="$WORK/run/retry.out" \
  --export=ALL "$SCRIPT" --resume "$manifest" --retry-failed || { cat retry.out >&2; fail "sbatch retry job failed"; }
grep -q "1 failed job(s) pending again" retry.out || { cat retry.out >&2; fail "--retry-failed did not reach the run"; }
grep -q "run complete: 6 done, 0 failed of 6 jobs" retry.out || { cat retry.out >&2; fail "the retried job not done"; }

# A gap diagnosis whose drapes the job's workers compute (`diagnose`): its report is the local one but its seconds.
mkdir -p "$WORK/diagnose"
cd "$WORK/diagnose"
"$DRAPEGEN" reality --alpha 13923,11455,8821 --beta=-35390,-29660,-22042 --density 300 --effect bias=12 \
  --resolution 14 --seed 4 --out capture > /dev/null
small=(--capture "$WORK/diagnose/capture" --quick --resolution 10 --states 2 --evaluations 8 --refit-evaluations 4
       --candidates shear,sensor --jobs 2)
"$DRAPEGEN" diagnose "${small[@]}" --json -q > local.json
DRAPEGEN=$DRAPEGEN DRAPEGEN_BIND=127.0.0.1 DRAPEGEN_HOST=127.0.0.1 DRAPEGEN_GIVE_UP=60 \
  sbatch --wait --ntasks="$cpus" --cpus-per-task=1 --time=10 --output="$WORK/diagnose/job.out" \
  --export=ALL "$SCRIPT" diagnose "${small[@]}" --report "$WORK/diagnose/report" \
  || { cat "$WORK/diagnose/job.out" >&2; fail "sbatch diagnose job failed"; }
grep -q "coordinator exit 0" job.out || { cat job.out >&2; fail "the diagnosis did not complete"; }
grep -q "fleet: [0-9]* drapes on $cpus worker(s)" job.out || { cat job.out >&2; fail "not every worker joined"; }
varying='seconds"|simulations_main_thread'
diff <(grep -Ev "$varying" local.json) <(grep -Ev "$varying" report/report.json) > /dev/null \
  || fail "the report on the fleet differs from the local one ($WORK/diagnose)"
echo "slurm_deploy_test: ok (sbatch --ntasks=$cpus; 6 jobs done by $workers worker(s); a failed one retried by a" \
  "resume; a diagnosis on $cpus workers)"
