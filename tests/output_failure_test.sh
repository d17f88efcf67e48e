#!/usr/bin/env bash
# Failures found after the work is done must not leave a half-published run (issue 29):
#  - a stdout that cannot be written (/dev/full, closed) is refused before the run, exit 3 naming
#    stdout, and the output folder stays as it was;
#  - a stdout that fails only when `run`, `sweep`, `study table1` or `fem-check` writes its report
#    (a broken pipe) rolls the run back: they write stdout before their commit (fem-check:
#    tests/fem_samples_test.sh);
#  - `sweep` onto a full file system (a tmpfs of 256 KiB, mounted in a private mount namespace
#    when the test may mount) exits 3 naming the file that could not be written, and leaves the
#    folder as it was.
# usage: output_failure_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$src/tests/check_lib.sh"
scene=$src/samples/two_spheres.toml
sweep_scene=$src/samples/fig4_sweep.toml

# A folder with an earlier run's file in it: it must come back byte for byte.
out=$tmp/out
mkdir -p "$out"
echo "earlier run" >"$out/force_two_spheres.csv"
before=$(cd "$out" && ls -A && cat force_two_spheres.csv)
unchanged() { [ "$(cd "$out" && ls -A && cat force_two_spheres.csv)" = "$before" ]; }

"$bin" run "$scene" --out "$out" --json >/dev/full 2>"$tmp/err"; rc=$?
check "run --json > /dev/full: exit 3" [ "$rc" = 3 ]
check "run --json > /dev/full: one line naming stdout" \
  grep -qx "impactdeck: error: stdout: write failed: No space left on device (checked before the run: nothing was computed or written)" "$tmp/err"
check "run --json > /dev/full: the output folder as before" unchanged

"$bin" run "$scene" --out "$out" >&- 2>"$tmp/err"; rc=$?
check "run with stdout closed: exit 3" [ "$rc" = 3 ]
check "run with stdout closed: names stdout" grep -q "^impactdeck: error: stdout: write failed: Bad file descriptor" "$tmp/err"
check "run with stdout closed: the output folder as before" unchanged

"$bin" run "$scene" --out "$out" 1</dev/null 2>"$tmp/err"; rc=$?
check "run with a read-only stdout: exit 3" [ "$rc" = 3 ]
check "run with a read-only stdout: the output folder as before" unchanged

"$bin" sweep "$sweep_scene" --out "$out" --json --quiet >/dev/full 2>"$tmp/err"; rc=$?
check "sweep > /dev/full: exit 3" [ "$rc" = 3 ]
check "sweep > /dev/full: the output folder as before" unchanged

# A stdout that passes the check before the run but fails when the report is written: a pipe
# whose reader has gone (a zero-byte write succeeds on it). `run` writes stdout before its commit,
# so the failure rolls the run back: exit 3, one line naming stdout, the folder as before — with
# SIGPIPE ignored (EPIPE) and with its default action (killing, as `| head` would).
for sigpipe in ignored default; do
  python3 - "$bin" "$scene" "$out" "$tmp/pipe_$sigpipe" "$sigpipe" <<'PY'
import os, signal, subprocess, sys
binary, scene, out, prefix, sigpipe = sys.argv[1:]
r, w = os.pipe()
os.close(r)  # the reader is gone before the run starts
def child():
    signal.signal(signal.SIGPIPE, signal.SIG_IGN if sigpipe == "ignored" else signal.SIG_DFL)
with open(prefix + ".err", "wb") as err:
    p = subprocess.run([binary, "run", scene, "--out", out, "--json"], stdout=w, stderr=err,
                       stdin=subprocess.DEVNULL, preexec_fn=child, restore_signals=False)
open(prefix + ".rc", "w").write(str(p.returncode))
PY
  check "run > a broken pipe (SIGPIPE $sigpipe): exit 3 (got $(cat "$tmp/pipe_$sigpipe.rc"))" [ "$(cat "$tmp/pipe_$sigpipe.rc")" = 3 ]
  check "run > a broken pipe (SIGPIPE $sigpipe): one line naming stdout" \
    bash -c "[ \$(wc -l <'$tmp/pipe_$sigpipe.err') = 1 ] && grep -q '^impactdeck: error: stdout: write failed: Broken pipe (before the commit: the run was rolled back, nothing was published)' '$tmp/pipe_$sigpipe.err'"
  check "run > a broken pipe (SIGPIPE $sigpipe): the output folder as before" unchanged
done

# sweep and study table1 write stdout before their commit too (a broken pipe, SIGPIPE ignored).
for cmd in sweep study; do
  case $cmd in
    sweep) args=(sweep "$sweep_scene" --out "$out" --json --grid-steps 4 --formats csv) ;;
    study) args=(study table1 --geometric-ratios 2 --mass-ratios 1 --grid-steps 4 --out "$out" --json --no-png) ;;
  esac
  python3 - "$tmp/pipe_$cmd" "$bin" "${args[@]}" <<'PY'
