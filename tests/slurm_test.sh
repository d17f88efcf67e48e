#!/usr/bin/env bash
# A real one-node Slurm cluster started by the test itself (Debian's slurm-wlm and munge): munged
# with its own key and socket, slurmctld and slurmd on localhost with a minimal slurm.conf
# (proctrack/linuxproc, task/none, no cgroups), every state folder in a temporary folder. A 4-case
# campaign is submitted with `campaign run --executor slurm`, waited for and collected; its table
# must equal the local executor's. The daemons are stopped by PID at the end. If they cannot
# start, the test FAILS and says why: it is never skipped.
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
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
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
job=$(echo "$out" | sed -n 's/^submitted job \([0-9]*\).*/\1/p')
[ -n "$job" ] || fail "no job id in: $out"
grep -q '^#SBATCH --array=0-3%2$' slurm/campaign.sbatch || fail "campaign.sbatch lacks '#SBATCH --array=0-3%2'"
grep -q "^exec '$exe' campaign run-case '$tmp/slurm' \"\$SLURM_ARRAY_TASK_ID\"" slurm/campaign.sbatch ||
  fail "campaign.sbatch does not run '$exe campaign run-case DIR \$SLURM_ARRAY_TASK_ID'"
done_=0
for _ in $(seq 200); do
  if [ -z "$(squeue -h -j "$job" 2>/dev/null)" ]; then done_=1; break; fi
  sleep 0.2
done
[ $done_ = 1 ] || fail "job $job still queued or running after 40 s: $(squeue -h 2>&1 | tr '\n' ' ')"
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
job2=$(echo "$out" | sed -n 's/^submitted job \([0-9]*\).*/\1/p')
[ -n "$job2" ] || fail "no job id in: $out"
for _ in $(seq 200); do
  [ -z "$(squeue -h -j "$job2" 2>/dev/null)" ] && break
  sleep 0.2
done
status=$("$exe" campaign status "$hostile/c") || fail "campaign status (hostile folder name)"
echo "$status" | grep -q '4 cases, 4 done' || fail "not every case done in the hostile folder: $status"
[ -f "$hostile/c/slurm/${job2}_0.out" ] || fail "the tasks' output is not in the hostile folder's slurm/"
! compgen -G "$mark.*" >/dev/null || fail "an injected command ran: $(compgen -G "$mark.*")"
echo "ok: Slurm job $job ran 4 cases; the table equals the local executor's; job $job2 ran 4 cases in a hostile folder, nothing injected"
