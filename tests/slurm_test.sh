#!/usr/bin/env bash
# A real one-node Slurm cluster started by the test itself (Debian's slurm-wlm and munge): munged
# with its own key and socket, slurmctld and slurmd on localhost with a minimal slurm.conf
# (proctrack/linuxproc, task/none, no cgroups), every state folder in a temporary folder. A 4-case
# campaign is submitted with `campaign run --executor slurm`, waited for and collected; its table
# must equal the local executor's. The daemons are stopped by PID at the end. If they cannot
# start, the test FAILS and says why: it is never skipped.
# MaxArraySize is 3 (array indices 0-2): each campaign is split into job arrays of at most 2 tasks.
# A campaign with a [slurm] table (partition, time, mem, a setup line that leaves a marker,
# cases_per_task = 2 over 5 cases: 3 tasks in 2 arrays) runs with its collect as a dependent job;
# a held campaign is cancelled with `campaign cancel` and never runs.
# Usage: slurm_test.sh IMPACTDECK SOURCE_DIR
set -uo pipefail
exe=$(readlink -f "$1"); src=$(readlink -f "$2")
tmp=$(mktemp -d /tmp/impactdeck-slurm.XXXXXX)
chmod 755 "$tmp"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$p" 2>/dev/null
  done
  rm -rf "$tmp"
}
trap cleanup EXIT
fail() {
  echo "FAIL: $*" >&2
  for f in munged.log slurmctld.log slurmd.log; do
    [ -f "$tmp/$f" ] && { echo "--- tail of $f:" >&2; tail -n 15 "$tmp/$f" >&2; }
  done
  exit 1
}
for p in munged mungekey slurmctld slurmd sbatch squeue; do
  command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] || fail "$p not found: install slurm-wlm and munge (scripts/packages.txt)"
done
export PATH="$PATH:/usr/sbin"

# munge: own key, socket, log, pid and seed files.
mkdir -p "$tmp/munge" && chmod 700 "$tmp/munge"
mungekey --create --keyfile="$tmp/munge/munge.key" 2>"$tmp/munged.log" || fail "mungekey could not create a key"
munged --force --key-file="$tmp/munge/munge.key" --socket="$tmp/munge/munge.socket" \
  --pid-file="$tmp/munge/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge/munged.seed" \
  >>"$tmp/munged.log" 2>&1 || fail "munged did not start"
for _ in $(seq 50); do [ -s "$tmp/munge/munged.pid" ] && break; sleep 0.1; done
[ -s "$tmp/munge/munged.pid" ] || fail "munged wrote no pid file"
pids+=("$(cat "$tmp/munge/munged.pid")")

