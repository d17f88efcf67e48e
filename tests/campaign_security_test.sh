#!/usr/bin/env bash
# Campaigns against hostile names, planted links and damaged files (issue 29; docs/reliability.md,
# "Campaigns: names are never code"):
# 1. Slurm: campaign folders named with a newline + `touch /tmp/PWNED_...`, `$(...)`, backticks,
#    `;`, spaces and quotes, and hostile --sbatch-option values, submitted to a fake sbatch (a
#    script on PATH) that runs every array task with bash in the --chdir folder as Slurm would, and
#    `campaign status` with a fake squeue: no injected command runs (no marker file), each case
#    runs in the right folder, sbatch and squeue get exactly the intended arguments; forged
#    slurm/jobs.txt lines are refused (exit 3 naming the file) before squeue runs.
# 2. Links: a symlinked case folder, a dangling .lock link, a link in the worst case's folder, a
#    `cases` link at plan time, a `collect` link, a result.json link: each refused with exit 3
#    naming the path, nothing outside touched.
# 3. Bounded work and damaged files: a FIFO as points CSV, a result.json nested 200 000 deep,
#    damaged campaign.json / result.json, a case result without the collected impact.
# 4. Messages and transactions: failed cases named by their folder, sbatch's refusal exit 3, a
#    plan cut short (file size limit) leaves nothing.
# usage: campaign_security_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$(readlink -f "$1"); src=$(readlink -f "$2")
tmp=$(mktemp -d); [ -n "${KEEP_TMP:-}" ] || trap 'rm -rf "$tmp"; rm -f /tmp/PWNED_$$_*' EXIT
mark=/tmp/PWNED_$$
fails=0
check() { if eval "$2"; then :; else echo "FAILED: $1"; fails=$((fails+1)); fi; }
no_markers() { ! compgen -G "${mark}_*" >/dev/null; }
results() { local r=("$1"/cases/*/result.json); [ -e "${r[0]}" ] && echo "${#r[@]}" || echo 0; }  # names may hold newlines
# expect_error NAME CODE PATTERN COMMAND...: exit CODE, one stderr line matching PATTERN.
expect_error() {
  local name=$1 code=$2 pattern=$3; shift 3
  "$@" >"$tmp/out.txt" 2>"$tmp/err.txt"
  local rc=$?
  if [ "$rc" != "$code" ] || [ "$(wc -l <"$tmp/err.txt")" != 1 ] || ! grep -Eq -- "$pattern" "$tmp/err.txt"; then
    echo "FAILED: $name: exit $rc (expected $code), stderr: $(head -c 400 "$tmp/err.txt")"
    fails=$((fails+1))
  fi
}
cd "$tmp" || exit 1

cp "$src/samples/two_spheres.toml" base.toml
cat >c.toml <<'TOML'
scene = "base.toml"
[product]
"impacts[0].restitution" = [0.9, 0.5]
TOML

# ---- 1. Slurm: fake sbatch and squeue on the PATH -------------------------------------------
mkdir fakebin slurmlog
cat >fakebin/sbatch <<'SH'
#!/bin/bash
# A fake sbatch: records its arguments (NUL-separated), then runs the job the way Slurm does: in
# the --chdir folder, output to the #SBATCH --output pattern (relative to that folder); a job
# array (job 4242) as each task the script run by bash with SLURM_ARRAY_TASK_ID set, a plain job
# (the collect job, 4243, arguments in sbatch_collect.args) once. FAKE_SBATCH_FAIL: refuse;
# FAKE_SBATCH_HANG: never answer (a hung slurmctld).
set -u
log=$FAKE_SLURM_LOG
script=${!#}
range=$(sed -n 's/^#SBATCH --array=\([0-9]*-[0-9]*\).*/\1/p' "$script")
if [ -n "$range" ]; then job=4242; printf '%s\0' "$@" >"$log/sbatch.args"; else job=4243; printf '%s\0' "$@" >"$log/sbatch_collect.args"; fi
if [ -n "${FAKE_SBATCH_HANG:-}" ]; then exec sleep 600; fi
if [ -n "${FAKE_SBATCH_FAIL:-}" ]; then echo "sbatch: error: Batch job submission failed: Invalid partition name specified" >&2; exit 1; fi
chdir=$PWD
for a in "${@:1:$#-1}"; do case $a in --chdir=*) chdir=${a#--chdir=} ;; esac; done
output=$(sed -n 's/^#SBATCH --output=//p' "$script")
cd "$chdir" || { echo "sbatch: error: cannot chdir" >&2; exit 1; }
printf '%s' "$PWD" >"$log/sbatch.pwd"
if [ -n "$range" ]; then
  for i in $(seq "${range%-*}" "${range#*-}"); do
    out=${output//%A/$job}; out=${out//%a/$i}
    SLURM_ARRAY_JOB_ID=$job SLURM_ARRAY_TASK_ID=$i bash "$script" >"$out" 2>&1
  done
else
  SLURM_JOB_ID=$job bash "$script" >"${output//%j/$job}" 2>&1
fi
echo "$job"
SH
cat >fakebin/squeue <<'SH'
#!/bin/bash
printf '%s\0' "$@" >"$FAKE_SLURM_LOG/squeue.args"
# FAKE_SQUEUE_FAIL: the controller cannot be reached (no answer on stdout, exit 1).
if [ -n "${FAKE_SQUEUE_FAIL:-}" ]; then echo "slurm_load_jobs error: Unable to contact slurm controller" >&2; exit 1; fi
echo "4242 RUNNING node1"
SH
chmod +x fakebin/sbatch fakebin/squeue
export PATH="$tmp/fakebin:$PATH" FAKE_SLURM_LOG="$tmp/slurmlog"

# Folder names that were shell commands in the old #SBATCH --chdir line, and ones with spaces and
# quotes (the old script ran the case in the wrong folder, or not at all).
names=(
  "$tmp/nl"$'\n'"touch ${mark}_1"$'\n'"x"
  "$tmp/sub \$(touch ${mark}_2) \`touch ${mark}_3\`; touch ${mark}_4"
  "$tmp/sp ace 'single' \"double\" #hash \\back"
)
k=0
for dir in "${names[@]}"; do
  k=$((k+1))
  mkdir -p "$dir"
  "$bin" campaign plan c.toml --out "$dir/camp" >/dev/null 2>"$tmp/err.txt" || { echo "FAILED: plan into hostile folder $k: $(cat "$tmp/err.txt")"; fails=$((fails+1)); continue; }
  camp="$dir/camp"
  rm -f slurmlog/*
  "$bin" campaign run "$camp" --executor slurm --jobs 2 \
    --sbatch-option='--comment=$(touch '"${mark}"'_5)' \
    --sbatch-option='--comment=`touch '"${mark}"'_6`' \
    --sbatch-option="--comment=a; touch ${mark}_7" \
    --sbatch-option="--comment=a b 'c' \"d\" #e" >out.txt 2>err.txt
  rc=$?
  check "folder $k: submitted (exit $rc: $(head -c 300 err.txt))" '[ $rc = 0 ] && grep -q "^submitted job 4242" out.txt'
  check "folder $k: no injected command ran" 'no_markers'
  check "folder $k: sbatch ran the tasks in the campaign folder" '[ "$(cat slurmlog/sbatch.pwd)" = "$camp" ]'
  check "folder $k: each task's output in the campaign folder's slurm/" '[ -f "$camp/slurm/4242_0.out" ] && [ -f "$camp/slurm/4242_1.out" ]'
  status=$("$bin" campaign status "$camp" 2>&1)
  check "folder $k: both cases ran in the right folder ($status)" '[[ "$status" == *"2 cases, 2 done"* ]]'
  # sbatch's arguments, exactly: the folder and each option one argument of their own.
  expected=$(printf '%s\0' --parsable "--chdir=$camp" '--comment=$(touch '"${mark}"'_5)' '--comment=`touch '"${mark}"'_6`' \
    "--comment=a; touch ${mark}_7" "--comment=a b 'c' \"d\" #e" "$camp/campaign.sbatch" | od -c)
  check "folder $k: sbatch's argument vector" '[ "$(od -c <slurmlog/sbatch.args)" = "$expected" ]'
  expected=$(printf '%s\0' --parsable "--chdir=$camp" --dependency=afterany:4242 '--comment=$(touch '"${mark}"'_5)' \
    '--comment=`touch '"${mark}"'_6`' "--comment=a; touch ${mark}_7" "--comment=a b 'c' \"d\" #e" "$camp/collect.sbatch" | od -c)
  check "folder $k: the collect job's argument vector (after the array)" '[ "$(od -c <slurmlog/sbatch_collect.args)" = "$expected" ]'
  check "folder $k: the collect job collected the campaign in its folder" \
    '[ -f "$camp/collect/cases.csv" ] && [ -f "$camp/slurm/collect_4243.out" ] && [ "$(grep -c ",done," "$camp/collect/cases.csv")" = 2 ]'
  check "folder $k: the scripts hold none of the folder's or options' text in #SBATCH lines" \
    '! grep -h "^#SBATCH" "$camp/campaign.sbatch" "$camp/collect.sbatch" | grep -q -e "$tmp" -e comment'
  check "folder $k: squeue got the job id as its own argument" \
    '[ "$(od -c <slurmlog/squeue.args)" = "$(printf "%s\0" -h -o "%i %T %R" -j 4242,4243 | od -c)" ]'
done

# A newline (or any control character) in an option cannot be made safe in a #SBATCH line nor is
# it an option: refused before anything is written or run.
camp="${names[0]}/camp"
rm -f slurmlog/* "$camp/campaign.sbatch"
expect_error "an option with a newline is refused" 3 "--sbatch-option: value 1 '--comment=x\\\\x0Atouch ${mark}_8': holds a control character" \
  "$bin" campaign run "$camp" --executor slurm --sbatch-option="--comment=x"$'\n'"touch ${mark}_8"
check "nothing submitted, no script written, no marker" '[ ! -e slurmlog/sbatch.args ] && [ ! -e "$camp/campaign.sbatch" ] && no_markers'
# --dry-run prints the submitting command, each argument quoted for sh: running it is safe.
"$bin" campaign run "$camp" --executor slurm --dry-run --sbatch-option='--comment=$(touch '"${mark}"'_9)' >out.txt
rm -f "$camp"/cases/*/result.json
out=$(cat out.txt)
bash -c "${out#*submit them with:$'\n'}" >/dev/null 2>dry.err || cat dry.err
check "--dry-run's printed command submits with the right arguments, nothing injected" \
  '[ "$(cat slurmlog/sbatch.pwd)" = "$camp" ] && no_markers && [ "$(results "$camp")" = 2 ]'

# A failed squeue is not an empty queue: each job's state is "unknown", with the failure.
st=$(FAKE_SQUEUE_FAIL=1 "$bin" campaign status "$camp" --json 2>/dev/null)
check "a failed squeue: every job 'unknown' with the reason, never []" "python3 -c '
import json, sys
d = json.loads(sys.argv[1])
assert [q[\"job\"] for q in d[\"squeue\"]] == d[\"slurm_jobs\"] and d[\"slurm_jobs\"], d
assert all(q[\"state\"] == \"unknown\" and \"exit status 1\" in q[\"reason\"] for q in d[\"squeue\"]), d
assert \"exit status 1\" in d[\"squeue_error\"], d' \"\$st\""
st=$(FAKE_SQUEUE_FAIL=1 "$bin" campaign status "$camp" 2>/dev/null)
check "a failed squeue (text): the jobs' state unknown ($st)" '[[ "$st" == *": state unknown: squeue failed (exit status 1)"* ]]'
st=$("$bin" campaign status "$camp" --json 2>/dev/null)
check "squeue answering: its lines, no error" "python3 -c '
import json, sys
d = json.loads(sys.argv[1])
assert d[\"squeue\"] == [{\"job\": \"4242\", \"state\": \"RUNNING\", \"reason\": \"node1\"}] and d[\"squeue_error\"] is None, d' \"\$st\""

# Forged job ids in slurm/jobs.txt: refused before squeue runs.
for forged in "1; touch ${mark}_10" "\$(touch ${mark}_11)" "4242 \`touch ${mark}_12\`" "-j1"; do
  rm -f slurmlog/squeue.args
  printf '4242\n%s\n' "$forged" >"$camp/slurm/jobs.txt"
  expect_error "forged job id '$forged'" 3 "/slurm/jobs.txt: line 2: '.*' is not a Slurm job id \(digits only\)" "$bin" campaign status "$camp"
  check "forged job id '$forged': squeue not run, no marker" '[ ! -e slurmlog/squeue.args ] && no_markers'
done
# ... and before sbatch runs: nothing is submitted next to a forged job list.
rm -f slurmlog/sbatch.args
expect_error "a forged job list refuses submission" 3 "/slurm/jobs.txt: line 2: '-j1' is not a Slurm job id" \
  "$bin" campaign run "$camp" --executor slurm
check "sbatch not run next to a forged job list" '[ ! -e slurmlog/sbatch.args ]'
printf '4242\n' >"$camp/slurm/jobs.txt"

# sbatch refusing: exit 3 (an external tool's failure, docs/cli.md), naming the script.
expect_error "sbatch refused" 3 "campaign\.sbatch: sbatch: sbatch refused it \(exit 1\): sbatch: error: Batch job submission failed" \
  env FAKE_SBATCH_FAIL=1 "$bin" campaign run "$camp" --executor slurm
# sbatch hanging: stopped after --sbatch-timeout-s, exit 3 naming the script (not a hang).
expect_error "sbatch hanging" 3 "campaign\.sbatch: sbatch: sbatch did not answer within 1 s \(--sbatch-timeout-s\) and was stopped" \
  env FAKE_SBATCH_HANG=1 "$bin" campaign run "$camp" --executor slurm --sbatch-timeout-s 1
expect_error "--sbatch-timeout-s needs slurm" 2 "--sbatch-timeout-s need --executor slurm" \
  "$bin" campaign run "$camp" --sbatch-timeout-s 5
expect_error "sbatch missing" 3 "^impactdeck: error: sbatch: submit: cannot run 'sbatch'" \
  env PATH=/nonexistent "$bin" campaign run "$camp" --executor slurm

# ---- 2. Links are never followed ------------------------------------------------------------
"$bin" campaign plan c.toml --out links >/dev/null
# A symlinked case folder: run-case used to delete out/ in the link's target first.
mv links/cases/0 outside0 && mkdir -p outside0/out/keep && ln -s "$tmp/outside0" links/cases/0
expect_error "run-case on a symlinked case folder" 3 "links/cases/0: symbolic link: is a symbolic link to '$tmp/outside0': refused" \
  "$bin" campaign run-case links 0
check "the link's target is untouched" '[ -d outside0/out/keep ] && [ ! -e outside0/result.json ] && [ ! -e outside0/failure.json ]'
expect_error "campaign run with a symlinked case folder" 3 "links/cases/0: symbolic link" "$bin" campaign run links --quiet
check "campaign run started nothing" '[ ! -e links/cases/1/result.json ] && [ ! -e links/cases/1/run.log ]'
rm links/cases/0 && mv outside0 links/cases/0 && rm -r links/cases/0/out
# A dangling .lock link: run-case created the file it pointed at.
ln -s "$tmp/created_outside" links/cases/1/.lock
expect_error "a dangling .lock link" 3 "links/cases/1/\.lock: symbolic link" "$bin" campaign run-case links 1
check "no file created outside" '[ ! -e created_outside ]'
rm links/cases/1/.lock
"$bin" campaign run links --quiet >/dev/null || echo "FAILED: run links"
# A link inside the worst case's folder: collect copied what it pointed at.
mkdir secret && echo "private" >secret/key.txt
for i in 0 1; do ln -s "$tmp/secret" "links/cases/$i/out/leak"; done
expect_error "collect with a link in the worst case" 3 "links/cases/[01]/out/leak: symbolic link" "$bin" campaign collect links
check "collect wrote nothing" '[ ! -e links/collect ]'
rm links/cases/*/out/leak
# A `collect` link and a result.json link.
mkdir elsewhere && ln -s "$tmp/elsewhere" links/collect
expect_error "a collect link" 3 "links/collect: symbolic link" "$bin" campaign collect links
check "nothing written through the collect link" '[ -z "$(ls -A elsewhere)" ]'
rm links/collect
mv links/cases/1/result.json result1.json && ln -s "$tmp/result1.json" links/cases/1/result.json
expect_error "a result.json link" 3 "links/cases/1/result\.json: symbolic link" "$bin" campaign collect links
expect_error "status with a result.json link" 3 "links/cases/1/result\.json: symbolic link" "$bin" campaign status links
rm links/cases/1/result.json && mv result1.json links/cases/1/result.json
"$bin" campaign collect links >/dev/null || echo "FAILED: collect links after the links were removed"
check "collect copies the worst case without its lock" '[ -f links/collect/worst_case/result.json ] && [ ! -e links/collect/worst_case/.lock ]'
# plan through a `cases` link.
mkdir planned target_of_link && ln -s "$tmp/target_of_link" planned/cases
expect_error "plan through a cases link" 3 "planned/cases: symbolic link" "$bin" campaign plan c.toml --out planned
check "nothing written through it" '[ -z "$(ls -A target_of_link)" ] && [ ! -e planned/campaign.json ]'

# ---- 3. Bounded work, damaged files ---------------------------------------------------------
mkfifo points.fifo
printf 'scene = "base.toml"\n[points]\ncsv = "points.fifo"\n' >fifo.toml
expect_error "a FIFO as points CSV" 3 "points\.fifo: file: is a FIFO" timeout 60 "$bin" campaign plan fifo.toml --out fifo_out
check "no folder made" '[ ! -e fifo_out ]'
cp -r links deep && rm -r deep/collect
# (inside the collected impact: copying it overflowed collect's stack, SIGSEGV)
python3 -c "import sys; sys.stdout.write('{\"impacts\": [{\"name\": \"impact1\", \"deep\": ' + '[' * 200000 + ']' * 200000 + '}]}')" >deep/cases/0/result.json
expect_error "a result.json nested 200 000 deep" 3 "deep/cases/0/result\.json: nesting: nested deeper than 64 levels" "$bin" campaign collect deep
cp -r links damaged && rm -r damaged/collect
printf '{"impacts": [{"name": "impact1", "max_force_N": 1' >damaged/cases/0/result.json
expect_error "a cut-short result.json" 3 "damaged/cases/0/result\.json: line 1, column [0-9]+: is not valid JSON: syntax error" "$bin" campaign collect damaged
printf '{"impacts": 3}' >damaged/cases/0/result.json
expect_error "a result.json of the wrong shape" 3 "damaged/cases/0/result\.json: key 'impacts': must be a list of impacts" "$bin" campaign collect damaged
sed 's/"name": "impact1"/"name": "impact2"/' links/cases/0/result.json >damaged/cases/0/result.json
expect_error "a result.json without the collected impact" 3 "damaged/cases/0/result\.json: key 'impacts': has no impact named 'impact1'.*; did you mean 'impact2'\?$" "$bin" campaign collect damaged
cp links/cases/0/result.json damaged/cases/0/result.json
head -c 100 links/campaign.json >damaged/campaign.json
expect_error "a cut-short campaign.json (status)" 3 "damaged/campaign\.json: line [0-9]+, column [0-9]+: is not valid JSON" "$bin" campaign status damaged
expect_error "a cut-short campaign.json (collect)" 3 "damaged/campaign\.json: line [0-9]+, column [0-9]+: is not valid JSON" "$bin" campaign collect damaged
python3 -c "import json,sys; j=json.load(open('links/campaign.json')); j['cases'][1]['id']='one'; json.dump(j, open('damaged/campaign.json','w'))"
expect_error "a campaign.json with a bad id (status)" 3 "damaged/campaign\.json: key 'cases\[1\]\.id': must be 1" "$bin" campaign status damaged
expect_error "a campaign.json with a bad id (collect)" 3 "damaged/campaign\.json: key 'cases\[1\]\.id': must be 1" "$bin" campaign collect damaged
# A failure.json that is not JSON, or that is another case's: refused by status and collect alike
# (status used to print the error as the case's reason and exit 0).
cp links/campaign.json damaged/campaign.json
mv damaged/cases/1/result.json damaged_result1.json
printf 'not json' >damaged/cases/1/failure.json
expect_error "a failure.json that is not JSON (status)" 3 "damaged/cases/1/failure\.json: line 1, column [0-9]+: is not valid JSON" "$bin" campaign status damaged
expect_error "a failure.json that is not JSON (collect)" 3 "damaged/cases/1/failure\.json: line 1, column [0-9]+: is not valid JSON" "$bin" campaign collect damaged
printf '{"id": 0, "state": "failed", "exit_code": 3, "reason": "forged"}' >damaged/cases/1/failure.json
expect_error "another case's failure.json" 3 "damaged/cases/1/failure\.json: key 'id': must be 1 \(the case's id\)" "$bin" campaign status damaged --json
rm damaged/cases/1/failure.json && mv damaged_result1.json damaged/cases/1/result.json
# A forged case folder in campaign.json: the case's folder is always cases/<id>.
python3 -c "import json; j=json.load(open('links/campaign.json')); j['cases'][1]['folder']='../../elsewhere'; json.dump(j, open('damaged/campaign.json','w'))"
expect_error "a forged case folder (status)" 3 "damaged/campaign\.json: key 'cases\[1\]\.folder': must be \"cases/1\"" "$bin" campaign status damaged
expect_error "a forged case folder (collect)" 3 "damaged/campaign\.json: key 'cases\[1\]\.folder': must be \"cases/1\"" "$bin" campaign collect damaged
check "no collect folder in the damaged campaigns" '[ ! -e deep/collect ] && [ ! -e damaged/collect ]'

# ---- 4. Messages and transactions -----------------------------------------------------------
"$bin" campaign plan c.toml --out failing >/dev/null
rm failing/cases/1/scene.toml
expect_error "failed cases are named by their folder" 3 "failing/cases/1: failure\.json: 1 of 2 case\(s\) failed \(cases 1; " \
  "$bin" campaign run failing --quiet
# A plan cut short by a write that fails (a file size limit of 1 KiB: EFBIG, as a full disk's
# ENOSPC; each case's scene.toml fits, campaign.json does not: the plan fails after staging every
# case) leaves nothing: no case folder, no campaign.json, no staging folder, not even the folder.
cat >many.toml <<'TOML'
scene = "base.toml"
[product]
"impacts[0].restitution" = [0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2]
TOML
expect_error "a plan cut short" 3 "write failed: File too large" bash -c "trap '' XFSZ; ulimit -f 1; exec \"$bin\" campaign plan many.toml --out cut"
check "the plan cut short left nothing" '[ ! -e cut ]'
mkdir cut2 && touch cut2/unrelated
expect_error "a plan cut short in an existing folder" 3 "write failed: File too large" bash -c "trap '' XFSZ; ulimit -f 1; exec \"$bin\" campaign plan many.toml --out cut2"
check "the existing folder holds what it held" '[ "$(ls -A cut2)" = unrelated ]'

[ "$fails" = 0 ] && echo "campaign_security_test: ok" || { echo "campaign_security_test: $fails failed"; exit 1; }