import os, signal, subprocess, sys
prefix, argv = sys.argv[1], sys.argv[2:]
r, w = os.pipe()
os.close(r)
with open(prefix + ".err", "wb") as err:
    p = subprocess.run(argv, stdout=w, stderr=err, stdin=subprocess.DEVNULL,
                       preexec_fn=lambda: signal.signal(signal.SIGPIPE, signal.SIG_IGN))
open(prefix + ".rc", "w").write(str(p.returncode))
PY
  check "$cmd > a broken pipe: exit 3 (got $(cat "$tmp/pipe_$cmd.rc"))" [ "$(cat "$tmp/pipe_$cmd.rc")" = 3 ]
  check "$cmd > a broken pipe: names stdout, rolled back" \
    grep -q '^impactdeck: error: stdout: write failed: Broken pipe (before the commit' "$tmp/pipe_$cmd.err"
  check "$cmd > a broken pipe: the output folder as before" unchanged
done

# campaign collect --json: refused before any work on /dev/full, rolled back on a broken pipe
# (the document is written before the commit): collect/ is not published either way.
cat >"$tmp/c.toml" <<TOML
scene = "$scene"
[product]
"impacts[0].restitution" = [0.9, 0.5]
TOML
"$bin" campaign plan "$tmp/c.toml" --out "$tmp/camp" >/dev/null && "$bin" campaign run "$tmp/camp" --quiet >/dev/null
"$bin" campaign collect "$tmp/camp" --json >/dev/full 2>"$tmp/err"; rc=$?
check "campaign collect --json > /dev/full: exit 3 (got $rc)" [ "$rc" = 3 ]
check "campaign collect --json > /dev/full: one line naming stdout" \
  bash -c "[ \$(wc -l <'$tmp/err') = 1 ] && grep -q '^impactdeck: error: stdout: write failed: No space left on device' '$tmp/err'"
check "campaign collect --json > /dev/full: nothing published" [ ! -e "$tmp/camp/collect" ]
python3 - "$tmp/pipe_collect" "$bin" campaign collect "$tmp/camp" --json <<'PY'
import os, signal, subprocess, sys
prefix, argv = sys.argv[1], sys.argv[2:]
r, w = os.pipe()
os.close(r)
with open(prefix + ".err", "wb") as err:
    p = subprocess.run(argv, stdout=w, stderr=err, stdin=subprocess.DEVNULL,
                       preexec_fn=lambda: signal.signal(signal.SIGPIPE, signal.SIG_IGN))
open(prefix + ".rc", "w").write(str(p.returncode))
PY
check "campaign collect --json > a broken pipe: exit 3" [ "$(cat "$tmp/pipe_collect.rc")" = 3 ]
check "campaign collect --json > a broken pipe: rolled back, says so" \
  grep -q '^impactdeck: error: stdout: write failed: Broken pipe (before the commit: the run was rolled back, nothing was published)' "$tmp/pipe_collect.err"
check "campaign collect --json > a broken pipe: nothing published" [ ! -e "$tmp/camp/collect" ]
"$bin" campaign collect "$tmp/camp" --json >"$tmp/collect.json" 2>"$tmp/err"; rc=$?
check "campaign collect --json: exit 0, published" bash -c "[ $rc = 0 ] && [ -f '$tmp/camp/collect/cases.csv' ]"

# The same commands with a usable stdout publish (the checks above are not refusing everything).
"$bin" run "$scene" --out "$out" --json >"$tmp/doc.json" 2>"$tmp/err"; rc=$?
check "run: exit 0" [ "$rc" = 0 ]
check "run: the file replaced" [ "$(head -c 4 "$out/force_two_spheres.csv")" = "time" ]

# sweep onto a full disk.
full=$tmp/full
mkdir -p "$full"
if unshare -m true 2>/dev/null; then
  unshare -m bash -c '
    mount -t tmpfs -o size=256k tmpfs "$1" || exit 77
    head -c 200000 /dev/zero >"$1/filler"
    "$2" sweep "$3" --out "$1" --quiet --grid-steps 40 --formats csv,vtp,pos >"$4/sweep.out" 2>"$4/sweep.err"
    echo $? >"$4/sweep.rc"
    ls -A "$1" >"$4/sweep.ls"
  ' _ "$full" "$bin" "$sweep_scene" "$tmp"
  if [ "$?" = 77 ]; then
    echo "output_failure_test: cannot mount a tmpfs here: the full-disk sweep case was not run"
  else
    check "sweep on a full disk: exit 3" [ "$(cat "$tmp/sweep.rc")" = 3 ]
    check "sweep on a full disk: one line" [ "$(wc -l <"$tmp/sweep.err")" = 1 ]
    check "sweep on a full disk: names the file and the reason" \
      grep -Eq "^impactdeck: error: $full/[^:]+: .*No space left on device" "$tmp/sweep.err"
    check "sweep on a full disk: nothing left but the filler" [ "$(cat "$tmp/sweep.ls")" = filler ]
    cat "$tmp/sweep.err"
  fi
else
  echo "output_failure_test: no mount namespace here: the full-disk sweep case was not run"
fi
finish output_failure_test