# Slurm: free ports, this host as the only node, the current user as SlurmUser.
port=$(python3 -c 'import socket
s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
dport=$(python3 -c 'import socket
s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
node=$(hostname -s)
mkdir -p "$tmp/state" "$tmp/spool"
cat >"$tmp/slurm.conf" <<CONF
ClusterName=impactdecktest
SlurmctldHost=$node(127.0.0.1)
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
SlurmctldPort=$port
SlurmdPort=$dport
AuthType=auth/munge
AuthInfo=socket=$tmp/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
MaxArraySize=3
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 RealMemory=1000 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$tmp/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >>"$tmp/slurmctld.log" 2>&1 &
pids+=($!)
slurmd -D -N "$node" -f "$SLURM_CONF" >>"$tmp/slurmd.log" 2>&1 &
pids+=($!)
up=0
for _ in $(seq 150); do
  kill -0 "${pids[1]}" 2>/dev/null || fail "slurmctld exited"
  kill -0 "${pids[2]}" 2>/dev/null || fail "slurmd exited"
  if sinfo -h -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then up=1; break; fi
  sleep 0.2
done
[ $up = 1 ] || fail "the node did not become idle within 30 s (sinfo: $(sinfo -h 2>&1 | tr '\n' ' '))"

# The same 4-case campaign, run here and through Slurm.
cd "$tmp" || fail "no temp folder"
cp "$src/samples/two_spheres.toml" base.toml
cat >campaign.toml <<'TOML'
scene = "base.toml"
[product]
"bodies[1].velocity_m_s" = [[-0.5, 0, 0], [-1.5, 0, 0]]
"impacts[0].restitution" = [1.0, 0.7]
TOML
"$exe" campaign plan campaign.toml --out local >/dev/null || fail "campaign plan (local)"
"$exe" campaign plan campaign.toml --out slurm >/dev/null || fail "campaign plan (slurm)"
"$exe" campaign run local --jobs 2 --quiet >/dev/null || fail "campaign run (local)"
out=$("$exe" campaign run slurm --executor slurm --jobs 2) || fail "campaign run --executor slurm: $out"
echo "$out"
job=$(echo "$out" | sed -n 's/^submitted job \([0-9]*\).*/\1/p' | head -n 1)
[ -n "$job" ] || fail "no job id in: $out"
# 4 tasks, MaxArraySize 3 (indices 0-2): two arrays of 2 tasks, then the collect job.
[ "$(grep -c '^submitted job' <<<"$out")" = 3 ] || fail "expected 2 arrays and a collect job: $out"
grep -q '^#SBATCH --array=0-1%2$' slurm/campaign.sbatch || fail "campaign.sbatch lacks '#SBATCH --array=0-1%2'"
grep -q '^#SBATCH --array=0-1%2$' slurm/campaign.1.sbatch || fail "campaign.1.sbatch lacks '#SBATCH --array=0-1%2'"
grep -q "^  '$exe' campaign run-case '$tmp/slurm' \"\$id\" --threads 1 || rc=\$?\$" slurm/campaign.sbatch ||
  fail "campaign.sbatch does not run '$exe campaign run-case DIR \$id'"
# wait_jobs DIR: until none of the campaign's jobs (slurm/jobs.txt) is queued or running.
wait_jobs() {
  local ids; ids=$(paste -sd, "$1/slurm/jobs.txt")
  for _ in $(seq 300); do
    [ -z "$(squeue -h -j "$ids" 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  fail "jobs $ids still queued or running after 60 s: $(squeue -h 2>&1 | tr '\n' ' ')"
}
wait_jobs slurm
status=$("$exe" campaign status slurm) || fail "campaign status"
echo "$status"
echo "$status" | grep -q '4 cases, 4 done' || { cat slurm/slurm/*.out >&2 2>/dev/null; fail "not every case done under Slurm"; }
"$exe" campaign collect local >/dev/null || fail "campaign collect (local)"
"$exe" campaign collect slurm >/dev/null || fail "campaign collect (slurm)"
diff local/collect/cases.csv slurm/collect/cases.csv >&2 || fail "the Slurm table differs from the local one"
[ "$(wc -l <slurm/collect/cases.csv)" = 5 ] || fail "the table should hold a header and 4 rows"
[ -f "slurm/slurm/${job}_0.out" ] || fail "no task output in the campaign folder's slurm/ (--output is relative to --chdir)"

# A campaign folder whose name holds spaces, quotes, \$(...), a backtick and a newline: the real
# sbatch gets it as its --chdir argument, the script quotes it for sh; every case runs there and
# no injected command runs (tests/campaign_security_test.sh does the same under a fake sbatch).
mark="$tmp/PWNED_slurm"
hostile="$tmp/sp ace 'q' \"d\" \$(touch $mark.1) \`touch $mark.2\`"$'\n'"touch $mark.3"
mkdir -p "$hostile"
"$exe" campaign plan campaign.toml --out "$hostile/c" >/dev/null || fail "campaign plan (hostile folder name)"
out=$("$exe" campaign run "$hostile/c" --executor slurm --sbatch-option='--comment=$(touch '"$mark"'.4)') ||
  fail "campaign run --executor slurm (hostile folder name): $out"
job2=$(echo "$out" | sed -n 's/^submitted job \([0-9]*\).*/\1/p' | head -n 1)
[ -n "$job2" ] || fail "no job id in: $out"
wait_jobs "$hostile/c"
status=$("$exe" campaign status "$hostile/c") || fail "campaign status (hostile folder name)"
echo "$status" | grep -q '4 cases, 4 done' || fail "not every case done in the hostile folder: $status"
[ -f "$hostile/c/slurm/${job2}_0.out" ] || fail "the tasks' output is not in the hostile folder's slurm/"
! compgen -G "$mark.*" >/dev/null || fail "an injected command ran: $(compgen -G "$mark.*")"
[ -f "$hostile/c/collect/cases.csv" ] || fail "the dependent collect job did not collect the hostile folder"

# [slurm]: partition, time, mem, a setup line leaving a marker per job, 2 cases per task over 5
# cases (3 tasks: arrays of 2 and 1 under MaxArraySize 3), collect as a dependent job.
cat >sl.toml <<'TOML'
scene = "base.toml"
[product]
"impacts[0].restitution" = [1.0, 0.9, 0.8, 0.7, 0.6]
[slurm]
partition = "test"
time = "0-00:10:00"
mem = "200M"
setup = ["touch \"setup-ran-$SLURM_JOB_ID\""]
cases_per_task = 2
TOML
"$exe" campaign plan sl.toml --out sl >/dev/null || fail "campaign plan (with [slurm])"
out=$("$exe" campaign run sl --executor slurm) || fail "campaign run --executor slurm (with [slurm]): $out"
echo "$out"
mapfile -t jobs3 < <(sed -n 's/^submitted job \([0-9]*\).*/\1/p' <<<"$out")
[ "${#jobs3[@]}" = 3 ] || fail "expected 2 arrays and a collect job: $out"
grep -q "cases 0 ... 3)" <<<"$out" && grep -q "cases 4 ... 4)" <<<"$out" || fail "the arrays should cover cases 0-3 and 4: $out"
dep=$(scontrol show job "${jobs3[2]}" 2>&1 | tr ' ' '\n' | grep '^Dependency=')
[[ "$dep" == *"afterany:${jobs3[0]}"*"afterany:${jobs3[1]}"* || "$dep" == *"afterany:${jobs3[0]}"*":${jobs3[1]}"* ]] ||
  fail "the collect job ${jobs3[2]} does not depend on ${jobs3[0]} and ${jobs3[1]}: '$dep'"
for f in sl/campaign.sbatch sl/campaign.1.sbatch sl/collect.sbatch; do
  for l in '#SBATCH --partition=test' '#SBATCH --time=0-00:10:00' '#SBATCH --mem=200M' 'touch "setup-ran-$SLURM_JOB_ID"'; do
    grep -qxF "$l" "$f" || fail "$f lacks the line '$l'"
  done
done
grep -q '^#SBATCH --array=0-1$' sl/campaign.sbatch && grep -q '^#SBATCH --array=0-0$' sl/campaign.1.sbatch ||
  fail "expected arrays 0-1 and 0-0: $(grep -h array sl/*.sbatch)"
wait_jobs sl
status=$("$exe" campaign status sl --json) || fail "campaign status --json"
python3 -c 'import json, sys
d = json.loads(sys.argv[1])
assert d["case_count"] == 5 and d["counts"] == {"done": 5, "failed": 0, "running": 0, "planned": 0}, d["counts"]
assert [c["state"] for c in d["cases"]] == ["done"] * 5
assert d["slurm_jobs"] == sys.argv[2:], (d["slurm_jobs"], sys.argv[2:])' "$status" "${jobs3[@]}" ||
  fail "campaign status --json: $status"
[ "$(ls sl/setup-ran-* 2>/dev/null | wc -l)" = 4 ] || fail "the setup line did not run once per job (3 tasks + collect): $(ls sl)"
# Each task ran its 2 cases in sequence (the last task 1): the cases' lines in the tasks' outputs.
grep -qx "case 0: done" "sl/slurm/${jobs3[0]}_0.out" && grep -qx "case 1: done" "sl/slurm/${jobs3[0]}_0.out" &&
  grep -qx "case 2: done" "sl/slurm/${jobs3[0]}_1.out" && grep -qx "case 3: done" "sl/slurm/${jobs3[0]}_1.out" &&
  grep -qx "case 4: done" "sl/slurm/${jobs3[1]}_0.out" || fail "the tasks did not run cases 0-1, 2-3 and 4: $(head sl/slurm/*.out)"
# The collect job ran after every case: its table has 5 done rows, its log is in slurm/.
[ -f "sl/slurm/collect_${jobs3[2]}.out" ] || fail "no output of the collect job"
[ "$(grep -c '^[0-9]*,done,' sl/collect/cases.csv)" = 5 ] || fail "the dependent collect did not see 5 done cases: $(cat sl/collect/cases.csv)"
coll=$("$exe" campaign collect sl --json) || fail "campaign collect --json"
python3 -c 'import json, sys
d = json.loads(sys.argv[1])
assert (d["done"], d["failed"], d["pending"]) == (5, 0, 0)
assert d["csv"].endswith("/sl/collect/cases.csv") and d["worst_case"]["by"] == "max_force_N"
assert d["worst_case"]["id"] in range(5) and d["worst_case"]["value"] > 0' "$coll" || fail "campaign collect --json: $coll"

# campaign cancel: a held campaign (never started) is cancelled; released afterwards, nothing runs.
"$exe" campaign plan campaign.toml --out held >/dev/null || fail "campaign plan (held)"
out=$("$exe" campaign run held --executor slurm --sbatch-option=--hold) || fail "campaign run (held): $out"
ids=$(paste -sd, held/slurm/jobs.txt)
[ "$(squeue -h -j "$ids" -o %i | wc -l)" -ge 3 ] || fail "the held jobs $ids are not queued: $(squeue -h 2>&1 | tr '\n' ' ')"
out=$("$exe" campaign cancel held) || fail "campaign cancel: $out"
[ "$out" = "cancelled job(s) $(paste -sd' ' held/slurm/jobs.txt)" ] || fail "campaign cancel printed: $out"
wait_jobs held
scontrol release "$(paste -sd, held/slurm/jobs.txt)" >/dev/null 2>&1
sleep 2
! compgen -G "held/cases/*/result.json" >/dev/null || fail "a cancelled case ran"
[ -z "$(squeue -h -j "$ids" 2>/dev/null)" ] || fail "cancelled jobs still queued: $(squeue -h -j "$ids")"
echo "ok: Slurm job $job ran 4 cases in 2 arrays; the table equals the local executor's; job $job2 ran 4 cases in a hostile folder, nothing injected; [slurm] campaign ${jobs3[*]}: 5 cases, 2 per task, setup ran, dependent collect; held campaign cancelled"
